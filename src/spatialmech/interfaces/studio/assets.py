"""Files the studio's frontends load: plotly.js from the installed plotly package (the web app
serves it, the Jupyter widget bundles it).  Imports neither FastAPI nor anywidget, so either
frontend can use it with only its own extra installed."""

from __future__ import annotations

from pathlib import Path

from ...errors import InputError, require

__all__ = ["plotly_js_path"]


def plotly_js_path() -> Path:
    """``plotly.min.js`` shipped inside the installed plotly package (the ``plot`` extra)."""
    require("plot", "plotly", what="the studio")
    import plotly

    p = Path(plotly.__file__).parent / "package_data" / "plotly.min.js"
    if not p.is_file():  # pragma: no cover - a broken plotly installation
        raise InputError(f"plotly: {p} is missing; reinstall plotly")
    return p
