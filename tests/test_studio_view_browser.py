"""The studio page's layout, top view and drag handle in headless Chromium (one browser, the
fixtures of tests/conftest.py): on the 6-SPS Stewart platform the key readouts (DJ,
the sigma_min and transmission lights, the events) are above the fold and above the sliders;
planar-4r opens in its top view (orthographic, along the plane's normal) with a toggle; dragging
the handle of the output point moves the linkage by the pose drag; no console errors.

The light 3-D view (static/scene2d.js, issue 30): headless Chromium renders WebGL in software
(SwiftShader), so the page chooses it by itself; it draws the session's joints where its camera
projects them, follows a drag, turns and resets, drags the output point by its handle, and its
buttons switch to plotly's scene and back.  ``SPATIALMECH_SCREENSHOTS=DIR`` keeps a screenshot."""

import os
import time
from pathlib import Path

import numpy as np
import pytest

import spatialmech as sm

from .browser_support import projected, wait_for  # the fixtures server and browser: tests/conftest.py

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
    b.get(server + "?view=full")  # plotly's scene: its camera is read below
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
    assert toggle.is_displayed() and toggle.text == "oblique view"
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


LIGHT = """const L = window.studio.light;
return {cam: L.camera(), joints: L.screen['joint centres'], handle: L.handleAt, frames: L.frames, busy: L.requested,
        view: window.studio.view, why: window.studio.viewWhy, renderer: window.studio.renderer};"""


def settled(driver) -> dict:
    """The light view's camera and drawn markers once the page is idle and the frame drawn."""
    wait_for(driver, "return !window.studio.inFlight && window.studio.pending === null")
    time.sleep(0.1)
    return wait_for(driver, "const v = (() => {" + LIGHT + "})(); return v.busy ? null : v;")


def test_the_light_view_draws_follows_a_drag_and_switches(server, browser, tmp_path):
    from matplotlib import image
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    b = browser
    b.set_window_size(1200, 800)
    b.get(server)  # view "auto": headless Chromium's WebGL is SwiftShader, a software renderer
    wait_for(b, "return window.studio && window.studio.state && window.studio.drawn > 0")
    load(b, "planar-4r")  # a fresh session: the module's server is shared
    v = settled(b)
    assert v["view"] == "light" and "swiftshader" in v["renderer"].lower(), v
    assert v["why"] == "light 3-D view: this browser renders WebGL in software (SwiftShader)"
    assert b.find_element(By.ID, "view3d-why").text == v["why"]
    assert not b.find_element(By.ID, "plot").is_displayed() and b.find_element(By.ID, "light").is_displayed()
    # the joints are drawn where the camera projects the session's joint points
    ref = sm.studio_session("planar-4r")
    want = projected(v["cam"], [j["centre_len"] for j in ref.state()["scene"]["joints"]])
    assert np.allclose(np.asarray(v["joints"])[:, :2], want, rtol=0, atol=1e-9)
    path = tmp_path / "light.png"
    assert b.find_element(By.ID, "light").screenshot(str(path))
    img = image.imread(path)[..., :3]
    for u, w in np.rint(want).astype(int):  # a marker (not the white background) at every joint
        patch = img[w - 1:w + 2, u - 1:u + 2]
        assert float(np.min(patch)) < 0.8, (u, w)
    # a slider drag: the joints and the handle follow, as the library computes them
    b.execute_script("const el = document.getElementById('slider-0'); el.value = Number(el.value) + 30;"
                     "el.dispatchEvent(new Event('input'));")
    wait_for(b, "return Math.abs(window.studio.state.actuators_deg['A0.rot'] - 30) < 1e-6")
    v2 = settled(b)
    assert v2["frames"] > v["frames"] and np.hypot(*np.subtract(v2["handle"], v["handle"])) > 3.0
    assert ref.drive([30.0]).status == "reached"
    want2 = projected(v2["cam"], [j["centre_len"] for j in ref.state()["scene"]["joints"]])
    assert np.allclose(np.asarray(v2["joints"])[:, :2], want2, rtol=0, atol=1e-9)
    assert v2["cam"]["fwd"] == pytest.approx([0.0, 0.0, -1.0], abs=1e-12)  # planar: along the plane's normal
    # the mouse turns the camera (away from the handle) and a double-click resets it
    front = b.find_element(By.CSS_SELECTOR, "#light canvas:last-child")
    w, h = v2["cam"]["width"], v2["cam"]["height"]
    ActionChains(b).move_to_element_with_offset(front, int(-w / 2 + 60), int(-h / 2 + 80)).click_and_hold() \
        .move_by_offset(40, 0).move_by_offset(0, 20).release().perform()
    turned = settled(b)["cam"]
    assert abs(float(np.dot(turned["right"], v2["cam"]["right"]))) < 0.99
    ActionChains(b).move_to_element_with_offset(front, int(-w / 2 + 60), int(-h / 2 + 80)).double_click().perform()
    assert np.allclose(settled(b)["cam"]["right"], v2["cam"]["right"], atol=1e-12)
    # the orange handle in the 3-D view drags the output point (planar-4r gives x; top view: +x is to the right)
    x0 = b.execute_script("return window.studio.state.task.values_len.x")
    hx, hy = v2["handle"]
    ActionChains(b).move_to_element_with_offset(front, round(hx - w / 2), round(hy - h / 2)).click_and_hold() \
        .move_by_offset(6, 0).move_by_offset(6, 0).release().perform()
    wait_for(b, "return window.studio.lastDragPoint && !window.studio.inFlight && window.studio.pending === null")
    time.sleep(0.3)
    settled(b)
    st = b.execute_script("return window.studio.state")
    want_x = b.execute_script("return window.studio.lastDragPoint")[0]
    assert want_x > x0 + 0.02  # 12 px to the right in the top view: +x
    assert st["task"]["values_len"]["x"] == pytest.approx(want_x, abs=1e-9)  # the pose drag reached it
    out = os.environ.get("SPATIALMECH_SCREENSHOTS")
    if out:
        b.save_screenshot(str(Path(out) / "studio-light-planar-4r.png"))
    # the buttons: plotly's scene and back
    assert b.execute_script("return window.studio.state.scene.joint_meshes") == []  # asked for with ?solids=0
    b.find_element(By.ID, "view3d-full").click()
    wait_for(b, "const p = document.getElementById('plot'); return window.studio.view === 'full' && p.data && "
                "p.offsetWidth > 0 && getComputedStyle(document.getElementById('light')).display === 'none'")
    wait_for(b, "return document.getElementById('plot').data.some(t => t.name.startsWith('joints of'))")  # the solids
    n = b.execute_script("return window.studio.light.frames")
    b.find_element(By.ID, "view3d-light").click()
    wait_for(b, "return window.studio.view === 'light' && window.studio.light.frames > arguments[0]", n)
    assert b.find_element(By.ID, "view3d-why").text == "light 3-D view: switched by hand"
    assert b.find_element(By.ID, "view3d-light").get_attribute("aria-pressed") == "true"
    severe = [e for e in b.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe and b.execute_script("return window.studio.errors") == []
