"""The state of one design-studio session, without HTTP: a model, its current configuration, the
chosen drivers, and the operations the page asks for.

* :meth:`Session.drive` moves the actuators to new values by pseudo-arclength continuation along
  the current branch (:class:`~spatialmech.kinematics.tracking.ActuatorPathProblem`), never by
  a fresh Newton solve from somewhere else: the mechanism follows the assembly mode it is in.
  It stops, and says so, when the chosen drivers lose control (their DJ changes sign, or the
  path turns back in the actuator values: a dead point / direct singularity), when the tracker
  cannot make a step (a bifurcation or a branch crossing), or when closure fails.  Sign changes
  of DJ of the *other* candidate drivers are reported as events (the places where they could
  not drive), the configuration moves on.
* :meth:`Session.state` is the readout: actuator and joint values (degrees / length unit), the
  output pose, DJ of the chosen drivers, the scale-free sigma_min of the complete Jacobian
  with a near-singular flag (:data:`~spatialmech.geometry.tolerances.NEAR_SINGULAR`), and the
  geometry the page draws.
* :meth:`Session.set_drivers` switches the actuated freedoms (same count), :meth:`Session.fk_all`
  runs forward position at the current actuator values through the one dispatcher
  (:func:`~spatialmech.kinematics.dispatch.solve_forward`, as ``sm.fk(..., all_solutions=True)``
  and ``fk --all``: the same engine, the same modes), :meth:`Session.pick_mode` moves to one of
  the modes found (an explicit branch change).

Values in and out are in the model's units with rotations in degrees (the edge of the
library); inside, SI and radians.  Every method raises :class:`~spatialmech.errors.InputError`
naming the field on bad input.  Not thread-safe: the web app holds a lock around each call.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import cast

import numpy as np

from ... import catalog
from ...errors import ConvergenceError, InputError
from ...geometry.tolerances import NEAR_SINGULAR, current
from ...kinematics.closure import Configuration, active_mask
from ...kinematics.backend import closure_residual, correct
from ...kinematics.motion import generic_configuration
from ...kinematics.dispatch import AssemblyMode
from ...geometry.rotations import check_sequence
from ...kinematics.position import freedom_values, platform_pose, within_limits
from ...kinematics.task import default_task, task_values
from ...kinematics.tracking import ActuatorPathProblem, conventional_sense, track
from ...model.mechanism import Mechanism
from ...model.task import TASK_NAMES, TaskCoordinates
from ...results import DriveStatus, TrackStatus
from ...serialize import freedom_values_dict, pose_dict
from .modes import AssemblyModes
from .monitors import DriverMonitors, same_event
from .posing import pose_path, transmission_readout
from .design import Desk
from .scene import scene

__all__ = ["DriveResult", "Session"]

#: Drive statuses (the ``status`` field of ``POST /api/drive``): :class:`~spatialmech.results.DriveStatus`.
REACHED = DriveStatus.REACHED
STOPPED_SINGULAR = DriveStatus.STOPPED_SINGULAR
STOPPED_TRACKER = DriveStatus.STOPPED_TRACKER
UNCHANGED = DriveStatus.UNCHANGED
STOPPED_LIMIT = DriveStatus.STOPPED_LIMIT
LIMB_SINGULAR = DriveStatus.LIMB_SINGULAR
UNREACHABLE = DriveStatus.UNREACHABLE
#: The name of the event where a single driver's path turns back (a dead point).
DEAD_POINT = "dead point (drivers)"
DRIVE_STATUSES = tuple(DriveStatus)

#: Half-width of the slider ranges around the start values (where a freedom has no joint
#: limits; the limits are the range otherwise): rotations (degrees) and slides (in
#: characteristic lengths).  The pose sliders use the same half-widths around the start pose.
SLIDER_HALF_DEG = 360.0
SLIDER_HALF_L = 1.0
#: Largest number of tracker steps per drive (a drag is answered quickly or stops).
MAX_STEPS = 400


@dataclass(frozen=True)
class DriveResult:
    """What one drive did: ``status`` (one of :data:`DRIVE_STATUSES`), a sentence, the events
    met (DJ sign changes, in the order met), the tracker steps and the time taken."""

    status: DriveStatus
    message: str
    events: tuple[dict, ...] = ()
    steps: int = 0
    elapsed_s: float = 0.0
    requested: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"status": self.status, "message": self.message, "events": list(self.events),
                "tracker_steps": self.steps, "elapsed_s": self.elapsed_s, **self.requested}


def _is_rot(mech: Mechanism, fid: str) -> bool:
    return mech.freedom(fid).freedom.kind != "P"


class Session(AssemblyModes, DriverMonitors):
    """One studio session on ``model`` (a ready-made name, a TOML path or a Mechanism)."""

    def __init__(self, model="five-cs-3"):
        self.load(model)

    # ------------------------------------------------------------------ model and start
    def load(self, model) -> None:
        """Load ``model`` and place it at its reference configuration (or, when that one is
        singular, at a nearby generic one: the page says so in ``note``)."""
        if not isinstance(model, (str, Mechanism)) and not hasattr(model, "__fspath__"):
            raise InputError(f"model: expected a model name or a file path, got {type(model).__name__}")
        mech = catalog.resolve(model)
        if not mech.actuators:
            raise InputError(f"model: {mech.name} has no actuators to drive")
        if mech.is_metamorphic:
            raise InputError(f"model: {mech.name} is metamorphic; the studio drives one motion mode (export it "
                             "with 'spatialmech export MODEL FILE --mode M' and open the file)")
        self.base = mech
        self.mech = mech
        self.note = ""
        #: The modes of the last fk_all, each with its configuration (None: fitted when picked).
        self.fk_modes: list[tuple[AssemblyMode, Configuration | None]] = []
        self.fk_branch: object = object()  # a new object whenever the branch is changed on purpose
        self._circuit: dict = {}
        self.history: list[np.ndarray] = []  # platform-point path, for the page's trail
        self.last_stop: dict | None = None  # the event of the last stop at a singularity
        c = Configuration.reference(mech)
        L = mech.characteristic_length
        if float(np.linalg.norm(closure_residual(mech, c))) > 1e-8 * max(1.0, L) or self._sigma(c) < NEAR_SINGULAR:
            best, best_sigma, how = c, self._sigma(c), ""
            for seed in range(6):  # the most regular of a few nearby generic configurations
                for step in (0.3, 1.0):
                    try:
                        g = generic_configuration(mech, seed=seed, step=step, steps=3)
                    except ConvergenceError:
                        continue
                    sg = self._sigma(g)
                    if sg > best_sigma:
                        best, best_sigma, how = g, sg, f"seed {seed}, step {step}"
                if best_sigma >= 2 * NEAR_SINGULAR:
                    break
            if how:
                c = best
                self.note = ("the reference configuration is singular or open: started at a nearby, more regular "
                             f"configuration (random steps along the closure, {how})")
        self.config = c
        self.start_values = self.actuator_values()
        self.history = [self._platform_point(c)]
        self.driven = [self.start_values]  # the actuator values at the end of each drive (desk.path_csv)
        self.desk = Desk(self)  # snapshots, coupler curve, sweeps (design.py)
        self._tasks: dict[str, TaskCoordinates | None] = {}
        self.euler = mech.task.euler if mech.task is not None else "ZYX"
        self.start_task = task_values(mech, c.D, self.euler)

    def _sigma(self, c: Configuration) -> float:
        try:
            return float(self._jacobian(c).sigma_min)
        except InputError:
            return 0.0

    # ------------------------------------------------------------------ actuator values
    def actuator_values(self, config: Configuration | None = None) -> np.ndarray:
        """The current actuator values (SI, radians), in the order of ``mech.actuators``."""
        c = self.config if config is None else config
        vals = freedom_values(self.mech, c.q)
        ids = [r.id for r in self.mech.freedom_refs]
        return np.array([vals[ids.index(a)] for a in self.mech.actuators])

    def _display(self, values: np.ndarray) -> dict:
        return freedom_values_dict(self.mech, dict(zip(self.mech.actuators, values, strict=True)), "actuators")

    def parse_actuators(self, values, name: str = "actuators") -> np.ndarray:
        """Actuator values from the page (model units, degrees for rotations): a list in the
        order of ``drivers`` or a map by freedom name; SI / radians out."""
        acts = list(self.mech.actuators)
        if isinstance(values, dict):
            try:
                given = {self.mech.freedom(k).id: v for k, v in values.items()}
            except KeyError as e:
                raise InputError(f"{name}: {e.args[0] if e.args else e}") from None
            missing = [a for a in acts if a not in given]
            extra = sorted(set(given) - set(acts))
            if missing or extra:
                raise InputError(f"{name}: expected values for exactly {', '.join(acts)}"
                                 + (f"; missing {', '.join(missing)}" if missing else "")
                                 + (f"; not driven: {', '.join(extra)}" if extra else ""))
            values = [given[a] for a in acts]
        if not isinstance(values, (list, tuple)):
            raise InputError(f"{name}: expected a list of {len(acts)} numbers ({', '.join(acts)}), "
                             f"got {type(values).__name__}")
        if len(values) != len(acts):
            raise InputError(f"{name}: expected {len(acts)} values ({', '.join(acts)}), got {len(values)}")
        out = []
        for k, (a, v) in enumerate(zip(acts, values, strict=True)):
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
                raise InputError(f"{name}[{k}] ({a}): expected a finite number, got {v!r}")
            out.append(np.radians(v) if _is_rot(self.mech, a) else float(v))
        return np.array(out, dtype=float)

    # ------------------------------------------------------------------ readouts
    def state(self, solids: bool = True) -> dict:
        """The readout of the current configuration (JSON payload, docs/studio.md); ``solids``:
        with the joint solids in the scene (:meth:`scene`)."""
        m, c = self.mech, self.config
        a = self.actuator_values()
        J = self._jacobian(c)
        sig = float(J.sigma_min)
        pose = platform_pose(m, c)
        vals = freedom_values(m, c.q)
        joints = freedom_values_dict(m, {r.id: v for r, v in zip(m.freedom_refs, vals, strict=True)}, "joints")
        lo = {aid: self.slider_range(aid, v0, v) for aid, v0, v in
              zip(m.actuators, self.start_values if len(self.start_values) == len(a) else a, a, strict=True)}
        return {
            "mechanism": m.name,
            "drivers": list(m.actuators),
            "candidate_drivers": self._candidates(),
            **self._display(a),
            "slider_ranges_deg": {k: list(v) for k, v in lo.items() if _is_rot(m, k)},
            "slider_ranges_len": {k: list(v) for k, v in lo.items() if not _is_rot(m, k)},
            **joints,
            "pose": pose_dict(pose.R, pose.p),
            **self._dj_readout(c, J),
            "dj_by_driver": self._dj_by_driver(c),
            "sigma_min": sig,
            **transmission_readout(J),
            "singular": bool(sig < current().singular),
            "near_singular": bool(sig < NEAR_SINGULAR),
            "near_singular_below": NEAR_SINGULAR,
            "residual": float(np.linalg.norm(closure_residual(m, c))) / max(m.characteristic_length, 1e-300),
            "outside_limits": within_limits(m, c.q),
            "task": self.task_readout(),
            "note": self.note,
            "scene": self.scene(solids),
        }

    def slider_range(self, aid: str, start: float, value: float) -> tuple[float, float]:
        """The slider range of actuator ``aid`` (degrees / length unit): its joint limits where
        it has them (an angle's shifted by whole turns to hold ``value``), else a half-width
        around the start value ``start``."""
        f = self.mech.freedom(aid).freedom
        rot = f.kind != "P"
        if f.limits is not None:
            lo, hi = f.limits
            if rot:
                k = np.round((0.5 * (lo + hi) - value) / (2 * np.pi))
                lo, hi = lo - 2 * np.pi * k, hi - 2 * np.pi * k
                return float(np.degrees(lo)), float(np.degrees(hi))
            return float(lo), float(hi)
        start, value = float(start), float(value)
        if rot:
            return float(np.degrees(start)) - SLIDER_HALF_DEG, float(np.degrees(start)) + SLIDER_HALF_DEG
        h = SLIDER_HALF_L * self.mech.characteristic_length
        return start - h, start + h

    # ------------------------------------------------------------------ task coordinates (pose)
    def task(self, euler: str | None = None) -> TaskCoordinates | None:
        """The task coordinates the output is posed by (in Euler sequence ``euler``, default
        the session's): the model's own ``task`` or :func:`~spatialmech.kinematics.task.default_task`;
        ``None`` where the output link cannot move."""
        euler = self.euler if euler is None else euler
        if euler not in self._tasks:
            own = self.mech.task
            try:
                self._tasks[euler] = (TaskCoordinates(own.given, euler) if own is not None
                                      else default_task(self.mech, euler))
            except InputError:
                self._tasks[euler] = None
        return self._tasks[euler]

    def task_values(self, euler: str | None = None) -> np.ndarray:
        """The six task coordinates of the current configuration (length unit, rad), angles
        unwrapped to within half a turn of the start pose's."""
        euler = self.euler if euler is None else euler
        v = task_values(self.mech, self.config.D, euler)
        if euler == self.euler:
            v[3:] = self.start_task[3:] + (v[3:] - self.start_task[3:] + np.pi) % (2 * np.pi) - np.pi
        return v

    def task_readout(self) -> dict | None:
        """The pose as task coordinates (``values_len`` x, y, z; ``values_deg`` a1, a2, a3 in
        the named ``euler`` sequence), which are ``given`` (controlled: the pose sliders) and
        which ``solved``, and the pose slider ranges of the given ones."""
        t = self.task()
        if t is None:
            return None
        v, v0 = self.task_values(), self.start_task
        h = SLIDER_HALF_L * self.mech.characteristic_length
        return {"given": list(t.given), "solved": list(t.solved), "euler": t.euler,
                "values_len": {n: float(v[i]) for i, n in enumerate(TASK_NAMES[:3])},
                "values_deg": {n: float(np.degrees(v[i + 3])) for i, n in enumerate(TASK_NAMES[3:])},
                "slider_ranges_len": {n: [float(v0[i] - h), float(v0[i] + h)] for i, n in enumerate(TASK_NAMES[:3])
                                      if n in t.given},
                "slider_ranges_deg": {n: [float(np.degrees(v0[i + 3])) - 180.0, float(np.degrees(v0[i + 3])) + 180.0]
                                      for i, n in enumerate(TASK_NAMES[3:]) if n in t.given}}

    def scene(self, solids: bool = True) -> dict:
        """What the page draws (:func:`.scene.scene`; ``solids=False``: without the joint solids)."""
        return scene(self.mech, self.config, self.history, solids)

    def model_info(self) -> dict:
        """The model: name, description, limbs, freedoms with their kinds, the ready-made models."""
        m = self.mech
        return {
            "mechanism": m.name,
            "description": catalog.describe(m.name) if m.name in catalog.names() else "",
            "limb_names": [l.name for l in m.limbs],
            "freedoms": [{"name": r.id, "kind": r.freedom.kind, "locked": bool(r.freedom.locked)} for r in m.freedom_refs],
            "ready_made": list(catalog.names()),
            "task_positions": len(m.positions),
        }

    # ------------------------------------------------------------------ operations
    def set_drivers(self, drivers) -> None:
        """Drive with the freedoms ``drivers`` (names or aliases, as many as now)."""
        if not isinstance(drivers, (list, tuple)) or not all(isinstance(x, str) for x in drivers):
            raise InputError(f"drivers: expected a list of freedom names, got {drivers!r}")
        n = len(self.base.actuators)
        if len(drivers) != n:
            raise InputError(f"drivers: {self.base.name} is driven by {n} freedom(s), got {len(drivers)}")
        try:
            ids = [self.base.freedom(x).id for x in drivers]
        except KeyError as e:
            raise InputError(f"drivers: {e.args[0] if e.args else e}") from None
        if len(set(ids)) != len(ids):
            raise InputError(f"drivers: repeated freedom in {list(drivers)}")
        for i in ids:
            if self.base.freedom(i).freedom.locked:
                raise InputError(f"drivers: {i} is locked")
        self.mech = self.base.with_actuators(ids)
        self.start_values = self.actuator_values()
        self.driven = [self.start_values]

    def drive(self, values, *, name: str = "actuators") -> DriveResult:
        """Move the actuators to ``values`` (model units, degrees for rotations) along the
        current branch (see the module docstring)."""
        t_start = time.perf_counter()
        m = self.mech
        a1 = self.parse_actuators(values, name)
        a0 = self.actuator_values()
        requested = {f"requested_{k.split('_', 1)[1]}": v for k, v in self._display(a1).items()}
        L = m.characteristic_length
        rot = np.array([_is_rot(m, a) for a in m.actuators])
        delta = a1 - a0
        delta = np.where(rot, (delta + np.pi) % (2 * np.pi) - np.pi, delta)  # the short way round
        nd = np.where(rot, delta, delta / L)
        ell = float(np.linalg.norm(nd))
        if ell < 1e-12:
            return DriveResult(UNCHANGED, "already at these values", requested=requested,
                               elapsed_s=time.perf_counter() - t_start)
        self._check_limits(a0, a1, delta, name)
        prob = ActuatorPathProblem(m, lambda lam: a0 + (lam / ell) * delta, lambda lam: delta / ell)
        act_idx = [[r.id for r in m.freedom_refs].index(a) for a in m.actuators]
        offsets = np.array([m.freedom_refs[i].freedom.offset for i in act_idx])

        x0 = (self.config, 0.0)
        cfg_memo: dict = {"x": x0, "c": self.config}  # the start (its readouts are remembered)

        def with_actuators(x) -> Configuration:  # one configuration object per tracked point
            if cfg_memo.get("x") is x:
                return cfg_memo["c"]
            cfg, lam = x
            q = cfg.q.copy()
            q[act_idx] = a0 + (lam / ell) * delta - offsets
            cfg_memo["x"], cfg_memo["c"] = x, cfg.with_q(q)
            return cfg_memo["c"]

        own0 = self._dj(self.config)
        memo: dict = {"x": x0, "v": own0}  # the start's DJ is known: the tracker's first monitor call reuses it

        def own_dj(x) -> float | None:  # evaluated once per tracked point (monitor and stop share it)
            if memo.get("x") is not x:
                memo["x"], memo["v"] = x, self._dj(with_actuators(x))
            return memo["v"]

        cands = self._candidates()
        names = [f"DJ {d}" for d in cands if d not in m.actuators]
        others = [d for d in cands if d not in m.actuators]
        monitors = {}
        if own0 is not None:
            monitors["DJ (drivers)"] = lambda x: float(own_dj(x) or 0.0)
        vector, noise_scale, by_rate = self._other_monitors(others, names, with_actuators)
        why = {"reason": ""}
        lam_prev = [0.0]
        ref_t: dict = {}
        tan0 = prob.tangent(x0)
        tan0 = tan0 / max(float(np.linalg.norm(tan0)), 1e-300)
        # the sense of travel: lam increasing, by the documented convention when its rate is
        # negligible (a dead point), not by the sign the SVD returned (docs/conventions.md)
        tan0 = tan0 * conventional_sense(tan0, prob.sense_order)
        if len(m.actuators) == 1:
            # a dead point of a single driver: the path turns back in its value, where the rate of
            # the driver along the curve (the last component of the tangent, oriented as the last
            # accepted point's) goes through zero; its DJ need not vanish there (e.g. the rocker of
            # an RSSR: the passive limb loses a freedom, the rocker's own DJ stays constant)
            ref_t["t"] = tan0

            def oriented(x) -> np.ndarray:
                if ref_t.get("x") is x:
                    return ref_t["tx"]
                t = prob.tangent(x)
                t = t / max(float(np.linalg.norm(t)), 1e-300)
                t = -t if float(t @ ref_t["t"]) < 0 else t
                ref_t["x"], ref_t["tx"] = x, t
                return t

            monitors[DEAD_POINT] = lambda x: float(oriented(x)[-1])

        def stop(x, s) -> bool:
            if ref_t:
                ref_t["t"] = oriented(x)
            lam = float(x[1])
            if lam >= ell:
                why["reason"] = "reached"
                return True
            if lam < lam_prev[0] - 1e-12:
                why["reason"] = "turned"
                return True
            lam_prev[0] = lam
            if own0 is not None:
                v = own_dj(x)
                if v is not None and np.sign(v) != np.sign(own0) and v != 0:
                    why["reason"] = "dj"
                    return True
            return False

        # the first step's arc length reaches lam = ell along the start tangent (a small drag is one
        # step: the monitors are evaluated at one tracked point), at most 0.1 (the largest step)
        h = min(0.1, max(1.02 * ell / max(abs(float(tan0[-1])), 1e-3), 1e-6))
        r = track(prob, x0, h0=h, h_max=0.1,
                  max_arc=200.0 * ell + 2.0, max_steps=MAX_STEPS, monitors=monitors, vector_monitor=vector,
                  detect_closure=False, stop=stop)
        steps = len(r.points) - 1
        events = []
        step_of: dict[int, int] = {}  # event -> index of the tracked point its step starts from
        own_crossed = None
        res = self._close_at(r, a1, act_idx, offsets) if why["reason"] == "reached" else None
        for e in self._sample_events(r, names, noise_scale, ell, vector, res.config if res and res.converged else None):
            xe = cast(np.ndarray, e.x)  # the drag problem's points are (configuration, lambda)
            a_e = a0 + (float(xe[1]) / ell) * delta
            ev = {"name": e.name, "kind": str(e.kind), **self._display(a_e)}
            if e.name == DEAD_POINT:
                if str(e.kind) != "zero" or own_crossed is not None:
                    continue
                own_crossed = ev
                ev["driver"] = ", ".join(m.actuators)
                ev["meaning"] = ("the path turns back in the driver's value here: a dead point, where the driver "
                                 "loses control of the motion")
            elif e.name == "DJ (drivers)":
                own_crossed = ev
                ev["driver"] = ", ".join(m.actuators)
                ev["meaning"] = "the chosen drivers lose control here (DJ = 0): a dead point / direct singularity"
            else:
                ev["driver"] = e.name[3:]
                why_ = ("its rate along the motion passes zero: the reduced Jacobian without it is singular" if by_rate
                        else "its DJ changes sign")
                ev["meaning"] = f"{e.name[3:]} could not drive through this point ({why_})"
            events.append(ev)
            step_of[id(ev)] = e.step
        reason = why["reason"]
        elapsed = lambda: time.perf_counter() - t_start  # noqa: E731
        if res is not None:
            if res.converged:
                fin = self._dj(res.config)
                if own0 is not None and fin is not None and np.sign(fin) != np.sign(own0) and fin != 0:
                    reason = "dj"
                else:
                    self._accept(res.config, r.points[1:])
                    self.last_stop = None
                    return DriveResult(REACHED, "reached the requested values along the current branch",
                                       tuple(events), steps, elapsed(), requested)
            else:
                return self._stop_before(r, STOPPED_TRACKER, "closure failed at the requested values (residual "
                                         f"{res.residual:.2e}); stopped at the last closed configuration on the path",
                                         events, steps, elapsed, requested, with_actuators)
        if reason in ("dj", "turned") or own_crossed is not None:
            # the configuration stays before the last step: the other drivers' events on it are not passed
            events = [ev for ev in events if ev is own_crossed or step_of[id(ev)] < len(r.points) - 2]
            where = own_crossed or {}
            at = ", ".join(f"{k} = {v:.6g} deg" for k, v in where.get("actuators_deg", {}).items())
            at += ", ".join(f"{k} = {v:.6g} {m.length_unit}" for k, v in where.get("actuators_len", {}).items())
            what = ("the path turns back in the driver's value" if where.get("name") == DEAD_POINT
                    else "DJ of the drivers changes sign")
            msg = (f"the drivers lose control before the requested values ({what}"
                   + (f" at {at}" if at else "") + "): a dead point of this branch; stopped just before it "
                   "(drive back, or switch drivers to pass it)")
            if reason == "turned" and own_crossed is None:
                msg = ("the path turns back in the actuator values (a dead point / direct singularity) before the "
                       "requested values; stopped just before it (drive back, or switch drivers)")
            events, msg = self._once(own_crossed, events, msg)
            return self._stop_before(r, STOPPED_SINGULAR, msg, events, steps, elapsed, requested, with_actuators)
        if r.status == TrackStatus.MAX_ARC or steps >= MAX_STEPS:
            msg = (f"moved part of the way ({steps} steps): the mechanism moves fast for these actuator values (near a "
                   "singularity); drive again to go on")
        else:
            msg = f"the tracker stopped on this branch: {r.message}"
        return self._stop_before(r, STOPPED_TRACKER, msg, events, steps, elapsed,
                                 requested, with_actuators)

    def _close_at(self, r, a1: np.ndarray, act_idx: list[int], offsets: np.ndarray):
        """Closure at the requested actuator values ``a1`` from the last tracked point of ``r``."""
        m = self.mech
        last = r.points[-1][0]
        mask = active_mask(m)
        mask[act_idx] = False
        q = last.q.copy()
        q[act_idx] = a1 - offsets
        return correct(m, last.with_q(q), active=mask, max_iter=30)

    def parse_pose(self, task_len=None, task_deg=None, *, euler=None, relative=False) -> tuple[TaskCoordinates, np.ndarray]:
        """The task coordinates and the six target values (SI, rad) of a pose request:
        ``task_len`` (x, y, z in the model's length unit) and ``task_deg`` (a1, a2, a3 in
        degrees, Euler sequence ``euler``), each a map by coordinate name, absolute or (``relative``)
        increments; coordinates not named keep their current values."""
        if euler is not None:
            if not isinstance(euler, str):
                raise InputError(f"euler: expected a sequence name such as 'ZYX', got {euler!r}")
            try:
                check_sequence(euler)
            except InputError as e:
                raise InputError(f"euler: {e}") from None
        if not isinstance(relative, bool):
            raise InputError(f"relative: expected true or false, got {relative!r}")
        t = self.task(euler)
        if t is None:
            raise InputError(f"task_len: {self.mech.name}'s output link cannot move; there is no pose to drive")
        v = self.task_values(t.euler)
        target = v.copy()
        for fname, names, deg, given in (("task_len", TASK_NAMES[:3], False, task_len),
                                         ("task_deg", TASK_NAMES[3:], True, task_deg)):
            given = {} if given is None else given
            if not isinstance(given, dict):
                raise InputError(f"{fname}: expected a map of coordinate -> value ({', '.join(names)}), "
                                 f"got {type(given).__name__}")
            for n, x in given.items():
                if n not in names:
                    other = "task_deg" if n in TASK_NAMES[3:] else "task_len" if n in TASK_NAMES else ""
                    raise InputError(f"{fname}.{n}: unknown coordinate; expected one of {', '.join(names)}"
                                     + (f" (give {n} in {other})" if other else ""))
                if n not in t.given:
                    raise InputError(f"{fname}.{n}: {self.mech.name} controls only {', '.join(t.given)} (Euler sequence "
                                     f"{t.euler}); {n} is solved (parasitic motion) and cannot be requested")
                if isinstance(x, bool) or not isinstance(x, (int, float)) or not np.isfinite(x):
                    raise InputError(f"{fname}.{n}: expected a finite number, got {x!r}")
                i = TASK_NAMES.index(n)
                val = np.radians(x) if deg else float(x)
                target[i] = v[i] + val if relative else val
        return t, target

    def drive_pose(self, task_len=None, task_deg=None, *, euler=None, relative=False) -> DriveResult:
        """Move the output link to a pose given by its task coordinates (see
        :meth:`parse_pose` and :mod:`.posing`) along the current branch."""
        t_start = time.perf_counter()
        t, target = self.parse_pose(task_len, task_deg, euler=euler, relative=relative)
        gi = [TASK_NAMES.index(n) for n in t.given]
        requested = {"requested_task_len": {n: float(target[i]) for i, n in enumerate(TASK_NAMES[:3]) if n in t.given},
                     "requested_task_deg": {n: float(np.degrees(target[i + 3])) for i, n in enumerate(TASK_NAMES[3:])
                                            if n in t.given}}
        v = self.task_values(t.euler)
        L = self.mech.characteristic_length
        d = target[gi] - v[gi]
        scale = np.array([L if i < 3 else 1.0 for i in gi])
        if float(np.linalg.norm(d / scale)) < 1e-12:
            return DriveResult(UNCHANGED, "already at this pose", requested=requested,
                               elapsed_s=time.perf_counter() - t_start)
        r = pose_path(self.mech, self.config, t, target, self._dj)
        events = []
        if r.event is not None:
            ev_cfg = r.event["config"]
            events.append({"name": "DJ (drivers)", "kind": "zero", "driver": ", ".join(self.mech.actuators),
                           "meaning": "the chosen drivers lose control here (DJ = 0): a direct singularity",
                           **self._display(self.actuator_values(ev_cfg)),
                           "task_len": {n: float(r.event["values"][i]) for i, n in enumerate(TASK_NAMES[:3])},
                           "task_deg": {n: float(np.degrees(r.event["values"][i + 3])) for i, n in enumerate(TASK_NAMES[3:])}})
        if r.passed:
            self._accept(r.config, [(c, None) for c in r.passed])
        events, msg = self._once(events[0] if events else None, events, r.message)
        return DriveResult(r.status, msg, tuple(events), r.steps, time.perf_counter() - t_start, requested)

    def drag_output(self, point_len) -> DriveResult:
        """The drag handle of the page's 3-D view: move the output point toward ``point_len``
        (x, y, z in the model's length unit) along the current branch.  The translational task
        coordinates the mechanism controls (``state.task.given`` among x, y, z) take the point's
        values, the others keep theirs (a planar 4-bar controls x only: its coupler point
        follows x); then as :meth:`drive_pose`."""
        if (not isinstance(point_len, (list, tuple)) or len(point_len) != 3
                or any(isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v) for v in point_len)):
            raise InputError(f"point_len: expected three finite numbers x, y, z ({self.mech.length_unit}), got {point_len!r}")
        t = self.task()
        given = [n for n in TASK_NAMES[:3] if t is not None and n in t.given]
        if not given:
            raise InputError(f"point_len: {self.mech.name} does not control the output point's position "
                             f"(given: {', '.join(t.given) if t is not None else 'none'}); use the pose sliders")
        return self.drive_pose({n: float(point_len[TASK_NAMES.index(n)]) for n in given})

    def _once(self, stop_event: dict | None, events: list, msg: str) -> tuple[list, str]:
        """Drop the event of a stop that repeats the last one (the same place, met again by a
        drive further on: the page logs it once) and remember it."""
        if stop_event is not None and same_event(self.last_stop, stop_event, self.mech):
            events = [ev for ev in events if ev is not stop_event]
            msg += " (the same stop as before; its event is not repeated)"
        self.last_stop = stop_event
        return events, msg

    def _check_limits(self, a0: np.ndarray, a1: np.ndarray, delta: np.ndarray, name: str) -> None:
        """Refuse a drive whose path (the target and points on the way) leaves an actuator's
        joint limits."""
        m = self.mech
        act_idx = [[r.id for r in m.freedom_refs].index(a) for a in m.actuators]
        if all(m.freedom_refs[i].freedom.limits is None for i in act_idx):
            return
        offsets = np.array([m.freedom_refs[i].freedom.offset for i in act_idx])
        for lam in np.linspace(0.0, 1.0, 33)[1:]:
            q = self.config.q.copy()
            q[act_idx] = a0 + lam * delta - offsets
            bad = within_limits(m, q, act_idx)
            if bad:
                f = m.freedom(bad[0]).freedom
                assert f.limits is not None  # within_limits names only freedoms with limits
                lo, hi = f.limits
                shown = (f"[{np.degrees(lo):.6g}, {np.degrees(hi):.6g}] deg" if f.kind != "P"
                         else f"[{lo:.6g}, {hi:.6g}] {m.length_unit}")
                where = "the requested value is" if lam == 1.0 else "the way there is"
                raise InputError(f"{name}: {where} outside the joint limits of {bad[0]} {shown}")

    def _stop_before(self, r, status, msg, events, steps, elapsed, requested, with_actuators) -> DriveResult:
        """Keep the last tracked point before the step that crossed (still on the branch)."""
        pts = r.points
        k = len(pts) - 2 if status == STOPPED_SINGULAR and len(pts) >= 2 else len(pts) - 1
        if k > 0:
            self._accept(with_actuators(pts[k]), pts[1 : k + 1])
        return DriveResult(status, msg, tuple(events), steps, elapsed(), requested)

    def _accept(self, config: Configuration, passed) -> None:
        self.config = config
        self.history.extend(self._platform_point(p[0]) for p in passed[-20:])
        self.history.append(self._platform_point(config))
        del self.history[:-400]
        self.driven.append(self.actuator_values(config))
