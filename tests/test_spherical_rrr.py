"""Paper C (seed 003) closed forms of the 3-RRR metamorphic spherical joint, configuration 3.

Eq 21 (inverse position) is checked against the general closure engine (``closure.correct``
with the platform held, continued from the home pose so that the branch is the continuous
one); eq 22 and the angular-velocity Jacobian against finite differences; the forward
solver against eq 21 (round trips) and against the general engine's forward position.
"""

import json

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar
from scipy.spatial.transform import Rotation

from spatialmech import catalog
from spatialmech.geometry.rotations import skew, transform
from spatialmech.kinematics.closed_forms import spherical_rrr as srrr
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.backend import closure_residual, correct

ACTUATORS = [0, 3, 6]  # R1.rot, R4.rot, R7.rot in the freedom order of three-rrr-sm
angle = st.floats(-3.0, 3.0, allow_nan=False)
tilt = st.floats(-1.5, 1.5, allow_nan=False)  # alpha inside scipy's YXZ range


def _wrap(x):
    return np.angle(np.exp(1j * np.asarray(x)))


@pytest.fixture(scope="module")
def mech():
    m = catalog.build("three-rrr-sm").in_mode("R1+R4+R7")
    assert [m.freedom_refs[i].id for i in ACTUATORS] == ["R1.rot", "R4.rot", "R7.rot"]
    return m


def _general_inverse_along(mech, Rs):
    """The general numerical inverse continued along orientations ``Rs`` from home."""
    q = np.zeros(len(mech.freedom_refs))
    out = []
    for R in Rs:
        res = correct(mech, Configuration(q, transform(R, np.zeros(3))), fix_platform=True)
        assert res.converged, res
        q = res.config.q
        out.append(q[ACTUATORS].copy())
    return np.array(out)


def section_42_angles(t_deg):
    """Section 4.2: alpha = beta = gamma = (pi/6) sin(pi t / 180), t in degrees."""
    return np.pi / 6 * np.sin(np.pi * np.asarray(t_deg, float) / 180.0)


# ---------------------------------------------------------------- eq 21
def test_home_pose_gives_zero_actuator_angles():
    assert np.array_equal(srrr.actuator_angles(0.0, 0.0, 0.0), np.zeros(3))
    assert np.allclose(srrr.actuator_angles_from_matrix(np.eye(3)), 0.0, atol=0)


def test_eq21_matches_general_inverse_on_random_orientations(mech):
    """Eq 21 (atan2, home branch) = the closure engine's inverse continued from home, on 12
    random orientations up to 2.8 rad per angle (tolerance 1e-9 rad).  Several of them have
    cos(alpha) cos(gamma) < 0, where the printed arctan would be off by pi."""
    rng = np.random.default_rng(21)
    targets = rng.uniform([-1.4, -2.8, -2.8], [1.4, 2.8, 2.8], size=(12, 3))
    flipped = 0
    for a, b, g in targets:
        s = np.linspace(0.0, 1.0, 15)
        Rs = srrr.orientation(a * s, b * s, g * s)
        assert np.min(srrr.limb_conditioning(Rs)) > 0.05  # the path stays clear of limb singularities
        theta_general = _general_inverse_along(mech, Rs)[-1]
        theta_closed = srrr.actuator_angles(a, b, g)
        assert np.allclose(_wrap(theta_general - theta_closed), 0.0, atol=1e-9), (a, b, g)
        flipped += np.cos(a) * np.cos(g) < 0
    assert flipped >= 3


def test_printed_arctan_of_eq21_takes_the_other_assembly_where_cos_alpha_cos_gamma_negative(mech):
    """The paper's arctan equals atan2 mod pi, so where cos(alpha) cos(gamma) < 0 it returns the
    theta + pi assembly of limb 2: limb 2 still closes there (both roots are assemblies) but
    the engine continued from home does not reach it."""
    a, b, g = 0.4, 0.3, 2.5  # cos(a) cos(g) < 0
    th = srrr.actuator_angles(a, b, g)
    sa, ca, sb, cb, sg, cg = np.sin(a), np.cos(a), np.sin(b), np.cos(b), np.sin(g), np.cos(g)
    printed = np.arctan((sb * sg + sa * cb * cg) / (ca * cg))
    assert abs(abs(_wrap(printed - th[1])) - np.pi) < 1e-12
    s = np.linspace(0, 1, 20)
    general = _general_inverse_along(mech, srrr.orientation(a * s, b * s, g * s))[-1]
    assert abs(_wrap(general[1] - th[1])) < 1e-9
    assert abs(abs(_wrap(general[1] - printed)) - np.pi) < 1e-9


def test_eq21_matches_general_inverse_along_the_section_42_path(mech):
    """The full section 4.2 motion t = 0..360 deg (5 deg steps): eq 21 with unwrap=True equals
    the engine continued along the path to 1e-9 rad at every step."""
    t = np.arange(0.0, 361.0, 5.0)
    x = section_42_angles(t)
    theta_closed = srrr.actuator_angles(x, x, x, unwrap=True)
    theta_general = _general_inverse_along(mech, srrr.orientation(x, x, x))
    assert np.allclose(theta_general, theta_closed, atol=1e-9)


def test_section_42_extremes_of_the_actuator_angles():
    """Paper C section 4.2 (fig 3a): theta1 spans +-30 deg, theta2 +39.81 / -11.94 deg, theta3
    +26.33 / -34.72 deg.  Extremes located by a bounded scalar search around the best of a
    1-deg grid; tolerance 0.01 deg.  (Measured: 30.000/-30.000, 39.806/-11.936 at t = 90 and
    226.63 deg, 26.330/-34.715.)"""
    expected = {0: (30.0, -30.0), 1: (39.81, -11.94), 2: (26.33, -34.72)}

    def theta_deg(t, k):
        x = section_42_angles(t)
        return float(np.degrees(srrr.actuator_angles(x, x, x)[k]))

    grid = np.arange(0.0, 361.0, 1.0)
    for k, (hi, lo) in expected.items():
        vals = np.array([theta_deg(t, k) for t in grid])
        for sign, target, t0 in ((-1, hi, grid[np.argmax(vals)]), (1, lo, grid[np.argmin(vals)])):
            r = minimize_scalar(lambda t, sign=sign, k=k: sign * theta_deg(t, k), bounds=(t0 - 2, t0 + 2), method="bounded",
                                options={"xatol": 1e-8})
            assert abs(theta_deg(r.x, k) - target) < 0.01, (k, theta_deg(r.x, k), target)


@settings(max_examples=60, deadline=None)
@given(tilt, angle, angle)
def test_matrix_form_equals_euler_form(a, b, g):
    """Eq 21 in Euler form and the axis form on R agree mod 2 pi (theta1 = beta unwrapped)."""
    R = srrr.orientation(a, b, g)
    assume(np.min(srrr.limb_conditioning(R)) >= 1e-6)
    assert np.allclose(_wrap(srrr.actuator_angles(a, b, g) - srrr.actuator_angles_from_matrix(R)), 0, atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(angle, angle, angle)
def test_eq21_closes_every_limb(a, b, g):
    """Invariant: with theta from eq 21 each limb's middle axis is perpendicular to its platform
    axis (the limb closes), for any Euler angles (also |alpha| > pi/2)."""
    R = srrr.orientation(a, b, g)
    f, _ = srrr._forward_terms(R, srrr.actuator_angles(a, b, g))
    assert np.allclose(f, 0.0, atol=1e-12)


def test_vectorised_over_grids():
    a = np.linspace(-1, 1, 5)[:, None, None]
    b = np.linspace(-1, 1, 4)[None, :, None]
    g = np.linspace(-2, 2, 3)[None, None, :]
    th = srrr.actuator_angles(a, b, g)
    assert th.shape == (5, 4, 3, 3)
    assert np.allclose(th[2, 1, 0], srrr.actuator_angles(a[2, 0, 0], b[0, 1, 0], g[0, 0, 0]))
    assert srrr.euler_rate_jacobian(a, b, g).shape == (5, 4, 3, 3, 3)
    assert srrr.actuator_angles_from_matrix(srrr.orientation(a, b, g)).shape == (5, 4, 3, 3)


# ---------------------------------------------------------------- eq 22 and angular velocity
@settings(max_examples=40, deadline=None)
@given(tilt, angle, angle)
def test_eq22_euler_rate_jacobian_matches_finite_differences(a, b, g):
    """thetadot = J (alphadot, betadot, gammadot): central differences of eq 21, h = 1e-6,
    tolerance 1e-6 (relative to max(1, |J|))."""
    R = srrr.orientation(a, b, g)
    assume(np.min(srrr.limb_conditioning(R)) >= 0.05)
    J = srrr.euler_rate_jacobian(a, b, g)
    h = 1e-6
    x = np.array([a, b, g])
    fd = np.empty((3, 3))
    for j in range(3):
        d = np.zeros(3)
        d[j] = h
        fd[:, j] = _wrap(srrr.actuator_angles(*(x + d)) - srrr.actuator_angles(*(x - d))) / (2 * h)
    assert np.allclose(J, fd, atol=1e-6 * max(1.0, np.abs(J).max()))


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_angular_velocity_jacobian_matches_finite_differences(seed):
    """thetadot = J_omega omega with omega in the fixed frame: R(h) = exp(h [omega]) R."""
    R = Rotation.random(random_state=seed).as_matrix()
    assume(np.min(srrr.limb_conditioning(R)) >= 0.05)
    J = srrr.angular_velocity_jacobian(R)
    h = 1e-6
    fd = np.empty((3, 3))
    for j in range(3):
        w = np.zeros(3)
        w[j] = h
        Rp = Rotation.from_rotvec(w).as_matrix() @ R
        Rm = Rotation.from_rotvec(-w).as_matrix() @ R
        fd[:, j] = _wrap(srrr.actuator_angles_from_matrix(Rp) - srrr.actuator_angles_from_matrix(Rm)) / (2 * h)
    assert np.allclose(J, fd, atol=1e-6 * max(1.0, np.abs(J).max()))


@settings(max_examples=30, deadline=None)
@given(tilt, angle, angle)
def test_euler_rate_matrix_gives_the_fixed_frame_angular_velocity(a, b, g):
    """omega = E Qdot: [omega]x = Rdot R^T, Rdot by central differences (h = 1e-6, tol 1e-7)."""
    E = srrr.euler_rate_matrix(a, b, g)
    h = 1e-6
    R = srrr.orientation(a, b, g)
    x = np.array([a, b, g])
    for j in range(3):
        d = np.zeros(3)
        d[j] = h
        Rdot = (srrr.orientation(*(x + d)) - srrr.orientation(*(x - d))) / (2 * h)
        assert np.allclose(Rdot @ R.T, skew(E[:, j]), atol=1e-7)


def test_jacobians_at_home_are_the_axis_permutation():
    """At home R1, R4, R7 are the y, x, z axes: thetadot = (omega_y, omega_x, omega_z), and
    the Euler rates there are (alphadot, betadot, gammadot) = (omega_x, omega_y, omega_z)."""
    P = np.array([[0, 1, 0], [1, 0, 0], [0, 0, 1.0]])
    assert np.allclose(srrr.angular_velocity_jacobian(np.eye(3)), P, atol=1e-15)
    assert np.allclose(srrr.euler_rate_jacobian(0, 0, 0), P, atol=1e-15)


def test_euler_rates_are_not_angular_velocity_away_from_home():
    """Eq 22 maps Euler-angle rates: at the t = 90 deg pose of section 4.2 it differs from the
    angular-velocity Jacobian by the factor E (which is not the identity there)."""
    x = np.pi / 6
    J = srrr.euler_rate_jacobian(x, x, x)
    Jw = srrr.angular_velocity_jacobian(srrr.orientation(x, x, x))
    assert np.allclose(J, Jw @ srrr.euler_rate_matrix(x, x, x), atol=1e-12)
    assert np.abs(J - Jw).max() > 0.1


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_forward_velocity_inverts_the_angular_velocity_jacobian(seed):
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=seed).as_matrix()
    J = srrr.angular_velocity_jacobian(R)
    assume(np.min(srrr.limb_conditioning(R)) >= 0.05 and abs(np.linalg.det(J)) >= 1e-3)
    w = rng.standard_normal(3)
    assert np.allclose(srrr.platform_angular_velocity(R, J @ w), w, atol=1e-8 * max(1, np.abs(J).max()))


def test_limb_singularity_is_reported():
    """Limb 1 is singular when its platform axis R z lies along its actuator axis y
    (alpha = -90 deg): the conditioning is 0, the J_omega row is NaN, and eq 22's row 1 stays
    (0, 1, 0) because eq 21 sets theta1 = beta."""
    R = srrr.orientation(-np.pi / 2, 0.3, 0.2)
    c = srrr.limb_conditioning(R)
    assert c[0] < 1e-12 and c[1] > 0.1 and c[2] > 0.1
    J = srrr.angular_velocity_jacobian(R)
    assert np.all(np.isnan(J[0])) and np.all(np.isfinite(J[1:]))
    assert np.array_equal(srrr.euler_rate_jacobian(-np.pi / 2, 0.3, 0.2)[0], [0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match=r"^R: .*singular"):
        srrr.platform_angular_velocity(R, [0.1, 0.0, 0.0])


# ---------------------------------------------------------------- forward position
def test_forward_round_trip_on_random_orientations():
    """Inverse then forward: theta = eq21(R_target); Newton continued along the straight
    actuator path from home recovers R_target on the home branch (tolerance 1e-9)."""
    rng = np.random.default_rng(7)
    for _ in range(15):
        a, b, g = rng.uniform([-1.0, -1.5, -1.5], [1.0, 1.5, 1.5])
        theta = srrr.actuator_angles(a, b, g)
        path = np.linspace(0, 1, 25)[:, None] * theta
        res = srrr.forward_orientation(path, along_path=True)
        assert res.ok, res.to_dict()["residual"][-1]
        assert np.allclose(res.R[-1], srrr.orientation(a, b, g), atol=1e-9)
        assert np.allclose([res.alpha[-1], res.beta[-1], res.gamma[-1]], [a, b, g], atol=1e-9)


def test_forward_matches_general_forward_position(mech):
    """The closed-form forward solver and the engine's forward position (actuators held,
    everything else free) give the same orientation along the section 4.2 path (1e-9)."""
    t = np.arange(0.0, 361.0, 10.0)
    x = section_42_angles(t)
    theta = srrr.actuator_angles(x, x, x, unwrap=True)
    ours = srrr.forward_orientation(theta, along_path=True)
    assert ours.ok
    active = np.ones(len(mech.freedom_refs), bool)
    active[ACTUATORS] = False
    q = np.zeros(len(mech.freedom_refs))
    D = np.eye(4)
    for k in range(len(t)):
        q = q.copy()
        q[ACTUATORS] = theta[k]
        res = correct(mech, Configuration(q, D), active=active)
        assert res.converged
        q, D = res.config.q, res.config.D
        assert np.allclose(D[:3, :3], ours.R[k], atol=1e-9)
        assert np.allclose(closure_residual(mech, res.config), 0, atol=1e-10)


def test_forward_reports_a_singular_solution_instead_of_hiding_it():
    """Started at home for a far target (no continuation), Newton converges (residual < 1e-12)
    to R = Ry(-90 deg) Rx(-90 deg), where every platform axis lies along its limb's base axis:
    all three limbs are singular (an inverse, type 1 singularity: the platform stays closed for
    ANY actuator angles; the forward Jacobian is regular there).  The result says so:
    limb_conditioning ~ 0, not on the home branch, ok = False."""
    theta = srrr.actuator_angles(0.9, -0.7, 1.2)
    res = srrr.forward_orientation(theta)
    assert bool(res.converged)
    assert np.allclose(res.R, srrr.orientation(-np.pi / 2, -np.pi / 2, 0.0), atol=1e-6)
    assert np.max(srrr.limb_conditioning(res.R)) < 1e-6
    assert float(res.limb_conditioning) < 1e-6 and float(res.conditioning) > 0.1
    assert not bool(res.on_home_branch) and not res.ok
    # any other actuator input also closes there
    f, _ = srrr._forward_terms(res.R, np.array([0.3, -1.1, 2.0]))
    assert np.allclose(f, 0, atol=1e-6)


def test_forward_reports_non_convergence():
    res = srrr.forward_orientation([0.5, 0.4, 0.3], max_iter=1)
    assert not bool(res.converged) and float(res.residual) > 1e-6
    assert not res.ok


def test_forward_result_is_json_serialisable():
    res = srrr.forward_orientation(np.array([[0.0, 0, 0], [0.1, 0.05, 0.02]]), along_path=True)
    d = json.loads(json.dumps(res.to_dict()))
    assert d["euler_sequence"].startswith("YXZ") and "units" not in d
    assert np.allclose(d["alpha_deg"], np.degrees(res.alpha)) and np.allclose(d["rotation_matrix"], res.R)
    assert d["converged"] == [True, True]


# ---------------------------------------------------------------- bad input
@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: srrr.actuator_angles(np.nan, 0, 0), "^alpha: contains NaN"),
        (lambda: srrr.actuator_angles(0, "x", 0), "^beta: expected numbers"),
        (lambda: srrr.actuator_angles(np.zeros(2), np.zeros(3), 0), "^alpha, beta, gamma: shapes"),
        (lambda: srrr.euler_rate_jacobian(0, 0, np.inf), "^gamma: contains NaN or infinity"),
        (lambda: srrr.actuator_angles_from_matrix(np.eye(4)), r"^R: expected shape \(\.\.\., 3, 3\)"),
        (lambda: srrr.actuator_angles_from_matrix(2 * np.eye(3)), "^R: not a rotation matrix"),
        (lambda: srrr.angular_velocity_jacobian(np.diag([1.0, 1.0, -1.0])), "^R: not a rotation matrix"),
        (lambda: srrr.forward_orientation([0.1, 0.2]), r"^theta: expected shape \(\.\.\., 3\)"),
        (lambda: srrr.forward_orientation(np.zeros((2, 2, 3)), along_path=True), "^theta: along_path"),
        (lambda: srrr.forward_orientation([0, 0, 0], R0=np.ones((3, 3))), "^R0: not a rotation"),
        (lambda: srrr.platform_angular_velocity(np.eye(3), [1.0, 2.0]), "^theta_dot: expected shape"),
    ],
)
def test_bad_input_raises_value_error_naming_the_argument(call, message):
    with pytest.raises(ValueError, match=message):
        call()
