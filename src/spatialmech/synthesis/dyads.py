"""CC and RC dyads: direction equations, linear moment equations, solution lines, slides.

A dyad joins the fixed link to the coupler: a *fixed* axis (unit ``v`` through ``P2``) and a
*moving* axis on the coupler (unit ``u0`` through ``P1`` at position 1), ``P1`` and ``P2`` the
feet of their common normal.  Over the task displacements ``x -> C_j x + d_j`` (world frame,
see :mod:`.tasks`) the moving axis becomes ``u_j = C_j u0`` through ``C_j P1 + d_j``.  A CC
dyad must keep the twist angle and the distance of its two axes (paper D eqs 1-4):

- direction (eq 3): ``u0^T (C_j^T - I) v = 0``;
- moment (eq 4/15, with ``u0o = P1 x u0``, ``vo = P2 x v``):
  ``c_j . u0o + d'_j . vo = r_j``, ``c_j = (C_j^T - I) v``, ``d'_j = (C_j - I) u0``,
  ``r_j = -u0^T (T_j C_j)^T v`` with ``T_j = [d_j]x`` (paper D writes ``[p_j]x``: the same
  because its ``p_1 = 0``).

With the directions fixed these are linear in the points (eqs 21-23)::

    P1 . (u0 x c_j) + P2 . (v x d'_j) = r_j,     u0 . (P1 - P2) = 0,     v . (P1 - P2) = 0

Four positions give five equations in six unknowns: the dyads form a line in R^6, i.e. two
corresponding straight *solution lines* of ``P1`` and ``P2`` (eqs 25-26).  We parametrise them
by the signed common-normal length ``h`` (task length unit)::

    P1 - P2 = h n,      n = (v x u0) / |v x u0|

(never by a coordinate, which fails for a line perpendicular to that axis); ``h = 0`` is the
dyad whose axes intersect, which every solution line contains.

Slide of the fixed joint from position 1 to ``j+1`` (sign kept; paper D eq 29 takes a norm and
loses it): ``s_j = (Q_j - Q_1) . v`` with ``Q_j`` the foot of the common normal on the fixed
axis.  It is affine in ``h`` along a solution line.  An RC dyad (fixed R joint) needs
``s_j = 0`` for every ``j``: exact for three positions (:func:`rc_dyad_three_positions`),
approximate for four (:meth:`SolutionLine.minimax_slide`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.rotations import skew
from ..geometry.validate import as_unit_vector
from .tasks import TaskPositions

__all__ = [
    "DIRECTION_ATOL",
    "Dyad",
    "SolutionLine",
    "direction_residuals",
    "dyad_joint_values",
    "minimax",
    "moment_equations",
    "rc_dyad_three_positions",
    "slide_equations",
    "solution_line",
]

#: Largest direction-equation residual accepted when building a solution line.
DIRECTION_ATOL = 1e-8


def _unit(x, name):
    return as_unit_vector(x, name, normalize=True)


def direction_residuals(task: TaskPositions, u, v) -> np.ndarray:
    """``u0^T (C_j^T - I) v`` for each relative displacement (paper D eq 3), unit vectors
    (normalised here).  Zero for a dyad that keeps its twist angle."""
    u = _unit(u, "u")
    v = _unit(v, "v")
    return np.einsum("a,jab,b->j", u, np.swapaxes(task.C, -1, -2) - np.eye(3), v)


def moment_equations(task: TaskPositions, u, v) -> tuple[np.ndarray, np.ndarray]:
    """The linear moment equations in ``X = (P1, P2)`` (paper D eq 21): rows (n-1, 6) and
    right-hand sides (n-1,)."""
    u = _unit(u, "u")
    v = _unit(v, "v")
    C, d = task.C, task.d
    c = np.einsum("jba,b->ja", C, v) - v  # (C_j^T - I) v
    dp = np.einsum("jab,b->ja", C, u) - u  # (C_j - I) u0
    T = skew(d)  # [d_j]x
    r = -np.einsum("a,jba,b->j", u, T @ C, v)  # -u0^T (T_j C_j)^T v
    rows = np.concatenate([np.cross(u, c), np.cross(v, dp)], axis=1)
    return rows, r


def _feet_rows(u, v) -> np.ndarray:
    return np.array([np.r_[u, -u], np.r_[v, -v]])


def slide_equations(task: TaskPositions, u, v) -> tuple[np.ndarray, np.ndarray]:
    """Fixed-joint slides ``s_j = G_j . X + k_j`` with ``X = (P1, P2)``: ``(G (n-1, 6), k (n-1,))``.

    ``Q_j`` is the foot, on the fixed axis, of the common normal of the fixed axis and the moved
    axis ``(u_j, C_j P1 + d_j)``; with ``b = u0 . v`` (constant) and ``m_j = v - b u_j``::

        s_j = (C_j P1 + d_j - P2) . m_j / (1 - b^2)
    """
    u = _unit(u, "u")
    v = _unit(v, "v")
    b = float(u @ v)
    if 1 - b * b < 1e-14:
        raise InputError("u, v: parallel axes have no common normal (use a P/planar model)")
    C, d = task.C, task.d
    uj = np.einsum("jab,b->ja", C, u)
    m = v - b * uj
    G = np.concatenate([np.einsum("jba,jb->ja", C, m), -m], axis=1) / (1 - b * b)
    k = np.sum(d * m, axis=1) / (1 - b * b)
    return G, k


@dataclass(frozen=True, eq=False)
class Dyad:
    """A dyad at position 1: fixed axis ``v`` through ``P2``, moving axis ``u`` through ``P1``
    (feet of the common normal).  ``kind`` is ``"CC"`` or ``"RC"`` (fixed joint R)."""

    u: np.ndarray
    v: np.ndarray
    P1: np.ndarray
    P2: np.ndarray
    kind: str = "CC"

    @property
    def twist_angle(self) -> float:
        """Angle between the axes (rad, in [0, pi])."""
        return float(np.arccos(np.clip(self.u @ self.v, -1.0, 1.0)))

    @property
    def h(self) -> float:
        """Signed common-normal length ``(P1 - P2) . n``, ``n = unit(v x u)``."""
        n = np.cross(self.v, self.u)
        return float((self.P1 - self.P2) @ n / np.linalg.norm(n))

    def moved(self, task: TaskPositions) -> tuple[np.ndarray, np.ndarray]:
        """The moving axis at every task position: directions (n, 3) and points (n, 3)."""
        C = np.concatenate([np.eye(3)[None], task.C])
        d = np.concatenate([np.zeros((1, 3)), task.d])
        return C @ self.u, C @ self.P1 + d

    def invariants(self, task: TaskPositions) -> tuple[np.ndarray, np.ndarray]:
        """Twist angle (rad) and common-normal distance of the fixed and moved axes at every
        task position (n,), (n,): constant for a dyad that reaches the task."""
        U, P = self.moved(task)
        ang = np.arccos(np.clip(U @ self.v, -1.0, 1.0))
        n = np.cross(self.v, U)
        dist = np.abs(np.sum((P - self.P2) * n, axis=1)) / np.linalg.norm(n, axis=1)
        return ang, dist

    def fixed_slides(self, task: TaskPositions) -> np.ndarray:
        """Signed slides ``s_j - s_0`` of the fixed joint along ``v`` (n-1,), task length unit."""
        G, k = slide_equations(task, self.u, self.v)
        return G @ np.r_[self.P1, self.P2] + k

    def to_dict(self) -> dict:
        """JSON (docs/json.md): axes as a unit ``direction`` and a ``point_len`` (task length
        unit), the twist angle in degrees, the common-normal length ``h_len``."""
        return {
            "kind": self.kind,
            "fixed_axis": {"direction": self.v.tolist(), "point_len": self.P2.tolist()},
            "moving_axis": {"direction": self.u.tolist(), "point_len": self.P1.tolist()},
            "twist_angle_deg": float(np.degrees(self.twist_angle)),
            "h_len": float(self.h),
        }


@dataclass(frozen=True, eq=False)
class SolutionLine:
    """The CC dyads of four positions with fixed directions: ``X(h) = X0 + h dX`` with
    ``X = (P1, P2)`` (paper D eqs 25-26), ``h`` the signed common-normal length."""

    u: np.ndarray
    v: np.ndarray
    X0: np.ndarray
    dX: np.ndarray
    slide_alpha: np.ndarray  # slides = slide_alpha + slide_beta * h
    slide_beta: np.ndarray

    def points(self, h) -> tuple[np.ndarray, np.ndarray]:
        """``P1(h)``, ``P2(h)`` (..., 3) on the two solution lines."""
        h = np.asarray(h, dtype=float)
        X = self.X0 + h[..., None] * self.dX
        return X[..., :3], X[..., 3:]

    def at(self, h: float, kind: str = "CC") -> Dyad:
        P1, P2 = self.points(float(h))
        return Dyad(self.u, self.v, P1, P2, kind)

    def slides(self, h) -> np.ndarray:
        """Fixed-joint slides (..., n-1) at parameter(s) ``h``: affine in ``h``."""
        h = np.asarray(h, dtype=float)
        return self.slide_alpha + h[..., None] * self.slide_beta

    def minimax_slide(self, h_range: tuple[float, float] | None = None) -> tuple[float, float]:
        """``(h*, max_j |s_j(h*)|)`` minimising the largest slide over ``h`` (exact: the
        optimum of a maximum of affine functions is at a crossing of two of ``+-s_j`` or at
        an end of ``h_range``)."""
        return minimax(self.slide_alpha[None], self.slide_beta[None], h_range)

    def to_dict(self) -> dict:
        """JSON (docs/json.md): ``u``, ``v`` unit directions; points and slides at ``h = 0`` in
        the task length unit (``*_len``); their rates per unit of ``h`` (unit-free)."""
        return {
            "u": self.u.tolist(), "v": self.v.tolist(),
            "P1_at_h0_len": self.X0[:3].tolist(), "P2_at_h0_len": self.X0[3:].tolist(),
            "dP1_dh": self.dX[:3].tolist(), "dP2_dh": self.dX[3:].tolist(),
            "slide_alpha_len": self.slide_alpha.tolist(), "slide_beta": self.slide_beta.tolist(),
        }


def minimax(alpha: np.ndarray, beta: np.ndarray, h_range=None):
    """Vectorised ``min_h max_j |alpha_j + beta_j h|`` for stacks (m, k): returns (h*, value)
    as arrays (m,) (or floats when m == 1)."""
    alpha = np.asarray(alpha, float)
    beta = np.asarray(beta, float)
    m, k = alpha.shape
    cands = []
    for i in range(k):
        for j in range(k):
            if i < j:
                for sgn in (1.0, -1.0):
                    den = beta[:, i] - sgn * beta[:, j]
                    with np.errstate(divide="ignore", invalid="ignore"):
                        cands.append(np.where(np.abs(den) > 1e-300, -(alpha[:, i] - sgn * alpha[:, j]) / den, np.nan))
        with np.errstate(divide="ignore", invalid="ignore"):
            cands.append(np.where(np.abs(beta[:, i]) > 1e-300, -alpha[:, i] / beta[:, i], np.nan))
    H = np.stack(cands, axis=1)  # (m, nc)
    if h_range is not None:
        lo, hi = float(h_range[0]), float(h_range[1])
        H = np.concatenate([np.clip(H, lo, hi), np.full((m, 1), lo), np.full((m, 1), hi)], axis=1)
    H = np.where(np.isfinite(H), H, 0.0)
    vals = np.max(np.abs(alpha[:, None, :] + H[..., None] * beta[:, None, :]), axis=-1)
    best = np.argmin(vals, axis=1)
    hs = H[np.arange(m), best]
    vs = vals[np.arange(m), best]
    if m == 1:
        return float(hs[0]), float(vs[0])
    return hs, vs


def solution_line(task: TaskPositions, u, v, *, atol: float = DIRECTION_ATOL) -> SolutionLine:
    """The solution lines of a CC dyad with directions ``u`` (moving, at position 1) and ``v``
    (fixed) for four positions (paper D eqs 15-26).

    Raises ``ValueError`` when the directions do not satisfy the direction equations (eq 3) to
    ``atol`` (as happens with paper D's printed eqs 28 and 30), or are parallel.
    """
    task.require(4, "a CC solution line")
    u = _unit(u, "u")
    v = _unit(v, "v")
    res = direction_residuals(task, u, v)
    if np.max(np.abs(res)) > atol:
        raise InputError(
            "u, v: do not satisfy the direction equations u^T (C_j^T - I) v = 0"
            f" (residuals {', '.join(f'{x:.3g}' for x in res)})"
        )
    n = np.cross(v, u)
    nn = np.linalg.norm(n)
    if nn < 1e-9:
        raise InputError("u, v: parallel axes have no common normal")
    n /= nn
    M, r = moment_equations(task, u, v)
    A5 = np.vstack([M, _feet_rows(u, v)])
    b5 = np.r_[r, 0.0, 0.0]
    hrow = np.r_[n, -n]
    X0 = np.linalg.solve(np.vstack([A5, hrow]), np.r_[b5, 0.0])
    dX = np.linalg.solve(np.vstack([A5, hrow]), np.r_[np.zeros(5), 1.0])
    G, k = slide_equations(task, u, v)
    return SolutionLine(u, v, X0, dX, G @ X0 + k, G @ dX)


def rc_dyad_three_positions(task: TaskPositions, u) -> Dyad:
    """The exact RC dyad of three positions for a chosen moving-axis direction ``u``.

    ``v`` is the null vector of the two direction equations, ``v ~ (C_1 - I) u x (C_2 - I) u``;
    then two moment equations, the two common-normal conditions and two zero-slide conditions
    are six linear equations in ``(P1, P2)``.  Raises ``ValueError`` for a singular choice.
    """
    task.require(3, "an exact RC dyad")
    u = _unit(u, "u")
    b = (task.C - np.eye(3)) @ u
    v = np.cross(b[0], b[1])
    nv = np.linalg.norm(v)
    if nv < 1e-9:
        raise InputError("u: this direction gives no unique fixed axis (a pole direction)")
    v /= nv
    if abs(u @ v) > 1 - 1e-12:
        raise InputError("u: the fixed axis is parallel to the moving axis")
    M, r = moment_equations(task, u, v)
    G, k = slide_equations(task, u, v)
    A = np.vstack([M, _feet_rows(u, v), G])
    rhs = np.r_[r, 0.0, 0.0, -k]
    if np.linalg.cond(A) > 1e12:
        raise InputError("u: the RC dyad equations are singular for this direction")
    X = np.linalg.solve(A, rhs)
    return Dyad(u, v, X[:3], X[3:], "RC")


def dyad_joint_values(dyad: Dyad, D) -> tuple[float, float, float, float]:
    """Joint values of a CC dyad that carries the coupler by displacement ``D`` (4x4) from
    position 1: ``(theta_fixed, s_fixed, theta_moving, s_moving)`` (rad, length) for the
    model of :func:`.rccc.assemble` (fixed joint = rotation then slide along ``v`` through
    ``P2``; moving joint along ``u`` through ``P1``, product of exponentials)."""
    from ..geometry.rotations import exp_twist, inverse_transform, log_transform
    from ..geometry.screws import axis_screw, translation_screw

    D = np.asarray(D, float)
    u, v = dyad.u, dyad.v
    uj = D[:3, :3] @ u
    a = u - (u @ v) * v
    b = uj - (uj @ v) * v
    th = float(np.arctan2(v @ np.cross(a, b), a @ b))
    G, k = slide_equations_single(D, u, v)
    s = float(G @ np.r_[dyad.P1, dyad.P2] + k)
    E1 = exp_twist(axis_screw(v, dyad.P2), th) @ exp_twist(translation_screw(v), s)
    E2 = inverse_transform(E1) @ D
    xi = log_transform(E2)
    th2 = float(xi[:3] @ u)
    s2 = float(xi[3:] @ u)
    return th, s, th2, s2


def slide_equations_single(D, u, v):
    """:func:`slide_equations` for one displacement ``D`` (4x4): ``(G (6,), k)``."""
    C = D[:3, :3]
    d = D[:3, 3]
    b = float(u @ v)
    m = v - b * (C @ u)
    return np.r_[C.T @ m, -m] / (1 - b * b), float(d @ m) / (1 - b * b)
