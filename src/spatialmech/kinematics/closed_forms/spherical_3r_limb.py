"""Every inverse solution of a spherical 3R limb, in closed form.

A limb of three revolute joints from the ground to the output link whose axes meet at one
point ``c`` (a spherical wrist, an Agile-Eye leg, paper C's legs) only orients the output link
about ``c``.  With the axes' reference directions ``u1, u2, u3`` the limb closes at the output
displacement ``(Rp, t)`` when ``Rp c + t = c`` and

    Rot(u1, q1) Rot(u2, q2) Rot(u3, q3) = Rp.

Paden and Kahan's subproblems solve it (Murray, Li and Sastry 1994, section 3.2):

1. ``v = Rp u3`` must be ``Rot(u1, q1) Rot(u2, q2) u3`` (the last rotation keeps ``u3``).
2. Subproblem 2: the middle point ``z = Rot(u2, q2) u3 = Rot(u1, -q1) v`` has ``u1.z = u1.v`` and
   ``u2.z = u2.u3``; written ``z = alpha u1 + beta u2 + gamma (u1 x u2)``, the two conditions fix
   ``alpha, beta`` and ``|z| = 1`` gives ``gamma^2``: two solutions (complex when
   ``gamma^2 < 0``, one double root when it is 0).
3. Subproblem 1 gives ``q2`` (``u3`` turned to ``z`` about ``u2``), ``q1`` (``z`` to ``v`` about
   ``u1``) and ``q3`` (the rotation left, about ``u3``), each unique when the vector turned is
   not on the axis.

So the limb has at most two configurations at any pose, and this finds both: complete by
construction (no probability, no path tracking).  The exceptions are named, not solved: ``z``
on ``u1`` (then ``v`` is on ``u1`` too and ``q1`` is free: a continuum) and consecutive
parallel axes (not a spherical 3R).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.mechanism import GROUND, Mechanism

__all__ = ["Spherical3R", "solve", "spherical_3r", "spherical_axes"]

#: |sin| of the angle between two axes below which they count as parallel (not a spherical 3R);
#: and the size below which a vector lies on the axis it is turned about (a continuum).
PARALLEL = 1e-9
#: |gamma^2| below which the two middle-axis placements are one double root (a singular pose).
DOUBLE = 1e-12


@dataclass(frozen=True)
class Spherical3R:
    """The reference axes ``u`` (3, 3) (rows: base, middle, last) through ``centre``."""

    u: np.ndarray
    centre: np.ndarray


def spherical_3r(mech: Mechanism, li: int, screws: np.ndarray, tol: float = 1e-9) -> Spherical3R | None:
    """The limb ``li`` as a spherical 3R (``screws``: its reference screws, (3, 6)), or ``None``:
    not three unlocked revolutes of pitch 0 from the ground to the output link, axes not through
    one point, or two consecutive axes parallel."""
    limb = mech.limbs[li]
    if limb.base != GROUND or limb.tip not in (None, mech.output) or len(limb.joints) != 3:
        return None
    if any(j.type != "R" or j.freedoms[0].locked or j.freedoms[0].pitch != 0.0 for j in limb.joints):
        return None
    return spherical_axes(screws, tol)


def spherical_axes(screws: np.ndarray, tol: float = 1e-9) -> Spherical3R | None:
    """Three rotation screws (3, 6) (direction; moment) as a spherical 3R: ``None`` when their
    axes do not meet at one point or two consecutive ones are parallel."""
    w, m = screws[:, :3], screws[:, 3:]
    # the common point: m_i = c x w_i  (moments about the origin), least squares over the three
    A = np.concatenate([np.array([[0.0, wi[2], -wi[1]], [-wi[2], 0.0, wi[0]], [wi[1], -wi[0], 0.0]]) for wi in w])
    c, *_ = np.linalg.lstsq(A, m.ravel(), rcond=None)
    scale = 1.0 + float(np.linalg.norm(m)) + float(np.linalg.norm(c))
    if np.linalg.norm(A @ c - m.ravel()) > tol * scale:
        return None
    u = w / np.linalg.norm(w, axis=1)[:, None]
    if min(np.linalg.norm(np.cross(u[0], u[1])), np.linalg.norm(np.cross(u[1], u[2]))) < PARALLEL:
        return None
    return Spherical3R(u, c)


def _turn(axis: np.ndarray, a: np.ndarray, b: np.ndarray) -> float | None:
    """Subproblem 1: the angle about the unit ``axis`` taking ``a`` to ``b`` (their components
    along the axis equal), ``None`` when ``a`` lies on the axis (every angle does)."""
    ap, bp = a - (axis @ a) * axis, b - (axis @ b) * axis
    if np.linalg.norm(ap) < PARALLEL or np.linalg.norm(bp) < PARALLEL:
        return None
    return float(np.arctan2(axis @ np.cross(ap, bp), ap @ bp))


def _rot(axis: np.ndarray, t: float) -> np.ndarray:
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(t) * K + (1.0 - np.cos(t)) * (K @ K)


def solve(s: Spherical3R, D: np.ndarray, L: float) -> tuple[list[np.ndarray], str, bool]:
    """The real configurations ``(q1, q2, q3)`` of the limb at the output displacement ``D``
    (4x4), a statement, and whether the set is proven complete (``False``: a continuum, the
    caller searches otherwise).  ``L``: the model's length scale (the centre's check)."""
    Rp = D[:3, :3]
    moved = float(np.linalg.norm(Rp @ s.centre + D[:3, 3] - s.centre)) / L
    head = "closed form for three revolutes with concurrent axes (a spherical 3R: Paden-Kahan subproblems)"
    if moved > 1e-9:
        return [], (f"complete (proven): {head}: the pose moves the axes' common point by {moved:.3g} L: "
                    "no configuration"), True
    u1, u2, u3 = s.u
    v = Rp @ u3
    k = float(u1 @ u2)
    a1, a2 = float(u1 @ v), float(u2 @ u3)
    alpha, beta = (a1 - k * a2) / (1 - k * k), (a2 - k * a1) / (1 - k * k)
    g2 = (1.0 - alpha * alpha - beta * beta - 2 * alpha * beta * k) / (1 - k * k)
    if g2 < -DOUBLE:
        return [], (f"complete (proven): {head}: the middle axis has no real placement (gamma^2 = {g2:.3g} < 0: "
                    "2 complex configurations, 0 real)"), True
    n12 = np.cross(u1, u2)
    # a tiny positive gamma^2 keeps both roots (Gauss-Newton polishes each; equal ones are one)
    gammas = [0.0] if g2 <= 0.0 else [np.sqrt(g2), -np.sqrt(g2)]
    out = []
    for g in gammas:
        z = alpha * u1 + beta * u2 + g * n12
        q2, q1 = _turn(u2, u3, z), _turn(u1, z, v)
        if q1 is None or q2 is None:
            return [], (f"NOT proven: {head}: a continuum (the middle point lies on an axis: that joint turns "
                        "freely)"), False
        R3 = _rot(u2, -q2) @ _rot(u1, -q1) @ Rp
        e = np.eye(3)[int(np.argmin(np.abs(u3)))]
        x = np.cross(u3, e)
        x /= np.linalg.norm(x)
        q3 = _turn(u3, x, R3 @ x)
        assert q3 is not None  # x is perpendicular to u3 by construction
        out.append(np.array([q1, q2, q3]))
    what = "one double root (a singular configuration)" if abs(g2) <= DOUBLE else "2 real configurations"
    return out, f"complete (proven): {head}: at most 2 configurations; {what}", True
