"""Figures of the RCCC synthesis, paper D (Matplotlib, Agg canvas, written to files; never shown).

Every function takes result objects and a path, writes one PNG (or any format Matplotlib
infers from the suffix) and returns the path.  Angles on axes are labelled in degrees,
lengths in the task's length unit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from ..kinematics.closure import Configuration, joint_points
from ..synthesis.burmester import BurmesterCurves, poles
from ..synthesis.rccc import RCCCResult
from ..synthesis.regions import TYPES, Region1, Region2, solution_region_2
from ..synthesis.tasks import TaskPositions

__all__ = ["plot_curves", "plot_linkage", "plot_region1", "plot_region2", "plot_solution_lines", "write_all"]

_TYPE_COLOURS = np.array(
    [[0.20, 0.55, 0.85], [0.95, 0.60, 0.15], [0.30, 0.70, 0.30], [0.80, 0.30, 0.35], [0.0, 0.0, 0.0]]
)


def _save(fig: Figure, path) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    FigureCanvasAgg(fig)
    fig.savefig(path, dpi=110)
    return path


def _sphere(ax):
    a, b = np.mgrid[0 : 2 * np.pi : 40j, 0 : np.pi : 20j]
    ax.plot_wireframe(np.cos(a) * np.sin(b), np.sin(a) * np.sin(b), np.cos(b), color="0.85", linewidth=0.4)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")


def plot_curves(curves: BurmesterCurves, path, task: TaskPositions | None = None) -> Path:
    """Circle-point and center-point curves on the unit sphere (both antipodal copies), with the
    poles when ``task`` is given."""
    fig = Figure(figsize=(11, 5.2))
    for col, (pts, title, key) in enumerate(
        [(curves.u, "circle-point curve (moving axes u0, position 1)", "circle"),
         (curves.v, "center-point curve (fixed axes v)", "center")]
    ):
        ax = fig.add_subplot(1, 2, col + 1, projection="3d")
        _sphere(ax)
        for b in range(curves.n_branches):
            sel = curves.branch == b
            for sgn in (1, -1):
                P = sgn * pts[sel]
                ax.plot(P[:, 0], P[:, 1], P[:, 2], ".", ms=1.5, color=f"C{b}",
                        label=f"branch {b} ({curves.kinds[b]})" if sgn == 1 else None)
        if task is not None:
            for name, pl in poles(task).items():
                p = np.array(pl[key])
                ax.scatter(*p, color="k", s=12)
                ax.text(*(1.08 * p), name, fontsize=7)
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=8, loc="upper left")
    return _save(fig, path)


def plot_region1(region: Region1, path, mark: tuple[float, float] | None = None) -> Path:
    """Solution region 1: colour = type, pale = defective (circuit, branch or order), black =
    degenerate; ``mark`` = (t_in, t_out) of the chosen linkage."""
    img = _TYPE_COLOURS[region.type.astype(int)]
    bad = region.defects != 0
    img = np.where(bad[..., None], 0.35 * img + 0.65, img)
    fig = Figure(figsize=(6.5, 6))
    ax = fig.add_subplot(1, 1, 1)
    ext = (region.t_out[0], region.t_out[-1], region.t_in[0], region.t_in[-1])
    ax.imshow(img, origin="lower", extent=ext, aspect="auto", interpolation="nearest")
    if mark is not None:
        ax.plot(mark[1], mark[0], "k*", ms=14, mec="w")
    ax.set_xlabel("output dyad: curve parameter t_out (branch + arc fraction)")
    ax.set_ylabel("input dyad: curve parameter t_in (branch + arc fraction)")
    ax.set_title("solution region 1 (spherical 4R; pale = defective)", fontsize=10)
    handles = [Patch(color=_TYPE_COLOURS[k], label=TYPES[k]) for k in range(len(TYPES))]
    handles.append(Patch(color=0.35 * _TYPE_COLOURS[0] + 0.65, label="defective (pale)"))
    ax.legend(handles=handles, fontsize=8, loc="upper right")
    return _save(fig, path)


def plot_solution_lines(res: RCCCResult, path, span: float | None = None) -> Path:
    """The two pairs of solution lines (paper D fig 4) around the chosen dyads."""
    span = span or 2.0 * res.task.length_scale
    fig = Figure(figsize=(7, 6))
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    for line, dy, lab in ((res.line_in, res.input_dyad, "input"), (res.line_out, res.output_dyad, "output")):
        h = np.linspace(dy.h - span, dy.h + span, 2)
        P1, P2 = line.points(h)
        ax.plot(*P1.T, label=f"{lab}: P1 (moving-axis foot)")
        ax.plot(*P2.T, "--", label=f"{lab}: P2 (fixed-axis foot)")
        ax.plot(*np.array([dy.P1, dy.P2]).T, "k-o", ms=3)
    ax.scatter(*res.task.p.T, color="k", s=10, label="task points")
    ax.set_xlabel(f"x ({res.task.length_unit})")
    ax.set_ylabel(f"y ({res.task.length_unit})")
    ax.set_zlabel(f"z ({res.task.length_unit})")
    ax.legend(fontsize=8)
    ax.set_title("solution lines (parameter h = signed common-normal length)", fontsize=10)
    return _save(fig, path)


def plot_region2(region: Region2, path, mark: tuple[float, float] | None = None) -> Path:
    """Solution region 2 coloured by the sign pattern of the input C joint's slide increments
    (paper D fig 5); ``mark`` = (h_in, h_out) of the chosen linkage."""
    uniq = sorted(set(region.patterns.tolist()))
    code = np.array([uniq.index(p) for p in region.patterns])
    grid = np.broadcast_to(code[:, None], (len(region.h_in), len(region.h_out)))
    fig = Figure(figsize=(6.5, 6))
    ax = fig.add_subplot(1, 1, 1)
    ext = (region.h_out[0], region.h_out[-1], region.h_in[0], region.h_in[-1])
    cmap = __import__("matplotlib").colormaps["tab10"]
    ax.imshow(grid, origin="lower", extent=ext, aspect="auto", interpolation="nearest", cmap=cmap, vmin=0, vmax=9)
    ax.axhline(region.best_h_in, color="k", lw=1)
    if mark is not None:
        ax.plot(mark[1], mark[0], "k*", ms=14, mec="w")
    ax.set_xlabel("output dyad: h_out (length unit)")
    ax.set_ylabel("input dyad: h_in (length unit)")
    ax.set_title(f"solution region 2 (4C); line: smallest max |slide| = {region.best_max_abs_slide:.3g}", fontsize=9)
    ax.legend(handles=[Patch(color=cmap(k), label=f"slides {p}") for k, p in enumerate(uniq)], fontsize=8)
    return _save(fig, path)


def plot_linkage(res: RCCCResult, path) -> Path:
    """The RCCC at the four task positions (3-D): joint axes, links, coupler and task points."""
    mech = res.linkage
    cfgs = (Configuration.reference(mech), *res.check.configurations)
    L = res.task.length_scale * 0.4
    fig = Figure(figsize=(8, 7))
    ax = fig.add_subplot(1, 1, 1, projection="3d")
    axes_ref = [j.freedoms[0].direction for limb in mech.limbs for j in limb.joints]
    for k, cfg in enumerate(cfgs):
        pts = joint_points(mech, cfg)
        D = cfg.D
        # moving joints' points and axes move with the coupler; fixed ones stay
        P = [pts[0][0], D[:3, :3] @ mech.limbs[0].joints[1].point + D[:3, 3],
             D[:3, :3] @ mech.limbs[1].joints[1].point + D[:3, 3], pts[1][0]]
        dirs = [axes_ref[0], D[:3, :3] @ axes_ref[1], D[:3, :3] @ axes_ref[3], axes_ref[2]]
        col = f"C{k}"
        ax.plot(*np.array(P).T, "-o", color=col, ms=3, label=f"position {res.task.names[k]}")
        for p, d in zip(P, dirs, strict=True):
            ax.plot(*np.array([p - L * d, p + L * d]).T, ":", color=col, lw=0.8)
        tp = D[:3, :3] @ mech.platform_point + D[:3, 3]
        ax.plot(*np.array([P[1], tp, P[2]]).T, "-", color=col, lw=0.6)
        ax.scatter(*res.task.p[k], color="k", marker="x")
    ax.set_xlabel(f"x ({res.task.length_unit})")
    ax.set_ylabel(f"y ({res.task.length_unit})")
    ax.set_zlabel(f"z ({res.task.length_unit})")
    ax.legend(fontsize=8)
    ax.set_title("RCCC at the task positions (x = task points; dotted = joint axes)", fontsize=10)
    return _save(fig, path)


def write_all(res: RCCCResult, out_dir, *, n: int = 121) -> list[Path]:
    """All figures of a synthesis into ``out_dir``: curves, region 1, solution lines, region 2,
    linkage.  Region 2 spans ``+-2`` task length scales around the chosen dyads."""
    out = Path(out_dir)
    span = 2.0 * res.task.length_scale
    r2 = solution_region_2(
        res.line_in, res.line_out,
        np.linspace(res.input_dyad.h - span, res.input_dyad.h + span, n),
        np.linspace(res.output_dyad.h - span, res.output_dyad.h + span, n),
    )
    return [
        plot_curves(res.curves, out / "burmester_curves.png", res.task),
        plot_region1(res.region1, out / "solution_region_1.png", mark=(res.t_in, res.t_out)),
        plot_solution_lines(res, out / "solution_lines.png"),
        plot_region2(r2, out / "solution_region_2.png", mark=(res.input_dyad.h, res.output_dyad.h)),
        plot_linkage(res, out / "rccc_linkage.png"),
    ]
