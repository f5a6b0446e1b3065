"""The float pass of the certificates, compiled: the entries of :mod:`.kernels_certify`, whose
Python reference is :mod:`..homotopy.certify_float` (the same enclosures and the same test,
operation by operation; :func:`krawczyk_limb` for ``certify_float.krawczyk_limb``,
:func:`krawczyk_test` for the test of ``certify_float.krawczyk_real``).  The ball values of the
points whose test fails with the float values (python-flint) are taken as in the reference."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from .kernels_certify import nb_krawczyk, nb_limb_enclosures

__all__ = ["krawczyk_limb", "krawczyk_test", "pack_limb"]

_PACKED: dict[int, tuple] = {}


_REFERENCE: list = []


def _reference() -> Any:
    """:mod:`..homotopy.certify_float` (its checks, preconditioners and ball values), imported
    when first needed: its caller has imported it already, and importing it here at the top
    would load the homotopy package with the compiled engine (0.2 s) in every process."""
    if not _REFERENCE:
        from ..homotopy import certify_float

        _REFERENCE.append(certify_float)
    return _REFERENCE[0]


def pack_limb(sysm) -> tuple:
    """The arguments of :func:`.kernels_certify.nb_limb_enclosures` that describe the limb
    ``sysm`` (:class:`..homotopy.inverse.LimbIK`): the S joint flag, its centre, the circles, the
    factors (left, then right) and the derivatives; cached per limb object."""
    hit = _PACKED.get(id(sysm))
    if hit is not None and hit[0] is sysm:
        return hit[1]
    rotation = _reference().rotation_coefficients()
    if len(_PACKED) > 256:
        _PACKED.clear()
    factors = tuple(sysm.left) + tuple(sysm.right)
    rev = np.array([fa.kind == "R" for fa in factors], dtype=np.bool_)
    i_s = np.array([fa.idx[1] if fa.kind == "R" else fa.idx[0] for fa in factors], dtype=np.int64)
    i_c = np.array([fa.idx[0] for fa in factors], dtype=np.int64)
    const = np.zeros((len(factors), 3, 4, 4))
    d_fac, d_z, dM = [], [], []
    for f, fa in enumerate(factors):
        const[f, 0], const[f, 1] = np.eye(4), fa.sign * fa.A
        if fa.kind == "R":
            const[f, 2] = fa.A2
            d_fac += [f, f]
            d_z += [fa.idx[0], fa.idx[1]]
            dM += [-np.asarray(fa.A2, dtype=float), fa.sign * fa.A]
        else:
            d_fac.append(f)
            d_z.append(fa.idx[0])
            dM.append(fa.sign * fa.A)
    circles = np.array(sysm.circles, dtype=np.int64).reshape(-1, 2)
    packed = (rotation, np.bool_(sysm.kind == "point"), np.ascontiguousarray(sysm.centre, dtype=float), circles, rev, i_s, i_c,
              const, np.int64(len(sysm.left)), np.array(d_fac, dtype=np.int64), np.array(d_z, dtype=np.int64),
              np.array(dM, dtype=float).reshape(-1, 4, 4))
    _PACKED[id(sysm)] = (sysm, packed)
    return packed


def krawczyk_limb(sysm, q: np.ndarray, t: np.ndarray, Y: np.ndarray, max_radius: float,
                  ball_values: Callable[[np.ndarray], Any] | None = None) -> list[float | None]:
    """``certify_float.krawczyk_limb`` compiled: the limb's values at the points ``Y`` (k, n)
    and its Jacobian over their largest boxes in interval arithmetic
    (:func:`.kernels_certify.nb_limb_enclosures`), then :func:`krawczyk_test`.  ``q`` and ``t``
    (the pose's exact floats) are checked by the caller."""
    cf = _reference()
    Y = np.ascontiguousarray(Y, dtype=float)
    k, n = Y.shape
    if not cf.testable(Y):
        return [None] * k
    Fm, Fr = np.empty((k, n)), np.empty((k, n))
    Jm, Jr = np.empty((k, n, n)), np.empty((k, n, n))
    nb_limb_enclosures(Y, cf.box_radii(Y, max_radius), np.ascontiguousarray(q, dtype=float),
                       np.ascontiguousarray(t, dtype=float), *pack_limb(sysm), Fm, Fr, Jm, Jr)
    A, ok = cf.preconditioners(Jm, Jr)
    return krawczyk_test(A, Jm, Jr, Fm, Fr, Y, max_radius, ok, ball_values)


def krawczyk_test(A: np.ndarray, Jm: np.ndarray, Jr: np.ndarray, Fm: np.ndarray, Fr: np.ndarray, Y: np.ndarray,
                  max_radius: float, ok: np.ndarray,
                  ball_values: Callable[[np.ndarray], Any] | None = None) -> list[float | None]:
    """The Krawczyk test of ``certify_float.krawczyk_real`` compiled
    (:func:`.kernels_certify.nb_krawczyk`) at the points ``Y`` (k, n) where ``ok``: ``A`` the
    preconditioners, ``(Jm, Jr)`` the Jacobian's enclosure over the largest boxes, ``(Fm, Fr)``
    the values' at the points.  Where the first radius fails, the values are taken from
    ``ball_values`` (when given) and the test runs again with the wider radii."""
    Y = np.ascontiguousarray(Y, dtype=float)
    k = Y.shape[0]
    args = [np.ascontiguousarray(a, dtype=float) for a in (A, Jm, Jr, Fm, Fr)]
    todo = np.ascontiguousarray(ok, dtype=np.bool_)
    res = np.zeros(k)
    nb_krawczyk(*args, Y, float(max_radius), todo, np.bool_(ball_values is None), res)
    again = todo & (res == 0.0)
    if ball_values is not None and again.any():
        cf = _reference()
        F = cf.with_ball_values(cf.MR(args[3], args[4]), np.flatnonzero(again), Y, ball_values)
        nb_krawczyk(*args[:3], F.m, np.ascontiguousarray(F.r), Y, float(max_radius), again, np.bool_(True), res)
    return [float(r) if r > 0.0 else None for r in res]
