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
"""

from __future__ import annotations

import numpy as np

from ...errors import ConvergenceError
from ...geometry.tolerances import current
from ...kinematics.closure import Configuration, active_mask
from ...kinematics.tracking import MotionProblem, conventional_sense
from ...model.mechanism import Mechanism

__all__ = ["EVENT_LOG_MAX", "MotionRates", "is_noise", "same_event"]

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
