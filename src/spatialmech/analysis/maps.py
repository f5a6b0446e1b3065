"""Performance maps: kinetostatic indices over a grid of platform poses (issue 28).

For every pose of a grid -- a position grid at a fixed orientation (``kind="position"``, free
``x, y, z``) or an orientation grid at a fixed position (``kind="orientation"``, free ``alpha,
beta, gamma`` of ``R = Rz(gamma) Ry(beta) Rx(alpha)``, as :mod:`.workspace`) -- the limits are
checked (:func:`.workspace.pose_checker`), the inverse position solved, the complete Jacobian
built (:func:`..kinematics.jacobian.complete_jacobian`: constraint rows, then actuation rows,
``J $p = (0, qdot)``) and these indices computed (:func:`pose_indices`), all nondimensional with
the model's characteristic length ``L`` (:attr:`MapResult.characteristic_length`):

``sigma_min``, ``condition``
    smallest singular value and inverse condition number ``sigma_min / sigma_max`` of the
    dimensionally consistent Jacobian: wrench moments divided by ``L``, each row normalised
    (exactly :attr:`~spatialmech.kinematics.jacobian.CompleteJacobian.sigma_min` and ``.condition``,
    the ``jacobian`` command's values); the condition number is ``1 / condition``.
``manipulability``, ``velocity_axes``, ``force_axes``
    of the forward velocity Jacobian ``G`` (actuator rates to platform twist, on the motion
    subspace the constraints allow) made nondimensional: twists ``(omega ; v / L)``, rates in
    rad/s or (length/s) / L.  ``velocity_axes`` are the semi-axes of the velocity ellipsoid
    ``{G qdot : |qdot| <= 1}`` (singular values of ``G``), ``manipulability = sqrt det(G^T G)``
    their product (Yoshikawa 1985), ``force_axes`` the semi-axes of the dual force ellipsoid (the
    platform wrenches that unit actuator efforts balance: ``1 / velocity_axes``).  At a forward
    singularity a velocity axis and the manipulability are infinite (``inf``; ``null`` in JSON).
``iti``, ``oti``, ``lti``, ``lci``
    transmission and constraint indices (Wang, Liu & Wang 2010, Mech. Mach. Theory 45:1462; Xie,
    Liu & Wang 2014, ASME J. Mech. Robot. 6:031006): power coefficients
    :func:`power_coefficient` between each actuation wrench (the transmission wrench) and its
    actuated joint's twist (input, ITI), and the platform twist left when every other actuator
    is locked (output, OTI); LTI = min(ITI, OTI) over the actuators; LCI: between each constraint
    wrench and the twist the platform would have were that constraint removed (inputs locked),
    minimum over the constraint rows (only where constraint wrenches exist).  All in [0, 1], 0 at
    a singularity.

Statuses (:data:`STATUS`): every cell has one, and the index arrays hold 0 where a cell has no
indices (``outside_limits``, ``unreachable``): never a silent NaN.

Backends: the Python reference is one pose at a time (:func:`pose_loop`).  With the compiled
engine (:mod:`..kinematics.backend`) the grid is batched: for a model whose limbs are all S-P-S /
U-P-S legs or a C-U column (the Gough-Stewart platform, the 4-SPS/CU) one kernel goes from the
pose to the indices; any other model gets its inverse positions batched
(``compiled.limb_inverse_many``), its Jacobians built per pose and its indices in a kernel.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.tolerances import current
from ..kinematics import backend
from ..kinematics.closure import Configuration, hub_displacements, limb_slices, recentre_balls
from ..kinematics.jacobian import complete_jacobian
from ..kinematics.position import inverse_position, platform_pose
from ..model.mechanism import Mechanism, Pose
from .workspace import COORDINATES, WorkspaceLimits, default_limits, pose_checker

__all__ = ["INDICES", "MAX_MAP_POSES", "STATUS", "MapResult", "closed_form_plan", "map_poses", "performance_map",
           "pose_indices", "pose_loop", "power_coefficient"]

#: Cell statuses, by code (the ``status`` arrays hold the code).
STATUS = ("ok", "singular", "inverse_singular", "outside_limits", "unreachable")
OK, SINGULAR, INVERSE_SINGULAR, OUTSIDE, UNREACHABLE = range(5)
#: Scalar indices, in the order of the kernels' output columns; then the ellipsoid semi-axes.
SCALARS = ("sigma_min", "condition", "manipulability", "iti", "oti", "lti", "lci")
INDICES = (*SCALARS, "velocity_axes", "force_axes")
#: Largest grid.
MAX_MAP_POSES = 4_000_000
_ANGLES = ("alpha", "beta", "gamma")

DEFINITIONS = {
    "sigma_min": "smallest singular value of the complete Jacobian, wrench moments / L, rows normalised (scale-free)",
    "condition": "inverse condition number sigma_min / sigma_max of the same matrix (condition number = 1 / condition)",
    "manipulability": "sqrt det(G^T G) of the forward velocity Jacobian G (actuator rates to platform twist on the "
                      "motion subspace), nondimensional: twist (omega ; v / L), slide rates / L (Yoshikawa)",
    "iti": "input transmission index: min over actuators of the power coefficient of the actuation wrench and the "
           "actuated joint's twist (Wang, Liu & Wang 2010)",
    "oti": "output transmission index: min over actuators of the power coefficient of the actuation wrench and the "
           "platform twist with every other actuator locked (Wang, Liu & Wang 2010)",
    "lti": "local transmission index min(ITI, OTI)",
    "lci": "local constraint index: min over constraint wrenches of the power coefficient of the wrench and the "
           "platform twist were it removed, inputs locked (Xie, Liu & Wang 2014)",
    "velocity_axes": "semi-axes of the velocity ellipsoid {G qdot : |qdot| <= 1} (singular values of G), descending",
    "force_axes": "semi-axes of the force ellipsoid (1 / velocity_axes), descending",
    "power_coefficient": "|W o T| / sqrt((h_W + h_T)^2 + max(d, L)^2) for unit wrench W and twist T (pitches h, "
                         "axis distance d); |f.v| / |f||v| for a translation, |m.w| / |m||w| for a couple",
}


# ------------------------------------------------------------------------------ indices of one pose
def power_coefficient(W, T, L: float) -> float:
    """Power coefficient of the wrench ``W = (f ; m)`` and the twist ``T = (omega ; v)`` (SI):
    their reciprocal product over the largest it could be for screws of the same pitches,

        |W o T| / sqrt((h_W + h_T)^2 + d_max^2),   d_max = max(d, L)

    with unit directions, ``d`` the distance between the axes, ``L`` the characteristic length
    (Wang, Liu & Wang 2010 normalise by a "potential maximal" distance ``d_max``; taking
    ``max(d, L)`` makes it frame-invariant, in [0, 1], zero for a force through a rotation axis,
    and the cosine of the pressure angle for axes farther apart than ``L``).  A pure
    translation (``omega = 0``) gives ``|f . v| / (|f| |v|)``; a couple ``|m . omega| / (|m|
    |omega|)``; a couple on a translation 0.

    >>> round(power_coefficient([0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0.6, 0.8], 1.0), 6)  # force z, v at 36.87 deg
    0.8
    """
    W = np.asarray(W, dtype=float)
    T = np.asarray(T, dtype=float)
    f, m, w, v = W[:3], W[3:], T[:3], T[3:]
    nf, nm, nw, nv = (float(np.linalg.norm(x)) for x in (f, m, w, v))
    couple = nf <= 1e-12 * (nf + nm / L)
    translation = nw <= 1e-12 * (nw + nv / L)
    if couple:
        return 0.0 if translation or nm == 0.0 else min(abs(float(m @ w)) / (nm * nw), 1.0)
    if translation:
        return 0.0 if nv == 0.0 else min(abs(float(f @ v)) / (nf * nv), 1.0)
    f, m, w, v = f / nf, m / nf, w / nw, v / nw
    cr = np.cross(f, w)
    s = float(np.linalg.norm(cr))
    dr = np.cross(w, v) - np.cross(f, m)
    d = abs(float(dr @ cr)) / s if s > 1e-12 else float(np.linalg.norm(np.cross(dr, f)))
    power = abs(float(f @ v + m @ w))
    return min(power / float(np.hypot(float(f @ m + w @ v), max(d, L))), 1.0)


def _null_twist(Jr: np.ndarray, i: int) -> np.ndarray:
    """``y_j = (-1)^j det(Jr without row i and column j)``: the twist reciprocal to every row but ``i``."""
    A = np.delete(Jr, i, axis=0)
    return np.array([(-1.0) ** j * np.linalg.det(np.delete(A, j, axis=1)) for j in range(6)])


def pose_indices(matrix, nc: int, inputs, act_scale, L: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The indices of one square complete Jacobian (Python reference of the compiled kernel).

    ``matrix`` (6, 6): rows ``(moment ; force)``, the first ``nc`` the constraint wrenches
    (:attr:`~spatialmech.kinematics.jacobian.CompleteJacobian.matrix`); ``inputs`` (na, 6): the
    actuated joints' twists ``(omega ; v)``; ``act_scale`` (na,): ``L`` for a slide, 1 for a
    rotation.  Returns ``(scalars, velocity_axes, force_axes)`` with ``scalars`` in the order of
    :data:`SCALARS` (``lci`` 0 without constraint rows).
    """
    M = np.asarray(matrix, dtype=float)
    na = 6 - nc
    Jn = M.copy()
    Jn[:, 3:] *= L
    Jn[nc:] /= np.asarray(act_scale, dtype=float)[:, None]
    nrm = np.linalg.norm(Jn, axis=1, keepdims=True)
    Jr = Jn / np.where(nrm > 0, nrm, 1.0)
    sv = np.linalg.svd(Jr, compute_uv=False)
    out = np.zeros(len(SCALARS))
    out[0] = sv[-1]
    out[1] = sv[-1] / sv[0] if sv[0] > 0 else 0.0
    N = np.linalg.svd(Jr[:nc])[2][nc:].T if nc else np.eye(6)  # motion subspace (orthonormal columns)
    fa = np.linalg.svd(Jn[nc:] @ N, compute_uv=False)
    with np.errstate(divide="ignore"):
        va = np.where(fa[::-1] > 0, 1.0 / np.where(fa[::-1] > 0, fa[::-1], 1.0), np.inf)
    prod = float(np.prod(fa))
    out[2] = 1.0 / prod if prod > 0 else np.inf
    wrenches = np.concatenate([M[:, 3:], M[:, :3]], axis=1)
    out[3] = min([power_coefficient(wrenches[nc + a], inputs[a], L) for a in range(na)], default=1.0)
    z = []
    for i in range(6):
        y = _null_twist(Jr, i)
        T = np.concatenate([y[:3], y[3:] * L])
        z.append(power_coefficient(wrenches[i], T, L) if np.linalg.norm(y) > 1e-13 else 0.0)
    out[4] = min(z[nc:], default=1.0)
    out[5] = min(out[3], out[4])
    out[6] = min(z[:nc]) if nc else 0.0
    return out, va, fa


# ------------------------------------------------------------------------------ the closed form
def closed_form_plan(mech: Mechanism) -> dict | str:
    """Arrays for :func:`..kinematics.compiled.maps.maps_closed` when every limb is an S-P-S or
    U-P-S leg actuated along its slide, or a passive C-U column; else why not (a string)."""
    p0 = mech.platform_point
    kinds, pa, pb, e1, e2 = [], [], [], [], []
    leg_of_slide: dict[int, int] = {}
    first = 0
    for k, limb in enumerate(mech.limbs):
        types = [j.type for j in limb.joints]
        nf = sum(len(j.freedoms) for j in limb.joints)
        if mech.limb_ends[k] != (None, 0) or any(f.locked for j in limb.joints for f in j.freedoms):
            return f"limb {limb.name}: not from the ground to the platform, or locked freedoms"
        if types in (["S", "P", "S"], ["U", "P", "S"]):
            Bj, Pj, Aj = limb.joints
            d = (Aj.point - Bj.point) / np.linalg.norm(Aj.point - Bj.point)
            if np.linalg.norm(np.cross(Pj.freedoms[0].direction, d)) > 1e-9:
                return f"limb {limb.name}: the prismatic joint is not along the leg"
            kinds.append(0)
            pa.append(Bj.point)
            pb.append(Aj.point - p0)
            leg_of_slide[first + len(Bj.freedoms)] = k
            e1.append(np.zeros(3))
            e2.append(np.zeros(3))
        elif types == ["C", "U"]:
            Cj, Uj = limb.joints
            kv = np.asarray(Cj.freedoms[0].direction, dtype=float)
            a = np.linalg.svd(kv[None, :])[2][1:]  # two unit vectors perpendicular to the column
            kinds.append(1)
            pa.append(Cj.point)
            pb.append(Uj.point - p0)
            e1.append(a[0])
            e2.append(a[1])
        else:
            return f"limb {limb.name}: joints {'-'.join(types)} have no closed form here"
        first += nf
    refs = mech.freedom_refs
    act = [refs.index(mech.freedom(a)) for a in mech.actuators]
    if any(i not in leg_of_slide for i in act):
        return "an actuator is not the slide of an S-P-S / U-P-S leg"
    return {"kind": np.array(kinds, dtype=np.int64), "pa": np.array(pa, dtype=float), "pb": np.array(pb, dtype=float),
            "e1": np.array(e1, dtype=float), "e2": np.array(e2, dtype=float),
            "act_limb": np.array([leg_of_slide[i] for i in act], dtype=np.int64),
            "act_scale": np.full(len(act), mech.characteristic_length), "nc": 2 * kinds.count(1)}


# ------------------------------------------------------------------------------ the grid
def _axis(name: str, spec) -> np.ndarray:
    if isinstance(spec, tuple) and len(spec) == 3 and isinstance(spec[2], (int, np.integer)):
        lo, hi, n = float(spec[0]), float(spec[1]), int(spec[2])
        if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi and n >= 2):
            raise InputError(f"over: {name} expects (lo, hi, n) with lo < hi finite and n >= 2, got {spec}")
        return np.linspace(lo, hi, n)
    vals = np.asarray(spec, dtype=float).ravel()
    if vals.size < 1 or not np.all(np.isfinite(vals)):
        raise InputError(f"over: {name} expects (lo, hi, n) or finite values, got {spec!r}")
    return vals


def map_poses(mech: Mechanism, kind: str, over: Mapping, at: Mapping | None = None):
    """``(axes, fixed, R (N, 3, 3), p (N, 3), shape)`` of the grid: ``over`` maps 1 to 3 free
    coordinates (``x, y, z`` for ``kind="position"``, ``alpha, beta, gamma`` for
    ``"orientation"``; SI, rad) to ``(lo, hi, n)`` or values; ``at`` holds the others (default:
    the reference platform point, no rotation)."""
    free = ("x", "y", "z") if kind == "position" else _ANGLES
    if not isinstance(over, Mapping) or not 1 <= len(over) <= 3:
        raise InputError(f"over: expected a mapping of 1 to 3 {kind} coordinates ({', '.join(free)}) to (lo, hi, n)")
    at = dict(at or {})
    for name in (*over, *at):
        if name not in COORDINATES:
            raise InputError(f"over/at: unknown coordinate {name!r}; expected one of {', '.join(COORDINATES)}")
    for name in over:
        if name not in free:
            raise InputError(f"over: {name} is not a {kind} coordinate (kind={kind!r} grids {', '.join(free)})")
        if name in at:
            raise InputError(f"at: {name} is on the grid (over)")
    p0 = platform_pose(mech, Configuration.reference(mech)).p
    ref = dict(zip(COORDINATES, (*p0, 0.0, 0.0, 0.0), strict=True))
    fixed = {c: float(at.get(c, ref[c])) for c in COORDINATES if c not in over}
    axes = {name: _axis(name, spec) for name, spec in over.items()}
    shape = tuple(a.size for a in axes.values())
    n = int(np.prod(shape))
    if n > MAX_MAP_POSES:
        raise InputError(f"over: {n} poses; at most {MAX_MAP_POSES}")
    mesh = dict(zip(axes, (g.ravel() for g in np.meshgrid(*axes.values(), indexing="ij")), strict=True))
    col = {c: mesh[c] if c in mesh else np.full(n, fixed[c]) for c in COORDINATES}
    p = np.stack([col["x"], col["y"], col["z"]], axis=-1)
    return axes, fixed, _zyx(col["gamma"], col["beta"], col["alpha"]), p, shape


def _zyx(g: np.ndarray, b: np.ndarray, a: np.ndarray) -> np.ndarray:
    """``Rz(g) Ry(b) Rx(a)`` (N, 3, 3), as :func:`..geometry.rotations.euler_matrix` ``("ZYX", (g, b, a))``."""
    cg, sg, cb, sb, ca, sa = np.cos(g), np.sin(g), np.cos(b), np.sin(b), np.cos(a), np.sin(a)
    R = np.empty((g.size, 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 0, 2] = cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa
    R[:, 1, 0], R[:, 1, 1], R[:, 1, 2] = sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa
    R[:, 2, 0], R[:, 2, 1], R[:, 2, 2] = -sb, cb * sa, cb * ca
    return R


# ------------------------------------------------------------------------------ the result
@dataclass(frozen=True, eq=False)
class MapResult:
    """Indices over a grid of poses (see the module docstring for the definitions).

    ``axes``: the free coordinates' values (SI, rad), in grid order; ``values[name]``: an array
    of the grid's shape for each scalar index (``velocity_axes`` / ``force_axes``: one more axis,
    by actuator count); ``status``: the code (:data:`STATUS`) of each cell; ``violated``: the
    limit a cell ``outside_limits`` violates first ("" elsewhere), flat in grid order."""

    mechanism: str
    kind: str
    axes: dict
    fixed: dict
    values: dict
    status: np.ndarray
    violated: tuple
    characteristic_length: float
    length_unit: str
    actuators: tuple
    constraint_rows: int
    path: str
    seconds: float
    indices: tuple = INDICES

    @property
    def shape(self) -> tuple:
        return self.status.shape

    @property
    def n_poses(self) -> int:
        return int(self.status.size)

    @property
    def valid(self) -> np.ndarray:
        """Cells that have indices (``ok`` or ``singular`` / ``inverse_singular``)."""
        return self.status <= INVERSE_SINGULAR

    def status_counts(self) -> dict[str, int]:
        return {name: int(np.sum(self.status == k)) for k, name in enumerate(STATUS)}

    def to_dict(self) -> dict:
        """JSON (docs/json.md, ``maps``): axes and fixed coordinates with unit suffixes (angles in
        degrees), the selected index grids (``null`` where a cell has none, or an infinite value),
        the status and violated-limit grids, and the definitions."""
        def key(c: str) -> str:
            return f"{c}_deg" if c in _ANGLES else f"{c}_len"

        def conv(c: str, v):
            return np.degrees(v) if c in _ANGLES else v

        def grid(a: np.ndarray, valid: np.ndarray) -> list:
            obj = np.where(valid & np.isfinite(a), a, np.nan).astype(object)
            obj[~(valid & np.isfinite(a))] = None
            return obj.tolist()

        maps = {}
        for name in self.indices:
            a = self.values[name]
            v = self.valid if a.ndim == self.status.ndim else self.valid[..., None]
            maps[name] = grid(a, np.broadcast_to(v, a.shape))
        return {
            "result": "performance_map", "kind": self.kind, "path": self.path, "over": list(self.axes),
            "axes": {key(c): conv(c, a).tolist() for c, a in self.axes.items()},
            "fixed": {key(c): float(conv(c, v)) for c, v in self.fixed.items()},
            "euler_sequence": "ZYX", "orientation_convention": "R = Rz(gamma) Ry(beta) Rx(alpha)",
            "characteristic_length_len": self.characteristic_length, "actuators": list(self.actuators),
            "constraint_rows": self.constraint_rows, "n_grid": self.n_poses, "seconds": self.seconds,
            "poses_per_s": self.n_poses / self.seconds if self.seconds > 0 else None,
            "status": np.array(STATUS, dtype=object)[self.status].tolist(), "status_counts": self.status_counts(),
            "violated": np.array(self.violated, dtype=object).reshape(self.shape).tolist(),
            "index_maps": maps, "definitions": {k: DEFINITIONS[k] for k in (*self.indices, "power_coefficient")},
        }


# ------------------------------------------------------------------------------ the computation
def _actuation(mech: Mechanism) -> tuple[list[tuple[int, int]], np.ndarray]:
    """(limb, column) of each actuator's twist, and each actuator's rate scale (L or 1)."""
    refs = mech.freedom_refs
    sls = limb_slices(mech)
    where, scale = [], []
    for a in mech.actuators:
        i = refs.index(mech.freedom(a))
        where.append((refs[i].limb, i - sls[refs[i].limb].start))
        scale.append(mech.characteristic_length if refs[i].freedom.kind == "P" else 1.0)
    return where, np.array(scale)


def _jacobian_at(mech: Mechanism, config: Configuration, where):
    """``(matrix, inputs, inverse_singular)`` at a closed configuration."""
    jac = complete_jacobian(mech, config)
    tw = backend.joint_twists(mech, config)
    inputs = np.array([tw[k][:, j] for k, j in where])
    return jac.matrix, inputs, bool(jac.inverse_singular)


def _statuses(checker, R, p) -> tuple[np.ndarray, list[str]]:
    """Cells outside the limits or out of reach (``OK`` elsewhere), and the violated limit's name."""
    feasible = checker.feasible(R, p)
    status = np.full(R.shape[0], OK, dtype=np.int8)
    violated = [""] * R.shape[0]
    bad = np.flatnonzero(~feasible)
    if bad.size:
        for i, name in zip(bad, checker.violated(R[bad], p[bad]), strict=True):
            status[i] = UNREACHABLE if name == "closure" else OUTSIDE
            violated[i] = name
    return status, violated


def _finish(status: np.ndarray, out: np.ndarray, inv_singular: np.ndarray) -> None:
    """Singular statuses of the cells that have indices."""
    live = status == OK
    status[live & (out[:, 0] < current().singular)] = SINGULAR
    status[live & inv_singular] = INVERSE_SINGULAR


def pose_loop(mech: Mechanism, R, p, checker) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The per-pose reference: for each pose its limits, :func:`..kinematics.position.inverse_position`,
    the complete Jacobian and :func:`pose_indices`.  Returns ``(out, vaxes, faxes, status)``."""
    where, scale = _actuation(mech)
    n, na = R.shape[0], len(where)
    out, va, fa = np.zeros((n, len(SCALARS))), np.zeros((n, na)), np.zeros((n, na))
    status = np.full(n, OK, dtype=np.int8)
    inv = np.zeros(n, dtype=bool)
    nc = 6 - na
    for i in range(n):
        st, _ = _statuses(checker, R[i : i + 1], p[i : i + 1])
        status[i] = st[0]
        if st[0] != OK:
            continue
        res = inverse_position(mech, Pose(R[i], p[i]))
        if not res.reachable or res.config is None:
            status[i] = UNREACHABLE
            continue
        M, inputs, inv[i] = _jacobian_at(mech, res.config, where)
        out[i], va[i], fa[i] = pose_indices(M, nc, inputs, scale, mech.characteristic_length)
    _finish(status, out, inv)
    return out, va, fa, status


def _batched_general(mech: Mechanism, R, p, status, fast):
    """Inverse positions batched (``limb_inverse_many``), Jacobians per pose, indices compiled."""
    where, scale = _actuation(mech)
    n, na = R.shape[0], len(where)
    live = np.flatnonzero(status == OK)
    D = np.zeros((live.size, 4, 4))
    D[:, :3, :3] = R[live]
    D[:, :3, 3] = p[live] - np.einsum("nij,j->ni", R[live], mech.platform_point)
    D[:, 3, 3] = 1.0
    q, ok = np.zeros((0, len(mech.freedom_refs))), np.zeros((0, 1), dtype=bool)
    if live.size:
        q, _res, ok = fast.limb_inverse_many(mech, D)
    Ms, inputs, inv = np.zeros((live.size, 6, 6)), np.zeros((live.size, na, 6)), np.zeros(n, dtype=bool)
    for j, i in enumerate(live):
        config = None
        if np.all(ok[j]):
            qi = recentre_balls(mech, q[j])
            config = Configuration(qi, D[j], hub_displacements(mech, qi, D[j]))
        else:
            res = inverse_position(mech, Pose(R[i], p[i]))
            config = res.config if res.reachable else None
        if config is None:
            status[i] = UNREACHABLE
            continue
        Ms[j], inputs[j], inv[i] = _jacobian_at(mech, config, where)
    out, va, fa = np.zeros((n, len(SCALARS))), np.zeros((n, na)), np.zeros((n, na))
    if live.size:
        o, v, f = fast.maps.indices_many(Ms, 6 - na, inputs, scale, mech.characteristic_length)
        keep = status[live] == OK
        out[live[keep]], va[live[keep]], fa[live[keep]] = o[keep], v[keep], f[keep]
    _finish(status, out, inv)
    return out, va, fa


def _batched_closed(mech: Mechanism, R, p, status, fast, plan: dict):
    """The closed-form kernel over the cells within the limits."""
    live = np.flatnonzero(status == OK)
    na = plan["act_limb"].size
    out, va, fa = np.zeros((R.shape[0], len(SCALARS))), np.zeros((R.shape[0], na)), np.zeros((R.shape[0], na))
    t = current()
    o, v, f, ok = fast.maps.maps_closed(R[live], p[live], plan, mech.characteristic_length, t.rank, t.pivot)
    out[live], va[live], fa[live] = o, v, f
    status[live[~ok]] = UNREACHABLE  # degenerate (a leg of zero length): no Jacobian
    _finish(status, out, np.zeros(R.shape[0], dtype=bool))
    return out, va, fa


def _square(mech: Mechanism) -> int:
    """The number of constraint rows; refuses a model whose complete Jacobian is not 6 x 6."""
    if mech.bodies:
        raise InputError(f"{mech.name}: performance maps need limbs from the ground to the platform (no internal bodies)")
    jac = complete_jacobian(mech, Configuration.reference(mech))
    if jac.matrix.shape[0] != 6:
        raise InputError(f"{mech.name}: the complete Jacobian has {jac.matrix.shape[0]} rows, not 6 (constraint rows "
                         f"{jac.constraint_rows} + actuators {len(jac.actuators)}): maps need a square one")
    return int(jac.constraint_rows)


def performance_map(mech: Mechanism, *, kind: str = "position", over: Mapping, at: Mapping | None = None,
                    limits: WorkspaceLimits | None = None, indices=None, method: str = "auto") -> MapResult:
    """The indices over a grid (:func:`map_poses`), under ``limits`` (default: the model's,
    :func:`.workspace.default_limits`).  ``method``: ``"auto"`` (compiled and batched when the
    engine is on, else the per-pose loop), ``"loop"`` (the per-pose Python reference) or
    ``"batched"``.  ``indices``: the names kept in the result (default: all that apply; ``lci``
    only with constraint rows)."""
    if kind not in ("position", "orientation"):
        raise InputError(f"kind: expected 'position' or 'orientation', got {kind!r}")
    if method not in ("auto", "loop", "batched"):
        raise InputError(f"method: expected 'auto', 'loop' or 'batched', got {method!r}")
    nc = _square(mech)
    available = tuple(n for n in INDICES if n != "lci" or nc)
    chosen = available if indices is None else tuple(indices)
    for name in chosen:
        if name not in available:
            raise InputError(f"indices: {name!r} is not available here; expected some of {', '.join(available)}")
    axes, fixed, R, p, shape = map_poses(mech, kind, over, at)
    checker = pose_checker(mech, default_limits(mech) if limits is None else limits)
    t0 = time.perf_counter()
    fast = backend.engine()
    if method == "loop" or fast is None:
        out, va, fa, status = pose_loop(mech, R, p, checker)
        path = "python per-pose loop"
    else:
        status, violated = _statuses(checker, R, p)
        plan = closed_form_plan(mech)
        if isinstance(plan, dict):
            out, va, fa = _batched_closed(mech, R, p, status, fast, plan)
            path = "compiled closed-form kernel"
        else:
            out, va, fa = _batched_general(mech, R, p, status, fast)
            path = "compiled indices, batched inverse position"
    seconds = time.perf_counter() - t0
    if method == "loop" or fast is None:
        violated = [""] * R.shape[0]
        bad = np.flatnonzero(status >= OUTSIDE)
        if bad.size:
            for i, name in zip(bad, checker.violated(R[bad], p[bad]), strict=True):
                violated[i] = name or "closure"
    else:  # the limits were named once by _statuses; cells the kernel found degenerate do not close
        for i in np.flatnonzero(status >= OUTSIDE):
            violated[i] = violated[i] or "closure"
    values = {name: out[:, k].reshape(shape) for k, name in enumerate(SCALARS)}
    values["velocity_axes"] = va.reshape(*shape, -1)
    values["force_axes"] = fa.reshape(*shape, -1)
    return MapResult(mech.name, kind, axes, fixed, values, status.reshape(shape), tuple(violated), mech.characteristic_length,
                     mech.length_unit, tuple(mech.actuators), nc, path, seconds, chosen)
