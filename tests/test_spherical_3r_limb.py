"""Every inverse solution of a spherical 3R limb in closed form (closed_forms/spherical_3r_limb.py):
an Agile-Eye leg, paper C's legs and any three revolutes whose axes meet, proven complete."""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import spatialmech as sm
from spatialmech.kinematics.closure import chain_forward, limb_chains
from spatialmech.kinematics.position import inverse_position
from spatialmech.model.joints import R
from spatialmech.model.mechanism import Limb, Mechanism


def _wrist(u, c):
    """One limb of three revolutes along ``u`` (rows) through ``c``, from the ground to the output."""
    return Mechanism("wrist", (Limb("w", tuple(R(f"J{i + 1}", c, u[i], actuated=True) for i in range(3))),),
                     platform_point=np.asarray(c, float))


def _angles(x):
    return np.angle(np.exp(1j * np.asarray(x)))


def _limb_report(res, li=0):
    return res.search["limbs"][li]


unit = st.lists(st.floats(-1, 1), min_size=3, max_size=3).map(np.array).filter(lambda v: np.linalg.norm(v) > 0.3)


@settings(max_examples=25, deadline=None)
@given(u1=unit, u2=unit, u3=unit, c=st.lists(st.integers(-20, 20).map(lambda k: k / 10), min_size=3, max_size=3),
       q=st.lists(st.floats(-3.1, 3.1), min_size=3, max_size=3))
def test_the_drawn_configuration_is_among_at_most_two_that_close(u1, u2, u3, c, q):
    """Round trip: the configuration a pose was made from is found, and every one listed closes."""
    u = np.array([u1, u2, u3]) / np.linalg.norm([u1, u2, u3], axis=1)[:, None]
    assume(min(np.linalg.norm(np.cross(u[0], u[1])), np.linalg.norm(np.cross(u[1], u[2]))) > 0.1)
    m = _wrist(u, c)
    ch = limb_chains(m)[0]
    T, _ = chain_forward(ch, np.array(q))
    # the last axis turned onto the first: the first and last joints turn together (a continuum)
    assume(np.linalg.norm(np.cross(u[0], T[:3, :3] @ u[2])) > 0.05)
    pose = sm.Pose.from_displacement(T, m.platform_point)
    res = inverse_position(m, pose, all_solutions=True)
    rep = _limb_report(res)
    assert rep["method"] == "closed-form" and rep["complete"], rep
    sols = res.limbs[0].solutions
    assert 1 <= len(sols) <= 2
    for s in sols:
        assert np.allclose(chain_forward(ch, s)[0], T, atol=1e-10)
    # near a double root (the two placements of the middle axis meet) the angles lose half their digits
    assert any(np.allclose(_angles(s - np.array(q)), 0, atol=1e-6) for s in sols)


def test_agile_eye_legs_two_modes_each_proven_and_the_multistart_agrees():
    m = sm.load_model("agile-eye")
    pose = sm.Pose(Rotation.from_rotvec([0.2, -0.3, 0.25]).as_matrix(), [0, 0, 0])
    closed = inverse_position(m, pose, all_solutions=True)
    multi = inverse_position(m, pose, all_solutions=True, method="multistart", n_seeds=48)
    assert closed.search["complete"] and not multi.search["complete"]
    for li in range(3):
        a, b = closed.limbs[li].solutions, multi.limbs[li].solutions
        assert len(a) == len(b) == 2
        for s in a:
            assert any(np.allclose(_angles(s - t), 0, atol=1e-9) for t in b)
        assert max(closed.limbs[li].residuals) < 1e-14


def test_an_orientation_out_of_reach_has_no_real_configuration_proven():
    """Link angles of 30 degrees: the last axis stays within 60 degrees of the first."""
    c30, s30 = np.cos(np.pi / 6), np.sin(np.pi / 6)
    u = np.array([[0, 0, 1.0], [s30, 0, c30], [2 * s30 * c30, 0, c30**2 - s30**2]])
    m = _wrist(u, [0, 0, 0])
    far = sm.Pose(Rotation.from_rotvec([np.pi / 2, 0, 0]).as_matrix(), [0, 0, 0])
    res = inverse_position(m, far, all_solutions=True)
    rep = _limb_report(res)
    assert rep["method"] == "closed-form" and rep["complete"] and "0 real" in rep["completeness"]
    assert not res.reachable and res.limbs[0].solutions == ()


def test_a_pose_that_moves_the_common_point_has_none():
    m = _wrist(np.eye(3), [0.1, 0.2, 0.3])
    res = inverse_position(m, sm.Pose(np.eye(3), [0.2, 0.2, 0.3]), all_solutions=True)
    rep = _limb_report(res)
    assert rep["complete"] and "moves the axes' common point" in rep["completeness"] and not res.reachable


def test_a_continuum_is_named_and_left_to_the_multistart():
    """Orthogonal wrist with the last axis turned onto the first: the first joint turns freely."""
    m = _wrist(np.eye(3)[[2, 1, 0]], [0, 0, 0])  # z, y, x
    Rp = Rotation.from_rotvec([0, -np.pi / 2, 0]).as_matrix()  # x -> z: the last axis onto the first
    res = inverse_position(m, sm.Pose(Rp, [0, 0, 0]), all_solutions=True)
    rep = _limb_report(res)
    assert rep["method"] == "multistart" and not rep["complete"]
    assert "continuum" in rep["completeness"]


@pytest.mark.parametrize("axes", [np.eye(3)[[2, 2, 0]], np.eye(3)])
def test_only_true_spherical_limbs_are_taken(axes):
    """Consecutive parallel axes are not a spherical 3R (and the closed form is not used); the
    orthogonal wrist is."""
    m = _wrist(axes, [0, 0, 0])
    res = inverse_position(m, sm.Pose(Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix() if axes[0] @ axes[1] == 0
                                      else Rotation.from_rotvec([0, 0, 0.3]).as_matrix(), [0, 0, 0]),
                           all_solutions=True)
    assert (_limb_report(res)["method"] == "closed-form") == (abs(axes[0] @ axes[1]) < 0.5)
