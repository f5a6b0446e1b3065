"""The closure engine: POE Jacobians against finite differences, Newton onto the manifold."""

import numpy as np
import pytest

from spatialmech import catalog
from spatialmech.geometry.rotations import exp_twist, inverse_transform, log_transform
from spatialmech.kinematics.closure import Configuration, limb_forward, limb_slices, reference_screws
from spatialmech.kinematics.backend import closure_residual, correct
from spatialmech.kinematics.motion import generic_configuration


@pytest.mark.parametrize("name", ["stewart-6sps", "five-cs-1", "bennett", "three-upu"])
def test_spatial_jacobian_matches_finite_differences(name, rng):
    mech = catalog.build(name)
    S = reference_screws(mech)
    for sl in limb_slices(mech):
        q = rng.uniform(-0.5, 0.5, sl.stop - sl.start)
        T, J = limb_forward(S[sl], q)
        h = 1e-6
        for i in range(len(q)):
            dq = np.zeros_like(q)
            dq[i] = h
            Tp, _ = limb_forward(S[sl], q + dq)
            Tm, _ = limb_forward(S[sl], q - dq)
            # spatial twist: dT T^-1
            V = (log_transform(Tp @ inverse_transform(T)) - log_transform(Tm @ inverse_transform(T))) / (2 * h)
            assert np.allclose(V, J[:, i], atol=1e-6)


def test_reference_configuration_is_closed():
    for name in catalog.names():
        mech = catalog.build(name)
        assert np.allclose(closure_residual(mech, Configuration.reference(mech)), 0, atol=1e-12), name


@pytest.mark.parametrize("name", ["four-sps-cu", "five-cs-2", "rssr", "planar-4r", "three-rrr-sm"])
def test_generic_configuration_is_on_the_manifold_and_away_from_reference(name):
    mech = catalog.build(name)
    if mech.is_metamorphic:
        mech = mech.in_mode(mech.all_modes()[-1])
    c = generic_configuration(mech, seed=3)
    assert np.linalg.norm(closure_residual(mech, c)) < 1e-10 * max(1.0, mech.characteristic_length)
    assert np.linalg.norm(c.q) > 1e-3


def test_newton_correction_converges_quadratically_from_a_perturbation():
    mech = catalog.build("stewart-6sps")
    c0 = generic_configuration(mech, seed=1)
    bumped = Configuration(c0.q + 0.01, exp_twist(np.array([0, 0, 1, 0.01, 0, 0]), 0.01) @ c0.D)
    res = correct(mech, bumped)
    assert res.converged and res.iterations <= 6
    assert res.residual < 1e-12


def test_newton_reports_non_convergence_instead_of_raising():
    mech = catalog.build("planar-4r")
    # with every joint held, a crank angle that the rocker cannot follow has no closure
    q = np.zeros(len(mech.freedom_refs))
    q[0] = 0.3
    res = correct(mech, Configuration(q, np.eye(4)), active=np.zeros(len(q), bool), max_iter=20)
    assert not res.converged and res.residual > 1e-3


def test_inverse_position_with_the_platform_held():
    mech = catalog.build("stewart-6sps")
    target = generic_configuration(mech, seed=5)
    res = correct(mech, Configuration(np.zeros(len(target.q)), target.D), fix_platform=True)
    assert res.converged
    assert np.allclose(res.config.D, target.D)
    # leg lengths (slides) agree with the target's
    from spatialmech.kinematics.closure import joint_points
    pa = joint_points(mech, res.config)
    pb = joint_points(mech, target)
    for a, b in zip(pa, pb, strict=True):
        assert np.allclose(a, b, atol=1e-9)


def test_joint_points_follow_the_platform():
    mech = catalog.build("four-sps-cu")
    c = generic_configuration(mech, seed=2)
    from spatialmech.kinematics.closure import joint_points
    pts = joint_points(mech, c)
    # each leg's last joint (S on the platform) is the displaced reference point
    for limb, p in zip(mech.limbs[:4], pts[:4], strict=True):
        A0 = limb.joints[-1].point
        assert np.allclose(p[-1], c.D[:3, :3] @ A0 + c.D[:3, 3], atol=1e-10)
        assert np.allclose(p[0], limb.joints[0].point)  # base joints stay put


@pytest.mark.parametrize("name", ["stewart-6sps", "five-cs-3", "rssr"])
def test_chain_jacobian_with_ball_joints_matches_finite_differences(name, rng):
    from spatialmech.kinematics.closure import chain_forward, limb_chains
    mech = catalog.build(name)
    for ch in limb_chains(mech):
        q = rng.uniform(-1.2, 1.2, len(ch.screws))
        T, J = chain_forward(ch, q)
        h = 1e-6
        for i in range(len(q)):
            dq = np.zeros_like(q)
            dq[i] = h
            Tp, _ = chain_forward(ch, q + dq)
            Tm, _ = chain_forward(ch, q - dq)
            V = (log_transform(Tp @ inverse_transform(T)) - log_transform(Tm @ inverse_transform(T))) / (2 * h)
            assert np.allclose(V, J[:, i], atol=1e-6)


def test_ball_joint_has_no_gimbal_lock_at_ninety_degrees():
    from spatialmech.geometry.screws import rank
    from spatialmech.kinematics.closure import chain_forward, limb_chains, recentre_balls
    mech = catalog.build("rssr")
    ch = limb_chains(mech)[0]  # R, S, S
    q = np.zeros(len(ch.screws))
    q[2] = np.pi / 2  # S about its y axis by 90 degrees
    _, J = chain_forward(ch, q)
    assert rank(J[:, 1:4].T) == 3
    # re-centring a rotation vector beyond pi keeps the displacement
    q2 = np.zeros(len(mech.freedom_refs))
    q2[1:4] = [2.5, -2.0, 1.0]
    q3 = recentre_balls(mech, q2)
    assert np.linalg.norm(q3[1:4]) < np.pi
    assert np.allclose(chain_forward(ch, q2[:7])[0], chain_forward(ch, q3[:7])[0])


@pytest.mark.parametrize("size", [1e-13, 5e-13, 1e-9])
def test_tiny_ball_rotations_and_logs_are_first_order_exact(size, rng):
    """A ball joint's rotation below 1e-12 rad still moves the chain (it was dropped: Newton then
    stalled on a 1.5e-12 residual, the spatial six-bar at a 6e-11 deg crank), and the log of a
    displacement that small keeps its rotation and the first-order term of its translation:
    ``T(q + dq) T(q)^-1`` is ``exp(J dq)`` and its log is ``J dq`` to second order."""
    from spatialmech.kinematics.closure import _log_single, chain_forward, limb_chains

    ch = limb_chains(catalog.build("rssr"))[0]  # R, S, S
    for q in (np.zeros(len(ch.screws)), rng.uniform(-1.0, 1.0, len(ch.screws))):
        T, J = chain_forward(ch, q, local=False)
        dq = rng.normal(size=len(q)) * size
        dT = chain_forward(ch, q + dq)[0] @ inverse_transform(T)
        for V in (log_transform(dT), _log_single(dT)):
            assert np.allclose(V, J @ dq, rtol=0, atol=2e-15 + 1e-6 * size)  # 2e-15: round-off of T (L = 1)
