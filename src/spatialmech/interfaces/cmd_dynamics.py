"""``spatialmech dynamics``: inverse dynamics of a closed chain along a trajectory
(``sm.inverse_dynamics``; docs/dynamics.md).  Parse, call, render."""

from __future__ import annotations

import click
import numpy as np

from .. import api as sm
from .cmd_kinematics import resolve_pose, with_pose
from .common import check_output_file, emit_json, json_option, parse_numbers


def _text(r) -> list[str]:
    mech = r.mechanism
    used = sorted(set(r.mass_source.values()))
    total = sum(li.mass_kg for li in r.masses.values())
    lines = [f"{mech.name}: inverse dynamics, {len(r.times)} samples over {r.times[-1] - r.times[0]:.4g} s, "
             f"gravity ({', '.join(f'{v:g}' for v in r.gravity)}) m/s^2",
             f"  masses ({' and '.join(used)}): {total:.6g} kg in all; "
             f"virtual-power balance residual {r.max_residual:.1e} (relative)"]
    units = ["N" if mech.freedom(a).freedom.kind == "P" else "N m" for a in r.actuators]
    head = "  t [s]     " + "  ".join(f"{a} [{u}]".rjust(16) for a, u in zip(r.actuators, units, strict=True))
    lines.append(head)
    for t, row in zip(r.times, r.efforts, strict=True):
        lines.append(f"  {t:<9.4g} " + "  ".join(f"{v:+16.6g}" for v in row))
    peak = np.max(np.abs(r.efforts), axis=0)
    lines.append("  peak |effort|: " + ", ".join(f"{a} {p:.6g} {u}" for a, p, u in zip(r.actuators, peak, units,
                                                                                           strict=True)))
    for note in r.notes:
        lines.append(f"  note: {note}")
    return lines


@click.command(name="dynamics")
@click.argument("model")
@with_pose
@click.option("--to", "to_text", default=None, metavar="V1,V2,...",
              help="Target actuator values (m, or deg for revolute actuators): a rest-to-rest quintic law from the "
                   "start (the pose, or the reference configuration). Without it: one sample at rest.")
@click.option("--duration", type=float, default=1.0, show_default=True, help="Seconds of the motion (with --to).")
@click.option("--samples", type=int, default=11, show_default=True, help="Samples, both ends included (with --to).")
@click.option("--gravity", "gravity_text", default="0,0,-9.81", show_default=True, metavar="GX,GY,GZ",
              help="Gravity, m/s^2.")
@click.option("--density", type=float, default=None,
              help="kg/m^3 for the links without masses in the model file (solid cylinders along the links).")
@click.option("--wrench", "wrench_text", default=None, metavar="FX,FY,FZ,MX,MY,MZ",
              help="External wrench on the output link (N; moment about the origin, N m).")
@click.option("--plot", "plot", default=None, help="Write a figure of the efforts against time (.png, .pdf, .svg).")
@json_option
def dynamics_cmd(model, xyz, euler, position, to_text, duration, samples, gravity_text, density, wrench_text, plot,
                 as_json):
    """Inverse dynamics: every actuator's force or torque and every joint's reaction along a
    trajectory of the actuators, with the links' masses (from the model file or --density) and
    gravity; Newton-Euler per link and virtual power over the closed chain.

    \b
    Examples:
      spatialmech dynamics delta-ruu --to 20,10,0 --duration 0.5 --density 2700
      spatialmech dynamics three-rps --to 0.36,0.34,0.35 --density 2700 --plot rps-dyn.png --json
      spatialmech dynamics four-sps-cu --pose 0,0,0.12,ZYX,17.19,-22.92,28.65 --density 2700   # at rest
    """
    plot_path = check_output_file(plot, "--plot", suffixes=(".png", ".pdf", ".svg"))
    mech = sm.load_model(model)
    given = xyz is not None or euler is not None or position is not None
    pose = resolve_pose(mech, xyz, euler, position) if given else None
    g = parse_numbers(gravity_text, "--gravity", count=3, what="components GX,GY,GZ")
    wrench = None if wrench_text is None else parse_numbers(wrench_text, "--wrench", count=6,
                                                            what="components FX,FY,FZ,MX,MY,MZ")
    to = None
    if to_text is not None:
        vals = parse_numbers(to_text, "--to", count=len(mech.actuators), what="actuator values")
        to = [v if mech.freedom(a).freedom.kind == "P" else float(np.radians(v))
              for a, v in zip(mech.actuators, vals, strict=True)]
    r = sm.inverse_dynamics(mech, pose, to=to, duration=duration, samples=samples, gravity=g, wrench=wrench,
                            density=density)
    if plot_path is not None:
        from ..present.dynamics import write_dynamics_plot

        write_dynamics_plot(r, plot_path)
    if as_json:
        doc = r.to_dict()
        doc["plot"] = None if plot_path is None else str(plot_path)
        emit_json("dynamics", mech, doc)
        return
    click.echo("\n".join(_text(r)))
    if plot_path is not None:
        click.echo(f"  figure: {plot_path}")
