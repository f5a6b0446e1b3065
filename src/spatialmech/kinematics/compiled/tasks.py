"""The task-coordinate solve compiled: the entry of :func:`.kernels_task.nb_task_solve`, whose
Python reference is :func:`spatialmech.kinematics.task.solve_task` (same steps, tolerances and
statuses; the reference hands its solve to this entry when the compiled engine is in use)."""

from __future__ import annotations

import weakref

import numpy as np

from ...model.mechanism import Mechanism
from ..closure import Configuration
from .engine import compile_mechanism
from .kernels_task import nb_task_solve

__all__ = ["task_solve"]

_AXES = {"x": 0, "y": 1, "z": 2}


def task_solve(mech: Mechanism, config: Configuration, values: np.ndarray, seeded: np.ndarray, free: np.ndarray,
               euler: str, tol: float, max_iter: int) -> tuple[Configuration, np.ndarray, int, int, float]:
    """Gauss-Newton of :func:`..task.solve_task` from ``config``: the task coordinates marked
    ``seeded`` (6,) bool start at ``config``'s, the others at ``values`` (6,); those marked
    ``free`` are solved; ``euler`` the named sequence.
    Returns ``(config, values, status, iterations, residual)``, status 1 converged, 2 stalled, 0
    not converged (iteration limit, or a residual that is not finite)."""
    cm = compile_mechanism(mech)
    q = np.array(config.q, dtype=np.float64)  # copies: the kernel works in place
    B = np.array(config.B, dtype=np.float64).reshape(-1, 4, 4)
    vals = np.array(values, dtype=np.float64)
    D = np.array(config.D, dtype=np.float64)
    axes = _axes(euler)
    info = np.empty(3)
    nb_task_solve(cm.screws, cm.ball_of, cm.ball_first, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends,
                  cm.linear, cm.length, cm.active, _point(mech), axes, np.bool_(euler.isupper()), np.asarray(seeded, dtype=np.bool_), np.asarray(free, dtype=np.bool_), vals, q, D, B, float(tol),
                  int(max_iter), info)
    return Configuration.of(q, D, B), vals, int(info[0]), int(info[1]), float(info[2])


_AXES_OF: dict[str, np.ndarray] = {}
_POINTS: weakref.WeakKeyDictionary[Mechanism, np.ndarray] = weakref.WeakKeyDictionary()


def _axes(euler: str) -> np.ndarray:
    """The axis indices (0 = x, 1 = y, 2 = z) of a named Euler sequence (cached)."""
    try:
        return _AXES_OF[euler]
    except KeyError:
        out = _AXES_OF[euler] = np.array([_AXES[c] for c in euler.lower()], dtype=np.int64)
        return out


def _point(mech: Mechanism) -> np.ndarray:
    """The output link's reference point as a float64 array (cached per mechanism)."""
    try:
        return _POINTS[mech]
    except KeyError:
        out = _POINTS[mech] = np.ascontiguousarray(mech.platform_point, dtype=np.float64).reshape(3)
        return out
