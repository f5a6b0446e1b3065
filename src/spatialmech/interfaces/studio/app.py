"""The design studio's web app (FastAPI): the page, plotly.js from the installed plotly package
(nothing from a CDN: it works offline), and a JSON API over one :class:`~spatialmech.services.studio.session.Session`.

Every API answer is a JSON document with the envelope of docs/json.md (``command: "studio"``)
and units in the field names; bad input answers 4xx with ``{"error": "<field>: ..."}``.

=====================  ==================================================================
``GET /api/model``     the model (``model_info``) and the current ``state``
``GET /api/state``     the current ``state``
``GET /api/circuit``   a 1-DOF model's traced circuit through the current configuration
                       (``circuit_len``) and the DJ zeros of its driver (``dj_zeros_len``)
``POST /api/drive``    ``{"actuators": [...]}`` (model units, degrees for rotations; a list in
                       the order of ``drivers`` or a map by name): drive along the current
                       branch; answers ``status``, ``message``, ``events`` and the new ``state``
``POST /api/pose``     ``{"task_len": {"z": ...}, "task_deg": {"a2": ...}, "euler": "ZYX",
                       "relative": false}``: move the output link to a pose (its given task
                       coordinates; x, y, z in the model's length unit, Euler angles in degrees
                       in the named sequence; ``relative``: increments) along the current
                       branch; answers like ``/api/drive``
``POST /api/drivers``  ``{"drivers": [...]}``: switch the driving freedoms
``POST /api/fk_all``   ``{"seeds": n}`` (optional): every assembly mode at the current values
``POST /api/mode``     ``{"mode_number": k}``: move to mode k of the last ``fk_all``
``POST /api/load``     ``{"model": "name or path"}``: another model
``POST /api/snapshot`` ``{"label": "..."}`` (optional): keep the configuration; ``snapshots``
``POST /api/undo``     back to the last snapshot (dropped); ``POST /api/restore``
                       ``{"number": k}``: back to snapshot k (kept)
``POST /api/coupler``  ``{"point_len": [x, y, z]}`` (output-link frame, optional): the path of
                       that point (``curve_len``) over the circuit or the driver's range
``POST /api/sweep``    ``{"driver": name, "samples": n}`` (optional): joint values,
                       ``transmission_min`` and ``sigma_min`` against one driver's ``input``
``GET /api/path.csv``  the driven path as the CSV of ``validate --actuators-path``
=====================  ==================================================================

Every route that answers a ``state`` takes ``?solids=0``: the scene without the joint solids
(``joint_meshes`` empty), which the light 3-D view does not draw (a smaller, faster answer).

Updates are answered by POST (the page sends the next slider value when the previous answer
has arrived); there are no websockets.
"""

from __future__ import annotations

import json
import threading
from importlib.resources import files

from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, Response

from ... import api as sm
from ...errors import ConvergenceError, InputError
from ...serialize import envelope, json_default
from .assets import check_view, plotly_js_path

__all__ = ["COMMAND", "create_app", "plotly_js_path", "studio_app"]

#: The ``command`` of every API document (and of ``spatialmech studio --json``).
COMMAND = "studio"


def _static(name: str) -> bytes:
    return files("spatialmech.interfaces.studio").joinpath("static", name).read_bytes()


def _json(doc: dict, status: int = 200) -> Response:
    return Response(json.dumps(doc, default=json_default, allow_nan=False), status_code=status,
                    media_type="application/json")


def _state(session, request: Request) -> dict:
    """``session.state()`` for ``request``: ``?solids=0`` leaves the joint solids out (the light view)."""
    return session.state(solids=request.query_params.get("solids") != "0")


def create_app(session, view: str = "auto") -> FastAPI:
    """The app over ``session`` (a :func:`spatialmech.studio_session`; one model at a time, one
    user: each call holds a lock).  ``view``: the page's 3-D view, ``"auto"`` (the light one where
    the browser renders WebGL in software), ``"light"`` or ``"full"`` (plotly's WebGL scene); the
    page's ``?view=`` overrides it."""
    view = check_view(view)
    app = FastAPI(title="spatialmech studio", docs_url=None, redoc_url=None, openapi_url=None)
    lock = threading.Lock()
    app.state.session = session

    def doc(payload: dict) -> dict:
        m = session.mech
        return envelope(COMMAND, m.name, payload, length_unit=m.length_unit)

    def error(msg: str, status: int = 422) -> Response:
        return _json({"error": msg}, status)

    async def body(request: Request, required: str | None) -> dict:
        raw = await request.body()
        if not raw.strip():
            if required:
                raise InputError(f"body: expected a JSON object with {required!r}")
            return {}
        try:
            data = json.loads(raw)
        except ValueError as e:
            raise InputError(f"body: not JSON ({e})") from None
        if not isinstance(data, dict):
            raise InputError(f"body: expected a JSON object, got {type(data).__name__}")
        if required and required not in data:
            raise InputError(f"{required}: missing from the body (got {', '.join(map(repr, data)) or 'nothing'})")
        return data

    def guarded(fn):
        async def run(request: Request):
            try:
                return await fn(request)
            except InputError as e:
                return error(str(e))
            except ConvergenceError as e:
                return error(f"the computation failed: {e}", 409)
        run.__name__ = fn.__name__
        return run

    @app.get("/", response_class=HTMLResponse)
    def index():
        page = _static("index.html").decode("utf-8")
        return HTMLResponse(page.replace('<body data-view="auto">', f'<body data-view="{view}">'))

    @app.get("/favicon.ico")
    def favicon():
        return Response(status_code=204)

    @app.get("/static/{name}")
    def static(name: str):
        types = {"studio.js": "text/javascript", "pad.js": "text/javascript", "design.js": "text/javascript",
                 "scene2d.js": "text/javascript", "studio.css": "text/css"}
        if name == "plotly.min.js":
            return Response(plotly_js_path().read_bytes(), media_type="text/javascript",
                            headers={"Cache-Control": "max-age=86400"})
        if name not in types:
            return error(f"name: no static file {name!r}", 404)
        return Response(_static(name), media_type=types[name])

    @app.get("/api/model")
    def model(request: Request):
        with lock:
            return _json(doc({"model_info": session.model_info(), "state": _state(session, request)}))

    @app.get("/api/state")
    def state(request: Request):
        with lock:
            return _json(doc({"state": _state(session, request)}))

    async def circuit(request: Request):
        with lock:
            return _json(doc(session.circuit()))

    async def drive(request: Request):
        data = await body(request, "actuators")
        with lock:
            r = session.drive(data["actuators"])
            return _json(doc({**r.to_dict(), "state": _state(session, request)}))

    async def pose(request: Request):
        data = await body(request, None)
        extra = sorted(set(data) - {"task_len", "task_deg", "euler", "relative"})
        if extra:
            raise InputError(f"{extra[0]}: unknown field; expected task_len, task_deg, euler, relative")
        if "task_len" not in data and "task_deg" not in data:
            raise InputError("task_len: give task_len (x, y, z) and/or task_deg (a1, a2, a3) in the body")
        with lock:
            r = session.drive_pose(data.get("task_len"), data.get("task_deg"), euler=data.get("euler"),
                                   relative=data.get("relative", False))
            return _json(doc({**r.to_dict(), "state": _state(session, request)}))

    async def drivers(request: Request):
        data = await body(request, "drivers")
        with lock:
            session.set_drivers(data["drivers"])
            return _json(doc({"state": _state(session, request)}))

    async def fk_all(request: Request):
        data = await body(request, None)
        with lock:
            sols = session.fk_all(data.get("seeds"))
            return _json(doc({"n_solutions": len(sols), "solutions": sols}))

    async def mode(request: Request):
        data = await body(request, "mode_number")
        with lock:
            session.pick_mode(data["mode_number"])
            return _json(doc({"state": _state(session, request)}))

    async def load(request: Request):
        data = await body(request, "model")
        if not isinstance(data["model"], str):
            raise InputError(f"model: expected a model name or file path, got {data['model']!r}")
        with lock:
            session.load(data["model"])
            return _json(doc({"model_info": session.model_info(), "state": _state(session, request)}))

    app.add_api_route("/api/circuit", guarded(circuit), methods=["GET"])
    add_desk_routes(app, session, lock, doc, body, guarded)
    for path, fn in (("/api/drive", drive), ("/api/pose", pose),
                     ("/api/drivers", drivers), ("/api/fk_all", fk_all), ("/api/mode", mode),
                     ("/api/load", load)):
        app.add_api_route(path, guarded(fn), methods=["POST"])
    return app


def add_desk_routes(app: FastAPI, session, lock, doc, body, guarded) -> None:
    """The design tools' routes (``session.desk``: snapshots, undo, coupler curve, sweep, the
    driven path as CSV) on ``app``, with the helpers of :func:`create_app`."""

    async def snapshot(request: Request):
        data = await body(request, None)
        with lock:
            return _json(doc({"snapshots": session.desk.snapshot(data.get("label"))}))

    async def undo(request: Request):
        with lock:
            label = session.desk.undo()
            return _json(doc({"restored": label, "snapshots": session.desk.listing(), "state": _state(session, request)}))

    async def restore(request: Request):
        data = await body(request, "number")
        with lock:
            session.desk.restore(data["number"])
            return _json(doc({"snapshots": session.desk.listing(), "state": _state(session, request)}))

    async def coupler(request: Request):
        data = await body(request, None)
        with lock:
            return _json(doc(session.desk.coupler_curve(data.get("point_len"), data.get("frames", 240))))

    async def sweep(request: Request):
        data = await body(request, None)
        with lock:
            return _json(doc(session.desk.sweep(data.get("driver"), data.get("samples", 61))))

    async def drag(request: Request):
        data = await body(request, "point_len")
        with lock:
            r = session.drag_output(data["point_len"])
            return _json(doc({**r.to_dict(), "state": _state(session, request)}))

    async def path_csv(request: Request):
        with lock:
            name = session.mech.name
            return Response(session.desk.path_csv(), media_type="text/csv",
                            headers={"Content-Disposition": f'attachment; filename="{name}-path.csv"'})

    app.add_api_route("/api/path.csv", guarded(path_csv), methods=["GET"])
    for path, fn in (("/api/snapshot", snapshot), ("/api/undo", undo), ("/api/restore", restore),
                     ("/api/coupler", coupler), ("/api/sweep", sweep), ("/api/drag", drag)):
        app.add_api_route(path, guarded(fn), methods=["POST"])


def studio_app(model: sm.ModelLike = "five-cs-3", view: str = "auto") -> FastAPI:
    """The web app on a new session of ``model``; the public entry, which checks the ``studio``
    extra first, is ``sm.studio_app`` (:func:`spatialmech.interfaces.studio.entry.studio_app`)."""
    view = check_view(view)
    return create_app(sm.studio_session(model), view)
