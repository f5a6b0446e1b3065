"""The ball systems of the homotopies' formulations (issue 27; certified by :mod:`.certify_core`):
the Study formulation's quadrics and linear equations (:class:`QuadricBallSystem`) and a limb's
inverse position (:class:`LimbBallSystem`), each with its floating-point first pass at real
points (:mod:`.certify_float`) and its floating-point Jacobians (the preconditioners).  Their
floats are the exact data of the stated system (docstring of :mod:`.certify`)."""

from __future__ import annotations

from typing import Any

import numpy as np
from flint import acb_mat, arb_mat

from ...errors import InputError
from .certify_balls import REAL, Field, field_of
from .certify_float import krawczyk_limb, krawczyk_quadrics

__all__ = ["LimbBallSystem", "QuadricBallSystem", "limb_system", "quadric_system"]


class QuadricBallSystem:
    """``x^T Q_k x`` for each quadric ``Q_k`` (m, n, n), then the linear equations ``B x = b``
    ((n - m, n) and (n - m,)): the Study formulation (seven quadrics and an affine patch)."""

    def __init__(self, Q, B, b) -> None:
        Q = np.asarray(Q)
        B = np.atleast_2d(np.asarray(B))
        b = np.asarray(b).ravel()
        self.m, self.n = Q.shape[0], Q.shape[1]
        if Q.shape[1:] != (self.n, self.n) or B.shape != (self.n - self.m, self.n) or b.shape != (self.n - self.m,):
            raise InputError(f"Q, B, b: expected m quadrics (n x n) and n - m linear equations of n unknowns, got shapes "
                             f"{Q.shape}, {B.shape}, {b.shape}")
        self.real = not (np.any(np.imag(Q)) or np.any(np.imag(B)) or np.any(np.imag(b)))
        self._Q, self._B, self._b = Q, B, b
        self._consts: dict[bool, tuple] = {}

    def _k(self, f: Field) -> tuple:
        hit = self._consts.get(f.real)
        if hit is None:
            Qk = [f.mat(Q) for Q in self._Q]
            # the Jacobian's rows Q_k + Q_k^T, stacked: exact balls (the sum is taken in ball arithmetic)
            S = f.mat(np.concatenate(list(self._Q))) + f.mat(np.concatenate([Q.T for Q in self._Q]))
            Bm = f.mat(self._B)
            hit = self._consts[f.real] = (Qk, S, Bm, f.col(self._b),
                                          [[Bm[k, j] for j in range(self.n)] for k in range(self.n - self.m)])
        return hit

    def values(self, x):
        Qk, _, Bm, bv, _ = self._k(field_of(x))
        xt = x.transpose()
        lin = Bm * x - bv
        rows: Any = [[(xt * (Q * x))[0, 0]] for Q in Qk]
        rows += [[lin[k, 0]] for k in range(self.n - self.m)]
        return arb_mat(rows) if isinstance(x, arb_mat) else acb_mat(rows)

    def krawczyk_float(self, Y: np.ndarray, max_radius: float) -> list[float | None]:
        """The fast first pass at the real points ``Y`` (:mod:`.certify_float`; real systems only)."""
        return krawczyk_quadrics(np.real(self._Q), np.real(self._B), np.real(self._b), Y, max_radius,
                                 lambda y: self.values(REAL.col(y)))

    def jacobian_float_many(self, Y: np.ndarray) -> np.ndarray:
        """``F'`` in floating point at the points ``Y`` (k, n) (the preconditioners only)."""
        Q = np.asarray(self._Q, dtype=complex)
        Jq = np.einsum("kij,pj->pki", Q + Q.transpose(0, 2, 1), np.asarray(Y, dtype=complex))
        return np.concatenate([Jq, np.broadcast_to(self._B, (len(Jq), *self._B.shape))], axis=1)

    def jacobian(self, x):
        _, S, _, _, Brows = self._k(field_of(x))
        SX = S * x
        n = self.n
        rows: Any = [[SX[k * n + j, 0] for j in range(n)] for k in range(self.m)] + Brows
        return arb_mat(rows) if isinstance(x, arb_mat) else acb_mat(rows)



def quadric_system(Q, B, b) -> QuadricBallSystem:
    """The ball system of quadrics ``Q`` (m, n, n) and linear equations ``B x = b``."""
    return QuadricBallSystem(Q, B, b)


class LimbBallSystem:
    """The square system of a limb's inverse position (:class:`.inverse.LimbIK` of the *rigid*
    family: as many equations as unknowns) at a real pose: the circles ``c^2 + s^2 = 1``, then
    the closure equations of :meth:`.inverse.LimbIK.equations` with the quaternion ``q`` and the
    translation ``t`` (over ``L``) as exact data."""

    def __init__(self, sysm, q, t) -> None:
        if not sysm.rigid:
            raise InputError("sysm: the limb's equations are not square (a graph family): no certificate")
        self.n = int(sysm.nx)
        self.real = True
        self.kind = sysm.kind
        self.circles = tuple(sysm.circles)
        self._sysm = sysm
        self._q = np.real(np.asarray(q)).astype(float)
        self._t = np.real(np.asarray(t)).astype(float)
        self._consts: dict[bool, dict] = {}

    def _k(self, f: Field) -> dict:
        hit = self._consts.get(f.real)
        if hit is not None:
            return hit
        w, i, j, k = (f.scalar(v) for v in self._q)
        rows = [[w * w + i * i - j * j - k * k, 2 * (i * j - w * k), 2 * (i * k + w * j)],
                [2 * (i * j + w * k), w * w - i * i + j * j - k * k, 2 * (j * k - w * i)],
                [2 * (i * k - w * j), 2 * (j * k + w * i), w * w - i * i - j * j + k * k]]
        zero = f.scalar(0.0)
        Erows: Any = [rows[a] + [zero] for a in range(3)] + [[zero] * 4]
        E = arb_mat(Erows) if f.real else acb_mat(Erows)

        hit = self._consts[f.real] = {"E": E, "s": w * w + i * i + j * j + k * k, "t": [f.scalar(v) for v in self._t],
                                      "one": f.scalar(1.0), **_limb_constants(self._sysm, f)}
        return hit

    @staticmethod
    def _chain(factors, x, K: dict, want: bool):
        """The product ``T``, and with ``want`` its prefix and suffix products and per factor the
        derivatives of its matrix ``{unknown: dM}``."""
        eye, one = K["eye"], K["one"]
        Ms: list[Any] = []
        dMs: list[tuple] = []
        for kind, A, A2, idx in factors:
            if kind == "R":
                c, s = x[idx[0], 0], x[idx[1], 0]
                Ms.append(eye + A * s + A2 * (one - c))
                dMs.append(((idx[0], -A2), (idx[1], A)))
            else:
                Ms.append(eye + A * x[idx[0], 0])
                dMs.append(((idx[0], A),))
        pre = [eye]
        for M in Ms:
            pre.append(M if len(pre) == 1 else pre[-1] * M)  # no product with the identity
        if not want:
            return pre[-1], pre, [], dMs
        suf = [eye]
        for M in reversed(Ms):
            suf.append(M if len(suf) == 1 else M * suf[-1])
        suf.reverse()  # suf[i] = M_i ... M_last
        return pre[-1], pre, suf, dMs

    def krawczyk_float(self, Y: np.ndarray, max_radius: float) -> list[float | None]:
        """The fast first pass at the real points ``Y`` (:mod:`.certify_float`)."""
        return krawczyk_limb(self._sysm, self._q, self._t, Y, max_radius, lambda y: self.values(REAL.col(y)))

    def jacobian_float_many(self, Y: np.ndarray) -> np.ndarray:
        """``F'`` in floating point at the points ``Y`` (k, n) (the preconditioners only)."""
        return _limb_float_jacobians(self._sysm, self._q, self._t, Y)

    def values(self, x):
        K = self._k(field_of(x))
        TL, _, _, _ = self._chain(K["left"], x, K, False)
        TR, _, _, _ = self._chain(K["right"], x, K, False)
        E, s, t = K["E"], K["s"], K["t"]
        out: Any = [[x[a, 0] * x[a, 0] + x[b, 0] * x[b, 0] - K["one"]] for a, b in self.circles]
        if self.kind == "point":
            u, v = TL * K["centre"], E * (TR * K["centre"])
            out += [[s * u[a, 0] - v[a, 0] - s * t[a]] for a in range(3)]
        else:
            Q = (E * TR).transpose() * TL  # P^T with P = TL^T E TR
            W = E * TR
            out += [[Q[1, 0]], [Q[2, 0]], [Q[2, 1]]] + [[s * TL[a, 3] - W[a, 3] - s * t[a]] for a in range(3)]
        return arb_mat(out) if isinstance(x, arb_mat) else acb_mat(out)

    def jacobian(self, x):
        f = field_of(x)
        K = self._k(f)
        TL, preL, sufL, dL = self._chain(K["left"], x, K, True)
        TR, preR, sufR, dR = self._chain(K["right"], x, K, True)
        E, s = K["E"], K["s"]
        zero = f.scalar(0.0)
        J: Any = [[zero] * self.n for _ in range(self.n)]
        for i, (a, b) in enumerate(self.circles):
            J[i][a], J[i][b] = 2 * x[a, 0], 2 * x[b, 0]
        k = len(self.circles)
        if self.kind == "point":
            c = K["centre"]
            for i, dm in enumerate(dL):
                tail = sufL[i + 1] * c
                for z, dM in dm:
                    u = dM * tail if i == 0 else preL[i] * (dM * tail)
                    for r in range(3):
                        J[k + r][z] = s * u[r, 0]
            for i, dm in enumerate(dR):
                tail = sufR[i + 1] * c
                for z, dM in dm:
                    v = E * (dM * tail if i == 0 else preR[i] * (dM * tail))
                    for r in range(3):
                        J[k + r][z] = -v[r, 0]
        else:
            ETRt = (E * TR).transpose()
            TLt = TL.transpose()
            nL, nR = len(dL), len(dR)
            for i, dm in enumerate(dL):
                for z, dM in dm:
                    dT = dM if i + 1 == nL else dM * sufL[i + 1]
                    dT = dT if i == 0 else preL[i] * dT
                    Q = ETRt * dT  # (E TR)^T dTL = P_z^T
                    vals = [Q[1, 0], Q[2, 0], Q[2, 1]] + [s * dT[a, 3] for a in range(3)]
                    for r, val in enumerate(vals):
                        J[k + r][z] = val
            for i, dm in enumerate(dR):
                lead = E * preR[i]
                for z, dM in dm:
                    W = lead * dM if i + 1 == nR else lead * dM * sufR[i + 1]  # E dTR
                    P = TLt * W
                    vals = [P[0, 1], P[0, 2], P[1, 2]] + [-W[a, 3] for a in range(3)]
                    for r, val in enumerate(vals):
                        J[k + r][z] = val
        return arb_mat(J) if f.real else acb_mat(J)



_LIMBS: dict[tuple[bytes, bool], dict] = {}


def _limb_float_jacobians(sysm, q: np.ndarray, t: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """``F'`` of the limb's square system in floating point at the points ``Y`` (k, n), batched
    (the preconditioners only: the same formulas as :meth:`LimbBallSystem.jacobian`)."""
    Y = np.asarray(Y, dtype=complex)
    k, n = Y.shape
    eye = np.broadcast_to(np.eye(4), (k, 4, 4))

    def chain(factors):
        Ms: list[np.ndarray] = []
        dMs: list[tuple] = []
        for fa in factors:
            A = fa.sign * fa.A
            if fa.kind == "R":
                c, s = Y[:, fa.idx[0], None, None], Y[:, fa.idx[1], None, None]
                Ms.append(eye + s * A + (1 - c) * fa.A2)
                dMs.append(((fa.idx[0], -fa.A2), (fa.idx[1], A)))
            else:
                Ms.append(eye + Y[:, fa.idx[0], None, None] * A)
                dMs.append(((fa.idx[0], A),))
        pre = [eye]
        for M in Ms:
            pre.append(pre[-1] @ M)
        suf = [eye]
        for M in reversed(Ms):
            suf.append(M @ suf[-1])
        suf.reverse()
        return pre, suf, dMs

    w, i, j, kq = q
    E = np.zeros((4, 4))
    E[:3, :3] = [[w * w + i * i - j * j - kq * kq, 2 * (i * j - w * kq), 2 * (i * kq + w * j)],
                 [2 * (i * j + w * kq), w * w - i * i + j * j - kq * kq, 2 * (j * kq - w * i)],
                 [2 * (i * kq - w * j), 2 * (j * kq + w * i), w * w - i * i - j * j + kq * kq]]
    s2 = float(q @ q)
    preL, sufL, dL = chain(sysm.left)
    preR, sufR, dR = chain(sysm.right)
    TL, TR = preL[-1], preR[-1]
    J = np.zeros((k, n, n), dtype=complex)
    for r, (a, b) in enumerate(sysm.circles):
        J[:, r, a], J[:, r, b] = 2 * Y[:, a], 2 * Y[:, b]
    m = len(sysm.circles)
    for side, (pre, suf, dm) in enumerate(((preL, sufL, dL), (preR, sufR, dR))):
        for f_i, derivs in enumerate(dm):
            for z, dM in derivs:
                dT = pre[f_i] @ dM @ suf[f_i + 1]
                if sysm.kind == "point":
                    c = np.asarray(sysm.centre, dtype=float)
                    J[:, m:m + 3, z] = s2 * (dT @ c)[:, :3] if side == 0 else -((E @ dT) @ c)[:, :3]
                    continue
                P = np.swapaxes(dT, 1, 2) @ E @ TR if side == 0 else np.swapaxes(TL, 1, 2) @ E @ dT
                tr = s2 * dT[:, :3, 3] if side == 0 else -(E @ dT)[:, :3, 3]
                J[:, m:m + 3, z] = np.stack([P[:, 0, 1], P[:, 0, 2], P[:, 1, 2]], axis=1)
                J[:, m + 3:m + 6, z] = tr
    return J


def _limb_constants(sysm, f: Field) -> dict:
    """The ball matrices of a limb's factors (cached per limb geometry and field)."""
    key = (sysm.key, f.real)
    hit = _LIMBS.get(key)
    if hit is None:
        if len(_LIMBS) > 256:
            _LIMBS.clear()

        def factor(fa):
            return (fa.kind, f.mat(fa.sign * fa.A), f.mat(fa.A2), fa.idx)

        hit = _LIMBS[key] = {"centre": f.col(np.asarray(sysm.centre, dtype=float)), "eye": f.identity(4),
                             "left": [factor(fa) for fa in sysm.left], "right": [factor(fa) for fa in sysm.right]}
    return hit


def limb_system(sysm, q, t) -> LimbBallSystem:
    """The ball system of the limb ``sysm`` (:class:`.inverse.LimbIK`, rigid family) at the pose
    of quaternion ``q`` (4, real) and translation ``t`` (3, over ``L``)."""
    return LimbBallSystem(sysm, q, t)
