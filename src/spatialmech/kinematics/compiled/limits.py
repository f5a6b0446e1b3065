"""Joint points of many configurations at once, compiled: the entry of
:func:`.kernels_limits.nb_joint_points`, whose Python reference is
:func:`spatialmech.kinematics.closure.joint_points` (one configuration at a time)."""

from __future__ import annotations

import weakref
from collections.abc import Sequence

import numpy as np

from ...errors import InputError
from ...model.mechanism import Mechanism
from .engine import compile_mechanism
from .kernels_limits import nb_joint_points, nb_link_margins

__all__ = ["joint_point_spec", "joint_points_many", "link_margins_many"]

_SPECS: weakref.WeakKeyDictionary[Mechanism, list[list[tuple[int, np.ndarray]]]] = weakref.WeakKeyDictionary()


def joint_point_spec(mech: Mechanism) -> list[list[tuple[int, np.ndarray]]]:
    """Per limb, per joint point of :func:`..closure.joint_points` (its joints with freedoms, in
    order): ``(global index of the joint's first freedom, the joint's reference point)``."""
    try:
        return _SPECS[mech]
    except KeyError:
        pass
    out: list[list[tuple[int, np.ndarray]]] = [[] for _ in mech.limbs]
    seen: set[tuple[int, int]] = set()
    for i, r in enumerate(mech.freedom_refs):
        if (r.limb, r.joint) not in seen:
            seen.add((r.limb, r.joint))
            out[r.limb].append((i, np.asarray(mech.limbs[r.limb].joints[r.joint].point, dtype=float)))
    _SPECS[mech] = out
    return out


def joint_points_many(mech: Mechanism, q, points: Sequence[tuple[int, int]]) -> np.ndarray:
    """The joint points ``points`` (``(limb, k)``: point ``k`` of limb ``limb`` in the order of
    :func:`..closure.joint_points`) at the joint variables ``q`` (N, n): an (N, len(points), 3)
    array.  Every limb whose points are asked for must start on the ground (its points do not
    depend on any hub displacement); :class:`InputError` otherwise."""
    cm = compile_mechanism(mech)
    qs = np.ascontiguousarray(q, dtype=float)
    if qs.ndim != 2 or qs.shape[1] != cm.n:
        raise InputError(f"q: expected shape (N, {cm.n}), got {qs.shape}")
    spec = joint_point_spec(mech)
    fr = np.empty(len(points), dtype=np.int64)
    loc = np.empty((len(points), 3))
    for j, (li, k) in enumerate(points):
        if mech.limb_ends[li][0] is not None:
            raise InputError(f"points: limb {mech.limbs[li].name} does not start on the ground")
        fr[j], loc[j] = spec[li][k]
    out = np.empty((qs.shape[0], len(points), 3))
    if qs.shape[0] and len(points):
        nb_joint_points(cm.screws, cm.ball_of, cm.ball_axes, cm.ball_centre, cm.limb_start, qs, fr, loc, out)
    return out


def link_margins_many(mech: Mechanism, q, R, link_points: Sequence[tuple[int, int]], cones, pairs) -> np.ndarray:
    """Cone and interference margins at the joint variables ``q`` (N, n) and platform
    orientations ``R`` (N, 3, 3): ``link_points`` the link ends (every link's start, then every
    link's end, as :func:`joint_points_many` takes them); ``cones`` ``(axis, in the platform
    frame, max_angle (rad), link index)`` per cone limit; ``pairs`` ``(link i, link j,
    clearance)`` per capsule pair.  Returns (N, len(cones) + len(pairs)): ``max_angle`` minus
    the link's angle to the axis (rad), then the links' distance minus the clearance."""
    pts = joint_points_many(mech, q, link_points)
    n = pts.shape[0]
    Rs = np.ascontiguousarray(R, dtype=float).reshape(n, 3, 3)
    out = np.empty((n, len(cones) + len(pairs)))
    if n and out.shape[1]:
        nb_link_margins(pts, len(link_points) // 2, Rs, np.array([c[3] for c in cones], dtype=np.int64),
                        np.array([c[0] for c in cones], dtype=float).reshape(-1, 3),
                        np.array([bool(c[1]) for c in cones], dtype=np.bool_).reshape(-1),
                        np.array([c[2] for c in cones], dtype=float).reshape(-1),
                        np.array([p[0] for p in pairs], dtype=np.int64), np.array([p[1] for p in pairs], dtype=np.int64),
                        np.array([p[2] for p in pairs], dtype=float).reshape(-1), out)
    return out
