"""The general closure engine compiled (numba): the same computations as :mod:`.closure`,
:func:`.jacobian.driver_determinants` and the per-limb inverse position, on plain arrays.

A mechanism is compiled once into arrays (:class:`CompiledMechanism`, cached per mechanism):
the reference screws of its freedoms, its ball (S) joints (first freedom, axes, centre), the
first freedom of each limb, the hub indices of each limb's ends (-1 = the ground, 0 = the output
link, 1 + i = internal body i) and the prismatic mask.  The kernels are ``@njit(cache=True)``
functions of those arrays: compiled on first use and cached on disk next to this file (or in
numba's user-wide cache when this directory is not writable), so later processes only load
them.

The Python path stays the reference: :func:`.closure.correct`, :func:`.closure.closure_jacobian`,
:func:`.closure.closure_residual`, :func:`.jacobian.driver_determinants` and the per-limb
Gauss-Newton of :mod:`.position` call these kernels when :func:`enabled` (numba importable and
the environment variable ``SPATIALMECH_PURE`` unset or ``0``) and run their own Python code
otherwise.  Same steps, tolerances and statuses; the results agree to rounding (the test suite
compares both paths on every ready-made model).

Batched entry points for many configurations, seeds or poses: :func:`closure_residuals`,
:func:`closure_jacobians`, :func:`correct_many`, :func:`limb_inverse_many`,
:func:`driver_determinants_many`, :func:`sps_leg_lengths`.
"""

from __future__ import annotations

import os
import warnings
import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism
from .closure import (
    Chain,
    Configuration,
    CorrectionResult,
    active_mask,
    check_configuration,
    limb_chains,
    limb_slices,
    reference_screws,
)

try:  # numba is a runtime dependency; without it the Python path runs (slower, same results)
    from numba import njit

    AVAILABLE = True
    UNAVAILABLE_REASON = ""
except ImportError as exc:  # pragma: no cover - exercised only where numba is missing
    AVAILABLE = False
    UNAVAILABLE_REASON = f"numba cannot be imported ({exc})"

    def njit(*args, **kwargs):
        if args and callable(args[0]):
            return args[0]
        return lambda f: f


__all__ = [
    "AVAILABLE",
    "PURE_ENV",
    "CompiledMechanism",
    "closure_jacobian",
    "closure_jacobians",
    "closure_residual",
    "closure_residuals",
    "compile_mechanism",
    "config_difference",
    "correct",
    "correct_many",
    "driver_determinants",
    "driver_determinants_many",
    "enabled",
    "limb_gn",
    "limb_inverse_many",
    "retract",
    "sps_leg_lengths",
    "warm_up",
]

#: Set this environment variable to ``1`` to run the pure-Python engine (the reference).
PURE_ENV = "SPATIALMECH_PURE"

_NOTED = False


def enabled() -> bool:
    """True when the compiled kernels are used: numba imports and ``SPATIALMECH_PURE`` is unset
    (or ``0``).  Read at every call, so a test or a benchmark can switch paths in one process.
    Without numba a one-time ``RuntimeWarning`` says that the Python path runs."""
    global _NOTED
    if os.environ.get(PURE_ENV, "").strip() not in ("", "0"):
        return False
    if not AVAILABLE:
        if not _NOTED:
            _NOTED = True
            warnings.warn(f"spatialmech: {UNAVAILABLE_REASON or 'numba is not available'}; the pure-Python engine "
                          "runs instead (slower, same results)", RuntimeWarning, stacklevel=3)
        return False
    return True


# ---------------------------------------------------------------------------- compiled model
@dataclass(frozen=True, eq=False)
class CompiledMechanism:
    """A mechanism as plain arrays (see the module docstring)."""

    n: int  # joint variables
    n_limbs: int
    n_bodies: int
    length: float  # characteristic length L
    screws: np.ndarray  # (n, 6) reference screws
    ball_of: np.ndarray  # (n,) int64: ball index at the first freedom of an S joint, else -1
    ball_first: np.ndarray  # (nb,) int64: global index of each ball's first freedom
    ball_axes: np.ndarray  # (nb, 3, 3): axes as columns
    ball_centre: np.ndarray  # (nb, 3)
    limb_start: np.ndarray  # (K + 1,) int64
    ends: np.ndarray  # (K, 2) int64: base and tip hub (-1 = ground)
    linear: np.ndarray  # (n,) bool: prismatic freedoms
    active: np.ndarray  # (n,) bool: the unlocked freedoms (default active mask)

    @property
    def chain_arrays(self) -> tuple:
        return self.screws, self.ball_of, self.ball_axes, self.ball_centre


_COMPILED: weakref.WeakKeyDictionary[Mechanism, CompiledMechanism] = weakref.WeakKeyDictionary()


def compile_mechanism(mech: Mechanism) -> CompiledMechanism:
    """The arrays of ``mech`` (cached per mechanism, like :func:`.closure.limb_chains`)."""
    try:
        return _COMPILED[mech]
    except KeyError:
        pass
    n = len(mech.freedom_refs)
    ball_of = np.full(n, -1, dtype=np.int64)
    first: list[int] = []
    axes: list[np.ndarray] = []
    centres: list[np.ndarray] = []
    start = 0
    for ch in limb_chains(mech):
        for k, c, A in ch.balls:
            ball_of[start + k] = len(first)
            first.append(start + k)
            axes.append(A)
            centres.append(c)
        start += len(ch.screws)
    sls = limb_slices(mech)
    limb_start = np.array([s.start for s in sls] + [n], dtype=np.int64)
    ends = np.array([[-1 if a is None else a, -1 if b is None else b] for a, b in mech.limb_ends],
                    dtype=np.int64).reshape(-1, 2)
    cm = CompiledMechanism(
        n, len(mech.limbs), len(mech.bodies), float(mech.characteristic_length),
        np.ascontiguousarray(reference_screws(mech), dtype=float).reshape(n, 6), ball_of,
        np.array(first, dtype=np.int64), np.ascontiguousarray(np.array(axes, dtype=float).reshape(-1, 3, 3)),
        np.ascontiguousarray(np.array(centres, dtype=float).reshape(-1, 3)), limb_start, ends,
        np.array([r.freedom.is_linear for r in mech.freedom_refs], dtype=np.bool_),
        np.ascontiguousarray(active_mask(mech), dtype=np.bool_).reshape(n))
    _COMPILED[mech] = cm
    return cm


@dataclass(frozen=True, eq=False)
class _ChainArrays:
    screws: np.ndarray
    ball_of: np.ndarray
    ball_first: np.ndarray
    ball_axes: np.ndarray
    ball_centre: np.ndarray


_CHAIN_ARRAYS: weakref.WeakKeyDictionary[Chain, _ChainArrays] = weakref.WeakKeyDictionary()


def _chain_arrays(chain: Chain) -> _ChainArrays:
    try:
        return _CHAIN_ARRAYS[chain]
    except KeyError:
        pass
    m = len(chain.screws)
    ball_of = np.full(m, -1, dtype=np.int64)
    for g, (k, _, _) in enumerate(chain.balls):
        ball_of[k] = g
    out = _ChainArrays(np.ascontiguousarray(chain.screws, dtype=float).reshape(m, 6), ball_of,
                       np.array([b[0] for b in chain.balls], dtype=np.int64),
                       np.ascontiguousarray(np.array([b[2] for b in chain.balls], dtype=float).reshape(-1, 3, 3)),
                       np.ascontiguousarray(np.array([b[1] for b in chain.balls], dtype=float).reshape(-1, 3)))
    _CHAIN_ARRAYS[chain] = out
    return out


# ---------------------------------------------------------------------------- small kernels
@njit(cache=True)
def _cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def _mv(M, v, out):
    for i in range(3):
        out[i] = M[i, 0] * v[0] + M[i, 1] * v[1] + M[i, 2] * v[2]


@njit(cache=True)
def _mm(A, B, out):
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@njit(cache=True)
def _skew(w, out):
    out[0, 0] = 0.0
    out[0, 1] = -w[2]
    out[0, 2] = w[1]
    out[1, 0] = w[2]
    out[1, 1] = 0.0
    out[1, 2] = -w[0]
    out[2, 0] = -w[1]
    out[2, 1] = w[0]
    out[2, 2] = 0.0


@njit(cache=True)
def _series(W, a, b, out):
    """``I + a W + b W W``."""
    W2 = np.empty((3, 3))
    _mm(W, W, W2)
    for i in range(3):
        for j in range(3):
            out[i, j] = a * W[i, j] + b * W2[i, j]
        out[i, i] += 1.0


@njit(cache=True)
def _rotvec_matrix(phi, out):
    """:func:`..geometry.rotations.rotvec_matrix`."""
    th = np.sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])
    W = np.empty((3, 3))
    if th < 1e-12:
        _skew(phi, W)
        for i in range(3):
            for j in range(3):
                out[i, j] = W[i, j]
            out[i, i] += 1.0
        return
    k = np.empty(3)
    for i in range(3):
        k[i] = phi[i] / th
    _skew(k, W)
    _series(W, np.sin(th), 1.0 - np.cos(th), out)


@njit(cache=True)
def _quat_rotvec(R, out):
    """scipy's ``Rotation.from_matrix(R).as_rotvec()`` for a rotation matrix (Shepperd's
    quaternion, canonical sign, then the rotation vector)."""
    tr = R[0, 0] + R[1, 1] + R[2, 2]
    choice = 3
    best = tr
    for i in range(3):
        if R[i, i] > best:
            best = R[i, i]
            choice = i
    qt = np.empty(4)
    if choice == 3:
        qt[0] = R[2, 1] - R[1, 2]
        qt[1] = R[0, 2] - R[2, 0]
        qt[2] = R[1, 0] - R[0, 1]
        qt[3] = 1.0 + tr
    else:
        i = choice
        j = (i + 1) % 3
        k = (j + 1) % 3
        qt[i] = 1.0 - tr + 2.0 * R[i, i]
        qt[j] = R[j, i] + R[i, j]
        qt[k] = R[k, i] + R[i, k]
        qt[3] = R[k, j] - R[j, k]
    nq = np.sqrt(qt[0] ** 2 + qt[1] ** 2 + qt[2] ** 2 + qt[3] ** 2)
    for i in range(4):
        qt[i] /= nq
    if qt[3] < 0.0:
        for i in range(4):
            qt[i] = -qt[i]
    ax = np.sqrt(qt[0] ** 2 + qt[1] ** 2 + qt[2] ** 2)
    angle = 2.0 * np.arctan2(ax, qt[3])
    if angle <= 1e-3:
        a2 = angle * angle
        scale = 2.0 + a2 / 12.0 + 7.0 * a2 * a2 / 2880.0
    else:
        scale = angle / np.sin(angle / 2.0)
    for i in range(3):
        out[i] = scale * qt[i]


@njit(cache=True)
def _matrix_rotvec(R, out):
    """:func:`..geometry.rotations.matrix_rotvec`."""
    c = (R[0, 0] + R[1, 1] + R[2, 2] - 1.0) / 2.0
    if c < -0.999:
        _quat_rotvec(R, out)
        return
    w0 = R[2, 1] - R[1, 2]
    w1 = R[0, 2] - R[2, 0]
    w2 = R[1, 0] - R[0, 1]
    sn = 0.5 * np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
    th = np.arctan2(sn, c)
    f = 0.5 if th < 1e-12 else th / (2.0 * sn)
    out[0] = w0 * f
    out[1] = w1 * f
    out[2] = w2 * f


@njit(cache=True)
def _log(T, fast, out):
    """The twist ``out`` (6,) of a displacement ``T``: :func:`.closure._log_single` when ``fast``
    (the rotation angle by ``arctan2`` away from a half turn), else
    :func:`..geometry.rotations.log_transform` (scipy's rotation vector)."""
    c = (T[0, 0] + T[1, 1] + T[2, 2] - 1.0) / 2.0
    p0, p1, p2 = T[0, 3], T[1, 3], T[2, 3]
    if fast and c >= -0.999:
        w0 = T[2, 1] - T[1, 2]
        w1 = T[0, 2] - T[2, 0]
        w2 = T[1, 0] - T[0, 1]
        sn = 0.5 * np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        th = np.arctan2(sn, c)
        if th < 1e-8:
            out[0], out[1], out[2] = 0.5 * w0, 0.5 * w1, 0.5 * w2
            out[3], out[4], out[5] = p0, p1, p2
            return
        f = 1.0 / (2.0 * sn)
        w0, w1, w2 = w0 * f, w1 * f, w2 * f
    else:
        Rc = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                Rc[i, j] = T[i, j]
        rv = np.empty(3)
        _quat_rotvec(Rc, rv)
        th = np.sqrt(rv[0] ** 2 + rv[1] ** 2 + rv[2] ** 2)
        if th < 1e-12:
            out[0] = out[1] = out[2] = 0.0
            out[3], out[4], out[5] = p0, p1, p2
            return
        w0, w1, w2 = rv[0] / th, rv[1] / th, rv[2] / th
    # G^-1 p = p / th - 0.5 w x p + a w x (w x p),  a = 1 / th - cot(th / 2) / 2
    a = 1.0 / th - 0.5 / np.tan(th / 2.0)
    x0 = w1 * p2 - w2 * p1
    x1 = w2 * p0 - w0 * p2
    x2 = w0 * p1 - w1 * p0
    y0 = w1 * x2 - w2 * x1
    y1 = w2 * x0 - w0 * x2
    y2 = w0 * x1 - w1 * x0
    out[0], out[1], out[2] = w0 * th, w1 * th, w2 * th
    out[3] = (p0 / th - 0.5 * x0 + a * y0) * th
    out[4] = (p1 / th - 0.5 * x1 + a * y1) * th
    out[5] = (p2 / th - 0.5 * x2 + a * y2) * th


@njit(cache=True)
def _inverse_into(T, out):
    for i in range(3):
        for j in range(3):
            out[i, j] = T[j, i]
    for i in range(3):
        out[i, 3] = -(T[0, i] * T[0, 3] + T[1, i] * T[1, 3] + T[2, i] * T[2, 3])
        out[3, i] = 0.0
    out[3, 3] = 1.0


@njit(cache=True)
def _copy44(src, dst):
    """``dst[:] = src`` for 4x4 arrays (element loops: numba's slice assignment is slow to compile)."""
    for i in range(4):
        for j in range(4):
            dst[i, j] = src[i, j]


@njit(cache=True)
def _mm4(A, B, out):
    for i in range(4):
        for j in range(4):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j] + A[i, 3] * B[3, j]


@njit(cache=True)
def _exp_twist(V, out):
    """:func:`..geometry.rotations.exp_twist` of one twist at ``theta = 1``."""
    wn = np.sqrt(V[0] * V[0] + V[1] * V[1] + V[2] * V[2])
    for i in range(4):
        for j in range(4):
            out[i, j] = 0.0
    out[3, 3] = 1.0
    if wn > 0.0:
        ws = np.empty(3)
        vs = np.empty(3)
        for i in range(3):
            ws[i] = V[i] / wn
            vs[i] = V[3 + i] / wn
        W = np.empty((3, 3))
        _skew(ws, W)
        W2 = np.empty((3, 3))
        _mm(W, W, W2)
        s = np.sin(wn)
        c = 1.0 - np.cos(wn)
        for i in range(3):
            for j in range(3):
                out[i, j] = s * W[i, j] + c * W2[i, j]
            out[i, i] += 1.0
        for i in range(3):
            acc = 0.0
            for j in range(3):
                G = c * W[i, j] + (wn - s) * W2[i, j]
                if i == j:
                    G += wn
                acc += G * vs[j]
            out[i, 3] = acc
    else:
        for i in range(3):
            out[i, i] = 1.0
            out[i, 3] = V[3 + i]


_EPS = float(np.finfo(np.float64).eps)


@njit(cache=True)
def _svd(A):
    """``np.linalg.svd(A, full_matrices=False)``: the one LAPACK routine the kernels use (each
    distinct numba linalg call adds seconds to the first compilation)."""
    return np.linalg.svd(A, full_matrices=False)


@njit(cache=True)
def _lstsq(A, b):
    """Minimum-norm least squares, as ``np.linalg.lstsq(A, b, rcond=None)``: singular values at
    or below ``eps max(m, n)`` times the largest count as zero."""
    m, n = A.shape
    x = np.zeros(n)
    if m == 0 or n == 0:
        return x
    U, s, Vt = _svd(A)
    cut = _EPS * max(m, n) * s[0]
    for i in range(len(s)):
        if s[i] > cut:
            c = 0.0
            for k in range(m):
                c += U[k, i] * b[k]
            c /= s[i]
            for j in range(n):
                x[j] += c * Vt[i, j]
    return x


@njit(cache=True)
def _det(M):
    """Determinant by LU with partial pivoting (LAPACK getrf's pivoting, as ``np.linalg.det``)."""
    n = M.shape[0]
    A = M.copy()
    det = 1.0
    for k in range(n):
        p = k
        best = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > best:
                best = abs(A[i, k])
                p = i
        if A[p, k] == 0.0:
            return 0.0
        if p != k:
            for j in range(n):
                t = A[k, j]
                A[k, j] = A[p, j]
                A[p, j] = t
            det = -det
        det *= A[k, k]
        for i in range(k + 1, n):
            f = A[i, k] / A[k, k]
            for j in range(k + 1, n):
                A[i, j] -= f * A[k, j]
    return det


@njit(cache=True)
def _orthonormal(D):
    """Keep the rotation of ``D`` orthonormal (``U Vt`` of its SVD: the nearest rotation), in place."""
    R = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            R[i, j] = D[i, j]
    U, _, Vt = _svd(R)
    for i in range(3):
        for j in range(3):
            D[i, j] = U[i, 0] * Vt[0, j] + U[i, 1] * Vt[1, j] + U[i, 2] * Vt[2, j]


# ---------------------------------------------------------------------------- chain and closure
@njit(cache=True)
def _rodrigues(w0, w1, w2, s, c, out):
    """``I + s W + c W W`` with ``W = skew(w)`` (``W W = w w^T - |w|^2 I``)."""
    n2 = w0 * w0 + w1 * w1 + w2 * w2
    out[0, 0] = 1.0 + c * (w0 * w0 - n2)
    out[1, 1] = 1.0 + c * (w1 * w1 - n2)
    out[2, 2] = 1.0 + c * (w2 * w2 - n2)
    out[0, 1] = -s * w2 + c * w0 * w1
    out[1, 0] = s * w2 + c * w0 * w1
    out[0, 2] = s * w1 + c * w0 * w2
    out[2, 0] = -s * w1 + c * w0 * w2
    out[1, 2] = -s * w0 + c * w1 * w2
    out[2, 1] = s * w0 + c * w1 * w2


@njit(cache=True)
def _chain(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J):
    """:func:`.closure.chain_forward` (``local=True``) of the freedoms ``lo:hi``: ``T`` (4x4) and
    the spatial Jacobian ``J[:, :hi - lo]``, in local coordinates for balls (their axes moved by
    the preceding freedoms).  Each joint (one freedom, or a ball's three) contributes columns
    ``(R a ; R m + p x R a)`` for its reference directions ``a`` and moments ``m``, then moves
    the chain's displacement ``(R, p)`` by its own ``(Rb, u)``: ``p += R u``, ``R = R Rb``."""
    R = np.zeros((3, 3))
    R[0, 0] = R[1, 1] = R[2, 2] = 1.0
    p = np.zeros(3)
    Rb = np.empty((3, 3))
    Rn = np.empty((3, 3))
    u = np.empty(3)
    ax = np.empty((3, 3))
    mo = np.empty((3, 3))
    i = lo
    while i < hi:
        g = ball_of[i]
        if g >= 0:
            k = 3
            A = ball_axes[g]
            c = ball_centre[g]
            for j in range(3):
                for a in range(3):
                    ax[a, j] = A[a, j]
                mo[0, j] = c[1] * A[2, j] - c[2] * A[1, j]
                mo[1, j] = c[2] * A[0, j] - c[0] * A[2, j]
                mo[2, j] = c[0] * A[1, j] - c[1] * A[0, j]
            f0 = A[0, 0] * q[i] + A[0, 1] * q[i + 1] + A[0, 2] * q[i + 2]
            f1 = A[1, 0] * q[i] + A[1, 1] * q[i + 1] + A[1, 2] * q[i + 2]
            f2 = A[2, 0] * q[i] + A[2, 1] * q[i + 1] + A[2, 2] * q[i + 2]
            th = np.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
            if th > 1e-12:
                _rodrigues(f0 / th, f1 / th, f2 / th, np.sin(th), 1.0 - np.cos(th), Rb)
            else:
                _rodrigues(0.0, 0.0, 0.0, 0.0, 0.0, Rb)
            for a in range(3):  # T <- T [Rb, c - Rb c]
                u[a] = c[a] - (Rb[a, 0] * c[0] + Rb[a, 1] * c[1] + Rb[a, 2] * c[2])
        else:
            k = 1
            w0, w1, w2 = S[i, 0], S[i, 1], S[i, 2]
            v0, v1, v2 = S[i, 3], S[i, 4], S[i, 5]
            ax[0, 0], ax[1, 0], ax[2, 0] = w0, w1, w2
            mo[0, 0], mo[1, 0], mo[2, 0] = v0, v1, v2
            t = q[i]
            if np.sqrt(w0 * w0 + w1 * w1 + w2 * w2) > 1e-12:
                st = np.sin(t)
                ct = 1.0 - np.cos(t)
                _rodrigues(w0, w1, w2, st, ct, Rb)
                x0 = w1 * v2 - w2 * v1  # w x v
                x1 = w2 * v0 - w0 * v2
                x2 = w0 * v1 - w1 * v0
                u[0] = t * v0 + ct * x0 + (t - st) * (w1 * x2 - w2 * x1)
                u[1] = t * v1 + ct * x1 + (t - st) * (w2 * x0 - w0 * x2)
                u[2] = t * v2 + ct * x2 + (t - st) * (w0 * x1 - w1 * x0)
            else:
                _rodrigues(0.0, 0.0, 0.0, 0.0, 0.0, Rb)
                u[0], u[1], u[2] = t * v0, t * v1, t * v2
        for j in range(k):
            col = i - lo + j
            for a in range(3):
                J[a, col] = R[a, 0] * ax[0, j] + R[a, 1] * ax[1, j] + R[a, 2] * ax[2, j]
                J[3 + a, col] = R[a, 0] * mo[0, j] + R[a, 1] * mo[1, j] + R[a, 2] * mo[2, j]
            J[3, col] += p[1] * J[2, col] - p[2] * J[1, col]
            J[4, col] += p[2] * J[0, col] - p[0] * J[2, col]
            J[5, col] += p[0] * J[1, col] - p[1] * J[0, col]
        for a in range(3):
            p[a] += R[a, 0] * u[0] + R[a, 1] * u[1] + R[a, 2] * u[2]
        for a in range(3):
            for b in range(3):
                Rn[a, b] = R[a, 0] * Rb[0, b] + R[a, 1] * Rb[1, b] + R[a, 2] * Rb[2, b]
        for a in range(3):
            for b in range(3):
                R[a, b] = Rn[a, b]
        i += k
    for a in range(3):
        for b in range(3):
            T[a, b] = R[a, b]
        T[a, 3] = p[a]
        T[3, a] = 0.0
    T[3, 3] = 1.0


@njit(cache=True)
def _hub(h, D, B):
    if h == 0:
        return D
    return B[h - 1]


@njit(cache=True)
def _adjoint_columns(H, J, m):
    """``J[:, :m] <- Ad(H) J[:, :m]`` in place."""
    top = np.empty(3)
    bot = np.empty(3)
    x = np.empty(3)
    for c in range(m):
        for a in range(3):
            top[a] = H[a, 0] * J[0, c] + H[a, 1] * J[1, c] + H[a, 2] * J[2, c]
            bot[a] = H[a, 0] * J[3, c] + H[a, 1] * J[4, c] + H[a, 2] * J[5, c]
        x[0] = H[1, 3] * top[2] - H[2, 3] * top[1]
        x[1] = H[2, 3] * top[0] - H[0, 3] * top[2]
        x[2] = H[0, 3] * top[1] - H[1, 3] * top[0]
        for a in range(3):
            J[a, c] = top[a]
            J[3 + a, c] = x[a] + bot[a]


@njit(cache=True)
def _max_limb(limb_start):
    m = 0
    for k in range(len(limb_start) - 1):
        m = max(m, limb_start[k + 1] - limb_start[k])
    return m


@njit(cache=True)
def _closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, want_A, A, r):
    """Residual ``r`` (6K,) and, when ``want_A``, the closure Jacobian ``A`` (6K, na + 6h):
    active joint columns at ``colmap[i]`` (-1: not active), then a twist per moving hub."""
    K = len(limb_start) - 1
    J = np.empty((6, max(_max_limb(limb_start), 1)))
    T = np.empty((4, 4))
    T2 = np.empty((4, 4))
    Hi = np.empty((4, 4))
    res = np.empty(6)
    if want_A:
        for i in range(A.shape[0]):
            for c in range(A.shape[1]):
                A[i, c] = 0.0
    for k in range(K):
        lo = limb_start[k]
        hi = limb_start[k + 1]
        _chain(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J)
        a = ends[k, 0]
        b = ends[k, 1]
        r0 = 6 * k
        if a >= 0:
            Ha = _hub(a, D, B)
            if want_A:
                _adjoint_columns(Ha, J, hi - lo)
                for i in range(6):
                    A[r0 + i, na + 6 * a + i] += 1.0
            _mm4(Ha, T, T2)
            _copy44(T2, T)
        if want_A:
            if b >= 0:
                for i in range(6):
                    A[r0 + i, na + 6 * b + i] -= 1.0
            for i in range(lo, hi):
                c = colmap[i]
                if c >= 0:
                    for x in range(6):
                        A[r0 + x, c] = J[x, i - lo]
        if b >= 0:
            _inverse_into(_hub(b, D, B), Hi)
            _mm4(T, Hi, T2)
            _log(T2, True, res)
        else:
            _log(T, True, res)
        for i in range(6):
            r[r0 + i] = res[i]


@njit(cache=True)
def _colmap(active):
    n = len(active)
    out = np.empty(n, dtype=np.int64)
    na = 0
    for i in range(n):
        out[i] = -1
        if active[i]:
            out[i] = na
            na += 1
    return out, na


@njit(cache=True)
def _scales(linear, active, K, h, L):
    """:func:`.closure.closure_scales`."""
    row = np.empty(6 * K)
    for k in range(K):
        for i in range(3):
            row[6 * k + i] = 1.0
            row[6 * k + 3 + i] = 1.0 / L
    na = 0
    for i in range(len(active)):
        if active[i]:
            na += 1
    col = np.empty(na + 6 * h)
    j = 0
    for i in range(len(active)):
        if active[i]:
            col[j] = L if linear[i] else 1.0
            j += 1
    for x in range(h):
        for i in range(3):
            col[na + 6 * x + i] = 1.0
            col[na + 6 * x + 3 + i] = L
    return row, col


@njit(cache=True)
def _retract(ball_first, ball_axes, q, D, B, active, step, na, fix_platform, q_out, D_out, B_out):
    """:func:`.closure.retract` into ``q_out``, ``D_out``, ``B_out``."""
    n = len(q)
    dq = np.zeros(n)
    j = 0
    for i in range(n):
        if active[i]:
            dq[i] = step[j]
            j += 1
    for i in range(n):
        q_out[i] = q[i] + dq[i]
    a = np.empty(3)
    b = np.empty(3)
    Ra = np.empty((3, 3))
    Rb = np.empty((3, 3))
    Rn = np.empty((3, 3))
    rv = np.empty(3)
    for g in range(len(ball_first)):
        i = ball_first[g]
        A = ball_axes[g]
        for x in range(3):
            a[x] = A[x, 0] * dq[i] + A[x, 1] * dq[i + 1] + A[x, 2] * dq[i + 2]
            b[x] = A[x, 0] * q[i] + A[x, 1] * q[i + 1] + A[x, 2] * q[i + 2]
        _rotvec_matrix(a, Ra)
        _rotvec_matrix(b, Rb)
        _mm(Ra, Rb, Rn)
        _matrix_rotvec(Rn, rv)
        for x in range(3):
            q_out[i + x] = A[0, x] * rv[0] + A[1, x] * rv[1] + A[2, x] * rv[2]
    nv = len(step) - na
    E = np.empty((4, 4))
    if fix_platform or nv < 6:
        _copy44(D, D_out)
    else:
        _exp_twist(step[na : na + 6], E)
        _mm4(E, D, D_out)
        _orthonormal(D_out)
    for bi in range(B.shape[0]):
        if nv >= 12 + 6 * bi:
            _exp_twist(step[na + 6 + 6 * bi : na + 12 + 6 * bi], E)
            _mm4(E, B[bi], B_out[bi])
            _orthonormal(B_out[bi])
        else:
            _copy44(B[bi], B_out[bi])


@njit(cache=True)
def _norm(x):
    s = 0.0
    for v in x:
        s += v * v
    return np.sqrt(s)


@njit(cache=True)
def _correct(S, ball_of, ball_first, ball_axes, ball_centre, limb_start, ends, linear, L, qs, Ds, Bs, active,
             fix_platform, tol, max_iter, q_out, D_out, B_out, status, iters, resid):
    """:func:`.closure.correct` from each seed ``qs[s], Ds[s], Bs[s]``: the result in ``q_out[s]``,
    ``D_out[s]``, ``B_out[s]``, with ``status[s]`` 1 converged, 2 stationary (steps vanished
    without closure), 0 not converged, the iterations and the residual."""
    K = len(limb_start) - 1
    h = 1 + Bs.shape[1]
    n = qs.shape[1]
    colmap, na = _colmap(active)
    row, col = _scales(linear, active, K, h, L)
    nc = na + 6 * h
    keep = np.ones(nc, dtype=np.bool_)
    if fix_platform:
        for i in range(na, na + 6):
            keep[i] = False
    nk = 0
    for i in range(nc):
        if keep[i]:
            nk += 1
    A = np.zeros((6 * K, nc))
    r = np.zeros(6 * K)
    As = np.empty((6 * K, nk))
    rhs = np.empty(6 * K)
    step = np.zeros(nc)
    q2 = np.empty(n)
    D2 = np.empty((4, 4))
    B2 = np.empty((h - 1, 4, 4))
    for s in range(qs.shape[0]):
        q = q_out[s]
        D = D_out[s]
        B = B_out[s]
        for i in range(n):
            q[i] = qs[s, i]
        _copy44(Ds[s], D)
        for b in range(h - 1):
            _copy44(Bs[s, b], B[b])
        st = 0
        rn = np.inf
        it = 0
        for it in range(max_iter + 1):
            _closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, True, A, r)
            sq = 0.0
            for i in range(6 * K):
                rhs[i] = -row[i] * r[i]
                sq += rhs[i] * rhs[i]
            rn = np.sqrt(sq)
            if rn < tol:
                st = 1
                break
            if it == max_iter or not np.isfinite(rn):
                break
            for i in range(6 * K):
                j = 0
                for c in range(nc):
                    if keep[c]:
                        As[i, j] = row[i] * A[i, c] * col[c]
                        j += 1
            x = _lstsq(As, rhs)
            if _norm(x) < 1e-13 * max(1.0, rn):
                st = 2
                break
            j = 0
            for c in range(nc):
                if keep[c]:
                    step[c] = col[c] * x[j]
                    j += 1
                else:
                    step[c] = 0.0
            _retract(ball_first, ball_axes, q, D, B, active, step, na, fix_platform, q2, D2, B2)
            for i in range(n):
                q[i] = q2[i]
            _copy44(D2, D)
            for b in range(h - 1):
                _copy44(B2[b], B[b])
        status[s] = st
        iters[s] = it
        resid[s] = rn


@njit(cache=True)
def _systems(S, ball_of, ball_axes, ball_centre, limb_start, ends, qs, Ds, Bs, active, want_A, A_out, r_out):
    """Residuals ``r_out[s]`` and, when ``want_A``, closure Jacobians ``A_out[s]`` of many configurations."""
    colmap, na = _colmap(active)
    for s in range(qs.shape[0]):
        _closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, qs[s], Ds[s], Bs[s], colmap, na, want_A,
                        A_out[s] if want_A else A_out[0], r_out[s])


# ---------------------------------------------------------------------------- limb inverse position
@njit(cache=True)
def _limb_gn(S, ball_of, ball_first, ball_axes, ball_centre, Ds, q0s, lin, L, tol, max_iter, hold, has_hold, q_out,
             res_out, ok_out):
    """``position._limb_gn`` for one chain at each tip displacement ``Ds[s]`` from ``q0s[s]``:
    Gauss-Newton in local coordinates (S joints updated by composing rotations); the result in
    ``q_out[s]``, its nondimensional residual and whether it converged."""
    m = q0s.shape[1]
    colscale = np.empty(m)
    for i in range(m):
        colscale[i] = L if lin[i] else 1.0
        if has_hold and hold[i]:
            colscale[i] = 0.0
    row = np.empty(6)
    for i in range(3):
        row[i] = 1.0
        row[3 + i] = 1.0 / L
    Dinv = np.empty((4, 4))
    T = np.empty((4, 4))
    T2 = np.empty((4, 4))
    J = np.empty((6, max(m, 1)))
    M = np.empty((6, m))
    r = np.empty(6)
    rhs = np.empty(6)
    qn = np.empty(m)
    a = np.empty(3)
    b = np.empty(3)
    Ra = np.empty((3, 3))
    Rb = np.empty((3, 3))
    Rn = np.empty((3, 3))
    rv = np.empty(3)
    for s in range(Ds.shape[0]):
        _inverse_into(Ds[s], Dinv)
        q = q_out[s]
        for i in range(m):
            q[i] = q0s[s, i]
        rn = np.inf
        for _ in range(max_iter):
            _chain(S, ball_of, ball_axes, ball_centre, q, 0, m, T, J)
            _mm4(T, Dinv, T2)
            _log(T2, False, r)
            sq = 0.0
            for i in range(6):
                rhs[i] = -row[i] * r[i]
                sq += rhs[i] * rhs[i]
            rn = np.sqrt(sq)
            if rn < tol:
                break
            for i in range(6):
                for j in range(m):
                    M[i, j] = row[i] * J[i, j] * colscale[j]
            x = _lstsq(M, rhs)
            if _norm(x) < 1e-14:
                break
            for j in range(m):
                qn[j] = q[j] + colscale[j] * x[j]
            for g in range(len(ball_first)):
                i = ball_first[g]
                A = ball_axes[g]
                for t in range(3):
                    a[t] = (A[t, 0] * colscale[i] * x[i] + A[t, 1] * colscale[i + 1] * x[i + 1]
                            + A[t, 2] * colscale[i + 2] * x[i + 2])
                    b[t] = A[t, 0] * q[i] + A[t, 1] * q[i + 1] + A[t, 2] * q[i + 2]
                _rotvec_matrix(a, Ra)
                _rotvec_matrix(b, Rb)
                _mm(Ra, Rb, Rn)
                _quat_rotvec(Rn, rv)
                for t in range(3):
                    qn[i + t] = A[0, t] * rv[0] + A[1, t] * rv[1] + A[2, t] * rv[2]
            for j in range(m):
                q[j] = qn[j]
        res_out[s] = rn
        ok_out[s] = rn < tol


# ---------------------------------------------------------------------------- driver determinants
@njit(cache=True)
def _det5_reciprocal(Tn, out):
    """:func:`..geometry.screws.cofactor_reciprocal` of five nondimensional screws (5, 6)."""
    y = np.empty(6)
    M = np.empty((5, 5))
    for j in range(6):
        for i in range(5):
            c2 = 0
            for c in range(6):
                if c != j:
                    M[i, c2] = Tn[i, c]
                    c2 += 1
        y[j] = (-1.0) ** j * _det(M)
    for i in range(3):
        out[i] = y[3 + i]
        out[3 + i] = y[i]


@njit(cache=True)
def _null_rows(Tn, rtol):
    """``vt[r:]`` of the row-normalised screws ``Tn`` (m, 6) (``screws._svd``/``reciprocal_basis``)."""
    m = Tn.shape[0]
    if m == 0:
        out = np.zeros((6, 6))
        for i in range(6):
            out[i, i] = 1.0
        return out
    X = np.empty((m, 6))
    for i in range(m):
        mx = 0.0
        for c in range(6):
            mx = max(mx, abs(Tn[i, c]))
        if mx <= 0.0:
            mx = 1.0
        nn = 0.0
        for c in range(6):
            X[i, c] = Tn[i, c] / mx
            nn += X[i, c] ** 2
        nn = np.sqrt(nn)
        if nn <= 0.0:
            nn = 1.0
        for c in range(6):
            X[i, c] /= nn
    if m >= 6:
        _, sv, vt = _svd(X)
    else:  # padded with zero rows: the reduced SVD of a 6x6 gives the full V
        P = np.zeros((6, 6))
        for i in range(m):
            for c in range(6):
                P[i, c] = X[i, c]
        _, sv, vt = _svd(P)
    r = 0
    if sv[0] != 0.0:
        lim = rtol * max(1.0, sv[0])
        for i in range(min(m, 6)):
            if sv[i] > lim:
                r += 1
    out = np.empty((6 - r, 6))
    for i in range(r, 6):
        for c in range(6):
            out[i - r, c] = vt[i, c]
    return out


@njit(cache=True)
def _actuation_direction(others, cn, rtol, out):
    """The unit wrench (nondimensional) reciprocal to four twists ``others`` and orthogonal to
    the limb's constraint wrench ``cn`` (unit): the null vector of those five conditions by
    cofactors, without an SVD.  Returns False (the caller takes the SVD path, whose rank
    decisions the Python reference makes) unless the conditions are independent by a wide margin
    (the relative cofactor norm above ``1e4 rtol``: then the four twists have rank 4 at ``rtol``
    and the direction is unique, so both paths agree)."""
    M = np.empty((5, 6))
    for i in range(4):
        mx = 0.0
        for c in range(6):
            mx = max(mx, abs(others[i, c]))
        if mx <= 0.0:
            return False
        nn = 0.0
        for c in range(6):
            nn += (others[i, c] / mx) ** 2
        nn = np.sqrt(nn)
        for c in range(3):  # swap: t . swap(w) = 0 is the reciprocity of twist t and wrench w
            M[i, c] = others[i, 3 + c] / mx / nn
            M[i, 3 + c] = others[i, c] / mx / nn
    for c in range(6):
        M[4, c] = cn[c]
    y = np.empty(6)
    _det5_reciprocal(M, y)  # swapped cofactors
    for c in range(3):
        out[c] = y[3 + c]
        out[3 + c] = y[c]
    ny = _norm(out)
    if not ny > 1e4 * rtol:
        return False
    for c in range(6):
        out[c] /= ny
    return True


@njit(cache=True)
def _driver_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, active, L, rtol, q, D, B, drivers, out):
    """:func:`.jacobian.driver_determinants` without internal bodies.  Returns 0 when ``out`` is
    filled, 1 when the constraint rows are not 5 (``out`` = NaN), 2 for a limb this kernel does not
    handle (fewer than five active twists, or five dependent ones: the Python path decides)."""
    K = len(limb_start) - 1
    n = len(q)
    J = np.empty((6, max(_max_limb(limb_start), 1)))
    T = np.empty((4, 4))
    tw = np.empty((n, 6))  # active twists, nondimensional, by global index
    limb_of = np.empty(n, dtype=np.int64)
    cons = np.zeros((K, 6))  # per limb: its constraint wrench (SI), when it has one
    has_con = np.zeros(K, dtype=np.bool_)
    ncons = 0
    for k in range(K):
        lo = limb_start[k]
        hi = limb_start[k + 1]
        _chain(S, ball_of, ball_axes, ball_centre, q, lo, hi, T, J)
        a = ends[k, 0]
        if a >= 0:
            _adjoint_columns(_hub(a, D, B), J, hi - lo)
        ma = 0
        for i in range(lo, hi):
            limb_of[i] = k
            if active[i]:
                ma += 1
            for c in range(6):
                tw[i, c] = J[c, i - lo] if c < 3 else J[c, i - lo] / L
        if ma == 5:
            Tn = np.empty((5, 6))
            j = 0
            prod = 1.0
            for i in range(lo, hi):
                if active[i]:
                    for c in range(6):
                        Tn[j, c] = tw[i, c]
                    prod *= _norm(tw[i])
                    j += 1
            w = np.empty(6)
            _det5_reciprocal(Tn, w)
            nw = _norm(w)
            if not nw > rtol * prod:
                return 2
            for c in range(6):
                cons[k, c] = w[c] / nw if c < 3 else w[c] / nw * L
            has_con[k] = True
            ncons += 1
        elif ma > 5:
            Tn = np.empty((ma, 6))
            j = 0
            for i in range(lo, hi):
                if active[i]:
                    for c in range(6):
                        Tn[j, c] = tw[i, c]
                    j += 1
            if _null_rows(Tn, rtol).shape[0] != 0:
                return 2
        else:
            return 2
    if ncons != 5:
        for x in range(len(drivers)):
            out[x] = np.nan
        return 1
    M = np.empty((6, 6))
    j = 0
    for k in range(K):
        if has_con[k]:
            for c in range(3):  # swap: (moment ; force)
                M[j, c] = cons[k, 3 + c]
                M[j, 3 + c] = cons[k, c]
            j += 1
    for x in range(len(drivers)):
        d = drivers[x]
        k = limb_of[d]
        lo = limb_start[k]
        hi = limb_start[k + 1]
        mo = 0
        for i in range(lo, hi):
            if active[i] and i != d:
                mo += 1
        others = np.empty((mo, 6))
        j = 0
        for i in range(lo, hi):
            if active[i] and i != d:
                for c in range(6):
                    others[j, c] = tw[i, c]
                j += 1
        cn = np.empty(6)
        if has_con[k]:
            for c in range(6):
                cn[c] = cons[k, c] if c < 3 else cons[k, c] / L
            nc = _norm(cn)
            for c in range(6):
                cn[c] /= nc
        v0 = np.empty(6)  # the actuation wrench's direction, nondimensional and unit (vt[0] below)
        if not (has_con[k] and mo == 4 and _actuation_direction(others, cn, rtol, v0)):
            if mo == 0:
                Rn = np.zeros((6, 6))
                for i in range(6):
                    Rn[i, i] = 1.0
                for i in range(6):
                    for c in range(3, 6):
                        Rn[i, c] /= L
            else:
                null = _null_rows(others, rtol)
                Rn = np.empty((null.shape[0], 6))
                for i in range(null.shape[0]):
                    for c in range(3):
                        Rn[i, c] = null[i, 3 + c]
                        Rn[i, 3 + c] = null[i, c]
            if has_con[k]:
                for i in range(Rn.shape[0]):
                    dot = 0.0
                    for c in range(6):
                        dot += Rn[i, c] * cn[c]
                    for c in range(6):
                        Rn[i, c] -= dot * cn[c]
            if Rn.shape[0] == 0:
                out[x] = 0.0
                continue
            P = np.zeros((6, 6))
            for i in range(Rn.shape[0]):
                for c in range(6):
                    P[i, c] = Rn[i, c]
            _, s, vt = _svd(P)
            if s[0] < rtol:
                out[x] = 0.0
                continue
            for c in range(6):
                v0[c] = vt[0, c]
        w = np.empty(6)
        for c in range(6):
            w[c] = v0[c] if c < 3 else v0[c] * L
        ta = tw[d]  # nondimensional twist of the driver
        prod = 0.0
        for c in range(3):  # reciprocal product with the SI twist (moments times L)
            prod += w[c] * ta[3 + c] * L + ta[c] * w[3 + c]
        scale = _norm(v0) * _norm(ta)
        if abs(prod) < rtol * max(scale, 1e-300):
            out[x] = 0.0
            continue
        for c in range(3):
            M[5, c] = w[3 + c] / prod
            M[5, 3 + c] = w[c] / prod
        out[x] = _det(M)
    return 0


@njit(cache=True)
def _closure_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, L, q, D, B, cols, out):
    """:func:`.jacobian.closure_determinant` for each active column in ``cols``."""
    K = len(limb_start) - 1
    h = 1 + B.shape[0]
    colmap, na = _colmap(active)
    row, col = _scales(linear, active, K, h, L)
    nc = na + 6 * h
    A = np.empty((6 * K, nc))
    r = np.empty(6 * K)
    _closure_system(S, ball_of, ball_axes, ball_centre, limb_start, ends, q, D, B, colmap, na, True, A, r)
    for i in range(6 * K):
        for c in range(nc):
            A[i, c] *= row[i] * col[c]
    if nc - 1 != 6 * K:
        for x in range(len(cols)):
            out[x] = np.nan
        return
    M = np.empty((6 * K, nc - 1))
    for x in range(len(cols)):
        for i in range(6 * K):
            j = 0
            for c in range(nc):
                if c != cols[x]:
                    M[i, j] = A[i, c]
                    j += 1
        out[x] = _det(M)


@njit(cache=True)
def _dets_many(S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, L, rtol, qs, Ds, Bs, drivers, cols,
               bodies, out):
    """Driver determinants at many configurations: the closure determinants of ``cols`` for a
    mechanism with internal bodies, else :func:`_driver_dets` (returns 2 as soon as it declines)."""
    for s in range(qs.shape[0]):
        if bodies:
            _closure_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, linear, active, L, qs[s], Ds[s], Bs[s],
                          cols, out[s])
        elif _driver_dets(S, ball_of, ball_axes, ball_centre, limb_start, ends, active, L, rtol, qs[s], Ds[s], Bs[s],
                          drivers, out[s]) == 2:
            return 2
    return 0


@njit(cache=True)
def _difference(ball_first, ball_axes, qa, Da, Ba, qb, Db, Bb, active, wrap, col, out):
    """``tracking._MechanismBase._config_diff``: local coordinates of ``b`` relative to ``a``
    (active joint differences, angles wrapped to [-pi, pi); relative rotations of S joints; the
    hubs' relative twists), divided by the column scales ``col``."""
    n = len(qa)
    dq = np.empty(n)
    for i in range(n):
        dq[i] = qb[i] - qa[i]
    a = np.empty(3)
    b = np.empty(3)
    Ra = np.empty((3, 3))
    Rb = np.empty((3, 3))
    Rn = np.empty((3, 3))
    rv = np.empty(3)
    for g in range(len(ball_first)):
        i = ball_first[g]
        A = ball_axes[g]
        for x in range(3):
            a[x] = A[x, 0] * qa[i] + A[x, 1] * qa[i + 1] + A[x, 2] * qa[i + 2]
            b[x] = A[x, 0] * qb[i] + A[x, 1] * qb[i + 1] + A[x, 2] * qb[i + 2]
        _rotvec_matrix(a, Ra)
        _rotvec_matrix(b, Rb)
        for x in range(3):  # Rb Ra^T
            for y in range(3):
                Rn[x, y] = Rb[x, 0] * Ra[y, 0] + Rb[x, 1] * Ra[y, 1] + Rb[x, 2] * Ra[y, 2]
        _quat_rotvec(Rn, rv)
        for x in range(3):
            dq[i + x] = A[0, x] * rv[0] + A[1, x] * rv[1] + A[2, x] * rv[2]
    j = 0
    for i in range(n):
        if active[i]:
            v = dq[i]
            if wrap[j]:
                v = (v + np.pi) % (2 * np.pi) - np.pi
            out[j] = v / col[j]
            j += 1
    Hi = np.empty((4, 4))
    T = np.empty((4, 4))
    tw = np.empty(6)
    for h in range(1 + Ba.shape[0]):
        _inverse_into(_hub(h, Da, Ba), Hi)
        _mm4(_hub(h, Db, Bb), Hi, T)
        _log(T, False, tw)
        for x in range(6):
            out[j + x] = tw[x] / col[j + x]
        j += 6


# ---------------------------------------------------------------------------- SPS legs
@njit(cache=True)
def _sps_legs(poses, base, plat, out):
    """Leg lengths ``|R b_i + p - a_i|`` of poses ``(x, y, z, a1, a2, a3)``, ``R = Rz(a1) Ry(a2) Rx(a3)``."""
    m = base.shape[0]
    for s in range(poses.shape[0]):
        x, y, z = poses[s, 0], poses[s, 1], poses[s, 2]
        sg, cg = np.sin(poses[s, 3]), np.cos(poses[s, 3])
        sb, cb = np.sin(poses[s, 4]), np.cos(poses[s, 4])
        sa, ca = np.sin(poses[s, 5]), np.cos(poses[s, 5])
        r00, r01, r02 = cg * cb, cg * sb * sa - sg * ca, cg * sb * ca + sg * sa
        r10, r11, r12 = sg * cb, sg * sb * sa + cg * ca, sg * sb * ca - cg * sa
        r20, r21, r22 = -sb, cb * sa, cb * ca
        for i in range(m):
            bx, by, bz = plat[i, 0], plat[i, 1], plat[i, 2]
            dx = r00 * bx + r01 * by + r02 * bz + x - base[i, 0]
            dy = r10 * bx + r11 * by + r12 * bz + y - base[i, 1]
            dz = r20 * bx + r21 * by + r22 * bz + z - base[i, 2]
            out[s, i] = np.sqrt(dx * dx + dy * dy + dz * dz)


# ---------------------------------------------------------------------------- Python entry points
def _f64(x, shape=None) -> np.ndarray:
    """A C-contiguous, writable float64 array: one numba type per kernel argument (a read-only
    view, e.g. from ``np.broadcast_to``, would be a different type and compile again)."""
    if not (type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable):
        x = np.require(x, np.float64, ["C", "W"])
    return x if shape is None else x.reshape(shape)


def _bools(x, shape) -> np.ndarray:
    return np.require(x, np.bool_, ["C", "W"]).reshape(shape)


def _mask(mech: Mechanism, cm: CompiledMechanism, active) -> np.ndarray:
    if active is None:
        return cm.active
    a = np.require(active, np.bool_, ["C", "W"])
    if a.shape != (cm.n,):
        raise InputError(f"active: {mech.name} has {cm.n} joint variables, got a mask of shape {a.shape}")
    return a


def _config_arrays(cm: CompiledMechanism, config: Configuration) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (_f64(config.q, (cm.n,)), _f64(config.D, (4, 4)), _f64(config.B, (cm.n_bodies, 4, 4)))


def _check(mech: Mechanism, cm: CompiledMechanism, config: Configuration) -> None:
    """:func:`.closure.check_configuration`, with a quick path for the usual valid configuration
    (NaN and infinity propagate into the sums; anything unusual gets the full check and its
    message)."""
    q, D, B = config.q, config.D, config.B
    if (type(q) is np.ndarray and type(D) is np.ndarray and type(B) is np.ndarray and q.shape == (cm.n,)
            and D.shape == (4, 4) and B.shape == (cm.n_bodies, 4, 4) and np.isfinite(q.sum() + D.sum() + B.sum())):
        return
    check_configuration(mech, config)


def _system_args(cm: CompiledMechanism) -> tuple:
    return (cm.screws, cm.ball_of, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends)


def _batch(mech: Mechanism, cm: CompiledMechanism, q, D, B):
    qs = _f64(q)
    if qs.ndim != 2 or qs.shape[1] != cm.n:
        raise InputError(f"q: expected shape (N, {cm.n}) for {mech.name}, got {qs.shape}")
    N = qs.shape[0]
    Ds = _f64(D)
    if Ds.shape == (4, 4):
        Ds = _f64(np.broadcast_to(Ds, (N, 4, 4)))
    if Ds.shape != (N, 4, 4):
        raise InputError(f"D: expected shape (N, 4, 4) or (4, 4) with N = {N}, got {Ds.shape}")
    if B is None:
        Bs = _f64(np.broadcast_to(np.eye(4), (N, cm.n_bodies, 4, 4)))
    else:
        Bs = _f64(B)
        if Bs.shape == (cm.n_bodies, 4, 4):
            Bs = _f64(np.broadcast_to(Bs, (N, cm.n_bodies, 4, 4)))
        if Bs.shape != (N, cm.n_bodies, 4, 4):
            raise InputError(f"B: expected shape (N, {cm.n_bodies}, 4, 4), got {Bs.shape}")
    if not (np.all(np.isfinite(qs)) and np.all(np.isfinite(Ds)) and np.all(np.isfinite(Bs))):
        raise InputError("q, D, B: contain NaN or infinity")
    return qs, Ds, Bs


def _run_systems(cm: CompiledMechanism, qs, Ds, Bs, act, want_A: bool):
    N = qs.shape[0]
    na = int(act.sum())
    A = np.empty((N, 6 * cm.n_limbs, na + 6 * (1 + cm.n_bodies)) if want_A else (1, 0, 0))
    r = np.empty((N, 6 * cm.n_limbs))
    if N:
        _systems(cm.screws, cm.ball_of, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends, qs, Ds, Bs, act, want_A, A,
                 r)
    return A, r


def closure_residual(mech: Mechanism, config: Configuration) -> np.ndarray:
    """:func:`.closure.closure_residual`, compiled."""
    cm = compile_mechanism(mech)
    _check(mech, cm, config)
    q, D, B = _config_arrays(cm, config)
    return _run_systems(cm, q[None], D[None], B[None], cm.active, False)[1][0]


def closure_jacobian(mech: Mechanism, config: Configuration, *, active: np.ndarray | None = None):
    """:func:`.closure.closure_jacobian`, compiled: ``(A, r)``."""
    cm = compile_mechanism(mech)
    _check(mech, cm, config)
    q, D, B = _config_arrays(cm, config)
    A, r = _run_systems(cm, q[None], D[None], B[None], _mask(mech, cm, active), True)
    return A[0], r[0]


def closure_residuals(mech: Mechanism, q, D, B=None) -> np.ndarray:
    """Residuals (N, 6K) of N configurations: joint variables ``q`` (N, n), output displacements
    ``D`` (N, 4, 4) or one (4, 4), body displacements ``B`` (N, k, 4, 4) (default: identities)."""
    cm = compile_mechanism(mech)
    qs, Ds, Bs = _batch(mech, cm, q, D, B)
    return _run_systems(cm, qs, Ds, Bs, cm.active, False)[1]


def closure_jacobians(mech: Mechanism, q, D, B=None, *, active: np.ndarray | None = None):
    """Closure Jacobians (N, 6K, n_active + 6h) and residuals (N, 6K) of N configurations (see
    :func:`closure_residuals` for the arguments)."""
    cm = compile_mechanism(mech)
    qs, Ds, Bs = _batch(mech, cm, q, D, B)
    return _run_systems(cm, qs, Ds, Bs, _mask(mech, cm, active), True)


def _correct_args(cm: CompiledMechanism) -> tuple:
    return (cm.screws, cm.ball_of, cm.ball_first, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends, cm.linear,
            cm.length)


def _result(config: Configuration | None, q, D, B, status: int, it: int, rn: float) -> CorrectionResult:
    # nothing moved: the caller's own configuration, as the Python path returns it
    c = config if config is not None and it == 0 else Configuration(q, D, B)
    return CorrectionResult(c, status == 1, int(it), float(rn), stationary=status == 2)


def _run_correct(mech: Mechanism, cm: CompiledMechanism, seeds: Sequence[Configuration], active, fix_platform: bool,
                 tol: float | None, max_iter: int) -> list[CorrectionResult]:
    act = _mask(mech, cm, active)
    if tol is None:  # the newton tolerance in force (geometry/tolerances.py)
        tol = current_tolerances().newton
    N = len(seeds)
    qs = _f64([c.q for c in seeds], (N, cm.n))
    Ds = _f64([c.D for c in seeds], (N, 4, 4))
    Bs = _f64([c.B for c in seeds], (N, cm.n_bodies, 4, 4))
    q_out, D_out, B_out = np.empty_like(qs), np.empty_like(Ds), np.empty_like(Bs)
    status = np.empty(N, dtype=np.int64)
    iters = np.empty(N, dtype=np.int64)
    resid = np.empty(N)
    if N:
        _correct(*_correct_args(cm), qs, Ds, Bs, act, bool(fix_platform), float(tol), int(max_iter), q_out, D_out,
                      B_out, status, iters, resid)
    return [_result(seeds[s], q_out[s], D_out[s], B_out[s], int(status[s]), int(iters[s]), float(resid[s]))
            for s in range(N)]


def correct(mech: Mechanism, config: Configuration, *, active: np.ndarray | None = None, fix_platform: bool = False,
            tol: float | None = None, max_iter: int = 50) -> CorrectionResult:
    """:func:`.closure.correct`, compiled (same steps, tolerances and statuses)."""
    cm = compile_mechanism(mech)
    _check(mech, cm, config)
    return _run_correct(mech, cm, [config], active, fix_platform, tol, max_iter)[0]


def correct_many(mech: Mechanism, seeds: Sequence[Configuration], *, active: np.ndarray | None = None,
                 fix_platform: bool = False, tol: float | None = None, max_iter: int = 50) -> list[CorrectionResult]:
    """:func:`correct` from many seeds in one compiled loop (multi-start forward position: pass
    ``active`` without the actuators, and seeds whose actuated variables hold the values)."""
    cm = compile_mechanism(mech)
    for c in seeds:
        _check(mech, cm, c)
    return _run_correct(mech, cm, seeds, active, fix_platform, tol, max_iter)


def retract(mech: Mechanism, config: Configuration, active, step, fix_platform: bool = False) -> Configuration:
    """:func:`.closure.retract`, compiled."""
    cm = compile_mechanism(mech)
    act = _mask(mech, cm, active)
    q, D, B = _config_arrays(cm, config)
    st = _f64(step).reshape(-1)
    na = int(act.sum())
    if len(st) < na:
        raise InputError(f"step: expected at least the {na} active joint steps, got {len(st)} values")
    q2, D2, B2 = np.empty_like(q), np.empty_like(D), np.empty_like(B)
    _retract(cm.ball_first, cm.ball_axes, q, D, B, act, st, na, bool(fix_platform), q2, D2, B2)
    return Configuration(q2, D2, B2)


def config_difference(mech: Mechanism, a: Configuration, b: Configuration, active, wrap, col) -> np.ndarray:
    """The tracker's local coordinates of ``b`` relative to ``a`` (``_config_diff`` of
    :mod:`.tracking`): ``wrap`` (n_active,) marks the rotations whose difference is wrapped to
    [-pi, pi), ``col`` the column scales of :func:`.closure.closure_scales`."""
    cm = compile_mechanism(mech)
    act = _mask(mech, cm, active)
    qa, Da, Ba = _config_arrays(cm, a)
    qb, Db, Bb = _config_arrays(cm, b)
    c = _f64(col).reshape(-1)
    w = _bools(wrap, (int(act.sum()),))
    out = np.empty(len(c))
    _difference(cm.ball_first, cm.ball_axes, qa, Da, Ba, qb, Db, Bb, act, w, c, out)
    return out


def _run_limb_gn(chain: Chain, Ds, q0s, lin, L, tol, max_iter, hold):
    ca = _chain_arrays(chain)
    m = len(ca.screws)
    N = Ds.shape[0]
    h = np.zeros(m, dtype=np.bool_) if hold is None else _bools(hold, (m,))
    q_out = np.empty((N, m))
    res = np.empty(N)
    ok = np.empty(N, dtype=np.bool_)
    if N:
        _limb_gn(ca.screws, ca.ball_of, ca.ball_first, ca.ball_axes, ca.ball_centre, Ds, q0s, _bools(lin, (m,)),
                 float(L), float(tol), int(max_iter), h, hold is not None, q_out, res, ok)
    return q_out, res, ok


def limb_gn(chain: Chain, D, q, lin, L, tol=1e-12, max_iter=60, hold=None):
    """``position._limb_gn`` (one limb, tip held at ``D``), compiled: ``(q, residual, converged)``."""
    m = len(chain.screws)
    q_out, res, ok = _run_limb_gn(chain, _f64(D, (1, 4, 4)), _f64(q, (1, m)), lin, L, tol, max_iter, hold)
    return q_out[0], float(res[0]), bool(ok[0])


def limb_inverse_many(mech: Mechanism, D, *, q0=None, tol: float | None = None, max_iter: int = 60):
    """Inverse position of every limb from the ground to the output link at many output
    displacements ``D`` (N, 4, 4), each limb by Gauss-Newton from ``q0`` (default: the reference).

    Returns ``q`` (N, n), the nondimensional residual (N, K) and ``converged`` (N, K); limbs that
    do not run from the ground to the output link are not solved (NaN, False).  One start per
    pose and limb: the solution nearest ``q0``, as :func:`..position.inverse_position` without
    ``all_solutions`` (without its retries when that solution violates a limit)."""
    cm = compile_mechanism(mech)
    Ds = _f64(D)
    if Ds.shape == (4, 4):
        Ds = Ds[None]
    if Ds.ndim != 3 or Ds.shape[1:] != (4, 4):
        raise InputError(f"D: expected shape (N, 4, 4), got {Ds.shape}")
    if not np.all(np.isfinite(Ds)):
        raise InputError("D: contains NaN or infinity")
    q_start = np.zeros(cm.n) if q0 is None else _f64(q0, (cm.n,))
    if tol is None:
        tol = current_tolerances().closure
    N = Ds.shape[0]
    q_out = np.full((N, cm.n), np.nan)
    res = np.full((N, cm.n_limbs), np.nan)
    ok = np.zeros((N, cm.n_limbs), dtype=np.bool_)
    for k, (ch, sl) in enumerate(zip(limb_chains(mech), limb_slices(mech), strict=True)):
        if mech.limb_ends[k] != (None, 0):
            continue
        q0s = _f64(np.broadcast_to(q_start[sl], (N, sl.stop - sl.start)))
        q_out[:, sl], res[:, k], ok[:, k] = _run_limb_gn(ch, Ds, q0s, cm.linear[sl], cm.length, tol, max_iter, None)
    return q_out, res, ok


_DRIVERS: weakref.WeakKeyDictionary[Mechanism, dict] = weakref.WeakKeyDictionary()


def _driver_indices(mech: Mechanism, drivers) -> np.ndarray:
    key = tuple(drivers)
    known = _DRIVERS.setdefault(mech, {})
    if key not in known:
        known[key] = _find_drivers(mech, key)
    return known[key]


def _find_drivers(mech: Mechanism, drivers) -> np.ndarray:
    refs = mech.freedom_refs
    idx = []
    for d in drivers:
        r = mech.freedom(d)
        if r.freedom.locked:
            raise InputError(f"drivers: {d} is locked")
        idx.append(refs.index(r))
    return np.array(idx, dtype=np.int64)


def driver_determinants(mech: Mechanism, config: Configuration, drivers) -> np.ndarray | None:
    """:func:`.jacobian.driver_determinants`, compiled, or ``None`` for a mechanism this kernel
    does not handle (a limb with fewer than five active twists, or five dependent ones): the
    caller then runs the Python path."""
    _check(mech, compile_mechanism(mech), config)
    out = driver_determinants_many(mech, np.asarray(config.q)[None], np.asarray(config.D)[None],
                                   None if not len(config.B) else np.asarray(config.B)[None], drivers)
    return None if out is None else out[0]


def driver_determinants_many(mech: Mechanism, q, D, B, drivers) -> np.ndarray | None:
    """``det J`` of each driver at N configurations (N, len(drivers)); ``None`` when the kernel
    does not handle the mechanism (see :func:`driver_determinants`)."""
    cm = compile_mechanism(mech)
    qs, Ds, Bs = _batch(mech, cm, q, D, B)
    idx = _driver_indices(mech, drivers)
    out = np.empty((qs.shape[0], len(idx)))
    pos = (np.cumsum(cm.active) - 1)[idx]
    flag = _dets_many(*_system_args(cm), cm.linear, cm.active, cm.length, current_tolerances().rank, qs, Ds, Bs, idx,
                      pos, cm.n_bodies > 0, out) if qs.shape[0] else 0
    return None if flag == 2 else out


def sps_leg_lengths(poses, base, platform) -> np.ndarray:
    """Inverse position of SPS (or UPS) legs for many poses: ``|R b_i + p - a_i|`` (N, m).

    ``poses`` (N, 6): ``x, y, z`` of the platform frame's origin and the ``"ZYX"`` (intrinsic)
    angles ``(a1, a2, a3)``, ``R = Rz(a1) Ry(a2) Rx(a3)``, rad; ``base`` (m, 3): the legs' base
    centres ``a_i``; ``platform`` (m, 3): their platform centres ``b_i`` in the platform frame."""
    P = _f64(poses)
    A = _f64(base)
    Bp = _f64(platform)
    if P.ndim != 2 or P.shape[1] != 6:
        raise InputError(f"poses: expected shape (N, 6), got {P.shape}")
    if A.ndim != 2 or A.shape[1] != 3 or Bp.shape != A.shape:
        raise InputError(f"base, platform: expected two (m, 3) arrays, got {A.shape} and {Bp.shape}")
    out = np.empty((P.shape[0], A.shape[0]))
    _sps_legs(P, A, Bp, out)
    return out


def warm_up() -> float:
    """Compile (or load from the on-disk cache) every kernel on a tiny mechanism; returns the
    seconds it took (the first-call cost a user pays once per process)."""
    import time

    from ..model.joints import R, S
    from ..model.mechanism import Limb  # here, not at the top: only the warm-up builds a model

    t0 = time.perf_counter()
    z = [0.0, 0.0, 1.0]
    mech = Mechanism("warm-up", limbs=(Limb("a", (R("A0", [0, 0, 0], z, actuated=True), S("A1", [0.3, 0, 0]),
                                                    S("B1", [0, 1, -0.1]))),
                                       Limb("b", (R("B0", [0, 1, 0.5], [1.0, 0, 0]),))),
                     platform_point=np.array([0, 1, -0.1]))
    c = Configuration.reference(mech)
    closure_residual(mech, c)
    closure_jacobian(mech, c)
    correct(mech, c)
    driver_determinants(mech, c, ["A0.rot"])
    limb_gn(limb_chains(mech)[0], np.eye(4), np.zeros(7), np.zeros(7, bool), 1.0)
    limb_inverse_many(mech, np.eye(4)[None])
    sps_leg_lengths(np.zeros((1, 6)), np.zeros((1, 3)), np.ones((1, 3)))
    return time.perf_counter() - t0
