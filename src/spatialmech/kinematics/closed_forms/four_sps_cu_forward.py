"""Paper B: forward position of the 4-SPS/CU parallel mechanism, closed-form equations
(:mod:`.four_sps_cu`: geometry, inverse position, velocity, acceleration, conditioning).

Pose ``phi = (z, alpha, beta, gamma)`` (metres, radians), ``R = Rz(gamma) Ry(beta) Rx(alpha)``
(intrinsic "ZYX", :data:`.four_sps_cu.EULER_SEQUENCE`).  :func:`forward` solves the four
equations ``(l_i(phi)^2 - l_i^2) / 2 = 0`` by a vectorised Levenberg-Marquardt iteration
(Jacobian ``J`` of eq 9) with a convergence status; :func:`forward_batch` does the same for many
(leg lengths, seed) pairs; :func:`forward_all` runs it from a deterministic quasi-random set of
seeds, de-duplicates the roots and follows singular ones along their self-motion.  Every root
``(z, R)`` has a mirror image ``(-z, -alpha, -beta, gamma)``: the same leg lengths with the
platform below the base (outside the CU limits).  Do not seed at ``alpha = beta = 0``
(singular: with the legs locked the platform keeps a self-motion).

Example (a pose and its leg lengths, back)::

    >>> import numpy as np
    >>> from spatialmech.kinematics.closed_forms.four_sps_cu import leg_lengths
    >>> r = forward(leg_lengths([0.25, 0.2, 0.1, 0.3]), seed=(0.25, 0.15, 0.05, 0.25))
    >>> str(r.status), np.round(r.phi, 6).tolist(), str(r.kind)
    ('converged', [0.25, 0.2, 0.1, 0.3], 'regular')
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...geometry.rotations import matrix_euler
from ...geometry.tolerances import current
from ...geometry.validate import as_finite_array
from ...results import SolveStatus
from ...serialize import pose_dict
from ..assembly import AssemblyKind, SelfMotion, dedup_tolerances, group_roots, pose_keys, singular_threshold, trace_set
from .four_sps_cu import (
    CONDITIONING_MEASURE,
    DEFAULT_SEED,
    EULER_SEQUENCE,
    PAPER_B,
    FourSpsCuGeometry,
    conditioning,
    jacobian_x,
    leg_squares_and_jacobian,
    rotation,
    twist_jacobian,
)

__all__ = [
    "ForwardAllResult",
    "ForwardBatch",
    "ForwardResult",
    "ForwardSearch",
    "forward",
    "forward_all",
    "forward_batch",
]


# ------------------------------------------------------------------ forward position
def _lm_batch(l, seeds, geometry: FourSpsCuGeometry, tol: float, max_iter: int):
    """Vectorised Levenberg-Marquardt on ``f = (l(phi)^2 - l^2) / (2 Lc^2) = 0`` from each seed
    (``l`` (4,) shared by all seeds, or (k, 4) one per seed).

    Unknowns are scaled ``(z / Lc, alpha, beta, gamma)`` (``Lc = b``).  Step
    ``(J^T J + mu D^2) h = -J^T f`` with Moré's non-decreasing column scaling ``D`` and
    Nielsen's damping update (``mu *= max(1/3, 1 - (2 rho - 1)^3)`` on success, ``mu *= nu,
    nu *= 2`` on failure), as in MINPACK but batched over the seeds.  A plain Newton iteration
    with a line search stalls in the narrow valleys around the singular set ``alpha = beta = 0``
    (measured on 2000 random poses with seeds perturbed by 0.3 rad / 0.06 m: 10.6 % failures
    for Newton with backtracking, 0.35 % here).

    Returns ``phi`` (k, 4), converged (k,), iterations (k,), residual
    ``max_i |l_i(phi) - l_i|`` (k,, metres) and status codes (0 max_iter, 1 converged,
    2 stalled: the damping grew beyond 1e20 without a decrease of ``|f|``).
    """
    Lc = geometry.length_scale
    a, b = geometry.a, geometry.b
    x = np.array(seeds, dtype=float)
    k = x.shape[0]
    lt = np.array(np.broadcast_to(l, x.shape), dtype=float)
    l2t = lt * lt
    colscale = np.array([Lc, 1.0, 1.0, 1.0])
    eye = np.eye(4)

    def evaluate(xx, rows):
        l2, J = leg_squares_and_jacobian(xx, a, b)
        return (l2 - l2t[rows]) / (2 * Lc * Lc), J * (colscale / (Lc * Lc)), l2

    def normal(Jr):
        A = np.swapaxes(Jr, -1, -2) @ Jr
        return A, np.diagonal(A, axis1=-2, axis2=-1)

    def residual():
        return np.max(np.abs(np.sqrt(np.maximum(l2, 0.0)) - lt), axis=-1)

    f, J, l2 = evaluate(x, slice(None))
    cost = np.sum(f * f, axis=-1)
    A, dA = normal(J)
    mu = 1e-3 * np.max(dA, axis=-1)
    nu = np.full(k, 2.0)
    D2 = np.maximum(dA, 1e-12)
    iters = np.zeros(k, dtype=int)
    status = np.zeros(k, dtype=int)
    for _ in range(max_iter):
        status[(status == 0) & (residual() <= tol)] = 1
        run = np.flatnonzero(status == 0)
        if run.size == 0:
            break
        iters[run] += 1
        Jr, fr = J[run], f[run]
        A, dA = normal(Jr)
        g = np.einsum("kji,kj->ki", Jr, fr)
        D2[run] = np.maximum(D2[run], dA)
        damp = mu[run, None] * D2[run]
        h = np.linalg.solve(A + damp[:, :, None] * eye, -g[..., None])[..., 0]
        trial = x[run] + h * colscale
        ft, Jt, l2tr = evaluate(trial, run)
        ct = np.sum(ft * ft, axis=-1)
        predicted = np.einsum("ki,ki->k", h, damp * h - g)  # cost(0) - model cost(h)
        rho = (cost[run] - ct) / np.maximum(predicted, 1e-300)
        ok = np.isfinite(ct) & (rho > 0)
        acc = run[ok]
        x[acc], f[acc], J[acc], l2[acc], cost[acc] = trial[ok], ft[ok], Jt[ok], l2tr[ok], ct[ok]
        mu[acc] *= np.maximum(1.0 / 3.0, 1.0 - (2.0 * rho[ok] - 1.0) ** 3)
        nu[acc] = 2.0
        rej = run[~ok]
        mu[rej] *= nu[rej]
        nu[rej] *= 2.0
        status[rej[mu[rej] > 1e20]] = 2
    status[(status != 1) & (residual() <= tol)] = 1
    return x, status == 1, iters, residual(), status


_STATUS = {0: SolveStatus.MAX_ITER, 1: SolveStatus.CONVERGED, 2: SolveStatus.STALLED}


def _canonical(phi: np.ndarray) -> np.ndarray:
    """Same pose with ``beta`` in [-pi/2, pi/2] and ``alpha, gamma`` in (-pi, pi] (from ``R``)."""
    import warnings

    with warnings.catch_warnings():  # at beta = +-pi/2 scipy sets alpha to 0 and says so: intended
        warnings.filterwarnings("ignore", message="Gimbal lock detected")
        ang = matrix_euler(EULER_SEQUENCE, rotation(phi))
    return np.concatenate([phi[..., :1], ang[..., ::-1]], axis=-1)


def _sigma_min(phi: np.ndarray, geometry: FourSpsCuGeometry) -> np.ndarray:
    """Smallest singular value of ``Jx`` (Euler-angle rates) with the angle columns divided by b:
    the conditioning of the solver's equations (it also vanishes at ``beta = +-pi/2``, a gimbal
    lock of the angles); the mechanism's own is :func:`.four_sps_cu.conditioning`."""
    scale = np.array([1.0, 1.0 / geometry.length_scale, 1.0 / geometry.length_scale, 1.0 / geometry.length_scale])
    return np.linalg.svd(jacobian_x(phi, geometry) * scale, compute_uv=False)[..., -1]


@dataclass(frozen=True, eq=False)
class ForwardResult:
    """One forward-position solution (or failed attempt) of the 4-SPS/CU.

    ``phi`` = ``(z [m], alpha, beta, gamma [rad])``, ``R = Rz(gamma) Ry(beta) Rx(alpha)``;
    ``residual`` = ``max_i |l_i(phi) - l_i|`` in metres; ``sigma_min`` and ``condition`` (=
    sigma_min / sigma_max) of :func:`conditioning` (0 at a singularity), ``singular`` below
    ``singular_below``; ``kind`` (regular, singular, self-motion: see
    :mod:`spatialmech.kinematics.assembly`), ``members`` (converged seeds standing for this
    result); ``within_limits`` checks leg lengths and the CU length ``z`` only (not the joint
    angles of eqs 18-21).
    """

    phi: np.ndarray
    leg_lengths: np.ndarray
    converged: bool
    status: SolveStatus
    iterations: int
    residual: float
    legs_within_limits: bool
    z_within_limits: bool
    sigma_min: float
    seed: np.ndarray
    length_scale: float = 1.0  # b: the nondimensional residual in JSON is residual / length_scale
    leg_limits: tuple[float, float] | None = None  # to name the legs outside their limits
    condition: float = 0.0  # sigma_min / sigma_max
    singular_below: float = 0.0  # sigma_min threshold of ``singular``
    kind: AssemblyKind | None = None  # None for a failed attempt
    members: int = 1
    self_motion: SelfMotion | None = None

    @property
    def within_limits(self) -> bool:
        return self.legs_within_limits and self.z_within_limits

    @property
    def singular(self) -> bool:
        return bool(self.sigma_min < self.singular_below)

    @property
    def rotation(self) -> np.ndarray:
        return rotation(self.phi)

    def to_dict(self, *, actuators=None) -> dict:
        """JSON (docs/json.md), the same fields as the general engine's forward solutions
        (:meth:`spatialmech.kinematics.forward.ForwardSolution.to_dict`): the pose as the
        platform point ``(0, 0, z)``, ``euler_deg`` of "ZYX" = ``(gamma, beta, alpha)`` in
        degrees and the rotation matrix; ``residual`` = largest leg-length error / ``b``;
        ``outside_limits`` names the legs (``actuators``, default ``l1..l4``) and ``"z"`` (the
        CU length) outside their limits (joint-angle limits of eqs 18-21 are not checked)."""
        names = _leg_names(actuators)
        if self.leg_limits is not None:
            lo, hi = self.leg_limits
            outside = [n for n, l in zip(names, self.leg_lengths, strict=True) if not lo <= l <= hi]
        else:
            outside = [] if self.legs_within_limits else list(names)
        if not self.z_within_limits:
            outside.append("z")
        return {
            "status": str(self.status),
            "converged": bool(self.converged),
            "iterations": int(self.iterations),
            "residual": float(self.residual) / self.length_scale,
            "pose": pose_dict(self.rotation, [0.0, 0.0, float(self.phi[0])]),
            "within_limits": bool(self.within_limits),
            "outside_limits": outside,
            "sigma_min": float(self.sigma_min),
            "singular": self.singular,
            "condition": float(self.condition),
            "singular_below": float(self.singular_below),
            "conditioning_measure": CONDITIONING_MEASURE,
            "kind": str(self.kind) if self.kind is not None else None,
            "members": int(self.members),
            "self_motion": self.self_motion.to_dict() if self.self_motion is not None else None,
        }


def _leg_names(actuators) -> list[str]:
    names = ["l1", "l2", "l3", "l4"] if actuators is None else [str(a) for a in actuators]
    if len(names) != 4:
        raise InputError(f"actuators: expected the 4 leg names, got {names}")
    return names


def _check_solver(tol: float, max_iter: int) -> None:
    if not (np.isfinite(tol) and tol > 0):
        raise InputError(f"tol: expected a positive tolerance in metres, got {tol}")
    if int(max_iter) != max_iter or max_iter < 1:
        raise InputError(f"max_iter: expected a positive integer, got {max_iter}")


def _leg_input(l, geometry: FourSpsCuGeometry) -> np.ndarray:
    l = as_finite_array(l, "l", shape=(4,))
    if np.any(l <= 0):
        raise InputError(f"l: leg lengths must be positive, got {l.tolist()}")
    return l


def _results(l, phi, conv, iters, res, status, seeds, geometry, tol) -> list[ForwardResult]:
    legs_ok = bool(np.all((l >= geometry.leg_limits[0]) & (l <= geometry.leg_limits[1])))
    sig, cond = conditioning(phi, geometry) if phi.shape[0] else (np.zeros(0), np.zeros(0))
    thr = singular_threshold(tol / geometry.length_scale)
    out = []
    for i in range(phi.shape[0]):
        z = phi[i, 0]
        out.append(
            ForwardResult(
                phi=phi[i].copy(),
                leg_lengths=l.copy(),
                converged=bool(conv[i]),
                status=_STATUS[int(status[i])],
                iterations=int(iters[i]),
                residual=float(res[i]),
                legs_within_limits=legs_ok,
                z_within_limits=bool(geometry.z_limits[0] <= z <= geometry.z_limits[1]),
                sigma_min=float(sig[i]),
                seed=np.asarray(seeds[i], dtype=float).copy(),
                length_scale=geometry.length_scale,
                leg_limits=geometry.leg_limits,
                condition=float(cond[i]),
                singular_below=thr,
            )
        )
    return out


def _key(phi: np.ndarray, geometry: FourSpsCuGeometry) -> np.ndarray:
    """Scale-free pose coordinates (..., 12) of ``phi``: platform point ``(0, 0, z) / b`` and ``R``."""
    p = np.zeros((*phi.shape[:-1], 3))
    p[..., 2] = phi[..., 0]
    return pose_keys(rotation(phi), p, geometry.length_scale)


class _LegProblem:
    """The poses with the legs held at ``l``, as a tracking problem (see
    :mod:`spatialmech.kinematics.tracking`): state ``(z, R)``, local coordinates
    ``(dz / b, omega)`` (rotation vector in the base frame), residual ``(|d_i|^2 - l_i^2) / (2 b^2)``
    with ``d_i = R A_i + (0, 0, z) - B_i``.  Free of the Euler angles' gimbal lock."""

    def __init__(self, l, geometry: FourSpsCuGeometry):
        self.l2 = np.asarray(l, dtype=float) ** 2
        self.g = geometry
        self.b = geometry.length_scale

    def _d(self, x):
        z, R = x
        RA = self.g.platform_points @ R.T
        d = RA - self.g.base_points
        d[:, 2] += z
        return RA, d

    def residual(self, x):
        _, d = self._d(x)
        return (np.sum(d * d, axis=1) - self.l2) / (2 * self.b * self.b)

    def jacobian(self, x):
        RA, d = self._d(x)
        return np.c_[d[:, 2] * self.b, np.cross(RA, d)] / (self.b * self.b)

    def retract(self, x, dx):
        from scipy.spatial.transform import Rotation

        z, R = x
        R2 = Rotation.from_rotvec(np.asarray(dx[1:], dtype=float)).as_matrix() @ R
        return (z + self.b * float(dx[0]), R2)

    def difference(self, x, y):
        from scipy.spatial.transform import Rotation

        return np.r_[(y[0] - x[0]) / self.b, Rotation.from_matrix(y[1] @ x[1].T).as_rotvec()]

    def tangent(self, x):
        return np.linalg.svd(self.jacobian(x))[2][-1]


def _trace(l, phi0: np.ndarray, geometry: FourSpsCuGeometry):
    """Follow the solution set of ``l(phi) = l`` through the singular root ``phi0`` (a self-motion
    of the platform with the legs held), on ``(z, R)`` (no Euler-angle singularity)."""

    def key(x):
        return pose_keys(x[1], [0.0, 0.0, x[0]], geometry.length_scale)

    return trace_set(_LegProblem(l, geometry), (float(phi0[0]), rotation(phi0)), key, h0=0.02, h_max=0.1, max_steps=800)


def _classify(l, sols: list[ForwardResult], geometry: FourSpsCuGeometry, tol: float,
              dedup_tol: float | None = None) -> list[ForwardResult]:
    """The converged roots ``sols`` as results: duplicates merged, roots on one self-motion one
    result (:func:`spatialmech.kinematics.assembly.group_roots`), each with its kind and members."""
    from dataclasses import replace

    if not sols:
        return []
    phis = np.array([s.phi for s in sols])
    keys = _key(phis, geometry)
    dedup, sdedup = dedup_tolerances(tol / geometry.length_scale)
    if dedup_tol is not None:
        dedup = float(dedup_tol)
    b = geometry.length_scale
    sv = np.linalg.svd(twist_jacobian(phis, geometry) * np.array([1.0, 1.0 / b, 1.0 / b, 1.0 / b]), compute_uv=False)
    free = [int(np.sum(row < s.singular_below)) for row, s in zip(sv, sols, strict=True)]
    groups = group_roots(keys, [s.singular for s in sols], [s.residual for s in sols],
                         lambda i: _trace(l, phis[i], geometry), dedup_tol=dedup, singular_dedup_tol=max(sdedup, dedup),
                         prefer=[s.within_limits for s in sols], free_dims=free)
    return [replace(sols[g.rep], kind=g.kind, members=len(g.members), self_motion=g.self_motion(keys, geometry.length_scale))
            for g in groups]


def forward(
    l,
    seed=DEFAULT_SEED,
    *,
    geometry: FourSpsCuGeometry = PAPER_B,
    tol: float = 1e-12,
    max_iter: int = 200,
) -> ForwardResult:
    """Forward position: the pose ``phi`` with leg lengths ``l`` (4,) [m], by Levenberg-Marquardt
    from ``seed`` (z [m], alpha, beta, gamma [rad]).

    Converged means ``max_i |l_i(phi) - l_i| <= tol`` (metres); otherwise ``status`` is
    ``"max_iter"`` or ``"stalled"`` and ``phi`` is the last iterate (never a silent wrong
    answer).  The angles are returned canonical (``|beta| <= pi/2``).  The result states its
    conditioning; a singular root is followed along its self-motion (``kind``).  Do not seed at
    ``alpha = beta = 0`` (singular).  Near a fold of the forward map two assembly modes lie
    close together (e.g. 0.045 rad apart) and the mode reached depends on the seed; it is
    always a genuine mode (:func:`forward_all` lists them all).
    """
    l = _leg_input(l, geometry)
    seed = as_finite_array(seed, "seed", shape=(4,))
    _check_solver(tol, max_iter)
    phi, conv, iters, res, status = _lm_batch(l, seed[None], geometry, tol, max_iter)
    out = _results(l, _canonical(phi), conv, iters, res, status, seed[None], geometry, tol)[0]
    return _classify(l, [out], geometry, tol)[0] if out.converged else out


@dataclass(frozen=True, eq=False)
class ForwardBatch:
    """Forward position of many (leg lengths, seed) pairs at once (arrays, one row per pair).

    ``phi`` (k, 4) canonical ``(z [m], alpha, beta, gamma [rad])``; ``converged`` (k,);
    ``iterations`` (k,); ``residual`` (k,) = ``max_i |l_i(phi) - l_i|`` in metres; ``status``
    (k,) of "converged" / "max_iter" / "stalled"; ``within_limits`` (k,) (leg and CU lengths);
    the conditioning of each row (:func:`conditioning`: ``sigma_min``, ``condition``, and
    ``singular``; self-motions are not traced here, see :func:`forward_all`).
    """

    phi: np.ndarray
    converged: np.ndarray
    iterations: np.ndarray
    residual: np.ndarray
    status: tuple[SolveStatus, ...]
    within_limits: np.ndarray
    sigma_min: np.ndarray | None = None  # (k,) of :func:`conditioning`
    condition: np.ndarray | None = None  # (k,) sigma_min / sigma_max
    singular: np.ndarray | None = None  # (k,) sigma_min below the singular threshold

    def to_dict(self) -> dict:
        """JSON (docs/json.md): one row per pair; ``z_len`` and the angles in degrees,
        ``R = Rz(gamma) Ry(beta) Rx(alpha)``."""
        return {
            "euler_sequence": EULER_SEQUENCE,
            "z_len": self.phi[:, 0].tolist(),
            "alpha_deg": np.degrees(self.phi[:, 1]).tolist(),
            "beta_deg": np.degrees(self.phi[:, 2]).tolist(),
            "gamma_deg": np.degrees(self.phi[:, 3]).tolist(),
            "converged": self.converged.tolist(),
            "iterations": self.iterations.tolist(),
            "residual_len": self.residual.tolist(),
            "status": [str(v) for v in self.status],
            "within_limits": self.within_limits.tolist(),
            "sigma_min": None if self.sigma_min is None else self.sigma_min.tolist(),
            "condition": None if self.condition is None else self.condition.tolist(),
            "singular": None if self.singular is None else self.singular.tolist(),
        }


def forward_batch(
    l,
    seeds,
    *,
    geometry: FourSpsCuGeometry = PAPER_B,
    tol: float = 1e-12,
    max_iter: int = 200,
) -> ForwardBatch:
    """Forward position for a batch: leg lengths ``l`` (k, 4) or (4,) and ``seeds`` (k, 4).

    The same Levenberg-Marquardt iteration as :func:`forward`, vectorised over the rows (the
    hot path for tracking and workspace scans).  Rows that do not converge are flagged.
    """
    seeds = as_finite_array(seeds, "seeds")
    if seeds.ndim != 2 or seeds.shape[1] != 4:
        raise InputError(f"seeds: expected shape (k, 4) ordered (z, alpha, beta, gamma), got {seeds.shape}")
    l = as_finite_array(l, "l")
    if l.shape not in ((4,), seeds.shape):
        raise InputError(f"l: expected shape (4,) or {seeds.shape} like seeds, got {l.shape}")
    if np.any(l <= 0):
        raise InputError("l: leg lengths must be positive")
    _check_solver(tol, max_iter)
    phi, conv, iters, res, status = _lm_batch(l, seeds, geometry, tol, max_iter)
    phi = _canonical(phi)
    lb = np.broadcast_to(l, seeds.shape)
    legs_ok = np.all((lb >= geometry.leg_limits[0]) & (lb <= geometry.leg_limits[1]), axis=-1)
    z_ok = (phi[:, 0] >= geometry.z_limits[0]) & (phi[:, 0] <= geometry.z_limits[1])
    sig, cond = conditioning(phi, geometry)
    sing = sig < singular_threshold(tol / geometry.length_scale)
    return ForwardBatch(phi, conv, iters, res, tuple(_STATUS[int(c)] for c in status), legs_ok & z_ok, sig, cond, sing)


@dataclass(frozen=True)
class ForwardSearch:
    """How :func:`forward_all` searched (so that a reader can judge its completeness)."""

    method: str
    sequence: str
    n_seeds: int
    box: dict
    tol_m: float
    max_iter: int
    dedup_tol: float
    n_converged: int
    n_distinct: int
    hits: tuple[int, ...] = field(default=())  # seeds that converged to each distinct solution
    n_regular: int = 0
    n_singular: int = 0  # isolated singular roots (assembly modes meeting)
    n_self_motion_sets: int = 0  # continua of poses with the legs held

    def to_dict(self) -> dict:
        """JSON (docs/json.md): the search box in the model's length unit and degrees."""
        box = {}
        for k, (lo, hi) in self.box.items():
            name, unit = k.rsplit("_", 1)
            box[f"{name}_deg" if unit == "rad" else f"{name}_len"] = (
                [float(np.degrees(lo)), float(np.degrees(hi))] if unit == "rad" else [float(lo), float(hi)])
        return {
            "method": self.method,
            "sequence": self.sequence,
            "n_seeds": self.n_seeds,
            "box": box,
            "tol_len": self.tol_m,
            "max_iter": self.max_iter,
            "dedup_tol": self.dedup_tol,
            "n_converged": self.n_converged,
            "n_distinct": self.n_distinct,
            "hits": list(self.hits),
            "n_regular": self.n_regular,
            "n_singular": self.n_singular,
            "n_self_motion_sets": self.n_self_motion_sets,
            "limits_checked": "leg lengths and CU length z (joint-angle limits of eqs 18-21 not checked)",
        }


@dataclass(frozen=True, eq=False)
class ForwardAllResult:
    """All distinct real assembly modes found for one leg-length vector, within limits first."""

    leg_lengths: np.ndarray
    solutions: tuple[ForwardResult, ...]
    search: ForwardSearch

    @property
    def n_within_limits(self) -> int:
        return sum(s.within_limits for s in self.solutions)

    @property
    def phis(self) -> np.ndarray:
        return np.array([s.phi for s in self.solutions]).reshape(-1, 4)

    def to_dict(self, *, actuators=None) -> dict:
        """JSON (docs/json.md), the same fields as the general engine's
        (:meth:`spatialmech.kinematics.forward.ForwardResult.to_dict`): the leg lengths held as
        ``actuators_len`` (named by ``actuators``, default ``l1..l4``), the distinct assembly
        modes and the search."""
        names = _leg_names(actuators)
        return {
            "method": "closed form of the 4-SPS/CU (kinematics/closed_forms/four_sps_cu.py)",
            "actuators_deg": {},
            "actuators_len": {n: float(v) for n, v in zip(names, self.leg_lengths, strict=True)},
            "n_solutions": len(self.solutions),
            "n_within_limits": self.n_within_limits,
            "solutions": [s.to_dict(actuators=names) for s in self.solutions],
            "search": self.search.to_dict(),
        }


def forward_all(
    l,
    *,
    geometry: FourSpsCuGeometry = PAPER_B,
    n_seeds: int = 512,
    qmc_seed: int = 0,
    tol: float = 1e-12,
    max_iter: int = 500,
    dedup_tol: float | None = None,
) -> ForwardAllResult:
    """All real assembly modes it can find for leg lengths ``l`` (4,) [m].

    Deterministic multi-seed search: ``n_seeds`` points of a scrambled Halton sequence
    (``scipy.stats.qmc``, seed ``qmc_seed``) over the box ``|z| <= max(l) + sqrt(2) a`` (every
    root lies inside: ``|z| <= l_i + |R A_i|``), ``alpha, gamma`` in ``[-pi, pi]``, ``beta`` in
    ``[-pi/2, pi/2]`` (this covers every orientation), each solved by the vectorised
    Levenberg-Marquardt iteration of :func:`forward`; converged roots closer than ``dedup_tol``
    (default: the ``dedup`` tolerance) in scale-free pose distance are one; singular roots
    are followed along their self-motion with the legs held and all roots on one continuum are
    one result of kind ``self-motion`` (:mod:`spatialmech.kinematics.assembly`).  Mirror roots ``(-z, -alpha,
    -beta, gamma)`` are real assembly modes too and are reported (outside the CU limits).
    A multi-seed search cannot prove completeness: ``search.hits`` says how many seeds reached
    each result.  Roots near the singular set ``alpha = beta = 0`` are reached slowly (LM
    converges linearly in their narrow valleys), hence the larger default ``max_iter``; e.g.
    for the legs of ``(0.256, 0.0085, 0.0077, -0.791)`` 256 seeds find all 8 roots with
    ``max_iter=500`` but only 5 with 200.  Solutions are sorted: within limits first, then by decreasing ``z``.
    """
    l = _leg_input(l, geometry)
    _check_solver(tol, max_iter)
    if int(n_seeds) < 1:
        raise InputError(f"n_seeds: expected a positive integer, got {n_seeds}")
    n_seeds = int(n_seeds)
    zmax = float(np.max(l) + np.sqrt(2.0) * geometry.a)
    box = {
        "z_m": (-zmax, zmax),
        "alpha_rad": (-np.pi, np.pi),
        "beta_rad": (-np.pi / 2, np.pi / 2),
        "gamma_rad": (-np.pi, np.pi),
    }
    lo = np.array([v[0] for v in box.values()])
    hi = np.array([v[1] for v in box.values()])
    from scipy.stats import qmc  # imported here: scipy.stats is slow to import

    u = qmc.Halton(d=4, scramble=True, seed=qmc_seed).random(n_seeds)
    seeds = lo + u * (hi - lo)
    phi, conv, iters, res, status = _lm_batch(l, seeds, geometry, tol, max_iter)
    idx = np.flatnonzero(conv)
    canon = _canonical(phi[idx]) if idx.size else np.zeros((0, 4))
    roots = _results(l, canon, conv[idx], iters[idx], res[idx], status[idx], seeds[idx], geometry, tol)
    dedup = current().dedup if dedup_tol is None else float(dedup_tol)
    sols = _classify(l, roots, geometry, tol, dedup)
    order = sorted(range(len(sols)), key=lambda i: (not sols[i].within_limits, -sols[i].phi[0]))
    kinds = [s.kind for s in sols]
    search = ForwardSearch(
        method="multi-seed Levenberg-Marquardt (batched, Nielsen damping) on (l(phi)^2 - l^2)/2 = 0; roots "
        "de-duplicated by pose distance sqrt(|dz / b|^2 + (2 sin(theta / 2))^2), singular roots on one traced "
        "self-motion counted once",
        sequence=f"scrambled Halton (scipy.stats.qmc), seed {qmc_seed}",
        n_seeds=n_seeds,
        box=box,
        tol_m=tol,
        max_iter=max_iter,
        dedup_tol=dedup,
        n_converged=int(idx.size),
        n_distinct=len(sols),
        hits=tuple(sols[i].members for i in order),
        n_regular=kinds.count(AssemblyKind.REGULAR),
        n_singular=kinds.count(AssemblyKind.SINGULAR),
        n_self_motion_sets=kinds.count(AssemblyKind.SELF_MOTION),
    )
    return ForwardAllResult(l.copy(), tuple(sols[i] for i in order), search)
