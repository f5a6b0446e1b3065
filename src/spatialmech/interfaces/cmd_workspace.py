"""CLI command ``workspace``: orientation / position workspace under joint limits, and (``--task``)
the workspace over the task coordinates of a lower-mobility mechanism.

Angles at the command line are in degrees, lengths in the model's length unit (m).  ``--at``
takes ``name=value`` pairs separated by commas: ``x, y, z`` (m) and ``alpha, beta, gamma``
(deg), with ``R = Rz(gamma) Ry(beta) Rx(alpha)`` (intrinsic "ZYX", paper B eq 7); with
``--task``, task coordinates ``x, y, z`` and ``a1, a2, a3`` (deg, the task's Euler sequence).
"""

from __future__ import annotations

from typing import Any

import click
import numpy as np

from .. import api as sm
from ..errors import InputError
from .common import StderrProgress, UserError, check_output_file, emit_json, json_option, load_model, parse_number
from .task_args import cone_limits, freedom_limits, parse_axes, parse_free, parse_task_at

_ANGLES = ("alpha", "beta", "gamma")
#: Largest grid (poses) the slow general kernel accepts from the CLI unless --max-poses says more.
GENERAL_MAX_POSES = 4000


def parse_at(text: str | None) -> dict[str, float]:
    """``"z=0.1,alpha=5"`` -> ``{"z": 0.1, "alpha": radians(5)}`` (SI inside)."""
    out: dict[str, float] = {}
    if not text:
        return out
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        if "=" not in part:
            raise InputError(f"--at: expected name=value pairs separated by commas, got {part!r}")
        k, v = (s.strip() for s in part.split("=", 1))
        if k not in sm.WORKSPACE_COORDINATES:
            raise InputError(f"--at: unknown coordinate {k!r}; expected one of {', '.join(sm.WORKSPACE_COORDINATES)}")
        val = parse_number(v, "--at", k)
        out[k] = float(np.radians(val)) if k in _ANGLES else val
    return out


def _with_unit(key: str, value: float, fmt: str, length_unit: str) -> str:
    """``"alpha_deg", 5`` -> ``"alpha=5 deg"``; ``"z_len", 0.1`` -> ``"z=0.1 m"``."""
    name, unit = key.rsplit("_", 1)
    return f"{name}={value:{fmt}} {'deg' if unit == 'deg' else length_unit}"


def _text(res, length_unit: str = "m") -> str:
    d = res.to_dict()
    lines = [f"{res.mechanism}: {res.kind} workspace ({res.path} path"
             + (f": {res.path_reason}" if res.path_reason else "") + ")",
             "fixed: " + ", ".join(_with_unit(k, v, ".6g", length_unit) for k, v in d["fixed"].items()),
             f"orientation: {d['euler_sequence']}: {d['orientation_convention']}"]
    for c in res.free:
        u = "deg" if c in _ANGLES else length_unit
        ext = d["extents"][f"{c}_deg" if c in _ANGLES else f"{c}_len"]
        for key, label in (("alone", "alone"), ("set", "whole set")):
            if ext[key] is None:
                lines.append(f"  {c:5s} {label:9s}: empty")
                continue
            lo_l, hi_l = ext[f"{key}_active_limits"]
            lines.append(f"  {c:5s} {label:9s}: [{ext[key][0]:.4f}, {ext[key][1]:.4f}] {u}   limits: {lo_l} / {hi_l}")
    vkey = next(k for k in d if k.startswith("volume_") and k != "volume_note" and not k.startswith("volume_error"))
    power = vkey[-1] if vkey[-1].isdigit() else ""
    vunit = ("deg" if "_deg" in vkey else length_unit) + (f"^{power}" if power else "")
    err = d.get(vkey.replace("volume_", "volume_error_", 1))
    pm = "" if err is None else f" +- {err:.2g} (grid estimate |V_h - V_2h| + bisection tolerance)"
    lines.append(f"volume: {d[vkey]:.6g}{pm} {vunit} ({d['volume_note']})")
    lines.append("active limits (boundary points): " + ", ".join(f"{k} {v}" for k, v in res.active_limits.items()))
    lines.append(f"{res.n_poses} poses checked in {res.seconds:.2f} s; tolerance "
                 + ", ".join(_with_unit(k, v, ".3g", length_unit) for k, v in d["boundary_tol"].items()))
    return "\n".join(lines)


def _check_diameter(link_diameter) -> None:
    if link_diameter is not None and not (np.isfinite(link_diameter) and link_diameter >= 0):
        raise InputError(f"--link-diameter: expected a non-negative number of metres, got {link_diameter}")


def _option_message(msg: str, kind: str) -> str:
    """A library error with its argument names replaced by the command-line options to change."""
    for lib in ("max_poses", "max_cells"):  # "raise --max-poses to at least N" is advice that works
        msg = msg.replace(f"{lib} =", "--max-poses =").replace(f"raise {lib}", "raise --max-poses")
    for arg, opt in (("step", "--step-deg" if kind == "orientation" else "--step"),
                     ("tol", "--tol-deg" if kind == "orientation" else "--tol")):
        if msg.startswith(arg + ":"):
            msg = f"{opt} ({arg})" + msg[len(arg):]
    return msg


def _progress_bar():
    """A progress callback counting on stderr (:class:`.common.StderrProgress`) and its closer."""
    bar = StderrProgress()
    return bar, bar.close


def _task_text(res, length_unit: str) -> str:
    """The text report of a workspace over task coordinates."""

    def show(c: str, v: float) -> str:
        return f"{np.degrees(v):.4f} deg" if c.startswith("a") else f"{v:.6g} {length_unit}"

    held = ", ".join(f"{c} = {show(c, v)}" for c, v in res.fixed.items())
    lines = [f"{res.mechanism}: workspace over task coordinates {', '.join(res.over)}"
             + (f" ({held} held)" if held else "") + f"; solved: {', '.join(res.solved) or 'none'}",
             f"orientation: {res.to_dict()['orientation_convention']}"]
    for c in res.over:
        e = res.extents[c]
        lines.append(f"  {c:3s}: empty" if e is None else
                     f"  {c:3s}: [{show(c, e.lo)}, {show(c, e.hi)}]   limits: {e.lo_limit} / {e.hi_limit}")
    solved = [f"{c} [{show(c, res.ranges[c][0])}, {show(c, res.ranges[c][1])}]" for c in res.solved
              if res.ranges.get(c) is not None]
    if solved:
        lines.append("  solved over the reachable set: " + ", ".join(solved))
    n = int(res.feasible.size)
    lines.append(f"reachable: {res.n_feasible} of {n} grid cells ({100 * res.reachable_fraction:.1f} %); "
                 f"{int(res.converged.sum())} close" + ("" if res.volume is None else
                                                       f"; measure {_measure(res, length_unit)}"))
    if res.active_limits:
        lines.append("active limits (boundary points): " + ", ".join(f"{k} {v}" for k, v in res.active_limits.items()))
    elif not res.limit_names:
        lines.append("no limits: the model has none and none were given (--limit, --cone); "
                     "only closure bounds the set")
    lines.append(f"{res.n_solves} solves in {res.seconds:.2f} s ({res.n_solves / max(res.seconds, 1e-9):.0f} per s); "
                 "boundary tolerance " + ", ".join(f"{c} {show(c, t)}" for c, t in res.tol.items()))
    return "\n".join(lines)


def _measure(res, length_unit: str) -> str:
    """``"1.234 deg^2 +- 0.05 (grid estimate ...)"``: the task workspace's measure and its error."""
    d = len(res.over)
    power = f"^{d}" if d > 1 else ""
    if res.over[0].startswith("a"):
        scale, unit = float(np.degrees(1.0)) ** d, "deg" + power
    else:
        scale, unit = 1.0, length_unit + power
    err = "" if res.volume_error is None else (f" +- {res.volume_error * scale:.2g} (grid estimate |V_h - V_2h| "
                                               "+ boundary tolerance)")
    return f"{res.volume * scale:.6g}{err} {unit}"


def _task_workspace(mech, over, at, free, limit_args, tol_deg, tol_m, max_cells, plot, as_json) -> None:
    """``workspace --task``: the grid, the held coordinates, the solve, the output."""
    free_names = parse_free(free)
    if over is None:
        hint = sm.suggest_task_grid(mech, free=free_names, degrees=True)
        over_s, at_s = _grid_text(hint)
        raise InputError(f"--task: give the grid with --over NAME:MIN:MAX:N[,...] over the given coordinates "
                         f"({', '.join(hint.given)}), e.g. --over {over_s}" + (f" --at {at_s}" if at_s else ""))
    axes = parse_axes(over, "--over")
    held = parse_task_at(at, "--at")
    for name, v in (("--tol-deg", tol_deg), ("--tol", tol_m)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise InputError(f"{name}: must be a positive number, got {v}")
    L = mech.characteristic_length
    tol = {c: (np.radians(tol_deg) if c.startswith("a") else (tol_m if tol_m is not None else 1e-6 * L)) for c in axes}
    progress, close = (None, lambda: None) if as_json else _progress_bar()
    try:
        res = sm.workspace(mech, kind="task", over=axes, at=held, free=free_names, tol=tol, max_poses=max_cells,
                           progress=progress, **limit_args)
    finally:
        close()
    if plot:
        from ..present.task_workspace import write_task_workspace_plot

        write_task_workspace_plot(res, plot)
    if as_json:
        emit_json("workspace", mech, {**res.to_dict(), "plot": str(plot) if plot else None})
        return
    click.echo(_task_text(res, mech.length_unit))
    if plot:
        click.echo(f"plot written to {plot}")


@click.command()
@click.argument("model")
@click.option("--orientation", "orientation_flag", is_flag=True,
              help="Orientation workspace at a fixed position (default).")
@click.option("--position", "position_flag", is_flag=True,
              help="Position workspace at a fixed orientation (not with --orientation).")
@click.option("--at", "at", default=None,
              help="Fixed coordinates, e.g. z=0.1 or alpha=0,beta=0,gamma=0 (m, deg).")
@click.option("--step-deg", type=float, default=2.0, show_default=True, help="Grid step of the angles (deg).")
@click.option("--tol-deg", type=float, default=1e-3, show_default=True, help="Boundary tolerance of the angles (deg).")
@click.option("--step", "step_m", type=float, default=None, help="Grid step of positions (m; default L/40).")
@click.option("--tol", "tol_m", type=float, default=None, help="Boundary tolerance of positions (m; default L*1e-6).")
@click.option("--method", type=click.Choice(["auto", "closed-form", "general"]), default="auto", show_default=True,
              help="Pose-check kernel: vectorised closed form, or per-pose inverse position.")
@click.option("--link-diameter", type=float, default=None,
              help="Link capsule diameter (m) for the interference check (default: the paper's, or none).")
@click.option("--no-interference", is_flag=True, help="Skip the link interference check.")
@click.option("--max-poses", type=click.IntRange(min=1), default=None,
              help=f"Largest grid accepted (default: {sm.WORKSPACE_MAX_POSES:.0e} on the closed-form path, {GENERAL_MAX_POSES} "
                   "on the general path); a larger grid is refused with its size before any work.")
@click.option("--task", "task_flag", is_flag=True,
              help="Workspace over the task coordinates of a lower-mobility mechanism: sample --over, hold --at, "
                   "solve the parasitic coordinates at every cell (docs/workspace.md).")
@click.option("--over", "over", default=None, metavar="NAME:MIN:MAX:N,...",
              help="With --task: 1 to 3 grid axes over task coordinates x, y, z (length) or a1, a2, a3 (deg).")
@click.option("--free", "free", default=None, metavar="NAME,...",
              help="With --task: the coordinates to solve (default: the model's task, or the grid and --at names).")
@click.option("--cone", "cones", multiple=True, metavar="JOINT=DEG",
              help="Cone limit of an S or U joint (deg): the link's angle to the platform z axis (to the base z axis "
                   "at a limb's first joint); repeatable or comma-separated.")
@click.option("--limit", "freedom_limits_text", multiple=True, metavar="FREEDOM=LO:HI",
              help="Limits of a freedom's value (length, or deg for a rotation); 'actuators=LO:HI' sets every "
                   "actuator; repeatable or comma-separated.")
@click.option("--plot", "plot", type=click.Path(dir_okay=False), default=None, help="Write a figure (.png/.svg/.pdf).")
@json_option
def workspace(model, orientation_flag, position_flag, at, step_deg, tol_deg, step_m, tol_m, method, link_diameter,
              no_interference, max_poses, task_flag, over, free, cones, freedom_limits_text, plot, as_json):
    """Workspace under joint limits (strokes, joint cones, link interference), sampled and refined
    at the boundary by bisection.

    \b
    JSON (docs/json.md): extents.alpha_deg.alone ([min, max] of one angle alone, others fixed),
    extents.alpha_deg.set (over the whole set), volume_deg3 (orientation) or volume_len3
    (position), active_limits (boundary points per limit), path (closed-form or general).
    --task (lower-mobility mechanisms): the given task coordinates on the --over grid, the
    parasitic ones solved at every cell; extents.a2_deg.range, solved_ranges, reachable_fraction,
    samples (docs/workspace.md).
    \b
    Examples:
      spatialmech workspace four-sps-cu --orientation --at z=0.1
      spatialmech workspace four-sps-cu --position --at alpha=0,beta=0,gamma=0 --json
      spatialmech workspace four-sps-cu --at z=0.1 --step-deg 3 --plot ws.png
      spatialmech workspace three-rps --task --over a2:-40:40:41,a3:-40:40:41 --at z=0.33 --cone S1=45,S2=45,S3=45
    """
    kind = "task" if task_flag else "position" if position_flag else "orientation"
    try:
        given = [name for name, v in (("--orientation", orientation_flag), ("--position", position_flag),
                                      ("--task", task_flag)) if v]
        if len(given) > 1:
            raise InputError(f"{', '.join(given)}: give one of them, not {'both' if len(given) == 2 else 'all three'}")
        if not task_flag:
            for name, v in (("--over", over), ("--free", free)):
                if v is not None:
                    raise InputError(f"{name}: only with --task (the workspace over task coordinates)")
        check_output_file(plot, "--plot", suffixes=(".png", ".svg", ".pdf"))
        mech = load_model(model)
        limit_args: dict[str, Any] = {"freedom_limits": freedom_limits(freedom_limits_text, mech) or None,
                      "cones": cone_limits(cones, mech) or None}
        if link_diameter is not None or no_interference:
            _check_diameter(link_diameter)
            limit_args.update(link_diameter=link_diameter, interference=not no_interference)
        if task_flag:
            _task_workspace(mech, over, at, free, limit_args, tol_deg, tol_m, max_poses, plot, as_json)
            return
        fixed = parse_at(at)
        for name, v in (("--step-deg", step_deg), ("--tol-deg", tol_deg)):
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name}: must be a positive number of degrees, got {v}")
        kw = dict(kind=kind, at=fixed, method=method, max_poses=max_poses, max_general_poses=GENERAL_MAX_POSES,
                  **limit_args)
        if kind == "orientation":
            kw.update(step=np.radians(step_deg), tol=np.radians(tol_deg))
        else:
            kw.update(step=step_m, tol=tol_m)
        if as_json:
            res = sm.workspace(mech, **kw)
        else:
            progress, close = _progress_bar()  # opened at the first report: none before an input error
            try:
                res = sm.workspace(mech, progress=progress, **kw)
            finally:
                close()
        if plot:
            from ..present.workspace import write_workspace_plot

            write_workspace_plot(res, plot)
    except InputError as e:  # not ConvergenceError (exit 1) nor a bug (exit 3): see cli._Group
        raise UserError(_option_message(str(e), kind)) from None
    if as_json:
        emit_json("workspace", mech, {**res.to_dict(), "plot": str(plot) if plot else None})
        return
    click.echo(_text(res, mech.length_unit))
    hint = _lower_mobility_hint(mech) if res.n_feasible == 0 or "closure" in res.active_limits else ""
    if hint:
        click.echo(hint)
    if plot:
        click.echo(f"plot written to {plot}")


def _grid_text(hint) -> tuple[str, str]:
    """A first --over / --at for ``workspace --task`` (``sm.suggest_task_grid(..., degrees=True)``)."""
    over = ",".join(f"{c}:{lo:.4g}:{hi:.4g}:{n}" for c, (lo, hi, n) in hint.over.items())
    at = ",".join(f"{c}={v:.4g}" for c, v in hint.at.items())
    return over, at


def _lower_mobility_hint(mech) -> str:
    """For a pose workspace bounded by closure (or empty) of a mechanism with fewer than six output
    freedoms: why, and the command that samples its task coordinates instead."""
    try:
        hint = sm.suggest_task_grid(mech, degrees=True)
    except InputError:
        return ""
    if len(hint.given) == 6:
        return ""
    over, at = _grid_text(hint)
    return (f"note: {mech.name}'s output has {len(hint.given)} freedoms ({', '.join(hint.given)} given; "
            f"{', '.join(hint.solved)} parasitic): a grid of six-coordinate poses almost never lies on its "
            f"closure set.  Sample its task coordinates instead: spatialmech workspace {mech.name} --task "
            f"--over {over}" + (f" --at {at}" if at else ""))
