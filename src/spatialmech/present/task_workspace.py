"""Matplotlib figure of a workspace over task coordinates
(:class:`~spatialmech.analysis.workspace.task.TaskWorkspaceResult`), Agg backend.

Angles are drawn in degrees, lengths in the model's unit, both labelled.  Two grid coordinates:
the reachable cells (grey), the cells that close but break a limit (coloured by that limit), the
cells that do not close (white), the refined boundary points coloured by their active limit;
then one panel per solved (parasitic) coordinate over the cells that close, with the outline of
the reachable set.  One grid coordinate: the same along a line.  Three: the refined boundary
points in 3-D, coloured by active limit, and the reachable cells.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .figures import figure_path, legend_once

__all__ = ["task_workspace_figure", "write_task_workspace_plot"]

_TASK_NAMES = ("x", "y", "z", "a1", "a2", "a3")


def _conv(c: str, v):
    return np.degrees(v) if c.startswith("a") else np.asarray(v, dtype=float)


def _label(c: str, unit: str) -> str:
    return f"{c} [deg]" if c.startswith("a") else f"{c} [{unit}]"


def task_workspace_figure(result):
    """A Matplotlib ``Figure`` of ``result`` (nothing is shown or written)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.colors import ListedColormap
    from matplotlib.figure import Figure

    over, d = result.over, len(result.over)
    length_unit = result.length_unit
    names = sorted({str(n) for n in result.boundary_limits} | {str(n) for n in result.cell_limits.ravel() if n})
    cmap = matplotlib.colormaps["tab10"]
    colour = {n: cmap(i % 10) for i, n in enumerate(names)}
    held = ", ".join(f"{c}={float(_conv(c, v)):.4g}{' deg' if c.startswith('a') else ' ' + length_unit}"
                     for c, v in result.fixed.items())
    title = (f"{result.mechanism}: workspace over task coordinates ({result.euler})"
             + (f", {held}" if held else "") + f"; solved {', '.join(result.solved)}")
    solved = list(result.solved)
    if d == 1:
        c = over[0]
        x = _conv(c, result.grid[0])
        fig = Figure(figsize=(8, 2.2 + 1.6 * len(solved)))
        axes = fig.subplots(1 + len(solved), 1, sharex=True, squeeze=False)[:, 0]
        ax = axes[0]
        ax.plot(x[result.feasible], np.zeros(int(result.feasible.sum())), "s", color="0.6", label="reachable")
        for xb, n in zip(result.boundary_points[:, 0], result.boundary_limits, strict=True):
            ax.plot(_conv(c, xb), 0, "o", color=colour[n], label=n)
        ax.set_yticks([])
        legend_once(ax)
        for a, s in zip(axes[1:], solved, strict=True):
            a.plot(x, _conv(s, result.values[:, _TASK_NAMES.index(s)]), "-", color="tab:blue")
            a.set_ylabel(_label(s, length_unit))
        axes[-1].set_xlabel(_label(c, length_unit))
        fig.suptitle(title, fontsize=8)
        return fig
    if d == 3:
        fig = Figure(figsize=(7, 6))
        ax = fig.add_subplot(111, projection="3d")
        pts = np.array([[result.grid[k][i] for k, i in enumerate(idx)] for idx in np.argwhere(result.feasible)])
        if pts.size:
            ax.scatter(*(_conv(c, pts[:, k]) for k, c in enumerate(over)), s=2, color="0.7", label="reachable")
        for n in names:
            sel = np.array([b == n for b in result.boundary_limits], dtype=bool)
            if sel.any():
                ax.scatter(*(_conv(c, result.boundary_points[sel, k]) for k, c in enumerate(over)), s=6,
                           color=colour[n], label=n)
        ax.set_xlabel(_label(over[0], length_unit))
        ax.set_ylabel(_label(over[1], length_unit))
        ax.set_zlabel(_label(over[2], length_unit))
        legend_once(ax)
        fig.suptitle(title, fontsize=8)
        return fig
    u, v = (_conv(c, g) for c, g in zip(over, result.grid, strict=True))
    n_pan = 1 + len(solved)
    cols = min(n_pan, 2)  # at most two panels side by side: the figure stays readable at a page's width
    rows = -(-n_pan // cols)
    fig = Figure(figsize=(5.2 * cols, 4.4 * rows))
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for extra in axes[n_pan:]:
        extra.set_visible(False)
    axes = axes[:n_pan]
    ax = axes[0]
    # cell classes: 0 reachable, 1 does not close, 2.. a broken limit
    codes = np.zeros(result.feasible.shape, dtype=int)
    codes[~result.converged] = 1
    lim_codes = {n: 2 + i for i, n in enumerate(names)}
    for idx in np.argwhere(result.converged & ~result.feasible):
        codes[tuple(idx)] = lim_codes.get(str(result.cell_limits[tuple(idx)]), 1)
    palette = ["0.6", "white"] + [tuple(0.55 + 0.45 * np.array(colour[n][:3])) for n in names]
    ax.pcolormesh(u, v, codes.T, cmap=ListedColormap(palette), vmin=-0.5, vmax=len(palette) - 0.5, shading="nearest")
    for n in names:
        sel = np.array([b == n for b in result.boundary_limits], dtype=bool)
        if sel.any():
            ax.plot(_conv(over[0], result.boundary_points[sel, 0]), _conv(over[1], result.boundary_points[sel, 1]), "o",
                    ms=3, color=colour[n], label=f"boundary: {n}")
    ax.set_title(f"reachable (grey): {result.n_feasible} of {result.feasible.size} cells", fontsize=9)
    ax.set_xlabel(_label(over[0], length_unit))
    ax.set_ylabel(_label(over[1], length_unit))
    legend_once(ax)
    for a, s in zip(axes[1:], solved, strict=True):
        z = _conv(s, result.values[..., _TASK_NAMES.index(s)]).T
        if np.isfinite(z).any():
            cs = a.contourf(u, v, np.ma.masked_invalid(z), levels=15, cmap="viridis")
            fig.colorbar(cs, ax=a, label=_label(s, length_unit))
        if result.feasible.any() and not result.feasible.all():
            a.contour(u, v, result.feasible.T.astype(float), levels=[0.5], colors="k", linewidths=1.0)
        a.set_title(f"solved {s} (black: edge of the reachable set)", fontsize=9)
        a.set_xlabel(_label(over[0], length_unit))
        a.set_ylabel(_label(over[1], length_unit))
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return fig


def write_task_workspace_plot(result, path) -> Path:
    """Write :func:`task_workspace_figure` to ``path`` (.png, .svg or .pdf)."""
    p = figure_path(path)
    fig = task_workspace_figure(result)
    fig.savefig(p, dpi=110)
    return p
