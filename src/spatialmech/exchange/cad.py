"""CAD export with units: one solid per link, as STEP, STL or GLB (docs/cad.md).

Every link of a mechanism becomes one solid: capsules along the link's segments (the body
tree's, :mod:`.bodies`) with the link diameter the model gives (its workspace limits'
``link_diameter``; otherwise 4 % of the characteristic length, the MJCF export's capsules), and
joint geometry on both links a joint connects: an R joint is a hub on one link and a longer,
thinner pin on the other; a U joint two crossed pins (with a cone limit, also a housing on the
link the cone's axis is fixed in, open over the cone, as an S joint's); an S joint a housing
sphere on one link and a smaller ball on the other (with a cone limit in the model's workspace
limits, the housing is on the link the cone's axis is fixed in and open over the cone the leg
may sweep); a P or C
joint a sleeve on one link and a rod as long as the slide's stroke (its limits; otherwise
0.3 L) on the other.

Each link is written in its own frame (the body tree's: world-aligned at the reference
configuration, at the point of the joint that leads to it) and the assembly with every link
placed at the chosen configuration; along a motion (:func:`export_cad_motion`), the link files
once (links are rigid), one assembly per sample (``part.000.step``, ...) and a JSON file of
every link's placement at every sample (``part.placements.json``, :func:`read_placements`).
The joints are features of the files that survive a round trip: the joint centres and axes of every link, in the link's frame, are

* STEP: a line edge per joint and link, from the centre along the axis, in the solid's
  compound, labelled ``J_<hex of the joint name>``; the unit is the STEP header's
  ``SI_UNIT(.MILLI.,.METRE.)`` or ``SI_UNIT($,.METRE.)``;
* GLB: the glTF ``extras`` of the scene (glTF is in metres by its specification: a GLB is
  always written in metres, and says so in ``extras``);
* STL: the JSON sidecar (STL carries no unit: the unit is in the file name, ``part.mm.stl``, and
  in the sidecar, which also records the mesh bounds that a re-import checks the scale by).

:func:`read_joint_frames` reads them back, in metres, and checks the unit.

The CAD libraries are optional (the ``cad`` extra): build123d (OpenCascade) for STEP, trimesh
with manifold3d for STL and GLB; a missing one is an :class:`~spatialmech.errors.InputError`
that names the extra.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, MissingExtraError
from ..kinematics.closure import Configuration, chain_forward, limb_chains, limb_slices
from ..model.mechanism import GROUND, Mechanism
from ..model.topology import link_graph
from .bodies import body_tree

__all__ = ["CAD_FORMATS", "CAD_UNITS", "CadExport", "CadMotion", "JointFeature", "LinkSolid", "cad_links", "export_cad",
           "export_cad_motion", "housing_mesh", "housing_solid", "link_displacements", "read_joint_frames",
           "read_placements"]

#: The CAD formats and their file extensions.
CAD_FORMATS = {"step": (".step", ".stp"), "stl": (".stl",), "glb": (".glb",)}
#: The units a CAD file may be written in, and their size in metres.
CAD_UNITS = {"m": 1.0, "mm": 1e-3}
#: The model length units a CAD export understands (their size in metres).
_MODEL_UNITS = {"m": 1.0, "mm": 1e-3}
#: Default link diameter, a fraction of the characteristic length (the MJCF capsules' 2 x 0.02 L).
DEFAULT_LINK_DIAMETER = 0.04
#: Segments of a mesh cylinder (STL, GLB).
_SECTIONS = 32
_FORMAT_TAG = "spatialmech cad 1"
_MOTION_TAG = "spatialmech cad motion 1"


@dataclass(frozen=True)
class JointFeature:
    """A joint as seen from one link: its ``centre`` and unit ``axis`` in the link's frame
    (model length unit; the axis is zero for an S joint), the joint ``type`` and the ``role``
    of this link's part of the joint (``"hub"``, ``"pin"``, ``"housing"``, ``"ball"``,
    ``"sleeve"``, ``"rod"``)."""

    name: str
    type: str
    centre: np.ndarray
    axis: np.ndarray
    role: str


@dataclass(frozen=True)
class LinkSolid:
    """One link: its primitives in its own frame (``("cyl", a, b, r)``, ``("sph", c, r)``,
    ``("housing", c, r, opening direction, cone half-angle)``, model length unit), its joints,
    its frame ``origin`` (world, reference configuration) and its displacement ``D`` (4x4,
    world) at the exported configuration."""

    link: str
    origin: np.ndarray
    D: np.ndarray
    primitives: tuple[tuple, ...]
    joints: tuple[JointFeature, ...]
    diameter: float

    @property
    def placement(self) -> np.ndarray:
        """The link frame in the world at the exported configuration: ``D @ [I, origin]``."""
        T = np.eye(4)
        T[:3, 3] = self.origin
        return self.D @ T


@dataclass(frozen=True)
class CadExport:
    """What :func:`export_cad` wrote: the assembly file, one file per link, the sidecar (STL),
    the format and the unit of the files; ``joints``: per link its file, diameter and joints
    placed in the world (model length unit)."""

    assembly: Path
    links: dict[str, Path]
    format: str
    unit: str
    sidecar: Path | None = None
    joints: dict[str, dict[str, Any]] = field(default_factory=dict)

    @property
    def files(self) -> list[Path]:
        out = [self.assembly, *self.links.values()]
        return [*out, self.sidecar] if self.sidecar is not None else out


@dataclass(frozen=True)
class CadMotion:
    """What :func:`export_cad_motion` wrote: one assembly per sample, one file per link (once),
    the placements file (JSON: every link's placement at every sample), the STL sidecar, the
    format and the unit of the files."""

    assemblies: tuple[Path, ...]
    links: dict[str, Path]
    placements: Path
    format: str
    unit: str
    sidecar: Path | None = None

    @property
    def files(self) -> list[Path]:
        out = [*self.assemblies, *self.links.values(), self.placements]
        return [*out, self.sidecar] if self.sidecar is not None else out


# ------------------------------------------------------------------ placement
def link_displacements(mech: Mechanism, config: Configuration) -> dict[str, np.ndarray]:
    """The displacement (4x4, world) of every link at ``config``: the ground's is the identity,
    the hubs' are ``config``'s, a limb's intermediate link moves with every freedom before it."""
    out: dict[str, np.ndarray] = {GROUND: np.eye(4), mech.output: np.asarray(config.D, float)}
    for k, b in enumerate(mech.bodies):
        out[b] = np.asarray(config.B[k], float)
    for li, (ch, sl) in enumerate(zip(limb_chains(mech), limb_slices(mech), strict=True)):
        limb = mech.limbs[li]
        _, _, pre = chain_forward(ch, np.asarray(config.q, float)[sl], prefixes=True)
        base = config.hub(mech.limb_ends[li][0])
        first: dict[int, int] = {}
        for k, r in enumerate(r for r in mech.freedom_refs if r.limb == li):
            first.setdefault(r.joint, k)
        for j, name in enumerate(limb.link_names):  # the link after joint j: before joint j + 1 moves
            out[name] = base @ pre[first[j + 1]]
    return out


# ------------------------------------------------------------------ geometry
def _diameters(mech: Mechanism) -> tuple[dict[str, float], float]:
    """Per link, the diameter of its capsules, and the default for the hubs."""
    from ..analysis.workspace.limits import default_limits

    lim = default_limits(mech)
    fallback = DEFAULT_LINK_DIAMETER * mech.characteristic_length
    per: dict[str, float] = {}
    for limb in mech.limbs:
        d = lim.diameter(limb.name)
        for name in limb.link_names:
            per[name] = d if d else fallback
    hub = max([fallback, *per.values()]) if per else fallback
    return per, hub


def _openings(mech: Mechanism) -> dict[str, tuple[str, np.ndarray, float]]:
    """Per S joint with a cone limit (the model's workspace limits): the link its housing is on
    (the one the cone's axis is fixed in: the ground for a ``base`` cone, the output link for a
    ``platform`` one), the direction the housing opens to (the leg leaves a base-side joint along
    ``+axis``, a platform-side one along ``-axis``) and the cone's half-angle (rad)."""
    from ..analysis.workspace.limits import default_limits

    out = {}
    for c in default_limits(mech).cones:
        w = np.asarray(c.axis, float)
        out[c.joint] = (GROUND, w, c.max_angle) if c.frame == "base" else (mech.output, -w, c.max_angle)
    return out


def _stroke(joint, L: float) -> float:
    lims = [f.limits for f in joint.freedoms if f.kind == "P" and f.limits is not None]
    return max([abs(hi - lo) for lo, hi in lims] or [0.3 * L])


def _joint_parts(gj, side: str, d: float, L: float, o: np.ndarray, opening: tuple[str, np.ndarray, float] | None
                 ) -> tuple[list[tuple], list[JointFeature]]:
    """The primitives and features of joint ``gj`` on the link at its ``side`` (``"a"`` or
    ``"b"``), in the frame at ``o``; ``opening``: the S joint's cone (:func:`_openings`)."""
    j = gj.joint
    c = j.point - o
    t = gj.type
    prims: list[tuple] = []
    if t in ("S", "Sm"):
        on = opening[0] if opening is not None and opening[0] in (gj.a, gj.b) else gj.a
        here = gj.a if side == "a" else gj.b
        if here != on:
            prims.append(("sph", c, 0.8 * d))
        elif opening is not None and on == opening[0]:  # a housing open over the cone the leg may sweep
            prims.append(("housing", c, 1.1 * d, opening[1], opening[2]))
        else:
            prims.append(("sph", c, 1.1 * d))
        return prims, [JointFeature(gj.name, t, c, np.zeros(3), "ball" if here != on else "housing")]
    axes = [f.direction for f in j.freedoms if f.kind != "P"] or [j.freedoms[0].direction]
    if t in ("P", "C"):
        u = j.freedoms[0].direction
        role = "sleeve" if side == "a" else "rod"
        h = 1.5 * d if side == "a" else 0.5 * _stroke(j, L) + 1.5 * d
        prims.append(("cyl", c - h * u, c + h * u, 0.9 * d if side == "a" else 0.45 * d))
        return prims, [JointFeature(gj.name, t, c, u / np.linalg.norm(u), role)]
    role = "hub" if side == "a" else "pin"
    feats = []
    here = gj.a if side == "a" else gj.b
    if t == "U" and opening is not None and opening[0] == here:  # the yoke's swing: a housing open over the cone
        prims.append(("housing", c, 1.1 * d, opening[1], opening[2]))
    for k, u in enumerate(axes[:2] if t == "U" else axes[:1]):
        u = u / np.linalg.norm(u)
        h = 1.0 * d if side == "a" else 2.0 * d
        prims.append(("cyl", c - h * u, c + h * u, 0.8 * d if side == "a" else 0.4 * d))
        feats.append(JointFeature(gj.name if k == 0 else f"{gj.name}#2", t, c, u, role))
    return prims, feats


def cad_links(mech: Mechanism, config: Configuration | None = None) -> list[LinkSolid]:
    """Every link of ``mech`` as a :class:`LinkSolid` placed at ``config`` (default: the
    reference configuration)."""
    config = Configuration.reference(mech) if config is None else config
    L = mech.characteristic_length
    tree = body_tree(mech)
    graph = link_graph(mech)
    per, hub_d = _diameters(mech)
    openings = _openings(mech)
    D = link_displacements(mech, config)
    origins = {GROUND: np.zeros(3)}
    segments: dict[str, list] = {GROUND: list(tree.ground_segments)}
    for b in tree.bodies:
        if not b.ghost:
            origins[b.link] = b.origin
            segments[b.link] = list(b.segments)
    out = []
    for link in [GROUND, *(b.link for b in tree.bodies if not b.ghost)]:
        o = origins[link]
        d = per.get(link, hub_d)
        prims: list[tuple] = []
        for a, b in segments[link]:
            prims += [("cyl", a - o, b - o, 0.5 * d), ("sph", a - o, 0.5 * d), ("sph", b - o, 0.5 * d)]
        feats: list[JointFeature] = []
        for gj in graph.joints:
            for side, end in (("a", gj.a), ("b", gj.b)):
                if end == link:
                    p, f = _joint_parts(gj, side, d, L, o, openings.get(gj.name))
                    prims += p
                    feats += f
        out.append(LinkSolid(link, o.copy(), D[link], _distinct(prims, L), tuple(feats), d))
    return out


def _distinct(prims: list[tuple], L: float) -> tuple[tuple, ...]:
    """The primitives less the spheres inside a larger one or a housing at the same centre
    (coincident spheres make the CAD kernel's boolean union slow; a capsule's end would fill a
    housing's opening)."""
    out = []
    for k, p in enumerate(prims):
        if p[0] == "sph" and any(q[0] in ("sph", "housing") and np.linalg.norm(q[1] - p[1]) <= 1e-12 * L
                                 and (q[2] > p[2] or (q[2] == p[2] and i < k)) for i, q in enumerate(prims)):
            continue
        out.append(p)
    return tuple(out)


# ------------------------------------------------------------------ files
def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_-]+", "-", name).strip("-") or "link"


def _scale(mech: Mechanism, unit: str) -> float:
    """Model length unit -> file unit."""
    if unit not in CAD_UNITS:
        raise InputError(f"unit: expected one of {', '.join(CAD_UNITS)}, got {unit!r}")
    if mech.length_unit not in _MODEL_UNITS:
        raise InputError(f"length_unit: a CAD export needs a model in {' or '.join(_MODEL_UNITS)}, "
                         f"{mech.name} is in {mech.length_unit!r}")
    return _MODEL_UNITS[mech.length_unit] / CAD_UNITS[unit]


def _features_dict(link: LinkSolid, s: float, T: np.ndarray | None) -> list[dict]:
    """The link's joint features in the file's unit, in its frame (``T`` None) or placed by ``T``."""
    R, p = (np.eye(3), np.zeros(3)) if T is None else (T[:3, :3], T[:3, 3])
    return [{"joint": f.name, "type": f.type, "role": f.role, "centre": [float(v) for v in s * (R @ f.centre + p / s)],
             "axis": [float(v) for v in R @ f.axis]} for f in link.joints]


def _need(module: str, what: str):
    """Import ``module`` (of the ``cad`` extra, or OpenCascade's ``OCP`` that build123d brings) or
    raise :class:`~spatialmech.errors.MissingExtraError` naming the extra."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError("cad", module.split(".")[0], what) from None


def _paths(out: Path, fmt: str, unit: str, links: list[LinkSolid], samples: int = 0
           ) -> tuple[list[Path], dict[str, Path], Path, Path]:
    """The assemblies' paths (one; along a motion of ``samples`` samples, ``part.000.step``, ...),
    each link's (``part.<link>.step``), the placements file's (``part.placements.json``) and the
    STL sidecar's (``part.mm.json``); STL names carry the unit (``part.mm.stl``,
    ``part.<link>.mm.stl``, ``part.000.mm.stl``)."""
    stem, suffix = out.name[: -len(out.suffix)] if out.suffix else out.name, out.suffix or CAD_FORMATS[fmt][0]
    if fmt == "stl":
        stem = stem[: -len(f".{unit}")] if stem.endswith(f".{unit}") else stem
        tail = f".{unit}{suffix}"
    else:
        tail = suffix
    width = max(3, len(str(samples - 1)))
    assemblies = ([out.with_name(f"{stem}.{i:0{width}d}{tail}") for i in range(samples)] if samples
                  else [out.with_name(stem + tail)])
    return (assemblies, {k.link: out.with_name(f"{stem}.{_safe(k.link)}{tail}") for k in links},
            out.with_name(f"{stem}.placements.json"), out.with_name(f"{stem}.{unit}.json"))


def _rows(T: np.ndarray, s: float) -> list[list[float]]:
    """A 4x4 placement (model length unit) as rows, its translation in the file's unit."""
    return [[float(v) * (s if c == 3 and r < 3 else 1.0) for c, v in enumerate(row)] for r, row in enumerate(T)]


def _origin(o: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = o
    return T


def _prepare(mech: Mechanism, fmt: str, unit: str, config: Configuration | None) -> tuple[list[LinkSolid], float]:
    if fmt not in CAD_FORMATS:
        raise InputError(f"format: expected one of {', '.join(CAD_FORMATS)}, got {fmt!r}")
    if fmt == "glb" and unit != "m":
        raise InputError(f"unit: a GLB is in metres (the glTF specification), got {unit!r}; use unit='m'")
    s = _scale(mech, unit)
    return cad_links(mech, config), s


def _meta(mech: Mechanism, unit: str, links: list[LinkSolid], paths: dict[str, Path], s: float,
          placements: dict[str, np.ndarray]) -> dict[str, Any]:
    """The files' metadata: per link its file, diameter, placement and joints (file unit)."""
    per_link = {k.link: {"file": paths[k.link].name, "diameter": k.diameter * s, "placement": _rows(placements[k.link], s),
                         "joints": _features_dict(k, s, None)} for k in links}
    return {"format": _FORMAT_TAG, "model": mech.name, "unit": unit, "links": per_link}


def _write(fmt: str, links: list[LinkSolid], s: float, paths: dict[str, Path],
           scenes: list[tuple[Path, dict[str, np.ndarray]]], meta: dict, sidecar: Path) -> Path | None:
    """Write the link files and one assembly per scene (its path and every link's placement);
    the STL sidecar's path, or None."""
    if fmt == "step":
        _write_step(links, s, paths, scenes, meta)
        return None
    if fmt == "glb":
        _write_glb(links, s, paths, scenes, meta)
        return None
    _write_stl(links, s, paths, scenes, meta, sidecar)
    return sidecar


def export_cad(mech: Mechanism, out, fmt: str, *, config: Configuration | None = None, unit: str = "mm") -> CadExport:
    """Write ``mech`` at ``config`` as CAD files (see the module docstring): the assembly at
    ``out`` and one file per link beside it, in ``unit`` (``"m"`` or ``"mm"``; a GLB is always in
    metres)."""
    links, s = _prepare(mech, fmt, unit, config)
    (assembly,), paths, _, sidecar_path = _paths(Path(os.fspath(out)), fmt, unit, links)
    placements = {k.link: k.placement for k in links}
    meta = _meta(mech, unit, links, paths, s, placements)
    sidecar = _write(fmt, links, s, paths, [(assembly, placements)], meta, sidecar_path)
    summary = {k.link: {"file": paths[k.link].name, "diameter_len": k.diameter,
                        "joints": [{("centre_len" if key == "centre" else key): v for key, v in f.items()}
                                   for f in _features_dict(k, 1.0, k.placement)]}
               for k in links}
    return CadExport(assembly, paths, fmt, unit, sidecar, summary)


def export_cad_motion(mech: Mechanism, out, fmt: str, configs, *, unit: str = "mm",
                      labels: list[dict] | None = None) -> CadMotion:
    """Write ``mech`` along a motion (``configs``, the samples in order) as CAD files: one file per
    link in its own frame (once: the links are rigid), one assembly per sample (``part.000.step``,
    ...) and ``part.placements.json``, every link's placement at every sample (rotation and
    origin, the origin in the files' unit), for a CAD user to animate the links; ``labels``: per
    sample, what else to record with it (e.g. its actuator values)."""
    configs = list(configs)
    if not configs:
        raise InputError("configs: no sample to export")
    if labels is not None and len(labels) != len(configs):
        raise InputError(f"labels: expected one per sample ({len(configs)}), got {len(labels)}")
    links, s = _prepare(mech, fmt, unit, configs[0])
    assemblies, paths, placements_path, sidecar_path = _paths(Path(os.fspath(out)), fmt, unit, links, len(configs))
    scenes = []
    for path, c in zip(assemblies, configs, strict=True):
        D = link_displacements(mech, c)
        scenes.append((path, {k.link: D[k.link] @ _origin(k.origin) for k in links}))
    meta = _meta(mech, unit, links, paths, s, scenes[0][1])
    sidecar = _write(fmt, links, s, paths, scenes, meta, sidecar_path)
    samples = []
    for i, (path, P) in enumerate(scenes):
        samples.append({"sample": i, "assembly": path.name, **(labels[i] if labels is not None else {}),
                        "links": {k: {"rotation": [[float(v) for v in row] for row in T[:3, :3]],
                                      f"origin_{unit}": [float(v) * s for v in T[:3, 3]]} for k, T in P.items()}})
    doc = {"format": _MOTION_TAG, "model": mech.name, "file_length_unit": unit, "file_format": fmt,
           "link_files": {k.link: paths[k.link].name for k in links}, "samples": samples}
    placements_path.write_text(json.dumps(doc, indent=1), encoding="utf-8")
    return CadMotion(tuple(assemblies), paths, placements_path, fmt, unit, sidecar)


def read_placements(path) -> dict[str, Any]:
    """The placements file of :func:`export_cad_motion`, in metres: ``{"unit": the files' unit,
    "link_files": {link: file}, "samples": [{"assembly": file, "links": {link: 4x4 array, metres}},
    ...]}`` (the other fields of each sample as written)."""
    path = Path(os.fspath(path))
    doc = json.loads(path.read_text(encoding="utf-8"))
    if doc.get("format") != _MOTION_TAG:
        raise InputError(f"{path}: not a spatialmech placements file (format {doc.get('format')!r})")
    unit = doc["file_length_unit"]
    if unit not in CAD_UNITS:
        raise InputError(f"{path}: file_length_unit: expected one of {', '.join(CAD_UNITS)}, got {unit!r}")
    samples = []
    for x in doc["samples"]:
        links = {}
        for k, v in x["links"].items():
            T = np.eye(4)
            T[:3, :3] = np.asarray(v["rotation"], float)
            T[:3, 3] = CAD_UNITS[unit] * np.asarray(v[f"origin_{unit}"], float)
            links[k] = T
        samples.append({**x, "links": links})
    return {"unit": unit, "link_files": doc["link_files"], "samples": samples}


# ------------------------------------------------------------------ STEP (build123d)
def _b3d_solid(b3d, prims, s: float):
    parts = []
    for p in prims:
        if p[0] == "cyl":
            a, b, r = s * p[1], s * p[2], s * p[3]
            h = float(np.linalg.norm(b - a))
            if h <= 0:
                continue
            plane = b3d.Plane(origin=tuple(a), z_dir=tuple((b - a) / h))
            parts.append(b3d.Solid.make_cylinder(r, h, plane))
        elif p[0] == "housing":
            parts.append(housing_solid(b3d, s * p[1], s * p[2], p[3], p[4]))
        else:
            parts.append(b3d.Solid.make_sphere(s * p[2]).moved(b3d.Location(tuple(s * p[1]))))
    # a fuzzy union (1e-5 of the largest radius): exact unions of tangent or coaxial primitives
    # are ten times slower in OpenCascade and give the same solid within that size
    tol = 1e-5 * s * max(p[3] if p[0] == "cyl" else p[2] for p in prims)
    return parts[0].fuse(*parts[1:], tol=tol) if len(parts) > 1 else parts[0]


def _cone_size(R: float, alpha: float) -> tuple[float, float]:
    """Height and base radius of the cone (apex at the centre) that cuts a housing of radius
    ``R`` with the half-angle ``alpha`` < pi/2: it reaches beyond the sphere."""
    H = 1.5 * R
    return H, H * float(np.tan(alpha))


def housing_solid(b3d, c: np.ndarray, R: float, w: np.ndarray, alpha: float):
    """A ball-joint housing as a build123d solid (``b3d``: the module): the sphere of radius
    ``R`` at ``c`` less the cone of half-angle ``alpha`` about ``w`` where the leg may swing
    (pi/2: a hemisphere; more: the sphere kept only inside the cone of pi - alpha about ``-w``)."""
    sphere = b3d.Solid.make_sphere(R).moved(b3d.Location(tuple(c)))
    if abs(alpha - np.pi / 2) < 1e-9:
        out = sphere.cut(b3d.Solid.make_cylinder(1.5 * R, 1.5 * R, b3d.Plane(origin=tuple(c), z_dir=tuple(w))))
    else:
        beta, sign = (alpha, 1.0) if alpha < np.pi / 2 else (np.pi - alpha, -1.0)
        H, r = _cone_size(R, beta)
        cone = b3d.Solid.make_cone(0.0, r, H, b3d.Plane(origin=tuple(c), z_dir=tuple(sign * w)))
        out = sphere.cut(cone) if sign > 0 else sphere.intersect(cone)
    if isinstance(out, list):  # build123d gives a list of the pieces: a housing is one
        if len(out) != 1:
            raise RuntimeError(f"a ball housing cut into {len(out)} pieces (alpha = {alpha} rad)")
        out = out[0]
    return out


def _b3d_edges(b3d, link: LinkSolid, s: float, L: float, T: np.ndarray) -> list:
    """The joint features as labelled line edges, placed by ``T`` (file unit)."""
    out = []
    for f in link.joints:
        u = T[:3, :3] @ (f.axis if np.linalg.norm(f.axis) > 0 else np.array([1.0, 0.0, 0.0]))
        c = T[:3, :3] @ (s * f.centre) + T[:3, 3]
        e = b3d.Edge.make_line(tuple(c), tuple(c + 0.25 * s * L * u))
        e.label = "J_" + f"{f.name}|{f.type}|{f.role}|{'S' if not np.any(f.axis) else 'A'}".encode().hex()
        out.append(e)
    return out


def _step_part(b3d, link: LinkSolid, solid, s: float, L: float, T: np.ndarray | None):
    """A link's compound: its solid and its joint edges, in its frame (``T`` None) or placed."""
    M = np.eye(4)
    if T is not None:
        M = T.copy()
        M[:3, 3] *= s
        gp = _need("OCP.gp", "a STEP export")
        trsf = gp.gp_Trsf()
        trsf.SetValues(*(float(v) for v in M[:3].ravel()))
        solid = solid.moved(b3d.Location(trsf))
    solid.label = "solid"
    return b3d.Compound(label="L_" + link.link.encode().hex(), children=[solid, *_b3d_edges(b3d, link, s, L, M)])


def _write_step(links: list[LinkSolid], s: float, paths: dict[str, Path],
                scenes: list[tuple[Path, dict[str, np.ndarray]]], meta: dict) -> None:
    b3d = _need("build123d", "a STEP export")
    unit = b3d.Unit.MM if meta["unit"] == "mm" else b3d.Unit.M
    # OpenCascade writes STEP in its session unit (mm by default) whatever the document's unit:
    # name the unit asked for (build123d's controllers are initialised once, so this stays)
    static = _need("OCP.Interface", "a STEP export").Interface_Static
    _need("OCP.STEPControl", "a STEP export").STEPControl_Controller.Init_s()
    static.SetCVal_s("write.step.unit", meta["unit"].upper())
    L = max(float(np.linalg.norm(p[2] - p[1])) for k in links for p in k.primitives if p[0] == "cyl") or 1.0
    stamp = "2000-01-01T00:00:00"  # reproducible files
    solids = {}
    for k in links:
        solids[k.link] = _b3d_solid(b3d, k.primitives, s)
        b3d.export_step(_step_part(b3d, k, solids[k.link], s, L, None), os.fspath(paths[k.link]), unit=unit,
                        timestamp=stamp)
    for assembly, placements in scenes:
        placed = [_step_part(b3d, k, solids[k.link], s, L, placements[k.link]) for k in links]
        b3d.export_step(b3d.Compound(label=meta["model"], children=placed), os.fspath(assembly), unit=unit,
                        timestamp=stamp)
    return None


_STEP_UNIT = re.compile(r"LENGTH_UNIT\(\)\s*NAMED_UNIT\(\*\)\s*SI_UNIT\((\.MILLI\.|\$),\.METRE\.\)")


def _read_step(path: Path) -> tuple[str, dict[str, list[dict]]]:
    b3d = _need("build123d", "reading a STEP file")
    units = set(_STEP_UNIT.findall(path.read_text(encoding="utf-8", errors="replace")))
    if len(units) != 1:
        raise InputError(f"{path}: expected one SI length unit (metre or millimetre) in the STEP header, found {units}")
    unit = "mm" if units.pop() == ".MILLI." else "m"
    links: dict[str, list[dict]] = {}

    def walk(node, link):
        label = node.label or ""
        if label.startswith("J_") and isinstance(node, b3d.Edge | b3d.Compound) and node.edges():
            name, typ, role, kind = bytes.fromhex(label[2:]).decode().split("|")
            e = node.edges()[0]
            a, b = np.array(tuple(e.position_at(0))), np.array(tuple(e.position_at(1)))
            ax = (b - a) / np.linalg.norm(b - a) if kind == "A" else np.zeros(3)
            links.setdefault(link, []).append({"joint": name, "type": typ, "role": role, "centre": a.tolist(),
                                               "axis": ax.tolist()})
            return
        if label.startswith("L_"):
            link = bytes.fromhex(label[2:]).decode()
        for ch in getattr(node, "children", ()) or ():
            walk(ch, link)

    # OpenCascade converts what it reads to its session unit by the header's unit: read in mm
    _need("OCP.STEPControl", "reading a STEP file").STEPControl_Controller.Init_s()
    _need("OCP.Interface", "reading a STEP file").Interface_Static.SetCVal_s("xstep.cascade.unit", "MM")
    walk(b3d.import_step(os.fspath(path)), None)
    per_file_unit = CAD_UNITS["mm"] / CAD_UNITS[unit]  # read (mm) -> the file's unit
    for feats in links.values():
        for x in feats:
            x["centre"] = [per_file_unit * v for v in x["centre"]]
    return unit, links


# ------------------------------------------------------------------ STL / GLB (trimesh)
def _mesh(tm, prims, s: float):
    parts = []
    for p in prims:
        if p[0] == "cyl":
            a, b = s * p[1], s * p[2]
            if np.linalg.norm(b - a) > 0:
                parts.append(tm.creation.cylinder(radius=s * p[3], segment=np.array([a, b]), sections=_SECTIONS))
        elif p[0] == "housing":
            parts.append(housing_mesh(tm, s * p[1], s * p[2], p[3], p[4]))
        else:
            sph = tm.creation.icosphere(subdivisions=2, radius=s * p[2])
            sph.apply_translation(s * p[1])
            parts.append(sph)
    return tm.boolean.union(parts, engine="manifold") if len(parts) > 1 else parts[0]


def housing_mesh(tm, c: np.ndarray, R: float, w: np.ndarray, alpha: float):
    """:func:`housing_solid` as a trimesh mesh (``tm``: the trimesh module; manifold3d booleans)."""
    sphere = tm.creation.icosphere(subdivisions=3, radius=R)
    if abs(alpha - np.pi / 2) < 1e-9:
        cutter = tm.creation.cylinder(radius=1.5 * R, segment=np.array([np.zeros(3), 1.5 * R * w]), sections=_SECTIONS)
        keep = False
    else:
        beta, sign = (alpha, 1.0) if alpha < np.pi / 2 else (np.pi - alpha, -1.0)
        H, r = _cone_size(R, beta)
        cutter = tm.creation.cone(radius=r, height=H, sections=_SECTIONS)  # base at z = 0, apex at z = H
        cutter.apply_transform(tm.transformations.rotation_matrix(np.pi, [1.0, 0.0, 0.0]) @
                               tm.transformations.translation_matrix([0.0, 0.0, -H]))  # apex at 0, base at z = H
        cutter.apply_transform(tm.geometry.align_vectors([0.0, 0.0, 1.0], sign * w))
        keep = sign < 0
    out = (tm.boolean.intersection if keep else tm.boolean.difference)([sphere, cutter], engine="manifold")
    out.apply_translation(c)
    return out


def _write_stl(links: list[LinkSolid], s: float, paths: dict[str, Path],
               scenes: list[tuple[Path, dict[str, np.ndarray]]], meta: dict, sidecar: Path) -> None:
    tm = _need("trimesh", "an STL export")
    _need("manifold3d", "an STL export")
    meshes = {}
    for k in links:
        meshes[k.link] = m = _mesh(tm, k.primitives, s)
        m.export(os.fspath(paths[k.link]))
        meta["links"][k.link]["bounds"] = m.bounds.tolist()
    records = []
    for assembly, placements in scenes:
        placed = []
        for k in links:
            T = placements[k.link].copy()
            T[:3, 3] *= s
            placed.append(meshes[k.link].copy().apply_transform(T))
        whole = tm.util.concatenate(placed)
        whole.export(os.fspath(assembly))
        records.append({"file": assembly.name, "bounds": whole.bounds.tolist(),
                        "placements": {k.link: _rows(placements[k.link], s) for k in links}})
    if len(scenes) == 1:
        meta["assembly"] = {key: v for key, v in records[0].items() if key != "placements"}
    else:
        meta["assemblies"] = records
    sidecar.write_text(json.dumps(meta, indent=1), encoding="utf-8")


def _write_glb(links: list[LinkSolid], s: float, paths: dict[str, Path],
               scenes: list[tuple[Path, dict[str, np.ndarray]]], meta: dict) -> None:
    tm = _need("trimesh", "a GLB export")
    _need("manifold3d", "a GLB export")
    meshes = {}
    for k in links:
        meshes[k.link] = m = _mesh(tm, k.primitives, s)
        one = tm.Scene()
        one.add_geometry(m, node_name=_safe(k.link), geom_name=_safe(k.link))
        one.metadata.update({"format": _FORMAT_TAG, "unit": "m", "link": k.link, "joints": meta["links"][k.link]["joints"]})
        one.export(os.fspath(paths[k.link]))
    for assembly, placements in scenes:
        scene = tm.Scene()
        for k in links:
            T = placements[k.link].copy()
            T[:3, 3] *= s
            scene.add_geometry(meshes[k.link], node_name=_safe(k.link), geom_name=_safe(k.link), transform=T)
        scene.metadata.update({**meta, "links": {k: {**v, "placement": _rows(placements[k], s)}
                                                 for k, v in meta["links"].items()}})
        scene.export(os.fspath(assembly))
    return None


def _glb_extras(path: Path) -> dict:
    import struct

    data = path.read_bytes()
    if data[:4] != b"glTF":
        raise InputError(f"{path}: not a GLB file")
    n = struct.unpack_from("<I", data, 12)[0]
    gltf = json.loads(data[20:20 + n])
    extras = gltf.get("extras") or (gltf.get("scenes") or [{}])[0].get("extras") or {}
    if extras.get("format") != _FORMAT_TAG:
        raise InputError(f"{path}: no spatialmech joint metadata in the glTF extras")
    return extras


def read_joint_frames(path) -> dict[str, Any]:
    """The joint features of a file :func:`export_cad` wrote, checked and converted to metres:
    ``{"unit": the file's unit, "links": {link: [{"joint", "type", "role", "centre", "axis"}]}}``
    (centres in metres in the frame the file is in: a link file its link's, the assembly the
    world).  STEP: the labelled edges and the header's unit; GLB: the glTF extras; STL: the
    sidecar, after checking that the mesh's bounds are the ones the sidecar records (a wrong
    scale is an ``InputError``)."""
    path = Path(os.fspath(path))
    fmt = next((f for f, ext in CAD_FORMATS.items() if path.suffix.lower() in ext), None)
    if fmt == "step":
        unit, links = _read_step(path)
    elif fmt == "glb":
        extras = _glb_extras(path)
        unit = extras["unit"]
        links = ({k: [_placed(x, v["placement"]) for x in v["joints"]] for k, v in extras["links"].items()}
                 if "links" in extras else {extras["link"]: extras["joints"]})
    elif fmt == "stl":
        unit, links = _read_stl(path)
    else:
        raise InputError(f"{path}: not a STEP, STL or GLB file")
    f = CAD_UNITS[unit]
    for feats in links.values():
        for x in feats:
            x["centre"] = [f * v for v in x["centre"]]
    return {"unit": unit, "links": links}


def _read_stl(path: Path) -> tuple[str, dict[str, list[dict]]]:
    tm = _need("trimesh", "reading an STL file")
    m = re.search(r"\.(m|mm)\.stl$", path.name, re.IGNORECASE)
    if m is None:
        raise InputError(f"{path}: the unit is not in the file name (expected NAME.m.stl or NAME.mm.stl)")
    unit = m.group(1).lower()
    sidecars = list(path.parent.glob(f"*.{unit}.json"))
    for sc in sidecars:
        meta = json.loads(sc.read_text(encoding="utf-8"))
        if meta.get("format") != _FORMAT_TAG or meta.get("unit") != unit:
            continue
        mesh = tm.load_mesh(os.fspath(path))
        if meta.get("assembly", {}).get("file") == path.name:
            _check_bounds(path, mesh.bounds, meta["assembly"]["bounds"])
            return unit, {k: [_placed(x, v["placement"]) for x in v["joints"]] for k, v in meta["links"].items()}
        for a in meta.get("assemblies", ()):  # a sample of a motion
            if a["file"] == path.name:
                _check_bounds(path, mesh.bounds, a["bounds"])
                return unit, {k: [_placed(x, a["placements"][k]) for x in v["joints"]] for k, v in meta["links"].items()}
        for k, v in meta["links"].items():
            if v["file"] == path.name:
                _check_bounds(path, mesh.bounds, v["bounds"])
                return unit, {k: v["joints"]}
    raise InputError(f"{path}: no sidecar ({path.parent}/*.{unit}.json) describes this file")


def _placed(x: dict, placement) -> dict:
    T = np.asarray(placement, float)
    return {**x, "centre": (T[:3, :3] @ np.asarray(x["centre"]) + T[:3, 3]).tolist(),
            "axis": (T[:3, :3] @ np.asarray(x["axis"])).tolist()}


def _check_bounds(path: Path, got, want) -> None:
    got, want = np.asarray(got, float), np.asarray(want, float)
    size = float(np.max(want[1] - want[0]))
    if not np.allclose(got, want, rtol=0, atol=1e-5 * size):  # float32 vertices
        raise InputError(f"{path}: its mesh bounds {got.tolist()} are not the sidecar's {want.tolist()} "
                         "(a scaled or different mesh)")
