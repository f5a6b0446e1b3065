"""Statics (sm.statics, analysis/statics.py, `spatialmech statics`): virtual work on every
ready-made model, paper B's 4-SPS/CU against a hand-built equilibrium, singular and redundant
cases, the joint reactions, bad input, the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech.geometry import screws as sc
from spatialmech.geometry.rotations import euler_matrix
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closure import joint_twists, limb_slices

#: Paper B's example pose, exactly (z = 0.12 m; R = Rz(gamma) Ry(beta) Rx(alpha), gamma 0.6, beta -0.1, alpha 0.2 rad).
PAPER_B_POSE = ([0.0, 0.0, 0.12], ("ZYX", 0.6, -0.1, 0.2))

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


def power_check(r, rates: np.ndarray, twist: np.ndarray) -> tuple[float, float]:
    """``sum(effort * rate) + wrench . twist`` and its scale: ``sum |effort| |rate| + L |F| |V|``
    (F, V nondimensional: f . v + m . omega = L (f . v / L + m / L . omega))."""
    L = r.mechanism.characteristic_length
    eff = np.array(list(r.efforts.values()))
    power = float(eff @ rates + sc.reciprocal_product(r.wrench, twist))
    scale = float(np.abs(eff) @ np.abs(rates)
                  + L * np.linalg.norm(sc.nondimensional(r.wrench, L)) * np.linalg.norm(np.r_[twist[:3], twist[3:] / L]))
    return power, scale


# ------------------------------------------------------------------ virtual work on every model
CASES = [(name, None) for name in sm.models()] + [("four-sps-cu", PAPER_B_POSE)]


@pytest.mark.parametrize("name, pose", CASES, ids=[f"{n}{'' if p is None else '@paper-pose'}" for n, p in CASES])
def test_virtual_work_on_every_ready_made_model(name, pose):
    """The efforts balance the wrench: for every motion the actuators' power cancels the external
    wrench's, sum(tau * qdot) = -(F . $p), to 1e-9 of the terms (property test over wrenches and
    actuator rates; the twist comes from the forward velocity, independent of the statics)."""
    mech = sm.load_model(name)
    probe = sm.statics(mech, pose, wrench=[1.0, 0, 0, 0, 0, 0])
    if probe.singular:
        pytest.skip(f"{name}: the {'reference' if pose is None else 'given'} configuration is singular "
                    f"(sigma_min {probe.sigma_min:.2g}): no twist for arbitrary actuator rates")
    n_a = len(probe.efforts)

    @settings(max_examples=12, deadline=None)
    @given(st.lists(finite, min_size=6, max_size=6), st.lists(st.floats(-10, 10), min_size=n_a, max_size=n_a))
    def prop(wrench, rates):
        r = sm.statics(mech, config=probe.config, wrench=wrench)
        assert r.balanced and not r.singular and not r.redundant
        v = sm.velocity(mech, config=probe.config, actuator_rates=rates)
        err, scale = power_check(r, np.asarray(rates), v.twist)
        assert abs(err) <= 1e-9 * max(scale, 1e-12), (err, scale)

    prop()


# ------------------------------------------------------------------ paper B by hand
def hand_four_sps_cu(z, R, F, a=0.1, b=0.2):
    """Leg forces t1..t4 (along the legs, base to platform) and the CU limb's horizontal forces
    (hx, hy) through the platform centre p = (0, 0, z), from the equilibrium written by hand:
    sum t_i (s_i ; A_i x s_i) + hx (x ; p x x) + hy (y ; p x y) + F = 0.  The CU limb (C about and
    along z at the origin, U at p) can only push sideways at p: a force through p perpendicular to
    z is reciprocal to all four of its twists."""
    signs = [(1, -1), (1, 1), (-1, 1), (-1, -1)]
    p = np.array([0.0, 0.0, z])
    cols = []
    for sx, sy in signs:
        A = R @ (a * np.array([sx, sy, 0.0])) + p
        B = b * np.array([sx, sy, 0.0])
        s = (A - B) / np.linalg.norm(A - B)
        cols.append(np.r_[s, np.cross(A, s)])
    for e in (np.array([1.0, 0, 0]), np.array([0, 1.0, 0])):
        cols.append(np.r_[e, np.cross(p, e)])
    M = np.array(cols).T  # 6 x 6, built without the library
    x, *_ = np.linalg.lstsq(M, -np.asarray(F, float), rcond=None)
    return x[:4], x[4:]


@pytest.mark.parametrize("point", [(0.0, 0.0), (0.03, -0.02)], ids=["on-axis", "off-axis"])
def test_four_sps_cu_against_the_hand_derived_equilibrium(point):
    """A vertical force of 100 N on the platform of paper B at its example pose (through the
    platform centre, or off it): the library's leg forces equal the hand-built 6x6 equilibrium's
    to 1e-9 (relative), and the U joint carries the CU limb's sideways force.  (The pose is
    near a singularity: the leg forces are about 100 times the load, of both signs.)"""
    z = 0.12
    R = euler_matrix("ZYX", PAPER_B_POSE[1][1:])
    at = np.array([point[0], point[1], z])
    f = np.array([0.0, 0.0, -100.0])
    F = np.r_[f, np.cross(at, f)]
    t_hand, h_hand = hand_four_sps_cu(z, R, F)
    r = sm.statics("four-sps-cu", PAPER_B_POSE, wrench=F)
    assert r.pose_fit is not None and r.pose_fit.exact
    assert r.balanced and not r.singular and not r.redundant
    got = np.array([r.efforts[f"L{i}.slide"] for i in range(1, 5)])
    assert np.allclose(got, t_hand, atol=1e-9 * np.abs(t_hand).max()), (got, t_hand)
    u5 = next(j for j in r.reactions if j.joint == "U5")
    assert np.allclose(u5.force, [h_hand[0], h_hand[1], 0.0], atol=1e-9 * np.abs(t_hand).max())
    assert np.allclose(u5.moment_at_point, 0.0, atol=1e-9 * np.abs(t_hand).max())  # a pure force through the U's centre


# ------------------------------------------------------------------ joint reactions
@pytest.mark.parametrize("name, pose", [("three-rps", ([0, 0, 0.33], ("ZYX", 0, 5, 5))), ("five-cs-1", None),
                                        ("rssr", None), ("three-rrr-sm", None)])
def test_reactions_do_no_work_and_the_limbs_hold_the_wrench(name, pose):
    """Each limb's wrench does on each of its freedoms the work of its actuator (or none); each
    joint's reaction is reciprocal to all of its freedoms; ball joints carry a pure force through
    their centre; the limb wrenches and the external wrench add up to zero."""
    F = np.array([3.0, -2.0, -50.0, 0.4, 0.7, -0.2])
    r = sm.statics(name, pose, wrench=F, degrees=True)
    mech, c = r.mechanism, r.config
    assert r.balanced
    W = r.analysis.limb_wrenches
    assert W is not None
    scale = np.linalg.norm(sc.nondimensional(F, mech.characteristic_length))
    assert np.allclose(sc.nondimensional(W.sum(axis=0) + F, mech.characteristic_length), 0, atol=1e-9 * scale)
    tw = joint_twists(mech, c)
    ids = [ref.id for ref in mech.freedom_refs]
    for k, sl in enumerate(limb_slices(mech)):
        for col, i in enumerate(range(sl.start, sl.stop)):
            work = float(sc.reciprocal_product(W[k], tw[k][:, col]))
            assert work == pytest.approx(r.efforts.get(ids[i], 0.0), abs=1e-9 * scale * mech.characteristic_length)
    by_joint = {(j.limb, j.joint): j for j in r.reactions}
    assert len(by_joint) == sum(len(limb.joints) for limb in mech.limbs)
    for k, limb in enumerate(mech.limbs):
        col = 0
        for joint in limb.joints:
            rj = by_joint[(limb.name, joint.name)]
            for g in range(len(joint.freedoms)):
                assert abs(float(sc.reciprocal_product(rj.wrench, tw[k][:, col + g]))) < 1e-9 * scale * mech.characteristic_length
            if joint.type == "S":
                assert np.allclose(rj.moment_at_point, 0.0, atol=1e-9 * scale * mech.characteristic_length)
            col += len(joint.freedoms)


# ------------------------------------------------------------------ singular, redundant, overconstrained
def test_singular_pose_says_which_wrench_cannot_be_balanced():
    """Paper B's reference pose (alpha = beta = 0, gamma = 0: the legs meet on the z axis) cannot
    hold a moment about z: flagged singular, the unbalanced wrench is the couple about z (sign
    fixed: positive), and the residual is exactly that part of the wrench."""
    L = sm.load_model("four-sps-cu").characteristic_length
    r = sm.statics("four-sps-cu", wrench=[0, 0, -10, 0, 0, 2.0])
    assert r.singular and not r.balanced and r.sigma_min < 1e-7
    u = r.unbalanced_wrench
    assert u is not None and np.allclose(u, [0, 0, 0, 0, 0, L], atol=1e-9)
    assert np.allclose(r.residual, [0, 0, 0, 0, 0, 2.0], atol=1e-9)
    assert any("singular" in n for n in r.notes)
    d = r.to_dict()
    assert d["singular"] and not d["balanced"] and d["unbalanced_wrench"][5] > 0
    # a wrench with no such part is still held (least squares, exactly): the vertical load
    v = sm.statics("four-sps-cu", wrench=[0, 0, -10, 0, 0, 0])
    assert v.singular and v.balanced
    assert np.allclose(list(v.efforts.values()), 10 / 4 / (0.2 / np.sqrt(0.2**2 + 2 * 0.1**2)), atol=1e-9)


def test_redundant_actuation_gets_the_minimum_norm_efforts():
    """The 4-SPS/CU with its CU slide driven too: five actuators where four suffice.  Flagged
    redundant; the efforts balance the wrench and are the least-norm ones among all that do, as
    found from a hand-built 6x7 equilibrium (the slide of the C joint pushes along the z axis)."""
    z = 0.12
    R = euler_matrix("ZYX", PAPER_B_POSE[1][1:])
    F = np.array([5.0, -3.0, -100.0, 1.0, -2.0, 0.5])
    drivers = ["L1.slide", "L2.slide", "L3.slide", "L4.slide", "C5.slide"]
    r = sm.statics("four-sps-cu", PAPER_B_POSE, wrench=F, drivers=drivers)
    assert r.redundant and r.balanced and not r.singular
    assert any("minimum-norm" in n for n in r.notes)
    # by hand: legs, the C slide's vertical force along the z axis, the CU's sideways forces at p
    signs = [(1, -1), (1, 1), (-1, 1), (-1, -1)]
    p = np.array([0, 0, z])
    cols = []
    for sx, sy in signs:
        A = R @ (0.1 * np.array([sx, sy, 0.0])) + p
        s = (A - 0.2 * np.array([sx, sy, 0.0]))
        s /= np.linalg.norm(s)
        cols.append(np.r_[s, np.cross(A, s)])
    cols.append(np.r_[0, 0, 1.0, 0, 0, 0])
    for e in (np.eye(3)[0], np.eye(3)[1]):
        cols.append(np.r_[e, np.cross(p, e)])
    M = np.array(cols).T  # 6 x 7
    x0, *_ = np.linalg.lstsq(M, -F, rcond=None)
    n = np.linalg.svd(M)[2][-1]  # the one self-stress
    zeta = -(x0[:5] @ n[:5]) / (n[:5] @ n[:5])  # least ||efforts||, the sideways forces free
    want = (x0 + zeta * n)[:5]
    got = np.array([r.efforts[d] for d in drivers])
    assert np.allclose(got, want, atol=1e-8), (got, want)


@pytest.mark.parametrize("name", sm.models())
def test_the_singular_flag_is_the_jacobians(name):
    """One threshold: statics calls a configuration singular exactly when the complete Jacobian does."""
    r = sm.statics(name, wrench=[1.0, 2.0, 3.0, 0.1, 0.2, 0.3])
    assert r.singular == r.analysis.jacobian.singular, (r.sigma_min, r.analysis.jacobian.sigma_min)
    assert (r.unbalanced_wrench is not None) == r.singular


def test_overconstrained_linkage_flags_indeterminate_reactions():
    r = sm.statics("bennett", wrench=[1.0, 2.0, 3.0, 0.1, 0.2, 0.3])
    assert r.indeterminate and r.balanced and not r.redundant and not r.singular
    assert any("indeterminate" in n for n in r.notes)


def test_graph_mechanism_gets_efforts_and_reactions():
    r = sm.statics("delta", ([0.02, 0.01, -0.33], None), wrench=[0, 0, -10, 0, 0, 0])
    assert r.balanced and len(r.reactions) == 15 and any("graph mechanism" in n for n in r.notes)
    assert set(r.efforts) == {"R1.rot", "R2.rot", "R3.rot"}


@pytest.mark.parametrize("name", ["stewart-6sps", "delta-ruu"])
def test_the_same_mechanism_in_millimetres(name):
    """Every length times 1000 (metres to millimetres), the wrench's moment too: the forces are the
    same, the torques (N mm) 1000 times larger, the flags unchanged."""
    from .test_tolerances import scaled

    F = np.array([2.0, -1.0, -60.0, 0.5, -0.3, 0.2])
    m = sm.statics(name, wrench=F)
    mm = sm.statics(scaled(sm.load_model(name), 1000.0), wrench=np.r_[F[:3], F[3:] * 1000])
    mech = m.mechanism
    for a, t in m.efforts.items():
        factor = 1.0 if mech.freedom(a).freedom.kind == "P" else 1000.0
        assert mm.efforts[a] == pytest.approx(t * factor, rel=1e-9)
    assert (mm.singular, mm.redundant, mm.indeterminate, mm.balanced) == (m.singular, m.redundant, m.indeterminate, m.balanced)


# ------------------------------------------------------------------ bad input
@pytest.mark.parametrize("wrench, error, text", [
    ([1, 2, 3, 4, 5], sm.InputError, "wrench: expected shape (6,)"),
    ([1, 2, float("nan"), 0, 0, 0], sm.InputError, "wrench: contains NaN"),
    ([1, 2, float("inf"), 0, 0, 0], sm.InputError, "wrench: contains NaN or infinity"),
    ("0,0,1,0,0,0", TypeError, "wrench: expected numbers"),
    ([[0, 0, 1, 0, 0, 0]], sm.InputError, "wrench: expected shape (6,)"),
])
def test_bad_wrench_names_the_field(wrench, error, text):
    with pytest.raises(error, match=text.replace("(", r"\(").replace(")", r"\)")):
        sm.statics("stewart-6sps", wrench=wrench)


def test_bad_driver_and_pose_name_the_field():
    with pytest.raises(sm.InputError, match="repeated freedom"):
        sm.statics("stewart-6sps", wrench=[0] * 6, drivers=["L1.slide", "L1.slide"])
    with pytest.raises(sm.UnknownNameError, match="nope"):
        sm.statics("stewart-6sps", wrench=[0] * 6, drivers=["nope"])
    with pytest.raises(TypeError, match="pose"):
        sm.statics("stewart-6sps", "up", wrench=[0] * 6)


# ------------------------------------------------------------------ command line
def test_cli_text_labels_the_units():
    r = CliRunner().invoke(cli, ["statics", "stewart-6sps", "--wrench", "0,0,-600,0,0,0"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    assert "L1.slide  force  +112.802 N" in r.output and "balanced" in r.output
    assert "joint reactions" in r.output and "N m" in r.output
    d = CliRunner().invoke(cli, ["statics", "delta", "--wrench=0,0,-10,0,0,0", "--xyz", "0.02", "0.01", "-0.33"],
                           catch_exceptions=False)
    assert d.exit_code == 0 and "torque" in d.output and "N m" in d.output
    s = CliRunner().invoke(cli, ["statics", "four-sps-cu", "--wrench", "0,0,-10,0,0,2"], catch_exceptions=False)
    assert s.exit_code == 0 and "SINGULAR" in s.output and "NOT balanced" in s.output


def test_cli_json_keys_efforts_by_actuator():
    r = CliRunner().invoke(cli, ["statics", "four-sps-cu", "--wrench", "0,0,-100,0,0,0", "--pose",
                                 "0,0,0.12,ZYX,34.3775,-5.72958,11.4592", "--json"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d["command"] == "statics" and d["model"] == "four-sps-cu" and d["length_unit"] == "m"
    assert set(d["forces_N"]) == {"L1.slide", "L2.slide", "L3.slide", "L4.slide"} and d["torques_N_len"] == {}
    t_hand, _ = hand_four_sps_cu(0.12, euler_matrix("ZYX", PAPER_B_POSE[1][1:]), [0, 0, -100, 0, 0, 0])
    assert np.allclose([d["forces_N"][f"L{i}.slide"] for i in range(1, 5)], t_hand, rtol=1e-4)  # the pose is rounded


@pytest.mark.parametrize("args, text", [
    (["--wrench", "1,2,3"], "--wrench: expected 6 components"),
    (["--wrench", "0,0,nan,0,0,0"], "--wrench: item 3 must be finite"),
    (["--wrench", "0,0,x,0,0,0"], "--wrench: item 3 expects a number"),
    (["--wrench", "0,0,1,0,0,0", "--driver", "nope"], "nope"),
])
def test_cli_bad_input_is_one_line_exit_2(args, text):
    r = CliRunner().invoke(cli, ["statics", "stewart-6sps", *args])
    assert r.exit_code == 2, r.output
    assert text in r.output and r.output.count("\n") == 1
