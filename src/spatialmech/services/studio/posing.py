"""Moving the studio's output link by its pose (inverse position), along the current branch.

The output link is posed by its **task coordinates** (:mod:`spatialmech.model.task`): ``x, y, z``
of its reference point (the model's length unit) and ``a1, a2, a3``, Euler angles in a named
sequence (degrees at the edge).  A mechanism with ``M < 6`` output freedoms is posed by its
``M`` *given* coordinates only (:func:`~spatialmech.kinematics.task.default_task`); the others
are solved (its parasitic motion) and cannot be requested.

:func:`pose_path` moves the given coordinates along the straight path from their current values
to the requested ones (angles the short way round) by natural-parameter continuation: small
steps of the path parameter, each corrected by :func:`~spatialmech.kinematics.task.solve_task`
(Gauss-Newton holding the given coordinates) from the previous configuration.  A step is kept
only if its Newton converges and no joint moves by more than :data:`MAX_JOINT_STEP` (radians, or
characteristic lengths for slides); otherwise it is halved.  So the configuration never jumps
to another branch; where the steps cannot go on (below :data:`MIN_STEP`) the path has reached
the edge of this branch's workspace: a limb at an inverse singularity (its actuation
transmission near zero: ``limb_singular``) or no closure beyond (``unreachable``).  A sign
change of the chosen drivers' DJ (a direct singularity: the actuators lose control of the
output there) is located by bisection, reported as an event, and the motion stops just before
it (``stopped_at_singularity``); a joint (actuated or passive) leaving its limits stops it
before the step (``stopped_at_limit``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...geometry.tolerances import INVERSE_SINGULAR, NEAR_INVERSE_SINGULAR
from ...kinematics.closure import Configuration
from ...kinematics.jacobian import complete_jacobian
from ...kinematics.position import within_limits
from ...kinematics.task import TaskPath, joint_change
from ...model.mechanism import Mechanism
from ...model.task import TASK_NAMES, TaskCoordinates
from ...results import DriveStatus

__all__ = ["MAX_JOINT_STEP", "MIN_STEP", "PosePath", "pose_path", "transmission_readout"]

#: Largest change of any joint in one continuation step (rad; slides in characteristic lengths).
MAX_JOINT_STEP = 0.15
#: Smallest step of the path parameter (the path's length in rad / characteristic lengths).
MIN_STEP = 1e-5
#: First and largest step of the path parameter.
MAX_STEP = 0.05
#: Largest number of continuation steps per request.
MAX_STEPS = 400
#: Actuation transmission below which a limb is called singular where the steps stop.
LIMB_SINGULAR_TRANSMISSION = INVERSE_SINGULAR


@dataclass
class PosePath:
    """The outcome of :func:`pose_path`: ``status``, a sentence, the last configuration reached
    (on the branch), the configurations passed, the DJ event (if any: path parameter and the six
    task values there) and the number of steps."""

    status: DriveStatus
    message: str
    config: Configuration
    passed: list = field(default_factory=list)
    event: dict | None = None
    steps: int = 0


def pose_path(mech: Mechanism, start: Configuration, task: TaskCoordinates, target: np.ndarray,
              dj: Callable[[Configuration], float | None]) -> PosePath:
    """Move the given coordinates of ``task`` from their values at ``start`` to those of
    ``target`` (six task values, SI / rad; the solved ones are ignored); ``dj`` is the chosen
    drivers' DJ (its sign is watched).  The steps are a walk along a
    :class:`~spatialmech.kinematics.task.TaskPath` (as ``continue_task``); see the module
    docstring."""
    target = np.asarray(target, dtype=float)
    path = TaskPath(mech, {n: float(target[TASK_NAMES.index(n)]) for n in task.given}, task=task, start=start)
    ell = path.length
    outside0 = set(within_limits(mech, start.q))  # already outside at the start: not watched

    def at(s: float, seed: Configuration) -> Configuration | None:
        r = path.at(s, seed)
        if not r.converged or joint_change(mech, seed, r.config) > MAX_JOINT_STEP:
            return None
        return r.config

    own0 = dj(start)
    cur, s_cur = start, 0.0
    passed: list[Configuration] = []
    walk = path.walk(step=MAX_STEP, min_step=MIN_STEP * max(1.0, ell), max_steps=MAX_STEPS,
                     max_joint_step=MAX_JOINT_STEP)
    for s, sol in walk:
        nxt = sol.config
        bad = [b for b in within_limits(mech, nxt.q) if b not in outside0]
        if bad:
            lims = ", ".join(f"{b} {_show_limits(mech, b)}" for b in bad)
            return PosePath(DriveStatus.STOPPED_LIMIT, f"joints leave their limits ({lims}) before the requested pose; stopped "
                            "just before", cur, passed, steps=path.steps)
        d1 = dj(nxt)
        if own0 is not None and d1 is not None and d1 != 0 and np.sign(d1) != np.sign(own0):
            lo, hi, c_lo = s_cur, s, cur
            for _ in range(20):  # locate the DJ zero by bisection of the path parameter
                mid = 0.5 * (lo + hi)
                c_mid = at(mid, c_lo)
                if c_mid is None:
                    break
                dm = dj(c_mid)
                if dm is not None and dm != 0 and np.sign(dm) != np.sign(own0):
                    hi = mid
                else:
                    lo, c_lo = mid, c_mid
            event = {"lambda": 0.5 * (lo + hi), "values": path.values(0.5 * (lo + hi)), "config": c_lo}
            return PosePath(DriveStatus.STOPPED_SINGULAR, "the chosen drivers lose control before the requested pose (DJ of "
                            "the drivers changes sign: a direct singularity); stopped just before it (move back, or "
                            "switch drivers)", cur, passed, event=event, steps=path.steps)
        cur, s_cur = nxt, s
        passed.append(cur)
    if path.status == "max_steps":
        return PosePath(DriveStatus.STOPPED_TRACKER, f"moved part of the way ({path.steps} steps); request again to go on", cur,
                        passed, steps=path.steps)
    if path.status == "stalled":
        return _edge(mech, cur, passed, path.steps)
    return PosePath(DriveStatus.REACHED, "reached the requested pose along the current branch", cur, passed,
                    steps=path.steps)


def _show_limits(mech: Mechanism, fid: str) -> str:
    f = mech.freedom(fid).freedom
    assert f.limits is not None  # called for the freedoms within_limits names: they have limits
    lo, hi = f.limits
    if f.kind == "P":
        return f"[{lo:.6g}, {hi:.6g}] {mech.length_unit}"
    return f"[{np.degrees(lo):.6g}, {np.degrees(hi):.6g}] deg"


def _edge(mech: Mechanism, cur: Configuration, passed: list, steps: int) -> PosePath:
    """The steps cannot go on from ``cur``: a limb singular there, or no closure beyond."""
    try:
        J = complete_jacobian(mech, cur)
        trans = dict(zip(J.actuators, J.transmission, strict=True)) if J.transmission else {}
        weak = sorted((t, a) for a, t in trans.items() if t < LIMB_SINGULAR_TRANSMISSION)
        weak = [(0.0, a) for a in J.inverse_singular] + weak
    except (InputError, np.linalg.LinAlgError):  # a degenerate Jacobian at the edge: report the edge without it
        weak = []
    if weak:
        t, a = weak[0]
        limb = mech.limbs[mech.freedom(a).limb].name
        return PosePath(DriveStatus.LIMB_SINGULAR, f"limb {limb} reaches an inverse singularity (actuator {a}, transmission "
                        f"{t:.2g}): the edge of the workspace of this branch; stopped there", cur, passed, steps=steps)
    return PosePath(DriveStatus.UNREACHABLE, "the requested pose is not reachable along this branch (no closed configuration "
                    "beyond this one); stopped at the last reachable pose", cur, passed, steps=steps)


def transmission_readout(J) -> dict:
    """The inverse (transmission) light of the studio beside the direct one (``sigma_min``):
    each actuator's transmission index ``|W.$a| / (|W| |$a|)`` of the complete Jacobian ``J``
    (0 where the actuation wrench does not exist: an inverse singularity), the smallest, which
    actuator it is, and the colour class: ``inverse_singular`` below :data:`INVERSE_SINGULAR`
    (the level where a pose drag reports ``limb_singular``), ``near_inverse_singular`` below
    :data:`NEAR_INVERSE_SINGULAR`."""
    trans = dict.fromkeys(J.inverse_singular, 0.0)
    trans.update((a, float(t)) for a, t in zip(J.actuators, J.transmission or (), strict=False) if a not in trans)
    worst = min(trans.items(), key=lambda kv: kv[1]) if trans else (None, None)
    low = worst[1] if worst[1] is not None else 1.0
    return {"transmission": trans, "transmission_min": worst[1], "transmission_min_actuator": worst[0],
            "inverse_singular": bool(low < INVERSE_SINGULAR), "near_inverse_singular": bool(low < NEAR_INVERSE_SINGULAR),
            "near_inverse_singular_below": NEAR_INVERSE_SINGULAR, "inverse_singular_below": INVERSE_SINGULAR}
