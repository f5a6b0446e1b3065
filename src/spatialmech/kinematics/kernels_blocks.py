"""Minimum-norm Newton steps of the closure by block elimination (compiled, :mod:`.compiled`).

The closure Jacobian of a mechanism has one block of six rows per limb.  A limb's own joint
columns touch only its rows; the hubs' twist columns (the output link, the internal bodies) are
shared.  With ``J_k`` the limb's own block, ``H_k`` its shared block and ``b_k`` its right-hand
side, the minimum-norm least-squares solution of the whole system (``np.linalg.lstsq``) is,
whenever the shared twists ``xi`` are determined:

1. a pivoted Householder QR of each ``J_k`` (``Q_k^T J_k P_k = [R_k ; 0]``, rank ``r_k``);
2. the rows ``r_k .. 5`` of ``Q_k^T [H_k  b_k]`` stacked: the *reduced* system in ``xi``
   (the constraints that the limb's own joints cannot absorb, e.g. the leg line of an S-P-S leg
   with its slide held);
3. ``xi`` from the reduced system, then each limb's minimum-norm least-squares ``dq_k`` from
   ``R_k dq_k = (Q_k^T (b_k - H_k xi))_{0..r_k-1}``.

When the reduced system is square and regular (a forward-position step of a non-redundant
mechanism away from a singularity) every solution of the whole system has that ``xi``, so the
minimum-norm solution minimises each ``|dq_k|`` separately: this *is* ``lstsq``'s step, to
rounding, at a few per cent of its cost.  When no column is shared (inverse position: the
output held) the limbs decouple and the same holds for any rank.  Everything else -- a rank the
factorization cannot tell (a pivot between ``BLOCK_RANK_ZERO`` and ``BLOCK_MAX_COND`` relative
to the largest, or a triangular factor conditioned worse than ``BLOCK_MAX_COND``), a reduced
system that is not square (overconstrained or redundant mechanisms), or an ill-conditioned one
-- returns ``False`` and the caller takes the general solver (:func:`.kernels_se3.nb_lstsq`).
"""

from __future__ import annotations

import numpy as np

from ..geometry.tolerances import BLOCK_MAX_COND, BLOCK_RANK_ZERO
from .jit import njit

__all__ = ["nb_minnorm_blocks", "nb_pivoted_qr", "nb_qt_apply", "nb_reflect", "nb_trapezoid_minnorm"]


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
    for c in range(r):
        for i in range(r - 1, -1, -1):
            acc = 1.0 if i == c else 0.0
            for k in range(i + 1, r):
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
    nb_qt_apply(V, r, m, v0, vn2, y, False)


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
def nb_minnorm_blocks(A, b, c_lo, c_hi, ns0, x):
    """Minimum-norm least-squares solution of ``A x = b`` into ``x`` by block elimination (module
    docstring).  ``A`` is (6K, n): limb ``k``'s rows ``6k .. 6k+5``; its own columns
    ``c_lo[k] .. c_hi[k]-1`` (nonzero only in its rows), the shared columns ``ns0 .. n-1``.
    Returns ``False`` (``x`` untouched) when the general solver must decide."""
    K = len(c_lo)
    n = A.shape[1]
    s = n - ns0
    mmax = 0
    for k in range(K):
        mmax = max(mmax, c_hi[k] - c_lo[k])
    Zs = np.empty((K, mmax + 1, 6))  # per limb [J_k b_k], transposed
    pivs = np.empty((K, max(mmax, 1)), dtype=np.int64)
    v0s = np.empty((K, 6))
    vn2s = np.empty((K, 6))
    ranks = np.empty(K, dtype=np.int64)
    scratch = np.empty(max(6, s))
    nred = 0
    for k in range(K):
        m = c_hi[k] - c_lo[k]
        Z = Zs[k]
        for c in range(m):
            for i in range(6):
                Z[c, i] = A[6 * k + i, c_lo[k] + c]
        for i in range(6):
            Z[m, i] = b[6 * k + i]
        r = nb_pivoted_qr(Z, 6, m, m + 1, pivs[k], v0s[k], vn2s[k], scratch)
        if r < 0:
            return False
        ranks[k] = r
        nred += 6 - r
    xi = np.zeros(s)
    e = np.empty(6)
    if s > 0:
        if nred != s:
            return False
        R = np.empty((s + 1, s))  # the reduced system [z_i^T H_k  z_i^T b_k], transposed
        i0 = 0
        for k in range(K):
            m = c_hi[k] - c_lo[k]
            for i in range(ranks[k], 6):
                for a in range(6):  # z_i = Q e_i: the limb's constraint the joints cannot absorb
                    e[a] = 0.0
                e[i] = 1.0
                nb_qt_apply(Zs[k], ranks[k], 6, v0s[k], vn2s[k], e, False)
                for c in range(s):
                    acc = 0.0
                    for a in range(6):
                        acc += e[a] * A[6 * k + a, ns0 + c]
                    R[c, i0] = acc
                R[s, i0] = Zs[k, m, i]
                i0 += 1
        pr = np.empty(s, dtype=np.int64)
        if nb_pivoted_qr(R, s, s, s + 1, pr, np.empty(s), np.empty(s), scratch) != s:
            return False
        for i in range(s - 1, -1, -1):
            acc = R[s, i]
            for c in range(i + 1, s):
                acc -= R[c, i] * xi[pr[c]]
            xi[pr[i]] = acc / R[i, i]
    y = np.empty(max(mmax, 1))
    V = np.empty((6, max(mmax, 1)))
    tv0 = np.empty(6)
    tvn2 = np.empty(6)
    for k in range(K):
        m = c_hi[k] - c_lo[k]
        r = ranks[k]
        Z = Zs[k]
        if s > 0:  # Q^T (b_k - H_k xi), the rows the limb's own joints take
            for a in range(6):
                acc = b[6 * k + a]
                for c in range(s):
                    acc -= A[6 * k + a, ns0 + c] * xi[c]
                e[a] = acc
            nb_qt_apply(Z, r, 6, v0s[k], vn2s[k], e, True)
        else:
            for a in range(6):
                e[a] = Z[m, a]
        if r > 0:
            nb_trapezoid_minnorm(Z, r, m, e, y, V, tv0, tvn2)
        else:
            for j in range(m):
                y[j] = 0.0
        for j in range(m):
            x[c_lo[k] + pivs[k, j]] = y[j]
    for c in range(s):
        x[ns0 + c] = xi[c]
    return True
