"""Workspace and singularity slices over the task coordinates of lower-mobility mechanisms
(issue 11): the given coordinates sampled, the parasitic ones solved at every cell.

Before: ``workspace three-rps`` over (z, alpha, beta) sampled six-coordinate poses, almost none
of which a 3-RPS reaches (its x, y and yaw are parasitic): 200 s and an empty set; singularity
slices of it failed the same way."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech import catalog
from spatialmech.analysis.singularity import singularity, singularity_at_pose
from spatialmech.analysis.task_slice import task_singularity_slice
from spatialmech.analysis.workspace import (
    ConeLimit,
    WorkspaceLimits,
    configuration_checker,
    pose_checker,
    position_workspace,
    task_workspace,
    with_freedom_limits,
)
from spatialmech.errors import InputError
from spatialmech.geometry.rotations import euler_matrix
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.task_args import parse_axes
from spatialmech.kinematics.closure import Configuration, closure_scales, active_mask
from spatialmech.kinematics.backend import closure_residual
from spatialmech.kinematics.jacobian import complete_jacobian
from spatialmech.kinematics.task import default_task, solve_task, task_values
from spatialmech.kinematics.task_grid import TASK_NAMES
from spatialmech.model.mechanism import Pose

MODELS = ["three-rps", "three-upu", "three-prs", "delta"]
DEG = np.pi / 180


def build(name):
    if name not in catalog.REGISTRY:
        pytest.skip(f"{name} is not a ready-made model yet")
    return catalog.build(name)


def cones(mech, deg):
    """Cone limits of every S joint after a limb's first joint (the platform side)."""
    return WorkspaceLimits(cones=tuple(ConeLimit(j.name, (0, 0, 1), "platform", deg * DEG)
                                       for limb in mech.limbs for j in limb.joints[1:] if j.type == "S"))


def stroke_limits(mech, fraction):
    """Every actuator limited to its reference value +- ``fraction`` of the characteristic length
    (a slide) or +- ``3 fraction`` rad (a rotation)."""
    L = mech.characteristic_length
    out = {}
    for a in mech.actuators:
        f = mech.freedom(a).freedom
        half = fraction * L if f.kind == "P" else 3 * fraction
        out[a] = (f.offset - half, f.offset + half)
    return with_freedom_limits(mech, out)


def closure_norm(mech, config):
    row, _ = closure_scales(mech, active_mask(mech))
    return float(np.linalg.norm(row * closure_residual(mech, config)))


def check_inside(mech, ws, index):
    """A cell reported reachable closes, holds its given coordinates, respects every limit."""
    config = ws.config_at(index)
    assert config is not None and ws.feasible[index]
    assert closure_norm(mech, config) < 1e-9
    values = task_values(mech, config.D, ws.euler)
    for k, c in enumerate(ws.over):
        assert values[TASK_NAMES.index(c)] == pytest.approx(ws.grid[k][index[k]], abs=1e-9)
    for c, v in ws.fixed.items():
        assert values[TASK_NAMES.index(c)] == pytest.approx(v, abs=1e-9)
    assert np.allclose(values, ws.values[index], atol=1e-9)
    margins = configuration_checker(mech, ws.limits).margins(config)
    assert np.all(margins >= 0.0), dict(zip(ws.limit_names, margins, strict=True))


def check_boundary(mech, ws, max_points=8):
    """Each refined boundary point lies inside with its active limit nearly reached, and a
    little further out (2 tol along its grid coordinate) that limit is broken."""
    checker = configuration_checker(mech, ws.limits)
    names = list(checker.names)
    assert ws.boundary_limits and set(ws.boundary_limits) <= {*names, "closure"}
    picks = np.linspace(0, len(ws.boundary_limits) - 1, min(max_points, len(ws.boundary_limits))).astype(int)
    for j in picks:
        lim, k, x, config = ws.boundary_limits[j], int(ws.boundary_axes[j]), ws.boundary_points[j], ws.boundary_configs[j]
        assert closure_norm(mech, config) < 1e-9
        m = checker.margins(config) / checker.scales
        assert np.all(m >= 0.0)
        if lim != "closure":
            assert m[names.index(lim)] < 1e-3, (lim, m[names.index(lim)])
        # outwards: towards the other end of the final bracket, twice the tolerance
        out = x.copy()
        out[k] += np.sign(ws.boundary_outside[j][k] - x[k]) * 2 * ws.tol[ws.over[k]]
        given = {**ws.fixed, **dict(zip(ws.over, (float(v) for v in out), strict=True))}
        res = solve_task(mech, given, task=_task(ws), seed=config)
        if lim == "closure":
            assert not res.converged or checker.violated(res.config)
        else:
            # the named limit is broken just outside (on a symmetric mechanism another limit may
            # be broken there too, and be the first one the checker names)
            assert res.converged and checker.violated(res.config) is not None
            assert (checker.margins(res.config) / checker.scales)[names.index(lim)] < 0.0, lim


def _task(ws):
    from spatialmech.model.task import TaskCoordinates

    return TaskCoordinates(given=ws.given, euler=ws.euler)


def reference_grid(mech, n=7, span_deg=30.0, span_len=0.3):
    """Two of the default task's given coordinates on a grid through the reference, the third held."""
    task = default_task(mech)
    v0 = task_values(mech, np.eye(4), task.euler)
    given = list(task.given)
    over = {}
    for c in given[:2]:
        half = span_deg * DEG if c.startswith("a") else span_len * mech.characteristic_length
        c0 = v0[TASK_NAMES.index(c)]
        over[c] = (c0 - half, c0 + half, n)
    at = {c: float(v0[TASK_NAMES.index(c)]) for c in given[2:]}
    return over, at


# ------------------------------------------------------------------ every lower-mobility model
@pytest.mark.parametrize("name", MODELS)
def test_task_workspace_is_not_empty_contains_the_reference_and_is_bounded_by_limits(name):
    mech = stroke_limits(build(name), 0.1)
    over, at = reference_grid(mech)
    ws = task_workspace(mech, over, at=at, tol={c: (1e-2 * DEG if c.startswith("a") else 1e-5) for c in over})
    centre = (3, 3)
    assert ws.n_feasible > 0 and ws.feasible[centre], "the reference pose is in the grid and reachable"
    assert np.allclose(ws.values[centre], task_values(mech, np.eye(4), ws.euler), atol=1e-9)
    assert 0 < ws.reachable_fraction < 1
    check_inside(mech, ws, centre)
    for idx in np.argwhere(ws.feasible)[:: max(1, ws.n_feasible // 6)]:
        check_inside(mech, ws, tuple(int(i) for i in idx))
    assert any(lim.endswith(("max", "min")) for lim in ws.boundary_limits)
    check_boundary(mech, ws)
    # the extents are those of the refined set, bounded by the sampled box
    for k, c in enumerate(ws.over):
        e = ws.extents[c]
        assert ws.grid[k][0] <= e.lo <= e.hi <= ws.grid[k][-1]


# ------------------------------------------------------------------ 3-RPS
@pytest.fixture(scope="module")
def rps():
    return catalog.build("three-rps")


@pytest.fixture(scope="module")
def rps_ws(rps):
    return task_workspace(rps, {"a2": (-40 * DEG, 40 * DEG, 9), "a3": (-40 * DEG, 40 * DEG, 9)}, at={"z": 0.3},
                          limits=cones(rps, 45.0), tol=1e-2 * DEG)


def test_three_rps_workspace_over_its_tilts_solves_x_y_and_yaw(rps, rps_ws):
    ws = rps_ws
    assert ws.given == ("z", "a2", "a3") and ws.solved == ("x", "y", "a1") and ws.fixed == {"z": 0.3}
    assert ws.feasible[4, 4] and np.allclose(ws.values[4, 4], [0, 0, 0.3, 0, 0, 0], atol=1e-9)
    # parasitic motion: tilting moves the platform point sideways and turns it about z
    inside = ws.values[ws.feasible]
    assert np.ptp(inside[:, 0]) > 1e-4 and np.ptp(inside[:, 3]) > 1e-3
    for c in ("a2", "a3"):
        e = ws.extents[c]
        assert e.lo < 0 < e.hi and e.lo_limit.endswith("cone") and e.hi_limit.endswith("cone")
    assert set(ws.active_limits) <= {"S1 cone", "S2 cone", "S3 cone"}
    check_boundary(rps, ws)
    for idx in np.argwhere(ws.feasible):
        check_inside(rps, ws, tuple(int(i) for i in idx))


def test_tighter_cones_give_a_subset(rps, rps_ws):
    tight = task_workspace(rps, {"a2": (-40 * DEG, 40 * DEG, 9), "a3": (-40 * DEG, 40 * DEG, 9)}, at={"z": 0.3},
                           limits=cones(rps, 40.0), tol=0.1 * DEG)
    assert tight.n_feasible < rps_ws.n_feasible
    assert not np.any(tight.feasible & ~rps_ws.feasible)
    for c in ("a2", "a3"):
        assert rps_ws.extents[c].lo <= tight.extents[c].lo <= tight.extents[c].hi <= rps_ws.extents[c].hi
    assert np.allclose(tight.values[tight.converged], rps_ws.values[tight.converged], atol=1e-9)


def test_without_limits_only_the_grid_bounds_the_set(rps):
    ws = task_workspace(rps, {"a2": (-10 * DEG, 10 * DEG, 3), "a3": (-10 * DEG, 10 * DEG, 3)}, at={"z": 0.33})
    assert ws.limit_names == () and ws.reachable_fraction == 1.0 and ws.boundary_limits == ()
    assert all(ws.extents[c].lo_limit == ws.extents[c].hi_limit == "box" for c in ("a2", "a3"))


def test_a_coordinate_the_task_solves_cannot_be_swept(rps):
    with pytest.raises(InputError, match=r"x is solved \(parasitic\) for three-rps"):
        task_workspace(rps, {"x": (-0.01, 0.01, 3), "a2": (-0.1, 0.1, 3)})
    with pytest.raises(InputError, match=r"over\.a2: expected lo < hi"):
        task_workspace(rps, {"a2": (0.1, -0.1, 3)})
    with pytest.raises(InputError, match=r"at\.a2: a2 is a grid coordinate"):
        task_workspace(rps, {"a2": (-0.1, 0.1, 3)}, at={"a2": 0.0})


# ------------------------------------------------------------------ 3-UPU: the position workspace
def upu_limited():
    return with_freedom_limits(catalog.build("three-upu"), {f"L{i}.slide": (0.30, 0.40) for i in (1, 2, 3)})


def test_three_upu_task_workspace_over_x_y_has_no_rotation_and_matches_the_pose_check():
    """A 3-UPU translates: its task workspace over (x, y) at fixed z is the position workspace at
    zero orientation.  Checked here at the refined boundary points (inside, and just outside)
    with the general pose checker (one inverse position per pose)."""
    mech = upu_limited()
    ws = task_workspace(mech, {"x": (-0.1, 0.1, 9), "y": (-0.1, 0.1, 9)}, at={"z": 0.3}, tol=1e-5)
    assert ws.solved == ("a1", "a2", "a3")
    assert np.allclose(ws.values[ws.converged][:, 3:], 0.0, atol=1e-9)
    checker = pose_checker(mech, ws.limits, method="general")
    picks = np.linspace(0, len(ws.boundary_limits) - 1, 3).astype(int)
    for j in picks:
        k, x = int(ws.boundary_axes[j]), ws.boundary_points[j]
        out = x.copy()
        out[k] += np.sign(ws.boundary_outside[j][k] - x[k]) * 3 * ws.tol[ws.over[k]]
        R = np.eye(3)[None]
        assert checker.feasible(R, np.array([[*x, 0.3]]))[0]
        assert checker.violated(R, np.array([[*out, 0.3]]))[0] == ws.boundary_limits[j]


@pytest.mark.slow
def test_three_upu_task_workspace_equals_the_position_workspace_cell_by_cell():
    mech = upu_limited()
    pw = position_workspace(mech, at={"z": 0.3, "alpha": 0, "beta": 0, "gamma": 0},
                            bounds={"x": (-0.1, 0.1), "y": (-0.1, 0.1)}, step=0.05, tol=1e-3, polish=False)
    ws = task_workspace(mech, {"x": (-0.1, 0.1, 5), "y": (-0.1, 0.1, 5)}, at={"z": 0.3}, tol=1e-3)
    assert [list(g) for g in pw.grid] == [list(g) for g in ws.grid]
    assert np.array_equal(pw.feasible, ws.feasible)
    for c in ("x", "y"):
        a, b = pw.extents[c], ws.extents[c]
        assert a.lo == pytest.approx(b.lo, abs=2e-3) and a.hi == pytest.approx(b.hi, abs=2e-3)
        assert (a.lo_limit, a.hi_limit) == (b.lo_limit, b.hi_limit)


# ------------------------------------------------------------------ singularity slices
def test_three_rps_singularity_slice_agrees_with_the_analysis_at_each_pose(rps):
    s = task_singularity_slice(rps, {"a2": np.radians(np.linspace(-20, 20, 5)), "a3": np.radians(np.linspace(-20, 20, 5))},
                               at={"z": 0.3})
    assert s.names == ("a2", "a3") and s.solved == ("x", "y", "a1") and np.isfinite(s.sigma_min).all()
    ref = Configuration.reference(rps)
    at_ref = singularity(rps, ref)
    assert s.sigma_min[2, 2] == pytest.approx(at_ref.sigma_min, rel=1e-9)
    assert s.det[2, 2] == pytest.approx(complete_jacobian(rps, ref).det, rel=1e-9)
    # elsewhere: the pose built from the solved coordinates, analysed on its own
    for j, i in ((0, 0), (1, 3), (4, 2)):
        v = s.values[j, i]
        pose = Pose(euler_matrix(s.euler, v[3:]), v[:3])
        r = singularity_at_pose(rps, pose)
        assert s.sigma_min[j, i] == pytest.approx(r.sigma_min, rel=1e-7)
        assert np.sign(s.det[j, i]) == np.sign(s.det[2, 2])  # no singularity inside +-20 deg


def test_delta_singularity_slice_keeps_the_sign_of_det_where_it_is_far_from_singular():
    """The Delta is a link-and-joint graph: its constraint rows are an orthonormal basis of
    arbitrary orientation at each configuration, so det J's sign flipped from point to point
    before the orientation was carried along the slice."""
    delta = catalog.build("delta")
    s = task_singularity_slice(delta, {"x": np.linspace(-0.15, 0.15, 5), "y": np.linspace(-0.15, 0.15, 5)})
    assert s.solved == ("a1", "a2", "a3") and np.isfinite(s.det).all()
    assert np.nanmin(s.sigma_min) > 0.1 and len(set(np.sign(s.det).ravel())) == 1
    assert np.allclose(s.values[..., 3:], 0.0, atol=1e-9)  # it translates
    assert s.sigma_min[2, 2] == pytest.approx(singularity(delta, Configuration.reference(delta)).sigma_min, rel=1e-9)


# ------------------------------------------------------------------ command line
def run(*args):
    return CliRunner().invoke(cli, list(args))


def test_cli_workspace_task_text_and_json(tmp_path):
    r = run("workspace", "three-rps", "--task", "--over", "a2:-40:40:5,a3:-40:40:5", "--at", "z=0.33",
            "--cone", "S1=45,S2=45,S3=45", "--tol-deg", "0.1", "--plot", str(tmp_path / "ws.png"))
    assert r.exit_code == 0, r.output
    assert "solved: x, y, a1" in r.output and "limits: S" in r.output and (tmp_path / "ws.png").stat().st_size > 0
    d = json.loads(run("workspace", "three-rps", "--task", "--over", "a2:-40:40:5,a3:-40:40:5", "--at", "z=0.33",
                       "--limit", "actuators=0.25:0.36", "--json").output)
    assert d["kind"] == "task" and d["given"] == ["z", "a2", "a3"] and d["solved"] == ["x", "y", "a1"]
    assert d["fixed"] == {"z_len": 0.33} and set(d["extents"]) == {"a2_deg", "a3_deg"}
    assert set(d["samples"]["values"]) == {"x_len", "y_len", "z_len", "a1_deg", "a2_deg", "a3_deg"}
    assert d["samples"]["axes"]["a2_deg"] == [-40.0, -20.0, 0.0, 20.0, 40.0]


@pytest.mark.slow
def test_a_pose_workspace_bounded_by_closure_points_to_the_task_workspace():
    """The issue's symptom (a 3-RPS pose workspace: 200 s, empty): the pose path still samples
    six-coordinate poses, and now says why the set is a sliver and which command to run."""
    r = run("workspace", "three-rps", "--orientation", "--at", "z=0.33,gamma=0,alpha=0", "--step-deg", "30",
            "--tol-deg", "1")
    assert r.exit_code == 0, r.output
    assert "limits: closure / closure" in r.output
    assert "spatialmech workspace three-rps --task --over a2:-20:20:41,a3:-20:20:41 --at z=0.3" in r.output


@pytest.mark.parametrize("args, message", [
    (["--over", "a2:-1:1:3"], "--over: only with --task"),
    (["--task"], "--task: give the grid with --over"),
    (["--task", "--orientation", "--over", "a2:-1:1:3"], "--orientation, --task: give one of them"),
    (["--task", "--over", "a2:-1:1:1"], "--over: a2 N must be 2..400"),
    (["--task", "--over", "alpha:-1:1:3"], "--over: expected NAME:MIN:MAX:N"),
    (["--task", "--over", "a2:-1:1:3", "--at", "alpha=3"], "--at: unknown task coordinate 'alpha'"),
    (["--task", "--over", "x:-0.01:0.01:3,a2:-1:1:3"], "x is solved (parasitic)"),
    (["--task", "--over", "a2:-1:1:3", "--cone", "R1=30"], "cones: joint 'R1' is a R joint"),
    (["--task", "--over", "a2:-1:1:3", "--limit", "L9.slide=0:1"], "--limit:"),
    (["--task", "--over", "a2:-1:1:3", "--free", "a1"], "three-rps's output has 3 freedoms, so 3 coordinates are given"),
    (["--task", "--over", "z:1e8:1e9:2"], "over.z: 1e+09 from the reference is more than 1e+06 times the size"),
    (["--task", "--over", "a2:-1e308:1e308:2"], "--over: a2 MIN and MAX are too far apart"),
])
def test_cli_workspace_task_errors_are_one_line(args, message):
    r = run("workspace", "three-rps", *args)
    assert r.exit_code == 2 and r.output.count("\n") == 1 and message in r.output, r.output


@pytest.mark.parametrize("model, given", [("three-upu", "x, y, z"), ("three-rps", "z, a2, a3")])
def test_cli_workspace_task_without_over_suggests_a_grid_of_the_models_own_coordinates(model, given):
    r = run("workspace", model, "--task")
    assert r.exit_code == 2 and f"over the given coordinates ({given})" in r.output, r.output
    words = r.output.split("e.g. ")[1].split()
    over, at = words[words.index("--over") + 1], words[words.index("--at") + 1]
    assert {a.split(":")[0] for a in over.split(",")} | {a.split("=")[0] for a in at.split(",")} == set(given.split(", "))
    coarse = ",".join(a.rsplit(":", 1)[0] + ":3" for a in over.split(","))  # the suggestion runs as given
    ok = run("workspace", model, "--task", "--over", coarse, "--at", at, "--json")
    assert ok.exit_code == 0, ok.output
    assert json.loads(ok.output)["given"] == given.split(", ")


def test_cli_singularity_task_slice(tmp_path):
    r = run("singularity", "three-rps", "--slice", "a2:-30:30:3,a3:-30:30:3", "--at", "z=0.33",
            "--plot", str(tmp_path / "s.png"))
    assert r.exit_code == 0, r.output
    assert "over task coordinates a2 x a3" in r.output and "solved x, y, a1" in r.output
    d = json.loads(run("singularity", "three-rps", "--slice", "a2:-30:30:3,a3:-30:30:3", "--at", "z=0.33",
                       "--json").output)
    assert d["result"] == "singularity_task_slice" and d["fixed"] == {"z_len": 0.33}
    assert set(d["solved_values"]) == {"x_len", "y_len", "a1_deg"} and d["axes"][0]["values_deg"] == [-30.0, 0.0, 30.0]
    bad = run("singularity", "three-rps", "--xyz", "0", "0", "0.3", "--euler", "ZYX", "0", "0", "0",
              "--slice", "a2:-30:30:3,a3:-30:30:3", "--at", "z=0.33")
    assert bad.exit_code == 2 and "--at: only with --slice and no pose" in bad.output


# ------------------------------------------------------------------ parsing
@settings(max_examples=50, deadline=None)
@given(st.sampled_from(TASK_NAMES), st.floats(-1e3, 1e3), st.floats(1e-3, 1e3), st.integers(2, 400))
def test_parse_axes_gives_si_values(name, lo, width, n):
    hi = lo + width
    got = parse_axes(f"{name}:{lo!r}:{hi!r}:{n}")[name]
    want = np.linspace(lo, hi, n)
    assert np.allclose(got, np.radians(want) if name.startswith("a") else want, rtol=1e-12, atol=1e-12)


# ------------------------------------------------------------------ malformed input: one-line errors
junk = st.one_of(st.sampled_from(["", "nan", "inf", "-inf", "1e400", "1e308", "-1e308", "0", "abc", "5e-324", "-0"]),
                 st.floats(-90, 90).map(lambda x: f"{x:.4g}"))


@st.composite
def axes_specs(draw):
    def axis():
        name = draw(st.sampled_from(["x", "y", "z", "a1", "a2", "a3", "alpha", ""]))
        n = draw(st.sampled_from(["2", "3", "1", "401", "x", "2.5"]))
        parts = [name, draw(junk), draw(junk), n]
        return ":".join(parts[: draw(st.sampled_from([4, 4, 4, 3]))])

    return ",".join(axis() for _ in range(draw(st.integers(0, 3))))


pairs = st.lists(st.tuples(st.sampled_from(["x", "z", "a1", "a2", "a3", "S1", "L1.slide", "actuators", "q", ""]), junk),
                 max_size=2).map(lambda kv: ",".join(f"{k}={v}" for k, v in kv))


def check_one_line(args):
    r = CliRunner().invoke(cli, args)
    assert r.exception is None or isinstance(r.exception, SystemExit), (args, repr(r.exception), r.output)
    assert r.exit_code in (0, 1, 2) and "Traceback" not in r.output, (args, r.exit_code, r.output)
    if r.exit_code:
        assert r.stderr.strip().splitlines()[-1].startswith("error: "), (args, r.stderr)
    elif "--json" in args:
        json.loads(r.stdout, parse_constant=lambda c: pytest.fail(f"{args}: {c} in the JSON output"))


@settings(max_examples=int(__import__("os").environ.get("T2_FUZZ", "40")), deadline=None)
@given(axes_specs(), st.one_of(st.none(), pairs), st.one_of(st.none(), st.sampled_from(["x,y,a1", "a1", "q", "", "x,x"])),
       st.one_of(st.none(), pairs), st.one_of(st.none(), st.sampled_from(["actuators=0.2:0.4", "L1.slide=1:0", "L1=a:b",
                                                                          "R1.rot=-10:10", "nosuch=0:1"])),
       st.sampled_from([[], ["--json"]]))
def test_fuzz_workspace_task_and_task_slices(over, at, free, cone, limit, as_json):
    """Junk grids, held values, free coordinates and limits: a result or a one-line error
    (exit 2), never a traceback, never NaN in the JSON."""
    args = ["workspace", "three-rps", "--task", "--over", over, "--tol-deg", "1", "--tol", "1e-3", *as_json]
    for opt, v in (("--at", at), ("--free", free), ("--cone", cone), ("--limit", limit)):
        if v is not None:
            args += [opt, v]
    check_one_line(args)
    slice_args = ["singularity", "three-rps", "--slice", over, *as_json]
    for opt, v in (("--at", at), ("--free", free)):
        if v is not None:
            slice_args += [opt, v]
    check_one_line(slice_args)
