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

Forward position is in :mod:`.four_sps_cu_forward` (``forward``, ``forward_all``,
``forward_batch``): the four equations ``(l_i(phi)^2 - l_i^2) / 2 = 0`` solved by a vectorised
Levenberg-Marquardt iteration (Jacobian ``J`` of eq 9, :func:`leg_squares_and_jacobian`) with a
convergence status.  Every root ``(z, R)`` has a mirror image ``(-z, M R M)``,
``M = diag(1, 1, -1)``, i.e. ``(-z, -alpha, -beta, gamma)``: the same leg lengths with the
platform below the base (outside the CU limits).  The conditioning of a pose
(:func:`conditioning`) is here: it belongs to the pose, not to the solver.

Limits checked: leg lengths ``0.1 <= l_i <= 0.4 m`` and CU length ``0.08 <= z <= 0.3 m``.  The
spherical/universal joint-angle limits of eqs 18-21 are NOT checked here (workspace issue).

Worked example (the pose of the multi-assembly check)::

    >>> import numpy as np
    >>> np.round(leg_lengths([0.12, 0.2, -0.1, 0.6]), 6)
    array([0.216745, 0.23896 , 0.227321, 0.206933])
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypedDict

import numpy as np

from ...errors import InputError
from ...geometry.rotations import euler_matrix, transform
from ...geometry.validate import as_finite_array
from ...serialize import fields_dict
from .. import backend
from . import sps

__all__ = [
    "CONDITIONING_MEASURE",
    "DEFAULT_SEED",
    "EULER_SEQUENCE",
    "PAPER_B",
    "PAPER_B_DIMENSIONS",
    "POSE_ORDER",
    "FourSpsCuGeometry",
    "angular_acceleration",
    "angular_velocity",
    "angular_velocity_matrix",
    "attachment_points",
    "conditioning",
    "euler_accelerations",
    "euler_rates",
    "forward_acceleration",
    "forward_velocity",
    "geometry_of",
    "inverse_acceleration",
    "inverse_velocity",
    "jacobian_x",
    "jacobian_x_rate",
    "jacobians",
    "leg_lengths",
    "leg_squares_and_jacobian",
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
        return fields_dict(self, {n: f"{n}_len" for n in ("a", "b", "leg_limits", "z_limits")})


#: Paper B, section 6: a = 0.1 m, b = 0.2 m, legs 0.1..0.4 m, CU 0.08..0.3 m.
PAPER_B = FourSpsCuGeometry()


class PaperBDimensions(TypedDict):
    """Paper B's linkage as the catalogue builds it: half-sizes, home height, leg and CU-slide limits."""

    a: float
    b: float
    z0: float
    leg_limits: tuple[float, float]
    cu_limits: tuple[float, float]


#: Paper B, section 6 (m): half-sides ``a`` (platform) and ``b`` (base), the leg-length and CU-length
#: limits, and ``z0``, the reference height of the ready-made model (``catalog.papers.four_sps_cu``
#: builds it from these: the catalogue depends on the closed form, not the reverse).
PAPER_B_DIMENSIONS: PaperBDimensions = {"a": PAPER_B.a, "b": PAPER_B.b, "z0": 0.2, "leg_limits": PAPER_B.leg_limits,
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


#: Poses from which :func:`leg_lengths` shares the work among the cores (below: one thread; the
#: threads' start-up would cost more than they save).
PARALLEL_FROM = 16384


def leg_lengths(phi, geometry: FourSpsCuGeometry = PAPER_B, *, squared: bool = False) -> np.ndarray:
    """Leg lengths ``l_i`` (..., 4), metres, of poses ``phi`` (..., 4): eq 8, corrected.

    Vectorised closed form (see the module docstring), processed in cache-sized blocks; for
    ``squared=True`` returns ``l_i^2`` (m^2).  Example: ``leg_lengths([0.2, 0, 0, 0])`` gives
    ``sqrt(0.06) = 0.2449...`` for every leg (the catalog model's reference).
    """
    fast = backend.enabled() and isinstance(phi, np.ndarray) and phi.dtype == np.float64 and phi.shape[-1:] == (4,)
    if not fast:  # the compiled kernels flag NaN and infinity themselves: no separate pass
        phi = _phi(phi)
    flat = np.ascontiguousarray(phi.reshape(-1, 4))
    out = np.empty_like(flat)
    if (engine := backend.engine()) is not None:  # the compiled kernels (numba), loaded on first use
        if engine.four_sps_cu_legs(flat, float(geometry.a), float(geometry.b), bool(squared), out,
                                   flat.shape[0] >= PARALLEL_FROM):
            _phi(phi)  # the named error (a finite pose whose sum overflowed passes: its legs are right)
        return out.reshape(phi.shape)
    for s in range(0, flat.shape[0], _CHUNK):
        blk = out[s : s + _CHUNK]
        _legs_sq_block(flat[s : s + _CHUNK], geometry.a, geometry.b, blk)
        if not squared:
            np.maximum(blk, 0.0, out=blk)  # round-off guard for (impossible) zero legs
            np.sqrt(blk, out=blk)
    return out.reshape(phi.shape)


def leg_squares_and_jacobian(phi: np.ndarray, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """``l^2`` (..., 4) and ``J = d(l^2/2)/d phi`` (..., 4, 4) by differentiating the closed form,
    for half-sides ``a`` (platform) and ``b`` (base); ``phi`` (..., 4) is not checked (the
    forward-position solver's inner loop; :func:`jacobians` checks its input)."""
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
    l2, J = leg_squares_and_jacobian(phi, geometry.a, geometry.b)
    l = np.sqrt(np.maximum(l2, 0.0))
    L = np.zeros((*phi.shape[:-1], 4, 4))
    idx = np.arange(4)
    L[..., idx, idx] = l
    return J, L


def jacobian_x(phi, geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """``Jx = L^-1 J = dl/d phi`` (..., 4, 4), so that ``l' = Jx phi'`` (eq 11, corrected)."""
    phi = _phi(phi)
    l2, J = leg_squares_and_jacobian(phi, geometry.a, geometry.b)
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


# ------------------------------------------------------------------ conditioning
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
