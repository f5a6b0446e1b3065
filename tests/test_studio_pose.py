"""Dragging the studio's output link (``POST /api/pose``, inverse position along the current
branch) and the joint limits on the actuator sliders and drives (issue 16), through FastAPI's
TestClient: the pose answered is the pose requested, the actuators answered give it back by
forward position, and refusals are clear."""

import numpy as np
import pytest
from fastapi.testclient import TestClient

import spatialmech as sm
from spatialmech.geometry.rotations import euler_matrix
from spatialmech.interfaces.studio.app import create_app
from spatialmech.services.studio.session import Session


def pose_of(state) -> tuple[np.ndarray, np.ndarray]:
    return np.array(state["pose"]["position_len"]), np.array(state["pose"]["rotation_matrix"])


def test_pose_drag_of_the_stewart_platform_gives_the_requested_pose_and_fk_agrees(studio_ok):
    c = TestClient(create_app(Session("stewart-6sps")))
    t = studio_ok(c.get("/api/state"))["state"]["task"]
    assert t["given"] == ["x", "y", "z", "a1", "a2", "a3"] and t["solved"] == []
    req_len = {"x": 0.05, "y": -0.03, "z": t["values_len"]["z"] + 0.1}
    req_deg = {"a1": 8.0, "a2": -5.0, "a3": 4.0}
    d = studio_ok(c.post("/api/pose", json={"task_len": req_len, "task_deg": req_deg, "euler": "ZYX"}))
    assert d["status"] == "reached", d["message"]
    assert d["requested_task_len"] == pytest.approx(req_len) and d["requested_task_deg"] == pytest.approx(req_deg)
    st = d["state"]
    assert st["task"]["values_len"] == pytest.approx(req_len, abs=1e-9)
    assert st["task"]["values_deg"] == pytest.approx(req_deg, abs=1e-9)
    p, R = pose_of(st)
    assert np.allclose(R, euler_matrix("ZYX", np.radians([8.0, -5.0, 4.0])), atol=1e-9)
    legs = st["actuators_len"]
    fk = sm.fk("stewart-6sps", legs)  # the legs answered give the pose back
    assert fk.converged and np.allclose(fk.poses[0].p, p, atol=1e-8) and np.allclose(fk.poses[0].R, R, atol=1e-8)
    # increments, in another Euler sequence: the pose moves by them
    d2 = studio_ok(c.post("/api/pose", json={"task_deg": {"a1": 2.0}, "euler": "XYZ", "relative": True}))
    assert d2["status"] == "reached"
    p2, R2 = pose_of(d2["state"])
    from spatialmech.geometry.rotations import matrix_euler
    assert np.degrees(matrix_euler("XYZ", R2)[0] - matrix_euler("XYZ", R)[0]) == pytest.approx(2.0, abs=1e-9)
    assert np.allclose(p2, p, atol=1e-9)


def test_a_lower_mobility_output_is_posed_by_the_coordinates_it_controls(studio_ok):
    c = TestClient(create_app(Session("four-sps-cu")))
    st = studio_ok(c.get("/api/state"))["state"]
    t = st["task"]
    assert t["given"] == ["z", "a1", "a2", "a3"] and t["solved"] == ["x", "y"]
    assert st["slider_ranges_len"] == {k: [0.1, 0.4] for k in st["drivers"]}  # the legs' joint limits
    r = c.post("/api/pose", json={"task_len": {"x": 0.01}})
    assert r.status_code == 422 and r.json()["error"].startswith("task_len.x") and "solved" in r.json()["error"]
    z = t["values_len"]["z"] + 0.01
    a3 = t["values_deg"]["a3"] + 2.0
    d = studio_ok(c.post("/api/pose", json={"task_len": {"z": z}, "task_deg": {"a3": a3}}))
    assert d["status"] == "reached", d["message"]
    got = d["state"]["task"]
    assert got["values_len"]["z"] == pytest.approx(z, abs=1e-9) and got["values_deg"]["a3"] == pytest.approx(a3, abs=1e-9)
    assert got["values_deg"]["a1"] == pytest.approx(t["values_deg"]["a1"], abs=1e-9)  # held
    p, R = pose_of(d["state"])
    fk = sm.fk("four-sps-cu", d["state"]["actuators_len"], all_solutions=True)  # closed form: every mode
    assert any(np.allclose(P.p, p, atol=1e-7) and np.allclose(P.R, R, atol=1e-7) for P in fk.poses)
    # far up: the legs reach their limits first; stopped inside them, with a clear status
    up = studio_ok(c.post("/api/pose", json={"task_len": {"z": 0.6}}))
    assert up["status"] == "stopped_at_limit" and "limits" in up["message"], up["message"]
    s = up["state"]
    assert s["outside_limits"] == [] and z < s["task"]["values_len"]["z"] < 0.6
    # a drive outside the legs' limits is refused, naming the actuator
    legs = list(s["actuators_len"].values())
    r = c.post("/api/drive", json={"actuators": [legs[0], legs[1], 0.45, legs[3]]})
    assert r.status_code == 422 and r.json()["error"].startswith("actuators:") and "L3" in r.json()["error"]


def test_the_rssr_rocker_angle_stops_at_the_edge_of_its_range(studio_ok):
    c = TestClient(create_app(Session("rssr")))
    t = studio_ok(c.get("/api/state"))["state"]["task"]
    assert t["given"] == ["a3"]
    d = studio_ok(c.post("/api/pose", json={"task_deg": {"a3": 20.0}}))
    assert d["status"] == "reached" and d["state"]["task"]["values_deg"]["a3"] == pytest.approx(20.0, abs=1e-9)
    crank = d["state"]["actuators_deg"]["A0.rot"]
    fk = sm.fk("rssr", [crank], degrees=True, all_solutions=True, seeds=8)
    assert any(np.allclose(P.R, pose_of(d["state"])[1], atol=1e-7) for P in fk.poses)
    # the rocker swings less than 90 deg: the crank's limb reaches an inverse singularity (dead centre)
    far = studio_ok(c.post("/api/pose", json={"task_deg": {"a3": 90.0}}))
    assert far["status"] == "limb_singular" and "A0.rot" in far["message"]
    a3 = far["state"]["task"]["values_deg"]["a3"]
    assert 20.0 < a3 < 90.0 and far["state"]["residual"] < 1e-9
    again = studio_ok(c.post("/api/pose", json={"task_deg": {"a3": 90.0}}))  # nothing further, nothing jumps
    assert again["status"] == "limb_singular" and again["state"]["task"]["values_deg"]["a3"] == pytest.approx(a3, abs=1e-6)


def test_a_direct_singularity_on_the_pose_path_is_located_and_stops_the_drag(studio_ok):
    c = TestClient(create_app(Session("four-sps-cu")))
    st = studio_ok(c.get("/api/state"))["state"]
    d = studio_ok(c.post("/api/pose", json={"task_deg": {"a2": 60.0}}))
    assert d["status"] == "stopped_at_singularity", d["message"]
    [ev] = d["events"]
    assert ev["name"] == "DJ (drivers)" and ev["kind"] == "zero"
    a2_ev = ev["task_deg"]["a2"]
    now = d["state"]
    assert st["task"]["values_deg"]["a2"] < now["task"]["values_deg"]["a2"] <= a2_ev < 60.0
    assert np.sign(now["dj"]) == np.sign(st["dj"])  # still on its branch


@pytest.mark.parametrize("body, field", [
    ({"task_deg": {"a1": "x"}}, "task_deg.a1"),
    ({"task_len": {"a1": 1.0}}, "task_len.a1"),
    ({"task_len": [0.1]}, "task_len"),
    ({"task_deg": {"a1": 1.0}, "euler": "ZZZ"}, "euler"),
    ({"task_deg": {"a1": 1.0}, "relative": "yes"}, "relative"),
    ({"euler": "ZYX"}, "task_len"),
    ({"pose": {}}, "pose"),
])
def test_bad_pose_bodies_answer_422_naming_the_field(body, field):
    c = TestClient(create_app(Session("rssr")))
    r = c.post("/api/pose", json=body)
    assert r.status_code == 422 and r.json()["error"].startswith(field), r.text


def test_the_static_viewer_draws_the_studios_joint_solids_and_platform_body():
    """One module draws both (present/shapes.py): at the studio's configuration the viewer's
    mesh traces are the studio's meshes (a 5-CS coupler: the hull of its joints, not a fold)."""
    from spatialmech.present.viewer import viewer_figure

    s = Session("five-cs-1")
    scene = s.state()["scene"]
    fig = viewer_figure(s.mech, [s.config])
    meshes = [t for t in fig.data if t.type == "mesh3d" and t.name != "base"]  # the first frame, styled
    plat, joints = meshes[0], meshes[1:]
    assert scene["hull_faces"] and len(plat.i) == len(scene["platform_mesh"]["triangles"]) == len(scene["hull_faces"])
    assert np.allclose(np.c_[plat.x, plat.y, plat.z], scene["platform_mesh"]["vertices_len"], atol=1e-6)
    assert len(joints) == len(scene["joint_meshes"]) == len(s.mech.limbs)
    for t, m in zip(joints, scene["joint_meshes"], strict=True):
        assert np.allclose(np.c_[t.x, t.y, t.z], m["vertices_len"], atol=1e-6)
        assert np.array_equal(np.c_[t.i, t.j, t.k], m["triangles"])
    # a ball per S joint and a cylinder per C joint, centred on the joints
    types = {j["type"] for j in scene["joints"]}
    assert types == {"C", "S"}
