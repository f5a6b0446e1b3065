"""The front door of position analysis: ONE place decides which engine answers a forward or an
inverse position request, refuses the options that engine would ignore, and returns one result
type whatever the engine (``sm.fk`` / ``sm.ik`` and the ``fk`` / ``ik`` commands go through here).

Forward position, :func:`solve_forward` (actuator values -> platform pose(s)):

- without ``all_solutions``: one Gauss-Newton solve from the reference configuration (engine
  ``"newton"``); ``method``, ``seeds`` and ``seed`` are refused (nothing to choose or to seed);
- ``method="closed-form"``: the registered closed form that recognises the model
  (:data:`FORWARD_CLOSED_FORMS`: the 4-SPS/CU of paper B's layout, whose multi-seed search takes
  ``seeds`` (default 512) and ``seed`` (the quasi-random sequence's); the spherical 3-RRR wrist,
  the 5-CS linkage and single loops of 4 to 7 R joints, proven complete, which refuse ``seeds``),
  else ``InputError``;
- ``method="homotopy"``: homotopy continuation, in Study parameters where the limbs reduce to
  them (engine ``"homotopy"``, proven complete; ``seeds`` refused: it tracks every path of a
  total-degree homotopy, a multi-start adds roots only at singular end points, with its default
  200 starts), else the loop formulation by monodromy (engine ``"monodromy"``; ``seeds`` sizes
  the multi-start it adds when it is not proven complete), else ``InputError``;
- ``method="multistart"``: the general engine's multi-start search (``seeds`` starts, default
  200), on every model, the 4-SPS/CU included (never a proof of completeness);
- ``method="auto"``: the closed form where one recognises the model, else what ``"homotopy"``
  would run (the monodromy capped, the multi-start instead when it gives up), else the
  multi-start.

Inverse position, :func:`solve_inverse` (platform pose -> every limb's joint values): the task
solve of the ``free`` coordinates (:func:`pose_with_free`), then a registered closed form
(:data:`INVERSE_CLOSED_FORMS`; none yet: the closed forms give the actuator values only, not
every limb's joints) or the general engine (:func:`.position.inverse_position`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from ..errors import InputError
from ..geometry.tolerances import Tolerances
from ..model.mechanism import Mechanism, Pose
from ..model.topology import link_graph
from ..results import Progress
from .assembly import AssemblyKind, SelfMotion
from .closed_forms.four_sps_cu_forward import ForwardAllResult
from .forward import ForwardResult, forward_position, homotopy_coverage
from .position import INVERSE_METHODS, InverseResult, inverse_position
from .solution_flags import SolutionFlags, actuator_targets, configuration_at_pose, solution_flags
from .task import TaskSolution, solve_pose

__all__ = [
    "FORWARD_CLOSED_FORMS",
    "FORWARD_METHODS",
    "INVERSE_CLOSED_FORMS",
    "AssemblyMode",
    "ClosedForm",
    "EndPoints",
    "ForwardAnswer",
    "InverseAnswer",
    "forward_engine",
    "pose_with_free",
    "solve_forward",
    "solve_inverse",
]

#: The engines that answer a forward-position request (``ForwardAnswer.engine``).
Engine = Literal["newton", "multistart", "closed-form", "homotopy", "monodromy"]
#: The values of ``method``.
FORWARD_METHODS = ("auto", "closed-form", "homotopy", "multistart")
#: Starts of the general multi-start search when ``seeds`` is not given.
DEFAULT_SEEDS = 200


# ============================================================================ one result
@dataclass(frozen=True, eq=False)
class AssemblyMode:
    """One forward-position result, whatever the engine: the platform pose, what it is
    (``kind``: regular, singular, self-motion), the conditioning (scale-free ``sigma_min``,
    ``condition`` = sigma_min / sigma_max, ``singular_below``), the limits, how many converged
    runs stand for it (``members``), for a self-motion what its trace found, and its ``flags``
    (:class:`.solution_flags.SolutionFlags`: forward singular, inverse singular,
    input-independent, the homotopy end point it came from)."""

    pose: Pose
    kind: AssemblyKind
    residual: float  # nondimensional
    outside_limits: tuple[str, ...]
    sigma_min: float
    condition: float
    singular_below: float
    members: int = 1
    self_motion: SelfMotion | None = None
    free_dim: int | None = None  # free directions of the platform at a singular root (general engine)
    flags: SolutionFlags | None = None  # None only where a caller built the mode without them

    @property
    def within_limits(self) -> bool:
        return not self.outside_limits

    @property
    def forward_singular(self) -> bool:
        """The platform moves with the actuators locked (the conditioning: ``sigma_min`` below
        ``singular_below``)."""
        return bool(self.sigma_min < self.singular_below)

    @property
    def inverse_singular(self) -> bool:
        """With the platform locked, an actuator can still move."""
        return self.flags is not None and self.flags.inverse_singular

    @property
    def input_independent(self) -> bool:
        """The pose closes for every actuator value (the actuators move without moving the
        platform): not an assembly mode of the requested values."""
        return self.flags is not None and self.flags.input_independent

    @property
    def assembly_mode(self) -> bool:
        """A regular, input-dependent root: one assembly mode of the requested values."""
        return self.kind == AssemblyKind.REGULAR and not self.input_independent


@dataclass(frozen=True)
class EndPoints:
    """Homotopy continuation: the status of every path end point (complex solutions)."""

    n_real: int
    n_complex: int
    n_singular: int
    n_at_infinity: int
    n_generic: int
    n_spurious: int | None  # the loop formulation: end points of the square system that do not close
    elapsed_s: float


@dataclass(frozen=True, eq=False)
class ForwardAnswer:
    """The answer of :func:`solve_forward`, the same fields for every engine.

    ``engine`` says which engine answered (:data:`Engine`), ``label`` names its method in a few
    words; ``modes`` are the converged results (assembly modes, singular roots, self-motion
    sets); ``complete`` is True only when the set is proven complete, ``completeness`` says how
    or why not; ``n_starts`` / ``n_converged`` count the Newton starts (of a multi-start search,
    or added to the homotopy's end points); ``endpoints`` (homotopy only) the path end points;
    ``failed_residual`` the residual of a single solve that did not converge.  ``detail`` is the
    engine's own result (:class:`.forward.ForwardResult`, or the closed form's)."""

    engine: Engine
    label: str
    all_solutions: bool
    modes: tuple[AssemblyMode, ...]
    complete: bool
    completeness: str
    n_starts: int
    n_converged: int
    endpoints: EndPoints | None
    failed_residual: float | None
    detail: ForwardResult | ForwardAllResult

    @property
    def n_within_limits(self) -> int:
        return sum(m.within_limits for m in self.modes)

    @property
    def n_input_independent(self) -> int:
        """Solutions that hold for every actuator value (:attr:`AssemblyMode.input_independent`)."""
        return sum(m.input_independent for m in self.modes)

    @property
    def n_certified(self) -> int | None:
        """Solutions certified (:mod:`.homotopy.certify`); ``None`` when none was attempted."""
        tried = [m.flags.certified for m in self.modes if m.flags is not None and m.flags.certified is not None]
        return sum(tried) if tried else None

    def to_dict(self, mech: Mechanism) -> dict:
        """JSON (docs/json.md, ``spatialmech fk --json``): the engine's fields and, for every
        engine, ``engine``, ``complete``, ``completeness``, ``n_input_independent``,
        ``n_certified`` and, on every solution, its flags (``forward_singular``, ``inverse_singular``,
        ``inverse_singular_actuators``, ``input_independent``, ``endpoint``, ``certified``; ``None``
        on a failed attempt)."""
        if isinstance(self.detail, ForwardAllResult):
            d = self.detail.to_dict(actuators=mech.actuators)
        else:
            d = self.detail.to_dict(mech)
        modes = iter(self.modes)
        for s in d["solutions"]:  # the converged solutions are the modes, in the same order
            m = next(modes, None) if s["converged"] else None
            f = m.flags if m is not None else None
            s.update(f.to_dict() if f is not None else dict.fromkeys(_FLAG_KEYS))
            s.setdefault("certificate", None)  # the closed form's solutions have none
            if m is not None:
                s["forward_singular"] = m.forward_singular
        return {"engine": self.engine, **d, "complete": self.complete, "completeness": self.completeness,
                "n_input_independent": self.n_input_independent, "n_certified": self.n_certified}


#: The flags of every solution in JSON (:meth:`.solution_flags.SolutionFlags.to_dict`).
_FLAG_KEYS = ("forward_singular", "inverse_singular", "inverse_singular_actuators", "input_independent", "endpoint",
              "certified")


# ============================================================================ the registry of closed forms
@dataclass(frozen=True)
class ClosedForm:
    """A closed form of a position problem: ``recognise(mechanism)`` returns its solver when the
    mechanism is of its layout (read from the mechanism itself), else ``None``.

    A forward solver is called ``solver(mech, values, seeds=..., seed=...)`` (``values``: the
    actuators' physical values in ``mech.actuators`` order; ``seeds``/``seed`` ``None`` for its
    defaults) and returns a :class:`ForwardAnswer`; an inverse solver ``solver(mech, pose,
    all_solutions=..., n_seeds=..., seed=..., tol=...)`` returns an
    :class:`~.position.InverseResult`."""

    name: str
    recognise: Callable[[Mechanism], Callable | None]


def _four_sps_cu_forward(mech: Mechanism):
    """The 4-SPS/CU of paper B's layout: :func:`.closed_forms.four_sps_cu_forward.forward_all`."""
    from .closed_forms import four_sps_cu as k4

    geom = k4.geometry_of(mech)
    if geom is None:
        return None

    def solve(mech: Mechanism, values, *, seeds: int | None, seed: int | None) -> ForwardAnswer:
        from .closed_forms import four_sps_cu_forward as k4f

        kw = {} if seeds is None else {"n_seeds": seeds}
        fa = k4f.forward_all(np.asarray(values, float), geometry=geom, qmc_seed=0 if seed is None else seed, **kw)
        modes = []
        targets = actuator_targets(mech, values)
        conv = [(n, s, Pose(k4.rotation(s.phi), k4.pose_transform(s.phi)[:3, 3], f"mode {n + 1}"))
                for n, s in enumerate(fa.solutions) if s.converged]
        cfgs = [configuration_at_pose(mech, pose, targets) for _, _, pose in conv]
        certs = _closed_form_certificates(mech, values, [c.D for c in cfgs])
        for (_n, s, pose), cfg, cert in zip(conv, cfgs, certs, strict=True):
            d = s.to_dict(actuators=mech.actuators)
            assert s.kind is not None
            flags = solution_flags(mech, cfg, targets,
                                   forward_singular=bool(s.sigma_min < s.singular_below),
                                   certified=None if cert is None else cert.certified)
            modes.append(AssemblyMode(pose, s.kind, d["residual"], tuple(d["outside_limits"]), float(s.sigma_min),
                                      float(s.condition), float(s.singular_below), s.members, s.self_motion,
                                      flags=flags))
        if seeds is not None:  # a search of the caller's size: its answer, not a proof
            return ForwardAnswer("closed-form", "closed-form multi-start", True, tuple(modes), False,
                                 "multi-seed search of the closed form: not a proof; assembly modes may be missing "
                                 "(the default, or method='homotopy', proves the set complete in the Study "
                                 "formulation)", fa.search.n_seeds, fa.search.n_converged, None, None, fa)
        complete, how = _proven_by_study_homotopy(mech, values, [m.pose for m in modes])
        return ForwardAnswer("closed-form", "closed-form multi-start, proven by homotopy" if complete
                             else "closed-form multi-start", True, tuple(modes), complete, how,
                             fa.search.n_seeds, fa.search.n_converged, None, None, fa)

    return solve


def _proven_by_study_homotopy(mech: Mechanism, values, poses: list[Pose]) -> tuple[bool, str]:
    """Whether the closed form's poses are every real assembly mode, by the Study homotopy
    (:func:`.forward.forward_position` with ``method="homotopy"``: complete by its own proof,
    a re-solve from the cached generic solution set after the first call): proven when its
    real solutions are exactly the given poses (rotation and position within 1e-7 of ``L``).
    Returns ``(complete, completeness statement)``."""
    from .homotopy.certify import certification

    with certification(False):  # the closed form's own poses are certified (Study formulation) above
        res = forward_position(mech, values, all_solutions=True, method="homotopy")
    sr = res.search
    n = len(poses)
    if not sr.get("complete"):
        return False, (f"the closed form's multi-seed search found {n} mode(s); the Study homotopy could not prove "
                       f"a complete set ({sr.get('completeness')}): not proven")
    L = mech.characteristic_length
    hom = [s.pose for s in res.solutions if s.converged]

    def same(a: Pose, b: Pose) -> bool:
        return float(np.max(np.abs(a.R - b.R))) + float(np.max(np.abs(a.p - b.p))) / L < 1e-7

    matched = all(any(same(h, q) for q in poses) for h in hom) and all(any(same(q, h) for h in hom) for q in poses)
    if not matched or len(hom) != n:
        return False, (f"the closed form's multi-seed search found {n} mode(s), the Study homotopy's proven set has "
                       f"{len(hom)} real solution(s) and they differ: not proven (method='homotopy' gives the "
                       "homotopy's set)")
    return True, (f"proven: the closed form's {n} mode(s) are exactly the real solutions of the Study homotopy, "
                  f"whose set is proven complete ({sr['completeness']})")


def _closed_form_certificates(mech: Mechanism, values, displacements: list) -> list:
    """The certificates of a closed form's platform displacements as roots of the Study
    formulation's system (:func:`.forward.study_certificates`); ``None`` each when certification
    is off."""
    from .forward import study_certificates
    from .homotopy.certify import enabled

    if not enabled() or not displacements:
        return [None] * len(displacements)
    return study_certificates(mech, values, displacements)


#: Closed forms of forward position, tried in order by :func:`solve_forward`.  (The spherical
#: 3-RRR's ``forward_orientation`` follows one assembly branch from a start and the 3-RPS's
#: closed form is its parasitic motion: neither finds every assembly mode, none is registered.)
FORWARD_CLOSED_FORMS: list[ClosedForm] = [ClosedForm("4-SPS/CU of paper B's layout", _four_sps_cu_forward)]


def _spherical_rrr_forward(mech: Mechanism):
    """A spherical 3-RRR wrist (nine R axes through one centre, one actuator per limb):
    :func:`.closed_forms.spherical_rrr_forward.solve`, proven complete by Bezout's bound."""
    from .closed_forms import spherical_rrr_forward as srf

    return srf.recognise(mech)


FORWARD_CLOSED_FORMS.append(ClosedForm("spherical 3-RRR wrist (3 quaternion quadrics)", _spherical_rrr_forward))


def _cs_forward(mech: Mechanism):
    """A 5-CS guidance linkage with one C rotation driven: :func:`.closed_forms.cs_forward.solve`,
    proven complete by a homotopy on SO(3) x C."""
    from .closed_forms import cs_forward as csf

    return csf.recognise(mech)


FORWARD_CLOSED_FORMS.append(ClosedForm("5-CS linkage (4 quadrics on SO(3) x C)", _cs_forward))


def _r_loop_forward(mech: Mechanism):
    """A single loop of 5 to 7 R joints, one driven: :func:`.closed_forms.r_loop_forward.solve`,
    the complete inverse position of a 6R."""
    from .closed_forms import r_loop_forward as rlf

    return rlf.recognise(mech)


FORWARD_CLOSED_FORMS.append(ClosedForm("single loop of 5-7 R joints (a 6R inverse position)", _r_loop_forward))


def _four_r_forward(mech: Mechanism):
    """A single loop of four R joints, one driven (Bennett, four-bars):
    :func:`.closed_forms.four_r_forward.solve`, one trigonometric equation."""
    from .closed_forms import four_r_forward as frf

    return frf.recognise(mech)


FORWARD_CLOSED_FORMS.append(ClosedForm("single loop of 4 R joints (one trigonometric equation)", _four_r_forward))
#: Closed forms of inverse position, tried in order by :func:`solve_inverse`.  None yet: the
#: closed forms (4-SPS/CU and S-P-S leg lengths, the spherical 3-RRR's actuator angles) give the
#: actuator values only, where inverse position answers every limb's joint values.
INVERSE_CLOSED_FORMS: list[ClosedForm] = []


def _closed_form(registry: Sequence[ClosedForm], mech: Mechanism) -> Callable | None:
    for cf in registry:
        solver = cf.recognise(mech)
        if solver is not None:
            return solver
    return None


# ============================================================================ forward position
def _mode(mech: Mechanism, s, targets: dict[int, float]) -> AssemblyMode:
    c = s.conditioning
    flags = solution_flags(mech, s.config, targets, forward_singular=c.singular, endpoint=s.endpoint,
                           certified=s.certified)
    return AssemblyMode(s.pose, s.kind, float(s.residual), tuple(s.outside_limits), c.sigma_min, c.condition,
                        c.threshold, s.members, s.self_motion, c.free_dim, flags)


def _general_answer(mech: Mechanism, values, res: ForwardResult, all_solutions: bool) -> ForwardAnswer:
    """The general engine's :class:`.forward.ForwardResult` as a :class:`ForwardAnswer`, every
    converged solution flagged (:func:`.solution_flags.solution_flags`)."""
    sr = res.search
    targets = actuator_targets(mech, values)
    modes = tuple(_mode(mech, s, targets) for s in res.solutions if s.converged)
    failed = None if modes or not res.solutions else float(res.solutions[0].residual)
    if "n_generic" in sr:  # homotopy continuation: Study parameters, or the loop formulation ("n_spurious")
        loop = "n_spurious" in sr
        ends = EndPoints(sr["n_real"], sr["n_complex"], sr["n_singular"], sr["n_at_infinity"], sr["n_generic"],
                         sr.get("n_spurious"), sr["elapsed_s"])
        return ForwardAnswer("monodromy" if loop else "homotopy",
                             "loop formulation by monodromy" if loop else "homotopy continuation", True, modes,
                             bool(sr["complete"]), sr["completeness"], sr["seeds"], sr["converged_runs"], ends, failed,
                             res)
    if all_solutions:
        return ForwardAnswer("multistart", sr["method"], True, modes, False, sr["completeness"], sr["seeds"],
                             sr["converged_runs"], None, failed, res)
    return ForwardAnswer("newton", sr["method"], False, modes, False,
                         "one Newton solve from the reference configuration: one assembly mode at most "
                         "(all_solutions for every one)", sr["seeds"], sr["converged_runs"], None, failed, res)


def forward_engine(mech: Mechanism, method: str = "auto", all_solutions: bool = True) -> Engine:
    """The engine :func:`solve_forward` runs for ``method`` (before it runs: with
    ``method="auto"`` the capped monodromy may still give up and leave it to the multi-start)."""
    if method not in FORWARD_METHODS:
        raise InputError(f"method: expected one of {', '.join(map(repr, FORWARD_METHODS))}, got {method!r}")
    if not all_solutions:
        return "newton"
    if method in ("auto", "closed-form") and _closed_form(FORWARD_CLOSED_FORMS, mech) is not None:
        return "closed-form"
    if method == "closed-form":
        names = ", ".join(cf.name for cf in FORWARD_CLOSED_FORMS)
        miss = closed_form_miss(mech)
        raise InputError(f"method: no closed form of forward position recognises {mech.name} (registered: {names})"
                         f"{'' if miss is None else '; ' + miss}; use method='auto'")
    if method == "multistart":
        return "multistart"
    why, gwhy = homotopy_coverage(mech)
    if why is None:
        return "homotopy"
    if gwhy is None:
        return "monodromy"
    if method == "homotopy":
        raise InputError(f"method: homotopy forward position does not cover {mech.name}: {why}; nor does the loop "
                         f"formulation: {gwhy}; use method='multistart'")
    return "multistart"


def solve_forward(mech: Mechanism, values, *, all_solutions: bool = False, method: str = "auto",
                  seeds: int | None = None, seed: int | None = None, progress: Progress | None = None
                  ) -> ForwardAnswer:
    """Forward position through the engine ``method`` picks (module docstring): ``values`` the
    actuators' physical values (SI: length, rad) in ``mech.actuators`` order.  ``seeds`` /
    ``seed``: the starts and the random seed of a multi-start search (``None``: the engine's
    default); options the chosen engine would ignore raise :class:`InputError` naming them.
    ``progress(done, total, message)`` is called by the engines that report progress (the
    multi-start search)."""
    if method not in FORWARD_METHODS:
        raise InputError(f"method: expected one of {', '.join(map(repr, FORWARD_METHODS))}, got {method!r}")
    if not all_solutions:
        given = [n for n, v in (("method", method != "auto"), ("seeds", seeds is not None), ("seed", seed is not None))
                 if v]
        if given:
            raise InputError(f"{', '.join(given)}: only with all_solutions (without it, one Newton solve from the "
                             "reference configuration: no engine to choose, no starts)")
        return _general_answer(mech, values, forward_position(mech, values), False)
    if link_graph(mech).n_loops == 0:
        return _serial_answer(mech, values, method, seeds, seed)
    engine = forward_engine(mech, method)
    if engine == "closed-form":
        solver = _closed_form(FORWARD_CLOSED_FORMS, mech)
        assert solver is not None
        return solver(mech, values, seeds=seeds, seed=seed)
    if engine == "homotopy" and seeds is not None:
        raise InputError(f"seeds: homotopy continuation answers {mech.name} (method={method!r}), which takes no "
                         "starts: it tracks every path of a total-degree homotopy and is proven complete; "
                         "method='multistart' runs a multi-start search of that many starts")
    res = forward_position(mech, values, all_solutions=True, n_seeds=DEFAULT_SEEDS if seeds is None else seeds,
                           seed=0 if seed is None else seed, progress=progress, method=method)
    ans = _general_answer(mech, values, res, True)
    miss = closed_form_miss(mech)
    return ans if miss is None else replace(ans, completeness=f"{ans.completeness}; {miss}")


def closed_form_miss(mech: Mechanism) -> str | None:
    """Why a registered closed form of forward position that nearly fits ``mech`` does not
    answer it (a 5-CS linkage with a slide driven instead of a rotation), else ``None``."""
    from .closed_forms import cs_forward as csf

    return csf.driven_slide_note(mech)


def _serial_answer(mech: Mechanism, values, method: str, seeds: int | None, seed: int | None) -> ForwardAnswer:
    """``all_solutions`` on a serial chain (no closed loop): with every freedom
    actuated or locked it has exactly one pose, the chain's forward kinematics; with a passive
    freedom the pose is not determined by the actuators (refused)."""
    passive = [r.id for r in mech.freedom_refs if not (r.freedom.actuated or r.freedom.locked)]
    if passive:
        raise InputError(f"all_solutions: {mech.name} is a serial chain (no closed loop) with passive freedoms "
                         f"({', '.join(passive)}): the actuators do not determine its pose")
    given = [n for n, v in (("method", method != "auto"), ("seeds", seeds is not None), ("seed", seed is not None))
             if v]
    if given:
        raise InputError(f"{', '.join(given)}: {mech.name} is a serial chain (no closed loop): with its actuators "
                         "given it has one pose, nothing to search")
    ans = solve_forward(mech, values)
    return replace(ans, all_solutions=True, complete=bool(ans.modes),
                   completeness="a serial chain (no closed loop): with its actuators given it has one pose, "
                                "its forward kinematics")


# ============================================================================ inverse position
@dataclass(frozen=True, eq=False)
class InverseAnswer:
    """The answer of :func:`solve_inverse`: the pose solved (with ``free``: the task solve's),
    every limb's joint values (``result``), the task solve (``None`` without ``free``) and the
    engine (``"closed-form"`` or ``"numerical"``)."""

    pose: Pose
    result: InverseResult
    task: TaskSolution | None
    engine: Literal["closed-form", "numerical"]


def pose_with_free(mech: Mechanism, pose: Pose, free: Sequence[str], euler: str = "ZYX") -> tuple[Pose, TaskSolution]:
    """The task solve of a requested pose whose coordinates ``free`` (from ``x, y, z, a1, a2,
    a3``, angles in sequence ``euler``) are solved and the others held: the solved pose (the
    requested one when the solve did not converge) and the solve."""
    task = solve_pose(mech, pose, list(free), euler=euler)
    if task.converged:
        R = task.D[:3, :3]
        pose = Pose(R, R @ mech.platform_point + task.D[:3, 3], "requested, solved")
    return pose, task


def solve_inverse(mech: Mechanism, pose: Pose, *, all_solutions: bool = False, n_seeds: int = 48, seed: int = 0,
                  tol: Tolerances | float | None = None, free: Sequence[str] | None = None,
                  euler: str = "ZYX", method: str = "auto") -> InverseAnswer:
    """Inverse position through the one front door: with ``free``, the task solve first
    (:func:`pose_with_free`); then a registered closed form (:data:`INVERSE_CLOSED_FORMS`) or the
    general engine, a pose that does not close exactly fitted onto the closure (``fit=True``).
    ``method`` (with ``all_solutions``): ``"auto"``, ``"homotopy"`` or ``"multistart"``, as
    :func:`~spatialmech.kinematics.position.inverse_position` (a closed form answers only under
    ``"auto"``)."""
    task = None
    if free is not None:
        pose, task = pose_with_free(mech, pose, free, euler)
    if method not in INVERSE_METHODS:
        raise InputError(f"method: expected one of {', '.join(map(repr, INVERSE_METHODS))}, got {method!r}")
    if method != "auto" and not all_solutions:
        raise InputError(f"method: {method!r} chooses how every solution is searched; it needs all_solutions=True")
    solver = _closed_form(INVERSE_CLOSED_FORMS, mech) if method == "auto" else None
    if solver is not None:
        return InverseAnswer(pose, solver(mech, pose, all_solutions=all_solutions, n_seeds=n_seeds, seed=seed, tol=tol),
                             task, "closed-form")
    res = inverse_position(mech, pose, all_solutions=all_solutions, n_seeds=n_seeds, seed=seed, tol=tol, fit=True,
                           start=task.config if task is not None and task.converged else None, method=method)
    return InverseAnswer(pose, res, task, "numerical")
