"""MuJoCo models (MJCF): write a mechanism's :class:`~.bodies.BodyTree`, read one back.

:func:`mjcf_tree` / :func:`to_mjcf` write the body tree as an MJCF document (built with
``xml.etree.ElementTree``):

- ``compiler angle="radian"``; gravity off and contacts off (``option``), the implicitfast
  integrator; every body has the same explicit inertia (mass 1, radius of gyration 0.2 L, L the
  characteristic length), so the file needs no unit of mass; joint damping of 10 per second
  (times the body's inertia about, or mass along, the joint) and a little armature;
- bodies nested as the spanning tree, frames world-aligned at the reference configuration; a
  ``hinge`` / ``slide`` per freedom with ``ref`` = the freedom's offset (its value is the
  physical value ``offset + q``: a leg length, an angle in radians), ``range`` from its limits;
  a ``ball`` per plain S joint;
- ``equality``: ``connect`` for cut S joints, ``weld`` of a ghost body for other cut joints,
  ``joint`` equalities for locked freedoms and helical couplings;
- ``actuator``: a ``position`` actuator per actuated freedom (critically damped), named by the
  freedom, its ``ctrlrange`` the freedom's limits;
- geometry to look at in the viewer: capsules for links, cylinders along hinge and slide axes
  (actuated ones red), spheres for spherical joints; they never collide;
- with mass properties (``to_mjcf(model, inertias)``, by link name), each body's ``inertial`` is
  its link's (shared equally by a link's body and its ghost copies);
- ``custom/text name="spatialmech"``: JSON with what MJCF cannot say (model name, unit, output
  body, limb names and end links, internal bodies, joint types and described directions),
  read back by :func:`from_mjcf`.

:func:`from_mjcf` reads an MJCF file with the ``mujoco`` package (so every form MuJoCo accepts
is read: defaults, orientations, includes), builds a body tree in world coordinates at
``qpos0`` and turns it into a mechanism (:func:`~.bodies.mechanism_from_tree`): hinges,
slides and balls, ``connect`` (S) and ``weld`` closures, joint-equality locks and helical
couplings.  The output link is the metadata's, or a body named ``platform``.  Without the
metadata (a hand-written file) the link graph is cut into limbs between hub links: a model with
internal loops (a Delta's parallelograms) comes back in graph form, with the same mobility.
"""

from __future__ import annotations

import json
from collections import Counter
import os
import xml.etree.ElementTree as ET

import numpy as np

from ..errors import InputError
from ..model.mechanism import Mechanism, Mode
from ..model.topology import OUTPUT
from .bodies import Axis, Body, BodyTree, Closure, Coupling, TreeJoint, as_body_tree, mechanism_from_tree

__all__ = ["METADATA", "from_mjcf", "mjcf_tree", "read_body_tree", "to_mjcf"]

#: Name of the ``custom/text`` element holding the spatialmech metadata (JSON).
METADATA = "spatialmech"

#: Colours (RGBA) of the drawing.
_GROUND, _LINK, _OUTPUT, _JOINT, _ACTUATED, _BALL = ("0.55 0.55 0.55 1", "0.25 0.45 0.8 1", "0.95 0.6 0.2 1",
                                                    "0.35 0.35 0.35 1", "0.85 0.15 0.15 1", "0.2 0.7 0.3 1")


def _num(x: float) -> str:
    """A float as the shortest text that reads back to the same double (no rounding)."""
    v = float(x)
    return "0" if v == 0.0 else repr(v)


def _vec(v) -> str:
    return " ".join(_num(x) for x in np.asarray(v, dtype=float).ravel())


def _require_mujoco():
    try:
        import mujoco  # type: ignore[import-untyped]
    except ImportError:  # pragma: no cover - mujoco is a dependency; a broken install still gets one line
        raise InputError("the 'mujoco' package is not installed: pip install 'mujoco>=3.2'") from None
    return mujoco


# ------------------------------------------------------------------ writing
def _geoms(parent: ET.Element, body: Body, origin: np.ndarray, L: float, colour: str) -> None:
    r = 0.02 * L
    for a, b in body.segments:
        ET.SubElement(parent, "geom", type="capsule", size=_num(r), fromto=_vec(np.r_[a - origin, b - origin]),
                      rgba=colour)
    if body.joint is None:
        return
    for ax in body.joint.axes:
        if ax.name.endswith(":slide"):
            continue
        at = ax.anchor - origin
        if ax.kind == "ball":
            ET.SubElement(parent, "geom", type="sphere", size=_num(0.045 * L), pos=_vec(at), rgba=_BALL)
        else:
            h = (0.07 if ax.kind == "hinge" else 0.12) * L
            rad = (0.03 if ax.kind == "hinge" else 0.015) * L
            ET.SubElement(parent, "geom", type="cylinder", size=_num(rad),
                          fromto=_vec(np.r_[at - h * ax.axis, at + h * ax.axis]),
                          rgba=_ACTUATED if ax.actuated else _JOINT)


def _joint(parent: ET.Element, ax: Axis, origin: np.ndarray, gyr: float) -> None:
    inertia = 1.0 if ax.kind == "slide" else gyr  # of a body of mass 1 along / about the joint
    attrs = {"name": ax.name, "type": ax.kind, "pos": _vec(ax.anchor - origin),
             "damping": _num(10.0 * inertia), "armature": _num(0.01 * inertia)}
    if ax.kind != "ball":
        attrs["axis"] = _vec(ax.axis)
        if ax.ref != 0.0:
            attrs["ref"] = _num(ax.ref)
        if ax.range is not None:
            attrs["range"] = _vec(ax.range)
    ET.SubElement(parent, "joint", attrs)


def _inertial(el: ET.Element, body: Body, inertias: dict | None, copies: dict[str, int], gyr: float) -> None:
    """The body's ``inertial``: its link's mass properties (shared equally by the link's body and
    its ghost copies, which a weld makes one rigid body) or the default mass 1."""
    li = None if inertias is None else inertias.get(body.link)
    if li is None:
        ET.SubElement(el, "inertial", pos="0 0 0", mass="1", diaginertia=_vec([gyr, gyr, gyr]))
        return
    n = copies[body.link]
    if li.mass_kg <= 0:
        raise InputError(f"masses: link {body.link!r} has no mass; MuJoCo needs a positive mass for every moving body")
    inertia = li.inertia_kg_m2 / n
    ET.SubElement(el, "inertial", pos=_vec(li.com_m - body.origin), mass=_num(li.mass_kg / n),
                  fullinertia=_vec([inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2],
                                    inertia[1, 2]]))


def mjcf_tree(tree: BodyTree, inertias: dict | None = None) -> ET.ElementTree:
    """The MJCF document (an ``ElementTree``) of a body tree; see the module docstring.
    ``inertias``: mass properties by link name (:class:`~spatialmech.model.inertia.LinkInertia`,
    world coordinates at the reference) written as each body's ``inertial`` instead of the
    default (mass 1, radius of gyration 0.2 L)."""
    L = tree.characteristic_length
    root = ET.Element("mujoco", model=tree.name)
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    opt = ET.SubElement(root, "option", gravity="0 0 0", timestep="0.002", integrator="implicitfast")
    ET.SubElement(opt, "flag", contact="disable")
    custom = ET.SubElement(root, "custom")
    ET.SubElement(custom, "text", name=METADATA, data=json.dumps(tree.metadata(), separators=(",", ":")))
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "geom", contype="0", conaffinity="0", group="1")
    pts = [p for b in tree.bodies for s in b.segments for p in s] + [p for s in tree.ground_segments for p in s]
    pts += [b.origin for b in tree.bodies]
    lo, hi = np.min(pts, axis=0), np.max(pts, axis=0)
    ET.SubElement(root, "statistic", center=_vec(0.5 * (lo + hi)), extent=_num(max(0.6 * float(np.max(hi - lo)), L)))
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", pos=_vec(0.5 * (lo + hi) + [0, 0, 3 * L]), dir="0 0 -1", directional="true")
    ground = Body("ground", "ground", None, np.zeros(3), None, segments=tree.ground_segments)
    _geoms(world, ground, np.zeros(3), L, _GROUND)
    elements: dict[str | None, ET.Element] = {None: world}
    origins: dict[str | None, np.ndarray] = {None: np.zeros(3)}
    gyr = (0.2 * L) ** 2
    copies = dict(Counter(b.link for b in tree.bodies))
    for b in tree.bodies:
        el = ET.SubElement(elements[b.parent], "body", name=b.name, pos=_vec(b.origin - origins[b.parent]))
        _inertial(el, b, inertias, copies, gyr)
        if b.joint is not None:
            for ax in b.joint.axes:
                _joint(el, ax, b.origin, gyr)
        colour = _OUTPUT if b.name == tree.output else _LINK
        _geoms(el, b, b.origin, L, colour)
        elements[b.name], origins[b.name] = el, b.origin
    for c in tree.closures:  # a cut S joint is drawn on the body it holds
        on = c.body2 if c.body2 is not None else c.body1
        if c.kind == "connect" and on is not None:
            ET.SubElement(elements[on], "geom", type="sphere", size=_num(0.045 * L), pos=_vec(c.anchor - origins[on]),
                          rgba=_BALL)
    if tree.closures or tree.couplings:
        eq = ET.SubElement(root, "equality")
        for c in tree.closures:
            b1, b2 = c.body1, c.body2
            if b1 is None:  # the anchor is given in body1's frame; the world cannot be body1
                b1, b2 = b2, None
            attrs = {"name": f"{c.kind}:{c.name}", "body1": str(b1)}
            if b2 is not None:
                attrs["body2"] = b2
            if c.kind == "connect":
                attrs["anchor"] = _vec(c.anchor - origins[b1])
            else:  # weld: anchor in body2's frame; relative pose that of the reference (qpos0)
                attrs["anchor"] = _vec(c.anchor - origins[b2])
                attrs["torquescale"] = _num(L)
            ET.SubElement(eq, c.kind, attrs)
        for cp in tree.couplings:
            attrs = {"name": cp.name, "joint1": cp.joint1, "polycoef": _vec([*cp.polycoef, 0, 0, 0])}
            if cp.joint2 is not None:
                attrs["joint2"] = cp.joint2
            ET.SubElement(eq, "joint", attrs)
    acts = tree.actuated
    if acts:
        act = ET.SubElement(root, "actuator")
        for ax in acts:
            kp = 400.0 if ax.kind == "slide" else 400.0 * gyr
            attrs = {"name": ax.name, "joint": ax.name, "kp": _num(kp), "dampratio": "1"}
            if ax.range is not None:
                attrs["ctrlrange"] = _vec(ax.range)
            ET.SubElement(act, "position", attrs)
    ET.indent(root)
    return ET.ElementTree(root)


def to_mjcf(model: Mechanism | BodyTree, inertias: dict | None = None) -> str:
    """The MJCF text of a mechanism (or of a body tree); it loads with ``mujoco.MjModel.from_xml_string``.
    ``inertias``: mass properties by link name (see :func:`mjcf_tree`)."""
    root = mjcf_tree(as_body_tree(model), inertias).getroot()
    if root is None:  # pragma: no cover - the writer always builds a root
        raise RuntimeError("empty MJCF document")
    return ET.tostring(root, encoding="unicode") + "\n"


# ------------------------------------------------------------------ reading
def _text(m, mujoco, name: str) -> str | None:
    for i in range(m.ntext):
        if mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_TEXT, i) == name:
            adr, size = int(m.text_adr[i]), int(m.text_size[i])
            return bytes(m.text_data[adr:adr + size]).split(b"\0", 1)[0].decode("utf-8")
    return None


def read_body_tree(path) -> BodyTree:
    """A :class:`~.bodies.BodyTree` (world coordinates at ``qpos0``) from an MJCF file, read by MuJoCo."""
    mujoco = _require_mujoco()
    p = os.fspath(path)
    try:
        m = mujoco.MjModel.from_xml_path(p)
    except ValueError as e:  # MuJoCo's parse and compile errors
        raise InputError(f"{p}: MuJoCo cannot load it: {str(e).strip().splitlines()[0]}") from None
    d = mujoco.MjData(m)
    d.qpos[:] = m.qpos0
    mujoco.mj_kinematics(m, d)
    meta_text = _text(m, mujoco, METADATA)
    try:
        meta = json.loads(meta_text) if meta_text else {}
    except json.JSONDecodeError as e:
        raise InputError(f"{p}: custom text {METADATA!r} is not JSON: {e}") from None

    def name(obj, i: int, prefix: str) -> str:
        return mujoco.mj_id2name(m, obj, i) or f"{prefix}{i}"

    actuated = {int(m.actuator_trnid[k, 0]) for k in range(m.nu)
                if m.actuator_trntype[k] == mujoco.mjtTrn.mjTRN_JOINT}
    body_names = {i: name(mujoco.mjtObj.mjOBJ_BODY, i, "body") for i in range(m.nbody)}
    bodies: list[Body] = []
    for i in range(1, m.nbody):
        axes = []
        for j in range(int(m.body_jntadr[i]), int(m.body_jntadr[i]) + int(m.body_jntnum[i])):
            t = int(m.jnt_type[j])
            jn = name(mujoco.mjtObj.mjOBJ_JOINT, j, "joint")
            if t == mujoco.mjtJoint.mjJNT_FREE:
                raise InputError(f"{p}: joint {jn!r} is a free joint; a mechanism's links are held by joints")
            kind = {int(mujoco.mjtJoint.mjJNT_HINGE): "hinge", int(mujoco.mjtJoint.mjJNT_SLIDE): "slide",
                    int(mujoco.mjtJoint.mjJNT_BALL): "ball"}[t]
            rng = (float(m.jnt_range[j, 0]), float(m.jnt_range[j, 1])) if m.jnt_limited[j] and kind != "ball" else None
            ref = float(m.qpos0[m.jnt_qposadr[j]]) if kind != "ball" else 0.0
            axes.append(Axis(jn, kind, d.xanchor[j].copy(), d.xaxis[j].copy() if kind != "ball" else np.zeros(3),
                             ref, rng, j in actuated))
        parent = int(m.body_parentid[i])
        bname = body_names[i]
        tj = TreeJoint(axes[0].name.split(".", 1)[0] if axes else bname, "", tuple(axes)) if axes else None
        bodies.append(Body(bname, bname, None if parent == 0 else body_names[parent], d.xpos[i].copy(), tj))
    closures, couplings = [], []
    for k in range(m.neq):
        t = int(m.eq_type[k])
        kinds = {int(mujoco.mjtEq.mjEQ_CONNECT): "connect", int(mujoco.mjtEq.mjEQ_WELD): "weld",
                 int(mujoco.mjtEq.mjEQ_JOINT): "joint"}
        en = name(mujoco.mjtObj.mjOBJ_EQUALITY, k, kinds.get(t, "equality"))
        if t in (mujoco.mjtEq.mjEQ_CONNECT, mujoco.mjtEq.mjEQ_WELD):
            if int(m.eq_objtype[k]) != int(mujoco.mjtObj.mjOBJ_BODY):
                raise InputError(f"{p}: equality {en!r} joins sites; give body1/body2 and an anchor")
            b1, b2 = int(m.eq_obj1id[k]), int(m.eq_obj2id[k])
            kind = "connect" if t == mujoco.mjtEq.mjEQ_CONNECT else "weld"
            anchor = d.xpos[b1] + d.xmat[b1].reshape(3, 3) @ m.eq_data[k, 0:3]  # a weld's only names its frame
            jn = en.split(":", 1)[1] if en.startswith(f"{kind}:") else en
            closures.append(Closure(jn, kind, None if b1 == 0 else body_names[b1], None if b2 == 0 else body_names[b2],
                                    anchor.copy(), ""))
        elif t == mujoco.mjtEq.mjEQ_JOINT:
            j1 = name(mujoco.mjtObj.mjOBJ_JOINT, int(m.eq_obj1id[k]), "joint")
            j2 = None if int(m.eq_obj2id[k]) < 0 else name(mujoco.mjtObj.mjOBJ_JOINT, int(m.eq_obj2id[k]), "joint")
            c = m.eq_data[k, :5]
            if j2 is not None and (c[0] != 0 or np.any(c[2:] != 0)):
                raise InputError(f"{p}: equality {en!r}: only a lock (no joint2) or a linear coupling "
                                 "(polycoef 0 a1 0 0 0, a helical joint) is supported")
            couplings.append(Coupling(en, j1, j2, (float(c[0]), float(c[1])), "lock" if j2 is None else "helical"))
        else:
            raise InputError(f"{p}: equality {en!r}: only connect, weld and joint equalities are supported")
    if not isinstance(meta, dict):
        raise InputError(f"{p}: custom text {METADATA!r}: expected a JSON object, got {type(meta).__name__}")
    try:
        bodies = _name_tree_joints(bodies, meta)
        output = str(meta.get("output", OUTPUT))
        if output not in {b.name for b in bodies}:
            raise InputError(f"{p}: no output link: name the body whose pose is the output '{OUTPUT}' (or say so in "
                             f"the custom text {METADATA!r}: {{\"output\": \"BODY\"}})")
        out_body = next(b for b in bodies if b.name == output)
        L = _characteristic_length([a.anchor for b in bodies if b.joint for a in b.joint.axes]
                                   + [c.anchor for c in closures] + [out_body.origin])
        modes = tuple(Mode(x["name"], tuple(x["driven"]), x.get("description", "")) for x in meta.get("modes", []))
        return BodyTree(
            name=str(meta.get("name") or bytes(m.names).split(b"\0", 1)[0].decode("utf-8") or "mjcf"),
            bodies=tuple(bodies), closures=tuple(closures), couplings=tuple(couplings), output=output,
            platform_point=np.asarray(meta.get("platform_point", out_body.origin), dtype=float),
            characteristic_length=L, length_unit=str(meta.get("length_unit", "m")),
            description=str(meta.get("description", "")),
            limbs=tuple((str(n), tuple(str(j) for j in js)) for n, js in meta.get("limbs", [])),
            joint_types={str(k): str(v) for k, v in meta.get("joint_types", {}).items()},
            aliases={str(k): str(v) for k, v in meta.get("aliases", {}).items()}, modes=modes,
            lockable=tuple(str(x) for x in meta.get("lockable", ())),
            limb_ends=tuple((str(a), str(b)) for a, b in meta.get("limb_ends", [])),
            hubs=tuple(str(x) for x in meta.get("bodies", [])),
            joint_links={str(k): (str(a), str(b)) for k, (a, b) in meta.get("joint_links", {}).items()})
    except InputError:
        raise
    except (TypeError, ValueError, KeyError, AttributeError) as e:  # a custom text written by hand, or damaged
        raise InputError(f"{p}: custom text {METADATA!r} is not spatialmech metadata ({type(e).__name__}: {e}); "
                         "remove it or fix it (docs/validation.md)") from None


def _characteristic_length(points) -> float:
    from ..geometry.tolerances import characteristic_length

    return characteristic_length(np.array(points, dtype=float), field="MJCF joint anchors")


def _name_tree_joints(bodies: list[Body], meta: dict) -> list[Body]:
    """Name each body's tree joint by its spatialmech joint: the part before the first dot of
    its simulator joints' names (``L1.slide`` -> ``L1``), or the joint name of a ball."""
    out = []
    for b in bodies:
        if b.joint is None:
            out.append(b)
            continue
        stems = {a.name.split(".", 1)[0].split(":", 1)[0] for a in b.joint.axes}
        jn = stems.pop() if len(stems) == 1 else "+".join(a.name for a in b.joint.axes)
        out.append(Body(b.name, b.link, b.parent, b.origin, TreeJoint(jn, meta.get("joint_types", {}).get(jn, ""),
                                                                      b.joint.axes), b.ghost, b.segments))
    return out


def from_mjcf(path) -> Mechanism:
    """The mechanism of an MJCF file (see the module docstring)."""
    return mechanism_from_tree(read_body_tree(path))
