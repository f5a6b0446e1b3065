"""Every verb of the facade (the functions of ``spatialmech.api.__all__``) has a numpydoc
docstring (issue 26, "Typed contract"): ``Parameters`` (each parameter of its signature, by
name), ``Returns`` and ``Raises`` sections (a verb without parameters: ``Returns``), and a
return annotation; its runnable examples stay
under ``Examples`` (tests/test_doctests.py runs them).  The check can fail: the last tests feed
it synthetic functions that break each rule."""

from __future__ import annotations

import inspect
import re
from collections.abc import Callable

import pytest

import spatialmech.api as api

#: ``Name\n----`` (the underline as long as the name or longer): a numpydoc section header.
_HEADER = re.compile(r"^(?P<name>[A-Z][A-Za-z ]*)\n-{3,}\s*$", re.M)
REQUIRED = ("Parameters", "Returns", "Raises")


def verbs() -> list[str]:
    return sorted(n for n in api.__all__ if inspect.isfunction(getattr(api, n)))


def sections(doc: str) -> dict[str, str]:
    """The numpydoc sections of a (dedented) docstring: header -> body."""
    heads = list(_HEADER.finditer(doc))
    return {h["name"]: doc[h.end():(heads[k + 1].start() if k + 1 < len(heads) else len(doc))]
            for k, h in enumerate(heads)}


def documented_parameters(body: str) -> list[str]:
    """The names a ``Parameters`` section documents: its unindented ``name : type`` lines
    (``a, b : type`` documents both; ``*args`` / ``**kw`` without the stars)."""
    names: list[str] = []
    for line in body.splitlines():
        if line and not line[0].isspace():
            head = line.split(" : ", 1)[0]
            names += [n.strip().lstrip("*") for n in head.split(",") if n.strip()]
    return names


def doc_problems(name: str, f: Callable) -> list[str]:
    """What ``f``'s docstring (numpydoc) and signature lack."""
    doc = inspect.getdoc(f) or ""
    if not doc:
        return [f"{name}: no docstring"]
    sig = inspect.signature(f)
    found = sections(doc)
    params = [p for p in sig.parameters if p not in ("self", "cls")]
    out = [f"{name}: no {s} section" for s in (REQUIRED if params else ("Returns",)) if s not in found]
    documented = documented_parameters(found.get("Parameters", ""))
    out += [f"{name}: parameter {p!r} is not documented" for p in params if p not in documented]
    out += [f"{name}: documents {p!r}, which is not a parameter" for p in documented if p not in params]
    if sig.return_annotation is inspect.Signature.empty:
        out.append(f"{name}: no return annotation")
    if ">>>" in doc and ">>>" not in found.get("Examples", ""):
        out.append(f"{name}: examples outside the Examples section")
    return out


def test_the_verbs_are_where_the_test_looks():
    names = verbs()
    assert len(names) >= 28 and {"ik", "fk", "workspace", "studio_session", "tolerances"} <= set(names), names


@pytest.mark.parametrize("name", verbs())
def test_every_verb_has_a_numpydoc_docstring(name):
    problems = doc_problems(name, getattr(api, name))
    assert not problems, "\n".join(problems)


def test_docs_api_md_names_every_verb():
    from pathlib import Path

    text = (Path(__file__).parent.parent / "docs" / "api.md").read_text(encoding="utf-8")
    missing = [n for n in verbs() if f"sm.{n}" not in text]
    assert not missing, f"docs/api.md does not show {missing}"


# ------------------------------------------------------------------ the check can fail
def _good(model, pose=None, *, degrees: bool = False) -> int:
    """One line.

    Parameters
    ----------
    model : str
        A model.
    pose, degrees : object
        Both.

    Returns
    -------
    int
        A number.

    Raises
    ------
    ValueError
        Never.

    Examples
    --------
    >>> 1
    1
    """
    return 1


def _no_raises(model, x) -> int:
    """One line.

    Parameters
    ----------
    model : str
        A model.

    Returns
    -------
    int
        A number.

    >>> 1
    1
    """
    return 1


def _no_annotation(model):
    """One line.

    Parameters
    ----------
    model : str
    extra : int

    Returns
    -------
    int

    Raises
    ------
    ValueError
    """


def test_the_check_accepts_a_complete_docstring():
    assert doc_problems("good", _good) == []


def test_the_check_flags_what_is_missing():
    found = doc_problems("bad", _no_raises)
    assert "bad: no Raises section" in found
    assert "bad: parameter 'x' is not documented" in found
    assert "bad: examples outside the Examples section" in found
    found = doc_problems("bad", _no_annotation)
    assert found == ["bad: documents 'extra', which is not a parameter", "bad: no return annotation"], found
    assert doc_problems("bad", lambda model: 1) == ["bad: no docstring"]

    def no_parameters() -> int:
        """One line.

        Returns
        -------
        int
        """
        return 1

    assert doc_problems("ok", no_parameters) == []
    no_parameters.__doc__ = "One line."
    assert doc_problems("bad", no_parameters) == ["bad: no Returns section"]
