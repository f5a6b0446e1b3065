"""Figure of an inverse-dynamics result (:class:`~spatialmech.api.dynamics.DynamicsResult`,
Matplotlib: PNG, PDF, SVG): every actuator's effort against time, forces (N) and torques (N m) on
their own axes, labelled with their units."""

from __future__ import annotations

from pathlib import Path

__all__ = ["dynamics_figure", "write_dynamics_plot"]


def dynamics_figure(result):
    """A Matplotlib ``Figure`` (nothing shown or written)."""
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    mech = result.mechanism
    groups: dict[str, list[int]] = {"force": [], "torque": []}
    for j, a in enumerate(result.actuators):
        groups["force" if mech.freedom(a).freedom.kind == "P" else "torque"].append(j)
    kinds = [k for k in ("force", "torque") if groups[k]]
    fig = Figure(figsize=(6.4, 2.6 + 1.9 * len(kinds)))
    for i, kind in enumerate(kinds):
        ax = fig.add_subplot(len(kinds), 1, i + 1)
        for j in groups[kind]:
            ax.plot(result.times, result.efforts[:, j], "-o", ms=3, label=result.actuators[j])
        ax.set_ylabel("actuator force [N]" if kind == "force" else "actuator torque [N m]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        if i == len(kinds) - 1:
            ax.set_xlabel("time [s]")
    g = ", ".join(f"{v:g}" for v in result.gravity)
    fig.suptitle(f"{mech.name}: inverse dynamics (gravity ({g}) m/s^2)", fontsize=9)
    fig.tight_layout()
    return fig


def write_dynamics_plot(result, path) -> Path:
    """Write the figure (``.png``, ``.pdf``, ``.svg``)."""
    path = Path(path)
    dynamics_figure(result).savefig(path, dpi=120)
    return path
