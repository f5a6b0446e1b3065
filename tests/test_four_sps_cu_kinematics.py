"""Paper B (4-SPS/CU): closed-form inverse position, Jacobians (eqs 9-13), forward position with
all assembly modes, the generic SPS kernel, and the benchmark (smoke test).

Tolerances are stated per test: closed forms agree to ~1e-15 m; finite differences (central,
h = 1e-6) to 1e-7 relative; Newton/LM roots to the solver tolerance 1e-12 m on the legs.
"""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from spatialmech import catalog
from spatialmech.errors import InputError
from spatialmech.geometry.rotations import euler_matrix, skew
from spatialmech.kinematics.closed_forms import four_sps_cu as k
from spatialmech.kinematics.closed_forms import four_sps_cu_forward as kf
from spatialmech.kinematics.closed_forms import sps
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.backend import correct
from spatialmech.model.mechanism import Pose

A, B = k.PAPER_B.a, k.PAPER_B.b
EXAMPLE = np.array([0.12, 0.2, -0.1, 0.6])  # (z, alpha, beta, gamma) of the multi-assembly claim


def random_phi(rng, n, ang=0.6, zlim=(0.08, 0.3), min_tilt=0.05):
    """Poses within the CU range, tilted away from the singular set alpha = beta = 0."""
    z = rng.uniform(*zlim, n)
    al, be = rng.uniform(-ang, ang, (2, n))
    al = np.where(np.abs(al) < min_tilt, np.copysign(min_tilt, al), al)
    be = np.where(np.abs(be) < min_tilt, np.copysign(min_tilt, be), be)
    return np.column_stack([z, al, be, rng.uniform(-1.5, 1.5, n)])


def direct_legs(phi):
    """``l_i = |T A_i + (0, 0, z) - B_i|`` straight from the definition (scipy rotation)."""
    R = euler_matrix("ZYX", phi[..., [3, 2, 1]])
    p = np.zeros((*phi.shape[:-1], 3))
    p[..., 2] = phi[..., 0]
    return sps.leg_lengths(R, p, k.PAPER_B.base_points, k.PAPER_B.platform_points)


# ------------------------------------------------------------------ inverse position (eq 8)
def test_reference_pose_legs_equal_catalog_offsets():
    """At the catalog reference (z0 = 0.2, no rotation) every leg is sqrt(0.06) m."""
    m = catalog.build("four-sps-cu")
    offsets = [r.freedom.offset for r in m.freedom_refs if r.id.endswith(".slide") and r.id.startswith("L")]
    assert np.allclose(k.leg_lengths([0.2, 0, 0, 0]), np.sqrt(0.06), atol=1e-15)
    assert np.allclose(k.leg_lengths([0.2, 0, 0, 0]), offsets, atol=1e-15)


def test_closed_form_matches_definition_on_stacks(rng):
    """The expanded closed form equals |T A_i + (0,0,z) - B_i| (tolerance 1e-15 m), for any
    leading shape and any angles (including beyond +-pi)."""
    phi = np.column_stack([rng.uniform(-0.4, 0.4, 600), rng.uniform(-7, 7, (600, 3))]).reshape(2, 3, 100, 4)
    legs = k.leg_lengths(phi)
    assert legs.shape == (2, 3, 100, 4)
    assert np.max(np.abs(legs - direct_legs(phi))) < 1e-15
    assert np.allclose(k.leg_lengths(phi, squared=True), legs**2, atol=1e-15)
    assert np.allclose(np.linalg.norm(k.leg_vectors(phi), axis=-1), legs, atol=1e-15)


def test_leg_lengths_cross_blocks_consistently(rng):
    """Arrays longer than the internal block give the same values as one pose at a time."""
    phi = random_phi(rng, 3 * k._CHUNK + 17)
    legs = k.leg_lengths(phi)
    idx = [0, k._CHUNK - 1, k._CHUNK, 2 * k._CHUNK + 5, phi.shape[0] - 1]
    for i in idx:
        assert np.array_equal(legs[i], k.leg_lengths(phi[i]))


@pytest.mark.parametrize("phi", [EXAMPLE, [0.25, -0.3, 0.2, -1.0], [0.09, 0.4, 0.35, 2.0], [0.2, 0.0, 0.0, 0.0]])
def test_closed_form_matches_general_closure_engine(phi):
    """Cross-check with the general engine: catalog model, platform held at the pose, Newton on
    the joint variables (inverse position); leg = offset + q, to 1e-10 m."""
    phi = np.asarray(phi, float)
    m = catalog.build("four-sps-cu")
    D = Pose.from_euler("ZYX", [phi[3], phi[2], phi[1]], [0, 0, phi[0]]).displacement(m.platform_point)
    q0 = np.zeros(len(m.freedom_refs))
    res = correct(m, Configuration(q0, D), fix_platform=True)
    assert res.converged
    ids = ("L1.slide", "L2.slide", "L3.slide", "L4.slide")
    legs = [r.freedom.offset + res.config.q[i] for i, r in enumerate(m.freedom_refs) if r.id in ids]
    assert np.allclose(legs, k.leg_lengths(phi), atol=1e-10)
    # the CU slide is z and the C rotation is gamma (the U then gives beta, alpha)
    cu = {r.id: r.freedom.offset + res.config.q[i] for i, r in enumerate(m.freedom_refs)}
    assert cu["C5.slide"] == pytest.approx(phi[0], abs=1e-10)


def printed_eq8(phi):
    """Eq 8 exactly as printed in seed 002 (section 4.1), transcribed term by term."""
    z, al, be, ga = np.moveaxis(np.asarray(phi, float), -1, 0)
    sa, ca, sb, cb, sg, cg = np.sin(al), np.cos(al), np.sin(be), np.cos(be), np.sin(ga), np.cos(ga)
    a, b = A, B
    l1 = (a*cg*cb - a*cg*sb*sa + a*sg*ca - b)**2 + (a*sg*cb - a*ca*cg - a*ca*sb*sg + b)**2 + (-a*sb - a*sa*cb + z)**2
    l2 = (a*cg*cb + a*cg*sb*sa - a*sg*ca - b)**2 + (a*sg*cb + a*ca*cg + a*sa*sb*sg - b)**2 + (-a*sb + a*sa*cb + z)**2
    l3 = (-a*cg*cb + a*cg*sb*sa - a*sg*ca + b)**2 + (-a*sg*cb + a*sa*sg + a*sa*sb*sg - b)**2 + (a*sb + a*sa*cb + z)**2
    l4 = (-a*cg*cb - a*cg*sb*sa + a*sg*ca + b)**2 + (-a*sg*cb - a*ca*cg - a*sa*sb*sg - b)**2 + (a*sb - a*sa*cb + z)**2
    return np.sqrt(np.stack([l1, l2, l3, l4], axis=-1))


def test_printed_eq8_is_wrong_for_legs_1_3_4(rng):
    """Paper eq 8 as printed disagrees with |T A_i + (0,0,z) - B_i| for legs 1, 3, 4 (leg 2 is
    right, to 1e-15 m).  Over the CU range z in [0.08, 0.3] m and angles within +-30 deg the
    largest error is 0.19 m (leg 4); legs 3 and 4 are already wrong at the home pose
    (0.055 m, 0.129 m)."""
    phi = np.column_stack([rng.uniform(0.08, 0.3, 200_000), rng.uniform(-np.pi / 6, np.pi / 6, (200_000, 3))])
    err = np.abs(printed_eq8(phi) - k.leg_lengths(phi)).max(axis=0)
    assert err[1] < 1e-15
    assert err[0] > 0.02 and err[2] > 0.09
    assert 0.18 < err[3] < 0.20
    home = np.abs(printed_eq8([0.2, 0, 0, 0]) - k.leg_lengths([0.2, 0, 0, 0]))
    assert home[:2] == pytest.approx([0, 0], abs=1e-15)
    assert home[2] == pytest.approx(0.0551, abs=1e-4) and home[3] == pytest.approx(0.1292, abs=1e-4)


def test_conventions_corrections_repair_eq8(rng):
    """With the three corrections of conventions.md (l1: ca sb sg -> sa sb sg; l3: a sa sg ->
    a ca cg; l4: -b -> +b in the Y term) the printed formula equals the model (1e-15 m)."""
    phi = random_phi(rng, 1000, ang=3.0)
    z, al, be, ga = phi.T
    sa, ca, sb, cb, sg, cg = np.sin(al), np.cos(al), np.sin(be), np.cos(be), np.sin(ga), np.cos(ga)
    a, b = A, B
    l1 = (a*cg*cb - a*cg*sb*sa + a*sg*ca - b)**2 + (a*sg*cb - a*ca*cg - a*sa*sb*sg + b)**2 + (-a*sb - a*sa*cb + z)**2
    l3 = (-a*cg*cb + a*cg*sb*sa - a*sg*ca + b)**2 + (-a*sg*cb + a*ca*cg + a*sa*sb*sg - b)**2 + (a*sb + a*sa*cb + z)**2
    l4 = (-a*cg*cb - a*cg*sb*sa + a*sg*ca + b)**2 + (-a*sg*cb - a*ca*cg - a*sa*sb*sg + b)**2 + (a*sb - a*sa*cb + z)**2
    legs = k.leg_lengths(phi)
    assert np.max(np.abs(np.sqrt(np.stack([l1, l3, l4], 1)) - legs[:, [0, 2, 3]])) < 1e-15


@settings(max_examples=40, deadline=None)
@given(st.floats(-0.4, 0.4), st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3))
def test_mirror_pose_has_the_same_legs(z, al, be, ga):
    """(z, R) and (-z, M R M), M = diag(1, 1, -1), i.e. (-z, -alpha, -beta, gamma), give the
    same leg lengths: every assembly mode has a mirror image below the base."""
    assert np.allclose(k.leg_lengths([z, al, be, ga]), k.leg_lengths([-z, -al, -be, ga]), atol=1e-15)


# ------------------------------------------------------------------ Jacobians (eqs 9-13)
def _fd(f, x, h=1e-6):
    cols = []
    for j in range(len(x)):
        e = np.zeros(len(x))
        e[j] = h
        cols.append((f(x + e) - f(x - e)) / (2 * h))
    return np.stack(cols, axis=-1)


def test_J_and_Jx_against_finite_differences(rng):
    """J = d(l^2/2)/d phi and Jx = dl/d phi (eq 9, L l' = J phi') match central differences
    (h = 1e-6, tolerance 1e-8 absolute on O(0.1) entries)."""
    for phi in random_phi(rng, 5):
        J, L = k.jacobians(phi)
        assert np.allclose(np.diag(L), k.leg_lengths(phi), atol=1e-15)
        assert np.allclose(J, _fd(lambda x: k.leg_lengths(x, squared=True) / 2, phi), atol=1e-9)
        assert np.allclose(k.jacobian_x(phi), _fd(k.leg_lengths, phi), atol=1e-8)
        assert np.allclose(np.linalg.solve(L, J), k.jacobian_x(phi), atol=1e-13)


def test_closed_form_J_equals_vector_form(rng):
    """Two derivations agree: differentiating the expanded l^2 and the screw form
    Jx = J_omega blockdiag(1, E) (leg lines against the twist)."""
    phi = random_phi(rng, 50)
    E = k.angular_velocity_matrix(phi)
    M = np.zeros((50, 4, 4))
    M[:, 0, 0] = 1
    M[:, 1:, 1:] = E
    assert np.allclose(k.twist_jacobian(phi) @ M, k.jacobian_x(phi), atol=1e-14)


def test_twist_jacobian_rows_are_leg_lines():
    """Angular-terms rows equal the generic SPS leg lines applied to the twist of the
    platform's four freedoms: l' = line . DELTA (omega ; v_O) with v_O = z' e_z - omega x p."""
    phi = np.array([0.17, 0.3, -0.2, 0.8])
    T = k.pose_transform(phi)
    lines = sps.leg_lines(T[:3, :3], T[:3, 3], k.PAPER_B.base_points, k.PAPER_B.platform_points)
    rng = np.random.default_rng(3)
    for _ in range(3):
        zd, om = rng.standard_normal(), rng.standard_normal(3)
        v0 = zd * np.array([0, 0, 1.0]) - np.cross(om, T[:3, 3])
        ld = sps.leg_rates(T[:3, :3], T[:3, 3], k.PAPER_B.base_points, k.PAPER_B.platform_points, np.r_[om, v0])
        assert np.allclose(ld, k.twist_jacobian(phi) @ np.r_[zd, om], atol=1e-14)
        assert np.allclose(ld, lines[:, :3] @ v0 + lines[:, 3:] @ om, atol=1e-14)


def test_jacobian_x_rate_against_finite_differences(rng):
    """Jx' along phi' equals (Jx(phi + h phi') - Jx(phi - h phi')) / 2h (h = 1e-6, 1e-7 abs)."""
    for phi in random_phi(rng, 4):
        phid = rng.standard_normal(4) * [0.05, 1, 1, 1]
        h = 1e-6
        fd = (k.jacobian_x(phi + h * phid) - k.jacobian_x(phi - h * phid)) / (2 * h)
        assert np.allclose(k.jacobian_x_rate(phi, phid), fd, atol=1e-7)


@pytest.mark.parametrize("terms", ["euler", "angular"])
def test_inverse_acceleration_against_trajectory(terms, rng):
    """l'' from eq 13 (corrected) equals the second difference of l along
    phi(t) = phi0 + phi' t + phi'' t^2 / 2 (h = 1e-4, tolerance 1e-6 m/s^2); in angular terms
    the rates and accelerations are converted with E and E'."""
    for phi in random_phi(rng, 3):
        phid = rng.standard_normal(4) * [0.05, 1, 1, 1]
        phidd = rng.standard_normal(4) * [0.05, 1, 1, 1]
        h = 1e-4

        def traj(t, phi=phi, phid=phid, phidd=phidd):
            return k.leg_lengths(phi + phid * t + phidd * t * t / 2)

        l_dd = (traj(h) - 2 * traj(0) + traj(-h)) / h**2
        l_d = (traj(h) - traj(-h)) / (2 * h)
        if terms == "euler":
            rates, acc = phid, phidd
        else:
            rates = np.r_[phid[0], k.angular_velocity(phi, phid)]
            acc = np.r_[phidd[0], k.angular_acceleration(phi, phid, phidd)]
        assert np.allclose(k.inverse_velocity(phi, rates, terms=terms), l_d, atol=1e-8)
        assert np.allclose(k.inverse_acceleration(phi, rates, acc, terms=terms), l_dd, atol=1e-6)


@pytest.mark.parametrize("terms", ["euler", "angular"])
def test_forward_velocity_and_acceleration_invert_the_inverse(terms, rng):
    """phi' = J^-1 L l' (eq 10) and phi'' = Jx^-1 (l'' - Jx' phi') (eq 12), corrected, invert
    the inverse relations on random poses (vectorised over 20 poses, 1e-9 relative)."""
    phi = random_phi(rng, 20)
    rates = rng.standard_normal((20, 4))
    acc = rng.standard_normal((20, 4))
    ld = k.inverse_velocity(phi, rates, terms=terms)
    ldd = k.inverse_acceleration(phi, rates, acc, terms=terms)
    assert np.allclose(k.forward_velocity(phi, ld, terms=terms), rates, rtol=1e-9, atol=1e-9)
    assert np.allclose(k.forward_acceleration(phi, ld, ldd, terms=terms), acc, rtol=1e-9, atol=1e-8)


def test_angular_velocity_against_rotation_derivative(rng):
    """[omega]x = R' R^T (base frame) for omega = E (alpha', beta', gamma'); omega' matches a
    finite difference of omega(t); euler_rates / euler_accelerations invert them."""
    for phi in random_phi(rng, 4):
        phid = rng.standard_normal(4)
        phidd = rng.standard_normal(4)
        h = 1e-6
        Rd = (k.rotation(phi + h * phid) - k.rotation(phi - h * phid)) / (2 * h)
        om = k.angular_velocity(phi, phid)
        assert np.allclose(Rd @ k.rotation(phi).T, skew(om), atol=1e-8)

        def w(t, phi=phi, phid=phid, phidd=phidd):
            return k.angular_velocity(phi + phid * t + phidd * t * t / 2, phid + phidd * t)

        assert np.allclose(k.angular_acceleration(phi, phid, phidd), (w(h) - w(-h)) / (2 * h), atol=1e-7)
        assert np.allclose(k.euler_rates(phi, om), phid[1:], atol=1e-12)
        omd = k.angular_acceleration(phi, phid, phidd)
        assert np.allclose(k.euler_accelerations(phi, phid, omd), phidd[1:], atol=1e-11)


def test_euler_rates_undefined_at_gimbal_lock():
    with pytest.raises(ValueError, match=r"^phi: cos\(beta\) = 0"):
        k.euler_rates([0.2, 0.1, np.pi / 2, 0.3], [0, 0, 1])


# ------------------------------------------------------------------ singularities
@settings(max_examples=25, deadline=None)
@given(st.floats(0.08, 0.3), st.floats(-2.5, 2.5))
def test_every_pose_with_alpha_beta_zero_is_singular(z, gamma):
    """NOT reproduced (paper: no singularity for well-chosen parameters): at alpha = beta = 0
    the z and gamma columns of J are parallel (rank <= 3; the four legs meet on the Z axis)."""
    J, _ = k.jacobians([z, 0.0, 0.0, gamma])
    sv = np.linalg.svd(J * [1, 1 / B, 1 / B, 1 / B], compute_uv=False)
    assert sv[-1] < 1e-12 * sv[0]


def test_self_motion_with_legs_locked():
    """With the legs locked at l (all equal at alpha = beta = 0) the platform still moves:
    z^2 = l^2 - 2a^2 - 2b^2 + 4ab cos(gamma) keeps every leg length (to 1e-15 m)."""
    l = np.sqrt(0.06)
    gam = np.linspace(-1.0, 1.0, 9)
    z = np.sqrt(l**2 - 2 * A**2 - 2 * B**2 + 4 * A * B * np.cos(gam))
    legs = k.leg_lengths(np.column_stack([z, 0 * z, 0 * z, gam]))
    assert np.allclose(legs, l, atol=1e-15)
    assert np.ptp(z) > 0.01  # a finite motion, not an infinitesimal one
    with pytest.raises(ValueError, match=r"^phi: singular pose"):
        k.forward_velocity([0.2, 0, 0, 0.3], [0.01, 0, 0, 0])


# ------------------------------------------------------------------ forward position
@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_forward_round_trip(seed):
    """Inverse then forward from a seed 0.002 rad / 0.0004 m away recovers the pose (to 1e-8)
    with the legs matched to the 1e-12 m tolerance, on well-conditioned poses (nondimensional
    sigma_min >= 0.01, 84 % of the sampled poses).  Measured on 50,506 such poses: 0 failures,
    largest pose error 6e-10.  Closer to a fold two modes come close together (next test)."""
    rng = np.random.default_rng(seed)
    phi = random_phi(rng, 1, min_tilt=0.1)[0]
    assume(kf._sigma_min(phi, k.PAPER_B) >= 0.01)
    res = kf.forward(k.leg_lengths(phi), phi + rng.uniform(-1, 1, 4) * [0.0004, 0.002, 0.002, 0.002])
    assert res.converged and res.status == "converged"
    assert res.residual <= 1e-12
    assert np.allclose(k.leg_lengths(res.phi), k.leg_lengths(phi), atol=1e-12)
    assert np.allclose(res.phi, phi, atol=1e-8)


def test_near_a_fold_a_close_seed_can_reach_the_neighbouring_mode():
    """Trap: the legs of (0.1401, 0.2047, -0.3974, -0.5903) (sigma_min 0.0021) have a second
    mode 0.045 rad away, (0.1327, 0.2186, -0.4210, -0.6357); from a seed 0.04 rad from the
    first, LM converges to the second.  Both are genuine modes (forward_all lists both): the
    solver is right, the round trip is ambiguous near a fold of the forward map."""
    phi = np.array([0.14011099, 0.20465682, -0.39739529, -0.5902849])
    seed = np.array([0.13559393, 0.19638262, -0.35724253, -0.62523112])
    l = k.leg_lengths(phi)
    res = kf.forward(l, seed)
    assert res.converged and np.allclose(k.leg_lengths(res.phi), l, atol=1e-12)
    assert np.allclose(res.phi, [0.13267437, 0.21857122, -0.42104119, -0.63566447], atol=1e-7)
    modes = kf.forward_all(l)
    assert len(modes.solutions) == 4 and modes.n_within_limits == 2
    assert _same_modes(modes.phis[:2], np.array([phi, res.phi]))


def test_forward_from_the_default_seed_finds_a_mode_of_the_example():
    res = kf.forward(k.leg_lengths(EXAMPLE))
    assert res.converged and res.within_limits
    assert np.allclose(k.leg_lengths(res.phi), k.leg_lengths(EXAMPLE), atol=1e-12)
    json.dumps(res.to_dict())


def test_forward_reports_non_convergence_for_impossible_legs():
    """Legs of 0.05 m cannot reach (min |B_i - A_i| = b sqrt2 - a sqrt2 = 0.141 m): the solver
    says so (status and residual), never a silent answer; forward_all returns no solution."""
    res = kf.forward([0.05] * 4)
    assert not res.converged and res.status in ("max_iter", "stalled")
    assert res.residual > 0.05
    allres = kf.forward_all([0.05] * 4, n_seeds=32, max_iter=50)
    assert allres.solutions == () and allres.search.n_converged == 0


def test_forward_batch_matches_single_solves(rng):
    phi = random_phi(rng, 30, min_tilt=0.1)
    seeds = phi + 0.03
    batch = kf.forward_batch(k.leg_lengths(phi), seeds)
    assert batch.converged.all() and np.all(batch.residual <= 1e-12)
    assert np.allclose(batch.phi, phi, atol=1e-8)
    one = kf.forward(k.leg_lengths(phi[7]), seeds[7])
    assert np.allclose(one.phi, batch.phi[7], atol=1e-12)
    json.dumps(batch.to_dict())


def _branch(z, l, sign):
    """Independent reduction to one unknown: the four leg equations are linear in
    U = -sin(beta), V = cos(beta) sin(alpha), P = R00 + R11, Q = R10 + R01 for given z; beta from U
    (cos(beta) >= 0), alpha from V with cos(alpha) = sign |..|, (cos(gamma), sin(gamma)) from a
    2x2 linear system; g(z) = cos^2 + sin^2 - 1 vanishes at the roots."""
    l2 = l * l
    C = 2 * A * A + 2 * B * B + z * z
    umv, upv = (l2[0] - l2[2]) / (4 * A * z), (l2[1] - l2[3]) / (4 * A * z)
    pmq, ppq = (2 * C - l2[0] - l2[2]) / (4 * A * B), (2 * C - l2[1] - l2[3]) / (4 * A * B)
    U, V, P, Q = (umv + upv) / 2, (upv - umv) / 2, (pmq + ppq) / 2, (ppq - pmq) / 2
    with np.errstate(invalid="ignore", divide="ignore"):
        sb, cb = -U, np.sqrt(1 - U * U)
        sa = V / cb
        ca = sign * np.sqrt(1 - sa * sa)
        m11, m12, m22 = cb + ca, sa * sb, cb - ca
        det = m11 * m22 - m12 * m12
        cg, sg = (P * m22 - m12 * Q) / det, (m11 * Q - m12 * P) / det
        g = cg * cg + sg * sg - 1
    return g, np.stack([z, np.arctan2(sa, ca), np.arctan2(sb, cb), np.arctan2(sg, cg)], axis=-1)


def univariate_roots(l, n=20001):
    zmax = l.max() + np.sqrt(2) * A
    out = []
    for zs in (np.linspace(1e-6, zmax, n), np.linspace(-zmax, -1e-6, n)):
        for sign in (1.0, -1.0):
            g, _ = _branch(zs, l, sign)
            ok = np.isfinite(g)
            for i in np.flatnonzero(ok[:-1] & ok[1:] & (np.sign(g[:-1]) != np.sign(g[1:]))):
                z = brentq(lambda t, sign=sign: _branch(t, l, sign)[0], zs[i], zs[i + 1], xtol=1e-15)
                phi = _branch(np.array(z), l, sign)[1]
                if np.abs(k.leg_lengths(phi) - l).max() < 1e-9:  # a root, not a pole
                    out.append(phi)
    return np.array(out).reshape(-1, 4)


def _same_modes(P1, P2, tol=1e-6):
    def key(P):
        return np.concatenate([P[:, :1] / B, k.rotation(P).reshape(-1, 9)], axis=1)
    K1, K2 = key(P1), key(P2)
    return len(K1) == len(K2) and all(np.min(np.abs(K2 - r).max(axis=1)) < tol for r in K1)


def test_multiple_assembly_modes_claim():
    """Claim (kinematics issue): the legs of (z, alpha, beta, gamma) = (0.12, 0.2, -0.1, 0.6)
    have at least 4 real assembly modes, 2 within the joint limits.  Reproduces, exactly:
    4 modes, the pose itself, (0.148563, 0.160886, -0.080727, 0.414450), and their mirror images
    (-z, -alpha, -beta, gamma) below the base; the two with z > 0 are within the leg and CU
    limits (joint-angle limits of eqs 18-21 not checked).  The independent one-unknown
    reduction finds the same 4 roots, and more seeds find nothing new."""
    l = k.leg_lengths(EXAMPLE)
    res = kf.forward_all(l)
    assert len(res.solutions) == 4 and res.n_within_limits == 2
    assert all(s.converged and s.residual <= 1e-12 for s in res.solutions)
    inside = res.phis[:2]
    assert np.allclose(inside[np.argmin(np.abs(inside[:, 0] - 0.12))], EXAMPLE, atol=1e-9)
    other = inside[np.argmax(np.abs(inside[:, 0] - 0.12))]
    assert np.allclose(other, [0.148563, 0.160886, -0.080727, 0.414450], atol=1e-6)
    assert np.all(res.phis[2:, 0] < 0)
    assert _same_modes(res.phis[2:], res.phis[:2] * [-1, -1, -1, 1])
    assert _same_modes(res.phis, univariate_roots(l))
    assert _same_modes(kf.forward_all(l, n_seeds=2048, qmc_seed=7).phis, res.phis)
    d = res.to_dict()
    json.dumps(d)
    assert d["search"]["n_seeds"] == 512 and sum(d["search"]["hits"]) == d["search"]["n_converged"]


def test_forward_all_agrees_with_the_univariate_reduction(rng):
    """On random poses the multi-seed search finds exactly the roots of the one-unknown
    reduction (4 or 8 real modes occur)."""
    counts = []
    for phi in random_phi(rng, 5, min_tilt=0.1):
        l = k.leg_lengths(phi)
        found = kf.forward_all(l, n_seeds=256).phis
        assert _same_modes(found, univariate_roots(l))
        counts.append(len(found))
    assert set(counts) <= {4, 8}


def test_eight_modes_near_the_singular_set():
    """Legs of (0.256, 0.0085, 0.0077, -0.791), close to alpha = beta = 0: 8 real modes,
    including upside-down platforms (alpha ~ pi); roots this close to the singular set converge
    slowly, which is why forward_all's default max_iter is 500."""
    l = k.leg_lengths([0.2559735, 0.00848177, 0.007662, -0.79141761])
    res = kf.forward_all(l, n_seeds=256)
    assert len(res.solutions) == 8
    assert _same_modes(res.phis, univariate_roots(l))
    assert np.sum(np.abs(np.abs(res.phis[:, 1]) - np.pi) < 0.1) == 4


# ------------------------------------------------------------------ generic SPS kernel
def test_generic_sps_against_closure_engine_on_stewart(rng):
    """sps.leg_lengths on the Gough-Stewart model equals the engine's inverse position (1e-10 m)."""
    m = catalog.build("stewart-6sps")
    refs = m.freedom_refs
    slides = [i for i, r in enumerate(refs) if r.id.endswith(".slide")]
    base = np.array([refs[i].freedom.point for i in slides])
    plat = np.array([lj.joints[-1].point for lj in m.limbs]) - m.platform_point
    for _ in range(2):
        R = euler_matrix("ZYX", rng.uniform(-0.2, 0.2, 3))
        p = m.platform_point + rng.uniform(-0.1, 0.1, 3)
        D = Pose(R, p).displacement(m.platform_point)
        res = correct(m, Configuration(np.zeros(len(refs)), D), fix_platform=True)
        assert res.converged
        legs = [refs[i].freedom.offset + res.config.q[i] for i in slides]
        assert np.allclose(sps.leg_lengths(R, p, base, plat), legs, atol=1e-10)


def test_generic_sps_leg_rates_against_finite_differences(rng):
    """l' = reciprocal product of the leg lines with the platform twist (screw convention,
    v = velocity of the point at the origin), against d/dt |exp([V] t) (R a + p) - b|."""
    from spatialmech.geometry.rotations import exp_twist

    base = rng.uniform(-1, 1, (6, 3))
    plat = rng.uniform(-0.5, 0.5, (6, 3))
    R, p = euler_matrix("ZYX", rng.uniform(-1, 1, 3)), rng.uniform(-1, 1, 3) + np.array([0, 0, 2])
    V = rng.standard_normal(6)
    h = 1e-6

    def legs(t):
        T = exp_twist(V, t) @ np.block([[R, p[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]])
        return sps.leg_lengths(T[:3, :3], T[:3, 3], base, plat)

    assert np.allclose(sps.leg_rates(R, p, base, plat, V), (legs(h) - legs(-h)) / (2 * h), atol=1e-8)
    lines = sps.leg_lines(R, p, base, plat)
    assert np.allclose(np.linalg.norm(lines[:, :3], axis=1), 1)
    assert np.allclose(np.sum(lines[:, :3] * lines[:, 3:], axis=1), 0, atol=1e-14)


def test_generic_sps_stacks_broadcast(rng):
    base = rng.uniform(-1, 1, (3, 3))
    plat = rng.uniform(-1, 1, (3, 3))
    R = euler_matrix("zyx", rng.uniform(-1, 1, (5, 3)))
    p = rng.uniform(-1, 1, (2, 1, 3))
    out = sps.leg_lengths(R, p, base, plat)
    assert out.shape == (2, 5, 3)
    assert np.allclose(out[1, 3], np.linalg.norm(R[3] @ plat.T + p[1, 0, :, None] - base.T, axis=0))


# ------------------------------------------------------------------ input errors
@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: k.leg_lengths([0.2, np.nan, 0, 0]), "^phi: contains NaN"),
        (lambda: k.leg_lengths([0.2, 0, 0]), "^phi: expected shape"),
        (lambda: kf.forward([0.2, 0.2, -0.1, 0.2]), "^l: leg lengths must be positive"),
        (lambda: kf.forward([0.2] * 3), "^l: expected shape"),
        (lambda: kf.forward([0.2] * 4, [0.2, 0, 0]), "^seed: expected shape"),
        (lambda: kf.forward([0.2] * 4, tol=0), "^tol:"),
        (lambda: kf.forward_all([0.2] * 4, n_seeds=0), "^n_seeds:"),
        (lambda: kf.forward_batch([0.2] * 4, np.zeros((3, 5))), "^seeds: expected shape"),
        (lambda: k.inverse_velocity(EXAMPLE, [0, 0, 0, 1], terms="deg"), "^terms:"),
        (lambda: k.inverse_velocity(EXAMPLE, [0, 0, 1]), "^rates: expected shape"),
        (lambda: k.FourSpsCuGeometry(a=-0.1), "^a: must be positive"),
        (lambda: k.FourSpsCuGeometry(leg_limits=(0.4, 0.1)), "^leg_limits:"),
        (lambda: sps.leg_lengths(np.eye(3), [0, 0, 1], [[0, 0, 0]], [[0, 0, 0], [1, 0, 0]]), "^platform_points:"),
        (lambda: sps.leg_lengths(np.eye(3), [0, 0], [[0, 0, 0]], [[0, 0, 0]]), "^p: expected shape"),
        (lambda: sps.leg_lines(np.eye(3), [0, 0, 0], [[0, 0, 0]], [[0, 0, 0]]), "zero length"),
    ],
)
def test_bad_input_raises_value_error_naming_the_field(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_other_geometry_is_used(rng):
    g = k.FourSpsCuGeometry(a=0.15, b=0.25)
    phi = random_phi(rng, 10)
    T = k.pose_transform(phi)
    ref = sps.leg_lengths(T[..., :3, :3], T[..., :3, 3], g.base_points, g.platform_points)
    assert np.allclose(k.leg_lengths(phi, g), ref, atol=1e-15)
    res = kf.forward(k.leg_lengths(phi[0], g), phi[0] + 0.02, geometry=g)
    assert res.converged and np.allclose(res.phi, phi[0], atol=1e-8)
    assert g.to_dict()["a_len"] == 0.15


# ------------------------------------------------------------------ benchmark smoke test
def test_benchmark_runs_with_a_tiny_size():
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_four_sps_cu.py"
    spec = importlib.util.spec_from_file_location("bench_four_sps_cu", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    res = mod.run(n=2000, loop_n=200, fk_n=3, repeat=1)
    json.dumps(res)
    assert res["inverse"]["max_abs_diff_m"] < 1e-14
    assert res["inverse"]["vectorised_poses_per_s"] > 0 and res["inverse"]["loop_poses_per_s"] > 0
    assert res["forward"]["batched_converged"] == 3


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_batched_legs_count_nan_and_infinity_in_the_kernel_and_name_phi(bad):
    """The compiled legs kernels count the poses that hold a NaN or an infinity themselves (no
    separate pass over the input); one such pose anywhere in a batch large enough for the
    parallel kernel still raises the named error, and the clean part gives the same legs."""
    n = k.PARALLEL_FROM + 3
    phi = np.tile([0.2, 0.1, -0.2, 0.3], (n, 1))
    good = k.leg_lengths(phi)
    assert np.allclose(good, good[0]) and np.all(np.isfinite(good))
    phi[n - 2, 1 + n % 3] = bad
    with pytest.raises(InputError, match="phi"):
        k.leg_lengths(phi)
    assert np.array_equal(k.leg_lengths(phi[: n - 2]), good[: n - 2])
