"""The forces section of the per-model report (issue 28, present/report_forces.py): statics,
stiffness, accuracy and a performance map, each stating its assumptions; what a model does not
support is listed with the reason."""

from __future__ import annotations

import json

import numpy as np

import spatialmech as sm
from spatialmech import catalog
from spatialmech.present.report import build_model_report
from spatialmech.present.report_forces import REPORT_DENSITY_KG_M3, forces_section


def test_forces_section_of_the_stewart_platform_matches_the_api():
    mech = catalog.resolve("stewart-6sps")
    sec = forces_section(mech)
    assert not sec.pending and len(sec.tables) == 3 and sec.figures[0].png.startswith(b"\x89PNG")
    assert f"{REPORT_DENSITY_KG_M3:g} kg/m^3" in sec.intro and "1 N along -z" in sec.intro
    assert "no geometric term" in sec.intro and "no clearance" in sec.intro
    statics_t, stiff_t, acc_t = sec.tables
    r = sm.statics(mech, wrench=[0, 0, -1.0, 0, 0, 0])
    assert np.allclose([row[2] for row in statics_t.rows], list(r.efforts.values()), rtol=1e-12)
    g = sm.statics(mech, wrench=[0] * 6, gravity=[0, 0, -9.81], density=REPORT_DENSITY_KG_M3)
    assert np.allclose([row[3] for row in statics_t.rows], list(g.efforts.values()), rtol=1e-12)
    k = sm.stiffness(mech)
    assert np.allclose([row[1] for row in stiff_t.rows], k.principal_stiffness, rtol=1e-12)
    a = sm.accuracy(mech, tolerances={"actuator": 1e-5, "geometry": 1e-5}, samples=0, mobility_check=False)
    assert np.allclose([row[2] for row in acc_t.rows], a.worst_case, rtol=1e-12)
    json.dumps(sec.to_dict(), allow_nan=False)


def test_forces_section_lists_what_it_cannot_do_with_the_reason():
    sec = forces_section(catalog.resolve("four-sps-cu"))  # singular reference configuration
    assert any(p.startswith("accuracy:") and "singular" in p for p in sec.pending)
    sec = forces_section(catalog.resolve("bennett"))  # a 9-row complete Jacobian: no map
    assert any(p.startswith("performance map:") for p in sec.pending) and len(sec.tables) == 3


def test_model_report_has_the_forces_section(tmp_path):
    data = build_model_report("rssr", tmp_path, progress=False, trace=False)
    keys = [s["key"] for s in data["sections"]]
    assert keys[-1] == "forces-rssr" and "Forces and accuracy" in (tmp_path / "index.html").read_text()
