"""CLI command ``workspace``: orientation / position workspace under joint limits.

Angles at the command line are in degrees, lengths in the model's length unit (m).  ``--at``
takes ``name=value`` pairs separated by commas: ``x, y, z`` (m) and ``alpha, beta, gamma``
(deg), with ``R = Rz(gamma) Ry(beta) Rx(alpha)`` (intrinsic "ZYX", paper B eq 7).
"""

from __future__ import annotations

import sys

import click
import numpy as np

from .. import catalog
from ..analysis.workspace import (
    COORDINATES,
    MAX_POSES,
    WorkspaceLimits,
    default_limits,
    orientation_workspace,
    pose_checker,
    position_workspace,
)
from ..errors import InputError
from .common import UserError, check_output_file, emit_json, json_option

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
        if k not in COORDINATES:
            raise InputError(f"--at: unknown coordinate {k!r}; expected one of {', '.join(COORDINATES)}")
        try:
            val = float(v)
        except ValueError:
            raise InputError(f"--at: {k} expects a number, got {v!r}") from None
        if not np.isfinite(val):
            raise InputError(f"--at: {k} must be finite, got {v!r}")
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
    vkey = next(k for k in d if k.startswith("volume_") and k != "volume_note")
    power = vkey[-1] if vkey[-1].isdigit() else ""
    vunit = ("deg" if "_deg" in vkey else length_unit) + (f"^{power}" if power else "")
    lines.append(f"volume: {d[vkey]:.6g} {vunit} ({d['volume_note']})")
    lines.append("active limits (boundary points): " + ", ".join(f"{k} {v}" for k, v in res.active_limits.items()))
    lines.append(f"{res.n_poses} poses checked in {res.seconds:.2f} s; tolerance "
                 + ", ".join(_with_unit(k, v, ".3g", length_unit) for k, v in d["boundary_tol"].items()))
    return "\n".join(lines)


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
              help=f"Largest grid accepted (default: {MAX_POSES:.0e} on the closed-form path, {GENERAL_MAX_POSES} "
                   "on the general path); a larger grid is refused with its size before any work.")
@click.option("--plot", "plot", type=click.Path(dir_okay=False), default=None, help="Write a figure (.png/.svg/.pdf).")
@json_option
def workspace(model, orientation_flag, position_flag, at, step_deg, tol_deg, step_m, tol_m, method, link_diameter,
              no_interference, max_poses, plot, as_json):
    """Workspace under joint limits (strokes, joint cones, link interference), sampled and refined
    at the boundary by bisection.

    \b
    JSON (docs/json.md): extents.alpha_deg.alone ([min, max] of one angle alone, others fixed),
    extents.alpha_deg.set (over the whole set), volume_deg3 (orientation) or volume_len3
    (position), active_limits (boundary points per limit), path (closed-form or general).
    \b
    Examples:
      spatialmech workspace four-sps-cu --orientation --at z=0.1
      spatialmech workspace four-sps-cu --position --at alpha=0,beta=0,gamma=0 --json
      spatialmech workspace four-sps-cu --at z=0.1 --step-deg 3 --plot ws.png
    """
    kind = "position" if position_flag else "orientation"
    try:
        if orientation_flag and position_flag:
            raise InputError("--orientation, --position: give one of them, not both")
        check_output_file(plot, "--plot", suffixes=(".png", ".svg", ".pdf"))
        mech = catalog.resolve(model)
        fixed = parse_at(at)
        limits = default_limits(mech)
        if link_diameter is not None or no_interference:
            if link_diameter is not None and not (np.isfinite(link_diameter) and link_diameter >= 0):
                raise InputError(f"--link-diameter: expected a non-negative number of metres, got {link_diameter}")
            limits = WorkspaceLimits(limits.cones, None if no_interference else link_diameter,
                                     limits.freedom_limits, limits.source)
        for name, v in (("--step-deg", step_deg), ("--tol-deg", tol_deg)):
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"{name}: must be a positive number of degrees, got {v}")
        path_kind = pose_checker(mech, limits, method=method).path
        if max_poses is None and path_kind == "general":
            max_poses = GENERAL_MAX_POSES
        kw = dict(at=fixed, limits=limits, method=method, max_poses=max_poses)
        if kind == "orientation":
            run = lambda progress: orientation_workspace(  # noqa: E731
                mech, step=np.radians(step_deg), tol=np.radians(tol_deg), progress=progress, **kw)
        else:
            run = lambda progress: position_workspace(mech, step=step_m, tol=tol_m, progress=progress, **kw)  # noqa: E731
        if as_json:
            res = run(None)
        else:
            bars = []  # opened at the first progress report: no progress line before an input error

            def progress(done, total, message):
                if not bars:
                    bars.append(click.progressbar(length=1, label=message or "checking poses", file=sys.stderr, show_pos=True))
                    bars[0].__enter__()
                bar = bars[0]
                n = int(done) - bar.pos
                bar.length = max(bar.length, int(done), int(total or 0))  # total: the search's estimate
                bar.update(n)
            try:
                res = run(progress)
            finally:
                if bars:
                    bars[0].__exit__(None, None, None)
        if plot:
            from ..analysis.workspace_plot import write_workspace_plot

            write_workspace_plot(res, plot)
    except InputError as e:  # not ConvergenceError (exit 1) nor a bug (exit 3): see cli._Group
        msg = str(e)
        # the library names its arguments; say which command-line option to change
        msg = msg.replace("max_poses =", "--max-poses =")
        for arg, opt in (("step", "--step-deg" if kind == "orientation" else "--step"),
                         ("tol", "--tol-deg" if kind == "orientation" else "--tol")):
            if msg.startswith(arg + ":"):
                msg = f"{opt} ({arg})" + msg[len(arg):]
        raise UserError(msg) from None
    if as_json:
        emit_json("workspace", mech, {**res.to_dict(), "plot": str(plot) if plot else None})
        return
    click.echo(_text(res, mech.length_unit))
    if plot:
        click.echo(f"plot written to {plot}")
