"""Pseudo-arclength continuation of one-dimensional solution curves.

The core (:func:`track`) follows the curve ``F(x) = 0``, ``F: R^(n+1) -> R^n`` (or a curve on a
manifold given by a *problem*: residual, Jacobian in local coordinates, retraction), with

- Keller's predictor-corrector: Euler predictor along the unit tangent, Newton corrector on
  the hyperplane orthogonal to the tangent at distance ``h``;
- step-size control: growth after easy corrections, halving after a rejection;
- guards against jumping to another branch: the corrector must contract, end close to the
  predicted point, and the new tangent must turn by less than ``max_turn`` — otherwise the
  step is halved and retried; below ``h_min`` the tracker stops and says why;
- events: sign changes of monitor functions (e.g. ``DJ`` of each driver) located by bisection
  on the step length to ``event_tol``;
- loop closure: the curve is closed when it crosses the hyperplane through the start point,
  orthogonal to the start tangent, close to the start.

The mechanism problems (:class:`MotionProblem`, :class:`ActuatorPathProblem`) turn a mechanism
into such a curve: a one-degree-of-freedom motion, or the configurations along a path of
actuator values (forward position by continuation).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..errors import ConvergenceError, InputError
from ..geometry.rotations import inverse_transform, log_transform, rotation_class
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism
from ..results import EventKind, Progress, TrackStatus
from . import backend
from .closure import Configuration, active_mask, ball_groups, closure_scales, hub_count
from .backend import closure_jacobian, retract
from .tracking_loop import DriverMonitor, compiled_loop, compiled_loops, python_loop, run_compiled

__all__ = [
    "SENSE_TOL",
    "ActuatorPathProblem",
    "CurveProblem",
    "DriverMonitor",
    "EuclideanProblem",
    "Event",
    "MotionProblem",
    "TrackResult",
    "compiled_loops",
    "conventional_sense",
    "correct_on_hyperplane",
    "predict_correct",
    "python_loop",
    "sense_order",
    "trace_motion",
    "track",
]


class CurveProblem(Protocol):
    """What :func:`track` needs.  ``x`` is any state; local coordinates are vectors of size
    ``n + 1`` (nondimensional)."""

    def residual(self, x) -> np.ndarray: ...

    def jacobian(self, x) -> np.ndarray: ...

    def retract(self, x, dx: np.ndarray): ...

    def difference(self, x, y) -> np.ndarray:  # local coordinates of y relative to x
        ...

    def tangent(self, x) -> np.ndarray: ...


#: A component of a unit tangent (nondimensional local coordinates) counts for the sense
#: convention (:func:`conventional_sense`) when its magnitude exceeds this. Rounding differences
#: between the compiled and Python paths, or between BLAS kernels, are ~1e-13: far below it.
SENSE_TOL = 1e-6


def conventional_sense(t: np.ndarray, order=(), tol: float = SENSE_TOL) -> float:
    """``+1.0`` or ``-1.0``: the sign that gives the tangent ``t`` the documented sense of travel
    (docs/conventions.md, *Sense of a traced motion*), whatever sign the SVD returned.

    The first coordinate in ``order`` (then every coordinate, in index order) whose component of
    the unit tangent exceeds ``tol`` in magnitude is made positive.  A nonzero unit vector of
    fewer than 1e12 coordinates always has one, so the rule depends on the model and the point
    only, never on the linear-algebra kernel."""
    t = np.asarray(t, dtype=float)
    n = float(np.linalg.norm(t))
    if not n > 0:
        return 1.0
    for i in (*order, *range(t.size)):
        c = float(t[i]) / n
        if abs(c) > tol:
            return 1.0 if c > 0 else -1.0
    return 1.0


def sense_order(mech: Mechanism, active: np.ndarray, first: str | None = None) -> list[int]:
    """Local coordinates (positions among the ``active`` freedoms) that decide the sense of a
    traced motion, in priority order: ``first`` (a freedom name) when given, then the
    mechanism's actuators in their declared order (those that are active)."""
    refs = mech.freedom_refs
    idx = np.flatnonzero(active).tolist()
    out: list[int] = []
    names = ([first] if first is not None else []) + list(mech.actuators)
    for k, name in enumerate(names):
        i = refs.index(mech.freedom(name))
        if k == 0 and first is not None and not active[i]:
            raise InputError(f"increasing: {first} is locked in this mode")
        if active[i] and idx.index(i) not in out:
            out.append(idx.index(i))
    return out


def _null_tangent(A: np.ndarray) -> np.ndarray:
    _, _, vt = np.linalg.svd(A, full_matrices=True)
    return vt[-1]


_LAST_SVD: list = [None, None]  # the last full SVD and the array it belongs to (see _full_svd)


def _full_svd(A: np.ndarray):
    """``np.linalg.svd(A, full_matrices=True)``, remembered for the last array: the tracker asks
    for the tangent and then for Keller's frame of the same Jacobian (the array object returned
    by the problem's memo; arrays are not changed in place here)."""
    if _LAST_SVD[0] is A:
        return _LAST_SVD[1]
    out = np.linalg.svd(A, full_matrices=True)
    _LAST_SVD[0], _LAST_SVD[1] = A, out
    return out


def _observable_tangent(A: np.ndarray, n_obs: int) -> np.ndarray:
    """Unit tangent of a curve whose Jacobian ``A`` may also vanish on passive directions (those
    that leave the last ``n_obs`` coordinates, e.g. the platform twist, at rest): the null
    vector with the largest observable part, which has no passive component."""
    _, sv, vt = _full_svd(A)
    r = int(np.sum(sv > current_tolerances().rank * max(1.0, sv[0]))) if sv.size else 0
    N = vt[r:]
    if N.shape[0] == 0:
        raise ConvergenceError("no tangent: the mechanism cannot move at this configuration (rigid)")
    if N.shape[0] == 1:
        return N[0]
    u, _, _ = np.linalg.svd(N[:, -n_obs:])
    t = u[:, 0] @ N
    return t / np.linalg.norm(t)


@dataclass
class EuclideanProblem:
    """``F: R^(n+1) -> R^n`` given as callables (``J`` optional: finite differences)."""

    F: Callable[[np.ndarray], np.ndarray]
    J: Callable[[np.ndarray], np.ndarray] | None = None

    def residual(self, x):
        return np.asarray(self.F(x), dtype=float)

    def jacobian(self, x):
        if self.J is not None:
            return np.asarray(self.J(x), dtype=float)
        h = 1e-7
        f0 = self.residual(x)
        return np.stack([(self.residual(x + h * e) - f0) / h for e in np.eye(len(x))], axis=1)

    def retract(self, x, dx):
        return np.asarray(x, dtype=float) + dx

    def difference(self, x, y):
        return np.asarray(y, dtype=float) - np.asarray(x, dtype=float)

    def tangent(self, x):
        return _null_tangent(self.jacobian(x))


@dataclass(frozen=True)
class Event:
    """A located zero of a monitor function along the curve."""

    name: str
    s: float  # arc length (nondimensional) from the start
    x: object
    step: int  # index of the accepted point after which it lies
    value_before: float
    value_after: float
    value: float = 0.0  # the monitor at the located point
    bracket: tuple[float, float] = (0.0, 0.0)  # monitor values at the ends of the final bracket

    @property
    def kind(self) -> EventKind:
        """``"zero"``, or ``"pole"`` when the sign changed through infinity: both values of the
        final (tiny) bracket are larger than both ends of the step."""
        lo = min(abs(self.bracket[0]), abs(self.bracket[1]))
        return EventKind.POLE if lo > max(abs(self.value_before), abs(self.value_after)) else EventKind.ZERO


@dataclass
class TrackResult:
    points: list
    s: np.ndarray
    tangents: list
    monitors: dict[str, np.ndarray]
    events: list[Event]
    closed: bool
    status: TrackStatus  # closed, max_arc, stopped, or h_min (failure: ``reason`` says why)
    rejected: int = 0
    corrector_iterations: int = 0
    min_monitor: dict[str, float] = field(default_factory=dict)
    reason: str = ""  # why the tracker failed (empty unless ``status`` is h_min)
    _stacked: tuple | None = field(default=None, repr=False, compare=False)
    _tangents: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: Per point, a floor of ``sigma_n / sigma_1`` of the problem's scaled Jacobian from the compiled step test's LU
    #: (``1 / (|[A; t]^-1|_F |A|_F)``, :mod:`.compiled.kernels_trace`), else 0; ``None``: none (use with a margin).
    sigma_floor: np.ndarray | None = field(default=None, repr=False, compare=False)

    def stacked(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The points' ``q``, ``D`` and ``B`` stacked (points that are configurations; remembered)."""
        if self._stacked is None:
            self._stacked = (np.array([x.q for x in self.points], dtype=float),
                             np.array([x.D for x in self.points], dtype=float),
                             np.array([x.B for x in self.points], dtype=float))
        return self._stacked

    def stacked_tangents(self) -> np.ndarray:
        """The tangents stacked (remembered)."""
        if self._tangents is None:
            self._tangents = np.array(self.tangents, dtype=float)
        return self._tangents

    @property
    def ok(self) -> bool:
        return self.status.ok

    @property
    def message(self) -> str:
        """The status with its reason, e.g. ``"h_min: no acceptable step above 1e-07 at ..."``."""
        return f"{self.status}: {self.reason}" if self.reason else str(self.status)


def _frame(A: np.ndarray, t: np.ndarray):
    """Row-space projection ``P`` and passive null directions ``G`` of ``A`` at a point, such that
    ``[P A; G; t]`` is square.  Kept fixed while a step is checked."""
    U, sv, vt = _full_svd(A)
    r = int(np.sum(sv > current_tolerances().rank * max(1.0, sv[0]))) if sv.size else 0
    if r == A.shape[0] and A.shape[1] == r + 1:
        # full row rank, a one-dimensional null space: P = U^T is orthogonal and G is empty, so
        # det [P A; t] = det(U^T) det [A; t], and det(U^T) is the same for every check made
        # with this frame: Keller's test compares the signs of det [A; t] alone
        return None, None
    P = U[:, :r].T
    N = vt[r:]
    Nt = N - np.outer(N @ t, t)  # null directions other than the tangent
    if Nt.shape[0] > 1:
        _, _s2, w = np.linalg.svd(Nt)
        G = w[: Nt.shape[0] - 1]
    else:
        G = np.zeros((0, A.shape[1]))
    return P, G


def _orientation(A: np.ndarray, t: np.ndarray, frame) -> float:
    """Sign of ``det [P A; G; t]``: constant along a regular branch with a continuously oriented
    tangent; it flips when a step crosses to another branch (Keller's test)."""
    P, G = frame
    M = np.vstack([A, t[None, :]]) if P is None else np.vstack([P @ A, G, t[None, :]])
    if M.shape[0] != M.shape[1]:
        return 0.0
    sign, _ = np.linalg.slogdet(M)
    return float(sign)


def _step_tangent(problem, xn, t: np.ndarray, frame) -> tuple[np.ndarray, np.ndarray, float | None]:
    """The unit tangent at the trial point ``xn`` in the sense of ``t``, the Jacobian there, and
    Keller's orientation ``sign det [A; tangent]`` when the compiled step test
    (:func:`.compiled.kernels_tracking.bordered_tangent`: one LU of ``[A; t]``, no SVD) applies
    and certifies that ``A`` has full row rank under the reference's rank test (``None``: the
    caller computes the orientation as the reference does).  The compiled test runs for the
    mechanism problems whose tangent is the Jacobian's null vector, while the frame of the last
    accepted point is the full-rank one; the same tangent and sign as the reference's SVD to
    rounding (``tests/test_tracking_compiled.py``)."""
    A_n = problem.jacobian(xn)
    fast = backend.engine() if frame[0] is None and getattr(problem, "null_tangent", False) else None
    if fast is not None and A_n.ndim == 2 and A_n.shape[1] == A_n.shape[0] + 1:
        got = fast.bordered_tangent(A_n, t)
        # sigma_n(A) >= smin and sigma_1(A) <= |A|_F: a margin of 10 over the rank test's threshold
        if got is not None and got[2] > 10.0 * current_tolerances().rank * max(1.0, got[3]):
            return got[0], A_n, got[1]
    tn = problem.tangent(xn)
    tn = tn / np.linalg.norm(tn)
    if float(tn @ t) < 0:
        tn = -tn
    return tn, A_n, None


def correct_on_hyperplane(problem, xp, t, tol, max_iter, contraction=0.6):
    """Newton on ``F(x) = 0`` with every correction orthogonal to ``t`` (the pseudo-arclength
    corrector; also used to land on a curve at a given distance along a tangent).  Returns
    ``(x, converged, iterations, total correction length)``; it stops early when the corrections
    stop contracting."""
    fast = getattr(problem, "compiled_correct", None)
    if fast is not None and backend.enabled():
        return fast(xp, t, tol, max_iter, contraction)
    moved = 0.0
    prev = np.inf
    for it in range(max_iter):
        r = problem.residual(xp)
        rn = float(np.linalg.norm(r))
        if rn < tol:
            return xp, True, it, moved
        A = problem.jacobian(xp)
        M = np.vstack([A, t[None, :]])
        rhs = np.r_[-r, 0.0]
        # minimum-norm least squares: the compiled solver when in use (the same solution to rounding)
        d = engine.lstsq(M, rhs) if (engine := backend.engine()) is not None else np.linalg.lstsq(M, rhs, rcond=None)[0]
        dn = float(np.linalg.norm(d))
        if it > 0 and dn > contraction * prev:
            return xp, False, it, moved
        prev = dn
        moved += dn
        xp = problem.retract(xp, d)
    return xp, float(np.linalg.norm(problem.residual(xp))) < tol, max_iter, moved


def predict_correct(problem, x, step, t, tol, max_iter, contraction=0.6):
    """``correct_on_hyperplane(problem, problem.retract(x, step), t, ...)``: the predictor step
    and the corrector, in one compiled call for a mechanism's motion."""
    fast = getattr(problem, "compiled_correct", None)
    if fast is not None and backend.enabled():
        return fast(x, t, tol, max_iter, contraction, predictor=step)
    return correct_on_hyperplane(problem, problem.retract(x, step), t, tol, max_iter, contraction)


@dataclass(frozen=True)
class _Settings:
    """The arguments of :func:`track` that the steps read."""

    x0: object
    t0: np.ndarray
    h0: float
    h_min: float
    h_max: float
    max_arc: float
    max_steps: int
    tol: float
    cos_max: float
    event_tol: float
    detect_closure: bool
    stop: Callable | None
    progress: Progress | None


@dataclass
class _Walk:
    """The tracker's state between steps: the current point ``x``, tangent ``t``, arc ``s``, step
    length ``h`` and Keller frame and orientation there, the points, arcs, tangents and monitor
    values so far, the events, the counters and the outcome."""

    x: object
    t: np.ndarray
    s: float
    h: float
    frame: tuple
    orient: float
    xs: list
    ss: list
    ts: list
    mon: dict[str, list[float]]
    events: list = field(default_factory=list)
    flips: int = 0
    rejected: int = 0
    total_iters: int = 0
    steps: int = 0
    d_last: tuple | None = None  # (point, difference of it from x0) of the last accepted step
    floors: dict = field(default_factory=dict)  # point index -> its sigma floor, from the compiled loop
    status: TrackStatus = TrackStatus.MAX_ARC
    reason: str = ""
    closed: bool = False

    def going(self, cfg: _Settings) -> bool:
        return self.s < cfg.max_arc and self.steps < cfg.max_steps

    def close(self, s: float, event_tol: float) -> None:
        """Closed at arc ``s``: an event at the closing point is the start point met again, not a
        new one."""
        self.events = [e for e in self.events if e.s < s - max(event_tol, 1e-9)]
        self.closed, self.status, self.s = True, TrackStatus.CLOSED, s

    def fail_h_min(self, cfg: _Settings) -> None:
        why = "an orientation flip (a bifurcation point or a crossing branch)" if self.flips else "a singular point"
        self.status = TrackStatus.H_MIN
        self.reason = f"no acceptable step above {cfg.h_min:g} at arc length {self.s:.6g}: {why}"


def _attempt(problem, w: _Walk, cfg: _Settings, h: float):
    """One predictor-corrector step of length ``h`` from ``w``'s point and its test: ``(ok, xn,
    tn, A_n, o_n, iterations)`` (``o_n``: the orientation at ``xn`` when the compiled step test
    certified it)."""
    xn, ok, iters, moved = predict_correct(problem, w.x, h * w.t, w.t, cfg.tol, 12)
    if not (ok and moved < 0.5 * h):
        return False, xn, None, None, None, iters
    tn, A_n, o_n = _step_tangent(problem, xn, w.t, w.frame)
    if float(tn @ w.t) < cfg.cos_max:
        return False, xn, tn, A_n, o_n, iters
    if w.orient != 0.0 and (o_n if o_n is not None else _orientation(A_n, tn, w.frame)) != w.orient:
        w.flips += 1  # the step crossed to another branch
        return False, xn, tn, A_n, o_n, iters
    return True, xn, tn, A_n, o_n, iters


def _closes(problem, w: _Walk, cfg: _Settings, xn, tn: np.ndarray, h: float) -> bool:
    """Whether the step from ``w``'s point to ``xn`` crosses the start point's plane close to
    it; if so the closing point is located and appended, and ``w`` is closed."""
    x0, t0 = cfg.x0, cfg.t0
    # the start point seen from the last point: remembered from the step before
    d_prev = w.d_last if w.d_last is not None and w.d_last[0] is w.x else (w.x, problem.difference(x0, w.x))
    d_new = (xn, problem.difference(x0, xn))
    w.d_last = d_new
    g0, g1 = float(t0 @ d_prev[1]), float(t0 @ d_new[1])
    if not (g0 < 0 <= g1 and np.linalg.norm(d_new[1]) < 3 * h + 1e-9 and float(tn @ t0) > 0):
        return False

    def gfun(y):  # land exactly on the start point's plane: the last point is the start again
        return float(t0 @ problem.difference(x0, y))

    ev = _locate(problem, w.x, w.t, h, gfun, "closure", g0, g1, w.s, len(w.xs) - 1, cfg.tol, cfg.event_tol)
    w.xs.append(ev.x)  # the caller appends the monitors there
    w.ss.append(ev.s)
    w.ts.append(tn)
    w.close(ev.s, cfg.event_tol)
    return True


def _python_step(problem, w: _Walk, cfg: _Settings, monitors: dict[str, Callable]) -> bool:
    """One step of the reference loop (a rejected step halves ``h``); False when the track ends."""
    h = w.h = min(w.h, cfg.h_max, cfg.max_arc - w.s + 1e-15)
    ok, xn, tn, A_n, o_n, iters = _attempt(problem, w, cfg, h)
    w.total_iters += iters
    if not ok:
        w.rejected += 1
        w.h *= 0.5
        if w.h < cfg.h_min:
            w.fail_h_min(cfg)
            return False
        return True
    assert tn is not None and A_n is not None  # both set whenever the step is accepted
    vals = {k: float(f(xn)) for k, f in monitors.items()}
    for k in monitors:
        a, b = w.mon[k][-1], vals[k]
        if np.sign(a) != np.sign(b) and a != 0:
            w.events.append(_locate(problem, w.x, w.t, h, monitors[k], k, a, b, w.s, len(w.xs) - 1, cfg.tol,
                                    cfg.event_tol))
    if cfg.detect_closure and w.s + h > 4 * cfg.h0 and len(w.xs) > 3 and _closes(problem, w, cfg, xn, tn, h):
        for k, f in monitors.items():
            w.mon[k].append(float(f(w.xs[-1])))
        return False
    w.xs.append(xn)
    w.ss.append(w.s + h)
    w.ts.append(tn)
    for k in monitors:
        w.mon[k].append(vals[k])
    w.x, w.t, w.s = xn, tn, w.s + h
    if o_n is not None:  # full row rank certified: the reference's frame is (None, None)
        w.frame, w.orient = (None, None), o_n
    else:
        w.frame = _frame(A_n, tn)
        w.orient = _orientation(A_n, tn, w.frame)
    w.steps += 1
    if cfg.progress is not None:
        cfg.progress(w.s, cfg.max_arc, "tracing")
    if iters <= 2:
        w.h *= 1.5
    elif iters >= 5:
        w.h *= 0.7
    if cfg.stop is not None and cfg.stop(w.x, w.s):
        w.status = TrackStatus.STOPPED
        return False
    return True


def track(
    problem,
    x0,
    *,
    direction: np.ndarray | None = None,
    h0: float = 0.02,
    h_min: float = 1e-7,
    h_max: float = 0.2,
    max_arc: float = 50.0,
    max_steps: int = 20000,
    tol: float = 1e-11,
    max_turn_deg: float = 15.0,
    monitors: dict[str, Callable] | None = None,
    vector_monitor: tuple[list[str], Callable] | None = None,
    event_tol: float = 1e-10,
    detect_closure: bool = True,
    stop: Callable | None = None,
    progress: Progress | None = None,
) -> TrackResult:
    """Follow the solution curve of ``problem`` from ``x0`` (which must lie on it).

    ``direction``: local-coordinate vector giving the sense of travel (the tangent is oriented
    to have a positive component on it).  Without it, or when the tangent's component on it is
    negligible (below ``SENSE_TOL`` of ``|direction|``), the sense follows the documented
    convention (:func:`conventional_sense` over the problem's ``sense_order``, times its
    ``sense``; docs/conventions.md), never the sign an SVD happens to return.
    ``monitors``: name -> function(x) whose sign changes are located as :class:`Event` s;
    ``vector_monitor = (names, f)`` evaluates several at once (``f(x)`` returns one value per
    name).  ``stop(x, s)``: return True to stop after a point.
    ``progress(s, max_arc, "tracing")`` is called after every accepted step.
    Arc length is measured in the problem's (nondimensional) local coordinates.

    A mechanism's motion (:class:`MotionProblem`) with its drivers' DJ as the vector monitor
    (:class:`DriverMonitor`) runs the compiled loop (:mod:`.compiled.kernels_trace`: the same
    steps, kernels and decisions; a step it cannot certify is made here), unless
    :func:`python_loop` or the Python reference (:func:`.backend.python_reference`) is in force.
    """
    monitors = _monitor_functions(monitors, vector_monitor)
    t = problem.tangent(x0)
    t = t / np.linalg.norm(t)
    along = float(t @ direction) if direction is not None else 0.0
    if direction is not None and abs(along) > SENSE_TOL * float(np.linalg.norm(direction)):
        t = t if along > 0 else -t
    else:  # the documented convention: the sense depends on the model and the point only
        t = t * (float(getattr(problem, "sense", 1.0)) * conventional_sense(t, getattr(problem, "sense_order", ())))
    cfg = _Settings(x0, t.copy(), h0, h_min, h_max, max_arc, max_steps, tol, float(np.cos(np.radians(max_turn_deg))),
                    event_tol, detect_closure, stop, progress)
    A_x = problem.jacobian(x0)
    frame = _frame(A_x, t)
    w = _Walk(x0, t, 0.0, h0, frame, _orientation(A_x, t, frame), [x0], [0.0], [t],
              {k: [float(f(x0))] for k, f in monitors.items()})
    loop = compiled_loop(problem, vector_monitor, len(monitors), cfg)
    while w.going(cfg):
        if loop is not None and w.frame[0] is None:
            if run_compiled(loop, w, cfg, vector_monitor[0] if vector_monitor else [], Event):
                break
            if not w.going(cfg):
                break
        if not _python_step(problem, w, cfg, monitors):
            break
    mons = {k: np.array(v) for k, v in w.mon.items()}
    floor = np.array([w.floors.get(i, 0.0) for i in range(len(w.xs))]) if w.floors else None
    return TrackResult(w.xs, np.array(w.ss), w.ts, mons, w.events, w.closed, w.status, w.rejected, w.total_iters,
                       {k: float(np.min(np.abs(v))) for k, v in mons.items()}, w.reason, sigma_floor=floor)


def _monitor_functions(monitors, vector_monitor) -> dict[str, Callable]:
    """``monitors`` and the components of ``vector_monitor`` as one dict of scalar functions
    (the vector evaluated once per point)."""
    monitors = dict(monitors or {})
    if vector_monitor is not None:
        vnames, vfun = vector_monitor
        cache: dict[int, tuple[object, np.ndarray]] = {}

        def _vec(x, _f=vfun):
            key = id(x)
            if key not in cache:
                cache.clear()
                cache[key] = (x, np.asarray(_f(x), dtype=float))
            return cache[key][1]

        for j, nm in enumerate(vnames):
            monitors[nm] = (lambda x, _k=j: float(_vec(x)[_k]))
    return monitors


def _locate(problem, x, t, h, f, name, fa, fb, s, step, tol, event_tol):
    """Zero of monitor ``f`` on the step of length ``h`` from ``x`` along ``t``: Illinois
    (modified regula falsi) on the step length, each trial point corrected onto the curve."""
    lo, hi, flo, fhi = 0.0, h, fa, fb
    true_lo, true_hi = fa, fb  # actual values (Illinois scales flo/fhi)
    best = None
    side = 0
    for _ in range(60):
        if flo != fhi:
            mid = hi - fhi * (hi - lo) / (fhi - flo)
            if not (lo < mid < hi):
                mid = 0.5 * (lo + hi)
        else:
            mid = 0.5 * (lo + hi)
        xm, ok, _, _ = predict_correct(problem, x, mid * t, t, tol, 20)
        fm = float(f(xm))
        best = (mid, xm)
        if not ok or fm == 0.0:
            break
        if np.sign(fm) == np.sign(flo):
            lo, flo, true_lo = mid, fm, fm
            if side == -1:
                fhi *= 0.5
            side = -1
        else:
            hi, fhi, true_hi = mid, fm, fm
            if side == 1:
                flo *= 0.5
            side = 1
        if hi - lo < event_tol:
            break
    assert best is not None  # the loop runs at least once
    mid, xm = best
    return Event(name, s + mid, xm, step, fa, fb, float(f(xm)), (float(true_lo), float(true_hi)))


# --------------------------------------------------------------------------- mechanisms
class _MechanismBase:
    #: The tracker's compiled loop (:func:`.tracking_loop.compiled_loop`) may run this motion.
    compiled_loop: bool = False
    #: The tangent is the null vector of the Jacobian wherever it has full row rank (the
    #: compiled step test of :func:`_step_tangent` applies).
    null_tangent: bool = True
    #: ``+1``: the traced motion starts in the conventional sense (:func:`conventional_sense`
    #: over ``sense_order``); ``-1``: the opposite one.
    sense: float = 1.0

    def __init__(self, mech: Mechanism, active: np.ndarray):
        self.mech = mech
        self.active = active
        #: the local coordinates that decide the sense of travel (:func:`sense_order`)
        self.sense_order: list[int] = sense_order(mech, active)
        self.row, self.col = closure_scales(mech, active)
        self.na = int(active.sum())
        self.nh = 6 * hub_count(mech)  # twists of the output link and the internal bodies
        self.L = mech.characteristic_length
        refs = mech.freedom_refs
        self.kinds = np.array([r.freedom.kind for r in refs])[active]

    def _closure(self, config):
        # the corrector asks for the residual and then the Jacobian at the same configuration:
        # remember the last one (configurations are never changed in place)
        last = getattr(self, "_last_closure", None)
        if last is not None and last[0] is config:
            return last[1]
        A, r = closure_jacobian(self.mech, config, active=self.active)
        out = (self.row[:, None] * A * self.col[None, :], self.row * r)
        self._last_closure = (config, out)
        return out

    def _config_step(self, config, dx):
        return retract(self.mech, config, self.active, self.col * dx)

    def _config_diff(self, a: Configuration, b: Configuration) -> np.ndarray:
        if (fast := backend.engine()) is not None:
            return fast.config_difference(self.mech, a, b, self.active, self.kinds != "P", self.col)
        dq_all = b.q - a.q
        for i, A in ball_groups(self.mech):  # relative rotation of each S joint
            sl = slice(i, i + 3)
            rel = rotation_class().from_rotvec(A @ b.q[sl]) * rotation_class().from_rotvec(A @ a.q[sl]).inv()
            dq_all[sl] = A.T @ rel.as_rotvec()
        dq = dq_all[self.active]
        rot = self.kinds != "P"
        dq = np.where(rot, (dq + np.pi) % (2 * np.pi) - np.pi, dq)
        V = [log_transform(b.D @ inverse_transform(a.D))]
        V += [log_transform(Bb @ inverse_transform(Ba)) for Ba, Bb in zip(a.B, b.B, strict=True)]
        return np.concatenate([dq, *V]) / self.col


class MotionProblem(_MechanismBase):
    """The motion of a mechanism with one platform degree of freedom (actuators free), as a
    curve in (joint variables, platform twist) local coordinates.  Passive freedoms (e.g. the
    spin of an SPS leg) are removed from the tangent, so the curve is one-dimensional.

    Sense of travel (when :func:`track` gets no ``direction``): ``first`` (a freedom name), else
    the first actuator, ... increasing; ``sense=-1``: decreasing (:func:`sense_order`)."""

    compiled_loop = True

    def __init__(self, mech: Mechanism, *, first: str | None = None, sense: int = 1):
        super().__init__(mech, active_mask(mech))
        if first is not None:
            self.sense_order = sense_order(mech, self.active, first)
        self.sense = 1.0 if sense >= 0 else -1.0

    def residual(self, x):
        return self._closure(x)[1]

    def jacobian(self, x):
        return self._closure(x)[0]

    def retract(self, x, dx):
        return self._config_step(x, dx)

    def difference(self, x, y):
        return self._config_diff(x, y)

    def compiled_correct(self, xp, t, tol, max_iter, contraction, predictor=None):
        """:func:`correct_on_hyperplane` with the whole Newton loop compiled (same steps); with
        ``predictor``, from ``retract(xp, predictor)`` (:func:`predict_correct`)."""
        fast = backend.engine()
        assert fast is not None, "compiled_correct runs only when the compiled engine is in use"
        return fast.correct_on_hyperplane(self.mech, xp, self.active, self.row, self.col, t, tol, max_iter, contraction,
                                          predictor)

    def differences(self, xs, y, stacked: tuple | None = None) -> np.ndarray:
        """:meth:`difference` of ``y`` relative to each of ``xs`` (rows), compiled in one loop
        (``stacked``: the points' ``q, D, B`` already stacked, :meth:`TrackResult.stacked`)."""
        if (fast := backend.engine()) is not None and len(xs):
            return fast.config_differences(self.mech, xs, y, self.active, self.kinds != "P", self.col, stacked)
        return np.array([self._config_diff(x, y) for x in xs])

    def step_arrays(self, fast) -> tuple:
        """The compiled kernels' arrays of this motion (:func:`.compiled.trace.motion_arrays`;
        remembered)."""
        G = getattr(self, "_arrays", None)
        if G is None:
            G = self._arrays = fast.motion_arrays(self.mech, self.active, self.row, self.col, self.kinds != "P")
        return G

    def tangent(self, x):
        return _observable_tangent(self.jacobian(x), self.nh)


class ActuatorPathProblem(_MechanismBase):
    """Forward position along a path of actuator values ``a(lam)``, ``lam`` in [0, 1]: the curve
    of configurations in (free joint variables, platform twist, lam).  Turning points in ``lam``
    are singular (direct-kinematics) configurations; the tracker passes them and reports them."""

    def __init__(
        self,
        mech: Mechanism,
        path: Callable[[float], np.ndarray],
        path_derivative: Callable[[float], np.ndarray] | None = None,
    ):
        mask = active_mask(mech)
        self.act_idx = [mech.freedom_refs.index(mech.freedom(a)) for a in mech.actuators]
        self.offsets = np.array([mech.freedom_refs[i].freedom.offset for i in self.act_idx])
        for i in self.act_idx:
            mask[i] = False
        super().__init__(mech, mask)
        self.sense_order = [self.na + self.nh]  # the path parameter lam increasing
        self.path = path
        self.dpath = path_derivative

    def _q_with(self, x):
        config, lam = x
        q = config.q.copy()
        q[self.act_idx] = np.asarray(self.path(lam), dtype=float) - self.offsets
        return config.with_q(q)

    def residual(self, x):
        return self._closure(self._q_with(x))[1]

    def jacobian(self, x):
        _config, lam = x
        c = self._q_with(x)
        A, _ = self._closure(c)
        # derivative with respect to lam through the actuated joint twists
        full, _ = closure_jacobian(self.mech, c, active=np.ones(len(c.q), bool))
        if self.dpath is not None:
            da = np.asarray(self.dpath(lam), dtype=float)
        else:
            e = 1e-7
            da = (np.asarray(self.path(lam + e)) - np.asarray(self.path(lam - e))) / (2 * e)
        col = full[:, self.act_idx] @ da
        return np.c_[A, self.row * col]

    def retract(self, x, dx):
        config, lam = x
        return (self._config_step(config, dx[:-1]), lam + float(dx[-1]))

    def difference(self, x, y):
        return np.r_[self._config_diff(x[0], y[0]), y[1] - x[1]]

    def tangent(self, x):
        return _observable_tangent(self.jacobian(x), self.nh + 1)


def trace_motion(
    mech: Mechanism,
    start: Configuration,
    *,
    increasing: str | None = None,
    sense: int = 1,
    monitors: dict[str, Callable[[Configuration], float]] | None = None,
    **kw,
) -> TrackResult:
    """Follow the one-degree-of-freedom motion of ``mech`` from ``start`` until it closes.

    Sense of travel (docs/conventions.md): the variable of ``increasing`` (a freedom name) grows
    at the start; without it, or where its rate is negligible, the first actuator's, then the
    next actuator's, then the first freedom's (in the model's order) with a non-negligible rate
    (:data:`SENSE_TOL` of the unit tangent).  ``sense=-1`` reverses it.  The same on the
    compiled and Python paths and on every BLAS kernel.  Extra keyword arguments go to
    :func:`track`.
    """
    prob = MotionProblem(mech, first=increasing, sense=sense)
    A = prob.jacobian(start)
    sv = np.linalg.svd(A, compute_uv=False)
    r = int(np.sum(sv > current_tolerances().rank * max(1.0, sv[0])))
    N = np.linalg.svd(A, full_matrices=True)[2][r:]
    if N.shape[0] > 1:  # more than one direction moves the platform: not a 1-DOF motion
        _u, s2, _ = np.linalg.svd(N[:, prob.na : prob.na + 6])
        dof = int(np.sum(s2 > 1e-7))
        if dof > 1:
            raise InputError(f"mechanism: trace_motion follows one-degree-of-freedom motions; {mech.name} has {dof} "
                             "here (lock or drive the others: an ActuatorPathProblem follows a path of actuator values)")
    return track(prob, start, monitors=monitors, **kw)
