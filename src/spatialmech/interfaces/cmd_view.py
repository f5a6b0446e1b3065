"""``spatialmech view``: write the interactive 3-D viewer page of a model.

Thin: check the output path, load the model, let ``sm.view`` compute the motion and write the
page (:mod:`spatialmech.present.viewer`).  Register it in the main group with
``cli.add_command(view)``.
"""

from __future__ import annotations

from pathlib import Path

import click

from .. import api as sm
from ..errors import ConvergenceError, InputError, require
from .common import UserError, check_output_file, emit_json, load_model, tol_option

#: Largest number of frames (each is a configuration drawn into the page).
MAX_FRAMES = 2000

__all__ = ["MOTIONS", "view"]

#: Motions the command can compute (``sm.view``).  "trace": the whole circuit of a
#: one-degree-of-freedom mechanism through its reference configuration, followed by the
#: continuation tracker, with the zeros of DJ (branch points of the first actuator) marked as
#: singular points; "demo": a short loop along the closure manifold (any mobility); "auto":
#: trace when the mechanism has one degree of freedom, else demo.
MOTIONS = sm.VIEW_MOTIONS


class _Failed(UserError):
    """A computation of the motion that did not converge: one line ``error: ...``, exit code 1
    (bad input: :class:`~.common.UserError`, exit code 2)."""

    exit_code = 1


@click.command(name="view")
@click.argument("model")
@click.option("--motion", type=click.Choice(MOTIONS), default="auto", show_default=True,
              help="Motion to animate: trace (1 DOF: the whole circuit by continuation, singular points marked), "
                   "demo (a short loop along the closure manifold, any mobility), auto (trace if 1 DOF).")
@click.option("--out", "out", required=True, type=click.Path(dir_okay=False, path_type=Path),
              help="The HTML file to write (self-contained: plotly.js is inlined, it opens offline).")
@click.option("--frames", type=click.IntRange(min=2, max=MAX_FRAMES), default=60, show_default=True,
              help=f"Number of configurations (animation frames, at most {MAX_FRAMES}).")
@click.option("--plotly", "plotly", type=click.Choice(["inline", "cdn", "directory"]), default="inline", show_default=True,
              help="How the page gets plotly.js: inline (self-contained, ~4.8 MB, offline), cdn (small, needs the "
                   "network), directory (small; plotly.min.js written once next to the page, offline).")
@tol_option("rank")
@click.option("--json", "as_json", is_flag=True,
              help="Print what was written (out, frames, bytes, plotly, motion, note) as JSON (docs/json.md).")
def view(model, motion, out, frames, plotly, as_json):
    """Write an interactive 3-D viewer of MODEL (base, platform, limbs, joint axes, task
    positions) animated along a motion, with a slider and play / pause buttons.

    \b
    Examples:
      spatialmech view four-sps-cu --out four-sps-cu.html
      spatialmech view five-cs-1 --frames 120 --out five-cs-1.html --json
      spatialmech view bennett --motion trace --out bennett.html
      spatialmech view rssr --out pages/rssr.html --plotly directory
      spatialmech view my-rounded-linkage.toml --tol 1e-4 --out linkage.html
    """
    require("plot", "plotly", what="the viewer")  # before any work: the extra to install, exit 2
    try:
        check_output_file(out, "--out")
        mech = load_model(model)
    except InputError as e:  # anything else is a bug: the main group shows it as one (exit 3)
        raise UserError(str(e)) from None
    try:
        written = sm.view(mech, out, motion=motion, frames=frames, plotly=plotly)
    except OSError as e:
        raise UserError(f"--out: cannot write {out}: {e.strerror or e}") from None
    except InputError as e:
        raise UserError(str(e)) from None
    except ConvergenceError as e:
        raise _Failed(str(e)) from None
    if as_json:
        emit_json("view", mech, written.to_dict())
    else:
        click.echo(f"wrote {written.out} ({written.frames} frames, {written.bytes} bytes)")
        if written.note:
            click.echo(f"note: {written.note}")
