"""Certificates of the loop formulation's solutions (issue 27): the forward position of a model
whose limbs do not reduce to the Study quadrics (:mod:`.loop_system`, solved by monodromy in
:mod:`.general`) certified by the Krawczyk test of :mod:`.certify`.

The exact system is the loop formulation's *square* system ``G(x; p) = 0`` at the requested
actuator values: the circles ``c^2 + s^2 = 1`` (and Study quadrics and patches of the hubs in
Study parameters), then the closure equations times the random complex matrix that makes the
system square (:meth:`.loop_system.LoopSystem.square`); its floats (the twist matrices, the
actuators' ``cos``/``sin`` or slides over ``L``, the random combination) taken as exact data.
Every configuration of the mechanism is a root of ``G``; a certificate proves that the box about
a solution holds exactly one root of ``G`` and that the boxes of the solutions are disjoint:
distinct configurations, each an approximate zero with its own root.  (Whether a root of ``G``
closes every equation of the full closure is the engine's floating-point check: ``G`` also has
spurious roots, none near a certified solution's box unless it is that box's one root.)

Ball evaluation.  :class:`LoopBallSystem` evaluates ``G`` and ``G'`` with python-flint's ball
matrices (``acb_mat`` products of the 4x4 factors, in C): each chain's product, and per unknown
only the derivatives that are structurally non-zero (``pre_i dM_i suf_{i+1}`` of the factor
that holds it; the parameters' columns are never formed), then the limbs' closure terms and the
random combination as ball matrix products.  It follows the formulas of
:meth:`.loop_system.LoopSystem.square` term by term at the mechanism's own offsets (``W`` the
identity offsets: ``E(q) = I``, zero translations and length changes, which enter exactly).
:class:`ReferenceLoopBallSystem` runs :meth:`.loop_system.LoopSystem.square` itself with
``reference=True`` on NumPy object arrays of ``acb`` balls (one code for the floats and the
balls, about ten times slower): systems with hubs in Study parameters use it, and the tests
check that both enclose the same values.  Either way every operation is carried out in ball
arithmetic, so the values at the point and the Jacobian over the box enclose the exact ones.
The coefficients are complex: no root is proven real by this test (``real`` stays undecided).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from flint import acb, acb_mat

from .certify import Certificate, certify
from .loop_system import LoopSystem, variables

__all__ = ["LoopBallSystem", "ReferenceLoopBallSystem", "certify_loop", "loop_ball_system"]

#: per unknown, a ball (matrix): the structurally non-zero derivatives only
Deriv = dict[int, Any]


def _exact(M) -> acb_mat:
    """An exact ball matrix of complex floats (python floats convert exactly)."""
    M = np.atleast_2d(np.asarray(M, dtype=complex))
    return acb_mat([[acb(complex(v)) for v in row] for row in M])


def _add(d: Deriv, z: int, v) -> None:
    d[z] = v if z not in d else d[z] + v


class ReferenceLoopBallSystem:
    """The square system of the loop formulation at the parameters ``p`` (the actuators), in
    ball arithmetic by :meth:`.loop_system.LoopSystem.square` on object arrays of ``acb`` (module
    docstring); ``n`` unknowns, complex coefficients."""

    real = False

    def __init__(self, sysm: LoopSystem, p: np.ndarray) -> None:
        self._sysm = sysm
        self.n = int(sysm.nx)
        self._p = [acb(complex(v)) for v in np.asarray(p, dtype=complex)]
        self._W = np.array([[acb(complex(v)) for v in sysm.identity_offsets(1)[0]]], dtype=object)

    def _z(self, x) -> np.ndarray:
        Z = np.empty((1, self.n + len(self._p)), dtype=object)
        for i in range(self.n):
            Z[0, i] = acb(x[i, 0])
        Z[0, self.n:] = self._p
        return Z

    def _eval(self, x, want_J: bool):
        F, J = self._sysm.square(self._z(x), self._W, reference=True, want_J=want_J)
        return F, J

    def values(self, x):
        F, _ = self._eval(x, False)
        return acb_mat([[acb(v)] for v in F[0]])

    def jacobian(self, x):
        _, J = self._eval(x, True)
        return acb_mat([[acb(v) for v in row[: self.n]] for row in J[0]])

    def jacobian_float_many(self, Y: np.ndarray) -> np.ndarray:
        """``G'`` in floating point at the points ``Y`` (k, n) (the preconditioners only)."""
        Y = np.asarray(Y, dtype=complex)
        P = np.broadcast_to(np.asarray([complex(v.mid()) for v in self._p]), (len(Y), len(self._p)))
        W = self._sysm.identity_offsets(len(Y))
        _, J = self._sysm.square(np.hstack([Y, P]), W, reference=True)
        return J[:, :, : self.n]


class LoopBallSystem(ReferenceLoopBallSystem):
    """The square system of the loop formulation at the parameters ``p``, evaluated with ball
    matrix products and structurally non-zero derivatives only (module docstring); systems with
    hubs in Study parameters are evaluated as :class:`ReferenceLoopBallSystem`."""

    def __init__(self, sysm: LoopSystem, p: np.ndarray) -> None:
        super().__init__(sysm, p)
        self._fast = not sysm.studies
        self._eye = acb_mat(4, 4, [1 if i == j else 0 for i in range(4) for j in range(4)])
        self._one = acb(1)
        self._factors: dict[int, tuple] = {}
        self._C = _exact(sysm.compress)
        self._c = {id(le): (_exact(le.c1[:, None]), _exact(le.c2[:, None]), acb(float(le.length2)))
                   for le in sysm.limbs}

    # ------------------------------------------------------------------ pieces
    def _consts(self, factors) -> tuple:
        """The factors' exact ball matrices ``(kind, sign A, A^2, idx)`` (cached per chain)."""
        hit = self._factors.get(id(factors))
        if hit is None or hit[0] is not factors:
            hit = self._factors[id(factors)] = (factors, [
                (f.kind, _exact((-1.0 if f.inverse else 1.0) * f.A), _exact(f.A2), f.idx) for f in factors])
        return hit[1]

    def _chain(self, factors, z: list, want: bool) -> tuple[Any, Deriv]:
        """The product of the factors (``None``: the identity) and its derivative per unknown."""
        if not factors:
            return None, {}
        Ms: list[Any] = []
        dMs: list[tuple] = []
        for kind, A, A2, idx in self._consts(factors):
            if kind == "R":
                Ms.append(self._eye + A * z[idx[1]] + A2 * (self._one - z[idx[0]]))
                dMs.append(((idx[0], -A2), (idx[1], A)))
            else:
                Ms.append(self._eye + A * z[idx[0]])
                dMs.append(((idx[0], A),))
        pre = [Ms[0]]
        for M in Ms[1:]:
            pre.append(pre[-1] * M)  # pre[i] = M_0 ... M_i
        if not want:
            return pre[-1], {}
        suf = [Ms[-1]]
        for M in reversed(Ms[:-1]):
            suf.append(M * suf[-1])
        suf.reverse()  # suf[i] = M_i ... M_last
        d: Deriv = {}
        last = len(Ms) - 1
        for i, dm in enumerate(dMs):
            for zi, dM in dm:
                if zi >= self.n:
                    continue  # a parameter: its column is not needed
                dT = dM if i == last else dM * suf[i + 1]
                _add(d, zi, dT if i == 0 else pre[i - 1] * dT)
        return pre[-1], d

    def _hubs(self, z: list, want: bool) -> dict:
        """``{hub: (H, dH, E, dE)}`` (``H`` ``None``: the identity; ``E`` 1) as
        :meth:`.loop_system.LoopSystem.hub_values` (no hub in Study parameters here)."""
        out: dict = {None: (None, {}, self._one, {})}
        for h in self._sysm.hubs:
            T, dT = self._chain(h.chain, z, want)
            Hf, dHf, Ef, dEf = out[h.frm]
            H = T if Hf is None else (Hf if T is None else Hf * T)
            dH: Deriv = {}
            for k, v in dHf.items():
                _add(dH, k, v if T is None else v * T)
            for k, v in dT.items():
                _add(dH, k, v if Hf is None else Hf * v)
            out[h.hub] = (H, dH, Ef, dEf)
        return out

    def _mat(self, M):
        return self._eye if M is None else M

    def _full(self, Tb, dTb: Deriv, D, dD: Deriv, Ea, dEa: Deriv, E, dE: Deriv, want: bool):
        """A limb without S joint: ``(A^T B)`` off the diagonal and the translations (6 rows)."""
        Tb, D = self._mat(Tb), self._mat(D)

        def terms(A4, B4):
            A3 = acb_mat([[A4[i, j] for j in range(3)] for i in range(3)])
            B3 = acb_mat([[B4[i, j] for j in range(3)] for i in range(3)])
            return A3.transpose() * B3

        P = terms(Tb, D)
        rows = [P[0, 1], P[0, 2], P[1, 2]] + [E * Tb[a, 3] - Ea * D[a, 3] for a in range(3)]
        cols: dict[int, list] = {}
        if want:
            for k in set(dTb) | set(dD) | set(dE) | set(dEa):
                dP = None
                if k in dTb:
                    dP = terms(dTb[k], D)
                if k in dD:
                    dP = terms(Tb, dD[k]) if dP is None else dP + terms(Tb, dD[k])
                col = [dP[0, 1], dP[0, 2], dP[1, 2]] if dP is not None else [acb(0)] * 3
                for a in range(3):
                    v = acb(0)
                    if k in dTb:
                        v += E * dTb[k][a, 3]
                    if k in dE:
                        v += dE[k] * Tb[a, 3]
                    if k in dD:
                        v -= Ea * dD[k][a, 3]
                    if k in dEa:
                        v -= dEa[k] * D[a, 3]
                    col.append(v)
                cols[k] = col
        return rows, cols

    def _sphere(self, le, Tb, dTb: Deriv, D, dD: Deriv, Ea, dEa: Deriv, E, dE: Deriv, z: list, want: bool):
        """A limb with S joint(s): the centre's closure (3 rows) or the rod's length (1 row)."""
        c1, c2, l2 = self._c[id(le)]
        Ta, dTa = self._chain(le.after_inv, z, want)
        u1 = c1 if Tb is None else Tb * c1
        v = c2 if Ta is None else Ta * c2
        u2 = v if D is None else D * v
        w = [E * u1[a, 0] - Ea * u2[a, 0] for a in range(3)]
        EE = Ea * E
        cols: dict[int, list] = {}
        dw: dict[int, list] = {}
        if want:
            for k in set(dTb) | set(dTa) | set(dD) | set(dE) | set(dEa):
                du2 = None
                if k in dTa:
                    dv = dTa[k] * c2
                    du2 = dv if D is None else D * dv
                if k in dD:
                    t = dD[k] * v
                    du2 = t if du2 is None else du2 + t
                du1 = dTb[k] * c1 if k in dTb else None
                col = []
                for a in range(3):
                    x = acb(0)
                    if du1 is not None:
                        x += E * du1[a, 0]
                    if k in dE:
                        x += dE[k] * u1[a, 0]
                    if du2 is not None:
                        x -= Ea * du2[a, 0]
                    if k in dEa:
                        x -= dEa[k] * u2[a, 0]
                    col.append(x)
                dw[k] = col
        if le.kind == "point":
            return w, dw
        rows = [w[0] * w[0] + w[1] * w[1] + w[2] * w[2] - EE * EE * l2]
        for k, col in dw.items():
            dEE = acb(0)
            if k in dEa:
                dEE += dEa[k] * E
            if k in dE:
                dEE += Ea * dE[k]
            cols[k] = [2 * (w[0] * col[0] + w[1] * col[1] + w[2] * col[2]) - 2 * (EE * l2) * dEE]
        return rows, cols

    def _square(self, x, want: bool):
        """``G`` (n x 1) and, with ``want``, ``G'`` (n x n) at the ball column ``x``."""
        sysm, n = self._sysm, self.n
        z = [x[i, 0] for i in range(n)] + self._p
        F1 = [z[a] * z[a] + z[b] * z[b] - self._one for a, b in sysm.circles]
        H = self._hubs(z, want)
        F2: list = []
        J2: list = []
        for le in sysm.limbs:
            Ha, dHa, Ea, dEa = H[le.a]
            Tb, dTb = self._chain(le.before, z, want)
            if Ha is not None:
                dTb2: Deriv = {}
                for k, v in dHa.items():
                    _add(dTb2, k, v if Tb is None else v * Tb)
                for k, v in dTb.items():
                    _add(dTb2, k, Ha * v)
                Tb, dTb = (Ha if Tb is None else Ha * Tb), dTb2
            D, dD, E, dE = H[le.b]
            if le.kind == "full":
                rows, cols = self._full(Tb, dTb, D, dD, Ea, dEa, E, dE, want)
            else:
                rows, cols = self._sphere(le, Tb, dTb, D, dD, Ea, dEa, E, dE, z, want)
            F2 += rows
            if want:
                block = [[acb(0)] * n for _ in rows]
                for k, col in cols.items():
                    for r, v in enumerate(col):
                        block[r][k] = v
                J2 += block
        F = acb_mat([[v] for v in F1] + [[v] for v in (self._C * acb_mat([[v] for v in F2])).entries()])
        if not want:
            return F, None
        J1 = [[acb(0)] * n for _ in sysm.circles]
        for i, (a, b) in enumerate(sysm.circles):
            J1[i][a], J1[i][b] = 2 * z[a], 2 * z[b]
        CJ = self._C * acb_mat(J2)
        return F, acb_mat(J1 + [[CJ[i, j] for j in range(n)] for i in range(CJ.nrows())])

    # ------------------------------------------------------------------ the ball system
    def values(self, x):
        return self._square(x, False)[0] if self._fast else super().values(x)

    def jacobian(self, x):
        return self._square(x, True)[1] if self._fast else super().jacobian(x)


def loop_ball_system(sysm: LoopSystem, p: np.ndarray) -> LoopBallSystem:
    """The ball system of the loop formulation ``sysm`` at the parameters ``p``."""
    return LoopBallSystem(sysm, p)


def certify_loop(sysm: LoopSystem, p: np.ndarray, configs: Sequence) -> list[Certificate]:
    """Certificates of the configurations ``configs`` (:class:`..closure.Configuration`) as roots
    of the square system of ``sysm`` at the actuator parameters ``p``
    (:meth:`.loop_system.LoopSystem.parameters`)."""
    if not configs:
        return []
    X = np.array([variables(sysm, c)[: sysm.nx] for c in configs], dtype=complex)
    return list(certify(LoopBallSystem(sysm, p), X))
