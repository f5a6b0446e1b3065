"""The light core and its extras (issue 31): a command whose extra is not installed says which
extra to install and exits with code 2; the core commands run with every extra hidden.

An extra is "not installed" in a subprocess whose first meta-path finder raises ImportError for
the extra's top-level modules (as a missing package does), so the test does not depend on what
this environment has installed.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import spatialmech as sm
from spatialmech.errors import EXTRAS, MissingExtraError, require

ROOT = Path(__file__).resolve().parents[1]

#: Runs the command line with the modules named in argv[1] (comma-separated) hidden.
_HIDE = """
import importlib.abc, runpy, sys
hidden = set(sys.argv[1].split(","))
class Hide(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in hidden:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None
sys.meta_path.insert(0, Hide())
for m in [m for m in sys.modules if m.split(".")[0] in hidden]:
    del sys.modules[m]
sys.argv = ["spatialmech", *sys.argv[2:]]
runpy.run_module("spatialmech", run_name="__main__")
"""

ALL_EXTRA_MODULES = sorted({m for mods in EXTRAS.values() for m in mods})


def _env() -> dict[str, str]:
    """The subprocesses' environment: this tree's package, the Python reference engine (these
    tests are about the extras, not the compiler: no kernel loading or first-run compile)."""
    return {**os.environ, "PYTHONPATH": str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""),
            "SPATIALMECH_PURE": "1"}


def run_hidden(hidden, *args, cwd=None):
    return subprocess.run([sys.executable, "-c", _HIDE, ",".join(hidden), *args], capture_output=True, text=True,
                          env=_env(), cwd=cwd, timeout=600)


# One command per extra (small arguments: each one fails before any work).
CASES = [
    ("plot", ["view", "four-sps-cu", "--out", "v.html"], "the viewer"),
    ("plot", ["singularity", "four-sps-cu", "--position", "1", "--plot", "s.png"], "--plot"),
    ("plot", ["demo", "--out", "report"], "the report"),
    ("studio", ["studio", "--no-browser"], "the studio"),
    ("sim", ["validate", "rssr"], "validation"),
    ("screen", ["screen", "--out", "screen"], "screening"),
    ("cad", ["export", "rssr", "part.stl", "--along", "30", "--samples", "3"], "the STL export"),
]


@pytest.mark.parametrize("extra, args, what", CASES, ids=[f"{c[0]}-{c[1][0]}" for c in CASES])
def test_a_missing_extra_names_itself_and_exits_2(tmp_path, extra, args, what):
    r = run_hidden(EXTRAS[extra], *args, cwd=tmp_path)
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    last = r.stderr.strip().splitlines()[-1]
    assert last.startswith(f"error: {what} needs the optional extra '{extra}'"), last
    assert f"pip install 'spatialmech[{extra}]'" in last
    assert not list(tmp_path.iterdir()), "nothing is written when the extra is missing"


#: Runs Python code (argv[2]) with the modules named in argv[1] hidden (as _HIDE).
_HIDE_CODE = _HIDE.split("sys.argv = ")[0] + "exec(sys.argv[2])\n"


def run_hidden_code(hidden, code: str, cwd=None):
    return subprocess.run([sys.executable, "-c", _HIDE_CODE, ",".join(hidden), code], capture_output=True, text=True,
                          env=_env(), cwd=cwd, timeout=600)


def test_the_notebook_widget_without_its_extra_names_it(tmp_path):
    """``sm.studio`` (the Jupyter widget) without anywidget: a MissingExtraError naming the
    ``notebook`` extra, raised by the call (``import spatialmech`` and ``sm.studio`` itself, the
    attribute, work on the core install: ``from spatialmech import *`` does not break)."""
    code = ("import spatialmech as sm\nfrom spatialmech import *\nfrom spatialmech.errors import MissingExtraError\n"
            "try:\n    sm.studio('rssr')\nexcept MissingExtraError as e:\n"
            "    print(type(e).__name__, isinstance(e, ImportError), e)\n")
    r = run_hidden_code(EXTRAS["notebook"], code, cwd=tmp_path)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.startswith("MissingExtraError True sm.studio (the studio in Jupyter) needs the optional extra "
                               "'notebook'"), r.stdout
    assert "pip install 'spatialmech[notebook]'" in r.stdout


#: Runs the command lines given as JSON (argv[3]) one after the other in one process (one
#: interpreter start for all) and prints their outputs as a JSON list.
_COMMANDS = """
import contextlib, io, json, sys
from spatialmech.interfaces.cli import main
outs = []
for argv in json.loads(sys.argv[3]):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        try:
            main(argv)
        except SystemExit as e:
            if e.code not in (0, None):
                raise
    outs.append(buf.getvalue())
print(json.dumps(outs))
"""


def test_core_commands_run_with_every_extra_hidden(tmp_path):
    commands = [["mobility", "four-sps-cu", "--json"],
                ["ik", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "34.38", "-5.73", "11.46", "--json"]]
    r = subprocess.run([sys.executable, "-c", _HIDE_CODE, ",".join(ALL_EXTRA_MODULES), _COMMANDS, json.dumps(commands)],
                       capture_output=True, text=True, env=_env(), cwd=tmp_path, timeout=600)
    assert r.returncode == 0, r.stderr[-2000:]
    mobility, ik = (json.loads(out) for out in json.loads(r.stdout))
    assert mobility["modes"][0]["dof"] == 4
    assert ik["reachable"] is True


def test_an_import_error_of_an_extra_module_maps_to_its_extra():
    e = MissingExtraError.from_import_error(ModuleNotFoundError("No module named 'plotly.graph_objects'",
                                                                name="plotly.graph_objects"))
    assert e is not None and (e.extra, e.module) == ("plot", "plotly")
    assert isinstance(e, ImportError) and isinstance(e, ValueError)
    assert MissingExtraError.from_import_error(ModuleNotFoundError("x", name="numpyy")) is None
    assert MissingExtraError.from_import_error(ValueError("plotly")) is None


def test_require_checks_the_named_modules(monkeypatch):
    monkeypatch.setitem(sys.modules, "anywidget", None)  # import anywidget raises ImportError
    with pytest.raises(MissingExtraError, match=r"pip install 'spatialmech\[notebook\]'"):
        require("notebook", what="the widget")
    with pytest.raises(KeyError, match="unknown extra"):
        require("plots")


def test_the_extras_table_matches_pyproject():
    """errors.EXTRAS (what the messages name) and pyproject.toml's extras (what pip installs)
    list the same extras; the core dependencies bring none of the extras' packages."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = project["optional-dependencies"]
    assert set(EXTRAS) <= set(extras)
    assert set(extras) - set(EXTRAS) == {"all", "test", "docs"}  # docs: building the site, not a feature
    assert extras["all"] == [f"spatialmech[{','.join(EXTRAS)}]"]
    assert "spatialmech[all]" in extras["test"]
    core = " ".join(project["dependencies"]).lower()
    for heavy in ("matplotlib", "plotly", "mujoco", "fastapi", "uvicorn", "dask", "pyarrow", "anywidget", "trimesh"):
        assert heavy not in core, heavy


#: Every facade verb that imports an optional package, called with that package hidden: the
#: module hidden, the extra named, what the call needs (small arguments; each fails first).
FACADE = [
    ("plotly", "plot", lambda d: sm.view("rssr", d / "v.html")),
    ("matplotlib", "plot", lambda d: sm.report("rssr", d / "r")),
    ("mujoco", "sim", lambda d: sm.demo(d / "report")),
    ("plotly", "plot", lambda d: sm.studio_session("rssr")),
    ("pyarrow", "screen", lambda d: sm.screen(out=d / "s.parquet", candidates=2)),
    ("mujoco", "sim", lambda d: sm.validate("rssr")),
    ("build123d", "cad", lambda d: sm.export("rssr", d / "p.step")),
    ("manifold3d", "cad", lambda d: sm.export("rssr", d / "p.glb", along=[0.5], samples=2)),
    ("matplotlib", "plot", lambda d: sm.defects("five-cs-1", plot=d / "figs")),
    ("matplotlib", "plot", lambda d: sm.synth_rccc(plot=d / "figs")),
    ("matplotlib", "plot", lambda d: sm.parasitic("three-rps", {"a2": (-0.1, 0.1, 3)}, at={"z": 0.33},
                                                  plot=d / "p.png")),
    ("anywidget", "notebook", lambda d: sm.studio("rssr")),
    ("fastapi", "studio", lambda d: sm.studio_app("rssr")),
]


@pytest.mark.parametrize("module, extra, call", FACADE, ids=[f"{c[1]}-{k}" for k, c in enumerate(FACADE)])
def test_a_facade_verb_requires_its_extra_first(tmp_path, monkeypatch, module, extra, call):
    """In process: ``import MODULE`` fails (``sys.modules[MODULE] = None``); the verb raises the
    MissingExtraError of its extra before writing anything."""
    monkeypatch.setitem(sys.modules, module, None)
    with pytest.raises(MissingExtraError) as e:
        call(tmp_path)
    assert e.value.extra == extra and e.value.module == module
    assert not list(tmp_path.iterdir()), "nothing is written when the extra is missing"


def _with_dependencies(extra: str, extras: dict) -> set[str]:
    """``extra`` and the extras its pyproject entry pulls in (``studio`` -> ``plot``)."""
    out = {extra}
    for req in extras[extra]:
        if req.startswith("spatialmech["):
            for e in req[len("spatialmech["):-1].split(","):
                out |= _with_dependencies(e, extras)
    return out


#: One command per extra, run with every *other* extra's modules hidden: the extra alone (with
#: the extras it pulls in) is enough for its commands (a CLI command line, or Python code that
#: prints ``reached``).  Small arguments: about a second each.
ALONE = [
    ("plot", ["view", "rssr", "--motion", "demo", "--frames", "2", "--plotly", "cdn", "--out", "v.html"], None),
    ("sim", ["validate", "rssr", "--poses", "2", "--arc", "0.1", "--json"], None),
    # screening runs a Dask job (seconds even for 2 candidates): here its service imports, with
    # the other extras hidden; tests/test_screening.py runs it
    ("screen", None, "from spatialmech.services.screening import run_screen\nprint('reached')\n"),
    ("cad", ["export", "rssr", "p.stl", "--json"], None),
    ("studio", None, "from fastapi.testclient import TestClient\nimport spatialmech as sm\n"
                     "c = TestClient(sm.studio_app('rssr'))\n"
                     "print(c.post('/api/drive', json={'actuators': [10.0]}).json()['status'])\n"),
    ("notebook", None, "import spatialmech as sm\nprint(sm.studio('rssr').drive([10.0]).status)\n"),
]


def test_every_extra_has_a_command_that_runs_alone():
    assert sorted(e for e, _, _ in ALONE) == sorted(EXTRAS)


@pytest.mark.parametrize("extra, args, code", ALONE, ids=[c[0] for c in ALONE])
def test_an_extra_alone_runs_its_command(tmp_path, extra, args, code):
    """``pip install 'spatialmech[EXTRA]'`` is enough for the extra's command: it runs (exit 0)
    with the modules of every extra it does not pull in hidden."""
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["optional-dependencies"]
    keep = {m for e in _with_dependencies(extra, extras) for m in EXTRAS[e]}
    hidden = sorted(set(ALL_EXTRA_MODULES) - keep)
    r = run_hidden(hidden, *args, cwd=tmp_path) if args else run_hidden_code(hidden, code, cwd=tmp_path)
    assert r.returncode == 0, (extra, r.stderr[-2000:])
    if code is not None:
        assert r.stdout.strip().endswith("reached"), r.stdout
