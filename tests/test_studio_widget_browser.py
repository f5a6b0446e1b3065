"""The notebook widget's frontend (``sm.studio``: static/widget.js appended to plotly.js) in
headless Chromium, without Jupyter: a static page imports the widget's ES module and renders it
on a small stand-in for the anywidget model (``get``, ``on``, ``send``) that holds the traits of
a real :class:`~spatialmech.interfaces.studio.widget.StudioWidget`.  A slider moved in the page
sends a drive message; the test hands it to the Python widget (as the Jupyter kernel would) and
pushes the new traits back: the readouts and the 3-D view follow, and the console has no errors.

Skipped without Chromium, chromedriver or selenium (failed instead when ``CI`` is set), as
tests/test_studio_browser.py.  ``SPATIALMECH_SCREENSHOTS=DIR`` keeps a screenshot in DIR.
"""

import functools
import http.server
import json
import os
import threading
import time
from pathlib import Path

import pytest

import spatialmech as sm

from .browser_support import assert_no_page_errors

pytestmark = pytest.mark.slow  # a browser start and software WebGL take seconds
pytest.importorskip("anywidget")

TRAITS = ("state", "figure", "unit", "last_drive", "answered", "error", "modes", "snapshots", "view")

HARNESS = """<!DOCTYPE html><html><head><meta charset="utf-8"><title>widget harness</title><link rel="icon" href="data:,"></head>
<body style="width: 900px"><div id="w"></div>
<script type="module">
const values = await (await fetch("traits.json")).json(), listeners = {};
window.sent = []; window.jsErrors = [];
window.addEventListener("error", e => window.jsErrors.push(String(e.message)));
const model = { get: k => values[k], send: m => window.sent.push(m),
  on: (ev, f) => { (listeners[ev] = listeners[ev] || []).push(f); } };
window.harness = { set(patch) { Object.assign(values, patch);
  Object.keys(patch).forEach(k => (listeners["change:" + k] || []).forEach(f => f())); } };
const widget = (await import("./bundle.js")).default;
widget.render({ model, el: document.getElementById("w") });
window.rendered = true;
</script></body></html>"""


class Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:  # no access log on stderr
        pass


def traits(w) -> dict:
    return {k: getattr(w, k) for k in TRAITS}


def serve(tmp_path_factory, model, view="full"):
    """A harness page of a new widget of ``model`` (plotly's 3-D view unless ``view`` says
    otherwise): ``(widget, url, server, thread)``."""
    from spatialmech.interfaces.studio.widget import esm_bundle

    w = sm.studio(model, view=view)
    root = tmp_path_factory.mktemp("widget-harness")
    (root / "index.html").write_text(HARNESS, encoding="utf-8")
    (root / "bundle.js").write_text(esm_bundle(), encoding="utf-8")
    (root / "traits.json").write_text(json.dumps(traits(w)), encoding="utf-8")
    handler = functools.partial(Quiet, directory=str(root))
    srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    th = threading.Thread(target=srv.serve_forever, daemon=True)
    th.start()
    return w, f"http://127.0.0.1:{srv.server_address[1]}/index.html", srv, th


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    w, url, srv, th = serve(tmp_path_factory, "rssr")
    yield w, url
    srv.shutdown()
    th.join(10)


def wait_for(driver, script, timeout=60.0):
    t0 = time.time()
    while time.time() - t0 < timeout:
        v = driver.execute_script(script)
        if v:
            return v
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for: {script}")


def test_the_widget_renders_and_a_slider_drives_the_session(page, browser):
    w, url = page
    browser.get(url)
    wait_for(browser, "return window.rendered === true && document.querySelector('.js-plotly-plot') !== null")
    n_traces = browser.execute_script("return document.querySelector('.sm-plot').data.length")
    assert n_traces == len(w.figure["data"])
    assert browser.execute_script("return document.querySelectorAll('.sm-sliders input').length") == 1
    assert browser.execute_script("return document.querySelectorAll('.sm-pose input').length") == 1  # a3
    # the user moves the slider: the page sends one drive message
    browser.execute_script("const el = document.querySelector('.sm-sliders input'); el.value = 35;"
                           "el.dispatchEvent(new Event('input'));")
    msg = wait_for(browser, "return window.sent.length ? window.sent[0] : null")
    assert msg == {"type": "drive", "actuators": [35.0]}
    # the kernel runs it on the session and the new traits reach the page
    w._handle_custom_msg(msg, [])
    assert w.last_drive["status"] == "reached"
    browser.execute_script("window.harness.set(arguments[0])", traits(w))
    x0 = w.figure["data"][1]["x"]
    wait_for(browser, "return document.querySelector('.sm-plot').data[1].x[0] === arguments[0]".replace(
        "arguments[0]", repr(x0[0])))
    text = browser.execute_script("return document.querySelector('.sm-readouts').textContent")
    assert "reached" in text and "sigma_min" in text
    # the snapshot button sends its message once the drive has been answered
    browser.execute_script("document.querySelector('.sm-snap').click()")
    snap = wait_for(browser, "return window.sent.length > 1 ? window.sent[1] : null")
    assert snap == {"type": "snapshot"}
    w._handle_custom_msg(snap, [])
    browser.execute_script("window.harness.set(arguments[0])", traits(w))
    wait_for(browser, "return document.querySelector('.sm-snaps').textContent === 'snapshot 1'")
    assert_no_page_errors(browser)
    out = os.environ.get("SPATIALMECH_SCREENSHOTS")
    if out:
        browser.set_window_size(1000, 900)
        assert browser.find_element("css selector", "#w").screenshot(str(Path(out) / "studio-widget-rssr.png"))


def test_the_widget_drag_pad_moves_the_output_point(tmp_path_factory, browser):
    """Issue 30: the notebook widget has the page's drag pad (static/pad.js, shared): a real mouse
    drag of the handle on planar-4r (its top view; it controls x) sends one drag message with the
    point under the mouse, which the session reaches by the pose drag (``Session.drag_output``)."""
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    w, url, srv, th = serve(tmp_path_factory, "planar-4r")
    try:
        browser.get(url)
        wait_for(browser, "return window.rendered === true && document.querySelector('.js-plotly-plot') !== null")
        assert browser.execute_script("return getComputedStyle(document.querySelector('.sm-pad')).display") != "none"
        label = browser.execute_script("return document.querySelector('.sm-pad-label').textContent")
        assert label == "drag the output point (x), the linkage's plane"
        x0 = w.state["task"]["values_len"]["x"]
        cx_of = "return Number(document.querySelector('.sm-drag-svg .drag-handle').getAttribute('cx'))"
        cx0 = browser.execute_script(cx_of)
        handle = browser.find_element(By.CSS_SELECTOR, ".sm-drag-svg .drag-handle")
        ActionChains(browser).click_and_hold(handle).move_by_offset(3, 0).move_by_offset(3, 0).release().perform()
        # the kernel answers each message; the page sends the newest pad point once answered
        k, msg = 0, None
        while True:
            try:
                nxt = wait_for(browser, f"return window.sent.length > {k} ? window.sent[{k}] : null", timeout=2.0)
            except AssertionError:
                break
            msg, k = nxt, k + 1
            assert msg["type"] == "drag" and len(msg["point_len"]) == 3
            w._handle_custom_msg(msg, [])
            assert w.error == "" and w.last_drive["status"] == "reached", (w.error, w.last_drive)
            browser.execute_script("window.harness.set(arguments[0])", traits(w))
        assert msg is not None
        want = msg["point_len"][0]
        assert want > x0 + 0.05  # 6 px to the right on planar-4r's top view: +x
        assert w.state["task"]["values_len"]["x"] == pytest.approx(want, abs=1e-9)  # the pose drag reached it
        assert browser.execute_script(cx_of) > cx0 + 3.0  # the handle redrawn where it was dragged
        # a bad message names the field
        w._handle_custom_msg({"type": "drag", "point_len": [0.0, "a"]}, [])
        assert w.error.startswith("point_len: ")
        assert_no_page_errors(browser)
    finally:
        srv.shutdown()
        th.join(10)


def test_the_widget_light_view_draws_follows_and_switches(tmp_path_factory, browser):
    """Issue 30: with ``view="auto"`` under headless Chromium (software WebGL) the widget draws
    its figure on planar-4r in the light 3-D view (static/scene2d.js), in the top view: the joint
    markers where its camera projects the session's joints, redrawn when the kernel answers a
    drive; its buttons switch to plotly's scene and back."""
    import numpy as np

    from .browser_support import projected

    w, url, srv, th = serve(tmp_path_factory, "planar-4r", view="auto")
    light = "document.querySelector('.sm-light').smView"
    drawn = (f"const L = {light}; return L.frames > 0 && !L.requested ? "
             "{cam: L.camera(), joints: L.screen['joints'], handle: L.handleAt, frames: L.frames} : null")
    try:
        browser.get(url)
        wait_for(browser, "return window.rendered === true")
        v = wait_for(browser, drawn)
        assert browser.execute_script("return getComputedStyle(document.querySelector('.sm-plot')).display") == "none"
        why = browser.execute_script("return document.querySelector('.sm-view-why').textContent")
        assert why == "light 3-D view: this browser renders WebGL in software (SwiftShader)"
        want = projected(v["cam"], [j["centre_len"] for j in w.state["scene"]["joints"]])
        assert np.allclose(np.asarray(v["joints"])[:, :2], want, rtol=0, atol=1e-9)
        w.drive([35.0])
        browser.execute_script("window.harness.set(arguments[0])", traits(w))
        v2 = wait_for(browser, drawn.replace("L.frames > 0", f"L.frames > {v['frames']}"))
        want2 = projected(v2["cam"], [j["centre_len"] for j in w.state["scene"]["joints"]])
        assert np.allclose(np.asarray(v2["joints"])[:, :2], want2, rtol=0, atol=1e-9)
        assert np.hypot(*np.subtract(v2["handle"], v["handle"])) > 3.0
        assert v2["cam"]["fwd"] == pytest.approx([0.0, 0.0, -1.0], abs=1e-12)  # looking along the plane's normal
        out = os.environ.get("SPATIALMECH_SCREENSHOTS")
        if out:
            browser.set_window_size(1000, 1400)
            time.sleep(0.3)
            assert browser.find_element("css selector", "#w").screenshot(str(Path(out) / "studio-widget-planar-4r.png"))
            browser.set_window_size(1200, 800)
        browser.execute_script("document.querySelector('.sm-view-full').click()")
        wait_for(browser, "return document.querySelector('.js-plotly-plot') !== null && "
                          "getComputedStyle(document.querySelector('.sm-light')).display === 'none'")
        browser.execute_script("document.querySelector('.sm-view-light').click()")
        wait_for(browser, drawn.replace("L.frames > 0", f"L.frames > {v2['frames']}"))
        assert_no_page_errors(browser)
    finally:
        srv.shutdown()
        th.join(10)
