"""Matplotlib figures of a :class:`~spatialmech.analysis.workspace.WorkspaceResult` (Agg backend).

Angles are drawn in degrees (labelled), lengths in metres.  Three free coordinates: the three
central slices of the sampled grid (feasible cells shaded, refined boundary points of that
slice coloured by their active limit) and a 3-D point cloud of every refined boundary point
coloured by its active limit.  Two: one slice; one: the feasible intervals along the line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .figures import figure_path, legend_once

__all__ = ["workspace_figure", "write_workspace_plot"]

_ANGLES = ("alpha", "beta", "gamma")


def _conv(c: str, v):
    return np.degrees(v) if c in _ANGLES else np.asarray(v)


def _label(c: str) -> str:
    return f"{c} [deg]" if c in _ANGLES else f"{c} [m]"


def workspace_figure(result):
    """A Matplotlib ``Figure`` of ``result`` (nothing is shown or written)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    free = result.free
    d = len(free)
    limits = sorted(set(result.boundary_limits))
    cmap = matplotlib.colormaps["tab20"]
    colour = {n: cmap(i % 20) for i, n in enumerate(limits)}
    title = f"{result.mechanism}: {result.kind} workspace ({result.path} path), fixed " + ", ".join(
        f"{c}={_conv(c, v):.4g}{' deg' if c in _ANGLES else ' m'}" for c, v in result.fixed.items())
    if d == 1:
        fig = Figure(figsize=(7, 2.5))
        ax = fig.add_subplot(111)
        c = free[0]
        for lo, hi in result.alone_intervals[c]:
            ax.plot(_conv(c, [lo, hi]), [0, 0], lw=8, color="tab:blue")
        for x, n in zip(result.boundary_points[:, 0], result.boundary_limits, strict=True):
            ax.plot(_conv(c, x), 0, "o", color=colour[n], label=n)
        ax.set_xlabel(_label(c))
        ax.set_yticks([])
        legend_once(ax, 8)
        fig.suptitle(title, fontsize=8)
        return fig
    planes = [(0, 1)] if d == 2 else [(0, 1), (0, 2), (1, 2)]
    n_pan = len(planes) + (1 if d == 3 else 0)
    rows, cols = (2, 2) if n_pan > 2 else (1, n_pan)  # two panels a row: readable at a page's width
    fig = Figure(figsize=(5.2 * cols, 4.6 * rows))
    for k, (i, j) in enumerate(planes):
        ax = fig.add_subplot(rows, cols, k + 1)
        other = [m for m in range(d) if m not in (i, j)]
        F = result.feasible
        sel = np.ones(len(result.boundary_points), dtype=bool)
        if other:
            m = other[0]
            c0 = result.center[free[m]]
            g = result.grid[m]
            idx = int(np.argmin(np.abs(g - c0)))
            F = np.take(F, idx, axis=m)
            sel = np.abs(result.boundary_points[:, m] - g[idx]) < 1e-12 * max(1.0, abs(g[idx]))
        gi, gj = _conv(free[i], result.grid[i]), _conv(free[j], result.grid[j])
        ax.pcolormesh(gi, gj, F.T.astype(float), shading="nearest", cmap="Greys", vmin=0, vmax=2.5)
        for n in limits:
            mk = sel & (np.array(result.boundary_limits) == n)
            if mk.any():
                ax.plot(_conv(free[i], result.boundary_points[mk, i]), _conv(free[j], result.boundary_points[mk, j]),
                        ".", ms=3, color=colour[n], label=n)
        ax.set_xlabel(_label(free[i]))
        ax.set_ylabel(_label(free[j]))
        if other:
            ax.set_title(f"slice {free[other[0]]} = {_conv(free[other[0]], result.center[free[other[0]]]):.4g}", fontsize=9)
        legend_once(ax, 8)
    if d == 3:
        ax = fig.add_subplot(rows, cols, n_pan, projection="3d")
        bp = result.boundary_points
        lim = np.array(result.boundary_limits)
        for n in limits:
            mk = lim == n
            ax.scatter(*(_conv(free[m], bp[mk, m]) for m in range(3)), s=2, color=colour[n], label=n)
        ax.set_xlabel(_label(free[0]))
        ax.set_ylabel(_label(free[1]))
        ax.set_zlabel(_label(free[2]))
        ax.set_title("refined boundary points (colour: active limit)", fontsize=9)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    return fig


def write_workspace_plot(result, path) -> Path:
    """Write :func:`workspace_figure` to ``path`` (format from the suffix: .png, .svg, .pdf)."""
    path = figure_path(path)
    fig = workspace_figure(result)
    fig.savefig(path, dpi=120)
    return path
