"""A platform on six S-P-S legs in pose coordinates, compiled: forward position, the entry of
:func:`.kernels_legs.nb_leg_platform`, whose Python reference is
:func:`spatialmech.kinematics.leg_platform.correct` (same steps, tolerances and statuses); and
inverse position in closed form at many poses (:func:`inverse_legs_many`)."""

from __future__ import annotations

import numpy as np

from ...geometry.tolerances import current as current_tolerances
from ...model.mechanism import Mechanism
from ...errors import InputError
from ..closure import Configuration, CorrectionResult, check_configuration
from ..leg_platform import LegPlatform, result_or_general
from .engine import correct as general_correct
from .kernels_legs import nb_leg_inverse, nb_leg_platform

__all__ = ["correct_legs", "inverse_legs_many"]

_F64 = np.dtype(np.float64)


def correct_legs(mech: Mechanism, lp: LegPlatform, config: Configuration, tol: float | None = None, max_iter: int = 50,
                 active: np.ndarray | None = None) -> CorrectionResult:
    """:func:`spatialmech.kinematics.leg_platform.correct`, compiled; the compiled general engine
    (:func:`.engine.correct`) is the fallback."""
    if tol is None:  # the newton tolerance in force (geometry/tolerances.py)
        tol = current_tolerances().newton
    q0, D0 = config.q, config.D
    if not (_plain(q0, (lp.n,)) and _plain(D0, (4, 4)) and type(config.B) is np.ndarray
            and config.B.shape == (0, 4, 4)):  # else the full check, and one numba type per argument
        check_configuration(mech, config)
        q0, D0 = np.require(q0, np.float64, ["C", "W"]), np.require(D0, np.float64, ["C", "W"])
    qn, Dn = np.empty(lp.n), np.empty((4, 4))
    status, it, rn, same = nb_leg_platform(lp.index, lp.data, lp.length, q0, D0, float(tol), int(max_iter), qn, Dn)
    if status == -1:  # NaN or infinity in the seed: the full check names it
        check_configuration(mech, config)
    if status == 1:
        return CorrectionResult.of(config if same else Configuration.of(qn, Dn), True, it, rn)
    return result_or_general(mech, lp, config, status, it, None, None, rn, tol, max_iter, active, general_correct)


def inverse_legs_many(lp: LegPlatform, D, tol: float | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inverse position of the legs ``lp`` at the platform displacements ``D`` (N, 4, 4) in
    closed form (:func:`.kernels_legs.nb_leg_inverse`): ``(q (N, n), residual (N, 6), converged
    (N, 6))`` as :func:`.engine.limb_inverse_many` returns them, a few microseconds a pose
    instead of a Gauss-Newton per leg.  The same leg lengths, ball centres and platform
    orientation; the legs' idle spins (rotation about their own axes, which moves nothing) are
    the reference's, not those the Gauss-Newton's path leaves: for callers whose answer does not
    depend on the spins (joint points, leg directions, slides).  ``tol``: the closure tolerance
    in force by default."""
    Ds = np.require(D, np.float64, ["C", "W"])
    if Ds.ndim != 3 or Ds.shape[1:] != (4, 4):
        raise InputError(f"D: expected shape (N, 4, 4), got {Ds.shape}")
    if not np.all(np.isfinite(Ds)):
        raise InputError("D: contains NaN or infinity")
    if tol is None:
        tol = current_tolerances().closure
    n = Ds.shape[0]
    q = np.zeros((n, lp.n))
    res = np.empty((n, lp.index.shape[0]))
    ok = np.empty((n, lp.index.shape[0]), dtype=np.bool_)
    if n:
        nb_leg_inverse(lp.index, lp.data, lp.length, Ds, float(tol), q, res, ok)
    return q, res, ok


def _plain(x, shape) -> bool:
    """A C-contiguous, writable float64 array of ``shape`` (what the kernel takes as it is)."""
    if type(x) is not np.ndarray or x.dtype is not _F64 or x.shape != shape:
        return False
    f = x.flags
    return f.c_contiguous and f.writeable
