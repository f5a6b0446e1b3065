"""The numba entry point of the compiled kernels (:mod:`.compiled`): ``njit``, or, where numba
cannot be imported, a stand-in that leaves functions as plain Python (the kernels then never
run: :func:`.compiled.enabled` is false and the Python reference path runs)."""

from __future__ import annotations

__all__ = ["AVAILABLE", "SAFE_FASTMATH", "UNAVAILABLE_REASON", "njit", "prange"]

#: numba ``fastmath`` flags that let LLVM vectorise and fuse multiply-adds but never reassociate:
#: :func:`.kernels_se3.nb_sincos`'s argument reduction (and any compensated sum) depends on the
#: order of its operations, which ``fastmath=True`` ("reassoc") would change.
SAFE_FASTMATH = {"nnan", "ninf", "nsz", "arcp", "afn", "contract"}

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
