"""Which loop :func:`.tracking.track` runs: the compiled one (:mod:`.compiled.kernels_trace`,
through :class:`.compiled.trace.TraceLoop`) for a mechanism's motion with its drivers' DJ as the
vector monitor (:class:`DriverMonitor`), else its Python loop (the reference), which
:func:`python_loop` also selects for a block of work."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

import numpy as np

from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism
from . import backend
from .jacobian import driver_determinants

__all__ = ["DriverMonitor", "compiled_loop", "compiled_loops", "python_loop", "run_compiled"]

_PYTHON_LOOP: ContextVar[bool] = ContextVar("spatialmech_python_loop", default=False)


@contextmanager
def python_loop() -> Iterator[None]:
    """Inside the block :func:`.tracking.track` makes every step in its Python loop (the
    reference), even where the compiled loop applies (a mechanism's motion with its drivers' DJ
    as the monitor), and the searches along a traced curve (:func:`compiled_loops`) run in
    Python too."""
    token = _PYTHON_LOOP.set(True)
    try:
        yield
    finally:
        _PYTHON_LOOP.reset(token)


def compiled_loops():
    """The compiled engine for the loops that :func:`python_loop` switches (the tracker's loop,
    the searches along a traced curve), or ``None``: inside :func:`python_loop`, or where the
    Python reference runs (:func:`.backend.python_reference`)."""
    return None if _PYTHON_LOOP.get() else backend.engine()


class DriverMonitor:
    """The vector monitor ``config -> DJ of each driver`` (:func:`.jacobian.driver_determinants`)
    of ``mech``: the one the compiled tracker loop evaluates itself."""

    def __init__(self, mech: Mechanism, drivers) -> None:
        self.mech = mech
        self.drivers = list(drivers)

    def __call__(self, config) -> np.ndarray:
        return driver_determinants(self.mech, config, self.drivers)


def compiled_loop(problem, vector_monitor, n_monitors: int, cfg):
    """The compiled loop (:class:`.compiled.trace.TraceLoop`) of a track with the settings
    ``cfg`` (``tracking._Settings``) when it applies: a motion problem that allows it
    (``compiled_loop``, with the compiled step test: ``null_tangent``) with a
    :class:`DriverMonitor` of its mechanism as its only monitors, the compiled engine in use, no
    ``stop`` or ``progress`` callback, outside :func:`python_loop`; else ``None``."""
    if (vector_monitor is None or not isinstance(vector_monitor[1], DriverMonitor)
            or not (getattr(problem, "compiled_loop", False) and getattr(problem, "null_tangent", False))
            or n_monitors != len(vector_monitor[0])
            or cfg.stop is not None or cfg.progress is not None or (fast := compiled_loops()) is None):
        return None
    mon = vector_monitor[1]
    if mon.mech is not problem.mech or not fast.TraceLoop.applies(problem.mech, problem.active, len(cfg.t0)):
        return None
    settings = (cfg.h0, cfg.h_min, cfg.h_max, cfg.max_arc, cfg.tol, cfg.cos_max, cfg.event_tol,
                1.0 if cfg.detect_closure else 0.0, float(cfg.max_steps))
    return fast.TraceLoop(problem.mech, problem.active, problem.row, problem.col, problem.kinds != "P", mon.drivers,
                          cfg.x0, cfg.t0, settings, current_tolerances().rank)


def run_compiled(loop, w, cfg, names: list[str], event_type) -> bool:
    """The compiled loop from the walk ``w`` (``tracking._Walk``); True when the track ended in it
    (``w``'s outcome set), False when it hands the next step to the Python loop."""
    code = loop.run(w, names, event_type)
    if code == loop.PYTHON_STEP:
        return False
    if code == loop.H_MIN:
        w.fail_h_min(cfg)
    elif code == loop.CLOSED:
        w.close(w.s, cfg.event_tol)
    return True
