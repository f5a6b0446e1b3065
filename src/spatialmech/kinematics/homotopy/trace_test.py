"""The trace test: a proof (with probability one) that a set of solutions of a generic member of
a parameter family of square systems ``F(x; P) = 0`` is the whole set of its isolated solutions.

Method (Leykin, Rodriguez and Sottile, "Trace test", 2018; the augmented system of del Campo and
Rodriguez, 2017, also used by HomotopyContinuation.jl's ``verify_solution_completeness``):

* the parameters move along a line ``P(lam) = P0 + lam V`` through a second generic member
  ``P0 + V``, where one solution ``x1`` is known; in the variables ``y = (x, lam)`` the solutions
  form a curve ``C``;
* the *witness points* ``W``: the points of ``C`` on the hyperplane ``a . x = 1`` (``a`` random
  complex, scaled so that ``x1`` is on it), found by monodromy over the hyperplane (loops
  ``a -> a1 -> a2 -> a`` through random hyperplanes): the monodromy of a curve's hyperplane
  sections acts transitively when the curve is irreducible, which a generic line of an
  irreducible family gives;
* the function ``f = (a . x - 1) lam`` on ``C`` vanishes exactly on the known solutions
  ``(x_i, 0)`` and on ``W``; it is proper on ``C`` (it grows at every point at infinity of ``C``
  when ``P0`` is generic), so its fibres ``f = -t`` all have the same number of points, and the
  sum of the points of a fibre (the *trace*) is a polynomial in ``t`` of degree at most one.
  For a proper subset of a fibre it is not;
* the test: track ``Z = {(x_i, 0)} + W`` to ``t = t1`` and ``t = t2`` (random complex, ``|t| =``
  :data:`TRACE_STEP`); the traces at ``0, t1, t2`` lie on one complex line, parametrised by
  ``t``, to :data:`TRACE_TOL` (relative to the sum of the points' sizes) iff nothing is missing:
  neither a solution of ``F(x; P0) = 0`` nor a witness point.

A deviation of order one that persists once the witness points stop growing means that the known
solutions are *not* complete; a path that fails in the trace homotopies leaves the test
inconclusive.  The caller supplies the family through one function (``curve``), so the same test
serves any formulation.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ...geometry.tolerances import MONODROMY_PARALLEL, TRACE_MAX_LOOPS, TRACE_STALE_LOOPS, TRACE_STEP, TRACE_TOL
from ...results import TraceVerdict
from .study import track

__all__ = ["TraceResult", "add_new_points", "around_triangle", "new_points", "trace_test"]

Curve = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class TraceResult:
    """``verdict``: "passed" (the known solutions are complete), "failed" (some are missing: the
    deviation stayed of order one while the witness points stopped growing), "inconclusive" (a
    trace path failed) or "capped" (the work cap ran out first).  ``deviation``: the last
    relative deviation of the traces from a line (infinity before any test)."""

    verdict: TraceVerdict
    deviation: float
    n_witness: int
    loops: int
    work: int
    seconds: float

    @property
    def passed(self) -> bool:
        return self.verdict == TraceVerdict.PASSED  # a plain "passed" too


def _crand(rng: np.random.Generator, *shape: int) -> np.ndarray:
    return rng.normal(size=shape) + 1j * rng.normal(size=shape)


def new_points(known: np.ndarray, cand: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """The rows of ``cand`` farther than ``tol`` (relative) from every row of ``known`` and from
    each other (the first of a cluster kept)."""
    out: list[np.ndarray] = []
    for y in cand:
        ref = np.vstack([known, *[o[None] for o in out]])
        if np.all(np.linalg.norm(ref - y, axis=1) / (1 + np.linalg.norm(y)) > tol):
            out.append(y)
    return np.array(out, dtype=complex).reshape(-1, known.shape[1])


def add_new_points(known: np.ndarray, cand: np.ndarray, stale: int, k: int) -> tuple[np.ndarray, int]:
    """A monodromy round's bookkeeping: ``known`` with the :func:`new_points` of ``cand`` appended,
    and the count of loops without a new point, ``stale``: back to 0 when there were some, else
    grown by the round's ``k`` loops."""
    new = new_points(known, cand)
    if len(new):
        return np.vstack([known, new]), 0
    return known, stale + k


def around_triangle(segment: Callable, X: np.ndarray, P0: np.ndarray, B1: np.ndarray, B2: np.ndarray) -> np.ndarray:
    """A monodromy loop: the points ``X`` carried from the parameters ``P0`` through ``B1`` and
    ``B2`` (one row per point) back to ``P0`` by ``segment(X, a, b) -> (X, t, done)``; a path that
    fails is dropped (with its waypoints).  Returns the points back at ``P0``."""
    for leg in range(3):
        a, b = ((P0, B1), (B1, B2), (B2, P0))[leg]
        X, _, done = segment(X, a, b)
        X, B1, B2 = X[done], B1[done], B2[done]
    return X


def _move_slices(curve: Curve, Y: np.ndarray, A0: np.ndarray, A1: np.ndarray):
    """Track the points ``Y`` (n, m + 1) of the curve from the hyperplanes ``A0 . x = 1`` to
    ``A1 . x = 1`` (one per point, (n, m))."""
    m = Y.shape[1] - 1

    def fun(Yc, t, idx):
        F, Fx, Fl = curve(Yc)
        a = A0[idx] + t[:, None] * (A1[idx] - A0[idx])
        n = len(Yc)
        H = np.concatenate([F, (np.einsum("ni,ni->n", a, Yc[:, :m]) - 1)[:, None]], axis=1)
        Hy = np.zeros((n, m + 1, m + 1), complex)
        Hy[:, :m, :m], Hy[:, :m, m], Hy[:, m, :m] = Fx, Fl, a
        Ht = np.zeros((n, m + 1), complex)
        Ht[:, m] = np.einsum("ni,ni->n", A1[idx] - A0[idx], Yc[:, :m])
        return H, Hy, Ht

    Ye, _, ok, _ = track(fun, Y, max_steps=2000, indexed=True)
    return Ye, ok


def _move_fibre(curve: Curve, Z: np.ndarray, a: np.ndarray, t1: complex):
    """Track the fibre ``(a . x - 1) lam = 0`` of the curve (points ``Z``) to ``= -t1``."""
    m = Z.shape[1] - 1

    def fun(Yc, t):
        F, Fx, Fl = curve(Yc)
        lam, g = Yc[:, m], Yc[:, :m] @ a - 1
        n = len(Yc)
        H = np.concatenate([F, (g * lam + t * t1)[:, None]], axis=1)
        Hy = np.zeros((n, m + 1, m + 1), complex)
        Hy[:, :m, :m], Hy[:, :m, m] = Fx, Fl
        Hy[:, m, :m], Hy[:, m, m] = lam[:, None] * a[None], g
        Ht = np.zeros((n, m + 1), complex)
        Ht[:, m] = t1
        return H, Hy, Ht

    Ze, _, ok, _ = track(fun, Z, max_steps=2000)
    return Ze, ok


def _deviation(curve: Curve, Z: np.ndarray, a: np.ndarray, rng: np.random.Generator) -> tuple[float, bool, int]:
    """The traces' relative deviation from a line in ``t``, whether every path was tracked, and
    the paths tracked."""
    th = rng.uniform(0.0, 2.0 * np.pi)
    ts = (TRACE_STEP * np.exp(1j * th), TRACE_STEP * np.exp(1j * (th + 2.0 * np.pi / 3.0)))
    T0 = Z.sum(axis=0)
    slopes, ok_all = [], True
    for t1 in ts:
        Ze, ok = _move_fibre(curve, Z, a, t1)
        ok_all &= bool(ok.all())
        slopes.append((Ze.sum(axis=0) - T0) / t1)
    dev = float(np.linalg.norm(slopes[0] - slopes[1]) * TRACE_STEP / max(np.abs(Z).sum(), 1e-300))
    return dev, ok_all, 2 * len(Z)


def trace_test(curve: Curve, X: np.ndarray, y1: np.ndarray, rng: np.random.Generator, *,
               max_work: int | None = None) -> TraceResult:
    """Whether ``X`` (k, m), solutions of ``F(x; P0) = 0``, are all of its isolated solutions.

    ``curve(Y)`` for points ``Y = (x, lam)`` (n, m + 1) returns ``F(x; P0 + lam V)`` (n, m), its
    Jacobian in ``x`` (n, m, m) and its derivative in ``lam`` (n, m); ``y1 = (x1, 1)`` is a point
    of the curve off the fibre ``lam = 0``.  ``max_work`` caps the paths tracked times ``m + 1``
    (verdict "capped")."""
    t0 = time.perf_counter()
    m = X.shape[1]
    a = _crand(rng, m)
    a = a / (a @ y1[:m])
    base = np.linalg.norm(a) / np.sqrt(m)  # a typical entry of a
    W = np.asarray(y1, dtype=complex)[None]
    fibre = np.concatenate([X, np.zeros((len(X), 1))], axis=1)
    loops = stale = work = 0
    dev, tested_at = np.inf, -1
    k = MONODROMY_PARALLEL

    def hyperplanes():
        """``k`` random hyperplanes at random scales (0.5 to 8 times a's entries; small ones alone
        may never wind about the tangent hyperplanes: the RSSR's circle, no swap in 20 loops),
        each repeated for every witness point."""
        B = base * np.exp(rng.uniform(np.log(0.5), np.log(8.0), (k, 1))) * _crand(rng, k, m)
        return np.repeat(B, len(W), axis=0)

    while loops < TRACE_MAX_LOOPS:
        if max_work is not None and work + (3 * k + 2) * len(W) * (m + 1) > max_work:  # the next round's
            return TraceResult(TraceVerdict.CAPPED, dev, len(W), loops, work, time.perf_counter() - t0)
        loops += k  # k loops at once, each through its own two random hyperplanes
        B1, B2 = hyperplanes(), hyperplanes()
        A = np.broadcast_to(a, B1.shape)
        Y = np.tile(W, (k, 1))
        work += 3 * len(Y) * (m + 1)
        for A0, A1 in ((A, B1), (B1, B2), (B2, A)):
            Y, ok = _move_slices(curve, Y, A0, A1)
            Y, A, B1, B2 = Y[ok], A[ok], B1[ok], B2[ok]
        new = new_points(W, Y)
        if len(new):
            W = np.vstack([W, new])
            stale = 0
            continue
        stale += k
        if tested_at != len(W):  # a round without a new point: test (cheaper than a round)
            dev, ok_all, w = _deviation(curve, np.vstack([fibre, W]), a, rng)
            work += w * (m + 1)
            if not ok_all:
                dev, ok_all, w = _deviation(curve, np.vstack([fibre, W]), a, rng)  # one more direction
                work += w * (m + 1)
                if not ok_all:
                    return TraceResult(TraceVerdict.INCONCLUSIVE, dev, len(W), loops, work, time.perf_counter() - t0)
            if dev < TRACE_TOL:
                return TraceResult(TraceVerdict.PASSED, dev, len(W), loops, work, time.perf_counter() - t0)
            tested_at = len(W)
        elif stale >= TRACE_STALE_LOOPS:  # failed, and nothing new since: solutions are missing
            return TraceResult(TraceVerdict.FAILED, dev, len(W), loops, work, time.perf_counter() - t0)
    return TraceResult(TraceVerdict.CAPPED, dev, len(W), loops, work, time.perf_counter() - t0)
