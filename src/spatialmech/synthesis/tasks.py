"""Task positions for rigid-body guidance synthesis: orientations plus a point.

A task is ``n`` positions of a moving body (the coupler to be guided), each an orientation
``R_i`` (3x3, body frame in world coordinates) and a point ``p_i`` (the body's reference point,
in the task's length unit).  Orientations can be given

- with McCarthy's longitude/latitude/azimuth (paper D, table 1)::

      R = Rz(longitude) Ry(-latitude) Rx(azimuth)

  (the only orientation convention of paper D; checked numerically in the spec's
  ``conventions.md``);
- with any *named* Euler sequence of :func:`spatialmech.geometry.rotations.euler_matrix`
  (``"ZXY"`` intrinsic, ``"zxy"`` extrinsic, as in ``scipy.spatial.transform``);
- as a rotation matrix.

Relative displacements (world frame) from position 1 to position ``j+1``::

    C_j = R_{j+1} R_1^T,        d_j = p_{j+1} - C_j p_1,        x -> C_j x + d_j

Inside the library angles are radians; degrees appear only in files and in the ``*_deg``
arguments/keys, which say so.

Task file (TOML), one of ``mccarthy_deg`` / ``euler`` / ``matrix`` per position::

    name = "my-task"
    length_unit = "mm"
    [[positions]]
    point = [0, 0, 0]
    mccarthy_deg = { longitude = 90, latitude = 0, azimuth = 15 }
    [[positions]]
    point = [-23, 8, 13]
    euler = { seq = "ZYX", angles_deg = [40, -45, 20] }
    [[positions]]
    point = [1, 2, 3]
    matrix = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any

import numpy as np
from annotated_types import Len
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from ..errors import InputError, UnknownNameError
from ..geometry.rotations import check_sequence, euler_matrix, rotation_angle, transform
from ..geometry.validate import as_finite_array

__all__ = [
    "MCCARTHY",
    "TASKS",
    "TaskPositions",
    "get_task",
    "load_task",
    "loads_task",
    "mccarthy_matrix",
    "resolve_task",
    "task_from_dict",
    "task_names",
]

#: The orientation convention of paper D, stated in words (used in reports and files).
MCCARTHY = "McCarthy: R = Rz(longitude) Ry(-latitude) Rx(azimuth)"

#: Orthonormality tolerance on ``R R^T - I`` for matrices given by the user.
ORTHO_ATOL = 1e-6
#: Two positions closer than this (rotation angle in rad, and distance / task scale) are identical.
IDENTICAL_RTOL = 1e-9


def mccarthy_matrix(longitude, latitude, azimuth, *, degrees: bool = False) -> np.ndarray:
    """McCarthy's orientation ``R = Rz(longitude) Ry(-latitude) Rx(azimuth)`` (stacks allowed).

    Paper D, table 1 gives (azimuth delta, longitude alpha, latitude beta) per position.
    Worked example: longitude 90 deg, latitude 0, azimuth 0 is a quarter turn about z::

        >>> np.round(mccarthy_matrix(90, 0, 0, degrees=True), 12) + 0.0
        array([[ 0., -1.,  0.],
               [ 1.,  0.,  0.],
               [ 0.,  0.,  1.]])
    """
    lon = np.asarray(as_finite_array(longitude, "longitude"), dtype=float)
    lat = np.asarray(as_finite_array(latitude, "latitude"), dtype=float)
    az = np.asarray(as_finite_array(azimuth, "azimuth"), dtype=float)
    angles = np.stack(np.broadcast_arrays(lon, -lat, az), axis=-1)
    return euler_matrix("ZYX", angles, degrees=degrees)


def _check_rotation(R: np.ndarray, name: str) -> np.ndarray:
    R = as_finite_array(R, name, shape=(3, 3))
    err = float(np.max(np.abs(R @ R.T - np.eye(3))))
    if err > ORTHO_ATOL:
        raise InputError(f"{name}: not orthonormal (max |R R^T - I| = {err:.3g})")
    if np.linalg.det(R) < 0:
        raise InputError(f"{name}: a reflection (det = -1), not a rotation")
    return R


@dataclass(frozen=True, eq=False)
class TaskPositions:
    """Validated task positions: orientations ``R`` (n, 3, 3) and points ``p`` (n, 3).

    ``convention`` records how the orientations were given (e.g. :data:`MCCARTHY`), and
    ``angles_deg`` the angles as given (or ``None`` for matrices), for reports.
    """

    R: np.ndarray
    p: np.ndarray
    name: str = "task"
    names: tuple[str, ...] = ()
    convention: str = "matrix"
    angles_deg: np.ndarray | None = None
    length_unit: str = "m"
    description: str = ""
    source: str = ""
    min_positions: int = field(default=2, repr=False)

    def __post_init__(self):
        R = as_finite_array(self.R, "positions.R")
        p = as_finite_array(self.p, "positions.p")
        if R.ndim != 3 or R.shape[1:] != (3, 3):
            raise InputError(f"positions.R: expected shape (n, 3, 3), got {R.shape}")
        if p.shape != (R.shape[0], 3):
            raise InputError(f"positions.p: expected shape ({R.shape[0]}, 3), got {p.shape}")
        n = R.shape[0]
        if n < self.min_positions:
            raise InputError(f"positions: need at least {self.min_positions} positions, got {n}")
        for i in range(n):
            _check_rotation(R[i], f"positions[{i}].matrix")
        names = tuple(self.names) or tuple(str(i + 1) for i in range(n))
        if len(names) != n:
            raise InputError(f"positions.names: expected {n} names, got {len(names)}")
        scale = max(1.0, float(np.max(np.linalg.norm(p - p.mean(axis=0), axis=1))))
        for i in range(n):
            for k in range(i):
                ang = float(rotation_angle(R[i] @ R[k].T))
                dist = float(np.linalg.norm(p[i] - p[k]))
                if ang < IDENTICAL_RTOL and dist < IDENTICAL_RTOL * scale:
                    raise InputError(
                        f"positions[{i}]: identical to positions[{k}] (same orientation and point)"
                    )
        object.__setattr__(self, "R", R)
        object.__setattr__(self, "p", p)
        object.__setattr__(self, "names", names)

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_mccarthy(cls, longitude, latitude, azimuth, points, *, degrees: bool = False, **kw):
        """Positions from McCarthy angles (arrays of length n) and points (n, 3)."""
        lon = as_finite_array(longitude, "longitude")
        lat = as_finite_array(latitude, "latitude")
        az = as_finite_array(azimuth, "azimuth")
        if not (lon.shape == lat.shape == az.shape) or lon.ndim != 1:
            raise InputError(
                f"longitude: longitude, latitude and azimuth must be 1-D of equal length,"
                f" got {lon.shape}, {lat.shape}, {az.shape}"
            )
        R = mccarthy_matrix(lon, lat, az, degrees=degrees)
        deg = np.stack([lon, lat, az], -1) * (1.0 if degrees else 180.0 / np.pi)
        kw.setdefault("convention", MCCARTHY + " (angles_deg columns: longitude, latitude, azimuth)")
        return cls(R, points, angles_deg=deg, **kw)

    @classmethod
    def from_euler(cls, seq: str, angles, points, *, degrees: bool = False, **kw):
        """Positions from Euler angles (n, 3) in the explicitly named sequence ``seq``."""
        check_sequence(seq)
        a = as_finite_array(angles, "angles")
        if a.ndim != 2 or a.shape[1] != 3:
            raise InputError(f"angles: expected shape (n, 3), got {a.shape}")
        R = euler_matrix(seq, a, degrees=degrees)
        deg = a * (1.0 if degrees else 180.0 / np.pi)
        kw.setdefault("convention", f"Euler {seq!r} ({'intrinsic' if seq.isupper() else 'extrinsic'}, scipy)")
        return cls(R, points, angles_deg=deg, **kw)

    @classmethod
    def from_matrices(cls, R, points, **kw):
        """Positions from rotation matrices (n, 3, 3) and points (n, 3)."""
        kw.setdefault("convention", "matrix")
        return cls(R, points, **kw)

    # ------------------------------------------------------------------ derived
    @property
    def n(self) -> int:
        return int(self.R.shape[0])

    @property
    def C(self) -> np.ndarray:
        """Relative rotations ``C_j = R_{j+1} R_1^T`` (n-1, 3, 3), world frame."""
        return self.R[1:] @ self.R[0].T

    @property
    def d(self) -> np.ndarray:
        """Relative translations ``d_j = p_{j+1} - C_j p_1`` (n-1, 3)."""
        return self.p[1:] - self.C @ self.p[0]

    def displacements(self) -> np.ndarray:
        """4x4 displacements (n, 4, 4) of the body from position 1 (the first is the identity)."""
        C = np.concatenate([np.eye(3)[None], self.C])
        d = np.concatenate([np.zeros((1, 3)), self.d])
        return transform(C, d)

    @property
    def length_scale(self) -> float:
        """A characteristic length: the largest distance of a task point from their centroid
        (1 when all points coincide)."""
        s = float(np.max(np.linalg.norm(self.p - self.p.mean(axis=0), axis=1)))
        return s if s > 1e-12 else 1.0

    def subset(self, indices) -> TaskPositions:
        """A task made of some of the positions (e.g. three of four), in the given order."""
        idx = list(indices)
        return TaskPositions(
            self.R[idx], self.p[idx], name=f"{self.name}[{','.join(self.names[i] for i in idx)}]",
            names=tuple(self.names[i] for i in idx), convention=self.convention,
            angles_deg=None if self.angles_deg is None else self.angles_deg[idx],
            length_unit=self.length_unit, description=self.description, source=self.source,
        )

    def require(self, n: int, what: str) -> TaskPositions:
        """Raise ``ValueError`` unless the task has exactly ``n`` positions."""
        if self.n != n:
            raise InputError(f"positions: {what} needs exactly {n} positions, got {self.n}")
        return self

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "length_unit": self.length_unit,
            "convention": self.convention,
            "positions": [
                {
                    "name": self.names[i],
                    "point_len": self.p[i].tolist(),
                    "rotation_matrix": self.R[i].tolist(),
                    **({"angles_deg": self.angles_deg[i].tolist()} if self.angles_deg is not None else {}),
                }
                for i in range(self.n)
            ],
        }


# ---------------------------------------------------------------------------- file format
Vec3 = Annotated[list[float], Len(3, 3)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class _McCarthy(_Strict):
    longitude: float
    latitude: float
    azimuth: float


class _Euler(_Strict):
    seq: str
    angles_deg: Vec3


class _Position(_Strict):
    name: str = ""
    point: Vec3
    mccarthy_deg: _McCarthy | None = None
    euler: _Euler | None = None
    matrix: Annotated[list[Vec3], Len(3, 3)] | None = None


class _Task(_Strict):
    name: str = "task"
    description: str = ""
    source: str = ""
    length_unit: str = "m"
    positions: list[_Position] = Field(default_factory=list)


def _loc(loc) -> str:
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else ("." if out else "") + str(part)
    return out


def task_from_dict(data: dict[str, Any], *, source: str = "<dict>", min_positions: int = 2) -> TaskPositions:
    """Validate a parsed task file (a dict); errors are ``ValueError`` naming the field."""
    try:
        spec = _Task.model_validate(data)
    except ValidationError as e:
        err = e.errors()[0]
        msg = {"extra_forbidden": "unknown field", "missing": "required field is missing"}.get(err["type"], err["msg"])
        raise InputError(f"{_loc(err['loc'])}: {msg}") from None
    Rs, ps, names, convs = [], [], [], []
    angs: list[list[float] | None] = []  # the angles as given (None: a matrix)
    for i, ps_ in enumerate(spec.positions):
        where = f"positions[{i}]"
        given = [k for k in ("mccarthy_deg", "euler", "matrix") if getattr(ps_, k) is not None]
        if len(given) != 1:
            raise InputError(f"{where}: give exactly one of 'mccarthy_deg', 'euler' or 'matrix' (got {given or 'none'})")
        if ps_.mccarthy_deg is not None:
            m = ps_.mccarthy_deg
            Rs.append(mccarthy_matrix(m.longitude, m.latitude, m.azimuth, degrees=True))
            convs.append(MCCARTHY + " (angles_deg columns: longitude, latitude, azimuth)")
            angs.append([m.longitude, m.latitude, m.azimuth])
        elif ps_.euler is not None:
            try:
                check_sequence(ps_.euler.seq)
            except ValueError as e:
                raise InputError(f"{where}.euler.{e}") from None
            Rs.append(euler_matrix(ps_.euler.seq, ps_.euler.angles_deg, degrees=True))
            convs.append(f"Euler {ps_.euler.seq!r} (scipy: upper case intrinsic, lower case extrinsic)")
            angs.append(list(ps_.euler.angles_deg))
        else:
            Rs.append(_check_rotation(np.array(ps_.matrix, dtype=float), f"{where}.matrix"))
            convs.append("matrix")
            angs.append(None)
        ps.append(ps_.point)
        names.append(ps_.name or str(i + 1))
    if len(spec.positions) < min_positions:
        raise InputError(f"positions: need at least {min_positions} positions, got {len(spec.positions)}")
    same = len(set(convs)) == 1 and bool(angs) and angs[0] is not None
    return TaskPositions(
        np.array(Rs), np.array(ps, dtype=float), name=spec.name, names=tuple(names),
        convention=convs[0] if len(set(convs)) == 1 else "mixed (see each position)" if convs else "none",
        angles_deg=np.array(angs, dtype=float) if same else None,
        length_unit=spec.length_unit, description=spec.description, source=spec.source or source,
        min_positions=min_positions,
    )


def loads_task(text: str, *, source: str = "<string>", min_positions: int = 2) -> TaskPositions:
    """Parse a TOML task."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(f"not valid TOML: {e}") from None
    return task_from_dict(data, source=source, min_positions=min_positions)


def load_task(path: str | Path, *, min_positions: int = 2) -> TaskPositions:
    """Read a TOML task file; errors are ``ValueError`` prefixed with the file name."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise InputError(f"{path}: cannot read: {e.strerror}") from None
    try:
        return loads_task(text, source=str(path), min_positions=min_positions)
    except ValueError as e:
        raise InputError(f"{path}: {e}") from None


# ---------------------------------------------------------------------------- ready-made tasks
def _paper_d_table1() -> TaskPositions:
    """Paper D, table 1: (azimuth delta, longitude alpha, latitude beta) in degrees and p."""
    delta = [15.0, 20.0, 25.0, 30.0]
    alpha = [90.0, 40.0, 35.0, 40.0]
    beta = [0.0, 45.0, 25.0, 5.0]
    p = [[0, 0, 0], [-23, 8, 13], [-42, 9, 13], [-55, -3, 1]]
    return TaskPositions.from_mccarthy(
        alpha, beta, delta, p, degrees=True, name="rccc-four-positions",
        description="Paper D (Cao & Han), table 1: four spatial positions for RCCC synthesis",
        length_unit="mm",
        source="paper D table 1 (no length unit printed; mm assumed)",
    )


#: name -> (builder, one-line description)
TASKS = {
    "rccc-four-positions": (_paper_d_table1, "Paper D table 1: four positions (McCarthy angles + points)"),
}


def task_names() -> list[str]:
    return list(TASKS)


def get_task(name: str) -> TaskPositions:
    """A ready-made task by name (``KeyError`` listing the known names otherwise)."""
    try:
        return TASKS[name][0]()
    except KeyError:
        raise UnknownNameError(f"unknown ready-made task {name!r}; known: {', '.join(TASKS)}") from None


def resolve_task(spec, *, min_positions: int = 2) -> TaskPositions:
    """A task from a ready-made name, a TOML file path, or a :class:`TaskPositions`."""
    if isinstance(spec, TaskPositions):
        return spec
    s = str(spec)
    if s in TASKS:
        return get_task(s)
    p = Path(s)
    if p.exists():
        return load_task(p, min_positions=min_positions)
    raise UnknownNameError(f"{s}: not a file and not a ready-made task (ready-made: {', '.join(TASKS)})")
