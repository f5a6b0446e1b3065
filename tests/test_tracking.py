"""The continuation tracker: closure of loops, branch safety, events, mechanism motions."""

import numpy as np
import pytest

from spatialmech import catalog
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.backend import closure_residual
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.jacobian import complete_jacobian
from spatialmech.kinematics.position import freedom_values
from spatialmech.kinematics.forward import forward_position
from spatialmech.kinematics.tracking import ActuatorPathProblem, EuclideanProblem, track, trace_motion


def circle():
    return EuclideanProblem(lambda x: np.array([x @ x - 1.0]), lambda x: 2 * x[None, :])


def test_circle_closes_on_its_start_point():
    r = track(circle(), np.array([1.0, 0.0]))
    assert r.closed and r.status == "closed"
    assert np.allclose(r.points[-1], [1.0, 0.0], atol=1e-8)
    assert r.s[-1] == pytest.approx(2 * np.pi, rel=0.01)  # arc length summed over chords
    assert max(abs(np.linalg.norm(p) - 1) for p in r.points) < 1e-10


@pytest.mark.parametrize("eps", [1e-2, 1e-4, 1e-6])
def test_tracking_never_silently_changes_branch(eps):
    """x^2 - y^2 = eps: two branches that nearly touch at the origin.  With large steps a
    naive tracker runs straight along the asymptote onto the other branch; this one must stay
    on x > 0 (the orientation of the augmented Jacobian would flip on a jump)."""
    P = EuclideanProblem(lambda x: np.array([x[0] ** 2 - x[1] ** 2 - eps]), lambda x: np.array([[2 * x[0], -2 * x[1]]]))
    x0 = np.array([np.sqrt(4 + eps), -2.0])
    r = track(P, x0, direction=np.array([0.0, 1.0]), h0=0.3, h_max=0.5, max_arc=8, detect_closure=False)
    xs = np.array(r.points)
    assert r.ok
    assert xs[:, 0].min() > 0
    assert xs[-1, 1] > 1.5  # it went round the turn, on its own branch


def test_events_are_located_precisely():
    # monitor y on the unit circle: zeros at (-1, 0) (and the start, excluded)
    r = track(circle(), np.array([1.0, 0.0]), monitors={"y": lambda x: x[1]}, event_tol=1e-12)
    ev = [e for e in r.events if e.name == "y"]
    assert len(ev) == 1
    assert np.allclose(ev[0].x, [-1.0, 0.0], atol=1e-9)
    assert ev[0].s == pytest.approx(np.pi, rel=0.01)


def test_planar_four_bar_crank_turns_fully_rocker_oscillates():
    m = catalog.build("planar-4r")
    r = trace_motion(m, Configuration.reference(m), increasing="A0")
    assert r.closed
    q = np.array([c.q for c in r.points])
    i_crank = [f.id for f in m.freedom_refs].index("A0.rot")
    i_rocker = [f.id for f in m.freedom_refs].index("B0.rot")
    assert q[:, i_crank].max() - q[:, i_crank].min() == pytest.approx(2 * np.pi, abs=1e-6)
    assert 0.1 < q[:, i_rocker].max() - q[:, i_rocker].min() < np.pi
    assert max(np.linalg.norm(closure_residual(m, c)) for c in r.points) < 1e-9


@pytest.mark.parametrize("name, driver", [("rssr", "A0"), pytest.param("bennett", "J1", marks=pytest.mark.slow),
                                          pytest.param("five-cs-2", "rot1", marks=pytest.mark.slow)])
def test_mechanism_circuits_close(name, driver):
    m = catalog.build(name)
    r = trace_motion(m, Configuration.reference(m), increasing=driver, max_arc=200)
    assert r.status == "closed", r.status
    end = r.points[-1]
    assert np.allclose(end.D, np.eye(4), atol=1e-7)
    assert max(np.linalg.norm(closure_residual(m, c)) for c in r.points[::5]) < 1e-8 * m.characteristic_length


@pytest.mark.slow
def test_dj_events_along_linkage2_match_sign_changes():
    m = catalog.build("five-cs-2")
    def dj(c):
        return complete_jacobian(m, c, ["rot1"]).det
    r = trace_motion(m, Configuration.reference(m), increasing="rot1", monitors={"rot1": dj})
    signs = np.sign(r.monitors["rot1"])
    assert len(r.events) == int(np.sum(signs[1:] != signs[:-1]))
    for e in r.events:
        J = complete_jacobian(m, e.x, ["rot1"])
        assert J.sigma_min < 1e-6  # located on the singularity


def test_forward_position_by_continuation_along_actuator_path():
    m = catalog.build("stewart-6sps")
    target = generic_configuration(m, seed=7, step=0.3)
    vals = freedom_values(m, target.q)
    idx = [[f.id for f in m.freedom_refs].index(a) for a in m.actuators]
    a0 = freedom_values(m, np.zeros(len(target.q)))[idx]
    a1 = vals[idx]
    prob = ActuatorPathProblem(m, lambda lam: a0 + lam * (a1 - a0), lambda lam: a1 - a0)
    r = track(prob, (Configuration.reference(m), 0.0), direction=np.r_[np.zeros(prob.na + 6), 1.0],
              stop=lambda x, s: x[1] >= 1.0, detect_closure=False, max_arc=20)
    assert r.status == "stopped"
    # finish exactly at lam = 1 by Newton from the last point
    last = r.points[-1][0]
    fk = forward_position(m, a1, start=last)
    assert fk.converged
    assert np.allclose(fk.solutions[0].config.D, target.D, atol=1e-8)


@pytest.mark.slow
def test_tracking_benchmark_smoke():
    import runpy
    from pathlib import Path

    bench = runpy.run_path(str(Path(__file__).parent.parent / "benchmarks" / "bench_tracking.py"))
    out = bench["main"](["--quick", "--json"])
    assert out["scipy_root_ok"] and out["dj_evaluations_per_s"] > 0 and out["tracker_path_status"] == "stopped"


@pytest.mark.slow
def test_linkage3_near_singular_stretch_is_crossed_without_jumps():
    """Between P3 and P4 linkage 3 passes close to a singularity (sigma ~ 4e-4): with large steps
    allowed, consecutive tracked points stay close (no jump to another branch) and the circuit
    still closes on its start."""
    m = catalog.build("five-cs-3")
    r = trace_motion(m, Configuration.reference(m), increasing="rot1", h_max=0.5, max_arc=400)
    assert r.closed
    pts = np.array([c.D[:3, :3] @ m.platform_point + c.D[:3, 3] for c in r.points])
    steps = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    ds = np.diff(r.s)
    assert np.all(steps <= 3 * m.characteristic_length * ds + 1e-9)  # the platform point moves with the arc
