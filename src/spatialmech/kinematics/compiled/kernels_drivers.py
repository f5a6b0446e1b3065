"""Compiled kernels of the driver determinants (:func:`.jacobian.driver_determinants`,
:func:`.jacobian.closure_determinant`), the tracker's configuration difference and the S-P-S
leg lengths (:mod:`.engine`)."""

from __future__ import annotations

import numpy as np

from .kernels_se3 import nb_ball_product, nb_det, nb_det_inplace, nb_inverse_into, nb_log, nb_mm4, nb_svd
from .kernels_closure import (
    nb_adjoint_columns,
    nb_chain_ws,
    nb_closure_system,
    nb_closure_ws_size,
    nb_colmap,
    nb_hub,
    nb_max_limb,
    nb_norm,
    nb_scales,
)
from .jit import njit

__all__ = [
    "nb_actuation_direction",
    "nb_closure_dets",
    "nb_det5_reciprocal",
    "nb_dets_many",
    "nb_difference",
    "nb_differences",
    "nb_driver_dets",
    "nb_null_rows",
    "nb_sigmas_many",
    "nb_sps_legs",
]


# ---------------------------------------------------------------------------- driver determinants
@njit(cache=True)
def nb_det5_reciprocal(Tn, out):
    """:func:`..geometry.screws.cofactor_reciprocal` of five nondimensional screws (5, 6)."""
    M = np.empty((5, 5))
    for j in range(6):
        for i in range(5):
            c2 = 0
            for c in range(6):
                if c != j:
                    M[i, c2] = Tn[i, c]
                    c2 += 1
        d = nb_det_inplace(M)  # M is rebuilt for the next j
        out[(j + 3) % 6] = -d if j % 2 == 1 else d  # (-1)^j det, swapped halves


@njit(cache=True)
def nb_null_rows(Tn, rtol):
    """``vt[r:]`` of the row-normalised screws ``Tn`` (m, 6) (``screws._svd``/``reciprocal_basis``)."""
    m = Tn.shape[0]
    if m == 0:
        out = np.zeros((6, 6))
        for i in range(6):
            out[i, i] = 1.0
        return out
    X = np.empty((m, 6))
    for i in range(m):
        mx = 0.0
        for c in range(6):
            mx = max(mx, abs(Tn[i, c]))
        if mx <= 0.0:
            mx = 1.0
        nn = 0.0
        for c in range(6):
            X[i, c] = Tn[i, c] / mx
            nn += X[i, c] ** 2
        nn = np.sqrt(nn)
        if nn <= 0.0:
            nn = 1.0
        for c in range(6):
            X[i, c] /= nn
    if m >= 6:
        _, sv, vt = nb_svd(X)
    else:  # padded with zero rows: the reduced SVD of a 6x6 gives the full V
        P = np.zeros((6, 6))
        for i in range(m):
            for c in range(6):
                P[i, c] = X[i, c]
        _, sv, vt = nb_svd(P)
    r = 0
    if sv[0] != 0.0:
        lim = rtol * max(1.0, sv[0])
        for i in range(min(m, 6)):
            if sv[i] > lim:
                r += 1
    out = np.empty((6 - r, 6))
    for i in range(r, 6):
        for c in range(6):
            out[i - r, c] = vt[i, c]
    return out


@njit(cache=True)
def nb_actuation_direction(others, cn, rtol, out):
    """The unit wrench (nondimensional) reciprocal to four twists ``others`` and orthogonal to
    the limb's constraint wrench ``cn`` (unit): the null vector of those five conditions by
    cofactors, without an SVD.  Returns False (the caller takes the SVD path, whose rank
    decisions the Python reference makes) unless the conditions are independent by a wide margin
    (the relative cofactor norm above ``1e4 rtol``: then the four twists have rank 4 at ``rtol``
    and the direction is unique, so both paths agree)."""
    M = np.empty((5, 6))
    for i in range(4):
        mx = 0.0
        for c in range(6):
            mx = max(mx, abs(others[i, c]))
        if mx <= 0.0:
            return False
        nn = 0.0
        for c in range(6):
            nn += (others[i, c] / mx) ** 2
        nn = np.sqrt(nn)
        for c in range(3):  # swap: t . swap(w) = 0 is the reciprocity of twist t and wrench w
            M[i, c] = others[i, 3 + c] / mx / nn
            M[i, 3 + c] = others[i, c] / mx / nn
    for c in range(6):
        M[4, c] = cn[c]
    y = np.empty(6)
    nb_det5_reciprocal(M, y)  # swapped cofactors
    for c in range(3):
        out[c] = y[3 + c]
        out[3 + c] = y[c]
    ny = nb_norm(out)
    if not ny > 1e4 * rtol:
        return False
    for c in range(6):
        out[c] /= ny
    return True


@njit(cache=True)
def _scale_free_sigma_min(M, L):  # pragma: no cover - compiled
    """``CompleteJacobian.sigma_min`` of the square matrix ``M`` (rows ``(moment ; force)``, SI):
    the smallest singular value of its wrenches ``(force ; moment / L)``, each row normalised (a
    zero row stays zero)."""
    W = np.empty((6, 6))
    for i in range(6):
        nrm = 0.0
        for c in range(3):
            W[i, c] = M[i, 3 + c]
            W[i, 3 + c] = M[i, c] / L
        for c in range(6):
            nrm += W[i, c] * W[i, c]
        nrm = np.sqrt(nrm)
        if nrm > 0.0:
            for c in range(6):
                W[i, c] /= nrm
    _, sv, _ = nb_svd(W)
    return sv[5]


@njit(cache=True)
def _actuation_rows(others, mo, cn, has_con, L, rtol):  # pragma: no cover - compiled
    """The rows whose leading right singular vector is the actuation wrench's direction (the
    reference's ``actuation_wrench`` without its QR): the wrenches reciprocal to the limb's other
    active twists ``others`` (``mo`` of them; all of wrench space when none), nondimensional, with
    the limb's unit constraint wrench ``cn`` projected out when it has one."""
    if mo == 0:
        Rn = np.zeros((6, 6))
        for i in range(6):
            Rn[i, i] = 1.0
        for i in range(6):
            for c in range(3, 6):
                Rn[i, c] /= L
    else:
        null = nb_null_rows(others, rtol)
        Rn = np.empty((null.shape[0], 6))
        for i in range(null.shape[0]):
            for c in range(3):
                Rn[i, c] = null[i, 3 + c]
                Rn[i, 3 + c] = null[i, c]
    if has_con:
        for i in range(Rn.shape[0]):
            dot = 0.0
            for c in range(6):
                dot += Rn[i, c] * cn[c]
            for c in range(6):
                Rn[i, c] -= dot * cn[c]
    return Rn


@njit(cache=True)
def nb_driver_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, active, L, rtol, q, D, B, drivers, out,
                   sig):
    """:func:`.jacobian.driver_determinants` without internal bodies.  Returns 0 when ``out`` is
    filled, 1 when the constraint rows are not 5 (``out`` = NaN), 2 for a limb this kernel does not
    handle (fewer than five active twists, or five dependent ones: the Python path decides).  When
    ``sig`` has one entry per driver, each driver's ``CompleteJacobian.sigma_min`` goes into it
    (0 where the actuation wrench does not exist: the reference's zero row); pass an empty array
    for DJ alone."""
    want = sig.shape[0] == out.shape[0]
    K = len(limb_start) - 1
    n = len(q)
    J = np.empty((6, max(nb_max_limb(limb_start), 1)))
    T = np.empty((4, 4))
    tw = np.empty((n, 6))  # active twists, nondimensional, by global index
    limb_of = np.empty(n, dtype=np.int64)
    cons = np.zeros((K, 6))  # per limb: its constraint wrench (SI), when it has one
    has_con = np.zeros(K, dtype=np.bool_)
    ncons = 0
    Wc = np.empty((6, 3, 3))  # scratch of the chains, the five twists and their reciprocal
    T5 = np.empty((5, 6))
    w = np.empty(6)
    for k in range(K):
        lo = limb_start[k]
        hi = limb_start[k + 1]
        nb_chain_ws(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J, Wc)
        a = ends[k, 0]
        if a >= 0:
            nb_adjoint_columns(nb_hub(a, D, B), J, hi - lo)
        ma = 0
        for i in range(lo, hi):
            limb_of[i] = k
            if active[i]:
                ma += 1
            for c in range(6):
                tw[i, c] = J[c, i - lo] if c < 3 else J[c, i - lo] / L
        if ma == 5:
            j = 0
            prod = 1.0
            for i in range(lo, hi):
                if active[i]:
                    for c in range(6):
                        T5[j, c] = tw[i, c]
                    prod *= nb_norm(tw[i])
                    j += 1
            nb_det5_reciprocal(T5, w)
            nw = nb_norm(w)
            if not nw > rtol * prod:
                return 2
            for c in range(6):
                cons[k, c] = w[c] / nw if c < 3 else w[c] / nw * L
            has_con[k] = True
            ncons += 1
        elif ma > 5:
            Tn = np.empty((ma, 6))
            j = 0
            for i in range(lo, hi):
                if active[i]:
                    for c in range(6):
                        Tn[j, c] = tw[i, c]
                    j += 1
            if nb_null_rows(Tn, rtol).shape[0] != 0:
                return 2
        else:
            return 2
    if ncons != 5:
        for x in range(len(drivers)):
            out[x] = np.nan
        return 1
    M = np.empty((6, 6))
    j = 0
    for k in range(K):
        if has_con[k]:
            for c in range(3):  # swap: (moment ; force)
                M[j, c] = cons[k, 3 + c]
                M[j, 3 + c] = cons[k, c]
            j += 1
    if want:
        sig[:] = 0.0  # a driver left at 0: its actuation wrench does not exist here
    for x in range(len(drivers)):
        d = drivers[x]
        k = limb_of[d]
        lo = limb_start[k]
        hi = limb_start[k + 1]
        mo = 0
        for i in range(lo, hi):
            if active[i] and i != d:
                mo += 1
        others = np.empty((mo, 6))
        j = 0
        for i in range(lo, hi):
            if active[i] and i != d:
                for c in range(6):
                    others[j, c] = tw[i, c]
                j += 1
        cn = np.empty(6)
        if has_con[k]:
            for c in range(6):
                cn[c] = cons[k, c] if c < 3 else cons[k, c] / L
            nc = nb_norm(cn)
            for c in range(6):
                cn[c] /= nc
        v0 = np.empty(6)  # the actuation wrench's direction, nondimensional and unit (vt[0] below)
        if not (has_con[k] and mo == 4 and nb_actuation_direction(others, cn, rtol, v0)):
            Rn = _actuation_rows(others, mo, cn, has_con[k], L, rtol)
            if Rn.shape[0] == 0:
                out[x] = 0.0
                continue
            P = np.zeros((6, 6))
            for i in range(Rn.shape[0]):
                for c in range(6):
                    P[i, c] = Rn[i, c]
            _, s, vt = nb_svd(P)
            if s[0] < rtol:
                out[x] = 0.0
                continue
            for c in range(6):
                v0[c] = vt[0, c]
        w = np.empty(6)
        for c in range(6):
            w[c] = v0[c] if c < 3 else v0[c] * L
        ta = tw[d]  # nondimensional twist of the driver
        prod = 0.0
        for c in range(3):  # reciprocal product with the SI twist (moments times L)
            prod += w[c] * ta[3 + c] * L + ta[c] * w[3 + c]
        scale = nb_norm(v0) * nb_norm(ta)
        if abs(prod) < rtol * max(scale, 1e-300):
            out[x] = 0.0
            continue
        for c in range(3):
            M[5, c] = w[3 + c] / prod
            M[5, 3 + c] = w[c] / prod
        out[x] = nb_det(M)
        if want:
            sig[x] = _scale_free_sigma_min(M, L)
    return 0


@njit(cache=True)
def nb_closure_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, L, q, D, B, cols, out):
    """:func:`.jacobian.closure_determinant` for each active column in ``cols``."""
    K = len(limb_start) - 1
    h = 1 + B.shape[0]
    colmap, na = nb_colmap(active)
    row, col = nb_scales(linear, active, K, h, L)
    nc = na + 6 * h
    A = np.zeros((6 * K, nc))
    r = np.empty(6 * K)
    nb_closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, A, r,
                      np.empty(nb_closure_ws_size(limb_start)))
    for i in range(6 * K):
        for c in range(nc):
            A[i, c] *= row[i] * col[c]
    if nc - 1 != 6 * K:
        for x in range(len(cols)):
            out[x] = np.nan
        return
    M = np.empty((6 * K, nc - 1))
    for x in range(len(cols)):
        for i in range(6 * K):
            j = 0
            for c in range(nc):
                if c != cols[x]:
                    M[i, j] = A[i, c]
                    j += 1
        out[x] = nb_det(M)


@njit(cache=True)
def nb_sigmas_many(S, ball_of, ball_axes, ball_centre, limb_start, ends, active, L, rtol, qs, Ds, Bs, drivers, out,
                   sig):  # pragma: no cover - compiled
    """:func:`nb_driver_dets` with its sigmas at many configurations (no internal bodies): 0, or
    the first nonzero code (the Python path decides)."""
    for s in range(qs.shape[0]):
        f = nb_driver_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, active, L, rtol, qs[s], Ds[s], Bs[s],
                           drivers, out[s], sig[s])
        if f != 0:
            return f
    return 0


@njit(cache=True)
def nb_dets_many(S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, L, rtol, qs, Ds, Bs, drivers, cols,
               bodies, out):
    """Driver determinants at many configurations: the closure determinants of ``cols`` for a
    mechanism with internal bodies, else :func:`nb_driver_dets` (returns 2 as soon as it declines)."""
    for s in range(qs.shape[0]):
        if bodies:
            nb_closure_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, L, qs[s], Ds[s], Bs[s],
                          cols, out[s])
        elif nb_driver_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, active, L, rtol, qs[s], Ds[s], Bs[s],
                            drivers, out[s], np.empty(0)) == 2:
            return 2
    return 0


@njit(cache=True)
def nb_difference(ball_first, ball_axes, qa, Da, Ba, qb, Db, Bb, active, wrap, col, out):
    """``tracking._MechanismBase._config_diff``: local coordinates of ``b`` relative to ``a``
    (active joint differences, angles wrapped to [-pi, pi); relative rotations of S joints; the
    hubs' relative twists), divided by the column scales ``col``."""
    n = len(qa)
    dq = np.empty(n)
    for i in range(n):
        dq[i] = qb[i] - qa[i]
    for g in range(len(ball_first)):
        i = ball_first[g]
        nb_ball_product(ball_axes[g], qb[i : i + 3], qa[i : i + 3], np.bool_(True), np.bool_(True), dq[i : i + 3])  # Rb Ra^T
    j = 0
    for i in range(n):
        if active[i]:
            v = dq[i]
            if wrap[j]:
                v = (v + np.pi) % (2 * np.pi) - np.pi
            out[j] = v / col[j]
            j += 1
    Hi = np.empty((4, 4))
    T = np.empty((4, 4))
    tw = np.empty(6)
    for h in range(1 + Ba.shape[0]):
        nb_inverse_into(nb_hub(h, Da, Ba), Hi)
        nb_mm4(nb_hub(h, Db, Bb), Hi, T)
        nb_log(T, np.bool_(False), tw)
        for x in range(6):
            out[j + x] = tw[x] / col[j + x]
        j += 6


# ---------------------------------------------------------------------------- SPS legs
@njit(cache=True)
def nb_sps_legs(poses, base, plat, out):
    """Leg lengths ``|R b_i + p - a_i|`` of poses ``(x, y, z, a1, a2, a3)``, ``R = Rz(a1) Ry(a2) Rx(a3)``."""
    m = base.shape[0]
    for s in range(poses.shape[0]):
        x, y, z = poses[s, 0], poses[s, 1], poses[s, 2]
        sg, cg = np.sin(poses[s, 3]), np.cos(poses[s, 3])
        sb, cb = np.sin(poses[s, 4]), np.cos(poses[s, 4])
        sa, ca = np.sin(poses[s, 5]), np.cos(poses[s, 5])
        r00, r01, r02 = cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa
        r10, r11, r12 = sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa
        r20, r21, r22 = -sb, cb * sa, cb * ca
        for i in range(m):
            bx, by, bz = plat[i, 0], plat[i, 1], plat[i, 2]
            dx = r00 * bx + r01 * by + r02 * bz + x - base[i, 0]
            dy = r10 * bx + r11 * by + r12 * bz + y - base[i, 1]
            dz = r20 * bx + r21 * by + r22 * bz + z - base[i, 2]
            out[s, i] = np.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True)
def nb_differences(ball_first, ball_axes, Qa, DAs, BAs, qb, Db, Bb, active, wrap, col, out):
    """:func:`nb_difference` of one configuration ``b`` relative to each of many ``a`` (stacked
    ``Qa`` (m, n), ``DAs`` (m, 4, 4), ``BAs`` (m, n_bodies, 4, 4)); ``out`` (m, n_local)."""
    for k in range(Qa.shape[0]):
        nb_difference(ball_first, ball_axes, Qa[k], DAs[k], BAs[k], qb, Db, Bb, active, wrap, col, out[k])
