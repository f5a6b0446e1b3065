"""The complete Jacobian (Joshi & Tsai 2002; paper A section 2) for any choice of actuators.

Rows are wrenches acting on the platform twist ``$p = (omega ; v)``:

- *constraint rows*: a basis of each limb's constraint-wrench system (the screws reciprocal to
  all of the limb's joint twists); ``W $p = 0``;
- *actuation rows*: for an actuated freedom ``a`` of limb ``k``, a wrench reciprocal to every
  other twist of limb ``k`` and not in the limb's constraint system, divided by its reciprocal
  product with ``$a`` (paper A eqs 13, 19), so that ``W_a $p = qdot_a``.

Stored as ``matrix = W DELTA`` (each wrench with its halves swapped), so that the plain matrix
product gives the reciprocal products: ``J $p = (0, ..., 0, qdot_actuators)``; the wrenches
themselves are :attr:`CompleteJacobian.wrenches`.  With as many rows as platform freedoms plus
constraints (6 for a mechanism whose actuators control it fully), ``DJ = det J``.

Signs.  For a limb with exactly five joint twists the constraint wrench is the cofactor
reciprocal (paper A eq 8), a polynomial in the twists: its sign is continuous along a path,
so the sign of ``DJ`` is comparable between configurations of the same mechanism and driver
(its magnitude is not).  Limbs with two or more constraint wrenches get a deterministic
basis, or one aligned with a ``reference`` Jacobian (projection of the reference rows onto
the current system) when following a path.  The actuation rows are unique up to constraint
components (which do not change the determinant) once divided by ``W . $a``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry import screws as sc
from ..geometry.tolerances import DEFAULT, current
from ..model.mechanism import Mechanism
from . import backend
from .closure import Configuration, active_mask, closure_scales, limb_slices
from .backend import closure_jacobian, joint_twists

__all__ = ["SINGULAR_SIGMA", "CompleteJacobian", "actuation_wrench", "closure_determinant", "complete_jacobian",
           "complete_jacobians", "limb_constraint_wrenches"]

#: Scale-free smallest singular value (:attr:`CompleteJacobian.sigma_min`) below which a
#: configuration is reported as singular (``"singular": true`` in JSON, a flag in text): the
#: default of :attr:`~spatialmech.geometry.tolerances.Tolerances.singular` (the one in force,
#: ``current().singular``, is used by :attr:`CompleteJacobian.singular`).
SINGULAR_SIGMA = DEFAULT.singular


@dataclass(frozen=True, eq=False)
class CompleteJacobian:
    """The complete Jacobian at one configuration."""

    matrix: np.ndarray  # (rows, 6): W DELTA, so that matrix @ twist = (0.., qdot)
    constraint_rows: int
    constraint_limbs: tuple[int, ...]  # limb index of each constraint row
    actuators: tuple[str, ...]
    inverse_singular: tuple[str, ...]  # actuators whose actuation wrench does not exist here
    length_scale: float
    transmission: tuple[float, ...] = ()  # per actuator, |W . $a| / (|W| |$a|): 0 at an inverse singularity

    @property
    def wrenches(self) -> np.ndarray:
        """The constraint then actuation wrenches ``(f ; m)``, one per row."""
        return sc.swap(self.matrix)

    @property
    def actuation(self) -> np.ndarray:
        return self.matrix[self.constraint_rows :]

    @property
    def constraints(self) -> np.ndarray:
        return self.matrix[: self.constraint_rows]

    @property
    def is_square(self) -> bool:
        return self.matrix.shape[0] == 6

    @property
    def det(self) -> float | None:
        """``det J`` (paper A's DJ) when square; only its sign is comparable between configurations."""
        return float(np.linalg.det(self.matrix)) if self.is_square else None

    def singular_values(self) -> np.ndarray:
        """Singular values of the nondimensional, row-normalised Jacobian (scale-free)."""
        M = sc.nondimensional(self.wrenches, self.length_scale)  # wrench moments / L
        n = np.linalg.norm(M, axis=1, keepdims=True)
        M = M / np.where(n > 0, n, 1.0)
        return np.linalg.svd(M, compute_uv=False)

    @property
    def sigma_min(self) -> float:
        """Smallest singular value of the scale-free Jacobian: 0 at a singularity."""
        sv = self.singular_values()
        return float(sv[-1]) if self.matrix.shape[0] >= 6 else 0.0

    @property
    def singular(self) -> bool:
        """``sigma_min`` below the ``singular`` tolerance in force (:mod:`~spatialmech.geometry.tolerances`)."""
        return bool(self.sigma_min < current().singular)

    @property
    def condition(self) -> float:
        """Inverse condition number (sigma_min / sigma_max) of the scale-free Jacobian, in [0, 1]."""
        sv = self.singular_values()
        return float(sv[-1] / sv[0]) if sv.size and sv[0] > 0 and self.matrix.shape[0] >= 6 else 0.0

    def to_dict(self) -> dict:
        """JSON (docs/json.md): ``matrix`` rows ``(moment ; direction)`` and ``wrenches``
        ``(direction ; moment)``, moments in the model's length unit; ``det`` (``None`` unless
        square; only its sign is comparable), the scale-free ``sigma_min``, ``condition`` (1 /
        condition number) and ``singular`` (``sigma_min`` below the ``singular`` tolerance in force);
        ``transmission`` by actuator."""
        sigma = self.sigma_min
        return {
            "matrix": self.matrix.tolist(),
            "wrenches": self.wrenches.tolist(),
            "constraint_rows": int(self.constraint_rows),
            "constraint_limbs": [int(k) for k in self.constraint_limbs],
            "actuators": list(self.actuators),
            "inverse_singular": list(self.inverse_singular),
            "det": self.det,
            "sigma_min": sigma,
            "condition": self.condition,
            "singular": bool(sigma < current().singular),  # = self.singular
            "singular_below": current().singular,
            "transmission": {a: float(t) for a, t in zip(self.actuators, self.transmission, strict=True)},
        }


def _nd(W: np.ndarray, L: float) -> np.ndarray:
    """Wrench to nondimensional coordinates: force part as is, moment divided by L."""
    return sc.nondimensional(W, L)


def _from_nd(W: np.ndarray, L: float) -> np.ndarray:
    out = np.array(W, dtype=float, copy=True)
    out[..., 3:] *= L
    return out


def limb_constraint_wrenches(twists: np.ndarray, *, length_scale: float = 1.0, reference: np.ndarray | None = None) -> np.ndarray:
    """Constraint wrenches (c, 6) of a limb with joint twists ``twists`` (m, 6).

    Five twists: the sign-continuous cofactor reciprocal.  Otherwise a basis of the reciprocal
    system, aligned with ``reference`` (c, 6) when given (projection onto the current system),
    else in reduced row-echelon form (deterministic).
    """
    T = np.atleast_2d(np.asarray(twists, dtype=float))
    L = float(length_scale)
    rtol = current().rank
    if T.shape[0] == 5:
        Tn = sc.nondimensional(T, L)
        w = sc.cofactor_reciprocal(Tn)  # in nd wrench coordinates
        # the five twists are independent (at the rank tolerance) when the cofactors, relative to
        # the product of the twists' norms, are not negligible
        if np.linalg.norm(w) > rtol * float(np.prod(np.linalg.norm(Tn, axis=1))):
            return _from_nd(w[None, :] / np.linalg.norm(w), L)
    W = sc.reciprocal_basis(T, length_scale=L)
    if W.shape[0] == 0:
        return W
    Wn = _nd(W, L)
    Q, _ = np.linalg.qr(Wn.T)  # orthonormal basis of the system (columns), nd
    if reference is not None and reference.shape == W.shape:
        P = _nd(reference, L) @ Q @ Q.T
        sv = np.linalg.svd(P, compute_uv=False)  # not row-normalised: a lost row must show
        if int(np.sum(sv > rtol * max(1.0, sv[0]))) == W.shape[0]:
            return _from_nd(P, L)
    # deterministic: reduced row echelon form of the nd basis
    A = sc.rref(Q.T)
    return _from_nd(A, L)


def actuation_wrench(twists: np.ndarray, index: int, constraints: np.ndarray, *, length_scale: float = 1.0,
                     with_transmission: bool = False):
    """Actuation wrench of freedom ``index`` of a limb, normalised so that ``W . $a = 1``.

    Returns ``None`` when it does not exist (the actuated twist depends on the others: an
    inverse, or serial, singularity).  With ``with_transmission`` returns ``(W, tau)`` where
    ``tau = |W . $a| / (|W| |$a|)`` (nondimensional, in [0, 1]) is the transmission index: 0 at
    an inverse singularity, where ``W`` itself is ``None``.
    """
    T = np.atleast_2d(np.asarray(twists, dtype=float))
    L = float(length_scale)
    others = np.delete(T, index, axis=0)
    R = sc.reciprocal_basis(others, length_scale=L) if others.shape[0] else np.eye(6)
    Rn = _nd(R, L)
    if constraints.shape[0]:
        Cn = _nd(constraints, L)
        Qc, _ = np.linalg.qr(Cn.T)
        Rn = Rn - (Rn @ Qc) @ Qc.T
    if Rn.shape[0] == 0:
        return (None, 0.0) if with_transmission else None
    _u, s, vt = np.linalg.svd(Rn)
    rtol = current().rank
    if s[0] < rtol:
        return (None, 0.0) if with_transmission else None
    w = _from_nd(vt[0], L)
    prod = sc.reciprocal_product(w, T[index])
    scale = float(np.linalg.norm(_nd(w, L)) * np.linalg.norm(sc.nondimensional(T[index], L)))
    tau = abs(prod) / (L * max(scale, 1e-300))  # product of nd screws = product / L
    if abs(prod) < rtol * max(scale, 1e-300):
        return (None, 0.0) if with_transmission else None
    return (w / prod, float(tau)) if with_transmission else w / prod


def complete_jacobian(
    mech: Mechanism,
    config: Configuration,
    actuators=None,
    *,
    reference: CompleteJacobian | None = None,
) -> CompleteJacobian:
    """The complete Jacobian of ``mech`` at ``config`` with the given actuators.

    ``actuators``: freedom names or aliases (default: the mechanism's actuated freedoms).
    ``reference``: a Jacobian at a nearby configuration of the same mechanism and actuators,
    to keep multi-wrench constraint bases continuous along a path.
    """
    act_ids = _actuator_ids(mech, actuators)
    if mech.bodies:
        return _graph_jacobian(mech, config, act_ids)
    return _with_actuators(mech, _ConstraintPart.at(mech, config, reference), act_ids)


def complete_jacobians(mech: Mechanism, config: Configuration, actuator_sets) -> list[CompleteJacobian]:
    """The complete Jacobians of ``mech`` at ``config`` for several sets of actuators (each
    as :func:`complete_jacobian` takes them), sharing one evaluation of the joint twists and of
    the limbs' constraint wrenches: equal, entry for entry, to
    ``[complete_jacobian(mech, config, a) for a in actuator_sets]``."""
    ids = [_actuator_ids(mech, a) for a in actuator_sets]
    if mech.bodies:
        return [_graph_jacobian(mech, config, a) for a in ids]
    part = _ConstraintPart.at(mech, config, None)
    return [_with_actuators(mech, part, a) for a in ids]


def _actuator_ids(mech: Mechanism, actuators) -> list[str]:
    if actuators is None:
        act_ids = list(mech.actuators)
    else:
        if isinstance(actuators, str):
            actuators = [actuators]
        act_ids = [mech.freedom(a).id for a in actuators]
    if len(set(act_ids)) != len(act_ids):
        raise InputError(f"actuators: repeated freedom in {list(actuators)}")
    return act_ids


@dataclass(frozen=True, eq=False)
class _ConstraintPart:
    """The actuator-free part of a complete Jacobian: each limb's active twists and constraint
    wrenches at one configuration."""

    L: float
    active_idx: list[list[int]]
    per_limb: list[tuple[np.ndarray, np.ndarray]]  # (T, W) by limb
    rows: list[np.ndarray]
    limbs_of_rows: list[int]

    @classmethod
    def at(cls, mech: Mechanism, config: Configuration, reference: CompleteJacobian | None) -> _ConstraintPart:
        L = mech.characteristic_length
        twists = joint_twists(mech, config)
        refs = mech.freedom_refs
        ref_rows = {}
        if reference is not None:
            for k in set(reference.constraint_limbs):
                ref_rows[k] = reference.constraints[[i for i, kk in enumerate(reference.constraint_limbs) if kk == k]]
        active_idx, per_limb, rows, limbs_of_rows = [], [], [], []
        for k, sl in enumerate(limb_slices(mech)):
            idx = [i for i in range(sl.start, sl.stop) if not refs[i].freedom.locked]
            active_idx.append(idx)
            T = twists[k][:, [i - sl.start for i in idx]].T
            W = limb_constraint_wrenches(T, length_scale=L, reference=ref_rows.get(k))
            per_limb.append((T, W))
            for w in W:
                rows.append(w)
                limbs_of_rows.append(k)
        return cls(L, active_idx, per_limb, rows, limbs_of_rows)


def _with_actuators(mech: Mechanism, part: _ConstraintPart, act_ids: list[str]) -> CompleteJacobian:
    L = part.L
    refs = mech.freedom_refs
    by_id = {r.id: r for r in refs}
    rows = list(part.rows)
    n_c = len(rows)
    singular = []
    trans = []
    for a in act_ids:
        r = by_id[a]
        if r.freedom.locked:
            raise InputError(f"actuators: {a} is locked in this mode")
        T, W = part.per_limb[r.limb]
        col = part.active_idx[r.limb].index(refs.index(r))
        w, tau = actuation_wrench(T, col, W, length_scale=L, with_transmission=True)
        trans.append(tau)
        if w is None:
            singular.append(a)
            w = np.zeros(6)
        rows.append(w)
    M = sc.swap(np.array(rows)) if rows else np.zeros((0, 6))
    return CompleteJacobian(M, n_c, tuple(part.limbs_of_rows), tuple(act_ids), tuple(singular), L, tuple(trans))


def _graph_jacobian(mech: Mechanism, config: Configuration, act_ids: list[str]) -> CompleteJacobian:
    """The complete Jacobian of a mechanism with internal bodies, by elimination from the
    nondimensional closure system ``A_p x_p + A_a qdot_a + A_V V = 0``: projected onto the left
    null space of the passive columns ``A_p`` (passive joints and bodies) it reads
    ``H V + G qdot_a = 0``; the constraint rows span ``N^T H`` with ``N`` the left null space of
    ``G``, the actuation rows are ``-G^+ H`` (so that ``J V = (0, qdot_a)`` as for limbs).  The
    rows are orthonormal bases: ``det`` is not sign-continuous along a path (use
    :func:`driver_determinants`, which is)."""
    refs = mech.freedom_refs
    by_id = {r.id: i for i, r in enumerate(refs)}
    active = active_mask(mech)
    for a in act_ids:
        if refs[by_id[a]].freedom.locked:
            raise InputError(f"actuators: {a} is locked in this mode")
    A, _ = closure_jacobian(mech, config, active=active)
    row, col = closure_scales(mech, active)
    As = row[:, None] * A * col[None, :]
    na = int(active.sum())
    pos = np.cumsum(active) - 1
    acols = [int(pos[by_id[a]]) for a in act_ids]
    vcols = list(range(na, na + 6))
    pcols = [c for c in range(As.shape[1]) if c not in set(acols) | set(vcols)]
    rtol = current().rank
    P = As[:, pcols]
    U, sv, _ = np.linalg.svd(P, full_matrices=True)
    r = int(np.sum(sv > rtol * max(1.0, sv[0] if sv.size else 0.0)))
    Qn = U[:, r:]  # left null space of the passive columns
    H = Qn.T @ As[:, vcols]
    G = Qn.T @ As[:, acols]
    colV = col[vcols]
    Ug, sg, _ = np.linalg.svd(G, full_matrices=True) if G.size else (np.eye(G.shape[0]), np.zeros(0), None)
    rg = int(np.sum(sg > rtol * max(1.0, sg[0] if sg.size else 0.0)))
    C = Ug[:, rg:].T @ H  # constraint part
    if C.shape[0]:
        _, sc_, Vc = np.linalg.svd(C, full_matrices=False)
        C = Vc[: int(np.sum(sc_ > rtol * max(1.0, sc_[0] if sc_.size else 0.0)))].copy()
        # oriented against the reduced row-echelon basis of the same system, so that the sign of
        # det does not follow the basis the SVD returned (docs/conventions.md)
        E = sc.rref(C)
        if C.shape[0] and E.shape[0] == C.shape[0] and np.linalg.det(C @ E.T) < 0:
            C[0] = -C[0]
    rows_out = [c / colV for c in C]
    singular, trans = [], []
    for k, a in enumerate(act_ids):
        g = G[:, k]
        others = np.delete(G, k, axis=1)
        if others.shape[1]:
            Qo, _ = np.linalg.qr(others)
            g_perp = g - Qo @ (Qo.T @ g)
        else:
            g_perp = g
        ng = float(np.linalg.norm(g))
        tau = float(np.linalg.norm(g_perp)) / ng if ng > 0 else 0.0
        trans.append(tau)
        if tau < rtol:
            singular.append(a)
            rows_out.append(np.zeros(6))
            continue
        # qdot_a = -(g_perp . H V) / (g_perp . g): the component of the closure along g_perp
        w = -(g_perp @ H) / float(g_perp @ g)
        rows_out.append(col[acols[k]] * w / colV)
    M = np.array(rows_out).reshape(-1, 6)
    return CompleteJacobian(M, int(C.shape[0]), tuple([-1] * int(C.shape[0])), tuple(act_ids), tuple(singular),
                            mech.characteristic_length, tuple(trans))


def closure_determinant(mech: Mechanism, config: Configuration, driver: str) -> float:
    """The determinant of the nondimensional closure Jacobian with ``driver``'s column removed
    (every other unlocked freedom and every moving hub free), for a mechanism whose closure
    system is square once the driver is held: zero exactly where the driver does not determine
    the motion (a branch point), and a polynomial in the joint twists, so its sign is
    continuous along a path.  ``nan`` when the system is not square."""
    active = active_mask(mech)
    A, _ = closure_jacobian(mech, config, active=active)
    row, col = closure_scales(mech, active)
    As = row[:, None] * A * col[None, :]
    pos = np.cumsum(active) - 1
    i = mech.freedom_refs.index(mech.freedom(driver))
    if not active[i]:
        raise InputError(f"drivers: {driver} is locked")
    M = np.delete(As, int(pos[i]), axis=1)
    return float(np.linalg.det(M)) if M.shape[0] == M.shape[1] else float("nan")


def driver_determinants(mech: Mechanism, config: Configuration, drivers) -> np.ndarray:
    """``det J`` for each single driver in ``drivers`` at one configuration, sharing the
    constraint rows (one twist evaluation for all drivers).  Equal to
    ``complete_jacobian(mech, config, [d]).det`` for each ``d``; ``nan`` where J is not square
    (a mechanism with redundant constraints) — use the driver rate along the motion instead.

    A mechanism with internal bodies (a link-and-joint graph) gets :func:`closure_determinant`
    per driver instead: the same zeros where a driver loses control of the motion, a different
    magnitude and no poles."""
    if (engine := backend.engine()) is not None and (fast := engine.driver_determinants(mech, config, drivers)) is not None:
        return fast
    if mech.bodies:
        return np.array([closure_determinant(mech, config, d) for d in drivers])
    L = mech.characteristic_length
    twists = joint_twists(mech, config)
    refs = mech.freedom_refs
    sls = limb_slices(mech)
    cons: list[np.ndarray] = []
    per_limb: list[tuple[np.ndarray, np.ndarray]] = []
    active_idx: list[list[int]] = []
    for k, sl in enumerate(sls):
        idx = [i for i in range(sl.start, sl.stop) if not refs[i].freedom.locked]
        active_idx.append(idx)
        T = twists[k][:, [i - sl.start for i in idx]].T
        W = limb_constraint_wrenches(T, length_scale=L)
        per_limb.append((T, W))
        cons.extend(W)
    out = np.full(len(drivers), np.nan)
    if len(cons) != 5:
        return out
    C = sc.swap(np.array(cons))
    for n, d in enumerate(drivers):
        r = mech.freedom(d)
        T, W = per_limb[r.limb]
        w = actuation_wrench(T, active_idx[r.limb].index(refs.index(r)), W, length_scale=L)
        out[n] = 0.0 if w is None else float(np.linalg.det(np.vstack([C, sc.swap(w)])))
    return out
