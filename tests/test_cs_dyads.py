"""Paper A section 3: seven-position synthesis of CS dyads (eqs 22-26) and 5-CS linkages.

Figures measured on table 9 (stated tolerances in each test):
- printed limbs of linkages 1-3 (tables 1-13, 3 decimals): largest |eq 24| (as a length
  difference) or |eq 25| = 0.0100; printed S centres vs ``D_j M1``: <= 0.0020;
- projected onto the family: distance <= 0.0042, printed slides reproduced to <= 0.0006;
  the rebuilt (refitted) linkages pass exactly through the 7 positions, while the printed ones
  miss them by up to 0.295 (linkage 3, P4);
- family (60 starts, seed 0): 9 branch pieces inside the box of 8 task scales, smallest
  ``max |s|`` = 5.3028 (then local minima 9.762, 10.904, 11.185, 11.809); five picks give a
  5-CS with pose errors < 1e-15 and 1 DOF.
"""


import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from spatialmech.catalog.papers import five_cs, five_cs_data, five_cs_positions
from spatialmech.geometry.rotations import inverse_transform, transform
from spatialmech.interfaces.cli import cli
from spatialmech.model.mechanism import Pose
from spatialmech.synthesis import cs_dyads as cd
from spatialmech.synthesis.cs_dyads import (
    CSDyad,
    cs_task,
    dyad_from_limb,
    dyad_jacobian,
    dyad_residual,
    pick_small_slides,
    project_dyad,
    solve_dyad,
    synthesize_cs,
    trace_branch,
)
from spatialmech.synthesis.five_cs import assemble_5cs, check_5cs, paper_a_check

from .conftest import seeds


# the paper-A family (tests/conftest.py: paper_a_cs_family, one for the session) costs ~4 s:
# every test that uses it (or claims) is marked slow
@pytest.fixture(scope="module")
def claims(paper_a_cs_family):
    return paper_a_check(five_cs_positions(), five_cs_data()["linkages"], family=paper_a_cs_family)


def _printed_limbs():
    task = cs_task(five_cs_positions())
    data = five_cs_data()["linkages"]
    out = []
    for k in sorted(data):
        lk = data[k]
        for i in range(5):
            out.append((k, i, dyad_from_limb(task, lk["u"][i], lk["B1"][i], lk["M_by_position"][0][i], lk["s"][i])))
    return out


def _random_task_from_dyad(seed):
    """Seven poses of a platform whose point M moves on the cylinder of a known CS dyad (the
    other freedoms random): the dyad must be in the family of these poses."""
    r = np.random.default_rng(seed)
    u = r.normal(size=3)
    u /= np.linalg.norm(u)
    B1 = r.uniform(-2, 2, 3)
    w = np.cross(u, r.normal(size=3))
    M1 = B1 + r.uniform(0.5, 2.0) * w / np.linalg.norm(w)
    p1 = M1 + r.uniform(-1, 1, 3)
    poses, slides = [Pose(np.eye(3), p1, "P1")], [0.0]
    for j in range(1, 7):
        th, s = r.uniform(-1.2, 1.2), r.uniform(-1.5, 1.5)
        Rj = Rotation.from_rotvec(r.normal(scale=0.5, size=3)).as_matrix()
        Mj = B1 + s * u + Rotation.from_rotvec(th * u).as_matrix() @ (M1 - B1)
        tj = Mj - Rj @ M1
        poses.append(Pose(Rj, Rj @ p1 + tj, f"P{j + 1}"))
        slides.append(s)
    dy = CSDyad(u, B1, M1, np.array(slides), float(np.linalg.norm(M1 - B1)), 0.0)
    return tuple(poses), dy


# ------------------------------------------------------------------ the equations
@settings(max_examples=25)
@given(seeds)
def test_jacobian_matches_central_differences(seed):
    """Analytic Jacobian of eqs 24-26 against central differences (rel. 1e-6)."""
    r = np.random.default_rng(seed)
    task = cs_task(_random_task_from_dyad(seed)[0])
    x = r.normal(size=15)
    J = dyad_jacobian(x, task.D)
    h = 1e-6
    Jn = np.stack([(dyad_residual(x + h * e, task.D) - dyad_residual(x - h * e, task.D)) / (2 * h)
                   for e in np.eye(15)], axis=1)
    assert np.max(np.abs(J - Jn)) <= 1e-6 * max(1.0, np.max(np.abs(J)))


def test_residual_and_jacobian_are_vectorised():
    r = np.random.default_rng(3)
    task = cs_task(five_cs_positions())
    X = r.normal(size=(2, 3, 15))
    F, J = dyad_residual(X, task.D), dyad_jacobian(X, task.D)
    assert F.shape == (2, 3, 14) and J.shape == (2, 3, 14, 15)
    for a in range(2):
        for b in range(3):
            assert np.allclose(F[a, b], dyad_residual(X[a, b], task.D), atol=1e-12)
            assert np.allclose(J[a, b], dyad_jacobian(X[a, b], task.D), atol=1e-12)


@settings(max_examples=25)
@given(seeds)
def test_residual_invariants_flip_and_world_frame(seed):
    """(u, s) -> (-u, -s) is the same dyad (|residual| unchanged), and a change of world frame
    G (poses G T_j, points G X, axis R_G u) leaves the residual unchanged (1e-9)."""
    r = np.random.default_rng(seed)
    poses, _ = _random_task_from_dyad(seed)
    task = cs_task(poses)
    x = r.normal(size=15)
    F = dyad_residual(x, task.D)
    assert np.allclose(np.abs(dyad_residual(cd._flip(x), task.D)), np.abs(F), atol=1e-9)
    G = transform(Rotation.random(random_state=seed).as_matrix(), r.uniform(-5, 5, 3))
    Dg = G @ task.D @ inverse_transform(G)
    xg = np.r_[G[:3, :3] @ x[0:3] + G[:3, 3], G[:3, :3] @ x[3:6] + G[:3, 3], G[:3, :3] @ x[6:9], x[9:]]
    assert np.allclose(dyad_residual(xg, Dg), F, atol=1e-9 * max(1.0, np.max(np.abs(F))))


@pytest.mark.slow
def test_dimension_count_is_one(paper_a_cs_family):
    """15 unknowns, 14 equations, and no gauge freedom: the Jacobian has full rank 14 along the
    family (smallest of its 14 singular values, nondimensional, > 1e-4 at every 25th tracked
    point), so the solution set is a curve; eq 25 at j = 1 pins B1 to the foot of the
    perpendicular from M1 (|u.(M1 - B1)| < 1e-9)."""
    fam = paper_a_cs_family
    task = fam.task
    Dn = task.nondim_D()
    worst = np.inf
    for b in fam.branches:
        Y = cd._to_nondim(task, b.points[::25])
        sv = np.linalg.svd(dyad_jacobian(Y, Dn), compute_uv=False)
        assert sv.shape[-1] == 14
        worst = min(worst, float(np.min(sv[:, -1])))
        assert np.max(np.abs(np.einsum("ka,ka->k", b.points[:, 6:9], b.points[:, 3:6] - b.points[:, 0:3]))) < 1e-9
    assert worst > 1e-4


@pytest.mark.slow
def test_bad_input_raises_naming_the_argument(paper_a_cs_family):
    poses = five_cs_positions()
    with pytest.raises(ValueError, match=r"^task_poses: .*exactly 7"):
        synthesize_cs(poses[:6])
    with pytest.raises(ValueError, match=r"^task_poses\[2\]"):
        cs_task([*poses[:2], "P3", *poses[3:]])
    with pytest.raises(ValueError, match=r"^task_poses: all seven poses coincide"):
        cs_task([poses[0]] * 7)
    with pytest.raises(ValueError, match=r"^x0"):
        solve_dyad(poses, np.full(15, np.nan))
    with pytest.raises(ValueError, match=r"^n_starts"):
        synthesize_cs(poses, n_starts=0)
    with pytest.raises(ValueError, match=r"^extent"):
        synthesize_cs(poses, extent=-1.0)
    with pytest.raises(ValueError, match=r"^dyads: .*exactly 5"):
        assemble_5cs(poses, paper_a_cs_family.picks[:4])
    with pytest.raises(ValueError, match=r"^slides"):
        dyad_from_limb(poses, [1, 0, 0], [0, 0, 0], [0, 1, 0], [1, 2, 3])
    with pytest.raises(ValueError, match=r"^u"):
        dyad_from_limb(poses, [0, 0, 0], [0, 0, 0], [0, 1, 0])


# ------------------------------------------------------------------ generic tasks
@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 7])
def test_known_dyad_is_in_the_family_and_five_of_its_branch_make_an_exact_5cs(seed):
    """Round trip on a generic task built from a known dyad: the dyad satisfies eqs 24-26
    (1e-12); least squares from it perturbed by 1e-3 lands back within 1e-2; its branch is
    tracked with residual < 1e-10, and five dyads spread along that branch form a 5-CS that
    passes exactly through the 7 poses (IK residual < 1e-10, 1 DOF)."""
    poses, true = _random_task_from_dyad(seed)
    task = cs_task(poses)
    assert np.max(np.abs(dyad_residual(true.vector, task.D))) < 1e-12
    noisy = true.vector + np.random.default_rng(seed).normal(scale=1e-3, size=15)
    x, ok, _ = solve_dyad(task, noisy)
    assert ok and np.linalg.norm(x - true.vector) < 1e-2
    br = trace_branch(task, true, extent=6.0)
    assert br.residual < 1e-10 and len(br.arc) > 50
    idx = br.sample(7)[1:-1][:5]
    dyads = [cd._dyad(task, br.points[i]) for i in idx]
    ch = check_5cs(assemble_5cs(task, dyads), dyads)
    assert np.all(ch.exact) and ch.max_pose_error < 1e-9 and np.max(ch.ik_residuals) < 1e-10
    assert ch.dof == 1 and ch.dof_instantaneous == 1
    assert np.max(np.abs(ch.slide_errors)) < 1e-8


# ------------------------------------------------------------------ paper A claims
def test_paper_a_printed_limbs_satisfy_eqs_24_25_to_the_printed_precision():
    """Claim (a): each printed limb (tables 1-13, 3 decimals, u normalised) satisfies the dyad
    equations at the 7 positions only to the rounding: largest |eq 24| (link length change) or
    |eq 25| (u.(M - B)) measured 0.0100 (tolerance 0.011; conventions.md: up to 0.01 / 0.0095),
    and not exactly (> 1e-3).  The printed S centres agree with M_j = D_j M1 (eq 23, table 9
    poses 'ZXY') to 0.0020 (tolerance 0.0025)."""
    task = cs_task(five_cs_positions())
    data = five_cs_data()["linkages"]
    res = [d.residual for _, _, d in _printed_limbs()]
    assert max(res) < 0.011 and min(res) > 1e-3
    for k, i, d in _printed_limbs():
        Mp = np.array([data[k]["M_by_position"][j][i] for j in range(7)])
        Mc = task.D[:, :3, :3] @ d.M1 + task.D[:, :3, 3]
        assert np.max(np.abs(Mp - Mc)) < 0.0025, (k, i)


@pytest.mark.slow
def test_paper_a_printed_limbs_project_onto_the_synthesised_family(paper_a_cs_family, claims):
    """Claim (b): the nearest dyad of the family to each printed limb (least squares over the 15
    printed numbers) is within 0.005 of it (measured 0.0042, consistent with 3-decimal rounding
    amplified by slides of 10-30), the printed slides s2..s7 are reproduced to 0.001 (measured
    0.0006), and that dyad lies on a branch found by the multi-start search (within 2e-3 task
    scales of a tracked polyline: the family found contains all 13 distinct printed limbs)."""
    cl = claims
    fam = paper_a_cs_family
    Y = [cd._to_nondim(fam.task, b.points) for b in fam.branches]
    for k, projs in cl.projections.items():
        for i, p in enumerate(projs):
            assert p.converged, (k, i)
            assert p.fitted.residual < 1e-9
            assert p.distance < 0.005 and p.slide_change < 0.001, (k, i, p.distance, p.slide_change)
            y = cd._to_nondim(fam.task, p.fitted.vector)
            d = min(min(cd._polyline_distance(P, y), cd._polyline_distance(P, cd._flip(y))) for P in Y)
            assert d < 2e-3, (k, i, d)


@pytest.mark.slow
def test_paper_a_refitted_linkages_pass_exactly_through_the_seven_positions(claims):
    """The three paper linkages rebuilt from their projected limbs close exactly at the 7
    positions (pose error < 1e-9, 1 DOF), whereas the printed (rounded) linkages only come
    within 0.295 (linkage 3 at P4; the nearest closed configuration, measured 0.2948; tolerance
    0.28-0.31) - the reason a refit is needed before judging circuits on printed data."""
    cl = claims
    for k, ch in cl.refitted.items():
        assert ch.ok and ch.max_pose_error < 1e-9 and np.max(np.abs(ch.slide_errors)) < 1e-9, k
    printed = check_5cs(five_cs(3))
    assert 0.28 < float(np.max(printed.position_errors)) < 0.31
    assert int(np.argmax(printed.position_errors)) == 3


@pytest.mark.slow
def test_paper_a_any_five_dyads_of_the_family_form_a_5cs(paper_a_cs_family, claims):
    """Claim (c) with the five small-slide picks: the 5-CS closes exactly at the 7 positions
    (pose error < 1e-9, IK residual < 1e-10), has 1 DOF (formula and numerical rank), and the
    C slides solved at each position equal the dyads' s_j (1e-9)."""
    fam = paper_a_cs_family
    ch = claims.synthesised
    assert len(fam.picks) == 5
    assert ch.ok and ch.max_pose_error < 1e-9 and np.max(ch.ik_residuals) < 1e-10
    assert ch.dof == 1 and ch.dof_instantaneous == 1
    assert np.max(np.abs(ch.slide_errors)) < 1e-9


@pytest.mark.slow
@settings(max_examples=4)
@given(st.integers(0, 10**6))
def test_any_five_family_points_form_an_exact_5cs(paper_a_cs_family, seed):
    """Claim (c) as a property: five random tracked dyads (distinct branches or far apart on
    one) give a 5-CS through the 7 positions (pose error < 1e-9) with 1 DOF."""
    fam = paper_a_cs_family
    r = np.random.default_rng(seed)
    P = fam.all_points()
    idx = []
    for i in r.permutation(len(P)):
        if all(np.linalg.norm(P[i] - P[j]) > 2.0 for j in idx):
            idx.append(int(i))
        if len(idx) == 5:
            break
    dyads = [cd._dyad(fam.task, P[i]) for i in idx]
    ch = check_5cs(assemble_5cs(fam.task, dyads), dyads)
    # the claim's bound (pose error < 1e-9): a tracked dyad is accurate to ~1e-10, so the stricter
    # `exact` flag (the closure tolerance) can miss by a few 1e-11 on some draws
    assert ch.max_pose_error < 1e-9 and ch.dof == 1


@pytest.mark.slow
def test_paper_a_small_slide_picks(paper_a_cs_family):
    """'Choose dyads with small slides': the first pick is the smallest max |s_j| of the family
    (measured 5.3028 on table 9; tolerance 5.25-5.35), no tracked point is smaller by more than
    1e-9, moving along the curve from it increases max |s| (a refined minimum), the picks are
    sorted by max |s| within the local minima (measured 5.303, 9.762, 10.904, 11.185, 11.809)
    and pairwise at least one task scale apart."""
    fam = paper_a_cs_family
    picks = fam.picks
    g = [p.max_abs_slide for p in picks]
    assert 5.25 < g[0] < 5.35
    assert g[0] <= min(float(np.min(b.max_abs_slide)) for b in fam.branches) + 1e-9
    assert g == sorted(g)
    task = fam.task
    prob = cd._problem(task)
    y = cd._to_nondim(task, picks[0].vector)
    t = prob.tangent(y)
    for sig in (-1e-3, 1e-3):
        z, ok, _, _ = cd.correct_on_hyperplane(prob, y + sig * t, t, 1e-11, 30)
        assert ok and np.max(np.abs(z[9:])) * task.scale > g[0]
    Y = [cd._to_nondim(task, p.vector) for p in picks]
    for a in range(5):
        for b in range(a):
            assert min(np.linalg.norm(Y[a] - Y[b]), np.linalg.norm(cd._flip(Y[a]) - Y[b])) >= 1.0
    assert len(pick_small_slides(fam, 2)) == 2


@pytest.mark.slow
def test_family_to_dict_is_json_serialisable(paper_a_cs_family, claims):
    import json

    d = paper_a_cs_family.to_dict(samples=10)
    s = json.dumps(d, allow_nan=False)
    assert '"picks"' in s and d["n_branches"] == len(paper_a_cs_family.branches)
    pts = sum(len(b["points"]) for b in d["branches"])
    assert 10 <= pts <= 10 + 2 * d["n_branches"]
    json.dumps(claims.to_dict(), allow_nan=False)


@pytest.mark.slow
def test_projection_of_an_exact_dyad_does_not_move_it(paper_a_cs_family):
    p = project_dyad(five_cs_positions(), paper_a_cs_family.picks[0])
    assert p.converged and p.distance < 1e-10


# ------------------------------------------------------------------ CLI
@pytest.mark.slow
def test_cli_synth_cs_json_and_save(tmp_path):
    from spatialmech.model.schema import load

    out = tmp_path / "five-cs.toml"
    r = CliRunner().invoke(cli, ["synth", "cs", "--json", "--samples", "6", "--starts", "6", "--save", str(out)])
    assert r.exit_code == 0, r.output
    import json

    d = json.loads(r.output)
    assert len(d["picks"]) == 5 and d["five_cs"]["dof"] == 1 and d["five_cs"]["ok"]
    assert max(d["five_cs"]["position_errors_len"]) < 1e-9 and d["length_unit"] == "unit"
    p = d["branches"][0]["points"][0]
    assert set(p) >= {"u", "B1_len", "M1_len", "slides_len", "max_abs_slide_len", "link_length_len"}
    m = load(out)
    assert [lb.joints[0].type for lb in m.limbs] == ["C"] * 5 and len(m.positions) == 7
    assert check_5cs(m).max_pose_error < 1e-9


def test_cli_synth_cs_positions_file_and_errors(tmp_path):
    lines = []
    for P in five_cs_positions()[:6]:
        ang = Rotation.from_matrix(P.R).as_euler("ZXY", degrees=True)
        lines += ["[[positions]]", f"point = {P.p.tolist()}",
                  f'euler = {{ seq = "ZXY", angles_deg = {ang.tolist()} }}', ""]
    f = tmp_path / "six.toml"
    f.write_text("\n".join(lines), encoding="utf-8")
    r = CliRunner().invoke(cli, ["synth", "cs", "--positions", str(f)])
    assert r.exit_code == 2 and "error: task_poses" in r.output
    r = CliRunner().invoke(cli, ["synth", "cs", "--pick", "3", "--save", str(tmp_path / "x.toml")])
    assert r.exit_code == 2 and "error: save" in r.output
