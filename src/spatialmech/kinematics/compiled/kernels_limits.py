"""Compiled kernel of the workspace limits (:mod:`spatialmech.kinematics.compiled`): the joint
points of many configurations at once, the same products of exponentials as
:func:`spatialmech.kinematics.closure.joint_points` (``chain_forward`` with ``prefixes=True``).

A joint's point moves with the link before it: it is displaced by the chain's displacement just
before the joint's first freedom moves.  The cone and interference margins are then a few
vectorised NumPy lines on the points (:mod:`spatialmech.analysis.workspace.checker`)."""

from __future__ import annotations

import numpy as np

from .jit import njit
from .kernels_se3 import nb_rodrigues, nb_screw_shift

__all__ = ["nb_joint_points"]


@njit(cache=True)
def nb_joint_points(S, ball_of, ball_axes, ball_centre, limb_start, qs, pt_freedom, pt_local, out):
    """``out[s, k]``: point ``pt_local[k]`` (reference position) moved by the displacement of its
    limb's chain (from the ground) just before freedom ``pt_freedom[k]`` moves, at the joint
    variables ``qs[s]``.  Each joint (one freedom, or a ball's three) moves the chain's
    displacement ``(R, p)`` by its own ``(Rb, u)``: ``p += R u``, ``R = R Rb`` (as
    :func:`.kernels_closure.nb_chain_ws`)."""
    n = S.shape[0]
    K = limb_start.shape[0] - 1
    P = pt_freedom.shape[0]
    pre = np.empty((n, 3, 4))
    R = np.empty((3, 3))
    Rb = np.empty((3, 3))
    Rn = np.empty((3, 3))
    p = np.empty(3)
    u = np.empty(3)
    for s in range(qs.shape[0]):
        q = qs[s]
        for li in range(K):
            for a in range(3):
                p[a] = 0.0
                for b in range(3):
                    R[a, b] = 1.0 if a == b else 0.0
            i = limb_start[li]
            hi = limb_start[li + 1]
            while i < hi:
                g = ball_of[i]
                k = 3 if g >= 0 else 1
                for j in range(k):
                    for a in range(3):
                        for b in range(3):
                            pre[i + j, a, b] = R[a, b]
                        pre[i + j, a, 3] = p[a]
                if g >= 0:
                    A = ball_axes[g]
                    c = ball_centre[g]
                    f0 = A[0, 0] * q[i] + A[0, 1] * q[i + 1] + A[0, 2] * q[i + 2]
                    f1 = A[1, 0] * q[i] + A[1, 1] * q[i + 1] + A[1, 2] * q[i + 2]
                    f2 = A[2, 0] * q[i] + A[2, 1] * q[i + 1] + A[2, 2] * q[i + 2]
                    th = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
                    if th > 1e-12:
                        nb_rodrigues(f0 / th, f1 / th, f2 / th, np.sin(th), 1.0 - np.cos(th), Rb)
                    else:
                        nb_rodrigues(0.0, 0.0, 0.0, 0.0, 0.0, Rb)
                    for a in range(3):  # T <- T [Rb, c - Rb c]
                        u[a] = c[a] - (Rb[a, 0] * c[0] + Rb[a, 1] * c[1] + Rb[a, 2] * c[2])
                else:
                    w0, w1, w2 = S[i, 0], S[i, 1], S[i, 2]
                    v0, v1, v2 = S[i, 3], S[i, 4], S[i, 5]
                    t = q[i]
                    if np.sqrt(w0 * w0 + w1 * w1 + w2 * w2) > 1e-12:
                        st = np.sin(t)
                        ct = 1.0 - np.cos(t)
                        nb_rodrigues(w0, w1, w2, st, ct, Rb)
                        u[0], u[1], u[2] = nb_screw_shift(w0, w1, w2, v0, v1, v2, t, st, ct)
                    else:
                        nb_rodrigues(0.0, 0.0, 0.0, 0.0, 0.0, Rb)
                        u[0], u[1], u[2] = t * v0, t * v1, t * v2
                for a in range(3):
                    p[a] += R[a, 0] * u[0] + R[a, 1] * u[1] + R[a, 2] * u[2]
                for a in range(3):
                    for b in range(3):
                        Rn[a, b] = R[a, 0] * Rb[0, b] + R[a, 1] * Rb[1, b] + R[a, 2] * Rb[2, b]
                for a in range(3):
                    for b in range(3):
                        R[a, b] = Rn[a, b]
                i += k
        for k in range(P):
            f = pt_freedom[k]
            x = pt_local[k]
            for a in range(3):
                out[s, k, a] = pre[f, a, 0] * x[0] + pre[f, a, 1] * x[1] + pre[f, a, 2] * x[2] + pre[f, a, 3]
