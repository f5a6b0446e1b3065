"""The continuation tracker's step test, compiled (:func:`spatialmech.kinematics.tracking.track`).

At an accepted point the Python reference takes a full SVD of the nondimensional closure
Jacobian ``A`` (``n x (n + 1)``) for the unit tangent (its null vector) and for Keller's
orientation test (the sign of ``det [A; t]``).  Where ``A`` has full row rank the step needs
less: one LU factorisation (partial pivoting) of the bordered matrix ``M = [A; t_prev]`` gives

- the tangent: ``M z = e_(n+1)`` puts ``z`` in the null space of ``A`` with ``t_prev . z = 1``,
  so ``z / |z|`` is the unit tangent already in the sense of travel (no SVD sign involved);
- the orientation: ``det [A; v]`` is linear in ``v`` and proportional to the null vector's
  component on ``v``, so the sign of ``det M`` is the sign of ``det [A; t]`` for the oriented
  unit tangent ``t``;
- a certificate of the rank: ``sigma_n(A) >= sigma_min(M) >= 1 / |M^-1|_F`` (interlacing), and
  ``sigma_1(A) <= |A|_F``; the caller uses the LU result only when this bound puts ``A``'s
  rank beyond doubt under the reference's rank test, and the reference SVD otherwise.
"""

from __future__ import annotations

import numpy as np

from .jit import njit

__all__ = ["bordered_tangent", "nb_bordered_tangent", "nb_lu_sign"]


@njit(cache=True)
def nb_lu_sign(M, piv):  # pragma: no cover - compiled
    """In-place LU of the square ``M`` with partial pivoting (row order in ``piv``); returns the
    sign of ``det M``, ``0.0`` when a pivot column is zero."""
    n1 = M.shape[0]
    sign = 1.0
    for k in range(n1):
        p = k
        for i in range(k + 1, n1):
            if abs(M[i, k]) > abs(M[p, k]):
                p = i
        if M[p, k] == 0.0:
            return 0.0
        if p != k:
            for j in range(n1):
                tmp = M[k, j]
                M[k, j] = M[p, j]
                M[p, j] = tmp
            tmp_i = piv[k]
            piv[k] = piv[p]
            piv[p] = tmp_i
            sign = -sign
        if M[k, k] < 0.0:
            sign = -sign
        for i in range(k + 1, n1):
            f = M[i, k] / M[k, k]
            M[i, k] = f
            for j in range(k + 1, n1):
                M[i, j] -= f * M[k, j]
    return sign


@njit(cache=True)
def _lu_inverse_fro(M, piv, Y, z):  # pragma: no cover - compiled
    """``|M0^-1|_F^2`` and ``z`` <- its last column, from the LU of :func:`nb_lu_sign`: the whole
    inverse solved row by row for all columns at once (independent chains that vectorise), each
    entry by the operations of its own column's solve.  Column ``c`` of the inverse is kept in
    ``Y[:, k]`` with ``piv[k] = c``: its entries above row ``k`` are exactly zero through the
    forward substitution (``L`` is unit lower triangular), so that pass skips them (a third of
    the dense pass); the squares are summed over each column in row order, then over the columns
    in their order."""
    n1 = M.shape[0]
    for i in range(n1):
        for k in range(n1):
            Y[i, k] = 1.0 if k == i else 0.0
        for j in range(i):
            f = M[i, j]
            for k in range(j + 1):
                Y[i, k] -= f * Y[j, k]
    for i in range(n1 - 1, -1, -1):
        for j in range(i + 1, n1):
            f = M[i, j]
            for k in range(n1):
                Y[i, k] -= f * Y[j, k]
        d = M[i, i]
        for k in range(n1):
            Y[i, k] = Y[i, k] / d
    acc = np.zeros(n1)
    for i in range(n1):
        for k in range(n1):
            acc[k] += Y[i, k] * Y[i, k]
    col_of = np.empty(n1, dtype=np.int64)  # the column of the inverse held in Y[:, k]
    for k in range(n1):
        col_of[piv[k]] = k
    tot = 0.0
    for c in range(n1):
        tot += acc[col_of[c]]
    last = col_of[n1 - 1]
    for i in range(n1):
        z[i] = Y[i, last]
    return tot


@njit(cache=True)
def nb_bordered_tangent(A, t, M, z, info):  # pragma: no cover - compiled
    """LU of ``M = [A; t]`` (scratch ``M``, ``(n + 1, n + 1)``): ``z`` <- the unit solution of
    ``M z = e_(n+1)``; ``info`` <- (1 if ``M`` is nonsingular else 0, sign of ``det M``,
    ``1 / |M^-1|_F``, ``|A|_F``)."""
    n = A.shape[0]
    n1 = A.shape[1]
    M[:n, :] = A
    M[n, :] = t
    info[:] = 0.0
    info[3] = np.sqrt(np.sum(A * A))
    piv = np.arange(n1)
    sign = nb_lu_sign(M, piv)
    if sign == 0.0:
        return
    # |M^-1|_F from the solutions of M x = e_c for every column c (the last one is z)
    fro = _lu_inverse_fro(M, piv, np.empty((n1, n1)), z)
    zn = np.sqrt(np.sum(z * z))
    if not (zn > 0.0 and np.isfinite(fro)):
        return
    z /= zn
    info[0] = 1.0
    info[1] = sign
    info[2] = 1.0 / np.sqrt(fro)


def bordered_tangent(A: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, float, float, float] | None:
    """``(unit tangent, sign of det [A; tangent], lower bound of sigma_n(A), |A|_F)`` from one
    LU of ``[A; t]`` (``A``: ``n x (n + 1)``; ``t``: the previous unit tangent), or ``None``
    when that matrix is singular to working precision."""
    A = np.ascontiguousarray(A, dtype=np.float64)
    tt = np.ascontiguousarray(t, dtype=np.float64)
    n1 = A.shape[1]
    M = np.empty((n1, n1))
    z = np.empty(n1)
    info = np.zeros(4)
    nb_bordered_tangent(A, tt, M, z, info)
    if info[0] != 1.0:
        return None
    return z, float(info[1]), float(info[2]), float(info[3])
