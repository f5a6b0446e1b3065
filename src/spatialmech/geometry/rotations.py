"""Rotations and rigid displacements.

Euler angles are always given with an explicitly named sequence, following
``scipy.spatial.transform.Rotation``: UPPER-CASE letters are *intrinsic* (rotations about the
moving axes), lower-case letters *extrinsic* (about the fixed axes).  ``"ZXY"`` is therefore
``Rz(a) Rx(b) Ry(c)`` as a matrix product.  The papers use:

- paper A (5-CS), table 9: ``A = Rz(gamma) Rx(alpha) Ry(beta)`` -> ``"ZXY"`` with angles
  ``(gamma, alpha, beta)``;
- paper B (4-SPS/CU): ``T = Rz(gamma) Ry(beta) Rx(alpha)`` -> ``"ZYX"``, ``(gamma, beta, alpha)``;
- paper C (3-RRR): ``R = Ry(beta) Rx(alpha) Rz(gamma)`` -> ``"YXZ"``, ``(beta, alpha, gamma)``.

Rigid displacements are 4x4 homogeneous matrices; twists use the screw convention of
:mod:`spatialmech.geometry.screws` (``(omega ; v)`` with ``v`` the velocity of the point at
the origin, i.e. the moment ``r x omega``).
"""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from .validate import as_finite_array

__all__ = [
    "check_sequence",
    "euler_matrix",
    "exp_twist",
    "inverse_transform",
    "log_transform",
    "matrix_euler",
    "matrix_rotvec",
    "nearest_rotation",
    "rotation_angle",
    "rotation_class",
    "rotvec_matrix",
    "skew",
    "transform",
]

_AXES = set("xyzXYZ")

if TYPE_CHECKING:
    from scipy.spatial.transform import Rotation as _RotationType


def rotation_class() -> type[_RotationType]:
    """``scipy.spatial.transform.Rotation``, imported on first use: ``scipy.spatial`` costs about
    half a second (k-d trees, Qhull, distances), which ``import spatialmech`` and the command
    line's start-up should not pay.  Modules use ``rotation_class().from_matrix(...)``, never a
    module-level ``from scipy.spatial.transform import Rotation`` (tests/test_startup.py)."""
    from scipy.spatial.transform import Rotation

    return Rotation


def check_sequence(seq: str) -> str:
    """Validate an Euler sequence name such as ``"ZXY"`` (intrinsic) or ``"zxy"`` (extrinsic)."""
    if not isinstance(seq, str) or len(seq) != 3 or not set(seq) <= _AXES:
        raise InputError(
            f"seq: expected three axis letters such as 'ZXY' (intrinsic) or 'zxy' (extrinsic), got {seq!r}"
        )
    if not (seq.isupper() or seq.islower()):
        raise InputError(f"seq: mixes intrinsic and extrinsic letters: {seq!r}")
    if seq[0].lower() == seq[1].lower() or seq[1].lower() == seq[2].lower():
        raise InputError(f"seq: consecutive axes must differ, got {seq!r}")
    return seq


def euler_matrix(seq: str, angles, *, degrees: bool = False) -> np.ndarray:
    """Rotation matrix (or stack) from Euler ``angles`` (..., 3) in the named sequence."""
    check_sequence(seq)
    a = as_finite_array(angles, "angles")
    if a.shape[-1:] != (3,):
        raise InputError(f"angles: expected shape (..., 3), got {a.shape}")
    flat = a.reshape(-1, 3)
    R = rotation_class().from_euler(seq, flat, degrees=degrees).as_matrix()
    return R.reshape((*a.shape[:-1], 3, 3))


def matrix_euler(seq: str, R, *, degrees: bool = False) -> np.ndarray:
    """Euler angles of a rotation matrix (or stack) in the named sequence.

    At gimbal lock (the middle angle at +-90 degrees for a Tait-Bryan sequence, 0 or 180 for a
    proper Euler one) only the sum or difference of the outer angles is defined: the third is
    set to zero (scipy's convention) and the angles still give back the matrix.  That is a
    property of the sequence, not a failure, so scipy's warning is not passed on (a command
    that prints a locked pose would show it among its lines)."""
    check_sequence(seq)
    R = as_finite_array(R, "R")
    flat = R.reshape(-1, 3, 3)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Gimbal lock detected")
        a = rotation_class().from_matrix(flat).as_euler(seq, degrees=degrees)
    return a.reshape((*R.shape[:-2], 3))


def skew(v) -> np.ndarray:
    """The 3x3 cross-product matrix ``[v]x`` (stacks allowed)."""
    v = np.asarray(v, dtype=float)
    if v.ndim == 1:  # fast path for one vector
        x, y, z = v
        return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    z = np.zeros(v.shape[:-1])
    return np.stack(
        [
            np.stack([z, -v[..., 2], v[..., 1]], -1),
            np.stack([v[..., 2], z, -v[..., 0]], -1),
            np.stack([-v[..., 1], v[..., 0], z], -1),
        ],
        -2,
    )


def transform(R, p) -> np.ndarray:
    """4x4 displacement from a rotation matrix and a translation (stacks allowed)."""
    R = np.asarray(R, dtype=float)
    p = np.asarray(p, dtype=float)
    shape = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    T = np.zeros((*shape, 4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def inverse_transform(T) -> np.ndarray:
    """Inverse of a rigid displacement without a general matrix inverse."""
    T = np.asarray(T, dtype=float)
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    return transform(Rt, -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3]))


def exp_twist(screw, theta) -> np.ndarray:
    """``exp([$] theta)``: the displacement produced by moving ``theta`` along screw ``$``.

    Closed form (Rodrigues / Modern Robotics eq. 3.88) for unit-direction screws, and pure
    translation when the direction part is zero.  Broadcasts over leading axes of ``screw``
    and ``theta``.
    """
    S = np.asarray(screw, dtype=float)
    th = np.asarray(theta, dtype=float)
    shape = np.broadcast_shapes(S.shape[:-1], th.shape)
    S = np.broadcast_to(S, (*shape, 6))
    th = np.broadcast_to(th, shape)
    w = S[..., :3]
    v = S[..., 3:]
    wn = np.linalg.norm(w, axis=-1)
    rot = wn > 0.0  # Rodrigues is exact for small angles: only a zero rotation is a translation
    # scale screws so that |w| = 1 where rotational; theta absorbs the magnitude
    ws = np.where(rot[..., None], w / np.where(rot, wn, 1.0)[..., None], 0.0)
    vs = np.where(rot[..., None], v / np.where(rot, wn, 1.0)[..., None], v)
    t = np.where(rot, th * wn, th)
    W = skew(ws)
    W2 = W @ W
    s = np.sin(t)[..., None, None]
    c = (1.0 - np.cos(t))[..., None, None]
    eye = np.eye(3)
    R = eye + s * W + c * W2
    G = t[..., None, None] * eye + c * W + (t[..., None, None] - s) * W2
    p = np.einsum("...ij,...j->...i", G, vs)
    return transform(R, p)


def log_transform(T) -> np.ndarray:
    """The twist ``xi`` (6,) with ``exp_twist(xi, 1) = T``, rotation angle in ``[0, pi]``."""
    T = np.asarray(T, dtype=float)
    flat = T.reshape(-1, 4, 4)
    rv = rotation_class().from_matrix(flat[:, :3, :3]).as_rotvec()
    th = np.linalg.norm(rv, axis=-1)
    out = np.zeros((flat.shape[0], 6))
    for i in range(flat.shape[0]):
        p = flat[i, :3, 3]
        if th[i] < 1e-12:  # first order: a rotation this small is still one (G^-1 p = p - w x p / 2)
            out[i] = np.concatenate([rv[i], p - 0.5 * np.cross(rv[i], p)])
            continue
        w = rv[i] / th[i]
        W = skew(w)
        t = th[i]
        Ginv = np.eye(3) / t - 0.5 * W + (1.0 / t - 0.5 / np.tan(t / 2.0)) * (W @ W)
        out[i] = np.concatenate([w, Ginv @ p]) * t
    return out.reshape((*T.shape[:-2], 6))


def rotvec_matrix(phi) -> np.ndarray:
    """Rotation matrix of one rotation vector (Rodrigues), without scipy's per-call overhead."""
    phi = np.asarray(phi, dtype=float)
    th = float(np.sqrt(phi @ phi))
    if th < 1e-12:
        return np.eye(3) + skew(phi)
    K = skew(phi / th)
    return np.eye(3) + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)


def matrix_rotvec(R) -> np.ndarray:
    """Rotation vector (angle in [0, pi]) of one rotation matrix."""
    R = np.asarray(R, dtype=float)
    c = (np.trace(R) - 1.0) / 2.0
    if c < -0.999:  # near a half turn: scipy's robust branch
        return rotation_class().from_matrix(R).as_rotvec()
    w = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    sn = 0.5 * float(np.sqrt(w @ w))
    th = float(np.arctan2(sn, c))
    if th < 1e-12:
        return 0.5 * w
    return w * (th / (2.0 * sn))


def rotation_angle(R) -> np.ndarray:
    """Rotation angle in ``[0, pi]`` of a rotation matrix (stacks allowed)."""
    R = np.asarray(R, dtype=float)
    return np.linalg.norm(rotation_class().from_matrix(R.reshape(-1, 3, 3)).as_rotvec(), axis=-1).reshape(
        R.shape[:-2]
    )


def nearest_rotation(M, *, name: str = "R") -> np.ndarray:
    """The rotation nearest to a 3x3 matrix ``M`` with positive determinant (in the Frobenius
    norm: its orthogonal polar factor), by Newton's iteration ``X <- (X + X^-T) / 2`` (Higham
    1986), which converges quadratically and needs no SVD (so no singular vector's sign enters).
    Meant for a matrix that is a rotation up to rounding (a pose typed with a few decimals).

    >>> R = nearest_rotation([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.000001]])
    >>> bool(np.allclose(R, [[0, -1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15))
    True
    """
    X = as_finite_array(M, name, shape=(3, 3))
    if not np.linalg.det(X) > 0:
        raise InputError(f"{name}: a rotation needs a positive determinant, got {np.linalg.det(X):.3g}")
    for _ in range(60):
        Y = 0.5 * (X + np.linalg.inv(X).T)
        done = np.max(np.abs(Y - X)) <= 1e-15
        X = Y
        if done:
            return X
    raise InputError(f"{name}: the nearest rotation did not converge (is the matrix far from a rotation?)")
