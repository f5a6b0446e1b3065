"""Helpers of the studio's headless-Chromium tests (the fixtures ``server`` and ``browser`` are
in tests/conftest.py): where Chromium and chromedriver are, their flags, what is missing, a
wait for a page script to turn true, and the light 3-D view's projection."""

import os
import time

import numpy as np

CHROMIUM = os.environ.get("SPATIALMECH_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("SPATIALMECH_CHROMEDRIVER", "/usr/bin/chromedriver")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
         "--no-first-run", "--enable-unsafe-swiftshader", "--window-size=1200,800", "--force-device-scale-factor=1")
TIMEOUT = 60


def missing() -> list[str]:
    """What the browser tests need and this machine lacks (empty: all there)."""
    out = []
    try:
        import selenium  # noqa: F401
    except ImportError:
        out.append("the pip package 'selenium'")
    out += [p for p in (CHROMIUM, CHROMEDRIVER) if not (os.path.isfile(p) and os.access(p, os.X_OK))]
    return out


def wait_for(driver, script, *args):
    """The first truthy value of ``script`` (run in the page with ``args``), polled every 0.1 s;
    an AssertionError after ``TIMEOUT`` seconds."""
    t0 = time.time()
    while time.time() - t0 < TIMEOUT:
        v = driver.execute_script(script, *args)
        if v:
            return v
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for: {script}")


def assert_no_page_errors(driver) -> None:
    """No JavaScript error caught by the page (``window.jsErrors``) and no SEVERE browser log."""
    assert driver.execute_script("return window.jsErrors") == []
    severe = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe, severe


def projected(cam: dict, pts) -> np.ndarray:
    """``pts`` (n, 3) where the light 3-D view's camera ``cam`` (``View.camera()`` of
    static/scene2d.js) draws them, in CSS pixels: ``(W/2 + zoom (p - c).right, H/2 - zoom (p - c).up)``."""
    c, r, u = (np.asarray(cam[k], float) for k in ("centre", "right", "up"))
    d = np.asarray(pts, float) - c
    return np.c_[cam["width"] / 2 + cam["zoom"] * (d @ r), cam["height"] / 2 - cam["zoom"] * (d @ u)]
