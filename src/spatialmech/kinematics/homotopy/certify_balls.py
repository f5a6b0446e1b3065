"""Ball arithmetic for the certificates (issue 27; :mod:`.certify`): exact ball matrices of
floats in python-flint's real (``arb``) or complex (``acb``) balls, the centred boxes of the
Krawczyk test, and the protocol of a square polynomial system evaluated in balls
(:class:`BallSystem`, implemented by :mod:`.certify_systems` and :mod:`.certify_loops`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from flint import acb, acb_mat, arb, arb_mat

__all__ = ["COMPLEX", "REAL", "Ball", "BallSystem", "Field", "field_of", "midpoints", "pow2_up"]


#: A ball matrix: :class:`flint.arb_mat` (real balls) or :class:`flint.acb_mat` (complex balls).
Ball = Any


class BallSystem(Protocol):
    """A square polynomial system evaluated in ball arithmetic.

    ``n``: the number of unknowns (and of equations); ``real``: whether its coefficients are real
    (then the conjugate of a root is a root).  ``values(x)`` encloses ``F`` at the ball vector
    ``x`` (an ``n x 1`` :class:`flint.acb_mat`); ``jacobian(x)`` encloses ``F'`` over it
    (``n x n``)."""

    n: int
    real: bool

    def values(self, x: Ball) -> Ball: ...

    def jacobian(self, x: Ball) -> Ball: ...




_I = acb(0, 1)


@dataclass(frozen=True)
class Field:
    """Real (``arb``) or complex (``acb``) balls: exact matrices of floats, columns, boxes."""

    real: bool

    def mat(self, M) -> arb_mat | acb_mat:
        """An exact ball matrix of the floats ``M`` (python floats convert exactly)."""
        M = np.asarray(M)
        if M.ndim == 1:
            M = M[:, None]
        re = arb_mat(np.ascontiguousarray(M.real, dtype=float).tolist())
        if self.real:
            return re
        out = acb_mat(re)
        if np.iscomplexobj(M) and np.any(M.imag):
            out += acb_mat(arb_mat(np.ascontiguousarray(M.imag, dtype=float).tolist())) * _I
        return out

    def col(self, v) -> arb_mat | acb_mat:
        return self.mat(np.asarray(v).ravel())

    def scalar(self, x: float) -> arb | acb:
        return arb(float(x)) if self.real else acb(float(x))

    def radius_col(self, n: int, r: float) -> arb_mat | acb_mat:
        """Balls of centre zero and radius ``r`` (each real and imaginary part), cached."""
        key = (self.real, n, r)
        hit = _RADII.get(key)
        if hit is None:
            if len(_RADII) > 4096:
                _RADII.clear()
            hit = _RADII[key] = (arb_mat([[arb(0, r)] for _ in range(n)]) if self.real
                                 else acb_mat([[acb(arb(0, r), arb(0, r))] for _ in range(n)]))
        return hit

    def identity(self, n: int) -> arb_mat | acb_mat:
        key = (self.real, -n, 0.0)
        hit = _RADII.get(key)
        if hit is None:
            flat = [1 if i == j else 0 for i in range(n) for j in range(n)]
            hit = _RADII[key] = arb_mat(n, n, flat) if self.real else acb_mat(n, n, flat)
        return hit


REAL, COMPLEX = Field(True), Field(False)
_RADII: dict[tuple[bool, int, float], arb_mat | acb_mat] = {}


def field_of(x) -> Field:
    """The field of the ball matrix ``x``: :data:`REAL` for an ``arb_mat``, else :data:`COMPLEX`."""
    return REAL if isinstance(x, arb_mat) else COMPLEX


def pow2_up(r: float) -> float:
    """The least power of two not below ``r``."""
    m, e = np.frexp(r)
    return float(np.ldexp(1.0, int(e) - (1 if m == 0.5 else 0)))


def midpoints(M) -> np.ndarray:
    """The midpoints of a ball matrix as floats."""
    shape = (M.nrows(), M.ncols())
    if isinstance(M, arb_mat):
        return np.array([float(v) for v in M.mid().entries()], dtype=float).reshape(shape)
    return np.array([complex(v) for v in M.mid().entries()], dtype=complex).reshape(shape)
