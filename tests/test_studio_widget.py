"""The studio in Jupyter (``sm.studio``, an anywidget over the studio session) run headless: the
messages the frontend sends (``{"type": "drive", ...}``) go through the widget's message handler
as ipywidgets delivers them, and the traits the frontend draws (``state``, ``figure``,
``last_drive``, ``answered``, ``error``) carry the new configuration; plus the results'
``_repr_html_`` tables.  The frontend itself runs in Chromium in tests/test_studio_widget_browser.py."""

import json

import numpy as np
import pytest

import spatialmech as sm

pytest.importorskip("anywidget")


@pytest.fixture(scope="module")
def widget():
    return sm.studio("rssr")


def send(w, content):
    """A message of the frontend, delivered as ipywidgets does (``model.send(content)`` in JS)."""
    w._handle_custom_msg(content, [])


def platform_point(fig) -> np.ndarray:
    frame = next(t for t in fig["data"] if t["name"] == "platform frame x")
    return np.array([frame["x"][0], frame["y"][0], frame["z"][0]])


def test_slider_message_drives_the_session_and_redraws(widget):
    w = widget
    n0, p0 = w.answered, platform_point(w.figure)
    send(w, {"type": "drive", "actuators": [25.0]})
    assert w.error == "" and w.last_drive["status"] == "reached"
    assert w.answered == n0 + 1                         # the frontend's cue to send the next value
    # the session moved, and the traits carry its new state and figure
    assert abs(np.degrees(w.session.actuator_values()[0]) - 25.0) < 1e-9
    assert abs(w.state["actuators_deg"]["A0.rot"] - 25.0) < 1e-9
    p1 = platform_point(w.figure)
    assert np.allclose(p1, w.state["scene"]["platform_point_len"], atol=1e-12)
    assert np.linalg.norm(p1 - p0) > 1e-3
    # the figure's traces keep their names and order (Plotly.react updates them in place)
    send(w, {"type": "drive", "actuators": [30.0]})
    names = [t["name"] for t in w.figure["data"]]
    assert names[:2] == ["base (ground)", "platform"] and "joints" in names
    assert w.figure["layout"]["scene"]["xaxis"]["title"]["text"] == f"x [{w.unit}]"


def test_the_widget_and_a_plain_session_agree():
    """The same session code: a widget drive and a session drive give the same pose."""
    w, s = sm.studio("rssr"), sm.studio_session("rssr")
    for v in (10.0, 40.0, -15.0):
        send(w, {"type": "drive", "actuators": [v]})
        s.drive([v])
    assert np.allclose(w.state["pose"]["position_len"], s.state()["pose"]["position_len"], atol=1e-12)


def test_bad_messages_name_the_field(widget):
    w = widget
    n0 = w.answered
    send(w, {"type": "drive", "actuators": [1.0, 2.0]})
    assert w.error == "actuators: expected 1 values (A0.rot), got 2" and w.answered == n0 + 1
    send(w, {"type": "teleport"})
    assert w.error.startswith("type: unknown message 'teleport'")
    send(w, {"type": "drive", "actuators": [5.0]})
    assert w.error == ""


def test_fk_all_and_mode_messages(widget):
    w = widget
    send(w, {"type": "fk_all"})
    assert w.error == "" and len(w.modes) >= 1
    send(w, {"type": "mode", "mode_number": 1})
    assert w.error == ""


def test_traits_are_plain_json(widget):
    for name in ("state", "figure", "last_drive"):
        json.dumps(getattr(widget, name), allow_nan=False)


def test_the_bundle_is_local():
    """plotly.js and the widget's own code in one ES module: no network address to load from."""
    from spatialmech.interfaces.studio.widget import esm_bundle

    esm = esm_bundle()
    assert "export default { render }" in esm and "plotly.js v" in esm[:2000]
    assert "cdn." not in esm.split("const Plotly = module.exports;")[1]


def test_results_have_an_html_table():
    fk = sm.fk("rssr", [10.0], degrees=True)
    html = fk._repr_html_()
    assert html.startswith("<div class='spatialmech-result'><b>fk: rssr</b>")
    assert "<th>status</th>" in html and "converged" in html and "ZYX" in html
    mob = sm.mobility("rssr")._repr_html_()
    assert "<th style='text-align:left'>dof</th><td style='text-align:left'>1</td>" in mob
    assert "5 x 6 matrix" in mob                    # constraint wrenches by their shape
    jac = sm.jacobian("rssr")._repr_html_()
    assert "6 x 6 matrix" in jac and "sigma_min" in jac
    ik = sm.ik("four-sps-cu", ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46)), degrees=True)._repr_html_()
    assert "<th>limb</th>" in ik and "leg1" in ik


def test_html_cell_escapes_and_shortens():
    from spatialmech.serialize import html_cell

    assert html_cell("<b>") == "&lt;b&gt;"
    assert html_cell(1.234567891) == "1.2346"
    assert html_cell("x" * 200).endswith("...") and len(html_cell("x" * 200)) == 120
    assert html_cell([[1, 2, 3], [4, 5, 6]]) == "2 x 3 matrix"


def test_snapshot_and_undo_messages():
    w = sm.studio("rssr")
    send(w, {"type": "drive", "actuators": [20.0]})
    send(w, {"type": "snapshot", "label": "twenty"})
    assert [x["label"] for x in w.snapshots] == ["twenty"]
    send(w, {"type": "drive", "actuators": [50.0]})
    send(w, {"type": "undo"})
    assert w.error == "" and w.snapshots == [] and abs(w.state["actuators_deg"]["A0.rot"] - 20.0) < 1e-9
    assert w.last_drive == {"status": "undone", "message": "back at twenty"}
    send(w, {"type": "undo"})
    assert w.error.startswith("undo: no snapshot")


def test_pose_message_moves_the_output_link():
    w = sm.studio("rssr")
    a3 = w.state["task"]["values_deg"]["a3"]
    send(w, {"type": "pose", "task_deg": {"a3": a3 + 5.0}, "euler": w.state["task"]["euler"]})
    assert w.error == "" and w.last_drive["status"] == "reached"
    assert abs(w.state["task"]["values_deg"]["a3"] - (a3 + 5.0)) < 1e-6


def test_drag_pad_message_moves_the_output_point_as_the_page_does():
    """The pad's message runs ``Session.drag_output`` (the page's ``POST /api/drag``): the same
    configuration as a plain session's drag; a bad point or a mechanism that controls none of
    x, y, z answers in ``error`` with the field named."""
    w, s = sm.studio("planar-4r"), sm.studio_session("planar-4r")
    p = np.array(w.state["scene"]["platform_point_len"])
    target = [float(p[0]) + 0.05, float(p[1]) + 0.3, float(p[2])]
    n0 = w.answered
    send(w, {"type": "drag", "point_len": target})
    assert w.error == "" and w.last_drive["status"] == "reached" and w.answered == n0 + 1
    assert s.drag_output(target).status == "reached"
    assert np.allclose(w.session.config.q, s.config.q, atol=1e-12)
    q = platform_point(w.figure)  # planar-4r controls x only: the coupler point follows x
    assert q[0] == pytest.approx(p[0] + 0.05, abs=1e-9)
    assert np.allclose(q, w.state["scene"]["platform_point_len"], atol=1e-12)
    send(w, {"type": "drag", "point_len": [0.0, 1.0]})
    assert w.error.startswith("point_len: expected three finite numbers") and w.answered == n0 + 2
    r = sm.studio("rssr")
    send(r, {"type": "drag", "point_len": [0.0, 1.0, 0.0]})
    assert r.error.startswith("point_len: rssr does not control the output point's position")


def test_the_widget_labels_an_unstated_length_unit():
    """Paper A's linkages state no length unit: the widget's labels say "length unit not stated"
    (present.numbers.unit_label), as the reports do, never "[unit]" (issue 30 item 9)."""
    w = sm.studio("five-cs-3")
    assert w.unit == "length unit not stated"
    assert w.figure["layout"]["scene"]["xaxis"]["title"]["text"] == "x [length unit not stated]"


def test_the_widget_view_choice_is_checked(widget):
    """Issue 30: ``sm.studio(model, view=...)`` and the ``view`` trait take "auto" (default),
    "light" or "full"; anything else is an InputError naming the field; the bundle carries the
    light view (static/scene2d.js)."""
    from spatialmech.interfaces.studio.widget import esm_bundle

    assert widget.view == "auto"
    with pytest.raises(sm.InputError, match=r"^view: expected one of 'auto', 'light', 'full', got 'fast'"):
        sm.studio("no-such-model", view="fast")  # checked before the model is loaded
    with pytest.raises(sm.InputError, match=r"^view: "):
        widget.view = "bogus"
    assert widget.view == "auto"
    widget.view = "light"
    assert widget.view == "light"
    widget.view = "auto"
    assert "const SMScene2D" in esm_bundle() and esm_bundle().index("const SMScene2D") < esm_bundle().index("function render(")
