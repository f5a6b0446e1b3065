"""``spatialmech synth``: linkage synthesis commands (thin: parse, call, print).

User errors raise ``ValueError`` / ``KeyError``; the main CLI group turns them into one-line
``error: ...`` messages with exit code 2.
"""

from __future__ import annotations

from pathlib import Path

import click
import numpy as np

from .. import api as sm
from ..errors import InputError
from .common import SEED_MAX, check_output_dir, check_output_file, emit_json

__all__ = ["synth"]


@click.group()
def synth():
    """Synthesis of linkages for task positions (papers A and D).

    \b
    Examples:
      spatialmech synth rccc --json
      spatialmech synth cs --json
    """


@synth.command()
@click.argument("task", default="rccc-four-positions")
@click.option("--json", "as_json", is_flag=True, help="Print machine-readable JSON.")
@click.option("--plot", "plot_dir", type=click.Path(file_okay=False, path_type=Path), default=None,
              help="Write the figures (curves, regions 1 and 2, solution lines, linkage) into DIR.")
@click.option("--save", "save_file", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the RCCC as a model file (TOML) that the other commands accept.")
@click.option("--pick", type=click.Choice(["best-rc", "interior"]), default="best-rc", show_default=True,
              help="best-rc: smallest max input slide over curve and line; interior: the most "
                   "interior defect-free crank-rocker of region 1.")
@click.option("--samples", type=click.IntRange(min=8, max=5000), default=360, show_default=True,
              help="Samples per Burmester-curve branch.")
def rccc(task, as_json, plot_dir, save_file, pick, samples):
    """Four-position RCCC synthesis by solution regions (paper D).

    TASK is a ready-made task name (default rccc-four-positions, paper D table 1) or a TOML
    task file.  Lengths in the task's unit, angles in degrees.

    \b
    Examples:
      spatialmech synth rccc
      spatialmech synth rccc my-task.toml --json --plot figs --save rccc.toml
    """
    check_output_file(save_file, "--save")
    check_output_dir(plot_dir, "--plot")
    res = sm.synth_rccc(task, pick=pick, samples=samples, save=save_file, plot=plot_dir)
    t = res.task
    if as_json:
        emit_json("synth rccc", None, res.to_dict(), length_unit=t.length_unit)
        return
    u = t.length_unit
    lines = [
        f"RCCC for task {t.name} ({t.n} positions; {t.convention}); pick: {pick}",
        f"  spherical 4R: {res.linkage_type}, defects: {'none' if res.defects == 0 else res.defects}",
    ]
    for key, dy in (("input (R-C)", res.input_dyad), ("output (C-C)", res.output_dyad)):
        lines.append(
            f"  {key}: fixed axis {np.round(dy.v, 4).tolist()} through {np.round(dy.P2, 3).tolist()},"
            f" moving axis {np.round(dy.u, 4).tolist()} through {np.round(dy.P1, 3).tolist()},"
            f" twist {np.degrees(dy.twist_angle):.2f} deg, h = {dy.h:.3f} {u}"
        )
    lines += [
        f"  input C slides replaced by the R joint: {np.round(res.slides, 4).tolist()} {u}"
        f" (max |slide| {res.max_abs_slide:.4g} {u})",
        f"  closure at positions 2..{t.n}: position errors {np.round(res.check.position_errors, 4).tolist()} {u},"
        f" orientation errors {np.round(np.degrees(res.check.orientation_errors), 9).tolist()} deg",
    ]
    if save_file is not None:
        lines.append(f"  wrote {save_file}")
    if plot_dir is not None:
        lines.append(f"  figures in {plot_dir}")
    click.echo("\n".join(lines))


@synth.command()
@click.option("--positions", "positions_file", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="TOML file with exactly seven [[positions]] (default: paper A table 9).")
@click.option("--json", "as_json", is_flag=True, help="Print machine-readable JSON.")
@click.option("--samples", type=click.IntRange(min=2, max=10000), default=40, show_default=True,
              help="Family points listed in the JSON, spread over the branches by arc length.")
@click.option("--pick", type=click.IntRange(min=0, max=100), default=5, show_default=True,
              help="Number of small-slide dyads to pick (5: also assemble and check the 5-CS).")
@click.option("--save", "save_file", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the 5-CS of the five picked dyads as a model file (TOML); needs --pick 5.")
@click.option("--starts", type=click.IntRange(min=1, max=5000), default=60, show_default=True,
              help="Random starts of the multi-start search for branches of the family.")
@click.option("--seed", type=click.IntRange(0, SEED_MAX), default=0, show_default=True, help="Seed of the random starts.")
@click.option("--skip-defects", is_flag=True,
              help="Do not run the defect analysis of the 5-CS (faster; the result is then not a verified success).")
def cs(positions_file, as_json, samples, pick, save_file, starts, seed, skip_defects):
    """Seven-position synthesis of CS dyads and a 5-CS linkage (paper A, section 3).

    The CS dyads of seven positions form a one-parameter family (15 unknowns, 14 equations,
    eqs 22-26): traced by continuation, then the dyads with the smallest largest C slide are
    picked; five of them make a 5-CS linkage, checked at the seven positions (pose errors,
    mobility) and by the defect analysis (circuit, order and branch defects for every candidate
    driver, as `spatialmech defects`; about 10 s).  The synthesis is reported a success only
    when the linkage is defect-free for at least one driver; otherwise the output says what is
    wrong.  Lengths in the positions' unit, angles in degrees.

    \b
    Examples:
      spatialmech synth cs
      spatialmech synth cs --positions my-7-positions.toml --json --save five-cs.toml
      spatialmech synth cs --skip-defects
    """
    if save_file is not None and pick != 5:
        raise InputError(f"save: a 5-CS linkage needs --pick 5 (got --pick {pick})")
    check_output_file(save_file, "--save")
    say = None if as_json else (lambda done, total, msg: click.echo(f"  ... defects: {msg}", err=True))
    r = sm.synth_cs(positions_file, pick=pick, starts=starts, seed=seed, samples=samples,
                    check_defects=not skip_defects, save=save_file, progress=say)
    fam, check, source = r.family, r.check, r.positions_source
    d = r.to_dict()
    if as_json:  # lengths in the positions' own unit (a positions file names none)
        emit_json("synth cs", None, d, length_unit="unit")
        return
    lines = [
        f"CS dyads for the 7 positions of {source} (paper A eqs 22-26: 15 unknowns, 14 equations)",
        f"  family: {len(fam.branches)} branch(es) inside the box of {fam.extent:g} task scales"
        f" ({fam.task.scale:.4g} each), {fam.n_points} points; starts: {fam.starts['converged']}/"
        f"{fam.starts['tried']} converged",
    ]
    for k, b in enumerate(fam.branches):
        lines.append(f"    branch {k + 1}: arc {b.arc[-1]:.3g}, {'closed' if b.closed else 'ends: ' + ', '.join(b.ends)},"
                     f" smallest max |slide| {np.min(b.max_abs_slide):.4g}")
    for k, p in enumerate(fam.picks):
        lines.append(f"  pick {k + 1}: max |slide| {p.max_abs_slide:.4g}, u {np.round(p.u, 4).tolist()},"
                     f" B1 {np.round(p.B1, 3).tolist()}, M1 {np.round(p.M1, 3).tolist()},"
                     f" link {p.link_length:.4g}")
    if check is not None:
        lines.append(f"  5-CS: dof {check.dof}; at the 7 positions: max pose error {check.max_pose_error:.3g}"
                     f" (position/angle rad), max IK residual {np.max(check.ik_residuals):.3g},"
                     f" closes exactly at all 7: {bool(np.all(check.exact))}")
        dr = check.defects
        if dr is not None:
            circ = "; ".join("{" + ", ".join(f"P{i}" for i in c) + "}" for c in dr.circuits)
            lines.append(f"  defects: {len(dr.circuits)} circuit(s) {circ}; circuit defect: "
                         f"{'YES' if dr.circuit_defect else 'no'}, order defect: {'YES' if dr.order_defect else 'no'}")
            lines.append("  drivers: " + ", ".join(
                f"{v.driver} {'usable' if v.usable else ('branch defect' if v.branch_defect else 'not usable')}"
                for v in dr.drivers))
        lines.append(f"  result: {check.verdict()}")
    if save_file is not None:
        lines.append(f"  wrote {save_file}" + ("" if check is None or check.success else " (the linkage as synthesised; "
                                                "it is NOT usable as it stands: see the result above)"))
    click.echo("\n".join(lines))
