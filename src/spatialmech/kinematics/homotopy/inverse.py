"""Every solution of the inverse position of one limb (a serial chain of R, P, C, U, S joints
from the ground to the output link, the output link's pose given) by a parameter homotopy, with
a completeness statement: the solver (the limb's system, its formulation and families, in
:mod:`.limb_system`).

Solver: monodromy over random complex parameters from the start pair (loops ``P0 -> P1 -> P2 ->
P0``, four per round, plus fresh start pairs moved to ``P0``), stopped when a round finds nothing
new for :data:`MONODROMY_STALE_LOOPS` loops, or at once when the count reaches a known bound (16
for a 6R: Primrose 1986, Lee and Liang 1988, Raghavan and Roth 1993; then the root count is the
proof).  Otherwise the trace test (:mod:`.trace_test`, over the line from ``P0`` through a second
start pair) proves the generic set complete or says why not.  The generic solve is cached per limb
geometry; a request then tracks only those paths, by a parameter homotopy along the straight
segment from ``P0`` to the request (probability one: ``P0`` is random complex), with a Cauchy end
game at singular end points.  Each real end point is polished by Gauss-Newton on the limb
(:func:`..position.limb_gauss_newton`) and checked against the full closure.

Completeness: every isolated solution at the request is the end of a path from a generic
solution (the parameter homotopy theorem, Morgan and Sommese 1989), so the solutions are
*complete (proven)* when the generic set is (bound reached, or trace test passed) and no path was
lost (stopped short away from infinity); else *NOT proven*, with the reason.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...geometry.rotations import matrix_rotvec
from ...geometry.tolerances import (
    HOMOTOPY_NEAR_REAL,
    HOMOTOPY_REAL,
    HOMOTOPY_SINGULAR,
    MONODROMY_DIVERGED,
    MONODROMY_MAX_LOOPS,
    MONODROMY_PARALLEL,
    MONODROMY_STALE_LOOPS,
    ENDGAME_RADIUS,
    IK_DETOURS,
    IK_DETOUR_SIZE,
    TRACE_MAX_WORK_FULL,
    TRACE_TOL,
)
from ...model.mechanism import Mechanism
from ...results import TraceVerdict
from .. import backend
from ..closure import limb_chains
from .endgame import cauchy_endgame, multiple_root_end
from .study import track
from .trace_test import TraceResult, add_new_points, around_triangle, trace_test
from .limb_system import (
    BOUND_3R_POINT,
    BOUND_6R,
    BOUND_6R_WRIST,
    LimbIK,
    clear_systems,
    crand,
    ik_reason,
    limb_ik_system,
    start_pair,
)

__all__ = [
    "BOUND_3R_POINT",
    "BOUND_6R",
    "BOUND_6R_WRIST",
    "LimbIK",
    "LimbIKResult",
    "clear_cache",
    "ik_reason",
    "limb_ik_system",
    "limb_inverse",
]


def auto_reason(mech: Mechanism, li: int, seed: int = 0) -> str | None:
    """``None`` when ``method="auto"`` takes the homotopy for limb ``li``: it covers the limb and
    either a known root count bounds its generic solutions (the proof is then a count, found in
    well under a second) or its generic solve is already cached; else why the multi-start
    answers instead (the homotopy would need a trace test: tens of seconds per limb geometry;
    ``method="homotopy"`` runs it)."""
    sysm = limb_ik_system(mech, li, seed)  # InputError when not covered at all
    if sysm.bound or sysm.key in _CACHE:
        return None
    return ("no root-count bound is known for this limb: a proof needs the trace test (tens of seconds per limb "
            "geometry); method='homotopy' runs it")


# ------------------------------------------------------------------------------ solving
def _segment(sysm: LimbIK, X, P0, P1, steps: list[int] | None = None):
    """Track the points ``X`` from the parameters ``P0`` to ``P1`` (straight segments; each
    (n_params,) for all points or (n, n_params) one per point)."""
    if len(X) == 0:
        return X, np.zeros(0), np.zeros(0, bool)
    A0 = np.broadcast_to(P0, (len(X), sysm.n_params))
    dA = np.broadcast_to(P1, A0.shape) - A0
    if (fast := backend.engine()) is not None:
        packed = _PACKED.get(sysm.key)
        if packed is None:
            packed = _PACKED[sysm.key] = fast.ik_pack(sysm)
        TH, t, done, n_steps = fast.ik_track(packed, sysm.angles(X), A0, A0 + dA)
        if steps is not None:
            steps[0] += int(np.sum(n_steps))
        return sysm.from_angles(TH), t, done

    def fun(Xc, t, idx):
        return sysm.square(Xc, A0[idx] + t[:, None] * dA[idx], dA[idx])

    Xe, t, done, n_steps = track(fun, X, max_steps=2000, indexed=True)
    if steps is not None:
        steps[0] += int(np.sum(n_steps))
    return Xe, t, done


@dataclass(frozen=True, eq=False)
class _Generic:
    P0: np.ndarray
    X: np.ndarray
    loops: int
    seconds: float
    saturated: bool  # stopped because loops found nothing new (or the bound was reached)
    bound_reached: bool
    trace: TraceResult | None


_CACHE: dict[bytes, _Generic] = {}
_PACKED: dict[bytes, tuple] = {}


def clear_cache() -> None:
    """Forget the cached generic solves (benchmarks time the first solve)."""
    _CACHE.clear()
    clear_systems()
    _PACKED.clear()


def _monodromy(sysm: LimbIK, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, int, bool]:
    """The generic instance's solutions by monodromy: ``(P0, X, loops, saturated)``."""
    x0, P0 = start_pair(sysm, rng)
    scale = np.abs(P0) + 1.0
    k = MONODROMY_PARALLEL

    def waypoints(n):
        B = scale * crand(rng, n, sysm.n_params)
        if sysm.rigid:
            B[:, 7:] = 0.0
        return np.repeat(B, len(known), axis=0)

    known = x0[None]
    stale = loops = 0
    while stale < MONODROMY_STALE_LOOPS and loops < MONODROMY_MAX_LOOPS:
        if sysm.bound and len(known) >= sysm.bound:
            break
        loops += k
        B1, B2 = waypoints(k), waypoints(k)
        X = np.tile(known, (k, 1))
        X = around_triangle(lambda Xs, a, b: _segment(sysm, Xs, a, b), X, P0, B1, B2)
        fresh = [start_pair(sysm, rng) for _ in range(k)]
        Xr, _, done = _segment(sysm, np.array([f[0] for f in fresh]), np.array([f[1] for f in fresh]), P0)
        X = np.vstack([X, Xr[done]])
        X = X[np.all(np.isfinite(X), axis=1) & (np.linalg.norm(X, axis=1) < MONODROMY_DIVERGED)]
        known, stale = add_new_points(known, X, stale, k)
    saturated = stale >= MONODROMY_STALE_LOOPS or bool(sysm.bound and len(known) >= sysm.bound)
    return P0, known, loops, saturated


def _trace(sysm: LimbIK, P0: np.ndarray, X: np.ndarray, rng: np.random.Generator) -> TraceResult:
    """The trace test of ``X`` over the line from ``P0`` through a fresh start pair."""
    x1, P1 = start_pair(sysm, rng)
    V = P1 - P0
    nx = sysm.nx

    def curve(Y):
        P = P0[None] + Y[:, nx : nx + 1] * V[None]
        F, J, Ft = sysm.square(Y[:, :nx], P, np.broadcast_to(V, P.shape))
        return F, J, Ft

    return trace_test(curve, X, np.concatenate([x1, [1.0]]), rng, max_work=TRACE_MAX_WORK_FULL)


def _generic(sysm: LimbIK, seed: int) -> tuple[_Generic, bool]:
    """The cached generic solve of the limb (and whether it was cached)."""
    hit = _CACHE.get(sysm.key)
    if hit is not None:
        return hit, True
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, 31337])
    P0, X, loops, saturated = _monodromy(sysm, rng)
    bound_reached = bool(sysm.bound and len(X) >= sysm.bound)
    tr = _trace(sysm, P0, X, rng) if saturated and not bound_reached else None
    g = _Generic(P0, X, loops, time.perf_counter() - t0, saturated, bound_reached, tr)
    _CACHE[sysm.key] = g
    return g, False


@dataclass(frozen=True, eq=False)
class LimbIKResult:
    """Every real solution found of one limb at one pose: joint variables ``q`` of the limb's
    freedoms (one array per solution, in the order the paths end), and the counts and the
    completeness statement."""

    solutions: tuple[np.ndarray, ...]
    complete: bool
    completeness: str
    n_paths: int  # the generic solutions tracked
    n_real: int
    n_complex: int
    n_singular: int
    n_infinity: int
    n_spurious: int  # end points of the square system that do not close (graph family)
    n_lost: int
    cached: bool
    seconds_generic: float
    seconds: float
    trace: TraceResult | None = None

    def report(self) -> dict:
        """The per-limb search fields of :meth:`..position.InverseResult.to_dict`."""
        tr = self.trace
        return {"method": "homotopy", "complete": self.complete, "completeness": self.completeness,
                "n_paths": self.n_paths, "n_real": self.n_real, "n_complex": self.n_complex,
                "n_singular": self.n_singular, "n_at_infinity": self.n_infinity, "n_spurious": self.n_spurious,
                "n_lost": self.n_lost, "cached": self.cached, "generic_elapsed_s": round(self.seconds_generic, 4),
                "seconds": round(self.seconds, 4), "trace_test": None if tr is None else str(tr.verdict)}


def _refine(sysm: LimbIK, X, P, iters: int = 3):
    """Newton on the square system at ``P``; a step kept only when it lowers the residual."""
    X = X.copy()
    Pn = np.broadcast_to(P, (len(X), sysm.n_params))
    with np.errstate(all="ignore"):
        for _ in range(iters):
            F, J, _ = sysm.square(X, Pn)
            trial = X.copy()
            for n in range(len(X)):
                try:
                    dx = np.linalg.solve(J[n], F[n])
                except np.linalg.LinAlgError:
                    continue
                if np.all(np.isfinite(dx)):
                    trial[n] -= dx
            Ft, _, _ = sysm.square(trial, Pn)
            better = np.linalg.norm(Ft, axis=1) < np.linalg.norm(F, axis=1)
            X[better] = trial[better]
    return X


def _ball_rotation(sysm: LimbIK, x: np.ndarray, D: np.ndarray) -> np.ndarray:
    """The S joint's rotation that closes the limb at the real point ``x``: ``left R_s right^-1
    = D`` in rotation, so ``R_s = R_left^T R_D R_right``."""
    TL = sysm._chain(sysm.left, x[None].astype(complex))[0][0].real
    TR = sysm._chain(sysm.right, x[None].astype(complex))[0][0].real
    return TL[:3, :3].T @ D[:3, :3] @ TR[:3, :3]


def _to_q(sysm: LimbIK, x: np.ndarray, D: np.ndarray, axes: np.ndarray | None) -> np.ndarray:
    """The limb's joint variables of a real solution ``x``."""
    q = np.zeros(len(sysm.slots))
    for k, s in enumerate(sysm.slots):
        if s[0] == "R":
            q[k] = np.arctan2(x[s[2]], x[s[1]])
        elif s[0] == "P":
            q[k] = x[s[1]] * sysm.L
    balls = [s[1] for s in sysm.slots if s[0] == "S"]
    if balls and axes is not None:
        k = balls[0]
        q[k : k + 3] = np.linalg.solve(axes, matrix_rotvec(_ball_rotation(sysm, x, D)))
    return q


def _classify(sysm: LimbIK, X, P1, done) -> tuple[list[np.ndarray], dict[str, int]]:
    """The real, finite end points that close (nonsingular ones, and near-real singular ones as
    candidates for the caller's polish: a real solution at a singular configuration is a
    multiple root, whose end points keep about the square root of the rounding in their
    imaginary parts), and the counts of the others.  A near-real end point is counted singular,
    not complex, when its square system is ill-conditioned there (:func:`.endgame.multiple_root_end`)."""
    cnt = {"complex": 0, "singular": 0, "infinity": 0, "spurious": 0, "lost": 0}
    real: list[np.ndarray] = []
    kept = np.zeros((0, sysm.nx), complex)
    Pn = np.broadcast_to(P1, (len(X), sysm.n_params))
    with np.errstate(all="ignore"):
        finite = np.all(np.isfinite(X), axis=1) & ~(np.linalg.norm(X, axis=1) > MONODROMY_DIVERGED)
        res = np.full(len(X), np.inf)
        res[finite] = sysm.residual(X[finite], Pn[finite])
        imag = np.max(np.abs(X.imag), axis=1) / (1 + np.max(np.abs(X.real), axis=1))
        # the conditioning only where it decides (closing, near real): one batched SVD
        near = np.flatnonzero(finite & (res < 1e-8) & ~(imag > HOMOTOPY_NEAR_REAL))
        regular = np.zeros(len(X), bool)
        multiple = np.zeros(len(X), bool)
        if len(near):
            _, J, _ = sysm.square(X[near], Pn[near])
            sv = np.linalg.svd(J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300), compute_uv=False)
            regular[near] = sv[:, -1] >= HOMOTOPY_SINGULAR * sv[:, 0]
            multiple[near] = multiple_root_end(imag[near], sv[:, -1] / sv[:, 0])
    for n, x in enumerate(X):
        if not finite[n]:
            cnt["infinity"] += 1
            continue
        if not res[n] < 1e-8:
            cnt["spurious" if done[n] else "lost"] += 1
            continue
        if len(kept) and np.min(np.linalg.norm(kept - x, axis=1) / (1 + np.linalg.norm(x))) < 1e-6:
            continue  # two paths to one (singular) end point
        kept = np.vstack([kept, x[None]])
        if imag[n] > HOMOTOPY_NEAR_REAL:  # far from real (however ill-conditioned: large complex angles)
            cnt["complex"] += 1
            continue
        if not regular[n] or multiple[n]:
            cnt["singular"] += 1  # a multiple root (or a continuum): its real part is a candidate
            real.append(x.real.copy())
            continue
        if imag[n] < HOMOTOPY_REAL:
            real.append(x.real.copy())
        else:
            cnt["complex"] += 1
    return real, cnt


def _statement(sysm: LimbIK, g: _Generic, cnt: dict[str, int], n_real: int) -> tuple[bool, str]:
    """Whether the solutions are proven complete, and the statement."""
    n = len(g.X)
    fam = ("the pose itself (a generic complex pose)" if sysm.rigid
           else "the equations combined at random and offset (a generic complex offset)")
    head = f"monodromy over {fam}: {n} generic solution(s) after {g.loops} loops"
    tail = (f"; a parameter homotopy tracked the {n} paths to the pose: {n_real} real, {cnt['complex']} complex, "
            f"{cnt['infinity']} at infinity" + (f", {cnt['spurious']} that do not close discarded" if cnt["spurious"] else "")
            + (f", {cnt['singular']} singular" if cnt["singular"] else "")
            + (" (through a random complex waypoint: a path had stopped midway)" if cnt.get("detour") else ""))
    if g.bound_reached:
        proof = f"root count: {n} generic solutions = {sysm.bound_source}"
    elif g.trace is not None and g.trace.passed:
        proof = (f"trace test passed (the {n} solutions and {g.trace.n_witness} witness points, traces on a line to "
                 f"{g.trace.deviation:.1e} <= {TRACE_TOL:g})")
    elif g.trace is not None:
        why = {TraceVerdict.FAILED: "trace test FAILED: generic solutions are missing",
               TraceVerdict.INCONCLUSIVE: "trace test inconclusive (a path of its homotopies failed)",
               TraceVerdict.CAPPED: "trace test stopped at its work cap"}
        return False, f"NOT proven: {why[g.trace.verdict]}; {head}{tail}"
    else:
        return False, f"NOT proven: monodromy not saturated ({MONODROMY_MAX_LOOPS} loops); {head}{tail}"
    if cnt["lost"]:
        return False, f"NOT proven: {cnt['lost']} path(s) lost before the pose; {proof}; {head}{tail}"
    if cnt["singular"]:
        return False, (f"NOT proven at this pose: {cnt['singular']} singular end point(s) (a multiple root or a "
                       f"continuum); {proof}; {head}{tail}")
    return True, f"complete (proven, with probability one): {proof}; {head}{tail}"


def _to_pose(sysm: LimbIK, g: _Generic, P1: np.ndarray, seed: int):
    """Every generic solution tracked to ``P1``: ``(X, done, PA, XA, detours)``.  When a path stops
    midway (a near miss of a branch point), all are tracked again through a random complex waypoint
    ``B`` near the pose (:data:`IK_DETOUR_SIZE`; ``P0 -> B`` gives every solution at ``B``, ``B -> P1``
    misses the branch points with probability one), at most :data:`IK_DETOURS` times; ``PA``, ``XA``:
    the last segment's start and points (for the end game)."""

    def midway(X, t, done):
        with np.errstate(all="ignore"):
            return int(np.sum(~done & (np.linalg.norm(X, axis=1) < MONODROMY_DIVERGED) & (t < 1.0 - ENDGAME_RADIUS)))

    X, t, done = _segment(sysm, g.X, g.P0, P1)  # a finished path ends with two Newton corrections
    PA, XA, detours = g.P0, g.X, 0
    for k in range(IK_DETOURS):
        if not (lost := midway(X, t, done)):
            break
        z = crand(np.random.default_rng([seed, 2727, k]), sysm.n_params)
        z[7:] *= not sysm.rigid  # the rigid family has no offset
        B = P1 + IK_DETOUR_SIZE * np.linalg.norm(P1 - g.P0) * z / np.linalg.norm(z)
        XB, _, okB = _segment(sysm, g.X, g.P0, B)
        X2, t2, done2 = _segment(sysm, XB, B, P1) if okB.all() else (X, t, done)
        if midway(X2, t2, done2) < lost:
            X, t, done, PA, XA, detours = X2, t2, done2, B, XB, k + 1
    return X, done, PA, XA, detours


def limb_inverse(mech: Mechanism, li: int, D: np.ndarray, *, seed: int = 0) -> LimbIKResult:
    """Every real solution of limb ``li`` (from the ground to the output link) with the output
    link at the displacement ``D`` (4x4, model units): joint variables of its freedoms, closing
    to rounding (not yet polished: the caller polishes and dedupes), and the completeness
    statement (module docstring).  ``InputError`` when the homotopy does not cover the limb."""
    t0 = time.perf_counter()
    sysm = limb_ik_system(mech, li, seed)
    g, cached = _generic(sysm, seed)
    P1 = sysm.pose_parameters(np.asarray(D, float))
    P1[:4] *= P1[:4] @ g.P0[:4]  # the same rotation; the quaternion nearest P0's (a shorter path)
    X, done, PA, XA, detour = _to_pose(sysm, g, P1, seed)
    cand = np.flatnonzero(~done & np.all(np.isfinite(X), axis=1) & (np.linalg.norm(X, axis=1) < MONODROMY_DIVERGED))
    if len(cand):  # stopped short, not diverging: the Cauchy end game

        def trk(PA, PB, _c, Xs):
            return _segment(sysm, Xs, PA, PB)

        eg = cauchy_endgame(trk, PA, P1, np.zeros(0), XA[cand])
        X[cand[eg.converged]] = eg.X[eg.converged]
        done = done.copy()
        done[cand[eg.converged]] = True
        X[cand] = _refine(sysm, X[cand], P1)
    real, cnt = _classify(sysm, X, P1, done)
    cnt["detour"] = detour  # re-tracked through a waypoint (_to_pose)
    chain = limb_chains(mech)[li]
    axes = chain.balls[0][2] if chain.balls else None
    sols = tuple(_to_q(sysm, x, np.asarray(D, float), axes) for x in real)
    complete, text = _statement(sysm, g, cnt, len(sols) - cnt["singular"])  # the singular ones: candidates
    return LimbIKResult(sols, complete, text, len(g.X), len(sols), cnt["complex"], cnt["singular"], cnt["infinity"],
                        cnt["spurious"], cnt["lost"], cached, g.seconds, time.perf_counter() - t0, g.trace)
