"""Compiled forward position of S-P-S platforms in pose coordinates: the same steps as
:mod:`.leg_platform` (Newton on the six leg distances over the platform pose, the legs placed
the shortest way from the seed, the general closure residual as the test)."""

from __future__ import annotations

import numpy as np

from .jit import njit
from .kernels_closure import nb_finite_config
from .kernels_se3 import nb_log, nb_matrix_rotvec, nb_rodrigues, nb_rotvec_matrix3

__all__ = ["nb_leg_closure", "nb_leg_inverse", "nb_leg_platform", "nb_leg_residual_sq", "nb_shortest_rotation",
           "nb_shortest_rotvec"]


@njit(cache=True)
def nb_shortest_rotvec(a0, a1, a2, b0, b1, b2, out):
    """:func:`.leg_platform.shortest_rotvec` of the unit vectors ``a`` and ``b``."""
    x0 = a1 * b2 - a2 * b1
    x1 = a2 * b0 - a0 * b2
    x2 = a0 * b1 - a1 * b0
    sn = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    dot = a0 * b0 + a1 * b1 + a2 * b2
    ang = np.arctan2(sn, dot)
    if sn > 1e-300:
        f = ang / sn
        out[0], out[1], out[2] = x0 * f, x1 * f, x2 * f
    elif dot > 0.0:
        out[0], out[1], out[2] = 0.0, 0.0, 0.0
    else:  # opposite: a half turn about the coordinate axis least aligned with a, made perpendicular
        k = 0
        if abs(a1) < abs(a0):
            k = 1
        if abs(a2) < min(abs(a0), abs(a1)):
            k = 2
        ak = a0 if k == 0 else (a1 if k == 1 else a2)
        p0, p1, p2 = -ak * a0, -ak * a1, -ak * a2
        if k == 0:
            p0 += 1.0
        elif k == 1:
            p1 += 1.0
        else:
            p2 += 1.0
        f = np.pi / np.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        out[0], out[1], out[2] = p0 * f, p1 * f, p2 * f


@njit(cache=True)
def nb_shortest_rotation(a0, a1, a2, b0, b1, b2, out, v):
    """:func:`.leg_platform.shortest_rotation` of the unit vectors ``a`` and ``b`` into ``out``
    (3x3); ``v`` (3,) scratch."""
    x0 = a1 * b2 - a2 * b1
    x1 = a2 * b0 - a0 * b2
    x2 = a0 * b1 - a1 * b0
    c = a0 * b0 + a1 * b1 + a2 * b2
    if c > -0.5:
        nb_rodrigues(x0, x1, x2, 1.0, 1.0 / (1.0 + c), out)
    else:
        nb_shortest_rotvec(a0, a1, a2, b0, b1, b2, v)
        nb_rotvec_matrix3(v[0], v[1], v[2], out)


@njit(cache=True)
def nb_leg_platform(index, geom, L, q0, D0, tol, max_iter, q, D):
    """:func:`.leg_platform.correct` before its fallback: the legs ``index`` (6, 3) (base ball,
    slide, platform ball) with ``geom`` (6, 27) (:attr:`.leg_platform.LegPlatform.data`: base
    centre, platform centre, slide direction, the two balls' axes) from
    the seed ``q0``, ``D0``.  The result in ``q``, ``D``; returns the status (1 converged, 0 not,
    -2 a singular or non-finite step, -1 NaN or infinity in the seed), the iterations, the
    nondimensional closure residual (:func:`nb_leg_closure`), and whether the seed itself is the
    result (already closed)."""
    m = index.shape[0]
    n = q0.shape[0]
    if not nb_finite_config(q0, D0, np.empty((0, 4, 4))):
        return -1, 0, np.nan, False
    Lk = np.empty(m)
    wu = np.empty((m, 3))  # each leg's direction in its base ball's frame (b - a + s e, unit)
    for k in range(m):
        s = q0[index[k, 1]]
        w0 = geom[k, 3] - geom[k, 0] + s * geom[k, 6]
        w1 = geom[k, 4] - geom[k, 1] + s * geom[k, 7]
        w2 = geom[k, 5] - geom[k, 2] + s * geom[k, 8]
        Lk[k] = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        wu[k, 0], wu[k, 1], wu[k, 2] = w0 / Lk[k], w1 / Lk[k], w2 / Lk[k]
    R = np.empty((3, 3))
    t = np.empty(3)
    for a in range(3):
        t[a] = D0[a, 3]
        for b in range(3):
            R[a, b] = D0[a, b]
    M = np.empty((6, 7))
    W = np.empty((3, 3))
    Rn = np.empty((3, 3))
    tn = np.empty(3)
    status = 0
    it = 0
    for it in range(max_iter + 1):
        sq = 0.0
        for k in range(m):
            p0 = R[0, 0] * geom[k, 3] + R[0, 1] * geom[k, 4] + R[0, 2] * geom[k, 5] + t[0]
            p1 = R[1, 0] * geom[k, 3] + R[1, 1] * geom[k, 4] + R[1, 2] * geom[k, 5] + t[1]
            p2 = R[2, 0] * geom[k, 3] + R[2, 1] * geom[k, 4] + R[2, 2] * geom[k, 5] + t[2]
            d0, d1, d2 = p0 - geom[k, 0], p1 - geom[k, 1], p2 - geom[k, 2]
            ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            f = ln - Lk[k]
            sq += f * f
            u0, u1, u2 = d0 / ln, d1 / ln, d2 / ln
            M[k, 0] = p1 * u2 - p2 * u1
            M[k, 1] = p2 * u0 - p0 * u2
            M[k, 2] = p0 * u1 - p1 * u0
            M[k, 3], M[k, 4], M[k, 5] = u0, u1, u2
            M[k, 6] = -f
        rn = np.sqrt(sq) / L
        if rn < tol:
            status = 1
            break
        if not np.isfinite(rn):
            status = -2
            break
        if it == max_iter:
            break
        for j in range(6):  # Gaussian elimination with partial pivoting
            p = j
            for i in range(j + 1, 6):
                if abs(M[i, j]) > abs(M[p, j]):
                    p = i
            if M[p, j] == 0.0:
                status = -2
                break
            if p != j:
                for c in range(j, 7):
                    M[j, c], M[p, c] = M[p, c], M[j, c]
            for i in range(j + 1, 6):
                g = M[i, j] / M[j, j]
                for c in range(j, 7):
                    M[i, c] -= g * M[j, c]
        if status == -2:
            break
        for j in range(5, -1, -1):
            acc = M[j, 6]
            for c in range(j + 1, 6):
                acc -= M[j, c] * M[c, 6]
            M[j, 6] = acc / M[j, j]
        if not np.isfinite(M[0, 6] + M[1, 6] + M[2, 6] + M[3, 6] + M[4, 6] + M[5, 6]):
            status = -2
            break
        nb_rotvec_matrix3(M[0, 6], M[1, 6], M[2, 6], W)
        for a in range(3):
            tn[a] = W[a, 0] * t[0] + W[a, 1] * t[1] + W[a, 2] * t[2] + M[3 + a, 6]
            for b in range(3):
                Rn[a, b] = W[a, 0] * R[0, b] + W[a, 1] * R[1, b] + W[a, 2] * R[2, b]
        for a in range(3):
            t[a] = tn[a]
            for b in range(3):
                R[a, b] = Rn[a, b]
    if status != 1:
        return status, it, np.inf, False
    W3 = np.empty((4, 3, 3))
    if it == 0:  # the seed's pose already closes the legs: the seed itself when it closes
        rn = nb_leg_closure(index, geom, L, q0, D0, W3)
        if rn < tol:
            return 1, it, rn, True
    for i in range(n):
        q[i] = q0[i]
    R1s = np.empty((3, 3))
    R1 = np.empty((3, 3))
    R2 = np.empty((3, 3))
    v = np.empty(3)
    for k in range(m):
        i1, i2 = index[k, 0], index[k, 2]
        A1 = geom[k, 9:18]  # row by row: A1[3 r + c]
        A2 = geom[k, 18:27]
        x0 = A1[0] * q0[i1] + A1[1] * q0[i1 + 1] + A1[2] * q0[i1 + 2]
        x1 = A1[3] * q0[i1] + A1[4] * q0[i1 + 1] + A1[5] * q0[i1 + 2]
        x2 = A1[6] * q0[i1] + A1[7] * q0[i1 + 1] + A1[8] * q0[i1 + 2]
        nb_rotvec_matrix3(x0, x1, x2, R1s)
        us0 = R1s[0, 0] * wu[k, 0] + R1s[0, 1] * wu[k, 1] + R1s[0, 2] * wu[k, 2]
        us1 = R1s[1, 0] * wu[k, 0] + R1s[1, 1] * wu[k, 1] + R1s[1, 2] * wu[k, 2]
        us2 = R1s[2, 0] * wu[k, 0] + R1s[2, 1] * wu[k, 1] + R1s[2, 2] * wu[k, 2]
        # the leg's new direction: the last residual's, at this pose (M[k, 3:6])
        nb_shortest_rotation(us0, us1, us2, M[k, 3], M[k, 4], M[k, 5], W, v)
        for a in range(3):
            for b in range(3):
                R1[a, b] = W[a, 0] * R1s[0, b] + W[a, 1] * R1s[1, b] + W[a, 2] * R1s[2, b]
        for a in range(3):  # R1^T R
            for b in range(3):
                R2[a, b] = R1[0, a] * R[0, b] + R1[1, a] * R[1, b] + R1[2, a] * R[2, b]
        nb_matrix_rotvec(R1, v)
        for j in range(3):
            q[i1 + j] = A1[j] * v[0] + A1[3 + j] * v[1] + A1[6 + j] * v[2]
        nb_matrix_rotvec(R2, v)
        for j in range(3):
            q[i2 + j] = A2[j] * v[0] + A2[3 + j] * v[1] + A2[6 + j] * v[2]
    for a in range(3):
        D[a, 3] = t[a]
        D[3, a] = 0.0
        for b in range(3):
            D[a, b] = R[a, b]
    D[3, 3] = 1.0
    rn = nb_leg_closure(index, geom, L, q, D, W3)
    return (1 if rn < tol else 0), it, rn, False


@njit(cache=True)
def nb_leg_closure(index, geom, L, q, D, W):
    """The nondimensional norm of the closure residual of S-P-S legs (6 per leg: rotation, then
    moment / ``L``), as :func:`.kernels_closure.nb_closure_system` computes it for any limb, with
    each leg's chain written out (:func:`nb_leg_residual_sq`).  ``W`` (4, 3, 3) scratch."""
    T = np.empty((4, 4))
    tw = np.empty(6)
    sq = 0.0
    for k in range(index.shape[0]):
        sq += nb_leg_residual_sq(index, geom, L, q, D, k, W, T, tw)
    return np.sqrt(sq)


@njit(cache=True)
def nb_leg_residual_sq(index, geom, L, q, D, k, W, T, tw):
    """The square of leg ``k``'s nondimensional closure residual: its chain
    ``T = [R1, a - R1 a] [I, s e] [R2, b - R2 b]`` and the residual ``log(T D^-1)`` (rotation,
    then moment / ``L``).  ``W`` (4, 3, 3), ``T`` (4, 4), ``tw`` (6,) scratch."""
    R1 = W[0]
    R2 = W[1]
    E = W[2]
    p = W[3, 0]
    x = W[3, 1]
    i1, i_s, i2 = index[k, 0], index[k, 1], index[k, 2]
    for o, i, Rb in ((9, i1, R1), (18, i2, R2)):
        A = geom[k, o:o + 9]  # the ball's axes, row by row
        nb_rotvec_matrix3(A[0] * q[i] + A[1] * q[i + 1] + A[2] * q[i + 2],
                          A[3] * q[i] + A[4] * q[i + 1] + A[5] * q[i + 2],
                          A[6] * q[i] + A[7] * q[i + 1] + A[8] * q[i + 2], Rb)
    s = q[i_s]
    for a in range(3):  # x = s e + b - R2 b;  p = a - R1 a + R1 x
        x[a] = s * geom[k, 6 + a] + geom[k, 3 + a] - (R2[a, 0] * geom[k, 3] + R2[a, 1] * geom[k, 4]
                                                       + R2[a, 2] * geom[k, 5])
    for a in range(3):
        p[a] = geom[k, a] + R1[a, 0] * (x[0] - geom[k, 0]) + R1[a, 1] * (x[1] - geom[k, 1]) + R1[a, 2] * (
            x[2] - geom[k, 2])
        for b in range(3):
            E[a, b] = R1[a, 0] * R2[0, b] + R1[a, 1] * R2[1, b] + R1[a, 2] * R2[2, b]
    for a in range(3):  # T D^-1 = [E R^T, p - E R^T t]
        for b in range(3):
            T[a, b] = E[a, 0] * D[b, 0] + E[a, 1] * D[b, 1] + E[a, 2] * D[b, 2]
    for a in range(3):
        T[a, 3] = p[a] - (T[a, 0] * D[0, 3] + T[a, 1] * D[1, 3] + T[a, 2] * D[2, 3])
    nb_log(T, np.bool_(True), tw)
    return tw[0] * tw[0] + tw[1] * tw[1] + tw[2] * tw[2] + (tw[3] * tw[3] + tw[4] * tw[4] + tw[5] * tw[5]) / (L * L)


@njit(cache=True)
def nb_leg_inverse(index, geom, L, Ds, tol, q, res, ok):
    """Inverse position of S-P-S legs in closed form at each platform displacement ``Ds[s]``
    (N, 4, 4) from the reference: each slide at the root nearest zero of
    ``|b - a + s e| = |D b - a|``, each base ball turned the shortest way from the reference
    direction of its leg (``b - a + s e``) to ``D b - a`` (the leg's idle spin stays the
    reference's, zero: the rule of :func:`.leg_platform.place_legs`), each platform ball
    ``R1^T R``.  ``q`` (N, n) rows must hold the reference (zeros) beforehand; per leg the
    nondimensional closure residual (:func:`nb_leg_residual_sq`) in ``res`` (N, 6) and whether
    it is below ``tol`` in ``ok``; a leg whose distance cannot be reached by its slide keeps the
    reference (NaN residual, not ok)."""
    W = np.empty((4, 3, 3))
    T = np.empty((4, 4))
    tw = np.empty(6)
    R1 = np.empty((3, 3))
    R2 = np.empty((3, 3))
    v = np.empty(3)
    for n in range(Ds.shape[0]):
        D = Ds[n]
        qn = q[n]
        for k in range(index.shape[0]):
            i1, i_s, i2 = index[k, 0], index[k, 1], index[k, 2]
            d0 = D[0, 0] * geom[k, 3] + D[0, 1] * geom[k, 4] + D[0, 2] * geom[k, 5] + D[0, 3] - geom[k, 0]
            d1 = D[1, 0] * geom[k, 3] + D[1, 1] * geom[k, 4] + D[1, 2] * geom[k, 5] + D[1, 3] - geom[k, 1]
            d2 = D[2, 0] * geom[k, 3] + D[2, 1] * geom[k, 4] + D[2, 2] * geom[k, 5] + D[2, 3] - geom[k, 2]
            ld2 = d0 * d0 + d1 * d1 + d2 * d2
            c0, c1, c2 = geom[k, 3] - geom[k, 0], geom[k, 4] - geom[k, 1], geom[k, 5] - geom[k, 2]
            e0, e1, e2 = geom[k, 6], geom[k, 7], geom[k, 8]
            ee = e0 * e0 + e1 * e1 + e2 * e2
            be = e0 * c0 + e1 * c1 + e2 * c2
            disc = be * be - ee * (c0 * c0 + c1 * c1 + c2 * c2 - ld2)
            if not (disc >= 0.0 and ee > 0.0 and ld2 > 0.0):
                res[n, k] = np.nan
                ok[n, k] = False
                continue
            r = np.sqrt(disc)
            sl = (r - be) / ee if be <= 0.0 else -(r + be) / ee  # the two roots without cancellation
            sf = (c0 * c0 + c1 * c1 + c2 * c2 - ld2) / (ee * sl) if sl != 0.0 else -2.0 * be / ee
            s = sl if abs(sl) <= abs(sf) else sf
            w0, w1, w2 = c0 + s * e0, c1 + s * e1, c2 + s * e2
            lw = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
            ld = np.sqrt(ld2)
            nb_shortest_rotation(w0 / lw, w1 / lw, w2 / lw, d0 / ld, d1 / ld, d2 / ld, R1, v)
            for a in range(3):  # R1^T R
                for b in range(3):
                    R2[a, b] = R1[0, a] * D[0, b] + R1[1, a] * D[1, b] + R1[2, a] * D[2, b]
            A1 = geom[k, 9:18]  # row by row: A1[3 r + c]; q = A^T (rotation vector)
            A2 = geom[k, 18:27]
            nb_matrix_rotvec(R1, v)
            for j in range(3):
                qn[i1 + j] = A1[j] * v[0] + A1[3 + j] * v[1] + A1[6 + j] * v[2]
            qn[i_s] = s
            nb_matrix_rotvec(R2, v)
            for j in range(3):
                qn[i2 + j] = A2[j] * v[0] + A2[3 + j] * v[1] + A2[6 + j] * v[2]
            rk = np.sqrt(nb_leg_residual_sq(index, geom, L, qn, D, k, W, T, tw))
            res[n, k] = rk
            ok[n, k] = rk < tol
