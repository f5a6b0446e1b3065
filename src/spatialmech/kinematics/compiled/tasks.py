"""The task-coordinate solve compiled: the entry of :func:`.kernels_task.nb_task_solve`, whose
Python reference is :func:`spatialmech.kinematics.task.solve_task` (same steps, tolerances and
statuses; the reference hands its solve to this entry when the compiled engine is in use)."""

from __future__ import annotations

import weakref

import numpy as np

from ...model.mechanism import Mechanism
from ...model.task import TASK_NAMES, TaskCoordinates
from ...results import Progress
from ..closure import Configuration
from .engine import compile_mechanism
from .kernels_task import nb_task_grid, nb_task_solve

__all__ = ["task_grid", "task_solve"]

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
                  cm.linear, cm.length, cm.active, _point(mech), axes, np.bool_(euler.isupper()),
                  np.asarray(seeded, dtype=np.bool_), np.asarray(free, dtype=np.bool_), vals, q, D, B, float(tol),
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


#: Solves between two progress reports of :func:`task_grid`.
GRID_CHUNK = 256


def task_grid(mech: Mechanism, task: TaskCoordinates, names: tuple[str, ...], axes: tuple[np.ndarray, ...],
              fixed: dict, order: np.ndarray, seed: Configuration, islands: bool, tol: float, max_iter: int,
              progress: Progress) -> tuple:
    """The sweep of :func:`..task_grid.solve_task_grid` compiled (:func:`.kernels_task.nb_task_grid`):
    ``(converged, values, q, D, B, residuals, n_solves)`` over the cells in C order, progress
    reported every :data:`GRID_CHUNK` solves."""
    cm = compile_mechanism(mech)
    shape = np.array([a.size for a in axes], dtype=np.int64)
    n_cells = int(np.prod(shape))
    grid = np.zeros((len(axes), int(max(shape))))
    for k, a in enumerate(axes):
        grid[k, : a.size] = a
    coord = np.array([TASK_NAMES.index(c) for c in names], dtype=np.int64)
    base = np.zeros(6)
    for c, v in fixed.items():
        base[TASK_NAMES.index(c)] = v
    free = np.array([n not in task.given for n in TASK_NAMES], dtype=np.bool_)
    nb = len(mech.bodies)
    q0 = np.array(seed.q, dtype=np.float64)
    D0 = np.array(seed.D, dtype=np.float64)
    B0 = np.array(seed.B, dtype=np.float64).reshape(nb, 4, 4)
    state = np.zeros(6, dtype=np.int64)
    attempts = np.zeros(n_cells, dtype=np.int8)
    converged = np.zeros(n_cells, dtype=np.bool_)
    parents = np.full(n_cells, -1, dtype=np.int64)
    queue = np.empty(n_cells, dtype=np.int64)
    q_out = np.full((n_cells, cm.n), np.nan)
    D_out = np.full((n_cells, 4, 4), np.nan)
    B_out = np.full((n_cells, nb, 4, 4), np.nan)
    values = np.full((n_cells, 6), np.nan)
    residuals = np.full(n_cells, np.nan)
    order = np.ascontiguousarray(order, dtype=np.int64)
    while state[5] == 0:
        nb_task_grid(cm.screws, cm.ball_of, cm.ball_first, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends,
                     cm.linear, cm.length, cm.active, _point(mech), _axes(task.euler), np.bool_(task.euler.isupper()),
                     free, base, grid, coord, shape, order, q0, D0, B0, np.bool_(islands), float(tol), int(max_iter),
                     int(state[4]) + GRID_CHUNK, state, attempts, converged, parents, queue, q_out, D_out, B_out,
                     values, residuals)
        done = int(state[4])
        progress(done, n_cells if done <= n_cells else None, "solving task coordinates")
    return converged, values, q_out, D_out, B_out, residuals, int(state[4])
