"""The interactive 3-D viewer: a self-contained HTML page (plotly, JavaScript inlined).

Three layers, each usable alone:

* :func:`drawing` -- pure geometry of one configuration (NumPy arrays, world frame, SI /
  the model's length unit): limb polylines, base and platform outlines, joint-axis segments,
  joint centres and the platform frame.  No plotting.
* :func:`viewer_figure` -- a ``plotly.graph_objects.Figure`` with one animation frame per
  configuration, a slider and play / pause buttons, the task positions (platform point + a
  small frame each) and the singular points as markers, equal axis scales, a legend.
* :func:`viewer_html` / :func:`write_viewer` -- the page, with ``plotly.min.js`` from the
  installed plotly package inlined (it opens offline; nothing is fetched from a CDN).

What is drawn (conventions of :mod:`..kinematics.closure`): at a configuration ``(q, D)`` the
joint points are :func:`~..kinematics.closure.joint_points`; the platform point is
``D[:3, :3] p0 + D[:3, 3]`` and the platform frame's axes are the columns of ``D[:3, :3]`` (the
platform frame is world-aligned at the reference).  A joint axis is the direction part of the
freedom's current twist (``s`` of ``(s ; s0)``; the moment part ``s0`` for a prismatic
freedom, whose twist is ``(0 ; v)``).  The figure draws the joints as solids
(:mod:`.shapes`, shared with the design studio): cylinders along the axes of R, H, U and C
joints, long thin ones for P, balls for S, in the limb's colour; the platform as a translucent
body (its polygon, or the convex hull of its attachment points and the platform point when
they are not in a plane).  :class:`Drawing` keeps the axis segments (``axes``).  The base and platform are the convex outlines
of the first / last joint points of the limbs (in their best-fit plane); thin lines join the
platform point to the platform outline's corners (the platform is one rigid body).  When two consecutive
R, H, C or U joints of a limb share their centre (a spherical linkage such as paper C's
3-RRR), the link
between them is drawn as a great-circle arc from the first joint's axis to the second's, on a
sphere whose radius grows with the limb index -- links of a spherical linkage are rigid
bodies carrying two axes through the centre, so the arc moves rigidly with the link.

Lengths are in the model's ``length_unit`` (labelled on the axes); nothing here converts
angles.  Example::

    from spatialmech import catalog
    from spatialmech.kinematics.motion import sample_motion
    from spatialmech.present.viewer import write_viewer
    mech = catalog.build("bennett")
    write_viewer("bennett.html", mech, sample_motion(mech, n=40))   # ViewerFile(frames=40, ...)
"""

from __future__ import annotations

import base64
import html as _html
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import plotly.graph_objects as go
from scipy.spatial import ConvexHull

from ..errors import InputError
from ..geometry.validate import as_finite_array
from ..kinematics.closure import Configuration, joint_points
from ..kinematics.backend import joint_twists
from ..model.mechanism import GROUND, Mechanism, Pose
from ..serialize import fields_dict
from .shapes import joint_list, joint_meshes, platform_solid
from .numbers import unit_label

__all__ = ["DIV_ID", "LIMB_COLOURS", "PLOTLY_MODES", "SINGULAR_SYMBOL", "Drawing", "ViewerFile", "drawing", "viewer_figure",
           "viewer_figure_dict", "viewer_html", "write_viewer"]

#: ``id`` of the plotly graph ``<div>`` in the page (the browser test reads it).
DIV_ID = "spatialmech-viewer"
#: Joint types whose axes are drawn as segments.
AXIS_JOINTS = ("R", "P", "H", "C", "U")
#: Joint types whose coincident-centre links are drawn as arcs (rotations about fixed axes).
ARC_JOINTS = ("R", "H", "C", "U")
#: Drawing sizes as fractions of the drawing scale (the characteristic length).
AXIS_HALF = 0.18
FRAME_LEN = 0.3
ARC_RADIUS0, ARC_RADIUS_STEP = 0.35, 0.2
#: Joint centres closer than this fraction of the scale are "the same point".
COINCIDENT = 1e-9
#: Marker of the singular points.  plotly draws 3-D markers as text glyphs: "x" is U+274C, an
#: emoji that shows as an empty box without an emoji font; "cross" is the ASCII "+", which every
#: font has (the task positions' "diamond" is U+25C6, in the basic Geometric Shapes block).
SINGULAR_SYMBOL = "cross"
#: Colours of the limbs, by limb index (cycled); the studio uses the same.
LIMB_COLOURS = _PALETTE = ("#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f")
_FRAME_COLOURS = ("#d62728", "#2ca02c", "#1f77b4")  # platform frame x, y, z


@dataclass(frozen=True, eq=False)
class Drawing:
    """The geometry of one configuration, world frame, model length unit.

    ``limbs``: per limb a (k, 3) polyline; ``base`` / ``platform``: closed outlines (k, 3)
    (a single point or a segment when the points are degenerate); ``axes``: (m, 2, 3) joint
    axis segments; ``joints``: (j, 3) joint centres with ``joint_names``; ``platform_point``
    (3,); ``platform_frame``: (3, 3) columns = platform x, y, z axes (unit vectors).
    """

    limbs: tuple[np.ndarray, ...]
    base: np.ndarray
    platform: np.ndarray
    axes: np.ndarray
    joints: np.ndarray
    joint_names: tuple[str, ...]
    platform_point: np.ndarray
    platform_frame: np.ndarray
    scale: float
    #: (m, 2, 3) segments of the internal bodies of a link-and-joint graph (each body's joints
    #: joined to their centroid); empty for limbs from the ground to the platform.
    bodies: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 3)))

    def points(self) -> np.ndarray:
        """Every drawn point (for bounding boxes and finiteness checks)."""
        parts = [*self.limbs, self.base, self.platform, self.axes.reshape(-1, 3), self.bodies.reshape(-1, 3), self.joints,
                 self.platform_point[None, :], self.platform_point + FRAME_LEN * self.scale * self.platform_frame.T]
        return np.vstack(parts)

    def to_dict(self) -> dict:
        """JSON (docs/json.md): points in the model's length unit (``*_len``); the platform
        frame's columns are unit vectors."""
        return fields_dict(self, {n: f"{n}_len" for n in ("limbs", "base", "platform", "axes", "joints", "platform_point",
                                                          "scale", "bodies")})


#: How a written page gets plotly.js: ``inline`` (in the page: one self-contained file that opens
#: offline, about 4.8 MB), ``cdn`` (a ``<script>`` from cdn.plot.ly: a small page that needs the
#: network), ``directory`` (a ``<script src="plotly.min.js">`` next to the page, the file copied
#: there once: small pages that share it, offline).
PLOTLY_MODES = ("inline", "cdn", "directory")


@dataclass(frozen=True)
class ViewerFile:
    """What :func:`write_viewer` wrote (``plotly``: one of :data:`PLOTLY_MODES`)."""

    out: str
    frames: int
    bytes: int
    plotly: str = "inline"

    def to_dict(self) -> dict:
        return fields_dict(self)


# ---------------------------------------------------------------------------- geometry
def _outline_order(points: np.ndarray, scale: float) -> np.ndarray:
    """Indices of a closed outline through ``points`` (n, 3): the convex hull in their best-fit
    plane; a segment along the principal direction when they are (nearly) collinear."""
    n = len(points)
    if n == 0:
        return np.zeros(0, int)
    # drop coincident points (keep the first of each)
    picked: list[int] = []
    for i in range(n):
        if all(np.linalg.norm(points[i] - points[j]) > COINCIDENT * scale for j in picked):
            picked.append(i)
    keep = np.array(picked)
    if len(keep) == 1:
        return keep
    P = points[keep] - points[keep].mean(axis=0)
    _, sv, vt = np.linalg.svd(P, full_matrices=False)
    if len(keep) == 2 or sv[1] <= 1e-6 * sv[0]:
        t = P @ vt[0]
        return keep[[int(np.argmin(t)), int(np.argmax(t))]]
    hull = ConvexHull(P @ vt[:2].T)
    return keep[hull.vertices]  # counter-clockwise in the plane


def _closed(points: np.ndarray, order: np.ndarray) -> np.ndarray:
    pts = points[order]
    return np.vstack([pts, pts[:1]]) if len(order) > 2 else pts


def _arc(centre, a, b, radius, n=12) -> np.ndarray:
    """Great-circle arc from direction ``a`` to direction ``b`` (unit) at ``radius``."""
    ang = float(np.arccos(np.clip(a @ b, -1.0, 1.0)))
    if ang < 1e-9 or np.pi - ang < 1e-9:
        return centre + radius * np.array([a, b])
    t = np.linspace(0.0, 1.0, n)[:, None]
    w = (np.sin((1 - t) * ang) * a + np.sin(t * ang) * b) / np.sin(ang)
    return centre + radius * w


def _freedom_direction(kind: str, twist: np.ndarray) -> np.ndarray:
    d = twist[3:] if kind == "P" else twist[:3]
    return d / np.linalg.norm(d)


def _check_config(mech: Mechanism, config, name: str) -> None:
    if not isinstance(config, Configuration):
        raise InputError(f"{name}: expected a Configuration, got {type(config).__name__}")
    as_finite_array(config.q, f"{name}.q", shape=(len(mech.freedom_refs),))
    as_finite_array(config.D, f"{name}.D", shape=(4, 4))
    as_finite_array(config.B, f"{name}.B", shape=(len(mech.bodies), 4, 4))


def _attachments(mech: Mechanism, pts: list[np.ndarray], link: str) -> np.ndarray:
    """The joint points by which limbs are attached to hub ``link`` (first joints of limbs that
    start there, last joints of limbs that end there)."""
    out = [P[0] for limb, P in zip(mech.limbs, pts, strict=True) if limb.base == link]
    out += [P[-1] for limb, P in zip(mech.limbs, pts, strict=True) if mech.limb_tip(limb) == link]
    return np.array(out).reshape(-1, 3)


_ORDERS: weakref.WeakKeyDictionary[Mechanism, np.ndarray] = weakref.WeakKeyDictionary()


def _platform_order(mech: Mechanism) -> np.ndarray:
    """The platform outline's corner order, from the reference configuration (cached per
    mechanism: the studio redraws at every drag)."""
    if mech in _ORDERS:
        return _ORDERS[mech]
    ref = Configuration.reference(mech)
    last = _attachments(mech, joint_points(mech, ref), mech.output)
    _ORDERS[mech] = order = _outline_order(last, mech.characteristic_length)
    return order


def drawing(mech: Mechanism, config: Configuration) -> Drawing:
    """The geometry of ``mech`` at ``config`` (see the module docstring for what is drawn).

    Pure and cheap (a product of exponentials per limb).  Raises ``ValueError`` when the
    configuration does not match the mechanism or contains NaN.
    """
    _check_config(mech, config, "config")
    s = mech.characteristic_length
    pts = joint_points(mech, config)
    tw = joint_twists(mech, config)
    R, p = config.D[:3, :3], config.D[:3, 3]
    pp = R @ mech.platform_point + p

    limbs, axes, centres, names = [], [], [], []
    for li, limb in enumerate(mech.limbs):
        refs = [(k, r) for k, r in enumerate(r for r in mech.freedom_refs if r.limb == li)]
        by_joint: dict[int, list] = {}
        for k, r in refs:
            by_joint.setdefault(r.joint, []).append((r.freedom.kind, tw[li][:, k]))
        P = pts[li]
        for j, joint in enumerate(limb.joints):
            centres.append(P[j])
            names.append(joint.name)
            if joint.type in AXIS_JOINTS:
                seen: list[np.ndarray] = []
                for kind, twist in by_joint[j]:
                    d = _freedom_direction(kind, twist)
                    if any(abs(d @ e) > 1 - 1e-9 for e in seen):
                        continue  # C joint: rotation and slide share the axis
                    seen.append(d)
                    axes.append([P[j] - AXIS_HALF * s * d, P[j] + AXIS_HALF * s * d])
        # the limb polyline, with arcs for links between joints that share their centre
        rho = (ARC_RADIUS0 + ARC_RADIUS_STEP * li) * s
        path = [P[0]]
        for j in range(len(limb.joints) - 1):
            piece = [P[j], P[j + 1]]
            out_f, in_f = by_joint[j][-1], by_joint[j + 1][0]
            if (
                np.linalg.norm(P[j + 1] - P[j]) <= COINCIDENT * s
                and {limb.joints[j].type, limb.joints[j + 1].type} <= set(ARC_JOINTS)
                and out_f[0] != "P" and in_f[0] != "P"
            ):  # a link of a spherical linkage: spoke, arc, spoke
                a, b = _freedom_direction(*out_f), _freedom_direction(*in_f)
                piece = [P[j], *_arc(P[j], a, b, rho), P[j + 1]]
            path.extend(piece[1:])
        limbs.append(np.array(path))

    first = _attachments(mech, pts, GROUND)
    last = _attachments(mech, pts, mech.output)
    order = _platform_order(mech)  # from the reference: the same corners at every configuration
    segs = []
    for body in mech.bodies:
        at = _attachments(mech, pts, body)
        c = at.mean(axis=0)
        segs += [[c, a] for a in at]
    return Drawing(
        limbs=tuple(limbs),
        base=_closed(first, _outline_order(first, s)),
        platform=_closed(last, order),
        axes=np.array(axes).reshape(-1, 2, 3),
        joints=np.array(centres),
        joint_names=tuple(names),
        platform_point=pp,
        platform_frame=R.copy(),
        scale=s,
        bodies=np.array(segs).reshape(-1, 2, 3),
    )


# ---------------------------------------------------------------------------- figure
def _segments(segs: np.ndarray) -> tuple[list, list, list]:
    """(m, 2, 3) segments as x, y, z lists with ``None`` gaps (one plotly trace)."""
    xs, ys, zs = [], [], []
    for a, b in segs:
        xs += [a[0], b[0], None]
        ys += [a[1], b[1], None]
        zs += [a[2], b[2], None]
    return xs, ys, zs


def _xyz(points: np.ndarray) -> dict:
    points = np.asarray(points, float).reshape(-1, 3)
    return {"x": points[:, 0].tolist(), "y": points[:, 1].tolist(), "z": points[:, 2].tolist()}


def _frame_segments(origin: np.ndarray, R: np.ndarray, length: float, axis: int) -> np.ndarray:
    return np.array([[origin, origin + length * R[:, axis]]])


def _solids(mech: Mechanism, config: Configuration, d: Drawing) -> tuple[dict | None, list[dict]]:
    """The platform body and the joint solids per limb (:mod:`.shapes`, as the studio draws
    them)."""
    solid = platform_solid(mech, d.platform, d.limbs, d.platform_point)
    return solid, joint_meshes(joint_list(mech, config), len(mech.limbs), d.scale)


_TYPED = {"float32": "f4", "float64": "f8", "int32": "i4", "int16": "i2", "int8": "i1", "uint8": "u1"}


def _typed(v):
    """A NumPy vector as plotly.js's base64 typed array (what plotly's validated figures write),
    anything else unchanged; int64 is written as int32 (plotly.js has no 64-bit integers)."""
    if not isinstance(v, np.ndarray) or v.size == 0:
        return v
    a = v.astype(np.int32) if v.dtype == np.int64 else v
    code = _TYPED.get(str(a.dtype))
    if code is None or a.ndim != 1:
        return v
    return {"dtype": code, "bdata": base64.b64encode(np.ascontiguousarray(a).tobytes()).decode("ascii")}


def _plain(kind: str):
    """A trace maker like ``go.Scatter3d``, giving a plain dict (arrays typed): animation frames
    built without plotly's validated setters (issue 29: 3-4 s of the demo for 564 frames)."""
    return lambda **kw: {"type": kind, **{k: _typed(v) for k, v in kw.items()}}


_GO = {"scatter3d": lambda **kw: go.Scatter3d(**kw), "mesh3d": lambda **kw: go.Mesh3d(**kw)}
_PLAIN = {"scatter3d": _plain("scatter3d"), "mesh3d": _plain("mesh3d")}


def _mesh3d(mesh: dict | None, faces: bool, make=_GO):
    """A mesh as a plotly trace, compact in the page: float32 vertices and int32 triangles
    (plotly writes NumPy arrays as base64 typed arrays); ``faces=False`` leaves the triangles
    out (an animation frame of a mesh whose topology does not change)."""
    if mesh is None:
        return make["mesh3d"](x=[], y=[], z=[])
    V = np.asarray(mesh["vertices"], np.float32)
    kw: dict[str, np.ndarray] = {"x": V[:, 0], "y": V[:, 1], "z": V[:, 2]}
    if faces:
        T = np.asarray(mesh["triangles"], np.int32)
        kw.update(i=T[:, 0], j=T[:, 1], k=T[:, 2])
    return make["mesh3d"](**kw)


def _animated(d: Drawing, fill: bool, solids: tuple[dict | None, list[dict]], first: bool = False,
              make=_GO) -> list:
    """The traces that move, in a fixed order; styles (and the joint solids' triangles, the same
    in every frame) are given only in the first frame.  ``make``: plotly objects (``_GO``) or
    plain dicts (``_PLAIN``, the frames of a page)."""
    sc = make["scatter3d"]
    out = [sc(**_xyz(d.platform))]
    x, y, z = _segments(np.array([[d.platform_point, q] for q in d.platform[: max(1, len(d.platform) - 1)]]))
    out.append(sc(x=x, y=y, z=z))
    solid, joints = solids
    if fill:  # the platform body: its polygon, or the hull of a non-planar one (triangles may change)
        out.append(_mesh3d(solid, True, make))
    out += [sc(**_xyz(l)) for l in d.limbs]
    out += [_mesh3d(m, first, make) for m in joints]
    if len(d.bodies):
        x, y, z = _segments(d.bodies)
        out.append(sc(x=x, y=y, z=z))
    out.append(sc(**_xyz(d.joints)))
    for k in range(3):
        x, y, z = _segments(_frame_segments(d.platform_point, d.platform_frame, FRAME_LEN * d.scale, k))
        out.append(sc(x=x, y=y, z=z))
    return out


def _style_animated(traces: list, d: Drawing, mech: Mechanism, fill: bool) -> None:
    i = 0
    traces[i].update(mode="lines", name="platform", line=dict(color="#ff7f0e", width=6), legendgroup="platform")
    i += 1
    traces[i].update(mode="lines", name="platform body (platform point to its joints)", legendgroup="platform",
                     showlegend=False, line=dict(color="#ff7f0e", width=2), hoverinfo="skip")
    i += 1
    if fill:
        traces[i].update(color="#ff7f0e", opacity=0.4, name="platform", legendgroup="platform", showlegend=False,
                         hoverinfo="skip")
        i += 1
    for li, limb in enumerate(mech.limbs):
        traces[i].update(mode="lines", name=limb_label(limb.name), line=dict(color=_PALETTE[li % len(_PALETTE)], width=7))
        i += 1
    for li in range(len(mech.limbs)):
        traces[i].update(color=_PALETTE[li % len(_PALETTE)], opacity=1.0, flatshading=True, hoverinfo="skip",
                         name="joint solids", legendgroup="joints",
                         showlegend=li == 0)
        i += 1
    if len(d.bodies):
        traces[i].update(mode="lines", name=f"internal bodies ({', '.join(mech.bodies)})",
                         line=dict(color="#7f7f7f", width=9))
        i += 1
    traces[i].update(mode="markers", name="joints", marker=dict(size=4, color="#333333"), text=list(d.joint_names),
                     hovertemplate="%{text}<br>(%{x:.4g}, %{y:.4g}, %{z:.4g})<extra></extra>")
    i += 1
    for k, c in enumerate(_FRAME_COLOURS):
        traces[i].update(mode="lines", name="platform frame (x red, y green, z blue)", line=dict(color=c, width=6),
                         legendgroup="platform frame", showlegend=k == 0)
        i += 1


def limb_label(name: str) -> str:
    """A limb's legend entry: ``"limb leg1"``, but ``"limb1"`` (not ``"limb limb1"``) when the
    name already says it is a limb."""
    return name if name.lower().startswith("limb") else f"limb {name}"


def _singular_point(mech: Mechanism, item, k: int) -> np.ndarray:
    if isinstance(item, Configuration):
        _check_config(mech, item, f"singular_points[{k}]")
        return item.D[:3, :3] @ mech.platform_point + item.D[:3, 3]
    return as_finite_array(item, f"singular_points[{k}]", shape=(3,))


def viewer_figure(
    mech: Mechanism,
    configs: Sequence[Configuration],
    *,
    title: str | None = None,
    task_positions: Sequence[Pose] = (),
    singular_points: Sequence = (),
    stop_points: Sequence = (),
) -> go.Figure:
    """The animated plotly figure of ``mech`` along ``configs`` (one frame per configuration).

    ``task_positions``: platform poses (:class:`Pose`, e.g. ``mech.positions``) shown as the
    platform point and a small frame each, labelled with the pose name.  ``singular_points``:
    platform points (3-vectors, world frame) or :class:`Configuration` objects (their platform
    point is drawn).  ``stop_points``: the same, where a traced motion stopped (a bifurcation
    point or a crossing branch), drawn as open squares.  Pure: builds the figure, writes nothing.  Raises ``ValueError`` on an
    empty or mismatched ``configs`` and on NaN anywhere.
    """
    fig, frames = _viewer_parts(mech, configs, title, task_positions, singular_points, _GO, stop_points)
    fig.frames = frames
    return fig


def viewer_figure_dict(
    mech: Mechanism,
    configs: Sequence[Configuration],
    *,
    title: str | None = None,
    task_positions: Sequence[Pose] = (),
    singular_points: Sequence = (),
    stop_points: Sequence = (),
) -> dict:
    """:func:`viewer_figure` as the plain dict plotly writes into a page (``Figure.to_dict()``:
    arrays as base64 typed arrays), its animation frames built as dicts without plotly's
    validated setters (the static traces and the layout still go through them).  For writing a
    page: ``plotly.io.to_html(d, validate=False, ...)``."""
    fig, frames = _viewer_parts(mech, configs, title, task_positions, singular_points, _PLAIN, stop_points)
    return {**fig.to_dict(), "frames": frames}


def _viewer_parts(mech, configs, title, task_positions, singular_points, make, stop_points=()):
    """The figure without its frames, and the frames (``make``: plotly objects or plain dicts)."""
    if not isinstance(mech, Mechanism):
        raise InputError(f"mech: expected a Mechanism, got {type(mech).__name__}")
    configs = list(configs)
    if not configs:
        raise InputError("configs: at least one configuration is needed")
    for k, c in enumerate(configs):
        _check_config(mech, c, f"configs[{k}]")
    poses = list(task_positions)
    for k, pz in enumerate(poses):
        if not isinstance(pz, Pose):
            raise InputError(f"task_positions[{k}]: expected a Pose, got {type(pz).__name__}")
    sing = np.array([_singular_point(mech, x, k) for k, x in enumerate(singular_points)]).reshape(-1, 3)
    stops = np.array([_singular_point(mech, x, k) for k, x in enumerate(stop_points)]).reshape(-1, 3)

    order = _platform_order(mech)
    draws = [drawing(mech, c) for c in configs]
    d0 = draws[0]
    s = d0.scale
    fill = len(order) >= 3

    static = []
    static.append(go.Scatter3d(**_xyz(d0.base), mode="lines", name="base", line=dict(color="#555555", width=6),
                               legendgroup="base"))
    if len(d0.base) >= 4:
        n = len(d0.base) - 1
        static.append(go.Mesh3d(**_xyz(d0.base[:-1]), i=[0] * (n - 2), j=list(range(1, n - 1)), k=list(range(2, n)),
                                color="#999999", opacity=0.3, name="base", legendgroup="base", hoverinfo="skip"))
    path = np.array([d.platform_point for d in draws])
    static.append(go.Scatter3d(**_xyz(path), mode="lines", name="platform point path",
                               line=dict(color="#ff7f0e", width=2, dash="dot")))
    extra = [path]
    if poses:
        P = np.array([pz.p for pz in poses])
        static.append(go.Scatter3d(**_xyz(P), mode="markers+text", name="task positions",
                                   text=[pz.name or f"#{k + 1}" for k, pz in enumerate(poses)],
                                   marker=dict(size=5, color="#000000", symbol="diamond"), legendgroup="task"))
        for k, colour in enumerate(_FRAME_COLOURS):
            segs = np.concatenate([_frame_segments(pz.p, pz.R, 0.6 * FRAME_LEN * s, k) for pz in poses])
            x, y, z = _segments(segs)
            static.append(go.Scatter3d(x=x, y=y, z=z, mode="lines", line=dict(color=colour, width=3), legendgroup="task",
                                       name="task frames", showlegend=False, hoverinfo="skip"))
            extra.append(segs.reshape(-1, 3))
    if len(sing):
        static.append(go.Scatter3d(**_xyz(sing), mode="markers", name="singular points",
                                   marker=dict(size=9, color="#d62728", symbol=SINGULAR_SYMBOL)))
        extra.append(sing)
    if len(stops):
        static.append(go.Scatter3d(**_xyz(stops), mode="markers", name="bifurcation (the tracker stopped here)",
                                   marker=dict(size=11, color="#9467bd", symbol="square-open")))
        extra.append(stops)

    solids = [_solids(mech, c, d) for c, d in zip(configs, draws, strict=True)]
    first = _animated(d0, fill, solids[0], first=True)
    _style_animated(first, d0, mech, fill)
    anim_idx = list(range(len(static), len(static) + len(first)))
    frames = [(go.Frame if make is _GO else dict)(data=_animated(d, fill, so, make=make), traces=anim_idx, name=str(k))
              for k, (d, so) in enumerate(zip(draws, solids, strict=True))]

    meshes = [m["vertices"] for so in solids for m in ([so[0]] if so[0] is not None else []) + so[1]]
    allp = np.vstack([d.points() for d in draws] + extra + meshes)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    centre, half = (lo + hi) / 2, max(float(np.max(hi - lo)) / 2 * 1.08, 1e-9 * s, 1e-12)
    unit = unit_label(mech.length_unit)
    scene: dict[str, object] = dict(aspectmode="cube")
    for ax, c in zip("xyz", centre, strict=True):
        scene[f"{ax}axis"] = dict(range=[c - half, c + half], title=dict(text=f"{ax} [{unit}]"), autorange=False)

    anim = dict(mode="immediate", frame=dict(duration=0, redraw=True), transition=dict(duration=0))
    fig = go.Figure(data=static + first)
    fig.update_layout(
        title=title if title is not None else f"{mech.name}: {len(configs)} configurations",
        scene=scene,
        legend=dict(itemsizing="constant"),
        margin=dict(l=0, r=0, t=40, b=0),
        uirevision="spatialmech",
        updatemenus=[dict(
            type="buttons", direction="left", x=0.0, y=0.0, xanchor="left", yanchor="top", pad=dict(t=50, r=10),
            showactive=False,
            buttons=[
                dict(label="Play", method="animate",
                     args=[None, dict(mode="immediate", fromcurrent=True, frame=dict(duration=60, redraw=True),
                                      transition=dict(duration=0))]),
                dict(label="Pause", method="animate", args=[[None], anim]),
            ],
        )],
        sliders=[dict(
            active=0, x=0.12, len=0.88, y=0.0, yanchor="top", pad=dict(t=40, b=10),
            currentvalue=dict(prefix="configuration ", visible=True),
            steps=[dict(label=str(k), method="animate", args=[[str(k)], anim]) for k in range(len(configs))],
        )],
    )
    return fig, frames


def viewer_html(
    mech: Mechanism,
    configs: Sequence[Configuration],
    *,
    title: str | None = None,
    task_positions: Sequence[Pose] = (),
    singular_points: Sequence = (),
    stop_points: Sequence = (),
    full_html: bool = True,
    include_plotlyjs: bool | str = True,
    div_id: str = DIV_ID,
    default_height: str = "92vh",
) -> str:
    """The viewer page as a string: plotly.min.js inlined (``include_plotlyjs=True``, works
    offline), the figure of :func:`viewer_figure` in a ``<div id="spatialmech-viewer">``
    (``div_id``), not auto-playing.  ``full_html=False`` gives an embeddable ``<div>`` (for a
    report that embeds several viewers, inline the JavaScript once and pass
    ``include_plotlyjs=False`` after).  Written from :func:`viewer_figure_dict` (the same page
    content, its frames without plotly's validated setters)."""
    import plotly.io as pio

    fig = viewer_figure_dict(mech, configs, title=title, task_positions=task_positions,
                             singular_points=singular_points, stop_points=stop_points)
    page = pio.to_html(
        fig, validate=False, include_plotlyjs=include_plotlyjs, full_html=full_html, auto_play=False, div_id=div_id,
        default_height=default_height, config={"displaylogo": False, "responsive": True},
    )
    if full_html:
        name = _html.escape(title if title is not None else mech.name)
        page = page.replace("<head>", f"<head><title>{name}</title>", 1)
    return page


def write_viewer(
    path,
    mech: Mechanism,
    configs: Sequence[Configuration],
    *,
    title: str | None = None,
    task_positions: Sequence[Pose] = (),
    singular_points: Sequence = (),
    plotly: str = "inline",
    stop_points: Sequence = (),
) -> ViewerFile:
    """Write :func:`viewer_html` (a full page) to ``path`` (UTF-8); ``plotly`` says how the page
    gets plotly.js (:data:`PLOTLY_MODES`; ``directory`` also writes ``plotly.min.js`` next to
    the page unless the same file is there already)."""
    if plotly not in PLOTLY_MODES:
        raise InputError(f"plotly: expected one of {', '.join(PLOTLY_MODES)}, got {plotly!r}")
    configs = list(configs)
    include: bool | str = True if plotly == "inline" else plotly
    page = viewer_html(mech, configs, title=title, task_positions=task_positions, singular_points=singular_points,
                       stop_points=stop_points, include_plotlyjs=include)
    data = page.encode("utf-8")
    p = Path(path)
    p.write_bytes(data)
    if plotly == "directory":
        from plotly.offline import get_plotlyjs

        js = get_plotlyjs().encode("utf-8")
        target = p.parent / "plotly.min.js"
        if not (target.is_file() and target.stat().st_size == len(js) and target.read_bytes() == js):
            target.write_bytes(js)
    return ViewerFile(str(p), len(configs), len(data), plotly)
