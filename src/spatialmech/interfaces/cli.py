"""The ``spatialmech`` command line (click).  Thin: parse, call an analysis, print text or JSON.

User errors (bad files, unknown names, impossible requests) print one line to stderr and exit
with code 2; nothing here computes.
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from .. import __version__, catalog
from ..analysis.mobility import mobility, mobility_modes
from ..model.schema import ModelFileError, dump
from .common import UserError, emit_json, json_option  # noqa: F401  (re-exported)


def _one_line_usage(e: click.UsageError) -> UserError:
    """A click usage error (bad option, missing argument, value out of range) as one line."""
    where = e.ctx.command_path if e.ctx is not None else "spatialmech"
    return UserError(f"{e.format_message()} (see '{where} --help')")


class _Group(click.Group):
    """Turns the library's input errors into one-line messages: exit code 2 for bad input (also
    click's usage errors and files that cannot be read or written), 1 for a failed computation."""

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
        except (ModelFileError, ValueError, KeyError) as e:
            msg = e.args[0] if isinstance(e, KeyError) and e.args else str(e)
            raise UserError(str(msg)) from None
        except BrokenPipeError:
            raise  # stdout closed early (``| head``): click exits quietly
        except OSError as e:
            name = e.filename if e.filename is not None else ""
            raise UserError(f"{name}: {e.strerror or e}" if name else str(e.strerror or e)) from None
        except RuntimeError as e:
            err = UserError(f"the computation failed: {e}")
            err.exit_code = 1
            raise err from None


def _model(spec: str):
    return catalog.resolve(spec)




@click.group(cls=_Group, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="spatialmech")
def cli():
    """Kinematic analysis and synthesis of spatial linkages and parallel mechanisms.

    MODEL arguments take a ready-made name (see `spatialmech models`) or a TOML file.

    \b
    Example:
      spatialmech mobility four-sps-cu
    """


@cli.command()
@json_option
def models(as_json):
    """List the ready-made models with a one-line description each.

    \b
    Example:
      spatialmech models --json
    """
    rows = [{"name": n, "description": catalog.describe(n)} for n in catalog.names()]
    if as_json:
        emit_json(rows)
        return
    w = max(len(r["name"]) for r in rows)
    for r in rows:
        click.echo(f"{r['name']:<{w}}  {r['description']}")


def _mobility_text(r) -> str:
    lines = [
        f"{r.mechanism}  mode {r.mode}" + (f"  (actuators: {', '.join(r.actuators)})" if r.actuators else ""),
        f"  {r.formula()}",
        f"  lambda = {r.lam} common constraints, d = {r.d}; t = {r.t}, k = {r.k}, v = t - k = {r.v};"
        f" xi = {r.xi} passive",
        f"  classic Grübler-Kutzbach (d = 6): {r.gk_classic}",
        f"  instantaneous mobility (closure-Jacobian rank, generic configuration): {r.dof_instantaneous}",
        f"  motion: {r.motion}  ({r.motion_class})",
    ]
    if r.constraint_wrenches:
        lines.append("  platform constraint wrenches (f ; m):")
        for w in r.constraint_wrenches:
            lines.append("    (" + " ".join(f"{x:+.4g}" for x in w[:3]) + " ; " + " ".join(f"{x:+.4g}" for x in w[3:]) + ")")
    lines.append(f"  {r.explanation}")
    return "\n".join(lines)


@cli.command(name="mobility")
@click.argument("model")
@click.option("--mode", default=None, help="Motion mode of a metamorphic mechanism (default: all modes).")
@json_option
def mobility_cmd(model, mode, as_json):
    """Mobility by the modified Kutzbach-Grübler formula, checked numerically.

    \b
    Examples:
      spatialmech mobility four-sps-cu
      spatialmech mobility three-rrr-sm --mode R1+R4 --json
      spatialmech mobility my-mechanism.toml
    """
    mech = _model(model)
    if mode is not None:
        results = [mobility(mech, mode)]
        single = True
    else:
        results = mobility_modes(mech)
        single = not mech.is_metamorphic
    if as_json:
        emit_json(results[0].to_dict() if single else [r.to_dict() for r in results])
        return
    click.echo("\n\n".join(_mobility_text(r) for r in results))


@cli.command()
@click.argument("model")
@click.argument("file", type=click.Path(dir_okay=False, writable=True, path_type=Path))
@json_option
def export(model, file, as_json):
    """Write a model (e.g. a ready-made one) as a TOML file to start your own from.

    \b
    Example:
      spatialmech export rssr my-rssr.toml
    """
    mech = _model(model)
    dump(mech, file)
    if as_json:
        emit_json({"model": mech.name, "out": str(file), "bytes": file.stat().st_size})
    else:
        click.echo(f"wrote {file}")


@cli.command()
@click.option("--out", "out", default="report", show_default=True, type=click.Path(file_okay=False, path_type=Path),
              help="Directory for index.html, results.json and figures/.")
@json_option
def demo(out, as_json):
    """Reproduce the four papers' examples into a report: DIR/index.html (self-contained, opens
    offline), DIR/results.json (every number) and DIR/figures/.  Each claim of a paper is a row:
    the paper's value, ours, reproduced or not and why.  Progress on stderr; about 45 s.

    \b
    Example:
      spatialmech demo --out report
    """
    from ..present.report import build_demo

    out.mkdir(parents=True, exist_ok=True)  # fail now on an unwritable --out, not after the work
    results = build_demo(out, progress=not as_json)
    if as_json:
        emit_json(results)
    else:
        s = results["summary"]
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
    from ..present.report import build_model_report

    mech = _model(model)
    out = out if out is not None else Path(f"report-{mech.name}")
    out.mkdir(parents=True, exist_ok=True)  # fail now on an unwritable --out, not after the work
    results = build_model_report(mech, out, progress=not as_json, trace=not no_trace)
    if as_json:
        emit_json(results)
    else:
        click.echo(f"report written to {out / 'index.html'} and {out / 'results.json'}")


from .cmd_kinematics import fk, ik, jacobian  # noqa: E402  (commands defined in their own modules)
from .cmd_synth import synth  # noqa: E402
from .cmd_view import view  # noqa: E402
from .cmd_defects import defects  # noqa: E402
from .cmd_workspace import workspace  # noqa: E402
from .cmd_singularity import singularity_cmd  # noqa: E402

for _cmd in (ik, fk, jacobian, synth, view, defects, workspace, singularity_cmd):
    cli.add_command(_cmd)


def main(argv=None):  # console-script entry point
    try:
        cli.main(args=argv, prog_name="spatialmech", standalone_mode=True)
    except SystemExit as e:
        if e.code not in (0, None):
            sys.exit(e.code)
