import json
import os
import shutil
import socket
import threading
import time

import numpy as np
import pytest
from hypothesis import settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import spatialmech as sm
from spatialmech.geometry.rotations import transform

from .browser_support import CHROMEDRIVER, CHROMIUM, FLAGS, TIMEOUT, missing

# No per-example deadline (machines differ in load); in CI the examples are derandomised so a
# run is reproducible (locally they stay random, to keep finding new cases).
settings.register_profile("spatialmech", deadline=None)
settings.register_profile("spatialmech-ci", deadline=None, derandomize=True)
settings.load_profile("spatialmech-ci" if os.environ.get("CI") else "spatialmech")

# The tests' command lines compile in the foreground, as they always did (no background compile
# and pure-Python first run on a fresh cache: spatialmech.services.first_run; the tests of that
# path, tests/test_first_run.py, turn it on in their own subprocesses).
os.environ.setdefault("SPATIALMECH_BACKGROUND_COMPILE", "0")


def _lock_numba_cache_saves() -> None:
    """Make numba's on-disk cache safe for the two pytest-xdist workers (README: ``pytest -n 2``).

    numba writes each file atomically, but ``IndexDataCacheFile.save`` reads the index, picks the
    first free data-file number and writes both back without a lock: two processes saving new
    signatures of one function at the same moment can both pick ``<fn>.1.nbc``, so one index entry
    then names the other signature's machine code (numba issue #10128 discusses a file lock).
    Here each save holds an exclusive ``flock`` on one lock file of that cache directory; loads
    need none (a data file only ever holds the code of the key that names it)."""
    try:
        import fcntl

        from numba.core import caching
    except ImportError:  # no numba (pure-Python fallback of kinematics/compiled/jit.py) or no fcntl
        return
    save = getattr(getattr(caching, "IndexDataCacheFile", None), "save", None)
    if save is None or getattr(save, "spatialmech_locked", False):  # another numba layout: leave it alone
        return

    def locked_save(self, key, data):
        os.makedirs(self._cache_path, exist_ok=True)
        with open(os.path.join(self._cache_path, "spatialmech-numba-save.lock"), "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            try:
                return save(self, key, data)
            finally:
                fcntl.flock(lock, fcntl.LOCK_UN)

    locked_save.spatialmech_locked = True
    caching.IndexDataCacheFile.save = locked_save


_lock_numba_cache_saves()


@pytest.fixture(scope="session")
def schema_validator():
    """``schema_validator(command)``: a JSON Schema validator of ``command``'s shipped schema
    (``spatialmech/interfaces/schemas/``), its references to ``common.schema.json`` resolved."""
    from jsonschema import Draft202012Validator
    from referencing import Registry, Resource

    from spatialmech.interfaces.common import load_schema

    common = load_schema("common")
    registry = Registry().with_resource(common["$id"], Resource.from_contents(common))
    return lambda command: Draft202012Validator(load_schema(command), registry=registry)


@pytest.fixture(scope="session")
def studio_ok(schema_validator):
    """``studio_ok(r)``: a studio answer (an HTTP response, or a ``studio --json`` document)
    checked: status 200, the envelope, the studio schema and the unit rule; returns the document."""
    from spatialmech.serialize import unit_rule_violations

    validator = schema_validator("studio")

    def check(r) -> dict:
        if hasattr(r, "status_code"):
            assert r.status_code == 200, r.text
            r = r.json()
        assert r["command"] == "studio" and r["schema_version"] == "2"
        errors = [(list(e.absolute_path), e.message[:200]) for e in validator.iter_errors(r)]
        assert not errors, errors[:3]
        assert unit_rule_violations(r) == []
        return r

    return check


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


finite = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
vec3 = st.lists(finite, min_size=3, max_size=3).map(np.array)
screw6 = st.lists(finite, min_size=6, max_size=6).map(np.array)
seeds = st.integers(0, 2**32 - 1)


def random_transform(seed: int) -> np.ndarray:
    r = np.random.default_rng(seed)
    return transform(Rotation.random(random_state=seed).as_matrix(), r.uniform(-5, 5, 3))


def built_once(tmp_path_factory, name: str, build, load):
    """``(directory, value)`` of an expensive build done once per test session.

    ``build(directory)`` computes the value and writes into the (empty) ``directory`` whatever
    ``load(directory)`` needs to give the same value back.  In one process this is just
    ``build`` into a fresh temporary directory.  Under pytest-xdist (``-n 2``) the workers share
    it: the first to ask builds it into the session's common temporary directory while holding a
    file lock; the others wait for the lock and ``load`` the result."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        out = tmp_path_factory.mktemp(name)
        return out, build(out)
    import fcntl

    shared = tmp_path_factory.getbasetemp().parent  # this session's directory, common to its workers
    # named after the run too: with --basetemp that directory outlives the session
    name = f"{name}-{os.environ.get('PYTEST_XDIST_TESTRUNUID', 'run')}"
    out, done = shared / name, shared / f"{name}.done"
    with open(shared / f"{name}.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            if not done.exists():
                shutil.rmtree(out, ignore_errors=True)
                out.mkdir()
                value = build(out)
                done.touch()
                return out, value
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)
    return out, load(out)


@pytest.fixture(scope="session")
def demo_report(tmp_path_factory):
    """``spatialmech demo`` built once for the whole session (about 25 s): ``(out_dir, results)``.
    The report tests, the regression test of its rows and the JSON-schema test of the ``demo``
    command all read this one run; nothing may modify ``results``.  Shared by the xdist workers
    (:func:`built_once`): what :func:`build_demo` returns is exactly its ``results.json``."""
    from spatialmech.present.report import build_demo

    # One process: both cores are busy with the xdist workers already, and a fork from a pytest
    # worker inherits whatever threads its earlier tests left (servers, browsers); the default
    # two-worker build is tested in a fresh process (test_report.py, two workers).
    return built_once(tmp_path_factory, "demo", lambda out: build_demo(out, progress=False, workers=1),
                      lambda out: json.loads((out / "results.json").read_text(encoding="utf-8")))


@pytest.fixture(scope="session")
def paper_a_cs_family(tmp_path_factory):
    """Paper A's CS dyad family of the seven positions of table 9 (``synthesize_cs`` with 60
    starts, seed 0, five picks; about 4 s), for every test that analyses that family
    (tests/test_cs_dyads.py, test_regressions.py, test_screening.py); frozen, not modified.
    Shared by the xdist workers as a pickle (:func:`built_once`)."""
    import pickle

    from spatialmech.catalog.papers import five_cs_positions
    from spatialmech.synthesis.cs_dyads import synthesize_cs

    def build(out):
        family = synthesize_cs(five_cs_positions(), n_starts=60, seed=0, pick=5)
        (out / "family.pickle").write_bytes(pickle.dumps(family))
        return family

    return built_once(tmp_path_factory, "paper-a-cs-family", build,
                      lambda out: pickle.loads((out / "family.pickle").read_bytes()))[1]


#: The seconds each test file took in a full run (tests/file_seconds.txt, written by
#: ``.ci/file_seconds.py`` from a JUnit XML); a file not listed there counts as ``UNLISTED_SECONDS``.
FILE_SECONDS = os.path.join(os.path.dirname(__file__), "file_seconds.txt")
UNLISTED_SECONDS = 10.0


def file_seconds() -> dict[str, float]:
    """``{file name: seconds}`` of tests/file_seconds.txt (lines ``seconds name``, ``#`` comments)."""
    out = {}
    with open(FILE_SECONDS, encoding="utf-8") as f:
        for line in f:
            line = line.split("#", 1)[0].split()
            if line:
                out[line[1]] = float(line[0])
    return out


def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist, the test files in order of the time they take, longest first, and in
    each file the tests that read the session's demo run (``demo_report``) last, the order
    otherwise kept.  A single process keeps the file order.

    - With ``--dist loadfile`` (README) a worker takes the next file of the collection when it
      is nearly done with its own: longest first keeps the last files short, so the two workers
      end together (pytest-xdist's own order, most tests first, put the few-but-slow files --
      browsers, homotopy, Dask -- at the end, and one worker ran alone for minutes).  That needs
      ``--no-loadscope-reorder`` (pyproject.toml's addopts).  The times: tests/file_seconds.txt.
    - A file's tests run in collection order, so the demo's readers run last in their file: a
      worker reaches them after the rest of it, by which time the other worker has often built
      the demo already (without this, one worker sat about 20 s waiting for the lock of
      :func:`built_once`)."""
    if not os.environ.get("PYTEST_XDIST_WORKER"):
        return
    weight = file_seconds()
    rank = {}
    for n, item in enumerate(items):
        name = os.path.basename(str(item.path))
        rank.setdefault(name, (-weight.get(name, UNLISTED_SECONDS), n))
    key = {id(item): (rank[os.path.basename(str(item.path))], "demo_report" in getattr(item, "fixturenames", ()), n)
           for n, item in enumerate(items)}
    items.sort(key=lambda item: key[id(item)])


@pytest.fixture(scope="session", autouse=True)
def _screen_family_cache(tmp_path_factory):
    """Screens synthesise their CS dyad family once and cache it (services/screen_family.py): in
    the tests, in a session directory rather than the user's ~/.cache."""
    with pytest.MonkeyPatch.context() as m:
        m.setenv("SPATIALMECH_CACHE_DIR", str(tmp_path_factory.mktemp("spatialmech-cache")))
        yield


# The studio's page server and headless Chromium, shared by tests/test_studio_*browser.py (module
# scope: one server and one browser per test file, as before the move).
@pytest.fixture(scope="module")
def server():
    import uvicorn

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    srv = uvicorn.Server(uvicorn.Config(sm.studio_app("rssr"), host="127.0.0.1", port=port, log_level="warning"))
    th = threading.Thread(target=srv.run, daemon=True)
    th.start()
    t0 = time.time()
    while not srv.started and time.time() - t0 < TIMEOUT:
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}/"
    srv.should_exit = True
    th.join(10)


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    gone = missing()
    if gone:
        msg = f"headless Chromium test needs {', '.join(gone)} (apt-get install chromium chromium-driver; pip install selenium)"
        if os.environ.get("CI"):
            pytest.fail(msg + " -- CI is set, so this must run", pytrace=False)
        pytest.skip(msg)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    os.environ["SE_OFFLINE"] = "true"  # never let Selenium Manager download anything
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for f in FLAGS:
        opts.add_argument(f)
    opts.add_argument(f"--user-data-dir={tmp_path_factory.mktemp('chromium-studio')}")
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=opts)
    driver.set_page_load_timeout(TIMEOUT)
    try:
        yield driver
    finally:
        driver.quit()
