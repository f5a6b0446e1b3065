"""What the studio's frontends share: plotly.js from the installed plotly package (the web app
serves it, the Jupyter widget bundles it) and the choice of 3-D view (``view="auto"``,
``"light"`` or ``"full"``).  Imports neither FastAPI nor anywidget, so either frontend can use
it with only its own extra installed."""

from __future__ import annotations

from pathlib import Path

from ...errors import InputError, require

__all__ = ["VIEWS", "check_view", "plotly_js_path"]

#: The 3-D views a frontend can be asked for: ``auto`` (the light view where the browser renders
#: WebGL in software or has none, plotly's WebGL scene elsewhere), ``light`` (a Canvas 2-D
#: drawing, static/scene2d.js) and ``full`` (plotly's gl3d scene).
VIEWS = ("auto", "light", "full")


def check_view(view: object) -> str:
    """``view`` if it is one of :data:`VIEWS`, else an :class:`~spatialmech.errors.InputError`
    naming the field and the choices."""
    if not isinstance(view, str) or view not in VIEWS:
        raise InputError(f"view: expected one of {', '.join(map(repr, VIEWS))}, got {view!r}")
    return view


def plotly_js_path() -> Path:
    """``plotly.min.js`` shipped inside the installed plotly package (the ``plot`` extra)."""
    require("plot", "plotly", what="the studio")
    import plotly

    p = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"
    if not p.is_file():  # pragma: no cover - a broken plotly installation
        raise InputError(f"plotly: {p} is missing; reinstall plotly")
    return p
