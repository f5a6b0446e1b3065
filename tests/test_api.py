"""The public API (``import spatialmech as sm``, :mod:`spatialmech.api`): every facade function on
ready-made models and on Mechanism objects, name / path / object resolution, argument checks
that name the argument, JSON payloads, status enums and the one progress signature.

The physics checks cross two facade functions (forward of inverse, the Jacobian against the
velocity, a workspace extent against its closed form), so a wrong wiring fails them."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import spatialmech as sm
from spatialmech import api
from spatialmech.results import BranchEnd, EventKind, SingularityKind, SolveStatus, TrackStatus

POSE_B = ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46))  # paper B's example pose (deg)


def strict_json(result) -> dict:
    """``to_dict()`` serialised by the standard library alone, no NaN; returned parsed."""
    d = result.to_dict()
    assert isinstance(d, dict)
    return json.loads(json.dumps(d, allow_nan=False))


# ------------------------------------------------------------------ the namespace
def test_every_analysis_has_a_short_name():
    for name in ("load_model", "mobility", "ik", "fk", "jacobian", "velocity", "singularity", "workspace", "track",
                 "defects", "synth_rccc", "synth_cs", "report", "view"):
        assert callable(getattr(sm, name)), name
        assert name in sm.__all__
    assert set(sm.__all__) <= set(dir(sm)) | {"closed_forms"}
    assert sm.closed_forms.four_sps_cu.leg_lengths([0.2, 0, 0, 0]).shape == (4,)


def test_mobility_accepts_a_name_and_a_limb_of_strings_is_a_type_error():
    """The two AttributeErrors of the review: ``sm.mobility("rssr")`` and ``Limb("x", ["R", "S"])``."""
    r = sm.mobility("rssr")
    assert r.dof == 1 and r.xi == 1
    with pytest.raises(TypeError, match=r"joints\[0\]: expected a Joint \(R, P, C, U, S, Sm, H\), got str 'R'"):
        sm.Limb("x", ["R", "S"])
    good = sm.Limb("a", [sm.R("A", [0, 0, 0], [0, 0, 1])])
    with pytest.raises(TypeError, match=r"limbs\[1\]: expected a Limb, got list"):
        sm.Mechanism("m", [good, [sm.R("B", [1, 0, 0], [0, 0, 1])]])
    with pytest.raises(TypeError, match=r"limbs: expected a sequence"):
        sm.Mechanism("m", good)
    with pytest.raises(TypeError, match=r"positions\[0\]: expected a Pose, got tuple"):
        sm.Mechanism("m", [good], positions=[([0, 0, 0], None)])
    with pytest.raises(TypeError, match=r"name: expected a str, got int 3"):
        sm.Mechanism(3, [good])


# ------------------------------------------------------------------ model resolution
def test_a_model_is_a_name_a_path_or_a_mechanism(tmp_path):
    mech = sm.load_model("bennett")
    path = tmp_path / "my-bennett.toml"
    sm.dump(mech, path)
    via = [sm.mobility(m) for m in (mech, "bennett", path, str(path))]
    assert {r.dof for r in via} == {1} and {r.gk_classic for r in via} == {-2}
    assert sm.load_model(mech) is mech
    with pytest.raises(sm.UnknownNameError, match=r"model: unknown ready-made model 'benett'.*known: .*bennett"):
        sm.mobility("benett")
    with pytest.raises(sm.InputError, match=r"nowhere\.toml"):
        sm.mobility(tmp_path / "nowhere.toml")
    with pytest.raises(TypeError, match=r"model: expected a Mechanism, a ready-made model name or a TOML file path, got int 7"):
        sm.ik(7, POSE_B)


# ------------------------------------------------------------------ position
def test_ik_then_fk_returns_the_pose_on_a_name_and_on_a_mechanism():
    mech = sm.load_model("stewart-6sps")
    pose = ([0.02, -0.01, 1.05], ("ZYX", 10, -5, 4))
    inv = sm.ik("stewart-6sps", pose, degrees=True)
    same = sm.ik(mech, sm.Pose.from_euler("ZYX", np.radians([10, -5, 4]), [0.02, -0.01, 1.05]))
    assert inv.reachable and inv.actuators == pytest.approx(same.actuators, abs=1e-12)
    fwd = sm.fk(mech, list(inv.actuators.values()))
    assert fwd.converged
    assert np.allclose(fwd.poses[0].p, pose[0], atol=1e-9) and np.allclose(fwd.poses[0].R, inv.pose.R, atol=1e-9)
    by_name = sm.fk(mech, inv.actuators)  # a mapping by freedom name
    assert np.allclose(by_name.poses[0].p, fwd.poses[0].p)
    d = strict_json(inv)
    assert d["reachable"] is True and len(d["limbs"]) == 6
    strict_json(fwd)


def test_ik_of_a_task_position_number_reports_the_fit():
    r = sm.ik("five-cs-1", 3)
    P3 = sm.load_model("five-cs-1").positions[2]
    assert r.position == 3 and np.array_equal(r.pose.p, P3.p) and np.array_equal(r.pose.R, P3.R)
    # printed, rounded data: not exactly reachable; the nearest closed configuration is reported
    assert not r.reachable and r.pose_fit.converged and r.pose_fit.position_error > 0
    assert strict_json(r)["pose_fit"]["converged"] is True
    assert sm.ik("stewart-6sps", ([0, 0, 1.05], None)).pose_fit is None


@pytest.mark.slow
def test_fk_degrees_flag_and_the_closed_form_path():
    legs = sm.ik("four-sps-cu", POSE_B, degrees=True).actuators
    r = sm.fk("four-sps-cu", list(legs.values()), all_solutions=True)
    assert r.closed_form
    assert all(isinstance(s.status, SolveStatus) for s in r.result.solutions)
    target = sm.Pose.from_euler("ZYX", POSE_B[1][1:], POSE_B[0], degrees=True)
    assert any(np.allclose(P.p, target.p, atol=1e-8) and np.allclose(P.R, target.R, atol=1e-8) for P in r.poses)
    strict_json(r)
    # rotational actuators read in degrees with degrees=True (an RSSR crank)
    a = sm.fk("rssr", [20.0], degrees=True)
    b = sm.fk("rssr", [np.radians(20.0)])
    assert np.allclose(a.poses[0].R, b.poses[0].R) and not np.allclose(a.poses[0].R, np.eye(3))


# ------------------------------------------------------------------ Jacobian and velocity
def test_the_jacobian_maps_the_forward_velocity_twist_to_the_actuator_rates():
    """``J $p = (0, ..., 0, qdot)``: the Jacobian of one facade call against the twist of another."""
    mech = sm.load_model("four-sps-cu")
    J = sm.jacobian(mech, POSE_B, degrees=True)
    rates = [0.01, -0.02, 0.005, 0.0]
    v = sm.velocity(mech, POSE_B, actuator_rates=rates, degrees=True)
    n_c = J.jacobian.constraint_rows
    assert np.allclose(J.jacobian.matrix @ v.twist, np.r_[np.zeros(n_c), rates], atol=1e-10)
    # and the inverse velocity of that twist gives the rates back
    inv = sm.velocity(mech, config=v.config, twist=v.twist)
    assert list(inv.actuator_rates.values()) == pytest.approx(rates, abs=1e-10)
    d = strict_json(v)
    assert d["given"] == "actuator_rates" and len(d["omega_deg_per_s"]) == 3
    assert np.allclose(d["omega_deg_per_s"], np.degrees(v.twist[:3]))
    strict_json(J)
    assert J.pose_fit is not None and J.to_dict()["pose_fit"]["exact"]


def test_velocity_degrees_reads_angular_rates_in_degrees():
    a = sm.velocity("bennett", actuator_rates=[5.0], degrees=True)
    b = sm.velocity("bennett", actuator_rates=[np.radians(5.0)])
    assert np.allclose(a.twist, b.twist) and np.linalg.norm(a.twist[:3]) > 0
    c = sm.velocity("bennett", twist=np.r_[np.degrees(b.twist[:3]), b.twist[3:]], degrees=True)
    assert c.actuator_rates == pytest.approx({"J1.rot": np.radians(5.0)})
    with pytest.raises(sm.InputError, match="twist/actuator_rates: give exactly one"):
        sm.velocity("bennett")
    with pytest.raises(sm.InputError, match=r"twist: expected shape \(6,\), got shape \(3,\)"):
        sm.velocity("bennett", twist=[0.0, 0.0, 5.0])


# ------------------------------------------------------------------ singularity and workspace
def test_singularity_kind_is_an_enum_and_the_reference_of_paper_b_is_direct():
    ref = sm.singularity("four-sps-cu")
    at = sm.singularity(sm.load_model("four-sps-cu"), POSE_B, degrees=True)
    assert ref.kind is SingularityKind.DIRECT and ref.kind == "direct" and ref.kind.singular
    assert at.kind is SingularityKind.NONE and not at.kind.singular and at.pose_fit.exact
    d = strict_json(ref)
    assert d["kind"] == "direct" and d["result"] == "singularity"


@pytest.mark.slow
def test_workspace_extent_matches_its_closed_form():
    """Paper B at z = 0.1 m: alpha alone reaches atan(z / b) = 26.565 deg (the A1 cone)."""
    seen = []
    ws = sm.workspace("four-sps-cu", at={"z": 0.1}, step=np.radians(10), progress=lambda *a: seen.append(a))
    assert np.degrees(ws.alone["alpha"].hi) == pytest.approx(np.degrees(np.arctan(0.1 / 0.2)), abs=2e-3)
    assert seen and all((t is None or t > 0) and isinstance(m, str) for _, t, m in seen)  # total: an estimate or None
    assert [d for d, _, _ in seen] == sorted(d for d, _, _ in seen)  # cumulative counts
    strict_json(ws)


# ------------------------------------------------------------------ tracking and defects
@pytest.fixture(scope="module")
def four_bar_motion():
    return sm.track("planar-4r", increasing="A0.rot")


def test_track_closes_and_every_traced_pose_is_reachable(four_bar_motion):
    m = four_bar_motion
    assert m.status is TrackStatus.CLOSED and m.closed and m.result.ok and m.result.reason == ""
    assert all(sm.ik("planar-4r", P).reachable for P in m.poses[::8])
    d = strict_json(m)
    assert d["status"] == "closed" and d["points"] == len(m.configurations)
    assert np.ptp(d["joint_values_deg"]["A0.rot"]) == pytest.approx(360.0, abs=1e-6)  # a crank


@pytest.mark.slow
def test_track_events_are_enum_kinds():
    m = sm.track("rssr")  # the rocker's two limit positions are poles of DJ(crank)
    kinds = [e.kind for e in m.result.events]
    assert kinds == [EventKind.POLE, EventKind.POLE]


@pytest.mark.slow
def test_defects_on_positions_from_the_motion(four_bar_motion):
    P = [four_bar_motion.poses[k] for k in (0, 9, 18, 27)]
    msgs = []
    ok = sm.defects("planar-4r", P, progress=lambda done, total, msg: msgs.append((done, total, msg)))
    assert not ok.circuit_defect and not ok.order_defect and ok.usable_drivers == ("A0.rot",)
    assert all(isinstance(s, TrackStatus) for s in ok.circuit_status)
    assert [m[0] for m in msgs] == list(range(1, len(msgs) + 1)) and all(isinstance(m[2], str) for m in msgs)
    shuffled = sm.defects(sm.load_model("planar-4r"), [P[0], P[2], P[1], P[3]])
    assert shuffled.order_defect and not shuffled.circuit_defect
    assert strict_json(ok)["circuit_status"] == ["closed"]


# ------------------------------------------------------------------ synthesis
@pytest.mark.slow
def test_synth_rccc_gives_a_one_dof_mechanism():
    r = sm.synth_rccc(samples=60)
    assert r.linkage_type == "crank-rocker" and r.defects == 0
    assert sm.mobility(r.linkage).dof == 1
    strict_json(r)


@pytest.mark.slow
def test_synth_cs_family_and_branch_ends_are_enums():
    r = sm.synth_cs(pick=0, starts=4)
    assert r.linkage is None and r.check is None and r.family.branches
    assert all(isinstance(e, BranchEnd) for b in r.family.branches for e in b.ends)
    d = strict_json(r)
    assert d["positions_source"] == "paper A table 9" and d["five_cs"] is None and r.success is None


@pytest.mark.slow
def test_synth_cs_assembles_a_5cs_from_a_models_positions():
    r = sm.synth_cs("five-cs-1", starts=12)
    assert r.positions_source == "the task positions of five-cs-1"
    assert r.check.dof == 1 and r.check.max_pose_error < 1e-9
    d = strict_json(r)
    assert d["five_cs"]["dof"] == 1 and d["success"] is r.success and isinstance(d["verdict"], str)


# ------------------------------------------------------------------ report and viewer
@pytest.mark.slow
def test_report_and_view_write_their_files(tmp_path):
    steps = []
    rep = sm.report(sm.load_model("planar-4r"), tmp_path / "rep", trace=False,
                    progress=lambda done, total, msg: steps.append((done, total)))
    assert rep.index_html.exists() and rep.results_json.exists()
    written = json.loads(rep.results_json.read_text(encoding="utf-8"))
    # results.json is the JSON envelope (docs/json.md: schema_version, command, model, length_unit)
    # around the report's payload, which is what to_dict() gives
    envelope = ("schema_version", "command", "model", "length_unit")
    assert written["model"] == "planar-4r" and written["command"] == "report"
    assert strict_json(rep) == {k: v for k, v in written.items() if k not in envelope}
    assert steps and all(t == steps[0][1] for _, t in steps) and steps[-1][0] <= steps[0][1]
    page = sm.view("rssr", tmp_path / "rssr.html", motion="demo", frames=6)
    assert page.frames == 6 and Path(page.out).stat().st_size == page.bytes
    assert strict_json(page)["motion"] == "demo"
    with pytest.raises(sm.InputError, match=r"out: cannot write .*does not exist"):
        sm.view("rssr", tmp_path / "no" / "such" / "dir.html")


# ------------------------------------------------------------------ argument checks
BAD_CALLS = [
    # (call, exception, message naming the argument and what was got)
    (lambda: sm.ik("stewart-6sps", "0,0,1"), TypeError, r"pose: expected a Pose.*got str '0,0,1'"),
    (lambda: sm.ik("stewart-6sps", ([0, 0], None)), sm.InputError, r"pose\[0\] \(xyz\): expected shape \(3,\), got shape \(2,\)"),
    (lambda: sm.ik("stewart-6sps", ([0, 0, 1], ("ZQX", 1, 2, 3))), sm.InputError, r"pose\[1\] \(orientation\): seq: .*'ZQX'"),
    (lambda: sm.ik("stewart-6sps", ([0, 0, np.nan], None)), sm.InputError, r"pose\[0\] \(xyz\): contains NaN"),
    (lambda: sm.ik("stewart-6sps", ([0, 0, 1], np.eye(3) * 2)), sm.InputError, r"pose: .*not a rotation matrix"),
    (lambda: sm.ik("five-cs-1", 9), sm.InputError, r"pose: expected a task position 1\.\.7, got 9"),
    (lambda: sm.ik("stewart-6sps", ([0, 0, 1], None), degrees="yes"), TypeError, r"degrees: expected True or False, got str"),
    (lambda: sm.ik("stewart-6sps", ([0, 0, 1], None), all_solutions=1), TypeError,
     r"all_solutions: expected True or False, got int"),
    (lambda: sm.fk("stewart-6sps", [1.2] * 5), sm.InputError, r"actuators: stewart-6sps has 6 actuators .*got shape \(5,\)"),
    (lambda: sm.fk("stewart-6sps", [True] * 6), TypeError, r"actuators: expected numbers, got list"),
    (lambda: sm.fk("stewart-6sps", "1.2"), TypeError, r"actuators: expected numbers, got str"),
    (lambda: sm.fk("rssr", {"A0.rot": 0.1, "B0.rot": 0.2}), sm.InputError, r"actuators: B0.rot are not actuated"),
    (lambda: sm.fk("rssr", {"nope": 0.1}), sm.UnknownNameError, r"unknown freedom 'nope'"),
    (lambda: sm.fk("stewart-6sps", [1.2] * 6, all_solutions=True, seeds=0), sm.InputError,
     r"seeds: expected an integer >= 1, got 0"),
    (lambda: sm.fk("stewart-6sps", [1.2] * 6, progress="bar"), TypeError, r"progress: expected a callable"),
    (lambda: sm.jacobian("bennett", drivers=3), TypeError, r"drivers: expected a freedom name or a sequence of names, got int 3"),
    (lambda: sm.jacobian("bennett", drivers=["R1", 2]), TypeError, r"drivers\[1\]: expected a freedom name \(str\), got int 2"),
    (lambda: sm.jacobian("bennett", config="ref"), TypeError, r"config: expected a Configuration, got str 'ref'"),
    (lambda: sm.jacobian("bennett", config=sm.Configuration(np.zeros(3), np.eye(4))), sm.InputError, r"config.q: bennett has 4"),
    (lambda: sm.jacobian("bennett", ([0, 0, 0], None), config=sm.Configuration(np.zeros(4), np.eye(4))),
     sm.InputError, r"pose/config: give a pose or a configuration, not both"),
    (lambda: sm.workspace("four-sps-cu", kind="volume"), sm.InputError,
     r"kind: expected one of 'orientation', 'position', 'task', got 'volume'"),
    (lambda: sm.workspace("three-rps", kind="task"), sm.InputError, r"over: kind='task' needs the grid"),
    (lambda: sm.workspace("three-rps", over={"a2": (-0.1, 0.1, 3)}), sm.InputError, r"over: only with kind='task'"),
    (lambda: sm.workspace("three-rps", kind="task", over={"a2": (-0.1, 0.1, 3)}, free=["q"]), sm.InputError,
     r"free: unknown task coordinate 'q'"),
    (lambda: sm.workspace("four-sps-cu", step=-1.0), sm.InputError, r"step: expected a positive number, got -1.0"),
    (lambda: sm.workspace("four-sps-cu", at=[("z", 0.1)]), TypeError, r"at: expected a mapping"),
    (lambda: sm.track("bennett", sense=2), sm.InputError, r"sense: expected \+1 or -1, got 2"),
    (lambda: sm.track("bennett", max_arc=float("inf")), sm.InputError, r"max_arc: expected a finite number"),
    (lambda: sm.track("bennett", increasing=1), TypeError, r"increasing: expected a freedom name"),
    (lambda: sm.defects("planar-4r", positions=3), TypeError,
     r"positions: expected a sequence of Pose or a TOML file path, got int 3"),
    (lambda: sm.defects("planar-4r", positions=[None, None]), TypeError, r"positions\[0\]: expected a Pose, got None"),
    (lambda: sm.defects("planar-4r", positions=[], monte_carlo=-1), sm.InputError,
     r"monte_carlo: expected an integer >= 0, got -1"),
    (lambda: sm.synth_rccc(pick="best"), sm.InputError, r"pick: expected one of 'best-rc', 'interior', got 'best'"),
    (lambda: sm.synth_rccc(task=4), TypeError, r"task: expected a task name, a TOML file path or a TaskPositions, got int 4"),
    (lambda: sm.synth_rccc(task="no-such-task"), sm.UnknownNameError, r"no-such-task"),
    (lambda: sm.synth_cs(pick=2.5), TypeError, r"pick: expected an integer, got float 2.5"),
    (lambda: sm.report("bennett", out=3), TypeError, r"out: expected a path"),
    (lambda: sm.view("bennett", "x.html", motion="spin"), sm.InputError, r"motion: expected one of"),
    (lambda: sm.view("bennett", "x.html", frames=1), sm.InputError, r"frames: expected an integer >= 2, got 1"),
    (lambda: sm.mobility("bennett", mode=3), TypeError, r"mode: expected a mode name"),
]


@pytest.mark.parametrize("call, exc, message", BAD_CALLS, ids=[m[:40] for _, _, m in BAD_CALLS])
def test_bad_arguments_name_the_argument(call, exc, message):
    with pytest.raises(exc, match=message):
        call()


def test_input_errors_are_value_errors_and_unknown_names_key_errors():
    assert issubclass(sm.InputError, ValueError) and issubclass(sm.UnknownNameError, KeyError)
    with pytest.raises(KeyError):
        sm.load_model("no-such-model")


# ------------------------------------------------------------------ results and progress
def test_results_are_frozen_dataclasses():
    import dataclasses

    r = sm.ik("stewart-6sps", ([0, 0, 1.05], None))
    assert dataclasses.is_dataclass(r)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.position = 2
    for cls in (api.IKResult, api.FKResult, api.JacobianResult, api.VelocityResult, api.TraceResult,
                api.CSSynthesisResult, api.ReportResult):
        assert dataclasses.is_dataclass(cls) and cls.__dataclass_params__.frozen, cls


@pytest.mark.slow
def test_one_progress_signature_for_fk_and_track():
    calls = []
    sm.fk("stewart-6sps", [1.2] * 6, all_solutions=True, seeds=5, method="multistart",
          progress=lambda done, total, msg: calls.append(("fk", done, total, msg)))
    assert [c[1] for c in calls] == [1, 2, 3, 4, 5] and {c[2] for c in calls} == {5}
    calls.clear()
    sm.track("bennett", max_arc=1.0, progress=lambda done, total, msg: calls.append((done, total, msg)))
    assert calls and all(t == 1.0 and 0 < d <= 1.0 + 1e-9 for d, t, _ in calls)
    assert [d for d, _, _ in calls] == sorted(d for d, _, _ in calls)


# ------------------------------------------------------------------ the same JSON as the command line
#: Keys of the CLI's envelope (spatialmech.serialize.envelope), not part of an analysis' payload.
ENVELOPE = ("schema_version", "command", "model", "length_unit")
#: Keys that echo command-line options (files written), and timings, which differ between runs.
CLI_ONLY = {"plot", "figures", "elapsed_s", "out"}


def _without(x, keys):
    if isinstance(x, dict):
        return {k: _without(v, keys) for k, v in x.items() if k not in keys}
    if isinstance(x, list):
        return [_without(v, keys) for v in x]
    return x


def _cli_payload(args):
    from click.testing import CliRunner

    from spatialmech.interfaces.cli import cli

    r = CliRunner().invoke(cli, [*args, "--json"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    return _without({k: v for k, v in doc.items() if k not in ENVELOPE}, CLI_ONLY)


PARITY = [
    # (facade call, CLI arguments without --json)
    ("mobility", lambda: sm.mobility_modes("three-rrr-sm"), ["mobility", "three-rrr-sm"]),
    ("ik", lambda: sm.ik("four-sps-cu", POSE_B, degrees=True),
     ["ik", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "34.38", "-5.73", "11.46"]),
    ("ik-position", lambda: sm.ik("five-cs-1", 3), ["ik", "five-cs-1", "--position", "3"]),
    ("fk", lambda: sm.fk("stewart-6sps", [1.2] * 6), ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2"]),
    ("fk-closed-form", lambda: sm.fk("four-sps-cu", [0.2167, 0.239, 0.2273, 0.2069], all_solutions=True, seeds=64),
     ["fk", "four-sps-cu", "--actuators", "0.2167,0.239,0.2273,0.2069", "--all", "--seeds", "64"]),
    ("jacobian", lambda: sm.jacobian("five-cs-1", 3, drivers="rot1"),
     ["jacobian", "five-cs-1", "--position", "3", "--driver", "rot1"]),
    ("singularity", lambda: sm.singularity("four-sps-cu"), ["singularity", "four-sps-cu", "--reference"]),
    ("workspace", lambda: sm.workspace("four-sps-cu", at={"z": 0.1}, step=np.radians(12)),
     ["workspace", "four-sps-cu", "--at", "z=0.1", "--step-deg", "12"]),
    ("workspace-task", lambda: sm.workspace("three-rps", kind="task", over={"a2": np.radians([-30, 0, 30]),
                                            "a3": np.radians([-30, 0, 30])}, at={"z": 0.33}, tol=np.radians(0.1)),
     ["workspace", "three-rps", "--task", "--over", "a2:-30:30:3,a3:-30:30:3", "--at", "z=0.33", "--tol-deg", "0.1"]),
    ("synth-rccc", lambda: sm.synth_rccc(samples=60), ["synth", "rccc", "--samples", "60"]),
    ("synth-cs", lambda: sm.synth_cs(pick=0, starts=4, samples=10),
     ["synth", "cs", "--pick", "0", "--starts", "4", "--samples", "10"]),
    ("mobility-mode", lambda: sm.mobility_modes("three-rrr-sm", mode="R1+R4"),
     ["mobility", "three-rrr-sm", "--mode", "R1+R4"]),
    ("singularity-slice-pose", lambda: _Tagged("singularity_slice", sm.singularity_slice(
        "four-sps-cu", {"a2": [-10, 0, 10], "a3": [-10, 0, 10]}, pose=([0, 0, 0.12], ("ZYX", 20, 0, 0)), degrees=True)),
     ["singularity", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "20", "0", "0",
      "--slice", "a2:-10:10:3,a3:-10:10:3"]),
    ("singularity-slice-task", lambda: _Tagged("singularity_task_slice", sm.singularity_slice(
        "three-rps", {"a2": np.radians([-10, 0, 10]), "a3": np.radians([-10, 0, 10])}, at={"z": 0.33})),
     ["singularity", "three-rps", "--slice", "a2:-10:10:3,a3:-10:10:3", "--at", "z=0.33"]),
]


class _Tagged:
    """A result whose command prints ``{"result": TAG, **to_dict()}`` (singularity's three kinds)."""

    def __init__(self, tag, result):
        self.tag, self.result = tag, result

    def to_dict(self):
        return {"result": self.tag, **self.result.to_dict()}


@pytest.mark.slow
@pytest.mark.parametrize("facade, args", [p[1:] for p in PARITY], ids=[p[0] for p in PARITY])
def test_to_dict_is_the_payload_of_the_command(facade, args):
    """``to_dict()`` of a facade result is what ``spatialmech ... --json`` prints inside its
    envelope.  Fails when a command's JSON changes and the facade does not (or the other way)."""
    assert _without(strict_json(facade()), CLI_ONLY) == _cli_payload(args)


# ------------------------------------------------------------------ the verbs the command line needs (issue 26)
def test_load_model_without_a_name_reports_the_value():
    """What the command line's MODEL argument says for an unknown name: the value, not 'model:'."""
    with pytest.raises(sm.ModelFileError, match=r"^no-such: not a file and not a ready-made model \(ready-made: "):
        sm.load_model("no-such", name=None)
    with pytest.raises(sm.UnknownNameError, match=r"model: unknown ready-made model 'no-such'"):
        sm.load_model("no-such")
    assert sm.load_model("rssr", name=None).name == "rssr"


def test_export_writes_each_format_and_checks_first(tmp_path):
    for name, fmt in (("r.toml", "toml"), ("r.xml", "mjcf"), ("r.urdf", "urdf")):
        r = sm.export("rssr", tmp_path / name)
        assert (r.format, r.out.is_file(), r.to_dict()["bytes"] > 0) == (fmt, True, True)
    assert sm.load(tmp_path / "r.toml").name == "rssr"
    with pytest.raises(sm.InputError, match="format"):
        sm.export("no-such-model", tmp_path / "r.png")  # the file's format is refused before the model is loaded
    with pytest.raises(sm.InputError, match="format: expected one of"):
        sm.export("rssr", tmp_path / "r.toml", format="iges")
    with pytest.raises(sm.InputError, match=r"format: 'step' contradicts the extension '\.toml'"):
        sm.export("rssr", tmp_path / "r.toml", format="step")  # a STEP file named .toml is refused


def test_tolerances_apply_inside_the_block_only():
    before = sm.default_tolerance("rank")
    with sm.tolerances("2e-3", primary="rank") as t:
        assert t.rank == 2e-3
        with sm.tolerances("singular=0.5") as u:
            assert (u.rank, u.singular) == (2e-3, 0.5)
    with sm.tolerances() as t:
        assert t.rank == before
    with pytest.raises(sm.InputError, match="unknown tolerance"):
        sm.default_tolerance("no-such")


def test_suggest_task_grid_names_given_and_solved_coordinates():
    g = sm.suggest_task_grid("three-rps", degrees=True)
    assert (g.given, g.solved, g.euler) == (("z", "a2", "a3"), ("x", "y", "a1"), "ZYX")
    assert g.over == {"a2": (-20.0, 20.0, 41), "a3": (-20.0, 20.0, 41)} and set(g.at) == {"z"}
    r = sm.suggest_task_grid("three-rps", free=["x", "y", "z"])
    assert r.given == ("a1", "a2", "a3") and r.over["a1"][1] == pytest.approx(np.radians(20))


def test_mobility_modes_of_one_mode():
    one = sm.mobility_modes("three-rrr-sm", mode="R1+R4")
    assert len(one) == 1 and one[0].dof == sm.mobility("three-rrr-sm", "R1+R4").dof
