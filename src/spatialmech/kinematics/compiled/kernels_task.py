"""Compiled kernel of the task-coordinate solve (:mod:`spatialmech.kinematics.compiled`): the same
Gauss-Newton steps as :func:`spatialmech.kinematics.task.solve_task` (the given task coordinates
held, the closure solved for the joint variables, the solved coordinates and the internal
bodies), on the plain arrays of the compiled model.

Euler sequences: ``axes`` holds the three axes (0 = x, 1 = y, 2 = z) of the named sequence and
``intrinsic`` its case (upper case intrinsic ``R = R1(a1) R2(a2) R3(a3)``, lower case extrinsic
``R = R3(a3) R2(a2) R1(a1)``), as :func:`spatialmech.geometry.rotations.euler_matrix` and
:func:`spatialmech.kinematics.velocity.euler_rate_matrix`."""

from __future__ import annotations

import numpy as np

from .jit import njit
from .kernels_closure import (
    RETRACT_WS,
    nb_closure_system,
    nb_closure_ws_size,
    nb_colmap,
    nb_norm,
    nb_retract,
    nb_scales,
)
from .kernels_se3 import nb_lstsq

__all__ = ["nb_euler", "nb_matrix_euler", "nb_predict", "nb_task_grid", "nb_task_solve"]


@njit(cache=True)
def nb_axis_rot(ax, t, out):
    """Rotation by ``t`` about coordinate axis ``ax`` (0 = x, 1 = y, 2 = z) into ``out``."""
    c = np.cos(t)
    s = np.sin(t)
    for i in range(3):
        for j in range(3):
            out[i, j] = 1.0 if i == j else 0.0
    i = (ax + 1) % 3
    j = (ax + 2) % 3
    out[i, i] = c
    out[j, j] = c
    out[i, j] = -s
    out[j, i] = s


@njit(cache=True)
def nb_rotate_by(M, ax, t, Rk, T):
    """``M <- M R_ax(t)`` (scratch ``Rk``, ``T``)."""
    nb_axis_rot(ax, t, Rk)
    for i in range(3):
        for j in range(3):
            T[i, j] = M[i, 0] * Rk[0, j] + M[i, 1] * Rk[1, j] + M[i, 2] * Rk[2, j]
    M[:, :] = T


@njit(cache=True)
def nb_euler(axes, intrinsic, a, R, E):
    """The rotation ``R`` of Euler angles ``a`` (3,) and ``E`` (``omega = E da/dt``, the angular
    velocity in the fixed frame), for the sequence ``axes`` / ``intrinsic``: intrinsic
    ``R = R1 R2 R3``, axis ``k`` moved by the rotations before it; extrinsic ``R = R3 R2 R1``,
    axis ``k`` moved by the rotations after it."""
    Rk = np.empty((3, 3))
    T = np.empty((3, 3))
    M = np.eye(3)
    for j in range(3):
        k = j if intrinsic else 2 - j
        E[:, k] = M[:, axes[k]]
        nb_rotate_by(M, axes[k], a[k], Rk, T)
    R[:, :] = M


@njit(cache=True)
def nb_matrix_euler(axes, intrinsic, R, out):
    """The Euler angles ``out`` (3,) of the rotation ``R`` in the sequence ``axes`` /
    ``intrinsic``: :func:`spatialmech.geometry.rotations.matrix_euler` (SciPy's
    ``Rotation.from_matrix(R).as_euler(seq)``: the quaternion by the largest of the trace and the
    diagonal, then Bernardes and Viollet's angles, each angle wrapped to [-pi, pi); at a gimbal
    lock the third angle is 0) for an orthonormal ``R``."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    choice = 0
    best = R[0, 0]
    for c in range(1, 4):
        v = tr if c == 3 else R[c, c]
        if v > best:
            best = v
            choice = c
    q = np.empty(4)
    if choice == 0:
        q[0], q[1], q[2], q[3] = 1 - tr + 2 * R[0, 0], R[1, 0] + R[0, 1], R[2, 0] + R[0, 2], R[2, 1] - R[1, 2]
    elif choice == 1:
        q[0], q[1], q[2], q[3] = R[1, 0] + R[0, 1], 1 - tr + 2 * R[1, 1], R[2, 1] + R[1, 2], R[0, 2] - R[2, 0]
    elif choice == 2:
        q[0], q[1], q[2], q[3] = R[2, 0] + R[0, 2], R[2, 1] + R[1, 2], 1 - tr + 2 * R[2, 2], R[1, 0] - R[0, 1]
    else:
        q[0], q[1], q[2], q[3] = R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1], 1 + tr
    nq = np.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    for t in range(4):
        q[t] /= nq
    extrinsic = not intrinsic
    if extrinsic:
        i, j, k = axes[0], axes[1], axes[2]
    else:
        i, j, k = axes[2], axes[1], axes[0]
    symmetric = i == k
    if symmetric:
        k = 3 - i - j
    sign = float((i - j) * (j - k) * (k - i) // 2)
    if symmetric:
        a, b, c, d = q[3], q[i], q[j], q[k] * sign
    else:
        a, b, c, d = q[3] - q[j], q[i] + q[k] * sign, q[j] + q[3], q[k] * sign - q[i]
    half_sum = np.arctan2(b, a)
    half_diff = np.arctan2(d, c)
    out[0] = 0.0
    out[1] = 2 * np.arctan2(np.hypot(c, d), np.hypot(a, b))
    out[2] = 0.0
    first = 0 if extrinsic else 2
    third = 2 if extrinsic else 0
    case1 = abs(out[1]) <= 1e-7
    case2 = abs(out[1] - np.pi) <= 1e-7
    case0 = not (case1 or case2)
    out[0] = 2 * half_sum if case1 else 2 * half_diff * (-1.0 if extrinsic else 1.0)
    if case0:
        out[first] = half_sum - half_diff
    a3 = half_sum + half_diff if case0 else out[third]
    if not symmetric:
        a3 = a3 * sign
        out[1] = out[1] - np.pi / 2
    out[third] = a3
    for t in range(3):
        out[t] = (out[t] + np.pi) % (2 * np.pi) - np.pi


@njit(cache=True)
def nb_pose_from_task(axes, intrinsic, values, p0, D, E):
    """The output displacement ``D`` of task coordinates ``values`` (6,) (the output link's
    reference point ``p0``), and the Euler rate matrix ``E`` there."""
    R = np.empty((3, 3))
    nb_euler(axes, intrinsic, values[3:], R, E)
    for i in range(3):
        for j in range(3):
            D[i, j] = R[i, j]
        D[i, 3] = values[i] - (R[i, 0] * p0[0] + R[i, 1] * p0[1] + R[i, 2] * p0[2])
        D[3, i] = 0.0
    D[3, 3] = 1.0


@njit(cache=True)
def nb_task_seed(axes, intrinsic, seeded, p0, D, values):
    """The task coordinates marked ``seeded`` (6,) set to those of the displacement ``D``."""
    start = np.empty(3)
    nb_matrix_euler(axes, intrinsic, D, start)
    for i in range(3):
        if seeded[i]:
            values[i] = D[i, 0] * p0[0] + D[i, 1] * p0[1] + D[i, 2] * p0[2] + D[i, 3]
        if seeded[3 + i]:
            values[3 + i] = start[i]


@njit(cache=True)
def nb_task_scales(free, col, na, h, L):
    """The indices of the solved coordinates (``free``) and the column scales of the task system:
    the active joints' (``col[:na]``), ``L`` for a solved length and 1 for an angle, the internal
    bodies' (``col[na + 6:]``)."""
    nf = 0
    for i in range(6):
        if free[i]:
            nf += 1
    fidx = np.empty(nf, dtype=np.int64)
    j = 0
    for i in range(6):
        if free[i]:
            fidx[j] = i
            j += 1
    scales = np.empty(na + nf + 6 * (h - 1))
    scales[:na] = col[:na]
    for k in range(nf):
        scales[na + k] = L if fidx[k] < 3 else 1.0
    scales[na + nf :] = col[na + 6 :]
    return fidx, scales


@njit(cache=True)
def nb_task_system(A, row, E, values, fidx, scales, na, C, G):
    """The scaled task system ``row G scales`` with ``G = [A_joints, A_output C_free, A_bodies]``,
    ``C = [[0, E], [I, skew(P) E]]`` the coordinate map at ``values`` (``V = C d(values)/dt``)."""
    nf = fidx.shape[0]
    C[:, :] = 0.0
    for i in range(3):
        C[3 + i, i] = 1.0
        for k in range(3):
            C[i, 3 + k] = E[i, k]
    for k in range(3):
        C[3, 3 + k] = values[1] * E[2, k] - values[2] * E[1, k]
        C[4, 3 + k] = values[2] * E[0, k] - values[0] * E[2, k]
        C[5, 3 + k] = values[0] * E[1, k] - values[1] * E[0, k]
    for i in range(A.shape[0]):
        for c in range(na):
            G[i, c] = row[i] * A[i, c] * scales[c]
        for k in range(nf):
            acc = 0.0
            for m in range(6):
                acc += A[i, na + m] * C[m, fidx[k]]
            G[i, na + k] = row[i] * acc * scales[na + k]
        for c in range(na + nf, G.shape[1]):
            G[i, c] = row[i] * A[i, c - nf + 6] * scales[c]


@njit(cache=True)
def nb_task_step(x, scales, fidx, na, step, values):
    """The retraction step (joints, no platform twist, bodies) and the solved coordinates moved by
    the scaled solution ``x``."""
    nf = fidx.shape[0]
    for c in range(na):
        step[c] = scales[c] * x[c]
    step[na : na + 6] = 0.0
    for c in range(na + nf, x.shape[0]):
        step[c - nf + 6] = scales[c] * x[c]
    for k in range(nf):
        values[fidx[k]] += scales[na + k] * x[na + k]


@njit(cache=True)
def nb_task_solve(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, active, p0, axes,
                  intrinsic, seeded, free, values, q, D, B, tol, max_iter, info):
    """``solve_task`` from the configuration ``q``, ``D``, ``B`` (updated in place, with
    ``values``): the task coordinates marked ``seeded`` (6,) start at the seed's (``D``'s), the
    others at ``values``; those marked ``free`` (6,) are solved, and end in ``values``.
    ``info``: status (1 converged, 2 stalled, 0 not converged), the iterations, the residual."""
    nb_task_seed(axes, intrinsic, seeded, p0, D, values)
    K = len(limb_start) - 1
    h = 1 + B.shape[0]
    n = q.shape[0]
    colmap, na = nb_colmap(active)
    row, col = nb_scales(linear, active, K, h, L)
    fidx, scales = nb_task_scales(free, col, na, h, L)
    A = np.zeros((6 * K, na + 6 * h))
    r = np.zeros(6 * K)
    G = np.empty((6 * K, scales.shape[0]))
    rhs = np.empty(6 * K)
    step = np.zeros(na + 6 * h)
    C = np.zeros((6, 6))
    E = np.empty((3, 3))
    q2 = np.empty(n)
    D2 = np.empty((4, 4))
    B2 = np.empty((h - 1, 4, 4))
    cws = np.empty(nb_closure_ws_size(limb_start))
    rws = np.empty(n + RETRACT_WS)
    nb_pose_from_task(axes, intrinsic, values, p0, D, E)
    st = 0
    rn = np.inf
    it = 0
    for it in range(max_iter + 1):
        nb_closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, A, r, cws)
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
        nb_task_system(A, row, E, values, fidx, scales, na, C, G)
        x = nb_lstsq(G, rhs)
        if nb_norm(x) < 1e-13 * max(1.0, rn):
            st = 2
            break
        nb_task_step(x, scales, fidx, na, step, values)
        nb_retract(ball_first, ball_axes, q, D, B, active, step, na, np.bool_(True), q2, D2, B2, rws)
        q[:] = q2
        B[:, :, :] = B2
        nb_pose_from_task(axes, intrinsic, values, p0, D, E)
    info[0] = st
    info[1] = it
    info[2] = rn


@njit(cache=True)
def nb_predict(qc, Dc, Bc, qp, Dp, Bp, q, D, B):
    """``task_grid.predict``: one more secant step ``prev -> cur`` from ``cur`` (joint variables
    extrapolated linearly, displacements by ``cur prev^-1 cur``) into ``q``, ``D``, ``B``."""
    inv = np.empty((4, 4))
    T = np.empty((4, 4))
    for i in range(q.shape[0]):
        q[i] = 2.0 * qc[i] - qp[i]
    for b in range(-1, B.shape[0]):
        P = Dp if b < 0 else Bp[b]
        C = Dc if b < 0 else Bc[b]
        out = D if b < 0 else B[b]
        for i in range(3):
            for j in range(3):
                inv[i, j] = P[j, i]
            inv[i, 3] = -(P[0, i] * P[0, 3] + P[1, i] * P[1, 3] + P[2, i] * P[2, 3])
            inv[3, i] = 0.0
        inv[3, 3] = 1.0
        for i in range(4):
            for j in range(4):
                T[i, j] = C[i, 0] * inv[0, j] + C[i, 1] * inv[1, j] + C[i, 2] * inv[2, j] + C[i, 3] * inv[3, j]
        for i in range(4):
            for j in range(4):
                out[i, j] = T[i, 0] * C[0, j] + T[i, 1] * C[1, j] + T[i, 2] * C[2, j] + T[i, 3] * C[3, j]


@njit(cache=True)
def nb_task_grid(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, active, p0, axes,
                 intrinsic, free, base, grid, coord, shape, order, q0, D0, B0, islands, tol, max_iter, budget, state,
                 attempts, converged, parents, queue, q_out, D_out, B_out, values_out, residuals):
    """``task_grid.solve_task_grid``'s sweep: the cells in ``order`` (flat, C order over ``shape``)
    each start a breadth-first sweep unless already attempted (only the first unless
    ``islands``), solved from the seed ``q0, D0, B0``; each neighbour (coordinate by coordinate,
    the step -1 then +1) not converged and attempted fewer than twice is solved from the secant
    prediction (when its parent's parent is in line) then from the parent's solution.  Cell
    values: ``base`` (6,) with grid coordinate ``k`` (task coordinate ``coord[k]``) at
    ``grid[k, i_k]``.  Resumable: ``state`` = (position in ``order``, queue head, queue tail,
    a sweep found, solves so far, finished); returns after the step in which the solves reach
    ``budget``."""
    d = shape.shape[0]
    n = q0.shape[0]
    stride = np.empty(d, dtype=np.int64)
    s_ = 1
    for k in range(d - 1, -1, -1):
        stride[k] = s_
        s_ *= shape[k]
    qs = np.empty((2, n))
    Ds = np.empty((2, 4, 4))
    Bs = np.empty((2, B0.shape[0], 4, 4))
    q = np.empty(n)
    D = np.empty((4, 4))
    B = np.empty((B0.shape[0], 4, 4))
    vals = np.empty(6)
    info = np.empty(3)
    cur_i = np.empty(d, dtype=np.int64)
    while state[5] == 0 and state[4] < budget:
        if state[2] > state[1]:  # the sweep goes on: the next cell of the queue
            cur = queue[state[1]]
            state[1] += 1
            rem = cur
            for k in range(d):
                cur_i[k] = rem // stride[k]
                rem -= cur_i[k] * stride[k]
            prev = parents[cur]
            for k in range(d):
                for step in (-1, 1):
                    if not 0 <= cur_i[k] + step < shape[k]:
                        continue
                    nb = cur + step * stride[k]
                    if converged[nb] or attempts[nb] >= 2:
                        continue
                    ns = np.int64(1)
                    if prev >= 0 and cur - prev == step * stride[k]:
                        nb_predict(q_out[cur], D_out[cur], B_out[cur], q_out[prev], D_out[prev], B_out[prev],
                                   qs[0], Ds[0], Bs[0])
                        ns = np.int64(2)
                    qs[ns - 1] = q_out[cur]
                    Ds[ns - 1] = D_out[cur]
                    Bs[ns - 1] = B_out[cur]
                    if _attempt(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, active,
                                p0, axes, intrinsic, free, base, grid, coord, stride, nb, qs, Ds, Bs, ns, tol,
                                max_iter, state, attempts, converged, q, D, B, vals, info, q_out, D_out, B_out,
                                values_out, residuals):
                        parents[nb] = cur
                        queue[state[2]] = nb
                        state[2] += 1
            continue
        # a new start
        while state[0] < order.shape[0] and attempts[order[state[0]]] > 0:
            state[0] += 1
        if state[0] >= order.shape[0] or (state[3] == 1 and not islands):
            state[5] = 1
            break
        start = order[state[0]]
        state[0] += 1
        qs[0] = q0
        Ds[0] = D0
        Bs[0] = B0
        if _attempt(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, active, p0, axes,
                    intrinsic, free, base, grid, coord, stride, start, qs, Ds, Bs, np.int64(1), tol, max_iter, state, attempts,
                    converged, q, D, B, vals, info, q_out, D_out, B_out, values_out, residuals):
            state[3] = 1
            queue[state[2]] = start
            state[2] += 1


@njit(cache=True)
def _attempt(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, active, p0, axes, intrinsic,
             free, base, grid, coord, stride, cell, qs, Ds, Bs, ns, tol, max_iter, state, attempts, converged, q, D, B,
             vals, info, q_out, D_out, B_out, values_out, residuals):
    """One attempt of grid cell ``cell`` from the seeds ``qs[:ns], Ds[:ns], Bs[:ns]`` in turn,
    until one converges; its solution stored (``task_grid``'s ``attempt``)."""
    attempts[cell] += 1
    rem = cell
    for k in range(stride.shape[0]):
        i = rem // stride[k]
        rem -= i * stride[k]
    for j in range(ns):
        state[4] += 1
        for t in range(6):
            vals[t] = base[t]
        rem = cell
        for k in range(stride.shape[0]):
            i = rem // stride[k]
            rem -= i * stride[k]
            vals[coord[k]] = grid[k, i]
        q[:] = qs[j]
        D[:, :] = Ds[j]
        B[:, :, :] = Bs[j]
        nb_task_solve(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, active, p0, axes,
                      intrinsic, free, free, vals, q, D, B, tol, max_iter, info)
        residuals[cell] = info[2]
        if info[0] == 1:
            converged[cell] = True
            q_out[cell] = q
            D_out[cell] = D
            B_out[cell] = B
            values_out[cell] = vals
            return True
    return False
