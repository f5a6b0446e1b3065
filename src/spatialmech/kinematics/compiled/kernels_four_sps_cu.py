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


@njit(cache=True, fastmath=_LEGS_FASTMATH, inline="always")
def _legs_from(ph, i, sa, ca, sb, cb, sg, cg, k, ab2, a, squared, out):
    """One pose of :func:`_legs_kernel` from its angles' sines and cosines (the closed form of
    :func:`_legs_sq_block`)."""
    z = ph[i, 0]
    t = sa * sb
    P = ab2 * (cb * cg + ca * cg + t * sg)
    Q = ab2 * (t * cg + cb * sg - ca * sg)
    az2 = 2.0 * a * z
    m = -az2 * sb
    n = az2 * cb * sa
    c = z * z + k - P
    c1 = c + Q
    c -= Q
    v0, v1, v2, v3 = c1 + (m - n), c + (m + n), c1 - (m - n), c - (m + n)
    if squared:
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = v0, v1, v2, v3
    else:
        out[i, 0] = np.sqrt(max(v0, 0.0))
        out[i, 1] = np.sqrt(max(v1, 0.0))
        out[i, 2] = np.sqrt(max(v2, 0.0))
        out[i, 3] = np.sqrt(max(v3, 0.0))


@njit(cache=True, fastmath=_LEGS_FASTMATH, inline="always")
def _legs_pose(ph, i, k, ab2, a, squared, out):
    """One pose by :func:`.kernels_se3.nb_sincos` (vectorisable); returns its largest angle
    (beyond ``SINCOS_MAX`` the pose is redone by :func:`_legs_pose_libm`)."""
    sa, ca = nb_sincos(ph[i, 1])
    sb, cb = nb_sincos(ph[i, 2])
    sg, cg = nb_sincos(ph[i, 3])
    _legs_from(ph, i, sa, ca, sb, cb, sg, cg, k, ab2, a, squared, out)
    return max(abs(ph[i, 1]), abs(ph[i, 2]), abs(ph[i, 3]))


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_pose_libm(ph, i, k, ab2, a, squared, out):
    """One pose with libm's sine and cosine (angles beyond :data:`.kernels_se3.SINCOS_MAX`)."""
    _legs_from(ph, i, np.sin(ph[i, 1]), np.cos(ph[i, 1]), np.sin(ph[i, 2]), np.cos(ph[i, 2]), np.sin(ph[i, 3]),
               np.cos(ph[i, 3]), k, ab2, a, squared, out)


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_redo_wide(ph, k, ab2, a, squared, out):
    for i in range(ph.shape[0]):
        if abs(ph[i, 1]) > SINCOS_MAX or abs(ph[i, 2]) > SINCOS_MAX or abs(ph[i, 3]) > SINCOS_MAX:
            _legs_pose_libm(ph, i, k, ab2, a, squared, out)


@njit(cache=True, fastmath=_LEGS_FASTMATH, inline="always")
def _legs_step(ph, i, k, ab2, a, squared, out):
    """:func:`_legs_pose`, and whether the pose may hold a NaN or an infinity: ``t - t`` is 0 for
    the finite sum ``t`` of its four numbers (a sum that overflows is flagged too; the caller
    then checks the input itself)."""
    w = _legs_pose(ph, i, k, ab2, a, squared, out)
    t = ph[i, 0] + ph[i, 1] + ph[i, 2] + ph[i, 3]
    return w, 0 if t - t == 0.0 else 1


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_finish(ph, k, ab2, a, squared, out, wide, bad):
    """After the loop: the wide poses again with libm; returns ``bad``."""
    if wide > SINCOS_MAX:
        _legs_redo_wide(ph, k, ab2, a, squared, out)
    return bad


@njit(cache=True, fastmath=_LEGS_FASTMATH)
def _legs_kernel(ph, a, b, squared, out):
    """:func:`_legs_sq_block` pose by pose (compiled: last-bit differences from the NumPy form),
    square roots unless ``squared``; returns the number of poses that hold a NaN or an infinity
    (their legs are not meaningful: the caller raises)."""
    k = 2.0 * a * a + 2.0 * b * b
    ab2 = 2.0 * a * b
    wide = 0.0
    bad = np.int64(0)
    for i in range(ph.shape[0]):
        w, e = _legs_step(ph, i, k, ab2, a, squared, out)
        wide = max(wide, w)
        bad += e
    return _legs_finish(ph, k, ab2, a, squared, out, wide, bad)


@njit(cache=True, fastmath=_LEGS_FASTMATH, parallel=True)
def _legs_kernel_parallel(ph, a, b, squared, out):
    """:func:`_legs_kernel` with the poses shared among the cores (numba's ``prange``): the same
    numbers, pose by pose."""
    k = 2.0 * a * a + 2.0 * b * b
    ab2 = 2.0 * a * b
    wide = 0.0
    bad = np.int64(0)  # (a bare 0 reached _legs_finish as a literal: a second compiled copy)
    for i in prange(ph.shape[0]):
        w, e = _legs_step(ph, i, k, ab2, a, squared, out)
        wide = max(wide, w)
        bad += e
    return _legs_finish(ph, k, ab2, a, squared, out, wide, bad)


def four_sps_cu_legs(flat, a: float, b: float, squared: bool, out, parallel: bool) -> int:
    """Leg lengths (squared if ``squared``) of the poses ``flat`` (n, 4) into ``out`` (n, 4) of
    a 4-SPS/CU platform of half-sides ``a``, ``b``; ``parallel``: shared among the cores.
    Returns the number of poses that hold a NaN or an infinity (the caller raises)."""
    kernel = _legs_kernel_parallel if parallel else _legs_kernel
    return int(kernel(flat, a, b, squared, out))
