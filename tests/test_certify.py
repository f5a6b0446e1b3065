"""Certified solutions (issue 27): a Krawczyk test in ball arithmetic proves each homotopy
solution an approximate zero of the exact system with its own root (kinematics/homotopy/certify.py)."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from flint import arb, ctx
from hypothesis import given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech import catalog
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.homotopy import certify as C
from spatialmech.kinematics.homotopy import inverse as ikh
from spatialmech.kinematics.homotopy import study as hc
from spatialmech.results import EndPointStatus

from .test_ik_distinct import PUMA560_DH, _check_serial_solutions, dh_pose, serial_arm
from .test_ik_homotopy import random_6r

LEGS = [1.2] * 6


def _square_root_system(a: float, n: int = 2) -> C.QuadricBallSystem:
    """``x0^2 - a x1^2 = 0`` with the patch ``x1 = 1`` (a test system: roots ``(+-sqrt(a), 1)``)."""
    Q = np.zeros((1, n, n))
    Q[0, 0, 0], Q[0, 1, 1] = 1.0, -a
    return C.quadric_system(Q, np.eye(n)[1:], np.ones(n - 1))


@pytest.fixture(scope="module")
def stewart():
    """stewart-6sps at legs 1.2 m: the Study system, its end points, and ``sm.fk``'s answer."""
    mech = catalog.resolve("stewart-6sps")
    sysm = hc.pose_system(mech)
    hr = hc.homotopy_forward(sysm, LEGS)
    fk = sm.fk(mech, LEGS, all_solutions=True)
    Qt = sysm.coefficients(np.array(LEGS))
    real = [s for s in hr.solutions if s.status == EndPointStatus.REAL]
    c = np.random.default_rng(5).normal(size=8)
    Y = np.array([s.study.real / (s.study.real @ c) for s in real])  # the real roots in the patch c.x = 1
    return {"mech": mech, "sysm": sysm, "hr": hr, "fk": fk, "Qt": Qt, "c": c, "Y": Y,
            "system": C.quadric_system(Qt, c[None], [1.0])}


# ------------------------------------------------------------------ forward (Study homotopy)
def test_stewart_forward_every_solution_and_end_point_certified(stewart):
    fk = stewart["fk"]
    d = fk.to_dict()
    assert fk.engine == "homotopy" and len(fk.modes) == 8 and fk.complete
    assert d["n_certified"] == 8 and all(s["certified"] for s in d["solutions"])
    for s in d["solutions"]:
        cert = s["certificate"]
        assert cert["certified"] and cert["real"] is True and 0 < cert["box_radius"] < 1e-10
    search = fk.answer.detail.search
    assert search["n_certified"] == 8 and search["n_certified_complex"] == 20  # 28 generic = 8 real + 20 complex
    assert search["certification"].startswith("8 of 8 solution(s) certified")


def test_certified_study_roots_are_the_listed_poses(stewart):
    """The certified real roots (Study parameters of the listed poses) close every leg."""
    sysm, fk = stewart["sysm"], stewart["fk"]
    for m in fk.modes:
        x = C.study_parameters(m.pose.displacement(stewart["mech"].platform_point), sysm.L)
        R, _ = hc.study_to_pose(x, sysm.L)
        assert np.allclose(R, m.pose.R, atol=1e-12)
        F = np.einsum("i,kij,j->k", x, sysm.coefficients(np.array(LEGS)), x)
        assert np.max(np.abs(F)) < 1e-12


def test_complex_end_points_certified_non_real_and_distinct(stewart):
    hr, Qt = stewart["hr"], stewart["Qt"]
    cx = np.array([s.study for s in hr.solutions if s.status == EndPointStatus.COMPLEX])
    _, certs = C.certify_forward(Qt, [], cx)
    assert len(certs) == 20 and all(c.certified and c.real is False for c in certs)


def test_perturbed_point_is_not_certified(stewart):
    system, Y = stewart["system"], stewart["Y"]
    good = C.certify(system, Y, real=[True] * len(Y))
    assert all(c.certified for c in good)
    off = Y[0] + 1e-3 * np.random.default_rng(1).normal(size=8)
    bad = C.certify(system, off[None], real=[True])[0]
    assert not bad.certified and bad.radius is None and "Newton correction" in bad.reason


def test_two_nearly_equal_points_are_not_both_certified_distinct(stewart):
    system, Y = stewart["system"], stewart["Y"]
    twin = Y[0] + 1e-14 * np.random.default_rng(2).normal(size=8)  # converges to the same root
    certs = C.certify(system, np.vstack([Y[0], twin, Y[1]]), real=[True] * 3)
    assert not (certs[0].certified and certs[1].certified)
    assert C.n_certified(certs) <= 2 and certs[2].certified
    assert any("same root" in c.reason or "overlaps" in c.reason for c in certs[:2])


def test_fk_no_certify_and_text(stewart):
    r = sm.fk(stewart["mech"], LEGS, all_solutions=True, certify=False)
    d = r.to_dict()
    assert d["n_certified"] is None and all(s["certified"] is None for s in d["solutions"])
    out = CliRunner().invoke(cli, ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all"],
                             catch_exceptions=False).output
    assert "certified yes" in out and "certificates: 8 of 8 solution(s) certified" in out
    doc = json.loads(CliRunner().invoke(cli, ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all",
                                              "--json", "--no-certify"], catch_exceptions=False).stdout)
    assert doc["n_certified"] is None and doc["solutions"][0]["certified"] is None


@pytest.mark.slow
def test_the_closed_form_multistart_poses_are_certified_in_the_study_formulation():
    # the 4-SPS/CU closed form's search proves nothing about completeness, but each pose it
    # found is certified as a real root of the Study formulation (tests/test_certify_engines.py)
    r = sm.fk("four-sps-cu", [0.216745, 0.23896, 0.227321, 0.206933], all_solutions=True, seeds=32)
    d = r.to_dict()
    assert r.engine == "closed-form" and not r.complete and d["n_certified"] == len(r.modes) == 4
    assert all(s["certified"] is True for s in d["solutions"])


# ------------------------------------------------------------------ the exact system
def test_coefficients_are_enclosed_exactly():
    """A coefficient changed by 1e-11 moves the root by 3.5e-12: the old point is certified
    tightly for the exact system only, and the perturbed system's box reaches the moved root;
    a change of 1e-13 is still seen (the box grows)."""
    y = np.array([np.sqrt(2.0), 1.0])
    exact = C.certify(_square_root_system(2.0), y[None], real=[True])[0]
    moved = C.certify(_square_root_system(2.0 + 1e-11), y[None], real=[True])[0]
    shift = float(np.sqrt(2.0 + 1e-11) - np.sqrt(2.0))  # about 3.5e-12
    assert exact.certified and exact.radius < shift
    assert moved.certified and moved.radius >= shift  # the box must hold the new root
    tight = 1e-12  # relative to 1 + max |y|: 2.4e-12 absolute
    assert C.certify(_square_root_system(2.0), y[None], real=[True], max_radius=tight)[0].certified
    assert not C.certify(_square_root_system(2.0 + 1e-11), y[None], real=[True], max_radius=tight)[0].certified
    tiny = C.certify(_square_root_system(2.0 + 1e-13), y[None], real=[True])[0]
    assert tiny.certified and tiny.radius >= float(np.sqrt(2.0 + 1e-13) - np.sqrt(2.0))


def test_double_root_and_nearby_point_are_not_certified():
    y = np.array([1e-9, 1.0])  # near the double root (0, 1) of x0^2 = 0
    c = C.certify(_square_root_system(0.0), y[None], real=[True])[0]
    assert not c.certified and c.radius is None
    c = C.certify(_square_root_system(0.0), np.array([[0.0, 1.0]]), real=[True])[0]
    assert not c.certified and "singular" in c.reason
    # two roots 2e-6 apart, the point 1e-7 from one of them (beyond its accuracy): not certified
    c = C.certify(_square_root_system(1e-12), np.array([[1.1e-6, 1.0]]), real=[True])[0]
    assert not c.certified
    # the same point as a simple root far from the others: certified
    assert C.certify(_square_root_system(1.0), np.array([[1.0, 1.0]]), real=[True])[0].certified


def test_an_ill_conditioned_simple_root_is_certified_in_its_own_box():
    """Roots +-1e-11 of ``x0^2 = 1e-22`` (condition about 5e10): the Jacobian enclosed over the
    shared wider box (100 x the first radius) does not contract, over the first box itself it
    does; both roots certified, distinct, real (the 3-UPU's ill-conditioned end points need it)."""
    system = _square_root_system(1e-22)
    certs = C.certify(system, np.array([[1e-11, 1.0], [-1e-11, 1.0]]), real=[True, True])
    assert all(c.certified and c.real is True for c in certs)
    assert all(c.radius < 1e-11 for c in certs)  # each box excludes the other root


def _ill_conditioned_pair():
    """``x0^2 - 2.2 x0 x1 + b x1^2`` with ``x1 = 1`` and ``b = 1.1^2 + 2^-52`` (floats as exact
    data): roots ``1.1 +- i s`` with ``s`` about 1.5e-8 (condition about 3e7), ``s`` computed at
    200 bits and rounded.  Returns ``(system, 1.1, s)``."""
    from flint import arb, ctx

    c, d = 1.1, 2.0**-26
    b = c * c + d * d
    prec, ctx.prec = ctx.prec, 200
    try:
        s = float((arb(b) - arb(c) ** 2).sqrt())
    finally:
        ctx.prec = prec
    Q = np.zeros((1, 2, 2))
    Q[0] = [[1.0, -c], [-c, b]]
    return C.quadric_system(Q, [[0.0, 1.0]], [1.0]), c, s


def test_a_root_too_ill_conditioned_for_53_bit_balls_is_certified_at_106_bits(monkeypatch):
    """The pair of :func:`_ill_conditioned_pair`.  At 53 bits ``F`` at a centre is enclosed with
    the rounding of its terms, ``A F`` too wide for any box to contract (checked by holding the
    second try at 53 bits); at ``CERTIFY_PRECISION_HIGH`` bits the pair is certified, non-real
    and distinct."""
    import spatialmech.kinematics.homotopy.certify_core as core

    system, c, s = _ill_conditioned_pair()
    pts = np.array([[c + 1j * s, 1.0], [c - 1j * s, 1.0]])
    certs = C.certify(system, pts)
    assert all(x.certified and x.real is False for x in certs), [x.reason for x in certs]
    assert all(x.radius < s for x in certs)
    monkeypatch.setattr(core, "CERTIFY_PRECISION_HIGH", 53)
    assert not any(x.certified for x in C.certify(system, pts))


def test_newton_refinement_in_high_precision_moves_a_point_onto_its_root():
    """A point 1e-9 from the root ``1.1 + i s`` of :func:`_ill_conditioned_pair` (too far for any
    box: refused), refined by :func:`newton_refine` (106-bit balls): within rounding of the root,
    and then certified; at a singular root the point is returned unchanged."""
    system, c, s = _ill_conditioned_pair()
    far = np.array([c + 1e-9 + 1j * s, 1.0])
    assert not C.certify(system, far[None])[0].certified
    near = C.newton_refine(system, far)
    assert abs(near[0] - (c + 1j * s)) < 1e-15 and near[1] == 1.0
    assert C.certify(system, near[None])[0].certified
    assert np.array_equal(C.newton_refine(_square_root_system(0.0), np.array([0.0, 1.0])), [0.0, 1.0])
    assert np.all(np.isfinite(C.newton_refine(_square_root_system(0.0), np.array([1e-9, 1.0]))))


def test_bad_points_are_refused_naming_the_field():
    system = _square_root_system(2.0)
    with pytest.raises(sm.InputError, match="points"):
        C.certify(system, np.array([[np.nan, 1.0]]))
    with pytest.raises(sm.InputError, match="points"):
        C.certify(system, np.ones((1, 3)))
    with pytest.raises(sm.InputError, match="real"):
        C.certify(system, np.ones((2, 2)), real=[True])


def test_real_and_non_real_verdicts():
    Q = np.zeros((1, 2, 2))
    Q[0, 0, 0], Q[0, 1, 1] = 1.0, 4.0  # x0^2 + 4 = 0: roots (+-2i, 1)
    system = C.quadric_system(Q, [[0.0, 1.0]], [1.0])
    certs = C.certify(system, np.array([[2j, 1.0], [-2j, 1.0]]))
    assert all(c.certified and c.real is False for c in certs)  # the pair: conjugate boxes, disjoint
    real = C.certify(_square_root_system(3.0), np.array([[np.sqrt(3.0), 1.0], [-np.sqrt(3.0), 1.0]]), real=[True, True])
    assert all(c.certified and c.real is True for c in real)


@settings(max_examples=25, deadline=None)
@given(a=st.lists(st.floats(0.1, 10.0), min_size=3, max_size=3), signs=st.lists(st.booleans(), min_size=3, max_size=3),
       shift=st.floats(-1e-9, 1e-9))
def test_certified_box_holds_the_true_root(a, signs, shift):
    """Decoupled quadrics ``x_i^2 = a_i x_3^2``, ``x_3 = 1``: every certified box holds the root
    ``(+-sqrt(a_i))`` computed in ball arithmetic independently."""
    n = 4
    Q = np.zeros((3, n, n))
    for i in range(3):
        Q[i, i, i], Q[i, 3, 3] = 1.0, -a[i]
    system = C.quadric_system(Q, np.eye(n)[3:], [1.0])
    y = np.array([(1 if s else -1) * np.sqrt(v) + shift for s, v in zip(signs, a, strict=True)] + [1.0])
    cert = C.certify(system, y[None], real=[True])[0]
    if abs(shift) < 1e-12:  # an accurate point of a well-conditioned root (|x_i| >= 0.3)
        assert cert.certified
    if cert.certified:
        old = ctx.prec
        ctx.prec = 200
        try:
            for i in range(3):
                root = arb(a[i]).sqrt() * (1 if signs[i] else -1)
                assert abs(root - arb(float(y[i]))) < arb(cert.radius)
        finally:
            ctx.prec = old


# ------------------------------------------------------------------ inverse (limb homotopy)
def test_puma560_eight_solutions_certified():
    m = serial_arm("puma560", PUMA560_DH)
    theta = np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4])
    r = sm.ik(m, dh_pose(PUMA560_DH, theta), all_solutions=True)
    d = r.to_dict()
    sols = d["limbs"][0]["solutions"]
    assert len(sols) == 8 and d["n_certified"] == 8
    assert all(s["certified"] and s["certificate"]["real"] for s in sols)
    rep = d["search"]["limbs"][0]
    assert rep["n_certified"] == 8 and rep["certification"].startswith("8 of 8")
    _check_serial_solutions(PUMA560_DH, theta, [np.asarray(q) for q in r.result.limbs[0].solutions])
    off = sm.ik(m, dh_pose(PUMA560_DH, theta), all_solutions=True, certify=False).to_dict()
    assert off["n_certified"] is None and all(s["certified"] is None for s in off["limbs"][0]["solutions"])


def test_limb_ball_system_matches_the_numpy_system():
    m = serial_arm("puma560", PUMA560_DH)
    pose = dh_pose(PUMA560_DH, np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4]))
    D = pose.displacement(m.platform_point)
    sysm = ikh.limb_ik_system(m, 0)
    P = sysm.pose_parameters(np.asarray(D, float))
    system = C.limb_system(sysm, P[:4].real, P[4:7].real)
    x = np.random.default_rng(3).normal(size=sysm.nx) + 0.3j * np.random.default_rng(4).normal(size=sysm.nx)
    F, J, _ = sysm.square(x[None], P[None])
    assert np.allclose(C._mid(system.values(C.COMPLEX.col(x)))[:, 0], F[0], atol=1e-12)
    assert np.allclose(C._mid(system.jacobian(C.COMPLEX.col(x))), J[0], atol=1e-12)
    # finite differences of the ball system's values against its Jacobian
    h = 1e-7
    Jfd = np.array([(C._mid(system.values(C.COMPLEX.col(x + h * e)))[:, 0]
                     - C._mid(system.values(C.COMPLEX.col(x - h * e)))[:, 0]) / (2 * h) for e in np.eye(sysm.nx)]).T
    assert np.allclose(Jfd, J[0], atol=1e-6)


@pytest.mark.slow
def test_general_6r_real_solutions_certified():
    dh, theta = random_6r(0)
    m = serial_arm("random-6r", dh)
    r = sm.ik(m, dh_pose(dh, theta), all_solutions=True)
    d = r.to_dict()
    n = len(d["limbs"][0]["solutions"])
    assert n >= 2 and d["n_certified"] == n
    # a solution moved by 1e-3 rad in one joint is not certified
    sysm = ikh.limb_ik_system(m, 0)
    D = dh_pose(dh, theta).displacement(m.platform_point)
    q = np.array(r.result.limbs[0].solutions[0], dtype=float)
    q[2] += 1e-3
    assert C.certify_inverse(sysm, D, [q])[0].certified is False


def test_certify_benchmark_reports_its_target(stewart):
    """benchmarks/bench_homotopy.py: ``certify_overhead_fraction`` and a verdict (quick: one
    re-solve each of the Stewart forward and the PUMA inverse)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_homotopy.py"
    spec = importlib.util.spec_from_file_location("bench_homotopy", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = bench.certify_case(1, quick=True)
    assert set(out["cases"]) == {"stewart-6sps fk", "PUMA 560 ik"}
    assert all(c["all_certified"] and c["fraction"] > 0 for c in out["cases"].values())
    assert isinstance(out["certify_met"], bool) and out["certify_overhead_fraction"] > 0
    comp = bench.certify_compiled_case(1)  # compiled float pass against the reference, one pose
    assert comp["same_certificates"] and comp["ms"] > 0 and comp["speedup"] > 0


def test_limb_float_jacobians_match_the_ball_system():
    """The batched floating-point Jacobians (the preconditioners) equal the ball system's."""
    m = serial_arm("puma560", PUMA560_DH)
    D = dh_pose(PUMA560_DH, np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4])).displacement(m.platform_point)
    sysm = ikh.limb_ik_system(m, 0)
    P = sysm.pose_parameters(np.asarray(D, float)).real
    system = C.limb_system(sysm, P[:4], P[4:7])
    Y = np.random.default_rng(8).normal(size=(3, sysm.nx))
    Jf = system.jacobian_float_many(Y)
    for y, J in zip(Y, Jf, strict=True):
        assert np.allclose(C._mid(system.jacobian(C.REAL.col(y))), J, atol=1e-12)


def test_quadric_float_jacobians_match_the_ball_system(stewart):
    system = stewart["system"]
    Y = stewart["Y"][:3] + 0.1j
    for y, J in zip(Y, system.jacobian_float_many(Y), strict=True):
        assert np.allclose(C._mid(system.jacobian(C.COMPLEX.col(y))), J, atol=1e-12)


def test_float_pass_gives_the_ball_tests_boxes_on_the_stewart(stewart):
    """The 8 real roots of stewart-6sps (Study quadrics in a real patch): the float pass
    (certify_float.py; its test compiled, and on the Python reference) grants each the box the
    ball test gives."""
    from .test_certify_float import _three_ways

    fast, ref, ball = _three_ways(stewart["system"], stewart["Y"])  # compiled test, Python reference, ball test
    assert len(fast) == 8 and all(r is not None for r in fast) and fast == ref == ball


def test_compiled_float_pass_gives_the_ball_tests_boxes_on_a_general_6r():
    """A general 6R's real inverse solutions (the fixture of the homotopy tests): the compiled
    float pass grants each the box the Python float pass and the ball test give."""
    from .test_certify_float import _limb_points, _three_ways

    dh, theta = random_6r(0)
    system, Y = _limb_points(serial_arm("random-6r", dh), dh, theta)
    fast, ref, ball = _three_ways(system, Y)
    assert len(Y) >= 2 and all(r is not None for r in fast) and fast == ref == ball
