"""The numba entry point of the compiled kernels (:mod:`.compiled`): ``njit``, or, where numba
cannot be imported, a stand-in that leaves functions as plain Python (the kernels then never
run: :func:`.compiled.enabled` is false and the Python reference path runs)."""

from __future__ import annotations

__all__ = ["AVAILABLE", "UNAVAILABLE_REASON", "njit", "prange"]

try:  # numba is a runtime dependency; without it the Python path runs (slower, same results)
    from numba import njit, prange

    AVAILABLE = True
    UNAVAILABLE_REASON = ""
except ImportError as exc:  # pragma: no cover - exercised only where numba is missing
    AVAILABLE = False
    UNAVAILABLE_REASON = f"numba cannot be imported ({exc})"

    def njit(*args, **kwargs):
        if args and callable(args[0]):
            return args[0]
        return lambda f: f

    prange = range
