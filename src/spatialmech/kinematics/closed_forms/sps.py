"""Closed-form inverse kinematics of SPS legs (any base/platform points, stacks of poses).

An SPS leg ``i`` joins the base point ``b_i`` (base frame) to the platform point ``a_i``
(platform frame).  For a platform pose ``(R, p)`` (rotation and position of the platform frame
in the base frame) the leg vector, length and unit direction are::

    d_i = R a_i + p - b_i,     l_i = |d_i|,     u_i = d_i / l_i .

The leg is a force line: with the screw convention of :mod:`spatialmech.geometry.screws`
(``(s ; s0)``, direction first) its normalised Plücker coordinates are ``(u_i ; b_i x u_i)``, and
for a platform twist ``$ = (omega ; v)`` (``v`` = velocity of the point at the base origin) the
leg rate is the reciprocal product ``l_i' = u_i . v + (b_i x u_i) . omega`` — one row of the
6-column inverse Jacobian.  This holds for any SPS mechanism (Gough-Stewart, 4-SPS/CU, ...).

Everything is SI (metres, radians) and vectorised: ``R`` (..., 3, 3) and ``p`` (..., 3)
broadcast against each other; results carry the leading shape and then the leg axis.

Worked example (one leg from (1, 0, 0) to a platform point (0, 0, 0) held at height 1)::

    >>> import numpy as np
    >>> float(leg_lengths(np.eye(3), [0, 0, 1.0], [[1, 0, 0]], [[0, 0, 0]])[0])
    1.4142135623730951
"""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...geometry.screws import reciprocal_product
from ...geometry.validate import as_finite_array

__all__ = ["leg_lengths", "leg_lines", "leg_rates", "leg_vectors"]


def _points(value, name: str) -> np.ndarray:
    pts = as_finite_array(value, name)
    if pts.ndim != 2 or pts.shape[1] != 3 or pts.shape[0] == 0:
        raise InputError(f"{name}: expected shape (n, 3) with n >= 1, got {pts.shape}")
    return pts


def _pose(R, p) -> tuple[np.ndarray, np.ndarray]:
    R = as_finite_array(R, "R")
    p = as_finite_array(p, "p")
    if R.shape[-2:] != (3, 3):
        raise InputError(f"R: expected shape (..., 3, 3), got {R.shape}")
    if p.shape[-1:] != (3,):
        raise InputError(f"p: expected shape (..., 3), got {p.shape}")
    try:
        np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    except ValueError:
        raise InputError(f"p: leading shape {p.shape[:-1]} does not broadcast with R's {R.shape[:-2]}") from None
    return R, p


def leg_vectors(R, p, base_points, platform_points) -> np.ndarray:
    """Leg vectors ``d_i = R a_i + p - b_i`` (..., n, 3) in the base frame, metres.

    ``R`` (..., 3, 3) and ``p`` (..., 3): platform orientation and position; ``base_points``
    (n, 3) in the base frame; ``platform_points`` (n, 3) in the platform frame.
    """
    R, p = _pose(R, p)
    B = _points(base_points, "base_points")
    A = _points(platform_points, "platform_points")
    if A.shape != B.shape:
        raise InputError(f"platform_points: expected {B.shape[0]} points like base_points, got {A.shape[0]}")
    RA = np.einsum("...ij,nj->...ni", R, A)
    return RA + p[..., None, :] - B


def leg_lengths(R, p, base_points, platform_points) -> np.ndarray:
    """Leg lengths ``l_i = |R a_i + p - b_i|`` (..., n), metres (inverse position of any SPS)."""
    return np.linalg.norm(leg_vectors(R, p, base_points, platform_points), axis=-1)


def leg_lines(R, p, base_points, platform_points) -> np.ndarray:
    """Normalised Plücker coordinates ``(u_i ; b_i x u_i)`` (..., n, 6) of the leg lines.

    These are the actuation wrenches of the legs (unit force along each leg) and the rows of
    the inverse Jacobian: ``l' = leg_lines @ DELTA @ twist``.  Raises ``ValueError`` when a leg
    has zero length (its line is undefined).
    """
    d = leg_vectors(R, p, base_points, platform_points)
    length = np.linalg.norm(d, axis=-1, keepdims=True)
    if np.any(length <= 1e-15):
        raise InputError("R, p: a leg has zero length (base and platform points coincide), its line is undefined")
    u = d / length
    B = np.broadcast_to(np.asarray(base_points, dtype=float), u.shape)
    return np.concatenate([u, np.cross(B, u)], axis=-1)


def leg_rates(R, p, base_points, platform_points, twist) -> np.ndarray:
    """Leg rates ``l_i'`` (..., n), m/s, for a platform twist ``(omega ; v)`` (..., 6).

    ``v`` is the velocity of the point of the platform that is at the base origin (screw
    convention), not of the platform reference point.
    """
    twist = as_finite_array(twist, "twist")
    if twist.shape[-1:] != (6,):
        raise InputError(f"twist: expected shape (..., 6), got {twist.shape}")
    lines = leg_lines(R, p, base_points, platform_points)
    return reciprocal_product(lines, twist[..., None, :])
