"""Mobility at singular references (issue 27, docs/mobility.md#singular-reference-configurations).

The linkage of the issue: a line-symmetric (Bricard) 6R described folded flat, its six axes
coplanar.  Six lines in the plane z = 0, the last three the images of the first three under the
half-turn about the z axis (the line symmetry of the loop: joint i + 3 is the image of joint i);
every such loop is a line-symmetric Bricard linkage, a 1-DOF motion of symmetric configurations.
At the flat configuration the six twists span only the 3-system of lines in a plane, so the
closure Jacobian has corank 3 there, and the "generic" configuration of the old check was pulled
back by Newton to 1e-6 from it, where the rank is full: mobility 0, "rigid".  Through the flat
configuration run two branches of the symmetric motion (the second-order obstruction restricted
to the symmetric configurations is one indefinite quadric in two variables: two real lines), each
of dimension 1: the issue's "branches through it, of dimension 1" — two of them for this loop.
"""

from __future__ import annotations

import json
from contextlib import contextmanager

import numpy as np
import pytest
from click.testing import CliRunner
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

import spatialmech as sm
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.common import load_schema
from spatialmech.kinematics import tracking
from spatialmech.kinematics.backend import joint_twists
from spatialmech.kinematics.closure import joint_points
from spatialmech.model import schema
from spatialmech.serialize import unit_rule_violations

Z = [0.0, 0.0, 1.0]
#: Points and axis angles (rad) of joints 1-3 of the folded Bricard 6R in the plane z = 0.
BRICARD_POINTS = ((-1.46, 0.36), (1.74, 1.18), (-1.67, -1.35))
BRICARD_ANGLES = (0.4, 0.87, 1.06)


def flat_six_r(points, angles, name="flat-bricard-6r") -> sm.Mechanism:
    """A 6R loop folded flat: joints 1-3 on the given lines of the plane z = 0, joints 4-6 their
    images under the half-turn about the z axis; limbs J1 J2 J3 and J6 J5 J4 meet at the link
    between J3 and J4 (the platform)."""
    p = [np.array([x, y, 0.0]) for x, y in points]
    u = [np.array([np.cos(a), np.sin(a), 0.0]) for a in angles]
    p += [-q for q in p]
    u += [-d for d in u]
    J = [sm.R(f"J{i + 1}", p[i], u[i]) for i in range(6)]
    return sm.Mechanism(name, [sm.Limb("a", [J[0], J[1], J[2]]), sm.Limb("b", [J[5], J[4], J[3]])],
                        platform_point=(p[2] + p[3]) / 2)


def bricard() -> sm.Mechanism:
    return flat_six_r(BRICARD_POINTS, BRICARD_ANGLES)


def four_bar(a0: float, a1: float, b0: float, b1: float, name="flat-4r") -> sm.Mechanism:
    """A planar four-bar described with its four pivots on the x axis."""
    return sm.Mechanism(name, [sm.Limb("a", [sm.R("A0", [a0, 0, 0], Z), sm.R("A1", [a1, 0, 0], Z)]),
                               sm.Limb("b", [sm.R("B0", [b0, 0, 0], Z), sm.R("B1", [b1, 0, 0], Z)])])


def redescribed(mech: sm.Mechanism, config, name: str) -> sm.Mechanism:
    """The same linkage described at another closed configuration (its joints' points and axes there)."""
    pts = joint_points(mech, config)
    tw = joint_twists(mech, config)
    limbs = []
    for limb, P, T in zip(mech.limbs, pts, tw, strict=True):
        limbs.append(sm.Limb(limb.name, [sm.R(j.name, P[i], T[:3, i]) for i, j in enumerate(limb.joints)]))
    D = config.D
    return sm.Mechanism(name, limbs, platform_point=D[:3, :3] @ mech.platform_point + D[:3, 3])


# ------------------------------------------------------------------ the folded Bricard 6R
def test_the_folded_6r_has_coplanar_axes_and_corank_3():
    m = bricard()
    axes = np.array([j.axes[0] for limb in m.limbs for j in limb.joints])
    points = np.array([j.point for limb in m.limbs for j in limb.joints])
    assert np.allclose(axes[:, 2], 0) and np.allclose(points[:, 2], 0)
    r = sm.mobility(m)
    assert r.dof_at_reference == 3 and r.dof == 3  # the formula at the flat reference: lambda = 3


def test_the_folded_6r_is_mobile_with_two_branches_of_dimension_one():
    r = sm.mobility(bricard())
    assert r.reference_singular
    assert r.dof_instantaneous == 1 == r.local_dof
    assert [b.dimension for b in r.branches] == [1, 1] and r.undecided == ""
    assert ("reference configuration is singular (instantaneous mobility 3 there" in r.singular_note
            and "branches through it: 2 of dimension 1" in r.singular_note)
    assert r.motion_class == "1H" and not r.agrees  # a branch moves the output on a screw
    d0, d1 = (np.array(b.direction) for b in r.branches)
    assert abs(np.linalg.norm(d0) - 1) < 1e-9 and abs(d0 @ d1) < 0.99  # two distinct tangents
    for b in r.branches:  # each sample closes and lies on the line-symmetric motion, off the plane
        assert 0.09 < b.arc < 0.11
        q = b.sample.q  # limb a: J1 J2 J3, limb b: J6 J5 J4; the half-turn maps joint i to i + 3
        assert np.allclose(q[:3], -q[3:][::-1], atol=1e-9) and np.max(np.abs(q)) > 0.01


def test_the_same_6r_at_a_regular_reference_is_mobile_without_a_note():
    m = bricard()
    sample = sm.mobility(m).branches[0].sample
    r = sm.mobility(redescribed(m, sample, "bricard-6r-moved"))
    assert not r.reference_singular and r.singular_note == "" and r.branches == ()
    assert r.dof == r.dof_instantaneous == r.local_dof == r.dof_at_reference == 1 and r.agrees


# ------------------------------------------------------------------ bifurcation and rigidity
def test_a_flat_parallelogram_is_a_bifurcation_of_two_branches():
    # ground 2, crank 1, coupler 2, rocker 1 folded flat: the parallelogram and the
    # anti-parallelogram motions cross here
    r = sm.mobility(four_bar(0, 1, 2, 3, "flat-parallelogram"))
    assert r.reference_singular and r.dof_at_reference == 2
    assert r.local_dof == 1 == r.dof_instantaneous and [b.dimension for b in r.branches] == [1, 1]
    turns = sorted(abs(np.arctan2(b.sample.D[1, 0], b.sample.D[0, 0])) for b in r.branches)
    assert turns[0] < 1e-9 < 0.01 < turns[1]  # the coupler translates on one branch, turns on the other


def test_a_triangle_is_rigid_and_regular():
    m = sm.Mechanism("triangle", [sm.Limb("a", [sm.R("A", [0, 0, 0], Z), sm.R("B", [1, 0, 0], Z)]),
                                  sm.Limb("b", [sm.R("C", [0.3, 0.8, 0], Z)])])
    r = sm.mobility(m)
    assert (r.dof, r.dof_instantaneous, r.local_dof, r.reference_singular, r.branches) == (0, 0, 0, False, ())


def test_six_generic_coplanar_axes_are_an_isolated_rigid_configuration():
    rng = np.random.default_rng(3)
    P, a = rng.uniform(-2, 2, (6, 2)), rng.uniform(0, np.pi, 6)
    J = [sm.R(f"J{i + 1}", [*P[i], 0.0], [np.cos(a[i]), np.sin(a[i]), 0.0]) for i in range(6)]
    r = sm.mobility(sm.Mechanism("flat-6r", [sm.Limb("a", J[:3]), sm.Limb("b", J[:2:-1])]))
    assert r.reference_singular and r.dof_at_reference == 3
    assert r.local_dof == 0 == r.dof_instantaneous and r.branches == () and r.motion == "rigid"
    assert "isolated configuration, rigid there" in r.singular_note


def test_a_regular_reference_gets_no_exploration():
    r = sm.mobility(sm.load_model("bennett"))
    assert not r.reference_singular and r.local_dof == 1 == r.dof_at_reference and r.singular_note == ""


# ------------------------------------------------------------------ determinism
_SVD = np.linalg.svd


def _flipped_svd(a, full_matrices=True, compute_uv=True, hermitian=False):
    """A valid SVD with every singular-vector pair negated and the null bases rotated."""
    out = _SVD(a, full_matrices=full_matrices, compute_uv=compute_uv, hermitian=hermitian)
    if not compute_uv or np.ndim(a) != 2:
        return out
    U, s, Vt = -out[0], out[1], -out[2]
    small = [i for i in range(s.size) if s[i] <= 1e-13 * max(1.0, s[0])]
    for M, idx, axis in ((U, small + list(range(s.size, U.shape[1])), 1), (Vt, small + list(range(s.size, Vt.shape[0])), 0)):
        if len(idx) > 1:
            q, r = np.linalg.qr(np.random.default_rng(len(idx)).standard_normal((len(idx), len(idx))))
            Q = q * np.sign(np.diag(r))
            if axis == 1:
                M[:, idx] = M[:, idx] @ Q
            else:
                M[idx] = Q @ M[idx]
    return type(out)(U, s, Vt)


@contextmanager
def flipped(monkeypatch):
    tracking._LAST_SVD[:] = [None, None]
    with monkeypatch.context() as mp:
        mp.setattr(np.linalg, "svd", _flipped_svd)
        yield
    tracking._LAST_SVD[:] = [None, None]


@pytest.mark.parametrize("make", [bricard, lambda: four_bar(0, 1, 2, 3)], ids=["bricard-6r", "parallelogram"])
def test_branches_do_not_depend_on_the_svd_signs_or_bases(make, monkeypatch):
    r0 = sm.mobility(make())
    with flipped(monkeypatch):
        r1 = sm.mobility(make())
    assert r1.singular_note == r0.singular_note and r1.motion == r0.motion
    assert len(r1.branches) == len(r0.branches)
    for b0, b1 in zip(r0.branches, r1.branches, strict=True):
        assert b1.dimension == b0.dimension
        np.testing.assert_allclose(b1.direction, b0.direction, atol=1e-6)
        np.testing.assert_allclose(b1.sample.q, b0.sample.q, atol=1e-6)


# ------------------------------------------------------------------ output
def test_json_and_text_show_the_singular_reference(tmp_path):
    path = tmp_path / "bricard.toml"
    schema.dump(bricard(), path)
    doc = json.loads(CliRunner().invoke(cli, ["mobility", str(path), "--json"], catch_exceptions=False).output)
    common = load_schema("common")
    reg = Registry().with_resource(common["$id"], Resource.from_contents(common))
    assert not list(Draft202012Validator(load_schema("mobility"), registry=reg).iter_errors(doc))
    assert unit_rule_violations(doc) == []
    [mode] = doc["modes"]
    assert mode["reference_singular"] and mode["local_dof"] == 1 and mode["dof_at_reference"] == 3
    assert [b["dimension"] for b in mode["branches"]] == [1, 1]
    assert set(mode["branches"][0]["sample_joints_deg"]) == {f"J{i}.rot" for i in range(1, 7)}
    text = CliRunner().invoke(cli, ["mobility", str(path)], catch_exceptions=False).output
    assert "reference configuration is singular (instantaneous mobility 3 there" in text
    assert "branches through it: 2 of dimension 1" in text


def test_a_singular_reference_with_no_second_order_quadric_is_not_an_internal_error(tmp_path):
    """Found by the fuzzer: three-sps-smpu with its Sm joint moved 1e5 m away: the reference is
    flagged singular and the tangent cone has no quadric (an empty array); the mobility is still
    computed (no reshape error)."""
    import tomllib

    import tomli_w

    path = tmp_path / "far-sm.toml"
    sm.export("three-sps-smpu", path)
    d = tomllib.loads(path.read_text())
    d["limbs"][3]["joints"][0]["point"][0] = 1.0e5
    path.write_text(tomli_w.dumps(d))
    r = sm.mobility(str(path), mode="R1+R7")   # the mode that failed
    # a 1e5 m offset puts the count at the edge of rounding (the text says so): 5 or 6, never an error
    assert r.dof_instantaneous in (5, 6) and json.dumps(r.to_dict(), allow_nan=False)
