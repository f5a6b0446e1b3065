"""Static checks that can fail: pyflakes rules (undefined names, unused imports and variables)
and syntax errors, over the package, the tests, the examples and the benchmarks."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent


def test_ruff_pyflakes_and_syntax():
    ruff = shutil.which("ruff") or str(Path(sys.executable).parent / "ruff")
    if not Path(ruff).exists():
        pytest.fail("ruff is not installed: it is in the test extra (pip install -e '.[test]')")
    p = subprocess.run([ruff, "check", "--select", "F,E9", "--no-cache", "src", "tests", "examples", "benchmarks"],
                       cwd=ROOT, capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr
