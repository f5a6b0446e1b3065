"""Workspace under joint limits: orientation workspace at a fixed position, position workspace at
a fixed orientation, for any model (paper B, section 6, eqs 16-22, generalised).

Pose coordinates
----------------
``x, y, z`` (m): the platform point ``p`` (:attr:`Mechanism.platform_point` at the reference)
in the base frame; ``alpha, beta, gamma`` (rad): the platform orientation

    R = Rz(gamma) Ry(beta) Rx(alpha)      # ORIENTATION_SEQUENCE = "ZYX", angles (gamma, beta, alpha)

which is paper B's eq 7 (and the matrix printed with eq 18).  ``alpha`` is about x, ``beta``
about y, ``gamma`` about z.  Everything inside is SI and radians; :meth:`WorkspaceResult.to_dict`
is the edge and gives angles in degrees with ``_deg`` keys.

Limits (all optional, from the model and a :class:`WorkspaceLimits`)
--------------------------------------------------------------------
- every freedom's ``limits`` on its physical value ``offset + q`` (actuator strokes, the passive
  CU length: paper B eqs 16, 17);
- cone limits of spherical / universal joints (:class:`ConeLimit`, paper B eqs 18-20): the angle
  between the limb's link at the joint (oriented from the base towards the platform) and a
  reference axis fixed in the base or in the platform must not exceed ``max_angle``;
- link interference (eq 22): every limb's links (segments between consecutive distinct joint
  points) are capsules of the given diameter; two links of different limbs that do not share a
  joint interfere when their distance is below the mean of their diameters;
- closure: the pose must be reachable by every limb (e.g. the CU limb keeps the platform point
  on the Z axis).

Algorithm
---------
1. A pose-check kernel returns named *margins* (>= 0 inside) for stacks of poses.  The
   closed-form kernel (limbs S-P-S, U-P-S or C-U, as in the 4-SPS/CU and Gough-Stewart
   platforms) is vectorised (the SPS leg vectors of :mod:`..kinematics.closed_forms.sps`) and
   processed in chunks of ``chunk`` poses to bound memory; any other model uses the general
   kernel: one :func:`..kinematics.position.inverse_position` per pose (from the reference
   configuration, so the assembly branch is the one reached from it), then the same limits on
   the solved joint values and :func:`..kinematics.closure.joint_points`.  The result says
   which ``path`` was used.
2. The free coordinates are sampled on a regular grid (step ``<= step``; the fixed point lies on
   the grid when the bounds are symmetric about it).
3. Every change of feasibility between two neighbouring grid samples, along each grid
   direction, is refined by vectorised bisection to ``tol``; the limit violated just outside
   is the *active limit* of that boundary point.
4. Extents: of each coordinate alone (the others at their fixed value, on a 1-D line sampled at
   ``step`` and refined the same way) and over the whole set (min/max of the refined boundary
   points, then polished by SLSQP on the closed-form kernel's margins and accepted only when
   the kernel confirms the polished pose is feasible).  Accuracy: ``tol`` along the lines;
   a feasible island narrower than the grid step can be missed (stated in the result).
5. Volume: the refined feasible length of every grid line along the first free coordinate,
   integrated over the other coordinates by the trapezoid rule (units: product of the free
   coordinates' units, e.g. rad^3 of Euler-angle coordinates; not the Haar measure of SO(3)).

Paper B (:func:`paper_b_limits`): at ``z = 0.1 m`` with ``a = 0.1, b = 0.2 m`` the model gives
``alpha, beta in +-atan(z / b) = +-26.565 deg`` (platform-side spherical cone, eq 18) and
``gamma in +-128.682 deg`` (leg length 0.4 m: ``l^2 = 2a^2 + 2b^2 + z^2 - 4ab cos(gamma)``),
and the whole set has the same extents; the paper's 48 / 48 / 65 deg do not follow from its
stated model (docs/workspace.md).

Example::

    >>> from spatialmech import catalog
    >>> ws = orientation_workspace(catalog.build("four-sps-cu"), at={"z": 0.1},
    ...                            limits=paper_b_limits(), step=np.radians(6))
    >>> round(float(np.degrees(ws.alone["alpha"].hi)), 3), ws.alone["alpha"].hi_limit
    (26.565, 'A1 cone')
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np
from scipy.optimize import minimize

from ..geometry.rotations import euler_matrix
from ..geometry.validate import as_finite_array, as_unit_vector
from ..model.mechanism import Mechanism, Pose

__all__ = [
    "ORIENTATION_SEQUENCE",
    "COORDINATES",
    "PAPER_B_LINK_DIAMETERS",
    "ConeLimit",
    "WorkspaceLimits",
    "paper_b_limits",
    "default_limits",
    "PoseChecker",
    "pose_checker",
    "segment_distance",
    "Extent",
    "WorkspaceResult",
    "orientation_workspace",
    "position_workspace",
]

#: ``R = Rz(gamma) Ry(beta) Rx(alpha)``: intrinsic "ZYX" with the angles ``(gamma, beta, alpha)``.
ORIENTATION_SEQUENCE = "ZYX"
#: Pose coordinates: position of the platform point (m) and the three angles (rad).
COORDINATES = ("x", "y", "z", "alpha", "beta", "gamma")
_POSITION = COORDINATES[:3]
_ORIENTATION = COORDINATES[3:]
#: Paper B eq 22 and section 6: link diameters ``D_min = 0.008 m <= D_i <= D_max = 0.01 m``.
PAPER_B_LINK_DIAMETERS = (0.008, 0.01)

_BOX = "box"
_CLOSURE = "closure"


# ------------------------------------------------------------------------------ limits
@dataclass(frozen=True)
class ConeLimit:
    """Cone limit of a spherical or universal joint (paper B eqs 18-20).

    The angle between the limb's link at joint ``joint`` (unit vector from the base-side end to
    the platform-side end of the link) and ``axis`` (a unit vector fixed in the base frame when
    ``frame == "base"``, in the platform frame when ``frame == "platform"``, i.e. ``R axis`` in
    the base frame) must be at most ``max_angle`` (rad).  Paper B: ``A_i`` (platform side)
    ``axis = (0, 0, 1), frame = "platform"``; ``B_i``: ``(0, 0, 1), "base"``; the CU column's
    universal joint ``U5``: ``(0, 0, 1), "platform"``; all ``max_angle = pi / 2``.
    """

    joint: str
    axis: tuple[float, float, float] = (0.0, 0.0, 1.0)
    frame: str = "base"
    max_angle: float = np.pi / 2

    def __post_init__(self):
        if not isinstance(self.joint, str) or not self.joint:
            raise ValueError(f"joint: expected a joint name, got {self.joint!r}")
        object.__setattr__(self, "axis", tuple(float(v) for v in as_unit_vector(self.axis, "axis")))
        if self.frame not in ("base", "platform"):
            raise ValueError(f"frame: expected 'base' or 'platform', got {self.frame!r}")
        ang = float(as_finite_array(self.max_angle, "max_angle", shape=()))
        if not 0.0 < ang <= np.pi:
            raise ValueError(f"max_angle: expected 0 < max_angle <= pi rad, got {ang}")
        object.__setattr__(self, "max_angle", ang)

    @property
    def name(self) -> str:
        return f"{self.joint} cone"

    def to_dict(self) -> dict:
        return {"joint": self.joint, "axis": list(self.axis), "frame": self.frame,
                "max_angle_deg": float(np.degrees(self.max_angle))}


@dataclass(frozen=True)
class WorkspaceLimits:
    """Limits that the model itself does not carry: joint cones and link capsules.

    ``freedom_limits``: also check every freedom's ``limits`` (actuator strokes, passive
    slides).  ``link_diameter``: ``None`` (no interference check), one diameter (m) for every
    limb's links, or a mapping ``{limb name: diameter}`` (only those limbs are checked).
    """

    cones: tuple[ConeLimit, ...] = ()
    link_diameter: float | Mapping[str, float] | None = None
    freedom_limits: bool = True
    source: str = ""

    def __post_init__(self):
        object.__setattr__(self, "cones", tuple(self.cones))
        for c in self.cones:
            if not isinstance(c, ConeLimit):
                raise ValueError(f"cones: expected ConeLimit items, got {type(c).__name__}")
        d = self.link_diameter
        if d is not None:
            items = dict(d) if isinstance(d, Mapping) else {"*": d}
            for k, v in items.items():
                v = float(as_finite_array(v, f"link_diameter[{k}]", shape=()))
                if v < 0:
                    raise ValueError(f"link_diameter[{k}]: must be >= 0, got {v}")
                items[k] = v
            object.__setattr__(self, "link_diameter", items["*"] if "*" in items else items)

    def diameter(self, limb: str) -> float | None:
        d = self.link_diameter
        if d is None:
            return None
        if isinstance(d, Mapping):
            return d.get(limb)
        return float(d)

    def to_dict(self) -> dict:
        d = self.link_diameter
        return {"cones": [c.to_dict() for c in self.cones], "freedom_limits": self.freedom_limits,
                "link_diameter_m": dict(d) if isinstance(d, Mapping) else d, "source": self.source}


def paper_b_limits(link_diameter: float = PAPER_B_LINK_DIAMETERS[1], max_angle: float = np.pi / 2) -> WorkspaceLimits:
    """Paper B section 6 limits beyond the model's strokes (legs 0.1..0.4 m, CU 0.08..0.3 m).

    Reading of eqs 18-21 (seed 002): with ``delta_i`` the leg direction ``B_i -> A_i``,
    ``delta_n1 = (0, 0, -1)``, ``delta_n2 = (0, 0, 1)`` and ``R`` the eq 7 matrix,
    eq 18 ``theta_pi = arccos(-delta_i . R delta_n1)`` is the angle between the leg and the
    platform normal ``R e_z`` (the spherical joint ``A_i``); eq 19 the angle between the leg
    and the base normal ``e_z`` (``B_i``); eq 20 the angle between the CU column
    ``delta_5 = (0, 0, z)`` and the platform normal (the universal joint ``U5``); eq 21 (the
    cylindrical joint) imposes nothing.  All limits ``90 deg``.  Eq 22 bounds the link
    diameters (``0.008..0.01 m``); the interference check uses capsules of the largest,
    ``0.01 m`` (the conservative choice).
    """
    cones = tuple(ConeLimit(f"A{i}", (0, 0, 1), "platform", max_angle) for i in range(1, 5))
    cones += tuple(ConeLimit(f"B{i}", (0, 0, 1), "base", max_angle) for i in range(1, 5))
    cones += (ConeLimit("U5", (0, 0, 1), "platform", max_angle),)
    return WorkspaceLimits(cones, link_diameter, True, "paper B section 6, eqs 16-22")


def default_limits(mech: Mechanism) -> WorkspaceLimits:
    """The paper's limits for the paper B model (``four-sps-cu``), else the model's own limits."""
    if mech.name == "four-sps-cu":
        return paper_b_limits()
    return WorkspaceLimits(source="the model's freedom limits")


# ------------------------------------------------------------------------------ geometry kernels
def segment_distance(p1, q1, p2, q2) -> np.ndarray:
    """Minimum distance (...,) between the segments ``p1 q1`` and ``p2 q2`` (..., 3), vectorised.

    Closest points of two segments (Ericson, *Real-Time Collision Detection*, 5.1.9), with the
    parallel and degenerate cases handled.  Example: the segments ``(0,0,0)-(1,0,0)`` and
    ``(0.5,1,-1)-(0.5,1,1)`` are 1 apart.
    """
    p1, q1, p2, q2 = (np.asarray(v, dtype=float) for v in (p1, q1, p2, q2))
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("...i,...i->...", d1, d1)
    e = np.einsum("...i,...i->...", d2, d2)
    b = np.einsum("...i,...i->...", d1, d2)
    c = np.einsum("...i,...i->...", d1, r)
    f = np.einsum("...i,...i->...", d2, r)
    tiny = 1e-300
    a_ = np.maximum(a, tiny)
    e_ = np.maximum(e, tiny)
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 1e-12 * a_ * e_, np.clip((b * f - c * e) / np.maximum(denom, tiny), 0.0, 1.0), 0.0)
        t = (b * s + f) / e_
        s = np.where(t < 0.0, np.clip(-c / a_, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / a_, 0.0, 1.0), s))
        t = np.clip(t, 0.0, 1.0)
        # degenerate segments (a point): Ericson's special cases
        deg_a, deg_e = a <= 1e-300, e <= 1e-300
        s = np.where(deg_e & ~deg_a, np.clip(-c / a_, 0.0, 1.0), s)
        t = np.where(deg_e, 0.0, t)
        t = np.where(deg_a & ~deg_e, np.clip(f / e_, 0.0, 1.0), t)
        s = np.where(deg_a, 0.0, s)
    diff = (p1 + s[..., None] * d1) - (p2 + t[..., None] * d2)
    return np.linalg.norm(diff, axis=-1)


def _cone_angles(direction: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """Angle (rad) between ``direction`` (n, 3) and the unit ``axis`` (n, 3) or (3,):
    ``atan2(|d x a|, d . a)``, accurate near 0 and pi (unlike ``arccos``)."""
    ax = np.broadcast_to(axis, direction.shape)
    return np.arctan2(np.linalg.norm(np.cross(direction, ax), axis=-1), np.einsum("...i,...i->...", direction, ax))


@dataclass(frozen=True)
class _Link:
    limb: int
    ends: tuple[int, int]  # joint indices of the two ends (base side first)


def _links(mech: Mechanism, points: list[np.ndarray]) -> list[_Link]:
    """Links of every limb: segments between consecutive distinct joint points (reference)."""
    out = []
    L = mech.characteristic_length
    for li, pts in enumerate(points):
        keep = [0]
        for j in range(1, len(pts)):
            if np.linalg.norm(pts[j] - pts[keep[-1]]) > 1e-9 * L:
                keep.append(j)
        out += [_Link(li, (keep[k], keep[k + 1])) for k in range(len(keep) - 1)]
    return out


def _link_of_joint(links: list[_Link], limb: int, joint: int) -> int:
    """Index of the link a cone limit at ``joint`` refers to: at the limb's first joint the link
    leaving it towards the platform, elsewhere the link arriving at it from the base side."""
    mine = [k for k, lk in enumerate(links) if lk.limb == limb]
    if not mine:
        raise ValueError(f"cones: the limb of joint #{joint} has no link (all its joints coincide)")
    if joint == 0:
        return mine[0]
    for k in mine:
        lo, hi = links[k].ends
        if lo < joint <= hi:
            return k
    return mine[-1] if joint > links[mine[-1]].ends[1] else mine[0]


# ------------------------------------------------------------------------------ pose checker
@dataclass(frozen=True, eq=False)
class PoseChecker:
    """Named margins (>= 0 inside every limit) for stacks of platform poses.

    ``margins(R, p)`` -> (n, m) array for ``R`` (n, 3, 3), ``p`` (n, 3) (the platform point);
    ``names[k]`` names margin ``k`` (e.g. ``"L1.slide max"``, ``"A1 cone"``,
    ``"interference leg1/cu"``, ``"closure"``); ``scales[k]`` makes margins comparable (m
    margins divided by the characteristic length, rad margins by 1).  ``path`` is
    ``"closed-form"`` (vectorised) or ``"general"`` (per-pose inverse position).
    """

    mechanism: Mechanism
    limits: WorkspaceLimits
    path: str
    names: tuple[str, ...]
    scales: np.ndarray
    _fn: Callable = field(repr=False)
    reason: str = ""
    pinned: dict = field(default_factory=dict)  # position coordinates fixed by a limb (closed form)
    _feasible_fn: Callable | None = field(default=None, repr=False)

    def margins(self, R, p) -> np.ndarray:
        R = np.asarray(R, dtype=float).reshape(-1, 3, 3)
        p = np.asarray(p, dtype=float).reshape(-1, 3)
        return self._fn(R, p)

    def feasible(self, R, p) -> np.ndarray:
        """``True`` where every margin is >= 0 (the closed form skips the interference check
        where another limit already fails)."""
        if self._feasible_fn is not None:
            R = np.asarray(R, dtype=float).reshape(-1, 3, 3)
            p = np.asarray(p, dtype=float).reshape(-1, 3)
            return self._feasible_fn(R, p)
        return np.all(self.margins(R, p) >= 0.0, axis=-1)

    def violated(self, R, p) -> list[str]:
        """Name of the most violated limit (scaled margins) of each pose, ``""`` if feasible."""
        m = self.margins(R, p) / self.scales
        k = np.argmin(m, axis=-1)
        return [self.names[i] if m[j, i] < 0 else "" for j, i in enumerate(k)]


def _freedom_margin_names(mech: Mechanism, idx: list[int]) -> list[str]:
    refs = mech.freedom_refs
    return [f"{refs[i].id} {side}" for i in idx for side in ("min", "max")]


def _freedom_margins(vals: np.ndarray, los: np.ndarray, his: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """(n, 2k) margins ``value - lo``, ``hi - value``; rotations wrapped to the range centre."""
    mid = 0.5 * (los + his)
    wrapped = vals + 2 * np.pi * np.round((mid - vals) / (2 * np.pi))
    v = np.where(rot, wrapped, vals)
    out = np.empty(v.shape[:-1] + (2 * v.shape[-1],))
    out[..., 0::2] = v - los
    out[..., 1::2] = his - v
    return out


def _common(mech: Mechanism, limits: WorkspaceLimits, ref_points: list[np.ndarray]):
    """Links, cone (limb, link, cone) triples, capsule pairs, freedom-limit indices."""
    L = mech.characteristic_length
    links = _links(mech, ref_points)
    joint_at = {j.name: (li, ji) for li, limb in enumerate(mech.limbs) for ji, j in enumerate(limb.joints)}
    cones = []
    for c in limits.cones:
        if c.joint not in joint_at:
            raise ValueError(f"cones: {mech.name} has no joint {c.joint!r}")
        li, ji = joint_at[c.joint]
        if mech.limbs[li].joints[ji].type not in ("S", "U", "Sm"):
            raise ValueError(f"cones: joint {c.joint!r} is a {mech.limbs[li].joints[ji].type} joint, not S or U")
        cones.append((c, _link_of_joint(links, li, ji)))
    pairs = []
    for i in range(len(links)):
        for j in range(i + 1, len(links)):
            a, b = links[i], links[j]
            if a.limb == b.limb:
                continue
            da, db = limits.diameter(mech.limbs[a.limb].name), limits.diameter(mech.limbs[b.limb].name)
            if da is None or db is None:
                continue
            ends_a = [ref_points[a.limb][k] for k in a.ends]
            ends_b = [ref_points[b.limb][k] for k in b.ends]
            if min(np.linalg.norm(x - y) for x in ends_a for y in ends_b) < 1e-9 * L:
                continue  # links joined at a common joint
            pairs.append((i, j, 0.5 * (da + db)))
    fl = [k for k, r in enumerate(mech.freedom_refs) if limits.freedom_limits and r.freedom.limits is not None]
    names = _freedom_margin_names(mech, fl)
    names += [c.name for c, _ in cones]
    names += [f"interference {mech.limbs[links[i].limb].name}/{mech.limbs[links[j].limb].name}" for i, j, _ in pairs]
    scale = [L if mech.freedom_refs[k].freedom.kind == "P" else 1.0 for k in fl for _ in (0, 1)]
    scale += [1.0] * len(cones) + [L] * len(pairs)
    return links, cones, pairs, fl, names, scale


def _cone_margins(seg_a, seg_b, R, cones):
    """Cone margins ``max_angle - angle`` (rad) from link end points ``seg_a``/``seg_b`` (n, n_links, 3)."""
    cols = []
    for c, k in cones:
        axis = np.asarray(c.axis)
        ax = np.einsum("nij,j->ni", R, axis) if c.frame == "platform" else axis
        cols.append(c.max_angle - _cone_angles(seg_b[:, k] - seg_a[:, k], ax))
    return cols


def _pair_margins(seg_a, seg_b, pairs):
    """Capsule margins ``distance - (d_i + d_j) / 2`` (m) of the link pairs."""
    return [segment_distance(seg_a[:, i], seg_b[:, i], seg_a[:, j], seg_b[:, j]) - clearance for i, j, clearance in pairs]


def _closed_form_plan(mech: Mechanism):
    """Per limb ``("leg", B, A_local, l_ref, slide index)`` or ``("cu", c, k, u_local, s_ref, slide
    index)``; or a string saying why the closed form does not apply."""
    p0 = mech.platform_point
    L = mech.characteristic_length
    plan = []
    first = 0
    for limb in mech.limbs:
        types = [j.type for j in limb.joints]
        nf = sum(len(j.freedoms) for j in limb.joints)
        limited = {f"{j.name}.{f.name}" for j in limb.joints for f in j.freedoms if f.limits is not None}
        if any(f.locked for j in limb.joints for f in j.freedoms):
            return f"limb {limb.name}: has locked freedoms"
        if types in (["S", "P", "S"], ["U", "P", "S"]):
            Bp, Pj, Aj = limb.joints
            d = Aj.point - Bp.point
            ln = float(np.linalg.norm(d))
            if ln < 1e-12 * L or np.linalg.norm(np.cross(Pj.freedoms[0].direction, d / ln)) > 1e-9:
                return f"limb {limb.name}: the prismatic joint is not along the leg"
            if limited - {f"{Pj.name}.slide"}:
                return f"limb {limb.name}: limits on rotations of its end joints"
            plan.append(("leg", Bp.point, Aj.point - p0, ln, first + len(Bp.freedoms)))
        elif types == ["C", "U"]:
            Cj, Uj = limb.joints
            k = Cj.freedoms[0].direction
            if limited - {f"{Cj.name}.slide"}:
                return f"limb {limb.name}: limits on its rotations"
            s_ref = float(np.dot(Uj.point - Cj.point, k))
            plan.append(("cu", Cj.point, k, Uj.point - p0, s_ref, first + 1))
        else:
            return f"limb {limb.name}: joints {'-'.join(types)} have no closed form here"
        first += nf
    return plan


def pose_checker(mech: Mechanism, limits: WorkspaceLimits | None = None, *, method: str = "auto",
                 general_seeds: int = 6) -> PoseChecker:
    """The pose-check kernel of ``mech``: ``method`` ``"auto"`` (closed form when every limb is
    S-P-S, U-P-S or C-U, else general), ``"closed-form"`` or ``"general"``.

    The general kernel solves each pose by :func:`..kinematics.position.inverse_position` from
    the reference configuration; when that assembly violates a limit it also searches every
    limb's other assemblies (``general_seeds`` random starts per limb) and keeps, per limb, one
    that violates the fewest freedom limits (limbs are independent once the pose is fixed).
    """
    if method not in ("auto", "closed-form", "general"):
        raise ValueError(f"method: expected 'auto', 'closed-form' or 'general', got {method!r}")
    limits = default_limits(mech) if limits is None else limits
    if not isinstance(limits, WorkspaceLimits):
        raise ValueError(f"limits: expected a WorkspaceLimits, got {type(limits).__name__}")
    from ..kinematics.closure import Configuration, joint_points

    ref_points = joint_points(mech, Configuration.reference(mech))
    links, cones, pairs, fl, names, scale = _common(mech, limits, ref_points)
    plan = _closed_form_plan(mech) if method != "general" else "general kernel requested"
    if isinstance(plan, str) and method == "closed-form":
        raise ValueError(f"method: no closed form for {mech.name}: {plan}")
    refs = mech.freedom_refs
    los = np.array([refs[k].freedom.limits[0] for k in fl])
    his = np.array([refs[k].freedom.limits[1] for k in fl])
    rot = np.array([refs[k].freedom.kind != "P" for k in fl], dtype=bool)
    offs = np.array([r.freedom.offset for r in refs])
    L = mech.characteristic_length
    n_links = len(links)
    names = names + [_CLOSURE]
    scale = np.array(scale + [L])

    if not isinstance(plan, str):
        slot = {k: i for i, k in enumerate(fl)}
        link_of_limb = {lk.limb: k for k, lk in enumerate(links)}

        def fn_pre(R, p):
            n = R.shape[0]
            seg_a = np.empty((n, n_links, 3))
            seg_b = np.empty((n, n_links, 3))
            vals = np.zeros((n, len(fl)))
            closure = np.full(n, 1e-9 * L)
            for li, item in enumerate(plan):
                if item[0] == "leg":
                    _, Bp, Aloc, lref, fi = item
                    A = np.einsum("nij,j->ni", R, Aloc) + p
                    length = np.linalg.norm(A - Bp, axis=-1)
                    a_end, b_end = np.broadcast_to(Bp, A.shape), A
                    if fi in slot:
                        vals[:, slot[fi]] = offs[fi] + length - lref
                else:
                    _, c, k, uloc, sref, fi = item
                    u = np.einsum("nij,j->ni", R, uloc) + p
                    rel = u - c
                    s = rel @ k
                    closure -= np.linalg.norm(rel - s[:, None] * k, axis=-1)
                    a_end, b_end = np.broadcast_to(c, u.shape), u
                    if fi in slot:
                        vals[:, slot[fi]] = offs[fi] + s - sref
                if li in link_of_limb:
                    seg_a[:, link_of_limb[li]] = a_end
                    seg_b[:, link_of_limb[li]] = b_end
            cols = [_freedom_margins(vals, los, his, rot)] if fl else []
            cols += [c[:, None] for c in _cone_margins(seg_a, seg_b, R, cones)]
            return np.concatenate(cols + [closure[:, None]], axis=1), seg_a, seg_b

        n_pre = len(names) - 1 - len(pairs)

        def fn(R, p):
            pre, seg_a, seg_b = fn_pre(R, p)
            out = np.empty((R.shape[0], len(names)))
            out[:, :n_pre] = pre[:, :-1]
            out[:, -1] = pre[:, -1]
            for k, col in enumerate(_pair_margins(seg_a, seg_b, pairs)):
                out[:, n_pre + k] = col
            return out

        def fn_feasible(R, p):
            pre, seg_a, seg_b = fn_pre(R, p)
            ok = np.all(pre >= 0.0, axis=1)
            live = np.flatnonzero(ok)  # interference (the costly part) only where the rest holds
            if live.size and pairs:
                for col in _pair_margins(seg_a[live], seg_b[live], pairs):
                    ok[live[col < 0.0]] = False
            return ok

        pinned = {}
        for item in plan:
            if item[0] == "cu" and np.linalg.norm(item[3]) < 1e-12 * L:
                axis_k = np.flatnonzero(np.abs(np.abs(item[2]) - 1.0) < 1e-12)
                if axis_k.size == 1:
                    pinned.update({_POSITION[i]: float(item[1][i]) for i in range(3) if i != axis_k[0]})
        return PoseChecker(mech, limits, "closed-form", tuple(names), scale, fn, "", pinned, fn_feasible)

    from ..kinematics.closure import limb_slices
    from ..kinematics.position import inverse_position

    def _general_row(config, R1):
        vals = offs + config.q
        pts = joint_points(mech, config)
        seg_a = np.array([[pts[lk.limb][lk.ends[0]] for lk in links]]).reshape(1, n_links, 3)
        seg_b = np.array([[pts[lk.limb][lk.ends[1]] for lk in links]]).reshape(1, n_links, 3)
        cols = [_freedom_margins(vals[fl][None], los, his, rot)] if fl else []
        cols += [c[:, None] for c in _cone_margins(seg_a, seg_b, R1, cones)]
        cols += [c[:, None] for c in _pair_margins(seg_a, seg_b, pairs)]
        cols.append(np.array([[1e-9 * L]]))  # reachable: the same closure margin as the closed form
        return np.concatenate(cols, axis=1)[0]

    def fn_general(R, p):
        n = R.shape[0]
        out = np.empty((n, len(names)))
        for i in range(n):
            pose = Pose(R[i], p[i])
            res = inverse_position(mech, pose)
            best = None
            if res.reachable and res.config is not None:
                best = _general_row(res.config, R[i : i + 1])
                if np.all(best >= 0.0):
                    out[i] = best
                    continue
            # another assembly of some limb (e.g. a leg flipped through its base joint, with a
            # negative slide) may satisfy the limits: search every limb's solutions
            alt = inverse_position(mech, pose, all_solutions=True, n_seeds=general_seeds)
            if alt.reachable:
                q = np.zeros(len(refs))
                for sl, lsol in zip(limb_slices(mech), alt.limbs):
                    k = min(range(len(lsol.solutions)), key=lambda j: len(lsol.violations[j]))
                    q[sl] = lsol.solutions[k]
                row = _general_row(Configuration(q, pose.displacement(mech.platform_point)), R[i : i + 1])
                if best is None or np.min(row / scale) > np.min(best / scale):
                    best = row
            if best is None:
                best = np.ones(len(names))  # only the closure margin decides
                best[-1] = -L
            out[i] = best
        return out

    return PoseChecker(mech, limits, "general", tuple(names), scale, fn_general, plan, {})


# ------------------------------------------------------------------------------ results
@dataclass(frozen=True)
class Extent:
    """``[lo, hi]`` of one coordinate (m or rad) and the limit active at each end (``"box"``:
    the sampled bounds, i.e. no limit found inside them)."""

    lo: float
    hi: float
    lo_limit: str
    hi_limit: str

    def to_dict(self, degrees: bool) -> dict:
        f = np.degrees if degrees else (lambda v: v)
        return {"range": [float(f(self.lo)), float(f(self.hi))], "active_limits": [self.lo_limit, self.hi_limit]}


@dataclass(frozen=True, eq=False)
class WorkspaceResult:
    """A sampled, boundary-refined workspace (see the module docstring for the method).

    ``alone[c]``: extent of coordinate ``c`` alone (the other free coordinates at their fixed
    value ``center``); ``alone_intervals[c]``: every feasible interval along that line;
    ``extents[c]``: extent over the whole set; ``volume`` in ``volume_unit``;
    ``boundary_points`` (n, d) refined boundary points (free coordinates, SI) and
    ``boundary_limits`` the active limit at each; ``feasible`` the sampled grid (axes ``grid``).
    """

    mechanism: str
    kind: str
    path: str
    path_reason: str
    sequence: str
    free: tuple[str, ...]
    fixed: dict
    center: dict
    bounds: dict
    grid: tuple[np.ndarray, ...]
    feasible: np.ndarray
    alone: dict
    alone_intervals: dict
    extents: dict
    extent_method: dict
    volume: float
    volume_unit: str
    boundary_points: np.ndarray
    boundary_limits: tuple[str, ...]
    step: dict
    tol: dict
    n_poses: int
    seconds: float
    limits: WorkspaceLimits

    @property
    def active_limits(self) -> dict[str, int]:
        """How many refined boundary points each limit bounds (largest first)."""
        names, counts = np.unique(np.array(self.boundary_limits, dtype=object).astype(str), return_counts=True)
        order = np.argsort(-counts, kind="stable")
        return {str(names[i]): int(counts[i]) for i in order}

    @property
    def n_feasible(self) -> int:
        return int(np.count_nonzero(self.feasible))

    def to_dict(self, *, boundary: bool = False) -> dict:
        """JSON-ready summary; angles in degrees (``*_deg`` keys), positions in metres (``*_m``).

        ``<c>_deg`` / ``<c>_m``: ``[min, max]`` of coordinate ``c`` alone (others fixed);
        ``<c>_deg_set`` / ``<c>_m_set``: over the whole set.
        """
        unit = lambda c: "deg" if c in _ORIENTATION else "m"  # noqa: E731
        conv = lambda c, v: float(np.degrees(v)) if c in _ORIENTATION else float(v)  # noqa: E731
        d: dict = {"mechanism": self.mechanism, "kind": self.kind, "path": self.path}
        if self.path_reason:
            d["path_reason"] = self.path_reason
        d["orientation_sequence"] = f"{self.sequence}: R = Rz(gamma) Ry(beta) Rx(alpha)"
        for c in self.free:
            e = self.alone[c]
            d[f"{c}_{unit(c)}"] = [conv(c, e.lo), conv(c, e.hi)] if e is not None else None
        for c in self.free:
            e = self.extents[c]
            d[f"{c}_{unit(c)}_set"] = [conv(c, e.lo), conv(c, e.hi)] if e is not None else None
        d["volume"] = float(self.volume)
        d["volume_unit"] = self.volume_unit
        d["active_limits"] = self.active_limits
        d["extents_active_limits"] = {
            **{f"{c}_{unit(c)}": [self.alone[c].lo_limit, self.alone[c].hi_limit] for c in self.free if self.alone[c]},
            **{f"{c}_{unit(c)}_set": [self.extents[c].lo_limit, self.extents[c].hi_limit] for c in self.free if self.extents[c]},
        }
        d["alone_intervals"] = {f"{c}_{unit(c)}": [[conv(c, a), conv(c, b)] for a, b in self.alone_intervals[c]] for c in self.free}
        d["set_extent_method"] = dict(self.extent_method)
        d["fixed"] = {f"{c}_{unit(c)}": conv(c, v) for c, v in self.fixed.items()}
        d["bounds"] = {f"{c}_{unit(c)}": [conv(c, v[0]), conv(c, v[1])] for c, v in self.bounds.items()}
        d["step"] = {f"{c}_{unit(c)}": conv(c, v) for c, v in self.step.items()}
        d["tolerance"] = {f"{c}_{unit(c)}": conv(c, v) for c, v in self.tol.items()}
        d["n_poses_checked"] = self.n_poses
        d["n_grid"] = int(self.feasible.size)
        d["n_grid_feasible"] = self.n_feasible
        d["seconds"] = self.seconds
        d["limits"] = self.limits.to_dict()
        d["caveat"] = ("extents are exact to the tolerance along the sampled lines; a feasible island "
                       "narrower than the grid step can be missed")
        if boundary:
            d["boundary_points"] = [[conv(c, v) for c, v in zip(self.free, row)] for row in self.boundary_points]
            d["boundary_limits"] = list(self.boundary_limits)
        return d


# ------------------------------------------------------------------------------ the analysis
class _Space:
    """Free coordinates -> poses (R, p), with the fixed ones filled in."""

    def __init__(self, free: tuple[str, ...], values: dict[str, float]):
        self.free = free
        self.values = values  # every coordinate's fixed / centre value
        self.idx = [COORDINATES.index(c) for c in free]

    def poses(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        full = np.tile(np.array([self.values[c] for c in COORDINATES]), (X.shape[0], 1))
        full[:, self.idx] = X
        R = euler_matrix(ORIENTATION_SEQUENCE, full[:, [5, 4, 3]])
        return R, full[:, :3]


class _Evaluator:
    def __init__(self, checker: PoseChecker, space: _Space, chunk: int, progress):
        self.checker, self.space, self.chunk, self.progress = checker, space, int(chunk), progress
        self.count = 0

    def margins(self, X: np.ndarray) -> np.ndarray:
        out = np.empty((X.shape[0], len(self.checker.names)))
        for s in range(0, X.shape[0], self.chunk):
            R, p = self.space.poses(X[s : s + self.chunk])
            out[s : s + self.chunk] = self.checker.margins(R, p)
            self._tick(R.shape[0])
        return out

    def feasible(self, X: np.ndarray) -> np.ndarray:
        out = np.empty(X.shape[0], dtype=bool)
        for s in range(0, X.shape[0], self.chunk):
            R, p = self.space.poses(X[s : s + self.chunk])
            out[s : s + self.chunk] = self.checker.feasible(R, p)
            self._tick(R.shape[0])
        return out

    def _tick(self, n: int):
        self.count += n
        if self.progress is not None:
            self.progress(n)

    def active(self, X_out: np.ndarray) -> list[str]:
        if X_out.shape[0] == 0:
            return []
        m = self.margins(X_out) / self.checker.scales
        k = np.argmin(m, axis=1)
        return [self.checker.names[i] if m[j, i] < 0 else "?" for j, i in enumerate(k)]


def _bisect(ev: _Evaluator, x_in: np.ndarray, x_out: np.ndarray, tol: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vectorised bisection between feasible ``x_in`` and infeasible ``x_out`` (n, d) until the
    bracket is below ``tol`` in every coordinate; returns the final (inside, outside) points."""
    x_in, x_out = x_in.copy(), x_out.copy()
    if x_in.shape[0] == 0:
        return x_in, x_out
    width = np.max(np.abs(x_out - x_in) / tol, axis=1).max()
    n_iter = int(np.ceil(np.log2(max(width, 1.0))))
    for _ in range(n_iter):
        mid = 0.5 * (x_in + x_out)
        ok = ev.feasible(mid)
        x_in[ok] = mid[ok]
        x_out[~ok] = mid[~ok]
    return x_in, x_out


def _axis_values(lo: float, hi: float, c: float, step: float) -> np.ndarray:
    """Regular samples of ``[lo, hi]`` with spacing ``<= step``, through ``c`` when symmetric."""
    n = max(int(np.ceil((hi - lo) / step - 1e-9)), 1)
    if abs((c - lo) - (hi - c)) < 1e-12 * max(1.0, hi - lo) and n % 2:
        n += 1
    return np.linspace(lo, hi, n + 1)


def _line_runs(F: np.ndarray, axis: int):
    """Start and end indices of the runs of True along ``axis``: (line index tuple, i0, i1)."""
    Fm = np.moveaxis(F, axis, -1)
    pad = np.zeros(Fm.shape[:-1] + (1,), dtype=bool)
    d = np.diff(np.concatenate([pad, Fm, pad], axis=-1).astype(np.int8), axis=-1)
    starts = np.argwhere(d == 1)  # (..., i): run starts at i
    ends = np.argwhere(d == -1)  # run ends at i - 1
    return starts, ends


def _refine_runs(ev, F, grid, axis, tol):
    """Refined run limits along ``axis`` of every grid line.

    Returns ``(lines, lo, hi, lo_lim, hi_lim, X_in_lo, X_in_hi)`` with one row per run.
    """
    d = F.ndim
    starts, ends = _line_runs(F, axis)
    n_ax = F.shape[axis]
    other = [k for k in range(d) if k != axis]

    def points(rows, idx):
        X = np.empty((rows.shape[0], d))
        for j, k in enumerate(other):
            X[:, k] = grid[k][rows[:, j]]
        X[:, axis] = grid[axis][idx]
        return X

    lines = starts[:, :-1]
    i0 = starts[:, -1]
    i1 = ends[:, -1] - 1
    lo = grid[axis][i0].astype(float)
    hi = grid[axis][i1].astype(float)
    lo_lim = np.array([_BOX] * len(i0), dtype=object)
    hi_lim = np.array([_BOX] * len(i1), dtype=object)
    xin_lo = points(lines, i0)
    xin_hi = points(lines, i1)
    for side, idx, nb, arr, lim, xin in (("lo", i0, i0 - 1, lo, lo_lim, xin_lo), ("hi", i1, i1 + 1, hi, hi_lim, xin_hi)):
        sel = np.flatnonzero((nb >= 0) & (nb < n_ax))
        if sel.size == 0:
            continue
        a_in, a_out = _bisect(ev, points(lines[sel], idx[sel]), points(lines[sel], nb[sel]), tol)
        arr[sel] = a_in[:, axis]
        xin[sel] = a_in
        lim[sel] = ev.active(a_out)
    return lines, lo, hi, lo_lim, hi_lim, xin_lo, xin_hi


def _trapezoid_weights(v: np.ndarray) -> np.ndarray:
    if v.size == 1:
        return np.ones(1)
    h = np.diff(v)
    w = np.zeros(v.size)
    w[:-1] += 0.5 * h
    w[1:] += 0.5 * h
    return w


def _polish(ev: _Evaluator, checker: PoseChecker, x0: np.ndarray, k: int, sign: float, bounds, tol) -> np.ndarray | None:
    """Maximise ``sign * x[k]`` subject to every margin >= 0 (SLSQP) from the feasible ``x0``."""
    scales = checker.scales

    def cons(x):
        return (ev.margins(x[None])[0] / scales)

    try:
        res = minimize(lambda x: -sign * x[k], x0, method="SLSQP", bounds=bounds,
                       constraints=[{"type": "ineq", "fun": cons}], options={"maxiter": 100, "ftol": 1e-12})
    except (ValueError, np.linalg.LinAlgError):
        return None
    x = np.asarray(res.x, dtype=float)
    return x if np.all(np.isfinite(x)) else None


def _polished_extent(ev, checker, x0, k, sign, bounds, tolv, stepv):
    """Polish one set extent: SLSQP optimum, then an inside point found by backing off along
    coordinate ``k`` and a bisection along ``k`` outwards to ``tol``.  ``None`` if no feasible
    point beyond the grid-line estimate is confirmed by the kernel."""
    x = _polish(ev, checker, x0, k, sign, bounds, tolv)
    if x is None:
        return None
    lo_b, hi_b = bounds[k]
    x_in = None
    for delta in stepv[k] * np.array([0.0, 1e-6, 1e-4, 1e-3, 1e-2, 0.1, 0.5, 1.0]):
        cand = x.copy()
        cand[k] = np.clip(x[k] - sign * delta, lo_b, hi_b)
        if ev.feasible(cand[None])[0]:
            x_in = cand
            break
    if x_in is None:
        return None
    x_out = x_in.copy()
    x_out[k] = np.clip(x_in[k] + sign * stepv[k], lo_b, hi_b)
    if ev.feasible(x_out[None])[0]:
        return None  # still feasible a grid step further out: leave it to the grid estimate
    a_in, a_out = _bisect(ev, x_in[None], x_out[None], tolv)
    return float(a_in[0, k]), ev.active(a_out)[0]


def _analyse(mech, kind, free, values, bounds, step, tol, limits, method, chunk, progress, max_poses, polish):
    t0 = time.perf_counter()
    checker = pose_checker(mech, limits, method=method)
    space = _Space(free, values)
    ev = _Evaluator(checker, space, chunk, progress)
    d = len(free)
    stepv = np.array([step[c] for c in free])
    tolv = np.array([tol[c] for c in free])
    grid = tuple(_axis_values(*bounds[c], values[c], step[c]) for c in free)
    shape = tuple(g.size for g in grid)
    n_grid = int(np.prod(shape))
    n_lines = sum(g.size for g in grid)
    if max_poses is not None and n_grid + n_lines > max_poses:
        raise ValueError(f"step: the grid has {n_grid} poses, more than max_poses = {max_poses} for the "
                         f"{checker.path} kernel; increase the step or narrow the bounds")
    centre = np.array([values[c] for c in free])

    # ---- each coordinate alone (others at their fixed value)
    alone, alone_int = {}, {}
    for k, c in enumerate(free):
        X = np.tile(centre, (grid[k].size, 1))
        X[:, k] = grid[k]
        F1 = ev.feasible(X)
        lo, hi, lo_lim, hi_lim = _refine_line(ev, F1, X, k, tolv)
        alone_int[c] = [(float(a), float(b)) for a, b in zip(lo, hi)]
        if lo.size:
            i, j = int(np.argmin(lo)), int(np.argmax(hi))
            alone[c] = Extent(float(lo[i]), float(hi[j]), str(lo_lim[i]), str(hi_lim[j]))
        else:
            alone[c] = None

    # ---- the grid
    F = np.empty(n_grid, dtype=bool)
    block = max(chunk, 1)
    for s in range(0, n_grid, block):
        idx = np.unravel_index(np.arange(s, min(s + block, n_grid)), shape)
        X = np.column_stack([grid[k][idx[k]] for k in range(d)])
        F[s : s + X.shape[0]] = ev.feasible(X)
    F = F.reshape(shape)

    # ---- boundary refinement along every grid direction
    bpts, blims = [], []
    extents, method_used = {}, {}
    volume = 0.0
    for k, c in enumerate(free):
        lines, lo, hi, lo_lim, hi_lim, xin_lo, xin_hi = _refine_runs(ev, F, grid, k, tolv)
        for X, lim, a in ((xin_lo, lo_lim, lo), (xin_hi, hi_lim, hi)):
            X = X.copy()
            X[:, k] = a
            bpts.append(X)
            blims += [str(v) for v in lim]
        if k == 0:
            w = np.ones(lines.shape[0])
            for j, kk in enumerate([m for m in range(d) if m != k]):
                w *= _trapezoid_weights(grid[kk])[lines[:, j]]
            volume = float(np.sum(w * (hi - lo)))
        if lo.size == 0:
            extents[c] = None
            continue
        i, j = int(np.argmin(lo)), int(np.argmax(hi))
        ext = [float(lo[i]), float(hi[j])]
        lims = [str(lo_lim[i]), str(hi_lim[j])]
        how = "bisection along grid lines"
        if polish and checker.path == "closed-form":
            bnds = [tuple(bounds[cc]) for cc in free]
            for side, (x0, sign) in enumerate(((xin_lo[i], -1.0), (xin_hi[j], 1.0))):
                if lims[side] == _BOX:
                    continue
                got = _polished_extent(ev, checker, x0, k, sign, bnds, tolv, stepv)
                if got is not None and sign * (got[0] - ext[side]) > 0.0:
                    ext[side], lims[side] = got
                    how = "bisection along grid lines, improved by SLSQP polish"
        extents[c] = Extent(ext[0], ext[1], lims[0], lims[1])
        method_used[c] = how
    if d == 1:
        volume_unit = "rad" if free[0] in _ORIENTATION else "m"
    else:
        us = ["rad" if c in _ORIENTATION else "m" for c in free]
        volume_unit = " ".join(f"{u}^{us.count(u)}" if us.count(u) > 1 else u for u in dict.fromkeys(us))
    if kind == "orientation":
        volume_unit += " (Euler-angle coordinates alpha, beta, gamma; not the Haar measure of SO(3))"
    bp = np.concatenate(bpts) if bpts else np.zeros((0, d))
    return WorkspaceResult(
        mechanism=mech.name, kind=kind, path=checker.path, path_reason=checker.reason,
        sequence=ORIENTATION_SEQUENCE, free=free,
        fixed={c: values[c] for c in COORDINATES if c not in free},
        center={c: values[c] for c in free}, bounds={c: tuple(bounds[c]) for c in free},
        grid=grid, feasible=F, alone=alone, alone_intervals=alone_int, extents=extents,
        extent_method=method_used, volume=volume, volume_unit=volume_unit, boundary_points=bp,
        boundary_limits=tuple(blims), step={c: float(g[1] - g[0]) if g.size > 1 else 0.0 for c, g in zip(free, grid)},
        tol={c: tol[c] for c in free}, n_poses=ev.count, seconds=time.perf_counter() - t0, limits=checker.limits,
    )


def _refine_line(ev, F1, X, k, tolv):
    """Runs of one sampled line (``X`` (n, d), feasibility ``F1``), refined along coordinate ``k``."""
    starts, ends = _line_runs(F1, 0)
    i0, i1 = starts[:, -1], ends[:, -1] - 1
    lo, hi = X[i0, k].astype(float), X[i1, k].astype(float)
    lo_lim = np.array([_BOX] * i0.size, dtype=object)
    hi_lim = np.array([_BOX] * i1.size, dtype=object)
    n = X.shape[0]
    for idx, nb, arr, lim in ((i0, i0 - 1, lo, lo_lim), (i1, i1 + 1, hi, hi_lim)):
        sel = np.flatnonzero((nb >= 0) & (nb < n))
        if sel.size:
            a_in, a_out = _bisect(ev, X[idx[sel]], X[nb[sel]], tolv)
            arr[sel] = a_in[:, k]
            lim[sel] = ev.active(a_out)
    return lo, hi, lo_lim, hi_lim


def _parse_at(at, allowed: tuple[str, ...], name: str = "at") -> dict[str, float]:
    if at is None:
        return {}
    if not isinstance(at, Mapping):
        raise ValueError(f"{name}: expected a mapping of coordinate -> value, got {type(at).__name__}")
    out = {}
    for k, v in at.items():
        if k not in allowed:
            raise ValueError(f"{name}: unknown coordinate {k!r}; expected one of {list(allowed)}")
        out[k] = float(as_finite_array(v, f"{name}.{k}", shape=()))
    return out


def _check_positive(value, name: str) -> float:
    v = float(as_finite_array(value, name, shape=()))
    if v <= 0:
        raise ValueError(f"{name}: must be positive, got {v}")
    return v


def _bounds_of(bounds, free, default) -> dict:
    out = dict(default)
    if bounds is not None:
        if not isinstance(bounds, Mapping):
            raise ValueError("bounds: expected a mapping of coordinate -> (lower, upper)")
        for c, v in bounds.items():
            if c not in free:
                raise ValueError(f"bounds: {c!r} is not a free coordinate ({list(free)})")
            b = as_finite_array(v, f"bounds.{c}", shape=(2,))
            if not b[0] < b[1]:
                raise ValueError(f"bounds.{c}: expected lower < upper, got {tuple(b)}")
            out[c] = (float(b[0]), float(b[1]))
    return out


def orientation_workspace(
    mech: Mechanism,
    *,
    at: Mapping[str, float] | None = None,
    limits: WorkspaceLimits | None = None,
    step: float = np.radians(2.0),
    tol: float = np.radians(1e-3),
    bounds: Mapping[str, tuple[float, float]] | None = None,
    method: str = "auto",
    chunk: int = 1 << 15,
    progress: Callable[[int], None] | None = None,
    max_poses: int | None = None,
    polish: bool = True,
) -> WorkspaceResult:
    """Orientation workspace at a fixed platform position (paper B fig 5).

    ``at``: fixed coordinates (SI, rad): ``x, y, z`` default to the reference platform point;
    angles given here are held fixed too (a slice).  The free angles ``alpha, beta, gamma``
    (``R = Rz(gamma) Ry(beta) Rx(alpha)``) are sampled over ``bounds`` (default
    ``alpha, gamma in [-pi, pi]``, ``beta in [-pi/2, pi/2]``, which covers SO(3)) with spacing
    ``<= step`` rad and refined to ``tol`` rad.  ``limits`` default to :func:`default_limits`.
    ``progress(n)`` is called with the number of poses checked by each block (for a progress
    bar); ``max_poses`` guards the slow general kernel (``ValueError`` when the grid is larger).
    """
    fixed = _parse_at(at, COORDINATES)
    step = _check_positive(step, "step")
    tol = _check_positive(tol, "tol")
    values = {c: float(mech.platform_point[i]) for i, c in enumerate(_POSITION)}
    values.update({c: 0.0 for c in _ORIENTATION})
    values.update(fixed)
    free = tuple(c for c in _ORIENTATION if c not in fixed)
    if not free:
        raise ValueError("at: every angle is fixed; nothing to sample")
    default = {"alpha": (-np.pi, np.pi), "beta": (-np.pi / 2, np.pi / 2), "gamma": (-np.pi, np.pi)}
    b = _bounds_of(bounds, free, {c: default[c] for c in free})
    return _analyse(mech, "orientation", free, values, b, {c: step for c in free}, {c: tol for c in free},
                    limits, method, chunk, progress, max_poses, polish)


def position_workspace(
    mech: Mechanism,
    *,
    at: Mapping[str, float] | None = None,
    limits: WorkspaceLimits | None = None,
    step: float | None = None,
    tol: float | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    method: str = "auto",
    chunk: int = 1 << 15,
    progress: Callable[[int], None] | None = None,
    max_poses: int | None = None,
    polish: bool = True,
) -> WorkspaceResult:
    """Position workspace of the platform point at a fixed orientation.

    ``at``: fixed coordinates: ``alpha, beta, gamma`` (rad, default 0) and any of ``x, y, z``
    to hold fixed (a slice).  Coordinates that a limb pins (the CU limb of paper B keeps
    ``x = y = 0``) are fixed automatically on the closed-form path.  Default ``step`` =
    characteristic length / 40, ``tol`` = characteristic length * 1e-6, ``bounds`` = reference
    point +- 2 characteristic lengths (m).
    """
    fixed = _parse_at(at, COORDINATES)
    L = mech.characteristic_length
    step = L / 40 if step is None else _check_positive(step, "step")
    tol = L * 1e-6 if tol is None else _check_positive(tol, "tol")
    checker_probe = pose_checker(mech, limits, method=method)
    values = {c: float(mech.platform_point[i]) for i, c in enumerate(_POSITION)}
    values.update({c: 0.0 for c in _ORIENTATION})
    for c, v in checker_probe.pinned.items():
        if c not in fixed:
            fixed[c] = v
    values.update(fixed)
    free = tuple(c for c in _POSITION if c not in fixed)
    if not free:
        raise ValueError("at: every position coordinate is fixed; nothing to sample")
    default = {c: (values[c] - 2 * L, values[c] + 2 * L) for c in free}
    b = _bounds_of(bounds, free, default)
    return _analyse(mech, "position", free, values, b, {c: step for c in free}, {c: tol for c in free},
                    limits, method, chunk, progress, max_poses, polish)
