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
or the machine has one core, :func:`default_workers` answers 1 and the demo runs in one process.
Two workers are opt-in (``SPATIALMECH_DEMO_WORKERS=2``): see :func:`default_workers`.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import queue as queue_module
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor

__all__ = ["LAST_RUN", "WORKERS_ENV", "build_sections", "default_workers"]

#: Environment variable: the demo's worker processes (default 2 on a machine with 2 cores or more).
WORKERS_ENV = "SPATIALMECH_DEMO_WORKERS"

#: Relative cost of each section (the order the pool takes them in: the longest first), measured
#: by profiling ``spatialmech demo``; a section not listed counts 1.
_COST = {"paper_a:section": 46.0, "paper_b:section": 21.0, "paper_d:section": 10.0, "paper_c:section": 4.0,
         "models:section": 3.0}

_QUEUE: list = []  # the progress queue the forked workers inherit (set by build_sections)

#: CPU seconds of the last :func:`build_sections` in this process: ``{"sections": {spec: s},
#: "workers": {pid: s}}`` (what ``benchmarks/bench_demo.py`` reports; the wall clock of a run on
#: two free cores is about the parent's CPU plus the largest worker's).
LAST_RUN: dict = {}


def default_workers(n_sections: int) -> int:
    """Worker processes for ``n_sections``: ``$SPATIALMECH_DEMO_WORKERS`` when set (an opt-in),
    else 1; never more than the sections nor the cores, and 1 where fork is unavailable.

    Opt-in because a forked worker of the full demo died abruptly (``BrokenProcessPool``) in a
    fresh-clone CI dry run inside a pytest-xdist worker, while the same build passed in a warm
    tree; the cause is not found yet (fork after OpenBLAS/numba/MuJoCo state is the suspect)."""
    if "fork" not in mp.get_all_start_methods():
        return 1
    env = os.environ.get(WORKERS_ENV, "").strip()
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    n = int(env) if env.isdigit() else 1
    return max(1, min(n, n_sections, cores))


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
