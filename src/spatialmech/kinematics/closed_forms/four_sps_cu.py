"""Paper B (seed 002): closed-form kinematics of the 4-SPS/CU parallel mechanism.

Geometry (conventions.md, section 6 of the paper): platform points
``A1 = a(1, -1, 0), A2 = a(1, 1, 0), A3 = a(-1, 1, 0), A4 = a(-1, -1, 0)`` in the platform
frame, base points ``B_i`` likewise with ``b`` in the base frame; ``a = 0.1 m``, ``b = 0.2 m``.

Pose ``phi = (z, alpha, beta, gamma)`` (metres, radians), in this order everywhere in this
module.  The passive CU limb keeps the platform centre on the Z axis (``x = y = 0``), so the
platform frame is at ``(0, 0, z)`` with orientation (eq 7)::

    R = Rz(gamma) Ry(beta) Rx(alpha)      # intrinsic "ZYX" with angles (gamma, beta, alpha)

Inverse position (eq 8, corrected): ``l_i = |R A_i + (0, 0, z) - B_i|``.  Expanding the square
with the signs ``(s1, s2)`` of ``A_i = a(s1, s2, 0)`` gives the closed form used here::

    l_i^2 = 2a^2 + 2b^2 + z^2 + 2 a z (s1 R20 + s2 R21) - 2 a b ((R00 + R11) + s1 s2 (R10 + R01))

with ``R20 = -sin(beta)``, ``R21 = cos(beta) sin(alpha)``,
``R00 + R11 = cb cg + sa sb sg + ca cg`` and ``R10 + R01 = cb sg + sa sb cg - ca sg``.
The printed eq 8 is wrong for legs 1, 3 and 4 (see conventions.md).

Velocity (eq 9): ``L l' = J phi'`` with ``L = diag(l)`` and ``J = d(l^2 / 2) / d phi``; the
paper's eqs 10-13 garble the symbols, the correct relations are ``phi' = J^-1 L l'`` and, with
``Jx = L^-1 J`` (so that ``l' = Jx phi'``), ``phi'' = Jx^-1 (l'' - Jx' phi')``.

Two kinds of platform rates are offered, always labelled by ``terms``:

- ``terms="euler"``: ``(z', alpha', beta', gamma')`` — the paper's generalised velocities
  (Euler-angle rates of the "ZYX" sequence);
- ``terms="angular"``: ``(z', omega_x, omega_y, omega_z)`` — the platform angular velocity in
  the base frame, ``omega = E(phi) (alpha', beta', gamma')`` (:func:`angular_velocity_matrix`).

Singularities: every pose with ``alpha = beta = 0`` is singular (the four legs meet on the Z
axis; with the legs locked the platform keeps the self-motion
``z^2 = l^2 - 2a^2 - 2b^2 + 4ab cos(gamma)``), contrary to the paper's claim.  Forward position
must therefore not be seeded there.

Forward position (:func:`forward`, :func:`forward_all`) solves the four equations
``(l_i(phi)^2 - l_i^2) / 2 = 0`` by a vectorised Levenberg-Marquardt iteration (Jacobian
``J`` of eq 9) with a convergence status; :func:`forward_all` runs it from a deterministic
quasi-random set of seeds and de-duplicates the roots.  Every root ``(z, R)`` has a mirror
image ``(-z, M R M)``, ``M = diag(1, 1, -1)``, i.e. ``(-z, -alpha, -beta, gamma)``: the same
leg lengths with the platform below the base (outside the CU limits).

Limits checked: leg lengths ``0.1 <= l_i <= 0.4 m`` and CU length ``0.08 <= z <= 0.3 m``.  The
spherical/universal joint-angle limits of eqs 18-21 are NOT checked here (workspace issue).

Worked example (the pose of the multi-assembly check)::

    >>> import numpy as np
    >>> np.round(leg_lengths([0.12, 0.2, -0.1, 0.6]), 6)
    array([0.216745, 0.23896 , 0.227321, 0.206933])
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...geometry.rotations import euler_matrix, matrix_euler, transform
from ...geometry.tolerances import current
from ...geometry.validate import as_finite_array
from ...results import SolveStatus
from ...serialize import pose_dict
from ..assembly import AssemblyKind, SelfMotion, dedup_tolerances, group_roots, pose_keys, singular_threshold, trace_set
from . import sps

__all__ = [
    "CONDITIONING_MEASURE",
    "DEFAULT_SEED",
    "EULER_SEQUENCE",
    "PAPER_B",
    "PAPER_B_DIMENSIONS",
    "POSE_ORDER",
    "ForwardAllResult",
    "ForwardBatch",
    "ForwardResult",
    "ForwardSearch",
    "FourSpsCuGeometry",
    "angular_acceleration",
    "angular_velocity",
    "angular_velocity_matrix",
    "attachment_points",
    "conditioning",
    "euler_accelerations",
    "euler_rates",
    "forward",
    "forward_acceleration",
    "forward_all",
    "forward_batch",
    "forward_velocity",
    "geometry_of",
    "inverse_acceleration",
    "inverse_velocity",
    "jacobian_x",
    "jacobian_x_rate",
    "jacobians",
    "leg_lengths",
    "leg_vectors",
    "pose_transform",
    "rotation",
    "twist_jacobian",
]

#: Order of the pose / generalised coordinates: z [m], alpha, beta, gamma [rad].
POSE_ORDER = ("z", "alpha", "beta", "gamma")
#: ``R = Rz(gamma) Ry(beta) Rx(alpha)``: intrinsic "ZYX" with angles ``(gamma, beta, alpha)``.
EULER_SEQUENCE = "ZYX"
#: Sign pattern ``(s1, s2)`` of ``A_i = a (s1, s2, 0)`` and ``B_i = b (s1, s2, 0)``.
SIGNS = np.array([[1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]])
#: Default forward-position seed (z [m], alpha, beta, gamma [rad]); the paper's home pose
#: (0.2, 0, 0, 0) is singular, so the seed is tilted away from alpha = beta = 0.
DEFAULT_SEED = (0.2, 0.1, -0.1, 0.1)

_CHUNK = 1 << 14  # poses per block of the vectorised leg-length kernel (fits in cache)
_TERMS = ("euler", "angular")


def attachment_points(a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """Platform points ``A_i = a (s1, s2, 0)`` (platform frame) and base points ``B_i = b (s1, s2, 0)``
    (4, 3) each, with the sign pattern :data:`SIGNS` (conventions.md)."""
    signs = np.c_[SIGNS, np.zeros(4)]
    return float(a) * signs, float(b) * signs


@dataclass(frozen=True)
class FourSpsCuGeometry:
    """Dimensions (m) and limits of the 4-SPS/CU; defaults are paper B, section 6."""

    a: float = 0.1
    b: float = 0.2
    leg_limits: tuple[float, float] = (0.1, 0.4)
    z_limits: tuple[float, float] = (0.08, 0.3)

    def __post_init__(self):
        for name in ("a", "b"):
            v = as_finite_array(getattr(self, name), name, shape=())
            if v <= 0:
                raise InputError(f"{name}: must be positive, got {float(v)}")
            object.__setattr__(self, name, float(v))
        for name in ("leg_limits", "z_limits"):
            lim = as_finite_array(getattr(self, name), name, shape=(2,))
            if not lim[0] < lim[1]:
                raise InputError(f"{name}: expected (lower, upper) with lower < upper, got {tuple(lim)}")
            object.__setattr__(self, name, (float(lim[0]), float(lim[1])))

    @property
    def platform_points(self) -> np.ndarray:
        """``A_i`` (4, 3) in the platform frame."""
        return attachment_points(self.a, self.b)[0]

    @property
    def base_points(self) -> np.ndarray:
        """``B_i`` (4, 3) in the base frame."""
        return attachment_points(self.a, self.b)[1]

    @property
    def length_scale(self) -> float:
        """Characteristic length used to make the equations nondimensional (``b``)."""
        return self.b

    def to_dict(self) -> dict:
        """JSON (docs/json.md): lengths in the model's unit (``*_len``; paper B: metres)."""
        return {"a_len": self.a, "b_len": self.b, "leg_limits_len": list(self.leg_limits), "z_limits_len": list(self.z_limits)}


#: Paper B, section 6: a = 0.1 m, b = 0.2 m, legs 0.1..0.4 m, CU 0.08..0.3 m.
PAPER_B = FourSpsCuGeometry()
#: Paper B, section 6 (m): half-sides ``a`` (platform) and ``b`` (base), the leg-length and CU-length
#: limits, and ``z0``, the reference height of the ready-made model (``catalog.papers.four_sps_cu``
#: builds it from these: the catalogue depends on the closed form, not the reverse).
PAPER_B_DIMENSIONS = {"a": PAPER_B.a, "b": PAPER_B.b, "z0": 0.2, "leg_limits": PAPER_B.leg_limits,
                      "cu_limits": PAPER_B.z_limits}


# ------------------------------------------------------------------ pose and inverse position
def _phi(phi, name: str = "phi") -> np.ndarray:
    phi = as_finite_array(phi, name)
    if phi.shape[-1:] != (4,):
        raise InputError(f"{name}: expected shape (..., 4) ordered (z, alpha, beta, gamma), got {phi.shape}")
    return phi


def _vec4(value, name: str, shape: tuple[int, ...]) -> np.ndarray:
    v = as_finite_array(value, name)
    if v.shape[-1:] != (4,):
        raise InputError(f"{name}: expected shape (..., 4), got {v.shape}")
    try:
        np.broadcast_shapes(v.shape[:-1], shape)
    except ValueError:
        raise InputError(f"{name}: leading shape {v.shape[:-1]} does not broadcast with phi's {shape}") from None
    return v


def _check_terms(terms: str) -> str:
    if terms not in _TERMS:
        raise InputError(f"terms: expected 'euler' (z', Euler-angle rates) or 'angular' (z', omega), got {terms!r}")
    return terms


def rotation(phi) -> np.ndarray:
    """Platform orientation ``R = Rz(gamma) Ry(beta) Rx(alpha)`` (..., 3, 3) (eq 7)."""
    phi = _phi(phi)
    return euler_matrix(EULER_SEQUENCE, phi[..., [3, 2, 1]])


def pose_transform(phi) -> np.ndarray:
    """4x4 pose of the platform frame (eq 7's ``T``), origin at ``(0, 0, z)`` (..., 4, 4)."""
    phi = _phi(phi)
    p = np.zeros((*phi.shape[:-1], 3))
    p[..., 2] = phi[..., 0]
    return transform(rotation(phi), p)


def leg_vectors(phi, geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """Leg vectors ``R A_i + (0, 0, z) - B_i`` (..., 4, 3), metres (generic SPS kernel)."""
    T = pose_transform(phi)
    return sps.leg_vectors(T[..., :3, :3], T[..., :3, 3], geometry.base_points, geometry.platform_points)


def _sincos(theta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sin, cos)`` through the half-angle tangent ``t = tan(theta / 2)``:
    ``sin = 2t / (1 + t^2)``, ``cos = (1 - t^2) / (1 + t^2)``.

    One ``tan`` instead of ``sin`` + ``cos``: NumPy's float64 ``tan`` is SIMD-vectorised where
    ``sin``/``cos`` are not (measured 3.6 ns against 2 x 17 ns per element), which doubles the
    throughput of :func:`leg_lengths`; the results agree with ``sin``/``cos`` to a few ulp.
    """
    t = np.multiply(theta, 0.5)
    np.tan(t, out=t)
    u = t * t
    d = u + 1.0
    np.reciprocal(d, out=d)
    c = np.subtract(1.0, u, out=u)
    c *= d
    t *= 2.0
    t *= d
    return t, c


def _legs_sq_block(ph: np.ndarray, a: float, b: float, out: np.ndarray) -> None:
    """Squared leg lengths of a block of poses (n, 4) into ``out`` (n, 4) (closed form above)."""
    z = ph[:, 0]
    sa, ca = _sincos(ph[:, 1])
    sb, cb = _sincos(ph[:, 2])
    sg, cg = _sincos(ph[:, 3])
    t = sa * sb
    P = cb * cg  # R00 + R11
    P += ca * cg
    Q = t * cg  # R10 + R01
    t *= sg
    P += t
    Q += cb * sg
    Q -= ca * sg
    az2 = (2.0 * a) * z
    m = az2 * sb  # = -2az R20
    m *= -1.0
    n = az2 * cb  # = 2az R21
    n *= sa
    c = z * z
    c += 2.0 * a * a + 2.0 * b * b
    P *= 2.0 * a * b
    Q *= 2.0 * a * b
    c -= P
    c1 = c + Q  # legs 1, 3: s1 s2 = -1
    c -= Q  # legs 2, 4: s1 s2 = +1
    mm = m - n  # s1 R20 + s2 R21 for leg 1 (1, -1); minus that for leg 3
    m += n  # leg 2 (1, 1); minus for leg 4
    np.add(c1, mm, out=out[:, 0])
    np.add(c, m, out=out[:, 1])
    np.subtract(c1, mm, out=out[:, 2])
    np.subtract(c, m, out=out[:, 3])


def leg_lengths(phi, geometry: FourSpsCuGeometry = PAPER_B, *, squared: bool = False) -> np.ndarray:
    """Leg lengths ``l_i`` (..., 4), metres, of poses ``phi`` (..., 4): eq 8, corrected.

    Vectorised closed form (see the module docstring), processed in cache-sized blocks; for
    ``squared=True`` returns ``l_i^2`` (m^2).  Example: ``leg_lengths([0.2, 0, 0, 0])`` gives
    ``sqrt(0.06) = 0.2449...`` for every leg (the catalog model's reference).
    """
    phi = _phi(phi)
    flat = np.ascontiguousarray(phi.reshape(-1, 4))
    out = np.empty_like(flat)
    for s in range(0, flat.shape[0], _CHUNK):
        blk = out[s : s + _CHUNK]
        _legs_sq_block(flat[s : s + _CHUNK], geometry.a, geometry.b, blk)
        if not squared:
            np.maximum(blk, 0.0, out=blk)  # round-off guard for (impossible) zero legs
            np.sqrt(blk, out=blk)
    return out.reshape(phi.shape)


def _closed_jacobian(phi: np.ndarray, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """``l^2`` (..., 4) and ``J = d(l^2/2)/d phi`` (..., 4, 4) by differentiating the closed form."""
    z, al, be, ga = np.moveaxis(phi, -1, 0)
    sa, ca, sb, cb, sg, cg = np.sin(al), np.cos(al), np.sin(be), np.cos(be), np.sin(ga), np.cos(ga)
    U, V = -sb, cb * sa
    P = cb * cg + sa * sb * sg + ca * cg
    Q = cb * sg + sa * sb * cg - ca * sg
    dU = (np.zeros_like(z), -cb, np.zeros_like(z))  # d/d(alpha, beta, gamma)
    dV = (cb * ca, -sb * sa, np.zeros_like(z))
    dP = (ca * sb * sg - sa * cg, -sb * cg + sa * cb * sg, -cb * sg + sa * sb * cg - ca * sg)
    dQ = (ca * sb * cg + sa * sg, -sb * sg + sa * cb * cg, cb * cg - sa * sb * sg - ca * cg)
    s1 = SIGNS[:, 0]
    s2 = SIGNS[:, 1]
    s12 = s1 * s2
    e = lambda x: np.asarray(x)[..., None]  # noqa: E731  broadcast over the leg axis
    l2 = 2 * a * a + 2 * b * b + e(z * z) + 2 * a * e(z) * (s1 * e(U) + s2 * e(V)) - 2 * a * b * (e(P) + s12 * e(Q))
    cols = [e(z) + a * (s1 * e(U) + s2 * e(V))]
    for k in range(3):
        cols.append(a * e(z) * (s1 * e(dU[k]) + s2 * e(dV[k])) - a * b * (e(dP[k]) + s12 * e(dQ[k])))
    return l2, np.stack(cols, axis=-1)


def jacobians(phi, geometry: FourSpsCuGeometry = PAPER_B) -> tuple[np.ndarray, np.ndarray]:
    """``(J, L)`` of eq 9, ``L l' = J phi'``: ``J = d(l^2/2)/d phi`` (..., 4, 4), ``L = diag(l)``.

    Rows are legs 1..4, columns ``(z, alpha, beta, gamma)``; ``J`` has units (m, m^2/rad).
    """
    phi = _phi(phi)
    l2, J = _closed_jacobian(phi, geometry.a, geometry.b)
    l = np.sqrt(np.maximum(l2, 0.0))
    L = np.zeros((*phi.shape[:-1], 4, 4))
    idx = np.arange(4)
    L[..., idx, idx] = l
    return J, L


def jacobian_x(phi, geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """``Jx = L^-1 J = dl/d phi`` (..., 4, 4), so that ``l' = Jx phi'`` (eq 11, corrected)."""
    phi = _phi(phi)
    l2, J = _closed_jacobian(phi, geometry.a, geometry.b)
    return J / np.sqrt(l2)[..., None]


# ------------------------------------------------------------------ Euler rates and angular velocity
def angular_velocity_matrix(phi) -> np.ndarray:
    """``E`` (..., 3, 3) with ``omega = E (alpha', beta', gamma')`` for ``R = Rz Ry Rx`` ("ZYX").

    ``omega`` is the platform angular velocity in the base frame; the columns are the axes of
    the three Euler rotations at the current pose: ``e_alpha = Rz(gamma) Ry(beta) e_x``,
    ``e_beta = Rz(gamma) e_y``, ``e_gamma = e_z``; ``det E = cos(beta)``.
    """
    phi = _phi(phi)
    _, _, be, ga = np.moveaxis(phi, -1, 0)
    sb, cb, sg, cg = np.sin(be), np.cos(be), np.sin(ga), np.cos(ga)
    E = np.zeros((*phi.shape[:-1], 3, 3))
    E[..., 0, 0], E[..., 1, 0], E[..., 2, 0] = cg * cb, sg * cb, -sb
    E[..., 0, 1], E[..., 1, 1] = -sg, cg
    E[..., 2, 2] = 1.0
    return E


def _E_dot(phi: np.ndarray, phidot: np.ndarray) -> np.ndarray:
    """Time derivative of :func:`angular_velocity_matrix` along ``phidot``."""
    E = angular_velocity_matrix(phi)
    _, bd, gd = np.moveaxis(np.asarray(phidot, dtype=float), -1, 0)[1:]
    ez = np.array([0.0, 0.0, 1.0])
    e_a, e_b = E[..., :, 0], E[..., :, 1]
    Ed = np.zeros(np.broadcast_shapes(E.shape, (*np.shape(phidot)[:-1], 3, 3)))
    Ed[..., :, 0] = np.cross(gd[..., None] * ez + bd[..., None] * e_b, e_a)
    Ed[..., :, 1] = gd[..., None] * np.cross(ez, e_b)
    return Ed


def angular_velocity(phi, phidot) -> np.ndarray:
    """Angular velocity ``omega`` (..., 3), rad/s, base frame, from ``phidot`` (..., 4) (z', Euler rates)."""
    phi = _phi(phi)
    phidot = _vec4(phidot, "phidot", phi.shape[:-1])
    return np.einsum("...ij,...j->...i", angular_velocity_matrix(phi), phidot[..., 1:])


def _E_inverse(phi: np.ndarray) -> np.ndarray:
    cb = np.cos(phi[..., 2])
    if np.any(np.abs(cb) < 1e-12):
        raise InputError("phi: cos(beta) = 0 (gimbal lock of the 'ZYX' angles): Euler-angle rates are undefined")
    return np.linalg.inv(angular_velocity_matrix(phi))


def euler_rates(phi, omega) -> np.ndarray:
    """Euler-angle rates ``(alpha', beta', gamma')`` (..., 3) from the angular velocity ``omega``
    (..., 3, base frame).  ``ValueError`` at ``cos(beta) = 0`` (gimbal lock)."""
    phi = _phi(phi)
    omega = as_finite_array(omega, "omega")
    return np.einsum("...ij,...j->...i", _E_inverse(phi), omega)


def angular_acceleration(phi, phidot, phiddot) -> np.ndarray:
    """``omega' = E psi'' + E' psi'`` (..., 3), rad/s^2, with ``psi = (alpha, beta, gamma)``."""
    phi = _phi(phi)
    phidot = _vec4(phidot, "phidot", phi.shape[:-1])
    phiddot = _vec4(phiddot, "phiddot", phi.shape[:-1])
    E = angular_velocity_matrix(phi)
    return np.einsum("...ij,...j->...i", E, phiddot[..., 1:]) + np.einsum(
        "...ij,...j->...i", _E_dot(phi, phidot), phidot[..., 1:]
    )


def euler_accelerations(phi, phidot, omegadot) -> np.ndarray:
    """Euler-angle accelerations ``psi'' = E^-1 (omega' - E' psi')`` (..., 3), rad/s^2."""
    phi = _phi(phi)
    phidot = _vec4(phidot, "phidot", phi.shape[:-1])
    omegadot = as_finite_array(omegadot, "omegadot")
    rhs = omegadot - np.einsum("...ij,...j->...i", _E_dot(phi, phidot), phidot[..., 1:])
    return np.einsum("...ij,...j->...i", _E_inverse(phi), rhs)


# ------------------------------------------------------------------ velocity and acceleration
def _vector_terms(phi: np.ndarray, geometry: FourSpsCuGeometry):
    """``RA_i``, ``c_i = (0,0,z) - B_i``, ``d_i``, ``l_i`` and ``w_i = RA_i x d_i`` (vector form)."""
    R = rotation(phi)
    RA = np.einsum("...ij,nj->...ni", R, geometry.platform_points)
    c = np.zeros((*phi.shape[:-1], 4, 3)) - geometry.base_points
    c[..., 2] += phi[..., 0, None]
    d = RA + c
    l = np.linalg.norm(d, axis=-1)
    return RA, c, d, l, np.cross(RA, c)


def twist_jacobian(phi, geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """``J_omega`` (..., 4, 4) with ``l' = J_omega (z', omega_x, omega_y, omega_z)`` (angular terms).

    Row ``i`` is ``(d_iz, (R A_i x d_i)) / l_i``: the leg line's reciprocal product with the
    platform twist restricted to the four freedoms left by the CU limb.  ``Jx = J_omega
    blockdiag(1, E)``.
    """
    phi = _phi(phi)
    _, _, d, l, w = _vector_terms(phi, geometry)
    return np.concatenate([d[..., 2:3], w], axis=-1) / l[..., None]


def jacobian_x_rate(phi, phidot, geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """``Jx'`` (..., 4, 4): the time derivative of ``Jx = L^-1 J`` along ``phidot`` (eq 12-13).

    With ``w_i = R A_i x c_i`` and ``J_i = (d_iz, w_i . E)``:
    ``J_i' = (d_iz', w_i' . E + w_i . E')``, ``w_i' = (omega x R A_i) x c_i + z' R A_i x e_z``,
    and ``Jx' = L^-1 (J' - diag(l') Jx)``.
    """
    phi = _phi(phi)
    phidot = _vec4(phidot, "phidot", phi.shape[:-1])
    RA, c, d, l, w = _vector_terms(phi, geometry)
    E = angular_velocity_matrix(phi)
    Ed = _E_dot(phi, phidot)
    omega = np.einsum("...ij,...j->...i", E, phidot[..., 1:])
    zd = phidot[..., 0]
    oRA = np.cross(omega[..., None, :], RA)
    ez = np.array([0.0, 0.0, 1.0])
    wd = np.cross(oRA, c) + zd[..., None, None] * np.cross(RA, ez)
    J = np.concatenate([d[..., 2:3], np.einsum("...nk,...kj->...nj", w, E)], axis=-1)
    Jd = np.concatenate(
        [
            oRA[..., 2:3] + zd[..., None, None],
            np.einsum("...nk,...kj->...nj", wd, E) + np.einsum("...nk,...kj->...nj", w, Ed),
        ],
        axis=-1,
    )
    Jx = J / l[..., None]
    ld = np.einsum("...ij,...j->...i", Jx, phidot)
    return (Jd - ld[..., None] * Jx) / l[..., None]


def _angular_bias(phi: np.ndarray, nu: np.ndarray, geometry: FourSpsCuGeometry) -> np.ndarray:
    """``J_omega' nu`` (..., 4): the leg accelerations at zero platform acceleration (angular terms)."""
    RA, _, d, l, _ = _vector_terms(phi, geometry)
    omega = nu[..., 1:]
    oRA = np.cross(omega[..., None, :], RA)
    dd = oRA.copy()
    dd[..., 2] += nu[..., 0, None]
    ddd = np.cross(omega[..., None, :], oRA)
    ld = np.sum(d * dd, axis=-1) / l
    return (np.sum(dd * dd, axis=-1) + np.sum(d * ddd, axis=-1) - ld**2) / l


def inverse_velocity(phi, rates, *, terms: str = "euler", geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """Leg rates ``l'`` (..., 4), m/s, from platform rates (eq 9 / 11 corrected).

    ``terms="euler"``: ``rates = (z', alpha', beta', gamma')``, ``l' = Jx phi'``;
    ``terms="angular"``: ``rates = (z', omega_x, omega_y, omega_z)`` (base frame),
    ``l' = J_omega rates``.
    """
    phi = _phi(phi)
    rates = _vec4(rates, "rates", phi.shape[:-1])
    Jm = jacobian_x(phi, geometry) if _check_terms(terms) == "euler" else twist_jacobian(phi, geometry)
    return np.einsum("...ij,...j->...i", Jm, rates)


def _solve(Jm: np.ndarray, rhs: np.ndarray, geometry: FourSpsCuGeometry) -> np.ndarray:
    """Solve ``Jm x = rhs`` with a singularity check on the nondimensional matrix."""
    scale = np.array([1.0, 1.0 / geometry.length_scale, 1.0 / geometry.length_scale, 1.0 / geometry.length_scale])
    sv = np.linalg.svd(Jm * scale, compute_uv=False)
    if np.any(sv[..., -1] <= 1e-12 * sv[..., 0]):
        worst = float(np.min(sv[..., -1] / sv[..., 0]))
        raise InputError(
            f"phi: singular pose (smallest/largest singular value of the Jacobian {worst:.1e}); "
            "the platform rates are not determined by the leg rates"
        )
    shape = np.broadcast_shapes(Jm.shape[:-1], rhs.shape)
    return np.linalg.solve(np.broadcast_to(Jm, (*shape, 4)), np.broadcast_to(rhs, shape)[..., None])[..., 0]


def forward_velocity(phi, ldot, *, terms: str = "euler", geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """Platform rates (..., 4) from leg rates ``l'`` (m/s): ``phi' = J^-1 L l'`` (eq 10 corrected).

    Returns ``(z', alpha', beta', gamma')`` for ``terms="euler"`` or
    ``(z', omega_x, omega_y, omega_z)`` for ``terms="angular"``.  ``ValueError`` at a singular
    pose (e.g. ``alpha = beta = 0``).
    """
    phi = _phi(phi)
    ldot = _vec4(ldot, "ldot", phi.shape[:-1])
    Jm = jacobian_x(phi, geometry) if _check_terms(terms) == "euler" else twist_jacobian(phi, geometry)
    return _solve(Jm, ldot, geometry)


def inverse_acceleration(
    phi, rates, accelerations, *, terms: str = "euler", geometry: FourSpsCuGeometry = PAPER_B
) -> np.ndarray:
    """Leg accelerations ``l''`` (..., 4), m/s^2 (eq 13 corrected).

    ``terms="euler"``: ``l'' = Jx phi'' + Jx' phi'`` with ``phi'' = (z'', alpha'', beta'', gamma'')``;
    ``terms="angular"``: ``l'' = J_omega (z'', omega') + J_omega' (z', omega)``.
    """
    phi = _phi(phi)
    rates = _vec4(rates, "rates", phi.shape[:-1])
    acc = _vec4(accelerations, "accelerations", phi.shape[:-1])
    if _check_terms(terms) == "euler":
        return np.einsum("...ij,...j->...i", jacobian_x(phi, geometry), acc) + np.einsum(
            "...ij,...j->...i", jacobian_x_rate(phi, rates, geometry), rates
        )
    return np.einsum("...ij,...j->...i", twist_jacobian(phi, geometry), acc) + _angular_bias(phi, rates, geometry)


def forward_acceleration(
    phi, ldot, lddot, *, terms: str = "euler", geometry: FourSpsCuGeometry = PAPER_B
) -> np.ndarray:
    """Platform accelerations (..., 4) from leg rates and accelerations (eq 12 corrected).

    ``terms="euler"``: ``phi'' = Jx^-1 (l'' - Jx' phi')`` with ``phi' = forward_velocity(...)``;
    ``terms="angular"``: ``(z'', omega') = J_omega^-1 (l'' - J_omega' (z', omega))``.
    """
    phi = _phi(phi)
    lddot = _vec4(lddot, "lddot", phi.shape[:-1])
    rates = forward_velocity(phi, ldot, terms=terms, geometry=geometry)
    if terms == "euler":
        Jm = jacobian_x(phi, geometry)
        bias = np.einsum("...ij,...j->...i", jacobian_x_rate(phi, rates, geometry), rates)
    else:
        Jm = twist_jacobian(phi, geometry)
        bias = _angular_bias(phi, rates, geometry)
    return _solve(Jm, lddot - bias, geometry)


# ------------------------------------------------------------------ forward position
def _lm_batch(l, seeds, geometry: FourSpsCuGeometry, tol: float, max_iter: int):
    """Vectorised Levenberg-Marquardt on ``f = (l(phi)^2 - l^2) / (2 Lc^2) = 0`` from each seed
    (``l`` (4,) shared by all seeds, or (k, 4) one per seed).

    Unknowns are scaled ``(z / Lc, alpha, beta, gamma)`` (``Lc = b``).  Step
    ``(J^T J + mu D^2) h = -J^T f`` with Moré's non-decreasing column scaling ``D`` and
    Nielsen's damping update (``mu *= max(1/3, 1 - (2 rho - 1)^3)`` on success, ``mu *= nu,
    nu *= 2`` on failure), as in MINPACK but batched over the seeds.  A plain Newton iteration
    with a line search stalls in the narrow valleys around the singular set ``alpha = beta = 0``
    (measured on 2000 random poses with seeds perturbed by 0.3 rad / 0.06 m: 10.6 % failures
    for Newton with backtracking, 0.35 % here).

    Returns ``phi`` (k, 4), converged (k,), iterations (k,), residual
    ``max_i |l_i(phi) - l_i|`` (k,, metres) and status codes (0 max_iter, 1 converged,
    2 stalled: the damping grew beyond 1e20 without a decrease of ``|f|``).
    """
    Lc = geometry.length_scale
    a, b = geometry.a, geometry.b
    x = np.array(seeds, dtype=float)
    k = x.shape[0]
    lt = np.array(np.broadcast_to(l, x.shape), dtype=float)
    l2t = lt * lt
    colscale = np.array([Lc, 1.0, 1.0, 1.0])
    eye = np.eye(4)

    def evaluate(xx, rows):
        l2, J = _closed_jacobian(xx, a, b)
        return (l2 - l2t[rows]) / (2 * Lc * Lc), J * (colscale / (Lc * Lc)), l2

    def normal(Jr):
        A = np.swapaxes(Jr, -1, -2) @ Jr
        return A, np.diagonal(A, axis1=-2, axis2=-1)

    def residual():
        return np.max(np.abs(np.sqrt(np.maximum(l2, 0.0)) - lt), axis=-1)

    f, J, l2 = evaluate(x, slice(None))
    cost = np.sum(f * f, axis=-1)
    A, dA = normal(J)
    mu = 1e-3 * np.max(dA, axis=-1)
    nu = np.full(k, 2.0)
    D2 = np.maximum(dA, 1e-12)
    iters = np.zeros(k, dtype=int)
    status = np.zeros(k, dtype=int)
    for _ in range(max_iter):
        status[(status == 0) & (residual() <= tol)] = 1
        run = np.flatnonzero(status == 0)
        if run.size == 0:
            break
        iters[run] += 1
        Jr, fr = J[run], f[run]
        A, dA = normal(Jr)
        g = np.einsum("kji,kj->ki", Jr, fr)
        D2[run] = np.maximum(D2[run], dA)
        damp = mu[run, None] * D2[run]
        h = np.linalg.solve(A + damp[:, :, None] * eye, -g[..., None])[..., 0]
        trial = x[run] + h * colscale
        ft, Jt, l2tr = evaluate(trial, run)
        ct = np.sum(ft * ft, axis=-1)
        predicted = np.einsum("ki,ki->k", h, damp * h - g)  # cost(0) - model cost(h)
        rho = (cost[run] - ct) / np.maximum(predicted, 1e-300)
        ok = np.isfinite(ct) & (rho > 0)
        acc = run[ok]
        x[acc], f[acc], J[acc], l2[acc], cost[acc] = trial[ok], ft[ok], Jt[ok], l2tr[ok], ct[ok]
        mu[acc] *= np.maximum(1.0 / 3.0, 1.0 - (2.0 * rho[ok] - 1.0) ** 3)
        nu[acc] = 2.0
        rej = run[~ok]
        mu[rej] *= nu[rej]
        nu[rej] *= 2.0
        status[rej[mu[rej] > 1e20]] = 2
    status[(status != 1) & (residual() <= tol)] = 1
    return x, status == 1, iters, residual(), status


_STATUS = {0: SolveStatus.MAX_ITER, 1: SolveStatus.CONVERGED, 2: SolveStatus.STALLED}


def _canonical(phi: np.ndarray) -> np.ndarray:
    """Same pose with ``beta`` in [-pi/2, pi/2] and ``alpha, gamma`` in (-pi, pi] (from ``R``)."""
    import warnings

    with warnings.catch_warnings():  # at beta = +-pi/2 scipy sets alpha to 0 and says so: intended
        warnings.filterwarnings("ignore", message="Gimbal lock detected")
        ang = matrix_euler(EULER_SEQUENCE, rotation(phi))
    return np.concatenate([phi[..., :1], ang[..., ::-1]], axis=-1)


def _sigma_min(phi: np.ndarray, geometry: FourSpsCuGeometry) -> np.ndarray:
    """Smallest singular value of ``Jx`` (Euler-angle rates) with the angle columns divided by b:
    the conditioning of the solver's equations (it also vanishes at ``beta = +-pi/2``, a gimbal
    lock of the angles); the mechanism's own is :func:`conditioning`."""
    scale = np.array([1.0, 1.0 / geometry.length_scale, 1.0 / geometry.length_scale, 1.0 / geometry.length_scale])
    return np.linalg.svd(jacobian_x(phi, geometry) * scale, compute_uv=False)[..., -1]


#: What :func:`conditioning` measures (stated in every forward-position result).
CONDITIONING_MEASURE = (
    "singular values of the leg-rate Jacobian J_omega (l' = J_omega (z', omega)) with the omega columns divided by b: "
    "zero when the platform can move with the legs held"
)


def conditioning(phi, geometry: FourSpsCuGeometry = PAPER_B) -> tuple[np.ndarray, np.ndarray]:
    """Conditioning of poses ``phi`` (..., 4) for forward position: ``(sigma_min, condition)``
    (...,), the smallest singular value and ``sigma_min / sigma_max`` of the nondimensional
    leg-rate Jacobian (:func:`twist_jacobian`, angular-velocity columns divided by ``b``).
    Zero exactly where the platform can move with the legs held (every ``alpha = beta = 0``
    pose); free of the Euler angles' own singularity at ``beta = +-pi/2``."""
    b = geometry.length_scale
    J = twist_jacobian(phi, geometry) * np.array([1.0, 1.0 / b, 1.0 / b, 1.0 / b])
    sv = np.linalg.svd(J, compute_uv=False)
    return sv[..., -1], np.where(sv[..., 0] > 0, sv[..., -1] / np.where(sv[..., 0] > 0, sv[..., 0], 1.0), 0.0)


@dataclass(frozen=True, eq=False)
class ForwardResult:
    """One forward-position solution (or failed attempt) of the 4-SPS/CU.

    ``phi`` = ``(z [m], alpha, beta, gamma [rad])``, ``R = Rz(gamma) Ry(beta) Rx(alpha)``;
    ``residual`` = ``max_i |l_i(phi) - l_i|`` in metres; ``sigma_min`` and ``condition`` (=
    sigma_min / sigma_max) of :func:`conditioning` (0 at a singularity), ``singular`` below
    ``singular_below``; ``kind`` (regular, singular, self-motion: see
    :mod:`spatialmech.kinematics.assembly`), ``members`` (converged seeds standing for this
    result); ``within_limits`` checks leg lengths and the CU length ``z`` only (not the joint
    angles of eqs 18-21).
    """

    phi: np.ndarray
    leg_lengths: np.ndarray
    converged: bool
    status: SolveStatus
    iterations: int
    residual: float
    legs_within_limits: bool
    z_within_limits: bool
    sigma_min: float
    seed: np.ndarray
    length_scale: float = 1.0  # b: the nondimensional residual in JSON is residual / length_scale
    leg_limits: tuple[float, float] | None = None  # to name the legs outside their limits
    condition: float = 0.0  # sigma_min / sigma_max
    singular_below: float = 0.0  # sigma_min threshold of ``singular``
    kind: AssemblyKind | None = None  # None for a failed attempt
    members: int = 1
    self_motion: SelfMotion | None = None

    @property
    def within_limits(self) -> bool:
        return self.legs_within_limits and self.z_within_limits

    @property
    def singular(self) -> bool:
        return bool(self.sigma_min < self.singular_below)

    @property
    def rotation(self) -> np.ndarray:
        return rotation(self.phi)

    def to_dict(self, *, actuators=None) -> dict:
        """JSON (docs/json.md), the same fields as the general engine's forward solutions
        (:meth:`spatialmech.kinematics.position.ForwardSolution.to_dict`): the pose as the
        platform point ``(0, 0, z)``, ``euler_deg`` of "ZYX" = ``(gamma, beta, alpha)`` in
        degrees and the rotation matrix; ``residual`` = largest leg-length error / ``b``;
        ``outside_limits`` names the legs (``actuators``, default ``l1..l4``) and ``"z"`` (the
        CU length) outside their limits (joint-angle limits of eqs 18-21 are not checked)."""
        names = _leg_names(actuators)
        if self.leg_limits is not None:
            lo, hi = self.leg_limits
            outside = [n for n, l in zip(names, self.leg_lengths, strict=True) if not lo <= l <= hi]
        else:
            outside = [] if self.legs_within_limits else list(names)
        if not self.z_within_limits:
            outside.append("z")
        return {
            "status": str(self.status),
            "converged": bool(self.converged),
            "iterations": int(self.iterations),
            "residual": float(self.residual) / self.length_scale,
            "pose": pose_dict(self.rotation, [0.0, 0.0, float(self.phi[0])]),
            "within_limits": bool(self.within_limits),
            "outside_limits": outside,
            "sigma_min": float(self.sigma_min),
            "singular": self.singular,
            "condition": float(self.condition),
            "singular_below": float(self.singular_below),
            "conditioning_measure": CONDITIONING_MEASURE,
            "kind": str(self.kind) if self.kind is not None else None,
            "members": int(self.members),
            "self_motion": self.self_motion.to_dict() if self.self_motion is not None else None,
        }


def _leg_names(actuators) -> list[str]:
    names = ["l1", "l2", "l3", "l4"] if actuators is None else [str(a) for a in actuators]
    if len(names) != 4:
        raise InputError(f"actuators: expected the 4 leg names, got {names}")
    return names


def _check_solver(tol: float, max_iter: int) -> None:
    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"tol: expected a positive tolerance in metres, got {tol}")
    if int(max_iter) != max_iter or max_iter < 1:
        raise InputError(f"max_iter: expected a positive integer, got {max_iter}")


def _leg_input(l, geometry: FourSpsCuGeometry) -> np.ndarray:
    l = as_finite_array(l, "l", shape=(4,))
    if np.any(l <= 0):
        raise InputError(f"l: leg lengths must be positive, got {l.tolist()}")
    return l


def _results(l, phi, conv, iters, res, status, seeds, geometry, tol) -> list[ForwardResult]:
    legs_ok = bool(np.all((l >= geometry.leg_limits[0]) & (l <= geometry.leg_limits[1])))
    sig, cond = conditioning(phi, geometry) if phi.shape[0] else (np.zeros(0), np.zeros(0))
    thr = singular_threshold(tol / geometry.length_scale)
    out = []
    for i in range(phi.shape[0]):
        z = phi[i, 0]
        out.append(
            ForwardResult(
                phi=phi[i].copy(),
                leg_lengths=l.copy(),
                converged=bool(conv[i]),
                status=_STATUS[int(status[i])],
                iterations=int(iters[i]),
                residual=float(res[i]),
                legs_within_limits=legs_ok,
                z_within_limits=bool(geometry.z_limits[0] <= z <= geometry.z_limits[1]),
                sigma_min=float(sig[i]),
                seed=np.asarray(seeds[i], dtype=float).copy(),
                length_scale=geometry.length_scale,
                leg_limits=geometry.leg_limits,
                condition=float(cond[i]),
                singular_below=thr,
            )
        )
    return out


def _key(phi: np.ndarray, geometry: FourSpsCuGeometry) -> np.ndarray:
    """Scale-free pose coordinates (..., 12) of ``phi``: platform point ``(0, 0, z) / b`` and ``R``."""
    p = np.zeros((*phi.shape[:-1], 3))
    p[..., 2] = phi[..., 0]
    return pose_keys(rotation(phi), p, geometry.length_scale)


class _LegProblem:
    """The poses with the legs held at ``l``, as a tracking problem (see
    :mod:`spatialmech.kinematics.tracking`): state ``(z, R)``, local coordinates
    ``(dz / b, omega)`` (rotation vector in the base frame), residual ``(|d_i|^2 - l_i^2) / (2 b^2)``
    with ``d_i = R A_i + (0, 0, z) - B_i``.  Free of the Euler angles' gimbal lock."""

    def __init__(self, l, geometry: FourSpsCuGeometry):
        self.l2 = np.asarray(l, dtype=float) ** 2
        self.g = geometry
        self.b = geometry.length_scale

    def _d(self, x):
        z, R = x
        RA = self.g.platform_points @ R.T
        d = RA - self.g.base_points
        d[:, 2] += z
        return RA, d

    def residual(self, x):
        _, d = self._d(x)
        return (np.sum(d * d, axis=1) - self.l2) / (2 * self.b * self.b)

    def jacobian(self, x):
        RA, d = self._d(x)
        return np.c_[d[:, 2] * self.b, np.cross(RA, d)] / (self.b * self.b)

    def retract(self, x, dx):
        from scipy.spatial.transform import Rotation

        z, R = x
        R2 = Rotation.from_rotvec(np.asarray(dx[1:], dtype=float)).as_matrix() @ R
        return (z + self.b * float(dx[0]), R2)

    def difference(self, x, y):
        from scipy.spatial.transform import Rotation

        return np.r_[(y[0] - x[0]) / self.b, Rotation.from_matrix(y[1] @ x[1].T).as_rotvec()]

    def tangent(self, x):
        return np.linalg.svd(self.jacobian(x))[2][-1]


def _trace(l, phi0: np.ndarray, geometry: FourSpsCuGeometry):
    """Follow the solution set of ``l(phi) = l`` through the singular root ``phi0`` (a self-motion
    of the platform with the legs held), on ``(z, R)`` (no Euler-angle singularity)."""

    def key(x):
        return pose_keys(x[1], [0.0, 0.0, x[0]], geometry.length_scale)

    return trace_set(_LegProblem(l, geometry), (float(phi0[0]), rotation(phi0)), key, h0=0.02, h_max=0.1, max_steps=800)


def _classify(l, sols: list[ForwardResult], geometry: FourSpsCuGeometry, tol: float,
              dedup_tol: float | None = None) -> list[ForwardResult]:
    """The converged roots ``sols`` as results: duplicates merged, roots on one self-motion one
    result (:func:`spatialmech.kinematics.assembly.group_roots`), each with its kind and members."""
    from dataclasses import replace

    if not sols:
        return []
    phis = np.array([s.phi for s in sols])
    keys = _key(phis, geometry)
    dedup, sdedup = dedup_tolerances(tol / geometry.length_scale)
    if dedup_tol is not None:
        dedup = float(dedup_tol)
    b = geometry.length_scale
    sv = np.linalg.svd(twist_jacobian(phis, geometry) * np.array([1.0, 1.0 / b, 1.0 / b, 1.0 / b]), compute_uv=False)
    free = [int(np.sum(row < s.singular_below)) for row, s in zip(sv, sols, strict=True)]
    groups = group_roots(keys, [s.singular for s in sols], [s.residual for s in sols],
                         lambda i: _trace(l, phis[i], geometry), dedup_tol=dedup, singular_dedup_tol=max(sdedup, dedup),
                         prefer=[s.within_limits for s in sols], free_dims=free)
    return [replace(sols[g.rep], kind=g.kind, members=len(g.members), self_motion=g.self_motion(keys, geometry.length_scale))
            for g in groups]


def forward(
    l,
    seed=DEFAULT_SEED,
    *,
    geometry: FourSpsCuGeometry = PAPER_B,
    tol: float = 1e-12,
    max_iter: int = 200,
) -> ForwardResult:
    """Forward position: the pose ``phi`` with leg lengths ``l`` (4,) [m], by Levenberg-Marquardt
    from ``seed`` (z [m], alpha, beta, gamma [rad]).

    Converged means ``max_i |l_i(phi) - l_i| <= tol`` (metres); otherwise ``status`` is
    ``"max_iter"`` or ``"stalled"`` and ``phi`` is the last iterate (never a silent wrong
    answer).  The angles are returned canonical (``|beta| <= pi/2``).  The result states its
    conditioning; a singular root is followed along its self-motion (``kind``).  Do not seed at
    ``alpha = beta = 0`` (singular).  Near a fold of the forward map two assembly modes lie
    close together (e.g. 0.045 rad apart) and the mode reached depends on the seed; it is
    always a genuine mode (:func:`forward_all` lists them all).
    """
    l = _leg_input(l, geometry)
    seed = as_finite_array(seed, "seed", shape=(4,))
    _check_solver(tol, max_iter)
    phi, conv, iters, res, status = _lm_batch(l, seed[None], geometry, tol, max_iter)
    out = _results(l, _canonical(phi), conv, iters, res, status, seed[None], geometry, tol)[0]
    return _classify(l, [out], geometry, tol)[0] if out.converged else out


@dataclass(frozen=True, eq=False)
class ForwardBatch:
    """Forward position of many (leg lengths, seed) pairs at once (arrays, one row per pair).

    ``phi`` (k, 4) canonical ``(z [m], alpha, beta, gamma [rad])``; ``converged`` (k,);
    ``iterations`` (k,); ``residual`` (k,) = ``max_i |l_i(phi) - l_i|`` in metres; ``status``
    (k,) of "converged" / "max_iter" / "stalled"; ``within_limits`` (k,) (leg and CU lengths);
    the conditioning of each row (:func:`conditioning`: ``sigma_min``, ``condition``, and
    ``singular``; self-motions are not traced here, see :func:`forward_all`).
    """

    phi: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    status: tuple[SolveStatus, ...]
    within_limits: np.ndarray
    sigma_min: np.ndarray | None = None  # (k,) of :func:`conditioning`
    condition: np.ndarray | None = None  # (k,) sigma_min / sigma_max
    singular: np.ndarray | None = None  # (k,) sigma_min below the singular threshold

    def to_dict(self) -> dict:
        """JSON (docs/json.md): one row per pair; ``z_len`` and the angles in degrees,
        ``R = Rz(gamma) Ry(beta) Rx(alpha)``."""
        return {
            "euler_sequence": EULER_SEQUENCE,
            "z_len": self.phi[:, 0].tolist(),
            "alpha_deg": np.degrees(self.phi[:, 1]).tolist(),
            "beta_deg": np.degrees(self.phi[:, 2]).tolist(),
            "gamma_deg": np.degrees(self.phi[:, 3]).tolist(),
            "converged": self.converged.tolist(),
            "iterations": self.iterations.tolist(),
            "residual_len": self.residual.tolist(),
            "status": [str(v) for v in self.status],
            "within_limits": self.within_limits.tolist(),
            "sigma_min": None if self.sigma_min is None else self.sigma_min.tolist(),
            "condition": None if self.condition is None else self.condition.tolist(),
            "singular": None if self.singular is None else self.singular.tolist(),
        }


def forward_batch(
    l,
    seeds,
    *,
    geometry: FourSpsCuGeometry = PAPER_B,
    tol: float = 1e-12,
    max_iter: int = 200,
) -> ForwardBatch:
    """Forward position for a batch: leg lengths ``l`` (k, 4) or (4,) and ``seeds`` (k, 4).

    The same Levenberg-Marquardt iteration as :func:`forward`, vectorised over the rows (the
    hot path for tracking and workspace scans).  Rows that do not converge are flagged.
    """
    seeds = as_finite_array(seeds, "seeds")
    if seeds.ndim != 2 or seeds.shape[1] != 4:
        raise InputError(f"seeds: expected shape (k, 4) ordered (z, alpha, beta, gamma), got {seeds.shape}")
    l = as_finite_array(l, "l")
    if l.shape not in ((4,), seeds.shape):
        raise InputError(f"l: expected shape (4,) or {seeds.shape} like seeds, got {l.shape}")
    if np.any(l <= 0):
        raise InputError("l: leg lengths must be positive")
    _check_solver(tol, max_iter)
    phi, conv, iters, res, status = _lm_batch(l, seeds, geometry, tol, max_iter)
    phi = _canonical(phi)
    lb = np.broadcast_to(l, seeds.shape)
    legs_ok = np.all((lb >= geometry.leg_limits[0]) & (lb <= geometry.leg_limits[1]), axis=-1)
    z_ok = (phi[:, 0] >= geometry.z_limits[0]) & (phi[:, 0] <= geometry.z_limits[1])
    sig, cond = conditioning(phi, geometry)
    sing = sig < singular_threshold(tol / geometry.length_scale)
    return ForwardBatch(phi, conv, iters, res, tuple(_STATUS[int(c)] for c in status), legs_ok & z_ok, sig, cond, sing)


@dataclass(frozen=True)
class ForwardSearch:
    """How :func:`forward_all` searched (so that a reader can judge its completeness)."""

    method: str
    sequence: str
    n_seeds: int
    box: dict
    tol_m: float
    max_iter: int
    dedup_tol: float
    n_converged: int
    n_distinct: int
    hits: tuple[int, ...] = field(default=())  # seeds that converged to each distinct solution
    n_regular: int = 0
    n_singular: int = 0  # isolated singular roots (assembly modes meeting)
    n_self_motion_sets: int = 0  # continua of poses with the legs held

    def to_dict(self) -> dict:
        """JSON (docs/json.md): the search box in the model's length unit and degrees."""
        box = {}
        for k, (lo, hi) in self.box.items():
            name, unit = k.rsplit("_", 1)
            box[f"{name}_deg" if unit == "rad" else f"{name}_len"] = (
                [float(np.degrees(lo)), float(np.degrees(hi))] if unit == "rad" else [float(lo), float(hi)])
        return {
            "method": self.method,
            "sequence": self.sequence,
            "n_seeds": self.n_seeds,
            "box": box,
            "tol_len": self.tol_m,
            "max_iter": self.max_iter,
            "dedup_tol": self.dedup_tol,
            "n_converged": self.n_converged,
            "n_distinct": self.n_distinct,
            "hits": list(self.hits),
            "n_regular": self.n_regular,
            "n_singular": self.n_singular,
            "n_self_motion_sets": self.n_self_motion_sets,
            "limits_checked": "leg lengths and CU length z (joint-angle limits of eqs 18-21 not checked)",
        }


@dataclass(frozen=True, eq=False)
class ForwardAllResult:
    """All distinct real assembly modes found for one leg-length vector, within limits first."""

    leg_lengths: np.ndarray
    solutions: tuple[ForwardResult, ...]
    search: ForwardSearch

    @property
    def n_within_limits(self) -> int:
        return sum(s.within_limits for s in self.solutions)

    @property
    def phis(self) -> np.ndarray:
        return np.array([s.phi for s in self.solutions]).reshape(-1, 4)

    def to_dict(self, *, actuators=None) -> dict:
        """JSON (docs/json.md), the same fields as the general engine's
        (:meth:`spatialmech.kinematics.position.ForwardResult.to_dict`): the leg lengths held as
        ``actuators_len`` (named by ``actuators``, default ``l1..l4``), the distinct assembly
        modes and the search."""
        names = _leg_names(actuators)
        return {
            "method": "closed form of the 4-SPS/CU (kinematics/closed_forms/four_sps_cu.py)",
            "actuators_deg": {},
            "actuators_len": {n: float(v) for n, v in zip(names, self.leg_lengths, strict=True)},
            "n_solutions": len(self.solutions),
            "n_within_limits": self.n_within_limits,
            "solutions": [s.to_dict(actuators=names) for s in self.solutions],
            "search": self.search.to_dict(),
        }


def forward_all(
    l,
    *,
    geometry: FourSpsCuGeometry = PAPER_B,
    n_seeds: int = 512,
    qmc_seed: int = 0,
    tol: float = 1e-12,
    max_iter: int = 500,
    dedup_tol: float | None = None,
) -> ForwardAllResult:
    """All real assembly modes it can find for leg lengths ``l`` (4,) [m].

    Deterministic multi-seed search: ``n_seeds`` points of a scrambled Halton sequence
    (``scipy.stats.qmc``, seed ``qmc_seed``) over the box ``|z| <= max(l) + sqrt(2) a`` (every
    root lies inside: ``|z| <= l_i + |R A_i|``), ``alpha, gamma`` in ``[-pi, pi]``, ``beta`` in
    ``[-pi/2, pi/2]`` (this covers every orientation), each solved by the vectorised
    Levenberg-Marquardt iteration of :func:`forward`; converged roots closer than ``dedup_tol``
    (default: the ``dedup`` tolerance) in scale-free pose distance are one; singular roots
    are followed along their self-motion with the legs held and all roots on one continuum are
    one result of kind ``self-motion`` (:mod:`spatialmech.kinematics.assembly`).  Mirror roots ``(-z, -alpha,
    -beta, gamma)`` are real assembly modes too and are reported (outside the CU limits).
    A multi-seed search cannot prove completeness: ``search.hits`` says how many seeds reached
    each result.  Roots near the singular set ``alpha = beta = 0`` are reached slowly (LM
    converges linearly in their narrow valleys), hence the larger default ``max_iter``; e.g.
    for the legs of ``(0.256, 0.0085, 0.0077, -0.791)`` 256 seeds find all 8 roots with
    ``max_iter=500`` but only 5 with 200.  Solutions are sorted: within limits first, then by decreasing ``z``.
    """
    l = _leg_input(l, geometry)
    _check_solver(tol, max_iter)
    if int(n_seeds) < 1:
        raise InputError(f"n_seeds: expected a positive integer, got {n_seeds}")
    n_seeds = int(n_seeds)
    zmax = float(np.max(l) + np.sqrt(2.0) * geometry.a)
    box = {
        "z_m": (-zmax, zmax),
        "alpha_rad": (-np.pi, np.pi),
        "beta_rad": (-np.pi / 2, np.pi / 2),
        "gamma_rad": (-np.pi, np.pi),
    }
    lo = np.array([v[0] for v in box.values()])
    hi = np.array([v[1] for v in box.values()])
    from scipy.stats import qmc  # imported here: scipy.stats is slow to import

    u = qmc.Halton(d=4, scramble=True, seed=qmc_seed).random(n_seeds)
    seeds = lo + u * (hi - lo)
    phi, conv, iters, res, status = _lm_batch(l, seeds, geometry, tol, max_iter)
    idx = np.flatnonzero(conv)
    canon = _canonical(phi[idx]) if idx.size else np.zeros((0, 4))
    roots = _results(l, canon, conv[idx], iters[idx], res[idx], status[idx], seeds[idx], geometry, tol)
    dedup = current().dedup if dedup_tol is None else float(dedup_tol)
    sols = _classify(l, roots, geometry, tol, dedup)
    order = sorted(range(len(sols)), key=lambda i: (not sols[i].within_limits, -sols[i].phi[0]))
    kinds = [s.kind for s in sols]
    search = ForwardSearch(
        method="multi-seed Levenberg-Marquardt (batched, Nielsen damping) on (l(phi)^2 - l^2)/2 = 0; roots "
        "de-duplicated by pose distance sqrt(|dz / b|^2 + (2 sin(theta / 2))^2), singular roots on one traced "
        "self-motion counted once",
        sequence=f"scrambled Halton (scipy.stats.qmc), seed {qmc_seed}",
        n_seeds=n_seeds,
        box=box,
        tol_m=tol,
        max_iter=max_iter,
        dedup_tol=dedup,
        n_converged=int(idx.size),
        n_distinct=len(sols),
        hits=tuple(sols[i].members for i in order),
        n_regular=kinds.count(AssemblyKind.REGULAR),
        n_singular=kinds.count(AssemblyKind.SINGULAR),
        n_self_motion_sets=kinds.count(AssemblyKind.SELF_MOTION),
    )
    return ForwardAllResult(l.copy(), tuple(sols[i] for i in order), search)


def geometry_of(mech) -> FourSpsCuGeometry | None:
    """The closed-form geometry of a mechanism when it *is* a 4-SPS/CU of paper B's layout, read
    from the mechanism itself, else ``None``: four S-P-S legs from ``B_i = b (s1, s2, 0)`` to
    ``A_i + (0, 0, z0)``, ``A_i = a (s1, s2, 0)`` (:func:`attachment_points`), each P freedom
    along its leg, actuated, its value the leg length (``offset`` = the reference length) and the
    same limits on all four, the actuators exactly these four in leg order; a C-U limb: C along
    +Z through the Z axis with the slide's value the height ``z`` (its limits the CU limits), U at
    ``(0, 0, z0)`` about Y then X; platform point ``(0, 0, z0)``.

    Lets general commands use the closed forms on a matching model (e.g. a file exported from
    the ready-made one) and fall back to the general engine on anything else.  (The catalogue's
    ``four_sps_cu`` builds its model from :data:`PAPER_B_DIMENSIONS` and :func:`attachment_points`;
    this module does not depend on the catalogue.)"""
    try:
        limbs = mech.limbs
        if [tuple(j.type for j in limb.joints) for limb in limbs] != [("S", "P", "S")] * 4 + [("C", "U")]:
            return None
        A1, B1 = np.asarray(limbs[0].joints[2].point, float), np.asarray(limbs[0].joints[0].point, float)
        a, b, z0 = float(A1[0]), float(B1[0]), float(A1[2])
        if not (a > 0 and b > 0):
            return None
        tol = 1e-9 * max(a, b, abs(z0))

        def near(u, v, t=tol) -> bool:
            return bool(np.all(np.abs(np.asarray(u, float) - np.asarray(v, float)) <= t))

        A, B = attachment_points(a, b)
        top = np.array([0.0, 0.0, z0])
        leg_limits, act_ids = None, []
        for i in range(4):
            bj, pj, aj = limbs[i].joints
            d = A[i] + top - B[i]
            length = float(np.linalg.norm(d))
            f = pj.freedoms[0]
            if not (near(bj.point, B[i]) and near(aj.point, A[i] + top) and near(f.direction, d / length, 1e-9)):
                return None
            if not f.actuated or f.locked or f.limits is None or abs(f.offset - length) > tol:
                return None
            if leg_limits is None:
                leg_limits = tuple(f.limits)
            elif not near(f.limits, leg_limits, 0.0):
                return None
            act_ids.append(f"{pj.name}.{f.name}")
        cj, uj = limbs[4].joints
        rot, slide = cj.freedoms
        ez = np.array([0.0, 0.0, 1.0])
        if not (near(cj.point[:2], [0.0, 0.0]) and near(rot.direction, ez, 1e-9) and near(slide.direction, ez, 1e-9)):
            return None
        if slide.limits is None or abs(slide.offset - z0) > tol:
            return None
        if any(f.actuated or f.locked for f in (*cj.freedoms, *uj.freedoms)):
            return None
        if not (near(uj.point, top) and near(uj.freedoms[0].direction, [0.0, 1.0, 0.0], 1e-9)
                and near(uj.freedoms[1].direction, [1.0, 0.0, 0.0], 1e-9) and near(mech.platform_point, top)):
            return None
        if list(mech.actuators) != act_ids:
            return None
        assert leg_limits is not None
        return FourSpsCuGeometry(a=a, b=b, leg_limits=(float(leg_limits[0]), float(leg_limits[1])),
                                 z_limits=(float(slide.limits[0]), float(slide.limits[1])))
    except (AttributeError, IndexError, TypeError, ValueError):
        return None
