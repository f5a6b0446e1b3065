"""Start-up and small matrices on one thread (issue 29): what ``import spatialmech``, ``spatialmech
--help`` and ``spatialmech models`` load (module sets, never timings: the timings are in
benchmarks/bench_startup.py), and the BLAS thread cap of the verbs and the command line."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import spatialmech as sm
from spatialmech.api import constants
from spatialmech.api.threads import blas_threads, one_blas_thread

SRC = Path(__file__).resolve().parents[1] / "src"
#: Third-party packages a start-up must not load: each costs a tenth of a second to a second.
HEAVY = ("scipy.spatial", "scipy.optimize", "numba", "llvmlite", "plotly", "matplotlib", "mujoco", "dask", "pyarrow",
         "fastapi")

#: Run a command line in-process after ``import sys``, then print the heavy modules loaded.
_PROBE = """
import json, runpy, sys
heavy = {heavy!r}
sys.argv = ["spatialmech", *({argv!r} or [])]
if {argv!r} is None:
    import spatialmech
else:
    try:
        runpy.run_module("spatialmech", run_name="__main__")
    except SystemExit:
        pass
loaded = sorted(m for m in sys.modules if any(m == h or m.startswith(h + ".") for h in heavy))
print("\\nLOADED " + json.dumps(loaded))
"""


def _loaded(argv: list[str] | None) -> list[str]:
    code = _PROBE.format(heavy=HEAVY, argv=argv)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0, p.stderr
    line = [x for x in p.stdout.splitlines() if x.startswith("LOADED ")][-1]
    return json.loads(line[len("LOADED "):])


@pytest.mark.parametrize("argv", [None, ["--help"], ["models"], ["fk", "--help"]],
                         ids=["import", "--help", "models", "fk --help"])
def test_start_up_loads_no_heavy_third_party_package(argv):
    assert _loaded(argv) == []


def test_the_probe_sees_a_heavy_package_when_one_is_loaded():
    assert "numba" in _loaded(["fk", "delta", "--actuators", "5.73,11.46,-5.73"])  # the kernels do load on use


def test_lazy_names_are_the_eager_ones():
    assert set(sm.__all__) <= set(dir(sm)) and set(sm.api.__all__) <= set(dir(sm.api))
    for name in sm.__all__:
        assert getattr(sm, name) is not None, name
    assert sm.fk is sm.api.fk and sm.Mechanism is sm.api.Mechanism
    import spatialmech.api.maps
    import spatialmech.api.stiffness  # noqa: F401
    assert callable(sm.api.maps) and callable(sm.api.stiffness) and sm.maps is sm.api.maps
    assert isinstance(sm.__version__, str)
    with pytest.raises(AttributeError):
        sm.no_such_name  # noqa: B018


def test_a_screen_worker_does_not_import_the_synthesis_it_does_not_run():
    """A screen's worker unpickles the dyad pool and judges candidates: it imports
    ``spatialmech.synthesis`` (its names load on first use, PEP 562) and the screening modules,
    not SciPy's optimisers nor the other synthesis modules (issue 29: a worker's fixed cost)."""
    code = ("import sys, spatialmech.services.screening, spatialmech.analysis.defects\n"
            "print('LOADED', sorted(m for m in ('scipy.optimize', 'spatialmech.synthesis.tasks', "
            "'spatialmech.synthesis.burmester', 'spatialmech.synthesis.rccc') if m in sys.modules))")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")])}
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=300)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip().splitlines()[-1] == "LOADED []", p.stdout
    import spatialmech.synthesis as syn

    assert set(syn.__all__) <= set(dir(syn))
    for name in syn.__all__:
        assert getattr(syn, name).__module__.startswith("spatialmech.synthesis."), name
    with pytest.raises(AttributeError, match="no_such_name"):
        syn.no_such_name  # noqa: B018


def test_the_constants_module_agrees_with_the_analyses():
    from spatialmech.analysis.workspace import COORDINATES, MAX_POSES
    from spatialmech.model.task import TASK_NAMES

    assert constants.WORKSPACE_COORDINATES == COORDINATES
    assert constants.WORKSPACE_MAX_POSES == MAX_POSES
    assert constants.TASK_COORDINATES == TASK_NAMES


# ------------------------------------------------------------------ one BLAS thread
threadpoolctl = pytest.importorskip("threadpoolctl")


def _blas_threads() -> list[int]:
    import scipy.linalg  # noqa: F401  (its own OpenBLAS, as in the verbs)

    return [d["num_threads"] for d in threadpoolctl.threadpool_info() if d["user_api"] == "blas"]


def test_a_verb_runs_on_one_blas_thread_and_restores_the_callers_setting():
    seen = []

    @one_blas_thread
    def verb():
        seen.append(_blas_threads())
        return 7

    with threadpoolctl.threadpool_limits(2, "blas"):
        before = _blas_threads()
        assert verb() == 7
        assert _blas_threads() == before == [2] * len(before)
    assert seen == [[1] * len(before)]


def test_the_api_verbs_carry_the_cap_and_it_nests():
    for verb in (sm.fk, sm.ik, sm.workspace, sm.maps, sm.defects, sm.screen, sm.track, sm.stiffness_map):
        assert getattr(verb, "__wrapped__", None) is not None, verb.__name__
    with threadpoolctl.threadpool_limits(2, "blas"):
        with blas_threads():
            with blas_threads():
                assert set(_blas_threads()) == {1}
            assert set(_blas_threads()) == {1}
        assert set(_blas_threads()) == {2}


def test_fk_all_solutions_inside_runs_on_one_thread(monkeypatch):
    seen = []
    real = np.linalg.svd

    def svd(*args, **kwargs):
        seen.append(max(_blas_threads()))
        return real(*args, **kwargs)

    monkeypatch.setattr(np.linalg, "svd", svd)
    with threadpoolctl.threadpool_limits(2, "blas"):
        sm.fk("delta", [0.1, 0.2, -0.1], all_solutions=True)
        assert set(_blas_threads()) == {2}
    assert seen and set(seen) == {1}


def test_the_environment_sets_the_cap(monkeypatch):
    monkeypatch.setenv("SPATIALMECH_BLAS_THREADS", "0")
    with threadpoolctl.threadpool_limits(2, "blas"), blas_threads():
        assert set(_blas_threads()) == {2}
