"""The public API: models carried to other tools -- writing a model as TOML, MJCF or URDF, and
checking the library's motion in MuJoCo (``sm.export``, ``sm.validate``)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import ConvergenceError, InputError, describe, require
from ..model.mechanism import Mechanism
if TYPE_CHECKING:  # imported where it runs (it loads the simulator's bindings lazily)
    from ..analysis.validation import ValidationResult

from .checks import (ModelLike, as_configuration, as_mechanism, as_pose, check_bool, check_choice, check_int,
                     check_number, check_numbers, check_path)

from .constants import CAD_FORMATS, CAD_UNITS
from .constants import EXPORT_FORMATS as EXPORT_FORMATS  # the formats export() writes
from .constants import VALIDATION_METHODS as VALIDATION_METHODS  # validate()'s methods and default tolerance
from .constants import VALIDATION_TOL as VALIDATION_TOL


@dataclass(frozen=True, eq=False)
class ExportResult:
    """A model written to :attr:`out` in :attr:`format` (``"toml"``, ``"mjcf"``, ``"urdf"``,
    ``"step"``, ``"stl"`` or ``"glb"``); ``to_dict()`` is the payload of ``spatialmech export
    --json``.  A CAD export also lists every file written (:attr:`files`: the assembly, one file
    per link, the STL sidecar), its length :attr:`unit` and the joint features of every link;
    along a motion, :attr:`out` is the first sample's assembly, :attr:`placements` the JSON file
    of every link's placement at every sample and :attr:`samples` their number."""

    mechanism: Mechanism
    out: Path
    format: str
    files: tuple[Path, ...] = ()
    unit: str | None = None
    joints: dict | None = None
    placements: Path | None = None
    samples: int = 1

    @property
    def bytes(self) -> int:
        return self.out.stat().st_size

    def to_dict(self) -> dict:
        d = {"out": str(self.out), "format": self.format, "bytes": self.bytes}
        if self.unit is not None:
            d.update(files=[str(f) for f in self.files], file_length_unit=self.unit)
        if self.joints is not None:
            d.update(links=self.joints)
        if self.placements is not None:
            d.update(placements=str(self.placements), samples=self.samples)
        return d


def export(model: ModelLike, file, *, format: str | None = None, mode: str | None = None, pose=None,
           actuators=None, degrees: bool = False, unit: str | None = None, along=None,
           samples: int = 11) -> ExportResult:
    """Write a model as a TOML model file, a MuJoCo model (MJCF), a URDF or CAD parts.

    A TOML file to start your own from; MJCF and URDF for other tools (URDF: loop closures in an
    extension block; docs/validation.md).  CAD (STEP, STL, GLB; the ``cad`` extra): one solid per
    link with its joint geometry, the assembly at a configuration and one file per link in its
    own frame, the unit written into the files (docs/cad.md); along a motion, one assembly per
    sample and a JSON file of every link's placement at every sample.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    file : str or path
        The file written.
    format : {"toml", "mjcf", "urdf", "step", "stl", "glb"}, optional
        Default: from the extension of ``file`` (.toml, .xml, .urdf, .step, .stl, .glb).
    mode : str, optional
        Write a metamorphic mechanism in that motion mode (its other lockable freedoms locked).
    pose : Pose, tuple or int, optional
        CAD: place the links at the configuration nearest this pose (a pose as in :func:`ik`).
    actuators : array of shape (n_actuators,), optional
        CAD: place the links at the forward-position solution for these actuator values (SI, or
        degrees with ``degrees``).  Neither: the reference configuration.
    degrees : bool
        Angles of ``pose`` and rotary ``actuators`` in degrees.
    unit : {"m", "mm"}, optional
        CAD: the files' length unit (default ``"mm"``; a GLB is always in metres).
    along : array of shape (n_actuators,), optional
        CAD along a motion: target actuator values (SI, or degrees with ``degrees``); the
        actuators move in a straight line from the start (``pose``, ``actuators`` or the
        reference) to these, the configurations followed by continuation, and ``samples``
        samples (both ends included) are written: ``part.000.step``, ... beside one file per
        link and ``part.placements.json`` (every link's rotation and origin at every sample).
    samples : int
        The number of samples with ``along`` (at least 2).

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
    MissingExtraError
        A CAD format whose packages (the ``cad`` extra) are not installed, before any work (an
        ``InputError``).
    ConvergenceError
        CAD: no assembly for ``actuators``, or the motion to ``along`` does not follow.
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
    if fmt in CAD_FORMATS:  # before any work: the extra to install
        require("cad", *CAD_MODULES[fmt], what=f"the {fmt.upper()} export")
    mech = as_mechanism(model)
    if mode is not None:
        if not isinstance(mode, str):
            raise TypeError(f"mode: expected a mode name (str) or None, got {describe(mode)}")
        mech = mech.in_mode(mode)
    if fmt in CAD_FORMATS:
        return _export_cad(mech, out, fmt, (pose, actuators, along, samples), check_bool(degrees, "degrees"), unit)
    if pose is not None or actuators is not None or unit is not None or along is not None:
        raise InputError(f"pose/actuators/unit/along: only for a CAD export (step, stl, glb), not {fmt}")
    return ExportResult(mech, out, export_model(mech, out, fmt))


#: The packages of the ``cad`` extra each CAD format needs.
CAD_MODULES = {"step": ("build123d",), "stl": ("trimesh", "manifold3d"), "glb": ("trimesh", "manifold3d")}


def _export_cad(mech: Mechanism, out: Path, fmt: str, where: tuple, degrees: bool, unit: str | None) -> ExportResult:
    """The CAD branch of :func:`export`: the configuration (``where``: pose, actuators, along,
    samples), or the motion, then the files."""
    from ..exchange.cad import export_cad
    from .kinematics import fk

    pose, actuators, along, samples = where
    unit = check_choice(unit, "unit", CAD_UNITS) if unit is not None else ("m" if fmt == "glb" else "mm")
    if pose is not None and actuators is not None:
        raise InputError("pose/actuators: give a pose or actuator values, not both")
    if along is not None:
        to = check_numbers(along, "along", shape=(len(mech.actuators),))
        n = check_int(samples, "samples", minimum=2)
    if actuators is not None:
        values = check_numbers(actuators, "actuators", shape=(len(mech.actuators),))
        r = fk(mech, values, degrees=degrees)
        if not r.converged:
            raise ConvergenceError(f"actuators: no assembly found for {', '.join(f'{v:g}' for v in values)}")
        pose = r.poses[0]
    config, _ = as_configuration(mech, pose, None, degrees)
    if along is None:
        w = export_cad(mech, out, fmt, config=config, unit=unit)
        return ExportResult(mech, w.assembly, fmt, tuple(w.files), w.unit, w.joints)
    return _export_cad_motion(mech, out, fmt, config, to, n, degrees, unit)


def _export_cad_motion(mech: Mechanism, out: Path, fmt: str, start, to, n: int, degrees: bool, unit: str
                       ) -> ExportResult:
    """The ``n`` samples of a straight line of actuator values from ``start`` to ``to``, followed
    by continuation, as CAD files (:func:`~spatialmech.exchange.cad.export_cad_motion`)."""
    from ..analysis.dynamics import actuator_values, follow_actuators
    from ..exchange.cad import export_cad_motion
    from ..serialize import freedom_values_dict

    rotary = np.array([mech.freedom(a).freedom.kind != "P" for a in mech.actuators])
    to = np.where(rotary, np.radians(to), to) if degrees else np.asarray(to, float)
    a0 = actuator_values(mech, start)
    V = a0 + np.linspace(0.0, 1.0, n)[:, None] * (to - a0)
    configs = follow_actuators(mech, start, V)
    labels = [freedom_values_dict(mech, dict(zip(mech.actuators, row, strict=True)), "actuators") for row in V]
    w = export_cad_motion(mech, out, fmt, configs, unit=unit, labels=labels)
    return ExportResult(mech, w.assemblies[0], fmt, tuple(w.files), w.unit, None, w.placements, n)


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
    MissingExtraError
        The ``sim`` extra (MuJoCo) is not installed (an ``InputError``).

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
    require("sim", "mujoco", what="validation")  # before any work: the extra to install
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
