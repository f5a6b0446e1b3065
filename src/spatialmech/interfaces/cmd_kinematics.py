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
from ..analysis.defects import dj_table as compute_dj_table
from ..errors import InputError
from ..geometry.rotations import euler_matrix, matrix_euler
from ..geometry.tolerances import current as current_tolerances
from ..kinematics.jacobian import complete_jacobian
from ..kinematics.position import configuration_at_pose, inverse_position
from ..kinematics.forward import forward_position
from ..kinematics.task import TaskJacobian, default_task, solve_pose, task_jacobian_at, task_solution_dict
from ..model.mechanism import Mechanism, Pose
from ..serialize import pose_dict
from .common import emit_json, json_option, parse_numbers, tol_option

#: Largest number of starts of ``fk --all`` (each start is one Newton solve).
MAX_SEEDS = 20_000

pose_options = [
    click.option("--pose", "pose_text", default=None,
                 help="X,Y,Z,SEQ,A1,A2,A3 in one option: platform point (length) and Euler angles (deg), "
                      "e.g. 0,0,0.12,ZYX,34.38,-5.73,11.46."),
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
                raise InputError("--pose: give either --pose or --xyz/--euler, not both")
            xyz, euler = parse_pose(pose_text)
        return f(*args, xyz=xyz, euler=euler, **kw)

    for opt in reversed(pose_options):
        wrapper = opt(wrapper)
    return wrapper


def parse_pose(text: str):
    """``"X,Y,Z,SEQ,A1,A2,A3"`` -> ((x, y, z), (seq, a1, a2, a3)), angles in degrees."""
    parts = [p.strip() for p in text.split(",")]
    if len(parts) != 7:
        raise InputError(f"--pose: expected X,Y,Z,SEQ,A1,A2,A3 (7 comma-separated values), got {len(parts)}")
    try:
        xyz = tuple(float(v) for v in parts[:3])
        ang = tuple(float(v) for v in parts[4:])
    except ValueError:
        raise InputError(f"--pose: expected numbers for X,Y,Z and A1,A2,A3, got {text!r}") from None
    return xyz, (parts[3], *ang)


def free_names(text: str) -> list[str]:
    """``--free x,y,a1`` -> ``["x", "y", "a1"]`` (the names are checked by ``solve_pose``)."""
    names = [n.strip() for n in text.split(",")]
    if any(not n for n in names):
        raise InputError(f"--free: empty name in {text!r}; expected names from x,y,z,a1,a2,a3 separated by commas")
    return names


#: Largest distance of a requested platform point from the reference one, in characteristic
#: lengths of the model (farther is out of the numerical range: squares overflow).
MAX_POSE_DISTANCE = 1e6
#: Largest rotational actuator value (degrees) accepted: beyond it a double has no precision left.
MAX_ANGLE_DEG = 1e9


def resolve_pose(mech: Mechanism, xyz, euler, position) -> Pose:
    if position is not None:
        if xyz is not None or euler is not None:
            raise InputError("--position: give either --position or --xyz/--euler, not both")
        if not mech.positions:
            raise InputError(f"--position: {mech.name} has no built-in task positions")
        if not 1 <= position <= len(mech.positions):
            raise InputError(f"--position: expected 1..{len(mech.positions)}, got {position}")
        return mech.positions[position - 1]
    if xyz is None and euler is None:
        raise InputError("--xyz/--euler: give a pose (or --position N)")
    p = np.asarray(xyz if xyz is not None else mech.platform_point, dtype=float)
    if not np.all(np.isfinite(p)):
        raise InputError(f"--xyz: expected finite numbers, got {', '.join(f'{v:g}' for v in p)}")
    with np.errstate(over="ignore"):
        dist = float(np.max(np.abs(p - mech.platform_point)))
    if dist > MAX_POSE_DISTANCE * mech.characteristic_length:  # squares of such numbers overflow
        raise InputError(f"--xyz: the point is {dist:.3g} {mech.length_unit} from the reference platform point of "
                         f"{mech.name}, more than {MAX_POSE_DISTANCE:g} times its size "
                         f"({mech.characteristic_length:.3g} {mech.length_unit}): out of range")
    if euler is None:
        R = np.eye(3)
    else:
        seq, *ang = euler
        if not np.all(np.isfinite(ang)):
            raise InputError(f"--euler: expected finite angles (degrees), got {', '.join(f'{v:g}' for v in ang)}")
        R = euler_matrix(seq, ang, degrees=True)
    return Pose(R, p, "requested")




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
@click.option("--free", "free", default=None,
              help="Task coordinates to SOLVE (parasitic), comma-separated from x,y,z,a1,a2,a3 (a1..a3: the --euler "
                   "sequence's angles, default ZYX); the others are held at the pose's values. For lower-mobility "
                   "mechanisms, e.g. --free x,y,a1 for a 3-RPS.")
@tol_option("reachability")
@json_option
def ik(model, xyz, euler, position, all_solutions, free, as_json):
    """Inverse position: joint values of every limb for a platform pose.

    \b
    Examples:
      spatialmech ik three-rps --pose 0,0,0.33,ZYX,0,5,5 --free x,y,a1 --json
      spatialmech ik four-sps-cu --xyz 0 0 0.12 --euler ZYX 34.38 -5.73 11.46
      spatialmech ik four-sps-cu --pose 0,0,0.12,ZYX,34.38,-5.73,11.46 --json
      spatialmech ik five-cs-1 --position 3 --json
      spatialmech ik delta --xyz 0.02 0.01 -0.33 --all
    """
    mech = catalog.resolve(model)
    pose = resolve_pose(mech, xyz, euler, position)
    task = None
    if free is not None:
        task = solve_pose(mech, pose, free_names(free), euler=euler[0] if euler is not None else "ZYX")
        if task.converged:
            pose = Pose(task.D[:3, :3], task.D[:3, :3] @ mech.platform_point + task.D[:3, 3], "requested, solved")
    res = inverse_position(mech, pose, all_solutions=all_solutions, fit=True,
                           start=task.config if task is not None and task.converged else None)
    # A pose that does not close exactly (printed, rounded data: a task position, a pose printed
    # by fk) is fitted onto the closure: reachable when the nearest closed configuration is
    # within the reachability tolerance, and either way the distance is said, never hidden.
    fit = res.pose_fit
    reach_tol = current_tolerances().reachability
    d = res.to_dict(mech)
    d["task"] = None if task is None else task_solution_dict(task)
    if as_json:
        d["pose_fit"] = None if fit is None else {
            **fit.to_dict(), "tolerance": reach_tol,
            "note": "the pose does not close exactly (printed, rounded data?); pose_fit is the nearest closed "
                    "configuration (configuration_at_pose); within the tolerance (pose_error: the larger of the "
                    "angle error in rad and the position error over the characteristic length) the pose is "
                    "reachable and the solutions are those of the fitted pose"}
        emit_json("ik", mech, d)
        return
    order = {r.id: i for i, r in enumerate(mech.freedom_refs)}
    fitted = (f" (fitted onto the closure: off by {fit.position_error:.3g} {mech.length_unit} and "
              f"{np.degrees(fit.angle_error):.3g} deg, within the tolerance {reach_tol:g})") if res.fitted else ""
    click.echo(f"{mech.name}: pose {'reachable' if res.reachable else 'NOT reachable'}{fitted}")
    if task is not None:
        t = d["task"]
        vals = {**t["values_len"], **t["values_deg"]}
        unit = {n: (mech.length_unit if n in t["values_len"] else "deg") for n in vals}
        click.echo(f"  task coordinates ({t['euler']}): given {', '.join(f'{n} = {vals[n]:.6g} {unit[n]}' for n in t['given'])}")
        click.echo(f"  solved{'' if task.converged else ' (NOT converged: ' + t['status'] + ')'}: "
                   + ", ".join(f"{n} = {vals[n]:.6g} {unit[n]}" for n in t["solved"]))
    for limb in d["limbs"]:
        extra = f", solution set of dimension {limb['passive_dim']} (passive freedoms)" if limb["passive_dim"] else ""
        click.echo(f"  {limb['limb']}: {len(limb['solutions'])} solution(s){extra}"
                   + ("" if limb["reachable"] else " [least-squares, not closed]"))
        for k, sol in enumerate(limb["solutions"]):
            values = sorted({**sol["joints_deg"], **sol["joints_len"]}.items(), key=lambda kv: order[kv[0]])
            vals = ", ".join(f"{fid}={v:.6g}" for fid, v in values)
            lim = f"  outside limits: {', '.join(sol['outside_limits'])}" if sol["outside_limits"] else ""
            click.echo(f"    [{k + 1}] {vals}  (residual {sol['residual']:.1e}){lim}")
    if res.config is not None:
        click.echo("  actuators: " + ", ".join(f"{k} = {_fmt_value(mech, k, v)}" for k, v in res.actuator_values(mech).items()))
    click.echo("  (rotations in degrees, slides in " + mech.length_unit + ")")
    if task is None and not res.reachable:
        dt = default_task(mech)
        if len(dt.given) < 6:
            click.echo(f"  note: {mech.name}'s output link has {len(dt.given)} freedoms: a full pose is reachable only with its "
                       f"parasitic coordinates solved; try --free {','.join(dt.solved)} (gives {', '.join(dt.given)})")
    if fit is not None and fit.converged and not res.reachable:
        what = f"task position {position} is printed (rounded) data; " if position is not None else ""
        click.echo(f"  note: {what}the nearest closed configuration is {fit.position_error:.3g} {mech.length_unit} and "
                   f"{np.degrees(fit.angle_error):.3g} deg from it (pose error {fit.error:.2g}, beyond the reachability "
                   f"tolerance {reach_tol:g}; `--tol` sets it; `spatialmech jacobian` uses that configuration)")


@click.command()
@click.argument("model")
@click.option("--actuators", "values", required=True,
              help="Comma-separated actuator values in mechanism order (degrees / length).")
@click.option("--all", "all_solutions", is_flag=True,
              help="All real assembly modes: homotopy continuation (proven complete) where it covers the model, "
                   "else multi-start.")
@click.option("--method", type=click.Choice(["auto", "homotopy", "multistart"]), default="auto", show_default=True,
              help="Method of --all (homotopy: proven complete for S-P-S and R-P-S legs, passive C-U limbs, ...; "
                   "by monodromy, not proven, for other limbs of R, P, C, U, S joints; see docs/homotopy.md).")
@click.option("--seeds", type=click.IntRange(min=1, max=MAX_SEEDS), default=None,
              help=f"Number of starts for --all (default: 200; 512 on the 4-SPS/CU closed form; at most {MAX_SEEDS}).")
@tol_option("newton")
@json_option
def fk(model, values, all_solutions, method, seeds, as_json):
    """Forward position: platform pose(s) for actuator values.

    \b
    Examples:
      spatialmech fk stewart-6sps --actuators 1.2,1.2,1.2,1.2,1.2,1.2
      spatialmech fk four-sps-cu --actuators 0.21,0.25,0.22,0.19 --all --json
      spatialmech fk stewart-6sps --actuators 1.2,1.2,1.2,1.2,1.2,1.2 --all
    """
    mech = catalog.resolve(model)
    raw = parse_numbers(values, "--actuators")
    acts = mech.actuators
    if len(raw) != len(acts):
        raise InputError(f"--actuators: {mech.name} has {len(acts)} actuators ({', '.join(acts)}), got {len(raw)} values")
    for k, (a, v) in enumerate(zip(acts, raw, strict=True), start=1):  # beyond these, squares overflow
        slide = mech.freedom(a).freedom.kind == "P"
        top = MAX_POSE_DISTANCE * mech.characteristic_length if slide else MAX_ANGLE_DEG
        if abs(v) > top:
            unit = mech.length_unit if slide else "deg"
            why = f" (1e6 times the size of {mech.name})" if slide else ""
            raise InputError(f"--actuators: item {k} ({a} = {v:g} {unit}) is out of range: at most {top:.3g} {unit}{why}")
    vals = [v if mech.freedom(a).freedom.kind == "P" else np.radians(v) for a, v in zip(acts, raw, strict=True)]
    from ..kinematics.closed_forms import four_sps_cu as k4
    from ..kinematics.closed_forms import four_sps_cu_forward as k4f

    closed = all_solutions and method == "auto" and k4.geometry_of(mech) is not None  # the 4-SPS/CU keeps its closed form
    pre = None
    if all_solutions and method != "multistart" and not closed:
        from ..kinematics.homotopy import study as hc
        from ..kinematics.homotopy import general as hg

        why = hc.unsupported_reason(mech)
        gwhy = hg.general_reason(mech) if why is not None else None
        if why is None or gwhy is None:
            pre = forward_position(mech, vals, all_solutions=True, method="homotopy" if why is None else method,
                                   n_seeds=200 if seeds is None else seeds)
            if "n_generic" in pre.search:
                _fk_homotopy(mech, pre, as_json)
                return
            # the loop formulation's monodromy stopped unsaturated: the multi-start ran instead (printed below)
        elif method == "homotopy":
            raise InputError(f"--method: homotopy does not cover {mech.name}: {why}; nor does the loop formulation: "
                             f"{gwhy}; use --method multistart")
    geom = k4.geometry_of(mech) if all_solutions and method != "multistart" else None
    if geom is not None:  # the closed form of this limb layout: faster and more thorough
        fa = k4f.forward_all(np.asarray(vals), geometry=geom, **({} if seeds is None else {"n_seeds": seeds}))
        if as_json:
            emit_json("fk", mech, fa.to_dict(actuators=acts))
            return
        if not fa.solutions:
            raise InputError(f"actuators: no assembly found among {fa.search.n_seeds} starts of the closed form "
                             f"({fa.search.n_converged} converged); not a proof that none exists: check the values "
                             "against the leg limits, or try more --seeds")
        click.echo(_fk_header(mech, [s_.kind for s_ in fa.solutions], "closed-form multi-start", fa.search.n_seeds,
                              fa.search.n_converged) + f"; {fa.n_within_limits} within the leg and CU limits")
        for n, s_ in enumerate(fa.solutions):
            z, al, be, ga = s_.phi
            click.echo(f"  [{n + 1}] z = {round(float(z), 6) + 0.0:.6f} m, alpha = {_deg(al):.4f}, beta = {_deg(be):.4f}, "
                       f"gamma = {_deg(ga):.4f} deg ('ZYX')  {'within limits' if s_.within_limits else 'outside limits'}")
            _fk_conditioning_lines(s_.kind, s_.sigma_min, s_.condition, s_.singular_below, s_.members, s_.self_motion,
                                   mech.length_unit, None)
        return
    seeds = 200 if seeds is None else seeds
    if pre is not None:
        res = pre
    elif all_solutions and not as_json:
        import sys

        with click.progressbar(length=seeds, label="assembly modes", file=sys.stderr) as bar:
            res = forward_position(mech, vals, all_solutions=True, n_seeds=seeds, progress=lambda k, n, msg: bar.update(1))
    else:
        res = forward_position(mech, vals, all_solutions=all_solutions, n_seeds=seeds)
    if as_json:
        emit_json("fk", mech, res.to_dict(mech))
        return
    converged = [s for s in res.solutions if s.converged]
    if not converged:
        if all_solutions:
            raise InputError(f"actuators: no assembly found among {res.search['seeds']} starts "
                             f"({res.search['converged_runs']} converged); not a proof that none exists: check the values "
                             "against the limits and the mechanism's size, or try more --seeds")
        r0 = res.solutions[0].residual if res.solutions else float("nan")
        raise InputError(f"actuators: no assembly found (Newton did not converge; residual {r0:.2e}); try --all")
    click.echo(_fk_header(mech, [s.kind for s in converged], res.search["method"], res.search["seeds"],
                          res.search["converged_runs"]))
    if all_solutions:
        click.echo(f"  NOT proven complete: {res.search['completeness']}")
    _fk_solution_lines(mech, converged)


def _fk_solution_lines(mech: Mechanism, converged) -> None:
    for k, s in enumerate(converged):
        e = matrix_euler("ZYX", s.pose.R, degrees=True)
        lim = "within limits" if not s.outside_limits else "outside limits: " + ", ".join(s.outside_limits)
        click.echo(f"  [{k + 1}] platform point ({_num(s.pose.p, '.6g')}) {mech.length_unit}, "
                   f"ZYX angles ({_num(e, '.4f')}) deg  {lim}")
        c = s.conditioning
        _fk_conditioning_lines(s.kind, c.sigma_min, c.condition, c.threshold, s.members, s.self_motion, mech.length_unit,
                               c.free_dim)


def _fk_homotopy(mech: Mechanism, res, as_json: bool) -> None:
    """``fk --all`` by homotopy continuation: counts, completeness, the real assembly modes."""
    if as_json:
        emit_json("fk", mech, res.to_dict(mech))
        return
    sr = res.search
    sols = list(res.solutions)
    kinds = [s.kind for s in sols]
    n_sm = sum(k == "self-motion" for k in kinds)
    click.echo(f"{mech.name}: {len(sols)} real assembly mode{'s' if len(sols) != 1 else ''}"
               + (f" ({n_sm} of them self-motion sets)" if n_sm else "")
               + f"; end points: {sr['n_real']} real, {sr['n_complex']} complex, {sr['n_singular']} singular, "
               f"{sr['n_at_infinity']} at infinity, of {sr['n_generic']} generic solutions"
               + (f" ({sr['n_spurious']} spurious end points of the square system discarded)" if "n_spurious" in sr else "")
               + f" ({'loop formulation by monodromy' if 'n_spurious' in sr else 'homotopy continuation'}, "
               f"{sr['elapsed_s']:.2f} s)")
    how = sr["completeness"]
    if sr["complete"] and how.startswith("complete (trace test): "):  # say "complete" once
        how = "by the trace test: " + how[len("complete (trace test): "):]
    click.echo(("  complete (proven): " if sr["complete"] else "  NOT proven complete: ") + how)
    _fk_solution_lines(mech, sols)


def _fk_header(mech: Mechanism, kinds, method: str, seeds: int, converged: int) -> str:
    """``NAME: 2 assembly modes, 1 self-motion set (method, N starts, M converged)``."""
    n_reg = sum(k == "regular" for k in kinds)
    n_sing = sum(k == "singular" for k in kinds)
    n_sm = sum(k == "self-motion" for k in kinds)
    parts = [f"{n_reg} assembly mode{'s' if n_reg != 1 else ''}"]
    if n_sing:
        parts.append(f"{n_sing} singular root{'s' if n_sing != 1 else ''}")
    if n_sm:
        parts.append(f"{n_sm} self-motion set{'s' if n_sm != 1 else ''} (a continuum of poses with the actuators held)")
    return f"{mech.name}: {', '.join(parts)} found ({method}, {seeds} start(s), {converged} converged)"


def _fk_conditioning_lines(kind, sigma_min, condition, threshold, members, self_motion, length_unit, free_dim) -> None:
    """The conditioning of one forward-position result, and what a singular one means."""
    cond = f"sigma_min {sigma_min:.2e}, condition {condition:.2e} (scale-free)"
    if kind == "regular":
        click.echo(f"      {cond}: regular (above {threshold:.0e})" + (f"; reached by {members} starts" if members > 1 else ""))
    elif kind == "singular" and free_dim is not None and free_dim >= 2:
        click.echo(f"      SINGULAR: {cond}, below {threshold:.0e}; the platform has {free_dim} free directions with the "
                   "actuators held (the actuators do not fix the pose here; a set of higher dimension, not traced); "
                   f"{members} start(s) reached this pose")
    elif kind == "singular":
        click.echo(f"      SINGULAR: {cond}, below {threshold:.0e}; an isolated root where assembly modes meet (no finite "
                   f"motion with the actuators held); {members} start(s) reached it")
    else:
        sm = self_motion
        trace = ""
        if sm is not None:
            trace = (f" (traced: platform point moves up to {sm.position_spread:.3g} {length_unit}, turns up to "
                     f"{np.degrees(sm.rotation_spread):.3g} deg{', a closed loop' if sm.closed else ''})")
        click.echo(f"      SINGULAR, SELF-MOTION: {cond}, below {threshold:.0e}; the platform moves with the actuators "
                   f"held: this pose is one point of a continuum{trace}, not an assembly mode; {members} start(s) "
                   "landed on it")


@click.command()
@click.argument("model")
@with_pose
@click.option("--driver", "drivers", multiple=True, help="Actuated freedom(s) (repeatable; default: the model's actuators).")
@click.option("--dj-table", is_flag=True, help="DJ at every built-in task position for every base-joint driver.")
@click.option("--free", "free", default=None,
              help="Task coordinates to SOLVE (parasitic), as for ik: the others are held at the pose's values and "
                   "both Jacobians are taken there; also the coordinates of the input-output Jacobian.")
@tol_option("singular")
@json_option
def jacobian(model, xyz, euler, position, drivers, dj_table, free, as_json):
    """Complete Jacobian (constraint + actuation wrenches), its determinant and conditioning; for a
    lower-mobility model also the input-output Jacobian over its given task coordinates (d actuators
    / d given coordinates, the parasitic ones solved).

    \b
    Examples:
      spatialmech jacobian five-cs-1 --position 3 --driver rot1
      spatialmech jacobian five-cs-3 --dj-table --json
      spatialmech jacobian four-sps-cu --xyz 0 0 0.12 --euler ZYX 34.38 -5.73 11.46
      spatialmech jacobian three-rps --pose 0,0,0.33,ZYX,0,5,5 --free x,y,a1
    """
    mech = catalog.resolve(model)
    if dj_table and free is not None:
        raise InputError("--free: not with --dj-table (the DJ table is at the built-in task positions)")
    if dj_table:
        if not mech.positions:
            raise InputError(f"--dj-table: {mech.name} has no built-in task positions")
        t = compute_dj_table(mech, list(drivers) or None)
        fits = t.fits
        data = t.to_dict()
        if as_json:
            emit_json("jacobian", mech, {"result": "dj_table", **data})
            return
        click.echo(f"{mech.name}: sign of DJ at {', '.join(data['positions'])}")
        for r in data["drivers"]:
            click.echo(f"  {r['driver']:>8s}  " + " ".join("+" if s > 0 else ("-" if s < 0 else "0") for s in r["signs"])
                       + ("   keeps its sign" if r["keeps_sign"] else "   changes sign"))
        worst = max(fits, key=lambda f: f.position_error)
        click.echo(f"  printed poses fitted onto the closure: largest error {worst.position_error:.3g} {mech.length_unit},"
                   f" {np.degrees(max(f.angle_error for f in fits)):.3g} deg")
        return
    pose = resolve_pose(mech, xyz, euler, position)
    sol = None
    if free is not None:
        sol = solve_pose(mech, pose, free_names(free), euler=euler[0] if euler is not None else "ZYX")
        if not sol.converged:
            raise InputError(f"--free: the held coordinates do not close with {free} solved ({sol.status}, residual "
                             f"{sol.residual:.2e}); the pose is out of reach")
        pose = Pose(sol.D[:3, :3], sol.D[:3, :3] @ mech.platform_point + sol.D[:3, 3], "requested, solved")
    fit = configuration_at_pose(mech, pose, start=None if sol is None else sol.config)
    if not fit.converged:
        raise InputError(f"pose: no closed configuration near it (residual {fit.ik_residual:.2e})")
    J = complete_jacobian(mech, fit.config, list(drivers) or None)
    tj = task_jacobian_at(mech, fit.config, list(drivers) or None, task=None if sol is None else sol.task)
    if as_json:
        emit_json("jacobian", mech, {"result": "complete_jacobian", "pose": pose_dict(pose.R, pose.p), **J.to_dict(),
                                     "pose_fit": fit.to_dict(),
                                     "task_jacobian": None if tj is None else tj.to_dict(mech)})
        return
    click.echo(f"{mech.name}: complete Jacobian (rows: {J.constraint_rows} constraint, {len(J.actuators)} actuation"
               f" [{', '.join(J.actuators)}]); J $p = (0, qdot)")
    for row in J.matrix:
        click.echo("  [" + " ".join(f"{x:+.5e}" for x in row) + "]")
    if J.det is not None:
        click.echo(f"  det J = {J.det:+.6e}")
    click.echo(f"  scale-free sigma_min = {J.sigma_min:.4g}, 1/condition = {J.condition:.4g}")
    if J.sigma_min < current_tolerances().singular:
        click.echo(f"  SINGULAR configuration (sigma_min < {current_tolerances().singular:g}): det J is round-off; "
                   "`spatialmech singularity` gives its kind and the uncontrolled twist")
    if J.inverse_singular:
        click.echo(f"  inverse (serial) singular for: {', '.join(J.inverse_singular)}")
    if not fit.exact:
        click.echo(f"  note: the pose was fitted onto the closure (error {fit.position_error:.3g} {mech.length_unit}, "
                   f"{np.degrees(fit.angle_error):.3g} deg)")
    if tj is not None:
        _echo_task_jacobian(mech, tj)


def _echo_task_jacobian(mech: Mechanism, tj: TaskJacobian) -> None:
    """The input-output Jacobian over the given task coordinates, as text (angles in degrees)."""
    sol = tj.solution
    u = mech.length_unit
    vals = ", ".join(f"{n} = {sol.values[n]:.6g} {u}" if n in ("x", "y", "z") else f"{n} = {np.degrees(sol.values[n]):.6g} deg"
                     for n in tj.solved)
    click.echo(f"  input-output Jacobian over the task ({sol.task.euler}: given {', '.join(tj.given)}; solved "
               f"{', '.join(tj.solved)}, here {vals}):")
    click.echo("  d actuator / d given coordinate (actuator in [unit], per unit of the coordinate):")
    cols = [f"{n} (per {u})" if n in ("x", "y", "z") else f"{n} (per deg)" for n in tj.given]
    click.echo(" " * 20 + "".join(f"{c:>16s}" for c in cols))
    for a, row in zip(tj.actuators, tj.matrix, strict=True):
        slide = mech.freedom(a).freedom.kind == "P"
        cells = [(x if slide else np.degrees(x)) * (1.0 if n in ("x", "y", "z") else np.pi / 180.0)
                 for x, n in zip(row, tj.given, strict=True)]
        click.echo(f"  {a + (f' [{u}]' if slide else ' [deg]'):>18s}" + "".join(f"{c:+16.6e}" for c in cells))
