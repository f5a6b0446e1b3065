"""Small compiled kernels of the closure engine (:mod:`.engine`): 3-vector and matrix products,
rotation vectors, SE(3) exponential and logarithm, least squares and determinants, on plain
float64 arrays, writing into ``out`` arguments (no allocation in the inner loops)."""

from __future__ import annotations

import numpy as np

from .jit import njit

__all__ = [
    "EPS",
    "SINCOS_MAX",
    "nb_ball_product",
    "nb_ball_product_ws",
    "nb_copy44",
    "nb_cross",
    "nb_det",
    "nb_det_inplace",
    "nb_exp_twist",
    "nb_inverse_into",
    "nb_log",
    "nb_lsq_qr",
    "nb_lstsq",
    "nb_matrix_rotvec",
    "nb_minnorm_normal",
    "nb_minnorm_qr",
    "nb_mm",
    "nb_mm4",
    "nb_mm4c",
    "nb_mv",
    "nb_orthonormal",
    "nb_quat_rotvec",
    "nb_rodrigues",
    "nb_rotvec_matrix",
    "nb_rotvec_matrix3",
    "nb_screw_shift",
    "nb_sincos",
    "nb_skew",
    "nb_svd",
]


# ---------------------------------------------------------------------------- small kernels
@njit(cache=True)
def nb_cross(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def nb_mv(M, v, out):
    for i in range(3):
        out[i] = M[i, 0] * v[0] + M[i, 1] * v[1] + M[i, 2] * v[2]


@njit(cache=True)
def nb_mm(A, B, out):
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]


@njit(cache=True)
def nb_skew(w, out):
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
def nb_rodrigues(w0, w1, w2, s, c, out):
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
def nb_rotvec_matrix3(p0, p1, p2, out):
    """:func:`..geometry.rotations.rotvec_matrix` of the rotation vector ``(p0, p1, p2)``:
    ``I + sin(th) K + (1 - cos(th)) K K`` with ``K = skew(phi / th)``, or ``I + skew(phi)``
    below 1e-12 rad (no temporaries: the retraction calls this for every ball)."""
    th = np.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
    if th < 1e-12:
        s, c, k0, k1, k2 = 1.0, 0.0, p0, p1, p2
    else:
        s, c, k0, k1, k2 = np.sin(th), 1.0 - np.cos(th), p0 / th, p1 / th, p2 / th
    nb_rodrigues(k0, k1, k2, s, c, out)


@njit(cache=True)
def nb_rotvec_matrix(phi, out):
    """:func:`..geometry.rotations.rotvec_matrix`."""
    nb_rotvec_matrix3(phi[0], phi[1], phi[2], out)


@njit(cache=True)
def nb_quat_rotvec(R, out):
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
def nb_matrix_rotvec(R, out):
    """:func:`..geometry.rotations.matrix_rotvec`."""
    c = (R[0, 0] + R[1, 1] + R[2, 2] - 1.0) / 2.0
    if c < -0.999:
        nb_quat_rotvec(R, out)
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
def nb_log(T, fast, out):
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
        if th < 1e-8:  # first order, as closure._log_single
            w0, w1, w2 = 0.5 * w0, 0.5 * w1, 0.5 * w2
            out[0], out[1], out[2] = w0, w1, w2
            out[3] = p0 - 0.5 * (w1 * p2 - w2 * p1)
            out[4] = p1 - 0.5 * (w2 * p0 - w0 * p2)
            out[5] = p2 - 0.5 * (w0 * p1 - w1 * p0)
            return
        f = 1.0 / (2.0 * sn)
        w0, w1, w2 = w0 * f, w1 * f, w2 * f
    else:
        Rc = np.empty((3, 3))
        for i in range(3):
            for j in range(3):
                Rc[i, j] = T[i, j]
        rv = np.empty(3)
        nb_quat_rotvec(Rc, rv)
        th = np.sqrt(rv[0] ** 2 + rv[1] ** 2 + rv[2] ** 2)
        if th < 1e-12:  # first order, as log_transform
            out[0], out[1], out[2] = rv[0], rv[1], rv[2]
            out[3] = p0 - 0.5 * (rv[1] * p2 - rv[2] * p1)
            out[4] = p1 - 0.5 * (rv[2] * p0 - rv[0] * p2)
            out[5] = p2 - 0.5 * (rv[0] * p1 - rv[1] * p0)
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
def nb_inverse_into(T, out):
    for i in range(3):
        for j in range(3):
            out[i, j] = T[j, i]
    for i in range(3):
        out[i, 3] = -(T[0, i] * T[0, 3] + T[1, i] * T[1, 3] + T[2, i] * T[2, 3])
        out[3, i] = 0.0
    out[3, 3] = 1.0


@njit(cache=True)
def nb_copy44(src, dst):
    """``dst[:] = src`` for 4x4 arrays (element loops: numba's slice assignment is slow to compile)."""
    for i in range(4):
        for j in range(4):
            dst[i, j] = src[i, j]


@njit(cache=True)
def nb_mm4(A, B, out):
    for i in range(4):
        for j in range(4):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j] + A[i, 3] * B[3, j]


@njit(cache=True)
def nb_mm4c(A, B, out):
    """``out = A B`` for complex 4x4 matrices (``out`` must not be ``A`` or ``B``)."""
    for a in range(4):
        for b in range(4):
            acc = 0.0j
            for e in range(4):
                acc += A[a, e] * B[e, b]
            out[a, b] = acc


@njit(cache=True)
def nb_screw_shift(w0, w1, w2, v0, v1, v2, t, st, ct):
    """The translation of the screw motion ``exp(t (w ; v))`` for a unit ``w`` (its rotation is
    ``nb_rodrigues(w, st, ct)``, ``st = sin t``, ``ct = 1 - cos t``):
    ``t v + ct (w x v) + (t - st) w x (w x v)``."""
    x0 = w1 * v2 - w2 * v1  # w x v
    x1 = w2 * v0 - w0 * v2
    x2 = w0 * v1 - w1 * v0
    return (t * v0 + ct * x0 + (t - st) * (w1 * x2 - w2 * x1),
            t * v1 + ct * x1 + (t - st) * (w2 * x0 - w0 * x2),
            t * v2 + ct * x2 + (t - st) * (w0 * x1 - w1 * x0))


@njit(cache=True)
def nb_exp_twist(V, out):
    """:func:`..geometry.rotations.exp_twist` of one twist at ``theta = 1`` (no allocation:
    ``W`` the skew matrix of the unit axis ``k``, ``W^2 = k k^T - I``)."""
    wn = np.sqrt(V[0] * V[0] + V[1] * V[1] + V[2] * V[2])
    for i in range(4):
        for j in range(4):
            out[i, j] = 0.0
    out[3, 3] = 1.0
    if wn > 0.0:
        k0, k1, k2 = V[0] / wn, V[1] / wn, V[2] / wn
        u0, u1, u2 = V[3] / wn, V[4] / wn, V[5] / wn
        s = np.sin(wn)
        c = 1.0 - np.cos(wn)
        nb_rodrigues(k0, k1, k2, s, c, out)  # out[:3, :3] = I + s W + c W^2
        out[0, 3], out[1, 3], out[2, 3] = nb_screw_shift(k0, k1, k2, u0, u1, u2, wn, s, c)
    else:
        for i in range(3):
            out[i, i] = 1.0
            out[i, 3] = V[3 + i]


EPS = float(np.finfo(np.float64).eps)

# pi/2 in three parts (Cody-Waite): k * PIO2_1 is exact for |k| < 2^20, the others carry the rest
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_3 = 2.02226624879595063154e-21
_TWO_OVER_PI = 6.36619772367581382433e-01
#: Largest |x| for :func:`nb_sincos` (2^20 quarter turns); callers take libm's sine beyond it.
SINCOS_MAX = 1.6e6


@njit(cache=True, inline="always")
def nb_sincos(x):
    """``(sin x, cos x)`` without a libm call, so that a loop over poses vectorises (PyPI's
    llvmlite has no vector math library): ``x`` is reduced to ``|r| <= pi/4`` by the nearest
    quarter turn ``k`` (pi/2 in three parts), then Taylor polynomials of degree 15 and 18 (their
    truncation error is below 1e-17 there) and the quadrant's swap and signs, as selects.  Within
    1 ulp of libm's values for ``|x| <= SINCOS_MAX`` (tested); beyond it the reduction loses
    digits and callers use ``np.sin``.  Inlined into the caller, whose fastmath flags must not
    reassociate (:data:`.jit.SAFE_FASTMATH`)."""
    k = np.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * _PIO2_1) - k * _PIO2_2) - k * _PIO2_3
    z = r * r
    sr = r + r * z * (-1.0 / 6.0 + z * (1.0 / 120.0 + z * (-1.0 / 5040.0 + z * (1.0 / 362880.0 + z * (
        -1.0 / 39916800.0 + z * (1.0 / 6227020800.0 + z * (-1.0 / 1307674368000.0)))))))
    cr = 1.0 + z * (-0.5 + z * (1.0 / 24.0 + z * (-1.0 / 720.0 + z * (1.0 / 40320.0 + z * (-1.0 / 3628800.0 + z * (
        1.0 / 479001600.0 + z * (-1.0 / 87178291200.0 + z * (1.0 / 20922789888000.0))))))))
    q = np.int64(k) & 3
    s = cr if (q & 1) else sr
    c = sr if (q & 1) else cr
    s = -s if (q & 2) else s
    c = -c if ((q + 1) & 2) else c
    return s, c



@njit(cache=True)
def nb_svd(A):
    """``np.linalg.svd(A, full_matrices=False)``: the one LAPACK routine the kernels use (each
    distinct numba linalg call adds seconds to the first compilation)."""
    return np.linalg.svd(A, full_matrices=False)


@njit(cache=True)
def nb_minnorm_normal(A, b, x):
    """Minimum-norm solution of the underdetermined ``A x = b`` (m <= n) by the normal equations
    ``A A^T y = b``, ``x = A^T y``, with one step of iterative refinement of ``y`` (the corrected
    semi-normal equations: accurate to about ``cond(A) eps`` at the conditioning accepted here).
    ``A A^T`` is summed column by column over each column's nonzero rows (a closure Jacobian's
    limb columns touch only their limb's rows), and factored ``U^T U`` by a right-looking
    Cholesky whose updates are contiguous row operations.  ``False`` (x untouched) when a pivot
    ``U[j, j]`` is below 1e-4 times the largest, i.e. ``cond(A)`` may exceed about 1e4: the
    squared conditioning would cost digits, and the QR or the SVD must decide."""
    m, n = A.shape
    rows = np.empty((n, m), dtype=np.int64)
    cnt = np.zeros(n, dtype=np.int64)
    for i in range(m):
        for c in range(n):
            if A[i, c] != 0.0:
                rows[c, cnt[c]] = i
                cnt[c] += 1
    U = np.zeros((m, m))  # upper triangle: U[j, i] = (A A^T)[j, i], i >= j
    for c in range(n):
        for a in range(cnt[c]):
            j = rows[c, a]
            v = A[j, c]
            for e in range(a, cnt[c]):
                i = rows[c, e]
                U[j, i] += v * A[i, c]
    big = 0.0
    for j in range(m):
        big = max(big, U[j, j])
    if not big > 0.0:
        return False
    for j in range(m):  # right-looking Cholesky A A^T = U^T U, in place
        d = U[j, j]
        if not d > 1e-8 * big:  # pivot^2 below (1e-4)^2 of the largest diagonal
            return False
        d = np.sqrt(d)
        U[j, j] = d
        for i in range(j + 1, m):
            U[j, i] /= d
        for k in range(j + 1, m):
            u = U[j, k]
            if u != 0.0:
                for i in range(k, m):
                    U[k, i] -= u * U[j, i]
    y = np.zeros(m)
    z = b.copy()
    xs = np.zeros(n)
    for sweep in range(2):
        for k in range(m):  # U^T w = z (forward, in place)
            z[k] /= U[k, k]
            wk = z[k]
            for i in range(k + 1, m):
                z[i] -= U[k, i] * wk
        for i in range(m - 1, -1, -1):  # U dy = w (backward, in place)
            acc = z[i]
            for k in range(i + 1, m):
                acc -= U[i, k] * z[k]
            z[i] = acc / U[i, i]
        for i in range(m):
            y[i] += z[i]
        for c in range(n):
            acc = 0.0
            for a in range(cnt[c]):
                i = rows[c, a]
                acc += A[i, c] * y[i]
            xs[c] = acc
        if sweep == 0:  # the residual of A x = b, for the refinement
            for i in range(m):
                z[i] = b[i]
            for c in range(n):
                v = xs[c]
                for a in range(cnt[c]):
                    i = rows[c, a]
                    z[i] -= A[i, c] * v
    for c in range(n):
        x[c] = xs[c]
    return True


@njit(cache=True)
def nb_minnorm_qr(A, b, x):
    """Minimum-norm solution of the underdetermined ``A x = b`` (m <= n) by Householder QR of
    ``A^T`` into ``x``; ``False`` (x untouched) when a diagonal entry of R is below 1e-8 times the
    largest, i.e. ``A`` may be rank deficient and the SVD must decide."""
    m, n = A.shape
    M = np.empty((n, m))
    for i in range(m):
        for j in range(n):
            M[j, i] = A[i, j]
    V = np.zeros((m, n))
    d = np.empty(m)
    for j in range(m):
        nrm = 0.0
        for i in range(j, n):
            nrm += M[i, j] * M[i, j]
        nrm = np.sqrt(nrm)
        alpha = -nrm if M[j, j] >= 0.0 else nrm
        vn = 0.0
        for i in range(j, n):
            V[j, i] = M[i, j]
        V[j, j] -= alpha
        for i in range(j, n):
            vn += V[j, i] * V[j, i]
        vn = np.sqrt(vn)
        d[j] = alpha
        if vn > 0.0:
            for i in range(j, n):
                V[j, i] /= vn
            for c in range(j + 1, m):
                dot = 0.0
                for i in range(j, n):
                    dot += V[j, i] * M[i, c]
                for i in range(j, n):
                    M[i, c] -= 2.0 * dot * V[j, i]
    big = 0.0
    for j in range(m):
        big = max(big, abs(d[j]))
    for j in range(m):
        if not abs(d[j]) > 1e-8 * big:
            return False
    # R^T y = b (R upper triangular: R[j, j] = d[j], R[j, c] = M[j, c] for c > j)
    z = np.zeros(n)
    for j in range(m):
        acc = b[j]
        for k in range(j):
            acc -= M[k, j] * z[k]
        z[j] = acc / d[j]
    # x = H_0 H_1 ... H_{m-1} z
    for j in range(m - 1, -1, -1):
        dot = 0.0
        for i in range(j, n):
            dot += V[j, i] * z[i]
        for i in range(j, n):
            z[i] -= 2.0 * dot * V[j, i]
    for i in range(n):
        x[i] = z[i]
    return True


@njit(cache=True)
def nb_lsq_qr(A, b, x):
    """Least-squares solution of the overdetermined ``A x = b`` (m >= n) by Householder QR of
    ``A`` into ``x``; ``False`` (x untouched) when a diagonal entry of R is below 1e-8 times the
    largest (``A`` may be rank deficient: the SVD must decide).  Used by the limb Gauss-Newton,
    whose small systems (6 rows, at most 6 columns) are full rank away from singularities."""
    m, n = A.shape
    M = A.copy()
    y = b.copy()
    d = np.empty(n)
    v = np.empty(m)
    for j in range(n):
        nrm = 0.0
        for i in range(j, m):
            nrm += M[i, j] * M[i, j]
        nrm = np.sqrt(nrm)
        alpha = -nrm if M[j, j] >= 0.0 else nrm
        for i in range(j, m):
            v[i] = M[i, j]
        v[j] -= alpha
        vn = 0.0
        for i in range(j, m):
            vn += v[i] * v[i]
        vn = np.sqrt(vn)
        d[j] = alpha
        if vn > 0.0:
            for i in range(j, m):
                v[i] /= vn
            for c in range(j + 1, n):
                dot = 0.0
                for i in range(j, m):
                    dot += v[i] * M[i, c]
                for i in range(j, m):
                    M[i, c] -= 2.0 * dot * v[i]
            dot = 0.0
            for i in range(j, m):
                dot += v[i] * y[i]
            for i in range(j, m):
                y[i] -= 2.0 * dot * v[i]
    big = 0.0
    for j in range(n):
        big = max(big, abs(d[j]))
    for j in range(n):
        if not abs(d[j]) > 1e-8 * big:
            return False
    for j in range(n - 1, -1, -1):  # R x = (Q^T b)[:n]
        acc = y[j]
        for c in range(j + 1, n):
            acc -= M[j, c] * x[c]
        x[j] = acc / d[j]
    return True


@njit(cache=True)
def nb_lstsq(A, b):
    """Minimum-norm least squares, as ``np.linalg.lstsq(A, b, rcond=None)``: singular values at
    or below ``eps max(m, n)`` times the largest count as zero.  A well-conditioned
    underdetermined system is solved by QR of ``A^T`` (the same minimum-norm solution to
    rounding, several times faster than the SVD); everything else by the SVD.  (QR of an
    overdetermined system was tried and dropped: on near-degenerate systems such as the Bennett
    linkage's its solutions moved the converged forward position by 1e-10 against the Python
    reference.)"""
    m, n = A.shape
    x = np.zeros(n)
    if m == 0 or n == 0:
        return x
    if m <= n and (nb_minnorm_normal(A, b, x) or nb_minnorm_qr(A, b, x)):
        return x
    U, s, Vt = nb_svd(A)
    cut = EPS * max(m, n) * s[0]
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
def nb_det(M):
    """Determinant by LU with partial pivoting (LAPACK getrf's pivoting, as ``np.linalg.det``)."""
    return nb_det_inplace(M.copy())


@njit(cache=True)
def nb_det_inplace(A):
    """:func:`nb_det` overwriting ``A`` with its elimination (no copy: for a caller that builds
    the matrix in scratch anyway)."""
    n = A.shape[0]
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
def nb_orthonormal(D, W):
    """Keep the rotation of ``D`` orthonormal (the nearest rotation, ``U Vt`` of its SVD), in
    place; scratch in ``W`` (2, 3, 3).  A product of rotations drifts from orthonormal only by
    rounding: then two steps of the Bjorck iteration ``R <- R (3 I - R^T R) / 2`` give the same
    polar factor (the error is squared each step) without the SVD; a drift above 1e-6 takes the
    SVD."""
    R = W[0]
    G = W[1]
    for i in range(3):
        for j in range(3):
            R[i, j] = D[i, j]
    drift = 0.0
    for sweep in range(2):
        for i in range(3):
            for j in range(3):
                G[i, j] = R[0, i] * R[0, j] + R[1, i] * R[1, j] + R[2, i] * R[2, j]
                if sweep == 0:
                    drift = max(drift, abs(G[i, j] - (1.0 if i == j else 0.0)))
        if sweep == 0 and not drift < 1e-6:
            U, _, Vt = nb_svd(R)
            for i in range(3):
                for j in range(3):
                    D[i, j] = U[i, 0] * Vt[0, j] + U[i, 1] * Vt[1, j] + U[i, 2] * Vt[2, j]
            return
        for i in range(3):
            for j in range(3):
                G[i, j] = (3.0 if i == j else 0.0) - G[i, j]
        for i in range(3):
            r0, r1, r2 = R[i, 0], R[i, 1], R[i, 2]
            for j in range(3):
                R[i, j] = 0.5 * (r0 * G[0, j] + r1 * G[1, j] + r2 * G[2, j])
    for i in range(3):
        for j in range(3):
            D[i, j] = R[i, j]


@njit(cache=True)
def nb_ball_product(A, u, v, invert_v, quat, out):
    """Freedom coordinates (``A^T`` rotation vector) of ``R(A u) R(A v)``, or of
    ``R(A u) R(A v)^T`` when ``invert_v``, for an S joint with axes ``A`` (columns): how a step
    ``u`` composes with the joint's rotation ``v`` (retraction) or how far ``u`` is from ``v``
    (difference).  ``quat``: the matrix -> rotation vector conversion by quaternion (as
    :func:`scipy.spatial.transform.Rotation.as_rotvec`) rather than by the matrix logarithm; each
    caller keeps the conversion of the Python code it mirrors."""
    nb_ball_product_ws(A, u, v, invert_v, quat, out, np.empty((4, 3, 3)))


@njit(cache=True)
def nb_ball_product_ws(A, u, v, invert_v, quat, out, work):
    """:func:`nb_ball_product` with its scratch matrices in ``work`` (4, 3, 3): a caller that
    composes many balls allocates them once."""
    Ra = work[0]
    Rb = work[1]
    Rn = work[2]
    rv = work[3, 0]
    nb_rotvec_matrix3(A[0, 0] * u[0] + A[0, 1] * u[1] + A[0, 2] * u[2],
                      A[1, 0] * u[0] + A[1, 1] * u[1] + A[1, 2] * u[2],
                      A[2, 0] * u[0] + A[2, 1] * u[1] + A[2, 2] * u[2], Ra)
    nb_rotvec_matrix3(A[0, 0] * v[0] + A[0, 1] * v[1] + A[0, 2] * v[2],
                      A[1, 0] * v[0] + A[1, 1] * v[1] + A[1, 2] * v[2],
                      A[2, 0] * v[0] + A[2, 1] * v[1] + A[2, 2] * v[2], Rb)
    if invert_v:
        for x in range(3):
            for y in range(3):
                Rn[x, y] = Ra[x, 0] * Rb[y, 0] + Ra[x, 1] * Rb[y, 1] + Ra[x, 2] * Rb[y, 2]
    else:
        nb_mm(Ra, Rb, Rn)
    if quat:
        nb_quat_rotvec(Rn, rv)
    else:
        nb_matrix_rotvec(Rn, rv)
    for x in range(3):
        out[x] = A[0, x] * rv[0] + A[1, x] * rv[1] + A[2, x] * rv[2]
