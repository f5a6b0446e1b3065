"""5-CS linkages from CS dyads (paper A, section 3): five dyads of the seven-position family
(:mod:`.cs_dyads`) assembled into a rigid-body guidance linkage (:func:`assemble_5cs`), the
linkage checked at its task positions, for its mobility and, optionally, for defects
(:func:`check_5cs`), and paper A's section 3 claims checked on its printed data
(:func:`paper_a_check`).

Lengths are in the task's length unit, angles in radians inside, ``*_deg`` keys in degrees.

Example: the paper's linkage 3 as printed (limbs rounded to 3 decimals) has one degree of
freedom but reaches only its first position exactly; the largest position error is 0.29 (task
length unit), which is why :func:`paper_a_check` projects the printed limbs onto the family
and refits the linkage::

    >>> from spatialmech import catalog
    >>> chk = check_5cs(catalog.build("five-cs-3"))
    >>> chk.dof, chk.exact.tolist()[:2], round(float(np.max(chk.position_errors)), 2)
    (1, [True, False], 0.29)
    >>> chk.verdict()
    'not a solution: the linkage does not reach P2, P3, P4, P5, P6, P7 exactly'
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InputError
from ..model.joints import C as Cjoint
from ..model.joints import Joint
from ..model.joints import S as Sjoint
from ..model.mechanism import Limb, Mechanism, Pose
from ..results import Progress
from .cs_dyads import CSDyad, CSFamily, CSTask, cs_task, dyad_from_limb, project_dyad, synthesize_cs

if TYPE_CHECKING:
    from ..analysis.defects import DefectResult

__all__ = [
    "FiveCSCheck",
    "PaperACheck",
    "assemble_5cs",
    "check_5cs",
    "cs_configuration",
    "cs_configurations",
    "cs_joints",
    "five_cs_limb",
    "five_cs_of_limbs",
    "paper_a_check",
]


# ------------------------------------------------------------------------------ 5-CS linkages
def assemble_5cs(
    task_poses, dyads: Sequence[CSDyad], *, name: str = "five-cs-synthesised", length_unit: str = "unit"
) -> Mechanism:
    """The 5-CS linkage of five dyads, built exactly like :func:`spatialmech.catalog.papers.five_cs`:
    limbs ``limb1..limb5`` = [C ``C{i}`` (axis ``u``, point ``B1``), S ``S{i}`` at ``M1``], the
    rotation of C1 actuated, aliases ``rot{i}``/``slide{i}``; ``platform_point`` = the task
    point of position 1; reference configuration = position 1 (all joint variables 0);
    ``positions`` = the task poses relative to position 1."""
    task = cs_task(task_poses)
    dyads = tuple(dyads)
    if len(dyads) != 5:
        raise InputError(f"dyads: a 5-CS linkage needs exactly 5 dyads, got {len(dyads)}")
    for i, dy in enumerate(dyads):
        if not isinstance(dy, CSDyad):
            raise InputError(f"dyads[{i}]: expected a CSDyad, got {type(dy).__name__}")
    return five_cs_of_limbs(task, tuple(five_cs_limb(i, cs_joints(dy, field=f"dyads[{i}]")) for i, dy in enumerate(dyads)),
                            name=name, length_unit=length_unit)


def cs_joints(dyad: CSDyad, *, field: str | None = None) -> tuple[Joint, Joint]:
    """The two joints of ``dyad``'s limb, not yet placed in a linkage: C (axis ``u``, point
    ``B1``, nothing actuated) and S at ``M1``, named ``"C"`` and ``"S"`` (:func:`five_cs_limb`
    names them by their place).  ``field`` prefixes error messages.  Joints are frozen, so a
    caller that builds many linkages from the same dyads may keep them."""
    w = field or "dyad"
    return (Cjoint("C", dyad.B1, dyad.u, normalize=True, field=f"{w}.C"), Sjoint("S", dyad.M1, field=f"{w}.S"))


def five_cs_limb(i: int, joints: tuple[Joint, Joint]) -> Limb:
    """Limb ``i`` (from 0) of :func:`assemble_5cs` from its dyad's :func:`cs_joints`:
    ``limb{i+1}`` = [``C{i+1}``, ``S{i+1}``], the rotation of C actuated for ``i = 0``."""
    c, sj = joints
    fs = (replace(c.freedoms[0], actuated=True), *c.freedoms[1:]) if i == 0 else c.freedoms
    return Limb(f"limb{i + 1}", (replace(c, name=f"C{i + 1}", freedoms=fs), replace(sj, name=f"S{i + 1}")))


def five_cs_of_limbs(task: CSTask, limbs: tuple[Limb, ...], *, name: str = "five-cs-synthesised",
                     length_unit: str = "unit") -> Mechanism:
    """:func:`assemble_5cs` from its five limbs (:func:`five_cs_limb` of each dyad, in order)."""
    aliases = {}
    for i in range(5):
        aliases[f"rot{i + 1}"] = f"C{i + 1}.rot"
        aliases[f"slide{i + 1}"] = f"C{i + 1}.slide"
    return Mechanism(
        name=name,
        limbs=tuple(limbs),
        platform_point=task.reference_point,
        description="5-CS rigid-body guidance linkage synthesised for seven positions (paper A section 3)",
        positions=task.relative_poses,
        aliases=aliases,
        length_unit=length_unit,
        source="spatialmech.synthesis.cs_dyads (paper A eqs 22-26)",
        notes="Reference configuration = task position 1 (slides zero). Drivers rot1..rot5 / slide1..slide5.",
    )


@dataclass(frozen=True, eq=False)
class FiveCSCheck:
    """A 5-CS linkage checked at its task positions: for each position the closed configuration
    nearest to the task pose (:func:`~spatialmech.kinematics.position.configuration_at_pose`),
    its position error (length unit) and angle error (rad), whether the pose itself closes
    (``exact``), the C slides found (``slides[j, i]``, limb i at position j) and their
    difference from the dyads' slides when given; the mobility (dof) of the linkage."""

    position_errors: np.ndarray
    angle_errors: np.ndarray
    ik_residuals: np.ndarray
    exact: np.ndarray
    converged: np.ndarray
    slides: np.ndarray
    slide_errors: np.ndarray | None
    dof: int
    dof_instantaneous: int
    defects: DefectResult | None = None  # the defect analysis of the linkage (None: not run)

    @property
    def max_pose_error(self) -> float:
        return float(max(np.max(self.position_errors), np.max(self.angle_errors)))

    @property
    def ok(self) -> bool:
        """The linkage closes exactly at every position and has one degree of freedom (it need
        not be able to *move* through them: see :attr:`success`)."""
        return bool(np.all(self.exact) and self.dof == 1 and self.dof_instantaneous == 1)

    @property
    def usable_drivers(self) -> tuple[str, ...]:
        """Drivers that move the linkage from the first to the last position in order, without a
        circuit, order or branch defect (empty when the defects were not analysed)."""
        return tuple(self.defects.usable_drivers) if self.defects is not None else ()

    @property
    def success(self) -> bool:
        """:attr:`ok` and defect-free for at least one driver (the defect analysis must have run)."""
        return self.ok and bool(self.usable_drivers)

    def verdict(self) -> str:
        """What the check found, in one plain sentence."""
        if not np.all(self.exact):
            bad = [f"P{j + 1}" for j, e in enumerate(self.exact) if not e]
            return f"not a solution: the linkage does not reach {', '.join(bad)} exactly"
        if self.dof != 1 or self.dof_instantaneous != 1:
            return f"not a guidance linkage: mobility {self.dof} (instantaneous {self.dof_instantaneous}) instead of 1"
        d = self.defects
        if d is None:
            return "closes at every position with one degree of freedom; defects NOT analysed, so not known to be usable"
        if self.usable_drivers:
            return (f"success: defect-free when driven by {', '.join(self.usable_drivers)} (no circuit, order or "
                    "branch defect)")
        problems = []
        if d.circuit_defect:
            circ = "; ".join("{" + ", ".join(f"P{i}" for i in c) + "}" for c in d.circuits)
            problems.append(f"circuit defect: the positions lie on {len(d.circuits)} separate circuits ({circ}), so no "
                            "driver can move the linkage through all of them")
        if d.order_defect:
            problems.append("order defect: along the circuit the positions are met in the order "
                            + ", ".join(f"P{i}" for i in d.order))
        if not problems:
            branch = [v.driver for v in d.drivers if v.branch_defect]
            problems.append(f"branch defect for every driver ({', '.join(branch) or 'none usable'})"
                            + (": a plan switching drivers along the path exists" if d.plan else ""))
        return "FAILED: " + "; ".join(problems)

    def to_dict(self) -> dict:
        return {
            "position_errors_len": self.position_errors.tolist(),
            "angle_errors_deg": np.degrees(self.angle_errors).tolist(),
            "ik_residuals": self.ik_residuals.tolist(),
            "exact": self.exact.tolist(),
            "converged": self.converged.tolist(),
            "slides_len": self.slides.tolist(),
            "max_slide_error_len": None if self.slide_errors is None else float(np.max(np.abs(self.slide_errors))),
            "dof": self.dof,
            "dof_instantaneous": self.dof_instantaneous,
            "ok": self.ok,
            "defects_analysed": self.defects is not None,
            "circuit_defect": None if self.defects is None else bool(self.defects.circuit_defect),
            "order_defect": None if self.defects is None else bool(self.defects.order_defect),
            "branch_defect_drivers": None if self.defects is None else [v.driver for v in self.defects.drivers
                                                                         if v.branch_defect],
            "usable_drivers": list(self.usable_drivers),
            "success": self.success,
            "verdict": self.verdict(),
            "defects": None if self.defects is None else self.defects.to_dict(),
        }


def cs_configuration(mech: Mechanism, pose: Pose):
    """Closed-form joint values of a mechanism of C-S limbs at a pose (the start of the pose
    fit; Gauss-Newton from all-zero joint values can stop at a wrong local minimum when a C
    rotation is near 180 degrees).  Per limb: slide ``s = u . (M_j - M1)``, rotation = signed
    angle about ``u`` from ``M1 - B1`` to ``M_j - B1 - s u`` (perpendicular parts), S rotation
    vector of ``R_u(theta)^T R``.  ``None`` when a limb is not [C, S]."""
    from scipy.spatial.transform import Rotation

    from ..kinematics.closure import Configuration

    D = pose.displacement(mech.platform_point)
    q = []
    for lb in mech.limbs:
        if [j.type for j in lb.joints] != ["C", "S"]:
            return None
        c, sj = lb.joints
        u = c.freedoms[0].direction
        B1, M1 = c.point, sj.point
        Mj = D[:3, :3] @ M1 + D[:3, 3]
        s = float(u @ (Mj - M1))
        a = (M1 - B1) - (u @ (M1 - B1)) * u
        b = (Mj - B1 - s * u) - (u @ (Mj - B1 - s * u)) * u
        th = float(np.arctan2(u @ np.cross(a, b), a @ b))
        Rs = Rotation.from_rotvec(-th * u).as_matrix() @ D[:3, :3]
        A = np.array([f.direction for f in sj.freedoms]).T
        q += [th, s, *(A.T @ Rotation.from_matrix(Rs).as_rotvec())]
    return Configuration(np.array(q), D)


def _cs_closed_forms_py(u, B1, M1, A, Ds, q):  # pragma: no cover - compiled by _cs_closed_forms
    """The C-S closed form of :func:`cs_configuration` for limbs ``k`` (C axis ``u[k]`` through
    ``B1[k]``, S centre ``M1[k]``, S axes the rows of ``A[k]``) at the displacements ``Ds[n]``,
    into ``q[n, 5k:5k+5]`` = (C rotation, C slide, S rotation vector in the S axes), in scalar
    loops (compiled by :func:`_cs_closed_forms`): ``R_u(-theta)`` by Rodrigues, the S rotation
    vector by SciPy's algorithm: ``kernels_se3``'s ``nb_rodrigues`` and ``nb_quat_rotvec`` (the
    module is bound to ``_se3`` by :func:`_cs_closed_forms`)."""
    Ru = np.empty((3, 3))
    Rs = np.empty((3, 3))
    rv = np.empty(3)
    Mj = np.empty(3)
    for n in range(Ds.shape[0]):
        for k in range(u.shape[0]):
            ux, uy, uz = u[k, 0], u[k, 1], u[k, 2]
            for a in range(3):
                Mj[a] = Ds[n, a, 0] * M1[k, 0] + Ds[n, a, 1] * M1[k, 1] + Ds[n, a, 2] * M1[k, 2] + Ds[n, a, 3]
            s = ux * (Mj[0] - M1[k, 0]) + uy * (Mj[1] - M1[k, 1]) + uz * (Mj[2] - M1[k, 2])
            e0, e1, e2 = M1[k, 0] - B1[k, 0], M1[k, 1] - B1[k, 1], M1[k, 2] - B1[k, 2]
            ue = ux * e0 + uy * e1 + uz * e2
            a0, a1, a2 = e0 - ue * ux, e1 - ue * uy, e2 - ue * uz
            w0, w1, w2 = Mj[0] - B1[k, 0] - s * ux, Mj[1] - B1[k, 1] - s * uy, Mj[2] - B1[k, 2] - s * uz
            uw = ux * w0 + uy * w1 + uz * w2
            b0, b1, b2 = w0 - uw * ux, w1 - uw * uy, w2 - uw * uz
            th = np.arctan2(ux * (a1 * b2 - a2 * b1) + uy * (a2 * b0 - a0 * b2) + uz * (a0 * b1 - a1 * b0),
                            a0 * b0 + a1 * b1 + a2 * b2)
            _se3.nb_rodrigues(ux, uy, uz, np.sin(-th), 1.0 - np.cos(th), Ru)  # R_u(-theta)
            for i in range(3):  # R_u(-theta) @ R_n
                for j in range(3):
                    Rs[i, j] = Ru[i, 0] * Ds[n, 0, j] + Ru[i, 1] * Ds[n, 1, j] + Ru[i, 2] * Ds[n, 2, j]
            _se3.nb_quat_rotvec(Rs, rv)
            q[n, 5 * k] = th
            q[n, 5 * k + 1] = s
            for d in range(3):
                q[n, 5 * k + 2 + d] = A[k, d, 0] * rv[0] + A[k, d, 1] * rv[1] + A[k, d, 2] * rv[2]


#: The module ``kinematics.compiled.kernels_se3``, bound on first use by :func:`_cs_closed_forms`
#: (importing it loads numba).
_se3: Any = None


@functools.cache
def _cs_closed_forms():
    """:func:`_cs_closed_forms_py` compiled (numba, ``cache=True``) on first use when the compiled
    engine is on (importing this module loads no numba), else the plain function (which calls the
    same kernels)."""
    global _se3
    from ..kinematics import backend
    from ..kinematics.compiled import kernels_se3

    _se3 = kernels_se3
    if not backend.enabled():
        return _cs_closed_forms_py
    from ..kinematics.compiled.jit import njit

    return njit(cache=True)(_cs_closed_forms_py)


def cs_configurations(mech: Mechanism, poses: Sequence[Pose] | None = None):
    """:func:`cs_configuration` at every pose of ``poses`` (default: the model's positions) at
    once, without SciPy (:func:`_cs_closed_forms_py`, compiled when the engine is on): the same
    joint values to rounding.  A list of configurations, or ``None`` when a limb is not [C, S]."""
    from ..kinematics.closure import Configuration

    poses = list(mech.positions if poses is None else poses)
    if any([j.type for j in lb.joints] != ["C", "S"] for lb in mech.limbs):
        return None
    if not poses:
        return []
    u = np.array([lb.joints[0].freedoms[0].direction for lb in mech.limbs], dtype=float)  # (k, 3)
    B1 = np.array([lb.joints[0].point for lb in mech.limbs], dtype=float)
    M1 = np.array([lb.joints[1].point for lb in mech.limbs], dtype=float)
    A = np.array([[f.direction for f in lb.joints[1].freedoms] for lb in mech.limbs], dtype=float)  # (k, 3 rows, 3)
    Ds = np.array([P.displacement(mech.platform_point) for P in poses])  # (n, 4, 4)
    q = np.empty((len(poses), 5 * len(mech.limbs)))
    _cs_closed_forms()(u, B1, M1, A, Ds, q)
    return [Configuration(q[i].copy(), Ds[i]) for i in range(len(poses))]


def check_5cs(mech: Mechanism, dyads: Sequence[CSDyad] | None = None, *, defects: bool = False,
              progress: Progress | None = None) -> FiveCSCheck:
    """Solve ``mech`` (from :func:`assemble_5cs` or the catalog) at each of its positions and
    compute its mobility (see :class:`FiveCSCheck`).  ``defects=True`` also runs the defect
    analysis (:func:`spatialmech.analysis.defects.defect_analysis`: circuits, order, branch
    points for every candidate driver; about a minute) when the linkage closes with one degree
    of freedom: a synthesised linkage is a success only if it is defect-free for at least one
    driver (:attr:`FiveCSCheck.success`)."""
    from ..analysis.mobility import mobility
    from ..kinematics.position import configuration_at_pose, freedom_values

    if not mech.positions:
        raise InputError(f"mech: {mech.name} has no task positions to check")
    ids = [r.id for r in mech.freedom_refs]
    sl_idx = [ids.index(f"{lb.joints[0].name}.slide") for lb in mech.limbs]
    pe, ae, ik, ex, cv, sl = [], [], [], [], [], []
    for P in mech.positions:
        fit = configuration_at_pose(mech, P, start=cs_configuration(mech, P))
        pe.append(fit.position_error)
        ae.append(fit.angle_error)
        ik.append(fit.ik_residual)
        ex.append(fit.exact)
        cv.append(fit.converged)
        sl.append(freedom_values(mech, fit.config.q)[sl_idx])
    slides = np.array(sl)
    errs = None
    if dyads is not None:
        errs = slides - np.array([d.slides for d in dyads]).T
    mob = mobility(mech)
    out = FiveCSCheck(np.array(pe), np.array(ae), np.array(ik), np.array(ex), np.array(cv), slides, errs, int(mob.dof),
                      int(mob.dof_instantaneous))
    if defects and out.ok:
        from ..analysis.defects import defect_analysis

        out = replace(out, defects=defect_analysis(mech, progress=progress))
    return out


# ------------------------------------------------------------------------------ paper A claims
@dataclass(frozen=True, eq=False)
class PaperACheck:
    """Paper A's section 3 claims on the data of table 9 and linkages 1-3 (tables 1-13).

    ``printed``: per linkage, per limb, the printed limb as a dyad (its ``residual`` = largest
    |eq 24| as a length difference and |eq 25|, from the 3-decimal rounding); ``projections``:
    each printed limb projected onto the family; ``refitted``: each paper linkage rebuilt from
    its projected limbs, checked at the seven positions; ``family`` and ``synthesised``: the
    family of table 9 and the check of the 5-CS from its five picked dyads."""

    printed: dict
    projections: dict
    refitted: dict
    family: CSFamily
    synthesised: FiveCSCheck

    def to_dict(self) -> dict:
        return {
            "printed_residuals_len": {k: [d.residual for d in v] for k, v in self.printed.items()},
            "projections": {k: [p.to_dict() for p in v] for k, v in self.projections.items()},
            "refitted": {k: v.to_dict() for k, v in self.refitted.items()},
            "family": self.family.to_dict(samples=20),
            "synthesised": self.synthesised.to_dict(),
        }


def paper_a_check(positions, linkages: dict, *, n_starts: int = 60, seed: int = 0, refit: bool = True,
                  family: CSFamily | None = None) -> PaperACheck:
    """Everything needed for paper A's section 3 claims (see :class:`PaperACheck`) on the data
    given: ``positions`` (table 9) and ``linkages`` (tables 1-13 by linkage number: ``u``,
    ``B1``, ``M_by_position``, ``s`` per limb; the catalogue's ``five_cs_data()["linkages"]``);
    ``family``: a family of table 9 already synthesised with five picks (else it is synthesised
    here).  The data are passed in: the numerical core does not read the catalogue."""
    task = cs_task(positions)
    data = linkages
    if not isinstance(data, dict) or not data:
        raise InputError(f"linkages: expected the paper's linkages by number, got {type(data).__name__}")
    printed, proj, refitted = {}, {}, {}
    for k in sorted(data):
        lk = data[k]
        dys = tuple(
            dyad_from_limb(task, lk["u"][i], lk["B1"][i], lk["M_by_position"][0][i], lk["s"][i]) for i in range(5)
        )
        printed[k] = dys
        proj[k] = tuple(project_dyad(task, d) for d in dys)
        if refit:
            fitted = tuple(p.fitted for p in proj[k])
            refitted[k] = check_5cs(assemble_5cs(task, fitted, name=f"five-cs-{k}-refitted"), fitted)
    fam = family if family is not None else synthesize_cs(task, n_starts=n_starts, seed=seed, pick=5)
    if len(fam.picks) != 5:
        raise InputError(f"family: expected 5 picked dyads, got {len(fam.picks)}")
    synth = check_5cs(assemble_5cs(task, fam.picks), fam.picks)
    return PaperACheck(printed, proj, refitted, fam, synth)
