"""Accuracy of a 3-RPS parallel mechanism (not from the papers): the platform error from leg-length
errors, joint clearances and manufacturing tolerances, three ways (docs/accuracy.md).

1. At the reference pose (z = 0.3 m, platform level) leg errors alone: the worst z error is the leg
   tolerance over the cosine of the legs' tilt (every leg adds t / (3 cos) to z), by hand.
2. At a tilted pose with every error source: the first-order worst case contains every Monte-Carlo
   sample of the exact model, whose spread matches the first-order standard deviation.
"""

import numpy as np

import spatialmech as sm

t = 1e-5  # m

# 1. leg errors at the reference: hand check of the z worst case
r = sm.accuracy("three-rps", tolerances={"actuator": t}, samples=0, mobility_check=False)
leg = np.hypot(0.3 - 0.15, 0.3)  # base radius 0.3, platform radius 0.15, height 0.3 (catalog/classic.py)
assert abs(r.worst_case[2] - t * leg / 0.3) < 1e-12
print(f"reference pose, leg errors +-{t:g} m: worst z error {r.worst_case[2]:.4g} m (hand: {t * leg / 0.3:.4g} m)")

# 2. a tilted pose, every source: legs, clearances of the R and S joints, joint points and axes
pose = ([0, 0, 0.33], ("ZYX", 0, 5, 5))  # pitch and roll 5 deg; the parasitic x, y, yaw are fitted
r = sm.accuracy("three-rps", pose, degrees=True, samples=100, seed=1,
                tolerances={"actuator": t, "clearance": t, "geometry": t})
a = r.analysis
kinds = sorted({p.kind for p in a.params})
assert kinds == ["actuator", "axis", "clearance", "point"] and a.mc_failures == 0
assert np.all(np.abs(a.mc_errors) <= r.worst_case)
assert np.all(np.abs(r.std_monte_carlo / r.std_first_order - 1) < 0.3)  # 100 samples: about 7 % sampling error
assert not r.loses_mobility  # a 3-RPS is not overconstrained
print(f"tilted pose, {len(a.params)} error sources ({', '.join(kinds)}):")
for name, wc, sd, mc in zip(("dx", "dy", "dz"), r.worst_case, r.std_first_order, r.std_monte_carlo, strict=False):
    print(f"  {name}: worst case {wc:.3g} m, first-order std {sd:.3g} m, Monte-Carlo std {mc:.3g} m")
print(f"  rotation: worst case {np.degrees(r.worst_case[3:]).round(5)} deg")
