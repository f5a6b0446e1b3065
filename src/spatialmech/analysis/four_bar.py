"""The linkage class of a planar four-bar: Grashof type, the input's range, the transmission
angle's range (what a designer reads first; issue 30 item 9).

A model is a planar four-bar when it has two limbs of two R joints each, all four axes parallel
and the joints in one plane normal to them.  Its links: ground ``g`` (the two base pivots), input
``a`` (the limb with the first actuator), coupler ``c`` (the two moving pivots), output ``b``.
With ``d`` the distance from the input's moving pivot to the output's base pivot,
``d^2 = a^2 + g^2 - 2 a g cos(theta)`` (``theta`` the input angle from the ground line), the
loop closes when ``|c - b| <= d <= c + b``, and the transmission angle (between coupler and
output) is ``mu = acos((b^2 + c^2 - d^2) / (2 b c))``, monotone in ``d``: both ranges follow
in closed form from the range of ``d``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.mechanism import Mechanism

__all__ = ["FourBarClass", "four_bar_class"]


@dataclass(frozen=True)
class FourBarClass:
    """Link lengths (model units), Grashof type and ranges (degrees) of a planar four-bar."""

    ground: float
    input: float
    coupler: float
    output: float
    grashof: bool
    kind: str
    #: The input angle from the ground line (base pivot of the input to the output's), degrees:
    #: ``(0, 360)`` for a crank, else ``[lo, hi]`` (and its mirror ``[-hi, -lo]``).
    input_range_deg: tuple[float, float]
    transmission_range_deg: tuple[float, float]

    def to_dict(self) -> dict:
        return {"ground_len": self.ground, "input_len": self.input, "coupler_len": self.coupler,
                "output_len": self.output, "grashof": self.grashof, "kind": self.kind,
                "input_range_deg": list(self.input_range_deg),
                "transmission_range_deg": list(self.transmission_range_deg)}


def _acos_deg(x: float) -> float:
    return float(np.degrees(np.arccos(np.clip(x, -1.0, 1.0))))


def four_bar_class(mech: Mechanism) -> FourBarClass | None:
    """The class of ``mech`` if it is a planar four-bar (see the module), else ``None``."""
    if mech.is_graph or len(mech.limbs) != 2 or any(len(lb.joints) != 2 for lb in mech.limbs):
        return None
    joints = [j for lb in mech.limbs for j in lb.joints]
    if any(j.type != "R" for j in joints):
        return None
    z = np.asarray(joints[0].axes[0], dtype=float)
    z = z / np.linalg.norm(z)
    pts = [np.asarray(j.point, dtype=float) for j in joints]
    scale = max(float(np.max(np.abs(np.array(pts)))), 1e-300)
    if any(abs(abs(float(np.dot(z, np.asarray(j.axes[0]) / np.linalg.norm(j.axes[0])))) - 1.0) > 1e-9 for j in joints):
        return None
    if any(abs(float(np.dot(p - pts[0], z))) > 1e-9 * scale for p in pts):
        return None
    first = mech.actuators[0] if mech.actuators else f"{joints[0].name}.rot"
    k = 1 if any(f"{j.name}." in first for j in mech.limbs[1].joints) else 0
    (P0, P1), (Q0, Q1) = (pts[2 * k], pts[2 * k + 1]), (pts[2 - 2 * k], pts[3 - 2 * k])
    g, a = float(np.linalg.norm(Q0 - P0)), float(np.linalg.norm(P1 - P0))
    c, b = float(np.linalg.norm(Q1 - P1)), float(np.linalg.norm(Q1 - Q0))
    s, lmax = min(g, a, c, b), max(g, a, c, b)
    grashof = s + lmax <= g + a + c + b - s - lmax + 1e-12 * scale
    if not grashof:
        kind = "non-Grashof (triple rocker)"
    elif s == g:
        kind = "Grashof double crank (drag link)"
    elif s == a:
        kind = "Grashof crank-rocker (the input turns fully)"
    elif s == b:
        kind = "Grashof rocker-crank (the output turns fully)"
    else:
        kind = "Grashof double rocker"
    lo, hi = max(abs(a - g), abs(c - b)), min(a + g, c + b)
    th_lo = _acos_deg((a * a + g * g - lo * lo) / (2 * a * g))
    th_hi = _acos_deg((a * a + g * g - hi * hi) / (2 * a * g))
    full = abs(a - g) >= abs(c - b) - 1e-12 * scale and a + g <= c + b + 1e-12 * scale
    mu = (_acos_deg((b * b + c * c - lo * lo) / (2 * b * c)), _acos_deg((b * b + c * c - hi * hi) / (2 * b * c)))
    return FourBarClass(g, a, c, b, bool(grashof), kind, (0.0, 360.0) if full else (th_lo, th_hi), mu)
