"""Input hardening of issue 10: the command line's error policy, malformed files, command-line
values, output paths checked before the work, searches with a size limit, the viewer's markers
and paper A's temporary directory.  Each test names the defect it pins ("Before: ...")."""

import codecs
import dataclasses
import importlib
import importlib.util
import re
import tempfile
import textwrap
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis.workspace import MAX_POSES, WorkspaceLimits, default_limits, orientation_workspace
from spatialmech.errors import ConvergenceError, InputError, SearchTooLargeError, UnknownNameError
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.common import check_output_dir, check_output_file, parse_numbers
from spatialmech.kinematics.closure import Configuration
from spatialmech.model.mechanism import MAX_IMPLICIT_MODES
from spatialmech.model.schema import ModelFileError, load_positions

RSSR = textwrap.dedent(
    """
    name = "my-rssr"
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
)


def run(*args, env=None):
    return CliRunner().invoke(cli, [str(a) for a in args], env=env)


def assert_one_line_error(r, code=2, contains=""):
    assert r.exit_code == code, r.output
    assert r.output.startswith("error: ") and r.output.count("\n") == 1, r.output
    assert "Traceback" not in r.output
    assert contains in r.output, r.output


# ------------------------------------------------------------------ the CLI's error policy
def _raise(exc):
    def f(*args, **kw):
        raise exc

    return f


@pytest.mark.parametrize("exc", [IndexError("list index out of range"), ValueError("a bug"), KeyError("k"),
                                 TypeError("unsupported operand"), ZeroDivisionError("division by zero")])
def test_a_programming_error_is_an_internal_error_not_a_user_error(monkeypatch, exc):
    """Before: every ValueError / KeyError became a one-line user error (exit 2), hiding bugs,
    and an IndexError was a raw traceback.  Now: exit code 3, one line that says it is a bug
    and how to see the traceback."""
    monkeypatch.setattr(catalog, "resolve", _raise(exc))
    r = run("mobility", "rssr")
    assert_one_line_error(r, 3, f"internal error ({type(exc).__name__}")
    assert "--debug" in r.output and "SPATIALMECH_DEBUG=1" in r.output


@pytest.mark.parametrize("how", ["option", "env"])
def test_debug_shows_the_traceback_of_an_internal_error(monkeypatch, how):
    monkeypatch.setattr(catalog, "resolve", _raise(IndexError("list index out of range")))
    r = run("--debug", "mobility", "rssr") if how == "option" else run("mobility", "rssr", env={"SPATIALMECH_DEBUG": "1"})
    assert r.exit_code == 3
    assert "Traceback (most recent call last)" in r.output and "IndexError: list index out of range" in r.output
    assert r.output.rstrip().splitlines()[-1].startswith("error: internal error (IndexError")


@pytest.mark.parametrize("exc, code", [(InputError("x: bad"), 2), (UnknownNameError("unknown thing 'q'"), 2),
                                       (ModelFileError("f.toml: limbs: bad"), 2), (SearchTooLargeError("step: too big"), 2),
                                       (ConvergenceError("Newton stalled"), 1),
                                       (FileNotFoundError(2, "No such file or directory", "in.toml"), 2)])
def test_the_projects_exceptions_and_os_errors_are_one_line_user_errors(monkeypatch, exc, code):
    monkeypatch.setattr(catalog, "resolve", _raise(exc))
    r = run("mobility", "rssr")
    assert_one_line_error(r, code)
    assert "internal error" not in r.output
    if isinstance(exc, UnknownNameError):
        assert r.output == "error: unknown thing 'q'\n"  # not KeyError's quoted repr


def test_debug_does_not_change_user_errors():
    r = run("--debug", "mobility", "no-such-model")
    assert_one_line_error(r, 2, "not a file and not a ready-made model")


# ------------------------------------------------------------------ malformed files
def test_a_deeply_nested_toml_is_a_clear_file_error(tmp_path):
    """Before: exit code 1 with 'the computation failed: maximum recursion depth exceeded'."""
    deep = tmp_path / "deep.toml"
    deep.write_text("name = 'x'\nnotes = " + "[" * 5000 + "]" * 5000 + "\n", encoding="utf-8")
    with pytest.raises(ModelFileError, match="nested too deeply"):
        sm.load(deep)
    assert_one_line_error(run("mobility", deep), 2, f"{deep}: ")


def test_a_non_utf8_file_names_the_file(tmp_path):
    """Before: "'utf-8' codec can't decode byte 0xff in position 9" without the file name."""
    f = tmp_path / "latin1.toml"
    f.write_bytes(RSSR.replace("my-rssr", "caf\xe9").encode("latin-1"))
    with pytest.raises(ModelFileError, match=re.escape(str(f)) + r": not UTF-8 text \(byte 0xe9 on line 2\)"):
        sm.load(f)
    assert_one_line_error(run("mobility", f), 2, str(f))
    positions = tmp_path / "positions.toml"
    positions.write_bytes(b"[[positions]]\nname = '\xff'\npoint = [0, 0, 0]\n")
    with pytest.raises(ModelFileError, match=re.escape(str(positions)) + ": not UTF-8"):
        load_positions(positions)


def test_a_file_too_large_is_refused_without_reading_it(tmp_path, monkeypatch):
    from spatialmech.model import schema

    monkeypatch.setattr(schema, "MAX_FILE_BYTES", 100)
    f = tmp_path / "big.toml"
    f.write_text(RSSR, encoding="utf-8")
    with pytest.raises(ModelFileError, match=r"big\.toml: larger than"):
        sm.load(f)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ("point = [0, 0, 0], axis", "point = [true, false, false], axis", "limbs[0].joints[0].point[0]: "),
        ("actuated = true", "actuated = 1", "limbs[0].joints[0].actuated: "),
        ("actuated = true", "actuated = true, pitch = '1'", "limbs[0].joints[0].pitch: "),
        ("point = [0.3, 0, 0]", "point = [0.3, '0', 0]", "limbs[0].joints[1].point[1]: "),
        ('name = "my-rssr"', "name = 3", "name: "),
        ('name = "my-rssr"', 'name = "my-rssr"\nnormalize_axes = 1', "normalize_axes: "),
        ('name = "my-rssr"', 'name = "my-rssr"\nformat = true', "format: "),
        ("actuated = true", "actuated = true, limits_deg = [0, true]", "limbs[0].joints[0].limits_deg[1]: "),
        ("actuated = true", "actuated = true, offset_deg = { rot = '5' }", "limbs[0].joints[0].offset_deg.rot: "),
    ],
)
def test_booleans_and_strings_are_not_numbers(old, new, field):
    """Before: ``point = [true, false, false]`` loaded as (1, 0, 0) and ``actuated = 1`` as true."""
    with pytest.raises(ModelFileError) as e:
        sm.loads(RSSR.replace(old, new, 1))
    assert str(e.value).startswith(field), str(e.value)


@pytest.mark.parametrize(
    "old, new, field",
    [
        ("point = [0.3, 0, 0]", "point = [0.3, nan, 0]", "limbs[0].joints[1].point[1]: "),
        ("point = [0.3, 0, 0]", "point = [0.3, -inf, 0]", "limbs[0].joints[1].point[1]: "),
        ("actuated = true", "actuated = true, limits_deg = [-inf, 90]", "limbs[0].joints[0].limits_deg[0]: "),
        ("actuated = true", "actuated = true, offset_deg = nan", "limbs[0].joints[0].offset_deg: "),
        ("actuated = true", "actuated = true, limits_deg = { rot = [0, nan] }", "limbs[0].joints[0].limits_deg.rot[1]: "),
        ("platform_point = [0.0, 1.0, -0.1]", "platform_point = [0.0, inf, -0.1]", "platform_point[1]: "),
        ("point = [0.3, 0, 0]", "point = [0.3, 1" + "0" * 400 + ", 0]", "limbs[0].joints[1].point[1]: "),
    ],
)
def test_nan_inf_and_overflow_in_files_are_refused_naming_the_field(old, new, field):
    with pytest.raises(ModelFileError) as e:
        sm.loads(RSSR.replace(old, new, 1))
    assert str(e.value).startswith(field), str(e.value)


@pytest.mark.parametrize("text, field", [
    (RSSR.replace("point = [0.3, 0, 0]", "point = [0.3, 1" + "0" * 5000 + ", 0]"), "not valid TOML: "),
    (RSSR.replace("actuated = true", "actuated = true, offset = 1" + "0" * 400), "limbs[0].joints[0].offset: "),
])
def test_integers_with_thousands_of_digits_are_file_errors(text, field):
    """Found by tests/test_fuzz.py: Python refuses to convert an integer of more than 4300 digits
    to text, so tomllib and the error message itself raised a plain ValueError (exit 3)."""
    with pytest.raises(ModelFileError) as e:
        sm.loads(text)
    assert str(e.value).startswith(field), str(e.value)
    assert len(str(e.value)) < 300


def test_integers_are_still_numbers_and_the_good_file_loads():
    mech = sm.loads(RSSR.replace("actuated = true", "actuated = true, limits_deg = [-180, 180], offset_deg = 10"))
    f = mech.freedom("A0").freedom
    assert f.limits == pytest.approx((-np.pi, np.pi)) and f.offset == pytest.approx(np.radians(10))


def test_a_length_unit_with_a_control_character_writes_a_readable_file():
    """Found by tests/test_fuzz.py: ``dumps`` put the length unit raw into its header comment, so
    a unit with a control character (or a newline) gave a file that ``loads`` refused."""
    for unit in ("m\x1f", "m\nname = 'injected'", "mm"):
        mech = dataclasses.replace(sm.loads(RSSR), length_unit=unit)
        again = sm.loads(sm.dumps(mech))
        assert again.length_unit == unit and again.name == "my-rssr"


# ------------------------------------------------------------------ command-line values
@pytest.mark.parametrize("values, contains", [("0.2,,0.2", "--actuators: item 2 of 3 is empty"),
                                              (",0.2", "--actuators: item 1 of 2 is empty"),
                                              ("0.2,", "--actuators: item 2 of 2 is empty"),
                                              ("0.2,abc", "--actuators: item 2 expects a number, got 'abc'"),
                                              ("0.2,nan", "--actuators: item 2 must be finite, got 'nan'"),
                                              ("1e999", "--actuators: item 1 must be finite, got '1e999'")])
def test_actuator_values_are_parsed_strictly(values, contains):
    """Before: ``--actuators 0.2,,0.2`` silently dropped the empty item."""
    assert_one_line_error(run("fk", "rssr", "--actuators", values), 2, contains)


@pytest.mark.parametrize("args, contains", [
    (["ik", "four-sps-cu", "--xyz", "-0.2", "1e308", "3"], "--xyz: the point is 1e+308 m from the reference platform point"),
    (["jacobian", "rssr", "--xyz", "0", "1", "1e30"], "more than 1e+06 times its size"),
    (["ik", "four-sps-cu", "--xyz", "0", "0", "nan"], "--xyz: expected finite numbers"),
    (["ik", "four-sps-cu", "--pose", "0,0,0.2,ZYX,0,inf,0"], "--euler: expected finite angles"),
])
def test_poses_out_of_the_numerical_range_are_refused_naming_the_option(args, contains):
    """Found by tests/test_fuzz.py: ``ik four-sps-cu --xyz -0.2 1e308 3`` overflowed into a
    zero quaternion inside scipy (an internal error, exit 3)."""
    assert_one_line_error(run(*args), 2, contains)


@pytest.mark.parametrize("args, contains", [
    (["fk", "four-sps-cu", "--actuators", "0.25,0.25,0.25,3.2e153", "--json"], "item 4 (L4.slide = 3.2e+153 m) is out of range"),
    (["fk", "rssr", "--actuators", "1e300"], "item 1 (A0.rot = 1e+300 deg) is out of range"),
])
def test_actuator_values_out_of_the_numerical_range_are_refused(args, contains):
    """Found by tests/test_fuzz.py: a leg length of 3.2e153 m overflowed to inf in the result and
    ``fk --json`` died in ``json.dumps`` (an internal error, exit 3)."""
    assert_one_line_error(run(*args), 2, contains)


def test_parse_numbers_checks_the_count():
    assert parse_numbers(" 1, 2.5 ,-3e-2", "--x") == [1.0, 2.5, -0.03]
    with pytest.raises(InputError, match="--x: expected 2 values, got 3"):
        parse_numbers("1,2,3", "--x", count=2)


def test_workspace_refuses_orientation_and_position_together():
    """Before: ``workspace --orientation --position`` silently ran one of them."""
    assert_one_line_error(run("workspace", "four-sps-cu", "--orientation", "--position"), 2,
                          "--orientation, --position: give one of them, not both")


# ------------------------------------------------------------------ output paths, before the work
def _not_called(what):
    def f(*args, **kw):
        raise AssertionError(f"{what} ran before the output path was checked")

    return f


@pytest.fixture
def blocker(tmp_path):
    """A regular file, so that ``blocker/x`` cannot be created."""
    b = tmp_path / "a-file"
    b.write_text("not a directory", encoding="utf-8")
    return b


@pytest.mark.parametrize(
    "args, option",
    [
        (["export", "rssr", "{b}/x.toml"], "FILE"),
        (["view", "rssr", "--out", "{b}/v.html"], "--out"),
        (["workspace", "four-sps-cu", "--plot", "{b}/ws.png"], "--plot"),
        (["singularity", "four-sps-cu", "--reference", "--plot", "{b}/loci.png"], "--plot"),
        (["defects", "five-cs-1", "--plot", "{b}/figs"], "--plot"),
        (["report", "rssr", "--out", "{b}/rep"], "--out"),
    ],
)
def test_output_paths_are_checked_before_the_model_is_even_loaded(monkeypatch, blocker, args, option):
    """Before: ``workspace --plot`` and ``defects --plot`` ran the whole analysis and then failed
    on the path (a traceback for some)."""
    monkeypatch.setattr(catalog, "resolve", _not_called("the command"))
    r = run(*[a.format(b=blocker) for a in args])
    assert_one_line_error(r, 2, f"{option}: ")
    assert str(blocker) in r.output


def test_synth_and_demo_check_their_outputs_first(monkeypatch, blocker, tmp_path):
    from spatialmech.present import report
    from spatialmech.synthesis import cs_dyads, tasks

    monkeypatch.setattr(tasks, "resolve_task", _not_called("synth rccc"))
    monkeypatch.setattr(cs_dyads, "synthesize_cs", _not_called("synth cs"))
    monkeypatch.setattr(report, "build_demo", _not_called("demo"))
    assert_one_line_error(run("synth", "rccc", "--save", blocker / "r.toml"), 2, "--save: ")
    assert_one_line_error(run("synth", "rccc", "--plot", blocker / "figs"), 2, "--plot: ")
    assert_one_line_error(run("synth", "cs", "--save", tmp_path / "no" / "c.toml"), 2, "--save: ")
    assert_one_line_error(run("demo", "--out", blocker / "d"), 2, "--out: ")


def test_workspace_plot_needs_a_known_format_before_the_work(monkeypatch, tmp_path):
    monkeypatch.setattr(catalog, "resolve", _not_called("workspace"))
    assert_one_line_error(run("workspace", "four-sps-cu", "--plot", tmp_path / "ws.jpg"), 2, ".png, .svg, .pdf")


def test_output_path_helpers(tmp_path, blocker):
    assert check_output_file(None, "--x") is None and check_output_dir(None, "--x") is None
    assert check_output_file(tmp_path / "f.png", "--x", suffixes=(".png",)) == tmp_path / "f.png"
    assert check_output_dir(tmp_path / "new" / "deeper", "--x") == tmp_path / "new" / "deeper"
    assert not (tmp_path / "new").exists()  # checked, not created
    with pytest.raises(InputError, match=r"--x: .* is a directory"):
        check_output_file(tmp_path, "--x")
    with pytest.raises(InputError, match=r"--x: .* is a file, not a directory"):
        check_output_dir(blocker, "--x")
    with pytest.raises(InputError, match="is not a directory"):
        check_output_file(blocker / "f.png", "--x")
    with pytest.raises(InputError, match="No such file or directory"):
        check_output_file(tmp_path / "no" / "f.png", "--x")


# ------------------------------------------------------------------ searches with a size limit
def _lockable_chain(n_sm: int) -> sm.Mechanism:
    return sm.Mechanism("many-sm", limbs=[sm.Limb("a", [sm.Sm(f"S{i}", [i, 0.3 * i, 0]) for i in range(n_sm)])])


def test_too_many_implicit_modes_are_refused_at_once():
    """Before: 4 Sm joints (12 lockable freedoms, no modes) made ``mobility`` enumerate and
    analyse 2^12 subsets (minutes; 2^30 for 10 joints: a hang).  How long the refusal takes:
    benchmarks/bench_refusals.py (``modes_refusal_s``, target < 1 s)."""
    mech = _lockable_chain(4)
    with pytest.raises(SearchTooLargeError, match=r"12 lockable freedoms .* 2\^12 = 4096 .* declare the modes"):
        mech.all_modes()
    with pytest.raises(SearchTooLargeError):
        sm.mobility(mech)
    assert 2 ** len(_lockable_chain(3).lockable) <= MAX_IMPLICIT_MODES  # 9 lockable: still enumerated
    assert len(_lockable_chain(3).all_modes()) == 2**9


def test_one_implicit_mode_can_still_be_named_when_there_are_too_many_to_list():
    mech = _lockable_chain(4)
    m = mech.mode("S0.rot1+S3.rot2")
    assert m.driven == ("S0.rot1", "S3.rot2") and mech.mode("all-locked").driven == ()
    with pytest.raises(UnknownNameError, match="joined by '\\+' in this order"):
        mech.mode("S3.rot2+S0.rot1")
    assert sm.mobility(mech, "S0.rot1+S3.rot2").mode == "S0.rot1+S3.rot2"


def test_mobility_cli_of_a_file_with_too_many_lockable_freedoms(tmp_path):
    """Refused (in how long: benchmarks/bench_refusals.py, ``modes_cli_refusal_s``)."""
    f = tmp_path / "many.toml"
    sm.dump(_lockable_chain(4), f)
    assert_one_line_error(run("mobility", f), 2, "declare the modes")


def test_a_workspace_grid_over_the_limit_is_refused_with_its_size():
    """Before: ``workspace --step-deg 1e-6`` allocated a 3.6e8-sample axis and hung.  In how
    long it is refused: benchmarks/bench_refusals.py (``workspace_refusal_s``)."""
    mech = catalog.build("four-sps-cu")
    with pytest.raises(SearchTooLargeError) as e:
        orientation_workspace(mech, at={"z": 0.1}, step=np.radians(1e-6))
    n = 360e6 * 180e6 * 360e6
    size = float(re.search(r"about ([0-9.e+]+) poses", str(e.value)).group(1))
    assert size == pytest.approx(n, rel=0.01) and f"max_poses = {MAX_POSES}" in str(e.value)
    factor = float(re.search(r"multiply the step by at least ([0-9.e+]+)", str(e.value)).group(1))
    assert factor == pytest.approx((n / MAX_POSES) ** (1 / 3), rel=0.01)
    with pytest.raises(SearchTooLargeError, match="about 1e9"):  # no overflow on a denormal step
        orientation_workspace(mech, at={"z": 0.1}, step=1e-320)
    r = run("workspace", "four-sps-cu", "--step-deg", "1e-6")
    assert_one_line_error(r, 2, "--step-deg (step): the grid has about")


@pytest.mark.slow
def test_workspace_progress_gives_an_estimate_of_the_total():
    """The progress bar of a workspace search has a total (so click shows an ETA): the grid and
    lines first, then the grid plus the bisections of the boundary changes it found."""
    mech = catalog.build("four-sps-cu")
    seen = []
    ws = orientation_workspace(mech, at={"z": 0.1}, step=np.radians(15), progress=lambda d, t, m: seen.append((d, t)))
    totals = [t for _, t in seen if t is not None]
    assert seen[0][1] is not None and totals, seen[:3]
    assert all(d <= t for d, t in seen if t is not None)
    assert abs(totals[-1] - ws.n_poses) < 0.1 * ws.n_poses, (totals[-1], ws.n_poses)


@pytest.mark.slow
def test_workspace_bisection_survives_a_denormal_tolerance_and_checks_chunk():
    """Before: ``tol = 5e-324`` overflowed the bisection count (OverflowError); ``chunk = 0`` was
    a ``range()`` error."""
    mech = catalog.build("four-sps-cu")
    lim = default_limits(mech)
    lim = WorkspaceLimits(lim.cones, None, lim.freedom_limits, lim.source)  # no interference: quicker
    ws = orientation_workspace(mech, at={"z": 0.1, "alpha": 0.0, "beta": 0.0}, step=np.radians(10), tol=5e-324,
                               polish=False, limits=lim)
    assert ws.alone["gamma"] is not None and np.isfinite(ws.alone["gamma"].hi)
    with pytest.raises(InputError, match="chunk"):
        orientation_workspace(mech, at={"z": 0.1, "alpha": 0.0}, step=np.radians(10), chunk=0)
    with pytest.raises(InputError, match="max_poses"):
        orientation_workspace(mech, at={"z": 0.1, "alpha": 0.0}, step=np.radians(10), max_poses=0)


@pytest.mark.parametrize(
    "args, contains",
    [
        (["fk", "four-sps-cu", "--actuators", "0.2,0.2,0.2,0.2", "--all", "--seeds", "100000000"], "--seeds"),
        (["view", "bennett", "--frames", "100000000", "--out", "v.html"], "--frames"),
        (["defects", "five-cs-1", "--monte-carlo", "1000000"], "--monte-carlo: at most"),
        (["synth", "rccc", "--samples", "100000000"], "--samples"),
        (["synth", "cs", "--starts", "100000000"], "--starts"),
        (["synth", "cs", "--samples", "100000000"], "--samples"),
        (["workspace", "four-sps-cu", "--max-poses", "0"], "--max-poses"),
    ],
)
def test_counts_from_the_command_line_are_bounded(args, contains):
    """Refused (in how long: benchmarks/bench_refusals.py, ``cli_counts_refusal_s``)."""
    assert_one_line_error(run(*args), 2, contains)


def test_refusal_benchmark_runs_and_reports_its_targets():
    """benchmarks/bench_refusals.py --quick: every case refused, a verdict and a ratio to the
    same run's baseline per target (the times themselves are not asserted here)."""
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_refusals.py"
    spec = importlib.util.spec_from_file_location("bench_refusals", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = bench.main(["--quick", "--json"])
    assert all(out["refused"].values()), out["refused"]
    assert set(out["met"]) == set(out["targets"]) == set(out["ratio_to_baseline"])
    assert all(isinstance(v, bool) for v in out["met"].values())
    assert set(out["cli_counts_by_command_s"]) == set(bench.CLI_COUNTS)


# ------------------------------------------------------------------ the viewer and paper A
def _plotly_glyphs(page: str) -> dict[str, str]:
    """plotly.js's table of 3-D marker glyphs, from the page's inlined plotly.min.js."""
    m = re.search(r'\{circle:"[^{}]*?x:"[^"]*"\}', page)
    assert m, "the glyph table of gl3d markers was not found in plotly.min.js"
    pairs = re.findall(r'"?([\w-]+)"?:"((?:\\u[0-9A-Fa-f]{4}|[^"\\])+)"', m.group(0))
    return {k: codecs.decode(v, "unicode_escape") for k, v in pairs}


def test_viewer_markers_are_glyphs_that_every_font_has(tmp_path):
    """Before: singular points used plotly's 3-D symbol "x", drawn as U+274C (an emoji): an
    empty box on machines without an emoji font.  Every 3-D marker symbol of the page must now
    be ASCII or in the basic Geometric Shapes block."""
    from spatialmech.present.viewer import write_viewer

    mech = catalog.build("five-cs-1")
    ref = Configuration.reference(mech)
    out = write_viewer(tmp_path / "v.html", mech, [ref, ref], task_positions=mech.positions,
                       singular_points=[np.array([0.0, 0.0, 0.0]), ref])
    page = Path(out.out).read_text(encoding="utf-8")
    glyphs = _plotly_glyphs(page)
    assert glyphs["x"] == "\u274c"  # the reason for the change, read from plotly itself
    symbols = set(re.findall(r'"symbol":\s*"([\w-]+)"', page))
    assert "cross" in symbols and "x" not in symbols, symbols
    for s in symbols:
        g = glyphs[s]
        assert all(ord(c) < 0x80 or 0x25A0 <= ord(c) <= 0x25FF for c in g), (s, g)


def test_importing_paper_a_creates_no_temporary_directory(monkeypatch):
    """Before: ``present/paper_a.py`` called ``tempfile.mkdtemp`` at import and never removed the
    directory (one left in /tmp per process)."""
    made = []
    real = tempfile.mkdtemp
    monkeypatch.setattr(tempfile, "mkdtemp", lambda *a, **k: made.append(1) or real(*a, **k))
    before = set(Path(tempfile.gettempdir()).glob("spatialmech-paper-a-*"))
    from spatialmech.present import paper_a

    importlib.reload(paper_a)
    assert made == [] and not hasattr(paper_a, "_TMP")
    assert set(Path(tempfile.gettempdir()).glob("spatialmech-paper-a-*")) == before


# ------------------------------------------------------------------ issue 30, item 11: found by fuzzing
SERIAL_RR = textwrap.dedent(
    """
    name = "serial-rr"
    links = ["ground", "arm", "platform"]

    [[joints]]
    name = "A"
    type = "R"
    links = ["ground", "arm"]
    point = [0, 0, 0]
    axis = [0, 0, 1]
    actuated = true

    [[joints]]
    name = "B"
    type = "R"
    links = ["arm", "platform"]
    point = [1, 0, 0]
    axis = [0, 0, 1]
    actuated = true
    """
)
ONE_R = textwrap.dedent(
    """
    name = "one-r"
    links = ["ground", "platform"]

    [[joints]]
    name = "A"
    type = "R"
    links = ["ground", "platform"]
    point = [0, 0, 0]
    axis = [0, 0, 1]
    actuated = true
    """
)


@pytest.mark.parametrize("text, values", [(SERIAL_RR, "10,20"), (ONE_R, "10")])
def test_fk_all_on_a_serial_chain_answers_its_one_pose(tmp_path, text, values):
    """Before: ``fk --all`` on a serial chain (no loop) stopped with an internal error
    (``cannot reshape array of size 0``, exit 3) or ran on without an answer."""
    f = tmp_path / "serial.toml"
    f.write_text(text)
    r = run("fk", f, "--actuators", values, "--all")
    assert r.exit_code == 0, r.output
    assert "1 assembly mode" in r.output and "serial chain" in r.output and "complete: " in r.output
    acts = [float(v) for v in values.split(",")]
    res = sm.fk(sm.load(f), acts, all_solutions=True)
    assert res.complete and len(res.poses) == 1
    np.testing.assert_allclose(res.poses[0].p, sm.fk(sm.load(f), acts).poses[0].p, atol=1e-9)
    assert_one_line_error(run("fk", f, "--actuators", values, "--all", "--seeds", 5), contains="serial chain")


def test_fk_all_on_a_serial_chain_with_a_passive_joint_is_refused(tmp_path):
    f = tmp_path / "serial.toml"
    f.write_text(SERIAL_RR.replace("actuated = true\n", "", 1))
    assert_one_line_error(run("fk", f, "--actuators", "20", "--all"), contains="passive")


@pytest.mark.parametrize("args", [["mobility"], ["ik", "--xyz", "1", "0", "0"], ["fk", "--actuators", "1,2"],
                                  ["singularity", "--xyz", "1", "0", "0"], ["export", "OUT"]])
@pytest.mark.parametrize("name", ["", " ", " arm"])
def test_an_empty_link_name_in_a_graph_file_names_the_field(tmp_path, args, name):
    """Before: an empty link name stopped mobility, ik, fk, singularity and export with an
    internal error (a ``TypeError``, exit 3)."""
    f = tmp_path / "bad.toml"
    f.write_text(SERIAL_RR.replace('links = ["ground", "arm", "platform"]', f'links = ["ground", "{name}", "platform"]'))
    args = [str(tmp_path / "out.toml") if a == "OUT" else a for a in args]
    assert_one_line_error(run(args[0], f, *args[1:]), contains="links[1]: a link name must be non-empty")
    assert not (tmp_path / "out.toml").exists()


def test_parasitic_honours_euler_without_free():
    """Before: ``parasitic three-rps --over a2:-20:20:5 --euler xyz`` silently used ZYX (the
    option was dropped without --free)."""
    import json

    r = run("parasitic", "three-rps", "--over", "a2:-20:20:5", "--euler", "xyz", "--json")
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["task"]["euler"] == "xyz"
    r = run("parasitic", "three-rps", "--over", "a2:-20:20:5")
    assert r.exit_code == 0 and "task ZYX" in r.output, r.output


@pytest.mark.parametrize("extra, contains", [(["--euler", "QQQ"], "--euler: expected three axis letters"),
                                             (["--free", "x,y,a1", "--euler", "QQQ"], "--euler: expected three"),
                                             (["--euler", "ZXZ"], "--euler: the angles of 'ZXZ' are singular")])
def test_parasitic_names_euler_in_its_errors(extra, contains):
    r = CliRunner().invoke(cli, ["parasitic", "three-rps", "--over", "a2:-20:20:5", *extra])
    assert r.exit_code == 2 and contains in r.stderr and "Traceback" not in r.output, r.output


def _delta_text(joint: str, old: str, new: str) -> str:
    text = sm.dumps(catalog.build("delta"))
    i = text.index(f'name = "{joint}"')
    j = text.index(old, i)
    return text[:j] + new + text[j + len(old):]


@pytest.mark.parametrize("text, contains", [
    (_delta_text("W1a", 'links = ["rod1a", "platform"]', 'links = ["rod1a", "arm1"]'),  # a rod joined to the wrong link
     "joint 'W1a' joins links 'rod1a' and 'arm1', already joined by joint 'E1a'"),
    (sm.dumps(catalog.build("delta")) + '\n[[joints]]\nname = "W1a2"\ntype = "S"\npoint = [0, 0, 0]\n'
     'links = ["platform", "rod1a"]\n', "joint 'W1a2' joins links 'platform' and 'rod1a', already joined by joint 'W1a'"),
])
@pytest.mark.parametrize("command", [["fk", "--actuators", "10,10,10", "--all"], ["singularity", "--reference"]])
def test_two_joints_between_the_same_two_links_are_refused(tmp_path, text, contains, command):
    """Before: ``fk --all`` on a Delta with a rod joined to the wrong link, or two links joined
    by a joint twice, ran past 60 s (a loop with no link in it: a spurious self-motion)."""
    f = tmp_path / "bad.toml"
    f.write_text(text)
    assert_one_line_error(run(command[0], f, *command[1:]), contains=contains)
