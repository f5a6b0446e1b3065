"""Posing lower-mobility mechanisms by task coordinates (issue 11): the 3-RPS / 3-PRS parasitic
motion against its closed form, ik --free and fk round trips, the task Jacobian against finite
differences."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech import catalog
from spatialmech.catalog import classic
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closed_forms.three_rps import parasitic
from spatialmech.geometry.rotations import matrix_euler
from spatialmech.kinematics.task import solve_task, task_jacobian


@pytest.mark.parametrize("build, rp, zs", [
    (classic.three_rps, 0.15, (0.26, 0.3, 0.34)),
    (classic.three_prs, 0.15, (0.26, 0.3, 0.34)),
    (lambda: classic.three_rps(rb=0.4, rp=0.22, h=0.35), 0.22, (0.3, 0.38)),  # not the defaults
])
def test_parasitic_motion_matches_the_closed_form(build, rp, zs):
    """Each S centre stays in its leg's radial plane: x, y and a1 (ZYX) depend on the tilts
    only (not on z), a1 = atan2(sin a2 sin a3, cos a2 + cos a3); engine vs closed form to 1e-10."""
    m = build()
    tilts = np.radians(np.linspace(-20.0, 20.0, 7))
    worst = 0.0
    for z in zs:
        seed = None
        for a2 in tilts:
            for a3 in tilts:
                r = solve_task(m, {"z": z, "a2": a2, "a3": a3}, seed=seed)
                assert r.converged
                seed = r.config
                x, y, a1 = parasitic(rp, a2, a3)
                worst = max(worst, abs(r.values["x"] - x), abs(r.values["y"] - y), abs(r.values["a1"] - a1))
    assert worst < 1e-10


@pytest.mark.parametrize("name, pose, free", [
    ("three-rps", ([0.0, 0.0, 0.33], ("ZYX", 0.0, 5.0, 5.0)), ["x", "y", "a1"]),
    ("three-prs", ([0.0, 0.0, 0.31], ("ZYX", 0.0, -6.0, 4.0)), ["x", "y", "a1"]),
    ("three-upu", ([0.02, -0.01, 0.31], ("ZYX", 3.0, 2.0, 1.0)), ["a1", "a2", "a3"]),
    ("delta", ([0.02, -0.01, -0.33], ("ZYX", 3.0, 2.0, 1.0)), ["a1", "a2", "a3"]),
])
def test_ik_with_free_coordinates_then_fk_returns_the_pose(name, pose, free):
    r = sm.ik(name, pose, degrees=True, free=free)
    assert r.reachable and r.task is not None and r.task.converged
    assert set(r.task.solved) == set(free)
    held = [n for n in ("x", "y", "z") if n not in free]
    for n in held:
        assert abs(r.task.values[n] - pose[0]["xyz".index(n)]) < 1e-12
    if name in ("three-upu", "delta"):  # translational: the solved rotations are zero
        assert max(abs(r.task.values[a]) for a in ("a1", "a2", "a3")) < 1e-9
    f = sm.fk(name, list(r.actuators.values()))
    p = f.poses[0]
    assert np.allclose(p.p, r.pose.p, atol=1e-9) and np.allclose(p.R, r.pose.R, atol=1e-9)


def test_cli_ik_free_prints_given_and_solved():
    out = CliRunner().invoke(cli, ["ik", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,y,a1", "--json"])
    assert out.exit_code == 0, out.output
    d = json.loads(out.output)
    t = d["task"]
    assert t["given"] == ["z", "a2", "a3"] and t["solved"] == ["x", "y", "a1"] and t["converged"]
    x, y, a1 = parasitic(0.15, np.radians(5.0), np.radians(5.0))
    assert abs(t["values_len"]["x"] - x) < 1e-10 and abs(t["values_len"]["y"] - y) < 1e-10
    assert abs(t["values_deg"]["a1"] - np.degrees(a1)) < 1e-8
    assert d["reachable"]
    text = CliRunner().invoke(cli, ["ik", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5"]).output
    assert "NOT reachable" in text and "--free x,y,a1" in text  # the suggestion
    bad = CliRunner().invoke(cli, ["ik", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,,a1"])
    assert bad.exit_code == 2 and "--free" in bad.output
    bad = CliRunner().invoke(cli, ["ik", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,q"])
    assert bad.exit_code == 2 and "'q'" in bad.output


@pytest.mark.parametrize("name, given", [
    ("three-rps", {"z": 0.33, "a2": 0.1, "a3": -0.05}),
    ("three-prs", {"z": 0.3, "a2": -0.08, "a3": 0.12}),
    ("delta", {"x": 0.02, "y": -0.01, "z": -0.33}),
])
def test_task_jacobian_matches_finite_differences(name, given):
    m = catalog.build(name)
    s = solve_task(m, given)
    J, acts, names = task_jacobian(m, s)
    assert J.shape == (len(acts), len(given)) == (3, 3)
    idx = [m.freedom_refs.index(m.freedom(a)) for a in acts]
    h = 1e-6
    cols = []
    for n in names:
        up, dn = dict(given), dict(given)
        up[n] += h
        dn[n] -= h
        cols.append((solve_task(m, up, seed=s.config).config.q[idx] - solve_task(m, dn, seed=s.config).config.q[idx]) / (2 * h))
    assert np.allclose(J, np.array(cols).T, atol=1e-7)


def test_parasitic_command_tabulates_and_plots(tmp_path):
    f = tmp_path / "p.png"
    out = CliRunner().invoke(cli, ["parasitic", "three-rps", "--over", "a2:-10:10:3,a3:-10:10:3", "--at", "z=0.3",
                                   "--plot", str(f), "--json"])
    assert out.exit_code == 0, out.output
    d = json.loads(out.output)
    assert d["task"]["solved"] == ["x", "y", "a1"] and d["n_converged"] == d["cells"] == 9
    a2, a3 = np.meshgrid(np.radians([-10.0, 0.0, 10.0]), np.radians([-10.0, 0.0, 10.0]), indexing="ij")
    x, y, a1 = parasitic(0.15, a2.ravel(), a3.ravel())
    assert np.allclose(d["solved_values"]["x_len"], x, atol=1e-10)
    assert np.allclose(d["solved_values"]["y_len"], y, atol=1e-10)
    assert np.allclose(d["solved_values"]["a1_deg"], np.degrees(a1), atol=1e-8)
    assert f.stat().st_size > 1000
    bad = CliRunner().invoke(cli, ["parasitic", "three-rps", "--over", "q:0:1:3"])
    assert bad.exit_code == 2 and "--over" in bad.output


# ------------------------------------------------------------------ jacobian: the input-output Jacobian
def _fd_task_jacobian(m, given: dict, acts, h=1e-6):
    """d actuators / d given coordinates by central differences of solve_task (SI, rad)."""
    s = solve_task(m, given)
    assert s.converged
    idx = [m.freedom_refs.index(m.freedom(a)) for a in acts]
    cols = []
    for n in given:
        up, dn = dict(given), dict(given)
        up[n] += h
        dn[n] -= h
        qu, qd = (solve_task(m, g, seed=s.config) for g in (up, dn))
        assert qu.converged and qd.converged
        cols.append((qu.config.q[idx] - qd.config.q[idx]) / (2 * h))
    return np.array(cols).T


@pytest.mark.parametrize("name, args", [
    ("three-rps", ["--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,y,a1"]),
    ("three-prs", ["--pose", "0,0,0.31,ZYX,0,-6,4", "--free", "x,y,a1"]),
    ("three-upu", ["--pose", "0.02,-0.01,0.31,ZYX,0,0,0", "--free", "a1,a2,a3"]),
    ("delta", ["--xyz", "0.02", "-0.01", "-0.33"]),  # reachable as it is: the pose is not fitted
])
def test_cli_jacobian_adds_the_input_output_jacobian(name, args):
    """``jacobian --json`` of a lower-mobility model: task_jacobian.io_matrix (nondimensional),
    restored to SI with characteristic_length_len, equals finite differences of solve_task at the
    pose's given coordinates; the text output prints it too."""
    m = catalog.build(name)
    out = CliRunner().invoke(cli, ["jacobian", name, *args, "--json"])
    assert out.exit_code == 0, out.output
    d = json.loads(out.output)
    t = d["task_jacobian"]
    want_given = ["x", "y", "z"] if name in ("three-upu", "delta") else ["z", "a2", "a3"]
    assert t["given"] == want_given and t["euler"] == "ZYX" and t["actuators"] == list(m.actuators)
    L = t["characteristic_length_len"]
    assert abs(L - m.characteristic_length) < 1e-12
    rows = np.array([L if m.freedom(a).freedom.kind == "P" else 1.0 for a in t["actuators"]])
    cols = np.array([L if n in ("x", "y", "z") else 1.0 for n in t["given"]])
    J = np.array(t["io_matrix"]) * rows[:, None] / cols[None, :]
    R = np.array(d["pose"]["rotation_matrix"])
    values = dict(zip(("x", "y", "z", "a1", "a2", "a3"),
                      [*d["pose"]["position_len"], *matrix_euler("ZYX", R)], strict=True))
    fd = _fd_task_jacobian(m, {n: values[n] for n in t["given"]}, t["actuators"])
    assert np.allclose(J, fd, rtol=1e-6, atol=1e-7 * np.abs(fd).max())
    text = CliRunner().invoke(cli, ["jacobian", name, *args]).output
    assert "input-output Jacobian over the task" in text and f"solved {', '.join(t['solved'])}" in text


def test_jacobian_task_part_is_null_at_six_freedoms_and_free_is_checked():
    d = json.loads(CliRunner().invoke(cli, ["jacobian", "stewart-6sps", "--xyz", "0", "0", "1.05", "--json"]).output)
    assert d["task_jacobian"] is None
    bad = CliRunner().invoke(cli, ["jacobian", "five-cs-3", "--dj-table", "--free", "x"])
    assert bad.exit_code == 2 and "--free" in bad.output
    bad = CliRunner().invoke(cli, ["jacobian", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,,a1"])
    assert bad.exit_code == 2 and "--free" in bad.output


def test_sm_jacobian_free_matches_the_cli_and_finite_differences():
    pose = ([0.0, 0.0, 0.33], ("ZYX", 0.0, 5.0, 5.0))
    J = sm.jacobian("three-rps", pose, degrees=True, free=["x", "y", "a1"])
    assert J.task is not None and J.task.given == ("z", "a2", "a3") and J.pose_fit.exact
    given = {"z": 0.33, "a2": np.radians(5.0), "a3": np.radians(5.0)}
    fd = _fd_task_jacobian(catalog.build("three-rps"), given, J.task.actuators)
    assert np.allclose(J.task.matrix, fd, rtol=1e-6, atol=1e-9)
    cli_doc = json.loads(CliRunner().invoke(cli, ["jacobian", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free",
                                                  "x,y,a1", "--json"]).output)
    assert np.allclose(J.to_dict()["task_jacobian"]["io_matrix"], cli_doc["task_jacobian"]["io_matrix"], atol=1e-12)
    assert sm.jacobian("stewart-6sps").task is None
    with pytest.raises(sm.InputError, match="free"):
        sm.jacobian("three-rps", free=["x", "y", "a1"])  # no pose to hold


# ------------------------------------------------------------------ sm.parasitic
def test_sm_parasitic_matches_the_closed_form_and_plots(tmp_path):
    a2 = np.radians(np.linspace(-20.0, 20.0, 5))
    t = sm.parasitic("three-prs", {"a2": a2, "a3": (-0.3, 0.3, 4)}, at={"z": 0.3}, plot=tmp_path / "p.svg")
    assert t.solved == ("x", "y", "a1") and t.grid.converged.all()
    A2, A3 = np.meshgrid(a2, np.linspace(-0.3, 0.3, 4), indexing="ij")
    x, y, a1 = parasitic(0.15, A2, A3)
    assert np.abs(t.values("x") - x).max() < 1e-10 and np.abs(t.values("y") - y).max() < 1e-10
    assert np.abs(t.values("a1") - a1).max() < 1e-10
    assert t.ranges["a1"] == pytest.approx((a1.min(), a1.max()), abs=1e-10)
    assert (tmp_path / "p.svg").stat().st_size > 1000
    d = json.loads(json.dumps(t.to_dict(), allow_nan=False))
    assert d["held"] == {"z_len": 0.3} and d["axes"]["a2_deg"] == pytest.approx([-20, -10, 0, 10, 20])
    assert np.allclose(d["solved_values"]["a1_deg"], np.degrees(a1).ravel(), atol=1e-8)


@pytest.mark.parametrize("name, over, at", [("three-upu", "x:-0.05:0.05:3,y:-0.05:0.05:3", "z=0.31"),
                                            ("delta", "x:-0.05:0.05:3,y:-0.05:0.05:3", "z=-0.33")])
def test_parasitic_rotations_of_the_translational_models_are_zero(name, over, at):
    out = CliRunner().invoke(cli, ["parasitic", name, "--over", over, "--at", at, "--json"])
    assert out.exit_code == 0, out.output
    d = json.loads(out.output)
    assert d["task"]["solved"] == ["a1", "a2", "a3"] and d["n_converged"] == 9
    for k in ("a1_deg", "a2_deg", "a3_deg"):
        assert max(abs(v) for v in d["solved_values"][k]) < 1e-8


def test_sm_parasitic_checks_its_arguments():
    with pytest.raises(TypeError, match="over"):
        sm.parasitic("three-rps", [("a2", -0.1, 0.1, 3)])
    with pytest.raises(sm.InputError, match="free"):
        sm.parasitic("three-rps", {"a2": (-0.1, 0.1, 3)}, free=["x", "q"])
    with pytest.raises(sm.InputError, match="over"):
        sm.parasitic("three-rps", {"a2": (-0.1, 0.1, 3), "a3": (0, 1, 2), "z": (0.3, 0.31, 2)})
    with pytest.raises(sm.InputError, match="plot"):
        sm.parasitic("three-rps", {"a2": (-0.1, 0.1, 3)}, plot="p.txt")
    with pytest.raises(sm.InputError, match="x"):  # x is solved (parasitic) for a 3-RPS: it cannot be a grid axis
        sm.parasitic("three-rps", {"x": (-0.1, 0.1, 3)}, at={"z": 0.33})
