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
def nb_singular_values(A, B, out):
    """Singular values (descending) of ``A`` (m, n), ``m <= n``, into ``out[:m]``: one-sided
    (Hestenes) Jacobi rotations of its rows (sv(A) = sv(A^T): contiguous rows), in the scratch
    ``B`` (at least (m, n)), no allocation; rows whose cosine is below 1e-15 count as orthogonal."""
    m, n = A.shape
    for i in range(m):
        for j in range(n):
            B[i, j] = A[i, j]
    for _sweep in range(60):
        worst = 0.0  # the largest |cos| between two rows that this sweep rotated
        for p in range(m - 1):
            for q in range(p + 1, m):
                alpha = 0.0
                beta = 0.0
                gamma = 0.0
                for j in range(n):
                    bp = B[p, j]
                    bq = B[q, j]
                    alpha += bp * bp
                    beta += bq * bq
                    gamma += bp * bq
                if gamma == 0.0:
                    continue
                cosine = abs(gamma) / np.sqrt(alpha * beta)
                if cosine <= 1e-15:
                    continue
                worst = max(worst, cosine)
                zeta = (beta - alpha) / (2.0 * gamma)
                t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / np.sqrt(1.0 + t * t)
                sn = cs * t
                for j in range(n):
                    bp = B[p, j]
                    bq = B[q, j]
                    B[p, j] = cs * bp - sn * bq
                    B[q, j] = sn * bp + cs * bq
        # a sweep whose rotations were all below 1e-8 leaves every pair orthogonal to ~1e-16 (each
        # rotation zeroes its pair and moves the others by products of two such cosines): no
        # confirming sweep needed
        if worst < 1e-8:
            break
    for i in range(m):
        s = 0.0
        for j in range(n):
            s += B[i, j] * B[i, j]
        out[i] = np.sqrt(s)
    for i in range(1, m):  # insertion sort, descending
        v = out[i]
        k = i - 1
        while k >= 0 and out[k] < v:
            out[k + 1] = out[k]
            k -= 1
        out[k + 1] = v


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
def nb_inverse6(A, G, X):
    """``X = A^-1`` (6, 6) by Gauss-Jordan elimination with partial pivoting, ``G`` (6, 6) scratch
    (ends as the identity); False if a pivot is 0."""
    n = 6
    for i in range(n):
        for j in range(n):
            G[i, j] = A[i, j]
            X[i, j] = 1.0 if i == j else 0.0
    for c in range(n):
        piv = c
        for i in range(c + 1, n):
            if abs(G[i, c]) > abs(G[piv, c]):
                piv = i
        if G[piv, c] == 0.0:
            return False
        if piv != c:
            for j in range(n):
                tmp = G[c, j]
                G[c, j] = G[piv, j]
                G[piv, j] = tmp
                tmp = X[c, j]
                X[c, j] = X[piv, j]
                X[piv, j] = tmp
        p = G[c, c]
        for j in range(n):
            G[c, j] /= p
            X[c, j] /= p
        for i in range(n):
            if i != c:
                f = G[i, c]
                if f != 0.0:
                    for j in range(n):
                        G[i, j] -= f * G[c, j]
                        X[i, j] -= f * X[c, j]
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
def nb_ellipsoids(Jn, Jr, nc, out, vaxes, faxes, work, vec):
    """Velocity / force ellipsoids on the motion subspace: the actuation rows ``Jn[nc:]`` projected
    off the constraint rows; ``out[2]`` the manipulability.  Scratch: ``work`` (>= 3, 6, 6),
    ``vec`` (>= 1, 6)."""
    na = 6 - nc
    Q = work[0]
    Kt = work[1]  # rows: the projected actuation rows (the columns of K)
    nq = 0
    for i in range(nc):
        for c in range(6):
            Q[nq, c] = Jr[i, c]
        nb_project_out(Q[nq], Q, nq)
        nx = 0.0
        for c in range(6):
            nx += Q[nq, c] * Q[nq, c]
        nx = np.sqrt(nx)
        if nx > 1e-12:
            for c in range(6):
                Q[nq, c] /= nx
            nq += 1
    for a in range(na):
        for c in range(6):
            Kt[a, c] = Jn[nc + a, c]
        nb_project_out(Kt[a], Q, nq)
    fs = vec[0]
    nb_singular_values(Kt[:na], work[2], fs)
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
def nb_transmission(M, Jr, sigma_min, nc, inputs, L, out, work, vec):
    """ITI, OTI, LTI, LCI into ``out[3:7]``: power coefficients of each row's wrench with the
    actuated joint's twist (ITI) and with the twist reciprocal to every other row (OTI, LCI).
    Scratch: ``work`` (>= 2, 6, 6), ``vec`` (>= 3, 6)."""
    na = 6 - nc
    W = vec[0]
    y = vec[1]
    T = vec[2]
    iti = 1.0
    for a in range(na):
        for c in range(3):
            W[c] = M[nc + a, 3 + c]
            W[3 + c] = M[nc + a, c]
        iti = min(iti, nb_power(W, inputs[a], L))
    oti = 1.0
    lci = 1.0
    X = work[0]
    # column i of Jr^-1 is the cofactor twist up to scale and sign (which the power coefficient
    # ignores); near a singularity the cofactors themselves
    by_inverse = sigma_min > 1e-6 and nb_inverse6(Jr, work[1], X)
    for i in range(6):
        if by_inverse:
            for c in range(6):
                y[c] = X[c, i]
        else:
            nb_cofactor_twist(Jr, i, y)
        ny = 0.0
        for c in range(3):
            W[c] = M[i, 3 + c]
            W[3 + c] = M[i, c]
            T[c] = y[c]
            T[3 + c] = y[3 + c] * L
            ny += y[c] * y[c] + y[3 + c] * y[3 + c]
        z = nb_power(W, T, L) if np.sqrt(ny) > 1e-13 else 0.0
        if i < nc:
            lci = min(lci, z)
        else:
            oti = min(oti, z)
    out[3] = iti
    out[4] = oti
    out[5] = min(iti, oti)
    out[6] = lci if nc > 0 else 0.0


@njit(cache=True)
def nb_indices(M, nc, inputs, act_scale, L, out, vaxes, faxes, work, vec):
    """The indices of one square complete Jacobian ``M`` (6, 6) (rows ``(moment ; force)``, the
    first ``nc`` the constraints), the actuated joints' twists ``inputs`` (na, 6) and the rate
    scale of each actuator (L for a slide, 1 for a rotation): :func:`..analysis.maps.pose_indices`.
    Scratch (allocated once by the caller): ``work`` (5, 6, 6), ``vec`` (4, 6)."""
    Jn = work[3]
    Jr = work[4]
    for i in range(6):
        s = 1.0 if i < nc else act_scale[i - nc]
        nrm = 0.0
        for c in range(6):
            v = (M[i, c] if c < 3 else M[i, c] * L) / s
            Jn[i, c] = v
            nrm += v * v
        nrm = np.sqrt(nrm)
        for c in range(6):
            Jr[i, c] = Jn[i, c] / nrm if nrm > 0.0 else Jn[i, c]
    sv = vec[3]
    nb_singular_values(Jr, work[0], sv)
    out[0] = sv[5]
    out[1] = sv[5] / sv[0] if sv[0] > 0.0 else 0.0
    nb_ellipsoids(Jn, Jr, nc, out, vaxes, faxes, work, vec)
    nb_transmission(M, Jr, sv[5], nc, inputs, L, out, work, vec)


@njit(cache=True)
def nb_indices_many(Ms, nc, inputs, act_scale, L, out, vaxes, faxes):
    """:func:`nb_indices` of many Jacobians ``Ms`` (N, 6, 6) and inputs (N, na, 6)."""
    work = np.empty((5, 6, 6))
    vec = np.empty((4, 6))
    for s in range(Ms.shape[0]):
        nb_indices(Ms[s], nc, inputs[s], act_scale, L, out[s], vaxes[s], faxes[s], work, vec)


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
def nb_cu_rows(R, p, pb, e1, e2, L, rank_tol, pivot_tol, M, row, C):
    """The two constraint rows of a C-U column at ``M[row]``, ``M[row + 1]``: forces through the
    U centre ``R pb + p`` perpendicular to the column, basis in reduced row-echelon form
    (``C`` (2, 6) scratch)."""
    u0 = R[0, 0] * pb[0] + R[0, 1] * pb[1] + R[0, 2] * pb[2] + p[0]
    u1 = R[1, 0] * pb[0] + R[1, 1] * pb[1] + R[1, 2] * pb[2] + p[1]
    u2 = R[2, 0] * pb[0] + R[2, 1] * pb[1] + R[2, 2] * pb[2] + p[2]
    for b in range(2):
        e = e1 if b == 0 else e2
        C[b, 0] = e[0]
        C[b, 1] = e[1]
        C[b, 2] = e[2]
        C[b, 3] = (u1 * e[2] - u2 * e[1]) / L
        C[b, 4] = (u2 * e[0] - u0 * e[2]) / L
        C[b, 5] = (u0 * e[1] - u1 * e[0]) / L
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
    pose (a leg of zero length, a constraint basis of the wrong rank); the caller decides.
    Every scratch array is allocated once, before the loop."""
    na = act_limb.shape[0]
    M = np.empty((6, 6))
    inp = np.zeros((na, 6))
    C = np.empty((2, 6))
    work = np.empty((5, 6, 6))
    vec = np.empty((4, 6))
    for s in range(R.shape[0]):
        ok[s] = True
        Rs = R[s]
        ps = p[s]
        row = 0
        for k in range(kind.shape[0]):
            if kind[k] == 1:
                if not nb_cu_rows(Rs, ps, pb[k], e1[k], e2[k], L, rank_tol, pivot_tol, M, row, C):
                    ok[s] = False
                row += 2
        if row != nc:
            ok[s] = False
            continue
        for a in range(na):
            k = act_limb[a]
            B = pa[k]
            P = pb[k]
            d0 = Rs[0, 0] * P[0] + Rs[0, 1] * P[1] + Rs[0, 2] * P[2] + ps[0] - B[0]
            d1 = Rs[1, 0] * P[0] + Rs[1, 1] * P[1] + Rs[1, 2] * P[2] + ps[1] - B[1]
            d2 = Rs[2, 0] * P[0] + Rs[2, 1] * P[1] + Rs[2, 2] * P[2] + ps[2] - B[2]
            ln = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if not ln > 1e-12 * L:
                ok[s] = False
                break
            u0 = d0 / ln
            u1 = d1 / ln
            u2 = d2 / ln
            M[nc + a, 0] = B[1] * u2 - B[2] * u1  # moment B x u
            M[nc + a, 1] = B[2] * u0 - B[0] * u2
            M[nc + a, 2] = B[0] * u1 - B[1] * u0
            M[nc + a, 3] = u0
            M[nc + a, 4] = u1
            M[nc + a, 5] = u2
            inp[a, 3] = u0
            inp[a, 4] = u1
            inp[a, 5] = u2
        if not ok[s]:
            continue
        nb_indices(M, nc, inp, act_scale, L, out[s], vaxes[s], faxes[s], work, vec)


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
