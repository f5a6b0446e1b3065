"""One closure formulation for every mechanism.

A configuration is the vector ``q`` of all joint variables (every freedom of every limb, in
:attr:`Mechanism.freedom_refs` order; zero at the reference), the platform (output link)
displacement ``D`` (4x4) and, for a mechanism with internal bodies (hub links of a
link-and-joint graph, :attr:`Mechanism.bodies`), their displacements ``B`` (k, 4, 4).
Limb ``k`` runs from hub ``a`` to hub ``b`` and closes when ``D_a FK_k(q_k) = D_b`` (``D_a`` is
the identity for the ground): the residual of limb ``k`` is the twist
``log(D_a FK_k D_b^-1)`` (6,), zero at closure.  For limbs from the ground to the platform
this is ``log(FK_k D^-1)``.

Linearisation: ``FK_k(q + dq) ~ exp(J_k dq) FK_k`` with ``J_k`` the limb's *spatial* Jacobian
(the joint twists at the current configuration, columns), and ``D_new = exp(V) D`` for every
hub; hence the closure Jacobian with blocks ``Ad(D_a) J_k``, ``+1`` under ``V_a`` and ``-1``
under ``V_b``, acting on ``(dq_active, V, V_bodies)``.

Only *active* freedoms (not locked) are unknowns; locked freedoms keep their value.
Nondimensional forms (moments divided by the characteristic length ``L``; prismatic variables
divided by ``L``) are used for rank decisions and convergence tests.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry.rotations import (
    exp_twist,
    inverse_transform,
    log_transform,
    matrix_rotvec,
    rotvec_matrix,
    skew,
    transform,
)
from ..geometry.screws import adjoint
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism

__all__ = [
    "Chain",
    "Configuration",
    "CorrectionResult",
    "active_mask",
    "ball_groups",
    "chain_forward",
    "check_configuration",
    "closure_jacobian",
    "closure_residual",
    "closure_scales",
    "correct",
    "hub_count",
    "hub_displacements",
    "joint_points",
    "joint_twists",
    "limb_chains",
    "limb_forward",
    "limb_slices",
    "placed_configuration",
    "recentre_balls",
    "reference_screws",
    "retract",
]


_NO_BODIES = np.zeros((0, 4, 4))
_NO_BODIES.setflags(write=False)


@dataclass(frozen=True, eq=False)
class Configuration:
    """Joint variables ``q`` (all freedoms), platform displacement ``D`` (4x4) and the
    displacements ``B`` (k, 4, 4) of the mechanism's internal bodies (none by default)."""

    q: np.ndarray
    D: np.ndarray
    B: np.ndarray = field(default_factory=lambda: _NO_BODIES)

    @classmethod
    def reference(cls, mech: Mechanism) -> Configuration:
        k = len(mech.bodies)
        return cls(np.zeros(len(mech.freedom_refs)), np.eye(4), np.tile(np.eye(4), (k, 1, 1)) if k else _NO_BODIES)

    @classmethod
    def of(cls, q: np.ndarray, D: np.ndarray, B: np.ndarray = _NO_BODIES) -> Configuration:
        """``Configuration(q, D, B)`` for arrays a solver has just made (taken as they are, like the
        constructor), without the frozen dataclass's ``__init__``: half the cost, which shows in a
        forward solve of a few microseconds."""
        c = object.__new__(cls)
        c.__dict__.update(q=q, D=D, B=B)
        return c

    def hub(self, index: int | None) -> np.ndarray:
        """The displacement of hub ``index`` (see :meth:`Mechanism.hub_index`)."""
        if index is None:
            return np.eye(4)
        return self.D if index == 0 else self.B[index - 1]

    def with_q(self, q) -> Configuration:
        """The same hub displacements with other joint variables."""
        return Configuration(np.asarray(q, dtype=float), self.D, self.B)


def check_configuration(mech: Mechanism, config: Configuration) -> None:
    """``ValueError`` naming the problem when ``config`` does not belong to ``mech``."""
    q = np.asarray(config.q)
    if q.shape != (len(mech.freedom_refs),):
        raise InputError(f"config.q: {mech.name} has {len(mech.freedom_refs)} joint variables, got shape {q.shape}")
    if np.asarray(config.D).shape != (4, 4):
        raise InputError(f"config.D: expected a 4x4 displacement, got shape {np.asarray(config.D).shape}")
    if np.shape(config.B) != (len(mech.bodies), 4, 4):
        raise InputError(f"config.B: {mech.name} has {len(mech.bodies)} internal bodies, got displacements of shape "
                         f"{np.shape(config.B)}")
    if not (np.all(np.isfinite(q)) and np.all(np.isfinite(config.D)) and np.all(np.isfinite(config.B))):
        raise InputError("config: contains NaN or infinity")


def limb_slices(mech: Mechanism) -> list[slice]:
    """Slices of ``q`` belonging to each limb."""
    out, start = [], 0
    for li in range(len(mech.limbs)):
        n = sum(1 for r in mech.freedom_refs if r.limb == li)
        out.append(slice(start, start + n))
        start += n
    return out


_REFERENCE_SCREWS: weakref.WeakKeyDictionary[Mechanism, np.ndarray] = weakref.WeakKeyDictionary()


def reference_screws(mech: Mechanism) -> np.ndarray:
    """Unit twists (n_freedoms, 6) of every freedom at the reference configuration (computed
    once per mechanism, which is frozen; each call returns a fresh copy)."""
    try:
        return _REFERENCE_SCREWS[mech].copy()
    except KeyError:
        pass
    S = np.array([r.freedom.screw for r in mech.freedom_refs])
    _REFERENCE_SCREWS[mech] = S
    return S.copy()


def active_mask(mech: Mechanism) -> np.ndarray:
    return np.array([not r.freedom.locked for r in mech.freedom_refs])


def limb_forward(screws: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Product of exponentials of a chain of one-freedom screws and its spatial Jacobian.

    ``screws`` (m, 6) at the reference, ``q`` (m,).  Returns ``T`` (4x4) and ``J`` (6, m):
    column ``i`` is the twist of freedom ``i`` at the current configuration,
    ``Ad(exp(S1 q1) ... exp(S_{i-1} q_{i-1})) S_i``.
    """
    E = exp_twist(screws, q)  # (m, 4, 4)
    T = np.eye(4)
    J = np.empty((6, len(q)))
    for i in range(len(q)):
        J[:, i] = adjoint(T) @ screws[i]
        T = T @ E[i]
    return T, J


@dataclass(frozen=True, eq=False)
class Chain:
    """One limb as a chain: its freedoms' reference screws and its ball (S) joints.

    An ``S`` joint's three variables are the components, on its three axes, of a rotation
    vector about its centre (exponential coordinates): singular only at a rotation of 2 pi
    (and re-centred beyond pi), unlike three serial rotations (gimbal lock at 90 degrees).
    ``Sm`` joints stay three serial, individually lockable rotations (paper C's model).
    """

    screws: np.ndarray
    balls: tuple[tuple[int, np.ndarray, np.ndarray], ...]  # (first index, centre, axes as columns)


_CHAINS: weakref.WeakKeyDictionary[Mechanism, list[Chain]] = weakref.WeakKeyDictionary()


def limb_chains(mech: Mechanism) -> list[Chain]:
    """The :class:`Chain` of every limb, in limb order (cached per mechanism)."""
    try:
        return _CHAINS[mech]
    except KeyError:
        pass
    S = reference_screws(mech)
    out = []
    for li, sl in enumerate(limb_slices(mech)):
        balls = []
        k = 0
        for joint in mech.limbs[li].joints:
            if joint.type == "S":
                balls.append((k, joint.point, np.array([f.direction for f in joint.freedoms]).T))
            k += len(joint.freedoms)
        out.append(Chain(S[sl], tuple(balls)))
    _CHAINS[mech] = out
    return out


def _left_jacobian_so3(phi: np.ndarray) -> np.ndarray:
    th = float(np.linalg.norm(phi))
    W = skew(phi)
    if th < 1e-6:
        return np.eye(3) + 0.5 * W + (W @ W) / 6.0
    return np.eye(3) + (1 - np.cos(th)) / th**2 * W + (th - np.sin(th)) / th**3 * (W @ W)


def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _rodrigues(W: np.ndarray, W2: np.ndarray, t: float) -> np.ndarray:
    return np.eye(3) + np.sin(t) * W + (1.0 - np.cos(t)) * W2


class _Fast:
    """Per-chain precomputed data for scalar forward kinematics (no stacking overhead)."""

    def __init__(self, chain: Chain):
        S = chain.screws
        self.m = len(S)
        self.w = [S[i, :3].copy() for i in range(self.m)]
        self.v = [S[i, 3:].copy() for i in range(self.m)]
        self.rot = [float(np.linalg.norm(S[i, :3])) > 1e-12 for i in range(self.m)]
        self.W = [skew(S[i, :3]) for i in range(self.m)]
        self.W2 = [Wi @ Wi for Wi in self.W]
        self.ball = {b[0]: (b[1], b[2]) for b in chain.balls}


_FAST: weakref.WeakKeyDictionary[Chain, _Fast] = weakref.WeakKeyDictionary()


def chain_forward(chain: Chain, q: np.ndarray, *, prefixes: bool = False, local: bool = False):
    """Forward kinematics of a :class:`Chain`: ``T`` (4x4) and spatial Jacobian ``J`` (6, m).

    ``local=False``: ``J`` holds the derivatives with respect to ``q``.  ``local=True``: for S
    joints, the columns are instead the rotations about the joint's reference axes (moved by
    the preceding freedoms), the local coordinates in which :func:`retract` composes
    rotation increments; they do not depend on how the joint's rotation is parametrised.
    With ``prefixes=True`` also returns the displacement applied to each freedom's body
    *before* it moves (used to place joint points).
    """
    f = _FAST.get(chain)
    if f is None:
        f = _FAST[chain] = _Fast(chain)
    m = f.m
    J = np.empty((6, m))
    R = np.eye(3)
    p = np.zeros(3)
    pre = np.empty((m, 4, 4)) if prefixes else None
    i = 0
    while i < m:
        if i in f.ball:
            c, A = f.ball[i]
            phi = A @ q[i : i + 3]
            th = float(np.sqrt(phi @ phi))
            if th > 1e-12:
                K = skew(phi / th)
                Rb = _rodrigues(K, K @ K, th)
            else:  # first order (exact to th^2): a rotation this small still moves the chain
                Rb = np.eye(3) + skew(phi)
            Wc = A if local else _left_jacobian_so3(phi) @ A
            for j in range(3):
                d = R @ Wc[:, j]
                J[:3, i + j] = d
                J[3:, i + j] = R @ _cross(c, Wc[:, j]) + _cross(p, d)
                if pre is not None:
                    pre[i + j] = transform(R, p)
            # T <- T [Rb, c - Rb c]
            p = R @ (c - Rb @ c) + p
            R = R @ Rb
            i += 3
            continue
        d = R @ f.w[i]
        J[:3, i] = d
        J[3:, i] = R @ f.v[i] + _cross(p, d)
        if pre is not None:
            pre[i] = transform(R, p)
        t = float(q[i])
        if f.rot[i]:
            Ri = _rodrigues(f.W[i], f.W2[i], t)
            st, ct = np.sin(t), 1.0 - np.cos(t)
            pi = t * f.v[i] + ct * (f.W[i] @ f.v[i]) + (t - st) * (f.W2[i] @ f.v[i])
            p = R @ pi + p
            R = R @ Ri
        else:
            p = R @ (t * f.v[i]) + p
        i += 1
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return (T, J, pre) if prefixes else (T, J)


def _log_single(T: np.ndarray) -> np.ndarray:
    """``log_transform`` for one 4x4 displacement, fast away from a half turn."""
    R = T[:3, :3]
    c = (np.trace(R) - 1.0) / 2.0
    if c < -0.999:
        return log_transform(T)
    w_raw = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    sn = 0.5 * float(np.sqrt(w_raw @ w_raw))
    th = float(np.arctan2(sn, c))  # accurate for small angles, unlike arccos
    p = T[:3, 3]
    if th < 1e-8:  # first order in the angle (G^-1 p = p - w x p / 2; dropping it errs by th |p| / 2)
        w = 0.5 * w_raw
        return np.r_[w, p - 0.5 * _cross(w, p)]
    w = w_raw / (2.0 * sn)
    W = skew(w)
    Ginv = np.eye(3) / th - 0.5 * W + (1.0 / th - 0.5 / np.tan(th / 2.0)) * (W @ W)
    return np.r_[w * th, (Ginv @ p) * th]


def recentre_balls(mech: Mechanism, q: np.ndarray) -> np.ndarray:
    """Replace every S joint's rotation vector longer than pi by the equivalent shorter one."""
    q = q.copy()
    start = 0
    for ch in limb_chains(mech):
        for k, _, A in ch.balls:
            sl = slice(start + k, start + k + 3)
            phi = A @ q[sl]
            th = np.linalg.norm(phi)
            if th > np.pi:
                phi = phi * (1 - 2 * np.pi / th)
                q[sl] = A.T @ phi
        start += len(ch.screws)
    return q


def joint_twists(mech: Mechanism, config: Configuration) -> list[np.ndarray]:
    """Per limb, the (6, m_k) spatial twists of all its freedoms at ``config``."""
    check_configuration(mech, config)
    out = []
    for (a, _), ch, sl in zip(mech.limb_ends, limb_chains(mech), limb_slices(mech), strict=True):
        J = chain_forward(ch, config.q[sl], local=True)[1]
        out.append(J if a is None else adjoint(config.hub(a)) @ J)
    return out


def hub_count(mech: Mechanism) -> int:
    """Moving hub links whose twists are unknowns of the closure: the output link and the
    internal bodies (``1 + len(mech.bodies)``)."""
    return 1 + len(mech.bodies)


def _place_hubs(mech: Mechanism, q: np.ndarray, known: dict) -> dict:
    """Place hubs through limbs from the ``known`` ones (hub index -> displacement), in place."""
    chains, sls = limb_chains(mech), limb_slices(mech)
    grew = True
    while grew and len(known) < len(mech.bodies) + 2:
        grew = False
        for (a, b), ch, sl in zip(mech.limb_ends, chains, sls, strict=True):
            if (a in known) == (b in known):
                continue
            T, _ = chain_forward(ch, q[sl])
            if a in known:
                known[b] = known[a] @ T
            else:
                known[a] = known[b] @ inverse_transform(T)
            grew = True
    return known


def hub_displacements(mech: Mechanism, q: np.ndarray, D: np.ndarray, B: np.ndarray | None = None) -> np.ndarray:
    """Displacements (k, 4, 4) of the internal bodies implied by the joint variables ``q``: each
    body placed through a limb from a hub already placed (the ground, the output link at ``D``,
    or a body placed before), as a start for Newton.  ``B``: bodies to keep where they are
    (rows with NaN are placed); by default every body is placed.  A body no limb reaches keeps
    the identity."""
    k = len(mech.bodies)
    out = np.tile(np.eye(4), (k, 1, 1)) if B is None else np.array(B, dtype=float)
    known = {None: np.eye(4), 0: np.asarray(D, dtype=float)}
    if B is not None:
        for i in range(k):
            if np.all(np.isfinite(out[i])):
                known[1 + i] = out[i]
    _place_hubs(mech, q, known)
    for i in range(k):
        out[i] = known.get(1 + i, np.eye(4))
    return out


def placed_configuration(mech: Mechanism, q) -> Configuration:
    """A configuration with joint variables ``q`` and every moving hub (the output link and the
    bodies) placed through the limbs from the ground: closed when ``q`` is, and otherwise a
    start for Newton that respects as many limbs as a tree of them can."""
    q = np.asarray(q, dtype=float)
    known = _place_hubs(mech, q, {None: np.eye(4)})
    B = np.array([known.get(1 + i, np.eye(4)) for i in range(len(mech.bodies))]).reshape(-1, 4, 4)
    return Configuration(q, known.get(0, np.eye(4)), B)


def closure_residual(mech: Mechanism, config: Configuration) -> np.ndarray:
    """Stacked limb residuals ``log(D_a FK_k D_b^-1)`` (6 K,), SI units."""
    check_configuration(mech, config)
    res = []
    for (a, b), ch, sl in zip(mech.limb_ends, limb_chains(mech), limb_slices(mech), strict=True):
        T, _ = chain_forward(ch, config.q[sl])
        if a is not None:
            T = config.hub(a) @ T
        res.append(_log_single(T @ inverse_transform(config.hub(b))))
    return np.concatenate(res)


def closure_jacobian(mech: Mechanism, config: Configuration, *, active: np.ndarray | None = None):
    """The closure Jacobian (6K, n_active + 6 h) in SI units and the residual (6K,).

    Columns: the active joint variables, then the spatial twist of the output link (6), then
    those of the internal bodies (6 each; ``h`` = :func:`hub_count`)."""
    check_configuration(mech, config)
    if active is None:
        active = active_mask(mech)
    sls = limb_slices(mech)
    K = len(sls)
    n = len(config.q)
    h = hub_count(mech)
    A = np.zeros((6 * K, n + 6 * h))
    res = []
    for k, ((a, b), ch, sl) in enumerate(zip(mech.limb_ends, limb_chains(mech), sls, strict=True)):
        T, J = chain_forward(ch, config.q[sl], local=True)
        rows = slice(6 * k, 6 * k + 6)
        if a is None:
            A[rows, sl] = J
        else:
            Da = config.hub(a)
            A[rows, sl] = adjoint(Da) @ J
            T = Da @ T
            A[rows, n + 6 * a : n + 6 * a + 6] += np.eye(6)
        if b is not None:  # a limb may also end at the ground
            A[rows, n + 6 * b : n + 6 * b + 6] -= np.eye(6)
        res.append(_log_single(T @ inverse_transform(config.hub(b))))
    cols = np.concatenate([active, np.ones(6 * h, bool)])
    return A[:, cols], np.concatenate(res)


def closure_scales(mech: Mechanism, active: np.ndarray):
    """Row and column scalings that make the closure system nondimensional: moment rows divided
    by the characteristic length ``L``, prismatic and hub-translation columns times ``L``."""
    L = mech.characteristic_length
    K = len(mech.limbs)
    row = np.tile(np.r_[np.ones(3), np.full(3, 1.0 / L)], K)
    lin = np.array([r.freedom.is_linear for r in mech.freedom_refs])[active]
    col = np.r_[np.where(lin, L, 1.0), np.tile(np.r_[np.ones(3), np.full(3, L)], hub_count(mech))]
    return row, col


@dataclass(frozen=True)
class CorrectionResult:
    config: Configuration
    converged: bool
    iterations: int
    residual: float  # nondimensional norm
    stationary: bool = False  # steps vanished without closure: a least-squares minimum

    @classmethod
    def of(cls, config: Configuration, converged: bool, iterations: int, residual: float,
           stationary: bool = False) -> CorrectionResult:
        """The constructor without the frozen dataclass's ``__init__`` (see :meth:`Configuration.of`)."""
        r = object.__new__(cls)
        r.__dict__.update(config=config, converged=converged, iterations=iterations, residual=residual,
                          stationary=stationary)
        return r


_BALLS: weakref.WeakKeyDictionary[Mechanism, list] = weakref.WeakKeyDictionary()


def ball_groups(mech: Mechanism) -> list[tuple[int, np.ndarray]]:
    """(first global index, axes as columns) of every S joint (cached per mechanism)."""
    if mech in _BALLS:
        return _BALLS[mech]
    out, start = [], 0
    for ch in limb_chains(mech):
        for k, _, A in ch.balls:
            out.append((start + k, A))
        start += len(ch.screws)
    _BALLS[mech] = out
    return out


def _orthonormal(D: np.ndarray) -> np.ndarray:
    U, _, Vt = np.linalg.svd(D[:3, :3])  # keep the rotation orthonormal (no drift)
    D[:3, :3] = U @ Vt
    return D


def retract(mech, config, active, step, fix_platform=False):
    """Retraction: add a local-coordinate step (see ``chain_forward(local=True)``).

    ``step``: the active joint steps, then a twist (6) per moving hub (:func:`hub_count`: the
    output link, then the internal bodies); a shorter step leaves the remaining hubs where they
    are.  ``fix_platform`` holds the output link (its twist in ``step`` is ignored)."""
    dq = np.zeros_like(config.q)
    na = int(active.sum())
    dq[active] = step[:na]
    q = config.q + dq
    for i, A in ball_groups(mech):
        sl = slice(i, i + 3)
        R_new = rotvec_matrix(A @ dq[sl]) @ rotvec_matrix(A @ config.q[sl])
        q[sl] = A.T @ matrix_rotvec(R_new)
    V = np.asarray(step[na:], dtype=float)
    D = config.D if fix_platform or len(V) < 6 else _orthonormal(exp_twist(V[:6], 1.0) @ config.D)
    B = config.B
    if len(B):
        B = B.copy()
        for i in range(len(B)):
            Vi = V[6 + 6 * i : 12 + 6 * i]
            if len(Vi) == 6:
                B[i] = _orthonormal(exp_twist(Vi, 1.0) @ B[i])
    return Configuration(q, D, B)


def correct(
    mech: Mechanism,
    config: Configuration,
    *,
    active: np.ndarray | None = None,
    fix_platform: bool = False,
    tol: float | None = None,
    max_iter: int = 50,
) -> CorrectionResult:
    """Gauss-Newton (minimum-norm) correction of ``config`` onto the closure manifold, on the joint
    variables: the Python reference of :func:`.backend.correct` (which callers use: it runs the
    compiled engine when it is in use, and the pose-coordinate path of six S-P-S legs).

    ``active`` selects the joint variables that may move (default: every unlocked freedom;
    pass a mask without the actuators for forward position).  ``fix_platform`` holds the
    platform displacement (inverse position); internal bodies always move.  Returns the corrected configuration with
    ``converged`` and the final nondimensional residual norm; never raises on
    non-convergence (the caller decides).
    """
    if active is None:
        active = active_mask(mech)
    if tol is None:  # the newton tolerance in force (geometry/tolerances.py)
        tol = current_tolerances().newton
    row, col = closure_scales(mech, active)
    na = int(active.sum())
    # unknowns: the active joints, the output twist unless held, the bodies' twists
    keep = np.ones(len(col), bool)
    if fix_platform:
        keep[na : na + 6] = False
    for it in range(max_iter + 1):
        A, r = closure_jacobian(mech, config, active=active)
        rn = float(np.linalg.norm(row * r))
        if rn < tol:
            return CorrectionResult(config, True, it, rn)
        if it == max_iter or not np.isfinite(rn):
            break
        As = (row[:, None] * A * col[None, :])[:, keep]
        x, *_ = np.linalg.lstsq(As, -(row * r), rcond=None)
        if np.linalg.norm(x) < 1e-13 * max(1.0, rn):
            return CorrectionResult(config, False, it, rn, stationary=True)
        step = np.zeros(len(col))
        step[keep] = col[keep] * x
        config = retract(mech, config, active, step, fix_platform)
    return CorrectionResult(config, False, it, rn)


def joint_points(mech: Mechanism, config: Configuration) -> list[np.ndarray]:
    """Per limb, the (n_joints, 3) positions of its joint points at ``config``.

    A joint's point moves with the link before it: it is displaced by every freedom that
    precedes the joint in its limb.  Together with the platform point ``D p0`` this is what a
    drawing of the mechanism needs.  The last answer is remembered (a drawing and its joint
    solids ask for the same configuration, which is never changed in place).
    """
    m0, c0, last = _LAST_JOINT_POINTS[0]
    if m0 is mech and c0 is config:
        return [p.copy() for p in last]
    out = []
    for li, (ch, sl) in enumerate(zip(limb_chains(mech), limb_slices(mech), strict=True)):
        _, _, pre = chain_forward(ch, config.q[sl], prefixes=True)
        a = mech.limb_ends[li][0]
        if a is not None:
            pre = config.hub(a) @ pre
        refs = [r for r in mech.freedom_refs if r.limb == li]
        pts = []
        seen = set()
        for k, r in enumerate(refs):
            if r.joint not in seen:
                seen.add(r.joint)
                p = mech.limbs[li].joints[r.joint].point
                pts.append(pre[k, :3, :3] @ p + pre[k, :3, 3])
        out.append(np.array(pts))
    _LAST_JOINT_POINTS[0] = (mech, config, [p.copy() for p in out])  # one tuple: read whole by any thread
    return out


_LAST_JOINT_POINTS: list[tuple] = [(None, None, [])]
