"""Benchmark: workspace limits in the compiled batch (issue 29), each against the Python reference
measured in the same run, both on one thread.

    python benchmarks/bench_limits.py [--json] [--quick]

Every target is printed with "met" or "NOT met"; BLAS is held to one thread before NumPy loads
(the compiled kernels measured here run on one thread); the baselines are the same calls inside
``backend.python_reference()`` (the per-pose Python path), on fewer poses or cells:

- ``checker_cones_three_rps_poses_per_s``: the general pose checker of three-rps with cone
  limits of 45 deg on S1, S2, S3 (the link's angle to the platform's z axis, as ``--cone
  S1=45,...``), on poses that close (their parasitic coordinates solved from random
  ``z, a2, a3``); target >= 1e4 poses/s;
- ``checker_cones_stewart_poses_per_s``: the same for stewart-6sps with cones of 40 deg on every
  base and platform ball (``B1..B6``: the base's z axis, ``A1..A6``: the platform's) and link
  capsules of 0.05 L; random poses around the reference; target >= 1e4 poses/s;
- ``task_workspace_three_rps_cells_per_s``: ``workspace three-rps --task --over
  a2:-40:40:41,a3:-40:40:41 --at z=0.33 --cone S1=45,S2=45,S3=45`` (grid cells per second of the
  whole analysis: continuation over the grid, limits, boundary refined to 1e-3 deg); target
  >= 5e3 cells/s; the baseline runs an 11 x 11 grid;
- ``*_speedup``: the compiled rate over the reference's, and ``*_agree``: the two paths give the
  same margins (to 1e-10), active limits and reachable cells on the poses / grid both ran;
- ``*_per_cpu_s``: the same rates over the process's CPU time instead of the wall clock (what the
  kernels cost when they get a core; not the verdict).

The machine running this is shared: absolute rates vary by 2-5x with its load; the ratios, whose
two sides run in the same process one after the other, vary less.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")  # both sides on one thread (the kernels measured here are serial)

import argparse  # noqa: E402
import json  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import spatialmech as sm  # noqa: E402
from spatialmech import catalog  # noqa: E402
from spatialmech.analysis.workspace import ConeLimit, WorkspaceLimits, pose_checker  # noqa: E402
from spatialmech.geometry.rotations import euler_matrix  # noqa: E402
from spatialmech.kinematics import backend  # noqa: E402
from spatialmech.kinematics.closure import Configuration  # noqa: E402
from spatialmech.kinematics.position import platform_pose  # noqa: E402
from spatialmech.kinematics.task import solve_task  # noqa: E402

TARGETS = {
    "checker_cones_three_rps_poses_per_s": 1e4,
    "checker_cones_stewart_poses_per_s": 1e4,
    "task_workspace_three_rps_cells_per_s": 5e3,
}


def _three_rps_poses(mech, n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    Rs, ps = [], []
    while len(Rs) < n:
        s = solve_task(mech, {"z": float(rng.uniform(0.25, 0.35)), "a2": float(rng.uniform(-0.4, 0.4)),
                              "a3": float(rng.uniform(-0.4, 0.4))})
        if s.converged:
            pose = platform_pose(mech, s.config)
            Rs.append(pose.R)
            ps.append(pose.p)
    return np.array(Rs), np.array(ps, dtype=float)


def _stewart_poses(mech, n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    R = euler_matrix("ZYX", rng.uniform(-0.3, 0.3, (n, 3)))
    p0 = platform_pose(mech, Configuration.reference(mech)).p
    return R, p0 + rng.uniform(-0.15, 0.15, (n, 3)) * mech.characteristic_length


def _checker(name: str, mech, limits: WorkspaceLimits, R, p, n_ref: int) -> dict:
    checker = pose_checker(mech, limits, method="general")
    checker.margins(R[:2], p[:2])  # kernels loaded
    t, c = time.perf_counter(), time.process_time()
    M = checker.margins(R, p)
    dt, cpu = time.perf_counter() - t, time.process_time() - c
    m = min(n_ref, R.shape[0])
    with backend.python_reference():
        t = time.perf_counter()
        M_ref = np.array([checker.margins(R[i : i + 1], p[i : i + 1])[0] for i in range(m)])
        dt_ref = time.perf_counter() - t
    names_fast = checker.violated(R[:m], p[:m])
    scaled = M_ref / checker.scales
    names_ref = [checker.names[int(np.argmin(row))] if np.min(row) < 0 else "" for row in scaled]
    rate, rate_ref = R.shape[0] / dt, m / dt_ref
    return {f"checker_cones_{name}_poses_per_s": rate, f"checker_cones_{name}_poses_per_cpu_s": R.shape[0] / cpu,
            f"checker_cones_{name}_reference_poses_per_s": rate_ref,
            f"checker_cones_{name}_speedup": rate / rate_ref,
            f"checker_cones_{name}_feasible_fraction": float(np.mean(np.all(M >= 0, axis=1))),
            f"checker_cones_{name}_agree": bool(np.max(np.abs(M[:m] - M_ref)) <= 1e-10 and names_fast == names_ref),
            f"checker_cones_{name}_poses": int(R.shape[0])}


def _task_workspace(n: int, n_ref: int) -> dict:
    cones = {"S1": np.radians(45), "S2": np.radians(45), "S3": np.radians(45)}

    def run(k: int):
        over = {"a2": (np.radians(-40), np.radians(40), k), "a3": (np.radians(-40), np.radians(40), k)}
        t = time.perf_counter()
        ws = sm.workspace("three-rps", kind="task", over=over, at={"z": 0.33}, cones=cones, tol=np.radians(1e-3))
        return ws, time.perf_counter() - t

    run(3)  # kernels loaded
    c = time.process_time()
    ws, dt = run(n)
    cpu = time.process_time() - c
    small, dt_small = run(n_ref)
    with backend.python_reference():
        ref, dt_ref = run(n_ref)
    agree = (np.array_equal(small.feasible, ref.feasible) and np.array_equal(small.converged, ref.converged)
             and list(small.cell_limits.ravel()) == list(ref.cell_limits.ravel())
             and small.boundary_limits == ref.boundary_limits
             and small.boundary_points.shape == ref.boundary_points.shape
             and float(np.max(np.abs(small.boundary_points - ref.boundary_points), initial=0.0)) <= 1e-10
             and float(np.nanmax(np.abs(small.values - ref.values))) <= 1e-10)
    ext = ws.extents
    return {"task_workspace_three_rps_cells_per_s": ws.feasible.size / dt,
            "task_workspace_three_rps_cells_per_cpu_s": ws.feasible.size / cpu,
            "task_workspace_three_rps_seconds": dt, "task_workspace_three_rps_cells": int(ws.feasible.size),
            "task_workspace_three_rps_solves": int(ws.n_solves),
            "task_workspace_three_rps_small_cells_per_s": small.feasible.size / dt_small,
            "task_workspace_three_rps_reference_cells_per_s": ref.feasible.size / dt_ref,
            "task_workspace_three_rps_speedup": (small.feasible.size / dt_small) / (ref.feasible.size / dt_ref),
            "task_workspace_three_rps_agree": bool(agree),
            "task_workspace_three_rps_a2_deg": [float(np.degrees(ext["a2"].lo)), float(np.degrees(ext["a2"].hi))],
            "task_workspace_three_rps_a3_deg": [float(np.degrees(ext["a3"].lo)), float(np.degrees(ext["a3"].hi))]}


def run(quick: bool = False) -> dict:
    rng = np.random.default_rng(0)
    n, n_ref = (200, 10) if quick else (20000, 40)
    out: dict = {"blas_threads": os.environ.get("OPENBLAS_NUM_THREADS"), "kernel_threads": 1}
    rps = catalog.build("three-rps")
    R, p = _three_rps_poses(rps, n, rng)
    cones = WorkspaceLimits(cones=tuple(ConeLimit(f"S{i}", (0, 0, 1), "platform", np.radians(45)) for i in (1, 2, 3)))
    out.update(_checker("three_rps", rps, cones, R, p, n_ref))
    stewart = catalog.build("stewart-6sps")
    R, p = _stewart_poses(stewart, n, rng)
    cones = tuple(ConeLimit(limb.joints[0].name, (0, 0, 1), "base", np.radians(40)) for limb in stewart.limbs)
    cones += tuple(ConeLimit(limb.joints[-1].name, (0, 0, 1), "platform", np.radians(40)) for limb in stewart.limbs)
    out.update(_checker("stewart", stewart, WorkspaceLimits(cones, 0.05 * stewart.characteristic_length), R, p, n_ref))
    out.update(_task_workspace(9 if quick else 41, 5 if quick else 11))
    out["met"] = {k: bool(out[k] >= v) for k, v in TARGETS.items()}
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="small sizes (a smoke test, not a measurement)")
    a = ap.parse_args(argv)
    out = run(a.quick)
    if a.json:
        print(json.dumps(out, indent=2))
        return
    word = {True: "met", False: "NOT met"}
    for name in ("three_rps", "stewart"):
        k = f"checker_cones_{name}"
        print(f"general checker with cones, {name}: {out[k + '_poses_per_s']:.3g} poses/s "
              f"({out[k + '_poses_per_cpu_s']:.3g} per CPU second) (target >= 1e4): "
              f"{word[out['met'][k + '_poses_per_s']]}; reference {out[k + '_reference_poses_per_s']:.3g} /s, "
              f"{out[k + '_speedup']:.0f}x; feasible {out[k + '_feasible_fraction']:.2f}; agree {out[k + '_agree']}")
    k = "task_workspace_three_rps"
    print(f"task workspace three-rps 41x41: {out[k + '_cells_per_s']:.3g} cells/s "
          f"({out[k + '_cells_per_cpu_s']:.3g} per CPU second), {out[k + '_seconds']:.2f} s "
          f"(target >= 5e3): {word[out['met'][k + '_cells_per_s']]}; 11x11 {out[k + '_small_cells_per_s']:.3g} /s "
          f"against the reference's {out[k + '_reference_cells_per_s']:.3g} /s, {out[k + '_speedup']:.0f}x; "
          f"agree {out[k + '_agree']}; a2 {out[k + '_a2_deg']}, a3 {out[k + '_a3_deg']} deg")


if __name__ == "__main__":
    main()
