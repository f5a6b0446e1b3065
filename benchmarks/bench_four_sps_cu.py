"""Benchmark: 4-SPS/CU (paper B) inverse kinematics, vectorised against a plain Python loop.

Run ``python benchmarks/bench_four_sps_cu.py [--json] [--n N] [--loop-n N] [--fk-n N]``.

Measured in the same run, on one core (BLAS threads pinned to 1 before NumPy loads, numba's
thread pool set to 1 thread; the batched and loop runs alternate so that both see the same load;
the multi-core rate of the batched kernel is reported apart, ``multi_core_*``):

- inverse position (pose -> four leg lengths) with the vectorised closed form
  :func:`spatialmech.kinematics.closed_forms.four_sps_cu.leg_lengths` in poses/s;
- the same computation as a plain Python loop (``math`` module, eq 7 matrix and
  ``l_i = |T A_i + (0, 0, z) - B_i|`` per leg), in poses/s, and the ratio (this is the
  strict baseline: hand-written scalar Python, no NumPy call overhead);
- a second baseline: a Python loop calling the library once per pose (``leg_lengths(pose)``),
  which is what a per-pose caller pays;
- forward position (leg lengths -> pose) by the Levenberg-Marquardt solver, in solves/s: one
  :func:`forward` call per solve, and :func:`forward_batch` over all solves at once.

Targets (the kinematics issue): vectorised >= 100 x the loop and >= 5 million poses/s.  Each
timing is the best of ``--repeat`` runs.  The loop's results are checked against the
vectorised ones (``max_abs_diff_m``) so that both compute the same thing.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402

from spatialmech.kinematics.closed_forms import four_sps_cu as k  # noqa: E402
from spatialmech.kinematics.closed_forms import four_sps_cu_forward as kf  # noqa: E402

TARGET_RATIO = 100.0
TARGET_POSES_PER_S = 5e6


def loop_leg_lengths(poses: list, a: float, b: float) -> list:
    """Plain Python reference: eq 7's matrix and the distance formula, one pose at a time."""
    A = [(a, -a), (a, a), (-a, a), (-a, -a)]
    B = [(b, -b), (b, b), (-b, b), (-b, -b)]
    out = []
    for z, al, be, ga in poses:
        sa, ca = math.sin(al), math.cos(al)
        sb, cb = math.sin(be), math.cos(be)
        sg, cg = math.sin(ga), math.cos(ga)
        # first two columns of T = Rz(gamma) Ry(beta) Rx(alpha) (A_i has no z component)
        r00, r01 = cb * cg, cg * sb * sa - sg * ca
        r10, r11 = cb * sg, sa * sb * sg + cg * ca
        r20, r21 = -sb, cb * sa
        legs = []
        for (ax, ay), (bx, by) in zip(A, B, strict=True):
            dx = r00 * ax + r01 * ay - bx
            dy = r10 * ax + r11 * ay - by
            dz = r20 * ax + r21 * ay + z
            legs.append(math.sqrt(dx * dx + dy * dy + dz * dz))
        out.append(legs)
    return out


def _best(fn, repeat: int) -> float:
    best = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _best_pair(fa, fb, repeat: int) -> tuple[float, float]:
    """Best times of ``fa`` and ``fb`` over ``repeat`` alternating runs of each."""
    ba = bb = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fa()
        ba = min(ba, time.perf_counter() - t0)
        t0 = time.perf_counter()
        fb()
        bb = min(bb, time.perf_counter() - t0)
    return ba, bb


def _poses(n: int, rng: np.random.Generator) -> np.ndarray:
    z = rng.uniform(0.08, 0.3, n)
    ang = rng.uniform(-0.5, 0.5, (n, 3))
    return np.column_stack([z, ang])


def run(n: int = 2_000_000, loop_n: int = 20_000, fk_n: int = 200, repeat: int = 5, seed: int = 0) -> dict:
    """Run the benchmark and return the figures as a JSON-serialisable dict."""
    if min(n, loop_n, fk_n, repeat) < 1:
        raise ValueError("n, loop_n, fk_n, repeat: expected positive integers")
    geom = k.PAPER_B
    rng = np.random.default_rng(seed)
    phi = _poses(n, rng)
    k.leg_lengths(phi[: min(n, 1000)])  # warm-up
    k.leg_lengths(phi[: min(n, k.PARALLEL_FROM + 1)])  # the parallel kernel's warm-up too

    loop_phi = phi[:loop_n] if loop_n <= n else _poses(loop_n, rng)
    loop_in = loop_phi.tolist()
    # the ratio measures the kernel, not the machine's load: both sides on one thread (numba's
    # pool too), their runs interleaved so that both see the same load; best of each
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        t_vec, t_loop = _best_pair(lambda: k.leg_lengths(phi, geom),
                                   lambda: loop_leg_lengths(loop_in, geom.a, geom.b), repeat)
    finally:
        numba.set_num_threads(threads)
    t_vec_mt = _best(lambda: k.leg_lengths(phi, geom), repeat)  # the multi-core speed-up, reported apart
    diff = float(np.max(np.abs(np.array(loop_leg_lengths(loop_in, geom.a, geom.b)) - k.leg_lengths(loop_phi, geom))))
    call_n = max(1, loop_n // 10)
    call_phi = loop_phi[:call_n]
    t_call = _best(lambda: [k.leg_lengths(p, geom) for p in call_phi], repeat)

    # forward position: seeds 0.05 rad / 0.01 m away from the pose that produced the legs
    fk_phi = _poses(fk_n, rng)
    fk_phi[:, 1:3] = np.where(np.abs(fk_phi[:, 1:3]) < 0.05, 0.05, fk_phi[:, 1:3])  # away from alpha = beta = 0
    legs = k.leg_lengths(fk_phi, geom)
    seeds = fk_phi + np.array([0.01, 0.05, -0.05, 0.05])
    t0 = time.perf_counter()
    single = [kf.forward(legs[i], seeds[i], geometry=geom) for i in range(fk_n)]
    t_single = time.perf_counter() - t0
    t0 = time.perf_counter()
    batch = kf.forward_batch(legs, seeds, geometry=geom)
    t_batch = time.perf_counter() - t0
    err = np.abs(batch.phi - fk_phi).max(axis=1)

    vec_rate = n / t_vec
    loop_rate = loop_n / t_loop
    return {
        "benchmark": "4-SPS/CU inverse position (pose -> leg lengths), paper B eq 8 corrected",
        "python": platform.python_version(),
        "numpy": np.__version__,
        "machine": platform.machine(),
        "threads": "1 (OMP/OpenBLAS/MKL pinned, numba.set_num_threads(1) for the ratio; NumPy element-wise code "
                   "is single-threaded); multi_core_* with numba's default threads",
        "repeat": repeat,
        "inverse": {
            "vectorised_poses": n,
            "vectorised_s": t_vec,
            "vectorised_poses_per_s": vec_rate,
            "loop_poses": loop_n,
            "loop_s": t_loop,
            "loop_poses_per_s": loop_rate,
            "ratio": vec_rate / loop_rate,
            "multi_core_threads": threads,
            "multi_core_poses_per_s": n / t_vec_mt,
            "multi_core_speedup": t_vec / t_vec_mt,
            "per_pose_call_poses": call_n,
            "per_pose_call_poses_per_s": call_n / t_call,
            "ratio_to_per_pose_call": vec_rate / (call_n / t_call),
            "max_abs_diff_m": diff,
            "target_ratio": TARGET_RATIO,
            "target_poses_per_s": TARGET_POSES_PER_S,
            "meets_targets": bool(vec_rate / loop_rate >= TARGET_RATIO and vec_rate >= TARGET_POSES_PER_S),
        },
        "forward": {
            "solves": fk_n,
            "seed_offset": "(+0.01 m, +0.05, -0.05, +0.05 rad) from the true pose",
            "single_call_solves_per_s": fk_n / t_single,
            "single_call_converged": int(sum(r.converged for r in single)),
            "batched_solves_per_s": fk_n / t_batch,
            "batched_converged": int(batch.converged.sum()),
            "batched_mean_iterations": float(batch.iterations.mean()),
            "batched_recovered_true_pose": int(np.sum(err < 1e-9)),
        },
    }


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2_000_000, help="poses for the vectorised kernel")
    parser.add_argument("--loop-n", type=int, default=20_000, help="poses for the plain Python loop")
    parser.add_argument("--fk-n", type=int, default=200, help="forward-position solves")
    parser.add_argument("--repeat", type=int, default=5, help="best of this many runs")
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args(argv)
    res = run(args.n, args.loop_n, args.fk_n, args.repeat)
    if args.json:
        print(json.dumps(res, indent=2))
        return res
    inv, fwd = res["inverse"], res["forward"]
    print(res["benchmark"])
    print(f"  vectorised : {inv['vectorised_poses_per_s']:.3e} poses/s ({inv['vectorised_poses']} poses)")
    print(f"  Python loop: {inv['loop_poses_per_s']:.3e} poses/s ({inv['loop_poses']} poses)")
    print(f"  ratio      : {inv['ratio']:.0f}x  (max |difference| {inv['max_abs_diff_m']:.1e} m; both on one thread)")
    print(f"  multi-core : {inv['multi_core_poses_per_s']:.3e} poses/s on {inv['multi_core_threads']} threads, "
          f"x{inv['multi_core_speedup']:.2f} the one-thread kernel")
    print(
        f"  per-pose library calls: {inv['per_pose_call_poses_per_s']:.3e} poses/s, "
        f"ratio {inv['ratio_to_per_pose_call']:.0f}x"
    )
    print(
        f"  targets    : >= {TARGET_RATIO:.0f}x the plain loop and >= {TARGET_POSES_PER_S:.0e} poses/s -> "
        + ("met" if inv["meets_targets"] else "NOT met")
    )
    print("forward position (Levenberg-Marquardt)")
    print(
        f"  one call per solve: {fwd['single_call_solves_per_s']:.0f} solves/s "
        f"({fwd['single_call_converged']}/{fwd['solves']} converged)"
    )
    print(
        f"  batched           : {fwd['batched_solves_per_s']:.0f} solves/s "
        f"({fwd['batched_converged']}/{fwd['solves']} converged, mean {fwd['batched_mean_iterations']:.1f} iterations)"
    )
    return res


if __name__ == "__main__":
    main(sys.argv[1:])
