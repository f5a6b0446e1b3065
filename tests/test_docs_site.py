"""The documentation site's configuration stays in step with docs/ and examples/ (issue 31).

The site itself is built by .ci/run (``mkdocs build --strict``: the gallery executes every
example; a failing example, a broken link or a page missing from the nav fails it).  These
cheap checks catch the usual drift without building it."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).parent.parent
yaml = pytest.importorskip("yaml", reason="PyYAML (the docs extra's mkdocs brings it) is not installed")


def _nav_pages(nav) -> list[str]:
    out = []
    for item in nav:
        value = next(iter(item.values())) if isinstance(item, dict) else item
        out += _nav_pages(value) if isinstance(value, list) else [value]
    return out


def _config() -> dict:
    class Loader(yaml.SafeLoader):
        pass

    Loader.add_multi_constructor("tag:yaml.org,2002:python/", lambda *a: None)  # mkdocs' !!python tags
    return yaml.load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"), Loader=Loader)


def test_every_docs_page_is_in_the_nav():
    pages = set(_nav_pages(_config()["nav"]))
    missing = sorted(p.name for p in (ROOT / "docs").glob("*.md") if p.name not in pages)
    assert not missing, f"mkdocs.yml nav does not list {missing}"
    stale = sorted(p for p in pages if not p.startswith("generated/") and not (ROOT / "docs" / p).exists())
    assert not stale, f"mkdocs.yml nav lists missing pages {stale}"


def test_the_site_is_offline_and_strict():
    cfg = _config()
    plugins = [next(iter(p)) if isinstance(p, dict) else p for p in cfg["plugins"]]
    assert {"search", "offline", "gallery", "mkdocstrings"} <= set(plugins)
    assert cfg["strict"] is True and cfg["use_directory_urls"] is False and cfg["theme"]["font"] is False


def test_every_example_has_a_gallery_title():
    """mkdocs-gallery titles each example by the first line of its docstring."""
    for path in sorted((ROOT / "examples").glob("*.py")):
        doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8")))
        assert doc and doc.splitlines()[0].strip(), f"{path.name}: no docstring title"
