"""Mass properties of a link: mass, centre of mass and inertia (for statics with gravity and
inverse dynamics, docs/dynamics.md).

Everything is stated **in world coordinates at the reference configuration** (every joint
variable zero; every link frame is world-aligned there): ``com_m`` is the centre of mass's world
position at the reference, ``inertia_kg_m2`` the 3x3 inertia tensor *about the centre of mass*
on the world axes at the reference.  At a configuration where the link is displaced by
``T = [[R, p], [0, 1]]`` they are ``R c + p`` and ``R I R^T``.  SI units: kilograms, metres
(the model's length unit must be the metre for dynamics), kg m^2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = ["LinkInertia", "check_inertia", "solid_cylinder", "spatial_inertia_matrix"]


@dataclass(frozen=True, eq=False)
class LinkInertia:
    """A link's mass (kg), centre of mass (3,) and inertia about it (3, 3), at the reference
    configuration in world coordinates (module docstring)."""

    mass_kg: float
    com_m: np.ndarray
    inertia_kg_m2: np.ndarray

    def moved(self, T: np.ndarray) -> LinkInertia:
        """The same body displaced by ``T`` (4x4): centre ``R c + p``, inertia ``R I R^T``."""
        R, p = T[:3, :3], T[:3, 3]
        return LinkInertia(self.mass_kg, R @ self.com_m + p, R @ self.inertia_kg_m2 @ R.T)

    def __add__(self, other: LinkInertia) -> LinkInertia:
        """Two bodies rigidly joined: total mass, common centre, inertia by the parallel-axis rule."""
        m = self.mass_kg + other.mass_kg
        if m == 0.0:
            return LinkInertia(0.0, np.zeros(3), np.zeros((3, 3)))
        c = (self.mass_kg * self.com_m + other.mass_kg * other.com_m) / m
        inertia = np.zeros((3, 3))
        for b in (self, other):
            d = b.com_m - c
            inertia += b.inertia_kg_m2 + b.mass_kg * (float(d @ d) * np.eye(3) - np.outer(d, d))
        return LinkInertia(m, c, inertia)

    def to_dict(self) -> dict:
        return {"mass_kg": float(self.mass_kg), "com_m": [float(v) for v in self.com_m],
                "inertia_kg_m2": [[float(v) for v in row] for row in self.inertia_kg_m2]}


def check_inertia(mass, com, inertia, where: str) -> LinkInertia:
    """A validated :class:`LinkInertia`: finite numbers, mass >= 0, a symmetric positive
    semi-definite inertia whose principal moments satisfy the triangle inequality (a physical
    body); an :class:`~spatialmech.errors.InputError` naming ``where`` otherwise."""
    try:
        m = float(mass)
        c = np.asarray(com, dtype=float)
        inertia_arr = np.asarray(inertia, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{where}: mass_kg, com_m and inertia_kg_m2 must be numbers") from None
    if isinstance(mass, bool) or not np.isfinite(m) or m < 0:
        raise InputError(f"{where}.mass_kg: expected a finite number >= 0, got {mass!r}")
    if c.shape != (3,) or not np.all(np.isfinite(c)):
        raise InputError(f"{where}.com_m: expected 3 finite numbers, got shape {c.shape}")
    if inertia_arr.shape != (3, 3) or not np.all(np.isfinite(inertia_arr)):
        raise InputError(f"{where}.inertia_kg_m2: expected a 3x3 matrix of finite numbers, got shape "
                         f"{inertia_arr.shape}")
    scale = max(float(np.max(np.abs(inertia_arr))), 1e-300)
    if np.max(np.abs(inertia_arr - inertia_arr.T)) > 1e-9 * scale:
        raise InputError(f"{where}.inertia_kg_m2: not symmetric")
    ev = np.linalg.eigvalsh(0.5 * (inertia_arr + inertia_arr.T))
    if ev[0] < -1e-9 * scale or ev[0] + ev[1] < ev[2] - 1e-9 * scale:
        raise InputError(f"{where}.inertia_kg_m2: not the inertia of a body (principal moments {ev.tolist()} must be "
                         ">= 0 and satisfy the triangle inequality)")
    if m == 0.0 and scale > 1e-300:
        raise InputError(f"{where}: a link of mass 0 cannot have an inertia")
    return LinkInertia(m, c, 0.5 * (inertia_arr + inertia_arr.T))


def solid_cylinder(a: np.ndarray, b: np.ndarray, radius: float, density: float) -> LinkInertia:
    """A solid circular cylinder of ``radius`` from ``a`` to ``b`` of uniform ``density``
    (kg/m^3): ``m = rho pi r^2 h``, about its centre ``m (3 r^2 + h^2) / 12`` across the axis and
    ``m r^2 / 2`` along it."""
    d = np.asarray(b, float) - np.asarray(a, float)
    h = float(np.linalg.norm(d))
    m = density * np.pi * radius**2 * h
    u = d / h
    across = m * (3 * radius**2 + h**2) / 12.0
    along = m * radius**2 / 2.0
    inertia = across * np.eye(3) + (along - across) * np.outer(u, u)
    return LinkInertia(m, 0.5 * (np.asarray(a, float) + np.asarray(b, float)), inertia)


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def spatial_inertia_matrix(body: LinkInertia) -> np.ndarray:
    """The 6x6 matrix ``M`` with momentum ``h = M V``: a twist ``V = (omega ; v)`` (``v`` the
    velocity of the body point at the origin) to the momentum screw ``h = (m v_c ; I omega +
    c x m v_c)`` (linear momentum ; angular momentum about the origin), at the body's current
    placement."""
    m, c, inertia = body.mass_kg, body.com_m, body.inertia_kg_m2
    C = _skew(c)
    M = np.zeros((6, 6))
    M[:3, :3] = -m * C
    M[:3, 3:] = m * np.eye(3)
    M[3:, :3] = inertia - m * C @ C
    M[3:, 3:] = m * C
    return M
