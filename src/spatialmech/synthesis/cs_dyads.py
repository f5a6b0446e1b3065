"""Seven-position synthesis of CS dyads and 5-CS linkages (paper A, section 3, eqs 22-26).

A CS dyad joins the base to the platform: a cylindrical joint C on the base (unit axis ``u``
through ``B1``) and a spherical joint S whose centre ``M`` is fixed in the platform.  Over the
task positions ``j = 1..7`` (platform displacements ``D_j`` from position 1, ``D_1 = I``):

- eq 22: ``B_j = B1 + s_j u`` (``s_j`` the slide of the C joint, ``s_1 = 0``);
- eq 23: ``M_j = D_j M1`` (homogeneous coordinates: ``M_j = R_j M1 + t_j``);
- eq 24: ``|M_j - B_j|^2 = |M_1 - B_1|^2``, ``j = 2..7`` (6 equations: constant link length);
- eq 25: ``u . (M_j - B_j) = 0``, ``j = 1..7`` (7 equations: the link is perpendicular to the
  C axis);
- eq 26: ``u . u = 1``.

Unknowns ``x = (B1, M1, u, s_2..s_7)``: 15; equations: 14.  Eq 25 at ``j = 1`` pins ``B1`` to the
foot of the perpendicular from ``M1`` to the axis, so there is no gauge freedom left (sliding
``B1`` along ``u`` would break it), and the Jacobian has full rank 14 at generic solutions: the
solution set is a curve (paper: "infinitely many CS dyads", a one-parameter family).  The same
count, geometrically: the seven points ``M_j(M1)`` must lie on one circular cylinder, the C
axis being its axis: ``3 (M1) + 5 (cylinder: axis 4 + radius 1) - 7 = 1``.  Every dyad appears
twice in ``x``-space, as ``(u, s)`` and ``(-u, -s)``; branches are deduplicated up to that flip.

Method (general for any seven positions):

1. seeded multi-start least squares (:func:`scipy.optimize.least_squares`) from random dyads
   around the task lands on the solution curve;
2. each new start is followed both ways by the project's pseudo-arclength continuation
   (:func:`spatialmech.kinematics.tracking.track` on an
   :class:`~spatialmech.kinematics.tracking.EuclideanProblem` ``F: R^15 -> R^14``), until the
   branch closes or leaves a box of ``extent`` task scales around the task;
3. "choose dyads with small slides" (paper A, section 1): the points of the family with the
   smallest ``max_j |s_j|`` (local minima refined along the curve), greedily picked so that
   they are well separated along the family;
4. any five dyads form a 5-CS linkage (:func:`spatialmech.synthesis.five_cs.assemble_5cs`),
   checked by solving its closure at the seven positions and by its mobility
   (:func:`spatialmech.synthesis.five_cs.check_5cs`); :mod:`.five_cs` also checks paper A's
   section 3 claims.

Internally the unknowns are nondimensional (points relative to the centroid of the task
points, lengths divided by the task scale ``L`` = RMS distance of the task points from their
centroid); everything returned is in the task's length unit.  Angles in radians inside,
``*_deg`` keys in degrees.

Example (paper A table 9)::

    >>> from spatialmech.catalog.papers import five_cs_positions
    >>> from spatialmech.synthesis.five_cs import assemble_5cs, check_5cs
    >>> fam = synthesize_cs(five_cs_positions(), seed=0)
    >>> len(fam.branches), [round(p.max_abs_slide, 2) for p in fam.picks]
    (9, [5.3, 9.76, 10.9, 11.18, 11.81])
    >>> check_5cs(assemble_5cs(fam.task, fam.picks)).dof
    1
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import InputError
from ..geometry.rotations import inverse_transform, rotation_angle, transform
from ..geometry.validate import as_finite_array, as_unit_vector
from ..kinematics import backend
from ..kinematics.tracking import EuclideanProblem, conventional_sense, correct_on_hyperplane, track
from ..model.mechanism import Pose
from ..results import BranchEnd
from ..serialize import fields_dict

__all__ = [
    "N_POSITIONS",
    "CSBranch",
    "CSDyad",
    "CSFamily",
    "CSTask",
    "Projection",
    "cs_task",
    "dyad_from_limb",
    "dyad_from_vector",
    "dyad_jacobian",
    "dyad_residual",
    "pick_small_slides",
    "project_dyad",
    "solve_dyad",
    "synthesize_cs",
    "trace_branch",
]

#: Number of task positions of the method (15 unknowns, 14 equations).
N_POSITIONS = 7
_NX = 15  # unknowns
_NF = 14  # equations
_TOL = 1e-11  # nondimensional residual of a solution


# ------------------------------------------------------------------------------ the task
@dataclass(frozen=True, eq=False)
class CSTask:
    """Seven task poses with their displacements from position 1 and the internal scaling.

    ``poses`` are the platform poses as given (``R_j``, the platform point ``p_j``);
    ``D[j] = T_j T_1^-1`` (4x4, ``T_j = transform(R_j, p_j)``) maps a platform point at
    position 1 to its place at position ``j`` (eq 23; ``D[0] = I``).  ``centre`` and
    ``scale`` define the nondimensional coordinates ``(X - centre) / scale``.
    """

    poses: tuple[Pose, ...]
    D: np.ndarray
    centre: np.ndarray
    scale: float

    @property
    def n(self) -> int:
        return len(self.poses)

    @cached_property
    def relative_poses(self) -> tuple[Pose, ...]:
        """The poses relative to position 1: ``Pose(R_j R_1^T, p_j)`` (the mechanism's reference
        configuration is position 1; equal to ``poses`` when ``R_1 = I``, as in table 9; made
        once: every linkage of a screen shares them)."""
        R1 = self.poses[0].R
        return tuple(Pose(P.R @ R1.T, P.p, name=P.name or f"P{j + 1}") for j, P in enumerate(self.poses))

    @property
    def reference_point(self) -> np.ndarray:
        return self.poses[0].p

    def nondim_D(self) -> np.ndarray:
        """``D`` in nondimensional coordinates."""
        c, L = self.centre, self.scale
        R = self.D[:, :3, :3]
        t = (self.D[:, :3, 3] + np.einsum("jab,b->ja", R, c) - c) / L
        out = self.D.copy()
        out[:, :3, 3] = t
        return out

    def to_dict(self) -> dict:
        return {
            "positions": [
                {"name": P.name, "point_len": P.p.tolist(),
                 "rotation_vector_deg": np.degrees(_rotvec(P.R)).tolist()}
                for P in self.poses
            ],
            "scale_len": self.scale,
            "centre_len": self.centre.tolist(),
        }


def _rotvec(R: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(R).as_rotvec()


def cs_task(task_poses: Sequence[Pose] | CSTask) -> CSTask:
    """Validate seven platform poses and build the :class:`CSTask` (``ValueError`` naming
    ``task_poses`` otherwise)."""
    if isinstance(task_poses, CSTask):
        return task_poses
    poses = tuple(task_poses)
    if len(poses) != N_POSITIONS:
        raise InputError(
            f"task_poses: seven-position CS synthesis needs exactly {N_POSITIONS} poses, got {len(poses)}"
            " (fewer leave a surface of dyads, more leave finitely many or none)"
        )
    for j, P in enumerate(poses):
        if not isinstance(P, Pose):
            raise InputError(f"task_poses[{j}]: expected a Pose, got {type(P).__name__}")
    T = np.array([transform(P.R, P.p) for P in poses])
    T1inv = inverse_transform(T[0])
    D = T @ T1inv
    pts = np.array([P.p for P in poses])
    centre = pts.mean(axis=0)
    scale = float(np.sqrt(np.mean(np.sum((pts - centre) ** 2, axis=1))))
    rot = max(float(rotation_angle(P.R @ poses[0].R.T)) for P in poses)
    if scale < 1e-12 and rot < 1e-12:
        raise InputError("task_poses: all seven poses coincide")
    if scale < 1e-12:
        scale = 1.0
    return CSTask(poses, D, centre, scale)


# ------------------------------------------------------------------------------ equations
def _split(x: np.ndarray):
    return x[..., 0:3], x[..., 3:6], x[..., 6:9], x[..., 9:15]


def _link_vectors(x: np.ndarray, D: np.ndarray):
    """``d_j = M_j - B_j`` for every position: shape (..., 7, 3), and the slides (..., 7)."""
    B1, M1, u, s = _split(x)
    s_all = np.concatenate([np.zeros((*s.shape[:-1], 1)), s], axis=-1)
    Mj = np.einsum("jab,...b->...ja", D[:, :3, :3], M1) + D[:, :3, 3]
    d = Mj - B1[..., None, :] - s_all[..., :, None] * u[..., None, :]
    return d, s_all


def _dyad_system_py(x, D, want_J, r, J):
    """:func:`dyad_residual` (into ``r``) and, when ``want_J``, :func:`dyad_jacobian` (into
    ``J``, which must be zero) of one dyad ``x`` (15,), compiled by :func:`_dyad_system` on first
    use: the same sums in the same order."""
    B1, M1, u = x[0:3], x[3:6], x[6:9]
    d = np.empty((7, 3))
    s_all = np.zeros(7)
    for j in range(1, 7):
        s_all[j] = x[8 + j]
    for j in range(7):
        for a in range(3):
            Mj = D[j, a, 0] * M1[0] + D[j, a, 1] * M1[1] + D[j, a, 2] * M1[2] + D[j, a, 3]
            d[j, a] = Mj - B1[a] - s_all[j] * u[a]
    n2 = np.empty(7)
    du = np.empty(7)
    for j in range(7):
        n2[j] = d[j, 0] * d[j, 0] + d[j, 1] * d[j, 1] + d[j, 2] * d[j, 2]
        du[j] = d[j, 0] * u[0] + d[j, 1] * u[1] + d[j, 2] * u[2]
    uu = u[0] * u[0] + u[1] * u[1] + u[2] * u[2]
    for j in range(6):
        r[j] = n2[j + 1] - n2[0]
    for j in range(7):
        r[6 + j] = du[j]
    r[13] = uu - 1.0
    if not want_J:
        return
    for k in range(6):
        j = k + 1
        for b in range(3):
            gM_j = 2 * (d[j, 0] * D[j, 0, b] + d[j, 1] * D[j, 1, b] + d[j, 2] * D[j, 2, b])
            gM_0 = 2 * (d[0, 0] * D[0, 0, b] + d[0, 1] * D[0, 1, b] + d[0, 2] * D[0, 2, b])
            J[k, b] = -2 * d[j, b] - (-2 * d[0, b])
            J[k, 3 + b] = gM_j - gM_0
            J[k, 6 + b] = -2 * s_all[j] * d[j, b] - (-2 * s_all[0] * d[0, b])
        J[k, 9 + k] = -2 * du[j]
    for j in range(7):
        for b in range(3):
            J[6 + j, b] = -u[b]
            J[6 + j, 3 + b] = u[0] * D[j, 0, b] + u[1] * D[j, 1, b] + u[2] * D[j, 2, b]
            J[6 + j, 6 + b] = d[j, b] - s_all[j] * u[b]
    for k in range(6):
        J[7 + k, 9 + k] = -uu
    for b in range(3):
        J[13, 6 + b] = 2 * u[b]


@functools.cache
def _dyad_system():
    """:func:`_dyad_system_py` compiled (numba, ``cache=True``), on first use: importing this
    module loads no numba.  Called only where :func:`_one_dyad` (the compiled engine is on)."""
    from ..kinematics.compiled.jit import njit

    return njit(cache=True)(_dyad_system_py)


def _one_dyad(x, D) -> bool:
    """True when the compiled single-dyad kernel serves this call."""
    return backend.enabled() and x.shape == (_NX,) and D.shape == (N_POSITIONS, 4, 4)


def dyad_residual(x, D) -> np.ndarray:
    """Residual of eqs 24-26 (paper A) for dyads ``x = (B1, M1, u, s2..s7)``.

    ``x``: (..., 15); ``D``: (7, 4, 4) displacements from position 1.  Returns (..., 14):
    ``|d_j|^2 - |d_1|^2`` (j = 2..7, eq 24), ``u . d_j`` (j = 1..7, eq 25), ``u . u - 1``
    (eq 26), with ``d_j = D_j M1 - B1 - s_j u``.  Units: the coordinates of ``x`` and ``D``
    (length^2, length, 1).  Vectorised over leading axes.
    """
    x = np.asarray(x, dtype=float)
    D = np.asarray(D, dtype=float)
    if _one_dyad(x, D):
        r = np.empty(_NF)
        _dyad_system()(x, D, False, r, np.empty((0, 0)))
        return r
    d, _ = _link_vectors(x, D)
    u = x[..., 6:9]
    n2 = np.einsum("...ja,...ja->...j", d, d)
    e24 = n2[..., 1:] - n2[..., :1]
    e25 = np.einsum("...ja,...a->...j", d, u)
    e26 = np.einsum("...a,...a->...", u, u)[..., None] - 1.0
    return np.concatenate([e24, e25, e26], axis=-1)


def dyad_jacobian(x, D) -> np.ndarray:
    """Jacobian of :func:`dyad_residual` with respect to ``x``: (..., 14, 15)."""
    x = np.asarray(x, dtype=float)
    D = np.asarray(D, dtype=float)
    if _one_dyad(x, D):
        J1 = np.zeros((_NF, _NX))
        _dyad_system()(x, D, True, np.empty(_NF), J1)
        return J1
    d, s_all = _link_vectors(x, D)
    u = x[..., 6:9]
    R = D[:, :3, :3]
    lead = x.shape[:-1]
    J = np.zeros((*lead, _NF, _NX))
    # derivatives of d_j: dM1 -> R_j, dB1 -> -I, du -> -s_j I, ds_j -> -u (j >= 2)
    gM = 2 * np.einsum("...ja,jab->...jb", d, R)  # grad of |d_j|^2 wrt M1
    gB = -2 * d
    gu = -2 * s_all[..., None] * d
    J[..., 0:6, 0:3] = gB[..., 1:, :] - gB[..., :1, :]
    J[..., 0:6, 3:6] = gM[..., 1:, :] - gM[..., :1, :]
    J[..., 0:6, 6:9] = gu[..., 1:, :] - gu[..., :1, :]
    for k in range(6):  # d|d_{k+2}|^2 / ds_{k+2} = -2 d . u
        J[..., k, 9 + k] = -2 * np.einsum("...a,...a->...", d[..., k + 1, :], u)
    # eq 25: u . d_j
    J[..., 6:13, 0:3] = -u[..., None, :]
    J[..., 6:13, 3:6] = np.einsum("...a,jab->...jb", u, R)
    J[..., 6:13, 6:9] = d - s_all[..., None] * u[..., None, :]
    uu = np.einsum("...a,...a->...", u, u)
    for k in range(6):
        J[..., 7 + k, 9 + k] = -uu
    J[..., 13, 6:9] = 2 * u
    return J


# ------------------------------------------------------------------------------ dyads
@dataclass(frozen=True, eq=False)
class CSDyad:
    """One CS dyad (task length unit): C axis ``u`` (unit) through ``B1`` (the foot of the
    perpendicular from ``M1``: the C joint at position 1), S centre ``M1`` at position 1,
    ``slides[j]`` = ``s_{j+1}`` (``slides[0] = 0``), link length ``|M1 - B1|``, and the
    largest residual of eqs 24-25 over the positions (length unit)."""

    u: np.ndarray
    B1: np.ndarray
    M1: np.ndarray
    slides: np.ndarray
    link_length: float
    residual: float

    @property
    def max_abs_slide(self) -> float:
        return float(np.max(np.abs(self.slides)))

    @property
    def vector(self) -> np.ndarray:
        """``x = (B1, M1, u, s2..s7)`` in the task's length unit."""
        return np.r_[self.B1, self.M1, self.u, self.slides[1:]]

    def flipped(self) -> CSDyad:
        """The same dyad with ``u -> -u`` (slides change sign)."""
        return CSDyad(-self.u, self.B1, self.M1, -self.slides, self.link_length, self.residual)

    def to_dict(self) -> dict:
        """JSON (docs/json.md): ``u`` unit direction; ``B1_len``, ``M1_len``, the link length,
        slides and ``residual_len`` (largest error of eqs 24-25, a length) in the task unit."""
        lengths = ("B1", "M1", "link_length", "slides", "max_abs_slide", "residual")
        return fields_dict(self, {n: f"{n}_len" for n in lengths}, names=("u", *lengths))


def _dyad_errors(x_phys: np.ndarray, task: CSTask) -> float:
    """Largest |eq 24| (as a length difference) and |eq 25| of a dyad in the task unit."""
    d, _ = _link_vectors(x_phys, task.D)
    n = np.linalg.norm(d, axis=-1)
    u = x_phys[6:9]
    return float(max(np.max(np.abs(n - n[0])), np.max(np.abs(d @ u)), abs(u @ u - 1.0)))


def _to_phys(task: CSTask, y: np.ndarray) -> np.ndarray:
    c, L = task.centre, task.scale
    y = np.asarray(y, dtype=float)
    return np.concatenate([y[..., 0:3] * L + c, y[..., 3:6] * L + c, y[..., 6:9], y[..., 9:15] * L], axis=-1)


def _to_nondim(task: CSTask, x: np.ndarray) -> np.ndarray:
    c, L = task.centre, task.scale
    x = np.asarray(x, dtype=float)
    return np.concatenate([(x[..., 0:3] - c) / L, (x[..., 3:6] - c) / L, x[..., 6:9], x[..., 9:15] / L], axis=-1)


def _dyad(task: CSTask, x_phys: np.ndarray) -> CSDyad:
    B1, M1, u, s = _split(np.asarray(x_phys, dtype=float))
    return CSDyad(
        u=np.array(u), B1=np.array(B1), M1=np.array(M1), slides=np.r_[0.0, s],
        link_length=float(np.linalg.norm(M1 - B1)), residual=_dyad_errors(x_phys, task),
    )


def dyad_from_vector(task_poses, x) -> CSDyad:
    """The :class:`CSDyad` of a family point ``x = (B1, M1, u, s2..s7)`` in the task's length unit
    (as in :attr:`CSBranch.points`); ``residual`` says how well it satisfies eqs 24-25."""
    task = cs_task(task_poses)
    x = as_finite_array(x, "x", shape=(_NX,))
    return _dyad(task, x)


def dyad_from_limb(task_poses, u, B1, M1, slides=None) -> CSDyad:
    """A :class:`CSDyad` from given (e.g. printed) limb data: ``u`` is normalised, ``slides``
    (7 values, ``s_1`` first, or 6 values ``s_2..s_7``) default to the feet of the
    perpendiculars from ``M_j`` (least-squares slides).  ``residual`` says how far the data is
    from satisfying eqs 24-25."""
    task = cs_task(task_poses)
    u = as_unit_vector(u, "u", normalize=True)
    B1 = as_finite_array(B1, "B1", shape=(3,))
    M1 = as_finite_array(M1, "M1", shape=(3,))
    if slides is None:
        Mj = task.D[:, :3, :3] @ M1 + task.D[:, :3, 3]
        s = (Mj - B1) @ u
        s = s - s[0]
    else:
        s = as_finite_array(slides, "slides")
        if s.shape == (6,):
            s = np.r_[0.0, s]
        if s.shape != (7,):
            raise InputError(f"slides: expected 7 values (s1..s7) or 6 (s2..s7), got shape {s.shape}")
    return _dyad(task, np.r_[B1, M1, u, s[1:]])


# ------------------------------------------------------------------------------ solving
def _problem(task: CSTask) -> EuclideanProblem:
    Dn = task.nondim_D()
    return EuclideanProblem(lambda y: dyad_residual(y, Dn), lambda y: dyad_jacobian(y, Dn))


def _random_guesses(task: CSTask, n: int, rng: np.random.Generator) -> np.ndarray:
    """Random nondimensional dyads near the task: M1 normal around the task centroid (1.5 task
    scales), a random axis at a log-uniform distance in [0.1, 5] task scales (dyads with long
    links are found too), slides = feet of the perpendiculars (only the cylinder condition is
    off)."""
    Dn = task.nondim_D()
    out = np.empty((n, _NX))
    for i in range(n):
        M1 = rng.normal(scale=1.5, size=3)
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        w = np.cross(u, rng.normal(size=3))
        w /= np.linalg.norm(w)
        B1 = M1 - np.exp(rng.uniform(np.log(0.1), np.log(5.0))) * w
        Mj = Dn[:, :3, :3] @ M1 + Dn[:, :3, 3]
        s = (Mj - B1) @ u
        out[i] = np.r_[B1, M1, u, s[1:] - s[0]]
    return out


def solve_dyad(task_poses, x0, *, nondimensional: bool = False) -> tuple[np.ndarray, bool, float]:
    """Least squares on eqs 24-26 from ``x0`` (15 values; physical units unless
    ``nondimensional``).  Returns ``(x, converged, residual norm)`` in the same units;
    ``converged`` means a nondimensional residual below 1e-11."""
    task = cs_task(task_poses)
    x0 = as_finite_array(x0, "x0", shape=(_NX,))
    y0 = x0 if nondimensional else _to_nondim(task, x0)
    prob = _problem(task)
    from scipy.optimize import least_squares  # on first use: a screen's workers never synthesise

    sol = least_squares(prob.residual, y0, jac=prob.jacobian, method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15,
                        max_nfev=200)
    y = sol.x
    y, ok, _, _ = _newton_min_norm(prob, y)
    rn = float(np.linalg.norm(prob.residual(y)))
    return (y if nondimensional else _to_phys(task, y)), bool(ok and rn < _TOL), rn


def _newton_min_norm(prob, y, tol=_TOL, max_iter=30):
    """Gauss-Newton with minimum-norm steps onto ``F = 0`` (the nearest point to first order)."""
    for it in range(max_iter):
        r = prob.residual(y)
        if np.linalg.norm(r) < tol:
            return y, True, it, 0.0
        dy, *_ = np.linalg.lstsq(prob.jacobian(y), -r, rcond=None)
        y = y + dy
    return y, bool(np.linalg.norm(prob.residual(y)) < tol), max_iter, 0.0


def _flip(y: np.ndarray) -> np.ndarray:
    z = np.array(y, dtype=float, copy=True)
    z[..., 6:9] *= -1
    z[..., 9:15] *= -1
    return z


def _polyline_distance(P: np.ndarray, y: np.ndarray) -> float:
    """Distance from ``y`` to the polyline through the rows of ``P``."""
    if len(P) == 1:
        return float(np.linalg.norm(P[0] - y))
    a, b = P[:-1], P[1:]
    ab = b - a
    t = np.clip(np.einsum("ka,ka->k", y - a, ab) / np.maximum(np.einsum("ka,ka->k", ab, ab), 1e-300), 0, 1)
    q = a + t[:, None] * ab
    return float(np.min(np.linalg.norm(q - y, axis=1)))


# ------------------------------------------------------------------------------ the family
@dataclass(frozen=True, eq=False)
class CSBranch:
    """One connected piece of the family (in the tracked sense of ``u``).

    ``points``: (K, 15) dyads ``x = (B1, M1, u, s2..s7)`` in the task unit; ``arc``: (K,)
    nondimensional arc length along the curve; ``closed``: the branch is a loop; ``ends``: why
    tracking stopped at each end (:class:`~spatialmech.results.BranchEnd`: "closed", "left the
    box", "h_min" = a singular point of the family, "max_arc")."""

    points: np.ndarray
    arc: np.ndarray
    closed: bool
    ends: tuple[BranchEnd, BranchEnd]
    residual: float  # largest nondimensional residual over the points

    @property
    def max_abs_slide(self) -> np.ndarray:
        return np.max(np.abs(self.points[:, 9:15]), axis=1)

    @property
    def link_length(self) -> np.ndarray:
        return np.linalg.norm(self.points[:, 3:6] - self.points[:, 0:3], axis=1)

    def sample(self, n: int) -> np.ndarray:
        """Indices of ``n`` points spread evenly in arc length (both ends included)."""
        n = max(2, int(n))
        if len(self.arc) <= n:
            return np.arange(len(self.arc))
        targets = np.linspace(self.arc[0], self.arc[-1], n)
        return np.unique(np.clip(np.searchsorted(self.arc, targets), 0, len(self.arc) - 1))

    def to_dict(self, samples: int | None = None) -> dict:
        idx = np.arange(len(self.arc)) if samples is None else self.sample(samples)
        P = self.points[idx]
        return {
            "closed": self.closed,
            "ends": list(self.ends),
            "n_points": len(self.arc),
            "arc_length": float(self.arc[-1] - self.arc[0]),
            "residual": self.residual,
            "min_max_abs_slide_len": float(np.min(self.max_abs_slide)),
            "points": [
                {"arc": float(self.arc[i]), "u": p[6:9].tolist(), "B1_len": p[0:3].tolist(), "M1_len": p[3:6].tolist(),
                 "link_length_len": float(np.linalg.norm(p[3:6] - p[0:3])),
                 "slides_len": [0.0, *p[9:15].tolist()], "max_abs_slide_len": float(np.max(np.abs(p[9:15])))}
                for i, p in zip(idx, P, strict=True)
            ],
        }


@dataclass(frozen=True, eq=False)
class CSFamily:
    """The one-parameter family of CS dyads of seven positions, and the picked dyads.

    ``starts``: how many random starts were tried / converged / were new; ``picks``: dyads with
    the smallest ``max |slide|``, well separated along the family (see
    :func:`pick_small_slides`)."""

    task: CSTask
    branches: tuple[CSBranch, ...]
    picks: tuple[CSDyad, ...]
    starts: dict
    extent: float

    @property
    def n_points(self) -> int:
        return int(sum(len(b.arc) for b in self.branches))

    def all_points(self) -> np.ndarray:
        return np.concatenate([b.points for b in self.branches]) if self.branches else np.zeros((0, _NX))

    def dyad(self, branch: int, index: int) -> CSDyad:
        return _dyad(self.task, self.branches[branch].points[index])

    def to_dict(self, samples: int | None = 40) -> dict:
        """JSON-ready: about ``samples`` points in all, spread over the branches by arc length
        (``None``: every tracked point)."""
        total = sum(float(b.arc[-1] - b.arc[0]) for b in self.branches) or 1.0
        brs = []
        for b in self.branches:
            n = None if samples is None else max(2, round(samples * float(b.arc[-1] - b.arc[0]) / total))
            brs.append(b.to_dict(n))
        return {
            "method": "paper A eqs 22-26: 15 unknowns (B1, M1, u, s2..s7), 14 equations -> a curve of dyads",
            "task": self.task.to_dict(),
            "extent": self.extent,
            "starts": {{"tried": "n_tried", "converged": "n_converged", "new_branches": "n_new_branches"}.get(k, k): v
                       for k, v in self.starts.items()},
            "n_branches": len(self.branches),
            "branches": brs,
            "picks": [p.to_dict() for p in self.picks],
        }


def _trace(prob, y0, *, h_max, max_arc, box):
    """Track both ways from ``y0``; returns (points, arc, closed, ends)."""
    def out(y, s):
        return bool(np.max(np.abs(y[:6])) > box or np.max(np.abs(y[9:])) > box)

    kw = dict(h0=0.01, h_max=h_max, h_min=1e-9, max_arc=max_arc, tol=_TOL, stop=out, max_steps=20000)
    t0 = prob.tangent(y0)
    t0 = t0 * conventional_sense(t0)  # forward: the documented sense, not the SVD's sign
    fwd = track(prob, y0, direction=t0, **kw)

    def why(r) -> BranchEnd:
        if r.status == "stopped":
            return BranchEnd.LEFT_BOX
        return BranchEnd(r.status)

    if fwd.closed:
        P = np.array(fwd.points)
        return P, np.asarray(fwd.s), True, (BranchEnd.CLOSED, BranchEnd.CLOSED)
    bwd = track(prob, y0, direction=-t0, **kw)
    if bwd.closed:  # unlikely: closing only in one sense
        P = np.array(bwd.points)
        return P[::-1], -np.asarray(bwd.s)[::-1], True, (BranchEnd.CLOSED, BranchEnd.CLOSED)
    P = np.concatenate([np.array(bwd.points)[::-1], np.array(fwd.points)[1:]])
    s = np.concatenate([-np.asarray(bwd.s)[::-1], np.asarray(fwd.s)[1:]])
    return P, s, False, (why(bwd), why(fwd))


def trace_branch(task_poses, dyad: CSDyad, *, extent: float = 8.0, h_max: float = 0.05,
                 max_arc: float = 200.0) -> CSBranch:
    """The branch of the family through (the dyad nearest to) ``dyad``: ``dyad`` is first
    solved onto the family by least squares, then tracked both ways (see :func:`synthesize_cs`
    for ``extent``, ``h_max``, ``max_arc``).  ``ValueError`` if it does not converge."""
    task = cs_task(task_poses)
    y, ok, rn = solve_dyad(task, _to_nondim(task, dyad.vector), nondimensional=True)
    if not ok:
        raise InputError(f"dyad: least squares from it did not reach the family (residual {rn:.3g})")
    P, s, closed, ends = _trace(_problem(task), y, h_max=h_max, max_arc=max_arc, box=extent)
    res = float(np.max(np.linalg.norm(dyad_residual(P, task.nondim_D()), axis=-1)))
    return CSBranch(_to_phys(task, P), s - s[0], closed, ends, res)


def synthesize_cs(
    task_poses,
    *,
    n_starts: int = 60,
    seed: int = 0,
    pick: int = 5,
    extent: float = 8.0,
    h_max: float = 0.05,
    max_arc: float = 200.0,
) -> CSFamily:
    """Paper A's seven-position CS dyad synthesis (section 3, eqs 22-26) for any seven poses.

    ``task_poses``: seven :class:`~spatialmech.model.Pose` (platform orientation and the
    platform point's position; position 1 is the mechanism's reference).  ``n_starts`` random
    starts (generator seeded with ``seed``) are solved by least squares; every start not on an
    already traced branch (up to the ``u -> -u`` flip) is tracked both ways until its branch
    closes or leaves the box ``|coordinate| <= extent`` (nondimensional: task scales from the
    centroid of the task points; slides too).  ``h_max``: largest continuation step
    (nondimensional).  ``pick``: how many small-slide dyads to pick (0: none).

    Raises ``ValueError`` for bad input or when no start converges (the status is in the
    message).
    """
    task = cs_task(task_poses)
    if not (isinstance(n_starts, (int, np.integer)) and n_starts >= 1):
        raise InputError(f"n_starts: expected a positive integer, got {n_starts!r}")
    if not (isinstance(pick, (int, np.integer)) and pick >= 0):
        raise InputError(f"pick: expected a non-negative integer, got {pick!r}")
    for nm, v in (("extent", extent), ("h_max", h_max), ("max_arc", max_arc)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{nm}: expected a positive finite number, got {v!r}")
    rng = np.random.default_rng(seed)
    prob = _problem(task)
    branches_nd: list[tuple] = []
    converged = new = 0
    for y0 in _random_guesses(task, n_starts, rng):
        y, ok, _ = solve_dyad(task, y0, nondimensional=True)
        if not ok or np.max(np.abs(y[:6])) > extent or np.max(np.abs(y[9:])) > extent:
            continue
        converged += 1
        near = 0.4 * h_max
        if any(min(_polyline_distance(b[0], y), _polyline_distance(b[0], _flip(y))) < near for b in branches_nd):
            continue
        new += 1
        branches_nd.append(_trace(prob, y, h_max=h_max, max_arc=max_arc, box=extent))
    if not branches_nd:
        raise InputError(f"task_poses: no CS dyad found from {n_starts} random starts (seed {seed}) within extent {extent}")
    branches = []
    for P, s, closed, ends in branches_nd:
        res = float(np.max(np.linalg.norm(dyad_residual(P, task.nondim_D()), axis=-1)))
        branches.append(CSBranch(_to_phys(task, P), s - s[0], closed, ends, res))
    branches.sort(key=lambda b: float(np.min(b.max_abs_slide)))
    fam = CSFamily(task, tuple(branches), (), {"tried": int(n_starts), "converged": converged, "new_branches": new,
                                              "seed": int(seed)}, float(extent))
    if pick:
        fam = CSFamily(task, fam.branches, pick_small_slides(fam, pick), fam.starts, fam.extent)
    return fam


# ------------------------------------------------------------------------------ picking
def _refine_min_slide(task: CSTask, prob, y: np.ndarray, t: np.ndarray, half: float) -> np.ndarray:
    """Minimise ``max |s_j|`` along the curve near ``y`` (tangent ``t``) over ``[-half, half]``."""
    L = task.scale

    def at(sig):
        z, ok, _, _ = correct_on_hyperplane(prob, y + sig * t, t, _TOL, 30)
        return z, ok

    def g(sig):
        z, ok = at(sig)
        return float(np.max(np.abs(z[9:]))) * L if ok else np.inf

    from scipy.optimize import minimize_scalar

    opt = minimize_scalar(g, bounds=(-half, half), method="bounded", options={"xatol": 1e-9})
    z, ok = at(float(opt.x))
    return z if ok and g(float(opt.x)) <= g(0.0) else y


def pick_small_slides(family: CSFamily, n: int = 5, *, separation: float = 1.0) -> tuple[CSDyad, ...]:
    """The ``n`` dyads of the family with the smallest ``max_j |s_j|``, well separated.

    Candidates, in this order of preference: the interior local minima of ``max |s|`` along
    each branch, each refined continuously along the curve (bounded Brent on the arc length,
    every trial point corrected onto the curve), sorted by their value; then every tracked
    point, sorted by its value.  Greedy: take the best candidate, skip any closer than
    ``separation`` to a picked one (nondimensional distance in ``(B1, M1, u, s)``, task scales,
    up to the ``u`` flip), repeat.  Fewer than ``n`` are returned when the family is too short.
    Each picked ``u`` has its largest component positive (the same dyad as ``-u``, ``-s``).
    """
    if not (isinstance(n, (int, np.integer)) and n >= 0):
        raise InputError(f"n: expected a non-negative integer, got {n!r}")
    if not (np.isfinite(separation) and separation >= 0):
        raise InputError(f"separation: expected a non-negative number, got {separation!r}")
    task = family.task
    prob = _problem(task)
    minima, others = [], []
    for b in family.branches:
        Y = _to_nondim(task, b.points)
        g = np.max(np.abs(Y[:, 9:]), axis=1)
        K = len(Y)
        for i in range(K):
            others.append((float(g[i]), Y[i]))
            if b.closed:
                lo, hi = g[(i - 1) % (K - 1)], g[(i + 1) % (K - 1)]
            elif 0 < i < K - 1:
                lo, hi = g[i - 1], g[i + 1]
            else:
                continue  # an open end is where the box cut the branch
            if g[i] <= lo and g[i] <= hi:
                half = max(float(np.linalg.norm(Y[min(i + 1, K - 1)] - Y[max(i - 1, 0)])), 1e-6)
                t = prob.tangent(Y[i])  # Brent's first trials: on the conventional side, not the SVD's
                z = _refine_min_slide(task, prob, Y[i], t * conventional_sense(t), half)
                minima.append((float(np.max(np.abs(z[9:]))), z))
    minima.sort(key=lambda c: c[0])
    others.sort(key=lambda c: c[0])
    picked: list[np.ndarray] = []
    for _, y in minima + others:
        if len(picked) >= n:
            break
        if all(min(np.linalg.norm(y - p), np.linalg.norm(_flip(y) - p)) >= separation for p in picked):
            picked.append(y)
    # the sign of u is a convention: the largest component of u positive
    picked = [_flip(y) if y[6 + int(np.argmax(np.abs(y[6:9])))] < 0 else y for y in picked]
    return tuple(_dyad(task, _to_phys(task, y)) for y in picked)


# ------------------------------------------------------------------------------ projection
@dataclass(frozen=True, eq=False)
class Projection:
    """The dyad of the family nearest to given (printed) limb data, in the printed units:
    minimises ``|x - x_printed|`` over ``(B1, M1, u, s2..s7)`` (u normalised first) subject to
    eqs 24-26.  ``distance`` = that norm; ``*_change`` = the parts of it (length unit; the
    axis change in degrees); ``slide_change`` = max ``|s_j - s_j printed|``."""

    printed: CSDyad
    fitted: CSDyad
    distance: float
    B1_change: float
    M1_change: float
    axis_change_deg: float
    slide_change: float
    link_length_change: float
    converged: bool

    def to_dict(self) -> dict:
        return fields_dict(self, {n: f"{n}_len" for n in ("distance", "B1_change", "M1_change", "slide_change",
                                                          "link_length_change")})


def project_dyad(task_poses, dyad: CSDyad, *, max_iter: int = 100) -> Projection:
    """Nearest point of the dyad family to ``dyad`` (e.g. a printed limb from
    :func:`dyad_from_limb`), by Gauss-Newton for the orthogonal projection onto the solution
    manifold: ``x_{k+1} = x0 - J^+ (F(x_k) - J (x_k - x0))`` in the printed (physical)
    coordinates, so every printed number weighs the same."""
    task = cs_task(task_poses)
    x0 = dyad.vector
    D = task.D
    L = task.scale
    w_eq = np.r_[np.full(6, 1.0 / L**2), np.full(7, 1.0 / L), 1.0]  # equation scaling only
    x = x0.copy()
    ok = False
    for _ in range(max_iter):
        F = w_eq * dyad_residual(x, D)
        J = w_eq[:, None] * dyad_jacobian(x, D)
        x_new = x0 + np.linalg.lstsq(J, -(F - J @ (x - x0)), rcond=None)[0] * 1.0
        step = float(np.linalg.norm(x_new - x))
        x = x_new
        if step < 1e-13 * max(1.0, float(np.linalg.norm(x0))):
            ok = True
            break
    ok = ok and float(np.linalg.norm(w_eq * dyad_residual(x, D))) < 1e-10
    fit = _dyad(task, x)
    return Projection(
        printed=dyad,
        fitted=fit,
        distance=float(np.linalg.norm(x - x0)),
        B1_change=float(np.linalg.norm(fit.B1 - dyad.B1)),
        M1_change=float(np.linalg.norm(fit.M1 - dyad.M1)),
        axis_change_deg=float(np.degrees(np.arccos(np.clip(fit.u @ dyad.u, -1, 1)))),
        slide_change=float(np.max(np.abs(fit.slides - dyad.slides))),
        link_length_change=abs(fit.link_length - dyad.link_length),
        converged=bool(ok),
    )
