"""The numerical core (geometry, model, kinematics, analysis, synthesis) never imports plotting,
the model catalogue, the presentation layer, the command line or the API facade (issue 10, "Code
health"): figures live in ``spatialmech.present``, ready-made models in ``spatialmech.catalog``.

Two checks, each able to fail (the last tests feed them a violation):

- static: every ``import`` / ``from ... import`` statement of every core module, module level
  and inside functions (lazy imports included), relative ones resolved, and every
  ``importlib.import_module("...")`` / ``__import__("...")`` with a literal name;
- at run time: every core module imported in a fresh interpreter, one after the other, and
  ``sys.modules`` inspected after each; this also catches what the core's third-party imports
  drag in.  The package's own ``spatialmech/__init__.py`` is not run there (it imports the API
  facade, which may use the catalogue): a bare package object with the same ``__path__`` stands in
  for it, so each core module is imported exactly with what it imports itself.

Above the core (issue 26, "Every driver goes through ``sm.*``"), three more rules, checked
statically the same way (:func:`layer_violations`):

- ``interfaces/`` (the drivers: the command line, the studio's web app) imports only the facade
  (``spatialmech.api``, or ``spatialmech`` itself), ``spatialmech.errors``, ``.results``,
  ``.serialize``, ``.present`` and its own modules (and third-party packages);
- ``api/`` never imports ``interfaces/``;
- ``services/`` (orchestrators below the API: the screen, the studio session) never imports
  ``api/`` nor ``interfaces/``.
"""

from __future__ import annotations

import ast
import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
PKG = ROOT / "src" / "spatialmech"
CORE = ("geometry", "model", "kinematics", "analysis", "synthesis")
#: Third-party packages the core must not import (by top-level name).
FORBIDDEN_THIRD_PARTY = ("matplotlib", "plotly")
#: Parts of spatialmech the core must not import (each with its sub-modules).
FORBIDDEN_OWN = ("spatialmech.catalog", "spatialmech.present", "spatialmech.interfaces", "spatialmech.api")


def module_name(path: Path) -> str:
    """``src/spatialmech/a/b.py`` -> ``spatialmech.a.b`` (a package's ``__init__.py``: the package)."""
    parts = list(path.relative_to(PKG.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def core_files() -> list[Path]:
    return sorted(p for c in CORE for p in (PKG / c).rglob("*.py") if "__pycache__" not in p.parts)


def forbidden(name: str) -> str | None:
    """The rule ``name`` (an absolute module name) breaks, or ``None``."""
    if name.split(".")[0] in FORBIDDEN_THIRD_PARTY:
        return name.split(".")[0]
    for own in FORBIDDEN_OWN:
        if name == own or name.startswith(own + "."):
            return own
    return None


def imported_names(source: str, module: str, is_package: bool) -> list[tuple[int, str]]:
    """``(line, absolute module name)`` of every import in ``source`` (the module ``module``):
    for ``from X import a, b`` both ``X`` and ``X.a``, ``X.b`` (``a`` may be a sub-module)."""
    package = module if is_package else module.rpartition(".")[0]
    out: list[tuple[int, str]] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = importlib.util.resolve_name("." * node.level + base, package)
            out.append((node.lineno, base))
            out += [(node.lineno, f"{base}.{a.name}") for a in node.names if a.name != "*"]
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            f = node.func
            called = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
            arg = node.args[0].value
            if called in ("import_module", "__import__") and isinstance(arg, str):
                name = importlib.util.resolve_name(arg, package) if arg.startswith(".") else arg
                out.append((node.lineno, name))
    return out


def static_violations(path: Path, source: str | None = None) -> list[str]:
    """Messages ``file:line: imports NAME (RULE)`` for one core file."""
    source = path.read_text(encoding="utf-8") if source is None else source
    mod = module_name(path)
    rel = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
    first: dict[int, tuple[str, str]] = {}  # one message per statement: its first forbidden name
    for line, name in imported_names(source, mod, path.name == "__init__.py"):
        if (rule := forbidden(name)) is not None:
            first.setdefault(line, (name, rule))
    return [f"{rel}:{line}: imports {name} ({rule} is not allowed in the numerical core)"
            for line, (name, rule) in sorted(first.items())]


#: Run in a fresh interpreter: argv[1] is a JSON list of modules to import in order; prints a JSON
#: object {module: [forbidden modules that appeared in sys.modules while importing it]}.
_PROBE = r"""
import importlib, importlib.util, json, sys, types
spec = importlib.util.find_spec("spatialmech")
bare = types.ModuleType("spatialmech")
bare.__path__ = list(spec.submodule_search_locations)
bare.__spec__ = spec
sys.modules["spatialmech"] = bare   # the package, without running its __init__ (the API facade)
third, own = json.loads(sys.argv[2]), json.loads(sys.argv[3])

def bad(name):
    return name.split(".")[0] in third or any(name == o or name.startswith(o + ".") for o in own)

seen, out = set(), {}
for mod in json.loads(sys.argv[1]):
    importlib.import_module(mod)
    new = sorted(m for m in sys.modules if m not in seen and bad(m))
    seen.update(sys.modules)
    if new:
        out[mod] = new
print(json.dumps(out))
"""


def runtime_violations(modules: list[str]) -> dict[str, list[str]]:
    p = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(modules), json.dumps(FORBIDDEN_THIRD_PARTY),
                        json.dumps(FORBIDDEN_OWN)], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout.strip().splitlines()[-1])


# ------------------------------------------------------------------ the checks
def test_the_core_is_where_the_test_looks():
    files = core_files()
    assert {f.relative_to(PKG).parts[0] for f in files} == set(CORE)
    assert len(files) > 30, files  # a moved tree would make the checks below vacuous


def test_no_core_module_imports_plotting_or_presentation_statically():
    problems = [m for f in core_files() for m in static_violations(f)]
    assert not problems, "the numerical core must not import these (draw in spatialmech.present):\n" + "\n".join(
        problems)


def test_importing_every_core_module_loads_no_plotting_or_presentation():
    modules = [module_name(f) for f in core_files()]
    found = runtime_violations(modules)
    assert not found, "importing these core modules loaded forbidden modules: " + json.dumps(found, indent=1)


# ------------------------------------------------------------------ the checks can fail
@pytest.mark.parametrize(("where", "source", "expected"), [
    ("analysis/example.py", "import matplotlib.pyplot as plt\n", "matplotlib"),
    ("synthesis/example.py", "def f():\n    from plotly import graph_objects\n", "plotly"),
    ("analysis/example.py", "from ..present.viewer import write_viewer\n", "spatialmech.present"),
    ("kinematics/closed_forms/example.py", "from ... import catalog\n", "spatialmech.catalog"),
    ("model/__init__.py", "from ..catalog.papers import five_cs_positions\n", "spatialmech.catalog"),
    ("geometry/example.py", "from spatialmech.interfaces import cli\n", "spatialmech.interfaces"),
    ("analysis/workspace/example.py", "def f():\n    from ...api import mobility\n", "spatialmech.api"),
    ("kinematics/example.py", "import importlib\nm = importlib.import_module('matplotlib')\n", "matplotlib"),
    ("synthesis/example.py", "cmap = __import__('matplotlib').colormaps\n", "matplotlib"),
])
def test_the_static_check_flags_a_forbidden_import(where, source, expected):
    found = static_violations(PKG / where, source)  # the file is not written: its source is given
    assert len(found) >= 1 and all(expected in m for m in found), found


def test_the_static_check_accepts_allowed_imports():
    source = ("import numpy as np\nfrom ..closure import correct\nfrom ...errors import InputError\n"
              "from .. import tracking\nimport scipy.linalg\nfrom ...analysis.catalogue_free import x\n")
    assert static_violations(PKG / "kinematics" / "closed_forms" / "example.py", source) == []


def test_the_runtime_check_flags_a_module_that_loads_plotting():
    # a presentation module imported after a core one: its imports are attributed to it
    found = runtime_violations(["spatialmech.geometry.screws", "spatialmech.present.viewer"])
    assert "spatialmech.geometry.screws" not in found
    assert "plotly" in {m.split(".")[0] for m in found["spatialmech.present.viewer"]}, found


# ------------------------------------------------------------------ the engine's two backends (issue 26)
# The Python reference (everything under kinematics/ but the compiled package and the front that
# picks a backend) never imports the compiled package; so the compiled package may import the
# reference (its data types, chains, checks) without an import circle.
KIN = PKG / "kinematics"
COMPILED = "spatialmech.kinematics.compiled"
FRONT = "spatialmech.kinematics.backend"
#: Reference modules that host numba kernels of their own and so import the compiled package's
#: leaf modules (``jit``, ``kernels_se3``), never its engine; each with its reason.
#: None since issue 29: four_sps_cu.py's leg-length kernels moved to compiled/kernels_four_sps_cu.py (importing
#: even a leaf runs the compiled package's ``__init__``, i.e. numba and every kernel: a closed form must not).
KERNEL_HOSTS: dict[str, str] = {}
KERNEL_LEAVES = (f"{COMPILED}.jit", f"{COMPILED}.kernels_se3")


def reference_files() -> list[Path]:
    return sorted(p for p in KIN.rglob("*.py") if "__pycache__" not in p.parts and not p.is_relative_to(KIN / "compiled")
                  and module_name(p) != FRONT)


def compiled_imports(path: Path, source: str | None = None) -> list[str]:
    """Messages ``file:line: imports NAME`` for every import of the compiled package (or a module
    of it) in one reference file (a kernel host: of anything but the leaf modules)."""
    source = path.read_text(encoding="utf-8") if source is None else source
    mod = module_name(path)
    allowed = KERNEL_LEAVES if mod in KERNEL_HOSTS else ()
    first: dict[int, str] = {}
    for line, name in imported_names(source, mod, path.name == "__init__.py"):
        if (name == COMPILED or name.startswith(COMPILED + ".")) and not any(
                name == a or name.startswith(a + ".") for a in allowed):
            first.setdefault(line, name)
    rel = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
    return [f"{rel}:{line}: imports {name}" for line, name in sorted(first.items())]


def import_graph(files: list[Path]) -> dict[str, set[str]]:
    """``module -> the spatialmech modules it imports`` (every import, lazy ones included; a
    ``from P import m`` counts as importing ``P.m`` when that is a module of ``files``; importing
    ``a.b.c`` also runs the packages ``a.b`` -- not the root package, whose ``__init__`` is the
    API facade and imports everything)."""
    known = {module_name(p) for p in files}
    graph: dict[str, set[str]] = {}
    for p in files:
        mod = module_name(p)
        out = set()
        for _, name in imported_names(p.read_text(encoding="utf-8"), mod, p.name == "__init__.py"):
            while name and name not in known:
                name = name.rpartition(".")[0]
            while name.count("."):  # the module and the packages that hold it
                if name != mod and not mod.startswith(name + "."):
                    out.add(name)
                name = name.rpartition(".")[0]
        graph[mod] = out
    return graph


def reaches(graph: dict[str, set[str]], start: str, goal: str) -> list[str] | None:
    """An import path from ``start`` to ``goal`` (a module or a package: any module in it), or ``None``."""
    seen, todo = {start}, [[start]]
    while todo:
        path = todo.pop()
        for nxt in sorted(graph.get(path[-1], ())):
            if nxt == goal or nxt.startswith(goal + "."):
                return [*path, nxt]
            if nxt not in seen:
                seen.add(nxt)
                todo.append([*path, nxt])
    return None


def test_the_python_reference_never_imports_the_compiled_package():
    files = reference_files()
    assert len(files) > 20 and KIN / "closure.py" in files and KIN / "tracking.py" in files, files
    problems = [m for f in files for m in compiled_imports(f)]
    assert not problems, ("the Python reference must not import the compiled package (ask kinematics/backend.py "
                          "for the engine):\n" + "\n".join(problems))
    assert set(KERNEL_HOSTS) <= {module_name(f) for f in files}, "a kernel host moved: update KERNEL_HOSTS"


def test_no_import_cycle_between_closure_and_compiled():
    files = sorted(p for p in PKG.rglob("*.py") if "__pycache__" not in p.parts)
    graph = import_graph(files)
    closure = "spatialmech.kinematics.closure"
    assert reaches(graph, COMPILED, closure) is not None  # the graph sees the compiled package use the reference
    path = reaches(graph, closure, COMPILED)
    assert path is None, "closure.py reaches the compiled package: " + " -> ".join(path or [])
    assert reaches(graph, closure, FRONT) is None, "closure.py must not import the front (backend.py)"


def test_the_compiled_import_check_flags_a_violation():
    for where, source in [
        ("kinematics/closure.py", "def f():\n    from . import compiled\n"),
        ("kinematics/tracking.py", "from .compiled.engine import lstsq\n"),
        ("kinematics/homotopy/study.py", "from ..compiled.jit import njit\n"),
        ("kinematics/closed_forms/four_sps_cu.py", "from .. import compiled\n"),
        ("kinematics/closed_forms/sps.py", "from ..compiled.kernels_se3 import nb_sincos\n"),
        ("kinematics/position.py", "import importlib\nm = importlib.import_module('spatialmech.kinematics.compiled')\n"),
    ]:
        found = compiled_imports(PKG / where, source)
        assert len(found) == 1 and COMPILED in found[0], (where, found)
    ok = "from . import backend\nfrom .closure import correct\nfrom ..geometry.tolerances import current\n"
    assert compiled_imports(PKG / "kinematics" / "tracking.py", ok) == []
    host = "from ..compiled.jit import njit\nfrom ..compiled.kernels_se3 import nb_sincos\n"
    where = PKG / "kinematics" / "closed_forms" / "four_sps_cu.py"
    assert len(compiled_imports(where, host)) == 2  # no kernel host any more
    KERNEL_HOSTS[module_name(where)] = "a host may import the leaves"
    try:
        assert compiled_imports(where, host) == []
    finally:
        del KERNEL_HOSTS[module_name(where)]


def test_the_cycle_check_finds_a_cycle():
    graph = {"spatialmech.kinematics.closure": {"spatialmech.kinematics.leg_platform"},
             "spatialmech.kinematics.leg_platform": {"spatialmech.kinematics.compiled.legs"},
             "spatialmech.kinematics.compiled.legs": {"spatialmech.kinematics.closure"}}
    assert reaches(graph, "spatialmech.kinematics.closure", COMPILED) == [
        "spatialmech.kinematics.closure", "spatialmech.kinematics.leg_platform", "spatialmech.kinematics.compiled.legs"]
    graph["spatialmech.kinematics.leg_platform"] = set()
    assert reaches(graph, "spatialmech.kinematics.closure", COMPILED) is None


# ------------------------------------------------------------------ the layers above the core
#: Parts of spatialmech the drivers (``interfaces/``) may import, each with its sub-modules;
#: ``spatialmech`` itself (the package, i.e. the facade it re-exports) is allowed as the exact name.
DRIVER_ALLOWED = ("spatialmech.api", "spatialmech.errors", "spatialmech.results", "spatialmech.serialize",
                  "spatialmech.present", "spatialmech.interfaces")
#: Layer (a folder of the package) -> the parts of spatialmech it must not import.
LAYER_FORBIDDEN = {
    "api": ("spatialmech.interfaces",),
    "services": ("spatialmech.api", "spatialmech.interfaces"),
}


def _within(name: str, part: str) -> bool:
    return name == part or name.startswith(part + ".")


def layer_files(layer: str) -> list[Path]:
    return sorted(p for p in (PKG / layer).rglob("*.py") if "__pycache__" not in p.parts)


def layer_rule(layer: str, name: str) -> str | None:
    """Why ``name`` (an absolute module name) may not be imported from ``layer``, or ``None``."""
    if not _within(name, "spatialmech"):
        return None  # the standard library and third-party packages
    if layer == "interfaces":
        if name == "spatialmech" or any(_within(name, a) for a in DRIVER_ALLOWED):
            return None
        top = name.split(".")
        if len(top) == 2 and not (PKG / top[1]).is_dir() and not (PKG / f"{top[1]}.py").is_file():
            return None  # ``from spatialmech import mobility, __version__``: a name of the facade, not a module
        return "a driver imports only spatialmech.api (or spatialmech), errors, results, serialize, present"
    for part in LAYER_FORBIDDEN.get(layer, ()):
        if _within(name, part):
            return f"{layer}/ must not import {part}"
    return None


def layer_violations(path: Path, source: str | None = None) -> list[str]:
    """Messages ``file:line: imports NAME (RULE)`` for one file of ``interfaces/``, ``api/`` or
    ``services/`` (its layer is the folder below the package)."""
    source = path.read_text(encoding="utf-8") if source is None else source
    layer = path.relative_to(PKG).parts[0]
    rel = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
    first: dict[int, tuple[str, str]] = {}
    for line, name in imported_names(source, module_name(path), path.name == "__init__.py"):
        if (rule := layer_rule(layer, name)) is not None:
            first.setdefault(line, (name, rule))
    return [f"{rel}:{line}: imports {name} ({rule})" for line, (name, rule) in sorted(first.items())]


def test_the_layers_are_where_the_test_looks():
    files = {layer: layer_files(layer) for layer in ("interfaces", "api", "services")}
    assert len(files["interfaces"]) > 10 and len(files["api"]) > 5 and len(files["services"]) >= 3, files


def test_drivers_import_only_the_facade():
    # no driver is exempt (issue 26: cmd_kinematics.py was the last, now on sm.* like the others)
    problems = [m for f in layer_files("interfaces") for m in layer_violations(f)]
    assert not problems, ("the drivers (interfaces/) must go through sm.* (add what they need to spatialmech.api):\n"
                          + "\n".join(problems))


def test_the_api_does_not_import_the_drivers_and_services_not_the_api():
    problems = [m for layer in ("api", "services") for f in layer_files(layer) for m in layer_violations(f)]
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize(("where", "source", "expected"), [
    ("interfaces/cmd_example.py", "from ..analysis.defects import defect_analysis\n", "spatialmech.analysis.defects"),
    ("interfaces/cmd_example.py", "from .. import catalog\n", "spatialmech.catalog"),
    ("interfaces/cmd_example.py", "from .. import __version__, kinematics\n", "spatialmech.kinematics"),
    ("interfaces/cmd_example.py", "def f():\n    from ..kinematics.jit import announce_compilation\n",
     "spatialmech.kinematics.jit"),
    ("interfaces/studio/example.py", "from ...synthesis.tasks import resolve_task\n", "spatialmech.synthesis.tasks"),
    ("interfaces/example.py", "import spatialmech.model.schema\n", "spatialmech.model.schema"),
    ("interfaces/example.py", "from spatialmech.services.screening import run_screen\n", "spatialmech.services"),
    ("interfaces/example.py", "from ..geometry.tolerances import use\n", "spatialmech.geometry.tolerances"),
    ("interfaces/example.py", "import importlib\nm = importlib.import_module('spatialmech.exchange')\n",
     "spatialmech.exchange"),
    ("api/example.py", "def f():\n    from ..interfaces.studio.app import create_app\n", "spatialmech.interfaces"),
    ("services/example.py", "from ..api.checks import as_mechanism\n", "spatialmech.api"),
    ("services/studio/example.py", "from ... import api\n", "spatialmech.api"),
    ("services/example.py", "from spatialmech.interfaces.common import emit_json\n", "spatialmech.interfaces"),
])
def test_the_layer_check_flags_a_forbidden_import(where, source, expected):
    found = layer_violations(PKG / where, source)
    assert len(found) >= 1 and all(expected in m for m in found), found


def test_the_layer_check_accepts_allowed_imports():
    driver = ("import click\nimport numpy as np\nfrom .. import api as sm\nimport spatialmech\n"
              "from ..errors import InputError\nfrom ..serialize import envelope\nfrom ..results import Progress\n"
              "from ..present.viewer import write_viewer\nfrom .common import emit_json\nfrom .studio.app import create_app\n"
              "from spatialmech.api.regions import TASK_COORDINATES\nfrom .. import __version__, mobility\n")
    assert layer_violations(PKG / "interfaces" / "cmd_example.py", driver) == []
    api = "from ..analysis.defects import defect_analysis\nfrom ..services.screening import run_screen\n"
    assert layer_violations(PKG / "api" / "example.py", api) == []
    services = "from ...kinematics.tracking import track\nfrom ... import catalog\nfrom ...present.viewer import drawing\n"
    assert layer_violations(PKG / "services" / "studio" / "example.py", services) == []

