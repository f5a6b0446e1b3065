"""Screw algebra: invariants as property tests, worked examples, validation."""

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from spatialmech.geometry import screws as sc
from spatialmech.geometry.rotations import exp_twist, inverse_transform, log_transform

from .conftest import random_transform, screw6, seeds


@given(screw6, screw6)
def test_reciprocal_product_is_symmetric(a, b):
    assert sc.reciprocal_product(a, b) == pytest.approx(sc.reciprocal_product(b, a), abs=1e-9)
    assert sc.reciprocal_product(a, b) == pytest.approx(a @ sc.DELTA @ b, abs=1e-9)


@given(screw6, screw6, seeds)
def test_reciprocal_product_invariant_under_rigid_displacement(a, b, seed):
    T = random_transform(seed)
    ta, tb = sc.transform_screws(T, a), sc.transform_screws(T, b)
    scale = 1 + np.abs(a).sum() * np.abs(b).sum() * 10
    assert sc.reciprocal_product(ta, tb) == pytest.approx(sc.reciprocal_product(a, b), abs=1e-9 * scale)


@given(seeds, st.integers(1, 6))
def test_reciprocal_basis_is_reciprocal_and_complementary(seed, m):
    rng = np.random.default_rng(seed)
    # m screws of random rank r <= m: combinations of r random lines
    r = int(rng.integers(1, m + 1))
    dirs, pts = rng.normal(size=(r, 3)), rng.normal(size=(r, 3)) * 3
    lines = np.array([sc.axis_screw(d / np.linalg.norm(d), p) for d, p in zip(dirs, pts, strict=True)])
    S = rng.normal(size=(m, r)) @ lines
    W = sc.reciprocal_basis(S, length_scale=3.0)
    assert W.shape == (6 - sc.rank(S, length_scale=3.0), 6)
    assert sc.rank(S, length_scale=3.0) == np.linalg.matrix_rank(S @ sc.DELTA, tol=1e-8)
    assert np.allclose(sc.reciprocal_product(S[:, None, :], W[None, :, :]), 0, atol=1e-9)
    assert sc.rank(np.vstack([W]), length_scale=3.0) == W.shape[0]


def test_reciprocal_basis_scale_aware():
    # the same geometry in millimetres and in metres has the same constraint system size
    rng = np.random.default_rng(1)
    d = rng.normal(size=(5, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    p = rng.normal(size=(5, 3))
    S_m = np.array([sc.axis_screw(di, pi) for di, pi in zip(d, p, strict=True)])
    S_mm = np.array([sc.axis_screw(di, 1000 * pi) for di, pi in zip(d, p, strict=True)])
    assert sc.rank(S_m, length_scale=1.0) == 5
    assert sc.rank(S_mm, length_scale=1000.0) == 5
    assert sc.reciprocal_basis(S_mm, length_scale=1000.0).shape == (1, 6)


@given(seeds)
def test_cofactor_reciprocal_matches_null_space(seed):
    rng = np.random.default_rng(seed)
    S = rng.normal(size=(5, 6))
    x = sc.cofactor_reciprocal(S)
    assert np.allclose(sc.reciprocal_product(S, x), 0, atol=1e-9 * np.abs(x).max())
    W = sc.reciprocal_basis(S)
    assert abs(abs(x @ W[0]) - np.linalg.norm(x) * np.linalg.norm(W[0])) < 1e-8 * np.linalg.norm(x)


def test_cofactor_reciprocal_is_sign_continuous_along_a_path():
    rng = np.random.default_rng(7)
    S0, S1 = rng.normal(size=(2, 5, 6))
    ts = np.linspace(0, 1, 201)
    xs = sc.cofactor_reciprocal(S0[None] * (1 - ts[:, None, None]) + S1[None] * ts[:, None, None])
    # consecutive values differ by a small step: no sign flips as with SVD null vectors
    steps = np.linalg.norm(np.diff(xs, axis=0), axis=1)
    assert steps.max() < 0.1 * np.linalg.norm(xs, axis=1).max()


def test_cofactor_reciprocal_vanishes_for_dependent_screws():
    rng = np.random.default_rng(3)
    S = rng.normal(size=(5, 6))
    S[4] = S[0] + 2 * S[1]
    assert np.allclose(sc.cofactor_reciprocal(S), 0, atol=1e-10)


def test_axis_screw_worked_example():
    t = sc.axis_screw([0, 0, 1], [1, 0, 0])
    assert np.allclose(t, [0, 0, 1, 0, -1, 0])
    assert sc.reciprocal_product(t, sc.axis_screw([0, 0, 1], [0, 0, 0])) == 0
    # a force along x through the origin does work +1 on a unit rotation about z through (0,1,0),
    # whose twist moves the origin with velocity (1, 0, 0)
    assert sc.reciprocal_product(sc.axis_screw([1, 0, 0], [0, 0, 0]), sc.axis_screw([0, 0, 1], [0, 1, 0])) == pytest.approx(1)


def test_pitch_and_translation():
    assert sc.pitch(sc.axis_screw([0, 1, 0], [3, 1, 2], pitch=0.25)) == pytest.approx(0.25)
    assert np.isinf(sc.pitch(sc.translation_screw([1, 0, 0])))


@pytest.mark.parametrize(
    "direction, msg",
    [([0, 0, 0], "zero vector"), ([1, 1, 0], "not a unit vector"), ([np.nan, 0, 1], "NaN"), ([1, 0], "shape")],
)
def test_bad_axes_are_rejected_with_the_field_name(direction, msg):
    with pytest.raises(ValueError, match=msg) as e:
        sc.axis_screw(direction, [0, 0, 0])
    assert str(e.value).startswith("direction")


def test_plucker_line_validation():
    L = sc.plucker_line([0, 0, 1], [1, 2, 3])
    assert np.allclose(sc.validate_line(L), L)
    assert np.allclose(sc.line_point(L), [1, 2, 0])
    with pytest.raises(ValueError, match="orthogonal"):
        sc.validate_line([0, 0, 1, 0, 0, 1], name="leg")
    with pytest.raises(ValueError, match="leg: direction part is not a unit"):
        sc.validate_line([0, 0, 2, 0, 0, 0], name="leg")


@given(screw6, st.floats(-3, 3), seeds)
def test_exp_log_round_trip_and_adjoint(s, theta, seed):
    n = np.linalg.norm(s[:3])
    assume(n >= 1e-3)
    s = s / n
    T = exp_twist(s, theta)
    xi = log_transform(T)
    assert np.allclose(exp_twist(xi, 1.0), T, atol=1e-9)
    # adjoint: displacing a screw then the displacement equals conjugation
    G = random_transform(seed)
    lhs = exp_twist(sc.transform_screws(G, s), theta)
    rhs = G @ T @ inverse_transform(G)
    assert np.allclose(lhs, rhs, atol=1e-8)


def test_intersection_and_contains():
    X, Y, Z = np.eye(3)
    A = np.array([sc.axis_screw(X, [0, 0, 0]), sc.axis_screw(Y, [0, 0, 0])])
    B = np.array([sc.axis_screw(Y, [0, 0, 0]), sc.axis_screw(Z, [0, 0, 0])])
    I = sc.intersection(A, B)
    assert I.shape[0] == 1 and sc.contains(I, sc.axis_screw(Y, [0, 0, 0]))
    assert not sc.contains(A, sc.axis_screw(Z, [0, 0, 0]))


def test_bad_screw_arrays():
    with pytest.raises(ValueError, match=r"screws: expected shape \(m, 6\)"):
        sc.rank(np.zeros((2, 5)))
    with pytest.raises(ValueError, match="NaN"):
        sc.reciprocal_basis(np.full((1, 6), np.nan))
    with pytest.raises(ValueError, match=r"\(\.\.\., 5, 6\)"):
        sc.cofactor_reciprocal(np.zeros((4, 6)))
