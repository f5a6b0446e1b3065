"""Closed form of the parasitic motion of the symmetric 3-RPS (``catalog.classic.three_rps``).

Each leg's base R joint has its axis ``t_i`` tangent to the base circle at ``B_i``, so the leg
moves in the plane through ``B_i`` normal to ``t_i``; that plane contains the base centre. The
S centre of leg ``i`` sits at ``rp r_i`` in the platform frame (``r_i`` the radial direction at
angle ``g_i`` = 90, 210, 330 deg). Pose: the platform point ``c = (x, y, z)`` and
``R = Rz(a1) Ry(a2) Rx(a3)`` (sequence ``"ZYX"``, upper case = intrinsic). The constraint of leg
``i`` is ``t_i . (R rp r_i + c) = 0``; with ``m_i = Ry(a2) Rx(a3) r_i``::

    -x sin g_i + y cos g_i + rp (cos a1 T_i + sin a1 Q_i) = 0,
    T_i = t_i . m_i,  Q_i = r_i . m_i.

Summed over the three legs (120 deg apart: sum sin g = sum cos g = sum sin 2g = 0,
sum sin^2 g = sum cos^2 g = 3/2) the x, y terms vanish::

    a1 = atan2(sin a2 sin a3, cos a2 + cos a3)

and then, with ``b_i = -rp (cos a1 T_i + sin a1 Q_i)``,
``x = -(2/3) sum sin g_i b_i``, ``y = (2/3) sum cos g_i b_i``.  None depends on ``z`` or on
the base radius.

    >>> import numpy as np
    >>> x, y, a1 = parasitic(0.15, np.radians(5.0), np.radians(5.0))
    >>> round(float(x), 9), round(float(np.degrees(a1)), 6)
    (-0.000569705, 0.218443)
"""

from __future__ import annotations

import numpy as np

__all__ = ["parasitic"]

_G = np.radians([90.0, 210.0, 330.0])


def parasitic(rp: float, a2, a3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The parasitic ``(x, y, a1)`` (length unit of ``rp``, rad) of the symmetric 3-RPS for tilts
    ``a2`` (about y) and ``a3`` (about x) in the ``"ZYX"`` sequence; broadcasts over arrays."""
    a2 = np.asarray(a2, dtype=float)
    a3 = np.asarray(a3, dtype=float)
    c2, s2, c3, s3 = np.cos(a2), np.sin(a2), np.cos(a3), np.sin(a3)
    a1 = np.arctan2(s2 * s3, c2 + c3)
    c1, s1 = np.cos(a1), np.sin(a1)
    x = np.zeros(np.broadcast(a2, a3).shape)
    y = np.zeros_like(x)
    for g in _G:
        sg, cg = np.sin(g), np.cos(g)
        T = sg * cg * (c3 - c2) - s2 * s3 * sg**2
        Q = c2 * cg**2 + s2 * s3 * sg * cg + c3 * sg**2
        b = -rp * (c1 * T + s1 * Q)
        x = x - (2.0 / 3.0) * sg * b
        y = y + (2.0 / 3.0) * cg * b
    return x, y, a1
