"""The reports a designer reads (issue 30 item 9): the one-model report of a 6-DOF platform has
its assembly modes, a singularity map and a workspace, each with its figure and the right
numbers; the reproduction report fits an 820-px page, says each caption once and prints no
"[unit]" placeholder.

One ``report stewart-6sps`` build serves the whole module; the demo is the session's one run
(tests/conftest.py)."""

import html
import json
import re

import numpy as np
import pytest

from spatialmech import catalog
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.jacobian import complete_jacobian
from spatialmech.present import model_platform
from spatialmech.present.numbers import unit_label
from spatialmech.present.report import build_model_report

pytestmark = pytest.mark.slow  # one report build (fk --all by homotopy, a slice, a workspace): ~10-20 s


@pytest.fixture(scope="module")
def stewart(tmp_path_factory):
    out = tmp_path_factory.mktemp("report-stewart")
    calls = []
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(model_platform, "PROGRESS_EVERY_S", 0.0)  # every count inside a step is passed on
        doc = build_model_report("stewart-6sps", out, progress=lambda d, t, m: calls.append((d, t, m)))
    sec = next(s for s in doc["sections"] if s["key"] == "platform-stewart-6sps")
    return out, doc, sec, calls


def test_the_workspace_step_reports_its_count_under_its_own_step_number(stewart):
    """A long step (the workspace's poses) shows progress inside the step: the same step number,
    the count in the message, never past the report's total."""
    *_, calls = stewart
    step = next(d for d, _, m in calls if m == "stewart-6sps: workspace")
    inner = [(d, m) for d, _, m in calls if m.startswith("stewart-6sps: workspace: checking poses ")]
    assert inner and all(d == step for d, _ in inner), calls
    assert all(d <= t for d, t, _ in calls if d is not None and t is not None)


def test_platform_section_lists_the_assembly_modes_of_fk_all(stewart):
    _, _, sec, _ = stewart
    m = sec["data"]["assembly_modes"]
    assert m["engine"] == "homotopy" and m["complete"] is True
    assert m["n_modes"] == 8 and all(x["certified"] for x in m["modes"])
    mech = catalog.build("stewart-6sps")
    ref = [x for x in m["modes"] if x["reference"]]
    assert len(ref) == 1 and np.allclose(ref[0]["position_len"], mech.platform_point, atol=1e-9)
    assert np.allclose(ref[0]["euler_deg"], 0.0, atol=1e-9)
    J = complete_jacobian(mech, Configuration.reference(mech))
    assert ref[0]["sigma_min"] == pytest.approx(J.sigma_min, rel=1e-6)
    # the mirror image through the base plane is a mode too (the legs' lengths do not see the sign of z)
    assert any(np.allclose(x["position_len"], -np.asarray(mech.platform_point), atol=1e-9) for x in m["modes"])
    table = next(t for t in sec["tables"] if t["title"].startswith("Assembly modes"))
    assert len(table["rows"]) == 8 and "proven complete" in table["note"] and "intrinsic ZYX" in table["note"]
    assert any(f["file"] == "figures/assembly_modes.png" for f in sec["figures"])
    assert sec["viewers"] and sec["viewers"][0]["frames"] == 8


def test_platform_section_maps_singularities_through_the_reference_pose(stewart):
    _, _, sec, _ = stewart
    s = sec["data"]["singularity_map"]
    nu, nv = model_platform.SLICE_POINTS
    assert s["grid"] == [nu, nv] and s["points"] == nu * nv
    assert s["points_on_branch"] == nu * nv and s["det_changes_sign"] is False
    mech = catalog.build("stewart-6sps")
    sig_ref = complete_jacobian(mech, Configuration.reference(mech)).sigma_min
    assert s["sigma_min_min"] < sig_ref < s["sigma_min_max"]  # the reference lies on the slice
    cap = next(f["caption"] for f in sec["figures"] if f["file"] == "figures/singularity_map.png")
    assert f"({nu} points)" in cap and f"({nv} points)" in cap and "keeps its sign" in cap


def test_platform_section_gives_the_workspace_volume_with_its_error(stewart):
    _, _, sec, _ = stewart
    w = sec["data"]["workspace"]
    mech = catalog.build("stewart-6sps")
    L = mech.characteristic_length
    n = model_platform.WORKSPACE_POINTS
    assert w["kind"] == "position" and w["grid"] == [n, n, n]
    # the ready-made Gough-Stewart has no limits: the set is the searched box, +- 2 L about the reference
    assert set(w["active_limits"]) == {"box"}
    assert w["volume_len3"] == pytest.approx((4 * L) ** 3, abs=w["volume_error_len3"] + 1e-9)
    assert 0 < w["volume_error_len3"] < 1e-3 * w["volume_len3"]
    cap = next(f["caption"] for f in sec["figures"] if f["file"] == "figures/workspace.png")
    assert f"({n} x {n} x {n} points)" in cap and "+- " in cap and "no limit" in cap


def test_platform_section_figures_are_written_and_embedded(stewart):
    out, doc, sec, _ = stewart
    page = (out / "index.html").read_text(encoding="utf-8")
    for f in sec["figures"]:
        assert (out / f["file"]).stat().st_size > 1000
        assert f"({f['file']})" in page
    assert json.loads((out / "results.json").read_text(encoding="utf-8"))["model"] == doc["model"]


def test_a_one_dof_linkage_gets_no_platform_section():
    assert not model_platform.applies(catalog.build("planar-4r"))
    assert model_platform.applies(catalog.build("three-rps"))


# ------------------------------------------------------------------ the reproduction report's page
def _figures(page: str) -> list[tuple[str, str]]:
    """``(alt, figcaption text)`` of every figure of a report page."""
    out = []
    for alt, cap in re.findall(r"<figure><img alt='([^']*)'[^>]*><figcaption>(.*?)</figcaption></figure>", page, re.S):
        out.append((html.unescape(alt), html.unescape(re.sub(r"<[^>]+>", "", cap))))
    return out


def test_demo_captions_say_their_title_once_and_no_unit_placeholder(demo_report):
    out, _ = demo_report
    page = (out / "index.html").read_text(encoding="utf-8")
    figs = _figures(page)
    assert len(figs) >= 15
    for alt, cap in figs:
        assert cap.count(alt) == 1, (alt, cap)
        body = cap.split(alt, 1)[1]
        assert not body.lstrip(". ").startswith(alt.split(":")[0] + ":"), cap  # "Linkage 1: ... Linkage 1: ..."
    assert "[unit]" not in page
    assert unit_label("unit") == "length unit not stated" and unit_label("mm") == "mm"


def test_demo_page_is_responsive(demo_report):
    out, _ = demo_report
    page = (out / "index.html").read_text(encoding="utf-8")
    assert "name='viewport'" in page and "figure img{max-width:100%;height:auto" in page
    tables = page.count("<table")
    assert tables > 0 and page.count("<div class='scroll'><table") == tables  # every table scrolls in its own box


def test_demo_page_fits_820_px_in_chromium(demo_report, browser):
    """Headless Chromium (tests/conftest.py's driver) at a window 820 px wide: the page
    does not scroll sideways (wide tables scroll inside their own box)."""
    out, _ = demo_report
    browser.set_window_size(820, 1000)
    browser.get((out / "index.html").as_uri())
    width = browser.execute_script("return document.documentElement.clientWidth")
    assert width <= 820
    assert browser.execute_script("return document.documentElement.scrollWidth") <= 820
    wide = browser.execute_script(
        "const w = document.documentElement.clientWidth; return [...document.querySelectorAll('img, table, .viewer')]"
        ".filter(e => !e.closest('.scroll') && e.getBoundingClientRect().right > w + 1).length")
    assert wide == 0


def test_a_serial_arm_gets_its_inverse_solutions_instead_of_assembly_modes():
    """The PUMA 560's report lists its 8 inverse solutions at the reference pose (proven,
    certified, the reference among them), not a one-row table of fk --all."""
    data: dict = {}
    mech = catalog.resolve("puma560")
    table, _ = model_platform._inverse_solutions(mech, data)
    inv = data["inverse_solutions"]
    assert inv["complete"] and inv["n_solutions"] == 8 == len(table.rows)
    assert all(s["certified"] for s in inv["solutions"]) and min(s["sigma_min"] for s in inv["solutions"]) > 0.1
    assert sum(r[-1] == "reference" for r in table.rows) == 1
    from spatialmech.serialize import unit_rule_violations

    assert unit_rule_violations({"length_unit": "m", "inverse_solutions": inv}) == []  # joints_deg / joints_len
    assert not model_platform._serial(catalog.resolve("stewart-6sps"))
