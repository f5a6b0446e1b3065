"""Accuracy: the output pose error produced by actuator errors, joint clearances and manufacturing
tolerances of the geometric parameters (issue 28; docs/accuracy.md).

The error model (SI units, radians):

- **Actuator errors**: each actuator's joint variable is off by up to ``actuator`` (its own unit:
  m for a slide, rad for a rotation).
- **Geometric parameters** (manufacturing tolerances): every joint's *point* (3 components, up
  to ``point`` m each; not for a joint made of slides only, whose point means nothing) and the
  *axis* of every single-axis joint (R, P, H, C: two small rotations about the joint's point, about
  two directions perpendicular to the axis, up to ``axis`` rad each).  The axes of U and S joints
  are not varied (an S joint's axes are only coordinates; a U joint's perpendicular axes are a
  model invariant).  The model is the product of exponentials at the reference configuration:
  a perturbed model is the same chains with their joint points and axes displaced *at the
  reference*, the joint variables keeping their meaning (the actuators zeroed at the reference:
  a home calibration).  Geometric errors therefore do not move the platform at the reference
  configuration, and grow away from it.
- **Clearances**: every passive joint (no actuated freedom) has play: its outboard link may be
  displaced relative to its inboard link by a small translation, up to ``clearance`` m along each
  world axis, at the configuration analysed (radial and axial play of a pin or a ball; tilting
  play is not modelled).  Play is a small displacement by nature: it enters every estimate,
  Monte-Carlo included, through its first-order effect.

Three estimates of the output error -- the translation of the output point (the platform point
``D p0``, m) and the rotation (a rotation vector, rad, world frame):

1. **First order**: the output error is ``G e`` for the parameter errors ``e``.  ``G`` comes from
   the complete Jacobian: a limb's closure ``FK_k(q; pi) = D`` perturbed gives
   ``J_k dq_k + s_k = dD`` (spatial twists); the limb's constraint wrenches and its actuation
   wrench (reciprocal to its passive twists, ``a o $_a = 1``) remove the passive ``dq``:
   ``M dD = (c o s_k ; e_a + a o s_k)``.  The error twist of a joint parameter is the screw
   derivative of the product of exponentials: displacing a joint by the small screw motion ``eta``
   (a translation ``(0 ; dr)`` of its point, or a rotation ``(phi ; r x phi)`` of its axis about
   its point) conjugates its exponentials, ``s = Ad(P_before) eta - Ad(P_through) eta``, with
   ``P_before`` / ``P_through`` the limb's displacement before / after the joint's freedoms.  A
   clearance translation ``dt`` is the twist ``(0 ; dt)``.  The test checks ``G`` against central
   finite differences of the exact forward position of perturbed models.
2. **Worst case** over the tolerance box: for each output component, ``sum_i |G_ci| t_i``
   (exact for the linearisation: a linear function's maximum over a box is at the vertex
   ``t sign(G_c)``); the vertex is kept, and the exact model is evaluated there.
3. **Monte-Carlo**: parameters uniform in the box (seeded), each sample's model re-assembled from
   the nominal configuration by the forward solver (Gauss-Newton with the actuators held,
   :func:`..kinematics.backend.correct`); samples that do not converge are counted as failures.
   First-order covariance for comparison: ``G diag(t^2 / 3) G^T`` (uniform errors).

**Overconstrained designs** (a Bennett linkage, a spherical 3-RRR): their mobility rests on special
geometry, so generic tolerances remove it.  :func:`mobility_breakdown` perturbs the geometric
parameters along one seeded direction of the tolerance box, scaled by ``k``, and finds by
bisection on ``log k`` the smallest scale at which the *numerical instantaneous mobility* of the
perturbed model at its reference configuration (the closure Jacobian's nullity at the ``rank``
tolerance, nondimensional) drops.  Mathematically any generic error breaks such a design; the
scale found is where the lost freedom's singular value passes the rank tolerance, so it is also
reported as a rate (``sigma / k``, scale-free).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import InputError
from ..geometry.rotations import matrix_rotvec, rotvec_matrix
from ..geometry.screws import adjoint
from ..geometry.tolerances import current
from ..kinematics import backend
from ..kinematics.closure import (
    Configuration,
    active_mask,
    chain_forward,
    closure_jacobian,
    closure_scales,
    hub_count,
    limb_chains,
    limb_slices,
)
from ..kinematics.jacobian import complete_jacobian
from ..model.mechanism import Mechanism

__all__ = ["AccuracyAnalysis", "ErrorBudget", "MobilityBreakdown", "Parameter", "accuracy_analysis", "error_parameters",
           "instantaneous_dof", "mobility_breakdown", "perturbed", "sensitivity"]

#: Output components, in the order of the rows of the sensitivity matrix.
COMPONENTS = ("dx_m", "dy_m", "dz_m", "rx_rad", "ry_rad", "rz_rad")


@dataclass(frozen=True)
class ErrorBudget:
    """Half-widths of the tolerance box: ``actuator`` (each actuator's own unit, m or rad; a number
    or a mapping by actuator name), ``clearance`` (m, per passive joint and world axis), ``point``
    (m, per joint point component) and ``axis`` (rad, per axis rotation; ``None``: ``point / L``,
    the rotation that moves a point one characteristic length away by ``point``)."""

    actuator: float | Mapping[str, float] = 0.0
    clearance: float = 0.0
    point: float = 0.0
    axis: float | None = None


@dataclass(frozen=True)
class Parameter:
    """One error source: ``kind`` ``actuator``, ``clearance``, ``point`` or ``axis``; ``name``
    (e.g. ``"A1.point.y"``, ``"R1.axis.1"``, ``"L1.slide"``, ``"B1.clearance.x"``); its limb, joint
    and freedom indices; ``tolerance`` (half-width, SI); ``direction``: the unit displacement
    (point, clearance: a 3-vector; axis: the rotation axis)."""

    name: str
    kind: str
    unit: str
    tolerance: float
    limb: int
    joint: int = -1
    freedom: int = -1  # global index of an actuator's freedom
    direction: np.ndarray = field(default_factory=lambda: np.zeros(3))


def _perpendiculars(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors perpendicular to ``d`` and each other (deterministic: from the world axis
    least aligned with ``d``)."""
    d = d / np.linalg.norm(d)
    e = np.eye(3)[int(np.argmin(np.abs(d)))]
    a = np.cross(d, e)
    a /= np.linalg.norm(a)
    return a, np.cross(d, a)


def _budget_value(b: ErrorBudget, mech: Mechanism, name: str) -> float:
    if isinstance(b.actuator, Mapping):
        ids = {mech.freedom(k).id: float(v) for k, v in b.actuator.items()}
        return ids.get(name, 0.0)
    return float(b.actuator)


def error_parameters(mech: Mechanism, budget: ErrorBudget) -> list[Parameter]:
    """Every error source of ``mech`` with its tolerance (see the module docstring); sources with
    a zero tolerance are left out."""
    axis_tol = budget.point / mech.characteristic_length if budget.axis is None else float(budget.axis)
    refs = mech.freedom_refs
    out: list[Parameter] = []
    for a in mech.actuators:
        r = mech.freedom(a)
        t = _budget_value(budget, mech, a)
        if t > 0:
            unit = "m" if r.freedom.kind == "P" else "rad"
            out.append(Parameter(a, "actuator", unit, t, r.limb, r.joint, refs.index(r)))
    for k, limb in enumerate(mech.limbs):
        for j, joint in enumerate(limb.joints):
            live = [f for f in joint.freedoms if not f.locked]
            if not live:
                continue
            if budget.point > 0 and any(f.kind != "P" for f in joint.freedoms):
                for c, ax in enumerate("xyz"):
                    out.append(Parameter(f"{joint.name}.point.{ax}", "point", "m", budget.point, k, j,
                                         direction=np.eye(3)[c]))
            if axis_tol > 0 and joint.type in ("R", "P", "H", "C"):
                for c, e in enumerate(_perpendiculars(joint.freedoms[0].direction), start=1):
                    out.append(Parameter(f"{joint.name}.axis.{c}", "axis", "rad", axis_tol, k, j, direction=e))
            if budget.clearance > 0 and not any(f.actuated for f in joint.freedoms):
                for c, ax in enumerate("xyz"):
                    out.append(Parameter(f"{joint.name}.clearance.{ax}", "clearance", "m", budget.clearance, k, j,
                                         direction=np.eye(3)[c]))
    return out


# ------------------------------------------------------------------------------ exact perturbed models
def _perturb_joint(joint, shift: np.ndarray, rot: np.ndarray):
    """The joint moved by ``shift`` and its axes rotated by the rotation vector ``rot`` about its point."""
    Rm = rotvec_matrix(rot)
    c = joint.point
    fs = tuple(replace(f, point=c + shift + Rm @ (f.point - c), direction=Rm @ f.direction) for f in joint.freedoms)
    return replace(joint, point=c + shift, freedoms=fs)


def perturbed(mech: Mechanism, params: list[Parameter], values) -> Mechanism:
    """The model with the geometric errors ``values`` (one per parameter; actuator and clearance
    entries are ignored here) applied at the reference configuration."""
    shifts: dict[tuple[int, int], np.ndarray] = {}
    rots: dict[tuple[int, int], np.ndarray] = {}
    for p, v in zip(params, values, strict=True):
        key = (p.limb, p.joint)
        if p.kind == "point":
            shifts[key] = shifts.get(key, np.zeros(3)) + v * p.direction
        elif p.kind == "axis":
            rots[key] = rots.get(key, np.zeros(3)) + v * p.direction
    if not shifts and not rots:
        return mech
    limbs = []
    for k, limb in enumerate(mech.limbs):
        joints = tuple(_perturb_joint(jt, shifts.get((k, j), np.zeros(3)), rots.get((k, j), np.zeros(3)))
                       if (k, j) in shifts or (k, j) in rots else jt for j, jt in enumerate(limb.joints))
        limbs.append(limb.with_joints(joints))
    return replace(mech, limbs=tuple(limbs))


def output_error(config: Configuration, nominal: Configuration, p0: np.ndarray) -> np.ndarray:
    """``(dp ; dtheta)`` of the output point and the rotation vector of ``R' R^T`` (world frame)."""

    D, D0 = config.D, nominal.D
    dp = (D[:3, :3] @ p0 + D[:3, 3]) - (D0[:3, :3] @ p0 + D0[:3, 3])
    return np.concatenate([dp, matrix_rotvec(D[:3, :3] @ D0[:3, :3].T)])


def assemble(mech: Mechanism, nominal: Configuration, act_errors: dict[int, float], max_iter: int = 50):
    """The perturbed model ``mech`` re-assembled from the nominal configuration with the actuators
    held at their nominal values plus ``act_errors`` (by global freedom index): the forward
    solver's Gauss-Newton (:func:`..kinematics.backend.correct`)."""
    q = nominal.q.copy()
    for i, e in act_errors.items():
        q[i] += e
    mask = active_mask(mech)
    for i in (mech.freedom_refs.index(mech.freedom(a)) for a in mech.actuators):
        mask[i] = False
    return backend.correct(mech, nominal.with_q(q), active=mask, max_iter=max_iter)


# ------------------------------------------------------------------------------ first order
def _joint_ranges(mech: Mechanism, k: int) -> list[tuple[int, int]]:
    out, i = [], 0
    for jt in mech.limbs[k].joints:
        out.append((i, i + len(jt.freedoms)))
        i += len(jt.freedoms)
    return out


def _source_twists(mech: Mechanism, config: Configuration, params: list[Parameter]) -> np.ndarray:
    """(6, n) spatial error twist of each geometric or clearance parameter (zero for actuators)."""
    S = np.zeros((6, len(params)))
    cache: dict[int, tuple] = {}
    for i, p in enumerate(params):
        if p.kind == "actuator":
            continue
        if p.kind == "clearance":
            S[3:, i] = p.direction
            continue
        if p.limb not in cache:
            sl = limb_slices(mech)[p.limb]
            T, _, pre = chain_forward(limb_chains(mech)[p.limb], config.q[sl], prefixes=True)
            cache[p.limb] = (T, pre, _joint_ranges(mech, p.limb))
        T, pre, ranges = cache[p.limb]
        a, b = ranges[p.joint]
        before = pre[a]
        through = pre[b] if b < len(pre) else T
        r = mech.limbs[p.limb].joints[p.joint].point
        eta = np.concatenate([np.zeros(3), p.direction]) if p.kind == "point" else \
            np.concatenate([p.direction, np.cross(r, p.direction)])
        # the limb's chain is placed on its base hub (identity for the ground)
        S[:, i] = adjoint(config.hub(mech.limb_ends[p.limb][0])) @ (adjoint(before) @ eta - adjoint(through) @ eta)
    return S


def sensitivity(mech: Mechanism, config: Configuration, params: list[Parameter]) -> tuple[np.ndarray, float, int]:
    """``(G (6, n), inconsistency, rows)``: the first-order output error ``(dp ; dtheta)`` per unit
    error of each parameter, at a closed configuration, from the complete Jacobian.
    ``inconsistency``: the largest relative residual of the least-squares solve when the complete
    Jacobian has more than 6 rows (redundant constraints: the errors cannot all be absorbed, the
    perturbed design deforms or does not assemble), 0 otherwise."""
    if mech.bodies:
        return _closure_sensitivity(mech, config, params)
    jac = complete_jacobian(mech, config)
    M = jac.matrix
    if jac.inverse_singular:
        raise InputError(f"{mech.name}: inverse singular here (no actuation wrench for {', '.join(jac.inverse_singular)})")
    rows_limb = list(jac.constraint_limbs) + [mech.freedom(a).limb for a in jac.actuators]
    act_row = {mech.freedom_refs.index(mech.freedom(a)): jac.constraint_rows + i for i, a in enumerate(jac.actuators)}
    S = _source_twists(mech, config, params)
    rhs = np.zeros((M.shape[0], len(params)))
    for i, p in enumerate(params):
        if p.kind == "actuator":
            rhs[act_row[p.freedom], i] = 1.0
            continue
        for r, k in enumerate(rows_limb):
            if k == p.limb:
                rhs[r, i] = M[r] @ S[:, i]
    L = mech.characteristic_length
    scale = np.concatenate([np.full(3, 1.0), np.full(3, L)])  # solve for (omega ; v / L): scale-free
    Ms = M * scale[None, :]
    if Ms.shape[0] < 6 or jac.sigma_min < current().singular:
        raise InputError(f"{mech.name}: the complete Jacobian is singular here (scale-free sigma_min "
                         f"{jac.sigma_min:.3g} < {current().singular:g}, or fewer constraint and actuation wrenches "
                         "than 6): the output error is not determined")
    X, *_ = np.linalg.lstsq(Ms, rhs, rcond=None)
    inconsistency = 0.0
    if Ms.shape[0] > 6:
        res = Ms @ X - rhs
        big = np.maximum(np.linalg.norm(rhs, axis=0), 1e-300)
        inconsistency = float(np.max(np.linalg.norm(res, axis=0) / big)) if len(params) else 0.0
    tw = X * scale[:, None]  # (omega ; v) at the origin
    p_out = config.D[:3, :3] @ mech.platform_point + config.D[:3, 3]
    G = np.empty_like(tw)
    G[3:] = tw[:3]
    G[:3] = tw[3:] + np.cross(tw[:3].T, p_out).T
    return G, inconsistency, int(M.shape[0])


def _closure_sensitivity(mech: Mechanism, config: Configuration, params: list[Parameter]) -> tuple[np.ndarray, float, int]:
    """:func:`sensitivity` for a graph mechanism (internal bodies), from the loop closures: per
    limb ``V_base + J_k dq_k + s_k - V_tip = 0`` with the actuators' ``dq`` the actuator errors,
    solved (nondimensional least squares) for the passive rates and the hubs' twists; the output
    link's twist is the error.  Raises :class:`InputError` where the actuators do not determine it
    (a direct singularity)."""
    active = active_mask(mech)
    A, _ = closure_jacobian(mech, config, active=active)
    row, col = closure_scales(mech, active)
    pos = np.cumsum(active) - 1
    acts = [int(pos[mech.freedom_refs.index(mech.freedom(a))]) for a in mech.actuators]
    nx = A.shape[1]
    B = np.zeros((len(acts), nx))
    B[np.arange(len(acts)), acts] = 1.0
    M = np.vstack([row[:, None] * A * col[None, :], B])
    S = _source_twists(mech, config, params)
    rhs = np.zeros((M.shape[0], len(params)))
    for i, p in enumerate(params):
        if p.kind == "actuator":
            rhs[A.shape[0] + acts.index(int(pos[p.freedom])), i] = 1.0 / col[int(pos[p.freedom])]
        else:
            rhs[6 * p.limb : 6 * p.limb + 6, i] = -row[6 * p.limb : 6 * p.limb + 6] * S[:, i]
    _, sv, vt = np.linalg.svd(M)
    rank = int(np.sum(sv > current().rank * max(1.0, float(sv[0]))))
    n_q = int(active.sum())
    if vt[rank:].size and np.max(np.abs(vt[rank:, n_q : n_q + 6])) > 1e-7:
        raise InputError(f"{mech.name}: a direct singularity here: the actuators do not determine the output link's "
                         "motion, so the output error is not determined")
    X, *_ = np.linalg.lstsq(M, rhs, rcond=None)
    res = M @ X - rhs
    big = np.maximum(np.linalg.norm(rhs, axis=0), 1e-300)
    inconsistency = float(np.max(np.linalg.norm(res, axis=0) / big)) if len(params) else 0.0
    tw = X[n_q : n_q + 6] * col[n_q : n_q + 6, None]  # (omega ; v) at the origin
    p_out = config.D[:3, :3] @ mech.platform_point + config.D[:3, 3]
    G = np.empty_like(tw)
    G[3:] = tw[:3]
    G[:3] = tw[3:] + np.cross(tw[:3].T, p_out).T
    return G, inconsistency, int(M.shape[0])


# ------------------------------------------------------------------------------ mobility under tolerances
def _reference_closure(mech: Mechanism, params: list[Parameter], values) -> np.ndarray:
    """The nondimensional closure Jacobian at the reference configuration of ``mech`` with the
    geometric errors ``values``, from the perturbed joints' screws (at ``q = 0`` a freedom's twist
    is its reference screw), scaled with the *nominal* characteristic length (a perturbed
    spherical model would otherwise get the spread of its joint points as its length)."""
    shifts: dict[tuple[int, int], np.ndarray] = {}
    rots: dict[tuple[int, int], np.ndarray] = {}
    for p, v in zip(params, values, strict=True):
        d = shifts if p.kind == "point" else rots if p.kind == "axis" else None
        if d is not None:
            d[(p.limb, p.joint)] = d.get((p.limb, p.joint), np.zeros(3)) + v * p.direction
    active = active_mask(mech)
    n = len(mech.freedom_refs)
    K = len(mech.limbs)
    h = hub_count(mech)
    A = np.zeros((6 * K, n + 6 * h))
    i = 0
    for k, limb in enumerate(mech.limbs):
        for j, jt in enumerate(limb.joints):
            if (k, j) in shifts or (k, j) in rots:
                jt = _perturb_joint(jt, shifts.get((k, j), np.zeros(3)), rots.get((k, j), np.zeros(3)))
            for f in jt.freedoms:
                A[6 * k : 6 * k + 6, i] = f.screw
                i += 1
        a, b = mech.limb_ends[k]  # at the reference every hub is at the identity
        if a is not None:
            A[6 * k : 6 * k + 6, n + 6 * a : n + 6 * a + 6] += np.eye(6)
        if b is not None:
            A[6 * k : 6 * k + 6, n + 6 * b : n + 6 * b + 6] -= np.eye(6)
    row, col = closure_scales(mech, active)
    return row[:, None] * A[:, np.concatenate([active, np.ones(6 * h, bool)])] * col[None, :]


def _dof(As: np.ndarray, mech: Mechanism, rtol: float) -> tuple[int, np.ndarray]:
    """(output-link degrees of freedom, relative singular values) of a nondimensional closure
    Jacobian: its nullity minus the limbs' passive freedoms (columns normalised)."""

    def nullity(B: np.ndarray) -> tuple[int, np.ndarray]:
        nrm = np.linalg.norm(B, axis=0)
        sv = np.linalg.svd(B / np.where(nrm > 0, nrm, 1.0), compute_uv=False)
        big = max(1.0, float(sv[0])) if sv.size else 1.0
        return B.shape[1] - int(np.sum(sv > rtol * big)), sv / big

    total, sv = nullity(As)
    idx = np.flatnonzero(active_mask(mech))
    passive = 0
    for sl in limb_slices(mech):
        cols = [i for i, g in enumerate(idx) if sl.start <= g < sl.stop]
        if cols:
            passive += nullity(As[:, cols])[0]
    return total - passive, sv


def instantaneous_dof(mech: Mechanism, config: Configuration, rtol: float) -> int:
    """Output-link degrees of freedom of ``mech`` at the closed configuration ``config``."""
    active = active_mask(mech)
    A, _ = closure_jacobian(mech, config, active=active)
    row, col = closure_scales(mech, active)
    return _dof(row[:, None] * A * col[None, :], mech, rtol)[0]


@dataclass(frozen=True)
class MobilityBreakdown:
    """Whether generic geometric errors remove degrees of freedom (see the module docstring)."""

    nominal_dof: int
    perturbed_dof: int  # at the largest scale tried
    loses_mobility: bool
    breaks_at_scale: float | None  # smallest k (tolerance box scale) at which the dof drops
    breaks_at_point_m: float | None  # k times the point tolerance
    breaks_at_axis_rad: float | None
    rate: float | None  # the deciding singular value over k, scale-free (any k > 0 breaks it at this rate)
    rank_tolerance: float
    seed: int
    method: str = ("numerical instantaneous mobility of the perturbed model at its reference configuration; "
                   "bisection on log(scale) of one seeded direction of the tolerance box")

    def to_dict(self) -> dict:
        return {"nominal_dof": self.nominal_dof, "perturbed_dof": self.perturbed_dof,
                "loses_mobility": self.loses_mobility, "breaks_at_scale": self.breaks_at_scale,
                "breaks_at_point_m": self.breaks_at_point_m, "breaks_at_axis_rad": self.breaks_at_axis_rad,
                "loss_rate": self.rate, "rank_tolerance": self.rank_tolerance, "seed": self.seed, "method": self.method}


def mobility_breakdown(mech: Mechanism, params: list[Parameter], *, seed: int = 0, k_max: float = 1e3,
                       k_min: float = 1e-12, steps: int = 60) -> MobilityBreakdown:
    """Smallest scale ``k`` of the geometric tolerance box (one seeded direction) at which the
    instantaneous mobility at the reference drops (bisection on ``log k``)."""
    geo = [p for p in params if p.kind in ("point", "axis")]
    rtol = current().rank
    dof0, _ = _dof(_reference_closure(mech, [], []), mech, rtol)
    point_tol = max((p.tolerance for p in geo if p.kind == "point"), default=0.0)
    axis_tol = max((p.tolerance for p in geo if p.kind == "axis"), default=0.0)
    if not geo:
        return MobilityBreakdown(dof0, dof0, False, None, None, None, None, rtol, seed)
    u = np.random.default_rng(seed).uniform(-1.0, 1.0, len(geo)) * np.array([p.tolerance for p in geo])

    def dof_at(k: float) -> tuple[int, np.ndarray]:
        return _dof(_reference_closure(mech, geo, k * u), mech, rtol)

    top, _ = dof_at(k_max)
    if top >= dof0:
        return MobilityBreakdown(dof0, top, False, None, None, None, None, rtol, seed)
    lo, hi = np.log(k_min), np.log(k_max)
    if dof_at(k_min)[0] < dof0:
        hi = lo
    for _ in range(steps):
        if hi - lo < 1e-3:
            break
        mid = 0.5 * (lo + hi)
        if dof_at(float(np.exp(mid)))[0] < dof0:
            hi = mid
        else:
            lo = mid
    k = float(np.exp(hi))
    # the rate: the singular value that left the null space, at a scale above the break, over that scale
    k_rate = min(k_max, 100.0 * k)
    d, sv = dof_at(k_rate)
    full = np.sort(np.concatenate([sv, np.zeros(max(0, _reference_closure(mech, [], []).shape[1] - sv.size))]))
    n_null = int(np.sum(full <= rtol))
    lost = full[min(n_null + (dof0 - d) - 1, full.size - 1)]
    return MobilityBreakdown(dof0, top, True, k, k * point_tol or None, k * axis_tol or None, float(lost) / k_rate,
                             rtol, seed)


# ------------------------------------------------------------------------------ the whole analysis
@dataclass(frozen=True, eq=False)
class AccuracyAnalysis:
    """The three estimates at one configuration (see the module docstring)."""

    params: tuple[Parameter, ...]
    G: np.ndarray  # (6, n): output error (dp m ; dtheta rad) per unit parameter error
    inconsistency: float
    worst_case: np.ndarray  # (6,): sum_i |G_ci| t_i
    worst_vertex: np.ndarray  # (6, n): the box vertex t sign(G_c) of each component
    exact_at_worst: np.ndarray  # (6,): the exact model's component at that vertex (nan: did not assemble)
    std_first_order: np.ndarray  # (6,)
    cov_first_order: np.ndarray  # (6, 6)
    samples: int
    mc_errors: np.ndarray  # (n_ok, 6)
    mc_failures: int
    seed: int
    breakdown: MobilityBreakdown | None
    inconsistent: bool = False  # inconsistency above the rank tolerance: errors the design cannot absorb


def _mc(mech: Mechanism, config: Configuration, params: list[Parameter], G: np.ndarray, n: int, seed: int):
    rng = np.random.default_rng(seed)
    t = np.array([p.tolerance for p in params])
    lin_only = np.array([p.kind == "clearance" for p in params])
    errs, fails = [], 0
    for _ in range(n):
        e = rng.uniform(-1.0, 1.0, len(params)) * t
        res = _exact(mech, config, params, e)
        if res is None:
            fails += 1
            continue
        errs.append(res + G[:, lin_only] @ e[lin_only])
    return np.array(errs).reshape(-1, 6), fails


def _exact(mech: Mechanism, config: Configuration, params: list[Parameter], e: np.ndarray) -> np.ndarray | None:
    """The exact output error of the perturbed model (clearances left out), ``None`` if it does not
    assemble or cannot be built (a spherical model whose perturbed joint points spread less than the
    smallest characteristic length the library accepts)."""
    try:
        pm = perturbed(mech, params, e)
    except InputError:
        return None
    acts = {p.freedom: float(v) for p, v in zip(params, e, strict=True) if p.kind == "actuator"}
    r = assemble(pm, config, acts)
    if not r.converged:
        return None
    return output_error(r.config, config, mech.platform_point)


def accuracy_analysis(mech: Mechanism, config: Configuration, budget: ErrorBudget, *, samples: int = 200,
                      seed: int = 0, breakdown: bool = True) -> AccuracyAnalysis:
    """First order, worst case and Monte-Carlo output errors at the closed configuration ``config``."""
    params = error_parameters(mech, budget)
    if not params:
        raise InputError("tolerances: every tolerance is zero; give an actuator error, a clearance or a geometric tolerance")
    G, inc, _ = sensitivity(mech, config, params)
    t = np.array([p.tolerance for p in params])
    wc = np.abs(G) @ t
    vert = np.sign(G) * t[None, :]
    exact = np.full(6, np.nan)
    lin_only = np.array([p.kind == "clearance" for p in params])
    for c in range(6):
        v = _exact(mech, config, params, vert[c])
        if v is not None:
            exact[c] = v[c] + G[c, lin_only] @ vert[c, lin_only]
    cov = G @ np.diag(t**2 / 3.0) @ G.T
    mc, fails = _mc(mech, config, params, G, samples, seed) if samples else (np.zeros((0, 6)), 0)
    bd = mobility_breakdown(mech, params, seed=seed) if breakdown else None
    return AccuracyAnalysis(tuple(params), G, inc, wc, vert, exact, np.sqrt(np.diag(cov)), cov, samples, mc, fails,
                            seed, bd, inc > current().rank)
