"""The public API: analyses over a grid of poses or task coordinates -- singularity loci on a
2-D slice (``sm.singularity_slice``) and a first grid over the task coordinates of a
lower-mobility mechanism (``sm.suggest_task_grid``) -- and the names those grids use."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, overload

import numpy as np

from ..errors import InputError, describe
from ..model.mechanism import Mechanism
from ..model.task import TASK_NAMES, TaskCoordinates
from ..results import Progress
if TYPE_CHECKING:
    from ..analysis.singularity import SliceResult
    from ..analysis.task_slice import TaskSliceResult

from .checks import ModelLike, as_mechanism, check_bool, check_names, check_numbers, optional_progress
from .threads import one_blas_thread

# the names of grids and held coordinates, the largest grid: see constants.py
from .constants import TASK_COORDINATES as TASK_COORDINATES
from .constants import WORKSPACE_COORDINATES as WORKSPACE_COORDINATES
from .constants import WORKSPACE_MAX_POSES as WORKSPACE_MAX_POSES

__all__ = ["TASK_COORDINATES", "WORKSPACE_COORDINATES", "WORKSPACE_MAX_POSES", "TaskGridSuggestion",
           "singularity_slice", "suggest_task_grid", "task_coordinates"]


def task_coordinates(mech: Mechanism, free=None, euler: str | None = None) -> TaskCoordinates | None:
    """The task that solves the coordinates ``free`` and gives the others, in the Euler sequence
    ``euler`` (default: the model's task's, else ``"ZYX"``); ``None`` without ``free``."""
    if free is None:
        return None
    names = check_names(free, "free") or []
    for n in names:
        if n not in TASK_NAMES:
            raise InputError(f"free: unknown task coordinate {n!r}; expected some of {', '.join(TASK_NAMES)}")
    if euler is not None and not isinstance(euler, str):
        raise TypeError(f"euler: expected a named Euler sequence such as 'ZYX', got {describe(euler)}")
    seq = euler or (mech.task.euler if mech.task is not None else "ZYX")
    return TaskCoordinates(given=tuple(n for n in TASK_NAMES if n not in names), euler=seq)


def _grid(over, count: int) -> list[tuple[str, np.ndarray]]:
    if not isinstance(over, Mapping) or len(over) != count:
        raise TypeError(f"over: expected a mapping of {count} coordinates -> grid values, got {describe(over)}")
    return [(str(k), check_numbers(v, f"over[{k}]").reshape(-1)) for k, v in over.items()]


@overload
def singularity_slice(model: ModelLike, over: Mapping[str, Any], *, pose: None = None,
                      at: Mapping[str, float] | None = None, free=None, drivers=None, degrees: bool = False,
                      progress: Progress | None = None) -> TaskSliceResult: ...
@overload
def singularity_slice(model: ModelLike, over: Mapping[str, Any], *, pose: Sequence[Any],
                      at: None = None, free: None = None, drivers=None, degrees: bool = False,
                      progress: Progress | None = None) -> SliceResult: ...
@one_blas_thread
def singularity_slice(model: ModelLike, over: Mapping[str, Any], *, pose: Sequence[Any] | None = None,
                      at: Mapping[str, float] | None = None, free=None, drivers=None, degrees: bool = False,
                      progress: Progress | None = None) -> SliceResult | TaskSliceResult:
    """The singularity loci (zero set of ``det J``) and the scale-free ``sigma_min`` on a 2-D slice.

    With ``pose``: the slice varies that pose, each grid row solved by continuation from its
    neighbour.  Without: over the task coordinates of a lower-mobility mechanism, the parasitic
    ones solved at every point.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    over : mapping
        Two coordinates -> their grid values, shape (n,) each (the first the columns ``u``, the
        second the rows ``v``): with ``pose`` ``x, y, z`` (length unit) or ``a1, a2, a3`` (the
        pose's Euler angles: rad, degrees with ``degrees=True``); without, task coordinates (SI,
        rad).
    pose : tuple, optional
        ``(xyz, (seq, a1, a2, a3))``: ``xyz`` shape (3,) (length unit), a named Euler sequence
        and its angles (rad, degrees with ``degrees=True``).
    at : mapping, optional
        Without ``pose``: other given task coordinates held (SI, rad).
    free : str or sequence of str, optional
        Without ``pose``: the task coordinates to solve (default: the model's task).
    drivers : str or sequence of str, optional
        The actuated freedoms (default: the model's actuators).
    degrees : bool
        Read the angles of a pose tuple (and angular values) in degrees instead of radians.
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.

    Returns
    -------
    SliceResult or TaskSliceResult
        With ``pose`` a :class:`~spatialmech.analysis.singularity.SliceResult`, without a
        :class:`~spatialmech.analysis.task_slice.TaskSliceResult`: the grid, ``det`` and
        ``sigma_min`` arrays of shape (len(v), len(u)); ``to_dict()`` is its JSON.

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
    >>> import numpy as np, spatialmech as sm
    >>> s = sm.singularity_slice("three-rps", {"a2": np.radians([-10, 0, 10]), "a3": np.radians([-10, 0, 10])},
    ...                          at={"z": 0.33})
    >>> s.solved, bool(np.all(s.sigma_min > 0))
    (('x', 'y', 'a1'), True)
    """
    mech = as_mechanism(model)
    degrees = check_bool(degrees, "degrees")
    acts = check_names(drivers, "drivers")
    progress = optional_progress(progress)
    if pose is None:
        from ..analysis.task_slice import task_singularity_slice

        axes: dict[str, Any] = dict(_grid(over, 2))
        if degrees:
            axes = {k: np.radians(v) if k.startswith("a") else v for k, v in axes.items()}
        if at is not None and not isinstance(at, Mapping):
            raise TypeError(f"at: expected a mapping of task coordinate -> value (SI, rad), got {describe(at)}")
        return task_singularity_slice(mech, axes, at=at, task=task_coordinates(mech, free), actuators=acts,
                                      progress=progress)
    for name, value in (("at", at), ("free", free)):
        if value is not None:
            raise InputError(f"{name}: only for a slice over task coordinates (no pose); with a pose the slice "
                             "varies the pose itself")
    return _pose_slice(mech, _grid(over, 2), pose, acts, degrees, progress)


def _pose_slice(mech: Mechanism, axes, pose, acts, degrees: bool, progress) -> SliceResult:
    from ..analysis.singularity import singularity_slice as _slice
    from ..geometry.rotations import euler_matrix
    from ..kinematics.position import configuration_at_pose
    from ..model.mechanism import Pose

    (n1, g1), (n2, g2) = axes
    names = ("x", "y", "z", "a1", "a2", "a3")
    if n1 not in names or n2 not in names or n1 == n2:
        raise InputError(f"over: expected two different coordinates of {', '.join(names)}, got {n1!r}, {n2!r}")
    if (not isinstance(pose, (tuple, list)) or len(pose) != 2 or not isinstance(pose[1], (tuple, list))
            or len(pose[1]) != 4 or not isinstance(pose[1][0], str)):
        raise TypeError(f"pose: expected (xyz, (seq, a1, a2, a3)) for a slice around a pose, got {describe(pose)}")
    xyz = check_numbers(pose[0], "pose[0] (xyz)", shape=(3,))
    seq = pose[1][0]
    ang = check_numbers(pose[1][1:], "pose[1] (angles)", shape=(3,))
    if not degrees:  # the slice is computed (and reported) in degrees, as the command line gives it
        ang = np.degrees(ang)
        g1, g2 = (np.degrees(g) if n.startswith("a") else g for n, g in ((n1, g1), (n2, g2)))
    x0, y0, z0 = (float(v) for v in xyz)
    b1, b2, b3 = (float(v) for v in ang)

    def pose_of(u, v):
        vals = {"x": x0, "y": y0, "z": z0, "a1": b1, "a2": b2, "a3": b3}
        vals[n1], vals[n2] = u, v
        R = euler_matrix(seq, [vals["a1"], vals["a2"], vals["a3"]], degrees=True)
        return Pose(R, np.array([vals["x"], vals["y"], vals["z"]]))

    units = tuple("deg" if n.startswith("a") else mech.length_unit for n in (n1, n2))
    given = Pose(euler_matrix(seq, [b1, b2, b3], degrees=True), np.array([x0, y0, z0]))
    fit = configuration_at_pose(mech, given)  # the configuration sm.jacobian analyses at this pose
    if not (fit.converged and fit.exact):
        raise InputError(f"pose: not reachable exactly (nearest closed pose is {fit.position_error:.3g} away); the "
                         "slice follows the given pose's working mode from its closed configuration")
    return _slice(mech, pose_of, g1, g2, names=(n1, n2), units=units, actuators=acts, start=(given, fit.config),
                  fixed={"position_len": [x0, y0, z0], "euler_sequence": seq, "euler_deg": [b1, b2, b3]},
                  progress=progress)


@dataclass(frozen=True)
class TaskGridSuggestion:
    """A first grid over the task coordinates of a mechanism: its ``given`` and ``solved``
    coordinates, ``over`` (the first two given ones, angles first: name -> ``(lo, hi, n)``,
    +-20 deg or +-L/2 about the reference) and ``at`` (the other given ones held at their
    reference values); angles in degrees when asked with ``degrees=True``, else rad."""

    given: tuple[str, ...]
    solved: tuple[str, ...]
    euler: str
    over: dict[str, tuple[float, float, int]]
    at: dict[str, float]

    def to_dict(self) -> dict:
        return {"given": list(self.given), "solved": list(self.solved), "euler": self.euler,
                "over": {k: list(v) for k, v in self.over.items()}, "at": dict(self.at)}


def suggest_task_grid(model: ModelLike, *, free=None, degrees: bool = False) -> TaskGridSuggestion:
    """A first grid over the task coordinates of a model.

    For ``sm.workspace(kind="task")`` or :func:`singularity_slice`: the model's task (or the one
    solving ``free``), its first two given coordinates as grid axes, the others held.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    free : str or sequence of str, optional
        The task coordinates to solve (default: the model's task).
    degrees : bool
        Give the angles of the grid in degrees instead of radians.

    Returns
    -------
    TaskGridSuggestion
        ``given``, ``solved``, ``euler``, ``over`` (the first two given ones, angles first:
        name -> ``(lo, hi, n)``, +-20 deg or +-L/2 about the reference) and ``at`` (the others).

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
        The output's freedoms cannot be told (an ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> g = sm.suggest_task_grid("three-rps", degrees=True)
    >>> g.given, g.solved, g.over["a2"]
    (('z', 'a2', 'a3'), ('x', 'y', 'a1'), (-20.0, 20.0, 41))
    """
    from ..kinematics.task import default_task, task_values

    mech = as_mechanism(model)
    degrees = check_bool(degrees, "degrees")
    task = task_coordinates(mech, free)
    if task is None:
        task = default_task(mech)
    ref = dict(zip(TASK_NAMES, task_values(mech, np.eye(4), task.euler), strict=True))
    L = mech.characteristic_length
    order = sorted(task.given, key=lambda c: not c.startswith("a"))  # angles first
    unit = (lambda x: float(np.degrees(x))) if degrees else float
    half = np.radians(20.0)
    over = {c: ((unit(-half), unit(half), 41) if c.startswith("a") else (ref[c] - L / 2, ref[c] + L / 2, 41))
            for c in order[:2]}
    if degrees:
        over = {c: ((-20.0, 20.0, 41) if c.startswith("a") else v) for c, v in over.items()}
    at = {c: unit(ref[c]) if c.startswith("a") else float(ref[c]) for c in order[2:]}
    return TaskGridSuggestion(tuple(task.given), tuple(task.solved), task.euler, over, at)
