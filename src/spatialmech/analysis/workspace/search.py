"""Grid sampling, boundary refinement and results of the position / orientation workspace."""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ...errors import InputError, SearchTooLargeError
from ...geometry.rotations import euler_matrix
from ...geometry.validate import as_finite_array
from ...model.mechanism import Mechanism
from ...results import Progress
from .checker import (
    PoseChecker,
    pose_checker,
)
from .limits import (
    BOX,
    COORDINATES,
    ORIENTATION_COORDINATES,
    ORIENTATION_SEQUENCE,
    POSITION_COORDINATES,
    WorkspaceLimits,
)


#: Largest grid (poses, including the lines through the centre) sampled unless ``max_poses``
#: says otherwise: 10^7 on the vectorised closed-form kernel (about a minute), 2 10^4 on the
#: general kernel (one inverse position per pose).
MAX_POSES = 10_000_000
MAX_POSES_GENERAL = 20_000


# ------------------------------------------------------------------------------ results
@dataclass(frozen=True)
class Extent:
    """``[lo, hi]`` of one coordinate (m or rad) and the limit active at each end (``"box"``:
    the sampled bounds, i.e. no limit found inside them)."""

    lo: float
    hi: float
    lo_limit: str
    hi_limit: str

    def to_dict(self, degrees: bool) -> dict:
        f = np.degrees if degrees else (lambda v: v)
        return {"range": [float(f(self.lo)), float(f(self.hi))], "active_limits": [self.lo_limit, self.hi_limit]}


@dataclass(frozen=True, eq=False)
class WorkspaceResult:
    """A sampled, boundary-refined workspace (see the module docstring for the method).

    ``alone[c]``: extent of coordinate ``c`` alone (the other free coordinates at their fixed
    value ``center``); ``alone_intervals[c]``: every feasible interval along that line;
    ``extents[c]``: extent over the whole set; ``volume`` in ``volume_unit``;
    ``boundary_points`` (n, d) refined boundary points (free coordinates, SI) and
    ``boundary_limits`` the active limit at each; ``feasible`` the sampled grid (axes ``grid``).
    """

    mechanism: str
    kind: str
    path: str
    path_reason: str
    sequence: str
    free: tuple[str, ...]
    fixed: dict
    center: dict
    bounds: dict
    grid: tuple[np.ndarray, ...]
    feasible: np.ndarray
    alone: dict
    alone_intervals: dict
    extents: dict
    extent_method: dict
    volume: float
    volume_unit: str
    boundary_points: np.ndarray
    boundary_limits: tuple[str, ...]
    step: dict
    tol: dict
    n_poses: int
    seconds: float
    limits: WorkspaceLimits
    #: Estimated error of :attr:`volume` (same unit): ``|V_h - V_2h|``, the volume again from
    #: every second grid line in the coordinates the rule integrates over (first-order
    #: Richardson: the lines resolve the set's edge across them to a grid step), plus the
    #: bisection tolerance at every refined run end.  See :func:`volume_error`.
    volume_error: float = 0.0

    @property
    def active_limits(self) -> dict[str, int]:
        """How many refined boundary points each limit bounds (largest first)."""
        names, counts = np.unique(np.array(self.boundary_limits, dtype=object).astype(str), return_counts=True)
        order = np.argsort(-counts, kind="stable")
        return {str(names[i]): int(counts[i]) for i in order}

    @property
    def n_feasible(self) -> int:
        return int(np.count_nonzero(self.feasible))

    def to_dict(self, *, boundary: bool = False) -> dict:
        """JSON (docs/json.md): coordinates keyed with their unit, ``alpha_deg`` ... (degrees) and
        ``x_len`` ... (the model's length unit).

        ``extents[<c>_<unit>]``: ``alone`` = ``[min, max]`` of coordinate ``c`` alone (the others
        at their fixed values) with ``alone_active_limits`` and every feasible interval
        ``alone_intervals``; ``set`` = ``[min, max]`` over the whole set with
        ``set_active_limits`` and ``set_method``.  ``volume_deg3`` (orientation: Euler-angle
        coordinates, cubic degrees) or ``volume_len3`` (position), with the power the number of
        free coordinates (``volume_deg2`` ...).  ``boundary`` adds the refined boundary points.
        """
        def key(c: str) -> str:
            return f"{c}_deg" if c in ORIENTATION_COORDINATES else f"{c}_len"

        def conv(c: str, v: float) -> float:
            return float(np.degrees(v)) if c in ORIENTATION_COORDINATES else float(v)

        def pair(c: str, e) -> list[float] | None:
            return None if e is None else [conv(c, e.lo), conv(c, e.hi)]

        codes = {"deg" if c in ORIENTATION_COORDINATES else "len" for c in self.free}
        if len(codes) != 1:
            raise InputError(f"free: expected angles only or positions only, got {list(self.free)}")
        code = codes.pop()
        power = len(self.free)
        volume = float(self.volume) * (float(np.degrees(1.0)) ** power if code == "deg" else 1.0)
        extents = {}
        for c in self.free:
            a, e = self.alone[c], self.extents[c]
            extents[key(c)] = {
                "alone": pair(c, a),
                "alone_active_limits": None if a is None else [a.lo_limit, a.hi_limit],
                "alone_intervals": [[conv(c, lo), conv(c, hi)] for lo, hi in self.alone_intervals[c]],
                "set": pair(c, e),
                "set_active_limits": None if e is None else [e.lo_limit, e.hi_limit],
                "set_method": self.extent_method.get(c),
            }
        d: dict = {
            "mechanism": self.mechanism,
            "kind": self.kind,
            "path": self.path,
            "path_reason": self.path_reason or None,
            "euler_sequence": self.sequence,
            "orientation_convention": "R = Rz(gamma) Ry(beta) Rx(alpha): alpha about x, beta about y, gamma about z",
            "free": list(self.free),
            "fixed": {key(c): conv(c, v) for c, v in self.fixed.items()},
            "extents": extents,
            f"volume_{code}{power if power > 1 else ''}": volume,
            f"volume_error_{code}{power if power > 1 else ''}": float(self.volume_error) * (
                float(np.degrees(1.0)) ** power if code == "deg" else 1.0),
            "volume_note": ("Euler-angle coordinates (alpha, beta, gamma), not the Haar measure of SO(3)"
                            if code == "deg" else "volume of the platform point's positions"),
            "active_limits": self.active_limits,
            "bounds": {key(c): [conv(c, v[0]), conv(c, v[1])] for c, v in self.bounds.items()},
            "step": {key(c): conv(c, v) for c, v in self.step.items()},
            "boundary_tol": {key(c): conv(c, v) for c, v in self.tol.items()},
            "n_poses_checked": self.n_poses,
            "n_grid": int(self.feasible.size),
            "n_grid_feasible": self.n_feasible,
            "elapsed_s": self.seconds,
            "limits": self.limits.to_dict(),
            "caveat": ("extents are exact to the tolerance along the sampled lines; a feasible island "
                       "narrower than the grid step can be missed"),
        }
        if boundary:
            d[f"boundary_points_{code}"] = [[conv(c, v) for c, v in zip(self.free, row, strict=True)]
                                            for row in self.boundary_points]
            d["boundary_free"] = list(self.free)
            d["boundary_limits"] = list(self.boundary_limits)
        return d


# ------------------------------------------------------------------------------ the analysis
class _Space:
    """Free coordinates -> poses (R, p), with the fixed ones filled in."""

    def __init__(self, free: tuple[str, ...], values: dict[str, float]):
        self.free = free
        self.values = values  # every coordinate's fixed / centre value
        self.idx = [COORDINATES.index(c) for c in free]

    def poses(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        full = np.tile(np.array([self.values[c] for c in COORDINATES]), (X.shape[0], 1))
        full[:, self.idx] = X
        R = euler_matrix(ORIENTATION_SEQUENCE, full[:, [5, 4, 3]])
        return R, full[:, :3]


class _Evaluator:
    def __init__(self, checker: PoseChecker, space: _Space, chunk: int, progress):
        self.checker, self.space, self.chunk, self.progress = checker, space, int(chunk), progress
        self.count = 0
        self.expected: int | None = None  # estimated poses in all (the progress total), None: unknown

    def margins(self, X: np.ndarray) -> np.ndarray:
        out = np.empty((X.shape[0], len(self.checker.names)))
        for s in range(0, X.shape[0], self.chunk):
            R, p = self.space.poses(X[s : s + self.chunk])
            out[s : s + self.chunk] = self.checker.margins(R, p)
            self._tick(R.shape[0])
        return out

    def feasible(self, X: np.ndarray) -> np.ndarray:
        out = np.empty(X.shape[0], dtype=bool)
        for s in range(0, X.shape[0], self.chunk):
            R, p = self.space.poses(X[s : s + self.chunk])
            out[s : s + self.chunk] = self.checker.feasible(R, p)
            self._tick(R.shape[0])
        return out

    def _tick(self, n: int):
        self.count += n
        if self.progress is not None:
            total = self.expected if self.expected is not None and self.count <= self.expected else None
            self.progress(self.count, total, "checking poses")

    def active(self, X_out: np.ndarray) -> list[str]:
        if X_out.shape[0] == 0:
            return []
        m = self.margins(X_out) / self.checker.scales
        k = np.argmin(m, axis=1)
        return [self.checker.names[i] if m[j, i] < 0 else "?" for j, i in enumerate(k)]


def _bisect(ev: _Evaluator, x_in: np.ndarray, x_out: np.ndarray, tol: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised bisection between feasible ``x_in`` and infeasible ``x_out`` (n, d) until the
    bracket is below ``tol`` in every coordinate; returns the final (inside, outside) points."""
    x_in, x_out = x_in.copy(), x_out.copy()
    if x_in.shape[0] == 0:
        return x_in, x_out
    with np.errstate(over="ignore"):
        width = float(np.max(np.abs(x_out - x_in) / tol, axis=1).max())
    # at most 200 halvings: beyond ~60 the bracket is at the float resolution of the coordinates
    n_iter = int(np.ceil(np.log2(width))) if 1.0 < width < 2.0**200 else (200 if width >= 2.0**200 else 0)
    for _ in range(n_iter):
        mid = 0.5 * (x_in + x_out)
        ok = ev.feasible(mid)
        x_in[ok] = mid[ok]
        x_out[~ok] = mid[~ok]
    return x_in, x_out


def _axis_values(lo: float, hi: float, c: float, step: float) -> np.ndarray:
    """Regular samples of ``[lo, hi]`` with spacing ``<= step``, through ``c`` when symmetric."""
    n = max(int(np.ceil((hi - lo) / step - 1e-9)), 1)
    if abs((c - lo) - (hi - c)) < 1e-12 * max(1.0, hi - lo) and n % 2:
        n += 1
    return np.linspace(lo, hi, n + 1)


def _line_runs(F: np.ndarray, axis: int):
    """Start and end indices of the runs of True along ``axis``: (line index tuple, i0, i1)."""
    Fm = np.moveaxis(F, axis, -1)
    pad = np.zeros((*Fm.shape[:-1], 1), dtype=bool)
    d = np.diff(np.concatenate([pad, Fm, pad], axis=-1).astype(np.int8), axis=-1)
    starts = np.argwhere(d == 1)  # (..., i): run starts at i
    ends = np.argwhere(d == -1)  # run ends at i - 1
    return starts, ends


def _refine_runs(ev, F, grid, axis, tol):
    """Refined run limits along ``axis`` of every grid line.

    Returns ``(lines, lo, hi, lo_lim, hi_lim, X_in_lo, X_in_hi)`` with one row per run.
    """
    d = F.ndim
    starts, ends = _line_runs(F, axis)
    n_ax = F.shape[axis]
    other = [k for k in range(d) if k != axis]

    def points(rows, idx):
        X = np.empty((rows.shape[0], d))
        for j, k in enumerate(other):
            X[:, k] = grid[k][rows[:, j]]
        X[:, axis] = grid[axis][idx]
        return X

    lines = starts[:, :-1]
    i0 = starts[:, -1]
    i1 = ends[:, -1] - 1
    lo = grid[axis][i0].astype(float)
    hi = grid[axis][i1].astype(float)
    lo_lim = np.array([BOX] * len(i0), dtype=object)
    hi_lim = np.array([BOX] * len(i1), dtype=object)
    xin_lo = points(lines, i0)
    xin_hi = points(lines, i1)
    for _side, idx, nb, arr, lim, xin in (("lo", i0, i0 - 1, lo, lo_lim, xin_lo), ("hi", i1, i1 + 1, hi, hi_lim, xin_hi)):
        sel = np.flatnonzero((nb >= 0) & (nb < n_ax))
        if sel.size == 0:
            continue
        a_in, a_out = _bisect(ev, points(lines[sel], idx[sel]), points(lines[sel], nb[sel]), tol)
        arr[sel] = a_in[:, axis]
        xin[sel] = a_in
        lim[sel] = ev.active(a_out)
    return lines, lo, hi, lo_lim, hi_lim, xin_lo, xin_hi


def volume_error(grid, lines: np.ndarray, lengths: np.ndarray, k: int, tol: float) -> float:
    """Error estimate of the volume ``sum w * lengths`` over refined runs along coordinate ``k``
    (``lines``: each run's grid indices in the other coordinates): ``max |V_h - V_2h|`` over the
    two coarse grids of every second grid line in each other coordinate (the even lines, and the
    odd ones; both keep the first and last line), plus ``tol`` times the weight of every run end
    (the bisection's resolution).  Two offsets, because on a coarse grid one of them can match
    ``V_h`` by chance (a set over the middle lines of five, sampled at lines 0, 2, 4)."""
    others = [m for m in range(len(grid)) if m != k]
    w_h = np.ones(lines.shape[0])
    for j, kk in enumerate(others):
        w_h *= trapezoid_weights(np.asarray(grid[kk]))[lines[:, j]]
    v_h = float(np.sum(w_h * lengths))
    rich = 0.0
    for first in (0, 1):
        w_2h = np.ones(lines.shape[0])
        for j, kk in enumerate(others):
            g = np.asarray(grid[kk])
            sub = np.unique(np.r_[0, np.arange(first, g.size, 2), g.size - 1])
            w_sub = np.zeros(g.size)
            w_sub[sub] = trapezoid_weights(g[sub])
            w_2h *= w_sub[lines[:, j]]
        if others:
            rich = max(rich, abs(v_h - float(np.sum(w_2h * lengths))))
    return rich + float(np.sum(w_h)) * 2.0 * abs(float(tol))


def trapezoid_weights(v: np.ndarray) -> np.ndarray:
    """Trapezoid-rule weights of the grid values ``v`` (a single value weighs 1)."""
    if v.size == 1:
        return np.ones(1)
    h = np.diff(v)
    w = np.zeros(v.size)
    w[:-1] += 0.5 * h
    w[1:] += 0.5 * h
    return w


def _polish(ev: _Evaluator, checker: PoseChecker, x0: np.ndarray, k: int, sign: float, bounds, tol) -> np.ndarray | None:
    """Maximise ``sign * x[k]`` subject to every margin >= 0 (SLSQP) from the feasible ``x0``."""
    scales = checker.scales

    def cons(x):
        return (ev.margins(x[None])[0] / scales)

    from scipy.optimize import minimize  # on first use: scipy.optimize (it loads scipy.spatial) is costly

    try:
        res = minimize(lambda x: -sign * x[k], x0, method="SLSQP", bounds=bounds,
                       constraints=[{"type": "ineq", "fun": cons}], options={"maxiter": 100, "ftol": 1e-12})
    except (ValueError, np.linalg.LinAlgError):
        return None
    x = np.asarray(res.x, dtype=float)
    return x if np.all(np.isfinite(x)) else None


def _polished_extent(ev, checker, x0, k, sign, bounds, tolv, stepv):
    """Polish one set extent: SLSQP optimum, then an inside point found by backing off along
    coordinate ``k`` and a bisection along ``k`` outwards to ``tol``.  ``None`` if no feasible
    point beyond the grid-line estimate is confirmed by the kernel."""
    x = _polish(ev, checker, x0, k, sign, bounds, tolv)
    if x is None:
        return None
    lo_b, hi_b = bounds[k]
    x_in = None
    for delta in stepv[k] * np.array([0.0, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0]):
        cand = x.copy()
        cand[k] = np.clip(x[k] - sign * delta, lo_b, hi_b)
        if ev.feasible(cand[None])[0]:
            x_in = cand
            break
    if x_in is None:
        return None
    x_out = x_in.copy()
    x_out[k] = np.clip(x_in[k] + sign * stepv[k], lo_b, hi_b)
    if ev.feasible(x_out[None])[0]:
        return None  # still feasible a grid step further out: leave it to the grid estimate
    a_in, a_out = _bisect(ev, x_in[None], x_out[None], tolv)
    return float(a_in[0, k]), ev.active(a_out)[0]


def _axis_count(lo: float, hi: float, c: float, step: float) -> float:
    """``_axis_values(lo, hi, c, step).size`` without building the array (a float: may be huge)."""
    with np.errstate(over="ignore"):
        n = max(float(np.ceil((hi - lo) / step - 1e-9)), 1.0)
    if np.isfinite(n) and n < 2**52 and abs((c - lo) - (hi - c)) < 1e-12 * max(1.0, hi - lo) and int(n) % 2:
        n += 1
    return n + 1


def _check_grid_size(free, values, bounds, step, path: str, max_poses) -> None:
    """Refuse a grid (plus its lines through the centre) larger than ``max_poses`` (default
    :data:`MAX_POSES` or :data:`MAX_POSES_GENERAL`), before any array is built."""
    limit = (MAX_POSES_GENERAL if path == "general" else MAX_POSES) if max_poses is None else max_poses
    counts = [_axis_count(bounds[c][0], bounds[c][1], values[c], step[c]) for c in free]
    n = float(np.prod(counts)) + sum(counts)
    if n <= limit:
        return
    # sizes by logarithms: a step below the float resolution of the bounds gives inf counts
    log10_n = sum(np.log10(bounds[c][1] - bounds[c][0]) - np.log10(step[c]) for c in free)
    e = float((max(log10_n, np.log10(n) if np.isfinite(n) else 0.0) - np.log10(limit)) / len(free))
    factor = f"{10.0**e:.3g}" if e < 300 else f"1e{e:.0f}"
    size = f"about {n:.3g}" if np.isfinite(n) else f"about 1e{log10_n:.0f}"
    or_raise = f", or raise max_poses to at least {n:.0f}" if np.isfinite(n) and n < 1e12 else ""
    raise SearchTooLargeError(
        f"step: the grid has {size} poses ({' x '.join(f'{c:.3g}' for c in counts)} plus the lines through the "
        f"centre), more than max_poses = {limit} for the {path} kernel; multiply the step by at least "
        f"{factor} or narrow the bounds{or_raise}")


def _analyse(mech, kind, free, values, bounds, step, tol, limits, method, chunk, progress, max_poses, polish):
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise InputError(f"chunk: expected a positive number of poses per block, got {chunk!r}")
    if max_poses is not None and (isinstance(max_poses, bool) or not isinstance(max_poses, (int, np.integer))
                                  or max_poses < 1):
        raise InputError(f"max_poses: expected a positive integer, got {max_poses!r}")
    t0 = time.perf_counter()
    checker = pose_checker(mech, limits, method=method)
    space = _Space(free, values)
    ev = _Evaluator(checker, space, int(chunk), progress)
    d = len(free)
    stepv = np.array([step[c] for c in free])
    tolv = np.array([tol[c] for c in free])
    _check_grid_size(free, values, bounds, step, checker.path, max_poses)
    grid = tuple(_axis_values(bounds[c][0], bounds[c][1], values[c], step[c]) for c in free)
    shape = tuple(g.size for g in grid)
    n_grid = int(np.prod(shape))
    centre = np.array([values[c] for c in free])
    # the progress total: the lines and the grid, then (below) the bisections of the boundary
    with np.errstate(over="ignore"):
        n_halvings = int(min(np.ceil(np.log2(max(float(np.max(stepv / tolv)), 2.0))), 200))  # as in _bisect
    ev.expected = n_grid + sum(g.size + 2 * n_halvings for g in grid)

    # ---- each coordinate alone (others at their fixed value)
    alone: dict[str, Extent | None] = {}
    alone_int: dict[str, list[tuple[float, float]]] = {}
    for k, c in enumerate(free):
        X = np.tile(centre, (grid[k].size, 1))
        X[:, k] = grid[k]
        F1 = ev.feasible(X)
        lo, hi, lo_lim, hi_lim = _refine_line(ev, F1, X, k, tolv)
        alone_int[c] = [(float(a), float(b)) for a, b in zip(lo, hi, strict=True)]
        if lo.size:
            i, j = int(np.argmin(lo)), int(np.argmax(hi))
            alone[c] = Extent(float(lo[i]), float(hi[j]), str(lo_lim[i]), str(hi_lim[j]))
        else:
            alone[c] = None

    # ---- the grid
    F = np.empty(n_grid, dtype=bool)
    block = max(chunk, 1)
    for s in range(0, n_grid, block):
        idx = np.unravel_index(np.arange(s, min(s + block, n_grid)), shape)
        X = np.column_stack([grid[k][idx[k]] for k in range(d)])
        F[s : s + X.shape[0]] = ev.feasible(X)
    F = F.reshape(shape)
    n_changes = sum(int(np.count_nonzero(np.diff(F, axis=k))) for k in range(d))
    ev.expected = ev.count + n_changes * (n_halvings + 1)

    # ---- boundary refinement along every grid direction
    bpts, blims = [], []
    extents: dict[str, Extent | None] = {}
    method_used: dict[str, str] = {}
    volume = volume_err = 0.0
    for k, c in enumerate(free):
        lines, lo, hi, lo_lim, hi_lim, xin_lo, xin_hi = _refine_runs(ev, F, grid, k, tolv)
        for X, lim, a in ((xin_lo, lo_lim, lo), (xin_hi, hi_lim, hi)):
            X = X.copy()
            X[:, k] = a
            bpts.append(X)
            blims += [str(v) for v in lim]
        if k == 0:
            w = np.ones(lines.shape[0])
            for j, kk in enumerate([m for m in range(d) if m != k]):
                w *= trapezoid_weights(grid[kk])[lines[:, j]]
            volume = float(np.sum(w * (hi - lo)))
            volume_err = volume_error(grid, lines, hi - lo, k, tolv[k] if np.ndim(tolv) else float(tolv))
        if lo.size == 0:
            extents[c] = None
            continue
        i, j = int(np.argmin(lo)), int(np.argmax(hi))
        ext = [float(lo[i]), float(hi[j])]
        lims = [str(lo_lim[i]), str(hi_lim[j])]
        how = "bisection along grid lines"
        if polish and checker.path == "closed-form":
            bnds = [tuple(bounds[cc]) for cc in free]
            for side, (x0, sign) in enumerate(((xin_lo[i], -1.0), (xin_hi[j], 1.0))):
                if lims[side] == BOX:
                    continue
                got = _polished_extent(ev, checker, x0, k, sign, bnds, tolv, stepv)
                if got is not None and sign * (got[0] - ext[side]) > 0.0:
                    ext[side], lims[side] = got
                    how = "bisection along grid lines, improved by SLSQP polish"
        extents[c] = Extent(ext[0], ext[1], lims[0], lims[1])
        method_used[c] = how
    if d == 1:
        volume_unit = "rad" if free[0] in ORIENTATION_COORDINATES else "m"
    else:
        us = ["rad" if c in ORIENTATION_COORDINATES else "m" for c in free]
        volume_unit = " ".join(f"{u}^{us.count(u)}" if us.count(u) > 1 else u for u in dict.fromkeys(us))
    if kind == "orientation":
        volume_unit += " (Euler-angle coordinates alpha, beta, gamma; not the Haar measure of SO(3))"
    bp = np.concatenate(bpts) if bpts else np.zeros((0, d))
    return WorkspaceResult(
        mechanism=mech.name, kind=kind, path=checker.path, path_reason=checker.reason,
        sequence=ORIENTATION_SEQUENCE, free=free,
        fixed={c: values[c] for c in COORDINATES if c not in free},
        center={c: values[c] for c in free}, bounds={c: tuple(bounds[c]) for c in free},
        grid=grid, feasible=F, alone=alone, alone_intervals=alone_int, extents=extents,
        extent_method=method_used, volume=volume, volume_unit=volume_unit, boundary_points=bp, volume_error=volume_err,
        boundary_limits=tuple(blims),
        step={c: float(g[1] - g[0]) if g.size > 1 else 0.0 for c, g in zip(free, grid, strict=True)},
        tol={c: tol[c] for c in free}, n_poses=ev.count, seconds=time.perf_counter() - t0, limits=checker.limits,
    )


def _refine_line(ev, F1, X, k, tolv):
    """Runs of one sampled line (``X`` (n, d), feasibility ``F1``), refined along coordinate ``k``."""
    starts, ends = _line_runs(F1, 0)
    i0, i1 = starts[:, -1], ends[:, -1] - 1
    lo, hi = X[i0, k].astype(float), X[i1, k].astype(float)
    lo_lim = np.array([BOX] * i0.size, dtype=object)
    hi_lim = np.array([BOX] * i1.size, dtype=object)
    n = X.shape[0]
    for idx, nb, arr, lim in ((i0, i0 - 1, lo, lo_lim), (i1, i1 + 1, hi, hi_lim)):
        sel = np.flatnonzero((nb >= 0) & (nb < n))
        if sel.size:
            a_in, a_out = _bisect(ev, X[idx[sel]], X[nb[sel]], tolv)
            arr[sel] = a_in[:, k]
            lim[sel] = ev.active(a_out)
    return lo, hi, lo_lim, hi_lim


def _parse_at(at, allowed: tuple[str, ...], name: str = "at") -> dict[str, float]:
    if at is None:
        return {}
    if not isinstance(at, Mapping):
        raise InputError(f"{name}: expected a mapping of coordinate -> value, got {type(at).__name__}")
    out = {}
    for k, v in at.items():
        if k not in allowed:
            raise InputError(f"{name}: unknown coordinate {k!r}; expected one of {list(allowed)}")
        out[k] = float(as_finite_array(v, f"{name}.{k}", shape=()))
    return out


#: Largest distance of a fixed position coordinate from the reference platform point, in
#: characteristic lengths (farther is out of the numerical range: squares overflow).
MAX_DISTANCE = 1e6


def _check_position_range(mech: Mechanism, fixed: Mapping[str, float]) -> None:
    L = mech.characteristic_length
    for i, c in enumerate(POSITION_COORDINATES):
        if c in fixed and abs(fixed[c] - float(mech.platform_point[i])) > MAX_DISTANCE * L:
            raise InputError(f"at.{c}: {fixed[c]:g} is more than {MAX_DISTANCE:g} times the size of {mech.name} "
                             f"({L:.3g} m) from its reference platform point: out of range")


def _check_positive(value, name: str) -> float:
    v = float(as_finite_array(value, name, shape=()))
    if v <= 0:
        raise InputError(f"{name}: must be positive, got {v}")
    return v


def _bounds_of(bounds, free, default) -> dict:
    out = dict(default)
    if bounds is not None:
        if not isinstance(bounds, Mapping):
            raise InputError("bounds: expected a mapping of coordinate -> (lower, upper)")
        for c, v in bounds.items():
            if c not in free:
                raise InputError(f"bounds: {c!r} is not a free coordinate ({list(free)})")
            b = as_finite_array(v, f"bounds.{c}", shape=(2,))
            if not b[0] < b[1]:
                raise InputError(f"bounds.{c}: expected lower < upper, got {tuple(b)}")
            out[c] = (float(b[0]), float(b[1]))
    return out


def orientation_workspace(
    mech: Mechanism,
    *,
    at: Mapping[str, float] | None = None,
    limits: WorkspaceLimits | None = None,
    step: float = np.radians(2.0),
    tol: float = np.radians(1e-3),
    bounds: Mapping[str, tuple[float, float]] | None = None,
    method: str = "auto",
    chunk: int = 1 << 15,
    progress: Progress | None = None,
    max_poses: int | None = None,
    polish: bool = True,
) -> WorkspaceResult:
    """Orientation workspace at a fixed platform position (paper B fig 5).

    ``at``: fixed coordinates (SI, rad): ``x, y, z`` default to the reference platform point;
    angles given here are held fixed too (a slice).  The free angles ``alpha, beta, gamma``
    (``R = Rz(gamma) Ry(beta) Rx(alpha)``) are sampled over ``bounds`` (default
    ``alpha, gamma in [-pi, pi]``, ``beta in [-pi/2, pi/2]``, which covers SO(3)) with spacing
    ``<= step`` rad and refined to ``tol`` rad.  ``limits`` default to :func:`default_limits`.
    ``progress(done, None, "checking poses")`` is called after each block with the number of
    poses checked so far (for a progress bar).  ``max_poses`` bounds the grid (default
    :data:`MAX_POSES` on the closed-form kernel, :data:`MAX_POSES_GENERAL` on the general one):
    a larger grid raises :class:`~spatialmech.errors.SearchTooLargeError` (a ``ValueError``)
    with its size, before any work.
    """
    fixed = _parse_at(at, COORDINATES)
    _check_position_range(mech, fixed)
    step = _check_positive(step, "step")
    tol = _check_positive(tol, "tol")
    values = {c: float(mech.platform_point[i]) for i, c in enumerate(POSITION_COORDINATES)}
    values.update(dict.fromkeys(ORIENTATION_COORDINATES, 0.0))
    values.update(fixed)
    free = tuple(c for c in ORIENTATION_COORDINATES if c not in fixed)
    if not free:
        raise InputError("at: every angle is fixed; nothing to sample")
    default = {"alpha": (-np.pi, np.pi), "beta": (-np.pi / 2, np.pi / 2), "gamma": (-np.pi, np.pi)}
    b = _bounds_of(bounds, free, {c: default[c] for c in free})
    return _analyse(mech, "orientation", free, values, b, dict.fromkeys(free, step), dict.fromkeys(free, tol),
                    limits, method, chunk, progress, max_poses, polish)


def position_workspace(
    mech: Mechanism,
    *,
    at: Mapping[str, float] | None = None,
    limits: WorkspaceLimits | None = None,
    step: float | None = None,
    tol: float | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    method: str = "auto",
    chunk: int = 1 << 15,
    progress: Progress | None = None,
    max_poses: int | None = None,
    polish: bool = True,
) -> WorkspaceResult:
    """Position workspace of the platform point at a fixed orientation.

    ``at``: fixed coordinates: ``alpha, beta, gamma`` (rad, default 0) and any of ``x, y, z``
    to hold fixed (a slice).  Coordinates that a limb pins (the CU limb of paper B keeps
    ``x = y = 0``) are fixed automatically on the closed-form path.  Default ``step`` =
    characteristic length / 40, ``tol`` = characteristic length * 1e-6, ``bounds`` = reference
    point +- 2 characteristic lengths (m).  ``max_poses`` as in :func:`orientation_workspace`.
    """
    fixed = _parse_at(at, COORDINATES)
    _check_position_range(mech, fixed)
    L = mech.characteristic_length
    step = L / 40 if step is None else _check_positive(step, "step")
    tol = L * 1e-6 if tol is None else _check_positive(tol, "tol")
    checker_probe = pose_checker(mech, limits, method=method)
    values = {c: float(mech.platform_point[i]) for i, c in enumerate(POSITION_COORDINATES)}
    values.update(dict.fromkeys(ORIENTATION_COORDINATES, 0.0))
    for c, v in checker_probe.pinned.items():
        if c not in fixed:
            fixed[c] = v
    values.update(fixed)
    free = tuple(c for c in POSITION_COORDINATES if c not in fixed)
    if not free:
        raise InputError("at: every position coordinate is fixed; nothing to sample")
    default = {c: (values[c] - 2 * L, values[c] + 2 * L) for c in free}
    b = _bounds_of(bounds, free, default)
    return _analyse(mech, "position", free, values, b, dict.fromkeys(free, step), dict.fromkeys(free, tol),
                    limits, method, chunk, progress, max_poses, polish)
