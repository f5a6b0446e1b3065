"""The circuit of a one-degree-of-freedom linkage through a configuration, followed by the
continuation tracker (:mod:`spatialmech.kinematics.tracking`) and subsampled to a number of
frames, with its branch points (the zeros of DJ of the first actuator,
:func:`spatialmech.analysis.defects.dj_function`): what ``spatialmech view --motion trace``
animates.  Numerics only; the viewer (:mod:`spatialmech.present.viewer`) draws the result.
"""

from __future__ import annotations

import numpy as np

from ..errors import ConvergenceError
from ..kinematics.closure import Configuration
from ..kinematics.tracking import trace_motion
from ..model.mechanism import Mechanism
from .defects import dj_function

__all__ = ["traced_motion"]


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
