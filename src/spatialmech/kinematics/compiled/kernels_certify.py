"""The float pass of the certificates, compiled (numba): the interval enclosures of a limb's
square system (:class:`..homotopy.certify_systems.LimbBallSystem`: the circles and the closure
rows) at real points and of its Jacobian over boxes about them, and the Krawczyk test on any
such enclosures; the Python reference is :mod:`..homotopy.certify_float` (``krawczyk_limb``,
``krawczyk_real``), which runs under ``SPATIALMECH_PURE=1``.  The entry is :mod:`.certify`.

The arithmetic is the reference's, operation by operation: midpoint-radius intervals in
round-to-nearest with the a-priori rounding bounds of :mod:`..homotopy.certify_float` (Rump
1999): a sum or product's radius is its operands' radii propagated plus ``u |m|`` for the
rounding of its midpoint ``m``; a matrix product's radius is ``|Ma| Rb + Ra (|Mb| + Rb) + (q +
1) u |Ma| |Mb|`` (inner dimension ``q``: Higham's ``gamma_q`` for any order of summation, with
or without fused multiply-add); every radius is then multiplied by ``1 + 2^-40`` and increased
by ``2^-1000`` (:func:`nb_up`), which covers the rounding of the radius's own computation (a few
hundred roundings of non-negative floats, each losing at most a factor ``1 - u``) and underflow.

Fused multiply-add and order.  The kernels are compiled without ``fastmath``: numba then gives
LLVM no ``contract`` or ``reassoc`` flag, so no multiply and add are fused and no sum is
reordered or vectorised across its terms: every operation rounds once, in the order written
(``tests/test_certify_compiled.py`` checks the machine code for fused multiply-adds).  The bounds
would hold with contraction too: a fused ``a b + c`` skips the rounding of ``a b``, whose bound
is counted all the same, and the radii are sums and products of non-negative floats, which a
fused operation rounds once instead of twice (still at most a factor ``1 - u`` each).
"""

from __future__ import annotations

import math

import numpy as np

from ...geometry.tolerances import CERTIFY_GROWTH, CERTIFY_MIN_RADIUS
from .jit import njit

__all__ = ["nb_imatmul", "nb_krawczyk", "nb_limb_enclosures", "nb_limb_values", "nb_pow2_up", "nb_up"]

U = 2.0**-53  # unit roundoff (round to nearest)
UP = 1.0 + 2.0**-40
TINY = 2.0**-1000


@njit(cache=True)
def nb_up(r):
    """An upper bound of the exact value of the radius ``r`` computed in round-to-nearest."""
    return r * UP + TINY


@njit(cache=True)
def nb_pow2_up(r):
    """The least power of two not below ``r > 0`` (finite)."""
    m, e = math.frexp(r)
    if m == 0.5:
        e -= 1
    return math.ldexp(1.0, e)


@njit(cache=True)
def nb_imatmul(am, ar, bm, br, cm, cr):
    """``C = A B`` of interval matrices ``(am, ar)`` (p, q) and ``(bm, br)`` (q, s) into ``(cm,
    cr)`` (distinct arrays); a constant enters with a zero radius."""
    p, q = am.shape
    s = bm.shape[1]
    g = (q + 1) * U
    for i in range(p):
        for j in range(s):
            m = 0.0
            r1 = 0.0
            r2 = 0.0
            for k in range(q):
                a = am[i, k]
                b = bm[k, j]
                m += a * b
                r1 += abs(a) * (br[k, j] + g * abs(b))
                r2 += ar[i, k] * (abs(b) + br[k, j])
            cm[i, j] = m
            cr[i, j] = nb_up(r1 + r2)


@njit(cache=True)
def nb_imatvec(am, ar, bm, br, cm, cr):
    """``c = A b`` of an interval matrix (p, 4) and an interval vector (4,), into (p,)."""
    g = 5 * U
    for i in range(am.shape[0]):
        m = 0.0
        r1 = 0.0
        r2 = 0.0
        for k in range(4):
            a = am[i, k]
            b = bm[k]
            m += a * b
            r1 += abs(a) * (br[k] + g * abs(b))
            r2 += ar[i, k] * (abs(b) + br[k])
        cm[i] = m
        cr[i] = nb_up(r1 + r2)


@njit(cache=True)
def nb_imul(am, ar, bm, br):
    """``a b`` of two intervals: (midpoint, radius)."""
    m = am * bm
    return m, nb_up(abs(am) * br + ar * (abs(bm) + br) + U * abs(m))


@njit(cache=True)
def nb_iadd(am, ar, bm, br):
    """``a + b`` of two intervals (``b`` negated by the caller for a difference)."""
    m = am + bm
    return m, nb_up(ar + br + U * abs(m))


@njit(cache=True)
def nb_pose(q, t, C, E, s, stv):
    """The pose's exact data in intervals: ``E(q)`` (4x4, ``E[:, :, 0]`` midpoints, ``[..., 1]``
    radii), ``s = q.q`` and ``stv = s t`` (``certify_float._rotation``): the products ``q_a q_b``
    as intervals, then their exact integer combinations ``C`` (17, 16)."""
    pm = np.empty(16)
    pr = np.empty(16)
    for a in range(4):
        for b in range(4):
            m = q[a] * q[b]
            pm[4 * a + b] = m
            pr[4 * a + b] = nb_up(U * abs(m))
    g = 17 * U
    for row in range(17):
        m = 0.0
        r = 0.0
        for k in range(16):
            m += C[row, k] * pm[k]
            r += abs(C[row, k]) * (pr[k] + g * abs(pm[k]))
        if row < 16:
            E[row // 4, row % 4, 0] = m
            E[row // 4, row % 4, 1] = nb_up(r)
        else:
            s[0] = m
            s[1] = nb_up(r)
    for a in range(3):
        m = s[0] * t[a]
        stv[a, 0] = m
        stv[a, 1] = nb_up(s[1] * abs(t[a]) + U * abs(m))


@njit(cache=True)
def nb_set4(dm, dr, sm, sr, identity):
    """``(dm, dr) = (sm, sr)`` (4x4), or the identity with radius zero (``identity``): explicit
    loops (an array assignment compiles numba's broadcasting for each call site)."""
    for a in range(4):
        for b in range(4):
            if identity:
                dm[a, b] = 1.0 if a == b else 0.0
                dr[a, b] = 0.0
            else:
                dm[a, b] = sm[a, b]
                dr[a, b] = sr[a, b]


@njit(cache=True)
def nb_side(xm, xr, lo, hi, rev, i_s, i_c, const, Mm, Mr, prem, prer, sufm, sufr, want_suf):
    """The factors ``lo:hi`` of one side at the interval point ``(xm, xr)``: ``M = (1, s, 1 - c) @
    (I ; A ; A^2)`` (``const`` (f, 3, 4, 4) exact), their prefix products ``pre[i] = M_0 ...
    M_(i-1)`` (``pre[0]`` the identity, ``pre[1] = M_0``) and, with ``want_suf``, the suffix
    products ``suf[i] = M_i ... M_last`` (``suf[last + 1]`` the identity); ``Mm, Mr`` (at least
    ``hi - lo``, 4, 4) scratch."""
    nf = hi - lo
    g = 4 * U
    for i in range(nf):
        f = lo + i
        u1m = xm[i_s[f]]
        u1r = xr[i_s[f]]
        u2m = 0.0
        u2r = 0.0
        if rev[f]:
            u2m = 1.0 - xm[i_c[f]]
            u2r = nb_up(xr[i_c[f]] + U * abs(u2m))
        for a in range(4):
            for b in range(4):
                c0, c1, c2 = const[f, 0, a, b], const[f, 1, a, b], const[f, 2, a, b]
                Mm[i, a, b] = c0 + u1m * c1 + u2m * c2
                Mr[i, a, b] = nb_up(g * abs(c0) + (u1r + g * abs(u1m)) * abs(c1) + (u2r + g * abs(u2m)) * abs(c2))
    nb_set4(prem[0], prer[0], Mm[0], Mr[0], np.bool_(True))  # the identity, exact
    for i in range(nf):
        if i == 0:
            nb_set4(prem[1], prer[1], Mm[0], Mr[0], np.bool_(False))
        else:
            nb_imatmul(prem[i], prer[i], Mm[i], Mr[i], prem[i + 1], prer[i + 1])
    if want_suf:
        nb_set4(sufm[nf], sufr[nf], Mm[0], Mr[0], np.bool_(True))
        for i in range(nf - 1, -1, -1):
            if i == nf - 1:
                nb_set4(sufm[i], sufr[i], Mm[i], Mr[i], np.bool_(False))
            else:
                nb_imatmul(Mm[i], Mr[i], sufm[i + 1], sufr[i + 1], sufm[i], sufr[i])


@njit(cache=True)
def nb_point_rows(TLm, TLr, TRm, TRr, Em, Er, s, stv, centre, zc, vec, out_m, out_r):
    """The closure rows of a limb with an S joint at its centre: ``s TL c - E TR c - s t`` (3);
    ``vec`` (6, 4) scratch."""
    nb_imatvec(TLm, TLr, centre, zc, vec[0], vec[1])
    nb_imatvec(TRm, TRr, centre, zc, vec[2], vec[3])
    nb_imatvec(Em, Er, vec[2], vec[3], vec[4], vec[5])
    for a in range(3):
        m, r = nb_imul(s[0], s[1], vec[0, a], vec[1, a])
        m, r = nb_iadd(m, r, -vec[4, a], vec[5, a])
        out_m[a], out_r[a] = nb_iadd(m, r, -stv[a, 0], stv[a, 1])


@njit(cache=True)
def nb_full_rows(TLm, TLr, Wm, Wr, s, stv, work, out_m, out_r):
    """The closure rows of a limb without an S joint: ``P = W^T TL`` (``W = E TR``) at (1, 0),
    (2, 0), (2, 1), then ``s TL[:3, 3] - W[:3, 3] - s t``; ``work`` (2, 4, 4) scratch."""
    nb_imatmul(Wm.T, Wr.T, TLm, TLr, work[0], work[1])  # W^T TL
    out_m[0], out_r[0] = work[0, 1, 0], work[1, 1, 0]
    out_m[1], out_r[1] = work[0, 2, 0], work[1, 2, 0]
    out_m[2], out_r[2] = work[0, 2, 1], work[1, 2, 1]
    for a in range(3):
        m, r = nb_imul(s[0], s[1], TLm[a, 3], TLr[a, 3])
        m, r = nb_iadd(m, r, -Wm[a, 3], Wr[a, 3])
        out_m[3 + a], out_r[3 + a] = nb_iadd(m, r, -stv[a, 0], stv[a, 1])


@njit(cache=True)
def nb_derivative_cols(side, point, dTm, dTr, Wm, Wr, TLm, TLr, Em, Er, s, centre, zc, work, vec, cm, cr):
    """The closure rows' derivatives for one unknown, from ``dT`` (the derivative of its side's
    product): as ``certify_float.krawczyk_limb``'s Jacobian, row by row; ``work`` (4, 4, 4) and
    ``vec`` (4, 4) scratch."""
    if point:
        nb_imatvec(dTm, dTr, centre, zc, vec[0], vec[1])
        if side == 0:
            for a in range(3):
                cm[a], cr[a] = nb_imul(s[0], s[1], vec[0, a], vec[1, a])
        else:
            nb_imatvec(Em, Er, vec[0], vec[1], vec[2], vec[3])
            for a in range(3):
                cm[a], cr[a] = -vec[2, a], vec[3, a]
        return
    if side == 0:
        nb_imatmul(Wm.T, Wr.T, dTm, dTr, work[0], work[1])
        cm[0], cr[0] = work[0, 1, 0], work[1, 1, 0]
        cm[1], cr[1] = work[0, 2, 0], work[1, 2, 0]
        cm[2], cr[2] = work[0, 2, 1], work[1, 2, 1]
        for a in range(3):
            cm[3 + a], cr[3 + a] = nb_imul(s[0], s[1], dTm[a, 3], dTr[a, 3])
        return
    nb_imatmul(Em, Er, dTm, dTr, work[2], work[3])
    nb_imatmul(TLm.T, TLr.T, work[2], work[3], work[0], work[1])
    cm[0], cr[0] = work[0, 0, 1], work[1, 0, 1]
    cm[1], cr[1] = work[0, 0, 2], work[1, 0, 2]
    cm[2], cr[2] = work[0, 1, 2], work[1, 1, 2]
    for a in range(3):
        cm[3 + a], cr[3 + a] = -work[2, a, 3], work[3, a, 3]


@njit(cache=True)
def nb_limb_values(xm, circles, point, TLm, TLr, TRm, TRr, Em, Er, s, stv, centre, zc, work, vec, Fm, Fr):
    """The limb's square system at the point ``xm`` (exact) into ``(Fm, Fr)`` (n,): the circles,
    then the closure rows (:func:`nb_point_rows` or :func:`nb_full_rows`)."""
    nc = circles.shape[0]
    for i in range(nc):
        a, b = circles[i, 0], circles[i, 1]
        ma, ra = nb_imul(xm[a], 0.0, xm[a], 0.0)
        mb, rb = nb_imul(xm[b], 0.0, xm[b], 0.0)
        m, r = nb_iadd(ma, ra, mb, rb)
        Fm[i], Fr[i] = nb_iadd(m, r, -1.0, 0.0)
    if point:
        nb_point_rows(TLm, TLr, TRm, TRr, Em, Er, s, stv, centre, zc, vec, Fm[nc:], Fr[nc:])
    else:
        nb_imatmul(Em, Er, TRm, TRr, work[2], work[3])
        nb_full_rows(TLm, TLr, work[2], work[3], s, stv, work, Fm[nc:], Fr[nc:])


@njit(cache=True)
def nb_limb_enclosures(Y, rbox, q, t, C, point, centre, circles, rev, i_s, i_c, const, nleft, d_fac, d_z, dM,
                       Fm, Fr, Jm, Jr):
    """For each real point ``Y[p]`` (k, n): the limb's square system at the point, ``(Fm, Fr)`` (k,
    n), and its Jacobian over the box ``Y[p] +- rbox[p]``, ``(Jm, Jr)`` (k, n, n), in intervals.
    The pose ``(q, t)`` with ``C`` (:func:`nb_pose`); the factors (left ``:nleft``, then right) by
    :func:`nb_side`'s arrays; the derivatives ``d_fac`` (the factor), ``d_z`` (the unknown),
    ``dM`` (exact 4x4)."""
    k, n = Y.shape
    E = np.empty((4, 4, 2))
    s = np.empty(2)
    stv = np.empty((3, 2))
    nb_pose(q, t, C, E, s, stv)
    Em = np.empty((4, 4))
    Er = np.empty((4, 4))
    for a in range(4):
        for b in range(4):
            Em[a, b], Er[a, b] = E[a, b, 0], E[a, b, 1]
    nf = rev.shape[0]
    nc = circles.shape[0]
    zc = np.zeros(4)
    z44 = np.zeros((4, 4))
    Mm = np.empty((nf, 4, 4))
    Mr = np.empty((nf, 4, 4))
    pre = np.empty((2, 2, nf + 1, 4, 4))  # [side, m / r, i]
    suf = np.empty((2, 2, nf + 1, 4, 4))
    work = np.empty((6, 4, 4))  # 0, 1: dM suf; 2, 3: dT; 4, 5: W = E TR
    cols = np.empty((4, 4, 4))
    vec = np.empty((6, 4))
    xr = np.empty(n)
    cm = np.empty(6)
    cr = np.empty(6)
    first = np.int64(0)  # not a literal: one compiled nb_side (jit.py)
    for p in range(k):
        xm = Y[p]
        for want in range(2):  # the values at the point, then the Jacobian over the box
            for i in range(n):
                xr[i] = 0.0 if want == 0 else rbox[p]
            for side in range(2):  # one call site: each is compiled into this kernel
                lo = first if side == 0 else nleft
                hi = nleft if side == 0 else nf
                nb_side(xm, xr, lo, hi, rev, i_s, i_c, const, Mm, Mr, pre[side, 0], pre[side, 1], suf[side, 0],
                        suf[side, 1], want == 1)
            TLm, TLr = pre[0, 0, nleft], pre[0, 1, nleft]
            TRm, TRr = pre[1, 0, nf - nleft], pre[1, 1, nf - nleft]
            if want == 0:
                nb_limb_values(xm, circles, point, TLm, TLr, TRm, TRr, Em, Er, s, stv, centre, zc, work, vec,
                               Fm[p], Fr[p])
                continue
            for i in range(n):
                for j in range(n):
                    Jm[p, i, j] = 0.0
                    Jr[p, i, j] = 0.0
            for i in range(nc):
                a, b = circles[i, 0], circles[i, 1]
                Jm[p, i, a], Jr[p, i, a] = 2.0 * xm[a], 2.0 * xr[a]  # exact: times 2
                Jm[p, i, b], Jr[p, i, b] = 2.0 * xm[b], 2.0 * xr[b]
            nb_imatmul(Em, Er, TRm, TRr, work[4], work[5])  # W = E TR
            for d in range(d_fac.shape[0]):
                f = d_fac[d]
                side = 0 if f < nleft else 1
                i = f if side == 0 else f - nleft
                nb_imatmul(dM[d], z44, suf[side, 0, i + 1], suf[side, 1, i + 1], work[0], work[1])
                nb_imatmul(pre[side, 0, i], pre[side, 1, i], work[0], work[1], work[2], work[3])
                nb_derivative_cols(side, point, work[2], work[3], work[4], work[5], TLm, TLr, Em, Er, s, centre, zc,
                                   cols, vec, cm, cr)
                for a in range(n - nc):
                    Jm[p, nc + a, d_z[d]] = cm[a]
                    Jr[p, nc + a, d_z[d]] = cr[a]


@njit(cache=True)
def nb_test_radius(AFm, AFr, MDs, r):
    """Whether ``K(X) - y`` lies inside the box of half-width ``r``: ``|-A F(y) + M (X - y)| < r``
    in every coordinate, with ``MDs[i]`` the sums ``sum_j (|M_ij| + rad M_ij)`` (the product
    ``M D`` of ``certify_float.krawczyk_real`` with ``D = <0, r>``)."""
    for i in range(AFm.shape[0]):
        mdr = nb_up(MDs[0, i] * r + MDs[1, i] * r)
        m = -AFm[i]
        rr = nb_up(AFr[i] + mdr + U * abs(m))
        bound = nb_up(abs(m) + rr)
        if not (bound < r) or not np.isfinite(bound):
            return False
    return True


@njit(cache=True)
def nb_krawczyk(A, Jm, Jr, Fm, Fr, Y, max_radius, todo, grow, out):
    """The Krawczyk test of ``certify_float.krawczyk_real`` at the points ``todo`` (k,) of ``Y``
    (k, n): ``A`` (k, n, n) the preconditioners, ``(Jm, Jr)`` the Jacobian's enclosure over the
    largest box (serves every box), ``(Fm, Fr)`` the values' at the points.  ``out[p]`` the first
    radius of the sequence (a power of two at least four Newton corrections, then times
    ``CERTIFY_GROWTH`` with ``grow``, up to ``max_radius (1 + max |y|)``) that passes, 0 for none;
    ``out`` is left alone at the other points."""
    k, n = Y.shape
    g = (n + 1) * U
    MDs = np.empty((2, n))
    AFm = np.empty(n)
    AFr = np.empty(n)
    for p in range(k):
        if not todo[p]:
            continue  # out[p] kept
        out[p] = 0.0
        for i in range(n):  # M = I - A J: the two sums of |M| and rad M times the radius
            s1 = 0.0
            s2 = 0.0
            for j in range(n):
                m = 0.0
                r = 0.0
                for l in range(n):
                    a = A[p, i, l]
                    m += a * Jm[p, l, j]
                    r += abs(a) * (Jr[p, l, j] + g * abs(Jm[p, l, j]))
                mm = (1.0 if i == j else 0.0) - m
                mr = nb_up(nb_up(r) + U * abs(mm))
                s1 += abs(mm)
                s2 += mr
            MDs[0, i] = s1
            MDs[1, i] = s2
            m = 0.0
            r = 0.0
            for l in range(n):
                a = A[p, i, l]
                m += a * Fm[p, l]
                r += abs(a) * (Fr[p, l] + g * abs(Fm[p, l]))
            AFm[i] = m
            AFr[i] = nb_up(r)
        step = 0.0
        big = 0.0
        for i in range(n):
            step = max(step, abs(AFm[i])) if np.isfinite(AFm[i]) else np.inf
            big = max(big, abs(Y[p, i]))
        scale = 1.0 + big
        rmax = max_radius * scale
        if not np.isfinite(step):
            continue
        r = nb_pow2_up(max(4.0 * step, CERTIFY_MIN_RADIUS * scale))
        while r <= rmax:
            if nb_test_radius(AFm, AFr, MDs, r):
                out[p] = r
                break
            if not grow:
                break
            r *= CERTIFY_GROWTH
