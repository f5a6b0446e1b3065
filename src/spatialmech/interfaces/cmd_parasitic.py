"""``spatialmech parasitic``: the solved (parasitic) task coordinates over a grid of given ones."""

from __future__ import annotations

import click
import numpy as np

from .. import api as sm
from ..errors import InputError
from ..present.numbers import fmt_number
from .common import check_output_file, emit_json, json_option, load_model
from .task_args import parse_axes, parse_free, parse_task_at


def _held(name: str, v: float, unit: str) -> str:
    return f"{name} = {np.degrees(v):.6g} deg" if name.startswith("a") else f"{name} = {v:.6g} {unit}"


@click.command(name="parasitic")
@click.argument("model")
@click.option("--over", "over_text", required=True,
              help="Grid of given coordinates NAME:MIN:MAX:N[,...] (1 or 2 axes; lengths in the model's unit, angles in deg).")
@click.option("--at", "at_text", default=None, help="Other given coordinates held, e.g. z=0.33 (angles in deg).")
@click.option("--free", "free_text", default=None,
              help="Coordinates to solve (default: those the model's task does not give).")
@click.option("--euler", "euler", default=None, help="Euler sequence of a1, a2, a3 (default: the model's task's, else ZYX).")
@click.option("--plot", "plot", default=None, help="Write a figure (PNG/PDF/SVG): one panel per solved coordinate.")
@json_option
def parasitic_cmd(model, over_text, at_text, free_text, euler, plot, as_json):
    """The parasitic motion of a lower-mobility mechanism: its solved task coordinates over a grid
    of the given ones (each cell by Newton from its solved neighbour).

    \b
    Examples:
      spatialmech parasitic three-rps --over a2:-20:20:41,a3:-20:20:41 --at z=0.33 --plot rps.png
      spatialmech parasitic three-prs --over a2:-10:10:5 --at z=0.3,a3=0 --json
    """
    mech = load_model(model)
    plot_path = check_output_file(plot, "--plot", suffixes=(".png", ".pdf", ".svg"))
    over = parse_axes(over_text, "--over", min_axes=1, max_axes=2)
    at = parse_task_at(at_text)
    free = parse_free(free_text)
    # --euler names the sequence of the task's angles (with --free: of the task it defines; without: of the
    # model's own task); the API checks the name
    try:
        table = sm.parasitic(mech, over, at=at, free=free, euler=euler, plot=plot_path)
    except InputError as e:
        if str(e).startswith("euler: "):  # the option's name
            raise InputError(f"--{e}") from None
        raise
    grid = table.grid
    solved = grid.solved
    n_ok = int(grid.converged.sum())
    if as_json:
        emit_json("parasitic", mech, table.to_dict(plot_path))
        return
    unit = mech.length_unit
    dims = " x ".join(f"{n} ({a.size})" for n, a in zip(grid.over, grid.axes, strict=True))
    click.echo(f"{mech.name}: parasitic motion over {dims}"
               f"; held {', '.join(_held(n, v, unit) for n, v in grid.fixed.items()) or 'nothing'}"
               f"  (task {grid.task.euler}: given {', '.join(grid.given)}; solved {', '.join(solved)})")
    click.echo(f"  {n_ok} of {grid.converged.size} cells solved in {grid.seconds:.2f} s"
               + ("" if n_ok == grid.converged.size else "; unsolved cells are left empty (not reachable from a neighbour)"))
    # round-off prints as 0, read against the model's size (lengths) or a radian in degrees (angles)
    for name, r in table.ranges.items():
        if r is not None:
            angle = name.startswith("a")
            lo, hi = (float(np.degrees(x)) if angle else float(x) for x in r)
            scale = float(np.degrees(1.0)) if angle else mech.characteristic_length
            click.echo(f"  {name}: {fmt_number(lo, '.6g', scale=scale)} .. {fmt_number(hi, '.6g', scale=scale)} "
                       f"{'deg' if angle else unit}")
    if plot_path is not None:
        click.echo(f"  figure: {plot_path}")
