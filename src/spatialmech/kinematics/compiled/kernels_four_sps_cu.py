"""The closed-form leg lengths of the 4-SPS/CU platform, compiled (numba): the kernels of
:func:`spatialmech.kinematics.closed_forms.four_sps_cu.leg_lengths` (the NumPy form there,
``_legs_sq_block``, is the reference), here so that importing the closed form loads no numba."""

from __future__ import annotations

import numpy as np

from .jit import SAFE_FASTMATH, njit, prange
from .kernels_se3 import SINCOS_MAX, nb_sincos

__all__ = ["four_sps_cu_legs"]

#: The legs kernels' fastmath flags: :data:`.jit.SAFE_FASTMATH` without "no NaN / no infinity",
#: so that the kernels themselves count the poses that hold one (and the caller names them).
_LEGS_FASTMATH = SAFE_FASTMATH - {"nnan", "ninf"}

#: Poses per block of :func:`_legs_kernel`: the block's poses and legs stay in the L1/L2 cache
#: between its loops.
_BLOCK = 512
#: Poses of a padded last block are a multiple of this (the vector loop's width times its
#: unrolling is at most 16 poses on AVX-512; 64 leaves room).
_PAD = 64


@njit(cache=True, fastmath=_LEGS_FASTMATH, inline="always")
def _legs_sq4(z, sa, ca, sb, cb, sg, cg, k, ab2, a):
    """The four squared legs of one pose from its height and its angles' sines and cosines (the
    closed form of :func:`_legs_sq_block`; ``k = 2a^2 + 2b^2``, ``ab2 = 2ab``)."""
    t = sa * sb
    P = ab2 * (cb * cg + ca * cg + t * sg)
    Q = ab2 * (t * cg + cb * sg - ca * sg)
    az2 = 2.0 * a * z
    m = -az2 * sb
    n = az2 * cb * sa
    c = z * z + k - P
    c1 = c + Q
    c -= Q
    return c1 + (m - n), c + (m + n), c1 - (m - n), c - (m + n)


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_pose_libm(ph, i, k, ab2, a, out):
    """One pose's squared legs with libm's sine and cosine (angles beyond
    :data:`.kernels_se3.SINCOS_MAX`)."""
    out[i, 0], out[i, 1], out[i, 2], out[i, 3] = _legs_sq4(
        ph[i, 0], np.sin(ph[i, 1]), np.cos(ph[i, 1]), np.sin(ph[i, 2]), np.cos(ph[i, 2]), np.sin(ph[i, 3]),
        np.cos(ph[i, 3]), k, ab2, a)


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_unusual(v):
    """How many of the numbers ``v`` (a block of poses, flat) are beyond ``SINCOS_MAX`` or not
    finite: an integer count, so that the loop vectorises (a float maximum without "no NaN"
    does not)."""
    c = np.int64(0)
    for j in range(v.shape[0]):
        c += not (abs(v[j]) <= SINCOS_MAX)
    return c


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_sq_flat(v, k, ab2, a, out):
    """The squared legs of the poses ``v`` (4 n,) into ``out`` (4 n,): the closed form of
    :func:`_legs_sq4` with its square roots left to :func:`_legs_sqrt_flat`.  Flat arrays give
    LLVM a constant stride of 4 and no square root or reduction in the loop: the loop vectorises
    (4 poses per AVX2 instruction).  Callers pass a multiple of :data:`_PAD` poses, so that no
    pose falls in the loop's scalar remainder (whose fused multiply-adds may round differently):
    a pose's legs do not depend on where it sits in the batch."""
    for i in range(v.shape[0] // 4):
        j = 4 * i
        sa, ca = nb_sincos(v[j + 1])
        sb, cb = nb_sincos(v[j + 2])
        sg, cg = nb_sincos(v[j + 3])
        out[j], out[j + 1], out[j + 2], out[j + 3] = _legs_sq4(v[j], sa, ca, sb, cb, sg, cg, k, ab2, a)


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_sqrt_flat(out):
    """``out = sqrt(max(out, 0))`` in place (a loop of its own: it vectorises)."""
    for j in range(out.shape[0]):
        x = out[j]
        out[j] = np.sqrt(x if x > 0.0 else 0.0)


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_redo(ph, k, ab2, a, out):
    """After :func:`_legs_sq_flat` on a block that holds an unusual number: the poses with an
    angle beyond ``SINCOS_MAX`` again with libm's sine (squared legs); returns how many poses
    hold a NaN or an infinity."""
    bad = np.int64(0)
    for i in range(ph.shape[0]):
        t = ph[i, 0] + ph[i, 1] + ph[i, 2] + ph[i, 3]
        bad += 0 if t - t == 0.0 else 1
        if abs(ph[i, 1]) > SINCOS_MAX or abs(ph[i, 2]) > SINCOS_MAX or abs(ph[i, 3]) > SINCOS_MAX:
            _legs_pose_libm(ph, i, k, ab2, a, out)
    return bad


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_block(ph, v, a, b, squared, out, o, lo, hi):
    """Poses ``lo:hi`` of ``ph`` (n, 4; ``v`` its flat view) into ``out`` (``o`` its flat view):
    the vectorised loops (a last block that is not a multiple of :data:`_PAD` poses goes through
    a padded copy), the unusual poses redone (:func:`_legs_redo`), then the square roots unless
    ``squared``; returns the number of poses that hold a NaN or an infinity."""
    k = 2.0 * a * a + 2.0 * b * b
    ab2 = 2.0 * a * b
    m = hi - lo
    if m % _PAD == 0:
        _legs_sq_flat(v[4 * lo : 4 * hi], k, ab2, a, o[4 * lo : 4 * hi])
    else:
        w = np.zeros(4 * (m + _PAD - m % _PAD))
        w[: 4 * m] = v[4 * lo : 4 * hi]
        r = np.empty_like(w)
        _legs_sq_flat(w, k, ab2, a, r)
        o[4 * lo : 4 * hi] = r[: 4 * m]
    bad = np.int64(0)
    if _legs_unusual(v[4 * lo : 4 * hi]) > 0:
        bad = _legs_redo(ph[lo:hi], k, ab2, a, out[lo:hi])
    if not squared:
        _legs_sqrt_flat(o[4 * lo : 4 * hi])
    return bad



@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_kernel(ph, v, a, b, squared, out, o):
    """The legs of the poses ``ph`` (n, 4) into ``out`` (n, 4) (``v``, ``o``: their flat views),
    block by block (:func:`_legs_block`); returns the number of poses that hold a NaN or an
    infinity (their legs are not meaningful: the caller raises)."""
    n = ph.shape[0]
    bad = np.int64(0)
    for lo in range(0, n, _BLOCK):
        bad += _legs_block(ph, v, a, b, squared, out, o, lo, min(lo + _BLOCK, n))
    return bad


@njit(cache=True, fastmath=_LEGS_FASTMATH, parallel=True)
def _legs_kernel_parallel(ph, v, a, b, squared, out, o):
    """:func:`_legs_kernel` with the blocks shared among the cores (numba's ``prange``): the same
    numbers, pose by pose."""
    n = ph.shape[0]
    bad = np.int64(0)
    for q in prange((n + _BLOCK - 1) // _BLOCK):
        lo = q * _BLOCK
        bad += _legs_block(ph, v, a, b, squared, out, o, lo, min(lo + _BLOCK, n))
    return bad


def four_sps_cu_legs(flat, a: float, b: float, squared: bool, out, parallel: bool) -> int:
    """Leg lengths (squared if ``squared``) of the poses ``flat`` (n, 4) into ``out`` (n, 4) of
    a 4-SPS/CU platform of half-sides ``a``, ``b``; ``parallel``: shared among the cores.
    Returns the number of poses that hold a NaN or an infinity (the caller raises)."""
    kernel = _legs_kernel_parallel if parallel else _legs_kernel
    return int(kernel(flat, flat.reshape(-1), a, b, squared, out, out.reshape(-1)))
