"""The loop formulation of the forward position (:mod:`.general`): the closure of a
model whose limbs do not reduce to quadrics in the Study parameters, as a square polynomial
system in the joint variables, generated from the model.

Formulation (joints R, P, C, U, S, Sm).  Every passive,
unlocked revolute freedom is a pair ``(c, s)`` with ``c^2 + s^2 = 1`` and its displacement
``exp(theta A) = I + s A + (1 - c) A^2`` (``A`` the 4x4 matrix of its unit twist, pitch 0:
``A^3 = -A``), every passive slide a linear variable ``d`` (over the characteristic length
``L``) with ``exp(d A) = I + d A``; an actuated freedom is the same with its ``(c, s)`` or ``d``
as a *parameter*.  The product of a limb's displacements is then polynomial.

Hubs (the ground, the platform or output link, the internal bodies of a link-and-joint graph):
a limb runs from hub ``a`` to hub ``b`` and closes as ``H_a FK = H_b``.  Each moving hub's
displacement is, in turn, the product of a limb without S joint (the one with the fewest
unknowns) from a hub placed before it (a *reference limb*; its factors inverted in reverse order
when the limb runs towards the placed hub), or, where no such limb reaches it, its own Study
parameters ``x = (e ; g)`` of :mod:`.study` (``(e.e) H`` polynomial, with ``e.g = 0`` and a
random complex patch).  Without bodies this is the platform's reference limb, or the platform in
Study parameters when every limb has an S joint.  Each other limb gives (``H_a`` multiplying
the side before its S joints, ``H_b`` the side after, each side times the other's scale):

* no S joint: ``H_a FK = H_b``: the three off-diagonal entries of ``(R_a R_FK)^T R_b`` and the
  translation difference (6 equations; they also vanish where ``(R_a R_FK)^T R_b`` is a half
  turn about a coordinate axis: spurious points that the full closure, all 12 entries, rejects);
* one S joint at centre ``c``: ``H_a before(c) = H_b after^-1(c)`` (3 entries): the S joint's
  rotation is then whatever closes the limb, so it is not a variable;
* two consecutive S joints (a rod, centres ``c1``, ``c2``): ``|H_a before(c1) - H_b
  after^-1(c2)|^2 = |c1 - c2|^2`` (1 entry): the rod's idle spin is not a variable either.

The equations can outnumber the conditions they impose (a spherical or planar limb has 3, an
overconstrained linkage such as the Bennett fewer than its equations): the number of
independent conditions of each limb is the rank of its equations at a generic configuration
(a random walk from the reference along the closure, actuators held), and the system is made
square by random complex combinations (each limb's equations to its rank when the ranks add
up to the number of unknowns, else all equations to that number), and every end point is
checked against the full closure: points of the square system that do not close are
*spurious* and discarded (their number is reported).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, replace

import numpy as np

from ...errors import InputError
from ...geometry.rotations import skew
from ...model.mechanism import Mechanism
from .. import backend
from ..closure import Configuration, limb_slices

__all__ = [
    "LoopSystem",
    "general_reason",
    "loop_system",
    "rotation_forms",
    "twist_matrix",
    "variables",
]

_I4 = np.eye(4)


def _dt(Z: np.ndarray) -> type:
    """The dtype of the evaluation at ``Z``: complex, or ``object`` for ball arithmetic (python-flint
    ``acb`` entries: the certificates of :mod:`.certify_loops` evaluate the same formulas)."""
    return object if Z.dtype == object else complex


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
    a: int | None = None  # the hub at the limb's base (None: the ground; 0: the platform; k: body k - 1)
    b: int | None = 0  # the hub at its tip


@dataclass(frozen=True, eq=False)
class _Hub:
    """How a moving hub's displacement is made: by a limb without S joint from a hub defined
    before it (``chain``: the limb's factors, inverted and reversed when it runs the other way),
    or by its own Study parameters (``study``: the index of ``e0`` in ``x``, with a patch)."""

    hub: int  # 0: the platform (output link); k: body k - 1
    frm: int | None  # the hub the chain starts from (None: the ground); unused for Study parameters
    chain: tuple[_Factor, ...]
    limb: int  # the limb of the chain (-1: Study parameters)
    study: int = -1
    patch: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class LoopSystem:
    """The polynomial closure of a model (module docstring): unknowns ``x`` (``nx``),
    parameters ``p`` (the actuators, ``npar``), the square system ``G`` and the full closure."""

    mech: Mechanism
    L: float
    nx: int
    npar: int
    circles: tuple[tuple[int, int], ...]  # (c, s) index pairs of the unknown revolutes
    hubs: tuple[_Hub, ...]  # the moving hubs (platform, bodies), in the order they are defined
    limbs: tuple[_LimbEq, ...]
    compress: np.ndarray  # (m, r) complex: closure entries -> square rows
    var_of: dict  # freedom index -> ("R", ic, is) / ("P", id) / ("A", ...) parameter / ("L",) locked / ("S",)
    params: tuple[tuple[int, str, tuple[int, ...]], ...]  # (freedom index, kind, z indices)
    n_conditions: int
    rigid_family: bool = False  # every limb's equations independent: monodromy over the limbs' offsets

    @property
    def n_rows(self) -> int:
        return self.compress.shape[0]

    @property
    def studies(self) -> tuple[_Hub, ...]:
        """The hubs in Study parameters (none when every hub is the product of a limb)."""
        return tuple(h for h in self.hubs if h.study >= 0)

    @property
    def study(self) -> int:
        """Index of ``e0`` in ``x`` of the first hub in Study parameters (-1: none)."""
        st = self.studies
        return st[0].study if st else -1

    @property
    def patch(self) -> np.ndarray | None:
        st = self.studies
        return st[0].patch if st else None

    @property
    def ref(self) -> tuple[_Factor, ...] | None:
        """The platform's reference limb's factors (None: the platform in Study parameters)."""
        h = self.hub_def(0)
        return h.chain if h.study < 0 and h.frm is None else None

    @property
    def ref_limb(self) -> int:
        return self.hub_def(0).limb

    def hub_def(self, hub: int) -> _Hub:
        return next(h for h in self.hubs if h.hub == hub)

    @property
    def n_bodies(self) -> int:
        return len(self.hubs) - 1

    def key(self) -> bytes:
        """The geometry and structure of the system (which variable or parameter drives each
        factor, the limbs' equation kinds): the cache key of its generic solve."""
        parts = [np.array([self.nx, self.npar, self.ref_limb, self.study, float(self.rigid_family)], float)]

        def factor(f):
            return np.concatenate([f.A.ravel(), [float(f.kind == "R"), float(f.inverse)], np.asarray(f.idx, float)])

        def hub(h):
            return -1.0 if h is None else float(h)

        for h in self.hubs:
            parts.append(np.array([-3.0, h.hub, hub(h.frm), h.limb, h.study]))
            parts += [factor(f) for f in h.chain]
        for le in self.limbs:
            parts += [np.array([{"full": 0.0, "point": 1.0, "rod": 2.0}[le.kind], -1.0, hub(le.a), hub(le.b)])]
            parts += [factor(f) for f in le.before] + [np.array([-2.0])] + [factor(f) for f in le.after_inv]
            parts += [le.c1, le.c2, np.array([le.length2])]
        parts.append(self.compress.real.ravel())
        parts.append(self.compress.imag.ravel())
        return np.round(np.concatenate(parts), 12).tobytes()

    # -------------------------------------------------------------------------- evaluation
    def _chain(self, factors, Z):
        n, nz = Z.shape
        T: np.ndarray = np.broadcast_to(_I4, (n, 4, 4)).astype(_dt(Z))
        dT = np.zeros((n, nz, 4, 4), _dt(Z))
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

    def _study_hub(self, Z, k):
        """``(e.e) H`` of a hub in Study parameters (``e0`` at ``k``), its derivative, ``e.e`` and its derivative."""
        n, nz = Z.shape
        X = Z[:, k : k + 8]
        Dn = np.einsum("ni,abij,nj->nab", X, _STUDY_Q, X)
        dDn = np.zeros((n, nz, 4, 4), _dt(Z))
        dDn[:, k : k + 8] = np.einsum("abij,nj->niab", _STUDY_Q + _STUDY_Q.transpose(0, 1, 3, 2), X)
        E = np.einsum("ni,ni->n", X[:, :4], X[:, :4])
        dE = np.zeros((n, nz), _dt(Z))
        dE[:, k : k + 4] = 2 * X[:, :4]
        return Dn, dDn, E, dE

    def hub_values(self, Z) -> dict:
        """Every hub's displacement times its scale, its derivative, the scale (1, or the product
        of the ``e.e`` of the Study hubs it hangs from) and its derivative: ``{hub: (Hn, dHn, E,
        dE)}``, the ground (``None``) included."""
        n, nz = Z.shape
        out: dict = {None: (np.broadcast_to(_I4, (n, 4, 4)).astype(_dt(Z)), np.zeros((n, nz, 4, 4), _dt(Z)),
                            np.ones(n, _dt(Z)), np.zeros((n, nz), _dt(Z)))}
        for h in self.hubs:
            if h.study >= 0:
                out[h.hub] = self._study_hub(Z, h.study)
                continue
            T, dT = self._chain(h.chain, Z)
            if h.frm is None:
                out[h.hub] = (T, dT, out[None][2], out[None][3])
                continue
            Hf, dHf, Ef, dEf = out[h.frm]
            out[h.hub] = (Hf @ T, dHf @ T[:, None] + Hf[:, None] @ dT, Ef, dEf)
        return out

    def _platform(self, Z):
        """``D`` (or ``(e.e) D``), its derivative, and the scale ``n`` (1, or ``e.e``) with its derivative."""
        return self.hub_values(Z)[0]

    def limb_sides(self, le: _LimbEq, H: dict, Z):
        """A limb's two sides: ``H_a before`` (scaled by ``E_a``) with its derivative, and ``H_b``
        (scaled by ``E_b``) with its derivative, and the two scales with theirs."""
        Ha, dHa, Ea, dEa = H[le.a]
        Tb, dTb = self._chain(le.before, Z)
        if le.a is not None:
            Tb, dTb = Ha @ Tb, dHa @ Tb[:, None] + Ha[:, None] @ dTb
        Hb, dHb, Eb, dEb = H[le.b]
        return Tb, dTb, Hb, dHb, Ea, dEa, Eb, dEb

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
        a limb from hub ``a`` to hub ``b`` without S joint gives the off-diagonal entries of
        ``(R_a R_limb)^T R_b`` and the translation difference (6; zero also at the three
        half-turns about the axes, spurious points the full closure rejects), or with ``full``
        every entry of ``H_a T_limb - H_b`` (12), each side times the other's scale."""
        H = self.hub_values(Z)
        rows, jac = [], []
        n = len(Z)
        off = self.w_offsets
        if W is None:
            W = self.identity_offsets(n)
        for k, le in enumerate(self.limbs):
            w_k = W[:, off[k] : off[k + 1]]
            Tb, dTb, D, dD, Ea, dEa, E, dE = self.limb_sides(le, H, Z)
            if le.kind == "full" and full:
                r = E[:, None, None] * Tb - Ea[:, None, None] * D
                dr = (E[:, None, None, None] * dTb + dE[:, :, None, None] * Tb[:, None]
                      - Ea[:, None, None, None] * dD - dEa[:, :, None, None] * D[:, None])
                rows.append(r[:, :3].reshape(n, 12))
                jac.append(dr[:, :, :3].reshape(n, -1, 12).transpose(0, 2, 1))
                continue
            if le.kind == "full":  # with the offset (q, t): R_b -> R_b E(q), p_b -> p_b + R_b t
                Eq = rotation_forms(w_k[:, :4])
                A, dA = Tb[:, :3, :3], dTb[:, :, :3, :3]
                B, dB = D[:, :3, :3] @ Eq, dD[:, :, :3, :3] @ Eq[:, None]
                P = np.einsum("nai,naj->nij", A, B)
                dP = np.einsum("nzai,naj->nzij", dA, B) + np.einsum("nai,nzaj->nzij", A, dB)
                ii, jj = (0, 0, 1), (1, 2, 2)
                tk = w_k[:, 4:7]
                s, Rt = D[:, :3, 3], np.einsum("nab,nb->na", D[:, :3, :3], tk)
                ds, dRt = dD[:, :, :3, 3], np.einsum("nzab,nb->nza", dD[:, :, :3, :3], tk)
                t = E[:, None] * Tb[:, :3, 3] - Ea[:, None] * s - Ea[:, None] * Rt
                dt = (E[:, None, None] * dTb[:, :, :3, 3] + dE[:, :, None] * Tb[:, None, :3, 3]
                      - Ea[:, None, None] * ds - Ea[:, None, None] * dRt - dEa[:, :, None] * (s + Rt)[:, None])
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
            w = E[:, None] * u1 - Ea[:, None] * u2
            dw = E[:, None, None] * du1 + dE[:, :, None] * u1[:, None] - Ea[:, None, None] * du2 - dEa[:, :, None] * u2[:, None]
            w, dw = w[:, :3], dw[:, :, :3]
            EE, dEE = Ea * E, dEa * E[:, None] + Ea[:, None] * dE
            if le.kind == "point":  # with the offset o: before(c) = H_b after^-1(c) + o
                rows.append(w - EE[:, None] * w_k)
                jac.append((dw - dEE[:, :, None] * w_k[:, None]).transpose(0, 2, 1))
            else:  # with the offset beta: length squared + beta
                l2 = le.length2 + w_k[:, 0]
                rows.append((np.einsum("na,na->n", w, w) - EE**2 * l2)[:, None])
                jac.append((2 * np.einsum("na,nza->nz", w, dw) - 2 * (EE * l2)[:, None] * dEE)[:, None])
        if not rows:
            return np.zeros((len(Z), 0), _dt(Z)), np.zeros((len(Z), 0, Z.shape[1]), _dt(Z))
        return np.concatenate(rows, axis=1), np.concatenate(jac, axis=1)

    def side(self, Z):
        """The circles, the Study quadrics and patches: entries (n, k) and derivative (n, k, nz)."""
        n, nz = Z.shape
        st = self.studies
        k = len(self.circles) + 2 * len(st)
        F = np.zeros((n, k), _dt(Z))
        J = np.zeros((n, k, nz), _dt(Z))
        for i, (a, b) in enumerate(self.circles):
            F[:, i] = Z[:, a] ** 2 + Z[:, b] ** 2 - 1
            J[:, i, a] = 2 * Z[:, a]
            J[:, i, b] = 2 * Z[:, b]
        i = len(self.circles)
        for h in st:
            s = h.study
            X = Z[:, s : s + 8]
            F[:, i] = np.einsum("ni,ni->n", X[:, :4], X[:, 4:])
            J[:, i, s : s + 4] = X[:, 4:]
            J[:, i, s + 4 : s + 8] = X[:, :4]
            assert h.patch is not None
            F[:, i + 1] = X @ h.patch - 1
            J[:, i + 1, s : s + 8] = h.patch
            i += 2
        return F, J

    def square(self, Z, W=None, *, reference: bool = False, want_J: bool = True):
        """The square system ``G`` (n, nx) and its derivative (n, nx, nz) in ``z = (x ; p)``,
        with the offset parameters ``W`` (n, nw; default none): compiled (``compiled/kernels_loops.py``)
        when the compiled core is in use and not ``reference``."""
        if W is None:
            W = self.identity_offsets(len(Z))
        if not reference and (fast := backend.engine()) is not None:
            packed = _PACKED.get(self)
            if packed is None:
                packed = _PACKED[self] = fast.pack_loop_system(self, _STUDY_Q)
            return fast.loop_square_batch(np.ascontiguousarray(Z, dtype=np.complex128),
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
        if len(self.studies) == 1:
            scale = np.maximum(scale, np.linalg.norm(Z[:, self.study : self.study + 8], axis=1) ** 4)
        elif self.studies:  # the equations' degree in the Study parameters: a product of their scales
            big = np.ones(len(Z))
            for h in self.studies:
                big = big * np.maximum(1.0, np.linalg.norm(Z[:, h.study : h.study + 8], axis=1) ** 2)
            scale = np.maximum(scale, big**2)
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


def rotation_forms(q: np.ndarray) -> np.ndarray:
    """``E(q) = (q.q) R(q)`` (n, 3, 3) of quaternions ``q`` (n, 4), complex allowed."""
    w, i, j, k = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    E = np.empty((q.shape[0], 3, 3), dtype=np.result_type(q.dtype, np.float64))  # filled, not stacked: called per point
    E[:, 0, 0], E[:, 0, 1], E[:, 0, 2] = w * w + i * i - j * j - k * k, 2 * (i * j - w * k), 2 * (i * k + w * j)
    E[:, 1, 0], E[:, 1, 1], E[:, 1, 2] = 2 * (i * j + w * k), w * w - i * i + j * j - k * k, 2 * (j * k - w * i)
    E[:, 2, 0], E[:, 2, 1], E[:, 2, 2] = 2 * (i * k - w * j), 2 * (j * k + w * i), w * w - i * i - j * j + k * k
    return E


def _study_forms() -> np.ndarray:
    """``(e.e) D`` of the Study parameters as quadratic forms: (4, 4, 8, 8) symmetric."""
    from .systems import qmul

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


def twist_matrix(S: np.ndarray, L: float, slide: bool) -> np.ndarray:
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
    L = mech.characteristic_length
    refs = mech.freedom_refs
    acts = set(mech.actuators)
    slices = limb_slices(mech)
    ends = mech.limb_ends
    # the S joints of each limb, and which limbs can define a hub
    s_of: list[list[tuple[int, np.ndarray]]] = []
    for limb in mech.limbs:
        k, ss, names = 0, [], []
        for j in limb.joints:
            if j.type == "S":
                if any(f.actuated for f in j.freedoms):
                    raise InputError(f"limb {limb.name}: S joint {j.name} is actuated")
                ss.append((k, np.asarray(j.point, float)))
                names.append(j.name)
            for f in j.freedoms:
                if f.kind == "H" and f.pitch != 0:
                    raise InputError(f"limb {limb.name}: helical joint {j.name} (its rotation angle enters both "
                                     "as an angle and through its sine and cosine: not polynomial)")
            k += len(j.freedoms)
        if len(ss) > 2 or (len(ss) == 2 and ss[1][0] != ss[0][0] + 3):
            raise InputError(f"limb {limb.name}: S joints {', '.join(names)} (the loop formulation covers one S joint "
                             "per limb, or two adjacent ones: a rod)")
        s_of.append(ss)
    no_s = [li for li in range(len(mech.limbs)) if not s_of[li]]
    n_unknown = [sum(1 for i in range(sl.start, sl.stop) if not refs[i].freedom.locked and refs[i].id not in acts)
                 for sl in slices]
    # a spanning forest of reference limbs: every moving hub is the product of a limb without S
    # joint from a hub defined before it (the fewest unknowns first), else in Study parameters
    plan: list[tuple[int, int | None, int]] = []  # (hub, from hub, limb; -1: Study parameters)
    defined: set[int | None] = {None}
    while len(defined) < len(mech.bodies) + 2:
        cands = [li for li in no_s if (ends[li][0] in defined) != (ends[li][1] in defined)]
        if cands:
            li = min(cands, key=lambda li: n_unknown[li])
            a, b = ends[li]
            hub, frm = (b, a) if a in defined else (a, b)
        else:
            hub, frm, li = next(h for h in range(len(mech.bodies) + 1) if h not in defined), None, -1
        assert hub is not None
        plan.append((hub, frm, li))
        defined.add(hub)
    ref_limbs = {li for _, _, li in plan if li >= 0}

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
    study_at = {}
    for hub, _, li in plan:
        if li < 0:
            study_at[hub] = nx
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
            A = twist_matrix(refs[i].freedom.screw, L, kind == "P")
            out.append(_Factor(kind, A, A @ A, tuple(v[1:])))
        return out

    limbs: list[_LimbEq] = []
    cond = 0
    for li in range(len(mech.limbs)):
        if li in ref_limbs:
            continue
        a, b = ends[li]
        m = slices[li].stop - slices[li].start
        ss = s_of[li]
        z4 = np.zeros(4)
        if not ss:
            limbs.append(_LimbEq("full", tuple(factors(li, 0, m)), (), z4, z4, 0.0, li, -1, a, b))
            cond += 6
            continue
        k0 = ss[0][0]
        k1 = ss[-1][0] + 3
        c1 = np.append(ss[0][1] / L, 1.0)
        c2 = np.append(ss[-1][1] / L, 1.0)
        after = [f.inverted() for f in reversed(factors(li, k1, m))]
        if len(ss) == 1:
            limbs.append(_LimbEq("point", tuple(factors(li, 0, k0)), tuple(after), c1, c1, 0.0, li, k0, a, b))
            cond += 3
        else:
            limbs.append(_LimbEq("rod", tuple(factors(li, 0, k0)), tuple(after), c1, c2,
                                 float(np.sum((c1 - c2) ** 2)), li, k0, a, b))
            cond += 1
    m_needed = nx - len(circles) - 2 * len(study_at)
    sizes = [6 if le.kind == "full" else 3 if le.kind == "point" else 1 for le in limbs]
    rng = np.random.default_rng(seed + 7919)
    hubs = []
    for hub, frm, li in plan:
        if li < 0:
            hubs.append(_Hub(hub, None, (), -1, study_at[hub], rng.normal(size=8) + 1j * rng.normal(size=8)))
            continue
        ch = factors(li, 0, slices[li].stop - slices[li].start)
        if ends[li][1] != hub:  # the limb runs from the hub to the one it hangs from: inverted
            ch = [f.inverted() for f in reversed(ch)]
        hubs.append(_Hub(hub, frm, tuple(ch), li))
    sysm = LoopSystem(mech, L, nx, npar, tuple(circles), tuple(hubs), tuple(limbs),
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
    """The variables ``z = (x ; p)`` of a real configuration (joint variables ``q``, the
    platform ``D`` and bodies ``B`` where they are in Study parameters)."""
    z = np.zeros(sysm.nx + sysm.npar)
    for i, v in sysm.var_of.items():
        qi = config.q[i]
        if v[0] in ("R", "A") and len(v) == 3:
            z[v[1]], z[v[2]] = np.cos(qi), np.sin(qi)
        elif v[0] in ("P", "A"):
            z[v[1]] = qi / sysm.L
    z = z.astype(complex)
    for h in sysm.studies:
        from scipy.spatial.transform import Rotation

        from .systems import qmul

        H = config.hub(h.hub)
        x, y, zz, w = Rotation.from_matrix(H[:3, :3]).as_quat()
        e = np.array([w, x, y, zz])
        g = 0.5 * qmul(np.concatenate([[0.0], H[:3, 3] / sysm.L]), e)
        xs = np.concatenate([e, g]).astype(complex)
        assert h.patch is not None
        z[h.study : h.study + 8] = xs / (xs @ h.patch)
    return z


def _limb_ranks(sysm: LoopSystem, sizes: list[int], rng: np.random.Generator) -> list[int]:
    """The number of independent conditions of each limb's closure entries on the unknowns: the
    rank of their derivative along the side equations' solution set (circles, Study quadric),
    the actuators held, at a generic
    configuration of the mechanism (a random walk from the reference along its closure)."""
    from ..motion import generic_configuration

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
