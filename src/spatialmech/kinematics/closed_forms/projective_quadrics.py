"""Every solution of ``k`` homogeneous quadrics in ``k + 1`` unknowns (points of projective
space ``P^k``), proven complete by Bezout's bound: the formulations of forward position whose
passive joints are eliminated down to such a system (:mod:`.spherical_rrr_forward`).

Method.  On a random complex affine patch ``c . x = 1`` the system is square: ``k`` quadrics and
one linear equation.  A total-degree homotopy ``H = (1 - t) gamma G + t F`` from
``G_j = x_j^2 - x_k^2`` (its ``2^k`` start points ``(+-1, ..., +-1, 1)``, scaled onto the patch;
``gamma`` a random unit complex number: the gamma trick) tracks ``2^k`` paths with
:func:`..homotopy.study.track`.  Every isolated solution of ``F`` is the end of a path.

Completeness.  By the refined Bezout theorem (Fulton, *Intersection theory*, 8.4.6) the degrees
of all the irreducible components of the intersection of ``k`` quadrics in ``P^k`` add up to at
most ``2^k``.  When the ``2^k`` paths end at ``2^k`` distinct nonsingular points, these are
``2^k`` components of degree 1: there is no other solution, neither isolated nor on a
positive-dimensional component (``complete``).  Otherwise (a singular or repeated end point, a
path that failed) the count proves nothing and the result says so.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...geometry.tolerances import HOMOTOPY_REAL, HOMOTOPY_SINGULAR
from ..homotopy.study import track

__all__ = ["QuadricSolutions", "solve_projective_quadrics"]


@dataclass(frozen=True, eq=False)
class QuadricSolutions:
    """The end points of :func:`solve_projective_quadrics`.

    ``X`` (n_paths, k + 1) the end points (complex, on the patch), ``real`` whether each is real
    up to its projective phase (``Y`` the points with the phase removed and unit norm),
    ``rcond`` the inverse condition number of each end point's row-normalised Jacobian,
    ``reached`` whether its path reached ``t = 1``; ``complete`` when Bezout's bound is attained
    by distinct nonsingular end points (module docstring); ``seconds`` the time taken."""

    X: np.ndarray
    Y: np.ndarray
    real: np.ndarray
    rcond: np.ndarray
    reached: np.ndarray
    complete: bool
    n_paths: int
    seconds: float

    @property
    def nonsingular(self) -> np.ndarray:
        return self.rcond >= HOMOTOPY_SINGULAR


def _evaluate(A: np.ndarray, c: np.ndarray, X: np.ndarray):
    """``F`` (n, k + 1): the quadrics ``x^T A_j x`` and the patch ``c . x - 1``; its Jacobian."""
    AX = np.einsum("kij,nj->nki", A, X)
    k = len(A)
    F = np.empty((len(X), k + 1), dtype=complex)
    J = np.empty((len(X), k + 1, k + 1), dtype=complex)
    F[:, :k] = np.einsum("nki,ni->nk", AX, X)
    J[:, :k] = 2 * AX
    F[:, k] = X @ c - 1
    J[:, k] = c
    return F, J


def _refine(A, c, X, iters: int = 3) -> np.ndarray:
    """Newton at ``t = 1``; a point keeps its value where a step does not lower the residual."""
    X = X.copy()
    with np.errstate(all="ignore"):
        for _ in range(iters):
            F, J = _evaluate(A, c, X)
            ok = np.all(np.isfinite(J), axis=(1, 2)) & (np.abs(np.linalg.det(J)) > 0)
            if not ok.any():
                break
            idx = np.flatnonzero(ok)
            Xn = X[idx] - np.linalg.solve(J[idx], F[idx][..., None])[..., 0]
            Fn, _ = _evaluate(A, c, Xn)
            better = np.all(np.isfinite(Xn), axis=1) & (np.linalg.norm(Fn, axis=1) <= np.linalg.norm(F[idx], axis=1))
            X[idx[better]] = Xn[better]
    return X


def _distinct(Y: np.ndarray) -> bool:
    """No two of the unit points ``Y`` are the same projective point (``|<y_i, y_j>| < 1``)."""
    if len(Y) < 2:
        return True
    G = np.abs(Y.conj() @ Y.T)
    np.fill_diagonal(G, 0)
    return bool(np.all(G < 1 - 1e-8))


def solve_projective_quadrics(A, *, seed: int = 0) -> QuadricSolutions:
    """Every solution of the ``k`` quadrics ``x^T A_j x = 0`` (``A`` (k, k + 1, k + 1), symmetric,
    real or complex) in ``P^k``, by the total-degree homotopy of the module docstring (``seed``
    draws the patch and ``gamma``; a second draw is tried when the first does not prove the count)."""
    t0 = time.perf_counter()
    A = np.asarray(A, dtype=complex)
    k = len(A)
    n = k + 1
    A = (A + np.swapaxes(A, 1, 2)) / 2
    scale = np.maximum(np.max(np.abs(A), axis=(1, 2), keepdims=True), 1e-300)
    A = A / scale
    rng = np.random.default_rng(seed)
    signs = np.array(np.meshgrid(*[[1.0, -1.0]] * k, indexing="ij")).reshape(k, -1).T
    S = np.hstack([signs, np.ones((len(signs), 1))]).astype(complex)
    best: QuadricSolutions | None = None
    for _attempt in range(2):
        c = rng.normal(size=n) + 1j * rng.normal(size=n)
        gamma = np.exp(1j * rng.uniform(0, 2 * np.pi))
        X0 = S / (S @ c)[:, None]

        def fun(X, t, c=c, gamma=gamma):
            F, J = _evaluate(A, c, X)
            G = np.zeros_like(F)
            JG = np.zeros_like(J)
            G[:, :k] = X[:, :k] ** 2 - X[:, k:] ** 2
            JG[:, np.arange(k), np.arange(k)] = 2 * X[:, :k]
            JG[:, :k, k] = -2 * X[:, k:]
            s = t[:, None]
            H = (1 - s) * gamma * G + s * F
            Hx = (1 - s[..., None]) * gamma * JG + s[..., None] * J
            Ht = F - gamma * G
            H[:, k], Hx[:, k], Ht[:, k] = F[:, k], J[:, k], 0
            return H, Hx, Ht

        X, _, reached, _ = track(fun, X0)
        X = _refine(A, c, X)
        _, J = _evaluate(A, c, X)
        with np.errstate(all="ignore"):
            rows = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
            fin = np.all(np.isfinite(rows), axis=(1, 2))
            sv = np.linalg.svd(np.where(fin[:, None, None], rows, np.eye(n)), compute_uv=False)
        rcond = np.where(fin, sv[:, -1] / sv[:, 0], 0.0)
        nrm = np.linalg.norm(X, axis=1)
        Y = X / np.where(np.isfinite(nrm) & (nrm > 0), nrm, 1.0)[:, None]
        kmax = np.argmax(np.abs(Y), axis=1)
        piv = Y[np.arange(len(Y)), kmax]
        Y = Y * np.where(piv != 0, np.abs(piv) / np.where(piv != 0, piv, 1), 1)[:, None]
        real = np.linalg.norm(Y.imag, axis=1) < HOMOTOPY_REAL
        ok = bool(np.all(reached) and np.all(np.isfinite(nrm)) and np.all(rcond >= HOMOTOPY_SINGULAR) and _distinct(Y))
        res = QuadricSolutions(X, Y, real, rcond, reached, ok, len(X0), time.perf_counter() - t0)
        if ok:
            return res
        best = best or res
    assert best is not None
    return best
