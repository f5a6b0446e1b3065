"""Position analysis on the general closure engine: inverse, forward, and poses onto the manifold.

- :func:`inverse_position`: platform pose -> every limb's joint values; all real solutions
  (multi-start Gauss-Newton per limb, deduplicated by the limb's joint geometry), with joint
  limits checked and positive-dimensional (passive) solution sets reported.
- :func:`forward_position`: actuator values -> platform pose from a seed with a convergence
  status; ``all_solutions=True`` searches many seeds (random walks along the closure manifold)
  and deduplicates, and says how it searched.
- :func:`configuration_at_pose`: the closed configuration nearest to a given (possibly
  inexact, e.g. printed and rounded) platform pose, with the pose error it implies.

Actuator values are physical values (``offset + q``: a leg length, an angle in radians).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial.transform import Rotation

from ..geometry.rotations import inverse_transform, log_transform, rotation_angle
from ..model.mechanism import Mechanism, Pose
from .closure import (
    Configuration,
    active_mask,
    chain_forward,
    correct,
    generic_configuration,
    joint_points,
    limb_chains,
    limb_slices,
    recentre_balls,
)

__all__ = [
    "PoseFit",
    "configuration_at_pose",
    "LimbSolutions",
    "InverseResult",
    "inverse_position",
    "ForwardSolution",
    "ForwardResult",
    "forward_position",
    "freedom_values",
    "within_limits",
    "platform_pose",
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

    def to_dict(self) -> dict:
        return {
            "converged": self.converged,
            "exact": self.exact,
            "position_error": self.position_error,
            "angle_error_deg": float(np.degrees(self.angle_error)),
            "ik_residual": self.ik_residual,
        }


def configuration_at_pose(
    mech: Mechanism,
    pose: Pose,
    *,
    start: Configuration | None = None,
    tol: float = 1e-10,
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
    request and the result is returned, never hidden.
    """
    D = pose.displacement(mech.platform_point)
    L = mech.characteristic_length
    q = (start.q if start is not None else np.zeros(len(mech.freedom_refs))).astype(float).copy()
    rng = np.random.default_rng(seed)
    for ch, sl in zip(limb_chains(mech), limb_slices(mech)):
        refs = mech.freedom_refs[sl]
        lin = np.array([r.freedom.kind == "P" for r in refs])
        hold = np.array([r.freedom.locked for r in refs])
        qk, rn, _ = _limb_gn(ch, D, q[sl].copy(), lin, L, tol=tol, max_iter=100, hold=hold)
        if rn > restart_tol:
            for _ in range(n_restarts):
                q0 = np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs)))
                q0 = np.where(hold, q[sl], q0)
                qt, rt, _ = _limb_gn(ch, D, q0, lin, L, tol=tol, max_iter=100, hold=hold)
                if rt < rn:
                    qk, rn = qt, rt
        q[sl] = qk
    ik = correct(mech, Configuration(q, D), fix_platform=True, max_iter=100)
    res = ik if ik.converged else correct(mech, ik.config, max_iter=100)
    Dn = res.config.D
    p_got = Dn[:3, :3] @ mech.platform_point + Dn[:3, 3]
    ang = float(rotation_angle(Dn[:3, :3] @ pose.R.T))
    return PoseFit(res.config, res.converged, ik.converged and ik.residual < tol,
                   float(np.linalg.norm(p_got - pose.p)), ang, ik.residual)


# ------------------------------------------------------------------------------ inverse
@dataclass(frozen=True, eq=False)
class LimbSolutions:
    limb: str
    solutions: tuple[np.ndarray, ...]  # joint variables q of the limb's freedoms, one per solution
    residuals: tuple[float, ...]
    reachable: bool
    passive_dim: int  # dimension of the solution set (0: finitely many)
    violations: tuple[tuple[str, ...], ...]  # per solution, freedoms outside their limits

    def to_dict(self, mech: Mechanism, first: int) -> dict:
        refs = mech.freedom_refs
        sols = []
        for q, res, bad in zip(self.solutions, self.residuals, self.violations):
            vals = {}
            for j, qj in enumerate(q):
                r = refs[first + j]
                v = r.freedom.offset + qj
                vals[r.id] = float(np.degrees(v)) if r.freedom.kind != "P" else float(v)
            sols.append({"values": vals, "residual": res, "outside_limits": list(bad)})
        return {"limb": self.limb, "reachable": self.reachable, "passive_dim": self.passive_dim,
                "solutions": sols, "units": "rotations in degrees, slides in length units"}


@dataclass(frozen=True, eq=False)
class InverseResult:
    pose: Pose
    limbs: tuple[LimbSolutions, ...]
    config: Configuration | None  # the first solution of every limb, when all are reachable
    search: dict = field(default_factory=dict)

    @property
    def reachable(self) -> bool:
        return all(l.reachable for l in self.limbs)

    def actuator_values(self, mech: Mechanism) -> dict[str, float]:
        if self.config is None:
            raise ValueError("pose: not reachable; no actuator values")
        vals = freedom_values(mech, self.config.q)
        return {r.id: float(vals[i]) for i, r in enumerate(mech.freedom_refs) if r.id in mech.actuators}

    def to_dict(self, mech: Mechanism) -> dict:
        firsts = [sl.start for sl in limb_slices(mech)]
        d = {"reachable": self.reachable, "limbs": [l.to_dict(mech, f) for l, f in zip(self.limbs, firsts)],
             "search": self.search}
        if self.config is not None:
            d["actuators"] = {k: (float(np.degrees(v)) if mech.freedom(k).freedom.kind != "P" else v)
                              for k, v in self.actuator_values(mech).items()}
        return d


def _violation(mech: Mechanism, sl: slice, q_limb) -> float:
    """How far a limb's values lie outside their limits (nondimensional: slides / L, angles in rad)."""
    L = mech.characteristic_length
    total = 0.0
    for r, q in zip(mech.freedom_refs[sl], q_limb):
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


def _limb_gn(chain, D, q, lin, L, tol=1e-12, max_iter=60, hold=None):
    """Gauss-Newton for one limb with the platform held at ``D``, in local coordinates (S
    joints updated by composing rotations); freedoms in the ``hold`` mask keep their value."""
    Dinv = inverse_transform(D)
    colscale = np.where(lin, L, 1.0)
    if hold is not None:
        colscale = np.where(hold, 0.0, colscale)
    row = np.r_[np.ones(3), np.full(3, 1.0 / L)]
    rn = np.inf
    for _ in range(max_iter):
        T, J = chain_forward(chain, q, local=True)
        r = log_transform(T @ Dinv)
        rn = float(np.linalg.norm(row * r))
        if rn < tol:
            return q, rn, True
        x, *_ = np.linalg.lstsq(row[:, None] * J * colscale[None, :], -(row * r), rcond=None)
        if np.linalg.norm(x) < 1e-14:
            break
        dq = colscale * x
        q_new = q + dq
        for k, _, A in chain.balls:
            sl = slice(k, k + 3)
            q_new[sl] = A.T @ (Rotation.from_rotvec(A @ dq[sl]) * Rotation.from_rotvec(A @ q[sl])).as_rotvec()
        q = q_new
    return q, rn, rn < tol


def _signature(chain, q, L) -> np.ndarray:
    """Geometry of a limb's solution, nondimensional: every one-freedom joint's line (its twist
    up to sign, so a universal joint's flipped cross (t1 + pi, pi - t2) counts once) and every
    S joint's centre (its axes are a parametrisation, not geometry)."""
    _, J, pre = chain_forward(chain, q, prefixes=True, local=True)
    scale = np.r_[np.ones(3), np.full(3, 1.0 / L)]
    ball = {k: c for k, c, _ in chain.balls}
    parts = []
    i = 0
    while i < J.shape[1]:
        if i in ball:
            c = ball[i]
            parts.append((pre[i, :3, :3] @ c + pre[i, :3, 3]) / L)
            i += 3
            continue
        col = J[:, i] * scale
        lead = int(np.argmax(np.abs(col) > 1e-9))
        parts.append(col * (np.sign(col[lead]) or 1.0))
        i += 1
    return np.concatenate(parts)


def wrap_rotations(mech: Mechanism, q, indices=None) -> np.ndarray:
    """Joint variables with every rotation's value ``offset + q`` wrapped to (-pi, pi]
    (S joints keep their rotation vectors)."""
    q = np.array(q, dtype=float, copy=True)
    refs = mech.freedom_refs
    idx = range(len(q)) if indices is None else indices
    for k, i in enumerate(idx):
        r = refs[i]
        if r.freedom.kind == "R" and mech.limbs[r.limb].joints[r.joint].type != "S":
            v = r.freedom.offset + q[k]
            q[k] = (v + np.pi) % (2 * np.pi) - np.pi - r.freedom.offset
            if q[k] + r.freedom.offset <= -np.pi:
                q[k] += 2 * np.pi
    return q


def inverse_position(
    mech: Mechanism,
    pose: Pose,
    *,
    all_solutions: bool = False,
    n_seeds: int = 48,
    seed: int = 0,
    start: Configuration | None = None,
    tol: float = 1e-10,
) -> InverseResult:
    """Joint values of every limb for a platform pose.

    Single solution: Gauss-Newton from ``start`` (default: the reference).  ``all_solutions``:
    also ``n_seeds`` random starts per limb; solutions are distinct when the limb's joint
    twists differ (so passive spins, which leave the geometry unchanged up to that freedom,
    are not counted twice); ``passive_dim > 0`` says the solution set is a continuum.
    """
    D = pose.displacement(mech.platform_point)
    L = mech.characteristic_length
    rng = np.random.default_rng(seed)
    q_start = start.q if start is not None else np.zeros(len(mech.freedom_refs))
    out = []
    q_all = np.zeros(len(mech.freedom_refs))
    all_ok = True
    for li, (ch, sl) in enumerate(zip(limb_chains(mech), limb_slices(mech))):
        refs = mech.freedom_refs[sl]
        lin = np.array([r.freedom.kind == "P" for r in refs])
        locked = np.array([r.freedom.locked for r in refs])
        starts = [q_start[sl].copy()]
        if all_solutions:
            for _ in range(n_seeds):
                qs = np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs)))
                starts.append(np.where(locked, q_start[sl], qs))
        sols, res, sigs = [], [], []
        best = (None, np.inf)
        for q0 in starts:
            q, rn, ok = _limb_gn(ch, D, q0.astype(float), lin, L, tol=tol)
            if not ok:
                if rn < best[1]:
                    best = (q, rn)
                continue
            q = wrap_rotations(mech, q, range(sl.start, sl.stop))
            sig_n = _signature(ch, q, L)
            if any(np.linalg.norm(sig_n - s2) < 1e-6 for s2 in sigs):
                continue
            sigs.append(sig_n)
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
                qs0 = np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs)))
                qs, rn, ok = _limb_gn(ch, D, np.where(locked, q_start[sl], qs0), lin, L, tol=tol)
                if ok:
                    qs = wrap_rotations(mech, qs, range(sl.start, sl.stop))
                    v = _violation(mech, sl, qs)
                    if v < best_v - 1e-12:
                        sols, res, best_v = [qs], [rn], v
                    if v == 0.0:
                        break
        reachable = bool(sols)
        if not reachable:
            all_ok = False
            sols = [best[0]] if best[0] is not None else []
            res = [best[1]]
        passive = 0
        if sols:
            _, J = chain_forward(ch, sols[0])
            passive = int(J.shape[1] - np.linalg.matrix_rank(J * np.r_[np.ones(3), np.full(3, 1 / L)][:, None], tol=1e-9))
            q_all[sl] = sols[0]
        idx = range(sl.start, sl.stop)
        viol = tuple(tuple(within_limits(mech, np.r_[q_all[: sl.start], s, q_all[sl.stop :]], indices=set(idx))) for s in sols)
        out.append(LimbSolutions(mech.limbs[li].name, tuple(sols), tuple(float(r) for r in res), reachable, passive, viol))
    config = Configuration(recentre_balls(mech, q_all), D) if all_ok else None
    search = {"method": "Gauss-Newton per limb", "starts_per_limb": 1 + (n_seeds if all_solutions else 0), "seed": seed,
              "tolerance": tol, "distinct_by": "joint twists (axis placement) of the limb"}
    return InverseResult(pose, tuple(out), config, search)


# ------------------------------------------------------------------------------ forward
@dataclass(frozen=True, eq=False)
class ForwardSolution:
    config: Configuration
    pose: Pose
    converged: bool
    residual: float
    iterations: int
    outside_limits: tuple[str, ...]

    def to_dict(self, mech: Mechanism) -> dict:
        from ..geometry.rotations import matrix_euler

        return {
            "converged": self.converged,
            "residual": self.residual,
            "iterations": self.iterations,
            "position": self.pose.p.tolist(),
            "rotation_matrix": self.pose.R.tolist(),
            "euler_ZYX_deg": matrix_euler("ZYX", self.pose.R, degrees=True).tolist(),
            "outside_limits": list(self.outside_limits),
            "within_limits": not self.outside_limits,
        }


@dataclass(frozen=True, eq=False)
class ForwardResult:
    solutions: tuple[ForwardSolution, ...]
    search: dict

    @property
    def converged(self) -> bool:
        return bool(self.solutions) and self.solutions[0].converged

    def to_dict(self, mech: Mechanism) -> dict:
        return {"solutions": [s.to_dict(mech) for s in self.solutions], "search": self.search}


def _actuator_q(mech: Mechanism, values) -> dict[int, float]:
    acts = list(mech.actuators)
    if isinstance(values, dict):
        items = {mech.freedom(k).id: float(v) for k, v in values.items()}
        missing = set(acts) - set(items)
        if missing:
            raise ValueError(f"actuators: missing values for {sorted(missing)}")
        extra = set(items) - set(acts)
        if extra:
            raise ValueError(f"actuators: {sorted(extra)} are not actuated in this mechanism (actuators: {acts})")
    else:
        vals = np.asarray(values, dtype=float).ravel()
        if vals.size != len(acts):
            raise ValueError(f"actuators: expected {len(acts)} values ({', '.join(acts)}), got {vals.size}")
        items = dict(zip(acts, vals))
    out = {}
    for k, v in items.items():
        if not np.isfinite(v):
            raise ValueError(f"actuators: value of {k} is not finite")
        r = mech.freedom(k)
        out[mech.freedom_refs.index(r)] = v - r.freedom.offset
    return out


def _pose_seed(mech: Mechanism, rng: np.random.Generator, targets: dict[int, float]) -> Configuration:
    """A start for the assembly-mode search: a random platform pose (any orientation, position
    within a few characteristic lengths, mirrored through the base half of the time) with every
    limb solved for it in the least-squares sense from random joint values, its actuators held
    at their target values."""
    from ..geometry.rotations import transform
    from scipy.spatial.transform import Rotation as _R

    L = mech.characteristic_length
    p0 = mech.platform_point
    if rng.random() < 0.5:  # any orientation
        R = _R.random(random_state=int(rng.integers(2**31))).as_matrix()
    else:  # near the reference orientation (mirror-image modes keep it)
        R = _R.from_rotvec(rng.normal(scale=0.3, size=3)).as_matrix()
    p = p0 * (1 if rng.random() < 0.5 else -1) + rng.normal(scale=L, size=3)
    D = transform(R, p - R @ p0)
    q = np.zeros(len(mech.freedom_refs))
    for ch, sl in zip(limb_chains(mech), limb_slices(mech)):
        refs = mech.freedom_refs[sl]
        lin = np.array([r.freedom.kind == "P" for r in refs])
        q0 = np.where(lin, rng.uniform(-1, 1, len(refs)) * L, rng.uniform(-np.pi, np.pi, len(refs)))
        hold = np.zeros(len(refs), bool)
        for i, v in targets.items():
            if sl.start <= i < sl.stop:
                q0[i - sl.start] = v
                hold[i - sl.start] = True
        q[sl] = _limb_gn(ch, D, q0, lin, L, max_iter=30, hold=hold)[0]
    return Configuration(q, D)


def _fk_from(mech, config, targets, mask, max_iter, patience=None):
    q = config.q.copy()
    for i, v in targets.items():
        q[i] = v
    c = Configuration(q, config.D)
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
    progress=None,
) -> ForwardResult:
    """Platform pose(s) for given actuator values (physical units, in ``mech.actuators`` order
    or a dict by name).

    From ``start`` (default: the reference) by Gauss-Newton with the actuators held; with
    ``all_solutions``, also from ``n_seeds`` configurations reached by random walks along the
    closure manifold (actuators free), deduplicated by the joint points of every limb.
    Non-converged runs are reported (``converged = False``), never returned as solutions of
    the all-solutions search.
    """
    targets = _actuator_q(mech, actuator_values)
    if all_solutions and (int(n_seeds) != n_seeds or n_seeds < 1):
        raise ValueError(f"n_seeds: expected a positive number of starts, got {n_seeds}")
    mask = active_mask(mech)
    for i in targets:
        mask[i] = False
    L = mech.characteristic_length
    first = _fk_from(mech, start or Configuration.reference(mech), targets, mask, max_iter)
    runs = [first]
    if all_solutions:
        rng = np.random.default_rng(seed)
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
                progress(s + 1, n_seeds)
    sols, sigs = [], []
    for k, r in enumerate(runs):
        if not r.converged and not (k == 0 and not all_solutions):
            continue
        sig = np.concatenate([p.ravel() for p in joint_points(mech, r.config)] + [r.config.D[:3, :3].ravel() * L, r.config.D[:3, 3]])
        if r.converged and any(np.linalg.norm(sig - s2) < 1e-6 * L for s2 in sigs):
            continue
        sigs.append(sig)
        sols.append(ForwardSolution(r.config, platform_pose(mech, r.config), r.converged, r.residual, r.iterations,
                                    tuple(within_limits(mech, r.config.q))))
    search = {"method": "Gauss-Newton with the actuators held" + (", multi-start" if all_solutions else ""),
              "seeds": 1 + (n_seeds if all_solutions else 0), "seed": seed if all_solutions else None,
              "converged_runs": sum(r.converged for r in runs), "distinct": sum(s.converged for s in sols),
              "seeding": ("random platform poses with least-squares limb solutions, and random walks along the closure "
                          "manifold with the actuators free, alternately") if all_solutions else "start configuration",
              "distinct_by": "joint points of every limb and the platform pose (tolerance 1e-6 L)"}
    return ForwardResult(tuple(sols), search)
