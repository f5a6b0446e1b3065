"""``spatialmech synth``: linkage synthesis commands (thin: parse, call, print).

User errors raise ``ValueError`` / ``KeyError``; the main CLI group turns them into one-line
``error: ...`` messages with exit code 2.
"""

from __future__ import annotations

import json
from pathlib import Path

import click
import numpy as np

from ..serialize import json_default

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
@click.option("--samples", type=click.IntRange(min=8), default=360, show_default=True,
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
    from ..model.schema import dump
    from ..synthesis.rccc import synthesize_rccc
    from ..synthesis.tasks import resolve_task

    t = resolve_task(task)
    res = synthesize_rccc(t, pick=pick, samples=samples)
    if save_file is not None:
        dump(res.linkage, save_file)
    if plot_dir is not None:
        from ..synthesis.figures import write_all

        write_all(res, plot_dir)
    d = res.to_dict()
    if as_json:
        click.echo(json.dumps(d, indent=2, default=json_default, allow_nan=False))
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
@click.option("--samples", type=click.IntRange(min=2), default=40, show_default=True,
              help="Family points listed in the JSON, spread over the branches by arc length.")
@click.option("--pick", type=click.IntRange(min=0), default=5, show_default=True,
              help="Number of small-slide dyads to pick (5: also assemble and check the 5-CS).")
@click.option("--save", "save_file", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the 5-CS of the five picked dyads as a model file (TOML); needs --pick 5.")
@click.option("--starts", type=click.IntRange(min=1), default=60, show_default=True,
              help="Random starts of the multi-start search for branches of the family.")
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the random starts.")
def cs(positions_file, as_json, samples, pick, save_file, starts, seed):
    """Seven-position synthesis of CS dyads and a 5-CS linkage (paper A, section 3).

    The CS dyads of seven positions form a one-parameter family (15 unknowns, 14 equations,
    eqs 22-26): traced by continuation, then the dyads with the smallest largest C slide are
    picked; five of them make a 5-CS linkage, checked at the seven positions (pose errors,
    mobility).  Lengths in the positions' unit, angles in degrees.

    \b
    Examples:
      spatialmech synth cs
      spatialmech synth cs --positions my-7-positions.toml --json --save five-cs.toml
    """
    from ..model.schema import dump, load_positions
    from ..synthesis.cs_dyads import assemble_5cs, check_5cs, synthesize_cs

    if save_file is not None and pick != 5:
        raise ValueError(f"save: a 5-CS linkage needs --pick 5 (got --pick {pick})")
    if positions_file is not None:
        poses = load_positions(positions_file)
        source = str(positions_file)
    else:
        from ..catalog.papers import five_cs_positions

        poses = five_cs_positions()
        source = "paper A table 9"
    fam = synthesize_cs(poses, n_starts=starts, seed=seed, pick=pick)
    d = fam.to_dict(samples=samples)
    d["positions_source"] = source
    check = mech = None
    if pick == 5:
        if len(fam.picks) < 5:
            raise ValueError(f"pick: only {len(fam.picks)} well separated dyads found; try more --starts")
        mech = assemble_5cs(fam.task, fam.picks)
        check = check_5cs(mech, fam.picks)
        d["five_cs"] = check.to_dict()
        if save_file is not None:
            dump(mech, save_file)
    if as_json:
        click.echo(json.dumps(d, indent=2, default=json_default, allow_nan=False))
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
                     f" all exact: {bool(np.all(check.exact))}")
    if save_file is not None:
        lines.append(f"  wrote {save_file}")
    click.echo("\n".join(lines))
