"""Singularity analysis for any mechanism (paper B section 5, made general).

At a configuration, with the actuators locked, the platform is held by the constraint wrenches
of the limbs and the actuation wrenches of the actuators: the rows of the complete Jacobian
(:mod:`spatialmech.kinematics.jacobian`).  The analysis reports

- ``rank`` of that wrench system (6 when the platform is held) and which kind of singularity
  it is: *inverse* (serial: an actuation wrench does not exist, the actuator can move with
  the platform at rest), *constraint* (the limbs' constraint wrenches lose rank: the
  platform gains a freedom it should not have), *direct* (parallel: constraint and actuation
  wrenches together lose rank: an uncontrolled platform twist), or none;
- the uncontrolled platform twist (the null space of ``J``) and, for an inverse singularity,
  the actuator that moves with the platform at rest;
- the smallest singular value of the scale-free Jacobian (distance to a direct or constraint
  singularity) and each actuator's transmission index ``|W . $a| / (|W| |$a|)`` (distance to
  an inverse singularity: 0 there);
- the line geometry of the wrench system when its members are lines (forces), by Grassmann's
  varieties (:mod:`spatialmech.geometry.line_geometry`), with witnesses;
- whether the uncontrolled motion is *finite* (a self-motion with the actuators locked: the
  motion can be followed by the continuation tracker with the actuators held) or only
  instantaneous.

:func:`singularity_slice` maps ``sign(det J)`` and ``sigma_min`` over a 2-D slice of a pose
parametrisation: the singularity loci are its zero contours (drawn by
:func:`spatialmech.present.singularity.slice_figure`).
"""

from __future__ import annotations

from collections import deque

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry import screws as sc
from ..geometry.line_geometry import classify_lines, json_dict
from ..kinematics.closure import Configuration
from ..kinematics.jacobian import CompleteJacobian, complete_jacobian
from ..kinematics.position import configuration_at_pose, platform_pose
from ..kinematics.forward import locked_actuators
from ..kinematics.tracking import MotionProblem, track
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism, Pose
from ..results import Progress, SingularityKind

__all__ = ["SingularityResult", "SliceResult", "locked_actuators", "singularity", "singularity_at_pose", "singularity_slice"]


@dataclass(frozen=True, eq=False)
class SingularityResult:
    rank: int
    expected_rank: int
    kind: SingularityKind  # none, inverse, constraint, direct, or inverse+constraint
    sigma_min: float
    condition: float
    transmission: tuple[float, ...]
    twist: tuple[tuple[float, ...], ...]  # uncontrolled platform twists (omega ; v), SI
    inverse_actuators: tuple[str, ...]
    constraint_rank: int
    constraint_rank_generic: int
    line_geometry: dict | None
    self_motion: dict | None
    jacobian: CompleteJacobian
    explanation: str

    def to_dict(self) -> dict:
        """JSON (docs/json.md): the uncontrolled ``twist`` screws ``(omega ; v)`` (``v`` in the
        model's length unit per unit of ``omega``), the line geometry and the self-motion with
        lengths in the model's unit (``*_len``) and angles in degrees."""
        sm = self.self_motion
        if sm is not None:
            names = {"platform_point_moved": "platform_point_moved_len", "end_platform_point": "end_platform_point_len"}
            sm = {names.get(k, k): v for k, v in sm.items()}
        return {
            "rank": self.rank,
            "expected_rank": self.expected_rank,
            "kind": self.kind,
            "singular": self.kind != "none",
            "sigma_min": self.sigma_min,
            "condition": self.condition,
            "transmission": dict(zip(self.jacobian.actuators, self.transmission, strict=True)),
            "twist": [list(t) for t in self.twist],
            "twist_convention": "(omega ; v): v = velocity of the point at the origin, in the length unit per unit of omega",
            "inverse_actuators": list(self.inverse_actuators),
            "constraint_rank": self.constraint_rank,
            "constraint_rank_generic": self.constraint_rank_generic,
            "line_geometry": None if self.line_geometry is None else json_dict(self.line_geometry),
            "self_motion": sm,
            "wrenches": self.jacobian.wrenches.tolist(),
            "actuators": list(self.jacobian.actuators),
            "explanation": self.explanation,
        }


def _is_line(w: np.ndarray, L: float, tol: float = 1e-7) -> bool:
    f, m = w[:3], w[3:]
    nf = np.linalg.norm(f)
    return bool(nf > 1e-12 and abs(f @ m) <= tol * nf * max(np.linalg.norm(m), L * nf))


def _as_unit_line(w: np.ndarray) -> np.ndarray:
    f = w[:3]
    n = np.linalg.norm(f)
    line = w / n
    # remove the tiny pitch left by rounding so the line validates exactly
    s, m = line[:3], line[3:]
    return np.r_[s, m - (s @ m) * s]


def _generic_constraint_rank(mech: Mechanism) -> int:
    from ..analysis.mobility import mobility

    r = mobility(mech) if not mech.is_metamorphic or len(mech.all_modes()) == 1 else None
    return (6 - r.dof - 0) if r is not None else -1


def _self_motion(mech: Mechanism, config: Configuration, actuators, arc: float) -> dict:
    """Follow the motion of the mechanism with its actuators locked, if there is one."""
    locked = locked_actuators(mech, actuators)
    prob = MotionProblem(locked)
    try:
        tr = track(prob, config, max_arc=arc, h0=min(0.01, arc / 10), detect_closure=True, max_steps=400)
    except RuntimeError as e:
        return {"finite": False, "reason": str(e)}
    if not tr.points or (tr.s[-1] < 0.5 * arc and not tr.closed):
        return {"finite": False, "reason": tr.message, "arc": float(tr.s[-1]) if len(tr.s) else 0.0}
    p0 = config.D[:3, :3] @ mech.platform_point + config.D[:3, 3]
    end = tr.points[-1]
    p1 = end.D[:3, :3] @ mech.platform_point + end.D[:3, 3]
    from ..geometry.rotations import rotation_angle

    ang = float(rotation_angle(end.D[:3, :3] @ config.D[:3, :3].T))
    return {
        "finite": True,
        "arc": float(tr.s[-1]),
        "closed": bool(tr.closed),
        "platform_point_moved": float(np.linalg.norm(p1 - p0)),
        "platform_rotated_deg": float(np.degrees(ang)),
        "end_platform_point": p1.tolist(),
        "status": tr.status,
    }


def singularity(
    mech: Mechanism,
    config: Configuration,
    actuators=None,
    *,
    rtol: float | None = None,
    self_motion_arc: float = 0.3,
) -> SingularityResult:
    """Singularity analysis of ``mech`` at a (closed) configuration with the given actuators.

    ``rtol``: the relative singular-value threshold of the wrench system's rank (default: the
    ``singular`` tolerance in force, :mod:`~spatialmech.geometry.tolerances`)."""
    rtol = current_tolerances().singular if rtol is None else rtol
    J = complete_jacobian(mech, config, actuators)
    L = mech.characteristic_length
    W = J.wrenches
    nd = sc.nondimensional(W, L)
    norms = np.linalg.norm(nd, axis=1, keepdims=True)
    nd = nd / np.where(norms > 0, norms, 1.0)
    sv = np.linalg.svd(nd, compute_uv=False) if nd.size else np.zeros(0)
    rank = int(np.sum(sv > rtol * max(1.0, sv[0] if sv.size else 1.0)))
    c_rows = nd[: J.constraint_rows]
    c_rank = int(np.linalg.matrix_rank(c_rows, tol=rtol)) if c_rows.size else 0
    generic = _generic_constraint_rank(mech)
    expected = min(6, J.matrix.shape[0])
    kinds = []
    if J.inverse_singular:
        kinds.append("inverse")
    if generic >= 0 and c_rank < generic:
        kinds.append("constraint")
    if rank < expected and not J.inverse_singular and "constraint" not in kinds:
        kinds.append("direct")
    elif rank < expected and "constraint" in kinds:
        pass
    kind = SingularityKind("+".join(kinds) if kinds else "none")
    # uncontrolled twists: matrix @ V = 0 (in nondimensional twist coordinates)
    M = sc.nondimensional(J.wrenches, L)
    M = sc.swap(M)  # rows act on (omega ; v / L)
    twist: tuple[tuple[float, ...], ...] = ()
    if rank < 6:
        _, s2, vt = np.linalg.svd(M if M.size else np.zeros((1, 6)))
        r2 = int(np.sum(s2 > rtol * max(1.0, s2[0]))) if s2.size else 0
        # a deterministic basis (reduced row-echelon form of the nondimensional null space: each
        # twist's first pivot positive), not the basis and signs the SVD happens to return
        N = sc.rref(vt[r2:]) if r2 < vt.shape[0] else vt[r2:].copy()
        N[:, 3:] *= L
        out = []
        for n in N:  # unit angular part, or unit translation for a pure translation
            w = np.linalg.norm(n[:3])
            n = n / (w if w > 1e-9 else np.linalg.norm(n))
            out.append(tuple(float(x) for x in np.where(np.abs(n) < 1e-12, 0.0, n)))
        twist = tuple(out)
    # line geometry of the wrench system when every wrench is a line
    lg = None
    if W.shape[0] and all(_is_line(w, L) for w in W):
        lines = np.array([_as_unit_line(w) for w in W])
        lg = classify_lines(lines, length_scale=L).as_dict()
    # finite or instantaneous?
    sm = None
    if kind != "none" and "inverse" not in kinds:
        sm = _self_motion(mech, config, actuators if actuators is not None else list(J.actuators), self_motion_arc)
    parts = []
    if kind == "none":
        parts.append(f"Not singular: the wrench system has rank {rank} (scale-free sigma_min {J.sigma_min:.3g}).")
    else:
        if "inverse" in kinds:
            parts.append(f"Inverse (serial) singularity: no actuation wrench for {', '.join(J.inverse_singular)}; "
                         "the actuator can move while the platform stays at rest.")
        if "constraint" in kinds:
            parts.append(f"Constraint singularity: the limbs' constraint wrenches have rank {c_rank} instead of {generic}.")
        if "direct" in kinds:
            parts.append("Direct (parallel) singularity: with the actuators locked the wrench system has "
                         f"rank {rank} < {expected}; the platform has an uncontrolled twist.")
        if sm is not None:
            parts.append("The uncontrolled motion is finite (a self-motion with the actuators locked)." if sm.get("finite")
                         else "The uncontrolled motion is only instantaneous.")
    if lg is not None:
        parts.append(f"Line geometry: rank {lg['rank']}, {lg['case']}.")
    return SingularityResult(rank, expected, kind, float(J.sigma_min), float(J.condition), tuple(J.transmission), twist,
                             tuple(J.inverse_singular), c_rank, generic, lg, sm, J, " ".join(parts))


def singularity_at_pose(mech: Mechanism, pose: Pose, actuators=None, **kw) -> SingularityResult:
    """Singularity analysis at a platform pose (fitted onto the closure first)."""
    fit = configuration_at_pose(mech, pose)
    if not fit.converged or not fit.exact:
        raise InputError(f"pose: not reachable exactly (nearest closed pose is {fit.position_error:.3g} away); "
                         "singularities are analysed at closed configurations")
    return singularity(mech, fit.config, actuators, **kw)


@dataclass(frozen=True, eq=False)
class SliceResult:
    names: tuple[str, str]
    u: np.ndarray
    v: np.ndarray
    det: np.ndarray  # (len(v), len(u)); nan where not reachable on the given pose's branch
    sigma_min: np.ndarray
    fixed: dict = field(default_factory=dict)
    units: tuple[str, str] = ("", "")
    #: per grid point: 0 on the given pose's branch, 1 on another branch, -1 not solved
    branch: np.ndarray | None = None
    #: ``det J`` and ``sigma_min`` at the given pose itself (as ``sm.jacobian`` gives them)
    at_pose: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON (docs/json.md): the two ``axes`` with their values (``values_deg`` for an
        angle, ``values_len`` for a length, by ``units``), ``det`` / ``sign`` / ``sigma_min``
        over the grid (rows along v, columns along u; ``None`` where no pose closes on the given
        pose's branch), ``branch`` (0 followed, 1 another branch, -1 not solved; masked in
        ``det``), ``at_pose`` and ``sign_changes_along_u`` (between neighbours on the branch)."""
        def clean(a):
            return [[None if not np.isfinite(x) else float(x) for x in row] for row in a]

        axes = []
        for name, unit, vals in zip(self.names, self.units, (self.u, self.v), strict=True):
            key = "values_deg" if unit == "deg" else "values_len"
            axes.append({"name": name, key: [float(x) for x in vals]})
        s = np.sign(self.det)
        both = np.isfinite(s[:, 1:]) & np.isfinite(s[:, :-1])
        out = {"axes": axes, "det": clean(self.det), "sign": clean(s), "sigma_min": clean(self.sigma_min),
               "fixed": self.fixed, "sign_changes_along_u": int(np.sum((s[:, 1:] != s[:, :-1]) & both))}
        if self.branch is not None:
            out["branch"] = self.branch.astype(int).tolist()
            out["n_branch_switched"] = int(np.sum(self.branch == 1))
            out["n_unreached"] = int(np.sum(self.branch == -1))
        if self.at_pose:
            out["at_pose"] = self.at_pose
        return out


def singularity_slice(
    mech: Mechanism,
    pose_of: Callable[[float, float], Pose],
    u: np.ndarray,
    v: np.ndarray,
    *,
    names=("u", "v"),
    units=("", ""),
    actuators=None,
    fixed: dict | None = None,
    progress: Progress | None = None,
    start: tuple[Pose, Configuration] | None = None,
) -> SliceResult:
    """``det J`` and the scale-free ``sigma_min`` over a grid ``pose_of(u_i, v_j)``, on the branch
    (working mode) of ``start = (pose, configuration)``: the given pose and its closed
    configuration (default: the reference's).

    The grid is solved neighbour to neighbour from the point nearest the given pose
    (:func:`~spatialmech.analysis.pose_slice.follow_grid`), each Jacobian's constraint rows
    oriented as its neighbour's, the given pose's Jacobian first: the sign of ``det`` there is
    ``sm.jacobian``'s.  Points on another branch or not solved are ``nan`` (``branch`` says
    which), so the zero contours of ``det`` are singularity loci of this branch only.
    ``progress(j, len(v), "slice")`` as the grid fills.
    """
    from .pose_slice import FOLLOWED, follow_grid
    from .task_slice import row_orientation

    u = np.asarray(u, float)
    v = np.asarray(v, float)
    if start is None:
        c0 = Configuration.reference(mech)
        start = (platform_pose(mech, c0), c0)
    configs, code, root = follow_grid(mech, pose_of, u, v, start[0], start[1], progress)
    det = np.full((len(v), len(u)), np.nan)
    sig = np.full((len(v), len(u)), np.nan)
    J0 = complete_jacobian(mech, start[1], actuators)
    at_pose = {"det": None if J0.det is None else float(J0.det), "sigma_min": float(J0.sigma_min)}
    # the Jacobians breadth first from the given pose, each referenced to its parent's
    seen: dict[tuple[int, int], tuple] = {}
    if code[root] == FOLLOWED:
        queue = deque([(root, J0, 1.0)])
        seen[root] = ()
        while queue:
            (j, i), ref, o = queue.popleft()
            J = complete_jacobian(mech, configs[j, i], actuators, reference=ref)
            o = o * row_orientation(J, ref)
            det[j, i] = o * J.det if J.det is not None else np.nan
            sig[j, i] = J.sigma_min
            for nb in ((j, i - 1), (j, i + 1), (j - 1, i), (j + 1, i)):
                if nb in seen or not (0 <= nb[0] < len(v) and 0 <= nb[1] < len(u)) or code[nb] != FOLLOWED:
                    continue
                seen[nb] = ()
                queue.append((nb, J, o))
    return SliceResult(tuple(names), u, v, det, sig, dict(fixed or {}), tuple(units), code, at_pose)
