"""Forward position of a user's single loop of R joints proven complete (issue 27): the loop
with its driven joint given is a 6R's inverse position (kinematics/closed_forms/r_loop_forward.py)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech.kinematics.closed_forms import r_loop_forward as rlf
from spatialmech.kinematics.dispatch import forward_engine


def line_symmetric_6r(seed: int = 4) -> sm.Mechanism:
    """A line-symmetric Bricard 6R (mobility 1, overconstrained): joints 1-3 on random lines,
    joints 4-6 their images under the half-turn about the z axis; J1 driven."""
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(3, 3))
    U = rng.normal(size=(3, 3))
    U /= np.linalg.norm(U, axis=1)[:, None]
    H = np.diag([-1.0, -1.0, 1.0])
    p = [*P, *(P @ H)]
    u = [*U, *(U @ H)]
    J = [sm.R(f"J{i + 1}", p[i], u[i], actuated=i == 0) for i in range(6)]
    return sm.Mechanism("my-bricard", [sm.Limb("a", J[:3]), sm.Limb("b", [J[5], J[4], J[3]])],
                        platform_point=(p[2] + p[3]) / 2)


@pytest.fixture(scope="module")
def bricard():
    return line_symmetric_6r()


@pytest.fixture(scope="module")
def bricard_all(bricard):
    return sm.fk(bricard, [0.3], all_solutions=True)


def test_the_6r_loop_is_mobile_and_recognised(bricard):
    assert sm.mobility(bricard).dof == 1
    assert forward_engine(bricard) == "closed-form"
    for name in ("bennett", "planar-4r", "rssr", "three-rrr-sm"):  # 4R loops and S joints: other engines
        assert rlf.loop_of(sm.load_model(name)) is None


def test_the_6r_loop_configurations_proven(bricard_all):
    r = bricard_all
    assert r.engine == "closed-form" and r.complete
    assert "a 6R: complete (proven, with probability one): root count: 16" in r.completeness
    e = r.answer.endpoints
    assert e.n_generic == 16 and e.n_real == len(r.modes) == 2
    assert e.n_real + e.n_complex + e.n_spurious + e.n_singular + e.n_at_infinity == 16
    assert all(m.residual < 1e-10 and m.assembly_mode for m in r.modes)
    assert r.to_dict()["n_certified"] == 2  # certified as roots of the padded 6R's limb system


@pytest.mark.slow
def test_the_multistart_finds_the_same_configurations(bricard, bricard_all):
    ms = sm.fk(bricard, [0.3], all_solutions=True, method="multistart", seeds=200, seed=0)
    ours = [m.pose.p for m in bricard_all.modes]
    assert len(ms.modes) == len(ours)
    for m in ms.modes:
        assert min(np.linalg.norm(m.pose.p - p) for p in ours) < 1e-8


def test_a_general_7r_at_its_reference_input_has_its_reference_pose():
    """A 7R loop of random axes (mobility 1; described at a closed configuration, every joint at
    0): the forward position at the reference input is proven, lists the reference pose, and
    every real configuration closes; the 16 end points, real ones in pairs with the complex."""
    rng = np.random.default_rng(8)
    J = [sm.R(f"J{i + 1}", rng.normal(size=3), rng.normal(size=3), actuated=i == 0, normalize=True) for i in range(7)]
    mech = sm.Mechanism("my-7r", [sm.Limb("a", J[:4]), sm.Limb("b", J[4:][::-1])], platform_point=[0.1, 0.2, 0.3])
    assert rlf.loop_of(mech).n_extra == 0
    r = sm.fk(mech, [0.0], all_solutions=True)
    assert r.engine == "closed-form" and r.complete
    assert any(np.allclose(m.pose.R, np.eye(3), atol=1e-9) and np.allclose(m.pose.p, [0.1, 0.2, 0.3], atol=1e-9)
               for m in r.modes)
    assert all(m.residual < 1e-10 for m in r.modes)
    e = r.answer.endpoints
    assert e.n_spurious == 0 and (e.n_real + e.n_complex) % 2 == 0 and e.n_generic == 16


# ------------------------------------------------------------------ four R joints: one trigonometric equation
@pytest.mark.parametrize(("name", "deg", "n"), [("bennett", 40.0, 1), ("planar-4r", 20.0, 2)])
def test_four_bar_loops_in_closed_form_agree_with_the_multistart(name, deg, n):
    m = sm.load_model(name)
    assert forward_engine(m) == "closed-form"
    r = sm.fk(m, [np.radians(deg)], all_solutions=True)
    assert r.engine == "closed-form" and r.complete and "at most 2 roots" in r.completeness
    assert len(r.modes) == n and all(x.residual < 1e-10 for x in r.modes)
    ms = sm.fk(m, [np.radians(deg)], all_solutions=True, method="multistart", seeds=40, seed=1)
    assert len(ms.modes) == n
    for x in ms.modes:
        assert min(np.linalg.norm(x.pose.R - y.pose.R) + np.linalg.norm(x.pose.p - y.pose.p) for y in r.modes) < 1e-8


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6))
def test_fk_at_the_reference_input_lists_the_reference_on_random_planar_four_bars(seed):
    """A random planar four-bar (pivots in the plane z = 0, axes along z), described at its
    reference configuration: at the reference input that configuration is among the proven ones,
    with at most 2 configurations in all."""
    rng = np.random.default_rng(seed)
    A0, A1, B1, B0 = (np.append(rng.normal(size=2), 0.0) for _ in range(4))
    z = [0, 0, 1]
    m = sm.Mechanism("my-4r", [sm.Limb("crank", [sm.R("A0", A0, z, actuated=True), sm.R("A1", A1, z)]),
                               sm.Limb("rocker", [sm.R("B0", B0, z), sm.R("B1", B1, z)])], platform_point=A1)
    r = sm.fk(m, [0.0], all_solutions=True)
    assert r.engine == "closed-form" and r.complete and 1 <= len(r.modes) <= 2
    assert any(np.allclose(x.pose.R, np.eye(3), atol=1e-9) and np.allclose(x.pose.p, A1, atol=1e-9) for x in r.modes)
