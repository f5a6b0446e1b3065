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
from typing import Annotated, Any, Literal

import numpy as np
import tomli_w
from annotated_types import Len
from pydantic import BaseModel, ConfigDict, Field, PlainValidator, ValidationError

from ..errors import InputError
from ..geometry.rotations import check_sequence
from .joints import Joint, make_joint
from .inertia import LinkInertia, check_inertia
from .mechanism import Limb, Mechanism, Mode, Pose
from .task import TaskCoordinates

__all__ = ["FORMAT_VERSION", "ModelFileError", "dump", "dumps", "from_dict", "load", "load_positions", "loads", "to_dict"]

FORMAT_VERSION = 1

#: Largest mechanism or positions file read (bytes): a bigger file is refused, not read into memory.
MAX_FILE_BYTES = 10_000_000


class ModelFileError(InputError):
    """A malformed mechanism file or description; the message is one line naming the field."""


def _show(v, width: int = 40) -> str:
    """A value as the user typed it (TOML spelling of booleans), shortened to ``width``."""
    if isinstance(v, bool):
        text = "true" if v else "false"
    elif isinstance(v, int) and v.bit_length() > 200:  # repr() of a 4300-digit int raises
        text = f"an integer of {len(str(abs(v))) if v.bit_length() < 14000 else 'more than 4000'} digits"
    else:
        text = repr(v)
    return text if len(text) <= width else text[: width - 3] + "..."


def _at(where: str, text: str) -> str:
    """``".rot[1]: text"``: a message below the field being validated (``where`` may be empty)."""
    return f"{where}: {text}" if where else text


def _number(v, where: str = "") -> float:
    """A finite number; booleans and strings are not numbers (``point = [true, 0, 0]``)."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ValueError(_at(where, f"expected a number, got {_show(v)}"))
    try:
        x = float(v)
    except OverflowError:
        raise ValueError(_at(where, f"number too large for a float: {_show(v)}")) from None
    if not math.isfinite(x):
        raise ValueError(_at(where, f"must be a finite number, got {_show(v)}"))
    return x


def _range(v, where: str = "") -> list[float]:
    if not isinstance(v, list) or len(v) != 2:
        raise ValueError(_at(where, f"expected [lower, upper] (two numbers), got {_show(v)}"))
    return [_number(x, f"{where}[{k}]") for k, x in enumerate(v)]


def _flags(v):
    """``true``/``false``, a freedom name, or a list of freedom names."""
    if isinstance(v, (bool, str)) or (isinstance(v, list) and all(isinstance(x, str) for x in v)):
        return v
    raise ValueError(f"expected true, false, a freedom name or a list of freedom names, got {_show(v)}")


def _range_or_table(v):
    """``[lower, upper]`` or a table of them by freedom name."""
    if isinstance(v, dict):
        return {k: _range(x, f".{k}") for k, x in v.items()}
    if isinstance(v, list):
        return _range(v)
    raise ValueError(f"expected [lower, upper] or a table of them by freedom name, got {_show(v)}")


def _number_or_table(v):
    """A number or a table of numbers by freedom name."""
    if isinstance(v, dict):
        return {k: _number(x, f".{k}") for k, x in v.items()}
    return _number(v)


def _format_version(v):
    if isinstance(v, bool) or v != FORMAT_VERSION or not isinstance(v, int):
        raise ValueError(f"unsupported format {_show(v)}; this version reads format {FORMAT_VERSION}")
    return v


Vec3 = Annotated[list[float], Len(3, 3)]
Flags = Annotated[bool | list[str] | str, PlainValidator(_flags)]
RangeOrTable = Annotated[list[float] | dict[str, list[float]] | None, PlainValidator(_range_or_table)]
NumberOrTable = Annotated[float | dict[str, float] | None, PlainValidator(_number_or_table)]


class _Strict(BaseModel):
    # strict: no coercion (true is not 1, "1" is not a number, 1 is not true); ints are numbers
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, strict=True)


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
    limits: RangeOrTable = None
    limits_deg: RangeOrTable = None
    offset: NumberOrTable = None
    offset_deg: NumberOrTable = None
    freedom_names: list[str] | None = None
    stiffness: NumberOrTable = None


class LimbSpec(_Strict):
    name: str
    joints: Annotated[list[JointSpec], Len(1)]
    constraint_stiffness: float | None = None


class GraphJointSpec(JointSpec):
    """A joint of the link-and-joint graph form: its freedoms move ``links[1]`` relative to ``links[0]``."""

    links: Annotated[list[str], Len(2, 2)]


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


class MassSpec(_Strict):
    """A link's mass properties, at the reference configuration in world coordinates (SI)."""

    link: str
    mass_kg: float
    com_m: Vec3
    inertia_kg_m2: Annotated[list[Vec3], Len(3, 3)] = Field(default_factory=lambda: [[0.0] * 3 for _ in range(3)])


class DHSpec(_Strict):
    """A serial arm by Denavit-Hartenberg rows (:func:`.dh.serial_from_dh`), instead of ``limbs``."""

    convention: Literal["standard", "modified"]
    d: Annotated[list[float], Len(1)]
    a: list[float]
    alpha_deg: list[float]
    theta_deg: list[float] | None = None
    joints: str | None = None
    reference_deg: list[float] | None = None


class MechanismSpec(_Strict):
    format: Annotated[Literal[1], PlainValidator(_format_version)] = 1
    name: str
    description: str = ""
    length_unit: str = "m"
    normalize_axes: bool = False
    platform_point: Vec3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    limbs: Annotated[list[LimbSpec], Len(1)] | None = None
    dh: DHSpec | None = None
    links: Annotated[list[str], Len(2)] | None = None
    joints: Annotated[list[GraphJointSpec], Len(1)] | None = None
    output: str | None = None
    task: list[str] | None = None
    task_euler: str = "ZYX"
    modes: list[ModeSpec] = Field(default_factory=list)
    positions: list[PoseSpec] = Field(default_factory=list)
    aliases: dict[str, str] = Field(default_factory=dict)
    source: str = ""
    notes: str = ""
    masses: list[MassSpec] = Field(default_factory=list)
    density_kg_m3: float | None = None


def _loc(loc) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        else:
            out += ("." if out else "") + str(part)
    return out


def _validation_message(e: ValidationError) -> str:
    """The first error of a pydantic validation as one line that starts with the field."""
    err = e.errors()[0]
    loc = _loc(err["loc"])
    if err["type"] == "extra_forbidden":
        msg = "unknown field"
    elif err["type"] == "missing":
        msg = "required field is missing"
    elif err["type"] == "value_error":
        msg = str(err["ctx"]["error"])  # our own validators' messages, without "Value error, "
    else:
        msg = f"{err['msg']}, got {_show(err.get('input'))}"
    if not loc:
        return msg
    return f"{loc}{msg}" if msg.startswith((".", "[")) else f"{loc}: {msg}"


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
            freedom_names=js.freedom_names, normalize=normalize, field=where, stiffness=js.stiffness,
        )
    except ModelFileError:
        raise
    except InputError as e:
        raise ModelFileError(str(e)) from None


def _pose(ps: PoseSpec, where: str) -> Pose:
    if (ps.euler is None) == (ps.matrix is None):
        raise ModelFileError(f"{where}: give exactly one of 'euler' or 'matrix'")
    try:
        if ps.euler is not None:
            check_sequence(ps.euler.seq)
            return Pose.from_euler(ps.euler.seq, ps.euler.angles_deg, ps.point, degrees=True, name=ps.name)
        return Pose(np.array(ps.matrix), np.asarray(ps.point, dtype=float), ps.name)
    except InputError as e:
        raise ModelFileError(f"{where}: {e}") from None


def _masses(specs: list[MassSpec]) -> dict[str, LinkInertia]:
    out: dict[str, LinkInertia] = {}
    for i, ms in enumerate(specs):
        if ms.link in out:
            raise ModelFileError(f"masses[{i}].link: {ms.link!r} given twice")
        try:
            out[ms.link] = check_inertia(ms.mass_kg, ms.com_m, ms.inertia_kg_m2, f"masses[{i}]")
        except InputError as e:
            raise ModelFileError(str(e)) from None
    return out


def _is_graph(spec: MechanismSpec) -> bool:
    """Whether the file uses the graph form (``links`` + ``joints``) rather than ``limbs``; the
    mixtures refused, naming the field."""
    graph = spec.links is not None or spec.joints is not None
    if graph and spec.limbs is not None:
        raise ModelFileError("limbs: give either 'limbs' or the graph form 'links' + 'joints', not both")
    if not graph and spec.limbs is None:
        raise ModelFileError("limbs: required field is missing (or give the graph form: 'links' and 'joints'; "
                             "or a serial arm's 'dh' rows)")
    if graph and (spec.links is None or spec.joints is None):
        raise ModelFileError(f"{'joints' if spec.joints is None else 'links'}: the graph form needs both 'links' and 'joints'")
    if not graph and spec.output is not None:
        raise ModelFileError("output: only the graph form ('links' + 'joints') names an output link; "
                             "with 'limbs' the output link is the platform")
    return graph


def from_dict(data: dict[str, Any], *, source: str = "<dict>") -> Mechanism:
    """Validate a parsed file (a dict) and build the mechanism."""
    if not isinstance(data, dict):
        raise ModelFileError(f"expected a table of fields (a dict), got {type(data).__name__}")
    try:
        spec = MechanismSpec.model_validate(data)
    except ValidationError as e:
        raise ModelFileError(_validation_message(e)) from None
    if spec.dh is not None:
        return _dh_mechanism(spec, data, source)
    graph = _is_graph(spec)
    positions = tuple(_pose(p, f"positions[{i}]") for i, p in enumerate(spec.positions))
    modes = tuple(Mode(m.name, tuple(m.driven), m.description) for m in spec.modes)
    task = None
    if spec.task is not None:
        try:
            task = TaskCoordinates(tuple(spec.task), spec.task_euler)
        except InputError as e:
            raise ModelFileError(str(e)) from None
    elif spec.task_euler != "ZYX":
        raise ModelFileError("task_euler: given without 'task' (the task coordinates it names the angles of)")
    common: dict[str, Any] = dict(task=task,
        platform_point=np.asarray(spec.platform_point, dtype=float),
        description=spec.description, modes=modes, positions=positions, aliases=spec.aliases,
        length_unit=spec.length_unit, source=spec.source or source, notes=spec.notes,
        inertias=_masses(spec.masses), density_kg_m3=spec.density_kg_m3,
    )
    try:
        if graph:
            edges = [(_joint(js, f"joints[{j}]", spec.normalize_axes), js.links[0], js.links[1])
                     for j, js in enumerate(spec.joints or [])]
            return Mechanism.from_graph(spec.name, spec.links, edges, output=spec.output, **common)
        limbs = []
        for i, ls in enumerate(spec.limbs or []):
            joints = tuple(_joint(js, f"limbs[{i}].joints[{j}]", spec.normalize_axes) for j, js in enumerate(ls.joints))
            try:
                limbs.append(Limb(ls.name, joints, constraint_stiffness=ls.constraint_stiffness))
            except InputError as e:
                raise ModelFileError(f"limbs[{i}].constraint_stiffness: {str(e).split(': ', 1)[-1]}") from None
        return Mechanism(name=spec.name, limbs=tuple(limbs), **common)
    except ModelFileError:
        raise
    except InputError as e:
        raise ModelFileError(str(e)) from None


def _dh_mechanism(spec: MechanismSpec, data: dict[str, Any], source: str) -> Mechanism:
    """The ``dh`` form: one limb ``arm`` of joints ``J1 .. Jn`` (all actuated), the platform point
    the last frame's origin; the reference angles of the revolute rows in ``reference_deg`` (a
    prismatic row's reference is its ``d``)."""
    from .dh import serial_from_dh

    dh = spec.dh
    assert dh is not None
    clash = [k for k in ("limbs", "links", "joints", "output", "platform_point") if k in data]
    if clash:
        raise ModelFileError(f"{clash[0]}: not with 'dh' (the DH rows make the one limb 'arm' and place the "
                             "platform point at the last frame's origin)")
    joints = dh.joints if dh.joints is not None else "R" * len(dh.d)
    ref = dh.reference_deg
    if ref is not None:
        bad = [i for i, (c, v) in enumerate(zip(joints, ref, strict=False)) if c == "P" and v != 0.0]
        if bad:
            raise ModelFileError(f"dh.reference_deg[{bad[0]}]: row {bad[0]} is prismatic: its reference slide is "
                                 "its 'd' (give 0 here)")
    try:
        mech = serial_from_dh(spec.name, d=dh.d, a=dh.a, alpha=dh.alpha_deg, theta=dh.theta_deg, joints=joints,
                              reference=ref, convention=dh.convention, degrees=True,
                              description=spec.description)
        if spec.modes or spec.positions or spec.task is not None or spec.masses or spec.aliases:
            raise ModelFileError("dh: give the arm's modes, positions, task, masses and aliases in the limbs form "
                                 "(`spatialmech export` writes it from this file)")
    except ModelFileError:
        raise
    except InputError as e:
        raise ModelFileError(f"dh.{e}") from None
    from dataclasses import replace

    return replace(mech, length_unit=spec.length_unit, source=spec.source or source, notes=spec.notes,
                   density_kg_m3=spec.density_kg_m3)


def _parse_toml(text: str) -> dict[str, Any]:
    if not isinstance(text, str):
        raise TypeError(f"text: expected TOML text (str), got {type(text).__name__}")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ModelFileError(f"not valid TOML: {e}") from None
    except ValueError:  # Python's limit on the digits of an int (sys.get_int_max_str_digits)
        raise ModelFileError("not valid TOML: an integer of more than 4300 digits") from None
    except RecursionError:
        raise ModelFileError("not a usable TOML file: arrays or tables nested too deeply") from None


def loads(text: str, *, source: str = "<string>") -> Mechanism:
    """Parse TOML text into a mechanism."""
    data = _parse_toml(text)
    try:
        return from_dict(data, source=source)
    except RecursionError:  # a value nested hundreds of levels deep
        raise ModelFileError("values nested too deeply") from None


def _read_text(path: Path) -> str:
    """The UTF-8 text of a file of at most :data:`MAX_FILE_BYTES`; errors name the file."""
    try:
        with path.open("rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)
    except OSError as e:
        raise ModelFileError(f"{path}: cannot read: {e.strerror or e}") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ModelFileError(f"{path}: larger than {MAX_FILE_BYTES // 1_000_000} MB; not a mechanism file")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        line = raw[: e.start].count(b"\n") + 1
        raise ModelFileError(f"{path}: not UTF-8 text (byte 0x{raw[e.start]:02x} on line {line}); "
                             "save the file as UTF-8") from None


def load(path: str | Path) -> Mechanism:
    """Read a mechanism file.  Errors are :class:`ModelFileError` prefixed with the file name."""
    path = Path(path)
    text = _read_text(path)
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
    d.update(_stiffness_entry(fs))
    return d


def _stiffness_entry(fs) -> dict:
    """``{"stiffness": k}`` (one freedom) or a table by freedom name; ``{}`` when none is given."""
    stiff = {f.name: f.stiffness for f in fs if f.stiffness is not None}
    if not stiff:
        return {}
    return {"stiffness": stiff[fs[0].name] if len(fs) == 1 else stiff}


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
    if mech.task is not None:
        d["task"] = list(mech.task.given)
        d["task_euler"] = mech.task.euler
    if mech.is_graph:
        from .topology import link_graph

        g = link_graph(mech)
        d["output"] = mech.output
        hubs = list(mech.hubs)
        d["links"] = hubs + [k.name for k in g.links if k.name not in hubs]
        d["joints"] = [{**_joint_dict(j.joint), "links": [j.a, j.b]} for j in g.joints]
    else:
        d["limbs"] = [{"name": l.name, "joints": [_joint_dict(j) for j in l.joints],
                       **({} if l.constraint_stiffness is None else {"constraint_stiffness": l.constraint_stiffness})}
                      for l in mech.limbs]
    if mech.modes:
        d["modes"] = [{"name": m.name, "driven": list(m.driven), "description": m.description} for m in mech.modes]
    if mech.density_kg_m3 is not None:
        d["density_kg_m3"] = mech.density_kg_m3
    if mech.inertias:
        d["masses"] = [{"link": name, "mass_kg": li.mass_kg, "com_m": _vec(li.com_m),
                        "inertia_kg_m2": [_vec(row) for row in li.inertia_kg_m2]} for name, li in mech.inertias.items()]
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
    unit = "".join(c if c.isprintable() else "?" for c in mech.length_unit)  # a comment ends at a newline
    head = f"# spatialmech mechanism file (format {FORMAT_VERSION}); angles in degrees, lengths in {unit}\n"
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
    text = _read_text(path)
    try:
        data = _parse_toml(text)
        spec = _PositionsFile.model_validate(data)
    except ModelFileError as e:
        raise ModelFileError(f"{path}: {e}") from None
    except ValidationError as e:
        raise ModelFileError(f"{path}: {_validation_message(e)}") from None
    except RecursionError:
        raise ModelFileError(f"{path}: values nested too deeply") from None
    try:
        return tuple(_pose(p, f"positions[{i}]") if p.name else replace_name(_pose(p, f"positions[{i}]"), f"P{i + 1}")
                     for i, p in enumerate(spec.positions))
    except ModelFileError as e:
        raise ModelFileError(f"{path}: {e}") from None


def replace_name(pose: Pose, name: str) -> Pose:
    return Pose(pose.R, pose.p, name)
