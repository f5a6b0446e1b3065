"""Benchmark: performance maps (analysis/maps.py, kernels in kinematics/compiled/maps.py).

    python benchmarks/bench_maps.py [--json] [--quick]

``maps_poses_per_s``: poses per second of ``sm.maps`` end to end (grid, limit checks with the
model's default limits, inverse position, complete Jacobian, every index), compiled and batched,
on stewart-6sps (position grid at the reference height) and four-sps-cu (orientation grid at
z = 0.12 m, paper B's limits: strokes, cones, link interference).  Target: >= 1e5 poses/s each
("met" / "NOT met").  ``ratio_vs_loop``: that rate over the per-pose Python loop's (the Python
reference, ``method="loop"`` under ``backend.python_reference()``), measured in the same run on
a sub-grid.  Both sides single-threaded (threadpoolctl limits BLAS/LAPACK to one thread when it
is installed; the compiled kernels do not spawn threads).  ``max_rel_diff_vs_loop``: the largest
difference between the two on the sub-grid (every index, cells with finite values).

The rates are the best of ``--repeat`` runs (default 5): on a shared machine the best run is the
one least disturbed by other processes, i.e. the closest to what the code itself costs;
``load_average`` (1 min, from the OS) is recorded with them.  ``maps_poses_per_cpu_s``: the same
runs timed by this process's CPU time (``time.process_time``; everything runs on one thread), the
cost of the code when other processes hold the cores (wall-clock rates then fall with the load,
CPU-time rates far less); "met" is printed for both.  ``kernel_poses_per_s``: the
compiled pose-to-indices kernel alone over the cells within the limits (the rest of
``maps_poses_per_s`` is the grid, the limit checks and the result's assembly).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import time

import numpy as np

from spatialmech import catalog
from spatialmech.analysis.maps import closed_form_plan, map_poses, performance_map
from spatialmech.analysis.workspace import default_limits, pose_checker
from spatialmech.geometry.tolerances import current
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


def _kernel_rate(mech, kind: str, over: dict, at, repeat: int) -> float | None:
    """Poses per second of the closed-form kernel alone, on the cells within the limits."""
    fast, plan = backend.engine(), closed_form_plan(mech)
    if fast is None or not isinstance(plan, dict):
        return None
    _, _, R, p, _ = map_poses(mech, kind, over, at)
    live = pose_checker(mech, default_limits(mech)).feasible(R, p)
    R, p = R[live], p[live]
    t, best = current(), np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fast.maps.maps_closed(R, p, plan, mech.characteristic_length, t.rank, t.pivot)
        best = min(best, time.perf_counter() - t0)
    return R.shape[0] / best


def run(name: str, n: int, n_loop: int, repeat: int = 5) -> dict:
    kind, coords, (lo, hi), at = CASES[name]
    mech = catalog.build(name)
    over = dict.fromkeys(coords, (lo, hi, n))
    performance_map(mech, kind=kind, over=dict.fromkeys(coords, (lo, hi, 3)), at=at)  # compile / load the kernels
    best, best_cpu = np.inf, np.inf
    for _ in range(repeat):
        t, c = time.perf_counter(), time.process_time()
        r = performance_map(mech, kind=kind, over=over, at=at)
        best, best_cpu = min(best, time.perf_counter() - t), min(best_cpu, time.process_time() - c)
    rate, rate_cpu = r.n_poses / best, r.n_poses / best_cpu
    kernel = _kernel_rate(mech, kind, over, at, repeat)
    small = dict.fromkeys(coords, (lo, hi, n_loop))
    t = time.perf_counter()
    with backend.python_reference():
        ref = performance_map(mech, kind=kind, over=small, at=at, method="loop")
    loop_rate = ref.n_poses / (time.perf_counter() - t)
    fast = performance_map(mech, kind=kind, over=small, at=at)
    return {"model": name, "poses": r.n_poses, "maps_poses_per_s": rate, "maps_poses_per_cpu_s": rate_cpu,
            "met_cpu": rate_cpu >= TARGET, "kernel_poses_per_s": kernel,
            "loop_poses_per_s": loop_rate,
            "ratio_vs_loop": rate / loop_rate, "max_rel_diff_vs_loop": _diff(ref, fast),
            "same_status": bool(np.array_equal(ref.status, fast.status)), "path": r.path,
            "status_counts": r.status_counts(), "met": rate >= TARGET}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="smaller grids")
    ap.add_argument("--repeat", type=int, default=5, help="runs per rate; the best is kept (default 5)")
    args = ap.parse_args()
    n, n_loop = (100, 5) if args.quick else (300, 12)
    ctx, threads = _single_thread()
    with ctx:
        rows = [run(name, n, n_loop, max(1, args.repeat)) for name in CASES]
    doc = {"maps_poses_per_s": {r["model"]: r["maps_poses_per_s"] for r in rows},
           "maps_poses_per_cpu_s": {r["model"]: r["maps_poses_per_cpu_s"] for r in rows}, "target_poses_per_s": TARGET,
           "threads": threads, "best_of": max(1, args.repeat), "load_average": os.getloadavg()[0], "cases": rows}
    if args.json:
        print(json.dumps(doc, indent=2))
        return
    for r in rows:
        kern = "" if r["kernel_poses_per_s"] is None else f", kernel alone {r['kernel_poses_per_s']:.3g}"
        print(f"{r['model']}: {r['maps_poses_per_s']:.3g} poses/s{kern} ({r['poses']} poses, {r['path']}) "
              f"{'met' if r['met'] else 'NOT met'} (target {TARGET:.0e}); by CPU time {r['maps_poses_per_cpu_s']:.3g} "
              f"{'met' if r['met_cpu'] else 'NOT met'}; per-pose Python loop "
              f"{r['loop_poses_per_s']:.3g} poses/s, ratio {r['ratio_vs_loop']:.0f}x; "
              f"largest relative difference {r['max_rel_diff_vs_loop']:.1e}, same statuses {r['same_status']}")
    print(f"{threads}; best of {doc['best_of']} runs; load average {doc['load_average']:.2f}")


if __name__ == "__main__":
    main()
