"""Regression tests of the numerical bugs of issue 10, one (or more) per bug, named after it.

1. ``fk MODEL --all`` in text mode crashed (IndexError) when no assembly was found.
2. ``fk`` at a singular configuration reported "1 assembly mode ... converged" with no flag, and
   the general engine reported many "modes" for one singular root or one self-motion.
3. ``singularity --reference`` silently ignored a pose given with it.
4. The report's paper B workspace row contradicted itself (gamma's cosine with the wrong sign,
   "WARNING: closed forms not matched", a list cut mid-word).
5. ``synth cs`` called a 5-CS with a circuit defect a success; the numerical core imported the
   catalogue (cs_dyads, the 4-SPS/CU closed form).
"""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.assembly import (
    AssemblyKind,
    Conditioning,
    dedup_tolerances,
    distance_to_polylines,
    group_roots,
    pose_keys,
    singular_threshold,
)
from spatialmech.kinematics.closed_forms import four_sps_cu as k
from spatialmech.kinematics.closed_forms import four_sps_cu_forward as kf
from spatialmech.kinematics.closed_forms import four_sps_cu_paper as kp
from spatialmech.kinematics.forward import forward_conditioning, forward_position
from spatialmech.present.report import Claim, join_names, render_html, summary

SRC = Path(__file__).resolve().parents[1] / "src" / "spatialmech"
HOME_LEG = float(np.sqrt(0.06))  # every leg of the 4-SPS/CU at its home pose (0.2449489742783178 m)
HOME_LEGS = ",".join([repr(HOME_LEG)] * 4)


def run(*args):
    return CliRunner().invoke(cli, [str(a) for a in args], catch_exceptions=False)


# ------------------------------------------------------------------ 1. fk --all without assembly
@pytest.mark.slow
@pytest.mark.parametrize("model, values", [("stewart-6sps", "100,0.01,100,0.01,100,0.01"), ("three-rps", "50,50,0.001")])
def test_fk_all_without_any_assembly_says_so_instead_of_crashing(model, values):
    """Absurd actuator values on general-engine models: a one-line error naming the number of
    starts and saying it is not a proof, exit code 2 (as the single-start 'no assembly found')."""
    r = run("fk", model, "--actuators", values, "--all", "--seeds", "2", "--method", "multistart")
    assert r.exit_code == 2, r.output
    assert "IndexError" not in r.output and "Traceback" not in r.output
    assert re.search(r"no assembly found among 3 starts \(0 converged\); not a proof that none exists", r.output), r.output
    # the JSON says the same with data: no solutions, nothing invented
    d = json.loads(run("fk", model, "--actuators", values, "--all", "--seeds", "2", "--method", "multistart",
                       "--json").output)
    assert d["n_solutions"] == 0 and not any(s["converged"] for s in d["solutions"])
    # by homotopy (the default where it covers the model) the absence is proven: no real end point
    r = run("fk", model, "--actuators", values, "--all")
    assert r.exit_code == 0 and "0 real assembly modes" in r.output and "complete (proven)" in r.output, r.output
    d = json.loads(run("fk", model, "--actuators", values, "--all", "--json").output)
    assert d["complete"] is True and d["n_real"] == 0 and d["n_solutions"] == 0


def test_fk_single_start_without_assembly_keeps_its_message():
    r = run("fk", "stewart-6sps", "--actuators", "100,0.01,100,0.01,100,0.01")
    assert r.exit_code == 2 and "no assembly found (Newton did not converge" in r.output


# ------------------------------------------------------------------ 2. singular forward position
@pytest.mark.slow
def test_fk_at_the_singular_home_pose_flags_a_self_motion_not_an_assembly_mode():
    """four-sps-cu with every leg sqrt(0.06) m: the home pose, on a finite self-motion (the legs
    locked, the platform still moves: z^2 = l^2 - 2a^2 - 2b^2 + 4ab cos(gamma))."""
    mech = sm.load_model("four-sps-cu")
    res = forward_position(mech, [HOME_LEG] * 4)
    (s,) = res.solutions
    assert s.converged and s.singular and s.kind == AssemblyKind.SELF_MOTION
    assert s.conditioning.sigma_min < s.conditioning.threshold and s.conditioning.condition < 1e-10
    # the trace really follows the self-motion: gamma reaches +-60 deg where z = 0
    sm_ = s.self_motion
    assert sm_.closed and sm_.position_spread == pytest.approx(0.4, abs=2e-3)
    assert np.degrees(sm_.rotation_spread) == pytest.approx(60.0, abs=1.0)
    assert res.search["distinct"] == 1 and res.search["n_regular"] == 0 and res.search["n_self_motion_sets"] == 1


@pytest.mark.slow
def test_fk_text_at_the_singular_home_pose_says_self_motion():
    text = run("fk", "four-sps-cu", "--actuators", HOME_LEGS).output
    assert "0 assembly modes, 1 self-motion set" in text and "SINGULAR, SELF-MOTION" in text
    assert "1 assembly mode" not in text


def test_fk_json_states_conditioning_and_kind_for_both_engines():
    general = json.loads(run("fk", "four-sps-cu", "--actuators", "0.216745,0.23896,0.227321,0.206933", "--json").output)
    closed = json.loads(run("fk", "four-sps-cu", "--actuators", "0.216745,0.23896,0.227321,0.206933", "--all",
                            "--seeds", "64", "--json").output)
    for sol in general["solutions"] + closed["solutions"]:
        assert {"sigma_min", "condition", "singular", "singular_below", "kind", "members", "self_motion"} <= set(sol)
        assert sol["kind"] == "regular" and sol["singular"] is False and 0 < sol["condition"] <= 1
        assert sol["sigma_min"] > sol["singular_below"]


def test_conditioning_of_the_general_engine_matches_the_closed_form_zero_set():
    """Both measures vanish on alpha = beta = 0 and nowhere near the example pose."""
    mech = sm.load_model("four-sps-cu")
    for phi, singular in (((0.15, 0.0, 0.0, 0.5), True), ((0.12, 0.2, -0.1, 0.6), False)):
        fit = sm.kinematics.position.configuration_at_pose(mech, sm.Pose.from_euler("ZYX", phi[:0:-1], [0, 0, phi[0]]))
        c = forward_conditioning(mech, fit.config)
        sig, _ = k.conditioning(np.array(phi))
        assert c.singular == singular and bool(sig < singular_threshold()) == singular


@pytest.mark.slow
def test_closed_form_forward_all_at_singular_legs_is_one_self_motion_set_not_hundreds_of_modes():
    res = kf.forward_all([HOME_LEG] * 4, n_seeds=128)
    assert res.search.n_converged > 100
    (s,) = res.solutions
    assert s.kind == AssemblyKind.SELF_MOTION and s.singular and s.members == res.search.n_converged
    assert res.search.n_self_motion_sets == 1 and res.search.n_regular == 0
    # the representative is a genuine root of the legs, within the limits
    assert np.allclose(k.leg_lengths(s.phi), HOME_LEG, atol=1e-10) and s.within_limits
    text = run("fk", "four-sps-cu", "--actuators", HOME_LEGS, "--all", "--seeds", "128").output
    assert text.count("[") == 1 and "0 assembly modes, 1 self-motion set" in text


def test_closed_form_keeps_the_four_regular_modes_of_the_example():
    res = kf.forward_all(k.leg_lengths([0.12, 0.2, -0.1, 0.6]), n_seeds=128)
    assert [s.kind for s in res.solutions] == [AssemblyKind.REGULAR] * 4
    assert sum(s.members for s in res.solutions) == res.search.n_converged


def test_a_double_root_at_a_fold_is_one_singular_result_and_its_mirror():
    """Legs of a pose on det J = 0 away from alpha = beta = 0: two assembly modes meet there;
    the root converges only to ~sqrt(tol), so a fixed 1e-6 de-duplication gave many 'modes'."""
    from scipy.optimize import brentq

    a0 = brentq(lambda a: kp.det_jacobian_nd([0.2, a, 0.3, 0.6]), 0.2, 0.26, xtol=1e-15)
    legs = k.leg_lengths([0.2, a0, 0.3, 0.6])
    res = kf.forward_all(legs, n_seeds=128)
    kinds = sorted(str(s.kind) for s in res.solutions)
    assert kinds.count("singular") == 2 and kinds.count("self-motion") == 0, kinds
    sing = [s for s in res.solutions if s.kind == AssemblyKind.SINGULAR]
    assert min(np.max(np.abs(s.phi - [0.2, a0, 0.3, 0.6])) for s in sing) < 1e-4


@pytest.mark.slow
def test_general_engine_all_solutions_at_singular_legs_is_one_self_motion_set():
    """Every converged start of the general engine lands on the one connected self-motion set
    (the loop through the home pose and the curve in the base plane that crosses it at
    gamma = +-60 deg): one result, not 'seven modes'."""
    mech = sm.load_model("four-sps-cu")
    res = forward_position(mech, [HOME_LEG] * 4, all_solutions=True, n_seeds=12, seed=3)
    conv = res.search["converged_runs"]
    assert conv >= 3
    assert [s.kind for s in res.solutions] == [AssemblyKind.SELF_MOTION]
    assert res.solutions[0].members == conv


def test_roots_with_several_free_directions_are_singular_and_not_traced():
    """An under-actuated model (three SPS legs driving a platform that the SmPU limb leaves more
    freedom): every root is singular with several free directions; none is called an assembly
    mode, and no curve tracer is started on a set of higher dimension (it took minutes)."""
    res = forward_position(sm.load_model("three-sps-smpu"), [0.4] * 3, all_solutions=True, n_seeds=4)
    sols = [s for s in res.solutions if s.converged]
    assert sols and all(s.kind == AssemblyKind.SINGULAR and s.conditioning.free_dim >= 2 for s in sols)
    assert all(s.self_motion is None for s in sols) and res.search["n_regular"] == 0


def test_group_roots_deduplicates_in_scale_free_pose_distance():
    """Two regular roots 1e-8 apart (in units of the length scale) are one; the same two roots in
    millimetres are still one; roots 1e-3 apart are two."""
    R = np.eye(3)
    for scale in (1.0, 1000.0):
        p = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0 + 1e-8], [0.0, 0.0, 1.001]]) * scale
        keys = pose_keys(np.broadcast_to(R, (3, 3, 3)), p, length_scale=scale)
        dedup, sdedup = dedup_tolerances()
        groups = group_roots(keys, [False] * 3, [1e-14, 2e-14, 1e-14], None, dedup_tol=dedup, singular_dedup_tol=sdedup)
        assert sorted(len(g.members) for g in groups) == [1, 2]


@given(st.floats(0.0, 2 * np.pi), st.floats(1e-3, 1e3))
def test_pose_keys_distance_is_the_rotation_chord_and_scaled_translation(theta, scale):
    from scipy.spatial.transform import Rotation

    R = Rotation.from_rotvec([0.0, 0.0, theta]).as_matrix()
    k1 = pose_keys(np.eye(3), [scale, 0.0, 0.0], scale)
    k2 = pose_keys(R, [scale, 2 * scale, 0.0], scale)
    assert np.linalg.norm(k2 - k1) == pytest.approx(np.hypot(2.0, 2 * np.sin(theta / 2)), rel=1e-9, abs=1e-12)


def test_distance_to_polylines_is_the_distance_to_the_nearest_segment():
    poly = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    d, seg = distance_to_polylines([[0.5, 0.2], [1.3, 0.5], [3.0, 3.0]], [poly])
    assert np.allclose(d, [0.2, 0.3, np.hypot(2.0, 2.0)]) and np.allclose(seg, 1.0)


def test_conditioning_from_singular_values():
    c = Conditioning.from_singular_values([3.0, 1.0, 0.0], "m", threshold=1e-5)
    assert c.singular and c.sigma_min == 0.0 and c.condition == 0.0
    c = Conditioning.from_singular_values([2.0, 1.0], "m", n_required=6, threshold=1e-5)
    assert c.singular  # fewer than 6 rows: the platform is free in some direction
    assert c.free_dim == 4
    c = Conditioning.from_singular_values([2.0, 0.5], "m", threshold=1e-5)
    assert not c.singular and c.condition == 0.25 and c.to_dict()["measure"] == "m" and c.free_dim == 0


# ------------------------------------------------------------------ 3. singularity --reference with a pose
@pytest.mark.parametrize("extra", [["--xyz", "0", "0", "0.12", "--euler", "ZYX", "34.38", "-5.73", "11.46"],
                                   ["--pose", "0,0,0.12,ZYX,34.38,-5.73,11.46"], ["--euler", "ZYX", "1", "2", "3"],
                                   ["--position", "1"], ["--slice", "a2:-30:30:5,a3:-30:30:5"]])
def test_singularity_reference_refuses_a_pose_instead_of_ignoring_it(extra):
    r = run("singularity", "four-sps-cu", "--reference", *extra)
    assert r.exit_code == 2, r.output
    assert r.output.startswith("error: --reference:") and "cannot be combined" in r.output


# ------------------------------------------------------------------ 4. paper B workspace row
def test_gamma_extent_closed_form_has_the_right_sign_of_the_cosine():
    """gamma alone at z = 0.1 m ends where the legs reach 0.4 m: +-128.68 deg (cos = -0.625);
    the reversed sign (cos = +0.625, 51.32 deg) leaves every leg well short of it."""
    ext = kp.single_angle_extents(0.1)
    g = ext["gamma"][0]
    assert np.degrees(g) == pytest.approx(128.6822, abs=1e-3) and np.cos(g) == pytest.approx(-0.625)
    assert np.max(k.leg_lengths([0.1, 0.0, 0.0, g])) == pytest.approx(0.4, abs=1e-12)
    wrong = np.arccos(0.625)
    assert np.max(k.leg_lengths([0.1, 0.0, 0.0, wrong])) < 0.3
    # alpha alone ends where a leg lies in the platform plane (the platform-side cone at 90 deg)
    a = ext["alpha"][0]
    d = k.leg_vectors([0.1, a, 0.0, 0.0])
    n = k.rotation([0.1, a, 0.0, 0.0]) @ [0, 0, 1]
    assert np.min(np.abs(d @ n)) == pytest.approx(0.0, abs=1e-12)


@given(st.lists(st.text(st.characters(categories=("L", "N")), min_size=1, max_size=12), max_size=30),
       st.integers(1, 10))
def test_join_names_never_cuts_a_name(names, limit):
    out = join_names(names, limit)
    shown, _, rest = out.partition(" and ")
    parts = shown.split(", ") if shown else []
    assert parts == names[: len(parts)]
    assert len(parts) == min(len(names), limit)
    if len(names) > limit:
        assert rest == f"{len(names) - limit} more"


def test_an_inconsistent_row_is_visible_and_counted():
    bad = Claim("B", "x", "1", "2", "not reproduced", "because", {"v": 1}, "t", consistent=False, consistency="2 vs 3")
    good = Claim("B", "y", "1", "1", "reproduced", "", {"v": 1}, "t", consistent=True, consistency="1 vs 1")
    sec = sm.present.report.Section("s", "S", "", (bad, good))
    s = summary([sec])
    assert s["inconsistent"] == 1 and s["by_section"]["s"]["inconsistent"] == 1
    page = render_html("t", [sec], {"summary": s, "version": "test", "elapsed_s": 0.0})
    assert "INCONSISTENT" in page and "2 vs 3" in page
    assert bad.to_dict()["consistent"] is False and good.to_dict()["consistent"] is True
    with pytest.raises(ValueError, match="consistent"):
        Claim("B", "x", "1", "2", "reproduced", consistent="yes")


def test_paper_b_workspace_row_is_consistent_with_its_closed_forms():
    """The row's own flag: measured extents against the closed forms of its explanation."""
    from spatialmech.present import paper_b

    claim, ws = paper_b.workspace_claim(step_deg=10.0, polish=False)
    assert claim.consistent is True, claim.consistency
    assert "WARNING" not in claim.note and "128.68" in claim.note and "51.32" not in claim.note
    assert "128.68" in claim.ours
    ev = claim.evidence
    assert max(ev["gap_deg"].values()) <= paper_b.WORKSPACE_AGREEMENT_DEG
    # every limit name shown is a whole name (the list is shortened by names, not characters)
    names = set(ws.active_limits)
    shown = claim.ours.split("active on the boundary of the set: ")[1]
    for part in re.split(r", | and ", shown):
        assert part in names or re.fullmatch(r"\d+ more", part), part


@pytest.mark.slow
def test_every_demo_report_row_is_consistent(demo_report):
    """Every claim row that cross-checks its explanation against its measured values agrees."""
    _, data = demo_report
    bad = [c["claim"] for c in data["claims"] if c["consistent"] is False]
    assert not bad and data["summary"]["inconsistent"] == 0
    assert any(c["consistent"] for c in data["claims"])  # the workspace row has its check


def test_present_paper_b_has_no_numerical_code():
    """The formulas live in the library: no linear algebra or inverse trigonometry in present/paper_b.py."""
    tree = ast.parse((SRC / "present" / "paper_b.py").read_text(encoding="utf-8"))
    calls = {ast.unparse(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
    banned = {c for c in calls if c.startswith("np.linalg") or c in {"np.arccos", "np.arctan", "np.arctan2", "np.arcsin"}}
    assert not banned, banned


# ------------------------------------------------------------------ 5. synth cs and the catalogue
def _check(defects, *, exact=True, dof=1):
    from spatialmech.synthesis.five_cs import FiveCSCheck

    z = np.zeros(7)
    return FiveCSCheck(z, z, z, np.full(7, exact), np.ones(7, bool), np.zeros((7, 5)), None, dof, dof, defects)


def _defects(*, circuits=((1, 2, 3, 4, 5, 6, 7),), order_defect=False, usable=(), plan=None):
    drivers = tuple(SimpleNamespace(driver=d, branch_defect=d not in usable, usable=d in usable)
                    for d in ("rot1", "slide1"))
    return SimpleNamespace(circuits=circuits, circuit_defect=len(circuits) > 1, order_defect=order_defect,
                           order=(1, 3, 2, 4, 5, 6, 7), drivers=drivers, plan=plan, usable_drivers=tuple(usable))


def test_synth_cs_success_needs_a_defect_free_driver():
    assert _check(_defects(usable=("rot1",))).success
    assert "success" in _check(_defects(usable=("rot1",))).verdict()
    c = _check(_defects(circuits=((1, 2, 3, 4), (5,), (6, 7)), usable=()))
    assert c.ok and not c.success
    assert c.verdict().startswith("FAILED: circuit defect") and "{P5}" in c.verdict()
    assert _check(_defects(order_defect=True)).verdict().startswith("FAILED: order defect")
    assert "branch defect for every driver" in _check(_defects()).verdict()
    assert not _check(None).success and "NOT analysed" in _check(None).verdict()
    assert _check(_defects(usable=("rot1",)), exact=False).verdict().startswith("not a solution")


@pytest.mark.slow
def test_synth_cs_of_paper_a_positions_reports_the_circuit_defect(paper_a_cs_family):
    """The five small-slide dyads of table 9 close at every position (the old 'all exact: True')
    but the linkage has a circuit defect: the synthesis says FAILED and why."""
    from spatialmech.synthesis.five_cs import assemble_5cs, check_5cs

    fam = paper_a_cs_family  # synthesize_cs(five_cs_positions(), seed=0, pick=5), tests/conftest.py
    check = check_5cs(assemble_5cs(fam.task, fam.picks), fam.picks, defects=True)
    assert check.ok and check.defects is not None
    assert check.defects.circuit_defect and not check.success
    assert check.verdict().startswith("FAILED: circuit defect")
    d = check.to_dict()
    assert d["success"] is False and d["circuit_defect"] is True and d["usable_drivers"] == []


def _imports(path: Path) -> set[str]:
    """Modules imported by a source file, relative imports resolved against the package."""
    rel = path.relative_to(SRC.parent).with_suffix("")
    pkg = list(rel.parts[:-1])
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = pkg[: len(pkg) - node.level + 1] if node.level else []
            mod = ".".join([*base, node.module] if node.module else base)
            out.add(mod)
            out |= {f"{mod}.{a.name}" for a in node.names}
    return out


@pytest.mark.parametrize("layer", ["geometry", "model", "kinematics", "analysis", "synthesis"])
def test_numerical_core_does_not_import_the_catalogue(layer):
    for path in sorted((SRC / layer).rglob("*.py")):
        bad = {m for m in _imports(path) if m.startswith(("spatialmech.catalog", "spatialmech.present",
                                                           "spatialmech.interfaces"))}
        assert not bad, (path.name, bad)


def test_the_catalogue_builds_the_4sps_cu_from_the_closed_form_data():
    from spatialmech.catalog import papers

    assert papers.FOUR_SPS_CU is k.PAPER_B_DIMENSIONS
    A, B = papers.four_sps_cu_points(0.1, 0.2)
    assert np.allclose(A, k.PAPER_B.platform_points) and np.allclose(B, k.PAPER_B.base_points)
    # the closed form recognises the model from the model itself (and other dimensions)
    assert k.geometry_of(papers.four_sps_cu(a=0.12, b=0.25, z0=0.3)) == k.FourSpsCuGeometry(a=0.12, b=0.25)
    assert k.geometry_of(sm.load_model("stewart-6sps")) is None
