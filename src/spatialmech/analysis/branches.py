"""Branches of the closure set through a singular configuration (issue 27; docs/mobility.md).

At a *singular* configuration ``x0`` the corank ``k`` of the loop-closure Jacobian ``J`` exceeds
the local dimension of the set of closed configurations (a folded 6R whose six axes are
coplanar: ``k = 3`` on a motion of dimension 1), so neither the rank there nor the rank at a point
that Newton pulled back next to it says how the mechanism moves.  The set is explored instead:

1. *Second-order tangent cone.*  Every real analytic curve ``x(s)`` of closed configurations
   through ``x0`` has a unit tangent ``v`` with ``J v = 0`` and ``P_C F''(v, v) = 0``, ``P_C``
   the projection onto the cokernel of ``J`` (the order ``s^2`` of ``F(x(s)) = 0``).  With ``K``
   a basis of the kernel, these are ``c`` quadrics ``Q_j(a) = a^T H_j a`` in ``a`` (``v = K a``);
   the ``H_j`` come from central second differences of the nondimensional closure residual
   along the retraction (step :data:`~spatialmech.geometry.tolerances.CONE_DIFFERENCE_STEP`).
   Their real zeros on the unit sphere are sought by damped Gauss-Newton from seeded starts
   (a seeded vector of the local coordinates projected onto the kernel, ``K K^T g``, which does
   not depend on the basis or the signs the SVD returns); a zero is ``|Q| <= CONE_ZERO`` (or the
   rank tolerance, if looser).  No real zero at all (``|Q| > CONE_EMPTY`` at every start, or ten
   times the zero threshold) proves the configuration isolated: rigid there.
2. *Following.*  Each zero direction, one per line ``+-v``, is a candidate tangent of a branch:
   a predictor step ``BRANCH_STEP`` along it and Newton on the hyperplane orthogonal to it (every
   corrected point is at least a step away from ``x0``, so the corrector cannot fall back onto
   it), then on along the secant, out to ``BRANCH_REACH``; the other sense when the first fails.
3. *Dimension.*  At the two outermost points the rank is read again (there the singular values
   that vanish at ``x0`` have grown to about ``BRANCH_REACH`` times their rate): equal ranks
   give the branch's dimension (its mobility: the nullity less the passive freedoms).
   Candidate directions within the tangent space of a branch already found of dimension > 1
   belong to it.

Undecided (said, not guessed): a cone whose smallest obstruction lies between ``CONE_ZERO`` and
``CONE_EMPTY``, a candidate that cannot be followed either way (a higher-order obstruction, or a
branch the corrector cannot reach), or a rank that differs between the two outermost points.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..geometry.tolerances import BRANCH_REACH, BRANCH_STEP, CONE_DIFFERENCE_STEP, CONE_EMPTY, CONE_ZERO
from ..geometry.tolerances import current as current_tolerances
from ..kinematics.closure import Configuration
from ..kinematics.tracking import MotionProblem, conventional_sense, correct_on_hyperplane
from ..model.mechanism import Mechanism
from ..serialize import freedom_values_dict

__all__ = ["Branch", "Exploration", "explore"]

#: Seeded starts of the cone search: this many plus four per kernel dimension.
_STARTS = 16
#: Largest number of candidate directions followed (a cone of dimension > 1 has infinitely many).
_MAX_CANDIDATES = 12
#: Two candidate lines closer than this (rad) are one; a candidate farther than
#: ``_IN_BRANCH`` from a branch's tangent space (found at a step from ``x0``) is another branch.
_SAME_LINE = 1e-3
_IN_BRANCH = 0.05


@dataclass(frozen=True)
class Branch:
    """One branch of the closure set through the reference: its ``dimension`` (the mobility on
    it: nullity less passive freedoms at a regular point), its unit tangent ``direction`` at the
    reference (local nondimensional coordinates: the active freedoms, rad or slide / L, then the
    twist ``(w ; v / L)`` of each moving hub; the sign of :func:`.tracking.conventional_sense`),
    and a ``sample`` configuration on it at ``arc`` (nondimensional) from the reference."""

    dimension: int
    direction: tuple[float, ...]
    arc: float
    sample: Configuration
    joints: dict

    def to_dict(self) -> dict:
        return {"dimension": self.dimension, "direction": list(self.direction), "arc": self.arc, **self.joints}


@dataclass(frozen=True)
class Exploration:
    """The branches found (largest dimension first) and, when the local dimension could not be
    decided, why (``undecided``, else empty)."""

    corank: int
    branches: tuple[Branch, ...]
    undecided: str = ""
    #: The smallest second-order obstruction met by the cone search (relative; 0: none).
    obstruction: float = 0.0

    @property
    def dimension(self) -> int | None:
        """The local mobility: the largest branch dimension (0: isolated), ``None`` if undecided."""
        if self.undecided:
            return None
        return max((b.dimension for b in self.branches), default=0)


def _quadrics(prob: MotionProblem, x0, K: np.ndarray, C: np.ndarray) -> np.ndarray:
    """``H`` (c, k, k): the second-order obstruction ``Q_j(a) = a^T H_j a`` of the closure along
    ``v = K a``, projected on the cokernel basis ``C`` (central second differences)."""
    s = CONE_DIFFERENCE_STEP

    def second(v):
        return C.T @ (prob.residual(prob.retract(x0, s * v)) + prob.residual(prob.retract(x0, -s * v))) / (2 * s * s)

    k = K.shape[1]
    H = np.zeros((C.shape[1], k, k))
    diag = [second(K[:, i]) for i in range(k)]
    for i in range(k):
        H[:, i, i] = diag[i]
        for j in range(i + 1, k):
            H[:, i, j] = H[:, j, i] = (second(K[:, i] + K[:, j]) - diag[i] - diag[j]) / 2
    return H


def _cone_zero(Hs: np.ndarray, a: np.ndarray) -> tuple[float, np.ndarray]:
    """Damped Gauss-Newton for ``Q(a) = 0`` on the unit sphere from ``a``: (|Q|, a)."""
    Q = np.einsum("jik,i,k->j", Hs, a, a)
    f, lam = float(Q @ Q), 1e-3
    for _ in range(200):
        G = 2 * np.einsum("jik,k->ji", Hs, a)
        G = G - np.outer(G @ a, a)  # along the sphere
        d = -np.linalg.solve(G.T @ G + lam * np.eye(a.size), G.T @ Q)
        b = (a + d) / np.linalg.norm(a + d)
        Qb = np.einsum("jik,i,k->j", Hs, b, b)
        if float(Qb @ Qb) < f:
            a, Q, f, lam = b, Qb, float(Qb @ Qb), lam / 3
        else:
            lam *= 4
        if f < 1e-30 or lam > 1e8:
            break
    return float(np.sqrt(f)), a


def _cone(prob: MotionProblem, x0, K: np.ndarray, C: np.ndarray, rng, zero: float) -> tuple[list[np.ndarray], float]:
    """Unit directions ``v`` (one per line) of the real second-order tangent cone, and the smallest
    relative obstruction met (0 when the cone is the whole kernel)."""
    k = K.shape[1]
    starts = [K.T @ rng.standard_normal(K.shape[0]) for _ in range(_STARTS + 4 * k)]
    H = _quadrics(prob, x0, K, C) if C.shape[1] else np.zeros((0, k, k))
    if not np.all(np.isfinite(H)):
        return [], np.nan
    # (no quadric -- no constraint left on the kernel -- or an empty kernel: no obstruction)
    scale = float(np.max(np.abs(H), initial=0.0)) if H.size == 0 else float(np.max(np.linalg.norm(
        H.reshape(H.shape[0], -1), axis=1), initial=0.0))
    if scale <= zero:  # no second-order obstruction: every kernel direction is a candidate
        return [K @ (a / np.linalg.norm(a)) for a in starts], 0.0
    found, best = [], np.inf
    for a in starts:
        q, a = _cone_zero(H / scale, a / np.linalg.norm(a))
        best = min(best, q)
        if q <= zero:
            found.append(K @ a)
    return found, best


def _lines(vs: list[np.ndarray], order) -> list[np.ndarray]:
    """One direction per line, the conventional sign, in a deterministic order."""
    out: list[np.ndarray] = []
    for v in vs:
        v = v / np.linalg.norm(v)
        v = v * conventional_sense(v, order)
        if all(np.linalg.norm(v - w) > _SAME_LINE for w in out):
            out.append(v)
    return sorted(out, key=_order_key)


def _order_key(v: np.ndarray) -> tuple[float, ...]:
    return tuple(float(x) for x in np.round(v, 6))


def _walk(prob: MotionProblem, x0, t: np.ndarray) -> list | None:
    """Closed configurations along a branch leaving ``x0`` along ``t``, out to ``BRANCH_REACH``."""
    tol = current_tolerances().newton
    x, pts = x0, []
    for _ in range(round(BRANCH_REACH / BRANCH_STEP)):
        y, ok, _, _ = correct_on_hyperplane(prob, prob.retract(x, BRANCH_STEP * t), t, tol, 30)
        d = prob.difference(x, y)
        if not ok or not 0.5 * BRANCH_STEP < np.linalg.norm(d) < 3 * BRANCH_STEP:
            return None  # not closed, or fell back, or jumped
        x, t = y, d / np.linalg.norm(d)
        pts.append(x)
    return pts


def _tangent_space(prob: MotionProblem, x, rtol: float) -> np.ndarray:
    A = prob.jacobian(x)
    _, sv, vt = np.linalg.svd(A)
    r = int(np.sum(sv > rtol * max(1.0, sv[0])))
    return vt[r:]


def _follow(prob, x0, v, dof_at: Callable, rtol: float):
    """(branch dimension, sample, arc, tangent space at the first point) or a reason string."""
    for sign in (1.0, -1.0):
        pts = _walk(prob, x0, sign * v)
        if pts is None:
            continue
        (d_mid, n_mid), (d_end, n_end) = dof_at(pts[len(pts) // 2 - 1]), dof_at(pts[-1])
        if (d_mid, n_mid) != (d_end, n_end):
            return f"the rank changes along the branch leaving along {_show(v)} (nullity {n_mid}, then {n_end})"
        arc = float(np.linalg.norm(prob.difference(x0, pts[-1])))
        return d_end, pts[-1], arc, _tangent_space(prob, pts[0], rtol)
    return f"the tangent-cone direction {_show(v)} could not be followed either way"


def _show(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.3g}" for x in v[:6]) + (", ...)" if v.size > 6 else ")")


def _joints(mech: Mechanism, config: Configuration) -> dict:
    return freedom_values_dict(mech, {r.id: float(q) for r, q in zip(mech.freedom_refs, config.q, strict=True)},
                               "sample_joints")


def explore(mech: Mechanism, x0: Configuration, dof_at: Callable, *, seed: int = 0) -> Exploration:
    """The branches of the closure set through ``x0`` (module docstring).  ``dof_at(config)``
    returns ``(mobility, nullity)`` at a configuration (the caller's rank rule)."""
    rtol = current_tolerances().rank
    prob = MotionProblem(mech)
    U, sv, vt = np.linalg.svd(prob.jacobian(x0))
    r = int(np.sum(sv > rtol * max(1.0, sv[0])))
    K, C = vt[r:].T, U[:, r:]
    if K.shape[1] == 0:
        return Exploration(0, ())
    zero = max(CONE_ZERO, rtol)  # a looser rank tolerance (rounded data) loosens the cone's zero too
    vs, best = _cone(prob, x0, K, C, np.random.default_rng(seed), zero)
    if not vs:
        if np.isnan(best):
            return Exploration(K.shape[1], (), "the closure residual is not finite near the reference", best)
        if best > max(CONE_EMPTY, 10 * zero):
            return Exploration(K.shape[1], (), obstruction=best)
        return Exploration(K.shape[1], (), f"the second-order tangent cone is ambiguous (smallest obstruction "
                                           f"{best:.2g}, between {zero:g} and {max(CONE_EMPTY, 10 * zero):g})", best)
    branches: list[Branch] = []
    spaces: list[np.ndarray] = []
    problems: list[str] = []
    for v in _lines(vs, prob.sense_order)[:_MAX_CANDIDATES]:
        if any(T.shape[0] > 1 and np.linalg.norm(v - T.T @ (T @ v)) < _IN_BRANCH for T in spaces):
            continue  # within a branch of dimension > 1 found already
        got = _follow(prob, x0, v, dof_at, rtol)
        if isinstance(got, str):
            problems.append(got)
            continue
        dim, sample, arc, T = got
        spaces.append(T)
        branches.append(Branch(int(dim), tuple(float(x) + 0.0 for x in np.round(v, 12).tolist()), arc, sample,
                               _joints(mech, sample)))
    branches.sort(key=lambda b: -b.dimension)
    return Exploration(K.shape[1], tuple(branches), "; ".join(problems))
