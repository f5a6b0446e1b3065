"""Benchmark: start-up and small matrices on one BLAS thread (issue 29), with the targets of the issue.

    python benchmarks/bench_startup.py [--json] [--quick]

Every target is printed with "met" or "NOT met" and the measured value; each measurement is a
fresh process (``sys.executable``, this checkout's ``src`` first on ``PYTHONPATH``), best of N:

- ``import_s``: wall time of ``python -c "import spatialmech"``. Target: < 0.3 s.
- ``models_cpu_s``: CPU time (user + system) of ``python -m spatialmech models``. Target: < 0.4 s.
- ``help_heavy_modules``: the heavy third-party packages ``spatialmech --help`` loads (scipy.spatial,
  numba, plotly, matplotlib, mujoco, dask, pyarrow, fastapi). Target: none.
- ``fk_all_s`` / ``fk_all_threads_s``: wall time of ``spatialmech fk delta --all`` with the BLAS cap
  (the default: one thread) and without it (``SPATIALMECH_BLAS_THREADS=0``: OpenBLAS's own pool);
  reported, no target (it depends on the cores and on the load of the machine).
- ``first_fk_s``: wall time of the first ``spatialmech fk four-sps-cu ... --all`` on a fresh install
  (an empty ``NUMBA_CACHE_DIR``; issue 31): the command answers on the Python engine while the
  kernels compile in a background process (stopped after the measurement). Target: < 5 s.
  ``first_fk_foreground_s`` is the same command compiling in the foreground
  (``SPATIALMECH_BACKGROUND_COMPILE=0``, the behaviour before issue 31), reported as the baseline of
  the same run (skipped by ``--quick``: a minute or more).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import subprocess
import sys
import time
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
TARGETS = {"import_s": 0.3, "models_cpu_s": 0.4, "first_fk_s": 5.0}
HEAVY = ("scipy.spatial", "numba", "plotly", "matplotlib", "mujoco", "dask", "pyarrow", "fastapi")
FK_ALL = ["fk", "delta", "--actuators", "5.73,11.46,-5.73", "--all"]
FIRST_FK = ["fk", "four-sps-cu", "--actuators", "0.2167,0.2390,0.2273,0.2069", "--all"]


def _env(**extra: str) -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), os.environ.get("PYTHONPATH", "")]),
            "SPATIALMECH_BACKGROUND_COMPILE": "0", **extra}


def _first_call(background: bool) -> float:
    """Wall seconds of the first fk on an empty numba cache; a background compilation it starts
    is stopped (its process group id is the first line of the lock file)."""
    import signal
    import tempfile

    with tempfile.TemporaryDirectory() as cache:
        try:
            return _run(["-m", "spatialmech", *FIRST_FK],
                        _env(NUMBA_CACHE_DIR=cache, SPATIALMECH_BACKGROUND_COMPILE="1" if background else "0"))[0]
        finally:
            for lock in Path(cache).glob("spatialmech-kernels-*.lock"):
                with contextlib.suppress(ProcessLookupError, ValueError):
                    os.killpg(int(lock.read_text().split()[0]), signal.SIGTERM)


def _run(args: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Wall and CPU (user + system) seconds of one child process."""
    t0 = time.perf_counter()
    p = subprocess.Popen([sys.executable, *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(args)}: exit code {p.returncode}")
    return wall, usage.ru_utime + usage.ru_stime


def _best(args: list[str], n: int, **extra: str) -> tuple[float, float]:
    runs = [_run(args, _env(**extra)) for _ in range(n)]
    return min(w for w, _ in runs), min(c for _, c in runs)


def _help_heavy() -> list[str]:
    code = ("import runpy, sys\nsys.argv = ['spatialmech', '--help']\ntry:\n    runpy.run_module('spatialmech', "
            "run_name='__main__')\nexcept SystemExit:\n    pass\nprint('LOADED', sorted({m for m in sys.modules "
            f"if any(m == h or m.startswith(h + '.') for h in {HEAVY!r})}}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=_env(), check=True).stdout
    return eval(out.split("LOADED", 1)[1])  # a printed list of names


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true", help="print the results as JSON")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    a = ap.parse_args()
    n = 3 if a.quick else 7
    _run(["-m", "spatialmech", *FK_ALL], _env())  # numba's cache and the OS's file cache warm
    res: dict[str, object] = {}
    res["import_s"] = _best(["-c", "import spatialmech"], n)[0]
    res["models_cpu_s"] = _best(["-m", "spatialmech", "models"], n)[1]
    res["help_heavy_modules"] = _help_heavy()
    k = 1 if a.quick else 3
    res["fk_all_s"], res["fk_all_cpu_s"] = _best(["-m", "spatialmech", *FK_ALL], k)
    res["fk_all_threads_s"], res["fk_all_threads_cpu_s"] = _best(["-m", "spatialmech", *FK_ALL], k,
                                                                 SPATIALMECH_BLAS_THREADS="0")
    res["first_fk_s"] = _first_call(background=True)
    res["first_fk_foreground_s"] = None if a.quick else _first_call(background=False)
    met = {"import_s": res["import_s"] < TARGETS["import_s"],  # type: ignore[operator]
           "first_fk_s": res["first_fk_s"] < TARGETS["first_fk_s"],  # type: ignore[operator]
           "models_cpu_s": res["models_cpu_s"] < TARGETS["models_cpu_s"],  # type: ignore[operator]
           "help_heavy_modules": not res["help_heavy_modules"]}
    if a.json:
        print(json.dumps({"results": res, "targets": TARGETS, "met": met}, indent=2))
        return
    word = {True: "met", False: "NOT met"}
    print(f"import spatialmech        {res['import_s']:.3f} s wall   (target < {TARGETS['import_s']} s: "
          f"{word[met['import_s']]})")
    print(f"spatialmech models        {res['models_cpu_s']:.3f} s CPU    (target < {TARGETS['models_cpu_s']} s: "
          f"{word[met['models_cpu_s']]})")
    print(f"spatialmech --help loads  {res['help_heavy_modules'] or 'no heavy package'}   "
          f"(target none: {word[met['help_heavy_modules']]})")
    print(f"fk delta --all            {res['fk_all_s']:.2f} s wall, {res['fk_all_cpu_s']:.2f} s CPU on one BLAS thread; "
          f"{res['fk_all_threads_s']:.2f} s wall, {res['fk_all_threads_cpu_s']:.2f} s CPU with OpenBLAS's pool")
    base = res["first_fk_foreground_s"]
    print(f"first fk, fresh install   {res['first_fk_s']:.2f} s wall   (target < {TARGETS['first_fk_s']} s: "
          f"{word[met['first_fk_s']]})" + ("" if base is None else f"; compiling in the foreground: {base:.1f} s "
                                            f"({base / res['first_fk_s']:.0f}x)"))  # type: ignore[operator]


if __name__ == "__main__":
    main()
