"""The numba entry point of the compiled kernels (:mod:`spatialmech.kinematics.compiled`): ``njit``, or, where numba
cannot be imported, a stand-in that leaves functions as plain Python (the kernels then never
run: :func:`..backend.enabled` is false and the Python reference path runs).

First-call compilation is what a new user waits for, so two rules for the kernels:

- a kernel passes flags and small constants to another kernel as ``np.bool_(True)`` or
  ``np.int64(6)`` (or values computed at run time), never as bare ``True`` or ``6``: numba types
  a bare constant as a literal and compiles a separate copy of the callee for it (the one
  exception, marked where it is made: the limb QR of :func:`.kernels_blocks.nb_minnorm_blocks`,
  whose copy with its six rows known runs a Stewart forward solve 4-5 us faster);
- no thin wrapper kernels (an allocating front for a kernel that takes scratch, a single-item
  front for a batched one): numba re-optimises a kernel's whole call tree inside each caller,
  so every layer costs seconds of compilation.  Allocate the scratch in the caller."""

from __future__ import annotations

__all__ = ["AVAILABLE", "SAFE_FASTMATH", "UNAVAILABLE_REASON", "announce_compilation", "njit", "prange"]

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


_ANNOUNCER: list = []  # the one listener announce_compilation installed, if any


def announce_compilation(stream) -> bool:
    """Write to ``stream`` (a terminal: the command line passes stderr when it is one) a line for
    each kernel that numba *compiles* -- a miss of its on-disk cache, i.e. the first use after
    installation or after an upgrade -- with the seconds it took; kernels loaded from the cache
    stay silent.  Only the outermost kernel of a nested compilation is named.  One listener per
    process: a second call redirects it, ``stream=None`` removes it.  Returns whether a listener
    is installed (never without numba)."""
    if stream is None:
        if _ANNOUNCER:
            from numba.core import event

            event.unregister("numba:compile", _ANNOUNCER.pop())
        return False
    if _ANNOUNCER:
        _ANNOUNCER[0].stream = stream
        return True
    if not AVAILABLE:
        return False
    import time

    from numba.core import event

    class _Announcer(event.Listener):
        def __init__(self) -> None:
            self.stream = stream
            self.depth = 0
            self.t0 = 0.0
            self.first = True

        def on_start(self, ev) -> None:
            if self.depth == 0:
                if self.first:
                    self.first = False
                    print("spatialmech: compiling numerical kernels for their first use; they are saved on disk, "
                          "and later runs load them in about a second", file=self.stream, flush=True)
                name = getattr(ev.data["dispatcher"].py_func, "__name__", "kernel")
                print(f"  compiling {name} ...", end="", file=self.stream, flush=True)
                self.t0 = time.perf_counter()
            self.depth += 1

        def on_end(self, ev) -> None:
            self.depth -= 1
            if self.depth == 0:
                print(f" {time.perf_counter() - self.t0:.1f} s", file=self.stream, flush=True)

    listener = _Announcer()
    event.register("numba:compile", listener)
    _ANNOUNCER.append(listener)
    return True
