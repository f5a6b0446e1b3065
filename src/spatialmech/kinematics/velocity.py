"""Velocity and acceleration, forward and inverse, for any mechanism.

Platform velocities are spatial twists ``V = (omega ; v)`` (``v``: velocity of the body point
at the origin) and their time derivatives ``Vdot`` (the *spatial* acceleration, not the
acceleration of a point).  :func:`point_velocity` and :func:`point_acceleration` give a point's
velocity and (true) acceleration; :func:`euler_rate_matrix` converts Euler-angle rates of any
named sequence to angular velocity.

Joint rates are those of the local coordinates of :mod:`.closure` (for a one-freedom joint its
variable's rate; for an S joint the components, on its displaced reference axes, of its
relative angular velocity).

For limb ``k`` with spatial Jacobian ``J_k``: ``V = J_k qdot_k`` and
``Vdot = J_k qddot_k + sum_{i<j} ad(J_i qdot_i) J_j qdot_j`` (the derivative of the columns,
each moved by the freedoms before it; ``ad`` is the Lie bracket of twists).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry.rotations import check_sequence
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism
from .closure import Configuration, active_mask, chain_forward, closure_scales, limb_chains, limb_slices
from .backend import closure_jacobian

__all__ = [
    "ad",
    "euler_rate_matrix",
    "forward_acceleration",
    "forward_velocity",
    "inverse_acceleration",
    "inverse_velocity",
    "limb_jacobians",
    "point_acceleration",
    "point_velocity",
]


def ad(V) -> np.ndarray:
    """The 6x6 Lie-bracket matrix of a twist: ``ad(V1) V2 = (w1 x w2 ; w1 x v2 - w2 x v1)``."""
    w, v = np.asarray(V, float)[:3], np.asarray(V, float)[3:]
    W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    Vv = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    out = np.zeros((6, 6))
    out[:3, :3] = W
    out[3:, 3:] = W
    out[3:, :3] = Vv
    return out


def limb_jacobians(mech: Mechanism, config: Configuration) -> list[np.ndarray]:
    """Per limb, its spatial Jacobian (6, m_k) in local coordinates (all freedoms)."""
    return [chain_forward(ch, config.q[sl], local=True)[1] for ch, sl in zip(limb_chains(mech), limb_slices(mech), strict=True)]


def _bias(J: np.ndarray, qd: np.ndarray) -> np.ndarray:
    """``Jdot qdot = sum_{i<j} ad(J_i qd_i) J_j qd_j``."""
    out = np.zeros(6)
    acc = np.zeros(6)  # sum of earlier columns' twists
    for j in range(J.shape[1]):
        out += ad(acc) @ (J[:, j] * qd[j])
        acc += J[:, j] * qd[j]
    return out


def _scale(mech):
    L = mech.characteristic_length
    return np.r_[np.ones(3), np.full(3, 1.0 / L)]


def _limb_solve(mech, J, rhs, locked, name):
    """Minimum-norm joint rates with ``J x = rhs`` (locked freedoms held at zero)."""
    row = _scale(mech)
    cols = ~locked
    x = np.zeros(J.shape[1])
    sol, *_ = np.linalg.lstsq(row[:, None] * J[:, cols], row * rhs, rcond=None)
    x[cols] = sol
    res = float(np.linalg.norm(row * (J @ x - rhs)))
    if res > 1e-9 * max(1.0, float(np.linalg.norm(row * rhs))):
        raise InputError(f"twist: limb {name} cannot produce it (residual {res:.2e}): the constraints forbid it")
    return x


def _no_graph_acceleration(mech: Mechanism) -> None:
    if mech.bodies:
        raise InputError(f"mechanism: accelerations of a mechanism with internal bodies ({mech.name}: "
                         f"{', '.join(mech.bodies)}) are not implemented yet; velocities are")


def inverse_velocity(mech: Mechanism, config: Configuration, twist) -> np.ndarray:
    """Joint rates of every freedom (local coordinates) for a platform twist ``(omega ; v)``.

    Raises ``ValueError`` naming the limb when the twist violates a limb's constraints.
    Passive freedoms (e.g. an SPS leg's spin) get the minimum-norm rates.
    """
    V = np.asarray(twist, float)
    if V.shape != (6,) or not np.all(np.isfinite(V)):
        raise InputError(f"twist: expected 6 finite numbers (omega ; v), got shape {V.shape}")
    if mech.bodies:
        return _graph_velocity(mech, config, {}, V)[1]
    qd = np.zeros(len(config.q))
    for limb, J, sl in zip(mech.limbs, limb_jacobians(mech, config), limb_slices(mech), strict=True):
        locked = np.array([r.freedom.locked for r in mech.freedom_refs[sl]])
        qd[sl] = _limb_solve(mech, J, V, locked, limb.name)
    return qd


def inverse_acceleration(mech: Mechanism, config: Configuration, twist, twist_dot) -> tuple[np.ndarray, np.ndarray]:
    """Joint rates and joint accelerations for a platform twist and its time derivative."""
    A = np.asarray(twist_dot, float)
    if A.shape != (6,) or not np.all(np.isfinite(A)):
        raise InputError(f"twist_dot: expected 6 finite numbers, got shape {A.shape}")
    _no_graph_acceleration(mech)
    qd = inverse_velocity(mech, config, twist)
    qdd = np.zeros_like(qd)
    for limb, J, sl in zip(mech.limbs, limb_jacobians(mech, config), limb_slices(mech), strict=True):
        locked = np.array([r.freedom.locked for r in mech.freedom_refs[sl]])
        qdd[sl] = _limb_solve(mech, J, A - _bias(J, qd[sl]), locked, limb.name)
    return qd, qdd


def _graph_velocity(mech: Mechanism, config: Configuration, rates: dict[int, float],
                    twist: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """Velocities of a mechanism with internal bodies from its closure system: the freedoms in
    ``rates`` (index -> rate) held, the output twist held when ``twist`` is given, every other
    unlocked freedom and every body free.  Returns ``(output twist, joint rates)``; raises
    :class:`~spatialmech.errors.InputError` when the held rates are incompatible with the
    constraints or do not determine the output twist."""
    active = active_mask(mech)
    A, _ = closure_jacobian(mech, config, active=active)
    row, col = closure_scales(mech, active)
    As = row[:, None] * A * col[None, :]
    na = int(active.sum())
    pos = np.cumsum(active) - 1
    x_held = np.zeros(As.shape[1])
    held = np.zeros(As.shape[1], bool)
    for i, v in rates.items():
        if not active[i]:
            raise InputError(f"actuator_rates: {mech.freedom_refs[i].id} is locked")
        x_held[pos[i]] = v / col[pos[i]]
        held[pos[i]] = True
    if twist is not None:
        x_held[na : na + 6] = twist / col[na : na + 6]
        held[na : na + 6] = True
    rhs = -As[:, held] @ x_held[held]
    M = As[:, ~held]
    x, *_ = np.linalg.lstsq(M, rhs, rcond=None)
    if np.linalg.norm(M @ x - rhs) > 1e-9 * max(1.0, float(np.linalg.norm(rhs))):
        what = "twist" if twist is not None else "actuator_rates"
        raise InputError(f"{what}: incompatible with the constraints here (the closure cannot be kept)")
    full = x_held.copy()
    full[~held] = x
    if twist is None:  # the output part must be unique
        _, sv, vt = np.linalg.svd(M)
        r = int(np.sum(sv > current_tolerances().rank * max(1.0, sv[0])))
        null = np.zeros((vt.shape[0] - r, As.shape[1]))
        null[:, ~held] = vt[r:]
        if null.size and np.max(np.abs(null[:, na : na + 6])) > 1e-7:
            raise InputError("actuator_rates: a direct singularity: the actuators do not determine the platform twist here")
    u = full * col
    qd = np.zeros(len(config.q))
    qd[active] = u[:na]
    return u[na : na + 6], qd


def _actuator_indices(mech: Mechanism, actuators) -> list[int]:
    acts = list(mech.actuators) if actuators is None else [mech.freedom(a).id for a in actuators]
    ids = [r.id for r in mech.freedom_refs]
    return [ids.index(a) for a in acts]


def _system(mech, config, idx):
    """Stacked closure rows [J_k | -I] in nondimensional scaling, split into free / actuated columns."""
    Js = limb_jacobians(mech, config)
    n = len(config.q)
    K = len(Js)
    A = np.zeros((6 * K, n + 6))
    for k, (J, sl) in enumerate(zip(Js, limb_slices(mech), strict=True)):
        A[6 * k : 6 * k + 6, sl] = J
        A[6 * k : 6 * k + 6, n:] = -np.eye(6)
    row = np.tile(_scale(mech), K)
    locked = np.array([r.freedom.locked for r in mech.freedom_refs])
    free = [i for i in range(n) if i not in idx and not locked[i]] + list(range(n, n + 6))
    return Js, row[:, None] * A, free


def forward_velocity(mech: Mechanism, config: Configuration, actuator_rates, actuators=None) -> tuple[np.ndarray, np.ndarray]:
    """Platform twist and all joint rates for actuator rates (``mech.actuators`` order).

    Raises ``ValueError`` at a direct singularity (the actuator rates do not determine the
    platform twist) or when the rates are incompatible (an inverse singularity).
    """
    idx = _actuator_indices(mech, actuators)
    r = np.asarray(actuator_rates, float).ravel()
    if r.size != len(idx) or not np.all(np.isfinite(r)):
        raise InputError(f"actuator_rates: expected {len(idx)} finite values, got {r.size}")
    if mech.bodies:
        return _graph_velocity(mech, config, dict(zip(idx, r, strict=True)), None)
    _, A, free = _system(mech, config, idx)
    rhs = -A[:, idx] @ r
    M = A[:, free]
    x, *_ = np.linalg.lstsq(M, rhs, rcond=None)
    if np.linalg.norm(M @ x - rhs) > 1e-9 * max(1.0, float(np.linalg.norm(rhs))):
        raise InputError("actuator_rates: incompatible with the constraints here (an inverse singularity)")
    # the platform part must be unique: no null motion of the free system moves the platform
    _, s, vt = np.linalg.svd(M)
    rank = int(np.sum(s > current_tolerances().rank * max(1.0, s[0])))
    null = vt[rank:]
    if null.size and np.max(np.abs(null[:, -6:])) > 1e-7:
        raise InputError("actuator_rates: a direct singularity: the actuators do not determine the platform twist here")
    qd = np.zeros(len(config.q))
    qd[idx] = r
    for k, i in enumerate(free[:-6]):
        qd[i] = x[k]
    return x[-6:], qd


def forward_acceleration(mech: Mechanism, config: Configuration, actuator_rates, actuator_accelerations,
                         actuators=None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(V, Vdot, qdot, qddot)`` for actuator rates and accelerations."""
    _no_graph_acceleration(mech)
    V, qd = forward_velocity(mech, config, actuator_rates, actuators)
    idx = _actuator_indices(mech, actuators)
    a = np.asarray(actuator_accelerations, float).ravel()
    if a.size != len(idx) or not np.all(np.isfinite(a)):
        raise InputError(f"actuator_accelerations: expected {len(idx)} finite values, got {a.size}")
    Js, A, free = _system(mech, config, idx)
    K = len(Js)
    bias = np.concatenate([_bias(J, qd[sl]) for J, sl in zip(Js, limb_slices(mech), strict=True)])
    row = np.tile(_scale(mech), K)
    rhs = -row * bias - A[:, idx] @ a
    x, *_ = np.linalg.lstsq(A[:, free], rhs, rcond=None)
    qdd = np.zeros(len(config.q))
    qdd[idx] = a
    for k, i in enumerate(free[:-6]):
        qdd[i] = x[k]
    return V, x[-6:], qd, qdd


def point_velocity(twist, point) -> np.ndarray:
    """Velocity of the body point at ``point`` for the spatial twist ``(omega ; v)``."""
    V = np.asarray(twist, float)
    return V[3:] + np.cross(V[:3], np.asarray(point, float))


def point_acceleration(twist, twist_dot, point) -> np.ndarray:
    """(True) acceleration of the body point at ``point``: ``vdot + wdot x p + w x pdot``."""
    V = np.asarray(twist, float)
    A = np.asarray(twist_dot, float)
    p = np.asarray(point, float)
    pd = point_velocity(V, p)
    return A[3:] + np.cross(A[:3], p) + np.cross(V[:3], pd)


def euler_rate_matrix(seq: str, angles, *, degrees: bool = False) -> np.ndarray:
    """``E`` with ``omega = E angle_rates`` (angular velocity in the fixed frame) for a named
    sequence (upper case intrinsic, lower case extrinsic, as :func:`euler_matrix`)."""
    check_sequence(seq)
    a = np.asarray(angles, float)
    if degrees:
        a = np.radians(a)
    axes = {"x": np.array([1.0, 0, 0]), "y": np.array([0, 1.0, 0]), "z": np.array([0, 0, 1.0])}
    cols = []
    if seq.isupper():  # R = R1(a1) R2(a2) R3(a3): axis i moved by the rotations before it
        R = np.eye(3)
        for k, ch in enumerate(seq.lower()):
            cols.append(R @ axes[ch])
            R = R @ _axis_rot(ch, a[k])
    else:  # extrinsic: R = R3(a3) R2(a2) R1(a1): axis i moved by the rotations after it
        for k, ch in enumerate(seq):
            R = np.eye(3)
            for j in range(k + 1, 3):
                R = _axis_rot(seq[j], a[j]) @ R
            cols.append(R @ axes[ch])
    return np.array(cols).T


def _axis_rot(ch: str, t: float) -> np.ndarray:
    c, s = np.cos(t), np.sin(t)
    if ch == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if ch == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
