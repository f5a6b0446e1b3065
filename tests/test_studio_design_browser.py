"""The studio's design tools in headless Chromium (static/design.js over the page of
tests/test_studio_browser.py, the same server and browser fixtures: tests/conftest.py): snapshot, drag, undo; the
coupler curve of a typed point drawn in the 3-D view; the joints-and-transmission chart; the
smaller redraw used during the drag; no console errors.  ``SPATIALMECH_SCREENSHOTS=DIR`` keeps
a screenshot of the page in DIR."""

import os
from pathlib import Path

import pytest

from .browser_support import wait_for  # the fixtures server and browser: tests/conftest.py

pytestmark = pytest.mark.slow  # a browser start and software WebGL take seconds


def crank(driver) -> float:
    return driver.execute_script("return window.studio.state.actuators_deg['A0.rot']")


def test_snapshot_undo_coupler_curve_and_sweep_in_the_page(server, browser):
    b = browser
    b.get(server + "?view=full")  # the coupler curve is looked for in plotly's traces
    wait_for(b, "return window.studio && window.studio.state && window.studio.drawn > 0 && "
                "document.getElementById('snap') !== null")
    b.execute_script("window.studio.errors = []")
    start = crank(b)
    b.find_element("id", "snap").click()
    wait_for(b, "return document.querySelectorAll('#snapshots button').length === 1")
    b.execute_script("const el = document.getElementById('slider-0'); el.value = Number(el.value) + 30;"
                     "el.dispatchEvent(new Event('input'));")
    wait_for(b, "return Math.abs(window.studio.state.actuators_deg['A0.rot'] - arguments[0]) > 20", start)
    drawn = b.execute_script("return window.studio.drawn")
    assert drawn > 1
    b.find_element("id", "undo").click()
    wait_for(b, "return Math.abs(window.studio.state.actuators_deg['A0.rot'] - arguments[0]) < 1e-9", start)
    # the coupler curve of a point on the output link
    b.find_element("id", "coupler-point").send_keys("0.05, 0, 0.02")
    b.find_element("id", "coupler").click()
    wait_for(b, "return document.getElementById('plot').data.some(t => t.name.startsWith('coupler curve'))")
    # joint values and transmission against the input
    b.find_element("id", "sweep").click()
    n = wait_for(b, "const d = document.getElementById('sweep-plot').data; return d && d.length")
    assert n >= 3
    assert b.execute_script("return document.getElementById('export-path').getAttribute('href')") == "/api/path.csv"
    assert b.execute_script("return window.studio.errors") == []
    severe = [e for e in b.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe, severe
    out = os.environ.get("SPATIALMECH_SCREENSHOTS")
    if out:
        b.execute_script("document.getElementById('design').scrollIntoView()")
        b.save_screenshot(str(Path(out) / "studio-design-rssr.png"))
