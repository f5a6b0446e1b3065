"""The link graph of a mechanism: links as vertices, joints as edges, a spanning tree and its loops.

Today a mechanism is described as limbs from the ground to one output link (the platform);
this module derives its link-and-joint graph, the first step towards graphs as the model
itself (issue 11):

- **links**: the ground, every intermediate link of every limb (a limb of ``n`` joints has
  ``n - 1`` of them, named ``"<limb>.link<k>"``, ``k = 1 .. n - 1`` from the ground side), and
  the output link (the platform, named ``"platform"``);
- **joints**: edges between two links; joint ``k`` of a limb joins link ``k - 1`` (the ground for
  the first joint) to link ``k`` (the output link for the last).  An edge has a direction, the
  limb's: its freedoms move link ``b`` relative to link ``a``;
- a **spanning tree** rooted at the ground (:func:`spanning_tree`): every link reached from the
  ground by exactly one path of tree joints; the remaining joints are the **cut joints**
  (:func:`cut_joints`), one per independent loop.  Which joints are cut is a choice; the
  default cuts spherical joints wherever a loop has one (a cut S joint is a point-coincidence
  constraint, the cheapest closure a simulator offers) and otherwise the joint nearest the
  output link;
- the **loops** (:func:`loops`): each cut joint with the tree path that closes it, a cycle
  basis of the graph.  Their number is ``joints - links + 1`` for a connected graph, ``limbs - 1``
  for limbs to one output link.

Pure functions on frozen dataclasses; nothing here computes kinematics.

    >>> from spatialmech import catalog
    >>> g = link_graph(catalog.build("four-sps-cu"))
    >>> len(g.links), len(g.joints), g.n_loops
    (11, 14, 4)
    >>> [j.name for j in cut_joints(spanning_tree(g))]
    ['A1', 'A2', 'A3', 'A4']
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError, UnknownNameError
from .joints import Joint
from .mechanism import GROUND, OUTPUT, Limb, Mechanism

__all__ = [
    "GROUND",
    "OUTPUT",
    "GraphJoint",
    "Link",
    "LinkGraph",
    "Loop",
    "SpanningTree",
    "cut_joints",
    "default_cut_preference",
    "link_graph",
    "loops",
    "mechanism_from_graph",
    "spanning_tree",
]



@dataclass(frozen=True)
class Link:
    """A rigid link: the ground, the output link, or an intermediate link of a limb.

    ``limb`` and ``index`` place an intermediate link (link ``index`` of limb ``limb``, counted
    from 1 on the ground side); they are ``None`` for the ground and the output link."""

    name: str
    kind: str  # "ground" | "output" | "body" | "link"
    limb: int | None = None
    index: int | None = None


@dataclass(frozen=True)
class GraphJoint:
    """A joint as an edge of the link graph: its freedoms move link ``b`` relative to link ``a``
    (``a`` is on the ground side of its limb).  ``limb``/``index``: where it sits in the limb."""

    name: str
    joint: Joint = field(compare=False, repr=False)
    a: str
    b: str
    limb: int
    index: int

    @property
    def type(self) -> str:
        return self.joint.type

    def other(self, link: str) -> str:
        """The link at the other end of this joint from ``link``."""
        if link == self.a:
            return self.b
        if link == self.b:
            return self.a
        raise InputError(f"link: {link!r} is not an end of joint {self.name!r} ({self.a!r} - {self.b!r})")


@dataclass(frozen=True)
class LinkGraph:
    """Links (vertices) and joints (edges) of a mechanism; see the module docstring."""

    mechanism: str
    links: tuple[Link, ...]
    joints: tuple[GraphJoint, ...]
    ground: str = GROUND
    output: str = OUTPUT

    def __post_init__(self):
        names = [k.name for k in self.links]
        if len(set(names)) != len(names):
            raise InputError(f"links: duplicate link names in {names}")
        known = set(names)
        for where in (self.ground, self.output):
            if where not in known:
                raise UnknownNameError(f"link: unknown link {where!r}; links: {', '.join(names)}")
        seen = set()
        for j in self.joints:
            if j.name in seen:
                raise InputError(f"joints: duplicate joint name {j.name!r}")
            seen.add(j.name)
            for end in (j.a, j.b):
                if end not in known:
                    raise UnknownNameError(f"joint {j.name!r}: unknown link {end!r}; links: {', '.join(names)}")
            if j.a == j.b:
                raise InputError(f"joint {j.name!r}: connects link {j.a!r} to itself")

    def link(self, name: str) -> Link:
        for k in self.links:
            if k.name == name:
                return k
        raise UnknownNameError(f"unknown link {name!r}; links: {', '.join(k.name for k in self.links)}")

    def joint(self, name: str) -> GraphJoint:
        for j in self.joints:
            if j.name == name:
                return j
        raise UnknownNameError(f"unknown joint {name!r}; joints: {', '.join(j.name for j in self.joints)}")

    def incident(self, link: str) -> tuple[GraphJoint, ...]:
        """The joints with ``link`` at one end, in graph order."""
        return tuple(j for j in self.joints if link in (j.a, j.b))

    @property
    def connected(self) -> bool:
        """Every link is reached from the ground through joints."""
        return len(_reach(self, self.ground)) == len(self.links)

    @property
    def n_loops(self) -> int:
        """Independent loops (the cycle rank): ``joints - links + components``."""
        return len(self.joints) - len(self.links) + _components(self)


def link_graph(mech: Mechanism) -> LinkGraph:
    """The link graph of a mechanism (see the module docstring).

    Every joint appears as it was described: a joint that a limb traverses backwards
    (:attr:`~spatialmech.model.joints.Joint.reversed`) is an edge from the link after it in
    the limb to the link before it."""
    if not isinstance(mech, Mechanism):
        raise TypeError(f"mech: expected a Mechanism, got {type(mech).__name__}")
    links = [Link(GROUND, "ground")]
    joints = []
    for li, limb in enumerate(mech.limbs):
        inner = limb.link_names
        for k, ln in enumerate(inner, start=1):
            links.append(Link(ln, "link", li, k))
        chain = (limb.base, *inner, mech.limb_tip(limb))
        for k, joint in enumerate(limb.joints):
            a, b = chain[k], chain[k + 1]
            if joint.reversed:
                a, b = b, a
            joints.append(GraphJoint(joint.name, joint.described, a, b, li, k))
    links.append(Link(mech.output, "output"))
    links.extend(Link(b, "body") for b in mech.bodies)
    return LinkGraph(mech.name, tuple(links), tuple(joints), output=mech.output)


#: An edge of a graph being read (:func:`mechanism_from_graph`): the joint moves link ``b``
#: relative to link ``a``.
_Edge = tuple[Joint, str, str]
#: A chain between two hub links: its base, its edges each with whether it is traversed from
#: ``a`` to ``b``, its intermediate links and its tip.
_Chain = tuple[str, list[tuple[int, bool]], list[str], str]


def mechanism_from_graph(name: str, links, joints, *, output: str | None = None, **kwargs) -> Mechanism:
    """A :class:`Mechanism` from its link-and-joint graph.

    ``links``: the link names, one of them ``"ground"`` (the fixed link).  ``joints``: a
    sequence of ``(joint, a, b)``, the joint's freedoms moving link ``b`` relative to link ``a``.
    ``output``: the link whose pose is the task (default: the link named ``"platform"``).
    ``kwargs`` go to :class:`Mechanism` (``platform_point`` is the output link's reference point).

    The graph is cut into *limbs*, serial chains between **hub** links: the ground, the output
    link and every link with three or more joints (an internal *body*, such as a Delta arm);
    links with two joints are the chains' intermediate links.  A chain is traversed in the
    direction most of its joints were described in (a joint traversed backwards is
    :meth:`~spatialmech.model.joints.Joint.flipped`, so its variables keep their meaning).
    Errors name the field: unknown, duplicate or empty link names, a joint from a link to
    itself, two joints between the same two links, links not connected to the ground, a link
    held by one joint only (it would move freely).
    """
    names = _link_names(links)
    output = _output_link(names, output)
    edges = _graph_edges(joints, names)
    degree = _check_held(names, edges, output)
    hubs = [GROUND, output] + [ln for ln in names if ln not in (GROUND, output) and degree[ln] >= 3]
    depth = _depths(edges)
    limbs = []
    taken: set[str] = set()
    for chain in _chains(hubs, edges):
        limb = _limb(edges, *_oriented(*chain, depth), output=output, taken=taken)
        taken.add(limb.name)
        limbs.append(limb)
    bodies = tuple(ln for ln in hubs[2:])
    return Mechanism(name=name, limbs=tuple(limbs), output=output, bodies=bodies, **kwargs)


def _link_names(links) -> list[str]:
    """The link names of :func:`mechanism_from_graph`, checked: strings, distinct, the ground among them."""
    if isinstance(links, (str, bytes)) or not hasattr(links, "__iter__"):
        raise TypeError(f"links: expected a sequence of link names, got {type(links).__name__}")
    names = list(links)
    for k, ln in enumerate(names):
        if not isinstance(ln, str):
            raise TypeError(f"links[{k}]: expected a link name (str), got {ln!r}")
        if not ln.strip() or ln != ln.strip():
            raise InputError(f"links[{k}]: a link name must be non-empty, without leading or trailing spaces; "
                             f"got {ln!r}")
    if len(set(names)) != len(names):
        dup = sorted({x for x in names if names.count(x) > 1})
        raise InputError(f"links: duplicate link names {dup}")
    if GROUND not in names:
        raise InputError(f"links: one link must be named {GROUND!r} (the fixed link); got {names}")
    return names


def _output_link(names: list[str], output: str | None) -> str:
    """The output link: ``output``, by default the link named ``"platform"``; never the ground."""
    if output is None:
        if OUTPUT not in names:
            raise InputError(f"output: name the output link (the link whose pose is the task); links: {', '.join(names)}")
        output = OUTPUT
    if output not in names:
        raise UnknownNameError(f"output: unknown link {output!r}; links: {', '.join(names)}")
    if output == GROUND:
        raise InputError("output: the output link cannot be the ground")
    return output


def _graph_edges(joints, names: list[str]) -> list[_Edge]:
    """The ``(joint, a, b)`` items of :func:`mechanism_from_graph`, checked: joints with
    distinct names between two different known links, at least one of them."""
    edges: list[_Edge] = []
    seen: set[str] = set()
    for k, item in enumerate(joints):
        if not (isinstance(item, (tuple, list)) and len(item) == 3):
            raise TypeError(f"joints[{k}]: expected (joint, link a, link b), got {item!r}")
        j, a, b = item
        if not isinstance(j, Joint):
            raise TypeError(f"joints[{k}]: expected a Joint (R, P, C, U, S, Sm, H), got {type(j).__name__}")
        for end in (a, b):
            if end not in names:
                raise UnknownNameError(f"joints[{k}].links: unknown link {end!r} in joint {j.name!r}; links: {', '.join(names)}")
        if a == b:
            raise InputError(f"joints[{k}].links: joint {j.name!r} connects link {a!r} to itself")
        if j.name in seen:
            raise InputError(f"joints[{k}].name: duplicate joint name {j.name!r}")
        twin = next((e[0].name for e in edges if {e[1], e[2]} == {a, b}), None)
        if twin is not None:
            raise InputError(f"joints[{k}].links: joint {j.name!r} joins links {a!r} and {b!r}, already joined by "
                             f"joint {twin!r}: two joints between the same two links make a loop with no link in it "
                             "(one joint between two links; check the links of both)")
        seen.add(j.name)
        edges.append((j, a, b))
    if not edges:
        raise InputError("joints: a mechanism needs at least one joint")
    return edges


def _check_held(names: list[str], edges: list[_Edge], output: str) -> dict[str, int]:
    """The number of joints at each link, after checking that every link is connected to the
    ground and held by two joints or more (the ground and the output link by one or more)."""
    degree = dict.fromkeys(names, 0)
    for _, a, b in edges:
        degree[a] += 1
        degree[b] += 1
    reached = {GROUND}
    grew = True
    while grew:
        grew = False
        for _, a, b in edges:
            if (a in reached) != (b in reached):
                reached |= {a, b}
                grew = True
    lost = [ln for ln in names if ln not in reached]
    if lost:
        raise InputError(f"links: not connected to the ground: {', '.join(lost)}")
    for ln in names:
        if ln not in (GROUND, output) and degree[ln] == 1:
            raise InputError(f"links: link {ln!r} is held by one joint only; it would move freely "
                             "(connect it or remove it)")
    return degree


def _depths(edges: list[_Edge]) -> dict[str, int]:
    """Each link's depth from the ground (joints on a shortest path), to orient chains with no
    preferred direction."""
    depth = {GROUND: 0}
    frontier = [GROUND]
    while frontier:
        nxt = []
        for x in frontier:
            for _, a, b in edges:
                for u, v in ((a, b), (b, a)):
                    if u == x and v not in depth:
                        depth[v] = depth[x] + 1
                        nxt.append(v)
        frontier = nxt
    return depth


def _chains(hubs: list[str], edges: list[_Edge]) -> list[_Chain]:
    """The serial chains between hub links, each followed from the first hub (in ``hubs``
    order) that has one of its end joints."""
    used: set[int] = set()
    chains: list[_Chain] = []
    hub_set = set(hubs)
    for h in hubs:
        for e0, (_, a0, b0) in enumerate(edges):
            if e0 in used or h not in (a0, b0):
                continue
            steps, inner, at, e = [], [], h, e0
            while True:
                used.add(e)
                _, a, b = edges[e]
                forward = at == a
                steps.append((e, forward))
                at = b if forward else a
                if at in hub_set:
                    break
                inner.append(at)
                e = next(i for i, (_, x, y) in enumerate(edges) if i not in used and at in (x, y))
            chains.append((h, steps, inner, at))
    return chains


def _oriented(base: str, steps: list[tuple[int, bool]], inner: list[str], tip: str, depth: dict[str, int]) -> _Chain:
    """The chain traversed in the direction most of its joints were described in (on a tie:
    from the end nearer the ground)."""
    n_back = sum(not f for _, f in steps)
    if 2 * n_back > len(steps) or (2 * n_back == len(steps) and depth[tip] < depth[base]):
        return tip, [(e, not f) for e, f in steps[::-1]], inner[::-1], base
    return base, steps, inner, tip


def _limb(edges: list[_Edge], base: str, steps: list[tuple[int, bool]], inner: list[str], tip: str, *,
          output: str, taken: set[str]) -> Limb:
    """The limb of an oriented chain, named after its end joints (primed until the name is not
    in ``taken``); a joint traversed backwards is flipped."""
    js = [edges[e][0] if f else edges[e][0].flipped() for e, f in steps]
    lname = js[0].name if len(js) == 1 else f"{js[0].name}-{js[-1].name}"
    while lname in taken:
        lname += "'"
    return Limb(lname, tuple(js), base=base, tip=None if tip == output else tip, links=tuple(inner))


def _reach(g: LinkGraph, start: str) -> set[str]:
    seen = {start}
    todo = [start]
    while todo:
        x = todo.pop()
        for j in g.incident(x):
            y = j.other(x)
            if y not in seen:
                seen.add(y)
                todo.append(y)
    return seen


def _components(g: LinkGraph) -> int:
    left = {k.name for k in g.links}
    n = 0
    while left:
        left -= _reach(g, next(iter(sorted(left))))
        n += 1
    return n


# ------------------------------------------------------------------ spanning tree
def default_cut_preference(j: GraphJoint) -> tuple[int, int, int]:
    """Sort key of the default choice of cut joints (smaller = cut first): spherical joints
    (``S``; a cut S is a point-coincidence constraint), then the other joints; within each, the
    joint nearest the output link of its limb first (a cut then leaves the limb's chain from the
    ground intact), and the later limb first (the first limb stays whole in the tree)."""
    return (0 if j.type == "S" else 1, -j.index, -j.limb)


@dataclass(frozen=True)
class SpanningTree:
    """A spanning tree of a :class:`LinkGraph` rooted at its ground.

    ``parent`` maps every link but the root to ``(parent link, tree joint name)``; ``order``
    lists the links from the root outwards (every parent before its children); ``cut`` names the
    joints not in the tree, one per independent loop."""

    graph: LinkGraph
    parent: Mapping[str, tuple[str, str]]
    order: tuple[str, ...]
    cut: tuple[str, ...]

    @property
    def root(self) -> str:
        return self.graph.ground

    @property
    def tree_joints(self) -> tuple[str, ...]:
        """The joints of the tree, in :attr:`order` of the link they lead to."""
        return tuple(self.parent[k][1] for k in self.order if k in self.parent)

    def reversed(self, joint: str) -> bool:
        """Whether tree joint ``joint`` leads from its link ``b`` to its link ``a`` (against its
        limb's direction: the child link is the one on the ground side)."""
        j = self.graph.joint(joint)
        if joint not in self.tree_joints:
            raise InputError(f"joint: {joint!r} is a cut joint, not a joint of the tree")
        return self.parent.get(j.a, ("", ""))[1] == joint

    def path_to_root(self, link: str) -> tuple[str, ...]:
        """The tree joints from ``link`` down to the root, in that order."""
        out = []
        while link in self.parent:
            link, jn = self.parent[link]
            out.append(jn)
        return tuple(out)


def spanning_tree(graph: LinkGraph, *, cut_preference: Callable[[GraphJoint], Any] | None = None) -> SpanningTree:
    """A spanning tree rooted at the ground that cuts the joints ``cut_preference`` ranks first.

    The tree is built greedily (Kruskal): joints are taken in *descending* cut preference (the
    ones to keep first) and join the tree unless they close a loop; the joints left over are the
    cut joints.  ``cut_preference`` is a sort key (smaller = cut first); default
    :func:`default_cut_preference` (cut S joints where a loop has one).  Raises
    :class:`~spatialmech.errors.InputError` when the graph is not connected."""
    if not isinstance(graph, LinkGraph):
        raise TypeError(f"graph: expected a LinkGraph, got {type(graph).__name__}")
    key = cut_preference if cut_preference is not None else default_cut_preference
    if not graph.connected:
        lost = sorted({k.name for k in graph.links} - _reach(graph, graph.ground))
        raise InputError(f"graph: links not connected to the ground: {', '.join(lost)}")
    up = {k.name: k.name for k in graph.links}  # union-find

    def find(x: str) -> str:
        while up[x] != x:
            up[x] = up[up[x]]
            x = up[x]
        return x

    order = sorted(range(len(graph.joints)), key=lambda i: key(graph.joints[i]), reverse=True)
    tree: set[str] = set()
    for i in order:
        j = graph.joints[i]
        ra, rb = find(j.a), find(j.b)
        if ra != rb:
            up[ra] = rb
            tree.add(j.name)
    cut = tuple(j.name for j in graph.joints if j.name not in tree)
    # orient the tree from the ground (breadth first, in graph order)
    parent: dict[str, tuple[str, str]] = {}
    seq = [graph.ground]
    k = 0
    while k < len(seq):
        x = seq[k]
        k += 1
        for j in graph.incident(x):
            if j.name in tree:
                y = j.other(x)
                if y != graph.ground and y not in parent:
                    parent[y] = (x, j.name)
                    seq.append(y)
    return SpanningTree(graph, parent, tuple(seq), cut)


def cut_joints(tree: SpanningTree) -> tuple[GraphJoint, ...]:
    """The joints not in ``tree``: one per independent loop, in graph order."""
    return tuple(tree.graph.joint(n) for n in tree.cut)


@dataclass(frozen=True)
class Loop:
    """An independent loop: the cut joint and the joints of the cycle it closes, in order round
    the cycle, each with its sense (+1 when the cycle runs along the joint's ``a -> b``)."""

    cut: str
    joints: tuple[tuple[str, int], ...]

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(n for n, _ in self.joints)


def loops(tree: SpanningTree) -> tuple[Loop, ...]:
    """The fundamental loops of ``tree`` (a cycle basis of its graph): for every cut joint
    ``a -> b``, the cut joint followed by the tree path from ``b`` back to ``a``."""
    g = tree.graph
    out = []
    for c in cut_joints(tree):
        pa, pb = tree.path_to_root(c.a), tree.path_to_root(c.b)
        common = 0  # shared part of the two paths at the root end
        while common < min(len(pa), len(pb)) and pa[-1 - common] == pb[-1 - common]:
            common += 1
        up_b = pb[: len(pb) - common]  # from b towards the meeting link
        down_a = pa[: len(pa) - common][::-1]  # from the meeting link towards a
        steps: list[tuple[str, int]] = [(c.name, 1)]
        at = c.b
        for jn in (*up_b, *down_a):
            j = g.joint(jn)
            steps.append((jn, 1 if at == j.a else -1))
            at = j.other(at)
        if at != c.a:  # pragma: no cover - a tree path always closes the cycle
            raise RuntimeError(f"loop of {c.name!r} does not close")
        out.append(Loop(c.name, tuple(steps)))
    return tuple(out)
