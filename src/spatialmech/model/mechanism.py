"""Limbs, mechanisms, task poses and motion modes.

A mechanism is a fixed base and a moving platform joined by limbs; each limb is a serial chain
of joints from the base to the platform.  Multi-loop parallel mechanisms are the main case; a
single-loop linkage is two limbs that meet at a chosen link (the "platform"), e.g. a four-bar
is ``[input crank R, coupler R]`` + ``[output rocker R, coupler R]`` with the coupler as
platform, or ``[R, S, S]`` + ``[R]`` for an RSSR with the output rocker as platform.

Everything is described at the reference configuration: every joint variable is zero there
and the platform frame is at ``platform_point`` with world-aligned axes.  A platform *pose*
``(R, p)`` is the orientation of the platform frame and the position of its origin; its
*displacement* from the reference is ``D = [[R, p - R p0], [0, 1]]``.
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from itertools import combinations

import numpy as np

from ..errors import InputError, SearchTooLargeError, UnknownNameError, describe
from ..geometry.rotations import euler_matrix, nearest_rotation, transform
from ..geometry.tolerances import ROTATION_EXACT, ROTATION_INPUT, characteristic_length
from ..geometry.tolerances import current as current_tolerances
from ..geometry.validate import as_finite_array
from .joints import Freedom, Joint
from .inertia import LinkInertia
from .task import TaskCoordinates

__all__ = ["GROUND", "MAX_IMPLICIT_MODES", "OUTPUT", "FreedomRef", "Limb", "Mechanism", "Mode", "Pose"]

#: Default name of the fixed link.
GROUND = "ground"
#: Default name of the output link (the platform).
OUTPUT = "platform"

#: Largest number of implicit modes (subsets of the lockable freedoms) of a mechanism without
#: declared modes: 2^10, i.e. at most 10 lockable freedoms.
MAX_IMPLICIT_MODES = 2**10


@dataclass(frozen=True, eq=False)
class Pose:
    """A platform pose: orientation ``R`` (3x3) and position ``p`` of the platform frame."""

    R: np.ndarray
    p: np.ndarray
    name: str = ""

    def __post_init__(self):
        R = as_finite_array(self.R, f"pose {self.name!r}.R", shape=(3, 3))
        err = float(np.max(np.abs(R @ R.T - np.eye(3))))
        if err > ROTATION_INPUT or np.linalg.det(R) < 0:
            raise InputError(f"pose {self.name!r}.R: not a rotation matrix (orthonormal, det +1)")
        if err > ROTATION_EXACT:  # typed with a few decimals: solve for the rotation meant
            R = nearest_rotation(R, name=f"pose {self.name!r}.R")
            warnings.warn(f"pose {self.name!r}.R: orthonormal only to {err:.2g}; its nearest rotation is used "
                          f"(it moves no entry by more than {float(np.max(np.abs(R - self.R))):.2g})",
                          stacklevel=3)
        object.__setattr__(self, "R", R)
        object.__setattr__(self, "p", as_finite_array(self.p, f"pose {self.name!r}.p", shape=(3,)))

    @classmethod
    def from_euler(cls, seq: str, angles, p, *, degrees: bool = False, name: str = "") -> Pose:
        """Pose from Euler angles in an explicitly named sequence (see :mod:`..geometry.rotations`)."""
        return cls(euler_matrix(seq, angles, degrees=degrees), p, name)

    def displacement(self, reference_point) -> np.ndarray:
        """The 4x4 displacement of the platform from its reference pose."""
        p0 = np.asarray(reference_point, dtype=float)
        return transform(self.R, self.p - self.R @ p0)

    @classmethod
    def from_displacement(cls, D, reference_point, *, name: str = "") -> Pose:
        D = np.asarray(D, dtype=float)
        return cls(D[:3, :3], D[:3, :3] @ np.asarray(reference_point, float) + D[:3, 3], name)


@dataclass(frozen=True, eq=False)
class Mode:
    """A motion mode of a metamorphic mechanism: which lockable freedoms are driven.

    Every lockable freedom not listed in ``driven`` is locked (its joint removed and its link
    merged with the neighbour, for counting purposes).
    """

    name: str
    driven: tuple[str, ...]
    description: str = ""


@dataclass(frozen=True, eq=False)
class Limb:
    """A serial chain of joints from link ``base`` (first joint) to link ``tip`` (last joint).

    By default a limb runs from the ground to the output link (the platform).  In a mechanism
    described as a link-and-joint graph (:meth:`Mechanism.from_graph`) a limb is a chain
    between two *hub* links: the ground, the output link or a named internal body (a link with
    three or more joints, such as a Delta arm).  ``links`` names the limb's intermediate links
    (one fewer than its joints; generated as ``"<limb>.link<k>"`` when empty).
    """

    name: str
    joints: tuple[Joint, ...]
    base: str = GROUND
    tip: str | None = None  # None: the mechanism's output link
    links: tuple[str, ...] = ()
    #: Stiffness of the limb against the displacements its constraint wrenches forbid (force per
    #: length unit, on unit nondimensional constraint wrenches; docs/stiffness.md); ``None``: rigid.
    constraint_stiffness: float | None = None

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise TypeError(f"limb name: expected a str, got {describe(self.name)}")
        object.__setattr__(self, "joints", _items(self.joints, Joint, _JOINT, f"limb {self.name!r}.joints"))
        if not self.joints:
            raise InputError(f"limb {self.name!r}: has no joints")
        for what in ("base", "tip"):
            v = getattr(self, what)
            if not (isinstance(v, str) and v) and not (what == "tip" and v is None):
                raise TypeError(f"limb {self.name!r}.{what}: expected a link name (str), got {describe(v)}")
        links = tuple(self.links)
        if links:
            if len(links) != len(self.joints) - 1:
                raise InputError(f"limb {self.name!r}.links: {len(self.joints)} joints have {len(self.joints) - 1} "
                                 f"intermediate links, got {len(links)} names")
            for k, v in enumerate(links):
                if not (isinstance(v, str) and v):
                    raise TypeError(f"limb {self.name!r}.links[{k}]: expected a link name (str), got {describe(v)}")
        object.__setattr__(self, "links", links)
        if self.constraint_stiffness is not None:
            kc = float(as_finite_array(self.constraint_stiffness, f"limb {self.name!r}.constraint_stiffness", shape=()))
            if not kc > 0.0:
                raise InputError(f"limb {self.name!r}.constraint_stiffness: a stiffness must be positive, got {kc:g}")
            object.__setattr__(self, "constraint_stiffness", kc)

    @property
    def dof(self) -> int:
        return sum(j.dof for j in self.joints)

    @property
    def link_names(self) -> tuple[str, ...]:
        """The names of the intermediate links, from the base side."""
        return self.links or tuple(f"{self.name}.link{k}" for k in range(1, len(self.joints)))

    def with_joints(self, joints) -> Limb:
        """This limb with other joints (same ends and link names)."""
        return replace(self, joints=tuple(joints))


_JOINT = "a Joint (R, P, C, U, S, Sm, H)"


def _items(values, cls, what: str, name: str) -> tuple:
    """``values`` as a tuple whose items are all ``cls``; ``TypeError`` naming the item otherwise,
    e.g. ``limbs[0].joints[1]: expected a Joint (R, P, C, U, S, Sm, H), got str 'S'``."""
    if isinstance(values, (str, bytes, cls)) or not hasattr(values, "__iter__"):
        raise TypeError(f"{name}: expected a sequence (list or tuple) of items, each {what}; got {describe(values)}")
    out = tuple(values)
    for k, v in enumerate(out):
        if not isinstance(v, cls):
            raise TypeError(f"{name}[{k}]: expected {what}, got {describe(v)}")
    return out


@dataclass(frozen=True)
class FreedomRef:
    """Where a freedom sits: its id (``"JOINT.freedom"``), limb, joint and freedom indices."""

    id: str
    limb: int
    joint: int
    index: int  # position within the joint
    freedom: Freedom = field(compare=False)


@dataclass(frozen=True, eq=False)
class Mechanism:
    """An immutable, validated description of a mechanism (see the module docstring)."""

    name: str
    limbs: tuple[Limb, ...]
    platform_point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    description: str = ""
    modes: tuple[Mode, ...] = ()
    positions: tuple[Pose, ...] = ()
    aliases: Mapping[str, str] = field(default_factory=dict)
    length_unit: str = "m"
    source: str = ""
    notes: str = ""
    output: str = OUTPUT
    bodies: tuple[str, ...] = ()
    #: The task coordinates a user gives to pose the output link (None: chosen from the
    #: mobility analysis, :func:`spatialmech.kinematics.task.default_task`).
    task: TaskCoordinates | None = None
    #: Mass properties by link name (:mod:`spatialmech.model.inertia`); links not named here get
    #: theirs from their shapes when ``density_kg_m3`` is given (docs/dynamics.md).
    inertias: Mapping[str, LinkInertia] = field(default_factory=dict)
    density_kg_m3: float | None = None

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise TypeError(f"name: expected a str, got {describe(self.name)}")
        object.__setattr__(self, "limbs", _items(self.limbs, Limb, "a Limb", "limbs"))
        for i, limb in enumerate(self.limbs):
            _items(limb.joints, Joint, _JOINT, f"limbs[{i}].joints")
        object.__setattr__(self, "modes", _items(self.modes, Mode, "a Mode", "modes"))
        object.__setattr__(self, "positions", _items(self.positions, Pose, "a Pose", "positions"))
        object.__setattr__(self, "aliases", dict(self.aliases))
        object.__setattr__(
            self, "platform_point", as_finite_array(self.platform_point, "platform_point", shape=(3,))
        )
        if not self.limbs:
            raise InputError("limbs: a mechanism needs at least one limb")
        seen_l, seen_j = set(), set()
        for i, limb in enumerate(self.limbs):
            if limb.name in seen_l:
                raise InputError(f"limbs[{i}].name: duplicate limb name {limb.name!r}")
            seen_l.add(limb.name)
            for j, joint in enumerate(limb.joints):
                if joint.name in seen_j:
                    raise InputError(f"limbs[{i}].joints[{j}].name: duplicate joint name {joint.name!r}")
                seen_j.add(joint.name)
        self._check_links()
        self._check_inertias()
        if self.task is not None and not isinstance(self.task, TaskCoordinates):
            raise TypeError(f"task: expected a TaskCoordinates, got {describe(self.task)}")
        for target in self.aliases.values():
            self.freedom(target)  # raises on unknown
        lockable = {r.id for r in self.freedom_refs if r.freedom.lockable}
        seen_m = set()
        for k, mode in enumerate(self.modes):
            if mode.name in seen_m:
                raise InputError(f"modes[{k}].name: duplicate mode name {mode.name!r}")
            seen_m.add(mode.name)
            for d in mode.driven:
                fid = self.freedom(d).id
                if fid not in lockable:
                    raise InputError(f"modes[{k}].driven: {d!r} is not a lockable freedom")
        # scale (geometry/tolerances.py): a length the nondimensional tolerances can handle
        L = self.characteristic_length  # InputError naming the joint points when out of range
        for r in self.freedom_refs:
            if r.freedom.kind == "H" and abs(r.freedom.pitch) > current_tolerances().max_ratio * L:
                raise InputError(f"limbs[{r.limb}].joints[{r.joint}].pitch: {r.freedom.pitch:.3g} per rad is more than "
                                 f"{current_tolerances().max_ratio:g} characteristic lengths ({L:.3g}): to the rank "
                                 "tolerance it is a prismatic joint; use a P joint")

    def _check_inertias(self) -> None:
        """Mass properties name moving links; the density is a positive number or None."""
        object.__setattr__(self, "inertias", dict(self.inertias))
        moving = {self.output, *self.bodies, *(ln for limb in self.limbs for ln in limb.link_names)}
        for name, li in self.inertias.items():
            if not isinstance(li, LinkInertia):
                raise TypeError(f"inertias[{name!r}]: expected a LinkInertia, got {describe(li)}")
            if name not in moving:
                raise InputError(f"masses: {name!r} is not a moving link; links: {', '.join(sorted(moving))}")
        d = self.density_kg_m3
        if d is not None and (isinstance(d, bool) or not isinstance(d, (int, float)) or not np.isfinite(d) or d <= 0):
            raise InputError(f"density_kg_m3: expected a positive number, got {d!r}")

    def _check_links(self) -> None:
        """Limb ends name known hub links; link names are unique; every body is attached by at
        least two limb ends and reached from the ground."""
        for what in ("output",):
            if not (isinstance(self.output, str) and self.output):
                raise TypeError(f"{what}: expected a link name (str), got {describe(self.output)}")
        object.__setattr__(self, "bodies", tuple(self.bodies))
        for k, b in enumerate(self.bodies):
            if not (isinstance(b, str) and b):
                raise TypeError(f"bodies[{k}]: expected a link name (str), got {describe(b)}")
        hubs = self.hubs
        if len(set(hubs)) != len(hubs):
            raise InputError(f"bodies: link names must be unique and differ from the ground and output link, got {list(hubs)}")
        names = set(hubs)
        for i, limb in enumerate(self.limbs):
            for what, end in (("base", limb.base), ("tip", self.limb_tip(limb))):
                if end not in names:
                    raise UnknownNameError(f"limbs[{i}].{what}: unknown link {end!r}; the limb ends are the hub links "
                                           f"{', '.join(hubs)}")
            for k, ln in enumerate(limb.link_names):
                if ln in names:
                    raise InputError(f"limbs[{i}].links[{k}]: duplicate link name {ln!r}")
                names.add(ln)
        ends = dict.fromkeys(hubs, 0)
        for limb in self.limbs:
            ends[limb.base] += 1
            ends[self.limb_tip(limb)] += 1
        for b in (self.output, *self.bodies):
            if ends[b] == 0:
                raise InputError(f"{'output' if b == self.output else 'bodies'}: link {b!r} is not attached to any limb")
        for b in self.bodies:
            if ends[b] < 2:
                raise InputError(f"bodies: link {b!r} is attached by one limb end only; it would move freely")
        reached, grew = {GROUND}, True
        while grew:
            grew = False
            for limb in self.limbs:
                a, b = limb.base, self.limb_tip(limb)
                if (a in reached) != (b in reached):
                    reached |= {a, b}
                    grew = True
        lost = [h for h in hubs if h not in reached]
        if lost:
            raise InputError(f"limbs: links not connected to the ground: {', '.join(lost)}")

    # ------------------------------------------------------------------ links
    @property
    def hubs(self) -> tuple[str, ...]:
        """The links that limbs start and end at: the ground, the output link, the bodies."""
        return (GROUND, self.output, *self.bodies)

    def limb_tip(self, limb: Limb) -> str:
        """The link a limb ends at (its ``tip``, the output link by default)."""
        return self.output if limb.tip is None else limb.tip

    def hub_index(self, link: str) -> int | None:
        """Where a hub link's displacement sits: ``None`` for the ground (fixed), 0 for the
        output link (``Configuration.D``), ``1 + i`` for body ``i`` (``Configuration.B[i]``)."""
        if link == GROUND:
            return None
        if link == self.output:
            return 0
        try:
            return 1 + self.bodies.index(link)
        except ValueError:
            raise UnknownNameError(f"unknown hub link {link!r}; hubs: {', '.join(self.hubs)}") from None

    @cached_property
    def limb_ends(self) -> tuple[tuple[int | None, int | None], ...]:
        """Per limb, the :meth:`hub_index` of its base and of its tip."""
        return tuple((self.hub_index(limb.base), self.hub_index(self.limb_tip(limb))) for limb in self.limbs)

    @property
    def is_graph(self) -> bool:
        """True unless every limb runs from the ground to the output link with its joints as
        described (a mechanism that needs the link-and-joint graph form to be written)."""
        return bool(self.bodies) or any(
            limb.base != GROUND or limb.tip not in (None, self.output) or limb.links
            or any(j.reversed for j in limb.joints) for limb in self.limbs)

    @classmethod
    def from_graph(cls, name: str, links, joints, *, output: str | None = None, **kwargs) -> Mechanism:
        """A mechanism from its link-and-joint graph; see :func:`spatialmech.model.topology.mechanism_from_graph`."""
        from .topology import mechanism_from_graph  # topology builds on this module

        return mechanism_from_graph(name, links, joints, output=output, **kwargs)

    # ------------------------------------------------------------------ freedoms
    @cached_property
    def freedom_refs(self) -> tuple[FreedomRef, ...]:
        """Every freedom of every joint, in limb/joint/chain order."""
        out = []
        for li, limb in enumerate(self.limbs):
            for ji, joint in enumerate(limb.joints):
                for fi, f in enumerate(joint.freedoms):
                    out.append(FreedomRef(f"{joint.name}.{f.name}", li, ji, fi, f))
        return tuple(out)

    def freedom(self, name: str) -> FreedomRef:
        """Look a freedom up by id (``"C1.rot"``), alias (``"rot1"``) or, for one-freedom
        joints, by joint name (``"B1"``)."""
        key = self.aliases.get(name, name)
        for r in self.freedom_refs:
            if r.id == key:
                return r
        matches = [r for r in self.freedom_refs if self.limbs[r.limb].joints[r.joint].name == key]
        if len(matches) == 1:
            return matches[0]
        known = sorted(set(self.aliases) | {r.id for r in self.freedom_refs})
        if len(matches) > 1:
            raise UnknownNameError(f"{name!r} names a joint with several freedoms: {[m.id for m in matches]}")
        raise UnknownNameError(f"unknown freedom {name!r}; known: {', '.join(known)}")

    @property
    def actuators(self) -> tuple[str, ...]:
        return tuple(r.id for r in self.freedom_refs if r.freedom.actuated and not r.freedom.locked)

    @property
    def lockable(self) -> tuple[str, ...]:
        return tuple(r.id for r in self.freedom_refs if r.freedom.lockable)

    @property
    def is_metamorphic(self) -> bool:
        return bool(self.lockable)

    @cached_property
    def characteristic_length(self) -> float:
        """RMS distance of the joint points from their centroid (see
        :func:`~spatialmech.geometry.tolerances.characteristic_length`: their distance from the
        origin if they coincide, 1 if that is zero too).

        Used to make screw-rank decisions and convergence tests independent of the length unit.
        """
        pts = np.array([j.point for limb in self.limbs for j in limb.joints] + [self.platform_point])
        return characteristic_length(pts, field="limbs[].joints[].point, platform_point")

    # ------------------------------------------------------------------ modes
    def all_modes(self) -> tuple[Mode, ...]:
        """The declared modes, or every subset of the lockable freedoms when none are declared.

        A mechanism without lockable freedoms has one mode, ``"default"``.  Without declared
        modes, at most :data:`MAX_IMPLICIT_MODES` subsets are enumerated (10 lockable freedoms);
        more raise :class:`~spatialmech.errors.SearchTooLargeError`: declare the modes.
        """
        if self.modes:
            return self.modes
        lk = self.lockable
        if not lk:
            return (Mode("default", ()),)
        if 2 ** len(lk) > MAX_IMPLICIT_MODES:
            raise SearchTooLargeError(
                f"modes: {self.name} has {len(lk)} lockable freedoms and no declared modes, i.e. 2^{len(lk)} = "
                f"{2 ** len(lk)} implicit modes (one per subset), more than {MAX_IMPLICIT_MODES}; declare the modes "
                "you mean ([[modes]] tables with name and driven freedoms in a file, Mechanism(modes=...) in Python)"
                " or mark fewer freedoms lockable")
        out = []
        for k in range(len(lk) + 1):
            for sub in combinations(lk, k):
                out.append(Mode("+".join(sub) if sub else "all-locked", tuple(sub)))
        return tuple(out)

    def mode(self, name: str) -> Mode:
        lk = self.lockable
        if not self.modes and 2 ** len(lk) > MAX_IMPLICIT_MODES:  # too many implicit modes to list: parse the name
            if name == "all-locked":
                return Mode(name, ())
            sub = name.split("+")
            if all(x in lk for x in sub) and sub == sorted(set(sub), key=lk.index):
                return Mode(name, tuple(sub))
            raise UnknownNameError(f"unknown mode {name!r}; the implicit modes of {self.name} are 'all-locked' and "
                                   f"lockable freedoms joined by '+' in this order: {', '.join(lk)}")
        for m in self.all_modes():
            if m.name == name:
                return m
        raise UnknownNameError(f"unknown mode {name!r}; modes: {', '.join(m.name for m in self.all_modes())}")

    def in_mode(self, mode: Mode | str) -> Mechanism:
        """This mechanism with the lockable freedoms not driven in ``mode`` locked and the
        driven ones actuated."""
        if isinstance(mode, str):
            mode = self.mode(mode)
        driven = {self.freedom(d).id for d in mode.driven}
        limbs = []
        for limb in self.limbs:
            joints = []
            for joint in limb.joints:
                for f in joint.freedoms:
                    if f.lockable:
                        fid = f"{joint.name}.{f.name}"
                        on = fid in driven
                        joint = joint.with_freedom(f.name, locked=not on, actuated=on)
                joints.append(joint)
            limbs.append(limb.with_joints(joints))
        return replace(self, limbs=tuple(limbs), modes=(mode,))

    def with_actuators(self, names) -> Mechanism:
        """This mechanism with exactly the named freedoms actuated (e.g. a driver choice)."""
        ids = {self.freedom(n).id for n in names}
        limbs = []
        for limb in self.limbs:
            joints = []
            for joint in limb.joints:
                for f in joint.freedoms:
                    joint = joint.with_freedom(f.name, actuated=f"{joint.name}.{f.name}" in ids)
                joints.append(joint)
            limbs.append(limb.with_joints(joints))
        return replace(self, limbs=tuple(limbs))
