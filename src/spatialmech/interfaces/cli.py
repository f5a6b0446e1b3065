"""The ``spatialmech`` command line (click).  Thin: parse, call one function of the public API
(``sm.*``), print its result as text or its ``to_dict()`` as JSON.

User errors (bad files, unknown names, impossible requests) print one line to stderr and exit
with code 2 (1 when a computation did not converge); any other exception is a bug: exit code 3,
with its traceback under ``--debug`` or ``SPATIALMECH_DEBUG=1`` (:class:`_Group`).  Nothing here
computes.
"""

from __future__ import annotations

import os
import sys
import traceback
from pathlib import Path
from typing import ClassVar

import click

from .. import api as sm
from ..errors import ConvergenceError, InputError, MissingExtraError, SpatialmechError, require
from .common import (UserError, check_output_dir, check_output_file, emit_json, json_option, load_model, parse_numbers,
                     tol_option)


#: Commands that never take the first-run path (services/first_run.py): `models` computes
#: nothing; the others are long jobs that are faster compiled than on the Python engine.
FOREGROUND_COMMANDS = frozenset({"models", "demo", "report", "screen", "studio"})


def _one_line_usage(e: click.UsageError) -> UserError:
    """A click usage error (bad option, missing argument, value out of range) as one line."""
    where = e.ctx.command_path if e.ctx is not None else "spatialmech"
    return UserError(f"{e.format_message()} (see '{where} --help')")


#: Environment variable that turns on the tracebacks of internal errors (like ``--debug``).
DEBUG_ENV = "SPATIALMECH_DEBUG"


def _one_line(e: BaseException) -> str:
    return "; ".join(part.strip() for part in str(e).splitlines() if part.strip())


class _FailedComputation(UserError):
    """A computation that did not converge: one line, exit code 1."""

    exit_code = 1


def _user_error(e: BaseException) -> UserError | None:
    """The one-line error of a user error (exit 2; 1 for a computation that did not converge),
    or ``None`` when ``e`` is a programming error.  An optional dependency that is not installed
    is a user error that names the extra to install (exit 2)."""
    missing = MissingExtraError.from_import_error(e)
    if missing is not None:
        return UserError(_one_line(missing))
    if isinstance(e, ConvergenceError):
        return _FailedComputation(f"the computation failed: {_one_line(e)}")
    if isinstance(e, SpatialmechError):
        return UserError(_one_line(e))
    if isinstance(e, OSError):  # a path the user gave: cannot read, cannot write, no such directory
        name = e.filename if e.filename is not None else ""
        return UserError(f"{name}: {e.strerror or e}" if name else str(e.strerror or e))
    return None


class _Group(click.Group):
    """The command line's error policy (docs/index.md, "Errors"):

    - user errors -- the library's own exceptions (:class:`~spatialmech.errors.SpatialmechError`:
      bad input, malformed files, unknown names, searches too large), click's usage errors, and
      ``OSError`` on the paths the user gave -- print one line ``error: ...`` and exit with code 2
      (1 for a :class:`~spatialmech.errors.ConvergenceError`);
    - anything else (a plain ``ValueError``, ``KeyError``, ``IndexError``, ``TypeError`` ...) is a
      bug: one line ``error: internal error ...`` and exit code 3; with ``--debug`` or
      ``SPATIALMECH_DEBUG=1`` the full traceback is printed first.
    """

    #: Commands defined in their own modules, imported only when used or listed (``--help``):
    #: name -> (module under ``spatialmech.interfaces``, attribute).  A short command such as
    #: ``models`` does not pay for the others' imports (issue 29: start-up).
    LAZY: ClassVar[dict[str, tuple[str, str]]] = {
        "accuracy": ("cmd_accuracy", "accuracy_cmd"), "defects": ("cmd_defects", "defects"),
        "dynamics": ("cmd_dynamics", "dynamics_cmd"), "fk": ("cmd_kinematics", "fk"),
        "ik": ("cmd_kinematics", "ik"), "jacobian": ("cmd_kinematics", "jacobian"), "maps": ("cmd_maps", "maps_cmd"),
        "parasitic": ("cmd_parasitic", "parasitic_cmd"), "screen": ("cmd_screen", "screen"),
        "singularity": ("cmd_singularity", "singularity_cmd"), "statics": ("cmd_statics", "statics_cmd"),
        "stiffness": ("cmd_stiffness", "stiffness_cmd"), "studio": ("cmd_studio", "studio"),
        "synth": ("cmd_synth", "synth"), "validate": ("cmd_validate", "validate_cmd"), "view": ("cmd_view", "view"),
        "workspace": ("cmd_workspace", "workspace"),
    }

    def list_commands(self, ctx):
        return sorted(set(super().list_commands(ctx)) | set(self.LAZY))

    def get_command(self, ctx, cmd_name):
        if cmd_name in self.LAZY and cmd_name not in self.commands:
            import importlib

            module, attr = self.LAZY[cmd_name]
            cmd = getattr(importlib.import_module(f"{__package__}.{module}"), attr)
            if cmd.name != cmd_name:
                raise RuntimeError(f"the command in {module}.{attr} is named {cmd.name!r}, not {cmd_name!r}")
            self.add_command(cmd)
        return super().get_command(ctx, cmd_name)

    def make_context(self, info_name, args, parent=None, **extra):
        try:
            return super().make_context(info_name, args, parent=parent, **extra)
        except click.exceptions.NoArgsIsHelpError:
            raise
        except click.UsageError as e:
            raise _one_line_usage(e) from None

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except (click.exceptions.NoArgsIsHelpError, click.exceptions.Exit, click.exceptions.Abort):
            raise  # --help, --version, Ctrl-C: click's own (Exit and Abort are RuntimeErrors)
        except click.UsageError as e:
            raise _one_line_usage(e) from None
        except click.ClickException:
            raise  # already one line (UserError)
        except BrokenPipeError:
            raise  # stdout closed early (``| head``): click exits quietly
        except Exception as e:
            err = _user_error(e)
            if err is not None:
                raise err from None
            raise InternalError(e, traceback.format_exc() if _debug(ctx) else None) from None


def _debug(ctx: click.Context) -> bool:
    return bool(ctx.params.get("debug")) or os.environ.get(DEBUG_ENV, "").strip().lower() in ("1", "true", "yes", "on")


class InternalError(click.ClickException):
    """A programming error: one line (exit code 3) that says how to get the traceback, or the
    traceback and that line under ``--debug`` / ``SPATIALMECH_DEBUG=1``."""

    exit_code = 3

    def __init__(self, error: BaseException, trace: str | None):
        first = (str(error).splitlines() or [""])[0]
        super().__init__(f"internal error ({type(error).__name__}: {first[:200]}); this is a bug in spatialmech, "
                         "please report it with the command line"
                         + ("" if trace else f"; run with --debug or {DEBUG_ENV}=1 for the traceback"))
        self.error, self.trace = error, trace

    def show(self, file=None):
        if self.trace:
            click.echo(self.trace.rstrip("\n"), err=True, file=file)
        click.echo(f"error: {self.format_message()}", err=True, file=file)




@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="spatialmech", prog_name="spatialmech")  # read on --version only
@click.option("--debug", is_flag=True,
              help=f"On a bug (exit code 3) print its traceback, as {DEBUG_ENV}=1 does.")
def cli(debug):
    """Kinematic analysis and synthesis of spatial linkages and parallel mechanisms.

    MODEL arguments take a ready-made name (see `spatialmech models`) or a TOML file.  Exit
    codes: 0 done, 2 bad input, 1 a computation that did not converge, 3 a bug (--debug shows
    its traceback); the reason is one line on stderr.

    \b
    Example:
      spatialmech mobility four-sps-cu
    """
    # A fresh install: compile the kernels in the background and answer this command on the
    # pure-Python engine (one line on stderr says so); `models` computes nothing.  The long jobs
    # (the papers' report, a model's report, screening, the studio) compile in the foreground as
    # before: on the Python engine, beside a compiling process, they would take longer.
    if click.get_current_context().invoked_subcommand not in FOREGROUND_COMMANDS and sm.first_run(sys.stderr):
        return
    if sys.stderr.isatty():  # a person waiting: say when a kernel compiles (first use only)
        sm.announce_compilation(sys.stderr)


@cli.command()
@json_option
def models(as_json):
    """List the ready-made models with a one-line description each.

    \b
    Example:
      spatialmech models --json
    """
    rows = [{"name": n, "description": d} for n, d in sm.models().items()]
    if as_json:
        emit_json("models", None, {"models": rows})
        return
    w = max(len(r["name"]) for r in rows)
    for r in rows:
        click.echo(f"{r['name']:<{w}}  {r['description']}")


def _mobility_text(r) -> str:
    lines = [
        f"{r.mechanism}  mode {r.mode}" + (f"  (actuators: {', '.join(r.actuators)})" if r.actuators else ""),
        f"  {r.formula()}",
        f"  links n = {r.n}, joints g = {r.g}, independent loops = {r.loops}",
        f"  lambda = {r.lam} common constraints, d = {r.d}; t = {r.t}, k = {r.k}, v = t - k = {r.v};"
        f" xi = {r.xi} passive"
        + ("  (t, k: closure equations of the loops)" if r.counted_by == "loops" else ""),
        f"  classic Grübler-Kutzbach (d = 6): {r.gk_classic}",
        f"  instantaneous mobility (closure-Jacobian rank, generic configuration): {r.dof_instantaneous}",
        f"  motion: {r.motion}  ({r.motion_class})",
    ]
    if r.screw_axes:  # the free twists' principal screws; a 1-DOF output's instantaneous screw
        lines.append("  instantaneous screw:" if len(r.screw_axes) == 1 and r.screw_axes[0].multiplicity == 1
                     else "  principal screws of the free twists:")
        lines += [f"    {a.describe()}" for a in r.screw_axes]
    if r.constraint_wrenches:
        lines.append("  platform constraint wrenches (f ; m):")
        for w in r.constraint_wrenches:
            lines.append("    (" + " ".join(f"{x:+.4g}" for x in w[:3]) + " ; " + " ".join(f"{x:+.4g}" for x in w[3:]) + ")")
    if r.singular_note:  # the branches through a singular reference (docs/mobility.md)
        lines.append(f"  {r.singular_note}")
    lines.append(f"  {r.explanation}")
    if r.tolerance_note:
        lines.append(f"  {r.tolerance_note}")
    return "\n".join(lines)


@cli.command(name="mobility")
@click.argument("model")
@click.option("--mode", default=None, help="Motion mode of a metamorphic mechanism (default: all modes).")
@tol_option("rank")
@json_option
def mobility_cmd(model, mode, as_json):
    """Mobility by the modified Kutzbach-Grübler formula, checked numerically, and how the
    count depends on the rank tolerance (for models typed with rounded numbers).

    \b
    Examples:
      spatialmech mobility four-sps-cu
      spatialmech mobility three-rrr-sm --mode R1+R4 --json
      spatialmech mobility my-mechanism.toml --tol 1e-4
    """
    mech = load_model(model)
    results = sm.mobility_modes(mech, mode=mode)
    if as_json:  # one shape for every model: the list of modes (one for an ordinary mechanism)
        emit_json("mobility", mech, results.to_dict())
        return
    click.echo("\n\n".join(_mobility_text(r) for r in results))


@cli.command()
@click.argument("model")
@click.argument("file", type=click.Path(dir_okay=False, writable=True, path_type=Path))
@click.option("--format", "fmt", type=click.Choice(["toml", "mjcf", "urdf", "step", "stl", "glb"]), default=None,
              help="toml (the model file format), mjcf (MuJoCo), urdf, or CAD parts: step, stl, glb; default: from "
                   "FILE's extension (.toml, .xml, .urdf, .step, .stl, .glb).")
@click.option("--mode", default=None, help="Export a metamorphic mechanism in this motion mode (the other "
                                           "lockable freedoms locked).")
@click.option("--pose", "pose_text", default=None,
              help="CAD: place the links at this pose, X,Y,Z,SEQ,A1,A2,A3 (length, degrees).")
@click.option("--position", type=int, default=None, help="CAD: place the links at built-in task position N.")
@click.option("--actuators", "values", default=None,
              help="CAD: place the links at these actuator values (comma-separated, degrees / length).")
@click.option("--unit", type=click.Choice(["m", "mm"]), default=None,
              help="CAD: the files' length unit (default mm; GLB is always m).")
@click.option("--along", "along_text", default=None, metavar="V1,V2,...",
              help="CAD along a motion: the actuators moved in a straight line from the start (--pose, --position, "
                   "--actuators or the reference) to these values (deg / length, as statics --along); one assembly "
                   "per sample (FILE.000.step, ...), the link files once and FILE.placements.json.")
@click.option("--samples", type=click.IntRange(2, 1000), default=11, show_default=True,
              help="Samples with --along (both ends included).")
@json_option
def export(model, file, fmt, mode, pose_text, position, values, unit, along_text, samples, as_json):
    """Write a model (e.g. a ready-made one) as a TOML file to start your own from, as a
    MuJoCo model (MJCF) or URDF to carry it to a simulator (docs/validation.md), or as CAD
    parts: one solid per link, an assembly and one file per link (docs/cad.md).

    \b
    Examples:
      spatialmech export rssr my-rssr.toml
      spatialmech export four-sps-cu four-sps-cu.xml     # MJCF: python -m mujoco.viewer --mjcf=four-sps-cu.xml
      spatialmech export stewart-6sps stewart.urdf       # URDF, loop closures in an extension block
      spatialmech export rssr part.step --unit mm        # STEP assembly + part.LINK.step per link
      spatialmech export stewart-6sps part.stl --position 1   # part.mm.stl, part.LINK.mm.stl, part.mm.json
      spatialmech export rssr part.glb --actuators 0 --along 60 --samples 7   # part.000.glb ... part.006.glb
    """
    check_output_file(file, "FILE")
    _require_cad(file, fmt)  # before any work: the extra to install, exit 2
    mech = load_model(model)
    pose = None
    if pose_text is not None or position is not None:
        if pose_text is not None and position is not None:
            raise InputError("--pose/--position: give one of them")
        from .cmd_kinematics import parse_pose

        pose = position if pose_text is None else parse_pose(pose_text)
    acts = None if values is None else parse_numbers(values, "--actuators")
    along = None if along_text is None else parse_numbers(along_text, "--along", count=len(mech.actuators),
                                                            what="actuator values")
    r = sm.export(mech, file, format=fmt, mode=mode, pose=pose, actuators=acts, degrees=True, unit=unit, along=along,
                  samples=samples)
    if as_json:
        emit_json("export", r.mechanism, r.to_dict())
    elif r.placements is not None:
        click.echo(f"wrote {r.samples} assemblies {r.files[0].name} .. {r.files[r.samples - 1].name} ({r.format}, "
                   f"{r.unit}), the placements {r.placements.name} and {len(r.files) - r.samples - 1} more: "
                   f"{', '.join(f.name for f in r.files[r.samples:] if f != r.placements)}")
    elif r.unit is not None:
        click.echo(f"wrote {r.out} ({r.format}, {r.unit}) and {len(r.files) - 1} more: "
                   f"{', '.join(f.name for f in r.files[1:])}")
    else:
        click.echo(f"wrote {file} ({r.format})")


#: The packages of the ``cad`` extra that each CAD file extension needs.
_CAD_NEEDS = {"step": ("build123d",), "stp": ("build123d",), "stl": ("trimesh", "manifold3d"),
              "glb": ("trimesh", "manifold3d")}


def _require_cad(file: Path, fmt: str | None) -> None:
    """A CAD export (by --format or FILE's extension) needs the ``cad`` extra: say so first."""
    kind = fmt or file.suffix.lower().lstrip(".")
    if kind in _CAD_NEEDS:
        require("cad", *_CAD_NEEDS[kind], what=f"the {kind.upper()} export")


@cli.command()
@click.option("--out", "out", default="report", show_default=True, type=click.Path(file_okay=False, path_type=Path),
              help="Directory for index.html, results.json and figures/.")
@json_option
def demo(out, as_json):
    """Reproduce the four papers' examples into a report: DIR/index.html (self-contained, opens
    offline), DIR/results.json (every number) and DIR/figures/.  Each claim of a paper is a row:
    the paper's value, ours, reproduced or not and why.  Progress on stderr; about 12 s on two free
    cores (two worker processes), 20 s on one.

    \b
    Example:
      spatialmech demo --out report
    """
    require("plot", "matplotlib", "plotly", what="the report")
    require("sim", "mujoco", what="the papers' report (its MuJoCo validation tables)")
    check_output_dir(out, "--out")  # fail now on an unwritable --out, not after the work
    r = sm.demo(out, progress=not as_json)
    if as_json:
        emit_json("demo", None, r.to_dict())
    else:
        s = r.data["summary"]
        click.echo(f"report written to {out / 'index.html'} and {out / 'results.json'}: {s['claims']} claims, "
                   f"{s['reproduced']} reproduced, {s['reproduced after correction']} after correction, "
                   f"{s['not reproduced']} not reproduced")


@cli.command()
@click.argument("model")
@click.option("--out", "out", default=None, type=click.Path(file_okay=False, path_type=Path),
              help="Directory for index.html, results.json and figures/ (default: report-NAME).")
@click.option("--no-trace", is_flag=True, help="Skip the continuation trace of a one-degree-of-freedom motion.")
@json_option
def report(model, out, no_trace, as_json):
    """Every analysis that applies to one model, as a report like `demo`: mobility of every
    mode, the complete Jacobian, DJ at the task positions, the traced motion (1 DOF) and an
    interactive 3-D viewer.

    \b
    Examples:
      spatialmech report bennett --out bennett-report
      spatialmech report my-rssr.toml --json
    """
    require("plot", "matplotlib", "plotly", what="the report")
    check_output_dir(out, "--out")  # fail now on an unwritable --out, not after the work
    mech = load_model(model)
    out = out if out is not None else Path(f"report-{mech.name}")
    check_output_dir(out, "--out")
    r = sm.report(mech, out, trace=not no_trace, progress=not as_json)
    if as_json:
        emit_json("report", mech, r.to_dict())
    else:
        click.echo(f"report written to {out / 'index.html'} and {out / 'results.json'}")


def main(argv=None):  # console-script entry point
    from ..api.threads import blas_threads  # small matrices: one BLAS thread for the whole run (issue 29)

    try:
        with blas_threads():
            cli.main(args=argv, prog_name="spatialmech", standalone_mode=True)
    except SystemExit as e:
        if e.code not in (0, None):
            sys.exit(e.code)
