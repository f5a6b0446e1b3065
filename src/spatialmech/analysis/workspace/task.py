"""Workspace over the task coordinates of a lower-mobility mechanism (issue 11).

A 3-RPS, 3-PRS or 3-UPU has ``M = 3`` independent task coordinates; the other ``6 - M`` are
parasitic and follow from the closure.  Sampling the full pose (``x, y, z, alpha, beta,
gamma``) finds almost nothing reachable: a pose is reachable only on the M-dimensional closure
set, so a grid of six-coordinate poses misses it.  :func:`task_workspace` samples the *given*
coordinates instead and solves the parasitic ones at every sample.

Coordinates: ``x, y, z`` (the output link's reference point, the model's length unit) and
``a1, a2, a3``, the Euler angles of the output orientation in the task's named sequence (default
``"ZYX"``, intrinsic: ``R = Rz(a1) Ry(a2) Rx(a3)``); SI and radians inside.

Method
------
1. One to three given coordinates are sampled on a grid (``over``), the other given ones held
   (``at``).  :func:`~spatialmech.kinematics.task_grid.solve_task_grid` solves the parasitic
   coordinates at each cell by continuation: Newton from an already solved neighbour, one short
   solve per cell, on the assembly branch of the seed (the reference configuration).
2. Each closed cell is checked against the limits (:func:`.checker.configuration_checker`: the
   freedoms' limits on ``offset + q``, cones of S/U joints, link capsules); a cell is *reachable*
   when it closes and is within every limit; a cell that does not close is outside, with the
   limit ``"closure"``.
3. Every pair of grid neighbours with one reachable and one unreachable cell is bracketed to
   ``tol`` in the grid coordinate (safeguarded false position on the margin of the limit broken
   outside, bisection where the outside does not close: about three solves per boundary point
   instead of ten), each probe solved from the inside point's configuration; the limit violated
   just outside is that boundary point's *active limit*.
4. Extents of each grid coordinate: min / max over the reachable cells and the refined boundary
   points (``"box"``: the grid's own bound, no limit met inside it); ranges of every other
   coordinate (the parasitic ones) over the same points; the reachable fraction of the cells;
   the measure of the set (refined run lengths along the first grid coordinate, integrated by the
   trapezoid rule over the others) when the grid coordinates share one unit.

Accuracy: to ``tol`` along the grid lines; a reachable island thinner than the grid step can be
missed; the set is the one on the seed's assembly branch (cells the sweep cannot reach from it
are tried from the seed directly).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import cast

import numpy as np

from ...errors import InputError
from ...geometry.validate import as_finite_array
from ...kinematics.closure import Configuration
from ...kinematics.task_grid import TASK_NAMES, TaskGrid, edge_value, solve_task_grid, solve_task_point, task_unit
from ...model.mechanism import Mechanism
from ...model.task import TaskCoordinates
from ...results import Progress, check_progress
from .checker import ConfigurationChecker, configuration_checker
from .limits import BOX, CLOSURE, WorkspaceLimits, default_limits
from .search import Extent, trapezoid_weights, volume_error

__all__ = ["TASK_PATH", "TaskWorkspaceResult", "euler_convention", "task_workspace"]

#: The ``path`` of a task-coordinate workspace (closed-form and general are the pose paths).
TASK_PATH = "task-continuation"


def euler_convention(seq: str) -> str:
    """``"ZYX"`` -> ``"R = Rz(a1) Ry(a2) Rx(a3) (intrinsic ZYX)"``; lower case: extrinsic."""
    if seq.isupper():
        return f"R = R{seq[0].lower()}(a1) R{seq[1].lower()}(a2) R{seq[2].lower()}(a3) (intrinsic {seq})"
    return f"R = R{seq[2]}(a3) R{seq[1]}(a2) R{seq[0]}(a1) (extrinsic {seq})"


@dataclass(frozen=True, eq=False)
class TaskWorkspaceResult:
    """A workspace over task coordinates (:func:`task_workspace`); SI and radians.

    ``over``: the grid coordinates, ``grid`` their values; ``fixed``: the held given coordinates;
    ``given`` / ``solved``: the task's given and parasitic coordinates; ``converged`` and
    ``feasible`` (grid shape): the cell closes / closes within every limit; ``cell_limits``: the
    most violated limit of each cell (``""`` inside, ``"closure"`` where it does not close);
    ``values`` (grid shape + (6,)): the six coordinates ``x, y, z, a1, a2, a3`` (NaN where not
    closed); ``extents[c]``: ``[lo, hi]`` of grid coordinate ``c`` over the reachable set with the
    active limit at each end; ``ranges[c]``: ``(lo, hi)`` of every coordinate over the reachable
    samples; ``boundary_points`` (n, d) refined boundary points (grid coordinates),
    ``boundary_values`` (n, 6) the six coordinates there, ``boundary_limits`` their active limits,
    ``boundary_configs`` their closed configurations, ``boundary_axes`` the grid coordinate along
    which each was bisected, ``boundary_outside`` the other end of its final bracket (outside);
    ``volume`` the measure of the set in ``volume_unit`` (``None`` for mixed units),
    ``volume_error`` its estimated error (same unit; see :func:`.search.volume_error`: the measure
    again from every second grid line, plus the boundary tolerance at every refined run end).
    """

    mechanism: str
    euler: str
    given: tuple[str, ...]
    solved: tuple[str, ...]
    over: tuple[str, ...]
    fixed: dict
    grid: tuple[np.ndarray, ...]
    converged: np.ndarray
    feasible: np.ndarray
    cell_limits: np.ndarray
    values: np.ndarray
    extents: dict
    ranges: dict
    volume: float | None
    volume_unit: str
    boundary_points: np.ndarray
    boundary_values: np.ndarray
    boundary_limits: tuple[str, ...]
    boundary_configs: tuple
    boundary_axes: np.ndarray
    boundary_outside: np.ndarray
    step: dict
    tol: dict
    n_solves: int
    seconds: float
    limits: WorkspaceLimits
    limit_names: tuple[str, ...]
    configs: np.ndarray
    length_unit: str = "m"
    volume_error: float | None = None
    kind: str = "task"
    path: str = TASK_PATH

    @property
    def n_feasible(self) -> int:
        return int(np.count_nonzero(self.feasible))

    @property
    def reachable_fraction(self) -> float:
        return self.n_feasible / max(int(self.feasible.size), 1)

    @property
    def active_limits(self) -> dict[str, int]:
        """How many refined boundary points each limit bounds (largest first)."""
        names, counts = np.unique(np.array(self.boundary_limits, dtype=object).astype(str), return_counts=True)
        order = np.argsort(-counts, kind="stable")
        return {str(names[i]): int(counts[i]) for i in order}

    def config_at(self, index) -> Configuration | None:
        """The closed configuration of grid cell ``index`` (``None`` where it does not close)."""
        return self.configs[tuple(index)]

    def to_dict(self) -> dict:
        """JSON (docs/json.md): coordinates keyed with their unit (``a2_deg``, ``z_len``).

        ``extents[<c>]``: ``range`` ``[min, max]`` of grid coordinate ``c`` over the reachable
        set and its ``active_limits``; ``solved_ranges``: ranges of every other coordinate;
        ``samples``: the grid (``axes``), ``reachable`` per cell and the ``values`` of every
        coordinate per cell (``null`` where the cell does not close).
        """
        def key(c: str) -> str:
            return f"{c}_{task_unit(c)}"

        def conv(c: str, v: float) -> float:
            return edge_value(c, v)

        def nested(a: np.ndarray, c: str):
            if a.ndim == 0:
                return None if not np.isfinite(a) else conv(c, float(a))
            return [nested(x, c) for x in a]

        extents = {}
        for c in self.over:
            e = self.extents[c]
            extents[key(c)] = {"range": None if e is None else [conv(c, e.lo), conv(c, e.hi)],
                               "active_limits": None if e is None else [e.lo_limit, e.hi_limit]}
        others = [c for c in TASK_NAMES if c not in self.over and c not in self.fixed]
        d: dict = {
            "mechanism": self.mechanism,
            "kind": self.kind,
            "path": self.path,
            "path_reason": (f"{', '.join(self.solved)} solved at every cell by Newton from a solved neighbour "
                            "(continuation), limits checked on the closed configuration"),
            "euler_sequence": self.euler,
            "orientation_convention": euler_convention(self.euler),
            "free": list(self.over),
            "given": list(self.given),
            "solved": list(self.solved),
            "fixed": {key(c): conv(c, v) for c, v in self.fixed.items()},
            "extents": extents,
            "solved_ranges": {key(c): (None if self.ranges.get(c) is None
                                       else [conv(c, self.ranges[c][0]), conv(c, self.ranges[c][1])]) for c in others},
            "reachable_fraction": self.reachable_fraction,
            "active_limits": self.active_limits,
            "limit_names": list(self.limit_names),
            "bounds": {key(c): [conv(c, float(g[0])), conv(c, float(g[-1]))] for c, g in zip(self.over, self.grid, strict=True)},
            "step": {key(c): conv(c, v) for c, v in self.step.items()},
            "boundary_tol": {key(c): conv(c, v) for c, v in self.tol.items()},
            "n_poses_checked": self.n_solves,
            "n_grid": int(self.feasible.size),
            "n_grid_converged": int(np.count_nonzero(self.converged)),
            "n_grid_feasible": self.n_feasible,
            "elapsed_s": self.seconds,
            "limits": self.limits.to_dict(),
            "samples": {
                "axes": {key(c): [conv(c, float(v)) for v in g] for c, g in zip(self.over, self.grid, strict=True)},
                "reachable": self.feasible.tolist(),
                "values": {key(c): nested(self.values[..., i], c) for i, c in enumerate(TASK_NAMES)},
            },
            "caveat": ("extents are exact to the tolerance along the grid lines; a reachable island thinner than "
                       "the grid step can be missed; the set is the one on the reference assembly branch"),
        }
        units = {task_unit(c) for c in self.over}
        if self.volume is not None and len(units) == 1:
            code = units.pop()
            power = len(self.over)
            scale = float(np.degrees(1.0)) ** power if code == "deg" else 1.0
            d[f"volume_{code}{power if power > 1 else ''}"] = float(self.volume) * scale
            d[f"volume_error_{code}{power if power > 1 else ''}"] = float(self.volume_error or 0.0) * scale
            d["volume_note"] = ("measure of the reachable set in the grid coordinates"
                                + (" (Euler angles, not the Haar measure of SO(3))" if code == "deg" else ""))
        else:
            d["volume_note"] = "no volume: the grid coordinates mix lengths and angles"
        return d


# ------------------------------------------------------------------------------ the analysis
class _Probe:
    """Solve + limit check at one point of the grid coordinates, counting the solves."""

    def __init__(self, mech: Mechanism, grid: TaskGrid, checker: ConfigurationChecker):
        self.mech, self.grid, self.checker = mech, grid, checker
        self.n = 0

    def margins(self, config: Configuration) -> np.ndarray:
        """The scaled margins (comparable across limits: lengths / L, rad) at ``config``."""
        return self.checker.margins(config) / self.checker.scales if self.checker.names else np.zeros(0)

    def limit(self, m: np.ndarray) -> str:
        """The most violated limit of the scaled margins ``m``, ``""`` when within every limit."""
        if m.size == 0:
            return ""
        k = _first_least(m)
        return self.checker.names[k] if m[k] < 0 else ""

    def __call__(self, x: np.ndarray, seed: Configuration):
        """``(config or None, values or None, scaled margins or None, limit)`` at grid point ``x``."""
        self.n += 1
        config, vals, _ = solve_task_point(self.mech, self.grid.given_at(x), self.grid.task, seed)
        if config is None:
            return None, None, None, CLOSURE
        m = self.margins(config)
        return config, vals, m, self.limit(m)


#: Relative difference below which two margins, or two extents, count as a tie (the first wins):
#: limits equal by symmetry (two legs of a 3-RPS) then get one name, not one picked by rounding.
TIE = 1e-12


def _first_least(v: np.ndarray) -> int:
    """The index of the least of ``v``, the first of those within :data:`TIE` of it."""
    lo = float(np.min(v))
    return int(np.flatnonzero(v <= lo + TIE * max(1.0, abs(lo)))[0])


def _bracket(probe: _Probe, k: int, x_in: np.ndarray, c_in: Configuration, v_in: np.ndarray, m_in: np.ndarray,
             x_out: np.ndarray, m_out: np.ndarray | None, lim_out: str, tol: float):
    """Shrink the bracket between a reachable ``x_in`` (configuration ``c_in``, scaled margins
    ``m_in``) and an unreachable ``x_out`` (margins ``m_out``, ``None`` where it does not close)
    along grid coordinate ``k`` to ``tol``; each probe is solved from the inside configuration
    (continuation).

    Safeguarded false position on the margin of the limit broken outside (Illinois: the end kept
    not moved twice in a row has its margin halved), a bisection where the outside does not close; a probe
    is kept at least ``tol / 2`` inside the bracket, so that the last steps close it.  Returns the
    last inside point, its configuration and coordinates, the last outside point and the limit
    broken there."""
    names = probe.checker.names
    moved = 0  # +1: the inside end moved last time, -1: the outside end
    f_in = f_out = None
    if lim_out != CLOSURE and m_out is not None:
        j = names.index(lim_out)
        f_in, f_out = float(m_in[j]), float(m_out[j])
    for _ in range(60):
        a, b = float(x_in[k]), float(x_out[k])
        w = abs(b - a)
        if w <= tol:
            break
        t = 0.5 * (a + b)  # bisection, unless the margins give a false-position estimate
        if f_in is not None and f_out is not None and f_in - f_out > 0:
            t = a + (b - a) * f_in / (f_in - f_out)
        lo, hi = min(a, b) + 0.5 * tol, max(a, b) - 0.5 * tol
        t = min(max(t, lo), hi) if lo <= hi else 0.5 * (a + b)
        x = x_in.copy()
        x[k] = t
        config, vals, m, lim = probe(x, c_in)
        if config is not None and lim == "":
            x_in, c_in, v_in, m_in = x, config, vals, m
            if f_in is not None:
                f_in = float(m[names.index(lim_out)])
                if moved == 1 and f_out is not None:
                    f_out *= 0.5
            moved = 1
        else:
            if lim != lim_out or m is None:  # another limit (or closure) breaks first: follow it
                f_in = float(m_in[names.index(lim)]) if lim != CLOSURE else None
            x_out, lim_out = x, lim
            f_out = float(m[names.index(lim)]) if m is not None and lim != CLOSURE else None
            if moved == -1 and f_in is not None:
                f_in *= 0.5
            moved = -1
    return x_in, c_in, v_in, x_out, lim_out


def _parse_over(over) -> dict[str, np.ndarray]:
    """``{name: values}`` or ``{name: (lo, hi, n)}`` -> ``{name: values}`` (SI, rad)."""
    if not isinstance(over, Mapping) or not over:
        raise InputError("over: expected a mapping of task coordinate -> (lo, hi, n) or grid values (SI, rad)")
    out = {}
    for c, v in over.items():
        if isinstance(v, tuple) and len(v) == 3 and isinstance(v[2], (int, np.integer)) and not isinstance(v[2], bool):
            lo, hi = (float(as_finite_array(x, f"over.{c}", shape=())) for x in v[:2])
            n = int(v[2])
            if n < 2:
                raise InputError(f"over.{c}: expected at least 2 grid points, got {n}")
            if not lo < hi:
                raise InputError(f"over.{c}: expected lo < hi, got ({lo}, {hi})")
            out[str(c)] = np.linspace(lo, hi, n)
        else:
            out[str(c)] = as_finite_array(v, f"over.{c}").reshape(-1)
    return out


def task_workspace(
    mech: Mechanism,
    over: Mapping[str, Sequence[float] | tuple[float, float, int]],
    *,
    at: Mapping[str, float] | None = None,
    task: TaskCoordinates | None = None,
    limits: WorkspaceLimits | None = None,
    tol: Mapping[str, float] | float | None = None,
    seed: Configuration | None = None,
    max_cells: int | None = None,
    progress: Progress | None = None,
) -> TaskWorkspaceResult:
    """Workspace of ``mech`` over its task coordinates (see the module docstring).

    ``over``: 1 to 3 given task coordinates -> ``(lo, hi, n)`` or increasing grid values (SI,
    rad); ``at``: the other given coordinates held (default: their reference value); ``task``:
    which coordinates are given (default: the model's, else the default task; a grid and ``at``
    that name exactly ``M`` coordinates make those the given ones).  ``limits``: default
    :func:`.limits.default_limits` (the model's freedom limits).  ``tol``: boundary tolerance
    (one number for every grid coordinate, or by name; default 1e-3 of the grid step).
    ``progress(done, total, message)``: the solves of the grid, then of the boundary.

    >>> import numpy as np
    >>> from spatialmech.catalog import build
    >>> ws = task_workspace(build("three-rps"), {"a2": (-0.2, 0.2, 5), "a3": (-0.2, 0.2, 5)}, at={"z": 0.33})
    >>> ws.solved, ws.reachable_fraction, ws.extents["a2"].hi_limit
    (('x', 'y', 'a1'), 1.0, 'box')
    """
    t0 = time.perf_counter()
    axes = _parse_over(over)
    limits = default_limits(mech) if limits is None else limits
    checker = configuration_checker(mech, limits)
    progress = check_progress(progress)
    g = solve_task_grid(mech, cast(Mapping[str, Sequence[float]], axes), at=at, task=task, seed=seed,
                        max_cells=max_cells, progress=progress)
    names, grid, d = g.over, g.axes, len(g.over)
    stepv = np.array([float(np.diff(a).mean()) if a.size > 1 else 1.0 for a in grid])
    tolv = _tolerances(tol, names, stepv)

    probe = _Probe(mech, g, checker)
    cell_limits, cell_margins = _cell_limits(probe, g)
    feasible = g.converged & (cell_limits == "")
    b = _refine_boundary(probe, g, feasible, cell_limits, cell_margins, stepv, tolv, progress)

    # ---- extents of the grid coordinates, ranges of every coordinate
    bp = np.array(b.points).reshape(-1, d)
    bv = np.array(b.values).reshape(-1, 6)
    ba = np.array(b.axes, dtype=int)
    extents = _extents(g, feasible, bp, ba, b.limits)
    reach_vals = np.concatenate([g.values[feasible].reshape(-1, 6), bv])
    ranges = {c: (None if reach_vals.shape[0] == 0 else (float(np.min(reach_vals[:, i])), float(np.max(reach_vals[:, i]))))
              for i, c in enumerate(TASK_NAMES)}

    volume, volume_err = _measure(g, feasible, b.refined_axis0, float(tolv[0]))
    units = {task_unit(c) for c in names}
    if len(units) == 1:
        u = "rad" if units.pop() == "deg" else mech.length_unit
        volume_unit = u if d == 1 else f"{u}^{d}"
        vol: float | None = float(volume)
    else:
        volume_unit, vol = "", None
    return TaskWorkspaceResult(
        mechanism=mech.name, euler=g.task.euler, given=g.given, solved=g.solved, over=names, fixed=dict(g.fixed),
        grid=grid, converged=g.converged, feasible=feasible, cell_limits=cell_limits, values=g.values,
        extents=extents, ranges=ranges, volume=vol, volume_unit=volume_unit, boundary_points=bp,
        boundary_values=bv, boundary_limits=tuple(b.limits), boundary_configs=tuple(b.configs), boundary_axes=ba,
        boundary_outside=np.array(b.outside).reshape(-1, d),
        step={c: float(s) for c, s in zip(names, stepv, strict=True)},
        tol={c: float(t) for c, t in zip(names, tolv, strict=True)}, n_solves=g.n_solves + probe.n,
        seconds=time.perf_counter() - t0, limits=checker.limits, limit_names=checker.names, configs=g.configs,
        length_unit=mech.length_unit, volume_error=None if vol is None else float(volume_err),
    )


def _tolerances(tol, names: tuple[str, ...], stepv: np.ndarray) -> np.ndarray:
    """The boundary tolerance of each grid coordinate from :func:`task_workspace`'s ``tol``."""
    if tol is None:
        tolv = 1e-3 * stepv
    elif isinstance(tol, Mapping):
        for c in tol:
            if c not in names:
                raise InputError(f"tol.{c}: {c} is not a grid coordinate ({', '.join(names)})")
        tolv = np.array([float(as_finite_array(tol.get(c, 1e-3 * s), f"tol.{c}", shape=()))
                         for c, s in zip(names, stepv, strict=True)])
    else:
        tolv = np.full(len(names), float(as_finite_array(tol, "tol", shape=())))
    if np.any(tolv <= 0):
        raise InputError(f"tol: must be positive, got {tol!r}")
    return tolv


def _cell_limits(probe: _Probe, g: TaskGrid) -> tuple[np.ndarray, dict[tuple, np.ndarray]]:
    """The most violated limit of every grid cell (``"closure"`` where it does not close) and
    the scaled margins of every closed cell."""
    cell_limits = np.full(g.shape, CLOSURE, dtype=object)
    cell_margins: dict[tuple, np.ndarray] = {}
    cells = list(zip(*np.nonzero(g.converged), strict=True))
    checker = probe.checker
    if checker.names and cells:
        scaled = checker.margins_many([g.configs[idx] for idx in cells]) / checker.scales
    else:
        scaled = np.zeros((len(cells), 0))
    for idx, m in zip(cells, scaled, strict=True):
        cell_margins[idx] = m
        cell_limits[idx] = probe.limit(m)
    return cell_limits, cell_margins


def _boundary_pairs(feasible: np.ndarray) -> list[tuple[int, tuple[int, ...], tuple[int, ...]]]:
    """``(k, i0, i1)`` for every pair of neighbours along grid coordinate ``k`` with one
    reachable cell and one unreachable."""
    d = feasible.ndim
    pairs: list[tuple[int, tuple[int, ...], tuple[int, ...]]] = []
    for k in range(d):
        a = [slice(None)] * d
        b = [slice(None)] * d
        a[k], b[k] = slice(0, -1), slice(1, None)
        change = feasible[tuple(a)] != feasible[tuple(b)]
        for idx in zip(*np.nonzero(change), strict=True):
            i0 = tuple(int(i) for i in idx)
            i1 = tuple(i + 1 if j == k else i for j, i in enumerate(i0))
            pairs.append((k, i0, i1))
    return pairs


@dataclass
class _Boundary:
    """The refined boundary points (:func:`_refine_boundary`), one entry each: the last inside
    point (grid coordinates), its six coordinates, the limit broken just outside, its closed
    configuration, the grid coordinate it was refined along and the last outside point.
    ``refined_axis0``: ``(cell index of the inside end, +-1 towards the outside) -> refined
    first grid coordinate``, for the pairs along the first grid coordinate."""

    points: list[np.ndarray] = field(default_factory=list)
    values: list[np.ndarray] = field(default_factory=list)
    limits: list[str] = field(default_factory=list)
    configs: list[Configuration] = field(default_factory=list)
    axes: list[int] = field(default_factory=list)
    outside: list[np.ndarray] = field(default_factory=list)
    refined_axis0: dict[tuple, float] = field(default_factory=dict)


def _refine_boundary(probe: _Probe, g: TaskGrid, feasible: np.ndarray, cell_limits: np.ndarray,
                     cell_margins: dict[tuple, np.ndarray], stepv: np.ndarray, tolv: np.ndarray,
                     progress: Progress) -> _Boundary:
    """Every reachable / unreachable pair of grid neighbours bracketed to ``tolv`` (:func:`_bracket`)."""
    pairs = _boundary_pairs(feasible)
    n_iter = int(np.ceil(np.log2(max(float(np.max(stepv / tolv)), 2.0))))
    total = g.n_solves + len(pairs) * n_iter
    out = _Boundary()
    for n, (k, i0, i1) in enumerate(pairs):
        inside, outside = (i0, i1) if feasible[i0] else (i1, i0)
        c0: Configuration = g.configs[inside]
        x_in, c_in, v_in, x_out, lim = _bracket(probe, k, g.point(inside), c0, g.values[inside],
                                                cell_margins[inside], g.point(outside), cell_margins.get(outside),
                                                str(cell_limits[outside]), float(tolv[k]))
        out.points.append(x_in)
        out.values.append(v_in)
        out.limits.append(lim)
        out.configs.append(c_in)
        out.axes.append(k)
        out.outside.append(x_out)
        if k == 0:
            out.refined_axis0[(inside, outside[0] - inside[0])] = float(x_in[0])
        progress(g.n_solves + (n + 1) * n_iter, total, "refining the boundary")
    return out


def _extents(g: TaskGrid, feasible: np.ndarray, bp: np.ndarray, ba: np.ndarray,
             blims: list[str]) -> dict[str, Extent | None]:
    """``[lo, hi]`` of each grid coordinate over the reachable cells and the refined boundary
    points ``bp`` (refined along grid coordinate ``ba``, limits ``blims``), with the limit met at
    each end; ``None`` when no cell is reachable."""
    cells = np.array([g.point(idx) for idx in zip(*np.nonzero(feasible), strict=True)]).reshape(-1, len(g.over))
    cell_idx = np.argwhere(feasible)
    extents: dict[str, Extent | None] = {}
    for k, c in enumerate(g.over):
        if cells.shape[0] == 0:
            extents[c] = None
            continue
        lo, lo_limit = _extent_end(g, k, -1.0, cells, cell_idx, bp, ba, blims)
        hi, hi_limit = _extent_end(g, k, 1.0, cells, cell_idx, bp, ba, blims)
        extents[c] = Extent(lo, hi, lo_limit, hi_limit)
    return extents


def _extent_end(g: TaskGrid, k: int, sign: float, cells: np.ndarray, cell_idx: np.ndarray, bp: np.ndarray,
                ba: np.ndarray, blims: list[str]) -> tuple[float, str]:
    """The lower (``sign < 0``) or upper end of grid coordinate ``k`` over the reachable set and
    the limit met there: a refined boundary point's, ``"box"`` at the grid's own bound, ``"?"``
    when neither explains it."""
    best_cell = cells[:, k].min() if sign < 0 else cells[:, k].max()
    best, lim = float(best_cell), BOX
    along = np.flatnonzero(ba == k)  # boundary points refined along this coordinate
    if along.size:
        j = int(along[_first_least(sign * -bp[along, k])])
        if sign * (bp[j, k] - best) >= 0:
            best, lim = float(bp[j, k]), blims[j]
    if lim == BOX:
        edge = 0 if sign < 0 else g.shape[k] - 1
        on_edge = np.any(cell_idx[:, k] == edge) and abs(best - g.axes[k][edge]) == 0.0
        lim = BOX if on_edge else "?"
    return best, lim


def _measure(g: TaskGrid, feasible: np.ndarray, refined_axis0: dict[tuple, float],
             tol0: float) -> tuple[float, float]:
    """The measure of the reachable set in the grid coordinates and its error estimate: refined
    run lengths along the first grid coordinate, trapezoid rule over the others; the error as
    the grid workspaces' (:func:`.search.volume_error`: ``|V_h - V_2h|`` over every second
    grid line, plus ``tol0`` at every run end)."""
    grid, shape = g.axes, g.shape
    x = grid[0]
    lines, lengths = [], []
    for other in np.ndindex(*shape[1:]):
        row = feasible[(slice(None), *other)]
        i = 0
        while i < shape[0]:
            if not row[i]:
                i += 1
                continue
            j = i
            while j + 1 < shape[0] and row[j + 1]:
                j += 1
            lo = refined_axis0.get(((i, *other), -1))
            hi = refined_axis0.get(((j, *other), 1))
            lines.append(other)
            lengths.append((x[j] if hi is None else hi) - (x[i] if lo is None else lo))
            i = j + 1
    if not lengths:
        return 0.0, 0.0
    L = np.array(lines, dtype=int).reshape(len(lengths), len(shape) - 1)
    runs = np.array(lengths, dtype=float)
    w = np.ones(runs.size)
    for j, a in enumerate(grid[1:]):
        w *= trapezoid_weights(a)[L[:, j]]
    return float(np.sum(w * runs)), volume_error(grid, L, runs, 0, tol0)
