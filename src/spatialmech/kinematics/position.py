"""Position analysis on the general closure engine: inverse position and poses onto the manifold.

- :func:`inverse_position`: platform pose -> every limb's joint values; all real solutions
  (multi-start Gauss-Newton per limb, told apart in configuration space: :func:`solution_key`),
  with joint limits checked and positive-dimensional (passive) solution sets reported.
- forward position (actuator values -> platform pose) is in :mod:`.forward`.
- :func:`configuration_at_pose`: the closed configuration nearest to a given (possibly
  inexact, e.g. printed and rounded) platform pose, with the pose error it implies.

Actuator values are physical values (``offset + q``: a leg length, an angle in radians).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import InputError
from ..geometry.rotations import rotation_angle
from ..geometry.tolerances import Tolerances
from ..geometry.tolerances import resolve as resolve_tolerances
from ..model.mechanism import Mechanism, Pose
from ..serialize import fields_dict, freedom_values_dict, pose_dict
from .closure import (
    Configuration,
    active_mask,
    chain_forward,
    closure_scales,
    hub_displacements,
    limb_chains,
    limb_slices,
    recentre_balls,
)
from .backend import closure_jacobian, correct, retract
from .distinct import SolutionForm, limb_gauss_newton, limb_polish, same_solution, solution_form, solution_key, wrap_rotations

__all__ = [
    "INVERSE_METHODS",
    "InverseResult",
    "LimbSolutions",
    "PoseFit",
    "SolutionForm",
    "cluster_newton",
    "cluster_system",
    "configuration_at_pose",
    "freedom_values",
    "inverse_position",
    "limb_clusters",
    "limb_gauss_newton",
    "platform_pose",
    "random_joint_values",
    "same_solution",
    "solution_form",
    "solution_key",
    "within_limits",
    "wrap_rotations",
]


def platform_pose(mech: Mechanism, config: Configuration, name: str = "") -> Pose:
    """The platform pose ``(R, p)`` of a configuration."""
    return Pose.from_displacement(config.D, mech.platform_point, name=name)


def freedom_values(mech: Mechanism, q) -> np.ndarray:
    """Physical values ``offset + q`` of every freedom (m or rad)."""
    return np.array([r.freedom.offset for r in mech.freedom_refs]) + np.asarray(q, dtype=float)


def _in_range(value: float, lim, rotational: bool) -> bool:
    lo, hi = lim
    if lo <= value <= hi:
        return True
    if rotational:  # an angle also stands for its 2 pi equivalents
        k = np.round((0.5 * (lo + hi) - value) / (2 * np.pi))
        return lo <= value + 2 * np.pi * k <= hi
    return False


def within_limits(mech: Mechanism, q, indices=None) -> list[str]:
    """Ids of the freedoms (among ``indices``) whose value violates its limits."""
    vals = freedom_values(mech, q)
    bad = []
    for i, r in enumerate(mech.freedom_refs):
        if indices is not None and i not in indices:
            continue
        f = r.freedom
        if f.limits is not None and not _in_range(vals[i], f.limits, f.kind != "P"):
            bad.append(r.id)
    return bad


# ------------------------------------------------------------------------------ pose fit
@dataclass(frozen=True, eq=False)
class PoseFit:
    """A closed configuration fitted to a requested pose."""

    config: Configuration
    converged: bool
    exact: bool  # the requested pose itself closes (within tolerance)
    position_error: float  # platform point distance, length unit
    angle_error: float  # rad
    ik_residual: float  # nondimensional closure residual with the platform held at the request
    length_scale: float = 1.0  # the mechanism's characteristic length

    @property
    def error(self) -> float:
        """The pose error, nondimensional: the larger of ``position_error / length_scale`` and
        ``angle_error`` (rad); compared with the ``reachability`` tolerance."""
        return float(max(self.position_error / self.length_scale, self.angle_error))

    def to_dict(self) -> dict:
        """JSON (docs/json.md): ``position_error_len`` in the model's length unit, degrees."""
        return fields_dict(self, {"position_error": "position_error_len", "angle_error": "angle_error_deg",
                                  "error": "pose_error"},
                           names=("converged", "exact", "position_error", "angle_error", "ik_residual", "error"))


def configuration_at_pose(
    mech: Mechanism,
    pose: Pose,
    *,
    start: Configuration | None = None,
    tol: float | None = None,
    restart_tol: float = 1e-3,
    n_restarts: int = 12,
    seed: int = 0,
) -> PoseFit:
    """The closed configuration nearest to ``pose``.

    First every limb is solved with the platform held at the pose (least squares if the pose
    cannot be reached exactly, as with rounded printed data), from ``start`` (default: the
    reference); a limb whose residual stays above ``restart_tol`` (nondimensional) is solved
    again from ``n_restarts`` seeded random starts and the best kept (a start far from the pose
    can stop in a wrong local minimum).  Then the platform is released and the configuration
    corrected onto the closure manifold by minimum-norm steps.  The pose error between the
    request and the result is returned, never hidden.  ``tol``: the nondimensional residual at
    which a limb counts as closed (default: the ``closure`` tolerance in force).
    """
    tol = resolve_tolerances(None).closure if tol is None else float(tol)
    D = pose.displacement(mech.platform_point)
    L = mech.characteristic_length
    q = (start.q if start is not None else np.zeros(len(mech.freedom_refs))).astype(float).copy()
    rng = np.random.default_rng(seed)
    if mech.bodies:  # limbs that share bodies are solved together (see _inverse)
        inv = _inverse(mech, pose, False, n_restarts, seed, start, resolve_tolerances(tol, "closure"))
        for ls, sl in zip(inv.limbs, limb_slices(mech), strict=True):
            if ls.solutions:
                q[sl] = ls.solutions[0]
        c0 = inv.config if inv.config is not None else Configuration(q, D, hub_displacements(mech, q, D))
        return _fit_from(mech, pose, c0, tol, L)
    for ch, sl in zip(limb_chains(mech), limb_slices(mech), strict=True):
        refs = mech.freedom_refs[sl]
        lin = np.array([r.freedom.kind == "P" for r in refs])
        hold = np.array([r.freedom.locked for r in refs])
        qk, rn, _ = limb_gauss_newton(ch, D, q[sl].copy(), lin, L, tol=tol, max_iter=100, hold=hold)
        if rn > restart_tol:
            for _ in range(n_restarts):
                q0 = np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs)))
                q0 = np.where(hold, q[sl], q0)
                qt, rt, _ = limb_gauss_newton(ch, D, q0, lin, L, tol=tol, max_iter=100, hold=hold)
                if rt < rn:
                    qk, rn = qt, rt
        q[sl] = qk
    return _fit_from(mech, pose, Configuration(q, D), tol, L)


def _fit_from(mech: Mechanism, pose: Pose, c0: Configuration, tol: float, L: float) -> PoseFit:
    """Close ``c0`` with the platform held at ``pose`` (else released), and the pose error."""
    ik = correct(mech, c0, fix_platform=True, max_iter=100)
    res = ik if ik.converged else correct(mech, ik.config, max_iter=100)
    Dn = res.config.D
    p_got = Dn[:3, :3] @ mech.platform_point + Dn[:3, 3]
    ang = float(rotation_angle(Dn[:3, :3] @ pose.R.T))
    return PoseFit(res.config, res.converged, ik.converged and ik.residual < tol,
                   float(np.linalg.norm(p_got - pose.p)), ang, ik.residual, L)


# ------------------------------------------------------------------------------ inverse
@dataclass(frozen=True, eq=False)
class LimbSolutions:
    limb: str
    solutions: tuple[np.ndarray, ...]  # joint variables q of the limb's freedoms, one per solution
    residuals: tuple[float, ...]
    reachable: bool
    passive_dim: int  # dimension of the solution set (0: finitely many)
    violations: tuple[tuple[str, ...], ...]  # per solution, freedoms outside their limits
    #: per solution, its certificate (homotopy/certify.py: ``certified``, ``box_radius``, ...);
    #: empty when none was attempted
    certificates: tuple[dict, ...] = ()

    def to_dict(self, mech: Mechanism, first: int) -> dict:
        """JSON (docs/json.md): per solution the joint values by freedom id, rotations in
        ``joints_deg`` and slides in ``joints_len``; ``first`` is the limb's first freedom index;
        ``certified`` and ``certificate`` (``None`` when not attempted)."""
        refs = mech.freedom_refs
        sols = []
        certs = self.certificates or (None,) * len(self.solutions)
        for q, res, bad, cert in zip(self.solutions, self.residuals, self.violations, certs, strict=True):
            vals = {refs[first + j].id: refs[first + j].freedom.offset + qj for j, qj in enumerate(q)}
            sols.append({**freedom_values_dict(mech, vals, "joints"), "residual": float(res),
                         "within_limits": not bad, "outside_limits": list(bad),
                         "certified": None if cert is None else cert["certified"], "certificate": cert})
        return {"limb": self.limb, "reachable": bool(self.reachable), "passive_dim": int(self.passive_dim),
                "solutions": sols}


@dataclass(frozen=True, eq=False)
class InverseResult:
    pose: Pose
    limbs: tuple[LimbSolutions, ...]
    config: Configuration | None  # the first solution of every limb, when all are reachable
    search: dict = field(default_factory=dict)
    #: With ``fit=True``, for a pose that does not close exactly: the nearest closed configuration
    #: and how far it is (the solutions are then those of the fitted pose when it is within the
    #: ``reachability`` tolerance, :attr:`fitted`).
    pose_fit: PoseFit | None = None

    @property
    def reachable(self) -> bool:
        return all(l.reachable for l in self.limbs)

    @property
    def fitted(self) -> bool:
        """The pose was off the closure by less than the reachability tolerance: the solutions
        are those of the nearest closed pose (:attr:`pose_fit` says how far it is)."""
        return self.pose_fit is not None and self.reachable

    def actuator_values(self, mech: Mechanism) -> dict[str, float]:
        if self.config is None:
            raise InputError("pose: not reachable; no actuator values")
        vals = freedom_values(mech, self.config.q)
        return {r.id: float(vals[i]) for i, r in enumerate(mech.freedom_refs) if r.id in mech.actuators}

    def to_dict(self, mech: Mechanism) -> dict:
        """JSON (docs/json.md): the requested ``pose``, every limb's solutions, the actuator
        values of the first solution (``actuators_deg`` / ``actuators_len``, ``None`` when the
        pose is not reachable), how the search was made, and ``fitted`` / ``pose_fit``."""
        firsts = [sl.start for sl in limb_slices(mech)]
        acts = (freedom_values_dict(mech, self.actuator_values(mech), "actuators") if self.config is not None
                else {"actuators_deg": None, "actuators_len": None})
        # the same fields for every pose: pose_fit is None unless fit=True and the pose does not close exactly
        tried = [c["certified"] for limb in self.limbs for c in limb.certificates]
        return {"reachable": bool(self.reachable), "pose": pose_dict(self.pose.R, self.pose.p),
                "limbs": [l.to_dict(mech, f) for l, f in zip(self.limbs, firsts, strict=True)], **acts,
                "n_certified": sum(tried) if tried else None,
                "search": dict(self.search), "fitted": bool(self.fitted),
                "pose_fit": None if self.pose_fit is None else self.pose_fit.to_dict()}


def _violation(mech: Mechanism, sl: slice, q_limb) -> float:
    """How far a limb's values lie outside their limits (nondimensional: slides / L, angles in rad)."""
    L = mech.characteristic_length
    total = 0.0
    for r, q in zip(mech.freedom_refs[sl], q_limb, strict=True):
        f = r.freedom
        if f.limits is None:
            continue
        v = f.offset + q
        lo, hi = f.limits
        if f.kind != "P" and not lo <= v <= hi:  # an angle stands for its 2 pi equivalents
            k = np.round((0.5 * (lo + hi) - v) / (2 * np.pi))
            v = v + 2 * np.pi * k
        d = max(lo - v, v - hi, 0.0)
        total += d / L if f.kind == "P" else d
    return total


def inverse_position(
    mech: Mechanism,
    pose: Pose,
    *,
    all_solutions: bool = False,
    n_seeds: int = 48,
    seed: int = 0,
    start: Configuration | None = None,
    tol: Tolerances | float | None = None,
    fit: bool = False,
    method: str = "auto",
) -> InverseResult:
    """Joint values of every limb for a platform pose.

    Single solution: Gauss-Newton from ``start`` (default: the reference).  ``all_solutions``:
    also ``n_seeds`` random starts per limb; two solutions are one when every freedom agrees
    within the ``dedup`` tolerance (:func:`solution_key`: angles modulo 2 pi, slides, S joints
    by their rotation), so a half turn of any joint is another solution; solutions joined by
    a continuum (a passive spin) count once, and ``passive_dim > 0`` says the set is one.

    ``tol``: a :class:`~spatialmech.geometry.tolerances.Tolerances` or a number (the ``closure``
    residual at which a limb counts as solved); default: the tolerances in force.

    ``fit``: when the pose does not close exactly (a printed, rounded pose of a constrained
    mechanism), find the nearest closed configuration (:func:`configuration_at_pose`); if it
    is within the ``reachability`` tolerance (nondimensional: rad, and length / L) the pose is
    reachable and the solutions are those of the fitted pose; either way :attr:`InverseResult.pose_fit`
    says how far it is.

    ``method`` (with ``all_solutions``; :data:`INVERSE_METHODS`): ``"homotopy"``: every limb
    from the ground to the output link that :mod:`.homotopy.inverse` covers (R, P, C, U joints,
    helical ones of pitch 0, at most one S joint; finitely many solutions) by a parameter
    homotopy, with a completeness statement (proven by a root count or a trace test, or "NOT
    proven: <reason>"); the other limbs by the multi-start, labelled with the reason (a helical
    joint of nonzero pitch: transcendental; passive freedoms: a positive-dimensional solution
    set; limbs coupled through internal bodies).  ``"auto"``: the homotopy where it covers the
    limb and a known root count bounds its solutions (6R: 16; a 6R wrist-partitioned arm: 8; a
    3R placing a point: 4), or its generic solve is cached; else the multi-start, labelled with
    the reason (a proof there needs the trace test, tens of seconds per limb geometry: ask
    ``"homotopy"``).  ``"multistart"``: the multi-start for every limb.
    ``search["limbs"]`` reports, per limb, the method, ``complete`` and ``completeness``.
    """
    if method not in INVERSE_METHODS:
        raise InputError(f"method: {method!r} is not one of {', '.join(INVERSE_METHODS)}")
    t = resolve_tolerances(tol, "closure")
    res = _inverse(mech, pose, all_solutions, n_seeds, seed, start, t, method)
    if not fit or res.reachable:
        return res
    pf = configuration_at_pose(mech, pose, start=start, tol=t.closure)
    if pf.converged and pf.error <= t.reachability:
        fitted_pose = platform_pose(mech, pf.config, name=pose.name)
        res2 = _inverse(mech, fitted_pose, all_solutions, n_seeds, seed, pf.config, t, method)
        if res2.reachable:
            return replace(res2, pose=pose, pose_fit=pf,
                           search={**res2.search, "fitted": "the solutions are those of the nearest closed pose"})
    return replace(res, pose_fit=pf)


def limb_clusters(mech: Mechanism) -> list[list[int]]:
    """The limbs grouped by the internal bodies they share (:attr:`Mechanism.bodies`): with the
    output link held, each group closes on its own (a Delta arm with its R joint and its two
    rods).  A limb from the ground to the output link is a group of its own.  In limb order."""
    parent = list(range(len(mech.limbs)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    owner: dict[int, int] = {}
    for li, ends in enumerate(mech.limb_ends):
        for h in ends:
            if h is not None and h >= 1:
                if h in owner:
                    parent[find(li)] = find(owner[h])
                else:
                    owner[h] = li
    groups: dict[int, list[int]] = {}
    for li in range(len(mech.limbs)):
        groups.setdefault(find(li), []).append(li)
    return sorted(groups.values())


def _inverse(mech: Mechanism, pose: Pose, all_solutions: bool, n_seeds: int, seed: int,
             start: Configuration | None, t: Tolerances, method: str = "multistart") -> InverseResult:
    D = pose.displacement(mech.platform_point)
    rng = np.random.default_rng(seed)
    q_start = start.q if start is not None else np.zeros(len(mech.freedom_refs))
    out: list[LimbSolutions | None] = [None] * len(mech.limbs)
    q_all = np.zeros(len(mech.freedom_refs))
    B_all = hub_displacements(mech, q_start, D) if start is None else start.B.copy()
    all_ok = True
    clusters = []
    reports: list[dict] = [{}] * len(mech.limbs)
    for cl in limb_clusters(mech):
        if len(cl) == 1 and mech.limb_ends[cl[0]] == (None, 0):
            res_l, reports[cl[0]] = _solve_limb(mech, cl[0], D, q_start, q_all, all_solutions, n_seeds, rng, t, method, seed)
            out[cl[0]] = res_l
            all_ok &= res_l.reachable
        else:
            for i in cl:
                reports[i] = {"limb": mech.limbs[i].name, "method": "multistart", "complete": False,
                              "completeness": ("NOT proven: multi-start Gauss-Newton on limbs coupled through internal "
                                               "bodies (the homotopy covers a limb from the ground to the output link)")}
            sols, B_all = _inverse_cluster(mech, cl, D, q_start, q_all, B_all, all_solutions, n_seeds, rng, t)
            clusters.append({"limbs": [mech.limbs[i].name for i in cl],
                             "bodies": sorted({mech.hubs[h + 1] for i in cl for h in mech.limb_ends[i]
                                               if h is not None and h >= 1}),
                             "n_solutions": len(sols[0].solutions) if sols[0].reachable else 0})
            for i, ls in zip(cl, sols, strict=True):
                out[i] = ls
                all_ok &= ls.reachable
    config = Configuration(recentre_balls(mech, q_all), D, B_all) if all_ok else None
    search = {"method": "Gauss-Newton per limb", "starts_per_limb": 1 + (n_seeds if all_solutions else 0), "seed": seed,
              "tolerance": t.closure, "dedup_tol": t.dedup,
              "distinct_by": ("joint values: angles modulo 2 pi (2 sin(d / 2)), slides / L, S joints by their rotation; "
                              "solutions joined by a continuum (a passive spin) count once")}
    homotopy = any(r.get("method") == "homotopy" for r in reports)
    if homotopy:
        search["method"] = "homotopy continuation per limb (Gauss-Newton multi-start where it does not cover the limb)"
    if all_solutions:
        search["method_requested"] = method
        search["limbs"] = reports
        search["complete"] = all(r.get("complete", False) for r in reports)
    if clusters:
        search["clusters"] = clusters
        search["coupled"] = ("limbs that share an internal body are solved together with the body (Gauss-Newton on their "
                             "closure equations); their solutions correspond index by index")
    return InverseResult(pose, tuple(x for x in out if x is not None), config, search)


#: The values of ``inverse_position(method=...)``.
INVERSE_METHODS = ("auto", "homotopy", "multistart")


def _solve_limb(mech: Mechanism, li: int, D: np.ndarray, q_start: np.ndarray, q_all: np.ndarray, all_solutions: bool,
                n_seeds: int, rng: np.random.Generator, t: Tolerances, method: str, seed: int) -> tuple[LimbSolutions, dict]:
    """One limb from the ground to the output link: by the homotopy (:func:`_homotopy_limb`) when
    asked and it covers the limb, else by the multi-start; and its per-limb search report."""
    name = mech.limbs[li].name
    refused = closed = ""
    if all_solutions and method == "auto":
        done = _closed_form_limb(mech, li, D, q_start, q_all, t, seed)
        if isinstance(done, str):
            closed = done
        elif done is not None:
            return done
    if all_solutions and method != "multistart":
        from .homotopy.inverse import auto_reason, limb_inverse

        try:
            refused = (auto_reason(mech, li, seed) if method == "auto" else None) or ""
            if not refused:
                hres = limb_inverse(mech, li, D, seed=seed)
                ls, cert = _certify_limb(mech, li, D, _homotopy_limb(mech, li, D, q_start, q_all, hres, t), seed)
                return ls, {"limb": name, **hres.report(), **cert}
        except InputError as exc:
            refused = str(exc)
    res = _inverse_limb(mech, li, D, q_start, q_all, all_solutions, n_seeds, rng, t)
    starts = 1 + (n_seeds if all_solutions else 0)
    why = f"multi-start Gauss-Newton from {starts} start(s) (no completeness argument)"
    if res.passive_dim:
        why += f"; the solution set has dimension {res.passive_dim} (passive freedoms), the multi-start's path"
    if closed:
        why += f"; the closed form could not decide: {closed}"
    if refused:
        why += f"; the homotopy refused the limb: {refused}"
    rep: dict = {"limb": name, "method": "multistart", "complete": False, "completeness": f"NOT proven: {why}"}
    if refused:
        rep["homotopy_refused"] = refused
    return res, rep


def _homotopy_limb(mech: Mechanism, li: int, D: np.ndarray, q_start: np.ndarray, q_all: np.ndarray, hres,
                   t: Tolerances) -> LimbSolutions:
    """The homotopy's real solutions of a limb, polished by Gauss-Newton on the limb, checked
    against the closure tolerance and told apart (:func:`solution_key`), nearest the start
    ``q_start`` first (the order of the homotopy's paths is arbitrary; the multi-start's first
    solution is also the start's own); fills ``q_all`` with the first."""
    L = mech.characteristic_length
    ch, sl = limb_chains(mech)[li], limb_slices(mech)[li]
    lin = np.array([r.freedom.kind == "P" for r in mech.freedom_refs[sl]])
    form = solution_form(mech, li)
    sols: list[np.ndarray] = []
    res: list[float] = []
    keys: list[np.ndarray] = []
    for q0 in hres.solutions:
        q, rn, ok = limb_gauss_newton(ch, D, np.asarray(q0, float).copy(), lin, L, tol=t.closure)
        if not ok:
            continue
        q, rn = limb_polish(ch, D, q, lin, L, rn)
        q = wrap_rotations(mech, q, range(sl.start, sl.stop))
        key = solution_key(form, q)
        if any(np.linalg.norm(key - k2) < t.dedup for k2 in keys):
            continue
        keys.append(key)
        sols.append(q)
        res.append(rn)
    home = solution_key(form, q_start[sl])
    order = sorted(range(len(sols)), key=lambda k: (float(np.linalg.norm(keys[k] - home)), k))
    sols, res = [sols[k] for k in order], [res[k] for k in order]
    idx_l = set(range(sl.start, sl.stop))
    if sols:
        q_all[sl] = sols[0]
    viol = tuple(tuple(within_limits(mech, np.r_[q_all[: sl.start], s, q_all[sl.stop :]], indices=idx_l)) for s in sols)
    return LimbSolutions(mech.limbs[li].name, tuple(sols), tuple(float(r) for r in res), bool(sols), 0, viol)


def _closed_form_limb(mech: Mechanism, li: int, D: np.ndarray, q_start: np.ndarray, q_all: np.ndarray,
                      t: Tolerances, seed: int) -> tuple[LimbSolutions, dict] | str | None:
    """Every solution of a limb that a structure solves: a spherical 3R in closed form
    (:mod:`.closed_forms.spherical_3r_limb`), or a six-joint limb with a spherical wrist and a
    slide among its first three joints, decoupled (:mod:`.wrist_limb`); polished and ordered as
    the homotopy's.  ``None`` when neither covers the limb, the statement when it could not
    decide (a continuum, an unproven wrist-centre solve)."""
    from types import SimpleNamespace

    from . import wrist_limb
    from .closed_forms import spherical_3r_limb as s3r

    ch = limb_chains(mech)[li]
    L = mech.characteristic_length
    form = s3r.spherical_3r(mech, li, ch.screws)
    split = wrist_limb.wrist_split(mech, li) if form is None else None
    if form is not None:
        sols, statement, proven = s3r.solve(form, D, L)
    elif split is not None:
        sols, statement, proven = wrist_limb.solve(mech, li, split, D, seed)
    else:
        return None
    if not proven:
        return statement
    off = [float(np.linalg.norm(T[:3, :3] - D[:3, :3]) + np.linalg.norm(T[:3, 3] - D[:3, 3]) / L)
           for T in (chain_forward(ch, q)[0] for q in sols)]
    if off and max(off) > 1e-8:  # a root that does not close: say so, claim nothing
        return f"{statement}; but a root is {max(off):.2g} off the pose"
    ls = _homotopy_limb(mech, li, D, q_start, q_all, SimpleNamespace(solutions=sols), t)
    rep = {"limb": mech.limbs[li].name, "method": "closed-form" if form is not None else "decoupled",
           "complete": True, "completeness": statement, "n_real": len(ls.solutions)}
    if form is not None:
        return ls, {**rep, "n_certified": None,
                    "certification": "not attempted: a closed form (the limb has more equations than unknowns)"}
    ls, cert = _certify_limb(mech, li, D, ls, seed)
    return ls, {**rep, **cert}


_LIMB_SYSTEMS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()  # per model: {(limb, seed): LimbIK}


def _certify_limb(mech: Mechanism, li: int, D: np.ndarray, ls: LimbSolutions, seed: int) -> tuple[LimbSolutions, dict]:
    """The homotopy's polished solutions of limb ``li`` certified as roots of its exact system
    (:func:`.homotopy.certify.certify_inverse`), and the report's ``n_certified`` and
    ``certification``; nothing attempted when certification is off or the limb's system is not
    square."""
    from time import perf_counter

    from .homotopy import certify as hcert
    from .homotopy.inverse import limb_ik_system

    if not hcert.enabled():
        return ls, {"n_certified": None, "certification": "not attempted (certification off)"}
    t0 = perf_counter()
    key = (li, seed)
    systems = _LIMB_SYSTEMS.setdefault(mech, {})
    if key not in systems:
        systems[key] = limb_ik_system(mech, li, seed)
    certs = hcert.certify_inverse(systems[key], D, ls.solutions)
    if certs is None:
        return ls, {"n_certified": None, "certification": ("not attempted: the limb has more equations than unknowns "
                                                           "(its square system is a random combination of them)")}
    ls = replace(ls, certificates=tuple(c.to_dict() for c in certs))
    return ls, {"n_certified": hcert.n_certified(certs), "certification": hcert.statement(certs),
                "certify_elapsed_s": round(perf_counter() - t0, 4)}


def random_joint_values(mech: Mechanism, rng: np.random.Generator, sl: slice, keep: np.ndarray, held) -> np.ndarray:
    """Random joint values for the freedoms of ``sl`` (slides within +-L, angles within +-pi);
    freedoms in the ``held`` mask keep ``keep``."""
    refs = mech.freedom_refs[sl]
    lin = np.array([r.freedom.kind == "P" for r in refs])
    L = mech.characteristic_length
    qs = np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs)))
    return np.where(held, keep, qs)


def _limb_passive(chain, q, L: float, rank: float) -> int:
    _, J = chain_forward(chain, q)
    Jn = J * np.r_[np.ones(3), np.full(3, 1 / L)][:, None]
    sv = np.linalg.svd(Jn, compute_uv=False)
    return int(J.shape[1] - np.sum(sv > rank * max(1.0, sv[0] if sv.size else 0.0)))


def _inverse_limb(mech: Mechanism, li: int, D: np.ndarray, q_start: np.ndarray, q_all: np.ndarray,
                  all_solutions: bool, n_seeds: int, rng: np.random.Generator, t: Tolerances) -> LimbSolutions:
    """Every solution (or the one nearest the start) of a limb from the ground to the output
    link held at ``D``; fills ``q_all`` with the first."""
    tol = t.closure
    L = mech.characteristic_length
    ch, sl = limb_chains(mech)[li], limb_slices(mech)[li]
    refs = mech.freedom_refs[sl]
    lin = np.array([r.freedom.kind == "P" for r in refs])
    locked = np.array([r.freedom.locked for r in refs])
    starts = [q_start[sl].copy()]
    if all_solutions:
        starts += [random_joint_values(mech, rng, sl, q_start[sl], locked) for _ in range(n_seeds)]
    form = solution_form(mech, li)
    sols: list[np.ndarray] = []
    res: list[float] = []
    keys: list[np.ndarray] = []
    best = (None, np.inf)
    for q0 in starts:
        q, rn, ok = limb_gauss_newton(ch, D, q0.astype(float), lin, L, tol=tol)
        if not ok:
            if rn < best[1]:
                best = (q, rn)
            continue
        q, rn = limb_polish(ch, D, q, lin, L, rn)
        q = wrap_rotations(mech, q, range(sl.start, sl.stop))
        key = solution_key(form, q)
        if any(np.linalg.norm(key - k2) < t.dedup for k2 in keys):
            continue
        passive = _limb_passive(ch, q, L, t.rank)
        if passive and any(same_solution(form, q, key, q2, k2, t, passive) for q2, k2 in zip(sols, keys, strict=True)):
            continue
        keys.append(key)
        sols.append(q)
        res.append(rn)
    idx_l = set(range(sl.start, sl.stop))

    def _outside(qs):
        return within_limits(mech, np.r_[q_all[: sl.start], qs, q_all[sl.stop :]], indices=idx_l)

    if not all_solutions and sols and _outside(sols[0]):
        # the solution nearest the start violates a limit (e.g. a leg flipped through its base
        # joint far from the reference): prefer one within the limits, else the least violation
        best_v = _violation(mech, sl, sols[0])
        for _ in range(n_seeds):
            qs, rn, ok = limb_gauss_newton(ch, D, random_joint_values(mech, rng, sl, q_start[sl], locked), lin, L, tol=tol)
            if ok:
                qs = wrap_rotations(mech, qs, range(sl.start, sl.stop))
                v = _violation(mech, sl, qs)
                if v < best_v - 1e-12:
                    sols, res, best_v = [qs], [rn], v
                if v == 0.0:
                    break
    reachable = bool(sols)
    if not reachable:
        sols = [best[0]] if best[0] is not None else []
        res = [best[1]]
    passive = 0
    if sols:
        passive = _limb_passive(ch, sols[0], L, t.rank)
        q_all[sl] = sols[0]
    viol = tuple(tuple(_outside(s)) for s in sols)
    return LimbSolutions(mech.limbs[li].name, tuple(sols), tuple(float(r) for r in res), reachable, passive, viol)


def cluster_newton(mech: Mechanism, config: Configuration, rows: np.ndarray, cols: np.ndarray, tol: float,
                    max_iter: int = 60) -> tuple[Configuration, float, bool]:
    """Gauss-Newton on the closure equations ``rows`` in the unknowns ``cols`` (of the
    nondimensional closure system with every unlocked freedom active), output link held."""
    active = active_mask(mech)
    row, col = closure_scales(mech, active)
    rn = np.inf
    for _ in range(max_iter):
        A, r = closure_jacobian(mech, config, active=active)
        rr = (row * r)[rows]
        rn = float(np.linalg.norm(rr))
        if rn < tol:
            return config, rn, True
        if not np.isfinite(rn):
            break
        As = (row[:, None] * A * col[None, :])[np.ix_(rows, cols)]
        x, *_ = np.linalg.lstsq(As, -rr, rcond=None)
        if np.linalg.norm(x) < 1e-14:
            break
        step = np.zeros(len(col))
        step[cols] = col[cols] * x
        config = retract(mech, config, active, step, fix_platform=True)
    return config, rn, rn < tol


def cluster_system(mech: Mechanism, cl: list[int], held=()) -> tuple[np.ndarray, list[int], np.ndarray, np.ndarray]:
    """For a group of limbs: their freedoms' indices, the hub indices of their bodies, and the
    rows and columns of the closure system (every unlocked freedom active) that are theirs; the
    freedoms in ``held`` are not unknowns."""
    sls = limb_slices(mech)
    active = active_mask(mech)
    na = int(active.sum())
    pos = np.cumsum(active) - 1  # index of each active freedom among the active columns
    idx = np.concatenate([np.arange(sls[i].start, sls[i].stop) for i in cl])
    held = set(held)
    qcols = [int(pos[i]) for i in idx if active[i] and i not in held]
    bodies = sorted({h for i in cl for h in mech.limb_ends[i] if h is not None and h >= 1})
    bcols = [na + 6 * h + k for h in bodies for k in range(6)]
    rows = np.concatenate([np.arange(6 * i, 6 * i + 6) for i in cl])
    return idx, bodies, rows, np.array(qcols + bcols, dtype=int)


def _same_cluster_solution(forms: dict[int, SolutionForm], cl: list[int], sls: list[slice], q: np.ndarray,
                           kb: np.ndarray, kl: list[np.ndarray], q2: np.ndarray,
                           k2: tuple[np.ndarray, list[np.ndarray]], t: Tolerances) -> bool:
    """Two solutions of a group of limbs are one when the shared bodies' poses agree and every
    limb's solutions are one (:func:`same_solution`: passive spins of a rod count once)."""
    if np.linalg.norm(kb - k2[0]) >= t.dedup:
        return False
    for i, ka, kb2 in zip(cl, kl, k2[1], strict=True):
        if np.linalg.norm(ka - kb2) < t.dedup:
            continue
        f = forms[i]
        passive = _limb_passive(f.chain, q[sls[i]], f.L, t.rank)
        if not same_solution(f, q[sls[i]], ka, q2[sls[i]], kb2, t, passive):
            return False
    return True


def _inverse_cluster(mech: Mechanism, cl: list[int], D: np.ndarray, q_start: np.ndarray, q_all: np.ndarray,
                     B_all: np.ndarray, all_solutions: bool, n_seeds: int, rng: np.random.Generator,
                     t: Tolerances) -> tuple[list[LimbSolutions], np.ndarray]:
    """Solutions of a group of limbs that share internal bodies (:func:`limb_clusters`), the
    output link held at ``D``: Newton on their closure equations in their joint variables and
    the bodies' twists, from the start and (``all_solutions``, or when the start fails) from
    random joint values with the bodies placed through the limbs.  Fills ``q_all`` (and returns
    the bodies' displacements) with the first solution."""
    L = mech.characteristic_length
    sls = limb_slices(mech)
    locked = ~active_mask(mech)
    idx, bodies, rows, cols = cluster_system(mech, cl)
    found: list[tuple[np.ndarray, np.ndarray, float]] = []  # (q, B, residual)
    keys: list[tuple[np.ndarray, list[np.ndarray]]] = []  # (the bodies' poses, each limb's solution_key)
    forms = {i: solution_form(mech, i) for i in cl}
    best: tuple[np.ndarray | None, np.ndarray | None, float] = (None, None, np.inf)
    n_starts = 1 + n_seeds
    for s in range(n_starts):
        q0 = q_all.copy()
        q0[idx] = q_start[idx]
        if s > 0:
            for i in cl:
                q0[sls[i]] = random_joint_values(mech, rng, sls[i], q_start[sls[i]], locked[sls[i]])
        B0 = B_all.copy()
        for h in bodies:
            B0[h - 1] = np.nan
        c0 = Configuration(q0, D, hub_displacements(mech, q0, D, B0))
        c, rn, ok = cluster_newton(mech, c0, rows, cols, t.closure)
        if not ok:
            if rn < best[2]:
                best = (c.q, c.B, rn)
        else:
            q = c.q.copy()
            q[idx] = wrap_rotations(mech, q[idx], idx)
            kb = np.concatenate([np.r_[c.B[h - 1][:3, :3].ravel(), c.B[h - 1][:3, 3] / L] for h in bodies])
            kl = [solution_key(forms[i], q[sls[i]]) for i in cl]
            if not any(_same_cluster_solution(forms, cl, sls, q, kb, kl, f[0], k2, t)
                       for f, k2 in zip(found, keys, strict=True)):
                keys.append((kb, kl))
                found.append((q, c.B, rn))
        if found and not all_solutions:
            break
    reachable = bool(found)
    if not reachable:
        found = [(best[0], best[1], best[2])] if best[0] is not None and best[1] is not None else []
    if found:
        q_first, B_first, _ = found[0]
        q_all[idx] = q_first[idx]
        B_all = B_all.copy()
        for h in bodies:
            B_all[h - 1] = B_first[h - 1]
    out = []
    for i in cl:
        sl = sls[i]
        sols = tuple(q[sl] for q, _, _ in found)
        viol = tuple(tuple(within_limits(mech, np.r_[q_all[: sl.start], qs, q_all[sl.stop :]],
                                         indices=set(range(sl.start, sl.stop)))) for qs in sols)
        passive = _limb_passive(limb_chains(mech)[i], sols[0], L, t.rank) if sols else 0
        out.append(LimbSolutions(mech.limbs[i].name, sols, tuple(float(r) for _, _, r in found), reachable, passive, viol))
    return out, B_all


# ------------------------------------------------------------------------------ forward
