"""Singularity analysis: paper B's cases found by the analysis itself, kinds, loci, CLI."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis.singularity import singularity, singularity_at_pose, singularity_slice
from spatialmech.catalog.papers import four_sps_cu
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.motion import generic_configuration

M = catalog.build("four-sps-cu")  # a = 0.1, b = 0.2, reference z0 = 0.2


def pose(z, alpha, beta, gamma):
    return sm.Pose.from_euler("ZYX", [gamma, beta, alpha], [0, 0, z])


def test_paper_B_home_pose_is_singular_contrary_to_the_paper():
    r = singularity(M, Configuration.reference(M))
    assert r.kind == "direct" and r.rank == 5
    assert r.sigma_min < 1e-12
    # the uncontrolled twist is a rotation about the Z axis
    assert np.allclose(np.abs(r.twist[0]), [0, 0, 1, 0, 0, 0], atol=1e-9)


def test_paper_B_home_pose_has_a_finite_self_motion_z2_formula():
    r = singularity(M, Configuration.reference(M), self_motion_arc=0.4)
    sm_ = r.self_motion
    assert sm_["finite"]
    a, b, z0 = 0.1, 0.2, 0.2
    l2 = 2 * (b - a) ** 2 + z0**2
    g = np.radians(sm_["platform_rotated_deg"])
    z = sm_["end_platform_point"][2]
    assert z**2 == pytest.approx(l2 - 2 * a**2 - 2 * b**2 + 4 * a * b * np.cos(g), abs=1e-9)
    assert sm_["platform_rotated_deg"] > 1.0


@pytest.mark.parametrize("gamma", [0.0, 0.4, -1.0])
def test_every_alpha_beta_zero_pose_is_singular(gamma):
    r = singularity_at_pose(M, pose(0.15, 0.0, 0.0, gamma), self_motion_arc=0.05)
    assert r.kind == "direct" and r.rank == 5 and r.self_motion["finite"]


def test_paper_B_case_b_leg_lines_concurrent_on_the_z_axis():
    r = singularity(M, Configuration.reference(M))
    legs = [c for c in r.line_geometry["circuits"] if c["case"] == "concurrent"]
    assert legs and sorted(legs[0]["indices"]) == [2, 3, 4, 5]  # rows 0-1: CU constraints
    # they meet at (0, 0, z b / (b - a)) = (0, 0, 0.4)
    assert np.allclose(legs[0]["witnesses"]["point"], [0, 0, 0.4], atol=1e-9)


def test_paper_B_case_a_parallel_legs_needs_a_equal_b():
    m = four_sps_cu(a=0.15, b=0.15, z0=0.2)
    r = singularity(m, Configuration.reference(m))
    assert r.kind == "direct" and r.line_geometry["rank"] == 5
    par = [c for c in r.line_geometry["circuits"] if c["case"] == "parallel"]
    assert par and np.allclose(np.abs(par[0]["witnesses"]["direction"]), [0, 0, 1], atol=1e-9)


def test_generic_pose_is_not_singular():
    r = singularity_at_pose(M, pose(0.12, 0.2, -0.1, 0.6))
    assert r.kind == "none" and r.rank == 6 and r.twist == () and r.self_motion is None
    assert r.line_geometry["case"] == "general"


def test_inverse_singularity_of_the_rssr_at_the_rocker_limit():
    m = catalog.build("rssr")
    c = generic_configuration(m, seed=0)
    assert singularity(m, c).kind in ("none",)
    # drive the rocker instead: at the crank's dead point the rocker cannot drive
    from spatialmech.kinematics.tracking import trace_motion

    tr = trace_motion(m, Configuration.reference(m), increasing="A0")
    i = [f.id for f in m.freedom_refs].index("A0.rot")
    k = int(np.argmin([abs(np.cos(p.q[i])) for p in tr.points]))  # crank near +-90 deg
    r = singularity(m, tr.points[k], ["A0"])
    # the coupler line nearly meets the crank axis: the crank can barely act (transmission ~ 0)
    assert r.transmission[0] < 0.05 < singularity(m, c, ["A0"]).transmission[0]
    # exactly at crank -90 deg the coupler (in the plane x = 0) meets the crank axis: inverse singular
    from spatialmech.kinematics.forward import forward_position
    fk = forward_position(m, [tr.points[k].q[i] / abs(tr.points[k].q[i]) * np.pi / 2], start=tr.points[k])
    assert fk.converged
    r = singularity(m, fk.solutions[0].config, ["A0"])
    assert r.kind.startswith("inverse") and r.transmission[0] < 1e-9


@pytest.mark.slow
def test_slice_det_changes_sign_across_the_workspace():
    res = singularity_slice(M, lambda u, v: pose(0.12, np.radians(v), np.radians(u), np.radians(20)),
                            np.linspace(-20, 20, 9), np.linspace(-20, 20, 9))
    assert np.all(np.isfinite(res.det))
    assert np.nanmin(res.det) < 0 < np.nanmax(res.det)
    assert res.sigma_min[4, 4] < 1e-10  # alpha = beta = 0 in the middle


@pytest.mark.slow
def test_cli_singularity_json_keys_and_errors(tmp_path):
    r = CliRunner().invoke(cli, ["singularity", "four-sps-cu", "--xyz", "0", "0", "0.12",
                                 "--euler", "ZYX", "34.38", "-5.73", "11.46", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    for k in ("rank", "kind", "line_geometry", "twist"):
        assert k in d
    assert d["kind"] == "none" and d["rank"] == 6 and d["result"] == "singularity"
    r = CliRunner().invoke(cli, ["singularity", "four-sps-cu", "--reference", "--json"])
    assert json.loads(r.output)["kind"] == "direct"
    p = tmp_path / "loci.png"
    r = CliRunner().invoke(cli, ["singularity", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "20", "0", "0",
                                 "--slice", "a2:-10:10:5,a3:-10:10:5", "--plot", str(p), "--json"])
    assert r.exit_code == 0 and p.stat().st_size > 1000
    r = CliRunner().invoke(cli, ["singularity", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "20", "0", "0",
                                 "--slice", "q:0:1:5"])
    assert r.exit_code == 2 and "--slice" in r.output
