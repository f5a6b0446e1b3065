"""The compiled evaluation of the loop formulation's square system (:mod:`.loop_system`):
the same equations as :meth:`.loop_system.LoopSystem.square` (the NumPy reference, which
runs under ``SPATIALMECH_PURE=1``), point by point in numba.

The system is packed once into flat arrays (:func:`pack`): every chain of factors (the reference
limb, and each limb's factors before and after its S joints) as ranges of one factor table
(kind, sign, variable indices, twist matrix ``A`` and ``A^2``), each limb's equation kind,
chains, centres and rod length, the Study forms, the circles, the patch and the compression.
"""

from __future__ import annotations

import numpy as np

from .jit import njit

__all__ = ["pack", "square_batch"]


def pack(sysm, study_q: np.ndarray) -> tuple:
    """The arguments of :func:`square_batch` for a :class:`.homotopy_general.LoopSystem`."""
    chains = []
    if sysm.ref is not None:
        chains.append(sysm.ref)
    for le in sysm.limbs:
        chains.append(le.before)
        chains.append(le.after_inv)
    kind: list[int] = []
    sign: list[float] = []
    i0: list[int] = []
    i1: list[int] = []
    A: list[np.ndarray] = []
    A2: list[np.ndarray] = []
    lo: list[int] = []
    hi: list[int] = []
    for ch in chains:
        lo.append(len(kind))
        for f in ch:
            kind.append(0 if f.kind == "R" else 1)
            sign.append(-1.0 if f.inverse else 1.0)
            i0.append(f.idx[0])
            i1.append(f.idx[1] if len(f.idx) > 1 else -1)
            A.append(f.A)
            A2.append(f.A2)
        hi.append(len(kind))
    off = 1 if sysm.ref is not None else 0
    lk = np.array([{"full": 0, "point": 1, "rod": 2}[le.kind] for le in sysm.limbs], np.int64)
    c1 = np.array([le.c1 for le in sysm.limbs], float).reshape(-1, 4)
    c2 = np.array([le.c2 for le in sysm.limbs], float).reshape(-1, 4)
    l2 = np.array([le.length2 for le in sysm.limbs], float)
    circ = np.array(sysm.circles, np.int64).reshape(-1, 2)
    patch = sysm.patch if sysm.patch is not None else np.zeros(8, complex)
    return (np.array(kind, np.int64), np.array(sign, float), np.array(i0, np.int64), np.array(i1, np.int64),
            np.array(A, float).reshape(-1, 4, 4), np.array(A2, float).reshape(-1, 4, 4),
            np.array(lo, np.int64), np.array(hi, np.int64), off, 0 if sysm.ref is not None else -1, sysm.study,
            np.ascontiguousarray(study_q), lk, c1, c2, l2, circ, np.ascontiguousarray(patch, dtype=np.complex128),
            np.ascontiguousarray(sysm.compress, dtype=np.complex128), sysm.nx, np.array(sysm.w_offsets, np.int64))


@njit(cache=True)
def _chain(kind, sign, i0, i1, A, A2, lo, hi, z, T, dT, nzd):
    for a in range(4):
        for b in range(4):
            T[a, b] = 1.0 if a == b else 0.0
    dT[:] = 0.0
    M = np.empty((4, 4), np.complex128)
    tmp = np.empty((4, 4), np.complex128)
    for f in range(lo, hi):
        sg = sign[f]
        if kind[f] == 0:
            c = z[i0[f]]
            s = z[i1[f]]
            for a in range(4):
                for b in range(4):
                    M[a, b] = (1.0 if a == b else 0.0) + sg * s * A[f, a, b] + (1.0 - c) * A2[f, a, b]
        else:
            d = z[i0[f]]
            for a in range(4):
                for b in range(4):
                    M[a, b] = (1.0 if a == b else 0.0) + sg * d * A[f, a, b]
        for k in range(nzd):  # dT <- dT M
            for a in range(4):
                for b in range(4):
                    acc = 0.0j
                    for e in range(4):
                        acc += dT[k, a, e] * M[e, b]
                    tmp[a, b] = acc
            dT[k] = tmp
        for a in range(4 if nzd > 0 else 0):  # + T dM
            for b in range(4):
                if kind[f] == 0:
                    acc_c = 0.0j
                    acc_s = 0.0j
                    for e in range(4):
                        acc_c -= T[a, e] * A2[f, e, b]
                        acc_s += T[a, e] * A[f, e, b]
                    dT[i0[f], a, b] += acc_c
                    dT[i1[f], a, b] += sg * acc_s
                else:
                    acc = 0.0j
                    for e in range(4):
                        acc += T[a, e] * A[f, e, b]
                    dT[i0[f], a, b] += sg * acc
        for a in range(4):
            for b in range(4):
                acc = 0.0j
                for e in range(4):
                    acc += T[a, e] * M[e, b]
                tmp[a, b] = acc
        T[:] = tmp


@njit(cache=True)
def square_batch(Z, W, want_J, kind, sign, i0, i1, A, A2, lo, hi, off, ref, study, Q, lk, c1, c2, l2, circ, patch, C,
                 nx, woff):
    """The square system ``G`` (n, nx) and its derivative (n, nx, nz) at points ``Z`` (n, nz),
    with the offset parameters ``W`` (n, nw); the derivative of the closure rows only with ``want_J`` (else left zero)."""
    n, nz = Z.shape
    nzd = nz if want_J else 0
    r = C.shape[1]
    nside = circ.shape[0] + (2 if study >= 0 else 0)
    F = np.zeros((n, nx), np.complex128)
    J = np.zeros((n, nx, nz), np.complex128)
    D = np.empty((4, 4), np.complex128)
    dD = np.empty((nz, 4, 4), np.complex128)
    Tb = np.empty((4, 4), np.complex128)
    dTb = np.empty((nz, 4, 4), np.complex128)
    Ta = np.empty((4, 4), np.complex128)
    dTa = np.empty((nz, 4, 4), np.complex128)
    rows = np.empty(r, np.complex128)
    drows = np.empty((r, nz), np.complex128)
    dE = np.empty(nz, np.complex128)
    w = np.empty(3, np.complex128)
    dw = np.empty((nz, 3), np.complex128)
    Eq = np.empty((3, 3), np.complex128)
    Bq = np.empty((3, 3), np.complex128)
    dBq = np.empty((nz, 3, 3), np.complex128)
    for p in range(n):
        z = Z[p]
        dE[:] = 0.0
        if ref >= 0:
            _chain(kind, sign, i0, i1, A, A2, lo[ref], hi[ref], z, D, dD, nzd)
            E = 1.0 + 0.0j
        else:
            dD[:] = 0.0
            E = 0.0j
            for i in range(4):
                E += z[study + i] * z[study + i]
                dE[study + i] = 2.0 * z[study + i]
            for a in range(4):
                for b in range(4):
                    acc = 0.0j
                    for i in range(8):
                        zi = z[study + i]
                        for j in range(8):
                            q = Q[a, b, i, j]
                            if q != 0.0:
                                acc += zi * q * z[study + j]
                                dD[study + i, a, b] += q * z[study + j]
                                dD[study + j, a, b] += q * zi
                    D[a, b] = acc
        row = 0
        for k in range(lk.shape[0]):
            cb = off + 2 * k
            _chain(kind, sign, i0, i1, A, A2, lo[cb], hi[cb], z, Tb, dTb, nzd)
            wk = W[p, woff[k] : woff[k + 1]]
            if lk[k] == 0:
                qw, qi, qj, qk = wk[0], wk[1], wk[2], wk[3]
                Eq[0, 0] = qw * qw + qi * qi - qj * qj - qk * qk
                Eq[0, 1] = 2.0 * (qi * qj - qw * qk)
                Eq[0, 2] = 2.0 * (qi * qk + qw * qj)
                Eq[1, 0] = 2.0 * (qi * qj + qw * qk)
                Eq[1, 1] = qw * qw - qi * qi + qj * qj - qk * qk
                Eq[1, 2] = 2.0 * (qj * qk - qw * qi)
                Eq[2, 0] = 2.0 * (qi * qk - qw * qj)
                Eq[2, 1] = 2.0 * (qj * qk + qw * qi)
                Eq[2, 2] = qw * qw - qi * qi - qj * qj + qk * qk
                for a in range(3):  # B = R_D E(q), dB
                    for b in range(3):
                        acc = 0.0j
                        for e in range(3):
                            acc += D[a, e] * Eq[e, b]
                        Bq[a, b] = acc
                        for v in range(nzd):
                            acc = 0.0j
                            for e in range(3):
                                acc += dD[v, a, e] * Eq[e, b]
                            dBq[v, a, b] = acc
                for m in range(3):
                    i = 0 if m < 2 else 1
                    j = 1 if m == 0 else 2
                    acc = 0.0j
                    for a in range(3):
                        acc += Tb[a, i] * Bq[a, j]
                    rows[row + m] = acc
                    for v in range(nzd):
                        acc = 0.0j
                        for a in range(3):
                            acc += dTb[v, a, i] * Bq[a, j] + Tb[a, i] * dBq[v, a, j]
                        drows[row + m, v] = acc
                for a in range(3):
                    acc = E * Tb[a, 3] - D[a, 3]
                    for e in range(3):
                        acc -= D[a, e] * wk[4 + e]
                    rows[row + 3 + a] = acc
                    for v in range(nzd):
                        acc = E * dTb[v, a, 3] + dE[v] * Tb[a, 3] - dD[v, a, 3]
                        for e in range(3):
                            acc -= dD[v, a, e] * wk[4 + e]
                        drows[row + 3 + a, v] = acc
                row += 6
                continue
            _chain(kind, sign, i0, i1, A, A2, lo[cb + 1], hi[cb + 1], z, Ta, dTa, nzd)
            vv = np.zeros(4, np.complex128)
            for a in range(4):
                for b in range(4):
                    vv[a] += Ta[a, b] * c2[k, b]
            for a in range(3):
                u1 = 0.0j
                u2 = 0.0j
                for b in range(4):
                    u1 += Tb[a, b] * c1[k, b]
                    u2 += D[a, b] * vv[b]
                w[a] = E * u1 - u2
                for v in range(nzd):
                    du1 = 0.0j
                    du2 = 0.0j
                    for b in range(4):
                        du1 += dTb[v, a, b] * c1[k, b]
                        dv = 0.0j
                        for e in range(4):
                            dv += dTa[v, b, e] * c2[k, e]
                        du2 += dD[v, a, b] * vv[b] + D[a, b] * dv
                    dw[v, a] = E * du1 + dE[v] * u1 - du2
            if lk[k] == 1:
                for a in range(3):
                    rows[row + a] = w[a] - E * wk[a]
                    for v in range(nzd):
                        drows[row + a, v] = dw[v, a] - dE[v] * wk[a]
                row += 3
            else:
                lsq = l2[k] + wk[0]
                rows[row] = w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - E * E * lsq
                for v in range(nzd):
                    drows[row, v] = 2.0 * (w[0] * dw[v, 0] + w[1] * dw[v, 1] + w[2] * dw[v, 2]) - 2.0 * E * lsq * dE[v]
                row += 1
        for i in range(circ.shape[0]):
            a = circ[i, 0]
            b = circ[i, 1]
            F[p, i] = z[a] * z[a] + z[b] * z[b] - 1.0
            J[p, i, a] = 2.0 * z[a]
            J[p, i, b] = 2.0 * z[b]
        if study >= 0:
            i = circ.shape[0]
            acc = 0.0j
            acc2 = -1.0 + 0.0j
            for j in range(4):
                acc += z[study + j] * z[study + 4 + j]
                J[p, i, study + j] = z[study + 4 + j]
                J[p, i, study + 4 + j] = z[study + j]
            for j in range(8):
                acc2 += z[study + j] * patch[j]
                J[p, i + 1, study + j] = patch[j]
            F[p, i] = acc
            F[p, i + 1] = acc2
        for m in range(C.shape[0]):
            acc = 0.0j
            for j in range(r):
                acc += C[m, j] * rows[j]
            F[p, nside + m] = acc
            for v in range(nzd):
                acc = 0.0j
                for j in range(r):
                    acc += C[m, j] * drows[j, v]
                J[p, nside + m, v] = acc
    return F, J
