"""A fast first pass of the certificates (issue 27): the Krawczyk test of :mod:`.certify` for
*real* points of *real* systems, evaluated for all points at once in floating-point
midpoint-radius interval arithmetic with rigorous error bounds (Rump 1999, "Fast and parallel
interval arithmetic"), in NumPy instead of python-flint balls.  A point whose test passes here is
certified exactly as by the ball test (the same theorem, a wider enclosure); a point whose test
fails here goes to the ball test of :mod:`.certify`, which decides it (this pass never refuses a
certificate, it only grants one).

Midpoint-radius arithmetic in round-to-nearest.  An interval ``<m, r>`` is the set
``{x : |x - m| <= r}``.  Every operation computes its midpoint in floating point and a radius
that bounds the operands' radii and the rounding error of the midpoint (``u = 2^-53``):

- ``a + b``: ``m = fl(ma + mb)``, ``r >= ra + rb + u |m|`` (a sum is exact when it underflows);
- ``a * b``: ``m = fl(ma mb)``, ``r >= |ma| rb + ra |mb| + ra rb + u |m| + eta`` (``eta``: underflow);
- ``A @ B`` (inner dimension ``n``): ``|fl(Ma Mb) - Ma Mb| <= gamma_n |Ma| |Mb|`` (``gamma_n =
  n u / (1 - n u)``, for any order of summation, with or without fused multiply-add; Higham,
  *Accuracy and Stability of Numerical Algorithms*, 3.5), so ``r >= |Ma| Rb + Ra (|Mb| + Rb) +
  gamma_n |Ma| |Mb|`` plus underflow;

with ``u |m|`` for ``u |x|`` (the excess ``u^2 |x|`` and ``gamma_n - (n + 1) u`` are far below
the margin of :func:`_up`).  The radii themselves are sums and products of non-negative floats
computed in round-to-nearest: each of their at most a few hundred roundings loses at most a
factor ``1 - u``, so :func:`_up` (times ``1 + 2^-40``, plus ``2^-1000`` for every underflow)
turns the computed radius into an upper bound of the exact one.

The values at the point itself are taken from the ball system (python-flint, one evaluation per
point: tight enclosures, so that the test passes in the same first box as the ball test) and
converted to midpoint-radius form outward; the Jacobian over the box, the expensive part (every
derivative of every matrix product), is evaluated here for all points at once.
The data are checked to be finite and below ``2^20`` in magnitude (else the ball test decides),
so no underflow can be magnified beyond ``2^-1000``.

With the compiled engine in use (:func:`..backend.engine`), a limb's enclosures and the test
(:func:`krawczyk_limb`; the quadrics' test of :func:`krawczyk_real`) run as numba kernels doing
this arithmetic operation by operation (``kinematics/compiled/kernels_certify.py``, compiled
without ``fastmath``: no fused multiply-add, no reordering); this module is their reference,
which runs under ``SPATIALMECH_PURE=1``.

Soundness is kept by construction: the systems' constants (twist matrices, the pose's quaternion
and translation, the quadrics) are the same floats the ball systems take as exact data, and every
derived constant (the rotation of the quaternion, ``Q + Q^T``) is computed in interval arithmetic.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from flint import arb

from ...geometry.tolerances import CERTIFY_GROWTH, CERTIFY_MIN_RADIUS
from .. import backend

__all__ = ["MR", "box_radii", "from_balls", "krawczyk_limb", "krawczyk_quadrics", "krawczyk_real", "preconditioners",
           "rotation_coefficients", "testable", "with_ball_values"]

_U = 2.0**-53  # u: |fl(x) - x| <= u |x|, and u / (1 - u) |fl(x)| (the excess is in _up's margin)
_UP = 1.0 + 2.0**-40
_TINY = 2.0**-1000
_BIG = 2.0**20


def _up(r: np.ndarray) -> np.ndarray:
    """An upper bound of the exact value of a radius computed in round-to-nearest (module docstring);
    ``r`` (a fresh array of the caller's) is overwritten."""
    if type(r) is np.ndarray and r.ndim and r.flags.writeable:
        r *= _UP
        r += _TINY
        return r
    return r * _UP + _TINY


class MR:
    """Real midpoint-radius interval arrays (module docstring): midpoints ``m`` and radii ``r``
    of one shape (``r`` may broadcast).  Constants (floats, arrays) enter as exact points."""

    __slots__ = ("m", "r")
    __array_ufunc__ = None  # ``ndarray + MR`` defers to ``MR.__radd__``

    def __init__(self, m, r=None) -> None:
        self.m = m if type(m) is np.ndarray and m.dtype == float else np.asarray(m, dtype=float)
        if r is None:
            self.r = np.zeros(self.m.shape)
        else:
            r = r if type(r) is np.ndarray and r.dtype == float else np.asarray(r, dtype=float)
            self.r = r if r.shape == self.m.shape else np.broadcast_to(r, self.m.shape)

    def __getitem__(self, k) -> MR:
        return MR(self.m[k], self.r[k])

    def __neg__(self) -> MR:
        return MR(-self.m, self.r)

    def __add__(self, o) -> MR:
        o = _mr(o)
        m = self.m + o.m
        return MR(m, _up(self.r + o.r + _U * np.abs(m)))

    __radd__ = __add__

    def __sub__(self, o) -> MR:
        o = _mr(o)
        m = self.m - o.m
        return MR(m, _up(self.r + o.r + _U * np.abs(m)))

    def __rsub__(self, o) -> MR:
        return _mr(o) - self

    def __mul__(self, o) -> MR:
        o = _mr(o)
        m = self.m * o.m
        return MR(m, _up(np.abs(self.m) * o.r + self.r * (np.abs(o.m) + o.r) + _U * np.abs(m)))

    __rmul__ = __mul__

    def __matmul__(self, o) -> MR:
        exact = not isinstance(o, MR)
        o = _mr(o)
        n = self.m.shape[-1]
        am, aom = np.abs(self.m), np.abs(o.m)
        m = self.m @ o.m
        if exact:  # an exact constant: no radius of its own
            return MR(m, _up((self.r + (_U * (n + 1)) * am) @ aom))
        # |Ma| Rb + Ra (|Mb| + Rb) + gamma |Ma| |Mb|, as two products of non-negative floats
        return MR(m, _up(am @ (o.r + (_U * (n + 1)) * aom) + self.r @ (aom + o.r)))

    def __rmatmul__(self, o) -> MR:
        a = np.asarray(o, dtype=float)  # an exact constant on the left
        aa = np.abs(a)
        n = a.shape[-1]
        return MR(a @ self.m, _up(aa @ (self.r + (_U * (n + 1)) * np.abs(self.m))))

    @property
    def T(self) -> MR:
        """The transpose of the last two axes."""
        return MR(np.swapaxes(self.m, -1, -2), np.swapaxes(self.r, -1, -2))

    @property
    def upper(self) -> np.ndarray:
        """An upper bound of ``|x|`` over the interval."""
        return _up(np.abs(self.m) + self.r)


def _mr(x) -> MR:
    return x if isinstance(x, MR) else MR(x)


def stack(items: Sequence[MR], axis: int = -1) -> MR:
    """Intervals stacked along a new axis (like :func:`numpy.stack`)."""
    return MR(np.stack([i.m for i in items], axis=axis), np.stack([i.r for i in items], axis=axis))


def concat(items: Sequence[MR], axis: int = -1) -> MR:
    """Intervals joined along an axis (like :func:`numpy.concatenate`)."""
    return MR(np.concatenate([i.m for i in items], axis=axis), np.concatenate([i.r for i in items], axis=axis))


def _pow2_up(r: np.ndarray) -> np.ndarray:
    m, e = np.frexp(r)
    return np.ldexp(1.0, e - (m == 0.5))


def from_balls(F) -> MR:
    """A column of python-flint real balls (an ``n x 1`` :class:`flint.arb_mat`) as an interval
    row (1, n), outward: the midpoint rounded to a float and the radius rounded up."""
    ents = F.entries()
    m = np.array([float(e) for e in ents])  # the midpoints as floats
    r = np.array([float(e.rad()) for e in ents])
    # |midpoint - m|: 0 where the midpoint is that float (the rule at 53 bits), else bounded in balls
    err = np.array([0.0 if e.mid() == arb(x) else float((e.mid() - x).abs_upper()) for e, x in zip(ents, m, strict=True)])
    r = _up(r + err + _U * (r + err + np.abs(m)))  # float() of the radius rounds to nearest: one more u
    return MR(m[None], r[None])


def preconditioners(J0: np.ndarray, Jr: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(A, ok)``: the inverses ``A`` (k, n, n) of the float Jacobians ``J0`` (the midpoints of
    their enclosures, radii ``Jr``) and whether each point can be tested (finite enclosure, an
    invertible ``J0``, an inverse finite and below ``2^20``); ``A`` is zero where not.  Any matrix
    serves as the preconditioner of the Krawczyk test: a poor one only makes it fail."""
    if np.isfinite(J0).all() and np.isfinite(Jr).all():  # the usual case, in fewer NumPy calls
        try:
            A = np.linalg.inv(J0)
            if np.isfinite(A).all() and np.abs(A).max(initial=0.0) < _BIG:
                return A, np.ones(len(J0), dtype=bool)
        except np.linalg.LinAlgError:
            pass
    ok = np.all(np.isfinite(J0), axis=(1, 2)) & np.all(np.isfinite(Jr), axis=(1, 2))
    A = np.zeros_like(J0)
    try:  # a singular one fails here
        A[ok] = np.linalg.inv(J0[ok])
    except np.linalg.LinAlgError:
        for i in np.flatnonzero(ok):
            try:
                A[i] = np.linalg.inv(J0[i])
            except np.linalg.LinAlgError:
                ok[i] = False
    ok &= np.all(np.isfinite(A), axis=(1, 2)) & (np.max(np.abs(A), axis=(1, 2), initial=0.0) < _BIG)
    A[~ok] = 0.0
    return A, ok


def testable(Y: np.ndarray) -> bool:
    """Whether the float pass may run at the points ``Y`` (k, n): some, all finite and below
    ``2^20`` in magnitude (module docstring: no underflow magnified beyond ``2^-1000``)."""
    return len(Y) > 0 and bool(np.all(np.isfinite(Y))) and float(np.max(np.abs(Y))) <= _BIG


def box_radii(Y: np.ndarray, max_radius: float) -> np.ndarray:
    """The half-width of the largest box of each point's sequence, a power of two (the box over
    which ``F'`` is enclosed once for every radius)."""
    return _pow2_up(max_radius * (1.0 + np.max(np.abs(Y), axis=1)))


def krawczyk_real(values: Callable[[MR], MR], jacobian: Callable[[MR], MR], Y: np.ndarray,
                  max_radius: float, ball_values: Callable[[np.ndarray], Any] | None = None) -> list[float | None]:
    """The half-width ``r`` of the first box of :func:`.certify.certify`'s sequence (a power of
    two, at least four Newton corrections, then times ``CERTIFY_GROWTH`` up to the largest) in
    which the real Krawczyk test passes at each real point of ``Y`` (k, n), or ``None`` when it
    passes in none here (the ball test then decides): so a certificate's box is one of the ball
    test's sequence (measured on the PUMA 560's 120 solutions at 15 poses: the same box as the
    ball test's for each, 12 of them after the first radius failed in both).  ``values`` and
    ``jacobian`` enclose ``F`` (k, n) and ``F'`` (k, n, n) over interval points (k, n);
    ``ball_values(y)``, when given, encloses ``F`` at one point in python-flint balls (an
    ``n x 1`` :class:`flint.arb_mat`: tighter) and is tried where the test fails with ``values``.
    The test itself runs compiled when the compiled engine is in use
    (:func:`..compiled.certify.krawczyk_test`: the same arithmetic), else here."""
    Y = np.asarray(Y, dtype=float)
    k = Y.shape[0]
    if not testable(Y):
        return [None] * k
    JX = jacobian(MR(Y, np.broadcast_to(box_radii(Y, max_radius)[:, None], Y.shape)))  # serves every box
    A, ok = preconditioners(JX.m, JX.r)  # the midpoints do not depend on the radii: F'(y) in floating point
    F = values(MR(Y))
    if (fast := backend.engine()) is not None:
        return fast.krawczyk_test(A, JX.m, JX.r, F.m, F.r, Y, max_radius, ok, ball_values)
    return _krawczyk_reference(A, ok, JX, F, Y, max_radius, ball_values)


def _krawczyk_reference(A: np.ndarray, ok: np.ndarray, JX: MR, F: MR, Y: np.ndarray, max_radius: float,
                        ball_values: Callable[[np.ndarray], Any] | None) -> list[float | None]:
    """The test of :func:`krawczyk_real` in NumPy interval arithmetic (the Python reference)."""
    k, n = Y.shape
    out: list[float | None] = [None] * k
    scale = 1.0 + np.max(np.abs(Y), axis=1)
    rmax = max_radius * scale
    M = np.eye(n) - A @ JX
    for stage in range(2):  # the values here; then from the ball system where the test failed
        AF = A @ _col(F)
        step = np.max(np.abs(AF.m[:, :, 0]), axis=1)
        r = _pow2_up(np.maximum(4.0 * step, CERTIFY_MIN_RADIUS * scale))
        go = ok & np.isfinite(step) & (r <= rmax)
        D = MR(np.zeros((k, n, 1)), np.broadcast_to(r[:, None, None], (k, n, 1)))
        bound = (-AF + M @ D).upper[:, :, 0]  # |K(X) - y| over the box of half-width r
        inside = np.all(bound < r[:, None], axis=1) & np.all(np.isfinite(bound), axis=1)
        for i in np.flatnonzero(go & inside):
            if out[i] is None:
                out[i] = float(r[i])
        again = [i for i in range(k) if ok[i] and out[i] is None]
        if stage or ball_values is None or not again:
            _grow(out, AF, M, r, rmax, go)
            break
        F = with_ball_values(F, again, Y, ball_values)
    return out


def with_ball_values(F: MR, rows, Y: np.ndarray, ball_values: Callable[[np.ndarray], Any]) -> MR:
    """``F`` (k, n) with the rows ``rows`` replaced by the ball system's enclosures at those
    points (:func:`from_balls`: outward)."""
    Fm, Fr = F.m.copy(), np.array(F.r, dtype=float)
    for j in rows:
        row = from_balls(ball_values(Y[j]))
        Fm[j], Fr[j] = row.m[0], row.r[0]
    return MR(Fm, Fr)


def _grow(out: list[float | None], AF: MR, M: MR, r0: np.ndarray, rmax: np.ndarray, go: np.ndarray) -> None:
    """The points of ``go`` not granted at their first radius ``r0``: the wider radii of the ball
    test's sequence (``r0`` times powers of ``CERTIFY_GROWTH``, up to ``rmax``) tried with the same
    enclosures (``M = I - A F'`` over the largest box serves every box); ``out[i]`` the first that
    passes.  A root whose Newton correction's enclosure is dominated by the rounding of ``F(y)``
    (ill-conditioned: ``|A| rad F(y)`` above the first box) then passes here, not in a second
    (ball) test."""
    n = AF.m.shape[1]
    for i in np.flatnonzero(go):
        if out[i] is not None:
            continue
        r = float(r0[i]) * CERTIFY_GROWTH
        while r <= rmax[i]:
            D = MR(np.zeros((n, 1)), np.full((n, 1), r))
            bound = (-AF[i] + M[i] @ D).upper[:, 0]
            if np.all(bound < r) and np.all(np.isfinite(bound)):
                out[i] = r
                break
            r *= CERTIFY_GROWTH


def _col(F: MR) -> MR:
    return MR(F.m[:, :, None], F.r[:, :, None])


# ------------------------------------------------------------------------------ the quadrics
def krawczyk_quadrics(Q: np.ndarray, B: np.ndarray, b: np.ndarray, Y: np.ndarray, max_radius: float,
                      ball_values: Callable[[np.ndarray], Any] | None = None) -> list[float | None]:
    """:func:`krawczyk_real` of ``x^T Q_j x`` (m, n, n) and ``B x = b`` (real) at real points."""
    Qm, Bm = MR(Q), MR(B)
    S = MR(Q) + MR(np.swapaxes(Q, 1, 2))  # Q + Q^T, in interval arithmetic

    def values(x: MR) -> MR:
        xc = _col(x)[:, None]  # (k, 1, n, 1)
        quad = (xc.T @ (Qm @ xc))[:, :, 0, 0]
        lin = (Bm @ _col(x))[:, :, 0] - b
        return concat([quad, lin], axis=1)

    def jacobian(x: MR) -> MR:
        Jq = (S @ _col(x)[:, None])[..., 0]  # (k, m, n): row j is (Q_j + Q_j^T) x
        k = x.m.shape[0]
        Bb = np.broadcast_to(B, (k, *B.shape))
        return MR(np.concatenate([Jq.m, Bb], axis=1), np.concatenate([_full(Jq), np.zeros(Bb.shape)], axis=1))

    return krawczyk_real(values, jacobian, Y, max_radius, ball_values)


def _full(x: MR) -> np.ndarray:
    return x.r


# ------------------------------------------------------------------------------ a limb's inverse position
_FACTORS: dict[int, tuple] = {}


def _factor_data(factors) -> tuple:
    """Per factor tuple (cached): revolute flags, the indices of ``s`` (or ``d``) and ``c``, the
    constant matrices ``(I ; A ; A^2)`` (f, 3, 16) and the derivatives ``((unknown, dM), ...)``."""
    hit = _FACTORS.get(id(factors))
    if hit is not None and hit[0] is factors:
        return hit[1]
    if len(_FACTORS) > 256:
        _FACTORS.clear()
    rev = np.array([fa.kind == "R" for fa in factors])
    i_s = np.array([fa.idx[1] if fa.kind == "R" else fa.idx[0] for fa in factors], dtype=np.int64)
    i_c = np.array([fa.idx[0] for fa in factors], dtype=np.int64)
    const = np.array([np.stack([np.eye(4).ravel(), (fa.sign * fa.A).ravel(),
                                np.asarray(fa.A2, dtype=float).ravel() if fa.kind == "R" else np.zeros(16)])
                      for fa in factors])
    dMs = [((fa.idx[0], -fa.A2), (fa.idx[1], fa.sign * fa.A)) if fa.kind == "R" else ((fa.idx[0], fa.sign * fa.A),)
           for fa in factors]
    _FACTORS[id(factors)] = (factors, (rev, i_s, i_c, const, dMs))
    return rev, i_s, i_c, const, dMs


def _chain(factors, x: MR):
    """The factors' matrices (k, 4, 4) and per factor the derivatives ``((unknown, dM), ...)``:
    ``M = I + s A + (1 - c) A^2`` (R) or ``I + d A`` (P), all factors in one interval product
    ``(1, s, 1 - c) @ (I ; A ; A^2)`` with the exact constant matrices (``1 - c`` in interval
    arithmetic, 0 for a slide)."""
    if not factors:
        return [], []
    k, f = x.m.shape[0], len(factors)
    rev, i_s, i_c, const, dMs = _factor_data(factors)
    um = np.empty((k, f, 1, 3))
    ur = np.zeros((k, f, 1, 3))
    um[..., 0] = 1.0
    um[:, :, 0, 1], ur[:, :, 0, 1] = x.m[:, i_s], x.r[:, i_s]
    one_c = 1.0 - x.m[:, i_c]
    um[:, :, 0, 2] = np.where(rev, one_c, 0.0)
    ur[:, :, 0, 2] = np.where(rev, _up(x.r[:, i_c] + _U * np.abs(one_c)), 0.0)
    Ms = MR(um, ur) @ const  # (k, f, 1, 16)
    Mm, Mr = Ms.m.reshape(k, f, 4, 4), Ms.r.reshape(k, f, 4, 4)
    return [MR(Mm[:, i], Mr[:, i]) for i in range(f)], dMs


def _product(Ms: list[MR], k: int) -> MR:
    """``M_0 ... M_last`` (the identity when empty)."""
    if not Ms:
        return MR(np.broadcast_to(np.eye(4), (k, 4, 4)))
    T = Ms[0]
    for M in Ms[1:]:
        T = T @ M
    return T


def _products(Ms: list[MR]) -> tuple[list[MR | None], list[MR | None]]:
    """Prefix ``pre[i] = M_0 ... M_{i-1}`` and suffix ``suf[i] = M_i ... M_last`` (None: identity)."""
    pre: list[MR | None] = [None]
    for M in Ms:
        pre.append(M if pre[-1] is None else pre[-1] @ M)
    suf: list[MR | None] = [None]
    for M in reversed(Ms):
        suf.append(M if suf[-1] is None else M @ suf[-1])
    suf.reverse()
    return pre, suf


def _expand(a: MR) -> MR:
    """``(k, 4, 4) -> (k, 1, 4, 4)``: to broadcast over the derivatives."""
    return MR(a.m[:, None], _full(a)[:, None])


def rotation_coefficients() -> np.ndarray:
    """The exact small-integer coefficients (17, 16) of ``E(q)`` (4x4, row-major: the
    unnormalised rotation, homogeneous) and of ``q.q`` in the products ``q_a q_b`` (``4 a + b``)."""
    C = np.zeros((17, 16))  # rows: E (4x4, row-major), then q.q
    w, i, j, k = range(4)

    def put(row: int, terms) -> None:
        for c, a, b in terms:
            C[row, 4 * a + b] += c

    put(0, [(1, w, w), (1, i, i), (-1, j, j), (-1, k, k)])
    put(1, [(2, i, j), (-2, w, k)])
    put(2, [(2, i, k), (2, w, j)])
    put(4, [(2, i, j), (2, w, k)])
    put(5, [(1, w, w), (-1, i, i), (1, j, j), (-1, k, k)])
    put(6, [(2, j, k), (-2, w, i)])
    put(8, [(2, i, k), (-2, w, j)])
    put(9, [(2, j, k), (2, w, i)])
    put(10, [(1, w, w), (-1, i, i), (-1, j, j), (1, k, k)])
    put(16, [(1, w, w), (1, i, i), (1, j, j), (1, k, k)])
    return C


_ROTATION = rotation_coefficients()


def _rotation(q: np.ndarray) -> tuple[MR, MR]:
    """``E(q)`` (4x4, homogeneous, the unnormalised rotation) and ``q.q`` in interval arithmetic:
    the products ``q_a q_b`` as intervals, then their exact integer combinations."""
    pq = MR(q[:, None]) * MR(q[None, :])
    out = _ROTATION @ MR(pq.m.ravel()[:, None], pq.r.ravel()[:, None])  # exact small-integer coefficients
    return MR(out.m[:16, 0].reshape(4, 4), out.r[:16, 0].reshape(4, 4)), MR(out.m[16, 0], out.r[16, 0])


def krawczyk_limb(sysm, q: np.ndarray, t: np.ndarray, Y: np.ndarray, max_radius: float,
                  ball_values: Callable[[np.ndarray], Any] | None = None) -> list[float | None]:
    """:func:`krawczyk_real` of a limb's square system (:class:`.certify.LimbBallSystem`: the
    same equations, term by term) at the pose ``(q, t)`` (exact floats) and the real points
    ``Y`` (k, n)."""
    q, t = np.asarray(q, dtype=float), np.asarray(t, dtype=float)
    if not (np.isfinite(q).all() and np.isfinite(t).all() and max(np.abs(q).max(), np.abs(t).max()) < _BIG):
        return [None] * len(Y)
    if (fast := backend.engine()) is not None:  # the enclosures and the test compiled (compiled/certify.py)
        return fast.krawczyk_limb(sysm, q, t, Y, max_radius, ball_values)
    E, s = _rotation(q)
    stv = s * t  # (3,)
    centre = np.asarray(sysm.centre, dtype=float)[:, None]
    point = sysm.kind == "point"

    def ends(x: MR):
        k = x.m.shape[0]
        eye = MR(np.broadcast_to(np.eye(4), (k, 4, 4)))
        out = []
        for factors in (sysm.left, sysm.right):
            Ms, dMs = _chain(factors, x)
            pre, suf = _products(Ms)
            out.append((pre, suf, dMs, eye if pre[-1] is None else pre[-1]))
        return out

    ca = np.array([a for a, _ in sysm.circles], dtype=np.int64)
    cb = np.array([b for _, b in sysm.circles], dtype=np.int64)
    lo, hi = (1, 2, 2), (0, 0, 1)

    def values(x: MR) -> MR:
        TL, TR = (_product(_chain(side, x)[0], x.m.shape[0]) for side in (sysm.left, sysm.right))
        xa, xb = x[:, ca], x[:, cb]
        rows = [xa * xa + xb * xb - 1.0]
        if point:
            u, v = s * (TL @ centre), E @ (TR @ centre)
            rows.append(u[:, :3, 0] - v[:, :3, 0] - stv)
        else:
            W = E @ TR
            P = W.T @ TL
            rows += [P[:, lo, hi], s * TL[:, :3, 3] - W[:, :3, 3] - stv]
        return concat(rows, axis=1)

    def jacobian(x: MR) -> MR:
        k, n = x.m.shape
        Jm, Jr = np.zeros((k, n, n)), np.zeros((k, n, n))
        xr = _full(x)
        for i, (a, b) in enumerate(sysm.circles):
            Jm[:, i, a], Jr[:, i, a] = 2.0 * x.m[:, a], 2.0 * xr[:, a]  # exact: times 2
            Jm[:, i, b], Jr[:, i, b] = 2.0 * x.m[:, b], 2.0 * xr[:, b]
        nc = len(sysm.circles)
        sides = ends(x)
        TL, W = sides[0][3], E @ sides[1][3]
        for side, (pre, suf, dMs, _) in enumerate(sides):
            zs = [z for derivs in dMs for z, _ in derivs]
            if not zs:
                continue
            eye = np.broadcast_to(np.eye(4), (k, 4, 4))
            at = [i for i, derivs in enumerate(dMs) for _ in derivs]
            Pre = stack([MR(eye) if pre[i] is None else pre[i] for i in at], axis=1)  # (k, d, 4, 4)
            Suf = stack([MR(eye) if suf[i + 1] is None else suf[i + 1] for i in at], axis=1)
            dM = np.array([dM for derivs in dMs for _, dM in derivs])  # (d, 4, 4), exact
            dT = Pre @ (dM @ Suf)  # every derivative of the side's product at once
            if point and side == 0:
                cols = (s * (dT @ centre))[:, :, :3, 0]
            elif point:
                cols = -(E @ (dT @ centre))[:, :, :3, 0]
            elif side == 0:
                P = _expand(W).T @ dT
                cols = concat([P[:, :, lo, hi], s * dT[:, :, :3, 3]], axis=2)
            else:
                V = E @ dT
                P = _expand(TL).T @ V
                cols = concat([P[:, :, hi, lo], -V[:, :, :3, 3]], axis=2)
            Jm[:, nc:, zs] = cols.m.transpose(0, 2, 1)  # cols (k, d, rows)
            Jr[:, nc:, zs] = cols.r.transpose(0, 2, 1)
        return MR(Jm, Jr)

    return krawczyk_real(values, jacobian, Y, max_radius, ball_values)
