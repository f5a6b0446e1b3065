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
    """Synthesis of linkages for task positions (paper D).

    \b
    Example:
      spatialmech synth rccc --json
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
