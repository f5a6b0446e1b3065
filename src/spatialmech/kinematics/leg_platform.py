"""Forward position of S-P-S platforms in pose coordinates.

A platform carried by six S-P-S legs (ball, slide, ball; from the ground to the platform) with
every slide held is, for forward position, six distance equations on the platform's six pose
coordinates: leg ``i`` holds its platform centre at the distance ``L_i = |b_i - a_i + s_i e_i|``
from its base centre (``a_i``, ``b_i`` the ball centres at the reference, ``e_i`` the slide
direction, ``s_i`` its held value).  :func:`correct` solves those six equations by Newton on the
pose (a step ``(w; v)`` moves every platform point ``p`` by ``w x p + v``; the new rotation is
``rotvec_matrix(w) R``), then places the legs:

- the base ball turns the leg the shortest way from where the seed had it to where the platform
  point now is (the rotation about ``(old direction) x (new direction)``): the spin of a leg
  about its own axis is idle (it moves nothing), and this rule keeps the seed's;
- the slide stays at its held value;
- the platform ball is what is left: ``R1^T R``.

The general closure residual of the result (:func:`.closure.closure_residual`) is the test of
convergence, with the Newton tolerance, as for the general engine.  This is the same pose as
the general Newton on all 42 joint variables finds (to rounding, from a seed in the same basin);
the legs' idle spins are the rule's, not the path's of the joint-space steps.  Where the six
equations cannot be solved (a singular step, NaN, no convergence within ``max_iter``) the
general engine starts again from the seed, and the result is its result (its statuses,
including ``stationary``; the iterations of both are counted).

:func:`.backend.correct` takes this path by itself (``method="auto"``) when it applies:
:func:`leg_platform` finds the legs, and the active mask must free every ball and hold every
slide.  The Python code here is the reference (it never imports the compiled package);
``compiled.correct_legs`` (:mod:`spatialmech.kinematics.compiled.legs`, the kernel
``kernels_legs.nb_leg_platform``) runs the same steps compiled, when :func:`.backend.enabled`.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..geometry.rotations import matrix_rotvec, rotvec_matrix, skew
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism
from .closure import (
    Configuration,
    CorrectionResult,
    active_mask,
    check_configuration,
    closure_residual,
    closure_scales,
    correct as closure_correct,
    limb_chains,
    limb_slices,
)

__all__ = ["LegPlatform", "correct", "leg_platform", "place_legs", "result_or_general", "shortest_rotation", "shortest_rotvec"]


@dataclass(frozen=True, eq=False)
class LegPlatform:
    """The six S-P-S legs of a mechanism, as arrays (:func:`leg_platform`)."""

    index: np.ndarray  # (6, 3) int64: first freedom of the base ball, the slide, first freedom of the platform ball
    #: (6, 27) per leg: base ball centre a_i, platform ball centre b_i (reference), slide direction
    #: e_i, then the base ball's and the platform ball's axes (3x3, columns, row by row)
    data: np.ndarray
    held: bytes  # the active mask this path applies to (every freedom but the slides), as bytes
    n: int  # joint variables of the mechanism
    length: float  # characteristic length L

    def applies(self, active) -> bool:
        """Whether ``active`` frees every ball and holds every slide."""
        return type(active) is np.ndarray and active.dtype is _BOOL and active.tobytes() == self.held

    @property
    def axes(self) -> np.ndarray:
        """(6, 2, 3, 3): the two balls' axes (columns)."""
        return self.data[:, 9:].reshape(6, 2, 3, 3)

    @property
    def base(self) -> np.ndarray:
        return self.data[:, 0:3]

    @property
    def tip(self) -> np.ndarray:
        return self.data[:, 3:6]

    @property
    def direction(self) -> np.ndarray:
        return self.data[:, 6:9]


_BOOL = np.dtype(np.bool_)
#: per mechanism (by ``id``; an entry leaves with its mechanism): a plain dict, as the lookup is
#: on every forward solve and a ``WeakKeyDictionary``'s costs a fifth of a microsecond
_LEGS: dict[int, LegPlatform | None] = {}


def leg_platform(mech: Mechanism) -> LegPlatform | None:
    """The legs of ``mech`` when it is a platform on six S-P-S legs from the ground (no internal
    bodies, no locked freedom; a leg's slide may be off the line of its balls), else ``None``
    (cached per mechanism)."""
    try:
        return _LEGS[id(mech)]
    except KeyError:
        pass
    _LEGS[id(mech)] = out = _find_legs(mech)
    weakref.finalize(mech, _LEGS.pop, id(mech), None)
    return out


def _find_legs(mech: Mechanism) -> LegPlatform | None:
    if mech.bodies or len(mech.limbs) != 6 or any(e != (None, 0) for e in mech.limb_ends):
        return None
    refs = mech.freedom_refs
    if any(r.freedom.locked for r in refs):
        return None
    index, base, tip, direction, axes = [], [], [], [], []
    for ch, sl in zip(limb_chains(mech), limb_slices(mech), strict=True):
        balls = {k: (c, A) for k, c, A in ch.balls}
        if sl.stop - sl.start != 7 or set(balls) != {0, 4} or refs[sl.start + 3].freedom.kind != "P":
            return None
        index.append([sl.start, sl.start + 3, sl.start + 4])
        base.append(balls[0][0])
        tip.append(balls[4][0])
        direction.append(ch.screws[3][3:])
        axes.append([balls[0][1], balls[4][1]])
    held = np.ones(len(refs), dtype=np.bool_)
    held[[i[1] for i in index]] = False
    data = np.hstack([base, tip, direction, np.array(axes, dtype=float).reshape(6, 18)])
    return LegPlatform(np.array(index, dtype=np.int64), np.ascontiguousarray(data, dtype=float), held.tobytes(),
                       len(refs), float(mech.characteristic_length))


def shortest_rotvec(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation vector of the smallest rotation taking the unit vector ``a`` to the unit vector
    ``b`` (about ``a x b``; for opposite vectors, a half turn about the coordinate axis least
    aligned with ``a``, made perpendicular to it)."""
    ax = np.cross(a, b)
    sn = float(np.sqrt(ax @ ax))
    ang = float(np.arctan2(sn, float(a @ b)))
    if sn > 1e-300:
        return ax * (ang / sn)
    if a @ b > 0.0:
        return np.zeros(3)
    k = int(np.argmin(np.abs(a)))
    p = -a[k] * a
    p[k] += 1.0
    return p * (np.pi / float(np.sqrt(p @ p)))


def shortest_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The matrix of :func:`shortest_rotvec`: ``I + [x] + [x]^2 / (1 + c)`` with ``x = a x b``,
    ``c = a . b`` (no trigonometry) unless ``a`` and ``b`` are more than 120 degrees apart."""
    c = float(a @ b)
    if c > -0.5:
        K = skew(np.cross(a, b))
        return np.eye(3) + K + (K @ K) / (1.0 + c)
    return rotvec_matrix(shortest_rotvec(a, b))


def _pose_newton(lp: LegPlatform, q0: np.ndarray, D0: np.ndarray, tol: float, max_iter: int):
    """Newton on the pose: (status 1 converged / 0 not / -2 singular or not finite, iterations,
    R, t)."""
    w = lp.tip - lp.base + q0[lp.index[:, 1]][:, None] * lp.direction
    L = np.sqrt(np.einsum("ij,ij->i", w, w))
    R, t = D0[:3, :3].copy(), D0[:3, 3].copy()
    it = 0
    for it in range(max_iter + 1):
        p = lp.tip @ R.T + t
        d = p - lp.base
        ln = np.sqrt(np.einsum("ij,ij->i", d, d))
        f = ln - L
        rn = float(np.sqrt(f @ f)) / lp.length
        if rn < tol:
            return 1, it, R, t
        if it == max_iter or not np.isfinite(rn):
            return (0 if np.isfinite(rn) else -2), it, R, t
        u = d / ln[:, None]
        M = np.hstack([np.cross(p, u), u])
        try:
            x = np.linalg.solve(M, -f)
        except np.linalg.LinAlgError:
            return -2, it, R, t
        if not np.all(np.isfinite(x)):
            return -2, it, R, t
        W = rotvec_matrix(x[:3])
        R = W @ R
        t = W @ t + x[3:]
    return 0, it, R, t


def place_legs(lp: LegPlatform, q0: np.ndarray, R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The joint variables for the platform pose ``(R, t)``: each base ball turned the shortest way
    from its value in ``q0``, the slides as in ``q0``, each platform ball ``R1^T R``."""
    q = q0.copy()
    for k in range(len(lp.index)):
        i1, i_s, i2 = lp.index[k]
        A1, A2 = lp.axes[k]
        R1s = rotvec_matrix(A1 @ q0[i1 : i1 + 3])
        w = lp.tip[k] - lp.base[k] + q0[i_s] * lp.direction[k]
        us = R1s @ (w / np.sqrt(w @ w))
        d = R @ lp.tip[k] + t - lp.base[k]
        R1 = shortest_rotation(us, d / np.sqrt(d @ d)) @ R1s
        q[i1 : i1 + 3] = A1.T @ matrix_rotvec(R1)
        q[i2 : i2 + 3] = A2.T @ matrix_rotvec(R1.T @ R)
    return q


def _closure_norm(mech: Mechanism, config: Configuration) -> float:
    """The general engine's convergence measure: the closure residual scaled by
    :func:`.closure.closure_scales`' rows (moments divided by the characteristic length)."""
    row, _ = closure_scales(mech, active_mask(mech))
    return float(np.linalg.norm(row * closure_residual(mech, config)))


def correct(mech: Mechanism, lp: LegPlatform, config: Configuration, tol: float | None = None, max_iter: int = 50,
            active: np.ndarray | None = None) -> CorrectionResult:
    """Forward position of the platform from ``config`` with the slides held (see the module
    docstring); the general engine (:func:`.closure.correct` with ``active``, by default every
    freedom but the slides) is the fallback.  The Python reference of the compiled
    ``compiled.correct_legs``; callers use :func:`.backend.correct`, which picks one."""
    if tol is None:  # the newton tolerance in force (geometry/tolerances.py)
        tol = current_tolerances().newton
    check_configuration(mech, config)
    status, it, q, D, rn = _correct_python(mech, lp, config, tol, max_iter)
    return result_or_general(mech, lp, config, status, it, q, D, rn, tol, max_iter, active, closure_correct)


def result_or_general(mech: Mechanism, lp: LegPlatform, config: Configuration, status: int, it: int,
                      q: np.ndarray | None, D: np.ndarray | None, rn: float, tol: float, max_iter: int,
                      active: np.ndarray | None, general: Callable[..., CorrectionResult]) -> CorrectionResult:
    """The result of the pose-coordinate solve (``status`` 1: converged to ``q``, ``D``, or to
    ``config`` itself when they are ``None``), or else ``general`` (the general engine's
    ``correct`` of the backend in use) from the seed, the iterations of both counted."""
    if status == 1:
        return CorrectionResult.of(config if q is None or D is None else Configuration.of(q, D), True, it, rn)
    if active is None:
        active = np.frombuffer(lp.held, dtype=np.bool_).copy()
    res = general(mech, config, active=active, tol=tol, max_iter=max_iter)
    return CorrectionResult(res.config, res.converged, it + res.iterations, res.residual, res.stationary)


def _correct_python(mech: Mechanism, lp: LegPlatform, config: Configuration, tol: float, max_iter: int):
    q0 = np.asarray(config.q, dtype=float)
    D0 = np.asarray(config.D, dtype=float)
    status, it, R, t = _pose_newton(lp, q0, D0, tol, max_iter)
    if status != 1:
        return status, it, None, None, np.inf
    if it == 0:  # the seed's pose already closes the legs: the seed itself when it closes
        rn = _closure_norm(mech, config)
        if rn < tol:
            return 1, 0, None, None, rn
    q = place_legs(lp, q0, R, t)
    D = np.eye(4)
    D[:3, :3] = R
    D[:3, 3] = t
    rn = _closure_norm(mech, Configuration(q, D))
    return (1 if rn < tol else 0), it, q, D, rn
