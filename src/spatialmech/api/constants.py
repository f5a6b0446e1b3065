"""The facade's constants (choices and defaults the drivers show in their ``--help``), in a module
that imports no analysis: the command line reads them when it builds its options, and its
start-up must not load the analyses behind them (issue 29).  Re-exported by :mod:`spatialmech.api`
and by the modules of the verbs they belong to."""

from __future__ import annotations

from ..model.task import TASK_NAMES

__all__ = ["CAD_FORMATS", "CAD_UNITS", "EXPORT_FORMATS", "TASK_COORDINATES", "VALIDATION_METHODS", "VALIDATION_TOL",
           "VIEW_MOTIONS", "WORKSPACE_COORDINATES", "WORKSPACE_MAX_POSES"]

#: The formats :func:`~spatialmech.api.export` writes.
EXPORT_FORMATS = ("toml", "mjcf", "urdf", "step", "stl", "glb")
#: The CAD formats among them (the ``cad`` extra) and the units a CAD file may be in.
CAD_FORMATS = ("step", "stl", "glb")
CAD_UNITS = ("m", "mm")
#: The ways :func:`~spatialmech.api.validate` drives the simulator, and the largest error that
#: passes by default (a fraction of the characteristic length, and radians).
VALIDATION_METHODS = ("project", "settle")
VALIDATION_TOL = 1e-8
#: The motions :func:`~spatialmech.api.view` can animate.
VIEW_MOTIONS = ("auto", "trace", "demo")
#: The coordinates of a pose workspace's ``at`` (``x, y, z`` length; ``alpha, beta, gamma`` rad of
#: ``R = Rz(gamma) Ry(beta) Rx(alpha)``): :data:`spatialmech.analysis.workspace.COORDINATES`,
#: written out here so that reading it loads no workspace code (tests/test_startup.py checks both agree).
WORKSPACE_COORDINATES = ("x", "y", "z", "alpha", "beta", "gamma")
#: The task coordinates: ``x, y, z`` of the output point, ``a1, a2, a3`` Euler angles in a named
#: sequence.
TASK_COORDINATES = TASK_NAMES
#: The largest grid a pose workspace accepts by default (``max_poses``):
#: :data:`spatialmech.analysis.workspace.MAX_POSES`, written out (checked as above).
WORKSPACE_MAX_POSES = 10_000_000
