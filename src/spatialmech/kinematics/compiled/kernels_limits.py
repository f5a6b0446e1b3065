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

__all__ = ["nb_chain_prefixes", "nb_joint_motion", "nb_joint_points", "nb_link_margins", "nb_segment_distance"]


@njit(cache=True)
def nb_joint_motion(S, ball_of, ball_axes, ball_centre, q, i, Rb, u):
    """The displacement ``(Rb, u)`` of the joint whose first freedom is ``i`` (one freedom, or a
    ball's three) at the joint variables ``q``; returns its number of freedoms."""
    g = ball_of[i]
    if g >= 0:  # indexed, not views (each view is an atomic reference count)
        f0 = ball_axes[g, 0, 0] * q[i] + ball_axes[g, 0, 1] * q[i + 1] + ball_axes[g, 0, 2] * q[i + 2]
        f1 = ball_axes[g, 1, 0] * q[i] + ball_axes[g, 1, 1] * q[i + 1] + ball_axes[g, 1, 2] * q[i + 2]
        f2 = ball_axes[g, 2, 0] * q[i] + ball_axes[g, 2, 1] * q[i + 1] + ball_axes[g, 2, 2] * q[i + 2]
        th = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
        if th > 1e-12:
            nb_rodrigues(f0 / th, f1 / th, f2 / th, np.sin(th), 1.0 - np.cos(th), Rb)
        else:  # I + skew(phi): first order, as closure.chain_forward
            nb_rodrigues(f0, f1, f2, 1.0, 0.0, Rb)
        c0, c1, c2 = ball_centre[g, 0], ball_centre[g, 1], ball_centre[g, 2]
        for a in range(3):  # T <- T [Rb, c - Rb c]
            u[a] = ball_centre[g, a] - (Rb[a, 0] * c0 + Rb[a, 1] * c1 + Rb[a, 2] * c2)
        return 3
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
    return 1


@njit(cache=True)
def nb_chain_prefixes(S, ball_of, ball_axes, ball_centre, q, lo, hi, pre, R, Rb, Rn, p, u):
    """The displacement of the chain of freedoms ``lo:hi`` just before each freedom moves, into
    ``pre[lo:hi]`` (3, 4): each joint moves the chain's ``(R, p)`` by its own ``(Rb, u)``:
    ``p += R u``, ``R = R Rb`` (as :func:`.kernels_closure.nb_chain_ws`)."""
    for a in range(3):
        p[a] = 0.0
        for b in range(3):
            R[a, b] = 1.0 if a == b else 0.0
    i = lo
    while i < hi:
        k = nb_joint_motion(S, ball_of, ball_axes, ball_centre, q, i, Rb, u)
        for j in range(k):
            pre[i + j, :, :3] = R
            pre[i + j, :, 3] = p
        for a in range(3):
            p[a] += R[a, 0] * u[0] + R[a, 1] * u[1] + R[a, 2] * u[2]
        for a in range(3):
            for b in range(3):
                Rn[a, b] = R[a, 0] * Rb[0, b] + R[a, 1] * Rb[1, b] + R[a, 2] * Rb[2, b]
        R[:, :] = Rn
        i += k


@njit(cache=True)
def nb_joint_points(S, ball_of, ball_axes, ball_centre, limb_start, qs, pt_freedom, pt_local, out):
    """``out[s, k]``: point ``pt_local[k]`` (reference position) moved by the displacement of its
    limb's chain (from the ground) just before freedom ``pt_freedom[k]`` moves, at the joint
    variables ``qs[s]`` (:func:`nb_chain_prefixes` of every limb)."""
    n = S.shape[0]
    K = limb_start.shape[0] - 1
    pre = np.empty((n, 3, 4))
    R = np.empty((3, 3))
    Rb = np.empty((3, 3))
    Rn = np.empty((3, 3))
    p = np.empty(3)
    u = np.empty(3)
    for s in range(qs.shape[0]):
        for li in range(K):
            nb_chain_prefixes(S, ball_of, ball_axes, ball_centre, qs[s], limb_start[li], limb_start[li + 1], pre, R, Rb,
                              Rn, p, u)
        for k in range(pt_freedom.shape[0]):
            f = pt_freedom[k]
            x = pt_local[k]
            for a in range(3):
                out[s, k, a] = pre[f, a, 0] * x[0] + pre[f, a, 1] * x[1] + pre[f, a, 2] * x[2] + pre[f, a, 3]


@njit(cache=True)
def nb_clip01(x):
    return 0.0 if x < 0.0 else 1.0 if x > 1.0 else x


@njit(cache=True)
def nb_segment_distance(p1, q1, p2, q2):
    """Minimum distance between the segments ``p1 q1`` and ``p2 q2``: the same closest points
    (Ericson 5.1.9, parallel and degenerate cases included) as
    :func:`spatialmech.analysis.workspace.checker.segment_distance`."""
    a = b = c = e = f = 0.0
    for x in range(3):
        d1 = q1[x] - p1[x]
        d2 = q2[x] - p2[x]
        r = p1[x] - p2[x]
        a += d1 * d1
        e += d2 * d2
        b += d1 * d2
        c += d1 * r
        f += d2 * r
    tiny = 1e-300
    a_ = max(a, tiny)
    e_ = max(e, tiny)
    denom = a * e - b * b
    s = nb_clip01((b * f - c * e) / max(denom, tiny)) if denom > 1e-12 * a_ * e_ else 0.0
    t = (b * s + f) / e_
    if t < 0.0:
        s = nb_clip01(-c / a_)
    elif t > 1.0:
        s = nb_clip01((b - c) / a_)
    t = nb_clip01(t)
    deg_a = a <= 1e-300
    deg_e = e <= 1e-300
    if deg_e and not deg_a:
        s = nb_clip01(-c / a_)
    if deg_e:
        t = 0.0
    if deg_a and not deg_e:
        t = nb_clip01(f / e_)
    if deg_a:
        s = 0.0
    sq = 0.0
    for x in range(3):
        g = (p1[x] + s * (q1[x] - p1[x])) - (p2[x] + t * (q2[x] - p2[x]))
        sq += g * g
    return np.sqrt(sq)


@njit(cache=True)
def nb_link_margins(pts, n_links, R, cone_link, cone_axis, cone_platform, cone_max, pair_i, pair_j, pair_clear, out):
    """Cone and interference margins from the link ends ``pts`` (N, 2 n_links, 3): every link's
    start, then every link's end.  Cone ``c`` (column ``c``): ``cone_max[c]`` minus the angle
    ``atan2(|d x a|, d . a)`` between link ``cone_link[c]``'s direction ``d`` and the axis ``a``
    (``R[s] cone_axis[c]`` when ``cone_platform[c]``); pair ``k`` (column ``n_cones + k``): the
    distance of links ``pair_i[k]`` and ``pair_j[k]`` minus ``pair_clear[k]``."""
    nc = cone_link.shape[0]
    ax = np.empty(3)
    d = np.empty(3)
    for s in range(pts.shape[0]):
        for c in range(nc):
            k = cone_link[c]
            for x in range(3):
                d[x] = pts[s, n_links + k, x] - pts[s, k, x]
                if cone_platform[c]:
                    ax[x] = R[s, x, 0] * cone_axis[c, 0] + R[s, x, 1] * cone_axis[c, 1] + R[s, x, 2] * cone_axis[c, 2]
                else:
                    ax[x] = cone_axis[c, x]
            c0 = d[1] * ax[2] - d[2] * ax[1]
            c1 = d[2] * ax[0] - d[0] * ax[2]
            c2 = d[0] * ax[1] - d[1] * ax[0]
            out[s, c] = cone_max[c] - np.arctan2(np.sqrt(c0 * c0 + c1 * c1 + c2 * c2),
                                                 d[0] * ax[0] + d[1] * ax[1] + d[2] * ax[2])
        for k in range(pair_i.shape[0]):
            i = pair_i[k]
            j = pair_j[k]
            out[s, nc + k] = nb_segment_distance(pts[s, i], pts[s, n_links + i], pts[s, j], pts[s, n_links + j]) \
                - pair_clear[k]
