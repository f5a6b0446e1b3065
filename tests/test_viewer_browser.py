"""The viewer page in a real browser: headless Chromium driven by Selenium through Debian's
``chromedriver`` (``apt-get install chromium chromium-driver``; pip ``selenium``; both installed
by ``.ci/run``).  No browser download, no network: the page is opened from a ``file://`` URL.

Skipped when Chromium, chromedriver or selenium is missing -- except when the environment
variable ``CI`` is set, where the test FAILS instead (CI must run it).
"""

import os
import shutil

import numpy as np
import pytest

from spatialmech import catalog
from spatialmech.kinematics.motion import sample_motion
from spatialmech.present.viewer import DIV_ID, viewer_figure, write_viewer

# The Chromium fixture (``browser``, one per test file) is tests/conftest.py's; the waits use its timeout.
from .browser_support import TIMEOUT

#: A browser start and WebGL rendering take tens of seconds: not part of the quick loop.
pytestmark = pytest.mark.slow

FRAMES = 16


_READ = f"""
const gd = document.getElementById('{DIV_ID}');
// plotly writes NumPy arrays as base64 typed arrays ({{dtype, bdata}}; the joint solids' float32 vertices)
const types = {{f4: Float32Array, f8: Float64Array, i4: Int32Array, u4: Uint32Array, i2: Int16Array, u2: Uint16Array,
               i1: Int8Array, u1: Uint8Array}};
function values(v) {{
  if (!v) return [];
  if (v.bdata !== undefined) {{
    const raw = atob(v.bdata), bytes = new Uint8Array(raw.length);
    for (let n = 0; n < raw.length; n++) bytes[n] = raw.charCodeAt(n);
    return Array.from(new types[v.dtype](bytes.buffer));
  }}
  return Array.from(v);
}}
return {{active: gd.layout.sliders[0].active,
        traces: arguments[0].map(i => ['x', 'y', 'z'].map(a => values(gd.data[i][a])))}};
"""


def _read(driver, fig):
    """The slider position and the coordinates of the animated traces as drawn (``null``
    gaps kept), read from the graph div's public ``data`` / ``layout``."""
    return driver.execute_script(_READ, list(fig.frames[0].traces))


def _flat(traces):
    return np.array([np.nan if v is None else v for t in traces for axis in t for v in axis], float)


def _expected(fig, k):
    """Frame ``k`` of the figure built in Python, flattened like :func:`_flat`."""
    return _flat([[list(t[a]) for a in "xyz"] for t in fig.frames[k].data])


def _same(a, b, tol=1e-9):
    return a.shape == b.shape and np.array_equal(np.isnan(a), np.isnan(b)) and np.allclose(
        a[~np.isnan(a)], b[~np.isnan(b)], atol=tol)


def _canvas_pixels(canvas, path):
    from matplotlib import image

    assert canvas.screenshot(str(path))
    return image.imread(path)[..., :3]


def test_console_errors_are_seen(browser, tmp_path):
    """The console check below can fail: an uncaught error in a page shows as SEVERE."""
    browser.set_window_size(1200, 900)
    page = tmp_path / "broken.html"
    page.write_text("<html><body><script>throw new Error('deliberate');</script></body></html>")
    browser.get_log("browser")
    browser.get(page.as_uri())
    assert any(e["level"] == "SEVERE" and "deliberate" in e["message"] for e in browser.get_log("browser"))


# One model: the page is the same code for every model (the figures of each are tested without a
# browser in tests/test_viewer.py); four-sps-cu has joint solids, limits and a platform body.
@pytest.mark.parametrize("name", ["four-sps-cu"])
def test_viewer_page_in_headless_chromium(browser, tmp_path, name):
    browser.set_window_size(1200, 900)  # the page's layout as tested before the fixture was shared
    from matplotlib import image
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    mech = catalog.build(name)
    configs = sample_motion(mech, n=FRAMES)
    page = tmp_path / f"{name}.html"
    write_viewer(page, mech, configs, task_positions=mech.positions)
    fig = viewer_figure(mech, configs, task_positions=mech.positions)
    browser.get_log("browser")  # start with an empty log
    browser.get(page.as_uri())

    ready = f"const gd = document.getElementById('{DIV_ID}'); return !!(gd && gd._fullLayout && " \
            "gd._fullLayout.sliders && gd.querySelector('.slider-grip-rect') && gd.querySelector('canvas'));"
    WebDriverWait(browser, TIMEOUT).until(lambda d: d.execute_script(ready))
    before = _read(browser, fig)
    assert before["active"] == 0
    canvas = browser.find_element(By.CSS_SELECTOR, f"#{DIV_ID} canvas")
    pixels_before = _canvas_pixels(canvas, tmp_path / "before.png")
    assert _same(_flat(before["traces"]), _expected(fig, 0))

    # drag the slider's grip with the mouse to about a quarter of the rail: the extreme of the loop
    grip = browser.find_element(By.CSS_SELECTOR, f"#{DIV_ID} .slider-grip-rect")
    rail = browser.find_element(By.CSS_SELECTOR, f"#{DIV_ID} .slider-rail-rect")
    target = FRAMES // 4
    dx = rail.size["width"] * target / (FRAMES - 1)
    ActionChains(browser).click_and_hold(grip).move_by_offset(int(dx / 2), 0).move_by_offset(
        int(dx) - int(dx / 2), 0).release().perform()
    WebDriverWait(browser, TIMEOUT).until(lambda d: _read(d, fig)["active"] != 0)
    k = _read(browser, fig)["active"]
    assert abs(k - target) <= 1
    WebDriverWait(browser, TIMEOUT).until(lambda d: _same(_flat(_read(d, fig)["traces"]), _expected(fig, k)))
    moved = _flat(_read(browser, fig)["traces"])
    b0 = _flat(before["traces"])
    change = np.nanmax(np.abs(moved - b0))
    assert change > 0.01 * mech.characteristic_length, f"the drawn geometry did not change ({change:.3g})"
    # ... and the picture changed too (the WebGL scene was redrawn, not only the data)
    pixels_after = _canvas_pixels(canvas, tmp_path / "after.png")
    redrawn = np.mean(np.any(np.abs(pixels_after - pixels_before) > 0.1, axis=-1))
    assert redrawn > 0.001, f"the canvas did not change after moving the slider ({redrawn:.2%} of pixels)"

    # the Play button animates from the current frame to the last one
    play = [e for e in browser.find_elements(By.CSS_SELECTOR, f"#{DIV_ID} .updatemenu-button") if e.text == "Play"]
    assert len(play) == 1
    play[0].click()
    WebDriverWait(browser, TIMEOUT).until(lambda d: _read(d, fig)["active"] == FRAMES - 1)
    WebDriverWait(browser, TIMEOUT).until(
        lambda d: _same(_flat(_read(d, fig)["traces"]), _expected(fig, FRAMES - 1)))

    # offline: nothing but the page itself was loaded
    resources = browser.execute_script("return performance.getEntriesByType('resource').map(e => e.name);")
    assert all(r.startswith("file:") or r.startswith("data:") for r in resources), resources
    # no console errors (warnings of the software WebGL renderer are fine)
    errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert not errors, errors

    # a screenshot that is not blank, and a 3-D canvas that shows the limbs
    shot = tmp_path / f"{name}.png"
    assert browser.save_screenshot(str(shot))
    img = image.imread(shot)[..., :3]
    assert img.shape[0] > 500 and img.shape[1] > 800
    not_white = np.mean(np.any(img < 0.95, axis=-1))
    colours = len(np.unique((img * 255).astype(np.uint8).reshape(-1, 3), axis=0))
    assert not_white > 0.05 and colours > 50, (not_white, colours)
    cshot = tmp_path / f"{name}-canvas.png"
    cimg = _canvas_pixels(canvas, cshot)
    limb1 = np.array([0x1F, 0x77, 0xB4]) / 255  # the first limb's colour
    near = np.all(np.abs(cimg - limb1) < 0.12, axis=-1)
    assert near.sum() > 50, f"the first limb is not visible in the WebGL canvas ({near.sum()} pixels)"
    if os.environ.get("SPATIALMECH_SCREENSHOTS"):  # keep them for a human to look at
        for f in (shot, cshot):
            shutil.copy(f, os.environ["SPATIALMECH_SCREENSHOTS"])
