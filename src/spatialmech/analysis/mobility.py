"""Mobility: the modified Kutzbach-Grübler formula from screw systems, and a numerical check.

Modified formula (Huang; papers B and C, eq 4 / eq 9)::

    M = d (n - g - 1) + sum(f_i) + v - xi,     d = 6 - lambda,   v = t - k

All of ``lambda, t, k, xi`` are derived from the screw systems of the limbs at the reference
configuration (not typed in):

- ``lambda`` common constraints: the wrenches reciprocal to every joint twist of the
  mechanism, ``6 - rank(all twists)``;
- ``t`` the number of limb constraint wrenches once the common ones are removed,
  ``sum_k (dim W_k - lambda)`` with ``W_k`` the constraint system of limb ``k``;
- ``k`` the number of independent ones among them, ``dim(sum_k W_k) - lambda``;
- ``v = t - k`` redundant constraints (paper C prints ``k - t``: a typo that is harmless there
  because ``t = k``);
- ``xi`` passive (local) freedoms: motions of a limb's joints with the platform at rest,
  ``sum_k (f_k - rank T_k)``, e.g. the spin of an SPS leg about its own axis.

``n`` counts links including base and platform, ``g`` joints; a locked joint is removed and its
two links merged.  The numerical check is independent: the nullity of the loop-closure
Jacobian at a *generic* configuration reached by moving along the closure manifold, minus the
passive freedoms, is the instantaneous mobility ``dof_instantaneous``.

Tolerance.  Every rank above is numerical: a singular value of a nondimensional matrix counts
when it exceeds the rank tolerance (:mod:`~spatialmech.geometry.tolerances`, default 1e-9).  A
model typed with rounded numbers (4-6 significant digits) can lose a special geometry (the
Bennett conditions) to rounding: at the default tolerance it is then rigid, at 1e-4 mobile.  So
the result also scans the tolerance: the count at every tolerance between 0 and 0.1
(:attr:`MobilityResult.dof_by_tolerance`, the singular values where it changes and which matrix
they belong to), and says so when the count changes between 1e-12 and 1e-2.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, replace
from itertools import pairwise

import numpy as np

from ..errors import ConvergenceError, InputError
from ..geometry import screws as sc
from ..geometry.screw_axes import ScrewAxis, principal_screws
from ..geometry.tolerances import SINGULAR_LEFT, Tolerances, current, resolve, use
from ..kinematics.closure import Configuration, active_mask, closure_scales, hub_count, limb_slices
from ..kinematics.backend import closure_jacobian, joint_twists
from ..kinematics.motion import generic_configuration
from ..kinematics.tracking import MotionProblem
from .branches import Branch, Exploration, explore
from ..model.mechanism import Mechanism, Mode
from ..serialize import fields_dict, html_summary

__all__ = ["ELEMENTARY_MOTIONS", "SCAN_RANGE", "MobilityResult", "ToleranceStep", "mobility", "mobility_modes", "motion_type"]

#: Tolerances scanned for the count's dependence on the rank tolerance: every singular value in
#: this range is a candidate change point; ``dof_at_tolerance`` lists the decades 1e-12 .. 1e-2.
SCAN_RANGE = (1e-14, 1e-1)
#: Where a change of the count is worth a note: a tolerance that rounded input data could need.
NOTE_RANGE = (1e-12, 1e-2)
#: Singular values at or below this (relative) are round-off zeros.
_ROUNDOFF = 1e-15

#: The elementary platform motions used to name a motion type, at the platform point.
ELEMENTARY_MOTIONS = {
    "Rx": np.array([1.0, 0, 0, 0, 0, 0]),
    "Ry": np.array([0, 1.0, 0, 0, 0, 0]),
    "Rz": np.array([0, 0, 1.0, 0, 0, 0]),
    "Tx": np.array([0, 0, 0, 1.0, 0, 0]),
    "Ty": np.array([0, 0, 0, 0, 1.0, 0]),
    "Tz": np.array([0, 0, 0, 0, 0, 1.0]),
}


def motion_type(twists, point, *, length_scale: float = 1.0, rtol: float | None = None) -> tuple[str, str]:
    """Name a platform twist system at ``point``: ``("RxRyRzTz", "3R1T")``.

    Screws of non-zero pitch (the principal screws of :func:`~spatialmech.geometry.screw_axes.principal_screws`)
    are named ``H``: a 3-system of pitch 1.74 m/rad is ``"3H"``, not ``"3R"``.
    The first name lists the elementary motions (rotations about axes through ``point``
    parallel to x, y, z; translations along x, y, z) when they span the system; otherwise it is
    the class name alone (e.g. a coupled screw motion, or rotation axes not through the point).
    """
    T = np.atleast_2d(np.asarray(twists, dtype=float))
    p = np.asarray(point, dtype=float)
    if T.size == 0:
        return "rigid", "0"
    at_p = T.copy()
    at_p[:, 3:] = T[:, 3:] + np.cross(T[:, :3], p)
    rtol = current().rank if rtol is None else rtol
    dim = sc.rank(at_p, length_scale=length_scale, rtol=rtol)
    if dim == 0:
        return "rigid", "0"
    B = sc.basis(at_p, length_scale=length_scale, rtol=rtol)  # orthonormal basis of the system
    w = B[:, :3]
    sv = np.linalg.svd(w, compute_uv=False)
    r = int(np.sum(sv > rtol))
    tdim = dim - r
    cls = (f"{r}R" if r else "") + (f"{tdim}T" if tdim else "")
    ctol = max(current().contains, rtol)  # a looser rank tolerance loosens membership too
    axes = principal_screws(T, length_scale=length_scale, rtol=rtol)
    helical = sum(a.multiplicity for a in axes if a.kind == "H")
    if helical:  # screws of non-zero pitch are not rotations: "3H", "1R2H", "2H1T"
        cls = (f"{r - helical}R" if r > helical else "") + f"{helical}H" + (f"{tdim}T" if tdim else "")
        return cls, cls
    members = [k for k, e in ELEMENTARY_MOTIONS.items() if sc.contains(at_p, e, length_scale=length_scale, rtol=ctol)]
    if len(members) == dim:
        return "".join(members), cls
    return cls, cls


@dataclass(frozen=True)
class ToleranceStep:
    """The count for rank tolerances in ``[lower, upper)``: it changes at ``lower``, a singular
    value of ``source`` (0 and "" for the first step)."""

    lower: float
    upper: float
    dof: int
    source: str = ""

    def to_dict(self) -> dict:
        return fields_dict(self, {"lower": "from", "upper": "to"})


@dataclass(frozen=True)
class MobilityResult:
    """Mobility of one mode of a mechanism, with the whole breakdown."""

    mechanism: str
    mode: str
    actuators: tuple[str, ...]
    dof: int
    dof_instantaneous: int
    gk_classic: int
    motion: str
    motion_class: str
    lam: int
    d: int
    n: int
    g: int
    sum_f: int
    t: int
    k: int
    v: int
    xi: int
    limb_constraints: tuple[int, ...]
    constraint_wrenches: tuple[tuple[float, ...], ...]
    agrees: bool
    explanation: str
    passive: tuple[int, ...] = field(default=())
    #: Independent loops of the link graph, ``g - n + 1``.
    loops: int = 0
    #: How ``t`` and ``k`` were counted: ``"limbs"`` (constraint wrenches of limbs between the
    #: ground and the output link) or ``"loops"`` (closure equations of the independent loops of
    #: a link-and-joint graph; see :func:`mobility`).
    counted_by: str = "limbs"
    #: The rank tolerance used (relative singular-value threshold, nondimensional).
    tolerance: float = 1e-9
    #: The count ``dof`` as a function of the rank tolerance over ``[0, SCAN_RANGE[1])``.
    dof_by_tolerance: tuple[ToleranceStep, ...] = field(default=())
    #: One line about that dependence (empty when there is nothing to say).
    tolerance_note: str = ""
    #: The reference configuration is singular: the generic configuration did not leave it, or
    #: the closure Jacobian's nullity there exceeds the nullity at the generic configuration.
    reference_singular: bool = False
    #: The instantaneous mobility at the reference itself (nullity less passive freedoms there).
    dof_at_reference: int = 0
    #: The mobility near the reference: ``dof_instantaneous`` at a regular reference, the largest
    #: dimension of the branches through a singular one (0: an isolated configuration), ``None``
    #: when that could not be decided (:attr:`undecided`).
    local_dof: int | None = None
    #: The branches through a singular reference (:mod:`.branches`), largest dimension first.
    branches: tuple[Branch, ...] = field(default=())
    #: One line about a singular reference (empty at a regular one).
    singular_note: str = ""
    #: Why the branches through a singular reference could not be decided (empty when they were).
    undecided: str = ""
    #: The principal screws of the output link's free twist system where the motion is named
    #: (world frame): for a 1-DOF mechanism its instantaneous screw (axis point, direction,
    #: pitch).  ``kind`` "H" marks a screw of non-zero pitch.
    screw_axes: tuple[ScrewAxis, ...] = field(default=())

    def dof_at(self, tolerance: float) -> int | None:
        """The count at another rank tolerance (within the scanned range; else ``None``)."""
        for s in self.dof_by_tolerance:
            if s.lower <= tolerance < s.upper:
                return s.dof
        return None

    @property
    def tolerance_margin(self) -> tuple[float, float]:
        """The range of rank tolerances around :attr:`tolerance` that give the same count."""
        for s in self.dof_by_tolerance:
            if s.lower <= self.tolerance < s.upper:
                return (s.lower, s.upper)
        return (0.0, float("nan"))

    def to_dict(self) -> dict:
        d = asdict(self)
        d["lambda"] = d.pop("lam")
        d["links"] = self.n
        d["actuators"] = list(self.actuators)
        d["limb_constraints"] = list(self.limb_constraints)
        d["passive"] = list(self.passive)
        d["constraint_wrenches"] = [list(w) for w in self.constraint_wrenches]
        d["dof_by_tolerance"] = [s.to_dict() for s in self.dof_by_tolerance]
        d["branches"] = [b.to_dict() for b in self.branches]
        d["screw_axes"] = [a.to_dict() for a in self.screw_axes]
        d["dof_at_tolerance"] = [{"tolerance": t, "dof": self.dof_at(t)} for t in _DECADES]
        return d

    def _repr_html_(self) -> str:  # a notebook's display
        return html_summary(f"mobility: {self.mechanism}", self.to_dict())

    def formula(self) -> str:
        return (
            f"M = d(n - g - 1) + sum f + v - xi = {self.d}({self.n} - {self.g} - 1) + {self.sum_f}"
            f" + {self.v} - {self.xi} = {self.dof}"
        )


def _canonical(W: np.ndarray, L: float) -> np.ndarray:
    """A readable basis of a screw system: reduced row echelon form (pivot tolerance in force:
    rounding noise is never a pivot), then each screw scaled to a unit direction (or a unit
    moment for a pure couple/translation)."""
    if W.shape[0] == 0:
        return W
    A = sc.rref(sc.nondimensional(W, L))
    A[:, 3:] *= L
    out = []
    for w in A:
        n = np.linalg.norm(w[:3])
        w = w / (n if n > current().pivot * np.linalg.norm(w[3:] / L) else np.linalg.norm(w[3:]))
        w = np.where(np.abs(w) < 1e-12, 0.0, w)
        out.append(np.round(w, 12) + 0.0)
    return np.array(out)


def _count_structure(mech: Mechanism) -> tuple[int, int, int, list[int]]:
    """Links n (incl. the ground, the output link and the internal bodies), joints g, sum of
    freedoms, per-limb freedoms; a locked joint is removed and its two links merged."""
    g = 0
    n = 2 + len(mech.bodies)
    f_limbs = []
    for limb in mech.limbs:
        gk = sum(1 for j in limb.joints if j.dof > 0)
        g += gk
        n += gk - 1
        f_limbs.append(limb.dof)
    return n, g, sum(f_limbs), f_limbs


def _relative_sv(A: np.ndarray) -> np.ndarray:
    """Singular values of ``A`` with every nonzero column normalised, divided by ``max(1, largest)``
    (the numbers compared with the rank tolerance), padded with zeros to one per column."""
    if A.shape[1] == 0:
        return np.zeros(0)
    if not np.all(np.isfinite(A)):
        raise ConvergenceError("mobility: the loop-closure Jacobian overflowed (NaN or infinity); check the model's scale")
    n = np.linalg.norm(A, axis=0)
    An = A / np.where(n > 0, n, 1.0)
    sv = np.linalg.svd(An, compute_uv=False) if A.shape[0] else np.zeros(0)
    sv = np.r_[sv, np.zeros(A.shape[1] - sv.size)]
    return sv / max(1.0, sv[0]) if sv.size and sv[0] > 0 else sv


def _nullity(A: np.ndarray, rtol: float) -> int:
    return int(np.sum(_relative_sv(A) <= rtol))


def _scaled_closure(mech: Mechanism, config: Configuration) -> tuple[np.ndarray, np.ndarray, list[list[int]]]:
    """The nondimensional closure Jacobian (moments / L, slides x L), the column scales, and
    per limb its columns."""
    active = active_mask(mech)
    A, _ = closure_jacobian(mech, config, active=active)
    row, col = closure_scales(mech, active)
    As = row[:, None] * A * col[None, :]
    idx = np.flatnonzero(active)
    cols = [[i for i, gi in enumerate(idx) if sl.start <= gi < sl.stop] for sl in limb_slices(mech)]
    return As, col, cols


def _instantaneous(mech: Mechanism, config: Configuration, rtol: float) -> tuple[int, int, np.ndarray]:
    """(platform dof, passive freedoms, platform twist basis) at ``config``, nondimensionally."""
    L = mech.characteristic_length
    As, col, limb_cols = _scaled_closure(mech, config)
    N = _nullity(As, rtol)
    # passive freedoms: limb Jacobians' null spaces (platform at rest)
    xi = sum(_nullity(As[:, c], rtol) for c in limb_cols if c)
    # platform twists = projection of the null space onto V (columns normalised for the SVD)
    n = np.linalg.norm(As, axis=0)
    n = np.where(n > 0, n, 1.0)
    _, sv, vt = np.linalg.svd(As / n)
    r = int(np.sum(sv > rtol * max(1.0, sv[0])))
    null = vt[r:] / n  # back to the scaled variables
    na = int(active_mask(mech).sum())
    V = null[:, na : na + 6] * col[na : na + 6]  # the output link's part, back to SI twists (u = col x)
    Vb = sc.basis(V, length_scale=L, rtol=rtol) if V.shape[0] else np.zeros((0, 6))
    return N - xi, xi, Vb


@dataclass(frozen=True)
class _Counts:
    lam: int
    d: int
    t: int
    k: int
    v: int
    xi: int
    M: int
    W: list
    Wall: np.ndarray
    passive: tuple[int, ...]


def _formula(limbs_T: list[np.ndarray], L: float, n: int, g: int, sum_f: int, f_limbs: list[int], rtol: float) -> _Counts:
    """The modified Kutzbach-Grübler count from the limbs' joint twists at rank tolerance ``rtol``."""
    all_T = np.vstack([T for T in limbs_T if T.size] or [np.zeros((0, 6))])
    lam = 6 - sc.rank(all_T, length_scale=L, rtol=rtol) if all_T.size else 6
    d = 6 - lam
    W = [sc.reciprocal_basis(T, length_scale=L, rtol=rtol) if T.size else np.eye(6) for T in limbs_T]
    ranks = [sc.rank(T, length_scale=L, rtol=rtol) if T.size else 0 for T in limbs_T]
    t = sum(w.shape[0] - lam for w in W)
    Wall = np.vstack(W)
    k = (sc.rank(Wall, length_scale=L, rtol=rtol) if Wall.size else 0) - lam
    v = t - k
    passive = tuple(f - r for f, r in zip(f_limbs, ranks, strict=True))
    xi = sum(passive)
    return _Counts(lam, d, t, k, v, xi, d * (n - g - 1) + sum_f + v - xi, W, Wall, passive)


def _loop_formula(limbs_T: list[np.ndarray], L: float, As: np.ndarray, limb_cols, hubs: int, n: int, g: int,
                  sum_f: int, f_limbs: list[int], rtol: float) -> _Counts:
    """The modified count for a link-and-joint graph, from its loops: ``t = d * loops`` closure
    equations (``d = 6 - lambda`` per loop), of which ``k`` are independent (the rank of the
    closure Jacobian at the reference less the ``6 * hubs`` columns of the moving hubs); ``xi``
    the motions of each limb with both its end links at rest."""
    all_T = np.vstack([T for T in limbs_T if T.size] or [np.zeros((0, 6))])
    lam = 6 - sc.rank(all_T, length_scale=L, rtol=rtol) if all_T.size else 6
    d = 6 - lam
    loops = g - n + 1
    t = d * loops
    k = As.shape[1] - _nullity(As, rtol) - 6 * hubs
    v = t - k
    W = [sc.reciprocal_basis(T, length_scale=L, rtol=rtol) if T.size else np.eye(6) for T in limbs_T]
    passive = tuple(_nullity(As[:, c], rtol) if c else 0 for c in limb_cols)
    xi = sum(passive)
    return _Counts(lam, d, t, k, v, xi, d * (n - g - 1) + sum_f + v - xi, W, np.zeros((0, 6)), passive)


#: The tolerances of ``dof_at_tolerance`` in the JSON (decades).
_DECADES = tuple(10.0**e for e in range(-12, -1))


def _candidates(limbs_T: list[np.ndarray], limb_names: list[str], L: float, As: np.ndarray, limb_cols,
                Wall: np.ndarray) -> list[tuple[float, str]]:
    """Every singular value (relative) at which a count of the formula or of the instantaneous
    mobility at the reference can change, with the matrix it belongs to."""
    out: list[tuple[float, str]] = []
    all_T = np.vstack([T for T in limbs_T if T.size] or [np.zeros((0, 6))])
    if all_T.size:
        out += [(float(s), "joint twists of all limbs") for s in sc.relative_singular_values(all_T, length_scale=L)]
    for T, name in zip(limbs_T, limb_names, strict=True):
        if T.size:
            out += [(float(s), f"joint twists of limb {name}") for s in sc.relative_singular_values(T, length_scale=L)]
    if Wall.size:
        out += [(float(s), "constraint wrenches of all limbs") for s in sc.relative_singular_values(Wall, length_scale=L)]
    out += [(float(s), "loop-closure Jacobian at the reference") for s in _relative_sv(As)]
    for c, name in zip(limb_cols, limb_names, strict=True):
        if c:
            out += [(float(s), f"Jacobian of limb {name}") for s in _relative_sv(As[:, c])]
    return out


def _scan(count, candidates: list[tuple[float, str]]) -> tuple[ToleranceStep, ...]:
    """``count(tol)`` as a step function over ``[0, SCAN_RANGE[1])``: evaluated between
    consecutive candidate singular values (the only places where it can change)."""
    lo, hi = SCAN_RANGE
    vals = sorted({v for v, _ in candidates if lo < v < hi})
    edges = [0.0, *vals, hi]
    steps: list[ToleranceStep] = []
    for a, b in pairwise(edges):
        mid = np.sqrt(max(a, _ROUNDOFF) * b) if a > 0 else min(b / 10.0, lo)
        m = count(mid)
        if steps and steps[-1].dof == m:
            steps[-1] = ToleranceStep(steps[-1].lower, b, m, steps[-1].source)
        else:
            src = sorted({name for v, name in candidates if v == a}) if a > 0 else []
            steps.append(ToleranceStep(a, b, m, ", ".join(src)))
    return tuple(steps)


def _say(m: int) -> str:
    return "rigid (M = 0)" if m == 0 else (f"mobile (M = {m})" if m > 0 else f"M = {m}")


def _round_tolerance(lower: float, upper: float) -> float:
    """A readable tolerance within ``[lower, upper)``: the smallest decade above ``lower``, or
    their geometric mean."""
    dec = 10.0 ** np.ceil(np.log10(lower)) if lower > 0 else 1e-12
    if dec == lower:
        dec *= 10
    return float(dec) if dec < upper else float(np.sqrt(lower * upper))


def _tolerance_note(steps: tuple[ToleranceStep, ...], tol: float, dof: int) -> str:
    """One line: at which tolerances the count differs from ``dof`` in the plausible range."""
    here = next((s for s in steps if s.lower <= tol < s.upper), None)
    if here is None:
        return ""
    a, b = NOTE_RANGE
    parts = []
    above = [s for s in steps if s.lower > tol and s.lower < b]
    below = [s for s in steps if s.upper <= tol and s.upper > a]
    if above:
        s = above[0]
        parts.append(f"{_say(dof)} at tolerance {tol:.0e}, {_say(s.dof)} at {_round_tolerance(s.lower, s.upper):.0e}: "
                     f"the smallest singular value counted at {tol:.0e} is {s.lower:.2g} ({s.source}), "
                     f"and the count stays {s.dof} up to {s.upper:.2g}")
    if below:
        s = below[-1]
        src = here.source or "round-off"
        parts.append(f"{_say(dof)} at tolerance {tol:.0e}, {_say(s.dof)} below {here.lower:.2g}: the largest singular "
                     f"value treated as zero at {tol:.0e} is {here.lower:.2g} ({src})")
    if not parts:
        lower = f"{here.lower:.2g}" if here.lower > _ROUNDOFF else "round-off"
        upper = f"to {here.upper:.2g}" if here.upper < SCAN_RANGE[1] else f"to at least {here.upper:.2g}"
        return (f"Tolerance: the count is {dof} for every rank tolerance from {lower} {upper} "
                f"(the one used, {tol:.0e}, included).")
    hint = ("; data typed with 4-6 significant digits loses special geometry to rounding: if the model is meant "
            "to have the other count, analyse it at that tolerance (--tol)")
    return "Tolerance: " + "; ".join(parts) + hint + "."


def _generic(m: Mechanism, ref: Configuration, seed: int, rtol: float):
    """(generic configuration, instantaneous mobility and platform twists there, a note)."""
    try:
        gen = generic_configuration(m, seed=seed)
        dof_inst, _, Vgen = _instantaneous(m, gen, rtol)
        return gen, dof_inst, Vgen, ""
    except RuntimeError as e:  # reported, not hidden
        dof_inst, _, Vgen = _instantaneous(m, ref, rtol)
        return ref, dof_inst, Vgen, f" (no generic configuration could be reached: {e}; the reference was used)"


@dataclass(frozen=True)
class _Reference:
    """Whether the reference is singular, the instantaneous mobility there, and the branches
    through it (explored only when singular)."""

    singular: bool
    dof_ref: int
    exploration: Exploration | None = None

    def note(self) -> str:
        e = self.exploration
        if e is None or not self.singular:
            return ""
        head = (f"The reference configuration is singular (instantaneous mobility {self.dof_ref} there; "
                f"corank {e.corank} of the closure Jacobian)")
        dims = [b.dimension for b in e.branches]
        found = ", ".join(f"{dims.count(d)} of dimension {d}" for d in sorted(set(dims), reverse=True))
        if e.undecided:
            return (f"{head}; the branches through it are undecided: {e.undecided}"
                    + (f" (found: {found})." if found else "."))
        if not dims:
            return (f"{head}, but no real branch leaves it (its second-order tangent cone is empty: smallest "
                    f"obstruction {e.obstruction:.2g}): an isolated configuration, rigid there.")
        return f"{head}; branches through it: {found}; the mobility is the largest, {max(dims)}."


def _reference_check(m: Mechanism, ref: Configuration, gen: Configuration, seed: int, rtol: float) -> _Reference:
    """Singular reference: the generic configuration stayed within ``SINGULAR_LEFT`` of it, or the
    nullity there is not the reference's; then its branches are explored (:mod:`.branches`)."""

    def dof_at(c: Configuration) -> tuple[int, int]:
        dof, xi, _ = _instantaneous(m, c, rtol)
        return dof, dof + xi

    dof_ref, null_ref = dof_at(ref)
    if null_ref == 0:
        return _Reference(False, dof_ref)
    left = float(np.linalg.norm(MotionProblem(m).difference(ref, gen)))
    if left > SINGULAR_LEFT and dof_at(gen)[1] == null_ref:
        return _Reference(False, dof_ref)
    e = explore(m, ref, dof_at, seed=seed)
    # one branch, of the reference's own instantaneous mobility: the reference is regular (the
    # generic configuration fell near another singular point)
    regular = not e.undecided and [b.dimension for b in e.branches] == [dof_ref]
    return _Reference(not regular, dof_ref, e)


def mobility(mech: Mechanism, mode: Mode | str | None = None, *, seed: int = 0,
             tol: Tolerances | float | None = None) -> MobilityResult:
    """Mobility of ``mech`` (in ``mode`` for a metamorphic mechanism).

    ``tol``: the rank tolerance (a number) or a :class:`~spatialmech.geometry.tolerances.Tolerances`;
    default: the tolerances in force.  Every rank decision (the formula, the generic
    configuration, the instantaneous mobility, the motion type) uses it; the result also says
    how the count depends on it (:attr:`MobilityResult.dof_by_tolerance`).

    Raises ``ValueError`` when a metamorphic mechanism is given without a mode while its
    declared modes are several (use :func:`mobility_modes`).
    """
    t = resolve(tol, "rank")
    with use(t):
        return _mobility(mech, mode, seed, t)


def _mobility(mech: Mechanism, mode, seed: int, tols: Tolerances) -> MobilityResult:
    rtol = tols.rank
    if mode is None:
        modes = mech.all_modes()
        if len(modes) != 1:
            raise InputError(
                f"mode: {mech.name} is metamorphic with modes {', '.join(m.name for m in modes)}; name one"
            )
        mode = modes[0]
    if isinstance(mode, str) and not mech.is_metamorphic:
        mode = mech.mode(mode)  # KeyError naming the modes for an unknown name
    m = mech.in_mode(mode) if mech.is_metamorphic else mech
    mode_obj = m.modes[0] if m.modes else (mode if isinstance(mode, Mode) else Mode(str(mode), ()))
    L = m.characteristic_length
    ref = Configuration.reference(m)
    active = active_mask(m)
    tw = joint_twists(m, ref)
    if not all(np.all(np.isfinite(J)) for J in tw):
        raise ConvergenceError("mobility: the joint twists at the reference overflowed (NaN or infinity); "
                               "check the model's scale")
    limbs_T = []
    for sl, J in zip(limb_slices(m), tw, strict=True):
        a = active[sl]
        limbs_T.append(J[:, a].T)
    n, g, sum_f, f_limbs = _count_structure(m)
    As_ref, _, limb_cols = _scaled_closure(m, ref)
    h = hub_count(m)
    by_loops = m.is_graph

    def count(tt: float) -> _Counts:
        if by_loops:
            return _loop_formula(limbs_T, L, As_ref, limb_cols, h, n, g, sum_f, f_limbs, tt)
        return _formula(limbs_T, L, n, g, sum_f, f_limbs, tt)

    c = count(rtol)
    lam, d, t, k, v, xi, M, W, Wall, passive = c.lam, c.d, c.t, c.k, c.v, c.xi, c.M, c.W, c.Wall, c.passive
    gk = 6 * (n - g - 1) + sum_f

    # how the count depends on the rank tolerance
    names = [limb.name for limb in m.limbs]
    cands = _candidates(limbs_T, names, L, As_ref, limb_cols, Wall)
    steps = _scan(lambda tt: count(tt).M, cands)
    note = _tolerance_note(steps, rtol, M)

    if by_loops:  # the output link's free twists at the reference, and the wrenches reciprocal to them
        _, _, Vref = _instantaneous(m, ref, rtol)
        Wall = sc.reciprocal_basis(Vref, length_scale=L, rtol=rtol) if Vref.shape[0] else np.eye(6)
    else:  # the free platform twist system at the reference: reciprocal to all limb constraints
        Vref = sc.reciprocal_basis(Wall, length_scale=L, rtol=rtol)
    gen, dof_inst, Vgen, generic_note = _generic(m, ref, seed, rtol)
    sing = _reference_check(m, ref, gen, seed, rtol)
    where = "at a generic configuration"
    if sing.exploration is not None and sing.exploration.dimension is not None:  # the branches decided
        dof_inst = sing.exploration.dimension
        gen = sing.exploration.branches[0].sample if sing.exploration.branches else ref
        Vgen = _instantaneous(m, gen, rtol)[2] if dof_inst else np.zeros((0, 6))
        where = ("at the (isolated) reference" if not dof_inst else
                 "on the first branch through the singular reference" if sing.singular else "on the reference's branch")
        if not sing.singular:
            generic_note += (" (the generic configuration fell near another singular configuration; the "
                             "reference's own branch was followed instead)")
    if Vref.shape[0] == dof_inst and not sing.singular:
        motion, mclass = motion_type(Vref, m.platform_point, length_scale=L, rtol=rtol)
        axes = principal_screws(Vref, length_scale=L, rtol=rtol)
        where = "at the reference configuration"
    else:
        p_now = gen.D[:3, :3] @ m.platform_point + gen.D[:3, 3]
        motion, mclass = motion_type(Vgen, p_now, length_scale=L, rtol=rtol)
        axes = principal_screws(Vgen, length_scale=L, rtol=rtol)

    notes = []
    if gk != M:
        parts = [f"{lam} common constraint(s) (d = {d})" if lam else "",
                 f"{v} redundant constraint(s)" if v else "",
                 f"{xi} passive freedom(s)" if xi else ""]
        notes.append(
            f"The classic Grübler-Kutzbach count (d = 6, no corrections) gives {gk}; it ignores the "
            + ", ".join(p for p in parts if p) + " found from the screw systems."
        )
    if dof_inst != M:
        notes.append(
            f"The screw systems at the reference configuration give M = {M}, but the loop-closure "
            f"Jacobian at a generic configuration has instantaneous mobility {dof_inst}: the "
            "reference configuration is special (singular or a bifurcation), so the formula's "
            "counts there do not describe the finite motion."
        )
    if not notes:
        notes.append(f"The modified formula and the numerical rank agree: {M}.")
    wr = _canonical(sc.basis(Wall, length_scale=L, rtol=rtol), L) if Wall.size else np.zeros((0, 6))
    return MobilityResult(
        mechanism=mech.name,
        mode=mode_obj.name,
        actuators=m.actuators,
        dof=int(M),
        dof_instantaneous=int(dof_inst),
        gk_classic=int(gk),
        motion=motion,
        motion_class=mclass,
        lam=int(lam),
        d=int(d),
        n=int(n),
        g=int(g),
        sum_f=int(sum_f),
        t=int(t),
        k=int(k),
        v=int(v),
        xi=int(xi),
        limb_constraints=tuple(int(w.shape[0]) for w in W),
        constraint_wrenches=tuple(tuple(float(x) for x in w) for w in wr),
        agrees=bool(dof_inst == M),
        explanation=" ".join(notes) + f" Motion named {where}." + generic_note,
        passive=passive,
        loops=int(g - n + 1),
        counted_by="loops" if by_loops else "limbs",
        tolerance=float(rtol),
        dof_by_tolerance=steps,
        tolerance_note=note,
        reference_singular=sing.singular,
        dof_at_reference=sing.dof_ref,
        local_dof=(int(dof_inst) if sing.exploration is None else sing.exploration.dimension),
        branches=sing.exploration.branches if sing.exploration is not None and sing.singular else (),
        singular_note=sing.note(),
        undecided=sing.exploration.undecided if sing.exploration is not None else "",
        screw_axes=tuple(replace(a, length_unit=mech.length_unit) for a in axes),
    )


def mobility_modes(mech: Mechanism, *, seed: int = 0, tol: Tolerances | float | None = None) -> list[MobilityResult]:
    """Mobility of every mode (one element for a mechanism that is not metamorphic)."""
    return [mobility(mech, m, seed=seed, tol=tol) for m in mech.all_modes()]
