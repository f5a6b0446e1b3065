"""The task coordinates of a lower-mobility mechanism solved over a grid, by continuation.

A mechanism whose output link has ``M < 6`` freedoms is posed by ``M`` *given* task coordinates;
the other ``6 - M`` (parasitic) ones are solved (:func:`spatialmech.kinematics.task.solve_task`).
Analyses over the task coordinates (the workspace, singularity slices) need that solve at every
point of a grid of one to three of the given coordinates (the others held at one value).
:func:`solve_task_grid` does it by continuation: each cell is solved by Newton from the solution
of a neighbouring cell that is already solved (a breadth-first sweep from the cell nearest the
seed's own task values), so one short Newton solve per cell, on the seed's assembly branch.  A
cell that fails from one neighbour is tried again from another; cells that no sweep reaches (an
island beyond an unreachable band) are tried from the seed itself (``islands=True``).

Coordinates: ``x, y, z`` (the output link's reference point, the model's length unit) and
``a1, a2, a3`` (the Euler angles of the output orientation in the task's named sequence, rad).

    >>> import numpy as np
    >>> from spatialmech.catalog import build
    >>> g = solve_task_grid(build("three-rps"), {"a2": np.radians([-5, 0, 5]), "a3": np.radians([0, 5])},
    ...                     at={"z": 0.33})
    >>> g.converged.all(), g.solved
    (np.True_, ('x', 'y', 'a1'))
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ConvergenceError, InputError, SearchTooLargeError
from ..geometry.rotations import inverse_transform
from ..geometry.tolerances import current as current_tolerances
from ..geometry.validate import as_finite_array
from ..model.mechanism import Mechanism
from ..model.task import TASK_NAMES, TaskCoordinates
from ..results import Progress, check_progress
from . import backend
from .closure import Configuration
from .task import default_task, solve_task, task_values

__all__ = ["MAX_CELLS", "TASK_NAMES", "TaskGrid", "edge_value", "predict", "resolve_task", "solve_task_grid",
           "solve_task_point", "task_unit"]

#: Largest grid (cells) solved unless ``max_cells`` says otherwise.
MAX_CELLS = 40_000


def task_unit(name: str) -> str:
    """``"deg"`` for the angles ``a1, a2, a3`` (at the edges), ``"len"`` for ``x, y, z``."""
    return "deg" if name.startswith("a") else "len"


def edge_value(name: str, value: float) -> float:
    """A coordinate's value at the edges (JSON, text): degrees for an angle, rounded to 1e-12 deg
    so that a typed ``-30`` comes back as ``-30.0`` and not ``-29.999999999999996``; lengths as
    they are."""
    if task_unit(name) == "deg":
        return round(float(np.degrees(value)), 12) + 0.0
    return float(value)


def resolve_task(mech: Mechanism, names: Sequence[str], task: TaskCoordinates | None = None) -> TaskCoordinates:
    """The task coordinates under which ``names`` (the coordinates a caller gives: a grid's axes
    and its held values) are all given.

    ``task`` (else the model's own ``mech.task``, else :func:`default_task`) when it gives every
    name; otherwise, when there are exactly ``M`` names, those names themselves (same Euler
    sequence); otherwise an :class:`InputError` saying which names would be solved.
    """
    for n in names:  # the six coordinates, in the order of TaskGrid.values: x, y, z, a1, a2, a3
        if n not in TASK_NAMES:
            raise InputError(f"task coordinate {n!r}: expected one of {', '.join(TASK_NAMES)}")
    if len(set(names)) != len(names):
        raise InputError(f"task coordinates: {list(names)} repeats a name")
    explicit = task is not None
    if task is None:
        task = getattr(mech, "task", None) or default_task(mech)
    if not isinstance(task, TaskCoordinates):
        raise InputError(f"task: expected a TaskCoordinates, got {type(task).__name__}")
    given = tuple(task.given)
    if explicit:
        m = len(default_task(replace(mech, task=None)).given)
        if len(given) != m:
            raise InputError(f"task: {mech.name}'s output has {m} freedoms, so {m} coordinates are given and "
                             f"{6 - m} solved; this task gives {len(given)} ({', '.join(given)}) and solves "
                             f"{', '.join(task.solved) or 'none'}")
    if set(names) <= set(given):
        return task
    if not explicit and len(names) == len(given):
        return TaskCoordinates(given=tuple(n for n in TASK_NAMES if n in names), euler=task.euler)
    solved = [n for n in names if n not in given]
    raise InputError(f"task coordinates: {', '.join(solved)} {'is' if len(solved) == 1 else 'are'} solved "
                     f"(parasitic) for {mech.name}, whose task gives {', '.join(given)} ({len(given)} of 6); "
                     f"give only those, or name {len(given)} coordinates in all to make them the given ones")


def solve_task_point(mech: Mechanism, given: Mapping[str, float], task: TaskCoordinates,
                     seed: Configuration | None):
    """One solve: ``(config, values (6,), residual)``, ``config`` ``None`` when it did not converge."""
    try:
        res = solve_task(mech, given, task=task, seed=seed)
    except ConvergenceError as e:  # a solver that raises instead of returning a status
        return None, None, float(getattr(e, "residual", np.nan))
    if not res.converged:
        return None, None, float(res.residual)
    return res.config, np.array([float(res.values[n]) for n in TASK_NAMES]), float(res.residual)


@dataclass(frozen=True, eq=False)
class TaskGrid:
    """The task coordinates solved over a grid (:func:`solve_task_grid`).

    ``axes[k]``: the values of coordinate ``over[k]`` (SI, rad); ``fixed``: the other given
    coordinates, held; ``converged`` (grid shape): the solve closed; ``values`` (grid shape +
    (6,)): the six coordinates ``TASK_NAMES`` (NaN where not converged); ``configs``: the closed
    configurations (``None`` where not converged); ``residuals``: the solves' final residuals.
    """

    mechanism: Mechanism
    task: TaskCoordinates
    over: tuple[str, ...]
    axes: tuple[np.ndarray, ...]
    fixed: dict
    converged: np.ndarray
    values: np.ndarray
    configs: np.ndarray
    residuals: np.ndarray
    n_solves: int
    seconds: float

    @property
    def given(self) -> tuple[str, ...]:
        return tuple(self.task.given)

    @property
    def solved(self) -> tuple[str, ...]:
        return tuple(n for n in TASK_NAMES if n not in self.task.given)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(a.size for a in self.axes)

    def point(self, index) -> np.ndarray:
        """The grid coordinates (``over``) of cell ``index``."""
        return np.array([self.axes[k][i] for k, i in enumerate(index)])

    def given_at(self, x) -> dict[str, float]:
        """The given coordinates at grid-coordinate point ``x`` (``over`` order) with the held ones."""
        return {**self.fixed, **{c: float(v) for c, v in zip(self.over, x, strict=True)}}


def predict(cur: Configuration, prev: Configuration) -> Configuration:
    """Secant predictor on the closure manifold: one more step ``prev -> cur`` from ``cur``
    (joint variables extrapolated linearly, displacements by ``cur prev^-1 cur``)."""
    q = 2.0 * np.asarray(cur.q) - np.asarray(prev.q)
    Rt = prev.D[:3, :3].T
    inv = np.eye(4)  # prev.D^-1, written out (inverse_transform's stacks cost more than the step)
    inv[:3, :3] = Rt
    inv[:3, 3] = -(Rt @ prev.D[:3, 3])
    D = cur.D @ inv @ cur.D
    B = np.array([c @ inverse_transform(p) @ c for c, p in zip(cur.B, prev.B, strict=True)]) if len(cur.B) else cur.B
    return Configuration(q, D, B)


#: Largest distance of a length coordinate from its reference value, in characteristic lengths,
#: and largest angle (rad): beyond them the closure's squares and sines lose every digit.
MAX_DISTANCE = 1e6
MAX_ANGLE = 1e6


def _check_range(mech: Mechanism, values: Mapping, reference: Mapping[str, float]) -> None:
    L = mech.characteristic_length
    for c, v in values.items():
        a = np.asarray(v, dtype=float)
        where = "over" if a.ndim else "at"
        if task_unit(c) == "deg":
            if np.max(np.abs(a)) > MAX_ANGLE:
                raise InputError(f"{where}.{c}: an angle of {np.max(np.abs(a)):.3g} rad is out of range (at most {MAX_ANGLE:g})")
        elif np.max(np.abs(a - reference[c])) > MAX_DISTANCE * L:
            raise InputError(f"{where}.{c}: {float(np.max(np.abs(a - reference[c]))):.3g} from the reference is more than "
                             f"{MAX_DISTANCE:g} times the size of {mech.name} ({L:.3g}): out of range")


def _axes(over: Mapping[str, Sequence[float]]) -> tuple[tuple[str, ...], tuple[np.ndarray, ...]]:
    if not isinstance(over, Mapping) or not over:
        raise InputError("over: expected a mapping of task coordinate -> grid values (SI, rad), e.g. "
                         "{'a2': np.radians(np.linspace(-20, 20, 21))}")
    if len(over) > 3:
        raise InputError(f"over: at most three grid coordinates, got {list(over)}")
    names, axes = [], []
    for c, v in over.items():
        a = as_finite_array(v, f"over.{c}").reshape(-1)
        if a.size < 1:
            raise InputError(f"over.{c}: expected at least one value")
        if a.size > 1 and not np.all(np.diff(a) > 0):
            raise InputError(f"over.{c}: expected increasing values")
        names.append(str(c))
        axes.append(a.astype(float))
    return tuple(names), tuple(axes)


def solve_task_grid(
    mech: Mechanism,
    over: Mapping[str, Sequence[float]],
    *,
    at: Mapping[str, float] | None = None,
    task: TaskCoordinates | None = None,
    seed: Configuration | None = None,
    islands: bool = True,
    max_cells: int | None = None,
    progress: Progress | None = None,
) -> TaskGrid:
    """Solve the task coordinates at every cell of the grid ``over`` (1 to 3 given coordinates ->
    increasing values, SI / rad), the other given coordinates held at ``at`` (default: their
    value at ``seed``, i.e. the reference configuration).

    The task: :func:`resolve_task` of the names in ``over`` and ``at``.  The sweep starts at the
    cell nearest the seed's task values (in grid steps), solved from ``seed`` (default the
    reference configuration), and continues breadth-first, each cell from an already solved
    neighbour (from the secant prediction :func:`predict` first when the neighbour was itself
    reached along the same grid line); a cell that fails gets one more attempt from another
    neighbour.  ``islands``: cells no sweep reached are then tried from ``seed`` (each start of a
    new sweep); ``False`` stops after the first sweep.  ``progress(done, n_cells, "solving task
    coordinates")`` after each solve.  A grid larger than ``max_cells`` (default
    :data:`MAX_CELLS`) raises :class:`~spatialmech.errors.SearchTooLargeError`, coordinates
    out of the numerical range an :class:`~spatialmech.errors.InputError`, before any work.
    Non-convergence is not an error: ``converged`` is ``False`` there.
    """
    t0 = time.perf_counter()
    names, axes = _axes(over)
    held = _held(at, names)
    task = resolve_task(mech, [*names, *held], task)
    limit = MAX_CELLS if max_cells is None else int(max_cells)
    shape = tuple(a.size for a in axes)
    n_cells = int(np.prod(shape))
    if n_cells > limit:
        raise SearchTooLargeError(f"over: the grid has {n_cells} cells ({' x '.join(map(str, shape))}), more than "
                                  f"max_cells = {limit}; use fewer points per coordinate or raise max_cells to at least "
                                  f"{n_cells}")
    progress = check_progress(progress)
    seed = Configuration.reference(mech) if seed is None else seed
    v0 = task_values(mech, seed.D, task.euler)
    start_values = dict(zip(TASK_NAMES, (float(x) for x in v0), strict=True))
    fixed = {c: held.get(c, start_values[c]) for c in task.given if c not in names}
    _check_range(mech, {**dict(zip(names, axes, strict=True)), **fixed}, start_values)
    d = len(names)

    order, grid_idx = _start_order(names, axes, start_values)
    if (fast := backend.engine()) is not None:  # the same sweep, compiled
        return _compiled_grid(fast, mech, task, names, axes, fixed, order, seed, islands, progress, t0)

    converged = np.zeros(shape, dtype=bool)
    attempts = np.zeros(shape, dtype=np.int8)
    values = np.full((*shape, 6), np.nan)
    configs = np.empty(shape, dtype=object)
    residuals = np.full(shape, np.nan)
    n_solves = 0

    def given_of(idx) -> dict[str, float]:
        return {**fixed, **{c: float(axes[k][i]) for k, (c, i) in enumerate(zip(names, idx, strict=True))}}

    parents: dict[tuple, tuple] = {}

    def attempt(idx, seeds) -> bool:
        """Solve cell ``idx`` from the first seed that converges (one attempt of the cell)."""
        nonlocal n_solves
        attempts[idx] += 1
        for from_config in seeds:
            n_solves += 1
            config, vals, res = solve_task_point(mech, given_of(idx), task, from_config)
            residuals[idx] = res
            progress(n_solves, n_cells if n_solves <= n_cells else None, "solving task coordinates")
            if config is not None:
                converged[idx], values[idx], configs[idx] = True, vals, config
                return True
        return False

    def seeds_for(nb: tuple, cur: tuple) -> list[Configuration]:
        """The secant prediction from ``cur``'s own parent when the three cells are in a row,
        then ``cur``'s solution itself."""
        prev = parents.get(cur)
        if prev is not None and all(2 * c - p == n for c, p, n in zip(cur, prev, nb, strict=True)):
            return [predict(configs[cur], configs[prev]), configs[cur]]
        return [configs[cur]]

    found = False
    for flat in order:
        start = tuple(int(i) for i in grid_idx[flat])
        if attempts[start] > 0:
            continue  # reached by a sweep (solved, or failed from a neighbour: not an island)
        if found and not islands:
            break
        if not attempt(start, [seed]):
            continue
        found = True
        queue = deque([start])
        while queue:
            cur = queue.popleft()
            for k in range(d):
                for step in (-1, 1):
                    nb = list(cur)
                    nb[k] += step
                    if not 0 <= nb[k] < shape[k]:
                        continue
                    nbt = tuple(nb)
                    if converged[nbt] or attempts[nbt] >= 2:
                        continue  # a cell failed from one neighbour gets one more chance from another
                    if attempt(nbt, seeds_for(nbt, cur)):
                        parents[nbt] = cur
                        queue.append(nbt)
    return TaskGrid(mech, task, names, axes, fixed, converged, values, configs, residuals, n_solves,
                    time.perf_counter() - t0)


def _held(at: Mapping[str, float] | None, names: tuple[str, ...]) -> dict[str, float]:
    """The held coordinates ``at`` (SI, rad), checked: a mapping, finite values, none of them a
    grid coordinate."""
    at = {} if at is None else at
    if not isinstance(at, Mapping):
        raise InputError(f"at: expected a mapping of task coordinate -> value (SI, rad), got {type(at).__name__}")
    for c in at:
        if c in names:
            raise InputError(f"at.{c}: {c} is a grid coordinate (over); hold it or sweep it, not both")
    return {str(c): float(as_finite_array(v, f"at.{c}", shape=())) for c, v in at.items()}


def _start_order(names: tuple[str, ...], axes: tuple[np.ndarray, ...],
                 start_values: Mapping[str, float]) -> tuple[np.ndarray, np.ndarray]:
    """The cells (flat, C order) by distance in grid steps from the seed's task values (the
    first start, then the islands'), and every cell's multi-index."""
    centre = [float(np.interp(start_values[c], a, np.arange(a.size))) if a.size > 1 else 0.0
              for c, a in zip(names, axes, strict=True)]
    grid_idx = np.indices(tuple(a.size for a in axes)).reshape(len(axes), -1).T
    return np.argsort(np.sum((grid_idx - np.array(centre)) ** 2, axis=1), kind="stable"), grid_idx


def _compiled_grid(fast, mech: Mechanism, task: TaskCoordinates, names: tuple[str, ...], axes: tuple[np.ndarray, ...],
                   fixed: dict, order: np.ndarray, seed: Configuration, islands: bool, progress: Progress,
                   t0: float) -> TaskGrid:
    """:func:`solve_task_grid`'s sweep by the compiled engine (``fast``): the same cells, seeds
    and order, each solve :func:`.task.solve_task`'s steps."""
    shape = tuple(a.size for a in axes)
    conv, vals, q, D, B, res, n_solves = fast.task_grid(mech, task, names, axes, fixed, order, seed, islands,
                                                         current_tolerances().newton, 60, progress)
    configs = np.empty(len(conv), dtype=object)
    for i in np.flatnonzero(conv):
        configs[i] = Configuration.of(q[i], D[i], B[i])
    return TaskGrid(mech, task, names, axes, fixed, conv.reshape(shape), vals.reshape((*shape, 6)),
                    configs.reshape(shape), res.reshape(shape), n_solves, time.perf_counter() - t0)
