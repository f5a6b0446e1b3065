"""The documentation runs: every ``spatialmech`` command and Python snippet in docs/*.md, and
every example is listed in examples/README.md.  Its own file (it was in tests/test_report.py) so
that ``--dist loadfile`` can give it and the demo report's tests to different workers: both are
among the longest files of the suite."""

import re
import shlex
from pathlib import Path

import pytest
from click.testing import CliRunner

from spatialmech.interfaces.cli import cli

ROOT = Path(__file__).parent.parent
DOCS = sorted((ROOT / "docs").glob("*.md"))
#: Pages of the user guide that must contain runnable blocks.
MY_PAGES = ("index.md", "kinematics.md", "viewer.md", "report.md", "file-format.md", "synthesis.md")


def _blocks(text: str, lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", text, flags=re.S)


#: Commands run as ``--help`` only: the demo (tests/test_report.py) and multi-start searches.
def _cheap(args: list[str]) -> list[str]:
    if args[0] == "demo" or "--all" in args:
        return [args[0], "--help"]
    return args


#: Pages whose blocks run in about a second; the others are slow (deselected by pytest -m "not slow").
QUICK_PAGES = ("conventions.md", "file-format.md", "mobility.md", "workspace.md")


@pytest.mark.parametrize("page", [pytest.param(p, id=p.name, marks=[] if p.name in QUICK_PAGES else [pytest.mark.slow])
                                  for p in DOCS])
def test_docs_commands_and_python_run(page, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    text = page.read_text(encoding="utf-8")
    ran = 0
    for block in _blocks(text, "sh"):
        for line in block.splitlines():
            line = line.split(" #")[0].strip()
            if not line.startswith("spatialmech "):
                continue
            args = _cheap(shlex.split(line)[1:])
            r = CliRunner().invoke(cli, args, catch_exceptions=False)
            assert r.exit_code == 0, f"{page.name}: {line}\n{r.output}"
            ran += 1
    ns: dict = {}
    for block in _blocks(text, "python"):
        exec(compile(block, f"{page.name}:python", "exec"), ns)
        ran += 1
    for block in _blocks(text, "toml"):
        if "[[limbs]]" in block and "{...}" not in block and block.lstrip().startswith("name"):
            from spatialmech import loads

            assert loads(block).limbs
            ran += 1
    if page.name in MY_PAGES:
        assert ran, f"{page.name}: no runnable block"


def test_examples_readme_lists_every_example():
    readme = (ROOT / "examples" / "README.md").read_text(encoding="utf-8")
    for p in (ROOT / "examples").glob("*.py"):
        assert f"({p.name})" in readme, p.name
