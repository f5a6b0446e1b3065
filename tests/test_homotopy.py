"""Forward position of 6-leg S-P-S platforms by homotopy continuation (issue 13)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.spatial.transform import Rotation

import spatialmech as sm
from spatialmech import catalog
from spatialmech.interfaces.cli import cli as main
from spatialmech.kinematics.homotopy import study as hc
from spatialmech.kinematics.forward import forward_position


def _lengths(sysm, R, p):
    return np.linalg.norm((R @ sysm.platform.T).T + p - sysm.base, axis=1)


@pytest.fixture(scope="module", autouse=True)
def phc_runs(tmp_path_factory):
    """PHCpack's blackbox solves for the two cross-checks below (10-25 s each), started when this
    module starts, so that they run on the other core while the module's other tests compute."""
    if shutil.which("phc") is None:
        yield {}
        return
    d = tmp_path_factory.mktemp("phc")
    cases = {"stewart-6sps": (hc.stewart_system(catalog.resolve("stewart-6sps")), [1.2] * 6),
             "three-rps": (hc.pose_system(catalog.resolve("three-rps")), [0.34, 0.36, 0.32])}
    jobs = {}
    for name, (sysm, vals) in cases.items():
        (d / f"{name}.in").write_text(hc.phc_input(sysm, vals, np.random.default_rng(3).normal(size=8)))
        jobs[name] = (subprocess.Popen(["phc", "-b", str(d / f"{name}.in"), str(d / f"{name}.out")],
                                       stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                       stderr=subprocess.DEVNULL), d / f"{name}.out")
    yield jobs
    for proc, _ in jobs.values():
        if proc.poll() is None:
            proc.kill()


def _phc_output(jobs, name: str) -> str:
    proc, out = jobs[name]
    assert proc.wait(timeout=300) == 0, f"phc -b failed on {name}"
    return out.read_text()


@pytest.fixture(scope="module")
def general():
    """A general 6-6 geometry and a real pose of it (its leg lengths)."""
    rng = np.random.default_rng(11)
    sysm = hc.system_from_points(rng.normal(size=(6, 3)), rng.normal(size=(6, 3)) * 0.7 + [0, 0, 1.5])
    R = Rotation.from_rotvec([0.2, -0.1, 0.3]).as_matrix()
    p = np.array([0.1, -0.05, 0.2])
    lengths = _lengths(sysm, R, p)
    return sysm, R, p, lengths, hc.homotopy_forward(sysm, lengths)


def test_general_6_6_has_40_solutions_proven(general):
    r = general[4]
    assert r.complete and "every path accounted for" in r.completeness
    assert r.n_generic == 40 and len(r.solutions) == 40
    assert r.count("at_infinity") + r.count("singular") == 0
    assert r.count("real") + r.count("complex") == 40
    assert r.count("real") % 2 == 0  # complex solutions come in conjugate pairs


def test_every_real_solution_closes_and_the_pose_is_among_them(general):
    sysm, R, p, lengths, r = general
    real = [s for s in r.solutions if s.status == "real"]
    assert real
    for s in real:  # closure residual of each real solution (leg lengths round trip)
        assert np.allclose(_lengths(sysm, s.R, s.p), lengths, atol=1e-9)
        assert np.allclose(s.R @ s.R.T, np.eye(3), atol=1e-10)
    assert min(np.linalg.norm(s.p - p) + np.linalg.norm(s.R - R) for s in real) < 1e-8


def test_parameter_homotopy_resolve_is_cached_and_consistent(general):
    """The re-solve reuses the cached generic solve; how fast it is: benchmarks/bench_homotopy.py
    (``resolve_median_ms``, target 50 ms, and ``resolve_speedup`` over the first solve)."""
    sysm, lengths = general[0], general[3]
    r2 = hc.homotopy_forward(sysm, lengths * 1.03)
    assert r2.cached and r2.complete
    for s in r2.solutions:
        if s.status == "real":
            assert np.allclose(_lengths(sysm, s.R, s.p), lengths * 1.03, atol=1e-9)


def test_study_parameters_round_trip():
    R = Rotation.from_rotvec([0.3, 0.2, -0.4]).as_matrix()
    p = np.array([0.3, -0.2, 0.5])
    q = Rotation.from_matrix(R).as_quat()
    e = np.r_[q[3], q[:3]]
    g = np.array([-p @ e[1:], *(p * e[0] + np.cross(p, e[1:]))]) / 2  # (0, p) e / 2
    R2, p2 = hc.study_to_pose(np.r_[e, g] * 3.7)  # projective: any scale
    assert np.allclose(R2, R) and np.allclose(p2, p)


@pytest.fixture(scope="module")
def stewart():
    mech = catalog.resolve("stewart-6sps")
    return mech, forward_position(mech, [1.2] * 6, all_solutions=True, method="homotopy")


def test_stewart_model_superset_of_multistart_and_verified(stewart):
    mech, res = stewart
    ms = forward_position(mech, [1.2] * 6, all_solutions=True, n_seeds=30)
    assert res.search["complete"] and res.search["n_real"] >= len(res.solutions)
    for s in res.solutions:  # each real mode: closed, actuators held, inverse position round trip
        assert s.converged and s.residual < 1e-10
        ik = sm.ik(mech, s.pose)
        assert ik.reachable
    keys = [np.r_[s.pose.p, s.pose.R.ravel()] for s in res.solutions]
    for m in ms.solutions:
        if m.converged:
            k = np.r_[m.pose.p, m.pose.R.ravel()]
            assert min(np.linalg.norm(k - x) for x in keys) < 1e-6, "multi-start found a mode homotopy missed"


def test_cli_json_and_text(stewart):
    runner = CliRunner()
    out = runner.invoke(main, ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all", "--json"])
    assert out.exit_code == 0, out.output
    d = json.loads(out.output)
    assert d["complete"] is True and d["n_real"] + d["n_complex"] + d["n_singular"] + d["n_at_infinity"] == len(d["endpoints"])
    assert {e["status"] for e in d["endpoints"]} <= {"real", "complex", "singular", "at_infinity"}
    txt = runner.invoke(main, ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all"])
    assert "complete (proven)" in txt.output
    ms = runner.invoke(main, ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all", "--method",
                              "multistart", "--seeds", "4", "--json"])
    assert json.loads(ms.output)["complete"] is False


def test_uncovered_model_clear_message():
    runner = CliRunner()
    out = runner.invoke(main, ["fk", "three-sps-smpu", "--actuators", "0.5,0.5,0.5", "--all", "--method", "homotopy"])
    assert out.exit_code != 0 and "does not cover three-sps-smpu" in out.output and "S joints B1, A1" in out.output
    assert "Traceback" not in out.output
    with pytest.raises(sm.InputError, match="method"):
        sm.fk("stewart-6sps", [1.2] * 6, all_solutions=True, method="newton")


@pytest.mark.parametrize("phi", [[0.12, 0.2, -0.1, 0.6], [0.15, -0.3, 0.2, -0.4]])
def test_four_sps_cu_agrees_with_the_closed_form(phi):
    from spatialmech.kinematics.closed_forms import four_sps_cu as k4
    from spatialmech.kinematics.closed_forms import four_sps_cu_forward as k4f

    mech = catalog.resolve("four-sps-cu")
    legs = k4.leg_lengths(phi)
    closed = k4f.forward_all(np.asarray(legs), geometry=k4.geometry_of(mech))
    res = forward_position(mech, legs, all_solutions=True, method="homotopy")
    assert res.search["complete"] and res.search["n_generic"] == res.search["n_real"] + res.search["n_complex"]
    assert len(res.solutions) == len(closed.solutions) > 0
    for s in closed.solutions:  # every real assembly mode of the closed form: same height, same rotation
        assert min(abs(h.pose.p[2] - s.phi[0]) + np.linalg.norm(h.pose.R - s.rotation) for h in res.solutions) < 1e-6


def test_three_rps_has_16_solutions_and_every_multistart_mode():
    mech = catalog.resolve("three-rps")
    legs = [0.34, 0.36, 0.32]
    res = forward_position(mech, legs, all_solutions=True, method="homotopy")
    assert res.search["complete"] and res.search["n_generic"] == 16  # the known count of the 3-RPS
    assert len(res.solutions) == res.search["n_real"] and all(s.residual < 1e-10 for s in res.solutions)
    ms = forward_position(mech, legs, all_solutions=True, n_seeds=40)
    for m in ms.solutions:
        assert min(np.linalg.norm(m.pose.p - h.pose.p) + np.linalg.norm(m.pose.R - h.pose.R) for h in res.solutions) < 1e-6


def test_homotopy_benchmark_runs_and_reports_its_targets():
    """benchmarks/bench_homotopy.py --quick: one case, a verdict per target."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_homotopy.py"
    spec = importlib.util.spec_from_file_location("bench_homotopy", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = bench.main(["--quick", "--json"])
    (c,) = out["cases"]
    assert c["complete"] and c["n_generic"] == 28 and c["first_solve_s"] > 0 and c["resolve_median_ms"] > 0
    assert isinstance(c["first_met"], bool) and isinstance(c["resolve_met"], bool)
    assert c["resolve_cached"] is True and isinstance(c["resolve_speedup"], float)


@pytest.mark.parametrize("name", ["stewart-6sps", "four-sps-cu"])
def test_compiled_parameter_tracker_equals_the_numpy_reference(name):
    """The compiled path-by-path parameter homotopy ends where the batched NumPy tracker does:
    the same end points (every complex one, to 1e-8) and the same statuses."""
    from spatialmech.kinematics import backend

    mech = catalog.resolve(name)
    sysm = hc.stewart_system(mech)
    vals = [1.21, 1.19, 1.2, 1.22, 1.18, 1.2] if name == "stewart-6sps" else [0.25, 0.24, 0.26, 0.245]
    fast = hc.homotopy_forward(sysm, vals)
    with backend.python_reference():
        ref = hc.homotopy_forward(sysm, vals)
    assert [s.status for s in fast.solutions] == [s.status for s in ref.solutions]
    for a, b in zip(fast.solutions, ref.solutions, strict=True):
        if a.status != "at_infinity":
            ya, yb = a.study / np.linalg.norm(a.study), b.study / np.linalg.norm(b.study)
            assert min(np.linalg.norm(ya - yb * ph) for ph in (1, -1)) < 1e-8


def test_a_continuum_is_reported_as_one_self_motion_set_not_as_points():
    """At the 4-SPS/CU's home leg lengths the platform has a self-motion: the homotopy's end
    points there are singular, so completeness is not claimed, and the result is one
    self-motion set (as the closed form says), not a scatter of singular points."""
    from spatialmech.kinematics.assembly import AssemblyKind
    from spatialmech.kinematics.closed_forms import four_sps_cu_forward as k4f

    mech = catalog.resolve("four-sps-cu")
    legs = [float(np.sqrt(0.06))] * 4
    res = forward_position(mech, legs, all_solutions=True, method="homotopy", n_seeds=16)
    assert res.search["complete"] is False and res.search["n_singular"] > 0
    assert "self-motion" in res.search["completeness"]
    kinds = [s.kind for s in res.solutions]
    closed = k4f.forward_all(np.array(legs))
    assert kinds.count(AssemblyKind.SELF_MOTION) == 1 == len(closed.solutions)


# ------------------------------------------------------------------ limbs reduced with the actuators given (issue 13, part 2)
def _same_pose(a, b) -> float:
    return float(np.linalg.norm(a.pose.p - b.pose.p) + np.linalg.norm(a.pose.R - b.pose.R))


@pytest.mark.parametrize(("name", "vals", "n_generic"), [
    ("three-prs", [0.02, -0.01, 0.03], 16),  # the published count of the 3-PRS (as the 3-RPS)
    ("three-upu", [0.37, 0.36, 0.35], None),
    ("delta", [0.1, 0.2, -0.1], 40),
])
def test_new_limb_types_are_proven_complete_and_contain_the_multistart(name, vals, n_generic):
    """P-R-S, U-P-U and S-S rods from driven arms: every real end point polishes to a closed
    assembly with the actuators held, and every mode the multi-start finds is among them."""
    mech = catalog.resolve(name)
    assert hc.unsupported_reason(mech) is None
    res = forward_position(mech, vals, all_solutions=True, method="homotopy")
    s = res.search
    assert s["complete"] and s["n_singular"] == 0
    if n_generic is not None:
        assert s["n_generic"] == n_generic
    assert s["n_real"] + s["n_complex"] + s["n_at_infinity"] == s["n_generic"]
    assert len(res.solutions) == s["n_real"] and all(x.converged and x.residual < 1e-10 for x in res.solutions)
    for x in res.solutions:
        q = forward_position(mech, vals, start=x.config)  # the polished pose is a root with the actuators held
        assert _same_pose(q.solutions[0], x) < 1e-8
    ms = forward_position(mech, vals, all_solutions=True, method="multistart", n_seeds=12)
    for m in ms.solutions:
        assert min(_same_pose(m, h) for h in res.solutions) < 1e-6, "multi-start found a mode homotopy missed"


def test_delta_two_translational_modes_among_the_40():
    """The Delta's six S-S rods from the driven arms: 40 generic complex solutions; the two
    translational assembly modes (the published count) are among the real ones."""
    sysm = hc.pose_system(catalog.resolve("delta"))
    assert isinstance(sysm, hc.PoseSystem) and len(sysm.affine_span()[1]) == 6  # (cos, sin) of each arm
    for vals in ([0.1, 0.2, -0.1], [0.3, -0.2, 0.5]):
        r = hc.homotopy_forward(sysm, vals)
        assert r.complete and r.n_generic == 40
        rot = [np.linalg.norm(s.R - np.eye(3)) for s in r.solutions if s.status == "real"]
        assert sum(d < 1e-8 for d in rot) == 2


def test_reduced_quadrics_vanish_on_closed_configurations():
    """Each limb's quadrics hold at assembled configurations away from the reference (random
    walks along the closure manifold), with the actuator values read from them."""
    from spatialmech.kinematics.motion import generic_configuration

    for name in ("three-prs", "three-upu", "delta"):
        mech = catalog.resolve(name)
        sysm = hc.pose_system(mech)
        for k in range(2):
            cfg = generic_configuration(mech, seed=k, step=0.5, steps=3)
            vals = [cfg.q[mech.freedom_refs.index(mech.freedom(a))] + mech.freedom(a).freedom.offset for a in mech.actuators]
            D = cfg.D
            q = Rotation.from_matrix(D[:3, :3]).as_quat()
            e = np.r_[q[3], q[:3]]
            p = D[:3, 3] / sysm.L
            g = np.array([-p @ e[1:], *(p * e[0] + np.cross(p, e[1:]))]) / 2
            x = np.r_[e, g]
            Qv = sysm.coefficients(vals)
            assert max(abs(x @ Qv[i] @ x) for i in range(7)) < 1e-9, name


def test_compiled_coefficient_tracker_equals_the_numpy_reference_on_the_delta():
    from spatialmech.kinematics import backend

    sysm = hc.pose_system(catalog.resolve("delta"))
    fast = hc.homotopy_forward(sysm, [0.3, -0.2, 0.5])
    with backend.python_reference():
        ref = hc.homotopy_forward(sysm, [0.3, -0.2, 0.5])
    assert [s.status for s in fast.solutions] == [s.status for s in ref.solutions]
    for a, b in zip(fast.solutions, ref.solutions, strict=True):
        if a.status != "at_infinity":
            ya, yb = a.study / np.linalg.norm(a.study), b.study / np.linalg.norm(b.study)
            assert min(np.linalg.norm(ya - yb * ph) for ph in (1, -1)) < 1e-8


#: Dietmaier's platform with 40 real forward solutions (Advances in Robot Kinematics 1998, pp. 7-16),
#: to the six digits published: base points, platform points (platform frame), leg lengths [m].
DIETMAIER_BASE = [[0, 0, 0], [1.107915, 0, 0], [0.549094, 0.756063, 0], [0.735077, -0.223935, 0.525991],
                  [0.514188, -0.526063, -0.368418], [0.590473, 0.094733, -0.205018]]
DIETMAIER_PLATFORM = [[0, 0, 0], [0.542805, 0, 0], [0.956919, -0.528915, 0], [0.665885, -0.353482, 1.402538],
                      [0.478359, 1.158742, 0.107672], [-0.137087, -0.235121, 0.353913]]
DIETMAIER_LEGS = [1.0, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071]


def test_dietmaier_platform_has_all_40_solutions_real_and_proven_complete():
    """Issue 13's check: a 6-6 platform with all 40 forward solutions real (Dietmaier's).  The
    homotopy finds 40, all real and distinct, every one closing the six legs, the set complete;
    examples/stewart_dietmaier.py gets the same through ``sm.fk`` on the mechanism built from the
    points."""
    a, b, legs = np.array(DIETMAIER_BASE), np.array(DIETMAIER_PLATFORM), np.array(DIETMAIER_LEGS)
    r = hc.homotopy_forward(hc.system_from_points(a, b), legs)
    assert r.complete and r.n_generic == 40 and len(r.solutions) == 40
    assert r.count("real") == 40
    for s in r.solutions:
        assert np.abs(np.linalg.norm((s.R @ b.T).T + s.p - a, axis=1) - legs).max() < 1e-9
    poses = np.array([np.r_[s.R.ravel(), s.p] for s in r.solutions])
    gaps = np.linalg.norm(poses[:, None] - poses[None], axis=2) + np.eye(40)
    assert gaps.min() > 1e-4  # 40 distinct postures, not a multiple root counted twice


@pytest.mark.slow
def test_geometry_family_resolve_matches_a_fresh_solve():
    """The parameter homotopy in a 96-dimensional coefficient space (the 42 geometry numbers of
    a 6-6 platform, benchmarks/bench_all_real.py): moving to a new geometry gives the 40
    solutions and the same real poses as a fresh total-degree solve of that platform."""
    rng = np.random.default_rng(5)
    a, b = rng.normal(size=(6, 3)), rng.normal(size=(6, 3)) * 0.7 + [0, 0, 1.5]
    fam = hc.geometry_family(a, b)
    assert len(fam.affine_span()[1]) > 42  # products of base and platform coordinates: not the actuator count
    a2, b2 = a + 0.2 * rng.normal(size=(6, 3)), b + 0.2 * rng.normal(size=(6, 3))
    legs = np.linalg.norm(b2 - a2, axis=1) * 1.02
    r = hc.homotopy_forward(fam, np.r_[a2.ravel(), b2.ravel(), legs])
    fresh = hc.homotopy_forward(hc.system_from_points(a2, b2, d_ref=legs, sign=np.ones(6), offset=legs.copy()), legs, seed=3)
    assert r.complete and fresh.complete and r.n_generic == fresh.n_generic == 40
    mine = sorted(tuple(np.round(s.p, 6)) for s in r.solutions if s.status == "real")
    theirs = sorted(tuple(np.round(s.p, 6)) for s in fresh.solutions if s.status == "real")
    assert len(mine) == len(theirs) > 0
    assert np.allclose(np.array(mine), np.array(theirs), atol=1e-5)


def test_a_user_6_rss_with_driven_cranks_is_covered():
    """A user's 6-RSS (actuated base revolutes, S-S rods): each limb a sphere about its crank's
    moving elbow; proven complete (40 generic) and containing every multi-start mode."""
    from spatialmech.model.joints import R, S
    from spatialmech.model.mechanism import Limb, Mechanism

    limbs = []
    for i in range(6):
        ang = 2 * np.pi * i / 6 + (0.3 if i % 2 else -0.3)
        base = np.array([0.3 * np.cos(ang), 0.3 * np.sin(ang), 0.0])
        pang = 2 * np.pi * i / 6 + (0.4 if i % 2 else -0.4)
        wrist = [0.12 * np.cos(pang), 0.12 * np.sin(pang), -0.35]
        limbs.append(Limb(f"leg{i + 1}", (R(f"R{i + 1}", base, [-np.sin(ang), np.cos(ang), 0.0], actuated=True),
                                          S(f"E{i + 1}", base * 1.4), S(f"W{i + 1}", wrist))))
    mech = Mechanism("six-rss", tuple(limbs), platform_point=[0, 0, -0.35])
    vals = [0.1, -0.05, 0.08, 0.0, -0.1, 0.05]
    res = forward_position(mech, vals, all_solutions=True, method="homotopy")
    s = res.search
    assert s["complete"] and s["n_generic"] == 40 and len(res.solutions) == s["n_real"] > 0
    assert all(x.residual < 1e-10 for x in res.solutions)
    ms = forward_position(mech, vals, all_solutions=True, method="multistart", n_seeds=10)
    for m in ms.solutions:
        assert min(_same_pose(m, h) for h in res.solutions) < 1e-6


# ------------------------------------------------------------------ end game at singular end points
def test_a_double_root_is_located_by_the_cauchy_end_game_and_proven_complete(general):
    """At leg lengths of a forward-singular pose two assembly modes merge: two paths end at one
    double root, where Newton cannot finish them. The Cauchy end game locates it (both loops
    close after two turns: winding number 2), the local dimension test finds it isolated, and the
    set is complete with the root counted twice; the pose comes back to rounding."""
    from scipy.optimize import brentq

    sysm = general[0]

    def pose(s):
        R = Rotation.from_rotvec(np.array([0.2, -0.1, 0.3]) * (1 + s)).as_matrix()
        return R, np.array([0.1, -0.05, 0.2]) + s * np.array([0.3, 0.2, 0.4])

    def det(s):  # the leg lines' determinant (forward singularity)
        R, p = pose(s)
        a = (R @ sysm.platform.T).T + p
        u = (a - sysm.base) / np.linalg.norm(a - sysm.base, axis=1, keepdims=True)
        return np.linalg.det(np.hstack([u, np.cross(a, u)]))

    s0 = brentq(det, 2.3, 2.5, xtol=1e-16, rtol=8.9e-16)
    R, p = pose(s0)
    r = hc.homotopy_forward(sysm, _lengths(sysm, R, p))
    sing = [s for s in r.solutions if s.status == "singular"]
    assert r.complete and "Cauchy end game" in r.completeness and "isolated" in r.completeness
    assert len(sing) == 2 and all(s.multiplicity == 2 and s.winding == 2 for s in sing)
    assert r.count("real") + r.count("complex") + 2 == 40
    for s in sing:
        assert np.linalg.norm(s.R - R) + np.linalg.norm(s.p - p) < 1e-9
        assert s.to_dict()["multiplicity"] == 2 and s.to_dict()["winding_number"] == 2


def test_local_dimension_tells_a_multiple_root_from_a_continuum():
    from spatialmech.kinematics.homotopy.endgame import local_dimension

    def ev(F):
        def evaluate(Y):
            return F(Y[0])[0][None], F(Y[0])[1][None]
        return evaluate

    double = ev(lambda v: (np.array([v[0] ** 2, v[1]]), np.array([[2 * v[0], 0], [0, 1]], dtype=complex)))
    line = ev(lambda v: (np.array([(v[0] - v[1]) * v[0], (v[0] - v[1]) * v[1]]),
                         np.array([[2 * v[0] - v[1], -v[0]], [v[1], v[0] - 2 * v[1]]], dtype=complex)))
    assert local_dimension(double, np.array([0.0, 0.0], dtype=complex)) == 0
    assert local_dimension(line, np.array([0.5, 0.5], dtype=complex)) == 1


# ------------------------------------------------------------------ PHCpack cross-checks (last: solves start with the module)
@pytest.mark.skipif(shutil.which("phc") is None, reason="PHCpack (Debian phcpack) not installed")
def test_phcpack_agrees_on_the_stewart_model(stewart, phc_runs):
    """Independent check: PHCpack's blackbox solver on the same system finds the same number of
    regular solutions and the same real ones (about 13 s, started with the module)."""
    mech, res = stewart
    sysm = hc.stewart_system(mech)
    out = _phc_output(phc_runs, "stewart-6sps")
    n_regular = int(re.findall(r"Number of regular solutions\s*:\s*(\d+)", out)[-1])
    assert n_regular == res.search["n_generic"] == res.search["n_real"] + res.search["n_complex"]
    phc_real = []
    for block in out[out.rfind("THE SOLUTIONS"):].split("solution ")[1:]:
        vals = {k: complex(float(x), float(y)) for k, x, y in re.findall(r"\b([eg]\d) :\s+(\S+)\s+(\S+)", block)}
        if len(vals) == 8 and "real regular" in block:
            phc_real.append(hc.study_to_pose(np.array([vals[k] for k in sorted(vals)]).real, sysm.L)[1])
    assert len(phc_real) == res.search["n_real"]
    ours = [s.config.D[:3, 3] for s in res.solutions]
    for p in phc_real:
        assert min(np.linalg.norm(p - q) for q in ours) < 1e-6


@pytest.mark.skipif(shutil.which("phc") is None, reason="PHCpack (Debian's phcpack) is not installed")
def test_phcpack_agrees_on_the_three_rps(phc_runs):
    """Second independent check (about 23 s of PHCpack's blackbox, started with the module): the
    3-RPS at legs (0.34, 0.36, 0.32) m, PHCpack and ours: 16 regular solutions, the same real
    ones."""
    mech = catalog.resolve("three-rps")
    legs = [0.34, 0.36, 0.32]
    sysm = hc.pose_system(mech)
    ours = hc.homotopy_forward(sysm, legs)
    out = _phc_output(phc_runs, "three-rps")
    assert int(re.findall(r"Number of regular solutions\s*:\s*(\d+)", out)[-1]) == ours.n_generic == 16
    phc_real = []
    for block in out[out.rfind("THE SOLUTIONS"):].split("solution ")[1:]:
        vals = {k: complex(float(x), float(y)) for k, x, y in re.findall(r"\b([eg]\d) :\s+(\S+)\s+(\S+)", block)}
        if len(vals) == 8 and "real regular" in block:
            phc_real.append(hc.study_to_pose(np.array([vals[k] for k in sorted(vals)]).real, sysm.L)[1])
    mine = [s.p for s in ours.solutions if s.status == "real"]
    assert len(phc_real) == len(mine) > 0
    for p in phc_real:
        assert min(np.linalg.norm(p - q) for q in mine) < 1e-6
