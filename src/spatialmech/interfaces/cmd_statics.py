"""``spatialmech statics``: actuator efforts and joint reactions against an external wrench on the
output link (``sm.statics``; docs/statics.md).  Parse, call ``sm.statics``, render."""

from __future__ import annotations

import click
import numpy as np

from .. import api as sm
from .cmd_kinematics import resolve_pose, with_pose
from .common import emit_json, json_option, parse_numbers, tol_option


def _vec(v, fmt: str = ".6g") -> str:
    v = np.where(np.abs(np.asarray(v, float)) < 1e-12, 0.0, np.asarray(v, float))
    return "(" + ", ".join(format(float(x) + 0.0, fmt) for x in v) + ")"


def _text(r, unit: str) -> list[str]:
    """The result as lines of text, units labelled (force N, torque N·length unit)."""
    mech, d = r.mechanism, r.to_dict()
    p = d["pose"]
    where = "the reference configuration" if r.pose is None else "the requested pose"
    lines = [f"{mech.name}: statics at {where}: platform point {_vec(p['position_len'])} {unit}, "
             f"{p['euler_sequence']} angles {_vec(p['euler_deg'], '.4f')} deg",
             f"  external wrench on the output link: force {_vec(r.wrench[:3])} N, moment about the origin "
             f"{_vec(r.wrench[3:])} N {unit}",
             "  actuator efforts (the force or torque each actuator exerts along its freedom):"]
    w = max(len(a) for a in r.efforts)
    for a, t in r.efforts.items():
        kind, lab = ("force", "N") if a in d["forces_N"] else ("torque", f"N {unit}")
        lines.append(f"    {a:<{w}}  {kind:<6s} {t:+.6g} {lab}")
    if r.balanced:
        lines.append("  balanced: the efforts and the constraint wrenches hold the external wrench")
    else:
        lines.append(f"  NOT balanced: residual force {_vec(r.residual[:3])} N, moment {_vec(r.residual[3:])} N {unit} "
                     "(the part the mechanism cannot hold here)")
    if r.singular:
        u = r.unbalanced_wrench
        lines.append(f"  SINGULAR (scale-free sigma_min {r.sigma_min:.3g} < {d['singular_below']:g}): the wrench "
                     f"(f ; m) = ({' '.join(f'{x:+.4g}' for x in u[:3])} ; {' '.join(f'{x:+.4g}' for x in u[3:])}) "
                     "cannot be balanced; the efforts are least-squares")
    else:
        lines.append(f"  scale-free sigma_min {r.sigma_min:.3g}")
    for note in r.notes:
        lines.append(f"  note: {note}")
    if r.reactions:
        lines.append("  joint reactions (the proximal body on the distal one, without the actuator efforts; "
                     f"moment about the joint's point, N {unit}):")
        for j in r.reactions:
            lines.append(f"    {j.limb}/{j.joint} at {_vec(j.point)} {unit}: force {_vec(j.force)} N, "
                         f"moment {_vec(j.moment_at_point)}")
    if r.gravity is not None:
        total = sum(li.mass_kg for li in (r.masses or {}).values())
        used = " and ".join(sorted(set((r.mass_source or {}).values())))
        lines.insert(2, f"  with the links' weights: gravity ({', '.join(f'{v:g}' for v in r.gravity)}) m/s^2, "
                        f"{total:.6g} kg in all (masses from: {used})")
    if r.pose_fit is not None and not r.pose_fit.exact:
        lines.append(f"  note: the pose was fitted onto the closure (error {r.pose_fit.position_error:.3g} {unit}, "
                     f"{np.degrees(r.pose_fit.angle_error):.3g} deg)")
    return lines


@click.command(name="statics")
@click.argument("model")
@click.option("--wrench", "wrench_text", default=None, metavar="FX,FY,FZ,MX,MY,MZ",
              help="External wrench on the output link (screw convention: force in N, then its moment about the "
                   "model's origin in N times the model's length unit); default none (then --gravity is needed).")
@with_pose
@click.option("--driver", "drivers", multiple=True, help="Actuated freedom(s) (repeatable; default: the model's actuators).")
@click.option("--gravity", "gravity_text", default=None, metavar="GX,GY,GZ",
              help="Also hold the links' weights under this gravity (m/s^2, e.g. 0,0,-9.81); masses from the model "
                   "file or --density.")
@click.option("--density", type=float, default=None,
              help="kg/m^3 for the links without masses in the model file (solid cylinders along the links).")
@click.option("--along", "along_text", default=None, metavar="V1,V2,...|FILE.toml",
              help="Statics along a motion: the actuators moved in a straight line from the start to these values "
                   "(m, or deg for revolute actuators), or the poses of a TOML file of [[positions]]; efforts per "
                   "sample.")
@click.option("--samples", type=int, default=11, show_default=True, help="Samples with --along (both ends included).")
@tol_option("singular")
@json_option
def statics_cmd(model, wrench_text, xyz, euler, position, drivers, gravity_text, density, along_text, samples, as_json):
    """Statics: every actuator's force or torque and every joint's reaction that hold the mechanism
    against an external wrench on its output link (at the reference configuration unless a pose is
    given).  Redundant actuation: minimum-norm efforts; a singular pose: least squares and the
    wrench that cannot be balanced.

    \b
    Examples:
      spatialmech statics stewart-6sps --wrench 0,0,-600,0,0,0
      spatialmech statics three-rps --wrench 0,0,-100,0,0,0 --pose 0,0,0.33,ZYX,0,5,5 --json
      spatialmech statics delta --wrench=0,0,-10,0,0,0 --xyz 0.02 0.01 -0.33
      spatialmech statics three-rps --gravity 0,0,-9.81 --density 2700
      spatialmech statics three-rps --wrench 0,0,-100,0,0,0 --gravity 0,0,-9.81 --density 2700 --along 0.36,0.34,0.35
    """
    if wrench_text is None and gravity_text is None:
        raise click.UsageError("give --wrench, --gravity or both")
    wrench = [0.0] * 6 if wrench_text is None else parse_numbers(wrench_text, "--wrench", count=6,
                                                                 what="components FX,FY,FZ,MX,MY,MZ")
    gravity = None if gravity_text is None else parse_numbers(gravity_text, "--gravity", count=3,
                                                              what="components GX,GY,GZ")
    mech = sm.load_model(model)
    given = xyz is not None or euler is not None or position is not None
    pose = resolve_pose(mech, xyz, euler, position) if given else None
    if along_text is not None:
        _along(mech, pose, along_text, samples, wrench, gravity, density, drivers, as_json)
        return
    r = sm.statics(mech, pose, wrench=wrench, drivers=list(drivers) or None, gravity=gravity, density=density)
    if as_json:
        emit_json("statics", mech, r.to_dict())
        return
    click.echo("\n".join(_text(r, mech.length_unit)))


def _along(mech, pose, along_text, samples, wrench, gravity, density, drivers, as_json) -> None:
    """``statics --along``: the efforts at each sample of a straight path of actuator values."""
    if drivers:
        raise click.UsageError("--driver: not with --along (the path is in the model's actuators)")
    if along_text.endswith(".toml"):
        if pose is not None:
            raise click.UsageError("--along FILE.toml: the file gives the poses; no --pose / --xyz / --position")
        p = sm.statics_along(mech, poses=along_text, wrench=wrench, gravity=gravity, density=density)
    else:
        vals = parse_numbers(along_text, "--along", count=len(mech.actuators), what="actuator values")
        to = [v if mech.freedom(a).freedom.kind == "P" else float(np.radians(v))
              for a, v in zip(mech.actuators, vals, strict=True)]
        p = sm.statics_along(mech, pose, to=to, samples=samples, wrench=wrench, gravity=gravity, density=density)
    if as_json:
        emit_json("statics along", mech, {"result": "statics along", **p.to_dict()})
        return
    units = ["N" if mech.freedom(a).freedom.kind == "P" else f"N {mech.length_unit}" for a in p.actuators]
    click.echo(f"{mech.name}: statics along {len(p.configs)} samples, wrench {_vec(p.wrench)}"
               + ("" if p.gravity is None else f", gravity {_vec(p.gravity)} m/s^2"))
    click.echo("  sample  " + "  ".join(f"{a} [{u}]".rjust(16) for a, u in zip(p.actuators, units, strict=True)))
    for i, row in enumerate(p.efforts):
        flag = "" if p.balanced[i] else "  (NOT balanced)"
        click.echo(f"  {i:<6d}  " + "  ".join(f"{v:+16.6g}" for v in row) + flag)
