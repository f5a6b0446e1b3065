"""The compiled evaluation of the loop formulation's square system (:mod:`..homotopy.loop_system`):
the same equations as :meth:`.loop_system.LoopSystem.square` (the NumPy reference, which
runs under ``SPATIALMECH_PURE=1``), point by point in numba.

The system is packed once into flat arrays (:func:`pack`): every chain of factors (each moving
hub's reference limb, then each limb's factors before and after its S joints) as ranges of one
factor table (kind, sign, variable indices, twist matrix ``A`` and ``A^2``); the hubs in the
order they are defined (the hub they hang from, their chain or the index of their Study
parameters and patch); each limb's end hubs, equation kind, centres and rod length; the Study
forms, the circles and the compression.  Hub slot 0 is the ground, slot ``h + 1`` hub ``h``
(the platform 0, the bodies 1, 2, ...).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .kernels_se3 import nb_mm4c

__all__ = ["pack", "square_batch"]


def pack(sysm, study_q: np.ndarray) -> tuple:
    """The arguments of :func:`square_batch` for a :class:`..homotopy.loop_system.LoopSystem`."""
    chains: list[tuple] = []
    h_chain: list[int] = []
    for h in sysm.hubs:
        if h.study >= 0:
            h_chain.append(-1)
        else:
            h_chain.append(len(chains))
            chains.append(h.chain)
    lc0 = len(chains)
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

    def slot(hub):
        return 0 if hub is None else hub + 1

    h_slot = np.array([slot(h.hub) for h in sysm.hubs], np.int64)
    h_frm = np.array([slot(h.frm) for h in sysm.hubs], np.int64)
    h_study = np.array([h.study for h in sysm.hubs], np.int64)
    h_patch = np.array([h.patch if h.patch is not None else np.zeros(8, complex) for h in sysm.hubs],
                       np.complex128).reshape(-1, 8)
    la = np.array([slot(le.a) for le in sysm.limbs], np.int64)
    lb = np.array([slot(le.b) for le in sysm.limbs], np.int64)
    lk = np.array([{"full": 0, "point": 1, "rod": 2}[le.kind] for le in sysm.limbs], np.int64)
    c1 = np.array([le.c1 for le in sysm.limbs], float).reshape(-1, 4)
    c2 = np.array([le.c2 for le in sysm.limbs], float).reshape(-1, 4)
    l2 = np.array([le.length2 for le in sysm.limbs], float)
    circ = np.array(sysm.circles, np.int64).reshape(-1, 2)
    return (np.array(kind, np.int64), np.array(sign, float), np.array(i0, np.int64), np.array(i1, np.int64),
            np.array(A, float).reshape(-1, 4, 4), np.array(A2, float).reshape(-1, 4, 4),
            np.array(lo, np.int64), np.array(hi, np.int64), h_slot, h_frm, np.array(h_chain, np.int64), h_study,
            h_patch, la, lb, lc0, np.ascontiguousarray(study_q), lk, c1, c2, l2, circ,
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
            nb_mm4c(dT[k], M, tmp)
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
        nb_mm4c(T, M, tmp)
        T[:] = tmp


@njit(cache=True)
def _mul_hub(H, dH, T, dT, out, dout, nzd):
    """``out = H T`` and ``dout = dH T + H dT`` (4x4, with ``nzd`` derivatives)."""
    nb_mm4c(H, T, out)
    for v in range(nzd):
        for a in range(4):
            for b in range(4):
                acc = 0.0j
                for e in range(4):
                    acc += dH[v, a, e] * T[e, b] + H[a, e] * dT[v, e, b]
                dout[v, a, b] = acc


@njit(cache=True)
def square_batch(Z, W, want_J, kind, sign, i0, i1, A, A2, lo, hi, h_slot, h_frm, h_chain, h_study, h_patch, la, lb,
                 lc0, Q, lk, c1, c2, l2, circ, C, nx, woff):
    """The square system ``G`` (n, nx) and its derivative (n, nx, nz) at points ``Z`` (n, nz),
    with the offset parameters ``W`` (n, nw); the derivative of the closure rows only with ``want_J`` (else left zero)."""
    n, nz = Z.shape
    nzd = nz if want_J else 0
    r = C.shape[1]
    nh = h_slot.shape[0]
    nst = 0
    for h in range(nh):
        if h_study[h] >= 0:
            nst += 1
    nside = circ.shape[0] + 2 * nst
    F = np.zeros((n, nx), np.complex128)
    J = np.zeros((n, nx, nz), np.complex128)
    Hs = np.zeros((nh + 1, 4, 4), np.complex128)  # slot 0: the ground
    dHs = np.zeros((nh + 1, nz, 4, 4), np.complex128)
    Es = np.ones(nh + 1, np.complex128)
    dEs = np.zeros((nh + 1, nz), np.complex128)
    for a in range(4):
        Hs[0, a, a] = 1.0
    T0 = np.empty((4, 4), np.complex128)
    dT0 = np.empty((nz, 4, 4), np.complex128)
    Tb = np.empty((4, 4), np.complex128)
    dTb = np.empty((nz, 4, 4), np.complex128)
    Ta = np.empty((4, 4), np.complex128)
    dTa = np.empty((nz, 4, 4), np.complex128)
    rows = np.empty(r, np.complex128)
    drows = np.empty((r, nz), np.complex128)
    w = np.empty(3, np.complex128)
    dw = np.empty((nz, 3), np.complex128)
    dEE = np.empty(nz, np.complex128)
    Eq = np.empty((3, 3), np.complex128)
    Bq = np.empty((3, 3), np.complex128)
    dBq = np.empty((nz, 3, 3), np.complex128)
    for p in range(n):
        z = Z[p]
        for h in range(nh):  # the hubs, in the order they are defined
            s = h_slot[h]
            D = Hs[s]
            dD = dHs[s]
            dEs[s, :] = 0.0
            if h_study[h] >= 0:
                st = h_study[h]
                dD[:] = 0.0
                E = 0.0j
                for i in range(4):
                    E += z[st + i] * z[st + i]
                    dEs[s, st + i] = 2.0 * z[st + i]
                Es[s] = E
                for a in range(4):
                    for b in range(4):
                        acc = 0.0j
                        for i in range(8):
                            zi = z[st + i]
                            for j in range(8):
                                q = Q[a, b, i, j]
                                if q != 0.0:
                                    acc += zi * q * z[st + j]
                                    dD[st + i, a, b] += q * z[st + j]
                                    dD[st + j, a, b] += q * zi
                        D[a, b] = acc
            elif h_frm[h] == 0:
                c = h_chain[h]
                _chain(kind, sign, i0, i1, A, A2, lo[c], hi[c], z, D, dD, nzd)
                Es[s] = 1.0
            else:
                c = h_chain[h]
                f = h_frm[h]
                _chain(kind, sign, i0, i1, A, A2, lo[c], hi[c], z, T0, dT0, nzd)
                _mul_hub(Hs[f], dHs[f], T0, dT0, D, dD, nzd)
                Es[s] = Es[f]
                dEs[s, :] = dEs[f, :]
        row = 0
        for k in range(lk.shape[0]):
            cb = lc0 + 2 * k
            if la[k] == 0:
                _chain(kind, sign, i0, i1, A, A2, lo[cb], hi[cb], z, Tb, dTb, nzd)
            else:
                _chain(kind, sign, i0, i1, A, A2, lo[cb], hi[cb], z, T0, dT0, nzd)
                _mul_hub(Hs[la[k]], dHs[la[k]], T0, dT0, Tb, dTb, nzd)
            Ea = Es[la[k]]
            dEa = dEs[la[k]]
            D = Hs[lb[k]]
            dD = dHs[lb[k]]
            E = Es[lb[k]]
            dE = dEs[lb[k]]
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
                for a in range(3):  # B = R_b E(q), dB
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
                for a in range(3):  # E_b (H_a T)_t - E_a (p_b + R_b t)
                    acc = E * Tb[a, 3] - Ea * D[a, 3]
                    sr = D[a, 3]
                    for e in range(3):
                        acc -= Ea * (D[a, e] * wk[4 + e])
                        sr += D[a, e] * wk[4 + e]
                    rows[row + 3 + a] = acc
                    for v in range(nzd):
                        acc = E * dTb[v, a, 3] + dE[v] * Tb[a, 3] - Ea * dD[v, a, 3]
                        for e in range(3):
                            acc -= Ea * (dD[v, a, e] * wk[4 + e])
                        if la[k] != 0:
                            acc -= dEa[v] * sr
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
                w[a] = E * u1 - Ea * u2
                for v in range(nzd):
                    du1 = 0.0j
                    du2 = 0.0j
                    for b in range(4):
                        du1 += dTb[v, a, b] * c1[k, b]
                        dv = 0.0j
                        for e in range(4):
                            dv += dTa[v, b, e] * c2[k, e]
                        du2 += dD[v, a, b] * vv[b] + D[a, b] * dv
                    dw[v, a] = E * du1 + dE[v] * u1 - Ea * du2 - dEa[v] * u2
            EE = Ea * E
            for v in range(nzd):
                dEE[v] = dEa[v] * E + Ea * dE[v]
            if lk[k] == 1:
                for a in range(3):
                    rows[row + a] = w[a] - EE * wk[a]
                    for v in range(nzd):
                        drows[row + a, v] = dw[v, a] - dEE[v] * wk[a]
                row += 3
            else:
                lsq = l2[k] + wk[0]
                rows[row] = w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - EE * EE * lsq
                for v in range(nzd):
                    drows[row, v] = 2.0 * (w[0] * dw[v, 0] + w[1] * dw[v, 1] + w[2] * dw[v, 2]) - 2.0 * EE * lsq * dEE[v]
                row += 1
        for i in range(circ.shape[0]):
            a = circ[i, 0]
            b = circ[i, 1]
            F[p, i] = z[a] * z[a] + z[b] * z[b] - 1.0
            J[p, i, a] = 2.0 * z[a]
            J[p, i, b] = 2.0 * z[b]
        i = circ.shape[0]
        for h in range(nh):  # the Study quadric and patch of each hub in Study parameters
            st = h_study[h]
            if st < 0:
                continue
            acc = 0.0j
            acc2 = -1.0 + 0.0j
            for j in range(4):
                acc += z[st + j] * z[st + 4 + j]
                J[p, i, st + j] = z[st + 4 + j]
                J[p, i, st + 4 + j] = z[st + j]
            for j in range(8):
                acc2 += z[st + j] * h_patch[h, j]
                J[p, i + 1, st + j] = h_patch[h, j]
            F[p, i] = acc
            F[p, i + 1] = acc2
            i += 2
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
