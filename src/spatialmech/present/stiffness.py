"""Figure of a :class:`~spatialmech.analysis.stiffness_map.StiffnessMap` (Matplotlib: PNG, PDF,
SVG): the softest principal stiffness over a workspace slice, a colour map for two grid axes, a
curve for one; cells without a value (outside the limits, out of reach) are left grey, singular
cells are 0; the colour bar names the unit."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["softest_label", "stiffness_map_figure", "write_stiffness_plot"]

_ANGLES = ("alpha", "beta", "gamma")


def softest_label(result) -> str:
    """The colour-bar title: the quantity and its unit."""
    default = " (per unit actuator stiffness: none in the model)" if result.defaulted else ""
    return (f"softest stiffness [N/{result.length_unit}; nondimensional about the platform point, "
            f"L = {result.characteristic_length:.4g} {result.length_unit}]{default}")


def _axis(c: str, result) -> tuple[np.ndarray, str]:
    v = result.axes[c]
    return (np.degrees(v), f"{c} [deg]") if c in _ANGLES else (np.asarray(v), f"{c} [{result.length_unit}]")


def stiffness_map_figure(result):
    """A Matplotlib ``Figure`` (nothing shown or written)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    names = list(result.axes)
    if len(names) > 2:
        raise ValueError("stiffness_map_figure: 1 or 2 grid axes")
    fig = Figure(figsize=(6.0, 4.6))
    ax = fig.add_subplot(1, 1, 1)
    a = np.where(np.isfinite(result.softest), result.softest, np.nan)
    x, xl = _axis(names[0], result)
    if len(names) == 1:
        ax.plot(x, a, "-o", ms=3)
        ax.set_xlabel(xl)
        ax.set_ylabel(softest_label(result), fontsize=7)
    else:
        y, yl = _axis(names[1], result)
        ax.set_facecolor("0.85")
        mesh = ax.pcolormesh(x, y, np.ma.masked_invalid(a).T, shading="nearest", cmap="viridis")
        bar = fig.colorbar(mesh, ax=ax)
        bar.set_label(softest_label(result), fontsize=7)
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
    fixed = ", ".join(f"{c}={np.degrees(v):.4g} deg" if c in _ANGLES else f"{c}={v:.4g} {result.length_unit}"
                      for c, v in result.fixed.items())
    ax.set_title(f"{result.mechanism}: softest stiffness ({result.kind} slice; {fixed})", fontsize=8)
    fig.tight_layout()
    return fig


def write_stiffness_plot(result, path) -> Path:
    """Write the figure (``.png``, ``.pdf``, ``.svg``)."""
    path = Path(path)
    stiffness_map_figure(result).savefig(path, dpi=120)
    return path
