"""Every inverse solution of a limb by homotopy continuation, with a completeness statement
(issue 27: "Complete inverse position of any limb or serial chain")."""

import numpy as np
import pytest

import spatialmech as sm
from spatialmech.errors import InputError
from spatialmech.kinematics.closure import chain_forward, limb_chains
from spatialmech.kinematics.homotopy import inverse as ikh
from spatialmech.kinematics.position import inverse_position
from spatialmech.model.joints import H, R, S, U, P
from spatialmech.model.mechanism import Limb, Mechanism

from .test_ik_distinct import PUMA560_DH, _check_serial_solutions, dh_pose, serial_arm


def _closes(mech, li, pose, sols, tol=1e-9):
    D = pose.displacement(mech.platform_point)
    ch = sm.kinematics.closure.limb_chains(mech)[li]
    for q in sols:
        T, _ = chain_forward(ch, np.asarray(q))
        assert np.max(np.abs(T - D)) < tol


def _wrapped(x):
    return np.angle(np.exp(1j * np.asarray(x)))


def _same_sets(a, b):
    assert len(a) == len(b)
    for q in a:
        assert any(np.max(np.abs(_wrapped(q - p))) < 1e-7 for p in b)


def test_puma560_eight_of_eight_proven():
    m = serial_arm("puma560", PUMA560_DH)
    theta = np.array([0.3, -0.7, 0.5, 0.9, 0.6, -0.4])
    pose = dh_pose(PUMA560_DH, theta)
    res = inverse_position(m, pose, all_solutions=True, method="homotopy")
    rep = res.search["limbs"][0]
    assert rep["method"] == "homotopy" and rep["complete"] and rep["completeness"].startswith("complete (proven")
    assert "Pieper" in rep["completeness"] and rep["n_paths"] == 8
    sols = [np.asarray(q) for q in res.limbs[0].solutions]
    assert len(sols) == 8 and res.search["complete"]
    _check_serial_solutions(PUMA560_DH, theta, sols)
    ms = inverse_position(m, pose, all_solutions=True, method="multistart", n_seeds=200)
    assert ms.search["limbs"][0]["method"] == "multistart" and not ms.search["limbs"][0]["complete"]
    _same_sets(sols, [np.asarray(q) for q in ms.limbs[0].solutions])
    # a re-solve at another pose tracks the cached 8 paths
    theta2 = np.array([-1.0, 0.4, -0.3, 0.2, -0.9, 1.1])
    res2 = inverse_position(m, dh_pose(PUMA560_DH, theta2), all_solutions=True)
    assert res2.search["limbs"][0]["cached"] and len(res2.limbs[0].solutions) == 8
    _check_serial_solutions(PUMA560_DH, theta2, [np.asarray(q) for q in res2.limbs[0].solutions])


def random_6r(seed=0):
    """A random general 6R: the count checked is its 16 complex solutions, proven by the root
    count (the published 16-real arm, Manseur and Doty's, is tests/test_6r_literature.py)."""
    rng = np.random.default_rng(seed)
    dh = [(rng.uniform(-0.5, 0.5), rng.uniform(0.1, 0.6), rng.uniform(-np.pi, np.pi)) for _ in range(6)]
    return dh, rng.uniform(-np.pi, np.pi, 6)


def test_general_6r_sixteen_proven_and_real_ones_close():
    dh, theta = random_6r(0)
    m = serial_arm("random-6r", dh)
    res = inverse_position(m, dh_pose(dh, theta), all_solutions=True)  # auto: the homotopy covers a 6R
    rep = res.search["limbs"][0]
    assert rep["method"] == "homotopy" and rep["complete"] and rep["n_paths"] == 16
    assert "root count: 16" in rep["completeness"]
    assert rep["n_real"] + rep["n_complex"] + rep["n_at_infinity"] + rep["n_singular"] == 16
    sols = [np.asarray(q) for q in res.limbs[0].solutions]
    assert len(sols) == rep["n_real"] >= 1 and len(sols) % 2 == 0  # complex ones come in pairs
    _check_serial_solutions(dh, theta, sols)
    # the multi-start finds no real solution the homotopy misses
    ms = inverse_position(m, dh_pose(dh, theta), all_solutions=True, method="multistart", n_seeds=300)
    for q in ms.limbs[0].solutions:
        assert any(np.max(np.abs(_wrapped(np.asarray(q) - p))) < 1e-7 for p in sols)


def planar_rrr_leg():
    """One leg of a planar 3-RRR (three parallel axes): two working modes."""
    z = np.array([0, 0, 1.0])
    return Mechanism("rrr-leg", (Limb("leg", (R("A", [1.0, 0, 0], z, actuated=True), R("B", [1.0, 0.6, 0], z),
                                                   R("C", [0.3, 0, 0], z))),), platform_point=np.zeros(3))


def test_planar_rrr_leg_two_modes_proven_by_trace_test():
    m = planar_rrr_leg()
    from scipy.spatial.transform import Rotation

    pose = sm.Pose(Rotation.from_rotvec([0, 0, 0.1]).as_matrix(), [0.05, -0.02, 0])
    res = inverse_position(m, pose, all_solutions=True, method="homotopy")
    rep = res.search["limbs"][0]
    assert rep["method"] == "homotopy" and rep["complete"] and "trace test passed" in rep["completeness"]
    assert len(res.limbs[0].solutions) == 2
    _closes(m, 0, pose, res.limbs[0].solutions)


def test_rus_type_limb_proven_by_its_root_count():
    e = np.eye(3)
    # an R-U-S limb: three revolutes place the S joint's centre (Pieper's quartic bounds it)
    rus = Mechanism("rus", (Limb("leg", (R("A", [0.2, 0, 0], e[2]), U("U", [0.2, 0.1, 0.3], [e[0], [0, 0.6, 0.8]]),
                                         S("S", [0.1, 0.05, 0.6]))),), platform_point=np.array([0.1, 0.05, 0.6]))
    q = np.array([0.3, -0.4, 0.2, 0.1, 0.2, -0.3])
    T, _ = chain_forward(sm.kinematics.closure.limb_chains(rus)[0], q)
    pose = sm.Pose.from_displacement(T, rus.platform_point)
    res = inverse_position(rus, pose, all_solutions=True, method="homotopy")
    rep = res.search["limbs"][0]
    assert rep["method"] == "homotopy" and rep["complete"], rep["completeness"]
    assert 1 <= len(res.limbs[0].solutions) <= 4
    _closes(rus, 0, pose, res.limbs[0].solutions)


def test_rrrp_type_limb(monkeypatch):
    """An R-R-R-P serial chain (fewer freedoms than conditions: the random combination and
    offset): the homotopy finds the pose's own solution, and every solution closes.  No proof is
    claimed here: the trace test on this limb ends inconclusive ("a path of its homotopies
    failed") after about 80 s of work, so its work cap is set to nothing (the trace test's own
    tests: test_planar_rrr_leg_two_modes_proven_by_trace_test, tests/test_homotopy_general.py)."""
    e = np.eye(3)
    monkeypatch.setattr(ikh, "TRACE_MAX_WORK_FULL", 1)
    ikh.clear_cache()  # a generic solve cached earlier in this process keeps its trace verdict
    rrrp = Mechanism("rrrp", (Limb("arm", (R("A", [0, 0, 0], e[2]), R("B", [0.3, 0, 0.2], e[1]),
                                           R("C", [0.6, 0.1, 0.2], [0, 0.6, 0.8]), P("D", [0.8, 0.1, 0.3], e[0]))),),
                     platform_point=np.array([0.9, 0.1, 0.3]))
    q = np.array([0.4, -0.2, 0.7, 0.05])
    T, _ = chain_forward(sm.kinematics.closure.limb_chains(rrrp)[0], q)
    pose = sm.Pose.from_displacement(T, rrrp.platform_point)
    res = inverse_position(rrrp, pose, all_solutions=True, method="homotopy")
    rep = res.search["limbs"][0]
    assert rep["method"] == "homotopy" and not rep["complete"] and "work cap" in rep["completeness"]
    assert any(np.max(np.abs(_wrapped(np.asarray(s) - q))) < 1e-7 for s in res.limbs[0].solutions)
    _closes(rrrp, 0, pose, res.limbs[0].solutions)
    ikh.clear_cache()  # no capped verdict left for later tests


def test_helical_pitch_refused_to_multistart_with_a_label():
    e = np.eye(3)
    m = Mechanism("rhr", (Limb("arm", (R("A", [0, 0, 0], e[2]), H("H", [0.3, 0, 0], e[0], pitch=0.02),
                                       R("C", [0.5, 0.2, 0], e[1]))),), platform_point=np.array([0.6, 0.2, 0]))
    with pytest.raises(InputError, match="transcendental"):
        ikh.limb_ik_system(m, 0)
    T, _ = chain_forward(sm.kinematics.closure.limb_chains(m)[0], np.array([0.2, 0.3, -0.1]))
    res = inverse_position(m, sm.Pose.from_displacement(T, m.platform_point), all_solutions=True, method="homotopy")
    rep = res.search["limbs"][0]
    assert rep["method"] == "multistart" and not rep["complete"]
    assert "transcendental" in rep["homotopy_refused"] and rep["completeness"].startswith("NOT proven")
    assert res.reachable


def test_passive_spin_keeps_the_multistart():
    from spatialmech import catalog  # the subpackage, not an attribute of the lazy facade

    m = catalog.build("stewart-6sps") if "stewart-6sps" in catalog.names() else None
    if m is None:
        pytest.skip("no Stewart model in the catalogue")
    res = inverse_position(m, sm.kinematics.position.platform_pose(m, sm.kinematics.closure.Configuration.reference(m)),
                           all_solutions=True, n_seeds=4)
    for rep in res.search["limbs"]:
        assert rep["method"] == "multistart" and "passive" in rep["completeness"]


def test_unknown_method_is_refused():
    m = planar_rrr_leg()
    with pytest.raises(InputError, match="method"):
        inverse_position(m, sm.Pose(np.eye(3), [0, 0, 0]), all_solutions=True, method="bogus")


def test_auto_takes_the_homotopy_only_where_a_root_count_proves_the_limb(tmp_path):
    """``method="auto"`` (the default of ``sm.ik`` and ``ik --all``): the PUMA 560 (Pieper's bound
    of 8) by the homotopy, proven; the planar RRR leg (no root count known, a proof would need
    the trace test) by the multi-start, labelled with the reason."""
    from click.testing import CliRunner

    from spatialmech.interfaces.cli import cli

    ikh.clear_cache()
    puma = serial_arm("puma560", PUMA560_DH)
    pose = dh_pose(PUMA560_DH, np.array([0.2, -0.5, 0.4, 0.7, 0.5, -0.3]))
    r = sm.ik(puma, pose, all_solutions=True)
    rep = r.to_dict()["search"]["limbs"][0]
    assert rep["method"] == "homotopy" and rep["complete"] and len(r.result.limbs[0].solutions) == 8
    leg = planar_rrr_leg()
    leg_pose = sm.Pose(np.eye(3), [0.05, -0.02, 0])
    rep = sm.ik(leg, leg_pose, all_solutions=True).to_dict()["search"]["limbs"][0]
    assert rep["method"] == "multistart" and not rep["complete"] and "root-count bound" in rep["completeness"]
    with pytest.raises(InputError, match="method"):
        sm.ik(puma, pose, method="homotopy")  # method needs all_solutions
    with pytest.raises(InputError, match="method"):
        sm.ik(puma, pose, all_solutions=True, method="newton")
    # the command line says it per limb, next to the solutions
    path = str(tmp_path / "puma560.toml")
    sm.export(puma, path)
    out = CliRunner().invoke(cli, ["ik", path, "--xyz", *map(str, pose.p), "--euler", "ZYX",
                                   *map(str, np.degrees(sm.api.matrix_euler("ZYX", pose.R))), "--all"])
    assert out.exit_code == 0, out.output
    assert "8 solution(s)" in out.output and "homotopy: complete (proven" in out.output


def test_a_path_stopped_midway_is_re_tracked_through_a_waypoint(monkeypatch):
    """A path of the re-solve that stops midway (a near miss of a branch point) sends every path
    through a random complex waypoint near the pose: the same real solutions, still proven, and
    the statement says so.  The stop is simulated on the straight segment's first path."""
    dh, theta = random_6r(0)
    m = serial_arm("random-6r", dh)
    pose = dh_pose(dh, theta)
    ref = inverse_position(m, pose, all_solutions=True, method="homotopy")
    real = ikh._segment

    def stalled(sysm, X, P0, P1, steps=None):
        Xe, t, done = real(sysm, X, P0, P1, steps)
        if np.ndim(P0) == 1 and np.allclose(P0, ikh._CACHE[sysm.key].P0) and np.allclose(P1[7:], 0) and not stalled.hit:
            stalled.hit = True
            t, done = t.copy(), done.copy()
            t[0], done[0] = 0.4, False
        return Xe, t, done

    stalled.hit = False
    monkeypatch.setattr(ikh, "_segment", stalled)
    res = inverse_position(m, pose, all_solutions=True, method="homotopy")
    rep = res.search["limbs"][0]
    assert stalled.hit and rep["complete"] and "waypoint" in rep["completeness"]
    _same_sets([np.asarray(q) for q in res.limbs[0].solutions], [np.asarray(q) for q in ref.limbs[0].solutions])


def test_angles_of_far_complex_points_keep_their_digits():
    """``c + i s`` is a difference of nearly equal large numbers when the angle is far from real:
    :meth:`LimbIK.angles` takes ``c - i s`` there, so the angles round-trip to rounding."""
    dh, _ = random_6r(0)
    sysm = ikh.limb_ik_system(serial_arm("random-6r", dh), 0)
    TH = np.array([[0.3 + 9j, -1.2 - 11j, 2.0 + 0.1j, 0.5 - 7j, -2.9 + 12j, 1.0]])
    back = sysm.angles(sysm.from_angles(TH))
    assert np.max(np.abs(np.angle(np.exp(1j * (back - TH)))) + np.abs((back - TH).imag)) < 1e-12


def test_a_real_solution_at_a_singular_configuration_is_never_called_complex():
    """At the DH zero every standard-DH arm is singular (every joint axis is perpendicular to x0:
    a couple about x0 is reciprocal to all of them); the pose reached there is a double root of
    the 6R's system.  Its two end points keep ~1e-6 imaginary parts, which were counted complex:
    the answer said "complete (proven) ... 0 real, 16 complex" with no solution.  Now they are
    singular end points: listed (near the true configuration), and the set is NOT proven."""
    rng = np.random.default_rng(0)
    dh = [(rng.uniform(-0.5, 0.5), rng.uniform(0.1, 0.6), rng.uniform(-np.pi, np.pi)) for _ in range(6)]
    m = serial_arm("random-6r", dh)
    _, J = chain_forward(limb_chains(m)[0], np.zeros(6))
    assert np.linalg.svd(J, compute_uv=False)[-1] < 1e-12  # singular there
    q = np.r_[np.zeros(5), 0.9]  # turning the last joint keeps the configuration singular
    res = inverse_position(m, dh_pose(dh, q), all_solutions=True)
    rep = res.search["limbs"][0]
    assert not rep["complete"] and "singular" in rep["completeness"], rep["completeness"]
    assert any(np.allclose(np.angle(np.exp(1j * (s - q))), 0, atol=1e-5) for s in res.limbs[0].solutions)
