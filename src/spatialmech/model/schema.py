"""The mechanism file format (TOML), validated with pydantic; reader and writer.

Units in files: lengths in the file's length unit (``length_unit``, a label; SI metres by
default), **angles in degrees** in keys that say so (``limits_deg``, ``offset_deg``,
``angles_deg``).  See ``docs/file-format.md`` for the reference and a complete example.

Every error is one line that names the field: ``limbs[0].joints[1].axis: not a unit vector``.
"""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import numpy as np
import tomli_w
from annotated_types import Len
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from ..geometry.rotations import check_sequence
from .joints import Joint, make_joint
from .mechanism import Limb, Mechanism, Mode, Pose

__all__ = ["ModelFileError", "load", "loads", "dump", "dumps", "to_dict", "from_dict", "load_positions", "FORMAT_VERSION"]

FORMAT_VERSION = 1

Vec3 = Annotated[list[float], Len(3, 3)]
Flags = Union[bool, list[str], str]
Range = Annotated[list[float], Len(2, 2)]


class ModelFileError(ValueError):
    """A malformed mechanism file or description; the message is one line naming the field."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=False)


class JointSpec(_Strict):
    name: str
    type: str
    point: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    axis: Vec3 | None = None
    axes: list[Vec3] | None = None
    pitch: float = 0.0
    actuated: Flags = False
    lockable: Flags = False
    locked: Flags = False
    limits: Range | dict[str, Range] | None = None
    limits_deg: Range | dict[str, Range] | None = None
    offset: float | dict[str, float] | None = None
    offset_deg: float | dict[str, float] | None = None
    freedom_names: list[str] | None = None


class LimbSpec(_Strict):
    name: str
    joints: Annotated[list[JointSpec], Len(1)]


class EulerSpec(_Strict):
    seq: str
    angles_deg: Vec3


class PoseSpec(_Strict):
    name: str = ""
    point: Vec3
    euler: EulerSpec | None = None
    matrix: Annotated[list[Vec3], Len(3, 3)] | None = None


class ModeSpec(_Strict):
    name: str
    driven: list[str] = Field(default_factory=list)
    description: str = ""


class MechanismSpec(_Strict):
    format: Literal[1] = 1
    name: str
    description: str = ""
    length_unit: str = "m"
    normalize_axes: bool = False
    platform_point: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    limbs: Annotated[list[LimbSpec], Len(1)]
    modes: list[ModeSpec] = Field(default_factory=list)
    positions: list[PoseSpec] = Field(default_factory=list)
    aliases: dict[str, str] = Field(default_factory=dict)
    source: str = ""
    notes: str = ""


def _loc(loc) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _merge_units(js: JointSpec, kinds: dict[str, str], where: str, key: str, deg_key: str) -> dict | None:
    """Combine a linear-unit table and a degree table into one per-freedom table in SI/rad."""
    lin = getattr(js, key)
    deg = getattr(js, deg_key)
    names = list(kinds)

    def as_table(v, k):
        if v is None:
            return {}
        if isinstance(v, dict):
            return dict(v)
        if len(names) != 1:
            raise ModelFileError(f"{where}.{k}: this joint has several freedoms {names}; give a table by name")
        return {names[0]: v}

    out = {}
    for name, v in as_table(lin, key).items():
        if name not in kinds:
            raise ModelFileError(f"{where}.{key}.{name}: unknown freedom; this joint has {names}")
        if kinds[name] != "P":
            raise ModelFileError(f"{where}.{key}.{name}: a rotation is given in degrees: use {deg_key}")
        out[name] = v
    for name, v in as_table(deg, deg_key).items():
        if name not in kinds:
            raise ModelFileError(f"{where}.{deg_key}.{name}: unknown freedom; this joint has {names}")
        if kinds[name] == "P":
            raise ModelFileError(f"{where}.{deg_key}.{name}: a slide is a length: use {key}")
        out[name] = [math.radians(x) for x in v] if isinstance(v, list) else math.radians(v)
    return out or None


def _joint(js: JointSpec, where: str, normalize: bool) -> Joint:
    try:
        probe = make_joint(
            js.type, js.name, point=js.point, axis=js.axis, axes=js.axes, pitch=js.pitch,
            freedom_names=js.freedom_names, normalize=normalize, field=where,
        )
        kinds = {f.name: f.kind for f in probe.freedoms}
        return make_joint(
            js.type, js.name, point=js.point, axis=js.axis, axes=js.axes, pitch=js.pitch,
            actuated=js.actuated, lockable=js.lockable, locked=js.locked,
            limits=_merge_units(js, kinds, where, "limits", "limits_deg"),
            offset=_merge_units(js, kinds, where, "offset", "offset_deg"),
            freedom_names=js.freedom_names, normalize=normalize, field=where,
        )
    except ModelFileError:
        raise
    except (ValueError, KeyError) as e:
        raise ModelFileError(str(e).strip("'\"")) from None


def _pose(ps: PoseSpec, where: str) -> Pose:
    if (ps.euler is None) == (ps.matrix is None):
        raise ModelFileError(f"{where}: give exactly one of 'euler' or 'matrix'")
    try:
        if ps.euler is not None:
            check_sequence(ps.euler.seq)
            return Pose.from_euler(ps.euler.seq, ps.euler.angles_deg, ps.point, degrees=True, name=ps.name)
        return Pose(np.array(ps.matrix), ps.point, ps.name)
    except ValueError as e:
        raise ModelFileError(f"{where}: {e}") from None


def from_dict(data: dict[str, Any], *, source: str = "<dict>") -> Mechanism:
    """Validate a parsed file (a dict) and build the mechanism."""
    try:
        spec = MechanismSpec.model_validate(data)
    except ValidationError as e:
        err = e.errors()[0]
        loc = _loc(err["loc"])
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown field"
        elif err["type"] == "missing":
            msg = "required field is missing"
        raise ModelFileError(f"{loc}: {msg}") from None
    limbs = []
    for i, ls in enumerate(spec.limbs):
        joints = tuple(_joint(js, f"limbs[{i}].joints[{j}]", spec.normalize_axes) for j, js in enumerate(ls.joints))
        limbs.append(Limb(ls.name, joints))
    positions = tuple(_pose(p, f"positions[{i}]") for i, p in enumerate(spec.positions))
    modes = tuple(Mode(m.name, tuple(m.driven), m.description) for m in spec.modes)
    try:
        return Mechanism(
            name=spec.name, limbs=tuple(limbs), platform_point=spec.platform_point,
            description=spec.description, modes=modes, positions=positions, aliases=spec.aliases,
            length_unit=spec.length_unit, source=spec.source or source, notes=spec.notes,
        )
    except (ValueError, KeyError) as e:
        raise ModelFileError(str(e).strip("'\"")) from None


def loads(text: str, *, source: str = "<string>") -> Mechanism:
    """Parse TOML text into a mechanism."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ModelFileError(f"not valid TOML: {e}") from None
    return from_dict(data, source=source)


def load(path: str | Path) -> Mechanism:
    """Read a mechanism file.  Errors are :class:`ModelFileError` prefixed with the file name."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise ModelFileError(f"{path}: cannot read: {e.strerror}") from None
    try:
        return loads(text, source=str(path))
    except ModelFileError as e:
        raise ModelFileError(f"{path}: {e}") from None


# ------------------------------------------------------------------------- writer
def _clean(x: float) -> float:
    x = float(x)
    return 0.0 if abs(x) < 1e-15 else x


def _vec(v) -> list[float]:
    return [_clean(x) for x in v]


def _joint_dict(j: Joint) -> dict:
    d: dict[str, Any] = {"name": j.name, "type": j.type, "point": _vec(j.point)}
    fs = j.freedoms
    if j.type in ("R", "P", "H", "C"):
        d["axis"] = _vec(fs[0].direction)
    elif j.type == "U" or not np.array_equal([f.direction for f in fs], np.eye(3)):
        d["axes"] = [_vec(f.direction) for f in fs]
    if j.type == "H":
        d["pitch"] = fs[0].pitch
    default_names = make_joint(j.type, "probe", point=j.point, axis=d.get("axis"), axes=d.get("axes"), pitch=d.get("pitch", 0.0))
    names = [f.name for f in fs]
    if names != [f.name for f in default_names.freedoms]:
        d["freedom_names"] = names
    for flag in ("actuated", "lockable", "locked"):
        on = [f.name for f in fs if getattr(f, flag)]
        if flag == "lockable" and j.type == "Sm" and len(on) == len(fs):
            continue
        if on:
            d[flag] = True if len(on) == len(fs) and len(fs) == 1 else on
    lim, lim_deg, off, off_deg = {}, {}, {}, {}
    for f in fs:
        if f.limits is not None:
            if f.kind == "P":
                lim[f.name] = list(f.limits)
            else:
                lim_deg[f.name] = [math.degrees(x) for x in f.limits]
        if f.offset != 0.0:
            if f.kind == "P":
                off[f.name] = f.offset
            else:
                off_deg[f.name] = math.degrees(f.offset)
    for key, tab in (("limits", lim), ("limits_deg", lim_deg), ("offset", off), ("offset_deg", off_deg)):
        if tab:
            d[key] = tab
    return d


def to_dict(mech: Mechanism) -> dict[str, Any]:
    """The file representation of a mechanism (a dict ready for TOML or JSON)."""
    d: dict[str, Any] = {"format": FORMAT_VERSION, "name": mech.name}
    if mech.description:
        d["description"] = mech.description
    d["length_unit"] = mech.length_unit
    d["platform_point"] = _vec(mech.platform_point)
    if mech.source:
        d["source"] = mech.source
    if mech.notes:
        d["notes"] = mech.notes
    if mech.aliases:
        d["aliases"] = dict(mech.aliases)
    d["limbs"] = [{"name": l.name, "joints": [_joint_dict(j) for j in l.joints]} for l in mech.limbs]
    if mech.modes:
        d["modes"] = [{"name": m.name, "driven": list(m.driven), "description": m.description} for m in mech.modes]
    if mech.positions:
        d["positions"] = [
            {"name": p.name, "point": _vec(p.p), "matrix": [_vec(row) for row in p.R]}
            for p in mech.positions
        ]
    return d


_ARRAY = re.compile(r"\[\n((?:[ \t]*[^\]\s][^\n]*,\n)+)[ \t]*\]")


def _collapse_arrays(text: str, width: int = 100) -> str:
    """Put short arrays on one line (tomli-w writes one element per line)."""

    def one_line(m: re.Match) -> str:
        items = [x.strip().rstrip(",") for x in m.group(1).splitlines()]
        flat = "[" + ", ".join(items) + "]"
        return flat if len(flat) <= width else m.group(0)

    for _ in range(3):  # innermost arrays first, then arrays of short arrays
        text = _ARRAY.sub(one_line, text)
    return text


def dumps(mech: Mechanism) -> str:
    """TOML text of a mechanism; ``loads(dumps(m))`` rebuilds the same mechanism."""
    head = f"# spatialmech mechanism file (format {FORMAT_VERSION}); angles in degrees, lengths in {mech.length_unit}\n"
    return head + _collapse_arrays(tomli_w.dumps(to_dict(mech)))


def dump(mech: Mechanism, path: str | Path) -> None:
    Path(path).write_text(dumps(mech), encoding="utf-8")


class _PositionsFile(_Strict):
    positions: Annotated[list[PoseSpec], Len(1)]
    length_unit: str = "m"


def load_positions(path: str | Path) -> tuple[Pose, ...]:
    """Task positions from a TOML file with ``[[positions]]`` tables (``point`` and either
    ``euler = {seq, angles_deg}`` or ``matrix``), as in a mechanism file."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise ModelFileError(f"{path}: cannot read: {e.strerror}") from None
    except tomllib.TOMLDecodeError as e:
        raise ModelFileError(f"{path}: not valid TOML: {e}") from None
    try:
        spec = _PositionsFile.model_validate(data)
    except ValidationError as e:
        err = e.errors()[0]
        raise ModelFileError(f"{path}: {_loc(err['loc'])}: {err['msg']}") from None
    try:
        return tuple(_pose(p, f"positions[{i}]") if p.name else replace_name(_pose(p, f"positions[{i}]"), f"P{i + 1}")
                     for i, p in enumerate(spec.positions))
    except ModelFileError as e:
        raise ModelFileError(f"{path}: {e}") from None


def replace_name(pose: Pose, name: str) -> Pose:
    return Pose(pose.R, pose.p, name)
