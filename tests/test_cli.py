"""The command line: version, models, mobility JSON keys, errors."""

import json

import pytest
from click.testing import CliRunner

from spatialmech import __version__
from spatialmech.interfaces.cli import cli

KEYS = {"dof", "dof_instantaneous", "motion", "lambda", "d", "n", "g", "sum_f", "v", "xi"}


def run(*args):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


def test_version():
    r = run("--version")
    assert r.exit_code == 0 and __version__ in r.output


def test_models_json_lists_every_required_model():
    r = run("models", "--json")
    d = json.loads(r.output)
    assert (d["command"], d["model"]) == ("models", None)
    names = {m["name"] for m in d["models"]}
    assert {"four-sps-cu", "three-rrr-sm", "three-sps-smpu", "five-cs-1", "five-cs-2", "five-cs-3", "stewart-6sps",
            "three-rps", "three-upu", "delta", "planar-4r", "bennett", "rssr"} <= names
    assert all(m["description"] for m in d["models"])


def test_mobility_json_single_mode():
    doc = json.loads(run("mobility", "four-sps-cu", "--json").output)
    assert (doc["command"], doc["model"], doc["metamorphic"]) == ("mobility", "four-sps-cu", False)
    [d] = doc["modes"]  # one mode: the same shape as a metamorphic mechanism's list
    assert set(d) >= KEYS
    assert (d["dof"], d["motion"], d["xi"], d["lambda"]) == (4, "RxRyRzTz", 4, 0)


def test_mobility_json_metamorphic_lists_modes():
    d = json.loads(run("mobility", "three-rrr-sm", "--json").output)["modes"]
    assert isinstance(d, list) and len(d) == 7
    for m in d:
        assert KEYS | {"mode", "actuators"} <= set(m)
    [one] = json.loads(run("mobility", "three-rrr-sm", "--mode", "R4+R7", "--json").output)["modes"]
    assert one["dof"] == 2 and one["mode"] == "R4+R7"


def test_mobility_text_shows_the_breakdown():
    out = run("mobility", "bennett").output
    assert "M = d(n - g - 1) + sum f + v - xi = 3(4 - 4 - 1) + 4 + 0 - 0 = 1" in out
    assert "classic Grübler-Kutzbach (d = 6): -2" in out


@pytest.mark.parametrize(
    "args, msg",
    [(["mobility", "no-such-model"], "not a file and not a ready-made model"),
     (["mobility", "three-rrr-sm", "--mode", "X"], "unknown mode 'X'")],
)
def test_user_errors_exit_2_with_one_line(args, msg):
    r = CliRunner().invoke(cli, args)
    assert r.exit_code == 2
    assert msg in r.output and r.output.count("\n") == 1


def test_export_then_mobility_of_the_file(tmp_path):
    f = tmp_path / "b.toml"
    assert run("export", "bennett", str(f)).exit_code == 0
    [d] = json.loads(run("mobility", str(f), "--json").output)["modes"]
    assert d["dof"] == 1 and d["gk_classic"] == -2


def test_pose_option_equals_xyz_euler():
    a = json.loads(run("ik", "four-sps-cu", "--pose", "0,0,0.12,ZYX,34.38,-5.73,11.46", "--json").output)
    xyz_euler = ["--xyz", "0", "0", "0.12", "--euler", "ZYX", "34.38", "-5.73", "11.46"]
    b = json.loads(run("ik", "four-sps-cu", *xyz_euler, "--json").output)
    assert a["actuators_len"] == b["actuators_len"] and len(a["actuators_len"]) == 4
    r = CliRunner().invoke(cli, ["singularity", "four-sps-cu", "--pose", "0,0,0.12,ZYX,1,2"])
    assert r.exit_code == 2 and "--pose" in r.output


@pytest.mark.slow
def test_view_traces_a_one_dof_mechanism_and_marks_singular_points(tmp_path):
    out = tmp_path / "b.html"
    r = CliRunner().invoke(cli, ["view", "planar-4r", "--motion", "trace", "--frames", "12", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d["frames"] == 12 and d["motion"] == "trace" and out.stat().st_size > 100_000
    from spatialmech.analysis.traced_motion import traced_motion
    from spatialmech import catalog

    m = catalog.build("planar-4r")
    configs, sing = traced_motion(m, frames=12)
    assert len(configs) == 12 and sing == ()  # a Grashof crank never reaches a branch point
