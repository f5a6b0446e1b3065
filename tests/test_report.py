"""The reproduction report (``spatialmech demo``) and the one-model report (``spatialmech report``).
That every command and Python snippet in docs/ runs: tests/test_docs_run.py."""

import json
import re
from html.parser import HTMLParser
from io import BytesIO, StringIO

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.image import imread

from spatialmech import catalog
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closed_forms import four_sps_cu as k
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.jacobian import complete_jacobian
from spatialmech.kinematics.position import configuration_at_pose, freedom_values
from spatialmech.kinematics.tracking import trace_motion
from spatialmech.present import paper_b
from spatialmech.analysis.defects import dj_table
from spatialmech.present.report import VERDICTS, Claim, Progress, Table, build_model_report


def run(*args):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


@pytest.fixture(scope="module")
def demo(demo_report):
    """The session's one demo run (tests/conftest.py)."""
    return demo_report


# ------------------------------------------------------------------ the demo report
def _claim(data, paper, text):
    hits = [c for c in data["claims"] if c["paper"] == paper and text in c["claim"]]
    assert len(hits) == 1, (paper, text, [c["claim"] for c in hits])
    return hits[0]


@pytest.mark.slow
def test_demo_claims_and_their_verdicts(demo):
    """Every claim of the four papers that the report covers, with the verdict the analyses give.
    Not reproduced (conventions.md, with evidence in the rows): paper B's printed eq 8 and its
    'no singularity' statement, paper D's example directions of eqs 28 and 30."""
    _, data = demo
    by_paper = {p: [c for c in data["claims"] if c["paper"] == p] for p in "ABCD"}
    assert {p: len(v) for p, v in by_paper.items()} == {"A": 17, "B": 10, "C": 18, "D": 6}
    not_repr = {(c["paper"], c["claim"].split(":")[0].split(" (")[0]) for c in data["claims"] if not c["reproduced"]}
    assert not_repr == {("B", "Inverse position, eq 8 as printed"),
                        ("B", "No singularity inside the workspace when the parameters are chosen well"),
                        ("B", "Orientation workspace at z = 0.1 m"), ("D", "Example m1"), ("D", "Example m2")}
    assert all(c["verdict"] == "reproduced" for c in by_paper["A"])
    corrected = {(c["paper"], c["claim"][:24]) for c in data["claims"] if c["verdict"] == "reproduced after correction"}
    assert corrected == {("B", "Inverse position, eq 8 w"), ("B", "Velocity and acceleratio"), ("C", "3-RRR metamorphic joint,"),
                         ("B", "Singular case (c): legs "), ("C", "Eq 21: closed-form actua")}
    s = data["summary"]
    assert s["claims"] == 51 and s["reproduced"] + s["reproduced after correction"] + s["not reproduced"] == 51
    for c in data["claims"]:
        assert c["verdict"] in VERDICTS and c["reproduced"] == (c["verdict"] != "not reproduced")
        assert c["paper_value"] and c["ours"] and c["evidence"], c["claim"]
        if not c["reproduced"]:
            assert c["note"], c["claim"]  # says why


@pytest.mark.slow
def test_demo_numbers_match_the_analyses(demo):
    """Spot checks of results.json against the analyses called directly (not via the report)."""
    _, data = demo
    sec = {s["key"]: s for s in data["sections"]}
    # paper A, linkage 3: the signs of DJ at P4 for every driver
    mech = catalog.build("five-cs-3")
    prev = None
    for P in mech.positions[:4]:
        fit = configuration_at_pose(mech, P, start=prev)
        prev = fit.config
    table = sec["paper-a"]["data"]["five-cs-3"]["dj_table"]
    for row in table["drivers"]:
        assert row["signs"][3] == np.sign(complete_jacobian(mech, prev, [row["driver"]]).det)
    # paper B: the example's leg lengths and the eq-8 error of leg 4 at the home pose
    ev = _claim(data, "B", "eq 8 as printed")["evidence"]
    assert ev["home_error_per_leg_len"][3] == pytest.approx(0.1292, abs=1e-4)
    fwd = _claim(data, "B", "Forward position")["evidence"]
    assert np.allclose(list(fwd["actuators_len"].values()), k.leg_lengths(paper_b.EXAMPLE_POSE), atol=1e-15)
    assert fwd["n_solutions"] == 4 and fwd["n_within_limits"] == 2
    # paper D: the RCCC errors of docs/synthesis.md
    rc = _claim(data, "D", "guides the coupler")["evidence"]
    assert np.allclose(rc["position_errors_len"], [2.686, 0.209, 2.800], atol=2e-3)
    m1 = _claim(data, "D", "Example m1")["evidence"]["residuals"]["u0,v"]
    assert np.allclose(m1, [-0.2439, -0.3600, -0.3934], atol=1e-4)


@pytest.mark.slow
def test_tables_are_rectangular_and_json_has_no_nan(demo):
    out, data = demo
    text = (out / "results.json").read_text(encoding="utf-8")
    json.loads(text, parse_constant=lambda c: pytest.fail(f"non-finite number {c} in results.json"))
    n_tables = 0
    for s in data["sections"]:
        for t in s["tables"]:
            n_tables += 1
            assert t["rows"] and all(len(r) == len(t["columns"]) for r in t["rows"]), t["title"]
    assert n_tables >= 9


class _Tags(HTMLParser):
    """Collects the attributes of every start tag (script contents are data, not tags)."""

    def __init__(self):
        super().__init__()
        self.attrs = []
        self.tags = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.attrs += [(tag, k, v or "") for k, v in attrs]


@pytest.mark.slow
def test_index_html_is_self_contained(demo):
    out, data = demo
    page = (out / "index.html").read_text(encoding="utf-8")
    assert page.startswith("<!doctype html>")
    p = _Tags()
    p.feed(page)
    links = [(t, k, v) for t, k, v in p.attrs if k in ("src", "href")]
    external = [x for x in links if re.match(r"\s*(https?:)?//", x[2])]
    assert not external, external[:3]
    imgs = [v for t, k, v in links if t == "img"]
    n_fig = sum(len(s["figures"]) for s in data["sections"])
    assert n_fig >= 10 and len(imgs) == n_fig and all(v.startswith("data:image/png;base64,") for v in imgs)
    assert p.tags.count("script") >= 2 and "<link" not in page.split("<body>")[0]
    ids = re.findall(r'id="(spatialmech-viewer-\d+)"', page)
    n_view = sum(len(s["viewers"]) for s in data["sections"])
    assert n_view == 5 and len(set(ids)) == n_view
    assert page.count("Plotly.newPlot") >= n_view
    for c in data["claims"]:
        assert c["verdict"] in page


@pytest.mark.slow
def test_figure_files_are_non_blank_pngs(demo):
    out, data = demo
    for s in data["sections"]:
        for f in s["figures"]:
            raw = (out / f["file"]).read_bytes()
            assert raw[:8] == b"\x89PNG\r\n\x1a\n"
            img = imread(BytesIO(raw), format="png")
            assert img.shape[0] > 200 and img.shape[1] > 300
            assert img[..., :3].std() > 0.05, f["file"]  # not a blank canvas


def test_cli_demo_help_shows_an_example():
    r = CliRunner().invoke(cli, ["demo", "--help"])
    assert r.exit_code == 0 and "spatialmech demo --out report" in r.output


# ------------------------------------------------------------------ building blocks
def test_claim_and_table_reject_bad_input():
    with pytest.raises(ValueError, match="verdict"):
        Claim("A", "c", "1", "1", "maybe")
    with pytest.raises(ValueError, match=r"rows\[1\]"):
        Table("t", ("a", "b"), ((1, 2), (1,)))


def test_progress_lines_and_silence():
    buf = StringIO()
    p = Progress(2, file=buf, label="x")
    p(1, 2, "first")  # the one progress signature: progress(done, total, message)
    p(2, 2, "second")
    p.close()
    lines = buf.getvalue().splitlines()
    assert lines[0].startswith("[ 1/2") and lines[0].endswith("first") and lines[-1].startswith("x: done in")
    quiet = StringIO()
    q = Progress(1, file=quiet, enabled=False)
    q(1, 1, "step")
    q.close()
    assert quiet.getvalue() == ""


@settings(max_examples=30, deadline=None)
@given(st.floats(0.08, 0.3), st.floats(-3, 3), st.floats(-1.5, 1.5), st.floats(-3, 3))
def test_eq8_corrected_equals_the_leg_lengths_and_printed_leg2_is_right(z, al, be, ga):
    phi = np.array([z, al, be, ga])
    assert np.allclose(paper_b.eq8_corrected(phi), k.leg_lengths(phi), atol=1e-14)
    assert paper_b.eq8_printed(phi)[1] == pytest.approx(k.leg_lengths(phi)[1], abs=1e-14)


def test_trajectory_rates_are_its_derivatives():
    t = np.linspace(0, 2, 41)
    h = 1e-6
    phi, dphi, ddphi = paper_b.trajectory(t)
    assert np.allclose((paper_b.trajectory(t + h)[0] - paper_b.trajectory(t - h)[0]) / (2 * h), dphi, atol=1e-8)
    assert np.allclose((paper_b.trajectory(t + h)[1] - paper_b.trajectory(t - h)[1]) / (2 * h), ddphi, atol=1e-6)
    assert np.min(np.hypot(phi[:, 1], phi[:, 2])) > 0.2  # never at the singular alpha = beta = 0


def test_dj_table_semantics_and_errors():
    t = dj_table(catalog.build("five-cs-1"), ["rot1", "rot5"])
    assert t.changes("rot1") == [5] and t.changes("rot5") == [2]
    assert not t.keeps_sign("rot1")
    assert t.dj.shape == (2, 7) and np.all(t.sigma_min > 0)
    json.dumps(t.to_dict())
    with pytest.raises(ValueError, match="mech: stewart-6sps has no task positions"):
        dj_table(catalog.build("stewart-6sps"))


@pytest.mark.slow
def test_rssr_dj_poles_are_the_rocker_limit_positions():
    """Along the RSSR's motion DJ of the crank changes sign twice without a singularity: it passes
    through infinity where the rocker (the platform) stops and reverses while the crank turns."""
    m = catalog.build("rssr")
    tr = trace_motion(m, Configuration.reference(m), increasing="A0",
                      monitors={"DJ": lambda c: complete_jacobian(m, c).det or 0.0})  # None: not square
    kinds = [{"kind": e.kind, "sigma_min": complete_jacobian(m, e.x).sigma_min} for e in tr.events]
    assert [e["kind"] for e in kinds] == ["pole", "pole"]
    i = [r.id for r in m.freedom_refs].index("B0.rot")
    rocker = np.array([freedom_values(m, c.q)[i] for c in tr.points])
    at_events = sorted(freedom_values(m, e.x.q)[i] for e in tr.events)
    # the events are the rocker's extremes: within 1e-4 rad of the sampled ones, and beyond them
    assert at_events == pytest.approx([rocker.min(), rocker.max()], abs=1e-4)
    assert at_events[0] <= rocker.min() + 1e-12 and at_events[1] >= rocker.max() - 1e-12
    assert min(e["sigma_min"] for e in kinds) > 0.1


@pytest.mark.slow
def test_dj_zeros_of_five_cs_2_are_singular():
    m = catalog.build("five-cs-2")
    tr = trace_motion(m, Configuration.reference(m), increasing="rot1",
                      monitors={"rot1": lambda c: complete_jacobian(m, c, ["rot1"]).det})
    kinds = [{"kind": e.kind, "sigma_min": complete_jacobian(m, e.x, ["rot1"]).sigma_min} for e in tr.events]
    assert len(kinds) == 2 and all(e["kind"] == "zero" and e["sigma_min"] < 1e-6 for e in kinds)


# ------------------------------------------------------------------ the one-model report
RSSR_TOML = """
name = "my-rssr"
length_unit = "m"
platform_point = [0.0, 1.0, -0.1]
[[limbs]]
name = "input"
joints = [
  { name = "A0", type = "R", point = [0, 0, 0], axis = [0, 0, 1], actuated = true },
  { name = "A1", type = "S", point = [0.3, 0, 0] },
  { name = "B1", type = "S", point = [0, 1, -0.1] },
]
[[limbs]]
name = "output"
joints = [ { name = "B0", type = "R", point = [0, 1, 0.5], axis = [1, 0, 0] } ]
"""


@pytest.mark.slow
def test_model_report_of_a_user_file(tmp_path):
    f = tmp_path / "my-rssr.toml"
    f.write_text(RSSR_TOML, encoding="utf-8")
    out = tmp_path / "rep"
    r = run("report", str(f), "--out", str(out))
    assert r.exit_code == 0, r.output
    data = json.loads((out / "results.json").read_text())
    sec = data["sections"][0]
    assert data["model"] == "my-rssr" and sec["data"]["mobility"][0]["dof"] == 1
    assert sec["data"]["trace"]["closed"] and len(sec["data"]["trace"]["events"]) == 2
    assert sec["viewers"][0]["frames"] == 60 and (out / "figures" / "motion.png").exists()
    assert 'id="spatialmech-viewer-1"' in (out / "index.html").read_text()


@pytest.mark.slow
def test_model_report_of_a_multi_dof_model_with_positions(tmp_path):
    data = build_model_report("four-sps-cu", tmp_path, progress=False)
    sec = data["sections"][0]
    assert "trace" not in sec["data"] and sec["viewers"][0]["frames"] == 48
    J = sec["data"]["jacobian_reference"]
    assert J["sigma_min"] < 1e-9  # the home pose alpha = beta = 0 is singular


@pytest.mark.slow
def test_model_report_dj_table_of_a_paper_linkage(tmp_path):
    data = build_model_report("five-cs-1", tmp_path, progress=False, trace=False)
    t = data["sections"][0]["data"]["dj_table"]
    assert len(t["drivers"]) == 10 and not any(row["keeps_sign"] for row in t["drivers"])


def test_report_command_errors_are_one_line():
    r = CliRunner().invoke(cli, ["report", "no-such-model"])
    assert r.exit_code == 2 and r.output.count("\n") == 1 and r.output.startswith("error: ")
    h = CliRunner().invoke(cli, ["report", "--help"])
    assert h.exit_code == 0 and "spatialmech report bennett --out bennett-report" in h.output


# ------------------------------------------------------------------ issue 30, item 11: atomic, with the envelope
def _tiny_sections():
    from spatialmech.present.figures import ReportFigure
    from spatialmech.present.report import Section, Table

    fig = ReportFigure("a.png", "A", "a figure", b"\x89PNG\r\n\x1a\nnot really")
    return [Section("s", "S", tables=(Table("t", ("x_len",), ((1.0,),)),), figures=(fig,), length_unit="m")]


def test_results_json_has_the_json_envelope(tmp_path):
    """Before: ``results.json`` lacked the envelope docs/json.md promises."""
    from spatialmech.present.report import write_report
    from spatialmech.serialize import SCHEMA_VERSION

    doc = write_report(tmp_path / "rep", "T", _tiny_sections(), 1.0, {"model": "m"}, command="report",
                       length_unit="mm")
    on_disk = json.loads((tmp_path / "rep" / "results.json").read_text())
    assert on_disk == doc
    assert list(doc)[:4] == ["schema_version", "command", "model", "length_unit"]
    assert (doc["schema_version"], doc["command"], doc["model"], doc["length_unit"]) == (SCHEMA_VERSION, "report", "m", "mm")
    doc = write_report(tmp_path / "demo", "T", _tiny_sections(), 1.0)
    assert (doc["command"], doc["model"], doc["length_unit"]) == ("demo", None, None)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo", "rep"]


@pytest.mark.parametrize("existing", [False, True])
def test_an_interrupted_report_leaves_nothing_partial(tmp_path, monkeypatch, existing):
    """Before: an interrupted ``report`` left a partial ``results.json`` and figures behind."""
    import spatialmech.present.report as rep

    out = tmp_path / "rep"
    if existing:
        rep.write_report(out, "old", _tiny_sections(), 1.0)
        (out / "notes.txt").write_text("mine")
    before = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(rep, "render_html", interrupted)
    with pytest.raises(KeyboardInterrupt):
        rep.write_report(out, "new", _tiny_sections(), 1.0)
    after = {p.relative_to(tmp_path): p.read_bytes() for p in tmp_path.rglob("*") if p.is_file()}
    assert after == before  # no partial results.json, no figures, no staging folder
    monkeypatch.undo()
    rep.write_report(out, "new", _tiny_sections(), 2.0)  # a rerun replaces the report, keeps other files
    assert json.loads((out / "results.json").read_text())["title"] == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]
    assert (out / "notes.txt").exists() == existing


_TWO_WORKERS_SCRIPT = r"""
import json, re, sys
from pathlib import Path
from spatialmech.present import demo_pool
from spatialmech.present.report import build_demo

tmp = Path(sys.argv[1])
assert demo_pool.fork_is_safe()  # a fresh process: no threading layer started
assert demo_pool.openmp_runtimes() == [], demo_pool.openmp_runtimes()  # nor an OpenMP runtime loaded
secs = ("paper_c:section", "models:section")
steps = []
a = build_demo(tmp / "a", progress=lambda d, t, m: steps.append(m), sections=secs, workers=2)
ran = dict(demo_pool.LAST_RUN)
b = build_demo(tmp / "b", progress=False, sections=secs, workers=1)
a.pop("elapsed_s"); b.pop("elapsed_s")
assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)
strip = lambda p: re.sub(r"generated in [0-9.]+ s", "", p.read_text(encoding="utf-8"))
assert strip(tmp / "a" / "index.html") == strip(tmp / "b" / "index.html")
for f in (tmp / "b" / "figures").iterdir():
    assert (tmp / "a" / "figures" / f.name).read_bytes() == f.read_bytes()
assert len(steps) == 4 and set(ran["sections"]) == set(secs) and len(ran["workers"]) == 2, ran

# The CI failure of stop 34: a parallel kernel started GNU OpenMP's threads in this process,
# after which a forked worker that runs one is killed.  Forking is then refused: one process.
import numba
import numpy as np
from spatialmech.kinematics.closed_forms import four_sps_cu as k
k.leg_lengths(np.zeros((k.PARALLEL_FROM, 4)))
layer = numba.threading_layer()
assert demo_pool.fork_is_safe() == (layer in ("tbb", "workqueue")), layer
if layer == "omp":
    assert any(n.startswith("libgomp") for n in demo_pool.openmp_runtimes()), demo_pool.openmp_runtimes()
    assert demo_pool.default_workers(5) == 1 and demo_pool.default_workers(5, 2) == 1
    c = build_demo(tmp / "c", progress=False, sections=secs, workers=2)
    c.pop("elapsed_s")
    assert json.dumps(c, sort_keys=True) == json.dumps(b, sort_keys=True)
print("ok", layer)
"""


@pytest.mark.slow
def test_openmp_runtimes_are_read_from_the_process_maps(tmp_path):
    """``demo_pool.openmp_runtimes`` names the GNU, LLVM and Intel OpenMP runtimes (vendored
    wheel copies too) among the mapped files and nothing else; no maps file (not Linux): none."""
    from spatialmech.present import demo_pool

    maps = tmp_path / "maps"
    maps.write_text("\n".join([
        "7f00-7f01 r-xp 00000000 08:01 1 /usr/lib/x86_64-linux-gnu/libgomp.so.1.0.0",
        "7f02-7f03 r-xp 00000000 08:01 2 /venv/site-packages/torch.libs/libgomp-a34b3233.so.1",
        "7f04-7f05 r-xp 00000000 08:01 3 /opt/llvm/lib/libomp.so",
        "7f06-7f07 r-xp 00000000 08:01 4 /opt/intel/lib/libiomp5.so",
        "7f08-7f09 r-xp 00000000 08:01 5 /usr/lib/libcomposite.so",
        "7f0a-7f0b r-xp 00000000 08:01 6 /venv/scipy/linalg/_decomp_interpolative.so",
        "7f0c-7f0d rw-p 00000000 00:00 0 [heap]",
    ]), encoding="utf-8")
    assert demo_pool.openmp_runtimes(maps) == ["libgomp-a34b3233.so.1", "libgomp.so.1.0.0", "libiomp5.so", "libomp.so"]
    assert demo_pool.openmp_runtimes(tmp_path / "absent") == []


def test_demo_sections_on_two_workers_equal_one_process(tmp_path):
    """The demo's sections built by two forked workers (present/demo_pool.py) give the same
    results.json (but for the elapsed time), page and figures as one process, and every step of
    both sections reaches the progress callback; once a parallel kernel has started GNU OpenMP in
    the process, the demo does not fork (a forked worker would be killed, as in a CI run of stop
    34) and still builds the same report.  In a fresh process: this pytest worker may have
    started OpenMP already."""
    import multiprocessing
    import subprocess
    import sys

    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork on this platform")
    r = subprocess.run([sys.executable, "-c", _TWO_WORKERS_SCRIPT, str(tmp_path)], capture_output=True, text=True,
                       timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    assert r.stdout.startswith("ok")
