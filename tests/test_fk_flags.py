"""Issue 27, "Every solution says what kind it is": every forward-position solution, whatever the
engine, carries ``forward_singular`` (the platform moves with the actuators locked),
``inverse_singular`` (an actuator moves with the platform locked) and ``input_independent``
(the pose closes for every actuator value), in the API, the text and the JSON of ``fk``.

Before: ``fk --all`` on the spherical 3-RRR wrist (Agile-Eye type, ``three-rrr-sm`` with R1, R4,
R7 driven) listed 8 orientations all ``regular``: 4 are its assembly modes, and 4 hold for every
input (each leg's platform axis on its base axis: the actuators turn without moving the
platform)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

import spatialmech as sm
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.common import load_schema
from spatialmech.geometry.rotations import transform
from spatialmech.kinematics.backend import correct
from spatialmech.kinematics.closure import Configuration, active_mask
from spatialmech.kinematics.solution_flags import actuator_targets, input_independent, solution_flags

WRIST_INPUTS = [0.3, -0.2, 0.5]  # rad: R1, R4, R7
WRIST_DEG = ",".join(f"{np.degrees(v):.12g}" for v in WRIST_INPUTS)


@pytest.fixture(scope="module")
def wrist():
    m = sm.load_model("three-rrr-sm").in_mode("R1+R4+R7")
    assert list(m.actuators) == ["R1.rot", "R4.rot", "R7.rot"]
    return m


@pytest.fixture(scope="module")
def wrist_all(wrist):
    return sm.fk(wrist, WRIST_INPUTS, all_solutions=True, method="multistart", seeds=200, seed=0)


def _signed_permutation(R) -> bool:
    A = np.abs(np.asarray(R))
    return bool(np.allclose(np.sort(A, axis=1), [[0, 0, 1]] * 3, atol=1e-9) and np.allclose(A.sum(axis=0), 1, atol=1e-9))


# ------------------------------------------------------------------ the spherical 3-RRR wrist
def test_wrist_lists_four_assembly_modes_and_flags_the_four_input_independent(wrist_all):
    """8 orientations: the 4 assembly modes (regular, no flag) and the 4 poses with each leg's
    platform axis on its base axis (signed permutations of the home frame: the same for every
    input), flagged input-independent and inverse singular in every actuator, yet forward
    regular (the locked actuators hold the platform there)."""
    modes = wrist_all.modes
    assert len(modes) == 8
    trivial = [m for m in modes if _signed_permutation(m.pose.R)]
    real = [m for m in modes if not _signed_permutation(m.pose.R)]
    assert len(trivial) == 4 and len(real) == 4
    for m in real:
        assert m.kind == "regular" and m.assembly_mode
        assert not (m.forward_singular or m.inverse_singular or m.input_independent)
    for m in trivial:
        assert m.input_independent and m.inverse_singular and not m.forward_singular and not m.assembly_mode
        assert m.flags.inverse_singular_actuators == ("R1.rot", "R4.rot", "R7.rot")
    assert wrist_all.answer.n_input_independent == 4


def test_wrist_input_independent_poses_do_not_depend_on_the_inputs(wrist, wrist_all):
    """The flag says what it means: the same 4 poses come back for other actuator values."""
    other = sm.fk(wrist, [-0.7, 0.4, 1.1], all_solutions=True, method="multistart", seeds=200, seed=1)
    key = lambda modes: sorted(tuple(np.round(m.pose.R, 6).ravel()) for m in modes if m.input_independent)  # noqa: E731
    assert key(other.modes) == key(wrist_all.modes) and len(key(other.modes)) == 4


def test_wrist_text_counts_and_flags(wrist):
    r = CliRunner().invoke(cli, ["fk", "three-rrr-sm", "--actuators", WRIST_DEG, "--all", "--method", "multistart",
                                 "--seeds", "200"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    out = r.stdout
    head = out.splitlines()[0]
    assert "4 assembly modes" in head
    assert "4 input-independent (the actuators move without moving the platform)" in head
    assert out.count("INPUT-INDEPENDENT") == 4
    assert out.count("flags: forward singular no, inverse singular no, input-independent no") == 4
    assert out.count("flags: forward singular no, inverse singular yes, input-independent yes") == 4


@pytest.mark.slow
def test_wrist_default_engine_reports_the_same(wrist):
    """The default engine (the wrist's closed form, proven complete:
    tests/test_spherical_rrr_forward.py) flags the same 4 input-independent poses."""
    r = sm.fk(wrist, WRIST_INPUTS, all_solutions=True)
    assert r.answer.n_input_independent == 4
    assert sum(m.assembly_mode for m in r.modes) == 4


# ------------------------------------------------------------------ no flags, forward singular
def test_stewart_at_a_generic_pose_has_no_flag():
    r = sm.fk("stewart-6sps", [1.2] * 6)
    [m] = r.modes
    assert m.kind == "regular" and m.flags is not None
    assert not (m.forward_singular or m.inverse_singular or m.input_independent)
    assert m.flags.endpoint is None  # one Newton solve: no homotopy end point
    d = r.to_dict()["solutions"][0]
    assert (d["forward_singular"], d["inverse_singular"], d["input_independent"]) == (False, False, False)
    assert d["inverse_singular_actuators"] == [] and r.to_dict()["n_input_independent"] == 0


def test_homotopy_solutions_name_their_end_point():
    """rssr by the loop formulation: every listed solution came from a real end point."""
    r = sm.fk("rssr", [np.radians(30)], all_solutions=True)
    assert r.engine == "monodromy" and r.modes
    for m in r.modes:
        assert m.flags.endpoint == "real" and not m.input_independent


@pytest.mark.slow
def test_study_homotopy_solutions_are_flagged():
    """three-rps by homotopy in Study parameters (16 generic, 8 real): every real mode from a real
    end point, none flagged; the complex end points are counted, not listed."""
    r = sm.fk("three-rps", [0.34, 0.36, 0.32], all_solutions=True)
    assert r.engine == "homotopy" and len(r.modes) == r.answer.endpoints.n_real == 8
    assert r.answer.endpoints.n_complex == 8
    for m in r.modes:
        assert m.flags.endpoint == "real" and m.assembly_mode
        assert not (m.forward_singular or m.inverse_singular or m.input_independent)


def test_four_sps_cu_at_paper_b_reference_is_forward_singular():
    """Every leg sqrt(0.06) m (the reference, z0 = 0.2, no rotation): the platform moves with
    the legs locked (a self-motion); the legs cannot move with the platform locked."""
    r = sm.fk("four-sps-cu", [np.sqrt(0.06)] * 4)
    [m] = r.modes
    assert m.forward_singular and m.kind in ("singular", "self-motion")
    assert not m.inverse_singular and not m.input_independent
    assert r.to_dict()["solutions"][0]["forward_singular"] is True


def test_four_sps_cu_closed_form_solutions_are_flagged():
    """The closed form gives poses only: the limbs are solved for each to flag it."""
    r = sm.fk("four-sps-cu", [0.216745, 0.23896, 0.227321, 0.206933], all_solutions=True, seeds=16)
    assert r.engine == "closed-form" and r.modes
    for m in r.modes:
        assert m.flags is not None and not (m.inverse_singular or m.input_independent)


# ------------------------------------------------------------------ inverse singular: a 5-bar, one leg stretched
def five_bar() -> sm.Mechanism:
    """A planar 5-bar built at the configuration where leg 1 is stretched (A1, B1, P in a line,
    |A1 B1| = |B1 P| = 1); the output link is leg 2's distal link B2-P."""
    z = [0, 0, 1]
    c, s = np.cos(np.radians(60)), np.sin(np.radians(60))
    A1, B1, P = np.zeros(3), np.array([c, s, 0]), np.array([2 * c, 2 * s, 0])
    A2, B2 = np.array([1.0, 0, 0]), np.array([1.5, s, 0])
    return sm.Mechanism("five-bar", [
        sm.Limb("leg1", [sm.R("A1", A1, z, actuated=True), sm.R("B1", B1, z), sm.R("P", P, z)]),
        sm.Limb("leg2", [sm.R("A2", A2, z, actuated=True), sm.R("B2", B2, z)]),
    ], platform_point=P)


def test_five_bar_with_a_stretched_leg_is_inverse_singular_only():
    r = sm.fk(five_bar(), [0.0, 0.0])
    [m] = r.modes
    assert m.inverse_singular and m.flags.inverse_singular_actuators == ("A1.rot",)
    assert not m.forward_singular and not m.input_independent  # the closure error grows with the square


def test_five_bar_away_from_the_stretched_leg_has_no_flag():
    r = sm.fk(five_bar(), [np.radians(-10), np.radians(5)])
    [m] = r.modes
    assert not (m.forward_singular or m.inverse_singular or m.input_independent)


def test_input_independence_test_on_a_hand_built_configuration(wrist):
    """The test itself: the home pose of the wrist is input-dependent; a signed permutation
    with each leg's platform axis on its base axis closes after the perturbations."""
    home = Configuration.reference(wrist)
    t = actuator_targets(wrist, [0.0, 0.0, 0.0])
    assert not input_independent(wrist, home, t)
    f = solution_flags(wrist, home, t, forward_singular=False)
    assert not (f.inverse_singular or f.input_independent)
    # each leg's platform axis on its base axis: R Z = Y (leg 1), R Y = X (leg 2), R X = Z (leg 3)
    R = np.array([[0.0, 1, 0], [0, 0, 1], [1, 0, 0]])
    t = actuator_targets(wrist, WRIST_INPUTS)
    q = np.zeros(len(wrist.freedom_refs))
    for i, v in t.items():
        q[i] = v
    mask = active_mask(wrist)
    mask[list(t)] = False
    c = correct(wrist, Configuration(q, transform(R, np.zeros(3))), active=mask, fix_platform=True)
    assert c.converged
    assert input_independent(wrist, c.config, t)
    f = solution_flags(wrist, c.config, t, forward_singular=False)
    assert f.input_independent and f.inverse_singular_actuators == ("R1.rot", "R4.rot", "R7.rot")


# ------------------------------------------------------------------ JSON
@pytest.fixture(scope="module")
def registry():
    common = load_schema("common")
    return Registry().with_resource(common["$id"], Resource.from_contents(common))


def _validated(args, registry) -> dict:
    r = CliRunner().invoke(cli, [*args, "--json"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    errors = list(Draft202012Validator(load_schema("fk"), registry=registry).iter_errors(doc))
    assert not errors, [(list(e.absolute_path), e.message[:300]) for e in errors[:5]]
    return doc


def test_json_flags_validate_against_the_schema(registry):
    doc = _validated(["fk", "three-rrr-sm", "--actuators", WRIST_DEG, "--all", "--method", "multistart", "--seeds",
                      "200"], registry)
    sols = doc["solutions"]
    assert doc["n_input_independent"] == 4 == sum(s["input_independent"] for s in sols)
    assert all(s["inverse_singular"] for s in sols if s["input_independent"])
    assert not any(s["forward_singular"] for s in sols)
    doc = _validated(["fk", "rssr", "--actuators", "30", "--all"], registry)
    assert {s["endpoint"] for s in doc["solutions"]} == {"real"}


def test_json_schema_refuses_a_solution_without_its_flags(registry):
    doc = _validated(["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2"], registry)
    del doc["solutions"][0]["input_independent"]
    assert list(Draft202012Validator(load_schema("fk"), registry=registry).iter_errors(doc))
