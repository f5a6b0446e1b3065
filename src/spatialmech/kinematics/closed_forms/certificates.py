"""Certificates of the closed forms' solutions (issue 27): each real solution of a closed form's
polynomial system is certified, as the homotopies' are, by the Krawczyk test in ball arithmetic
of :mod:`..homotopy.certify` (a unique root of the exact system in a box about the point, the
boxes disjoint, the root real).  The systems, their floats taken as exact data:

- the spherical 3-RRR wrist: its three quaternion quadrics in ``P^3`` on a real affine patch
  (:func:`projective`);
- the 5-CS linkage: its ten quadrics on ``SO(3) x C`` homogenised, ``h = 1``
  (:func:`..cs_forward.homogeneous_quadrics`, :func:`affine`);
- the four-bar loop: ``c^2 + s^2 = h^2`` and the coupler condition ``alpha c + beta s + gamma h
  = 0`` in ``(cos phi, sin phi, h)``, ``h = 1`` (:func:`four_bar`);
- a loop of 5 to 7 R joints: the padded 6R's limb system (:func:`..homotopy.certify.certify_inverse`).

:func:`run` times a certification and returns ``None`` when certification is off
(:func:`..homotopy.certify.enabled`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..homotopy import certify as hcert

__all__ = ["Certified", "affine", "four_bar", "projective", "run"]


@dataclass(frozen=True)
class Certified:
    """The certificates of a closed form's listed solutions (one per candidate pose, in order;
    ``None``: not attempted), the sentence saying what was proven and the time taken (s)."""

    certificates: tuple[hcert.Certificate | None, ...]
    statement: str
    seconds: float

    @property
    def n_certified(self) -> int:
        return hcert.n_certified([c for c in self.certificates if c is not None])


def run(fn: Callable[[], Sequence[hcert.Certificate | None] | None]) -> Certified | None:
    """``fn()`` timed as a :class:`Certified`; ``None`` when certification is off (or ``fn``
    attempts none)."""
    if not hcert.enabled():
        return None
    t0 = time.perf_counter()
    certs = fn()
    if certs is None:
        return None
    certs = tuple(certs)
    return Certified(certs, hcert.statement(certs), time.perf_counter() - t0)


def projective(Q, points: Sequence[np.ndarray]) -> list[hcert.Certificate | None]:
    """Certificates of the real ``points`` of ``P^k`` as roots of the homogeneous quadrics ``Q``
    (k, k + 1, k + 1) (:func:`..homotopy.certify.certify_projective`)."""
    if not len(points):
        return []
    return hcert.certify_projective(np.asarray(Q, dtype=float), [np.real(p) for p in points])[0]


def affine(Q, points: Sequence[np.ndarray]) -> list[hcert.Certificate | None]:
    """Certificates of the real ``points`` (their last coordinate ``h = 1``) as roots of the
    homogeneous quadrics ``Q`` (n - 1, n, n) on the patch ``h = 1``."""
    if not len(points):
        return []
    Q = np.asarray(Q, dtype=float)
    n = Q.shape[1]
    B = np.zeros((1, n))
    B[0, -1] = 1.0
    return list(hcert.certify(hcert.quadric_system(Q, B, [1.0]), np.real(np.array(points)), real=[True] * len(points)))


def four_bar(alpha: float, beta: float, gamma: float, phis: Sequence[float]) -> list[hcert.Certificate | None]:
    """Certificates of the output angles ``phis`` (rad) as roots of ``alpha cos + beta sin +
    gamma = 0`` on the circle: the system ``c^2 + s^2 - h^2 = 0``, ``alpha c + beta s + gamma h =
    0``, ``h = 1`` in ``(c, s, h)``."""
    if not len(phis):
        return []
    Q = np.diag([1.0, 1.0, -1.0])[None]
    B = np.array([[alpha, beta, gamma], [0.0, 0.0, 1.0]], dtype=float)
    P = np.array([[np.cos(p), np.sin(p), 1.0] for p in phis])
    return list(hcert.certify(hcert.quadric_system(Q, B, [0.0, 1.0]), P, real=[True] * len(P)))
