"""The first command on a fresh install (issue 31): with no compiled kernels (an empty
``NUMBA_CACHE_DIR``) the command line says so in one line, starts the compilation in a background
process and answers on the pure-Python engine, with the same answer as the compiled engine."""

from __future__ import annotations

import contextlib
import io
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

import spatialmech as sm
from spatialmech.services import first_run

ROOT = Path(__file__).resolve().parents[1]
IK = ["ik", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "34.38", "-5.73", "11.46", "--json"]
LINE = "spatialmech: first run here: numerical kernels are compiling in the background"


def _cli(args, **env):
    full = {**os.environ, "PYTHONPATH": str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""), **env}
    return subprocess.run([sys.executable, "-m", "spatialmech", *args], capture_output=True, text=True, env=full,
                          timeout=600)


def _same(a, b, path="") -> None:
    """Equal JSON, numbers to 1e-9 relative (the two engines round differently in the last bits)."""
    if isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _same(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and isinstance(b, float):
        assert b == pytest.approx(a, rel=1e-9, abs=1e-12), path
    else:
        assert a == b, path


def _stop_warm_up(cache: Path) -> None:
    """Stop the background compilation the test started (its pid is in the lock file)."""
    for lock in cache.glob("spatialmech-kernels-*.lock"):
        pid = int(lock.read_text().split()[0])
        with contextlib.suppress(ProcessLookupError):
            os.killpg(pid, signal.SIGTERM)


@pytest.mark.slow
def test_a_fresh_cache_answers_on_the_python_engine_and_compiles_in_the_background(tmp_path):
    cache = tmp_path / "numba"
    cache.mkdir()
    try:
        r = _cli(IK, NUMBA_CACHE_DIR=str(cache), SPATIALMECH_BACKGROUND_COMPILE="1")
        assert r.returncode == 0, r.stderr[-2000:]
        assert r.stderr.count(LINE) == 1, r.stderr
        locks = list(cache.glob("spatialmech-kernels-*.lock"))
        assert len(locks) == 1 and int(locks[0].read_text()) > 0
        # a second command while the first compilation runs: no second compilation, no second line
        again = _cli(IK, NUMBA_CACHE_DIR=str(cache), SPATIALMECH_BACKGROUND_COMPILE="1")
        assert again.returncode == 0 and LINE not in again.stderr
        assert json.loads(again.stdout) == json.loads(r.stdout)
    finally:
        _stop_warm_up(cache)
    compiled = _cli(IK)  # the compiled engine (the suite's cache, foreground)
    _same(json.loads(r.stdout), json.loads(compiled.stdout))


def test_compiled_kernels_are_used_once_the_marker_exists(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv(first_run.BACKGROUND_ENV, "1")
    marker = first_run.marker_path()
    assert marker.parent == tmp_path and not marker.exists()
    marker.write_text("compiled\n")
    out = io.StringIO()
    assert first_run.start(out) is False and out.getvalue() == ""


def test_background_compilation_can_be_turned_off(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv(first_run.BACKGROUND_ENV, "0")
    out = io.StringIO()
    assert sm.first_run(out) is False and out.getvalue() == ""
    assert not list(tmp_path.iterdir())
    with pytest.raises(TypeError, match="stream"):
        sm.first_run(42)
