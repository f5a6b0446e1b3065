"""The public API: statics (``sm.statics``): the actuator efforts and joint reactions that hold a
mechanism against an external wrench on its output link (docs/statics.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analysis.statics import JointReaction, Statics
from ..analysis.statics import statics as _statics
from ..errors import InputError
from ..geometry.tolerances import current as current_tolerances
from ..kinematics.closure import Configuration
from ..kinematics.position import PoseFit, platform_pose
from ..model.mechanism import Mechanism, Pose
from ..serialize import pose_dict
from .checks import ModelLike, check_numbers, where

__all__ = ["StaticsResult", "statics"]

#: How the wrench of ``statics`` is written, in its JSON.
WRENCH_CONVENTION = ("(f ; m) applied to the output link, m the moment about the origin; efforts: the force (P) or "
                     "torque (R, H) each actuator exerts along its freedom; reactions: the wrench a joint's proximal body "
                     "exerts on its distal body, without the actuator efforts")


def _wrench_dict(w: np.ndarray) -> dict:
    return {"force_N": [float(v) + 0.0 for v in w[:3]], "moment_N_len": [float(v) + 0.0 for v in w[3:]]}


def _split(mech: Mechanism, values: dict[str, float]) -> dict[str, dict[str, float]]:
    """Efforts by kind: forces (prismatic freedoms) and torques (revolute, helical)."""
    forces = {a: float(v) for a, v in values.items() if mech.freedom(a).freedom.kind == "P"}
    torques = {a: float(v) for a, v in values.items() if mech.freedom(a).freedom.kind != "P"}
    return {"forces_N": forces, "torques_N_len": torques}


@dataclass(frozen=True, eq=False)
class StaticsResult:
    """The static equilibrium at one configuration (:func:`statics`).  Forces in the unit of the
    given wrench's force (N), torques and moments in that unit times the model's length unit."""

    mechanism: Mechanism
    config: Configuration
    wrench: np.ndarray  # (6,) external wrench on the output link, (f ; m about the origin)
    efforts: dict[str, float]  # actuator -> force (P) or torque (R, H) it exerts along its freedom
    reactions: tuple[JointReaction, ...]  # every joint of every limb
    residual: np.ndarray  # (6,) the part of ``wrench`` left unbalanced (zero when balanced)
    balanced: bool
    singular: bool
    redundant: bool
    indeterminate: bool
    sigma_min: float
    unbalanced_wrench: np.ndarray | None  # (6,) the wrench direction that cannot be balanced, when singular
    analysis: Statics  # the core result: constraint intensities, limb wrenches, the complete Jacobian
    pose_fit: PoseFit | None = None
    pose: Pose | None = None  # the requested pose (default: the configuration's)
    gravity: np.ndarray | None = None  # m/s^2, when the links' weights are balanced too
    masses: dict | None = None  # link -> LinkInertia used for the weights
    mass_source: dict | None = None  # link -> "file" | "density" | "none"

    @property
    def notes(self) -> tuple[str, ...]:
        return self.analysis.notes

    def to_dict(self) -> dict:
        """JSON (docs/json.md, ``spatialmech statics --json``): efforts split into ``forces_N`` and
        ``torques_N_len`` by actuator; wrenches as ``force_N`` and ``moment_N_len`` (about the
        origin); ``unbalanced_wrench`` a screw ``(f ; m)`` or ``None``."""
        mech, s = self.mechanism, self.analysis
        P = self.pose if self.pose is not None else platform_pose(mech, self.config)
        names = [limb.name for limb in mech.limbs]
        reactions = []
        for r in self.reactions:
            reactions.append({"limb": r.limb, "joint": r.joint, "point_len": [float(v) for v in r.point],
                              **_wrench_dict(r.wrench),
                              "moment_at_point_N_len": [float(v) + 0.0 for v in r.moment_at_point],
                              "efforts": _split(mech, r.efforts)})
        return {
            "result": "statics",
            "pose": pose_dict(P.R, P.p),
            "wrench_convention": WRENCH_CONVENTION,
            "wrench": _wrench_dict(self.wrench),
            "actuators": list(s.actuators),
            **_split(mech, self.efforts),
            "balanced": self.balanced,
            "singular": self.singular,
            "redundant": self.redundant,
            "indeterminate": self.indeterminate,
            "sigma_min": self.sigma_min,
            "singular_below": current_tolerances().singular,
            "inverse_singular": list(s.jacobian.inverse_singular),
            "unbalanced_wrench": None if self.unbalanced_wrench is None else [float(v) for v in self.unbalanced_wrench],
            "residual": _wrench_dict(self.residual),
            "constraints": [{"limb": names[k] if k >= 0 else None, "intensity_N": float(y), **_wrench_dict(w)}
                            for k, y, w in zip(s.constraint_limbs, s.constraint_intensities, s.constraint_wrenches,
                                               strict=True)],
            "limbs": [] if s.limb_wrenches is None else [{"limb": n, **_wrench_dict(w)}
                                                         for n, w in zip(names, s.limb_wrenches, strict=True)],
            "reactions": reactions,
            "notes": list(self.notes),
            "pose_fit": None if self.pose_fit is None else self.pose_fit.to_dict(),
            **({} if self.gravity is None else {
                "gravity_len_per_s2": [float(v) for v in self.gravity],
                "masses": [{"link": n, "source": (self.mass_source or {}).get(n, "file"), "mass_kg": float(li.mass_kg)}
                           for n, li in (self.masses or {}).items()]}),
        }


def statics(model: ModelLike, pose=None, *, wrench, config: Configuration | None = None, drivers=None,
            degrees: bool = False, gravity=None, density: float | None = None) -> StaticsResult:
    """Statics at a pose (fitted onto the closure), a configuration or the reference
    configuration: the force or torque of every actuator, and every joint's reaction, that hold the
    mechanism against an external ``wrench`` on its output link (massless links, no friction).

    Parameters
    ----------
    model : Mechanism, str or path
        A mechanism, a ready-made model name (``sm.models()``) or a TOML file.
    pose : Pose, tuple or int, optional
        The output link's pose (see :mod:`spatialmech.api`); default the reference configuration.
    wrench : sequence of 6 floats
        ``(fx, fy, fz, mx, my, mz)``: the force (N) and its moment about the origin (N times the
        model's length unit) that act on the output link (screw convention: direction first).
    config : Configuration, optional
        A configuration instead of a pose.
    drivers : str or sequence of str, optional
        The actuated freedoms (default: the model's actuators); more than the mechanism needs is
        redundant actuation.
    degrees : bool
        Read a pose tuple's Euler angles in degrees.
    gravity : sequence of 3 floats, optional
        m/s^2: also balance the links' weights (limbs from the ground to the output link; the
        model in metres).  The masses are the file's, or solid cylinders along the links of
        ``density`` (docs/dynamics.md); ``masses`` and ``mass_source`` say which.
    density : float, optional
        kg/m^3 for the links without masses in the file (with ``gravity``).

    Returns
    -------
    StaticsResult
        ``efforts`` by actuator (force for a prismatic, torque for a revolute freedom: the effort
        the actuator exerts along its freedom), the joint ``reactions``, and the flags:
        ``singular`` (least squares; ``unbalanced_wrench`` is the wrench that cannot be balanced,
        ``residual`` the part of ``wrench`` left over, ``balanced`` whether there is one),
        ``redundant`` (minimum-norm efforts), ``indeterminate`` (overconstrained: minimum-norm
        constraint intensities and reactions).  Virtual work: for every motion,
        ``sum(effort * actuator rate) = -(wrench . twist)`` (the reciprocal product).

    Raises
    ------
    TypeError
        A wrench that is not numbers, a wrong type of pose or model.
    InputError
        A wrench not of shape (6,) or with NaN or infinity; a pose with no closed configuration
        near it; an unknown or locked driver; a mechanism without actuators.

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.statics("stewart-6sps", wrench=[0, 0, -600, 0, 0, 0])     # 600 N down on the platform
    >>> [round(f, 3) for f in r.efforts.values()]                          # each leg pushes: 100 N / its cosine
    [112.802, 112.802, 112.802, 112.802, 112.802, 112.802]
    >>> r.singular, r.redundant, r.balanced
    (False, False, True)
    """
    w = where(model, pose, config, drivers, degrees)
    mech, c, fit, requested, drivers = w.mech, w.config, w.fit, w.pose, w.drivers
    F = check_numbers(wrench, "wrench", shape=(6,))
    g, loads, masses, source = None, None, None, None
    if gravity is not None:
        from ..analysis.dynamics import gravity_loads
        from .dynamics import masses_for

        g = check_numbers(gravity, "gravity", shape=(3,))
        masses, source = masses_for(mech, density)
        loads = gravity_loads(mech, c, masses, g)
    elif density is not None:
        raise InputError("density: only with gravity (the links' weights)")
    s = _statics(mech, c, F, drivers, loads)
    return StaticsResult(mech, c, F, s.by_actuator, s.reactions, s.residual, s.balanced, s.singular, s.redundant,
                         s.indeterminate, s.sigma_min, s.unbalanced_wrench, s, fit, requested, g, masses, source)
