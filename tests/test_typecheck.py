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


def config_problems(cfg: dict) -> list[str]:
    """What in a ``[tool.mypy]`` table (``cfg``) leaves part of the package unchecked."""
    out = []
    if PACKAGE not in cfg.get("files", []):
        out.append(f"files does not name {PACKAGE}: {cfg.get('files')}")
    if cfg.get("check_untyped_defs") is not True:
        out.append("check_untyped_defs is not true")
    if cfg.get("ignore_errors", False):
        out.append("ignore_errors is set for everything")
    # no part of the package is read silently, none has its errors ignored (issue 26: the API,
    # the drivers and the services were the last), the core is exempt from nothing
    for o in cfg.get("overrides", []):
        mods = o["module"] if isinstance(o["module"], list) else [o["module"]]
        ours = [m for m in mods if m == "spatialmech" or m.startswith("spatialmech.")]
        if not ours:
            continue
        if o.get("follow_imports") == "silent":
            out.append(f"follow_imports = 'silent' for {ours}")
        if o.get("ignore_errors", False):
            out.append(f"ignore_errors for {ours}: fix the errors instead")
        if any(m.startswith(f"spatialmech.{c.rsplit('/', 1)[1]}") for c in CORE for m in ours):
            out.append(f"an override of the numerical core: {ours}")
    return out


def test_mypy_config_covers_the_whole_package():
    problems = config_problems(_config()["tool"]["mypy"])
    assert not problems, "\n".join(problems)


def test_the_config_check_flags_an_ignored_module():
    """The check can fail: an ``ignore_errors`` override of any spatialmech module is refused
    (third-party overrides are not)."""
    cfg = {**_config()["tool"]["mypy"]}
    assert config_problems(cfg) == []
    for mods in (["spatialmech.api.*"], "spatialmech.services.studio.session", ["scipy", "spatialmech.interfaces.*"]):
        bad = {**cfg, "overrides": [*cfg.get("overrides", []), {"module": mods, "ignore_errors": True}]}
        found = config_problems(bad)
        assert len(found) == 1 and "ignore_errors" in found[0], found
    ok = {**cfg, "overrides": [*cfg.get("overrides", []), {"module": ["pyarrow.*"], "ignore_errors": True}]}
    assert config_problems(ok) == []
    assert any("files" in m for m in config_problems({**cfg, "files": ["src/spatialmech/api"]}))


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
