"""Forward position of a single loop of revolute joints (an overconstrained 5R or 6R such as
Goldberg's or Bricard's, or a general 7R), one joint driven: every configuration, proven
complete through the complete inverse position of a 6R chain.

Recognised from the mechanism itself (:func:`recognise`): two limbs from the ground to the
output link, every joint an R joint (no pitch, none locked), 5 to 7 joints in all, one of them
actuated.  Read as one cycle (the first limb's joints, then the second's in reverse with their
axes reversed) the loop closes when ``exp(xi_1 t_1) ... exp(xi_n t_n) = I`` (reference axes, the
model's reference configuration closes); started at the driven joint ``a`` it reads

    exp(xi_a+1 t_a+1) ... exp(xi_a-1 t_a-1) = exp(-xi_a t_a):

the inverse position of the chain of the other ``n - 1`` joints to a known displacement.  With
``7 - n`` more R joints of random (seeded) axes appended, the chain is a 6R, and the loop's
configurations are exactly the 6R solutions whose added joints are at 0 (mod 2 pi).  The 6R's
inverse position is solved completely by :func:`..homotopy.inverse.limb_inverse` (monodromy to
the root count 16 of any 6R, or the trace test; then a parameter homotopy to the pose), so the
loop's set is proven complete whenever that solve is.  A loop whose 6R has a positive-dimensional
solution set (a singular input) is reported unproven by that solve.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...geometry.rotations import transform
from ...model.joints import R as RJoint
from ...model.joints import Freedom
from ...model.mechanism import Limb, Mechanism

__all__ = ["RLoop", "loop_cycle", "loop_of", "platform_pose_of", "recognise", "rotation_about", "solve"]

#: Seed of the added joints' axes (the chain is then a general-enough 6R with probability one).
EXTRA_SEED = 27


@dataclass(frozen=True, eq=False)
class RLoop:
    """A single loop of R joints as a cycle starting at the driven joint: per joint its point,
    unit direction (reversed for the second limb's joints, whose variable is then the limb's own)
    and the index of its freedom; ``offset`` of the driven joint; ``aux`` the 6R chain of the
    others plus the ``n_extra`` added joints."""

    points: np.ndarray
    dirs: np.ndarray
    index: tuple[int, ...]
    offset: float
    aux: Mechanism
    n_extra: int


def rotation_about(p: np.ndarray, u: np.ndarray, t: float) -> np.ndarray:
    """The displacement (4x4) turning by ``t`` (rad, right-handed) about the line through ``p``
    along the unit ``u``."""
    K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    R = np.eye(3) + np.sin(t) * K + (1 - np.cos(t)) * (K @ K)
    return transform(R, p - R @ p)


def loop_cycle(mech: Mechanism) -> list[tuple[np.ndarray, np.ndarray, int, Freedom]] | None:
    """The joints of a single loop of R joints as a cycle starting at the driven one: per joint
    its point, unit direction (reversed for the second limb's joints, whose variable is then the
    limb's own), freedom index and freedom; ``None`` unless ``mech`` is two limbs of R joints
    (no pitch, none locked) from the ground to the output link with one actuator."""
    if mech.is_graph or len(mech.limbs) != 2 or len(mech.actuators) != 1:
        return None
    refs = mech.freedom_refs
    cyc = []
    for li, limb in enumerate(mech.limbs):
        js = list(enumerate(limb.joints))
        for ji, j in (js if li == 0 else js[::-1]):
            if j.type != "R" or len(j.freedoms) != 1:
                return None
            f = j.freedoms[0]
            if f.kind != "R" or f.pitch != 0 or f.locked:
                return None
            idx = next(k for k, r in enumerate(refs) if r.limb == li and r.joint == ji)
            d = np.asarray(f.direction, float) / np.linalg.norm(f.direction)
            cyc.append((np.asarray(f.point, float), d if li == 0 else -d, idx, f))
    a = next(k for k, c in enumerate(cyc) if c[3].actuated)
    return cyc[a:] + cyc[:a]


def platform_pose_of(mech: Mechanism, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The output link's rotation and platform point of a loop's joint variables ``q`` (every
    freedom): the product of exponentials of the first limb."""
    T = np.eye(4)
    for i, r_ in enumerate(mech.freedom_refs):
        if r_.limb == 0:
            f = r_.freedom
            T = T @ rotation_about(np.asarray(f.point, float), np.asarray(f.direction, float) /
                                   np.linalg.norm(f.direction), q[i])
    P0 = np.asarray(mech.platform_point, float)
    return T[:3, :3], T[:3, :3] @ P0 + T[:3, 3]


def loop_of(mech: Mechanism) -> RLoop | None:
    """The :class:`RLoop` of ``mech`` when it is a single loop of 5 to 7 R joints with one
    driven (module docstring), else ``None``."""
    cyc = loop_cycle(mech)
    if cyc is None or not 5 <= len(cyc) <= 7:
        return None
    rng = np.random.default_rng(EXTRA_SEED)
    L = mech.characteristic_length
    centre = np.mean([c[0] for c in cyc], axis=0)
    n_extra = 7 - len(cyc)
    extra = []
    for _ in range(n_extra):
        v = rng.normal(size=3)
        extra.append((centre + rng.normal(size=3) * L, v / np.linalg.norm(v)))
    joints = [RJoint(f"K{k}", p, u) for k, (p, u) in enumerate([(c[0], c[1]) for c in cyc[1:]] + extra)]
    aux = Mechanism(f"{mech.name}-cut", (Limb("chain", tuple(joints)),), platform_point=centre)
    return RLoop(np.array([c[0] for c in cyc]), np.array([c[1] for c in cyc]), tuple(c[2] for c in cyc),
                 cyc[0][3].offset, aux, n_extra)


def solve(mech: Mechanism, values, *, seeds: int | None = None, seed: int | None = None):
    """The registered forward solver (:data:`..dispatch.FORWARD_CLOSED_FORMS`): every
    configuration of the loop at the driven joint's ``values`` (rad), a
    :class:`..dispatch.ForwardAnswer` (module docstring).  ``seeds`` is refused (no search);
    ``seed`` is the 6R solve's."""
    from ..homotopy import certify as hcert
    from ..homotopy.inverse import limb_ik_system, limb_inverse
    from . import certificates
    from .forward_answer import Counts, answer_from_poses

    if seeds is not None:
        raise InputError(f"seeds: the single-loop closed form of {mech.name} solves a 6R's inverse position "
                         "completely and takes no starts; method='multistart' runs a multi-start search")
    t0 = time.perf_counter()
    loop = loop_of(mech)
    assert loop is not None
    theta = float(np.asarray(values, float).ravel()[0]) - loop.offset
    D = rotation_about(loop.points[0], loop.dirs[0], -theta)
    r = limb_inverse(loop.aux, 0, D, seed=0 if seed is None else seed)
    n_rest = len(loop.points) - 1
    keep = [q for q in r.solutions if np.all(np.abs(np.angle(np.exp(1j * q[n_rest:]))) < 1e-6)]
    poses = []
    for q in keep:
        qq = np.zeros(len(mech.freedom_refs))
        qq[loop.index[0]] = theta
        for k, i in enumerate(loop.index[1:]):
            qq[i] = q[k]
        poses.append(platform_pose_of(mech, qq))
    n = len(loop.points)
    added = (f" with {loop.n_extra} R joint(s) of random axes added (the loop's configurations are its solutions "
             f"with them at 0: {len(keep)} of its {r.n_real} real ones)") if loop.n_extra else ""
    how = (f"the loop of {n} R joints with the driven one given is the inverse position of the chain of the other "
           f"{n - 1}{added}, a 6R: {r.completeness}")
    if not r.complete:
        how = "NOT proven: " + how
    certs = certificates.run(lambda: hcert.certify_inverse(limb_ik_system(loop.aux, 0, 0 if seed is None else seed), D,
                                                           keep))
    return answer_from_poses(mech, values, poses, label=f"single {n}R loop as a 6R inverse position",
                             complete=r.complete, completeness=how,
                             counts=Counts(len(keep), r.n_complex, r.n_singular, r.n_infinity, r.n_paths,
                                           r.n_real - len(keep)),
                             seconds=time.perf_counter() - t0, certified=certs)


def recognise(mech: Mechanism):
    """The forward solver :func:`solve` when ``mech`` is a single loop of 5 to 7 R joints with
    one driven, else ``None``."""
    return solve if loop_of(mech) is not None else None
