"""Readability (issue 30 item 9): round-off prints as 0 (one helper, present/numbers.py), no
"[unit]" placeholders in text headers."""

from __future__ import annotations

import re

from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st

from spatialmech.interfaces.cli import cli
from spatialmech.present.numbers import ROUNDOFF, fmt_number, fmt_numbers


def test_roundoff_is_zero_and_real_values_keep_their_digits():
    assert fmt_number(-5.0e-16, "+.5e") == " 0.00000e+00"
    assert fmt_number(-0.0, ".4g") == "0"
    assert fmt_number(-5.0e-16, ".4g", scale=1e-15) == "-5e-16"  # not round-off at that scale
    assert fmt_number(0.12, "+.5e") == "+1.20000e-01"
    assert fmt_numbers([1.0, -3e-17, 2.0]) == "1 0 2"
    assert fmt_numbers([float("nan"), 1.0]) == "nan 1"


@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False), st.floats(min_value=1e-6, max_value=1e6))
def test_only_roundoff_becomes_zero(x, scale):
    text = fmt_number(x, ".6e", scale=scale)
    if abs(x) > ROUNDOFF * scale:
        assert float(text) == float(format(x, ".6e"))
    else:
        assert float(text) == 0.0 and not text.startswith("-")


def test_jacobian_text_prints_no_roundoff_and_no_unit_placeholder():
    out = CliRunner().invoke(cli, ["jacobian", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "0", "0", "0"],
                             catch_exceptions=False).output
    rows = [ln for ln in out.splitlines() if ln.strip().startswith("[") or "slide [m]" in ln]
    assert rows and not any(re.search(r"e-1[5-9]", ln) for ln in rows)
    assert "-0.00000e+00" not in out and "[unit]" not in out



def test_parasitic_text_prints_roundoff_ranges_as_zero():
    """three-rps over a2 keeps x and a3 at 0 up to round-off (2e-17 m, 1e-15 deg printed before)."""
    out = CliRunner().invoke(cli, ["parasitic", "three-rps", "--over", "a2:-20:20:5", "--euler", "xyz"],
                             catch_exceptions=False).output
    assert "  x: 0 .. 0 m" in out and "  a3: 0 .. 0 deg" in out and not re.search(r"e-1[5-9]", out)
    assert re.search(r"  y: 0 \.\. 0\.00452\d* m", out)  # a real range keeps its digits


def _rocker_driven_4r():
    import spatialmech as sm
    from spatialmech.catalog import build

    m0, z = build("planar-4r"), [0, 0, 1.0]
    (a0, a1), (b0, b1) = (j.point for j in m0.limbs[0].joints), (j.point for j in m0.limbs[1].joints)
    return sm.Mechanism("rocker-driven-4r", limbs=[
        sm.Limb("crank", [sm.R("A0", a0, z), sm.R("A1", a1, z)]),
        sm.Limb("rocker", [sm.R("B0", b0, z, actuated=True), sm.R("B1", b1, z)])], platform_point=m0.platform_point)


def test_four_bar_class_reference_values():
    import numpy as np

    from spatialmech.analysis.four_bar import four_bar_class
    from spatialmech.catalog import build

    cr = four_bar_class(build("planar-4r"))  # ground 4, crank 1, coupler 3.5, rocker 3
    assert cr is not None and cr.kind.startswith("Grashof crank-rocker") and cr.input_range_deg == (0.0, 360.0)
    # d in [3, 5]: mu = acos((3^2 + 3.5^2 - d^2) / (2 3 3.5)), to 1e-9 deg
    mu = np.degrees(np.arccos([(9 + 12.25 - 9) / 21, (9 + 12.25 - 25) / 21]))
    assert np.allclose(cr.transmission_range_deg, mu, atol=1e-9)
    rk = four_bar_class(_rocker_driven_4r())
    assert rk is not None and rk.kind.startswith("Grashof rocker-crank")
    # the rocker (3) swings while the rocker-to-crank-pivot distance stays in [2.5, 4.5]
    lo = np.degrees(np.arccos((9 + 16 - 2.5**2) / 24))
    hi = np.degrees(np.arccos((9 + 16 - 4.5**2) / 24))
    assert np.allclose(rk.input_range_deg, (lo, hi), atol=1e-9) and np.allclose(rk.transmission_range_deg, (0, 180))
    assert four_bar_class(build("bennett")) is None


def test_report_counts_the_dead_points_of_a_rocker_driven_four_bar():
    from spatialmech.present.models import model_section

    sec = model_section(_rocker_driven_4r())
    zeros = [e for e in sec.data["trace"]["events"] if e["kind"] == "zero"]
    assert len(zeros) == 2 and "red: 2 zeros" in " ".join(f.caption for f in sec.figures)
    assert sec.data["four_bar"]["kind"].startswith("Grashof rocker-crank")
    assert any(t.title == "Linkage class (planar four-bar)" for t in sec.tables)


def test_studio_axis_titles_use_title_text_and_roundoff_prints_zero():
    from fastapi.testclient import TestClient

    import spatialmech as sm

    js = TestClient(sm.studio_app("planar-4r")).get("/static/studio.js").text
    # the bundled plotly ignores a bare string axis title: the units would vanish
    assert 'title: { text: n + " [" + S.unit + "]" }' in js and "title: { text: S.state.mechanism" in js
    assert 'Math.abs(Number(x)) < 1e-13 ? "0"' in js


def test_legends_do_not_say_limb_twice():
    from spatialmech.present.viewer import limb_label

    assert limb_label("limb1") == "limb1" and limb_label("Limb_a") == "Limb_a" and limb_label("leg1") == "limb leg1"
