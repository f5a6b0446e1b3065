"""The parameter homotopy of the Study formulation, compiled (numba): the same RK4 predictor,
Newton corrector and step control as the batched NumPy ``track`` of
:mod:`spatialmech.kinematics.homotopy.study` (the reference), path by path."""

from __future__ import annotations

import numpy as np

from ...geometry.tolerances import HOMOTOPY_JUMP, HOMOTOPY_NEWTON
from .jit import njit

__all__ = ["nb_lu_solve", "nb_lu_solve_inplace", "nb_param_system", "nb_param_vel", "nb_step_control",
           "nb_track_param", "track_parameter"]


@njit(cache=True)
def nb_lu_solve_inplace(M, y):
    """``M x = y`` (complex, small) by LU with partial pivoting, in place: ``M`` is destroyed and
    ``y`` becomes ``x``; False when a pivot is zero or not finite."""
    n = M.shape[0]
    for k in range(n):
        p = k
        big = abs(M[k, k])
        for i in range(k + 1, n):
            if abs(M[i, k]) > big:
                big = abs(M[i, k])
                p = i
        if not big > 0.0 or not np.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                M[k, j], M[p, j] = M[p, j], M[k, j]
            y[k], y[p] = y[p], y[k]
        for i in range(k + 1, n):
            f = M[i, k] / M[k, k]
            for j in range(k, n):
                M[i, j] -= f * M[k, j]
            y[i] -= f * y[k]
    for i in range(n - 1, -1, -1):
        acc = y[i]
        for j in range(i + 1, n):
            acc -= M[i, j] * y[j]
        y[i] = acc / M[i, i]
    return True


@njit(cache=True)
def nb_lu_solve(A, b, out):
    """``A x = b`` (complex, small) by LU with partial pivoting into ``out`` (``A`` and ``b`` are
    kept); False when a pivot is zero or not finite (the batched NumPy tracker's LinAlgError)."""
    y = b.copy()
    if not nb_lu_solve_inplace(A.copy(), y):
        return False
    out[:] = y
    return True


@njit(cache=True)
def nb_param_system(Q0, dQ, c, x, t, F, J, Ht):
    """``study._eval_quad`` of one point on the straight coefficient path ``Q0 + t dQ`` and ``H_t``."""
    n = x.shape[0]
    for k in range(7):
        acc = 0.0j
        acct = 0.0j
        for i in range(n):
            qx = 0.0j
            dx = 0.0j
            for j in range(n):
                qx += (Q0[k, i, j] + t * dQ[k, i, j]) * x[j]
                dx += dQ[k, i, j] * x[j]
            J[k, i] = 2.0 * qx
            acc += qx * x[i]
            acct += dx * x[i]
        F[k] = acc
        Ht[k] = acct
    acc = -1.0 + 0.0j
    for i in range(n):
        acc += x[i] * c[i]
        J[7, i] = c[i]
    F[7] = acc
    Ht[7] = 0.0


@njit(cache=True)
def nb_param_vel(Q0, dQ, c, x, t, F, J, Ht, out):
    ok = True
    nb_param_system(Q0, dQ, c, x, t, F, J, Ht)
    for i in range(Ht.shape[0]):
        Ht[i] = -Ht[i]
    ok = nb_lu_solve(J, Ht, out)
    return ok


@njit(cache=True)
def nb_step_control(ok, d0, d1, jump, newton, h, good):
    """The trackers' acceptance test of a step (the step ``ok``, both Newton corrections ``d0``,
    ``d1`` finite, the first below ``jump``, the second contracting or below ``newton``) and
    their step control: the step ``h`` doubles after two accepted steps in a row (``good`` counts
    them) and halves on a rejected one.  Returns ``(accepted, h, good)``."""
    acc = ok and np.isfinite(d0) and np.isfinite(d1) and d0 < jump and (d1 < 0.1 * d0 or d1 < newton)
    if acc:
        good += 1
        if good >= 2:
            h *= 2.0
            good = 0
    else:
        h *= 0.5
        good = 0
    return acc, h, good


@njit(cache=True)
def nb_track_param(Q0, dQ, c, X0, h0, hmin, max_steps, jump, newton, X, T, done):
    """:func:`track` of the parameter homotopy, path by path (compiled): the same RK4 predictor,
    two Newton corrections, acceptance test and step control."""
    n = X0.shape[1]
    F = np.empty(n, dtype=np.complex128)
    J = np.empty((n, n), dtype=np.complex128)
    Ht = np.empty(n, dtype=np.complex128)
    k1 = np.empty(n, dtype=np.complex128)
    k2 = np.empty(n, dtype=np.complex128)
    k3 = np.empty(n, dtype=np.complex128)
    k4 = np.empty(n, dtype=np.complex128)
    xs = np.empty(n, dtype=np.complex128)
    xc = np.empty(n, dtype=np.complex128)
    dx = np.empty(n, dtype=np.complex128)
    for p in range(X0.shape[0]):
        x = X[p]
        for i in range(n):
            x[i] = X0[p, i]
        t = 0.0
        h = h0
        good = 0
        fin = False
        for _ in range(max_steps):
            hh = min(h, 1.0 - t)
            ok = nb_param_vel(Q0, dQ, c, x, t, F, J, Ht, k1)
            if ok:
                for i in range(n):
                    xs[i] = x[i] + 0.5 * hh * k1[i]
                ok = nb_param_vel(Q0, dQ, c, xs, t + 0.5 * hh, F, J, Ht, k2)
            if ok:
                for i in range(n):
                    xs[i] = x[i] + 0.5 * hh * k2[i]
                ok = nb_param_vel(Q0, dQ, c, xs, t + 0.5 * hh, F, J, Ht, k3)
            if ok:
                for i in range(n):
                    xs[i] = x[i] + hh * k3[i]
                ok = nb_param_vel(Q0, dQ, c, xs, t + hh, F, J, Ht, k4)
            d0 = np.inf
            d1 = np.inf
            tn = t + hh
            if ok:
                nx = 0.0
                for i in range(n):
                    xc[i] = x[i] + hh / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                    nx += abs(xc[i]) ** 2
                nx = 1.0 + np.sqrt(nx)
                nb_param_system(Q0, dQ, c, xc, tn, F, J, Ht)
                ok = nb_lu_solve(J, F, dx)
                if ok:
                    s0 = 0.0
                    for i in range(n):
                        s0 += abs(dx[i]) ** 2
                        xc[i] -= dx[i]
                    d0 = np.sqrt(s0) / nx
                    nb_param_system(Q0, dQ, c, xc, tn, F, J, Ht)
                    ok = nb_lu_solve(J, F, dx)
                if ok:
                    s1 = 0.0
                    for i in range(n):
                        s1 += abs(dx[i]) ** 2
                        xc[i] -= dx[i]
                    d1 = np.sqrt(s1) / nx
            acc, h, good = nb_step_control(ok, d0, d1, jump, newton, h, good)
            if acc:
                for i in range(n):
                    x[i] = xc[i]
                t = tn
                if t >= 1.0:
                    fin = True
                    break
            elif h < hmin:
                break
        T[p] = t
        done[p] = fin


def track_parameter(Q0: np.ndarray, dQ: np.ndarray, c: np.ndarray, X0: np.ndarray, *, h0: float = 0.02,
                    hmin: float = 1e-14, max_steps: int = 4000):
    """``study.track_parameter``, compiled: the parameter homotopy from the quadrics ``Q0``
    (complex, C-contiguous; points ``X0``) along ``Q0 + t dQ``, ``t`` from 0 to 1.  Returns
    ``(X, t, done)``."""
    X = np.empty_like(X0)
    T = np.zeros(len(X0))
    done = np.zeros(len(X0), dtype=np.bool_)
    if len(X0):
        nb_track_param(Q0, dQ, np.ascontiguousarray(c, dtype=complex), X0,
                       float(h0), float(hmin), int(max_steps), float(HOMOTOPY_JUMP), float(HOMOTOPY_NEWTON),
                       X, T, done)
    return X, T, done
