"""Independent validation in MuJoCo (analysis/validation.py, ``spatialmech validate``): the
exported model, driven through a motion of the library, reproduces the library's forward
position; the check fails when the exported geometry is wrong or the simulator leaves the
library's branch."""

import json
import sys

import numpy as np
import pytest
from click.testing import CliRunner
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

from spatialmech import catalog
from spatialmech.analysis import validation as V
from spatialmech.errors import InputError
from spatialmech.exchange import mjcf
from spatialmech.geometry.rotations import matrix_euler, rotation_angle
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.common import load_schema
from spatialmech.kinematics.closed_forms import four_sps_cu as k4
from spatialmech.kinematics.closed_forms.four_sps_cu_paper import cone_trajectory
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.position import configuration_at_pose
from spatialmech.model.mechanism import Pose
from spatialmech.serialize import unit_rule_violations
from tests.test_exchange import flipped_graph


def run(*args):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


def within(r: V.ValidationResult, tol: float = 1e-8) -> None:
    """Passed: every pose settled on the library's branch, errors at most tol L and tol rad."""
    L = r.mechanism.characteristic_length
    assert r.passed and not r.branch_switches and all(p.settled for p in r.poses)
    assert r.max_position_error <= tol * L and r.max_orientation_error <= tol, (r.max_position_error, r.max_orientation_error)


def cone_legs(t0: float, t1: float, n: int):
    """Paper B's demonstration trajectory (four_sps_cu_paper.cone_trajectory) between t0 and t1
    s: its start pose and leg lengths.  On [0.3, 0.75] s it stays clear of singularities (the
    whole 2 s trajectory crosses direct singularities near t = 0.265, 0.79, 1.225, 1.705 s)."""
    phi = cone_trajectory(np.linspace(t0, t1, n))[0]
    T = k4.pose_transform(phi[0])
    return Pose(T[:3, :3], T[:3, 3]), k4.leg_lengths(phi)


# ------------------------------------------------------------------ the papers' mechanisms
def test_four_sps_cu_along_paper_b_trajectory():
    start, legs = cone_legs(0.3, 0.75, 8)
    r = V.validate(catalog.build("four-sps-cu"), actuator_path=legs, start=start)
    within(r)
    assert r.motion == "actuators" and [p.label for p in r.poses] == [f"row {k}" for k in range(1, 9)]
    assert max(p.residual for p in r.poses) < 1e-13  # MuJoCo's own constraints, solved to round-off
    # the library's poses are the closed form's (the paper's trajectory itself)
    phi = cone_trajectory(np.linspace(0.3, 0.75, 8))[0]
    for p, ph in zip(r.poses, phi, strict=True):
        T = k4.pose_transform(ph)
        assert np.allclose(p.library.p, T[:3, 3], atol=1e-10) and np.allclose(p.library.R, T[:3, :3], atol=1e-10)


def test_four_sps_cu_settles_quasi_statically():
    """The settle method: position actuators, damping, stepped until at rest (measured: pose
    errors about 2e-11 m on a loop from a non-singular pose)."""
    start = Pose.from_euler("ZYX", [0.3, 0.3, 0.3], [0, 0, 0.12])
    r = V.validate(catalog.build("four-sps-cu"), "loop", start=start, frames=4, method="settle")
    within(r)
    assert all(p.iterations > 100 for p in r.poses[1:])  # time steps, not a projection


@pytest.mark.slow
def test_five_cs_3_driven_by_rot1_from_p1_to_p7():
    mech = catalog.build("five-cs-3")
    r = V.validate(mech, "trace", start=mech.positions[0], to_position=7)
    within(r)
    assert (r.poses[0].label, r.poses[-1].label) == ("P1", "P7")
    # the last pose is task position 7 fitted onto the closure (the printed, rounded table-9 pose
    # is 0.065 units, 0.4 % of the characteristic length, from the linkage's circuit)
    P7 = mech.positions[6]
    assert np.linalg.norm(r.poses[-1].simulated.p - P7.p) < 0.01 * mech.characteristic_length
    rot1 = [p.actuators["C1.rot"] for p in r.poses]
    assert np.all(np.diff(rot1) < 0)  # rot1 turns one way from P1 to P7: no branch point on the way
    assert [p.label for p in r.poses if p.label.startswith("P")] == [f"P{n}" for n in range(1, 8)]
    assert not any("turns back" in n for n in r.notes)


@pytest.mark.slow
def test_five_cs_1_driven_by_rot1_switches_branch_at_its_branch_point():
    """Paper A, fig 14: rot1 of linkage 1 has a branch point K2 between P6 and P7.  The library's
    path passes it (the driver turns back); MuJoCo driven quasi-statically by rot1 cannot follow
    and leaves the path there, as ADAMS would: flagged, and the validation fails."""
    mech = catalog.build("five-cs-1")
    r = V.validate(mech, "trace", start=mech.positions[0], to_position=7, method="settle")
    labels = [p.label for p in r.poses]
    [note] = [n for n in r.notes if "turns back" in n]
    after = labels.index(note.split(" and ")[1].split(" (")[0])
    assert labels.index("P6") < after <= labels.index("P7")
    assert not r.passed and r.branch_switches and labels.index(r.branch_switches[0]) == after
    assert all(not p.branch_switched for p in r.poses[:after])  # on the library's path up to K2
    assert max(p.position_error for p in r.poses[:after]) < 1e-8 * mech.characteristic_length


@pytest.mark.parametrize("mode, motion", [("R1", "trace"), ("R1+R4", "loop"), ("R1+R4+R7", "loop")])
def test_three_rrr_sm_in_each_configuration(mode, motion):
    """The 3-RRR joint with one, two and three actuators (1R, 2R, 3R: paper C's configurations)."""
    r = V.validate(catalog.build("three-rrr-sm"), mode=mode, frames=5)
    within(r)
    assert r.motion == motion and r.mode == mode and len(r.mechanism.actuators) == mode.count("+") + 1
    assert max(np.degrees(p.orientation_error) for p in r.poses) < 1e-9
    moved = max(np.degrees(rotation_angle(p.library.R)) for p in r.poses)
    assert moved > 1.0  # the platform did turn


def test_stewart_platform():
    r = V.validate(catalog.build("stewart-6sps"), frames=6)
    within(r)
    assert r.motion == "loop" and r.max_position_error < 1e-12


# ------------------------------------------------------------------ link-and-joint graphs (issue 11)
def test_clavel_delta():
    """The Delta with its parallelograms (3 R + 12 S, 5 loops): its three arms driven round a
    loop from a generic configuration; the platform translates without turning, in MuJoCo as in
    the library, and the arms (internal bodies) are where the library puts them."""
    mech = catalog.build("delta")
    start = generic_configuration(mech, seed=3, step=0.3)
    r = V.validate(mech, start=start, frames=6, amplitude=0.05)
    within(r)
    assert r.motion == "loop" and len(r.poses) == 6 and r.max_position_error < 1e-12
    assert max(rotation_angle(p.library.R) for p in r.poses) < 1e-9  # 3T: the platform never turns
    assert max(rotation_angle(p.simulated.R) for p in r.poses) < 1e-9
    moved = max(np.linalg.norm(p.library.p - r.poses[0].library.p) for p in r.poses)
    assert moved > 0.01 * mech.characteristic_length
    assert max(p.joint_deviation for p in r.poses) < 1e-9
    assert not any("turns back" in n for n in r.notes)  # round a loop the actuators turn back by design


def test_spatial_six_bar_and_its_internal_body():
    """Two RSSR loops sharing the rocker (an internal body), the follower as output link: traced
    by the crank.  The simulator's rocker is compared with the library's too."""
    mech = catalog.build("spatial-six-bar")
    r = V.validate(mech, frames=6)
    within(r)
    assert r.motion == "trace" and r.mechanism.output == "follower"
    turned = max(np.degrees(rotation_angle(p.library.R)) for p in r.poses)
    assert turned > 1.0  # the follower did turn
    sim = V.MujocoSimulator(mech)
    a, b = (generic_configuration(mech, seed=s, step=0.3) for s in (1, 2))
    sim.set_configuration(a)
    assert sim.body_deviation(a) < 1e-12 < 1e-3 < sim.body_deviation(b)


def test_graph_with_joints_described_backwards():
    """Flipped S, R and U joints, a loop closed by a weld, an output point off the pivot."""
    r = V.validate(flipped_graph(), frames=5, arc=1.0)
    within(r)
    assert max(np.degrees(rotation_angle(p.library.R)) for p in r.poses) > 5.0  # the follower turned
    assert max(np.linalg.norm(p.library.p - r.poses[0].library.p) for p in r.poses) > 0.01  # and its point moved


def test_cli_validates_the_delta():
    r = run("validate", "delta", "--poses", "4", "--json")
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["passed"] and doc["model"] == "delta" and doc["motion"] == "loop" and doc["n_poses_checked"] == 4
    assert doc["max_position_error_len"] < 1e-8 * doc["characteristic_length_len"]


# ------------------------------------------------------------------ the check can fail
def test_a_wrong_export_is_caught(monkeypatch):
    """A base ball joint placed 1e-6 L off in the exported file: the validation reports errors of that
    order, far above its tolerance, and fails."""
    mech = catalog.build("stewart-6sps")
    L = mech.characteristic_length
    good = mjcf.to_mjcf

    def shifted(model):
        text = good(model)
        key = 'name="B3" type="ball" pos="'
        head, tail = text.split(key, 1)
        x, rest = tail.split(" ", 1)
        return head + key + repr(float(x) + 1e-6 * L) + " " + rest

    monkeypatch.setattr(mjcf, "to_mjcf", shifted)
    r = V.validate(mech, frames=4)
    assert not r.passed and 1e-8 * L < r.max_position_error < 1e-4 * L


def test_a_wrong_graph_export_is_caught(monkeypatch):
    """A Delta whose platform-side ball W2a is 1e-5 L off in the exported file (a cut joint: a
    connect equality's anchor): one rod of a parallelogram longer than the other, so that the
    platform turns a little (measured: 5e-7 rad); caught."""
    mech = catalog.build("delta")
    L = mech.characteristic_length
    good = mjcf.to_mjcf

    def shifted(model):
        text = good(model)
        key = 'name="connect:W2a" body1="rod2a" body2="platform" anchor="'
        head, tail = text.split(key, 1)
        x, rest = tail.split(" ", 1)
        return head + key + repr(float(x) + 1e-5 * L) + " " + rest

    monkeypatch.setattr(mjcf, "to_mjcf", shifted)
    r = V.validate(mech, frames=4)
    assert not r.passed and all(p.settled for p in r.poses)
    assert 1e-8 < r.max_orientation_error < 1e-4 and r.max_position_error < 1e-4 * L


def test_a_branch_switch_is_flagged(monkeypatch):
    """The simulator started in another assembly mode (the mirror image below the base) stays
    there: every pose is flagged, and the validation fails."""
    mech = catalog.build("four-sps-cu")
    start = Pose.from_euler("ZYX", [0.3, 0.3, 0.3], [0, 0, 0.12])
    mirror = Pose(start.R, -start.p)
    real = V.library_motion

    def motion(*args, **kw):
        poses = real(*args, **kw)
        other = configuration_at_pose(mech, mirror).config
        return [V.LibraryPose(poses[0].label, other, poses[0].actuators), *poses[1:]]

    monkeypatch.setattr(V, "library_motion", motion)
    r = V.validate(mech, "loop", start=start, frames=3)
    assert not r.passed and len(r.branch_switches) == 3
    assert r.max_position_error > 0.1 * mech.characteristic_length


def test_missing_mujoco_is_an_input_error(monkeypatch):
    monkeypatch.setitem(sys.modules, "mujoco", None)  # import mujoco raises ImportError
    with pytest.raises(InputError, match="pip install"):
        V.validate(catalog.build("rssr"))


@pytest.mark.parametrize("kw, message", [
    ({"method": "dynamics"}, "method"),
    ({"motion": "wiggle"}, "motion"),
    ({"motion": "trace", "mode": "R1+R4"}, "one actuator"),
    ({"motion": "actuators"}, "actuator_path"),
    ({"tol": -1.0}, "tol"),
    ({"mode": "R1", "to_position": 2}, "task positions"),
])
def test_bad_arguments_name_themselves(kw, message):
    kw = dict(kw)
    motion = kw.pop("motion", None)
    with pytest.raises(InputError, match=message):
        V.validate(catalog.build("three-rrr-sm"), motion, **kw)


# ------------------------------------------------------------------ command line
def test_cli_text_and_json(tmp_path):
    r = run("validate", "three-rrr-sm", "--mode", "R1+R4", "--poses", "4")
    assert r.exit_code == 0, r.output
    assert "PASSED" in r.output and "orientation error (deg)" in r.output and "MuJoCo" in r.output
    out = tmp_path / "sim.xml"
    r = run("validate", "three-rrr-sm", "--mode", "R1", "--poses", "3", "--json", "--mjcf", str(out))
    doc = json.loads(r.output)
    common = load_schema("common")
    registry = Registry().with_resource(common["$id"], Resource.from_contents(common))
    Draft202012Validator(load_schema("validate"), registry=registry).validate(doc)
    assert unit_rule_violations(doc) == []
    assert (doc["command"], doc["model"], doc["mode"], doc["length_unit"]) == ("validate", "three-rrr-sm", "R1", "m")
    assert doc["passed"] and doc["n_poses_checked"] == len(doc["poses"]) == 3
    assert doc["max_position_error_len"] <= 1e-8 and doc["max_orientation_error_deg"] <= np.degrees(1e-8)
    assert out.read_text().startswith('<mujoco model="three-rrr-sm">')


def test_cli_actuator_path_file(tmp_path):
    start, legs = cone_legs(0.4, 0.6, 4)
    f = tmp_path / "legs.csv"
    f.write_text("# paper B, t = 0.4 .. 0.6 s\nL2.slide,L1.slide,L3.slide,L4.slide\n"
                 + "\n".join(",".join(repr(float(x)) for x in row[[1, 0, 2, 3]]) for row in legs) + "\n")
    ang = matrix_euler("ZYX", start.R, degrees=True)
    pose = ",".join(repr(float(x)) for x in start.p) + ",ZYX," + ",".join(repr(float(x)) for x in ang)
    r = run("validate", "four-sps-cu", "--actuators-path", str(f), "--pose", pose, "--json")
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["passed"] and doc["motion"] == "actuators" and len(doc["poses"]) == 4
    assert doc["poses"][1]["actuators_len"]["L1.slide"] == pytest.approx(legs[1][0])


@pytest.mark.parametrize("text, message", [
    ("rot1\n10\n", "rotation: give it in degrees"),
    ("rot1_deg,rot2_deg\n1,2\n", "not an actuator"),
    ("rot1_deg\nten\n", "not a number"),
    ("rot1_deg\n", "at least one row"),
    ("nope_deg\n1\n", "unknown freedom"),
])
def test_cli_actuator_path_errors(tmp_path, text, message):
    f = tmp_path / "p.csv"
    f.write_text(text)
    r = run("validate", "five-cs-3", "--actuators-path", str(f))
    assert r.exit_code == 2 and message in r.output
