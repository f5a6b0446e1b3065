"""The Krawczyk test of the certificates (issue 27; the theorem and the acceptance rules: the
docstring of :mod:`.certify`): :func:`certify` over a :class:`.certify_balls.BallSystem` and
points returns one :class:`Certificate` per point; :func:`krawczyk_box` is the test of one point
(the smallest box of the sequence that passes), and the distinctness of the boxes is decided
over all points together."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from flint import ctx

from ...errors import InputError
from ...geometry.tolerances import (CERTIFY_GROWTH, CERTIFY_MAX_RADIUS, CERTIFY_MIN_RADIUS, CERTIFY_PRECISION,
                                    CERTIFY_PRECISION_HIGH)
from .certify_balls import COMPLEX, REAL, BallSystem, midpoints, pow2_up

__all__ = ["Certificate", "certify", "krawczyk_box", "n_certified", "newton_refine"]


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


def krawczyk_box(system: BallSystem, y: np.ndarray, max_radius: float,
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
        Ainv = _inverse(midpoints(system.jacobian(yc)))
    if Ainv is None:
        return None, "the Jacobian is singular at the point", f.real
    A = f.mat(Ainv.real if f.real else Ainv)
    AF = A * system.values(yc)
    step = float(np.max(np.abs(midpoints(AF))))
    r = pow2_up(max(4.0 * step, CERTIFY_MIN_RADIUS * scale))
    if not r <= rmax:
        return None, (f"its Newton correction ({step:.1e}) exceeds the largest box ({rmax:.1e}): not an accurate "
                      "approximation of a root"), f.real
    rJ = min(pow2_up(rmax), r * CERTIFY_GROWTH)  # the box of the shared enclosure of F'
    eye = f.identity(n)
    M = eye - A * system.jacobian(yc + f.radius_col(n, rJ))
    base = yc - AF
    while r <= rmax:
        D = f.radius_col(n, r)
        Mr = M if r <= rJ else eye - A * system.jacobian(yc + D)
        if _contained(yc + D, base + Mr * D, n):
            return r, "", f.real
        if r < rJ and _contained(yc + D, base + (eye - A * system.jacobian(yc + D)) * D, n):
            return r, "", f.real  # F' over this box only: an ill-conditioned root needs the tighter enclosure
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


def newton_refine(system: BallSystem, y: np.ndarray, *, steps: int = 4) -> np.ndarray:
    """``y`` moved by ``steps`` Newton steps computed in complex balls of
    ``CERTIFY_PRECISION_HIGH`` bits (each step from the midpoint of the last), rounded back to
    floats: an end point of an ill-conditioned root, accurate to its condition number times the
    rounding, becomes accurate to the rounding, so that a Krawczyk box about it can contract.
    ``y`` unchanged when a Jacobian is singular or a step is not finite.  A refinement, not a
    proof: :func:`certify` decides."""
    prec = ctx.prec
    ctx.prec = CERTIFY_PRECISION_HIGH
    try:
        x = COMPLEX.col(np.asarray(y, dtype=complex))
        for _ in range(steps):
            try:
                x = (x - system.jacobian(x).solve(system.values(x))).mid()
            except (ZeroDivisionError, ValueError):
                return np.asarray(y, dtype=complex)
        out = midpoints(x).ravel()
    finally:
        ctx.prec = prec
    return out if np.all(np.isfinite(out)) else np.asarray(y, dtype=complex)


def _retry_at_high_precision(system: BallSystem, Ys: list, found: list, todo: list[int], max_radius: float) -> None:
    """The points of ``todo`` whose every box failed, tried again with the balls at
    ``CERTIFY_PRECISION_HIGH`` bits (the same boxes about the same points: an ill-conditioned
    root needs ``A F(y)`` enclosed more tightly than 53 bits allow).  Updates ``found``."""
    again = [i for i in todo if found[i][1] is None and found[i][2].startswith("the Krawczyk test failed")]
    if not again:
        return
    prec = ctx.prec
    ctx.prec = CERTIFY_PRECISION_HIGH
    try:
        for i in again:
            r, why, rb = krawczyk_box(system, Ys[i], max_radius)
            if r is not None:
                found[i] = (Ys[i], r, why, rb, 0.0)
    finally:
        ctx.prec = prec


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
            found[i] = (Ys[i], *krawczyk_box(system, Ys[i], max_radius, Ainv), 0.0)
        _retry_at_high_precision(system, Ys, found, todo, max_radius)
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
