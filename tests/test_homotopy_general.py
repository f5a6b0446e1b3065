"""The loop formulation (kinematics/homotopy/general.py): models whose limbs do not reduce to
quadrics in the Study parameters, solved by monodromy; checked against closed forms, the
multi-start search and the full closure."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech.interfaces.cli import cli as main
from spatialmech.kinematics.homotopy import general as hg
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.backend import closure_residual
from spatialmech.kinematics.forward import forward_position


def _rotate(point, axis_point, axis, phi):
    """``point`` turned by ``phi`` about the line through ``axis_point`` along unit ``axis``."""
    u = np.asarray(point, float) - axis_point
    n = np.asarray(axis, float)
    return axis_point + u * np.cos(phi) + np.cross(n, u) * np.sin(phi) + n * (n @ u) * (1 - np.cos(phi))


def _circle_roots(f):
    """Roots in (-pi, pi] of ``f(phi) = k0 + kc cos(phi) + ks sin(phi)`` (sampled at three angles)."""
    a = np.array([f(0.0), f(np.pi / 2), f(np.pi)])
    k0, kc, ks = (a[0] + a[2]) / 2, (a[0] - a[2]) / 2, a[1] - (a[0] + a[2]) / 2
    r = np.hypot(kc, ks)
    if abs(k0) > r:
        return []
    base, w = np.arctan2(ks, kc), np.arccos(-k0 / r)
    return [base + w, base - w]


def _rocker_angles(mech, theta, b1):
    """Closed form: the crank (limb 0, axis at its joint 0, coupler at its joint 1) turned by
    ``theta``; the angles of the rocker (limb 1's joint 0) that carry the coupler's other end
    ``b1`` to the coupler's length from the crank; with the rocker's axis point and direction."""
    a0, az = _joint(mech, 0, 0)
    a1, _ = _joint(mech, 0, 1)
    b0, bx = _joint(mech, 1, 0)
    A1 = _rotate(a1, a0, az, theta)
    length2 = np.sum((a1 - b1) ** 2)
    return _circle_roots(lambda phi: np.sum((A1 - _rotate(b1, b0, bx, phi)) ** 2) - length2), b0, bx


def _joint(mech, limb, k):
    j = mech.limbs[limb].joints[k]
    return np.asarray(j.freedoms[0].point, float), np.asarray(j.freedoms[0].direction, float)


@pytest.fixture(scope="module")
def rssr():
    return sm.load_model("rssr")


def test_rssr_two_assembly_modes_match_the_closed_form(rssr):
    theta = np.radians(30.0)
    r = forward_position(rssr, [theta], all_solutions=True, method="homotopy")
    d = r.to_dict(rssr)
    assert d["complete"] is True and "trace test passed" in d["completeness"] and "monodromy" in d["completeness"]
    assert d["n_real"] == 2 and d["search"]["n_generic"] == 2
    # closed form: the crank point turned by theta, the rocker point on its circle, the rod's length kept
    b1, _ = _joint(rssr, 0, 2)
    phis, b0, bx = _rocker_angles(rssr, theta, b1)
    assert len(phis) == 2
    found = [s.pose for s in r.solutions]
    assert len(found) == 2
    for phi in phis:  # each closed-form rocker angle is one found pose of the output link
        B1 = _rotate(b1, b0, bx, phi)
        assert any(np.allclose(P.R @ (b1 - b0), B1 - b0, atol=1e-8) for P in found)
    for s in r.solutions:
        assert s.converged and s.kind == "regular"


def test_planar_four_bar_both_modes_match_the_circle_intersection():
    m = sm.load_model("planar-4r")
    theta = np.radians(20.0)
    r = forward_position(m, [theta], all_solutions=True, method="homotopy")
    a0, az = _joint(m, 0, 0)
    a1, _ = _joint(m, 0, 1)
    b1, _ = _joint(m, 1, 1)
    A1 = _rotate(a1, a0, az, theta)
    phis, b0, bz = _rocker_angles(m, theta, b1)
    assert len(phis) == 2 and len(r.solutions) == 2
    for phi in phis:  # the coupler carries a1 to A1 and b1 to the rocker's point
        B1 = _rotate(b1, b0, bz, phi)
        assert any(np.allclose(D[:3, :3] @ a1 + D[:3, 3], A1, atol=1e-8) and
                   np.allclose(D[:3, :3] @ b1 + D[:3, 3], B1, atol=1e-8) for D in (s.config.D for s in r.solutions))
    d = r.to_dict(m)
    assert d["search"]["n_spurious"] + d["n_real"] + d["n_complex"] + d["n_singular"] + d["n_at_infinity"] == \
        d["search"]["n_generic"]


def test_bennett_overconstrained_spurious_points_discarded_and_multistart_agrees():
    m = sm.load_model("bennett")
    theta = np.radians(40.0)
    r = forward_position(m, [theta], all_solutions=True, method="homotopy")
    d = r.to_dict(m)
    # the square system (3 of the closure's equations in random combination) has points that do not close
    assert d["search"]["n_spurious"] > 0 and "discarded" in d["completeness"]
    # the trace test covers the square system's 40 generic solutions, spurious ones included
    assert d["complete"] is True and d["search"]["trace_test"] == "passed" and d["search"]["n_generic"] == 40
    assert d["n_real"] >= 1
    for s in r.solutions:  # every reported mode closes the loop with the input held
        assert np.max(np.abs(closure_residual(m, s.config))) < 1e-9
        assert s.config.q[0] == pytest.approx(theta)
    ms = forward_position(m, [theta], all_solutions=True, n_seeds=12, seed=3)
    for s in ms.solutions:  # every multi-start mode is among the homotopy's
        if s.converged:
            assert any(np.allclose(s.pose.R, h.pose.R, atol=1e-7) and np.allclose(s.pose.p, h.pose.p, atol=1e-7)
                       for h in r.solutions)


def test_loop_equations_vanish_on_closed_configurations(rssr):
    """The formulation's equations (square and full) are zero at closed configurations, and the
    configuration rebuilt from a solution's variables closes the mechanism."""
    from spatialmech.kinematics.motion import generic_configuration

    for name in ("rssr", "bennett", "five-cs-3", "three-rrr-sm"):
        m = sm.load_model(name)
        sysm = hg.loop_system(m)
        c = generic_configuration(m, seed=5, step=0.4, steps=3)
        z = hg.variables(sysm, c)[None]
        F, J = sysm.square(z)
        assert np.max(np.abs(F)) < 1e-9, name
        assert sysm.residual(z)[0] < 1e-9, name
        # a finite-difference check of the derivative
        dz = 1e-7 * (np.random.default_rng(1).normal(size=z.shape[1]))
        F2, _ = sysm.square(z + dz)
        assert np.allclose(F2[0] - F[0], J[0] @ dz, atol=1e-11), name


def test_unsupported_models_say_why_and_auto_falls_back():
    """What the loop formulation still does not cover is named (limb and joints): S joints other
    than one or an adjacent pair per limb (the 3-SPS/SmPU's S-P-S legs), helical joints."""
    smpu = sm.load_model("three-sps-smpu")
    why = hg.general_reason(smpu)
    assert why is not None and "limb leg1" in why and "S joints B1, A1" in why
    z, x = [0, 0, 1], [1, 0, 0]
    helix = sm.Mechanism("rssh", limbs=[
        sm.Limb("input", [sm.R("A0", [0, 0, 0], z, actuated=True), sm.S("A1", [0.3, 0, 0]), sm.S("B1", [0, 1, -0.1])]),
        sm.Limb("output", [sm.H("B0", [0, 1, 0.5], x, pitch=0.01)])], platform_point=[0, 1, -0.1])
    why = hg.general_reason(helix)
    assert why is not None and "limb output" in why and "helical joint B0" in why
    with pytest.raises(sm.InputError, match="nor does the loop formulation: limb output: helical joint B0"):
        forward_position(helix, [0.3], all_solutions=True, method="homotopy")
    runner = CliRunner()
    out = runner.invoke(main, ["fk", "three-sps-smpu", "--actuators", "0.5,0.5,0.5", "--all", "--method", "homotopy"])
    assert out.exit_code != 0 and "does not cover three-sps-smpu" in out.output and "loop formulation" in out.output
    assert "S joints B1, A1" in out.output and "Traceback" not in out.output


def test_cli_text_and_json_say_proven_by_the_trace_test():
    runner = CliRunner()
    out = runner.invoke(main, ["fk", "rssr", "--actuators", "30", "--all"])
    assert out.exit_code == 0 and "complete (proven)" in out.output and "trace test passed" in out.output
    assert "2 real assembly modes" in out.output
    d = json.loads(runner.invoke(main, ["fk", "rssr", "--actuators", "30", "--all", "--json"]).output)
    assert d["complete"] is True and d["n_real"] == 2 and len(d["endpoints"]) == 2
    assert all(len(e["variables_real"]) == 2 for e in d["endpoints"])


def test_configuration_of_a_point_limb_and_a_study_platform():
    """A model whose limbs all carry an S joint (the platform in Study parameters): the
    variables of a closed configuration map back to that configuration."""
    m = sm.load_model("five-cs-3")
    sysm = hg.loop_system(m)
    assert sysm.study >= 0 and {le.kind for le in sysm.limbs} == {"point"}
    from spatialmech.kinematics.motion import generic_configuration

    c = generic_configuration(m, seed=2, step=0.3, steps=3)
    z = hg.variables(sysm, c)
    targets = {i: c.q[i] for i, v in sysm.var_of.items() if v[0] == "A"}
    q, D = hg.rebuild(sysm, z[: sysm.nx].real, targets)
    assert np.allclose(D, c.D, atol=1e-9)
    assert np.max(np.abs(closure_residual(m, Configuration(q, D)))) < 1e-9


@pytest.mark.parametrize("name", ["bennett", "five-cs-3", "rssr"])
def test_compiled_square_system_equals_the_numpy_reference(name):
    """The numba evaluation (kernels_loops) and the NumPy reference of the square system and its
    derivative agree at random complex points and offsets (full limbs, point limbs with a Study
    platform, rods)."""
    sysm = hg.loop_system(sm.load_model(name))
    rng = np.random.default_rng(4)
    Z = rng.normal(size=(6, sysm.nx + sysm.npar)) + 1j * rng.normal(size=(6, sysm.nx + sysm.npar))
    nw = sysm.w_offsets[-1]
    W = rng.normal(size=(6, nw)) + 1j * rng.normal(size=(6, nw))  # the limbs' offsets of the monodromy family
    F0, J0 = sysm.square(Z, W, reference=True)
    F1, J1 = sysm.square(Z, W)
    assert np.max(np.abs(F0 - F1)) < 1e-12 * (1 + np.max(np.abs(F0)))
    assert np.max(np.abs(J0 - J1)) < 1e-12 * (1 + np.max(np.abs(J0)))


def test_auto_gives_up_on_a_large_square_system_and_runs_the_multistart(monkeypatch):
    """Under method="auto" the monodromy stops at its cap (here lowered to 4 generic solutions on
    the Bennett's 40) and the multi-start runs instead, saying why; nothing unsaturated is cached."""
    monkeypatch.setattr(hg, "MONODROMY_MAX_SOLUTIONS", 4)
    hg.clear_cache()
    m = sm.load_model("bennett")
    r = forward_position(m, [0.3], all_solutions=True, n_seeds=4, method="auto")
    d = r.to_dict(m)
    assert d["complete"] is False and "multi-start" in d["completeness"] and "gave up" in d["completeness"]
    assert "n_spurious" not in d["search"]
    part = hg.general_forward(m, {0: 0.3}, capped=True)
    assert not part.saturated and "NOT saturated" in part.completeness


def test_the_cache_key_tells_which_joint_is_driven():
    """Two RSSR with the same geometry, driven at the input or at the output crank, are other
    systems: their generic solves are not shared."""
    z, x = [0, 0, 1], [1, 0, 0]

    def rssr(drive_input: bool):
        return sm.Mechanism("k", limbs=[
            sm.Limb("input", [sm.R("A0", [0, 0, 0], z, actuated=drive_input), sm.S("A1", [0.3, 0, 0]),
                              sm.S("B1", [0, 1, -0.1])]),
            sm.Limb("output", [sm.R("B0", [0, 1, 0.5], x, actuated=not drive_input)])], platform_point=[0, 1, -0.1])

    a, b = hg.loop_system(rssr(True)), hg.loop_system(rssr(False))
    assert a.key() != b.key() and a.key() == hg.loop_system(rssr(True)).key()


def test_a_dead_point_double_root_is_located_by_the_end_game():
    """An RSSR driven at its output revolute, at the output's limit angle atan(0.6 / 0.84): the
    two assembly modes merge into a double root (input crank at 90 deg). Newton cannot finish
    those paths; the Cauchy end game locates the root to rounding (winding number 2) and the
    statement says so."""
    z, x = [0, 0, 1], [1, 0, 0]
    m = sm.Mechanism("rssr-output-driven", limbs=[
        sm.Limb("input", [sm.R("A0", [0, 0, 0], z), sm.S("A1", [0.3, 0, 0]), sm.S("B1", [0, 1, -0.1])]),
        sm.Limb("output", [sm.R("B0", [0, 1, 0.5], x, actuated=True)]),
    ], platform_point=[0, 1, -0.1])
    phi = float(np.arctan2(0.6, 0.84))  # |sin(input)| = 1 there (the coupler-length equation)
    g = hg.general_forward(m, {m.freedom_refs.index(m.freedom(m.actuators[0])): phi})
    sing = [s for s in g.solutions if s.status == "singular"]
    assert len(sing) == 1 and "Cauchy end game (winding numbers [2])" in g.completeness
    assert g.complete and g.trace is not None and g.trace.passed  # an isolated double root: still complete
    c, s = sing[0].x[:2]  # the input crank's (cos, sin)
    assert abs(c) < 1e-12 and abs(s - 1) < 1e-12


# ------------------------------------------------------------------ internal bodies (link-and-joint graphs)
def _six_bar_closed_form(mech, theta):
    """The spatial six-bar's assembly modes at crank angle ``theta``, loop by loop: the rocker
    angles of the first RSSR (crank A0-A1, rod A1-B1, rocker about B0), then for each the
    follower angles of the second (rod C1-D1 from the rocker, follower about D0): at most 2 x 2."""
    b1, _ = _joint(mech, 0, 2)
    phis, b0, bx = _rocker_angles(mech, theta, b1)
    c1, _ = _joint(mech, 3, 0)
    d1, _ = _joint(mech, 3, 1)
    d0, dy = _joint(mech, 2, 0)
    rod2 = np.sum((c1 - d1) ** 2)
    out = []
    for phi in phis:
        C1 = _rotate(c1, b0, bx, phi)
        out += [(phi, psi) for psi in _circle_roots(lambda psi, C1=C1: np.sum((C1 - _rotate(d1, d0, dy, psi)) ** 2) - rod2)]
    return out


@pytest.fixture(scope="module")
def six_bar_30():
    m = sm.load_model("spatial-six-bar")
    theta = np.radians(30.0)
    return m, theta, forward_position(m, [theta], all_solutions=True, method="auto")


def test_six_bar_internal_body_every_mode_proven(six_bar_30):
    """The spatial six-bar (two RSSR loops sharing the rocker, an internal body): the loop
    formulation with the rocker and the follower each the product of their revolute from the
    ground finds 4 generic solutions, all real at crank 30 deg, each closing the whole graph;
    they are the closed form's 2 x 2 (each RSSR has two assembly modes), and the trace test proves
    the set complete."""
    m, theta, r = six_bar_30
    d = r.to_dict(m)
    assert d["complete"] is True and d["completeness"].startswith("complete (trace test)")
    assert "loop closure" in d["search"]["method"] and d["search"]["trace_test"] == "passed"
    assert d["search"]["n_generic"] == 4 and d["n_real"] == 4 and d["search"]["n_spurious"] == 0
    i_b0, i_d0 = (m.freedom_refs.index(m.freedom(n)) for n in ("B0.rot", "D0.rot"))
    modes = _six_bar_closed_form(m, theta)
    assert len(modes) == 4 and len(r.solutions) == 4
    c1, _ = _joint(m, 3, 0)
    b0, bx = _joint(m, 1, 0)
    for s in r.solutions:
        assert s.converged and s.kind == "regular"
        assert np.max(np.abs(closure_residual(m, s.config))) < 1e-9  # every limb, the rocker's B included
        assert s.config.q[0] == pytest.approx(theta)
        phi, psi = s.config.q[i_b0], s.config.q[i_d0]
        assert sum(abs(np.angle(np.exp(1j * (phi - a)))) < 1e-8 and abs(np.angle(np.exp(1j * (psi - b)))) < 1e-8
                   for a, b in modes) == 1
        Bk = s.config.B[0]  # the rocker's displacement carries C1 where the rocker angle puts it
        assert np.allclose(Bk[:3, :3] @ c1 + Bk[:3, 3], _rotate(c1, b0, bx, phi), atol=1e-9)


def test_six_bar_multistart_modes_are_among_the_proven_set(six_bar_30):
    m, theta, r = six_bar_30
    ms = forward_position(m, [theta], all_solutions=True, method="multistart", n_seeds=40, seed=1)
    assert ms.to_dict(m)["complete"] is False
    found = [s for s in ms.solutions if s.converged]
    assert found
    for s in found:
        assert any(np.allclose(s.pose.R, h.pose.R, atol=1e-7) and np.allclose(s.pose.p, h.pose.p, atol=1e-7)
                   for h in r.solutions)


def test_six_bar_described_backwards_gives_the_same_modes(six_bar_30):
    """Limbs that end at the ground or run from the output link to the rocker: the reference
    chains are inverted and the limbs' equations take their hubs the other way; same modes."""
    from spatialmech.model.mechanism import Mechanism
    from spatialmech.model.topology import link_graph

    base, theta, r0 = six_bar_30
    g = link_graph(base)
    flip = [False, True, True, True, True, True, False]
    edges = [(j.joint, j.b, j.a) if f else (j.joint, j.a, j.b) for j, f in zip(g.joints, flip, strict=True)]
    m = Mechanism.from_graph("six-backwards", [k.name for k in g.links], edges, output="follower",
                             platform_point=base.platform_point)
    sysm = hg.loop_system(m)
    assert any(h.chain and h.chain[0].inverse for h in sysm.hubs)  # a reference limb run backwards
    r = forward_position(m, [theta], all_solutions=True, method="homotopy")
    assert r.to_dict(m)["complete"] is True and len(r.solutions) == 4
    for s in r.solutions:
        assert np.max(np.abs(closure_residual(m, s.config))) < 1e-9
        assert any(np.allclose(s.pose.p, h.pose.p, atol=1e-8) and np.allclose(s.pose.R, h.pose.R, atol=1e-8)
                   for h in r0.solutions)


def _cs_body():
    """five-cs-3's five C-S limbs ending at an internal body ``mid`` (no limb without S joint
    reaches it), the output link hinged to it and held by an S-S rod from the ground: one hub
    in Study parameters, the other the product of the hinge from it."""
    import dataclasses

    f = sm.load_model("five-cs-3")
    pp = np.asarray(f.platform_point, float)
    limbs = [dataclasses.replace(limb, tip="mid") for limb in f.limbs]
    limbs.append(sm.Limb("hinge", [sm.R("H", pp, [0, 0, 1])], base="mid"))
    limbs.append(sm.Limb("rod", [sm.S("G", pp + np.array([0.5, 0.3, 0.2])), sm.S("K", pp + np.array([0.1, 0.4, 0.0]))]))
    return sm.Mechanism("cs-body", limbs, platform_point=pp, bodies=("mid",))


@pytest.mark.parametrize("name", ["spatial-six-bar", "delta", "cs-body"])
def test_hub_equations_vanish_and_rebuild_the_bodies(name):
    """With bodies (reference chains from the ground or from a hub in Study parameters, limbs
    between any two hubs): the equations vanish at a closed configuration, their derivative
    matches finite differences, the compiled system equals the NumPy reference, and the
    variables rebuild the configuration, bodies included."""
    from spatialmech.kinematics.motion import generic_configuration

    m = _cs_body() if name == "cs-body" else sm.load_model(name)
    sysm = hg.loop_system(m)
    assert sysm.n_bodies == len(m.bodies) > 0
    c = generic_configuration(m, seed=2, step=0.3, steps=3)
    z = hg.variables(sysm, c)[None]
    F, J = sysm.square(z)
    assert np.max(np.abs(F)) < 1e-9 and sysm.residual(z)[0] < 1e-9
    dz = 1e-7 * np.random.default_rng(1).normal(size=z.shape[1])
    assert np.allclose(sysm.square(z + dz)[0][0] - F[0], J[0] @ dz, atol=1e-11)
    rng = np.random.default_rng(4)
    Z = rng.normal(size=(4, z.shape[1])) + 1j * rng.normal(size=(4, z.shape[1]))
    W = rng.normal(size=(4, sysm.w_offsets[-1])) + 1j * rng.normal(size=(4, sysm.w_offsets[-1]))
    F0, J0 = sysm.square(Z, W, reference=True)
    F1, J1 = sysm.square(Z, W)
    assert np.max(np.abs(F0 - F1)) < 1e-12 * (1 + np.max(np.abs(F0)))
    assert np.max(np.abs(J0 - J1)) < 1e-12 * (1 + np.max(np.abs(J0)))
    targets = {i: c.q[i] for i, v in sysm.var_of.items() if v[0] == "A"}
    back = hg.rebuild_configuration(sysm, z[0, : sysm.nx].real, targets)
    assert np.allclose(back.D, c.D, atol=1e-9) and np.allclose(back.B, c.B, atol=1e-9)
    assert np.max(np.abs(closure_residual(m, back))) < 1e-9
