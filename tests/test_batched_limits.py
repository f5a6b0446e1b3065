"""Limits in the compiled batch (issue 29): the general pose checker's cone and interference
margins, the configuration checker of the task workspace, the compiled task solve; each against
its Python reference (the per-pose path, or ``backend.python_reference()``): margins to 1e-10,
the same active limits and statuses."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis.workspace import ConeLimit, WorkspaceLimits, configuration_checker, pose_checker
from spatialmech.analysis.workspace.checker import segment_distance
from spatialmech.analysis.workspace.limits import paper_b_limits, with_freedom_limits
from spatialmech.geometry.rotations import euler_matrix, matrix_euler
from spatialmech.kinematics import backend, compiled
from spatialmech.kinematics.closure import Configuration, joint_points
from spatialmech.kinematics.compiled.kernels_limits import nb_segment_distance
from spatialmech.kinematics.compiled.kernels_task import nb_matrix_euler
from spatialmech.kinematics.position import platform_pose
from spatialmech.kinematics.task import default_task, solve_task

pytestmark = pytest.mark.skipif(not backend.enabled(), reason="the compiled engine is not in use")

DIETMAIER = Path(__file__).resolve().parents[1] / "examples" / "models" / "stewart-dietmaier.toml"


def _cones(mech, deg: float) -> tuple[ConeLimit, ...]:
    """A cone on every S or U joint: the base's z axis at a limb's first joint, else the
    platform's (as ``--cone``)."""
    out = []
    for limb in mech.limbs:
        for k, j in enumerate(limb.joints):
            if j.type in ("S", "U"):
                out.append(ConeLimit(j.name, (0, 0, 1), "base" if k == 0 else "platform", np.radians(deg)))
    return tuple(out)


def _poses(mech, n: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """Poses that close: the parasitic coordinates solved for a lower-mobility mechanism, random
    displacements of the reference pose otherwise."""
    task = default_task(mech)
    ref = platform_pose(mech, Configuration.reference(mech))
    L = mech.characteristic_length
    if len(task.given) == 6:
        R = euler_matrix("ZYX", rng.uniform(-0.25, 0.25, (n, 3))) @ ref.R
        return R, ref.p + rng.uniform(-0.12, 0.12, (n, 3)) * L
    v0 = dict(zip(("x", "y", "z", "a1", "a2", "a3"), [*ref.p, *matrix_euler(task.euler, ref.R)], strict=True))
    Rs, ps = [], []
    for _ in range(20 * n):
        given = {c: v0[c] + (rng.uniform(-0.35, 0.35) if c.startswith("a") else rng.uniform(-0.15, 0.15) * L)
                 for c in task.given}
        s = solve_task(mech, given, task=task)
        if s.converged:
            pose = platform_pose(mech, s.config)
            Rs.append(pose.R)
            ps.append(pose.p)
        if len(Rs) == n:
            break
    return np.array(Rs), np.array(ps, dtype=float)


CASES = {
    # the one ready-made model that carries limits: paper B's strokes, cones and capsules
    "four-sps-cu": (lambda: catalog.build("four-sps-cu"), lambda m: paper_b_limits(), 10),
    # the model's strokes ignored by the checker (yet the per-pose solve retries a solution outside them)
    "four-sps-cu strokes ignored": (lambda: catalog.build("four-sps-cu"),
                                    lambda m: WorkspaceLimits(paper_b_limits().cones, 0.01, freedom_limits=False), 10),
    "three-rps": (lambda: catalog.build("three-rps"), lambda m: WorkspaceLimits(_cones(m, 40), 0.02), 24),
    "three-prs": (lambda: catalog.build("three-prs"), lambda m: WorkspaceLimits(_cones(m, 30)), 16),
    "three-upu": (lambda: catalog.build("three-upu"), lambda m: WorkspaceLimits(_cones(m, 40)), 16),
    "stewart-6sps": (lambda: catalog.build("stewart-6sps"),
                     lambda m: WorkspaceLimits(_cones(m, 35), 0.05 * m.characteristic_length), 16),
    # a user's file with cones, and stroke limits (whose violators take the per-pose search)
    "dietmaier-file": (lambda: _with_strokes(catalog.resolve(str(DIETMAIER)), 0.2),
                       lambda m: WorkspaceLimits(_cones(m, 60)), 10),
}


def _with_strokes(mech, half: float):
    """``mech`` with every actuator's slide limited to its reference value +- ``half`` (m)."""
    refs = [r for r in mech.freedom_refs if r.freedom.kind == "P"]
    return with_freedom_limits(mech, {r.id: (r.freedom.offset - half, r.freedom.offset + half) for r in refs})


def _names(checker, M) -> list[str]:
    """The most violated limit (scaled margins) of each row, ``""`` when within every limit."""
    s = M / checker.scales
    return [checker.names[int(np.argmin(r))] if np.min(r) < 0 else "" for r in s]


#: Cases whose per-pose reference searches other assemblies for many poses (seconds each).
SLOW = {"dietmaier-file", "stewart-6sps"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n for n in sorted(CASES)])
def test_batched_checker_margins_and_active_limits_equal_the_per_pose_path(name):
    build, limits_of, n = CASES[name]
    mech = build()
    checker = pose_checker(mech, limits_of(mech), method="general")
    R, p = _poses(mech, n, np.random.default_rng(7))
    assert R.shape[0] == n
    M = checker.margins(R, p)  # batched
    M_ref = np.array([checker.margins(R[i : i + 1], p[i : i + 1])[0] for i in range(n)])  # the per-pose path
    assert np.max(np.abs(M - M_ref)) <= 1e-10
    assert checker.violated(R, p) == _names(checker, M_ref)
    feasible = np.all(M >= 0, axis=1)
    if not name.startswith("four-sps-cu"):
        assert 0 < feasible.sum() < n, "the sample should hold poses on both sides of the limits"


def test_batched_checker_equals_the_pure_python_reference():
    mech = catalog.build("three-rps")
    checker = pose_checker(mech, WorkspaceLimits(_cones(mech, 40), 0.02), method="general")
    R, p = _poses(mech, 8, np.random.default_rng(3))
    M = checker.margins(R, p)
    with backend.python_reference():
        M_ref = np.array([checker.margins(R[i : i + 1], p[i : i + 1])[0] for i in range(R.shape[0])])
    assert np.max(np.abs(M - M_ref)) <= 1e-10
    assert checker.violated(R, p) == _names(checker, M_ref)


@pytest.mark.parametrize("name", ["three-rps", "stewart-6sps", "four-sps-cu", "five-cs-1", "delta-ruu"])
def test_compiled_joint_points_equal_the_reference(name):
    mech = catalog.build(name)
    rng = np.random.default_rng(1)
    q = rng.normal(size=(6, len(mech.freedom_refs)))
    ref0 = joint_points(mech, Configuration.reference(mech))
    pts = [(li, k) for li in range(len(mech.limbs)) for k in range(len(ref0[li]))]
    out = compiled.joint_points_many(mech, q, pts)
    for s in range(q.shape[0]):
        ref = joint_points(mech, Configuration(q[s], np.eye(4)))
        assert np.max(np.abs(out[s] - np.array([ref[li][k] for li, k in pts]))) <= 1e-12


@pytest.mark.parametrize("name", ["stewart-6sps", "dietmaier-file"])
def test_closed_form_legs_close_where_the_gauss_newton_does(name):
    """The general checker of a platform on six S-P-S legs places the legs in closed form
    (``compiled.inverse_legs_many``) instead of a Gauss-Newton per leg: every leg closes to
    rounding, the joint points and slides are the Gauss-Newton's to its own tolerance (closure
    1e-10), only the legs' idle spins differ."""
    from spatialmech.kinematics.leg_platform import leg_platform

    mech = CASES[name][0]()
    lp = leg_platform(mech)
    assert lp is not None
    R, p = _poses(mech, 12, np.random.default_rng(4))
    D = np.zeros((12, 4, 4))
    D[:, :3, :3], D[:, 3, 3] = R, 1.0
    D[:, :3, 3] = p - np.einsum("nij,j->ni", R, mech.platform_point)
    q, res, ok = compiled.inverse_legs_many(lp, D)
    q_gn, _, ok_gn = compiled.limb_inverse_many(mech, D)
    assert ok.all() and ok_gn.all() and np.max(res) < 1e-13
    pts = [(li, k) for li in range(6) for k in range(3)]
    L = mech.characteristic_length
    P, P_gn = compiled.joint_points_many(mech, q, pts), compiled.joint_points_many(mech, q_gn, pts)
    assert np.max(np.abs(P - P_gn)) <= 1e-9 * L
    assert np.max(np.abs(q[:, lp.index[:, 1]] - q_gn[:, lp.index[:, 1]])) <= 1e-9 * L


def test_configuration_checker_batch_equals_one_by_one():
    mech = catalog.build("stewart-6sps")
    checker = configuration_checker(mech, WorkspaceLimits(_cones(mech, 35), 0.05 * mech.characteristic_length))
    rng = np.random.default_rng(2)
    configs = []
    for _ in range(5):
        D = np.eye(4)
        D[:3, :3] = euler_matrix("ZYX", rng.normal(scale=0.3, size=3))
        configs.append(Configuration(rng.normal(scale=0.3, size=len(mech.freedom_refs)), D))
    M = checker.margins_many(configs)
    with backend.python_reference():
        M_ref = np.array([checker.margins(c) for c in configs])
    assert M.shape == (5, len(checker.names)) and np.max(np.abs(M - M_ref)) <= 1e-12


_coord = st.floats(-2.0, 2.0, allow_nan=False)
_point = st.tuples(_coord, _coord, _coord)


@settings(max_examples=300, deadline=None)
@given(_point, _point, _point, _point)
@example((0, 0, 0), (1, 0, 0), (0.5, 1, -1), (0.5, 1, 1))  # crossing: 1 apart
@example((0, 0, 0), (1, 0, 0), (0.5, 1, 0), (2, 1, 0))  # parallel
@example((0, 0, 0), (0, 0, 0), (0.5, 1, 0), (2, 1, 0))  # a point and a segment
@example((1, 1, 1), (1, 1, 1), (0, 0, 0), (0, 0, 0))  # two points
def test_compiled_segment_distance_equals_the_reference(p1, q1, p2, q2):
    a, b, c, d = (np.array(v, dtype=float) for v in (p1, q1, p2, q2))
    assert abs(nb_segment_distance(a, b, c, d) - float(segment_distance(a, b, c, d))) <= 1e-12


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(["ZYX", "XYZ", "zyx", "xyz", "ZXZ", "zxz", "YXY", "yzy"]),
       st.tuples(*(st.floats(-3.1, 3.1, allow_nan=False),) * 3), st.booleans())
def test_compiled_euler_angles_equal_scipys(seq, angles, lock):
    a = np.array(angles)
    if lock:  # the gimbal lock: the middle angle at its singular value
        a[1] = np.pi / 2 if seq[0].lower() != seq[2].lower() else 0.0
    R = euler_matrix(seq, a)
    out = np.empty(3)
    nb_matrix_euler(np.array(["xyz".index(c) for c in seq.lower()]), seq.isupper(), R, out)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # SciPy's gimbal-lock warning
        ref = matrix_euler(seq, R)
    assert np.max(np.abs(np.angle(np.exp(1j * (out - ref))))) <= 1e-10
    assert np.allclose(euler_matrix(seq, out), R, atol=1e-6)  # SciPy takes 1e-7 rad off a lock as the lock


@pytest.mark.parametrize("name", ["three-rps", "three-prs", "three-upu", "delta-ruu"])
def test_compiled_task_solve_equals_the_reference(name):
    mech = catalog.build(name)
    task = default_task(mech)
    rng = np.random.default_rng(4)
    ref = platform_pose(mech, Configuration.reference(mech))
    v0 = dict(zip(("x", "y", "z", "a1", "a2", "a3"), [*ref.p, *matrix_euler(task.euler, ref.R)], strict=True))
    L = mech.characteristic_length
    for _ in range(12):
        g = {c: v0[c] + (rng.uniform(-0.4, 0.4) if c.startswith("a") else rng.uniform(-0.2, 0.2) * L) for c in task.given}
        a = solve_task(mech, g, task=task)
        with backend.python_reference():
            b = solve_task(mech, g, task=task)
        assert a.status == b.status
        if b.converged:
            assert max(abs(a.values[c] - b.values[c]) for c in b.values) <= 1e-10
            assert np.max(np.abs(a.config.D - b.config.D)) <= 1e-10
            # the joint variables: the same up to whole turns of a passive spin (the 3-UPU's
            # rank-deficient steps reach it by other multiples of 2 pi)
            dq = a.config.q - b.config.q
            assert np.max(np.abs(dq - 2 * np.pi * np.round(dq / (2 * np.pi)))) <= 1e-9
            if name != "three-upu":
                assert a.iterations == b.iterations and np.max(np.abs(dq)) <= 1e-10


def test_partial_given_keeps_the_seeds_other_coordinates():
    mech = catalog.build("three-rps")
    a = solve_task(mech, {"a2": 0.1})
    with backend.python_reference():
        b = solve_task(mech, {"a2": 0.1})
    assert a.converged and b.converged and a.iterations == b.iterations
    assert max(abs(a.values[c] - b.values[c]) for c in b.values) <= 1e-12


@pytest.mark.slow
def test_task_workspace_compiled_equals_the_reference():
    kw = dict(kind="task", over={"a2": (np.radians(-40), np.radians(40), 9), "a3": (np.radians(-40), np.radians(40), 9)},
              at={"z": 0.33}, cones={f"S{i}": np.radians(45) for i in (1, 2, 3)}, tol=np.radians(1e-3))
    a = sm.workspace("three-rps", **kw)
    with backend.python_reference():
        b = sm.workspace("three-rps", **kw)
    assert np.array_equal(a.converged, b.converged) and np.array_equal(a.feasible, b.feasible)
    assert list(a.cell_limits.ravel()) == list(b.cell_limits.ravel())
    assert np.nanmax(np.abs(a.values - b.values)) <= 1e-10
    assert a.boundary_limits == b.boundary_limits and a.n_solves == b.n_solves
    assert np.max(np.abs(a.boundary_points - b.boundary_points)) <= 1e-10
    for c in ("a2", "a3"):
        ea, eb = a.extents[c], b.extents[c]
        assert (ea.lo_limit, ea.hi_limit) == (eb.lo_limit, eb.hi_limit)
        assert abs(ea.lo - eb.lo) <= 1e-10 and abs(ea.hi - eb.hi) <= 1e-10
    assert 0 < a.reachable_fraction < 1 and a.extents["a2"].hi_limit.endswith("cone")



GRIDS = {
    "three-rps 2-D": ("three-rps", {"a2": np.radians(np.linspace(-60, 60, 9)), "a3": np.radians(np.linspace(-60, 60, 7))},
                      {"z": 0.33}),
    "three-rps 3-D": ("three-rps", {"z": np.linspace(0.25, 0.4, 4), "a2": np.radians(np.linspace(-30, 30, 4)),
                                    "a3": np.radians(np.linspace(-30, 30, 3))}, {}),
    "delta (internal bodies)": ("delta", {"x": np.linspace(-0.05, 0.05, 5), "y": np.linspace(-0.05, 0.05, 4)}, {}),
}


@pytest.mark.parametrize("case", sorted(GRIDS))
def test_compiled_task_grid_sweep_equals_the_reference(case):
    from spatialmech.kinematics.task_grid import solve_task_grid

    name, over, at = GRIDS[case]
    mech = catalog.build(name)
    seen: list[tuple] = []
    a = solve_task_grid(mech, over, at=at, progress=lambda done, total, msg: seen.append((done, total, msg)))
    with backend.python_reference():
        b = solve_task_grid(mech, over, at=at)
    assert np.array_equal(a.converged, b.converged) and a.n_solves == b.n_solves and a.converged.any()
    d = a.values - b.values
    d[..., 3:] = np.angle(np.exp(1j * d[..., 3:]))  # angles modulo 2 pi (a yaw at +-pi)
    assert np.nanmax(np.abs(d)) <= 1e-10
    for idx in zip(*np.nonzero(a.converged), strict=True):
        assert np.max(np.abs(a.configs[idx].D - b.configs[idx].D)) <= 1e-10
    assert seen and seen[-1][0] == a.n_solves and seen[-1][2] == "solving task coordinates"


@pytest.mark.slow
def test_bench_limits_quick_reports_every_key_and_agrees():
    """benchmarks/bench_limits.py --quick (tiny sizes): a verdict per target, both paths agree."""
    import importlib.util

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_limits.py"
    spec = importlib.util.spec_from_file_location("bench_limits", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    out = mod.run(quick=True)
    assert set(out["met"]) == set(mod.TARGETS)
    assert out["checker_cones_three_rps_agree"] and out["checker_cones_stewart_agree"]
    assert out["task_workspace_three_rps_agree"]
