"""Static checks that can fail: ruff with the project's own configuration (pyproject.toml
[tool.ruff.lint]: pycodestyle, pyflakes, bugbear, pyupgrade, simplify, comprehensions and ruff's
own rules) over the package, the tests, the examples and the benchmarks."""

import fnmatch
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
TARGETS = ["src", "tests", "examples", "benchmarks"]
# the rule families issue 10 requires; the config may ignore single rules (each with a reason)
REQUIRED_FAMILIES = {"E", "F", "W", "B", "UP", "SIM", "C4", "RUF"}


def _ruff() -> str:
    ruff = shutil.which("ruff") or str(Path(sys.executable).parent / "ruff")
    if not Path(ruff).exists():
        pytest.fail("ruff is not installed: it is in the test extra (pip install -e '.[test]')")
    return ruff


def test_ruff_config_selects_the_required_rule_families():
    lint = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["ruff"]["lint"]
    assert set(lint["select"]) >= REQUIRED_FAMILIES, lint["select"]
    # whole families must not be switched off again through `ignore`
    assert not REQUIRED_FAMILIES & set(lint.get("ignore", [])), lint["ignore"]


def test_ruff_check_is_clean_with_the_project_config():
    # no --select/--ignore override: exactly what `ruff check src tests` reports for a developer
    p = subprocess.run([_ruff(), "check", "--no-cache", "--output-format", "concise", *TARGETS],
                       cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr


def test_ruff_reports_a_violation(tmp_path):
    """The check can fail: a file with a bugbear, a pyupgrade and a pyflakes violation is flagged
    under the project config."""
    bad = tmp_path / "bad.py"
    bad.write_text("import os\nfrom typing import Union\n\n\ndef f(x: Union[int, str], acc=[]):\n"
                   "    return list(zip(acc, acc))\n", encoding="utf-8")
    p = subprocess.run([_ruff(), "check", "--no-cache", "--config", str(ROOT / "pyproject.toml"),
                        "--output-format", "concise", str(bad)], cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == 1, p.stdout + p.stderr
    for code in ("F401", "UP007", "B006", "B905"):
        assert code in p.stdout, (code, p.stdout)


# ------------------------------------------------------------------ README layout = the tree
def _layout_block() -> str:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Layout", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```\n(.*?)```", section, flags=re.S)[0]


def test_readme_layout_matches_the_tree():
    """Every module and sub-package of src/spatialmech is named in README's Layout section (by
    name or by a glob such as ``cmd_*.py``), and every name there exists."""
    block = _layout_block()
    pkg = ROOT / "src" / "spatialmech"
    files = [p for p in pkg.rglob("*") if p.is_file() and "__pycache__" not in p.parts
             and p.suffix in (".py", ".json", ".typed", ".toml")]
    dirs = [p for p in pkg.rglob("*") if p.is_dir() and p.name != "__pycache__"]
    patterns = set(re.findall(r"[\w*?\[\]-][\w*?\[\].-]*\.(?:py|json|typed|toml)\b", block))
    named_dirs = set(re.findall(r"(\w+)/", block))
    unlisted = sorted(str(p.relative_to(pkg)) for p in files if p.name not in ("__init__.py", "__main__.py")
                      and not any(fnmatch.fnmatch(p.name, pat) for pat in patterns))
    assert not unlisted, f"README Layout does not mention: {unlisted}"
    stale = sorted(pat for pat in patterns if not any(fnmatch.fnmatch(p.name, pat) for p in files))
    assert not stale, f"README Layout names files that do not exist: {stale}"
    assert {d.name for d in dirs} <= named_dirs, sorted({d.name for d in dirs} - named_dirs)
    assert named_dirs - {"src", "spatialmech"} <= {d.name for d in dirs}, sorted(named_dirs - {d.name for d in dirs})
