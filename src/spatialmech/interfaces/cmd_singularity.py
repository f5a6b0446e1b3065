"""CLI: ``spatialmech singularity`` (kind, rank, uncontrolled twist, line geometry, loci)."""

from __future__ import annotations

import sys
from pathlib import Path

import click
import numpy as np

from .. import api as sm
from ..errors import InputError
from .cmd_kinematics import resolve_pose, with_pose
from .common import check_output_file, emit_json, json_option, load_model, tol_option
from .task_args import parse_axes, parse_free, parse_task_at

_SLICE_NAMES = ("x", "y", "z", "a1", "a2", "a3")


def _parse_slice(text: str):
    axes = []
    for part in text.split(","):
        bits = part.strip().split(":")
        if len(bits) != 4 or bits[0] not in _SLICE_NAMES:
            raise InputError(f"--slice: expected NAME:MIN:MAX:N,NAME:MIN:MAX:N with NAME in {', '.join(_SLICE_NAMES)}, "
                             f"got {part!r}")
        try:
            lo, hi, n = float(bits[1]), float(bits[2]), int(bits[3])
        except ValueError:
            raise InputError(f"--slice: bad numbers in {part!r}") from None
        if n < 2 or n > 400:
            raise InputError(f"--slice: N must be 2..400, got {n}")
        if not (np.isfinite(lo) and np.isfinite(hi)):
            raise InputError(f"--slice: MIN and MAX must be finite, got {part!r}")
        axes.append((bits[0], np.linspace(lo, hi, n)))
    if len(axes) != 2 or axes[0][0] == axes[1][0]:
        raise InputError("--slice: give exactly two different axes")
    return axes


def _task_slice(mech, slice_spec: str, at, free, acts, plot, as_json) -> None:
    """``singularity --slice ... [--at ...]`` without a pose: a slice over task coordinates."""
    axes = parse_axes(slice_spec, "--slice", min_axes=2, max_axes=2)
    held = parse_task_at(at, "--at")
    free_names = parse_free(free)
    bar = None if as_json else click.progressbar(length=1, label="slice (solving task coordinates)", file=sys.stderr)

    def prog(done, total, msg):
        if bar is not None:
            bar.length = max(bar.length or 0, int(total or done))
            bar.update(int(done) - bar.pos)

    res = sm.singularity_slice(mech, axes, at=held, free=free_names, drivers=acts, progress=prog if bar else None)
    if bar:
        bar.render_finish()
    (n1, n2) = res.names
    if not np.isfinite(res.sigma_min).any():
        raise InputError(f"--slice: the task coordinates do not close at any point of the {n1} x {n2} slice; "
                         "move or narrow the slice")
    if plot is not None:
        from ..present.singularity import slice_figure  # matplotlib: only when a figure is asked for

        shown = res.for_display()
        slice_figure(shown, f"{mech.name}: singularity loci over task coordinates ({res.euler}, angles in degrees; "
                            f"solved {', '.join(res.solved)})").savefig(plot)
    if as_json:
        emit_json("singularity", mech, {"result": "singularity_task_slice", **res.to_dict()})
        return
    det, finite = res.det, np.isfinite(res.sigma_min)
    held_text = ", ".join(f"{c} = {np.degrees(v):.4g} deg" if c.startswith("a") else f"{c} = {v:.6g} {mech.length_unit}"
                          for c, v in res.held.items())
    click.echo(f"{mech.name}: det J over task coordinates {n1} x {n2} ({len(res.u)} x {len(res.v)} points"
               + (f", {held_text} held" if held_text else "") + f"; solved {', '.join(res.solved) or 'none'}; "
               f"{int(finite.sum())} close): {int(np.sum(det[finite] > 0))} positive, {int(np.sum(det[finite] < 0))} "
               f"negative, smallest sigma_min {np.nanmin(res.sigma_min):.3g}")
    click.echo(f"  orientation: {res.to_dict()['orientation_convention']}; {res.n_solves} solves in {res.seconds:.2f} s")
    if plot is not None:
        click.echo(f"  wrote {plot}")


@click.command(name="singularity")
@click.argument("model")
@with_pose
@click.option("--reference", is_flag=True, help="Analyse the model's reference configuration.")
@click.option("--driver", "drivers", multiple=True, help="Actuated freedom(s) (default: the model's actuators).")
@click.option("--slice", "slice_spec", default=None,
              help="Loci on a 2-D slice around the pose: NAME:MIN:MAX:N,NAME:MIN:MAX:N with NAME in x,y,z (length) "
                   "or a1,a2,a3 (the --euler angles, degrees); without a pose, over task coordinates (see --at).")
@click.option("--at", "at", default=None, metavar="NAME=VALUE,...",
              help="A slice over task coordinates (lower-mobility mechanisms; no pose given): the given coordinates "
                   "held, x, y, z (length) or a1, a2, a3 (deg); the parasitic ones are solved at every grid point.")
@click.option("--free", "free", default=None, metavar="NAME,...",
              help="With a task slice: the coordinates to solve (default: the model's task, or the slice and --at names).")
@click.option("--plot", "plot", type=click.Path(dir_okay=False, path_type=Path), default=None, help="PNG of the slice.")
@tol_option("singular")
@json_option
def singularity_cmd(model, xyz, euler, position, reference, drivers, slice_spec, at, free, plot, as_json):
    """Singularity analysis at a pose: rank of the wrench system, kind (inverse, direct,
    constraint), uncontrolled twist, line geometry of the wrenches, finite self-motion.

    \b
    Examples:
      spatialmech singularity four-sps-cu --reference
      spatialmech singularity four-sps-cu --xyz 0 0 0.12 --euler ZYX 34.38 -5.73 11.46 --json
      spatialmech singularity four-sps-cu --xyz 0 0 0.12 --euler ZYX 20 0 0 \\
          --slice a2:-30:30:25,a3:-30:30:25 --plot loci.png
      spatialmech singularity three-rps --slice a2:-30:30:31,a3:-30:30:31 --at z=0.33
    """
    if reference:
        given = [name for name, v in (("a pose (--xyz/--euler/--pose)", xyz if xyz is not None else euler),
                                      ("--position", position), ("--slice", slice_spec), ("--at", at),
                                      ("--free", free)) if v is not None]
        if given:
            raise InputError(f"--reference: analyses the model's reference configuration and takes no pose; "
                             f"it cannot be combined with {', '.join(given)} (drop --reference to analyse the pose)")
    posed = xyz is not None or euler is not None or position is not None
    for name, v in (("--at", at), ("--free", free)):
        if v is not None and (slice_spec is None or posed):
            raise InputError(f"{name}: only with --slice and no pose (a slice over task coordinates, the parasitic "
                             "ones solved); with a pose, --slice varies the pose itself")
    check_output_file(plot, "--plot")
    mech = load_model(model)
    acts = list(drivers) or None
    if slice_spec is not None and not posed:
        _task_slice(mech, slice_spec, at, free, acts, plot, as_json)
        return
    if slice_spec is not None:
        if euler is None or xyz is None:
            raise InputError("--slice: give the base pose with --xyz and --euler")
        (n1, g1), (n2, g2) = _parse_slice(slice_spec)
        bar = None if as_json else click.progressbar(length=len(g2), label="slice", file=sys.stderr)
        prog = (lambda j, n, msg: bar.update(1)) if bar else None
        res = sm.singularity_slice(mech, {n1: g1, n2: g2}, pose=(list(xyz), tuple(euler)), drivers=acts, degrees=True,
                                   progress=prog)
        if bar:
            bar.render_finish()
        if not np.isfinite(res.det).any():
            raise InputError(f"--slice: no pose of the {n1} x {n2} slice closes (the mechanism cannot assemble "
                             "at any of them); move or narrow the slice")
        if plot is not None:
            from ..present.singularity import slice_figure

            slice_figure(res, f"{mech.name}: singularity loci ({euler[0]}, angles in degrees)").savefig(plot)
        d = res.to_dict()
        if as_json:
            emit_json("singularity", mech, {"result": "singularity_slice", **d})
            return
        det = res.det
        finite = np.isfinite(det)
        click.echo(f"{mech.name}: det J over {n1} x {n2} ({len(g1)} x {len(g2)} poses, {int(finite.sum())} reachable): "
                   f"{int(np.sum(det[finite] > 0))} positive, {int(np.sum(det[finite] < 0))} negative, "
                   f"smallest sigma_min {np.nanmin(res.sigma_min):.3g}")
        if plot is not None:
            click.echo(f"  wrote {plot}")
        return
    pose = None if reference else resolve_pose(mech, xyz, euler, position)  # None: the reference configuration
    r = sm.singularity(mech, pose, drivers=acts)
    if as_json:
        emit_json("singularity", mech, r.to_dict())
        return
    click.echo(f"{mech.name}: {r.kind if r.kind != 'none' else 'not singular'}; "
               f"wrench-system rank {r.rank} of {r.expected_rank}; "
               f"scale-free sigma_min {r.sigma_min:.3g}")
    for t in r.twist:
        click.echo("  uncontrolled twist (omega ; v): (" + " ".join(f"{x:+.4g}" for x in t[:3]) + " ; "
                   + " ".join(f"{x:+.4g}" for x in t[3:]) + ")")
    if r.line_geometry:
        lg = r.line_geometry
        click.echo(f"  line geometry of the {len(r.jacobian.wrenches)} wrenches: rank {lg['rank']}, "
                   f"{lg['case']}: {lg['description']}")
        for c in lg.get("circuits", [])[:4]:
            click.echo(f"    dependent subset {c.get('indices')}: {c.get('case')}: {c.get('description')}")
    if r.self_motion:
        sm_ = r.self_motion
        if sm_.get("finite"):
            click.echo(f"  finite self-motion with the actuators locked: platform point moved {sm_['platform_point_moved']:.4g} "
                       f"{mech.length_unit} and turned {sm_['platform_rotated_deg']:.3g} deg over a traced arc of "
                       f"{sm_['arc']:.3g} (nondimensional)")
        else:
            click.echo("  the uncontrolled motion is only instantaneous")
    click.echo(f"  {r.explanation}")
