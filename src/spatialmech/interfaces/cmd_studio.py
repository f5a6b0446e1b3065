"""``spatialmech studio``: the interactive design studio in the browser (docs/studio.md).

Thin: load the model into a session (``sm.studio_session``), build the app (:mod:`.studio.app`),
serve it with uvicorn on 127.0.0.1 and open the browser.
"""

from __future__ import annotations

import socket
import threading
import webbrowser

import click

from .. import api as sm
from ..errors import require
from .common import UserError, emit_json, load_model

__all__ = ["studio"]


def _free(port: int) -> bool:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as uvicorn: a closed server's port is free
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


@click.command(name="studio")
@click.argument("model", required=False, default="five-cs-3")
@click.option("--port", type=click.IntRange(0, 65535), default=8765, show_default=True,
              help="Port on 127.0.0.1 (0: any free port).")
@click.option("--no-browser", is_flag=True, help="Do not open a browser (print the address only).")
@click.option("--view", type=click.Choice(["auto", "light", "full"]), default="auto", show_default=True,
              help="The page's 3-D view: light (a Canvas 2-D drawing, fast where WebGL is rendered in "
                   "software), full (plotly's WebGL scene) or auto (light where the browser's WebGL is software).")
@click.option("--json", "as_json", is_flag=True,
              help="Print the address and the starting state as JSON (docs/json.md) before serving.")
def studio(model, port, no_browser, view, as_json):
    """Open MODEL (default five-cs-3) in the interactive design studio: a local web page where
    sliders drive the actuators and the real solver (continuation along the current branch)
    answers with the new configuration, joint readouts, DJ and sigma_min, and events at DJ
    zeros.  Serves on 127.0.0.1 only, works offline; Ctrl-C stops it.

    \b
    Examples:
      spatialmech studio five-cs-3
      spatialmech studio stewart-6sps --port 8800 --no-browser
      spatialmech studio planar-4r --view light
    """
    require("plot", "plotly", what="the studio")
    require("studio", "fastapi", "uvicorn", what="the studio")
    import uvicorn

    from .studio.app import COMMAND, create_app

    session = sm.studio_session(load_model(model))  # bad models fail here, with the CLI's one-line error
    if port == 0:
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
    elif not _free(port):
        raise UserError(f"--port: 127.0.0.1:{port} is in use; pick another port (or --port 0 for any free one)")
    url = f"http://127.0.0.1:{port}/"
    if as_json:
        emit_json(COMMAND, session.mech, {"url": url, "port": port, "view": view, "state": session.state()})
    else:
        click.echo(f"spatialmech studio: {session.mech.name} at {url} ({view} 3-D view; Ctrl-C to stop)")
    if not no_browser:
        threading.Timer(1.0, lambda: webbrowser.open(url)).start()
    uvicorn.run(create_app(session, view), host="127.0.0.1", port=port, log_level="warning")
