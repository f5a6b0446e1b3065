"""Figure of a parasitic-motion table: one contour panel per solved task coordinate over a 2-D
grid of given ones (or a line per solved coordinate over a 1-D grid).  Drawing only."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from ..kinematics.task_grid import TaskGrid
from ..model.task import TASK_NAMES

__all__ = ["parasitic_figure"]


def _display(name: str, v, unit: str):
    return (np.degrees(v), "deg") if name.startswith("a") else (np.asarray(v), unit)


def parasitic_figure(grid: TaskGrid, path) -> None:
    """Write the figure of ``grid`` (from :func:`~spatialmech.kinematics.task_grid.solve_task_grid`) to ``path``."""
    unit = grid.mechanism.length_unit
    solved = grid.solved
    fig, axes = plt.subplots(1, len(solved), figsize=(4.6 * len(solved), 4.0), squeeze=False)
    held = ", ".join(f"{k} = {_display(k, v, unit)[0]:.4g} {_display(k, v, unit)[1]}" for k, v in grid.fixed.items())
    for ax, name in zip(axes[0], solved, strict=True):
        k = TASK_NAMES.index(name)
        val, vu = _display(name, grid.values[..., k], unit)
        if len(grid.over) == 1:
            x, xu = _display(grid.over[0], grid.axes[0], unit)
            ax.plot(x, val)
            ax.set_xlabel(f"{grid.over[0]} [{xu}]")
            ax.set_ylabel(f"{name} [{vu}]")
        else:
            x, xu = _display(grid.over[0], grid.axes[0], unit)
            y, yu = _display(grid.over[1], grid.axes[1], unit)
            cs = ax.contourf(x, y, val.T if val.ndim == 2 else val[..., 0].T, levels=15, cmap="viridis")
            fig.colorbar(cs, ax=ax, label=f"{name} [{vu}]")
            ax.set_xlabel(f"{grid.over[0]} [{xu}]")
            ax.set_ylabel(f"{grid.over[1]} [{yu}]")
        ax.set_title(f"solved {name}")
    fig.suptitle(f"{grid.mechanism.name}: parasitic motion ({grid.task.euler}; {held or 'nothing held'})")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
