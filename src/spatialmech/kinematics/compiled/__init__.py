"""The compiled engine (numba).

:mod:`.engine` holds the compiled model and the Python entry points (the same computations as
the Python reference in :mod:`spatialmech.kinematics.closure` and the modules that use it);
the kernels are plain-array ``@njit(cache=True)`` functions in :mod:`.kernels_se3`,
:mod:`.kernels_closure`, :mod:`.kernels_blocks`, :mod:`.kernels_drivers`, :mod:`.kernels_legs`
(with its entry :mod:`.legs`: six S-P-S legs in pose coordinates), :mod:`.kernels_homotopy` (the
Study formulation's parameter homotopy) and :mod:`.kernels_loops` (the loop formulation's square
system), :mod:`.kernels_ik` (one limb's inverse position),
:mod:`.kernels_four_sps_cu` (the 4-SPS/CU closed-form leg lengths), :mod:`.kernels_limits`
(with its entry :mod:`.limits`: joint points of many configurations, for the workspace limits),
:mod:`.kernels_task` (with its entry :mod:`.tasks`: the task-coordinate solve), :mod:`.kernels_tracking` (the
continuation tracker's tangent and orientation test), :mod:`.kernels_trace` (with its entry
:mod:`.trace`: the tracker's loop), :mod:`.kernels_certify` (with its entry :mod:`.certify`: the float
pass of the certificates); :mod:`.jit` is numba's ``njit`` or its
stand-in.

Callers do not choose between this package and the Python reference themselves:
:mod:`spatialmech.kinematics.backend` does (``backend.engine()`` is this package when it is in
use, else ``None``).  This package imports the Python reference (its data types, chains and
checks); the reference never imports this package.
"""

from __future__ import annotations

from .certify import krawczyk_limb, krawczyk_test
from .engine import (
    CompiledMechanism,
    closure_jacobian,
    closure_jacobians,
    closure_residual,
    closure_residuals,
    compile_mechanism,
    config_difference,
    config_differences,
    correct,
    correct_many,
    correct_on_hyperplane,
    driver_determinants,
    driver_determinants_many,
    driver_sigmas_many,
    limb_gn,
    limb_inverse_many,
    lstsq,
    minnorm_blocks,
    nearest_point,
    retract,
    sps_leg_lengths,
    warm_up,
)
from .jit import AVAILABLE, UNAVAILABLE_REASON
from .kernels_four_sps_cu import four_sps_cu_legs
from .kernels_homotopy import track_parameter
from .kernels_ik import ik_pack, ik_track
from .kernels_loops import pack as pack_loop_system
from .kernels_loops import square_batch as loop_square_batch
from .kernels_tracking import bordered_tangent
from .legs import correct_legs, inverse_legs_many
from .trace import TraceLoop, arc_near, motion_arrays, pose_search
from .limits import joint_points_many, link_margins_many
from .tasks import task_grid, task_solve
from . import maps as maps  # performance-map kernels (analysis/maps.py)

__all__ = [
    "AVAILABLE",
    "UNAVAILABLE_REASON",
    "CompiledMechanism",
    "TraceLoop",
    "arc_near",
    "bordered_tangent",
    "closure_jacobian",
    "closure_jacobians",
    "closure_residual",
    "closure_residuals",
    "compile_mechanism",
    "config_difference",
    "config_differences",
    "correct",
    "correct_legs",
    "correct_many",
    "correct_on_hyperplane",
    "driver_determinants",
    "driver_determinants_many",
    "driver_sigmas_many",
    "four_sps_cu_legs",
    "ik_pack",
    "ik_track",
    "inverse_legs_many",
    "joint_points_many",
    "krawczyk_limb",
    "krawczyk_test",
    "limb_gn",
    "limb_inverse_many",
    "link_margins_many",
    "loop_square_batch",
    "lstsq",
    "minnorm_blocks",
    "motion_arrays",
    "nearest_point",
    "pack_loop_system",
    "pose_search",
    "retract",
    "sps_leg_lengths",
    "task_grid",
    "task_solve",
    "track_parameter",
    "warm_up",
]
