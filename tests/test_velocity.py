"""Velocity and acceleration on the general engine, against finite differences of motions."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech import catalog
from spatialmech.geometry.rotations import euler_matrix, exp_twist, inverse_transform, log_transform
from spatialmech.kinematics.closure import Configuration, active_mask
from spatialmech.kinematics.backend import retract, correct
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.velocity import (
    euler_rate_matrix,
    forward_acceleration,
    forward_velocity,
    inverse_acceleration,
    inverse_velocity,
    point_acceleration,
    point_velocity,
)

STEWART = catalog.build("stewart-6sps")


def _ik_at(mech, config, D):
    res = correct(mech, Configuration(config.q, D), fix_platform=True)
    assert res.converged
    return res.config


def _legs(mech, q):
    ids = [r.id for r in mech.freedom_refs]
    return np.array([q[ids.index(a)] for a in mech.actuators])


@settings(max_examples=8, deadline=None)
@given(st.integers(0, 1000))
def test_stewart_inverse_velocity_and_acceleration_against_finite_differences(seed):
    rng = np.random.default_rng(seed)
    c0 = generic_configuration(STEWART, seed=seed, step=0.2)
    V, A = rng.normal(size=6) * 0.3, rng.normal(size=6) * 0.3
    h = 1e-4
    def D(t):
        return exp_twist(V * t + 0.5 * A * t * t, 1.0) @ c0.D  # a smooth platform path
    # the spatial twist and its derivative of this path at t = 0
    Vs = (log_transform(D(h) @ inverse_transform(D(0))) - log_transform(D(-h) @ inverse_transform(D(0)))) / (2 * h)
    qm, q0, qp = (_legs(STEWART, _ik_at(STEWART, c0, D(t)).q) for t in (-h, 0.0, h))
    qd, qdd = inverse_acceleration(STEWART, c0, Vs, A)
    assert np.allclose(_legs(STEWART, qd), (qp - qm) / (2 * h), atol=1e-6)
    assert np.allclose(_legs(STEWART, qdd), (qp - 2 * q0 + qm) / h**2, atol=2e-3)
    # forward velocity/acceleration invert the inverse ones
    V2, A2, _, _ = forward_acceleration(STEWART, c0, _legs(STEWART, qd), _legs(STEWART, qdd))
    assert np.allclose(V2, Vs, atol=1e-9) and np.allclose(A2, A, atol=1e-8)


def test_five_cs_forward_velocity_along_the_motion():
    m = catalog.build("five-cs-1")
    c0 = generic_configuration(m, seed=3)
    V, qd = forward_velocity(m, c0, [0.7], ["rot1"])
    # step along the motion by the predicted rates and check the platform moved as V says
    h = 1e-6
    step = np.r_[qd[active_mask(m)], V] * h
    c1 = correct(m, retract(m, c0, active_mask(m), step)).config
    Vfd = log_transform(c1.D @ inverse_transform(c0.D)) / h
    assert np.linalg.norm(Vfd - V) < 1e-4 * np.linalg.norm(V)


def test_incompatible_twist_is_an_error_naming_the_limb():
    m = catalog.build("four-sps-cu")
    c = generic_configuration(m, seed=1, step=0.4)
    with pytest.raises(ValueError, match="limb cu cannot produce it"):
        inverse_velocity(m, c, [0, 0, 0, 1.0, 0, 0])  # translation along x: the CU limb forbids it


def test_direct_singularity_is_reported():
    m = catalog.build("four-sps-cu")
    with pytest.raises(ValueError, match="direct singularity"):
        forward_velocity(m, Configuration.reference(m), [0.1, 0.1, 0.1, 0.1])


def test_point_velocity_and_acceleration_of_a_rotation():
    V = np.array([0, 0, 2.0, 0, 0, 0])
    assert np.allclose(point_velocity(V, [1, 0, 0]), [0, 2, 0])
    assert np.allclose(point_acceleration(V, np.zeros(6), [1, 0, 0]), [-4, 0, 0])  # centripetal


@pytest.mark.parametrize("seq", ["ZXY", "ZYX", "YXZ", "zxy", "xyz"])
def test_euler_rate_matrix_against_finite_differences(seq):
    a = np.array([0.3, -0.4, 0.7])
    rates = np.array([0.2, -0.5, 0.9])
    h = 1e-6
    R0 = euler_matrix(seq, a)
    Rd = (euler_matrix(seq, a + h * rates) - euler_matrix(seq, a - h * rates)) / (2 * h)
    W = Rd @ R0.T
    w = np.array([W[2, 1], W[0, 2], W[1, 0]])
    assert np.allclose(euler_rate_matrix(seq, a) @ rates, w, atol=1e-8)
