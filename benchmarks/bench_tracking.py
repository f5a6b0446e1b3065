"""Benchmark: tracing 5-CS linkage 3 (paper A) with the pseudo-arclength tracker, against a
straightforward tracker that steps the driver (rot1) and calls ``scipy.optimize.root`` per step,
measured in the same run; and DJ evaluations per second.

    python benchmarks/bench_tracking.py [--json] [--quick]

The scipy baseline can only follow the path while rot1 is monotonic (it cannot pass a turning
point of its parameter), so both are timed on the path P1 -> P7, where rot1 is; the tracker's
whole circuit is timed on its own.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from scipy.optimize import root

from spatialmech import catalog
from spatialmech.analysis.defects import candidate_drivers
from spatialmech.geometry.rotations import exp_twist
from spatialmech.kinematics.closure import Configuration, active_mask
from spatialmech.kinematics.backend import closure_residual
from spatialmech.kinematics.jacobian import driver_determinants
from spatialmech.kinematics.position import configuration_at_pose
from spatialmech.kinematics.tracking import trace_motion


def scipy_tracker(mech, start: Configuration, i_driver: int, target: float, steps: int):
    """Step the driver from its start value to ``target``; solve the closure with scipy root
    (hybr, finite-difference Jacobian) at every step from the previous solution."""
    free = active_mask(mech)
    free[i_driver] = False
    q, D = start.q.copy(), start.D
    x = np.zeros(int(free.sum()) + 6)
    nfev = 0
    configs = []
    for v in np.linspace(start.q[i_driver], target, steps + 1)[1:]:
        q = q.copy()
        q[i_driver] = v

        def F(x, q=q, D=D):
            qq = q.copy()
            qq[free] = q[free] + x[:-6]
            return closure_residual(mech, Configuration(qq, exp_twist(x[-6:], 1.0) @ D))

        sol = root(F, np.zeros_like(x), method="hybr", tol=1e-12)
        nfev += sol.nfev
        if not sol.success:
            return configs, nfev, False
        q[free] = q[free] + sol.x[:-6]
        D = exp_twist(sol.x[-6:], 1.0) @ D
        configs.append(Configuration(q.copy(), D))
    return configs, nfev, True


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="tiny sizes (smoke test)")
    args = ap.parse_args(argv)
    mech = catalog.build("five-cs-3")
    drivers = candidate_drivers(mech)
    ids = [r.id for r in mech.freedom_refs]
    i_rot1 = ids.index("C1.rot")
    fits, prev = [], None
    for P in mech.positions:
        prev = configuration_at_pose(mech, P, start=prev).config
        fits.append(prev)
    out = {}
    def djf(c):
        return driver_determinants(mech, c, drivers)
    if not args.quick:
        t = time.perf_counter()
        tr = trace_motion(mech, fits[0], increasing="rot1", max_arc=400, vector_monitor=(drivers, djf))
        out["tracker_whole_circuit_s"] = time.perf_counter() - t
        out["tracker_whole_circuit_points"] = len(tr.points)
        out["tracker_whole_circuit_closed"] = tr.closed
        out["tracker_whole_circuit_events"] = len(tr.events)
    # the path P1 -> P7 with both trackers
    target = fits[-1].q[i_rot1]
    t = time.perf_counter()
    sense = int(np.sign(target - fits[0].q[i_rot1]))
    tr = trace_motion(mech, fits[0], increasing="rot1", sense=sense, max_arc=400,
                      stop=lambda x, s: (x.q[i_rot1] - target) * sense >= 0)
    t_ours = time.perf_counter() - t
    steps = max(4, len(tr.points)) if not args.quick else 4
    t = time.perf_counter()
    _cfgs, nfev, ok = scipy_tracker(mech, fits[0], i_rot1, target if not args.quick else fits[0].q[i_rot1] + 0.05, steps)
    t_scipy = time.perf_counter() - t
    out.update({
        "path": "P1 -> P7 of five-cs-3, driver rot1 (monotonic there)",
        "tracker_path_s": t_ours, "tracker_path_points": len(tr.points), "tracker_path_status": tr.status,
        "scipy_root_path_s": t_scipy, "scipy_root_steps": steps, "scipy_root_nfev": int(nfev), "scipy_root_ok": ok,
        "speedup_vs_scipy_root": t_scipy / t_ours if t_ours > 0 else None,
    })
    n = 20 if args.quick else 300
    t = time.perf_counter()
    for k in range(n):
        djf(fits[k % len(fits)])
    dt = time.perf_counter() - t
    out["dj_evaluations_per_s"] = n * len(drivers) / dt
    out["dj_note"] = "one evaluation = DJ of one driver; the ten drivers share the twists and constraint rows"
    if args.json:
        print(json.dumps(out, indent=2))
    else:
        for k, v in out.items():
            print(f"{k:32s} {v}")
    return out


if __name__ == "__main__":
    main()
