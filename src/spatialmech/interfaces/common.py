"""Helpers shared by the command modules: loading the MODEL argument, one-line user errors, JSON
output, the --json flag, checks of output paths (before the work starts), parsing of
comma-separated numbers and the --tol option.

The command modules are drivers: they parse, call one function of the public API
(``spatialmech.api``, imported as ``sm``) and render its result; they import nothing below it
(tests/test_layering.py)."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

import click

from .. import api as sm
from ..errors import InputError, require
from ..serialize import envelope, json_default


def load_model(spec):
    """The mechanism of a MODEL argument (a ready-made name or a TOML file): an unknown name is
    reported by its value, ``NAME: not a file and not a ready-made model (...)``."""
    return sm.load_model(spec, name=None)


class UserError(click.ClickException):
    """One-line error, exit code 2."""

    exit_code = 2

    def show(self, file=None):
        click.echo(f"error: {self.format_message()}", err=True, file=file)


def emit_json(command: str, model, payload, *, length_unit: str | None = None) -> None:
    """Print one command's JSON document: the envelope (``schema_version``, ``command``,
    ``model``, ``length_unit``; :func:`..serialize.envelope`) around ``payload``.

    ``model`` is a mechanism (its name and length unit are used), a model name, or ``None``
    where no model applies; ``length_unit`` overrides the mechanism's (e.g. a task's unit).
    The rule of the fields (units in the key names) is docs/json.md.
    """
    name = getattr(model, "name", model)
    unit = length_unit if length_unit is not None else getattr(model, "length_unit", None)
    doc = envelope(command, name, payload, length_unit=unit)
    click.echo(json.dumps(doc, indent=2, default=json_default, allow_nan=False))


json_option = click.option("--json", "as_json", is_flag=True, help="Print machine-readable JSON (docs/json.md).")


def schema_file_name(command: str) -> str:
    """``"synth rccc"`` -> ``"synth-rccc.schema.json"``: the JSON Schema of a command's ``--json``
    output, shipped in ``spatialmech/interfaces/schemas/`` (``common.schema.json`` holds the
    shared definitions that the others ``$ref``)."""
    return f"{command.replace(' ', '-')}.schema.json"


def load_schema(command: str) -> dict:
    """The JSON Schema (a dict) of ``command``'s ``--json`` output, or of ``"common"``."""
    from importlib.resources import files

    path = files("spatialmech.interfaces").joinpath("schemas", schema_file_name(command))
    if not path.is_file():
        raise InputError(f"command: no JSON schema for {command!r}")
    return json.loads(path.read_text(encoding="utf-8"))


# ------------------------------------------------------------------ output paths
def _writable(d: Path) -> bool:
    return os.access(d, os.W_OK | os.X_OK)


def _require_plot(option: str, html: bool) -> None:
    """``--plot`` needs the ``plot`` extra (Matplotlib; plotly for ``.html``): say so before any
    work (:class:`~spatialmech.errors.MissingExtraError`, exit 2)."""
    if option == "--plot":
        require("plot", "plotly" if html else "matplotlib", what="--plot")


def check_output_file(path, option: str, *, suffixes: tuple[str, ...] | None = None) -> Path | None:
    """Check a file the command will write (``--plot``, ``--out``, ``--save``) before any work:
    not a directory, its directory exists and is writable, an existing file is writable, and
    (``suffixes``) a known extension.  ``None`` passes through.  Raises :class:`InputError`
    naming the option."""
    if path is None:
        return None
    p = Path(path)
    _require_plot(option, p.suffix.lower() == ".html")
    if p.is_dir():
        raise InputError(f"{option}: {p} is a directory; give a file name")
    if suffixes is not None and p.suffix.lower() not in suffixes:
        raise InputError(f"{option}: {p}: expected a file name ending in {', '.join(suffixes)}")
    parent = p.parent
    if not parent.exists():
        raise InputError(f"{option}: cannot write {p}: {parent}: No such file or directory (create the directory first)")
    if not parent.is_dir():
        raise InputError(f"{option}: cannot write {p}: {parent} is not a directory")
    if p.exists() and not os.access(p, os.W_OK):
        raise InputError(f"{option}: cannot write {p}: the file is not writable")
    if not p.exists() and not _writable(parent):
        raise InputError(f"{option}: cannot write {p}: the directory {parent} is not writable")
    return p


def check_output_dir(path, option: str) -> Path | None:
    """Check a directory the command will write into (created if missing) before any work: not
    an existing file, and it or its nearest existing ancestor is a writable directory.  ``None``
    passes through.  Raises :class:`InputError` naming the option."""
    if path is None:
        return None
    p = Path(path)
    _require_plot(option, False)
    if p.exists() and not p.is_dir():
        raise InputError(f"{option}: {p} is a file, not a directory")
    base = p
    while not base.exists() and base != base.parent:
        base = base.parent
    if not base.is_dir():
        raise InputError(f"{option}: cannot create the directory {p}: {base} is not a directory")
    if not _writable(base):
        raise InputError(f"{option}: cannot write into {p}: {base} is not writable")
    return p


# ------------------------------------------------------------------ numbers at the command line
def parse_number(text: str, option: str, what: str) -> float:
    """One finite number typed at the command line; ``what`` (e.g. ``"z"``, ``"item 2"``) and
    ``option`` name it in the error: ``--at: z expects a number, got 'abc'``,
    ``--actuators: item 2 must be finite, got 'nan'``."""
    try:
        v = float(text)
    except ValueError:
        raise InputError(f"{option}: {what} expects a number, got {text!r}") from None
    if not math.isfinite(v):
        raise InputError(f"{option}: {what} must be finite, got {text!r}")
    return v


def parse_numbers(text: str, option: str, *, count: int | None = None, what: str = "values") -> list[float]:
    """``"0.2,0.25,0.2"`` -> ``[0.2, 0.25, 0.2]``: every item a finite number (an empty item,
    as in ``0.2,,0.2``, is an error naming the option and the position, not skipped);
    ``count`` checks the number of items."""
    parts = [x.strip() for x in str(text).split(",")]
    out = []
    for k, part in enumerate(parts, start=1):
        if not part:
            raise InputError(f"{option}: item {k} of {len(parts)} is empty in {text!r}")
        out.append(parse_number(part, option, f"item {k}"))
    if count is not None and len(out) != count:
        raise InputError(f"{option}: expected {count} {what}, got {len(out)}")
    return out


#: Largest ``--seed`` (a random generator's seed: a non-negative integer, stored as a 64-bit one).
SEED_MAX = 2**63 - 1


# ------------------------------------------------------------------ tolerances
_TOL_MEANING = {
    "rank": "relative singular-value threshold of the rank decisions",
    "reachability": "largest pose error (rad, and length / characteristic length) that is fitted instead of refused",
    "newton": "residual at which Newton stops and an assembly counts as converged",
    "singular": "scale-free sigma_min below which a configuration is singular",
}


def tol_option(primary: str):
    """``--tol``: run the command with other tolerances (geometry/tolerances.py).  A number sets
    ``primary`` (the tolerance the command decides on); ``NAME=VALUE[,NAME=VALUE]`` sets named
    ones (rank, singular, newton, closure, reachability, dedup, pivot, contains, unit).  The
    command body runs inside :func:`spatialmech.tolerances`."""
    import functools

    def deco(f):
        @functools.wraps(f)
        def wrapper(*args, tol_text=None, **kw):
            if tol_text is None:
                return f(*args, **kw)
            with sm.tolerances(tol_text, primary=primary):
                return f(*args, **kw)

        return click.option(
            "--tol", "tol_text", default=None, metavar="TOL",
            help=f"Tolerance: a number sets '{primary}' ({_TOL_MEANING.get(primary, primary)}; default "
                 f"{sm.default_tolerance(primary):g}); or NAME=VALUE,... for others (docs/conventions.md, Tolerances).",
        )(wrapper)

    return deco


class StderrProgress:
    """A progress callback (``progress(done, total, message)``) for long commands, on stderr.

    On a terminal one line is redrawn in place; otherwise (a log, a pipe) a line is printed when
    the phase (``message``) changes and then at most every :attr:`every_s` seconds, each with
    the count, the percentage of ``total`` when known, the elapsed time and the rate:
    ``solving task coordinates: 1024/1681 (61 %), 12.3 s, 83 per s``.  ``close()`` prints the
    last count of the run.
    """

    #: Seconds between two lines off a terminal (one per phase change in any case).
    every_s = 5.0

    def __init__(self, label: str = "", file=None):
        import sys
        import time

        self.file = file if file is not None else sys.stderr
        self.label = label
        self.tty = bool(getattr(self.file, "isatty", lambda: False)())
        self.clock = time.perf_counter
        self.t0 = self.clock()
        self.last_line = -math.inf
        self.phase: str | None = None
        self.state: tuple[float, float | None, str] | None = None
        self.pending = False

    def _line(self) -> str:
        assert self.state is not None
        done, total, message = self.state
        t = self.clock() - self.t0
        count = f"{int(done)}/{int(total)} ({100 * done / total:.0f} %)" if total else f"{int(done)}"
        rate = f", {done / t:.0f} per s" if t > 0 and done else ""
        return f"{self.label + ': ' if self.label else ''}{message or 'working'}: {count}, {t:.1f} s{rate}"

    def __call__(self, done, total, message) -> None:
        total = None if total is None or float(total) <= 0 else max(float(total), float(done))
        self.state = (float(done), total, str(message or ""))
        now = self.clock()
        if self.tty:
            self.file.write(f"\r{self._line()[:110]:<110}")
            self.file.flush()
            return
        if message != self.phase or now - self.last_line >= self.every_s:
            self.phase = message
            self.last_line = now
            self.file.write(self._line() + "\n")
            self.file.flush()
            self.pending = False
        else:
            self.pending = True

    def close(self) -> None:
        """End the display: the last count (if not yet shown), then a new line on a terminal."""
        if self.state is None:
            return
        if self.tty:
            self.file.write("\n")
        elif self.pending:
            self.file.write(self._line() + "\n")
        self.file.flush()
