"""CLI commands of the position / Jacobian analyses: ``ik``, ``fk``, ``jacobian``.

Each parses its options, calls ONE function of the public API (``sm.ik``, ``sm.fk``,
``sm.jacobian``, ``sm.dj_table``: the engine is chosen there) and renders its result: the text
below, or the result's ``to_dict()`` in the JSON envelope.

Poses at the command line: ``--xyz X Y Z`` (the platform point, length unit of the model) and
``--euler SEQ A1 A2 A3`` (an explicitly named sequence, angles in degrees; upper case =
intrinsic); or ``--position N`` for a model's built-in task positions (numbered from 1).
Rotational actuator values are in degrees, slides in the model's length unit.
"""

from __future__ import annotations

import sys

from typing import TYPE_CHECKING

import click
import numpy as np

from .. import api as sm
from ..api import Mechanism, Pose, matrix_euler
from ..errors import InputError
from ..present.numbers import fmt_numbers
from .common import emit_json, json_option, parse_numbers, tol_option

if TYPE_CHECKING:
    from click._termui_impl import ProgressBar  # what click.progressbar returns

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


def pose_argument(mech: Mechanism, xyz, euler, position):
    """The pose options as the API's pose argument (angles in degrees): the task position number,
    or ``(xyz, (seq, a1, a2, a3))`` / ``(xyz, None)``; checked here to name the options."""
    if position is not None:
        if xyz is not None or euler is not None:
            raise InputError("--position: give either --position or --xyz/--euler, not both")
        if not mech.positions:
            raise InputError(f"--position: {mech.name} has no built-in task positions")
        if not 1 <= position <= len(mech.positions):
            raise InputError(f"--position: expected 1..{len(mech.positions)}, got {position}")
        return position
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
        return (p, None)
    seq, *ang = euler
    if not np.all(np.isfinite(ang)):
        raise InputError(f"--euler: expected finite angles (degrees), got {', '.join(f'{v:g}' for v in ang)}")
    return (p, (seq, *ang))


def resolve_pose(mech: Mechanism, xyz, euler, position) -> Pose:
    """The pose options as a :class:`Pose` (for the commands that take a pose object)."""
    arg = pose_argument(mech, xyz, euler, position)
    if isinstance(arg, int):
        return mech.positions[arg - 1]
    p, orient = arg
    if orient is None:
        return Pose(np.eye(3), p, "requested")
    return Pose.from_euler(orient[0], orient[1:], p, degrees=True, name="requested")


def current_tolerances() -> sm.Tolerances:
    """The tolerances in force (those ``--tol`` set)."""
    with sm.tolerances() as t:
        return t


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
@click.option("--method", "method", type=click.Choice(["auto", "homotopy", "multistart"]), default="auto",
              show_default=True,
              help="Method of --all: homotopy continuation per limb (proven complete by a root count or the trace "
                   "test), multistart (not proven), or auto (homotopy where a root count proves the limb).")
@click.option("--free", "free", default=None,
              help="Task coordinates to SOLVE (parasitic), comma-separated from x,y,z,a1,a2,a3 (a1..a3: the --euler "
                   "sequence's angles, default ZYX); the others are held at the pose's values. For lower-mobility "
                   "mechanisms, e.g. --free x,y,a1 for a 3-RPS.")
@click.option("--no-certify", "no_certify", is_flag=True,
              help="With --all: skip the certificates of the homotopy's solutions (Krawczyk test in ball arithmetic).")
@tol_option("reachability")
@json_option
def ik(model, xyz, euler, position, all_solutions, method, free, no_certify, as_json):
    """Inverse position: joint values of every limb for a platform pose.

    \b
    Examples:
      spatialmech ik three-rps --pose 0,0,0.33,ZYX,0,5,5 --free x,y,a1 --json
      spatialmech ik four-sps-cu --xyz 0 0 0.12 --euler ZYX 34.38 -5.73 11.46
      spatialmech ik four-sps-cu --pose 0,0,0.12,ZYX,34.38,-5.73,11.46 --json
      spatialmech ik five-cs-1 --position 3 --json
      spatialmech ik delta --xyz 0.02 0.01 -0.33 --all
      spatialmech ik my-arm.toml --xyz 0.4 0.1 0.3 --euler ZYX 10 20 30 --all --method homotopy
    """
    mech = sm.load_model(model)
    r = sm.ik(mech, pose_argument(mech, xyz, euler, position), all_solutions=all_solutions, degrees=True,
              free=None if free is None else free_names(free), method=method, certify=not no_certify)
    if as_json:
        emit_json("ik", mech, r.to_dict())
        return
    _ik_text(r)


def _completeness_lines(search: dict) -> dict[str, str]:
    """Per limb name, ``"homotopy: complete (proven ...): ..."`` or ``"multistart: NOT proven:
    ..."`` of an ``ik --all`` search (nothing without ``--all``)."""
    return {str(rep.get("limb")): f"{rep.get('method')}: {rep.get('completeness', '')}"
            for rep in search.get("limbs") or ()}


def _ik_headline(r: sm.IKResult) -> str:
    """``reachable``; ``NOT reachable`` only where proven (a complete search found nothing, or the
    nearest closed configuration is beyond the tolerance); else ``not found from the reference``
    with why: the task solve's status and how far the continuation from the reference pose got."""
    res, fit = r.result, r.pose_fit
    if r.reachable:
        return "reachable"
    if r.task is not None and not r.task.converged:
        s = r.task.continuation
        cont = f"; continuation from the reference pose failed at s={s:.3g}" if s is not None else ""
        limbs = " (the limbs close at the pose asked for, but not with the given coordinates held)" if res.reachable \
            else ""
        return (f"not found from the reference (the task solve of {', '.join(r.task.solved)} did not converge: "
                f"{r.task.status}{cont}){limbs}")
    if r.proven_unreachable:
        return "NOT reachable (proven: every limb's search is complete)"
    if fit is not None and fit.converged:
        return "NOT reachable within the tolerance (see the note)"
    return "not found from the reference (a Newton solve per limb; --all searches every solution)"


def _warning_lines(warnings) -> None:
    """``warning: ...`` lines of a result's plausibility warnings."""
    for w in warnings:
        click.echo(f"warning: {w}")


def _ik_text(r: sm.IKResult) -> None:
    # A pose that does not close exactly (printed, rounded data: a task position, a pose printed
    # by fk) is fitted onto the closure: reachable when the nearest closed configuration is
    # within the reachability tolerance, and either way the distance is said, never hidden.
    mech, res, fit, reach_tol = r.mechanism, r.result, r.pose_fit, r.reachability
    d = r.to_dict()
    order = {f.id: i for i, f in enumerate(mech.freedom_refs)}
    searched = _completeness_lines(d.get("search") or {})
    certified = {str(rep.get("limb")): rep["certification"] for rep in (d.get("search") or {}).get("limbs") or ()
                 if rep.get("certification") is not None}
    fitted = (f" (fitted onto the closure: off by {fit.position_error:.3g} {mech.length_unit} and "
              f"{np.degrees(fit.angle_error):.3g} deg, within the tolerance {reach_tol:g})"
              ) if res.fitted and fit is not None else ""  # fitted: the pose has a fit
    click.echo(f"{mech.name}: pose {_ik_headline(r)}{fitted if r.reachable else ''}")
    if r.task is not None:
        t = d["task"]
        vals = {**t["values_len"], **t["values_deg"]}
        unit = {n: (mech.length_unit if n in t["values_len"] else "deg") for n in vals}
        click.echo(f"  task coordinates ({t['euler']}): given {', '.join(f'{n} = {vals[n]:.6g} {unit[n]}' for n in t['given'])}")
        click.echo(f"  solved{'' if r.task.converged else ' (NOT converged: ' + t['status'] + ')'}: "
                   + ", ".join(f"{n} = {vals[n]:.6g} {unit[n]}" for n in t["solved"]))
    for limb in d["limbs"]:
        extra = f", solution set of dimension {limb['passive_dim']} (passive freedoms)" if limb["passive_dim"] else ""
        click.echo(f"  {limb['limb']}: {len(limb['solutions'])} solution(s){extra}"
                   + ("" if limb["reachable"] else " [least-squares, not closed]"))
        how = searched.get(limb["limb"])
        if how is not None:
            click.echo(f"    {how}")
        cert = certified.get(limb["limb"])
        if cert is not None:
            click.echo(f"    certificates: {cert}")
        for k, sol in enumerate(limb["solutions"]):
            values = sorted({**sol["joints_deg"], **sol["joints_len"]}.items(), key=lambda kv: order[kv[0]])
            shown = ", ".join(f"{fid}={v:.6g}" for fid, v in values)
            lim = f"  outside limits: {', '.join(sol['outside_limits'])}" if sol["outside_limits"] else ""
            cert = {True: ", certified", False: ", NOT certified"}.get(sol.get("certified"), "")
            click.echo(f"    [{k + 1}] {shown}  (residual {sol['residual']:.1e}{cert}){lim}")
    if r.config is not None:
        head = "  actuators: " if r.reachable else "  actuators (of the limbs' solutions, not of the pose asked for): "
        click.echo(head + ", ".join(f"{k} = {_fmt_value(mech, k, v)}" for k, v in r.actuators.items()))
    click.echo("  (rotations in degrees, slides in " + mech.length_unit + ")")
    _warning_lines(d["warnings"])
    if r.task is None and not res.reachable:
        dt = r.default_task
        if len(dt.given) < 6:
            click.echo(f"  note: {mech.name}'s output link has {len(dt.given)} freedoms: a full pose is reachable only with its "
                       f"parasitic coordinates solved; try --free {','.join(dt.solved)} (gives {', '.join(dt.given)})")
    if fit is not None and fit.converged and not res.reachable:
        what = f"task position {r.position} is printed (rounded) data; " if r.position is not None else ""
        click.echo(f"  note: {what}the nearest closed configuration is {fit.position_error:.3g} {mech.length_unit} and "
                   f"{np.degrees(fit.angle_error):.3g} deg from it (pose error {fit.error:.2g}, beyond the reachability "
                   f"tolerance {reach_tol:g}; `--tol` sets it; `spatialmech jacobian` uses that configuration)")


@click.command()
@click.argument("model")
@click.option("--actuators", "values", required=True,
              help="Comma-separated actuator values in mechanism order (degrees / length).")
@click.option("--all", "all_solutions", is_flag=True,
              help="All real assembly modes: a closed form where one recognises the model (the 4-SPS/CU of paper B, "
                   "a spherical 3-RRR wrist, a 5-CS linkage, a single loop of 4 to 7 R joints), else homotopy "
                   "continuation (proven complete) where it covers the model, else multi-start.")
@click.option("--method", type=click.Choice(["auto", "closed-form", "homotopy", "multistart"]), default="auto",
              show_default=True,
              help="Method of --all (closed-form: the registered closed forms of --all; homotopy: proven complete for "
                   "S-P-S and R-P-S legs, "
                   "passive C-U limbs, ...; by monodromy, proven when its trace test passes, for other limbs of R, P, C, U, S "
                   "joints; "
                   "multistart: the general multi-start search on any model; see docs/homotopy.md).")
@click.option("--seeds", type=click.IntRange(min=1, max=MAX_SEEDS), default=None,
              help=f"Number of starts of a multi-start search with --all (default: 200; 512 on the 4-SPS/CU closed "
                   f"form; at most {MAX_SEEDS}); refused where homotopy continuation answers.")
@click.option("--no-certify", "no_certify", is_flag=True,
              help="With --all: skip the certificates of the solutions (Krawczyk test in ball arithmetic; homotopy, "
                   "closed forms, loop formulation).")
@tol_option("newton")
@json_option
def fk(model, values, all_solutions, method, seeds, no_certify, as_json):
    """Forward position: platform pose(s) for actuator values.

    \b
    Examples:
      spatialmech fk stewart-6sps --actuators 1.2,1.2,1.2,1.2,1.2,1.2
      spatialmech fk four-sps-cu --actuators 0.216745,0.23896,0.227321,0.206933 --all --json
      spatialmech fk stewart-6sps --actuators 1.2,1.2,1.2,1.2,1.2,1.2 --all
    """
    mech = sm.load_model(model)
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
    with _progress_bar(enabled=all_solutions and not as_json) as progress:
        r = sm.fk(mech, raw, all_solutions=all_solutions, method=method, seeds=seeds, degrees=True, progress=progress,
                  certify=not no_certify)
    if as_json:
        emit_json("fk", mech, r.to_dict())
        return
    _fk_text(r)
    _warning_lines(r.warnings)


class _progress_bar:
    """A progress callback for ``sm.fk`` that opens a bar on stderr at its first call (only the
    engines that report progress call it), and closes it on exit."""

    def __init__(self, enabled: bool):
        self.enabled = enabled
        self.bar: ProgressBar[int] | None = None

    def __enter__(self):
        return self if self.enabled else None

    def __call__(self, done, total, message) -> None:
        if self.bar is None:
            self.bar = click.progressbar(length=total, label=message, file=sys.stderr)
            self.bar.__enter__()
        self.bar.update(1)

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.__exit__(*exc)
        return False


def _fk_text(r: sm.FKResult) -> None:
    """``fk`` as text: the header (what was found, by which engine), completeness, every mode."""
    mech, a = r.mechanism, r.answer
    modes = a.modes
    n_ii = a.n_input_independent
    ii = (f", {n_ii} input-independent (the actuators move without moving the platform)" if n_ii else "")
    limited = any(f.freedom.limits is not None for f in mech.freedom_refs)
    if a.endpoints is not None:  # homotopy continuation: counts of the path end points
        e = a.endpoints
        n_sm = sum(m.kind == "self-motion" and not m.input_independent for m in modes)
        n_real = len(modes) - n_ii
        click.echo(f"{mech.name}: {n_real} real assembly mode{'s' if n_real != 1 else ''}"
                   + (f" ({n_sm} of them self-motion sets)" if n_sm else "") + ii
                   + f"; end points: {e.n_real} real, {e.n_complex} complex, {e.n_singular} singular, "
                   f"{e.n_at_infinity} at infinity, of {e.n_generic} "
                   + ("paths (the closed form's root bound)" if a.engine == "closed-form" else "generic solutions")
                   + (f" ({e.n_spurious} spurious end points of the square system discarded)" if e.n_spurious is not None
                      else "")
                   + f" ({a.label}, {e.elapsed_s:.2f} s)")
        how = a.completeness
        if a.complete and how.startswith("complete (trace test): "):  # say "complete" once
            how = "by the trace test: " + how[len("complete (trace test): "):]
        click.echo(("  complete (proven): " if a.complete else "  NOT proven complete: ") + how)
        search = getattr(a.detail, "search", None)
        cert = search.get("certification") if isinstance(search, dict) else None
        if cert is not None:
            click.echo(f"  certificates: {cert}")
    else:
        if not modes:
            _fk_none_found(mech, a)
            return
        click.echo(_fk_header(mech, [m.kind for m in modes if not m.input_independent], a.label, a.n_starts,
                              a.n_converged, n_ii)
                   + ("" if not a.all_solutions else f"; {a.n_within_limits} within limits" if limited
                      else "; no joint limits in the model"))
        if a.all_solutions:
            click.echo(("  complete: " if a.complete else "  NOT proven complete: ") + a.completeness)
    for k, m in enumerate(modes):
        ang = matrix_euler("ZYX", m.pose.R, degrees=True)
        lim = ("outside limits: " + ", ".join(m.outside_limits) if not m.within_limits
               else "within limits" if limited else "no joint limits in the model")
        click.echo(f"  [{k + 1}] platform point ({_num(m.pose.p, '.6g')}) {mech.length_unit}, "
                   f"ZYX angles ({_num(ang, '.4f')}) deg  {lim}")
        _fk_conditioning_lines(m.kind, m.sigma_min, m.condition, m.singular_below, m.members, m.self_motion,
                               mech.length_unit, m.free_dim)
        _fk_flag_lines(m)


def _fk_none_found(mech: Mechanism, a) -> None:
    """``fk`` as text when no mode converged (other than the homotopy's): a proven empty set
    (the 4-SPS/CU's closed form checked by the homotopy) is an answer, else an ``InputError``."""
    if a.all_solutions and a.complete:
        click.echo(f"{mech.name}: 0 real assembly modes ({a.label})")
        click.echo("  complete (proven): " + a.completeness)
        return
    if a.all_solutions:
        raise InputError(f"actuators: no assembly found among {a.n_starts} starts ({a.n_converged} converged); "
                         "not a proof that none exists: check the values against the limits and the "
                         "mechanism's size, or try more --seeds")
    raise InputError(f"actuators: no assembly found (Newton did not converge; residual {a.failed_residual:.2e}); "
                     "try --all")


def _fk_flag_lines(m) -> None:
    """The flags of one forward-position result beside its conditioning (forward singular is
    the conditioning line above): input-independent, inverse singular, the homotopy end point."""
    f = m.flags
    if f is None:
        return
    yn = {True: "yes", False: "no"}
    click.echo(f"      flags: forward singular {yn[m.forward_singular]}, inverse singular {yn[f.inverse_singular]}, "
               f"input-independent {yn[f.input_independent]}"
               + (f", certified {yn[f.certified]}" if f.certified is not None else "")
               + (f"; from a {f.endpoint} end point of the homotopy" if f.endpoint is not None else ""))
    for w in f.words():
        click.echo(f"      {w}")


def _fk_header(mech: Mechanism, kinds, method: str, seeds: int, converged: int, n_input_independent: int = 0) -> str:
    """``NAME: 2 assembly modes, 1 self-motion set, 4 input-independent (...) (method, N starts,
    M converged)``; ``kinds`` those of the input-dependent results."""
    n_reg = sum(k == "regular" for k in kinds)
    n_sing = sum(k == "singular" for k in kinds)
    n_sm = sum(k == "self-motion" for k in kinds)
    parts = [f"{n_reg} assembly mode{'s' if n_reg != 1 else ''}"]
    if n_sing:
        parts.append(f"{n_sing} singular root{'s' if n_sing != 1 else ''}")
    if n_sm:
        parts.append(f"{n_sm} self-motion set{'s' if n_sm != 1 else ''} (a continuum of poses with the actuators held)")
    if n_input_independent:
        parts.append(f"{n_input_independent} input-independent (the actuators move without moving the platform)")
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
    mech = sm.load_model(model)
    if dj_table and free is not None:
        raise InputError("--free: not with --dj-table (the DJ table is at the built-in task positions)")
    if dj_table:
        if not mech.positions:
            raise InputError(f"--dj-table: {mech.name} has no built-in task positions")
        t = sm.dj_table(mech, list(drivers) or None)
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
    jr = sm.jacobian(mech, pose_argument(mech, xyz, euler, position), drivers=list(drivers) or None, degrees=True,
                     free=None if free is None else free_names(free))
    if as_json:
        emit_json("jacobian", mech, jr.to_dict())
        return
    J, fit = jr.jacobian, jr.pose_fit
    click.echo(f"{mech.name}: complete Jacobian (rows: {J.constraint_rows} constraint, {len(J.actuators)} actuation"
               f" [{', '.join(J.actuators)}]); J $p = (0, qdot)")
    big = float(np.max(np.abs(J.matrix))) if np.size(J.matrix) else 1.0
    for row in J.matrix:  # round-off against the matrix's largest entry prints as 0
        click.echo("  [" + fmt_numbers(row, "+.5e", scale=big) + "]")
    if J.det is not None:
        click.echo(f"  det J = {J.det:+.6e}")
    click.echo(f"  scale-free sigma_min = {J.sigma_min:.4g}, 1/condition = {J.condition:.4g}")
    if J.sigma_min < current_tolerances().singular:
        click.echo(f"  SINGULAR configuration (sigma_min < {current_tolerances().singular:g}): det J is round-off; "
                   "`spatialmech singularity` gives its kind and the uncontrolled twist")
    if J.inverse_singular:
        click.echo(f"  inverse (serial) singular for: {', '.join(J.inverse_singular)}")
    if fit is not None and not fit.exact:
        click.echo(f"  note: the pose was fitted onto the closure (error {fit.position_error:.3g} {mech.length_unit}, "
                   f"{np.degrees(fit.angle_error):.3g} deg)")
    if jr.task is not None:
        _echo_task_jacobian(jr)


def _echo_task_jacobian(jr: sm.JacobianResult) -> None:
    """The input-output Jacobian over the given task coordinates (``jr.task``), as text (angles
    in degrees)."""
    mech, tj = jr.mechanism, jr.task
    assert tj is not None
    sol = tj.solution
    u = mech.length_unit
    vals = ", ".join(f"{n} = {sol.values[n]:.6g} {u}" if n in ("x", "y", "z") else f"{n} = {np.degrees(sol.values[n]):.6g} deg"
                     for n in tj.solved)
    click.echo(f"  input-output Jacobian over the task ({sol.task.euler}: given {', '.join(tj.given)}; solved "
               f"{', '.join(tj.solved)}, here {vals}):")
    click.echo("  d actuator / d given coordinate (each actuator in the unit after its name, per unit of the coordinate):")
    cols = [f"{n} (per {u})" if n in ("x", "y", "z") else f"{n} (per deg)" for n in tj.given]
    click.echo(" " * 20 + "".join(f"{c:>16s}" for c in cols))
    for a, row in zip(tj.actuators, tj.matrix, strict=True):
        slide = mech.freedom(a).freedom.kind == "P"
        cells = [(x if slide else np.degrees(x)) * (1.0 if n in ("x", "y", "z") else np.pi / 180.0)
                 for x, n in zip(row, tj.given, strict=True)]
        click.echo(f"  {a + (f' [{u}]' if slide else ' [deg]'):>18s}" + fmt_numbers(cells, "+16.6e", sep=""))
