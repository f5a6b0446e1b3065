"""Forward position of a Gough-Stewart platform: assembly modes for one set of leg lengths.

The leg lengths come from the inverse position of a chosen pose.  ``sm.fk(..., all_solutions=True)``
picks its engine (here homotopy continuation: every complex solution, the set of real assembly
modes proven complete; ``method="multistart"`` would run a multi-start search instead, never a
proof) and the result says which one answered and whether its set is complete.  It finds that
pose again and other assembly modes; each is checked against the closed-form SPS leg lengths
|R a_i + p - b_i|, and so is its mirror image in the base plane (the same leg lengths with the
platform below the base).
"""

import numpy as np

import spatialmech as sm

sps = sm.closed_forms.sps                                                            # |R a_i + p - b_i|

mech = sm.load_model("stewart-6sps")
pose = sm.Pose.from_euler("ZYX", [12, -6, 4], [0.03, -0.02, 1.05], degrees=True)   # Rz(12) Ry(-6) Rx(4), metres
legs = np.array(list(sm.ik(mech, pose).actuators.values()))
print("leg lengths [m]:", np.round(legs, 6))

res = sm.fk(mech, legs, all_solutions=True, seed=2)                                 # method="auto"
modes = res.modes
print(f"{len(modes)} assembly modes found by {res.engine} ({'proven complete' if res.complete else 'NOT proven complete'}: "
      f"{res.completeness})")
for s in modes:
    print("  platform point", np.round(s.pose.p, 4), "| within limits" if s.within_limits else "| outside limits")

assert res.engine == "homotopy" and res.complete                                    # what the text above says
base = np.array([limb.joints[0].point for limb in mech.limbs])                       # b_i, world frame
plat = np.array([limb.joints[-1].point for limb in mech.limbs]) - mech.platform_point  # a_i, platform frame
M = np.diag([1.0, 1.0, -1.0])                                                         # reflection in z = 0
assert np.allclose(base[:, 2], 0.0)
assert any(np.allclose(s.pose.p, pose.p, atol=1e-8) and np.allclose(s.pose.R, pose.R, atol=1e-8) for s in modes)
assert len(modes) >= 2
for s in modes:
    assert np.allclose(sps.leg_lengths(s.pose.R, s.pose.p, base, plat), legs, atol=1e-8)
    assert np.allclose(sps.leg_lengths(M @ s.pose.R @ M, M @ s.pose.p, base, plat), legs, atol=1e-8)
