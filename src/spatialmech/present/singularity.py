"""Figure of a singularity slice (:class:`~spatialmech.analysis.singularity.SliceResult`): the
sign of ``det J`` with its zero contours (the singularity loci) and the scale-free ``sigma_min``
(Matplotlib, Agg canvas; nothing is shown).  Axes carry the units of the slice (degrees for
angles, as :meth:`~spatialmech.analysis.task_slice.TaskSliceResult.for_display` gives them)."""

from __future__ import annotations

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..analysis.singularity import SliceResult

__all__ = ["slice_figure"]


def slice_figure(res: SliceResult, title: str = ""):
    """Sign of ``det J`` with its zero contours (the singularity loci) and ``sigma_min``."""
    f = Figure(figsize=(11, 4.6), dpi=110)
    FigureCanvasAgg(f)
    ax1, ax2 = f.subplots(1, 2)
    U, V = np.meshgrid(res.u, res.v)
    ax1.pcolormesh(U, V, np.sign(res.det), cmap="coolwarm", vmin=-1.5, vmax=1.5, shading="auto")
    if np.nanmin(res.det) < 0 < np.nanmax(res.det):
        # masked where no pose closes on the branch: no zero is drawn across a gap or a branch switch
        ax1.contour(U, V, np.ma.masked_invalid(res.det), levels=[0.0], colors="k", linewidths=1.5)
    left = "sign of det J (red +, blue -); black: det J = 0"
    if res.branch is not None and np.any(res.branch == 1):
        jj, ii = np.nonzero(res.branch == 1)
        ax1.scatter(res.u[ii], res.v[jj], marker="x", s=14, c="0.3", linewidths=0.8,
                    label="another working mode (masked)")
        ax1.legend(loc="upper right", fontsize=8)
        left += "; x: branch switched"
    ax1.set_title(left, fontsize=10)
    c = ax2.pcolormesh(U, V, np.log10(np.maximum(res.sigma_min, 1e-12)), cmap="viridis", shading="auto")
    f.colorbar(c, ax=ax2, label="log10 sigma_min (scale-free)")
    ax2.set_title("distance to a singularity")
    for ax in (ax1, ax2):
        ax.set_xlabel(f"{res.names[0]} ({res.units[0]})")
        ax.set_ylabel(f"{res.names[1]} ({res.units[1]})")
    f.suptitle(title or "singularity loci")
    return f
