"""CLI command ``maps``: performance maps (kinetostatic indices) over a grid of poses; calls
``sm.maps`` only.  Lengths in the model's unit, angles in degrees (``R = Rz(gamma) Ry(beta)
Rx(alpha)``, as ``workspace``)."""

from __future__ import annotations

import math

import click
import numpy as np

from .. import api as sm
from ..errors import InputError
from .common import check_output_file, emit_json, json_option, parse_number
from .cmd_workspace import parse_at

_ANGLES = ("alpha", "beta", "gamma")
_POSITION = ("x", "y", "z")
#: Largest number of points along one grid axis at the command line.
MAX_AXIS_POINTS = 2000


def parse_over(text: str) -> dict[str, np.ndarray]:
    """``"x:-0.1:0.1:21,y:-0.1:0.1:21"`` -> grid values (SI; angles given in degrees)."""
    out: dict[str, np.ndarray] = {}
    for part in str(text).split(","):
        bits = [b.strip() for b in part.strip().split(":")]
        if len(bits) != 4 or bits[0] not in (*_POSITION, *_ANGLES):
            raise InputError(f"--over: expected NAME:MIN:MAX:N[,...] with NAME in x, y, z (length) or alpha, beta, gamma "
                             f"(deg), got {part.strip()!r}")
        name = bits[0]
        lo, hi = (parse_number(b, "--over", f"{name} {w}") for b, w in zip(bits[1:3], ("MIN", "MAX"), strict=True))
        if not bits[3].isdigit() or not 2 <= int(bits[3]) <= MAX_AXIS_POINTS:
            raise InputError(f"--over: {name} N expects a whole number 2..{MAX_AXIS_POINTS}, got {bits[3]!r}")
        if not lo < hi or name in out:
            raise InputError(f"--over: {name} expects MIN < MAX, once")
        vals = np.linspace(lo, hi, int(bits[3]))
        out[name] = np.radians(vals) if name in _ANGLES else vals
    return out


def over_kind(over: dict) -> str:
    """The ``kind`` of a map over the grid axes ``over``: ``"position"`` or ``"orientation"``."""
    if all(n in _POSITION for n in over):
        return "position"
    if all(n in _ANGLES for n in over):
        return "orientation"
    raise InputError("--over: either position coordinates (x, y, z) or angles (alpha, beta, gamma), not both")


def parse_grid(over_text: str, plot, suffixes: tuple[str, ...]):
    """``--over`` and ``--plot`` of a map over a grid of poses: ``(over, plot file or None)``; a
    figure takes 1 or 2 grid axes."""
    plot_path = check_output_file(plot, "--plot", suffixes=suffixes)
    over = parse_over(over_text)
    if plot_path is not None and len(over) > 2:
        raise InputError("--plot: 1 or 2 grid axes")
    return over, plot_path


def emit_map(command: str, result, plot_path, as_json: bool, text) -> None:
    """Print a map over a grid of poses: its JSON (with the figure's path as ``plot``), or
    ``text()`` and the figure's path."""
    if as_json:
        doc = result.to_dict()
        doc["plot"] = None if plot_path is None else str(plot_path)
        emit_json(command, result.mechanism, doc, length_unit=result.length_unit)
        return
    click.echo(text())
    if plot_path is not None:
        click.echo(f"  figure: {plot_path}")


def _fmt(v: float) -> str:
    return "-" if not math.isfinite(v) else f"{v:.4g}"


def _text(r) -> str:
    unit = r.length_unit
    fixed = ", ".join(f"{c}={np.degrees(v):.4g} deg" if c in _ANGLES else f"{c}={v:.4g} {unit}" for c, v in r.fixed.items())
    dims = " x ".join(f"{c} ({a.size})" for c, a in r.axes.items())
    lines = [f"{r.mechanism}: performance maps over {dims}; fixed {fixed}",
             f"  path: {r.path}; {r.n_poses} poses in {r.seconds:.3f} s; characteristic length L = "
             f"{r.characteristic_length:.6g} {unit}; constraint rows {r.constraint_rows}",
             "  cells: " + ", ".join(f"{k} {v}" for k, v in r.status_counts().items() if v)]
    for name in r.indices:
        a = r.values[name]
        v = r.valid if a.ndim == r.status.ndim else np.broadcast_to(r.valid[..., None], a.shape)
        good = a[v & np.isfinite(a)]
        rng = f"{_fmt(float(good.min()))} .. {_fmt(float(good.max()))}" if good.size else "no cell"
        lines.append(f"  {name:15s} {rng}")
    return "\n".join(lines)


@click.command(name="maps")
@click.argument("model")
@click.option("--over", "over_text", required=True,
              help="Grid NAME:MIN:MAX:N[,...]: x, y, z (model length unit) or alpha, beta, gamma (deg); 1 to 3 axes.")
@click.option("--at", "at_text", default=None, help="Fixed coordinates, e.g. z=0.12 or alpha=5 (deg).")
@click.option("--index", "index_text", default=None,
              help="Indices to keep: sigma_min, condition, manipulability, iti, oti, lti, lci, velocity_axes, "
                   "force_axes (default: all that apply).")
@click.option("--plot", "plot", default=None, help="Write a figure: .png/.pdf/.svg (Matplotlib) or .html (plotly).")
@json_option
def maps_cmd(model, over_text, at_text, index_text, plot, as_json):
    """Performance maps: sigma_min and condition of the dimensionally consistent complete
    Jacobian, manipulability and ellipsoids, transmission (ITI, OTI, LTI) and constraint (LCI)
    indices at every pose of a grid (docs/maps.md).

    \b
    Examples:
      spatialmech maps stewart-6sps --over x:-0.1:0.1:41,y:-0.1:0.1:41 --plot stewart.png
      spatialmech maps four-sps-cu --over alpha:-30:30:31,beta:-30:30:31 --at z=0.12 --index sigma_min,lti --json
    """
    over, plot_path = parse_grid(over_text, plot, (".png", ".pdf", ".svg", ".html"))
    indices = [s.strip() for s in index_text.split(",") if s.strip()] if index_text else None
    result = sm.maps(model, kind=over_kind(over), over=over, at=parse_at(at_text), indices=indices)
    if plot_path is not None:
        from ..present.maps import write_maps_plot

        write_maps_plot(result, plot_path)
    emit_map("maps", result, plot_path, as_json, lambda: _text(result))

