"""The public API: singularity, workspace and parasitic motion (``sm.singularity``,
``sm.workspace``, ``sm.parasitic``): where the mechanism can go, and where it loses control."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InputError, describe, require
from ..kinematics.closure import Configuration
from ..kinematics.position import PoseFit
from ..model.mechanism import Mechanism
from ..results import Progress

if TYPE_CHECKING:  # the analyses are imported where they run (lazily): their types only here
    from ..analysis.parasitic import ParasiticTable
    from ..analysis.singularity import SingularityResult
    from ..analysis.workspace import TaskWorkspaceResult, WorkspaceLimits, WorkspaceResult

from .checks import (
    ModelLike,
    as_mechanism,
    check_bool,
    check_choice,
    check_int,
    check_names,
    check_number,
    check_path,
    optional_progress,
    where,
)
from .threads import one_blas_thread


@dataclass(frozen=True, eq=False)
class SingularityAnalysis:
    """The singularity analysis at one configuration (:attr:`result`, a
    :class:`~spatialmech.analysis.singularity.SingularityResult`: ``kind``, ``rank``, ``twist``,
    ``line_geometry``, ``self_motion`` ...; its attributes are readable here directly)."""

    mechanism: Mechanism
    config: Configuration
    result: SingularityResult
    pose_fit: PoseFit | None = None

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_") or name == "result":
            raise AttributeError(name)
        return getattr(self.result, name)

    def to_dict(self) -> dict:
        return {"result": "singularity", **self.result.to_dict()}


@one_blas_thread
def singularity(model: ModelLike, pose=None, *, config: Configuration | None = None, drivers=None,
                degrees: bool = False) -> SingularityAnalysis:
    """Singularity analysis at a pose, a configuration, or the reference configuration.

    Rank and kind (:class:`~spatialmech.results.SingularityKind`), uncontrolled twists, line
    geometry of the wrenches, finite self-motion.

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

    Returns
    -------
    SingularityAnalysis
        ``result`` (:class:`~spatialmech.analysis.singularity.SingularityResult`, its attributes
        readable directly: ``kind``, ``rank``, ``twist``, ``line_geometry``, ``self_motion``
        ...), ``config``, ``pose_fit``; ``to_dict()`` is the payload of
        ``spatialmech singularity --json``.

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
    >>> r = sm.singularity("four-sps-cu")            # the reference pose, alpha = beta = 0
    >>> r.kind, r.kind.singular
    (<SingularityKind.DIRECT: 'direct'>, True)
    """
    from ..analysis.singularity import singularity as _singularity

    w = where(model, pose, config, drivers, degrees)
    return SingularityAnalysis(w.mech, w.config, _singularity(w.mech, w.config, w.drivers), w.fit)


@one_blas_thread
def workspace(model: ModelLike, *, kind: str = "orientation", at: Mapping[str, float] | None = None,
              step: float | None = None, tol=None, bounds=None, method: str = "auto",
              link_diameter: float | None = None, interference: bool = True, max_poses: int | None = None,
              progress: Progress | None = None, over: Mapping | None = None, free=None, limits=None,
              cones: Mapping[str, float] | None = None, freedom_limits: Mapping | None = None,
              max_general_poses: int | None = None) -> WorkspaceResult | TaskWorkspaceResult:
    """Workspace under joint limits (strokes, joint cones, link interference).

    Sampled and refined at the boundary: ``kind="orientation"`` at a fixed position (free
    angles alpha, beta, gamma of ``R = Rz(gamma) Ry(beta) Rx(alpha)``), ``"position"`` at a
    fixed orientation, or ``"task"`` over the task coordinates of a lower-mobility mechanism
    (docs/workspace.md; the parasitic coordinates solved at every cell).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    kind : {"orientation", "position", "task"}
        The workspace computed.
    at : mapping, optional
        Fixed coordinates (``x, y, z`` length unit, ``alpha, beta, gamma`` rad; task: other
        given task coordinates held).
    step : float, optional
        The sampling step: rad (orientation; default 2 deg) or length unit (position).
    tol : float or mapping, optional
        The boundary tolerance: rad (orientation; default 0.001 deg) or length unit (position);
        task: a number or by coordinate (default 1e-3 of the grid step).
    bounds : mapping, optional
        Coordinate -> ``(lo, hi)`` searched (SI, rad; not with ``kind="task"``).
    method : {"auto", "closed-form", "general"}
        The pose checker (the 4-SPS/CU's closed form, or the general per-pose path).
    link_diameter : float, optional
        Overrides the interference check's capsule diameter (length unit).
    interference : bool
        ``False`` skips the interference check.
    max_poses : int, optional
        The largest grid.
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.
    over : mapping, optional
        ``kind="task"``: 1 to 3 given task coordinates (``x, y, z`` length, ``a1, a2, a3`` rad)
        -> ``(lo, hi, n)`` or grid values.
    free : str or sequence of str, optional
        ``kind="task"``: the coordinates to solve (default: the model's task).
    limits : WorkspaceLimits, optional
        Replaces the default limits (:class:`~spatialmech.analysis.workspace.WorkspaceLimits`).
    cones : mapping, optional
        Extra cone limits of S or U joints: joint name -> largest angle (rad) between the link at
        the joint and the platform's ``z`` axis (the base's at a limb's first joint).
    freedom_limits : mapping, optional
        Replaces the limits of freedoms' values: name -> ``(lo, hi)`` (SI, rad; ``"actuators"``
        sets every actuator).
    max_general_poses : int, optional
        The largest grid on the general (per-pose) path when ``max_poses`` is not given.

    Returns
    -------
    WorkspaceResult or TaskWorkspaceResult
        A :class:`~spatialmech.analysis.workspace.WorkspaceResult` (orientation, position:
        ``alone`` extents with the limits that bound them, the sampled grid) or, with
        ``kind="task"``, a :class:`~spatialmech.analysis.workspace.TaskWorkspaceResult`
        (``solved``, ``reachable_fraction`` ...); ``to_dict()`` is its JSON.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
    SearchTooLargeError
        The grid exceeds ``max_poses`` (an ``InputError``).

    Examples
    --------
    >>> import numpy as np, spatialmech as sm
    >>> ws = sm.workspace("four-sps-cu", at={"z": 0.1}, step=np.radians(10))
    >>> round(float(np.degrees(ws.alone["alpha"].hi)), 1), ws.alone["alpha"].hi_limit
    (26.6, 'A1 cone')
    >>> t = sm.workspace("three-rps", kind="task", over={"a2": (-0.2, 0.2, 3), "a3": (-0.2, 0.2, 3)}, at={"z": 0.33})
    >>> t.solved, t.reachable_fraction
    (('x', 'y', 'a1'), 1.0)
    """
    from ..analysis.workspace import orientation_workspace, pose_checker, position_workspace

    mech = _with_freedom_limits(as_mechanism(model), freedom_limits)
    kind = check_choice(kind, "kind", ("orientation", "position", "task"))
    method = check_choice(method, "method", ("auto", "closed-form", "general"))
    interference = check_bool(interference, "interference")
    if at is not None and not isinstance(at, Mapping):
        raise TypeError(f"at: expected a mapping of coordinate -> value (SI, rad), got {describe(at)}")
    step = check_number(step, "step", positive=True, optional=True)
    if kind != "task" or not isinstance(tol, Mapping):
        tol = check_number(tol, "tol", positive=True, optional=True)
    link_diameter = check_number(link_diameter, "link_diameter", optional=True)
    if link_diameter is not None and link_diameter < 0:
        raise InputError(f"link_diameter: expected a non-negative length, got {link_diameter}")
    if max_poses is not None:
        max_poses = check_int(max_poses, "max_poses", minimum=1)
    if max_general_poses is not None:
        max_general_poses = check_int(max_general_poses, "max_general_poses", minimum=1)
    limits = _workspace_limits(mech, limits, cones, link_diameter, interference)
    if kind == "task":
        return _task_workspace(mech, over, at, free, limits, tol, step, bounds, max_poses, progress)
    for name, value in (("over", over), ("free", free)):
        if value is not None:
            raise InputError(f"{name}: only with kind='task' (the workspace over task coordinates)")
    if max_poses is None and max_general_poses is not None and pose_checker(mech, limits, method=method).path == "general":
        max_poses = max_general_poses
    kw = dict(at=at, limits=limits, bounds=bounds, method=method, max_poses=max_poses, progress=optional_progress(progress))
    if kind == "orientation":
        return orientation_workspace(mech, step=np.radians(2.0) if step is None else step,
                                     tol=np.radians(1e-3) if tol is None else tol, **kw)
    return position_workspace(mech, step=step, tol=tol, **kw)


def _with_freedom_limits(mech: Mechanism, freedom_limits) -> Mechanism:
    """``mech`` with other limits on some freedoms (``workspace(freedom_limits=...)``; the name
    ``"actuators"`` sets every actuator)."""
    from ..analysis.workspace import with_freedom_limits

    if freedom_limits is None:
        return mech
    if not isinstance(freedom_limits, Mapping):
        raise TypeError(f"freedom_limits: expected a mapping of freedom -> (lo, hi), got {describe(freedom_limits)}")
    named = {fid: rng for name, rng in freedom_limits.items()
             for fid in (mech.actuators if name == "actuators" else (name,))}
    return with_freedom_limits(mech, named) if named else mech


def _workspace_limits(mech: Mechanism, limits, cones, link_diameter, interference: bool) -> WorkspaceLimits:
    """The limits of ``workspace``: ``limits`` (default: the model's), with the extra ``cones``
    and the interference check's ``link_diameter`` (none without ``interference``)."""
    from ..analysis.workspace import ConeLimit, WorkspaceLimits, default_limits

    if limits is not None and not isinstance(limits, WorkspaceLimits):
        raise TypeError(f"limits: expected a WorkspaceLimits, got {describe(limits)}")
    limits = default_limits(mech) if limits is None else limits
    if cones:
        if not isinstance(cones, Mapping):
            raise TypeError(f"cones: expected a mapping of joint -> angle (rad), got {describe(cones)}")
        first = {limb.joints[0].name for limb in mech.limbs if limb.joints}
        extra = tuple(ConeLimit(j, (0.0, 0.0, 1.0), "base" if j in first else "platform",
                                check_number(a, f"cones[{j}]", positive=True)) for j, a in cones.items())
        limits = WorkspaceLimits(limits.cones + extra, limits.link_diameter, limits.freedom_limits,
                                 (limits.source + " + " if limits.source else "") + "cones")
    if link_diameter is not None or not interference:
        limits = WorkspaceLimits(limits.cones, link_diameter if interference else None, limits.freedom_limits, limits.source)
    return limits


def _task_workspace(mech: Mechanism, over, at, free, limits, tol, step, bounds, max_poses,
                    progress) -> TaskWorkspaceResult:
    """``workspace(kind="task")``: the checks of its own arguments, then the analysis."""
    from ..analysis.workspace import task_workspace
    from ..model.task import TASK_NAMES, TaskCoordinates

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
                          progress=optional_progress(progress))


@one_blas_thread
def parasitic(model: ModelLike, over: Mapping, *, at: Mapping[str, float] | None = None, free=None,
              euler: str | None = None, plot=None, progress: Progress | None = None) -> ParasiticTable:
    """The parasitic motion of a lower-mobility mechanism over a grid of given coordinates.

    Its solved task coordinates over a grid of one or two given ones (``spatialmech parasitic``,
    docs/lower-mobility.md).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    over : mapping
        The grid's given coordinates (``x, y, z`` length unit, ``a1, a2, a3`` rad) -> ``(lo, hi, n)``
        or increasing values.
    at : mapping, optional
        Other given coordinates held (default: their reference values; SI, rad).
    free : str or sequence of str, optional
        The coordinates to solve (default: those the model's task does not give).
    euler : str, optional
        The Euler sequence of ``a1, a2, a3`` (default: the model's task's, else ``"ZYX"``).
    plot : str or path, optional
        A figure file (.png, .pdf, .svg), one panel per solved coordinate.
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.

    Returns
    -------
    ParasiticTable
        :class:`~spatialmech.analysis.parasitic.ParasiticTable`: ``solved``, ``values(name)``
        (arrays of the grid's shape), ``ranges``; ``to_dict()`` is its JSON.

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
    >>> t = sm.parasitic("three-rps", {"a2": (-0.1, 0.1, 3), "a3": (-0.1, 0.1, 3)}, at={"z": 0.33})
    >>> t.solved, {n: round(hi, 6) for n, (lo, hi) in t.ranges.items()}
    (('x', 'y', 'a1'), {'x': 0.000747, 'y': 0.000375, 'a1': 0.005008})
    """
    from ..analysis.parasitic import parasitic_table
    from ..geometry.rotations import check_sequence
    from ..kinematics.task import default_task
    from ..model.task import TASK_NAMES, TaskCoordinates

    mech = as_mechanism(model)
    if not isinstance(over, Mapping):
        raise TypeError(f"over: expected a mapping of task coordinate -> (lo, hi, n) or values, got {describe(over)}")
    if at is not None and not isinstance(at, Mapping):
        raise TypeError(f"at: expected a mapping of task coordinate -> value (SI, rad), got {describe(at)}")
    if euler is not None and not isinstance(euler, str):
        raise TypeError(f"euler: expected a named Euler sequence such as 'ZYX', got {describe(euler)}")
    task = None
    if free is not None or euler is not None:
        seq = euler if euler is not None else (mech.task.euler if mech.task is not None else "ZYX")
        try:
            check_sequence(seq)
        except InputError as e:
            raise InputError(f"euler: {str(e).split(': ', 1)[-1]}") from None
        if free is None:
            try:
                given = default_task(mech, seq).given  # the model's own task, else the default
            except np.linalg.LinAlgError:
                raise InputError(f"euler: the angles of {seq!r} are singular (gimbal lock) at the reference pose of "
                                 f"{mech.name}: choose another sequence, or name the solved coordinates (free)"
                                 ) from None
        else:
            names = check_names(free, "free") or []
            for n in names:
                if n not in TASK_NAMES:
                    raise InputError(f"free: unknown task coordinate {n!r}; expected some of {', '.join(TASK_NAMES)}")
            given = tuple(n for n in TASK_NAMES if n not in names)
        task = TaskCoordinates(given, seq)
    path = None if plot is None else check_path(plot, "plot")
    if path is not None and path.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise InputError(f"plot: expected a .png, .pdf or .svg file, got {str(path)!r}")
    if path is not None:  # before any work: the extra to install
        require("plot", "matplotlib", what="plot")
    table = parasitic_table(mech, over, at=at, task=task, progress=optional_progress(progress))
    if path is not None:
        from ..present.parasitic import parasitic_figure

        parasitic_figure(table.grid, path)
    return table
