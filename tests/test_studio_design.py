"""The studio as a design tool (issue 30, "Also build") through the session API
(``session.desk``) and the HTTP API: snapshots with undo, the driven path as the CSV that
``validate --actuators-path`` reads (round trip through its reader), sweeps of one driver
(joint values and transmission against the input) and the coupler curve of a picked point."""

from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

import spatialmech as sm
from spatialmech.interfaces.cmd_validate import read_actuator_path


@pytest.fixture()
def rssr():
    return sm.studio_session("rssr")


def crank(s) -> float:
    return s.state()["actuators_deg"]["A0.rot"]


def test_snapshot_and_undo_go_back_exactly(rssr):
    s = rssr
    s.drive([20.0])
    pose = s.state()["pose"]
    assert [x["label"] for x in s.desk.snapshot("twenty")] == ["twenty"]
    s.drive([45.0])
    s.desk.snapshot()
    s.drive([60.0])
    assert s.desk.undo() == "snapshot 2" and abs(crank(s) - 45.0) < 1e-9
    assert s.desk.undo() == "twenty" and abs(crank(s) - 20.0) < 1e-9
    assert s.state()["pose"] == pose                   # the same configuration, not a new solve
    assert s.drive([25.0]).status == "reached"        # and driving goes on from there
    with pytest.raises(sm.InputError, match="undo: no snapshot"):
        s.desk.undo()
    s.desk.snapshot("again")
    s.drive([30.0])
    s.desk.restore(1)
    assert abs(crank(s) - 25.0) < 1e-9 and len(s.desk.listing()) == 1
    with pytest.raises(sm.InputError, match="number: expected 1 to 1"):
        s.desk.restore(2)
    with pytest.raises(sm.InputError, match="label: expected text"):
        s.desk.snapshot(3)


def test_the_driven_path_round_trips_through_validates_reader(rssr, tmp_path):
    s = rssr
    for v in (10.0, 25.5, -12.25):
        assert s.drive([v]).status == "reached"
    f = tmp_path / "path.csv"
    f.write_text(s.desk.path_csv(), encoding="utf-8")
    rows = read_actuator_path(s.mech, f)
    assert np.allclose(np.degrees(rows[:, 0]), [0.0, 10.0, 25.5, -12.25], atol=1e-9)


def test_the_driven_path_of_a_slide_driven_model(tmp_path):
    s = sm.studio_session("four-sps-cu")
    a = np.array(list(s.state()["actuators_len"].values()))
    assert s.drive(list(a + 0.002)).status == "reached"
    f = tmp_path / "legs.csv"
    f.write_text(s.desk.path_csv(), encoding="utf-8")
    assert f.read_text().splitlines()[1] == ",".join(s.mech.actuators)   # slides bare, in the length unit
    rows = read_actuator_path(s.mech, f)
    assert np.allclose(rows, [a, a + 0.002], atol=1e-12)


def test_a_sweep_stops_at_the_dead_points_and_puts_the_session_back(rssr):
    s = rssr
    s.drive([20.0])
    before = s.state()["pose"]
    sw = s.desk.sweep(samples=41)
    assert s.state()["pose"] == before
    x = np.array(sw["input"])
    assert sw["driver"] == "A0.rot" and sw["input_unit"] == "deg" and np.all(np.diff(x) > 0)
    # rssr's crank rocks between the dead points at -90 and +90 deg (the session's own stop)
    assert -90.0 < x[0] < -80.0 and 80.0 < x[-1] < 90.0 and len(sw["stops"]) == 2
    n = len(x)
    assert all(len(v) == n for v in sw["joints_deg"].values())
    assert len(sw["transmission_min"]) == n == len(sw["sigma_min"]) == len(sw["point_len"])
    # the sweep's samples are the session's configurations: the crank joint equals the input
    assert np.allclose(sw["joints_deg"]["A0.rot"], x, atol=1e-9)
    with pytest.raises(sm.InputError, match="samples: expected a whole number from 5 to 721"):
        s.desk.sweep(samples=2)
    with pytest.raises(sm.InputError, match=r"driver: expected one of the drivers A0\.rot"):
        s.desk.sweep("nope")


def test_the_coupler_curve_of_a_picked_point(rssr):
    s = rssr
    point = [0.05, 0.0, 0.02]                            # in the output link's frame
    cc = s.desk.coupler_curve(point, frames=30)
    assert cc["over"] == "circuit" and len(cc["curve_len"]) == 30
    # the curve passes through the picked point's place in the current configuration
    c = s.config
    here = c.D[:3, :3] @ np.array(point) + c.D[:3, 3]
    assert min(np.linalg.norm(np.array(cc["curve_len"]) - here, axis=1)) < 0.05 * s.mech.characteristic_length
    with pytest.raises(sm.InputError, match=r"point_len: expected three numbers"):
        s.desk.coupler_curve([1.0, 2.0])


def test_the_http_api_of_the_desk():
    client = TestClient(sm.studio_app("rssr"))
    assert client.post("/api/drive", json={"actuators": [15.0]}).json()["status"] == "reached"
    assert client.post("/api/snapshot", json={"label": "fifteen"}).json()["snapshots"][0]["label"] == "fifteen"
    client.post("/api/drive", json={"actuators": [40.0]})
    r = client.get("/api/path.csv")
    assert r.status_code == 200 and r.headers["content-type"].startswith("text/csv")
    assert r.text.splitlines()[1:] == ["A0.rot_deg", "0", "15", "40"]
    doc = client.post("/api/undo").json()
    assert doc["restored"] == "fifteen" and abs(doc["state"]["actuators_deg"]["A0.rot"] - 15.0) < 1e-9
    assert client.post("/api/undo").json()["error"].startswith("undo: no snapshot")
    sw = client.post("/api/sweep", json={"samples": 11}).json()
    assert sw["command"] == "studio" and len(sw["input"]) >= 5
    assert client.post("/api/coupler", json={"point_len": "x"}).status_code == 422


def test_the_desk_is_documented():
    text = (Path(__file__).parent.parent / "docs" / "studio.md").read_text(encoding="utf-8")
    for path in ("/api/snapshot", "/api/undo", "/api/coupler", "/api/sweep", "/api/path.csv"):
        assert path in text, path


def test_switching_drivers_updates_the_readout_at_the_same_configuration():
    """The readout's Jacobian belongs to the drivers: after set_drivers at the same configuration
    the transmission indices are those of the new drivers (the cache was keyed on the
    configuration only), and so after an undo across a driver switch."""
    s = sm.studio_session("stewart-6sps")
    assert "L1.slide" in s.state()["transmission"]
    s.desk.snapshot("legs")
    new = ["B1.rot1", "L2.slide", "L3.slide", "L4.slide", "L5.slide", "L6.slide"]
    s.set_drivers(new)
    st = s.state()
    assert st["drivers"] == new and set(st["transmission"]) == set(new)
    s.desk.undo()
    assert set(s.state()["transmission"]) == {f"L{k}.slide" for k in range(1, 7)}
