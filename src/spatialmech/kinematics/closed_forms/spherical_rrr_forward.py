"""Forward position of a spherical 3-RRR parallel wrist (Agile-Eye type; paper C's metamorphic
joint with its three actuators), every assembly mode, proven complete.

Recognised from the mechanism itself (:func:`recognise`), whatever its name: three limbs from
the ground to the platform, each of three R joints (no pitch, none locked) whose nine axes all
pass through one centre ``o``, one actuated joint per limb, the two axes of each link distinct.

Elimination of the passive joints.  A limb with reference axes ``a, m, p`` (base, middle,
platform; unit vectors from ``o``) turns the platform by ``R = Rot(a, t1) Rot(m, t2) Rot(p, t3)``
(product of exponentials about the reference axes).  With its actuated angle given, the two
passive angles drop out and one condition on ``R`` is left, ``u . R v = k`` with ``u`` (world) and
``v`` (platform frame) known unit vectors:

    base joint actuated (angle t1):     u = Rot(a, t1) m,  v = p,               k = m . p
    middle joint actuated (t2):         u = a,             v = p,               k = a . Rot(m, t2) p
    platform joint actuated (t3):       u = a,             v = Rot(p, -t3) m,   k = a . m

In quaternion coordinates ``x`` of ``R`` (``R = R~(x) / (x . x)``, ``R~`` quadratic) each is the
homogeneous quadric ``u . R~(x) v - k (x . x) = 0``: three quadrics in ``P^3``, Bezout number 8
(the known bound of 8 assembly modes of the spherical 3-RRR).  They are solved by the
total-degree homotopy of :mod:`.projective_quadrics` (8 paths); when the 8 end points are distinct
and nonsingular the refined Bezout theorem proves that there is no other solution.  A point with
``x . x = 0`` (an isotropic quaternion) is no rotation: counted "at infinity".  Each real rotation
is lifted to every joint and polished (:mod:`.forward_answer`) and flagged as every forward
solution is: a pose that closes for every actuator value (each limb's platform axis on its base
axis: ``R p = +-a``, the actuators turning without moving the platform) is flagged
``input_independent`` and is no assembly mode.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...geometry.tolerances import HOMOTOPY_INFINITY, HOMOTOPY_NEAR_REAL, current
from ...model.mechanism import Mechanism
from .projective_quadrics import solve_projective_quadrics

__all__ = ["SphericalWrist", "forward_rotations", "matrix_quadric", "quaternion_quadric", "quaternion_rotation", "recognise",
           "solve", "wrist_of"]


@dataclass(frozen=True)
class SphericalWrist:
    """The geometry read from a spherical 3-RRR: the centre ``o``; per limb the reference axes
    ``a, m, p`` (rows of ``axes`` (3, 3, 3)), which joint is actuated (``actuated`` (3,): 0 base,
    1 middle, 2 platform) and the actuator's offset (``offsets``: value = offset + joint angle)."""

    centre: np.ndarray
    axes: np.ndarray
    actuated: tuple[int, int, int]
    offsets: np.ndarray

    def conditions(self, angles) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(u, v, k)`` of the three conditions ``u_i . R v_i = k_i`` (module docstring) at the
        actuators' joint angles ``angles`` (rad, in limb order)."""
        U, V, K = np.empty((3, 3)), np.empty((3, 3)), np.empty(3)
        for i, (t, j) in enumerate(zip(angles, self.actuated, strict=True)):
            a, m, p = self.axes[i]
            if j == 0:
                U[i], V[i], K[i] = _rot(a, t) @ m, p, m @ p
            elif j == 1:
                U[i], V[i], K[i] = a, p, a @ _rot(m, t) @ p
            else:
                U[i], V[i], K[i] = a, _rot(p, -t) @ m, a @ m
        return U, V, K


def _rot(axis: np.ndarray, t: float) -> np.ndarray:
    """Right-handed rotation by ``t`` (rad) about the unit ``axis`` (Rodrigues)."""
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * (K @ K)


def _rtilde(x) -> np.ndarray:
    """``R~(x) = (x . x) R(x)`` of the quaternion ``x = (w, i, j, k)`` (quadratic in ``x``)."""
    w, i, j, k = x
    return np.array([[w * w + i * i - j * j - k * k, 2 * (i * j - w * k), 2 * (i * k + w * j)],
                     [2 * (i * j + w * k), w * w - i * i + j * j - k * k, 2 * (j * k - w * i)],
                     [2 * (i * k - w * j), 2 * (j * k + w * i), w * w - i * i - j * j + k * k]])


def _rtilde_forms() -> np.ndarray:
    """The symmetric 4x4 matrices ``M_ab`` with ``R~(x)_ab = x^T M_ab x`` (by polarisation; the
    entries are integers, so this is exact)."""
    E = np.eye(4)
    M = np.empty((3, 3, 4, 4))
    for r in range(4):
        M[:, :, r, r] = _rtilde(E[r])
        for s in range(r + 1, 4):
            M[:, :, r, s] = M[:, :, s, r] = (_rtilde(E[r] + E[s]) - _rtilde(E[r]) - _rtilde(E[s])) / 2
    return M


_M = _rtilde_forms()


def quaternion_quadric(u, v, k: float) -> np.ndarray:
    """The symmetric 4x4 matrix ``A`` with ``x^T A x = u . R~(x) v - k (x . x)``: the condition
    ``u . R v = k`` in quaternion coordinates."""
    return matrix_quadric(np.outer(np.asarray(u, float), np.asarray(v, float)), k)


def matrix_quadric(C, k) -> np.ndarray:
    """The symmetric 4x4 matrix ``A`` with ``x^T A x = sum_ab C_ab R~(x)_ab - k (x . x)``: the
    linear condition ``sum_ab C_ab R_ab = k`` on a rotation, in quaternion coordinates (``C``
    (3, 3) and ``k`` real or complex)."""
    return np.einsum("ab,abrs->rs", np.asarray(C), _M) - k * np.eye(4)


def quaternion_rotation(x) -> np.ndarray:
    """``R~(x) / (x . x)``: the (complex) rotation matrix of the quaternion ``x`` (``x . x != 0``)."""
    x = np.asarray(x)
    return _rtilde(x) / (x @ x)


def _quaternion_matrix(x: np.ndarray) -> np.ndarray:
    R = _rtilde(x) / float(x @ x)
    U, _, Vt = np.linalg.svd(R)  # re-orthonormalise (rounding only: the point is real and x.x > 0)
    return U @ Vt


def wrist_of(mech: Mechanism) -> SphericalWrist | None:
    """The :class:`SphericalWrist` of ``mech`` when it is a spherical 3-RRR (module docstring),
    else ``None``."""
    if mech.is_graph or len(mech.limbs) != 3 or len(mech.actuators) != 3:
        return None
    L = mech.characteristic_length
    tol = max(current().unit, 1e-9)
    lines, axes, act, offs = [], [], [], []
    for limb in mech.limbs:
        if len(limb.joints) != 3:
            return None
        fs = [j.freedoms[0] for j in limb.joints if j.type == "R" and len(j.freedoms) == 1]
        if len(fs) != 3 or any(f.kind != "R" or f.pitch != 0 or f.locked for f in fs):
            return None
        acted = [n for n, f in enumerate(fs) if f.actuated]
        if len(acted) != 1:
            return None
        act.append(acted[0])
        offs.append(fs[acted[0]].offset)
        lines.append([(np.asarray(f.point, float), np.asarray(f.direction, float) / np.linalg.norm(f.direction))
                      for f in fs])
    # the point nearest to the nine axes (least squares), then every axis must pass through it
    P = [pt for li in lines for pt, _ in li]
    D = [d for li in lines for _, d in li]
    A = sum(np.eye(3) - np.outer(d, d) for d in D)
    b = sum((np.eye(3) - np.outer(d, d)) @ pt for pt, d in zip(P, D, strict=True))
    o = np.linalg.lstsq(A, b, rcond=None)[0]
    if any(np.linalg.norm(np.cross(pt - o, d)) > tol * L for pt, d in zip(P, D, strict=True)):
        return None
    for li in lines:
        a, m, p = (d for _, d in li)
        if np.linalg.norm(np.cross(a, m)) < tol or np.linalg.norm(np.cross(m, p)) < tol:
            return None  # a link whose two axes coincide: the limb is degenerate
        axes.append([a, m, p])
    return SphericalWrist(o, np.array(axes), (act[0], act[1], act[2]), np.array(offs))


def forward_rotations(wrist: SphericalWrist, angles, *, seed: int = 0):
    """Every platform rotation of the wrist at the actuators' joint angles (rad): the three
    quaternion quadrics solved in ``P^3`` (:func:`.projective_quadrics.solve_projective_quadrics`).
    Returns ``(rotations, counts, complete, seconds)``: the real rotations, the counts
    ``(real, complex, singular, at_infinity, paths)`` of the end points, and whether Bezout's
    bound proves the set complete."""
    rots, counts, complete, seconds, _ = _forward_quaternions(wrist, angles, seed=seed)
    return rots, counts, complete, seconds


def _forward_quaternions(wrist: SphericalWrist, angles, *, seed: int = 0):
    """:func:`forward_rotations` and, last, ``(A, Y)``: the three quadrics (3, 4, 4) and the
    quaternions (unit, real) of the listed rotations, for their certificates."""
    U, V, K = wrist.conditions(angles)
    A = np.array([quaternion_quadric(U[i], V[i], K[i]) for i in range(3)])
    sol = solve_projective_quadrics(A, seed=seed)
    E = np.abs(np.einsum("ni,ni->n", sol.Y, sol.Y))  # |x.x| of the unit points: 0 is no rotation
    inf = E < HOMOTOPY_INFINITY
    sing = ~sol.nonsingular & ~inf
    real = sol.real & ~inf & ~sing
    near = sing & (np.linalg.norm(sol.Y.imag, axis=1) < HOMOTOPY_NEAR_REAL)  # listed too (polished by the lift)
    rots = [_quaternion_matrix(np.real(y)) for y in sol.Y[real | near]]
    counts = (int(real.sum()), int((~sol.real & ~inf & ~sing).sum()), int(sing.sum()), int(inf.sum()), sol.n_paths)
    return rots, counts, sol.complete, sol.seconds, (A, np.real(sol.Y[real | near]))


def solve(mech: Mechanism, values, *, seeds: int | None = None, seed: int | None = None):
    """The registered forward solver (:data:`..dispatch.FORWARD_CLOSED_FORMS`): every assembly
    mode of the wrist at the actuator ``values`` (rad, in ``mech.actuators`` order), a
    :class:`..dispatch.ForwardAnswer`.  ``seeds`` is refused (no search); ``seed`` draws the
    homotopy's random patch and ``gamma``."""
    from ...errors import InputError
    from . import certificates
    from .forward_answer import Counts, answer_from_poses

    if seeds is not None:
        raise InputError(f"seeds: the spherical 3-RRR closed form of {mech.name} tracks the 8 paths of a total-degree "
                         "homotopy and takes no starts; method='multistart' runs a multi-start search")
    t0 = time.perf_counter()
    wrist = wrist_of(mech)
    assert wrist is not None
    vals = np.asarray(values, dtype=float).ravel()
    order = [mech.freedom(a).limb for a in mech.actuators]
    angles = np.empty(3)
    angles[order] = vals - wrist.offsets[order]
    rots, (nr, nc, ns, ni, npaths), proven, _, (A, Y) = _forward_quaternions(wrist, angles,
                                                                            seed=0 if seed is None else seed)
    certs = certificates.run(lambda: certificates.projective(A, list(Y)))
    o, p0 = wrist.centre, np.asarray(mech.platform_point, float)
    poses = [(R, o + R @ (p0 - o)) for R in rots]
    if proven:
        how = (f"Bezout's bound attained: the three limb conditions are 3 quadrics in the platform's quaternion (P^3), "
               f"at most 8 solutions, and the 8 paths of a total-degree homotopy end at 8 distinct nonsingular points "
               f"({nr} real, {nc} complex, {ni} isotropic quaternions x.x = 0, no rotation): no other solution exists")
    else:
        how = (f"NOT proven: the 8 paths of the total-degree homotopy in the platform's quaternion end at {nr} real, "
               f"{nc} complex, {ns} singular (a multiple root or a continuum of poses: a singular input) and {ni} "
               "points at infinity, not 8 distinct nonsingular points")
    return answer_from_poses(mech, vals, poses, label="spherical 3-RRR closed form (3 quaternion quadrics, 8 paths)",
                             complete=proven, completeness=how, counts=Counts(nr, nc, ns, ni, npaths),
                             seconds=time.perf_counter() - t0, certified=certs)


def recognise(mech: Mechanism):
    """The forward solver :func:`solve` when ``mech`` is a spherical 3-RRR, else ``None``."""
    return solve if wrist_of(mech) is not None else None
