"""mypy on the whole package, with the project's own configuration ([tool.mypy] in
pyproject.toml: the files to check, check_untyped_defs, ...), and the typing marker that the
package ships."""

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
CORE = {f"src/spatialmech/{p}" for p in ("geometry", "model", "kinematics", "analysis")}
PACKAGE = "src/spatialmech"

pytest.importorskip("mypy", reason="mypy is in the test extra (pip install -e '.[test]')")


def _mypy(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "mypy", *args], cwd=ROOT, capture_output=True, text=True)


def _config() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_mypy_config_covers_the_whole_package():
    cfg = _config()["tool"]["mypy"]
    assert PACKAGE in cfg["files"], cfg["files"]
    assert cfg.get("check_untyped_defs") is True
    assert not cfg.get("ignore_errors", False)
    # no part of the package is read silently any more; the core is never exempt from errors
    for o in cfg.get("overrides", []):
        mods = o["module"] if isinstance(o["module"], list) else [o["module"]]
        ours = [m for m in mods if m.startswith("spatialmech")]
        assert not ours or o.get("follow_imports") != "silent", o
        assert not any(m.startswith(f"spatialmech.{c.rsplit('/', 1)[1]}") for c in CORE for m in ours), o


@pytest.mark.slow
def test_mypy_is_clean_on_the_package():
    # no targets on the command line: the `files` of [tool.mypy] (the whole package)
    p = _mypy("--no-error-summary")
    assert p.returncode == 0, p.stdout + p.stderr


def test_mypy_reports_a_type_error(tmp_path):
    """The check can fail: the same configuration rejects a wrong type in a checked body (an
    unannotated function: check_untyped_defs)."""
    bad = tmp_path / "bad.py"
    bad.write_text("import numpy as np\n\n\ndef f():\n    x: float = np.zeros(3)\n    return x\n", encoding="utf-8")
    p = _mypy("--config-file", str(ROOT / "pyproject.toml"), str(bad))
    assert p.returncode == 1, p.stdout + p.stderr
    assert "bad.py:5: error" in p.stdout and "[assignment]" in p.stdout, p.stdout


def test_package_ships_py_typed():
    assert (ROOT / "src" / "spatialmech" / "py.typed").is_file()
    data = _config()["tool"]["setuptools"]["package-data"]
    assert "py.typed" in data.get("spatialmech", []), data
