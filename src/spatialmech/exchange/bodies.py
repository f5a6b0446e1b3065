"""The one intermediate structure of the exports: a body tree with loop closures.

:func:`body_tree` turns a mechanism into a :class:`BodyTree`, which both writers read
(:mod:`.mjcf` for MuJoCo, :mod:`.urdf`), and :func:`mechanism_from_tree` turns a body tree
back into a mechanism (the MJCF import builds a body tree from a MuJoCo model first).

From mechanism to body tree
---------------------------
The link graph and its spanning tree come from :mod:`spatialmech.model.topology` (cut S
joints where a loop has one), so a mechanism described as limbs from the ground to a platform
and one described as a link-and-joint graph with internal loops (the Clavel Delta, a spatial
six-bar) go through the same path.  Every link but the ground is a :class:`Body`; the tree
joint that leads to it says how it moves relative to its parent body.  Everything is stated
**in world coordinates at the reference configuration** (every joint variable zero), where
every body frame is world-aligned: a body's origin is the point of the joint that leads to it
(the output link's is the platform point, so that its pose *is* the platform pose).

A spatialmech joint becomes simulator joints (:class:`Axis`), applied in order from parent to
child: ``R`` a hinge, ``P`` a slide, ``C`` a hinge and a slide on one axis, ``U`` two hinges,
``S`` one ball (three hinges when a freedom is actuated, lockable or locked; ``Sm`` always
three hinges), ``H`` a hinge and a slide coupled by the pitch (:class:`Coupling`).  A hinge or
slide's value is the freedom's *physical* value ``offset + q`` (its ``ref`` is the offset), so
limits and actuator targets are the model's own numbers.  A tree joint that runs against its
limb (the child is on the ground side) has its simulator joints in reverse order with negated
axes; the values are unchanged.

Each cut joint becomes a :class:`Closure`: a cut ``S`` is a ``connect`` (the two links keep one
point in common); any other cut joint ``a -> b`` is rebuilt as a tree joint from ``a`` to a
*ghost* copy of ``b`` that a ``weld`` holds to ``b`` (six independent equations, so the
closure is exact for every joint type).  A locked freedom keeps its joint and gets a
:class:`Coupling` holding it at its value.

Each joint keeps the direction it was *described* in (its freedoms move link ``b`` relative to
link ``a``, :attr:`BodyTree.joint_links`), whichever way a limb or the tree traverses it; the
limbs (names, joints, end links) and the internal bodies travel as metadata, so an import gives
back the same limbs.

From body tree to mechanism
---------------------------
:func:`mechanism_from_tree` makes links of the bodies (a ghost, or a body welded to another, is
the other body's link; a body without joints is its parent's), joints of the tree joints and
the ``connect`` closures, and rebuilds the limbs the metadata names.  Without metadata (a
hand-written MJCF) the link graph is cut into limbs between hub links
(:func:`~spatialmech.model.topology.mechanism_from_graph`): limbs from the ground to the output
link, or the graph form when the model has internal loops.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from itertools import pairwise
from typing import Any

import numpy as np

from ..errors import InputError, UnknownNameError
from ..model.joints import Joint, make_joint
from ..model.mechanism import GROUND, Limb, Mechanism, Mode
from ..model.topology import GraphJoint, link_graph, mechanism_from_graph, spanning_tree

__all__ = [
    "Axis",
    "Body",
    "BodyTree",
    "Closure",
    "Coupling",
    "TreeJoint",
    "as_body_tree",
    "body_tree",
    "mechanism_from_tree",
]


@dataclass(frozen=True, eq=False)
class Axis:
    """One simulator joint: a ``hinge`` or ``slide`` (one freedom) or a ``ball`` (a whole S).

    ``anchor`` and ``axis`` are in world coordinates at the reference configuration (``axis``
    is zero for a ball); ``ref`` is the joint's value there (the freedom's offset), ``range``
    its limits (physical values) or ``None``; ``freedoms`` the spatialmech freedom ids it
    stands for."""

    name: str
    kind: str  # "hinge" | "slide" | "ball"
    anchor: np.ndarray
    axis: np.ndarray
    ref: float = 0.0
    range: tuple[float, float] | None = None
    actuated: bool = False
    locked: bool = False
    freedoms: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class TreeJoint:
    """A spatialmech joint on a tree edge: its simulator joints in the order applied from the
    parent body to the child body (reversed and negated when ``reversed``)."""

    name: str
    type: str
    axes: tuple[Axis, ...]
    reversed: bool = False
    pitch: float = 0.0  # H joints


@dataclass(frozen=True, eq=False)
class Body:
    """A rigid body of the tree: the link ``link`` (a ghost is a copy of a link that closes a
    cut joint), attached to ``parent`` (``None``: the ground) by ``joint`` (``None``: rigidly).
    ``origin``: world position of its frame at the reference (frames are world-aligned there).
    ``segments``: pairs of world points (at the reference) to draw the link between."""

    name: str
    link: str
    parent: str | None
    origin: np.ndarray
    joint: TreeJoint | None
    ghost: bool = False
    segments: tuple[tuple[np.ndarray, np.ndarray], ...] = ()


@dataclass(frozen=True, eq=False)
class Closure:
    """A loop closure (a cut joint): ``connect`` (a common point, ``anchor``) or ``weld`` (a
    common frame) between ``body1`` and ``body2`` (``None``: the ground)."""

    name: str
    kind: str  # "connect" | "weld"
    body1: str | None
    body2: str | None
    anchor: np.ndarray
    joint_type: str


@dataclass(frozen=True, eq=False)
class Coupling:
    """A joint equality ``y - y0 = a0 + a1 (x - x0)`` between simulator joints ``joint1`` (y) and
    ``joint2`` (x; ``None``: ``y`` held at ``y0 + a0``): an H joint's slide and hinge, or a lock."""

    name: str
    joint1: str
    joint2: str | None
    polycoef: tuple[float, float]
    purpose: str  # "helical" | "lock"


@dataclass(frozen=True, eq=False)
class BodyTree:
    """A mechanism as bodies (parents before children), loop closures and couplings, in world
    coordinates at the reference configuration; see the module docstring."""

    name: str
    bodies: tuple[Body, ...]
    closures: tuple[Closure, ...]
    couplings: tuple[Coupling, ...]
    output: str  # the body whose frame is the platform frame (the output link)
    platform_point: np.ndarray
    characteristic_length: float
    length_unit: str = "m"
    description: str = ""
    limbs: tuple[tuple[str, tuple[str, ...]], ...] = ()  # limb names and their joint names, base to tip
    joint_types: dict[str, str] = field(default_factory=dict)
    #: Per limb (as ``limbs``), the links it runs between: (base, tip).  Empty: ground to output.
    limb_ends: tuple[tuple[str, str], ...] = ()
    #: The mechanism's internal bodies (hub links other than the ground and the output link).
    hubs: tuple[str, ...] = ()
    #: Per joint, the links it was described between, (a, b): its freedoms move b relative to a.
    joint_links: dict[str, tuple[str, str]] = field(default_factory=dict)
    aliases: dict[str, str] = field(default_factory=dict)
    modes: tuple[Mode, ...] = ()
    ground_segments: tuple[tuple[np.ndarray, np.ndarray], ...] = ()  # to draw the ground between
    lockable: tuple[str, ...] = ()  # lockable freedoms (metamorphic mechanisms), by id

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise UnknownNameError(f"unknown body {name!r}; bodies: {', '.join(b.name for b in self.bodies)}")

    @property
    def axes(self) -> tuple[Axis, ...]:
        """Every simulator joint, in body order."""
        return tuple(a for b in self.bodies if b.joint is not None for a in b.joint.axes)

    @property
    def actuated(self) -> tuple[Axis, ...]:
        return tuple(a for a in self.axes if a.actuated and not a.locked)

    def metadata(self) -> dict:
        """What a simulator file cannot say by itself, for a faithful import: the model's name,
        unit, output body, limb names, order and end links, internal bodies, joint types and
        described directions, aliases and modes."""
        return {
            "format": "spatialmech body tree 2",
            "name": self.name,
            "description": self.description,
            "length_unit": self.length_unit,
            "output": self.output,
            "platform_point": [float(x) for x in self.platform_point],
            "limbs": [[n, list(js)] for n, js in self.limbs],
            "limb_ends": [list(e) for e in self.limb_ends],
            "bodies": list(self.hubs),
            "joint_types": dict(self.joint_types),
            "joint_links": {k: list(v) for k, v in self.joint_links.items()},
            "aliases": dict(self.aliases),
            "lockable": list(self.lockable),
            "modes": [{"name": m.name, "driven": list(m.driven), "description": m.description} for m in self.modes],
        }


# ------------------------------------------------------------------ mechanism -> body tree
def _plain_ball(joint: Joint) -> bool:
    """An S joint with no actuated, lockable or locked freedom: one MuJoCo ball."""
    return joint.type == "S" and not any(f.actuated or f.lockable or f.locked for f in joint.freedoms)


def _axes_of(joint: Joint, reversed_: bool) -> tuple[tuple[Axis, ...], tuple[Coupling, ...]]:
    if _plain_ball(joint):
        ball = Axis(joint.name, "ball", joint.point.copy(), np.zeros(3),
                    freedoms=tuple(f"{joint.name}.{f.name}" for f in joint.freedoms))
        return (ball,), ()
    axes: list[Axis] = []
    couplings: list[Coupling] = []
    for f in joint.freedoms:
        fid = f"{joint.name}.{f.name}"
        kind = "slide" if f.kind == "P" else "hinge"
        axes.append(Axis(fid, kind, f.point.copy(), f.direction.copy(), float(f.offset), f.limits,
                         f.actuated and not f.locked, f.locked, (fid,)))
        if f.kind == "H":  # a hinge and a slide on one axis, slide = pitch * hinge
            slide = f"{fid}:slide"
            axes.append(Axis(slide, "slide", f.point.copy(), f.direction.copy(), 0.0, None, False, False, ()))
            couplings.append(Coupling(f"helical:{fid}", slide, fid, (0.0, float(f.pitch)), "helical"))
        if f.locked:
            couplings.append(Coupling(f"lock:{fid}", fid, None, (0.0, 0.0), "lock"))
    if reversed_:
        axes = [Axis(a.name, a.kind, a.anchor, -a.axis, a.ref, a.range, a.actuated, a.locked, a.freedoms)
                for a in reversed(axes)]
    return tuple(axes), tuple(couplings)


def _attachments(mech: Mechanism, graph) -> dict[str, list[np.ndarray]]:
    """Points to draw each link between: its joints' points, and the platform point for the
    output link; a link whose points all coincide (a spherical linkage) is drawn between points
    half a characteristic length out along its joints' first axes."""
    L = mech.characteristic_length
    out: dict[str, list[np.ndarray]] = {k.name: [] for k in graph.links}
    axes: dict[str, list[np.ndarray]] = {k.name: [] for k in graph.links}
    for j in graph.joints:
        for end in (j.a, j.b):
            out[end].append(j.joint.point)
            axes[end].append(j.joint.freedoms[0].direction)
    out[mech.output] = [mech.platform_point, *out[mech.output]]
    axes[mech.output] = [np.zeros(3), *axes[mech.output]]
    for k, pts in out.items():
        if len(pts) > 1 and max(float(np.linalg.norm(p - pts[0])) for p in pts) < 1e-9 * L:
            out[k] = [p + 0.5 * L * a for p, a in zip(pts, axes[k], strict=True) if np.linalg.norm(a) > 0]
    return out


def _segments(points: list[np.ndarray], hub: np.ndarray | None, L: float) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """Capsules from ``hub`` to each point (a star: platform, ground, internal bodies), or along
    the points in order (a link of a limb); segments shorter than 1e-6 L are left out."""
    pairs = [(hub, p) for p in points] if hub is not None else list(pairwise(points))
    return tuple((a.copy(), b.copy()) for a, b in pairs if float(np.linalg.norm(b - a)) > 1e-6 * L)


def as_body_tree(model: Mechanism | BodyTree) -> BodyTree:
    """What the writers (MJCF, URDF) take: a mechanism's :func:`body_tree`, or a body tree as it
    is; a ``TypeError`` naming ``model`` for anything else."""
    tree = body_tree(model) if isinstance(model, Mechanism) else model
    if not isinstance(tree, BodyTree):
        raise TypeError(f"model: expected a Mechanism or a BodyTree, got {type(model).__name__}")
    return tree


def body_tree(mech: Mechanism) -> BodyTree:
    """The :class:`BodyTree` of a mechanism (see the module docstring): limbs from the ground to
    the output link and link-and-joint graphs with internal bodies alike."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"mech: expected a Mechanism, got {type(mech).__name__}")
    graph = link_graph(mech)
    tree = spanning_tree(graph)
    L = mech.characteristic_length
    att = _attachments(mech, graph)
    kinds = {k.name: k.kind for k in graph.links}
    bodies: list[Body] = []
    couplings: list[Coupling] = []
    closures: list[Closure] = []

    def body_of(link: str) -> str | None:
        return None if link == GROUND else link

    for link in tree.order[1:]:  # the ground is the world, not a body
        plink, jname = tree.parent[link]
        gj: GraphJoint = graph.joint(jname)
        rev = tree.reversed(jname)
        axes, cps = _axes_of(gj.joint, rev)
        couplings.extend(cps)
        origin = mech.platform_point.copy() if link == mech.output else gj.joint.point.copy()
        pts = att[link]
        if link == mech.output:
            segs = _segments(pts[1:], pts[0], L)
        elif kinds[link] == "body":  # an internal body (a Delta arm): a star from its tree joint
            segs = _segments([p for p in pts if float(np.linalg.norm(p - origin)) > 1e-9 * L], origin, L)
        else:
            segs = _segments(pts, None, L)
        bodies.append(Body(link, link, body_of(plink), origin,
                           TreeJoint(gj.name, gj.type, axes, rev, float(gj.joint.freedoms[0].pitch)), segments=segs))
    for c in (graph.joint(n) for n in tree.cut):
        if _plain_ball(c.joint):
            closures.append(Closure(c.name, "connect", body_of(c.a), body_of(c.b), c.joint.point.copy(), c.type))
            continue
        ghost = f"{c.b}~{c.name}"
        axes, cps = _axes_of(c.joint, False)
        couplings.extend(cps)
        bodies.append(Body(ghost, c.b, body_of(c.a), c.joint.point.copy(),
                           TreeJoint(c.name, c.type, axes, False, float(c.joint.freedoms[0].pitch)), ghost=True))
        closures.append(Closure(c.name, "weld", ghost, body_of(c.b), c.joint.point.copy(), c.type))
    pts = att[GROUND]
    ground = _segments(pts, np.mean(pts, axis=0), L) if len(pts) > 1 else ()
    return BodyTree(
        name=mech.name, bodies=tuple(bodies), closures=tuple(closures), couplings=tuple(couplings), output=mech.output,
        platform_point=mech.platform_point.copy(), characteristic_length=L, length_unit=mech.length_unit,
        description=mech.description, limbs=tuple((limb.name, tuple(j.name for j in limb.joints)) for limb in mech.limbs),
        joint_types={j.name: j.type for j in graph.joints}, aliases=dict(mech.aliases),
        modes=tuple(mech.modes), ground_segments=ground, lockable=mech.lockable,
        limb_ends=tuple((limb.base, mech.limb_tip(limb)) for limb in mech.limbs), hubs=tuple(mech.bodies),
        joint_links={j.name: (j.a, j.b) for j in graph.joints})


# ------------------------------------------------------------------ body tree -> mechanism
@dataclass(frozen=True)
class _Edge:
    name: str
    a: str  # link the simulator joints move from
    b: str
    axes: tuple[Axis, ...]
    kind: str  # "tree" | "connect"


def _reverse(axes: tuple[Axis, ...]) -> tuple[Axis, ...]:
    return tuple(Axis(a.name, a.kind, a.anchor, -a.axis, a.ref, a.range, a.actuated, a.locked, a.freedoms)
                 for a in reversed(axes))


def _close(u, v, tol: float) -> bool:
    return bool(np.linalg.norm(np.asarray(u, float) - np.asarray(v, float)) <= tol)


def _fields(name: str, axes: list[Axis], defaults: list[str], lockable: frozenset[str]) -> dict:
    """Freedom names and per-freedom flags of ``axes`` as :func:`~spatialmech.model.joints.make_joint`
    keywords.  A simulator joint named ``"JOINT.freedom"`` names its freedom."""
    names = [a.name.split(".", 1)[1] if a.name.startswith(f"{name}.") else d for a, d in zip(axes, defaults, strict=True)]
    return {
        "freedom_names": names,
        "actuated": [n for n, a in zip(names, axes, strict=True) if a.actuated],
        "locked": [n for n, a in zip(names, axes, strict=True) if a.locked],
        "lockable": [n for n, a in zip(names, axes, strict=True) if a.name in lockable],
        "limits": {n: a.range for n, a in zip(names, axes, strict=True) if a.range is not None} or None,
        "offset": {n: a.ref for n, a in zip(names, axes, strict=True) if a.ref != 0.0} or None,
    }


def _joint_from_axes(name: str, axes: tuple[Axis, ...], L: float, declared: str | None,
                     helical: dict[str, tuple[str, float]], lockable: frozenset[str], where: str) -> Joint:
    """A spatialmech joint from simulator joints in limb order: R, P, C, U, S, Sm, or H (a hinge
    with a slide coupled to it, ``helical``: slide name -> (hinge name, pitch))."""
    slides = {s for s in helical if any(a.name == s for a in axes)}
    real = [a for a in axes if a.name not in slides]
    kinds = [a.kind for a in real]
    tol = 1e-9 * max(L, 1.0)
    if kinds == ["ball"]:
        if declared not in (None, "S"):
            raise InputError(f"{where}: a ball joint cannot be a {declared} joint")
        return make_joint("S", name, point=real[0].anchor)
    if slides:
        (slide,) = slides
        hinge, pitch = helical[slide]
        s = next(a for a in axes if a.name == slide)
        if kinds != ["hinge"] or real[0].name != hinge or abs(abs(float(s.axis @ real[0].axis)) - 1.0) > 1e-9:
            raise InputError(f"{where}: a coupled slide that does not make a helical joint with one hinge on its axis")
        sign = float(np.sign(s.axis @ real[0].axis))
        return make_joint("H", name, point=real[0].anchor, axis=real[0].axis, pitch=sign * pitch, normalize=True,
                          **_fields(name, real, ["screw"], lockable))
    if kinds in (["hinge"], ["slide"]):
        t = "R" if kinds == ["hinge"] else "P"
        return make_joint(t, name, point=real[0].anchor, axis=real[0].axis, normalize=True,
                          **_fields(name, real, ["rot" if t == "R" else "slide"], lockable))
    if sorted(kinds) == ["hinge", "slide"]:
        h, s = real[kinds.index("hinge")], real[kinds.index("slide")]
        if abs(abs(float(h.axis @ s.axis)) - 1.0) > 1e-9 or np.linalg.norm(np.cross(s.anchor - h.anchor, h.axis)) > tol:
            raise InputError(f"{where}: a hinge and a slide that are not on one axis (not a C joint)")
        if float(h.axis @ s.axis) < 0:
            s = Axis(s.name, s.kind, s.anchor, -s.axis, -s.ref, None if s.range is None else (-s.range[1], -s.range[0]),
                     s.actuated, s.locked, s.freedoms)
        return make_joint("C", name, point=h.anchor, axis=h.axis, normalize=True,
                          **_fields(name, [h, s], ["rot", "slide"], lockable))
    if kinds == ["hinge", "hinge"]:
        if not _close(real[0].anchor, real[1].anchor, tol) or abs(float(real[0].axis @ real[1].axis)) > 1e-9:
            raise InputError(f"{where}: two hinges that do not meet at right angles (not a U joint)")
        return make_joint("U", name, point=real[0].anchor, axes=[real[0].axis, real[1].axis], normalize=True,
                          **_fields(name, real, ["rot1", "rot2"], lockable))
    if kinds == ["hinge", "hinge", "hinge"]:
        if not all(_close(a.anchor, real[0].anchor, tol) for a in real):
            raise InputError(f"{where}: three hinges that do not meet in a point (not a spherical joint)")
        t = declared if declared in ("S", "Sm") else "S"
        kw = _fields(name, real, ["rot1", "rot2", "rot3"], lockable)
        if t == "Sm":
            kw["lockable"] = kw["freedom_names"]
        return make_joint(t, name, point=real[0].anchor, axes=[a.axis for a in real], normalize=True, **kw)
    raise InputError(f"{where}: simulator joints {kinds} do not make a spatialmech joint (R, P, H, C, U, S, Sm)")


@dataclass(frozen=True)
class _LimbWalk:
    """A limb of the metadata laid on the imported link graph: its joints, each with the links it
    goes from and to in the limb's direction, and its intermediate links."""

    name: str
    base: str
    tip: str
    steps: tuple[tuple[str, str, str], ...]  # (joint, from link, to link)
    inner: tuple[str, ...]


def _walk_limbs(bt: BodyTree, ends: dict[str, tuple[str, str]], output: str) -> list[_LimbWalk] | None:
    """The metadata's limbs (``bt.limbs``, ``bt.limb_ends``) walked along the joints' links
    ``ends``; ``None`` when there is no metadata or it does not fit the graph (a joint unknown or
    used twice, a joint not at the link the walk has reached, a limb not ending at its tip, a
    joint on no limb): the graph is then cut into limbs afresh."""
    if not bt.limbs:
        return None
    limb_ends = bt.limb_ends or tuple((GROUND, output) for _ in bt.limbs)
    if len(limb_ends) != len(bt.limbs):
        return None
    used: set[str] = set()
    out = []
    for (name, jnames), (base, tip) in zip(bt.limbs, limb_ends, strict=True):
        at, steps, inner = base, [], []
        for jn in jnames:
            if jn not in ends or jn in used or at not in ends[jn]:
                return None
            a, b = ends[jn]
            nxt = b if at == a else a
            used.add(jn)
            steps.append((jn, at, nxt))
            inner.append(nxt)
            at = nxt
        if not steps or at != tip:
            return None
        out.append(_LimbWalk(name, base, tip, tuple(steps), tuple(inner[:-1])))
    return out if used == set(ends) else None


def _links_and_joints(bt: BodyTree) -> tuple[list[str], list[_Edge], str]:
    """The links (the ground first, then in body order), the joints as edges (tree joints and
    ``connect`` closures; simulator joints in the edge's ``a -> b`` order, locks marked) and the
    output link of a body tree."""
    link_of: dict[str | None, str] = {None: GROUND}
    for b in bt.bodies:  # parents come first
        if b.parent not in link_of:
            raise InputError(f"body {b.name!r}: its parent {b.parent!r} is not listed before it")
        link_of[b.name] = b.name if b.joint is not None else link_of[b.parent]
    for c in bt.closures:  # a weld makes one link of two bodies
        if c.kind == "weld":
            keep, drop = link_of[c.body2], link_of[c.body1]
            for body, lk in list(link_of.items()):
                if lk == drop:
                    link_of[body] = keep
    locked = {cp.joint1 for cp in bt.couplings if cp.joint2 is None}

    def marked(axes: tuple[Axis, ...]) -> tuple[Axis, ...]:
        return tuple(Axis(a.name, a.kind, a.anchor, a.axis, a.ref, a.range, a.actuated, a.locked or a.name in locked,
                          a.freedoms) for a in axes)

    edges: list[_Edge] = []
    for b in bt.bodies:
        if b.joint is not None:
            edges.append(_Edge(b.joint.name, link_of[b.parent], link_of[b.name], marked(b.joint.axes), "tree"))
    for c in bt.closures:
        if c.kind == "connect":
            edges.append(_Edge(c.name, link_of[c.body1], link_of[c.body2], (Axis(c.name, "ball", c.anchor, np.zeros(3)),),
                               "connect"))
        elif c.kind != "weld":
            raise InputError(f"closure {c.name!r}: unsupported kind {c.kind!r} (connect or weld)")
    if bt.output not in link_of:
        raise UnknownNameError(f"output: no body {bt.output!r}; bodies: {', '.join(b.name for b in bt.bodies)}")
    seen: set[str] = set()
    for e in edges:
        if e.a == e.b:
            raise InputError(f"joint {e.name!r}: joins link {e.a!r} to itself (a weld or a fixed body in its loop)")
        if e.name in seen:
            raise InputError(f"joint {e.name!r}: two joints of this name (name the simulator joints 'JOINT.freedom' "
                             "and the equalities uniquely)")
        seen.add(e.name)
    links = list(dict.fromkeys([GROUND, *(link_of[b.name] for b in bt.bodies)]))
    return links, edges, link_of[bt.output]


def mechanism_from_tree(bt: BodyTree) -> Mechanism:
    """The mechanism a :class:`BodyTree` describes (the module docstring).

    Joints are the tree joints and the ``connect`` closures (S joints); couplings lock a freedom
    (``joint2`` empty) or make a helical joint.  Each joint is rebuilt in the direction it was
    described in (``bt.joint_links``; otherwise the direction of the limb it is on, or of the
    tree).  The limbs are the metadata's (names, order, end links, internal bodies) when they fit
    the graph; otherwise the graph is cut into limbs between hub links
    (:func:`~spatialmech.model.topology.mechanism_from_graph`), which gives the graph form when
    the model has internal loops.  Raises :class:`~spatialmech.errors.InputError` when a joint
    is not a spatialmech joint or the graph is not a mechanism (a link held by one joint, links
    not connected to the ground)."""
    links, edges, output = _links_and_joints(bt)
    helical: dict[str, tuple[str, float]] = {}
    for cp in bt.couplings:
        if cp.joint2 is None and cp.polycoef[0] != 0.0:
            raise InputError(f"equality {cp.name!r}: holds {cp.joint1!r} away from its reference value; spatialmech "
                             "locks a freedom at its reference value")
        if cp.joint2 is not None:
            helical[cp.joint1] = (cp.joint2, cp.polycoef[1])
    walks = _walk_limbs(bt, {e.name: (e.a, e.b) for e in edges}, output)
    along = {jn: (u, v) for w in walks or () for jn, u, v in w.steps}
    joints: dict[str, tuple[Joint, str, str]] = {}
    for e in edges:
        d = tuple(bt.joint_links.get(e.name, ()))
        a, b = d if d in ((e.a, e.b), (e.b, e.a)) else along.get(e.name, (e.a, e.b))
        axes = e.axes if (a, b) == (e.a, e.b) else _reverse(e.axes)
        joints[e.name] = (_joint_from_axes(e.name, axes, bt.characteristic_length, bt.joint_types.get(e.name), helical,
                                           frozenset(bt.lockable), f"joint {e.name!r}"), a, b)
    # Mechanism's keywords, of their several types
    kw: dict[str, Any] = {"platform_point": bt.platform_point, "description": bt.description, "modes": bt.modes,
                          "aliases": bt.aliases, "length_unit": bt.length_unit}
    if walks is not None:
        limbs = []
        for w in walks:
            js = []
            for jn, u, v in w.steps:
                joint, a, b = joints[jn]
                js.append(joint if (u, v) == (a, b) else joint.flipped())
            generated = tuple(f"{w.name}.link{k}" for k in range(1, len(js)))
            limbs.append(Limb(w.name, tuple(js), base=w.base, tip=None if w.tip == output else w.tip,
                              links=() if w.inner == generated else w.inner))
        try:
            return Mechanism(bt.name, tuple(limbs), output=output, bodies=bt.hubs, **kw)
        except InputError:  # metadata that does not fit (internal bodies not named): cut the graph afresh
            pass
    mech = mechanism_from_graph(bt.name, links, [joints[e.name] for e in edges], output=output, **kw)
    # a ball has no direction of its own: one the cut traverses backwards is the same S joint forwards
    fixed = []
    for limb in mech.limbs:
        fixed.append(limb.with_joints(
            make_joint("S", j.name, point=j.point) if j.reversed and _plain_ball(j) and j.name not in bt.joint_links
            else j for j in limb.joints))
    return replace(mech, limbs=tuple(fixed))
