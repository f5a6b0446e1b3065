"""Inverse solutions are told apart in configuration space (issue 27, first item).

Two solutions of a limb are one only when every freedom agrees (angles modulo 2 pi, slides,
an S joint's rotation), not when the joint axes lie on the same lines: the PUMA 560 has its
eight solutions, an Agile-Eye leg its two working modes.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import spatialmech as sm
from spatialmech.geometry.tolerances import DEFAULT
from spatialmech.model.joints import C, H, P, R, S, U, Sm
from spatialmech.model.mechanism import Limb, Mechanism
from spatialmech.kinematics.closure import chain_forward
from spatialmech.kinematics.position import inverse_position, same_solution, solution_form, solution_key

# Unimation PUMA 560, standard Denavit-Hartenberg parameters (d, a, alpha) in metres and
# radians, as in P. Corke's Robotics Toolbox, mdl_puma560 (after Corke and Armstrong-Helouvry,
# "A search for consensus among model parameters reported for the PUMA 560 robot", ICRA 1994).
PUMA560_DH = [
    (0.0, 0.0, np.pi / 2),
    (0.0, 0.4318, 0.0),
    (0.15005, 0.0203, -np.pi / 2),
    (0.4318, 0.0, np.pi / 2),
    (0.0, 0.0, -np.pi / 2),
    (0.0, 0.0, 0.0),
]


def dh_frames(dh, theta):
    """Frames 0..n of a standard-DH chain: T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)."""
    T = np.eye(4)
    out = [T]
    for (d, a, al), t in zip(dh, theta, strict=True):
        ct, s_t, ca, sa = np.cos(t), np.sin(t), np.cos(al), np.sin(al)
        T = T @ np.array([[ct, -s_t * ca, s_t * sa, a * ct], [s_t, ct * ca, -ct * sa, a * s_t], [0, sa, ca, d], [0, 0, 0, 1.0]])
        out.append(T)
    return out


def serial_arm(name, dh):
    """A serial arm as a mechanism of one limb of R joints from the ground to the output link
    (the last DH frame): joint i turns about z_(i-1) through o_(i-1) at the zero angles."""
    F = dh_frames(dh, np.zeros(len(dh)))
    joints = tuple(R(f"J{i + 1}", F[i][:3, 3], F[i][:3, 2], actuated=True) for i in range(len(dh)))
    return Mechanism(name, (Limb("arm", joints),), platform_point=F[-1][:3, 3])


def dh_pose(dh, theta):
    """The output link's pose at joint angles ``theta`` (the displacement from the zero angles)."""
    F0 = dh_frames(dh, np.zeros(len(dh)))[-1]
    return sm.Pose.from_displacement(dh_frames(dh, theta)[-1] @ np.linalg.inv(F0), F0[:3, 3])


def _wrapped(x):
    return np.angle(np.exp(1j * np.asarray(x)))


def _check_serial_solutions(dh, theta, sols):
    """Every solution reproduces the pose by the DH forward kinematics (an independent product)
    to 1e-9, and the solutions differ pairwise modulo 2 pi."""
    target = dh_frames(dh, theta)[-1]
    for q in sols:
        F = dh_frames(dh, q)[-1]
        assert np.max(np.abs(F[:3, :3] - target[:3, :3])) < 1e-9 and np.max(np.abs(F[:3, 3] - target[:3, 3])) < 1e-9
    for i in range(len(sols)):
        for j in range(i):
            assert np.max(np.abs(_wrapped(sols[i] - sols[j]))) > 1e-3


def test_puma560_has_its_eight_inverse_solutions():
    m = serial_arm("puma560", PUMA560_DH)
    theta = np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4])  # generic: no wrist, elbow or shoulder singularity
    res = sm.ik(m, dh_pose(PUMA560_DH, theta), all_solutions=True, n_seeds=200)
    assert res.result.reachable
    (limb,) = res.result.limbs
    sols = [np.asarray(q) for q in limb.solutions]
    # shoulder left / right x elbow up / down x wrist flipped or not (the flip: t4 + pi, -t5, t6 + pi,
    # every wrist axis on the same line as before, which the old axis-line signature merged)
    assert len(sols) == 8 and limb.passive_dim == 0
    _check_serial_solutions(PUMA560_DH, theta, sols)
    flip = theta + np.array([0, 0, 0, np.pi, 0, np.pi])
    flip[4] = -theta[4]
    assert any(np.max(np.abs(_wrapped(q - flip))) < 1e-8 for q in sols)


def test_general_6r_solutions_are_distinct_and_close():
    """A random 6R (not a published 16-real-solution example): every solution found closes and
    is distinct; the six found here are all the multi-start finds with 300 seeds."""
    rng = np.random.default_rng(0)
    dh = [(rng.uniform(-0.5, 0.5), rng.uniform(0.1, 0.6), rng.uniform(-np.pi, np.pi)) for _ in range(6)]
    theta = rng.uniform(-np.pi, np.pi, 6)
    inv = inverse_position(serial_arm("random-6r", dh), dh_pose(dh, theta), all_solutions=True, n_seeds=300)
    sols = list(inv.limbs[0].solutions)
    assert len(sols) == 6
    _check_serial_solutions(dh, theta, sols)


def agile_eye():
    """A spherical 3-RRR wrist of the Agile-Eye type (the ready-made ``agile-eye``): every axis
    through the origin, every link angle 90 degrees."""
    return sm.load_model("agile-eye")


def test_agile_eye_leg_has_two_working_modes():
    m = agile_eye()
    Rp = Rotation.from_rotvec([0.2, -0.3, 0.25]).as_matrix()
    inv = inverse_position(m, sm.Pose(Rp, [0, 0, 0]), all_solutions=True, n_seeds=48)
    assert inv.reachable
    for li, limb in enumerate(inv.limbs):
        # the middle axis is +-(u x w): one line, two working modes (the old signature kept one)
        assert len(limb.solutions) == 2 and limb.passive_dim == 0
        ch = solution_form(m, li).chain
        mids = []
        for q in limb.solutions:
            T, J = chain_forward(ch, np.asarray(q))
            assert np.allclose(T[:3, :3], Rp, atol=1e-9)
            mids.append(J[:3, 1])
        assert np.allclose(mids[0], -mids[1], atol=1e-8)


# ---------------------------------------------------------------- the rule itself
_E = np.eye(3)
_LIMB = Mechanism(
    "all-joints",
    (Limb("chain", (R("r", [0, 0, 0], _E[2]), U("u", [0.3, 0, 0], [_E[0], _E[1]]), P("p", [0.6, 0, 0], _E[0]),
                    S("s", [0.9, 0.1, 0]), C("c", [1.2, 0, 0.1], _E[1]), H("h", [1.5, 0, 0], _E[2], pitch=0.05),
                    Sm("sm", [1.8, 0.2, 0]))),),
    platform_point=[2.0, 0, 0],
)
_FORM = solution_form(_LIMB, 0)
_R_FREEDOMS = [0, 1, 2, 7]  # r.rot, u.rot1, u.rot2, c.rot
_S, _SM = slice(4, 7), slice(10, 13)
_N = len(_LIMB.freedom_refs)


def _same(q1, q2):
    return same_solution(_FORM, q1, solution_key(_FORM, q1), q2, solution_key(_FORM, q2), DEFAULT, 0)


_vals = st.lists(st.floats(-3.0, 3.0, allow_nan=False), min_size=_N, max_size=_N).map(np.array)


@settings(max_examples=60, deadline=None)
@given(_vals, st.sampled_from(_R_FREEDOMS), st.sampled_from([-1, 1]), st.integers(-2, 2))
def test_half_turns_are_never_merged_full_turns_and_redundant_parametrisations_are(q, i, sign, turns):
    assert _same(q, q.copy())
    # a half turn of any R freedom (of an R, U or C joint) is another configuration
    q2 = q.copy()
    q2[i] += sign * np.pi + 2 * np.pi * turns
    assert not _same(q, q2)
    # a whole number of turns of every angle is the same configuration
    q3 = q.copy()
    q3[_R_FREEDOMS] += 2 * np.pi * turns
    assert _same(q, q3)
    # an S joint's rotation vector theta * a and (theta - 2 pi) * a: one rotation
    phi = q[_S]
    th = np.linalg.norm(phi)
    if th > 1e-3:
        q4 = q.copy()
        q4[_S] = phi * (1 - 2 * np.pi / th)
        assert _same(q, q4)
        q5 = q.copy()
        q5[_S] = phi * (1 + np.pi / th)  # a half turn more about the same axis: not the same
        assert not _same(q, q5)
    # an Sm's three serial rotations (a1 + pi, pi - a2, a3 + pi): the same rotation
    q6 = q.copy()
    q6[_SM] = [q[10] + np.pi, np.pi - q[11], q[12] + np.pi]
    assert _same(q, q6)
    # a slide or a helical value differs by any amount: another configuration
    for k, d in ((3, 1e-3), (8, 1e-3), (9, 2 * np.pi)):
        q7 = q.copy()
        q7[k] += d
        assert not _same(q, q7)


@settings(max_examples=30, deadline=None)
@given(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0))
def test_a_u_joints_flipped_cross_is_another_configuration(t1, t2):
    """(t1 + pi, pi - t2) puts the U's second axis on the same line (the old signature merged
    it), but the joint's displacement differs by a half turn about the normal of its two axes:
    not a redundant parametrisation, so not merged."""
    q = np.zeros(_N)
    q[1:3] = t1, t2
    q2 = q.copy()
    q2[1:3] = t1 + np.pi, np.pi - t2
    assert not _same(q, q2)
    rot = Rotation.from_rotvec(_E[0] * t1) * Rotation.from_rotvec(_E[1] * t2)
    rot2 = Rotation.from_rotvec(_E[0] * (t1 + np.pi)) * Rotation.from_rotvec(_E[1] * (np.pi - t2))
    assert (rot.inv() * rot2).magnitude() == pytest.approx(np.pi)
    assert np.allclose(np.abs((rot.inv() * rot2).as_rotvec()) / np.pi, _E[2], atol=1e-9)
