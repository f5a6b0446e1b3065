"""The public API: every analysis by a short name, ``import spatialmech as sm``.

A thin facade over the library (no numerics here): each function takes a model -- a
:class:`~spatialmech.Mechanism`, a ready-made name (``sm.models()``) or a TOML file path --, a pose
where one is needed, and keyword-only options; it checks its arguments (``TypeError`` for a
wrong type, :class:`~spatialmech.InputError` -- a ``ValueError`` -- for a bad value, each naming the
argument and what it got) and returns a frozen dataclass whose ``to_dict()`` is the JSON payload
of the analysis (what ``spatialmech COMMAND --json`` prints inside its envelope).

Units: SI and radians, as everywhere in Python; ``degrees=True`` (keyword-only, as in
``scipy.spatial.transform``) reads the angles of a pose tuple, of rotational actuator values
and of angular rates in degrees.  Statuses are enums (:mod:`spatialmech.results`); progress
callbacks have one signature, ``progress(done, total_or_None, message)``.

Poses (``pose=``): a :class:`~spatialmech.Pose`; a tuple ``(xyz, (seq, a1, a2, a3))`` with a named
Euler sequence (upper case intrinsic, ``"ZYX"``), ``(xyz, R)`` with a 3x3 rotation matrix or
``(xyz, None)`` for the reference orientation; or an ``int`` N, the model's N-th built-in task
position (from 1, as ``--position N``).

    >>> import json, spatialmech as sm
    >>> r = sm.ik("four-sps-cu", ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46)), degrees=True)
    >>> r.reachable, list(r.actuators)
    (True, ['L1.slide', 'L2.slide', 'L3.slide', 'L4.slide'])
    >>> text = json.dumps(r.to_dict(), allow_nan=False)   # the payload of `spatialmech ik --json`
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import catalog
from .analysis.mobility import MobilityResult
from .analysis.mobility import mobility as _mobility
from .analysis.mobility import mobility_modes as _mobility_modes
from .errors import InputError, UnknownNameError, describe
from .geometry.tolerances import resolve as resolve_tolerances
from .geometry.rotations import euler_matrix
from .kinematics.closure import Configuration, check_configuration
from .kinematics.jacobian import CompleteJacobian, complete_jacobian
from .kinematics.task import TaskJacobian, TaskSolution, solve_pose, task_jacobian_at, task_solution_dict
from .kinematics.position import (
    ForwardResult,
    InverseResult,
    PoseFit,
    configuration_at_pose,
    forward_position,
    freedom_values,
    inverse_position,
    platform_pose,
)
from .model.mechanism import Mechanism, Pose
from .results import Progress, TrackStatus, check_progress
from .serialize import pose_dict

__all__ = [
    "CSSynthesisResult",
    "FKResult",
    "IKResult",
    "JacobianResult",
    "MobilityModes",
    "ReportResult",
    "SingularityAnalysis",
    "TraceResult",
    "VelocityResult",
    "ViewResult",
    "defects",
    "dj_table",
    "fk",
    "ik",
    "jacobian",
    "load_model",
    "mobility",
    "mobility_modes",
    "models",
    "parasitic",
    "report",
    "singularity",
    "synth_cs",
    "synth_rccc",
    "track",
    "velocity",
    "view",
    "workspace",
]

#: What a model argument may be.
ModelLike = Mechanism | str | os.PathLike


# ============================================================================ argument checks
def _check_bool(value, name: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {describe(value)}")
    return bool(value)


def _check_int(value, name: str, *, minimum: int | None = None, maximum: int | None = None) -> int:
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name}: expected an integer, got {describe(value)}")
    v = int(value)
    if minimum is not None and v < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {v}")
    if maximum is not None and v > maximum:
        raise InputError(f"{name}: expected an integer <= {maximum}, got {v}")
    return v


def _check_number(value, name: str, *, positive: bool = False, optional: bool = False) -> float | None:
    if value is None and optional:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}: expected a number, got {describe(value)}")
    v = float(value)
    if not np.isfinite(v):
        raise InputError(f"{name}: expected a finite number, got {v}")
    if positive and v <= 0:
        raise InputError(f"{name}: expected a positive number, got {v}")
    return v


def _check_choice(value, name: str, choices: Sequence[str]) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected one of {', '.join(map(repr, choices))}, got {describe(value)}")
    if value not in choices:
        raise InputError(f"{name}: expected one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def _numbers(value, name: str, *, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """Finite numbers (no bools, no strings) as a float array of the given shape."""
    if isinstance(value, (str, bytes, Mapping)) or value is None:
        raise TypeError(f"{name}: expected numbers, got {describe(value)}")
    try:
        a = np.asarray(value)
    except ValueError:  # ragged
        raise InputError(f"{name}: expected numbers of shape {shape}, got a ragged sequence") from None
    if a.dtype == bool or a.dtype.kind not in "iuf":
        raise TypeError(f"{name}: expected numbers, got {describe(value)}")
    a = a.astype(float)
    if shape is not None and a.shape != shape:
        raise InputError(f"{name}: expected shape {shape}, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name}: contains NaN or infinity")
    return a


def _names(value, name: str) -> list[str] | None:
    """``None``, one freedom name, or a sequence of them."""
    if value is None:
        return None
    if isinstance(value, str):
        return [value]
    if not isinstance(value, Sequence):
        raise TypeError(f"{name}: expected a freedom name or a sequence of names, got {describe(value)}")
    for k, v in enumerate(value):
        if not isinstance(v, str):
            raise TypeError(f"{name}[{k}]: expected a freedom name (str), got {describe(v)}")
    return list(value) or None


def _progress(progress) -> Progress | None:
    return None if progress is None else check_progress(progress)


# ============================================================================ models and poses
def models() -> dict[str, str]:
    """The ready-made models: name -> one-line description.

    >>> import spatialmech as sm
    >>> "bennett" in sm.models() and "four-sps-cu" in sm.models()
    True
    """
    return {n: catalog.describe(n) for n in catalog.names()}


def load_model(model: ModelLike) -> Mechanism:
    """A mechanism from a ready-made name, a TOML file path, or a Mechanism (returned as is).

    Unknown names raise :class:`~spatialmech.UnknownNameError` (listing the known ones); a
    malformed file :class:`~spatialmech.ModelFileError` naming the file and the field.

    >>> import spatialmech as sm
    >>> mech = sm.load_model("rssr")
    >>> mech.name, mech.actuators
    ('rssr', ('A0.rot',))
    """
    return _mechanism(model)


def _mechanism(model, name: str = "model") -> Mechanism:
    if isinstance(model, Mechanism):
        return model
    if not isinstance(model, (str, os.PathLike)):
        raise TypeError(f"{name}: expected a Mechanism, a ready-made model name or a TOML file path, got {describe(model)}")
    s = os.fspath(model)
    if isinstance(s, bytes):
        raise TypeError(f"{name}: expected a str path, got bytes {s!r}")
    if s in catalog.REGISTRY:
        return catalog.build(s)
    p = Path(s)
    if not p.exists() and p.suffix == "" and os.sep not in s and (os.altsep is None or os.altsep not in s):
        raise UnknownNameError(f"{name}: unknown ready-made model {s!r} (and no such file); known: "
                               f"{', '.join(catalog.names())}")
    return catalog.resolve(p)


def _pose(mech: Mechanism, pose, degrees: bool, name: str = "pose") -> tuple[Pose, int | None]:
    """A :class:`Pose` from the accepted forms (see the module docstring), and the task-position
    number when one was given."""
    if isinstance(pose, Pose):
        return pose, None
    if isinstance(pose, (int, np.integer)) and not isinstance(pose, (bool, np.bool_)):
        n = int(pose)
        if not mech.positions:
            raise InputError(f"{name}: {mech.name} has no built-in task positions (got position {n})")
        if not 1 <= n <= len(mech.positions):
            raise InputError(f"{name}: expected a task position 1..{len(mech.positions)}, got {n}")
        return mech.positions[n - 1], n
    if not isinstance(pose, (tuple, list)) or len(pose) != 2:
        raise TypeError(f"{name}: expected a Pose, (xyz, (seq, a1, a2, a3)), (xyz, R), (xyz, None) or a task position "
                        f"number, got {describe(pose)}")
    xyz, orient = pose
    p = _numbers(xyz, f"{name}[0] (xyz)", shape=(3,))
    if orient is None:
        R = np.eye(3)
    elif isinstance(orient, (tuple, list)) and len(orient) == 4 and isinstance(orient[0], str):
        seq, *angles = orient
        a = _numbers(angles, f"{name}[1] (angles)", shape=(3,))
        try:
            R = euler_matrix(seq, a, degrees=degrees)
        except InputError as e:
            raise InputError(f"{name}[1] (orientation): {e}") from None
    elif isinstance(orient, (tuple, list, np.ndarray)):
        R = _numbers(orient, f"{name}[1] (rotation matrix)", shape=(3, 3))
    else:
        raise TypeError(f"{name}[1]: expected (seq, a1, a2, a3), a 3x3 rotation matrix or None, got {describe(orient)}")
    try:
        return Pose(R, p, "requested"), None
    except InputError as e:
        raise InputError(f"{name}: {e}") from None


def _configuration(mech: Mechanism, pose, config, degrees: bool, *, pose_name: str = "pose"
                   ) -> tuple[Configuration, PoseFit | None]:
    """The configuration to analyse: ``config`` itself, the closed configuration nearest to
    ``pose`` (with its fit), or the reference configuration when neither is given."""
    if pose is not None and config is not None:
        raise InputError(f"{pose_name}/config: give a pose or a configuration, not both")
    if config is not None:
        if not isinstance(config, Configuration):
            raise TypeError(f"config: expected a Configuration, got {describe(config)}")
        check_configuration(mech, config)
        return config, None
    if pose is None:
        return Configuration.reference(mech), None
    P, _ = _pose(mech, pose, degrees, pose_name)
    fit = configuration_at_pose(mech, P)
    if not fit.converged:
        raise InputError(f"{pose_name}: no closed configuration near it (residual {fit.ik_residual:.2e})")
    return fit.config, fit


# ============================================================================ mobility
def mobility(model: ModelLike, mode: str | None = None, *, seed: int = 0, tol=None) -> MobilityResult:
    """Mobility by the modified Kutzbach-Grübler formula, checked numerically (one mode of a
    metamorphic mechanism: ``mode``; every mode: :func:`mobility_modes`).  ``tol``: a
    :class:`~spatialmech.geometry.tolerances.Tolerances` or the rank tolerance (default: the
    tolerances in force).

    >>> import spatialmech as sm
    >>> r = sm.mobility("four-sps-cu")
    >>> (r.dof, r.motion)
    (4, 'RxRyRzTz')
    """
    mech = _mechanism(model)
    if mode is not None and not isinstance(mode, str):
        raise TypeError(f"mode: expected a mode name (str) or None, got {describe(mode)}")
    return _mobility(mech, mode, seed=_check_int(seed, "seed"), tol=tol)


@dataclass(frozen=True, eq=False)
class MobilityModes:
    """The mobility of every motion mode (a sequence of
    :class:`~spatialmech.analysis.mobility.MobilityResult`; one for an ordinary mechanism)."""

    mechanism: Mechanism
    modes: tuple[MobilityResult, ...]

    def __iter__(self):
        return iter(self.modes)

    def __len__(self) -> int:
        return len(self.modes)

    def __getitem__(self, k):
        return self.modes[k]

    def to_dict(self) -> dict:
        return {"metamorphic": self.mechanism.is_metamorphic, "modes": [r.to_dict() for r in self.modes]}


def mobility_modes(model: ModelLike, *, seed: int = 0, tol=None) -> MobilityModes:
    """Mobility of every motion mode (one result for a mechanism that is not metamorphic);
    ``to_dict()`` is the payload of ``spatialmech mobility --json``.

    >>> import spatialmech as sm
    >>> [r.dof for r in sm.mobility_modes("three-rrr-sm")]
    [1, 1, 1, 2, 2, 2, 3]
    """
    mech = _mechanism(model)
    return MobilityModes(mech, tuple(_mobility_modes(mech, seed=_check_int(seed, "seed"), tol=tol)))


# ============================================================================ position
#: The note on ``pose_fit`` in the JSON of ``ik`` (as ``spatialmech ik --json``).
_IK_FIT_NOTE = ("the pose does not close exactly (printed, rounded data?); pose_fit is the nearest closed "
                "configuration (configuration_at_pose); within the tolerance (pose_error: the larger of the "
                "angle error in rad and the position error over the characteristic length) the pose is "
                "reachable and the solutions are those of the fitted pose")


@dataclass(frozen=True, eq=False)
class IKResult:
    """Inverse position: every limb's joint values for one platform pose (:attr:`result`).

    A pose that does not close exactly (printed, rounded data) is fitted onto the closure:
    :attr:`pose_fit` says how far the nearest closed configuration is; within the
    ``reachability`` tolerance the pose counts as reachable (``result.fitted``)."""

    mechanism: Mechanism
    pose: Pose
    result: InverseResult
    position: int | None = None
    reachability: float = 0.0  # the reachability tolerance used (nondimensional)
    #: With ``free``: the task solve (the coordinates held and the parasitic ones solved).
    task: TaskSolution | None = None

    @property
    def reachable(self) -> bool:
        return self.result.reachable

    @property
    def pose_fit(self) -> PoseFit | None:
        return self.result.pose_fit

    @property
    def config(self) -> Configuration | None:
        """The configuration of the first solution of every limb (``None`` if not reachable)."""
        return self.result.config

    @property
    def actuators(self) -> dict[str, float]:
        """Actuator values (SI: rad, length), by freedom id; raises when not reachable."""
        return self.result.actuator_values(self.mechanism)

    def to_dict(self) -> dict:
        d = self.result.to_dict(self.mechanism)
        fit = self.pose_fit
        d["pose_fit"] = None if fit is None else {**fit.to_dict(), "tolerance": self.reachability, "note": _IK_FIT_NOTE}
        d["task"] = None if self.task is None else task_solution_dict(self.task)
        return d


def ik(model: ModelLike, pose, *, all_solutions: bool = False, n_seeds: int = 48, seed: int = 0,
       degrees: bool = False, tol=None, free=None) -> IKResult:
    """Inverse position: the joint values of every limb for a platform pose.

    ``all_solutions``: also ``n_seeds`` random starts per limb (every real solution it finds).
    ``tol``: a :class:`~spatialmech.geometry.tolerances.Tolerances` or the closure tolerance.
    ``free``: task coordinates to solve (names from ``x, y, z, a1, a2, a3``; angles in the pose's
    Euler sequence, ``"ZYX"`` when it gives none): for a lower-mobility mechanism, the parasitic
    ones (:attr:`IKResult.task` has the solved values); the others are held at the pose's values.

    >>> import spatialmech as sm
    >>> r = sm.ik("three-rps", ([0, 0, 0.33], ("ZYX", 0, 5, 5)), degrees=True, free=["x", "y", "a1"])
    >>> r.reachable, [round(v, 6) for v in r.actuators.values()]
    (True, [0.374613, 0.366706, 0.347013])

    >>> r = sm.ik("four-sps-cu", ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46)), degrees=True)
    >>> [round(v, 4) for v in r.actuators.values()]
    [0.2167, 0.239, 0.2273, 0.2069]
    """
    mech = _mechanism(model)
    degrees = _check_bool(degrees, "degrees")
    all_solutions = _check_bool(all_solutions, "all_solutions")
    P, position = _pose(mech, pose, degrees)
    task = None
    if free is not None:
        names = _names(free, "free") or []
        task = solve_pose(mech, P, names, euler=_pose_sequence(pose))
        if task.converged:
            P = Pose(task.D[:3, :3], task.D[:3, :3] @ mech.platform_point + task.D[:3, 3], "requested, solved")
    res = inverse_position(mech, P, all_solutions=all_solutions, n_seeds=_check_int(n_seeds, "n_seeds", minimum=1),
                           seed=_check_int(seed, "seed"), tol=tol, fit=True,
                           start=task.config if task is not None and task.converged else None)
    return IKResult(mech, P, res, position, resolve_tolerances(tol, "closure").reachability, task)


@dataclass(frozen=True, eq=False)
class FKResult:
    """Forward position: the platform pose(s) for actuator values.

    ``result`` is the general engine's :class:`~spatialmech.kinematics.position.ForwardResult`, or,
    for ``all_solutions`` on a 4-SPS/CU of paper B's layout, the closed form's
    ``ForwardAllResult`` (``closed_form`` is True)."""

    mechanism: Mechanism
    actuator_values: np.ndarray  # SI (rad, length), in mechanism.actuators order
    result: object
    closed_form: bool = False

    @property
    def poses(self) -> tuple[Pose, ...]:
        """The platform pose of every converged solution (assembly mode)."""
        if self.closed_form:
            from .kinematics.closed_forms import four_sps_cu as k4

            return tuple(Pose(k4.rotation(s.phi), k4.pose_transform(s.phi)[:3, 3], f"mode {n + 1}")
                         for n, s in enumerate(self.result.solutions) if s.converged)
        return tuple(s.pose for s in self.result.solutions if s.converged)

    @property
    def converged(self) -> bool:
        """At least one assembly was found."""
        return bool(self.poses)

    def to_dict(self) -> dict:
        if self.closed_form:
            return self.result.to_dict(actuators=self.mechanism.actuators)
        return self.result.to_dict(self.mechanism)


def fk(model: ModelLike, actuators, *, all_solutions: bool = False, seeds: int | None = None, seed: int = 0,
       degrees: bool = False, progress: Progress | None = None) -> FKResult:
    """Forward position: platform pose(s) for actuator values (``actuators``: a sequence in the
    order of ``mechanism.actuators`` or a mapping by freedom name; lengths in the model's unit,
    rotations in radians, or degrees with ``degrees=True``).

    From the reference configuration by Newton; ``all_solutions``: every assembly mode a
    multi-start search finds (``seeds`` starts: default 200, 512 on the 4-SPS/CU closed form).
    Nothing is raised when no assembly is found: see ``converged`` and ``to_dict()``.

    >>> import spatialmech as sm
    >>> r = sm.fk("stewart-6sps", [1.2] * 6)
    >>> r.converged, len(r.poses)
    (True, 1)
    >>> r = sm.fk("four-sps-cu", [0.216745, 0.23896, 0.227321, 0.206933], all_solutions=True)   # closed form
    >>> sorted(round(float(P.p[2]), 3) for P in r.poses)      # the pose z = 0.12 m, another mode, two mirrors
    [-0.149, -0.12, 0.12, 0.149]
    """
    mech = _mechanism(model)
    degrees = _check_bool(degrees, "degrees")
    all_solutions = _check_bool(all_solutions, "all_solutions")
    acts = list(mech.actuators)
    if not acts:
        raise InputError(f"model: {mech.name} has no actuators")
    if isinstance(actuators, Mapping):
        vals = {}
        for k, v in actuators.items():
            if not isinstance(k, str):
                raise TypeError(f"actuators: expected freedom names as keys, got {describe(k)}")
            x = float(_numbers(v, f"actuators[{k!r}]", shape=()))
            vals[mech.freedom(k).id] = np.radians(x) if degrees and mech.freedom(k).freedom.kind != "P" else x
        missing = [a for a in acts if a not in vals]
        if missing:
            raise InputError(f"actuators: missing values for {', '.join(missing)} (actuators: {', '.join(acts)})")
        extra = sorted(set(vals) - set(acts))
        if extra:
            raise InputError(f"actuators: {', '.join(extra)} are not actuated in {mech.name} (actuators: {', '.join(acts)})")
        values = np.array([vals[a] for a in acts])
    else:
        raw = _numbers(actuators, "actuators")
        if raw.shape != (len(acts),):
            raise InputError(f"actuators: {mech.name} has {len(acts)} actuators ({', '.join(acts)}), got shape {raw.shape}")
        values = np.array([np.radians(v) if degrees and mech.freedom(a).freedom.kind != "P" else v
                           for a, v in zip(acts, raw, strict=True)])
    if seeds is not None:
        seeds = _check_int(seeds, "seeds", minimum=1)
    seed = _check_int(seed, "seed")
    progress = _progress(progress)
    if all_solutions:
        from .kinematics.closed_forms import four_sps_cu as k4

        geom = k4.geometry_of(mech)
        if geom is not None:
            fa = k4.forward_all(values, geometry=geom, **({} if seeds is None else {"n_seeds": seeds}))
            return FKResult(mech, values, fa, True)
    res: ForwardResult = forward_position(mech, values, all_solutions=all_solutions,
                                          n_seeds=200 if seeds is None else seeds, seed=seed, progress=progress)
    return FKResult(mech, values, res)


# ============================================================================ Jacobian, velocity
@dataclass(frozen=True, eq=False)
class JacobianResult:
    """The complete Jacobian (:attr:`jacobian`) at one configuration, and the fit of the
    requested pose onto the closure (``None`` when a configuration was given)."""

    mechanism: Mechanism
    config: Configuration
    jacobian: CompleteJacobian
    pose_fit: PoseFit | None = None
    pose: Pose | None = None  # the requested pose (default: the configuration's)
    #: Lower-mobility models: the input-output Jacobian over the given task coordinates
    #: (``None`` when the output link has six freedoms).
    task: TaskJacobian | None = None

    @property
    def det(self) -> float | None:
        return self.jacobian.det

    @property
    def sigma_min(self) -> float:
        return self.jacobian.sigma_min

    def to_dict(self) -> dict:
        P = self.pose if self.pose is not None else platform_pose(self.mechanism, self.config)
        return {"result": "complete_jacobian", "pose": pose_dict(P.R, P.p), **self.jacobian.to_dict(),
                "pose_fit": None if self.pose_fit is None else self.pose_fit.to_dict(),
                "task_jacobian": None if self.task is None else self.task.to_dict(self.mechanism)}


def jacobian(model: ModelLike, pose=None, *, config: Configuration | None = None, drivers=None,
             degrees: bool = False, free=None) -> JacobianResult:
    """The complete Jacobian (constraint + actuation wrenches), ``det J`` and its conditioning at
    a pose (fitted onto the closure), a configuration, or the reference configuration; for a
    lower-mobility model also :attr:`JacobianResult.task`, the input-output Jacobian over the
    given task coordinates (the parasitic ones solved).

    ``drivers``: the actuated freedom(s) (default: the model's actuators).  ``free``: as in
    :func:`ik`, task coordinates to solve, the others held at the pose's values (and the
    coordinates of the input-output Jacobian; default: the model's task).

    >>> import spatialmech as sm
    >>> J = sm.jacobian("five-cs-1", 3, drivers="rot1")
    >>> J.det > 0, J.jacobian.matrix.shape, J.pose_fit.exact
    (True, (6, 6), False)
    >>> J = sm.jacobian("three-rps", ([0, 0, 0.33], ("ZYX", 0, 5, 5)), degrees=True, free=["x", "y", "a1"])
    >>> J.task.given, J.task.matrix.shape
    (('z', 'a2', 'a3'), (3, 3))
    """
    mech = _mechanism(model)
    degrees = _check_bool(degrees, "degrees")
    drivers = _names(drivers, "drivers")
    task = None
    if free is not None:
        if pose is None or config is not None:
            raise InputError("free: needs a pose (and no config): the coordinates not named are held at its values")
        names = _names(free, "free") or []
        P, _ = _pose(mech, pose, degrees)
        sol = solve_pose(mech, P, names, euler=_pose_sequence(pose))
        if not sol.converged:
            raise InputError(f"free: the held coordinates do not close with {', '.join(names)} solved ({sol.status}, "
                             f"residual {sol.residual:.2e}); the pose is out of reach")
        task = sol.task
        solved = Pose(sol.D[:3, :3], sol.D[:3, :3] @ mech.platform_point + sol.D[:3, 3], "requested, solved")
        fit = configuration_at_pose(mech, solved, start=sol.config)
        if not fit.converged:
            raise InputError(f"pose: no closed configuration near it (residual {fit.ik_residual:.2e})")
        c, requested = fit.config, solved
    else:
        c, fit = _configuration(mech, pose, config, degrees)
        requested = _pose(mech, pose, degrees)[0] if pose is not None else None
    return JacobianResult(mech, c, complete_jacobian(mech, c, drivers), fit, requested,
                          task_jacobian_at(mech, c, drivers, task=task))


def _pose_sequence(pose) -> str:
    """The Euler sequence a pose tuple names (``"ZYX"`` when it names none)."""
    if (isinstance(pose, (tuple, list)) and len(pose) == 2 and isinstance(pose[1], (tuple, list))
            and len(pose[1]) == 4 and isinstance(pose[1][0], str)):
        return pose[1][0]
    return "ZYX"


@dataclass(frozen=True, eq=False)
class VelocityResult:
    """Platform twist ``(omega ; v)`` (rad/s; ``v``: velocity of the body point at the origin,
    length unit/s) and every joint rate (local coordinates, rad/s or length/s) at one
    configuration.  ``given``: ``"twist"`` (inverse velocity) or ``"actuator_rates"`` (forward)."""

    mechanism: Mechanism
    config: Configuration
    twist: np.ndarray
    joint_rates: np.ndarray
    given: str
    pose_fit: PoseFit | None = None

    @property
    def actuator_rates(self) -> dict[str, float]:
        """The actuators' rates (SI), by freedom id."""
        ids = [r.id for r in self.mechanism.freedom_refs]
        return {a: float(self.joint_rates[ids.index(a)]) for a in self.mechanism.actuators}

    def to_dict(self) -> dict:
        from .serialize import freedom_values_dict

        ids = [r.id for r in self.mechanism.freedom_refs]
        rates = freedom_values_dict(self.mechanism, dict(zip(ids, self.joint_rates, strict=True)), "joint_rates")
        d = {
            "given": self.given,
            "twist_convention": "(omega ; v), v = velocity of the body point at the origin",
            "omega_deg_per_s": [float(x) for x in np.degrees(self.twist[:3])],
            "v_len_per_s": [float(x) for x in self.twist[3:]],
            "joint_rates_deg_per_s": rates["joint_rates_deg"],
            "joint_rates_len_per_s": rates["joint_rates_len"],
            "actuators": list(self.mechanism.actuators),
        }
        if self.pose_fit is not None:
            d["pose_fit"] = self.pose_fit.to_dict()
        return d


def velocity(model: ModelLike, pose=None, *, config: Configuration | None = None, twist=None, actuator_rates=None,
             drivers=None, degrees: bool = False) -> VelocityResult:
    """Velocity analysis at a pose (fitted onto the closure), a configuration or the reference
    configuration: give the platform ``twist`` ``(omega ; v)`` (inverse velocity: the joint
    rates) or the ``actuator_rates`` of ``drivers`` (default: the model's actuators; forward
    velocity: the twist and the joint rates).  Rates in SI (rad/s, length/s); ``degrees=True``:
    angular rates and pose angles in degrees.

    >>> import spatialmech as sm
    >>> v = sm.velocity("four-sps-cu", ([0, 0, 0.12], ("ZYX", 30, -5, 10)), twist=[0, 0, 0, 0, 0, 0.01], degrees=True)
    >>> sorted(round(r, 4) for r in v.actuator_rates.values())
    [0.0047, 0.0053, 0.0059, 0.0064]
    """
    from .kinematics.velocity import forward_velocity, inverse_velocity

    mech = _mechanism(model)
    degrees = _check_bool(degrees, "degrees")
    if (twist is None) == (actuator_rates is None):
        raise InputError("twist/actuator_rates: give exactly one of them")
    drivers = _names(drivers, "drivers")
    c, fit = _configuration(mech, pose, config, degrees)
    if twist is not None:
        V = _numbers(twist, "twist", shape=(6,))
        if degrees:
            V = np.r_[np.radians(V[:3]), V[3:]]
        qd = inverse_velocity(mech, c, V)
        return VelocityResult(mech, c, V, qd, "twist", fit)
    ids = drivers if drivers is not None else list(mech.actuators)
    r = _numbers(actuator_rates, "actuator_rates", shape=(len(ids),))
    if degrees:
        r = np.array([np.radians(x) if mech.freedom(a).freedom.kind != "P" else x for a, x in zip(ids, r, strict=True)])
    V, qd = forward_velocity(mech, c, r, drivers)
    return VelocityResult(mech, c, np.asarray(V, float), qd, "actuator_rates", fit)


# ============================================================================ singularity, workspace
@dataclass(frozen=True, eq=False)
class SingularityAnalysis:
    """The singularity analysis at one configuration (:attr:`result`, a
    :class:`~spatialmech.analysis.singularity.SingularityResult`: ``kind``, ``rank``, ``twist``,
    ``line_geometry``, ``self_motion`` ...; its attributes are readable here directly)."""

    mechanism: Mechanism
    config: Configuration
    result: object
    pose_fit: PoseFit | None = None

    def __getattr__(self, name):
        if name.startswith("_") or name == "result":
            raise AttributeError(name)
        return getattr(self.result, name)

    def to_dict(self) -> dict:
        return {"result": "singularity", **self.result.to_dict()}


def singularity(model: ModelLike, pose=None, *, config: Configuration | None = None, drivers=None,
                degrees: bool = False) -> SingularityAnalysis:
    """Singularity analysis at a pose (fitted onto the closure), a configuration, or the
    reference configuration: rank and kind (:class:`~spatialmech.results.SingularityKind`),
    uncontrolled twists, line geometry of the wrenches, finite self-motion.

    >>> import spatialmech as sm
    >>> r = sm.singularity("four-sps-cu")            # the reference pose, alpha = beta = 0
    >>> r.kind, r.kind.singular
    (<SingularityKind.DIRECT: 'direct'>, True)
    """
    from .analysis.singularity import singularity as _singularity

    mech = _mechanism(model)
    degrees = _check_bool(degrees, "degrees")
    drivers = _names(drivers, "drivers")
    c, fit = _configuration(mech, pose, config, degrees)
    return SingularityAnalysis(mech, c, _singularity(mech, c, drivers), fit)


def workspace(model: ModelLike, *, kind: str = "orientation", at: Mapping[str, float] | None = None,
              step: float | None = None, tol=None, bounds=None, method: str = "auto",
              link_diameter: float | None = None, interference: bool = True, max_poses: int | None = None,
              progress: Progress | None = None, over: Mapping | None = None, free=None, limits=None):
    """Workspace under joint limits (strokes, joint cones, link interference), sampled and
    refined at the boundary: ``kind="orientation"`` at a fixed position (free angles alpha,
    beta, gamma of ``R = Rz(gamma) Ry(beta) Rx(alpha)``), or ``"position"`` at a fixed
    orientation.  SI and radians: ``at`` fixes coordinates (``x, y, z`` length,
    ``alpha, beta, gamma`` rad); ``step``/``tol`` are radians (orientation; default 2 deg and
    0.001 deg) or lengths (position).  ``link_diameter`` overrides the interference check's
    capsules, ``interference=False`` skips it; ``limits`` (a
    :class:`~spatialmech.analysis.workspace.WorkspaceLimits`) replaces the default limits.
    Returns a :class:`~spatialmech.analysis.workspace.WorkspaceResult`.

    ``kind="task"``: over the task coordinates of a lower-mobility mechanism (docs/workspace.md):
    ``over`` maps 1 to 3 given task coordinates (``x, y, z`` length, ``a1, a2, a3`` rad) to
    ``(lo, hi, n)`` or grid values, ``at`` holds other given ones, ``free`` names the coordinates
    to solve (default: the model's task); ``tol`` is the boundary tolerance (a number, or by
    coordinate; default 1e-3 of the grid step), ``max_poses`` the largest grid.  The parasitic
    coordinates are solved at every cell.  Returns a
    :class:`~spatialmech.analysis.workspace.TaskWorkspaceResult`.

    >>> import numpy as np, spatialmech as sm
    >>> ws = sm.workspace("four-sps-cu", at={"z": 0.1}, step=np.radians(10))
    >>> round(float(np.degrees(ws.alone["alpha"].hi)), 1), ws.alone["alpha"].hi_limit
    (26.6, 'A1 cone')
    >>> t = sm.workspace("three-rps", kind="task", over={"a2": (-0.2, 0.2, 3), "a3": (-0.2, 0.2, 3)}, at={"z": 0.33})
    >>> t.solved, t.reachable_fraction
    (('x', 'y', 'a1'), 1.0)
    """
    from .analysis.workspace import WorkspaceLimits, default_limits, orientation_workspace, position_workspace

    mech = _mechanism(model)
    kind = _check_choice(kind, "kind", ("orientation", "position", "task"))
    method = _check_choice(method, "method", ("auto", "closed-form", "general"))
    interference = _check_bool(interference, "interference")
    if at is not None and not isinstance(at, Mapping):
        raise TypeError(f"at: expected a mapping of coordinate -> value (SI, rad), got {describe(at)}")
    step = _check_number(step, "step", positive=True, optional=True)
    if kind != "task" or not isinstance(tol, Mapping):
        tol = _check_number(tol, "tol", positive=True, optional=True)
    link_diameter = _check_number(link_diameter, "link_diameter", optional=True)
    if link_diameter is not None and link_diameter < 0:
        raise InputError(f"link_diameter: expected a non-negative length, got {link_diameter}")
    if max_poses is not None:
        max_poses = _check_int(max_poses, "max_poses", minimum=1)
    if limits is not None and not isinstance(limits, WorkspaceLimits):
        raise TypeError(f"limits: expected a WorkspaceLimits, got {describe(limits)}")
    limits = default_limits(mech) if limits is None else limits
    if link_diameter is not None or not interference:
        limits = WorkspaceLimits(limits.cones, link_diameter if interference else None, limits.freedom_limits, limits.source)
    if kind == "task":
        return _task_workspace(mech, over, at, free, limits, tol, step, bounds, max_poses, progress)
    for name, value in (("over", over), ("free", free)):
        if value is not None:
            raise InputError(f"{name}: only with kind='task' (the workspace over task coordinates)")
    kw = dict(at=at, limits=limits, bounds=bounds, method=method, max_poses=max_poses, progress=_progress(progress))
    if kind == "orientation":
        return orientation_workspace(mech, step=np.radians(2.0) if step is None else step,
                                     tol=np.radians(1e-3) if tol is None else tol, **kw)
    return position_workspace(mech, step=step, tol=tol, **kw)


def _task_workspace(mech: Mechanism, over, at, free, limits, tol, step, bounds, max_poses, progress):
    """``workspace(kind="task")``: the checks of its own arguments, then the analysis."""
    from .analysis.workspace import task_workspace
    from .model.task import TASK_NAMES, TaskCoordinates

    if over is None:
        raise InputError("over: kind='task' needs the grid: {coordinate: (lo, hi, n)} over task coordinates "
                         "(x, y, z length; a1, a2, a3 rad)")
    if not isinstance(over, Mapping):
        raise TypeError(f"over: expected a mapping of task coordinate -> (lo, hi, n) or values, got {describe(over)}")
    for name, value in (("step", step), ("bounds", bounds)):
        if value is not None:
            raise InputError(f"{name}: not with kind='task' (the grid is given by over)")
    task = None
    if free is not None:
        names = [free] if isinstance(free, str) else free
        if not isinstance(names, Sequence) or not all(isinstance(n, str) for n in names):
            raise TypeError(f"free: expected task coordinate names, got {describe(free)}")
        own = mech.task.euler if mech.task is not None else "ZYX"
        for n in names:
            if n not in TASK_NAMES:
                raise InputError(f"free: unknown task coordinate {n!r}; expected some of {', '.join(TASK_NAMES)}")
        task = TaskCoordinates(tuple(n for n in TASK_NAMES if n not in names), own)
    return task_workspace(mech, over, at=at, task=task, limits=limits, tol=tol, max_cells=max_poses,
                          progress=_progress(progress))


def parasitic(model: ModelLike, over: Mapping, *, at: Mapping[str, float] | None = None, free=None,
              euler: str | None = None, plot=None, progress: Progress | None = None):
    """The parasitic motion of a lower-mobility mechanism: its solved task coordinates over a grid
    of one or two given ones (``spatialmech parasitic``, docs/lower-mobility.md).

    SI and radians: ``over`` maps the grid's given coordinates (``x, y, z`` length, ``a1, a2, a3``
    rad) to ``(lo, hi, n)`` or increasing values; ``at`` holds other given ones (default: their
    reference values); ``free`` names the coordinates to solve (default: those the model's task
    does not give) and ``euler`` the sequence of ``a1, a2, a3`` (default: the model's task's, else
    ``"ZYX"``).  ``plot``: a figure file (.png, .pdf, .svg), one panel per solved coordinate.
    Returns a :class:`~spatialmech.analysis.parasitic.ParasiticTable` (``values(name)``,
    ``ranges``, ``to_dict()``).

    >>> import spatialmech as sm
    >>> t = sm.parasitic("three-rps", {"a2": (-0.1, 0.1, 3), "a3": (-0.1, 0.1, 3)}, at={"z": 0.33})
    >>> t.solved, {n: round(hi, 6) for n, (lo, hi) in t.ranges.items()}
    (('x', 'y', 'a1'), {'x': 0.000747, 'y': 0.000375, 'a1': 0.005008})
    """
    from .analysis.parasitic import parasitic_table
    from .kinematics.task import default_task
    from .model.task import TASK_NAMES, TaskCoordinates

    mech = _mechanism(model)
    if not isinstance(over, Mapping):
        raise TypeError(f"over: expected a mapping of task coordinate -> (lo, hi, n) or values, got {describe(over)}")
    if at is not None and not isinstance(at, Mapping):
        raise TypeError(f"at: expected a mapping of task coordinate -> value (SI, rad), got {describe(at)}")
    if euler is not None and not isinstance(euler, str):
        raise TypeError(f"euler: expected a named Euler sequence such as 'ZYX', got {describe(euler)}")
    task = None
    if free is not None or euler is not None:
        seq = euler if euler is not None else (mech.task.euler if mech.task is not None else "ZYX")
        if free is None:
            given = default_task(mech, seq).given  # the model's own task, else the default
        else:
            names = _names(free, "free") or []
            for n in names:
                if n not in TASK_NAMES:
                    raise InputError(f"free: unknown task coordinate {n!r}; expected some of {', '.join(TASK_NAMES)}")
            given = tuple(n for n in TASK_NAMES if n not in names)
        task = TaskCoordinates(given, seq)
    path = None if plot is None else _path(plot, "plot")
    if path is not None and path.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise InputError(f"plot: expected a .png, .pdf or .svg file, got {str(path)!r}")
    table = parasitic_table(mech, over, at=at, task=task, progress=_progress(progress))
    if path is not None:
        from .present.parasitic import parasitic_figure

        parasitic_figure(table.grid, path)
    return table


# ============================================================================ tracking
@dataclass(frozen=True, eq=False)
class TraceResult:
    """The one-degree-of-freedom motion traced by continuation (:attr:`result`, a
    :class:`~spatialmech.kinematics.tracking.TrackResult` whose points are configurations), with
    the sign changes of DJ of the actuators as events (zeros: branch points)."""

    mechanism: Mechanism
    result: object

    @property
    def status(self) -> TrackStatus:
        return self.result.status

    @property
    def closed(self) -> bool:
        return self.result.closed

    @property
    def configurations(self) -> list[Configuration]:
        return self.result.points

    @property
    def poses(self) -> list[Pose]:
        return [platform_pose(self.mechanism, c) for c in self.result.points]

    def to_dict(self) -> dict:
        from .serialize import freedom_values_dict

        tr, mech = self.result, self.mechanism
        ids = [r.id for r in mech.freedom_refs]
        q = np.array([freedom_values(mech, c.q) for c in tr.points]).reshape(len(tr.points), len(ids))
        values = freedom_values_dict(mech, dict.fromkeys(ids, 0.0), "joint_values")
        deg = {fid: [float(x) for x in np.degrees(q[:, ids.index(fid)])] for fid in values["joint_values_deg"]}
        lin = {fid: [float(x) for x in q[:, ids.index(fid)]] for fid in values["joint_values_len"]}
        return {
            "status": tr.status,
            "reason": tr.reason,
            "ok": tr.ok,
            "closed": tr.closed,
            "points": len(tr.points),
            "arc_length": float(tr.s[-1]),
            "arc": [float(s) for s in tr.s],
            "events": [{"name": e.name, "arc": float(e.s), "kind": e.kind} for e in tr.events],
            "rejected_steps": tr.rejected,
            "platform_points_len": [[float(x) for x in p.p] for p in self.poses],
            "joint_values_deg": deg,
            "joint_values_len": lin,
            "units": {"arc": "nondimensional arc length (joint rad, lengths / characteristic length)"},
        }


def track(model: ModelLike, start=None, *, increasing: str | None = None, sense: int = 1, max_arc: float = 50.0,
          max_steps: int = 20000, h0: float = 0.02, degrees: bool = False,
          progress: Progress | None = None) -> TraceResult:
    """Follow the one-degree-of-freedom motion by pseudo-arclength continuation from ``start``
    (a pose, fitted onto the closure; a Configuration; default the reference) until it closes
    (``status`` closed) or the arc length reaches ``max_arc`` (nondimensional).  ``increasing``:
    a freedom whose variable grows at the start (``sense=-1``: decreases).  The sign changes of
    DJ of the actuators are located as events.

    >>> import spatialmech as sm
    >>> m = sm.track("bennett")
    >>> m.status, m.closed
    (<TrackStatus.CLOSED: 'closed'>, True)
    """
    from .analysis.defects import dj_function
    from .kinematics.tracking import trace_motion

    mech = _mechanism(model)
    degrees = _check_bool(degrees, "degrees")
    if increasing is not None and not isinstance(increasing, str):
        raise TypeError(f"increasing: expected a freedom name (str) or None, got {describe(increasing)}")
    sense = _check_int(sense, "sense")
    if sense not in (-1, 1):
        raise InputError(f"sense: expected +1 or -1, got {sense}")
    max_arc = _check_number(max_arc, "max_arc", positive=True)
    h0 = _check_number(h0, "h0", positive=True)
    max_steps = _check_int(max_steps, "max_steps", minimum=1)
    if isinstance(start, Configuration):
        c, _ = _configuration(mech, None, start, degrees)
    else:
        c, _ = _configuration(mech, start, None, degrees, pose_name="start")
    acts = list(mech.actuators)
    mon = None
    if acts:
        try:
            f, _ = dj_function(mech, acts, c)
            mon = (["DJ " + a for a in acts], f)
        except InputError:
            mon = None  # DJ undefined here (e.g. an actuator is locked): trace without events
    tr = trace_motion(mech, c, increasing=increasing, sense=sense, vector_monitor=mon, max_arc=max_arc,
                      max_steps=max_steps, h0=h0, progress=_progress(progress))
    return TraceResult(mech, tr)


# ============================================================================ defects
def dj_table(model: ModelLike, drivers=None, positions=None):
    """DJ (det of the complete Jacobian) at the model's task positions, per driver (default:
    every base-joint freedom); only the signs along one driver are comparable.  Returns a
    :class:`~spatialmech.analysis.defects.DJTable`.

    >>> import spatialmech as sm
    >>> t = sm.dj_table("five-cs-3", ["rot1", "rot3"])
    >>> t.keeps_sign("rot1"), t.keeps_sign("rot3")
    (True, False)
    """
    from .analysis.defects import dj_table as _dj_table

    mech = _mechanism(model)
    return _dj_table(mech, _names(drivers, "drivers"), _positions(positions))


def _positions(positions) -> tuple[Pose, ...] | None:
    """``None``, a TOML file of ``[[positions]]``, or a sequence of Pose."""
    if positions is None:
        return None
    if isinstance(positions, (str, os.PathLike)):
        from .model.schema import load_positions

        return load_positions(positions)
    if not isinstance(positions, Sequence):
        raise TypeError(f"positions: expected a sequence of Pose or a TOML file path, got {describe(positions)}")
    for k, p in enumerate(positions):
        if not isinstance(p, Pose):
            raise TypeError(f"positions[{k}]: expected a Pose, got {describe(p)}")
    return tuple(positions)


def defects(model: ModelLike, positions=None, *, drivers=None, pose_tol: float | None = None,
            angle_tol_deg: float = 1.0, monte_carlo: int = 0, seed: int = 0, precision: float = 5e-4,
            progress: Progress | None = None):
    """Circuit, branch and order defects of a one-degree-of-freedom linkage for its task
    positions (``positions``: default the model's own; a sequence of Pose or a TOML file),
    the drivers that can be used, and a dual-drive plan when no single one can (paper A).
    Returns a :class:`~spatialmech.analysis.defects.DefectResult` (``circuit_status``:
    :class:`~spatialmech.results.TrackStatus`).

    >>> import spatialmech as sm
    >>> motion = sm.track("planar-4r")                  # three positions on its circuit, in order
    >>> P = [motion.poses[k] for k in (0, 9, 18)]
    >>> r = sm.defects("planar-4r", P)
    >>> r.circuit_defect, r.order_defect, r.usable_drivers, r.circuit_status
    (False, False, ('A0.rot',), (<TrackStatus.CLOSED: 'closed'>,))
    """
    from .analysis.defects import defect_analysis

    mech = _mechanism(model)
    positions = _positions(positions)
    pose_tol = _check_number(pose_tol, "pose_tol", positive=True, optional=True)
    angle_tol_deg = _check_number(angle_tol_deg, "angle_tol_deg", positive=True)
    precision = _check_number(precision, "precision")
    return defect_analysis(mech, positions, drivers=_names(drivers, "drivers"), pose_tol=pose_tol,
                           angle_tol_deg=angle_tol_deg, monte_carlo=_check_int(monte_carlo, "monte_carlo", minimum=0),
                           seed=_check_int(seed, "seed"), precision=precision, progress=_progress(progress))


# ============================================================================ synthesis
def synth_rccc(task="rccc-four-positions", *, pick: str = "best-rc", samples: int = 360):
    """Four-position RCCC synthesis by solution regions (paper D).  ``task``: a ready-made task
    name, a TOML task file, or a ``TaskPositions``; ``pick``: ``"best-rc"`` (the smallest
    largest input slide) or ``"interior"`` (the most interior defect-free crank-rocker);
    ``samples`` per Burmester-curve branch.  Returns a
    :class:`~spatialmech.synthesis.RCCCResult` (``linkage`` is a Mechanism).

    >>> import spatialmech as sm
    >>> r = sm.synth_rccc(samples=60)
    >>> r.linkage_type, r.defects
    ('crank-rocker', 0)
    """
    from .synthesis.rccc import synthesize_rccc
    from .synthesis.tasks import TaskPositions, resolve_task

    if not isinstance(task, (str, os.PathLike, TaskPositions)):
        raise TypeError(f"task: expected a task name, a TOML file path or a TaskPositions, got {describe(task)}")
    pick = _check_choice(pick, "pick", ("best-rc", "interior"))
    samples = _check_int(samples, "samples", minimum=8)
    return synthesize_rccc(resolve_task(task), pick=pick, samples=samples)


@dataclass(frozen=True, eq=False)
class CSSynthesisResult:
    """Seven-position CS dyad synthesis (paper A): the one-parameter ``family`` of dyads, the
    picked dyads (``family.picks``), and with five picks the assembled 5-CS ``linkage`` and its
    ``check`` at the seven positions."""

    family: object
    positions_source: str
    samples: int
    linkage: Mechanism | None = None
    check: object | None = None

    @property
    def success(self) -> bool | None:
        """The 5-CS closes at the seven positions with one degree of freedom and (when its defects
        were checked) is defect-free for some driver; ``None`` without a 5-CS."""
        return None if self.check is None else self.check.success

    def to_dict(self) -> dict:
        d = {**self.family.to_dict(samples=self.samples), "positions_source": self.positions_source,
             "five_cs": None, "success": None, "verdict": None}
        if self.check is not None:
            d["five_cs"] = self.check.to_dict()
            d["success"] = self.check.success
            d["verdict"] = self.check.verdict()
        return d


def synth_cs(positions=None, *, pick: int = 5, starts: int = 60, seed: int = 0, samples: int = 40,
             check_defects: bool = True, progress: Progress | None = None) -> CSSynthesisResult:
    """Seven-position synthesis of CS dyads and a 5-CS linkage (paper A, section 3).
    ``positions``: seven task poses -- default paper A's table 9; a model name or Mechanism (its
    task positions), a TOML file of ``[[positions]]``, or a sequence of Pose.  ``starts`` random
    starts (``seed``); ``pick`` small-slide dyads (5: also assemble and check the 5-CS, and with
    ``check_defects`` its circuit, order and branch defects, about a minute; ``progress``
    reports on it); ``samples``: family points listed in ``to_dict()``.

    >>> import spatialmech as sm
    >>> r = sm.synth_cs(pick=0, starts=4)
    >>> len(r.family.branches) >= 1, r.linkage is None
    (True, True)
    """
    from .synthesis.cs_dyads import assemble_5cs, check_5cs, synthesize_cs

    pick = _check_int(pick, "pick", minimum=0)
    check_defects = _check_bool(check_defects, "check_defects")
    progress = _progress(progress)
    starts = _check_int(starts, "starts", minimum=1)
    seed = _check_int(seed, "seed")
    samples = _check_int(samples, "samples", minimum=2)
    if positions is None:
        from .catalog.papers import five_cs_positions

        poses, source = five_cs_positions(), "paper A table 9"
    elif isinstance(positions, Mechanism) or (isinstance(positions, str) and positions in catalog.REGISTRY):
        mech = _mechanism(positions, "positions")
        poses, source = mech.positions, f"the task positions of {mech.name}"
    else:
        poses = _positions(positions)
        source = os.fspath(positions) if isinstance(positions, (str, os.PathLike)) else "given poses"
    fam = synthesize_cs(poses, n_starts=starts, seed=seed, pick=pick)
    if pick != 5:
        return CSSynthesisResult(fam, source, samples)
    if len(fam.picks) < 5:
        raise InputError(f"pick: only {len(fam.picks)} well separated dyads found; try more starts")
    linkage = assemble_5cs(fam.task, fam.picks)
    check = check_5cs(linkage, fam.picks, defects=check_defects, progress=progress)
    return CSSynthesisResult(fam, source, samples, linkage, check)


# ============================================================================ report, viewer
@dataclass(frozen=True, eq=False)
class ReportResult:
    """A report written into ``out``: ``index.html`` (opens offline), ``results.json`` (every
    number: :attr:`data`) and ``figures/``.  ``to_dict()`` is ``data`` without the model name
    (the payload of ``spatialmech report --json``, whose envelope names the model)."""

    out: Path
    data: dict

    @property
    def index_html(self) -> Path:
        return self.out / "index.html"

    @property
    def results_json(self) -> Path:
        return self.out / "results.json"

    def to_dict(self) -> dict:
        return {k: v for k, v in self.data.items() if k != "model"}


def report(model: ModelLike, out=None, *, trace: bool = True, progress: bool | Progress | None = None) -> ReportResult:
    """Every analysis that applies to one model, written as a report into the directory
    ``out`` (default ``report-NAME``): mobility of every mode, the complete Jacobian, DJ at the
    task positions, the traced motion (1 DOF; ``trace=False`` skips it) and a 3-D viewer.
    ``progress``: True prints on stderr, or a callback.

    >>> import spatialmech as sm, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     r = sm.report("planar-4r", d, trace=False)
    ...     r.index_html.exists(), r.data["model"]
    (True, 'planar-4r')
    """
    from .present.report import build_model_report

    mech = _mechanism(model)
    trace = _check_bool(trace, "trace")
    if progress is not None and not isinstance(progress, bool):
        progress = check_progress(progress)
    out = Path(f"report-{mech.name}") if out is None else _path(out, "out")
    if out.exists() and not out.is_dir():
        raise InputError(f"out: {out} is a file, not a directory")
    out.mkdir(parents=True, exist_ok=True)  # fail now on an unwritable directory, not after the work
    data = build_model_report(mech, out, progress=False if progress is None else progress, trace=trace)
    return ReportResult(out, data)


def _path(value, name: str) -> Path:
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name}: expected a path (str or os.PathLike), got {describe(value)}")
    return Path(value)


#: The motions :func:`view` can animate.
VIEW_MOTIONS = ("auto", "trace", "demo")


@dataclass(frozen=True, eq=False)
class ViewResult:
    """The viewer page written (:attr:`file`: ``out``, ``frames``, ``bytes``) and the motion shown
    (``"trace"`` or ``"demo"``)."""

    file: object
    motion: str

    @property
    def out(self) -> str:
        return self.file.out

    @property
    def frames(self) -> int:
        return self.file.frames

    @property
    def bytes(self) -> int:
        return self.file.bytes

    def to_dict(self) -> dict:
        return {**self.file.to_dict(), "motion": self.motion}


def view(model: ModelLike, out, *, motion: str = "auto", frames: int = 60) -> ViewResult:
    """Write the interactive 3-D viewer of a model (one self-contained HTML file, opens
    offline) animated along a motion: ``"trace"`` (1 DOF: the whole circuit by continuation,
    with the zeros of DJ marked), ``"demo"`` (a short loop along the closure manifold, any
    mobility) or ``"auto"`` (trace when the mechanism has one degree of freedom).

    >>> import spatialmech as sm, tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     v = sm.view("rssr", os.path.join(d, "rssr.html"), frames=12)
    ...     v.frames, v.bytes > 100_000
    (12, True)
    """
    from .present.motion import sample_motion, traced_motion
    from .present.viewer import write_viewer

    mech = _mechanism(model)
    motion = _check_choice(motion, "motion", VIEW_MOTIONS)
    frames = _check_int(frames, "frames", minimum=2)
    out = _path(out, "out")
    if out.is_dir():
        raise InputError(f"out: {out} is a directory; give a file name")
    if not out.parent.is_dir():
        raise InputError(f"out: cannot write {out}: the directory {out.parent} does not exist")
    singular = ()
    if motion == "auto":
        motion = "trace" if (not mech.is_metamorphic and _mobility(mech).dof_instantaneous == 1) else "demo"
    if motion == "trace":
        configs, singular = traced_motion(mech, frames=frames)
        title = (f"{mech.name}: the traced circuit ({len(configs)} frames); x: DJ zeros of "
                 f"{', '.join(mech.actuators[:1]) or '-'}")
    else:
        configs = sample_motion(mech, n=frames)
        title = f"{mech.name}: a demonstration loop, {len(configs)} configurations (not the tracker)"
    written = write_viewer(out, mech, configs, title=title, task_positions=mech.positions, singular_points=singular)
    return ViewResult(written, motion)
