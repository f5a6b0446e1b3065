"""CLI commands of the position / Jacobian analyses: ``ik``, ``fk``, ``jacobian``.

Poses at the command line: ``--xyz X Y Z`` (the platform point, length unit of the model) and
``--euler SEQ A1 A2 A3`` (an explicitly named sequence, angles in degrees; upper case =
intrinsic); or ``--position N`` for a model's built-in task positions (numbered from 1).
Rotational actuator values are in degrees, slides in the model's length unit.
"""

from __future__ import annotations

import click
import numpy as np

from .. import catalog
from ..geometry.rotations import euler_matrix, matrix_euler
from ..analysis.defects import dj_table as compute_dj_table
from ..kinematics.jacobian import complete_jacobian
from ..kinematics.position import configuration_at_pose, forward_position, inverse_position
from ..model.mechanism import Mechanism, Pose
from .common import emit_json, json_option

pose_options = [
    click.option("--pose", "pose_text", default=None,
                 help="X,Y,Z,SEQ,A1,A2,A3 in one option: platform point (length) and Euler angles (deg), e.g. 0,0,0.12,ZYX,34.38,-5.73,11.46."),
    click.option("--xyz", nargs=3, type=float, default=None, help="Platform point position X Y Z (model length unit)."),
    click.option("--euler", "euler", nargs=4, type=(str, float, float, float), default=None,
                 help="Orientation: SEQ A1 A2 A3, angles in degrees (e.g. ZYX 30 -5 10; upper case = intrinsic)."),
    click.option("--position", "position", type=int, default=None, help="Built-in task position number (from 1)."),
]


def with_pose(f):
    """Add the pose options; the command receives ``xyz, euler, position`` (``--pose`` is parsed
    into ``xyz`` and ``euler``)."""
    import functools

    @functools.wraps(f)
    def wrapper(*args, pose_text=None, xyz=None, euler=None, **kw):
        if pose_text is not None:
            if xyz is not None or euler is not None:
                raise ValueError("--pose: give either --pose or --xyz/--euler, not both")
            xyz, euler = parse_pose(pose_text)
        return f(*args, xyz=xyz, euler=euler, **kw)

    for opt in reversed(pose_options):
        wrapper = opt(wrapper)
    return wrapper


def parse_pose(text: str):
    """``"X,Y,Z,SEQ,A1,A2,A3"`` -> ((x, y, z), (seq, a1, a2, a3)), angles in degrees."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 7:
        raise ValueError(f"--pose: expected X,Y,Z,SEQ,A1,A2,A3 (7 comma-separated values), got {len(parts)}")
    try:
        xyz = tuple(float(v) for v in parts[:3])
        ang = tuple(float(v) for v in parts[4:])
    except ValueError:
        raise ValueError(f"--pose: expected numbers for X,Y,Z and A1,A2,A3, got {text!r}") from None
    return xyz, (parts[3], *ang)


def resolve_pose(mech: Mechanism, xyz, euler, position) -> Pose:
    if position is not None:
        if xyz is not None or euler is not None:
            raise ValueError("--position: give either --position or --xyz/--euler, not both")
        if not mech.positions:
            raise ValueError(f"--position: {mech.name} has no built-in task positions")
        if not 1 <= position <= len(mech.positions):
            raise ValueError(f"--position: expected 1..{len(mech.positions)}, got {position}")
        return mech.positions[position - 1]
    if xyz is None and euler is None:
        raise ValueError("--xyz/--euler: give a pose (or --position N)")
    p = np.asarray(xyz if xyz is not None else mech.platform_point, dtype=float)
    if euler is None:
        R = np.eye(3)
    else:
        seq, *ang = euler
        R = euler_matrix(seq, ang, degrees=True)
    return Pose(R, p, "requested")


#: Scale-free smallest singular value below which a configuration is reported as singular.
SINGULAR_SIGMA = 1e-9


def _deg(a: float, ndigits: int = 4) -> float:
    """Degrees rounded to ``ndigits``, without a negative zero (``-0.0000``) from round-off."""
    return round(float(np.degrees(a)), ndigits) + 0.0


def _num(v, fmt: str) -> str:
    """``"0, -0.01, 1.05"``: components rounded to ``fmt``, round-off (< 1e-12) shown as 0."""
    v = np.where(np.abs(np.asarray(v, float)) < 1e-12, 0.0, np.asarray(v, float))
    return ", ".join(format(float(x) + 0.0, fmt) for x in v)


def _fmt_value(mech: Mechanism, fid: str, v: float) -> str:
    f = mech.freedom(fid).freedom
    return f"{v:.6g} {mech.length_unit}" if f.kind == "P" else f"{np.degrees(v):.6g} deg"


@click.command()
@click.argument("model")
@with_pose
@click.option("--all", "all_solutions", is_flag=True, help="Search every real solution of every limb.")
@json_option
def ik(model, xyz, euler, position, all_solutions, as_json):
    """Inverse position: joint values of every limb for a platform pose.

    \b
    Examples:
      spatialmech ik four-sps-cu --xyz 0 0 0.12 --euler ZYX 34.38 -5.73 11.46
      spatialmech ik four-sps-cu --pose 0,0,0.12,ZYX,34.38,-5.73,11.46 --json
      spatialmech ik five-cs-1 --position 3 --json
      spatialmech ik delta --xyz 0.02 0.01 -0.33 --all
    """
    mech = catalog.resolve(model)
    pose = resolve_pose(mech, xyz, euler, position)
    res = inverse_position(mech, pose, all_solutions=all_solutions)
    # A model's task positions are printed (rounded) data: say how far the nearest closed
    # configuration is instead of leaving a bare "not reachable".
    fit = configuration_at_pose(mech, pose) if (position is not None and not res.reachable) else None
    if as_json:
        d = res.to_dict(mech)
        if fit is not None:
            d["pose_fit"] = {**fit.to_dict(), "note": f"P{position} is printed (rounded) data; pose_fit is the "
                             "nearest closed configuration (configuration_at_pose), position_error in the model's length unit"}
        emit_json(d)
        return
    click.echo(f"{mech.name}: pose {'reachable' if res.reachable else 'NOT reachable'}")
    for limb in res.to_dict(mech)["limbs"]:
        extra = f", solution set of dimension {limb['passive_dim']} (passive freedoms)" if limb["passive_dim"] else ""
        click.echo(f"  {limb['limb']}: {len(limb['solutions'])} solution(s){extra}" + ("" if limb["reachable"] else " [least-squares, not closed]"))
        for k, sol in enumerate(limb["solutions"]):
            vals = ", ".join(f"{fid}={v:.6g}" for fid, v in sol["values"].items())
            lim = f"  outside limits: {', '.join(sol['outside_limits'])}" if sol["outside_limits"] else ""
            click.echo(f"    [{k + 1}] {vals}  (residual {sol['residual']:.1e}){lim}")
    if res.config is not None:
        click.echo("  actuators: " + ", ".join(f"{k} = {_fmt_value(mech, k, v)}" for k, v in res.actuator_values(mech).items()))
    click.echo("  (rotations in degrees, slides in " + mech.length_unit + ")")
    if fit is not None and fit.converged:
        click.echo(f"  note: task position {position} is printed (rounded) data; the nearest closed configuration is "
                   f"{fit.position_error:.3g} {mech.length_unit} and {np.degrees(fit.angle_error):.3g} deg from it "
                   "(`spatialmech jacobian --position N` uses that configuration)")


@click.command()
@click.argument("model")
@click.option("--actuators", "values", required=True, help="Comma-separated actuator values in mechanism order (degrees / length).")
@click.option("--all", "all_solutions", is_flag=True, help="Search all real assembly modes (multi-start).")
@click.option("--seeds", type=click.IntRange(min=1), default=None,
              help="Number of starts for --all (default: 200; 512 on the 4-SPS/CU closed form).")
@json_option
def fk(model, values, all_solutions, seeds, as_json):
    """Forward position: platform pose(s) for actuator values.

    \b
    Examples:
      spatialmech fk stewart-6sps --actuators 1.2,1.2,1.2,1.2,1.2,1.2
      spatialmech fk four-sps-cu --actuators 0.21,0.25,0.22,0.19 --all --json
    """
    mech = catalog.resolve(model)
    try:
        raw = [float(x) for x in values.split(",") if x.strip()]
    except ValueError:
        raise ValueError(f"--actuators: expected comma-separated numbers, got {values!r}") from None
    acts = mech.actuators
    if len(raw) != len(acts):
        raise ValueError(f"--actuators: {mech.name} has {len(acts)} actuators ({', '.join(acts)}), got {len(raw)} values")
    vals = [v if mech.freedom(a).freedom.kind == "P" else np.radians(v) for a, v in zip(acts, raw)]
    from ..kinematics.closed_forms import four_sps_cu as k4

    geom = k4.geometry_of(mech) if all_solutions else None
    if geom is not None:  # the closed form of this limb layout: faster and more thorough
        fa = k4.forward_all(np.asarray(vals), geometry=geom, **({} if seeds is None else {"n_seeds": seeds}))
        d = fa.to_dict()
        d["method"] = "closed form of the 4-SPS/CU (kinematics/closed_forms/four_sps_cu.py)"
        if as_json:
            emit_json(d)
            return
        click.echo(f"{mech.name}: {len(fa.solutions)} assembly mode(s) found ({fa.n_within_limits} within the leg and CU "
                   f"limits; closed-form multi-start, {fa.search.n_seeds} seeds)")
        for n, s_ in enumerate(fa.solutions):
            z, al, be, ga = s_.phi
            sing = f"  singular (sigma_min {s_.sigma_min:.1e})" if s_.sigma_min < SINGULAR_SIGMA else ""
            click.echo(f"  [{n + 1}] z = {round(float(z), 6) + 0.0:.6f} m, alpha = {_deg(al):.4f}, beta = {_deg(be):.4f}, "
                       f"gamma = {_deg(ga):.4f} deg ('ZYX')  {'within limits' if s_.within_limits else 'outside limits'}{sing}")
        n_sing = sum(s_.sigma_min < SINGULAR_SIGMA for s_ in fa.solutions)
        if n_sing:
            click.echo(f"  warning: {n_sing} of these poses are singular (scale-free sigma_min < {SINGULAR_SIGMA:g}): "
                       "the locked mechanism has a self-motion there, and singular poses found by different starts "
                       "are samples of a continuum, not distinct assembly modes")
        return
    seeds = 200 if seeds is None else seeds
    if all_solutions and not as_json:
        import sys

        with click.progressbar(length=seeds, label="assembly modes", file=sys.stderr) as bar:
            res = forward_position(mech, vals, all_solutions=True, n_seeds=seeds, progress=lambda k, n: bar.update(1))
    else:
        res = forward_position(mech, vals, all_solutions=all_solutions, n_seeds=seeds)
    if as_json:
        emit_json(res.to_dict(mech))
        return
    if not res.solutions or not any(s.converged for s in res.solutions):
        raise ValueError(f"actuators: no assembly found (Newton did not converge; residual {res.solutions[0].residual:.2e}); try --all")
    click.echo(f"{mech.name}: {res.search['distinct']} assembly mode(s) found ({res.search['method']}, {res.search['seeds']} start(s))")
    for k, s in enumerate(res.solutions):
        if not s.converged:
            continue
        e = matrix_euler("ZYX", s.pose.R, degrees=True)
        lim = "within limits" if not s.outside_limits else "outside limits: " + ", ".join(s.outside_limits)
        click.echo(f"  [{k + 1}] platform point ({_num(s.pose.p, '.6g')}) {mech.length_unit}, "
                   f"ZYX angles ({_num(e, '.4f')}) deg  {lim}")


@click.command()
@click.argument("model")
@with_pose
@click.option("--driver", "drivers", multiple=True, help="Actuated freedom(s) (repeatable; default: the model's actuators).")
@click.option("--dj-table", is_flag=True, help="DJ at every built-in task position for every base-joint driver.")
@json_option
def jacobian(model, xyz, euler, position, drivers, dj_table, as_json):
    """Complete Jacobian (constraint + actuation wrenches), its determinant and conditioning.

    \b
    Examples:
      spatialmech jacobian five-cs-1 --position 3 --driver rot1
      spatialmech jacobian five-cs-3 --dj-table --json
      spatialmech jacobian four-sps-cu --xyz 0 0 0.12 --euler ZYX 34.38 -5.73 11.46
    """
    mech = catalog.resolve(model)
    if dj_table:
        if not mech.positions:
            raise ValueError(f"--dj-table: {mech.name} has no built-in task positions")
        t = compute_dj_table(mech, list(drivers) or None)
        fits = t.fits
        rows = [{"driver": d, "dj": [float(x) for x in t.dj[i]], "signs": [int(x) for x in t.signs[i]],
                 "keeps_sign": t.keeps_sign(d), "sigma_min": [float(x) for x in t.sigma_min[i]]}
                for i, d in enumerate(t.drivers)]
        data = {"model": mech.name, "positions": [p.name for p in mech.positions],
                "pose_fit": [f.to_dict() for f in fits], "drivers": rows,
                "note": "DJ magnitudes are not comparable between drivers; only signs along one driver are."}
        if as_json:
            emit_json(data)
            return
        click.echo(f"{mech.name}: sign of DJ at {', '.join(data['positions'])}")
        for r in rows:
            click.echo(f"  {r['driver']:>8s}  " + " ".join("+" if s > 0 else ("-" if s < 0 else "0") for s in r["signs"])
                       + ("   keeps its sign" if r["keeps_sign"] else "   changes sign"))
        worst = max(fits, key=lambda f: f.position_error)
        click.echo(f"  printed poses fitted onto the closure: largest error {worst.position_error:.3g} {mech.length_unit},"
                   f" {np.degrees(max(f.angle_error for f in fits)):.3g} deg")
        return
    pose = resolve_pose(mech, xyz, euler, position)
    fit = configuration_at_pose(mech, pose)
    if not fit.converged:
        raise ValueError(f"pose: no closed configuration near it (residual {fit.ik_residual:.2e})")
    J = complete_jacobian(mech, fit.config, list(drivers) or None)
    if as_json:
        emit_json({**J.to_dict(), "pose_fit": fit.to_dict()})
        return
    click.echo(f"{mech.name}: complete Jacobian (rows: {J.constraint_rows} constraint, {len(J.actuators)} actuation"
               f" [{', '.join(J.actuators)}]); J $p = (0, qdot)")
    for row in J.matrix:
        click.echo("  [" + " ".join(f"{x:+.5e}" for x in row) + "]")
    if J.det is not None:
        click.echo(f"  det J = {J.det:+.6e}")
    click.echo(f"  scale-free sigma_min = {J.sigma_min:.4g}, 1/condition = {J.condition:.4g}")
    if J.sigma_min < SINGULAR_SIGMA:
        click.echo(f"  SINGULAR configuration (sigma_min < {SINGULAR_SIGMA:g}): det J is round-off; "
                   "`spatialmech singularity` gives its kind and the uncontrolled twist")
    if J.inverse_singular:
        click.echo(f"  inverse (serial) singular for: {', '.join(J.inverse_singular)}")
    if not fit.exact:
        click.echo(f"  note: the pose was fitted onto the closure (error {fit.position_error:.3g} {mech.length_unit}, {np.degrees(fit.angle_error):.3g} deg)")
