"""The circuit of a one-degree-of-freedom linkage through a configuration, followed by the
continuation tracker (:mod:`spatialmech.kinematics.tracking`) and subsampled to a number of
frames, with its branch points (the zeros of DJ of the first actuator,
:func:`spatialmech.analysis.defects.dj_function`): what ``spatialmech view --motion trace``
animates.  Numerics only; the viewer (:mod:`spatialmech.present.viewer`) draws the result.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ConvergenceError
from ..kinematics.closure import Configuration
from ..kinematics.tracking import trace_motion
from ..model.mechanism import Mechanism
from .defects import dj_function

__all__ = ["TracedMotion", "traced_motion", "traced_part"]


@dataclass(frozen=True)
class TracedMotion:
    """A traced motion: ``configs`` (subsampled frames), ``singular`` (the configurations where
    DJ of the first actuator vanishes), ``stops`` (the configurations where the tracker could not
    go on: a bifurcation or a crossing branch; empty when the circuit closed) and ``note`` (why
    it stopped, empty when it closed)."""

    configs: list
    singular: tuple
    stops: tuple = ()
    note: str = ""


def traced_motion(mech: Mechanism, *, frames: int = 60, start: Configuration | None = None):
    """The circuit of a one-degree-of-freedom mechanism through ``start`` (default: the reference),
    followed by the continuation tracker and subsampled to ``frames`` configurations, with the
    platform points where DJ of the first actuator vanishes (its branch points).

    Raises ``RuntimeError`` when the tracker cannot follow the motion."""
    start = start if start is not None else Configuration.reference(mech)
    acts = list(mech.actuators[:1])
    mon = None
    if acts:
        f, _ = dj_function(mech, acts, start)
        mon = (acts, f)
    tr = trace_motion(mech, start, increasing=acts[0] if acts else None, vector_monitor=mon, max_arc=400)
    if not tr.ok:
        raise ConvergenceError(f"the tracker stopped: {tr.message}")
    idx = np.unique(np.linspace(0, len(tr.points) - 1, min(frames, len(tr.points))).round().astype(int))
    configs = [tr.points[i] for i in idx]
    sing = tuple(e.x for e in tr.events if e.kind == "zero")
    return configs, sing


def _frames(points: list, frames: int) -> list:
    idx = np.unique(np.linspace(0, len(points) - 1, min(frames, len(points))).round().astype(int))
    return [points[i] for i in idx]


def traced_part(mech: Mechanism, *, frames: int = 60, start: Configuration | None = None) -> TracedMotion:
    """Like :func:`traced_motion`, but a tracker that stops (at a bifurcation point or a crossing
    branch: a Sarrus linkage folded flat) does not lose what it traced: the motion is followed
    from ``start`` in both senses, up to the stop in each, and the stops are returned as points to
    mark.  Raises :class:`~spatialmech.errors.ConvergenceError` only when neither sense got off
    the start."""
    start = start if start is not None else Configuration.reference(mech)
    acts = list(mech.actuators[:1])
    mon = (acts, dj_function(mech, acts, start)[0]) if acts else None
    first = acts[0] if acts else None
    fwd = trace_motion(mech, start, increasing=first, vector_monitor=mon, max_arc=400)
    if fwd.ok:
        return TracedMotion(_frames(fwd.points, frames), tuple(e.x for e in fwd.events if e.kind == "zero"))
    back = trace_motion(mech, start, increasing=first, sense=-1, vector_monitor=mon, max_arc=400)
    parts = [t for t in (back, fwd) if len(t.points) > 1]
    if not parts:
        raise ConvergenceError(f"the tracker stopped at the start: {fwd.message}")
    points = list(reversed(back.points[1:])) + list(fwd.points) if len(back.points) > 1 else list(fwd.points)
    stops = tuple(t.points[-1] for t in (back, fwd) if not t.ok and len(t.points) > 1)
    sing = tuple(e.x for t in (back, fwd) for e in t.events if e.kind == "zero")
    why = "; ".join(dict.fromkeys(t.message for t in (back, fwd) if not t.ok))
    note = (f"traced {len(points)} configurations between {len(stops)} stop(s) of the tracker ({why}); "
            "the stops are marked")
    return TracedMotion(_frames(points, frames), sing, stops, note)
