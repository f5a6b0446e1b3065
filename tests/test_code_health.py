"""Code health (issue 10): no module over ~800 lines, no private names imported across modules,
and the defect analysis split into named steps of modest complexity.

Each check is a function of source text, so that the last tests can feed it a violation and
show that it fails.
"""

from __future__ import annotations

import ast
import importlib.util
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
PKG = ROOT / "src" / "spatialmech"
#: Largest module, in lines.
MAX_LINES = 800
#: Modules allowed over MAX_LINES for now, each with the reason; an entry that is no longer over
#: the limit must be removed (the list only shrinks).
KNOWN_LARGE = {
}
#: Largest cyclomatic complexity (McCabe, as ruff's C901 counts it) of any function of the
#: defect analysis: ``defect_analysis`` itself was about 100 before it was split into steps.
MAX_DEFECT_COMPLEXITY = 12
DEFECT_MODULES = ("analysis/defects.py", "analysis/defect_circuits.py")


def modules() -> list[Path]:
    return sorted(p for p in PKG.rglob("*.py") if "__pycache__" not in p.parts)


def module_name(path: Path) -> str:
    parts = list(path.relative_to(PKG.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def private_imports(source: str, module: str, is_package: bool = False) -> list[str]:
    """``line: what`` for every private name (``_x``, not ``__x__``) that ``source`` (the module
    ``module``) takes from another spatialmech module: ``from M import _x`` and ``m._x`` where
    ``m`` is bound by ``import M as m`` / ``from P import m`` to a spatialmech module."""
    package = module if is_package else module.rpartition(".")[0]
    found: list[str] = []
    aliases: dict[str, str] = {}  # local name -> spatialmech module it may stand for
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = importlib.util.resolve_name("." * node.level + base, package)
            if base.split(".")[0] != "spatialmech" or base == module:
                continue
            for a in node.names:
                if _private(a.name):
                    found.append(f"{node.lineno}: from {base} import {a.name}")
                aliases[a.asname or a.name] = f"{base}.{a.name}"
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] == "spatialmech" and a.asname:
                    aliases[a.asname] = a.name
    for node in ast.walk(ast.parse(source)):
        if (isinstance(node, ast.Attribute) and _private(node.attr) and isinstance(node.value, ast.Name)
                and node.value.id in aliases):
            found.append(f"{node.lineno}: {node.value.id}.{node.attr} ({aliases[node.value.id]})")
    return found


def line_count(path: Path) -> int:
    return len(path.read_text(encoding="utf-8").splitlines())


def _ruff() -> str:
    ruff = shutil.which("ruff") or str(Path(sys.executable).parent / "ruff")
    if not Path(ruff).exists():
        pytest.fail("ruff is not installed: it is in the test extra (pip install -e '.[test]')")
    return ruff


def complexity_violations(paths: list[Path], limit: int) -> str:
    """ruff's C901 report (empty when every function is at most ``limit``)."""
    p = subprocess.run([_ruff(), "check", "--no-cache", "--isolated", "--select", "C901", "--config",
                        f"lint.mccabe.max-complexity={limit}", "--output-format", "concise", *map(str, paths)],
                       cwd=ROOT, capture_output=True, text=True)
    assert p.returncode in (0, 1), p.stderr
    return p.stdout.strip() if p.returncode else ""


def _is_njit(fn: ast.FunctionDef) -> bool:
    for d in fn.decorator_list:
        f = d.func if isinstance(d, ast.Call) else d
        if isinstance(f, ast.Name) and f.id == "njit":
            return True
    return False


#: The marker of a deliberate literal argument (a specialised copy that pays at run time); it
#: must stand on the call's line or in the comment lines just above it.
LITERAL_ON_PURPOSE = "literal"


def kernel_names(sources: list[str]) -> set[str]:
    """Names of the module-level ``@njit`` functions in ``sources``."""
    names = set()
    for src in sources:
        for node in ast.parse(src).body:
            if isinstance(node, ast.FunctionDef) and _is_njit(node):
                names.add(node.name)
    return names


def literal_kernel_arguments(source: str, kernels: set[str]) -> list[str]:
    """``line: call`` for each call, inside a kernel, of another kernel with a bare ``True``,
    ``False`` or integer argument: numba types it as a literal and compiles a separate copy of the
    callee (kinematics/compiled/jit.py).  A call marked as deliberate (``LITERAL_ON_PURPOSE`` in a comment
    on its line or the lines above it) is allowed."""
    lines = source.splitlines()
    found = []
    for fn in ast.parse(source).body:
        if not (isinstance(fn, ast.FunctionDef) and _is_njit(fn)):
            continue
        for node in ast.walk(fn):
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id in kernels):
                continue
            args = list(node.args) + [k.value for k in node.keywords]
            if not any(isinstance(a, ast.Constant) and type(a.value) in (bool, int) for a in args):
                continue
            above = lines[max(0, node.lineno - 3) : node.lineno]
            if any("#" in ln and LITERAL_ON_PURPOSE in ln.split("#", 1)[1] for ln in above):
                continue
            found.append(f"{node.lineno}: {node.func.id}(...)")
    return found


TESTS = ROOT / "tests"


def suite_files() -> list[Path]:
    return sorted(TESTS.glob("*.py"))


def _decorator_name(d: ast.expr) -> str:
    return ast.unparse(d.func if isinstance(d, ast.Call) else d)


def _own_nodes(fn: ast.FunctionDef):
    """The nodes of ``fn``'s body, not those of functions, lambdas or classes defined inside it."""
    stack = list(fn.body)
    while stack:
        node = stack.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            continue
        yield node
        stack.extend(ast.iter_child_nodes(node))


def given_test_returns(source: str) -> list[str]:
    """``line: test`` for each ``return`` in a hypothesis test (a function decorated with
    ``@given``): a return skips the rest of the example but hypothesis counts the example as
    tested; ``hypothesis.assume(...)`` (or ``reject()``) says it does not apply, so hypothesis
    draws another and reports when too few apply."""
    found = []
    for fn in ast.walk(ast.parse(source)):
        if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)) and any(
                _decorator_name(d).split(".")[-1] == "given" for d in fn.decorator_list):
            found += [f"{n.lineno}: {fn.name}" for n in _own_nodes(fn) if isinstance(n, ast.Return)]
    return sorted(found, key=lambda x: int(x.split(":")[0]))


#: Clock readings (``time.perf_counter()``, ``perf_counter()``, ...).
CLOCKS = {"perf_counter", "perf_counter_ns", "monotonic", "monotonic_ns", "process_time", "process_time_ns",
          "time", "time_ns"}
#: Variables, and (with a unit suffix) attributes and keys, that hold a measured duration
#: (``elapsed``, ``r.seconds``, ``out["first_solve_s"]``).
DURATION_NAME = re.compile(r"(^|_)(seconds|elapsed|duration|wall)(_|$)")
DURATION = re.compile(DURATION_NAME.pattern + r"|_(s|ms|us|ns)$")


def _is_clock_call(node: ast.AST) -> bool:
    if not isinstance(node, ast.Call):
        return False
    f = node.func
    if isinstance(f, ast.Attribute):
        return f.attr in CLOCKS and isinstance(f.value, ast.Name) and f.value.id == "time"
    return isinstance(f, ast.Name) and f.id in CLOCKS - {"time", "time_ns"}


def _clock_names(tree: ast.AST) -> set[str]:
    """Names assigned (anywhere in ``tree``) from a clock reading or from another such name."""
    names: set[str] = set()
    while True:
        before = len(names)
        for node in ast.walk(tree):
            if isinstance(node, (ast.Assign, ast.AnnAssign, ast.AugAssign, ast.NamedExpr)) and node.value is not None \
                    and _is_timing(node.value, names):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                names |= {n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name)}
        if len(names) == before:
            return names


def _is_timing(expr: ast.AST, clock_names: set[str]) -> bool:
    for n in ast.walk(expr):
        if _is_clock_call(n) or (isinstance(n, ast.Name) and (n.id in clock_names or DURATION_NAME.search(n.id))):
            return True
        if isinstance(n, ast.Attribute) and DURATION.search(n.attr):
            return True
        if isinstance(n, ast.Subscript) and isinstance(n.slice, ast.Constant) and isinstance(n.slice.value, str) \
                and DURATION.search(n.slice.value):
            return True
    return False


def wall_clock_asserts(source: str) -> list[str]:
    """``line: assertion`` for each ``assert`` that bounds a wall-clock measurement (a clock
    reading, a name assigned from one, or a value named as a duration: ``seconds``, ``elapsed``,
    ``*_s``, ``*_ms``) with ``<``, ``<=``, ``>`` or ``>=``: its result depends on the machine's
    load, so the target belongs in benchmarks/ (met / NOT met, against a baseline of the same
    run).  A sign check against 0 (``> 0``: the benchmark measured something) is allowed."""
    tree = ast.parse(source)
    clock_names = _clock_names(tree)
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Assert):
            continue
        for cmp in (n for n in ast.walk(node.test) if isinstance(n, ast.Compare)):
            if not all(isinstance(op, (ast.Lt, ast.LtE, ast.Gt, ast.GtE)) for op in cmp.ops):
                continue
            sides = [cmp.left, *cmp.comparators]
            timed = [x for x in sides if _is_timing(x, clock_names)]
            rest = [x for x in sides if not _is_timing(x, clock_names)]
            if timed and not all(isinstance(x, ast.Constant) and x.value == 0 for x in rest):
                found.append(f"{node.lineno}: {ast.unparse(cmp)}")
    return found


# ------------------------------------------------------------------ the checks
def test_no_test_asserts_on_a_wall_clock_measurement():
    bad = [f"{p.name}:{hit}" for p in suite_files() for hit in wall_clock_asserts(p.read_text(encoding="utf-8"))]
    assert not bad, "tests asserting on elapsed time (move the target to benchmarks/):\n" + "\n".join(bad)


def test_no_hypothesis_test_returns_early():
    bad = [f"{p.name}:{hit}" for p in suite_files() for hit in given_test_returns(p.read_text(encoding="utf-8"))]
    assert not bad, "@given tests that return to skip an example (use hypothesis.assume):\n" + "\n".join(bad)


def test_no_kernel_passes_a_literal_constant_to_another_kernel():
    """First-call compilation: a bare constant between kernels compiles the callee again."""
    texts = {p: p.read_text(encoding="utf-8") for p in modules()}
    kernels = kernel_names(list(texts.values()))
    assert len(kernels) > 50
    bad = [f"{p.relative_to(PKG)}:{hit}" for p, src in texts.items() for hit in literal_kernel_arguments(src, kernels)]
    assert not bad, "kernels called with literal constants (pass np.bool_(...) / np.int64(...)):\n" + "\n".join(bad)


def test_the_literal_argument_check_flags_a_violation_and_accepts_a_marked_one():
    src = (
        "@njit(cache=True)\ndef inner(a, flag):\n    return a\n\n"
        "@njit(cache=True)\ndef outer(a):\n    x = inner(a, True)\n"
        "    # a literal copy on purpose\n    y = inner(a, 6)\n    return inner(a, np.bool_(True))\n"
    )
    assert literal_kernel_arguments(src, kernel_names([src])) == ["7: inner(...)"]


def test_the_checks_see_the_package():
    assert len(modules()) > 60


def test_no_module_is_over_the_size_limit():
    over = {str(p.relative_to(PKG)): line_count(p) for p in modules() if line_count(p) > MAX_LINES}
    new = {k: v for k, v in over.items() if k not in KNOWN_LARGE}
    assert not new, f"modules over {MAX_LINES} lines (split them by concept): {new}"
    stale = sorted(set(KNOWN_LARGE) - set(over))
    assert not stale, f"no longer over {MAX_LINES} lines: remove from KNOWN_LARGE: {stale}"


def test_no_private_name_is_imported_across_modules():
    problems = [f"{p.relative_to(ROOT)}:{m}" for p in modules()
                for m in private_imports(p.read_text(encoding="utf-8"), module_name(p), p.name == "__init__.py")]
    assert not problems, "private names used outside their module (make them public or move the code):\n" + "\n".join(
        problems)


def test_the_defect_analysis_is_split_into_steps_of_modest_complexity():
    out = complexity_violations([PKG / m for m in DEFECT_MODULES], MAX_DEFECT_COMPLEXITY)
    assert not out, out


def test_every_step_of_the_defect_analysis_says_what_it_does():
    for m in DEFECT_MODULES:
        tree = ast.parse((PKG / m).read_text(encoding="utf-8"))
        bare = [f.name for f in tree.body if isinstance(f, ast.FunctionDef) and not ast.get_docstring(f)]
        assert not bare, f"{m}: module-level functions without a docstring: {bare}"


# ------------------------------------------------------------------ the checks can fail
@pytest.mark.parametrize(("source", "expected"), [
    ("from .limits import _BOX\n", "from spatialmech.analysis.workspace.limits import _BOX"),
    ("from ...kinematics.position import _limb_gn as gn\n", "spatialmech.kinematics.position import _limb_gn"),
    ("from spatialmech.kinematics.closure import _compiled\n", "import _compiled"),
    ("from . import limits\nx = limits._CLOSURE\n", "limits._CLOSURE"),
    ("import spatialmech.synthesis.cs_dyads as cd\ny = cd._flip(0)\n", "cd._flip"),
])
def test_the_private_import_check_flags_a_violation(source, expected):
    found = private_imports(source, "spatialmech.analysis.workspace.example")
    assert len(found) == 1 and expected in found[0], found


def test_the_private_import_check_accepts_public_names_and_own_privates():
    source = ("from __future__ import annotations\nfrom .limits import BOX, CLOSURE\nimport numpy as np\n"
              "x = np._NoValue\ndef _helper():\n    return _helper\nclass A:\n    def __init__(self):\n"
              "        self._x = 1\n")
    assert private_imports(source, "spatialmech.analysis.workspace.example") == []


def test_the_complexity_check_flags_a_complex_function(tmp_path):
    branches = "".join(f"    if x == {k}:\n        return {k}\n" for k in range(MAX_DEFECT_COMPLEXITY + 2))
    bad = tmp_path / "bad.py"
    bad.write_text(f"def f(x):\n{branches}    return None\n", encoding="utf-8")
    assert "C901" in complexity_violations([bad], MAX_DEFECT_COMPLEXITY)


def test_the_hypothesis_return_check_flags_a_return_and_accepts_assume():
    src = (
        "from hypothesis import assume, given\nimport hypothesis\n\n"
        "@given(x)\ndef test_a(x):\n    if x < 0:\n        return\n    assert x >= 0\n\n"
        "@hypothesis.given(x)\ndef test_b(x):\n    for y in x:\n        if y:\n            return None\n\n"
        "@given(x)\ndef test_c(x):\n    assume(x >= 0)\n    def f():\n        return x\n    g = lambda: x\n"
        "    assert f() == g()\n\n"
        "def test_d():\n    return\n"
    )
    assert given_test_returns(src) == ["7: test_a", "14: test_b"]


@pytest.mark.parametrize("source", [
    "import time\nt0 = time.perf_counter()\nf()\nassert time.perf_counter() - t0 < 1.0\n",
    "from time import perf_counter\nt = perf_counter()\nf()\ndt = perf_counter() - t\nassert dt <= 5\n",
    "import time\nt0 = time.monotonic()\nassert f() and time.monotonic() - t0 < 2\n",
    "r = solve()\nassert r.cached and r.seconds < 2.0\n",
    "out = bench()\nassert out['first_solve_s'] < 2.0\n",
    "elapsed = run()\nassert 0 < elapsed < 3\n",
])
def test_the_wall_clock_check_flags_a_timed_assertion(source):
    assert len(wall_clock_asserts(source)) == 1, source


def test_the_wall_clock_check_accepts_other_assertions():
    source = ("import time\nt0 = time.perf_counter()\nwhile time.perf_counter() - t0 < 5:\n    poll()\n"
              "assert out['first_solve_s'] > 0 and out['resolve_median_ms'] > 0\n"
              "assert r.cached and len(r.solutions) < 50 and r.residual < 1e-9\n"
              "assert data['t_s'] == [0.0, 0.5]\n")
    assert wall_clock_asserts(source) == []
