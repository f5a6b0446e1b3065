"""The parasitic motion of a lower-mobility mechanism as a result in itself: its solved task
coordinates tabulated over a grid of one or two given ones (the others held), as the 3-RPS
literature does (Lee and Shah; Tsai).

Coordinates (:mod:`spatialmech.model.task`): ``x, y, z`` the output link's reference point (the
model's length unit) and ``a1, a2, a3`` its Euler angles in the task's named sequence (``ZYX`` by
default, upper case = intrinsic), in radians here; degrees only in :meth:`ParasiticTable.to_dict`.
Every cell is solved by :func:`~spatialmech.kinematics.task_grid.solve_task_grid` (Newton from a
solved neighbour, so one assembly branch over the grid).

    >>> import numpy as np
    >>> from spatialmech.catalog import build
    >>> t = parasitic_table(build("three-rps"), {"a2": (-0.1, 0.1, 3), "a3": (-0.1, 0.1, 3)}, at={"z": 0.33})
    >>> t.solved, int(t.grid.converged.sum())
    (('x', 'y', 'a1'), 9)
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.validate import as_finite_array
from ..kinematics.task_grid import TaskGrid, solve_task_grid
from ..model.mechanism import Mechanism
from ..model.task import TASK_NAMES, TaskCoordinates
from ..results import Progress

__all__ = ["MAX_AXES", "ParasiticTable", "parasitic_table"]

#: Largest number of grid axes (a table, and a figure of contour panels).
MAX_AXES = 2


def _edge(name: str, v):
    """Degrees for an angle, as is for a length (the JSON/text edge)."""
    return np.degrees(v) if name.startswith("a") else np.asarray(v, dtype=float)


def _key(name: str) -> str:
    return f"{name}_deg" if name.startswith("a") else f"{name}_len"


@dataclass(frozen=True, eq=False)
class ParasiticTable:
    """The solved task coordinates over a grid (:attr:`grid`, a
    :class:`~spatialmech.kinematics.task_grid.TaskGrid`: ``values[..., k]`` is coordinate
    ``TASK_NAMES[k]``, NaN where the cell did not close)."""

    grid: TaskGrid

    @property
    def given(self) -> tuple[str, ...]:
        return self.grid.given

    @property
    def solved(self) -> tuple[str, ...]:
        return self.grid.solved

    def values(self, name: str) -> np.ndarray:
        """The values of coordinate ``name`` over the grid (SI, rad; NaN where not solved)."""
        if name not in TASK_NAMES:
            raise InputError(f"name: unknown task coordinate {name!r}; expected one of {', '.join(TASK_NAMES)}")
        return self.grid.values[..., TASK_NAMES.index(name)]

    @property
    def ranges(self) -> dict[str, tuple[float, float] | None]:
        """``(min, max)`` of every solved coordinate over the solved cells (SI, rad); ``None``
        when no cell closed."""
        out: dict[str, tuple[float, float] | None] = {}
        for n in self.solved:
            v = self.values(n)
            ok = v[np.isfinite(v)]
            out[n] = (float(ok.min()), float(ok.max())) if ok.size else None
        return out

    def to_dict(self, plot=None) -> dict:
        """JSON (docs/json.md, ``parasitic``): lengths in ``*_len``, angles in ``*_deg``; the
        solved values flattened in C order over the grid (first axis slowest), ``null`` where a
        cell did not close."""
        g = self.grid
        table = {}
        for n in self.solved:
            v = _edge(n, self.values(n)).ravel()
            table[_key(n)] = [float(x) if np.isfinite(x) else None for x in v]
        return {
            "task": {"given": list(g.given), "solved": list(self.solved), "euler": g.task.euler},
            "over": list(g.over),
            "axes": {_key(n): [float(x) for x in _edge(n, a)] for n, a in zip(g.over, g.axes, strict=True)},
            "held": {_key(n): float(_edge(n, v)) for n, v in g.fixed.items()},
            "grid_points": list(g.shape), "cells": int(g.converged.size), "n_converged": int(g.converged.sum()),
            "converged": [bool(c) for c in g.converged.ravel()],
            "solved_values": table,
            "elapsed_s": float(g.seconds), "plot": None if plot is None else str(plot),
        }


def _axes(over) -> dict:
    if not isinstance(over, Mapping) or not over:
        raise InputError("over: expected a mapping of given task coordinate -> (lo, hi, n) or grid values (SI, rad)")
    if len(over) > MAX_AXES:
        raise InputError(f"over: at most {MAX_AXES} grid coordinates (a table over one or two), got {list(over)}")
    out = {}
    for c, v in over.items():
        if isinstance(v, tuple) and len(v) == 3 and isinstance(v[2], (int, np.integer)) and not isinstance(v[2], bool):
            lo, hi = (float(as_finite_array(x, f"over.{c}", shape=())) for x in v[:2])
            if int(v[2]) < 2 or not lo < hi:
                raise InputError(f"over.{c}: expected (lo, hi, n) with lo < hi and n >= 2, got {v}")
            out[str(c)] = np.linspace(lo, hi, int(v[2]))
        else:
            out[str(c)] = as_finite_array(v, f"over.{c}").reshape(-1)
    return out


def parasitic_table(mech: Mechanism, over, *, at: Mapping[str, float] | None = None,
                    task: TaskCoordinates | None = None, max_cells: int | None = None,
                    progress: Progress | None = None) -> ParasiticTable:
    """The solved (parasitic) task coordinates of ``mech`` over ``over`` (one or two given
    coordinates -> ``(lo, hi, n)`` or increasing values, SI / rad), the other given ones held at
    ``at`` (default: their reference values).  ``task``: which coordinates are given (default:
    the model's, else :func:`~spatialmech.kinematics.task.default_task`).  Cells that do not
    close are NaN in the table, never an error."""
    grid = solve_task_grid(mech, _axes(over), at=at, task=task, max_cells=max_cells, progress=progress)
    return ParasiticTable(grid)
