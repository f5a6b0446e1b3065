"""Issue 30, items 1-3: the studio and the singularity slices a designer trusts.

1. On linkages with common constraints (planar-4r, bennett, a Sarrus linkage built here) the
   complete Jacobian is not square; the studio decides where a driver loses control on the
   motion's tangent space, logs no events on round-off, gives the DJ readout a value or a
   reason, and logs a repeated stop once.
2. A pose slice of a 6-RUS hexapod (built here) follows the given pose's working mode: det J at
   the pose is ``sm.jacobian``'s, and every sign change of det J on the grid lies between two
   points on that branch, at a real singularity (small sigma_min).
3. The studio's readout carries an inverse (transmission) light: the 6-RUS pose drag that stops
   with ``limb_singular`` shows it red while sigma_min is far from singular.
"""

from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

import spatialmech as sm
from spatialmech.analysis.pose_slice import FOLLOWED, mode_signature
from spatialmech.geometry.tolerances import INVERSE_SINGULAR, NEAR_SINGULAR
from spatialmech.services.studio.monitors import EVENT_LOG_MAX


def six_rus(rb=0.2, rp=0.1, a=0.08, h=0.2, split=15.0, psplit=45.0) -> sm.Mechanism:
    """A hexapod with rotary actuators: R on the base (axis tangential), U at the crank tip, S at
    the platform; the reference is the platform at height ``h``, level."""
    limbs = []
    for k in range(6):
        sgn = -1 if k % 2 == 0 else 1
        th, ph = np.radians(120 * (k // 2) + sgn * split), np.radians(120 * (k // 2) + sgn * psplit)
        radial, tang = np.array([np.cos(th), np.sin(th), 0.0]), np.array([-np.sin(th), np.cos(th), 0.0])
        A = rb * radial
        C = A + a * radial
        B = np.array([rp * np.cos(ph), rp * np.sin(ph), h])
        u2 = np.cross((B - C) / np.linalg.norm(B - C), tang)
        limbs.append(sm.Limb(f"leg{k + 1}", [sm.R(f"A{k + 1}", A, tang, actuated=True),
                                            sm.U(f"C{k + 1}", C, [tang, u2 / np.linalg.norm(u2)]), sm.S(f"B{k + 1}", B)]))
    return sm.Mechanism("six-rus", limbs=limbs, platform_point=[0, 0, h])


def sarrus(h=0.2) -> sm.Mechanism:
    """Two planar R-R-R limbs in perpendicular planes: the platform translates along z."""
    x, y = [1.0, 0, 0], [0, 1.0, 0]
    return sm.Mechanism("sarrus", limbs=[
        sm.Limb("yz", [sm.R("A1", [0, -0.05, 0], x, actuated=True), sm.R("B1", [0, -0.15, h / 2], x),
                       sm.R("C1", [0, -0.05, h], x)]),
        sm.Limb("xz", [sm.R("A2", [0.05, 0, 0], y), sm.R("B2", [0.15, 0, h / 2], y), sm.R("C2", [0.05, 0, h], y)]),
    ], platform_point=[0, 0, h])


def drag(client, start: float, steps: int, step: float) -> list[dict]:
    """``steps`` drive requests of ``step`` degrees each; every answer."""
    return [client.post("/api/drive", json={"actuators": [start + step * (k + 1)]}).json() for k in range(steps)]


@pytest.mark.parametrize("model", ["planar-4r", "bennett", "sarrus"])
def test_no_false_events_on_linkages_with_common_constraints(model):
    mech = sarrus() if model == "sarrus" else model
    client = TestClient(sm.studio_app(mech))
    st = client.get("/api/state").json()["state"]
    assert st["dj"] is None and "not square" in st["dj_note"]  # a reason, not '-'
    assert 0.0 < st["dj_rate"] <= 1.0 and set(st["dj_by_driver"]) == set(st["candidate_drivers"])
    a0 = st["actuators_deg"][st["drivers"][0]]
    step = 1.0 if model != "sarrus" else 0.5  # the Sarrus crank's range is small
    docs = drag(client, a0, 30, step)
    assert all(d["status"] == "reached" for d in docs), [d["message"] for d in docs if d["status"] != "reached"]
    assert [e for d in docs for e in d["events"]] == []


def test_planar_4r_events_are_the_dead_points_of_the_other_drivers():
    """A full crank turn in 5-degree steps: the rocker B0 and the coupler-rocker joint B1 each
    have two dead points (their values turn back there, checked by the joint values 1 degree
    either side), and nothing else is logged."""
    s = sm.studio_session("planar-4r")
    events = [e for k in range(1, 73) for e in s.drive([5.0 * k]).events]
    assert sorted(e["driver"] for e in events) == ["B0.rot", "B0.rot", "B1.rot", "B1.rot"]
    assert all("rate along the motion" in e["meaning"] for e in events)
    for e in events:
        at = e["actuators_deg"]["A0.rot"] % 360.0
        vals = []
        for d in (-1.0, 0.0, 1.0):
            assert s.drive([at + d]).status == "reached"
            vals.append(s.state()["joints_deg"][e["driver"]])
        assert (vals[1] - vals[0]) * (vals[2] - vals[1]) < 0, (e["driver"], at, vals)  # an extremum: a dead point


def test_a_repeated_stop_is_logged_once_and_the_page_list_is_bounded():
    client = TestClient(sm.studio_app("five-cs-3"))
    a0 = client.get("/api/state").json()["state"]["actuators_deg"]["C1.rot"]
    for d in (120.0, 240.0):  # a drive takes the short way round: two requests
        assert client.post("/api/drive", json={"actuators": [a0 - d]}).json()["status"] == "reached"
    first = client.post("/api/drive", json={"actuators": [a0 - 250.0]}).json()
    assert first["status"] == "stopped_at_singularity"
    assert [e["name"] for e in first["events"]].count("DJ (drivers)") == 1
    for d in (251.0, 252.0, 253.0):
        again = client.post("/api/drive", json={"actuators": [a0 - d]}).json()
        assert again["status"] == "stopped_at_singularity" and again["events"] == []
        assert "same stop" in again["message"]
    assert client.post("/api/drive", json={"actuators": [a0 - 230.0]}).json()["status"] == "reached"
    back = client.post("/api/drive", json={"actuators": [a0 - 250.0]}).json()
    assert [e["name"] for e in back["events"]].count("DJ (drivers)") == 1  # a new approach is logged again
    assert EVENT_LOG_MAX == 100
    js = Path(sm.__path__[0]) / "interfaces" / "studio" / "static" / "studio.js"
    assert "EVENT_LOG_MAX = 100" in js.read_text()


def test_six_rus_pose_drag_shows_the_inverse_light_red_where_it_stops():
    client = TestClient(sm.studio_app(six_rus()))
    st = client.get("/api/state").json()["state"]
    J = sm.jacobian(six_rus(), config=sm.studio_session(six_rus()).config).jacobian
    assert st["transmission"] == pytest.approx(dict(zip(J.actuators, J.transmission, strict=True)), rel=1e-12)
    assert st["transmission_min"] == pytest.approx(min(J.transmission), rel=1e-12)
    assert not st["inverse_singular"]
    doc = None
    for z in np.arange(0.19, 0.10, -0.01):
        doc = client.post("/api/pose", json={"task_len": {"z": float(z)}}).json()
        if doc["status"] != "reached":
            break
    assert doc is not None and doc["status"] == "limb_singular"
    st = doc["state"]
    assert st["inverse_singular"] and st["transmission_min"] < INVERSE_SINGULAR
    assert st["transmission_min_actuator"] in doc["message"]
    assert st["sigma_min"] > NEAR_SINGULAR and not st["near_singular"]  # the direct light alone would be green


def test_a_pose_slice_of_a_six_rus_follows_the_given_working_mode():
    mech = six_rus()
    pose = ([0, 0, 0.2], ("ZYX", 0, 0, 0))
    a1, z = np.linspace(-90, 90, 13), np.linspace(0.12, 0.26, 8)
    res = sm.singularity_slice(mech, {"a1": a1, "z": z}, pose=pose, degrees=True)
    J = sm.jacobian(mech, pose, degrees=True)
    assert res.at_pose["det"] == pytest.approx(J.det, rel=1e-9)
    j, i = int(np.argmin(abs(z - 0.2))), int(np.argmin(abs(a1)))
    assert np.sign(res.det[j, i]) == np.sign(J.det)  # the grid point nearest the pose is on its branch
    assert res.branch is not None and res.branch[j, i] == FOLLOWED
    assert np.all(np.isfinite(res.det) == (res.branch == FOLLOWED))  # other branches and gaps are masked
    changes = 0
    for a, b in (((slice(None), slice(1, None)), (slice(None), slice(None, -1))),
                 ((slice(1, None), slice(None)), (slice(None, -1), slice(None)))):
        flip = np.isfinite(res.det[a]) & np.isfinite(res.det[b]) & (np.sign(res.det[a]) != np.sign(res.det[b]))
        assert np.all(res.branch[a][flip] == FOLLOWED) and np.all(res.branch[b][flip] == FOLLOWED)
        # a real zero between the two: one of them is close to singular (the false locus had 0.19)
        assert np.all(np.minimum(res.sigma_min[a], res.sigma_min[b])[flip] < 0.1)
        changes += int(flip.sum())
    assert changes > 0  # the slice does reach the direct-singularity locus near a1 = +-90 deg
    d = res.to_dict()
    assert d["at_pose"]["det"] == pytest.approx(J.det, rel=1e-9) and len(d["branch"]) == len(z)


def test_the_other_crank_solution_of_a_limb_has_another_mode_signature():
    """Limb 1 of the 6-RUS at the reference pose: of its other crank solutions (two U/S
    coordinate sets each), the one nearest the reference's coordinates (the one continuation
    would reach) has the other working-mode sign; the reference's own solutions keep it."""
    from spatialmech.kinematics.closure import Configuration, limb_slices

    mech = six_rus()
    ref = Configuration.reference(mech)
    ik = sm.ik(mech, ([0, 0, 0.2], ("ZYX", 0, 0, 0)), degrees=True, all_solutions=True)
    sl = limb_slices(mech)[0]

    def with_limb(sol):
        q = ref.q.copy()
        q[sl] = sol
        return ref.with_q(q)

    def distance(sol):
        d = np.asarray(sol) - ref.q[sl]
        return float(np.max(np.abs((d + np.pi) % (2 * np.pi) - np.pi)))

    sols = ik.result.limbs[0].solutions
    other = [s for s in sols if abs(((s[0] - ref.q[sl][0]) + np.pi) % (2 * np.pi) - np.pi) > 0.5]
    same = [s for s in sols if distance(s) < 1e-6]
    assert len(other) == 2 and same
    assert mode_signature(mech, with_limb(same[0])) == mode_signature(mech, ref)
    near = min(other, key=distance)
    assert mode_signature(mech, with_limb(near))[0] == -mode_signature(mech, ref)[0] != 0
    assert mode_signature(mech, with_limb(near))[1:] == mode_signature(mech, ref)[1:]


def test_ik_with_every_solution_answers_in_the_working_mode_nearest_the_start():
    """``sm.ik(..., all_solutions=True)`` answers (``actuators``, ``config``) with each limb's
    solution nearest the start (the reference), as ``sm.ik`` without it: the homotopy's path order
    is arbitrary, and limb 1 of the 6-RUS came back at its reference pose with the crank at
    120.9 deg while ``sm.jacobian`` used the reference's 0 deg.  From a start in limb 1's other
    crank mode, that mode comes first.  (After the test above: the limbs' generic solve is cached.)"""
    from spatialmech.kinematics.closure import Configuration, limb_slices
    from spatialmech.kinematics.position import inverse_position

    def wrapped(x):
        return np.angle(np.exp(1j * np.asarray(x)))

    mech = six_rus()
    for pose in (([0, 0, 0.2], ("ZYX", 0, 0, 0)), ([0.01, -0.005, 0.195], ("ZYX", 3.0, -2.0, 1.0))):
        one = sm.ik(mech, pose, degrees=True)
        every = sm.ik(mech, pose, degrees=True, all_solutions=True, certify=False)
        assert every.reachable and every.actuators == pytest.approx(one.actuators, abs=1e-9)
        assert max(abs(v) for v in every.actuators.values()) < np.radians(20)  # the other crank mode: > 100 deg
        for ls in every.result.limbs:
            far = [np.max(np.abs(wrapped(q))) for q in ls.solutions]
            assert len(far) == 4 and far[0] == min(far) < 0.35 < min(far[1:])  # a distinct nearest, first
        J = sm.jacobian(mech, pose, degrees=True)
        assert sm.jacobian(mech, config=every.config).det == pytest.approx(J.det, rel=1e-7)
    sols = every.result.limbs[0].solutions
    other = sols[int(np.argmax([abs(wrapped(q[0])) for q in sols]))]  # crank 112.8 deg
    q = every.config.q.copy()
    q[limb_slices(mech)[0]] = other
    P = every.result.pose
    start = Configuration(q, P.displacement(mech.platform_point), every.config.B)
    res = inverse_position(mech, P, all_solutions=True, start=start)
    assert np.max(np.abs(wrapped(res.limbs[0].solutions[0] - other))) < 1e-7
