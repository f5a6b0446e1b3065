"""URDF: the spanning tree of a mechanism's :class:`~.bodies.BodyTree`, with its loop closures in
an extension block.

URDF describes a tree of links: it cannot hold a closed loop (every link has one parent joint),
nor a joint with more than one freedom.  :func:`urdf_tree` / :func:`to_urdf` therefore write

- one ``link`` per body (the ground is the root link ``ground``; a ghost body that closes a cut
  joint is a link too), its frame at the anchor of the joint that leads to it, world-aligned at
  the reference configuration;
- one URDF ``joint`` per freedom: ``revolute`` (``continuous`` without limits), ``prismatic``
  (limits of +-100 characteristic lengths when the model has none: URDF requires them) or
  ``fixed`` for a locked freedom; a C, U or S joint is a chain of them through massless-ish
  intermediate links ``<joint>.<freedom>.frame``; a ball (plain S) is three revolutes about x, y,
  z; a helical joint's slide ``mimic``\\ s its hinge with the pitch as multiplier.  **URDF joint
  values are the joint variables q, zero at the reference configuration** (where every loop
  closes, so a URDF viewer shows the assembled mechanism); the physical value (a leg length) is
  ``offset + q``, and the offsets are listed in the extension block;
- the loop closures in an extension block, three times over (none of them is URDF):

  - ``<spatialmech:loop_closures>``: every closure, with its kind (``ball``: the two links keep
    a point in common; ``weld``: a ghost link and the real one keep a frame in common), the two
    links and the point in each link's frame; also every freedom's offset;
  - ``<drake:ball_constraint>`` per ball closure, as Drake's URDF parser reads it;
  - a ``<gazebo>`` block with an SDFormat ``joint`` per closure (``ball`` or ``fixed``): Gazebo
    converts URDF to SDFormat, copying these joints in, and SDFormat allows loops.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np

from ..model.mechanism import Mechanism
from .bodies import Axis, BodyTree, as_body_tree

__all__ = ["DRAKE_NS", "SPATIALMECH_NS", "to_urdf", "urdf_tree"]

#: XML namespaces of the extension elements.
SPATIALMECH_NS = "https://spatialmech.invalid/urdf/loop-closures/1"
DRAKE_NS = "http://drake.mit.edu"

_LINK_RGBA, _OUTPUT_RGBA = "0.25 0.45 0.8 1", "0.95 0.6 0.2 1"


def _num(x: float) -> str:
    v = float(x)
    return "0" if v == 0.0 else repr(v)


def _vec(v) -> str:
    return " ".join(_num(x) for x in np.asarray(v, dtype=float).ravel())


def _rpy_z_to(d: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw (URDF: R = Rz(yaw) Ry(pitch) Rx(roll)) of a rotation taking z to ``d``."""
    d = d / np.linalg.norm(d)
    pitch = float(np.arctan2(np.hypot(d[0], d[1]), d[2]))
    yaw = float(np.arctan2(d[1], d[0]))
    return np.array([0.0, pitch, yaw])


def _inertial(link: ET.Element, mass: float, inertia: float) -> None:
    el = ET.SubElement(link, "inertial")
    ET.SubElement(el, "origin", xyz="0 0 0", rpy="0 0 0")
    ET.SubElement(el, "mass", value=_num(mass))
    ET.SubElement(el, "inertia", ixx=_num(inertia), ixy="0", ixz="0", iyy=_num(inertia), iyz="0", izz=_num(inertia))


def _visuals(link: ET.Element, segments, frame: np.ndarray, radius: float, rgba: str, name: str) -> None:
    for a, b in segments:
        d = b - a
        el = ET.SubElement(link, "visual")
        ET.SubElement(el, "origin", xyz=_vec(0.5 * (a + b) - frame), rpy=_vec(_rpy_z_to(d)))
        geo = ET.SubElement(el, "geometry")
        ET.SubElement(geo, "cylinder", radius=_num(radius), length=_num(float(np.linalg.norm(d))))
        mat = ET.SubElement(el, "material", name=name)
        ET.SubElement(mat, "color", rgba=rgba)


def _scalar_axes(ax: Axis) -> list[Axis]:
    """A ball as three hinges about x, y, z through its centre; other axes as they are."""
    if ax.kind != "ball":
        return [ax]
    names = list(ax.freedoms) or [f"{ax.name}.rot{k}" for k in (1, 2, 3)]
    return [Axis(n, "hinge", ax.anchor, e) for n, e in zip(names, np.eye(3), strict=True)]


def urdf_tree(tree: BodyTree) -> ET.ElementTree:
    """The URDF document (an ``ElementTree``) of a body tree; see the module docstring."""
    L = tree.characteristic_length
    root = ET.Element("robot", {"name": tree.name, "xmlns:spatialmech": SPATIALMECH_NS, "xmlns:drake": DRAKE_NS})
    gyr = (0.2 * L) ** 2
    ground = ET.SubElement(root, "link", name="ground")
    _visuals(ground, tree.ground_segments, np.zeros(3), 0.02 * L, "0.55 0.55 0.55 1", "ground")
    frames: dict[str | None, np.ndarray] = {None: np.zeros(3)}
    link_name: dict[str | None, str] = {None: "ground"}
    offsets: list[tuple[str, float]] = []
    coupled = {c.joint1: c for c in tree.couplings if c.joint2 is not None}
    for b in tree.bodies:
        parent_link, parent_frame = link_name[b.parent], frames[b.parent]
        axes = [s for ax in (b.joint.axes if b.joint is not None else ()) for s in _scalar_axes(ax)]
        for k, ax in enumerate(axes):
            last = k == len(axes) - 1
            child = b.name if last else f"{ax.name}.frame"
            if not last:
                el = ET.SubElement(root, "link", name=child)
                _inertial(el, 1e-6, 1e-6 * gyr)
            kind = "fixed" if ax.locked else ("prismatic" if ax.kind == "slide" else
                                               "revolute" if ax.range is not None else "continuous")
            j = ET.SubElement(root, "joint", name=ax.name, type=kind)
            ET.SubElement(j, "parent", link=parent_link)
            ET.SubElement(j, "child", link=child)
            ET.SubElement(j, "origin", xyz=_vec(ax.anchor - parent_frame), rpy="0 0 0")
            if kind != "fixed":
                ET.SubElement(j, "axis", xyz=_vec(ax.axis))
            if kind in ("revolute", "prismatic"):
                lo, hi = ax.range if ax.range is not None else (ax.ref - 100 * L, ax.ref + 100 * L)
                ET.SubElement(j, "limit", lower=_num(lo - ax.ref), upper=_num(hi - ax.ref), effort="0", velocity="0")
            if ax.name in coupled:
                c = coupled[ax.name]
                ET.SubElement(j, "mimic", joint=str(c.joint2), multiplier=_num(c.polycoef[1]), offset="0")
            if ax.ref != 0.0:
                offsets.append((ax.name, ax.ref))
            parent_link, parent_frame = child, ax.anchor
        if not axes:  # rigidly attached
            j = ET.SubElement(root, "joint", name=f"{b.name}.fixed", type="fixed")
            ET.SubElement(j, "parent", link=parent_link)
            ET.SubElement(j, "child", link=b.name)
            ET.SubElement(j, "origin", xyz=_vec(b.origin - parent_frame), rpy="0 0 0")
            parent_frame = b.origin
        link = ET.SubElement(root, "link", name=b.name)
        _inertial(link, 1e-6 if b.ghost else 1.0, (1e-6 if b.ghost else 1.0) * gyr)
        if not b.ghost:
            rgba = _OUTPUT_RGBA if b.name == tree.output else _LINK_RGBA
            _visuals(link, b.segments, parent_frame, 0.02 * L, rgba, "output" if b.name == tree.output else "link")
        frames[b.name], link_name[b.name] = parent_frame, b.name
    # ---- the extension block
    ext = ET.SubElement(root, "spatialmech:loop_closures", length_unit=tree.length_unit, output=tree.output,
                        note="URDF cannot hold kinematic loops: these closures complete the tree above "
                             "(docs/validation.md). Joint values are q, zero at the reference; physical "
                             "value = offset + q.")
    for cl in tree.closures:
        link1, link2 = link_name[cl.body1], link_name[cl.body2]
        ET.SubElement(ext, "spatialmech:closure", name=cl.name, joint_type=cl.joint_type,
                      kind="ball" if cl.kind == "connect" else "weld", link1=link1, link2=link2,
                      xyz1=_vec(cl.anchor - frames[cl.body1]), xyz2=_vec(cl.anchor - frames[cl.body2]), rpy="0 0 0")
    for name, value in offsets:
        ET.SubElement(ext, "spatialmech:offset", joint=name, value=_num(value))
    for cl in tree.closures:
        if cl.kind != "connect":
            continue
        ball = ET.SubElement(root, "drake:ball_constraint")
        ET.SubElement(ball, "drake:ball_constraint_body_A", name=link_name[cl.body1])
        ET.SubElement(ball, "drake:ball_constraint_p_AP", value=_vec(cl.anchor - frames[cl.body1]))
        ET.SubElement(ball, "drake:ball_constraint_body_B", name=link_name[cl.body2])
        ET.SubElement(ball, "drake:ball_constraint_p_BQ", value=_vec(cl.anchor - frames[cl.body2]))
    if tree.closures:
        gz = ET.SubElement(root, "gazebo")
        for cl in tree.closures:
            j = ET.SubElement(gz, "joint", name=f"closure:{cl.name}", type="ball" if cl.kind == "connect" else "fixed")
            ET.SubElement(j, "parent").text = link_name[cl.body1]
            ET.SubElement(j, "child").text = link_name[cl.body2]
            ET.SubElement(j, "pose").text = f"{_vec(cl.anchor - frames[cl.body2])} 0 0 0"  # in the child link's frame
    ET.indent(root)
    return ET.ElementTree(root)


def to_urdf(model: Mechanism | BodyTree) -> str:
    """The URDF text of a mechanism (or of a body tree)."""
    return '<?xml version="1.0"?>\n' + ET.tostring(_root(urdf_tree(as_body_tree(model))), encoding="unicode") + "\n"


def _root(doc: ET.ElementTree) -> ET.Element:
    root = doc.getroot()
    if root is None:  # pragma: no cover - the writers always build a root
        raise RuntimeError("empty XML document")
    return root
