"""Every assembly mode of a model whose limbs do not reduce to quadrics in the Study parameters
(:mod:`.systems`): the loop formulation of :mod:`.loop_system` (joint variables,
generated from the model; link-and-joint graphs with internal bodies included, each body's
displacement the product of a reference limb or its own Study parameters) solved by monodromy
and a parameter homotopy.  A real solution becomes a :class:`Configuration` with its bodies
(:func:`rebuild_configuration`).

Solver: monodromy on a family of square systems with a start pair built from a random complex
point, then a parameter homotopy to the request.  When every limb's equations are independent
(the ranks equal the numbers of equations: no random combination needed), the family moves the
limbs themselves (:attr:`LoopSystem.rigid_family`): a complex rigid offset ``W_k`` (a
quaternion and a translation) per limb without S joint, a point offset per single S joint and a
change of length per rod; a random complex point ``x0`` on the circles (and the Study quadric)
closes with the offsets it misses by, and the genuine solutions form an irreducible incidence
variety (parametrised by ``x`` and the actuators), so the loops act transitively on the generic
solutions and never leave them: no spurious points (the general 6R loop: the 16 solutions of
the inverse kinematics, no more).  Otherwise (overconstrained or spherical limbs) the family is
``G(x; p) = b`` with an offset ``b`` of the square system: for a random complex ``x0`` and
``p0``, ``b0 = G(x0; p0)``; that incidence variety is the graph of ``G``, irreducible too, but
its generic solutions include points of the square system that do not close.  Loops
``P0 -> P1 -> P2 -> P0`` through random complex parameters (four per round, each round also
moving fresh start pairs to ``P0``) stop after :data:`MONODROMY_STALE_LOOPS` loops in a row
without a new solution: a *saturation*, not a proof; the trace test (:mod:`.trace_test`, over
the line from ``P0`` through a fresh start pair) then proves the generic solutions complete or
says why not, and ``complete`` is true only when it passed.  A parameter homotopy along the
straight segment from ``P0`` to the request (actuators given, no offsets) then tracks every
known solution, with the NumPy tracker
:func:`.study.track` and the compiled square system (``compiled/kernels_loops.py``).  The generic
solve is cached per geometry (in memory).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...geometry.rotations import matrix_rotvec, skew
from ...geometry.tolerances import (
    HOMOTOPY_INFINITY,
    HOMOTOPY_REAL,
    HOMOTOPY_SINGULAR,
    MONODROMY_DIVERGED,
    MONODROMY_MAX_LOOPS,
    MONODROMY_MAX_SOLUTIONS,
    MONODROMY_MAX_WORK,
    MONODROMY_PARALLEL,
    MONODROMY_RESIDUAL,
    MONODROMY_STALE_LOOPS,
    TRACE_MAX_WORK,
    TRACE_MAX_WORK_FULL,
    TRACE_TOL,
)
from ...model.mechanism import Mechanism
from ...results import EndPointStatus, TraceVerdict
from ..closure import Configuration, limb_slices
from .endgame import cauchy_endgame, multiple_root_end
from .study import study_to_pose, track
from .loop_system import LoopSystem, general_reason, loop_system, variables
from .trace_test import TraceResult, add_new_points, around_triangle, trace_test

__all__ = [
    "GeneralResult",
    "GeneralSolution",
    "LoopSystem",
    "angle_form",
    "clear_cache",
    "configuration",
    "general_forward",
    "general_reason",
    "line_eval",
    "loop_system",
    "rebuild",
    "rebuild_configuration",
    "variables",
]


# ------------------------------------------------------------------------------ solving
def _rotations(sysm: LoopSystem) -> list[tuple[int, int]]:
    """The ``(c, s)`` slots of the driven rotations in the actuator parameters."""
    return [(idx[0] - sysm.nx, idx[1] - sysm.nx) for _, kind, idx in sysm.params if kind == "R"]


def angle_form(sysm: LoopSystem, P: np.ndarray) -> np.ndarray:
    """Parameters ``P`` (..., np + nw + nx, or the actuators alone) with each driven rotation's ``(c, s)`` (on its circle)
    replaced by ``(theta, 0)``, ``c + i s = exp(i theta)`` (complex ``theta``): the form in
    which the homotopies move them, so that every point of a straight segment keeps the
    rotation on its circle (off it the family is larger, and its members with the actuators on
    the circle, the request's included, are special ones that lose solutions to infinity)."""
    P = np.array(P, dtype=complex)
    for ic, js in _rotations(sysm):
        P[..., ic], P[..., js] = -1j * np.log(P[..., ic] + 1j * P[..., js]), 0.0
    return P


def line_eval(sysm: LoopSystem, X: np.ndarray, P: np.ndarray, dP: np.ndarray):
    """The square system ``G(x; P) = square(x; p, W) - b`` at the points ``X`` (n, nx) with the
    parameters ``P`` (n, np + nw + nx, :func:`angle_form`: actuator parameters, the limbs' offsets
    ``W``, the offsets ``b``), its Jacobian in ``x`` and its derivative along ``dP`` (n, same):
    exact in the actuators and ``b``; by central differences in ``W`` (exact up to rounding for
    the parts of degree two or less, ample for a predictor)."""
    nx, npar, nw = sysm.nx, sysm.npar, sysm.w_offsets[-1]
    h = 1e-5
    rot = _rotations(sysm)
    if rot:  # (theta, 0) -> (cos, sin), and the chain rule
        P, dP = P.copy(), dP.copy()
        for ic, js in rot:
            th, dth = P[:, ic].copy(), dP[:, ic].copy()
            P[:, ic], P[:, js] = np.cos(th), np.sin(th)
            dP[:, ic], dP[:, js] = -np.sin(th) * dth, np.cos(th) * dth

    def G(Xc, Pc, want_J):
        F, J = sysm.square(np.concatenate([Xc, Pc[:, :npar]], axis=1), Pc[:, npar : npar + nw], want_J=want_J)
        return F - Pc[:, npar + nw :], J

    n = len(X)
    F, J = G(X, P, True)
    Ft = np.einsum("nkp,np->nk", J[:, :, nx:], dP[:, :npar]) - dP[:, npar + nw :]
    if np.any(dP[:, npar : npar + nw]):  # the limbs' offsets: central differences in W alone
        dW = np.zeros_like(P)
        dW[:, npar : npar + nw] = h * dP[:, npar : npar + nw]
        Fp, _ = G(np.tile(X, (2, 1)), np.concatenate([P + dW, P - dW]), False)
        Ft = Ft + (Fp[:n] - Fp[n:]) / (2 * h)
    return F, J[:, :, :nx], Ft


def _segment(sysm: LoopSystem, X, P0, P1, steps: list[int] | None = None):
    """Track the points ``X`` (n, nx) from the parameters ``P0`` to ``P1`` (straight segments;
    each (np + nw + nx,) for all points or (n, np + nw + nx) one per point; :func:`line_eval`)."""
    nx, npar, nw = sysm.nx, sysm.npar, sysm.w_offsets[-1]
    if len(X) == 0:
        return X, np.zeros(0), np.zeros(0, bool)
    A0 = np.broadcast_to(P0, (len(X), npar + nw + nx))
    dA = np.broadcast_to(P1, A0.shape) - A0

    def fun(Xc, t, idx):
        return line_eval(sysm, Xc, A0[idx] + t[:, None] * dA[idx], dA[idx])

    Xe, t, done, n_steps = track(fun, X, max_steps=2000, indexed=True)
    if steps is not None:  # the caller's count of the tracker's accepted steps
        steps[0] += int(np.sum(n_steps))
    return Xe, t, done


def _random_point(sysm: LoopSystem, rng: np.random.Generator) -> np.ndarray:
    """A random complex point ``x`` on the side equations (circles, Study quadric, patch)."""
    x = rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)
    for a, b in sysm.circles:
        th = rng.uniform(-np.pi, np.pi) + 1j * rng.normal(scale=0.5)
        x[a], x[b] = np.cos(th), np.sin(th)
    for h in sysm.studies:
        s = h.study
        e, g = x[s : s + 4], x[s + 4 : s + 8]
        g = g - (e @ g) / (e @ e) * e
        xs = np.concatenate([e, g])
        assert h.patch is not None
        x[s : s + 8] = xs / (xs @ h.patch)
    return x


def _random_parameters(sysm: LoopSystem, rng: np.random.Generator) -> np.ndarray:
    """Random complex actuator parameters, a driven rotation's ``(c, s)`` on its circle (so that
    every displacement of a start pair is a complex rigid motion)."""
    p = rng.normal(size=sysm.npar) + 1j * rng.normal(size=sysm.npar)
    for _, kind, idx in sysm.params:
        if kind == "R":
            th = rng.uniform(-np.pi, np.pi) + 1j * rng.normal(scale=0.5)
            p[idx[0] - sysm.nx], p[idx[1] - sysm.nx] = np.cos(th), np.sin(th)
    return p


def _start_offsets(sysm: LoopSystem, x: np.ndarray, p: np.ndarray) -> np.ndarray:
    """The offset parameters for which ``x`` (on the side equations) with actuator parameters
    ``p`` solves the closure: each limb's offset is what it misses by."""
    z = np.concatenate([x, p])[None]
    H = sysm.hub_values(z)
    off = sysm.w_offsets
    W = np.zeros(off[-1], complex)
    for k, le in enumerate(sysm.limbs):
        Tb3, _, D3, _, Ea3, _, E3, _ = sysm.limb_sides(le, H, z)
        Tb, D, Ea, E = Tb3[0], D3[0], Ea3[0], E3[0]
        if le.kind == "full":
            M = np.linalg.solve(D[:3, :3], Tb[:3, :3])  # proportional to a complex rotation
            sc = np.sqrt(np.trace(M.T @ M) / 3)
            if abs(np.linalg.det(M) / sc**3 + 1) < 0.5:
                sc = -sc
            R = M / sc
            W[off[k] : off[k] + 4] = [1 + np.trace(R), R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]
            W[off[k] + 4 : off[k] + 7] = np.linalg.solve(D[:3, :3], E * Tb[:3, 3] / Ea - D[:3, 3])
            continue
        Ta = sysm._chain(le.after_inv, z)[0][0]
        w = (E * (Tb @ le.c1) - Ea * (D @ (Ta @ le.c2)))[:3]
        if le.kind == "point":
            W[off[k] : off[k] + 3] = w / (Ea * E)
        else:
            W[off[k]] = (w @ w) / (Ea * E) ** 2 - le.length2
    return W


def _start_pairs(sysm: LoopSystem, rng: np.random.Generator, n: int,
                 p_fixed: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``n`` start pairs ``(x, P)``: with limb offsets, a point on the side equations and the
    offsets that make it close; else any point and the offset ``b`` that makes it a solution.
    The actuator parameters are random (a driven rotation's on its circle), or ``p_fixed``."""
    xs, Ps = [], []
    for _ in range(n):
        p = _random_parameters(sysm, rng) if p_fixed is None else p_fixed
        if sysm.rigid_family:
            x = _random_point(sysm, rng)
            Ps.append(np.concatenate([p, _start_offsets(sysm, x, p), np.zeros(sysm.nx)]))
        else:
            x = rng.normal(size=sysm.nx) + 1j * rng.normal(size=sysm.nx)
            W = sysm.identity_offsets()[0]
            b = sysm.square(np.concatenate([x, p])[None], W[None])[0][0]
            Ps.append(np.concatenate([p, W, b]))
        xs.append(x)
    return np.array(xs), angle_form(sysm, np.array(Ps))


@dataclass(frozen=True, eq=False)
class _GenericLoop:
    P0: np.ndarray  # the generic parameters: actuators, then offsets
    X: np.ndarray
    loops: int
    seconds: float
    saturated: bool


_CACHE: dict[bytes, _GenericLoop] = {}


def _monodromy(sysm: LoopSystem, seed: int, capped: bool) -> _GenericLoop:
    """The generic instance's solutions by monodromy; ``capped``: also stop at
    :data:`MONODROMY_MAX_SOLUTIONS` solutions or :data:`MONODROMY_MAX_WORK` (tracker steps times
    unknowns: a count, so that the choice does not depend on the machine's speed; unsaturated)."""
    key = sysm.key() + bytes([seed % 256])
    if key in _CACHE:
        return _CACHE[key]
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)

    def crand(*shape):
        return rng.normal(size=shape) + 1j * rng.normal(size=shape)

    rigid = sysm.rigid_family
    X0, P0s = _start_pairs(sysm, rng, 1)
    x0, P0 = X0[0], P0s[0]
    npar, nw = sysm.npar, sysm.w_offsets[-1]
    free = np.zeros(len(P0), bool)  # the parameters the loops move: actuators, and W or b
    free[:npar] = True
    if rigid:
        free[npar : npar + nw] = True
    else:
        free[npar + nw :] = True
    scale = np.where(free, np.abs(P0) + 1.0, 0.0)

    def waypoints(n):
        """Random parameters of the family: offsets at random, the actuators as a start pair's
        (a driven rotation's ``(c, s)`` stays on its circle: off it, the instances with the
        actuators on it, the request's included, are special and lose solutions to infinity)."""
        B = np.where(free, scale * crand(n, len(P0)), P0)
        B[:, :npar] = angle_form(sysm, np.array([_random_parameters(sysm, rng) for _ in range(n)]))
        return B

    known = x0[None]
    stale = loops = 0
    k = MONODROMY_PARALLEL
    capped_out = False
    steps = [0]  # tracker steps; the work: steps times unknowns
    per_path = 0.0  # the last round's steps per path: the next round's work is predicted from it
    while stale < MONODROMY_STALE_LOOPS and loops < MONODROMY_MAX_LOOPS:
        next_work = per_path * (3 * k * len(known) + k) * sysm.nx
        if capped and (len(known) > MONODROMY_MAX_SOLUTIONS or steps[0] * sysm.nx + next_work > MONODROMY_MAX_WORK):
            capped_out = True
            break
        loops += k  # k loops at once, each through its own two random parameter points
        B1 = np.repeat(waypoints(k), len(known), axis=0)
        B2 = np.repeat(waypoints(k), len(known), axis=0)
        X = np.tile(known, (k, 1))
        before, n_paths = steps[0], 3 * len(X) + k
        X = around_triangle(lambda Xs, a, b: _segment(sysm, Xs, a, b, steps), X, P0, B1, B2)
        xr, Pr = _start_pairs(sysm, rng, k)  # and fresh start pairs, moved to P0
        Xr, _, done = _segment(sysm, xr, Pr, P0, steps)
        per_path = (steps[0] - before) / n_paths
        X = np.vstack([X, Xr[done]])
        known, stale = add_new_points(known, X, stale, k)
    g = _GenericLoop(P0, known, loops, time.perf_counter() - t0, stale >= MONODROMY_STALE_LOOPS)
    if not capped_out:  # a capped run is redone in full when asked without the caps
        _CACHE[key] = g
    return g


_TRACES: dict[bytes, TraceResult] = {}


def _trace(sysm: LoopSystem, gen: _GenericLoop, seed: int, capped: bool) -> TraceResult:
    """The trace test of the generic solutions ``gen.X`` (:mod:`.trace_test`): the parameters
    move along the line from ``gen.P0`` through a fresh start pair's parameters; ``capped``: stop
    at :data:`TRACE_MAX_WORK`."""
    key = sysm.key() + bytes([seed % 256])
    if key in _TRACES:
        return _TRACES[key]
    rng = np.random.default_rng([seed, 7])
    p0 = gen.P0[: sysm.npar].copy()  # the line moves the offsets alone: the actuators as at P0
    for ic, js in _rotations(sysm):
        p0[ic], p0[js] = np.cos(gen.P0[ic]), np.sin(gen.P0[ic])
    x1, P1 = _start_pairs(sysm, rng, 1, p_fixed=p0)
    V = P1[0] - gen.P0
    nx = sysm.nx

    def curve(Y):
        P = gen.P0[None] + Y[:, nx : nx + 1] * V[None]
        return line_eval(sysm, Y[:, :nx], P, np.broadcast_to(V, P.shape))

    tr = trace_test(curve, gen.X, np.concatenate([x1[0], [1.0]]), rng, max_work=TRACE_MAX_WORK if capped else TRACE_MAX_WORK_FULL)
    if tr.verdict != "capped":
        _TRACES[key] = tr
    return tr


def clear_cache() -> None:
    """Forget the cached generic solves and trace tests (benchmarks time the first solve)."""
    _CACHE.clear()
    _TRACES.clear()


@dataclass(frozen=True, eq=False)
class GeneralSolution:
    """One end point at the request: ``status`` real / complex / singular / at_infinity, the
    variables ``x`` and, for a real one, the joint variables ``q``, platform ``D`` and internal
    bodies ``B``."""

    status: EndPointStatus
    x: np.ndarray
    rcond: float
    imag_ratio: float
    residual: float
    q: np.ndarray | None = None
    D: np.ndarray | None = None
    B: np.ndarray | None = None  # the internal bodies' displacements (k, 4, 4)

    def to_dict(self) -> dict:
        fin = bool(np.all(np.isfinite(self.x)))  # a path that diverged: no numbers to give
        return {"status": self.status, "variables_real": [float(v) for v in self.x.real] if fin else [],
                "variables_imag": [float(v) for v in self.x.imag] if fin else [],
                "inverse_condition": _finite(self.rcond), "imaginary_ratio": _finite(self.imag_ratio),
                "residual": _finite(self.residual)}


def _finite(v: float) -> float:
    """``v``, or the largest float for a quantity that overflowed on a diverged path (JSON has no
    infinity)."""
    return float(v) if np.isfinite(v) else float(np.finfo(float).max)


@dataclass(frozen=True, eq=False)
class GeneralResult:
    solutions: tuple[GeneralSolution, ...]
    saturated: bool  # the monodromy stopped because loops found nothing new (not at a cap)
    complete: bool
    completeness: str
    n_generic: int
    n_spurious: int
    loops: int
    seconds_generic: float
    seconds: float
    cached: bool
    trace: TraceResult | None = None  # the trace test of the generic solutions (None: not run)

    def count(self, status: EndPointStatus | str) -> int:
        return sum(s.status == status for s in self.solutions)


def general_forward(mech: Mechanism, targets: dict[int, float], *, seed: int = 0, capped: bool = False) -> GeneralResult:
    """Every solution found of the forward position of ``mech`` with the actuators at
    ``targets`` (joint variables by freedom index, as ``forward.actuator_q`` gives them);
    ``capped``: the monodromy gives up early on large systems (``saturated`` false)."""
    t0 = time.perf_counter()
    sysm = loop_system(mech)
    if set(targets) != {fi for fi, _, _ in sysm.params}:
        raise InputError(f"actuators: expected values for {list(mech.actuators)}")
    cached = sysm.key() + bytes([seed % 256]) in _CACHE
    gen = _monodromy(sysm, seed, capped)
    tr = _trace(sysm, gen, seed, capped) if gen.saturated else None
    p1 = sysm.parameters(targets).astype(complex)
    P1 = angle_form(sysm, np.concatenate([p1, sysm.identity_offsets()[0], np.zeros(sysm.nx)]))
    X, _, done = _segment(sysm, gen.X, gen.P0, P1)
    Z = np.concatenate([X, np.broadcast_to(p1, (len(X), sysm.npar))], axis=1)
    Z = _refine(sysm, Z)
    # singular end points and paths stopped short (not diverging): the Cauchy end game
    cand = _endgame_candidates(sysm, Z, done)
    winding: list[int] = []
    if len(cand):
        eg = cauchy_endgame(lambda PA, PB, c, Xs: _segment(sysm, Xs, PA, PB), gen.P0, P1, np.zeros(0), gen.X[cand])
        Z[cand[eg.converged], : sysm.nx] = eg.X[eg.converged]
        done = done.copy()
        done[cand[eg.converged]] = True
        winding = sorted(set(eg.winding[eg.converged].tolist()))
        Z[cand] = _refine(sysm, Z[cand])
    res = sysm.residual(Z)
    sols: list[GeneralSolution] = []
    spurious = lost = 0
    kept = np.zeros((0, sysm.nx), complex)
    for n in range(len(Z)):
        z = Z[n]
        x = z[: sysm.nx]
        big = not np.all(np.isfinite(x)) or np.linalg.norm(x) > 1.0 / HOMOTOPY_INFINITY
        for h in sysm.studies:
            e = x[h.study : h.study + 4]
            big = big or abs(e @ e) / max(np.linalg.norm(x[h.study : h.study + 8]) ** 2, 1e-300) < HOMOTOPY_INFINITY
        if big or (not done[n] and np.linalg.norm(x) > MONODROMY_DIVERGED):
            sols.append(GeneralSolution(EndPointStatus.AT_INFINITY, x, 0.0, 0.0, float(res[n])))
            continue
        if not res[n] < MONODROMY_RESIDUAL:
            if done[n]:
                spurious += 1
            else:
                lost += 1
            continue
        if len(kept) and np.min(np.linalg.norm(kept - x, axis=1) / (1 + np.linalg.norm(x))) < 1e-6:
            continue  # two paths to one (singular) end point
        kept = np.vstack([kept, x[None]])
        _, J = sysm.square(z[None])
        Jx = J[0, :, : sysm.nx]
        rows = Jx / np.maximum(np.linalg.norm(Jx, axis=1, keepdims=True), 1e-300)
        sv = np.linalg.svd(rows, compute_uv=False)
        rcond = float(sv[-1] / sv[0]) if sv[0] > 0 else 0.0
        y = x.copy()
        for h in sysm.studies:
            s = slice(h.study, h.study + 8)
            k = int(np.argmax(np.abs(y[s])))
            y[s] = y[s] * (abs(y[s][k]) / y[s][k])
        imag = float(np.max(np.abs(y.imag)) / (1 + np.max(np.abs(y.real))))
        st = (EndPointStatus.SINGULAR if rcond < HOMOTOPY_SINGULAR or multiple_root_end(imag, rcond)
              else EndPointStatus.REAL if imag < HOMOTOPY_REAL else EndPointStatus.COMPLEX)
        q = D = B = None
        if st == EndPointStatus.REAL:
            c = rebuild_configuration(sysm, y.real, targets)
            q, D, B = c.q, c.D, c.B
        sols.append(GeneralSolution(st, y, rcond, imag, float(res[n]), q, D, B))
    n_sing = sum(s.status == EndPointStatus.SINGULAR for s in sols)
    fam = ("the limbs offset by generic complex rigid motions" if sysm.rigid_family
           else "the square system with a generic complex offset")
    head = (f"monodromy saturated after {gen.loops} loops ({MONODROMY_STALE_LOOPS} in a row without a new solution; "
            f"{len(gen.X)} solutions of a generic complex instance: {fam})")
    tail = (f"then a parameter homotopy to the requested actuator values; {spurious} end point(s) of the square "
            "system that do not satisfy the full closure discarded")
    how = head
    if tr is not None and tr.passed:
        lead = "complete (trace test)" if lost == 0 else "NOT proven at the request"
        how = (f"{lead}: {head}; trace test passed (the {len(gen.X)} solutions and {tr.n_witness} "
               f"witness points of the curve through a second generic instance, traces on a line to "
               f"{tr.deviation:.1e} <= {TRACE_TOL:g}); {tail}")
    elif tr is not None:
        why_not = {TraceVerdict.FAILED: f"trace test FAILED (deviation {tr.deviation:.1e} > {TRACE_TOL:g} with {tr.n_witness} "
                             "witness points that stopped growing): solutions of the generic instance are missing",
                   TraceVerdict.INCONCLUSIVE: "trace test inconclusive (a path of its homotopies failed)",
                   TraceVerdict.CAPPED: f"trace test stopped at its cap (a work of {tr.work} paths tracked times unknowns, "
                             f"{tr.loops} loops; {tr.n_witness} witness points so far): not proven"
                             + ("; method=\"homotopy\" runs it further" if capped else "")}
        how = f"{head}; {why_not[tr.verdict]}; {tail}: not a proof"
    if not gen.saturated:
        why = (f"more than {MONODROMY_MAX_SOLUTIONS} solutions of the square system" if len(gen.X) > MONODROMY_MAX_SOLUTIONS
               else f"{MONODROMY_MAX_LOOPS} loops" if gen.loops >= MONODROMY_MAX_LOOPS
               else f"a work of {MONODROMY_MAX_WORK} (tracker steps times unknowns)")
        how = (f"monodromy NOT saturated: stopped at {why} ({len(gen.X)} solutions of the generic instance so far, "
               f"{gen.loops} loops); {spurious} spurious end point(s) discarded: not a proof, solutions may be missing")
    if n_sing and winding:
        how += (f"; {n_sing} singular end point(s) (a continuum or a multiple root), located by a Cauchy end game "
                f"(winding numbers {winding})")
    elif n_sing:
        how += f"; {n_sing} singular end point(s) (a continuum or a multiple root), located to a few digits only"
    if lost:
        how += f"; {lost} path(s) stopped short of the request away from any solution (lost)"
    complete = bool(tr is not None and tr.passed and lost == 0)
    return GeneralResult(tuple(sols), gen.saturated, complete, how, len(gen.X), spurious, gen.loops, gen.seconds,
                         time.perf_counter() - t0, cached, tr)


def _refine(sysm: LoopSystem, Z, iters: int = 3):
    """Newton on the square system; a step is kept only when it lowers the residual (at a
    singular root, located by the end game, a Newton step would throw the point elsewhere)."""
    Z = Z.copy()
    nx = sysm.nx
    with np.errstate(all="ignore"):
        for _ in range(iters):
            F, J = sysm.square(Z)
            trial = Z.copy()
            for n in range(len(Z)):
                if not (np.all(np.isfinite(F[n])) and np.all(np.isfinite(J[n]))):
                    continue
                try:
                    dx = np.linalg.solve(J[n, :, :nx], F[n])
                except np.linalg.LinAlgError:
                    continue
                if np.all(np.isfinite(dx)):
                    trial[n, :nx] -= dx
            Ft, _ = sysm.square(trial, want_J=False) if len(Z) else (F, J)
            better = np.linalg.norm(Ft, axis=1) < np.linalg.norm(F, axis=1)
            Z[better] = trial[better]
    return Z


def _endgame_candidates(sysm: LoopSystem, Z, done) -> np.ndarray:
    """End points for the end game: finite, not escaping, and singular or stopped short."""
    if not len(Z):
        return np.zeros(0, dtype=np.int64)
    with np.errstate(all="ignore"):
        _, J = sysm.square(Z)
        out = []
        for n in range(len(Z)):
            x = Z[n, : sysm.nx]
            if not (np.all(np.isfinite(x)) and np.all(np.isfinite(J[n]))) or np.linalg.norm(x) > MONODROMY_DIVERGED:
                continue
            Jx = J[n, :, : sysm.nx]
            sv = np.linalg.svd(Jx / np.maximum(np.linalg.norm(Jx, axis=1, keepdims=True), 1e-300), compute_uv=False)
            if not done[n] or not sv[-1] >= HOMOTOPY_SINGULAR * sv[0]:
                out.append(n)
    return np.array(out, dtype=np.int64)


def rebuild(sysm: LoopSystem, x: np.ndarray, targets: dict[int, float]) -> tuple[np.ndarray, np.ndarray]:
    """Joint variables ``q`` (every freedom) and platform displacement ``D`` (model units) of a
    real solution ``x`` (:func:`rebuild_configuration`, which also gives the internal bodies)."""
    c = rebuild_configuration(sysm, x, targets)
    return c.q, c.D


def rebuild_configuration(sysm: LoopSystem, x: np.ndarray, targets: dict[int, float]) -> Configuration:
    """The configuration (joint variables ``q``, platform ``D``, internal bodies ``B``; model
    units) of a real solution ``x``; the S joints' rotation vectors are those that close their
    limbs (a rod takes the smallest rotation at its first S joint)."""
    mech, L = sysm.mech, sysm.L
    refs = mech.freedom_refs
    p = sysm.parameters(targets)
    z = np.concatenate([x, p])[None].astype(complex)
    q = np.zeros(len(refs))
    for i, v in sysm.var_of.items():
        if v[0] == "A":
            q[i] = targets[i]
        elif v[0] == "R":
            q[i] = np.arctan2(x[v[2]], x[v[1]])
        elif v[0] == "P":
            q[i] = x[v[1]] * L
    Hv = sysm.hub_values(z)
    hub: dict = {None: np.eye(4)}  # every hub's displacement, translations over L
    for h in sysm.hubs:
        if h.study >= 0:
            M = np.eye(4)
            M[:3, :3], M[:3, 3] = study_to_pose(x[h.study : h.study + 8], 1.0)
        else:
            M = (Hv[h.hub][0][0] / Hv[h.hub][2][0]).real
            M[3] = [0, 0, 0, 1]
        hub[h.hub] = M
    slices = limb_slices(mech)
    chains = {}
    from ..closure import limb_chains

    for ch, sl in zip(limb_chains(mech), slices, strict=True):
        for first, _, axes in ch.balls:
            chains[sl.start + first] = axes
    for le in sysm.limbs:
        if le.kind == "full":
            continue
        Tb = hub[le.a] @ sysm._chain(le.before, z)[0][0].real
        Ta = sysm._chain(le.after_inv, z)[0][0].real
        D = hub[le.b]
        start = slices[le.limb].start + le.s_first
        if le.kind == "point":
            Rs = Tb[:3, :3].T @ D[:3, :3] @ Ta[:3, :3]
            q[start : start + 3] = np.linalg.solve(chains[start], matrix_rotvec(Rs))
            continue
        a = le.c2[:3] - le.c1[:3]
        bvec = Tb[:3, :3].T @ ((D @ Ta @ le.c2)[:3] - (Tb @ le.c1)[:3])
        R1 = _min_rotation(a, bvec)
        q[start : start + 3] = np.linalg.solve(chains[start], matrix_rotvec(R1))
        Rs2 = R1.T @ Tb[:3, :3].T @ D[:3, :3] @ Ta[:3, :3]
        q[start + 3 : start + 6] = np.linalg.solve(chains[start + 3], matrix_rotvec(Rs2))
    out = {k: v.copy() for k, v in hub.items() if k is not None}
    for v in out.values():
        v[:3, 3] *= L
    nb = sysm.n_bodies
    B = np.array([out[1 + i] for i in range(nb)]).reshape(nb, 4, 4) if nb else Configuration.reference(mech).B
    return Configuration(q, out[0], B)


def _min_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation taking the direction of ``a`` to that of ``b``."""
    a = a / np.linalg.norm(a)
    b = b / np.linalg.norm(b)
    v = np.cross(a, b)
    c = float(a @ b)
    if c < -1 + 1e-12:
        w = np.cross(a, [1.0, 0, 0]) if abs(a[0]) < 0.9 else np.cross(a, [0, 1.0, 0])
        w /= np.linalg.norm(w)
        return 2 * np.outer(w, w) - np.eye(3)
    K = skew(v)
    return np.eye(3) + K + K @ K / (1 + c)


def configuration(sol: GeneralSolution) -> Configuration:
    """The :class:`Configuration` of a real solution (joint variables, platform, internal bodies)."""
    assert sol.q is not None and sol.D is not None
    if sol.B is None:
        return Configuration(sol.q, sol.D)
    return Configuration(sol.q, sol.D, sol.B)
