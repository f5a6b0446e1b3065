"""Forward position of a 3-PRS platform by elimination: a univariate polynomial of degree 16
(issue 27), an independent check of the homotopy's proven-complete set.

Each P-R-S limb (an actuated slide, a revolute, a ball on the platform) keeps its ball centre
``A_i`` on a circle: in the plane through the slider's foot ``f_i(v)`` normal to the R axis
``n_i``, at the distance ``rho_i`` of the centre from that axis:
``A_i = f_i(v) + rho_i (cos th_i u_i + sin th_i w_i)`` (``u_i, w_i`` an orthonormal basis of the
plane, turned by a fixed angle so that no symmetric configuration falls on ``th = pi``).  The
platform is rigid: ``|A_i - A_j|^2 = d_ij^2`` for the three pairs.  With ``t_i = tan(th_i / 2)``
each is a polynomial of bidegree (2, 2) in ``(t_i, t_j)``; eliminating ``t_3`` (a Sylvester
resultant: bidegree (4, 4) in ``(t_1, t_2)``), then ``t_2``, leaves one polynomial in ``t_1`` of
degree ``2 * 4 + 2 * 4 = 16``: the published count of the 3-RPS / 3-PRS (Tsai).  Its
coefficients are interpolated at roots of unity (determinants evaluated there, an inverse DFT),
its roots found as the eigenvalues of the companion matrix (``numpy.roots``); each root gives
``t_2`` and ``t_3`` by back-substitution and the three centres give the platform pose (the
proper rotation carrying the reference centres onto them).  A root at ``t = infinity`` (a
degree drop) is counted apart.

Not registered as the forward closed form under ``method="auto"``: the homotopy answers the
3-PRS, proves its set complete and lifts every solution to all joints; this module is its
cross-check (tests/test_fk_families.py, the same 16 complex solutions and the same real poses).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...model.mechanism import Mechanism, Pose

__all__ = ["PrsForward", "prs_forward"]

#: The change from ``(cos, sin, 1)`` to the half-angle basis ``(1, t, t^2)`` (times ``1 + t^2``).
_P = np.array([[1.0, 0.0, -1.0], [0.0, 2.0, 0.0], [1.0, 0.0, 1.0]])


@dataclass(frozen=True, eq=False)
class PrsForward:
    """The forward position by elimination: ``poses`` the real platform poses, ``n_real``,
    ``n_complex`` (the other roots of the degree-16 polynomial), ``n_at_infinity`` (its degree
    drop), ``residual`` the largest nondimensional error of the limb conditions at the real
    solutions, ``statement`` how the count is proven."""

    poses: tuple[Pose, ...]
    n_real: int
    n_complex: int
    n_at_infinity: int
    residual: float
    statement: str


def _limbs(mech: Mechanism) -> list[tuple]:
    """Per limb: ``(foot at the reference, slide direction, actuator index, offset, rho, u, w,
    platform centre at the reference)``; ``InputError`` unless three P-R-S limbs to the platform."""
    if mech.bodies or len(mech.limbs) != 3:
        raise InputError(f"model: {mech.name} is not a 3-PRS (three P-R-S limbs from the ground to the platform)")
    acts = list(mech.actuators)
    out = []
    for k, limb in enumerate(mech.limbs):
        if [j.type for j in limb.joints] != ["P", "R", "S"]:
            raise InputError(f"model: limb {limb.name} of {mech.name} is not P-R-S")
        sl, rj, sj = limb.joints[0].freedoms[0], limb.joints[1].freedoms[0], limb.joints[2]
        name = f"{limb.joints[0].name}.{sl.name}"
        ids = [mech.freedom(a).id for a in acts]
        if not sl.actuated or name not in ids:
            raise InputError(f"model: the slide of limb {limb.name} of {mech.name} is not an actuator")
        n = rj.direction / np.linalg.norm(rj.direction)
        f = rj.point + float((sj.point - rj.point) @ n) * n
        rho = float(np.linalg.norm(sj.point - f))
        if rho < 1e-9 * mech.characteristic_length:
            raise InputError(f"model: the S centre of limb {limb.name} is on its R axis")
        u0 = (sj.point - f) / rho
        w0 = np.cross(n, u0)
        a = 0.7 + 0.9 * k  # a fixed turn of the angle origin: th = pi is then no symmetric configuration
        u, w = np.cos(a) * u0 + np.sin(a) * w0, -np.sin(a) * u0 + np.cos(a) * w0
        out.append((f, sl.direction / np.linalg.norm(sl.direction), ids.index(name), sl.offset, rho, u, w, sj.point))
    return out


def _pair(li, lj, fi, fj, d2: float, L: float) -> np.ndarray:
    """``C`` (3, 3): ``(|A_i - A_j|^2 - d^2) (1 + t_i^2)(1 + t_j^2) / L^2 = sum C[a, b] t_i^a t_j^b``."""
    _, _, _, _, ri, ui, wi, _ = li
    _, _, _, _, rj, uj, wj, _ = lj
    g = fi - fj
    Vi, Vj = np.array([ri * ui, ri * wi, np.zeros(3)]), np.array([rj * uj, rj * wj, np.zeros(3)])
    M = -2.0 * Vi @ Vj.T  # (c_i, s_i, 1) x (c_j, s_j, 1)
    M[:2, 2] += 2.0 * Vi[:2] @ g
    M[2, :2] -= 2.0 * Vj[:2] @ g
    M[2, 2] += g @ g + ri * ri + rj * rj - d2
    return _P.T @ M @ _P / (L * L)


def _poly_y(C: np.ndarray, x: complex) -> np.ndarray:
    """Coefficients (in ``y``, lowest first) of ``sum C[a, b] x^a y^b``."""
    return np.array([1.0, x, x * x]) @ C


def _sylvester_det(p: np.ndarray, q: np.ndarray) -> complex:
    """The resultant of two polynomials (coefficients lowest first) by Sylvester's determinant."""
    m, n = len(p) - 1, len(q) - 1
    S = np.zeros((m + n, m + n), dtype=complex)
    for r in range(n):
        S[r, r : r + m + 1] = p[::-1]
    for r in range(m):
        S[n + r, r : r + n + 1] = q[::-1]
    return complex(np.linalg.det(S))


def _interpolate(fun, degree: int) -> np.ndarray:
    """Coefficients (lowest first) of a polynomial of at most ``degree`` from its values at the
    ``degree + 1`` roots of unity (an inverse DFT)."""
    z = np.exp(2j * np.pi * np.arange(degree + 1) / (degree + 1))
    return np.fft.fft(np.array([fun(v) for v in z])) / (degree + 1)


def prs_forward(mech: Mechanism, values) -> PrsForward:
    """Every forward-position solution of a 3-PRS (three P-R-S limbs, the slides actuated) at the
    actuator values ``values`` (model units, ``mech.actuators`` order), by the degree-16
    elimination of the module docstring.  ``InputError`` for another model."""
    limbs = _limbs(mech)
    v = np.asarray(values, dtype=float).ravel()
    if v.size != 3:
        raise InputError(f"values: expected 3 slide values, got {v.size}")
    L = mech.characteristic_length
    feet = [f + (v[k] - off) * s for f, s, k, off, *_ in limbs]
    b = [lb[7] for lb in limbs]
    C12 = _pair(limbs[0], limbs[1], feet[0], feet[1], float(np.sum((b[0] - b[1]) ** 2)), L)
    C23 = _pair(limbs[1], limbs[2], feet[1], feet[2], float(np.sum((b[1] - b[2]) ** 2)), L)
    C31 = _pair(limbs[2], limbs[0], feet[2], feet[0], float(np.sum((b[2] - b[0]) ** 2)), L)

    def r_t2(t1: complex, t2: complex) -> complex:  # t3 eliminated from E23(t2, t3) and E31(t3, t1)
        return _sylvester_det(_poly_y(C23, t2), _poly_y(C31.T, t1))

    def f_t1(t1: complex) -> complex:  # then t2 from E12(t1, t2) and R(t1, t2)
        return _sylvester_det(_poly_y(C12, t1), _interpolate(lambda t2: r_t2(t1, t2), 4))

    coef = _interpolate(f_t1, 16)
    scale = np.abs(coef).max()
    nz = np.flatnonzero(np.abs(coef) > 1e-12 * scale)
    deg = int(nz[-1]) if nz.size else 0
    roots = np.roots(coef[: deg + 1][::-1]) if deg > 0 else np.zeros(0, complex)
    poses: list[Pose] = []
    res, n_real = 0.0, 0
    for t1 in roots:
        c2 = np.roots(_poly_y(C12, t1)[::-1])
        rt = _interpolate(lambda y, t1=t1: r_t2(t1, y), 4)[::-1]
        # each candidate judged on the projective line (|q(y)| / (1 + |y|)^deg): a raw |q(y)|
        # grows as |y|^deg and passed over the right partner near a half turn (t2 = 498)
        t2 = c2[np.argmin([abs(np.polyval(rt, y)) / (1.0 + abs(y)) ** 4 for y in c2])]
        c3 = np.roots(_poly_y(C31.T, t1)[::-1])
        t3 = c3[np.argmin([abs(np.polyval(_poly_y(C23, t2)[::-1], y)) / (1.0 + abs(y)) ** 2 for y in c3])]
        t = _polish(np.array([t1, t2, t3], dtype=complex), (C12, C23, C31))
        if np.abs(t.imag).max() > 1e-9 * (1.0 + np.abs(t).max()):
            continue
        t = _polish(t.real, (C12, C23, C31))
        th = 2.0 * np.arctan(t)
        A = np.array([feet[k] + lb[4] * (np.cos(th[k]) * lb[5] + np.sin(th[k]) * lb[6]) for k, lb in enumerate(limbs)])
        R, p = _rigid(np.array(b), A)
        err = max(float(abs(np.linalg.norm(A[i] - A[j]) - np.linalg.norm(b[i] - b[j])))
                  for i, j in ((0, 1), (1, 2), (2, 0)))
        res = max(res, err / L)
        poses.append(Pose(R, R @ mech.platform_point + p, f"mode {len(poses) + 1}"))
        n_real += 1
    n_inf = 16 - deg
    statement = (f"univariate elimination (two Sylvester resultants of the three rigid-distance conditions in the "
                 f"half-angle tangents): a polynomial of degree 16 in t1, the published bound, whose roots are every "
                 f"solution with finite tangents; {n_real} real, "
                 f"{deg - n_real} complex" + (f", {n_inf} at infinity (degree drop)" if n_inf else ""))
    return PrsForward(tuple(poses), n_real, deg - n_real, n_inf, float(res), statement)


def _polish(t: np.ndarray, Cs: tuple, steps: int = 6) -> np.ndarray:
    """A few Newton steps on the three pair conditions (complex or real ``t``): the polynomial's
    roots carry its conditioning (1e-8 to 1e-6 here, a real root of size 5 can come out with an
    imaginary part of 1e-6); after them the residual is rounding and a real root is real.

    A tangent larger than 1 (an angle past +-90 deg) is polished as u = -1/t, the tangent of the
    half-angle measured from the other side: near a half turn t runs to infinity and Newton in t
    jumps to another root (a root t1 = -790 went to 64), while u stays small."""
    pairs = ((0, 1), (1, 2), (2, 0))
    flip = np.abs(t) > 1.0
    z = np.where(flip, -1.0 / np.where(flip, t, 1.0), t)

    def basis(k: int) -> tuple[np.ndarray, np.ndarray]:  # (1, t, t^2) up to a factor, d/dz
        if flip[k]:
            return np.array([z[k] ** 2, -z[k], 1.0]), np.array([2.0 * z[k], -1.0, 0.0])
        return np.array([1.0, z[k], z[k] ** 2]), np.array([0.0, 1.0, 2.0 * z[k]])

    for _ in range(steps):
        F, J = np.zeros(3, dtype=z.dtype), np.zeros((3, 3), dtype=z.dtype)
        for r, ((i, j), C) in enumerate(zip(pairs, Cs, strict=True)):
            (xi, di), (xj, dj) = basis(i), basis(j)
            F[r] = xi @ C @ xj
            J[r, i] = di @ C @ xj
            J[r, j] = xi @ C @ dj
        try:
            z = z - np.linalg.solve(J, F)
        except np.linalg.LinAlgError:  # a singular root: keep the polynomial's value
            break
    out = z.copy()
    with np.errstate(divide="ignore", invalid="ignore"):  # u = 0 is an exact half turn: t infinite
        out[flip] = -1.0 / z[flip]
    return out


def _rigid(b: np.ndarray, A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The proper rigid motion ``A_i = R b_i + p`` of three points (their triangles congruent):
    orthonormal frames of both triangles, the normal by the cross product (no SVD sign)."""

    def frame(P):
        e1 = (P[1] - P[0]) / np.linalg.norm(P[1] - P[0])
        e3 = np.cross(P[1] - P[0], P[2] - P[0])
        e3 /= np.linalg.norm(e3)
        return np.column_stack([e1, np.cross(e3, e1), e3])

    R = frame(A) @ frame(b).T
    return R, A[0] - R @ b[0]
