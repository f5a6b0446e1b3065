"""The design studio's HTTP API (issue 16), called through FastAPI's TestClient: the answers are
checked against the library (the task positions fitted by ``dj_table``, inverse position, the
closure residual) and against the studio's JSON Schema and the unit rule of docs/json.md."""

import numpy as np
import pytest
from click.testing import CliRunner
from fastapi.testclient import TestClient

import spatialmech as sm
from spatialmech import catalog
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.studio.app import create_app
from spatialmech.services.studio.session import Session
from spatialmech.kinematics.backend import closure_residual


@pytest.fixture(scope="module")
def five_cs():
    return TestClient(create_app(Session("five-cs-3")))


@pytest.fixture(scope="module")
def table():
    return sm.dj_table("five-cs-3")


def test_drive_linkage3_from_p1_to_p7_follows_the_circuit_and_reports_dj_events(five_cs, table, studio_ok):
    mech = catalog.build("five-cs-3")
    ids = [r.id for r in mech.freedom_refs]
    k_rot1 = ids.index("C1.rot")
    fits = [f.config for f in table.fits]
    rot1 = [float(np.degrees(sm.Configuration(c.q, c.D).q[k_rot1])) for c in fits]  # offsets are 0 here
    start = studio_ok(five_cs.get("/api/model"))["state"]
    assert start["drivers"] == ["C1.rot"] and start["actuators_deg"]["C1.rot"] == pytest.approx(rot1[0], abs=1e-9)
    sc = start["scene"]  # the folded coupler is drawn as a solid: the hull of its 5 S centres and the platform point
    assert len(sc["platform_hull_len"]) == 6 and len(sc["hull_faces"]) == 8
    assert {i for f in sc["hull_faces"] for i in f} == set(range(6))
    drivers = [mech.freedom(d).id for d in table.drivers]
    for k in range(1, len(fits)):
        events: list[str] = []
        for target in np.linspace(rot1[k - 1], rot1[k], 3)[1:]:  # two drags per stretch
            d = studio_ok(five_cs.post("/api/drive", json={"actuators": [float(target)]}))
            assert d["status"] == "reached", d["message"]
            events += [e["driver"] for e in d["events"]]
            st = d["state"]
            assert st["actuators_deg"]["C1.rot"] == pytest.approx(target, abs=1e-9)
            assert st["residual"] < 1e-9
        # at P(k+1): the pose of the fitted configuration, i.e. the same circuit, not another branch
        pose = st["pose"]
        D = fits[k].D
        p_fit = D[:3, :3] @ mech.platform_point + D[:3, 3]
        assert np.allclose(pose["position_len"], p_fit, atol=1e-7)
        assert np.allclose(pose["rotation_matrix"], D[:3, :3], atol=1e-7)
        # every sign change of another driver's DJ between the positions is reported (parity)
        for i, drv in enumerate(drivers):
            if drv == "C1.rot":
                continue
            changed = bool(table.signs[i, k - 1] != table.signs[i, k])
            assert (events.count(drv) % 2 == 1) == changed, (k, drv, events)
    assert table.keeps_sign("rot1") and not any(e.startswith("C1.rot") for e in events)


def test_drive_a_parallel_mechanism_checked_by_inverse_position(studio_ok):
    c = TestClient(create_app(Session("stewart-6sps")))
    st = studio_ok(c.get("/api/state"))["state"]
    assert st["scene"]["hull_faces"] == [] and len(st["scene"]["platform_len"]) == 7  # a planar hexagon
    legs = np.array(list(st["actuators_len"].values()))
    target = legs + np.array([0.04, -0.02, 0.03, 0.0, 0.05, -0.01])
    d = studio_ok(c.post("/api/drive", json={"actuators": target.tolist()}))
    assert d["status"] == "reached" and d["events"] == []
    s = d["state"]
    assert np.allclose(list(s["actuators_len"].values()), target, atol=1e-12)
    pose = (s["pose"]["position_len"], np.array(s["pose"]["rotation_matrix"]))
    inv = sm.ik("stewart-6sps", pose)  # the legs of the returned pose, by inverse position
    assert inv.reachable and np.allclose(list(inv.actuators.values()), target, atol=1e-8)
    # by name, in the model's units, with a map
    named = {k: v - 0.01 for k, v in s["actuators_len"].items()}
    d2 = studio_ok(c.post("/api/drive", json={"actuators": named}))
    assert d2["status"] == "reached" and d2["state"]["actuators_len"] == pytest.approx(named, abs=1e-12)
    modes = studio_ok(c.post("/api/fk_all", json={}))
    assert modes["n_solutions"] >= 1 and modes["solutions"][0]["mode_number"] == 1
    back = studio_ok(c.post("/api/mode", json={"mode_number": 1}))["state"]
    assert np.allclose(back["pose"]["position_len"], modes["solutions"][0]["pose"]["position_len"], atol=1e-9)
    # homotopy continuation answers the 6-SPS (as `fk --all`): it takes no starts
    r = c.post("/api/fk_all", json={"seeds": 12})
    assert r.status_code == 422 and r.json()["error"].startswith("seeds: homotopy"), r.text


@pytest.mark.parametrize(("model", "engine", "n_modes"), [("four-sps-cu", "closed-form", 4),
                                                          ("stewart-6sps", "homotopy", 8)])
def test_the_studio_finds_the_modes_of_sm_fk(model, engine, n_modes, studio_ok):
    """fk_all goes through the one dispatcher (solve_forward): the studio's assembly modes are
    those of ``sm.fk(..., all_solutions=True)`` at the same actuator values (the current one
    first), and each can be picked (a closed form gives poses: the configuration is fitted)."""
    session = Session(model)
    c = TestClient(create_app(session))
    got = studio_ok(c.post("/api/fk_all", json={}))["solutions"]
    ref = sm.fk(model, session.actuator_values(), all_solutions=True)
    assert ref.engine == engine and len(ref.modes) == n_modes and len(got) == n_modes
    unmatched = list(ref.modes)
    for g in got:
        R, p = np.array(g["pose"]["rotation_matrix"]), np.array(g["pose"]["position_len"])
        k = next(i for i, m in enumerate(unmatched) if np.allclose(m.pose.R, R, atol=1e-9)
                 and np.allclose(m.pose.p, p, atol=1e-9))
        m = unmatched.pop(k)
        assert g["kind"] == str(m.kind) and g["sigma_min"] == pytest.approx(m.sigma_min, rel=1e-9)
        assert g["singular"] == (m.sigma_min < m.singular_below) and g["within_limits"] == m.within_limits
    assert not unmatched
    here = studio_ok(c.get("/api/state"))["state"]["pose"]["position_len"]
    assert np.allclose(got[0]["pose"]["position_len"], here, atol=1e-9)  # the current configuration's mode first
    last = studio_ok(c.post("/api/mode", json={"mode_number": n_modes}))["state"]
    assert np.allclose(last["pose"]["position_len"], got[-1]["pose"]["position_len"], atol=1e-9)
    assert last["residual"] < 1e-9


def test_a_rocker_driven_past_its_dead_point_stops_before_it(studio_ok):
    session = Session("rssr")
    c = TestClient(create_app(session))
    st = studio_ok(c.post("/api/drivers", json={"drivers": ["B0.rot"]}))["state"]
    assert st["drivers"] == ["B0.rot"] and set(st["candidate_drivers"]) == {"A0.rot", "B0.rot"}
    dj0 = st["dj"]
    a0 = st["actuators_deg"]["B0.rot"]
    d = studio_ok(c.post("/api/drive", json={"actuators": [a0 + 170.0]}))
    assert d["status"] == "stopped_at_singularity", d["message"]
    # the dead point is located as an event (the rocker's own DJ does not vanish there: the
    # path turns back in its value) ...
    [dead] = [e for e in d["events"] if e["name"] == "dead point (drivers)"]
    assert dead["kind"] == "zero" and dead["driver"] == "B0.rot"
    s = d["state"]
    assert np.sign(s["dj"]) == np.sign(dj0)  # still on the branch it started on
    assert a0 < s["actuators_deg"]["B0.rot"] < dead["actuators_deg"]["B0.rot"] < a0 + 170.0
    # ... where the rocker's angle is largest: posed by its angle (inverse position), it stops there too
    c2 = TestClient(create_app(Session("rssr")))
    edge = c2.post("/api/pose", json={"task_deg": {"a3": a0 + 170.0}}).json()
    assert edge["status"] == "limb_singular"
    assert edge["state"]["task"]["values_deg"]["a3"] == pytest.approx(dead["actuators_deg"]["B0.rot"], abs=0.01)
    assert np.linalg.norm(closure_residual(session.mech, session.config)) < 1e-9
    # driving back works from there
    back = studio_ok(c.post("/api/drive", json={"actuators": [a0]}))
    assert back["status"] == "reached"


@pytest.mark.parametrize("path, body, field", [
    ("/api/drive", {"actuators": [1.0, 2.0]}, "actuators"),
    ("/api/drive", {"actuators": ["x"]}, "actuators[0]"),
    ("/api/drive", {"actuators": {"nope": 1.0}}, "actuators"),
    ("/api/drive", {"actuator": [1.0]}, "actuators"),
    ("/api/drive", [1.0], "body"),
    ("/api/drivers", {"drivers": ["C9.rot"]}, "drivers"),
    ("/api/drivers", {"drivers": "C1.rot"}, "drivers"),
    ("/api/fk_all", {"seeds": 0}, "seeds"),
    ("/api/load", {"model": "no-such-model"}, "no-such-model"),
])
def test_bad_bodies_answer_4xx_naming_the_field(five_cs, path, body, field):
    before = five_cs.get("/api/state").json()["state"]["actuators_deg"]
    r = five_cs.post(path, json=body)
    assert 400 <= r.status_code < 500 and r.json()["error"].startswith(field), r.text
    assert five_cs.get("/api/state").json()["state"]["actuators_deg"] == before  # nothing moved


def test_not_json_and_mode_before_fk_all(five_cs):
    r = five_cs.post("/api/drive", content=b"{oops", headers={"Content-Type": "application/json"})
    assert r.status_code == 422 and r.json()["error"].startswith("body: not JSON")
    r = TestClient(create_app(Session("rssr"))).post("/api/mode", json={"mode_number": 1})
    assert r.status_code == 422 and "fk_all" in r.json()["error"]


def test_the_page_and_plotly_are_served_from_the_package(five_cs):
    page = five_cs.get("/")
    assert page.status_code == 200 and "/static/plotly.min.js" in page.text and "cdn" not in page.text.lower()
    js = five_cs.get("/static/plotly.min.js")
    assert js.status_code == 200 and len(js.content) > 1_000_000
    assert five_cs.get("/static/studio.js").status_code == 200 and five_cs.get("/static/x.js").status_code == 404


def test_studio_command_errors_are_one_line():
    r = CliRunner().invoke(cli, ["studio", "no-such-model", "--no-browser"])
    assert r.exit_code == 2 and r.output.startswith("error: ") and r.output.count("\n") == 1
    h = CliRunner().invoke(cli, ["studio", "--help"])
    assert h.exit_code == 0 and "--no-browser" in h.output


def test_the_3d_view_choice_is_checked_and_reaches_the_page(monkeypatch, studio_ok):
    """Issue 30: ``view`` ("auto", "light", "full") of ``sm.studio_app`` and ``studio --view``;
    anything else is refused naming the field, before any work; the page gets the choice."""
    import json

    import uvicorn

    for bad in ("fast", "", None, 3, "LIGHT"):
        with pytest.raises(sm.InputError, match=r"^view: expected one of 'auto', 'light', 'full', got "):
            sm.studio_app("no-such-model", view=bad)  # the view is checked first
    r = CliRunner().invoke(cli, ["studio", "rssr", "--view", "fast", "--no-browser"])
    assert r.exit_code == 2 and r.output.startswith("error: Invalid value for '--view'") and r.output.count("\n") == 1
    served = {}
    monkeypatch.setattr(uvicorn, "run", lambda app, host, port, **kw: served.update(app=app))
    r = CliRunner().invoke(cli, ["studio", "rssr", "--port", "0", "--no-browser", "--view", "light", "--json"])
    assert r.exit_code == 0, r.output
    assert studio_ok(json.loads(r.output))["view"] == "light"
    client = TestClient(served["app"])
    page = client.get("/").text
    assert '<body data-view="light">' in page and '<script src="/static/scene2d.js">' in page
    assert "const SMScene2D" in client.get("/static/scene2d.js").text
    # ?solids=0 (the light view's requests): the same state without the joint solids
    light = studio_ok(client.post("/api/drive?solids=0", json={"actuators": [10.0]}).json())["state"]
    full = studio_ok(client.get("/api/state").json())["state"]
    assert light["scene"]["joint_meshes"] == [] and len(full["scene"]["joint_meshes"]) == 2
    drop = lambda st: {**st, "scene": {**st["scene"], "joint_meshes": None}}  # noqa: E731
    assert drop(light) == drop(full)
    assert '<body data-view="auto">' in TestClient(sm.studio_app("rssr")).get("/").text  # the default


def test_studio_command_json_before_serving(monkeypatch, studio_ok):
    """``studio --json`` prints the address and the start state, then serves (uvicorn.run is
    replaced here: the app it would serve is checked instead)."""
    import json

    import uvicorn

    served = {}
    monkeypatch.setattr(uvicorn, "run", lambda app, host, port, **kw: served.update(app=app, host=host, port=port))
    r = CliRunner().invoke(cli, ["studio", "rssr", "--port", "0", "--no-browser", "--json"])
    assert r.exit_code == 0, r.output
    doc = studio_ok(json.loads(r.output))
    assert served["host"] == "127.0.0.1" and doc["url"] == f"http://127.0.0.1:{served['port']}/" == f"http://127.0.0.1:{doc['port']}/"
    assert TestClient(served["app"]).get("/api/state").json()["state"]["drivers"] == doc["state"]["drivers"] == ["A0.rot"]


def test_the_traced_circuit_passes_through_the_current_configuration(studio_ok):
    session = Session("rssr")
    c = TestClient(create_app(session))
    d = studio_ok(c.get("/api/circuit"))
    pts = np.array(d["circuit_len"])
    here = np.array(session.state()["scene"]["platform_point_len"])
    assert len(pts) > 20 and np.min(np.linalg.norm(pts - here, axis=1)) < 1e-9
    assert np.linalg.norm(pts[0] - pts[-1]) < 1e-6  # a closed circuit
    r = TestClient(create_app(Session("stewart-6sps"))).get("/api/circuit")
    assert r.status_code == 422 and r.json()["error"].startswith("circuit:")
