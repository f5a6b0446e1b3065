"""Which single drivers keep control of a one-degree-of-freedom linkage, decided on the motion's
tangent space (scale-free), and the studio's event bookkeeping.

With common constraints (a planar or spherical four-bar, the Bennett linkage, a Sarrus linkage)
the complete Jacobian is not square: the limbs' constraint wrenches are more than the five a
one-degree-of-freedom platform needs, and the single-driver determinants ``DJ`` do not exist
(:func:`~spatialmech.kinematics.jacobian.driver_determinants` gives ``nan``).  Their signs
must not decide anything.  Instead:

* The closure Jacobian ``A`` (nondimensional: moments / L, slides / L) of every unlocked freedom
  has a one-dimensional null space along the motion (passive spins removed), spanned by the unit
  tangent ``t``.  The *reduced* Jacobian of driver ``d``, ``A`` without the column of ``d``, is
  of full column rank -- locking ``d`` holds the linkage, ``d`` drives it -- exactly where
  ``t_d != 0``.  :class:`MotionRates` gives ``t_d`` for every freedom: the driver's share of the
  motion, scale-free in ``[-1, 1]``.
* Its sign is the tangent's orientation, which an SVD chooses arbitrarily: the tangent is
  oriented by the documented convention (:func:`~spatialmech.kinematics.tracking.conventional_sense`)
  at the start and then by continuity (``t . t_previous > 0``), so a sign change of ``t_d`` along a
  drive is a dead point of ``d``, never a kernel's choice.  The readout shows ``|t_d|``.
* A sign change counts only when one side exceeds :attr:`Tolerances.singular` (a freedom whose
  rate is round-off on the whole path, e.g. a joint that does not move, has no events).
* A zero that falls exactly on a driven sample (planar-4r's B1.rot at 120 deg, driven in 10-deg
  steps) is counted once, by the drive that arrives there, whatever the kernel: there the rate
  is round-off (1e-16) of either sign, so neither "the drive that ends there crossed" nor "the
  next drive starts on the other side" may be decided by its sign.  A value below the noise
  level at the target is a zero reached (:meth:`DriverMonitors._sample_events`); a drive that
  starts on one is not a new event.
"""

from __future__ import annotations

from typing import cast

import numpy as np

from ...errors import ConvergenceError
from ...geometry.tolerances import current
from ...kinematics.closure import Configuration, active_mask
from ...kinematics.jacobian import complete_jacobian, driver_determinants
from ...kinematics.tracking import Event, MotionProblem, TrackResult, conventional_sense
from ...model.mechanism import Mechanism

__all__ = ["EVENT_LOG_MAX", "DriverMonitors", "MotionRates", "is_noise", "same_event"]

#: The most events the studio page keeps in its list (the oldest are dropped).
EVENT_LOG_MAX = 100


class MotionRates:
    """The rates of the unlocked freedoms of a one-degree-of-freedom ``mech`` along the unit
    tangent of its motion (nondimensional joint rates: rad, slides / L; the joint part of the
    tangent has norm 1)."""

    def __init__(self, mech: Mechanism):
        self.mech = mech
        self.problem = MotionProblem(mech)
        mask = active_mask(mech)
        self.ids = [r.id for r, a in zip(mech.freedom_refs, mask, strict=True) if a]
        self.index = {fid: k for k, fid in enumerate(self.ids)}
        self.na = int(mask.sum())

    def tangent(self, config: Configuration, ref: np.ndarray | None = None) -> np.ndarray:
        """The unit joint-rate tangent at ``config``: oriented as ``ref`` (the previous point's)
        when given, else by the documented convention (``sense_order``: the first actuator
        increasing, ...)."""
        try:
            t = np.asarray(self.problem.tangent(config), dtype=float)[: self.na]
        except ConvergenceError:  # rigid here (no tangent): every rate is zero
            return np.zeros(self.na)
        n = float(np.linalg.norm(t))
        if not n > 0:
            return np.zeros(self.na)
        t = t / n
        if ref is not None and ref.shape == t.shape and float(np.linalg.norm(ref)) > 0:
            return -t if float(t @ ref) < 0 else t
        return t * conventional_sense(t, [i for i in self.problem.sense_order if i < self.na])

    def rates(self, config: Configuration, names, ref: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``(rates of names, tangent)``: the oriented tangent's component on each freedom."""
        t = self.tangent(config, ref)
        return np.array([t[self.index[n]] if n in self.index else 0.0 for n in names]), t


def is_noise(before: float, after: float, scale: float = 1.0) -> bool:
    """A sign change between two values that are both round-off (below ``singular`` times
    ``scale``): not an event."""
    tol = current().singular * max(float(scale), 1e-300)
    return max(abs(float(before)), abs(float(after))) < tol


def same_event(a: dict | None, b: dict, mech: Mechanism) -> bool:
    """Whether event ``b`` is event ``a`` met again (same name and driver, the actuators at the
    same values: rad, or slides / L, within 1e-6): a drive repeated into the same stop."""
    if a is None or a.get("name") != b.get("name") or a.get("driver") != b.get("driver"):
        return False
    L = mech.characteristic_length
    for key, scale in (("actuators_deg", np.radians(1.0)), ("actuators_len", 1.0 / L)):
        va, vb = a.get(key, {}), b.get(key, {})
        if set(va) != set(vb):
            return False
        if any(abs(va[k] - vb[k]) * scale > 1e-6 for k in va):
            return False
    return True


class DriverMonitors:
    """The drivers' readouts and monitors of a studio session (a mixin of
    :class:`~spatialmech.services.studio.session.Session`, which sets ``mech`` and ``config``):
    DJ of the chosen drivers, each candidate driver's DJ or rate along the motion, and the
    vector monitor of a drive."""

    mech: Mechanism
    config: Configuration

    def _jacobian(self, c: Configuration):
        """The complete Jacobian at ``c``, remembered for the last configuration asked (a drive
        evaluates it at its end, and the readout that follows, and the next drive's start, at
        the same configuration object)."""
        last = getattr(self, "_last_jacobian", None)
        if last is not None and last[0] is c and last[2] is self.mech:  # the drivers are part of J
            return last[1]
        J = complete_jacobian(self.mech, c)
        self._last_jacobian = (c, J, self.mech)
        return J

    def _candidates(self) -> list[str]:
        """Single drivers whose DJ is watched (a one-degree-of-freedom model: every unlocked
        non-spherical freedom; otherwise none)."""
        if len(self.mech.actuators) != 1:
            return []
        refs = self.mech.freedom_refs
        out = []
        for r in refs:
            j = self.mech.limbs[r.limb].joints[r.joint]
            if not r.freedom.locked and j.type not in ("S", "U"):
                out.append(r.id)
        return out

    def _driver_dets(self, c: Configuration) -> dict[str, float]:
        """The single-driver determinants of every candidate driver and the chosen one at ``c``
        (one evaluation shared by the readout, the drive's stop test and its monitors; the last
        configuration asked is remembered)."""
        last = getattr(self, "_last_dets", None)
        if last is not None and last[0] is c and last[2] is self.mech:
            return last[1]
        names = list(dict.fromkeys([*self._candidates(), *self.mech.actuators]))
        vals = driver_determinants(self.mech, c, names)
        out = {d: float(v) for d, v in zip(names, vals, strict=True)}
        self._last_dets = (c, out, self.mech)
        return out

    def _dj(self, c: Configuration, J=None) -> float | None:
        """DJ of the chosen drivers: ``det`` of the complete Jacobian (one driver: the
        sign-continuous driver determinant); ``None`` where it is not square."""
        if len(self.mech.actuators) == 1:
            v = self._driver_dets(c)[self.mech.actuators[0]]
        else:
            d = (J if J is not None else self._jacobian(c)).det
            v = float("nan") if d is None else float(d)
        return v if np.isfinite(v) else None

    def _dj_by_driver(self, c: Configuration) -> dict[str, float]:
        cands = self._candidates()
        if not cands:
            return {}
        vals = self._driver_dets(c)
        if not all(np.isfinite(vals[d]) for d in cands):  # not square: each driver's |rate| on the motion
            return dict(zip(cands, np.abs(self._rates().rates(c, cands)[0]).tolist(), strict=True))
        return {d: vals[d] for d in cands}

    def _rates(self) -> MotionRates:
        """The motion's tangent-space rates of the current model (one-degree-of-freedom)."""
        r = getattr(self, "_motion_rates", None)
        if r is None or r.mech is not self.mech:
            r = self._motion_rates = MotionRates(self.mech)
        return r

    def _dj_readout(self, c: Configuration, J) -> dict:
        """``dj`` with ``dj_rate`` (one driver: its share of the motion, scale-free, 0 where it
        loses control) and ``dj_note``, the reason when ``dj`` has no value."""
        dj = self._dj(c, J)
        out: dict = {"dj": dj, "dj_rate": None, "dj_note": ""}
        if len(self.mech.actuators) == 1 and self._candidates():
            out["dj_rate"] = float(abs(self._rates().rates(c, self.mech.actuators)[0][0]))
        if dj is None:
            shape = " x ".join(map(str, J.matrix.shape))
            out["dj_note"] = (f"the complete Jacobian is {shape}, not square (common constraints): no determinant"
                              + ("; the driver's rate along the motion (dj_rate) decides where it loses control"
                                 if out["dj_rate"] is not None else "; sigma_min decides"))
        return out

    def _other_monitors(self, others: list[str], names: list[str], with_actuators) -> tuple:
        """The vector monitor of the other candidate drivers along a drive and the scale of its
        values, and whether they are rates: their DJ where the complete Jacobian is square (scale:
        the largest |DJ| at the start), else their rates along the motion's tangent, oriented by
        continuity (scale 1; see :mod:`.monitors`)."""
        if not others:
            return None, 1.0, False
        dets = self._driver_dets(self.config)
        if all(np.isfinite(dets[d]) for d in others):
            scale = max(abs(v) for v in dets.values() if np.isfinite(v))
            return (names, lambda x: [self._driver_dets(with_actuators(x))[d] for d in others]), scale, False
        rates = self._rates()
        ref = {"t": rates.tangent(self.config)}

        def vec(x):
            v, ref["t"] = rates.rates(with_actuators(x), others, ref["t"])
            return v
        return (names, vec), 1.0, True

    def _sample_events(self, r: TrackResult, names: list[str], scale: float, ell: float, vector,
                       end: Configuration | None) -> list[Event]:
        """The events of drive ``r`` (to ``lambda = ell``) counted as passed: the tracker's sign
        changes without round-off among the other drivers' monitors ``names`` (:func:`is_noise`
        with ``scale``), without those in the overshoot of the last step (beyond the target) and
        without a zero the drive starts on; with a zero reached exactly at the target ``end`` (the
        closed configuration at the requested values, ``None`` when it was not reached): once,
        at the target, whatever side the round-off puts it on."""
        tol = current().singular * max(float(scale), 1e-300)
        raw = [e for e in r.events if e.name not in names or not is_noise(e.value_before, e.value_after, scale)]
        raw = [e for e in raw if not (e.name in names and e.step == 0 and abs(e.value_before) < tol)]
        keep = [e for e in raw if float(cast(tuple, e.x)[1]) <= ell]
        if end is None or vector is None:
            return keep
        last = len(r.points) - 2  # the step that reached the target starts at this tracked point
        f_end = np.asarray(vector[1]((end, ell)), dtype=float)
        for k, n in enumerate(names):
            before = float(r.monitors[n][-2]) if len(r.points) >= 2 else 0.0
            if abs(f_end[k]) >= tol or abs(before) < tol:
                continue  # not at a zero, or round-off on the whole last step
            if any(e.name == n and e.step == last and float(cast(tuple, e.x)[1]) <= ell for e in raw):
                continue  # located before the target on this step: counted there
            keep.append(Event(n, float(r.s[-1]), (end, ell), last, before, 0.0, 0.0, (before, 0.0)))
        return keep
