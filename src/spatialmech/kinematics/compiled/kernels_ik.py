"""The compiled parameter homotopy of one limb's inverse position (:mod:`..homotopy.inverse`).

The NumPy reference tracks the system in the variables ``(c, s)`` of every revolute (with its
circle); here each freedom is its angle ``theta`` (or slide ``d``), complex, ``c = cos theta``,
``s = sin theta``: the same equations without the circles, half the unknowns, and the derivative
of a product of exponentials from its prefixes and suffixes (``d/dtheta_i T = pre_i A_i suf_i``),
every product taken as a displacement (rows 0-2 only, 36 products instead of 64) with the real
twist matrices.  A path in ``theta`` maps onto the path in ``(c, s)``; the caller converts at both
ends.  The tracker is :func:`.kernels_homotopy.nb_track_param`'s: the same RK4 predictor, two
Newton corrections (an in-place LU), acceptance test and step control, path by path; it also
accepts a step whose two corrections are both below ``HOMOTOPY_FLOOR`` (the rounding floor of an
ill-conditioned point, a complex angle far from real, where the second cannot contract the first).

Packed system (:func:`ik_pack`): the factors before the cut (``left``) and the inverted factors
after it in reverse order (``right``), each as kind (0: rotation, 1: slide), variable index,
``A`` and ``A^2`` (4x4, real); whether the limb closes at an S joint's centre (``point``), the
centre, the compression ``C`` (rows, equations) complex, and whether ``C`` is the identity (the
rigid family).  Parameters ``P = (q (4), t (3), b)``.
"""

from __future__ import annotations

import numpy as np

from ...geometry.tolerances import HOMOTOPY_FLOOR, HOMOTOPY_JUMP, HOMOTOPY_NEWTON
from .jit import njit
from .kernels_homotopy import nb_lu_solve_inplace, nb_step_control

__all__ = ["ik_pack", "ik_track", "nb_ik_system", "nb_ik_track", "nb_ik_workspace"]


@njit(cache=True)
def _aff(A, B, out):
    """Rows 0-2 of ``A B`` for a ``B`` whose last row is ``(0, 0, 0, 1)`` (a displacement; rows
    0-2 of ``A`` and ``B`` are read, the last rows never: 36 products instead of 64)."""
    for a in range(3):
        for b in range(3):
            out[a, b] = A[a, 0] * B[0, b] + A[a, 1] * B[1, b] + A[a, 2] * B[2, b]
        out[a, 3] = A[a, 0] * B[0, 3] + A[a, 1] * B[1, 3] + A[a, 2] * B[2, 3] + A[a, 3]


@njit(cache=True)
def _aff_twist(A, B, out, sg):
    """``sg`` times rows 0-2 of ``A B`` for a displacement ``A`` and a (real) twist matrix ``B``
    (last row zero)."""
    for a in range(3):
        for b in range(4):
            out[a, b] = sg * (A[a, 0] * B[0, b] + A[a, 1] * B[1, b] + A[a, 2] * B[2, b])


@njit(cache=True)
def _factors(th, kinds, A, A2, idx, sg, Ms):
    """Rows 0-2 of every factor ``M_i = I + sg sin A + (1 - cos) A^2`` (or ``I + sg d A``)."""
    for i in range(kinds.shape[0]):
        v = th[idx[i]]
        if kinds[i] == 0:
            sn = sg * np.sin(v)
            cs = 1.0 - np.cos(v)
            for a in range(3):
                for b in range(4):
                    Ms[i, a, b] = (1.0 if a == b else 0.0) + sn * A[i, a, b] + cs * A2[i, a, b]
        else:
            d = sg * v
            for a in range(3):
                for b in range(4):
                    Ms[i, a, b] = (1.0 if a == b else 0.0) + d * A[i, a, b]


@njit(cache=True)
def _chain(th, kinds, A, A2, idx, sg, T, dT, pre, suf, Ms, tmp):
    """Rows 0-2 (the last rows are never read) of ``T`` = the product of the factors ``M_0 ...
    M_(m-1)`` and of ``dT[idx[i]]`` = its derivative in their variables, ``sg pre_i A_i suf_i``
    with ``pre_i = M_0 ... M_(i-1)`` and ``suf_i = M_i ... M_(m-1)`` (``A_i`` commutes with
    ``M_i``: the first is ``sg A_0 T``, the last ``sg pre_m A``); the twist matrices ``A``,
    ``A2 = A^2`` are real."""
    m = kinds.shape[0]
    _factors(th, kinds, A, A2, idx, sg, Ms)
    if m == 0:
        for a in range(3):
            for b in range(4):
                T[a, b] = 1.0 if a == b else 0.0
        return
    pre[1, :, :] = Ms[0]
    for i in range(1, m):
        _aff(pre[i], Ms[i], pre[i + 1])
    T[:, :] = pre[m]
    suf[m - 1, :, :] = Ms[m - 1]
    for i in range(m - 2, 0, -1):  # suf_0 = T is not needed
        _aff(Ms[i], suf[i + 1], suf[i])
    _derivatives(A, idx, sg, T, dT, pre, suf, tmp)


@njit(cache=True)
def _derivatives(A, idx, sg, T, dT, pre, suf, tmp):
    """``dT[idx[i]] = sg pre_i A_i suf_i`` (rows 0-2; :func:`_chain`)."""
    m = A.shape[0]
    for i in range(m):
        D = dT[idx[i]]
        if i == m - 1:  # pre_m A
            _aff_twist(pre[m], A[i], D, sg)
        elif i == 0:  # A suf_0 = A T
            for a in range(3):
                for b in range(4):
                    acc = A[0, a, 0] * T[0, b] + A[0, a, 1] * T[1, b] + A[0, a, 2] * T[2, b]
                    if b == 3:
                        acc += A[0, a, 3]
                    D[a, b] = sg * acc
        else:
            _aff_twist(pre[i], A[i], tmp, sg)
            _aff(tmp, suf[i], D)


@njit(cache=True)
def _rotform(q, out):
    w, i, j, k = q[0], q[1], q[2], q[3]
    out[0, 0] = w * w + i * i - j * j - k * k
    out[0, 1] = 2 * (i * j - w * k)
    out[0, 2] = 2 * (i * k + w * j)
    out[1, 0] = 2 * (i * j + w * k)
    out[1, 1] = w * w - i * i + j * j - k * k
    out[1, 2] = 2 * (j * k - w * i)
    out[2, 0] = 2 * (i * k - w * j)
    out[2, 1] = 2 * (j * k + w * i)
    out[2, 2] = w * w - i * i - j * j + k * k


@njit(cache=True)
def nb_ik_system(th, P, dP, lk, lA, lA2, li, rk, rA, rA2, ri, point, centre, C, ident, F, J, Ft, ws):
    """The square system ``C r(theta; q, t) - b`` (``F``), its Jacobian in ``theta`` (``J``) and
    its derivative along ``dP`` (``Ft``) at one point; ``ident``: ``C`` is the identity (the
    rigid family: ``r - b`` directly); ``ws``: scratch (:func:`nb_ik_workspace`)."""
    TL, dTL, TR, dTR, pre, suf, Ms, tmp, E, dE, qa, qb, r, rt, dr, LE, ER, LdE = ws
    dTL[:, :3, :] = 0.0
    dTR[:, :3, :] = 0.0
    _chain(th, lk, lA, lA2, li, 1.0, TL, dTL, pre, suf, Ms, tmp)
    _chain(th, rk, rA, rA2, ri, -1.0, TR, dTR, pre, suf, Ms, tmp)
    _rotform(P[:4], E)
    for a in range(4):
        qa[a] = P[a] + dP[a]
        qb[a] = P[a] - dP[a]
    _rotform(qa, dE)
    _rotform(qb, tmp)
    s = P[0] * P[0] + P[1] * P[1] + P[2] * P[2] + P[3] * P[3]
    ds = 2.0 * (P[0] * dP[0] + P[1] * dP[1] + P[2] * dP[2] + P[3] * dP[3])
    for a in range(3):
        for b in range(3):
            dE[a, b] = 0.5 * (dE[a, b] - tmp[a, b])
    if point:
        _point_eqs(TL, dTL, TR, dTR, E, dE, s, ds, P, dP, centre, r, rt, dr)
    else:
        _full_eqs(TL, dTL, TR, dTR, E, dE, s, ds, P, dP, r, rt, dr, LE, ER, LdE)
    if ident:
        for i in range(F.shape[0]):
            F[i] = r[i] - P[7 + i]
            Ft[i] = rt[i] - dP[7 + i]
            for z in range(J.shape[1]):
                J[i, z] = dr[i, z]
    else:
        _compress(C, P, dP, r, rt, dr, F, J, Ft)


@njit(cache=True)
def nb_ik_workspace(n, m, size):
    """The scratch of :func:`nb_ik_system` for ``n`` variables, at most ``m`` factors on a side
    and ``size`` equations."""
    c = np.complex128
    return (np.empty((4, 4), c), np.empty((n, 4, 4), c), np.empty((4, 4), c), np.empty((n, 4, 4), c),
            np.empty((m + 1, 4, 4), c), np.empty((m + 1, 4, 4), c), np.empty((m + 1, 4, 4), c), np.empty((4, 4), c),
            np.empty((3, 3), c), np.empty((4, 4), c), np.empty(4, c), np.empty(4, c), np.empty(size, c),
            np.empty(size, c), np.empty((size, n), c), np.empty((3, 3), c), np.empty((3, 3), c), np.empty((3, 3), c))


@njit(cache=True)
def _point_eqs(TL, dTL, TR, dTR, E, dE, s, ds, P, dP, centre, r, rt, dr):
    """The S joint's centre seen from both sides, and its derivatives."""
    n = dTL.shape[0]
    for a in range(3):
        u = 0j
        v = 0j
        for b in range(4):
            u += TL[a, b] * centre[b]
        Ev = 0j
        dEv = 0j
        for c in range(3):
            vc = 0j
            for b in range(4):
                vc += TR[c, b] * centre[b]
            Ev += E[a, c] * vc
            dEv += dE[a, c] * vc
        v = Ev
        r[a] = s * (u - P[4 + a]) - v
        rt[a] = ds * (u - P[4 + a]) - s * dP[4 + a] - dEv
        for z in range(n):
            du = 0j
            for b in range(4):
                du += dTL[z, a, b] * centre[b]
            dv = 0j
            for c in range(3):
                vc = 0j
                for b in range(4):
                    vc += dTR[z, c, b] * centre[b]
                dv += E[a, c] * vc
            dr[a, z] = s * du - dv


@njit(cache=True)
def _full_eqs(TL, dTL, TR, dTR, E, dE, s, ds, P, dP, r, rt, dr, LE, ER, LdE):
    """The off-diagonal rotation entries and the translation, and their derivatives
    (``LE``, ``ER``, ``LdE``: 3x3 scratch)."""
    n = dTL.shape[0]
    # Pm = RL^T E RR: the entries (0, 1), (0, 2), (1, 2); LE = RL^T E, ER = E RR
    for a in range(3):
        for b in range(3):
            LE[a, b] = TL[0, a] * E[0, b] + TL[1, a] * E[1, b] + TL[2, a] * E[2, b]
            ER[a, b] = E[a, 0] * TR[0, b] + E[a, 1] * TR[1, b] + E[a, 2] * TR[2, b]
            LdE[a, b] = TL[0, a] * dE[0, b] + TL[1, a] * dE[1, b] + TL[2, a] * dE[2, b]
    for e in range(3):
        a = 0 if e < 2 else 1
        b = 1 if e == 0 else 2
        acc = 0j
        acct = 0j
        for c in range(3):
            acc += LE[a, c] * TR[c, b]
            acct += LdE[a, c] * TR[c, b]
        r[e] = acc
        rt[e] = acct
        for z in range(n):
            d = 0j
            for c in range(3):
                d += dTL[z, c, a] * ER[c, b] + LE[a, c] * dTR[z, c, b]
            dr[e, z] = d
    for a in range(3):
        Ep = 0j
        dEp = 0j
        for c in range(3):
            Ep += E[a, c] * TR[c, 3]
            dEp += dE[a, c] * TR[c, 3]
        r[3 + a] = s * (TL[a, 3] - P[4 + a]) - Ep
        rt[3 + a] = ds * (TL[a, 3] - P[4 + a]) - s * dP[4 + a] - dEp
        for z in range(n):
            d = 0j
            for c in range(3):
                d += E[a, c] * dTR[z, c, 3]
            dr[3 + a, z] = s * dTL[z, a, 3] - d


@njit(cache=True)
def _compress(C, P, dP, r, rt, dr, F, J, Ft):
    """``C r - b`` and its derivatives."""
    n = dr.shape[1]
    size = C.shape[1]
    for i in range(C.shape[0]):
        f = -P[7 + i]
        ft = -dP[7 + i]
        for e in range(size):
            f += C[i, e] * r[e]
            ft += C[i, e] * rt[e]
        F[i] = f
        Ft[i] = ft
        for z in range(n):
            acc = 0j
            for e in range(size):
                acc += C[i, e] * dr[e, z]
            J[i, z] = acc


@njit(cache=True)
def _vel(th, P0, dP, t, sysargs, F, J, Ft, Pt, ws, out):
    for a in range(P0.shape[0]):
        Pt[a] = P0[a] + t * dP[a]
    lk, lA, lA2, li, rk, rA, rA2, ri, point, centre, C, ident = sysargs
    nb_ik_system(th, Pt, dP, lk, lA, lA2, li, rk, rA, rA2, ri, point, centre, C, ident, F, J, Ft, ws)
    for i in range(out.shape[0]):
        out[i] = -Ft[i]
    return nb_lu_solve_inplace(J, out)


@njit(cache=True)
def _step(x, P0, dP, t, hh, sysargs, F, J, Ft, Pt, ws, ks, xs, xc, dx):
    """One RK4 predictor step of ``hh`` from ``(x, t)`` and two Newton corrections into ``xc``:
    ``(ok, d0, d1)``, the corrections' sizes relative to ``1 + |x|``."""
    n = x.shape[0]
    ok = _vel(x, P0, dP, t, sysargs, F, J, Ft, Pt, ws, ks[0])
    for k, frac in ((1, 0.5), (2, 0.5), (3, 1.0)):
        if ok:
            for i in range(n):
                xs[i] = x[i] + frac * hh * ks[k - 1, i]
            ok = _vel(xs, P0, dP, t + frac * hh, sysargs, F, J, Ft, Pt, ws, ks[k])
    d0 = np.inf
    d1 = np.inf
    if not ok:
        return False, d0, d1
    nx = 0.0
    for i in range(n):
        xc[i] = x[i] + hh / 6.0 * (ks[0, i] + 2.0 * ks[1, i] + 2.0 * ks[2, i] + ks[3, i])
        nx += abs(xc[i]) ** 2
    nx = 1.0 + np.sqrt(nx)
    lk, lA, lA2, li, rk, rA, rA2, ri, point, centre, C, ident = sysargs
    for a in range(P0.shape[0]):
        Pt[a] = P0[a] + (t + hh) * dP[a]
    for c in range(2):
        nb_ik_system(xc, Pt, dP, lk, lA, lA2, li, rk, rA, rA2, ri, point, centre, C, ident, F, J, Ft, ws)
        for i in range(n):
            dx[i] = F[i]
        if not nb_lu_solve_inplace(J, dx):
            return False, d0, d1
        sq = 0.0
        for i in range(n):
            sq += abs(dx[i]) ** 2
            xc[i] -= dx[i]
        if c == 0:
            d0 = np.sqrt(sq) / nx
        else:
            d1 = np.sqrt(sq) / nx
    return True, d0, d1


@njit(cache=True)
def nb_ik_track(X0, P0s, P1s, lk, lA, lA2, li, rk, rA, rA2, ri, point, centre, C, ident, h0, hmin, max_steps, jump,
                newton, floor, X, T, done, steps):
    """Track every path ``X0[p]`` from ``P0s[p]`` to ``P1s[p]`` (straight segments)."""
    n = X0.shape[1]
    sysargs = (lk, lA, lA2, li, rk, rA, rA2, ri, point, centre, C, ident)
    ws = nb_ik_workspace(n, max(lk.shape[0], rk.shape[0]), C.shape[1])
    F = np.empty(n, dtype=np.complex128)
    J = np.empty((n, n), dtype=np.complex128)
    Ft = np.empty(n, dtype=np.complex128)
    Pt = np.empty(P0s.shape[1], dtype=np.complex128)
    dP = np.empty(P0s.shape[1], dtype=np.complex128)
    ks = np.empty((4, n), dtype=np.complex128)
    xs = np.empty(n, dtype=np.complex128)
    xc = np.empty(n, dtype=np.complex128)
    dx = np.empty(n, dtype=np.complex128)
    for p in range(X0.shape[0]):
        x = X[p]
        x[:] = X0[p]
        dP[:] = P1s[p] - P0s[p]
        t = 0.0
        h = h0
        good = 0
        for _ in range(max_steps):
            hh = min(h, 1.0 - t)
            ok, d0, d1 = _step(x, P0s[p], dP, t, hh, sysargs, F, J, Ft, Pt, ws, ks, xs, xc, dx)
            if ok and d0 < floor and d1 < floor:  # both corrections at the rounding floor (HOMOTOPY_FLOOR)
                d1 = 0.0
            acc, h, good = nb_step_control(ok, d0, d1, jump, newton, h, good)
            if acc:
                x[:] = xc
                t += hh
                steps[p] += 1
                if t >= 1.0:
                    done[p] = True
                    break
            elif h < hmin:
                break
        T[p] = t


def ik_pack(sysm) -> tuple:
    """The system arguments of :func:`nb_ik_track` for a :class:`..homotopy.inverse.LimbIK`."""

    def side(factors):
        k = np.array([0 if f.kind == "R" else 1 for f in factors], dtype=np.int64)
        A = np.array([f.A for f in factors], dtype=np.float64).reshape(len(factors), 4, 4)
        A2 = np.array([f.A2 for f in factors], dtype=np.float64).reshape(len(factors), 4, 4)
        idx = np.array([f.theta for f in factors], dtype=np.int64)
        return k, A, A2, idx

    C = np.ascontiguousarray(sysm.C, dtype=np.complex128)
    ident = C.shape[0] == C.shape[1] and bool(np.all(np.eye(C.shape[0]) == C))
    return (*side(sysm.left), *side(sysm.right), np.bool_(sysm.kind == "point"),
            sysm.centre.astype(np.complex128), C, np.bool_(ident))


def ik_track(packed: tuple, TH: np.ndarray, P0: np.ndarray, P1: np.ndarray, *, h0: float = 0.02,
             hmin: float = 1e-14, max_steps: int = 2000):
    """Track the points ``TH`` (n, m: angles and slides) from the parameters ``P0`` to ``P1``
    ((n, k) each).  Returns ``(TH, t, done, steps)``."""
    TH = np.ascontiguousarray(TH, dtype=np.complex128)
    X = np.empty_like(TH)
    T = np.zeros(len(TH))
    done = np.zeros(len(TH), dtype=np.bool_)
    steps = np.zeros(len(TH), dtype=np.int64)
    if len(TH):
        nb_ik_track(TH, np.ascontiguousarray(P0, dtype=np.complex128), np.ascontiguousarray(P1, dtype=np.complex128),
                    *packed, float(h0), float(hmin), int(max_steps), float(HOMOTOPY_JUMP), float(HOMOTOPY_NEWTON),
                    float(HOMOTOPY_FLOOR), X, T, done, steps)
    return X, T, done, steps
