"""The design studio in Jupyter (JupyterLab, VS Code, Colab): an anywidget over the same
:class:`~spatialmech.services.studio.session.Session` as the web app (``sm.studio(model)``).

The notebook frontend (``static/widget.js``, with plotly.js from the installed plotly package
and ``static/scene2d.js`` bundled into the widget's module: nothing from a CDN) draws the
:attr:`StudioWidget.figure` trait, in plotly's WebGL scene or in the light 3-D view (Canvas
2-D; :attr:`StudioWidget.view`), and the readouts of :attr:`StudioWidget.state`, and sends one
message per slider move::

    {"type": "drive", "actuators": [...]}          # model units, degrees for rotations
    {"type": "pose", "task_len": {...}, "task_deg": {...}}
    {"type": "drag", "point_len": [x, y, z]}      # the drag pad: the output point moved in a plane
    {"type": "fk_all"} / {"type": "mode", "mode_number": k}
    {"type": "snapshot", "label": "..."} / {"type": "undo"}   # the session's desk

Each message runs the session's operation (the same code as ``POST /api/drive`` and the others)
and answers by setting :attr:`~StudioWidget.last_drive` (status, message, events),
:attr:`~StudioWidget.state` and :attr:`~StudioWidget.figure`; bad input sets
:attr:`~StudioWidget.error` (the field named).  The same operations are methods for a notebook
cell (:meth:`StudioWidget.drive`, ...).
"""

from __future__ import annotations

import json
from functools import lru_cache
from importlib.resources import files

import anywidget
import traitlets

from ... import api as sm
from ...errors import ConvergenceError, InputError
from ...present.numbers import unit_label
from ...serialize import json_default
from .assets import check_view, plotly_js_path

__all__ = ["StudioWidget", "figure", "studio", "top_camera"]

#: Height of the 3-D view in the notebook (CSS pixels).
VIEW_HEIGHT_PX = 460


@lru_cache(maxsize=1)
def esm_bundle() -> str:
    """The widget's ES module: plotly.js (its UMD build, run with a local ``module`` object so
    that neither a page's AMD loader nor ``window`` is involved), then ``pad.js`` (the drag pad's
    geometry), ``scene2d.js`` (the light 3-D view), both shared with the page, and ``widget.js``."""
    plotly = plotly_js_path().read_text(encoding="utf-8")
    static = files("spatialmech.interfaces.studio").joinpath("static")
    pad, light, own = (static.joinpath(n).read_text(encoding="utf-8") for n in ("pad.js", "scene2d.js", "widget.js"))
    return ("const module = { exports: {} };\nconst exports = module.exports;\n" + plotly
            + "\nconst Plotly = module.exports;\n" + pad + "\n" + light + "\n" + own)


def _plain(doc):
    """``doc`` as plain JSON values (what a trait can carry); NaN refused as in the web app."""
    return json.loads(json.dumps(doc, default=json_default, allow_nan=False))


def _xyz(pts) -> dict:
    return {"x": [p[0] for p in pts], "y": [p[1] for p in pts], "z": [p[2] for p in pts]}


def figure(state: dict, unit: str) -> dict:
    """The plotly figure (``data``, ``layout``) of a session state: base and platform outlines,
    the limbs, the joint centres, the platform frame and the platform point's path.  The traces
    keep their order and names from one state to the next (the frontend's ``Plotly.react``
    then updates them in place)."""
    sc = state["scene"]
    line = lambda pts, colour, width, name, **kw: {  # noqa: E731
        "type": "scatter3d", "mode": "lines", **_xyz(pts), "line": {"color": colour, "width": width}, "name": name, **kw}
    data = [line(sc["base_len"], "#555555", 5, "base (ground)"),
            line(sc["platform_len"], "#ff7f0e", 6, "platform")]
    limbs = zip(sc["limbs_len"], sc["limb_names"], strict=True)
    data += [line(pl, sc["limb_colours"][k], 8, name) for k, (pl, name) in enumerate(limbs)]
    joints = sc["joints"]
    data.append({"type": "scatter3d", "mode": "markers", **_xyz([j["centre_len"] for j in joints]),
                 "marker": {"size": 3, "color": "#222222"}, "text": [f"{j['name']} ({j['type']})" for j in joints],
                 "hovertemplate": "%{text}<extra></extra>", "name": "joints"})
    p, fr, s = sc["platform_point_len"], sc["platform_frame"], 0.3 * sc["scale_len"]
    for a, colour in enumerate(("#d62728", "#2ca02c", "#1f77b4")):
        e = [p[i] + s * fr[i][a] for i in range(3)]
        data.append(line([p, e], colour, 6, "platform frame " + "xyz"[a], showlegend=False))
    trail = sc["trail_len"] if len(sc["trail_len"]) > 1 else [p]
    data.append({**line(trail, "#ff7f0e", 2, "platform point path"), "line": {"color": "#ff7f0e", "width": 2, "dash": "dot"}})
    ax = {n: {"title": {"text": f"{n} [{unit}]"}} for n in "xyz"}
    planar = sc.get("plane_normal") is not None  # a planar linkage: its top view, as the page opens it
    scene: dict = {"aspectmode": "data", "xaxis": ax["x"], "yaxis": ax["y"], "zaxis": ax["z"]}
    if planar:
        scene["camera"] = top_camera(sc["plane_normal"])
    layout = {"uirevision": "studio", "height": VIEW_HEIGHT_PX, "margin": {"l": 0, "r": 0, "t": 30, "b": 0},
              "title": {"text": state["mechanism"] + (" (top view: along the plane's normal)" if planar else "")},
              "scene": scene, "legend": {"itemsizing": "constant"}}
    return {"data": data, "layout": layout}


def top_camera(normal) -> dict:
    """The plotly camera looking along a planar linkage's plane ``normal`` (orthographic), with
    the world axis least along it (y first) made perpendicular to it as "up" (as the page's
    ``planeBasis``)."""
    n = [float(v) for v in normal]
    dot = lambda a, b: sum(x * y for x, y in zip(a, b, strict=True))  # noqa: E731
    cand = min(([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), key=lambda a: abs(dot(a, n)))
    up = [c - dot(cand, n) * v for c, v in zip(cand, n, strict=True)]
    norm = dot(up, up) ** 0.5
    return {"eye": dict(zip("xyz", (2.0 * v for v in n), strict=True)),
            "up": dict(zip("xyz", (v / norm for v in up), strict=True)),
            "center": {"x": 0.0, "y": 0.0, "z": 0.0}, "projection": {"type": "orthographic"}}


class StudioWidget(anywidget.AnyWidget):
    """The studio as a notebook widget over ``session`` (a :func:`spatialmech.studio_session`)."""

    _esm = traitlets.Unicode("").tag(sync=True)
    #: The session's readout (``Session.state()``, docs/studio.md) and the model's length unit as
    #: labels show it (``present.numbers.unit_label``: "length unit not stated" where none is).
    state = traitlets.Dict().tag(sync=True)
    unit = traitlets.Unicode("").tag(sync=True)
    #: The 3-D view: ``{"data": [...], "layout": {...}}`` (plotly).
    figure = traitlets.Dict().tag(sync=True)
    #: What the last operation did (``DriveResult.to_dict()``, or ``{"status": ...}``) and the
    #: number of operations answered (the frontend sends its next slider value when it grows).
    last_drive = traitlets.Dict().tag(sync=True)
    answered = traitlets.Int(0).tag(sync=True)
    #: The last bad input or failed computation ("" when the last operation went through).
    error = traitlets.Unicode("").tag(sync=True)
    #: The assembly modes of the last ``fk_all``.
    modes: traitlets.List[dict] = traitlets.List().tag(sync=True)
    #: The snapshots kept (``session.desk.listing()``).
    snapshots: traitlets.List[dict] = traitlets.List().tag(sync=True)
    #: The 3-D view asked for: "auto" (the light view where the browser renders WebGL in
    #: software or has none, plotly's WebGL scene elsewhere), "light" or "full".
    view = traitlets.Unicode("auto").tag(sync=True)

    @traitlets.validate("view")
    def _valid_view(self, proposal):
        return check_view(proposal["value"])

    def __init__(self, session, view: str = "auto", **kwargs):
        super().__init__(_esm=esm_bundle(), view=check_view(view), **kwargs)
        self.session = session
        self.on_msg(self._on_message)
        self._refresh()

    # ------------------------------------------------------------------ operations (cells or messages)
    def drive(self, actuators):
        """Drive the actuators to ``actuators`` (as ``Session.drive``) and redraw."""
        return self._run(lambda: self.session.drive(actuators))

    def drive_pose(self, task_len=None, task_deg=None, *, euler=None, relative=False):
        """Move the output link to a pose (as ``Session.drive_pose``) and redraw."""
        return self._run(lambda: self.session.drive_pose(task_len, task_deg, euler=euler, relative=relative))

    def drag_output(self, point_len):
        """Move the output point toward ``point_len`` (the drag pad; as ``Session.drag_output``)
        and redraw."""
        return self._run(lambda: self.session.drag_output(point_len))

    def fk_all(self, seeds=None) -> list[dict]:
        """Every assembly mode at the current actuator values (as ``Session.fk_all``)."""
        self.modes = _plain(self.session.fk_all(seeds))
        self.answered += 1
        return self.modes

    def pick_mode(self, number) -> None:
        """Move to mode ``number`` of the last :meth:`fk_all` and redraw."""
        self.session.pick_mode(number)
        self._refresh()
        self.answered += 1

    def snapshot(self, label=None) -> list[dict]:
        """Keep the current configuration (``session.desk.snapshot``)."""
        self.snapshots = _plain(self.session.desk.snapshot(label))
        self.answered += 1
        return self.snapshots

    def undo(self) -> str:
        """Back to the last snapshot, which is dropped (``session.desk.undo``); its label."""
        label = self.session.desk.undo()
        self.snapshots = _plain(self.session.desk.listing())
        self.last_drive = {"status": "undone", "message": f"back at {label}"}
        self._refresh()
        self.answered += 1
        return label

    def _run(self, op):
        r = op()
        self.last_drive = _plain(r.to_dict())
        self._refresh()
        self.answered += 1
        return r

    def _refresh(self) -> None:
        st = _plain(self.session.state())
        unit = unit_label(self.session.mech.length_unit)  # "length unit not stated" for paper A
        with self.hold_sync():
            self.unit = unit
            self.state = st
            self.figure = figure(st, unit)

    def _on_message(self, widget, content, buffers) -> None:
        """One message of the frontend (module docstring); bad input answers in :attr:`error`."""
        kind = content.get("type") if isinstance(content, dict) else None
        ops = {"drive": lambda c: self.drive(c.get("actuators")),
               "pose": lambda c: self.drive_pose(c.get("task_len"), c.get("task_deg"), euler=c.get("euler")),
               "drag": lambda c: self.drag_output(c.get("point_len")),
               "fk_all": lambda c: self.fk_all(c.get("seeds")),
               "mode": lambda c: self.pick_mode(c.get("mode_number")),
               "snapshot": lambda c: self.snapshot(c.get("label")), "undo": lambda c: self.undo()}
        try:
            if kind not in ops:
                raise InputError(f"type: unknown message {kind!r}; expected one of {', '.join(ops)}")
            ops[kind](content)
            self.error = ""
        except (InputError, ConvergenceError) as e:
            self.error = str(e)
            self.answered += 1


def studio(model: sm.ModelLike = "five-cs-3", view: str = "auto") -> StudioWidget:
    """The widget on a new session of ``model``; the public entry, which checks the ``notebook``
    extra first, is ``sm.studio`` (:func:`spatialmech.interfaces.studio.entry.studio`)."""
    view = check_view(view)
    return StudioWidget(sm.studio_session(model), view=view)
