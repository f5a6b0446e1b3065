"""Figure of an accuracy analysis (:func:`spatialmech.api.accuracy.accuracy`; Matplotlib: PNG, PDF,
SVG): per output component, the Monte-Carlo histogram of the exact model's error, the first-order
normal density with the same standard deviation, and the worst-case bounds; units labelled."""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = ["accuracy_figure", "write_accuracy_plot"]

_LABELS = ("dx [{u}]", "dy [{u}]", "dz [{u}]", "rotation x [deg]", "rotation y [deg]", "rotation z [deg]")


def accuracy_figure(result):
    """A Matplotlib ``Figure`` (nothing shown or written)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    a = result.analysis
    unit = result.mechanism.length_unit
    scale = np.array([1, 1, 1, *(3 * [np.degrees(1.0)])])
    fig = Figure(figsize=(10.0, 5.6))
    for c in range(6):
        ax = fig.add_subplot(2, 3, c + 1)
        wc, sd = a.worst_case[c] * scale[c], a.std_first_order[c] * scale[c]
        if a.mc_errors.shape[0]:
            ax.hist(a.mc_errors[:, c] * scale[c], bins=30, density=True, color="0.7", label="Monte-Carlo (exact)")
        if sd > 0:
            x = np.linspace(-wc, wc, 200)
            ax.plot(x, np.exp(-0.5 * (x / sd) ** 2) / (sd * np.sqrt(2 * np.pi)), "b-", lw=1, label="first order")
        for s in (-wc, wc):
            ax.axvline(s, color="r", ls="--", lw=1, label="worst case" if s > 0 else None)
        ax.set_xlabel(_LABELS[c].format(u=unit), fontsize=8)
        ax.tick_params(labelsize=7)
        if c == 0:
            ax.legend(fontsize=8)
    fig.suptitle(f"{result.mechanism.name}: output error (output point, rotation vector); "
                 f"{a.mc_errors.shape[0]} samples assembled, {a.mc_failures} failed", fontsize=9)
    fig.tight_layout()
    return fig


def write_accuracy_plot(result, path) -> Path:
    """Write the figure (``.png``, ``.pdf``, ``.svg``)."""
    path = Path(path)
    accuracy_figure(result).savefig(path, dpi=110)
    return path
