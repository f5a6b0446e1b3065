"""Workspace under joint limits (paper B section 6, eqs 16-22): the pose-check kernels, the
sampled + bisection-refined extents, the volume, active limits, plots, the CLI and the benchmark.

Tolerances: extents are refined to the requested ``tol`` (1e-3 deg unless stated) and are
compared with closed forms to that tolerance; kernels agree with independent computations to
1e-12 (m or rad).
"""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize

from spatialmech import catalog
from spatialmech.analysis.workspace import (
    ConeLimit,
    WorkspaceLimits,
    orientation_workspace,
    paper_b_limits,
    pose_checker,
    position_workspace,
    segment_distance,
)
from spatialmech.geometry.rotations import euler_matrix
from spatialmech.interfaces.cmd_workspace import parse_at, workspace
from spatialmech.kinematics.closed_forms import four_sps_cu as k4

A, B = k4.PAPER_B.a, k4.PAPER_B.b
L_MAX = k4.PAPER_B.leg_limits[1]
TOL_DEG = 1e-3
MECH = catalog.build("four-sps-cu")


def gamma_leg_limit(z):
    """gamma alone (alpha = beta = 0): every leg has l^2 = 2a^2 + 2b^2 + z^2 - 4ab cos(gamma)."""
    return np.arccos((2 * A * A + 2 * B * B + z * z - L_MAX**2) / (4 * A * B))


@pytest.fixture(scope="module")
def ws_z01():
    return orientation_workspace(MECH, at={"z": 0.1}, limits=paper_b_limits(), step=np.radians(5))


def poses(ang, z=0.1):
    """(R, p) of angles (n, 3) ordered (alpha, beta, gamma), R = Rz(gamma) Ry(beta) Rx(alpha)."""
    ang = np.atleast_2d(ang)
    return euler_matrix("ZYX", ang[:, [2, 1, 0]]), np.tile([0.0, 0.0, z], (ang.shape[0], 1))


# ------------------------------------------------------------------ paper B, section 6
@pytest.mark.slow
def test_paper_b_alpha_beta_alone_are_the_platform_cone_atan_z_over_b(ws_z01):
    """Claim checked against the closed form: alpha, beta alone in +-atan(z/b) = +-26.565 deg,
    the platform-side spherical cone (eq 18) active.  The paper's 48 deg does NOT reproduce."""
    exact = np.degrees(np.arctan(0.1 / B))
    assert abs(exact - 26.56505) < 1e-5
    for c in ("alpha", "beta"):
        e = ws_z01.alone[c]
        assert abs(np.degrees(e.hi) - exact) <= TOL_DEG and abs(np.degrees(e.lo) + exact) <= TOL_DEG
        assert e.lo_limit.endswith(" cone") and e.lo_limit.startswith("A")
        assert e.hi_limit.endswith(" cone") and e.hi_limit.startswith("A")
    assert abs(exact - 48.0) > 20  # the printed alpha_max = 48 deg is far from the model


@pytest.mark.slow
def test_paper_b_gamma_alone_is_the_maximum_leg_length(ws_z01):
    """gamma alone in +-128.682 deg (leg length 0.4 m active); the paper's 65 deg does NOT reproduce."""
    exact = np.degrees(gamma_leg_limit(0.1))
    assert abs(exact - 128.68219) < 1e-4
    e = ws_z01.alone["gamma"]
    assert abs(np.degrees(e.hi) - exact) <= TOL_DEG and abs(np.degrees(e.lo) + exact) <= TOL_DEG
    assert e.lo_limit.endswith(".slide max") and e.hi_limit.endswith(".slide max")
    assert e.hi_limit.startswith("L")


@pytest.mark.slow
def test_paper_b_section6_extents_are_not_48_48_65_deg(ws_z01):
    """NOT reproduced (section 6, fig 5): at z = 0.1 m the paper prints alpha_max = beta_max =
    48 deg and gamma_max = 65 deg; the stated model gives +-atan(z/b) = 26.565 deg for alpha and
    beta alone and +-128.682 deg for gamma alone (closed forms), none within 20 deg of the print."""
    closed = {"alpha": np.degrees(np.arctan(0.1 / B)), "beta": np.degrees(np.arctan(0.1 / B)),
              "gamma": np.degrees(gamma_leg_limit(0.1))}
    printed = {"alpha": 48.0, "beta": 48.0, "gamma": 65.0}
    for c, exact in closed.items():
        e = ws_z01.alone[c]
        assert abs(np.degrees(e.hi) - exact) <= TOL_DEG and abs(np.degrees(e.lo) + exact) <= TOL_DEG, c
        assert abs(np.degrees(e.hi) - printed[c]) > 20, c


@pytest.mark.slow
def test_paper_b_whole_set_has_the_same_extents(ws_z01):
    """Over the whole 3-D set the extents equal the single-angle ones (conventions.md)."""
    for c in ("alpha", "beta", "gamma"):
        a, s = ws_z01.alone[c], ws_z01.extents[c]
        assert abs(s.lo - a.lo) <= np.radians(TOL_DEG) and abs(s.hi - a.hi) <= np.radians(TOL_DEG)


@pytest.mark.slow
def test_paper_b_extents_at_another_height():
    """The closed forms hold at z = 0.15 m too: atan(0.15/0.2) = 36.870 deg, gamma 117.953 deg."""
    ws = orientation_workspace(MECH, at={"z": 0.15}, step=np.radians(6))
    assert abs(np.degrees(ws.alone["alpha"].hi) - np.degrees(np.arctan(0.15 / B))) <= TOL_DEG
    assert abs(np.degrees(ws.alone["gamma"].hi) - np.degrees(gamma_leg_limit(0.15))) <= TOL_DEG


@pytest.mark.slow
def test_boundary_pose_has_the_leg_perpendicular_to_the_platform_normal(ws_z01):
    """Independent check of the eq 18 reading: at alpha = atan(z/b) the leg of A1 (or A2) lies in
    the platform plane direction, i.e. at 90 deg to the platform normal R e_z."""
    al = ws_z01.alone["alpha"].hi
    phi = np.array([0.1, al, 0.0, 0.0])
    d = k4.leg_vectors(phi)
    n = k4.rotation(phi) @ [0, 0, 1]
    ang = np.degrees(np.arccos(d @ n / np.linalg.norm(d, axis=1)))
    assert abs(ang.max() - 90.0) < 2e-3  # within the bisection tolerance of the angle


def test_position_workspace_is_the_cu_stroke_on_the_z_axis():
    """At alpha = beta = gamma = 0 the position workspace is a segment of the Z axis (the paper
    says so); its ends are the CU length limits 0.08 and 0.3 m (legs stay in 0.141..0.361 m)."""
    ws = position_workspace(MECH, at={"alpha": 0, "beta": 0, "gamma": 0})
    assert ws.free == ("z",) and ws.fixed["x"] == 0.0 and ws.fixed["y"] == 0.0
    tol = ws.tol["z"]
    e = ws.alone["z"]
    assert abs(e.lo - 0.08) <= tol and abs(e.hi - 0.3) <= tol
    assert (e.lo_limit, e.hi_limit) == ("C5.slide min", "C5.slide max")
    assert abs(ws.volume - 0.22) <= 2 * tol and ws.volume_unit == "m"


@pytest.mark.slow
def test_interference_is_active_somewhere_but_not_at_the_extents(ws_z01):
    """Link capsules of 0.01 m (eq 22): legs 1/2, 1/4, 2/3, 3/4 touch on part of the boundary at
    large gamma with tilt, but the extents are set by the cone and leg-length limits."""
    act = ws_z01.active_limits
    assert any(k.startswith("interference leg") for k in act)
    assert not any("interference" in v for e in ws_z01.alone.values() for v in (e.lo_limit, e.hi_limit))
    no_caps = orientation_workspace(MECH, at={"z": 0.1}, step=np.radians(5),
                                    limits=WorkspaceLimits(paper_b_limits().cones, None))
    assert no_caps.volume > ws_z01.volume  # removing a limit can only enlarge the set
    assert not any("interference" in k for k in no_caps.active_limits)


@pytest.mark.slow
def test_volume_converges_with_the_grid(ws_z01):
    """Line integration of refined lengths: the volume at 5 deg and at 3.6 deg agree within 2 %."""
    fine = orientation_workspace(MECH, at={"z": 0.1}, step=np.radians(3.6), polish=False)
    assert abs(fine.volume - ws_z01.volume) / fine.volume < 0.02
    assert "rad^3" in ws_z01.volume_unit


@pytest.mark.slow
def test_polish_recovers_the_extent_when_no_grid_line_passes_through_it():
    """With bounds that keep beta = 0 off the grid, the grid lines miss the extreme pose; the
    SLSQP polish + bisection still gives atan(z/b) to the tolerance (without: > 0.2 deg off)."""
    b = {"beta": (-1.3, 1.5), "alpha": (-3.0, 3.1), "gamma": (-3.1, 3.0)}
    ws = orientation_workspace(MECH, at={"z": 0.1}, step=np.radians(7), bounds=b)
    raw = orientation_workspace(MECH, at={"z": 0.1}, step=np.radians(7), bounds=b, polish=False)
    exact = np.degrees(np.arctan(0.1 / B))
    assert abs(np.degrees(ws.extents["alpha"].hi) - exact) <= TOL_DEG
    assert np.degrees(raw.extents["alpha"].hi) < exact - 0.2
    assert "polish" in ws.extent_method["alpha"]


# ------------------------------------------------------------------ kernels
@settings(max_examples=30, deadline=None)
@given(st.floats(0.08, 0.3), st.lists(st.floats(-1.5, 1.5), min_size=3, max_size=3))
def test_kernel_legs_match_the_paper_b_closed_form(z, ang):
    """``L_i.slide max`` margin = 0.4 - l_i with l_i from four_sps_cu.leg_lengths (eq 8 corrected)."""
    ck = pose_checker(MECH, paper_b_limits())
    R, p = poses(np.array(ang), z)
    m = ck.margins(R, p)[0]
    legs = k4.leg_lengths([z, *ang])
    for i in range(4):
        assert abs(m[ck.names.index(f"L{i + 1}.slide max")] - (L_MAX - legs[i])) < 1e-12
    assert abs(m[ck.names.index("C5.slide min")] - (z - 0.08)) < 1e-12
    # U5 cone (eq 20): angle between the column (0, 0, z) and the platform normal
    n = R[0] @ [0, 0, 1]
    assert abs(m[ck.names.index("U5 cone")] - (np.pi / 2 - np.arctan2(np.hypot(n[0], n[1]), n[2]))) < 1e-12


@pytest.mark.slow
def test_vectorised_kernel_equals_a_per_pose_loop_and_chunking_does_not_matter(rng):
    ck = pose_checker(MECH, paper_b_limits())
    ang = rng.uniform([-0.6, -0.6, -2.4], [0.6, 0.6, 2.4], (3000, 3))
    R, p = poses(ang)
    ok = ck.feasible(R, p)
    assert 0 < ok.sum() < ok.size
    assert np.array_equal(ok, np.all(ck.margins(R, p) >= 0, axis=1))  # short-circuit = full margins
    assert np.array_equal(ok[:200], [ck.feasible(R[i : i + 1], p[i : i + 1])[0] for i in range(200)])
    a = orientation_workspace(MECH, at={"z": 0.1}, step=np.radians(10), chunk=997, polish=False)
    b = orientation_workspace(MECH, at={"z": 0.1}, step=np.radians(10), polish=False)
    assert np.array_equal(a.feasible, b.feasible) and a.volume == b.volume


@pytest.mark.slow
def test_general_kernel_agrees_with_the_closed_form(rng):
    """Per-pose inverse position + joint points give the same margins on feasible poses and the
    same verdict everywhere (infeasible poses may differ in which assembly was tried)."""
    ck = pose_checker(MECH, paper_b_limits())
    gk = pose_checker(MECH, paper_b_limits(), method="general")
    assert (ck.path, gk.path) == ("closed-form", "general")
    ang = np.vstack([rng.uniform([-0.3, -0.3, -1.5], [0.3, 0.3, 1.5], (6, 3)), [[0.6, 0, 0], [0, 0, 2.4]]])
    R, p = poses(ang)
    mc, mg = ck.margins(R, p), gk.margins(R, p)
    fc, fg = np.all(mc >= 0, axis=1), np.all(mg >= 0, axis=1)
    assert np.array_equal(fc, fg) and fc.any() and not fc.all()
    assert np.max(np.abs(mc[fc] - mg[fc])) < 1e-9


@pytest.mark.slow
def test_general_path_workspace_matches_on_a_slice():
    """The slow fallback on a 1-D slice (alpha = beta = 0) finds the gamma leg-length limit."""
    ws = orientation_workspace(MECH, at={"z": 0.1, "alpha": 0.0, "beta": 0.0}, step=np.radians(30),
                               tol=np.radians(0.1), method="general")
    assert ws.path == "general" and ws.free == ("gamma",)
    assert abs(ws.alone["gamma"].hi - gamma_leg_limit(0.1)) <= np.radians(0.1)
    assert ws.alone["gamma"].hi_limit.endswith(".slide max")


def test_any_model_runs_through_the_general_path():
    """A model without a closed form (3-SPS/SmPU: Sm-P-U limb) and no limits: every gamma of
    the sampled box is reachable; the result says so (active limit 'box') and which path ran."""
    ws = orientation_workspace(catalog.build("three-sps-smpu"), at={"alpha": 0, "beta": 0},
                               step=np.radians(60), tol=np.radians(1))
    assert ws.path == "general" and "Sm-P-U" in ws.path_reason
    e = ws.alone["gamma"]
    assert (np.degrees(e.lo), np.degrees(e.hi)) == pytest.approx((-180, 180)) and e.hi_limit == "box"


def test_stewart_closed_form_with_a_cone_and_capsules():
    """6-SPS: the closed form applies; adding base cones of 30 deg makes the cone the active limit."""
    st6 = catalog.build("stewart-6sps")
    cones = [ConeLimit(f"B{i}", (0, 0, 1), "base", np.radians(30)) for i in range(1, 7)]
    ws = position_workspace(st6, at={"x": 0.0, "y": 0.0}, limits=WorkspaceLimits(cones, 0.02), step=0.1)
    assert ws.path == "closed-form" and ws.free == ("z",)
    assert ws.alone["z"].lo_limit.startswith("B") and ws.alone["z"].lo_limit.endswith("cone")


@pytest.mark.slow
@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1, 1), min_size=12, max_size=12))
def test_segment_distance_is_the_convex_minimum(v):
    """Against a bounded minimisation of |P(s) - Q(t)|^2 (convex in (s, t)) over [0, 1]^2."""
    p1, q1, p2, q2 = np.reshape(v, (4, 3))
    f = lambda x: np.sum((p1 + x[0] * (q1 - p1) - p2 - x[1] * (q2 - p2)) ** 2)  # noqa: E731
    best = min(minimize(f, x0, bounds=[(0, 1), (0, 1)], method="L-BFGS-B", options={"ftol": 1e-15, "gtol": 1e-12}).fun
               for x0 in ([0.5, 0.5], [0, 0], [1, 1], [0, 1], [1, 0]))
    d = segment_distance(p1, q1, p2, q2)
    assert d <= np.sqrt(max(best, 0)) + 1e-9
    assert d >= np.sqrt(max(best, 0)) - 1e-6


def test_segment_distance_examples():
    assert segment_distance([0, 0, 0], [1, 0, 0], [0.5, 1, -1], [0.5, 1, 1]) == pytest.approx(1.0)
    assert segment_distance([0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]) == pytest.approx(1.0)  # collinear
    assert segment_distance([0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]) == pytest.approx(1.0)  # parallel


# ------------------------------------------------------------------ errors and results
def test_bad_inputs_name_the_argument():
    with pytest.raises(ValueError, match=r"^at"):
        orientation_workspace(MECH, at={"q": 1.0})
    with pytest.raises(ValueError, match=r"^at\.z"):
        orientation_workspace(MECH, at={"z": float("nan")})
    with pytest.raises(ValueError, match=r"^step"):
        orientation_workspace(MECH, step=-1.0)
    with pytest.raises(ValueError, match=r"^method"):
        pose_checker(catalog.build("three-rps"), method="closed-form")
    with pytest.raises(ValueError, match=r"^cones"):
        pose_checker(MECH, WorkspaceLimits((ConeLimit("L1"),)))
    with pytest.raises(ValueError, match=r"^max_angle"):
        ConeLimit("A1", max_angle=4.0)
    with pytest.raises(ValueError, match=r"^bounds\.alpha"):
        orientation_workspace(MECH, bounds={"alpha": (1.0, -1.0)})
    with pytest.raises(ValueError, match=r"^step"):
        orientation_workspace(MECH, at={"z": 0.1}, method="general", step=np.radians(5), max_poses=100)


@pytest.mark.slow
def test_to_dict_is_json_and_labelled(ws_z01):
    d = json.loads(json.dumps(ws_z01.to_dict(boundary=True)))
    for c in ("alpha", "beta", "gamma"):
        assert len(d["extents"][f"{c}_deg"]["alone"]) == 2 and len(d["extents"][f"{c}_deg"]["set"]) == 2
    # the volume in cubic degrees: the Python attribute is in rad^3
    assert d["path"] == "closed-form" and d["volume_deg3"] == pytest.approx(ws_z01.volume * np.degrees(1.0) ** 3)
    assert "rad^3" in ws_z01.volume_unit and "volume" not in d
    assert len(d["boundary_points_deg"]) == len(d["boundary_limits"]) == sum(d["active_limits"].values())


@pytest.mark.slow
def test_plot_writes_a_png(tmp_path, ws_z01):
    from spatialmech.present.workspace import write_workspace_plot

    out = write_workspace_plot(ws_z01, tmp_path / "ws.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match=r"^plot"):
        write_workspace_plot(ws_z01, tmp_path / "ws.txt")


# ------------------------------------------------------------------ CLI
@pytest.mark.slow
def test_cli_orientation_json_keys(tmp_path):
    r = CliRunner().invoke(workspace, ["four-sps-cu", "--orientation", "--at", "z=0.1", "--step-deg", "6",
                                       "--json", "--plot", str(tmp_path / "w.png")])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert set(d["extents"]) == {"alpha_deg", "beta_deg", "gamma_deg"}
    for key in ("volume_deg3", "active_limits", "plot", "fixed"):
        assert key in d
    assert d["fixed"] == {"x_len": 0.0, "y_len": 0.0, "z_len": 0.1} and d["length_unit"] == "m"
    assert d["extents"]["alpha_deg"]["alone"][1] == pytest.approx(np.degrees(np.arctan(0.5)), abs=TOL_DEG)
    assert d["extents"]["gamma_deg"]["alone"][1] == pytest.approx(np.degrees(gamma_leg_limit(0.1)), abs=TOL_DEG)
    assert (tmp_path / "w.png").exists()


def test_cli_position_text_and_errors():
    r = CliRunner().invoke(workspace, ["four-sps-cu", "--position", "--at", "alpha=0,beta=0,gamma=0"])
    assert r.exit_code == 0, r.output
    assert "z     alone" in r.output and "C5.slide max" in r.output
    bad = CliRunner().invoke(workspace, ["four-sps-cu", "--at", "z=abc"])
    assert bad.exit_code == 2 and "error: --at: z expects a number" in bad.output
    bad = CliRunner().invoke(workspace, ["four-sps-cu", "--step-deg", "0"])
    assert bad.exit_code == 2 and "--step-deg" in bad.output
    assert parse_at("z=0.1, gamma=90") == {"z": 0.1, "gamma": pytest.approx(np.pi / 2)}


# ------------------------------------------------------------------ benchmark smoke test
@pytest.mark.slow
def test_workspace_benchmark_runs_with_a_tiny_size():
    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_workspace.py"
    spec = importlib.util.spec_from_file_location("bench_workspace", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    res = mod.run(n=2000, loop_n=100, general_n=2, step_deg=0, repeat=1)
    json.dumps(res)
    assert res["loop"]["agree"] and res["general"]["agree"]
    assert res["vectorised"]["pose_checks_per_s"] > 0 and res["loop"]["pose_checks_per_s"] > 0
