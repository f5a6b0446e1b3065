"""A dead point that falls exactly on a driven sample is counted once, whatever sign the
round-off gives the rate there (issue 30; the kernels themselves: tests/test_blas_independence.py)."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from spatialmech.services.studio import monitors
from spatialmech.services.studio.session import Session



@pytest.fixture(scope="module")
def at_110():
    s = Session("planar-4r")
    s.drive([110.0])
    return s.config


@pytest.mark.parametrize("signs", [(1.0,), (-1.0,), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0, -1.0)])
def test_a_zero_rate_on_a_sample_is_one_event_whatever_the_roundoff_sign(signs, at_110, monkeypatch):
    """planar-4r: B1.rot's rate is exactly zero at A0.rot = 120 deg.  Every value below 1e-12 is
    replaced by +-1e-16 in the order ``signs`` (cycled): 110 -> 120 -> 130 -> 120 -> 110 passes
    the dead point twice, and logs it twice, at 120 deg, never three or one times."""
    real = monitors.MotionRates.rates
    cycle = itertools.cycle(signs)

    def noisy(self, config, names, ref=None):
        v, t = real(self, config, names, ref)
        v = np.array([next(cycle) * 1e-16 if abs(x) < 1e-12 else x for x in v])
        return v, t

    monkeypatch.setattr(monitors.MotionRates, "rates", noisy)
    s = Session("planar-4r")
    s.config = at_110
    s.driven = [s.actuator_values()]
    events = []
    for a in (120.0, 130.0, 120.0, 110.0):
        events += [(e["driver"], e["actuators_deg"]["A0.rot"]) for e in s.drive([a]).events]
    assert [d for d, _ in events] == ["B1.rot", "B1.rot"], events
    assert np.allclose([a for _, a in events], 120.0, atol=1e-6)
