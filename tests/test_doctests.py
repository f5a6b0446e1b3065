"""Every ``>>>`` example in the package's docstrings runs and prints what it says.

The modules are collected with :mod:`pkgutil` (every module of ``spatialmech`` whose source has
a ``>>>``), so a new docstring example is tested without registering it here.  Examples that
take more than a few seconds are marked ``slow`` (``SLOW``); none is skipped.
"""

from __future__ import annotations

import doctest
import importlib
import importlib.util
import pkgutil

import pytest

import spatialmech

#: Modules whose examples take more than a few seconds (run by the full suite only).
SLOW = {"spatialmech.synthesis.cs_dyads", "spatialmech.api", "spatialmech.api.kinematics", "spatialmech.api.spaces",
        "spatialmech.api.linkages", "spatialmech.api.outputs", "spatialmech.analysis.workspace",
        "spatialmech.synthesis"}

#: Modules that must have examples (the public API page's functions, the errors, the package).
REQUIRED = {"spatialmech", "spatialmech.api", "spatialmech.api.structure", "spatialmech.api.kinematics",
            "spatialmech.api.spaces",
            "spatialmech.api.linkages", "spatialmech.api.outputs", "spatialmech.errors", "spatialmech.results"}


def _modules_with_examples() -> list[str]:
    names = ["spatialmech"]
    names += [m.name for m in pkgutil.walk_packages(spatialmech.__path__, "spatialmech.")]
    out = []
    for name in names:
        spec = importlib.util.find_spec(name)
        if spec is None or spec.origin is None or not spec.origin.endswith(".py"):
            continue
        with open(spec.origin, encoding="utf-8") as f:  # read, not import: importing has side effects
            if ">>>" in f.read():
                out.append(name)
    return sorted(out)


MODULES = _modules_with_examples()


def test_the_required_modules_have_examples():
    assert set(MODULES) >= REQUIRED, REQUIRED - set(MODULES)


@pytest.mark.parametrize(
    "name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in MODULES]
)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    res = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False,
                          report=True)
    assert res.attempted > 0, f"{name}: no example found"
    assert res.failed == 0, f"{name}: {res.failed} of {res.attempted} examples failed (see the output above)"


def test_every_public_api_function_has_an_example():
    """docs/api.md promises a runnable example for every function of ``sm``."""
    from spatialmech import api

    # the functions are defined in the api package's modules (a finder only looks at the objects
    # a module defines itself, not at those it re-exports)
    finder = doctest.DocTestFinder()
    modules = [api] + [importlib.import_module(m.name) for m in pkgutil.iter_modules(api.__path__, "spatialmech.api.")]
    with_examples = {t.name.rsplit(".", 1)[-1] for m in modules for t in finder.find(m) if t.examples}
    functions = {n for n in api.__all__ if callable(getattr(api, n)) and not isinstance(getattr(api, n), type)}
    assert functions <= with_examples, functions - with_examples
