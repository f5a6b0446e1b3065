"""Every assembly mode of a model whose limbs do not reduce to quadrics in the Study parameters
(:mod:`.homotopy_systems`): a polynomial formulation in the joint variables, generated from the
model, solved by monodromy and a parameter homotopy.

Formulation (limbs from the ground to the platform; joints R, P, C, U, S, Sm).  Every passive,
unlocked revolute freedom is a pair ``(c, s)`` with ``c^2 + s^2 = 1`` and its displacement
``exp(theta A) = I + s A + (1 - c) A^2`` (``A`` the 4x4 matrix of its unit twist, pitch 0:
``A^3 = -A``), every passive slide a linear variable ``d`` (over the characteristic length
``L``) with ``exp(d A) = I + d A``; an actuated freedom is the same with its ``(c, s)`` or ``d``
as a *parameter*.  The product of a limb's displacements is then polynomial.  The platform
displacement ``D`` is the product of the first limb without an S joint (the *reference
limb*), or, when every limb has one, the Study parameters ``x = (e ; g)`` of :mod:`.homotopy`
(``(e.e) D`` polynomial, with ``e.g = 0`` and a random complex patch).  Each other limb gives:

* no S joint: ``FK = D``: the three off-diagonal entries of ``R_FK^T R_D`` and the
  translation difference (6 equations; they also vanish where ``R_FK^T R_D`` is a half turn
  about a coordinate axis: spurious points that the full closure, all 12 entries, rejects);
* one S joint at centre ``c``: ``before(c) = D after^-1(c)`` (3 entries): the S joint's rotation
  is then whatever closes the limb, so it is not a variable;
* two consecutive S joints (a rod, centres ``c1``, ``c2``): ``|before(c1) - D after^-1(c2)|^2 =
  |c1 - c2|^2`` (1 entry): the rod's idle spin is not a variable either.

The equations can outnumber the conditions they impose (a spherical or planar limb has 3, an
overconstrained linkage such as the Bennett fewer than its equations): the number of
independent conditions of each limb is the rank of its equations at a generic configuration
(a random walk from the reference along the closure, actuators held), and the system is made
square by random complex combinations (each limb's equations to its rank when the ranks add
up to the number of unknowns, else all equations to that number), and every end point is
checked against the full closure: points of the square system that do not close are
*spurious* and discarded (their number is reported).

Solver: monodromy on a family of square systems with a start pair built from a random complex
point, then a parameter homotopy to the request.  When every limb's equations are independent
(the ranks equal the numbers of equations: no random combination needed), the family moves the
limbs themselves (:attr:`LoopSystem.rigid_family`): a complex rigid offset ``W_k`` (a
quaternion and a translation) per limb without S joint, a point offset per single S joint and a
change of length per rod; a random complex point ``x0`` on the circles (and the Study quadric)
closes with the offsets it misses by, and the genuine solutions form an irreducible incidence
variety (parametrised by ``x`` and the actuators), so the loops act transitively on the generic
solutions and never leave them: no spurious points (the general 6R loop: the 16 solutions of
the inverse kinematics, no more).  Otherwise (overconstrained or spherical limbs) the family is
``G(x; p) = b`` with an offset ``b`` of the square system: for a random complex ``x0`` and
``p0``, ``b0 = G(x0; p0)``; that incidence variety is the graph of ``G``, irreducible too, but
its generic solutions include points of the square system that do not close.  Loops
``P0 -> P1 -> P2 -> P0`` through random complex parameters (four per round, each round also
moving fresh start pairs to ``P0``) stop after :data:`MONODROMY_STALE_LOOPS` loops in a row
without a new solution: a *saturation*, not a proof (no trace test), and the result says so
(``complete`` is false).  A parameter homotopy along the straight segment from ``P0`` to the
request (actuators given, no offsets) then tracks every known solution, with the NumPy tracker
:func:`.homotopy.track` and the compiled square system (:mod:`.kernels_loops`).  The generic
solve is cached per geometry (in memory).
"""

from __future__ import annotations

import time
import weakref
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from ..geometry.rotations import matrix_rotvec, skew
from ..geometry.tolerances import (
    HOMOTOPY_INFINITY,
    HOMOTOPY_REAL,
    HOMOTOPY_SINGULAR,
    MONODROMY_DIVERGED,
    MONODROMY_MAX_LOOPS,
    MONODROMY_MAX_SECONDS,
    MONODROMY_MAX_SOLUTIONS,
    MONODROMY_PARALLEL,
    MONODROMY_RESIDUAL,
    MONODROMY_STALE_LOOPS,
)
from ..model.mechanism import Mechanism
from . import compiled, kernels_loops
from .closure import Configuration, limb_slices
from .homotopy import study_to_pose, track

__all__ = [
    "GeneralResult",
    "GeneralSolution",
    "LoopSystem",
    "clear_cache",
    "configuration",
    "general_forward",
    "general_reason",
    "loop_system",
    "rebuild",
    "variables",
]

_I4 = np.eye(4)


@dataclass(frozen=True, eq=False)
class _Factor:
    kind: str  # "R" or "P"
    A: np.ndarray  # 4x4 twist matrix (moments over L)
    A2: np.ndarray
    idx: tuple[int, ...]  # (c, s) or (d,) in the variable vector z = (x ; p)
    inverse: bool = False

    def inverted(self) -> _Factor:
        return _Factor(self.kind, self.A, self.A2, self.idx, not self.inverse)


@dataclass(frozen=True, eq=False)
class _LimbEq:
    kind: str  # "full", "point", "rod"
    before: tuple[_Factor, ...]
    after_inv: tuple[_Factor, ...]  # the factors after the S joint(s), inverted, in reverse order
    c1: np.ndarray  # homogeneous centre(s) (over L)
    c2: np.ndarray
    length2: float  # rod length squared (over L^2)
    limb: int
    s_first: int  # index in the limb of the first S freedom (-1: none)


@dataclass(frozen=True, eq=False)
class LoopSystem:
    """The polynomial closure of a model (module docstring): unknowns ``x`` (``nx``),
    parameters ``p`` (the actuators, ``npar``), the square system ``G`` and the full closure."""

    mech: Mechanism
    L: float
    nx: int
    npar: int
    circles: tuple[tuple[int, int], ...]  # (c, s) index pairs of the unknown revolutes
    ref: tuple[_Factor, ...] | None  # the reference limb's factors (None: Study parameters)
    ref_limb: int
    study: int  # index of e0 in x when the platform is in Study parameters (-1 otherwise)
    patch: np.ndarray | None
    limbs: tuple[_LimbEq, ...]
    compress: np.ndarray  # (m, r) complex: closure entries -> square rows
    var_of: dict  # freedom index -> ("R", ic, is) / ("P", id) / ("A", ...) parameter / ("L",) locked / ("S",)
    params: tuple[tuple[int, str, tuple[int, ...]], ...]  # (freedom index, kind, z indices)
    n_conditions: int
    rigid_family: bool = False  # every limb's equations independent: monodromy over the limbs' offsets

    @property
    def n_rows(self) -> int:
        return self.compress.shape[0]

    def key(self) -> bytes:
        parts = [np.array([self.nx, self.npar, self.ref_limb, self.study], float)]
        for f in self.ref or ():
            parts.append(f.A.ravel())
        for le in self.limbs:
            parts += [f.A.ravel() for f in le.before + le.after_inv] + [le.c1, le.c2, np.array([le.length2])]
        return np.round(np.concatenate(parts), 12).tobytes()

    # -------------------------------------------------------------------------- evaluation
    def _chain(self, factors, Z):
        n, nz = Z.shape
        T = np.broadcast_to(_I4, (n, 4, 4)).astype(complex)
        dT = np.zeros((n, nz, 4, 4), complex)
        for f in factors:
            sg = -1.0 if f.inverse else 1.0
            if f.kind == "R":
                c, s = Z[:, f.idx[0]], Z[:, f.idx[1]]
                M = _I4 + sg * s[:, None, None] * f.A + (1 - c)[:, None, None] * f.A2
                dT = dT @ M[:, None]
                dT[:, f.idx[0]] += T @ (-f.A2)
                dT[:, f.idx[1]] += T @ (sg * f.A)
            else:
                d = Z[:, f.idx[0]]
                M = _I4 + sg * d[:, None, None] * f.A
                dT = dT @ M[:, None]
                dT[:, f.idx[0]] += T @ (sg * f.A)
            T = T @ M
        return T, dT

    def _platform(self, Z):
        """``D`` (or ``(e.e) D``), its derivative, and the scale ``n`` (1, or ``e.e``) with its derivative."""
        n, nz = Z.shape
        if self.ref is not None:
            T, dT = self._chain(self.ref, Z)
            return T, dT, np.ones(n, complex), np.zeros((n, nz), complex)
        k = self.study
        X = Z[:, k : k + 8]
        Dn = np.einsum("ni,abij,nj->nab", X, _STUDY_Q, X)
        dDn = np.zeros((n, nz, 4, 4), complex)
        dDn[:, k : k + 8] = np.einsum("abij,nj->niab", _STUDY_Q + _STUDY_Q.transpose(0, 1, 3, 2), X)
        E = np.einsum("ni,ni->n", X[:, :4], X[:, :4])
        dE = np.zeros((n, nz), complex)
        dE[:, k : k + 4] = 2 * X[:, :4]
        return Dn, dDn, E, dE

    @property
    def w_offsets(self) -> tuple[int, ...]:
        """Start of each limb's offset parameters in ``W`` (a limb without S joint: a quaternion
        and a translation, 7; one S joint: a translation, 3; a rod: a change of length squared, 1)
        and, last, their number."""
        out = [0]
        for le in self.limbs:
            out.append(out[-1] + (7 if le.kind == "full" else 3 if le.kind == "point" else 1))
        return tuple(out)

    def identity_offsets(self, n: int = 1) -> np.ndarray:
        """The offset parameters of the mechanism itself (no offset): (n, nw)."""
        off = self.w_offsets
        W = np.zeros((n, off[-1]), complex)
        for k, le in enumerate(self.limbs):
            if le.kind == "full":
                W[:, off[k]] = 1.0
        return W

    def closure(self, Z, full: bool = False, W=None):
        """The closure equations (n, r) and their derivative (n, r, nz) at points ``Z = (x ; p)``:
        a limb without S joint gives the off-diagonal entries of ``R_limb^T R_platform`` and the
        translation difference (6; zero also at the three half-turns about the axes, spurious
        points the full closure rejects), or with ``full`` every entry of ``T_limb - D`` (12)."""
        D, dD, E, dE = self._platform(Z)
        rows, jac = [], []
        n = len(Z)
        off = self.w_offsets
        if W is None:
            W = self.identity_offsets(n)
        for k, le in enumerate(self.limbs):
            w_k = W[:, off[k] : off[k + 1]]
            Tb, dTb = self._chain(le.before, Z)
            if le.kind == "full" and full:
                r = E[:, None, None] * Tb - D
                dr = E[:, None, None, None] * dTb + dE[:, :, None, None] * Tb[:, None] - dD
                rows.append(r[:, :3].reshape(n, 12))
                jac.append(dr[:, :, :3].reshape(n, -1, 12).transpose(0, 2, 1))
                continue
            if le.kind == "full":  # with the offset (q, t): R_D -> R_D E(q), p_D -> p_D + R_D t
                Eq = _rotation_forms(w_k[:, :4])
                A, dA = Tb[:, :3, :3], dTb[:, :, :3, :3]
                B, dB = D[:, :3, :3] @ Eq, dD[:, :, :3, :3] @ Eq[:, None]
                P = np.einsum("nai,naj->nij", A, B)
                dP = np.einsum("nzai,naj->nzij", dA, B) + np.einsum("nai,nzaj->nzij", A, dB)
                ii, jj = (0, 0, 1), (1, 2, 2)
                tk = w_k[:, 4:7]
                t = E[:, None] * Tb[:, :3, 3] - D[:, :3, 3] - np.einsum("nab,nb->na", D[:, :3, :3], tk)
                dt = (E[:, None, None] * dTb[:, :, :3, 3] + dE[:, :, None] * Tb[:, None, :3, 3] - dD[:, :, :3, 3]
                      - np.einsum("nzab,nb->nza", dD[:, :, :3, :3], tk))
                rows.append(np.concatenate([P[:, ii, jj], t], axis=1))
                jac.append(np.concatenate([dP[:, :, ii, jj], dt], axis=2).transpose(0, 2, 1))
                continue
            Ta, dTa = self._chain(le.after_inv, Z)
            u1 = Tb @ le.c1
            du1 = dTb @ le.c1
            v = Ta @ le.c2
            dv = dTa @ le.c2
            u2 = np.einsum("nab,nb->na", D, v)
            du2 = np.einsum("nzab,nb->nza", dD, v) + np.einsum("nab,nzb->nza", D, dv)
            w = E[:, None] * u1 - u2
            dw = E[:, None, None] * du1 + dE[:, :, None] * u1[:, None] - du2
            w, dw = w[:, :3], dw[:, :, :3]
            if le.kind == "point":  # with the offset o: before(c) = D after^-1(c) + o
                rows.append(w - E[:, None] * w_k)
                jac.append((dw - dE[:, :, None] * w_k[:, None]).transpose(0, 2, 1))
            else:  # with the offset beta: length squared + beta
                l2 = le.length2 + w_k[:, 0]
                rows.append((np.einsum("na,na->n", w, w) - E**2 * l2)[:, None])
                jac.append((2 * np.einsum("na,nza->nz", w, dw) - 2 * (E * l2)[:, None] * dE)[:, None])
        if not rows:
            return np.zeros((len(Z), 0), complex), np.zeros((len(Z), 0, Z.shape[1]), complex)
        return np.concatenate(rows, axis=1), np.concatenate(jac, axis=1)

    def side(self, Z):
        """The circles, the Study quadric and patch: entries (n, k) and derivative (n, k, nz)."""
        n, nz = Z.shape
        k = len(self.circles) + (2 if self.study >= 0 else 0)
        F = np.zeros((n, k), complex)
        J = np.zeros((n, k, nz), complex)
        for i, (a, b) in enumerate(self.circles):
            F[:, i] = Z[:, a] ** 2 + Z[:, b] ** 2 - 1
            J[:, i, a] = 2 * Z[:, a]
            J[:, i, b] = 2 * Z[:, b]
        if self.study >= 0:
            s, i = self.study, len(self.circles)
            X = Z[:, s : s + 8]
            F[:, i] = np.einsum("ni,ni->n", X[:, :4], X[:, 4:])
            J[:, i, s : s + 4] = X[:, 4:]
            J[:, i, s + 4 : s + 8] = X[:, :4]
            assert self.patch is not None
            F[:, i + 1] = X @ self.patch - 1
            J[:, i + 1, s : s + 8] = self.patch
        return F, J

    def square(self, Z, W=None, *, reference: bool = False, want_J: bool = True):
        """The square system ``G`` (n, nx) and its derivative (n, nx, nz) in ``z = (x ; p)``,
        with the offset parameters ``W`` (n, nw; default none): compiled (:mod:`.kernels_loops`)
        when the compiled core is in use and not ``reference``."""
        if W is None:
            W = self.identity_offsets(len(Z))
        if not reference and compiled.enabled():
            packed = _PACKED.get(self)
            if packed is None:
                packed = _PACKED[self] = kernels_loops.pack(self, _STUDY_Q)
            return kernels_loops.square_batch(np.ascontiguousarray(Z, dtype=np.complex128),
                                              np.ascontiguousarray(W, dtype=np.complex128), want_J, *packed)
        F1, J1 = self.side(Z)
        F2, J2 = self.closure(Z, W=W)
        F = np.concatenate([F1, np.einsum("mr,nr->nm", self.compress, F2)], axis=1)
        J = np.concatenate([J1, np.einsum("mr,nrz->nmz", self.compress, J2)], axis=1)
        return F, J

    def residual(self, Z):
        """Relative residual of the full closure (every entry) and the side equations per point."""
        F1, _ = self.side(Z)
        F2, _ = self.closure(Z, full=True)
        scale = 1.0 + np.linalg.norm(Z[:, : self.nx], axis=1)
        if self.study >= 0:
            scale = np.maximum(scale, np.linalg.norm(Z[:, self.study : self.study + 8], axis=1) ** 4)
        return np.concatenate([np.abs(F1), np.abs(F2)], axis=1).max(axis=1, initial=0.0) / scale

    def parameters(self, targets: dict[int, float]) -> np.ndarray:
        """The parameter vector of actuator values ``targets`` (joint variable by freedom index)."""
        p = np.zeros(self.npar)
        for fi, kind, idx in self.params:
            v = targets[fi]
            if kind == "R":
                p[idx[0] - self.nx], p[idx[1] - self.nx] = np.cos(v), np.sin(v)
            else:
                p[idx[0] - self.nx] = v / self.L
        return p


def _rotation_forms(q: np.ndarray) -> np.ndarray:
    """``E(q) = (q.q) R(q)`` (n, 3, 3) of quaternions ``q`` (n, 4), complex allowed."""
    w, i, j, k = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([np.stack([w * w + i * i - j * j - k * k, 2 * (i * j - w * k), 2 * (i * k + w * j)], -1),
                     np.stack([2 * (i * j + w * k), w * w - i * i + j * j - k * k, 2 * (j * k - w * i)], -1),
                     np.stack([2 * (i * k - w * j), 2 * (j * k + w * i), w * w - i * i - j * j + k * k], -1)], 1)


def _study_forms() -> np.ndarray:
    """``(e.e) D`` of the Study parameters as quadratic forms: (4, 4, 8, 8) symmetric."""
    from .homotopy_systems import qmul

    def nd(x):
        e, g = x[:4], x[4:]
        w, i, j, k = e
        M = np.zeros((4, 4))
        M[:3, :3] = [[w * w + i * i - j * j - k * k, 2 * (i * j - w * k), 2 * (i * k + w * j)],
                     [2 * (i * j + w * k), w * w - i * i + j * j - k * k, 2 * (j * k - w * i)],
                     [2 * (i * k - w * j), 2 * (j * k + w * i), w * w - i * i - j * j + k * k]]
        M[:3, 3] = 2 * qmul(g, e * np.array([1, -1, -1, -1]))[1:]
        M[3, 3] = e @ e
        return M

    Q = np.zeros((4, 4, 8, 8))
    eye = np.eye(8)
    for a in range(8):
        Q[:, :, a, a] = nd(eye[a])
    for a in range(8):
        for b in range(a + 1, 8):
            Q[:, :, a, b] = Q[:, :, b, a] = 0.5 * (nd(eye[a] + eye[b]) - nd(eye[a]) - nd(eye[b]))
    return Q


_STUDY_Q = _study_forms()
_PACKED: weakref.WeakKeyDictionary[LoopSystem, tuple] = weakref.WeakKeyDictionary()


def _twist_matrix(S: np.ndarray, L: float, slide: bool) -> np.ndarray:
    """The 4x4 matrix of a unit twist in units of ``L``: a rotation's moment over ``L``; a
    slide's direction as it is (its variable is the slide over ``L``)."""
    A = np.zeros((4, 4))
    A[:3, :3] = skew(S[:3])
    A[:3, 3] = S[3:] if slide else S[3:] / L
    return A


def general_reason(mech: Mechanism) -> str | None:
    """``None`` when :func:`loop_system` formulates ``mech``, else why not (one sentence)."""
    try:
        loop_system(mech)
    except InputError as exc:
        return str(exc)
    return None


_SYSTEMS: weakref.WeakKeyDictionary[Mechanism, LoopSystem] = weakref.WeakKeyDictionary()


def loop_system(mech: Mechanism, seed: int = 0) -> LoopSystem:
    """The polynomial closure of ``mech`` (module docstring); ``InputError`` naming the limb or
    joint when the formulation does not cover it."""
    hit = _SYSTEMS.get(mech)
    if hit is not None:
        return hit
    if mech.bodies:
        raise InputError("a link-and-joint graph (internal bodies): the loop formulation covers limbs from the ground "
                         "to the platform only")
    L = mech.characteristic_length
    refs = mech.freedom_refs
    acts = set(mech.actuators)
    slices = limb_slices(mech)
    # the S joints of each limb, and which limbs can define the platform
    s_of: list[list[tuple[int, np.ndarray]]] = []
    for limb in mech.limbs:
        if limb.base != "ground" or limb.tip is not None:
            raise InputError(f"limb {limb.name} does not run from the ground to the platform")
        k, ss = 0, []
        for j in limb.joints:
            if j.type == "S":
                if any(f.actuated for f in j.freedoms):
                    raise InputError(f"limb {limb.name}: S joint {j.name} is actuated")
                ss.append((k, np.asarray(j.point, float)))
            for f in j.freedoms:
                if f.kind == "H" and f.pitch != 0:
                    raise InputError(f"limb {limb.name}: helical joint {j.name} (its rotation angle enters both "
                                     "as an angle and through its sine and cosine: not polynomial)")
            k += len(j.freedoms)
        if len(ss) > 2 or (len(ss) == 2 and ss[1][0] != ss[0][0] + 3):
            raise InputError(f"limb {limb.name}: S joints other than one, or two adjacent (a rod)")
        s_of.append(ss)
    no_s = [li for li in range(len(mech.limbs)) if not s_of[li]]
    n_unknown = [sum(1 for i in range(sl.start, sl.stop) if not refs[i].freedom.locked and refs[i].id not in acts)
                 for sl in slices]
    ref_limb = min(no_s, key=lambda li: n_unknown[li]) if no_s else -1

    var_of: dict = {}
    nx = 0
    circles = []
    for i, r in enumerate(refs):
        li = r.limb
        k = i - slices[li].start
        if any(k0 <= k < k0 + 3 for k0, _ in s_of[li]):
            var_of[i] = ("S",)
        elif r.freedom.locked:
            var_of[i] = ("L",)
        elif r.id in acts:
            var_of[i] = ("A",)
        elif r.freedom.kind == "P":
            var_of[i] = ("P", nx)
            nx += 1
        else:
            var_of[i] = ("R", nx, nx + 1)
            circles.append((nx, nx + 1))
            nx += 2
    study = -1
    if ref_limb < 0:
        study = nx
        nx += 8
    params = []
    npar = 0
    for i, r in enumerate(refs):
        if var_of[i] == ("A",):
            idx = (nx + npar, nx + npar + 1) if r.freedom.kind != "P" else (nx + npar,)
            var_of[i] = ("A", *idx)
            params.append((i, "P" if r.freedom.kind == "P" else "R", idx))
            npar += len(idx)

    def factors(li: int, lo: int, hi: int) -> list[_Factor]:
        out = []
        for i in range(slices[li].start + lo, slices[li].start + hi):
            v = var_of[i]
            if v[0] in ("L", "S"):
                continue
            kind = "P" if refs[i].freedom.kind == "P" else "R"
            A = _twist_matrix(refs[i].freedom.screw, L, kind == "P")
            out.append(_Factor(kind, A, A @ A, tuple(v[1:])))
        return out

    limbs: list[_LimbEq] = []
    cond = 0
    for li in range(len(mech.limbs)):
        if li == ref_limb:
            continue
        m = slices[li].stop - slices[li].start
        ss = s_of[li]
        z4 = np.zeros(4)
        if not ss:
            limbs.append(_LimbEq("full", tuple(factors(li, 0, m)), (), z4, z4, 0.0, li, -1))
            cond += 6
            continue
        k0 = ss[0][0]
        k1 = ss[-1][0] + 3
        c1 = np.append(ss[0][1] / L, 1.0)
        c2 = np.append(ss[-1][1] / L, 1.0)
        after = [f.inverted() for f in reversed(factors(li, k1, m))]
        if len(ss) == 1:
            limbs.append(_LimbEq("point", tuple(factors(li, 0, k0)), tuple(after), c1, c1, 0.0, li, k0))
            cond += 3
        else:
            limbs.append(_LimbEq("rod", tuple(factors(li, 0, k0)), tuple(after), c1, c2,
                                 float(np.sum((c1 - c2) ** 2)), li, k0))
            cond += 1
    m_needed = nx - len(circles) - (2 if study >= 0 else 0)
    sizes = [6 if le.kind == "full" else 3 if le.kind == "point" else 1 for le in limbs]
    rng = np.random.default_rng(seed + 7919)
    patch = (rng.normal(size=8) + 1j * rng.normal(size=8)) if study >= 0 else None
    ref = tuple(factors(ref_limb, 0, slices[ref_limb].stop - slices[ref_limb].start)) if ref_limb >= 0 else None
    sysm = LoopSystem(mech, L, nx, npar, tuple(circles), ref, ref_limb, study, patch, tuple(limbs),
                      np.eye(sum(sizes), dtype=complex), var_of, tuple(params), cond)
    ranks = _limb_ranks(sysm, sizes, rng)
    cond = sum(ranks)
    if cond < m_needed:
        raise InputError(f"the closure of {mech.name} leaves {m_needed - cond} freedom(s) undetermined with the actuators "
                         "held (a mobility the loop formulation does not remove, e.g. an idle freedom other than an S-S "
                         "rod's spin)")

    def rnd(a, b):
        M = rng.normal(size=(a, b)) + 1j * rng.normal(size=(a, b))
        return M / np.linalg.norm(M, axis=1, keepdims=True)

    if cond == m_needed:  # each limb's entries to its number of independent conditions
        C = np.zeros((m_needed, sum(sizes)), complex)
        row = col = 0
        for rk, sz in zip(ranks, sizes, strict=True):
            C[row : row + rk, col : col + sz] = rnd(rk, sz) if rk < sz else np.eye(sz)
            row += rk
            col += sz
    else:  # overconstrained as a whole: every entry into the number of rows needed
        C = rnd(m_needed, sum(sizes))
    sysm = replace(sysm, compress=C, n_conditions=cond,
                   rigid_family=cond == m_needed and all(rk == sz for rk, sz in zip(ranks, sizes, strict=True)))
    _SYSTEMS[mech] = sysm
    return sysm


def variables(sysm: LoopSystem, config: Configuration) -> np.ndarray:
    """The variables ``z = (x ; p)`` of a real configuration (joint variables ``q``, platform ``D``)."""
    z = np.zeros(sysm.nx + sysm.npar)
    for i, v in sysm.var_of.items():
        qi = config.q[i]
        if v[0] in ("R", "A") and len(v) == 3:
            z[v[1]], z[v[2]] = np.cos(qi), np.sin(qi)
        elif v[0] in ("P", "A"):
            z[v[1]] = qi / sysm.L
    if sysm.study >= 0:
        from scipy.spatial.transform import Rotation

        x, y, zz, w = Rotation.from_matrix(config.D[:3, :3]).as_quat()
        e = np.array([w, x, y, zz])
        from .homotopy_systems import qmul

        g = 0.5 * qmul(np.concatenate([[0.0], config.D[:3, 3] / sysm.L]), e)
        xs = np.concatenate([e, g]).astype(complex)
        assert sysm.patch is not None
        z = z.astype(complex)
        z[sysm.study : sysm.study + 8] = xs / (xs @ sysm.patch)
    return np.asarray(z, complex)


def _limb_ranks(sysm: LoopSystem, sizes: list[int], rng: np.random.Generator) -> list[int]:
    """The number of independent conditions of each limb's closure entries on the unknowns: the
    rank of their derivative along the side equations' solution set (circles, Study quadric),
    the actuators held, at a generic
    configuration of the mechanism (a random walk from the reference along its closure)."""
    from .closure import generic_configuration

    try:
        config = generic_configuration(sysm.mech, seed=int(rng.integers(2**31)), step=0.5, steps=4)
    except RuntimeError:
        config = Configuration.reference(sysm.mech)
    z = variables(sysm, config)[None]
    _, Js = sysm.side(z)
    _, Jc = sysm.closure(z)
    Js, Jc = Js[:, :, : sysm.nx], Jc[:, :, : sysm.nx]  # the actuators held
    _, sv, vt = np.linalg.svd(Js[0])
    N = vt[int(np.sum(sv > 1e-9 * max(1.0, sv[0] if sv.size else 0.0))):].conj().T
    out, j = [], 0
    for sz in sizes:
        M = Jc[0, j : j + sz] @ N
        s = np.linalg.svd(M, compute_uv=False)
        out.append(int(np.sum(s > 1e-8 * max(1.0, s[0] if s.size else 0.0))))
        j += sz
    return out


# ------------------------------------------------------------------------------ solving
def _segment(sysm: LoopSystem, X, P0, P1):
    """Track the points ``X`` (n, nx) from the parameters ``P0`` to ``P1`` (straight segments;
    each (np + nw + nx,) for all points or (n, np + nw + nx) one per point: actuator parameters,
    the limbs' offsets ``W``, then the offsets ``b`` of the square system ``G = b``).  ``H_t``:
    exact in the actuators and ``b``; by central differences in ``W`` (exact up to rounding for
    the parts of degree two or less, ample for the predictor elsewhere)."""
    nx, npar, nw = sysm.nx, sysm.npar, sysm.w_offsets[-1]
    if len(X) == 0:
        return X, np.zeros(0), np.zeros(0, bool)
    A0 = np.broadcast_to(P0, (len(X), npar + nw + nx))
    dA = np.broadcast_to(P1, A0.shape) - A0
    h = 1e-5

    def G(Xc, P, want_J):
        F, J = sysm.square(np.concatenate([Xc, P[:, :npar]], axis=1), P[:, npar : npar + nw], want_J=want_J)
        return F - P[:, npar + nw :], J

    moves_w = bool(np.any(dA[:, npar : npar + nw]))

    def fun(Xc, t, idx):
        P = A0[idx] + t[:, None] * dA[idx]
        n = len(Xc)
        F, J = G(Xc, P, True)
        d = dA[idx]
        Ht = np.einsum("nkp,np->nk", J[:, :, nx:], d[:, :npar]) - d[:, npar + nw :]
        if moves_w:  # the limbs' offsets: central differences in W alone
            dW = np.zeros_like(P)
            dW[:, npar : npar + nw] = h * d[:, npar : npar + nw]
            Fp, _ = G(np.tile(Xc, (2, 1)), np.concatenate([P + dW, P - dW]), False)
            Ht = Ht + (Fp[:n] - Fp[n:]) / (2 * h)
        return F, J[:, :, :nx], Ht

    Xe, t, done, _ = track(fun, X, max_steps=2000, indexed=True)
    return Xe, t, done


def _new_points(known: np.ndarray, cand: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    out: list[np.ndarray] = []
    for x in cand:
        ref = known if not out else np.vstack([known, *[o[None] for o in out]])
        d = np.linalg.norm(ref - x, axis=1) / (1 + np.linalg.norm(x))
        if np.all(d > tol):
            out.append(x)
    return np.array(out).reshape(-1, known.shape[1])


def _random_point(sysm: LoopSystem, rng: np.random.Generator) -> np.ndarray:
    """A random complex point ``x`` on the side equations (circles, Study quadric, patch)."""
    x = rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)
    for a, b in sysm.circles:
        th = rng.uniform(-np.pi, np.pi) + 1j * rng.normal(scale=0.5)
        x[a], x[b] = np.cos(th), np.sin(th)
    if sysm.study >= 0:
        s = sysm.study
        e, g = x[s : s + 4], x[s + 4 : s + 8]
        g = g - (e @ g) / (e @ e) * e
        xs = np.concatenate([e, g])
        assert sysm.patch is not None
        x[s : s + 8] = xs / (xs @ sysm.patch)
    return x


def _random_parameters(sysm: LoopSystem, rng: np.random.Generator) -> np.ndarray:
    """Random complex actuator parameters, a driven rotation's ``(c, s)`` on its circle (so that
    every displacement of a start pair is a complex rigid motion)."""
    p = rng.normal(size=sysm.npar) + 1j * rng.normal(size=sysm.npar)
    for _, kind, idx in sysm.params:
        if kind == "R":
            th = rng.uniform(-np.pi, np.pi) + 1j * rng.normal(scale=0.5)
            p[idx[0] - sysm.nx], p[idx[1] - sysm.nx] = np.cos(th), np.sin(th)
    return p


def _start_offsets(sysm: LoopSystem, x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The offset parameters for which ``x`` (on the side equations) with actuator parameters
    ``p`` solves the closure: each limb's offset is what it misses by."""
    z = np.concatenate([x, p])[None]
    D, _, E, _ = sysm._platform(z)
    D, E = D[0], E[0]
    off = sysm.w_offsets
    W = np.zeros(off[-1], complex)
    for k, le in enumerate(sysm.limbs):
        Tb = sysm._chain(le.before, z)[0][0]
        if le.kind == "full":
            M = np.linalg.solve(D[:3, :3], Tb[:3, :3])  # proportional to a complex rotation
            sc = np.sqrt(np.trace(M.T @ M) / 3)
            if abs(np.linalg.det(M) / sc**3 + 1) < 0.5:
                sc = -sc
            R = M / sc
            W[off[k] : off[k] + 4] = [1 + np.trace(R), R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]
            W[off[k] + 4 : off[k] + 7] = np.linalg.solve(D[:3, :3], E * Tb[:3, 3] - D[:3, 3])
            continue
        Ta = sysm._chain(le.after_inv, z)[0][0]
        w = (E * (Tb @ le.c1) - D @ (Ta @ le.c2))[:3]
        if le.kind == "point":
            W[off[k] : off[k] + 3] = w / E
        else:
            W[off[k]] = (w @ w) / E**2 - le.length2
    return W


@dataclass(frozen=True, eq=False)
class _GenericLoop:
    P0: np.ndarray  # the generic parameters: actuators, then offsets
    X: np.ndarray
    loops: int
    seconds: float
    saturated: bool


_CACHE: dict[bytes, _GenericLoop] = {}


def _monodromy(sysm: LoopSystem, seed: int, capped: bool) -> _GenericLoop:
    """The generic instance's solutions by monodromy; ``capped``: also stop at
    :data:`MONODROMY_MAX_SOLUTIONS` solutions or :data:`MONODROMY_MAX_SECONDS` (unsaturated)."""
    key = sysm.key() + bytes([seed % 256])
    if key in _CACHE:
        return _CACHE[key]
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)

    def crand(*shape):
        return rng.normal(size=shape) + 1j * rng.normal(size=shape)

    rigid = sysm.rigid_family

    def start(n):
        xs, Ps = [], []
        for _ in range(n):
            p = _random_parameters(sysm, rng)
            if rigid:  # a point on the side equations, the limbs' offsets that make it close
                x = _random_point(sysm, rng)
                Ps.append(np.concatenate([p, _start_offsets(sysm, x, p), np.zeros(sysm.nx)]))
            else:  # any point, the offset b of the square system that makes it a solution
                x = rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)
                W = sysm.identity_offsets()[0]
                b = sysm.square(np.concatenate([x, p])[None], W[None])[0][0]
                Ps.append(np.concatenate([p, W, b]))
            xs.append(x)
        return np.array(xs), np.array(Ps)

    X0, P0s = start(1)
    x0, P0 = X0[0], P0s[0]
    npar, nw = sysm.npar, sysm.w_offsets[-1]
    free = np.zeros(len(P0), bool)  # the parameters the loops move: actuators, and W or b
    free[:npar] = True
    if rigid:
        free[npar : npar + nw] = True
    else:
        free[npar + nw :] = True
    scale = np.where(free, np.abs(P0) + 1.0, 0.0)
    known = x0[None]
    stale = loops = 0
    k = MONODROMY_PARALLEL
    capped_out = False
    while stale < MONODROMY_STALE_LOOPS and loops < MONODROMY_MAX_LOOPS:
        if capped and (len(known) > MONODROMY_MAX_SOLUTIONS or time.perf_counter() - t0 > MONODROMY_MAX_SECONDS):
            capped_out = True
            break
        loops += k  # k loops at once, each through its own two random parameter points
        B1 = np.repeat(np.where(free, scale * crand(k, len(P0)), P0), len(known), axis=0)
        B2 = np.repeat(np.where(free, scale * crand(k, len(P0)), P0), len(known), axis=0)
        X = np.tile(known, (k, 1))
        for leg in range(3):
            a, b = ((P0, B1), (B1, B2), (B2, P0))[leg]
            X, _, done = _segment(sysm, X, a, b)
            X, B1, B2 = X[done], B1[done], B2[done]  # a failed path is dropped
        xr, Pr = start(k)  # and fresh start pairs, moved to P0
        Xr, _, done = _segment(sysm, xr, Pr, P0)
        X = np.vstack([X, Xr[done]])
        new = _new_points(known, X)
        if len(new):
            known = np.vstack([known, new])
            stale = 0
        else:
            stale += k
    g = _GenericLoop(P0, known, loops, time.perf_counter() - t0, stale >= MONODROMY_STALE_LOOPS)
    if not capped_out:  # a capped run is redone in full when asked without the caps
        _CACHE[key] = g
    return g


def clear_cache() -> None:
    """Forget the cached generic solves (benchmarks time the first solve)."""
    _CACHE.clear()


@dataclass(frozen=True, eq=False)
class GeneralSolution:
    """One end point at the request: ``status`` real / complex / singular / at_infinity, the
    variables ``x`` and, for a real one, the joint variables ``q`` and platform ``D``."""

    status: str
    x: np.ndarray
    rcond: float
    imag_ratio: float
    residual: float
    q: np.ndarray | None = None
    D: np.ndarray | None = None

    def to_dict(self) -> dict:
        return {"status": self.status, "variables_real": [float(v) for v in self.x.real],
                "variables_imag": [float(v) for v in self.x.imag], "inverse_condition": self.rcond,
                "imaginary_ratio": self.imag_ratio, "residual": self.residual}


@dataclass(frozen=True, eq=False)
class GeneralResult:
    solutions: tuple[GeneralSolution, ...]
    saturated: bool  # the monodromy stopped because loops found nothing new (not at a cap)
    complete: bool
    completeness: str
    n_generic: int
    n_spurious: int
    loops: int
    seconds_generic: float
    seconds: float
    cached: bool

    def count(self, status: str) -> int:
        return sum(s.status == status for s in self.solutions)


def general_forward(mech: Mechanism, targets: dict[int, float], *, seed: int = 0, capped: bool = False) -> GeneralResult:
    """Every solution found of the forward position of ``mech`` with the actuators at
    ``targets`` (joint variables by freedom index, as ``forward._actuator_q`` gives them);
    ``capped``: the monodromy gives up early on large systems (``saturated`` false)."""
    t0 = time.perf_counter()
    sysm = loop_system(mech)
    if set(targets) != {fi for fi, _, _ in sysm.params}:
        raise InputError(f"actuators: expected values for {list(mech.actuators)}")
    cached = sysm.key() + bytes([seed % 256]) in _CACHE
    gen = _monodromy(sysm, seed, capped)
    p1 = sysm.parameters(targets).astype(complex)
    P1 = np.concatenate([p1, sysm.identity_offsets()[0], np.zeros(sysm.nx)])
    X, _, done = _segment(sysm, gen.X, gen.P0, P1)
    Z = np.concatenate([X, np.broadcast_to(p1, (len(X), sysm.npar))], axis=1)
    Z = _refine(sysm, Z)
    res = sysm.residual(Z)
    sols: list[GeneralSolution] = []
    spurious = lost = 0
    kept = np.zeros((0, sysm.nx), complex)
    for n in range(len(Z)):
        z = Z[n]
        x = z[: sysm.nx]
        big = not np.all(np.isfinite(x)) or np.linalg.norm(x) > 1.0 / HOMOTOPY_INFINITY
        if not big and sysm.study >= 0:
            e = x[sysm.study : sysm.study + 4]
            big = abs(e @ e) / max(np.linalg.norm(x[sysm.study : sysm.study + 8]) ** 2, 1e-300) < HOMOTOPY_INFINITY
        if big or (not done[n] and np.linalg.norm(x) > MONODROMY_DIVERGED):
            sols.append(GeneralSolution("at_infinity", x, 0.0, 0.0, float(res[n])))
            continue
        if not res[n] < MONODROMY_RESIDUAL:
            if done[n]:
                spurious += 1
            else:
                lost += 1
            continue
        if len(kept) and np.min(np.linalg.norm(kept - x, axis=1) / (1 + np.linalg.norm(x))) < 1e-6:
            continue  # two paths to one (singular) end point
        kept = np.vstack([kept, x[None]])
        _, J = sysm.square(z[None])
        Jx = J[0, :, : sysm.nx]
        rows = Jx / np.maximum(np.linalg.norm(Jx, axis=1, keepdims=True), 1e-300)
        sv = np.linalg.svd(rows, compute_uv=False)
        rcond = float(sv[-1] / sv[0]) if sv[0] > 0 else 0.0
        y = x.copy()
        if sysm.study >= 0:
            s = slice(sysm.study, sysm.study + 8)
            k = int(np.argmax(np.abs(y[s])))
            y[s] = y[s] * (abs(y[s][k]) / y[s][k])
        imag = float(np.max(np.abs(y.imag)) / (1 + np.max(np.abs(y.real))))
        st = "singular" if rcond < HOMOTOPY_SINGULAR else "real" if imag < HOMOTOPY_REAL else "complex"
        q = D = None
        if st == "real":
            q, D = rebuild(sysm, y.real, targets)
        sols.append(GeneralSolution(st, y, rcond, imag, float(res[n]), q, D))
    n_sing = sum(s.status == "singular" for s in sols)
    how = (f"monodromy saturated after {gen.loops} loops ({MONODROMY_STALE_LOOPS} in a row without a new solution; "
           f"{len(gen.X)} solutions of a generic complex instance of the square system) then a parameter homotopy to "
           f"the requested actuator values; {spurious} end point(s) of the square system that do not satisfy the full "
           "closure discarded: not a proof (no trace test)")
    if not gen.saturated:
        why = (f"more than {MONODROMY_MAX_SOLUTIONS} solutions of the square system" if len(gen.X) > MONODROMY_MAX_SOLUTIONS
               else f"{MONODROMY_MAX_LOOPS} loops" if gen.loops >= MONODROMY_MAX_LOOPS
               else f"{MONODROMY_MAX_SECONDS:g} s")
        how = (f"monodromy NOT saturated: stopped at {why} ({len(gen.X)} solutions of the generic instance so far, "
               f"{gen.loops} loops); {spurious} spurious end point(s) discarded: not a proof, solutions may be missing")
    if n_sing:
        how += f"; {n_sing} singular end point(s) (a continuum or a multiple root), located to a few digits only"
    if lost:
        how += f"; {lost} path(s) stopped short of the request away from any solution (lost)"
    return GeneralResult(tuple(sols), gen.saturated, False, how, len(gen.X), spurious, gen.loops, gen.seconds,
                         time.perf_counter() - t0, cached)


def _refine(sysm: LoopSystem, Z, iters: int = 3):
    Z = Z.copy()
    nx = sysm.nx
    with np.errstate(all="ignore"):
        for _ in range(iters):
            F, J = sysm.square(Z)
            for n in range(len(Z)):
                if not (np.all(np.isfinite(F[n])) and np.all(np.isfinite(J[n]))):
                    continue
                try:
                    dx = np.linalg.solve(J[n, :, :nx], F[n])
                except np.linalg.LinAlgError:
                    continue
                if np.all(np.isfinite(dx)):
                    Z[n, :nx] -= dx
    return Z


def rebuild(sysm: LoopSystem, x: np.ndarray, targets: dict[int, float]) -> tuple[np.ndarray, np.ndarray]:
    """Joint variables ``q`` (every freedom) and platform displacement ``D`` (model units) of a
    real solution ``x``; the S joints' rotation vectors are those that close their limbs (a rod
    takes the smallest rotation at its first S joint)."""
    mech, L = sysm.mech, sysm.L
    refs = mech.freedom_refs
    p = sysm.parameters(targets)
    z = np.concatenate([x, p])[None].astype(complex)
    q = np.zeros(len(refs))
    for i, v in sysm.var_of.items():
        if v[0] == "A":
            q[i] = targets[i]
        elif v[0] == "R":
            q[i] = np.arctan2(x[v[2]], x[v[1]])
        elif v[0] == "P":
            q[i] = x[v[1]] * L
    Dn, _, E, _ = sysm._platform(z)
    D = (Dn[0] / E[0]).real
    D[3] = [0, 0, 0, 1]
    if sysm.study >= 0:
        R, pp = study_to_pose(x[sysm.study : sysm.study + 8], 1.0)
        D[:3, :3], D[:3, 3] = R, pp
    slices = limb_slices(mech)
    chains = {}
    from .closure import limb_chains

    for ch, sl in zip(limb_chains(mech), slices, strict=True):
        for first, _, axes in ch.balls:
            chains[sl.start + first] = axes
    for le in sysm.limbs:
        if le.kind == "full":
            continue
        Tb = sysm._chain(le.before, z)[0][0].real
        Ta = sysm._chain(le.after_inv, z)[0][0].real
        start = slices[le.limb].start + le.s_first
        if le.kind == "point":
            Rs = Tb[:3, :3].T @ D[:3, :3] @ Ta[:3, :3]
            q[start : start + 3] = np.linalg.solve(chains[start], matrix_rotvec(Rs))
            continue
        a = le.c2[:3] - le.c1[:3]
        bvec = Tb[:3, :3].T @ ((D @ Ta @ le.c2)[:3] - (Tb @ le.c1)[:3])
        R1 = _min_rotation(a, bvec)
        q[start : start + 3] = np.linalg.solve(chains[start], matrix_rotvec(R1))
        Rs2 = R1.T @ Tb[:3, :3].T @ D[:3, :3] @ Ta[:3, :3]
        q[start + 3 : start + 6] = np.linalg.solve(chains[start + 3], matrix_rotvec(Rs2))
    D = D.copy()
    D[:3, 3] *= L
    return q, D


def _min_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the direction of ``a`` to that of ``b``."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v = np.cross(a, b)
    c = float(a @ b)
    if c < -1 + 1e-12:
        w = np.cross(a, [1.0, 0, 0]) if abs(a[0]) < 0.9 else np.cross(a, [0, 1.0, 0])
        w /= np.linalg.norm(w)
        return 2 * np.outer(w, w) - np.eye(3)
    K = skew(v)
    return np.eye(3) + K + K @ K / (1 + c)


def configuration(sol: GeneralSolution) -> Configuration:
    """The :class:`Configuration` of a real solution (a mechanism without internal bodies)."""
    assert sol.q is not None and sol.D is not None
    return Configuration(sol.q, sol.D)
