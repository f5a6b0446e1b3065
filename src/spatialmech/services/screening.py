"""Defect screening at scale: the candidates of :mod:`spatialmech.synthesis.screening` judged
in chunks on Dask (a ``LocalCluster`` of processes by default, or an existing cluster), the
verdicts streamed into a Parquet dataset, chunk by chunk, so that an interrupted screen resumes
where it stopped; the best usable linkages written as model files.

The dataset directory (``OUT``, e.g. ``screen.parquet``)::

    OUT/part-00000.parquet ...   one file per chunk of candidates (the verdict rows)
    OUT/_screen.json             the arguments, the task, the candidate fingerprint, the summary
    OUT/_pool.parquet            the sampled dyads (the candidates' limbs)
    OUT/_family.npz              the CS dyad family (reused by a rerun; also cached: screen_family.py)
    OUT/_top/rank-01.toml ...    the best usable linkages as model files

Files and folders whose names start with ``_`` are skipped by Parquet readers, so
``pyarrow.parquet.read_table(OUT)`` (or pandas, Dask, DuckDB) reads the verdicts alone.

Determinism: the family, the pool and the candidates depend only on the task and the
arguments (seeded), and each judgement only on its candidate, so a screen on any number of
workers gives the same rows as the serial one (``workers=0``), up to the ``seconds`` and
``worker`` columns.
"""

from __future__ import annotations

import atexit
import contextlib
import gc
import hashlib
import json
import math
import os
import signal
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..model.mechanism import Pose
from ..results import Progress, check_progress
from ..synthesis.cs_dyads import CSFamily, cs_task
from .screen_family import FAMILY_FILE, obtain_family, save_family
from ..synthesis.screening import (
    RANKINGS,
    STAGES,
    VERDICT_COLUMNS,
    DyadPool,
    candidate_linkage,
    candidate_sets,
    dyad_pool,
    judge_candidates,
    rank_key,
)

__all__ = ["CONNECT_TIMEOUT", "MANIFEST", "MIN_CANDIDATES_PER_WORKER", "STOP_POLL_S", "TASKS_PER_WORKER", "ScreenSummary",
           "chunk_runs", "judge_chunks", "read_rows", "row_schema", "run_screen", "too_small_note"]

#: The dataset's description file.
MANIFEST = "_screen.json"
#: How long to wait for an existing Dask scheduler (``scheduler=``) to answer.
CONNECT_TIMEOUT = "20s"
#: Guided self-scheduling: each Dask task takes ``1 / (TASKS_PER_WORKER * workers)`` of the
#: chunks still unassigned (large tasks first hide the scheduler's per-task cost, single chunks
#: last keep the workers' finishing times within about one chunk of each other).
TASKS_PER_WORKER = 2
#: Below this many candidates per worker, a run on workers says it would be faster serially.
MIN_CANDIDATES_PER_WORKER = 250
_POOL = "_pool.parquet"
_TOP = "_top"
_FORMAT = "spatialmech-screen/1"


def row_schema():
    """The pyarrow schema of one verdict row (docs/screening.md describes the columns): the
    verdict's columns (:data:`~spatialmech.synthesis.screening.VERDICT_COLUMNS`), with the
    ``chunk`` after the candidate number and the ``worker`` last."""
    import pyarrow as pa

    def arrow(t: str):
        return pa.list_(pa.type_for_alias(t[5:-1])) if t.startswith("list<") else pa.type_for_alias(t)

    cols = [(c, arrow(t)) for _, c, t in VERDICT_COLUMNS]
    return pa.schema([cols[0], ("chunk", pa.int32()), *cols[1:], ("worker", pa.string())])


def judge_chunk(pool: DyadPool, sets: np.ndarray, first: int, chunk: int) -> list[dict]:
    """The verdict rows of one chunk (runs on a worker): candidates ``first, first + 1, ...``."""
    import socket

    who = f"{socket.gethostname()}:{os.getpid()}"
    rows = []
    for v in judge_candidates(pool, sets, first):
        rows.append({**v.row(), "chunk": int(chunk), "worker": who})
    return rows


# ------------------------------------------------------------------------------ the summary
@dataclass
class ScreenSummary:
    """What a screen did: the counts per stage over the whole dataset (earlier runs included),
    the time and candidates judged by this run, the workers, and the best usable linkages."""

    out: Path
    candidates: int
    mode: str
    judged: int
    judged_this_run: int
    chunks: int
    chunks_resumed: int
    rejected_by_stage: dict
    usable: int
    seconds: float
    workers: int
    scheduler: str
    pool: dict
    family: dict
    top: list = field(default_factory=list)
    rank_by: str = "singularity"
    #: Where the seven task positions came from (set by ``sm.screen``; listed by ``to_dict`` when set).
    positions_source: str | None = None
    #: Advice about this run (e.g. too few candidates to gain from workers); listed when set.
    note: str = ""

    @property
    def rate(self) -> float | None:
        """Candidates judged per second by this run."""
        return self.judged_this_run / self.seconds if self.seconds > 0 and self.judged_this_run else None

    def to_dict(self) -> dict:
        """JSON (docs/json.md, ``screen``): counts, ``seconds`` and the rate of this run, the top list."""
        return {
            "out": str(self.out), "candidates": self.candidates, "candidate_mode": self.mode, "judged": self.judged,
            "judged_this_run": self.judged_this_run, "chunks": self.chunks, "chunks_resumed": self.chunks_resumed,
            "rejected_by_stage": dict(self.rejected_by_stage), "usable": self.usable, "seconds": self.seconds,
            "candidates_per_s": self.rate, "workers": self.workers, "scheduler": self.scheduler,
            "pool": dict(self.pool), "family": dict(self.family), "top": list(self.top),
            "ranking": ("min_sigma_on_path (larger first), then stroke_len (smaller first)" if self.rank_by == "singularity"
                        else "stroke_len (smaller first), then min_sigma_on_path (larger first)"),
        } | ({} if self.positions_source is None else {"positions_source": self.positions_source}) \
          | ({"note": self.note} if self.note else {})


# ------------------------------------------------------------------------------ helpers
def _poses_json(poses: Sequence[Pose]) -> list[dict]:
    return [{"name": p.name, "R": np.asarray(p.R).tolist(), "p": np.asarray(p.p).tolist()} for p in poses]


def _fingerprint(pool: DyadPool, sets: np.ndarray) -> str:
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(np.round(pool.vectors, 8)).tobytes())
    h.update(np.ascontiguousarray(sets, dtype=np.int64).tobytes())
    return h.hexdigest()


def _part(out: Path, chunk: int) -> Path:
    return out / f"part-{chunk:05d}.parquet"


def _write_rows(path: Path, rows: list[dict]) -> None:
    """Write one chunk atomically (a temporary file renamed into place)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    tmp = path.with_name("_tmp-" + path.name)
    pq.write_table(pa.Table.from_pylist(rows, schema=row_schema()), tmp)
    os.replace(tmp, path)


def read_rows(out: str | os.PathLike) -> list[dict]:
    """Every verdict row of a screening dataset, in candidate order."""
    import pyarrow.parquet as pq

    out = Path(out)
    parts = sorted(out.glob("part-*.parquet"))
    rows = [r for p in parts for r in pq.read_table(p, schema=row_schema()).to_pylist()]
    return sorted(rows, key=lambda r: r["candidate"])


def _read_manifest(out: Path) -> dict | None:
    """The manifest of the screen in ``out`` (``None`` when there is none)."""
    mf = out / MANIFEST
    if not mf.is_file():
        return None
    try:
        return json.loads(mf.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        raise InputError(f"out: {mf} is not readable ({e}); use a new directory") from None


def _refuse_other_screen(out: Path, arguments: dict, positions: list[dict]) -> None:
    """An ``InputError`` now when ``out`` already holds a screen of other arguments or positions
    (:func:`_check_out` checks the candidates themselves once they are formed)."""
    old = _read_manifest(out)
    if old is None:
        return
    same_pos = isinstance(old.get("positions"), list) and len(old["positions"]) == len(positions) and all(
        np.allclose(a["R"], b["R"], atol=1e-12) and np.allclose(a["p"], b["p"], atol=1e-12)
        for a, b in zip(old["positions"], positions, strict=True))
    if old.get("arguments") != arguments or not same_pos:
        raise InputError(f"out: {out} holds a screen with other arguments or positions; use a new directory "
                         "(or the same arguments to resume it)")


def _check_out(out: Path, manifest: dict) -> int:
    """Prepare ``out``; returns how many chunks are already there (a resume).  An existing
    screen (its arguments and positions already checked by :func:`_refuse_other_screen`) must
    have the same candidates; any other existing directory must be empty."""
    if out.exists() and not out.is_dir():
        raise InputError(f"out: {out} exists and is not a directory")
    old = _read_manifest(out)
    if old is not None:
        if old.get("format") != _FORMAT or old.get("fingerprint") != manifest["fingerprint"]:
            raise InputError(f"out: {out} holds a screen with other arguments or candidates; use a new directory "
                             "(or the same arguments to resume it)")
        return sum(1 for k in range(manifest["chunks"]) if _part(out, k).exists())
    if out.exists() and any(out.iterdir()):
        raise InputError(f"out: {out} is not empty and holds no screen ({MANIFEST} missing); use a new directory")
    out.mkdir(parents=True, exist_ok=True)
    (out / MANIFEST).write_text(json.dumps(manifest, indent=2), encoding="utf-8")
    return 0


def _write_pool(out: Path, pool: DyadPool) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    names = ["B1_x", "B1_y", "B1_z", "M1_x", "M1_y", "M1_z", "u_x", "u_y", "u_z"] + [f"s{j}" for j in range(2, 8)]
    cols = {"dyad": np.arange(len(pool)), "branch": pool.branch, "arc": pool.arc}
    cols.update({n: pool.vectors[:, k] for k, n in enumerate(names)})
    pq.write_table(pa.table(cols), out / _POOL)


class _Reporter:
    """Progress of the judgements: candidates done, rate, ETA, usable so far."""

    def __init__(self, progress: Callable, total: int, done: int):
        self.progress, self.total, self.done0, self.done = progress, total, done, done
        self.usable = 0
        self.t0 = time.perf_counter()

    def __call__(self, n: int, usable: int) -> None:
        self.done += n
        self.usable += usable
        dt = time.perf_counter() - self.t0
        rate = (self.done - self.done0) / dt if dt > 0 else 0.0
        eta = (self.total - self.done) / rate if rate > 0 else math.inf
        eta_s = f"{eta:.0f} s" if math.isfinite(eta) else "?"
        self.progress(self.done, self.total, f"{self.done}/{self.total} candidates, {rate:.2f} /s, ETA {eta_s}, "
                                             f"{self.usable} usable so far")


def _connect(client_type, scheduler: str):
    """A Dask client of the scheduler at ``scheduler``, or :class:`InputError` within about
    :data:`CONNECT_TIMEOUT`: Dask bounds the connection, not the handshake, so a server that
    accepts and then says nothing (or garbage) would hang it; the attempt runs in a thread
    that is abandoned at the deadline (a client it makes later is closed)."""
    import threading

    from dask.utils import parse_timedelta

    limit = float(parse_timedelta(CONNECT_TIMEOUT, default="s"))
    box: dict = {}
    lock = threading.Lock()

    def attempt() -> None:
        try:
            c = client_type(scheduler, timeout=CONNECT_TIMEOUT)
        except Exception as e:  # any failure of the handshake is the address's fault
            box["error"] = e
            return
        with lock:
            box["client"] = c
            late = box.get("abandoned", False)
        if late:
            c.close()

    t = threading.Thread(target=attempt, name="spatialmech-dask-connect", daemon=True)
    t.start()
    t.join(limit + 2.0)
    with lock:
        box["abandoned"] = "client" not in box and "error" not in box
    if box["abandoned"]:
        raise InputError(f"scheduler: no Dask scheduler answered at {scheduler!r} within {CONNECT_TIMEOUT} "
                         "(the server accepts connections but does not speak Dask's protocol)")
    if "error" in box:
        e = box["error"]
        raise InputError(f"scheduler: cannot reach a Dask scheduler at {scheduler!r} within "
                         f"{CONNECT_TIMEOUT} ({type(e).__name__}: {str(e)[:200]})")
    return box["client"]


def _skip_final_collections() -> None:
    """Runs in each worker process of this module's own ``LocalCluster`` (a worker plugin's set-up):
    at the process's exit, the objects it holds are frozen out of the garbage collector
    (``gc.freeze``), so that the interpreter's final collections skip them (the operating system
    frees the memory anyway).  With the compiled kernels loaded, those collections made the
    cluster's close take 0.46-0.50 s, against 0.08-0.10 s with this (stop 42), and the screen
    waits for it.  Handlers registered before this one (Dask's, ``weakref`` finalizers, logging)
    still run after it; only reference cycles left at exit go unfinalized."""
    atexit.register(gc.freeze)


def _local_cluster(workers: int):
    import logging

    from distributed import Client, LocalCluster
    from distributed.diagnostics.plugin import WorkerPlugin

    class _QuickExit(WorkerPlugin):
        def setup(self, worker) -> None:
            _skip_final_collections()

    # Ctrl-C is this process's to handle (it cancels the run, keeps the chunks written and closes
    # the workers): the workers are spawned with SIGINT ignored, which they inherit, else each
    # prints its event loop's KeyboardInterrupt traceback.  (Only from the main thread, where
    # signal handlers live; a Ctrl-C during the cluster's start, about 0.4 s, is then ignored.)
    # (A handler not installed from Python, ``getsignal`` None, could not be put back: left alone.)
    previous = signal.getsignal(signal.SIGINT) if threading.current_thread() is threading.main_thread() else None
    if previous is not None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address=None, silence_logs=logging.ERROR)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    client = Client(cluster)
    client.register_plugin(_QuickExit(), name="spatialmech-quick-exit")
    return cluster, client


#: How often (seconds) a worker's run of chunks asks whether the screen was stopped.
STOP_POLL_S = 0.5


def judge_chunks(pool: DyadPool, todo: list, stop: str | None = None) -> list[tuple[int, list[dict]]]:
    """The verdict rows of several chunks ``(k, first, sets)`` in one task (runs on a worker):
    ``[(k, rows), ...]``.  Fewer, larger tasks hide the scheduler's per-task cost.  ``stop``: the
    name of a Dask ``Event`` the screen sets when it is interrupted; between chunks, at most every
    :data:`STOP_POLL_S`, the run asks it and returns the chunks judged so far once it is set (a
    running task cannot be cancelled from outside, and a first run is a quarter of a worker's
    share: minutes of judging on a large screen)."""
    event = None
    if stop is not None:
        from distributed import Event

        event = Event(stop)
    out: list[tuple[int, list[dict]]] = []
    asked = time.monotonic()
    for k, first, sets in todo:
        if event is not None and time.monotonic() - asked >= STOP_POLL_S:
            asked = time.monotonic()
            if event.is_set():
                break
        out.append((k, judge_chunk(pool, sets, first, k)))
    return out


def chunk_runs(todo: list, n_workers: int) -> list[list]:
    """``todo`` cut into runs of chunks of decreasing length (guided self-scheduling): each run
    takes ``ceil(remaining / (TASKS_PER_WORKER * n_workers))`` chunks, so the first tasks are
    long and the last ones a single chunk; submitted in this order, the workers end within about
    one chunk's time of each other instead of one long task's."""
    share = TASKS_PER_WORKER * max(1, n_workers)
    runs, i = [], 0
    while i < len(todo):
        size = max(1, math.ceil((len(todo) - i) / share))
        runs.append(todo[i:i + size])
        i += size
    return runs


def _run_distributed(client, pool, todo, report, write, n_workers: int) -> None:
    from distributed import Event, as_completed

    pool_f = client.scatter(pool, broadcast=True)
    stop = Event(f"spatialmech-screen-stop-{os.getpid()}-{time.time_ns()}", client=client)
    futures = [client.submit(judge_chunks, pool_f, b, stop.name, pure=False) for b in chunk_runs(todo, n_workers)]
    try:
        for fut in as_completed(futures):
            for k, rows in fut.result():  # a worker's exception is raised here, with its traceback
                write(k, rows)
                report(len(rows), sum(r["usable"] for r in rows))
    except BaseException:
        # the runs already started end at their next chunk (judge_chunks); best effort only, so that
        # a lost connection still reports its own error rather than this one's
        with contextlib.suppress(Exception):
            stop.set()
        client.cancel(futures)
        raise


def too_small_note(n: int, workers: int) -> str:
    """A note when ``n`` candidates (at least one: a finished screen resumed has nothing to say)
    are too few to gain from ``workers`` worker processes (their start, their first kernels and
    their close, about 1.3 s on two cores, against what they save), else ``""``."""
    if workers >= 2 and 0 < n < MIN_CANDIDATES_PER_WORKER * workers:
        return (f"{n} candidates are too few to gain from {workers} workers (starting them and loading their "
                f"kernels takes a second or more); "
                f"workers=0 (--workers 0) judges them serially, faster; workers pay off from about "
                f"{MIN_CANDIDATES_PER_WORKER * workers} candidates")
    return ""


def _local_workers(workers: int | None) -> int:
    """The worker processes of a local cluster (``None``: one per core; ``0``: serial)."""
    return int(os.cpu_count() or 1) if workers is None else int(workers)


def _family_for(task, family: CSFamily | None, starts: int, seed: int, out: Path, say):
    """``(family, source, key)``: the given family (checked against the task; key ``None``), or
    the one stored with the dataset, cached or synthesised (:func:`.screen_family.obtain_family`)."""
    if family is None:
        say(0, None, "the CS dyad family of the seven positions (stored with the dataset and cached)")
        return obtain_family(task, starts, seed, out)
    if family.task.D.shape != task.D.shape or not np.allclose(family.task.D, task.D, atol=1e-12):
        raise InputError("family: it was synthesised for other positions")
    return family, "given", None


# ------------------------------------------------------------------------------ the screen
def run_screen(
    positions: Sequence[Pose],
    out: str | os.PathLike,
    *,
    candidates: int = 1000,
    density: float = 0.5,
    seed: int = 0,
    starts: int = 60,
    separation: float = 0.5,
    chunk_size: int = 20,
    workers: int | None = None,
    scheduler: str | None = None,
    top: int = 5,
    rank_by: str = "singularity",
    family: CSFamily | None = None,
    progress: Progress | None = None,
) -> ScreenSummary:
    """Screen 5-CS linkages for seven task ``positions`` (see the module docstring).

    ``candidates``, ``density``, ``seed``, ``separation``: :func:`~..synthesis.screening.dyad_pool`
    and :func:`~..synthesis.screening.candidate_sets`; ``starts``: random starts of the family
    synthesis (:func:`~..synthesis.cs_dyads.synthesize_cs`, same ``seed``), or a ready ``family``
    of these positions; ``chunk_size``: candidates per Parquet file and per Dask task;
    ``workers``: local worker processes (``None``: one per core; ``0``: serial, in this
    process, no Dask); ``scheduler``: the address of an existing Dask scheduler (then
    ``workers`` is ignored; the workers need spatialmech installed); ``top``: how many of the
    best usable linkages to write as model files, ranked by ``rank_by``
    (:func:`~..synthesis.screening.rank_key`).  ``progress(done, total, message)`` is called
    after every chunk.  A rerun with the same arguments into the same ``out`` skips the chunks
    already written.
    """
    from ..model.schema import dump

    say = check_progress(progress)
    for nm, v, lo in (("candidates", candidates, 1), ("chunk_size", chunk_size, 1), ("top", top, 0),
                      ("starts", starts, 1)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < lo:
            raise InputError(f"{nm}: expected a whole number >= {lo}, got {v!r}")
    if rank_by not in RANKINGS:
        raise InputError(f"rank_by: expected one of {', '.join(RANKINGS)}, got {rank_by!r}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 0):
        raise InputError(f"workers: expected a whole number >= 0 (0: serial), got {workers!r}")
    if scheduler is not None and not str(scheduler).strip():
        raise InputError("scheduler: expected a Dask scheduler address such as tcp://10.0.0.5:8786, got an empty value")
    for nm, x in (("density", density), ("separation", separation)):
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x) or x < 0 \
                or (nm == "density" and x == 0):
            raise InputError(f"{nm}: expected a {'positive' if nm == 'density' else 'non-negative'} number, got {x!r}")
    out = Path(out)
    task = cs_task(positions)
    arguments = {"candidates": int(candidates), "density": float(density), "seed": int(seed), "starts": int(starts),
                 "separation": float(separation), "chunk_size": int(chunk_size)}
    _refuse_other_screen(out, arguments, _poses_json(task.poses))  # before the work, not after the family
    family, family_source, family_key = _family_for(task, family, int(starts), seed, out, say)
    pool = dyad_pool(family, density)
    sets, mode = candidate_sets(pool, int(candidates), seed=seed, separation=separation)
    if len(sets) == 0:
        raise InputError(f"candidates: no well spread set of five dyads found (pool of {len(pool)}, separation "
                         f"{separation}); raise --density")
    n_chunks = math.ceil(len(sets) / chunk_size)
    manifest = {
        "format": _FORMAT,
        "arguments": arguments,
        "positions": _poses_json(task.poses),
        "fingerprint": _fingerprint(pool, sets),
        "n_candidates": len(sets), "candidate_mode": mode, "chunks": n_chunks, "pool_size": len(pool),
    }
    resumed = _check_out(out, manifest)
    if not (out / _POOL).exists():
        _write_pool(out, pool)
    if family_key is not None and not (out / FAMILY_FILE).exists():
        save_family(family, out / FAMILY_FILE, family_key)
    todo = [(k, k * chunk_size, sets[k * chunk_size:(k + 1) * chunk_size]) for k in range(n_chunks)
            if not _part(out, k).exists()]
    done_before = len(sets) - sum(len(s) for _, _, s in todo)
    report = _Reporter(say, len(sets), done_before)

    def write(k, rows):
        _write_rows(_part(out, k), rows)

    t0 = time.perf_counter()
    n_workers, where = 0, "serial (this process)"
    note = too_small_note(len(sets) - done_before, _local_workers(workers) if scheduler is None else 0)
    if note:
        say(done_before, len(sets), note)
    if todo:
        if scheduler is None and workers == 0:
            for k, first, s in todo:
                rows = judge_chunk(pool, s, first, k)
                write(k, rows)
                report(len(rows), sum(r["usable"] for r in rows))
        else:
            from distributed import Client

            if scheduler is not None:
                cluster, client = None, _connect(Client, str(scheduler))
                where = str(scheduler)
            else:
                cluster, client = _local_cluster(_local_workers(workers))
                where = "local cluster (127.0.0.1)"
            try:
                n_workers = len(client.scheduler_info().get("workers", {}))
                say(done_before, len(sets), f"judging {len(sets) - done_before} candidates on {n_workers} workers")
                _run_distributed(client, pool, todo, report, write, n_workers)
            finally:
                client.close()
                if cluster is not None:
                    cluster.close()
    seconds = time.perf_counter() - t0
    rows = read_rows(out)
    counts = dict.fromkeys((*STAGES, "error"), 0)
    for r in rows:
        if r["rejected_by"] is not None:
            counts[r["rejected_by"]] += 1
    usable = sorted((r for r in rows if r["usable"]), key=lambda r: rank_key(r, rank_by))
    top_dir = out / _TOP
    top_rows = []
    if usable and top:
        top_dir.mkdir(exist_ok=True)
        for old in top_dir.glob("rank-*.toml"):
            old.unlink()
    for rank, r in enumerate(usable[:top], start=1):
        path = top_dir / f"rank-{rank:02d}.toml"
        mech = candidate_linkage(pool, r["dyads"], name=f"five-cs-screened-{r['candidate']}")
        dump(mech, path)
        top_rows.append({"place": rank, "candidate": r["candidate"], "dyads": r["dyads"],
                         **{k: r[k] for k in ("usable_drivers", "best_driver", "min_sigma_on_path",
                                              "min_closure_sigma_on_path", "stroke_len", "max_abs_slide_len")},
                         "model_file": str(path)})
    summary = ScreenSummary(
        out=out, candidates=len(sets), mode=mode, judged=len(rows), judged_this_run=len(sets) - done_before,
        chunks=n_chunks, chunks_resumed=resumed, rejected_by_stage=counts, usable=len(usable), seconds=seconds,
        workers=n_workers, scheduler=where,
        pool={"dyads": len(pool), "density": float(density), "separation": float(separation)},
        family={"n_branches": len(family.branches), "n_points": family.n_points, "source": family_source},
        top=top_rows, rank_by=rank_by,
        note=note,
    )
    doc = {**manifest, "summary": summary.to_dict()}
    (out / MANIFEST).write_text(json.dumps(doc, indent=2, default=float), encoding="utf-8")
    return summary
