"""Benchmark: the compiled core (kinematics/compiled/, switched by kinematics/backend.py) against baselines measured in the same
run, with the targets of the compiled-core issue.

    python benchmarks/bench_core.py [--json] [--quick]

Every target is printed with "met" or "NOT met" and the measured ratio or rate:

- ``fk_solve_us``: one forward-position solve of stewart-6sps from the reference with the legs
  held, as ``correct`` runs it (a platform on six S-P-S legs: Newton on the pose, then the legs
  placed and the closure checked, kinematics/leg_platform.py), and ``fk_joints_us`` the general
  engine on the same solve (``method="joints"``: Newton on 42 joint variables and the platform
  twist), against ``fk_scipy_root_us`` (scipy ``root``, hybr, on the 6-equation leg-length residual
  of the same platform) and ``fk_handwritten_us`` (a minimal hand-written numba Newton on that
  6x6 residual: no allocation in its loop, Gaussian elimination inline). The three are timed in
  turn, round after round, each keeping its best. Targets: >= 10x faster than scipy, within 5x
  of the hand-written Newton.
- ``circuit_five_cs_3_s``: the whole circuit of 5-CS linkage 3 (paper A) with the ten driver
  determinants as monitors, compiled, and ``circuit_python_s`` the same on the Python reference
  (``SPATIALMECH_PURE=1``). Targets: < 1 s and >= 10x.
- ``workspace_general_poses_per_s``: the general pose checker of three-rps (no closed form; the
  poses carry their parasitic coordinates). Target: >= 1e4 poses/s.
- ``dj_per_s``: driver determinants of five-cs-3 (one evaluation = one driver at one
  configuration), batched over the traced circuit. Target: >= 1e5 /s.
- ``ik_batch_vs_loop``: batched 4-SPS/CU inverse position against a plain-math Python loop.
  Target: >= 100x.
- ``first_call_cached_s`` / ``first_call_cold_s``: the compile cost a user pays: a fresh process
  loading every kernel from numba's on-disk cache, and compiling them into an empty cache.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit
from scipy.optimize import root

from spatialmech import catalog
from spatialmech.analysis.defects import candidate_drivers
from spatialmech.analysis.workspace.checker import pose_checker
from spatialmech.kinematics import backend, compiled
from spatialmech.kinematics.closure import Configuration, active_mask
from spatialmech.kinematics.backend import correct
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.jacobian import driver_determinants
from spatialmech.kinematics.position import configuration_at_pose, platform_pose
from spatialmech.kinematics.tracking import trace_motion

TARGETS = {
    "fk_vs_scipy_root": 10.0,  # at least this many times faster
    "fk_vs_handwritten": 5.0,  # at most this many times slower
    "circuit_s": 1.0,
    "circuit_speedup": 10.0,
    "workspace_general_poses_per_s": 1e4,
    "dj_per_s": 1e5,
    "ik_batch_vs_loop": 100.0,
}


pure = backend.python_reference


def best_time(fn, repeat: int, number: int) -> float:
    """Best of ``repeat`` runs of ``number`` calls, seconds per call."""
    return best_times({"fn": (fn, number)}, repeat)["fn"]


def best_times(fns: dict, repeat: int) -> dict:
    """Best of ``repeat`` rounds, seconds per call, for each ``name: (fn, number)``.  Each round
    runs every function once in turn, so that a slow spell of a shared machine falls on all of
    them alike and the ratios stay fair."""
    best = dict.fromkeys(fns, math.inf)
    for _ in range(repeat):
        for k, (fn, number) in fns.items():
            t = time.perf_counter()
            for _ in range(number):
                fn()
            best[k] = min(best[k], (time.perf_counter() - t) / number)
    return best


# ---------------------------------------------------------------------- Stewart forward position
@njit(cache=False)  # not cached: a script and an imported module would share (and confuse) one cache
def handwritten_stewart_newton(A, B, target, R0, t0, tol, max_iter, R, t):
    """Minimal Newton on the six leg lengths ``|R A_i + t - B_i| - target_i`` of a 6-6 Stewart
    platform: rows ``[(x_i x u_i)^T, u_i^T]`` (spatial twist), Gaussian elimination with partial
    pivoting on the 6x7 augmented matrix, update ``R <- exp(w) R``, ``t <- exp(w) t + v``; no
    allocation in the loop.  ``R``, ``t``: the result (from ``R0``, ``t0``).  Returns the
    iterations, or -1 when it did not converge."""
    M = np.empty((6, 7))
    for a in range(3):
        t[a] = t0[a]
        for b in range(3):
            R[a, b] = R0[a, b]
    for it in range(max_iter):
        worst = 0.0
        for i in range(6):
            x0 = R[0, 0] * A[i, 0] + R[0, 1] * A[i, 1] + R[0, 2] * A[i, 2] + t[0]
            x1 = R[1, 0] * A[i, 0] + R[1, 1] * A[i, 1] + R[1, 2] * A[i, 2] + t[1]
            x2 = R[2, 0] * A[i, 0] + R[2, 1] * A[i, 1] + R[2, 2] * A[i, 2] + t[2]
            d0, d1, d2 = x0 - B[i, 0], x1 - B[i, 1], x2 - B[i, 2]
            ln = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            u0, u1, u2 = d0 / ln, d1 / ln, d2 / ln
            ri = ln - target[i]
            worst = max(worst, abs(ri))
            M[i, 0] = x1 * u2 - x2 * u1
            M[i, 1] = x2 * u0 - x0 * u2
            M[i, 2] = x0 * u1 - x1 * u0
            M[i, 3], M[i, 4], M[i, 5] = u0, u1, u2
            M[i, 6] = -ri
        if worst < tol:
            return it
        for j in range(6):
            p = j
            for i in range(j + 1, 6):
                if abs(M[i, j]) > abs(M[p, j]):
                    p = i
            if p != j:
                for c in range(j, 7):
                    M[j, c], M[p, c] = M[p, c], M[j, c]
            for i in range(j + 1, 6):
                f = M[i, j] / M[j, j]
                for c in range(j, 7):
                    M[i, c] -= f * M[j, c]
        for j in range(5, -1, -1):
            acc = M[j, 6]
            for c in range(j + 1, 6):
                acc -= M[j, c] * M[c, 6]
            M[j, 6] = acc / M[j, j]
        w0, w1, w2 = M[0, 6], M[1, 6], M[2, 6]
        th = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        k0 = k1 = k2 = s = c = 0.0
        if th > 0.0:
            k0, k1, k2 = w0 / th, w1 / th, w2 / th
            s, c = math.sin(th), 1.0 - math.cos(th)
        W00, W11, W22 = 1.0 + c * (k0 * k0 - 1.0), 1.0 + c * (k1 * k1 - 1.0), 1.0 + c * (k2 * k2 - 1.0)
        W01, W10 = -s * k2 + c * k0 * k1, s * k2 + c * k0 * k1
        W02, W20 = s * k1 + c * k0 * k2, -s * k1 + c * k0 * k2
        W12, W21 = -s * k0 + c * k1 * k2, s * k0 + c * k1 * k2
        for b in range(3):
            r0, r1, r2 = R[0, b], R[1, b], R[2, b]
            R[0, b] = W00 * r0 + W01 * r1 + W02 * r2
            R[1, b] = W10 * r0 + W11 * r1 + W12 * r2
            R[2, b] = W20 * r0 + W21 * r1 + W22 * r2
        r0, r1, r2 = t[0], t[1], t[2]
        t[0] = W00 * r0 + W01 * r1 + W02 * r2 + M[3, 6]
        t[1] = W10 * r0 + W11 * r1 + W12 * r2 + M[4, 6]
        t[2] = W20 * r0 + W21 * r1 + W22 * r2 + M[5, 6]
    return -1


def stewart_case():
    """stewart-6sps, leg lengths of a generic pose, the anchors of its legs, the start."""
    mech = catalog.build("stewart-6sps")
    goal = generic_configuration(mech, seed=3, step=0.25)
    refs = mech.freedom_refs
    act = [i for i, r in enumerate(refs) if r.freedom.actuated]
    B = np.array([lb.joints[0].point for lb in mech.limbs])  # base S centres
    A = np.array([lb.joints[-1].point for lb in mech.limbs])  # platform S centres (reference)
    legs = np.linalg.norm((A @ goal.D[:3, :3].T + goal.D[:3, 3]) - B, axis=1)
    return mech, goal, act, A, B, legs


def bench_fk(quick: bool) -> dict:
    mech, goal, act, A, B, legs = stewart_case()
    start = Configuration.reference(mech)
    q0 = start.q.copy()
    q0[act] = goal.q[act]
    seed = start.with_q(q0)
    mask = active_mask(mech)
    mask[act] = False
    tol = 1e-12
    # the engine (compiled), then the Python reference
    res = correct(mech, seed, active=mask)
    assert res.converged, "the engine's forward solve did not converge"
    D = res.config.D
    err_engine = float(np.max(np.abs(D - goal.D)))
    rep, num = (2, 3) if quick else (25, 40)
    with pure():
        t_python = best_time(lambda: correct(mech, seed, active=mask), 2, 2 if quick else 5)

    # scipy root on the 6-equation leg-length residual (platform twist from the reference)
    def F(x):  # lean on purpose: the baseline is not slowed by the library's checks
        w = x[:3]
        th = math.sqrt(w @ w)
        if th > 0.0:
            k = w / th
            K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
            Rw = np.eye(3) + math.sin(th) * K + (1.0 - math.cos(th)) * (K @ K)
        else:
            Rw = np.eye(3)
        return np.linalg.norm(A @ Rw.T + x[3:] - B, axis=1) - legs

    sol = root(F, np.zeros(6), method="hybr", tol=tol)
    assert sol.success, "scipy root did not converge"
    # the hand-written numba Newton on the same residual
    R0, t0 = np.eye(3), np.zeros(3)
    Rh, th = np.empty((3, 3)), np.empty(3)
    it = handwritten_stewart_newton(A, B, legs, R0, t0, tol, 50, Rh, th)
    assert it >= 0, "the hand-written Newton did not converge"
    err_hand = float(max(np.max(np.abs(Rh - goal.D[:3, :3])), np.max(np.abs(th - goal.D[:3, 3]))))
    # the three timed in turn, round after round (best_times)
    t = best_times({
        "engine": (lambda: correct(mech, seed, active=mask), num),
        "joints": (lambda: correct(mech, seed, active=mask, method="joints"), max(1, num // 4)),
        "scipy": (lambda: root(F, np.zeros(6), method="hybr", tol=tol), max(1, num // 8)),
        "hand": (lambda: handwritten_stewart_newton(A, B, legs, R0, t0, tol, 50, np.empty((3, 3)), np.empty(3)),
                 num * 4),
    }, rep)
    t_engine, t_joints, t_scipy, t_hand = t["engine"], t["joints"], t["scipy"], t["hand"]
    joints = correct(mech, seed, active=mask, method="joints")
    assert joints.converged, "the general engine's forward solve did not converge"
    return {
        "fk_solve_us": t_engine * 1e6,
        "fk_joints_us": t_joints * 1e6,
        "fk_joints_iterations": int(joints.iterations),
        "fk_joints_vs_scipy_root": t_scipy / t_joints,
        "fk_joints_max_pose_difference": float(np.max(np.abs(joints.config.D - D))),
        "fk_python_us": t_python * 1e6,
        "fk_scipy_root_us": t_scipy * 1e6,
        "fk_handwritten_us": t_hand * 1e6,
        "fk_engine_iterations": int(res.iterations),
        "fk_handwritten_iterations": int(it),
        "fk_engine_max_error": err_engine,
        "fk_handwritten_max_error": err_hand,
        "fk_vs_scipy_root": t_scipy / t_engine,
        "fk_vs_handwritten": t_engine / t_hand,
        "fk_vs_python": t_python / t_engine,
    }


# ---------------------------------------------------------------------- 5-CS circuit and DJ
def five_cs_case():
    mech = catalog.build("five-cs-3")
    drivers = candidate_drivers(mech)
    prev = None
    fits = []
    for P in mech.positions:
        prev = configuration_at_pose(mech, P, start=prev).config
        fits.append(prev)
    return mech, drivers, fits


def circuit(mech, drivers, start, max_arc):
    return trace_motion(mech, start, increasing="rot1", max_arc=max_arc,
                        vector_monitor=(drivers, lambda c: driver_determinants(mech, c, drivers)))


def bench_circuit(quick: bool) -> dict:
    mech, drivers, fits = five_cs_case()
    max_arc = 3.0 if quick else 400.0
    circuit(mech, drivers, fits[0], 0.2)  # compile / load everything it uses
    t = time.perf_counter()
    tr = circuit(mech, drivers, fits[0], max_arc)
    t_fast = time.perf_counter() - t
    with pure():
        t = time.perf_counter()
        tr_py = circuit(mech, drivers, fits[0], max_arc)
        t_py = time.perf_counter() - t
    # the same curve: every compiled point lies within 1e-8 of the Python one (joint space)
    n = min(len(tr.points), len(tr_py.points))
    diff = max(float(np.max(np.abs(tr.points[i].q - tr_py.points[i].q))) for i in range(n)) if n else math.nan
    # DJ of every driver, batched over the traced points
    pts = tr.points
    qs = np.array([c.q for c in pts])
    Ds = np.array([c.D for c in pts])
    compiled.driver_determinants_many(mech, qs[:2], Ds[:2], None, drivers)
    rep = 2 if quick else 5
    t_dj = best_time(lambda: compiled.driver_determinants_many(mech, qs, Ds, None, drivers), rep, 1)
    t_one = best_time(lambda: driver_determinants(mech, pts[0], drivers), rep, 20)
    return {
        "circuit_five_cs_3_s": t_fast,
        "circuit_points": len(tr.points),
        "circuit_closed": bool(tr.closed),
        "circuit_events": len(tr.events),
        "circuit_python_s": t_py,
        "circuit_python_points": len(tr_py.points),
        "circuit_speedup": t_py / t_fast,
        "circuit_max_joint_difference": diff,
        "dj_per_s": len(pts) * len(drivers) / t_dj,
        "dj_single_call_per_s": len(drivers) / t_one,
    }


# ---------------------------------------------------------------------- general workspace checker
def bench_workspace(quick: bool) -> dict:
    from spatialmech.kinematics.task import solve_task

    mech = catalog.build("three-rps")
    checker = pose_checker(mech, method="general")
    rng = np.random.default_rng(0)
    n = 20 if quick else 400
    Rs, ps = [], []
    while len(Rs) < n:  # poses with their parasitic coordinates solved
        given = {"z": float(rng.uniform(0.25, 0.35)), "a2": float(rng.uniform(-0.3, 0.3)),
                 "a3": float(rng.uniform(-0.3, 0.3))}
        s = solve_task(mech, given)
        if s.converged:
            pose = platform_pose(mech, s.config)
            Rs.append(pose.R)
            ps.append(pose.p)
    R = np.array(Rs)
    p = np.array(ps, dtype=float)
    checker.feasible(R[:2], p[:2])
    t = time.perf_counter()
    ok = checker.feasible(R, p)
    dt = time.perf_counter() - t
    return {"workspace_general_poses_per_s": n / dt, "workspace_poses": n,
            "workspace_feasible_fraction": float(np.mean(ok)), "workspace_model": "three-rps"}


# ---------------------------------------------------------------------- 4-SPS/CU batched IK
def bench_ik(quick: bool) -> dict:
    """benchmarks/bench_four_sps_cu.py's inverse-position measurement (its plain-math loop is
    checked against the batched closed form there)."""
    import importlib.util
    from pathlib import Path

    spec = importlib.util.spec_from_file_location("bench_four_sps_cu", Path(__file__).with_name("bench_four_sps_cu.py"))
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    n, loop_n, fk_n, rep = (20_000, 2_000, 2, 2) if quick else (2_000_000, 20_000, 2, 3)
    inv = mod.run(n, loop_n, fk_n, rep)["inverse"]
    return {"ik_batch_poses_per_s": inv["vectorised_poses_per_s"], "ik_loop_poses_per_s": inv["loop_poses_per_s"],
            "ik_batch_vs_loop": inv["ratio"], "ik_max_abs_difference_m": inv["max_abs_diff_m"]}


# ---------------------------------------------------------------------- first-call cost
def bench_first_call() -> dict:
    code = ("import time; t = time.perf_counter(); from spatialmech.kinematics import compiled; "
            "compiled.warm_up(); print(time.perf_counter() - t)")
    out = {}
    cached = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    out["first_call_cached_s"] = float(cached.stdout.split()[-1])
    with tempfile.TemporaryDirectory() as d:
        env = {**os.environ, "NUMBA_CACHE_DIR": d}
        cold = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
    out["first_call_cold_s"] = float(cold.stdout.split()[-1])
    return out


def verdicts(out: dict) -> dict:
    return {
        "fk_vs_scipy_root": out["fk_vs_scipy_root"] >= TARGETS["fk_vs_scipy_root"],
        "fk_vs_handwritten": out["fk_vs_handwritten"] <= TARGETS["fk_vs_handwritten"],
        "circuit_s": out["circuit_five_cs_3_s"] < TARGETS["circuit_s"],
        "circuit_speedup": out["circuit_speedup"] >= TARGETS["circuit_speedup"],
        "workspace_general_poses_per_s": out["workspace_general_poses_per_s"] >= TARGETS["workspace_general_poses_per_s"],
        "dj_per_s": out["dj_per_s"] >= TARGETS["dj_per_s"],
        "ik_batch_vs_loop": out["ik_batch_vs_loop"] >= TARGETS["ik_batch_vs_loop"],
    }


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--json", action="store_true", help="print the results as JSON")
    ap.add_argument("--quick", action="store_true", help="tiny sizes (a smoke test; the targets mean nothing then)")
    args = ap.parse_args(argv)
    if not backend.enabled():
        raise SystemExit("the compiled core is not in use (numba missing or SPATIALMECH_PURE set)")
    out: dict = {"quick": bool(args.quick)}
    out.update(bench_fk(args.quick))
    out.update(bench_circuit(args.quick))
    out.update(bench_workspace(args.quick))
    out.update(bench_ik(args.quick))
    if not args.quick:
        out.update(bench_first_call())
    out["targets"] = TARGETS
    out["met"] = verdicts(out)
    if args.json:
        print(json.dumps(out, indent=2))
        return out
    met = out["met"]
    word = {True: "met", False: "NOT met"}
    print(f"FK solve, stewart-6sps      engine {out['fk_solve_us']:.1f} us, scipy root {out['fk_scipy_root_us']:.1f} us, "
          f"hand-written numba {out['fk_handwritten_us']:.2f} us, Python path {out['fk_python_us']:.0f} us")
    print(f"  general engine (method='joints') {out['fk_joints_us']:.1f} us, {out['fk_joints_vs_scipy_root']:.1f}x "
          f"faster than scipy root; same pose to {out['fk_joints_max_pose_difference']:.1e}")
    print(f"  vs scipy root             {out['fk_vs_scipy_root']:.1f}x faster (target >= 10x): {word[met['fk_vs_scipy_root']]}")
    print(f"  vs hand-written Newton    {out['fk_vs_handwritten']:.1f}x slower (target <= 5x): {word[met['fk_vs_handwritten']]}")
    print(f"circuit of five-cs-3        {out['circuit_five_cs_3_s']:.2f} s, {out['circuit_points']} points, "
          f"{out['circuit_events']} events (target < 1 s): {word[met['circuit_s']]}")
    print(f"  Python path               {out['circuit_python_s']:.2f} s, {out['circuit_speedup']:.1f}x "
          f"(target >= 10x): {word[met['circuit_speedup']]}")
    print(f"general checker, three-rps  {out['workspace_general_poses_per_s']:.3g} poses/s (target >= 1e4): "
          f"{word[met['workspace_general_poses_per_s']]}")
    print(f"driver determinants         {out['dj_per_s']:.3g} /s batched, {out['dj_single_call_per_s']:.3g} /s one call "
          f"(target >= 1e5): {word[met['dj_per_s']]}")
    print(f"4-SPS/CU batched IK         {out['ik_batch_vs_loop']:.0f}x the plain loop (target >= 100x): "
          f"{word[met['ik_batch_vs_loop']]}")
    if "first_call_cached_s" in out:
        print(f"first call                  {out['first_call_cached_s']:.2f} s from the disk cache, "
              f"{out['first_call_cold_s']:.1f} s compiling into an empty cache")
    return out


if __name__ == "__main__":
    main()
