"""Stiffness (issue 28): the Cartesian stiffness against finite differences of the statics and of
the kinematics, its symmetries, units and errors (docs/stiffness.md)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.linalg import expm

import spatialmech as sm
from spatialmech.analysis.stiffness import point_transform, stiffness, with_stiffness
from spatialmech.geometry import screws as sc
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.forward import forward_position
from spatialmech.kinematics.jacobian import complete_jacobian
from spatialmech.kinematics.position import inverse_position, platform_pose
from spatialmech.model.mechanism import Pose

from .test_tolerances import scaled

STEWART_K = {f"L{i + 1}.slide": 1e6 * (1 + 0.2 * i) for i in range(6)}  # unequal legs: no accidental symmetry


def hat(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def displaced(pose: Pose, twist) -> Pose:
    """``pose`` moved by the screw displacement ``exp(twist)``, ``twist = (dtheta ; dp)`` about the origin."""
    X = np.zeros((4, 4))
    X[:3, :3], X[:3, 3] = hat(twist[:3]), twist[3:]
    D = expm(X)
    return Pose(D[:3, :3] @ pose.R, D[:3, :3] @ pose.p + D[:3, 3])


def actuator_values(mech, config, acts) -> np.ndarray:
    refs = mech.freedom_refs
    return np.array([config.q[refs.index(mech.freedom(a))] for a in acts])


def nd(w, L):
    return np.r_[w[:3], w[3:] / L]


# ------------------------------------------------------------------ 1. K against the statics
def test_stiffness_is_the_finite_difference_of_the_statics():
    """Move the platform by a small twist (nondimensional 1e-5, central differences), read the
    actuators' deflections from the inverse position, their restoring efforts ``-k dq``, and the
    wrench those efforts balance at the displaced pose from ``sm.statics`` (linear in the wrench):
    it is ``K d`` to 1e-7 relative."""
    mech = with_stiffness(sm.load_model("stewart-6sps"), actuators=STEWART_K)
    pose0 = Pose.from_euler("ZYX", [10, 5, -3], [0.05, -0.03, 1.02], degrees=True)
    c0 = inverse_position(mech, pose0).config
    r = sm.stiffness(mech, config=c0)
    L = mech.characteristic_length
    k = np.array([STEWART_K[a] for a in r.analysis.actuators])
    q0 = actuator_values(mech, c0, r.analysis.actuators)

    def held(tw):
        c = inverse_position(mech, displaced(pose0, tw)).config
        tau = -k * (actuator_values(mech, c, r.analysis.actuators) - q0)
        T = np.column_stack([list(sm.statics(mech, config=c, wrench=e).efforts.values()) for e in np.eye(6)])
        return np.linalg.solve(T, tau)  # the external wrench these efforts hold

    rng = np.random.default_rng(7)
    for _ in range(3):
        u = rng.normal(size=6)
        tw = 1e-5 * np.r_[u[:3] / L, u[3:]] / np.linalg.norm(u)
        F = (held(tw) - held(-tw)) / 2
        assert np.linalg.norm(nd(F - r.analysis.wrench_of(tw), L)) <= 1e-7 * np.linalg.norm(nd(F, L))
        # the same through the symmetric matrix and the force-first displacement
        assert np.allclose(r.matrix @ sc.swap(tw), r.analysis.wrench_of(tw), rtol=0, atol=1e-9 * np.abs(F).max())


def test_compliance_is_the_finite_difference_of_the_kinematics_with_rigid_constraints():
    """3-RPS (three rigid constraint wrenches): apply a small wrench, read the efforts from the
    statics, let each actuator give ``-tau / k`` and solve the forward position: the platform moves
    by ``C F`` (central differences)."""
    ks = {"L1.slide": 2e6, "L2.slide": 1e6, "L3.slide": 1.5e6}
    mech = with_stiffness(sm.load_model("three-rps"), actuators=ks)
    r = sm.stiffness(mech, ([0, 0, 0.33], ("ZYX", 0, 5, 5)), degrees=True)
    assert r.analysis.rigid_rank == 3 and r.compliance is not None
    c0 = r.config
    acts = r.analysis.actuators
    P0 = platform_pose(mech, c0)
    q0 = actuator_values(mech, c0, acts)
    L = mech.characteristic_length

    def moved(F):
        s = sm.statics(mech, config=c0, wrench=F)
        dq = -np.array([s.efforts[a] / ks[a] for a in acts])
        vals = q0 + dq + np.array([mech.freedom(a).freedom.offset for a in acts])
        sol = forward_position(mech, vals, start=c0).solutions[0]
        assert sol.converged
        P = sol.pose
        Rd = P.R @ P0.R.T
        dth = np.array([Rd[2, 1] - Rd[1, 2], Rd[0, 2] - Rd[2, 0], Rd[1, 0] - Rd[0, 1]]) / 2  # small rotation
        dp = P.p - P0.p - np.cross(dth, P0.p)  # the point at the origin
        return np.r_[dp, dth]

    rng = np.random.default_rng(3)
    for _ in range(2):
        F = rng.normal(size=6) * np.r_[1.0, 1.0, 1.0, L, L, L] * 20.0
        d = (moved(F) - moved(-F)) / 2
        expect = r.compliance @ F
        assert np.linalg.norm(np.r_[d[:3], L * d[3:]] - np.r_[expect[:3], L * expect[3:]]) <= \
            2e-5 * np.linalg.norm(np.r_[expect[:3], L * expect[3:]])


def test_compliance_is_the_sum_over_the_actuators_of_their_unit_twists():
    """Actuators only, non-singular: ``C = sum_j (1 / k_j) s_j s_j^T`` with ``s_j`` (force-first)
    the twist of actuator ``j`` alone: a column of ``J^-1``; ``K C`` projects onto the allowed
    motions; K is ``J_a^T k J_a`` in the twist convention."""
    for name, ks in (("three-rps", {"L1.slide": 2e6, "L2.slide": 1e6, "L3.slide": 1.5e6}), ("stewart-6sps", STEWART_K)):
        mech = with_stiffness(sm.load_model(name), actuators=ks)
        c = Configuration.reference(mech)
        r = stiffness(mech, c)
        J = complete_jacobian(mech, c)
        Jinv = np.linalg.inv(J.matrix)
        nc = J.constraint_rows
        C = sum(np.outer(sc.swap(Jinv[:, nc + j]), sc.swap(Jinv[:, nc + j])) / ks[a] for j, a in enumerate(J.actuators))
        assert np.allclose(r.compliance, C, rtol=0, atol=1e-9 * np.abs(C).max())
        Ja = J.matrix[nc:]
        kd = np.array([ks[a] for a in J.actuators])
        assert np.allclose(sc.swap(sc.swap(r.matrix).T).T, Ja.T @ (kd[:, None] * Ja), atol=1e-9 * np.abs(r.matrix).max())


# ------------------------------------------------------------------ 2. symmetry, invariance
@pytest.mark.parametrize("name", ["stewart-6sps", "three-rps", "delta"])
def test_stiffness_and_compliance_are_symmetric_and_positive(name):
    r = sm.stiffness(name, actuator_stiffness=3.0)
    K = r.matrix
    assert np.allclose(K, K.T, atol=1e-12 * np.abs(K).max())
    assert np.all(np.linalg.eigvalsh(K) >= -1e-9 * np.abs(K).max())
    if r.compliance is not None:
        assert np.allclose(r.compliance, r.compliance.T, atol=1e-12 * np.abs(r.compliance).max())
        # C K C = C: the compliance is the inverse of K on the allowed motions
        assert np.allclose(r.compliance @ K @ r.compliance, r.compliance, atol=1e-9 * np.abs(r.compliance).max())
    # each principal direction: K d = k S^2 d about the platform point (an eigenvector), up to
    # the rigid constraint wrenches (which do no work on the allowed displacements)
    A, B = point_transform(r.analysis.reference_point)
    L = r.analysis.characteristic_length
    S2 = np.diag([1, 1, 1, L * L, L * L, L * L])
    free = [A @ sc.swap(t) for k, t in zip(r.principal_stiffness, r.principal_twists, strict=True) if np.isfinite(k)]
    for k, t in zip(r.principal_stiffness, r.principal_twists, strict=True):
        if np.isfinite(k):
            dP = A @ sc.swap(t)
            residual = B @ K @ sc.swap(t) - k * S2 @ dP
            assert np.allclose([residual @ d for d in free], 0.0, atol=1e-9 * np.abs(K).max() * L)


def test_stewart_home_pose_is_invariant_under_the_120_degree_rotation():
    """Equal legs at the home pose: K about the origin (on the symmetry axis) satisfies
    ``K = Q K Q^T`` with ``Q = diag(Rz, Rz)`` for a 120-degree turn; the lateral stiffnesses come
    in pairs, and the softest direction is chosen by its space (rref), not by the eigen-solver."""
    r = sm.stiffness("stewart-6sps", actuator_stiffness=2e6)
    Rz = np.array([[np.cos(2 * np.pi / 3), -np.sin(2 * np.pi / 3), 0], [np.sin(2 * np.pi / 3), np.cos(2 * np.pi / 3), 0],
                   [0, 0, 1]])
    Q = np.kron(np.eye(2), Rz)
    assert np.allclose(Q @ r.matrix @ Q.T, r.matrix, atol=1e-9 * np.abs(r.matrix).max())
    assert list(r.analysis.multiplicity) == [2, 2, 1, 2, 2, 1]
    assert r.softest_stiffness == pytest.approx(r.principal_stiffness[1], rel=1e-12)
    # the pair's directions: rotations about y and x through the same point above the platform
    t0, t1 = r.principal_twists[:2]
    assert abs(t0[0]) < 1e-12 and abs(t0[2]) < 1e-12 and abs(t1[1]) < 1e-12 and abs(t1[2]) < 1e-12
    again = sm.stiffness("stewart-6sps", actuator_stiffness=2e6)
    assert np.array_equal(again.principal_twists, r.principal_twists)


def test_rotating_the_whole_model_rotates_the_answer():
    """The principal stiffnesses do not depend on the frame the model is written in (they are
    computed about the platform point)."""
    m = sm.load_model("three-rps")
    r1 = sm.stiffness(m, actuator_stiffness=1e6)
    shifted = _translated(m, np.array([0.3, -0.2, 0.1]))
    r2 = sm.stiffness(shifted, actuator_stiffness=1e6)
    assert np.allclose(r1.principal_stiffness[:3], r2.principal_stiffness[:3], rtol=1e-9)


def _translated(mech, v):
    from dataclasses import replace

    limbs = []
    for limb in mech.limbs:
        joints = [replace(j, point=j.point + v, freedoms=tuple(replace(f, point=f.point + v) for f in j.freedoms))
                  for j in limb.joints]
        limbs.append(replace(limb, joints=tuple(joints)))
    return replace(mech, limbs=tuple(limbs), platform_point=mech.platform_point + v)


# ------------------------------------------------------------------ 3. units and scale
def test_a_millimetre_model_scales_as_the_units_say():
    """The same Stewart in mm with the same physical legs (1e6 N/m = 1e3 N/mm): the translation
    block in N/mm is 1000 times smaller, the coupling (N) the same, the rotation block (N mm/rad)
    1000 times larger; the principal stiffnesses (N per length unit) 1000 times smaller; the
    directions the same (in nondimensional terms)."""
    m = sm.load_model("stewart-6sps")
    a = sm.stiffness(m, actuator_stiffness=1e6)
    b = sm.stiffness(scaled(m, 1000.0), actuator_stiffness=1e3)
    K, Kmm = a.matrix, b.matrix
    scale = np.abs(K).max()
    assert np.allclose(Kmm[:3, :3] * 1e3, K[:3, :3], atol=1e-9 * scale)
    assert np.allclose(Kmm[:3, 3:], K[:3, 3:], atol=1e-9 * scale)
    assert np.allclose(Kmm[3:, 3:] / 1e3, K[3:, 3:], atol=1e-9 * scale)
    assert np.allclose(b.principal_stiffness * 1e3, a.principal_stiffness, rtol=1e-9)
    assert np.allclose(b.principal_twists[:, :3] * 1e3, a.principal_twists[:, :3], atol=1e-9)
    assert np.allclose(b.principal_twists[:, 3:], a.principal_twists[:, 3:], atol=1e-9)


def test_stiffness_is_linear_in_the_springs_and_defaults_are_said():
    a = sm.stiffness("stewart-6sps")
    b = sm.stiffness("stewart-6sps", actuator_stiffness=5.0)
    assert np.allclose(5 * a.matrix, b.matrix)
    assert a.analysis.defaulted == a.analysis.actuators and not b.analysis.defaulted
    assert any("1 assumed" in n for n in a.notes) and not any("assumed" in n for n in b.notes)


# ------------------------------------------------------------------ 4. constraints, singular poses
def test_elastic_constraints_tend_to_the_rigid_ones():
    ks = {"L1.slide": 2e6, "L2.slide": 1e6, "L3.slide": 1.5e6}
    rigid = sm.stiffness("three-rps", actuator_stiffness=ks)
    stiff = sm.stiffness("three-rps", actuator_stiffness=ks, constraint_stiffness=1e14)
    soft = sm.stiffness("three-rps", actuator_stiffness=ks, constraint_stiffness=1e5)
    assert rigid.analysis.rigid_rank == 3 and stiff.analysis.rigid_rank == 0
    assert np.all(np.isinf(rigid.principal_stiffness[3:])) and np.all(np.isfinite(stiff.principal_stiffness))
    assert np.allclose(stiff.compliance, rigid.compliance, atol=1e-6 * np.abs(rigid.compliance).max())
    assert np.allclose(np.linalg.inv(stiff.matrix), stiff.compliance, atol=1e-6 * np.abs(rigid.compliance).max())
    assert soft.softest_stiffness < rigid.softest_stiffness
    # the constraint springs do not depend on the basis of the limb's constraint system
    one = sm.stiffness("three-rps", actuator_stiffness=ks, constraint_stiffness={"leg1": 1e7})
    assert one.analysis.rigid_rank == 2


def test_a_singular_pose_has_zero_softest_stiffness_along_the_uncontrolled_motion():
    r = sm.stiffness("four-sps-cu", actuator_stiffness=1e6)  # the reference pose: rotation about z uncontrolled
    assert r.singular and r.compliance is None and r.softest_stiffness == 0.0
    t = r.softest_twist
    assert np.allclose(t[[0, 1, 3, 4, 5]], 0.0, atol=1e-9) and t[2] > 0
    J = r.analysis.jacobian
    assert np.allclose(J.matrix @ t, 0.0, atol=1e-9)
    assert r.to_dict()["compliance"] is None and any("singular" in n for n in r.notes)


# ------------------------------------------------------------------ 5. the model file
TOML = """
name = "stiff-rps"
length_unit = "mm"
[[limbs]]
name = "leg1"
constraint_stiffness = 5e4
[[limbs.joints]]
name = "R1"
type = "R"
point = [0, 300, 0]
axis = [-1, 0, 0]
[[limbs.joints]]
name = "L1"
type = "P"
point = [0, 300, 0]
axis = [0, -0.4472135954999579, 0.8944271909999159]
actuated = true
offset = 335.4101966249685
stiffness = 2000
[[limbs.joints]]
name = "S1"
type = "S"
point = [0, 150, 300]
"""


def test_the_model_file_carries_the_stiffness_and_writes_it_back():
    text = sm.dumps(sm.load_model("three-rps"))
    assert "stiffness" not in text  # existing models are unchanged
    m = sm.loads(TOML)
    assert m.freedom("L1.slide").freedom.stiffness == 2000.0 and m.limbs[0].constraint_stiffness == 5e4
    back = sm.loads(sm.dumps(m))
    assert back.freedom("L1.slide").freedom.stiffness == 2000.0 and back.limbs[0].constraint_stiffness == 5e4
    table = sm.loads(TOML + "stiffness = {rot2 = 7}\n")
    assert table.freedom("S1.rot2").freedom.stiffness == 7.0
    assert sm.loads(sm.dumps(table)).freedom("S1.rot2").freedom.stiffness == 7.0


@pytest.mark.parametrize("old, new, field", [
    ("stiffness = 2000", "stiffness = -1", "limbs[0].joints[1].stiffness"),
    ("stiffness = 2000", "stiffness = 0", "limbs[0].joints[1].stiffness"),
    ("stiffness = 2000", 'stiffness = "stiff"', "limbs[0].joints[1].stiffness"),
    ("stiffness = 2000", "stiffness = {rot = 3}", "limbs[0].joints[1].stiffness"),
    ("constraint_stiffness = 5e4", "constraint_stiffness = -3", "limbs[0].constraint_stiffness"),
    ("constraint_stiffness = 5e4", "constraint_stiffness = true", "limbs[0].constraint_stiffness"),
])
def test_bad_stiffness_in_a_file_names_the_field(old, new, field):
    with pytest.raises(sm.ModelFileError, match=field.replace("[", r"\[").replace("]", r"\]").replace(".", r"\.")):
        sm.loads(TOML.replace(old, new))


def test_bad_arguments_name_them():
    with pytest.raises(sm.InputError, match="actuator_stiffness"):
        sm.stiffness("stewart-6sps", actuator_stiffness=-1)
    with pytest.raises(sm.InputError, match=r"actuator_stiffness.*nan"):
        sm.stiffness("stewart-6sps", actuator_stiffness=float("nan"))
    with pytest.raises(TypeError, match="actuator_stiffness"):
        sm.stiffness("stewart-6sps", actuator_stiffness="stiff")
    with pytest.raises(TypeError, match="constraint_stiffness"):
        sm.stiffness("stewart-6sps", constraint_stiffness=True)
    with pytest.raises(sm.InputError, match="constraint_stiffness: unknown limb 'legX'"):
        sm.stiffness("three-rps", constraint_stiffness={"legX": 1.0})
    with pytest.raises(sm.UnknownNameError, match="L9"):
        sm.stiffness("three-rps", actuator_stiffness={"L9.slide": 1.0})
    with pytest.raises(sm.InputError, match="over"):
        sm.stiffness_map("stewart-6sps", over={"q": (0, 1, 2)})


# ------------------------------------------------------------------ 6. the slice and the command
def test_the_slice_agrees_with_the_pointwise_answer():
    r = sm.stiffness_map("stewart-6sps", over={"y": (-0.1, 0.1, 3)}, at={"z": 1.0}, actuator_stiffness=1e6)
    assert r.status_counts()["ok"] == 3
    one = sm.stiffness("stewart-6sps", ([0, 0.1, 1.0], None), actuator_stiffness=1e6)
    assert r.softest[2] == pytest.approx(one.softest_stiffness, rel=1e-9)
    assert r.softest[0] == pytest.approx(r.softest[2], rel=1e-6)  # mirror symmetry about the xz plane
    out = sm.stiffness_map("three-rps", over={"x": (0.5, 0.6, 2)}, at={"z": 0.3})
    assert out.status_counts()["unreachable"] == 2 and np.all(np.isnan(out.softest)) and out.minimum() is None


def test_the_command_prints_and_plots(tmp_path):
    run = CliRunner().invoke(cli, ["stiffness", "stewart-6sps", "--k", "2e6"], catch_exceptions=False)
    assert run.exit_code == 0 and "softest: 605311 N/m" in run.output
    png = tmp_path / "soft.png"
    run = CliRunner().invoke(cli, ["stiffness", "three-rps", "--k", "1e6", "--over", "alpha:-10:10:3,beta:-10:10:2",
                                   "--at", "z=0.3", "--plot", str(png), "--json"], catch_exceptions=False)
    assert run.exit_code == 0, run.output
    d = json.loads(run.output)
    assert d["result"] == "stiffness_map" and d["plot"] == str(png) and png.stat().st_size > 1000
    bad = CliRunner().invoke(cli, ["stiffness", "stewart-6sps", "--k", "L1.slide=abc"])
    assert bad.exit_code == 2 and "--k: L1.slide expects a number" in bad.output
    bad = CliRunner().invoke(cli, ["stiffness", "stewart-6sps", "--at", "z=1"])
    assert bad.exit_code == 2 and "--at: only with --over" in bad.output
