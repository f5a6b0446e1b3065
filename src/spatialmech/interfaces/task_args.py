"""Command-line arguments of the analyses over task coordinates, and of extra workspace limits.

Task coordinates at the command line: ``x, y, z`` in the model's length unit, ``a1, a2, a3`` in
degrees (the Euler angles of the output orientation in the task's named sequence); SI and
radians inside.

- ``--over NAME:MIN:MAX:N[,NAME:MIN:MAX:N ...]``: grid axes (``N`` points from ``MIN`` to ``MAX``);
- ``--at NAME=VALUE[,...]``: given coordinates held;
- ``--free NAME[,...]``: the coordinates to solve (the others are given);
- ``--cone JOINT=DEG`` and ``--limit FREEDOM=LO:HI``: workspace limits beyond the model's.
"""

from __future__ import annotations

import math

import numpy as np

from .. import api as sm
from ..errors import InputError
from .common import parse_number

__all__ = ["MAX_AXIS_POINTS", "TASK_NAMES", "cone_limits", "freedom_limits", "parse_axes", "parse_free",
           "parse_task_at"]

#: The task coordinates, in order.
TASK_NAMES = sm.TASK_COORDINATES

#: Largest number of points along one grid axis.
MAX_AXIS_POINTS = 400


def _si(name: str, value: float) -> float:
    return math.radians(value) if name.startswith("a") else value


def parse_axes(text: str, option: str = "--over", *, min_axes: int = 1, max_axes: int = 3) -> dict[str, np.ndarray]:
    """``"a2:-20:20:41,a3:-20:20:41"`` -> ``{"a2": radians(linspace(-20, 20, 41)), ...}`` (SI)."""
    out: dict[str, np.ndarray] = {}
    for part in str(text).split(","):
        bits = [b.strip() for b in part.strip().split(":")]
        if len(bits) != 4 or bits[0] not in TASK_NAMES:
            raise InputError(f"{option}: expected NAME:MIN:MAX:N[,...] with NAME in {', '.join(TASK_NAMES)} (lengths in "
                             f"the model's unit, angles in degrees), got {part.strip()!r}")
        name = bits[0]
        lo, hi = (parse_number(b, option, f"{name} {w}") for b, w in zip(bits[1:3], ("MIN", "MAX"), strict=True))
        try:
            n = int(bits[3])
        except ValueError:
            raise InputError(f"{option}: {name} N expects a whole number of points, got {bits[3]!r}") from None
        if not 2 <= n <= MAX_AXIS_POINTS:
            raise InputError(f"{option}: {name} N must be 2..{MAX_AXIS_POINTS}, got {n}")
        if not lo < hi:
            raise InputError(f"{option}: {name} expects MIN < MAX, got {bits[1]}:{bits[2]}")
        if not math.isfinite(hi - lo):
            raise InputError(f"{option}: {name} MIN and MAX are too far apart for a float grid, got {bits[1]}:{bits[2]}")
        if name in out:
            raise InputError(f"{option}: {name} is given twice")
        out[name] = np.array([_si(name, v) for v in np.linspace(lo, hi, n)])
    if not min_axes <= len(out) <= max_axes:
        want = str(min_axes) if min_axes == max_axes else f"{min_axes} to {max_axes}"
        raise InputError(f"{option}: expected {want} axes, got {len(out)}")
    return out


def parse_task_at(text: str | None, option: str = "--at") -> dict[str, float]:
    """``"z=0.33,a1=5"`` -> ``{"z": 0.33, "a1": radians(5)}`` (SI)."""
    out: dict[str, float] = {}
    if not text:
        return out
    for part in str(text).split(","):
        part = part.strip()
        if not part:
            continue
        if "=" not in part:
            raise InputError(f"{option}: expected NAME=VALUE pairs separated by commas, got {part!r}")
        k, v = (s.strip() for s in part.split("=", 1))
        if k not in TASK_NAMES:
            raise InputError(f"{option}: unknown task coordinate {k!r}; expected one of {', '.join(TASK_NAMES)} "
                             "(lengths in the model's unit, angles in degrees)")
        if k in out:
            raise InputError(f"{option}: {k} is given twice")
        out[k] = _si(k, parse_number(v, option, k))
    return out


def parse_free(text: str | None, option: str = "--free") -> list[str] | None:
    """``"x,y,a1"`` -> ``["x", "y", "a1"]``, the task coordinates to solve (the others are given);
    ``None`` without text."""
    if text is None:
        return None
    free = [s.strip() for s in str(text).split(",") if s.strip()]
    for n in free:
        if n not in TASK_NAMES:
            raise InputError(f"{option}: unknown task coordinate {n!r}; expected some of {', '.join(TASK_NAMES)}")
    if len(set(free)) != len(free):
        raise InputError(f"{option}: {text!r} names a coordinate twice")
    return free


def cone_limits(items, mech, option: str = "--cone") -> dict[str, float]:
    """``["S1=40", "S2=40"]`` or ``["S1=40,S2=40"]`` -> ``{"S1": radians(40), ...}``: cone limits
    (degrees at the command line) of S or U joints of ``mech`` (``sm.workspace(cones=...)``: the
    angle between the limb's link at the joint and the ``z`` axis of the platform, or of the base
    at the limb's first joint)."""
    known = {j.name for limb in mech.limbs for j in limb.joints}
    out: dict[str, float] = {}
    for item in items or ():
        for part in str(item).split(","):
            part = part.strip()
            if not part:
                continue
            if "=" not in part:
                raise InputError(f"{option}: expected JOINT=DEG, got {part!r}")
            joint, deg = (s.strip() for s in part.split("=", 1))
            if joint not in known:
                raise InputError(f"{option}: {mech.name} has no joint {joint!r}; its joints: {', '.join(sorted(known))}")
            angle = parse_number(deg, option, joint)
            if not 0 < angle <= 180:
                raise InputError(f"{option}: {joint} expects 0 < DEG <= 180, got {deg}")
            out[joint] = min(out.get(joint, math.inf), math.radians(angle))  # twice: both hold, the narrower
    return out


def freedom_limits(items, mech, option: str = "--limit") -> dict[str, tuple[float, float]]:
    """``["L1.slide=0.25:0.45"]`` -> ``{"L1.slide": (0.25, 0.45)}`` (SI: a rotation's limits are
    typed in degrees); ``actuators`` as the name sets every actuator."""
    out: dict[str, tuple[float, float]] = {}
    for item in items or ():
        for part in str(item).split(","):
            part = part.strip()
            if not part:
                continue
            if "=" not in part or ":" not in part.split("=", 1)[1]:
                raise InputError(f"{option}: expected FREEDOM=LO:HI, got {part!r}")
            name, rng = (s.strip() for s in part.split("=", 1))
            lo_t, hi_t = rng.split(":", 1)
            lo, hi = parse_number(lo_t, option, f"{name} LO"), parse_number(hi_t, option, f"{name} HI")
            if not lo < hi:
                raise InputError(f"{option}: {name} expects LO < HI, got {rng}")
            names = list(mech.actuators) if name == "actuators" else [name]
            for n in names:
                try:
                    ref = mech.freedom(n)
                except (KeyError, ValueError) as e:
                    raise InputError(f"{option}: {e}") from None
                rot = ref.freedom.kind != "P"
                out[ref.id] = (math.radians(lo), math.radians(hi)) if rot else (lo, hi)
    return out
