"""The studio's top view of planar linkages and the drag handle on the output point (issue 30,
items 9 and "Also build"), through the session and the HTTP API; the page itself:
tests/test_studio_view_browser.py."""

from __future__ import annotations

import numpy as np
import pytest

import spatialmech as sm
from spatialmech.errors import InputError
from spatialmech.services.studio.scene import plane_normal
from spatialmech.services.studio.session import Session


def test_a_planar_linkage_gets_its_plane_normal_and_others_none():
    assert Session("planar-4r").scene()["plane_normal"] == pytest.approx([0.0, 0.0, 1.0], abs=1e-12)
    for name in ("bennett", "rssr"):
        assert Session(name).scene()["plane_normal"] is None


def test_plane_normal_rule():
    r = lambda a: {"type": "R", "axes": [np.array(a, dtype=float)]}  # noqa: E731
    p = lambda a: {"type": "P", "axes": [np.array(a, dtype=float)]}  # noqa: E731
    n = np.array([1.0, 2.0, -2.0]) / 3.0
    assert plane_normal([r(-n), r(2 * n), r(n)]) == pytest.approx(n)  # oriented by the largest component
    assert plane_normal([r(n), r(n), p(np.cross(n, [0.0, 0.0, 1.0]))]) == pytest.approx(n)  # a slider-crank
    assert plane_normal([r(n), r(n), p(n)]) is None  # a slide out of the plane
    assert plane_normal([r(n), r(n + np.array([0.0, 0.0, 1e-4]))]) is None  # not parallel
    assert plane_normal([r(n), r(n), {"type": "S", "axes": []}]) is None
    assert plane_normal([r(n)]) is None


def test_the_drag_handle_moves_the_output_point_along_the_branch():
    s = Session("planar-4r")  # controls x only: the coupler point follows x
    p = np.array(s.scene()["platform_point_len"])
    r = s.drag_output([float(p[0]) + 0.05, float(p[1]) + 0.3, 0.0])
    assert r.status == "reached"
    q = np.array(s.scene()["platform_point_len"])
    assert q[0] == pytest.approx(p[0] + 0.05, abs=1e-9)
    same = Session("planar-4r")
    same.drive_pose({"x": float(p[0]) + 0.05})
    assert np.allclose(same.config.q, s.config.q, atol=1e-12)  # the pose drag, nothing else

    st = Session("stewart-6sps")  # x, y, z given: the point goes where the mouse is
    p = np.array(st.scene()["platform_point_len"])
    want = p + np.array([0.05, -0.03, 0.0])
    assert st.drag_output(want.tolist()).status == "reached"
    assert np.allclose(st.scene()["platform_point_len"], want, atol=1e-9)


@pytest.mark.parametrize("bad", [None, [0.0, 1.0], [0.0, float("nan"), 0.0], ["a", 0.0, 0.0], [True, 0.0, 0.0]])
def test_bad_drag_points_are_refused_naming_the_field(bad):
    with pytest.raises(InputError, match=r"^point_len: expected three finite numbers"):
        Session("planar-4r").drag_output(bad)


def test_a_mechanism_that_does_not_control_its_point_refuses_the_drag():
    with pytest.raises(InputError, match=r"^point_len: rssr does not control the output point's position"):
        Session("rssr").drag_output([0.0, 1.0, 0.0])


def test_the_drag_route(studio_ok):
    from fastapi.testclient import TestClient

    client = TestClient(sm.studio_app("planar-4r"))
    p = client.get("/api/state").json()["state"]["scene"]["platform_point_len"]
    doc = studio_ok(client.post("/api/drag", json={"point_len": [p[0] - 0.05, p[1], p[2]]}))
    assert doc["status"] == "reached" and doc["state"]["scene"]["platform_point_len"][0] == pytest.approx(p[0] - 0.05, abs=1e-9)
    assert doc["state"]["scene"]["plane_normal"] == pytest.approx([0.0, 0.0, 1.0], abs=1e-12)
    bad = client.post("/api/drag", json={"point_len": [1.0]})
    assert bad.status_code == 422 and bad.json()["error"].startswith("point_len")


def test_the_notebook_widget_opens_a_planar_linkage_in_its_top_view():
    pytest.importorskip("anywidget")
    from spatialmech.interfaces.studio.widget import figure

    cam = figure(Session("planar-4r").state(), "m")["layout"]["scene"]["camera"]
    assert [cam["eye"][a] for a in "xyz"] == pytest.approx([0.0, 0.0, 2.0])
    assert [cam["up"][a] for a in "xyz"] == pytest.approx([0.0, 1.0, 0.0]) and cam["projection"]["type"] == "orthographic"
    assert "camera" not in figure(Session("rssr").state(), "m")["layout"]["scene"]
