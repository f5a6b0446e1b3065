"""The studio page in headless Chromium (Debian's chromium and chromedriver, pip selenium, as
tests/test_viewer_browser.py): the app served by uvicorn on 127.0.0.1 in a thread, the page
loaded, a slider dragged; the mechanism moved (the state the page holds, and the plot's
pixels), the readouts changed, and the console has no errors.

Skipped when Chromium, chromedriver or selenium is missing -- except when ``CI`` is set, where
the test fails instead.
"""

import time

import numpy as np
import pytest

import spatialmech as sm

from .browser_support import TIMEOUT

pytestmark = pytest.mark.slow  # a browser start and software WebGL take seconds

def wait(driver, script, timeout=TIMEOUT):
    t0 = time.time()
    while time.time() - t0 < timeout:
        v = driver.execute_script(script)
        if v:
            return v
        time.sleep(0.2)
    raise AssertionError(f"timed out waiting for: {script}")


def pixels(driver, tmp_path, name):
    from matplotlib import image
    from selenium.webdriver.common.by import By

    path = tmp_path / name
    assert driver.find_element(By.ID, "plot").screenshot(str(path))
    return image.imread(path)[..., :3]


def test_dragging_a_slider_moves_the_mechanism(server, browser, tmp_path):
    from selenium.webdriver.common.by import By

    browser.get(server + "?view=full")  # plotly's WebGL scene (the light view: tests/test_studio_view_browser.py)
    wait(browser, "return window.studio && window.studio.drawn > 0")
    time.sleep(0.5)  # let WebGL finish the first frame
    before = browser.execute_script("return window.studio.state")
    readout = browser.find_element(By.ID, "readouts").text
    img0 = pixels(browser, tmp_path, "before.png")
    browser.execute_script("const el = document.getElementById('slider-0'); el.value = Number(el.value) + 40;"
                           "el.dispatchEvent(new Event('input'));")
    wait(browser, "return window.studio.state.actuators_deg['A0.rot'] > 39.9 && !window.studio.inFlight")
    time.sleep(0.5)
    after = browser.execute_script("return window.studio.state")
    assert after["actuators_deg"]["A0.rot"] == pytest.approx(40.0, abs=1e-6)
    moved = np.linalg.norm(np.subtract(after["scene"]["platform_point_len"], before["scene"]["platform_point_len"]))
    assert moved > 0.1 * after["scene"]["scale_len"]
    # what the page holds is what the library computes at 40 deg along the branch
    ref = sm.studio_session("rssr")
    assert ref.drive([40.0]).status == "reached"
    assert np.allclose(after["scene"]["platform_point_len"], ref.state()["scene"]["platform_point_len"], atol=1e-9)
    assert browser.find_element(By.ID, "readouts").text != readout
    # the inverse (transmission) light beside the direct one, coloured by the state's verdict
    light = browser.find_element(By.ID, "transmission")
    want = "sing" if after["inverse_singular"] else "near" if after["near_inverse_singular"] else "ok"
    assert light.get_attribute("class") == want and float(light.text) == pytest.approx(after["transmission_min"], rel=1e-3)
    assert "transmission (inverse)" in browser.find_element(By.ID, "readouts").text
    assert "reached" in browser.find_element(By.ID, "status").text
    img1 = pixels(browser, tmp_path, "after.png")
    assert img0.shape == img1.shape and float(np.mean(np.any(np.abs(img0 - img1) > 0.05, axis=-1))) > 0.002
    severe = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe and browser.execute_script("return window.studio.errors") == []
    # the output pose slider (the rocker angle a3, inverse position along the branch) moves it back
    a3 = after["task"]["values_deg"]["a3"]
    assert browser.execute_script("return document.querySelectorAll('#pose-sliders input').length") == 1
    target = browser.execute_script("const el = document.getElementById('pose-0'); el.value = Number(el.value) - 5;"
                                    "el.dispatchEvent(new Event('input')); return Number(el.value);")  # on the slider's step
    assert target == pytest.approx(a3 - 5, abs=0.1)
    wait(browser, f"return Math.abs(window.studio.state.task.values_deg.a3 - {target}) < 1e-6 && !window.studio.inFlight")
    posed = browser.execute_script("return window.studio.state")
    assert posed["actuators_deg"]["A0.rot"] != pytest.approx(40.0, abs=1e-3)  # the crank followed
    assert "reached" in browser.find_element(By.ID, "status").text
    severe = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe and browser.execute_script("return window.studio.errors") == []
