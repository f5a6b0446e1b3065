"""Benchmark: the loop formulation of the forward position (kinematics/homotopy/general.py) by
monodromy, on models the Study reductions do not cover.

    python benchmarks/bench_homotopy_loops.py [--json] [--quick]

Cases: rssr, planar-4r and bennett at an input angle (first solve, including the monodromy), and
(unless --quick) a general 6R loop: one limb of six R joints with seeded random axes, the
platform held by a locked joint, no actuator -- the inverse kinematics of a general 6R arm, whose
published count is 16 complex solutions.  Every real solution is checked against the closure;
each case prints the trace test's verdict (kinematics/homotopy/trace_test.py) and whether the set is proven.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import spatialmech as sm
from spatialmech.kinematics.homotopy import general as hg
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.backend import closure_residual


def six_r() -> sm.Mechanism:
    rng = np.random.default_rng(3)
    axes = rng.normal(size=(6, 3))
    joints = [sm.R(f"J{k}", rng.normal(size=3) * 0.5, axes[k] / np.linalg.norm(axes[k])) for k in range(6)]
    weld = sm.R("W", [0, 0, 0], [0, 0, 1], lockable=True, locked=True)
    return sm.Mechanism("six-r", limbs=[sm.Limb("arm", joints), sm.Limb("weld", [weld])], platform_point=[0, 0, 0])


def targets(mech: sm.Mechanism, values) -> dict[int, float]:
    """Actuator values (mechanism order) as joint variables by freedom index."""
    refs = mech.freedom_refs
    return {refs.index(mech.freedom(a)): v - mech.freedom(a).freedom.offset for a, v in zip(mech.actuators, values,
                                                                                              strict=True)}


def case(mech: sm.Mechanism, values) -> dict:
    hg.clear_cache()
    t = time.perf_counter()
    r = hg.general_forward(mech, targets(mech, values))
    sec = time.perf_counter() - t
    worst = max((float(np.max(np.abs(closure_residual(mech, Configuration(s.q, s.D)))))
                 for s in r.solutions if s.q is not None), default=0.0)
    return {"model": mech.name, "family": "limb offsets" if hg.loop_system(mech).rigid_family else "offset b",
            "n_generic": r.n_generic, "n_real": r.count("real"), "n_complex": r.count("complex"),
            "n_singular": r.count("singular"), "n_at_infinity": r.count("at_infinity"), "n_spurious": r.n_spurious,
            "loops": r.loops, "seconds": round(sec, 3), "worst_real_closure_residual": worst,
            "complete": r.complete, "trace_test": r.trace.verdict if r.trace else "not run",
            "n_witness": r.trace.n_witness if r.trace else 0,
            "trace_seconds": round(r.trace.seconds, 3) if r.trace else 0.0}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--quick", action="store_true", help="the small models only (no 6R)")
    args = ap.parse_args()
    rows = [case(sm.load_model("rssr"), [np.radians(30)]), case(sm.load_model("planar-4r"), [np.radians(20)]),
            case(sm.load_model("bennett"), [np.radians(40)])]
    if not args.quick:
        rows.append(case(six_r(), []))
    if args.json:
        print(json.dumps(rows, indent=2))
        return
    for r in rows:
        print(f"{r['model']:10s} {r['family']:12s} generic {r['n_generic']:4d}  real {r['n_real']:2d}  complex "
              f"{r['n_complex']:3d}  spurious {r['n_spurious']:4d}  at infinity {r['n_at_infinity']:4d}  "
              f"{r['seconds']:.2f} s  (worst closure residual of a real one {r['worst_real_closure_residual']:.1e}); "
              f"trace test {r['trace_test']} ({r['n_witness']} witness points, {r['trace_seconds']:.2f} s): "
              f"{'complete' if r['complete'] else 'NOT proven'}")
    six = [r for r in rows if r["model"] == "six-r"]
    if six:
        n = six[0]["n_real"] + six[0]["n_complex"]
        print(f"general 6R: {n} finite solutions (published: 16): {'met' if n == 16 else 'NOT met'}")


if __name__ == "__main__":
    main()
