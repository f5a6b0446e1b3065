"""Forward position on the general closure engine: actuator values -> output-link pose(s).

- :func:`forward_position`: from a seed with a convergence status; ``all_solutions=True``
  searches many seeds (random walks along the closure manifold), deduplicates, follows singular
  roots along their self-motion, and says how it searched.
- :func:`forward_conditioning`: how well the actuators hold the output link at a configuration.
- :func:`locked_actuators`: the structure that holds the output link (actuators locked).

Actuator values are physical values (``offset + q``: a leg length, an angle in radians).
Inverse position and poses onto the manifold: :mod:`.position`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import InputError
from ..geometry.tolerances import MONODROMY_MAX_SOLUTIONS, MONODROMY_MAX_WORK
from ..geometry.tolerances import resolve as resolve_tolerances
from ..geometry import screws as sc
from ..model.mechanism import Mechanism, Pose
from ..results import EndPointStatus, Progress
from ..serialize import freedom_values_dict, pose_dict
from .closure import (
    Configuration,
    active_mask,
    closure_scales,
    hub_displacements,
    limb_chains,
    limb_slices,
    placed_configuration,
)
from .backend import closure_jacobian, correct, joint_twists
from .motion import generic_configuration
from .assembly import (
    AssemblyKind,
    Conditioning,
    SelfMotion,
    dedup_tolerances,
    group_roots,
    pose_keys,
    singular_threshold,
    trace_set,
)
from .tracking import MotionProblem

from .position import (
    cluster_newton,
    cluster_system,
    freedom_values,
    limb_clusters,
    limb_gauss_newton,
    platform_pose,
    random_joint_values,
    within_limits,
)

__all__ = [
    "FK_CONDITIONING_MEASURE",
    "ForwardResult",
    "ForwardSolution",
    "actuator_q",
    "forward_conditioning",
    "forward_position",
    "homotopy_coverage",
    "limbs_at",
    "locked_actuators",
]


@dataclass(frozen=True, eq=False)
class ForwardSolution:
    config: Configuration
    pose: Pose
    converged: bool
    residual: float
    iterations: int
    outside_limits: tuple[str, ...]
    conditioning: Conditioning | None = None  # of a converged root (None for a failed attempt)
    kind: AssemblyKind | None = None  # regular, singular or self-motion (None for a failed attempt)
    members: int = 1  # converged runs that this result stands for
    self_motion: SelfMotion | None = None  # the continuum traced through a self-motion result
    endpoint: str | None = None  # homotopy: status of the end point it came from (None: found by a multi-start)
    certified: bool | None = None  # homotopy: its certificate's verdict (None: not attempted; homotopy/certify.py)
    certificate: dict | None = None  # the certificate (box radius, real, reason)

    @property
    def singular(self) -> bool:
        return self.conditioning is not None and self.conditioning.singular

    def to_dict(self, mech: Mechanism) -> dict:
        """JSON (docs/json.md), the same fields as the closed forms' forward solutions: status,
        nondimensional closure ``residual``, the platform ``pose`` (position, named Euler angles
        in degrees, rotation matrix), limits, and the conditioning (:func:`forward_conditioning`:
        scale-free ``sigma_min``, ``condition`` = sigma_min / sigma_max, ``singular`` below
        ``singular_below``); ``kind`` (regular, singular, self-motion), ``members`` (converged
        runs standing for this result) and, for a self-motion, what its trace found."""
        c = self.conditioning
        return {
            "status": "converged" if self.converged else "not_converged",
            "converged": bool(self.converged),
            "iterations": int(self.iterations),
            "residual": float(self.residual),
            "pose": pose_dict(self.pose.R, self.pose.p),
            "within_limits": not self.outside_limits,
            "outside_limits": list(self.outside_limits),
            "sigma_min": c.sigma_min if c is not None else None,
            "singular": c.singular if c is not None else None,
            "condition": c.condition if c is not None else None,
            "singular_below": c.threshold if c is not None else None,
            "conditioning_measure": c.measure if c is not None else None,
            "kind": str(self.kind) if self.kind is not None else None,
            "members": self.members,
            "self_motion": self.self_motion.to_dict() if self.self_motion is not None else None,
            "certificate": self.certificate,
        }


@dataclass(frozen=True, eq=False)
class ForwardResult:
    solutions: tuple[ForwardSolution, ...]
    search: dict

    @property
    def converged(self) -> bool:
        return bool(self.solutions) and self.solutions[0].converged

    def to_dict(self, mech: Mechanism) -> dict:
        """JSON (docs/json.md), the same fields as the closed forms' (e.g.
        :meth:`..closed_forms.four_sps_cu.ForwardAllResult.to_dict`): the actuator values held,
        the converged solutions (or the failed attempt), and the search."""
        acts = {}
        if self.solutions:  # the actuators are held at their values in every solution
            vals = freedom_values(mech, self.solutions[0].config.q)
            acts = {r.id: float(vals[i]) for i, r in enumerate(mech.freedom_refs) if r.id in mech.actuators}
        sols = [s for s in self.solutions if s.converged] or list(self.solutions[:1])
        lift = _COMPLETENESS_KEYS if "endpoints" in self.search else _COMPLETENESS_KEYS[:2]
        names = {"seeds": "n_seeds", "converged_runs": "n_converged", "distinct": "n_distinct", "regular": "n_regular",
                 "singular": "n_singular", "self_motion_sets": "n_self_motion_sets"}  # as the closed forms
        return {
            "method": self.search.get("method", ""),
            **freedom_values_dict(mech, acts, "actuators"),
            "n_solutions": sum(s.converged for s in self.solutions),
            "n_within_limits": sum(s.converged and not s.outside_limits for s in self.solutions),
            "solutions": [s.to_dict(mech) for s in sols],
            **{k: self.search[k] for k in lift if k in self.search},
            "search": {names.get(k, k): v for k, v in self.search.items() if k not in lift},
        }


#: Search entries that ``ForwardResult.to_dict`` lifts to the top level of the JSON.
_COMPLETENESS_KEYS = ("complete", "completeness", "n_complex", "n_real", "n_singular", "n_at_infinity", "endpoints")


def actuator_q(mech: Mechanism, values) -> dict[int, float]:
    acts = list(mech.actuators)
    if isinstance(values, dict):
        items = {mech.freedom(k).id: float(v) for k, v in values.items()}
        missing = set(acts) - set(items)
        if missing:
            raise InputError(f"actuators: missing values for {sorted(missing)}")
        extra = set(items) - set(acts)
        if extra:
            raise InputError(f"actuators: {sorted(extra)} are not actuated in this mechanism (actuators: {acts})")
    else:
        vals = np.asarray(values, dtype=float).ravel()
        if vals.size != len(acts):
            raise InputError(f"actuators: expected {len(acts)} values ({', '.join(acts)}), got {vals.size}")
        items = dict(zip(acts, vals, strict=True))
    out = {}
    for k, v in items.items():
        if not np.isfinite(v):
            raise InputError(f"actuators: value of {k} is not finite")
        r = mech.freedom(k)
        out[mech.freedom_refs.index(r)] = v - r.freedom.offset
    return out


def _pose_seed(mech: Mechanism, rng: np.random.Generator, targets: dict[int, float]) -> Configuration:
    """A start for the assembly-mode search: a random platform pose (any orientation, position
    within a few characteristic lengths, mirrored through the base half of the time) with every
    limb solved for it in the least-squares sense from random joint values, its actuators held
    at their target values."""
    from scipy.spatial.transform import Rotation as _R

    from ..geometry.rotations import transform

    L = mech.characteristic_length
    p0 = mech.platform_point
    if rng.random() < 0.5:  # any orientation
        R = _R.random(random_state=int(rng.integers(2**31))).as_matrix()
    else:  # near the reference orientation (mirror-image modes keep it)
        R = _R.from_rotvec(rng.normal(scale=0.3, size=3)).as_matrix()
    p = p0 * (1 if rng.random() < 0.5 else -1) + rng.normal(scale=L, size=3)
    D = transform(R, p - R @ p0)
    q = np.zeros(len(mech.freedom_refs))
    if mech.bodies:  # a link-and-joint graph: random joint values, the bodies placed through the limbs
        for sl in limb_slices(mech):
            q[sl] = random_joint_values(mech, rng, sl, q[sl], np.zeros(sl.stop - sl.start, bool))
        for i, v in targets.items():
            q[i] = v
        if rng.random() < 0.25:  # the output placed through the limbs too
            return placed_configuration(mech, q)
        c = Configuration(q, D, hub_displacements(mech, q, D))
        for cl in limb_clusters(mech):  # each group of limbs fitted to the pose (least squares)
            _, _, rows, cols = cluster_system(mech, cl, held=targets)
            c = cluster_newton(mech, c, rows, cols, 1e-12, max_iter=30)[0]
        return c
    for ch, sl in zip(limb_chains(mech), limb_slices(mech), strict=True):
        refs = mech.freedom_refs[sl]
        lin = np.array([r.freedom.kind == "P" for r in refs])
        q0 = np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs)))
        hold = np.zeros(len(refs), bool)
        for i, v in targets.items():
            if sl.start <= i < sl.stop:
                q0[i - sl.start] = v
                hold[i - sl.start] = True
        q[sl] = limb_gauss_newton(ch, D, q0, lin, L, max_iter=30, hold=hold)[0]
    return Configuration(q, D)


#: What :func:`forward_conditioning` measures (stated in every forward-position result).
FK_CONDITIONING_MEASURE = (
    "singular values of the stacked orthonormal bases of the limbs' wrench systems with the actuators locked "
    "(moments / L): zero when the platform can move with the actuators held"
)


def forward_conditioning(mech: Mechanism, config: Configuration) -> Conditioning:
    """Whether the actuators hold the platform at ``config``: for every limb, an orthonormal
    basis of the screws reciprocal to its joint twists with the actuators locked (in
    nondimensional coordinates, moments / L), stacked; its smallest singular value is 0 exactly
    when a platform twist is compatible with every limb (a direct singularity; passive spins
    inside a limb do not count), and ``sigma_min / sigma_max`` is the inverse condition number.
    Where no actuator is serially singular this equals the scale-free ``sigma_min`` of the complete
    Jacobian (``kinematics.jacobian``)."""
    from ..geometry.tolerances import current

    rank_tol = current().rank
    if mech.bodies:
        return _graph_forward_conditioning(mech, config, rank_tol)
    L = mech.characteristic_length
    acts = set(mech.actuators)
    refs = mech.freedom_refs
    rows = []
    for T, sl in zip(joint_twists(mech, config), limb_slices(mech), strict=True):
        keep = [i - sl.start for i in range(sl.start, sl.stop) if not refs[i].freedom.locked and refs[i].id not in acts]
        if keep:
            _, sv, vt = np.linalg.svd(sc.nondimensional(T[:, keep].T, L), full_matrices=True)
            r = int(np.sum(sv > rank_tol * max(1.0, sv[0])))
            rows.append(vt[r:])
        else:
            rows.append(np.eye(6))
    C = np.vstack(rows)
    sv = np.linalg.svd(C, compute_uv=False) if C.shape[0] else np.zeros(0)
    return Conditioning.from_singular_values(sv, FK_CONDITIONING_MEASURE, n_required=6, threshold=singular_threshold())


def _graph_forward_conditioning(mech: Mechanism, config: Configuration, rank_tol: float) -> Conditioning:
    """:func:`forward_conditioning` of a mechanism with internal bodies: with the actuators
    locked, the part of the output link's columns of the nondimensional closure Jacobian that
    the other unknowns (passive joints, bodies) cannot absorb; its singular values equal those
    of the stacked limb wrench bases when every limb runs from the ground to the output."""
    mask = active_mask(mech)
    acts = set(mech.actuators)
    for i, r in enumerate(mech.freedom_refs):
        if r.id in acts:
            mask[i] = False
    A, _ = closure_jacobian(mech, config, active=mask)
    row, col = closure_scales(mech, mask)
    As = row[:, None] * A * col[None, :]
    na = int(mask.sum())
    out = As[:, na : na + 6]
    other = np.delete(As, np.s_[na : na + 6], axis=1)
    if other.shape[1]:
        U, sv, _ = np.linalg.svd(other, full_matrices=False)
        Q = U[:, : int(np.sum(sv > rank_tol * max(1.0, sv[0] if sv.size else 0.0)))]
        out = out - Q @ (Q.T @ out)
    sv = np.linalg.svd(out, compute_uv=False)
    return Conditioning.from_singular_values(sv, FK_CONDITIONING_MEASURE, n_required=6, threshold=singular_threshold())


def locked_actuators(mech: Mechanism, actuators=None) -> Mechanism:
    """``mech`` with its actuators (or the freedoms named in ``actuators``, by id or alias)
    locked and no longer actuated: the structure that must hold the platform (forward position's
    self-motions, the singularity analysis)."""
    ids = {mech.freedom(a).id for a in (actuators if actuators is not None else mech.actuators)}
    limbs = []
    for limb in mech.limbs:
        joints = []
        for j in limb.joints:
            for f in j.freedoms:
                if f"{j.name}.{f.name}" in ids:
                    j = j.with_freedom(f.name, locked=True, actuated=False)
            joints.append(j)
        limbs.append(limb.with_joints(joints))
    return replace(mech, limbs=tuple(limbs), modes=())


def _pose_key(mech: Mechanism, config: Configuration) -> np.ndarray:
    pose = platform_pose(mech, config)
    return pose_keys(pose.R, pose.p, mech.characteristic_length)


def _trace_self_motion(mech: Mechanism, locked: Mechanism, config: Configuration):
    """The solution set through a singular root, followed with the actuators held."""
    return trace_set(MotionProblem(locked), config, lambda c: _pose_key(mech, c), h0=0.05, h_max=0.3, max_steps=600)


def homotopy_coverage(mech: Mechanism) -> tuple[str | None, str | None]:
    """Which homotopy covers ``mech``'s forward position: ``(why, gwhy)``, why homotopy
    continuation in Study parameters does not (``None``: it does) and why the loop formulation
    by monodromy does not (``None``: it does; asked only when the first does not)."""
    from .homotopy import study as hc

    why = hc.unsupported_reason(mech)
    if why is None:
        return None, None
    from .homotopy import general as hg

    return why, hg.general_reason(mech)


def _fk_from(mech, config, targets, mask, max_iter, patience=None):
    q = config.q.copy()
    for i, v in targets.items():
        q[i] = v
    c = config.with_q(q)
    if patience is not None:  # abandon starts that are not converging after a few steps
        res = correct(mech, c, active=mask, max_iter=patience)
        if res.converged or res.residual > 1e-1:
            return res
        c = res.config
    return correct(mech, c, active=mask, max_iter=max_iter)


def forward_position(
    mech: Mechanism,
    actuator_values,
    *,
    start: Configuration | None = None,
    all_solutions: bool = False,
    n_seeds: int = 200,
    seed: int = 0,
    max_iter: int = 60,
    progress: Progress | None = None,
    method: str = "multistart",
) -> ForwardResult:
    """Platform pose(s) for given actuator values (physical units, in ``mech.actuators`` order
    or a dict by name).

    From ``start`` (default: the reference) by Gauss-Newton with the actuators held; with
    ``all_solutions``, also from ``n_seeds`` configurations reached by random walks along the
    closure manifold (actuators free).  Every converged root states its conditioning
    (:func:`forward_conditioning`) and its ``kind``: roots are distinct when their platform poses
    differ (scale-free pose distance, :mod:`spatialmech.kinematics.assembly`); a singular root
    is followed along its self-motion with the actuators held, and all roots on one such
    continuum are one result of kind ``self-motion`` (not many assembly modes).
    Non-converged runs are reported (``converged = False``), never returned as solutions of
    the all-solutions search.  ``progress(k, n_seeds, "assembly modes")`` after each start.

    ``method`` (with ``all_solutions``): ``"multistart"`` (the search above, never a proof of
    completeness), ``"homotopy"`` (every complex solution by homotopy continuation,
    :mod:`spatialmech.kinematics.homotopy`; limbs that reduce to quadrics in the Study parameters only, else
    ``InputError``) or
    ``"auto"`` (homotopy where it covers the model).  The homotopy's real end points are
    polished by the same Newton step and classified as the multi-start roots; the search then
    holds ``complete``, ``completeness`` and the counts of every end point's status.
    """
    if method not in ("multistart", "homotopy", "auto"):
        raise InputError(f"method: expected 'multistart', 'homotopy' or 'auto', got {method!r}")
    targets = actuator_q(mech, actuator_values)
    why: str | None = None  # why homotopy in Study parameters does not cover the model
    gwhy: str | None = None  # why the loop formulation (homotopy/general.py) does not cover the model
    if all_solutions and method != "multistart":
        why, gwhy = homotopy_coverage(mech)
        if why is None:
            return _forward_homotopy(mech, targets, seed, max_iter, n_seeds)
        if gwhy is None:
            gres = _forward_general(mech, targets, seed, max_iter, n_seeds, fallback=method == "auto")
            if gres is not None:
                return gres
            gwhy = (f"its monodromy gave up unsaturated (more than {MONODROMY_MAX_SOLUTIONS} solutions of the square system, "
                    f"or a work of {MONODROMY_MAX_WORK} tracker steps times unknowns); method='homotopy' runs it without "
                    "these caps")
        elif method == "homotopy":
            raise InputError(f"method: homotopy forward position does not cover {mech.name}: {why}; nor does the loop "
                             f"formulation: {gwhy}; use method='multistart'")
    if all_solutions and (int(n_seeds) != n_seeds or n_seeds < 1):
        raise InputError(f"n_seeds: expected a positive number of starts, got {n_seeds}")
    mask = active_mask(mech)
    for i in targets:
        mask[i] = False
    L = mech.characteristic_length
    first = _fk_from(mech, start or Configuration.reference(mech), targets, mask, max_iter)
    runs = [first]
    if all_solutions:
        runs += _multistart_runs(mech, targets, mask, n_seeds, seed, max_iter, progress)
    thr = singular_threshold()
    dedup, sdedup = dedup_tolerances()
    locked = locked_actuators(mech)
    if not all_solutions:
        r = first
        if not r.converged:  # the failed attempt, with the conditioning where it stopped
            sols = [ForwardSolution(r.config, platform_pose(mech, r.config), False, r.residual, r.iterations,
                                    tuple(within_limits(mech, r.config.q)), forward_conditioning(mech, r.config))]
        else:
            cond = forward_conditioning(mech, r.config)
            groups = group_roots(_pose_key(mech, r.config)[None, :], [cond.singular], [r.residual],
                                 lambda i: _trace_self_motion(mech, locked, r.config), dedup_tol=dedup,
                                 singular_dedup_tol=sdedup, free_dims=[cond.free_dim])
            g = groups[0]
            sols = [ForwardSolution(r.config, platform_pose(mech, r.config), True, r.residual, r.iterations,
                                    tuple(within_limits(mech, r.config.q)), cond, g.kind, 1,
                                    g.self_motion(np.atleast_2d(_pose_key(mech, r.config)), L))]
    else:
        conv = [r for r in runs if r.converged]
        keys = np.array([_pose_key(mech, r.config) for r in conv]).reshape(-1, 12)
        conds = [forward_conditioning(mech, r.config) for r in conv]
        groups = group_roots(keys, [c.singular for c in conds], [r.residual for r in conv],
                             lambda i: _trace_self_motion(mech, locked, conv[i].config), dedup_tol=dedup,
                             singular_dedup_tol=sdedup, prefer=[not within_limits(mech, r.config.q) for r in conv],
                             free_dims=[c.free_dim for c in conds])
        groups.sort(key=lambda g: min(g.members))  # in the order found (the start's own root first)
        sols = []
        for g in groups:
            r = conv[g.rep]
            sols.append(ForwardSolution(r.config, platform_pose(mech, r.config), True, r.residual, r.iterations,
                                        tuple(within_limits(mech, r.config.q)), conds[g.rep], g.kind, len(g.members),
                                        g.self_motion(keys, L)))
    kinds = [s.kind for s in sols if s.converged]
    search = {"method": "Gauss-Newton with the actuators held" + (", multi-start" if all_solutions else ""),
              "seeds": 1 + (n_seeds if all_solutions else 0), "seed": seed if all_solutions else None,
              "converged_runs": sum(r.converged for r in runs), "distinct": len(kinds),
              "n_regular": kinds.count(AssemblyKind.REGULAR), "n_singular": kinds.count(AssemblyKind.SINGULAR),
              "n_self_motion_sets": kinds.count(AssemblyKind.SELF_MOTION),
              "seeding": ("random platform poses with least-squares limb solutions, and random walks along the closure "
                          "manifold with the actuators free, alternately") if all_solutions else "start configuration",
              "distinct_by": (f"platform pose distance sqrt(|dp / L|^2 + (2 sin(theta / 2))^2): regular roots within "
                              f"{dedup:g} are one, isolated singular roots within {sdedup:g}; singular roots on one "
                              "self-motion traced with the actuators held are one result"),
              "singular_below": thr}
    if all_solutions:
        search["complete"] = False
        search["completeness"] = ("multi-start search: not a proof; assembly modes may be missing" +
                                  ("" if method == "multistart" else f" (homotopy does not cover {mech.name}: "
                                   f"{why}; nor does the loop formulation: {gwhy})"))
    return ForwardResult(tuple(sols), search)


def limbs_at(mech: Mechanism, D: np.ndarray, q0: np.ndarray, targets: dict[int, float], seed: int) -> Configuration:
    """Every limb solved for the platform displacement ``D`` with its actuator held at its value
    (from ``q0``, then from seeded random starts: an S-P-S leg also reaches its platform point
    reversed through its base, with the opposite slide)."""
    rng = np.random.default_rng(seed)
    L = mech.characteristic_length
    q = q0.copy()
    tol = resolve_tolerances(None).closure
    if mech.bodies:  # a link-and-joint graph: the bodies placed through the limbs, each group fitted together
        held = np.zeros(len(q), bool)
        held[list(targets)] = True
        best, rb = None, np.inf
        for attempt in range(12):
            if attempt:
                q = np.concatenate([random_joint_values(mech, rng, sl, q0[sl], held[sl]) for sl in limb_slices(mech)])
            c = Configuration(q, D, hub_displacements(mech, q, D))
            worst = 0.0
            for cl in limb_clusters(mech):
                _, _, rows, cols = cluster_system(mech, cl, held=targets)
                c, rn, _ = cluster_newton(mech, c, rows, cols, tol, max_iter=60)
                worst = max(worst, rn)
            if worst < rb:
                best, rb = c, worst
            if rb <= tol:
                break
        assert best is not None
        return best
    for ch, sl in zip(limb_chains(mech), limb_slices(mech), strict=True):
        refs = mech.freedom_refs[sl]
        lin = np.array([r.freedom.kind == "P" for r in refs])
        hold = np.array([sl.start + k in targets for k in range(len(refs))])
        best, rb, _ = limb_gauss_newton(ch, D, q[sl].copy(), lin, L, tol=tol, max_iter=100, hold=hold)
        for _ in range(24):
            if rb <= tol:
                break
            qs = np.where(hold, q[sl], np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs))))
            qt, rt, _ = limb_gauss_newton(ch, D, qs, lin, L, tol=tol, max_iter=100, hold=hold)
            if rt < rb:
                best, rb = qt, rt
        q[sl] = best
    return Configuration(q, D)


def _multistart_runs(mech: Mechanism, targets: dict[int, float], mask: np.ndarray, n_seeds: int, seed: int,
                     max_iter: int, progress: Progress | None = None) -> list:
    """Newton with the actuators held from ``n_seeds`` starts (alternately a random output pose
    with the limbs fitted, and a random walk along the closure manifold)."""
    rng = np.random.default_rng(seed)
    runs = []
    for s in range(n_seeds):
        if s % 2 == 0:
            c = _pose_seed(mech, rng, targets)
        else:
            try:
                c = generic_configuration(mech, seed=int(rng.integers(2**31)), step=float(rng.uniform(0.3, 1.2)), steps=4)
            except RuntimeError:
                continue
        runs.append(_fk_from(mech, c, targets, mask, max_iter, patience=12))
        if progress is not None:
            progress(s + 1, n_seeds, "assembly modes")
    return runs


def _forward_homotopy(mech: Mechanism, targets: dict[int, float], seed: int, max_iter: int,
                      n_seeds: int = 200) -> ForwardResult:
    """``forward_position(..., method="homotopy")``: the real end points polished with the
    actuators held, grouped and classified as the multi-start roots."""
    from ..geometry.rotations import transform
    from .homotopy import study as hc

    refs = mech.freedom_refs
    vals = [targets[refs.index(mech.freedom(a))] + mech.freedom(a).freedom.offset for a in mech.actuators]
    hr = hc.homotopy_forward(mech, vals, seed=seed)
    mask = active_mask(mech)
    for i in targets:
        mask[i] = False
    runs, origins = [], []
    q0 = np.zeros(len(refs))
    for i, v in targets.items():  # the slides start at their values (not the leg reversed through its base)
        q0[i] = v
    for e in hr.solutions:
        if e.R is None or e.p is None:
            continue
        D = transform(e.R, e.p)
        runs.append(_fk_from(mech, limbs_at(mech, D, q0, targets, seed), targets, mask, max_iter))
        origins.append(str(e.status))
    n_endpoint_runs = len(runs)
    if hr.count(EndPointStatus.SINGULAR):
        # singular end points (a continuum, as the 4-SPS/CU's self-motion at its home legs, or a
        # multiple root) are located to a few digits only: the multi-start search adds its roots,
        # and a singular root is followed along its self-motion and reported as one continuum
        runs += _multistart_runs(mech, targets, mask, n_seeds, seed, max_iter)
    sols, conv = _group_runs(mech, runs, origins)
    sols, cert = _certify_solutions(mech, vals, sols, hr)
    kinds = [s.kind for s in sols]
    extra = len(runs) - n_endpoint_runs
    search = {"method": "homotopy continuation (Study parameters), real end points polished by Newton"
                        + (f"; singular end points: {extra} multi-start seeds added" if extra else ""),
              "seeds": extra, "seed": seed, "converged_runs": len(conv), "distinct": len(kinds),
              "n_regular": kinds.count(AssemblyKind.REGULAR), "n_singular_roots": kinds.count(AssemblyKind.SINGULAR),
              "n_self_motion_sets": kinds.count(AssemblyKind.SELF_MOTION),
              "complete": hr.complete, "completeness": hr.completeness,
              "n_complex": hr.count(EndPointStatus.COMPLEX), "n_real": hr.count(EndPointStatus.REAL),
              "n_singular": hr.count(EndPointStatus.SINGULAR),
              "n_at_infinity": hr.count(EndPointStatus.AT_INFINITY), "n_generic": hr.n_generic,
              "n_paths": hr.n_paths_total_degree, "elapsed_s": hr.seconds, "generic_elapsed_s": hr.seconds_generic,
              "generic_cached": hr.cached, "endpoints": [e.to_dict() for e in hr.solutions],
              "singular_below": singular_threshold(), **cert}
    from .closed_forms.translational import translational_note

    if (note := translational_note(mech, vals, [s.pose for s in sols])) is not None:
        search["completeness"] = f"{search['completeness']}; {note}"
    return ForwardResult(tuple(sols), search)


def _certify_solutions(mech: Mechanism, vals, sols: list, hr) -> tuple[list, dict]:
    """Each converged solution certified as a root of the Study formulation's exact system at
    ``vals`` (its polished pose's Study parameters), together with the complex end points
    (:func:`.homotopy.certify.certify_forward`); the search fields ``n_certified``,
    ``certification``, ``certify_elapsed_s``.  Nothing when certification is off."""
    from time import perf_counter

    from .homotopy import certify as hcert
    from .homotopy.systems import pose_system

    if not hcert.enabled():
        return sols, {"n_certified": None, "certification": "not attempted (certification off)"}
    t0 = perf_counter()
    sysm = pose_system(mech)
    pts = [hcert.study_parameters(s.config.D, sysm.L) if s.converged else None for s in sols]
    cx = np.array([e.study for e in hr.solutions if e.status == EndPointStatus.COMPLEX]).reshape(-1, 8)
    certs, ccerts = hcert.certify_forward(sysm.coefficients(np.asarray(vals, dtype=float)), pts, cx)
    out = [s if c is None else replace(s, certified=c.certified, certificate=c.to_dict())
           for s, c in zip(sols, certs, strict=True)]
    return out, {"n_certified": hcert.n_certified([c for c in certs if c is not None]),
                 "n_certified_complex": hcert.n_certified(ccerts), "certification": hcert.statement(certs, ccerts),
                 "certify_elapsed_s": perf_counter() - t0}


def study_certificates(mech: Mechanism, vals, displacements: Sequence[np.ndarray | None]) -> list:
    """Certificates (:class:`.homotopy.certify.Certificate`, ``None`` where the displacement is
    ``None``) of platform displacements (4x4, model units) as real roots of the Study
    formulation's exact system at the actuator values ``vals`` (a model it covers): the
    certificates of a closed form's poses (the 4-SPS/CU's)."""
    from .homotopy import certify as hcert
    from .homotopy.systems import pose_system

    sysm = pose_system(mech)
    pts = [None if D is None else hcert.study_parameters(D, sysm.L) for D in displacements]
    return hcert.certify_forward(sysm.coefficients(np.asarray(vals, dtype=float)), pts, np.zeros((0, 8)))[0]


def _group_runs(mech: Mechanism, runs: list, origins: list[str] | None = None) -> tuple[list, list]:
    """The converged runs grouped into results (distinct poses, self-motions), in the order found;
    ``origins[i]`` the status of the homotopy end point that run ``i`` polished (the runs past
    them: a multi-start's), so that each result says the best end point it came from."""
    conv_idx = [i for i, r in enumerate(runs) if r.converged]
    conv = [runs[i] for i in conv_idx]
    origin = [origins[i] if origins is not None and i < len(origins) else None for i in conv_idx]
    dedup, sdedup = dedup_tolerances()
    locked = locked_actuators(mech)
    L = mech.characteristic_length
    keys = np.array([_pose_key(mech, r.config) for r in conv]).reshape(-1, 12)
    conds = [forward_conditioning(mech, r.config) for r in conv]
    groups = group_roots(keys, [c.singular for c in conds], [r.residual for r in conv],
                         lambda i: _trace_self_motion(mech, locked, conv[i].config), dedup_tol=dedup,
                         singular_dedup_tol=sdedup, prefer=[not within_limits(mech, r.config.q) for r in conv],
                         free_dims=[c.free_dim for c in conds])
    sols = []
    for g in sorted(groups, key=lambda g: min(g.members)):
        r = conv[g.rep]
        ends = {o for j in g.members if (o := origin[j]) is not None}
        end = "real" if "real" in ends else min(ends) if ends else None
        sols.append(ForwardSolution(r.config, platform_pose(mech, r.config), True, r.residual, r.iterations,
                                    tuple(within_limits(mech, r.config.q)), conds[g.rep], g.kind, len(g.members),
                                    g.self_motion(keys, L), end))
    return sols, conv


def _json_float(v: float) -> float | None:
    return float(v) if np.isfinite(v) else None


def _forward_general(mech: Mechanism, targets: dict[int, float], seed: int, max_iter: int,
                     n_seeds: int = 200, fallback: bool = False) -> ForwardResult | None:
    """``forward_position(..., method="homotopy")`` on a model whose limbs do not reduce to the
    Study-parameter quadrics: the loop formulation in joint variables solved by monodromy
    (:mod:`.homotopy.general`); each real end point is a configuration, polished by the same
    Newton step and grouped as the multi-start roots.  ``complete`` when the trace test of the
    generic solutions passed and every path to the request is accounted for."""
    from .homotopy import general as hg

    hr = hg.general_forward(mech, targets, seed=seed, capped=fallback)
    if fallback and not hr.saturated:  # method="auto": the multi-start instead
        return None
    mask = active_mask(mech)
    for i in targets:
        mask[i] = False
    runs = [_fk_from(mech, hg.configuration(e), targets, mask, max_iter) for e in hr.solutions if e.q is not None]
    origins = [str(e.status) for e in hr.solutions if e.q is not None]
    n_endpoint_runs = len(runs)
    # a continuum, a multiple root, or no proof: the multi-start adds its roots
    if hr.count(EndPointStatus.SINGULAR) or not hr.complete:
        runs += _multistart_runs(mech, targets, mask, n_seeds, seed, max_iter)
    sols, conv = _group_runs(mech, runs, origins)
    sols, cert = _certify_loop_solutions(mech, targets, sols)
    kinds = [s.kind for s in sols]
    extra = len(runs) - n_endpoint_runs
    why_more = "singular end points" if hr.count(EndPointStatus.SINGULAR) else "not proven complete"
    search = {"method": "homotopy continuation (loop closure in joint variables, monodromy), real end points polished "
                        "by Newton" + (f"; {why_more}: {extra} multi-start seeds added" if extra else ""),
              "seeds": extra, "seed": seed, "converged_runs": len(conv), "distinct": len(kinds),
              "n_regular": kinds.count(AssemblyKind.REGULAR), "n_singular_roots": kinds.count(AssemblyKind.SINGULAR),
              "n_self_motion_sets": kinds.count(AssemblyKind.SELF_MOTION),
              "complete": hr.complete,
              "completeness": hr.completeness + (f"; a {extra}-start multi-start search added its roots"
                                                 if extra and not hr.complete else ""),
              "n_complex": hr.count(EndPointStatus.COMPLEX), "n_real": hr.count(EndPointStatus.REAL),
              "n_singular": hr.count(EndPointStatus.SINGULAR),
              "n_at_infinity": hr.count(EndPointStatus.AT_INFINITY), "n_generic": hr.n_generic, "n_spurious": hr.n_spurious,
              "n_paths": hr.n_generic, "monodromy_loops": hr.loops, "elapsed_s": hr.seconds,
              "generic_elapsed_s": hr.seconds_generic, "generic_cached": hr.cached,
              "trace_test": hr.trace.verdict if hr.trace else "not run",
              "trace_deviation": _json_float(hr.trace.deviation) if hr.trace else None,
              "n_witness": hr.trace.n_witness if hr.trace else 0,
              "trace_elapsed_s": hr.trace.seconds if hr.trace else 0.0,
              "endpoints": [e.to_dict() for e in hr.solutions], "singular_below": singular_threshold(), **cert}
    return ForwardResult(tuple(sols), search)


def _certify_loop_solutions(mech: Mechanism, targets: dict[int, float], sols: list) -> tuple[list, dict]:
    """Each converged solution certified as a root of the loop formulation's square system at
    ``targets`` (:func:`.homotopy.certify_loops.certify_loop`); the search fields ``n_certified``,
    ``certification``, ``certify_elapsed_s``.  Nothing when certification is off."""
    from time import perf_counter

    from .homotopy import certify as hcert
    from .homotopy.certify_loops import certify_loop
    from .homotopy.loop_system import loop_system

    if not hcert.enabled():
        return sols, {"n_certified": None, "certification": "not attempted (certification off)"}
    t0 = perf_counter()
    sysm = loop_system(mech)
    idx = [i for i, s in enumerate(sols) if s.converged]
    certs = certify_loop(sysm, sysm.parameters(targets), [sols[i].config for i in idx])
    out = list(sols)
    for i, c in zip(idx, certs, strict=True):
        out[i] = replace(sols[i], certified=c.certified, certificate=c.to_dict())
    text = hcert.statement(certs).replace("root of the exact polynomial system", "root of the loop formulation's exact "
                                          "square system").replace(" of each, real, and", " of each (complex "
                                                                   "coefficients: not proven real), and")
    return out, {"n_certified": hcert.n_certified(certs), "certification": text,
                 "certify_elapsed_s": perf_counter() - t0}
