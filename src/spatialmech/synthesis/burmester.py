"""Spherical Burmester theory for four orientations (paper D, section 1.2, eqs 8-14).

A dyad of two revolute (or cylindrical) axes keeps its twist angle when its moving axis ``u0``
(a unit vector of the coupler, given at position 1) and its fixed axis ``v`` satisfy the
*direction equations* (paper D eq 3)::

    u0^T (C_j^T - I) v = 0,        j = 1, 2, 3,        C_j = R_{j+1} R_1^T

Written as ``B(u0) v = 0`` with rows ``b_j = (C_j - I) u0`` (eqs 8-9) a solution ``v`` exists iff
``det B(u0) = 0``: a homogeneous cubic in ``u0`` (eq 10), a cubic cone whose trace on the unit
sphere (eq 11) is the **circle-point curve** (eq 12).  Likewise ``A(v) u0 = 0`` with rows
``a_j = (C_j^T - I) v`` (eqs 13-14) gives the **center-point curve** ``det A(v) = 0``.  A point of
one curve determines its partner on the other (the null vector of ``B`` or ``A``): the
*correspondence*.  Both cubics are odd (``f(-x) = -f(x)``): ``x`` and ``-x`` describe the same
axis, so each curve is a plane cubic of the projective plane, with one *pseudo-line* branch
(a loop on the sphere through ``x`` and ``-x``) and possibly one *oval* (two antipodal loops on
the sphere).

Curves are traced by predictor-corrector continuation on the sphere, seeded with every real
root of the cubic on a pencil of great circles (a great circle is a projective line: it meets
the cubic in 1 or 3 real points), so every real branch, ovals included, is found.  Each branch
is returned once (the pseudo-line from ``x`` to ``-x``; one of the two antipodal copies of an
oval), sampled uniformly in arc length, every sample projected onto ``det = 0`` by Newton.

Curve parameter ``t``: integer part = branch index (0 = pseudo-line, 1 = oval when present),
fractional part = arc-length fraction along the branch.  Dimensionless.

The six poles ``P_ik`` (axes of the relative rotations ``R_k R_i^T``, fixed frame) lie on the
center-point curve; the image poles (axes of ``C_k^T C_i``, in the frame of position 1) lie on
the circle-point curve.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np

from ..errors import ConvergenceError, InputError
from ..geometry.rotations import rotation_class
from .tasks import TaskPositions

__all__ = [
    "MONOMIALS",
    "BurmesterCurves",
    "burmester_curves",
    "burmester_det",
    "burmester_gradient",
    "burmester_matrices",
    "center_point",
    "circle_point",
    "cubic_coefficients",
    "poles",
    "project_to_curve",
]

#: The monomials of the cubic (paper D eq 10's H1..H10 order, with eq 10's "H6 y^2" read as
#: the garbled ``H6 x y^2``).
MONOMIALS = ("x^3", "y^3", "z^3", "x^2 y", "x^2 z", "x y^2", "x z^2", "y^2 z", "y z^2", "x y z")
_EXPONENTS = np.array(
    [[3, 0, 0], [0, 3, 0], [0, 0, 3], [2, 1, 0], [2, 0, 1], [1, 2, 0], [1, 0, 2], [0, 2, 1], [0, 1, 2], [1, 1, 1]]
)


def _rotations(task_or_C) -> np.ndarray:
    if isinstance(task_or_C, TaskPositions):
        task_or_C.require(4, "four-orientation Burmester theory")
        C = task_or_C.C
    else:
        C = np.asarray(task_or_C, dtype=float)
    if C.shape != (3, 3, 3):
        raise InputError(f"C: expected three relative rotations (3, 3, 3), got {C.shape}")
    ang = np.linalg.norm(rotation_class().from_matrix(C).as_rotvec(), axis=-1)
    for j in range(3):
        if ang[j] < 1e-9:
            raise InputError(
                f"positions[{j + 1}]: same orientation as position 1: the spherical Burmester"
                " problem is degenerate (every direction is a solution)"
            )
    for j, k in combinations(range(3), 2):
        if np.linalg.norm(rotation_class().from_matrix(C[k] @ C[j].T).as_rotvec()) < 1e-9:
            raise InputError(
                f"positions[{k + 1}]: same orientation as positions[{j + 1}]: the spherical"
                " Burmester problem is degenerate"
            )
    return C


def burmester_matrices(task_or_C, kind: str = "circle") -> np.ndarray:
    """The three matrices ``K_j`` (3, 3, 3): ``C_j - I`` (``kind="circle"``, rows of ``B(u0)``)
    or ``C_j^T - I`` (``kind="center"``, rows of ``A(v)``)."""
    C = _rotations(task_or_C)
    if kind == "circle":
        return C - np.eye(3)
    if kind == "center":
        return np.swapaxes(C, -1, -2) - np.eye(3)
    raise InputError(f"kind: expected 'circle' or 'center', got {kind!r}")


def _rows(K: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("jab,...b->...ja", K, x)  # (..., 3 rows, 3)


def _det_grad(K: np.ndarray, x: np.ndarray):
    b = _rows(K, x)
    b1, b2, b3 = b[..., 0, :], b[..., 1, :], b[..., 2, :]
    c23, c31, c12 = np.cross(b2, b3), np.cross(b3, b1), np.cross(b1, b2)
    f = np.sum(b1 * c23, axis=-1)
    g = (
        np.einsum("ab,...a->...b", K[0], c23)
        + np.einsum("ab,...a->...b", K[1], c31)
        + np.einsum("ab,...a->...b", K[2], c12)
    )
    return f, g


def burmester_det(K: np.ndarray, x) -> np.ndarray:
    """``det [K_1 x, K_2 x, K_3 x]`` (rows), broadcast over leading axes of ``x`` (..., 3).

    With ``K = burmester_matrices(task, "circle")`` this is ``det B(u0)`` (paper D eq 9), with
    ``"center"`` it is ``det A(v)`` (eq 14).  Zero on the curve.
    """
    return _det_grad(np.asarray(K, float), np.asarray(x, float))[0]


def burmester_gradient(K: np.ndarray, x) -> np.ndarray:
    """Gradient of :func:`burmester_det` with respect to ``x`` (..., 3)."""
    return _det_grad(np.asarray(K, float), np.asarray(x, float))[1]


def cubic_coefficients(K: np.ndarray) -> np.ndarray:
    """The ten coefficients ``H1..H10`` of the cubic (paper D eq 10) in :data:`MONOMIALS` order.

    Exact up to rounding: the cubic is interpolated at ten generic points.
    """
    pts = np.random.default_rng(7).standard_normal((10, 3))
    V = np.prod(pts[:, None, :] ** _EXPONENTS[None], axis=-1)
    return np.linalg.solve(V, burmester_det(K, pts))


def project_to_curve(K: np.ndarray, x, *, tol: float = 1e-15, max_iter: int = 30) -> np.ndarray:
    """Newton projection of unit vectors ``x`` (..., 3) onto ``det = 0`` on the unit sphere.

    Steps along the spherical gradient; vectorised; returns unit vectors.
    """
    K = np.asarray(K, float)
    x = np.array(x, dtype=float, copy=True)
    x /= np.linalg.norm(x, axis=-1, keepdims=True)
    for _ in range(max_iter):
        f, g = _det_grad(K, x)
        gt = g - np.sum(g * x, axis=-1, keepdims=True) * x
        gg = np.sum(gt * gt, axis=-1)
        step = np.where(gg[..., None] > 0, (f / np.where(gg > 0, gg, 1.0))[..., None] * gt, 0.0)
        x = x - step
        x /= np.linalg.norm(x, axis=-1, keepdims=True)
        if np.all(np.abs(f) < tol):
            break
    return x


def _null_of_rows(b: np.ndarray) -> np.ndarray:
    """Unit null vector of three (nearly) dependent rows (..., 3, 3): the largest of the three
    pairwise cross products, normalised."""
    cands = np.stack(
        [np.cross(b[..., 1, :], b[..., 2, :]), np.cross(b[..., 2, :], b[..., 0, :]), np.cross(b[..., 0, :], b[..., 1, :])],
        axis=-2,
    )
    n = np.linalg.norm(cands, axis=-1)
    k = np.argmax(n, axis=-1)
    best = np.take_along_axis(cands, k[..., None, None], axis=-2)[..., 0, :]
    nb = np.take_along_axis(n, k[..., None], axis=-1)
    if np.any(nb < 1e-12):
        raise InputError("x: the direction equations have a pencil of solutions here (rank < 2)")
    return best / nb


def center_point(task_or_C, u) -> np.ndarray:
    """The center point ``v`` (fixed axis) of circle point(s) ``u`` (moving axis at position 1):
    the unit null vector of ``B(u)`` (paper D eq 9).  Sign arbitrary (an axis)."""
    K = burmester_matrices(task_or_C, "circle")
    return _null_of_rows(_rows(K, np.asarray(u, float)))


def circle_point(task_or_C, v) -> np.ndarray:
    """The circle point ``u0`` of center point(s) ``v``: the unit null vector of ``A(v)`` (eq 14)."""
    K = burmester_matrices(task_or_C, "center")
    return _null_of_rows(_rows(K, np.asarray(v, float)))


def _axis(R: np.ndarray) -> np.ndarray:
    rv = rotation_class().from_matrix(R).as_rotvec()
    return rv / np.linalg.norm(rv)


def poles(task: TaskPositions) -> dict[str, dict[str, list[float]]]:
    """Poles of the relative rotations for every pair of positions ``i < k`` (1-based names).

    ``center``: axis of ``R_k R_i^T`` (fixed frame; on the center-point curve);
    ``circle``: axis of ``C_k^T C_i`` with ``C_1 = I`` (coupler frame at position 1; on the
    circle-point curve).  Sign: the right-handed rotation axis.
    """
    task.require(4, "the four-position poles")
    C = np.concatenate([np.eye(3)[None], task.C])
    out = {}
    for i, k in combinations(range(task.n), 2):
        out[f"P{i + 1}{k + 1}"] = {
            "center": _axis(task.R[k] @ task.R[i].T).tolist(),
            "circle": _axis(C[k].T @ C[i]).tolist(),
            "angle_deg": float(np.degrees(np.linalg.norm(rotation_class().from_matrix(task.R[k] @ task.R[i].T).as_rotvec()))),
        }
    return out


# ---------------------------------------------------------------------------- tracing
def _seeds(K: np.ndarray, n_circles: int) -> np.ndarray:
    """Every real point of the cubic on ``n_circles`` great circles through a generic axis."""
    e = np.array([0.2672612419124244, 0.5345224838248488, 0.8017837257372732])  # (1,2,3)/sqrt(14)
    if abs(burmester_det(K, e)) < 1e-6 * np.max(np.abs(cubic_coefficients(K))):
        e = np.array([0.8017837257372732, -0.2672612419124244, 0.5345224838248488])
    a = np.cross(e, [1.0, 0, 0])
    a /= np.linalg.norm(a)
    b = np.cross(e, a)
    phi = np.pi * (np.arange(n_circles) + 0.5) / n_circles
    w = np.cos(phi)[:, None] * a + np.sin(phi)[:, None] * b  # (M, 3), w _|_ e
    # f(cos th e + sin th w) = sum_i c_i cos^(3-i) sin^i  ->  cubic in tau = tan th
    th = np.array([0.0, 0.4, 0.9, 1.3])
    X = np.cos(th)[None, :, None] * e + np.sin(th)[None, :, None] * w[:, None, :]  # (M, 4, 3)
    F = burmester_det(K, X)  # (M, 4)
    V = np.stack([np.cos(th) ** (3 - i) * np.sin(th) ** i for i in range(4)], axis=-1)  # (4, 4)
    c = np.linalg.solve(V, F.T).T  # (M, 4): c0 + c1 tau + c2 tau^2 + c3 tau^3 (times cos^3)
    pts = []
    for m in range(n_circles):
        coef = c[m]
        if abs(coef[3]) < 1e-14 * np.max(np.abs(coef)):  # w itself on the curve
            pts.append(w[m])
            coef = coef[:3]
        r = np.roots(coef[::-1])
        r = r[np.abs(r.imag) < 1e-7 * (1 + np.abs(r.real))].real
        for tau in r:
            x = e + tau * w[m]
            pts.append(x / np.linalg.norm(x))
    P = np.array(pts)
    return project_to_curve(K, P)


def _trace(K: np.ndarray, x0: np.ndarray, h: float, max_steps: int = 20000):
    """Trace the spherical curve from ``x0``; stop on return to ``x0`` (oval) or at ``-x0``
    (pseudo-line).  Returns the polyline (m, 3) and the kind."""
    pts = [x0]
    x = x0
    _, g = _det_grad(K, x)
    t_prev = np.cross(x, g)
    t_prev /= np.linalg.norm(t_prev)
    travelled = 0.0
    step = h
    for _ in range(max_steps):
        _, g = _det_grad(K, x)
        t = np.cross(x, g)
        t /= np.linalg.norm(t)
        if t @ t_prev < 0:
            t = -t
        while True:
            y = x + step * t
            y = project_to_curve(K, y / np.linalg.norm(y))
            dist = float(np.linalg.norm(y - x))
            _, gy = _det_grad(K, y)
            ty = np.cross(y, gy)
            ty /= np.linalg.norm(ty)
            if (dist < 1.6 * step and abs(ty @ t) > 0.98) or step < 1e-6:
                break
            step *= 0.5
        travelled += dist
        x = y
        t_prev = t
        step = min(h, step * 1.5)
        if travelled > 4 * h:
            if np.linalg.norm(x - x0) < 1.01 * h:
                return np.array(pts), "oval"
            if np.linalg.norm(x + x0) < 1.01 * h:
                return np.array(pts), "pseudo-line"
        pts.append(x)
    raise ConvergenceError("Burmester curve tracing did not close (increase max_steps)")


def _resample(K: np.ndarray, poly: np.ndarray, kind: str, n: int):
    """Uniform arc-length resampling of a closed (projectively) polyline, projected onto the
    curve.  Returns (n, 3) points and the branch length (rad)."""
    end = -poly[0] if kind == "pseudo-line" else poly[0]
    closed = np.vstack([poly, end])
    seg = np.linalg.norm(np.diff(closed, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    L = s[-1]
    target = np.arange(n) / n * L
    idx = np.clip(np.searchsorted(s, target, side="right") - 1, 0, len(seg) - 1)
    w = (target - s[idx]) / np.where(seg[idx] > 0, seg[idx], 1.0)
    P = closed[idx] * (1 - w)[:, None] + closed[idx + 1] * w[:, None]
    return project_to_curve(K, P), float(L)


@dataclass(frozen=True, eq=False)
class BurmesterCurves:
    """Sampled circle-point and center-point curves with the correspondence built in.

    ``t`` (N,) curve parameter (branch + arc-length fraction); ``u`` (N, 3) circle points
    (moving axes at position 1); ``v`` (N, 3) the corresponding center points (fixed axes);
    ``branch`` (N,) branch index; ``kinds`` per branch (``"pseudo-line"`` or ``"oval"``);
    ``lengths`` per branch (rad, on the unit sphere, one projective copy).
    """

    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    branch: np.ndarray
    kinds: tuple[str, ...]
    lengths: tuple[float, ...]
    K_circle: np.ndarray
    K_center: np.ndarray

    @property
    def n_branches(self) -> int:
        return len(self.kinds)

    def at(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Circle and center points at arbitrary parameter(s) ``t``: linear interpolation of
        the samples of the branch, projected onto the circle-point curve, then the
        correspondence.  Returns ``(u, v)``; ``v``'s sign follows the neighbouring sample."""
        t = np.asarray(t, dtype=float)
        flat = np.atleast_1d(t).ravel()
        U = np.empty((flat.size, 3))
        V = np.empty((flat.size, 3))
        for i, ti in enumerate(flat):
            b = int(np.floor(ti))
            if b < 0 or b >= self.n_branches:
                raise InputError(f"t: {ti} outside [0, {self.n_branches})")
            sel = np.flatnonzero(self.branch == b)
            n = sel.size
            x = (ti - b) * n
            k = int(np.floor(x)) % n
            w = x - np.floor(x)
            p0 = self.u[sel[k]]
            p1 = self.u[sel[(k + 1) % n]]
            if k + 1 == n and self.kinds[b] == "pseudo-line":
                p1 = -p1
            y = (1 - w) * p0 + w * p1
            U[i] = project_to_curve(self.K_circle, y / np.linalg.norm(y))
            vi = _null_of_rows(_rows(self.K_circle, U[i]))
            V[i] = vi if vi @ self.v[sel[k]] >= 0 else -vi
        return U.reshape((*t.shape, 3)), V.reshape((*t.shape, 3))

    def to_dict(self) -> dict:
        return {
            "t": self.t.tolist(),
            "circle_points": self.u.tolist(),
            "center_points": self.v.tolist(),
            "branch": self.branch.tolist(),
            "kinds": list(self.kinds),
            "lengths_deg": [float(np.degrees(v)) for v in self.lengths],
            "circle_cubic": dict(zip(MONOMIALS, cubic_coefficients(self.K_circle).tolist(), strict=True)),
            "center_cubic": dict(zip(MONOMIALS, cubic_coefficients(self.K_center).tolist(), strict=True)),
        }


def burmester_curves(
    task_or_C, *, samples: int = 360, step: float = 0.01, n_circles: int = 120
) -> BurmesterCurves:
    """Trace every real branch of the circle-point curve of four orientations (paper D eq 12)
    and map it to the center-point curve by the correspondence.

    ``samples`` points per branch (uniform in arc length), ``step`` the tracing step (rad),
    ``n_circles`` the great circles used to seed the tracing.  Every returned circle point
    satisfies ``|det B(u)| < 1e-12`` and every center point ``|det A(v)| < 1e-12``.
    """
    if samples < 8:
        raise InputError(f"samples: need at least 8 points per branch, got {samples}")
    Kc = burmester_matrices(task_or_C, "circle")
    Kv = burmester_matrices(task_or_C, "center")
    seeds = _seeds(Kc, n_circles)
    branches = []
    remaining = seeds
    while len(remaining):
        poly, kind = _trace(Kc, remaining[0], step)
        branches.append((poly, kind))
        both = np.vstack([poly, -poly])
        d = np.min(np.linalg.norm(remaining[:, None, :] - both[None, :, :], axis=-1), axis=1)
        remaining = remaining[d > 3 * step]
        if len(branches) > 4:
            raise ConvergenceError("Burmester curve: more than two branches traced (tracing failed)")
    # pseudo-line first, then ovals by decreasing length
    branches.sort(key=lambda bk: (bk[1] != "pseudo-line", -len(bk[0])))
    us, ts, bs, kinds, lengths = [], [], [], [], []
    for b, (poly, kind) in enumerate(branches):
        P, L = _resample(Kc, poly, kind, samples)
        us.append(P)
        ts.append(b + np.arange(samples) / samples)
        bs.append(np.full(samples, b))
        kinds.append(kind)
        lengths.append(L)
    u = np.vstack(us)
    v = _null_of_rows(_rows(Kc, u))
    # sign continuity of v along each branch (an axis: the sign is a choice)
    branch = np.concatenate(bs)
    for b in range(len(kinds)):
        sel = np.flatnonzero(branch == b)
        for i in range(1, sel.size):
            if v[sel[i]] @ v[sel[i - 1]] < 0:
                v[sel[i]] = -v[sel[i]]
    v = project_to_curve(Kv, v)
    return BurmesterCurves(
        t=np.concatenate(ts), u=u, v=v, branch=branch, kinds=tuple(kinds), lengths=tuple(lengths),
        K_circle=Kc, K_center=Kv,
    )
