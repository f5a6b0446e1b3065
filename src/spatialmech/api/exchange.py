"""The public API: models carried to other tools -- writing a model as TOML, MJCF or URDF, and
checking the library's motion in MuJoCo (``sm.export``, ``sm.validate``)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import InputError, describe
from ..model.mechanism import Mechanism
if TYPE_CHECKING:  # imported where it runs (it loads the simulator's bindings lazily)
    from ..analysis.validation import ValidationResult

from .checks import ModelLike, as_mechanism, as_pose, check_bool, check_choice, check_int, check_number, check_path

from .constants import EXPORT_FORMATS as EXPORT_FORMATS  # the formats export() writes
from .constants import VALIDATION_METHODS as VALIDATION_METHODS  # validate()'s methods and default tolerance
from .constants import VALIDATION_TOL as VALIDATION_TOL


@dataclass(frozen=True, eq=False)
class ExportResult:
    """A model written to :attr:`out` in :attr:`format` (``"toml"``, ``"mjcf"`` or ``"urdf"``);
    ``to_dict()`` is the payload of ``spatialmech export --json``."""

    mechanism: Mechanism
    out: Path
    format: str

    @property
    def bytes(self) -> int:
        return self.out.stat().st_size

    def to_dict(self) -> dict:
        return {"out": str(self.out), "format": self.format, "bytes": self.bytes}


def export(model: ModelLike, file, *, format: str | None = None, mode: str | None = None) -> ExportResult:
    """Write a model as a TOML model file, a MuJoCo model (MJCF) or a URDF.

    A TOML file to start your own from; MJCF and URDF for other tools (URDF: loop closures in an
    extension block; docs/validation.md).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    file : str or path
        The file written.
    format : {"toml", "mjcf", "urdf"}, optional
        Default: from the extension of ``file`` (.toml, .xml, .urdf).
    mode : str, optional
        Write a metamorphic mechanism in that motion mode (its other lockable freedoms locked).

    Returns
    -------
    ExportResult
        ``out`` (the path), ``format``, ``bytes``; ``to_dict()`` is the payload of
        ``spatialmech export --json``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
    OSError
        The file cannot be written.

    Examples
    --------
    >>> import spatialmech as sm, tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     r = sm.export("rssr", os.path.join(d, "rssr.xml"))
    ...     r.format, r.bytes > 0
    ('mjcf', True)
    """
    from ..exchange import export_model, format_of

    if format is not None:
        check_choice(format, "format", EXPORT_FORMATS)
    out = check_path(file, "file")
    fmt = format_of(out, format)  # before any work: a file name whose format is unknown
    mech = as_mechanism(model)
    if mode is not None:
        if not isinstance(mode, str):
            raise TypeError(f"mode: expected a mode name (str) or None, got {describe(mode)}")
        mech = mech.in_mode(mode)
    return ExportResult(mech, out, export_model(mech, out, fmt))


def validate(model: ModelLike, motion: str | None = None, *, mode: str | None = None, start=None,
             degrees: bool = False, method: str = "project", frames: int = 12, to_position: int | None = None,
             amplitude: float = 0.02, arc: float = 2.0, actuator_path=None, tol: float = VALIDATION_TOL,
             mjcf: str | os.PathLike | None = None) -> ValidationResult:
    """Check the library's motion in MuJoCo (docs/validation.md; needs the ``mujoco`` package).

    The model exported to MuJoCo is driven through a motion computed by the library and the
    simulated output-link pose compared with the library's at every pose.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    motion : {"trace", "loop", "actuators"}, optional
        ``"trace"``: the 1-DOF motion (default with one actuator); ``"loop"``: a loop of the
        actuators (default otherwise); ``"actuators"``: the rows of ``actuator_path``.
    mode : str, optional
        A motion mode of a metamorphic mechanism.
    start : Pose, tuple, int or Configuration, optional
        The first pose (a pose as in :func:`ik`) or configuration; default: the reference.
    degrees : bool
        Read the angles of a ``start`` pose tuple in degrees.
    method : {"project", "settle"}
        How the simulator is driven.
    frames : int
        Poses compared (at least 2).
    to_position : int, optional
        Trace towards the model's task position N (from 1).
    amplitude : float
        The loop's amplitude (SI: rad or length unit).
    arc : float
        The traced arc length (nondimensional).
    actuator_path : array of shape (n, n_actuators), optional
        Rows of actuator values, SI (rad, length), in the order of the actuators.
    tol : float
        The largest error that passes (a fraction of the characteristic length, and rad).
    mjcf : str or path, optional
        Also write the simulated MJCF model there.

    Returns
    -------
    ValidationResult
        ``passed``, the errors at every pose; ``to_dict()`` is its JSON.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
    ConvergenceError
        The library's motion cannot be computed (the closure does not converge).

    The missing ``mujoco`` package is an ``InputError`` naming it.

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.validate("rssr", frames=3, arc=0.2)                    # doctest: +SKIP
    >>> r.passed                                                      # doctest: +SKIP
    True
    >>> sm.validate("rssr", method="guess")
    Traceback (most recent call last):
    ...
    spatialmech.errors.InputError: method: expected one of 'project', 'settle', got 'guess'
    """
    from ..analysis.validation import validate as _validate
    from ..kinematics.closure import Configuration

    method = check_choice(method, "method", VALIDATION_METHODS)
    mech = as_mechanism(model)
    if mode is not None and not isinstance(mode, str):
        raise TypeError(f"mode: expected a mode name (str) or None, got {describe(mode)}")
    posed = mech.in_mode(mode) if mode is not None else mech
    degrees = check_bool(degrees, "degrees")
    frames = check_int(frames, "frames", minimum=2)
    if to_position is not None:
        to_position = check_int(to_position, "to_position")
    amplitude = check_number(amplitude, "amplitude")
    arc = check_number(arc, "arc")
    tol = check_number(tol, "tol", positive=True)
    out = None if mjcf is None else check_path(mjcf, "mjcf")
    if actuator_path is not None and motion not in (None, "actuators"):
        raise InputError(f"actuator_path: give either an actuator path or motion={motion!r}, not both")
    if start is not None and not isinstance(start, Configuration):
        start, _ = as_pose(posed, start, degrees, "start")
    r = _validate(mech, "actuators" if actuator_path is not None else motion, method=method, start=start,
                  frames=frames, to_position=to_position, amplitude=amplitude, arc=arc, actuator_path=actuator_path,
                  tol=tol, mode=mode)
    if out is not None:
        from ..exchange import to_mjcf

        out.write_text(to_mjcf(posed), encoding="utf-8")
    return r
