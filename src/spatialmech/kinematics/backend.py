"""The front of the closure engine: which backend runs, and the entry points callers use.

Two backends compute the same things, with the same steps, tolerances and statuses (the results
agree to rounding; ``tests/test_compiled.py`` compares both on every ready-made model):

- the **Python reference**: :mod:`.closure` (closure, Newton), :mod:`.leg_platform` (six S-P-S
  legs in pose coordinates) and the NumPy paths of :mod:`.tracking`, :mod:`.position`,
  :mod:`.jacobian` and :mod:`.homotopy`; it never imports the compiled package;
- the **compiled engine**, :mod:`spatialmech.kinematics.compiled` (numba), which builds on the
  reference's data types; this module imports it on first use (:func:`enabled`), never at import.

This module is the only place that picks one.  Callers take the closure's entry points from here
(:func:`correct`, :func:`closure_residual`, :func:`closure_jacobian`, :func:`retract`,
:func:`joint_twists`); a module with its own reference path asks :func:`engine`::

    if (fast := backend.engine()) is not None:
        return fast.limb_gn(...)
    ...  # the Python reference

**The switch** is a :class:`contextvars.ContextVar` (as :func:`..geometry.tolerances.use`):
its default is ``SPATIALMECH_PURE`` as it was when this module was imported (set and not ``0``:
the Python reference), and :func:`python_reference` sets it for a block (a test or a benchmark
runs both paths in one process).  The process environment is never changed: a subprocess
started inside the block reads its own ``SPATIALMECH_PURE``.  Without numba the reference runs,
with one ``RuntimeWarning``.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from types import ModuleType

import numpy as np

from ..errors import InputError
from ..model.mechanism import Mechanism
from . import closure, leg_platform
from .closure import Configuration, CorrectionResult

__all__ = [
    "PURE_ENV",
    "closure_jacobian",
    "closure_residual",
    "correct",
    "enabled",
    "engine",
    "joint_twists",
    "python_reference",
    "retract",
    "use_python_reference",
]

#: Set this environment variable to ``1`` to run the pure-Python engine (the reference).
PURE_ENV = "SPATIALMECH_PURE"


def _env_pure() -> bool:
    pure = os.environ.get(PURE_ENV)
    return bool(pure and pure.strip() not in ("", "0"))


#: True: the Python reference runs.  Read on every solve (a ContextVar lookup, ~50 ns), set by
#: :func:`python_reference`; its default is the environment at import.
_ENV_PURE: bool = _env_pure()
_PURE: ContextVar[bool] = ContextVar("spatialmech_pure", default=_ENV_PURE)
_NOTED = False
#: True for the rest of the process: the Python reference runs (:func:`use_python_reference`).
_FORCED: list[bool] = []


_COMPILED: list[ModuleType] = []  # the compiled package once imported (a hot path: no import statement per call)


def _compiled() -> ModuleType:
    """The compiled package, imported on first use (numba and the kernels: about a second), so
    that importing spatialmech -- or a closed form -- loads none of it."""
    if not _COMPILED:
        from . import compiled

        _COMPILED.append(compiled)
    return _COMPILED[0]


def enabled() -> bool:
    """True when the compiled engine runs: numba imports, ``SPATIALMECH_PURE`` was unset (or
    ``0``) when spatialmech was imported, and no :func:`python_reference` block is open.  Without
    numba a one-time ``RuntimeWarning`` says that the Python path runs."""
    global _NOTED
    if _FORCED or _PURE.get():
        return False
    compiled = _compiled()
    if not compiled.AVAILABLE:
        if not _NOTED:
            _NOTED = True
            warnings.warn(f"spatialmech: {compiled.UNAVAILABLE_REASON or 'numba is not available'}; the pure-Python "
                          "engine runs instead (slower, same results)", RuntimeWarning, stacklevel=3)
        return False
    return True


def engine() -> ModuleType | None:
    """The compiled package (:mod:`spatialmech.kinematics.compiled`) when it is in use
    (:func:`enabled`), else ``None``: the caller runs its Python reference."""
    return _compiled() if enabled() else None


def use_python_reference() -> None:
    """Run the Python reference for the rest of the process, in every thread (the first command
    on a fresh install while the kernels compile in the background: :mod:`.first_run`)."""
    _FORCED.append(True)
    os.environ[PURE_ENV] = "1"  # and in the processes it starts


@contextmanager
def python_reference(on: bool = True) -> Iterator[None]:
    """Run the block on the pure-Python reference path (``on=False``: on the compiled engine,
    where numba imports), for comparisons and benchmarks.  Blocks nest; the setting belongs to
    the current context (thread, task), and the environment is left alone."""
    token = _PURE.set(bool(on))
    try:
        yield
    finally:
        _PURE.reset(token)


# ---------------------------------------------------------------------------- entry points
def closure_residual(mech: Mechanism, config: Configuration) -> np.ndarray:
    """:func:`.closure.closure_residual` on the backend in use."""
    if (fast := engine()) is not None:
        return fast.closure_residual(mech, config)
    return closure.closure_residual(mech, config)


def closure_jacobian(mech: Mechanism, config: Configuration, *, active: np.ndarray | None = None):
    """:func:`.closure.closure_jacobian` on the backend in use: ``(A, r)``."""
    if (fast := engine()) is not None:
        return fast.closure_jacobian(mech, config, active=active)
    return closure.closure_jacobian(mech, config, active=active)


def retract(mech, config, active, step, fix_platform=False):
    """:func:`.closure.retract` on the backend in use."""
    if (fast := engine()) is not None:
        return fast.retract(mech, config, active, step, fix_platform)
    return closure.retract(mech, config, active, step, fix_platform)


def joint_twists(mech: Mechanism, config: Configuration) -> list[np.ndarray]:
    """:func:`.closure.joint_twists` on the backend in use (compiled: the joint columns of the
    closure Jacobian with every freedom active)."""
    if (fast := engine()) is not None:
        A, _ = fast.closure_jacobian(mech, config, active=np.ones(len(mech.freedom_refs), dtype=bool))
        return [A[6 * k : 6 * k + 6, sl].copy() for k, sl in enumerate(closure.limb_slices(mech))]
    return closure.joint_twists(mech, config)


def correct(
    mech: Mechanism,
    config: Configuration,
    *,
    active: np.ndarray | None = None,
    fix_platform: bool = False,
    tol: float | None = None,
    max_iter: int = 50,
    method: str = "auto",
) -> CorrectionResult:
    """Gauss-Newton (minimum-norm) correction of ``config`` onto the closure manifold
    (:func:`.closure.correct`, on the backend in use).

    ``active`` selects the joint variables that may move (default: every unlocked freedom;
    pass a mask without the actuators for forward position).  ``fix_platform`` holds the
    platform displacement (inverse position); internal bodies always move.  Returns the corrected
    configuration with ``converged`` and the final nondimensional residual norm; never raises on
    non-convergence (the caller decides).

    ``method``: ``"joints"`` runs the general Newton on the joint variables; ``"auto"`` (the
    default) does too, except for forward position of a platform on six S-P-S legs (``active``
    frees every ball and holds every slide), which is solved in pose coordinates
    (:mod:`.leg_platform`: the same pose; each leg's idle spin by the shortest-turn rule).
    """
    fast = engine()
    if method != "joints":
        if method != "auto":
            raise InputError(f"method: expected 'auto' or 'joints', got {method!r}")
        if active is not None and not fix_platform:
            lp = leg_platform.leg_platform(mech)
            if lp is not None and lp.applies(active):
                if fast is not None:
                    return fast.correct_legs(mech, lp, config, tol, max_iter, active)
                return leg_platform.correct(mech, lp, config, tol, max_iter, active)
    if fast is not None:
        return fast.correct(mech, config, active=active, fix_platform=fix_platform, tol=tol, max_iter=max_iter)
    return closure.correct(mech, config, active=active, fix_platform=fix_platform, tol=tol, max_iter=max_iter)
