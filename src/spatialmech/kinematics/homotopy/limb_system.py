"""Every solution of the inverse position of one limb (a serial chain of R, P, C, U, S joints
from the ground to the output link, the output link's pose given) by a parameter homotopy, with
a completeness statement: the limb's polynomial system (this module; the solver is
:mod:`.inverse`).

Formulation (the loop formulation of :mod:`.loop_system`, cut down to one limb whose far end
is held): every revolute freedom is a pair ``(c, s)`` on its circle ``c^2 + s^2 = 1``, its
displacement ``I + s A + (1 - c) A^2``; a slide is ``d`` (over the characteristic length ``L``),
``I + d A``.  The chain is cut in two (Lee and Liang's halving: each equation is then linear in
every pair, and of degree about half the number of joints on either side), so the closure
``T_1 ... T_m = D`` reads ``left(x) = D right(x)`` with ``right`` the inverted factors after
the cut, in reverse order.  The requested displacement ``D`` enters through parameters: a
quaternion ``q`` (``E(q) = (q.q) R(q)``, polynomial) and a translation ``t``:

* a limb without S joint: the three off-diagonal entries above the diagonal of
  ``R_left^T E(q) R_right`` (zero also at the half turns about the axes: points that the full
  closure rejects) and ``(q.q) (p_left - t) - E(q) p_right`` (3 + 3 equations);
* a limb with one S joint at centre ``c``: the centre seen from both sides,
  ``(q.q) (left(c) - t) - E(q) right(c)`` (3 equations; the S joint's rotation is then whatever
  closes the limb, :func:`_ball_rotation`).

Families.  When the equations are as many as the unknowns (a 6-freedom limb without S joint, or
3 freedoms besides one S joint) and independent, the family is the requested pose itself (the
*rigid* family): a random complex joint point ``x0`` is a solution for the pose it gives, the
genuine solutions form the graph of the forward kinematics (irreducible), so loops in the pose
(``q, t``) act transitively on them and never leave them.  A limb with fewer freedoms than
equations (a planar or spherical leg, an R-P-S leg) has its equations combined at random into as
many rows as unknowns, offset by ``b`` (the graph family ``G(x; q, t) = b``, as
:mod:`.general`): its generic solutions may include points that do not close, which are tracked
along and discarded at the end.  A limb whose equations have a smaller rank than its unknowns has
a positive-dimensional solution set (a passive freedom: an S-S rod's spin, a redundant chain):
not covered (:func:`ik_reason`).
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...model.mechanism import Mechanism
from ..closure import limb_slices
from .loop_system import rotation_forms, twist_matrix

__all__ = [
    "BOUND_3R_POINT",
    "BOUND_6R",
    "BOUND_6R_WRIST",
    "LimbIK",
    "clear_systems",
    "crand",
    "ik_reason",
    "limb_ik_system",
    "quaternion_of",
    "random_point",
    "start_pair",
]

_I4 = np.eye(4)
#: The number of inverse solutions of a general 6R (Primrose 1986: at most 16; Lee and Liang
#: 1988, Raghavan and Roth 1993: 16), a bound for every 6R geometry (the number of isolated
#: solutions never exceeds the generic one of a family).
BOUND_6R = 16
#: A 6R whose first or last three axes meet at one point (a spherical shoulder or wrist, the
#: PUMA's): that point's position is a 3R positioning problem, at most 4 solutions (Pieper 1968:
#: a quartic), and the wrist's orientation at most 2 for each.
BOUND_6R_WRIST = 8
#: A 3R placing a point (the centre of an S joint after three revolutes): Pieper's quartic.
BOUND_3R_POINT = 4


def _concurrent(screws: np.ndarray, tol: float = 1e-9) -> bool:
    """Whether the axes of the rotation screws (k, 6) meet at one point and are not all parallel."""
    w, m = screws[:, :3], screws[:, 3:]
    A = np.concatenate([-np.array([[[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]]]) for a in w]).reshape(-1, 3)
    x, *_ = np.linalg.lstsq(A, m.ravel(), rcond=None)
    scale = 1.0 + float(np.linalg.norm(m)) + float(np.linalg.norm(x))
    return bool(np.linalg.norm(A @ x - m.ravel()) < tol * scale and np.linalg.matrix_rank(w, tol=1e-9) > 1)


def _bound(kinds: list[str], screws: np.ndarray, kind: str) -> tuple[int, str]:
    """A known bound on the number of generic solutions, and its source (``0, ""``: none)."""
    if kind == "full" and kinds == ["R"] * 6:
        if _concurrent(screws[:3]) or _concurrent(screws[3:]):
            return BOUND_6R_WRIST, ("the bound for a 6R with three concurrent axes at one end (Pieper 1968: 4 positions "
                                    "of their common point times 2 orientations)")
        return BOUND_6R, "the bound for any 6R (Primrose 1986; Lee and Liang 1988; Raghavan and Roth 1993)"
    if kind == "point" and kinds == ["R"] * 3:
        return BOUND_3R_POINT, "the bound for a 3R placing a point (Pieper 1968: a quartic)"
    return 0, ""


def _T(A: np.ndarray) -> np.ndarray:
    """The last two axes of ``A`` swapped (a stack of transposes, no conjugation)."""
    return np.swapaxes(A, -1, -2)


def _apply(M: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``M[n] @ v[n]`` for stacks ``M`` (n, a, b) and ``v`` (n, b): matmul, not einsum (called on
    one point at a time by the trackers, where einsum's parsing costs ~50 us a call)."""
    return (M @ v[..., None])[..., 0]


@dataclass(frozen=True, eq=False)
class _Factor:
    kind: str  # "R" or "P"
    A: np.ndarray  # 4x4 twist matrix (moments over L)
    A2: np.ndarray
    idx: tuple[int, ...]  # (c, s) or (d,) in x
    sign: float = 1.0  # -1: the inverse displacement
    theta: int = 0  # its angle's (or slide's) index in the compiled formulation


@dataclass(frozen=True, eq=False)
class LimbIK:
    """The polynomial inverse position of one limb (module docstring): unknowns ``x`` (``nx``:
    a ``(c, s)`` pair per revolute, ``d / L`` per slide), parameters ``P = (q (4), t (3), b)``."""

    kind: str  # "full" (no S joint) or "point" (one S joint)
    left: tuple[_Factor, ...]
    right: tuple[_Factor, ...]  # the factors after the cut (or the S joint), inverted, in reverse order
    centre: np.ndarray  # (4,) the S joint's centre over L, homogeneous (point kind)
    nx: int
    circles: tuple[tuple[int, int], ...]
    slots: tuple[tuple, ...]  # per freedom of the limb: ("R", ic, is), ("P", i) or ("S", first)
    C: np.ndarray  # (rows, equations) complex: the equations -> the square rows
    rigid: bool  # the pose alone is the family (no offset b)
    bound: int  # a known bound on the generic count (0: none)
    L: float
    key: bytes = field(repr=False, default=b"")
    bound_source: str = ""

    @property
    def n_rows(self) -> int:
        return self.nx - len(self.circles)

    @property
    def n_params(self) -> int:
        return 7 + self.n_rows

    # ---------------------------------------------------------------------- evaluation
    def _chain(self, factors, X):
        n, nz = X.shape
        T = np.empty((n, 4, 4), complex)
        T[:] = _I4
        dT = np.zeros((n, nz, 4, 4), complex)
        for f in factors:
            if f.kind == "R":
                c, s = X[:, f.idx[0]], X[:, f.idx[1]]
                M = _I4 + f.sign * s[:, None, None] * f.A + (1 - c)[:, None, None] * f.A2
                dT = dT @ M[:, None]
                dT[:, f.idx[0]] -= T @ f.A2
                dT[:, f.idx[1]] += T @ (f.sign * f.A)
            else:
                d = X[:, f.idx[0]]
                M = _I4 + f.sign * d[:, None, None] * f.A
                dT = dT @ M[:, None]
                dT[:, f.idx[0]] += T @ (f.sign * f.A)
            T = T @ M
        return T, dT

    def equations(self, X, P, dP=None, full: bool = False):
        """The limb's equations (n, k) at points ``X`` with parameters ``P`` (n, n_params), their
        derivative in ``x`` (n, k, nx) and along ``dP`` (n, k; ``None`` without ``dP``);
        ``full``: every entry of the rotation (9) instead of the three above the diagonal."""
        q, t = P[:, :4], P[:, 4:7]
        E = rotation_forms(q)
        s = (q * q).sum(axis=1)
        TL, dTL = self._chain(self.left, X)
        TR, dTR = self._chain(self.right, X)
        if dP is not None:
            dq, dt = dP[:, :4], dP[:, 4:7]
            dE = 0.5 * (rotation_forms(q + dq) - rotation_forms(q - dq))  # exact: E is quadratic
            ds = 2 * (q * dq).sum(axis=1)
        if self.kind == "point":
            u, du = TL @ self.centre, dTL @ self.centre
            v, dv = TR @ self.centre, dTR @ self.centre
            r = s[:, None] * (u[:, :3] - t) - _apply(E, v[:, :3])
            dr = s[:, None, None] * du[:, :, :3] - dv[:, :, :3] @ _T(E)
            rt = None
            if dP is not None:
                rt = ds[:, None] * (u[:, :3] - t) - s[:, None] * dt - _apply(dE, v[:, :3])
            return r, dr.transpose(0, 2, 1), rt
        RL, RR = TL[:, :3, :3], TR[:, :3, :3]
        ERR = E @ RR
        RLt = _T(RL)
        Pm = RLt @ ERR
        dPm = _T(dTL[:, :, :3, :3]) @ ERR[:, None] + (RLt @ E)[:, None] @ dTR[:, :, :3, :3]
        pl, pr = TL[:, :3, 3], TR[:, :3, 3]
        tr = s[:, None] * (pl - t) - _apply(E, pr)
        dtr = s[:, None, None] * dTL[:, :, :3, 3] - dTR[:, :, :3, 3] @ _T(E)
        n = len(X)
        if full:
            rot = Pm.reshape(n, 9) - s[:, None] * np.eye(3).ravel()
            return np.concatenate([rot, tr], axis=1), None, None
        ii, jj = (0, 0, 1), (1, 2, 2)
        r = np.concatenate([Pm[:, ii, jj], tr], axis=1)
        dr = np.concatenate([dPm[:, :, ii, jj], dtr], axis=2)
        rt = None
        if dP is not None:
            dPt = RLt @ dE @ RR
            trt = ds[:, None] * (pl - t) - s[:, None] * dt - _apply(dE, pr)
            rt = np.concatenate([dPt[:, ii, jj], trt], axis=1)
        return r, dr.transpose(0, 2, 1), rt

    def square(self, X, P, dP=None):
        """The square system ``G`` (n, nx): the circles, then ``C r - b``; its Jacobian in ``x``
        and its derivative along ``dP`` (zeros without ``dP``)."""
        n = len(X)
        r, dr, rt = self.equations(X, P, dP)
        F = np.zeros((n, self.nx), complex)
        J = np.zeros((n, self.nx, self.nx), complex)
        Ft = np.zeros((n, self.nx), complex)
        for i, (a, b) in enumerate(self.circles):
            F[:, i] = X[:, a] ** 2 + X[:, b] ** 2 - 1
            J[:, i, a], J[:, i, b] = 2 * X[:, a], 2 * X[:, b]
        k = len(self.circles)
        F[:, k:] = r @ self.C.T - P[:, 7:]
        J[:, k:] = self.C @ dr
        if dP is not None and rt is not None:
            Ft[:, k:] = rt @ self.C.T - dP[:, 7:]
        return F, J, Ft

    def angles(self, X: np.ndarray) -> np.ndarray:
        """The angles (complex; ``c + i s = exp(i theta)``) and slides of the points ``X`` (n, nx).
        Of ``c + i s`` and ``c - i s = exp(-i theta)`` (their product is 1) the larger is taken: the
        smaller is a difference of nearly equal large numbers when ``theta`` is far from real."""
        facts = sorted(self.left + self.right, key=lambda f: f.theta)
        cols = []
        with np.errstate(all="ignore"):
            for f in facts:
                up, down = X[:, f.idx[0]] + 1j * X[:, f.idx[-1]], X[:, f.idx[0]] - 1j * X[:, f.idx[-1]]
                cols.append(np.where(np.abs(up) >= np.abs(down), -1j * np.log(up), 1j * np.log(down))
                            if f.kind == "R" else X[:, f.idx[0]])
        return np.array(cols, dtype=complex).T.reshape(len(X), len(facts))

    def from_angles(self, TH: np.ndarray) -> np.ndarray:
        """The points ``x`` of angles and slides ``TH`` (:meth:`angles`)."""
        X = np.zeros((len(TH), self.nx), complex)
        with np.errstate(all="ignore"):
            for f in self.left + self.right:
                if f.kind == "R":
                    X[:, f.idx[0]], X[:, f.idx[1]] = np.cos(TH[:, f.theta]), np.sin(TH[:, f.theta])
                else:
                    X[:, f.idx[0]] = TH[:, f.theta]
        return X

    def residual(self, X, P) -> np.ndarray:
        """Relative residual of the full closure (every entry) and the circles per point."""
        r, _, _ = self.equations(X, P, full=True)
        circ = np.array([X[:, a] ** 2 + X[:, b] ** 2 - 1 for a, b in self.circles]).T.reshape(len(X), -1)
        scale = (1 + np.linalg.norm(X, axis=1)) * (1 + np.linalg.norm(P[:, :7], axis=1)) ** 2
        return np.concatenate([np.abs(r), np.abs(circ)], axis=1).max(axis=1, initial=0.0) / scale

    # ---------------------------------------------------------------------- parameters
    def pose_parameters(self, D: np.ndarray) -> np.ndarray:
        """The parameters of a real displacement ``D`` (4x4, model units), no offset."""
        return np.concatenate([quaternion_of(D[:3, :3].astype(complex)), D[:3, 3] / self.L, np.zeros(self.n_rows)])

    def forward(self, x: np.ndarray) -> np.ndarray:
        """The displacement (4x4, translation over L, complex) of the limb's tip at ``x``
        (no S joint: the limb's own; one S joint: not determined, a ``ValueError``)."""
        TL = self._chain(self.left, x[None])[0][0]
        TR = self._chain(self.right, x[None])[0][0]
        return TL @ np.linalg.inv(TR)


def quaternion_of(R: np.ndarray) -> np.ndarray:
    """A quaternion ``q`` (complex allowed, unnormalised) with ``E(q) / (q.q) = R``, from the
    largest of the four candidate rows (Shepperd)."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    cands = np.array([
        [1 + tr, R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]],
        [R[2, 1] - R[1, 2], 1 + R[0, 0] - R[1, 1] - R[2, 2], R[0, 1] + R[1, 0], R[0, 2] + R[2, 0]],
        [R[0, 2] - R[2, 0], R[0, 1] + R[1, 0], 1 - R[0, 0] + R[1, 1] - R[2, 2], R[1, 2] + R[2, 1]],
        [R[1, 0] - R[0, 1], R[0, 2] + R[2, 0], R[1, 2] + R[2, 1], 1 - R[0, 0] - R[1, 1] + R[2, 2]],
    ])
    q = cands[int(np.argmax(np.linalg.norm(cands, axis=1)))]
    return q / np.sqrt(np.sum(np.abs(q) ** 2))


# ------------------------------------------------------------------------------ building
def _ball_joints(mech: Mechanism, li: int) -> list[tuple[int, np.ndarray, str]]:
    """(first index in the limb, centre, name) of every S joint of limb ``li``, or an
    ``InputError`` for what the formulation does not cover."""
    limb = mech.limbs[li]
    out = []
    k = 0
    for j in limb.joints:
        for f in j.freedoms:
            if f.kind == "H" and f.pitch != 0:
                raise InputError(f"limb {limb.name}: helical joint {j.name} of pitch {f.pitch:g} (its angle enters both "
                                 "as an angle and through its sine and cosine: transcendental, not polynomial)")
            if f.locked:
                raise InputError(f"limb {limb.name}: freedom {j.name}.{f.name} is locked (the homotopy solves every freedom)")
        if j.type == "S":
            out.append((k, np.asarray(j.point, float), j.name))
        k += len(j.freedoms)
    if len(out) == 2 and out[1][0] == out[0][0] + 3:
        raise InputError(f"limb {limb.name}: S joints {out[0][2]}, {out[1][2]} make a rod whose spin about its axis is "
                         "free (a passive freedom: a one-dimensional solution set)")
    if len(out) > 1:
        raise InputError(f"limb {limb.name}: {len(out)} S joints (the homotopy covers at most one)")
    return out


def _generic_rank(sysm: LimbIK, rng: np.random.Generator) -> int:
    """The number of independent conditions the limb's equations put on its unknowns: the rank of
    their derivative along the circles at a random complex point with the pose it reaches."""
    x0, P0 = start_pair(sysm, rng, genuine=True)
    _, dr, _ = sysm.equations(x0[None], P0[None])
    Js = np.zeros((len(sysm.circles), sysm.nx), complex)
    for i, (a, b) in enumerate(sysm.circles):
        Js[i, a], Js[i, b] = 2 * x0[a], 2 * x0[b]
    _, sv, vt = np.linalg.svd(Js)
    N = vt[int(np.sum(sv > 1e-9)):].conj().T
    s = np.linalg.svd(dr[0] @ N, compute_uv=False)
    return int(np.sum(s > 1e-8 * max(1.0, s[0] if s.size else 0.0)))


_SYSTEMS: dict[bytes, LimbIK] = {}
#: Per model object (immutable): ``(li, seed)`` -> its system, or why the homotopy refuses the limb.
_BY_MECH: weakref.WeakKeyDictionary[Mechanism, dict[tuple[int, int], LimbIK | str]] = weakref.WeakKeyDictionary()


def limb_ik_system(mech: Mechanism, li: int, seed: int = 0) -> LimbIK:
    """The :class:`LimbIK` of limb ``li`` of ``mech`` (a limb from the ground to the output
    link); ``InputError`` saying why when the homotopy does not cover it (:func:`ik_reason`).
    Kept per model object, so that a re-solve does not rebuild it."""
    per = _BY_MECH.setdefault(mech, {})
    hit = per.get((li, seed))
    if hit is None:
        try:
            hit = _build_system(mech, li, seed)
        except InputError as exc:
            hit = str(exc)
        per[(li, seed)] = hit
    if isinstance(hit, str):
        raise InputError(hit)
    return hit


def _build_system(mech: Mechanism, li: int, seed: int) -> LimbIK:
    if mech.limb_ends[li] != (None, 0):
        raise InputError(f"limb {mech.limbs[li].name}: does not run from the ground to the output link")
    balls = _ball_joints(mech, li)
    L = mech.characteristic_length
    refs = mech.freedom_refs[limb_slices(mech)[li]]
    m = len(refs)
    ball = balls[0][0] if balls else -1
    slots: list[tuple] = []
    nx = 0
    circles = []
    facts: list[_Factor] = []
    for k, r in enumerate(refs):
        if ball >= 0 and ball <= k < ball + 3:
            slots.append(("S", ball))
            continue
        A = twist_matrix(r.freedom.screw, L, r.freedom.kind == "P")
        if r.freedom.kind == "P":
            slots.append(("P", nx))
            facts.append(_Factor("P", A, A @ A, (nx,), 1.0, len(facts)))
            nx += 1
        else:
            slots.append(("R", nx, nx + 1))
            circles.append((nx, nx + 1))
            facts.append(_Factor("R", A, A @ A, (nx, nx + 1), 1.0, len(facts)))
            nx += 2
    if ball >= 0:
        n_before = sum(1 for s in slots[:ball] if s[0] != "S")
        cut = n_before
        kind, size = "point", 3
        centre = np.append(balls[0][1] / L, 1.0)
    else:
        kind, size = "full", 6
        cut = (len(facts) + 1) // 2
        centre = np.zeros(4)
    left = tuple(facts[:cut])
    right = tuple(_Factor(f.kind, f.A, f.A2, f.idx, -1.0, f.theta) for f in reversed(facts[cut:]))
    n_rows = nx - len(circles)
    geo = np.concatenate([np.array([float(kind == "point"), cut, seed])]
                         + [np.r_[f.A.ravel(), float(f.kind == "R")] for f in facts] + [centre])
    key = np.round(geo, 10).tobytes()
    hit = _SYSTEMS.get(key)
    if hit is not None:
        return hit
    rng = np.random.default_rng([seed, 2718])
    nonball = [k for k in range(m) if slots[k][0] != "S"]
    bound, source = _bound([refs[k].freedom.kind for k in nonball],
                           np.array([refs[k].freedom.screw for k in nonball]).reshape(-1, 6), kind)
    sysm = LimbIK(kind, left, right, centre, nx, tuple(circles), tuple(slots), np.eye(size, dtype=complex)[:n_rows],
                  False, 0, L, key=key)
    name = mech.limbs[li].name
    if n_rows > size:
        raise InputError(f"limb {name}: {n_rows} freedoms against {size} conditions: a solution set of positive "
                         "dimension (a redundant chain)")
    full_C = np.eye(size, dtype=complex)
    probe = LimbIK(kind, left, right, centre, nx, tuple(circles), tuple(slots), full_C, False, 0, L, key=key)
    rank = _generic_rank(probe, rng)
    if rank < n_rows:
        raise InputError(f"limb {name}: its closure puts {rank} independent conditions on {n_rows} unknowns: a solution "
                         f"set of dimension {n_rows - rank} (passive freedoms)")
    if n_rows == size:
        sysm = LimbIK(kind, left, right, centre, nx, tuple(circles), tuple(slots), full_C, True, bound, L, key=key,
                      bound_source=source)
    else:
        Cm = rng.normal(size=(n_rows, size)) + 1j * rng.normal(size=(n_rows, size))
        sysm = LimbIK(kind, left, right, centre, nx, tuple(circles), tuple(slots),
                      Cm / np.linalg.norm(Cm, axis=1, keepdims=True), False, 0, L, key=key)
    _SYSTEMS[key] = sysm
    return sysm


def ik_reason(mech: Mechanism, li: int) -> str | None:
    """``None`` when the homotopy covers limb ``li``, else why not (one sentence)."""
    try:
        limb_ik_system(mech, li)
    except InputError as exc:
        return str(exc)
    return None


def crand(rng: np.random.Generator, *shape: int) -> np.ndarray:
    """Standard complex normal samples of ``shape``."""
    return rng.normal(size=shape) + 1j * rng.normal(size=shape)


def random_point(sysm: LimbIK, rng: np.random.Generator) -> np.ndarray:
    x = crand(rng, sysm.nx)
    for a, b in sysm.circles:
        th = rng.uniform(-np.pi, np.pi) + 1j * rng.normal(scale=0.5)
        x[a], x[b] = np.cos(th), np.sin(th)
    return x


def start_pair(sysm: LimbIK, rng: np.random.Generator, genuine: bool | None = None) -> tuple[np.ndarray, np.ndarray]:
    """A random complex point ``x`` on the circles and parameters for which it is a solution:
    the pose it reaches (the rigid family, or ``genuine``), else a random pose and the offset
    ``b`` it misses by."""
    x = random_point(sysm, rng)
    genuine = sysm.rigid if genuine is None else genuine
    P = np.zeros(sysm.n_params, complex)
    if genuine and sysm.kind == "full":
        D = sysm.forward(x)
        P[:4], P[4:7] = quaternion_of(D[:3, :3]), D[:3, 3]
    elif genuine:  # the S joint's centre: any rotation, the translation that brings it there
        q = crand(rng, 4)
        TL = sysm._chain(sysm.left, x[None])[0][0]
        TR = sysm._chain(sysm.right, x[None])[0][0]
        E = rotation_forms(q[None])[0] / (q @ q)
        P[:4], P[4:7] = q, (TL @ sysm.centre)[:3] - E @ (TR @ sysm.centre)[:3]
    else:
        P[:7] = crand(rng, 7)
        r, _, _ = sysm.equations(x[None], P[None])
        P[7:] = (r @ sysm.C.T)[0]
    return x, P

def clear_systems() -> None:
    """Forget the cached limb systems (with :func:`.inverse.clear_cache`)."""
    _SYSTEMS.clear()
    _BY_MECH.clear()
