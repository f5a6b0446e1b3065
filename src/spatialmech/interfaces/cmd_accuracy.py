"""``spatialmech accuracy``: the output pose error from actuator errors, joint clearances and
manufacturing tolerances (``sm.accuracy``; docs/accuracy.md).  Parse, call ``sm.accuracy``, render."""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from .. import api as sm
from ..errors import InputError, require
from .cmd_kinematics import resolve_pose, with_pose
from .common import emit_json, json_option, tol_option


def _row(name: str, v, unit: str) -> str:
    v = np.asarray(v, dtype=float)
    pos = ", ".join(f"{x:.3g}" for x in v[:3])
    rot = ", ".join(f"{x:.3g}" for x in np.degrees(v[3:]))
    return f"  {name:<34s} dp ({pos}) {unit}   rotation ({rot}) deg"


def _text(r) -> list[str]:
    a, mech, u = r.analysis, r.mechanism, r.mechanism.length_unit
    d = r.to_dict()
    lines = [f"{mech.name}: accuracy at the output point {tuple(round(x, 6) for x in d['output_point_len'])} {u}, "
             f"{len(a.params)} error sources",
             _row("first order, standard deviation", a.std_first_order, u),
             _row("worst case over the box (linear)", a.worst_case, u),
             _row("exact model at that vertex", a.exact_at_worst, u)]
    if a.mc_errors.shape[0]:
        lines.append(_row(f"Monte-Carlo std ({a.mc_errors.shape[0]} assembled)", r.std_monte_carlo, u))
        lines.append(_row("Monte-Carlo largest |error|", np.abs(a.mc_errors).max(axis=0), u))
    if a.samples:
        lines.append(f"  Monte-Carlo: {a.samples} samples, {a.mc_failures} did not assemble; within the worst case: "
                     f"{d['monte_carlo']['within_worst_case']}")
    if a.inconsistent:
        lines.append(f"  note: redundant constraints: the first-order errors cannot all be absorbed (relative residual "
                     f"{a.inconsistency:.3g}); the design deforms or does not assemble")
    b = a.breakdown
    if b is not None:
        if b.loses_mobility:
            lines.append(f"  OVERCONSTRAINED: generic tolerances remove {b.nominal_dof - b.perturbed_dof} degree(s) of "
                         f"freedom; numerically visible from {b.breaks_at_scale:.3g} x the tolerances (point "
                         f"{b.breaks_at_point_m or 0:.3g} {u}, axis {np.degrees(b.breaks_at_axis_rad or 0):.3g} deg) at "
                         f"the rank tolerance {b.rank_tolerance:g}; loss rate {b.rate:.3g} per unit scale (bisection)")
        else:
            lines.append(f"  mobility kept under the tolerances (dof {b.nominal_dof}, up to 1000 x the tolerances)")
    lines.append("  " + d["error_model"])
    return lines


@click.command(name="accuracy")
@click.argument("model")
@with_pose
@click.option("--actuator-error", "act", type=float, default=0.0, show_default=True,
              help="Actuator error, each actuator's own unit (m for a slide, rad for a rotation).")
@click.option("--clearance", "clearance", type=float, default=0.0, show_default=True,
              help="Clearance of each passive joint, model length unit along each world axis.")
@click.option("--geometry-tolerance", "geometry", type=float, default=0.0, show_default=True,
              help="Tolerance of each joint point component, model length unit.")
@click.option("--axis-tolerance-deg", "axis_deg", type=float, default=None,
              help="Tolerance of each axis rotation, degrees (default: the geometry tolerance / L, in radians).")
@click.option("--samples", type=int, default=200, show_default=True, help="Monte-Carlo samples (0: none).")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the samples.")
@click.option("--mode", default=None, help="Mode of a metamorphic mechanism.")
@click.option("--plot", "plot", default=None, help="Write a figure (.png, .pdf, .svg).")
@tol_option("rank")
@json_option
def accuracy_cmd(model, xyz, euler, position, act, clearance, geometry, axis_deg, samples, seed, mode, plot, as_json):
    """Accuracy: the output pose error from actuator errors, joint clearances and tolerances of the
    joint points and axes: first order, worst case over the tolerance box, Monte-Carlo with the exact
    forward position; overconstrained designs that lose their mobility are flagged.

    \b
    Examples:
      spatialmech accuracy stewart-6sps --pose 0.05,0,1.0,ZYX,10,0,0 --actuator-error 1e-5 --geometry-tolerance 1e-5
      spatialmech accuracy three-rps --xyz 0 0 0.33 --actuator-error 1e-5 --clearance 1e-5 --json
      spatialmech accuracy bennett --geometry-tolerance 1e-5 --samples 0
    """
    if plot is not None and Path(plot).suffix.lower() not in (".png", ".pdf", ".svg"):
        raise InputError(f"--plot: expected a .png, .pdf or .svg file, got {plot!r}")
    if plot is not None:  # before any work: the extra to install, exit 2
        require("plot", "matplotlib", what="--plot")
    mech = sm.load_model(model)
    given = xyz is not None or euler is not None or position is not None
    pose = resolve_pose(mech, xyz, euler, position) if given else None
    tol = {"actuator": act, "clearance": clearance, "geometry": geometry}
    if axis_deg is not None:
        tol["axis"] = float(np.radians(axis_deg))
    r = sm.accuracy(mech, pose, tolerances=tol, samples=samples, seed=seed, mode=mode)
    if plot is not None:
        from ..present.accuracy import write_accuracy_plot

        write_accuracy_plot(r, plot)
    if as_json:
        emit_json("accuracy", r.mechanism, {**r.to_dict(), "plot": plot})
        return
    click.echo("\n".join(_text(r)))
    if plot is not None:
        click.echo(f"  figure: {plot}")
