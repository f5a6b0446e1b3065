"""A forward-position answer (:class:`..dispatch.ForwardAnswer`) from the platform poses a
closed form found: each pose lifted to every joint (:func:`..solution_flags.configuration_at_pose`),
polished by Newton with the actuators held, its conditioning and flags computed as for every
engine (:func:`..solution_flags.solution_flags`), and the completeness statement of the closed
form carried through (``complete``, the end-point counts).  Used by the closed forms that prove
their solution set complete (:mod:`.spherical_rrr_forward`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...model.mechanism import Mechanism, Pose
from ..assembly import AssemblyKind, dedup_tolerances, pose_keys, singular_threshold
from ..backend import correct
from ..closure import active_mask
from ..dispatch import AssemblyMode, EndPoints, ForwardAnswer
from ..forward import ForwardResult, ForwardSolution, forward_conditioning
from ..position import platform_pose, within_limits
from ..solution_flags import actuator_targets, configuration_at_pose, solution_flags

if TYPE_CHECKING:
    from .certificates import Certified

__all__ = ["Counts", "answer_from_poses"]


@dataclass(frozen=True)
class Counts:
    """The end points of a closed form's polynomial system: real (the candidate poses), complex,
    singular, at infinity (not a pose), the number of paths (the bound they attain) and the end
    points of a larger system that are no solution (``n_spurious``, ``None`` where there is none)."""

    n_real: int
    n_complex: int
    n_singular: int
    n_at_infinity: int
    n_paths: int
    n_spurious: int | None = None  # end points of a larger system that are no solution of the mechanism


def answer_from_poses(mech: Mechanism, values, poses: list[tuple[np.ndarray, np.ndarray]], *, label: str,
                      complete: bool, completeness: str, counts: Counts, seconds: float,
                      max_iter: int = 30, certified: Certified | None = None) -> ForwardAnswer:
    """The :class:`ForwardAnswer` (engine ``"closed-form"``) of the candidate platform poses
    ``poses`` (rotation, position of the platform point), each lifted and polished (module
    docstring); a pose whose limbs do not close is dropped and ``complete`` withdrawn.
    ``certified``: the certificates of the closed form's points, one per pose
    (:mod:`.certificates`; ``None``: not attempted)."""
    targets = actuator_targets(mech, values)
    mask = active_mask(mech)
    for i in targets:
        mask[i] = False
    L = mech.characteristic_length
    dedup = dedup_tolerances()[0]
    sols: list[ForwardSolution] = []
    modes: list[AssemblyMode] = []
    keys: list[np.ndarray] = []
    dropped = 0
    for n, (R, p) in enumerate(poses):
        cfg = configuration_at_pose(mech, Pose(R, p, f"mode {n + 1}"), targets)
        res = correct(mech, cfg, active=mask, max_iter=max_iter)
        if not res.converged:
            dropped += 1
            continue
        c = res.config
        pose = platform_pose(mech, c)
        key = pose_keys(pose.R, pose.p, L)
        if any(np.linalg.norm(key - k) < dedup for k in keys):
            continue
        keys.append(key)
        cond = forward_conditioning(mech, c)
        kind = AssemblyKind.SINGULAR if cond.singular else AssemblyKind.REGULAR
        outside = tuple(within_limits(mech, c.q))
        cert = certified.certificates[n] if certified is not None else None
        ok = None if cert is None else cert.certified
        flags = solution_flags(mech, c, targets, forward_singular=cond.singular, endpoint="real", certified=ok)
        sols.append(ForwardSolution(c, pose, True, float(res.residual), int(getattr(res, "iterations", 0)), outside,
                                    cond, kind, 1, None, "real", ok, None if cert is None else cert.to_dict()))
        modes.append(AssemblyMode(pose, kind, float(res.residual), outside, cond.sigma_min, cond.condition,
                                  cond.threshold, 1, None, cond.free_dim, flags))
    if dropped:
        complete = False
        completeness = (f"NOT proven: {dropped} real solution(s) of the closed form did not lift to a closed "
                        f"configuration ({completeness})")
    kinds = [s.kind for s in sols]
    search = {"method": label, "seeds": 0, "seed": None, "converged_runs": len(sols), "distinct": len(sols),
              "n_regular": kinds.count(AssemblyKind.REGULAR), "n_singular_roots": kinds.count(AssemblyKind.SINGULAR),
              "n_self_motion_sets": 0, "complete": complete, "completeness": completeness,
              "n_complex": counts.n_complex, "n_real": counts.n_real, "n_singular": counts.n_singular,
              "n_at_infinity": counts.n_at_infinity, "n_generic": counts.n_paths, "n_paths": counts.n_paths,
              "elapsed_s": seconds, "endpoints": [], "singular_below": singular_threshold(),
              "n_certified": None if certified is None else certified.n_certified,
              "certification": "not attempted" if certified is None else certified.statement,
              "certify_elapsed_s": None if certified is None else certified.seconds}
    ends = EndPoints(counts.n_real, counts.n_complex, counts.n_singular, counts.n_at_infinity, counts.n_paths,
                     counts.n_spurious, seconds)
    return ForwardAnswer("closed-form", label, True, tuple(modes), complete, completeness, 0, len(modes), ends, None,
                         ForwardResult(tuple(sols), search))
