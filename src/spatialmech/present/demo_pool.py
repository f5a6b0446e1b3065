"""The demo's sections built by two processes at once (issue 29: ``demo`` under 15 s on two cores).

The sections of the reproduction report (:data:`.report.DEMO_SECTIONS`) are independent: each
calls the library's analyses and draws its own figures.  :func:`build_sections` hands them to a
pool of forked worker processes, the longest first (paper A's is about half of the work), each
worker also rendering its sections' 3-D viewers (:func:`.report.prerender`); the parent relays
the workers' progress steps to the caller's callback in the order they arrive and returns the
sections in their order.  The report is the same as one built in a single process (each section
computes the same numbers; nothing is shared between sections).

Forking is the only start method used: a worker inherits the loaded modules and compiled kernels
(a spawned one would import and load them again, seconds each).  Where ``fork`` is unavailable,
the machine has one core, or forking is not safe in this process (:func:`fork_is_safe`),
:func:`default_workers` answers 1 and the demo runs in one process.

Why a fork can be unsafe: numba's parallel kernels (the 4-SPS/CU legs of large batches) run on
numba's threading layer, GNU OpenMP where Intel TBB is not installed, and GNU OpenMP does not
survive a fork: a child that runs a parallel kernel after its parent started OpenMP's threads is
terminated ("fork() called from a process already using GNU OpenMP, this is unsafe").  That is
what killed a worker in a CI run: the demo was built inside a pytest worker that had run the
4-SPS/CU tests before.  A fresh ``spatialmech demo`` has started no threads when it forks.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import queue as queue_module
import re
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

__all__ = ["LAST_RUN", "WORKERS_ENV", "build_sections", "default_workers", "fork_is_safe", "openmp_runtimes"]

#: Environment variable: the demo's worker processes (default 2 on a machine with 2 cores or more
#: where a fork is safe, see :func:`fork_is_safe`).
WORKERS_ENV = "SPATIALMECH_DEMO_WORKERS"

#: Relative cost of each section (the order the pool takes them in: the longest first), measured
#: by profiling ``spatialmech demo``; a section not listed counts 1.
_COST = {"paper_a:section": 46.0, "paper_b:section": 21.0, "paper_d:section": 10.0, "paper_c:section": 4.0,
         "models:section": 3.0}

#: File names of OpenMP runtimes: GNU (libgomp), LLVM (libomp), Intel (libiomp5).
_OPENMP_RUNTIME = re.compile(r"lib(g|i)?omp[0-9]*[.-]")

_QUEUE: list = []  # the progress queue the forked workers inherit (set by build_sections)

#: CPU seconds of the last :func:`build_sections` in this process: ``{"sections": {spec: s},
#: "workers": {pid: s}}`` (what ``benchmarks/bench_demo.py`` reports; the wall clock of a run on
#: two free cores is about the parent's CPU plus the largest worker's).
LAST_RUN: dict = {}


def fork_is_safe() -> bool:
    """Whether this process can fork workers that run the library's kernels: ``fork`` exists and
    numba's threading layer is either not started yet or one that survives a fork (TBB or
    numba's own workqueue; GNU OpenMP does not, see the module docstring), and no OpenMP runtime
    is loaded in the process by anything else (:func:`openmp_runtimes`)."""
    if "fork" not in mp.get_all_start_methods():
        return False
    try:
        import numba
    except ImportError:  # pragma: no cover - numba is a dependency; without it no threads start
        return True
    try:
        layer = numba.threading_layer()
    except ValueError:  # numba: "Threading layer is not initialized." -- no parallel kernel ran
        layer = None
    return layer in (None, "tbb", "workqueue") and not openmp_runtimes()


def openmp_runtimes(maps: str | Path = "/proc/self/maps") -> list[str]:
    """The OpenMP runtimes (GNU ``libgomp``, LLVM ``libomp``, Intel ``libiomp``) mapped into this
    process, read from ``maps`` (Linux; ``[]`` where the file does not exist).  A process that
    loaded one may have started its threads without numba (a host application's own OpenMP code,
    a library linked with it), so :func:`fork_is_safe` refuses to fork then: conservative, one
    process builds the same report.  A fresh ``spatialmech demo`` maps none before it forks."""
    try:
        text = Path(maps).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return []
    names = {line.rsplit("/", 1)[-1] for line in text.splitlines() if "/" in line}
    return sorted(n for n in names if _OPENMP_RUNTIME.match(n))


def default_workers(n_sections: int, requested: int | None = None) -> int:
    """Worker processes for ``n_sections``: ``requested``, else ``$SPATIALMECH_DEMO_WORKERS``
    when set, else 2; never more than the sections nor the cores, and 1 where forking is not
    safe in this process (:func:`fork_is_safe`: a worker would be killed, so one process builds
    the report instead, with the same result)."""
    env = os.environ.get(WORKERS_ENV, "").strip()
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    n = int(requested) if requested is not None else (int(env) if env.isdigit() else 2)
    n = max(1, min(n, n_sections, cores))
    return n if n == 1 or fork_is_safe() else 1


def _build(index: int, spec: str):
    """In a worker: build section ``spec`` (its progress steps to the inherited queue) and render
    its viewers."""
    import time

    from .report import prerender, section_function

    c0 = time.process_time()
    fn, _ = section_function(spec)
    q = _QUEUE[0]
    sec = fn(lambda done, total, message: q.put((index, message)))
    return prerender(sec), os.getpid(), time.process_time() - c0


def build_sections(specs: Sequence[str], steps: Sequence[int], sink: Callable, total: int, workers: int) -> list:
    """The sections ``specs`` built by ``workers`` forked processes; ``sink(done, total,
    message)`` gets every step (``done`` counted over all sections, as they arrive)."""
    ctx = mp.get_context("fork")
    q = ctx.Queue()
    _QUEUE[:] = [q]
    order = sorted(range(len(specs)), key=lambda i: -_COST.get(specs[i], 1.0))
    done = 0
    try:
        with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
            futures = {i: pool.submit(_build, i, specs[i]) for i in order}
            pending = set(futures.values())
            while pending:
                try:
                    _, message = q.get(timeout=0.1)
                except queue_module.Empty:
                    pending = {f for f in pending if not f.done()}
                    continue
                done += 1
                sink(min(done, total), total, message)
            results = [futures[i].result() for i in range(len(specs))]
        while True:  # steps still in the queue when the last worker finished
            try:
                _, message = q.get_nowait()
            except queue_module.Empty:
                break
            done += 1
            sink(min(done, total), total, message)
    finally:
        _QUEUE.clear()
        q.close()
    workers_cpu: dict[int, float] = {}
    for _, pid, cpu in results:
        workers_cpu[pid] = workers_cpu.get(pid, 0.0) + cpu
    LAST_RUN.clear()
    LAST_RUN.update(sections={spec: r[2] for spec, r in zip(specs, results, strict=True)}, workers=workers_cpu)
    return [r[0] for r in results]
