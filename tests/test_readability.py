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
