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
:mod:`~spatialmech.api.outputs` (report, viewer); :mod:`~spatialmech.api.checks` has the argument
checks they share.
"""

from __future__ import annotations

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
from .maps import MapResult, maps
from .stiffness import StiffnessMap, StiffnessResult, stiffness, stiffness_map
from .linkages import CSSynthesisResult, TraceResult, defects, dj_table, screen, synth_cs, synth_rccc, track
from .outputs import VIEW_MOTIONS as VIEW_MOTIONS  # the motions view() animates
from .outputs import ReportResult, ViewResult, report, studio_app, studio_session, view
from .structure import MobilityModes, load_model, mobility, mobility_modes, models

__all__ = [
    "CSSynthesisResult",
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
    "TraceResult",
    "VelocityResult",
    "ViewResult",
    "defects",
    "dj_table",
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
    "statics",
    "stiffness",
    "stiffness_map",
    "studio_app",
    "studio_session",
    "synth_cs",
    "synth_rccc",
    "track",
    "velocity",
    "view",
    "workspace",
]
