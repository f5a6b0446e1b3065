"""Figures of a :class:`~spatialmech.analysis.maps.MapResult`: static (Matplotlib: PNG, PDF,
SVG) and interactive (plotly: HTML).  One panel per index; two grid axes give a colour map, one
a curve; cells without indices (outside the limits, out of reach) are left blank (grey); every
colour bar names its unit (the indices are nondimensional, with the characteristic length L)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["index_label", "maps_figure", "write_maps_plot"]

_ANGLES = ("alpha", "beta", "gamma")
_NAMES = {"sigma_min": "sigma_min", "condition": "1 / condition number", "manipulability": "manipulability",
          "iti": "ITI", "oti": "OTI", "lti": "LTI", "lci": "LCI"}


def index_label(name: str, L: float, unit: str) -> str:
    """The colour-bar title of an index, with its unit."""
    if name in ("iti", "oti", "lti", "lci"):
        return f"{_NAMES[name]} [1, power coefficient in 0..1]"
    return f"{_NAMES.get(name, name)} [1, nondimensional, L = {L:.4g} {unit}]"


def _axis_label(c: str, unit: str) -> str:
    return f"{c} [deg]" if c in _ANGLES else f"{c} [{unit}]"


def _axis_values(c: str, v) -> np.ndarray:
    return np.degrees(v) if c in _ANGLES else np.asarray(v)


def _panels(result, indices) -> list[tuple[str, np.ndarray]]:
    names = [n for n in (indices or result.indices) if n in _NAMES]
    out = []
    for n in names:
        a = np.where(result.valid & np.isfinite(result.values[n]), result.values[n], np.nan)
        out.append((n, a))
    return out


def _title(result) -> str:
    fixed = ", ".join(f"{c}={_axis_values(c, v):.4g}{' deg' if c in _ANGLES else ' ' + result.length_unit}"
                      for c, v in result.fixed.items())
    return f"{result.mechanism}: performance maps ({result.kind} grid; fixed {fixed})"


def maps_figure(result, indices=None):
    """A Matplotlib ``Figure`` (nothing shown or written)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    if len(result.axes) > 2:
        raise ValueError("maps_figure: 1 or 2 grid axes (slice a 3-axis map first)")
    panels = _panels(result, indices)
    cols = min(3, len(panels))
    rows = -(-len(panels) // cols)
    fig = Figure(figsize=(4.8 * cols, 4.0 * rows))
    names = list(result.axes)
    for k, (n, a) in enumerate(panels):
        ax = fig.add_subplot(rows, cols, k + 1)
        x = _axis_values(names[0], result.axes[names[0]])
        label = index_label(n, result.characteristic_length, result.length_unit)
        if len(names) == 1:
            ax.plot(x, a, "-o", ms=2)
            ax.set_xlabel(_axis_label(names[0], result.length_unit))
            ax.set_ylabel(label, fontsize=7)
        else:
            y = _axis_values(names[1], result.axes[names[1]])
            ax.set_facecolor("0.85")
            mesh = ax.pcolormesh(x, y, np.ma.masked_invalid(a).T, shading="nearest", cmap="viridis")
            bar = fig.colorbar(mesh, ax=ax)
            bar.set_label(label, fontsize=7)
            ax.set_xlabel(_axis_label(names[0], result.length_unit))
            ax.set_ylabel(_axis_label(names[1], result.length_unit))
        ax.set_title(_NAMES[n], fontsize=9)
    fig.suptitle(_title(result), fontsize=8)
    fig.tight_layout()
    return fig


def _plotly_figure(result, indices=None):
    from plotly import graph_objects as go
    from plotly.subplots import make_subplots

    panels = _panels(result, indices)
    cols = min(3, len(panels))
    rows = -(-len(panels) // cols)
    fig = make_subplots(rows=rows, cols=cols, subplot_titles=[_NAMES[n] for n, _ in panels])
    names = list(result.axes)
    x = _axis_values(names[0], result.axes[names[0]])
    for k, (n, a) in enumerate(panels):
        r, c = k // cols + 1, k % cols + 1
        label = index_label(n, result.characteristic_length, result.length_unit)
        if len(names) == 1:
            fig.add_trace(go.Scatter(x=x, y=a, name=label, mode="lines+markers"), row=r, col=c)
        else:
            y = _axis_values(names[1], result.axes[names[1]])
            sx = "xaxis" if k == 0 else f"xaxis{k + 1}"
            sy = "yaxis" if k == 0 else f"yaxis{k + 1}"
            dx, dy = fig.layout[sx].domain, fig.layout[sy].domain
            fig.add_trace(go.Heatmap(x=x, y=y, z=a.T, colorscale="Viridis",
                                     colorbar={"title": {"text": label, "side": "right"}, "x": dx[1] + 0.005,
                                               "y": 0.5 * (dy[0] + dy[1]), "len": dy[1] - dy[0], "thickness": 10}),
                          row=r, col=c)
        fig.update_xaxes(title_text=_axis_label(names[0], result.length_unit), row=r, col=c)
        if len(names) == 2:
            fig.update_yaxes(title_text=_axis_label(names[1], result.length_unit), row=r, col=c)
    fig.update_layout(title=_title(result), height=420 * rows, width=520 * cols, showlegend=False)
    return fig


def write_maps_plot(result, path, indices=None) -> Path:
    """Write the figure: ``.html`` interactive (plotly), ``.png`` / ``.pdf`` / ``.svg`` static."""
    path = Path(path)
    if len(result.axes) > 2:
        raise ValueError("write_maps_plot: 1 or 2 grid axes (slice a 3-axis map first)")
    if path.suffix.lower() == ".html":
        _plotly_figure(result, indices).write_html(str(path), include_plotlyjs=True)
    else:
        maps_figure(result, indices).savefig(path, dpi=120)
    return path
