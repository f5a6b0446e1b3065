"""mkdocs hook (mkdocs.yml ``hooks``), before each build:

* docs/generated/reference.md, the API reference of the public facade: one mkdocstrings block
  per name of ``spatialmech.__all__`` (the verbs, the model classes, the errors), so the
  reference follows the code's exports;
* docs/generated/views/bennett.html, an interactive viewer page (``sm.view``, plotly.js inline:
  no CDN) that docs/showcase.md embeds; made once (delete it to remake it).

And on each page, a link to the examples' README in the repository (``../examples/README.md``
from docs/index.md: what a reader browsing the repository on disk or on GitHub can open) becomes
a link to the executed gallery the site builds (``generated/gallery/index.md``).
"""

from __future__ import annotations

import inspect
import posixpath
import re
from pathlib import Path

#: A Markdown link to the examples' README (``](../examples/README.md)`` and the like).
_EXAMPLES_README = re.compile(r"\]\(((?:\.\./)+)examples/README\.md\)")
#: The executed gallery's index in the site (mkdocs.yml: the gallery plugin's gallery_dirs).
GALLERY_INDEX = "generated/gallery/index.md"

HEADER = """# API reference

Generated from the docstrings (numpydoc) of every public name of `spatialmech`
(`import spatialmech as sm`; docs/api.md is the one-page tour).  Units: SI and radians unless a
parameter says `degrees`.

"""


def on_pre_build(config, **kwargs) -> None:
    import spatialmech as sm

    verbs, classes, other = [], [], []
    for name in sorted(n for n in sm.__all__ if not n.startswith("_")):
        obj = getattr(sm, name)
        if inspect.ismodule(obj):
            continue
        where = f"{obj.__module__}.{obj.__qualname__}" if hasattr(obj, "__qualname__") else None
        if where is None:
            continue
        (verbs if inspect.isfunction(obj) else classes if inspect.isclass(obj) else other).append((name, where))
    lines = [HEADER, "## Functions\n"]
    lines += [f"::: {where}\n    options:\n      heading_level: 3\n" for _, where in verbs]
    lines += ["\n## Classes and errors\n"]
    lines += [f"::: {where}\n    options:\n      heading_level: 3\n      members: false\n" for _, where in classes]
    view = Path(config["docs_dir"]) / "generated" / "views" / "bennett.html"
    if not view.exists():
        view.parent.mkdir(parents=True, exist_ok=True)
        sm.view("bennett", view, frames=24, plotly="inline")
    out = Path(config["docs_dir"]) / "generated" / "reference.md"
    out.parent.mkdir(parents=True, exist_ok=True)
    text = "\n".join(lines)
    if not out.exists() or out.read_text(encoding="utf-8") != text:
        out.write_text(text, encoding="utf-8")


def on_page_markdown(markdown: str, page, config, files) -> str:
    """Links to the repository's examples/README.md point to the built gallery in the site."""
    docs = Path(config["docs_dir"]).resolve()
    readme = (docs.parent / "examples" / "README.md").resolve()
    here = posixpath.dirname(page.file.src_uri)

    def swap(m: re.Match) -> str:
        if (docs / here / m.group(1) / "examples" / "README.md").resolve() != readme:
            return m.group(0)
        return f"]({posixpath.relpath(GALLERY_INDEX, here or '.')})"

    return _EXAMPLES_README.sub(swap, markdown)
