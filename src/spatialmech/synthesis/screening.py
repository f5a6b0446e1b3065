"""Defect screening of 5-CS linkages drawn from a seven-position CS dyad family (paper A's
workflow taken to scale): sample dyads along every branch of the family (:func:`dyad_pool`),
form candidate linkages of five of them (:func:`candidate_sets`), and judge each one
(:func:`judge_candidate`) in stages, cheapest first:

1. ``assembly``: the linkage is built from its dyads (:func:`~.five_cs.assemble_5cs`), put at
   each task position in closed form (:func:`~.five_cs.cs_configuration`), and must close there
   (closure residual) with one degree of freedom (the scale-free smallest singular value of the
   closure Jacobian above the rank tolerance);
2. ``dj_signs``: DJ of every candidate driver (the rotation and the slide of each C joint) at the
   seven positions; a driver whose DJ changes sign between two positions has a zero (a branch
   point) or a pole of DJ between them, and is dropped; no driver left: rejected.  This is the
   fast rejection of the issue; a pole of DJ (the driver's own limb serially singular) would
   make it reject a usable driver, which the benchmark measures by judging rejected candidates
   in full;
3. ``circuits``: the defect analysis of ``spatialmech defects``
   (:func:`~spatialmech.analysis.defects.defect_analysis`) with the drivers left: circuit and
   order defects, branch points per driver along the path, the usable drivers, and the closest
   approach of the path to a singularity.

A candidate is *usable* when it passes all three with at least one usable driver.  Ranking
(:func:`rank_key`): the largest, over the usable drivers, of the smallest scale-free singular
value of the driver's complete Jacobian along the task path (the distance to a singularity),
then the total C-slide stroke over the positions (smaller first).

Everything here is serial and pure: the Dask / Parquet orchestration is in
:mod:`spatialmech.interfaces.batch`.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Sequence
from contextlib import nullcontext
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..geometry.tolerances import current as current_tolerances
from ..model.mechanism import Mechanism
from ..results import ScreenStage
from ..serialize import fields_dict
from ..kinematics.tracking import conventional_sense, python_loop
from .cs_dyads import CSBranch, CSDyad, CSFamily, CSTask, cs_task, dyad_from_vector
from .five_cs import cs_configuration, cs_configurations, cs_joints, five_cs_limb, five_cs_of_limbs

if TYPE_CHECKING:
    from ..analysis.defects import DJTable

__all__ = [
    "RANKINGS",
    "STAGES",
    "VERDICT_COLUMNS",
    "CandidateVerdict",
    "DyadPool",
    "candidate_linkage",
    "candidate_sets",
    "canonical",
    "closed_form_table",
    "dyad_pool",
    "judge_candidate",
    "judge_candidates",
    "nondimensional",
    "oriented",
    "rank_key",
]

#: The stages of the judgement, in order; a rejected candidate names the stage that rejected it.
STAGES = (ScreenStage.ASSEMBLY, ScreenStage.DJ_SIGNS, ScreenStage.CIRCUITS)


# ------------------------------------------------------------------------------ coordinates
def nondimensional(task_poses, x) -> np.ndarray:
    """Family points ``x = (B1, M1, u, s2..s7)`` (``(..., 15)``, task unit) in the family's
    nondimensional coordinates (points from the task centre, lengths divided by the task scale,
    ``u`` unchanged): the coordinates in which the family is traced and dyads are compared."""
    task = cs_task(task_poses)
    x = np.asarray(x, dtype=float)
    c, L = task.centre, task.scale
    return np.concatenate([(x[..., 0:3] - c) / L, (x[..., 3:6] - c) / L, x[..., 6:9], x[..., 9:15] / L], axis=-1)


def canonical(x) -> np.ndarray:
    """Family points ``x`` (``(..., 15)``) with the sign convention of picked dyads: the largest
    component of ``u`` positive (``u -> -u`` with ``s -> -s`` is the same dyad)."""
    x = np.array(x, dtype=float, copy=True)
    k = np.argmax(np.abs(x[..., 6:9]), axis=-1)
    neg = np.take_along_axis(x[..., 6:9], k[..., None], axis=-1)[..., 0] < 0
    x[neg, 6:15] *= -1
    return x


# ------------------------------------------------------------------------------ the dyad pool
@dataclass(frozen=True, eq=False)
class DyadPool:
    """Dyads sampled along the family: ``vectors[i] = (B1, M1, u, s2..s7)`` (task length unit,
    the sign convention of :func:`~.cs_dyads.canonical`), the ``branch`` (from 0) and ``arc``
    (nondimensional arc length along its branch) each came from; ``density`` = dyads per unit of
    nondimensional arc length."""

    task: CSTask
    vectors: np.ndarray
    branch: np.ndarray
    arc: np.ndarray
    density: float
    #: The joints of the dyads' limbs built so far, by dyad: candidates share dyads, and joints
    #: are frozen (:func:`candidate_linkage`).
    _joints: dict = field(default_factory=dict, init=False, repr=False, compare=False)  # not carried by replace()

    def __len__(self) -> int:
        return len(self.vectors)

    def __getstate__(self) -> dict:  # the joints are rebuilt where the pool is unpickled (a worker)
        return {**self.__dict__, "_joints": {}}

    @property
    def max_abs_slide(self) -> np.ndarray:
        """Largest |C slide| of each dyad over the positions (task length unit)."""
        return np.max(np.abs(self.vectors[:, 9:15]), axis=1)

    def dyad(self, i: int) -> CSDyad:
        return dyad_from_vector(self.task, self.vectors[int(i)])

    def dyads(self, idx: Sequence[int]) -> tuple[CSDyad, ...]:
        return tuple(self.dyad(i) for i in idx)


def oriented(task: CSTask, branch: CSBranch) -> CSBranch:
    """``branch`` in the pool's orientation, which depends on the branch as a curve, not on the
    sense it was traced in: an open branch runs from the end to the other so that the chord
    between its ends (nondimensional, :func:`nondimensional`) has its first non-negligible
    component positive (the rule of :func:`~spatialmech.kinematics.tracking.conventional_sense`);
    a closed one is kept as traced (from its start, in the tracer's conventional sense).  The
    same open branch traced the other way is the same points in the reverse order, so it gives
    the same pool: neither the dyads sampled nor their indices follow the tracer's sense."""
    if branch.closed or len(branch.arc) < 2:
        return branch
    ends = nondimensional(task, branch.points[[0, -1]])
    if conventional_sense(ends[1] - ends[0]) > 0:
        return branch
    arc = branch.arc[-1] - branch.arc[::-1]
    return replace(branch, points=branch.points[::-1], arc=arc, ends=branch.ends[::-1])


def dyad_pool(family: CSFamily, density: float) -> DyadPool:
    """Dyads spread evenly in arc length along every branch of ``family``: ``max(2, round(density
    * arc length))`` per branch (ends included), ``density`` in dyads per unit of nondimensional
    arc length (the family is traced in task scales).  Each branch is sampled in its
    :func:`oriented` order, so the pool does not depend on the sense its branches were traced in."""
    if not (isinstance(density, (int, float)) and math.isfinite(density) and density > 0):
        raise InputError(f"density: expected a positive number of dyads per unit arc length, got {density!r}")
    vecs, br, arc = [], [], []
    for k, b in enumerate(family.branches):
        b = oriented(family.task, b)
        n = max(2, round(density * float(b.arc[-1] - b.arc[0])))
        idx = b.sample(n)
        vecs.append(b.points[idx])
        br.append(np.full(len(idx), k))
        arc.append(b.arc[idx])
    if not vecs:
        raise InputError("family: it has no branches to sample")
    return DyadPool(family.task, canonical(np.concatenate(vecs)), np.concatenate(br), np.concatenate(arc),
                    float(density))


# ------------------------------------------------------------------------------ candidates
def _separated(Y: np.ndarray, idx, separation: float) -> bool:
    """Every pair of ``Y[idx]`` (nondimensional) at least ``separation`` apart, up to the u flip."""
    P = Y[list(idx)]
    flipped = P.copy()
    flipped[:, 6:15] *= -1
    for a, b in itertools.combinations(range(len(P)), 2):
        if min(np.linalg.norm(P[a] - P[b]), np.linalg.norm(P[a] - flipped[b])) < separation:
            return False
    return True


def candidate_sets(pool: DyadPool, n: int, *, seed: int = 0, separation: float = 0.5,
                   max_tries: int | None = None) -> tuple[np.ndarray, str]:
    """Up to ``n`` candidate linkages as sorted index quintuples into ``pool`` (``(m, 5)``, in a
    fixed order) and how they were formed:

    - ``"all"``: when the pool has at most ``n`` combinations of five, every combination whose
      dyads are pairwise at least ``separation`` apart (nondimensional, up to the u flip);
    - ``"weighted sample"``: otherwise, distinct quintuples drawn with a generator seeded with
      ``seed``, each dyad with probability proportional to ``(s_min / s)^2`` (``s`` its largest
      |slide|, ``s_min`` the pool's smallest: small slides preferred), kept when well spread
      (``separation``); at most ``max_tries`` draws (default ``50 n``).
    """
    if not (isinstance(n, (int, np.integer)) and n >= 1):
        raise InputError(f"candidates: expected a positive whole number, got {n!r}")
    if not (math.isfinite(separation) and separation >= 0):
        raise InputError(f"separation: expected a number >= 0, got {separation!r}")
    m = len(pool)
    if m < 5:
        raise InputError(f"density: only {m} dyads sampled from the family; a 5-CS needs 5 (raise the density)")
    Y = nondimensional(pool.task, pool.vectors)
    if math.comb(m, 5) <= n:
        out: list[tuple[int, ...]] = [c for c in itertools.combinations(range(m), 5) if _separated(Y, c, separation)]
        return np.array(out, dtype=np.int64).reshape(-1, 5), "all"
    s = pool.max_abs_slide
    w = (np.min(s) / np.maximum(s, 1e-300)) ** 2
    w = w / w.sum()
    rng = np.random.default_rng(seed)
    seen: set[tuple[int, ...]] = set()
    out = []
    tries = 50 * n if max_tries is None else int(max_tries)
    for _ in range(tries):
        if len(out) >= n:
            break
        c = tuple(sorted(int(i) for i in rng.choice(m, 5, replace=False, p=w)))
        if c in seen:
            continue
        seen.add(c)
        if _separated(Y, c, separation):
            out.append(c)
    return np.array(out, dtype=np.int64).reshape(-1, 5), "weighted sample"


def candidate_linkage(pool: DyadPool, idx: Sequence[int], *, name: str | None = None) -> Mechanism:
    """The 5-CS linkage of the pool's dyads ``idx`` (:func:`~.five_cs.assemble_5cs`)."""
    idx = [int(i) for i in idx]
    if len(idx) != 5:
        raise InputError(f"idx: a 5-CS linkage needs exactly 5 dyads, got {len(idx)}")
    limbs = []
    for place, i in enumerate(idx):
        joints = pool._joints.get(i)
        if joints is None:
            joints = pool._joints[i] = cs_joints(pool.dyad(i), field=f"pool dyad {i}")
        limbs.append(five_cs_limb(place, joints))
    return five_cs_of_limbs(pool.task, tuple(limbs), name=name or "five-cs-" + "-".join(map(str, idx)))


# ------------------------------------------------------------------------------ judging
@dataclass(frozen=True)
class CandidateVerdict:
    """The judgement of one candidate (:func:`judge_candidate`): ``rejected_by`` = the stage
    that rejected it (``None``: it passed every stage; ``"error"``: a numerical routine failed,
    ``error`` says how), the drivers whose DJ keeps its sign at the positions, the drivers the
    full analysis found usable or with a branch defect, its circuit/order defects, the closest
    approach to a singularity (closure, and the best usable driver), the C-slide stroke
    (sum over the limbs of max - min slide over the positions, task unit) and the time taken."""

    candidate: int
    dyads: tuple[int, ...]
    rejected_by: ScreenStage | None
    keeps_sign: tuple[str, ...] = ()
    usable_drivers: tuple[str, ...] = ()
    branch_defect_drivers: tuple[str, ...] = ()
    circuit_defect: bool | None = None
    order_defect: bool | None = None
    n_circuits: int | None = None
    min_closure_sigma_positions: float | None = None
    min_closure_sigma_path: float | None = None
    min_driver_sigma_path: float | None = None
    best_driver: str | None = None
    stroke: float = math.nan
    max_abs_slide: float = math.nan
    seconds: float = 0.0
    error: str | None = None

    @property
    def usable(self) -> bool:
        return self.rejected_by is None and bool(self.usable_drivers)

    def row(self) -> dict:
        """One row of the screening dataset (docs/screening.md names the columns)."""
        return fields_dict(self, {a: c for a, c, _ in VERDICT_COLUMNS if a != c}, names=[a for a, _, _ in VERDICT_COLUMNS])


#: The columns of a verdict row, in order (docs/screening.md): (attribute of
#: :class:`CandidateVerdict`, column, Parquet type).  The one spelling of each column: :meth:`CandidateVerdict.row`
#: and the dataset's Parquet schema (``row_schema`` of the batch screen, which adds ``chunk`` and ``worker``) read it.
VERDICT_COLUMNS: tuple[tuple[str, str, str], ...] = (
    ("candidate", "candidate", "int64"),
    ("dyads", "dyads", "list<int32>"),
    ("rejected_by", "rejected_by", "string"),
    ("usable", "usable", "bool"),
    ("keeps_sign", "keeps_sign", "list<string>"),
    ("usable_drivers", "usable_drivers", "list<string>"),
    ("branch_defect_drivers", "branch_defect_drivers", "list<string>"),
    ("circuit_defect", "circuit_defect", "bool"),
    ("order_defect", "order_defect", "bool"),
    ("n_circuits", "n_circuits", "int32"),
    ("min_closure_sigma_positions", "min_closure_sigma_at_positions", "float64"),
    ("min_closure_sigma_path", "min_closure_sigma_on_path", "float64"),
    ("min_driver_sigma_path", "min_sigma_on_path", "float64"),
    ("best_driver", "best_driver", "string"),
    ("stroke", "stroke_len", "float64"),
    ("max_abs_slide", "max_abs_slide_len", "float64"),
    ("seconds", "seconds", "float64"),
    ("error", "error", "string"),
)

#: The rankings of usable candidates (:func:`rank_key`), the default first.
RANKINGS = ("singularity", "slide")


def row_differences(a: dict, b: dict, rel_tol: float) -> list[str]:
    """The columns in which two verdict rows differ.

    Parameters
    ----------
    a, b : dict
        Verdict rows (:meth:`CandidateVerdict.row`) of the same candidate, e.g. by the
        reference and the batched judgement.
    rel_tol : float
        Floats agree within ``rel_tol * max(1, |a|)``; two NaN agree.  The ``seconds``
        column (a timing) is not compared.

    Returns
    -------
    list of str
        The differing columns, in the order of ``a`` (empty: the rows agree).
    """
    bad = []
    for k in a:
        if k == "seconds":
            continue
        x, y = a[k], b[k]
        if isinstance(x, float) and isinstance(y, float):
            if not ((math.isnan(x) and math.isnan(y)) or abs(x - y) <= rel_tol * max(1.0, abs(x))):
                bad.append(k)
        elif x != y:
            bad.append(k)
    return bad


def rank_key(row, by: str = "singularity") -> tuple[float, float]:
    """Sort key of usable candidates (a :class:`CandidateVerdict` or its :meth:`row`), best
    first.  ``by="singularity"``: the larger distance to a singularity along the path
    (``min_sigma_on_path``), then the smaller stroke; ``by="slide"``: the smaller stroke, then
    the larger distance."""
    if by not in RANKINGS:
        raise InputError(f"rank_by: expected one of {', '.join(RANKINGS)}, got {by!r}")
    r = row.row() if isinstance(row, CandidateVerdict) else row
    sig = r["min_sigma_on_path"]
    far = -(sig if sig is not None and math.isfinite(sig) else -1.0)
    stroke = float(r["stroke_len"])
    return (far, stroke) if by == "singularity" else (stroke, far)


def _closure_at_positions(mech: Mechanism, configs) -> tuple[float, float, np.ndarray]:
    """Largest nondimensional closure residual and smallest scale-free closure sigma over
    ``configs``, and each one's row-scaled residual norm (as :func:`~..kinematics.closure.correct`
    reports it)."""
    from ..kinematics.closure import active_mask, closure_scales
    from ..kinematics.backend import closure_jacobian, closure_residual

    L = mech.characteristic_length
    active = active_mask(mech)
    row, col = closure_scales(mech, active)
    worst_res, min_sig, norms = 0.0, math.inf, []
    for c in configs:
        r = np.asarray(closure_residual(mech, c), dtype=float).reshape(-1, 6)
        worst_res = max(worst_res, float(np.max(np.abs(r[:, :3]))), float(np.max(np.abs(r[:, 3:]))) / L)
        norms.append(float(np.linalg.norm(row * r.reshape(-1))))
        A, _ = closure_jacobian(mech, c, active=active)
        sv = np.linalg.svd(row[:, None] * A * col[None, :], compute_uv=False)
        min_sig = min(min_sig, float(sv[-1] / sv[0]))
    return worst_res, min_sig, np.array(norms)


def _closure_at_positions_batched(mech: Mechanism, configs, engine) -> tuple[float, float, np.ndarray]:
    """:func:`_closure_at_positions` with the compiled engine: one batched call for the residuals
    and Jacobians at every position, one stacked SVD (the same numbers, per position)."""
    from ..kinematics.closure import closure_scales

    L = mech.characteristic_length
    cm = engine.compile_mechanism(mech)
    row, col = closure_scales(mech, cm.active)
    q = np.array([c.q for c in configs])
    D = np.array([c.D for c in configs])
    A, r = engine.closure_jacobians(mech, q, D)
    norms = np.linalg.norm(row[None, :] * r.reshape(len(configs), -1), axis=1)
    r = r.reshape(len(configs), -1, 6)
    worst_res = max(0.0, float(np.max(np.abs(r[:, :, :3]))), float(np.max(np.abs(r[:, :, 3:]))) / L)
    sv = np.linalg.svd(row[None, :, None] * A * col[None, None, :], compute_uv=False)
    return worst_res, float(np.min(sv[:, -1] / sv[:, 0])), norms


def _unwrapped(mech: Mechanism, configs: list) -> list:
    """The closed-form configurations with each C rotation made continuous from position to
    position (:func:`numpy.unwrap`; the closed form gives it in (-pi, pi]): the values a fit
    from the previous position finds, so that circuits traced from them read the same."""
    from ..kinematics.closure import Configuration

    rot = np.array([r.freedom.kind == "R" and mech.limbs[r.limb].joints[r.joint].type == "C" for r in mech.freedom_refs])
    Q = np.array([c.q for c in configs])
    Q[:, rot] = np.unwrap(Q[:, rot], axis=0)
    return [Configuration(Q[j], c.D, c.B) for j, c in enumerate(configs)]


@dataclass(frozen=True, eq=False)
class _AtPositions:
    """Stages 1 and 2 at the task positions: the worst closure residual, the smallest scale-free
    closure sigma, the candidate drivers, DJ ``(positions, drivers)`` (``None`` when the closure
    fails the assembly stage), the closed-form configurations and their residual norms."""

    residual: float
    sigma: float
    drivers: list
    dj: np.ndarray | None
    configs: list
    norms: np.ndarray

    def table(self, mech: Mechanism, drivers) -> DJTable:
        """The :class:`~..analysis.defects.DJTable` of ``drivers`` (a subset of :attr:`drivers`)
        from these configurations: what :func:`~..analysis.defects.dj_table` would fit, without
        fitting (the closed form is exact; the pose errors are measured)."""
        from ..analysis.defects import DJTable
        from ..geometry.rotations import matrix_rotvec
        from ..kinematics.position import PoseFit

        if self.dj is None:
            raise InputError(f"mech: {mech.name} does not close at its positions (residual {self.residual:.2e}, "
                             f"closure sigma {self.sigma:.2e})")
        tol = current_tolerances()
        L = mech.characteristic_length
        fits = []
        for P, c, rn in zip(mech.positions, _unwrapped(mech, self.configs), self.norms, strict=True):
            p_got = c.D[:3, :3] @ mech.platform_point + c.D[:3, 3]
            ang = float(np.linalg.norm(matrix_rotvec(c.D[:3, :3] @ P.R.T)))
            fits.append(PoseFit(c, bool(rn < tol.closure), bool(rn < tol.closure), float(np.linalg.norm(p_got - P.p)),
                                ang, float(rn), L))
        cols = [self.drivers.index(d) for d in drivers]
        return DJTable(mech.name, tuple(P.name for P in mech.positions), tuple(drivers), self.dj[:, cols].T.copy(),
                       tuple(fits), mech, tol)


def _positions_stage(mech: Mechanism, batched: bool) -> _AtPositions:
    """At the task positions (their C-S configurations): stages 1 and 2 of
    :func:`judge_candidate` (:class:`_AtPositions`).  ``batched``: closed forms vectorised over
    the positions and the compiled engine called once for all of them (when it is in use); else
    the reference path, position by position."""
    from ..analysis.defects import candidate_drivers, dj_function
    from ..kinematics import backend

    engine = backend.engine() if batched else None
    if engine is None:
        configs = [cs_configuration(mech, P) for P in mech.positions]
        if any(c is None for c in configs):
            raise InputError("dyads: a candidate limb is not a C-S chain")
        res, sig, norms = _closure_at_positions(mech, configs)
    else:
        cfgs = cs_configurations(mech)
        if cfgs is None:
            raise InputError("dyads: a candidate limb is not a C-S chain")
        configs = cfgs
        res, sig, norms = _closure_at_positions_batched(mech, configs, engine)
    drivers = candidate_drivers(mech)
    if not (res <= current_tolerances().reachability and sig > current_tolerances().rank):
        return _AtPositions(res, sig, drivers, None, configs, norms)
    dj = None
    if engine is not None:
        dj = engine.driver_determinants_many(mech, np.array([c.q for c in configs]), np.array([c.D for c in configs]),
                                             None, drivers)
        if dj is not None and not np.all(np.isfinite(dj[0])):
            dj = None  # not the complete-Jacobian determinant: the reference's DJ function decides
    if dj is None:
        djf, _ = dj_function(mech, drivers, configs[0])
        dj = np.array([djf(c) for c in configs])
    return _AtPositions(res, sig, drivers, dj, configs, norms)


def closed_form_table(mech: Mechanism, drivers=None) -> DJTable:
    """The :class:`~..analysis.defects.DJTable` of a 5-CS linkage (default drivers: every
    candidate driver) from the closed-form C-S configurations at its positions, as the screen
    hands it to the defect analysis: :func:`~..analysis.defects.dj_table`'s numbers without its
    Gauss-Newton fits.  ``InputError`` when the linkage does not close at its positions."""
    at = _positions_stage(mech, True)
    return at.table(mech, at.drivers if drivers is None else list(drivers))


def judge_candidate(pool: DyadPool, idx: Sequence[int], *, candidate: int = 0, h0: float = 0.02,
                    max_arc: float = 400.0, batched: bool = True) -> CandidateVerdict:
    """Judge the 5-CS of the pool's dyads ``idx`` in the stages of the module docstring.  A
    failure of a numerical routine inside a stage (``InputError``/``ValueError``/
    ``RuntimeError``, e.g. a position that cannot be fitted, a circuit that cannot be traced)
    rejects the candidate as ``"error"`` with the message; it is never dropped silently.
    ``batched``: the positions' stages in batches (:func:`_positions_stage`); ``False``: the
    reference path, position by position (the same verdicts, ``tests/test_screen_batched.py``)."""
    from ..analysis.defects import defect_analysis

    t0 = time.perf_counter()
    idx = tuple(int(i) for i in idx)
    V = pool.vectors[list(idx)]
    slides = np.concatenate([np.zeros((5, 1)), V[:, 9:15]], axis=1)
    stroke, max_abs_slide = float(np.sum(np.ptp(slides, axis=1))), float(np.max(np.abs(slides)))

    def done(**kw) -> CandidateVerdict:
        return CandidateVerdict(candidate=int(candidate), dyads=idx, stroke=stroke, max_abs_slide=max_abs_slide, **kw,
                                seconds=time.perf_counter() - t0)

    try:
        mech = candidate_linkage(pool, idx)
        at = _positions_stage(mech, batched)
        sig, drivers, dj = at.sigma, at.drivers, at.dj
        if dj is None:
            return done(rejected_by=ScreenStage.ASSEMBLY, min_closure_sigma_positions=sig)
        s = np.sign(dj)
        keeps = tuple(d for k, d in enumerate(drivers) if np.all(s[:, k] == s[0, k]) and s[0, k] != 0)
        if not keeps:
            return done(rejected_by=ScreenStage.DJ_SIGNS, min_closure_sigma_positions=sig)
        # one degree of freedom is shown by the assembly stage (the closure Jacobian has full row
        # rank at the positions, so generically): the analysis's own mobility check is skipped;
        # the positions need no fit (the closed form closes them: the assembly stage)
        with nullcontext() if batched else python_loop():  # the reference: the tracker's Python loop
            r = defect_analysis(mech, drivers=list(keeps), h0=h0, max_arc=max_arc, check_dof=not batched,
                                table=at.table(mech, keeps))
    except (InputError, ValueError, RuntimeError, np.linalg.LinAlgError) as e:
        return done(rejected_by=ScreenStage.ERROR, error=f"{type(e).__name__}: {e}")
    usable = tuple(r.usable_drivers)
    sig_d = {v.driver: v.min_sigma_on_path for v in r.drivers if v.usable and v.min_sigma_on_path is not None}
    best = max(sig_d, key=lambda d: sig_d[d]) if sig_d else None
    return done(
        rejected_by=None if usable else ScreenStage.CIRCUITS, keeps_sign=keeps, usable_drivers=usable,
        branch_defect_drivers=tuple(v.driver for v in r.drivers if v.branch_defect),
        circuit_defect=bool(r.circuit_defect), order_defect=bool(r.order_defect), n_circuits=len(r.circuits),
        min_closure_sigma_positions=sig, min_closure_sigma_path=r.min_closure_sigma,
        min_driver_sigma_path=sig_d[best] if best else None, best_driver=best,
    )


def judge_candidates(pool: DyadPool, sets: np.ndarray, first: int = 0, **kw) -> list[CandidateVerdict]:
    """:func:`judge_candidate` over the rows of ``sets`` (candidate numbers from ``first``)."""
    return [judge_candidate(pool, c, candidate=first + k, **kw) for k, c in enumerate(np.asarray(sets))]
