"""CLI command ``validate``: replay a motion of the library in MuJoCo and compare the output-link
poses (``sm.validate``; docs/validation.md).

An actuator path file (``--actuators-path``) is CSV: a header naming the actuators (freedom ids
or aliases), rotations with the suffix ``_deg`` (degrees), slides bare or with ``_len`` (the
model's length unit), then one row per pose; ``#`` starts a comment line::

    # paper B's legs
    L1.slide,L2.slide,L3.slide,L4.slide
    0.2392,0.2601,0.2956,0.2696
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import click
import numpy as np

from .. import api as sm
from .cmd_kinematics import resolve_pose, with_pose
from ..errors import InputError, require
from .common import check_output_file, emit_json, json_option, load_model


def read_actuator_path(mech, path: Path) -> np.ndarray:
    """Rows of actuator values (SI: rad, length) in ``mech.actuators`` order from a CSV file (the
    module docstring)."""
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise InputError(f"--actuators-path: {path}: not a text (UTF-8) file") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(lines))))
    if len(rows) < 2:
        raise InputError(f"--actuators-path: {path}: expected a header naming the actuators and at least one row")
    columns = []
    for k, raw in enumerate(rows[0]):
        name = raw.strip()
        unit = "deg" if name.endswith("_deg") else "len" if name.endswith("_len") else ""
        base = name[: -len(unit) - 1] if unit else name
        try:
            fid = mech.freedom(base).id
        except InputError as e:
            raise InputError(f"--actuators-path: {path}: column {k + 1} ({name!r}): {e}") from None
        if fid not in mech.actuators:
            raise InputError(f"--actuators-path: {path}: column {k + 1} ({name!r}) is not an actuator of {mech.name} "
                             f"(actuators: {', '.join(mech.actuators)})")
        rotation = mech.freedom(fid).freedom.kind != "P"
        if rotation and unit != "deg":
            raise InputError(f"--actuators-path: {path}: column {k + 1} ({name!r}) is a rotation: give it in degrees "
                             f"and say so, '{base}_deg'")
        if not rotation and unit == "deg":
            raise InputError(f"--actuators-path: {path}: column {k + 1} ({name!r}) is a slide, in "
                             f"{mech.length_unit}: name it '{base}' or '{base}_len'")
        columns.append((fid, rotation))
    ids = [c[0] for c in columns]
    if sorted(ids) != sorted(mech.actuators) or len(set(ids)) != len(ids):
        raise InputError(f"--actuators-path: {path}: the header must name each actuator once: "
                         f"{', '.join(mech.actuators)} (got {', '.join(ids)})")
    out = np.empty((len(rows) - 1, len(ids)))
    for r, row in enumerate(rows[1:], start=2):
        if len(row) != len(ids):
            raise InputError(f"--actuators-path: {path}: row {r} has {len(row)} values, expected {len(ids)}")
        for k, cell in enumerate(row):
            try:
                v = float(cell)
            except ValueError:
                raise InputError(f"--actuators-path: {path}: row {r}, column {k + 1}: {cell.strip()!r} is not a "
                                 "number") from None
            if not np.isfinite(v):
                raise InputError(f"--actuators-path: {path}: row {r}, column {k + 1}: not a finite number")
            out[r - 2, mech.actuators.index(ids[k])] = np.radians(v) if columns[k][1] else v
    return out


def _text(r) -> str:
    mech = r.mechanism
    u, L = mech.length_unit, mech.characteristic_length
    head = (f"{mech.name}{f'  mode {r.mode}' if r.mode else ''}: {r.simulator}, method {r.method}, motion {r.motion} "
            f"({len(r.poses)} poses, {r.elapsed:.1f} s)")
    w = max(len(p.label) for p in r.poses)
    lines = [head, f"  {'pose':<{w}}  {'position error (' + u + ')':>22}  {'orientation error (deg)':>24}  settled  branch"]
    for p in r.poses:
        lines.append(f"  {p.label:<{w}}  {p.position_error:>22.3e}  {np.degrees(p.orientation_error):>24.3e}  "
                     f"{'yes' if p.settled else 'NO':>7}  {'SWITCHED' if p.branch_switched else 'same'}")
    lines += [f"  note: {n}" for n in r.notes[1:]]
    verdict = "PASSED" if r.passed else "FAILED"
    lines.append(f"  largest errors: position {r.max_position_error:.3e} {u} ({r.max_position_error / L:.2e} of the "
                 f"characteristic length {L:.4g} {u}), orientation {np.degrees(r.max_orientation_error):.3e} deg")
    lines.append(f"  {verdict} (tolerance {r.tolerance:g} of the characteristic length and {r.tolerance:g} rad"
                 + (f"; branch switched at {', '.join(r.branch_switches)}" if r.branch_switches else "") + ")")
    return "\n".join(lines)


@click.command("validate")
@click.argument("model")
@click.option("--motion", type=click.Choice(["trace", "loop"]), default=None,
              help="The library's motion: trace (the 1-DOF motion; default with one actuator) or loop (a loop of the "
                   "actuators; default otherwise).")
@click.option("--actuators-path", "actuators_path", type=click.Path(exists=True, dir_okay=False, path_type=Path),
              default=None, help="CSV of actuator values, one row per pose (header: actuator names, rotations "
                                 "NAME_deg in degrees); replaces --motion.")
@click.option("--mode", default=None, help="Motion mode of a metamorphic mechanism.")
@with_pose
@click.option("--to-position", "to_position", type=int, default=None,
              help="trace: follow the motion up to this task position (through the others).")
@click.option("--poses", "frames", type=click.IntRange(2, 1000), default=12, show_default=True,
              help="Poses to check along a trace or loop.")
@click.option("--amplitude", type=float, default=0.02, show_default=True,
              help="loop: actuator amplitude (rad, or fraction of the characteristic length for slides).")
@click.option("--arc", type=float, default=2.0, show_default=True,
              help="trace: arc length to follow (nondimensional: rad, length / characteristic length).")
@click.option("--method", type=click.Choice(sm.VALIDATION_METHODS), default="project", show_default=True,
              help="project: solve MuJoCo's constraints with the actuated joints held; settle: simulate with "
                   "the position actuators until at rest.")
@click.option("--max-error", "max_error", type=float, default=sm.VALIDATION_TOL, show_default=True,
              help="Largest error that passes: a fraction of the characteristic length (and rad).")
@click.option("--mjcf", "mjcf_out", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Also write the MJCF model that was simulated.")
@json_option
def validate_cmd(model, motion, actuators_path, mode, xyz, euler, position, to_position, frames, amplitude, arc,
                 method, max_error, mjcf_out, as_json):
    """Drive the model exported to MuJoCo through a motion computed by spatialmech and compare
    the simulated output-link pose with the library's forward position at every pose: the
    largest position and orientation errors, per-pose values, and the poses where the
    simulator switched branch.  The simulator starts in the library's first configuration
    (--pose/--position, default the reference).

    \b
    Examples:
      spatialmech validate five-cs-3 --position 1 --to-position 7
      spatialmech validate three-rrr-sm --mode R1+R4 --json
      spatialmech validate four-sps-cu --pose 0,0,0.12,ZYX,17.19,17.19,17.19 --method settle
    """
    require("sim", "mujoco", what="validation")
    check_output_file(mjcf_out, "--mjcf")
    model_mech = load_model(model)
    mech = model_mech.in_mode(mode) if mode is not None else model_mech
    if actuators_path is not None and motion is not None:
        raise InputError("--actuators-path: give either --actuators-path or --motion, not both")
    start = None if (xyz is None and euler is None and position is None) else resolve_pose(mech, xyz, euler, position)
    path = read_actuator_path(mech, actuators_path) if actuators_path is not None else None
    r = sm.validate(model_mech, motion, mode=mode, method=method, start=start, frames=frames, to_position=to_position,
                    amplitude=amplitude, arc=arc, actuator_path=path, tol=max_error, mjcf=mjcf_out)
    if as_json:
        emit_json("validate", mech, r.to_dict())
    else:
        click.echo(_text(r))
