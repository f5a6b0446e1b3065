"""``view`` on a linkage whose traced motion meets a bifurcation (issue 30 item 7): a Sarrus
linkage built here is drawn up to the stops, which are marked, and ``--tol`` is accepted."""

from __future__ import annotations

import json

import numpy as np
from click.testing import CliRunner

import spatialmech as sm
from spatialmech.analysis.traced_motion import traced_part
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closure import Configuration


def sarrus(h: float = 0.2) -> sm.Mechanism:
    """Two planar R-R-R limbs in perpendicular planes: the platform translates along z."""
    x, y = [1.0, 0, 0], [0, 1.0, 0]
    return sm.Mechanism("sarrus", limbs=[
        sm.Limb("yz", [sm.R("A1", [0, -0.05, 0], x, actuated=True), sm.R("B1", [0, -0.15, h / 2], x),
                       sm.R("C1", [0, -0.05, h], x)]),
        sm.Limb("xz", [sm.R("A2", [0.05, 0, 0], y), sm.R("B2", [0.15, 0, h / 2], y), sm.R("C2", [0.05, 0, h], y)]),
    ], platform_point=[0, 0, h])


def test_sarrus_trace_stops_at_two_bifurcations_and_keeps_the_part():
    m = sarrus()
    tr = traced_part(m, frames=30)
    assert len(tr.stops) == 2 and "stop(s) of the tracker" in tr.note and len(tr.configs) == 30
    # the platform only translates along z on the traced part, from one stop to the other
    zs = []
    for c in tr.configs:
        assert np.allclose(c.D[:3, :3], np.eye(3), atol=1e-8) and np.allclose(c.D[:2, 3], 0, atol=1e-8)
        zs.append(c.D[2, 3])
    ref = Configuration.reference(m).D[2, 3]
    assert min(zs) < ref < max(zs)
    ends = sorted(s.D[2, 3] for s in tr.stops)
    assert ends[0] <= min(zs) + 1e-9 and ends[1] >= max(zs) - 1e-9


def test_view_command_writes_the_page_and_says_why(tmp_path):
    path = tmp_path / "sarrus.toml"
    path.write_text(sm.dumps(sarrus()))
    out = tmp_path / "s.html"
    run = CliRunner().invoke(cli, ["view", str(path), "--out", str(out), "--frames", "20", "--plotly", "cdn",
                                   "--tol", "1e-9", "--json"], catch_exceptions=False)
    assert run.exit_code == 0, run.output
    doc = json.loads(run.output)
    assert doc["motion"] == "trace" and "stop(s)" in doc["note"] and out.exists()
    assert "bifurcation (the tracker stopped here)" in out.read_text()
    text = CliRunner().invoke(cli, ["view", str(path), "--out", str(out), "--frames", "20", "--plotly", "cdn"],
                              catch_exceptions=False).output
    assert text.startswith("wrote ") and "note: traced" in text
