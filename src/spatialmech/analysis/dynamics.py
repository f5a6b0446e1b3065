"""Inverse dynamics of closed chains by the principle of virtual power (docs/dynamics.md).

**Coordinates.**  The velocity state is ``x = (qdot ; V_hubs)``: the rates of every unlocked
freedom (local coordinates of :mod:`spatialmech.kinematics.closure`; an S joint's three are the
components of its relative angular velocity on its axes) and the spatial twists ``(omega ; v)``
of the hub links (the output link, then the internal bodies).  Each limb closes:
``V_base + sum_f S_f qdot_f - V_tip = 0`` (``S_f`` the freedoms' current twists, ``V`` of the
ground 0), i.e. ``A x = 0``, and differentiated, ``A xdot + beta(x) = 0`` with
``beta = sum_f ad(P_f) S_f qdot_f``, ``P_f`` the twist of the body that carries freedom ``f``'s
axis (the freedoms of one S joint share theirs).

**Links.**  Every moving link (the intermediate links of the limbs, the output link, the internal
bodies) has a twist ``V_l = E_l x`` and a spatial acceleration ``Vdot_l = E_l xdot + beta_l``.
With its mass properties (:mod:`spatialmech.model.inertia`; momentum ``h = M_l V``) the wrench
the link needs from its joints is (Newton-Euler about the world origin, wrenches ``(f ; m)``)::

    W_l = M_l Vdot_l + V_l x* (M_l V_l) - G_l - F_l,     V x* (f ; m) = (w x f ; v x f + w x m),

``G_l = (m g ; c x m g)`` its weight and ``F_l`` an external wrench (given on the output link).

**Virtual power.**  For every virtual velocity ``dx`` with ``A dx = 0``:
``sum_l W_l . E_l dx = sum_j tau_j dqdot_j`` (``.``: the reciprocal product, the power), so
``Q = sum_l E_l^T Delta W_l`` splits as ``Q = B^T tau + A^T lambda``: ``B`` picks the actuated
rates, ``tau`` are the actuator efforts (force along a prismatic, torque about a revolute
freedom, exerted on the distal body), ``lambda`` the loop-closure multipliers.  Limb ``k``
exerts ``P_k = -Delta lambda_k`` on its tip link.  A joint of a limb from the ground to the output
link transmits ``P_k + sum`` (the ``W_l`` of the limb's links beyond it); its *reaction* is that
minus the actuator efforts along its freedoms (as in :mod:`.statics`).

**Idle motions.**  Motions with every actuator still (an SPS leg's spin about its own line) are
not decided by the kinematics: their accelerations are solved from the dynamics (no effort acts
on them): ``N^T (Q + M_x N alpha) = 0`` over a basis ``N`` of them.  The residual of
``Q = B^T tau + A^T lambda`` is reported (zero to round-off when the balance is consistent).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConvergenceError, InputError
from ..geometry.tolerances import current
from ..kinematics.closure import (
    Configuration,
    active_mask,
    chain_forward,
    hub_count,
    joint_twists,
    limb_chains,
    limb_slices,
)
from ..kinematics.forward import forward_position
from ..kinematics.position import freedom_values
from ..kinematics.velocity import ad
from ..model.inertia import LinkInertia, solid_cylinder, spatial_inertia_matrix
from ..model.mechanism import GROUND, Mechanism

__all__ = [
    "DynamicsState",
    "InverseDynamics",
    "follow_actuators",
    "gravity_loads",
    "inverse_dynamics",
    "link_placements",
    "mass_properties",
    "quintic",
    "rest_state",
    "state_from_actuators",
]

#: Radius of the solid cylinders that stand for the links when masses come from a density: the
#: radius of the capsules of the MuJoCo export, times the characteristic length.
SHAPE_RADIUS = 0.02


def _swap(w: np.ndarray) -> np.ndarray:
    """``Delta w``: the two halves of a 6-vector exchanged (``a . b = a^T Delta b``)."""
    return np.r_[w[3:], w[:3]]


def mass_properties(mech: Mechanism, density: float | None = None) -> tuple[dict[str, LinkInertia], dict[str, str]]:
    """Every moving link's mass properties and where they come from: ``"file"`` (the model's
    ``masses``), ``"density"`` (solid cylinders of radius ``SHAPE_RADIUS * L`` along the link's
    drawn segments, the MuJoCo export's capsules, of ``density`` kg/m^3; default the model's
    ``density_kg_m3``) or ``"none"`` (massless).  Raises :class:`InputError` for a model whose
    length unit is not the metre (masses are SI)."""
    from ..exchange.bodies import body_tree

    if mech.length_unit != "m":
        raise InputError(f"length_unit: dynamics needs a model in metres, {mech.name} is in {mech.length_unit!r}")
    rho = mech.density_kg_m3 if density is None else density
    if rho is not None and (isinstance(rho, bool) or not np.isfinite(rho) or rho <= 0):
        raise InputError(f"density: expected a positive number (kg/m^3), got {rho!r}")
    names = [mech.output, *mech.bodies, *(ln for limb in mech.limbs for ln in limb.link_names)]
    out: dict[str, LinkInertia] = {}
    source: dict[str, str] = {}
    segments: dict[str, list] = {}
    if rho is not None:
        for b in body_tree(mech).bodies:
            if not b.ghost:
                segments[b.link] = list(b.segments)
        segments.update(_limb_segments(mech))
    r = SHAPE_RADIUS * mech.characteristic_length
    for name in names:
        if name in mech.inertias:
            out[name], source[name] = mech.inertias[name], "file"
        elif rho is not None and segments.get(name):
            total = LinkInertia(0.0, np.zeros(3), np.zeros((3, 3)))
            for a, b in segments[name]:
                total = total + solid_cylinder(a, b, r, float(rho))
            out[name], source[name] = total, "density"
        else:
            out[name], source[name] = LinkInertia(0.0, np.zeros(3), np.zeros((3, 3))), "none"
    return out, source


def _limb_segments(mech: Mechanism) -> dict[str, list]:
    """The axis of each intermediate link of a limb: from its proximal joint's point to its distal
    joint's; where the two coincide (an SPS leg's cylinder between the S and the P joint), half way
    towards the next distinct point of the limb (the platform point last)."""
    tol = 1e-6 * mech.characteristic_length
    out: dict[str, list] = {}
    for limb in mech.limbs:
        pts = [j.point for j in limb.joints] + [mech.platform_point]
        for j, name in enumerate(limb.link_names):
            a, b = pts[j], pts[j + 1]
            if np.linalg.norm(b - a) < tol:
                later = [p for p in pts[j + 2 :] if np.linalg.norm(p - a) >= tol]
                if not later:
                    continue
                b = a + 0.5 * (later[0] - a)
            out[name] = [(a.copy(), b.copy())]
    return out


# ------------------------------------------------------------------ structure
@dataclass(frozen=True)
class _Link:
    name: str
    hub: int | None  # hub index of a hub link
    limb: int | None  # limb of an intermediate link
    end: int  # freedoms of the limb before this link


def _links(mech: Mechanism) -> list[_Link]:
    out = [_Link(mech.output, 0, None, 0)] + [_Link(b, 1 + i, None, 0) for i, b in enumerate(mech.bodies)]
    for k, limb in enumerate(mech.limbs):
        n = 0
        for j, joint in enumerate(limb.joints[:-1]):
            n += len(joint.freedoms)
            out.append(_Link(limb.link_names[j], None, k, n))
    return out


def _groups(mech: Mechanism, k: int) -> list[int]:
    """Per freedom of limb ``k``, the index of the first freedom of its group (an S joint's
    freedoms are one group: they share the body that carries their axes)."""
    out = []
    i = 0
    for joint in mech.limbs[k].joints:
        m = len(joint.freedoms)
        out += [i] * m if joint.type == "S" else list(range(i, i + m))
        i += m
    return out


@dataclass(frozen=True, eq=False)
class _Frame:
    """The velocity maps at one configuration."""

    A: np.ndarray  # (6K, nx) closure
    E: list[np.ndarray]  # per link (6, nx)
    twists: list[np.ndarray]  # per limb (6, m_k)
    cols: list[np.ndarray]  # per limb, the x index of each freedom (-1: locked)
    act: np.ndarray  # x indices of the actuators
    row: np.ndarray  # (6K,) row scaling of A
    col: np.ndarray  # (nx,) column scaling of x


def _frame(mech: Mechanism, config: Configuration, drivers=None) -> _Frame:
    active = active_mask(mech)
    pos = np.cumsum(active) - 1
    n_act = int(active.sum())
    nx = n_act + 6 * hub_count(mech)
    K = len(mech.limbs)
    tw = joint_twists(mech, config)
    A = np.zeros((6 * K, nx))
    cols = []
    for k, ((a, b), sl) in enumerate(zip(mech.limb_ends, limb_slices(mech), strict=True)):
        c = np.array([pos[i] if active[i] else -1 for i in range(sl.start, sl.stop)], dtype=int)
        cols.append(c)
        rows = slice(6 * k, 6 * k + 6)
        A[rows, c[c >= 0]] = tw[k][:, c >= 0]
        if a is not None:
            A[rows, n_act + 6 * a : n_act + 6 * a + 6] += np.eye(6)
        if b is not None:
            A[rows, n_act + 6 * b : n_act + 6 * b + 6] -= np.eye(6)
    E = []
    for link in _links(mech):
        e = np.zeros((6, nx))
        if link.hub is not None:
            e[:, n_act + 6 * link.hub : n_act + 6 * link.hub + 6] = np.eye(6)
        else:
            k = int(link.limb)  # type: ignore[arg-type]
            a = mech.limb_ends[k][0]
            if a is not None:
                e[:, n_act + 6 * a : n_act + 6 * a + 6] = np.eye(6)
            c = cols[k][: link.end]
            e[:, c[c >= 0]] = tw[k][:, : link.end][:, c >= 0]
        E.append(e)
    ids = [r.id for r in mech.freedom_refs]
    acts = mech.actuators if drivers is None else tuple(mech.freedom(d).id for d in drivers)
    act = []
    for d in acts:
        i = ids.index(d)
        if not active[i]:
            raise InputError(f"drivers: {d} is locked")
        act.append(int(pos[i]))
    L = mech.characteristic_length
    row = np.tile(np.r_[np.ones(3), np.full(3, 1.0 / L)], K)
    lin = np.array([r.freedom.is_linear for r in mech.freedom_refs])[active]
    col = np.r_[np.where(lin, L, 1.0), np.tile(np.r_[np.ones(3), np.full(3, L)], hub_count(mech))]
    return _Frame(A, E, tw, cols, np.array(act, dtype=int), row, col)


def _biases(mech: Mechanism, fr: _Frame, x: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
    """``beta`` of the closure (6K,) and of every link (6,) for the velocity state ``x``."""
    n_act = fr.A.shape[1] - 6 * hub_count(mech)
    per_limb = []  # per limb, the cumulative bias after each freedom (m_k + 1, 6)
    for k, (a, _) in enumerate(mech.limb_ends):
        base = np.zeros(6) if a is None else x[n_act + 6 * a : n_act + 6 * a + 6]
        S, c = fr.twists[k], fr.cols[k]
        rates = np.where(c >= 0, x[np.maximum(c, 0)], 0.0)
        groups = _groups(mech, k)
        run = base.copy()  # twist after each freedom
        before = {}  # twist of the body before each group
        cum = np.zeros((S.shape[1] + 1, 6))
        for i in range(S.shape[1]):
            if groups[i] == i:
                before[i] = run.copy()
            cum[i + 1] = cum[i] + ad(before[groups[i]]) @ (S[:, i] * rates[i])
            run = run + S[:, i] * rates[i]
        per_limb.append(cum)
    beta = np.concatenate([cum[-1] for cum in per_limb])
    link_beta = []
    for link in _links(mech):
        if link.hub is not None:
            link_beta.append(np.zeros(6))
        else:
            link_beta.append(per_limb[int(link.limb)][link.end].copy())  # type: ignore[arg-type]
    return beta, link_beta


def link_placements(mech: Mechanism, config: Configuration) -> dict[str, np.ndarray]:
    """Every moving link's displacement from the reference configuration (4x4), by name."""
    out: dict[str, np.ndarray] = {}
    pre_by_limb = [chain_forward(ch, config.q[sl], prefixes=True, local=True)[2]
                   for ch, sl in zip(limb_chains(mech), limb_slices(mech), strict=True)]
    for link in _links(mech):
        if link.hub is not None:
            out[link.name] = config.hub(link.hub)
        else:
            k = int(link.limb)  # type: ignore[arg-type]
            out[link.name] = config.hub(mech.limb_ends[k][0]) @ pre_by_limb[k][link.end]
    return out


def gravity_loads(mech: Mechanism, config: Configuration, inertias: dict[str, LinkInertia], gravity) -> dict[str, np.ndarray]:
    """The weight of every link with mass at ``config``: ``(m g ; c x m g)`` (moment about the
    origin), by link name."""
    g = np.asarray(gravity, float)
    out = {}
    for name, T in link_placements(mech, config).items():
        li = inertias.get(name)
        if li is not None and li.mass_kg > 0:
            c = T[:3, :3] @ li.com_m + T[:3, 3]
            out[name] = np.r_[li.mass_kg * g, np.cross(c, li.mass_kg * g)]
    return out


# ------------------------------------------------------------------ states
@dataclass(frozen=True, eq=False)
class DynamicsState:
    """A configuration with its velocity state ``x`` and its derivative ``xdot`` (module docstring);
    ``t`` the time (s) and the actuators' values, rates and accelerations."""

    config: Configuration
    x: np.ndarray
    xdot: np.ndarray
    t: float = 0.0
    values: np.ndarray | None = None
    rates: np.ndarray | None = None
    accelerations: np.ndarray | None = None
    frame: _Frame | None = field(default=None, repr=False)  # the velocity maps at config (reused)


def _solve_free(M: np.ndarray, rhs: np.ndarray, what: str) -> np.ndarray:
    x, *_ = np.linalg.lstsq(M, rhs, rcond=None)
    res = float(np.linalg.norm(M @ x - rhs))
    if res > 1e-9 * max(1.0, float(np.linalg.norm(rhs))):
        raise InputError(f"{what}: incompatible with the loop closures here (an inverse singularity; residual {res:.2e})")
    return x


def state_from_actuators(mech: Mechanism, config: Configuration, rates, accelerations, drivers=None,
                         *, t: float = 0.0) -> DynamicsState:
    """The velocity state and its derivative for the actuators' rates and accelerations (the
    idle motions' rates minimum-norm; their accelerations are fixed later by the dynamics).
    Raises :class:`InputError` at a direct singularity (the actuators do not determine the hubs'
    motion) or an inverse one."""
    fr = _frame(mech, config, drivers)
    nx = fr.A.shape[1]
    r = np.asarray(rates, float).ravel()
    acc = np.asarray(accelerations, float).ravel()
    if r.size != fr.act.size or acc.size != fr.act.size or not (np.all(np.isfinite(r)) and np.all(np.isfinite(acc))):
        raise InputError(f"rates/accelerations: expected {fr.act.size} finite values each")
    As = fr.row[:, None] * fr.A * fr.col[None, :]
    free = np.setdiff1d(np.arange(nx), fr.act)
    M = As[:, free]
    _, s, vt = np.linalg.svd(M)
    rank = int(np.sum(s > current().rank * max(1.0, float(s[0]))))
    null = vt[rank:]
    n_q = nx - 6 * hub_count(mech)
    if null.size and np.max(np.abs(null[:, free >= n_q])) > 1e-7:
        raise InputError("config: a direct singularity: the actuators do not determine the motion of the output link here")
    xs = np.zeros(nx)
    xs[fr.act] = r / fr.col[fr.act]
    xs[free] = _solve_free(M, -As[:, fr.act] @ xs[fr.act], "rates")
    x = xs * fr.col
    beta, _ = _biases(mech, fr, x)
    xd = np.zeros(nx)
    xd[fr.act] = acc / fr.col[fr.act]
    xd[free] = _solve_free(M, -fr.row * beta - As[:, fr.act] @ xd[fr.act], "accelerations")
    return DynamicsState(config, x, xd * fr.col, t, None, r, acc, fr if drivers is None else None)


# ------------------------------------------------------------------ the balance
@dataclass(frozen=True, eq=False)
class InverseDynamics:
    """The balance at one state (module docstring).  Efforts in N (prismatic) or N m (revolute)."""

    state: DynamicsState
    actuators: tuple[str, ...]
    efforts: np.ndarray  # (n_a,)
    link_wrenches: dict[str, np.ndarray]  # W_l, (f ; m about the origin), by link
    link_twists: dict[str, np.ndarray]
    link_accelerations: dict[str, np.ndarray]
    limb_wrenches: np.ndarray  # (K, 6) P_k: what each limb exerts on its tip link
    multipliers: np.ndarray  # (6K,) lambda
    idle: int  # dimension of the idle motions
    residual: float  # relative residual of Q = B^T tau + A^T lambda (nondimensional)
    xdot: np.ndarray  # the state derivative with the idle accelerations from the dynamics

    @property
    def by_actuator(self) -> dict[str, float]:
        return {a: float(v) for a, v in zip(self.actuators, self.efforts, strict=True)}


def _crf(V: np.ndarray, h: np.ndarray) -> np.ndarray:
    """``V x* h`` for a twist ``(w ; v)`` and a momentum or wrench ``(f ; m)``."""
    w, v = V[:3], V[3:]
    return np.r_[np.cross(w, h[:3]), np.cross(v, h[:3]) + np.cross(w, h[3:])]


def rest_state(mech: Mechanism, config: Configuration) -> DynamicsState:
    """The mechanism at rest at ``config``: zero velocity state and zero derivative (no
    singularity check: the statics at a singular configuration is a least-squares balance)."""
    nx = int(active_mask(mech).sum()) + 6 * hub_count(mech)
    return DynamicsState(config, np.zeros(nx), np.zeros(nx))


def _solve_balance(fr: _Frame, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``Q = B^T tau + A^T lambda`` for the efforts ``tau`` and the multipliers ``lambda``, and the
    relative residual.  Redundant actuation: the efforts of the least norm with torques divided by
    the characteristic length (forces as they are) -- the definition of :mod:`.statics` -- then
    the least multipliers in the scaled coordinates."""
    n_a = fr.act.size
    B = np.zeros((n_a, Q.size))
    B[np.arange(n_a), fr.act] = 1.0
    K = np.hstack([B.T, fr.col[:, None] * fr.A.T * fr.row[None, :]])
    rhs = fr.col * Q
    U, s, vt = np.linalg.svd(K, full_matrices=True)
    rtol = current().rank * max(1.0, float(s[0]) if s.size else 0.0)
    r = int(np.sum(s > rtol))
    z = vt[:r].T @ ((U[:, :r].T @ rhs) / s[:r])
    N = vt[r:].T  # combinations that balance nothing
    if N.shape[1] and n_a:
        # z[:n_a] = tau * col: a force times L, a torque as it is: uniformly the statics' weights times L
        u, s2, v2 = np.linalg.svd(N[:n_a], full_matrices=True)
        r2 = int(np.sum(s2 > rtol))
        z = z + N @ (v2[:r2].T @ ((u[:, :r2].T @ -z[:n_a]) / s2[:r2]))
    res = float(np.linalg.norm(K @ z - rhs)) / max(float(np.linalg.norm(rhs)), 1e-300)
    return z[:n_a] / fr.col[fr.act], fr.row * z[n_a:], res if np.any(rhs) else 0.0


def inverse_dynamics(mech: Mechanism, state: DynamicsState, inertias: dict[str, LinkInertia], gravity=(0.0, 0.0, -9.81),
                     wrench=None, drivers=None, loads=None) -> InverseDynamics:
    """Actuator efforts, loop multipliers and link wrenches at ``state`` (module docstring);
    ``wrench``: an external wrench ``(f ; m about the origin)`` on the output link; ``loads``:
    further wrenches on links, by name (added to their weights)."""
    config = state.config
    fr = state.frame if state.frame is not None and drivers is None else _frame(mech, config, drivers)
    g = np.asarray(gravity, float)
    F = np.zeros(6) if wrench is None else np.asarray(wrench, float)
    links = _links(mech)
    place = link_placements(mech, config)
    x = state.x
    _, lbeta = _biases(mech, fr, x)
    Ms, Vs, As_ = [], [], []
    for link, E, b in zip(links, fr.E, lbeta, strict=True):
        li = inertias.get(link.name)
        Ms.append(np.zeros((6, 6)) if li is None or li.mass_kg == 0 else spatial_inertia_matrix(li.moved(place[link.name])))
        Vs.append(E @ x)
        As_.append(E @ state.xdot + b)
    weights = gravity_loads(mech, config, inertias, g)
    extra_loads = {} if loads is None else loads
    unknown = sorted(set(extra_loads) - {lk.name for lk in links})
    if unknown:
        raise InputError(f"loads: no moving link named {', '.join(unknown)}")
    total = {n: weights.get(n, np.zeros(6)) + extra_loads.get(n, np.zeros(6)) for n in set(weights) | set(extra_loads)}

    def balance(xdot_extra: np.ndarray) -> tuple[np.ndarray, list[np.ndarray]]:
        Q = np.zeros(x.size)
        Ws = []
        for link, E, M, V, Acc in zip(links, fr.E, Ms, Vs, As_, strict=True):
            W = M @ (Acc + E @ xdot_extra) + _crf(V, M @ V) - total.get(link.name, np.zeros(6))
            if link.hub == 0:
                W = W - F
            Ws.append(W)
            Q += E.T @ _swap(W)
        return Q, Ws

    # idle motions: actuators still and the closure kept
    As = fr.row[:, None] * fr.A * fr.col[None, :]
    B = np.zeros((fr.act.size, x.size))
    B[np.arange(fr.act.size), fr.act] = 1.0
    _, s, vt = np.linalg.svd(np.vstack([As, B]))
    rank = int(np.sum(s > current().rank * max(1.0, float(s[0]))))
    N = (vt[rank:] * fr.col[None, :]).T  # (nx, d) in x units
    extra = np.zeros(x.size)
    if N.shape[1]:
        Q0, _ = balance(extra)
        Mx = sum((E.T @ np.vstack([M[3:], M[:3]]) @ E for E, M in zip(fr.E, Ms, strict=True)), np.zeros((x.size, x.size)))
        alpha, *_ = np.linalg.lstsq(N.T @ Mx @ N, -(N.T @ Q0), rcond=None)
        extra = N @ alpha
    Q, Ws = balance(extra)
    tau, lam, res = _solve_balance(fr, Q)
    P = np.array([-_swap(lam[6 * k : 6 * k + 6]) for k in range(len(mech.limbs))])
    acts = mech.actuators if drivers is None else tuple(mech.freedom(d).id for d in drivers)
    names = [lk.name for lk in links]
    return InverseDynamics(state, tuple(acts), tau, dict(zip(names, Ws, strict=True)),
                           dict(zip(names, Vs, strict=True)),
                           {n: a + E @ extra for n, a, E in zip(names, As_, fr.E, strict=True)},
                           P, lam, int(N.shape[1]), res, state.xdot + extra)


def distal_wrenches(mech: Mechanism, result: InverseDynamics) -> list[np.ndarray]:
    """Per limb, per joint, the sum of the wrenches ``W_l`` of the limb's links beyond the joint
    (what the joint must transmit besides the limb's wrench on its tip)."""
    out = []
    for limb in mech.limbs:
        n = len(limb.joints)
        acc = np.zeros((n, 6))
        for j in range(n - 2, -1, -1):  # link j sits after joint j
            acc[j] = acc[j + 1] + result.link_wrenches[limb.link_names[j]]
        out.append(acc)
    return out


# ------------------------------------------------------------------ trajectories
def quintic(start, end, duration: float, samples: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A rest-to-rest quintic time law from ``start`` to ``end`` actuator values:
    ``a(t) = a0 + (a1 - a0) s(t/T)``, ``s = 10 u^3 - 15 u^4 + 6 u^5``.  Returns the times,
    values, rates and accelerations at ``samples`` equally spaced times (both ends included)."""
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 2:
        raise InputError(f"samples: expected an integer >= 2, got {samples!r}")
    if not (isinstance(duration, (int, float)) and not isinstance(duration, bool) and math.isfinite(duration)
            and duration > 0):
        raise InputError(f"duration: expected a positive number of seconds, got {duration!r}")
    a0, a1 = np.asarray(start, float), np.asarray(end, float)
    t = np.linspace(0.0, float(duration), samples)
    u = t / duration
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    sd = (30 * u**2 - 60 * u**3 + 30 * u**4) / duration
    sdd = (60 * u - 180 * u**2 + 120 * u**3) / duration**2
    d = a1 - a0
    return t, a0 + s[:, None] * d, sd[:, None] * d, sdd[:, None] * d


def actuator_values(mech: Mechanism, config: Configuration, drivers=None) -> np.ndarray:
    """The physical values of the actuators (``mech.actuators`` order, or ``drivers``) at ``config``."""
    ids = [r.id for r in mech.freedom_refs]
    acts = mech.actuators if drivers is None else tuple(mech.freedom(d).id for d in drivers)
    vals = freedom_values(mech, config.q)
    return np.array([vals[ids.index(a)] for a in acts])


def follow_actuators(mech: Mechanism, start: Configuration, values: np.ndarray, *, step: float = 0.02) -> list[Configuration]:
    """The configurations at each row of actuator ``values`` (physical units), followed by
    continuation from ``start`` (steps of at most ``step`` rad or ``step`` characteristic
    lengths).  Raises :class:`ConvergenceError` where the forward position does not follow."""
    L = mech.characteristic_length
    scale = np.array([L if mech.freedom(a).freedom.kind == "P" else 1.0 for a in mech.actuators])
    cur = start
    a_cur = actuator_values(mech, start)
    out = []
    for k, target in enumerate(np.atleast_2d(values)):
        n = max(1, math.ceil(float(np.max(np.abs(target - a_cur) / scale)) / step))
        for i in range(1, n + 1):
            res = forward_position(mech, a_cur + i / n * (target - a_cur), start=cur)
            sol = res.solutions[0] if res.solutions else None
            if sol is None or not sol.converged:
                raise ConvergenceError(f"trajectory: the forward position does not follow the actuators to sample {k} "
                                       "(a singularity or the edge of the workspace)")
            cur = sol.config
        a_cur = np.asarray(target, float)
        out.append(cur)
    return out


def limb_base_ground(mech: Mechanism) -> bool:
    """Whether every limb runs from the ground to the output link with joints in its direction
    (the joint reactions are computed for those)."""
    return not mech.bodies and all(limb.base == GROUND and mech.limb_tip(limb) == mech.output
                                   and not any(j.reversed for j in limb.joints) for limb in mech.limbs)
