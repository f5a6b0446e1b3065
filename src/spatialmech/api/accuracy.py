"""The public API: accuracy (``sm.accuracy``): the output pose error produced by actuator errors,
joint clearances and manufacturing tolerances, to first order, in the worst case and by
Monte-Carlo with the exact forward position (docs/accuracy.md)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..analysis.accuracy import AccuracyAnalysis, ErrorBudget, accuracy_analysis
from ..errors import InputError
from ..kinematics.closure import Configuration
from ..kinematics.position import PoseFit, platform_pose
from ..model.mechanism import Mechanism
from ..serialize import pose_dict
from .checks import ModelLike, as_configuration, as_mechanism, check_bool, check_int

__all__ = ["AccuracyResult", "accuracy"]

ERROR_MODEL = ("actuators: each joint variable off by up to its tolerance; joint points (3 components) and single-axis "
               "joint axes (2 rotations about the joint point) displaced at the reference configuration, the joint "
               "variables keeping their meaning (actuators zeroed at the reference); clearances: each passive joint's "
               "outboard link translated by up to the clearance along each world axis (first order in every estimate); "
               "output: translation of the output point (m) and rotation vector (rad, world frame)")
_KEYS = ("actuator", "clearance", "geometry", "axis")


def _budget(tolerances) -> ErrorBudget:
    if isinstance(tolerances, ErrorBudget):
        return tolerances
    if not isinstance(tolerances, Mapping):
        raise TypeError(f"tolerances: expected a mapping with keys {', '.join(_KEYS)}, got {type(tolerances).__name__}")
    for k in tolerances:
        if k not in _KEYS:
            raise InputError(f"tolerances: unknown key {k!r}; expected some of {', '.join(_KEYS)}")

    def num(key: str, v) -> float:
        try:
            x = float(v)
        except (TypeError, ValueError):
            raise InputError(f"tolerances.{key}: expected a number, got {v!r}") from None
        if not np.isfinite(x) or x < 0:
            raise InputError(f"tolerances.{key}: expected a finite number >= 0, got {v!r}")
        return x

    act = tolerances.get("actuator", 0.0)
    act_v: float | dict[str, float] = ({str(k): num(f"actuator.{k}", v) for k, v in act.items()}
                                       if isinstance(act, Mapping) else num("actuator", act))
    axis = tolerances.get("axis")
    return ErrorBudget(act_v, num("clearance", tolerances.get("clearance", 0.0)),
                       num("geometry", tolerances.get("geometry", 0.0)), None if axis is None else num("axis", axis))


def _comp(v) -> dict:
    """``{position_len: [dx, dy, dz], rotation_deg: [rx, ry, rz]}`` (``null`` where not finite)."""
    v = np.asarray(v, dtype=float)
    out = np.concatenate([v[:3], np.degrees(v[3:])])
    vals = [None if not np.isfinite(x) else float(x) for x in out]
    return {"position_len": vals[:3], "rotation_deg": vals[3:]}


def _tolerance(p) -> dict:
    return {"tolerance_len": p.tolerance} if p.unit == "m" else {"tolerance_deg": float(np.degrees(p.tolerance))}


@dataclass(frozen=True, eq=False)
class AccuracyResult:
    """Output pose errors at one configuration (:func:`accuracy`); ``analysis`` holds the arrays:
    ``G`` (6, n) the first-order sensitivities (rows :data:`COMPONENTS`: ``dx, dy, dz`` of the
    output point in m, the rotation vector in rad), ``worst_case``, ``exact_at_worst``,
    ``std_first_order``, ``mc_errors`` (samples, 6), ``breakdown``."""

    mechanism: Mechanism
    config: Configuration
    analysis: AccuracyAnalysis
    pose_fit: PoseFit | None = None

    @property
    def worst_case(self) -> np.ndarray:
        return self.analysis.worst_case

    @property
    def std_first_order(self) -> np.ndarray:
        return self.analysis.std_first_order

    @property
    def std_monte_carlo(self) -> np.ndarray:
        e = self.analysis.mc_errors
        return e.std(axis=0, ddof=1) if e.shape[0] > 1 else np.full(6, np.nan)

    @property
    def loses_mobility(self) -> bool:
        b = self.analysis.breakdown
        return bool(b is not None and b.loses_mobility)

    def to_dict(self) -> dict:
        """JSON (``spatialmech accuracy --json``, docs/json.md): each estimate as ``position_len``
        (the output point's dx, dy, dz) and ``rotation_deg`` (the rotation vector): the first-order
        standard deviation, the worst case over the box and the exact model at its vertex, the
        Monte-Carlo statistics; each parameter's effect at its tolerance; ``residual``: the relative
        inconsistency of the first-order solve (redundant constraints); the mobility check (``k``:
        the tolerance scale that removes a freedom, ``loss_rate``: the deciding singular value per
        unit scale, ``tol``: the rank tolerance)."""
        a, mech = self.analysis, self.mechanism
        P = platform_pose(mech, self.config)
        mc = a.mc_errors
        n_ok = int(mc.shape[0])
        within = (np.all(np.abs(mc) <= a.worst_case[None, :] * (1 + 1e-9) + 1e-15, axis=0) if n_ok else
                  np.zeros(6, bool))
        bd = a.breakdown
        return {
            "result": "accuracy",
            "pose": pose_dict(P.R, P.p),
            "output_point_len": [float(v) for v in P.p],
            "error_model": ERROR_MODEL,
            "parameters": [{"name": p.name, "kind": p.kind, **_tolerance(p)} for p in a.params],
            "std_first_order": _comp(a.std_first_order),
            "first_order_distribution": "independent, uniform over each tolerance interval (variance t^2 / 3)",
            "worst_case": _comp(a.worst_case),
            "worst_case_method": "sum_i |G_ci| t_i per component: exact for the linearisation (box vertex t sign(G_c))",
            "exact_at_worst_vertex": _comp(a.exact_at_worst),
            "position_norm_bound_len": float(np.linalg.norm(a.worst_case[:3])),
            "effect_at_tolerance": {p.name: _comp(a.G[:, i] * p.tolerance) for i, p in enumerate(a.params)},
            "residual": a.inconsistency,
            "monte_carlo": {"samples": a.samples, "n_converged": n_ok, "failed": a.mc_failures, "seed": a.seed,
                            "mean": _comp(mc.mean(axis=0) if n_ok else np.full(6, np.nan)),
                            "std": _comp(self.std_monte_carlo),
                            "max_abs": _comp(np.abs(mc).max(axis=0) if n_ok else np.full(6, np.nan)),
                            "within_worst_case": bool(np.all(within)) if n_ok else None},
            "mobility_under_tolerances": None if bd is None else {
                "dof": bd.nominal_dof, "dof_instantaneous": bd.perturbed_dof, "loses_mobility": bd.loses_mobility,
                "k": bd.breaks_at_scale,
                "breaks_at_point_len": bd.breaks_at_point_m,
                "breaks_at_axis_deg": None if bd.breaks_at_axis_rad is None else float(np.degrees(bd.breaks_at_axis_rad)),
                "loss_rate": bd.rate, "tol": bd.rank_tolerance, "seed": bd.seed, "method": bd.method},
            "pose_fit": None if self.pose_fit is None else self.pose_fit.to_dict(),
        }


def accuracy(model: ModelLike, pose=None, *, tolerances, config: Configuration | None = None, samples: int = 200,
             seed: int = 0, mode: str | None = None, degrees: bool = False, mobility_check: bool = True
             ) -> AccuracyResult:
    """Accuracy at a pose: the output pose error produced by actuator errors, joint clearances and
    manufacturing tolerances of the joint points and axes, to first order, in the worst case over
    the tolerance box and by Monte-Carlo with the exact forward position (docs/accuracy.md).

    Parameters
    ----------
    model : Mechanism, str or path
        A mechanism, a ready-made model name (``sm.models()``) or a TOML file.
    pose : Pose, tuple or int, optional
        The output link's pose (fitted onto the closure, see :mod:`spatialmech.api`); default the
        reference configuration.
    tolerances : mapping
        Half-widths of the tolerance box, SI: ``actuator`` (each actuator's own unit, m or rad; a
        number or a mapping by actuator name), ``clearance`` (m, per passive joint and world
        axis), ``geometry`` (m, per joint point component), ``axis`` (rad, per axis rotation;
        default ``geometry / L``, L the characteristic length).  Missing keys are 0.
    config : Configuration, optional
        A configuration instead of a pose.
    samples : int
        Monte-Carlo samples (0: none).
    seed : int
        Seed of the Monte-Carlo samples and of the mobility check's direction.
    mode : str, optional
        The mode of a metamorphic mechanism.
    degrees : bool
        Read a pose tuple's Euler angles in degrees.
    mobility_check : bool
        Search the smallest tolerance scale that removes a degree of freedom (overconstrained designs).

    Returns
    -------
    AccuracyResult
        ``worst_case`` and ``std_first_order`` (6,: ``dx, dy, dz`` of the output point in m, the
        rotation vector in rad), ``std_monte_carlo``, ``loses_mobility``; ``analysis`` holds the
        sensitivities ``G`` and the samples; ``to_dict()`` is the JSON.

    Raises
    ------
    TypeError
        A wrong type of model, pose or tolerances.
    InputError
        A negative or non-finite tolerance, an unknown key, every tolerance zero; a pose with no
        closed configuration near it; a singular pose (the output error is not determined).

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.accuracy("stewart-6sps", ([0.05, 0, 1.0], ("ZYX", 10, 0, 0)), degrees=True,
    ...                 tolerances={"actuator": 1e-5, "geometry": 1e-5}, samples=20)
    >>> bool(r.worst_case[0] > r.std_first_order[0] > 0), r.loses_mobility
    (True, False)
    """
    mech = as_mechanism(model)
    if mode is not None:
        mech = mech.in_mode(mode)
    elif mech.is_metamorphic:
        raise InputError(f"mode: {mech.name} is metamorphic with modes {', '.join(m.name for m in mech.all_modes())}; "
                         "name one")
    degrees = check_bool(degrees, "degrees")
    budget = _budget(tolerances)
    samples = check_int(samples, "samples", minimum=0)
    seed = check_int(seed, "seed")
    c, fit = as_configuration(mech, pose, config, degrees)
    a = accuracy_analysis(mech, c, budget, samples=samples, seed=seed, breakdown=check_bool(mobility_check,
                                                                                          "mobility_check"))
    return AccuracyResult(mech, c, a, fit)
