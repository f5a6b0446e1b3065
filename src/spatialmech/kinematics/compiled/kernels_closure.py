"""Compiled kernels of the closure engine (:mod:`spatialmech.kinematics.compiled`): limb chains by products of
exponentials, the closure residual and Jacobian, Newton correction with retraction, and the
per-limb Gauss-Newton of inverse position; the same steps as :mod:`.closure` and :mod:`.position`."""

from __future__ import annotations

import numpy as np

from .kernels_blocks import nb_blocks_workspace, nb_minnorm_blocks
from .kernels_limits import nb_joint_motion
from .kernels_se3 import (
    nb_lsq_qr,
    nb_ball_product,
    nb_ball_product_ws,
    nb_copy44,
    nb_exp_twist,
    nb_inverse_into,
    nb_log,
    nb_lstsq,
    nb_mm4,
    nb_orthonormal,
)
from .jit import njit

__all__ = [
    "RETRACT_WS",
    "nb_adjoint_columns",
    "nb_chain",
    "nb_chain_ws",
    "nb_closure_system",
    "nb_closure_ws_size",
    "nb_colmap",
    "nb_correct",
    "nb_correct_hyperplane",
    "nb_correct_hyperplane_ws",
    "nb_corrector_workspace",
    "nb_finite_config",
    "nb_hub",
    "nb_limb_columns",
    "nb_limb_gn",
    "nb_max_limb",
    "nb_norm",
    "nb_retract",
    "nb_scales",
    "nb_systems",
]


# ---------------------------------------------------------------------------- chain and closure
@njit(cache=True)
def nb_chain(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J):
    """:func:`.closure.chain_forward` (``local=True``) of the freedoms ``lo:hi``: ``T`` (4x4) and
    the spatial Jacobian ``J[:, :hi - lo]``, in local coordinates for balls (their axes moved by
    the preceding freedoms).  Each joint (one freedom, or a ball's three) contributes columns
    ``(R a ; R m + p x R a)`` for its reference directions ``a`` and moments ``m``, then moves
    the chain's displacement ``(R, p)`` by its own ``(Rb, u)``: ``p += R u``, ``R = R Rb``."""
    nb_chain_ws(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J, np.empty((6, 3, 3)))


@njit(cache=True)
def nb_chain_ws(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J, W):
    """:func:`nb_chain` with its scratch matrices in ``W`` (6, 3, 3): a caller that runs many
    chains allocates them once.  ``W[0]`` holds the chain's rotation ``R``, ``W[1]`` the joint's
    ``Rb``, ``W[2]`` the product, ``W[3]``/``W[4]`` the joint's reference directions and moments,
    ``W[5, 0]`` the chain's ``p`` and ``W[5, 1]`` the joint's ``u``.  They are indexed in ``W``
    rather than taken as views: each view costs an atomic reference count in and out (numba's
    runtime), and this runs for every limb of every closure system."""
    Rb = W[1]
    u = W[5, 1]
    for a in range(3):
        W[5, 0, a] = 0.0
        for b in range(3):
            W[0, a, b] = 1.0 if a == b else 0.0
    i = lo
    while i < hi:
        g = ball_of[i]
        if g >= 0:
            k = 3
            c0, c1, c2 = ball_centre[g, 0], ball_centre[g, 1], ball_centre[g, 2]
            for j in range(3):
                for a in range(3):
                    W[3, a, j] = ball_axes[g, a, j]
                W[4, 0, j] = c1 * ball_axes[g, 2, j] - c2 * ball_axes[g, 1, j]
                W[4, 1, j] = c2 * ball_axes[g, 0, j] - c0 * ball_axes[g, 2, j]
                W[4, 2, j] = c0 * ball_axes[g, 1, j] - c1 * ball_axes[g, 0, j]
        else:
            k = 1
            W[3, 0, 0], W[3, 1, 0], W[3, 2, 0] = S[i, 0], S[i, 1], S[i, 2]
            W[4, 0, 0], W[4, 1, 0], W[4, 2, 0] = S[i, 3], S[i, 4], S[i, 5]
        nb_joint_motion(S, ball_of, ball_axes, ball_centre, q, i, Rb, u)  # the joint's own (Rb, u)
        for j in range(k):
            col = i - lo + j
            for a in range(3):
                J[a, col] = W[0, a, 0] * W[3, 0, j] + W[0, a, 1] * W[3, 1, j] + W[0, a, 2] * W[3, 2, j]
                J[3 + a, col] = W[0, a, 0] * W[4, 0, j] + W[0, a, 1] * W[4, 1, j] + W[0, a, 2] * W[4, 2, j]
            J[3, col] += W[5, 0, 1] * J[2, col] - W[5, 0, 2] * J[1, col]
            J[4, col] += W[5, 0, 2] * J[0, col] - W[5, 0, 0] * J[2, col]
            J[5, col] += W[5, 0, 0] * J[1, col] - W[5, 0, 1] * J[0, col]
        for a in range(3):
            W[5, 0, a] += W[0, a, 0] * W[5, 1, 0] + W[0, a, 1] * W[5, 1, 1] + W[0, a, 2] * W[5, 1, 2]
        for a in range(3):
            for b in range(3):
                W[2, a, b] = W[0, a, 0] * W[1, 0, b] + W[0, a, 1] * W[1, 1, b] + W[0, a, 2] * W[1, 2, b]
        for a in range(3):
            for b in range(3):
                W[0, a, b] = W[2, a, b]
        i += k
    for a in range(3):
        for b in range(3):
            T[a, b] = W[0, a, b]
        T[a, 3] = W[5, 0, a]
        T[3, a] = 0.0
    T[3, 3] = 1.0


@njit(cache=True)
def nb_hub(h, D, B):
    if h == 0:
        return D
    return B[h - 1]


@njit(cache=True)
def nb_adjoint_columns(H, J, m):
    """``J[:, :m] <- Ad(H) J[:, :m]`` in place."""
    for c in range(m):
        t0 = H[0, 0] * J[0, c] + H[0, 1] * J[1, c] + H[0, 2] * J[2, c]
        t1 = H[1, 0] * J[0, c] + H[1, 1] * J[1, c] + H[1, 2] * J[2, c]
        t2 = H[2, 0] * J[0, c] + H[2, 1] * J[1, c] + H[2, 2] * J[2, c]
        b0 = H[0, 0] * J[3, c] + H[0, 1] * J[4, c] + H[0, 2] * J[5, c]
        b1 = H[1, 0] * J[3, c] + H[1, 1] * J[4, c] + H[1, 2] * J[5, c]
        b2 = H[2, 0] * J[3, c] + H[2, 1] * J[4, c] + H[2, 2] * J[5, c]
        J[0, c], J[1, c], J[2, c] = t0, t1, t2
        J[3, c] = H[1, 3] * t2 - H[2, 3] * t1 + b0
        J[4, c] = H[2, 3] * t0 - H[0, 3] * t2 + b1
        J[5, c] = H[0, 3] * t1 - H[1, 3] * t0 + b2


@njit(cache=True)
def nb_max_limb(limb_start):
    m = 0
    for k in range(len(limb_start) - 1):
        m = max(m, limb_start[k + 1] - limb_start[k])
    return m


@njit(cache=True)
def nb_closure_ws_size(limb_start):
    """Length of the scratch of :func:`nb_closure_system`."""
    return 6 * max(nb_max_limb(limb_start), 1) + 3 * 16 + 6 + 54


@njit(cache=True)
def nb_closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, A, r, ws):
    """Residual ``r`` (6K,) and, unless ``A`` has no rows (shape (0, 0): the residual only), the
    closure Jacobian ``A`` (6K, na + 6h):
    active joint columns at ``colmap[i]`` (-1: not active), then a twist per moving hub.
    Scratch in ``ws`` (:func:`nb_closure_ws_size`; a Newton loop allocates it once).  Only the
    hub columns of ``A`` are cleared: a limb's active columns are written whole and nothing else
    is, so the rest of ``A`` must be zero (allocate it with ``np.zeros``)."""
    K = len(limb_start) - 1
    mj = max(nb_max_limb(limb_start), 1)
    J = ws[: 6 * mj].reshape((6, mj))
    o = 6 * mj
    T = ws[o : o + 16].reshape((4, 4))
    T2 = ws[o + 16 : o + 32].reshape((4, 4))
    Hi = ws[o + 32 : o + 48].reshape((4, 4))
    res = ws[o + 48 : o + 54]
    W = ws[o + 54 : o + 108].reshape((6, 3, 3))
    want_A = A.shape[0] > 0  # (no flag argument: a literal True or False would compile another copy)
    if want_A:
        for i in range(A.shape[0]):
            for c in range(na, A.shape[1]):
                A[i, c] = 0.0
    for k in range(K):
        lo = limb_start[k]
        hi = limb_start[k + 1]
        nb_chain_ws(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J, W)
        a = ends[k, 0]
        b = ends[k, 1]
        r0 = 6 * k
        if a >= 0:
            Ha = nb_hub(a, D, B)
            if want_A:
                nb_adjoint_columns(Ha, J, hi - lo)
                for i in range(6):
                    A[r0 + i, na + 6 * a + i] += 1.0
            nb_mm4(Ha, T, T2)
            nb_copy44(T2, T)
        if want_A:
            if b >= 0:
                for i in range(6):
                    A[r0 + i, na + 6 * b + i] -= 1.0
            for i in range(lo, hi):
                c = colmap[i]
                if c >= 0:
                    for x in range(6):
                        A[r0 + x, c] = J[x, i - lo]
        if b >= 0:
            nb_inverse_into(nb_hub(b, D, B), Hi)
            nb_mm4(T, Hi, T2)
            nb_log(T2, np.bool_(True), res)
        else:
            nb_log(T, np.bool_(True), res)
        for i in range(6):
            r[r0 + i] = res[i]


@njit(cache=True)
def nb_colmap(active):
    n = len(active)
    out = np.empty(n, dtype=np.int64)
    na = 0
    for i in range(n):
        out[i] = -1
        if active[i]:
            out[i] = na
            na += 1
    return out, na


@njit(cache=True)
def nb_limb_columns(limb_start, colmap):
    """Each limb's active columns ``c_lo[k] .. c_hi[k]-1`` (contiguous: a limb's freedoms are
    consecutive and :func:`nb_colmap` numbers the active ones in order)."""
    K = len(limb_start) - 1
    c_lo = np.empty(K, dtype=np.int64)
    c_hi = np.empty(K, dtype=np.int64)
    c = 0
    for k in range(K):
        c_lo[k] = c
        for i in range(limb_start[k], limb_start[k + 1]):
            if colmap[i] >= 0:
                c += 1
        c_hi[k] = c
    return c_lo, c_hi


@njit(cache=True)
def nb_scales(linear, active, K, h, L):
    """:func:`.closure.closure_scales`."""
    row = np.empty(6 * K)
    for k in range(K):
        for i in range(3):
            row[6 * k + i] = 1.0
            row[6 * k + 3 + i] = 1.0 / L
    na = 0
    for i in range(len(active)):
        if active[i]:
            na += 1
    col = np.empty(na + 6 * h)
    j = 0
    for i in range(len(active)):
        if active[i]:
            col[j] = L if linear[i] else 1.0
            j += 1
    for x in range(h):
        for i in range(3):
            col[na + 6 * x + i] = 1.0
            col[na + 6 * x + 3 + i] = L
    return row, col


#: Scratch entries of :func:`nb_retract` beyond one per joint variable.
RETRACT_WS = 70


@njit(cache=True)
def nb_retract(ball_first, ball_axes, q, D, B, active, step, na, fix_platform, q_out, D_out, B_out, ws):
    """:func:`.closure.retract` into ``q_out``, ``D_out``, ``B_out``; scratch in ``ws``
    (``len(q) + RETRACT_WS`` entries)."""
    n = len(q)
    dq = ws[:n]
    work = ws[n : n + 36].reshape((4, 3, 3))
    E = ws[n + 36 : n + 52].reshape((4, 4))
    orth = ws[n + 52 : n + RETRACT_WS].reshape((2, 3, 3))
    j = 0
    for i in range(n):
        dq[i] = 0.0
        if active[i]:
            dq[i] = step[j]
            j += 1
    for i in range(n):
        q_out[i] = q[i] + dq[i]
    for g in range(len(ball_first)):
        i = ball_first[g]
        nb_ball_product_ws(ball_axes[g], dq[i : i + 3], q[i : i + 3], np.bool_(False), np.bool_(False), q_out[i : i + 3], work)
    nv = len(step) - na
    if fix_platform or nv < 6:
        nb_copy44(D, D_out)
    else:
        nb_exp_twist(step[na : na + 6], E)
        nb_mm4(E, D, D_out)
        nb_orthonormal(D_out, orth)
    for bi in range(B.shape[0]):
        if nv >= 12 + 6 * bi:
            nb_exp_twist(step[na + 6 + 6 * bi : na + 12 + 6 * bi], E)
            nb_mm4(E, B[bi], B_out[bi])
            nb_orthonormal(B_out[bi], orth)
        else:
            nb_copy44(B[bi], B_out[bi])


@njit(cache=True)
def nb_norm(x):
    s = 0.0
    for v in x:
        s += v * v
    return np.sqrt(s)


@njit(cache=True)
def nb_finite_config(q, D, B):
    """Whether a configuration's ``q``, ``D`` and ``B`` hold no NaN or infinity (one sum: either
    propagates into it)."""
    tot = 0.0
    for i in range(q.shape[0]):
        tot += q[i]
    for i in range(4):
        for j in range(4):
            tot += D[i, j]
    for b in range(B.shape[0]):
        for i in range(4):
            for j in range(4):
                tot += B[b, i, j]
    return np.isfinite(tot)


@njit(cache=True)
def nb_correct(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, qs, Ds, Bs, active,
             fix_platform, tol, max_iter, q_out, D_out, B_out, status, iters, resid):
    """:func:`..closure.correct` from each seed ``qs[s], Ds[s], Bs[s]``: the result in ``q_out[s]``,
    ``D_out[s]``, ``B_out[s]``, with ``status[s]`` 1 converged, 2 stationary (steps vanished
    without closure), 0 not converged, -1 a seed holding NaN or infinity (left unsolved: the
    caller names the problem), the iterations and the residual."""
    K = len(limb_start) - 1
    h = 1 + Bs.shape[1]
    n = qs.shape[1]
    colmap, na = nb_colmap(active)
    row, col = nb_scales(linear, active, K, h, L)
    nc = na + 6 * h
    keep = np.ones(nc, dtype=np.bool_)
    if fix_platform:
        for i in range(na, na + 6):
            keep[i] = False
    nk = 0
    for i in range(nc):
        if keep[i]:
            nk += 1
    c_lo, c_hi = nb_limb_columns(limb_start, colmap)
    x = np.empty(nk)
    A = np.zeros((6 * K, nc))
    r = np.zeros(6 * K)
    As = np.zeros((6 * K, nk))
    rhs = np.empty(6 * K)
    step = np.zeros(nc)
    q2 = np.empty(n)
    D2 = np.empty((4, 4))
    B2 = np.empty((h - 1, 4, 4))
    fbuf, ibuf = nb_blocks_workspace(c_lo, c_hi, na, nk)
    no_border = np.empty(0)
    cws = np.empty(nb_closure_ws_size(limb_start))
    rws = np.empty(n + RETRACT_WS)
    for s in range(qs.shape[0]):
        q = q_out[s]
        D = D_out[s]
        B = B_out[s]
        for i in range(n):
            q[i] = qs[s, i]
        nb_copy44(Ds[s], D)
        for b in range(h - 1):
            nb_copy44(Bs[s, b], B[b])
        st = 0
        rn = np.inf
        it = 0
        if not nb_finite_config(q, D, B):
            status[s] = -1
            iters[s] = 0
            resid[s] = np.nan
            continue
        for it in range(max_iter + 1):
            nb_closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, A, r,
                                 cws)
            sq = 0.0
            for i in range(6 * K):
                rhs[i] = -row[i] * r[i]
                sq += rhs[i] * rhs[i]
            rn = np.sqrt(sq)
            if rn < tol:
                st = 1
                break
            if it == max_iter or not np.isfinite(rn):
                break
            for k in range(K):  # the scaled system: only a limb's own and the shared columns are nonzero
                for i in range(6 * k, 6 * k + 6):
                    for c in range(c_lo[k], c_hi[k]):
                        As[i, c] = row[i] * A[i, c] * col[c]
                    j = na
                    for c in range(na, nc):
                        if keep[c]:
                            As[i, j] = row[i] * A[i, c] * col[c]
                            j += 1
            if not nb_minnorm_blocks(As, rhs, no_border, 0.0, c_lo, c_hi, na, x, fbuf, ibuf):  # lstsq's step, by blocks
                x = nb_lstsq(As, rhs)
            if nb_norm(x) < 1e-13 * max(1.0, rn):
                st = 2
                break
            j = 0
            for c in range(nc):
                if keep[c]:
                    step[c] = col[c] * x[j]
                    j += 1
                else:
                    step[c] = 0.0
            nb_retract(ball_first, ball_axes, q, D, B, active, step, na, fix_platform, q2, D2, B2, rws)
            for i in range(n):
                q[i] = q2[i]
            nb_copy44(D2, D)
            for b in range(h - 1):
                nb_copy44(B2[b], B[b])
        status[s] = st
        iters[s] = it
        resid[s] = rn


@njit(cache=True)
def _copy_config(q0, D0, B0, q, D, B):  # pragma: no cover - compiled
    """``q, D, B`` <- ``q0, D0, B0``."""
    for i in range(len(q0)):
        q[i] = q0[i]
    nb_copy44(D0, D)
    for b in range(B0.shape[0]):
        nb_copy44(B0[b], B[b])


@njit(cache=True)
def nb_correct_hyperplane(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, q0, D0, B0, active, row, col,
                          t, tol, max_iter, contraction, pred, has_pred, q, D, B, info, A, r):
    """``tracking.correct_on_hyperplane`` for a mechanism's motion (``tracking.MotionProblem``):
    Newton on the row-scaled closure with every correction orthogonal to ``t`` (local coordinates
    scaled by ``col``), from ``q0, D0, B0`` -- first moved by the predictor step ``pred`` (local
    coordinates) when ``has_pred`` -- into ``q, D, B``; ``info`` = (converged, iterations,
    total correction length).  Each step solves the square ``[A; t] d = [-r; 0]`` by limb blocks
    with ``t`` as border row (:func:`.kernels_blocks.nb_minnorm_blocks`), or by
    :func:`.kernels_se3.nb_lstsq` where the blocks decline (a limb's own columns dependent, an
    ill-conditioned reduced system).  Scratch from the caller: the closure Jacobian ``A``
    ``(6K, n_local)``, zero where :func:`nb_closure_system` writes nothing (allocate it with
    ``np.zeros``; it may be reused), and the residual ``r`` ``(6K,)``.  Returns ``True`` when
    the corrector converged by its residual test inside the loop: ``A`` and ``r`` are then those
    of ``q, D, B`` (unscaled), so that a caller needing the Jacobian there (the tracker's step
    test) need not evaluate it again."""
    ws = nb_corrector_workspace(limb_start, active, len(q0), B0.shape[0])
    return nb_correct_hyperplane_ws(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, q0, D0, B0, active,
                                    row, col, t, tol, max_iter, contraction, pred, has_pred, q, D, B, info, A, r, ws)


@njit(cache=True)
def nb_corrector_workspace(limb_start, active, n, n_hubs):
    """The scratch of :func:`nb_correct_hyperplane_ws` for a mechanism of ``n`` joint
    coordinates, ``n_hubs`` moving hubs and these limbs and active joints: a tuple
    ``(colmap, c_lo, c_hi, fbuf, ibuf, M, rhs, step, d, q2, D2, B2, cws, rws)``.  A caller that
    corrects many times (the tracker's steps, its event and pose searches) allocates it once;
    every call overwrites it before reading it, so no call sees what an earlier one left."""
    colmap, na = nb_colmap(active)
    nc = na + 6 * (1 + n_hubs)
    m = 6 * (len(limb_start) - 1)
    c_lo, c_hi = nb_limb_columns(limb_start, colmap)
    fbuf, ibuf = nb_blocks_workspace(c_lo, c_hi, na, nc)
    return (colmap, c_lo, c_hi, fbuf, ibuf, np.empty((m + 1, nc)), np.empty(m + 1), np.empty(nc), np.empty(nc),
            np.empty(n), np.empty((4, 4)), np.empty((n_hubs, 4, 4)), np.empty(nb_closure_ws_size(limb_start)),
            np.empty(n + RETRACT_WS))


@njit(cache=True)
def nb_correct_hyperplane_ws(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, q0, D0, B0, active, row,
                             col, t, tol, max_iter, contraction, pred, has_pred, q, D, B, info, A, r, ws):
    """:func:`nb_correct_hyperplane` with its scratch ``ws`` from :func:`nb_corrector_workspace`
    (made for the same ``limb_start`` and ``active``)."""
    colmap, c_lo, c_hi, fbuf, ibuf, M, rhs, step, d, q2, D2, B2, cws, rws = ws
    m = M.shape[0] - 1
    nc = M.shape[1]
    na = nc - 6 * (1 + B0.shape[0])
    if has_pred:
        for c in range(nc):
            step[c] = col[c] * pred[c]
        nb_retract(ball_first, ball_axes, q0, D0, B0, active, step, na, np.bool_(False), q, D, B, rws)
    else:
        _copy_config(q0, D0, B0, q, D, B)
    moved = 0.0
    prev = np.inf
    for it in range(max_iter):
        nb_closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, A, r, cws)
        sq = 0.0
        for i in range(m):
            v = row[i] * r[i]
            rhs[i] = -v
            sq += v * v
        if np.sqrt(sq) < tol:
            info[0] = 1.0
            info[1] = it
            info[2] = moved
            return True
        for i in range(m):
            for c in range(nc):
                M[i, c] = row[i] * A[i, c] * col[c]
        for c in range(nc):
            M[m, c] = t[c]
        rhs[m] = 0.0
        # the square system's solution by limb blocks with the tangent as border row, else lstsq's
        if not nb_minnorm_blocks(M, rhs, M[m], 0.0, c_lo, c_hi, na, d, fbuf, ibuf):
            d[:] = nb_lstsq(M, rhs)
        dn = nb_norm(d)
        if it > 0 and dn > contraction * prev:
            info[0] = 0.0
            info[1] = it
            info[2] = moved
            return False
        prev = dn
        moved += dn
        for c in range(nc):
            step[c] = col[c] * d[c]
        nb_retract(ball_first, ball_axes, q, D, B, active, step, na, np.bool_(False), q2, D2, B2, rws)
        _copy_config(q2, D2, B2, q, D, B)
    nb_closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, np.zeros((0, 0)), r,
                      cws)  # the residual only
    sq = 0.0
    for i in range(m):
        v = row[i] * r[i]
        sq += v * v
    info[0] = 1.0 if np.sqrt(sq) < tol else 0.0
    info[1] = max_iter
    info[2] = moved
    return False


@njit(cache=True)
def nb_systems(S, ball_of, ball_axes, ball_centre, limb_start, ends, qs, Ds, Bs, active, want_A, A_out, r_out):
    """Residuals ``r_out[s]`` and, when ``want_A``, closure Jacobians ``A_out[s]`` of many configurations."""
    colmap, na = nb_colmap(active)
    ws = np.empty(nb_closure_ws_size(limb_start))
    for s in range(qs.shape[0]):
        if want_A:
            for i in range(A_out.shape[1]):
                for c in range(A_out.shape[2]):
                    A_out[s, i, c] = 0.0
        nb_closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, qs[s], Ds[s], Bs[s], colmap, na,
                          A_out[s] if want_A else A_out[0], r_out[s], ws)


# ---------------------------------------------------------------------------- limb inverse position
@njit(cache=True)
def nb_limb_gn(S, ball_of, ball_first, ball_axes, ball_centre, Ds, q0s, lin, L, tol, max_iter, hold, has_hold, q_out,
             res_out, ok_out):
    """``position._limb_gn`` for one chain at each tip displacement ``Ds[s]`` from ``q0s[s]``:
    Gauss-Newton in local coordinates (S joints updated by composing rotations); the result in
    ``q_out[s]``, its nondimensional residual and whether it converged."""
    m = q0s.shape[1]
    colscale = np.empty(m)
    for i in range(m):
        colscale[i] = L if lin[i] else 1.0
        if has_hold and hold[i]:
            colscale[i] = 0.0
    row = np.empty(6)
    for i in range(3):
        row[i] = 1.0
        row[3 + i] = 1.0 / L
    Dinv = np.empty((4, 4))
    T = np.empty((4, 4))
    T2 = np.empty((4, 4))
    J = np.empty((6, max(m, 1)))
    M = np.empty((6, m))
    r = np.empty(6)
    rhs = np.empty(6)
    qn = np.empty(m)
    a = np.empty(3)
    for s in range(Ds.shape[0]):
        nb_inverse_into(Ds[s], Dinv)
        q = q_out[s]
        for i in range(m):
            q[i] = q0s[s, i]
        rn = np.inf
        for _ in range(max_iter):
            nb_chain(S, ball_of, ball_axes, ball_centre, q, np.int64(0), m, T, J)
            nb_mm4(T, Dinv, T2)
            nb_log(T2, np.bool_(False), r)
            sq = 0.0
            for i in range(6):
                rhs[i] = -row[i] * r[i]
                sq += rhs[i] * rhs[i]
            rn = np.sqrt(sq)
            if rn < tol:
                break
            for i in range(6):
                for j in range(m):
                    M[i, j] = row[i] * J[i, j] * colscale[j]
            if m < 6:  # overdetermined (6 rows): QR when full rank, else the SVD
                x = np.zeros(m)
                if not nb_lsq_qr(M, rhs, x):
                    x = nb_lstsq(M, rhs)
            else:
                x = nb_lstsq(M, rhs)
            if nb_norm(x) < 1e-14:
                break
            for j in range(m):
                qn[j] = q[j] + colscale[j] * x[j]
            for g in range(len(ball_first)):
                i = ball_first[g]
                for t in range(3):
                    a[t] = colscale[i + t] * x[i + t]
                nb_ball_product(ball_axes[g], a, q[i : i + 3], np.bool_(False), np.bool_(True), qn[i : i + 3])
            for j in range(m):
                q[j] = qn[j]
        res_out[s] = rn
        ok_out[s] = rn < tol
