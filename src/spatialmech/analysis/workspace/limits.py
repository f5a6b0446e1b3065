"""Workspace limits: joint cones, link capsules, the paper-B instance; coordinates."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...geometry.validate import as_finite_array, as_unit_vector
from ...model.mechanism import Mechanism
from ...serialize import fields_dict

#: ``R = Rz(gamma) Ry(beta) Rx(alpha)``: intrinsic "ZYX" with the angles ``(gamma, beta, alpha)``.
ORIENTATION_SEQUENCE = "ZYX"
#: Pose coordinates: position of the platform point (m) and the three angles (rad).
COORDINATES = ("x", "y", "z", "alpha", "beta", "gamma")
#: The position coordinates (m) and the orientation coordinates (rad) among :data:`COORDINATES`.
POSITION_COORDINATES = COORDINATES[:3]
ORIENTATION_COORDINATES = COORDINATES[3:]
#: Paper B eq 22 and section 6: link diameters ``D_min = 0.008 m <= D_i <= D_max = 0.01 m``.
PAPER_B_LINK_DIAMETERS = (0.008, 0.01)

#: The active limit of a boundary point that is the sampling box's own bound (no limit met
#: inside it), and the name of the margin that says whether a pose closes.
BOX = "box"
CLOSURE = "closure"


# ------------------------------------------------------------------------------ limits
@dataclass(frozen=True)
class ConeLimit:
    """Cone limit of a spherical or universal joint (paper B eqs 18-20).

    The angle between the limb's link at joint ``joint`` (unit vector from the base-side end to
    the platform-side end of the link) and ``axis`` (a unit vector fixed in the base frame when
    ``frame == "base"``, in the platform frame when ``frame == "platform"``, i.e. ``R axis`` in
    the base frame) must be at most ``max_angle`` (rad).  Paper B: ``A_i`` (platform side)
    ``axis = (0, 0, 1), frame = "platform"``; ``B_i``: ``(0, 0, 1), "base"``; the CU column's
    universal joint ``U5``: ``(0, 0, 1), "platform"``; all ``max_angle = pi / 2``.
    """

    joint: str
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    frame: str = "base"
    max_angle: float = np.pi / 2

    def __post_init__(self):
        if not isinstance(self.joint, str) or not self.joint:
            raise InputError(f"joint: expected a joint name, got {self.joint!r}")
        object.__setattr__(self, "axis", tuple(float(v) for v in as_unit_vector(self.axis, "axis")))
        if self.frame not in ("base", "platform"):
            raise InputError(f"frame: expected 'base' or 'platform', got {self.frame!r}")
        ang = float(as_finite_array(self.max_angle, "max_angle", shape=()))
        if not 0.0 < ang <= np.pi:
            raise InputError(f"max_angle: expected 0 < max_angle <= pi rad, got {ang}")
        object.__setattr__(self, "max_angle", ang)

    @property
    def name(self) -> str:
        return f"{self.joint} cone"

    def to_dict(self) -> dict:
        return fields_dict(self, {"max_angle": "max_angle_deg"})


@dataclass(frozen=True)
class WorkspaceLimits:
    """Limits that the model itself does not carry: joint cones and link capsules.

    ``freedom_limits``: also check every freedom's ``limits`` (actuator strokes, passive
    slides).  ``link_diameter``: ``None`` (no interference check), one diameter (m) for every
    limb's links, or a mapping ``{limb name: diameter}`` (only those limbs are checked).
    """

    cones: tuple[ConeLimit, ...] = ()
    link_diameter: float | Mapping[str, float] | None = None
    freedom_limits: bool = True
    source: str = ""

    def __post_init__(self):
        object.__setattr__(self, "cones", tuple(self.cones))
        for c in self.cones:
            if not isinstance(c, ConeLimit):
                raise InputError(f"cones: expected ConeLimit items, got {type(c).__name__}")
        d = self.link_diameter
        if d is not None:
            items = dict(d) if isinstance(d, Mapping) else {"*": d}
            for k, v in items.items():
                v = float(as_finite_array(v, f"link_diameter[{k}]", shape=()))
                if v < 0:
                    raise InputError(f"link_diameter[{k}]: must be >= 0, got {v}")
                items[k] = v
            object.__setattr__(self, "link_diameter", items.get("*", items))

    def diameter(self, limb: str) -> float | None:
        d = self.link_diameter
        if d is None:
            return None
        if isinstance(d, Mapping):
            return d.get(limb)
        return float(d)

    def to_dict(self) -> dict:
        d = self.link_diameter
        return {"cones": [c.to_dict() for c in self.cones], "freedom_limits": self.freedom_limits,
                "link_diameter_len": dict(d) if isinstance(d, Mapping) else d, "source": self.source}


def paper_b_limits(link_diameter: float = PAPER_B_LINK_DIAMETERS[1], max_angle: float = np.pi / 2) -> WorkspaceLimits:
    """Paper B section 6 limits beyond the model's strokes (legs 0.1..0.4 m, CU 0.08..0.3 m).

    Reading of eqs 18-21 (seed 002): with ``delta_i`` the leg direction ``B_i -> A_i``,
    ``delta_n1 = (0, 0, -1)``, ``delta_n2 = (0, 0, 1)`` and ``R`` the eq 7 matrix,
    eq 18 ``theta_pi = arccos(-delta_i . R delta_n1)`` is the angle between the leg and the
    platform normal ``R e_z`` (the spherical joint ``A_i``); eq 19 the angle between the leg
    and the base normal ``e_z`` (``B_i``); eq 20 the angle between the CU column
    ``delta_5 = (0, 0, z)`` and the platform normal (the universal joint ``U5``); eq 21 (the
    cylindrical joint) imposes nothing.  All limits ``90 deg``.  Eq 22 bounds the link
    diameters (``0.008..0.01 m``); the interference check uses capsules of the largest,
    ``0.01 m`` (the conservative choice).
    """
    cones = tuple(ConeLimit(f"A{i}", (0, 0, 1), "platform", max_angle) for i in range(1, 5))
    cones += tuple(ConeLimit(f"B{i}", (0, 0, 1), "base", max_angle) for i in range(1, 5))
    cones += (ConeLimit("U5", (0, 0, 1), "platform", max_angle),)
    return WorkspaceLimits(cones, link_diameter, True, "paper B section 6, eqs 16-22")


def default_limits(mech: Mechanism) -> WorkspaceLimits:
    """The paper's limits for the paper B model (``four-sps-cu``), else the model's own limits."""
    if mech.name == "four-sps-cu":
        return paper_b_limits()
    return WorkspaceLimits(source="the model's freedom limits")


def with_freedom_limits(mech: Mechanism, limits: Mapping[str, tuple[float, float]]) -> Mechanism:
    """``mech`` with other limits on some freedoms' physical values ``offset + q`` (SI, rad):
    ``{"L1.slide": (0.25, 0.45)}``; names are freedom ids or aliases."""
    from dataclasses import replace

    if not isinstance(limits, Mapping):
        raise InputError(f"limits: expected a mapping of freedom -> (lower, upper), got {type(limits).__name__}")
    new: dict[str, tuple[float, float]] = {}
    for name, rng in limits.items():
        ref = mech.freedom(name)
        lo, hi = (float(v) for v in as_finite_array(rng, f"limits[{name}]", shape=(2,)))
        if not lo < hi:
            raise InputError(f"limits[{name}]: expected lower < upper, got ({lo}, {hi})")
        new[ref.id] = (lo, hi)
    limbs = []
    for limb in mech.limbs:
        joints = []
        for j in limb.joints:
            for f in j.freedoms:
                if f"{j.name}.{f.name}" in new:
                    j = j.with_freedom(f.name, limits=new[f"{j.name}.{f.name}"])
            joints.append(j)
        limbs.append(limb.with_joints(joints))
    return replace(mech, limbs=tuple(limbs))
