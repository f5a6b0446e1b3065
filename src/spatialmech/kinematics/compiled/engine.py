"""The general closure engine compiled (numba): the same computations as :mod:`..closure`,
:func:`..jacobian.driver_determinants` and the per-limb inverse position, on plain arrays.

The kernels themselves are plain-array numba functions in :mod:`.kernels_se3` (small linear
algebra, SE(3)), :mod:`.kernels_closure` (chains, closure system, Newton, limb Gauss-Newton) and
:mod:`.kernels_drivers` (driver determinants, configuration difference, S-P-S legs); this module
holds the compiled model and the Python entry points.

A mechanism is compiled once into arrays (:class:`CompiledMechanism`, cached per mechanism):
the reference screws of its freedoms, its ball (S) joints (first freedom, axes, centre), the
first freedom of each limb, the hub indices of each limb's ends (-1 = the ground, 0 = the output
link, 1 + i = internal body i) and the prismatic mask.  The kernels are ``@njit(cache=True)``
functions of those arrays: compiled on first use and cached on disk next to this file (or in
numba's user-wide cache when this directory is not writable), so later processes only load
them.

The Python path stays the reference: :func:`..closure.correct`, :func:`..closure.closure_jacobian`,
:func:`..closure.closure_residual`, :func:`..jacobian.driver_determinants` and the per-limb
Gauss-Newton of :mod:`..position`.  :mod:`..backend` picks this engine or the reference
(:func:`..backend.enabled`: numba importable, ``SPATIALMECH_PURE`` unset or ``0`` at import, no
``python_reference()`` block open).  Same steps, tolerances and statuses; the results agree to
rounding (the test suite compares both paths on every ready-made model).

Batched entry points for many configurations, seeds or poses: :func:`closure_residuals`,
:func:`closure_jacobians`, :func:`correct_many`, :func:`limb_inverse_many`,
:func:`driver_determinants_many`, :func:`sps_leg_lengths`.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...geometry.tolerances import current as current_tolerances
from ...model.mechanism import Mechanism
from ..closure import (
    Chain,
    Configuration,
    CorrectionResult,
    active_mask,
    check_configuration,
    limb_chains,
    limb_slices,
    reference_screws,
)

from .kernels_blocks import nb_blocks_workspace, nb_minnorm_blocks
from .kernels_closure import RETRACT_WS, nb_correct, nb_correct_hyperplane, nb_limb_gn, nb_retract, nb_systems
from .kernels_drivers import nb_dets_many, nb_difference, nb_differences, nb_sigmas_many, nb_sps_legs
from .kernels_se3 import nb_lstsq



__all__ = [
    "CompiledMechanism",
    "closure_jacobian",
    "closure_jacobians",
    "closure_residual",
    "closure_residuals",
    "compile_mechanism",
    "config_difference",
    "config_differences",
    "correct",
    "correct_many",
    "correct_on_hyperplane",
    "driver_columns",
    "driver_determinants",
    "driver_determinants_many",
    "driver_sigmas_many",
    "limb_gn",
    "limb_inverse_many",
    "lstsq",
    "minnorm_blocks",
    "nearest_point",
    "retract",
    "sps_leg_lengths",
    "warm_up",
]

# ---------------------------------------------------------------------------- compiled model
@dataclass(frozen=True, eq=False)
class CompiledMechanism:
    """A mechanism as plain arrays (see the module docstring)."""

    n: int  # joint variables
    n_limbs: int
    n_bodies: int
    length: float  # characteristic length L
    screws: np.ndarray  # (n, 6) reference screws
    ball_of: np.ndarray  # (n,) int64: ball index at the first freedom of an S joint, else -1
    ball_first: np.ndarray  # (nb,) int64: global index of each ball's first freedom
    ball_axes: np.ndarray  # (nb, 3, 3): axes as columns
    ball_centre: np.ndarray  # (nb, 3)
    limb_start: np.ndarray  # (K + 1,) int64
    ends: np.ndarray  # (K, 2) int64: base and tip hub (-1 = ground)
    linear: np.ndarray  # (n,) bool: prismatic freedoms
    active: np.ndarray  # (n,) bool: the unlocked freedoms (default active mask)

    @property
    def chain_arrays(self) -> tuple:
        return self.screws, self.ball_of, self.ball_axes, self.ball_centre


_COMPILED: weakref.WeakKeyDictionary[Mechanism, CompiledMechanism] = weakref.WeakKeyDictionary()


def compile_mechanism(mech: Mechanism) -> CompiledMechanism:
    """The arrays of ``mech`` (cached per mechanism, like :func:`.closure.limb_chains`)."""
    try:
        return _COMPILED[mech]
    except KeyError:
        pass
    n = len(mech.freedom_refs)
    ball_of = np.full(n, -1, dtype=np.int64)
    first: list[int] = []
    axes: list[np.ndarray] = []
    centres: list[np.ndarray] = []
    start = 0
    for ch in limb_chains(mech):
        for k, c, A in ch.balls:
            ball_of[start + k] = len(first)
            first.append(start + k)
            axes.append(A)
            centres.append(c)
        start += len(ch.screws)
    sls = limb_slices(mech)
    limb_start = np.array([s.start for s in sls] + [n], dtype=np.int64)
    ends = np.array([[-1 if a is None else a, -1 if b is None else b] for a, b in mech.limb_ends],
                    dtype=np.int64).reshape(-1, 2)
    cm = CompiledMechanism(
        n, len(mech.limbs), len(mech.bodies), float(mech.characteristic_length),
        np.ascontiguousarray(reference_screws(mech), dtype=float).reshape(n, 6), ball_of,
        np.array(first, dtype=np.int64), np.ascontiguousarray(np.array(axes, dtype=float).reshape(-1, 3, 3)),
        np.ascontiguousarray(np.array(centres, dtype=float).reshape(-1, 3)), limb_start, ends,
        np.array([r.freedom.is_linear for r in mech.freedom_refs], dtype=np.bool_),
        np.ascontiguousarray(active_mask(mech), dtype=np.bool_).reshape(n))
    _COMPILED[mech] = cm
    return cm


@dataclass(frozen=True, eq=False)
class _ChainArrays:
    screws: np.ndarray
    ball_of: np.ndarray
    ball_first: np.ndarray
    ball_axes: np.ndarray
    ball_centre: np.ndarray


_CHAIN_ARRAYS: weakref.WeakKeyDictionary[Chain, _ChainArrays] = weakref.WeakKeyDictionary()


def _chain_arrays(chain: Chain) -> _ChainArrays:
    try:
        return _CHAIN_ARRAYS[chain]
    except KeyError:
        pass
    m = len(chain.screws)
    ball_of = np.full(m, -1, dtype=np.int64)
    for g, (k, _, _) in enumerate(chain.balls):
        ball_of[k] = g
    out = _ChainArrays(np.ascontiguousarray(chain.screws, dtype=float).reshape(m, 6), ball_of,
                       np.array([b[0] for b in chain.balls], dtype=np.int64),
                       np.ascontiguousarray(np.array([b[2] for b in chain.balls], dtype=float).reshape(-1, 3, 3)),
                       np.ascontiguousarray(np.array([b[1] for b in chain.balls], dtype=float).reshape(-1, 3)))
    _CHAIN_ARRAYS[chain] = out
    return out


# ---------------------------------------------------------------------------- Python entry points
_NO_BODIES_W = np.empty((0, 4, 4))  # never written: it has no entries


def _f64(x, shape=None) -> np.ndarray:
    """A C-contiguous, writable float64 array: one numba type per kernel argument (a read-only
    view, e.g. from ``np.broadcast_to``, would be a different type and compile again)."""
    if not (type(x) is np.ndarray and x.dtype == np.float64 and x.flags.c_contiguous and x.flags.writeable):
        x = np.require(x, np.float64, ["C", "W"])
    return x if shape is None else x.reshape(shape)


def _bools(x, shape) -> np.ndarray:
    return np.require(x, np.bool_, ["C", "W"]).reshape(shape)


def _mask(mech: Mechanism, cm: CompiledMechanism, active) -> np.ndarray:
    if active is None:
        return cm.active
    if type(active) is np.ndarray and active.dtype == np.bool_ and active.shape == (cm.n,) and active.flags.c_contiguous:
        return active
    a = np.require(active, np.bool_, ["C", "W"])
    if a.shape != (cm.n,):
        raise InputError(f"active: {mech.name} has {cm.n} joint variables, got a mask of shape {a.shape}")
    return a


def _config_arrays(cm: CompiledMechanism, config: Configuration) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return (_f64(config.q, (cm.n,)), _f64(config.D, (4, 4)), _f64(config.B, (cm.n_bodies, 4, 4)))


def _check(mech: Mechanism, cm: CompiledMechanism, config: Configuration) -> None:
    """:func:`.closure.check_configuration`, with a quick path for the usual valid configuration
    (NaN and infinity propagate into the sums; anything unusual gets the full check and its
    message)."""
    q, D, B = config.q, config.D, config.B
    if (type(q) is np.ndarray and type(D) is np.ndarray and type(B) is np.ndarray and q.shape == (cm.n,)
            and D.shape == (4, 4) and B.shape == (cm.n_bodies, 4, 4) and np.isfinite(q.sum() + D.sum() + B.sum())):
        return
    check_configuration(mech, config)


def _system_args(cm: CompiledMechanism) -> tuple:
    return (cm.screws, cm.ball_of, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends)


def _batch(mech: Mechanism, cm: CompiledMechanism, q, D, B):
    qs = _f64(q)
    if qs.ndim != 2 or qs.shape[1] != cm.n:
        raise InputError(f"q: expected shape (N, {cm.n}) for {mech.name}, got {qs.shape}")
    N = qs.shape[0]
    Ds = _f64(D)
    if Ds.shape == (4, 4):
        Ds = _f64(np.broadcast_to(Ds, (N, 4, 4)))
    if Ds.shape != (N, 4, 4):
        raise InputError(f"D: expected shape (N, 4, 4) or (4, 4) with N = {N}, got {Ds.shape}")
    if B is None:
        Bs = _f64(np.broadcast_to(np.eye(4), (N, cm.n_bodies, 4, 4)))
    else:
        Bs = _f64(B)
        if Bs.shape == (cm.n_bodies, 4, 4):
            Bs = _f64(np.broadcast_to(Bs, (N, cm.n_bodies, 4, 4)))
        if Bs.shape != (N, cm.n_bodies, 4, 4):
            raise InputError(f"B: expected shape (N, {cm.n_bodies}, 4, 4), got {Bs.shape}")
    if not (np.all(np.isfinite(qs)) and np.all(np.isfinite(Ds)) and np.all(np.isfinite(Bs))):
        raise InputError("q, D, B: contain NaN or infinity")
    return qs, Ds, Bs


def _run_systems(cm: CompiledMechanism, qs, Ds, Bs, act, want_A: bool):
    N = qs.shape[0]
    na = int(act.sum())
    A = np.empty((N, 6 * cm.n_limbs, na + 6 * (1 + cm.n_bodies)) if want_A else (1, 0, 0))
    r = np.empty((N, 6 * cm.n_limbs))
    if N:
        nb_systems(cm.screws, cm.ball_of, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends, qs, Ds, Bs, act, want_A, A,
                 r)
    return A, r


def closure_residual(mech: Mechanism, config: Configuration) -> np.ndarray:
    """:func:`.closure.closure_residual`, compiled."""
    cm = compile_mechanism(mech)
    _check(mech, cm, config)
    q, D, B = _config_arrays(cm, config)
    return _run_systems(cm, q[None], D[None], B[None], cm.active, False)[1][0]


def closure_jacobian(mech: Mechanism, config: Configuration, *, active: np.ndarray | None = None):
    """:func:`.closure.closure_jacobian`, compiled: ``(A, r)``."""
    cm = compile_mechanism(mech)
    _check(mech, cm, config)
    q, D, B = _config_arrays(cm, config)
    A, r = _run_systems(cm, q[None], D[None], B[None], _mask(mech, cm, active), True)
    return A[0], r[0]


def closure_residuals(mech: Mechanism, q, D, B=None) -> np.ndarray:
    """Residuals (N, 6K) of N configurations: joint variables ``q`` (N, n), output displacements
    ``D`` (N, 4, 4) or one (4, 4), body displacements ``B`` (N, k, 4, 4) (default: identities)."""
    cm = compile_mechanism(mech)
    qs, Ds, Bs = _batch(mech, cm, q, D, B)
    return _run_systems(cm, qs, Ds, Bs, cm.active, False)[1]


def closure_jacobians(mech: Mechanism, q, D, B=None, *, active: np.ndarray | None = None):
    """Closure Jacobians (N, 6K, n_active + 6h) and residuals (N, 6K) of N configurations (see
    :func:`closure_residuals` for the arguments)."""
    cm = compile_mechanism(mech)
    qs, Ds, Bs = _batch(mech, cm, q, D, B)
    return _run_systems(cm, qs, Ds, Bs, _mask(mech, cm, active), True)


def _correct_args(cm: CompiledMechanism) -> tuple:
    return (cm.screws, cm.ball_of, cm.ball_first, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends, cm.linear,
            cm.length)


def _result(config: Configuration | None, q, D, B, status: int, it: int, rn: float) -> CorrectionResult:
    # nothing moved: the caller's own configuration, as the Python path returns it
    c = config if config is not None and it == 0 else Configuration(q, D, B)
    return CorrectionResult(c, status == 1, int(it), float(rn), stationary=status == 2)


def _run_correct(mech: Mechanism, cm: CompiledMechanism, seeds: Sequence[Configuration], active, fix_platform: bool,
                 tol: float | None, max_iter: int) -> list[CorrectionResult]:
    act = _mask(mech, cm, active)
    if tol is None:  # the newton tolerance in force (geometry/tolerances.py)
        tol = current_tolerances().newton
    N = len(seeds)
    qs = _f64([c.q for c in seeds], (N, cm.n))
    Ds = _f64([c.D for c in seeds], (N, 4, 4))
    Bs = _f64([c.B for c in seeds], (N, cm.n_bodies, 4, 4))
    q_out, D_out, B_out = np.empty_like(qs), np.empty_like(Ds), np.empty_like(Bs)
    status = np.empty(N, dtype=np.int64)
    iters = np.empty(N, dtype=np.int64)
    resid = np.empty(N)
    if N:
        nb_correct(*_correct_args(cm), qs, Ds, Bs, act, bool(fix_platform), float(tol), int(max_iter), q_out, D_out,
                      B_out, status, iters, resid)
    for s, st in enumerate(status.tolist()):
        if st < 0:  # NaN or infinity in a seed: the full check names it
            check_configuration(mech, seeds[s])
    return [_result(seeds[s], q_out[s], D_out[s], B_out[s], int(status[s]), int(iters[s]), float(resid[s]))
            for s in range(N)]


def _shapes(mech: Mechanism, cm: CompiledMechanism, config: Configuration) -> None:
    """The shapes of ``config`` (finiteness is the kernel's check), else the full check's message."""
    q, D, B = config.q, config.D, config.B
    if not (type(q) is np.ndarray and type(D) is np.ndarray and type(B) is np.ndarray and q.shape == (cm.n,)
            and D.shape == (4, 4) and B.shape == (cm.n_bodies, 4, 4)):
        check_configuration(mech, config)


def correct(mech: Mechanism, config: Configuration, *, active: np.ndarray | None = None, fix_platform: bool = False,
            tol: float | None = None, max_iter: int = 50) -> CorrectionResult:
    """:func:`..closure.correct`, compiled (same steps, tolerances and statuses)."""
    cm = compile_mechanism(mech)
    _shapes(mech, cm, config)
    act = _mask(mech, cm, active)
    if tol is None:  # the newton tolerance in force (geometry/tolerances.py)
        tol = current_tolerances().newton
    # no bodies: a writable empty array, not a copy of the read-only shared one
    B0 = _f64(config.B) if cm.n_bodies else _NO_BODIES_W
    q0, D0 = _f64(config.q), _f64(config.D)
    nb = cm.n_bodies
    q, D, B = np.empty((1, cm.n)), np.empty((1, 4, 4)), np.empty((1, nb, 4, 4))
    info = np.empty(2, dtype=np.int64)  # status, iterations (the residual in its own array)
    rn = np.empty(1)
    # the batched kernel with a batch of one: a separate single-seed kernel would cost as much
    # compilation again (numba re-optimises a kernel's callees inside each caller) for ~1 us
    nb_correct(*_correct_args(cm), q0.reshape(1, cm.n), D0.reshape(1, 4, 4), B0.reshape(1, nb, 4, 4), act,
               bool(fix_platform), float(tol), int(max_iter), q, D, B, info[0:1], info[1:2], rn)
    status, it = info[0], info[1]
    if status < 0:  # NaN or infinity in the seed: the full check names it
        check_configuration(mech, config)
    return _result(config, q[0], D[0], B[0], int(status), int(it), float(rn[0]))


def correct_many(mech: Mechanism, seeds: Sequence[Configuration], *, active: np.ndarray | None = None,
                 fix_platform: bool = False, tol: float | None = None, max_iter: int = 50) -> list[CorrectionResult]:
    """:func:`correct` from many seeds in one compiled loop (multi-start forward position: pass
    ``active`` without the actuators, and seeds whose actuated variables hold the values)."""
    cm = compile_mechanism(mech)
    for c in seeds:
        _shapes(mech, cm, c)
    return _run_correct(mech, cm, seeds, active, fix_platform, tol, max_iter)


def retract(mech: Mechanism, config: Configuration, active, step, fix_platform: bool = False) -> Configuration:
    """:func:`.closure.retract`, compiled."""
    cm = compile_mechanism(mech)
    act = _mask(mech, cm, active)
    q, D, B = _config_arrays(cm, config)
    st = _f64(step).reshape(-1)
    na = int(act.sum())
    if len(st) < na:
        raise InputError(f"step: expected at least the {na} active joint steps, got {len(st)} values")
    q2, D2, B2 = np.empty_like(q), np.empty_like(D), np.empty_like(B)
    nb_retract(cm.ball_first, cm.ball_axes, q, D, B, act, st, na, bool(fix_platform), q2, D2, B2,
               np.empty(cm.n + RETRACT_WS))
    return Configuration(q2, D2, B2)


def config_difference(mech: Mechanism, a: Configuration, b: Configuration, active, wrap, col) -> np.ndarray:
    """The tracker's local coordinates of ``b`` relative to ``a`` (``_config_diff`` of
    :mod:`.tracking`): ``wrap`` (n_active,) marks the rotations whose difference is wrapped to
    [-pi, pi), ``col`` the column scales of :func:`.closure.closure_scales`."""
    cm = compile_mechanism(mech)
    act = _mask(mech, cm, active)
    qa, Da, Ba = _config_arrays(cm, a)
    qb, Db, Bb = _config_arrays(cm, b)
    c = _f64(col).reshape(-1)
    w = _bools(wrap, (int(act.sum()),))
    out = np.empty(len(c))
    nb_difference(cm.ball_first, cm.ball_axes, qa, Da, Ba, qb, Db, Bb, act, w, c, out)
    return out


def config_differences(mech: Mechanism, points: Sequence[Configuration], b: Configuration, active, wrap,
                       col, stacked: tuple | None = None) -> np.ndarray:
    """:func:`config_difference` of ``b`` relative to each of ``points``, in one compiled loop:
    ``(len(points), n_local)``.  ``stacked``: the points' ``q, D, B`` already stacked."""
    cm = compile_mechanism(mech)
    act = _mask(mech, cm, active)
    if stacked is None:
        stacked = (np.array([p.q for p in points], dtype=float), np.array([p.D for p in points], dtype=float),
                   np.array([p.B for p in points], dtype=float))
    Qa = _f64(stacked[0]).reshape(len(points), cm.n)
    DAs = _f64(stacked[1]).reshape(len(points), 4, 4)
    BAs = _f64(stacked[2]).reshape(len(points), cm.n_bodies, 4, 4)
    c = _f64(col).reshape(-1)
    return _differences(cm, (Qa, DAs, BAs), _config_arrays(cm, b), act, _bools(wrap, (int(act.sum()),)), c)


def _differences(cm: CompiledMechanism, points: tuple, b: tuple, act, w, c) -> np.ndarray:
    """The compiled loop of :func:`config_differences` on arrays already shaped: ``points`` and
    ``b`` their ``q, D, B`` (stacked for the points)."""
    if not np.isfinite(points[0].sum() + points[1].sum() + points[2].sum()):
        raise InputError("points: a configuration holds NaN or infinity")
    out = np.empty((len(points[0]), len(c)))
    nb_differences(cm.ball_first, cm.ball_axes, *points, *b, act, w, c, out)
    return out


_NEAREST: weakref.WeakKeyDictionary[Mechanism, dict] = weakref.WeakKeyDictionary()


def _nearest_arrays(mech: Mechanism, cm: CompiledMechanism, act: np.ndarray, wrap, col) -> tuple:
    """:func:`nearest_point`'s index arrays and scales for one motion (remembered per mechanism,
    active mask, wrapped coordinates and column scales): the plain (non-S) active freedoms, their
    column scales and wrap flags, then the wrap flags and column scales of the full difference."""
    c = _f64(col).reshape(-1)
    w = _bools(wrap, (int(act.sum()),))
    key = (act.tobytes(), w.tobytes(), c.tobytes())
    memo = _NEAREST.setdefault(mech, {})
    got = memo.get(key)
    if got is None:
        in_ball = np.zeros(cm.n, dtype=bool)
        for g in cm.ball_first:
            in_ball[g:g + 3] = True
        j_of = np.cumsum(act) - 1  # local column of each active freedom
        plain = np.flatnonzero(act & ~in_ball)
        got = memo[key] = (plain, w[j_of[plain]], c[j_of[plain]], w, c)
    return got


def nearest_point(mech: Mechanism, stacked: tuple, b: Configuration, active, wrap, col) -> int:
    """The index of the point (``stacked``: their ``q, D, B``) nearest ``b``:
    ``argmin(np.linalg.norm(config_differences(...), axis=1))``, the same index (the first one on
    ties), with the full difference evaluated only at the points that a lower bound does not rule
    out.  The bound is the norm of the differences of the active joints outside S joints (a part
    of the full difference's components): a point whose bound exceeds the full distance of the
    point with the smallest bound cannot be nearest."""
    cm = compile_mechanism(mech)
    act = _mask(mech, cm, active)
    plain, wr, cp, w, c = _nearest_arrays(mech, cm, act, wrap, col)
    Qa = _f64(stacked[0]).reshape(-1, cm.n)
    DAs = _f64(stacked[1]).reshape(len(Qa), 4, 4)
    BAs = _f64(stacked[2]).reshape(len(Qa), cm.n_bodies, 4, 4)
    _check(mech, cm, b)
    bq = _config_arrays(cm, b)
    V = bq[0][plain][None, :] - Qa[:, plain]
    V[:, wr] = (V[:, wr] + np.pi) % (2 * np.pi) - np.pi
    lb = np.linalg.norm(V / cp[None, :], axis=1)

    def full(idx: np.ndarray) -> np.ndarray:
        return np.linalg.norm(_differences(cm, (Qa[idx], DAs[idx], BAs[idx]), bq, act, w, c), axis=1)

    first = int(np.argmin(lb))
    f0 = float(full(np.array([first]))[0])
    cand = np.flatnonzero(lb <= f0 * (1.0 + 1e-9))  # rounding of the bound: a margin, never a miss
    if cand.size == 0:  # a distance that is not a number (NaN): no bound rules anything out
        cand = np.arange(len(Qa))
    return int(cand[int(np.argmin(full(cand)))])


def correct_on_hyperplane(mech: Mechanism, config: Configuration, active, row, col, t, tol: float, max_iter: int,
                          contraction: float, predictor=None) -> tuple[Configuration, bool, int, float]:
    """``tracking.correct_on_hyperplane`` of a ``MotionProblem`` (row and column scales ``row``,
    ``col`` of :func:`.closure.closure_scales`), the whole Newton loop compiled:
    ``(config, converged, iterations, total correction length)``.  With ``predictor`` (a step in
    the problem's local coordinates) the Newton loop starts from ``config`` moved by it (the
    problem's ``retract``), in the same call."""
    cm = compile_mechanism(mech)
    act = _mask(mech, cm, active)
    _check(mech, cm, config)
    q0, D0, B0 = _config_arrays(cm, config)
    q, D, B = np.empty_like(q0), np.empty_like(D0), np.empty_like(B0)
    info = np.zeros(3)
    tt = _f64(t)
    pred = tt if predictor is None else _f64(predictor)
    if pred.shape != tt.shape:
        raise InputError(f"predictor: expected {tt.shape[0]} local coordinates, got shape {pred.shape}")
    m = 6 * cm.n_limbs
    nb_correct_hyperplane(cm.screws, cm.ball_of, cm.ball_first, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends,
                          q0, D0, B0, act, _f64(row), _f64(col), tt, float(tol), int(max_iter), float(contraction), pred,
                          predictor is not None, q, D, B, info, np.zeros((m, len(tt))), np.empty(m))
    it = int(info[1])
    out = config if it == 0 and predictor is None else Configuration(q, D, B)
    return out, bool(info[0]), it, float(info[2])


def _run_limb_gn(chain: Chain, Ds, q0s, lin, L, tol, max_iter, hold):
    ca = _chain_arrays(chain)
    m = len(ca.screws)
    N = Ds.shape[0]
    h = np.zeros(m, dtype=np.bool_) if hold is None else _bools(hold, (m,))
    q_out = np.empty((N, m))
    res = np.empty(N)
    ok = np.empty(N, dtype=np.bool_)
    if N:
        nb_limb_gn(ca.screws, ca.ball_of, ca.ball_first, ca.ball_axes, ca.ball_centre, Ds, q0s, _bools(lin, (m,)),
                 float(L), float(tol), int(max_iter), h, hold is not None, q_out, res, ok)
    return q_out, res, ok


def lstsq(A, b) -> np.ndarray:
    """Minimum-norm least-squares solution of ``A x = b`` as ``np.linalg.lstsq(A, b,
    rcond=None)[0]`` (the solver inside every compiled Newton step: when the system is
    underdetermined, the normal equations with one refinement step if it is well conditioned
    (cond below about 1e4), else the QR; the SVD for everything else)."""
    A = _f64(A)
    b = _f64(b)
    if A.ndim != 2 or b.shape != (A.shape[0],):
        raise InputError(f"A, b: expected shapes (m, n) and (m,), got {A.shape} and {b.shape}")
    return nb_lstsq(A, b)


def minnorm_blocks(A, b, c_lo, c_hi, ns0: int, *, border: tuple | None = None) -> np.ndarray | None:
    """The minimum-norm least-squares solution of a closure-shaped ``A x = b`` by block
    elimination (:mod:`.kernels_blocks`): limb ``k``'s rows ``6k .. 6k+5`` and own columns
    ``c_lo[k] .. c_hi[k]-1``, shared columns from ``ns0``; ``None`` where it declines (the
    general solver, :func:`lstsq`, must decide).  ``border=(t, t_rhs)``: the solution of the
    square ``[A; t] x = [b; t_rhs]`` instead (``A`` with one column more than rows: the
    hyperplane corrector's step)."""
    A = _f64(A)
    b = _f64(b)
    lo = np.require(c_lo, np.int64, ["C"])
    hi = np.require(c_hi, np.int64, ["C"])
    if A.ndim != 2 or A.shape[0] % 6 or A.shape[0] != 6 * len(lo) or b.shape != (A.shape[0],) or lo.shape != hi.shape:
        raise InputError(f"A, b, c_lo, c_hi: expected (6K, n), (6K,), (K,), (K,); got {A.shape}, {b.shape}, "
                         f"{lo.shape}, {hi.shape}")
    t, t_rhs = (np.empty(0), 0.0) if border is None else (_f64(border[0]), float(border[1]))
    if border is not None and t.shape != (A.shape[1],):
        raise InputError(f"border: expected a row of {A.shape[1]} entries, got shape {t.shape}")
    x = np.empty(A.shape[1])
    fbuf, ibuf = nb_blocks_workspace(lo, hi, int(ns0), A.shape[1])
    return x if nb_minnorm_blocks(A, b, t, t_rhs, lo, hi, int(ns0), x, fbuf, ibuf) else None


def limb_gn(chain: Chain, D, q, lin, L, tol=1e-12, max_iter=60, hold=None):
    """``position._limb_gn`` (one limb, tip held at ``D``), compiled: ``(q, residual, converged)``."""
    m = len(chain.screws)
    q_out, res, ok = _run_limb_gn(chain, _f64(D, (1, 4, 4)), _f64(q, (1, m)), lin, L, tol, max_iter, hold)
    return q_out[0], float(res[0]), bool(ok[0])


def limb_inverse_many(mech: Mechanism, D, *, q0=None, tol: float | None = None, max_iter: int = 60):
    """Inverse position of every limb from the ground to the output link at many output
    displacements ``D`` (N, 4, 4), each limb by Gauss-Newton from ``q0`` (default: the reference).

    Returns ``q`` (N, n), the nondimensional residual (N, K) and ``converged`` (N, K); limbs that
    do not run from the ground to the output link are not solved (NaN, False).  One start per
    pose and limb: the solution nearest ``q0``, as :func:`..position.inverse_position` without
    ``all_solutions`` (without its retries when that solution violates a limit)."""
    cm = compile_mechanism(mech)
    Ds = _f64(D)
    if Ds.shape == (4, 4):
        Ds = Ds[None]
    if Ds.ndim != 3 or Ds.shape[1:] != (4, 4):
        raise InputError(f"D: expected shape (N, 4, 4), got {Ds.shape}")
    if not np.all(np.isfinite(Ds)):
        raise InputError("D: contains NaN or infinity")
    q_start = np.zeros(cm.n) if q0 is None else _f64(q0, (cm.n,))
    if tol is None:
        tol = current_tolerances().closure
    N = Ds.shape[0]
    q_out = np.full((N, cm.n), np.nan)
    res = np.full((N, cm.n_limbs), np.nan)
    ok = np.zeros((N, cm.n_limbs), dtype=np.bool_)
    for k, (ch, sl) in enumerate(zip(limb_chains(mech), limb_slices(mech), strict=True)):
        if mech.limb_ends[k] != (None, 0):
            continue
        q0s = _f64(np.broadcast_to(q_start[sl], (N, sl.stop - sl.start)))
        q_out[:, sl], res[:, k], ok[:, k] = _run_limb_gn(ch, Ds, q0s, cm.linear[sl], cm.length, tol, max_iter, None)
    return q_out, res, ok


_DRIVERS: weakref.WeakKeyDictionary[Mechanism, dict] = weakref.WeakKeyDictionary()


def _driver_indices(mech: Mechanism, drivers) -> np.ndarray:
    key = tuple(drivers)
    known = _DRIVERS.setdefault(mech, {})
    if key not in known:
        known[key] = _find_drivers(mech, key)
    return known[key]


def driver_columns(mech: Mechanism, cm: CompiledMechanism, drivers) -> tuple[np.ndarray, np.ndarray]:
    """The drivers' joint indices and their places among the active joints (remembered)."""
    key = ("columns", tuple(drivers))
    known = _DRIVERS.setdefault(mech, {})
    if key not in known:
        idx = _driver_indices(mech, drivers)
        known[key] = (idx, (np.cumsum(cm.active) - 1)[idx])
    return known[key]


def _find_drivers(mech: Mechanism, drivers) -> np.ndarray:
    refs = mech.freedom_refs
    idx = []
    for d in drivers:
        r = mech.freedom(d)
        if r.freedom.locked:
            raise InputError(f"drivers: {d} is locked")
        idx.append(refs.index(r))
    return np.array(idx, dtype=np.int64)


def driver_determinants(mech: Mechanism, config: Configuration, drivers) -> np.ndarray | None:
    """:func:`.jacobian.driver_determinants`, compiled, or ``None`` for a mechanism this kernel
    does not handle (a limb with fewer than five active twists, or five dependent ones): the
    caller then runs the Python path."""
    cm = compile_mechanism(mech)
    _check(mech, cm, config)
    q, D, B = _config_arrays(cm, config)  # checked: the batch of one goes straight to the kernel
    idx, pos = driver_columns(mech, cm, drivers)
    out = np.empty((1, len(idx)))
    flag = nb_dets_many(*_system_args(cm), cm.linear, cm.active, cm.length, current_tolerances().rank, q[None], D[None],
                        B[None], idx, pos, cm.n_bodies > 0, out)
    return None if flag == 2 else out[0]


def driver_determinants_many(mech: Mechanism, q, D, B, drivers) -> np.ndarray | None:
    """``det J`` of each driver at N configurations (N, len(drivers)); ``None`` when the kernel
    does not handle the mechanism (see :func:`driver_determinants`)."""
    cm = compile_mechanism(mech)
    qs, Ds, Bs = _batch(mech, cm, q, D, B)
    idx = _driver_indices(mech, drivers)
    out = np.empty((qs.shape[0], len(idx)))
    pos = (np.cumsum(cm.active) - 1)[idx]
    flag = nb_dets_many(*_system_args(cm), cm.linear, cm.active, cm.length, current_tolerances().rank, qs, Ds, Bs, idx,
                      pos, cm.n_bodies > 0, out) if qs.shape[0] else 0
    return None if flag == 2 else out


def driver_sigmas_many(mech: Mechanism, q, D, B, drivers) -> np.ndarray | None:
    """``CompleteJacobian.sigma_min`` of each driver at N configurations (N, len(drivers)): the
    scale-free smallest singular value of the complete Jacobian with that driver alone, from the
    matrix :func:`driver_determinants_many` takes the determinant of.  ``None`` where the kernel
    does not decide (internal bodies, a limb it does not handle, constraint rows other than 5):
    the Python path (``complete_jacobians``) must."""
    cm = compile_mechanism(mech)
    if cm.n_bodies:
        return None
    qs, Ds, Bs = _batch(mech, cm, q, D, B)
    idx = _driver_indices(mech, drivers)
    dets = np.empty((qs.shape[0], len(idx)))
    sig = np.empty((qs.shape[0], len(idx)))
    if len(idx) == 0:
        return sig
    flag = nb_sigmas_many(*_system_args(cm), cm.active, cm.length, current_tolerances().rank, qs, Ds, Bs, idx, dets,
                          sig) if qs.shape[0] else 0
    return None if flag != 0 else sig


def sps_leg_lengths(poses, base, platform) -> np.ndarray:
    """Inverse position of SPS (or UPS) legs for many poses: ``|R b_i + p - a_i|`` (N, m).

    ``poses`` (N, 6): ``x, y, z`` of the platform frame's origin and the ``"ZYX"`` (intrinsic)
    angles ``(a1, a2, a3)``, ``R = Rz(a1) Ry(a2) Rx(a3)``, rad; ``base`` (m, 3): the legs' base
    centres ``a_i``; ``platform`` (m, 3): their platform centres ``b_i`` in the platform frame."""
    P = _f64(poses)
    A = _f64(base)
    Bp = _f64(platform)
    if P.ndim != 2 or P.shape[1] != 6:
        raise InputError(f"poses: expected shape (N, 6), got {P.shape}")
    if A.ndim != 2 or A.shape[1] != 3 or Bp.shape != A.shape:
        raise InputError(f"base, platform: expected two (m, 3) arrays, got {A.shape} and {Bp.shape}")
    out = np.empty((P.shape[0], A.shape[0]))
    nb_sps_legs(P, A, Bp, out)
    return out


def warm_up() -> float:
    """Compile (or load from the on-disk cache) every kernel on a tiny mechanism; returns the
    seconds it took (the first-call cost a user pays once per process)."""
    import time

    from ...model.joints import P, R, S
    from ...model.mechanism import Limb  # here, not at the top: only the warm-up builds a model
    from ..leg_platform import leg_platform
    from .legs import correct_legs, inverse_legs_many  # here, not at the top: legs.py builds on this module

    t0 = time.perf_counter()
    z = [0.0, 0.0, 1.0]
    mech = Mechanism("warm-up", limbs=(Limb("a", (R("A0", [0, 0, 0], z, actuated=True), S("A1", [0.3, 0, 0]),
                                                    S("B1", [0, 1, -0.1]))),
                                       Limb("b", (R("B0", [0, 1, 0.5], [1.0, 0, 0]),))),
                     platform_point=np.array([0, 1, -0.1]))
    c = Configuration.reference(mech)
    closure_residual(mech, c)
    closure_jacobian(mech, c)
    correct(mech, c)
    correct_many(mech, [c, c])
    minnorm_blocks(np.eye(6), np.ones(6), [0], [6], 6)
    driver_determinants(mech, c, ["A0.rot"])
    limb_gn(limb_chains(mech)[0], np.eye(4), np.zeros(7), np.zeros(7, bool), 1.0)
    limb_inverse_many(mech, np.eye(4)[None])
    sps_leg_lengths(np.zeros((1, 6)), np.zeros((1, 3)), np.ones((1, 3)))
    # six S-P-S legs: the pose-coordinate forward solve (leg_platform.py)
    ang = np.arange(6) * np.pi / 3.0
    a, b = np.c_[np.cos(ang), np.sin(ang), np.zeros(6)], np.c_[0.5 * np.cos(ang + 0.4), 0.5 * np.sin(ang + 0.4), np.ones(6)]
    stewart = Mechanism("warm-up legs", limbs=tuple(
        Limb(f"l{i}", (S(f"a{i}", a[i]), P(f"p{i}", a[i], (b[i] - a[i]) / np.linalg.norm(b[i] - a[i]), actuated=True),
                       S(f"b{i}", b[i]))) for i in range(6)), platform_point=np.zeros(3))
    held = active_mask(stewart)
    held[[7 * i + 3 for i in range(6)]] = False
    q = np.zeros(42)
    q[~held] = 0.01
    lp = leg_platform(stewart)
    assert lp is not None and lp.applies(held)
    correct_legs(stewart, lp, Configuration(q, np.eye(4)), active=held)
    inverse_legs_many(lp, np.eye(4)[None])  # the general checker's closed-form legs
    return time.perf_counter() - t0
