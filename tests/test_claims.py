"""Every paper claim of the reproduction report names the test function that checks it (issue 26).

A claim row (:class:`spatialmech.present.report.Claim`) of ``spatialmech demo`` carries ``test``:
``tests/test_x.py::test_function``, or ``tests/test_x.py::test_function[id]`` for one case of a
parametrised test.  The references are read from the report builders' source
(``present/paper_*.py``, every ``Claim(...)`` call) without building the demo: a literal
reference must name a module-level test function of that file; an f-string (claims made in a
loop) must name the function before its id (``...::test_function[{...}]``) and the function
must be parametrised.  The built demo (slow) then checks the ids too, by collecting them.

Each check is a function of source text, so that the last tests can feed it a violation and
show that it fails.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
PRESENT = ROOT / "src" / "spatialmech" / "present"
#: Position of ``test`` among Claim's fields (paper, claim, paper_value, ours, verdict, note,
#: evidence, test, ...).
TEST_ARG = 7
#: ``tests/test_x.py::test_function`` with an optional ``[id]``.
REFERENCE = re.compile(r"(?P<file>tests/test_\w+\.py)::(?P<function>test_\w+)(?P<id>\[.*\])?")


def claim_test_references(source: str) -> list[tuple[int, str | None]]:
    """``(line, reference)`` for each ``Claim(...)`` call of ``source``: its ``test`` argument
    (positional or keyword).  For an f-string the reference is its text up to the first
    replacement field (``"file::function["`` for a parametrised test's id); ``None`` when the
    argument is missing or not a literal (so it cannot be checked)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "Claim"):
            continue
        arg = next((k.value for k in node.keywords if k.arg == "test"), None)
        if arg is None and len(node.args) > TEST_ARG:
            arg = node.args[TEST_ARG]
        ref = None
        if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
            ref = arg.value
        elif isinstance(arg, ast.JoinedStr) and arg.values and isinstance(arg.values[0], ast.Constant):
            ref = arg.values[0].value if len(arg.values) > 1 else None
        found.append((node.lineno, ref))
    return found


def _is_parametrised(fn: ast.FunctionDef) -> bool:
    return any(ast.unparse(d.func if isinstance(d, ast.Call) else d).endswith("mark.parametrize")
               for d in fn.decorator_list)


def reference_problem(ref: str | None, root: Path = ROOT) -> str:
    """Why ``ref`` does not name a test function that exists ("" when it does).  A reference
    ending in ``[`` (an f-string's text before the id) or with an ``[id]`` needs a parametrised
    function."""
    if not ref:
        return "no test named (or not a literal string)"
    partial = ref.endswith("[")
    m = REFERENCE.fullmatch(ref + "]" if partial else ref)
    if m is None:
        return "expected tests/test_x.py::test_function (a test function, not only a file)"
    path = root / m["file"]
    if not path.is_file():
        return f"no file {m['file']}"
    fns = {n.name: n for n in ast.parse(path.read_text(encoding="utf-8")).body if isinstance(n, ast.FunctionDef)}
    fn = fns.get(m["function"])
    if fn is None:
        return f"no function {m['function']} in {m['file']}"
    if (partial or m["id"]) and not _is_parametrised(fn):
        return f"{m['function']} is not parametrised: it has no [id]"
    return ""


def claim_modules() -> list[Path]:
    return sorted(p for p in PRESENT.glob("*.py") if claim_test_references(p.read_text(encoding="utf-8")))


# ------------------------------------------------------------------ the checks
def test_the_check_sees_the_claims_of_the_four_papers():
    assert [p.name for p in claim_modules()] == ["paper_a.py", "paper_b.py", "paper_c.py", "paper_d.py"]
    assert sum(len(claim_test_references(p.read_text(encoding="utf-8"))) for p in claim_modules()) >= 30


def test_every_claim_of_the_report_names_a_test_function():
    bad = [f"{p.name}:{line}: {ref!r}: {why}" for p in claim_modules()
           for line, ref in claim_test_references(p.read_text(encoding="utf-8")) if (why := reference_problem(ref))]
    assert not bad, "claims without a test function (file::function):\n" + "\n".join(bad)


@pytest.mark.slow
def test_every_claim_of_the_built_demo_names_a_collected_test(demo_report):
    """The references as the demo wrote them: each names a test function, and every
    parametrised case (``[id]``) is one pytest collects."""
    _, data = demo_report
    refs = [c["test"] for c in data["claims"]]
    assert len(refs) == data["summary"]["claims"]
    bad = [f"{c['claim']}: {c['test']!r}: {why}" for c in data["claims"] if (why := reference_problem(c["test"]))]
    assert not bad, "\n".join(bad)
    cases = sorted({r for r in refs if "[" in r})
    assert cases  # the claims made in loops (mobility of each linkage and mode)
    p = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider", *cases],
                       cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    collected = set(p.stdout.split())
    assert not [c for c in cases if c not in collected], p.stdout[-2000:]


# ------------------------------------------------------------------ the checks can fail
CLAIM_SOURCE = 'Claim("A", "c", "1", "1", "reproduced", "", {{}}, {test})\n'


@pytest.mark.parametrize(("test", "expected"), [
    ('"tests/test_mobility.py"', "not only a file"),
    ('"tests/test_mobility.py::test_no_such_function"', "no function test_no_such_function"),
    ('"tests/test_no_such_file.py::test_x"', "no file tests/test_no_such_file.py"),
    ('f"tests/test_mobility.py::test_paper_B_four_sps_cu_mobility_breakdown[{k}]"', "is not parametrised"),
    ('"tests/test_mobility.py::test_paper_B_four_sps_cu_mobility_breakdown[1]"', "is not parametrised"),
    ('name', "not a literal"),
    ('""', "no test named"),
    ('f"{name}"', "not a literal"),
])
def test_the_claim_check_flags_a_claim_without_a_test_function(test, expected):
    ((line, ref),) = claim_test_references(CLAIM_SOURCE.format(test=test))
    assert line == 1 and expected in reference_problem(ref), (ref, reference_problem(ref))


def test_the_claim_check_flags_a_claim_without_a_test_argument():
    ((_, ref),) = claim_test_references('Claim("A", "c", "1", "1", "reproduced", note="n")\n')
    assert ref is None and reference_problem(ref)


@pytest.mark.parametrize("test", [
    '"tests/test_mobility.py::test_paper_B_four_sps_cu_mobility_breakdown"',
    'f"tests/test_mobility.py::test_paper_A_five_cs_is_one_dof[{k}]"',
    '"tests/test_mobility.py::test_paper_A_five_cs_is_one_dof[2]"',
])
def test_the_claim_check_accepts_a_test_function_and_a_parametrised_case(test):
    ((_, ref),) = claim_test_references(CLAIM_SOURCE.format(test=test))
    assert reference_problem(ref) == ""
    ((_, kw),) = claim_test_references(f'Claim("A", "c", "1", "1", "reproduced", test={test})\n')
    assert kw == ref
