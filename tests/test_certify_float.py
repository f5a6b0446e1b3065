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


# ------------------------------------------------------------------ the compiled float pass (compiled/certify.py)
def _limb_points(m, dh, theta):
    """The limb system, its pose parameters and the real solutions' points of the arm ``m`` at
    the joint angles ``theta``."""
    import spatialmech as sm

    sysm = ikh.limb_ik_system(m, 0)
    P = sysm.pose_parameters(np.asarray(dh_pose(dh, theta).displacement(m.platform_point), float)).real
    qs = sm.ik(m, dh_pose(dh, theta), all_solutions=True, certify=False).result.limbs[0].solutions
    return C.limb_system(sysm, P[:4], P[4:7]), np.array([C.limb_point(sysm, np.asarray(q)) for q in qs])


def _three_ways(system, Y, ball=True):
    """The float pass compiled, the float pass on the Python reference, and the ball test's box
    of each point (53 bits, the preconditioners of ``certify``)."""
    from flint import ctx

    from spatialmech.kinematics import backend
    from spatialmech.kinematics.compiled import kernels_certify

    ctx.prec, old = 53, ctx.prec
    try:
        fast = system.krawczyk_float(Y, C.CERTIFY_MAX_RADIUS)
        assert kernels_certify.nb_krawczyk.signatures or not backend.enabled()  # the compiled path ran
        with backend.python_reference():
            ref = system.krawczyk_float(Y, C.CERTIFY_MAX_RADIUS)
        pre = system.jacobian_float_many(Y.astype(complex)) if ball else []
        balls = [C._one(system, y.astype(complex), C.CERTIFY_MAX_RADIUS, np.linalg.inv(J))[0]
                 for y, J in zip(Y[: len(pre)], pre, strict=True)]
    finally:
        ctx.prec = old
    return fast, ref, balls


def test_compiled_float_pass_equals_the_reference_and_the_ball_test_on_the_puma():
    """PUMA 560 at 15 random poses, 120 solutions: the compiled float pass grants every one the
    box the Python float pass grants and the ball test gives (the ill-conditioned wrist
    solutions one radius up included)."""
    m = serial_arm("puma560", PUMA560_DH)
    rng = np.random.default_rng(5)
    n = 0
    for _ in range(15):
        system, Y = _limb_points(m, PUMA560_DH, rng.uniform(-np.pi, np.pi, 6))
        fast, ref, ball = _three_ways(system, Y)
        assert all(r is not None for r in fast) and fast == ref == ball
        n += len(Y)
    assert n == 120


def test_compiled_float_pass_equals_the_reference_on_a_limb_with_an_s_joint():
    """An R-R-P-S leg (a limb system of the ``point`` kind: the S joint's centre), its 4
    solutions at two poses: the compiled float pass grants the reference's and the ball test's
    boxes."""
    import spatialmech as sm
    from spatialmech.model.joints import P, R, S
    from spatialmech.model.mechanism import Limb, Mechanism, Pose

    def unit(v):
        return list(np.asarray(v, dtype=float) / np.linalg.norm(v))

    mech = Mechanism("rrps", (Limb("leg", (R("A", [0, 0, 0], [0, 0, 1.0]), R("B", [0.1, 0.05, 0.2], unit([1, 0.2, 0])),
                                            P("C", [0.1, 0.05, 0.2], unit([0.1, 1, 0.3])), S("D", [0.15, 0.6, 0.35]))),),
                     platform_point=np.array([0.15, 0.6, 0.35]))
    sysm = ikh.limb_ik_system(mech, 0)
    assert sysm.kind == "point" and sysm.rigid
    rng = np.random.default_rng(1)
    for _ in range(2):
        D = np.eye(4)
        D[:3, 3] = 0.1 * rng.normal(size=3)
        qs = sm.ik(mech, Pose.from_displacement(D, mech.platform_point), all_solutions=True,
                   certify=False).result.limbs[0].solutions
        P0 = sysm.pose_parameters(D).real
        Y = np.array([C.limb_point(sysm, np.asarray(q)) for q in qs])
        fast, ref, ball = _three_ways(C.limb_system(sysm, P0[:4], P0[4:7]), Y)
        assert len(Y) == 4 and None not in fast and fast == ref == ball


def test_compiled_float_pass_refuses_moved_points_and_near_singular_roots():
    """A PUMA 560 solution moved by 1e-3 (and by 1e-6), and the two wrist solutions near the
    wrist singularity (theta5 = +-1e-6: each near a continuum of solutions): not granted,
    compiled or not (the ball test decides them)."""
    m = serial_arm("puma560", PUMA560_DH)
    system, Y = _limb_points(m, PUMA560_DH, np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4]))
    moved = np.repeat(Y[:1], 2, axis=0)
    moved[0, 2] += 1e-3
    moved[1, 4] += 1e-6
    fast, ref, _ = _three_ways(system, moved, ball=False)
    assert fast == ref == [None, None]
    theta = np.array([0.3, -0.7, 0.5, 0.9, 1e-6, -0.4])
    system, _ = _limb_points(m, PUMA560_DH, theta)
    sysm = ikh.limb_ik_system(m, 0)
    flip = theta + np.array([0, 0, 0, np.pi, -2e-6, np.pi])  # the other wrist solution
    Y = np.array([C.limb_point(sysm, q) for q in (theta, flip)])
    assert np.max(np.abs(C._mid(system.values(C.REAL.col(Y[1]))))) < 1e-14  # a root too
    fast, ref, _ = _three_ways(system, Y, ball=False)
    assert fast == ref == [None, None]


def test_compiled_test_refuses_a_near_double_root():
    """``x0^2 - a x1^2``, ``x1 = 1`` with ``a = 1e-12`` (roots 2e-6 apart): a point off a root by
    1e-7 and the point between the two roots are refused by the compiled test as by the
    reference; a root (1e-6, 1) itself, and the simple root of ``a = 2``, are granted the same
    boxes."""
    from spatialmech.kinematics import backend

    def system(a):
        Q = np.zeros((1, 2, 2))
        Q[0, 0, 0], Q[0, 1, 1] = 1.0, -a
        return C.quadric_system(Q, np.eye(2)[1:], np.ones(1))

    near, simple = np.array([[1.1e-6, 1.0], [0.0, 1.0], [1e-6, 1.0]]), np.array([[np.sqrt(2.0), 1.0]])
    fast = system(1e-12).krawczyk_float(near, C.CERTIFY_MAX_RADIUS) + system(2.0).krawczyk_float(simple, 1e-8)
    with backend.python_reference():
        ref = system(1e-12).krawczyk_float(near, C.CERTIFY_MAX_RADIUS) + system(2.0).krawczyk_float(simple, 1e-8)
    assert fast == ref and fast[:2] == [None] * 2 and None not in fast[2:]


def test_compiled_kernels_round_every_operation_once():
    """The rounding bound of the compiled arithmetic assumes no fused multiply-add and no
    reordering (kernels_certify.py): every kernel is compiled as ``@njit(cache=True)``, without
    ``fastmath``, and a kernel compiled so computes ``a b + c`` in two roundings, with no
    fused multiply-add in its machine code."""
    import inspect
    import re

    import pytest

    from spatialmech.kinematics.compiled import jit, kernels_certify

    if not jit.AVAILABLE:
        pytest.skip("numba cannot be imported: no kernel is compiled")
    source = inspect.getsource(kernels_certify)
    assert "fastmath" not in source.replace("without ``fastmath``", "").replace("``fastmath``", "")
    decorators = re.findall(r"^@.*$", source, flags=re.M)
    assert decorators and set(decorators) == {"@njit(cache=True)"}

    def probe(a, b, c, out):
        for i in range(a.shape[0]):
            out[i] = a[i] * b[i] + c[i]

    kernel = jit.njit(probe)
    a, b, c, out = np.array([1 + 2.0**-30]), np.array([1 - 2.0**-30]), np.array([-1.0]), np.zeros(1)
    kernel(a, b, c, out)
    assert out[0] == 0.0  # fl(fl(a b) + c); a fused a b + c is -2^-60
    asm = kernel.inspect_asm(kernel.signatures[0])
    assert "mulsd" in asm and not re.search(r"\bv?fn?m(add|sub)\d*[sp]d\b", asm)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_compiled_interval_kernels_enclose_the_exact_results(seed):
    """The compiled interval operations (kernels_certify.py: a product and a transposed product
    of 4x4 interval matrices, a matrix-vector product, a product and a sum of intervals, and the
    pose's rotation ``E(q)``, ``q.q`` and ``(q.q) t``) hold the exact results of members of their
    operands (rational arithmetic)."""
    from spatialmech.kinematics.compiled import kernels_certify as K
    from spatialmech.kinematics.homotopy import certify_float as CF

    rng = np.random.default_rng(seed)
    A, B = rng.normal(size=(4, 4)) * 10 ** rng.uniform(-3, 3), rng.normal(size=(4, 4)) * 10 ** rng.uniform(-3, 3)
    Ra, Rb = np.abs(rng.normal(size=(4, 4))) * 1e-9, np.abs(rng.normal(size=(4, 4))) * 1e-12
    Ta, Tb = rng.uniform(-1, 1, (4, 4)), rng.uniform(-1, 1, (4, 4))
    xa = [[Fraction(A[i, j]) + Fraction(Ta[i, j]) * Fraction(Ra[i, j]) for j in range(4)] for i in range(4)]
    xb = [[Fraction(B[i, j]) + Fraction(Tb[i, j]) * Fraction(Rb[i, j]) for j in range(4)] for i in range(4)]
    for transpose in (False, True):
        Cm, Cr = np.empty((4, 4)), np.empty((4, 4))
        K.nb_imatmul(A.T if transpose else A, Ra.T if transpose else Ra, B, Rb, Cm, Cr)  # A^T B on views, as the kernels
        for i in range(4):
            for j in range(4):
                exact = sum((xa[k][i] if transpose else xa[i][k]) * xb[k][j] for k in range(4))
                assert _inside(exact, float(Cm[i, j]), float(Cr[i, j]))
    vm, vr = np.empty(4), np.empty(4)
    K.nb_imatvec(A, Ra, B[:, 0].copy(), Rb[:, 0].copy(), vm, vr)
    assert all(_inside(sum(xa[i][k] * xb[k][0] for k in range(4)), float(vm[i]), float(vr[i])) for i in range(4))
    a, b = xa[0][0], xb[1][2]
    for (m, r), exact in ((K.nb_imul(A[0, 0], Ra[0, 0], B[1, 2], Rb[1, 2]), a * b),
                          (K.nb_iadd(A[0, 0], Ra[0, 0], B[1, 2], Rb[1, 2]), a + b)):
        assert _inside(exact, m, r)
    # the pose's data: E(q) (the unnormalised rotation), q.q and (q.q) t from floats q, t
    q, t = rng.normal(size=4), rng.normal(size=3)
    E, sq, stv = np.empty((4, 4, 2)), np.empty(2), np.empty((3, 2))
    K.nb_pose(q, t, CF.rotation_coefficients(), E, sq, stv)
    w, i, j, k = (Fraction(v) for v in q)
    n2 = w * w + i * i + j * j + k * k
    R = [[w * w + i * i - j * j - k * k, 2 * (i * j - w * k), 2 * (i * k + w * j)],
         [2 * (i * j + w * k), w * w - i * i + j * j - k * k, 2 * (j * k - w * i)],
         [2 * (i * k - w * j), 2 * (j * k + w * i), w * w - i * i - j * j + k * k]]
    assert all(_inside(R[a][c], float(E[a, c, 0]), float(E[a, c, 1])) for a in range(3) for c in range(3))
    assert _inside(n2, float(sq[0]), float(sq[1]))
    assert all(_inside(n2 * Fraction(t[a]), float(stv[a, 0]), float(stv[a, 1])) for a in range(3))


def test_compiled_limb_enclosures_hold_the_exact_values():
    """PUMA 560: the compiled enclosure of the values at each solution holds the values computed
    in 200-bit balls, and that of the Jacobian over the largest box holds the Jacobian at the
    box's corners and centre (200-bit balls); its midpoints are the float Jacobian at the points."""
    from flint import ctx

    from spatialmech.kinematics.compiled import certify as KC
    from spatialmech.kinematics.compiled import kernels_certify as K
    from spatialmech.kinematics.homotopy import certify_float as CF
    from spatialmech.kinematics.homotopy.certify_balls import REAL

    sysm, P, Y = _puma_system()
    k, n = Y.shape
    rbox = CF.box_radii(Y, C.CERTIFY_MAX_RADIUS)
    Fm, Fr, Jm, Jr = np.empty((k, n)), np.empty((k, n)), np.empty((k, n, n)), np.empty((k, n, n))
    K.nb_limb_enclosures(Y, rbox, P[:4].copy(), P[4:7].copy(), *KC.pack_limb(sysm), Fm, Fr, Jm, Jr)
    system = C.limb_system(sysm, P[:4], P[4:7])
    old, ctx.prec = ctx.prec, 200
    try:
        for p in range(k):
            F = system.values(REAL.col(Y[p]))
            assert all(abs(F[i, 0] - float(Fm[p, i])) + F[i, 0].rad() < float(Fr[p, i]) for i in range(n))
            h = rbox[p] * (1 - 2.0**-20)  # within the box after rounding
            corners = [Y[p], Y[p] + h, Y[p] - h, Y[p] + h * np.sign(np.sin(np.arange(n) + p))]
            for y in corners:
                J = system.jacobian(REAL.col(y))  # the corners: exact floats
                assert all(abs(J[i, j] - float(Jm[p, i, j])) + J[i, j].rad() <= float(Jr[p, i, j])
                           for i in range(n) for j in range(n))
    finally:
        ctx.prec = old
    assert np.allclose(Fm, 0.0, atol=1e-13) and np.allclose(Jm, system.jacobian_float_many(Y).real, atol=1e-13)
