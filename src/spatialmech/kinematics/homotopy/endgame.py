"""Cauchy end game of a parameter homotopy, and a local dimension test at its end points.

A path of the parameter homotopy ``H(x, t) = F(x; Q0 + t (Q1 - Q0))`` that ends at a singular
solution of the target (``t = 1``) cannot be finished by Newton: the Jacobian degenerates, and
the last tracked points locate the end to a few digits only.  Near ``t = 1`` such a path is a
convergent Puiseux series: with ``t = 1 - s^w`` (``w`` its winding number) ``x`` is analytic in
``s``.  The Cauchy end game (Morgan, Sommese and Wampler 1992) therefore tracks the path around
circles ``t = 1 - r e^{i theta}`` in the complex plane of the homotopy parameter (straight chords
of the coefficient path between ``points`` samples of each loop) until it returns to where it
started, which takes ``w`` loops, and takes the mean of the samples: by Cauchy's integral formula
the mean of an analytic function over a circle is its value at the centre, here ``x(s = 0)``.
The estimates at two radii (``r`` and ``r / 4``) must agree before the end point is accepted.

Several paths ending at one point make it a multiple root (multiplicity = the number of paths),
or the point lies on a positive-dimensional solution set (a self-motion of the mechanism).
:func:`local_dimension` tells the two apart: Gauss-Newton projections of small random
perturbations of the point return to it when it is isolated (linear convergence at a multiple
root), and stop on other solutions, as far away as the perturbation, when the point lies on a
continuum.

Both functions take the tracker and the system as functions (``track(QA, QB, c, X)`` as
:func:`.study.track_parameter`, ``evaluate(X) -> (F, J)``), so that they serve any square
polynomial system on an affine patch.
"""

from __future__ import annotations

from dataclasses import dataclass
from collections.abc import Callable

import numpy as np

from ...geometry.tolerances import (
    HOMOTOPY_ILL,
    HOMOTOPY_NEAR_REAL,
    HOMOTOPY_REAL,
    ENDGAME_AGREE,
    ENDGAME_CLOSED,
    ENDGAME_LOOPS,
    ENDGAME_POINTS,
    ENDGAME_RADIUS,
    LOCAL_DIMENSION_STEP,
)

__all__ = ["EndgameResult", "cauchy_endgame", "local_dimension", "multiple_root_end"]


@dataclass(frozen=True, eq=False)
class EndgameResult:
    """Per path: the end point estimate ``X`` (n, m), the winding number (0 when the loops did
    not close), the relative change of the estimate between the last two radii, and whether the
    end point was accepted (closed loops at every radius and agreeing estimates)."""

    X: np.ndarray
    winding: np.ndarray
    change: np.ndarray
    converged: np.ndarray


def _loops(track, Q0, dQ, c, X, r: float, points: int, max_loops: int):
    """Loops of radius ``r`` about ``t = 1`` from the points ``X`` at ``t = 1 - r``: (mean of the
    samples over the closing loops, winding numbers (0: did not close or a chord failed))."""
    n = len(X)
    theta = 2 * np.pi * np.arange(points + 1) / points
    ts = 1 - r * np.exp(1j * theta)
    start = X.copy()
    cur = X.copy()
    total = np.zeros_like(X)
    count = 0
    wind = np.zeros(n, dtype=np.int64)
    alive = np.ones(n, dtype=bool)
    mean = np.full_like(X, np.nan)
    for loop in range(1, max_loops + 1):
        for k in range(points):
            idx = np.flatnonzero(alive)
            if not len(idx):
                break
            total[idx] += cur[idx]
            Y, _, done = track(Q0 + ts[k] * dQ, Q0 + ts[k + 1] * dQ, c, cur[idx])
            cur[idx] = Y
            alive[idx[~done]] = False
        count += points
        idx = np.flatnonzero(alive)
        scale = np.maximum(np.linalg.norm(start[idx], axis=1), 1e-300)
        closed = np.linalg.norm(cur[idx] - start[idx], axis=1) / scale < ENDGAME_CLOSED
        for i in idx[closed]:
            wind[i] = loop
            mean[i] = total[i] / count
            alive[i] = False
        if not alive.any():
            break
    return mean, wind


def multiple_root_end(imag, rcond):
    """Whether an end point is a multiple root's (a real solution at a singular configuration):
    near real (``imag`` below :data:`HOMOTOPY_NEAR_REAL`) but not real to :data:`HOMOTOPY_REAL`,
    and ill-conditioned (``rcond``, sigma_min / sigma_max of its system, below
    :data:`HOMOTOPY_ILL`).  Such end points keep about the square root of the rounding in their
    imaginary parts; they are singular end points, never complex solutions.  Works on scalars
    and on arrays (elementwise)."""
    return (imag >= HOMOTOPY_REAL) & (imag < HOMOTOPY_NEAR_REAL) & (rcond < HOMOTOPY_ILL)


def cauchy_endgame(track: Callable, Q0: np.ndarray, Q1: np.ndarray, c: np.ndarray, X0: np.ndarray, *,
                   radius: float = ENDGAME_RADIUS, points: int = ENDGAME_POINTS, max_loops: int = ENDGAME_LOOPS,
                   radii: int = 3) -> EndgameResult:
    """End points of the paths that start at ``X0`` (n, m) at ``t = 0`` of the straight coefficient
    path from ``Q0`` to ``Q1``, by the Cauchy end game (module docstring): loops at the radii
    ``radius / 4^k``, ``k < radii``; the estimate of the smallest radius is returned, accepted
    when it agrees with the previous one to ``ENDGAME_AGREE`` (relative)."""
    X0 = np.ascontiguousarray(X0, dtype=complex)
    Q0 = np.asarray(Q0, dtype=complex)
    dQ = np.asarray(Q1, dtype=complex) - Q0
    n = len(X0)
    est = np.full_like(X0, np.nan)
    prev = np.full_like(X0, np.nan)
    wind = np.zeros(n, dtype=np.int64)
    ok = np.ones(n, dtype=bool)
    t_now = 0.0
    X = X0.copy()
    for k in range(radii):
        r = radius / 4.0**k
        idx = np.flatnonzero(ok)
        if not len(idx):
            break
        Y, _, done = track(Q0 + t_now * dQ, Q0 + (1 - r) * dQ, c, X[idx])  # along the real segment
        X[idx] = Y
        ok[idx[~done]] = False
        idx = np.flatnonzero(ok)
        mean, w = _loops(track, Q0, dQ, c, X[idx], r, points, max_loops)
        t_now = 1 - r
        bad = (w == 0) | ((k > 0) & (w != wind[idx]))
        ok[idx[bad]] = False
        prev[idx] = est[idx]
        est[idx] = mean
        wind[idx] = w
    scale = np.maximum(np.linalg.norm(est, axis=1), 1e-300)
    with np.errstate(invalid="ignore"):
        change = np.linalg.norm(est - prev, axis=1) / scale
    change = np.where(np.isfinite(change), change, np.inf)
    converged = ok & (change < ENDGAME_AGREE) if radii > 1 else ok
    return EndgameResult(est, np.where(ok, wind, 0), change, converged)


def local_dimension(evaluate: Callable, x: np.ndarray, *, trials: int = 3, iterations: int = 40,
                    seed: int = 0) -> int:
    """0 when the solution ``x`` of ``F = 0`` is isolated, 1 when it lies on a positive-dimensional
    solution set (module docstring).  ``evaluate(X)`` returns ``F`` (n, m) and ``J`` (n, m, m) of
    the square system at the points ``X`` (n, m)."""
    rng = np.random.default_rng(seed)
    x = np.asarray(x, dtype=complex)
    size = LOCAL_DIMENSION_STEP * max(float(np.linalg.norm(x)), 1.0)
    for _ in range(trials):
        d = rng.normal(size=x.shape) + 1j * rng.normal(size=x.shape)
        y = x + size * d / np.linalg.norm(d)
        for _ in range(iterations):
            F, J = evaluate(y[None])
            step = np.linalg.lstsq(J[0], F[0], rcond=1e-10)[0]
            y = y - step
            if np.linalg.norm(step) < 1e-15 * max(float(np.linalg.norm(y)), 1.0):
                break
        F, _ = evaluate(y[None])
        on = np.linalg.norm(F[0]) < 1e-10 * max(float(np.linalg.norm(y)), 1.0) ** 2
        if on and np.linalg.norm(y - x) > 0.1 * size:
            return 1
    return 0
