"""The studio page in headless Chromium (Debian's chromium and chromedriver, pip selenium, as
tests/test_viewer_browser.py): the app served by uvicorn on 127.0.0.1 in a thread, the page
loaded, a slider dragged; the mechanism moved (the state the page holds, and the plot's
pixels), the readouts changed, and the console has no errors.

Skipped when Chromium, chromedriver or selenium is missing -- except when ``CI`` is set, where
the test fails instead.
"""

import os
import socket
import threading
import time

import numpy as np
import pytest

import spatialmech as sm

pytestmark = pytest.mark.slow  # a browser start and software WebGL take seconds

CHROMIUM = os.environ.get("SPATIALMECH_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("SPATIALMECH_CHROMEDRIVER", "/usr/bin/chromedriver")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
         "--no-first-run", "--enable-unsafe-swiftshader", "--window-size=1200,800", "--force-device-scale-factor=1")
TIMEOUT = 60


def missing() -> list[str]:
    out = []
    try:
        import selenium  # noqa: F401
    except ImportError:
        out.append("the pip package 'selenium'")
    out += [p for p in (CHROMIUM, CHROMEDRIVER) if not (os.path.isfile(p) and os.access(p, os.X_OK))]
    return out


@pytest.fixture(scope="module")
def server():
    import uvicorn

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    srv = uvicorn.Server(uvicorn.Config(sm.studio_app("rssr"), host="127.0.0.1", port=port, log_level="warning"))
    th = threading.Thread(target=srv.run, daemon=True)
    th.start()
    t0 = time.time()
    while not srv.started and time.time() - t0 < TIMEOUT:
        time.sleep(0.05)
    yield f"http://127.0.0.1:{port}/"
    srv.should_exit = True
    th.join(10)


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    gone = missing()
    if gone:
        msg = f"headless Chromium test needs {', '.join(gone)} (apt-get install chromium chromium-driver; pip install selenium)"
        if os.environ.get("CI"):
            pytest.fail(msg + " -- CI is set, so this must run", pytrace=False)
        pytest.skip(msg)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    os.environ["SE_OFFLINE"] = "true"  # never let Selenium Manager download anything
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for f in FLAGS:
        opts.add_argument(f)
    opts.add_argument(f"--user-data-dir={tmp_path_factory.mktemp('chromium-studio')}")
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=opts)
    driver.set_page_load_timeout(TIMEOUT)
    try:
        yield driver
    finally:
        driver.quit()


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

    browser.get(server)
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
