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
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closed_forms.three_rps import parasitic
from spatialmech.kinematics.task import solve_task, task_jacobian


@pytest.mark.parametrize("name", ["three-rps", "three-prs"])
def test_parasitic_motion_matches_the_closed_form(name):
    """Each S centre stays in its leg's radial plane: x, y and a1 (ZYX) depend on the tilts
    only (not on z), a1 = atan2(sin a2 sin a3, cos a2 + cos a3); engine vs closed form to 1e-10."""
    m = catalog.build(name)
    tilts = np.radians(np.linspace(-20.0, 20.0, 7))
    worst = 0.0
    for z in (0.26, 0.3, 0.34):
        seed = None
        for a2 in tilts:
            for a3 in tilts:
                r = solve_task(m, {"z": z, "a2": a2, "a3": a3}, seed=seed)
                assert r.converged
                seed = r.config
                x, y, a1 = parasitic(0.15, a2, a3)
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
