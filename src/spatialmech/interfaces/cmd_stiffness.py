"""``spatialmech stiffness``: the Cartesian stiffness at the output link, its principal directions
and the softest one, at a pose or over a workspace slice (``sm.stiffness`` / ``sm.stiffness_map``;
docs/stiffness.md).  Parse, call one ``sm`` function, render."""

from __future__ import annotations

import click
import numpy as np

from .. import api as sm
from ..errors import InputError
from .cmd_kinematics import resolve_pose, with_pose
from .cmd_maps import emit_map, over_kind, parse_grid
from .cmd_workspace import parse_at
from .common import emit_json, json_option, parse_number, tol_option


def parse_stiffness(text: str | None, option: str):
    """``"2e6"`` (every one) or ``"L1.slide=2e6,L2.slide=3e6"`` -> a number or a mapping."""
    if text is None:
        return None
    if "=" not in text:
        return parse_number(text.strip(), option, "the stiffness")
    out = {}
    for part in text.split(","):
        if "=" not in part:
            raise InputError(f"{option}: expected NAME=VALUE pairs separated by commas (or one number), got {part.strip()!r}")
        k, v = (s.strip() for s in part.split("=", 1))
        out[k] = parse_number(v, option, k)
    return out


def _vec(v, fmt: str = ".4g") -> str:
    v = np.where(np.abs(np.asarray(v, float)) < 1e-12, 0.0, np.asarray(v, float))
    return "(" + ", ".join(format(float(x) + 0.0, fmt) for x in v) + ")"


def _screw(t, L: float, unit: str) -> str:
    """A displacement twist ``(dtheta ; dp)`` in words: a translation, or a rotation about an axis
    (through the point nearest the origin) with a pitch."""
    w, v = np.asarray(t[:3], float), np.asarray(t[3:], float)
    nw = float(np.linalg.norm(w))
    if nw * L <= 1e-9 * max(float(np.linalg.norm(v)), 1e-300):
        return f"translation along {_vec(v / np.linalg.norm(v), '.3f')}"
    c = np.cross(w, v) / nw**2
    h = float(w @ v) / nw**2
    pitch = "" if abs(h) <= 1e-9 * L else f", pitch {h:.4g} {unit}/rad"
    return f"rotation about {_vec(w / nw, '.3f')} through {_vec(c)} {unit}{pitch}"


def _direction_line(d: dict, L: float, unit: str) -> str:
    k = "rigid" if d["rigid"] else f"{d['stiffness_N_per_len']:.6g} N/{unit}"
    rep = f" (x{d['repeated']})" if d["repeated"] > 1 else ""
    return f"    {k:>18s}{rep:5s} {_screw(d['twist'], L, unit)}"


def _text(r) -> list[str]:
    mech, d = r.mechanism, r.to_dict()
    unit = mech.length_unit
    p = d["pose"]
    where = "the reference configuration" if r.pose is None else "the requested pose"
    lines = [f"{mech.name}: stiffness at {where}: platform point {_vec(p['position_len'])} {unit}, "
             f"{p['euler_sequence']} angles {_vec(p['euler_deg'])} deg; L = {d['characteristic_length_len']:.6g} {unit}",
             "  springs: " + ", ".join(f"{a} {k:.4g} N/{unit}" for a, k in d["actuator_stiffness"]["linear_N_per_len"].items())
             + "".join(f", {a} {k:.4g} N {unit}/rad" for a, k in d["actuator_stiffness"]["torsional_N_len"].items()),
             "  constraints: " + ", ".join(f"{n} {'rigid' if k is None else f'{k:.4g} N/{unit}'}"
                                           for n, k in d["constraint_stiffness_N_per_len"].items())
             + f" (rigid rank {d['rigid_rank']})",
             f"  K about the origin, F = K (dp ; dtheta): f in N, m in N {unit}, dp in {unit}, dtheta in rad:"]
    K = np.where(np.abs(r.matrix) < 1e-12 * float(np.max(np.abs(r.matrix))), 0.0, r.matrix)  # round-off shown as 0
    for row in K:
        lines.append("    [" + " ".join(f"{x + 0.0:+11.4e}" for x in row) + "]")
    lines.append(f"  principal stiffnesses (nondimensional about the platform point, N/{unit}; a rotation: "
                 f"k L^2 N {unit}/rad), softest first:")
    lines.extend(_direction_line(x, d["characteristic_length_len"], unit) for x in d["principal"])
    if r.singular:
        lines.append(f"  SINGULAR (scale-free sigma_min {r.sigma_min:.3g} < {d['singular_below']:g}): the softest "
                     "stiffness is 0 along the uncontrolled motion; the compliance is infinite")
    else:
        lines.append(f"  softest: {r.softest_stiffness:.6g} N/{unit}; scale-free sigma_min {r.sigma_min:.3g}")
    lines.extend(f"  note: {n}" for n in r.notes)
    if r.pose_fit is not None and not r.pose_fit.exact:
        lines.append(f"  note: the pose was fitted onto the closure (error {r.pose_fit.position_error:.3g} {unit}, "
                     f"{np.degrees(r.pose_fit.angle_error):.3g} deg)")
    return lines


def _map_text(r) -> list[str]:
    unit = r.length_unit
    fixed = ", ".join(f"{c}={np.degrees(v):.4g} deg" if c in ("alpha", "beta", "gamma") else f"{c}={v:.4g} {unit}"
                      for c, v in r.fixed.items())
    dims = " x ".join(f"{c} ({a.size})" for c, a in r.axes.items())
    lines = [f"{r.mechanism}: softest stiffness over {dims}; fixed {fixed}; L = {r.characteristic_length:.6g} {unit}",
             f"  {r.status.size} poses in {r.seconds:.3f} s; cells: "
             + ", ".join(f"{k} {v}" for k, v in r.status_counts().items() if v)]
    good = r.softest[np.isfinite(r.softest)]
    if good.size:
        low = r.minimum()
        at = ", ".join(f"{c}={np.degrees(v):.4g} deg" if c in ("alpha", "beta", "gamma") else f"{c}={v:.4g} {unit}"
                       for c, v in low[1].items()) if low else ""
        lines.append(f"  softest stiffness {good.min():.6g} .. {good.max():.6g} N/{unit}; the least at {at}")
    if r.defaulted:
        lines.append(f"  note: no stiffness in the model for {', '.join(r.defaulted)}: 1 assumed")
    return lines


@click.command(name="stiffness")
@click.argument("model")
@with_pose
@click.option("--driver", "drivers", multiple=True, help="Actuated freedom(s) (repeatable; default: the model's actuators).")
@click.option("--k", "k_text", default=None, metavar="K|NAME=K,...",
              help="Actuator stiffness (N per length unit for a slide, N length/rad for a rotation): one number for "
                   "all, or freedom=value pairs; default: the model's (1 where it has none).")
@click.option("--kc", "kc_text", default=None, metavar="K|LIMB=K,...",
              help="Limb constraint stiffness (N per length unit): one number for all, or limb=value; default: the "
                   "model's (rigid where it has none).")
@click.option("--over", "over_text", default=None,
              help="Tabulate the softest stiffness over a grid NAME:MIN:MAX:N[,...]: x, y, z (length) or alpha, beta, "
                   "gamma (deg); 1 to 3 axes.")
@click.option("--at", "at_text", default=None, help="With --over: fixed coordinates, e.g. z=1.0 or alpha=5 (deg).")
@click.option("--plot", "plot", default=None, help="With --over: write a figure (.png, .pdf, .svg).")
@tol_option("singular")
@json_option
def stiffness_cmd(model, xyz, euler, position, drivers, k_text, kc_text, over_text, at_text, plot, as_json):
    """Stiffness: the Cartesian stiffness matrix at the output link from the actuators' (and the
    limbs' constraint) stiffness, its principal directions and the softest one; with --over, the
    softest stiffness over a workspace slice.

    \b
    Examples:
      spatialmech stiffness stewart-6sps --k 2e6
      spatialmech stiffness three-rps --k 1e6 --kc 1e8 --pose 0,0,0.33,ZYX,0,5,5 --json
      spatialmech stiffness stewart-6sps --k 2e6 --over x:-0.2:0.2:21,y:-0.2:0.2:21 --at z=1.0 --plot soft.png
    """
    k, kc = parse_stiffness(k_text, "--k"), parse_stiffness(kc_text, "--kc")
    given = xyz is not None or euler is not None or position is not None
    if over_text is None:
        if at_text is not None or plot is not None:
            raise InputError(f"{'--at' if at_text is not None else '--plot'}: only with --over (a workspace slice)")
        mech = sm.load_model(model)
        pose = resolve_pose(mech, xyz, euler, position) if given else None
        r = sm.stiffness(mech, pose, drivers=list(drivers) or None, actuator_stiffness=k, constraint_stiffness=kc)
        if as_json:
            emit_json("stiffness", mech, r.to_dict())
            return
        click.echo("\n".join(_text(r)))
        return
    if given:
        raise InputError("--over: give the fixed coordinates with --at, not a pose")
    over, plot_path = parse_grid(over_text, plot, (".png", ".pdf", ".svg"))
    m = sm.stiffness_map(model, over=over, at=parse_at(at_text), kind=over_kind(over), drivers=list(drivers) or None,
                         actuator_stiffness=k, constraint_stiffness=kc)
    if plot_path is not None:
        from ..present.stiffness import write_stiffness_plot

        write_stiffness_plot(m, plot_path)
    emit_map("stiffness", m, plot_path, as_json, lambda: "\n".join(_map_text(m)))
