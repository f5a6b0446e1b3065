"""Describe your own mechanism in a few lines of Python and analyse its mobility.

A 3-PRS parallel mechanism (actuated vertical sliders, revolute joints, spherical joints on a
triangular platform): 3 DOF, one translation and two rotations (with parasitic motion).
"""

import numpy as np

import spatialmech as sm

limbs = []
for i, ang in enumerate(np.deg2rad([90, 210, 330])):
    radial = np.array([np.cos(ang), np.sin(ang), 0.0])
    tangent = np.array([-np.sin(ang), np.cos(ang), 0.0])
    base = 0.4 * radial
    knee = base + np.array([0, 0, 0.1])
    ankle = 0.15 * radial + np.array([0, 0, 0.45])
    limbs.append(sm.Limb(f"leg{i + 1}", [
        sm.P(f"P{i + 1}", base, [0, 0, 1], actuated=True, limits=[0.0, 0.5]),
        sm.R(f"R{i + 1}", knee, tangent),
        sm.S(f"S{i + 1}", ankle),
    ]))

mech = sm.Mechanism("3-PRS", limbs, platform_point=[0, 0, 0.45])
result = sm.mobility(mech)
print(result.formula())
print("motion:", result.motion, "| instantaneous:", result.dof_instantaneous)

assert result.dof == result.dof_instantaneous == 3
assert result.motion == "RxRyTz"
