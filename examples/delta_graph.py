"""The Clavel Delta as a link-and-joint graph: 3 R + 12 S joints, 11 links, 5 independent loops.

Each limb is an actuated R joint, an arm, and a parallelogram of two rods with spherical joints
at both ends.  The mobility count works loop by loop: 3 DOF, pure translation, and the six rods'
spins as passive freedoms.  Inverse position solves each arm with its two rods (two solutions
per arm), and forward position of the actuator angles gives the pose back.
"""

import numpy as np

import spatialmech as sm

links = ["ground", "platform"]
joints = []
for i, ang in enumerate(np.deg2rad([90, 210, 330])):
    k = i + 1
    radial = np.array([np.cos(ang), np.sin(ang), 0.0])
    tangent = np.array([-np.sin(ang), np.cos(ang), 0.0])
    shoulder, elbow = 0.2 * radial, 0.4 * radial
    wrist = 0.05 * radial + np.array([0, 0, -0.35])
    links += [f"arm{k}", f"rod{k}a", f"rod{k}b"]
    joints.append((sm.R(f"R{k}", shoulder, tangent, actuated=True), "ground", f"arm{k}"))
    for side, sign in (("a", 1.0), ("b", -1.0)):
        off = sign * 0.03 * tangent
        joints.append((sm.S(f"E{k}{side}", elbow + off), f"arm{k}", f"rod{k}{side}"))
        joints.append((sm.S(f"W{k}{side}", wrist + off), f"rod{k}{side}", "platform"))

delta = sm.Mechanism.from_graph("my-delta", links, joints, platform_point=[0, 0, -0.35])
m = sm.mobility(delta)
print(m.formula(), "| loops:", m.loops, "| motion:", m.motion, "| passive spins:", m.xi)

pose = ([0.03, -0.02, -0.34], ("ZYX", 0.0, 0.0, 0.0))
ik = sm.ik(delta, pose, degrees=True)
angles = ik.actuators
print("actuator angles [deg]:", {k: round(float(np.degrees(v)), 4) for k, v in angles.items()})
fk = sm.fk(delta, list(angles.values()))
print("forward position:", np.round(fk.poses[0].p, 9))
clusters = ik.result.search["clusters"]                 # limbs sharing a body, solved together
print("inverse:", ik.result.search["method"], "| arm clusters:", [c["limbs"] for c in clusters],
      "| forward:", fk.to_dict()["method"])

assert (m.dof, m.loops, m.motion, m.xi) == (3, 5, "TxTyTz", 6)
assert ik.result.search["method"] == "Gauss-Newton per limb"
assert sorted(len(c["limbs"]) for c in clusters) == [3, 3, 3]          # each arm with its two rods
assert fk.to_dict()["method"].startswith("Gauss-Newton with the actuators held")
assert np.allclose(fk.poses[0].p, pose[0], atol=1e-9)
