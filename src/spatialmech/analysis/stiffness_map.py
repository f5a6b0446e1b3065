"""The softest stiffness over a workspace slice (docs/stiffness.md): for every pose of a grid
(:func:`.maps.map_poses`: positions at a fixed orientation, or orientations at a fixed position),
the limits checked (:func:`.workspace.pose_checker`), the inverse position solved and
:func:`.stiffness.stiffness` evaluated; one Python loop (a few ms per pose).

Statuses (:data:`STATUS`): ``ok``, ``singular`` (softest stiffness 0), ``outside_limits``,
``unreachable``; cells without a value hold NaN in the arrays and ``null`` in JSON.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..kinematics.position import inverse_position
from ..model.mechanism import Mechanism, Pose
from .maps import map_poses
from .stiffness import stiffness
from .workspace import WorkspaceLimits, default_limits, pose_checker

__all__ = ["STATUS", "StiffnessMap", "stiffness_map"]

#: Cell statuses, by code.
STATUS = ("ok", "singular", "outside_limits", "unreachable")
OK, SINGULAR, OUTSIDE, UNREACHABLE = range(4)
_ANGLES = ("alpha", "beta", "gamma")


@dataclass(frozen=True, eq=False)
class StiffnessMap:
    """The softest principal stiffness (force per length unit, nondimensional about the platform
    point: :mod:`.stiffness`) and its direction (a twist ``(dtheta ; dp)`` about the origin) at
    every cell of a grid; ``axes`` the free coordinates' values (SI, rad), ``fixed`` the others."""

    mechanism: str
    kind: str
    axes: dict
    fixed: dict
    softest: np.ndarray  # grid shape; NaN where no value, 0 where singular
    softest_twist: np.ndarray  # grid shape + (6,); NaN where no value
    status: np.ndarray  # grid shape, codes of STATUS
    violated: tuple  # flat, the limit a cell outside the limits violates ("" elsewhere)
    characteristic_length: float
    length_unit: str
    actuators: tuple
    defaulted: tuple  # actuators without a stiffness in the model (1 assumed)
    seconds: float

    @property
    def shape(self) -> tuple:
        return self.status.shape

    def status_counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.status == k)) for k, name in enumerate(STATUS)}

    def to_dict(self) -> dict:
        """JSON (docs/json.md, ``spatialmech stiffness --over ... --json``): axes and fixed
        coordinates with unit suffixes (angles in degrees), the softest stiffness and its twist per
        cell (``null`` where a cell has none), the minimum, the statuses."""
        def key(c: str) -> str:
            return f"{c}_deg" if c in _ANGLES else f"{c}_len"

        def conv(c: str, v):
            return np.degrees(v) if c in _ANGLES else v

        soft = np.empty(self.shape, dtype=object)
        twist = np.empty(self.shape, dtype=object)
        for idx in np.ndindex(self.shape):
            ok = bool(np.isfinite(self.softest[idx]))
            soft[idx] = float(self.softest[idx]) if ok else None
            twist[idx] = [float(x) + 0.0 for x in self.softest_twist[idx]] if ok else None
        low = self.minimum()
        return {
            "result": "stiffness_map", "kind": self.kind, "over": list(self.axes),
            "axes": {key(c): conv(c, a).tolist() for c, a in self.axes.items()},
            "fixed": {key(c): float(conv(c, v)) for c, v in self.fixed.items()},
            "euler_sequence": "ZYX", "orientation_convention": "R = Rz(gamma) Ry(beta) Rx(alpha)",
            "characteristic_length_len": self.characteristic_length, "actuators": list(self.actuators),
            "defaulted": list(self.defaulted), "n_grid": int(self.status.size), "seconds": self.seconds,
            "softest_N_per_len": soft.tolist(), "softest_twist": twist.tolist(),
            "minimum": None if low is None else {"softest_N_per_len": low[0],
                                                 "at": {key(c): float(conv(c, v)) for c, v in low[1].items()}},
            "status": np.array(STATUS, dtype=object)[self.status].tolist(), "status_counts": self.status_counts(),
            "violated": np.array(self.violated, dtype=object).reshape(self.shape).tolist(),
        }

    def minimum(self) -> tuple[float, dict] | None:
        """The smallest softest stiffness over the cells that have one and where it is (SI, rad)."""
        a = np.where(np.isfinite(self.softest), self.softest, np.inf)
        if not np.isfinite(a).any():
            return None
        idx = np.unravel_index(int(np.argmin(a)), a.shape)
        return float(a[idx]), {c: float(v[i]) for (c, v), i in zip(self.axes.items(), idx, strict=True)}


def stiffness_map(mech: Mechanism, *, kind: str = "position", over: Mapping, at: Mapping | None = None,
                  limits: WorkspaceLimits | None = None, drivers=None) -> StiffnessMap:
    """The softest stiffness over the grid ``over`` (1 to 3 coordinates to ``(lo, hi, n)`` or
    values; ``at``: the fixed ones), under ``limits`` (default: the model's)."""
    axes, fixed, R, p, shape = map_poses(mech, kind, over, at)
    checker = pose_checker(mech, default_limits(mech) if limits is None else limits)
    t0 = time.perf_counter()
    n = R.shape[0]
    soft, tw = np.full(n, np.nan), np.full((n, 6), np.nan)
    status = np.full(n, OK, dtype=np.int8)
    violated = [""] * n
    feasible = checker.feasible(R, p)
    defaulted: tuple = ()
    actuators: tuple = ()
    for i in range(n):
        if not feasible[i]:
            name = checker.violated(R[i : i + 1], p[i : i + 1])[0]
            status[i] = UNREACHABLE if name in ("closure", "") else OUTSIDE
            violated[i] = name or "closure"
            continue
        res = inverse_position(mech, Pose(R[i], p[i]))
        if not res.reachable or res.config is None:
            status[i], violated[i] = UNREACHABLE, "closure"
            continue
        s = stiffness(mech, res.config, drivers)
        soft[i], tw[i] = s.softest_stiffness, s.softest_twist
        status[i] = SINGULAR if s.singular else OK
        defaulted, actuators = s.defaulted, s.actuators
    seconds = time.perf_counter() - t0
    return StiffnessMap(mech.name, kind, axes, fixed, soft.reshape(shape), tw.reshape(*shape, 6), status.reshape(shape),
                        tuple(violated), mech.characteristic_length, mech.length_unit, actuators, defaulted, seconds)
