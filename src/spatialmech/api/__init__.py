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

The functions live in modules by concept (this package re-exports them; import them from here or
from ``spatialmech``): :mod:`~spatialmech.api.structure` (models, mobility),
:mod:`~spatialmech.api.kinematics` (position, Jacobian, velocity), :mod:`~spatialmech.api.spaces`
(singularity, workspace, parasitic motion), :mod:`~spatialmech.api.forces` (statics),
:mod:`~spatialmech.api.stiffness` (stiffness), :mod:`~spatialmech.api.linkages` (tracking, defects, synthesis),
:mod:`~spatialmech.api.outputs` (report, demo, viewer, studio session), :mod:`~spatialmech.api.exchange`
(export, validation in MuJoCo), :mod:`~spatialmech.api.regions` (singularity slices, task grids),
:mod:`~spatialmech.api.settings` (tolerances, compilation notices); :mod:`~spatialmech.api.checks` has
the argument checks they share.  The command line and the studio's web app
(:mod:`spatialmech.interfaces`) are drivers over these functions and nothing below them.
"""

from __future__ import annotations

import importlib
import sys
import types
from typing import TYPE_CHECKING

from ..geometry.rotations import euler_matrix as euler_matrix  # Euler angles <-> rotation matrices, for
from ..geometry.rotations import matrix_euler as matrix_euler  # the drivers (named sequences, as Pose.from_euler)
from ..geometry.tolerances import Tolerances as Tolerances  # what sm.tolerances() yields

if TYPE_CHECKING:  # what mypy (and a reader) sees; at run time __getattr__ imports these on first use
    from ..model.mechanism import Mechanism as Mechanism  # the model and pose types the verbs take
    from ..model.mechanism import Pose as Pose
    from .checks import ModelLike as ModelLike  # the type of a model argument
    from .constants import (  # the choices and defaults the drivers show (a light module: no analysis)
        EXPORT_FORMATS as EXPORT_FORMATS,
        TASK_COORDINATES as TASK_COORDINATES,
        VALIDATION_METHODS as VALIDATION_METHODS,
        VALIDATION_TOL as VALIDATION_TOL,
        VIEW_MOTIONS as VIEW_MOTIONS,
        WORKSPACE_COORDINATES as WORKSPACE_COORDINATES,
        WORKSPACE_MAX_POSES as WORKSPACE_MAX_POSES,
    )
    from .accuracy import AccuracyResult, accuracy
    from .forces import StaticsResult, statics
    from .dynamics import DynamicsResult, StaticsPath, inverse_dynamics, statics_along
    from .kinematics import (
        FKResult,
        IKResult,
        JacobianResult,
        VelocityResult,
        fk,
        ik,
        jacobian,
        velocity,
    )
    from .spaces import SingularityAnalysis, parasitic, singularity, workspace
    from .exchange import ExportResult, export, validate
    from .linkages import CSSynthesisResult, DefectAnalysis, TraceResult, defects, dj_table, screen, synth_cs, synth_rccc, track
    from .maps import MapResult, maps
    from .stiffness import StiffnessMap, StiffnessResult, stiffness, stiffness_map
    from .outputs import ReportResult, ViewResult, demo, report, studio_session, view
    from .regions import TaskGridSuggestion, singularity_slice, suggest_task_grid
    from .settings import announce_compilation, default_tolerance, first_run, tolerances
    from .structure import MobilityModes, load_model, mobility, mobility_modes, models

#: Name -> the module (relative to this package) that defines it: every function and result type
#: is imported on first use (PEP 562, :func:`__getattr__`), so ``import spatialmech`` loads none
#: of the analyses (nor scipy.spatial, numba, ...) until one is called.
_LAZY: dict[str, str] = {
    **dict.fromkeys(("Mechanism", "Pose"), "..model.mechanism"),
    **dict.fromkeys(("ModelLike",), ".checks"),
    **dict.fromkeys(("AccuracyResult", "accuracy"), ".accuracy"),
    **dict.fromkeys(("StaticsResult", "statics"), ".forces"),
    **dict.fromkeys(("DynamicsResult", "StaticsPath", "inverse_dynamics", "statics_along"), ".dynamics"),
    **dict.fromkeys(("FKResult", "IKResult", "JacobianResult", "VelocityResult", "fk", "ik", "jacobian", "velocity"),
                    ".kinematics"),
    **dict.fromkeys(("SingularityAnalysis", "parasitic", "singularity", "workspace"), ".spaces"),
    **dict.fromkeys(("EXPORT_FORMATS", "TASK_COORDINATES", "VALIDATION_METHODS", "VALIDATION_TOL", "VIEW_MOTIONS",
                     "WORKSPACE_COORDINATES", "WORKSPACE_MAX_POSES"), ".constants"),
    **dict.fromkeys(("ExportResult", "export", "validate"), ".exchange"),
    **dict.fromkeys(("CSSynthesisResult", "DefectAnalysis", "TraceResult", "defects", "dj_table", "screen", "synth_cs",
                     "synth_rccc", "track"), ".linkages"),
    **dict.fromkeys(("MapResult", "maps"), ".maps"),
    **dict.fromkeys(("StiffnessMap", "StiffnessResult", "stiffness", "stiffness_map"), ".stiffness"),
    **dict.fromkeys(("ReportResult", "ViewResult", "demo", "report", "studio_session", "view"), ".outputs"),
    **dict.fromkeys(("TaskGridSuggestion", "singularity_slice", "suggest_task_grid"), ".regions"),
    **dict.fromkeys(("announce_compilation", "default_tolerance", "first_run", "tolerances"), ".settings"),
    **dict.fromkeys(("MobilityModes", "load_model", "mobility", "mobility_modes", "models"), ".structure"),
}

__all__ = [
    "AccuracyResult",
    "CSSynthesisResult",
    "DefectAnalysis",
    "DynamicsResult",
    "ExportResult",
    "FKResult",
    "IKResult",
    "JacobianResult",
    "MapResult",
    "MobilityModes",
    "ReportResult",
    "SingularityAnalysis",
    "StaticsPath",
    "StaticsResult",
    "StiffnessMap",
    "StiffnessResult",
    "TaskGridSuggestion",
    "TraceResult",
    "VelocityResult",
    "ViewResult",
    "accuracy",
    "announce_compilation",
    "default_tolerance",
    "defects",
    "demo",
    "dj_table",
    "export",
    "first_run",
    "fk",
    "ik",
    "inverse_dynamics",
    "jacobian",
    "load_model",
    "maps",
    "mobility",
    "mobility_modes",
    "models",
    "parasitic",
    "report",
    "screen",
    "singularity",
    "singularity_slice",
    "statics",
    "statics_along",
    "stiffness",
    "stiffness_map",
    "studio_session",
    "suggest_task_grid",
    "synth_cs",
    "synth_rccc",
    "tolerances",
    "track",
    "validate",
    "velocity",
    "view",
    "workspace",
]


def __getattr__(name: str):
    """A name of :data:`_LAZY`: import its module, bind the name here (later lookups are plain
    attribute reads) and return it."""
    where = _LAZY.get(name)
    if where is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(where, __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


class _Facade(types.ModuleType):
    """This package's module type: importing ``api/maps.py`` or ``api/stiffness.py`` (a module
    named as a function of the facade) must not rebind ``api.maps`` / ``api.stiffness`` to the
    module, as the import system does for a submodule; the function stays (as when this package
    imported everything eagerly)."""

    def __setattr__(self, name: str, value) -> None:
        if isinstance(value, types.ModuleType) and _LAZY.get(name) == "." + name:
            return
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Facade
