"""Posing a lower-mobility mechanism by its task coordinates; the parasitic ones are solved.

Task coordinates (:mod:`spatialmech.model.task`): ``x, y, z`` the output link's reference point
(the model's length unit) and ``a1, a2, a3`` its Euler angles in a named sequence (rad).  For a
displacement ``D`` of the output link, the point is ``P = R p0 + t`` and the spatial twist of
the output is ``V = (omega ; dP/dt - omega x P)`` with ``omega = E(a) da/dt`` (:func:`euler_rate_matrix`),
so ``V = C(values) d(values)/dt`` with the 6x6 map :func:`coordinate_map`.

:func:`solve_task` holds the given coordinates exactly and solves the closure equations by
Gauss-Newton (minimum norm) in the unknowns: every unlocked joint variable (actuators included),
the solved coordinates and the internal bodies' twists.  :func:`default_task` picks the given
coordinates from the output link's twist space at the reference configuration.

    >>> from spatialmech.catalog import build
    >>> import numpy as np
    >>> m = build("three-rps")
    >>> default_task(m).given
    ('z', 'a2', 'a3')
    >>> r = solve_task(m, {"z": 0.33, "a2": np.radians(5), "a3": np.radians(5)})
    >>> r.converged, r.solved
    (True, ('x', 'y', 'a1'))
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from itertools import combinations

import numpy as np

from ..errors import InputError
from ..geometry.rotations import euler_matrix, matrix_euler, skew, transform
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism
from ..model.task import TASK_NAMES, TaskCoordinates
from ..results import SolveStatus
from .closure import Configuration, active_mask, closure_scales
from . import backend
from .backend import closure_jacobian, retract
from .velocity import euler_rate_matrix

__all__ = [
    "TaskJacobian",
    "TaskPath",
    "TaskSolution",
    "continue_task",
    "coordinate_map",
    "default_task",
    "joint_change",
    "pose_from_task",
    "solve_pose",
    "solve_task",
    "task_jacobian",
    "task_jacobian_at",
    "task_solution_dict",
    "task_values",
]


def task_values(mech: Mechanism, D, euler: str = "ZYX") -> np.ndarray:
    """The six task coordinates ``(x, y, z, a1, a2, a3)`` (length unit, rad) of the output
    displacement ``D`` (4x4)."""
    D = np.asarray(D, dtype=float)
    P = D[:3, :3] @ mech.platform_point + D[:3, 3]
    return np.r_[P, matrix_euler(euler, D[:3, :3])]


def pose_from_task(mech: Mechanism, values, euler: str = "ZYX") -> np.ndarray:
    """The output displacement (4x4) with task coordinates ``values`` (6,)."""
    v = np.asarray(values, dtype=float)
    R = euler_matrix(euler, v[3:])
    return transform(R, v[:3] - R @ mech.platform_point)


def coordinate_map(values, euler: str = "ZYX") -> np.ndarray:
    """``C`` (6x6) with ``V = C d(values)/dt``: the spatial twist of the output link for rates of
    its task coordinates at ``values``."""
    v = np.asarray(values, dtype=float)
    E = euler_rate_matrix(euler, v[3:])
    C = np.zeros((6, 6))
    C[:3, 3:] = E
    C[3:, :3] = np.eye(3)
    C[3:, 3:] = skew(v[:3]) @ E  # -omega x P = P x omega
    return C


def default_task(mech: Mechanism, euler: str = "ZYX") -> TaskCoordinates:
    """The given coordinates of ``mech`` by default: the mechanism's own ``task`` if declared;
    otherwise the ``M`` coordinates (``M`` = the output link's freedoms at the reference, the
    nullity of the closure Jacobian projected on the output twist) whose rates parametrise the
    output twist space there: for every ``M``-subset, the smallest singular value of its rows of
    an orthonormal basis of ``C^-1 V`` (positions divided by the characteristic length); among
    the subsets within a factor 2 of the best, the one with the most angles (a rotary output is
    posed by its angle), then the best conditioned, then the earliest in ``x, y, z, a1, a2, a3``."""
    own = getattr(mech, "task", None)
    if own is not None:
        return own
    c = Configuration.reference(mech)
    active = active_mask(mech)
    A, _ = closure_jacobian(mech, c, active=active)
    row, col = closure_scales(mech, active)
    As = row[:, None] * A * col[None, :]
    _, sv, vt = np.linalg.svd(As)
    r = int(np.sum(sv > current_tolerances().rank * max(1.0, sv[0] if sv.size else 0.0)))
    na = int(active.sum())
    V = (vt[r:] * col[None, :])[:, na : na + 6]  # output twists of the null motions (SI)
    L = mech.characteristic_length
    rates = np.linalg.solve(coordinate_map(task_values(mech, c.D, euler), euler), V.T)  # (6, k)
    rates[:3] /= L
    U, s, _ = np.linalg.svd(rates, full_matrices=False)
    M = int(np.sum(s > 1e-7 * max(1.0, s[0] if s.size else 0.0)))
    if M == 0:
        raise InputError(f"task: {mech.name}'s output link cannot move at the reference configuration")
    if M == 6:
        return TaskCoordinates(TASK_NAMES, euler)
    B = U[:, :M]  # orthonormal basis of the coordinate-rate space
    subs = list(combinations(range(6), M))
    smin = [float(np.linalg.svd(B[list(sub)], compute_uv=False)[-1]) for sub in subs]
    top = max(smin)
    # among the well-conditioned subsets (at least half the best), the one with the most angles
    # (a rotary output is posed by its angle, which does not fold back as a point's coordinate does)
    ok = [k for k in range(len(subs)) if smin[k] >= 0.5 * top]
    best = max(ok, key=lambda k: (sum(i >= 3 for i in subs[k]), round(smin[k], 9), -k))
    return TaskCoordinates(tuple(TASK_NAMES[i] for i in subs[best]), euler)


@dataclass(frozen=True, eq=False)
class TaskSolution:
    """A configuration with the given task coordinates held and the others solved."""

    config: Configuration
    values: Mapping[str, float]  # all six coordinates (length unit, rad)
    task: TaskCoordinates
    converged: bool
    residual: float  # nondimensional closure residual
    iterations: int
    status: SolveStatus
    #: How far (path parameter ``s`` in [0, 1]) a continuation from the reference pose got when
    #: the direct solve failed (:func:`continue_task`); ``None`` when none was run.
    continuation: float | None = None

    @property
    def given(self) -> tuple[str, ...]:
        return self.task.given

    @property
    def solved(self) -> tuple[str, ...]:
        return self.task.solved

    @property
    def D(self) -> np.ndarray:
        return self.config.D


#: The compiled solve's status codes (:func:`.compiled.tasks.task_solve`).
_STATUS = {1: SolveStatus.CONVERGED, 2: SolveStatus.STALLED, 0: SolveStatus.MAX_ITER}


def _check_given(task: TaskCoordinates, given: Mapping[str, float]) -> dict[str, float]:
    if not isinstance(given, Mapping):
        raise InputError(f"given: expected a mapping of task coordinate -> value, got {type(given).__name__}")
    out = {}
    for k, v in given.items():
        if k not in TASK_NAMES:
            raise InputError(f"given.{k}: unknown task coordinate; expected one of {', '.join(TASK_NAMES)}")
        if k not in task.given:
            raise InputError(f"given.{k}: {k} is solved (parasitic) under this task ({', '.join(task.given)} given); "
                             "name it among the given coordinates (task / --free) to hold it")
        x = float(v)
        if not np.isfinite(x):
            raise InputError(f"given.{k}: must be finite, got {v!r}")
        out[k] = x
    return out


def solve_task(mech: Mechanism, given: Mapping[str, float], *, task: TaskCoordinates | None = None,
               seed: Configuration | None = None, tol: float | None = None, max_iter: int = 60) -> TaskSolution:
    """Hold the ``given`` task coordinates (a subset of ``task.given``; the rest of the given
    ones keep the seed's values) and solve the closure for the joint variables, the solved
    coordinates and the internal bodies, by Gauss-Newton from ``seed`` (default: the
    reference).  Never raises on non-convergence: ``converged``/``status`` say."""
    task = default_task(mech) if task is None else task
    if not isinstance(task, TaskCoordinates):
        raise TypeError(f"task: expected a TaskCoordinates, got {type(task).__name__}")
    g = _check_given(task, given)
    tol = current_tolerances().newton if tol is None else float(tol)
    config = Configuration.reference(mech) if seed is None else seed
    if (fast := backend.engine()) is not None:  # the same steps, compiled
        values = np.array([g.get(n, 0.0) for n in TASK_NAMES])
        solved = np.array([n not in task.given for n in TASK_NAMES])
        seeded = np.array([n not in g for n in TASK_NAMES]) | solved
        config, values, code, it, rn = fast.task_solve(mech, config, values, seeded, solved, task.euler, tol, max_iter)
        return TaskSolution(config, dict(zip(TASK_NAMES, map(float, values), strict=True)), task, code == 1, rn, it,
                            _STATUS[code])
    values = task_values(mech, config.D, task.euler)
    for k, v in g.items():
        values[TASK_NAMES.index(k)] = v
    free = [i for i, n in enumerate(TASK_NAMES) if n in task.solved]
    config = Configuration(config.q, pose_from_task(mech, values, task.euler), config.B)
    active = active_mask(mech)
    na = int(active.sum())
    row, col = closure_scales(mech, active)
    L = mech.characteristic_length
    cscale = np.array([L, L, L, 1.0, 1.0, 1.0])[free]
    scales = np.r_[col[:na], cscale, col[na + 6 :]]
    rn = np.inf
    it = 0
    status = SolveStatus.MAX_ITER
    for it in range(max_iter + 1):
        A, r = closure_jacobian(mech, config, active=active)
        rn = float(np.linalg.norm(row * r))
        if rn < tol:
            return TaskSolution(config, dict(zip(TASK_NAMES, map(float, values), strict=True)), task, True, rn, it,
                                SolveStatus.CONVERGED)
        if it == max_iter or not np.isfinite(rn):
            break
        Cf = coordinate_map(values, task.euler)[:, free]
        G = np.hstack([A[:, :na], A[:, na : na + 6] @ Cf, A[:, na + 6 :]])
        x, *_ = np.linalg.lstsq(row[:, None] * G * scales[None, :], -(row * r), rcond=None)
        if np.linalg.norm(x) < 1e-13 * max(1.0, rn):
            status = SolveStatus.STALLED
            break
        u = scales * x
        nf = len(free)
        step = np.r_[u[:na], np.zeros(6), u[na + nf :]]
        values[free] += u[na : na + nf]
        config = retract(mech, config, active, step, fix_platform=True)
        config = Configuration(config.q, pose_from_task(mech, values, task.euler), config.B)
    return TaskSolution(config, dict(zip(TASK_NAMES, map(float, values), strict=True)), task, False, rn, it, status)


def solve_pose(mech: Mechanism, pose, free, *, euler: str = "ZYX", seed: Configuration | None = None) -> TaskSolution:
    """A requested output pose (:class:`~spatialmech.model.mechanism.Pose`) whose coordinates
    ``free`` (names from ``x, y, z, a1, a2, a3``, angles in sequence ``euler``) are to be solved:
    the other coordinates are held at the pose's values and :func:`solve_task` finds the rest.
    As many coordinates must stay given as the output link has freedoms (:func:`default_task`),
    else :class:`InputError` names both counts.  From the reference (no ``seed``), a failed solve
    is retried by :func:`continue_task` (continuation from the reference pose)."""
    names = [str(n).strip() for n in free]
    for k, n in enumerate(names):
        if n not in TASK_NAMES:
            raise InputError(f"free[{k}]: unknown task coordinate {n!r}; expected one of {', '.join(TASK_NAMES)}")
    if len(set(names)) != len(names):
        raise InputError(f"free: {names} repeats a coordinate")
    if len(names) >= 6:
        raise InputError("free: at least one coordinate must be given (held)")
    task = TaskCoordinates(tuple(n for n in TASK_NAMES if n not in names), euler)
    _check_count(mech, task, names)
    values = task_values(mech, pose.displacement(mech.platform_point), euler)
    given = {n: float(values[TASK_NAMES.index(n)]) for n in task.given}
    sol = solve_task(mech, given, task=task, seed=seed)
    if sol.converged or seed is not None:
        return sol
    far, s = continue_task(mech, given, task=task)
    return far if far is not None else replace(sol, continuation=s)


def _check_count(mech: Mechanism, task: TaskCoordinates, names: list[str]) -> None:
    """Refuse a task that gives more or fewer coordinates than the output link has freedoms
    (over-determined: generally no pose; under-determined: one of a family, picked silently)."""
    own = default_task(mech, task.euler)
    m = len(own.given)
    if len(task.given) == m:
        return
    what = "over-determined" if len(task.given) > m else "under-determined"
    hint = f"e.g. --free {','.join(own.solved)}" if own.solved else "give no --free"
    raise InputError(f"free (--free): {mech.name}'s output link has {m} freedoms, so {m} task coordinates are given "
                     f"and {6 - m} solved; --free {','.join(names) or '(none)'} solves {len(names)} and leaves "
                     f"{len(task.given)} given ({', '.join(task.given)}): {what}; name {6 - m} to solve ({hint})")


#: Continuation from the reference: the first and largest step of the path (nondimensional:
#: rad, characteristic lengths), the smallest, and the most steps.
CONTINUATION_STEP = 0.05
CONTINUATION_MIN_STEP = 1e-4
CONTINUATION_MAX_STEPS = 2000


def joint_change(mech: Mechanism, a: Configuration, b: Configuration) -> float:
    """The largest change of any joint from ``a`` to ``b``: rad (the short way round), slides in
    characteristic lengths."""
    dq = b.q - a.q
    rot = np.array([r.freedom.kind != "P" for r in mech.freedom_refs])
    dq = np.where(rot, (dq + np.pi) % (2 * np.pi) - np.pi, dq / mech.characteristic_length)
    return float(np.max(np.abs(dq))) if dq.size else 0.0


class TaskPath:
    """The straight path of the given task coordinates from their values at ``start`` (default:
    the reference) to ``given`` (angles the short way round), ``s`` in [0, 1]; ``length`` is its
    nondimensional length (rad, characteristic lengths).  :meth:`walk` follows it by
    natural-parameter continuation; :attr:`status` says how the last walk ended: ``"reached"``,
    ``"stalled"`` (no step above the smallest converged: the edge of the branch) or
    ``"max_steps"``."""

    def __init__(self, mech: Mechanism, given: Mapping[str, float], *, task: TaskCoordinates,
                 start: Configuration | None = None):
        self.given = _check_given(task, given)
        self.mech, self.task = mech, task
        self.start = Configuration.reference(mech) if start is None else start
        self.v0 = task_values(mech, self.start.D, task.euler)
        gi = [TASK_NAMES.index(n) for n in self.given]
        self.delta = np.zeros(6)
        self.delta[gi] = np.array([self.given[n] for n in self.given]) - self.v0[gi]
        self.delta[3:] = (self.delta[3:] + np.pi) % (2 * np.pi) - np.pi
        L = mech.characteristic_length
        self.length = float(np.linalg.norm(np.r_[self.delta[:3] / L, self.delta[3:]]))
        self.status = ""
        self.steps = 0

    def values(self, s: float) -> np.ndarray:
        """The six task values at ``s`` (the solved ones: the start's)."""
        return self.v0 + s * self.delta

    def at(self, s: float, seed: Configuration, max_iter: int = 12) -> TaskSolution:
        """:func:`solve_task` at ``s`` from ``seed``."""
        v = self.values(s)
        return solve_task(self.mech, {n: float(v[TASK_NAMES.index(n)]) for n in self.given}, task=self.task,
                          seed=seed, max_iter=max_iter)

    def walk(self, *, step: float = CONTINUATION_STEP, min_step: float = CONTINUATION_MIN_STEP,
             max_steps: int = CONTINUATION_MAX_STEPS,
             max_joint_step: float | None = None) -> Iterator[tuple[float, TaskSolution]]:
        """Yield ``(s, solution)`` for every accepted step from the start: each step (``step``
        long at first and at most, nondimensional) solved from the previous configuration, kept
        when it converges and no joint moves more than ``max_joint_step`` (see
        :func:`joint_change`), else halved down to ``min_step``.  The caller may stop at any
        step; :attr:`status` and :attr:`steps` tell how a finished walk ended."""
        cur, s, h = self.start, 0.0, min(step, self.length)
        self.steps, self.status = 0, "reached"
        while s < 1.0 and self.length > 0.0:
            if self.steps >= max_steps:
                self.status = "max_steps"
                return
            nxt = min(1.0, s + h / self.length)
            r = self.at(nxt, cur)
            if not r.converged or (max_joint_step is not None and joint_change(self.mech, cur, r.config) > max_joint_step):
                h *= 0.5
                if h < min_step:
                    self.status = "stalled"
                    return
                continue
            self.steps += 1
            yield nxt, r
            cur, s, h = r.config, nxt, min(step, 1.5 * h)


def continue_task(mech: Mechanism, given: Mapping[str, float], *, task: TaskCoordinates,
                  start: Configuration | None = None) -> tuple[TaskSolution | None, float]:
    """Natural-parameter continuation (a homotopy in the pose, as the studio's pose drag,
    :mod:`spatialmech.services.studio.posing`; both walk a :class:`TaskPath`): the given
    coordinates are moved along the straight path from their values at ``start`` (default: the
    reference) to ``given`` (angles the short way round), each step corrected by
    :func:`solve_task` from the previous configuration and halved when it does not converge.
    Returns ``(solution, s)``: the converged solve at the target (its ``continuation`` 1.0) and
    ``s = 1``, or ``None`` and the path parameter ``s`` in [0, 1) where the steps could not go on."""
    path = TaskPath(mech, given, task=task, start=start)
    cur, s = path.start, 0.0
    for s_step, sol in path.walk():
        s, cur = s_step, sol.config
    if s < 1.0:
        return None, float(s)
    final = path.at(1.0, cur, 60)
    return (replace(final, continuation=1.0) if final.converged else None), float(s)


def task_solution_dict(sol: TaskSolution) -> dict:
    """JSON (docs/json.md) of a task solve: which coordinates were given and solved, the six
    values (``values_len``: x, y, z in the model's length unit; ``values_deg``: a1, a2, a3)."""
    return {"given": list(sol.given), "solved": list(sol.solved), "euler": sol.task.euler,
            "converged": bool(sol.converged), "status": str(sol.status), "residual": float(sol.residual),
            "continuation_fraction": None if sol.continuation is None else float(sol.continuation),
            "values_len": {n: float(sol.values[n]) for n in TASK_NAMES[:3]},
            "values_deg": {n: float(np.degrees(sol.values[n])) for n in TASK_NAMES[3:]}}


def task_jacobian(mech: Mechanism, sol: TaskSolution, drivers=None) -> tuple[np.ndarray, tuple[str, ...], tuple[str, ...]]:
    """The input-output Jacobian over the task coordinates at a task solution: ``J`` (n_act x M)
    with ``d actuators = J d(given coordinates)``, the parasitic coordinates, the passive joints
    and the bodies following (minimum-norm solve of the linearised closure).  Returns
    ``(J, actuator ids, given coordinate names)``; actuator rates in their own units (rad, length)
    per unit of each given coordinate (length unit or rad).  ``drivers``: the freedoms whose
    rates are the rows (default: the model's actuators)."""
    active = active_mask(mech)
    na = int(active.sum())
    A, _ = closure_jacobian(mech, sol.config, active=active)
    row, col = closure_scales(mech, active)
    C = coordinate_map([sol.values[n] for n in TASK_NAMES], sol.task.euler)
    gi = [TASK_NAMES.index(n) for n in sol.given]
    fi = [TASK_NAMES.index(n) for n in sol.solved]
    L = mech.characteristic_length
    cs = np.array([L, L, L, 1.0, 1.0, 1.0])
    G = np.hstack([A[:, :na], A[:, na : na + 6] @ C[:, fi], A[:, na + 6 :]])
    scales = np.r_[col[:na], cs[fi], col[na + 6 :]]
    rhs = -(A[:, na : na + 6] @ C[:, gi])
    X, *_ = np.linalg.lstsq(row[:, None] * G * scales[None, :], row[:, None] * rhs, rcond=None)
    U = scales[:, None] * X  # rates of the unknowns per unit rate of each given coordinate
    pos = np.cumsum(active) - 1
    acts = tuple(mech.actuators) if drivers is None else tuple(mech.freedom(a).id for a in drivers)
    refs = [mech.freedom_refs.index(mech.freedom(a)) for a in acts]
    locked = [a for a, r in zip(acts, refs, strict=True) if not active[r]]
    if locked:
        raise InputError(f"drivers: {', '.join(locked)} {'is' if len(locked) == 1 else 'are'} locked in {mech.name}")
    return U[[int(pos[r]) for r in refs]], acts, tuple(sol.given)


@dataclass(frozen=True, eq=False)
class TaskJacobian:
    """The input-output Jacobian of a lower-mobility mechanism over its given task coordinates
    (:func:`task_jacobian_at`): ``matrix`` (n_drivers x M, SI: actuator rate in rad or length
    per unit rate of each given coordinate, length or rad), with the parasitic coordinates
    solved; ``solution`` the task solve at the configuration (its six ``values``)."""

    matrix: np.ndarray
    actuators: tuple[str, ...]
    solution: TaskSolution

    @property
    def given(self) -> tuple[str, ...]:
        return self.solution.given

    @property
    def solved(self) -> tuple[str, ...]:
        return self.solution.solved

    def scaled(self, mech: Mechanism) -> np.ndarray:
        """The matrix nondimensional: lengths (actuator slides and x, y, z) divided by the
        characteristic length, angles in rad."""
        L = mech.characteristic_length
        r = np.array([L if mech.freedom(a).freedom.kind == "P" else 1.0 for a in self.actuators])
        c = np.array([L if n in TASK_NAMES[:3] else 1.0 for n in self.given])
        return self.matrix * c[None, :] / r[:, None]

    def to_dict(self, mech: Mechanism) -> dict:
        """JSON (docs/json.md): ``given``, ``solved``, ``euler``, ``actuators``, ``io_matrix``
        (:meth:`scaled`: rows by actuator, columns by given coordinate, nondimensional) and
        ``characteristic_length_len`` to restore the units."""
        return {"given": list(self.given), "solved": list(self.solved), "euler": self.solution.task.euler,
                "actuators": list(self.actuators), "io_matrix": self.scaled(mech).tolist(),
                "characteristic_length_len": float(mech.characteristic_length)}


def task_jacobian_at(mech: Mechanism, config: Configuration, drivers=None, *,
                     task: TaskCoordinates | None = None) -> TaskJacobian | None:
    """:func:`task_jacobian` at a closed configuration of a lower-mobility mechanism, over its
    task (``task``, else the model's own, else :func:`default_task`); ``None`` when the output
    link has six freedoms (then every coordinate is given) or cannot move."""
    try:
        task = default_task(mech) if task is None else task
    except InputError:  # the output link cannot move
        return None
    if len(task.given) == 6:
        return None
    values = task_values(mech, config.D, task.euler)
    sol = solve_task(mech, {n: float(values[TASK_NAMES.index(n)]) for n in task.given}, task=task, seed=config)
    if not sol.converged:
        return None
    J, acts, _ = task_jacobian(mech, sol, drivers)
    return TaskJacobian(J, acts, sol)
