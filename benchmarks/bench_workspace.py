"""Benchmark: orientation-workspace pose checks of the 4-SPS/CU (paper B limits), vectorised
against a per-pose loop, measured in the same run.

Run ``python benchmarks/bench_workspace.py [--json] [--n N] [--loop-n N] [--general-n N]``.

- ``vectorised``: :meth:`PoseChecker.feasible` of the closed-form kernel on ``n`` random
  orientations at ``z = 0.1 m`` (one call, chunked inside), in pose checks/s;
- ``loop``: the same kernel called once per pose (``loop_n`` poses), in pose checks/s, and the
  ratio; the two must agree pose by pose (``agree``);
- ``general``: the per-pose inverse-position fallback (``general_n`` poses), in pose checks/s;
- ``workspace``: the full orientation workspace at ``step_deg`` (grid + bisection), seconds.

Each timing is the best of ``--repeat`` runs; BLAS threads are pinned to 1 before NumPy loads.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from spatialmech import catalog  # noqa: E402
from spatialmech.analysis.workspace import orientation_workspace, paper_b_limits, pose_checker  # noqa: E402
from spatialmech.geometry.rotations import euler_matrix  # noqa: E402


def _best(fn, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def run(n: int = 1_000_000, loop_n: int = 5000, general_n: int = 20, step_deg: float = 2.0, repeat: int = 3) -> dict:
    mech = catalog.build("four-sps-cu")
    limits = paper_b_limits()
    fast = pose_checker(mech, limits)
    rng = np.random.default_rng(0)
    ang = np.column_stack([rng.uniform(-0.6, 0.6, n), rng.uniform(-0.6, 0.6, n), rng.uniform(-2.4, 2.4, n)])
    R = euler_matrix("ZYX", ang[:, [2, 1, 0]])
    p = np.tile([0.0, 0.0, 0.1], (n, 1))
    t_vec = _best(lambda: fast.feasible(R, p), repeat)
    ok = fast.feasible(R, p)
    m = min(loop_n, n)
    loop_ok = np.zeros(m, dtype=bool)

    def loop():
        for i in range(m):
            loop_ok[i] = fast.feasible(R[i : i + 1], p[i : i + 1])[0]

    t_loop = _best(loop, repeat)
    out = {
        "machine": platform.machine(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "model": "four-sps-cu, paper B limits, z = 0.1 m",
        "vectorised": {"n": n, "seconds": t_vec, "pose_checks_per_s": n / t_vec, "feasible_fraction": float(ok.mean())},
        "loop": {"n": m, "seconds": t_loop, "pose_checks_per_s": m / t_loop, "agree": bool(np.array_equal(loop_ok, ok[:m]))},
    }
    out["ratio_vectorised_over_loop"] = out["vectorised"]["pose_checks_per_s"] / out["loop"]["pose_checks_per_s"]
    if general_n:
        slow = pose_checker(mech, limits, method="general")
        g = min(general_n, n)
        t0 = time.perf_counter()
        g_ok = slow.feasible(R[:g], p[:g])
        dt = time.perf_counter() - t0
        out["general"] = {"n": g, "seconds": dt, "pose_checks_per_s": g / dt, "agree": bool(np.array_equal(g_ok, ok[:g]))}
    if step_deg:
        t0 = time.perf_counter()
        ws = orientation_workspace(mech, at={"z": 0.1}, limits=limits, step=np.radians(step_deg))
        dt = time.perf_counter() - t0
        d = ws.to_dict()
        out["workspace"] = {"step_deg": step_deg, "seconds": dt, "poses_checked": ws.n_poses,
                            "pose_checks_per_s": ws.n_poses / dt,
                            **{c: d["extents"][c]["alone"] for c in ("alpha_deg", "beta_deg", "gamma_deg")},
                            **{f"{c}_set": d["extents"][c]["set"] for c in ("alpha_deg", "beta_deg", "gamma_deg")},
                            "volume_deg3": d["volume_deg3"]}
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--loop-n", type=int, default=5000)
    ap.add_argument("--general-n", type=int, default=20)
    ap.add_argument("--step-deg", type=float, default=2.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args(argv)
    res = run(a.n, a.loop_n, a.general_n, a.step_deg, a.repeat)
    if a.json:
        print(json.dumps(res, indent=2))
        return
    print(f"vectorised: {res['vectorised']['pose_checks_per_s']:.3g} pose checks/s ({res['vectorised']['n']} poses)")
    print(f"per-pose loop: {res['loop']['pose_checks_per_s']:.3g} pose checks/s (agree: {res['loop']['agree']})")
    print(f"ratio: {res['ratio_vectorised_over_loop']:.0f} x")
    if "general" in res:
        print(f"general fallback: {res['general']['pose_checks_per_s']:.3g} pose checks/s (agree: {res['general']['agree']})")
    if "workspace" in res:
        w = res["workspace"]
        print(f"orientation workspace at {w['step_deg']} deg: {w['seconds']:.2f} s, {w['poses_checked']} poses; "
              f"alpha {w['alpha_deg']}, beta {w['beta_deg']}, gamma {w['gamma_deg']} deg")


if __name__ == "__main__":
    main()
