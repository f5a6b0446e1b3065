"""Joints as ordered sets of elementary one-freedom screw axes.

A joint is described at the *reference configuration* of its mechanism (the assembled
configuration in which every joint variable is zero and the platform is at its reference
pose).  Each joint is a short serial chain of elementary freedoms, applied in order as a
product of exponentials:

======  =========================================  =====================================
type    freedoms (names)                           geometry
======  =========================================  =====================================
``R``   ``rot``                                    axis through ``point``
``P``   ``slide``                                  direction ``axis``
``H``   ``screw`` (rotation with ``pitch``)        axis through ``point``
``C``   ``rot``, ``slide``                         the same axis for both
``U``   ``rot1``, ``rot2``                         ``axes[0]`` then ``axes[1]``, intersecting
                                                   at ``point``, perpendicular
``S``   ``rot1``, ``rot2``, ``rot3``               three orthonormal axes through ``point``
                                                   (default x, y, z)
``Sm``  like ``S``; each freedom lockable          the metamorphic spherical joint of
                                                   paper C in its serial-equivalent form
======  =========================================  =====================================

Units: SI and radians; ``limits`` and ``offset`` are in the freedom's own unit (rad or m).
A freedom's *value* is ``offset + q`` where ``q`` is the joint variable (zero at the reference).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from ..errors import InputError, UnknownNameError
from ..geometry.screws import axis_screw, translation_screw
from ..geometry.tolerances import DEFAULT, current
from ..geometry.validate import as_finite_array, as_model_number, as_unit_vector

__all__ = ["JOINT_TYPES", "C", "Freedom", "H", "Joint", "P", "R", "S", "Sm", "U", "make_joint"]

#: Joint types and their number of freedoms.
JOINT_TYPES = {"R": 1, "P": 1, "H": 1, "C": 2, "U": 2, "S": 3, "Sm": 3}

#: Tolerance for perpendicular / orthonormal joint axes (the default of
#: :attr:`~spatialmech.geometry.tolerances.Tolerances.unit`; the one in force is used).
AXIS_ORTHO_ATOL = DEFAULT.unit


@dataclass(frozen=True, eq=False)
class Freedom:
    """One elementary freedom: a rotation (``R``), translation (``P``) or helical motion (``H``)."""

    name: str
    kind: str  # "R" | "P" | "H"
    direction: np.ndarray
    point: np.ndarray
    pitch: float = 0.0
    actuated: bool = False
    lockable: bool = False
    locked: bool = False
    limits: tuple[float, float] | None = None
    offset: float = 0.0
    #: Lumped stiffness along this freedom when it is actuated (docs/stiffness.md): force per
    #: length unit for a slide (P), torque (force x length unit) per radian for a rotation (R, H);
    #: ``None``: not given (the stiffness analysis then assumes 1 and says so).
    stiffness: float | None = None

    @property
    def screw(self) -> np.ndarray:
        """The unit twist of this freedom at the reference configuration (a fresh array; it is
        computed once per freedom, which is frozen)."""
        return self._reference_screw.copy()

    @cached_property
    def _reference_screw(self) -> np.ndarray:
        if self.kind == "P":
            return translation_screw(self.direction)
        return axis_screw(self.direction, self.point, pitch=self.pitch if self.kind == "H" else 0.0)

    @property
    def is_linear(self) -> bool:
        return self.kind == "P"


@dataclass(frozen=True, eq=False)
class Joint:
    """A joint: its type, its centre / reference point and its freedoms (in chain order)."""

    name: str
    type: str
    point: np.ndarray
    freedoms: tuple[Freedom, ...]
    #: True when this joint is traversed against the direction it was described in (its
    #: freedoms then move its first link relative to its second; see :meth:`flipped`).
    reversed: bool = False

    def flipped(self) -> Joint:
        """The same joint traversed the other way: the motion of its first link relative to its
        second.  The inverse of ``exp(S1 q1) ... exp(Sn qn)`` is ``exp(-Sn qn) ... exp(-S1 q1)``:
        the freedoms in reverse order with negated directions (every screw negated), so every
        joint variable keeps its value and meaning.  ``flipped().flipped()`` is the original."""
        fs = tuple(replace(f, direction=-f.direction) for f in self.freedoms[::-1])
        return replace(self, freedoms=fs, reversed=not self.reversed)

    @property
    def described(self) -> Joint:
        """This joint as it was described (un-flipped)."""
        return self.flipped() if self.reversed else self

    @property
    def dof(self) -> int:
        """Freedoms that are not locked."""
        return sum(not f.locked for f in self.freedoms)

    @property
    def axes(self) -> np.ndarray:
        return np.array([f.direction for f in self.freedoms])

    def freedom(self, name: str) -> Freedom:
        for f in self.freedoms:
            if f.name == name:
                return f
        raise UnknownNameError(f"joint {self.name!r} has no freedom {name!r} (has {[f.name for f in self.freedoms]})")

    def with_freedom(self, name: str, **changes) -> Joint:
        fs = tuple(replace(f, **changes) if f.name == name else f for f in self.freedoms)
        return replace(self, freedoms=fs)


def _flags(value, names: tuple[str, ...], field_name: str) -> set[str]:
    """Normalise an actuated/lockable/locked flag: bool (all freedoms) or a list of names."""
    if value is True:
        return set(names)
    if value is False or value is None:
        return set()
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, (list, tuple, set, frozenset)):
        raise InputError(f"{field_name}: expected true, false or a list of freedom names {list(names)}, got {value!r}")
    out = set()
    for v in value:
        if v not in names:
            raise InputError(f"{field_name}: unknown freedom {v!r}; this joint has {list(names)}")
        out.add(v)
    return out


def _per_freedom(value, names: tuple[str, ...], field_name: str) -> dict:
    if value is None:
        return {}
    if isinstance(value, dict):
        for k in value:
            if k not in names:
                raise InputError(f"{field_name}: unknown freedom {k!r}; this joint has {list(names)}")
        return dict(value)
    if len(names) != 1:
        raise InputError(f"{field_name}: this joint has several freedoms {list(names)}; give a table by name")
    return {names[0]: value}


def _check_stiffness(k, field_name: str) -> float | None:
    """A stiffness: ``None`` or a positive finite number."""
    if k is None:
        return None
    v = float(as_model_number(k, field_name))
    if not v > 0.0:
        raise InputError(f"{field_name}: a stiffness must be positive, got {v:g}")
    return v


def _check_limits(lim, field_name: str):
    if lim is None:
        return None
    a = as_model_number(lim, field_name, shape=(2,))
    if a[0] > a[1]:
        raise InputError(f"{field_name}: lower limit {a[0]:g} is above upper limit {a[1]:g}")
    return (float(a[0]), float(a[1]))


def make_joint(
    type: str,
    name: str,
    *,
    point=(0.0, 0.0, 0.0),
    axis=None,
    axes=None,
    pitch: float = 0.0,
    actuated=False,
    lockable=False,
    locked=False,
    limits=None,
    offset=None,
    freedom_names=None,
    normalize: bool = False,
    field: str | None = None,
    stiffness=None,
) -> Joint:
    """Build and validate a joint of any type.  ``field`` prefixes error messages.  ``stiffness``:
    a positive number (one-freedom joint) or a table by freedom name: the lumped stiffness of an
    actuated freedom (:attr:`Freedom.stiffness`)."""
    where = field or f"joint {name!r}"
    if type not in JOINT_TYPES:
        raise InputError(f"{where}.type: unknown joint type {type!r}; expected one of {sorted(JOINT_TYPES)}")
    p = as_model_number(point, f"{where}.point", shape=(3,))
    if type in ("R", "P", "H", "C"):
        if axis is None:
            raise InputError(f"{where}.axis: required for a {type} joint")
        if axes is not None:
            raise InputError(f"{where}.axes: a {type} joint takes 'axis', not 'axes'")
        dirs = [as_unit_vector(axis, f"{where}.axis", normalize=normalize)]
    elif type == "U":
        if axes is None:
            raise InputError(f"{where}.axes: a U joint needs two axes")
        axs = as_finite_array(axes, f"{where}.axes", shape=(2, 3))
        dirs = [as_unit_vector(axs[i], f"{where}.axes[{i}]", normalize=normalize) for i in range(2)]
        if abs(dirs[0] @ dirs[1]) > current().unit:
            raise InputError(f"{where}.axes: the two axes of a U joint must be perpendicular (cos = {dirs[0] @ dirs[1]:.3g})")
    else:  # S, Sm
        if axis is not None:
            raise InputError(f"{where}.axis: a {type} joint takes 'axes' (three) or nothing")
        axs = np.eye(3) if axes is None else as_finite_array(axes, f"{where}.axes", shape=(3, 3))
        dirs = [as_unit_vector(axs[i], f"{where}.axes[{i}]", normalize=normalize) for i in range(3)]
        G = np.array(dirs) @ np.array(dirs).T
        if np.max(np.abs(G - np.eye(3))) > current().unit:
            raise InputError(f"{where}.axes: the three axes of a {type} joint must be mutually perpendicular")

    names: tuple[str, ...]
    if type == "R":
        kinds, names = ["R"], ("rot",)
    elif type == "P":
        kinds, names = ["P"], ("slide",)
    elif type == "H":
        kinds, names = ["H"], ("screw",)
        pitch = as_model_number(pitch, f"{where}.pitch")
    elif type == "C":
        kinds, names = ["R", "P"], ("rot", "slide")
        dirs = [dirs[0], dirs[0]]
    elif type == "U":
        kinds, names = ["R", "R"], ("rot1", "rot2")
    else:
        kinds, names = ["R", "R", "R"], ("rot1", "rot2", "rot3")
    if freedom_names is not None:
        freedom_names = tuple(freedom_names)
        if len(freedom_names) != len(names) or len(set(freedom_names)) != len(names):
            raise InputError(f"{where}.freedom_names: expected {len(names)} distinct names, got {list(freedom_names)}")
        names = freedom_names
    act = _flags(actuated, names, f"{where}.actuated")
    lk = _flags(lockable, names, f"{where}.lockable")
    lkd = _flags(locked, names, f"{where}.locked")
    if type == "Sm" and lockable is False:
        lk = set(names)
    lims = _per_freedom(limits, names, f"{where}.limits")
    offs = _per_freedom(offset, names, f"{where}.offset")
    stiff = _per_freedom(stiffness, names, f"{where}.stiffness")
    freedoms = []
    for kind, nm, d in zip(kinds, names, dirs, strict=True):
        freedoms.append(
            Freedom(
                name=nm,
                kind=kind,
                direction=d,
                point=p,
                pitch=float(pitch) if kind == "H" else 0.0,
                actuated=nm in act,
                lockable=nm in lk,
                locked=nm in lkd,
                limits=_check_limits(lims.get(nm), f"{where}.limits.{nm}"),
                offset=as_model_number(offs.get(nm, 0.0), f"{where}.offset.{nm}"),
                stiffness=_check_stiffness(stiff.get(nm), f"{where}.stiffness" + (f".{nm}" if len(names) > 1 else "")),
            )
        )
    return Joint(name=name, type=type, point=p, freedoms=tuple(freedoms))


def R(name: str, point, axis, **kw) -> Joint:
    """Revolute joint about unit ``axis`` through ``point``."""
    return make_joint("R", name, point=point, axis=axis, **kw)


def P(name: str, point, axis, **kw) -> Joint:
    """Prismatic joint along unit ``axis`` (``point`` places it for drawing and reports)."""
    return make_joint("P", name, point=point, axis=axis, **kw)


def H(name: str, point, axis, pitch: float, **kw) -> Joint:
    """Helical joint: rotation about ``axis`` with translation ``pitch`` per radian."""
    return make_joint("H", name, point=point, axis=axis, pitch=pitch, **kw)


def C(name: str, point, axis, **kw) -> Joint:
    """Cylindrical joint: rotation ``rot`` and slide ``slide`` along the same axis."""
    return make_joint("C", name, point=point, axis=axis, **kw)


def U(name: str, point, axes, **kw) -> Joint:
    """Universal joint: ``rot1`` about ``axes[0]`` then ``rot2`` about ``axes[1]`` (perpendicular)."""
    return make_joint("U", name, point=point, axes=axes, **kw)


def S(name: str, point, axes=None, **kw) -> Joint:
    """Spherical joint: three rotations about orthonormal ``axes`` through ``point``."""
    return make_joint("S", name, point=point, axes=axes, **kw)


def Sm(name: str, point, axes=None, **kw) -> Joint:
    """Metamorphic spherical joint: an ``S`` whose three rotations can each be locked."""
    return make_joint("Sm", name, point=point, axes=axes, **kw)
