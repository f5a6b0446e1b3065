"""The continuation tracker's loop compiled (:func:`spatialmech.kinematics.tracking.track`) for
a mechanism's motion (``tracking.MotionProblem``) with the DJ of its drivers as the vector
monitor (``tracking.DriverMonitor``, what the defect analysis traces).

:func:`nb_trace` makes the reference loop's steps -- the predictor and corrector
(:func:`.kernels_closure.nb_correct_hyperplane`), the step test (:func:`.kernels_tracking.nb_bordered_tangent`:
the tangent, its turn, Keller's orientation), the step control, the DJ of every driver at each
accepted point (:func:`.kernels_drivers.nb_driver_dets`), the location of their sign changes by
Illinois on the step length, and the loop closure -- with the same kernels, in the same order,
as many as it can in one call.  It hands a step back to the Python loop, *before* changing
anything for it, where the reference would leave the compiled kernels: a step test that the
bordered LU does not certify (the reference then takes an SVD), a driver determinant the kernel
declines or that is not finite.  The Python loop makes that one step and calls again.

Arrays (``G``, a tuple): ``S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends,
linear, active, drivers, cols, row, col, wrap`` (the compiled model, the drivers' joint indices
and their active columns, the problem's row and column scales, the wrapped local coordinates).
``par``: ``L, rank tolerance, h0, h_min, h_max, max_arc, tol, cos(max turn), event_tol,
detect_closure, max_steps, bodies`` (see :data:`PAR`).  State (in and out): ``fs`` = (arc length,
step length, orientation, arc of the closing point); ``ist`` = (flips, rejected, corrector
iterations, steps, points written, events written, points before them: the Python lists'
length); the current point ``X = (q, D, B)`` and tangent ``t``, the
monitors at it ``mlast``.  Output, in ``Bf`` from index 0: the accepted points (``q, D, B``, arc,
tangent, monitors; ``ist[4]`` of them), the events (``q, D, B`` and ``Ef`` = driver, arc,
step, value before, value after, value, bracket; ``ist[5]``) and, last, each accepted point's
floor of the scale-free closure sigma: ``1 / (|M^-1|_F |A|_F)`` from the step test's LU of
``M = [A; t]`` (``A`` the row- and column-scaled closure Jacobian there), a lower bound of
``sigma_n(A) / sigma_1(A)`` (0 for the closing point, which has no step test).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .kernels_closure import nb_closure_system, nb_copy44, nb_correct_hyperplane_ws, nb_corrector_workspace
from .kernels_drivers import nb_closure_dets, nb_difference, nb_driver_dets
from .kernels_tracking import nb_bordered_tangent

__all__ = ["PAR", "nb_trace", "nb_trace_correct", "nb_trace_dets"]

#: The names of ``par``'s entries, in order.
PAR = ("L", "rank", "h0", "h_min", "h_max", "max_arc", "tol", "cos_max", "event_tol", "detect_closure", "max_steps",
       "bodies")

#: :func:`nb_trace`'s return codes.
DONE, H_MIN, CLOSED, PYTHON_STEP, FULL = 0, 1, 2, 3, 4


@njit(cache=True)
def nb_trace_correct(G, q, D, B, t, a, tol, max_iter, pred, qo, Do, Bo, info, A, r, cw):  # pragma: no cover - compiled
    """``tracking.predict_correct(problem, x, a * t, t, tol, max_iter)`` of a ``MotionProblem``:
    ``info`` = (converged, iterations, total correction length); ``A``, ``r``, ``cw``: the
    corrector's scratch (:func:`.kernels_closure.nb_correct_hyperplane_ws`, ``A`` allocated with
    ``np.zeros``, ``cw`` by :func:`_corrector_ws`).
    ``True`` when ``A`` is then the (unscaled) closure Jacobian at the corrected point."""
    S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, active, row, col = (G[0], G[1], G[2], G[3], G[4],
                                                                                       G[5], G[6], G[8], G[11], G[12])
    for c in range(len(t)):
        pred[c] = a * t[c]
    return nb_correct_hyperplane_ws(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, q, D, B, active,
                                    row, col, t, tol, max_iter, 0.6, pred, np.bool_(True), qo, Do, Bo, info, A, r, cw)


@njit(cache=True)
def _corrector_ws(G, q, B):  # pragma: no cover - compiled
    """:func:`nb_trace_correct`'s ``cw`` for the mechanism ``G`` at a configuration shaped like
    ``(q, B)``."""
    return nb_corrector_workspace(G[5], G[8], len(q), B.shape[0])


@njit(cache=True)
def nb_trace_dets(G, par, q, D, B, lo, hi, out):  # pragma: no cover - compiled
    """The DJ of drivers ``lo .. hi - 1`` (``engine.driver_determinants``; each driver's value
    does not depend on the others asked with it) into ``out[: hi - lo]``: 0, or 2 where the
    Python path must decide (the kernel declines, or a value is not finite)."""
    S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, drivers, cols = (G[0], G[1], G[3], G[4], G[5],
                                                                                          G[6], G[7], G[8], G[9], G[10])
    o = out[: hi - lo]
    if par[11] != 0.0:
        nb_closure_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, par[0], q, D, B,
                        cols[lo:hi], o)
    elif nb_driver_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, active, par[0], par[1], q, D, B,
                        drivers[lo:hi], o, np.empty(0)) != 0:
        return 2
    for v in o:
        if not np.isfinite(v):
            return 2
    return 0


@njit(cache=True)
def _dot(a, b):  # pragma: no cover - compiled
    s = 0.0
    for i in range(len(a)):
        s += a[i] * b[i]
    return s


@njit(cache=True)
def _monitor(G, par, which, q, D, B, X0, t0, vals, dif):  # pragma: no cover - compiled
    """(flag, value): DJ of driver ``which`` at ``(q, D, B)`` (that driver's alone: the same
    number as among all drivers); ``which = -1``: the closure function ``t0 . difference(x0, x)``."""
    if which >= 0:
        if nb_trace_dets(G, par, q, D, B, which, which + 1, vals) != 0:
            return 2, 0.0
        return 0, vals[0]
    nb_difference(G[2], G[3], X0[0], X0[1], X0[2], q, D, B, G[8], G[13], G[12], dif)
    return 0, _dot(t0, dif)


@njit(cache=True)
def _locate(G, par, X, t, h, which, fa, fb, X0, t0, Xm, W, res):  # pragma: no cover - compiled
    """``tracking._locate``: Illinois on the step length ``[0, h]`` from ``X`` along ``t``, each
    trial corrected onto the curve, into ``Xm``; ``res`` = (step length, monitor there, bracket
    values).  Returns 0, or 2 where the Python path must decide."""
    pred, info, vals, dif, Aw, rw, cw = W
    lo, hi, flo, fhi = 0.0, h, fa, fb
    true_lo, true_hi = fa, fb
    side = 0
    mid, fm = 0.0, 0.0
    for _ in range(60):
        if flo != fhi:
            mid = hi - fhi * (hi - lo) / (fhi - flo)
            if not (lo < mid < hi):
                mid = 0.5 * (lo + hi)
        else:
            mid = 0.5 * (lo + hi)
        nb_trace_correct(G, X[0], X[1], X[2], t, mid, par[6], np.int64(20), pred, Xm[0], Xm[1], Xm[2], info, Aw, rw,
                         cw)
        flag, fm = _monitor(G, par, which, Xm[0], Xm[1], Xm[2], X0, t0, vals, dif)
        if flag != 0:
            return 2
        if info[0] == 0.0 or fm == 0.0:
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
        if hi - lo < par[8]:
            break
    res[0], res[1], res[2], res[3] = mid, fm, true_lo, true_hi
    return 0


@njit(cache=True)
def _attempt(G, par, X, t, h, orient, Xn, tn, S):  # pragma: no cover - compiled
    """One predictor-corrector step of length ``h`` and its test: (code, corrector iterations,
    orientation at the new point); code 0 accepted, 1 rejected, 3 rejected by an orientation
    flip, 2 handed to the Python loop (the bordered LU does not certify the step test)."""
    pred, info, info4, A, As, Mb, r, cw = S
    colmap, cws = cw[0], cw[12]  # the corrector's column map and closure scratch (it is done with them)
    fresh = nb_trace_correct(G, X[0], X[1], X[2], t, h, par[6], np.int64(12), pred, Xn[0], Xn[1], Xn[2], info, A, r,
                             cw)
    iters = int(info[1])
    if not (info[0] == 1.0 and info[2] < 0.5 * h):
        return 1, iters, 0.0
    row, col = G[11], G[12]
    nc = As.shape[1]
    if not fresh:  # the corrector's last Jacobian is that of the new point unless it stopped at max_iter
        nb_closure_system(G[0], G[1], G[3], G[4], G[5], G[6], Xn[0], Xn[1], Xn[2], colmap, nc - 6 * (1 + Xn[2].shape[0]),
                          A, r, cws)
    for i in range(As.shape[0]):
        for c in range(nc):
            As[i, c] = row[i] * A[i, c] * col[c]
    nb_bordered_tangent(As, t, Mb, tn, info4)
    if not (info4[0] == 1.0 and info4[2] > 10.0 * par[1] * max(1.0, info4[3])):
        return 2, iters, 0.0
    if _dot(tn, t) < par[7]:
        return 1, iters, info4[1]
    if orient != 0.0 and info4[1] != orient:
        return 3, iters, info4[1]
    return 0, iters, info4[1]


@njit(cache=True)
def _put_point(Bf, k, q, D, B, s, t, m, floor):  # pragma: no cover - compiled
    Pq, PD, PB, Ps, Pt, Pm = Bf[0], Bf[1], Bf[2], Bf[3], Bf[4], Bf[5]
    Bf[10][k] = floor
    Pq[k, :] = q
    nb_copy44(D, PD[k])
    for b in range(B.shape[0]):
        nb_copy44(B[b], PB[k, b])
    Ps[k] = s
    Pt[k, :] = t
    Pm[k, :] = m


@njit(cache=True)
def _events(G, par, fs, ist, X, t, h, Xn, mlast, vals, X0, t0, Xm, W, Bf):  # pragma: no cover - compiled
    """The sign changes of the monitors over the step from ``X`` to ``Xn`` (monitors ``vals``
    there), located and written from event ``ist[5]`` on (not counted yet); returns the number
    written, or -1 where the Python path must decide."""
    Eq, ED, EB, Ef = Bf[6], Bf[7], Bf[8], Bf[9]
    res = np.empty(4)
    ne = ist[5]
    vm = np.empty(len(vals))
    W2 = (W[0], W[1], vm, W[3], W[4], W[5], W[6])
    for k in range(len(vals)):
        a, b = mlast[k], vals[k]
        if np.sign(a) != np.sign(b) and a != 0:
            if _locate(G, par, X, t, h, k, a, b, X0, t0, Xm, W2, res) != 0:
                return -1
            Eq[ne, :] = Xm[0]
            nb_copy44(Xm[1], ED[ne])
            for j in range(Xm[2].shape[0]):
                nb_copy44(Xm[2][j], EB[ne, j])
            Ef[ne, 0], Ef[ne, 1], Ef[ne, 2], Ef[ne, 3] = k, fs[0] + res[0], ist[6] + ist[4] - 1, a
            Ef[ne, 4], Ef[ne, 5], Ef[ne, 6], Ef[ne, 7] = b, res[1], res[2], res[3]
            ne += 1
    return ne - ist[5]


@njit(cache=True)
def _accept(G, par, fs, ist, X, t, h, Xn, tn, mlast, X0, t0, Xm, W, D2, Bf, floor):  # pragma: no cover - compiled
    """The accepted step's monitors, events and loop closure (the reference's order), the new
    point written out: 0, 1 (the curve closed: the closing point written, ``fs[3]`` its arc), or
    2 where the Python path must decide (nothing counted).  ``floor``: the new point's floor of
    the scale-free closure sigma (module docstring)."""
    vals = W[2]
    dcur, dnew, dvalid = D2
    nd = len(vals)
    if nb_trace_dets(G, par, Xn[0], Xn[1], Xn[2], np.int64(0), nd, vals) != 0:
        return 2
    ne = _events(G, par, fs, ist, X, t, h, Xn, mlast, vals, X0, t0, Xm, W, Bf)
    if ne < 0:
        return 2
    s_new = fs[0] + h
    checked = par[9] != 0.0 and s_new > 4 * par[2] and ist[6] + ist[4] > 3
    if checked:
        if dvalid[0] == 0:
            nb_difference(G[2], G[3], X0[0], X0[1], X0[2], X[0], X[1], X[2], G[8], G[13], G[12], dcur)
        nb_difference(G[2], G[3], X0[0], X0[1], X0[2], Xn[0], Xn[1], Xn[2], G[8], G[13], G[12], dnew)
        g0, g1 = _dot(t0, dcur), _dot(t0, dnew)
        if g0 < 0 <= g1 and np.sqrt(_dot(dnew, dnew)) < 3 * h + 1e-9 and _dot(tn, t0) > 0:
            res = np.empty(4)
            vm = np.empty(len(vals))
            if _locate(G, par, X, t, h, -1, g0, g1, X0, t0, Xm, W, res) != 0:
                return 2
            if nb_trace_dets(G, par, Xm[0], Xm[1], Xm[2], np.int64(0), nd, vm) != 0:
                return 2
            _put_point(Bf, ist[4], Xm[0], Xm[1], Xm[2], fs[0] + res[0], tn, vm, 0.0)
            ist[4] += 1
            ist[5] += ne
            fs[3] = fs[0] + res[0]
            return 1
    _put_point(Bf, ist[4], Xn[0], Xn[1], Xn[2], s_new, tn, vals, floor)
    ist[4] += 1
    ist[5] += ne
    mlast[:] = vals
    if checked:
        dcur[:] = dnew
    dvalid[0] = 1 if checked else 0
    return 0


@njit(cache=True)
def nb_trace(G, par, X0, t0, X, t, fs, ist, mlast, Bf):  # pragma: no cover - compiled
    """The tracker's loop from the state ``X, t, fs, ist, mlast`` (module docstring), in place.
    Returns :data:`DONE` (arc or step budget spent), :data:`H_MIN` (no acceptable step above
    ``h_min``), :data:`CLOSED`, :data:`PYTHON_STEP` (the Python loop makes the next step) or
    :data:`FULL` (the output arrays are full: call again with larger ones)."""
    q, D, B = X
    nl = len(t)
    m = 6 * (len(G[5]) - 1)
    Xn = (np.empty_like(q), np.empty((4, 4)), np.empty_like(B))
    Xm = (np.empty_like(q), np.empty((4, 4)), np.empty_like(B))
    tn = np.empty(nl)
    cw = _corrector_ws(G, q, B)  # one corrector scratch for the steps, their test and the event searches
    S = (np.empty(nl), np.zeros(3), np.zeros(4), np.zeros((m, nl)), np.empty((m, nl)), np.empty((nl, nl)), np.empty(m),
         cw)
    W = (S[0], np.zeros(3), np.empty(len(mlast)), np.empty(nl), np.zeros((m, nl)), np.empty(m), cw)
    D2 = (np.empty(nl), np.empty(nl), np.zeros(1, dtype=np.int64))
    cap, ecap = Bf[3].shape[0], Bf[9].shape[0]
    while fs[0] < par[5] and ist[3] < par[10]:
        if ist[4] + 2 > cap or ist[5] + len(mlast) + 1 > ecap:
            return FULL
        h = min(fs[1], par[4], par[5] - fs[0] + 1e-15)
        fs[1] = h
        code, iters, o_n = _attempt(G, par, X, t, h, fs[2], Xn, tn, S)
        if code == 2:
            return PYTHON_STEP
        if code != 0:
            ist[2] += iters
            ist[1] += 1
            ist[0] += 1 if code == 3 else 0
            fs[1] = h * 0.5
            if fs[1] < par[3]:
                return H_MIN
            continue
        got = _accept(G, par, fs, ist, X, t, h, Xn, tn, mlast, X0, t0, Xm, W, D2, Bf,
                      S[2][2] / S[2][3] if S[2][3] > 0.0 else 0.0)
        if got == 2:
            return PYTHON_STEP
        ist[2] += iters
        if got == 1:
            return CLOSED
        q[:] = Xn[0]
        nb_copy44(Xn[1], D)
        for b in range(B.shape[0]):
            nb_copy44(Xn[2][b], B[b])
        t[:] = tn
        fs[0], fs[2] = fs[0] + h, o_n
        ist[3] += 1
        if iters <= 2:
            fs[1] = h * 1.5
        elif iters >= 5:
            fs[1] = h * 0.7
    return DONE


# ---------------------------------------------------------------------------- a pose's distance from a step
@njit(cache=True)
def nb_pose_measure(D, pose, out):  # pragma: no cover - compiled
    """``defect_circuits.pose_distance``'s measure of the output link at ``D`` against a printed
    pose: ``pose`` = (R row by row, p, platform point, pose_tol, angle_tol); ``out`` = (normalised
    distance, |dp|, rotation angle)."""
    dx = D[0, 0] * pose[12] + D[0, 1] * pose[13] + D[0, 2] * pose[14] + D[0, 3] - pose[9]
    dy = D[1, 0] * pose[12] + D[1, 1] * pose[13] + D[1, 2] * pose[14] + D[1, 3] - pose[10]
    dz = D[2, 0] * pose[12] + D[2, 1] * pose[13] + D[2, 2] * pose[14] + D[2, 3] - pose[11]
    dp = np.sqrt(dx * dx + dy * dy + dz * dz)
    Q = np.empty((3, 3))  # R pose.R^T
    for i in range(3):
        for j in range(3):
            Q[i, j] = D[i, 0] * pose[3 * j] + D[i, 1] * pose[3 * j + 1] + D[i, 2] * pose[3 * j + 2]
    a0, a1, a2 = Q[2, 1] - Q[1, 2], Q[0, 2] - Q[2, 0], Q[1, 0] - Q[0, 1]
    th = np.arctan2(0.5 * np.sqrt(a0 * a0 + a1 * a1 + a2 * a2), 0.5 * (Q[0, 0] + Q[1, 1] + Q[2, 2] - 1.0))
    out[0] = np.hypot(dp / pose[15], th / pose[16])
    out[1] = dp
    out[2] = th


@njit(cache=True)
def _pose_at(G, q, D, B, t, a, pose, Xm, W, out):  # pragma: no cover - compiled
    """The measure at the point ``a`` along the step (corrected onto the curve), infinite where
    the corrector does not converge."""
    nb_trace_correct(G, q, D, B, t, a, 1e-11, np.int64(20), W[0], Xm[0], Xm[1], Xm[2], W[1], W[2], W[3], W[4])
    if W[1][0] == 1.0:  # converged
        nb_pose_measure(Xm[1], pose, out)
    else:
        out[0] = out[1] = out[2] = np.inf


@njit(cache=True)
def nb_pose_search(G, q, D, B, t, h, pose, xatol, res):  # pragma: no cover - compiled
    """The smallest :func:`nb_pose_measure` along the step of length ``h`` from ``(q, D, B)``
    along ``t``: SciPy's bounded Brent (``minimize_scalar(method="bounded")``, golden section
    with parabolic steps, ``maxiter`` 500), step for step, each trial point corrected onto the
    curve.  ``res`` = (step length, normalised distance, |dp|, angle) of the best point."""
    Xm = (np.empty_like(q), np.empty((4, 4)), np.empty_like(B))
    m = 6 * (len(G[5]) - 1)
    # the predictor, info, the corrector's scratch (A, r, cw)
    W = (np.empty(len(t)), np.zeros(3), np.zeros((m, len(t))), np.empty(m), _corrector_ws(G, q, B))
    mf, mu = np.empty(3), np.empty(3)
    sqrt_eps = np.sqrt(2.2e-16)
    golden_mean = 0.5 * (3.0 - np.sqrt(5.0))
    a, b = 0.0, h
    fulc = a + golden_mean * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    _pose_at(G, q, D, B, t, xf, pose, Xm, W, mf)
    fx = mf[0]
    num = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = sqrt_eps * abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        rat, e = _brent_step(a, b, xf, nfc, fulc, fx, fnfc, ffulc, xm, tol1, tol2, rat, e, golden_mean)
        si = np.sign(rat) + (1.0 if rat == 0 else 0.0)
        x = xf + si * max(abs(rat), tol1)
        _pose_at(G, q, D, B, t, x, pose, Xm, W, mu)
        fu = mu[0]
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
            mf[:] = mu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if (fu <= fnfc) or (nfc == xf):
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif (fu <= ffulc) or (fulc == xf) or (fulc == nfc):  # noqa: SIM109 - SciPy's test, as written
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = sqrt_eps * abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= 500:
            break
    res[0], res[1], res[2], res[3] = xf, mf[0], mf[1], mf[2]


@njit(cache=True)
def _brent_step(a, b, xf, nfc, fulc, fx, fnfc, ffulc, xm, tol1, tol2, rat, e, golden_mean):  # pragma: no cover
    """The next step ``rat`` (and the new ``e``) of :func:`nb_pose_search`: parabolic where the
    parabola through the last three points is acceptable, else golden section."""
    golden = True
    if abs(e) > tol1:
        golden = False
        r = (xf - nfc) * (fx - ffulc)
        q = (xf - fulc) * (fx - fnfc)
        p = (xf - fulc) * q - (xf - nfc) * r
        q = 2.0 * (q - r)
        if q > 0.0:
            p = -p
        q = abs(q)
        r = e
        e = rat
        if (abs(p) < abs(0.5 * q * r)) and (p > q * (a - xf)) and (p < q * (b - xf)):
            rat = (p + 0.0) / q
            x = xf + rat
            if ((x - a) < tol2) or ((b - x) < tol2):
                si = np.sign(xm - xf) + (1.0 if (xm - xf) == 0 else 0.0)
                rat = tol1 * si
        else:
            golden = True
    if golden:
        e = (a - xf) if xf >= xm else (b - xf)
        rat = golden_mean * e
    return rat, e


# ---------------------------------------------------------------------------- a configuration on a traced curve
@njit(cache=True)
def nb_arc_near(G, Q, DS, BS, T, s, ks, q, D, B, res):  # pragma: no cover - compiled
    """``defect_circuits.arc_on_curve``'s corrections: for each traced point ``k`` of ``ks`` (in
    that order; ``Q, DS, BS`` the points, ``T`` their tangents, ``s`` their arcs), the point
    ``a = t . difference(x_k, c)`` along its tangent corrected onto the curve (``tol`` 1e-11, 30
    iterations) and its distance from ``c = (q, D, B)``; ``res`` = (smallest distance, its arc),
    ``(inf, nan)`` when no correction converged."""
    nl = T.shape[1]
    dif = np.empty(nl)
    Xm = (np.empty_like(q), np.empty((4, 4)), np.empty_like(B))
    pred, info = np.empty(nl), np.zeros(3)
    m = 6 * (len(G[5]) - 1)
    A, r, cw = np.zeros((m, nl)), np.empty(m), _corrector_ws(G, q, B)
    res[0], res[1] = np.inf, np.nan
    for k in ks:
        nb_difference(G[2], G[3], Q[k], DS[k], BS[k], q, D, B, G[8], G[13], G[12], dif)
        a = _dot(T[k], dif)
        nb_trace_correct(G, Q[k], DS[k], BS[k], T[k], a, 1e-11, np.int64(30), pred, Xm[0], Xm[1], Xm[2], info, A, r,
                         cw)
        if info[0] == 0.0:
            continue
        nb_difference(G[2], G[3], Xm[0], Xm[1], Xm[2], q, D, B, G[8], G[13], G[12], dif)
        dist = np.sqrt(_dot(dif, dif))
        if dist < res[0]:
            res[0], res[1] = dist, s[k] + a
