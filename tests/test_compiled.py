"""The compiled engine (kinematics/compiled.py) against the pure-Python reference on every
ready-made model: residuals and Jacobians, Gauss-Newton corrections (forward position with the
actuators held, inverse position with the output held), retraction, tracking, driver
determinants and limb inverse position.  ``SPATIALMECH_PURE=1`` selects the reference path."""

from __future__ import annotations

import os
from contextlib import contextmanager

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("numba")
if os.environ.get("SPATIALMECH_PURE", "").strip() not in ("", "0"):
    pytest.skip("SPATIALMECH_PURE is set: both paths would be the reference", allow_module_level=True)

from spatialmech import catalog
from spatialmech.analysis.defects import candidate_drivers
from spatialmech.errors import InputError
from spatialmech.geometry.rotations import exp_twist
from spatialmech.kinematics import backend, compiled
from spatialmech.kinematics.compiled import kernels_se3
from spatialmech.kinematics.closed_forms import four_sps_cu
from spatialmech.kinematics.closure import Configuration, active_mask, hub_count
from spatialmech.kinematics.backend import closure_jacobian, closure_residual, correct, retract
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.jacobian import driver_determinants
from spatialmech.kinematics.position import inverse_position, platform_pose
from spatialmech.kinematics.tracking import MotionProblem, trace_motion

NAMES = catalog.names()
ONE_DOF = ["five-cs-1", "five-cs-2", "five-cs-3", "planar-4r", "bennett", "rssr", "spatial-six-bar"]


pure = backend.python_reference


_GENERIC: dict[str, Configuration] = {}


def generic(name: str) -> Configuration:
    if name not in _GENERIC:
        _GENERIC[name] = generic_configuration(catalog.build(name), seed=7)
    return _GENERIC[name]


def perturbed(mech, config: Configuration, seed: int, size: float = 0.05) -> Configuration:
    """An open (not closed) configuration near ``config``: joints, output and bodies moved."""
    rng = np.random.default_rng(seed)
    q = config.q + size * rng.standard_normal(len(config.q))
    D = exp_twist(size * rng.standard_normal(6), 1.0) @ config.D
    B = np.array([exp_twist(size * rng.standard_normal(6), 1.0) @ b for b in config.B]).reshape(config.B.shape)
    return Configuration(q, D, B)


def close(a, b, tol):
    a, b = np.asarray(a, float), np.asarray(b, float)
    assert a.shape == b.shape
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * max(1.0, float(np.max(np.abs(b), initial=0.0))))


def test_the_compiled_path_is_on_by_default_and_pure_switches_it_off():
    assert backend.enabled()
    with pure():
        assert not backend.enabled()
    assert backend.enabled()


@pytest.mark.parametrize("name", NAMES)
def test_residual_and_jacobian_match_the_reference(name):
    mech = catalog.build(name)
    for config in (generic(name), perturbed(mech, generic(name), 1)):
        with pure():
            r0 = closure_residual(mech, config)
            A0, s0 = closure_jacobian(mech, config)
        r1 = closure_residual(mech, config)
        A1, s1 = closure_jacobian(mech, config)
        close(r1, r0, 1e-12)
        close(s1, s0, 1e-12)
        close(A1, A0, 1e-12)
        if len(config.q) > 1:  # another active mask: the columns follow it
            act = active_mask(mech)
            act[0] = False
            with pure():
                A0, _ = closure_jacobian(mech, config, active=act)
            close(closure_jacobian(mech, config, active=act)[0], A0, 1e-12)


def _held(mech) -> np.ndarray:
    mask = active_mask(mech)
    for a in mech.actuators:
        mask[mech.freedom_refs.index(mech.freedom(a))] = False
    return mask


def same_correction(r1, r0, tol=1e-10):
    assert (r1.converged, r1.stationary) == (r0.converged, r0.stationary)
    assert r1.iterations == r0.iterations
    if r0.converged:
        close(r1.config.q, r0.config.q, tol)
        close(r1.config.D, r0.config.D, tol)
        close(r1.config.B, r0.config.B, tol)
        assert r1.residual < 1e-11 and r0.residual < 1e-11


@pytest.mark.parametrize("name", NAMES)
def test_forward_position_from_the_reference_matches(name):
    """``correct()`` with the actuators held at a generic configuration's values, started from the
    reference configuration: the same statuses, iterations and result."""
    mech = catalog.build(name)
    target = generic(name)
    mask = _held(mech)
    ref = Configuration.reference(mech)
    q = ref.q.copy()
    q[~mask] = target.q[~mask]
    start = Configuration(q, ref.D, ref.B)
    with pure():
        r0 = correct(mech, start, active=mask)
    r1 = correct(mech, start, active=mask)
    same_correction(r1, r0)
    # and near a solution (a few iterations), plus the inverse position (output held)
    near = perturbed(mech, target, 2, size=0.01)
    for kw in ({"active": mask}, {"fix_platform": True}, {}):
        with pure():
            r0 = correct(mech, near, **kw)
        # nothing held: the correction is underdetermined (minimum-norm steps along the motion; an
        # overconstrained linkage's rows nearly dependent), so the two solvers' rounding comes out
        # amplified: bennett's seed-7 point differs by 1.03e-10 (seeds 2, 3, 5 of the configurations
        # before issue 26 already gave 1.2e-10 to 1.7e-10)
        same_correction(correct(mech, near, **kw), r0, tol=1e-10 if kw else 1e-9)


@pytest.mark.parametrize("name", ["stewart-6sps", "delta", "five-cs-3"])
def test_retraction_and_tracker_differences_match(name):
    mech = catalog.build(name)
    c = generic(name)
    act = active_mask(mech)
    rng = np.random.default_rng(3)
    for n_hubs in (hub_count(mech), 1, 0):  # a shorter step leaves the remaining hubs where they are
        step = 0.05 * rng.standard_normal(int(act.sum()) + 6 * n_hubs)
        for fix in (False, True):
            with pure():
                c0 = retract(mech, c, act, step, fix)
            c1 = retract(mech, c, act, step, fix)
            close(c1.q, c0.q, 1e-12)
            close(c1.D, c0.D, 1e-12)
            close(c1.B, c0.B, 1e-12)
    prob = MotionProblem(mech)
    other = perturbed(mech, c, 4, size=0.3)
    with pure():
        d0 = prob.difference(c, other)
    close(prob.difference(c, other), d0, 1e-12)
    with pytest.raises(InputError, match="step"):
        retract(mech, c, act, np.zeros(2))


@pytest.mark.parametrize("name", ONE_DOF)
def test_tracking_matches_the_reference(name):
    """A few steps of the continuation tracker (predictor, corrector, guards, monitors) give the
    same points on both paths."""
    mech = catalog.build(name)
    start = generic(name)
    drivers = candidate_drivers(mech)
    if not np.all(np.isfinite(driver_determinants(mech, start, drivers))):
        drivers = []  # DJ is NaN (not square) here: NaN monitors would only add spurious events

    def run():
        return trace_motion(mech, start, max_steps=6, h0=0.05,
                            vector_monitor=(drivers, lambda c: driver_determinants(mech, c, drivers)))

    with pure():
        t0 = run()
    t1 = run()
    assert len(t1.points) == len(t0.points) and t1.status == t0.status and t1.rejected == t0.rejected
    for a, b in zip(t1.points, t0.points, strict=True):
        close(a.q, b.q, 1e-10)
        close(a.D, b.D, 1e-10)
    for k in t0.monitors:
        close(t1.monitors[k], t0.monitors[k], 1e-10)


@pytest.mark.parametrize("name", ["five-cs-1", "five-cs-2", "five-cs-3", "spatial-six-bar", "delta", "rssr"])
def test_driver_determinants_match(name):
    mech = catalog.build(name)
    drivers = candidate_drivers(mech)
    for seed in range(3):
        c = generic_configuration(mech, seed=seed) if seed else generic(name)
        with pure():
            d0 = driver_determinants(mech, c, drivers)
        d1 = driver_determinants(mech, c, drivers)
        assert np.array_equal(np.isnan(d0), np.isnan(d1))
        ok = ~np.isnan(d0)
        close(d1[ok], d0[ok], 1e-10)
    if name.startswith("five-cs"):  # the compiled kernel itself runs (no fallback) and batches
        c = generic(name)
        many = compiled.driver_determinants_many(mech, np.stack([c.q, c.q]), np.stack([c.D, c.D]), None, drivers)
        assert many is not None
        close(many[1], driver_determinants(mech, c, drivers), 1e-14)
    if name == "rssr":  # a limb of one twist: the kernel declines, the Python path answers
        assert compiled.driver_determinants(mech, generic(name), drivers) is None


@pytest.mark.parametrize("name", ["five-cs-1", "five-cs-3", "spatial-six-bar", "rssr"])
def test_driver_sigmas_match_the_complete_jacobians(name):
    """The scale-free smallest singular value of each driver's complete Jacobian (the defect
    analysis's distance to a singularity along the path, issue 29) from the kernel equals
    ``CompleteJacobian.sigma_min`` to 1e-12 at generic configurations; the kernel declines
    (None) where it would not decide."""
    from spatialmech.kinematics.jacobian import complete_jacobians

    mech = catalog.build(name)
    drivers = candidate_drivers(mech)
    cs = [generic(name), *(generic_configuration(mech, seed=s) for s in (1, 2))]
    got = compiled.driver_sigmas_many(mech, np.stack([c.q for c in cs]), np.stack([c.D for c in cs]),
                                      np.stack([c.B for c in cs]), drivers)
    if name in ("spatial-six-bar", "rssr"):  # internal bodies, a limb of one twist: the Python path answers
        assert got is None
        return
    ref = np.array([[cj.sigma_min for cj in complete_jacobians(mech, c, [[d] for d in drivers])] for c in cs])
    assert got is not None and got.shape == ref.shape and np.all(ref > 1e-6)
    close(got, ref, 1e-12)


@pytest.mark.parametrize("name", ["stewart-6sps", "four-sps-cu"])
def test_limb_inverse_position_matches(name):
    mech = catalog.build(name)
    pose = platform_pose(mech, generic(name))
    with pure():
        i0 = inverse_position(mech, pose, all_solutions=True, n_seeds=6)
    i1 = inverse_position(mech, pose, all_solutions=True, n_seeds=6)
    assert i1.reachable and i0.reachable
    for a, b in zip(i1.limbs, i0.limbs, strict=True):
        assert len(a.solutions) == len(b.solutions)
        for x, y in zip(a.solutions, b.solutions, strict=True):
            close(x, y, 1e-10)
    close(i1.config.q, i0.config.q, 1e-10)
    # batched: many poses at once, the same as one by one
    Ds = np.stack([generic(name).D, generic_configuration(mech, seed=11).D])
    q, res, ok = compiled.limb_inverse_many(mech, Ds)
    assert ok.all() and res.max() < 1e-10
    for k in range(2):
        one = inverse_position(mech, platform_pose(mech, Configuration(q[k], Ds[k])))
        assert one.reachable
        assert np.max(np.abs(closure_residual(mech, Configuration(q[k], Ds[k])))) < 1e-9


def test_batched_entry_points_equal_single_calls():
    mech = catalog.build("delta")
    cs = [generic("delta"), perturbed(mech, generic("delta"), 6), perturbed(mech, generic("delta"), 7)]
    q = np.stack([c.q for c in cs])
    D = np.stack([c.D for c in cs])
    B = np.stack([c.B for c in cs])
    A, r = compiled.closure_jacobians(mech, q, D, B)
    res = compiled.closure_residuals(mech, q, D, B)
    for k, c in enumerate(cs):
        A1, r1 = closure_jacobian(mech, c)
        assert np.array_equal(A[k], A1) and np.array_equal(r[k], r1) and np.array_equal(res[k], r1)
    mask = _held(mech)
    many = compiled.correct_many(mech, cs, active=mask)
    for c, m in zip(cs, many, strict=True):
        one = correct(mech, c, active=mask)
        assert (m.converged, m.iterations) == (one.converged, one.iterations)
        assert np.array_equal(m.config.q, one.config.q)
    with pytest.raises(InputError, match="q: expected shape"):
        compiled.closure_residuals(mech, q[:, :3], D, B)


def test_errors_name_the_argument_on_both_paths():
    mech = catalog.build("stewart-6sps")
    bad = Configuration(np.zeros(3), np.eye(4))
    for ctx in (pure, _nothing):
        with ctx():
            with pytest.raises(InputError, match=r"config\.q"):
                closure_jacobian(mech, bad)
            with pytest.raises(InputError, match="NaN"):
                correct(mech, Configuration(np.full(len(mech.freedom_refs), np.nan), np.eye(4)))
    with pytest.raises(InputError, match="active"):
        closure_jacobian(mech, Configuration.reference(mech), active=np.ones(3, bool))


@contextmanager
def _nothing():
    yield


def test_sps_leg_lengths_agree_with_the_closed_form():
    rng = np.random.default_rng(1)
    phi = np.column_stack([rng.uniform(0.08, 0.3, 50), rng.uniform(-0.5, 0.5, (50, 3))])  # z, alpha, beta, gamma
    g = four_sps_cu.PAPER_B
    s1 = np.array([1, 1, -1, -1.0])
    s2 = np.array([-1, 1, 1, -1.0])
    plat = np.column_stack([g.a * s1, g.a * s2, np.zeros(4)])
    base = np.column_stack([g.b * s1, g.b * s2, np.zeros(4)])
    poses = np.column_stack([np.zeros((50, 2)), phi[:, 0], phi[:, 3], phi[:, 2], phi[:, 1]])
    close(compiled.sps_leg_lengths(poses, base, plat), four_sps_cu.leg_lengths(phi, g), 1e-14)


def test_batched_4sps_cu_legs_on_all_cores_equal_the_reference():
    """From ``PARALLEL_FROM`` poses the legs are computed on every core (prange): the numbers are
    those of the one-thread kernel and, to rounding, of the NumPy reference."""
    rng = np.random.default_rng(2)
    n = four_sps_cu.PARALLEL_FROM + 17
    phi = np.column_stack([rng.uniform(0.08, 0.3, n), rng.uniform(-3, 3, (n, 3))])
    big = four_sps_cu.leg_lengths(phi)
    one = np.concatenate([four_sps_cu.leg_lengths(phi[i:i + 1000]) for i in range(0, n, 1000)])
    assert np.array_equal(big, one)
    with backend.python_reference():
        ref = four_sps_cu.leg_lengths(phi)
    close(big, ref, 1e-14)
    # angles beyond the polynomial sine's range are redone with libm's, on both kernels
    phi[::97, 2] += 3e6
    for part in (phi, phi[:500]):
        with backend.python_reference():
            ref = four_sps_cu.leg_lengths(part)
        close(four_sps_cu.leg_lengths(part), ref, 1e-14)


def test_4sps_cu_legs_do_not_depend_on_where_a_pose_sits_in_the_batch():
    """The legs kernel runs blocks of poses through vectorised flat loops (squares, then square
    roots), a last short block through a padded copy, so that no pose falls in a loop's scalar
    remainder: a pose's legs are the same bits wherever it sits in the batch, squared or not, and
    equal the NumPy reference to rounding.  A block with a wide angle redoes that pose with libm;
    a NaN is still named."""
    rng = np.random.default_rng(5)
    n = 3 * 512 + 7
    phi = np.column_stack([rng.uniform(0.08, 0.3, n), rng.uniform(-4, 4, (n, 3))])
    phi[600, 3] += 2e6
    for squared in (False, True):
        full = four_sps_cu.leg_lengths(phi, squared=squared)
        for sl in (np.s_[3:], np.s_[511:1030], np.s_[::-1]):
            assert np.array_equal(four_sps_cu.leg_lengths(phi[sl].copy(), squared=squared), full[sl])
        one = np.concatenate([four_sps_cu.leg_lengths(phi[i:i + 1], squared=squared) for i in range(0, n, 97)])
        assert np.array_equal(one, full[::97])
        with backend.python_reference():
            ref = four_sps_cu.leg_lengths(phi, squared=squared)
        close(full, ref, 1e-14)
    phi[1200, 1] = np.nan
    with pytest.raises(InputError, match="phi: contains NaN"):
        four_sps_cu.leg_lengths(phi)


@settings(max_examples=60, deadline=None)
@given(st.floats(-kernels_se3.SINCOS_MAX, kernels_se3.SINCOS_MAX, allow_nan=False),
       st.integers(-4000, 4000), st.floats(-1e-9, 1e-9))
def test_vectorisable_sine_cosine_equals_libm(x, k, eps):
    """The polynomial sine and cosine that let pose loops vectorise agree with libm's to an ulp,
    anywhere in their range and next to the quarter turns, where the argument reduction counts."""
    for v in (x, k * np.pi / 2 + eps):
        s, c = kernels_se3.nb_sincos(v)
        assert abs(s - np.sin(v)) <= 2.3e-16 and abs(c - np.cos(v)) <= 2.3e-16, v


def test_without_numba_the_python_path_runs_with_a_note(monkeypatch):
    monkeypatch.setattr(compiled, "AVAILABLE", False)
    with pytest.warns(RuntimeWarning, match="numba"):
        assert not backend.enabled()
    mech = catalog.build("rssr")
    assert np.allclose(closure_residual(mech, Configuration.reference(mech)), 0, atol=1e-12)


MODELS_H = ["stewart-6sps", "five-cs-3", "delta", "three-rps", "spatial-six-bar"]


@settings(max_examples=25)
@given(st.sampled_from(MODELS_H), st.integers(0, 2**31 - 1), st.floats(0.01, 1.5))
def test_random_configurations_match(name, seed, size):
    """Residual, Jacobian and one Gauss-Newton correction at random (open) configurations."""
    mech = catalog.build(name)
    c = perturbed(mech, Configuration.reference(mech), seed, size)
    with pure():
        r0 = closure_residual(mech, c)
        A0, _ = closure_jacobian(mech, c)
        k0 = correct(mech, c, max_iter=1)
    close(closure_residual(mech, c), r0, 1e-12)
    close(closure_jacobian(mech, c)[0], A0, 1e-12)
    k1 = correct(mech, c, max_iter=1)
    close(k1.config.q, k0.config.q, 1e-10)
    close(k1.config.D, k0.config.D, 1e-10)
    assert k1.residual == pytest.approx(k0.residual, rel=1e-9, abs=1e-14)


def test_minimum_norm_solver_equals_lstsq_and_falls_back_on_rank_deficiency():
    """The QR path of the compiled least squares gives numpy's minimum-norm solution; a rank
    deficient system (two equal rows) goes to the SVD and still matches lstsq."""
    rng = np.random.default_rng(4)
    for m, n in ((36, 42), (6, 6), (5, 12), (12, 7)):
        A, b = rng.standard_normal((m, n)), rng.standard_normal(m)
        close(compiled.lstsq(A, b), np.linalg.lstsq(A, b, rcond=None)[0], 1e-12)
    A = rng.standard_normal((6, 9))
    A[3] = A[1]
    b = rng.standard_normal(6)
    b[3] = b[1]
    close(compiled.lstsq(A, b), np.linalg.lstsq(A, b, rcond=None)[0], 1e-10)
    # sparse, increasingly ill-conditioned underdetermined systems: the normal-equations path
    # (cond up to about 1e4), then the QR, then the SVD, each to lstsq's minimum-norm solution
    for cond in (1e0, 1e2, 1e3, 1e5, 1e9):
        U, _ = np.linalg.qr(rng.standard_normal((36, 36)))
        V, _ = np.linalg.qr(rng.standard_normal((42, 36)))
        A = (U * np.geomspace(1.0, 1.0 / cond, 36)) @ V.T
        A[np.abs(A) < 0.02] = 0.0  # zeros as in a closure Jacobian
        b = rng.standard_normal(36)
        ref = np.linalg.lstsq(A, b, rcond=None)[0]
        err = np.max(np.abs(compiled.lstsq(A, b) - ref)) / np.max(np.abs(ref))
        assert err < 1e-13 * max(np.linalg.cond(A), 1.0), (cond, err)


def test_nearest_rotation_without_the_svd_equals_the_svd():
    """The retraction re-orthonormalises rotations by the Bjorck iteration when they drift by
    rounding, by the SVD otherwise: both give the polar factor ``U Vt``."""
    from scipy.spatial.transform import Rotation

    from spatialmech.kinematics.compiled.kernels_se3 import nb_orthonormal

    rng = np.random.default_rng(5)
    for _ in range(200):
        R = Rotation.from_rotvec(rng.standard_normal(3) * 2.0).as_matrix()
        D = np.eye(4)
        D[:3, :3] = R + rng.standard_normal((3, 3)) * 10.0 ** rng.uniform(-16, -3)
        U, _, Vt = np.linalg.svd(D[:3, :3])
        nb_orthonormal(D, np.empty((2, 3, 3)))
        close(D[:3, :3], U @ Vt, 1e-14)


def test_batched_general_pose_checker_equals_pose_by_pose():
    """The general workspace checker solves many poses in one compiled batch; its margins equal
    those of the pose-by-pose path (which also searches other assemblies where a limit is
    broken) on feasible, infeasible and unreachable poses."""
    from spatialmech.analysis.workspace import pose_checker, with_freedom_limits
    from spatialmech.kinematics.position import platform_pose

    for name in ("three-rps", "stewart-6sps"):
        mech = catalog.build(name)
        L = mech.characteristic_length
        mech = with_freedom_limits(mech, {a: (mech.freedom(a).freedom.offset - 0.1 * L,
                                              mech.freedom(a).freedom.offset + 0.1 * L) for a in mech.actuators})
        checker = pose_checker(mech, method="general")
        rng = np.random.default_rng(2)
        Rs, ps = [], []
        for k in range(12):
            config = generic_configuration(mech, seed=k, step=0.02 + 0.04 * k)
            pose = platform_pose(mech, config)
            Rs.append(pose.R)
            ps.append(pose.p + (0.0 if k % 4 else 0.05 * rng.standard_normal(3)))  # some off the closure
        R, p = np.array(Rs), np.array(ps)
        batch = checker.margins(R, p)
        single = np.array([checker.margins(R[i : i + 1], p[i : i + 1])[0] for i in range(len(R))])
        # stewart-6sps: the batch places the legs in closed form (exact), the per-pose path by a
        # Gauss-Newton; three-rps: the batch's Gauss-Newton stops within the closure tolerance
        # (1e-10), the per-pose path polishes its solution on to round-off: they agree to that
        close(batch, single, 1e-10)
        feasible = np.all(batch >= 0, axis=1)
        assert feasible.any() and not feasible.all(), name
        if name == "three-rps":  # a 3-DOF platform cannot reach the poses moved off its closure
            assert np.any(batch[:, -1] < 0)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**31 - 1))
def test_cs_dyad_equations_compiled_equal_the_vectorised_form(seed):
    """The compiled one-dyad residual and Jacobian (the synthesis tracker's inner loop) equal the
    vectorised NumPy form (a stack of one dyad takes that path) and the pure path."""
    from spatialmech.synthesis.cs_dyads import dyad_jacobian, dyad_residual

    rng = np.random.default_rng(seed)
    x = rng.standard_normal(15)
    D = np.array([exp_twist(rng.standard_normal(6), 1.0) for _ in range(7)])
    r, J = dyad_residual(x, D), dyad_jacobian(x, D)
    close(r, dyad_residual(x[None], D)[0], 1e-13)
    close(J, dyad_jacobian(x[None], D)[0], 1e-13)
    with pure():
        close(r, dyad_residual(x, D), 1e-13)
        close(J, dyad_jacobian(x, D), 1e-13)


def test_core_benchmark_runs_and_reports_every_target(capsys):
    """benchmarks/bench_core.py --quick (tiny sizes): every key of the issue, a verdict per
    target, and the engine, scipy and the hand-written Newton agree on the Stewart pose."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "bench_core.py"
    spec = importlib.util.spec_from_file_location("bench_core", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    out = bench.main(["--quick", "--json"])
    for key in ("fk_solve_us", "fk_scipy_root_us", "fk_handwritten_us", "circuit_five_cs_3_s", "circuit_python_s",
                "workspace_general_poses_per_s", "dj_per_s", "ik_batch_vs_loop"):
        assert out[key] > 0, key
    assert set(out["met"]) == set(out["targets"]) and all(isinstance(v, bool) for v in out["met"].values())
    assert out["fk_engine_max_error"] < 1e-10 and out["fk_handwritten_max_error"] < 1e-10
    assert out["circuit_max_joint_difference"] < 1e-8 and out["ik_max_abs_difference_m"] < 1e-12
    assert '"fk_solve_us"' in capsys.readouterr().out


@pytest.mark.parametrize("name", NAMES)
def test_joint_twists_match_the_reference(name):
    """Joint twists (the complete Jacobian's and the viewer's input) from the compiled closure
    Jacobian equal the Python chains', locked freedoms included."""
    from spatialmech.kinematics.backend import joint_twists

    mech = catalog.build(name)
    config = generic(name)
    with pure():
        ref = joint_twists(mech, config)
    fast = joint_twists(mech, config)
    assert len(fast) == len(ref)
    for a, b in zip(fast, ref, strict=True):
        close(a, b, 1e-12)


def test_a_kernel_compiled_on_first_use_is_announced_and_a_cached_one_is_not():
    """The command line tells a person at a terminal when numba compiles a kernel (a cache miss:
    the first use after installation), with its time; the outermost kernel only."""
    import io

    from numba import njit

    from spatialmech.kinematics.compiled.jit import announce_compilation

    @njit(cache=False)
    def inner_kernel_for_the_notice(x):
        return x + 1.0

    @njit(cache=False)
    def outer_kernel_for_the_notice(x):
        return inner_kernel_for_the_notice(x) * 2.0

    buf = io.StringIO()
    assert announce_compilation(buf)
    try:
        assert outer_kernel_for_the_notice(1.0) == 4.0
        assert outer_kernel_for_the_notice(2.0) == 6.0  # compiled already: nothing more said
    finally:
        announce_compilation(None)
    text = buf.getvalue()
    assert "outer_kernel_for_the_notice" in text and "inner_kernel_for_the_notice" not in text
    assert text.count("compiling outer_kernel_for_the_notice ...") == 1
    assert text.rstrip().endswith(" s")
    outer_kernel_for_the_notice(3)  # an int signature compiles, but the listener is gone
    assert buf.getvalue() == text
