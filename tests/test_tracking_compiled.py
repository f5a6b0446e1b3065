"""The tracker's compiled step test (issue 29): one LU of the bordered Jacobian ``[A; t]``
instead of a full SVD per step gives the same tangents, orientation signs, statuses and events
as the reference's SVD path, and steps aside (to the SVD) wherever the rank is in doubt.

The tracker's compiled loop (``kernels_trace.nb_trace``: steps, DJ monitors, events, closure)
traces what the Python loop (``tracking.python_loop()``) traces, also where it hands steps back."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech import catalog
from spatialmech.analysis import defect_circuits
from spatialmech.analysis.defects import defect_analysis
from spatialmech.kinematics import backend, tracking
from spatialmech.kinematics.compiled import bordered_tangent
from spatialmech.kinematics.tracking import MotionProblem

TRACE_TOL = 1e-10  # arc lengths, tangents and event positions: compiled step test against the SVD path


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 40))
def test_bordered_tangent_is_the_svd_null_vector_with_keller_sign(seed, n):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n + 1))
    t_prev = rng.standard_normal(n + 1)
    t_prev /= np.linalg.norm(t_prev)
    got = bordered_tangent(A, t_prev)
    assert got is not None
    z, sign, smin, anorm = got
    _, sv, vt = np.linalg.svd(A)
    ref = vt[-1] if vt[-1] @ t_prev > 0 else -vt[-1]  # oriented as the tracker does
    assert np.linalg.norm(z) == pytest.approx(1.0, abs=1e-12)
    assert z @ t_prev > 0
    scale = 1.0 / max(sv[-1], 1e-300)
    assert np.max(np.abs(z - ref)) < 1e-12 * max(1.0, scale)
    assert sign == np.linalg.slogdet(np.vstack([A, ref]))[0]
    assert smin <= sv[-1] * (1 + 1e-12)  # a lower bound of sigma_n(A) (interlacing)
    # the bound is 1 / |M^-1|_F of M = [A; t_prev] (the forward substitution skips its zeros)
    assert smin == pytest.approx(1.0 / np.linalg.norm(np.linalg.inv(np.vstack([A, t_prev]))), rel=1e-10)
    assert anorm >= sv[0] * (1 - 1e-12)


def test_bordered_tangent_of_a_rank_deficient_jacobian_is_not_certified():
    rng = np.random.default_rng(3)
    A = rng.standard_normal((6, 7))
    A[5] = A[4] + 1e-13 * rng.standard_normal(7)  # rank 5 to working precision
    got = bordered_tangent(A, np.eye(7)[0])
    assert got is None or got[2] < 1e-9 * got[3]


def _traces(mech, fast, monkeypatch):
    """The TrackResults of a defect analysis, with the compiled step test on or off."""
    rec = []

    def recording(*a, **k):
        r = tracking.track(*a, **k)
        rec.append(r)
        return r

    with monkeypatch.context() as m:
        m.setattr(defect_circuits, "track", recording)
        m.setattr(MotionProblem, "null_tangent", fast)
        res = defect_analysis(mech)
    return res, rec


def _assert_same_traces(a, b):
    assert len(a) == len(b)
    for ra, rb in zip(a, b, strict=True):
        assert ra.status == rb.status and ra.closed == rb.closed
        assert len(ra.s) == len(rb.s) and ra.rejected == rb.rejected
        assert np.max(np.abs(ra.s - rb.s)) < TRACE_TOL
        assert max(float(np.max(np.abs(x - y))) for x, y in zip(ra.tangents, rb.tangents, strict=True)) < TRACE_TOL
        assert [e.name for e in ra.events] == [e.name for e in rb.events]
        assert all(abs(x.s - y.s) < TRACE_TOL for x, y in zip(ra.events, rb.events, strict=True))


@pytest.mark.parametrize("name", ["five-cs-1", "five-cs-2", pytest.param("five-cs-3", marks=pytest.mark.slow)])
def test_compiled_step_test_traces_the_same_circuits_as_the_svd_path(name, monkeypatch):
    if not backend.enabled():
        pytest.skip("the compiled engine is not in use")
    mech = catalog.build(name)
    ra, fast = _traces(mech, True, monkeypatch)
    rb, ref = _traces(mech, False, monkeypatch)
    _assert_same_traces(fast, ref)
    assert ra.usable_drivers == rb.usable_drivers
    assert len(ra.circuits) == len(rb.circuits)
    assert (ra.circuit_defect, ra.order_defect) == (rb.circuit_defect, rb.order_defect)


@pytest.mark.slow
def test_compiled_step_test_agrees_with_the_python_reference_on_five_cs_1(monkeypatch):
    if not backend.enabled():
        pytest.skip("the compiled engine is not in use")
    mech = catalog.build("five-cs-1")
    ra, fast = _traces(mech, True, monkeypatch)
    with backend.python_reference():
        rb, ref = _traces(mech, True, monkeypatch)  # null_tangent on, but no engine: the SVD path
    _assert_same_traces(fast, ref)
    assert ra.usable_drivers == rb.usable_drivers


# ------------------------------------------------------------------ the compiled loop (kernels_trace.nb_trace)
def flat(o, path=""):
    """``(path, leaf)`` pairs of a JSON-like document."""
    if isinstance(o, dict):
        for k, v in o.items():
            yield from flat(v, f"{path}/{k}")
    elif isinstance(o, (list, tuple)):
        for i, v in enumerate(o):
            yield from flat(v, f"{path}[{i}]")
    else:
        yield path, o


def assert_same_document(a: dict, b: dict, tol: float = TRACE_TOL) -> None:
    """Two JSON documents with the same keys and leaves, floats to ``tol`` (relative above 1)."""
    fa, fb = dict(flat(a)), dict(flat(b))
    assert fa.keys() == fb.keys()
    for k, x in fa.items():
        y = fb[k]
        if isinstance(x, float) and isinstance(y, float):
            assert x == y or abs(x - y) <= tol * max(1.0, abs(x)), (k, x, y)
        else:
            assert x == y, (k, x, y)


def _analysis(mech, monkeypatch, python: bool):
    """A defect analysis, its TrackResults and the compiled loop's return codes, with the
    tracker's compiled loop or inside ``python_loop()``."""
    from spatialmech.kinematics.compiled import trace

    rec, codes = [], []
    run = trace.TraceLoop.run

    def recording(*a, **k):
        r = tracking.track(*a, **k)
        rec.append(r)
        return r

    def counting(self, *a, **k):
        codes.append(run(self, *a, **k))
        return codes[-1]

    with monkeypatch.context() as m:
        m.setattr(defect_circuits, "track", recording)
        m.setattr(trace.TraceLoop, "run", counting)
        if python:
            with tracking.python_loop():
                res = defect_analysis(mech)
        else:
            res = defect_analysis(mech)
    return res, rec, codes


@pytest.mark.parametrize("name, rank", [("five-cs-1", None), ("five-cs-2", None), ("five-cs-1", 1e-3)])
def test_the_compiled_loop_traces_what_the_python_loop_traces(name, rank, monkeypatch):
    """Points, arcs, tangents, DJ monitors, events (place, values, bracket, kind), statuses and
    counters of every traced circuit, and the whole analysis (JSON), to 1e-10 (measured: equal bit
    for bit).  five-cs-1: branch defects; five-cs-2: a circuit defect (four circuits).  With the
    rank tolerance at 1e-3 the bordered LU certifies no step: every step goes back to the Python
    loop (the kernel's hand-back path) and the result is still the reference's."""
    from spatialmech.geometry.tolerances import use
    from spatialmech.kinematics.compiled import trace

    if not backend.enabled():
        pytest.skip("the compiled engine is not in use")
    mech = catalog.build(name)
    with use(**({"rank": rank} if rank else {})):
        ra, fast, codes = _analysis(mech, monkeypatch, python=False)
        rb, ref, none = _analysis(mech, monkeypatch, python=True)
    assert not none and codes  # python_loop() keeps the kernel out; without it the kernel runs
    assert (trace.PYTHON_STEP in codes) == (rank is not None)
    assert len(fast) == len(ref)
    for a, b in zip(fast, ref, strict=True):
        assert (a.status, a.closed, a.rejected, a.corrector_iterations) == (b.status, b.closed, b.rejected,
                                                                            b.corrector_iterations)
        assert len(a.points) == len(b.points) and np.max(np.abs(a.s - b.s)) <= TRACE_TOL
        assert max(float(np.max(np.abs(x.q - y.q))) for x, y in zip(a.points, b.points, strict=True)) <= TRACE_TOL
        assert max(float(np.max(np.abs(x - y))) for x, y in zip(a.tangents, b.tangents, strict=True)) <= TRACE_TOL
        assert a.monitors.keys() == b.monitors.keys()
        for k in a.monitors:
            assert np.allclose(a.monitors[k], b.monitors[k], rtol=TRACE_TOL, atol=0.0)
        assert [(e.name, e.step, e.kind) for e in a.events] == [(e.name, e.step, e.kind) for e in b.events]
        for e, f in zip(a.events, b.events, strict=True):
            assert abs(e.s - f.s) <= TRACE_TOL and np.max(np.abs(e.x.q - f.x.q)) <= TRACE_TOL
            assert np.allclose([e.value_before, e.value_after, e.value, *e.bracket],
                               [f.value_before, f.value_after, f.value, *f.bracket], rtol=TRACE_TOL, atol=1e-300)
    assert_same_document(ra.to_dict(), rb.to_dict())


@pytest.mark.parametrize("kw", [dict(max_turn_deg=0.2, h_min=1e-2), dict(max_arc=0.7), dict(max_steps=25),
                                dict(detect_closure=False, max_arc=5.0)])
def test_the_compiled_loop_ends_a_track_as_the_python_loop_does(kw, monkeypatch):
    """No acceptable step above ``h_min`` (the same message), the arc and step budgets, no loop
    closure: the same status, points, rejections and events on both loops.  The kernel's output
    arrays hold 8 points and 4 events here: it refills them (``FULL``) many times a track."""
    from spatialmech.analysis.defects import candidate_drivers, dj_function
    from spatialmech.kinematics.compiled import trace
    from spatialmech.kinematics.position import configuration_at_pose

    monkeypatch.setattr(trace.TraceLoop, "CAPACITY", (8, 4))

    if not backend.enabled():
        pytest.skip("the compiled engine is not in use")
    mech = catalog.build("five-cs-1")
    x0 = configuration_at_pose(mech, mech.positions[0]).config
    drivers = candidate_drivers(mech)
    mon = (drivers, dj_function(mech, drivers, x0)[0])
    a = tracking.track(MotionProblem(mech), x0, vector_monitor=mon, **kw)
    with tracking.python_loop():
        b = tracking.track(MotionProblem(mech), x0, vector_monitor=mon, **kw)
    assert (a.status, a.message, a.rejected, len(a.points)) == (b.status, b.message, b.rejected, len(b.points))
    assert np.max(np.abs(a.s - b.s)) <= TRACE_TOL and [e.name for e in a.events] == [e.name for e in b.events]
    assert all(abs(e.s - f.s) <= TRACE_TOL for e, f in zip(a.events, b.events, strict=True))


def _problems_and_traces(mech):
    """``(MotionProblem, TrackResult)`` of each circuit a defect analysis of ``mech`` traces."""
    rec = []

    def recording(*a, **k):
        rec.append((a[0], tracking.track(*a, **k)))
        return rec[-1][1]

    with pytest.MonkeyPatch.context() as m:
        m.setattr(defect_circuits, "track", recording)
        defect_analysis(mech, sigma_along_path=False)
    return rec


def test_the_pruned_nearest_point_is_the_full_argmin():
    """``compiled.nearest_point`` (the full difference only where its bound does not rule a point
    out) returns the index of the full ``argmin`` of the distances, on a traced 5-CS circuit, for
    the traced points themselves, points between them and configurations off the curve."""
    from spatialmech.kinematics import compiled

    if not backend.enabled():
        pytest.skip("the compiled engine is not in use")
    mech = catalog.build("five-cs-1")
    prob, tr = _problems_and_traces(mech)[0]
    rng = np.random.default_rng(0)
    queries = [tr.points[k] for k in range(0, len(tr.points), 7)]
    queries += [prob.retract(tr.points[k], 0.5 * (tr.s[k + 1] - tr.s[k]) * tr.tangents[k])
                for k in range(0, len(tr.points) - 1, 11)]
    queries += [prob.retract(tr.points[k], 0.3 * rng.normal(size=len(tr.tangents[k]))) for k in range(0, len(tr.points), 13)]
    wrap = prob.kinds != "P"
    for y in queries:
        d = np.linalg.norm(prob.differences(tr.points, y, tr.stacked()), axis=1)
        assert compiled.nearest_point(mech, tr.stacked(), y, prob.active, wrap, prob.col) == int(np.argmin(d))


@pytest.mark.parametrize("name", ["five-cs-1", "five-cs-2"])
def test_the_sigma_floors_bound_the_ratios_and_the_pruned_minimum_is_the_full_one(name):
    """Every floor the compiled loop writes (``TrackResult.sigma_floor``) is at most the scale-free
    closure sigma ``sigma_n / sigma_1`` the reference's SVD gives at that point, most points have
    one, and :func:`defect_circuits.closure_sigma_ratios` (an SVD only where the floors do not
    rule a point out) gives the full computation's smallest ratio, at the same first point.  Where the ratio varies
    along a circuit by less than the floors' slack (about 5) nothing is pruned (one of
    five-cs-2's circuits); some points are, over each model's circuits."""
    if not backend.enabled():
        pytest.skip("the compiled engine is not in use")
    rec = _problems_and_traces(catalog.build(name))
    pruned = 0
    for prob, tr in rec:
        assert tr.sigma_floor is not None and tr.sigma_floor.shape == (len(tr.points),)
        full = np.array([(lambda sv: sv[-1] / sv[0])(np.linalg.svd(prob.jacobian(x), compute_uv=False))
                         for x in tr.points])
        has = tr.sigma_floor > 0
        assert has.mean() > 0.9
        assert np.all(tr.sigma_floor[has] <= full[has])
        got = defect_circuits.closure_sigma_ratios(prob, tr.points, tr.sigma_floor)
        pruned += int(np.isinf(got).sum())
        k = int(np.argmin(full))
        assert int(np.argmin(got)) == k and got[k] == full[k]
        assert np.all(got[np.isfinite(got)] == full[np.isfinite(got)])
    assert pruned > 0
