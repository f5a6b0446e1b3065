"""Tolerances and rounded input (issue 10): one place for the tolerances, ``--tol``, poses off the
closure by less than the tolerance, rounded models, scale, extreme values."""

from __future__ import annotations

import json
import math
import re
from dataclasses import replace

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech.analysis.mobility import mobility
from spatialmech.errors import InputError
from spatialmech.geometry import screws as sc
from spatialmech.geometry import tolerances as tl
from spatialmech.geometry.rotations import euler_matrix
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.position import inverse_position
from spatialmech.model import schema
from spatialmech.model.joints import H, P, R, S
from spatialmech.model.mechanism import Limb, Pose


def run(*args):
    return CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)


# ----------------------------------------------------------------- helpers: rounded and scaled models
def _walk_floats(x, f):
    if isinstance(x, dict):
        return {k: _walk_floats(v, f) for k, v in x.items()}
    if isinstance(x, list):
        return [_walk_floats(v, f) for v in x]
    return f(x) if isinstance(x, float) else x


def round_sig(x: float, digits: int) -> float:
    return x if x == 0 else round(x, digits - 1 - math.floor(math.log10(abs(x))))


def rounded_model(name: str, *, decimals: int | None = None, digits: int | None = None) -> dict:
    """The file form (dict) of a ready-made model with every number rounded, axes normalised on
    reading (as a user typing a model from a paper would have to)."""
    d = schema.to_dict(sm.load_model(name))
    f = (lambda x: round(x, decimals)) if decimals is not None else (lambda x: round_sig(x, digits))
    d = _walk_floats(d, f)
    d["normalize_axes"] = True
    return d


def scaled(mech, s: float):
    """``mech`` with every length multiplied by ``s`` (points, slide offsets and limits, pitches,
    task positions): the same mechanism in another unit."""
    limbs = []
    for limb in mech.limbs:
        joints = []
        for j in limb.joints:
            fs = []
            for f in j.freedoms:
                lin = f.kind == "P"
                fs.append(replace(f, point=f.point * s, pitch=f.pitch * s, offset=f.offset * s if lin else f.offset,
                                  limits=tuple(x * s for x in f.limits) if (lin and f.limits) else f.limits))
            joints.append(replace(j, point=j.point * s, freedoms=tuple(fs)))
        limbs.append(Limb(limb.name, tuple(joints)))
    return replace(mech, limbs=tuple(limbs), platform_point=mech.platform_point * s,
                   positions=tuple(replace(p, p=p.p * s) for p in mech.positions))


# ----------------------------------------------------------------- 1. one place for the tolerances
def test_tolerances_are_validated_named_and_parsed():
    t = tl.DEFAULT
    assert t.rank == 1e-9 and t.reachability > t.closure > t.newton
    assert tl.Tolerances.parse("1e-4", primary="reachability") == t.replace(reachability=1e-4)
    assert tl.Tolerances.parse("rank=1e-6, closure=1e-8") == t.replace(rank=1e-6, closure=1e-8)
    for bad, needle in [("rank=2", "below 1"), ("foo=1", "unknown name"), ("rank=nan", "positive finite"),
                        ("rank=x", "expected a number"), ("", "empty"), ("rank=1e-3,rank=1e-4", "twice")]:
        with pytest.raises(InputError, match=needle) as e:
            tl.Tolerances.parse(bad)
        assert str(e.value).startswith("--tol")
    with pytest.raises(InputError, match="min_length"):
        tl.Tolerances(min_length=1.0, max_length=0.5)


def test_use_routes_the_rank_decisions_of_the_geometry_core():
    """Screws dependent to 1e-6: independent at the default rank tolerance, dependent at 1e-4 -
    inside ``use`` and with an explicit ``rtol``, and back outside."""
    a = sc.axis_screw([0, 0, 1], [0, 0, 0])
    b = sc.axis_screw([0, 0, 1], [1, 0, 0])
    c = (a + b) / 2 + 1e-6 * sc.axis_screw([1, 0, 0], [0, 0, 0])
    S = np.array([a, b, c])
    assert sc.rank(S) == 3 and sc.reciprocal_basis(S).shape[0] == 3
    with tl.use(rank=1e-4) as t:
        assert tl.current() is t
        assert sc.rank(S) == 2 and sc.reciprocal_basis(S).shape[0] == 4
    assert tl.current() is tl.DEFAULT and sc.rank(S) == 3
    assert sc.rank(S, rtol=1e-4) == 2
    # the relative singular values are what the tolerance is compared with
    rsv = sc.relative_singular_values(S)
    assert rsv[2] < 1e-5 < rsv[1] and all(sc.rank(S, rtol=t) == int(np.sum(rsv > t)) for t in (1e-12, 1e-8, 1e-4, 0.5))


@pytest.mark.parametrize("args", [
    ("mobility", "bennett"),
    ("ik", "three-rps", "--xyz", 0, 0, 0.3),
    ("fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2"),
    ("jacobian", "four-sps-cu", "--xyz", 0, 0, 0.12, "--euler", "ZYX", 30, -5, 10),
    ("singularity", "four-sps-cu", "--xyz", 0, 0, 0.12, "--euler", "ZYX", 30, -5, 10),
])
def test_commands_that_decide_on_tolerances_accept_tol(args):
    ok = run(*args, "--tol", "1e-6")
    assert ok.exit_code == 0, ok.output
    bad = run(*args, "--tol", "rank=1e3")
    assert bad.exit_code == 2 and "--tol" in bad.output and "below 1" in bad.output
    assert "--tol" in run(args[0], "--help").output


def test_tol_decides_the_singular_flag_of_jacobian_and_singularity():
    pose = ("--xyz", 0, 0, 0.12, "--euler", "ZYX", 34.38, -5.73, 11.46)
    J = json.loads(run("jacobian", "four-sps-cu", *pose, "--json").output)
    assert 1e-6 < J["sigma_min"] < 0.5 and not J["singular"]
    loose = json.loads(run("jacobian", "four-sps-cu", *pose, "--tol", 2 * J["sigma_min"], "--json").output)
    assert loose["singular"] and loose["sigma_min"] == pytest.approx(J["sigma_min"])
    s = run("singularity", "four-sps-cu", *pose)
    s_loose = run("singularity", "four-sps-cu", *pose, "--tol", 2 * J["sigma_min"])
    assert "not singular" in s.output and "not singular" not in s_loose.output


# ----------------------------------------------------------------- 2. poses off the closure
def test_ik_fits_a_pose_off_the_closure_by_less_than_the_tolerance():
    """A 3-RPS pose with its angles rounded to 1e-4 deg (as ``fk`` prints them) does not close
    (the parasitic motion is coupled); it is fitted, and the fit error is reported."""
    m = sm.load_model("three-rps")
    pose = Pose(euler_matrix("ZYX", [-0.0050, -4.9308, 0.1150], degrees=True), [1.29187e-05, 0.000277408, 0.304959])
    exact = inverse_position(m, pose)
    assert not exact.reachable and exact.pose_fit is None  # without fit: unchanged behaviour
    r = inverse_position(m, pose, fit=True)
    assert r.reachable and r.fitted and r.config is not None
    f = r.pose_fit
    assert 0 < f.error <= tl.DEFAULT.reachability and not f.exact
    assert f.error == pytest.approx(max(f.position_error / m.characteristic_length, f.angle_error))
    # the solutions are those of the fitted pose: they close to the solver tolerance there
    assert max(max(limb.residuals) for limb in r.limbs) < tl.DEFAULT.closure
    # a tighter tolerance refuses it, and still says how far it is
    tight = inverse_position(m, pose, fit=True, tol=tl.DEFAULT.replace(reachability=f.error / 2))
    assert not tight.reachable and tight.pose_fit.error == pytest.approx(f.error, rel=1e-3)
    # a pose far off the closure is not reachable, with the distance
    far = inverse_position(m, Pose(pose.R, [0.02, 0.0, 0.3]), fit=True)
    assert not far.reachable and far.pose_fit.error > 1e-3


FK_LINE = re.compile(r"\[1\] platform point \(([^)]*)\) \S+, ZYX angles \(([^)]*)\) deg")


def _fk_text_pose(model, acts):
    r = run("fk", model, "--actuators", ",".join(f"{a:.6g}" for a in acts))
    assert r.exit_code == 0, r.output
    m = FK_LINE.search(r.output)
    assert m, r.output
    return [float(x) for x in m.group(1).split(",")], [float(x) for x in m.group(2).split(",")]


def _fk_json_pose(model, acts):
    r = run("fk", model, "--actuators", ",".join(f"{a:.6g}" for a in acts), "--json")
    assert r.exit_code == 0, r.output
    p = json.loads(r.output)["solutions"][0]["pose"]
    assert p["euler_sequence"] == "ZYX"
    return p["position_len"], p["euler_deg"]


def _ik_of(model, xyz, zyx, acts):
    r = run("ik", model, "--xyz", *xyz, "--euler", "ZYX", *zyx, "--json")
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d["reachable"], d.get("pose_fit")
    got = {**d["actuators_len"], **d["actuators_deg"]}
    mech = sm.load_model(model)
    assert sorted(got) == sorted(mech.actuators)
    # the printed pose is rounded: the legs agree with those given to fk to the printed precision
    given_ = [float(f"{a:.6g}") for a in acts]
    assert np.allclose([got[a] for a in mech.actuators], given_, atol=1e-5 * mech.characteristic_length)
    return d


@pytest.mark.slow
@pytest.mark.parametrize("model, acts", [
    ("stewart-6sps", [1.2, 1.25, 1.2, 1.22, 1.2, 1.21]),
    ("four-sps-cu", [0.2167, 0.2390, 0.2273, 0.2069]),
    ("three-rps", [0.34, 0.33, 0.35]),
])
def test_a_pose_printed_by_fk_is_reachable_by_ik(model, acts):
    """Text (rounded to 6 digits / 1e-4 deg) and JSON: pasted back into ``ik``, reachable."""
    for xyz, zyx in (_fk_text_pose(model, acts), _fk_json_pose(model, acts)):
        _ik_of(model, xyz, zyx, acts)
    # the 3-RPS text pose does not close exactly: ik says it fitted it, and by how much
    if model == "three-rps":
        xyz, zyx = _fk_text_pose(model, acts)
        r = run("ik", model, "--xyz", *xyz, "--euler", "ZYX", *zyx)
        assert "pose reachable (fitted onto the closure: off by" in r.output
        d = json.loads(run("ik", model, "--xyz", *xyz, "--euler", "ZYX", *zyx, "--json").output)
        assert d["fitted"] and 0 < d["pose_fit"]["pose_error"] <= d["pose_fit"]["tolerance"]
        tight = run("ik", model, "--xyz", *xyz, "--euler", "ZYX", *zyx, "--tol", d["pose_fit"]["pose_error"] / 3)
        assert "NOT reachable" in tight.output and "beyond the reachability tolerance" in tight.output


@settings(max_examples=4)
@given(st.lists(st.floats(0.30, 0.36), min_size=3, max_size=3))
def test_three_rps_fk_text_round_trip_property(acts):
    xyz, zyx = _fk_text_pose("three-rps", acts)
    _ik_of("three-rps", xyz, zyx, acts)


# ----------------------------------------------------------------- 3. rounded models
def test_rounded_bennett_is_rigid_at_the_default_tolerance_and_mobile_at_1e_4():
    exact = mobility(sm.load_model("bennett"))
    assert exact.dof == 1 and len(exact.dof_by_tolerance) == 1  # no change between 0 and 0.1
    assert exact.dof_at(1e-12) == exact.dof_at(1e-2) == 1 and "for every rank tolerance" in exact.tolerance_note
    m = schema.from_dict(rounded_model("bennett", decimals=4))
    r = mobility(m)
    assert r.dof == 0 and r.dof_at(1e-10) == 0 and r.dof_at(1e-4) == 1
    change = next(s for s in r.dof_by_tolerance if s.dof == 1)
    sigma = change.lower
    assert 1e-7 < sigma < 1e-4 and change.source and r.tolerance_margin == (0.0, sigma)
    assert ("rigid (M = 0) at tolerance 1e-09, mobile (M = 1) at 1e-04: the smallest singular value counted at 1e-09 "
            f"is {sigma:.2g}") in r.tolerance_note
    # the scan agrees with the analysis itself on both sides of the change
    assert mobility(m, tol=sigma * 0.9).dof == 0
    loose = mobility(m, tol=sigma * 1.1)
    assert loose.dof == 1 and loose.dof_instantaneous == 1 and loose.motion == "1H"
    # JSON fields
    d = r.to_dict()
    assert d["tolerance"] == 1e-9
    at = {e["tolerance"]: e["dof"] for e in d["dof_at_tolerance"]}
    assert at[1e-10] == 0 and at[1e-4] == 1 and at[1e-2] == 1
    assert [s["dof"] for s in d["dof_by_tolerance"]] == [0, 1] and d["dof_by_tolerance"][1]["from"] == sigma


def test_mobility_cli_states_the_gap_text_and_json(tmp_path):
    path = tmp_path / "bennett4.toml"
    path.write_text(schema.dumps(schema.from_dict(rounded_model("bennett", decimals=4))).replace(
        "format = 1", "format = 1\nnormalize_axes = true"))
    r = run("mobility", path)
    assert r.exit_code == 0 and "rigid (M = 0) at tolerance 1e-09, mobile (M = 1) at 1e-04" in r.output
    r4 = run("mobility", path, "--tol", "1e-4", "--json")
    d = json.loads(r4.output)["modes"][0]
    assert d["dof"] == 1 and d["tolerance"] == 1e-4 and "rigid (M = 0) below" in d["tolerance_note"]


@settings(max_examples=6)
@given(st.sampled_from(["bennett", "three-rps", "rssr", "four-sps-cu"]), st.integers(4, 6))
def test_rounded_models_keep_or_announce_their_mobility(name, digits):
    """Rounded to 4-6 significant digits: either the count is unchanged, or the scan says at
    which tolerance (a singular value below 1e-2) the intended count returns."""
    want = mobility(sm.load_model(name)).dof
    r = mobility(schema.from_dict(rounded_model(name, digits=digits)))
    if r.dof != want:
        back = [s for s in r.dof_by_tolerance if s.dof == want and s.lower < 1e-2]
        assert back and f"M = {want}" in r.tolerance_note
        assert mobility(schema.from_dict(rounded_model(name, digits=digits)), tol=back[0].lower * 1.5).dof == want


def test_constraint_wrenches_of_a_rounded_3rps_are_readable():
    """Typed with 6 decimals the 3-RPS printed wrenches with 1e15 entries (rref pivoting on noise)."""
    for decimals in (4, 6):
        r = mobility(schema.from_dict(rounded_model("three-rps", decimals=decimals)))
        W = np.array(r.constraint_wrenches)
        assert r.dof == 3 and W.shape == (3, 6)
        assert np.max(np.abs(W)) < 2.0  # unit forces with moments of the size of the mechanism (0.3)
        exact = np.array(mobility(sm.load_model("three-rps")).constraint_wrenches)
        assert np.allclose(W, exact, atol=10.0 ** (1 - decimals))


@settings(max_examples=40)
@given(st.integers(0, 2**32 - 1), st.integers(1, 5), st.floats(1e-9, 1e-5))
def test_rref_never_pivots_on_noise(seed, r, noise):
    """Rows spanning an r-system plus noise: r rows, the same span (to the noise), bounded entries."""
    rng = np.random.default_rng(seed)
    B = np.linalg.qr(rng.standard_normal((6, r)))[0].T
    B[:, rng.integers(0, 6)] = 0.0  # a column that is zero in exact arithmetic...
    A = B + noise * rng.standard_normal(B.shape)  # ...and noise there
    E = sc.rref(A)
    assert E.shape == (r, 6)
    assert np.max(np.abs(E)) < 1.0 / tl.DEFAULT.pivot + 1
    # same span: projecting E onto the row space of A leaves it unchanged
    Q = np.linalg.qr(A.T)[0]
    assert np.allclose(E - (E @ Q) @ Q.T, 0, atol=1e-8)


# ----------------------------------------------------------------- 4. scale
@pytest.mark.slow
@settings(max_examples=12)
@given(st.sampled_from(["stewart-6sps", "bennett", "three-rps", "four-sps-cu"]), st.floats(-11.0, 11.0))
def test_mobility_does_not_depend_on_the_unit_of_length(name, exponent):
    m = sm.load_model(name)
    ref = mobility(m)
    r = mobility(scaled(m, 10.0**exponent))
    assert (r.dof, r.dof_instantaneous, r.motion, r.lam, r.xi) == (ref.dof, ref.dof_instantaneous, ref.motion, ref.lam, ref.xi)


@pytest.mark.parametrize("s", [1e-300, 1e-14, 1e14, 1e300])
def test_scales_outside_the_supported_range_are_refused_naming_the_field(s):
    """Every length times 1e-300 gave stewart-6sps mobility 3 instead of 6: now refused."""
    with pytest.raises(InputError, match=r"point.*characteristic length.*outside the supported range"):
        scaled(sm.load_model("stewart-6sps"), s)


def test_scale_limits_in_a_file_exit_2_naming_the_field(tmp_path):
    import tomli_w

    tiny = _walk_floats(schema.to_dict(sm.load_model("rssr")), lambda x: x * 1e-14)  # every length (and axis)
    tiny["normalize_axes"] = True
    with pytest.raises(InputError, match="characteristic length"):
        schema.from_dict(tiny)
    path = tmp_path / "tiny.toml"
    path.write_text(tomli_w.dumps(tiny))
    r = run("mobility", path)
    assert r.exit_code == 2 and "characteristic length" in r.output and "point" in r.output
    assert "Traceback" not in r.output


def test_a_model_far_from_its_origin_is_refused():
    """A mechanism 1e-3 in size placed 1e8 from the origin: its screws' moments would have lost
    the digits that the rank decisions need."""
    joints = [R("A", [1e8, 0, 0], Z), S("B", [1e8 + 1e-3, 0, 0])]
    with pytest.raises(InputError, match="from its origin"):
        sm.Mechanism("far", limbs=[Limb("a", joints)], platform_point=[1e8 + 1e-3, 0, 0])
    near = sm.Mechanism("near", limbs=[Limb("a", [R("A", [0, 0, 0], Z), S("B", [1e-3, 0, 0])])], platform_point=[1e-3, 0, 0])
    assert near.characteristic_length == pytest.approx(np.sqrt(2) / 3 * 1e-3)


def test_a_spherical_mechanism_at_the_origin_keeps_length_one():
    m = sm.load_model("three-rrr-sm")
    assert m.characteristic_length == 1.0
    assert tl.characteristic_length([[0, 0, 0], [0, 0, 0]]) == 1.0
    assert tl.characteristic_length([[2, 0, 0], [2, 0, 0]]) == 2.0  # coinciding points away from the origin


# ----------------------------------------------------------------- 5. extreme values
Z, X = [0, 0, 1], [1, 0, 0]


def helical_loop(pitch):
    return sm.Mechanism("h", limbs=[Limb("a", [R("A", [0, 0, 0], Z), H("B", [1, 0, 0], X, pitch=pitch)]),
                                    Limb("b", [R("C", [0, 1, 0], Z), R("D", [1, 1, 0], [0, 1, 0])])],
                        platform_point=[1, 0.5, 0])


def test_huge_helical_pitch_is_refused_not_counted():
    """Pitch 1e308 gave dof_instantaneous 8 for a 4-joint loop."""
    with pytest.raises(InputError, match=r"pitch.*beyond the supported magnitude"):
        helical_loop(1e308)
    with pytest.raises(InputError, match=r"limbs\[0\]\.joints\[1\]\.pitch.*use a P joint"):
        helical_loop(1e8)  # representable, but a prismatic joint to the rank tolerance


@settings(max_examples=15)
@given(st.floats(-1e5, 1e5))
def test_helical_loop_counts_stay_within_the_freedoms(pitch):
    r = mobility(helical_loop(pitch))
    assert 0 <= r.dof_instantaneous <= 4 and r.dof <= 4 and r.xi >= 0


BAD = [float("nan"), float("inf"), -float("inf"), 1e300]


@pytest.mark.parametrize("bad", BAD)
@pytest.mark.parametrize("where, build", [
    ("point", lambda b: R("A", [0, b, 0], Z)),
    ("axis", lambda b: R("A", [0, 0, 0], [0, 0, b])),
    ("pitch", lambda b: H("A", [0, 0, 0], Z, pitch=b)),
    ("limits", lambda b: P("A", [0, 0, 0], Z, limits=[0, b])),
    ("offset", lambda b: P("A", [0, 0, 0], Z, offset=b)),
    ("platform_point", lambda b: sm.Mechanism("m", limbs=[Limb("a", [R("A", [0, 0, 0], Z)])], platform_point=[b, 0, 0])),
])
def test_nan_inf_and_overflow_in_numeric_input_are_refused_naming_the_field(where, build, bad):
    with pytest.raises(InputError, match=where):
        build(bad)


@pytest.mark.parametrize("bad", [[True, 0, 0], ["1", 0, 0], "0,0,0"])
def test_booleans_and_strings_are_not_numbers(bad):
    with pytest.raises(InputError, match="point: expected numbers"):
        R("A", bad, Z)
    with pytest.raises(InputError, match="actuated"):
        R("A", [0, 0, 0], Z, actuated=1)


@pytest.mark.parametrize("text, field", [
    ("point = [0.0, nan, 0.0]", "point"),
    ("point = [0.0, 1e400, 0.0]", "point"),
    ("point = [0.0, 1e300, 0.0]", "point"),
])
def test_file_numbers_out_of_range_exit_2_naming_the_field(tmp_path, text, field):
    src = schema.dumps(sm.load_model("rssr"))
    bad = src.replace("point = [0.0, 0.0, 0.0]", text, 1)
    assert bad != src
    path = tmp_path / "bad.toml"
    path.write_text(bad)
    r = run("mobility", path)
    assert r.exit_code == 2 and field in r.output and "Traceback" not in r.output


def test_overflowing_screws_are_not_silent():
    """Rank decisions on huge (finite) screws do not overflow into NaN; infinite ones raise."""
    assert sc.rank([[1e308, 0, 0, 0, 0, 1e308], [0, 1, 0, 0, 0, 0]]) == 2
    with pytest.raises(InputError, match="NaN or infinity"):
        sc.rank([[np.inf, 0, 0, 0, 0, 0]])
    with np.errstate(all="raise"):  # no floating-point overflow on the way
        big = tl.DEFAULT.replace(max_length=1e300)
        assert tl.characteristic_length([[1e200, 0, 0], [-1e200, 0, 0]], tol=big) == pytest.approx(1e200)
        assert sc.rank([[1e300, 0, 0, 0, 0, 1e300], [0, 1e-300, 0, 0, 0, 0]]) == 2
