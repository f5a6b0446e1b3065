"""Argument checks shared by the public API's modules (:mod:`spatialmech.api`).

Each check raises ``TypeError`` for a wrong type and :class:`~spatialmech.InputError` (a
``ValueError``) for a bad value, naming the argument and what it got.  The ``as_*`` functions
turn the accepted forms of an argument (a model name, a pose tuple, ...) into library objects.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Literal, overload

import numpy as np

from .. import catalog
from ..errors import InputError, UnknownNameError, describe
from ..geometry.rotations import euler_matrix
from ..kinematics.closure import Configuration, check_configuration
from ..kinematics.position import PoseFit, configuration_at_pose
from ..model.mechanism import Mechanism, Pose
from ..results import Progress, check_progress

#: What a model argument may be: a Mechanism, a ready-made model name or a TOML file path.
ModelLike = Mechanism | str | os.PathLike


# ============================================================================ argument checks
def check_bool(value, name: str) -> bool:
    """``value`` if it is a bool (NumPy's included), else ``TypeError`` naming ``name``."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {describe(value)}")
    return bool(value)


def check_int(value, name: str, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """An integer (not a bool) within ``[minimum, maximum]``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name}: expected an integer, got {describe(value)}")
    v = int(value)
    if minimum is not None and v < minimum:
        raise InputError(f"{name}: expected an integer >= {minimum}, got {v}")
    if maximum is not None and v > maximum:
        raise InputError(f"{name}: expected an integer <= {maximum}, got {v}")
    return v


@overload
def check_number(value, name: str, *, positive: bool = ..., optional: Literal[False] = ...) -> float: ...
@overload
def check_number(value, name: str, *, positive: bool = ..., optional: bool) -> float | None: ...
def check_number(value, name: str, *, positive: bool = False, optional: bool = False) -> float | None:
    """A finite number (not a bool) as a float; ``None`` passes when ``optional``."""
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


def check_choice(value, name: str, choices: Sequence[str]) -> str:
    """One of the strings ``choices``."""
    if not isinstance(value, str):
        raise TypeError(f"{name}: expected one of {', '.join(map(repr, choices))}, got {describe(value)}")
    if value not in choices:
        raise InputError(f"{name}: expected one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def check_numbers(value, name: str, *, shape: tuple[int, ...] | None = None) -> np.ndarray:
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


def check_names(value, name: str) -> list[str] | None:
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


def check_grid(over, at, limits) -> None:
    """The grid of a map over poses: ``over`` a mapping of coordinate -> ``(lo, hi, n)`` or
    values, ``at`` ``None`` or a mapping of coordinate -> value, ``limits`` ``None`` or a
    :class:`~spatialmech.analysis.workspace.WorkspaceLimits`."""
    from ..analysis.workspace import WorkspaceLimits

    if not isinstance(over, Mapping):
        raise TypeError(f"over: expected a mapping of coordinate -> (lo, hi, n) or values, got {describe(over)}")
    if at is not None and not isinstance(at, Mapping):
        raise TypeError(f"at: expected a mapping of coordinate -> value (SI, rad), got {describe(at)}")
    if limits is not None and not isinstance(limits, WorkspaceLimits):
        raise TypeError(f"limits: expected a WorkspaceLimits, got {describe(limits)}")


def optional_progress(progress) -> Progress | None:
    """``None`` or a progress callback of the one signature (:func:`~spatialmech.results.check_progress`)."""
    return None if progress is None else check_progress(progress)


# ============================================================================ models, poses, paths
def as_mechanism(model, name: str | None = "model") -> Mechanism:
    """A :class:`Mechanism` from a Mechanism, a ready-made model name or a TOML file path.
    ``name``: the argument in the error messages; ``None`` for a value typed without a name (the
    command line's MODEL): an unknown name or a missing file is then reported by its value,
    ``NAME: not a file and not a ready-made model (...)``."""
    if isinstance(model, Mechanism):
        return model
    if not isinstance(model, (str, os.PathLike)):
        raise TypeError(f"{name or 'model'}: expected a Mechanism, a ready-made model name or a TOML file path, "
                        f"got {describe(model)}")
    s = os.fspath(model)
    if isinstance(s, bytes):
        raise TypeError(f"{name or 'model'}: expected a str path, got bytes {s!r}")
    if name is None:
        return catalog.resolve(s)
    if s in catalog.REGISTRY:
        return catalog.build(s)
    p = Path(s)
    if not p.exists() and p.suffix == "" and os.sep not in s and (os.altsep is None or os.altsep not in s):
        raise UnknownNameError(f"{name}: unknown ready-made model {s!r} (and no such file); known: "
                               f"{', '.join(catalog.names())}")
    return catalog.resolve(p)


def as_pose(mech: Mechanism, pose, degrees: bool, name: str = "pose") -> tuple[Pose, int | None]:
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
    p = check_numbers(xyz, f"{name}[0] (xyz)", shape=(3,))
    if orient is None:
        R = np.eye(3)
    elif isinstance(orient, (tuple, list)) and len(orient) == 4 and isinstance(orient[0], str):
        seq, *angles = orient
        a = check_numbers(angles, f"{name}[1] (angles)", shape=(3,))
        try:
            R = euler_matrix(seq, a, degrees=degrees)
        except InputError as e:
            raise InputError(f"{name}[1] (orientation): {e}") from None
    elif isinstance(orient, (tuple, list, np.ndarray)):
        R = check_numbers(orient, f"{name}[1] (rotation matrix)", shape=(3, 3))
    else:
        raise TypeError(f"{name}[1]: expected (seq, a1, a2, a3), a 3x3 rotation matrix or None, got {describe(orient)}")
    try:
        return Pose(R, p, "requested"), None
    except InputError as e:
        raise InputError(f"{name}: {e}") from None


def as_configuration(mech: Mechanism, pose, config, degrees: bool, *, pose_name: str = "pose"
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
    P, _ = as_pose(mech, pose, degrees, pose_name)
    fit = configuration_at_pose(mech, P)
    if not fit.converged:
        raise InputError(f"{pose_name}: no closed configuration near it (residual {fit.ik_residual:.2e})")
    return fit.config, fit


@dataclass(frozen=True, eq=False)
class Where:
    """The arguments of a verb that analyses one configuration, checked (:func:`where`)."""

    mech: Mechanism
    config: Configuration
    fit: PoseFit | None  # the pose fitted onto the closure (a pose given)
    pose: Pose | None  # the requested pose (a pose given)
    drivers: list[str] | None
    degrees: bool


def where(model: ModelLike, pose, config, drivers=None, degrees=False) -> Where:
    """The model, ``degrees``, ``drivers`` and the configuration to analyse (:func:`as_configuration`)
    of a verb's ``(model, pose=None, *, config=None, drivers=None, degrees=False)``, checked in
    that order: the one parser of these arguments."""
    mech = as_mechanism(model)
    degrees = check_bool(degrees, "degrees")
    drivers = check_names(drivers, "drivers")
    c, fit = as_configuration(mech, pose, config, degrees)
    requested = as_pose(mech, pose, degrees)[0] if pose is not None else None
    return Where(mech, c, fit, requested, drivers, degrees)


def pose_sequence(pose) -> str:
    """The Euler sequence a pose tuple names (``"ZYX"`` when it names none)."""
    if (isinstance(pose, (tuple, list)) and len(pose) == 2 and isinstance(pose[1], (tuple, list))
            and len(pose[1]) == 4 and isinstance(pose[1][0], str)):
        return pose[1][0]
    return "ZYX"


def as_positions(positions) -> tuple[Pose, ...] | None:
    """``None``, a TOML file of ``[[positions]]``, or a sequence of Pose."""
    if positions is None:
        return None
    if isinstance(positions, (str, os.PathLike)):
        from ..model.schema import load_positions

        return load_positions(Path(positions))
    if not isinstance(positions, Sequence):
        raise TypeError(f"positions: expected a sequence of Pose or a TOML file path, got {describe(positions)}")
    for k, p in enumerate(positions):
        if not isinstance(p, Pose):
            raise TypeError(f"positions[{k}]: expected a Pose, got {describe(p)}")
    return tuple(positions)


def check_path(value, name: str) -> Path:
    """A ``str`` or ``os.PathLike`` as a :class:`~pathlib.Path`."""
    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name}: expected a path (str or os.PathLike), got {describe(value)}")
    return Path(value)
