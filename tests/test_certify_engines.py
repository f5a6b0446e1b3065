"""Certificates for every forward engine (issue 27): the closed forms' systems (the wrist's
quaternion quadrics, the 5-CS's quadrics on SO(3) x C, the four-bar's circle and coupler
condition; an R loop's padded 6R in tests/test_r_loop_forward.py), the 4-SPS/CU's poses in the Study formulation and the loop
formulation's square system in ball arithmetic (kinematics/closed_forms/certificates.py,
kinematics/homotopy/certify_loops.py)."""

import numpy as np
import pytest
from flint import acb_mat, ctx

import spatialmech as sm
from spatialmech.kinematics.assembly import AssemblyKind
from spatialmech.kinematics.closed_forms import certificates as CC
from spatialmech.kinematics.closed_forms import cs_forward as csf
from spatialmech.kinematics.homotopy import certify as C
from spatialmech.kinematics.homotopy.certify_loops import LoopBallSystem, certify_loop
from spatialmech.kinematics.homotopy.loop_system import loop_system, variables
from spatialmech.kinematics.solution_flags import actuator_targets

#: (model, actuator values in degrees or metres, the number of solutions listed)
CASES = [("three-rrr-sm", [10, 20, 30], 8), ("five-cs-3", [10], 4), ("bennett", [30], 1), ("planar-4r", [20], 2),
         ("rssr", [30], 2)]


def _regular(fk) -> int:
    return sum(m.kind == AssemblyKind.REGULAR for m in fk.modes)


@pytest.mark.parametrize(("name", "values", "n"), CASES)
def test_fk_all_certifies_every_regular_solution(name, values, n):
    mech = sm.load_model(name)
    fk = sm.fk(mech, values, all_solutions=True, degrees=name != "four-sps-cu")
    d = fk.to_dict()
    assert len(fk.modes) == n and fk.complete
    assert d["n_certified"] == _regular(fk) == n
    for s in d["solutions"]:
        assert s["certified"] is True and s["certificate"]["certified"] and 0 < s["certificate"]["box_radius"] < 1e-8
    assert fk.answer.detail.search["certification"].startswith(f"{n} of {n} solution(s) certified")


def test_the_4sps_cu_closed_form_poses_certified_in_the_study_formulation():
    fk = sm.fk(sm.load_model("four-sps-cu"), [0.216745, 0.23896, 0.227321, 0.206933], all_solutions=True)
    assert fk.engine == "closed-form" and len(fk.modes) == 4
    assert fk.to_dict()["n_certified"] == 4


def test_certification_off_leaves_the_closed_forms_uncertified():
    fk = sm.fk(sm.load_model("three-rrr-sm"), [10, 20, 30], all_solutions=True, degrees=True, certify=False)
    d = fk.to_dict()
    assert d["n_certified"] is None and all(s["certified"] is None for s in d["solutions"])


# ------------------------------------------------------------------ the systems, checked against the floats
def test_the_5cs_homogeneous_quadrics_are_its_float_system():
    link = csf.linkage_of(sm.load_model("five-cs-3"))
    a, o = link.driven, link.others()
    g = link.line(0.4)
    D, E, U, ua, r = link.s[o] - link.s[a], g[None] - link.c[o], link.u[o], link.u[a], link.r[o]
    Q = csf.homogeneous_quadrics(D, E, U, ua, r)
    X = np.random.default_rng(3).normal(size=(5, 10)) + 1j * np.random.default_rng(4).normal(size=(5, 10))
    P, _ = csf._orth(X)
    F, _ = csf._target(X, D, E, U, ua.astype(complex), r)
    Z = np.hstack([X, np.ones((5, 1))])
    hom = np.einsum("ni,kij,nj->nk", Z, Q, Z)
    assert np.allclose(hom, np.hstack([P, F]), rtol=1e-12, atol=1e-12)


@pytest.fixture(scope="module")
def rssr():
    mech = sm.load_model("rssr")
    fk = sm.fk(mech, [30], all_solutions=True, degrees=True)
    sysm = loop_system(mech)
    p = sysm.parameters(actuator_targets(mech, [np.radians(30.0)]))
    return mech, fk, sysm, p


def test_the_loop_ball_system_encloses_the_float_system_and_its_derivative(rssr):
    _, _, sysm, p = rssr
    rng = np.random.default_rng(8)
    x = rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)
    ball = LoopBallSystem(sysm, p)
    xb = acb_mat([[complex(v)] for v in x])
    F, J = sysm.square(np.concatenate([x, p])[None].astype(complex), reference=True)
    prec = ctx.prec
    ctx.prec = 53
    try:
        Fb, Jb = ball.values(xb), ball.jacobian(xb)
    finally:
        ctx.prec = prec
    for i in range(sysm.nx):
        assert abs(complex(Fb[i, 0].mid()) - F[0, i]) <= 1e-12 * (1 + abs(F[0, i]))
        for j in range(sysm.nx):
            assert abs(complex(Jb[i, j].mid()) - J[0, i, j]) <= 1e-12 * (1 + abs(J[0, i, j]))
    # the Jacobian is the derivative: central differences of the float system
    h = 1e-6
    for j in range(sysm.nx):
        e = np.zeros(sysm.nx + sysm.npar, complex)
        e[j] = h
        z = np.concatenate([x, p])
        Fp, _ = sysm.square((z + e)[None], reference=True, want_J=False)
        Fm, _ = sysm.square((z - e)[None], reference=True, want_J=False)
        assert np.allclose((Fp - Fm)[0] / (2 * h), J[0, :, j], rtol=1e-6, atol=1e-6)


def test_a_perturbed_point_is_not_certified():
    # the four-bar: a root moved by 1e-5 rad fails, the root itself passes
    a, b, c = 0.7, -0.4, 0.2
    base, w = np.arctan2(b, a), np.arccos(-c / np.hypot(a, b))
    ok = CC.four_bar(a, b, c, [base + w, base - w])
    bad = CC.four_bar(a, b, c, [base + w + 1e-5])
    assert all(x.certified for x in ok) and not bad[0].certified
    assert "Newton correction" in bad[0].reason


def test_a_perturbed_loop_configuration_is_not_certified(rssr):
    _, fk, sysm, p = rssr
    cfgs = [s.config for s in fk.answer.detail.solutions if s.converged]
    good = certify_loop(sysm, p, cfgs)
    assert all(c.certified for c in good)
    X = np.array([variables(sysm, c)[: sysm.nx] for c in cfgs], dtype=complex)
    X[0, 0] += 1e-6
    bad = C.certify(LoopBallSystem(sysm, p), X)
    assert not bad[0].certified and bad[1].certified


# ------------------------------------------------------------------ 3-UPU, equal short legs (issue 27)
def _endpoint(e, g, status):
    from spatialmech.kinematics.homotopy.study import HomotopySolution

    y = np.concatenate([e, g]).astype(complex)
    return HomotopySolution(status, y, 1e-13, 1.5e-7, float(np.linalg.norm(y.imag) / np.linalg.norm(y)), 1e-12)


def test_singular_end_points_near_the_exceptional_generator_are_described():
    from spatialmech.kinematics.homotopy.study import _near_infinity_note
    from spatialmech.results import EndPointStatus

    # the end point of the 3-UPU at legs 0.05 m: e ~ 4e-4 |x|, g isotropic (g.g = 0), far from real
    near = _endpoint([-1.1e-4 + 3.5e-4j, 0, 0, -1.7e-4], [-1.1e-4, 0.568j, 0.568, 4.8e-5], EndPointStatus.SINGULAR)
    finite = _endpoint([0.7, 0.1, 0.0, 0.7j], [0.1, 0.2, 0.3, 0.1], EndPointStatus.SINGULAR)
    note = _near_infinity_note([near, finite])
    assert "1 of the singular end point(s) lie near the exceptional generator e = 0" in note
    assert "g isotropic" in note and "none is near a real pose" in note
    assert _near_infinity_note([finite]) == ""


@pytest.mark.parametrize("slides, real, complex_", [((0.4056, 0.4032, 0.4059), 16, 62),
                                                    ((0.3648, 0.3629, 0.3633), 28, 50)])
def test_three_upu_ill_conditioned_end_points_certified_simple_make_the_set_complete(slides, real, complex_):
    """The nominal 3-UPU at two poses hypothesis found: 6 end points near the exceptional
    generator each are too ill-conditioned to count as regular (sigma_min / sigma_max about
    1e-8).  Refined by Newton steps in 106-bit balls (at the second pose the float end points
    are too far from their roots for any box) and certified together with every other finite
    end point, they are simple non-real roots with disjoint boxes, so every path is accounted
    for: complete (proven), every solution certified, none singular."""
    fk = sm.fk("three-upu", list(slides), all_solutions=True)
    d = fk.to_dict()
    assert fk.engine == "homotopy" and fk.complete, fk.completeness
    assert "6 end point(s) too ill-conditioned to count as regular" in fk.completeness
    assert (d["n_real"], d["n_complex"], d["n_singular"]) == (real, complex_, 0)
    assert d["n_certified"] == real and d["search"]["n_certified_complex"] == complex_


@pytest.mark.slow
def test_three_upu_equal_short_legs_says_why_not_proven():
    fk = sm.fk("three-upu", [0.05, 0.05, 0.05], all_solutions=True)
    assert fk.engine == "homotopy" and not fk.complete and len(fk.modes) == 0
    assert "lie near the exceptional generator e = 0" in fk.completeness
    assert "the translational closed form (three spheres: at most 2, Bezout) gives 0 real" in fk.completeness


# ------------------------------------------------------------------ the loop system's two ball evaluations
def _overlap_and_agree(A, B) -> float:
    """The largest radius ratio of ``A``'s balls over ``B``'s, after checking that every pair
    overlaps (both enclose the exact value) and their midpoints agree to 1e-13."""
    worst = 0.0
    for a, b in zip(A.entries(), B.entries(), strict=True):
        assert a.overlaps(b)
        assert abs(complex(a.mid()) - complex(b.mid())) <= 1e-13 * (1 + abs(complex(b.mid())))
        ra, rb = float(a.rad()), float(b.rad())
        worst = max(worst, ra / rb if rb > 0 else (0.0 if ra == 0 else np.inf))
    return worst


@pytest.mark.parametrize("name", ["spatial-six-bar", "rssr"])
def test_the_ball_matrix_evaluation_encloses_what_the_object_arrays_enclose(name):
    """``LoopBallSystem`` (acb_mat products, the structurally non-zero derivatives only) and
    ``ReferenceLoopBallSystem`` (``LoopSystem.square`` on object arrays of balls, the evaluation
    of before): at a closed configuration (the model's reference), over boxes about it and at
    random complex points, their enclosures of ``G`` and ``G'`` overlap, agree to 1e-13 and are
    as tight (radii within a factor 4); the certificates are the same (the same boxes)."""
    from flint import acb, arb

    from spatialmech.kinematics.closure import Configuration
    from spatialmech.kinematics.homotopy.certify_loops import ReferenceLoopBallSystem

    mech = sm.load_model(name)
    sysm = loop_system(mech)
    z = variables(sysm, Configuration.reference(mech))
    x, p = z[: sysm.nx].astype(complex), z[sysm.nx:]
    new, old = LoopBallSystem(sysm, p), ReferenceLoopBallSystem(sysm, p)
    rng = np.random.default_rng(27)
    points = [x, x + 1e-3 * (rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)),
              rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)]
    ratio = 0.0
    prec = ctx.prec
    ctx.prec = 53
    try:
        for y in points:
            for r in (0.0, 1e-11, 1e-6):
                col = acb_mat([[acb(arb(v.real, r), arb(v.imag, r))] for v in y])  # the box of half-width r
                ratio = max(ratio, _overlap_and_agree(new.values(col), old.values(col)),
                            _overlap_and_agree(new.jacobian(col), old.jacobian(col)))
    finally:
        ctx.prec = prec
    assert ratio <= 4.0
    twin = x + 1e-14
    moved = x.copy()
    moved[0] += 1e-6
    P = np.array([x, twin, moved])
    certs = C.certify(new, P)
    assert certs == C.certify(old, P)
    assert C.certify(new, x[None])[0].certified and not (certs[0].certified or certs[1].certified)  # twins: not distinct
    assert not certs[2].certified and "Newton correction" in certs[2].reason


@pytest.mark.parametrize("variant", ["hub from hub", "point ends"])
def test_the_ball_matrix_evaluation_covers_every_loop_term(variant):
    """The branches no ready-made model without Study hubs reaches, on spatial-six-bar's system
    altered (no longer its mechanism, the same formulas): the platform's chain hung from body 1
    (a hub made from another hub), and each rod's two S joints read as one S joint (a limb ending
    at a point: three closure rows, combined by a random complex matrix).  The two ball
    evaluations enclose the same values and Jacobians."""
    from dataclasses import replace

    from flint import acb, arb

    from spatialmech.kinematics.closure import Configuration
    from spatialmech.kinematics.homotopy.certify_loops import ReferenceLoopBallSystem

    mech = sm.load_model("spatial-six-bar")
    sysm = loop_system(mech)
    z = variables(sysm, Configuration.reference(mech))
    rng = np.random.default_rng(5)
    if variant == "hub from hub":
        assert [h.frm for h in sysm.hubs] == [None, None] and sysm.hubs[0].hub == 1
        sysm = replace(sysm, hubs=(sysm.hubs[0], replace(sysm.hubs[1], frm=1)))
    else:
        assert all(le.kind == "rod" for le in sysm.limbs)
        limbs = tuple(replace(le, kind="point") for le in sysm.limbs)
        sysm = replace(sysm, limbs=limbs, compress=rng.normal(size=(3, 6)) + 1j * rng.normal(size=(3, 6)))
    p = z[sysm.nx:]
    new, old = LoopBallSystem(sysm, p), ReferenceLoopBallSystem(sysm, p)
    prec = ctx.prec
    ctx.prec = 53
    try:
        for y in (z[: sysm.nx], rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)):
            for r in (0.0, 1e-9):
                col = acb_mat([[acb(arb(v.real, r), arb(v.imag, r))] for v in y.astype(complex)])
                assert _overlap_and_agree(new.values(col), old.values(col)) <= 4.0
                assert _overlap_and_agree(new.jacobian(col), old.jacobian(col)) <= 4.0
    finally:
        ctx.prec = prec
