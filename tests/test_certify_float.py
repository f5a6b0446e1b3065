"""The floating-point first pass of the certificates (kinematics/homotopy/certify_float.py):
its interval arithmetic encloses the exact results (rational arithmetic), and it never grants a
certificate the ball test would refuse (points moved, double roots, twins, close roots)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech.kinematics.homotopy import certify as C
from spatialmech.kinematics.homotopy import inverse as ikh
from spatialmech.kinematics.homotopy.certify_float import MR, from_balls

from .test_ik_distinct import PUMA560_DH, dh_pose, serial_arm

FLOATS = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)
RADII = st.floats(0.0, 1e-3, allow_nan=False)


def _inside(x: Fraction, m: float, r: float) -> bool:
    return abs(x - Fraction(m)) <= Fraction(r)


@settings(max_examples=60, deadline=None)
@given(a=FLOATS, b=FLOATS, ra=RADII, rb=RADII, ta=st.floats(-1, 1), tb=st.floats(-1, 1))
def test_interval_operations_enclose_the_exact_results(a, b, ra, rb, ta, tb):
    """For members ``x = a + ta ra`` and ``y = b + tb rb`` (exact rationals), ``x + y``, ``x - y``
    and ``x y`` lie in the computed intervals."""
    x = Fraction(a) + Fraction(ta) * Fraction(ra)
    y = Fraction(b) + Fraction(tb) * Fraction(rb)
    X, Y = MR(np.array([a]), np.array([ra])), MR(np.array([b]), np.array([rb]))
    for Z, exact in ((X + Y, x + y), (X - Y, x - y), (X * Y, x * y), (1.0 - X, 1 - x)):
        assert _inside(exact, float(Z.m[0]), float(Z.r[0]))


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), exact_left=st.booleans())
def test_matrix_products_enclose_the_exact_product(seed, exact_left):
    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(3, 4)) * 10 ** rng.uniform(-3, 3), rng.normal(size=(4, 2))
    Ra, Rb = np.abs(rng.normal(size=A.shape)) * 1e-9, np.abs(rng.normal(size=B.shape)) * 1e-9
    if exact_left:
        Ra[:] = 0.0
    Ta, Tb = rng.uniform(-1, 1, A.shape), rng.uniform(-1, 1, B.shape)
    P = (A @ MR(B, Rb)) if exact_left else (MR(A, Ra) @ MR(B, Rb))
    for i in range(3):
        for j in range(2):
            exact = sum((Fraction(A[i, k]) + Fraction(Ta[i, k]) * Fraction(Ra[i, k]))
                        * (Fraction(B[k, j]) + Fraction(Tb[k, j]) * Fraction(Rb[k, j])) for k in range(4))
            assert _inside(exact, float(P.m[i, j]), float(P.r[i, j]))


def test_balls_convert_outward():
    from flint import arb, arb_mat, ctx

    old = ctx.prec
    ctx.prec = 53
    try:
        F = arb_mat([[arb(1) / 3], [arb(2).sqrt()]])
        row = from_balls(F)
    finally:
        ctx.prec = old
    ctx.prec = 200
    try:
        for v, m, r in zip((arb(1) / 3, arb(2).sqrt()), row.m[0], row.r[0], strict=True):
            assert abs(v - arb(float(m))) < arb(float(r))
    finally:
        ctx.prec = old


def _puma_system():
    m = serial_arm("puma560", PUMA560_DH)
    theta = np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4])
    D = dh_pose(PUMA560_DH, theta).displacement(m.platform_point)
    sysm = ikh.limb_ik_system(m, 0)
    P = sysm.pose_parameters(np.asarray(D, float)).real
    import spatialmech as sm

    qs = [np.asarray(q) for q in sm.ik(m, dh_pose(PUMA560_DH, theta), all_solutions=True, certify=False)
          .result.limbs[0].solutions]
    return sysm, P, np.array([C.limb_point(sysm, q) for q in qs])


def test_limb_float_pass_grants_the_ball_tests_boxes_and_refuses_bad_points():
    """PUMA 560: the float pass certifies the 8 solutions in the boxes the ball test gives; a
    point moved by 1e-6, a pose coefficient changed by 1e-9 and a singular point are refused by
    it (and by the ball test), and two copies 1e-14 apart are not both certified."""
    from flint import ctx

    sysm, P, Y = _puma_system()
    system = C.limb_system(sysm, P[:4], P[4:7])
    ctx.prec, old = 53, ctx.prec
    try:
        fast = system.krawczyk_float(Y, C.CERTIFY_MAX_RADIUS)
        ball = [C._one(system, y.astype(complex), C.CERTIFY_MAX_RADIUS)[0] for y in Y]
        assert all(r is not None for r in fast) and fast == ball
        moved = Y[0].copy()
        moved[2] += 1e-6
        assert system.krawczyk_float(moved[None], C.CERTIFY_MAX_RADIUS) == [None]
        other = C.limb_system(sysm, P[:4], P[4:7] + 1e-9)  # its root moves by about 1e-9
        wide = other.krawczyk_float(Y[:1], C.CERTIFY_MAX_RADIUS)[0]
        assert wide is not None and wide > 1e-9  # the box must reach the moved root
        assert other.krawczyk_float(Y[:1], 1e-11) == [None]
        singular = np.zeros_like(Y[0])  # every (c, s) = (0, 0): the circles' Jacobian vanishes
        assert system.krawczyk_float(singular[None], C.CERTIFY_MAX_RADIUS) == [None]
    finally:
        ctx.prec = old
    certs = C.certify(system, np.vstack([Y[:1], Y[:1] + 1e-14]), real=[True, True])
    assert not (certs[0].certified and certs[1].certified)
    assert not C.certify(system, moved[None], real=[True])[0].certified


def test_quadric_float_pass_refuses_a_double_root_and_close_roots():
    """``x0^2 - a x1^2``, ``x1 = 1``: the double root (a = 0) and a point between two roots 2e-6
    apart are refused by the float pass; a simple root is granted in the ball test's box."""
    def system(a):
        Q = np.zeros((1, 2, 2))
        Q[0, 0, 0], Q[0, 1, 1] = 1.0, -a
        return C.quadric_system(Q, np.eye(2)[1:], np.ones(1))

    assert system(0.0).krawczyk_float(np.array([[1e-9, 1.0]]), C.CERTIFY_MAX_RADIUS) == [None]
    assert system(0.0).krawczyk_float(np.array([[0.0, 1.0]]), C.CERTIFY_MAX_RADIUS) == [None]
    assert system(1e-12).krawczyk_float(np.array([[1.1e-6, 1.0]]), C.CERTIFY_MAX_RADIUS) == [None]
    y = np.array([[np.sqrt(2.0), 1.0]])
    r = system(2.0).krawczyk_float(y, C.CERTIFY_MAX_RADIUS)[0]
    assert r is not None and r < 1e-11
    assert system(2.0 + 1e-11).krawczyk_float(y, 1e-12) == [None]  # the moved root is outside every box tried


def test_float_pass_grants_the_ball_tests_boxes_at_ill_conditioned_points():
    """PUMA 560 near a wrist singularity (theta5 = -3.11 rad): two of its 8 solutions fail the
    first box (the rounding of F(y) times |A| fills it) and pass one radius up, in the float pass
    (which tries the ball test's wider radii) as in the ball test; every box equals the ball
    test's."""
    import spatialmech as sm
    from flint import ctx

    from spatialmech.kinematics.homotopy.certify_balls import pow2_up

    m = serial_arm("puma560", PUMA560_DH)
    theta = np.array([-2.58, -0.22, -1.29, 0.37, -3.11, 3.11])
    sysm = ikh.limb_ik_system(m, 0)
    P = sysm.pose_parameters(np.asarray(dh_pose(PUMA560_DH, theta).displacement(m.platform_point), float)).real
    qs = sm.ik(m, dh_pose(PUMA560_DH, theta), all_solutions=True, certify=False).result.limbs[0].solutions
    Y = np.array([C.limb_point(sysm, np.asarray(q)) for q in qs])
    system = C.limb_system(sysm, P[:4], P[4:7])
    ctx.prec, old = 53, ctx.prec
    try:
        fast = system.krawczyk_float(Y, C.CERTIFY_MAX_RADIUS)
        pre = system.jacobian_float_many(Y.astype(complex))
        ball = [C._one(system, y.astype(complex), C.CERTIFY_MAX_RADIUS, np.linalg.inv(J))[0]
                for y, J in zip(Y, pre, strict=True)]
    finally:
        ctx.prec = old
    assert len(Y) == 8 and all(r is not None for r in fast) and fast == ball
    assert sum(r != pow2_up(r) for r in fast) == 2  # past the first radius (a power of two)
