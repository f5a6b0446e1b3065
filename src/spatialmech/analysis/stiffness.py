"""Cartesian stiffness of a mechanism at the output link, from its screw systems (docs/stiffness.md).

**Springs.**  Each actuator ``j`` is a spring of stiffness ``k_j`` along its freedom
(:attr:`~spatialmech.model.joints.Freedom.stiffness`: force per length unit for a slide, torque
per radian for a rotation; 1 when not given, and the result says so).  A limb may be elastic
against the displacements its constraint wrenches forbid
(:attr:`~spatialmech.model.mechanism.Limb.constraint_stiffness` ``k_c``, force per length unit);
otherwise its constraints are rigid.  Links and passive joints are rigid and frictionless; the
pose is unloaded (no preload: the geometric, load-dependent term is not included).

**Displacement and wrench.**  A small displacement of the output link is the twist
``dx = (dtheta ; dp)`` (rotation, then the displacement of the point at the origin); the wrench
that holds it is ``F = (f ; m)``, ``m`` about the origin (the statics convention, docs/statics.md).
Their work is the reciprocal product ``F o dx = f . dp + m . dtheta``, so the symmetric stiffness
matrix pairs ``F`` with the displacement written *force-first*, ``d = (dp ; dtheta)``::

    F = K d,    K = sum_j k_j a_j a_j^T  +  sum_limbs k_c S Q_c Q_c^T S

``a_j`` the actuation wrenches of the complete Jacobian (``a_j o $_j = 1``, so an actuator's
deflection is ``dq_j = a_j o dx = a_j^T d`` and its restoring effort ``tau_j = -k_j dq_j``: the
equilibrium ``sum tau_j a_j + F = 0`` of docs/statics.md gives ``F = K d``), ``Q_c`` an
orthonormal basis of the limb's constraint wrenches in nondimensional coordinates ``(f ; m / L)``
and ``S = diag(1, 1, 1, L, L, L)`` (``L`` the characteristic length).  In terms of the complete
Jacobian ``J = W Delta`` that acts on twists: ``J_a^T diag(k) J_a = Delta K Delta`` (the
congruence form ``J^T K_j J``); :attr:`Stiffness.twist_matrix` is ``K Delta``, the map
``dx -> F`` itself (not symmetric).

**Rigid constraints.**  With rigid constraint wrenches ``c_i`` the output link can only move with
``c_i o dx = 0``; ``K`` is then the stiffness on that subspace (infinite across it: any
combination of the rigid constraint wrenches is held for free) and the complete description is
the compliance ``C`` (``d = C F``, symmetric, positive semi-definite): the minimiser of the
spring energy ``U = d^T K d / 2 - F^T d`` over the allowed ``d``::

    C = N (N^T K N)^-1 N^T,     N: a basis of {d : c_i^T d = 0}

For actuators only and a non-singular complete Jacobian this is ``C = sum_j (1 / k_j) s_j s_j^T``
with ``s_j`` the twist (force-first) the platform makes when actuator ``j`` alone moves by one
unit (a column of ``J^-1``).

**Principal directions.**  The eigen-decomposition of ``N^T K N`` in nondimensional coordinates
about the *platform point* (the output link's reference point where it is now, so that the answer
does not depend on where the model's origin is): ``d_nd = (dp_P ; L dtheta)`` (lengths),
``F_nd = (f ; m_P / L)`` (forces), ``K_nd`` in force per length unit.  Each principal direction is
a unit ``d_nd`` (``|dp_P|^2 + L^2 |dtheta|^2 = 1``) with its stiffness ``k`` (``F_nd = k d_nd``:
a pure translation has the linear stiffness ``k``, a pure rotation the torsional stiffness
``k L^2`` per radian); the rigid directions (the complement of ``N``) have ``k = inf``.  Sorted
softest first.  Eigenvectors of an eigenvalue repeated (to the ``rank`` tolerance, as at a
symmetric pose) are replaced by the orthonormalised reduced row-echelon basis of their space, and
every direction's largest nondimensional component is made positive: no answer depends on the
sign or the basis an eigen-solver returns.

**Singular.**  Where the complete Jacobian is singular (``sigma_min`` below the ``singular``
tolerance: the statics' threshold) the output link can move with every actuator locked: the
softest stiffness is 0, its direction the uncontrolled motion, and the compliance infinite
(``None``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry import screws as sc
from ..geometry.tolerances import current
from ..kinematics.closure import Configuration
from ..kinematics.jacobian import CompleteJacobian, complete_jacobian
from ..kinematics.position import platform_pose
from ..model.mechanism import Mechanism

__all__ = ["DEFAULT_STIFFNESS", "Stiffness", "point_transform", "stiffness", "with_stiffness"]

#: Stiffness assumed for an actuator whose freedom has none (force per length unit, or torque
#: per radian): the results are then per unit actuator stiffness (and say so).
DEFAULT_STIFFNESS = 1.0


@dataclass(frozen=True, eq=False)
class Stiffness:
    """The stiffness of a mechanism at one configuration (see the module docstring).

    ``matrix`` and ``compliance`` are about the origin: ``F = K d`` and ``d = C F`` with
    ``F = (f ; m)`` and the force-first displacement ``d = (dp ; dtheta)``.  The principal
    directions are twists ``(dtheta ; dp)`` about the origin (``dp``: the displacement of the
    point at the origin), each of unit nondimensional size about the platform point, softest
    first, with their stiffness in force per length unit (``inf``: rigid)."""

    matrix: np.ndarray  # (6, 6) K: d -> F, symmetric; the elastic part (infinite across rigid constraints)
    compliance: np.ndarray | None  # (6, 6) C: F -> d, symmetric; None when singular (infinite)
    principal_stiffness: np.ndarray  # (6,) force / length, ascending; inf for rigid directions
    principal_twists: np.ndarray  # (6, 6) rows: twists (dtheta ; dp about the origin)
    multiplicity: np.ndarray  # (6,) how many principal stiffnesses equal each one (to the rank tolerance)
    actuators: tuple[str, ...]
    actuator_stiffness: np.ndarray  # (n_a,) each actuator's k (force / length or torque / rad)
    defaulted: tuple[str, ...]  # actuators given DEFAULT_STIFFNESS (no stiffness in the model)
    constraint_stiffness: tuple[float | None, ...]  # per limb: k_c, None rigid
    rigid_rank: int  # independent rigid constraint wrenches (0..6)
    reference_point: np.ndarray  # (3,) the platform point at this configuration (length)
    characteristic_length: float
    singular: bool
    sigma_min: float
    jacobian: CompleteJacobian
    notes: tuple[str, ...] = ()

    @property
    def twist_matrix(self) -> np.ndarray:
        """``K Delta``: the map from the twist ``dx = (dtheta ; dp)`` to ``F = (f ; m)`` (not symmetric)."""
        return sc.swap(self.matrix)

    @property
    def softest_stiffness(self) -> float:
        """The smallest principal stiffness (force per length unit; 0 at a singularity)."""
        return float(self.principal_stiffness[0])

    @property
    def softest_twist(self) -> np.ndarray:
        """The softest direction: a twist ``(dtheta ; dp)`` about the origin of unit nondimensional
        size about the platform point, its largest nondimensional component positive."""
        return self.principal_twists[0]

    def translation_at_point(self, twist) -> np.ndarray:
        """The displacement of the platform point under ``twist``: ``dp + dtheta x P``."""
        t = np.asarray(twist, float)
        return t[3:] + np.cross(t[:3], self.reference_point)

    def wrench_of(self, twist) -> np.ndarray:
        """The elastic wrench ``(f ; m about the origin)`` that holds the displacement ``twist``."""
        return self.twist_matrix @ np.asarray(twist, float)


def point_transform(P) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)`` for a point ``P``: ``d_P = A d`` (force-first displacement about ``P``) and
    ``F_P = B F`` (wrench with its moment about ``P``); ``B^T A = I`` (work is invariant)."""
    X = np.array([[0.0, -P[2], P[1]], [P[2], 0.0, -P[0]], [-P[1], P[0], 0.0]])
    A, B = np.eye(6), np.eye(6)
    A[:3, 3:] = -X  # dp_P = dp + dtheta x P = dp - P x dtheta
    B[3:, :3] = -X  # m_P = m - P x f
    return A, B


def _sign(v: np.ndarray) -> np.ndarray:
    k = int(np.argmax(np.abs(v)))
    return -v if v[k] < 0 else v


def _deterministic_basis(E: np.ndarray) -> np.ndarray:
    """An orthonormal basis (columns) of the span of the columns of ``E``, chosen by the space
    alone: the reduced row-echelon rows, orthonormalised in order, each sign-normalised."""
    if E.shape[1] <= 1:
        return np.column_stack([_sign(E[:, 0])]) if E.shape[1] else E
    R = sc.rref(E.T)
    if R.shape[0] != E.shape[1]:  # rref lost a row to its tolerances: keep the solver's basis
        R = E.T
    out: list[np.ndarray] = []
    for r in R:
        v = r - sum((u @ r) * u for u in out) if out else r.copy()
        out.append(_sign(v / np.linalg.norm(v)))
    return np.column_stack(out)


def _clusters(values: np.ndarray, rtol: float) -> list[list[int]]:
    """Indices of sorted ``values`` grouped where neighbours are equal to ``rtol`` of the largest."""
    scale = max(float(np.max(np.abs(values))) if values.size else 0.0, 1e-300)
    groups: list[list[int]] = []
    for i, v in enumerate(values):
        if groups and abs(v - values[groups[-1][-1]]) <= rtol * scale:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def _springs(mech: Mechanism, J: CompleteJacobian) -> tuple[np.ndarray, np.ndarray, list[str], list[str]]:
    """``(K about the origin, rigid constraint rows (f ; m), defaulted actuators, notes)``."""
    L = J.length_scale
    W = J.wrenches
    n_c = J.constraint_rows
    S = np.diag([1.0, 1.0, 1.0, L, L, L])
    ks = []
    for a in J.actuators:
        k = mech.freedom(a).freedom.stiffness
        ks.append(DEFAULT_STIFFNESS if k is None else k)
    K = W[n_c:].T @ (np.array(ks)[:, None] * W[n_c:]) if ks else np.zeros((6, 6))
    rigid, notes = [], []
    limbs = np.array(J.constraint_limbs[:n_c], dtype=int)
    for k in sorted(set(limbs.tolist())):
        rows = W[:n_c][limbs == k]
        kc = mech.limbs[k].constraint_stiffness if k >= 0 else None
        if kc is None:
            rigid.extend(rows)
            continue
        Q = _orthonormal_rows(sc.nondimensional(rows, L))
        K = K + kc * S @ Q.T @ Q @ S
    if mech.bodies and any(limb.constraint_stiffness is not None for limb in mech.limbs):
        notes.append("constraint_stiffness is ignored for a mechanism with internal bodies: its constraints are rigid")
    defaulted = [a for a in J.actuators if mech.freedom(a).freedom.stiffness is None]
    return 0.5 * (K + K.T), np.array(rigid).reshape(-1, 6), defaulted, notes


def _orthonormal_rows(A: np.ndarray) -> np.ndarray:
    """An orthonormal basis (rows) of the row space of ``A`` (rank tolerance in force)."""
    _, s, vt = np.linalg.svd(A, full_matrices=False)
    r = int(np.sum(s > current().rank * max(1.0, float(s[0]) if s.size else 0.0)))
    return vt[:r]


def _principal(K_nd: np.ndarray, R_nd: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """``(stiffness ascending, directions (columns, nd), multiplicity, rigid rank)`` of ``K_nd`` on
    the null space of the rigid rows ``R_nd`` (both nondimensional, about the platform point)."""
    tol = current()
    Rq = _orthonormal_rows(R_nd) if R_nd.shape[0] else np.zeros((0, 6))
    rigid_rank = Rq.shape[0]
    N = np.linalg.svd(Rq, full_matrices=True)[2][rigid_rank:].T if rigid_rank else np.eye(6)  # allowed d_nd
    lam, V = np.linalg.eigh(N.T @ K_nd @ N) if N.shape[1] else (np.zeros(0), np.zeros((0, 0)))
    E = N @ V
    values = np.r_[lam, np.full(rigid_rank, np.inf)]
    dirs = np.zeros((6, 6))
    mult = np.zeros(6, dtype=int)
    for g in _clusters(lam, tol.rank):
        dirs[:, g] = _deterministic_basis(E[:, g])
        mult[g] = len(g)
    if rigid_rank:
        dirs[:, 6 - rigid_rank:] = _deterministic_basis(Rq.T)
        mult[6 - rigid_rank:] = rigid_rank
    return values, dirs, mult, rigid_rank


def stiffness(mech: Mechanism, config: Configuration, drivers=None) -> Stiffness:
    """The stiffness of ``mech`` at ``config`` (see the module docstring).  ``drivers``: the
    actuated freedoms (default: the mechanism's actuators), each a spring of its freedom's
    :attr:`~spatialmech.model.joints.Freedom.stiffness` (:data:`DEFAULT_STIFFNESS` if none).
    Raises :class:`~spatialmech.errors.InputError` for a mechanism with no actuator."""
    J = complete_jacobian(mech, config, drivers)
    if not J.actuators:
        raise InputError(f"drivers: {mech.name} has no actuators; name the actuated freedoms")
    L = J.length_scale
    K, rigid, defaulted, notes = _springs(mech, J)
    P = platform_pose(mech, config).p
    A, B = point_transform(P)
    Sinv = np.diag([1.0, 1.0, 1.0, 1.0 / L, 1.0 / L, 1.0 / L])
    K_nd = Sinv @ B @ K @ B.T @ Sinv  # about P, force per length
    R_nd = rigid @ B.T @ Sinv if rigid.shape[0] else rigid  # rows (f ; m_P / L)
    values, dirs, mult, rigid_rank = _principal(0.5 * (K_nd + K_nd.T), R_nd)
    singular = bool(J.singular)
    free = np.isfinite(values)
    if singular:
        values[0] = 0.0
        compliance = None
    else:
        E = dirs[:, free]
        C_nd = E @ np.diag(1.0 / values[free]) @ E.T
        compliance = B.T @ Sinv @ C_nd @ Sinv @ B
        compliance = 0.5 * (compliance + compliance.T)
    twists = np.zeros((6, 6))
    for i in range(6):
        dP = Sinv @ dirs[:, i]  # (dp_P ; dtheta)
        dO = np.linalg.solve(A, dP)  # (dp_O ; dtheta)
        twists[i] = np.r_[dO[3:], dO[:3]]
    ks = np.array([DEFAULT_STIFFNESS if mech.freedom(a).freedom.stiffness is None else mech.freedom(a).freedom.stiffness
                   for a in J.actuators])
    notes = _notes(mech, J, defaulted, rigid_rank, singular) + notes
    return Stiffness(K, compliance, values, twists, mult, J.actuators, ks, tuple(defaulted),
                     tuple(limb.constraint_stiffness for limb in mech.limbs), rigid_rank, P, L, singular,
                     float(J.sigma_min), J, tuple(notes))


def _notes(mech: Mechanism, J: CompleteJacobian, defaulted: list[str], rigid_rank: int, singular: bool) -> list[str]:
    notes = []
    if defaulted:
        notes.append(f"no stiffness in the model for {', '.join(defaulted)}: {DEFAULT_STIFFNESS:g} assumed (force per "
                     "length unit for a slide, torque per radian for a rotation); the results scale with it")
    passive = [r.id for r in mech.freedom_refs if r.freedom.stiffness is not None and r.id not in J.actuators]
    if passive:
        notes.append(f"stiffness of freedoms that are not actuated here ignored ({', '.join(passive)}): passive "
                     "joints are free")
    if rigid_rank:
        notes.append(f"{rigid_rank} independent rigid constraint wrench(es): infinite stiffness across them "
                     "(give a limb constraint_stiffness to make them elastic)")
    if J.inverse_singular:
        notes.append(f"inverse (serial) singular for {', '.join(J.inverse_singular)}: no actuation wrench, that "
                     "actuator's spring holds nothing here")
    if singular:
        notes.append("singular: the output link can move with every actuator locked; the softest stiffness is 0 along "
                     "that motion and the compliance is infinite")
    notes.append("unloaded: the geometric (load-dependent) stiffness is not included; links and passive joints are rigid")
    return notes


def _value(k, where: str) -> float | None:
    if k is None:
        return None
    if isinstance(k, bool) or not isinstance(k, (int, float, np.integer, np.floating)):
        raise TypeError(f"{where}: expected a positive number, got {type(k).__name__}")
    v = float(k)
    if not (np.isfinite(v) and v > 0.0):
        raise InputError(f"{where}: a stiffness must be a positive finite number, got {v:g}")
    return v


def _table(spec, names: list[str], what: str, lookup) -> dict[str, float | None]:
    """``spec``: a number (every name) or a mapping name -> number (``None``: rigid / cleared)."""
    if spec is None:
        return {}
    if not isinstance(spec, dict):
        return {n: _value(spec, what) for n in names}
    out: dict[str, float | None] = {}
    for key, k in spec.items():
        if not isinstance(key, str):
            raise TypeError(f"{what}: expected names (str) as keys, got {type(key).__name__}")
        out[lookup(key)] = _value(k, f"{what}[{key!r}]")
    return out


def with_stiffness(mech: Mechanism, *, actuators=None, constraints=None) -> Mechanism:
    """``mech`` with other stiffnesses: ``actuators`` a number (every actuator) or a mapping
    freedom -> stiffness (force / length or torque / rad); ``constraints`` a number (every limb)
    or a mapping limb name -> constraint stiffness (force / length; ``None``: rigid).  Errors name
    the argument and the key."""
    from dataclasses import replace

    acts = _table(actuators, list(mech.actuators), "actuator_stiffness", lambda n: mech.freedom(n).id)
    limb_names = [limb.name for limb in mech.limbs]

    def limb_id(n: str) -> str:
        if n not in limb_names:
            raise InputError(f"constraint_stiffness: unknown limb {n!r}; limbs: {', '.join(limb_names)}")
        return n

    cons = _table(constraints, limb_names, "constraint_stiffness", limb_id)
    if not acts and not cons:
        return mech
    limbs = []
    for limb in mech.limbs:
        joints = []
        for joint in limb.joints:
            fs = tuple(replace(f, stiffness=acts[f"{joint.name}.{f.name}"]) if f"{joint.name}.{f.name}" in acts else f
                       for f in joint.freedoms)
            joints.append(replace(joint, freedoms=fs))
        kc = cons.get(limb.name, limb.constraint_stiffness)
        limbs.append(replace(limb, joints=tuple(joints), constraint_stiffness=kc))
    return replace(mech, limbs=tuple(limbs))
