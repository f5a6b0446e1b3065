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
:mod:`~spatialmech.api.kinematics` (position, Jacobian, velocity, singularity, workspace,
parasitic motion), :mod:`~spatialmech.api.forces` (statics),
:mod:`~spatialmech.api.stiffness` (stiffness), :mod:`~spatialmech.api.linkages` (tracking, defects, synthesis),
:mod:`~spatialmech.api.outputs` (report, demo, viewer, studio session), :mod:`~spatialmech.api.exchange`
(export, validation in MuJoCo), :mod:`~spatialmech.api.regions` (singularity slices, task grids),
:mod:`~spatialmech.api.settings` (tolerances, compilation notices); :mod:`~spatialmech.api.checks` has
the argument checks they share.  The command line and the studio's web app
(:mod:`spatialmech.interfaces`) are drivers over these functions and nothing below them.
"""

from __future__ import annotations

from ..geometry.rotations import euler_matrix as euler_matrix  # Euler angles <-> rotation matrices, for
from ..geometry.rotations import matrix_euler as matrix_euler  # the drivers (named sequences, as Pose.from_euler)
from ..geometry.tolerances import Tolerances as Tolerances  # what sm.tolerances() yields
from ..model.mechanism import Mechanism as Mechanism  # the model and pose types the verbs take
from ..model.mechanism import Pose as Pose
from .checks import ModelLike as ModelLike  # the type of a model argument
from .forces import StaticsResult, statics
from .kinematics import (
    FKResult,
    IKResult,
    JacobianResult,
    SingularityAnalysis,
    VelocityResult,
    fk,
    ik,
    jacobian,
    parasitic,
    singularity,
    velocity,
    workspace,
)
from .exchange import EXPORT_FORMATS as EXPORT_FORMATS  # the formats export() writes
from .exchange import VALIDATION_METHODS as VALIDATION_METHODS  # validate()'s methods and default tolerance
from .exchange import VALIDATION_TOL as VALIDATION_TOL
from .exchange import ExportResult, export, validate
from .linkages import CSSynthesisResult, DefectAnalysis, TraceResult, defects, dj_table, screen, synth_cs, synth_rccc, track
from .maps import MapResult, maps
from .stiffness import StiffnessMap, StiffnessResult, stiffness, stiffness_map
from .outputs import VIEW_MOTIONS as VIEW_MOTIONS  # the motions view() animates
from .outputs import ReportResult, ViewResult, demo, report, studio_session, view
from .regions import TASK_COORDINATES as TASK_COORDINATES  # the names of grids and held coordinates
from .regions import WORKSPACE_COORDINATES as WORKSPACE_COORDINATES
from .regions import WORKSPACE_MAX_POSES as WORKSPACE_MAX_POSES
from .regions import TaskGridSuggestion, singularity_slice, suggest_task_grid
from .settings import announce_compilation, default_tolerance, tolerances
from .structure import MobilityModes, load_model, mobility, mobility_modes, models

__all__ = [
    "CSSynthesisResult",
    "DefectAnalysis",
    "ExportResult",
    "FKResult",
    "IKResult",
    "JacobianResult",
    "MapResult",
    "MobilityModes",
    "ReportResult",
    "SingularityAnalysis",
    "StaticsResult",
    "StiffnessMap",
    "StiffnessResult",
    "TaskGridSuggestion",
    "TraceResult",
    "VelocityResult",
    "ViewResult",
    "announce_compilation",
    "default_tolerance",
    "defects",
    "demo",
    "dj_table",
    "export",
    "fk",
    "ik",
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
