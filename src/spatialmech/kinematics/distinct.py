"""Distinct solutions in configuration space: two inverse (or forward) solutions of a limb are
the same only when every freedom agrees (angles modulo 2 pi, slides exactly, within the
``dedup`` tolerance) up to the parametrisations that are truly redundant: an S joint compared by
its rotation matrix, an Sm joint by the product of its three rotations, and a passive spin
(an S-P-S leg, an S-S rod) walked along its free motion (:func:`same_solution`).  Also the
limb's Gauss-Newton (:func:`limb_gauss_newton`) those checks use, and :func:`wrap_rotations`."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.rotations import inverse_transform, log_transform, rotation_class
from ..geometry.tolerances import Tolerances
from ..model.mechanism import Mechanism
from . import backend
from .closure import Chain, chain_forward, limb_chains, limb_slices

__all__ = [
    "SolutionForm",
    "limb_gauss_newton",
    "limb_polish",
    "same_solution",
    "solution_form",
    "solution_key",
    "wrap_rotations",
]


def limb_gauss_newton(chain, D, q, lin, L, tol=1e-12, max_iter=60, hold=None):
    """Gauss-Newton for one limb with the platform held at ``D``, in local coordinates (S
    joints updated by composing rotations); freedoms in the ``hold`` mask keep their value."""
    if (fast := backend.engine()) is not None:
        return fast.limb_gn(chain, D, q, lin, L, tol=tol, max_iter=max_iter, hold=hold)
    Dinv = inverse_transform(D)
    colscale = np.where(lin, L, 1.0)
    if hold is not None:
        colscale = np.where(hold, 0.0, colscale)
    row = np.r_[np.ones(3), np.full(3, 1.0 / L)]
    rn = np.inf
    for _ in range(max_iter):
        T, J = chain_forward(chain, q, local=True)
        r = log_transform(T @ Dinv)
        rn = float(np.linalg.norm(row * r))
        if rn < tol:
            return q, rn, True
        x, *_ = np.linalg.lstsq(row[:, None] * J * colscale[None, :], -(row * r), rcond=None)
        if np.linalg.norm(x) < 1e-14:
            break
        dq = colscale * x
        q_new = q + dq
        for k, _, A in chain.balls:
            sl = slice(k, k + 3)
            q_new[sl] = A.T @ (rotation_class().from_rotvec(A @ dq[sl]) * rotation_class().from_rotvec(A @ q[sl])).as_rotvec()
        q = q_new
    return q, rn, rn < tol


def limb_polish(chain, D, q, lin, L, rn, hold=None, max_steps=3):
    """Newton steps past the closure tolerance, down to round-off: :func:`limb_gauss_newton`
    stops as soon as the residual ``rn`` is below the tolerance (often 1e-11 after its last
    quadratic step); each further step is kept only while it at least halves the residual.
    Returns the polished ``(q, rn)``."""
    for _ in range(max_steps):
        q2, rn2, ok = limb_gauss_newton(chain, D, q.copy(), lin, L, tol=0.5 * rn, max_iter=2, hold=hold)
        if not ok:
            break
        q, rn = q2, rn2
    return q, rn


@dataclass(frozen=True, eq=False)
class SolutionForm:
    """How the solutions of one limb are told apart (:func:`solution_key`): which freedoms are
    angles (compared modulo 2 pi), which are numbers (slides, divided by ``L``, and helical
    values), and which triples are the rotation of one spherical joint (compared by its matrix:
    an ``S`` joint's rotation vector, an ``Sm`` joint's three serial rotations)."""

    chain: Chain
    angles: np.ndarray  # (m,) bool: an angle of its own (R, U, C rotations; H of pitch 0)
    wrap: np.ndarray  # (m,) bool: a rotation whose difference is wrapped (the angles and the Sm rotations)
    lin: np.ndarray  # (m,) bool: a slide
    exact: np.ndarray  # indices compared as numbers
    exact_scale: np.ndarray  # 1 / L for a slide, 1 for a helical value
    balls: tuple[tuple[int, np.ndarray], ...]  # (first index, axes as columns) of S joints (rotation vectors)
    serial_balls: tuple[tuple[int, np.ndarray], ...]  # (first index, axes as columns) of Sm joints
    L: float


def solution_form(mech: Mechanism, li: int) -> SolutionForm:
    """The :class:`SolutionForm` of limb ``li``."""
    ch, sl = limb_chains(mech)[li], limb_slices(mech)[li]
    refs = mech.freedom_refs[sl]
    L = mech.characteristic_length
    joints = mech.limbs[li].joints
    angles = np.zeros(len(refs), dtype=bool)
    wrap = np.zeros(len(refs), dtype=bool)
    exact: list[int] = []
    scale: list[float] = []
    serial = []
    k = 0
    while k < len(refs):
        jt = joints[refs[k].joint].type
        if jt in ("S", "Sm"):
            if jt == "Sm":  # three serial rotations about the reference directions of its axes
                serial.append((k, ch.screws[k : k + 3, :3].T.copy()))
                wrap[k : k + 3] = True
            k += 3
            continue
        f = refs[k].freedom
        if f.kind == "R" or (f.kind == "H" and f.pitch == 0.0):
            angles[k] = wrap[k] = True
        else:  # a slide, or a helical value (a turn more is a pitch further)
            exact.append(k)
            scale.append(1.0 / L if f.kind == "P" else 1.0)
        k += 1
    lin = np.array([r.freedom.kind == "P" for r in refs], dtype=bool)
    return SolutionForm(ch, angles, wrap, lin, np.array(exact, dtype=int), np.array(scale, dtype=float),
                        tuple((k, A) for k, _, A in ch.balls), tuple(serial), L)


def _serial_rotation(A: np.ndarray, q: np.ndarray) -> np.ndarray:
    Rm = np.eye(3)
    for j in range(3):
        Rm = Rm @ rotation_class().from_rotvec(A[:, j] * q[j]).as_matrix()
    return Rm


def solution_key(form: SolutionForm, q) -> np.ndarray:
    """A limb's solution as a point whose distances tell solutions apart in configuration
    space, nondimensional: every angle ``t`` as ``(cos t, sin t)`` (a distance of
    ``2 |sin(dt / 2)|``: ``t`` and ``t + 2 pi`` are one value, a half turn is 2 away), slides
    divided by ``L``, helical values as they are, and every spherical joint's rotation matrix
    divided by ``sqrt(2)`` (again ``2 |sin(dt / 2)|``, ``dt`` the angle between the two
    rotations: its three variables are a redundant parametrisation, the rotation is not).

    A universal joint's two angles are compared as angles: its flipped cross ``(t1 + pi,
    pi - t2)`` is not the same joint displacement (the next link is turned by a half turn about
    the normal of the two axes), so it is another configuration, like any R joint's half turn."""
    q = np.asarray(q, dtype=float)
    a = q[form.angles]
    parts = [np.cos(a), np.sin(a), q[form.exact] * form.exact_scale]
    for k, A in form.balls:
        parts.append(rotation_class().from_rotvec(A @ q[k : k + 3]).as_matrix().ravel() / np.sqrt(2.0))
    for k, A in form.serial_balls:
        parts.append(_serial_rotation(A, q[k : k + 3]).ravel() / np.sqrt(2.0))
    return np.concatenate(parts)


def _difference(form: SolutionForm, q: np.ndarray, q_to: np.ndarray) -> np.ndarray:
    """The step from ``q`` to ``q_to`` in the local coordinates of :func:`limb_gauss_newton`
    (angles the short way round; an S joint's rotation composed on the left)."""
    d = q_to - q
    d[form.wrap] = (d[form.wrap] + np.pi) % (2 * np.pi) - np.pi
    for k, A in form.balls:
        rel = rotation_class().from_rotvec(A @ q_to[k : k + 3]) * rotation_class().from_rotvec(A @ q[k : k + 3]).inv()
        d[k : k + 3] = A.T @ rel.as_rotvec()
    return d


def _joins(form: SolutionForm, q_from: np.ndarray, q_to: np.ndarray, t: Tolerances, max_iter: int = 40) -> bool:
    """Whether ``q_from`` reaches ``q_to`` along the limb's solution set with its tip held (a
    passive spin, a continuum of solutions): steps along the null space of the limb's Jacobian
    towards ``q_to`` (at most 0.5 nondimensional each), each corrected back onto the set, until
    the two are one solution (:func:`solution_key` within the ``dedup`` tolerance).  ``False``
    when the set does not lead there (a distinct solution, or a continuum of its own)."""
    ch, L = form.chain, form.L
    T = chain_forward(ch, q_to)[0]
    key_to = solution_key(form, q_to)
    colscale = np.where(form.lin, L, 1.0)
    row = np.r_[np.ones(3), np.full(3, 1.0 / L)]
    q = q_from.copy()
    kicked = False
    for _ in range(max_iter):
        if np.linalg.norm(solution_key(form, q) - key_to) < t.dedup:
            return True
        _, J = chain_forward(ch, q, local=True)
        _, sv, Vt = np.linalg.svd(row[:, None] * J * colscale[None, :])
        rank = int(np.sum(sv > t.rank * max(1.0, sv[0] if sv.size else 0.0)))
        N = Vt[rank:].T  # the tangent of the solution set (nondimensional)
        if N.shape[1] == 0:
            return False
        x = N @ (N.T @ (_difference(form, q, q_to) / colscale))
        nx = float(np.linalg.norm(x))
        if nx < 1e-9:  # the far side of a closed continuum (a spin by half a turn): go round one way
            if kicked:
                return False
            x, nx, kicked = N[:, 0].copy(), 1.0, True
        dq = colscale * (x if nx <= 0.5 else x * (0.5 / nx))
        q_new = q + dq
        for k, A in form.balls:
            sl = slice(k, k + 3)
            q_new[sl] = A.T @ (rotation_class().from_rotvec(A @ dq[sl]) * rotation_class().from_rotvec(A @ q[sl])).as_rotvec()
        q, _, ok = limb_gauss_newton(ch, T, q_new, form.lin, L, tol=t.closure)
        if not ok:
            return False
    return False


def same_solution(form: SolutionForm, q: np.ndarray, key: np.ndarray, q2: np.ndarray, key2: np.ndarray,
                  t: Tolerances, passive: int) -> bool:
    """Whether two closed solutions of one limb (its tip at the same place) are one: their
    :func:`solution_key` within the ``dedup`` tolerance, or, when the first lies on a continuum
    (``passive > 0`` free directions), the continuum leads to the second (:func:`_joins`)."""
    if np.linalg.norm(key - key2) < t.dedup:
        return True
    return passive > 0 and _joins(form, q, q2, t)


def wrap_rotations(mech: Mechanism, q, indices=None) -> np.ndarray:
    """Joint variables with every rotation's value ``offset + q`` wrapped to (-pi, pi]
    (S joints keep their rotation vectors)."""
    q = np.array(q, dtype=float, copy=True)
    refs = mech.freedom_refs
    idx = range(len(q)) if indices is None else indices
    for k, i in enumerate(idx):
        r = refs[i]
        if r.freedom.kind == "R" and mech.limbs[r.limb].joints[r.joint].type != "S":
            v = r.freedom.offset + q[k]
            q[k] = (v + np.pi) % (2 * np.pi) - np.pi - r.freedom.offset
            if q[k] + r.freedom.offset <= -np.pi:
                q[k] += 2 * np.pi
    return q
