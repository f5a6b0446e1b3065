"""The public API: what is written to files -- a model's report, the papers' demonstration
report and a model's 3-D viewer (``sm.report``, ``sm.demo``, ``sm.view``), and the design
studio's session (``sm.studio_session``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from ..analysis.mobility import mobility as _mobility
from ..errors import InputError, require
from ..results import Progress, check_progress
if TYPE_CHECKING:
    from ..present.viewer import ViewerFile
    from ..services.studio.session import Session

from .checks import ModelLike, as_mechanism, check_bool, check_choice, check_int, check_path
from .threads import one_blas_thread


# ============================================================================ report, viewer
@dataclass(frozen=True, eq=False)
class ReportResult:
    """A report written into ``out``: ``index.html`` (opens offline), ``results.json`` (every
    number: :attr:`data`, with its JSON envelope) and ``figures/``.  ``to_dict()`` is ``data``
    without the envelope (the payload of ``spatialmech report --json``, which adds its own)."""

    out: Path
    data: dict

    @property
    def index_html(self) -> Path:
        return self.out / "index.html"

    @property
    def results_json(self) -> Path:
        return self.out / "results.json"

    def to_dict(self) -> dict:
        return {k: v for k, v in self.data.items() if k not in ("schema_version", "command", "model", "length_unit")}


@one_blas_thread
def report(model: ModelLike, out=None, *, trace: bool = True, progress: bool | Progress | None = None) -> ReportResult:
    """Every analysis that applies to one model, written as a report into a directory.

    Mobility of every mode, the complete Jacobian, DJ at the task positions, the traced motion
    (1 DOF) and a 3-D viewer.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    out : str or path, optional
        The directory (default ``report-NAME``); created if needed.
    trace : bool
        Trace the one-degree-of-freedom motion (``False`` skips it).
    progress : bool or callable, optional
        ``True`` prints on stderr; a callable ``progress(done, total_or_None, message)``.

    Returns
    -------
    ReportResult
        ``out``, ``index_html`` (opens offline), ``results_json`` and ``data`` (every number);
        ``to_dict()`` is the payload of ``spatialmech report --json``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
    OSError
        The directory cannot be written.

    Examples
    --------
    >>> import spatialmech as sm, tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     r = sm.report("planar-4r", d, trace=False)
    ...     r.index_html.exists(), r.data["model"]
    (True, 'planar-4r')
    """
    require("plot", "matplotlib", "plotly", what="the report")  # before any work: the extra to install
    from ..present.report import build_model_report

    mech = as_mechanism(model)
    trace = check_bool(trace, "trace")
    if progress is not None and not isinstance(progress, bool):
        progress = check_progress(progress)
    out = Path(f"report-{mech.name}") if out is None else check_path(out, "out")
    if out.exists() and not out.is_dir():
        raise InputError(f"out: {out} is a file, not a directory")
    out.mkdir(parents=True, exist_ok=True)  # fail now on an unwritable directory, not after the work
    data = build_model_report(mech, out, progress=False if progress is None else progress, trace=trace)
    return ReportResult(out, data)


@one_blas_thread
def demo(out="report", *, progress: bool | Progress | None = None) -> ReportResult:
    """Reproduce the four papers' examples into a report (about 45 s).

    ``index.html`` (self-contained, opens offline), ``results.json`` (every number) and
    ``figures/``; each claim of a paper is a row (the paper's value, ours, reproduced or not and
    why; ``data["summary"]`` counts them).

    Parameters
    ----------
    out : str or path
        The directory (created if needed).
    progress : bool or callable, optional
        ``True`` prints on stderr; a callable ``progress(done, total_or_None, message)``.

    Returns
    -------
    ReportResult
        As :func:`report`.

    Raises
    ------
    TypeError
        ``out`` is not a path, ``progress`` not a bool or callable.
    InputError
        ``out`` exists and is not a directory.
    OSError
        The directory cannot be written.

    Examples
    --------
    >>> import spatialmech as sm
    >>> sm.demo(out=42)
    Traceback (most recent call last):
    ...
    TypeError: out: expected a path (str or os.PathLike), got int 42
    """
    require("plot", "matplotlib", "plotly", what="the report")  # before any work: the extras to install
    require("sim", "mujoco", what="the papers' report (its MuJoCo validation tables)")
    from ..present.report import build_demo

    out = check_path(out, "out")
    if progress is not None and not isinstance(progress, bool):
        progress = check_progress(progress)
    if out.exists() and not out.is_dir():
        raise InputError(f"out: {out} is a file, not a directory")
    out.mkdir(parents=True, exist_ok=True)  # fail now on an unwritable directory, not after the work
    data = build_demo(out, progress=False if progress is None else progress)
    return ReportResult(out, data)


from .constants import VIEW_MOTIONS as VIEW_MOTIONS  # the motions view() can animate  # noqa: E402


@dataclass(frozen=True, eq=False)
class ViewResult:
    """The viewer page written (:attr:`file`: ``out``, ``frames``, ``bytes``) and the motion shown
    (``"trace"`` or ``"demo"``)."""

    file: ViewerFile
    motion: str
    #: Why a traced motion is only part of a circuit (the tracker stopped at a bifurcation; the
    #: stops are marked in the page); empty when the circuit closed or for a demonstration loop.
    note: str = ""

    @property
    def out(self) -> str:
        return self.file.out

    @property
    def frames(self) -> int:
        return self.file.frames

    @property
    def bytes(self) -> int:
        return self.file.bytes

    def to_dict(self) -> dict:
        return {**self.file.to_dict(), "motion": self.motion, "note": self.note}


def view(model: ModelLike, out, *, motion: str = "auto", frames: int = 60, plotly: str = "inline") -> ViewResult:
    """Write the interactive 3-D viewer of a model, animated along a motion.

    One self-contained HTML file (opens offline).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    out : str or path
        The HTML file (its directory must exist).
    motion : {"auto", "trace", "demo"}
        ``"trace"`` (1 DOF: the whole circuit by continuation, the zeros of DJ marked),
        ``"demo"`` (a short loop along the closure manifold, any mobility) or ``"auto"`` (trace
        when the mechanism has one degree of freedom).
    frames : int
        The number of frames (at least 2).
    plotly : {"inline", "cdn", "directory"}
        plotly.js in the page, loaded from cdn.plot.ly (needs the network), or ``plotly.min.js``
        written once next to the page (small pages, offline).

    Returns
    -------
    ViewResult
        The file written (``out``, ``frames``, ``bytes``) and the ``motion`` shown.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
    OSError
        The directory cannot be written.

    Examples
    --------
    >>> import spatialmech as sm, tempfile, os
    >>> with tempfile.TemporaryDirectory() as d:
    ...     v = sm.view("rssr", os.path.join(d, "rssr.html"), frames=12)
    ...     v.frames, v.bytes > 100_000
    (12, True)
    """
    from ..analysis.traced_motion import traced_part
    from ..kinematics.motion import sample_motion
    require("plot", "plotly", what="the viewer")  # before any work: the extra to install
    from ..present.viewer import PLOTLY_MODES, write_viewer

    mech = as_mechanism(model)
    motion = check_choice(motion, "motion", VIEW_MOTIONS)
    plotly = check_choice(plotly, "plotly", PLOTLY_MODES)
    frames = check_int(frames, "frames", minimum=2)
    out = check_path(out, "out")
    if out.is_dir():
        raise InputError(f"out: {out} is a directory; give a file name")
    if not out.parent.is_dir():
        raise InputError(f"out: cannot write {out}: the directory {out.parent} does not exist")
    singular: tuple = ()
    stops: tuple = ()
    note = ""
    if motion == "auto":
        motion = "trace" if (not mech.is_metamorphic and _mobility(mech).dof_instantaneous == 1) else "demo"
    if motion == "trace":
        tr = traced_part(mech, frames=frames)
        configs, singular, stops, note = tr.configs, tr.singular, tr.stops, tr.note
        what = f"the traced part up to {len(stops)} bifurcation(s) (open squares)" if stops else "the traced circuit"
        title = (f"{mech.name}: {what} ({len(configs)} frames); +: DJ zeros of "
                 f"{', '.join(mech.actuators[:1]) or '-'}")
    else:
        configs = sample_motion(mech, n=frames)
        title = f"{mech.name}: a demonstration loop, {len(configs)} configurations (not the tracker)"
    written = write_viewer(out, mech, configs, title=title, task_positions=mech.positions, singular_points=singular,
                           plotly=plotly, stop_points=stops)
    return ViewResult(written, motion, note)


# ============================================================================ design studio
def studio_session(model: ModelLike = "five-cs-3") -> Session:
    """A design-studio session on a model: what ``spatialmech studio`` serves, without HTTP.

    ``drive(values)`` moves the actuators (model units, degrees for rotations) along the current
    branch by continuation and says how it went; ``state()`` is the readout (JSON payload,
    docs/studio.md); ``set_drivers``, ``fk_all`` (the modes of ``fk(..., all_solutions=True)``),
    ``pick_mode``.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.

    Returns
    -------
    Session
        The session (:class:`spatialmech.services.studio.session.Session`), at the model's
        reference configuration (or a generic one near it).

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).
        A metamorphic model is refused (export one of its modes).

    Examples
    --------
    >>> import spatialmech as sm
    >>> s = sm.studio_session("rssr")
    >>> r = s.drive([10.0])                                  # the crank to 10 degrees
    >>> str(r.status), round(s.state()["actuators_deg"]["A0.rot"], 9)
    ('reached', 10.0)
    """
    require("plot", "plotly", what="the studio")  # its scene is drawn with plotly
    from ..services.studio.session import Session

    return Session(as_mechanism(model))

