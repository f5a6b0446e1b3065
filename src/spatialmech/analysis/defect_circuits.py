"""Circuit geometry for the defect analysis (:func:`spatialmech.analysis.defects.defect_analysis`):
tracing a circuit with its DJ monitor, where a configuration or a printed pose lies on a traced
curve, the fewest circuits that hold every position, which positions bracket an arc along the
path, and the driver-switching plan of a multi-drive (paper A section 6).

These are steps of the defect analysis, public so that the analysis module can import them; the
results of the analysis are its own (:class:`~spatialmech.analysis.defects.DefectResult`).
Arcs are the nondimensional arc length of the tracked curve (joint rad, lengths / L).
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import combinations

import numpy as np

from ..kinematics.closure import Configuration
from ..kinematics.jacobian import complete_jacobians
from ..kinematics.tracking import MotionProblem, TrackResult, compiled_loops, predict_correct, track
from ..model.mechanism import Mechanism, Pose
from ..results import Progress

__all__ = [
    "arc_on_curve",
    "closure_sigma_ratios",
    "driver_sigmas",
    "fewest_circuits",
    "pose_distance",
    "positions_between",
    "switching_plan",
    "trace_circuit",
]


def trace_circuit(mech: Mechanism, start: Configuration, names: list[str], djf: Callable, max_arc: float,
                  h0: float, progress: Progress | None = None, *,
                  sense: int = 1) -> tuple[MotionProblem, TrackResult]:
    """The circuit of ``mech`` through ``start``, traced by the continuation tracker with the DJ
    of every driver in ``names`` (``djf``: configuration -> array, one value per driver) as a
    vector monitor, so that its zeros (branch points) and poles become events of the track.
    ``sense``: ``1`` the conventional sense of travel, ``-1`` the opposite one."""
    prob = MotionProblem(mech, sense=sense)
    tr = track(prob, start, vector_monitor=(names, djf), max_arc=max_arc, h0=h0, event_tol=1e-9,
               progress=progress)
    return prob, tr


def arc_on_curve(problem: MotionProblem, tr: TrackResult, config: Configuration, tol: float) -> float | None:
    """Arc length of ``config`` on the traced curve ``tr``, or ``None`` when it is not on it
    (its distance from the curve, nondimensional, is ``tol`` or more).

    The nearest sample and its neighbours are each corrected onto the curve along their tangent
    (the hyperplane through ``config``); the closest corrected point gives the arc."""
    if (fast := compiled_loops()) is not None:  # the same nearest sample, its distance pruned by a bound
        k0 = fast.nearest_point(problem.mech, tr.stacked(), config, problem.active, problem.kinds != "P", problem.col)
    else:
        k0 = int(np.argmin(np.linalg.norm(problem.differences(tr.points, config, tr.stacked()), axis=1)))
    ks = list({max(0, k0 - 1), k0, min(len(tr.points) - 1, k0 + 1)})  # the reference's order (ties)
    if fast is not None:
        dist_c, arc = fast.arc_near(problem.step_arrays(fast), tr.stacked(), tr.stacked_tangents(), tr.s, ks, config)
        return arc if dist_c < tol else None
    best: tuple[float, float | None] = (np.inf, None)
    for k in ks:
        x, t = tr.points[k], tr.tangents[k]
        a = float(t @ problem.difference(x, config))
        xs, ok, _, _ = predict_correct(problem, x, a * t, t, 1e-11, 30)
        if not ok:
            continue
        dist = float(np.linalg.norm(problem.difference(xs, config)))
        if dist < best[0]:
            best = (dist, tr.s[k] + a)
    return best[1] if best[0] < tol else None


def _pose_of(mech: Mechanism, x: Configuration):
    """Orientation and platform point of the output link in configuration ``x``."""
    D = x.D
    return D[:3, :3], D[:3, :3] @ mech.platform_point + D[:3, 3]


def pose_distance(mech: Mechanism, prob: MotionProblem, tr: TrackResult, pose: Pose, pose_tol: float,
                  angle_tol: float) -> tuple[float, float, float, float]:
    """Distance of a printed pose from a traced curve, normalised by the tolerances
    (``hypot(|dp| / pose_tol, dtheta / angle_tol)``, ``angle_tol`` in rad), refined along the
    curve between samples by bounded Brent search (compiled, :func:`_nearest_on_step`, unless
    :func:`~..kinematics.tracking.python_loop` is in force).  Returns (normalised distance, arc,
    |dp|, dtheta)."""

    def meas_many(xs, Ds=None):
        Ds = np.array([x.D for x in xs]) if Ds is None else Ds
        R = np.ascontiguousarray(Ds[:, :3, :3])
        p = R @ mech.platform_point + np.ascontiguousarray(Ds[:, :3, 3])
        dp = np.linalg.norm(p - pose.p, axis=1)
        Q = R @ pose.R.T  # the rotation angle: atan2(|axial vector|, (trace - 1) / 2), exact to rounding up to pi
        ax = np.stack([Q[:, 2, 1] - Q[:, 1, 2], Q[:, 0, 2] - Q[:, 2, 0], Q[:, 1, 0] - Q[:, 0, 1]], axis=1)
        th = np.arctan2(0.5 * np.linalg.norm(ax, axis=1), 0.5 * (np.trace(Q, axis1=1, axis2=2) - 1.0))
        return np.hypot(dp / pose_tol, th / angle_tol), dp, th

    def meas(x):
        v, dp, th = meas_many([x])
        return float(v[0]), float(dp[0]), float(th[0])

    vals = meas_many(tr.points, tr.stacked()[1])[0]
    k0 = int(np.argmin(vals))
    best = (float(vals[k0]), float(tr.s[k0]), *meas(tr.points[k0])[1:])
    fast = compiled_loops()
    for k in (k0 - 1, k0):
        if k < 0 or k + 1 >= len(tr.points):
            continue
        x, t, h = tr.points[k], tr.tangents[k], float(tr.s[k + 1] - tr.s[k])
        if fast is not None:
            m = _nearest_on_step(fast, mech, prob, x, t, h, pose, pose_tol, angle_tol)
            if m[1] < best[0]:
                best = (m[1], float(tr.s[k] + m[0]), m[2], m[3])
            continue
        cache: dict[float, tuple[float, float, float]] = {}

        def at(a, x=x, t=t, cache=cache):
            if a not in cache:
                xa, ok, _, _ = predict_correct(prob, x, a * t, t, 1e-11, 20)
                cache[a] = meas(xa) if ok else (np.inf, np.inf, np.inf)
            return cache[a]

        # the distance along one step of the curve: bounded Brent (golden section with parabolic steps)
        from scipy.optimize import minimize_scalar  # the Python loop only: the compiled search is its own

        opt = minimize_scalar(lambda a, at=at: at(a)[0], bounds=(0.0, h), method="bounded",
                              options={"xatol": 1e-6 * max(h, 1e-12)})
        a = float(opt.x)
        m = at(a)
        if m[0] < best[0]:
            best = (m[0], float(tr.s[k] + a), m[1], m[2])
    return best


def _nearest_on_step(fast, mech: Mechanism, prob: MotionProblem, x: Configuration, t: np.ndarray, h: float, pose: Pose,
                     pose_tol: float, angle_tol: float) -> tuple[float, float, float, float]:
    """:func:`pose_distance`'s search along one step, compiled (SciPy's bounded Brent step for
    step, :func:`.compiled.trace.pose_search`): ``(step length, normalised distance, |dp|,
    dtheta)`` of the best point."""
    P = np.concatenate([np.asarray(pose.R, dtype=float).ravel(), np.asarray(pose.p, dtype=float),
                        np.asarray(mech.platform_point, dtype=float), [pose_tol, angle_tol]])
    return fast.pose_search(prob.step_arrays(fast), x, t, h, P, 1e-6 * max(h, 1e-12))


def closure_sigma_ratios(problem: MotionProblem, points: list, floor: np.ndarray | None = None) -> np.ndarray:
    """The scale-free closure sigma ``sigma_n / sigma_1`` of the problem's (nondimensional)
    closure Jacobian at each point, or ``inf`` at a point that cannot hold the smallest: its
    ``floor`` (a lower bound of the ratio, 0 where unknown: ``TrackResult.sigma_floor``), taken
    with a margin of 10 %, exceeds a ratio already computed.  The smallest ratio and the first
    point holding it are those of every point computed.  Compiled: the Jacobians of the points
    in one call and one stacked SVD (the same numbers, point by point), the points in the order
    of their floors, in blocks, until the next floor clears the smallest ratio so far; inside
    ``python_loop()``, the reference's loop at every point."""
    fast = compiled_loops()
    if fast is None or len(points) < 2:
        return np.array([_ratio(np.linalg.svd(problem.jacobian(x), compute_uv=False)) for x in points])

    def ratios(idx) -> np.ndarray:
        pts = [points[i] for i in idx]
        A, _ = fast.closure_jacobians(problem.mech, np.array([x.q for x in pts]), np.array([x.D for x in pts]),
                                      np.array([x.B for x in pts]), active=problem.active)
        sv = np.linalg.svd(problem.row[None, :, None] * A * problem.col[None, None, :], compute_uv=False)
        return sv[:, -1] / sv[:, 0]

    out = np.full(len(points), np.inf)
    if floor is None:
        out[:] = ratios(np.arange(len(points)))
        return out
    f = 0.9 * np.asarray(floor, dtype=float)  # computed in floating point: a margin
    f[~np.isfinite(f)] = 0.0  # never skip a point for a bound that is not a number
    order = np.argsort(f, kind="stable")
    best, k = np.inf, 0
    while k < len(order) and f[order[k]] <= best:
        idx = order[k:k + _SIGMA_BLOCK]
        idx = idx[f[idx] <= best]
        out[idx] = ratios(idx)
        best = min(best, float(np.min(out[idx])))
        k += _SIGMA_BLOCK
    return out


#: Points per block of :func:`closure_sigma_ratios`'s pruned search.
_SIGMA_BLOCK = 16


def _ratio(sv: np.ndarray) -> float:
    """The scale-free sigma ``sigma_n / sigma_1`` of singular values ``sv`` (descending)."""
    return float(sv[-1] / sv[0])


def driver_sigmas(mech: Mechanism, points: list, drivers: list[str]) -> np.ndarray:
    """``CompleteJacobian.sigma_min`` of each driver alone at each point ``(points, drivers)``:
    the compiled kernel for all points at once where it decides (the same matrices), else one
    set of constraint wrenches per point shared by the drivers (``complete_jacobians``), as
    inside ``python_loop()``."""
    if not drivers or not points:
        return np.zeros((len(points), len(drivers)))
    if (fast := compiled_loops()) is not None and len(points) >= 2:
        sig = fast.driver_sigmas_many(mech, np.array([x.q for x in points]), np.array([x.D for x in points]),
                                      np.array([x.B for x in points]), drivers)
        if sig is not None:
            return sig
    return np.array([[cj.sigma_min for cj in complete_jacobians(mech, x, [[d] for d in drivers])] for x in points])


def fewest_circuits(D: np.ndarray) -> list[int]:
    """Fewest circuits (rows of ``D``) covering every position (column) within tolerance
    (``D <= 1``, the normalised distances of :func:`pose_distance`); ties broken by the smallest
    total distance.  Positions no circuit covers keep their own (the nearest).  Sorted indices."""
    nC, nP = D.shape
    need = [j for j in range(nP) if np.any(D[:, j] <= 1.0)]
    for size in range(1, nC + 1):
        best = None
        for sub in combinations(range(nC), size):
            if all(np.any(D[list(sub), j] <= 1.0) for j in need):
                cost = sum(np.min(D[list(sub), j]) for j in need)
                if best is None or cost < best[0]:
                    best = (cost, list(sub))
        if best is not None:
            chosen = best[1]
            for j in range(nP):  # positions out of tolerance everywhere: their own circuit
                if j not in need:
                    chosen.append(int(np.argmin(D[:, j])))
            return sorted(set(chosen))
    return list(range(nC))


def positions_between(arc: float, arcs: list[float]) -> tuple[int, int] | None:
    """Positions (from 1) whose arcs bracket ``arc`` on the path (``arcs`` sorted along the
    path), or ``None`` outside them."""
    for j in range(len(arcs) - 1):
        if arcs[j] <= arc <= arcs[j + 1]:
            return (j + 1, j + 2)
    return None


def switching_plan(drivers: list[str], zeros: dict[str, list[float]], a: float, b: float):
    """Fewest driver switches covering the path ``[a, b]`` with no driver passing its own DJ
    zero (``zeros``: the arcs of each driver's zeros on the path).

    Greedy: from the current arc, take the driver that goes furthest before its next zero; it
    must be switched before that zero, after the last zero of the next driver, in the middle of
    that window.  Returns ``[driver, from_arc, to_arc, switch_window or None]`` per step, or
    ``None`` when no plan exists (or it needs more than 20 steps)."""
    steps: list[list] = []
    c = a
    current = None
    guard = 0
    while guard < 20:
        guard += 1
        reach = {}
        for d in drivers:
            nxt = [z for z in zeros[d] if z > c + 1e-12]
            reach[d] = min(nxt) if nxt else np.inf
        if current is None:
            current = max(drivers, key=lambda d: reach[d])
        r = reach[current]
        if r >= b:
            steps.append([current, c, b, None])
            return steps
        # next driver: regular on (w, its next zero) with w < r
        best, best_reach, best_lo = None, -np.inf, None
        for d in drivers:
            if d == current:
                continue
            before = [z for z in zeros[d] if z < r]
            lo = max([c, *before])
            if lo >= r:
                continue
            nxt = [z for z in zeros[d] if z > lo + 1e-12]
            rd = min(nxt) if nxt else np.inf
            # furthest reach first; on a tie the widest switching window
            if rd > best_reach or (rd == best_reach and best_lo is not None and lo < best_lo):
                best, best_reach, best_lo = d, rd, lo
        if best is None or best_lo is None or best_reach <= r:  # best_lo is set with best
            return None
        c_new = 0.5 * (best_lo + r)  # switch in the middle of the window
        steps.append([current, c, c_new, (best_lo, r)])
        c = c_new
        current = best
    return None
