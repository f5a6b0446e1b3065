"""Inverse dynamics of a Delta robot (3-RUU) carrying a payload: the motor torques of a
rest-to-rest move, from Newton-Euler per link and virtual power over the closed chain.

The physics the example checks:
- at rest the motors hold the weights: the dynamics equal the statics with gravity;
- along the same path, the inertial part of the torques (acceleration and velocity-squared terms)
  scales as 1/T^2: halving the move's duration multiplies it by exactly 4;
- the payload's mass, given in the model (not derived from the shapes), is used and said so.
"""

import dataclasses

import numpy as np

import spatialmech as sm
from spatialmech.model.inertia import LinkInertia

delta = sm.load_model("delta-ruu")
# a 0.5 kg payload on the platform, a small cylinder below it (world axes at the reference pose)
p0 = delta.platform_point
payload = LinkInertia(0.5, p0 + np.array([0.0, 0.0, -0.02]), np.diag([2e-4, 2e-4, 1e-4]))
delta = dataclasses.replace(delta, inertias={"platform": payload}, density_kg_m3=2700.0)

target = np.radians([25.0, 10.0, -5.0])  # motor angles at the end of the move
slow = sm.inverse_dynamics(delta, to=target, duration=0.6, samples=13)
fast = sm.inverse_dynamics(delta, to=target, duration=0.3, samples=13)
assert slow.mass_source["platform"] == "file" and slow.mass_source["arm1.link1"] == "density"
assert max(slow.max_residual, fast.max_residual) < 1e-10

# the quasi-static torques at the same configurations (no rates, no accelerations)
rest = sm.inverse_dynamics(delta, values=slow.values)
inertial_slow = slow.efforts - rest.efforts
inertial_fast = fast.efforts - rest.efforts
assert np.allclose(inertial_fast, 4.0 * inertial_slow, rtol=0, atol=1e-9 * np.abs(inertial_fast).max())

# at rest: the statics with gravity
st = sm.statics(delta, wrench=[0] * 6, gravity=[0, 0, -9.81])
assert np.allclose(rest.efforts[0], list(st.efforts.values()), rtol=1e-10)

print("t [s]   " + "  ".join(f"{a} [N m]" for a in slow.actuators))
for t, row in zip(fast.times, fast.efforts, strict=True):
    print(f"{t:5.3f}  " + "  ".join(f"{v:+12.5f}" for v in row))
print(f"peak torque of the 0.3 s move: {np.abs(fast.efforts).max():.4f} N m "
      f"(holding at rest: {np.abs(rest.efforts).max():.4f} N m)")
