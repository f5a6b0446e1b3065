"""The public API: position, Jacobian and velocity (``sm.ik``, ``sm.fk``, ``sm.jacobian``,
``sm.velocity``); singularity, workspace and parasitic motion are in :mod:`.spaces`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError, describe
from ..geometry.tolerances import resolve as resolve_tolerances
from ..kinematics.closed_forms.four_sps_cu_forward import ForwardAllResult
from ..kinematics.closure import Configuration
from ..kinematics.dispatch import AssemblyMode, Engine, ForwardAnswer, pose_with_free, solve_forward, solve_inverse
from ..kinematics.forward import ForwardResult
from ..kinematics.jacobian import CompleteJacobian, complete_jacobian
from ..kinematics.plausibility import plausibility_warnings
from ..kinematics.position import InverseResult, PoseFit, configuration_at_pose, platform_pose
from ..kinematics.task import TaskJacobian, TaskSolution, default_task, task_jacobian_at, task_solution_dict
from ..model.mechanism import Mechanism, Pose
from ..model.task import TaskCoordinates
from ..results import Progress
from ..serialize import html_summary, pose_dict

if TYPE_CHECKING:  # the analyses are imported where they run (lazily): their types only here
    pass

from .checks import (
    ModelLike,
    as_mechanism,
    as_pose,
    check_bool,
    check_choice,
    check_int,
    check_names,
    check_numbers,
    optional_progress,
    pose_sequence,
    where,
)
from .threads import one_blas_thread

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
        """Every limb closes at the pose and, with ``free``, the task solve converged (a pose whose
        held coordinates did not close with the others solved is not the pose asked for)."""
        return self.result.reachable and (self.task is None or self.task.converged)

    @property
    def proven_unreachable(self) -> bool:
        """Not reachable, and proven so: every limb's search complete (``all_solutions`` with a
        proof) and found nothing, the task solve (if any) converged."""
        return (not self.result.reachable and bool(self.result.search.get("complete"))
                and (self.task is None or self.task.converged))

    @property
    def warnings(self) -> list[str]:
        """Plausibility (:func:`~spatialmech.kinematics.plausibility.plausibility_warnings`): a pose
        or actuator far beyond the model's size (a unit mistake?), a negative leg length."""
        acts = self.actuators if self.result.config is not None else {}
        return plausibility_warnings(self.mechanism, [self.pose.p], acts)

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

    @property
    def default_task(self) -> TaskCoordinates:
        """The model's task coordinates (its own, else those its output link's freedoms give):
        fewer than six given ones say a full pose is reachable only with the others ``free``."""
        return default_task(self.mechanism)

    def to_dict(self) -> dict:
        d = self.result.to_dict(self.mechanism)
        fit = self.pose_fit
        d["pose_fit"] = None if fit is None else {**fit.to_dict(), "tolerance": self.reachability, "note": _IK_FIT_NOTE}
        d["task"] = None if self.task is None else task_solution_dict(self.task)
        d["reachable"] = bool(self.reachable)
        d["warnings"] = self.warnings
        return d

    def _repr_html_(self) -> str:  # a notebook's display: the fields and one row per limb
        return html_summary(f"ik: {self.mechanism.name}", self.to_dict(), "limbs", ("limb", "reachable", "passive_dim"))


@one_blas_thread
def ik(model: ModelLike, pose, *, all_solutions: bool = False, n_seeds: int = 48, seed: int = 0,
       degrees: bool = False, tol=None, free=None, method: str = "auto", certify: bool = True) -> IKResult:
    """Inverse position: the joint values of every limb for a platform pose.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    pose : Pose, tuple or int
        The platform (output link) pose: a :class:`~spatialmech.Pose`, ``(xyz, (seq, a1, a2, a3))``
        (``xyz`` shape (3,) in the model's length unit, a named Euler sequence and its angles: rad,
        degrees with ``degrees=True``), ``(xyz, R)`` (``R`` shape (3, 3), a rotation matrix),
        ``(xyz, None)`` (the reference orientation) or ``int`` N, the model's N-th task position
        (from 1).
    all_solutions : bool
        Every real solution of each limb (``method``), listed nearest the reference
        configuration first; ``actuators`` and ``config`` are each limb's first.  Without it,
        one solution per limb: Gauss-Newton from the reference (normally its working mode).
    n_seeds : int
        Random starts per limb with ``all_solutions``.
    seed : int
        Their random seed.
    degrees : bool
        Read the angles of a pose tuple (and angular values) in degrees instead of radians.
    tol : Tolerances or float, optional
        A :class:`~spatialmech.geometry.tolerances.Tolerances` or the closure tolerance
        (nondimensional; default: the tolerances in force).
    free : str or sequence of str, optional
        Task coordinates to solve (names from ``x, y, z, a1, a2, a3``; angles in the pose's Euler
        sequence, ``"ZYX"`` when it gives none): for a lower-mobility mechanism, the parasitic
        ones; the others are held at the pose's values.
    method : {"auto", "homotopy", "multistart"}
        With ``all_solutions``, how every solution is searched: ``"auto"`` (a registered closed
        form, else per limb homotopy continuation where it covers the limb and a root count
        proves it complete, else the multi-start, labelled not proven), ``"homotopy"`` (every
        limb it covers, proven by a root count or the trace test) or ``"multistart"``.  The
        result's ``to_dict()["search"]`` says per limb the method and its completeness.
    certify : bool
        Certify each solution the homotopy returns (a Krawczyk test in ball arithmetic: a unique
        real root of the limb's exact system near it, distinct from the others; ``certified`` per
        solution and ``n_certified`` in ``to_dict()``, docs/homotopy.md); ``False`` skips it
        (``certified`` is then ``None``, as for the multi-start).

    Returns
    -------
    IKResult
        ``reachable``, ``actuators`` (SI: rad, length, by freedom id), ``config``, every limb's
        solutions (``result``), ``pose_fit`` (a pose that does not close exactly is fitted onto the
        closure) and, with ``free``, ``task`` (the solved coordinates); ``to_dict()`` is the payload
        of ``spatialmech ik --json``.  An unreachable pose is not an error: see ``reachable``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.ik("three-rps", ([0, 0, 0.33], ("ZYX", 0, 5, 5)), degrees=True, free=["x", "y", "a1"])
    >>> r.reachable, [round(v, 6) for v in r.actuators.values()]
    (True, [0.374613, 0.366706, 0.347013])

    >>> r = sm.ik("four-sps-cu", ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46)), degrees=True)
    >>> [round(v, 4) for v in r.actuators.values()]
    [0.2167, 0.239, 0.2273, 0.2069]
    """
    mech = as_mechanism(model)
    degrees = check_bool(degrees, "degrees")
    all_solutions = check_bool(all_solutions, "all_solutions")
    P, position = as_pose(mech, pose, degrees)
    names = None if free is None else (check_names(free, "free") or [])
    from ..kinematics.homotopy.certify import certification

    with certification(check_bool(certify, "certify")):
        ans = solve_inverse(mech, P, all_solutions=all_solutions, n_seeds=check_int(n_seeds, "n_seeds", minimum=1),
                            seed=check_int(seed, "seed"), tol=tol, free=names, euler=pose_sequence(pose),
                            method=check_choice(method, "method", ("auto", "homotopy", "multistart")))
    return IKResult(mech, ans.pose, ans.result, position, resolve_tolerances(tol, "closure").reachability, ans.task)


@dataclass(frozen=True, eq=False)
class FKResult:
    """Forward position: the platform pose(s) for actuator values, the same fields whatever
    engine answered (:attr:`answer`, a :class:`~spatialmech.kinematics.dispatch.ForwardAnswer`):
    :attr:`engine`, :attr:`modes` (each an
    :class:`~spatialmech.kinematics.dispatch.AssemblyMode`), :attr:`complete` and
    :attr:`completeness`.  :attr:`result` is the engine's own result: the general engine's
    :class:`~spatialmech.kinematics.forward.ForwardResult`, or the 4-SPS/CU closed form's
    ``ForwardAllResult``."""

    mechanism: Mechanism
    actuator_values: np.ndarray  # SI (rad, length), in mechanism.actuators order
    answer: ForwardAnswer

    @property
    def engine(self) -> Engine:
        """``"newton"``, ``"multistart"``, ``"closed-form"``, ``"homotopy"`` or ``"monodromy"``."""
        return self.answer.engine

    @property
    def result(self) -> ForwardResult | ForwardAllResult:
        return self.answer.detail

    @property
    def closed_form(self) -> bool:
        return self.answer.engine == "closed-form"

    @property
    def complete(self) -> bool:
        """The assembly modes are proven complete (homotopy continuation)."""
        return self.answer.complete

    @property
    def completeness(self) -> str:
        return self.answer.completeness

    @property
    def modes(self) -> tuple[AssemblyMode, ...]:
        """Every converged result (assembly modes, singular roots, self-motion sets)."""
        return self.answer.modes

    @property
    def poses(self) -> tuple[Pose, ...]:
        """The platform pose of every converged solution (assembly mode)."""
        return tuple(m.pose for m in self.answer.modes)

    @property
    def converged(self) -> bool:
        """At least one assembly was found."""
        return bool(self.answer.modes)

    @property
    def warnings(self) -> list[str]:
        """Plausibility (:func:`~spatialmech.kinematics.plausibility.plausibility_warnings`): a
        platform point or an actuator slide far beyond the model's size (a unit mistake?), a
        negative leg length."""
        acts = dict(zip(self.mechanism.actuators, map(float, self.actuator_values), strict=True))
        return plausibility_warnings(self.mechanism, [m.pose.p for m in self.modes], acts)

    def to_dict(self) -> dict:
        return {**self.answer.to_dict(self.mechanism), "warnings": self.warnings}

    def _repr_html_(self) -> str:  # a notebook's display: the fields and one row per solution
        return html_summary(f"fk: {self.mechanism.name}", self.to_dict(), "solutions",
                            ("status", "pose", "kind", "sigma_min", "within_limits", "residual"))


@one_blas_thread
def fk(model: ModelLike, actuators, *, all_solutions: bool = False, seeds: int | None = None, seed: int | None = None,
       degrees: bool = False, progress: Progress | None = None, method: str = "auto", certify: bool = True) -> FKResult:
    """Forward position: platform pose(s) for actuator values.

    Without ``all_solutions``: one Newton solve from the reference configuration (``method``,
    ``seeds`` and ``seed`` are refused).  With ``all_solutions``, every assembly mode, by the
    engine ``method`` picks (:mod:`spatialmech.kinematics.dispatch`, docs/kinematics.md).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    actuators : array_like of shape (n_actuators,) or mapping
        The actuator values in the order of ``mechanism.actuators``, or a mapping by freedom name:
        lengths in the model's length unit, rotations in rad (degrees with ``degrees=True``).
    all_solutions : bool
        Every assembly mode instead of one Newton solve.
    seeds : int, optional
        The starts of a multi-start search (default 200; the closed form's 512; the starts the
        loop formulation adds when it is not proven complete); refused where homotopy in Study
        parameters answers (it takes no starts).
    seed : int, optional
        The random seed (the closed form's quasi-random sequence).
    degrees : bool
        Rotational actuator values in degrees.
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.
    method : {"auto", "closed-form", "homotopy", "multistart"}
        With ``all_solutions``: ``"auto"``: a registered closed form where one recognises the model
        (the 4-SPS/CU of paper B's layout, a multi-seed search, not a proof; a spherical 3-RRR
        wrist, a 5-CS linkage, a single loop of 4 to 7 R joints: proven complete), else homotopy
        continuation where it covers the model
        (S-P-S and R-P-S legs, passive C-U limbs: proven complete), else the loop formulation by
        monodromy (limbs of R, P, C, U, Sm and S joints; complete when its trace test passes),
        else the multi-start search; ``"closed-form"``: the registered closed form;
        ``"homotopy"``: homotopy continuation or the loop formulation, uncapped;
        ``"multistart"``: the general multi-start search (never a proof).
    certify : bool
        Certify each solution of ``all_solutions`` (a Krawczyk test in ball arithmetic: a unique
        root of the engine's exact polynomial system near it, distinct from the others: the Study
        formulation, real and also distinct from the complex end points; the closed forms'
        systems; the loop formulation's square system; ``certified`` per solution and
        ``n_certified`` in ``to_dict()``, docs/homotopy.md); ``False`` skips it (``certified`` is
        then ``None``, as for the multi-start).

    Returns
    -------
    FKResult
        ``engine`` (which answered), ``modes`` (each an
        :class:`~spatialmech.kinematics.dispatch.AssemblyMode`: pose, kind, conditioning),
        ``poses``, ``complete`` and ``completeness``, ``converged``; ``to_dict()`` is the payload of
        ``spatialmech fk --json``.  Nothing is raised when no assembly is found: see ``converged``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
        ``method``, ``seeds`` or ``seed`` the chosen engine would ignore; a ``method`` that does
        not cover the model.

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.fk("stewart-6sps", [1.2] * 6)
    >>> r.converged, len(r.poses), r.engine
    (True, 1, 'newton')
    >>> r = sm.fk("four-sps-cu", [0.216745, 0.23896, 0.227321, 0.206933], all_solutions=True)   # closed form
    >>> sorted(round(float(P.p[2]), 3) for P in r.poses)      # the pose z = 0.12 m, another mode, two mirrors
    [-0.149, -0.12, 0.12, 0.149]
    >>> r.engine, r.complete        # the closed form's poses, proven complete by the Study homotopy
    ('closed-form', True)
    """
    mech = as_mechanism(model)
    degrees = check_bool(degrees, "degrees")
    all_solutions = check_bool(all_solutions, "all_solutions")
    acts = list(mech.actuators)
    if not acts:
        raise InputError(f"model: {mech.name} has no actuators")
    if isinstance(actuators, Mapping):
        vals = {}
        for k, v in actuators.items():
            if not isinstance(k, str):
                raise TypeError(f"actuators: expected freedom names as keys, got {describe(k)}")
            x = float(check_numbers(v, f"actuators[{k!r}]", shape=()))
            vals[mech.freedom(k).id] = np.radians(x) if degrees and mech.freedom(k).freedom.kind != "P" else x
        missing = [a for a in acts if a not in vals]
        if missing:
            raise InputError(f"actuators: missing values for {', '.join(missing)} (actuators: {', '.join(acts)})")
        extra = sorted(set(vals) - set(acts))
        if extra:
            raise InputError(f"actuators: {', '.join(extra)} are not actuated in {mech.name} (actuators: {', '.join(acts)})")
        values = np.array([vals[a] for a in acts])
    else:
        raw = check_numbers(actuators, "actuators")
        if raw.shape != (len(acts),):
            raise InputError(f"actuators: {mech.name} has {len(acts)} actuators ({', '.join(acts)}), got shape {raw.shape}")
        values = np.array([np.radians(v) if degrees and mech.freedom(a).freedom.kind != "P" else v
                           for a, v in zip(acts, raw, strict=True)])
    if seeds is not None:
        seeds = check_int(seeds, "seeds", minimum=1)
    if seed is not None:
        seed = check_int(seed, "seed")
    method = check_choice(method, "method", ("auto", "closed-form", "homotopy", "multistart"))
    from ..kinematics.homotopy.certify import certification

    with certification(check_bool(certify, "certify")):
        ans = solve_forward(mech, values, all_solutions=all_solutions, method=method, seeds=seeds, seed=seed,
                            progress=optional_progress(progress))
    return FKResult(mech, values, ans)


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

    def _repr_html_(self) -> str:  # a notebook's display (matrices by their shape)
        return html_summary(f"jacobian: {self.mechanism.name}", self.to_dict())


def jacobian(model: ModelLike, pose=None, *, config: Configuration | None = None, drivers=None,
             degrees: bool = False, free=None) -> JacobianResult:
    """The complete Jacobian (constraint + actuation wrenches), ``det J`` and its conditioning.

    At a pose (fitted onto the closure), a configuration, or the reference configuration; for a
    lower-mobility model also :attr:`JacobianResult.task`, the input-output Jacobian over the
    given task coordinates (the parasitic ones solved).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    pose : Pose, tuple or int, optional
        The platform (output link) pose: a :class:`~spatialmech.Pose`, ``(xyz, (seq, a1, a2, a3))``
        (``xyz`` shape (3,) in the model's length unit, a named Euler sequence and its angles: rad,
        degrees with ``degrees=True``), ``(xyz, R)`` (``R`` shape (3, 3), a rotation matrix),
        ``(xyz, None)`` (the reference orientation) or ``int`` N, the model's N-th task position
        (from 1).  Fitted onto the closure; default: the reference configuration.
    config : Configuration, optional
        A configuration instead of a pose (not with ``pose``).
    drivers : str or sequence of str, optional
        The actuated freedoms (default: the model's actuators).
    degrees : bool
        Read the angles of a pose tuple (and angular values) in degrees instead of radians.
    free : str or sequence of str, optional
        Task coordinates to solve (names from ``x, y, z, a1, a2, a3``; angles in the pose's Euler
        sequence, ``"ZYX"`` when it gives none): for a lower-mobility mechanism, the parasitic
        ones; the others are held at the pose's values (needs ``pose``, not
        ``config``); also the coordinates of the input-output Jacobian (default: the model's task).

    Returns
    -------
    JacobianResult
        ``jacobian`` (:class:`~spatialmech.kinematics.jacobian.CompleteJacobian`: ``matrix`` of
        shape (6, 6) for a square problem, ``det``, ``sigma_min``, ``condition``), ``pose_fit``,
        ``task``; ``to_dict()`` is the payload of ``spatialmech jacobian --json``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
        A pose out of reach (no closed configuration near it, or the held coordinates do not
        close with ``free`` solved).

    Examples
    --------
    >>> import spatialmech as sm
    >>> J = sm.jacobian("five-cs-1", 3, drivers="rot1")
    >>> J.det > 0, J.jacobian.matrix.shape, J.pose_fit.exact
    (True, (6, 6), False)
    >>> J = sm.jacobian("three-rps", ([0, 0, 0.33], ("ZYX", 0, 5, 5)), degrees=True, free=["x", "y", "a1"])
    >>> J.task.given, J.task.matrix.shape
    (('z', 'a2', 'a3'), (3, 3))
    """
    if free is None:
        w = where(model, pose, config, drivers, degrees)
        return JacobianResult(w.mech, w.config, complete_jacobian(w.mech, w.config, w.drivers), w.fit, w.pose,
                              task_jacobian_at(w.mech, w.config, w.drivers))
    mech = as_mechanism(model)
    degrees = check_bool(degrees, "degrees")
    drivers = check_names(drivers, "drivers")
    if pose is None or config is not None:
        raise InputError("free: needs a pose (and no config): the coordinates not named are held at its values")
    names = check_names(free, "free") or []
    P, _ = as_pose(mech, pose, degrees)
    solved, sol = pose_with_free(mech, P, names, pose_sequence(pose))
    if not sol.converged:
        raise InputError(f"free: the held coordinates do not close with {', '.join(names)} solved ({sol.status}, "
                         f"residual {sol.residual:.2e}); the pose is out of reach")
    fit = configuration_at_pose(mech, solved, start=sol.config)
    if not fit.converged:
        raise InputError(f"pose: no closed configuration near it (residual {fit.ik_residual:.2e})")
    c = fit.config
    return JacobianResult(mech, c, complete_jacobian(mech, c, drivers), fit, solved,
                          task_jacobian_at(mech, c, drivers, task=sol.task))


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
        from ..serialize import freedom_values_dict

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
    """Velocity analysis: inverse (from the platform twist) or forward (from actuator rates).

    At a pose (fitted onto the closure), a configuration or the reference configuration; give
    exactly one of ``twist`` and ``actuator_rates``.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    pose : Pose, tuple or int, optional
        The platform (output link) pose: a :class:`~spatialmech.Pose`, ``(xyz, (seq, a1, a2, a3))``
        (``xyz`` shape (3,) in the model's length unit, a named Euler sequence and its angles: rad,
        degrees with ``degrees=True``), ``(xyz, R)`` (``R`` shape (3, 3), a rotation matrix),
        ``(xyz, None)`` (the reference orientation) or ``int`` N, the model's N-th task position
        (from 1).  Fitted onto the closure; default: the reference configuration.
    config : Configuration, optional
        A configuration instead of a pose (not with ``pose``).
    twist : array_like of shape (6,), optional
        The platform twist ``(omega ; v)``: ``omega`` rad/s (degrees/s with ``degrees=True``),
        ``v`` the velocity of the body point at the origin (length unit/s).  Inverse velocity.
    actuator_rates : array_like of shape (n_drivers,), optional
        The rates of ``drivers`` (rad/s or length unit/s; degrees/s with ``degrees=True``).
        Forward velocity.
    drivers : str or sequence of str, optional
        The actuated freedoms (default: the model's actuators).
    degrees : bool
        Angular rates and pose angles in degrees.

    Returns
    -------
    VelocityResult
        ``twist`` (shape (6,), SI), ``joint_rates`` (every freedom, SI), ``actuator_rates`` (by
        freedom id), ``given``; ``to_dict()`` is its JSON.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
        Both or neither of ``twist`` and ``actuator_rates``.

    Examples
    --------
    >>> import spatialmech as sm
    >>> v = sm.velocity("four-sps-cu", ([0, 0, 0.12], ("ZYX", 30, -5, 10)), twist=[0, 0, 0, 0, 0, 0.01], degrees=True)
    >>> sorted(round(r, 4) for r in v.actuator_rates.values())
    [0.0047, 0.0053, 0.0059, 0.0064]
    """
    from ..kinematics.velocity import forward_velocity, inverse_velocity

    if (twist is None) == (actuator_rates is None):
        raise InputError("twist/actuator_rates: give exactly one of them")
    w = where(model, pose, config, drivers, degrees)
    mech, c, fit, drivers, degrees = w.mech, w.config, w.fit, w.drivers, w.degrees
    if twist is not None:
        V = check_numbers(twist, "twist", shape=(6,))
        if degrees:
            V = np.r_[np.radians(V[:3]), V[3:]]
        qd = inverse_velocity(mech, c, V)
        return VelocityResult(mech, c, V, qd, "twist", fit)
    ids = drivers if drivers is not None else list(mech.actuators)
    r = check_numbers(actuator_rates, "actuator_rates", shape=(len(ids),))
    if degrees:
        r = np.array([np.radians(x) if mech.freedom(a).freedom.kind != "P" else x for a, x in zip(ids, r, strict=True)])
    V, qd = forward_velocity(mech, c, r, drivers)
    return VelocityResult(mech, c, np.asarray(V, float), qd, "actuator_rates", fit)
