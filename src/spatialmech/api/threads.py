"""Small matrices on one BLAS thread (issue 29).

The library's linear algebra is on small matrices (a 54x57 closure Jacobian, 6x6 blocks), where
OpenBLAS's thread pool costs more than it saves: its threads spin up and wait for each call (one
54x57 SVD took 66 ms instead of 0.3-0.5 ms; ``spatialmech fk delta --all`` 3.6 s by default, 1.9 s
with ``OPENBLAS_NUM_THREADS=1``).  So the heavy verbs of the API run under :func:`one_blas_thread`
and the command line's whole run under :func:`blas_threads`; both limit the BLAS libraries that
are loaded (NumPy's and SciPy's OpenBLAS) for the block only and restore the caller's setting
after it, so a user's own NumPy outside the verbs keeps its threads.  Nothing here runs at import.

``SPATIALMECH_BLAS_THREADS`` sets the number (default 1; ``0``: leave BLAS alone).  Without
threadpoolctl installed the blocks change nothing.  The limit is process-wide while a block is
open (BLAS has no per-thread setting): a thread of the caller's running BLAS in parallel with a
verb shares the limit for that time.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Any, ParamSpec, TypeVar

__all__ = ["BLAS_THREADS_ENV", "blas_threads", "one_blas_thread"]

#: Environment variable: the BLAS threads of the library's verbs (default 1; 0 leaves BLAS alone).
BLAS_THREADS_ENV = "SPATIALMECH_BLAS_THREADS"

_P = ParamSpec("_P")
_T = TypeVar("_T")

#: ``[(len(sys.modules), controller)]``: threadpoolctl's scan of the loaded libraries costs ~2 ms,
#: a limit through a kept controller ~20 us; the scan is redone when modules were imported since
#: (one of them may have loaded another BLAS, as scipy.linalg does).
_CONTROLLER: list[tuple[int, Any]] = []


def _controller() -> Any | None:
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - threadpoolctl is a dependency
        return None
    key = len(sys.modules)
    if not _CONTROLLER or _CONTROLLER[0][0] != key:
        _CONTROLLER[:] = [(key, ThreadpoolController())]
    return _CONTROLLER[0][1]


def _wanted(n: int | None) -> int:
    if n is not None:
        return n
    text = os.environ.get(BLAS_THREADS_ENV, "").strip()
    try:
        return max(int(text), 0) if text else 1
    except ValueError:
        return 1


@contextmanager
def blas_threads(n: int | None = None) -> Iterator[None]:
    """Limit the loaded BLAS libraries to ``n`` threads for the block (default: 1, or
    ``SPATIALMECH_BLAS_THREADS``; 0: no limit), then restore their settings.  Blocks nest."""
    n = _wanted(n)
    controller = _controller() if n > 0 else None
    if controller is None:
        yield
        return
    with controller.limit(limits=n, user_api="blas"):
        yield


def one_blas_thread(func: Callable[_P, _T]) -> Callable[_P, _T]:
    """Decorator of a verb: its body runs under :func:`blas_threads` (one BLAS thread)."""

    @functools.wraps(func)
    def verb(*args: _P.args, **kwargs: _P.kwargs) -> _T:
        with blas_threads():
            return func(*args, **kwargs)

    return verb
