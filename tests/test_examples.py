"""Every script in examples/ runs and its own assertions on the physics pass."""

import runpy
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).parent.parent / "examples").glob("*.py"))
#: Examples that take more than ~2 s (deselected by the quick loop, pytest -m "not slow").
SLOW_EXAMPLES = {"stewart_forward_all.py", "rssr_from_file.py", "rccc_synthesis.py", "screen_five_cs.py", "singularity_map.py",
                 "cad_parts.py"}


@pytest.mark.parametrize("path", [pytest.param(p, id=p.name, marks=[pytest.mark.slow] if p.name in SLOW_EXAMPLES else [])
                                  for p in EXAMPLES])
def test_example_runs(path, capsys):
    runpy.run_path(str(path), run_name="__main__")


def test_there_are_examples():
    assert EXAMPLES
