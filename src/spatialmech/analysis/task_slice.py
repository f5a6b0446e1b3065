"""Singularity slices over the task coordinates of a lower-mobility mechanism (issue 11).

:func:`~spatialmech.analysis.singularity.singularity_slice` poses the platform with all six
coordinates; a 3-RPS reaches almost none of those poses (its parasitic ``x, y`` and yaw follow
from the closure), so a slice of it came back empty.  :func:`task_singularity_slice` sweeps two
*given* task coordinates instead, the other given ones held, and solves the parasitic ones at
every grid point by continuation (:func:`~spatialmech.kinematics.task_grid.solve_task_grid`);
``det J`` and the scale-free ``sigma_min`` of the complete Jacobian are evaluated at the closed
configurations.  Each Jacobian takes its neighbour's as the reference of its constraint-wrench
bases, and the orientation of those bases is carried from neighbour to neighbour (the constraint
rows of a mechanism with internal bodies, e.g. the Delta, are an orthonormal basis of arbitrary
orientation at each configuration), so the sign of ``det J`` is comparable across the slice: the
singularity loci are its zero contours.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from ..errors import InputError
from ..kinematics.closure import Configuration
from ..kinematics.jacobian import complete_jacobian
from ..kinematics.task_grid import TASK_NAMES, edge_value, solve_task_grid, task_unit
from ..model.mechanism import Mechanism
from ..model.task import TaskCoordinates
from ..results import Progress
from .singularity import SliceResult
from .workspace.task import euler_convention

__all__ = ["TaskSliceResult", "row_orientation", "task_singularity_slice"]


@dataclass(frozen=True, eq=False)
class TaskSliceResult(SliceResult):
    """A :class:`~spatialmech.analysis.singularity.SliceResult` over task coordinates.

    ``u``, ``v``: the two swept task coordinates (SI and radians, ``units`` says which: ``"rad"``
    or the length unit; :meth:`for_display` gives degrees); ``det`` / ``sigma_min``
    (len(v), len(u)), NaN where the task coordinates do not close; ``values`` (len(v), len(u), 6):
    the six coordinates ``x, y, z, a1, a2, a3`` there (the parasitic ones solved); ``held``: the
    other given coordinates; ``euler``: the named sequence of ``a1, a2, a3``.
    """

    euler: str = "ZYX"
    given: tuple[str, ...] = ()
    solved: tuple[str, ...] = ()
    held: dict = field(default_factory=dict)
    values: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 6)))
    n_solves: int = 0
    seconds: float = 0.0
    configs: np.ndarray = field(default_factory=lambda: np.empty((0, 0), dtype=object))

    def _base_dict(self) -> dict:
        return super().to_dict()

    def config_at(self, j: int, i: int) -> Configuration | None:
        """The closed configuration at ``(v[j], u[i])`` (``None`` where it does not close)."""
        return self.configs[j, i]

    def for_display(self) -> TaskSliceResult:
        """The same slice with angle axes in degrees (``units`` ``"deg"``), for figures."""
        conv = [(np.round(np.degrees(a), 12) + 0.0, "deg") if u == "rad" else (a, u)
                for a, u in zip((self.u, self.v), self.units, strict=True)]
        return replace(self, u=conv[0][0], v=conv[1][0], units=(conv[0][1], conv[1][1]))

    def to_dict(self) -> dict:
        """JSON (docs/json.md): ``axes`` (``values_deg`` / ``values_len``), ``det``, ``sign``,
        ``sigma_min`` (rows along v, ``null`` where the task coordinates do not close),
        ``fixed`` (the held coordinates, ``z_len`` ...), ``given``, ``solved`` and
        ``solved_values`` (the parasitic coordinates per grid point, ``x_len``, ``a1_deg`` ...)."""
        base = self.for_display()._base_dict()

        def conv(c: str, a: np.ndarray):
            a = np.degrees(a) if task_unit(c) == "deg" else a
            return [[None if not np.isfinite(x) else float(x) for x in row] for row in a]

        def key(c: str) -> str:
            return f"{c}_{task_unit(c)}"

        base["fixed"] = {key(c): edge_value(c, v) for c, v in self.held.items()}
        base.update({
            "euler_sequence": self.euler,
            "orientation_convention": euler_convention(self.euler),
            "given": list(self.given),
            "solved": list(self.solved),
            "solved_values": {key(c): conv(c, self.values[..., TASK_NAMES.index(c)]) for c in self.solved},
            "n_grid": int(self.det.size),
            "n_grid_converged": int(np.count_nonzero(np.isfinite(self.sigma_min))),
            "n_poses_checked": self.n_solves,
            "elapsed_s": self.seconds,
        })
        return base


def row_orientation(J, ref) -> float:
    """+1 when the constraint rows of ``J`` are oriented as those of the neighbouring ``ref``,
    -1 when they are the opposite orientation of the same (nearly the same) space: the sign
    ``det J`` must be multiplied by to be continuous across the slice.  The constraint wrenches
    of a mechanism with internal bodies are an orthonormal basis whose orientation is arbitrary
    at each configuration; a limb's single constraint wrench (cofactors) or a basis referenced
    to its neighbour's already keeps its orientation, and this gives +1."""
    c = J.constraint_rows
    if ref is None or c == 0 or ref.constraint_rows != c:
        return 1.0
    return 1.0 if np.linalg.det(J.constraints @ ref.constraints.T) >= 0.0 else -1.0


def task_singularity_slice(
    mech: Mechanism,
    over: Mapping[str, Sequence[float]],
    *,
    at: Mapping[str, float] | None = None,
    task: TaskCoordinates | None = None,
    actuators=None,
    seed: Configuration | None = None,
    progress: Progress | None = None,
) -> TaskSliceResult:
    """``det J`` and the scale-free ``sigma_min`` over two task coordinates.

    ``over``: two given task coordinates -> increasing values (SI, rad): the first is ``u``
    (columns), the second ``v`` (rows); ``at``: other given coordinates held (default: their
    reference value); ``task``, ``seed`` as in
    :func:`~spatialmech.kinematics.task_grid.solve_task_grid`; ``actuators``: the drivers
    (default: the model's).  ``progress(done, total, message)`` after each solve.

    >>> import numpy as np
    >>> from spatialmech.catalog import build
    >>> s = task_singularity_slice(build("three-rps"), {"a2": np.radians([-10, 0, 10]),
    ...                            "a3": np.radians([-10, 0, 10])}, at={"z": 0.33})
    >>> s.solved, bool(np.all(s.sigma_min > 0))
    (('x', 'y', 'a1'), True)
    """
    if not isinstance(over, Mapping) or len(over) != 2:
        raise InputError(f"over: expected two task coordinates -> values, got {over!r}")
    g = solve_task_grid(mech, over, at=at, task=task, seed=seed, progress=progress)
    nu, nv = g.shape
    det = np.full((nv, nu), np.nan)
    sig = np.full((nv, nu), np.nan)
    jac = np.empty((nu, nv), dtype=object)
    orient = np.ones((nu, nv))
    # rows of the grid in order, each Jacobian referenced to a neighbour's for continuous bases
    for i in range(nu):
        for j in range(nv):
            config = g.configs[i, j]
            if config is None:
                continue
            nb = (i, j - 1) if j > 0 and jac[i, j - 1] is not None else (i - 1, j) if i > 0 else None
            ref = jac[nb] if nb is not None else None
            J = complete_jacobian(mech, config, actuators, reference=ref)
            jac[i, j] = J
            orient[i, j] = (orient[nb] if nb is not None else 1.0) * row_orientation(J, ref)
            det[j, i] = orient[i, j] * J.det if J.det is not None else np.nan
            sig[j, i] = J.sigma_min
    u0, u1 = ("rad" if task_unit(c) == "deg" else mech.length_unit for c in g.over)
    return TaskSliceResult(
        names=(g.over[0], g.over[1]), u=g.axes[0], v=g.axes[1], det=det, sigma_min=sig, fixed={}, units=(u0, u1),
        euler=g.task.euler, given=g.given, solved=g.solved, held=dict(g.fixed),
        values=np.transpose(g.values, (1, 0, 2)), n_solves=g.n_solves, seconds=g.seconds, configs=g.configs.T,
    )
