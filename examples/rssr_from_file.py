"""A custom RSSR linkage from a TOML file: its mobility and its traced motion.

The input crank (R joint about z, actuated) drives an output rocker (R joint about x) through a
coupler with spherical joints at both ends.  Mobility: M = 6(4 - 4 - 1) + 8 + 0 - 1 = 1, with one
passive freedom (the coupler's spin about the S-S line).  Traced by continuation, the crank
turns fully while the rocker oscillates between two limit positions.
"""

import tempfile
from pathlib import Path

import numpy as np

import spatialmech as sm

MODEL = """
name = "my-rssr"
description = "input crank about z, output rocker about x"
length_unit = "m"
platform_point = [0.0, 1.0, -0.1]      # the output rocker is the platform

[[limbs]]
name = "input"
joints = [
  { name = "A0", type = "R", point = [0, 0, 0], axis = [0, 0, 1], actuated = true, limits_deg = [-180, 180] },
  { name = "A1", type = "S", point = [0.3, 0, 0] },
  { name = "B1", type = "S", point = [0, 1, -0.1] },
]

[[limbs]]
name = "output"
joints = [ { name = "B0", type = "R", point = [0, 1, 0.5], axis = [1, 0, 0] } ]
"""

with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "my-rssr.toml"
    path.write_text(MODEL, encoding="utf-8")
    mech = sm.load(path)

m = sm.mobility(mech)
print(m.formula(), "| passive freedoms:", m.xi)

tr = sm.track(mech, increasing="A0")               # from the reference configuration
joints = tr.to_dict()["joint_values_deg"]           # degrees along the traced path, by freedom
crank, rocker = np.radians(joints["A0.rot"]), np.radians(joints["B0.rot"])
print(f"traced {len(tr.configurations)} configurations ({tr.status}); crank turns {np.degrees(np.ptp(crank)):.1f} deg, "
      f"rocker swings between {np.degrees(rocker.min()):.2f} and {np.degrees(rocker.max()):.2f} deg")

assert m.dof == m.dof_instantaneous == 1 and m.xi == 1
assert tr.closed
assert abs(np.ptp(crank) - 2 * np.pi) < 1e-6                                                # a full crank turn
assert 0 < np.ptp(rocker) < np.pi                                                              # a rocker
for P in tr.poses[::10]:                                                                      # the traced poses close:
    assert sm.ik(mech, P).reachable                                                           # every limb reaches them
