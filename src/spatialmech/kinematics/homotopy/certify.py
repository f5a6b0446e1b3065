"""Certified solutions (issue 27): a Krawczyk test in ball arithmetic (python-flint's ``acb``)
proves that a numerical end point is an approximate zero of the *exact* polynomial system, with
its own root, and that distinct end points have distinct roots.

The exact system.  The systems of the homotopies are evaluated from floating-point data: the
quadrics of the Study formulation (:mod:`.study`), the twist matrices and the pose parameters of
the limb formulation (:mod:`.inverse`).  Those floats are taken as the exact data of the stated
model (each one is a binary rational, enclosed by a ball of radius zero); every operation on them
is carried out in ball arithmetic, so the enclosures hold for the exact polynomials, not for
their floating-point evaluation.

The test (Krawczyk 1969; Moore 1977; Rump's verification method).  For a square system ``F`` of
``n`` polynomials in ``n`` unknowns, a point ``y`` (exact floats), a box ``X = y + [-r, r]^n
(1 + i)`` (each real and imaginary part within ``r``) and a floating-point inverse ``A`` of
``F'(y)``, the Krawczyk operator

    K(X) = y - A F(y) + (I - A F'(X)) (X - y)

is enclosed in ball arithmetic.  If ``K(X)`` lies in the interior of ``X``, then ``X`` holds
exactly one root of ``F`` (and ``F'`` is nonsingular there): the certificate.  The box is built
around the numerical point with the smallest radius that works, from ``CERTIFY_MIN_RADIUS``
(relative to the point's size) up by factors of ``CERTIFY_GROWTH`` to ``CERTIFY_MAX_RADIUS``; a
point whose Newton correction exceeds the largest box is *not* certified (it is no accurate
approximation of a root, however near one it may be), nor is a point where the test fails at
every radius (a singular root, or roots closer than the point's accuracy).

Distinct roots.  Two certified boxes that are disjoint hold two different roots.  When the
box of a point lies inside the box of an earlier one, both hold the same (unique) root: the later
point is a *duplicate* and not certified.  Boxes that overlap otherwise leave the question open:
neither point is certified.

Real roots.  For a system with real coefficients, a box with a real centre is its own complex
conjugate, so the unique root in it equals its conjugate: it is real.  A box that misses the real
space in some coordinate holds a non-real root (its conjugate is another root).

The modules.  :func:`certify` over a :class:`BallSystem` and points returns one
:class:`Certificate` per point (:mod:`.certify_core`: the test; :mod:`.certify_balls`: the ball
matrices and boxes); :func:`quadric_system` builds the ball system of the Study formulation
(quadrics and linear equations), :func:`limb_system` that of a limb's inverse position
(:mod:`.certify_systems`), each with a fast first pass at real points in floating-point interval
arithmetic (:mod:`.certify_float`); the loop formulation's system is in :mod:`.certify_loops`.
This module holds the solvers' side: the points they certify (:func:`certify_forward`,
:func:`certify_projective`, :func:`certify_inverse`), the switch (:func:`certification`) and the
sentence of the results (:func:`statement`); every name above is importable from here.
HomotopyContinuation.jl's ``certify`` (Breiding, Rose and Timme 2020) uses the same test; this is
an independent implementation.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar

import numpy as np

from ...geometry.tolerances import CERTIFY_MAX_RADIUS
from .certify_balls import COMPLEX, REAL, BallSystem
from .certify_balls import midpoints as _mid
from .certify_core import Certificate, certify, n_certified, newton_refine
from .certify_core import krawczyk_box as _one
from .certify_systems import LimbBallSystem, QuadricBallSystem, limb_system, quadric_system

__all__ = [
    "CERTIFY_MAX_RADIUS",
    "COMPLEX",
    "REAL",
    "BallSystem",
    "Certificate",
    "LimbBallSystem",
    "QuadricBallSystem",
    "certification",
    "certify",
    "certify_forward",
    "certify_inverse",
    "certify_projective",
    "enabled",
    "limb_point",
    "limb_system",
    "n_certified",
    "newton_refine",
    "quadric_system",
    "refine_projective",
    "statement",
    "study_parameters",
]

#: The test of one point and the midpoints of a ball matrix under their names of before the split
#: (:func:`.certify_core.krawczyk_box`, :func:`.certify_balls.midpoints`; the tests use them).
_COMPAT = (_one, _mid)


# ------------------------------------------------------------------------------ switch
_ENABLED: ContextVar[bool] = ContextVar("spatialmech_certify", default=True)


def enabled() -> bool:
    """Whether the solvers certify their solutions (default ``True``; :func:`certification`)."""
    return _ENABLED.get()


@contextmanager
def certification(on: bool) -> Iterator[None]:
    """Certify (``on``) or not the solutions of the solvers called inside the block
    (``sm.fk(..., certify=False)`` and ``sm.ik(..., certify=False)`` use it)."""
    token = _ENABLED.set(bool(on))
    try:
        yield
    finally:
        _ENABLED.reset(token)



# ------------------------------------------------------------------------------ the solvers' points
def study_parameters(D: np.ndarray, L: float) -> np.ndarray:
    """The Study parameters ``(e ; g)`` (8,) of a real displacement ``D`` (4x4, model units) in
    the convention of :func:`.study.study_to_pose` (``e`` a unit quaternion, ``g = p e / 2``
    with ``p`` over ``L``)."""
    R = np.asarray(D, dtype=float)[:3, :3]
    p = np.asarray(D, dtype=float)[:3, 3] / L
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    cands = np.array([[1 + tr, R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]],
                      [R[2, 1] - R[1, 2], 1 + R[0, 0] - R[1, 1] - R[2, 2], R[0, 1] + R[1, 0], R[0, 2] + R[2, 0]],
                      [R[0, 2] - R[2, 0], R[0, 1] + R[1, 0], 1 - R[0, 0] + R[1, 1] - R[2, 2], R[1, 2] + R[2, 1]],
                      [R[1, 0] - R[0, 1], R[0, 2] + R[2, 0], R[1, 2] + R[2, 1], 1 - R[0, 0] - R[1, 1] + R[2, 2]]])
    e = cands[int(np.argmax(np.linalg.norm(cands, axis=1)))]
    e = e / np.linalg.norm(e)
    w, x, y, z = e
    P = np.array([[0.0, -p[0], -p[1], -p[2]], [p[0], 0.0, -p[2], p[1]], [p[1], p[2], 0.0, -p[0]],
                  [p[2], -p[1], p[0], 0.0]])  # left multiplication by the pure quaternion p
    return np.concatenate([e, 0.5 * P @ np.array([w, x, y, z])])


def _real_patch(points: np.ndarray, seed: int = 27) -> np.ndarray:
    """A real affine patch ``c . x = 1`` far from every point's hyperplane at infinity (the best
    of a few seeded random ``c``)."""
    rng = np.random.default_rng(seed)
    best, score = None, -1.0
    norms = np.maximum(np.linalg.norm(points, axis=1), 1e-300) if len(points) else np.ones(0)
    for _ in range(8):
        c = rng.normal(size=points.shape[1] if len(points) else 8)
        c /= np.linalg.norm(c)
        s = float(np.min(np.abs(points @ c) / norms)) if len(points) else 1.0
        if s > score:
            best, score = c, s
    assert best is not None
    return best


def certify_forward(Qt: np.ndarray, real_points: Sequence[np.ndarray | None],
                    complex_points: np.ndarray) -> tuple[list[Certificate | None], list[Certificate]]:
    """Certificates of the Study formulation's seven quadrics ``Qt`` (7, 8, 8, real: the
    requested actuator values) for the listed real solutions (their Study parameters,
    :func:`study_parameters`; ``None``: not attempted) and the complex end points (k, 8): all in
    one real affine patch, so that they are told apart together and the real ones proven real
    (:func:`certify_projective`)."""
    return certify_projective(Qt, real_points, complex_points)


def certify_projective(Q: np.ndarray, real_points: Sequence[np.ndarray | None],
                       complex_points: np.ndarray | None = None) -> tuple[list[Certificate | None], list[Certificate]]:
    """Certificates of ``k`` homogeneous quadrics ``x^T Q_j x = 0`` (``Q`` (k, k + 1, k + 1), real)
    for points of ``P^k``: the listed real points (``None``: not attempted) and the complex ones
    (m, k + 1), all scaled onto one real affine patch ``c . x = 1`` (:func:`_real_patch`), so that
    they are told apart together and the real ones proven real.  Used by the Study formulation
    and the closed forms' quadrics (the wrist's quaternion, the 5-CS's rotation entries)."""
    n = np.asarray(Q).shape[1]
    have = [i for i, x in enumerate(real_points) if x is not None]
    R = np.array([np.asarray(real_points[i], dtype=complex) for i in have]).reshape(len(have), n)
    C = np.asarray(() if complex_points is None else complex_points, dtype=complex).reshape(-1, n)
    P = np.vstack([R, C])
    if len(P) == 0:
        return [None] * len(real_points), []
    c = _real_patch(P)
    s = P @ c
    P = P / np.where(np.abs(s) > 0, s, 1.0)[:, None]
    certs = certify(quadric_system(np.real(Q), c[None], [1.0]), P, real=[True] * len(R) + [False] * len(C))
    out: list[Certificate | None] = [None] * len(real_points)
    for k, i in enumerate(have):
        out[i] = certs[k]
    return out, list(certs[len(R):])


def refine_projective(Q: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points of ``P^k`` (m, k + 1) on the homogeneous quadrics ``Q`` (real), each refined by
    :func:`.certify_core.newton_refine` on a real affine patch chosen for them (the result is
    homogeneous: any scaling of it is the same point)."""
    P = np.asarray(points, dtype=complex).reshape(-1, np.asarray(Q).shape[1])
    if len(P) == 0:
        return P
    c = _real_patch(P)
    s = P @ c
    P = P / np.where(np.abs(s) > 0, s, 1.0)[:, None]
    system = quadric_system(np.real(Q), c[None], [1.0])
    return np.array([newton_refine(system, y) for y in P])


def limb_point(sysm, q) -> np.ndarray:
    """The unknowns ``x`` of a limb's :class:`.inverse.LimbIK` at its joint variables ``q``
    (``(cos, sin)`` per revolute, slide over ``L``; an S joint's variables have none)."""
    idx = _SLOTS.get(sysm.key)
    if idx is None:
        rot = [(k, s[1], s[2]) for k, s in enumerate(sysm.slots) if s[0] == "R"]
        lin = [(k, s[1]) for k, s in enumerate(sysm.slots) if s[0] == "P"]
        idx = _SLOTS[sysm.key] = (np.array([r[0] for r in rot], dtype=np.int64), np.array([r[1] for r in rot], dtype=np.int64),
                                  np.array([r[2] for r in rot], dtype=np.int64), np.array([r[0] for r in lin], dtype=np.int64),
                                  np.array([r[1] for r in lin], dtype=np.int64))
    kr, ic, js, kp, ip = idx
    q = np.asarray(q, dtype=float)
    x = np.zeros(sysm.nx)
    x[ic], x[js] = np.cos(q[kr]), np.sin(q[kr])
    x[ip] = q[kp] / sysm.L
    return x


_SLOTS: dict[bytes, tuple] = {}


def certify_inverse(sysm, D: np.ndarray, qs: Sequence[np.ndarray]) -> list[Certificate] | None:
    """Certificates of a limb's solutions ``qs`` (joint variables) with its output link at ``D``
    (4x4, model units); ``None`` when the limb's system is not square (a graph family: more
    equations than unknowns, made square by random combinations; no certificate is attempted)."""
    if not sysm.rigid:
        return None
    if not qs:
        return []
    P = np.real(sysm.pose_parameters(np.asarray(D, dtype=float)))
    return list(certify(limb_system(sysm, P[:4], P[4:7]), np.array([limb_point(sysm, q) for q in qs]),
                        real=[True] * len(qs)))


def statement(certs: Sequence[Certificate | None], complex_certs: Sequence[Certificate] = ()) -> str:
    """One sentence on what was certified (the ``certification`` field of fk and ik)."""
    tried = [c for c in certs if c is not None]
    if not tried and not complex_certs:
        return "not attempted"
    n_ok = n_certified(tried)
    text = (f"{n_ok} of {len(tried)} solution(s) certified: a Krawczyk test in ball arithmetic proved a unique root "
            "of the exact polynomial system (the floats of the model as exact data) within the stated box of each, "
            "real, and every box disjoint from the others")
    if complex_certs:
        text += (f"; {n_certified(complex_certs)} of {len(complex_certs)} complex end point(s) certified (distinct "
                 "non-real roots)")
    bad = [c.reason for c in tried if not c.certified]
    if bad:
        text += f"; not certified: {bad[0]}"
    return text
