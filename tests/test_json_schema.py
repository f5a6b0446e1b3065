"""One result schema (issue 10): every ``--json`` output has the envelope (schema_version,
command, model, length_unit), validates against its shipped JSON Schema
(``spatialmech/interfaces/schemas/<command>.schema.json``), follows the unit rule of
docs/json.md (checked mechanically), and has the same shape for every model of a command
(closed forms and the general engine alike)."""

import json
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st
from jsonschema import Draft202012Validator
from referencing import Registry, Resource
from scipy.spatial.transform import Rotation

from spatialmech.geometry.rotations import euler_matrix
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.common import load_schema, schema_file_name
from spatialmech.serialize import (
    EMBEDDED_KEYS,
    SCHEMA_VERSION,
    SCREW_KEYS,
    UNIT_FREE_KEYS,
    UNIT_SUFFIXES,
    envelope,
    pose_dict,
    unit_rule_violations,
)

DOCS = Path(__file__).parent.parent / "docs"

FK_ACTUATORS = "0.216745,0.23896,0.227321,0.206933"  # paper B's example: 4 assembly modes, 2 within limits
POSE = ["--pose", "0,0,0.12,ZYX,34.38,-5.73,11.46"]


@pytest.fixture(scope="module")
def registry():
    common = load_schema("common")
    return Registry().with_resource(common["$id"], Resource.from_contents(common))


def run_json(*args: str) -> dict:
    r = CliRunner().invoke(cli, [*args, "--json"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    return json.loads(r.output)


def check(doc: dict, command: str, model: str | None, registry) -> dict:
    """The envelope, the command's schema and the unit rule; returns ``doc``."""
    assert doc["schema_version"] == SCHEMA_VERSION == "2"
    assert doc["command"] == command and doc["model"] == model
    errors = sorted(Draft202012Validator(load_schema(command), registry=registry).iter_errors(doc),
                    key=lambda e: list(e.absolute_path))
    assert not errors, [(list(e.absolute_path), e.message[:300]) for e in errors[:5]]
    assert unit_rule_violations(doc) == []
    return doc


# ------------------------------------------------------------------ every command, several models
CASES = [
    (["models"], "models", None),
    (["mobility", "four-sps-cu"], "mobility", "four-sps-cu"),
    (["mobility", "three-rrr-sm"], "mobility", "three-rrr-sm"),
    (["ik", "four-sps-cu", *POSE], "ik", "four-sps-cu"),
    (["ik", "delta", "--xyz", "0.02", "0.01", "-0.33"], "ik", "delta"),
    (["ik", "five-cs-1", "--position", "3"], "ik", "five-cs-1"),  # not reachable: rounded data, pose_fit
    (["ik", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,y,a1"], "ik", "three-rps"),
    (["ik", "puma560", "--pose", "0.5,-0.15,0.1,ZYX,10,20,30", "--all"], "ik", "puma560"),  # homotopy, certified
    (["ik", "agile-eye", "--pose", "0,0,0,ZYX,10,20,30", "--all"], "ik", "agile-eye"),  # closed-form limbs
    (["parasitic", "three-rps", "--over", "a2:-10:10:3,a3:-5:5:2", "--at", "z=0.33"], "parasitic", "three-rps"),
    (["fk", "four-sps-cu", "--actuators", FK_ACTUATORS, "--all", "--seeds", "16"], "fk", "four-sps-cu"),  # closed form
    (["fk", "four-sps-cu", "--actuators", FK_ACTUATORS], "fk", "four-sps-cu"),  # general engine
    (["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2"], "fk", "stewart-6sps"),
    (["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all"], "fk", "stewart-6sps"),  # homotopy
    (["fk", "rssr", "--actuators", "30", "--all"], "fk", "rssr"),  # loop formulation, monodromy
    (["jacobian", "four-sps-cu", *POSE], "jacobian", "four-sps-cu"),
    (["jacobian", "five-cs-1", "--position", "3", "--driver", "rot1"], "jacobian", "five-cs-1"),
    (["jacobian", "five-cs-3", "--dj-table"], "jacobian", "five-cs-3"),
    (["jacobian", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,y,a1"], "jacobian", "three-rps"),
    (["jacobian", "delta", "--xyz", "0.02", "0.01", "-0.33"], "jacobian", "delta"),  # task_jacobian over x, y, z
    (["singularity", "four-sps-cu", *POSE], "singularity", "four-sps-cu"),
    (["singularity", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "20", "0", "0",
      "--slice", "a2:-30:30:3,z:0.1:0.14:3"], "singularity", "four-sps-cu"),
    (["workspace", "four-sps-cu", "--position", "--at", "alpha=0,beta=0,gamma=0", "--step", "0.05"],
     "workspace", "four-sps-cu"),
    (["workspace", "three-sps-smpu", "--orientation", "--at", "alpha=0,beta=0", "--step-deg", "60", "--tol-deg", "1"],
     "workspace", "three-sps-smpu"),  # general path
    (["workspace", "three-rps", "--task", "--over", "a2:-30:30:3,a3:-30:30:3", "--at", "z=0.33",
      "--cone", "S1=40,S2=40,S3=40", "--tol-deg", "1"], "workspace", "three-rps"),  # over task coordinates
    (["workspace", "three-upu", "--task", "--over", "x:-0.1:0.1:3", "--at", "z=0.3", "--limit", "actuators=0.3:0.4",
      "--tol", "1e-3"], "workspace", "three-upu"),
    (["singularity", "three-rps", "--slice", "a2:-30:30:3,a3:-30:30:3", "--at", "z=0.33"], "singularity", "three-rps"),
    (["statics", "four-sps-cu", "--wrench", "0,0,-10,0,0,1", *POSE], "statics", "four-sps-cu"),
    (["statics", "four-sps-cu", "--wrench", "0,0,-10,0,0,1"], "statics", "four-sps-cu"),  # singular: unbalanced
    (["statics", "delta", "--wrench=-1,0,-10,0,0,0", "--xyz", "0.02", "0.01", "-0.33"], "statics", "delta"),  # graph
    (["accuracy", "three-rps", "--xyz", "0", "0", "0.33", "--actuator-error", "1e-5", "--geometry-tolerance", "1e-5",
      "--clearance", "1e-5", "--samples", "4"], "accuracy", "three-rps"),
    (["stiffness", "stewart-6sps", "--k", "2e6"], "stiffness", "stewart-6sps"),
    (["stiffness", "three-rps", "--k", "1e6", "--kc", "leg1=1e8", "--pose", "0,0,0.33,ZYX,0,5,5"], "stiffness", "three-rps"),
    (["stiffness", "four-sps-cu"], "stiffness", "four-sps-cu"),  # singular at the reference: compliance null
    (["stiffness", "delta", "--over", "x:-0.02:0.02:2,y:-0.02:0.02:2", "--at", "z=-0.33"], "stiffness", "delta"),
]
SLOW_CASES = [  # more than ~1 s each: deselected by the quick loop (pytest -m "not slow")
    (["workspace", "four-sps-cu", "--orientation", "--at", "z=0.1", "--step-deg", "15"], "workspace", "four-sps-cu"),
    (["synth", "rccc", "--samples", "60"], "synth rccc", None),
    (["singularity", "four-sps-cu", "--reference"], "singularity", "four-sps-cu"),  # finite self-motion
    (["defects", "five-cs-1"], "defects", "five-cs-1"),
    (["synth", "cs", "--samples", "6", "--starts", "20"], "synth cs", None),
]


@pytest.mark.parametrize("args, command, model", CASES, ids=[" ".join(c[0][:3]) for c in CASES])
def test_json_follows_its_schema_and_the_unit_rule(args, command, model, registry):
    check(run_json(*args), command, model, registry)


@pytest.mark.slow
@pytest.mark.parametrize("args, command, model", SLOW_CASES, ids=[" ".join(c[0][:3]) for c in SLOW_CASES])
def test_json_of_the_slow_commands(args, command, model, registry):
    check(run_json(*args), command, model, registry)


@pytest.mark.slow
def test_export_and_view_json(tmp_path, registry):
    d = check(run_json("export", "rssr", str(tmp_path / "r.toml")), "export", "rssr", registry)
    assert d["bytes"] == (tmp_path / "r.toml").stat().st_size and d["length_unit"] == "m"
    v = check(run_json("view", "bennett", "--frames", "4", "--out", str(tmp_path / "b.html")), "view", "bennett", registry)
    assert v["frames"] == 4 and v["motion"] == "trace" and v["bytes"] == (tmp_path / "b.html").stat().st_size


@pytest.mark.slow
def test_report_json(tmp_path, registry):
    d = check(run_json("report", "bennett", "--out", str(tmp_path / "rep")), "report", "bennett", registry)
    assert d["sections"] and json.loads((tmp_path / "rep" / "results.json").read_text())["title"] == d["title"]


@pytest.mark.slow
def test_demo_json(tmp_path, registry, demo_report, monkeypatch):
    """The command's JSON of the session's one demo run (the build itself is not repeated: the
    CLI's call of build_demo answers that run's results)."""
    import spatialmech.present.report as report_module

    _, results = demo_report
    calls = []
    monkeypatch.setattr(report_module, "build_demo", lambda out, progress: calls.append(out) or results)
    d = check(run_json("demo", "--out", str(tmp_path / "demo")), "demo", None, registry)
    assert calls == [tmp_path / "demo"]
    assert d["summary"]["claims"] == len(d["claims"]) > 0 and d["length_unit"] is None
    units = {s["key"]: s["length_unit"] for s in d["sections"]}
    assert (units["paper-a"], units["paper-b"], units["paper-d"]) == ("unit", "m", "mm")


# ------------------------------------------------------------------ the same shape for every model
def keys(d: dict) -> set[str]:
    return set(d)


def test_fk_closed_form_and_general_engine_give_the_same_fields():
    """Before: the closed form printed z_m, alpha_rad, ... and the general engine position,
    euler_ZYX_deg (issue 10).  Now both print the pose as position_len + a named Euler sequence
    in degrees + the rotation matrix, and agree on the pose they find."""
    closed = run_json("fk", "four-sps-cu", "--actuators", FK_ACTUATORS, "--all", "--seeds", "16")
    general = run_json("fk", "four-sps-cu", "--actuators", FK_ACTUATORS)
    other = run_json("fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2")
    assert keys(closed) == keys(general) == keys(other)
    assert keys(closed["solutions"][0]) == keys(general["solutions"][0]) == keys(other["solutions"][0])
    assert keys(closed["search"]) >= {"method", "n_seeds", "n_converged", "n_distinct"} <= keys(general["search"])
    assert closed["actuators_len"] == general["actuators_len"] and closed["actuators_deg"] == general["actuators_deg"] == {}
    # the general engine's mode is one of the closed form's, in the same units and sequence
    g = general["solutions"][0]["pose"]
    match = [s["pose"] for s in closed["solutions"]
             if np.allclose(s["pose"]["rotation_matrix"], g["rotation_matrix"], atol=1e-8)]
    assert len(match) == 1
    assert np.allclose(match[0]["position_len"], g["position_len"], atol=1e-9)
    assert np.allclose(match[0]["euler_deg"], g["euler_deg"], atol=1e-6)
    assert np.allclose(euler_matrix("ZYX", g["euler_deg"], degrees=True), g["rotation_matrix"], atol=1e-9)


@pytest.mark.slow
def test_ik_jacobian_workspace_give_the_same_fields_for_every_model():
    a = run_json("ik", "four-sps-cu", *POSE)
    b = run_json("ik", "delta", "--xyz", "0.02", "0.01", "-0.33")
    assert keys(a) == keys(b)
    sa, sb = a["limbs"][0]["solutions"][0], b["limbs"][0]["solutions"][0]
    assert keys(sa) == keys(sb) == {"joints_deg", "joints_len", "residual", "within_limits", "outside_limits",
                                    "certified", "certificate"}
    assert set(a["actuators_len"]) == {"L1.slide", "L2.slide", "L3.slide", "L4.slide"} and a["actuators_deg"] == {}
    assert set(b["actuators_deg"]) == {"R1.rot", "R2.rot", "R3.rot"} and b["actuators_len"] == {}

    j1 = run_json("jacobian", "four-sps-cu", *POSE)
    j2 = run_json("jacobian", "five-cs-1", "--position", "3", "--driver", "rot1")
    assert keys(j1) == keys(j2)

    closed = run_json("workspace", "four-sps-cu", "--orientation", "--at", "z=0.1,alpha=0,beta=0", "--step-deg", "30")
    general = run_json("workspace", "three-sps-smpu", "--orientation", "--at", "alpha=0,beta=0", "--step-deg", "60",
                       "--tol-deg", "1")
    assert (closed["path"], general["path"]) == ("closed-form", "general")
    assert keys(closed) == keys(general)
    assert keys(closed["extents"]) == keys(general["extents"]) == {"gamma_deg"}
    assert keys(closed["extents"]["gamma_deg"]) == keys(general["extents"]["gamma_deg"])


def test_singularity_angles_are_degrees_and_line_geometry_lengths_are_labelled():
    """Before: the line geometry's pair angles were printed as ``angle`` in radians."""
    d = run_json("singularity", "four-sps-cu", *POSE)
    lg = d["line_geometry"]
    pairs = [p for p in lg["pairs"] if "angle_deg" in p]
    assert pairs and all(0.0 <= p["angle_deg"] <= 90.0 + 1e-9 for p in pairs)
    assert "angle" not in json.dumps(lg).replace('"angle_deg"', "")  # no other angle field
    assert lg["length_scale_len"] > 0 and "units" not in lg


# ------------------------------------------------------------------ the rule can fail
@pytest.mark.parametrize("doc, problem", [
    ({"angle": 0.5}, "angle: an angle without the '_deg' suffix"),
    ({"solutions": [{"alpha_rad": 0.1}]}, "solutions[].alpha_rad: radians in JSON"),
    ({"pose": {"position": [0, 0, 1]}}, "pose.position: a number under a key with no unit suffix"),
    ({"length_unit": None, "x_len": 1.0}, "length_unit: *_len fields (x_len) without a length_unit"),
    ({"sections": [{"length_unit": None, "data": {"x_len": 1.0}}]}, "length_unit: *_len fields (sections[].data.x_len)"),
    ({"rank": {"point": [1, 2, 3], "n": 1}}, "rank.point: a number under a key with no unit suffix"),
])
def test_the_unit_rule_check_finds_violations(doc, problem):
    found = unit_rule_violations(doc)
    assert any(p.startswith(problem) for p in found), found


def test_the_unit_rule_check_accepts_the_documented_forms():
    assert unit_rule_violations({"sections": [{"length_unit": "mm", "data": {"x_len": 1.0}}]}) == []
    ok = {"length_unit": "mm", "actuators_len": {"L1.slide": 0.2}, "transmission": {"L1.slide": 0.8},
          "extents": {"alpha_deg": {"alone": [-1, 1]}}, "wrenches": [[1, 0, 0, 0, 0.2, 0]], "count": "3",
          "linkage": {"point": [0, 0, 0]}, "flag": True}
    assert unit_rule_violations(ok) == []


def test_a_schema_rejects_the_old_fields(registry):
    """The schemas are strict: the pre-issue-10 fk solution fields do not validate."""
    doc = run_json("fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2")
    doc["solutions"][0]["euler_ZYX_deg"] = doc["solutions"][0]["pose"].pop("euler_deg")
    v = Draft202012Validator(load_schema("fk"), registry=registry)
    assert not v.is_valid(doc)
    assert not v.is_valid({**doc, "schema_version": "1"})


def test_envelope_refuses_to_be_overwritten():
    with pytest.raises(ValueError, match="envelope"):
        envelope("fk", "x", {"model": "y"})
    with pytest.raises(TypeError, match="command"):
        envelope("", None, {})


@given(st.integers(0, 2**32 - 1), st.lists(st.floats(-1e3, 1e3), min_size=3, max_size=3))
def test_pose_dict_euler_angles_rebuild_its_rotation_matrix(seed, p):
    R = Rotation.random(random_state=seed).as_matrix()
    d = pose_dict(R, p)
    assert d["euler_sequence"] == "ZYX" and unit_rule_violations({"length_unit": "m", "pose": d}) == []
    assert np.allclose(euler_matrix("ZYX", d["euler_deg"], degrees=True), R, atol=1e-9)
    assert np.allclose(d["rotation_matrix"], R, atol=1e-14) and np.allclose(d["position_len"], p, atol=1e-12)


# ------------------------------------------------------------------ the schema is written down
def command_paths(group=cli, prefix=""):
    for name, cmd in group.commands.items():
        if hasattr(cmd, "commands"):
            yield from command_paths(cmd, f"{prefix}{name} ")
        else:
            yield f"{prefix}{name}"


def test_every_command_has_a_schema_and_a_section_in_docs_json():
    text = (DOCS / "json.md").read_text()
    for command in command_paths():
        schema = load_schema(command)
        assert schema["$id"].endswith(schema_file_name(command))
        assert f"### `{command}`" in text, command
    assert "(json.md)" in (DOCS / "index.md").read_text()


def table_keys(text: str, heading: str) -> set[str]:
    """The first-column keys of the markdown table under ``heading``."""
    part = text.split(heading, 1)[1].split("\n## ", 1)[0]
    return {m.group(1) for m in re.finditer(r"^\| `([^`]+)` \|", part, flags=re.M)}


def test_docs_json_lists_the_unit_free_keys_suffixes_and_screws():
    text = (DOCS / "json.md").read_text()
    assert table_keys(text, "## Unit suffixes") == set(UNIT_SUFFIXES)
    assert table_keys(text, "## Unit-free keys") == set(UNIT_FREE_KEYS)
    assert table_keys(text, "## Screws") == set(SCREW_KEYS)
    assert all(f"`{k}`" in text for k in EMBEDDED_KEYS)
