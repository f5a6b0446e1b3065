"""Compiled kernels of the performance maps (:mod:`spatialmech.analysis.maps`): the indices of a
complete Jacobian (:func:`nb_indices_many`) and, for models whose limbs all have a closed form
(S-P-S / U-P-S legs, a C-U column), the whole chain from the pose to the indices
(:func:`nb_maps_closed`).  The Python reference is :func:`spatialmech.analysis.maps.pose_indices`
with :func:`~spatialmech.kinematics.jacobian.complete_jacobian`; the two agree to rounding
(``tests/test_maps.py``).

Singular values by one-sided (Hestenes) Jacobi rotations (relative accuracy, no LAPACK call per
pose); determinants of 5x5 minors by :func:`.kernels_se3.nb_det` (LU, partial pivoting).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .kernels_se3 import nb_det

__all__ = ["N_SCALARS", "indices_many", "maps_closed", "nb_indices_many", "nb_maps_closed"]

#: Scalars per pose in ``out``: sigma_min, condition, manipulability, iti, oti, lti, lci.
N_SCALARS = 7


@njit(cache=True)
def nb_singular_values(A, out):
    """Singular values (descending) of ``A`` (m, n) into ``out`` (min(m, n)): one-sided Jacobi."""
    m, n = A.shape
    B = A.copy() if m >= n else A.T.copy()
    r, c = B.shape
    nrm = np.empty(c)
    for _sweep in range(60):
        for j in range(c):  # squared column norms, refreshed each sweep and updated by each rotation
            s = 0.0
            for i in range(r):
                s += B[i, j] * B[i, j]
            nrm[j] = s
        rotated = False
        for p in range(c - 1):
            for q in range(p + 1, c):
                alpha = nrm[p]
                beta = nrm[q]
                gamma = 0.0
                for i in range(r):
                    gamma += B[i, p] * B[i, q]
                if gamma == 0.0 or abs(gamma) <= 1e-15 * np.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / np.sqrt(1.0 + t * t)
                sn = cs * t
                for i in range(r):
                    bp = B[i, p]
                    bq = B[i, q]
                    B[i, p] = cs * bp - sn * bq
                    B[i, q] = sn * bp + cs * bq
                nrm[p] = alpha - t * gamma
                nrm[q] = beta + t * gamma
        if not rotated:
            break
    for j in range(c):
        s = 0.0
        for i in range(r):
            s += B[i, j] * B[i, j]
        out[j] = np.sqrt(s)
    out[:c] = np.sort(out[:c])[::-1]


@njit(cache=True)
def nb_power(W, T, L):
    """Power coefficient of the wrench ``W = (f ; m)`` and the twist ``T = (w ; v)`` (SI):
    :func:`spatialmech.analysis.maps.power_coefficient`."""
    nf = np.sqrt(W[0] ** 2 + W[1] ** 2 + W[2] ** 2)
    nm = np.sqrt(W[3] ** 2 + W[4] ** 2 + W[5] ** 2)
    nw = np.sqrt(T[0] ** 2 + T[1] ** 2 + T[2] ** 2)
    nv = np.sqrt(T[3] ** 2 + T[4] ** 2 + T[5] ** 2)
    couple = nf <= 1e-12 * (nf + nm / L)
    translation = nw <= 1e-12 * (nw + nv / L)
    if couple:
        if translation or nm == 0.0:
            return 0.0
        return min(abs(W[3] * T[0] + W[4] * T[1] + W[5] * T[2]) / (nm * nw), 1.0)
    if translation:
        if nv == 0.0:
            return 0.0
        return min(abs(W[0] * T[3] + W[1] * T[4] + W[2] * T[5]) / (nf * nv), 1.0)
    f0, f1, f2 = W[0] / nf, W[1] / nf, W[2] / nf
    m0, m1, m2 = W[3] / nf, W[4] / nf, W[5] / nf
    w0, w1, w2 = T[0] / nw, T[1] / nw, T[2] / nw
    v0, v1, v2 = T[3] / nw, T[4] / nw, T[5] / nw
    c0, c1, c2 = f1 * w2 - f2 * w1, f2 * w0 - f0 * w2, f0 * w1 - f1 * w0  # f x w
    s = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
    d0 = (w1 * v2 - w2 * v1) - (f1 * m2 - f2 * m1)  # (w x v) - (f x m)
    d1 = (w2 * v0 - w0 * v2) - (f2 * m0 - f0 * m2)
    d2 = (w0 * v1 - w1 * v0) - (f0 * m1 - f1 * m0)
    if s > 1e-12:
        d = abs(d0 * c0 + d1 * c1 + d2 * c2) / s
    else:
        x0, x1, x2 = d1 * f2 - d2 * f1, d2 * f0 - d0 * f2, d0 * f1 - d1 * f0
        d = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
    dmax = max(d, L)
    h = f0 * m0 + f1 * m1 + f2 * m2 + w0 * v0 + w1 * v1 + w2 * v2
    power = abs(f0 * v0 + f1 * v1 + f2 * v2 + m0 * w0 + m1 * w1 + m2 * w2)
    return min(power / np.sqrt(h * h + dmax * dmax), 1.0)


@njit(cache=True)
def nb_pivot(G, c):
    """Swap into row ``c`` the row (from ``c`` down) with the largest ``|G[., c]|``; False if it is 0."""
    piv = c
    for i in range(c + 1, G.shape[0]):
        if abs(G[i, c]) > abs(G[piv, c]):
            piv = i
    if G[piv, c] == 0.0:
        return False
    if piv != c:
        for j in range(G.shape[1]):
            tmp = G[c, j]
            G[c, j] = G[piv, j]
            G[piv, j] = tmp
    return True


@njit(cache=True)
def nb_inverse6(A, X):
    """``X = A^-1`` (6, 6) by Gauss-Jordan elimination with partial pivoting; False if a pivot is 0."""
    n = 6
    G = np.empty((n, 2 * n))
    for i in range(n):
        for j in range(n):
            G[i, j] = A[i, j]
            G[i, n + j] = 1.0 if i == j else 0.0
    for c in range(n):
        if not nb_pivot(G, c):
            return False
        p = G[c, c]
        for j in range(2 * n):
            G[c, j] /= p
        for i in range(n):
            if i != c:
                f = G[i, c]
                if f != 0.0:
                    for j in range(2 * n):
                        G[i, j] -= f * G[c, j]
    for i in range(n):
        for j in range(n):
            X[i, j] = G[i, n + j]
    return True


@njit(cache=True)
def nb_project_out(x, Q, nq):
    """``x`` minus its components along the orthonormal rows ``Q[:nq]`` (twice, for accuracy)."""
    for _twice in range(2):
        for j in range(nq):
            dot = 0.0
            for c in range(6):
                dot += x[c] * Q[j, c]
            for c in range(6):
                x[c] -= dot * Q[j, c]


@njit(cache=True)
def nb_ellipsoids(Jn, Jr, nc, out, vaxes, faxes):
    """Velocity / force ellipsoids on the motion subspace: the actuation rows ``Jn[nc:]`` projected
    off the constraint rows; ``out[2]`` the manipulability."""
    na = 6 - nc
    Q = np.zeros((6, 6))
    nq = 0
    for i in range(nc):
        x = Jr[i].copy()
        nb_project_out(x, Q, nq)
        nx = np.sqrt(np.sum(x * x))
        if nx > 1e-12:
            Q[nq] = x / nx
            nq += 1
    K = np.empty((6, na))
    for a in range(na):
        x = Jn[nc + a].copy()
        nb_project_out(x, Q, nq)
        K[:, a] = x
    fs = np.empty(na)
    nb_singular_values(K, fs)
    prod = 1.0
    for a in range(na):
        faxes[a] = fs[a]
        vaxes[a] = 1.0 / fs[na - 1 - a] if fs[na - 1 - a] > 0.0 else np.inf
        prod *= fs[a]
    out[2] = 1.0 / prod if prod > 0.0 else np.inf


@njit(cache=True)
def nb_cofactor_twist(Jr, i, y):
    """``y_j = (-1)^j det(Jr without row i and column j)``: the twist reciprocal to every other row."""
    minor = np.empty((5, 5))
    for j in range(6):
        r2 = 0
        for r in range(6):
            if r != i:
                c2 = 0
                for c in range(6):
                    if c != j:
                        minor[r2, c2] = Jr[r, c]
                        c2 += 1
                r2 += 1
        y[j] = (-1.0) ** j * nb_det(minor)


@njit(cache=True)
def nb_transmission(M, Jr, sigma_min, nc, inputs, L, out):
    """ITI, OTI, LTI, LCI into ``out[3:7]``: power coefficients of each row's wrench with the
    actuated joint's twist (ITI) and with the twist reciprocal to every other row (OTI, LCI)."""
    na = 6 - nc
    W = np.empty(6)
    iti = 1.0
    for a in range(na):
        for c in range(3):
            W[c] = M[nc + a, 3 + c]
            W[3 + c] = M[nc + a, c]
        iti = min(iti, nb_power(W, inputs[a], L))
    oti = 1.0
    lci = 1.0
    y = np.empty(6)
    T = np.empty(6)
    X = np.empty((6, 6))
    # column i of Jr^-1 is the cofactor twist up to scale and sign (which the power coefficient
    # ignores); near a singularity the cofactors themselves
    by_inverse = sigma_min > 1e-6 and nb_inverse6(Jr, X)
    for i in range(6):
        if by_inverse:
            y[:] = X[:, i]
        else:
            nb_cofactor_twist(Jr, i, y)
        ny = np.sqrt(np.sum(y * y))
        for c in range(3):
            W[c] = M[i, 3 + c]
            W[3 + c] = M[i, c]
            T[c] = y[c]
            T[3 + c] = y[3 + c] * L
        z = nb_power(W, T, L) if ny > 1e-13 else 0.0
        if i < nc:
            lci = min(lci, z)
        else:
            oti = min(oti, z)
    out[3] = iti
    out[4] = oti
    out[5] = min(iti, oti)
    out[6] = lci if nc > 0 else 0.0


@njit(cache=True)
def nb_indices(M, nc, inputs, act_scale, L, out, vaxes, faxes):
    """The indices of one square complete Jacobian ``M`` (6, 6) (rows ``(moment ; force)``, the
    first ``nc`` the constraints), the actuated joints' twists ``inputs`` (na, 6) and the rate
    scale of each actuator (L for a slide, 1 for a rotation): :func:`..analysis.maps.pose_indices`."""
    Jn = M.copy()
    Jn[:, 3:] *= L
    for a in range(6 - nc):
        Jn[nc + a] /= act_scale[a]
    Jr = Jn.copy()
    for i in range(6):
        s = np.sqrt(np.sum(Jr[i] * Jr[i]))
        if s > 0.0:
            Jr[i] /= s
    sv = np.empty(6)
    nb_singular_values(Jr, sv)
    out[0] = sv[5]
    out[1] = sv[5] / sv[0] if sv[0] > 0.0 else 0.0
    nb_ellipsoids(Jn, Jr, nc, out, vaxes, faxes)
    nb_transmission(M, Jr, sv[5], nc, inputs, L, out)


@njit(cache=True)
def nb_indices_many(Ms, nc, inputs, act_scale, L, out, vaxes, faxes):
    """:func:`nb_indices` of many Jacobians ``Ms`` (N, 6, 6) and inputs (N, na, 6)."""
    for s in range(Ms.shape[0]):
        nb_indices(Ms[s], nc, inputs[s], act_scale, L, out[s], vaxes[s], faxes[s])


@njit(cache=True)
def nb_block_max(A, r, c):
    """Largest ``|A[r:, c:]|``."""
    big = 0.0
    for i in range(r, A.shape[0]):
        for cc in range(c, A.shape[1]):
            big = max(big, abs(A[i, cc]))
    return big


@njit(cache=True)
def nb_eliminate(A, r, c):
    """Scale row ``r`` to a unit pivot in column ``c`` and clear that column elsewhere."""
    rows, cols = A.shape
    p = A[r, c]
    for cc in range(cols):
        A[r, cc] /= p
    for i in range(rows):
        if i != r:
            f = A[i, c]
            for cc in range(cols):
                A[i, cc] -= f * A[r, cc]
            A[i, c] = 0.0
    A[r, c] = 1.0


@njit(cache=True)
def nb_rref_rows(A, rank_tol, pivot_tol):
    """:func:`..geometry.screws.rref` of the rows of ``A`` (r, 6) in place; returns the rank."""
    rows, cols = A.shape
    floor = rank_tol * nb_block_max(A, np.int64(0), np.int64(0))
    r = 0
    for c in range(cols):
        if r == rows:
            break
        big = nb_block_max(A, r, c)
        if big <= floor:
            break
        piv = r
        for i in range(r + 1, rows):
            if abs(A[i, c]) > abs(A[piv, c]):
                piv = i
        if abs(A[piv, c]) < pivot_tol * big:
            continue
        for cc in range(cols):
            tmp = A[r, cc]
            A[r, cc] = A[piv, cc]
            A[piv, cc] = tmp
        nb_eliminate(A, r, c)
        r += 1
    return r


@njit(cache=True)
def nb_cu_rows(R, p, pb, e1, e2, L, rank_tol, pivot_tol, M, row):
    """The two constraint rows of a C-U column at ``M[row]``, ``M[row + 1]``: forces through the
    U centre ``R pb + p`` perpendicular to the column, basis in reduced row-echelon form."""
    C = np.empty((2, 6))
    u = np.empty(3)
    for c in range(3):
        u[c] = R[c, 0] * pb[0] + R[c, 1] * pb[1] + R[c, 2] * pb[2] + p[c]
    for b in range(2):
        e = e1 if b == 0 else e2
        C[b, 0] = e[0]
        C[b, 1] = e[1]
        C[b, 2] = e[2]
        C[b, 3] = (u[1] * e[2] - u[2] * e[1]) / L
        C[b, 4] = (u[2] * e[0] - u[0] * e[2]) / L
        C[b, 5] = (u[0] * e[1] - u[1] * e[0]) / L
    good = nb_rref_rows(C, rank_tol, pivot_tol) == 2
    for b in range(2):
        for c in range(3):  # matrix row: (moment ; force)
            M[row + b, c] = C[b, 3 + c] * L
            M[row + b, 3 + c] = C[b, c]
    return good


@njit(cache=True)
def nb_maps_closed(R, p, kind, pa, pb, e1, e2, act_limb, act_scale, nc, L, rank_tol, pivot_tol, out, vaxes, faxes,
                   ok):
    """Poses ``(R, p)`` (platform point) to the indices, for limbs with a closed form: ``kind[k]``
    0 (an S-P-S / U-P-S leg from the base centre ``pa[k]`` to the platform centre ``R pb[k] + p``,
    actuated along the leg) or 1 (a C-U column: constraint forces through ``R pb[k] + p``
    perpendicular to the column, spanned by ``e1[k]``, ``e2[k]``, basis put in reduced row-echelon
    form as :func:`..jacobian.limb_constraint_wrenches` does).  ``ok[s]`` False: a degenerate
    pose (a leg of zero length, a constraint basis of the wrong rank); the caller decides."""
    na = act_limb.shape[0]
    M = np.empty((6, 6))
    inp = np.zeros((na, 6))
    for s in range(R.shape[0]):
        ok[s] = True
        row = 0
        for k in range(kind.shape[0]):
            if kind[k] == 1:
                if not nb_cu_rows(R[s], p[s], pb[k], e1[k], e2[k], L, rank_tol, pivot_tol, M, row):
                    ok[s] = False
                row += 2
        if row != nc:
            ok[s] = False
            continue
        for a in range(na):
            k = act_limb[a]
            B = pa[k]
            d = np.empty(3)
            for c in range(3):
                d[c] = R[s, c, 0] * pb[k, 0] + R[s, c, 1] * pb[k, 1] + R[s, c, 2] * pb[k, 2] + p[s, c] - B[c]
            ln = np.sqrt(np.sum(d * d))
            if not ln > 1e-12 * L:
                ok[s] = False
                break
            u = d / ln
            mom = np.cross(B, u)
            for c in range(3):
                M[nc + a, c] = mom[c]
                M[nc + a, 3 + c] = u[c]
                inp[a, c] = 0.0
                inp[a, 3 + c] = u[c]
        if not ok[s]:
            continue
        nb_indices(M, nc, inp, act_scale, L, out[s], vaxes[s], faxes[s])


def indices_many(Ms, nc: int, inputs, act_scale, L: float):
    """``(out (N, 7), velocity axes (N, na), force axes (N, na))`` of Jacobians ``Ms`` (N, 6, 6)."""
    Ms = np.ascontiguousarray(Ms, dtype=float)
    N = Ms.shape[0]
    na = 6 - int(nc)
    out = np.zeros((N, N_SCALARS))
    va = np.zeros((N, na))
    fa = np.zeros((N, na))
    nb_indices_many(Ms, np.int64(nc), np.ascontiguousarray(inputs, dtype=float), np.ascontiguousarray(act_scale, dtype=float),
                    float(L), out, va, fa)
    return out, va, fa


def maps_closed(R, p, plan: dict, L: float, rank_tol: float, pivot_tol: float):
    """:func:`nb_maps_closed` over poses ``R`` (N, 3, 3), ``p`` (N, 3); ``plan``: the arrays of
    :func:`spatialmech.analysis.maps.closed_form_plan`.  Returns ``(out, vaxes, faxes, ok)``."""
    R = np.ascontiguousarray(R, dtype=float)
    p = np.ascontiguousarray(p, dtype=float)
    N = R.shape[0]
    na = plan["act_limb"].shape[0]
    out = np.zeros((N, N_SCALARS))
    va = np.zeros((N, na))
    fa = np.zeros((N, na))
    ok = np.zeros(N, dtype=np.bool_)
    nb_maps_closed(R, p, plan["kind"], plan["pa"], plan["pb"], plan["e1"], plan["e2"], plan["act_limb"],
                   plan["act_scale"], np.int64(plan["nc"]), float(L), float(rank_tol), float(pivot_tol), out, va, fa, ok)
    return out, va, fa, ok
