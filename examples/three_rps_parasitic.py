"""A 3-RPS posed by its task coordinates: z, pitch a2 and roll a3 given, the parasitic x, y and
yaw a1 solved (sequence "ZYX", upper case = intrinsic).  The legs for a pose, the pose back from
the legs, the input-output Jacobian, and the parasitic motion over a grid of tilts against its
closed form.  SI units and radians in Python; degrees only where a name or a keyword says so."""

import numpy as np

import spatialmech as sm
from spatialmech.kinematics.closed_forms.three_rps import parasitic

# 1. Inverse position with x, y, a1 free: the legs, and the parasitic values solved.
pose = ([0.0, 0.0, 0.33], ("ZYX", 0.0, 5.0, 5.0))  # metres, degrees
r = sm.ik("three-rps", pose, degrees=True, free=["x", "y", "a1"])
legs = list(r.actuators.values())
print("given", r.task.given, "solved", r.task.solved, "| limbs:", r.result.search["method"])
assert r.task.converged and r.result.search["method"] == "Gauss-Newton per limb"
print(f"x = {r.task.values['x'] * 1e3:.4f} mm, y = {r.task.values['y'] * 1e3:.6f} mm, "
      f"a1 = {np.degrees(r.task.values['a1']):.4f} deg; legs (m): {np.round(legs, 6)}")

# 2. Forward position of those legs returns the same pose.
back = sm.fk("three-rps", legs)
print("forward:", back.to_dict()["method"])
assert back.to_dict()["method"].startswith("Gauss-Newton with the actuators held")
assert np.allclose(back.poses[0].p, r.pose.p, atol=1e-9) and np.allclose(back.poses[0].R, r.pose.R, atol=1e-9)

# 3. The 3 x 3 input-output Jacobian: d legs / d (z, a2, a3), parasitic coordinates following.
J = sm.jacobian("three-rps", pose, degrees=True, free=["x", "y", "a1"])
print("d legs / dz (m per m):", np.round(J.task.matrix[:, 0], 4))
h = 1e-6  # check one column by finite differences of the legs
up, dn = (sm.ik("three-rps", ([0, 0, 0.33 + s], ("ZYX", 0, 5, 5)), degrees=True, free=["x", "y", "a1"]) for s in (h, -h))
assert np.allclose(J.task.matrix[:, 0], (np.array(list(up.actuators.values())) - list(dn.actuators.values())) / (2 * h),
                   atol=1e-7)

# 4. The parasitic motion over tilts within +-20 deg, against the closed form (no z dependence).
tilt = np.radians(np.linspace(-20.0, 20.0, 9))
t = sm.parasitic("three-rps", {"a2": tilt, "a3": tilt}, at={"z": 0.33})
x, y, a1 = parasitic(0.15, *np.meshgrid(tilt, tilt, indexing="ij"))
err = max(np.abs(t.values("x") - x).max(), np.abs(t.values("y") - y).max(), np.abs(t.values("a1") - a1).max())
print(f"parasitic motion over 9 x 9 tilts: engine vs closed form {err:.1e}; "
      f"a1 within +-{np.degrees(t.ranges['a1'][1]):.2f} deg, x within +-{t.ranges['x'][1] * 1e3:.2f} mm")
assert err < 1e-10
