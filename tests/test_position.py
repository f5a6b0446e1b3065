"""Position analysis on the general engine: inverse/forward round trips, all solutions, errors."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech import catalog
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.position import freedom_values, inverse_position, platform_pose
from spatialmech.kinematics.forward import forward_position

STEWART = catalog.build("stewart-6sps")
DELTA = catalog.build("delta")


@pytest.mark.slow
@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10_000))
def test_stewart_inverse_then_forward_round_trip(seed):
    target = generic_configuration(STEWART, seed=seed, step=0.25)
    pose = platform_pose(STEWART, target)
    inv = inverse_position(STEWART, pose)
    assert inv.reachable
    legs = list(inv.actuator_values(STEWART).values())
    fwd = forward_position(STEWART, legs, start=sm.kinematics.closure.Configuration.reference(STEWART))
    assert fwd.converged
    assert np.allclose(fwd.solutions[0].pose.p, pose.p, atol=1e-9)
    assert np.allclose(fwd.solutions[0].pose.R, pose.R, atol=1e-9)


@pytest.mark.slow
def test_delta_inverse_finds_both_elbows_of_every_arm():
    pose = sm.Pose(np.eye(3), [0.02, 0.01, -0.33])
    inv = inverse_position(DELTA, pose, all_solutions=True)
    assert inv.reachable
    # Clavel Delta: three R limbs (ground -> arm) and six S-S rods (arm -> platform); each arm's
    # cluster (its R limb and its two rods) is solved together, so every limb lists both elbows
    assert [lb.base for lb in DELTA.limbs[:3]] == ["ground"] * 3
    assert [len(l.solutions) for l in inv.limbs] == [2] * 9
    # the two elbow solutions have different actuator angles
    for l in inv.limbs[:3]:
        assert abs(l.solutions[0][0] - l.solutions[1][0]) > 0.5


def test_passive_spin_is_reported_as_a_continuum():
    pose = platform_pose(STEWART, generic_configuration(STEWART, seed=1))
    inv = inverse_position(STEWART, pose, all_solutions=True, n_seeds=8)
    # every leg spins freely about its line (one continuum, listed once whatever the seeds land
    # on) and closes with its length or with minus its length (the leg through its base joint: a
    # configuration of its own, which the old axis-line signature merged with the first)
    assert all(l.passive_dim == 1 and len(l.solutions) == 2 for l in inv.limbs)
    for k, l in enumerate(inv.limbs):
        lengths = sorted(STEWART.freedom_refs[7 * k + 3].freedom.offset + q[3] for q in l.solutions)
        assert lengths[0] == pytest.approx(-lengths[1], rel=1e-9) and lengths[1] > 0


def test_unreachable_pose_is_reported_not_hidden():
    pose = sm.Pose(np.eye(3), [0.0, 0.0, -3.0])  # far below the delta's reach
    inv = inverse_position(DELTA, pose)
    assert not inv.reachable and inv.config is None
    with pytest.raises(ValueError, match="not reachable"):
        inv.actuator_values(DELTA)


@pytest.mark.slow
def test_forward_all_finds_several_assembly_modes_of_the_stewart_platform():
    legs = freedom_values(STEWART, np.zeros(len(STEWART.freedom_refs)))[[3 + 7 * k for k in range(6)]]
    res = forward_position(STEWART, legs, all_solutions=True, n_seeds=40, seed=1)
    poses = [s.pose for s in res.solutions if s.converged]
    assert res.search["distinct"] >= 2  # at least the home pose and its mirror image below the base
    assert any(np.allclose(p.p, [0, 0, 1.0], atol=1e-9) for p in poses)
    assert any(p.p[2] < 0 for p in poses)


def test_forward_bad_inputs():
    with pytest.raises(ValueError, match="actuators: expected 6 values"):
        forward_position(STEWART, [1.0, 1.0])
    with pytest.raises(ValueError, match="not finite"):
        forward_position(STEWART, [1.0, np.nan, 1, 1, 1, 1])
    res = forward_position(STEWART, [10.0] * 6, max_iter=15)  # legs far too long to close from home
    assert not res.converged or np.linalg.norm(res.solutions[0].pose.p) > 5


def run(*args):
    return CliRunner().invoke(cli, list(args))


def test_cli_dj_table_json_layout():
    r = run("jacobian", "five-cs-3", "--dj-table", "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    rows = {x["driver"]: x for x in d["drivers"]}
    assert set(rows) == {f"rot{i}" for i in range(1, 6)} | {f"slide{i}" for i in range(1, 6)}
    assert all(len(x["dj"]) == 7 and len(x["signs"]) == 7 for x in rows.values())
    assert {k for k, x in rows.items() if x["keeps_sign"]} == {"rot1", "rot2"}


def test_cli_ik_fk_jacobian():
    r = run("ik", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "34.38", "-5.73", "11.46", "--json")
    assert r.exit_code == 0, r.output
    legs = json.loads(r.output)["actuators_len"]
    r2 = run("fk", "four-sps-cu", "--actuators", ",".join(str(v) for v in legs.values()), "--all", "--json")
    d2 = json.loads(r2.output)
    assert "closed form" in d2["method"]  # the model is paper B's layout: the closed-form search is used
    assert len(d2["solutions"]) == 4 and sum(s["within_limits"] for s in d2["solutions"]) == 2
    r3 = run("fk", "four-sps-cu", "--actuators", ",".join(str(v) for v in legs.values()), "--json")  # one Newton solve
    assert json.loads(r3.output)["solutions"][0]["converged"]
    r4 = run("jacobian", "five-cs-1", "--position", "3", "--driver", "rot1", "--json")
    d = json.loads(r4.output)
    assert len(d["matrix"]) == 6 and d["det"] is not None


@pytest.mark.parametrize(
    "args, msg",
    [(["fk", "stewart-6sps", "--actuators", "1,1"], "has 6 actuators"),
     (["ik", "five-cs-1", "--position", "9"], "expected 1..7"),
     (["ik", "stewart-6sps", "--position", "1"], "no built-in task positions"),
     (["ik", "stewart-6sps", "--xyz", "0", "0", "1", "--euler", "ZZX", "0", "0", "0"], "seq"),
     (["jacobian", "five-cs-1", "--position", "2", "--driver", "rot9"], "unknown freedom 'rot9'")],
)
def test_cli_kinematics_errors(args, msg):
    r = run(*args)
    assert r.exit_code == 2 and msg in r.output


@pytest.mark.slow
def test_general_forward_all_agrees_with_the_closed_form_of_the_4sps_cu():
    """Every assembly mode the general engine finds is one of the closed form's (cross-check)."""
    from spatialmech.kinematics.closed_forms import four_sps_cu as k4
    from spatialmech.kinematics.closed_forms import four_sps_cu_forward as k4f
    from spatialmech.geometry.rotations import matrix_euler

    m = catalog.build("four-sps-cu")
    assert k4.geometry_of(m) is not None and k4.geometry_of(STEWART) is None
    legs = k4.leg_lengths([0.12, 0.2, -0.1, 0.6])
    closed = k4f.forward_all(legs).phis
    gen = forward_position(m, legs, all_solutions=True, n_seeds=60, seed=1)
    found = [s for s in gen.solutions if s.converged]
    assert len(found) >= 2
    for s in found:
        g, b, a = matrix_euler("ZYX", s.pose.R)
        phi = np.array([s.pose.p[2], a, b, g])
        assert np.min(np.max(np.abs(closed - phi), axis=1)) < 1e-7


@pytest.mark.slow
def test_inverse_prefers_solutions_within_limits_or_the_least_violation():
    m = catalog.build("four-sps-cu")
    far = inverse_position(m, sm.Pose(np.eye(3), [0, 0, 2.0]))
    legs = list(far.actuator_values(m).values())
    assert all(l > 0 for l in legs)  # not the leg flipped through its base joint (-2.005 m)
    near = inverse_position(m, sm.Pose.from_euler("ZYX", [10, 5, 5], [0, 0, 0.2], degrees=True))
    assert all(not v for l in near.limbs for v in l.violations)


def test_wrong_configuration_and_multi_dof_trace_are_clear_errors():
    from spatialmech.kinematics.closure import Configuration
    from spatialmech.kinematics.jacobian import complete_jacobian
    from spatialmech.kinematics.tracking import trace_motion

    with pytest.raises(ValueError, match=r"config\.q: stewart-6sps has 42 joint variables"):
        complete_jacobian(STEWART, Configuration(np.zeros(3), np.eye(4)))
    with pytest.raises(ValueError, match="one-degree-of-freedom motions; stewart-6sps has 6"):
        trace_motion(STEWART, Configuration.reference(STEWART))
