"""Four-position synthesis of the spatial RCCC linkage by solution regions (paper D).

Steps (paper D section 2.1):

1. spherical Burmester curves of the four orientations (:mod:`.burmester`) and solution
   region 1 (:mod:`.regions`): pick the input and output dyad directions;
2. with the directions fixed, each dyad's moment equations give a solution line
   (:mod:`.dyads`);
3. the input dyad's fixed C joint slides ``s_j`` (affine along its line); where they vanish the
   joint may be an R joint.  Three affine conditions in one line parameter have no common zero
   in general, so we take the point of smallest ``max_j |s_j|`` over the solution line and over
   the input dyad's place on the Burmester curve (among the input dyads that make a
   defect-free crank-rocker with some output dyad);
4. the RCCC is assembled as a :class:`~spatialmech.model.Mechanism` (coupler = platform):
   limb ``input`` = [R ``A0`` on the base (axis ``v_in`` through ``P2_in``), C ``A1`` on the
   coupler (``u_in`` through ``P1_in``)], limb ``output`` = [C ``B0`` on the base, C ``B1`` on the
   coupler]; ``platform_point`` = the task point of position 1, reference configuration =
   position 1;
5. it is checked by solving its closure (:func:`spatialmech.kinematics.backend.correct`) at
   each task position with the input R angle held at the spherical 4R's input angle.  The
   orientation is exact by construction (the spherical image of the RCCC is the spherical 4R);
   the position errors are the price of replacing the input C by an R joint.

Units: the task's length unit; angles in radians (``*_deg`` keys in degrees).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from scipy.optimize import minimize_scalar

from ..errors import InputError
from ..geometry.rotations import rotation_angle
from ..kinematics.closure import Configuration
from ..kinematics.backend import correct
from ..model.joints import C as Cjoint
from ..model.joints import R as Rjoint
from ..model.mechanism import Limb, Mechanism, Pose
from ..model.schema import to_dict as mechanism_to_dict
from .burmester import BurmesterCurves, burmester_curves
from .dyads import Dyad, SolutionLine, dyad_joint_values, minimax, solution_line
from .regions import TYPES, Region1, classify_spherical_4r, solution_region_1
from .tasks import TaskPositions

__all__ = [
    "ClosureCheck",
    "RCCCResult",
    "assemble",
    "check_linkage",
    "interior_pick",
    "synthesize_rccc",
]


def assemble(task: TaskPositions, input_dyad: Dyad, output_dyad: Dyad, *, name: str | None = None) -> Mechanism:
    """The linkage of two dyads as a Mechanism (coupler = platform; see the module docstring).

    The input fixed joint is an R joint when ``input_dyad.kind == "RC"`` (an RCCC), a C joint
    otherwise (a 4C); its rotation is the actuator.  ``positions`` holds the task poses of the
    platform frame (world-aligned at position 1): ``Pose(C_j, p_j)``.
    """
    rc = input_dyad.kind == "RC"
    fixed = Rjoint if rc else Cjoint
    limbs = (
        Limb("input", (
            fixed("A0", input_dyad.P2, input_dyad.v, actuated=True if rc else ["rot"], normalize=True),
            Cjoint("A1", input_dyad.P1, input_dyad.u, normalize=True),
        )),
        Limb("output", (
            Cjoint("B0", output_dyad.P2, output_dyad.v, normalize=True),
            Cjoint("B1", output_dyad.P1, output_dyad.u, normalize=True),
        )),
    )
    Cs = np.concatenate([np.eye(3)[None], task.C])
    positions = tuple(Pose(Cs[j], task.p[j], name=f"position {task.names[j]}") for j in range(task.n))
    kind = "RCCC" if rc else "4C"
    return Mechanism(
        name=name or f"{task.name}-{kind.lower()}",
        limbs=limbs,
        platform_point=task.p[0],
        description=f"{kind} linkage synthesised for the {task.n} positions of task {task.name!r} (paper D method)",
        positions=positions,
        length_unit=task.length_unit,
        source="spatialmech.synthesis (paper D: four-position RCCC synthesis by solution regions)",
        notes=(
            "Coupler = platform; reference configuration = task position 1. Limb 'input' = fixed"
            f" {'R' if rc else 'C'} A0 + moving C A1; limb 'output' = fixed C B0 + moving C B1."
        ),
    )


@dataclass(frozen=True, eq=False)
class ClosureCheck:
    """The linkage's closure solved at each task position with the input held.

    Arrays over positions 2..n: ``input_angles`` (rad), ``orientation_errors`` (rad, angle of
    ``R_achieved R_task^T``), ``position_errors`` (task length unit, distance of the coupler's
    task point from ``p_j``), ``converged``, and the solved configurations."""

    input_angles: np.ndarray
    orientation_errors: np.ndarray
    position_errors: np.ndarray
    converged: np.ndarray
    configurations: tuple[Configuration, ...] = field(repr=False)


def check_linkage(mech: Mechanism, task: TaskPositions, input_dyad: Dyad, output_dyad: Dyad) -> ClosureCheck:
    """Solve the closure of ``mech`` (from :func:`assemble`) at each task position.

    The input rotation ``A0.rot`` (and, for a 4C, the slide ``A0.slide``) is held at the value
    the dyad needs for that position; every other joint and the platform move
    (:func:`~spatialmech.kinematics.backend.correct` with an ``active`` mask without them),
    starting from the exact 4C joint values.
    """
    ids = [r.id for r in mech.freedom_refs]
    held = {"A0.rot", "A0.slide"}
    active = np.array([i not in held for i in ids])
    D = task.displacements()
    th, ori, pos, ok, cfgs = [], [], [], [], []
    for j in range(1, task.n):
        a = dyad_joint_values(input_dyad, D[j])
        b = dyad_joint_values(output_dyad, D[j])
        vals = {"A0.rot": a[0], "A0.slide": a[1], "A1.rot": a[2], "A1.slide": a[3],
                "B0.rot": b[0], "B0.slide": b[1], "B1.rot": b[2], "B1.slide": b[3]}
        q = np.array([vals[i] for i in ids])
        res = correct(mech, Configuration(q, D[j]), active=active)
        Dj = res.config.D
        th.append(a[0])
        ori.append(float(rotation_angle(Dj[:3, :3] @ D[j][:3, :3].T)))
        pos.append(float(np.linalg.norm(Dj[:3, :3] @ task.p[0] + Dj[:3, 3] - task.p[j])))
        ok.append(bool(res.converged))
        cfgs.append(res.config)
    return ClosureCheck(np.array(th), np.array(ori), np.array(pos), np.array(ok), tuple(cfgs))


def interior_pick(region: Region1, type_name: str = "crank-rocker") -> tuple[int, int]:
    """The defect-free cell of the given type farthest (in cells) from any other kind of cell:
    a robust pick in region 1 (row, column indices)."""
    mask = region.mask(type_name, defect_free=True)
    if not mask.any():
        raise InputError(f"type: region 1 has no defect-free {type_name} cell for this task")
    dist = ndimage.distance_transform_edt(mask)
    i, k = np.unravel_index(int(np.argmax(dist)), mask.shape)
    return int(i), int(k)


def _longest_run_centre(row: np.ndarray) -> int:
    """Centre index of the longest run of True in a periodic boolean row."""
    n = row.size
    if row.all():
        return n // 2
    start = int(np.argmin(row))  # a False: runs do not wrap past it
    r = np.roll(row, -start)
    best, best_len, cur = 0, 0, 0
    for i in range(n):
        cur = cur + 1 if r[i] else 0
        if cur > best_len:
            best_len, best = cur, i - cur // 2
    return int((best + start) % n)


@dataclass(frozen=True, eq=False)
class RCCCResult:
    """A synthesised RCCC (or the best RC approximation of it) and its check."""

    task: TaskPositions
    curves: BurmesterCurves = field(repr=False)
    region1: Region1 = field(repr=False)
    pick: str
    t_in: float
    t_out: float
    line_in: SolutionLine = field(repr=False)
    line_out: SolutionLine = field(repr=False)
    input_dyad: Dyad
    output_dyad: Dyad
    slides: np.ndarray
    linkage: Mechanism = field(repr=False)
    check: ClosureCheck = field(repr=False)
    linkage_type: str
    defects: int

    @property
    def max_abs_slide(self) -> float:
        return float(np.max(np.abs(self.slides)))

    def to_dict(self) -> dict:
        ch = self.check
        return {
            "task": self.task.name,
            "pick": self.pick,
            "input_dyad": {**self.input_dyad.to_dict(), "curve_parameter": self.t_in},
            "output_dyad": {**self.output_dyad.to_dict(), "curve_parameter": self.t_out},
            "spherical_4r": {"type": self.linkage_type, "defects": self.defects},
            "max_abs_slide_len": self.max_abs_slide,
            "slides_len": self.slides.tolist(),
            "position_errors_len": ch.position_errors.tolist(),
            "orientation_errors_deg": np.degrees(ch.orientation_errors).tolist(),
            "input_angles_deg": np.degrees(ch.input_angles).tolist(),
            "closure_converged": ch.converged.tolist(),
            "linkage": mechanism_to_dict(self.linkage),
        }


def _lines(task, curves) -> tuple[np.ndarray, np.ndarray]:
    al, be = [], []
    for u, v in zip(curves.u, curves.v, strict=True):
        L = solution_line(task, u, v)
        al.append(L.slide_alpha)
        be.append(L.slide_beta)
    return np.array(al), np.array(be)


def synthesize_rccc(
    task: TaskPositions,
    *,
    pick: str = "best-rc",
    samples: int = 360,
    stride: int = 2,
    h_range: tuple[float, float] | None = None,
    name: str | None = None,
) -> RCCCResult:
    """Paper D's RCCC synthesis for four task positions.

    ``pick="best-rc"``: the input dyad minimises the largest input slide over its solution line
    and over the Burmester curve, among input dyads that form a defect-free crank-rocker with
    some output dyad (refined continuously along the curve); the output dyad is the centre of
    the longest run of defect-free crank-rocker cells in that row of region 1.
    ``pick="interior"``: the defect-free crank-rocker cell of region 1 farthest from other
    kinds (like the paper's point m1), with the best RC point on its input solution line only.
    The output dyad's point on its line minimises its own fixed slide.  ``h_range`` bounds the
    input line parameter (task length unit).  ``samples`` points per curve branch, region 1 on
    every ``stride``-th sample.
    """
    task.require(4, "four-position RCCC synthesis")
    if pick not in ("best-rc", "interior"):
        raise InputError(f"pick: expected 'best-rc' or 'interior', got {pick!r}")
    curves = burmester_curves(task, samples=samples)
    region = solution_region_1(task, curves, stride=stride)
    mask = region.mask("crank-rocker", defect_free=True)
    if not mask.any():
        raise InputError("task: region 1 has no defect-free crank-rocker for these positions")
    if pick == "interior":
        i, k = interior_pick(region)
        t_in, t_out = float(region.t_in[i]), float(region.t_out[k])
        u_in, v_in = curves.u[region.index_in[i]], curves.v[region.index_in[i]]
    else:
        al, be = _lines(task, curves)
        _hs, ms = minimax(al, be, h_range)
        rows = mask.any(axis=1)
        valid = np.zeros(len(curves.t), bool)
        valid[region.index_in[rows]] = True
        cand = np.where(valid, ms, np.inf)
        i0 = int(np.argmin(cand))
        row = int(np.searchsorted(region.index_in, i0))
        row = min(row, len(region.index_in) - 1)
        k = _longest_run_centre(mask[row])
        t_out = float(region.t_out[k])

        def objective(t):
            u, v = curves.at(t)
            return solution_line(task, u, v).minimax_slide(h_range)[1]

        t0 = float(curves.t[i0])
        n_b = int(np.sum(curves.branch == curves.branch[i0]))
        b = np.floor(t0)
        lo, hi = max(b, t0 - 1.0 / n_b), min(b + 1 - 1e-12, t0 + 1.0 / n_b)
        opt = minimize_scalar(objective, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10})
        t_in = float(opt.x) if opt.fun < ms[i0] else t0
        u_in, v_in = curves.at(t_in)
        T, Dd = classify_spherical_4r(task.C, u_in, v_in, curves.u[region.index_out[k]], curves.v[region.index_out[k]])
        if not (T == 0 and Dd == 0):  # refinement left the defect-free region: keep the sample
            t_in = t0
            u_in, v_in = curves.u[i0], curves.v[i0]
    u_out, v_out = curves.u[region.index_out[k]], curves.v[region.index_out[k]]
    line_in = solution_line(task, u_in, v_in)
    line_out = solution_line(task, u_out, v_out)
    h_in, _ = line_in.minimax_slide(h_range)
    h_out, _ = line_out.minimax_slide()
    din = line_in.at(h_in, "RC")
    dout = line_out.at(h_out, "CC")
    T, Dd = classify_spherical_4r(task.C, din.u, din.v, dout.u, dout.v)
    mech = assemble(task, din, dout, name=name)
    check = check_linkage(mech, task, din, dout)
    return RCCCResult(
        task=task, curves=curves, region1=region, pick=pick, t_in=t_in, t_out=t_out,
        line_in=line_in, line_out=line_out, input_dyad=din, output_dyad=dout,
        slides=line_in.slides(h_in), linkage=mech, check=check,
        linkage_type=TYPES[int(T)], defects=int(Dd),
    )
