"""Issue 30, items 4 and 5: task coordinates are checked (counts), a far task target is reached by
continuation from the reference, the ik headline says what was proven, plausibility warnings
(units, negative leg lengths, no joint limits) and models read from MJCF."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.task import default_task, solve_task, task_values

POSE = ([0, 0, 0.33], ("ZYX", 0, 5, 5))


def run(*args):
    return CliRunner().invoke(cli, list(args))


# ------------------------------------------------------------------ (a) counts of task coordinates
@pytest.mark.parametrize("free, given, what", [(["x", "y"], 4, "over-determined"),
                                               (["x", "y", "a1", "z"], 2, "under-determined")])
def test_free_count_refused_naming_counts(free, given, what):
    with pytest.raises(sm.InputError) as e:
        sm.ik("three-rps", POSE, degrees=True, free=free)
    msg = str(e.value)
    assert msg.startswith("free (--free):") and "has 3 freedoms" in msg and what in msg
    assert f"solves {len(free)} and leaves {given} given" in msg and "--free x,y,a1" in msg
    out = run("ik", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", ",".join(free))
    assert out.exit_code == 2 and "--free" in out.output and f"leaves {given} given" in out.output
    assert "reachable" not in out.output
    with pytest.raises(sm.InputError, match="has 3 freedoms"):
        sm.jacobian("three-rps", POSE, degrees=True, free=free)


def test_free_on_a_six_freedom_output_refused():
    out = run("ik", "stewart-6sps", "--pose", "0,0,1.08,ZYX,0,0,0", "--free", "x")
    assert out.exit_code == 2 and "6 freedoms" in out.output and "give no --free" in out.output


# ------------------------------------------------------------------ (b) headline, (c) continuation
FAR_PRS = "0,0,0.791,ZYX,0,70.19,-76.37"  # three-prs: the solve fails, the continuation stops short


def test_ik_headline_reflects_a_failed_task_solve():
    r = sm.ik("three-prs", ([0, 0, 0.791], ("ZYX", 0, 70.19, -76.37)), degrees=True, free=["x", "y", "a1"])
    assert r.task is not None and not r.task.converged and not r.reachable
    d = r.to_dict()
    assert d["reachable"] is False and 0.0 <= d["task"]["continuation_fraction"] < 1.0
    out = run("ik", "three-prs", "--pose", FAR_PRS, "--free", "x,y,a1")
    assert out.exit_code == 0, out.output
    head = out.output.splitlines()[0]
    assert "pose reachable" not in head and "NOT reachable" not in head
    assert "not found from the reference" in head and "continuation from the reference pose failed at s=" in head


def test_fk_far_assembly_modes_found_by_ik_through_continuation():
    """fk --all of a 3-UPU returns modes below the base; where the solve from the reference does
    not reach them, the continuation from the reference pose does. (Since small S/U rotations
    move the chain to first order, the Newton solve reaches this pose directly.)"""
    m = sm.load_model("three-upu")
    r = sm.ik(m, ([0.0336, -0.0856, -0.5516], None), free=["a1", "a2", "a3"])
    assert r.reachable and r.task.continuation in (None, 1.0)
    f = sm.fk(m, list(r.actuators.values()), all_solutions=True)
    task = default_task(m)
    continued = 0
    for mode in f.modes:
        v = task_values(m, mode.pose.displacement(m.platform_point))
        direct = solve_task(m, {n: float(v[k]) for k, n in enumerate(("x", "y", "z")) if n in task.given}, task=task)
        back = sm.ik(m, mode.pose, free=["a1", "a2", "a3"])
        assert back.reachable, mode.pose.p
        assert np.allclose(back.pose.p, mode.pose.p, atol=1e-8)  # the given x, y, z (the orientation is solved)
        if not direct.converged:
            continued += 1
            assert back.task.continuation == 1.0
    assert continued >= 2
    out = run("ik", "three-upu", "--xyz", "0.0336", "-0.0856", "-0.5516", "--free", "a1,a2,a3", "--json")
    d = json.loads(out.output)
    assert d["reachable"] and d["task"]["continuation_fraction"] in (None, 1.0)


# ------------------------------------------------------------------ (d) plausibility
def test_fk_far_from_the_model_size_warns_of_units():
    r = sm.fk("stewart-6sps", [1200.0] * 6)
    assert r.converged and any("is the unit of the values wrong" in w for w in r.warnings)
    assert r.to_dict()["warnings"] == r.warnings
    out = run("fk", "stewart-6sps", "--actuators", "1200,1200,1200,1200,1200,1200")
    assert out.exit_code == 0 and "warning: platform point" in out.output and "unit" in out.output
    assert "no joint limits in the model" in out.output and "within limits" not in out.output
    assert sm.fk("stewart-6sps", [1.2] * 6).warnings == []


def test_ik_negative_leg_length_warns_without_limits():
    r = sm.ik("stewart-6sps", ([0, 0, -1], ("ZYX", 0, 0, 0)), degrees=True)
    assert any(w.startswith("negative leg length") for w in r.warnings)
    out = run("ik", "stewart-6sps", "--xyz", "0", "0", "-1", "--euler", "ZYX", "0", "0", "0", "--json")
    assert any("negative leg length" in w for w in json.loads(out.output)["warnings"])
    out = run("ik", "stewart-6sps", "--xyz", "0", "0", "-1", "--euler", "ZYX", "0", "0", "0")
    assert "warning: negative leg length" in out.output
    assert sm.ik("stewart-6sps", ([0, 0, 1.08], None)).warnings == []


# ------------------------------------------------------------------ (e) models from MJCF / URDF
def test_model_from_mjcf_and_urdf_refused(tmp_path):
    xml, urdf = tmp_path / "rssr.xml", tmp_path / "rssr.urdf"
    assert run("export", "rssr", str(xml)).exit_code == 0 and run("export", "rssr", str(urdf)).exit_code == 0
    m = sm.load_model(xml)
    assert m.name == "rssr" and sm.mobility(xml).dof == sm.mobility("rssr").dof
    out = run("mobility", str(xml))
    assert out.exit_code == 0 and "not valid TOML" not in out.output
    out = run("mobility", str(urdf))
    assert out.exit_code == 2 and "URDF" in out.output and ".xml" in out.output and "not valid TOML" not in out.output
    with pytest.raises(sm.InputError, match="URDF"):
        sm.load_model(urdf)


def test_headline_never_reachable_when_the_task_solve_failed(capsys):
    """The limbs close at the pose asked for, the task solve did not converge: not 'reachable'."""
    from dataclasses import replace

    from spatialmech.interfaces.cmd_kinematics import _ik_text
    from spatialmech.results import SolveStatus

    r = sm.ik("three-rps", POSE, degrees=True, free=["x", "y", "a1"])
    assert r.reachable and r.result.reachable
    bad = replace(r, task=replace(r.task, converged=False, status=SolveStatus.MAX_ITER, continuation=0.25))
    assert not bad.reachable and bad.to_dict()["reachable"] is False
    _ik_text(bad)
    head = capsys.readouterr().out.splitlines()[0]
    assert "pose reachable" not in head and "not found from the reference" in head
    assert "failed at s=0.25" in head and "the limbs close at the pose asked for" in head
