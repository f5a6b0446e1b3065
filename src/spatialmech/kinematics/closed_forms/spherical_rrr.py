"""Closed-form kinematics of paper C's 3-RRR metamorphic spherical joint (configuration 3).

Conventions (``docs/conventions.md``, checked numerically):

- Orientation of the moving platform: ``R = Ry(beta) Rx(alpha) Rz(gamma)`` (paper C eq 17),
  the intrinsic sequence ``"YXZ"`` with the angles given to :func:`euler_matrix` in the order
  ``(beta, alpha, gamma)``.  Every function of this module takes the three angles as *named*
  arguments ``alpha, beta, gamma`` (radians) so that the order cannot be confused.
- Limbs (all axes through the centre, mutually perpendicular at the home pose ``R = I``):
  limb 1 ``R1(Y) R2(X) R3(Z)``, limb 2 ``R4(X) R5(Z) R6(Y)``, limb 3 ``R7(Z) R8(Y) R9(X)``.
  The actuated base joints R1, R4, R7 turn right-handed about +Y, +X, +Z by ``theta1, theta2,
  theta3`` (zero at home).  This is ``catalog.build("three-rrr-sm")``.
- Velocities: ``omega`` is the platform's angular velocity in the *fixed* (base) frame
  (rad/s).  ``Qdot = (alphadot, betadot, gammadot)`` are *Euler-angle rates*, which are NOT an
  angular velocity: ``omega = E(alpha, beta) Qdot`` (:func:`euler_rate_matrix`).  Paper C's
  eq 22 ``thetadot = J Qdot`` is the Euler-rate Jacobian :func:`euler_rate_jacobian`; the
  angular-velocity Jacobian ``thetadot = J_omega omega`` is :func:`angular_velocity_jacobian`.

Closed form (one limb at a time).  A limb with base axis ``a``, middle axis ``m`` and platform
axis ``p`` at home (``a, m, p`` mutually perpendicular) closes exactly when its middle axis
after the actuator rotation, ``n(theta) = cos(theta) m + sin(theta) a x m``, is perpendicular to
the platform axis ``w = R p``: ``tan(theta) = (m . w) / ((m x a) . w)``.  Using ``atan2`` with
the signs chosen so that ``theta = 0`` at home gives the assembly branch continuous from the
home pose; the other root ``theta + pi`` is the other assembly of the limb.  For paper C this
is eq 21::

    theta1 = beta
    theta2 = atan2(sin(beta) sin(gamma) + sin(alpha) cos(beta) cos(gamma), cos(alpha) cos(gamma))
    theta3 = atan2(cos(alpha) sin(gamma), sin(alpha) sin(beta) sin(gamma) + cos(beta) cos(gamma))

The paper prints ``arctan`` of the quotients, which jumps to the ``theta + pi`` branch where
``cos(alpha) cos(gamma) < 0`` (resp. the denominator of ``theta3`` is negative).  The result
does not depend on the link radii (the axes all pass through the centre).

Worked example (section 4.2 at ``t = 90 deg``: ``alpha = beta = gamma = pi/6``)::

    >>> import numpy as np
    >>> np.round(np.degrees(actuator_angles(np.pi / 6, np.pi / 6, np.pi / 6)), 2)
    array([30.  , 39.81, 26.33])

A limb is singular (its actuator angle undetermined, its Jacobian row infinite) when its
platform axis ``R p`` is parallel to its base axis ``a``; :func:`limb_conditioning` returns the
sine of that angle for each limb.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...geometry.rotations import euler_matrix, matrix_euler, rotation_class
from ...geometry.validate import as_finite_array

__all__ = [
    "EULER_SEQ",
    "LIMB_AXES",
    "ForwardOrientation",
    "actuator_angles",
    "actuator_angles_from_matrix",
    "angular_velocity_jacobian",
    "euler_angles",
    "euler_rate_jacobian",
    "euler_rate_matrix",
    "forward_orientation",
    "limb_conditioning",
    "orientation",
    "platform_angular_velocity",
]

#: Paper C's Euler sequence (intrinsic Y-X'-Z''): angles passed as ``(beta, alpha, gamma)``.
EULER_SEQ = "YXZ"

_X, _Y, _Z = np.eye(3)
#: Per limb (rows): base (actuated) axis ``a``, middle axis ``m`` and platform axis ``p`` at
#: the home pose, for paper C (R1 R2 R3 = Y X Z, R4 R5 R6 = X Z Y, R7 R8 R9 = Z Y X).
LIMB_AXES = np.array([[_Y, _X, _Z], [_X, _Z, _Y], [_Z, _Y, _X]])

#: Below this conditioning a limb is treated as singular (Jacobian rows are NaN).
SINGULAR_ATOL = 1e-12


def _angles(alpha, beta, gamma):
    a = as_finite_array(alpha, "alpha")
    b = as_finite_array(beta, "beta")
    g = as_finite_array(gamma, "gamma")
    try:
        return np.broadcast_arrays(a, b, g)
    except ValueError:
        raise InputError(
            f"alpha, beta, gamma: shapes {a.shape}, {b.shape}, {g.shape} do not broadcast"
        ) from None


def _rotations(R, name: str = "R") -> np.ndarray:
    R = as_finite_array(R, name)
    if R.shape[-2:] != (3, 3):
        raise InputError(f"{name}: expected shape (..., 3, 3), got {R.shape}")
    err = np.max(np.abs(np.swapaxes(R, -1, -2) @ R - np.eye(3)), initial=0.0)
    if err > 1e-6 or np.any(np.linalg.det(R) < 0):
        raise InputError(f"{name}: not a rotation matrix (orthonormal with det +1); error {err:.3g}")
    return R


def orientation(alpha, beta, gamma) -> np.ndarray:
    """``R = Ry(beta) Rx(alpha) Rz(gamma)`` (paper C eq 17), shape ``(..., 3, 3)``; radians."""
    a, b, g = _angles(alpha, beta, gamma)
    return euler_matrix(EULER_SEQ, np.stack([b, a, g], axis=-1))


def euler_angles(R) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(alpha, beta, gamma)`` of ``R = Ry(beta) Rx(alpha) Rz(gamma)``, ``alpha`` in
    ``[-pi/2, pi/2]`` (scipy's range for the middle angle); radians.  At gimbal lock
    (``cos(alpha) = 0``) ``gamma`` is set to 0."""
    R = _rotations(R)
    with warnings.catch_warnings():
        # at gimbal lock (cos(alpha) = 0) scipy sets gamma = 0 and warns; that is documented here
        warnings.filterwarnings("ignore", message="Gimbal lock detected")
        e = matrix_euler(EULER_SEQ, R)
    return e[..., 1], e[..., 0], e[..., 2]


def _limb_terms(R: np.ndarray):
    """For each limb: ``w = R p``, the atan2 arguments ``(y, x)`` and the vectors needed for
    the derivatives.  Shapes ``(..., 3 limbs, 3)`` and ``(..., 3)``."""
    a, m, p = LIMB_AXES[:, 0], LIMB_AXES[:, 1], LIMB_AXES[:, 2]
    mxa = np.cross(m, a)
    sigma = np.sign(np.sum(mxa * p, axis=-1))  # +1 for paper C; makes theta = 0 at home
    w = np.einsum("...ij,kj->...ki", R, p)  # (..., 3, 3): w_k = R p_k
    y = sigma * np.sum(w * m, axis=-1)
    x = sigma * np.sum(w * mxa, axis=-1)
    return w, y, x, m, mxa, sigma


def actuator_angles_from_matrix(R, *, unwrap: bool = False) -> np.ndarray:
    """Actuator angles ``(theta1, theta2, theta3)`` (rad, in ``(-pi, pi]``) of the home
    assembly branch for platform orientation(s) ``R`` (``(..., 3, 3)``), paper C eq 21 in
    matrix form (``theta_k = atan2(m.w, (m x a).w)``, see the module docstring).

    With ``unwrap=True`` the leading axis is a path and the angles are made continuous along
    it (``np.unwrap``), e.g. for a path that winds round a limb singularity.
    At a limb singularity (:func:`limb_conditioning` = 0) every angle closes the limb; the
    value returned there is ``atan2(0, 0) = 0``.
    """
    R = _rotations(R)
    _, y, x, *_ = _limb_terms(R)
    th = np.arctan2(y, x)
    return np.unwrap(th, axis=0) if unwrap and th.ndim > 1 else th


def actuator_angles(alpha, beta, gamma, *, unwrap: bool = False) -> np.ndarray:
    """Paper C eq 21 with ``atan2``: actuator angles (rad) ``(..., 3)`` for Euler angles
    ``R = Ry(beta) Rx(alpha) Rz(gamma)`` (rad, broadcast).

    ``theta1 = beta`` exactly (as printed; not wrapped), ``theta2, theta3`` by ``atan2`` on the
    branch that is continuous from the home pose (in ``(-pi, pi]``; ``unwrap=True`` makes them
    continuous along a path given on the leading axis).  Section 4.2 example at ``t = 90 deg``:
    ``actuator_angles(pi/6, pi/6, pi/6) = (30.00, 39.81, 26.33) deg``.
    """
    a, b, g = _angles(alpha, beta, gamma)
    sa, ca, sb, cb, sg, cg = np.sin(a), np.cos(a), np.sin(b), np.cos(b), np.sin(g), np.cos(g)
    th = np.stack(
        [
            b,
            np.arctan2(sb * sg + sa * cb * cg, ca * cg),
            np.arctan2(ca * sg, sa * sb * sg + cb * cg),
        ],
        axis=-1,
    )
    if unwrap and th.ndim > 1:
        th[..., 1:] = np.unwrap(th[..., 1:], axis=0)
    return th


def limb_conditioning(R) -> np.ndarray:
    """Per limb, ``|a x R p|``: the sine of the angle between the actuated base axis and the
    platform axis (``(..., 3)``, in ``[0, 1]``; 1 at home).  Zero means the limb is singular:
    its actuator angle is undetermined and the inverse Jacobian row infinite."""
    R = _rotations(R)
    _, y, x, *_ = _limb_terms(R)
    return np.hypot(y, x)


def angular_velocity_jacobian(R) -> np.ndarray:
    """``J_omega`` (``(..., 3, 3)``) with ``thetadot = J_omega omega``, ``omega`` the platform's
    angular velocity in the fixed frame (rad/s -> rad/s).

    Row ``k`` is ``(x (w x m) - y (w x (m x a))) / (x^2 + y^2)`` for ``theta_k = atan2(y, x)``,
    from ``wdot = omega x w``.  Rows of singular limbs (:func:`limb_conditioning` below
    ``1e-12``) are NaN: the actuator rate is unbounded there.  At home ``J_omega`` is the
    permutation taking ``omega`` to ``(omega_y, omega_x, omega_z)``.
    """
    R = _rotations(R)
    w, y, x, m, mxa, sigma = _limb_terms(R)
    r2 = x * x + y * y
    num = x[..., None] * np.cross(w, m) - y[..., None] * np.cross(w, mxa)
    num = sigma[:, None] * num
    with np.errstate(divide="ignore", invalid="ignore"):
        J = num / r2[..., None]
    return np.where((np.sqrt(r2) < SINGULAR_ATOL)[..., None], np.nan, J)


def euler_rate_matrix(alpha, beta, gamma) -> np.ndarray:
    """``E`` (``(..., 3, 3)``) with ``omega = E (alphadot, betadot, gammadot)``, ``omega`` in the
    fixed frame, for ``R = Ry(beta) Rx(alpha) Rz(gamma)``.

    Columns: ``Ry(beta) x`` (alpha), ``y`` (beta), ``Ry(beta) Rx(alpha) z`` (gamma).  Singular
    when ``cos(alpha) = 0`` (gimbal lock of the Y-X-Z sequence).
    """
    a, b, _g = _angles(alpha, beta, gamma)
    sa, ca, sb, cb = np.sin(a), np.cos(a), np.sin(b), np.cos(b)
    z, o = np.zeros_like(a), np.ones_like(a)
    col_a = np.stack([cb, z, -sb], axis=-1)
    col_b = np.stack([z, o, z], axis=-1)
    col_g = np.stack([sb * ca, -sa, cb * ca], axis=-1)
    return np.stack([col_a, col_b, col_g], axis=-1)


def euler_rate_jacobian(alpha, beta, gamma) -> np.ndarray:
    """Paper C eq 22: ``J`` (``(..., 3, 3)``) with ``thetadot = J (alphadot, betadot, gammadot)``
    -- *Euler-angle rates* of ``R = Ry(beta) Rx(alpha) Rz(gamma)``, not angular velocity.

    The derivative of eq 21: row 1 is ``(0, 1, 0)`` exactly (``theta1 = beta``); rows 2 and 3
    are ``J_omega E``.  At home ``J = [[0, 1, 0], [1, 0, 0], [0, 0, 1]]``.
    """
    a, b, g = _angles(alpha, beta, gamma)
    R = orientation(a, b, g)
    J = angular_velocity_jacobian(R) @ euler_rate_matrix(a, b, g)
    J[..., 0, :] = np.array([0.0, 1.0, 0.0])
    return J


def platform_angular_velocity(R, theta_dot) -> np.ndarray:
    """Forward velocity: the fixed-frame angular velocity ``omega`` (rad/s) produced by the
    actuator rates ``theta_dot`` (rad/s, ``(..., 3)``) at orientation ``R``.

    Raises ``ValueError`` at an orientation where ``J_omega`` is singular or undefined."""
    R = _rotations(R)
    td = as_finite_array(theta_dot, "theta_dot")
    if td.shape[-1:] != (3,):
        raise InputError(f"theta_dot: expected shape (..., 3), got {td.shape}")
    J = angular_velocity_jacobian(R)
    if not np.all(np.isfinite(J)) or np.any(np.abs(np.linalg.det(J)) < 1e-12):
        raise InputError("R: the mechanism is singular at this orientation (J_omega not invertible)")
    return np.linalg.solve(J, td[..., None])[..., 0]


# ---------------------------------------------------------------- forward position
@dataclass(frozen=True, eq=False)
class ForwardOrientation:
    """Result of :func:`forward_orientation` (arrays over the leading shape of ``theta``).

    ``R`` orientations; ``alpha, beta, gamma`` their ``"YXZ"`` Euler angles (rad);
    ``converged`` per solve; ``residual`` max ``|n_k . R p_k|`` (dimensionless: cosines);
    ``on_home_branch`` whether eq 21 at ``R`` returns ``theta`` (every limb on the assembly
    branch of the home pose; False means a limb closed on its ``theta + pi`` assembly, or a
    limb is singular there); ``conditioning`` the smallest singular value of the forward
    Jacobian (rows ``(R p_k) x n_k``; zero at a forward (type 2) singularity, where the
    solution is not isolated); ``limb_conditioning`` the smallest :func:`limb_conditioning`
    (zero at an inverse (type 1) singularity, e.g. ``R = Ry(-90 deg) Rx(-90 deg)``, where
    every platform axis lies along its limb's base axis and the platform stays closed for any
    actuator angles); ``iterations`` total Newton iterations used.
    """

    R: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    gamma: np.ndarray
    converged: np.ndarray
    residual: np.ndarray
    on_home_branch: np.ndarray
    conditioning: np.ndarray
    limb_conditioning: np.ndarray
    iterations: int

    @property
    def ok(self) -> bool:
        """Every solve converged on the home branch, away from forward and inverse
        singularities (both conditionings above 1e-6)."""
        return bool(
            np.all(self.converged)
            and np.all(self.on_home_branch)
            and np.all(self.conditioning > 1e-6)
            and np.all(self.limb_conditioning > 1e-6)
        )

    def to_dict(self) -> dict:
        """JSON (docs/json.md): angles in degrees (``alpha_deg`` ...), the rotation matrix."""
        return {
            "rotation_matrix": np.asarray(self.R).tolist(),
            "euler_sequence": f"{EULER_SEQ} (R = Ry(beta) Rx(alpha) Rz(gamma))",
            "alpha_deg": np.degrees(np.asarray(self.alpha)).tolist(),
            "beta_deg": np.degrees(np.asarray(self.beta)).tolist(),
            "gamma_deg": np.degrees(np.asarray(self.gamma)).tolist(),
            "converged": np.asarray(self.converged).tolist(),
            "residual": np.asarray(self.residual).tolist(),
            "on_home_branch": np.asarray(self.on_home_branch).tolist(),
            "conditioning": np.asarray(self.conditioning).tolist(),
            "limb_conditioning": np.asarray(self.limb_conditioning).tolist(),
            "iterations": int(self.iterations),
        }


def _forward_terms(R, theta):
    """Residuals ``f_k = n_k(theta_k) . R p_k`` and their Jacobian rows ``(R p_k) x n_k``
    with respect to a fixed-frame rotation increment of the platform."""
    a, m, p = LIMB_AXES[:, 0], LIMB_AXES[:, 1], LIMB_AXES[:, 2]
    c, s = np.cos(theta)[..., None], np.sin(theta)[..., None]
    n = c * m + s * np.cross(a, m)  # (..., 3, 3)
    w = np.einsum("...ij,kj->...ki", R, p)
    return np.sum(n * w, axis=-1), np.cross(w, n)


def _newton(R, theta, tol, max_iter):
    its = 0
    for its in range(max_iter + 1):
        f, G = _forward_terms(R, theta)
        res = np.max(np.abs(f), axis=-1)
        if np.all(res < tol) or its == max_iter:
            break
        dw = -np.einsum("...ij,...j->...i", np.linalg.pinv(G), f)
        # limit the step (a rotation of at most 0.5 rad) to keep Newton in its basin
        nrm = np.linalg.norm(dw, axis=-1, keepdims=True)
        dw = dw * np.minimum(1.0, 0.5 / np.maximum(nrm, 1e-300))
        dw = np.where((res < tol)[..., None], 0.0, dw)
        R = rotation_class().from_rotvec(dw.reshape(-1, 3)).as_matrix().reshape((*dw.shape, 3)) @ R
    return R, res, its


def forward_orientation(
    theta,
    *,
    R0=None,
    along_path: bool = False,
    tol: float = 1e-12,
    max_iter: int = 50,
) -> ForwardOrientation:
    """Forward position: platform orientation(s) from actuator angles ``theta`` (rad,
    ``(..., 3)``) by Newton's method on the three limb conditions ``n_k(theta_k) . R p_k = 0``.

    ``R0`` is the starting orientation (default: home, ``I``).  With ``along_path=True`` the
    leading axis of ``theta`` is a path: each solve starts from the previous solution
    (continuation), which follows the assembly mode of ``R0``.  Non-convergence and a solution
    on another assembly are reported in the result (``converged``, ``on_home_branch``), never
    raised: the forward problem of a spherical 3-RRR has several solutions.
    """
    th = as_finite_array(theta, "theta")
    if th.shape[-1:] != (3,):
        raise InputError(f"theta: expected shape (..., 3), got {th.shape}")
    if along_path and th.ndim != 2:
        raise InputError(f"theta: along_path needs shape (n, 3), got {th.shape}")
    R0 = np.eye(3) if R0 is None else _rotations(R0, "R0")
    if along_path:
        Rs, rs, total = [], [], 0
        R = R0
        for row in th:
            R, r, its = _newton(R, row, tol, max_iter)
            Rs.append(R)
            rs.append(r)
            total += its
        R, res, its = np.array(Rs), np.array(rs), total
    else:
        R, res, its = _newton(np.broadcast_to(R0, (*th.shape[:-1], 3, 3)).copy(), th, tol, max_iter)
    back = actuator_angles_from_matrix(R)
    d = np.angle(np.exp(1j * (back - th)))
    on_branch = np.all(np.abs(d) < 1e-6, axis=-1)
    a, b, g = euler_angles(R)
    _, G = _forward_terms(R, th)
    cond = np.linalg.svd(G, compute_uv=False)[..., -1]
    limb = np.min(limb_conditioning(R), axis=-1)
    return ForwardOrientation(R, a, b, g, res < tol, res, on_branch, cond, limb, int(its))
