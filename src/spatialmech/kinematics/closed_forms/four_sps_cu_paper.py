"""Paper B's own formulas and the checks of its claims, on the 4-SPS/CU closed forms.

Numerical code that the report (``present/paper_b.py``) needs beyond the kinematics of
:mod:`.four_sps_cu`: eq 8 as printed and as corrected, a demonstration trajectory, the
self-motion of the ``alpha = beta = 0`` poses, the closed-form single-angle extents of the
orientation workspace (cross-checked against the numerical workspace), the nondimensional
``det Jx`` and the wrench lines of the singular cases.  Pose ``phi = (z, alpha, beta, gamma)``
(m, rad), ``R = Rz(gamma) Ry(beta) Rx(alpha)``.
"""

from __future__ import annotations

import numpy as np

from ...geometry.validate import as_finite_array
from .four_sps_cu import PAPER_B, FourSpsCuGeometry, jacobian_x

__all__ = [
    "cone_trajectory",
    "det_jacobian_nd",
    "eq8_corrected",
    "eq8_printed",
    "self_motion_height",
    "single_angle_extents",
    "wrench_lines",
]


def eq8_printed(phi, a: float = PAPER_B.a, b: float = PAPER_B.b) -> np.ndarray:
    """Paper B eq 8 **exactly as printed** (seed 002, section 4.1): leg lengths (..., 4) in m.

    Wrong for legs 1, 3 and 4 (conventions.md); kept to measure by how much.  The pose is
    ``phi = (z, alpha, beta, gamma)``."""
    z, al, be, ga = np.moveaxis(np.asarray(phi, float), -1, 0)
    sa, ca, sb, cb, sg, cg = np.sin(al), np.cos(al), np.sin(be), np.cos(be), np.sin(ga), np.cos(ga)
    l1 = (a*cg*cb - a*cg*sb*sa + a*sg*ca - b)**2 + (a*sg*cb - a*ca*cg - a*ca*sb*sg + b)**2 + (-a*sb - a*sa*cb + z)**2
    l2 = (a*cg*cb + a*cg*sb*sa - a*sg*ca - b)**2 + (a*sg*cb + a*ca*cg + a*sa*sb*sg - b)**2 + (-a*sb + a*sa*cb + z)**2
    l3 = (-a*cg*cb + a*cg*sb*sa - a*sg*ca + b)**2 + (-a*sg*cb + a*sa*sg + a*sa*sb*sg - b)**2 + (a*sb + a*sa*cb + z)**2
    l4 = (-a*cg*cb - a*cg*sb*sa + a*sg*ca + b)**2 + (-a*sg*cb - a*ca*cg - a*sa*sb*sg - b)**2 + (a*sb - a*sa*cb + z)**2
    return np.sqrt(np.stack([l1, l2, l3, l4], axis=-1))


def eq8_corrected(phi, a: float = PAPER_B.a, b: float = PAPER_B.b) -> np.ndarray:
    """Eq 8 with the three corrections of conventions.md (l1 Y term ``ca sb sg -> sa sb sg``;
    l3 Y term ``a sa sg -> a ca cg``; l4 Y term ``-b -> +b``): equals ``|T A_i - B_i|``."""
    z, al, be, ga = np.moveaxis(np.asarray(phi, float), -1, 0)
    sa, ca, sb, cb, sg, cg = np.sin(al), np.cos(al), np.sin(be), np.cos(be), np.sin(ga), np.cos(ga)
    l1 = (a*cg*cb - a*cg*sb*sa + a*sg*ca - b)**2 + (a*sg*cb - a*ca*cg - a*sa*sb*sg + b)**2 + (-a*sb - a*sa*cb + z)**2
    l2 = (a*cg*cb + a*cg*sb*sa - a*sg*ca - b)**2 + (a*sg*cb + a*ca*cg + a*sa*sb*sg - b)**2 + (-a*sb + a*sa*cb + z)**2
    l3 = (-a*cg*cb + a*cg*sb*sa - a*sg*ca + b)**2 + (-a*sg*cb + a*ca*cg + a*sa*sb*sg - b)**2 + (a*sb + a*sa*cb + z)**2
    l4 = (-a*cg*cb - a*cg*sb*sa + a*sg*ca + b)**2 + (-a*sg*cb - a*ca*cg - a*sa*sb*sg + b)**2 + (a*sb - a*sa*cb + z)**2
    return np.sqrt(np.stack([l1, l2, l3, l4], axis=-1))


def cone_trajectory(t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A demonstration trajectory ``phi(t)``, its rate and acceleration (..., 4), t in s:
    ``z = 0.2 + 0.02 sin(2 pi t / T)`` m, ``alpha = 0.25 cos(w t)``, ``beta = 0.25 sin(w t)``,
    ``gamma = 0.3 sin(w t)`` rad, ``w = pi`` rad/s (a cone that never meets ``alpha = beta = 0``,
    where the mechanism is singular)."""
    t = np.asarray(t, float)
    w = np.pi
    s, c, s2, c2 = np.sin(w * t), np.cos(w * t), np.sin(2 * w * t), np.cos(2 * w * t)
    phi = np.stack([0.2 + 0.02 * s2, 0.25 * c, 0.25 * s, 0.3 * s], axis=-1)
    dphi = np.stack([0.04 * w * c2, -0.25 * w * s, 0.25 * w * c, 0.3 * w * c], axis=-1)
    ddphi = np.stack([-0.08 * w * w * s2, -0.25 * w * w * c, -0.25 * w * w * s, -0.3 * w * w * s], axis=-1)
    return phi, dphi, ddphi


def self_motion_height(l, gamma, geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """Height ``z >= 0`` (m) of the self-motion with every leg locked at ``l`` (m): the poses
    ``(z, 0, 0, gamma)`` with ``z^2 = l^2 - 2a^2 - 2b^2 + 4ab cos(gamma)``; NaN where ``z^2 < 0``
    (no such pose).  Every ``alpha = beta = 0`` pose is on one of these curves."""
    a, b = geometry.a, geometry.b
    z2 = np.asarray(l, float) ** 2 - 2 * a * a - 2 * b * b + 4 * a * b * np.cos(np.asarray(gamma, float))
    return np.sqrt(np.where(z2 >= 0, z2, np.nan))


def single_angle_extents(z: float, geometry: FourSpsCuGeometry = PAPER_B) -> dict[str, tuple[float, str]]:
    """Closed-form extent (rad) of each angle alone (the others zero) at height ``z`` (m), with
    the limit that sets it, for paper B's limits (spherical-joint cones of 90 deg, eq 18, and
    the leg lengths):

    - ``alpha``, ``beta``: ``atan(z / b)``, where the leg ``A_i B_i`` lies in the plane of the
      platform (the platform-side cone of eq 18 reaches 90 deg: ``b sin(alpha) = z cos(alpha)``);
    - ``gamma``: the twist at which the legs reach their maximum length ``l_max``: with
      ``alpha = beta = 0`` every leg has ``l^2 = 2a^2 + 2b^2 + z^2 - 4ab cos(gamma)``, so
      ``cos(gamma) = (2a^2 + 2b^2 + z^2 - l_max^2) / (4ab)`` (-0.625 for paper B at z = 0.1 m:
      128.68 deg).

    These are what the numerical workspace must find when those limits are the active ones; the
    report cross-checks the two."""
    a, b = geometry.a, geometry.b
    lmax = geometry.leg_limits[1]
    tilt = float(np.arctan2(z, b))
    c = (2 * a * a + 2 * b * b + z * z - lmax * lmax) / (4 * a * b)
    gamma = float(np.arccos(np.clip(c, -1.0, 1.0))) if c >= -1.0 else float(np.pi)
    return {"alpha": (tilt, "A cone"), "beta": (tilt, "A cone"), "gamma": (gamma, "leg length max")}


def det_jacobian_nd(phi, geometry: FourSpsCuGeometry = PAPER_B) -> np.ndarray:
    """``det Jx / b^3`` (...,): the determinant of ``Jx = dl/dphi`` made nondimensional (its sign
    map shows the singularity loci; zero on every ``alpha = beta = 0`` pose)."""
    return np.linalg.det(jacobian_x(phi, geometry)) / geometry.b**3


def wrench_lines(meeting_points, geometry: FourSpsCuGeometry = PAPER_B, cu_point=(0.0, 0.0, 0.2)) -> np.ndarray:
    """The six constraint/actuation lines (6, 6) of the 4-SPS/CU when leg ``i`` runs from its base
    point ``B_i`` through ``meeting_points[i]`` (4, 3), plus the CU limb's two constraint forces
    along X and Y through ``cu_point``: Plücker lines ``(s ; p x s)`` with unit ``s``.  Used to
    test paper B's singular cases by line geometry with platform points placed on the lines."""
    P = as_finite_array(meeting_points, "meeting_points", shape=(4, 3))
    u = as_finite_array(cu_point, "cu_point", shape=(3,))
    B = geometry.base_points

    def line(d, p):
        d = np.asarray(d, float) / np.linalg.norm(d)
        return np.r_[d, np.cross(np.asarray(p, float), d)]

    legs = [line(P[i] - B[i], B[i]) for i in range(4)]
    return np.array([*legs, line([1.0, 0.0, 0.0], u), line([0.0, 1.0, 0.0], u)])
