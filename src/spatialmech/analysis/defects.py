"""Defect judgement of one-degree-of-freedom rigid-body guidance linkages (paper A, sections 2.3,
4, 5, 6), for any 1-DOF mechanism (5-CS, planar/spherical 4R, RSSR, RCCC, ...).

Procedure (paper A fig 5, made general):

1. every task position is fitted onto the closure manifold (the printed poses are rounded: the
   pose error of each fit is reported);
2. ``DJ`` (the determinant of the complete Jacobian for one driver; or, where the complete
   Jacobian is not square because of redundant constraints, the sign-continuous cofactor of
   the closure Jacobian without the driver's column, which vanishes at the same points) is
   evaluated at every position for every candidate driver;
3. the circuit through position 1 is traced with the continuation tracker until it closes,
   locating every zero of every driver's DJ (a *branch point*: the driver reaches a turning
   point there; sign changes through a pole of DJ — where the driver's own limb is serially
   singular and the output turns back while the driver moves on — are counted apart); a
   position lies on the traced circuit when the curve passes through its
   fitted configuration (to ``on_curve_tol``, nondimensional), which also gives its arc
   length; positions not on it get circuits of their own, traced the same way;
4. verdicts: circuit defect (positions on several circuits), order defect (positions not met
   in their order along the circuit, in either direction), branch defect per driver (DJ zero
   between the first and the last position along the path), usable drivers, and, when none is
   usable but there is no circuit or order defect, a multi-drive plan that switches drivers
   inside intervals free of their singularities (paper A section 6);
5. robustness: the smallest scale-free singular value along the path (distance to the nearest
   singularity of the linkage and of each usable/planned driver) and, optionally, a seeded
   Monte-Carlo check of the verdicts against perturbations of the data at its printed
   precision.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import cast

import numpy as np

from ..errors import InputError
from ..geometry import screws as sc
from ..kinematics.closure import Configuration, active_mask, closure_scales
from ..kinematics.backend import closure_jacobian
from ..kinematics.jacobian import complete_jacobians, driver_determinants
from ..geometry.tolerances import Tolerances
from ..geometry.tolerances import current as current_tolerances
from ..geometry.tolerances import use as use_tolerances
from ..kinematics.position import PoseFit, configuration_at_pose, freedom_values
from ..kinematics.tracking import DriverMonitor, MotionProblem, TrackResult
from ..model.joints import make_joint
from ..model.mechanism import Mechanism, Pose
from ..results import Progress, Steps, TrackStatus
from .defect_circuits import (
    arc_on_curve,
    closure_sigma_ratios,
    driver_sigmas,
    fewest_circuits,
    pose_distance,
    positions_between,
    switching_plan,
    trace_circuit,
)

__all__ = [
    "BranchPoint",
    "DJTable",
    "DefectResult",
    "DriverVerdict",
    "PlanStep",
    "candidate_drivers",
    "defect_analysis",
    "dj_function",
    "dj_table",
    "perturbed",
]


def candidate_drivers(mech: Mechanism) -> list[str]:
    """Every freedom of each limb's base joint (the natural actuator places), by alias when the
    model defines one (``rot1`` ... ``slide5`` for the 5-CS)."""
    alias_of = {v: k for k, v in mech.aliases.items()}
    out = []
    for limb in mech.limbs:
        j = limb.joints[0]
        for f in j.freedoms:
            if not f.locked:
                fid = f"{j.name}.{f.name}"
                out.append(alias_of.get(fid, fid))
    return out


def dj_function(mech: Mechanism, drivers: list[str], reference: Configuration):
    """A function ``config -> array of DJ per driver`` whose signs are comparable between
    configurations.  The complete-Jacobian determinant when it is square (paper A), else the
    cofactor of the nondimensional closure Jacobian without the driver's column, its rows
    projected on the row space at ``reference`` (sign-continuous, zero at the same points)."""
    test = driver_determinants(mech, reference, drivers)
    if np.all(np.isfinite(test)):
        return DriverMonitor(mech, drivers), "complete Jacobian determinant"
    active = active_mask(mech)
    row, col = closure_scales(mech, active)
    A0, _ = closure_jacobian(mech, reference, active=active)
    A0 = row[:, None] * A0 * col[None, :]
    U, sv, _ = np.linalg.svd(A0)
    r = int(np.sum(sv > current_tolerances().rank * sv[0]))
    P = U[:, :r].T
    # orient the row-space basis against its reduced row-echelon basis (the same for every
    # orthonormal basis of the row space), so that the sign of DJ does not follow the basis the
    # SVD returned (docs/conventions.md)
    E = sc.rref(P)
    if E.shape[0] == P.shape[0] and np.linalg.det(P @ E.T) < 0:
        P[0] = -P[0]
    idx = np.flatnonzero(active).tolist()
    cols = [idx.index(mech.freedom_refs.index(mech.freedom(d))) for d in drivers]

    def f(c):
        A, _ = closure_jacobian(mech, c, active=active)
        B = P @ (row[:, None] * A * col[None, :])
        out = np.empty(len(cols))
        for n, j in enumerate(cols):
            M = np.delete(B, j, axis=1)
            out[n] = np.linalg.det(M) if M.shape[0] == M.shape[1] else np.nan
        return out

    return f, "cofactor of the closure Jacobian without the driver (redundant constraints)"


@dataclass(frozen=True)
class BranchPoint:
    """A zero of a driver's DJ along a traced circuit: the driver reaches a turning point."""

    driver: str
    circuit: int
    arc: float  # nondimensional arc length from the circuit's first position
    between: tuple[int, int] | None  # positions (from 1) it lies between along the path
    point: tuple[float, float, float]  # platform point there
    driver_value: float  # the driver's value there (rad or length)

    def to_dict(self, rotational: bool) -> dict:
        """JSON (docs/json.md): ``driver_value_deg`` for a rotational driver, else
        ``driver_value_len``; ``platform_point_len``; ``arc`` nondimensional."""
        value = {"driver_value_deg": float(np.degrees(self.driver_value))} if rotational else {
            "driver_value_len": float(self.driver_value)}
        return {
            "driver": self.driver,
            "circuit": self.circuit,
            "arc": self.arc,
            "between": list(self.between) if self.between else None,
            "platform_point_len": [float(x) for x in self.point],
            **value,
        }


@dataclass(frozen=True)
class DriverVerdict:
    driver: str
    dj: tuple[float, ...]
    signs: tuple[int, ...]
    keeps_sign: bool
    branch_points: tuple[BranchPoint, ...]  # on the path from the first to the last position
    circuit_branch_points: tuple[BranchPoint, ...]  # everywhere on the traced circuit(s)
    branch_defect: bool
    usable: bool
    min_sigma_on_path: float | None = None  # scale-free distance to this driver's singularity
    inverse_singular_points: int = 0  # DJ poles on the circuit(s): the driver's limb is serially singular

    def to_dict(self, rotational: bool) -> dict:
        return {
            "driver": self.driver,
            "dj": list(self.dj),
            "signs": list(self.signs),
            "keeps_sign": self.keeps_sign,
            "branch_points": [b.to_dict(rotational) for b in self.branch_points],
            "circuit_branch_points": [b.to_dict(rotational) for b in self.circuit_branch_points],
            "branch_defect": self.branch_defect,
            "usable": self.usable,
            "min_sigma_on_path": self.min_sigma_on_path,
            "inverse_singular_points": self.inverse_singular_points,
        }


@dataclass(frozen=True)
class PlanStep:
    driver: str
    start_arc: float
    end_arc: float
    switch_window: tuple[float, float] | None  # arc interval in which to switch to the next driver
    switch_between: tuple[int, int] | None  # positions bracketing the window's middle

    def to_dict(self) -> dict:
        """JSON (docs/json.md): arcs (``from``, ``to``, ``switch_window``) nondimensional."""
        return {
            "driver": self.driver,
            "from": self.start_arc,
            "to": self.end_arc,
            "switch_window": list(self.switch_window) if self.switch_window else None,
            "switch_between": list(self.switch_between) if self.switch_between else None,
        }


@dataclass(frozen=True, eq=False)
class DefectResult:
    mechanism: str
    drivers: tuple[DriverVerdict, ...]
    circuits: tuple[tuple[int, ...], ...]
    circuit_closed: tuple[bool, ...]
    circuit_status: tuple[TrackStatus, ...]
    circuit_defect: bool
    order_defect: bool
    order: tuple[int, ...]  # positions of the first circuit in the order they are met
    direction: int  # +1: the path runs along the traced direction; -1: against it
    position_arcs: tuple[float | None, ...]  # along the first circuit, from position 1, along the path
    path_length: float | None
    usable_drivers: tuple[str, ...]
    plan: tuple[PlanStep, ...] | None
    fits: tuple[PoseFit, ...]
    dj_method: str
    min_closure_sigma: float | None  # scale-free closeness of the path to a singularity of the linkage
    min_closure_sigma_between: tuple[int, int] | None
    membership: tuple = ()
    tolerances: dict = field(default_factory=dict)
    table: DJTable | None = None
    robustness: dict = field(default_factory=dict)
    traces: tuple = ()  # TrackResult per circuit (for figures; not serialised)
    rotational: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "mechanism": self.mechanism,
            "circuits": [list(c) for c in self.circuits],
            "circuit_closed": list(self.circuit_closed),
            "circuit_status": list(self.circuit_status),
            "order_defect": self.order_defect,
            "circuit_defect": self.circuit_defect,
            "order": list(self.order),
            "path_direction": self.direction,
            "position_arcs": list(self.position_arcs),
            "path_length": self.path_length,
            "drivers": [d.to_dict(self.rotational.get(d.driver, True)) for d in self.drivers],
            "usable_drivers": list(self.usable_drivers),
            "plan": [p.to_dict() for p in self.plan] if self.plan is not None else None,
            "pose_fit": [f.to_dict() for f in self.fits],
            "dj_method": self.dj_method,
            "min_closure_sigma_on_path": self.min_closure_sigma,
            "min_closure_sigma_between": list(self.min_closure_sigma_between) if self.min_closure_sigma_between else None,
            "membership": [_membership_json(m) for m in self.membership],
            "tolerances": _renamed(self.tolerances, {"pose": "pose_len"}),
            "robustness": _renamed(self.robustness, {"precision_length": "precision_len"}),
            "arc_note": "arc: nondimensional arc length of the tracked curve (joint rad, lengths / L)",
        }


def _renamed(d: dict, names: dict[str, str]) -> dict:
    """``d`` with keys renamed for JSON (units in the key names, docs/json.md)."""
    return {names.get(k, k): v for k, v in d.items()}


def _membership_json(m: dict) -> dict:
    """One position's circuit membership for JSON: units in the key names."""
    out = _renamed(m, {"position": "position_number"})
    if isinstance(out.get("distance"), dict):
        out["distance"] = _renamed(out["distance"], {"position": "position_len"})
    return out


@dataclass(frozen=True, eq=False)
class DJTable:
    """``DJ`` (det of the complete Jacobian) at a mechanism's task positions, per driver.

    ``dj`` (n_drivers, n_positions): only the signs along one row are comparable;
    ``sigma_min`` the scale-free smallest singular value (0 at a singularity; computed when it
    is first asked for, under the tolerances in force when the table was made); ``fits`` the
    closed configurations fitted to the (rounded, printed) positions, with their errors.
    """

    model: str
    positions: tuple[str, ...]
    drivers: tuple[str, ...]
    dj: np.ndarray
    fits: tuple[PoseFit, ...]
    mech: Mechanism = field(repr=False)  # the linkage, for sigma_min
    tolerances: Tolerances = field(repr=False)  # in force when the table was made

    @cached_property
    def sigma_min(self) -> np.ndarray:
        """The scale-free smallest singular value of each driver's complete Jacobian at each
        position ``(n_drivers, n_positions)``."""
        sig = np.empty_like(self.dj)
        with use_tolerances(self.tolerances):
            for k, f in enumerate(self.fits):  # one set of constraint wrenches per position, shared by the drivers
                for i, cj in enumerate(complete_jacobians(self.mech, f.config, [[d] for d in self.drivers])):
                    sig[i, k] = cj.sigma_min
        return sig

    @property
    def signs(self) -> np.ndarray:
        return np.sign(self.dj).astype(int)

    def keeps_sign(self, driver: str) -> bool:
        s = self.signs[self.drivers.index(driver)]
        return bool(np.all(s == s[0]) and s[0] != 0)

    def changes(self, driver: str) -> list[int]:
        """Indices ``k`` where the sign changes between positions ``k`` and ``k + 1``."""
        s = self.signs[self.drivers.index(driver)]
        return [int(k) for k in np.flatnonzero(s[1:] != s[:-1])]

    def to_dict(self) -> dict:
        """JSON (docs/json.md): per driver its ``dj`` and ``signs`` at the positions, whether it
        keeps its sign, and the scale-free ``sigma_min``; the pose fits of the positions."""
        return {
            "mechanism": self.model,
            "positions": list(self.positions),
            "drivers": [
                {"driver": d, "dj": [float(x) for x in self.dj[i]], "signs": [int(x) for x in self.signs[i]],
                 "keeps_sign": self.keeps_sign(d), "sigma_min": [float(x) for x in self.sigma_min[i]]}
                for i, d in enumerate(self.drivers)
            ],
            "pose_fit": [f.to_dict() for f in self.fits],
            "note": "DJ magnitudes are not comparable between drivers; only signs along one driver are.",
        }


def dj_table(mech: Mechanism, drivers=None, positions=None) -> DJTable:
    """DJ at every task position of ``mech`` for each driver (default :func:`candidate_drivers`).

    The positions are fitted onto the closure in order, each fit starting from the previous
    one (:func:`configuration_at_pose`).  Raises ``ValueError`` when the model has no task
    positions or a position cannot be fitted.

    Example: ``dj_table(catalog.build("five-cs-3")).keeps_sign("rot1")`` is True (paper A
    fig 15).
    """
    positions = tuple(positions if positions is not None else mech.positions)
    if not positions:
        raise InputError(f"mech: {mech.name} has no task positions")
    drivers = tuple(drivers) if drivers is not None else tuple(candidate_drivers(mech))
    fits, prev = [], None
    for P in positions:
        fit = configuration_at_pose(mech, P, start=prev)
        if not fit.converged:
            raise InputError(f"positions: {P.name or 'a position'} has no closed configuration near it "
                             f"(residual {fit.ik_residual:.2e}): is it reachable by this linkage?")
        fits.append(fit)
        prev = fit.config
    djf, _ = dj_function(mech, list(drivers), fits[0].config)
    dj = np.array([djf(f.config) for f in fits]).T
    # sigma_min is computed when first read (the defect analysis never reads it)
    return DJTable(mech.name, tuple(p.name for p in positions), drivers, dj, tuple(fits), mech, current_tolerances())



def perturbed(mech: Mechanism, positions, rng: np.random.Generator, length: float, angle_deg: float):
    """A copy of ``mech`` and ``positions`` with every joint point and axis and every position
    perturbed uniformly within the printed precision (``length``; axes by ``length`` per
    component then normalised; position angles by ``angle_deg`` about each axis)."""
    from scipy.spatial.transform import Rotation

    def jitter(v):
        return np.asarray(v, float) + rng.uniform(-length, length, 3)

    limbs = []
    for limb in mech.limbs:
        joints = []
        for j in limb.joints:
            fs = j.freedoms
            kw = dict(point=jitter(j.point), pitch=fs[0].pitch,
                      actuated=[f.name for f in fs if f.actuated], lockable=[f.name for f in fs if f.lockable],
                      locked=[f.name for f in fs if f.locked],
                      limits={f.name: f.limits for f in fs if f.limits is not None} or None,
                      offset={f.name: f.offset for f in fs if f.offset}, freedom_names=[f.name for f in fs])
            if j.type in ("R", "P", "H", "C"):
                ax = jitter(fs[0].direction)
                kw["axis"] = ax / np.linalg.norm(ax)
            elif j.type == "U":
                a1 = jitter(fs[0].direction)
                a1 /= np.linalg.norm(a1)
                a2 = jitter(fs[1].direction)
                a2 -= (a2 @ a1) * a1
                a2 /= np.linalg.norm(a2)
                kw["axes"] = [a1, a2]
            else:
                kw["axes"] = [f.direction for f in fs]
            joints.append(make_joint(j.type, j.name, **kw))
        limbs.append(limb.with_joints(joints))
    new_pos = []
    for P in positions:
        dR = Rotation.from_rotvec(np.radians(rng.uniform(-angle_deg, angle_deg, 3))).as_matrix()
        new_pos.append(Pose(dR @ P.R, jitter(P.p), P.name))
    return replace(mech, limbs=tuple(limbs), positions=tuple(new_pos)), new_pos


# ----------------------------------------------------------------------------- analysis
def defect_analysis(
    mech: Mechanism,
    positions=None,
    *,
    drivers=None,
    on_curve_tol: float = 1e-6,
    pose_tol: float | None = None,
    angle_tol_deg: float = 1.0,
    max_arc: float = 400.0,
    h0: float = 0.02,
    monte_carlo: int = 0,
    seed: int = 0,
    precision: float = 5e-4,
    angle_precision_deg: float = 0.05,
    sigma_along_path: bool = True,
    progress: Progress | None = None,
    sense: int = 1,
    check_dof: bool = True,
    table: DJTable | None = None,
) -> DefectResult:
    """Defect judgement of a 1-DOF linkage for its task positions (default: the model's own).

    A printed position belongs to a circuit when the circuit passes within ``pose_tol`` (length;
    default 2 % of the characteristic length) and ``angle_tol_deg`` of it (combined as
    ``hypot(dp / pose_tol, dtheta / angle_tol) <= 1``); among the traced circuits the fewest
    that hold every position are kept.  ``progress(done, None, message)`` is called with the
    number of the step and a short message while it works.  ``sense``: the sense every circuit
    is traced in (``1``: the conventional one of :func:`~..kinematics.tracking.trace_motion`,
    ``-1``: the opposite); the verdict (circuits, defects, usable drivers) does not depend on it,
    only the traced arcs and ``direction`` do.  ``check_dof=False`` skips the mobility check of
    step 0 for a caller that has already shown one degree of freedom (the screen: a closure
    Jacobian of full row rank at a task position, so of full row rank generically).  ``table``:
    the :class:`DJTable` of these positions and drivers when the caller already has one (the
    screen builds it from the closed-form configurations of a 5-CS); by default
    :func:`dj_table` fits the positions.

    The steps (module docstring): :func:`_checked_arguments`, :func:`dj_table` (fits and DJ),
    :func:`_trace_circuits`, :func:`_assign_circuits`, :func:`_path_along_first_circuit`,
    :func:`_driver_verdict` per driver, :func:`_drive_plan`, :func:`_distance_to_singularities`
    and, optionally, :func:`_monte_carlo`.
    """
    say = Steps(progress)
    positions, drivers, pose_tol = _checked_arguments(mech, positions, drivers, pose_tol=pose_tol,
                                                      angle_tol_deg=angle_tol_deg, precision=precision,
                                                      monte_carlo=monte_carlo, check_dof=check_dof)
    if table is None:
        say("fitting the task positions onto the closure; DJ at every position")
        table = dj_table(mech, drivers, positions)
    elif not (table.mech is mech and table.drivers == tuple(drivers) and len(table.fits) == len(positions)
              and table.positions == tuple(p.name for p in positions)):
        raise InputError(f"table: a DJ table of {table.model} for drivers {list(table.drivers)} at "
                         f"{len(table.fits)} positions, not of this linkage, these drivers and positions")
    fits = list(table.fits)
    djf, dj_method = dj_function(mech, drivers, fits[0].config)
    dj_pos = table.dj.T  # (positions, drivers)

    problems, traces, on_curve = _trace_circuits(mech, fits, drivers, djf, on_curve_tol, max_arc, h0, say, sense)
    say("assigning the positions to circuits")
    circ = _assign_circuits(mech, positions, fits, problems, traces, pose_tol=pose_tol,
                            angle_tol=np.radians(angle_tol_deg), on_curve_tol=on_curve_tol, on_curve=on_curve)
    circuit_defect = len(circ.circuits) > 1
    path = _path_along_first_circuit(circ)
    order_defect = path.order_defect

    verdicts: list[DriverVerdict] = []
    zeros_on_path: dict[str, list[float]] = {}
    for di, d in enumerate(drivers):
        verdict = _driver_verdict(mech, d, dj_pos[:, di], circ.traces, path, circuit_defect=circuit_defect,
                                  order_defect=order_defect)
        verdicts.append(verdict)
        zeros_on_path[d] = [b.arc for b in verdict.branch_points]
    usable = tuple(v.driver for v in verdicts if v.usable)
    plan = None
    if not usable and not circuit_defect and not order_defect:
        plan = _drive_plan(drivers, zeros_on_path, path)

    min_sig, min_between = None, None
    if sigma_along_path and not circuit_defect:
        say("measuring the distance to singularities along the path")
        watch = set(usable) | ({s.driver for s in plan} if plan else set())
        min_sig, min_between, verdicts = _distance_to_singularities(mech, circ.problems[0], circ.traces[0], path,
                                                                    verdicts, watch)

    rot = {d: mech.freedom(d).freedom.kind != "P" for d in drivers}
    result = DefectResult(
        mechanism=mech.name, drivers=tuple(verdicts), circuits=tuple(circ.circuits),
        circuit_closed=tuple(tr.closed for tr in circ.traces), circuit_status=tuple(tr.status for tr in circ.traces),
        circuit_defect=circuit_defect, order_defect=order_defect, order=tuple(path.order),
        direction=path.direction, position_arcs=tuple(path.position_arcs),
        path_length=float(path.end) if not circuit_defect else None,
        usable_drivers=usable, plan=plan, fits=tuple(fits), dj_method=dj_method, min_closure_sigma=min_sig,
        min_closure_sigma_between=min_between, traces=tuple(circ.traces), rotational=rot,
        membership=tuple(circ.membership),
        tolerances={"pose": pose_tol, "angle_deg": angle_tol_deg, "on_curve": on_curve_tol}, table=table,
    )
    if monte_carlo:
        result = replace(result, robustness=_monte_carlo(mech, positions, result, monte_carlo, seed, precision,
                                                         angle_precision_deg, drivers, max_arc, h0, say))
    return result


# ----------------------------------------------------------------------------- its steps
def _checked_arguments(mech: Mechanism, positions, drivers, *, pose_tol: float | None, angle_tol_deg: float,
                       precision: float, monte_carlo: int,
                       check_dof: bool = True) -> tuple[tuple[Pose, ...], list[str], float]:
    """Step 0: the arguments of :func:`defect_analysis` checked (an ``InputError`` naming the
    argument), the defaults filled in.  The mechanism must have one degree of freedom and, when
    metamorphic, be in one mode (not checked with ``check_dof=False``).  Returns
    ``(positions, drivers, pose_tol)``."""
    if pose_tol is None:
        pose_tol = 0.02 * mech.characteristic_length
    for name, v in (("pose_tol", pose_tol), ("angle_tol_deg", angle_tol_deg)):
        if not (np.isfinite(v) and v > 0):
            raise InputError(f"{name}: expected a positive finite number, got {v}")
    if not (np.isfinite(precision) and precision >= 0):
        raise InputError(f"precision: expected a finite number >= 0, got {precision}")
    if int(monte_carlo) != monte_carlo or monte_carlo < 0:
        raise InputError(f"monte_carlo: expected a number of samples >= 0, got {monte_carlo}")
    positions = tuple(positions if positions is not None else mech.positions)
    if len(positions) < 2:
        raise InputError("positions: a defect analysis needs at least two task positions")
    if check_dof:
        _check_one_dof(mech)
    drivers = list(drivers) if drivers is not None else candidate_drivers(mech)
    if not drivers:
        raise InputError("drivers: no candidate drivers")
    for d in drivers:
        mech.freedom(d)  # raises on unknown names
    return positions, drivers, pose_tol


def _check_one_dof(mech: Mechanism) -> None:
    """An ``InputError`` unless ``mech`` has one (instantaneous) degree of freedom in one mode."""
    from .mobility import mobility

    if mech.is_metamorphic and len(mech.all_modes()) > 1:
        raise InputError(f"mechanism: {mech.name} is metamorphic; analyse one mode (mech.in_mode(name))")
    dof = mobility(mech).dof_instantaneous
    if dof != 1:
        raise InputError(f"mechanism: the defect analysis is for one-degree-of-freedom linkages; {mech.name} has {dof}")


#: :func:`arc_on_curve`'s answer by (traced circuit, position), both from 0.
_OnCurve = dict[tuple[int, int], float | None]


def _trace_circuits(mech: Mechanism, fits: list[PoseFit], drivers: list[str], djf, on_curve_tol: float,
                    max_arc: float, h0: float, say: Steps,
                    sense: int = 1) -> tuple[list[MotionProblem], list[TrackResult], _OnCurve]:
    """Step 3a: trace circuits until every fitted position lies on a traced curve (to
    ``on_curve_tol``, nondimensional): the circuit through position 1, then one through each
    position that no traced circuit passes through, in order.  Also returns the
    :func:`arc_on_curve` answers it computed, by (circuit, position), for
    :func:`_assign_circuits` to reuse."""
    traces: list[TrackResult] = []
    problems: list[MotionProblem] = []
    on_curve: _OnCurve = {}
    for j, fit in enumerate(fits):
        found = False
        for c, (pr, tr) in enumerate(zip(problems, traces, strict=True)):
            on_curve[c, j] = arc_on_curve(pr, tr, fit.config, on_curve_tol)
            if on_curve[c, j] is not None:
                found = True
                break
        if found:
            continue
        say(f"tracing the circuit through position {j + 1}")
        prob, tr = trace_circuit(mech, fit.config, drivers, djf, max_arc, h0, None, sense=sense)
        traces.append(tr)
        problems.append(prob)
    return problems, traces, on_curve


@dataclass(frozen=True, eq=False)
class _Circuits:
    """The circuits kept by :func:`_assign_circuits`, in the order of their first position."""

    problems: list[MotionProblem]
    traces: list[TrackResult]
    circuit_of: list[int]  # the circuit (from 0) of each position
    circuits: list[tuple[int, ...]]  # the positions (from 1) on each circuit
    arcs_on: list[float]  # traced arc of each position on the first circuit (nan on the others)
    membership: list[dict]  # per position: its circuit, its distance from it, other circuits near it


def _assign_circuits(mech: Mechanism, positions, fits: list[PoseFit], problems: list[MotionProblem],
                     traces: list[TrackResult], *, pose_tol: float, angle_tol: float, on_curve_tol: float,
                     on_curve: _OnCurve | None = None) -> _Circuits:
    """Step 3b: every position's distance from every traced circuit (0 when its fitted
    configuration lies on it; else the normalised distance of the printed pose,
    :func:`pose_distance`, ``angle_tol`` in rad), the fewest circuits that hold every position
    (:func:`fewest_circuits`), each position on its nearest kept circuit; the kept circuits are
    renumbered in the order of their first position.  ``on_curve``: :func:`arc_on_curve`'s
    answers already computed (by :func:`_trace_circuits`), by (circuit, position)."""
    n = len(positions)
    Dm = np.empty((len(traces), n))
    meas: dict[tuple[int, int], tuple[float, float, float, float]] = {}
    for c, (pr, tr) in enumerate(zip(problems, traces, strict=True)):
        for j, P in enumerate(positions):
            # exactly on the curve (the fitted configuration itself): unambiguous, even where the
            # platform takes the same pose twice on a circuit; else the nearest pose on the curve
            if tr.points[0] is fits[j].config:
                a: float | None = 0.0
            elif on_curve is not None and (c, j) in on_curve:  # already asked by _trace_circuits
                a = on_curve[c, j]
            else:
                a = arc_on_curve(pr, tr, fits[j].config, on_curve_tol)
            if a is not None:
                meas[c, j] = (0.0, float(a), fits[j].position_error, fits[j].angle_error)
            else:
                meas[c, j] = pose_distance(mech, pr, tr, P, pose_tol, angle_tol)
            Dm[c, j] = meas[c, j][0]
    chosen = fewest_circuits(Dm)
    nearest = [min(chosen, key=lambda c: Dm[c, j]) for j in range(n)]
    order_c = sorted(chosen, key=lambda c: min(j for j in range(n) if nearest[j] == c))
    remap = {c: k for k, c in enumerate(order_c)}
    circuit_of = [remap[c] for c in nearest]
    circuits = [tuple(j + 1 for j in range(n) if circuit_of[j] == k) for k in range(len(order_c))]
    arcs_on = [meas[order_c[0], j][1] if circuit_of[j] == 0 else np.nan for j in range(n)]
    membership = [{"position": j + 1, "circuit": circuit_of[j] + 1,
                   "distance": {"position": meas[nearest[j], j][2],
                                "angle_deg": float(np.degrees(meas[nearest[j], j][3]))},
                   # other traced circuits that also pass within tolerance: kept ones by number, the
                   # ones the fewest-circuits cover dropped as "extra"
                   "also_within_tolerance_of": [remap[c] + 1 if c in remap else "extra" for c in range(len(Dm))
                                                if c != nearest[j] and Dm[c, j] <= 1.0]}
                  for j in range(n)]
    return _Circuits([problems[c] for c in order_c], [traces[c] for c in order_c], circuit_of, circuits, arcs_on,
                     membership)


def _along(arc_traced: float, period: float | None, direction: int) -> float:
    """A traced arc as an arc along the path: modulo the circuit's length when it closed,
    reversed when the path runs against the traced direction."""
    if direction == 1:
        return arc_traced % period if period else arc_traced
    return ((period - arc_traced) % period) if period else -arc_traced


@dataclass(frozen=True)
class _Path:
    """The path from position 1 along the first circuit (:func:`_path_along_first_circuit`)."""

    direction: int  # +1 along the traced direction, -1 against it
    order: list[int]  # positions (from 1) on the first circuit in the order the path meets them
    expected: list[int]  # the same positions in their given order
    path_arcs: list[float]  # their arcs along the path, sorted
    position_arcs: list[float | None]  # arc along the path of every position (None off the first circuit)
    period: float | None  # length of the first circuit when it closed

    @property
    def end(self) -> float:
        """Arc of the last position met along the path (0 without positions)."""
        return self.path_arcs[-1] if self.path_arcs else 0.0

    @property
    def order_defect(self) -> bool:
        return self.order != self.expected

    def to_path(self, arc_traced: float) -> float:
        return _along(arc_traced, self.period, self.direction)


def _path_along_first_circuit(circ: _Circuits) -> _Path:
    """Step 4a: order and direction along the first circuit.  The positions on it are sorted by
    their arcs both ways round; the direction in which they come in their given order is the
    path's (forward when neither does: an order defect)."""
    tr0 = circ.traces[0]
    S = tr0.s[-1] if tr0.closed else None
    on0 = [i for i, c in enumerate(circ.circuit_of) if c == 0]
    expected = [i + 1 for i in on0]
    fwd = [_along(circ.arcs_on[i], S, 1) for i in on0]
    bwd = [_along(circ.arcs_on[i], S, -1) for i in on0]
    order_f = [on0[k] + 1 for k in np.argsort(fwd, kind="stable")]
    order_b = [on0[k] + 1 for k in np.argsort(bwd, kind="stable")]
    if order_f != expected and order_b == expected:
        direction, order, path_arcs = -1, order_b, sorted(bwd)
    else:
        direction, order, path_arcs = 1, order_f, sorted(fwd)
    pos_arcs: list[float | None] = [None] * len(circ.circuit_of)
    for i in on0:
        pos_arcs[i] = _along(circ.arcs_on[i], S, direction)
    return _Path(direction, order, expected, path_arcs, pos_arcs, S)


def _branch_points(mech: Mechanism, driver: str, traces: list[TrackResult], path: _Path, *,
                   circuit_defect: bool) -> tuple[list[BranchPoint], list[BranchPoint], int]:
    """Step 4b: the zeros of ``driver``'s DJ met by the tracker (events of the traced circuits):
    all of them, those strictly inside the path (none when there is a circuit defect), and the
    number of poles (DJ through infinity: the driver's limb is serially singular and the output
    turns back while the driver moves on; not branch points)."""
    idx = mech.freedom_refs.index(mech.freedom(driver))
    all_bp, path_bp = [], []
    poles = 0
    for k, tr in enumerate(traces):
        for e in tr.events:
            if e.name != driver:
                continue
            if e.kind == "pole":
                poles += 1
                continue
            cfg = cast(Configuration, e.x)  # a mechanism's motion problem: points are configurations
            p = cfg.D[:3, :3] @ mech.platform_point + cfg.D[:3, 3]
            point = (float(p[0]), float(p[1]), float(p[2]))
            val = float(freedom_values(mech, cfg.q)[idx])
            if k == 0:
                pa = path.to_path(e.s)
                bp = BranchPoint(driver, k + 1, float(pa), positions_between(pa, path.path_arcs), point, val)
                if 0.0 < pa < path.end and not circuit_defect:
                    path_bp.append(bp)
            else:
                bp = BranchPoint(driver, k + 1, float(e.s), None, point, val)
            all_bp.append(bp)
    all_bp.sort(key=lambda b: (b.circuit, b.arc))
    path_bp.sort(key=lambda b: b.arc)
    return all_bp, path_bp, poles


def _driver_verdict(mech: Mechanism, driver: str, dj: np.ndarray, traces: list[TrackResult], path: _Path, *,
                    circuit_defect: bool, order_defect: bool) -> DriverVerdict:
    """Step 4c: the verdict on one driver from its DJ at the positions (``dj``) and its branch
    points (:func:`_branch_points`).  With one circuit the path decides the branch defect (a
    sign change through a pole is no branch point); with several, a change of DJ's sign does.
    Usable: no circuit, order or branch defect."""
    all_bp, path_bp, poles = _branch_points(mech, driver, traces, path, circuit_defect=circuit_defect)
    signs = tuple(int(x) for x in np.sign(dj))
    keeps = len(set(signs)) == 1 and 0 not in signs
    branch_defect = (not keeps) if circuit_defect else bool(path_bp)
    is_usable = not circuit_defect and not order_defect and not branch_defect
    return DriverVerdict(driver, tuple(map(float, dj)), signs, keeps, tuple(path_bp), tuple(all_bp),
                         branch_defect, is_usable, inverse_singular_points=poles)


def _drive_plan(drivers: list[str], zeros_on_path: dict[str, list[float]], path: _Path) -> tuple[PlanStep, ...] | None:
    """Step 4d: when no single driver is usable (and there is no circuit or order defect), a
    multi-drive plan that switches drivers inside intervals free of their DJ zeros
    (:func:`switching_plan`, paper A section 6), or ``None`` when there is none."""
    raw = switching_plan(drivers, zeros_on_path, 0.0, path.end)
    if raw is None:
        return None
    return tuple(PlanStep(d, float(a), float(b), (float(w[0]), float(w[1])) if w else None,
                          positions_between(0.5 * (w[0] + w[1]), path.path_arcs) if w else None)
                 for d, a, b, w in raw)


def _distance_to_singularities(mech: Mechanism, problem: MotionProblem, tr0: TrackResult, path: _Path,
                               verdicts: list[DriverVerdict], watch: set[str]):
    """Step 5: the scale-free smallest singular value of the closure Jacobian at every traced
    point on the path (its minimum and the positions bracketing it), and for each driver in
    ``watch`` (the usable and planned ones) that of its complete Jacobian.  Returns
    ``(min_sigma, between, verdicts)`` (``None, None`` without points on the path)."""
    arcs = [path.to_path(s) for s in tr0.s]
    on = np.array([0.0 <= a <= path.end for a in arcs], dtype=bool)
    path_pts = [(a, x) for a, x, o in zip(arcs, tr0.points, on, strict=True) if o]
    floor = None if tr0.sigma_floor is None else tr0.sigma_floor[on]
    min_sig, min_between = None, None
    sig = [(float(r), a) for r, (a, _) in zip(closure_sigma_ratios(problem, [x for _, x in path_pts], floor),
                                             path_pts, strict=True)]
    if sig:
        mval, marc = min(sig)
        min_sig, min_between = mval, positions_between(marc, path.path_arcs)
    watched = [vd.driver for vd in verdicts if vd.driver in watch]
    sig_w = driver_sigmas(mech, [x for _, x in path_pts], watched)
    new = []
    for vd in verdicts:
        if vd.driver in watch:
            vals = sig_w[:, watched.index(vd.driver)]
            vd = replace(vd, min_sigma_on_path=float(np.min(vals)) if vals.size else None)
        new.append(vd)
    return min_sig, min_between, new


def _verdict_key(r: DefectResult):
    """What the Monte-Carlo check compares: circuit and order defects, the usable drivers and
    the drivers whose DJ keeps its sign."""
    return (r.circuit_defect, r.order_defect, tuple(sorted(r.usable_drivers)),
            tuple(sorted(v.driver for v in r.drivers if v.keeps_sign)))


def _monte_carlo(mech, positions, base, n, seed, precision, angle_deg, drivers, max_arc, h0, say):
    """Step 6 (optional): ``n`` seeded samples of the data perturbed within its printed
    precision (:func:`perturbed`), each analysed again; how many give the same verdict
    (:func:`_verdict_key`) as ``base``, how many fail (e.g. a perturbed overconstrained linkage
    is rigid), and the other verdicts met."""
    rng = np.random.default_rng(seed)
    key0 = _verdict_key(base)
    same, failures, keys = 0, 0, []
    for k in range(n):
        say(f"Monte-Carlo sample {k + 1}/{n}")
        m2, pos2 = perturbed(mech, positions, rng, precision, angle_deg)
        try:
            r = defect_analysis(m2, pos2, drivers=drivers, max_arc=max_arc, h0=h0, sigma_along_path=False)
        except (ValueError, RuntimeError):
            failures += 1
            continue
        keys.append(_verdict_key(r))
        same += _verdict_key(r) == key0
    return {
        "samples": n,
        "seed": seed,
        "precision_length": precision,
        "precision_angle_deg": angle_deg,
        "same_verdict": same,
        "failed": failures,
        "fraction_same": same / n if n else None,
        "verdict": {"circuit_defect": key0[0], "order_defect": key0[1], "usable_drivers": list(key0[2])},
        "other_verdicts": [{"circuit_defect": k[0], "order_defect": k[1], "usable_drivers": list(k[2])}
                           for k in keys if k != key0],
    }
