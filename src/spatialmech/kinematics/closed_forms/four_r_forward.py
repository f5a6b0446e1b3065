"""Forward position of a single loop of four R joints (a Bennett linkage, a planar or spherical
four-bar), one joint driven: every configuration in closed form, proven complete.

Recognised from the mechanism itself (:func:`recognise`): two limbs of R joints from the ground
to the output link, four joints in all, one actuated (:func:`.r_loop_forward.loop_cycle`).  Read
as the cycle ``a, b, c, d`` from the driven joint (``exp(xi_a t_a) ... exp(xi_d t_d) = I``), the
driven angle places the axis of ``b`` (point ``P_b``, direction ``U_b``), and the angle ``phi =
t_d`` of the joint ``d`` on the ground places the axis of ``c``: ``Q(phi), V(phi)``, a rotation
about ``d`` by ``-phi`` of its reference point and direction.  The link between ``b`` and ``c``
is rigid and turns about ``b`` only, so five quantities keep their reference values:

    |Q - P_b|^2,  U_b . V,  U_b . (Q - P_b),  V . (Q - P_b),  (U_b x (Q - P_b)) . V

(lengths over the characteristic length).  Each is ``alpha cos(phi) + beta sin(phi) + gamma``
(``Q`` and ``V`` turn about a fixed line): every configuration satisfies the one with the largest
``(alpha, beta)``, which has at most 2 roots, both computed in closed form (real or a complex
pair); those that satisfy all five are the configurations (the others are counted spurious).  When
all five vanish identically the output turns freely with the input held (a continuum): not
proven.  ``t_b`` and ``t_c`` follow from the rigid link, the pose from the first limb.
"""

from __future__ import annotations

import time

import numpy as np

from ...errors import InputError
from ...model.mechanism import Mechanism
from .r_loop_forward import loop_cycle, platform_pose_of, rotation_about

__all__ = ["coupler_conditions", "recognise", "solve"]


def _invariants(Pb, Ub, Q, V, L: float) -> np.ndarray:
    d = (Q - Pb) / L
    return np.array([d @ d, Ub @ V, Ub @ d, V @ d, np.cross(Ub, d) @ V])


def coupler_conditions(cyc, theta: float, L: float):
    """``(alpha, beta, gamma)`` (5 each) of the coupler conditions ``alpha cos(phi) + beta sin(phi)
    + gamma = 0`` at the driven angle ``theta`` (module docstring), and ``A`` the driven link's
    displacement."""
    (pa, ua, *_), (pb, ub, *_), (pc, uc, *_), (pd, ud, *_) = cyc
    A = rotation_about(pa, ua, theta)
    Pb, Ub = A[:3, :3] @ pb + A[:3, 3], A[:3, :3] @ ub
    ref = _invariants(pb, ub, pc, uc, L)

    def f(phi):
        D = rotation_about(pd, ud, -phi)
        return _invariants(Pb, Ub, D[:3, :3] @ pc + D[:3, 3], D[:3, :3] @ uc, L) - ref

    f0, f1, f2 = f(0.0), f(np.pi / 2), f(np.pi)
    gamma = (f0 + f2) / 2
    return (f0 - f2) / 2, f1 - gamma, gamma, A


def _angle_about(u, v0, v1) -> float:
    """The turn about the unit ``u`` taking the component of ``v0`` normal to ``u`` to that of ``v1``."""
    r0, r1 = v0 - (v0 @ u) * u, v1 - (v1 @ u) * u
    return float(np.arctan2(u @ np.cross(r0, r1), r0 @ r1))


def _configuration(mech: Mechanism, cyc, theta: float, phi: float, A: np.ndarray) -> np.ndarray:
    """Every freedom's value of the loop at the driven angle ``theta`` and ``t_d = phi``."""
    (_, _, ia, _), (pb, ub, ib, _), (pc, uc, ic, _), (pd, ud, idd, _) = cyc
    D = rotation_about(pd, ud, -phi)  # the link between c and d
    Ai = np.linalg.inv(A)
    Q = Ai[:3, :3] @ (D[:3, :3] @ pc + D[:3, 3]) + Ai[:3, 3]  # c's point seen from the driven link
    if np.linalg.norm((pc - pb) - ((pc - pb) @ ub) * ub) > 1e-9 * max(1.0, float(np.linalg.norm(pc - pb))):
        tb = _angle_about(ub, pc - pb, Q - pb)
    else:  # c's point on b's axis: c's direction instead
        tb = _angle_about(ub, uc, Ai[:3, :3] @ D[:3, :3] @ uc)
    M = np.linalg.inv(A @ rotation_about(pb, ub, tb)) @ D
    R = M[:3, :3]
    tc = float(np.arctan2(uc @ np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) / 2,
                          (np.trace(R) - 1) / 2))
    q = np.zeros(len(mech.freedom_refs))
    q[ia], q[ib], q[ic], q[idd] = theta, tb, tc, phi
    return q


def solve(mech: Mechanism, values, *, seeds: int | None = None, seed: int | None = None):
    """The registered forward solver (:data:`..dispatch.FORWARD_CLOSED_FORMS`): every
    configuration of the four-bar loop at the driven joint's ``values`` (rad), a
    :class:`..dispatch.ForwardAnswer`.  ``seeds`` and ``seed`` are refused (nothing to search or
    draw)."""
    from . import certificates
    from .forward_answer import Counts, answer_from_poses

    given = [n for n, v in (("seeds", seeds), ("seed", seed)) if v is not None]
    if given:
        raise InputError(f"{', '.join(given)}: the four-bar closed form of {mech.name} solves one trigonometric "
                         "equation and takes no starts; method='multistart' runs a multi-start search")
    t0 = time.perf_counter()
    cyc = loop_cycle(mech)
    assert cyc is not None
    L = mech.characteristic_length
    theta = float(np.asarray(values, float).ravel()[0]) - cyc[0][3].offset
    alpha, beta, gamma, A = coupler_conditions(cyc, theta, L)
    size = np.hypot(alpha, beta)
    k = int(np.argmax(size))
    if size[k] < 1e-12:
        how = ("NOT proven: the five coupler conditions do not depend on the output joint's angle at this input (the "
               "output turns with the input held: a continuum); no configuration listed")
        return answer_from_poses(mech, values, [], label="four-bar closed form", complete=False, completeness=how,
                                 counts=Counts(0, 0, 1, 0, 2), seconds=time.perf_counter() - t0)
    c = -gamma[k] / size[k]
    base = float(np.arctan2(beta[k], alpha[k]))
    roots = [base + np.arccos(np.clip(c, -1, 1)), base - np.arccos(np.clip(c, -1, 1))] if abs(c) <= 1 + 1e-12 else []
    n_complex = 2 - len(roots)
    poses, spurious = [], 0
    for phi in roots:
        res = alpha * np.cos(phi) + beta * np.sin(phi) + gamma
        if np.max(np.abs(res)) > 1e-9:
            spurious += 1
            continue
        poses.append(platform_pose_of(mech, _configuration(mech, cyc, theta, float(phi), A)))
    names = ("|Q - P_b|^2", "U_b . V", "U_b . (Q - P_b)", "V . (Q - P_b)", "(U_b x (Q - P_b)) . V")
    how = (f"every configuration satisfies the coupler condition {names[k]} = its reference value, "
           f"a cos(phi) + b sin(phi) = c in the output joint's angle phi (nonzero a, b): at most 2 roots, both "
           f"computed in closed form ({len(roots)} real, {n_complex} complex); {len(poses)} satisfy all five conditions "
           f"of the rigid coupler" + (f", {spurious} do not" if spurious else ""))
    double = len(roots) == 2 and abs(roots[0] - roots[1]) < 1e-9
    kept = [phi for phi in roots if np.max(np.abs(alpha * np.cos(phi) + beta * np.sin(phi) + gamma)) <= 1e-9]
    certs = certificates.run(lambda: certificates.four_bar(alpha[k], beta[k], gamma[k], kept[:1] if double else kept))
    return answer_from_poses(mech, values, poses[:1] if double else poses, label="four-bar closed form (2 roots)",
                             complete=True, completeness=how, certified=certs,
                             counts=Counts(len(poses), n_complex, int(double), 0, 2, spurious), seconds=time.perf_counter() - t0)


def recognise(mech: Mechanism):
    """The forward solver :func:`solve` when ``mech`` is a single loop of four R joints with one
    driven, else ``None``."""
    cyc = loop_cycle(mech)
    return solve if cyc is not None and len(cyc) == 4 else None
