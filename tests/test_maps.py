"""Performance maps (issue 28): the per-pose Python loop and the compiled batched kernels agree,
the indices pass hand checks, statuses flag cells without indices, figures and JSON are written."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis.maps import OUTSIDE, UNREACHABLE, performance_map, pose_indices, power_coefficient
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.common import load_schema
from spatialmech.kinematics import backend, compiled
from spatialmech.serialize import unit_rule_violations

CASES = [
    ("stewart-6sps", "position", {"x": (-0.2, 0.2, 4), "y": (-0.15, 0.15, 3)}, None),
    ("four-sps-cu", "orientation", {"alpha": (-0.5, 0.5, 4), "beta": (-0.45, 0.45, 3)}, {"z": 0.12}),
    ("three-rps", "position", {"z": (0.26, 0.4, 5)}, None),
]


def _compare(a, b, where):
    for k in a.values:
        x, y = a.values[k][where], b.values[k][where]
        fin = np.isfinite(x) & np.isfinite(y)
        assert np.array_equal(np.isfinite(x), np.isfinite(y)), k
        rel = np.abs(x[fin] - y[fin]) / np.maximum(1.0, np.abs(x[fin]))
        assert rel.size == 0 or rel.max() < 1e-10, (k, rel.max())


@pytest.mark.parametrize("name, kind, over, at", CASES, ids=[c[0] for c in CASES])
def test_loop_and_batched_kernel_agree(name, kind, over, at):
    mech = catalog.build(name)
    fast = performance_map(mech, kind=kind, over=over, at=at)
    assert fast.path.startswith("compiled")
    with backend.python_reference():
        ref = performance_map(mech, kind=kind, over=over, at=at, method="loop")
    assert ref.path == "python per-pose loop"
    assert np.array_equal(ref.status, fast.status)
    assert fast.valid.sum() >= 3
    well = fast.valid & (ref.values["sigma_min"] > 1e-3)  # away from singularities (conditioning of the IK)
    _compare(ref, fast, well)


@pytest.mark.parametrize("name", ["stewart-6sps", "four-sps-cu", "three-rps"])
def test_index_kernel_equals_python_on_the_same_jacobians(name):
    from spatialmech.analysis.maps import _actuation, _jacobian_at

    mech = catalog.build(name)
    pose = {"stewart-6sps": ([0.05, -0.03, 1.02], ("ZYX", 5, -3, 4)),
            "four-sps-cu": ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46)),
            "three-rps": ([0, 0, 0.33], None)}[name]
    config = sm.ik(mech, pose, degrees=True).config
    where, scale = _actuation(mech)
    M, inputs, _ = _jacobian_at(mech, config, where)
    nc = 6 - len(where)
    ref = pose_indices(M, nc, inputs, scale, mech.characteristic_length)
    out, va, fa = compiled.maps.indices_many(M[None], nc, inputs[None], scale, mech.characteristic_length)
    for x, y in zip(ref, (out[0], va[0], fa[0]), strict=True):
        assert np.allclose(x, y, rtol=1e-12, atol=1e-13), (x, y)
    J = sm.jacobian(mech, pose, degrees=True)
    assert abs(ref[0][0] - J.sigma_min) < 1e-10 and abs(ref[0][1] - J.jacobian.condition) < 1e-10


def test_stewart_home_hand_checks():
    r = sm.maps("stewart-6sps", over={"x": (-0.1, 0.1, 3), "y": (-0.1, 0.1, 3)})
    J = sm.jacobian("stewart-6sps")
    centre = (1, 1)
    assert abs(r.values["sigma_min"][centre] - J.sigma_min) < 1e-10
    assert abs(r.values["condition"][centre] - J.jacobian.condition) < 1e-10
    assert np.all(r.values["iti"] == pytest.approx(1.0, abs=1e-12))  # force along the leg, slide along the leg
    assert r.values["lti"][centre] == pytest.approx(r.values["oti"][centre])
    # at the symmetric home every leg's output transmission is the same: OTI is the common value
    mech = catalog.build("stewart-6sps")
    from spatialmech.analysis.maps import _actuation, _jacobian_at

    where, _scale = _actuation(mech)
    from spatialmech.kinematics.closure import Configuration

    M, _inputs, _ = _jacobian_at(mech, Configuration.reference(mech), where)
    Jr = M.copy()
    Jr[:, 3:] *= mech.characteristic_length
    Jr /= np.linalg.norm(Jr, axis=1, keepdims=True)
    X = np.linalg.inv(Jr)
    per_leg = [power_coefficient(np.r_[M[i, 3:], M[i, :3]], np.r_[X[:3, i], X[3:, i] * mech.characteristic_length],
                                 mech.characteristic_length) for i in range(6)]
    assert np.ptp(per_leg) < 1e-9 and abs(min(per_leg) - r.values["oti"][centre]) < 1e-10
    # manipulability is the product of the velocity semi-axes, force axes their inverses
    assert r.values["manipulability"][centre] == pytest.approx(np.prod(r.values["velocity_axes"][centre]))
    assert np.allclose(np.sort(r.values["force_axes"][centre]), np.sort(1 / r.values["velocity_axes"][centre]))


def test_power_coefficient_hand_values():
    L = 1.0
    assert power_coefficient([1, 0, 0, 0, 0, 0], [0, 0, 0, 1, 0, 0], L) == pytest.approx(1.0)  # force // slide
    assert power_coefficient([1, 0, 0, 0, 0, 0], [0, 0, 0, 0, 1, 0], L) == 0.0  # force _|_ slide
    # force along x through (0, 2, 0) (moment r x f = (0, 0, -2)), rotation about z through the origin:
    # d = 2 > L, theta = 90 deg: the cosine of the pressure angle is 1
    assert power_coefficient([1, 0, 0, 0, 0, -2], [0, 0, 1, 0, 0, 0], L) == pytest.approx(1.0)
    # the same force at d = 0.5 < L: power 0.5 over the largest power with d_max = L
    assert power_coefficient([1, 0, 0, 0, 0, -0.5], [0, 0, 1, 0, 0, 0], L) == pytest.approx(0.5)
    assert power_coefficient([1, 0, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0], L) == 0.0  # force through the axis


def test_unreachable_and_outside_limits_are_flagged_not_nan():
    r = sm.maps("four-sps-cu", kind="orientation", over={"alpha": (-1.2, 1.2, 7), "beta": (-0.3, 0.3, 3)}, at={"z": 0.12})
    assert np.any(r.status == OUTSIDE)
    for a in r.values.values():
        assert not np.any(np.isnan(a))
        bad = r.status >= OUTSIDE
        assert np.all(a[bad] == 0.0)
    assert all(v for v, s in zip(r.violated, r.status.ravel(), strict=True) if s >= OUTSIDE)
    r3 = sm.maps("three-rps", kind="orientation", over={"beta": (-0.2, 0.2, 3)}, at={"z": 0.33})
    assert list(r3.status) == [UNREACHABLE, 0, UNREACHABLE]  # lower mobility: off home the pose needs its parasitic
    assert r3.violated == ("closure", "", "closure")  # coordinates (x, y, a1 solved): a task slice is not done here


def test_figures_are_written(tmp_path):
    r = sm.maps("stewart-6sps", over={"x": (-0.1, 0.1, 4), "y": (-0.1, 0.1, 3)}, indices=["sigma_min", "lti"])
    from spatialmech.present.maps import write_maps_plot

    for name in ("m.png", "m.svg", "m.html"):
        p = write_maps_plot(r, tmp_path / name)
        assert p.stat().st_size > 1000
    assert "nondimensional" in (tmp_path / "m.html").read_text() and "L = 0.9889 m" in (tmp_path / "m.svg").read_text()
    one = sm.maps("stewart-6sps", over={"z": (0.9, 1.1, 5)})
    assert write_maps_plot(one, tmp_path / "line.png").stat().st_size > 1000


def test_cli_json_validates_against_its_schema(tmp_path):
    out = CliRunner().invoke(cli, ["maps", "four-sps-cu", "--over", "alpha:-20:20:3,beta:-10:10:2", "--at", "z=0.12",
                                   "--index", "sigma_min,lti,lci,force_axes", "--plot", str(tmp_path / "f.png"),
                                   "--json"], catch_exceptions=False)
    assert out.exit_code == 0, out.output
    doc = json.loads(out.output)
    common = load_schema("common")
    registry = Registry().with_resource(common["$id"], Resource.from_contents(common))
    Draft202012Validator(load_schema("maps"), registry=registry).validate(doc)
    assert unit_rule_violations(doc) == []
    assert set(doc["index_maps"]) == {"sigma_min", "lti", "lci", "force_axes"}
    assert doc["axes"]["alpha_deg"] == [-20.0, 0.0, 20.0] and doc["characteristic_length_len"] == 0.24
    text = CliRunner().invoke(cli, ["maps", "stewart-6sps", "--over", "x:-0.1:0.1:3"])
    assert text.exit_code == 0 and "sigma_min" in text.output and "L = 0.988914 m" in text.output


def test_bad_arguments():
    with pytest.raises(sm.InputError, match="not a position coordinate"):
        sm.maps("stewart-6sps", over={"alpha": (-0.1, 0.1, 3)})
    with pytest.raises(sm.InputError, match="lci"):
        sm.maps("stewart-6sps", over={"x": (-0.1, 0.1, 3)}, indices=["lci"])  # no constraint wrenches
    bad = CliRunner().invoke(cli, ["maps", "stewart-6sps", "--over", "x:-0.1:0.1:3,alpha:-5:5:3"])
    assert bad.exit_code == 2 and "not both" in bad.output
