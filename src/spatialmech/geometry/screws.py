"""Screws, twists, wrenches and screw systems.

Convention (the one convention of the whole library, as in the papers):
a screw is a 6-vector ``$ = (s ; s0)``: first the direction part ``s`` (angular velocity of a
twist, force of a wrench), then the moment part ``s0``.  For a line through point ``r`` with
direction ``s`` and pitch ``h``: ``s0 = r x s + h s``; a pure translation (or a couple) is
``(0 ; s)``.  SI units, radians.

The reciprocal product of ``$1`` and ``$2`` is ``s1 . s02 + s2 . s01 = $1^T DELTA $2``.

Every function works on stacks: the last axis has length 6, leading axes broadcast.

Worked example (a revolute axis along z through (1, 0, 0) and a force along z through the
origin are coplanar parallel lines, hence reciprocal)::

    >>> import numpy as np
    >>> t = axis_screw([0, 0, 1], [1, 0, 0])
    >>> t
    array([ 0.,  0.,  1.,  0., -1.,  0.])
    >>> float(reciprocal_product(t, axis_screw([0, 0, 1], [0, 0, 0])))
    0.0
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from .rotations import skew
from .tolerances import DEFAULT, current
from .validate import as_finite_array, as_unit_vector

__all__ = [
    "DELTA",
    "adjoint",
    "axis_screw",
    "basis",
    "cofactor_reciprocal",
    "contains",
    "intersection",
    "line_point",
    "nondimensional",
    "pitch",
    "plucker_line",
    "rank",
    "reciprocal_basis",
    "reciprocal_product",
    "relative_singular_values",
    "rref",
    "swap",
    "transform_screws",
    "translation_screw",
    "validate_line",
]

#: The reciprocal-product matrix ``[[0, I3], [I3, 0]]``.
DELTA = np.block([[np.zeros((3, 3)), np.eye(3)], [np.eye(3), np.zeros((3, 3))]])

#: Default relative tolerance for rank decisions on nondimensional, row-normalised screws (the
#: default of :attr:`~spatialmech.geometry.tolerances.Tolerances.rank`; functions given no
#: ``rtol`` use the one in force, :func:`~spatialmech.geometry.tolerances.current`).
RANK_RTOL = DEFAULT.rank


def axis_screw(direction, point, *, pitch: float = 0.0, name: str = "direction") -> np.ndarray:
    """Unit screw on the line through ``point`` along unit ``direction``: ``(s ; p x s + h s)``.

    ``direction`` must be a unit vector (checked; not silently normalised).
    """
    s = as_unit_vector(direction, name)
    p = as_finite_array(point, "point", shape=(3,))
    return np.concatenate([s, np.cross(p, s) + pitch * s])


def translation_screw(direction, *, name: str = "direction") -> np.ndarray:
    """Pure translation (twist) or couple (wrench) ``(0 ; s)`` along unit ``direction``."""
    s = as_unit_vector(direction, name)
    return np.concatenate([np.zeros(3), s])


def swap(screws) -> np.ndarray:
    """``DELTA $``: exchange the direction and moment parts."""
    s = np.asarray(screws, dtype=float)
    return np.concatenate([s[..., 3:], s[..., :3]], axis=-1)


def reciprocal_product(a, b) -> np.ndarray:
    """``s1 . s02 + s2 . s01``, broadcast over leading axes.  Zero means reciprocal."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return np.sum(a[..., :3] * b[..., 3:], axis=-1) + np.sum(b[..., :3] * a[..., 3:], axis=-1)


def adjoint(T) -> np.ndarray:
    """6x6 adjoint of a rigid displacement ``T`` (4x4, or stack ...x4x4).

    Maps a screw ``(s ; s0)`` attached to a body to the same screw after the body is displaced
    by ``T = [[R, p], [0, 1]]``: ``(R s ; p x R s + R s0)``.
    """
    T = np.asarray(T, dtype=float)
    R = T[..., :3, :3]
    p = T[..., :3, 3]
    Ad = np.zeros((*T.shape[:-2], 6, 6))
    Ad[..., :3, :3] = R
    Ad[..., 3:, 3:] = R
    Ad[..., 3:, :3] = skew(p) @ R
    return Ad


def transform_screws(T, screws) -> np.ndarray:
    """Displace screws (last axis 6) rigidly by ``T``: ``adjoint(T) @ $``."""
    T = np.asarray(T, dtype=float)
    s = np.asarray(screws, dtype=float)
    R = T[..., :3, :3]
    p = T[..., :3, 3]
    d = np.einsum("...ij,...j->...i", R, s[..., :3])
    m = np.einsum("...ij,...j->...i", R, s[..., 3:]) + np.cross(p, d)
    return np.concatenate([d, m], axis=-1)


def plucker_line(direction, point) -> np.ndarray:
    """Normalised Plücker coordinates ``(s ; r x s)`` of a line (unit direction required)."""
    return axis_screw(direction, point)


def validate_line(line, *, name: str = "line", atol: float = 1e-9) -> np.ndarray:
    """Check that ``line`` is a normalised Plücker line: ``|s| = 1`` and ``s . s0 = 0``.

    Raises ``ValueError`` naming ``name`` and the violated condition.
    """
    L = as_finite_array(line, name, shape=(6,))
    n = np.linalg.norm(L[:3])
    if abs(n - 1.0) > atol:
        raise InputError(f"{name}: direction part is not a unit vector (|s| = {n:.6g})")
    scale = max(1.0, float(np.linalg.norm(L[3:])))
    if abs(L[:3] @ L[3:]) > atol * scale:
        raise InputError(
            f"{name}: not a line: direction is not orthogonal to moment (s.s0 = {L[:3] @ L[3:]:.3g})"
        )
    return L


def line_point(line) -> np.ndarray:
    """Point of the line (unit direction) closest to the origin: ``s x s0``."""
    L = np.asarray(line, dtype=float)
    return np.cross(L[..., :3], L[..., 3:])


def pitch(screw) -> np.ndarray:
    """Pitch ``s . s0 / s . s``; ``inf`` for pure translations / couples."""
    S = np.asarray(screw, dtype=float)
    num = np.sum(S[..., :3] * S[..., 3:], axis=-1)
    den = np.sum(S[..., :3] ** 2, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), np.inf)


def nondimensional(screws, length_scale: float) -> np.ndarray:
    """Divide moment parts by a characteristic length so that both halves are comparable.

    Reciprocity and linear dependence are preserved (each screw is only scaled by a positive
    factor relative to the others), which makes rank decisions independent of the unit of
    length.
    """
    S = np.array(screws, dtype=float, copy=True)
    S[..., 3:] /= float(length_scale)
    return S


def _row_normalised(S: np.ndarray) -> np.ndarray:
    m = np.max(np.abs(S), axis=-1, keepdims=True)  # scale first: no overflow in the squares
    S = S / np.where(m > 0, m, 1.0)
    n = np.linalg.norm(S, axis=-1, keepdims=True)
    return S / np.where(n > 0, n, 1.0)


def _svd(screws, length_scale: float):
    S = np.atleast_2d(np.asarray(screws, dtype=float))
    if S.shape[-1] != 6:
        raise InputError(f"screws: expected shape (m, 6), got {S.shape}")
    if not np.all(np.isfinite(S)):
        raise InputError("screws: contain NaN or infinity")
    Sn = _row_normalised(nondimensional(S, length_scale))
    if Sn.shape[0] == 0:
        return Sn, np.zeros(0), np.eye(6)
    _, sv, vt = np.linalg.svd(Sn, full_matrices=True)
    return Sn, sv, vt


def _rank_from_sv(sv: np.ndarray, rtol: float | None) -> int:
    if sv.size == 0 or sv[0] == 0:
        return 0
    rtol = current().rank if rtol is None else rtol
    return int(np.sum(sv > rtol * max(1.0, sv[0])))


def relative_singular_values(screws, *, length_scale: float = 1.0) -> np.ndarray:
    """The singular values that rank decisions compare with ``rtol``: those of the
    nondimensional, row-normalised screws divided by ``max(1, largest)`` (``min(m, 6)`` values,
    descending).  ``rank(S, rtol=t)`` is the number above ``t``."""
    _, sv, _ = _svd(screws, length_scale)
    if sv.size == 0 or sv[0] == 0:
        return np.zeros(sv.size)
    return sv / max(1.0, sv[0])


def rank(screws, *, length_scale: float = 1.0, rtol: float | None = None) -> int:
    """Dimension of the screw system spanned by ``screws`` (m x 6).

    Scale-aware: moments are divided by ``length_scale`` and every screw normalised before
    the singular values are compared with ``rtol`` (default: the rank tolerance in force,
    :mod:`~spatialmech.geometry.tolerances`).
    """
    _, sv, _ = _svd(screws, length_scale)
    return _rank_from_sv(sv, rtol)


def basis(screws, *, length_scale: float = 1.0, rtol: float | None = None) -> np.ndarray:
    """An orthonormal (in nondimensional terms) basis of the span, returned in SI units."""
    _, sv, vt = _svd(screws, length_scale)
    r = _rank_from_sv(sv, rtol)
    B = vt[:r].copy()
    B[:, 3:] *= length_scale
    return B


def reciprocal_basis(screws, *, length_scale: float = 1.0, rtol: float | None = None) -> np.ndarray:
    """Basis (6 - rank, 6) of the screws reciprocal to every screw in ``screws``.

    Solved in nondimensional form (moments divided by ``length_scale``) and converted back,
    so the result is in SI units: for a twist system it is the constraint-wrench system.
    """
    S = np.atleast_2d(np.asarray(screws, dtype=float))
    if S.shape[0] == 0:
        return np.eye(6)
    _, sv, vt = _svd(S, length_scale)
    r = _rank_from_sv(sv, rtol)
    null = vt[r:]  # rows y with Sn y = 0, i.e. Sn DELTA (DELTA y) = 0
    W = swap(null)  # in nondimensional units: (f ; m')
    W[:, 3:] *= length_scale
    return W


def cofactor_reciprocal(screws) -> np.ndarray:
    """The reciprocal screw of five screws by cofactors (the papers' eq 8), sign-continuous.

    For a 5x6 matrix ``S`` (stack ...x5x6) returns ``x = DELTA y`` with
    ``y_j = (-1)^j det(S without column j)``, so that ``S DELTA x = S y = 0``.  Being a
    polynomial in the entries of ``S``, ``x`` varies continuously along a path and its sign is
    meaningful (unlike an SVD null vector, whose sign is arbitrary).  It vanishes exactly when
    the five screws are dependent.
    """
    S = np.asarray(screws, dtype=float)
    if S.shape[-2:] != (5, 6):
        raise InputError(f"screws: expected shape (..., 5, 6), got {S.shape}")
    cols = []
    for j in range(6):
        minor = np.delete(S, j, axis=-1)
        cols.append((-1) ** j * np.linalg.det(minor))
    y = np.stack(cols, axis=-1)
    return swap(y)


def rref(A, *, tol: float | None = None) -> np.ndarray:
    """Reduced row-echelon form of the rows of ``A`` (dependent rows dropped): a deterministic,
    readable basis of their span (e.g. a constraint system given as forces along x and y
    rather than an arbitrary SVD basis).  Pass nondimensional screws (see
    :func:`nondimensional`) so that the tolerances are scale-free.

    Columns are taken in order; a column gives the next pivot only when its largest remaining
    entry is at least ``tol`` (default: the ``pivot`` tolerance in force,
    :mod:`~spatialmech.geometry.tolerances`) times the largest entry left in the whole
    remaining block, so that the rounding noise of typed data never becomes a pivot (dividing
    by it would blow the row up to 1e15).  The number of rows returned is the rank at the
    ``rank`` tolerance in force: rows stop only when everything left is below it (relative to
    the largest entry of ``A``).
    """
    t = current()
    ptol = t.pivot if tol is None else float(tol)
    A = np.array(A, dtype=float, copy=True)
    if A.ndim != 2:
        raise InputError(f"A: expected a matrix (rows of screws), got shape {A.shape}")
    rows, cols = A.shape
    if A.size == 0:
        return A[:0]
    floor = t.rank * float(np.max(np.abs(A)))
    r = 0
    for c in range(cols):
        if r == rows:
            break
        block = np.abs(A[r:, c:])
        big = float(np.max(block))
        if big <= floor:
            break  # the remaining rows are zero up to round-off
        piv = r + int(np.argmax(block[:, 0]))
        if abs(A[piv, c]) < ptol * big:
            continue
        A[[r, piv]] = A[[piv, r]]
        A[r] /= A[r, c]
        for i in range(rows):
            if i != r:
                A[i] -= A[i, c] * A[r]
        A[r, c] = 1.0
        A[np.arange(rows) != r, c] = 0.0
        r += 1
    return A[:r]


def intersection(A, B, *, length_scale: float = 1.0, rtol: float | None = None) -> np.ndarray:
    """Basis of the intersection of the spans of ``A`` and ``B`` (as screw systems)."""
    # span(A) ∩ span(B) = reciprocal( reciprocal(A) ∪ reciprocal(B) )
    RA = reciprocal_basis(A, length_scale=length_scale, rtol=rtol)
    RB = reciprocal_basis(B, length_scale=length_scale, rtol=rtol)
    both = np.vstack([RA, RB])
    return reciprocal_basis(both, length_scale=length_scale, rtol=rtol)


def contains(system, screw, *, length_scale: float = 1.0, rtol: float | None = None) -> bool:
    """Whether ``screw`` lies in the span of ``system`` (scale-aware; ``rtol`` default: the
    ``contains`` tolerance in force)."""
    rtol = current().contains if rtol is None else rtol
    S = np.atleast_2d(np.asarray(system, dtype=float))
    r0 = rank(S, length_scale=length_scale, rtol=rtol) if S.size else 0
    r1 = rank(np.vstack([S, np.atleast_2d(screw)]) if S.size else np.atleast_2d(screw),
              length_scale=length_scale, rtol=rtol)
    return r1 == r0
