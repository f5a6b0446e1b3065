"""Forward position of S-P-S platforms in pose coordinates (kinematics/leg_platform.py): the same
pose as the general engine, each leg's idle spin by the shortest-turn rule, the compiled and
Python paths equal, and the general engine as the fallback."""

from __future__ import annotations

from contextlib import nullcontext
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech import catalog
from spatialmech.errors import InputError
from spatialmech.geometry.rotations import exp_twist, matrix_rotvec, rotvec_matrix
from spatialmech.kinematics import backend, leg_platform
from spatialmech.kinematics.closure import Configuration, active_mask
from spatialmech.kinematics.backend import closure_residual, correct
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.compiled.kernels_legs import nb_shortest_rotation, nb_shortest_rotvec

ROOT = Path(__file__).resolve().parents[1]
pure = backend.python_reference


def _stewart():
    mech = catalog.build("stewart-6sps")
    lp = leg_platform.leg_platform(mech)
    held = active_mask(mech)
    held[lp.index[:, 1]] = False
    return mech, lp, held


def _seed(mech, lp, target: Configuration, start: Configuration) -> Configuration:
    q = start.q.copy()
    q[lp.index[:, 1]] = target.q[lp.index[:, 1]]
    return Configuration(q, start.D)


def _dietmaier():
    mech = sm.load(ROOT / "examples" / "models" / "stewart-dietmaier.toml")
    lp = leg_platform.leg_platform(mech)
    held = active_mask(mech)
    held[lp.index[:, 1]] = False
    return mech, lp, held


def test_the_path_applies_to_six_sps_legs_with_the_slides_held_only():
    mech, lp, held = _stewart()
    assert lp is not None and lp.index.shape == (6, 3)
    assert lp.applies(held)
    assert not lp.applies(active_mask(mech))  # a slide free: the general engine
    other = held.copy()
    other[0] = False  # a ball freedom held
    assert not lp.applies(other)
    for name in ("four-sps-cu", "three-rps", "three-sps-smpu", "five-cs-3", "delta"):
        assert leg_platform.leg_platform(catalog.build(name)) is None, name
    assert _dietmaier()[1] is not None


@pytest.mark.parametrize("seed", [3, 11, 29])
def test_the_pose_equals_the_general_engines_and_only_idle_spins_differ(seed):
    """From the reference with the legs of a generic pose held: the pose path and the general
    Newton on 42 joint variables reach the same pose; each leg points the same way and keeps its
    slide; the joint values differ only by turns of a leg about its own axis."""
    mech, lp, held = _stewart()
    target = generic_configuration(mech, seed=seed, step=0.25)
    start = _seed(mech, lp, target, Configuration.reference(mech))
    auto = correct(mech, start, active=held)
    joints = correct(mech, start, active=held, method="joints")
    assert auto.converged and joints.converged
    assert auto.residual < 1e-12 and joints.residual < 1e-12
    np.testing.assert_allclose(auto.config.D, joints.config.D, atol=1e-12)
    np.testing.assert_allclose(auto.config.D, target.D, atol=1e-10)
    qa, qj = auto.config.q, joints.config.q
    np.testing.assert_array_equal(qa[lp.index[:, 1]], start.q[lp.index[:, 1]])
    for k, (i1, i_s, _) in enumerate(lp.index):
        A1 = lp.axes[k, 0]
        Ra, Rj = rotvec_matrix(A1 @ qa[i1:i1 + 3]), rotvec_matrix(A1 @ qj[i1:i1 + 3])
        w = lp.tip[k] - lp.base[k] + qa[i_s] * lp.direction[k]
        u = w / np.linalg.norm(w)
        np.testing.assert_allclose(Ra @ u, Rj @ u, atol=1e-12)  # the same leg direction
        spin = matrix_rotvec(Rj.T @ Ra)  # what differs is a turn about the leg's own axis
        np.testing.assert_allclose(np.cross(spin, u), 0.0, atol=1e-10)
    assert np.abs(qa - qj).max() > 1e-3  # the spins do differ: the rule, not the path, sets them


@pytest.mark.parametrize("seed", [1, 2, 5])
def test_each_base_ball_turns_the_shortest_way_from_the_seed(seed):
    """The rotation from the seed's base ball to the result's is about (old leg direction) x (new
    leg direction) and takes one to the other."""
    mech, lp, held = _stewart()
    rng = np.random.default_rng(seed)
    target = generic_configuration(mech, seed=seed, step=0.3)
    D = exp_twist(0.05 * rng.standard_normal(6), 1.0) @ target.D
    start = Configuration(target.q + 0.2 * rng.standard_normal(len(target.q)), D)
    start = _seed(mech, lp, target, start)
    res = correct(mech, start, active=held)
    assert res.converged
    for k, (i1, i_s, _) in enumerate(lp.index):
        A1 = lp.axes[k, 0]
        R0, R1 = rotvec_matrix(A1 @ start.q[i1:i1 + 3]), rotvec_matrix(A1 @ res.config.q[i1:i1 + 3])
        w = lp.tip[k] - lp.base[k] + start.q[i_s] * lp.direction[k]
        u0, u1 = R0 @ w / np.linalg.norm(w), R1 @ w / np.linalg.norm(w)
        turn = matrix_rotvec(R1 @ R0.T)
        np.testing.assert_allclose(rotvec_matrix(turn) @ u0, u1, atol=1e-12)
        assert abs(turn @ u0) < 1e-12 and abs(turn @ u1) < 1e-12
        assert abs(np.linalg.norm(turn) - np.arccos(np.clip(u0 @ u1, -1, 1))) < 1e-9


def _unit(v):
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


vectors = st.lists(st.floats(-1, 1), min_size=3, max_size=3).filter(lambda v: np.linalg.norm(v) > 1e-3)


@settings(max_examples=60, deadline=None)
@given(vectors, vectors, st.booleans())
def test_shortest_rotation_takes_a_to_b_about_their_normal(a, b, opposite):
    a = _unit(a)
    b = -a if opposite else _unit(b)
    v = leg_platform.shortest_rotvec(a, b)
    np.testing.assert_allclose(rotvec_matrix(v) @ a, b, atol=1e-12)
    assert abs(v @ a) < 1e-12  # perpendicular to a (and to b)
    np.testing.assert_allclose(np.linalg.norm(v), np.arccos(np.clip(a @ b, -1.0, 1.0)), atol=1e-7)
    out = np.empty(3)
    nb_shortest_rotvec(*a, *b, out)
    np.testing.assert_allclose(out, v, atol=1e-15)
    M = leg_platform.shortest_rotation(a, b)  # the same rotation, without trigonometry unless > 120 deg
    np.testing.assert_allclose(M, rotvec_matrix(v), atol=1e-14)
    Mc = np.empty((3, 3))
    nb_shortest_rotation(*a, *b, Mc, np.empty(3))
    np.testing.assert_allclose(Mc, M, atol=1e-15)


@pytest.mark.parametrize("model", ["stewart-6sps", "dietmaier"])
def test_compiled_and_python_paths_agree(model):
    """Same statuses, iterations and results to 1e-10, from the reference and from perturbed
    seeds.  (Seeds from which Newton diverges are left out: there rounding decides the path, for
    the general engine too.)"""
    mech, lp, held = _stewart() if model == "stewart-6sps" else _dietmaier()
    rng = np.random.default_rng(4)
    target = generic_configuration(mech, seed=5, step=0.25)
    starts = [_seed(mech, lp, target, Configuration.reference(mech))]
    for size in (0.01, 0.1, 0.2):
        q = target.q + size * rng.standard_normal(len(target.q))
        starts.append(_seed(mech, lp, target, Configuration(q, exp_twist(size * rng.standard_normal(6), 1.0) @ target.D)))
    for start in starts:
        with pure():
            r0 = correct(mech, start, active=held, max_iter=30)
        r1 = correct(mech, start, active=held, max_iter=30)
        assert (r1.converged, r1.stationary, r1.iterations) == (r0.converged, r0.stationary, r0.iterations)
        np.testing.assert_allclose(r1.config.q, r0.config.q, atol=1e-10)
        np.testing.assert_allclose(r1.config.D, r0.config.D, atol=1e-10)
        assert abs(r1.residual - r0.residual) < 1e-10 or (r1.residual > 1 and np.isclose(r1.residual, r0.residual))


@pytest.mark.parametrize("use_pure", [False, True])
def test_unreachable_legs_fall_back_to_the_general_engine(use_pure):
    """Legs too long for any pose: the pose Newton fails; the result is the general engine's from
    the same seed, with both iteration counts added."""
    mech, lp, held = _stewart()
    start = Configuration.reference(mech)
    q = start.q.copy()
    q[lp.index[:, 1]] = [5.0, -0.5, 5.0, -0.5, 5.0, -0.5]
    start = start.with_q(q)
    with pure() if use_pure else nullcontext():
        auto = correct(mech, start, active=held, max_iter=20)
        joints = correct(mech, start, active=held, max_iter=20, method="joints")
    assert not auto.converged
    assert (auto.converged, auto.stationary, auto.residual) == (joints.converged, joints.stationary, joints.residual)
    np.testing.assert_array_equal(auto.config.q, joints.config.q)
    assert auto.iterations > joints.iterations


def test_a_closed_seed_is_returned_itself():
    mech, _, held = _stewart()
    target = generic_configuration(mech, seed=3, step=0.25)
    for use_pure in (False, True):
        with pure() if use_pure else nullcontext():
            res = correct(mech, target, active=held)
        assert res.converged and res.iterations == 0 and res.config is target


def test_bad_input_names_the_field_on_both_paths():
    mech, _, held = _stewart()
    bad = Configuration(np.full(len(mech.freedom_refs), np.nan), np.eye(4))
    with pytest.raises(InputError, match="NaN"):
        correct(mech, bad, active=held)
    with pure(), pytest.raises(InputError, match="NaN"):
        correct(mech, bad, active=held)
    with pytest.raises(InputError, match="method"):
        correct(mech, Configuration.reference(mech), active=held, method="pose")
    with pytest.raises(InputError, match=r"config\.q"):
        correct(mech, Configuration(np.zeros(3), np.eye(4)), active=held)


def test_the_closure_of_placed_legs_is_the_leg_length_mismatch():
    """place_legs closes every leg's rotation exactly; what is left of the closure residual is each
    leg's length mismatch, along the leg."""
    mech, lp, _ = _stewart()
    target = generic_configuration(mech, seed=8, step=0.25)
    D = exp_twist(np.r_[0.0, 0.0, 0.0, 0.0, 0.0, 1e-3], 1.0) @ target.D  # the platform 1 mm up
    q = leg_platform.place_legs(lp, target.q, D[:3, :3], D[:3, 3])
    r = closure_residual(mech, Configuration(q, D)).reshape(6, 6)
    np.testing.assert_allclose(r[:, :3], 0.0, atol=1e-14)
    p = lp.tip @ D[:3, :3].T + D[:3, 3] - lp.base
    w = lp.tip - lp.base + target.q[lp.index[:, 1]][:, None] * lp.direction
    mismatch = np.linalg.norm(p, axis=1) - np.linalg.norm(w, axis=1)
    assert np.abs(mismatch).max() > 1e-5
    np.testing.assert_allclose(np.linalg.norm(r[:, 3:], axis=1), np.abs(mismatch), rtol=1e-6, atol=1e-15)


def _random_platform(seed: int, skewed: bool):
    """Six S-P-S legs of a random platform; ``skewed``: each slide off the line of its balls."""
    from spatialmech.model.joints import P, S
    from spatialmech.model.mechanism import Limb, Mechanism

    rng = np.random.default_rng(seed)
    ang = np.arange(6) * np.pi / 3.0 + rng.uniform(-0.2, 0.2, 6)
    a = np.c_[np.cos(ang), np.sin(ang), rng.uniform(-0.1, 0.1, 6)]
    b = np.c_[0.5 * np.cos(ang + 0.5), 0.5 * np.sin(ang + 0.5), 1.0 + rng.uniform(-0.1, 0.1, 6)]
    limbs = []
    for i in range(6):
        e = _unit(b[i] - a[i])
        if skewed:
            e = _unit(e + 0.3 * rng.standard_normal(3))
        limbs.append(Limb(f"l{i}", (S(f"a{i}", a[i]), P(f"p{i}", a[i], e, actuated=True), S(f"b{i}", b[i]))))
    return Mechanism(f"random-{seed}", limbs=tuple(limbs), platform_point=np.zeros(3))


@pytest.mark.parametrize("seed,skewed", [(1, False), (2, True), (3, True)])
def test_a_users_platform_with_slides_off_the_leg_line_gets_the_same_pose(seed, skewed):
    """A platform built in a few lines of Python (the slides need not lie on the line of their
    balls): the pose path finds the general engine's pose, on both paths alike."""
    mech = _random_platform(seed, skewed)
    lp = leg_platform.leg_platform(mech)
    assert lp is not None
    held = active_mask(mech)
    held[lp.index[:, 1]] = False
    # near enough the reference that both Newtons, started there, reach the same assembly: with
    # step 0.2 one sample in twelve (seed 3 since issue 26's generic configurations) sends the
    # joint-space Newton to another one, 0.09 away (both closed: not a disagreement of the paths)
    target = generic_configuration(mech, seed=seed, step=0.15)
    start = _seed(mech, lp, target, Configuration.reference(mech))
    auto = correct(mech, start, active=held)
    joints = correct(mech, start, active=held, method="joints")
    with pure():
        ref = correct(mech, start, active=held)
    assert auto.converged and joints.converged and ref.converged
    np.testing.assert_allclose(auto.config.D, joints.config.D, atol=1e-11)
    np.testing.assert_allclose(auto.config.q, ref.config.q, atol=1e-10)
    assert auto.iterations == ref.iterations
    assert np.abs(closure_residual(mech, auto.config)).max() < 1e-12
