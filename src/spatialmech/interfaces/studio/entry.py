"""The studio's entry points on the facade, ``sm.studio`` (the Jupyter widget) and
``sm.studio_app`` (the web app): each checks the extras its frontend needs before importing
them, so a missing one is one :class:`~spatialmech.errors.MissingExtraError` naming the extra to
install (an ``InputError`` and an ``ImportError``), not an import error from deep inside.  This
module imports no optional package: ``import spatialmech`` and ``from spatialmech import *`` work
on the core install."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ...errors import require

if TYPE_CHECKING:
    from fastapi import FastAPI

    from ...api import ModelLike
    from .widget import StudioWidget

__all__ = ["studio", "studio_app"]


def studio(model: ModelLike = "five-cs-3", view: str = "auto") -> StudioWidget:
    """The design studio as a Jupyter widget (anywidget) on a new session
    (:func:`spatialmech.studio_session`): the live mechanism in 3-D with actuator sliders and the
    readouts.  Needs the ``notebook`` extra (``pip install 'spatialmech[notebook]'``).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    view : {"auto", "light", "full"}
        The 3-D view: ``"auto"`` (default) draws the light view (Canvas 2-D) where the browser
        renders WebGL in software (remote desktops, VMs, headless browsers) and plotly's WebGL
        scene elsewhere; ``"light"`` or ``"full"`` asks for one.  The widget's buttons switch it.

    Returns
    -------
    StudioWidget
        The widget; its ``session`` is the :class:`~spatialmech.services.studio.session.Session`,
        its ``state`` and ``figure`` traits the readout and the 3-D view.

    Raises
    ------
    MissingExtraError
        anywidget or plotly is not installed (the ``notebook`` extra), before any work.
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad model (as :func:`spatialmech.studio_session`), or a ``view`` not in the list.

    Examples
    --------
    >>> import spatialmech as sm
    >>> w = sm.studio("rssr")            # the last expression of a notebook cell shows it
    >>> str(w.drive([10.0]).status), round(w.state["actuators_deg"]["A0.rot"], 9)
    ('reached', 10.0)
    """
    require("notebook", "anywidget", what="sm.studio (the studio in Jupyter)")
    require("notebook", "plotly", what="sm.studio (the studio in Jupyter)")  # the widget bundles plotly.js
    from .assets import check_view
    from .widget import StudioWidget
    from ... import api as sm

    view = check_view(view)
    return StudioWidget(sm.studio_session(model), view=view)


def studio_app(model: ModelLike = "five-cs-3", view: str = "auto") -> FastAPI:
    """The design studio's web app (FastAPI) on a new session (:func:`spatialmech.studio_session`):
    serve it with uvicorn, or call its JSON API directly (docs/studio.md).  Needs the ``studio``
    extra (``pip install 'spatialmech[studio]'``).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    view : {"auto", "light", "full"}
        The page's 3-D view: ``"auto"`` (default) the light one (Canvas 2-D) where the browser
        renders WebGL in software, plotly's WebGL scene elsewhere; ``"light"`` or ``"full"``
        asks for one (a page's ``?view=`` overrides it, its buttons switch it).

    Returns
    -------
    FastAPI
        The app: ``POST /api/drive`` and the other routes of docs/studio.md.

    Raises
    ------
    MissingExtraError
        FastAPI or plotly is not installed (the ``studio`` extra), before any work.
    InputError
        A bad model (as :func:`spatialmech.studio_session`), or a ``view`` not in the list.

    Examples
    --------
    >>> import spatialmech as sm
    >>> from fastapi.testclient import TestClient
    >>> client = TestClient(sm.studio_app("rssr"))
    >>> client.post("/api/drive", json={"actuators": [10.0]}).json()["status"]
    'reached'
    >>> client.post("/api/drive", json={"actuators": [1, 2]}).json()["error"]
    'actuators: expected 1 values (A0.rot), got 2'
    """
    require("studio", "fastapi", what="sm.studio_app (the studio's web app)")
    require("studio", "plotly", what="sm.studio_app (the studio's web app)")
    from .app import create_app
    from .assets import check_view
    from ... import api as sm

    view = check_view(view)
    return create_app(sm.studio_session(model), view)
