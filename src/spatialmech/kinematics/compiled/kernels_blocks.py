"""Minimum-norm Newton steps of the closure by block elimination (compiled, :mod:`.engine`).

The closure Jacobian of a mechanism has one block of six rows per limb.  A limb's own joint
columns touch only its rows; the hubs' twist columns (the output link, the internal bodies) are
shared.  With ``J_k`` the limb's own block, ``H_k`` its shared block and ``b_k`` its right-hand
side, the minimum-norm least-squares solution of the whole system (``np.linalg.lstsq``) is,
whenever the shared twists ``xi`` are determined:

1. a Householder QR of each ``J_k^T`` with its columns (the limb's six constraint rows)
   pivoted: ``J_k^T P_k = Q_k R_k``, rank ``r_k``;
2. the left null space of ``J_k`` -- the constraints that the limb's own joints cannot absorb,
   e.g. the leg line of an S-P-S leg with its slide held -- is ``P_k u`` with ``R_k u = 0``: one
   back substitution per missing rank, each vector normalised; these rows applied to
   ``[H_k  b_k]``, stacked over the limbs, are the *reduced* system in ``xi``;
3. ``xi`` from the reduced system, then each limb's minimum-norm ``dq_k = Q_k z`` of the now
   consistent ``J_k dq_k = b_k - H_k xi`` from the triangular ``R_k[:, :r_k]^T z = (P_k^T (b_k -
   H_k xi))_{0..r_k-1}``.

One factorization per limb serves both the reduced system and the limb's step.  When the
reduced system is square and regular (a forward-position step of a non-redundant mechanism away
from a singularity) every solution of the whole system has that ``xi``, so the
minimum-norm solution minimises each ``|dq_k|`` separately: this *is* ``lstsq``'s step, to
rounding, at a few per cent of its cost.  When no column is shared (inverse position: the
output held) the limbs decouple: each limb's least-squares step, any rank, from a column-pivoted
QR of ``[J_k  b_k]`` and :func:`nb_trapezoid_minnorm`.  Everything else -- a rank the
factorization cannot tell (a pivot between ``BLOCK_RANK_ZERO`` and ``BLOCK_MAX_COND`` relative
to the largest, or a triangular factor conditioned worse than ``BLOCK_MAX_COND``), a reduced
system that is not square (overconstrained or redundant mechanisms), or an ill-conditioned one
-- returns ``False`` and the caller takes the general solver (:func:`.kernels_se3.nb_lstsq`).
"""

from __future__ import annotations

import numpy as np

from ...geometry.tolerances import BLOCK_MAX_COND, BLOCK_RANK_ZERO
from .jit import njit

__all__ = [
    "nb_blocks_workspace",
    "nb_minnorm_blocks",
    "nb_pivoted_qr",
    "nb_qt_apply",
    "nb_reflect",
    "nb_trapezoid_minnorm",
]


@njit(cache=True, inline="always")
def nb_reflect(ZT, j, nrows, ncols, nrm, v0, vn2):
    """One Householder step of a block stored transposed (``ZT[c, i]``: row ``i`` of column
    ``c``): the reflector that maps column ``j`` (rows ``j ..``, norm ``nrm``) onto
    ``R_jj e_j``, applied to the columns after it up to ``ncols``.  It stays below the diagonal
    (``ZT[j, j+1:nrows]``) with its first entry in ``v0[j]`` and squared norm in ``vn2[j]``;
    ``ZT[j, j]`` becomes ``R_jj``."""
    alpha = -nrm if ZT[j, j] >= 0.0 else nrm
    ZT[j, j] -= alpha  # the reflector v = (Z[j, j] - alpha, Z[j+1:, j]) in place
    w = 0.0
    for i in range(j, nrows):
        w += ZT[j, i] * ZT[j, i]
    if w > 0.0:
        for c in range(j + 1, ncols):
            dot = 0.0
            for i in range(j, nrows):
                dot += ZT[j, i] * ZT[c, i]
            f = 2.0 * dot / w
            for i in range(j, nrows):
                ZT[c, i] -= f * ZT[j, i]
    v0[j] = ZT[j, j]
    vn2[j] = w
    ZT[j, j] = alpha


@njit(cache=True)
def nb_pivoted_qr(ZT, nrows, m, ncols, piv, v0, vn2, e):
    """Householder QR with column pivoting of a block stored *transposed* (``ZT[c, i]`` is row
    ``i`` of column ``c``: every inner loop runs along a contiguous column) over its first
    ``nrows`` rows and ``m`` columns, the reflectors applied to every column up to ``ncols``
    (pivoting permutes only the first ``m``), in place: ``R`` upper trapezoidal in ``ZT[:m,
    :r]`` (transposed), ``piv[j]`` the original index of column ``j``.  Returns the rank ``r``
    (remaining columns at or below ``BLOCK_RANK_ZERO`` times the largest count as zero), or
    ``-1`` when a pivot lies between that and ``1 / BLOCK_MAX_COND`` of the largest (the rank is
    not clear) or ``R[:r, :r]`` is conditioned worse than ``BLOCK_MAX_COND`` (Frobenius norms of
    it and its inverse).  The reflectors stay below the diagonal (``ZT[j, j+1:nrows]``), with
    their first entries in ``v0`` and squared norms in ``vn2`` (:func:`nb_qt_apply`); ``e``: scratch
    of at least ``min(nrows, m)`` entries."""
    for j in range(m):
        piv[j] = j
    big = 0.0
    r = 0
    for j in range(min(nrows, m)):
        best = -1.0
        p = j
        for c in range(j, m):
            s = 0.0
            for i in range(j, nrows):
                s += ZT[c, i] * ZT[c, i]
            if s > best:
                best = s
                p = c
        nrm = np.sqrt(best)
        if j == 0:
            big = nrm
            if not big > 0.0:
                return 0
        if nrm <= BLOCK_RANK_ZERO * big:
            break
        if nrm * BLOCK_MAX_COND <= big:
            return -1
        if p != j:
            for i in range(nrows):
                t = ZT[j, i]
                ZT[j, i] = ZT[p, i]
                ZT[p, i] = t
            t2 = piv[j]
            piv[j] = piv[p]
            piv[p] = t2
        nb_reflect(ZT, j, nrows, ncols, nrm, v0, vn2)
        r = j + 1
    # the conditioning of R[:r, :r]: |R|_F |R^-1|_F, the inverse column by column (r <= 6 here
    # for a limb; the reduced system's r is the number of shared columns)
    fro = 0.0
    for c in range(r):
        for i in range(c + 1):
            fro += ZT[c, i] * ZT[c, i]
    inv = 0.0
    for c in range(r):  # column c of R^-1, zero below row c: only rows c .. 0 are solved
        e[c] = 1.0 / ZT[c, c]
        inv += e[c] * e[c]
        for i in range(c - 1, -1, -1):
            acc = 0.0
            for k in range(i + 1, c + 1):
                acc -= ZT[k, i] * e[k]
            e[i] = acc / ZT[i, i]
            inv += e[i] * e[i]
    if np.sqrt(fro * inv) > BLOCK_MAX_COND:
        return -1
    return r


@njit(cache=True)
def nb_trapezoid_minnorm(ZT, r, m, d, y, V, v0, vn2):
    """The minimum-norm ``y`` (m,) of ``R y = d`` with ``R`` upper trapezoidal of full row rank
    ``r``, stored transposed (``R[i, c] = ZT[c, i]``): back substitution when ``r == m``, else
    ``R^T = Q [U ; 0]`` by Householder steps (:func:`nb_reflect`) and ``y = Q [z ; 0]`` with
    ``U^T z = d`` (scratch: ``V`` at least (r, m), ``v0`` and ``vn2`` at least r)."""
    if r == m:
        for i in range(r - 1, -1, -1):
            acc = d[i]
            for k in range(i + 1, r):
                acc -= ZT[k, i] * y[k]
            y[i] = acc / ZT[i, i]
        return
    for i in range(r):  # V[i] = row i of R = column i of R^T: R^T stored transposed
        for c in range(m):
            V[i, c] = ZT[c, i] if c >= i else 0.0
    for j in range(r):
        nrm = 0.0
        for c in range(j, m):
            nrm += V[j, c] * V[j, c]
        nb_reflect(V, j, m, r, np.sqrt(nrm), v0, vn2)
    for j in range(r):  # U^T z = d, U[i, j] = V[j, i] (i <= j)
        acc = d[j]
        for i in range(j):
            acc -= V[j, i] * y[i]
        y[j] = acc / V[j, j]
    for j in range(r, m):
        y[j] = 0.0
    nb_qt_apply(V, r, m, v0, vn2, y, np.bool_(False))


@njit(cache=True)
def nb_qt_apply(ZT, r, nrows, v0, vn2, y, transpose):
    """``y <- Q^T y`` (``transpose``) or ``y <- Q y`` with the first ``r`` reflectors kept by
    :func:`nb_pivoted_qr`."""
    for jj in range(r):
        j = jj if transpose else r - 1 - jj
        if vn2[j] > 0.0:
            dot = v0[j] * y[j]
            for i in range(j + 1, nrows):
                dot += ZT[j, i] * y[i]
            f = 2.0 * dot / vn2[j]
            y[j] -= f * v0[j]
            for i in range(j + 1, nrows):
                y[i] -= f * ZT[j, i]


@njit(cache=True)
def nb_blocks_workspace(c_lo, c_hi, ns0, n):
    """Scratch of :func:`nb_minnorm_blocks` for a system with these limb columns and ``n``
    columns in all (allocated once per solve, not per Newton step): ``(floats, ints)``."""
    K = len(c_lo)
    mmax = 1
    for k in range(K):
        mmax = max(mmax, c_hi[k] - c_lo[k])
    s = n - ns0
    shared = K * 6 * mmax + 12 * K + (s + 1) * s + 3 * s + max(6, s) + 12 + mmax + (s + 1 + mmax)
    decoupled = 13 * mmax + 36
    return np.empty(max(shared, decoupled)), np.empty(7 * K + s + mmax, dtype=np.int64)


@njit(cache=True)
def nb_minnorm_blocks(A, b, tb, tb_rhs, c_lo, c_hi, ns0, x, fbuf, ibuf):
    """Minimum-norm least-squares solution of ``A x = b`` into ``x`` by block elimination (module
    docstring).  ``A`` is (6K, n): limb ``k``'s rows ``6k .. 6k+5``; its own columns
    ``c_lo[k] .. c_hi[k]-1`` (nonzero only in its rows), the shared columns ``ns0 .. n-1``;
    scratch from :func:`nb_blocks_workspace`.  Returns ``False`` (``x`` partly written) when the
    general solver must decide.  With shared
    columns, one pivoted QR per limb of ``J_k^T`` (rows of ``J_k`` pivoted): ``J_k^T P_k = Q_k
    R_k``.  Its left null space (the constraints the limb's joints cannot absorb) is ``P_k u``
    with ``R_k u = 0``, by back substitution; once the shared twists ``xi`` are known, the
    minimum-norm ``dq_k`` of the consistent ``J_k dq_k = b_k - H_k xi`` is ``Q_k z`` with
    ``R_k[:, :r]^T z = (P_k^T (b_k - H_k xi))_{0..r-1}``.

    With a border row ``tb`` (``n`` entries; ``np.empty(0)`` for none): the solution of the
    square ``[A; tb] x = [b; tb_rhs]`` instead -- the hyperplane corrector's step, ``A`` with one
    column more than rows.  It needs every limb's own columns independent (``r_k`` = their count,
    so that ``dq_k`` is a function of ``xi``); the border is then one more row of the reduced
    system (:func:`_border_part`)."""
    K = len(c_lo)
    n = A.shape[1]
    s = n - ns0
    if s == 0:  # limbs decoupled: least squares of each limb, any rank
        return _decoupled(A, b, c_lo, c_hi, x, fbuf, ibuf)
    mmax = 1
    for k in range(K):
        mmax = max(mmax, c_hi[k] - c_lo[k])
    o = 0
    Gs = fbuf[o : o + K * 6 * mmax].reshape((K, 6, mmax))  # per limb J_k row by row = J_k^T transposed
    o += K * 6 * mmax
    v0s = fbuf[o : o + 6 * K].reshape((K, 6))
    o += 6 * K
    vn2s = fbuf[o : o + 6 * K].reshape((K, 6))
    o += 6 * K
    R = fbuf[o : o + (s + 1) * s].reshape((s + 1, s))  # the reduced system [w^T H_k  w^T b_k], transposed
    o += (s + 1) * s
    rv0 = fbuf[o : o + s]
    o += s
    rvn2 = fbuf[o : o + s]
    o += s
    xi = fbuf[o : o + s]
    o += s
    e = fbuf[o : o + max(6, s)]
    o += max(6, s)
    w = fbuf[o : o + 6]
    o += 6
    c = fbuf[o : o + 6]
    o += 6
    y = fbuf[o : o + mmax]
    o += mmax
    bord = fbuf[o : o + s + 1]  # the border row in xi, then its right-hand side
    o += s + 1
    g = fbuf[o : o + mmax]
    bordered = tb.shape[0] > 0
    pivs = ibuf[: 6 * K].reshape((K, 6))
    ranks = ibuf[6 * K : 7 * K]
    pr = ibuf[7 * K : 7 * K + s]
    nred = 0
    for k in range(K):
        m = c_hi[k] - c_lo[k]
        G = Gs[k]
        for i in range(6):
            for j in range(m):
                G[i, j] = A[6 * k + i, c_lo[k] + j]
        # literal 6s on purpose: the one specialised copy of the QR (its loops over the six rows of
        # J_k unrolled) saves 4-5 us of a Stewart forward solve for about 1.5 s of compilation
        r = nb_pivoted_qr(G, m, 6, 6, pivs[k], v0s[k], vn2s[k], e)
        if r < 0:
            return False
        ranks[k] = r
        nred += 6 - r
        if bordered and r != m:
            return False
    if nred + (1 if bordered else 0) != s:
        return False
    if bordered:
        for cc in range(s):
            bord[cc] = tb[ns0 + cc]
        bord[s] = tb_rhs
    i0 = 0
    for k in range(K):
        G = Gs[k]
        r = ranks[k]
        piv = pivs[k]
        if bordered:
            _border_part(A, b, tb, k, c_lo[k], c_hi[k] - c_lo[k], r, G, piv, v0s[k], vn2s[k], ns0, y, g, bord)
        for t in range(r, 6):  # u: R u = 0 with u[t] = 1, u[r:] = 0 otherwise; w = P u, unit
            for i in range(r, 6):
                e[i] = 0.0
            e[t] = 1.0
            for i in range(r - 1, -1, -1):
                acc = -G[t, i]
                for j in range(i + 1, r):
                    acc -= G[j, i] * e[j]
                e[i] = acc / G[i, i]
            nrm = 0.0
            for i in range(6):
                nrm += e[i] * e[i]
            nrm = np.sqrt(nrm)
            for i in range(6):
                w[piv[i]] = e[i] / nrm
            for cc in range(s):
                acc = 0.0
                for a in range(6):
                    acc += w[a] * A[6 * k + a, ns0 + cc]
                R[cc, i0] = acc
            acc = 0.0
            for a in range(6):
                acc += w[a] * b[6 * k + a]
            R[s, i0] = acc
            i0 += 1
    if bordered:
        for cc in range(s):
            R[cc, i0] = bord[cc]
        R[s, i0] = bord[s]
    if nb_pivoted_qr(R, s, s, s + 1, pr, rv0, rvn2, e) != s:
        return False
    for i in range(s - 1, -1, -1):
        acc = R[s, i]
        for cc in range(i + 1, s):
            acc -= R[cc, i] * xi[pr[cc]]
        xi[pr[i]] = acc / R[i, i]
    for k in range(K):
        _limb_step(A, b, k, c_lo[k], c_hi[k] - c_lo[k], ranks[k], Gs[k], pivs[k], v0s[k], vn2s[k], ns0, xi, c, y, x)
    for cc in range(s):
        x[ns0 + cc] = xi[cc]
    return True


@njit(cache=True)
def _limb_step(A, b, k, c0, m, r, G, piv, v0, vn2, ns0, xi, c, y, x):
    """Limb ``k``'s minimum-norm ``dq_k`` (into ``x[c0 : c0 + m]``) once the shared twists ``xi``
    are known: ``Q_k [z ; 0]`` with ``R_k[:, :r]^T z = (P_k^T (b_k - H_k xi))_{0..r-1}``."""
    s = len(xi)
    for a in range(6):  # b_k - H_k xi, consistent now
        acc = b[6 * k + a]
        for cc in range(s):
            acc -= A[6 * k + a, ns0 + cc] * xi[cc]
        c[a] = acc
    for j in range(r):  # R[:, :r]^T z = (P^T c)[:r], lower triangular: R[i, j] = G[j, i]
        acc = c[piv[j]]
        for i in range(j):
            acc -= G[j, i] * y[i]
        y[j] = acc / G[j, j]
    for j in range(r, m):
        y[j] = 0.0
    nb_qt_apply(G, r, m, v0, vn2, y, np.bool_(False))  # dq_k = Q [z ; 0]
    for j in range(m):
        x[c0 + j] = y[j]


@njit(cache=True)
def _border_part(A, b, tb, k, c0, m, r, G, piv, v0, vn2, ns0, y, g, bord):
    """Limb ``k``'s part of the border row in ``xi`` (:func:`nb_minnorm_blocks`): ``t_k . dq_k =
    g_k . (P_k^T (b_k - H_k xi))_{0..r-1}`` with ``R_k[:, :r] g_k = (Q_k^T t_k)_{0..r-1}``, moved
    into ``bord`` (coefficients of ``xi``, then the right-hand side)."""
    s = len(bord) - 1
    for j in range(m):
        y[j] = tb[c0 + j]
    nb_qt_apply(G, r, m, v0, vn2, y, np.bool_(True))
    for i in range(r - 1, -1, -1):  # R[:, :r] g = u, upper triangular: R[i, j] = G[j, i]
        acc = y[i]
        for j in range(i + 1, r):
            acc -= G[j, i] * g[j]
        g[i] = acc / G[i, i]
    for j in range(r):
        a = piv[j]
        for cc in range(s):
            bord[cc] -= g[j] * A[6 * k + a, ns0 + cc]
        bord[s] -= g[j] * b[6 * k + a]


@njit(cache=True)
def _decoupled(A, b, c_lo, c_hi, x, fbuf, ibuf):
    """Each limb's minimum-norm least-squares step when no column is shared: a pivoted QR of
    ``[J_k b_k]`` (columns pivoted), then :func:`nb_trapezoid_minnorm`."""
    K = len(c_lo)
    mmax = 1
    for k in range(K):
        mmax = max(mmax, c_hi[k] - c_lo[k])
    o = 0
    Z = fbuf[o : o + (mmax + 1) * 6].reshape((mmax + 1, 6))
    o += (mmax + 1) * 6
    v0 = fbuf[o : o + 6]
    o += 6
    vn2 = fbuf[o : o + 6]
    o += 6
    e = fbuf[o : o + 6]
    o += 6
    tv0 = fbuf[o : o + 6]
    o += 6
    tvn2 = fbuf[o : o + 6]
    o += 6
    y = fbuf[o : o + mmax]
    o += mmax
    V = fbuf[o : o + 6 * mmax].reshape((6, mmax))
    piv = ibuf[:mmax]
    for k in range(K):
        m = c_hi[k] - c_lo[k]
        for cc in range(m):
            for i in range(6):
                Z[cc, i] = A[6 * k + i, c_lo[k] + cc]
        for i in range(6):
            Z[m, i] = b[6 * k + i]
        r = nb_pivoted_qr(Z, Z.shape[1], m, m + 1, piv, v0, vn2, e)
        if r < 0:
            return False
        for a in range(6):
            e[a] = Z[m, a]
        if r > 0:
            nb_trapezoid_minnorm(Z, r, m, e, y, V, tv0, tvn2)
        else:
            for j in range(m):
                y[j] = 0.0
        for j in range(m):
            x[c_lo[k] + piv[j]] = y[j]
    return True
