"""The reproduction report (``spatialmech demo``) and the one-model report (``spatialmech report``).

A report is a list of :class:`Section` s.  A section holds

- claim rows (:class:`Claim`): what a paper says, what spatialmech computes, the verdict
  (``reproduced``, ``reproduced after correction`` or ``not reproduced``), why, the numbers
  behind it (``evidence``) and the test of the suite that asserts it;
- tables (:class:`Table`), figures (:class:`~.figures.ReportFigure`, Matplotlib PNGs) and
  interactive 3-D viewers (:class:`Viewer`, plotly; see :mod:`.viewer`).

Each paper's section is built by one function, ``section(progress)`` of
:mod:`.paper_a` ... :mod:`.paper_d` (listed in :data:`DEMO_SECTIONS`); to add a claim or a
figure, add it there.  The functions only call the library's analyses; this module only
assembles and renders:

- ``DIR/results.json``: every number of every table and claim (JSON, no NaN);
- ``DIR/index.html``: one self-contained page (figures as base64 PNG, plotly.js inlined once
  from the installed plotly package; no external URL anywhere in the markup), opens offline;
- ``DIR/figures/*.png``: the figures as files.

Progress goes to stderr (a bar on a terminal, one line per step otherwise); nothing is cached
between runs.  The demo's sections are built by two worker processes where the machine has two
cores (:mod:`.demo_pool`).  Example::

    from spatialmech.present.report import build_demo
    data = build_demo("report")          # ~19 CPU s; data["summary"] counts the verdicts
"""

from __future__ import annotations

import contextlib
import html
import importlib
import json
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..model.mechanism import Mechanism
from ..results import Progress as ProgressCallback
from ..results import Verdict, check_progress
from ..serialize import fields_dict, json_default
from .figures import ReportFigure

__all__ = [
    "DEMO_SECTIONS",
    "VERDICTS",
    "Claim",
    "Progress",
    "Section",
    "Table",
    "Viewer",
    "build_demo",
    "build_model_report",
    "join_names",
    "prerender",
    "render_html",
    "section_function",
    "write_report",
]

#: The three verdicts of a claim row (the values of :class:`~spatialmech.results.Verdict`).
VERDICTS = tuple(v.value for v in Verdict)

#: The sections of the demo report, in order: ``module:function`` in :mod:`spatialmech.present`,
#: each ``function(progress) -> Section``.
DEMO_SECTIONS = (
    "paper_a:section",
    "paper_b:section",
    "paper_c:section",
    "paper_d:section",
    "models:section",
)


def join_names(names, limit: int = 8) -> str:
    """``"a, b, c"``; past ``limit`` names, ``"a, b, ... and 5 more"``: a list is shortened by whole
    names, never cut inside one."""
    names = [str(n) for n in names]
    if limit < 1:
        raise InputError(f"limit: expected a positive number of names, got {limit}")
    if len(names) <= limit:
        return ", ".join(names)
    return ", ".join(names[:limit]) + f" and {len(names) - limit} more"


@dataclass(frozen=True)
class Claim:
    """One claim of a paper checked by the project.

    ``paper_value``: what the paper states (text, as printed, translated); ``ours``: what the
    project's analysis gives (text with numbers and units); ``evidence``: the numbers behind
    ``ours`` (JSON-serialisable); ``note``: why it does (not) reproduce; ``test``: the test
    function of the suite that asserts the same thing (``tests/test_x.py::test_function``, with
    ``[id]`` for one case of a parametrised test; tests/test_claims.py checks that it exists).

    ``consistent``: the row's own cross-check, when it has one (``None``: none), e.g. measured
    values against the closed forms quoted in ``note``; ``consistency`` says what was compared.
    A row whose explanation and measured value disagree has ``consistent = False``: it is shown
    as INCONSISTENT in the page, counted in the summary, and fails the test suite
    (tests/test_regressions.py).
    """

    paper: str
    claim: str
    paper_value: str
    ours: str
    verdict: Verdict
    note: str = ""
    evidence: dict = field(default_factory=dict)
    test: str = ""
    consistent: bool | None = None
    consistency: str = ""

    def __post_init__(self):
        if self.consistent is not None and not isinstance(self.consistent, (bool, np.bool_)):
            raise InputError(f"consistent: expected True, False or None, got {self.consistent!r}")
        if self.consistent is not None:
            object.__setattr__(self, "consistent", bool(self.consistent))
        if self.verdict not in VERDICTS:
            raise InputError(f"verdict: expected one of {VERDICTS}, got {self.verdict!r}")
        object.__setattr__(self, "verdict", Verdict(self.verdict))

    @property
    def reproduced(self) -> bool:
        """True unless the verdict is ``not reproduced``."""
        return self.verdict is not Verdict.NOT_REPRODUCED

    def to_dict(self) -> dict:
        return fields_dict(self, names=("paper", "claim", "paper_value", "ours", "verdict", "reproduced", "note",
                                        "evidence", "test", "consistent", "consistency"))


@dataclass(frozen=True)
class Table:
    """A table of numbers: ``rows`` are tuples in the order of ``columns``."""

    title: str
    columns: tuple[str, ...]
    rows: tuple[tuple, ...]
    note: str = ""

    def __post_init__(self):
        for k, r in enumerate(self.rows):
            if len(r) != len(self.columns):
                raise InputError(f"rows[{k}]: expected {len(self.columns)} values ({', '.join(self.columns)}), got {len(r)}")

    def to_dict(self) -> dict:
        return fields_dict(self)


@dataclass(frozen=True, eq=False)
class Viewer:
    """An interactive 3-D viewer to embed: ``configs`` along a motion of ``mech``
    (see :func:`.viewer.viewer_figure` for ``task_positions`` and ``singular_points``)."""

    title: str
    mech: Mechanism = field(repr=False)
    configs: tuple = field(repr=False)
    task_positions: tuple = field(default=(), repr=False)
    singular_points: tuple = field(default=(), repr=False)
    note: str = ""
    #: the viewer's markup rendered ahead (by a demo worker, :func:`prerender`), its div id
    #: :data:`_PRERENDER_ID` until the page numbers it; empty: rendered with the page
    html: str = field(default="", repr=False)

    def to_dict(self) -> dict:
        return {"title": self.title, "model": self.mech.name, "frames": len(self.configs),
                "task_positions": len(self.task_positions), "singular_points": len(self.singular_points),
                "note": self.note}


@dataclass(frozen=True)
class Section:
    """One section of a report (one paper, one model, ...)."""

    key: str
    title: str
    intro: str = ""
    claims: tuple[Claim, ...] = ()
    tables: tuple[Table, ...] = ()
    figures: tuple[ReportFigure, ...] = ()
    viewers: tuple[Viewer, ...] = ()
    pending: tuple[str, ...] = ()  # analyses of the paper not (yet) in the report
    data: dict = field(default_factory=dict)  # extra numbers (JSON-serialisable)
    length_unit: str | None = None  # unit of the section's *_len fields (its model's or paper's; docs/json.md)

    def to_dict(self) -> dict:
        """JSON (docs/json.md): the section's ``length_unit`` declares the unit of the ``*_len``
        fields of its claims and data (a report spans models in different units)."""
        return fields_dict(self, names=("key", "title", "length_unit", "intro", "claims", "tables", "figures", "viewers",
                                        "pending", "data"))


# ------------------------------------------------------------------------------ progress
class Progress:
    """Progress of a report on ``file`` (stderr), a :data:`spatialmech.results.Progress`
    callback: ``progress(done, total, "label")`` announces step ``done`` (counted here when
    ``done`` is ``None``).

    On a terminal: a bar over ``total`` steps with the current label; otherwise one line per
    step with the elapsed time.  ``enabled=False`` prints nothing.
    """

    def __init__(self, total: int, *, enabled: bool = True, file=None, label: str = "spatialmech"):
        self.total = max(int(total), 1)
        self.enabled = enabled
        self.file = file if file is not None else sys.stderr
        self.label = label
        self.count = 0
        self.t0 = time.perf_counter()
        self.tty = bool(getattr(self.file, "isatty", lambda: False)())

    @property
    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def __call__(self, done: float | None, total: float | None, step: str) -> None:
        self.count = self.count + 1 if done is None else int(done)
        if total is not None:
            self.total = max(int(total), 1)
        if not self.enabled:
            return
        n = min(self.count, self.total)
        if self.tty:
            width = 24
            done = int(width * n / self.total)
            line = f"\r{self.label} [{'#' * done}{'-' * (width - done)}] {n}/{self.total} {self.elapsed:5.1f} s  {step[:60]:<60}"
            self.file.write(line)
        else:
            self.file.write(f"[{n:2d}/{self.total} {self.elapsed:6.1f} s] {step}\n")
        self.file.flush()

    def close(self) -> None:
        if self.enabled:
            end = f"done in {self.elapsed:.1f} s"
            self.file.write((f"\r{self.label}: {end}{' ' * 90}\n") if self.tty else f"{self.label}: {end}\n")
            self.file.flush()


def section_function(spec: str) -> tuple[Callable, int]:
    """The function of a section spec ``module:function`` (in :mod:`spatialmech.present`) and its
    number of progress steps (the module's ``STEPS``)."""
    mod_name, fn_name = spec.split(":")
    mod = importlib.import_module(f"{__package__}.{mod_name}")
    return getattr(mod, fn_name), int(getattr(mod, "STEPS", 1))


# ------------------------------------------------------------------------------ rendering
_CSS = """
*,*::before,*::after{box-sizing:border-box}
body{font-family:system-ui,-apple-system,Segoe UI,sans-serif;margin:1.5em auto;max-width:1180px;color:#222;padding:0 1em;
overflow-wrap:break-word}
h1{margin-bottom:.2em} h2{border-bottom:2px solid #ddd;padding-bottom:.2em;margin-top:2em}
.scroll{max-width:100%;overflow-x:auto;margin:.6em 0 1.2em}
table{border-collapse:collapse;font-size:13px}
td,th{border:1px solid #ccc;padding:3px 7px;text-align:left;vertical-align:top}
th{background:#f3f3f3} td.num{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
table.claims td{min-width:7em} table.claims td:last-child{min-width:16em}
.v-reproduced{color:#176f2c;font-weight:bold} .v-corrected{color:#8a5a00;font-weight:bold}
.v-not{color:#b3261e;font-weight:bold} .small{font-size:12px;color:#555} .bad{color:#b3261e;font-weight:bold;font-size:12px}
code{background:#f5f5f5;padding:0 3px;overflow-wrap:anywhere} figure{margin:1em 0;max-width:100%}
figure img{max-width:100%;height:auto;border:1px solid #eee}
figcaption{font-size:13px;color:#444} .pending{background:#fff8e1;padding:.4em .8em;border-left:3px solid #f0c36d}
.viewer{border:1px solid #ddd;margin:1em 0;max-width:100%;overflow:hidden}
"""

_VERDICT_CLASS = {"reproduced": "v-reproduced", "reproduced after correction": "v-corrected", "not reproduced": "v-not"}


def _fmt(v) -> str:
    if isinstance(v, bool) or v is None:
        return str(v)
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if v == 0.0:
            return "0"
        a = abs(v)
        return f"{v:.4g}" if 1e-3 <= a < 1e5 else f"{v:.3e}"
    if isinstance(v, (list, tuple)):
        return ", ".join(_fmt(x) for x in v)
    return str(v)


def _table_html(t: Table) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in t.columns)
    body = "".join(
        "<tr>" + "".join(
            f"<td class='num'>{html.escape(_fmt(x))}</td>" if isinstance(x, (int, float, np.number)) and not isinstance(x, bool)
            else f"<td>{html.escape(_fmt(x))}</td>" for x in r) + "</tr>"
        for r in t.rows
    )
    note = f"<p class='small'>{html.escape(t.note)}</p>" if t.note else ""
    return (f"<h3>{html.escape(t.title)}</h3><div class='scroll'><table><thead><tr>{head}</tr></thead>"
            f"<tbody>{body}</tbody></table></div>{note}")


def _claims_html(claims: Sequence[Claim]) -> str:
    rows = []
    for c in claims:
        test = f"<div class='small'>test: <code>{html.escape(c.test)}</code></div>" if c.test else ""
        if c.consistent is False:
            test += ("<div class='bad'>INCONSISTENT: the explanation and the measured values disagree "
                     f"({html.escape(c.consistency)})</div>")
        elif c.consistent:
            test += f"<div class='small'>cross-checked: {html.escape(c.consistency)}</div>"
        rows.append(
            f"<tr><td>{html.escape(c.claim)}</td><td>{html.escape(c.paper_value)}</td><td>{html.escape(c.ours)}</td>"
            f"<td class='{_VERDICT_CLASS[c.verdict]}'>{html.escape(c.verdict)}</td><td>{html.escape(c.note)}{test}</td></tr>"
        )
    return ("<div class='scroll'><table class='claims'><thead><tr>"
            "<th>claim</th><th>paper</th><th>spatialmech</th><th>verdict</th><th>why / evidence</th>"
            "</tr></thead><tbody>" + "".join(rows) + "</tbody></table></div>")


#: The div id of a viewer rendered ahead of its page (:attr:`Viewer.html`), replaced by its number.
_PRERENDER_ID = "spatialmech-viewer-prerendered-7f3a"


def _viewer_div(v: Viewer, div_id: str) -> str:
    from .viewer import viewer_html

    return viewer_html(v.mech, list(v.configs), title=v.title, task_positions=v.task_positions,
                       singular_points=v.singular_points, full_html=False, include_plotlyjs=False, div_id=div_id,
                       default_height="640px")


def prerender(sec: Section) -> Section:
    """``sec`` with its viewers' markup rendered (:attr:`Viewer.html`): a demo worker renders its
    sections' viewers itself, in parallel with the other worker, instead of the page doing all."""
    import dataclasses

    return dataclasses.replace(sec, viewers=tuple(dataclasses.replace(v, html=_viewer_div(v, _PRERENDER_ID))
                                                  for v in sec.viewers))


def _viewer_html(v: Viewer, div_id: str) -> str:
    div = v.html.replace(_PRERENDER_ID, div_id) if v.html else _viewer_div(v, div_id)
    note = f"<p class='small'>{html.escape(v.note)}</p>" if v.note else ""
    return f"<div class='viewer'>{div}</div>{note}"


def _figure_html(f: ReportFigure) -> str:
    """A figure with its title in bold and its caption, the title said once (a caption that
    opens with its title is shown alone)."""
    title, caption = f.title.strip().rstrip("."), f.caption.strip()
    head = "" if caption.lower().startswith(title.lower()) else f"<b>{html.escape(title)}.</b> "
    return (f"<figure><img alt='{html.escape(title)}' src='{f.data_uri()}'><figcaption>{head}"
            f"{html.escape(caption)} <span class='small'>(figures/{html.escape(f.name)})</span>"
            "</figcaption></figure>")


def summary(sections: Sequence[Section]) -> dict:
    """Counts of the verdicts, overall and per section."""
    out: dict[str, int] = {"claims": 0, **dict.fromkeys(VERDICTS, 0), "inconsistent": 0}
    by_section: dict[str, dict[str, int]] = {}
    for s in sections:
        per = {v: sum(c.verdict == v for c in s.claims) for v in VERDICTS}
        bad = sum(c.consistent is False for c in s.claims)
        by_section[s.key] = {"claims": len(s.claims), **per, "inconsistent": bad}
        out["claims"] += len(s.claims)
        out["inconsistent"] += bad
        for v in VERDICTS:
            out[v] += per[v]
    return {**out, "by_section": by_section}


def render_html(title: str, sections: Sequence[Section], data: dict) -> str:
    """The self-contained page (plotly.js inlined once if any section has a viewer)."""
    s = data["summary"]
    toc = "".join(
        f"<li><a href='#{html.escape(sec.key)}'>{html.escape(sec.title)}</a>"
        + (f" ({s['by_section'][sec.key]['claims']} claims: {s['by_section'][sec.key]['reproduced']} reproduced,"
           f" {s['by_section'][sec.key]['reproduced after correction']} after correction,"
           f" {s['by_section'][sec.key]['not reproduced']} not reproduced)" if sec.claims else "")
        + "</li>"
        for sec in sections
    )
    parts = []
    n_view = 0
    for sec in sections:
        parts.append(f"<h2 id='{html.escape(sec.key)}'>{html.escape(sec.title)}</h2>")
        if sec.intro:
            parts.append("".join(f"<p>{html.escape(p)}</p>" for p in sec.intro.split("\n\n")))
        if sec.claims:
            parts.append(_claims_html(sec.claims))
        if sec.pending:
            parts.append("<div class='pending'><b>Not (yet) in this report:</b><ul>"
                         + "".join(f"<li>{html.escape(p)}</li>" for p in sec.pending) + "</ul></div>")
        for t in sec.tables:
            parts.append(_table_html(t))
        for f in sec.figures:
            parts.append(_figure_html(f))
        for v in sec.viewers:
            n_view += 1
            parts.append(f"<h3>{html.escape(v.title)}</h3>" + _viewer_html(v, f"spatialmech-viewer-{n_view}"))
    js = ""
    if n_view:
        from plotly.offline import get_plotlyjs

        js = f"<script type='text/javascript'>{get_plotlyjs()}</script>"
    head = (f"<p>spatialmech {html.escape(data['version'])}; generated in {data['elapsed_s']:.1f} s. "
            f"{s['claims']} claims: {s['reproduced']} reproduced, {s['reproduced after correction']} reproduced after "
            f"correction, {s['not reproduced']} not reproduced (each with the reason). Every number is in "
            f"<code>results.json</code>; the figures are also in <code>figures/</code>.</p>")
    return (f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<style>{_CSS}</style>{js}</head><body><h1>{html.escape(title)}</h1>{head}<ul>{toc}</ul>"
            + "".join(parts) + "</body></html>\n")


def write_report(out, title: str, sections: Sequence[Section], elapsed: float, extra: dict | None = None, *,
                 command: str = "demo", length_unit: str | None = None) -> dict:
    """Write ``out/results.json``, ``out/index.html`` and ``out/figures/*.png``; return the
    document written to ``results.json``: the JSON envelope of ``command`` (docs/json.md; its
    ``model`` is ``extra["model"]``, else ``None``) around the report's data.

    Atomic: everything is written into a new folder next to ``out``, which then replaces
    ``out``'s report files; an interrupted run leaves no partial report behind (other files in
    an existing ``out`` are kept)."""
    from .. import __version__
    from ..serialize import envelope

    out = Path(out)
    names = [f.name for sec in sections for f in sec.figures]
    dup = {n for n in names if names.count(n) > 1}
    if dup:
        raise InputError(f"figures: duplicate file names {sorted(dup)}")
    data = {
        "title": title,
        "version": __version__,
        "elapsed_s": round(float(elapsed), 2),
        "verdicts": list(VERDICTS),
        "summary": summary(sections),
        "claims": [{**c.to_dict(), "length_unit": sec.length_unit} for sec in sections for c in sec.claims],  # as its section
        "sections": [sec.to_dict() for sec in sections],
        **(extra or {}),
    }
    model = data.pop("model", None)
    doc = envelope(command, model, data, length_unit=length_unit)
    text = json.dumps(doc, indent=1, default=json_default, allow_nan=False)
    doc = json.loads(text)
    with _staged(out) as tmp:
        (tmp / "figures").mkdir()
        for sec in sections:
            for f in sec.figures:
                (tmp / "figures" / f.name).write_bytes(f.png)
        (tmp / "results.json").write_text(text, encoding="utf-8")
        (tmp / "index.html").write_text(render_html(title, sections, doc), encoding="utf-8")
    return doc


#: The entries of a report folder (:func:`write_report`), replaced together.
REPORT_ENTRIES = ("figures", "results.json", "index.html")


@contextlib.contextmanager
def _staged(out: Path):
    """A new, hidden folder next to ``out`` to write a report into; on success its entries
    replace :data:`REPORT_ENTRIES` of ``out`` (renames in one file system), on any failure or
    interrupt it is removed and ``out`` is untouched."""
    import shutil
    import uuid

    parent = out.parent
    parent.mkdir(parents=True, exist_ok=True)
    tmp = parent / f".{out.name}.partial-{uuid.uuid4().hex[:12]}"
    tmp.mkdir()
    try:
        yield tmp
        if not out.exists():
            tmp.rename(out)
            return
        old = parent / f".{out.name}.old-{uuid.uuid4().hex[:12]}"
        old.mkdir()
        for name in REPORT_ENTRIES:  # the previous report's entries aside, the new ones in
            if (out / name).exists() or (out / name).is_symlink():
                (out / name).rename(old / name)
        for name in REPORT_ENTRIES:
            (tmp / name).rename(out / name)
        shutil.rmtree(old, ignore_errors=True)
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


# ------------------------------------------------------------------------------ entry points
def _reporter(progress: bool | ProgressCallback | None, total: int, label: str):
    """``(sink, bar)``: the callback the sections report to and the :class:`Progress` that times
    the run (printing on stderr when ``progress`` is True; a callable gets every step too)."""
    if progress is None or isinstance(progress, bool):
        bar = Progress(total, enabled=bool(progress), label=label)
        return bar, bar
    user = check_progress(progress)
    bar = Progress(total, enabled=False, label=label)

    def sink(done, tot, message):
        bar(done, tot, message)
        user(done, tot, message)

    return sink, bar


def _offset(sink: ProgressCallback, start: int, total: int) -> ProgressCallback:
    """A section's callback (steps 1..its STEPS) as steps ``start + 1 ..`` of the whole run."""
    return lambda done, _total, message: sink(start + (done or 0), total, message)


def build_demo(out, *, progress: bool | ProgressCallback = True, sections: Sequence[str] = DEMO_SECTIONS,
               workers: int | None = None) -> dict:
    """Reproduce every paper's examples and write the report into ``out`` (see module docstring).

    ``sections``: ``module:function`` specs (default :data:`DEMO_SECTIONS`).  ``progress``: True
    prints on stderr, False nothing; a :data:`~spatialmech.results.Progress` callback gets
    ``(step, steps, message)``.  ``workers``: processes building the sections (they are
    independent; default: two where the machine has two cores and a fork is safe, see
    :mod:`.demo_pool`; 1: all in this process; never more than the cores).  The report is the same either way.  Returns the
    data written to ``results.json``.
    """
    from .demo_pool import build_sections, default_workers

    fns = [section_function(s) for s in sections]
    total = sum(n for _, n in fns)
    sink, bar = _reporter(progress, total, "spatialmech demo")
    n_workers = default_workers(len(fns), workers)
    if n_workers > 1:
        built = build_sections(list(sections), [n for _, n in fns], sink, total, n_workers)
    else:
        built, start = [], 0
        for fn, n in fns:
            built.append(fn(_offset(sink, start, total)))
            start += n
    data = write_report(out, "spatialmech reproduction report", built, bar.elapsed)
    bar.close()
    return data


def build_model_report(model, out, *, progress: bool | ProgressCallback = True, trace: bool = True) -> dict:
    """Every analysis that applies to one model (ready-made name, TOML file or Mechanism),
    written like the demo into ``out`` (see :func:`.models.model_section`).  ``trace=False``
    skips the continuation trace of a one-degree-of-freedom motion; ``progress`` as in
    :func:`build_demo`."""
    from .. import catalog
    from . import models

    from .model_platform import PLATFORM_STEPS, platform_section

    mech = catalog.resolve(model)
    total = models.MODEL_STEPS + PLATFORM_STEPS
    sink, bar = _reporter(progress, total, f"spatialmech report {mech.name}")
    sec = models.model_section(mech, _offset(sink, 0, total), trace=trace)
    platform = platform_section(mech, _offset(sink, models.MODEL_STEPS, total))
    from .report_forces import forces_section

    sections = [sec, *([platform] if platform is not None else []), forces_section(mech)]
    data = write_report(out, f"spatialmech report: {mech.name}", sections, bar.elapsed, {"model": mech.name},
                        command="report", length_unit=mech.length_unit)
    bar.close()
    return data
