"""The studio page's layout, top view and drag handle in headless Chromium (one browser, the
fixtures of tests/conftest.py): on the 6-SPS Stewart platform the key readouts (DJ,
the sigma_min and transmission lights, the events) are above the fold and above the sliders;
planar-4r opens in its top view (orthographic, along the plane's normal) with a toggle; dragging
the handle of the output point moves the linkage by the pose drag; no console errors."""

import time

import pytest

from .browser_support import wait_for  # the fixtures server and browser: tests/conftest.py

pytestmark = pytest.mark.slow  # a browser start and software WebGL take seconds


def load(driver, model):
    driver.execute_script("const s = document.getElementById('model-select'); s.value = arguments[0];"
                          "s.dispatchEvent(new Event('change'));", model)
    wait_for(driver, "return window.studio.state.mechanism === arguments[0] && !window.studio.inFlight", model)
    time.sleep(0.3)


RECTS = """const r = id => document.getElementById(id).getBoundingClientRect();
return {fold: innerHeight, sigma: r('sigma').bottom, transmission: r('transmission').bottom,
        dj: document.getElementById('readouts').rows[0].getBoundingClientRect().bottom,
        events: r('events').top, sliders: r('sliders').top,
        pad: getComputedStyle(document.getElementById('drag-pad')).display};"""
CAMERA = ("const c = document.getElementById('plot')._fullLayout.scene.camera;"
          "return [c.eye.x, c.eye.y, c.eye.z, c.projection.type];")


def test_readouts_above_the_fold_top_view_and_drag_handle(server, browser):
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    b = browser
    b.set_window_size(1280, 800)
    b.get(server)
    wait_for(b, "return window.studio && window.studio.state && window.studio.drawn > 0")
    load(b, "stewart-6sps")
    r = b.execute_script(RECTS)
    assert max(r["sigma"], r["transmission"], r["dj"], r["events"]) < min(r["fold"], r["sliders"]), r
    assert r["pad"] != "none"  # x, y, z given: the handle drags in the x-y plane

    load(b, "planar-4r")
    assert b.execute_script("return window.studio.topView") is True
    eye = b.execute_script(CAMERA)
    assert eye[:3] == pytest.approx([0.0, 0.0, 2.0], abs=1e-9) and eye[3] == "orthographic"
    toggle = b.find_element(By.ID, "view-toggle")
    assert toggle.is_displayed() and toggle.text == "3-D view"
    toggle.click()
    eye3 = b.execute_script(CAMERA)
    assert b.execute_script("return window.studio.topView") is False and abs(eye3[0]) > 0.1 and eye3[3] == "perspective"
    toggle.click()
    assert b.execute_script(CAMERA)[:3] == pytest.approx([0.0, 0.0, 2.0], abs=1e-9)

    x0 = b.execute_script("return window.studio.state.task.values_len.x")
    handle = b.find_element(By.ID, "drag-handle")
    ActionChains(b).click_and_hold(handle).move_by_offset(3, 0).move_by_offset(3, 0).release().perform()
    wait_for(b, "return !window.studio.inFlight && window.studio.pending === null && window.studio.lastDragPoint")
    time.sleep(0.3)
    wait_for(b, "return !window.studio.inFlight && window.studio.pending === null")
    st = b.execute_script("return window.studio.state")
    want = b.execute_script("return window.studio.lastDragPoint")[0]
    assert want > x0 + 0.05  # 6 px to the right on the pad: +x on planar-4r's top view
    assert st["task"]["values_len"]["x"] == pytest.approx(want, abs=1e-9)  # the pose drag reached it
    assert "reached" in b.find_element(By.ID, "status").text
    # paper A's linkages state no length unit: the labels say so, not "[unit]" (issue 30 item 9)
    load(b, "five-cs-3")
    title = b.execute_script("return document.getElementById('plot')._fullLayout.scene.xaxis.title.text")
    assert title == "x [length unit not stated]"
    assert "[unit]" not in b.find_element(By.ID, "readouts").text
    severe = [e for e in b.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe and b.execute_script("return window.studio.errors") == []
