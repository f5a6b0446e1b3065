"""Shared Matplotlib helpers of the reports: figures as PNG bytes (Agg canvas, never shown).

A report figure is a :class:`ReportFigure`: a file name, a title, a caption and the PNG bytes.
The report writes the bytes under ``DIR/figures/`` and embeds them in ``index.html`` as a
base64 ``data:`` URI (self-contained, opens offline).  Nothing here computes kinematics: the
helpers take arrays that the analyses produced.  Angles on axes are labelled in degrees,
lengths in the model's length unit (the caller passes the labels).
"""

from __future__ import annotations

import base64
import io
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import ListedColormap
from matplotlib.figure import Figure

from ..errors import InputError

__all__ = [
    "ReportFigure",
    "curves",
    "figure_from_file",
    "new_figure",
    "scalar_field",
    "sign_matrix",
    "to_png",
]

#: Resolution of the report PNGs (dots per inch).
DPI = 100
#: Colours of negative / zero / positive signs in sign tables.
_SIGN_CMAP = ListedColormap(["#d6604d", "#f7f7f7", "#4393c3"])


@dataclass(frozen=True)
class ReportFigure:
    """One figure of a report: ``name`` is the file name under ``figures/`` (``*.png``)."""

    name: str
    title: str
    caption: str
    png: bytes = field(repr=False)

    def data_uri(self) -> str:
        """The PNG as a ``data:image/png;base64,...`` URI (for a self-contained page)."""
        return "data:image/png;base64," + base64.b64encode(self.png).decode("ascii")

    def to_dict(self) -> dict:
        return {"file": f"figures/{self.name}", "title": self.title, "caption": self.caption}


def new_figure(figsize=(7.0, 4.2)) -> Figure:
    """A Matplotlib figure on an Agg canvas (no GUI, thread-safe, never shown)."""
    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def to_png(fig: Figure, name: str, title: str, caption: str) -> ReportFigure:
    """Render ``fig`` to PNG bytes (``DPI``) as a :class:`ReportFigure`."""
    if not name.endswith(".png"):
        raise InputError(f"name: expected a file name ending in .png, got {name!r}")
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI)
    return ReportFigure(name, title, caption, buf.getvalue())


def figure_from_file(path, name: str, title: str, caption: str) -> ReportFigure:
    """A PNG written by another module (e.g. :func:`spatialmech.present.synthesis_figures.write_all`)."""
    return ReportFigure(name, title, caption, Path(path).read_bytes())


def sign_matrix(ax, values: np.ndarray, rows: Sequence[str], cols: Sequence[str], *, title: str = "") -> None:
    """A table of signs: cell ``(i, j)`` coloured by ``sign(values[i, j])`` and labelled +, - or 0.

    Used for paper A's DJ sign tables (rows = drivers, columns = task positions)."""
    v = np.asarray(values, dtype=float)
    s = np.sign(v)
    ax.imshow(s, cmap=_SIGN_CMAP, vmin=-1, vmax=1, aspect="auto")
    for i in range(s.shape[0]):
        for j in range(s.shape[1]):
            ax.text(j, i, {1.0: "+", -1.0: "\u2212", 0.0: "0"}[float(s[i, j])], ha="center", va="center", fontsize=11)
    ax.set_xticks(range(len(cols)), cols)
    ax.set_yticks(range(len(rows)), rows)
    ax.set_xticks(np.arange(-0.5, len(cols)), minor=True)
    ax.set_yticks(np.arange(-0.5, len(rows)), minor=True)
    ax.grid(which="minor", color="#999999", linewidth=0.5)
    ax.tick_params(which="minor", length=0)
    if title:
        ax.set_title(title, fontsize=10)


def curves(ax, x, ys: dict[str, np.ndarray], *, xlabel: str, ylabel: str, title: str = "",
           markers: Sequence[tuple[float, str]] = (), zero_line: bool = False, logy: bool = False) -> None:
    """Several labelled curves over one abscissa; ``markers``: vertical lines ``(x, label)``."""
    x = np.asarray(x, dtype=float)
    for label, y in ys.items():
        ax.plot(x, np.asarray(y, dtype=float), label=label, linewidth=1.4)
    if zero_line:
        ax.axhline(0.0, color="#444444", linewidth=0.7)
    for xm, label in markers:
        ax.axvline(xm, color="#b3261e", linewidth=0.8, linestyle="--")
        ax.annotate(label, (xm, 1.0), xycoords=("data", "axes fraction"), rotation=90, fontsize=7,
                    ha="right", va="top", color="#b3261e")
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title, fontsize=10)
    if len(ys) > 1:
        ax.legend(fontsize=8)
    ax.grid(alpha=0.3)


def scalar_field(ax, x, y, values, *, xlabel: str, ylabel: str, label: str, title: str = "",
                 zero_contour: bool = True, cmap: str = "viridis"):
    """A 2-D map ``values[iy, ix]`` over the grid ``x`` (columns) x ``y`` (rows), with its zero
    contour drawn in red when ``zero_contour`` (e.g. ``det J = 0``: a singularity locus)."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    V = np.asarray(values, dtype=float)
    im = ax.pcolormesh(x, y, V, shading="auto", cmap=cmap)
    ax.figure.colorbar(im, ax=ax, label=label)
    if zero_contour and np.nanmin(V) < 0 < np.nanmax(V):
        ax.contour(x, y, V, levels=[0.0], colors="#d62728", linewidths=1.5)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title, fontsize=10)
    return im


def legend_once(ax, fontsize: float = 8) -> None:
    """A legend with each label once (the first handle drawn with it), if anything is labelled."""
    seen: dict = {}
    for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
        seen.setdefault(label, handle)
    if seen:
        ax.legend(seen.values(), seen.keys(), fontsize=fontsize, loc="best")


def figure_path(path, name: str = "plot") -> Path:
    """``path`` as a Path, checked to end in .png, .svg or .pdf (else an error naming ``name``)."""
    p = Path(path)
    if p.suffix.lower() not in (".png", ".svg", ".pdf"):
        raise InputError(f"{name}: expected a .png, .svg or .pdf file name, got {str(p)!r}")
    return p
