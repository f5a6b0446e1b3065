"""The public API: stiffness (``sm.stiffness``, ``sm.stiffness_map``): the Cartesian stiffness at
the output link from actuator and limb stiffnesses, its principal directions, and the softest
one over a workspace slice (docs/stiffness.md)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..analysis.stiffness import Stiffness
from ..analysis.stiffness import stiffness as _stiffness
from ..analysis.stiffness import with_stiffness
from ..analysis.stiffness_map import StiffnessMap
from ..analysis.stiffness_map import stiffness_map as _stiffness_map
from ..analysis.workspace import WorkspaceLimits
from ..errors import describe
from ..geometry.tolerances import current as current_tolerances
from ..kinematics.closure import Configuration
from ..kinematics.position import PoseFit, platform_pose
from ..model.mechanism import Mechanism, Pose
from ..serialize import pose_dict
from .checks import ModelLike, as_mechanism, check_choice, check_grid, check_names, where
from .threads import one_blas_thread

__all__ = ["StiffnessMap", "StiffnessResult", "stiffness", "stiffness_map"]

#: How the matrices of ``stiffness`` are written, in its JSON.
CONVENTION = ("F = K d: the wrench F = (f ; m about the origin) that holds the small displacement d = (dp ; dtheta) "
              "(dp: the displacement of the point at the origin, dtheta: the rotation in rad); d = C F. Blocks: "
              "translation = df/d(dp), coupling = df/d(dtheta) = (dm/d(dp))^T (force per rad), rotation = dm/d(dtheta) "
              "(moment per rad); compliance blocks likewise (translation d(dp)/df, coupling d(dp)/dm = (d(dtheta)/df)^T, "
              "rotation d(dtheta)/dm). Principal directions: eigenvectors of K in nondimensional coordinates about the "
              "platform point, (dp_P ; L dtheta), each of unit size, its stiffness in force per length unit (a pure "
              "rotation: k L^2 per rad), softest first, the largest nondimensional component positive")


def _c(v) -> float:
    return float(v) + 0.0


def _blocks(M: np.ndarray, keys: tuple[str, str, str]) -> dict:
    return {keys[0]: [[_c(x) for x in r] for r in M[:3, :3]], keys[1]: [[_c(x) for x in r] for r in M[:3, 3:]],
            keys[2]: [[_c(x) for x in r] for r in M[3:, 3:]]}


def _direction(s: Stiffness, i: int) -> dict:
    """One principal direction as JSON."""
    t = s.principal_twists[i]
    k = float(s.principal_stiffness[i])
    rigid = not np.isfinite(k)
    w = None if rigid else s.wrench_of(t)
    return {"stiffness_N_per_len": None if rigid else _c(k), "rigid": bool(rigid), "repeated": int(s.multiplicity[i]),
            "twist": [_c(x) for x in t], "translation_len": [_c(x) for x in s.translation_at_point(t)],
            "rotation_deg": [_c(x) for x in np.degrees(t[:3])],
            "wrench": None if w is None else {"force_N": [_c(x) for x in w[:3]], "moment_N_len": [_c(x) for x in w[3:]]}}


@dataclass(frozen=True, eq=False)
class StiffnessResult:
    """The stiffness at one configuration (:func:`stiffness`).  Forces in N (any consistent force
    unit), lengths in the model's unit, rotations in rad (see :mod:`spatialmech.analysis.stiffness`)."""

    mechanism: Mechanism  # with the stiffnesses used (the model's, or the ones given)
    config: Configuration
    matrix: np.ndarray  # (6, 6) K about the origin: F = (f ; m) = K (dp ; dtheta)
    compliance: np.ndarray | None  # (6, 6) C = K^-1 on the allowed motions; None when singular
    principal_stiffness: np.ndarray  # (6,) N per length unit, ascending; inf: rigid
    principal_twists: np.ndarray  # (6, 6) rows (dtheta ; dp about the origin), unit nondimensional size
    softest_stiffness: float  # N per length unit (0 at a singularity)
    softest_twist: np.ndarray  # (6,)
    singular: bool
    sigma_min: float
    analysis: Stiffness
    pose_fit: PoseFit | None = None
    pose: Pose | None = None

    @property
    def notes(self) -> tuple[str, ...]:
        return self.analysis.notes

    def to_dict(self) -> dict:
        """JSON (docs/json.md, ``spatialmech stiffness --json``): the stiffness and compliance as
        3x3 blocks with unit-suffixed keys, the principal directions softest first (``null``
        stiffness: rigid), the stiffnesses used and the notes."""
        mech, s = self.mechanism, self.analysis
        P = self.pose if self.pose is not None else platform_pose(mech, self.config)
        kinds = {a: mech.freedom(a).freedom.kind for a in s.actuators}
        return {
            "result": "stiffness",
            "pose": pose_dict(P.R, P.p),
            "convention": CONVENTION,
            "reference_point_len": [_c(x) for x in s.reference_point],
            "characteristic_length_len": float(s.characteristic_length),
            "actuators": list(s.actuators),
            "actuator_stiffness": {
                "linear_N_per_len": {a: float(k) for a, k in zip(s.actuators, s.actuator_stiffness, strict=True)
                                     if kinds[a] == "P"},
                "torsional_N_len": {a: float(k) for a, k in zip(s.actuators, s.actuator_stiffness, strict=True)
                                    if kinds[a] != "P"}},
            "defaulted": list(s.defaulted),
            "constraint_stiffness_N_per_len": {limb.name: limb.constraint_stiffness for limb in mech.limbs},
            "rigid_rank": int(s.rigid_rank),
            "stiffness": _blocks(self.matrix, ("translation_N_per_len", "coupling_N", "rotation_N_len")),
            "compliance": None if self.compliance is None else _blocks(
                self.compliance, ("translation_len_per_N", "coupling_per_N", "rotation_per_N_len")),
            "principal": [_direction(s, i) for i in range(6)],
            "softest": _direction(s, 0) if np.isfinite(s.principal_stiffness[0]) else None,
            "singular": self.singular,
            "sigma_min": self.sigma_min,
            "singular_below": current_tolerances().singular,
            "inverse_singular": list(s.jacobian.inverse_singular),
            "notes": list(self.notes),
            "pose_fit": None if self.pose_fit is None else self.pose_fit.to_dict(),
        }


def stiffness(model: ModelLike, pose=None, *, config: Configuration | None = None, drivers=None,
              actuator_stiffness=None, constraint_stiffness=None, degrees: bool = False) -> StiffnessResult:
    """The Cartesian stiffness at the output link at a pose (fitted onto the closure), a
    configuration or the reference configuration, from the actuators' stiffness and the limbs'
    constraint stiffness (massless rigid links, frictionless passive joints, no preload).

    Parameters
    ----------
    model : Mechanism, str or path
        A mechanism, a ready-made model name (``sm.models()``) or a TOML file (whose joints may
        give ``stiffness`` and limbs ``constraint_stiffness``: docs/file-format.md).
    pose : Pose, tuple or int, optional
        The output link's pose (see :mod:`spatialmech.api`); default the reference configuration.
    config : Configuration, optional
        A configuration instead of a pose.
    drivers : str or sequence of str, optional
        The actuated freedoms (default: the model's actuators).
    actuator_stiffness : float or mapping, optional
        Overrides the model's: one number for every actuator, or freedom -> stiffness (N per
        length unit for a slide, N times the length unit per radian for a rotation).  An actuator
        with none is given 1 (``notes`` and ``defaulted`` say so).
    constraint_stiffness : float or mapping, optional
        Overrides the model's: one number for every limb, or limb name -> stiffness (N per length
        unit, on unit nondimensional constraint wrenches; ``None``: rigid, the default).
    degrees : bool
        Read a pose tuple's Euler angles in degrees.

    Returns
    -------
    StiffnessResult
        ``matrix`` ``K`` (``F = K (dp ; dtheta)``, moments about the origin, symmetric),
        ``compliance`` ``C`` (``(dp ; dtheta) = C F``; ``None`` at a singularity),
        ``principal_stiffness`` ascending (N per length unit, nondimensional about the platform
        point; ``inf`` across rigid constraints) with ``principal_twists``, and the softest.

    Raises
    ------
    TypeError
        A stiffness that is not a number, a wrong type of pose or model.
    InputError
        A stiffness not positive and finite; an unknown limb or freedom; a pose with no closed
        configuration near it; a mechanism without actuators.

    Examples
    --------
    >>> import numpy as np, spatialmech as sm
    >>> r = sm.stiffness("stewart-6sps", actuator_stiffness=2e6)     # legs of 2e6 N/m
    >>> bool(np.allclose(r.matrix, r.matrix.T)), r.singular
    (True, False)
    >>> round(r.softest_stiffness / 2e6, 4), int(r.analysis.multiplicity[0])   # a pair: 120-degree symmetry
    (0.3027, 2)
    >>> round(float(r.matrix[2, 2]) / 2e6, 4)                       # vertical: 6 cos^2 of the legs' angle
    4.7154
    """
    mech = as_mechanism(model)
    for name, v in (("actuator_stiffness", actuator_stiffness), ("constraint_stiffness", constraint_stiffness)):
        if isinstance(v, bool) or not (v is None or isinstance(v, (int, float, Mapping))):
            raise TypeError(f"{name}: expected a positive number or a mapping name -> number, got {describe(v)}")
    mech = with_stiffness(mech, actuators=None if actuator_stiffness is None else _plain(actuator_stiffness),
                          constraints=None if constraint_stiffness is None else _plain(constraint_stiffness))
    w = where(mech, pose, config, drivers, degrees)
    mech, c, fit, requested = w.mech, w.config, w.fit, w.pose
    s = _stiffness(mech, c, w.drivers)
    return StiffnessResult(mech, c, s.matrix, s.compliance, s.principal_stiffness, s.principal_twists,
                           s.softest_stiffness, s.softest_twist, s.singular, s.sigma_min, s, fit, requested)


def _plain(v):
    return dict(v) if isinstance(v, Mapping) else v


@one_blas_thread
def stiffness_map(model: ModelLike, *, over: Mapping, at: Mapping[str, float] | None = None, kind: str = "position",
                  drivers=None, actuator_stiffness=None, constraint_stiffness=None,
                  limits: WorkspaceLimits | None = None) -> StiffnessMap:
    """The softest principal stiffness (N per length unit) and its direction at every pose of a
    workspace slice (a Python loop over the grid: a few ms per pose).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, as for :func:`stiffness`.
    over : mapping
        1 to 3 coordinates, each to ``(lo, hi, n)`` or to its values (SI, rad): ``x, y, z`` for
        ``kind="position"``, ``alpha, beta, gamma`` (``R = Rz(gamma) Ry(beta) Rx(alpha)``) for
        ``kind="orientation"``.
    at : mapping, optional
        The other coordinates (default: the reference platform point, no rotation).
    kind : {"position", "orientation"}
    drivers, actuator_stiffness, constraint_stiffness
        As for :func:`stiffness`.
    limits : WorkspaceLimits, optional
        Default: the model's.

    Returns
    -------
    StiffnessMap
        ``softest`` (grid; NaN where a cell has none, 0 where singular), ``softest_twist``,
        ``status`` codes of ``STATUS``; ``minimum()``.

    Raises
    ------
    TypeError
        ``over`` or ``at`` is not a mapping, or another argument has the wrong type.
    InputError
        A bad value (unknown coordinate or kind, a grid that is not increasing, a stiffness that
        is not positive and finite), named in the message.

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.stiffness_map("stewart-6sps", over={"x": (-0.1, 0.1, 3)}, actuator_stiffness=1e6)
    >>> r.status_counts()["ok"], bool(abs(r.softest[1] / 1e6 - 0.3027) < 1e-4)
    (3, True)
    """
    mech = as_mechanism(model)
    kind = check_choice(kind, "kind", ("position", "orientation"))
    drivers = check_names(drivers, "drivers")
    check_grid(over, at, limits)
    mech = with_stiffness(mech, actuators=None if actuator_stiffness is None else _plain(actuator_stiffness),
                          constraints=None if constraint_stiffness is None else _plain(constraint_stiffness))
    return _stiffness_map(mech, kind=kind, over=over, at=at, limits=limits, drivers=drivers)

