"""A complexity ratchet over the whole package (issue 26).

No function of ``src/spatialmech`` may have a cyclomatic complexity above ``LIMIT`` (McCabe, as
ruff's C901 counts it: ``ruff check --select C901``), except the functions listed in
``tests/complexity_allowlist.txt`` (``ALLOWLIST``) with their complexity when they were listed.
The list only shrinks.  The test fails when

(a) a function that is not listed is above ``LIMIT`` (split it into named steps);
(b) a listed function is more complex than its recorded number;
(c) a listed function is now at most ``LIMIT``, or no longer exists: its line must be deleted;
(d) a listed function is less complex than recorded but still above ``LIMIT``: its number must be
    lowered to the new one (the ratchet clicks).

Entries are keyed by the file (relative to ``src/spatialmech``) and the function's qualified name
(``Class.method``, ``outer.inner``), never by line number, so that edits elsewhere in a file do not
touch the list.  When a function moves to another file, (a) and (c) fire together and the message
names the one line to rewrite.  Every message gives the exact line to delete, add or change.

The checks are functions of data (``measure`` of files, ``parse_allowlist`` of text), so the last
tests feed them synthetic violations and show that each can fail.
"""

from __future__ import annotations

import ast
import json
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
PKG = ROOT / "src" / "spatialmech"
ALLOWLIST = Path(__file__).parent / "complexity_allowlist.txt"
#: Largest cyclomatic complexity of a function that is not on the allow-list.
LIMIT = 15
_MESSAGE = re.compile(r"^`(?P<name>[^`]+)` is too complex \((?P<n>\d+) > \d+\)$")
_ENTRY = re.compile(r"^(?P<file>\S+\.py)::(?P<qualname>[\w.]+)\s+(?P<n>\d+)$")


def _ruff() -> str:
    ruff = shutil.which("ruff") or str(Path(sys.executable).parent / "ruff")
    if not Path(ruff).exists():
        pytest.fail("ruff is not installed: it is in the test extra (pip install -e '.[test]')")
    return ruff


# ------------------------------------------------------------------ measuring
def qualnames(source: str) -> dict[tuple[int, str], str]:
    """``(line of the name, name) -> qualified name`` of every function in ``source``:
    ``f``, ``Class.method``, ``outer.inner`` (the line is the one of the ``def`` keyword, where
    ruff reports the function)."""
    out: dict[tuple[int, str], str] = {}

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                q = f"{prefix}{child.name}"
                if not isinstance(child, ast.ClassDef):
                    out[(child.lineno, child.name)] = q
                visit(child, q + ".")
            else:
                visit(child, prefix)

    visit(ast.parse(source), "")
    return out


def measure(files: list[Path], base: Path) -> dict[str, int]:
    """``"<file relative to base>::<qualified name>" -> complexity`` of every function of
    ``files`` (ruff's C901 with the threshold 0 reports them all).  Two functions with one key
    (a property and its setter, a function defined in two branches) count as the larger."""
    p = subprocess.run([_ruff(), "check", "--no-cache", "--isolated", "--select", "C901", "--config",
                        "lint.mccabe.max-complexity=0", "--output-format", "json", *map(str, files)],
                       cwd=ROOT, capture_output=True, text=True)
    assert p.returncode in (0, 1), p.stderr
    names: dict[Path, dict[tuple[int, str], str]] = {}
    out: dict[str, int] = {}
    for d in json.loads(p.stdout or "[]"):
        m = _MESSAGE.match(d["message"])
        assert m and d["code"] == "C901", d
        path = Path(d["filename"]).resolve()
        if path not in names:
            names[path] = qualnames(path.read_text(encoding="utf-8"))
        row = d["location"]["row"]
        qual = names[path].get((row, m["name"]))
        assert qual is not None, f"{path}:{row}: ruff reports {m['name']!r}, no function of that name starts there"
        key = f"{path.relative_to(base.resolve()).as_posix()}::{qual}"
        out[key] = max(out.get(key, 0), int(m["n"]))
    return out


# ------------------------------------------------------------------ the allow-list
@dataclass(frozen=True)
class Entry:
    line: int  # 1-based line in the allow-list file
    text: str  # the line as written
    complexity: int


def parse_allowlist(text: str) -> tuple[dict[str, Entry], list[str]]:
    """``(key -> Entry, problems)``: one ``<file>::<qualified name> <complexity>`` per line;
    blank lines and ``#`` comments are skipped; a malformed or repeated line is a problem."""
    entries: dict[str, Entry] = {}
    problems: list[str] = []
    for i, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        m = _ENTRY.match(line)
        if m is None:
            problems.append(f"line {i}: {raw.strip()!r} is not '<file>::<qualified name> <complexity>': fix or delete it")
            continue
        key = f"{m['file']}::{m['qualname']}"
        if key in entries:
            problems.append(f"line {i}: {key} is listed twice (also line {entries[key].line}): delete line {i}")
            continue
        entries[key] = Entry(i, line, int(m["n"]))
    return entries, problems


def _qualname(key: str) -> str:
    return key.split("::", 1)[1]


def ratchet_problems(measured: dict[str, int], allowed: dict[str, Entry], limit: int = LIMIT,
                     where: str = "tests/complexity_allowlist.txt") -> list[str]:
    """What breaks the ratchet, each with the exact edit of the allow-list that fixes it (after
    simplifying the function, for (a) and (b))."""
    over = {k: n for k, n in measured.items() if n > limit}
    new = {k: n for k, n in over.items() if k not in allowed}
    gone = {k: e for k, e in allowed.items() if k not in measured}
    problems = []
    # a function that moved to another file: one line to rewrite instead of a delete and an add
    for key, e in sorted(gone.items(), key=lambda kv: kv[1].line):
        moved = [k for k in new if _qualname(k) == _qualname(key)]
        if len(moved) == 1 and new[moved[0]] <= e.complexity:
            to = moved[0]
            problems.append(f"{where} line {e.line}: {key} moved to {to.split('::')[0]}: "
                            f"replace the line {e.text!r} by '{to} {new.pop(to)}'")
        else:
            problems.append(f"{where} line {e.line}: {key} no longer exists: delete the line {e.text!r}")
    for key, n in sorted(new.items()):
        problems.append(f"{key}: complexity {n} > {limit} and not on the allow-list: split it into functions "
                        f"of complexity <= {limit} (the list only shrinks; do not add '{key} {n}' to {where})")
    for key, e in sorted(allowed.items(), key=lambda kv: kv[1].line):
        n = measured.get(key)
        if n is None:
            continue
        if n > e.complexity:
            problems.append(f"{key}: complexity {n} > {e.complexity} recorded on {where} line {e.line}: "
                            f"simplify it back to <= {e.complexity} (the list only shrinks)")
        elif n <= limit:
            problems.append(f"{where} line {e.line}: {key} is now {n} <= {limit}: delete the line {e.text!r}")
        elif n < e.complexity:
            problems.append(f"{where} line {e.line}: {key} is now {n} < {e.complexity}: "
                            f"replace the line {e.text!r} by '{key} {n}'")
    return problems


def package_files() -> list[Path]:
    return sorted(p for p in PKG.rglob("*.py") if "__pycache__" not in p.parts)


# ------------------------------------------------------------------ the check
def test_the_ratchet_sees_the_package():
    measured = measure(package_files(), PKG)
    assert len(measured) > 1000, len(measured)
    assert "model/topology.py::link_graph" in measured
    assert "model/topology.py::LinkGraph.__post_init__" in measured


def test_no_function_is_more_complex_than_the_ratchet_allows():
    entries, problems = parse_allowlist(ALLOWLIST.read_text(encoding="utf-8"))
    problems += ratchet_problems(measure(package_files(), PKG), entries)
    if problems:
        pytest.fail(f"complexity ratchet (McCabe, ruff C901; limit {LIMIT}; see tests/test_complexity.py):\n"
                    + "\n".join(problems), pytrace=False)


# ------------------------------------------------------------------ the checks can fail
def _branchy(name: str, n: int, indent: str = "") -> str:
    """A function of complexity ``n`` (``n - 1`` ifs)."""
    body = "".join(f"{indent}    if x == {k}:\n{indent}        return {k}\n" for k in range(n - 1))
    return f"{indent}def {name}(x):\n{body}{indent}    return None\n"


@pytest.fixture
def synthetic(tmp_path):
    """A package of one module with a 20, a 16 (a method), a 15 and a nested 17 (in a 19)."""
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "mod.py").write_text(
        _branchy("big", 20) + "\n\nclass A:\n" + _branchy("method", 16, "    ") + "\n\n" + _branchy("fine", 15)
        + "\n\ndef outer(x):\n" + _branchy("inner", 17, "    ") + "    if x:\n        return inner(x)\n    return 0\n",
        encoding="utf-8")
    return pkg, measure([pkg / "mod.py"], pkg)


def _listed(*lines: str) -> dict[str, Entry]:
    entries, problems = parse_allowlist("# header\n\n" + "\n".join(lines) + "\n")
    assert not problems, problems
    return entries


def test_measure_gives_ruffs_numbers_under_qualified_names(synthetic):
    _, measured = synthetic
    assert measured == {"mod.py::big": 20, "mod.py::A.method": 16, "mod.py::fine": 15,
                        "mod.py::outer": 19, "mod.py::outer.inner": 17}


def test_the_ratchet_accepts_an_exact_allow_list(synthetic):
    _, measured = synthetic
    allowed = _listed("mod.py::big 20", "mod.py::A.method 16", "mod.py::outer 19  # a comment", "mod.py::outer.inner 17")
    assert ratchet_problems(measured, allowed) == []


def test_the_ratchet_flags_an_unlisted_function_over_the_limit(synthetic):
    _, measured = synthetic
    problems = ratchet_problems(measured, _listed("mod.py::big 20", "mod.py::outer 19", "mod.py::outer.inner 17"))
    assert len(problems) == 1 and problems[0].startswith("mod.py::A.method: complexity 16 > 15 and not on"), problems


def test_the_ratchet_flags_a_listed_function_that_got_more_complex(synthetic):
    _, measured = synthetic
    problems = ratchet_problems(measured, _listed("mod.py::big 19", "mod.py::A.method 16", "mod.py::outer 19",
                                                  "mod.py::outer.inner 17"))
    assert problems == ["mod.py::big: complexity 20 > 19 recorded on tests/complexity_allowlist.txt line 3: "
                        "simplify it back to <= 19 (the list only shrinks)"], problems


def test_the_ratchet_flags_a_listed_function_now_within_the_limit(synthetic):
    _, measured = synthetic
    problems = ratchet_problems(measured, _listed("mod.py::big 20", "mod.py::A.method 16", "mod.py::outer 19",
                                                  "mod.py::outer.inner 17", "mod.py::fine 18"))
    assert problems == ["tests/complexity_allowlist.txt line 7: mod.py::fine is now 15 <= 15: "
                        "delete the line 'mod.py::fine 18'"], problems


def test_the_ratchet_flags_a_listed_function_that_no_longer_exists(synthetic):
    _, measured = synthetic
    problems = ratchet_problems(measured, _listed("mod.py::big 20", "mod.py::A.method 16", "mod.py::outer 19",
                                                  "mod.py::outer.inner 17", "mod.py::gone 30"))
    assert problems == ["tests/complexity_allowlist.txt line 7: mod.py::gone no longer exists: "
                        "delete the line 'mod.py::gone 30'"], problems


def test_the_ratchet_asks_to_lower_a_number_that_went_down(synthetic):
    _, measured = synthetic
    problems = ratchet_problems(measured, _listed("mod.py::big 25", "mod.py::A.method 16", "mod.py::outer 19",
                                                  "mod.py::outer.inner 17"))
    assert problems == ["tests/complexity_allowlist.txt line 3: mod.py::big is now 20 < 25: "
                        "replace the line 'mod.py::big 25' by 'mod.py::big 20'"], problems


def test_the_ratchet_names_the_line_to_rewrite_when_a_function_moves(synthetic):
    pkg, _ = synthetic
    (pkg / "sub").mkdir()
    (pkg / "mod.py").rename(pkg / "sub" / "moved.py")
    measured = measure([pkg / "sub" / "moved.py"], pkg)
    problems = ratchet_problems(measured, _listed("mod.py::big 20", "mod.py::A.method 16", "mod.py::outer 19",
                                                  "mod.py::outer.inner 17"))
    assert problems[0] == ("tests/complexity_allowlist.txt line 3: mod.py::big moved to sub/moved.py: "
                           "replace the line 'mod.py::big 20' by 'sub/moved.py::big 20'"), problems
    assert len(problems) == 4 and all("moved to sub/moved.py" in p for p in problems), problems


def test_a_moved_function_that_also_grew_is_not_taken_for_a_move():
    problems = ratchet_problems({"other.py::big": 21}, _listed("mod.py::big 20"))
    assert problems[0].endswith("no longer exists: delete the line 'mod.py::big 20'"), problems
    assert problems[1].startswith("other.py::big: complexity 21 > 15 and not on the allow-list"), problems


@pytest.mark.parametrize(("text", "expected"), [
    ("mod.py::big\n", "line 1: 'mod.py::big' is not '<file>::<qualified name> <complexity>'"),
    ("mod.py:big 20\n", "line 1: 'mod.py:big 20' is not"),
    ("# c\nmod.py::big 20\nmod.py::big 20\n", "line 3: mod.py::big is listed twice (also line 2): delete line 3"),
])
def test_the_allow_list_parser_flags_a_malformed_line(text, expected):
    _, problems = parse_allowlist(text)
    assert len(problems) == 1 and problems[0].startswith(expected), problems
