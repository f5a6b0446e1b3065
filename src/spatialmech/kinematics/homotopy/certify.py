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

This module is pure: :func:`certify` over a :class:`BallSystem` and points returns one
:class:`Certificate` per point.  :func:`quadric_system` builds the ball system of the Study
formulation (quadrics and linear equations), :func:`limb_system` that of a limb's inverse
position.  HomotopyContinuation.jl's ``certify`` (Breiding, Rose and Timme 2020) uses the same
test; this is an independent implementation.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from flint import acb, acb_mat, arb, arb_mat, ctx

from ...errors import InputError
from ...geometry.tolerances import CERTIFY_GROWTH, CERTIFY_MAX_RADIUS, CERTIFY_MIN_RADIUS, CERTIFY_PRECISION
from .certify_float import krawczyk_limb, krawczyk_quadrics

__all__ = [
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
    "quadric_system",
    "statement",
    "study_parameters",
]


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


@dataclass(frozen=True)
class Certificate:
    """The verdict on one point.

    ``certified``: the box of half-width ``radius`` about the point (each real and imaginary part)
    holds exactly one root of the exact system, and no other point's certified box shares it.
    ``radius``: the half-width of the smallest box that passed (in the system's coordinates);
    ``None`` when no box passed.  ``real``: ``True`` when the root is proven real, ``False`` when
    proven non-real, ``None`` when not decided.  ``duplicate_of``: the index of the earlier point
    whose box holds the same root.  ``reason``: why not certified (empty when certified)."""

    certified: bool
    radius: float | None
    real: bool | None
    reason: str = ""
    duplicate_of: int | None = None

    def to_dict(self) -> dict:
        return {"certified": self.certified, "box_radius": self.radius, "real": self.real,
                "reason": self.reason or None, "duplicate_of": self.duplicate_of}


def n_certified(certs: Sequence[Certificate]) -> int:
    """The number of distinct roots certified."""
    return sum(c.certified for c in certs)


# ------------------------------------------------------------------------------ ball helpers
_I = acb(0, 1)


@dataclass(frozen=True)
class _Field:
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


REAL, COMPLEX = _Field(True), _Field(False)
_RADII: dict[tuple[bool, int, float], arb_mat | acb_mat] = {}


def _field(x) -> _Field:
    return REAL if isinstance(x, arb_mat) else COMPLEX


def _pow2_up(r: float) -> float:
    """The least power of two not below ``r``."""
    m, e = np.frexp(r)
    return float(np.ldexp(1.0, int(e) - (1 if m == 0.5 else 0)))


def _mid(M) -> np.ndarray:
    """The midpoints of a ball matrix as floats."""
    shape = (M.nrows(), M.ncols())
    if isinstance(M, arb_mat):
        return np.array([float(v) for v in M.mid().entries()], dtype=float).reshape(shape)
    return np.array([complex(v) for v in M.mid().entries()], dtype=complex).reshape(shape)


# ------------------------------------------------------------------------------ the test
def _contained(X, K, n: int) -> bool:
    return all(X[i, 0].contains_interior(K[i, 0]) for i in range(n))


def _inverse(J: np.ndarray) -> np.ndarray | None:
    if not np.all(np.isfinite(J)):
        return None
    try:
        A = np.linalg.inv(J)
    except np.linalg.LinAlgError:
        return None
    return A if np.all(np.isfinite(A)) else None


def _conjugate_partners(system: BallSystem, Ys: list[np.ndarray], real: list[bool]) -> dict[int, int]:
    """``{j: i}``: the point ``j`` is (to 1e-8 relative) the conjugate of the point ``i < j``, for a
    system with real coefficients: ``j`` is then certified by the conjugate of ``i``'s box."""
    if not system.real or len(Ys) < 2 or all(real):
        return {}
    Y = np.array(Ys)
    scale = 1.0 + np.max(np.abs(Y), axis=1)
    dist = np.max(np.abs(Y[None, :, :] - Y.conj()[:, None, :]), axis=2) / scale[None, :]  # [i, j]: |y_j - conj y_i|
    out: dict[int, int] = {}
    used: set[int] = set()
    for i in range(len(Ys)):
        if real[i] or i in out or i in used or not np.any(Y[i].imag):
            continue
        for jj in np.flatnonzero(dist[i] < 1e-8):
            j = int(jj)
            if j > i and not real[j] and j not in out and j not in used:
                out[j] = i
                used.add(i)
                break
    return out


def _one(system: BallSystem, y: np.ndarray, max_radius: float,
         Ainv: np.ndarray | None = None) -> tuple[float | None, str, bool]:
    """(radius, reason, real box) of one point: the smallest box that passes, or why none does.
    A real point of a real system gets a real box (uniqueness among real points).

    ``F'`` is enclosed once over a box ``CERTIFY_GROWTH`` times wider than the first one tried
    (it encloses ``F'`` over every box inside it, so one evaluation serves those radii; the
    preconditioner ``A`` is the inverse of its midpoint, or ``Ainv`` when given: any matrix
    serves); a radius beyond it is tried with ``F'`` over its own box."""
    n = system.n
    f = REAL if system.real and not np.any(y.imag) else COMPLEX
    yc = f.col(y.real if f.real else y)
    scale = 1.0 + float(np.max(np.abs(y)))
    rmax = max_radius * scale
    if Ainv is None:
        Ainv = _inverse(_mid(system.jacobian(yc)))
    if Ainv is None:
        return None, "the Jacobian is singular at the point", f.real
    A = f.mat(Ainv.real if f.real else Ainv)
    AF = A * system.values(yc)
    step = float(np.max(np.abs(_mid(AF))))
    r = _pow2_up(max(4.0 * step, CERTIFY_MIN_RADIUS * scale))
    if not r <= rmax:
        return None, (f"its Newton correction ({step:.1e}) exceeds the largest box ({rmax:.1e}): not an accurate "
                      "approximation of a root"), f.real
    rJ = min(_pow2_up(rmax), r * CERTIFY_GROWTH)  # the box of the shared enclosure of F'
    eye = f.identity(n)
    M = eye - A * system.jacobian(yc + f.radius_col(n, rJ))
    base = yc - AF
    while r <= rmax:
        D = f.radius_col(n, r)
        Mr = M if r <= rJ else eye - A * system.jacobian(yc + D)
        if _contained(yc + D, base + Mr * D, n):
            return r, "", f.real
        r *= CERTIFY_GROWTH
    return None, ("the Krawczyk test failed in every box up to the largest (a singular root, or roots closer than the "
                  "point's accuracy)"), f.real


def _real_verdict(system: BallSystem, y: np.ndarray, r: float, real_box: bool) -> bool | None:
    if real_box:
        return True  # a real box: its root is real
    if not system.real:
        return None
    if not np.any(y.imag):
        return True  # a conjugation-symmetric box: its unique root is its own conjugate
    if np.any(np.abs(y.imag) > 2.0 * r):
        return False  # the box misses its conjugate: the conjugate root is another one
    return None


def _pairs(Y: np.ndarray, R: np.ndarray, Rim: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(disjoint, inside)`` (m, m) of the boxes of centres ``Y`` (m, n) and half-widths ``R``
    (real parts) and ``Rim`` (imaginary parts; 0 for a real box): ``disjoint[i, j]`` when the
    boxes certainly do not meet, ``inside[i, j]`` when box ``i`` certainly lies inside box ``j``
    (margins for the floats of the comparison)."""
    a = np.abs(Y)
    eps = 4e-16 * (a[:, None, :] + a[None, :, :])
    dre = np.abs(Y.real[:, None, :] - Y.real[None, :, :])
    dim = np.abs(Y.imag[:, None, :] - Y.imag[None, :, :])
    gre = 1.01 * (R[:, None, None] + R[None, :, None]) + eps
    gim = 1.01 * (Rim[:, None, None] + Rim[None, :, None]) + eps
    disjoint = np.any((dre > gre) | (dim > gim), axis=2)
    sre = R[None, :, None] - R[:, None, None] - eps
    sim = Rim[None, :, None] - Rim[:, None, None] - eps
    inside = np.all((dre < sre) & ((dim < sim) | ((Rim[:, None, None] == 0) & (Rim[None, :, None] == 0) & (dim == 0))),
                    axis=2)
    return disjoint, inside


def certify(system: BallSystem, points, *, real: Sequence[bool] | None = None,
            max_radius: float = CERTIFY_MAX_RADIUS) -> tuple[Certificate, ...]:
    """Certify each of ``points`` (m, n) as an approximate zero of ``system`` with its own root.

    ``real[i]``: the point is meant to be real; its imaginary part is dropped and a real box
    about it proves a unique real root there (``system.real`` required).  ``max_radius``: the
    largest box half-width tried, relative to ``1 + max |y|`` (default ``CERTIFY_MAX_RADIUS``).
    Returns one :class:`Certificate` per point (module docstring)."""
    P = np.atleast_2d(np.asarray(points, dtype=complex))
    if P.size == 0:
        return ()
    flags = [False] * len(P) if real is None else [bool(v) for v in real]
    if len(flags) != len(P):
        raise InputError(f"real: {len(flags)} flags for {len(P)} points")
    Ys = [y.real.astype(complex) if flags[i] and system.real else y for i, y in enumerate(P)]
    if P.shape[1] != system.n or not np.all(np.isfinite(P)):
        raise InputError(f"points: expected rows of {system.n} finite numbers, got shape {P.shape}")
    prec = ctx.prec
    ctx.prec = CERTIFY_PRECISION
    try:
        partner = _conjugate_partners(system, Ys, flags)
        todo = [i for i in range(len(Ys)) if i not in partner]
        found: list = [None] * len(Ys)
        fast = getattr(system, "krawczyk_float", None)  # real points, all at once (certify_float)
        quick = [i for i in todo if system.real and not np.any(Ys[i].imag)]
        if fast is not None and quick:
            for i, r in zip(quick, fast(np.array([Ys[i].real for i in quick]), max_radius), strict=True):
                if r is not None:
                    found[i] = (Ys[i], r, "", True, 0.0)
        todo = [i for i in todo if found[i] is None]
        many = getattr(system, "jacobian_float_many", None)
        pre: list = [None] * len(todo)
        if many is not None and todo:  # floating-point preconditioners, all points at once
            pre = [_inverse(J) for J in many(np.array([Ys[i] for i in todo]))]
        for i, Ainv in zip(todo, pre, strict=True):
            found[i] = (Ys[i], *_one(system, Ys[i], max_radius, Ainv), 0.0)
        for j, i in partner.items():  # the conjugate of a certified box holds the conjugate root
            yi, ri, why, rb, _ = found[i]
            yj = yi.conj()
            found[j] = (yj, ri, why, rb, float(np.max(np.abs(Ys[j] - yj))))
    finally:
        ctx.prec = prec
    ok = [i for i, f in enumerate(found) if f[1] is not None]
    disjoint, inside = _pairs(np.array([found[i][0] for i in ok]).reshape(len(ok), system.n),
                              np.array([found[i][1] for i in ok], dtype=float),
                              np.array([0.0 if found[i][3] else found[i][1] for i in ok], dtype=float))
    pos = {i: k for k, i in enumerate(ok)}
    out: list[Certificate] = []
    for i, (y, r, why, real_box, extra) in enumerate(found):
        if r is None:
            out.append(Certificate(False, None, None, why))
            continue
        a = pos[i]
        dup = next((j for j in ok if j < i and inside[a, pos[j]]), None)
        clash = next((j for j in ok if j != i and not disjoint[a, pos[j]] and not inside[a, pos[j]]
                      and not (j > i and inside[pos[j], a])), None)
        rv = _real_verdict(system, y, r, real_box)
        r = r + extra  # from the point to its root: the box's half-width and the distance to its centre
        if dup is not None:
            out.append(Certificate(False, r, rv, f"the same root as point {dup} (its box lies inside that one)", dup))
        elif clash is not None:
            out.append(Certificate(False, r, rv, f"its box overlaps that of point {clash}: distinct roots not proven"))
        else:
            out.append(Certificate(True, r, rv))
    return tuple(out)


# ------------------------------------------------------------------------------ the systems
class QuadricBallSystem:
    """``x^T Q_k x`` for each quadric ``Q_k`` (m, n, n), then the linear equations ``B x = b``
    ((n - m, n) and (n - m,)): the Study formulation (seven quadrics and an affine patch)."""

    def __init__(self, Q, B, b) -> None:
        Q = np.asarray(Q)
        B = np.atleast_2d(np.asarray(B))
        b = np.asarray(b).ravel()
        self.m, self.n = Q.shape[0], Q.shape[1]
        if Q.shape[1:] != (self.n, self.n) or B.shape != (self.n - self.m, self.n) or b.shape != (self.n - self.m,):
            raise InputError(f"Q, B, b: expected m quadrics (n x n) and n - m linear equations of n unknowns, got shapes "
                             f"{Q.shape}, {B.shape}, {b.shape}")
        self.real = not (np.any(np.imag(Q)) or np.any(np.imag(B)) or np.any(np.imag(b)))
        self._Q, self._B, self._b = Q, B, b
        self._consts: dict[bool, tuple] = {}

    def _k(self, f: _Field) -> tuple:
        hit = self._consts.get(f.real)
        if hit is None:
            Qk = [f.mat(Q) for Q in self._Q]
            # the Jacobian's rows Q_k + Q_k^T, stacked: exact balls (the sum is taken in ball arithmetic)
            S = f.mat(np.concatenate(list(self._Q))) + f.mat(np.concatenate([Q.T for Q in self._Q]))
            Bm = f.mat(self._B)
            hit = self._consts[f.real] = (Qk, S, Bm, f.col(self._b),
                                          [[Bm[k, j] for j in range(self.n)] for k in range(self.n - self.m)])
        return hit

    def values(self, x):
        Qk, _, Bm, bv, _ = self._k(_field(x))
        xt = x.transpose()
        lin = Bm * x - bv
        rows: Any = [[(xt * (Q * x))[0, 0]] for Q in Qk]
        rows += [[lin[k, 0]] for k in range(self.n - self.m)]
        return arb_mat(rows) if isinstance(x, arb_mat) else acb_mat(rows)

    def krawczyk_float(self, Y: np.ndarray, max_radius: float) -> list[float | None]:
        """The fast first pass at the real points ``Y`` (:mod:`.certify_float`; real systems only)."""
        return krawczyk_quadrics(np.real(self._Q), np.real(self._B), np.real(self._b), Y, max_radius,
                                 lambda y: self.values(REAL.col(y)))

    def jacobian_float_many(self, Y: np.ndarray) -> np.ndarray:
        """``F'`` in floating point at the points ``Y`` (k, n) (the preconditioners only)."""
        Q = np.asarray(self._Q, dtype=complex)
        Jq = np.einsum("kij,pj->pki", Q + Q.transpose(0, 2, 1), np.asarray(Y, dtype=complex))
        return np.concatenate([Jq, np.broadcast_to(self._B, (len(Jq), *self._B.shape))], axis=1)

    def jacobian(self, x):
        _, S, _, _, Brows = self._k(_field(x))
        SX = S * x
        n = self.n
        rows: Any = [[SX[k * n + j, 0] for j in range(n)] for k in range(self.m)] + Brows
        return arb_mat(rows) if isinstance(x, arb_mat) else acb_mat(rows)



def quadric_system(Q, B, b) -> QuadricBallSystem:
    """The ball system of quadrics ``Q`` (m, n, n) and linear equations ``B x = b``."""
    return QuadricBallSystem(Q, B, b)


class LimbBallSystem:
    """The square system of a limb's inverse position (:class:`.inverse.LimbIK` of the *rigid*
    family: as many equations as unknowns) at a real pose: the circles ``c^2 + s^2 = 1``, then
    the closure equations of :meth:`.inverse.LimbIK.equations` with the quaternion ``q`` and the
    translation ``t`` (over ``L``) as exact data."""

    def __init__(self, sysm, q, t) -> None:
        if not sysm.rigid:
            raise InputError("sysm: the limb's equations are not square (a graph family): no certificate")
        self.n = int(sysm.nx)
        self.real = True
        self.kind = sysm.kind
        self.circles = tuple(sysm.circles)
        self._sysm = sysm
        self._q = np.real(np.asarray(q)).astype(float)
        self._t = np.real(np.asarray(t)).astype(float)
        self._consts: dict[bool, dict] = {}

    def _k(self, f: _Field) -> dict:
        hit = self._consts.get(f.real)
        if hit is not None:
            return hit
        w, i, j, k = (f.scalar(v) for v in self._q)
        rows = [[w * w + i * i - j * j - k * k, 2 * (i * j - w * k), 2 * (i * k + w * j)],
                [2 * (i * j + w * k), w * w - i * i + j * j - k * k, 2 * (j * k - w * i)],
                [2 * (i * k - w * j), 2 * (j * k + w * i), w * w - i * i - j * j + k * k]]
        zero = f.scalar(0.0)
        Erows: Any = [rows[a] + [zero] for a in range(3)] + [[zero] * 4]
        E = arb_mat(Erows) if f.real else acb_mat(Erows)

        hit = self._consts[f.real] = {"E": E, "s": w * w + i * i + j * j + k * k, "t": [f.scalar(v) for v in self._t],
                                      "one": f.scalar(1.0), **_limb_constants(self._sysm, f)}
        return hit

    @staticmethod
    def _chain(factors, x, K: dict, want: bool):
        """The product ``T``, and with ``want`` its prefix and suffix products and per factor the
        derivatives of its matrix ``{unknown: dM}``."""
        eye, one = K["eye"], K["one"]
        Ms: list[Any] = []
        dMs: list[tuple] = []
        for kind, A, A2, idx in factors:
            if kind == "R":
                c, s = x[idx[0], 0], x[idx[1], 0]
                Ms.append(eye + A * s + A2 * (one - c))
                dMs.append(((idx[0], -A2), (idx[1], A)))
            else:
                Ms.append(eye + A * x[idx[0], 0])
                dMs.append(((idx[0], A),))
        pre = [eye]
        for M in Ms:
            pre.append(M if len(pre) == 1 else pre[-1] * M)  # no product with the identity
        if not want:
            return pre[-1], pre, [], dMs
        suf = [eye]
        for M in reversed(Ms):
            suf.append(M if len(suf) == 1 else M * suf[-1])
        suf.reverse()  # suf[i] = M_i ... M_last
        return pre[-1], pre, suf, dMs

    def krawczyk_float(self, Y: np.ndarray, max_radius: float) -> list[float | None]:
        """The fast first pass at the real points ``Y`` (:mod:`.certify_float`)."""
        return krawczyk_limb(self._sysm, self._q, self._t, Y, max_radius, lambda y: self.values(REAL.col(y)))

    def jacobian_float_many(self, Y: np.ndarray) -> np.ndarray:
        """``F'`` in floating point at the points ``Y`` (k, n) (the preconditioners only)."""
        return _limb_float_jacobians(self._sysm, self._q, self._t, Y)

    def values(self, x):
        K = self._k(_field(x))
        TL, _, _, _ = self._chain(K["left"], x, K, False)
        TR, _, _, _ = self._chain(K["right"], x, K, False)
        E, s, t = K["E"], K["s"], K["t"]
        out: Any = [[x[a, 0] * x[a, 0] + x[b, 0] * x[b, 0] - K["one"]] for a, b in self.circles]
        if self.kind == "point":
            u, v = TL * K["centre"], E * (TR * K["centre"])
            out += [[s * u[a, 0] - v[a, 0] - s * t[a]] for a in range(3)]
        else:
            Q = (E * TR).transpose() * TL  # P^T with P = TL^T E TR
            W = E * TR
            out += [[Q[1, 0]], [Q[2, 0]], [Q[2, 1]]] + [[s * TL[a, 3] - W[a, 3] - s * t[a]] for a in range(3)]
        return arb_mat(out) if isinstance(x, arb_mat) else acb_mat(out)

    def jacobian(self, x):
        f = _field(x)
        K = self._k(f)
        TL, preL, sufL, dL = self._chain(K["left"], x, K, True)
        TR, preR, sufR, dR = self._chain(K["right"], x, K, True)
        E, s = K["E"], K["s"]
        zero = f.scalar(0.0)
        J: Any = [[zero] * self.n for _ in range(self.n)]
        for i, (a, b) in enumerate(self.circles):
            J[i][a], J[i][b] = 2 * x[a, 0], 2 * x[b, 0]
        k = len(self.circles)
        if self.kind == "point":
            c = K["centre"]
            for i, dm in enumerate(dL):
                tail = sufL[i + 1] * c
                for z, dM in dm:
                    u = dM * tail if i == 0 else preL[i] * (dM * tail)
                    for r in range(3):
                        J[k + r][z] = s * u[r, 0]
            for i, dm in enumerate(dR):
                tail = sufR[i + 1] * c
                for z, dM in dm:
                    v = E * (dM * tail if i == 0 else preR[i] * (dM * tail))
                    for r in range(3):
                        J[k + r][z] = -v[r, 0]
        else:
            ETRt = (E * TR).transpose()
            TLt = TL.transpose()
            nL, nR = len(dL), len(dR)
            for i, dm in enumerate(dL):
                for z, dM in dm:
                    dT = dM if i + 1 == nL else dM * sufL[i + 1]
                    dT = dT if i == 0 else preL[i] * dT
                    Q = ETRt * dT  # (E TR)^T dTL = P_z^T
                    vals = [Q[1, 0], Q[2, 0], Q[2, 1]] + [s * dT[a, 3] for a in range(3)]
                    for r, val in enumerate(vals):
                        J[k + r][z] = val
            for i, dm in enumerate(dR):
                lead = E * preR[i]
                for z, dM in dm:
                    W = lead * dM if i + 1 == nR else lead * dM * sufR[i + 1]  # E dTR
                    P = TLt * W
                    vals = [P[0, 1], P[0, 2], P[1, 2]] + [-W[a, 3] for a in range(3)]
                    for r, val in enumerate(vals):
                        J[k + r][z] = val
        return arb_mat(J) if f.real else acb_mat(J)



_LIMBS: dict[tuple[bytes, bool], dict] = {}


def _limb_float_jacobians(sysm, q: np.ndarray, t: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """``F'`` of the limb's square system in floating point at the points ``Y`` (k, n), batched
    (the preconditioners only: the same formulas as :meth:`LimbBallSystem.jacobian`)."""
    Y = np.asarray(Y, dtype=complex)
    k, n = Y.shape
    eye = np.broadcast_to(np.eye(4), (k, 4, 4))

    def chain(factors):
        Ms: list[np.ndarray] = []
        dMs: list[tuple] = []
        for fa in factors:
            A = fa.sign * fa.A
            if fa.kind == "R":
                c, s = Y[:, fa.idx[0], None, None], Y[:, fa.idx[1], None, None]
                Ms.append(eye + s * A + (1 - c) * fa.A2)
                dMs.append(((fa.idx[0], -fa.A2), (fa.idx[1], A)))
            else:
                Ms.append(eye + Y[:, fa.idx[0], None, None] * A)
                dMs.append(((fa.idx[0], A),))
        pre = [eye]
        for M in Ms:
            pre.append(pre[-1] @ M)
        suf = [eye]
        for M in reversed(Ms):
            suf.append(M @ suf[-1])
        suf.reverse()
        return pre, suf, dMs

    w, i, j, kq = q
    E = np.zeros((4, 4))
    E[:3, :3] = [[w * w + i * i - j * j - kq * kq, 2 * (i * j - w * kq), 2 * (i * kq + w * j)],
                 [2 * (i * j + w * kq), w * w - i * i + j * j - kq * kq, 2 * (j * kq - w * i)],
                 [2 * (i * kq - w * j), 2 * (j * kq + w * i), w * w - i * i - j * j + kq * kq]]
    s2 = float(q @ q)
    preL, sufL, dL = chain(sysm.left)
    preR, sufR, dR = chain(sysm.right)
    TL, TR = preL[-1], preR[-1]
    J = np.zeros((k, n, n), dtype=complex)
    for r, (a, b) in enumerate(sysm.circles):
        J[:, r, a], J[:, r, b] = 2 * Y[:, a], 2 * Y[:, b]
    m = len(sysm.circles)
    for side, (pre, suf, dm) in enumerate(((preL, sufL, dL), (preR, sufR, dR))):
        for f_i, derivs in enumerate(dm):
            for z, dM in derivs:
                dT = pre[f_i] @ dM @ suf[f_i + 1]
                if sysm.kind == "point":
                    c = np.asarray(sysm.centre, dtype=float)
                    J[:, m:m + 3, z] = s2 * (dT @ c)[:, :3] if side == 0 else -((E @ dT) @ c)[:, :3]
                    continue
                P = np.swapaxes(dT, 1, 2) @ E @ TR if side == 0 else np.swapaxes(TL, 1, 2) @ E @ dT
                tr = s2 * dT[:, :3, 3] if side == 0 else -(E @ dT)[:, :3, 3]
                J[:, m:m + 3, z] = np.stack([P[:, 0, 1], P[:, 0, 2], P[:, 1, 2]], axis=1)
                J[:, m + 3:m + 6, z] = tr
    return J


def _limb_constants(sysm, f: _Field) -> dict:
    """The ball matrices of a limb's factors (cached per limb geometry and field)."""
    key = (sysm.key, f.real)
    hit = _LIMBS.get(key)
    if hit is None:
        if len(_LIMBS) > 256:
            _LIMBS.clear()

        def factor(fa):
            return (fa.kind, f.mat(fa.sign * fa.A), f.mat(fa.A2), fa.idx)

        hit = _LIMBS[key] = {"centre": f.col(np.asarray(sysm.centre, dtype=float)), "eye": f.identity(4),
                             "left": [factor(fa) for fa in sysm.left], "right": [factor(fa) for fa in sysm.right]}
    return hit


def limb_system(sysm, q, t) -> LimbBallSystem:
    """The ball system of the limb ``sysm`` (:class:`.inverse.LimbIK`, rigid family) at the pose
    of quaternion ``q`` (4, real) and translation ``t`` (3, over ``L``)."""
    return LimbBallSystem(sysm, q, t)


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
