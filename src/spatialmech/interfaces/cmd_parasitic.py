"""``spatialmech parasitic``: the solved (parasitic) task coordinates over a grid of given ones."""

from __future__ import annotations

import click
import numpy as np

from .. import catalog
from ..kinematics.task_grid import solve_task_grid
from ..model.task import TASK_NAMES
from .common import check_output_file, emit_json, json_option
from .task_args import parse_axes, parse_task_at, task_from_free


def _unit_key(name: str) -> str:
    return f"{name}_deg" if name.startswith("a") else f"{name}_len"


def _shown(name: str, v):
    return np.degrees(v) if name.startswith("a") else np.asarray(v)


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
    mech = catalog.resolve(model)
    plot_path = check_output_file(plot, "--plot", suffixes=(".png", ".pdf", ".svg"))
    over = parse_axes(over_text, "--over", min_axes=1, max_axes=2)
    at = parse_task_at(at_text)
    task = task_from_free(free_text, mech, euler)
    grid = solve_task_grid(mech, over, at=at, task=task)
    solved = grid.solved
    n_ok = int(grid.converged.sum())
    table = {}
    for name in solved:
        k = TASK_NAMES.index(name)
        v = _shown(name, grid.values[..., k])
        table[_unit_key(name)] = [None if not np.isfinite(x) else float(x) for x in v.ravel()]
        ok = v[np.isfinite(v)]
        table[name] = {"min": float(ok.min()) if ok.size else None, "max": float(ok.max()) if ok.size else None}
    if plot_path is not None:
        from ..present.parasitic import parasitic_figure

        parasitic_figure(grid, plot_path)
    if as_json:
        emit_json("parasitic", mech, {
            "task": {"given": list(grid.given), "solved": list(solved), "euler": grid.task.euler},
            "over": list(grid.over),
            "axes": {_unit_key(n): [float(x) for x in _shown(n, a)] for n, a in zip(grid.over, grid.axes, strict=True)},
            "held": {_unit_key(n): float(_shown(n, v)) for n, v in grid.fixed.items()},
            "grid_points": list(grid.shape), "cells": int(grid.converged.size), "n_converged": n_ok,
            "converged": [bool(c) for c in grid.converged.ravel()],
            "solved_values": {_unit_key(n): table[_unit_key(n)] for n in solved},
            "elapsed_s": float(grid.seconds), "plot": None if plot_path is None else str(plot_path)})
        return
    unit = mech.length_unit
    dims = " x ".join(f"{n} ({a.size})" for n, a in zip(grid.over, grid.axes, strict=True))
    click.echo(f"{mech.name}: parasitic motion over {dims}"
               f"; held {', '.join(f'{n} = {float(_shown(n, v)):.6g}' for n, v in grid.fixed.items()) or 'nothing'}"
               f"  (task {grid.task.euler}: given {', '.join(grid.given)}; solved {', '.join(solved)})")
    click.echo(f"  {n_ok} of {grid.converged.size} cells solved in {grid.seconds:.2f} s"
               + ("" if n_ok == grid.converged.size else "; unsolved cells are left empty (not reachable from a neighbour)"))
    for name in solved:
        r = table[name]
        u = "deg" if name.startswith("a") else unit
        if r["min"] is not None:
            click.echo(f"  {name}: {r['min']:.6g} .. {r['max']:.6g} {u}")
    if plot_path is not None:
        click.echo(f"  figure: {plot_path}")
