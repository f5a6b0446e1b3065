"""Six-joint limbs with a spherical wrist, decoupled (kinematics/wrist_limb.py): the Stanford arm
(R R P + wrist) gets all 8 inverse solutions, proven and certified."""

import numpy as np
import pytest

import spatialmech as sm
from spatialmech import catalog
from spatialmech.kinematics import wrist_limb
from spatialmech.kinematics.closure import chain_forward, limb_chains

# the Stanford arm (Spong's standard DH: d2 = 0.154 m, d6 = 0.263 m), the slide's reference 0.5 m
STANFORD = """
name = "stanford-arm"
[dh]
convention = "standard"
d = [0.0, 0.154, 0.5, 0.0, 0.0, 0.263]
a = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]
alpha_deg = [-90, 90, 0, -90, 90, 0]
joints = "RRPRRR"
reference_deg = [0, 30, 0, 10, 40, 0]
"""


def _angles(x):
    return np.angle(np.exp(1j * np.asarray(x)))


@pytest.mark.slow  # the wrist centre's trace test, once per geometry: ~5 s
def test_stanford_arm_eight_solutions_proven_certified_and_the_drawn_one_among_them():
    m = sm.loads(STANFORD)
    ch = limb_chains(m)[0]
    for q_true in (np.array([0.3, -0.4, 0.1, 0.5, -0.6, 0.7]), np.array([-1.2, 0.8, -0.2, 2.0, 0.3, -2.5])):
        T, _ = chain_forward(ch, q_true)
        inv = sm.ik(m, sm.Pose.from_displacement(T, m.platform_point), all_solutions=True).to_dict()
        rep = inv["search"]["limbs"][0]
        assert rep["method"] == "decoupled" and rep["complete"], rep["completeness"]
        sols = inv["limbs"][0]["solutions"]
        assert len(sols) == 8 and inv["n_certified"] == 8
        qs = [np.array([s["joints_deg"].get(r.id, 0.0) for r in m.freedom_refs]) for s in sols]
        qs = [np.where([r.freedom.kind == "P" for r in m.freedom_refs],
                       [s["joints_len"].get(r.id, 0.0) for r in m.freedom_refs], np.radians(q))
              for q, s in zip(qs, sols, strict=True)]
        for q in qs:
            assert np.allclose(chain_forward(ch, q)[0], T, atol=1e-12)
        assert any(np.allclose(_angles(q - q_true), 0, atol=1e-9) for q in qs)


def test_only_six_joint_limbs_with_a_slide_before_a_spherical_wrist_are_split():
    assert wrist_limb.wrist_split(sm.loads(STANFORD), 0) is not None
    assert wrist_limb.wrist_split(catalog.resolve("puma560"), 0) is None  # a 6R: its root count proves it
    offset = STANFORD.replace("a = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0]", "a = [0.0, 0.0, 0.0, 0.05, 0.0, 0.0]")
    assert wrist_limb.wrist_split(sm.loads(offset), 0) is None  # the wrist's axes do not meet
