"""Benchmark: performance maps (analysis/maps.py, kernels in kinematics/compiled/maps.py).

    python benchmarks/bench_maps.py [--json] [--quick]

``maps_poses_per_s``: poses per second of ``sm.maps`` end to end (grid, limit checks with the
model's default limits, inverse position, complete Jacobian, every index), compiled and batched,
on stewart-6sps (position grid at the reference height) and four-sps-cu (orientation grid at
z = 0.12 m, paper B's limits: strokes, cones, link interference).  Target: >= 1e5 poses/s each
("met" / "NOT met").  ``ratio_vs_loop``: that rate over the per-pose Python loop's (the Python
reference, ``method="loop"`` under ``backend.python_reference()``), measured in the same run on
a sub-grid.  Both sides single-threaded (threadpoolctl limits BLAS/LAPACK to one thread when it
is installed; the compiled kernels do not spawn threads).  ``max_abs_diff``: the largest
difference between the two on the sub-grid (every index, cells with finite values).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import time

import numpy as np

from spatialmech import catalog
from spatialmech.analysis.maps import performance_map
from spatialmech.kinematics import backend

TARGET = 1e5
CASES = {
    "stewart-6sps": ("position", ("x", "y"), (-0.2, 0.2), None),
    "four-sps-cu": ("orientation", ("alpha", "beta"), (-0.5, 0.5), {"z": 0.12}),
}


def _single_thread():
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return contextlib.nullcontext(), "threadpoolctl not installed: BLAS threads not limited"
    return threadpool_limits(1), "threadpoolctl: 1 thread"


def _diff(a, b) -> float:
    worst = 0.0
    for k in a.values:
        x, y = a.values[k], b.values[k]
        fin = np.isfinite(x) & np.isfinite(y)
        if fin.any():
            scale = np.maximum(1.0, np.abs(x[fin]))
            worst = max(worst, float(np.max(np.abs(x[fin] - y[fin]) / scale)))
    return worst


def run(name: str, n: int, n_loop: int) -> dict:
    kind, coords, (lo, hi), at = CASES[name]
    mech = catalog.build(name)
    over = dict.fromkeys(coords, (lo, hi, n))
    performance_map(mech, kind=kind, over=dict.fromkeys(coords, (lo, hi, 3)), at=at)  # compile / load the kernels
    best = np.inf
    for _ in range(3):
        t = time.perf_counter()
        r = performance_map(mech, kind=kind, over=over, at=at)
        best = min(best, time.perf_counter() - t)
    rate = r.n_poses / best
    small = dict.fromkeys(coords, (lo, hi, n_loop))
    t = time.perf_counter()
    with backend.python_reference():
        ref = performance_map(mech, kind=kind, over=small, at=at, method="loop")
    loop_rate = ref.n_poses / (time.perf_counter() - t)
    fast = performance_map(mech, kind=kind, over=small, at=at)
    return {"model": name, "poses": r.n_poses, "maps_poses_per_s": rate, "loop_poses_per_s": loop_rate,
            "ratio_vs_loop": rate / loop_rate, "max_rel_diff_vs_loop": _diff(ref, fast),
            "same_status": bool(np.array_equal(ref.status, fast.status)), "path": r.path,
            "status_counts": r.status_counts(), "met": rate >= TARGET}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="smaller grids")
    args = ap.parse_args()
    n, n_loop = (100, 5) if args.quick else (300, 12)
    ctx, threads = _single_thread()
    with ctx:
        rows = [run(name, n, n_loop) for name in CASES]
    doc = {"maps_poses_per_s": {r["model"]: r["maps_poses_per_s"] for r in rows}, "target_poses_per_s": TARGET,
           "threads": threads, "cases": rows}
    if args.json:
        print(json.dumps(doc, indent=2))
        return
    for r in rows:
        print(f"{r['model']}: {r['maps_poses_per_s']:.3g} poses/s ({r['poses']} poses, {r['path']}) "
              f"{'met' if r['met'] else 'NOT met'} (target {TARGET:.0e}); per-pose Python loop "
              f"{r['loop_poses_per_s']:.3g} poses/s, ratio {r['ratio_vs_loop']:.0f}x; "
              f"largest relative difference {r['max_rel_diff_vs_loop']:.1e}, same statuses {r['same_status']}")
    print(threads)


if __name__ == "__main__":
    main()
