"""Defect judgement: every claim of paper A (linkages 1-3), and the same code on a four-bar."""

import itertools
import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis.defects import candidate_drivers, defect_analysis
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closure import Configuration
from spatialmech.kinematics.position import platform_pose
from spatialmech.kinematics.tracking import trace_motion

DRIVERS = [f"rot{i}" for i in range(1, 6)] + [f"slide{i}" for i in range(1, 6)]


@pytest.fixture(scope="module")
def linkage1():
    return defect_analysis(catalog.build("five-cs-1"))


@pytest.fixture(scope="module")
def linkage2():
    return defect_analysis(catalog.build("five-cs-2"))


@pytest.fixture(scope="module")
def linkage3():
    return defect_analysis(catalog.build("five-cs-3"))


def by_driver(res):
    return {v.driver: v for v in res.drivers}


def test_candidate_drivers_of_the_five_cs_are_the_ten_c_freedoms():
    assert candidate_drivers(catalog.build("five-cs-1")) == ["rot1", "slide1", "rot2", "slide2", "rot3", "slide3",
                                                             "rot4", "slide4", "rot5", "slide5"]


@pytest.mark.slow
def test_paper_A_linkage1_every_driver_changes_sign_figs_6_7(linkage1):
    assert all(not v.keeps_sign for v in linkage1.drivers)


@pytest.mark.slow
def test_paper_A_linkage1_one_circuit_no_order_defect_fig_11(linkage1):
    assert linkage1.circuits == ((1, 2, 3, 4, 5, 6, 7),)
    assert not linkage1.circuit_defect and not linkage1.order_defect
    assert linkage1.circuit_closed == (True,)
    arcs = linkage1.position_arcs
    assert all(a < b for a, b in itertools.pairwise(arcs))


@pytest.mark.slow
def test_paper_A_linkage1_K2_of_rot1_between_P6_P7_and_K1_of_rot5_between_P3_P4(linkage1):
    d = by_driver(linkage1)
    assert [b.between for b in d["rot1"].branch_points] == [(6, 7)]
    assert [b.between for b in d["rot5"].branch_points] == [(3, 4)]
    assert not linkage1.usable_drivers


@pytest.mark.slow
def test_paper_A_linkage1_dual_drive_rot1_then_rot5_switching_between_K1_and_K2_fig_14(linkage1):
    plan = linkage1.plan
    assert plan is not None and [s.driver for s in plan] == ["rot1", "rot5"]
    d = by_driver(linkage1)
    K2 = d["rot1"].branch_points[0].arc
    K1 = d["rot5"].branch_points[0].arc
    lo, hi = plan[0].switch_window
    assert lo == pytest.approx(K1) and hi == pytest.approx(K2) and K1 < K2
    assert lo < plan[0].end_arc < hi and plan[1].start_arc == plan[0].end_arc
    assert plan[1].end_arc == pytest.approx(linkage1.path_length)


@pytest.mark.slow
def test_paper_A_linkage2_slides_3_4_5_keep_sign_figs_8_9(linkage2):
    assert {v.driver for v in linkage2.drivers if v.keeps_sign} == {"slide3", "slide4", "slide5"}


@pytest.mark.slow
def test_paper_A_linkage2_circuit_defect_three_circuits_fig_10(linkage2):
    assert linkage2.circuit_defect
    assert linkage2.circuits == ((1,), (2, 3), (4, 5, 6, 7))
    assert not linkage2.usable_drivers and linkage2.plan is None


@pytest.mark.slow
def test_paper_A_linkage3_rot1_rot2_keep_sign_others_change_figs_15_16(linkage3):
    assert {v.driver for v in linkage3.drivers if v.keeps_sign} == {"rot1", "rot2"}


@pytest.mark.slow
def test_paper_A_linkage3_usable_one_circuit_in_order_no_dj_zero_figs_17_19(linkage3):
    assert linkage3.circuits == ((1, 2, 3, 4, 5, 6, 7),) and not linkage3.order_defect
    d = by_driver(linkage3)
    assert d["rot1"].branch_points == () and d["rot2"].branch_points == ()
    assert set(linkage3.usable_drivers) == {"rot1", "rot2"}


@pytest.mark.slow
def test_paper_A_linkage3_passes_close_to_a_singularity_between_P3_and_P4(linkage3):
    # reported, not hidden: the smallest scale-free singular value of the closure Jacobian on the path
    assert linkage3.min_closure_sigma_between == (3, 4)
    assert linkage3.min_closure_sigma < 1e-3
    assert 0 < by_driver(linkage3)["rot1"].min_sigma_on_path < 1e-2


@pytest.mark.slow
def test_dj_zeros_sit_where_the_driver_turns(linkage1):
    """Along a tracked path DJ changes sign exactly where the driver reaches a turning point."""
    mech = catalog.build("five-cs-1")
    tr = linkage1.traces[0]
    i = [f.id for f in mech.freedom_refs].index("C1.rot")
    q = np.array([c.q[i] for c in tr.points])
    for b in by_driver(linkage1)["rot1"].circuit_branch_points:
        k = int(np.searchsorted(tr.s, b.arc if linkage1.direction == 1 else tr.s[-1] - b.arc))
        k = min(max(k, 2), len(q) - 3)
        d_before, d_after = q[k - 1] - q[k - 2], q[k + 2] - q[k + 1]
        assert np.sign(d_before) != np.sign(d_after)


# ------------------------------------------------------------------ the same code on a four-bar
@pytest.fixture(scope="module")
def fourbar():
    m = catalog.build("planar-4r")
    tr = trace_motion(m, Configuration.reference(m), increasing="A0")
    idx = np.linspace(0, len(tr.points) - 2, 6).astype(int)
    poses = [platform_pose(m, tr.points[k], name=f"P{n + 1}") for n, k in enumerate(idx)]
    return m, poses


@pytest.mark.slow
def test_four_bar_crank_is_usable_rocker_has_branch_defects(fourbar):
    m, poses = fourbar
    res = defect_analysis(m, poses, drivers=["A0", "B0"])
    d = by_driver(res)
    assert res.circuits == ((1, 2, 3, 4, 5, 6),) and not res.order_defect
    assert d["A0"].usable and d["A0"].circuit_branch_points == ()  # a Grashof crank never turns back
    assert len(d["B0"].circuit_branch_points) == 2  # the rocker's two limit positions
    assert d["B0"].branch_defect


@pytest.mark.slow
def test_scrambled_positions_give_an_order_defect(fourbar):
    m, poses = fourbar
    res = defect_analysis(m, [poses[0], poses[3], poses[1], poses[2], poses[4]], drivers=["A0"])
    assert not res.circuit_defect and res.order_defect


def rccc():
    """A small RCCC guidance linkage (coupler as platform): 1 DOF, not overconstrained."""
    z = np.array([0, 0, 1.0])
    a1 = np.array([0.2, 0.3, 0.93])
    a1 /= np.linalg.norm(a1)
    b0 = np.array([0.1, 0.9, 0.2])
    b0 /= np.linalg.norm(b0)
    b1 = np.array([0.8, 0.1, 0.4])
    b1 /= np.linalg.norm(b1)
    return sm.Mechanism("rccc-test", [
        sm.Limb("input", [sm.R("A0", [0, 0, 0], z, actuated=True), sm.C("A1", [1.0, 0, 0.2], a1)]),
        sm.Limb("output", [sm.C("B0", [3.0, 0.5, 0], b0), sm.C("B1", [2.2, 1.8, 0.6], b1)]),
    ], platform_point=[1.6, 1.0, 0.4])


@pytest.mark.slow
def test_monte_carlo_is_seeded_and_reports():
    m = rccc()
    tr = trace_motion(m, Configuration.reference(m), increasing="A0", max_arc=60)
    assert tr.closed
    k = np.linspace(0, len(tr.points) // 3, 4).astype(int)
    poses = [platform_pose(m, tr.points[i], name=f"P{n + 1}") for n, i in enumerate(k)]
    a = defect_analysis(m, poses, drivers=["A0"], monte_carlo=2, seed=3, precision=1e-4)
    b = defect_analysis(m, poses, drivers=["A0"], monte_carlo=2, seed=3, precision=1e-4)
    assert a.robustness["samples"] == 2 and a.robustness == b.robustness
    assert a.robustness["same_verdict"] == 2 and a.robustness["failed"] == 0


def test_monte_carlo_on_an_overconstrained_linkage_reports_lost_mobility(fourbar):
    # a perturbed planar four-bar is a generic spatial 4R: rigid.  Reported as failed samples.
    m, poses = fourbar
    a = defect_analysis(m, poses[:3], drivers=["A0"], monte_carlo=1, seed=0)
    assert a.robustness["failed"] == 1 and a.robustness["same_verdict"] == 0


def test_bad_inputs(fourbar):
    m, poses = fourbar
    st = catalog.build("stewart-6sps")
    with pytest.raises(ValueError, match="one-degree-of-freedom linkages; stewart-6sps has 6"):
        defect_analysis(st, [sm.Pose(np.eye(3), [0, 0, 1.0]), sm.Pose(np.eye(3), [0, 0, 1.1])])
    with pytest.raises(ValueError, match="at least two task positions"):
        defect_analysis(m, poses[:1])
    with pytest.raises(KeyError, match="unknown freedom"):
        defect_analysis(m, poses, drivers=["nope"])


@pytest.mark.slow
def test_cli_json_layout_and_positions_file(fourbar, tmp_path):
    _m, poses = fourbar
    f = tmp_path / "pos.toml"
    lines = []
    for p in poses:
        lines.append("[[positions]]")
        lines.append(f"name = \"{p.name}\"")
        lines.append(f"point = [{', '.join(repr(float(x)) for x in p.p)}]")
        lines.append("matrix = [" + ", ".join("[" + ", ".join(repr(float(x)) for x in row) + "]" for row in p.R) + "]")
    f.write_text("\n".join(lines))
    r = CliRunner().invoke(cli, ["defects", "planar-4r", "--positions", str(f), "--driver", "A0", "--driver", "B0",
                                 "--json", "--plot", str(tmp_path / "figs")])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    for key in ("circuits", "order_defect", "circuit_defect", "drivers", "usable_drivers", "plan"):
        assert key in d
    drv = {x["driver"]: x for x in d["drivers"]}
    for key in ("driver", "signs", "branch_points", "circuit_branch_points", "branch_defect", "usable"):
        assert key in drv["A0"]
    assert d["circuits"] == [[1, 2, 3, 4, 5, 6]] and d["usable_drivers"] == ["A0"]
    assert len(list((tmp_path / "figs").glob("*.png"))) == 4 and len(d["figures"]) == 4
