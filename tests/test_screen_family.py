"""Screening that scales (issue 29): the CS dyad family stored with the dataset and cached
(services/screen_family.py), reused by later screens with the same rows; workers fed runs of
chunks; a note when a run is too small to gain from workers."""

import dataclasses
import os
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pytest

from spatialmech.catalog.papers import five_cs_positions
from spatialmech.services import screen_family as sf
from spatialmech.services.screening import (
    MIN_CANDIDATES_PER_WORKER,
    TASKS_PER_WORKER,
    _local_cluster,
    chunk_runs,
    judge_chunks,
    read_rows,
    run_screen,
    too_small_note,
)
from spatialmech.synthesis.cs_dyads import cs_task
from spatialmech.synthesis.screening import candidate_sets, dyad_pool


def strip(rows):
    return [{k: v for k, v in r.items() if k not in ("seconds", "worker")} for r in rows]


def test_a_run_too_small_for_its_workers_says_so():
    assert too_small_note(MIN_CANDIDATES_PER_WORKER * 2, 2) == ""
    assert too_small_note(1000, 0) == "" and too_small_note(10, 1) == ""
    assert too_small_note(0, 2) == ""  # a finished screen, resumed: nothing to judge, nothing to say
    note = too_small_note(200, 2)
    assert "too few to gain from 2 workers" in note and "--workers 0" in note


def test_workers_get_runs_of_decreasing_length_covering_every_chunk_once():
    todo = [(k, 20 * k, None) for k in range(50)]
    for w in (1, 2, 3, 8):
        b = chunk_runs(todo, w)
        assert [c for run in b for c in run] == todo
        sizes = [len(r) for r in b]
        assert sizes == sorted(sizes, reverse=True) and sizes[-1] == 1
        assert sizes[0] == -(-50 // (TASKS_PER_WORKER * w))  # the first run: its share of the whole
        assert len(b) < 50  # fewer tasks than chunks
    assert [len(r) for r in chunk_runs(todo, 2)][:4] == [13, 10, 7, 5]
    assert chunk_runs(todo[:3], 2) == [[t] for t in todo[:3]]


_CYCLE_AT_EXIT = """
import os, sys
class Cycle:
    def __del__(self, _write=os.write):
        _write(1, b"collected")
c = Cycle(); c.me = c
if sys.argv[1] == "skip":
    from spatialmech.services.screening import _skip_final_collections
    _skip_final_collections()
del c
"""


@pytest.mark.parametrize("skip", [False, True])
def test_a_worker_skips_the_final_collections_at_exit(skip):
    """The worker plugin's set-up freezes the objects out of the collector at exit: a reference
    cycle still alive then is left to the operating system (not finalized), where a plain
    interpreter collects it (issue 29: a worker with the kernels loaded closed in 0.46-0.50 s,
    0.09-0.10 s with this)."""
    p = subprocess.run([sys.executable, "-c", _CYCLE_AT_EXIT, "skip" if skip else "plain"], capture_output=True,
                       text=True, check=True)
    assert p.stdout == ("" if skip else "collected")


def test_the_screen_own_cluster_gives_its_workers_the_quick_exit_and_leaves_ctrl_c_to_the_screen():
    before = signal.getsignal(signal.SIGINT)
    cluster, client = _local_cluster(1)
    try:
        names = client.run(lambda dask_worker: sorted(dask_worker.plugins))
        ignored = client.run(lambda: signal.getsignal(signal.SIGINT) == signal.SIG_IGN)
    finally:
        client.close()
        cluster.close()
    assert [("spatialmech-quick-exit" in v) for v in names.values()] == [True]
    assert list(ignored.values()) == [True]  # the worker ignores Ctrl-C ...
    assert signal.getsignal(signal.SIGINT) is before  # ... and this process handles it as before


def test_a_run_of_chunks_stops_at_its_next_chunk_once_the_screen_is_stopped(family, monkeypatch):
    """A task cannot be cancelled once it runs: ``judge_chunks`` asks the screen's stop event
    between chunks (here at every chunk) and returns the chunks judged so far."""
    from distributed import Client, Event, LocalCluster

    from spatialmech.services import screening

    monkeypatch.setattr(screening, "STOP_POLL_S", 0.0)  # an in-process worker sees the module's value
    pool = dyad_pool(family, 0.5)
    sets, _ = candidate_sets(pool, 4, seed=0, separation=0.5)
    todo = [(k, k, sets[k:k + 1]) for k in range(4)]
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as c, \
            Client(c) as client:
        stop = Event("test-screen-stop", client=client)
        going = client.submit(judge_chunks, pool, todo, stop.name, pure=False).result()
        stop.set()
        stopped = client.submit(judge_chunks, pool, todo, stop.name, pure=False).result()
    assert [k for k, _ in going] == [0, 1, 2, 3] and stopped == []
    assert all(len(rows) == 1 for _, rows in going)


def test_ctrl_c_on_a_screen_with_workers_ends_it_cleanly(tmp_path):
    """Ctrl-C reaches the whole foreground process group: the command says it was interrupted
    (exit 130) and no worker prints a traceback (each printed its event loop's KeyboardInterrupt
    until stop 42); the workers are gone soon after."""
    out = tmp_path / "i.parquet"
    p = subprocess.Popen([sys.executable, "-m", "spatialmech", "screen", "--candidates", "600", "--chunk-size", "2",
                          "--workers", "2", "--starts", "20", "--out", str(out)], stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        seen = []
        for line in p.stderr:
            seen.append(line)
            if "judging" in line:
                break
        else:
            pytest.fail("the screen ended before judging: " + "".join(seen)[-2000:])
        time.sleep(1.0)
        os.killpg(p.pid, signal.SIGINT)
        err = p.stderr.read()
        assert p.wait(timeout=60) == 130, err[-2000:]
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
    assert "interrupted: the chunks written so far are kept" in err and "Traceback" not in err, err[-2000:]
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline:
        try:
            os.killpg(p.pid, 0)
        except ProcessLookupError:
            break
        time.sleep(0.1)
    else:
        os.killpg(p.pid, signal.SIGKILL)
        pytest.fail("worker processes outlived the interrupted screen by 20 s")


@pytest.fixture(scope="module")
def family(paper_a_cs_family):
    return dataclasses.replace(paper_a_cs_family, picks=())


@pytest.mark.slow
def test_the_stored_family_round_trips_exactly(family, tmp_path):
    task = cs_task(five_cs_positions())
    key = sf.family_key(task, 60, 0)
    path = tmp_path / "f.npz"
    sf.save_family(family, path, key)
    got = sf.load_family(path, task, key)
    assert got is not None and len(got.branches) == len(family.branches)
    for a, b in zip(got.branches, family.branches, strict=True):
        assert np.array_equal(a.points, b.points) and np.array_equal(a.arc, b.arc)
        assert (a.closed, a.ends, a.residual) == (b.closed, b.ends, b.residual)
    assert got.starts == family.starts and got.extent == family.extent
    pa, pb = dyad_pool(got, 0.5), dyad_pool(family, 0.5)
    assert np.array_equal(pa.vectors, pb.vectors)
    assert np.array_equal(candidate_sets(pa, 50)[0], candidate_sets(pb, 50)[0])
    # another task, seed or number of starts: another key, nothing read
    assert sf.family_key(task, 60, 1) != key and sf.family_key(task, 59, 0) != key
    assert sf.load_family(path, task, sf.family_key(task, 60, 1)) is None
    # a damaged file is ignored (and said so), never half read
    path.write_bytes(b"not a family")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        assert sf.load_family(path, task, key) is None
    assert any("ignoring the stored CS family" in str(x.message) for x in w)


@pytest.mark.slow
def test_a_screen_reuses_the_cached_then_the_stored_family_with_the_same_rows(family, tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    monkeypatch.setenv(sf.CACHE_ENV, str(cache))
    task = cs_task(five_cs_positions())
    key = sf.family_key(task, 60, 0)
    sf.save_family(family, cache / "cs-families" / f"{key}.npz", key)  # as a first screen would have
    ref = run_screen(five_cs_positions(), tmp_path / "given", candidates=6, chunk_size=3, workers=0, family=family,
                     top=0)
    a = run_screen(five_cs_positions(), tmp_path / "a", candidates=6, chunk_size=3, workers=0, top=0)
    assert a.family["source"] == "cache" and ref.family["source"] == "given"
    assert (tmp_path / "a" / sf.FAMILY_FILE).is_file()
    assert strip(read_rows(tmp_path / "a")) == strip(read_rows(tmp_path / "given"))
    # the same screen again into the same dataset, the cache gone: the dataset's own copy
    (cache / "cs-families" / f"{key}.npz").unlink()
    b = run_screen(five_cs_positions(), tmp_path / "a", candidates=6, chunk_size=3, workers=0, top=0)
    assert b.family["source"] == "dataset" and b.judged_this_run == 0 and b.chunks_resumed == 2
    # a run of chunks judged in one task gives the rows of the chunks judged one by one
    pool = dyad_pool(family, 0.5)
    sets = candidate_sets(pool, 6)[0]
    runs = judge_chunks(pool, [(0, 0, sets[:3]), (1, 3, sets[3:])])
    assert [k for k, _ in runs] == [0, 1]
    assert strip([r for _, rows in runs for r in rows]) == strip(read_rows(tmp_path / "given"))
