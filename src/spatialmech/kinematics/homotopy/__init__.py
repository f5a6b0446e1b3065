"""Every assembly mode of the forward position by homotopy continuation.

Two formulations, each its own module:

- :mod:`.study` (with :mod:`.systems`): platforms whose limbs, actuators given, are quadrics in
  the Study parameters of the platform displacement (Stewart, 3-RPS, 3-PRS, 3-UPU, Delta, ...):
  :func:`homotopy_forward`;
- :mod:`.general` (with :mod:`.loop_system`): any other limbs of R, P, C, U, S joints, as the
  loop closure in joint variables, solved by monodromy and proven complete by the trace test
  (:mod:`.trace_test`): :func:`general_forward`.

:mod:`.endgame` is the Cauchy end game both use at singular end points.  The NumPy code here is
the reference; the compiled parameter homotopy and the loop system's compiled evaluation live
in :mod:`spatialmech.kinematics.compiled` and are reached through
:mod:`spatialmech.kinematics.backend`.  Each module keeps its own caches (``study.clear_cache``,
``general.clear_cache``).
"""

from __future__ import annotations

from .endgame import EndgameResult, cauchy_endgame, local_dimension
from .general import GeneralResult, GeneralSolution, general_forward, rebuild_configuration
from .loop_system import LoopSystem, general_reason, loop_system
from .study import HomotopyResult, HomotopySolution, homotopy_forward, study_to_pose, track, track_parameter
from .systems import PoseSystem, StewartSystem, pose_system, stewart_system, system_from_points, unsupported_reason
from .trace_test import TraceResult, trace_test

__all__ = [
    "EndgameResult",
    "GeneralResult",
    "GeneralSolution",
    "HomotopyResult",
    "HomotopySolution",
    "LoopSystem",
    "PoseSystem",
    "StewartSystem",
    "TraceResult",
    "cauchy_endgame",
    "general_forward",
    "general_reason",
    "homotopy_forward",
    "local_dimension",
    "loop_system",
    "pose_system",
    "rebuild_configuration",
    "stewart_system",
    "study_to_pose",
    "system_from_points",
    "trace_test",
    "track",
    "track_parameter",
    "unsupported_reason",
]
