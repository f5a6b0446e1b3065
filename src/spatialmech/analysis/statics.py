"""Statics (kinetostatics without inertia) of a mechanism from its screw systems.

An external wrench ``F = (f ; m)`` acts on the output link (``m``: moment about the origin).  The
complete Jacobian (:func:`~spatialmech.kinematics.jacobian.complete_jacobian`) holds, for the
platform twist, the limbs' *constraint* wrenches ``c_i`` (reciprocal to every joint twist of
their limb) and one *actuation* wrench ``a_j`` per actuator, reciprocal to every other twist of
its limb and scaled so that ``a_j . $_j = 1`` (``.``: the reciprocal product ``$1^T Delta $2``);
``J $p = (0, qdot_a)``.

**Efforts.**  A serial limb ``k`` joining the ground to the output link exerts on the output
link a wrench ``W_k`` that does no work on its passive joint twists and, on its actuated twist
``$_j``, ``W_k . $_j = tau_j`` (the actuator's force, or torque, along its freedom).  So
``W_k`` is ``tau_j a_j`` plus a combination of the limb's constraint wrenches, and the output
link is in equilibrium when::

    sum_i lambda_i c_i + sum_j tau_j a_j + F = 0,    i.e.  W^T (lambda ; tau) = -F,

``W`` the wrenches of ``J`` (one per row).  Then for every motion the mechanism can make,
``sum_j tau_j qdot_j = (lambda ; tau) . J $p = -F . $p``: the actuators' power cancels the
external wrench's (virtual work).  ``tau`` is a *force* for a prismatic freedom and a *torque*
for a revolute (or helical) one, in the units of ``F``'s force (newtons: SI) times the model's
length unit where a torque.

The system is solved in nondimensional coordinates (force ; moment / L), each wrench
normalised, by an SVD truncated at the ``singular`` tolerance
(:mod:`~spatialmech.geometry.tolerances`, the threshold of the complete Jacobian's
``singular`` flag):

- *singular* (``sigma_min`` below it: a direct or constraint singularity, or fewer actuation and
  constraint wrenches than six): the least-squares efforts; the external wrench's part along the
  lost direction cannot be balanced (:attr:`Statics.residual`), and :attr:`Statics.unbalanced_wrench`
  says which wrench that is (the left singular vector of the smallest singular value, a wrench
  ``(f ; m)`` with ``|f|^2 + |m / L|^2 = 1``, its largest nondimensional component positive);
- *redundant* (more actuation wrenches than the constraints leave to balance:
  ``n_actuators + rank(constraints) > 6``): among the efforts that balance ``F`` those of the
  least norm (torques divided by ``L``), then the least constraint intensities;
- *indeterminate* (overconstrained: dependent constraint wrenches): the efforts are unique but
  the share of the constraint wrenches between the limbs is not: the least-norm intensities.

**Reactions.**  For a limb that is a serial chain from the ground to the output link, every
joint transmits the same wrench ``W_k`` (massless links): the wrench its proximal body (towards
the ground) exerts on its distal body.  A joint's reaction is ``W_k`` without the efforts along
its actuated freedoms (a torque about a revolute axis, a force along a prismatic axis through the
joint's point): ``W_k - sum_f tau_f eta_f`` with ``eta_f . $_g = delta_fg`` over the joint's
freedoms, so the reaction is reciprocal to every freedom of the joint (it does no work).
**Graph mechanisms** (internal bodies, limbs between any two hubs, reversed joints: the Delta's
parallelograms, the spatial six-bar): the efforts, the wrench each limb exerts on its tip link and
the joint reactions come from the virtual-power balance at rest of
:func:`spatialmech.analysis.dynamics.inverse_dynamics` (massless links, the loads as given): the
same equilibrium written in the loop closures' multipliers, with the same minimum-norm rule for
redundant actuation.  A joint of a limb transmits the limb's wrench on its tip link plus what the
limb's links beyond it need (``-load``); its reaction is that minus the efforts along its
freedoms, as for serial limbs.  The flags (singular, ``unbalanced_wrench``, ``residual`` of the
external wrench alone) come from the complete Jacobian as above.

**Loads on the links** (``loads``: a wrench on each named link, e.g. its weight, see
:func:`spatialmech.analysis.dynamics.gravity_loads`), for limbs from the ground to the output link.
A load on the output link adds to ``F``.  In limb ``k`` a joint now transmits ``W_k`` plus
``D_j``, the sum of ``-load`` over the limb's links beyond it, so ``W_k . $_f = tau_f - D_j . $_f``:
``W_k = P0_k + (tau a + lambda c)`` with ``P0_k . $_f = -D_j . $_f`` for every freedom (a least-squares
solve over the limb's twists; a residual means the loads drive a motion no actuator holds, e.g. a
weight off an SPS leg's line spinning the leg, and is reported).  The platform's balance is then
the massless one against ``F + load_output + sum_k P0_k``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry import screws as sc
from ..geometry.tolerances import current
from ..kinematics.closure import Configuration, chain_forward, joint_twists, limb_chains, limb_slices
from ..kinematics.jacobian import CompleteJacobian, complete_jacobian
from ..model.mechanism import GROUND, Mechanism

__all__ = ["JointReaction", "Statics", "joint_reactions", "statics", "unbalanced_direction"]


@dataclass(frozen=True, eq=False)
class JointReaction:
    """The reaction of one joint of a serial limb: the wrench ``(f ; m)`` (``m`` about the origin)
    that the joint's proximal body exerts on its distal body, without the actuator efforts along
    its freedoms (reciprocal to every freedom of the joint)."""

    limb: str
    joint: str
    point: np.ndarray  # (3,) the joint's centre / reference point at the configuration (length)
    wrench: np.ndarray  # (6,) (f ; m about the origin)
    efforts: dict[str, float]  # actuated freedoms of this joint -> their effort (N or N length)

    @property
    def force(self) -> np.ndarray:
        return self.wrench[:3]

    @property
    def moment_at_point(self) -> np.ndarray:
        """The reaction's moment about the joint's point: ``m - point x f``."""
        return self.wrench[3:] - np.cross(self.point, self.wrench[:3])


@dataclass(frozen=True, eq=False)
class Statics:
    """The static equilibrium of a mechanism at one configuration (see the module docstring)."""

    wrench: np.ndarray  # (6,) the external wrench on the output link, (f ; m about the origin)
    actuators: tuple[str, ...]  # freedom ids, in the order of ``efforts``
    kinds: tuple[str, ...]  # per actuator "force" (P) or "torque" (R, H)
    efforts: np.ndarray  # (n_a,) force (P) or torque (R, H) of each actuator
    constraint_limbs: tuple[int, ...]  # limb index of each constraint wrench (-1: graph elimination)
    constraint_intensities: np.ndarray  # (n_c,) intensity of each unit (nondimensional) constraint wrench, force units
    constraint_wrenches: np.ndarray  # (n_c, 6) each constraint wrench times its intensity, (f ; m)
    limb_wrenches: np.ndarray | None  # (K, 6) the wrench each limb exerts on the output link; None for graphs
    reactions: tuple[JointReaction, ...]
    residual: np.ndarray  # (6,) F + W^T x: the part of F left unbalanced (0 when balanced)
    balanced: bool
    singular: bool
    redundant: bool
    indeterminate: bool
    sigma_min: float
    unbalanced_wrench: np.ndarray | None  # (6,) the wrench direction that cannot be balanced (when singular)
    jacobian: CompleteJacobian
    notes: tuple[str, ...] = ()
    loads: dict[str, np.ndarray] | None = None  # wrench (f ; m about the origin) on each loaded link

    @property
    def by_actuator(self) -> dict[str, float]:
        """Effort of each actuator (force for P, torque for R/H), by freedom id."""
        return {a: float(t) for a, t in zip(self.actuators, self.efforts, strict=True)}


def _effort_scale(mech: Mechanism, act: str) -> float:
    """Factor that makes an effort nondimensional-comparable: 1 for a force, 1/L for a torque."""
    return 1.0 if mech.freedom(act).freedom.kind == "P" else 1.0 / mech.characteristic_length


def unbalanced_direction(u_nd: np.ndarray, L: float) -> np.ndarray:
    """A nondimensional unit wrench direction as a wrench ``(f ; m)``, its sign fixed so that the
    largest-magnitude nondimensional component is positive (deterministic)."""
    u = np.asarray(u_nd, float).copy()
    u /= np.linalg.norm(u)
    k = int(np.argmax(np.abs(u)))
    if u[k] < 0:
        u = -u
    out = u.copy()
    out[3:] *= L
    return out


def _null(A: np.ndarray, rtol: float) -> np.ndarray:
    """Orthonormal basis (columns) of the null space of ``A``, at the relative tolerance ``rtol``."""
    if A.shape[1] == 0:
        return np.zeros((0, 0))
    _, s, vt = np.linalg.svd(A, full_matrices=True)
    r = int(np.sum(s > rtol * max(1.0, float(s[0]) if s.size else 0.0)))
    return vt[r:].T


def _lstsq(A: np.ndarray, b: np.ndarray, rtol: float) -> np.ndarray:
    """Minimum-norm least squares ``A z ~ b`` with singular values below ``rtol * max(1, s_max)``
    dropped (an absolute floor: a block of round-off does not count as a direction)."""
    u, s, vt = np.linalg.svd(A, full_matrices=False)
    r = int(np.sum(s > rtol * max(1.0, float(s[0]) if s.size else 0.0)))
    return vt[:r].T @ ((u[:, :r].T @ b) / s[:r])


def _limb_transfer(mech: Mechanism, config: Configuration, loads: dict[str, np.ndarray]
                   ) -> tuple[np.ndarray, list[np.ndarray], float]:
    """Per limb ``P0_k`` and the per-joint distal sums ``D_j`` of the loads (module docstring), and
    the largest relative residual of the ``P0_k`` solves."""
    L = mech.characteristic_length
    twists = joint_twists(mech, config)
    P0 = np.zeros((len(mech.limbs), 6))
    distal = []
    worst = 0.0
    for k, limb in enumerate(mech.limbs):
        n = len(limb.joints)
        D = np.zeros((n, 6))
        for j in range(n - 2, -1, -1):
            D[j] = D[j + 1] - loads.get(limb.link_names[j], np.zeros(6))
        distal.append(D)
        joint_of = [j for j, joint in enumerate(limb.joints) for _ in joint.freedoms]
        S = twists[k]
        rhs = -np.array([float(sc.reciprocal_product(S[:, f], D[joint_of[f]])) for f in range(S.shape[1])]) / L
        rows = np.hstack([S[3:].T / L, S[:3].T])  # . (f ; m / L)
        z, *_ = np.linalg.lstsq(rows, rhs, rcond=None)
        if np.any(rhs):
            worst = max(worst, float(np.linalg.norm(rows @ z - rhs) / np.linalg.norm(rhs)))
        P0[k] = np.r_[z[:3], z[3:] * L]
    return P0, distal, worst


def statics(mech: Mechanism, config: Configuration, wrench, drivers=None, loads=None) -> Statics:
    """Actuator efforts, constraint-wrench intensities and joint reactions that hold ``mech`` at
    ``config`` against the external ``wrench`` ``(f ; m)`` on its output link (``m`` about the
    origin; SI force, moment in force times the model's length unit).

    ``drivers``: the actuated freedoms (default: the mechanism's actuators).  Raises
    :class:`~spatialmech.errors.InputError` for a wrench that is not 6 finite numbers or a
    mechanism with no actuator.  ``loads``: wrenches on links by name (module docstring).
    """
    F_given = np.asarray(wrench, dtype=float)
    if F_given.shape != (6,) or not np.all(np.isfinite(F_given)):
        raise InputError(f"wrench: expected 6 finite numbers (fx, fy, fz ; mx, my, mz), got shape {F_given.shape}")
    F = F_given
    P0, distal, transfer_residual = None, None, 0.0
    serial = _serial_limbs(mech)
    if loads and serial:
        P0, distal, transfer_residual = _limb_transfer(mech, config, loads)
        F = F_given + loads.get(mech.output, np.zeros(6)) + P0.sum(axis=0)
    J = complete_jacobian(mech, config, drivers)
    acts = J.actuators
    if not acts:
        raise InputError(f"drivers: {mech.name} has no actuators; name the actuated freedoms")
    L = mech.characteristic_length
    tol = current()
    W = J.wrenches  # (n, 6): constraint rows, then actuation rows
    n_c = J.constraint_rows
    n = W.shape[0]
    Wn = sc.nondimensional(W, L)
    norms = np.linalg.norm(Wn, axis=1)
    live = norms > 0  # an inverse-singular actuator has a zero row
    M = np.zeros((6, n))
    M[:, live] = (Wn[live] / norms[live, None]).T
    Fn = sc.nondimensional(F, L)
    # truncated SVD at the `singular` tolerance: the threshold of the complete Jacobian's flag
    U, s, vt = np.linalg.svd(M, full_matrices=True)
    r = int(np.sum(s > tol.singular))  # as CompleteJacobian.singular: absolute, the columns are unit
    y = -(vt[:r].T @ ((U[:, :r].T @ Fn) / s[:r]))
    N = vt[r:].T  # (n, n - r): intensities that balance nothing (to the singular tolerance)
    # redundancy: the least effort norm (torques / L), then the least constraint intensities
    D = np.array([_effort_scale(mech, a) for a in acts]) / np.where(live[n_c:], norms[n_c:], 1.0)
    if N.shape[1]:
        NA = D[:, None] * N[n_c:]
        z = _lstsq(NA, -D * y[n_c:], tol.rank)
        y = y + N @ z
        N2 = N @ _null(NA, tol.rank)
        if N2.shape[1] and n_c:
            z2 = _lstsq(N2[:n_c], -y[:n_c], tol.rank)
            y = y + N2 @ z2
        # a direction counts when its norm is above the rank tolerance (the floor of _lstsq)
        effort_free = bool(NA.size and np.linalg.norm(NA, 2) > tol.rank)
        indeterminate = bool(N2.shape[1] and n_c and np.linalg.norm(N2[:n_c], 2) > tol.rank)
    else:
        effort_free, indeterminate = False, False
    x = np.where(live, y / np.where(live, norms, 1.0), 0.0)  # intensities of the rows of W
    residual = F + W.T @ x
    Rn = sc.nondimensional(residual, L)
    balanced = bool(np.linalg.norm(Rn) <= tol.rank * max(float(np.linalg.norm(Fn)), 1e-300) or not np.any(Fn))
    singular = bool(r < 6)
    sigma = J.sigma_min
    rank_c = sc.rank(W[:n_c], length_scale=L) if n_c else 0
    n_live = int(live[n_c:].sum())
    redundant = bool(n_live + rank_c > 6)
    unbalanced = unbalanced_direction(U[:, 5], L) if singular else None
    efforts = x[n_c:].copy()
    notes = _notes(J, singular, balanced, redundant, effort_free, indeterminate, n_live, rank_c)
    # per limb: the wrench it exerts on the output link, and the reactions of its joints
    limb_w: np.ndarray | None = None
    reactions: tuple[JointReaction, ...] = ()
    balanced = balanced and transfer_residual <= tol.rank
    if not serial:
        efforts, limb_w, reactions, balance_residual = _graph_balance(mech, config, F_given, drivers, loads)
        balanced = bool(balanced and balance_residual <= tol.rank)
        notes.append("a graph mechanism: the efforts and the joint reactions from the balance of the loop closures at rest"
                     + (f" (relative residual {balance_residual:.2e}: not balanced)" if balance_residual > tol.rank else ""))
        if loads:
            notes.append("residual and unbalanced_wrench: of the external wrench alone (the loads on the links are in "
                         "the efforts and reactions)")
    else:
        act_limb = [mech.freedom(a).limb for a in acts]
        limb_w = np.zeros((len(mech.limbs), 6))
        for i in range(n_c):
            limb_w[J.constraint_limbs[i]] += x[i] * W[i]
        for j, k in enumerate(act_limb):
            limb_w[k] += x[n_c + j] * W[n_c + j]
        if P0 is not None:
            limb_w += P0
        reactions = joint_reactions(mech, config, limb_w, dict(zip(acts, efforts, strict=True)), distal)
    if transfer_residual > tol.rank:
        notes.append(f"the loads on the limbs' links drive a motion no actuator holds (relative residual "
                     f"{transfer_residual:.2e}, e.g. a weight off an SPS leg's line spinning the leg): not balanced")
    kinds = tuple("force" if mech.freedom(a).freedom.kind == "P" else "torque" for a in acts)
    return Statics(F_given, acts, kinds, efforts, tuple(J.constraint_limbs[:n_c]), y[:n_c].copy(),
                   x[:n_c, None] * W[:n_c], limb_w, reactions, residual, balanced,
                   singular, redundant, indeterminate, float(sigma), unbalanced, J, tuple(notes),
                   None if not loads else dict(loads))


def _graph_balance(mech: Mechanism, config: Configuration, F: np.ndarray, drivers, loads
                   ) -> tuple[np.ndarray, np.ndarray, tuple[JointReaction, ...], float]:
    """Efforts, limb wrenches (on each limb's tip link), joint reactions and the relative residual
    of the balance at rest of a graph mechanism (module docstring)."""
    from .dynamics import distal_wrenches, inverse_dynamics, rest_state

    d = inverse_dynamics(mech, rest_state(mech, config), {}, np.zeros(3), F, drivers, loads=loads)
    reactions = joint_reactions(mech, config, d.limb_wrenches, d.by_actuator, distal_wrenches(mech, d))
    return d.efforts.copy(), d.limb_wrenches, reactions, d.residual


def _notes(J: CompleteJacobian, singular: bool, balanced: bool, redundant: bool, effort_free: bool,
           indeterminate: bool, n_live: int, rank_c: int) -> list[str]:
    """What the flags of :func:`statics` mean for its answer, in words."""
    notes: list[str] = []
    if J.inverse_singular:
        notes.append(f"inverse (serial) singular for {', '.join(J.inverse_singular)}: its actuation wrench does not "
                     "exist here; that actuator cannot carry a load (effort 0)")
    if singular:
        notes.append("singular: the actuation and constraint wrenches span less than 6 directions; the efforts are "
                     "the least-squares ones and the external wrench's component along unbalanced_wrench is not balanced"
                     + ("" if balanced else " (residual)"))
    if redundant:
        notes.append(f"redundant actuation: {n_live} actuation wrenches where {6 - rank_c} suffice; the efforts are the "
                     "minimum-norm ones (torques divided by the characteristic length)")
    elif effort_free and not singular:
        notes.append("the efforts are not unique here; the minimum-norm ones are given")
    if indeterminate:
        notes.append("overconstrained: the constraint wrenches are dependent; their share between the limbs (and the "
                     "joint reactions) is statically indeterminate: the minimum-norm intensities are given")
    return notes


def _serial_limbs(mech: Mechanism) -> bool:
    """Every limb a serial chain from the ground to the output link, joints in its direction."""
    return not mech.bodies and not any(
        limb.base != GROUND or mech.limb_tip(limb) != mech.output or any(j.reversed for j in limb.joints)
        for limb in mech.limbs)


def joint_reactions(mech: Mechanism, config: Configuration, limb_w: np.ndarray, efforts: dict[str, float],
                    distal: list[np.ndarray] | None = None) -> tuple[JointReaction, ...]:
    """Every joint's reaction: the wrench limb ``k`` exerts on its tip link ``limb_w[k]``, plus
    (``distal[k][j]``) what joint ``j`` carries for the limb's links beyond it, without the actuator
    ``efforts`` along the joint's freedoms.  The reaction is the wrench of the joint's body towards
    the limb's base on its body towards the limb's tip."""
    twists = joint_twists(mech, config)
    out = []
    for k, (limb, ch, sl) in enumerate(zip(mech.limbs, limb_chains(mech), limb_slices(mech), strict=True)):
        _, _, pre = chain_forward(ch, config.q[sl], prefixes=True, local=True)
        base = config.hub(mech.limb_ends[k][0])
        T = twists[k]
        i = 0
        for jj, joint in enumerate(limb.joints):
            m = len(joint.freedoms)
            P = base @ pre[i]
            c = P[:3, :3] @ joint.point + P[:3, 3]
            ids = [f"{joint.name}.{f.name}" for f in joint.freedoms]
            tau = {fid: float(efforts[fid]) for fid in ids if fid in efforts}
            w = limb_w[k].copy() if distal is None else limb_w[k] + distal[k][jj]
            if tau:
                S = T[:, i : i + m].T  # (m, 6) the joint's current twists
                E = np.array([np.r_[S[g, 3:], np.cross(c, S[g, 3:])] if joint.freedoms[g].kind == "P"
                              else np.r_[np.zeros(3), S[g, :3]] for g in range(m)])
                G = np.array([[float(sc.reciprocal_product(E[f], S[g])) for g in range(m)] for f in range(m)])
                eta = np.linalg.solve(G, E)  # eta_f . $_g = delta_fg
                for g, fid in enumerate(ids):
                    if fid in tau:
                        w = w - tau[fid] * eta[g]
            out.append(JointReaction(limb.name, joint.name, c, w, tau))
            i += m
    return tuple(out)
