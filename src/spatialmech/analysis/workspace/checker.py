"""Vectorised pose checking: margins of every limit for stacks of poses (closed form or general)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...model.mechanism import Mechanism, Pose
from .limits import (
    CLOSURE,
    POSITION_COORDINATES,
    WorkspaceLimits,
    default_limits,
)


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
        raise InputError(f"cones: the limb of joint #{joint} has no link (all its joints coincide)")
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
    out = np.empty((*v.shape[:-1], 2 * v.shape[-1]))
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
            raise InputError(f"cones: {mech.name} has no joint {c.joint!r}")
        li, ji = joint_at[c.joint]
        if mech.limbs[li].joints[ji].type not in ("S", "U", "Sm"):
            raise InputError(f"cones: joint {c.joint!r} is a {mech.limbs[li].joints[ji].type} joint, not S or U")
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


def _cone_specs(cones) -> list[tuple]:
    """The cone (limit, link) pairs as the compiled margins take them: ``(axis, in the platform
    frame, max_angle, link)``."""
    return [(c.axis, c.frame == "platform", c.max_angle, k) for c, k in cones]


def _pair_margins(seg_a, seg_b, pairs):
    """Capsule margins ``distance - (d_i + d_j) / 2`` (m) of the link pairs."""
    return [segment_distance(seg_a[:, i], seg_b[:, i], seg_a[:, j], seg_b[:, j]) - clearance for i, j, clearance in pairs]


def _closed_form_plan(mech: Mechanism):
    """Per limb ``("leg", B, A_local, l_ref, slide index)`` or ``("cu", c, k, u_local, s_ref, slide
    index)``; or a string saying why the closed form does not apply."""
    p0 = mech.platform_point
    L = mech.characteristic_length
    plan: list[tuple] = []  # ("leg", B, A, length, index) or ("cu", C, k, U, s_ref, index)
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
        raise InputError(f"method: expected 'auto', 'closed-form' or 'general', got {method!r}")
    limits = default_limits(mech) if limits is None else limits
    if not isinstance(limits, WorkspaceLimits):
        raise InputError(f"limits: expected a WorkspaceLimits, got {type(limits).__name__}")
    from ...kinematics.closure import Configuration, joint_points

    ref_points = joint_points(mech, Configuration.reference(mech))
    links, cones, pairs, fl, names, scale = _common(mech, limits, ref_points)
    plan = _closed_form_plan(mech) if method != "general" else "general kernel requested"
    if isinstance(plan, str) and method == "closed-form":
        raise InputError(f"method: no closed form for {mech.name}: {plan}")
    refs = mech.freedom_refs
    L = mech.characteristic_length
    kern = _Kernel(
        mech=mech, links=links, cones=cones, pairs=pairs, fl=fl,
        los=np.array([refs[k].freedom.limits[0] for k in fl]),
        his=np.array([refs[k].freedom.limits[1] for k in fl]),
        rot=np.array([refs[k].freedom.kind != "P" for k in fl], dtype=bool),
        offs=np.array([r.freedom.offset for r in refs]),
        L=L, names=[*names, CLOSURE], scale=np.array([*scale, L]),
    )
    if not isinstance(plan, str):
        cf = _ClosedFormKernel(kern, plan)
        return PoseChecker(mech, limits, "closed-form", tuple(kern.names), kern.scale, cf.margins, "", _pinned(plan, L),
                           cf.feasible)
    general = _GeneralKernel(kern, general_seeds)
    return PoseChecker(mech, limits, "general", tuple(kern.names), kern.scale, general.margins, plan, {})


@dataclass(frozen=True, eq=False)
class _Kernel:
    """What both pose-check kernels use: the links, cone (limit, link) pairs and capsule pairs
    of :func:`_common`, the limited freedoms ``fl`` with their ranges (``los``, ``his``; ``rot``:
    a rotation) and every freedom's offset, the characteristic length, the margin names and
    scales (``"closure"`` last)."""

    mech: Mechanism
    links: list[_Link]
    cones: list
    pairs: list
    fl: list[int]
    los: np.ndarray
    his: np.ndarray
    rot: np.ndarray
    offs: np.ndarray
    L: float
    names: list[str]
    scale: np.ndarray


class _ClosedFormKernel:
    """Margins of stacks of poses from the closed-form plan (:func:`_closed_form_plan`)."""

    def __init__(self, k: _Kernel, plan: list):
        self.k, self.plan = k, plan
        self.slot = {f: i for i, f in enumerate(k.fl)}
        self.link_of_limb = {lk.limb: i for i, lk in enumerate(k.links)}
        self.n_pre = len(k.names) - 1 - len(k.pairs)

    def pre(self, R, p):
        """``(margins but interference, closure last; link starts; link ends)``."""
        k = self.k
        n = R.shape[0]
        seg_a = np.empty((n, len(k.links), 3))
        seg_b = np.empty((n, len(k.links), 3))
        vals = np.zeros((n, len(k.fl)))
        closure = np.full(n, 1e-9 * k.L)
        for li, item in enumerate(self.plan):
            if item[0] == "leg":
                _, Bp, Aloc, lref, fi = item
                A = np.einsum("nij,j->ni", R, Aloc) + p
                length = np.linalg.norm(A - Bp, axis=-1)
                a_end, b_end = np.broadcast_to(Bp, A.shape), A
                if fi in self.slot:
                    vals[:, self.slot[fi]] = k.offs[fi] + length - lref
            else:
                _, c, ax, uloc, sref, fi = item
                u = np.einsum("nij,j->ni", R, uloc) + p
                rel = u - c
                s = rel @ ax
                closure -= np.linalg.norm(rel - s[:, None] * ax, axis=-1)
                a_end, b_end = np.broadcast_to(c, u.shape), u
                if fi in self.slot:
                    vals[:, self.slot[fi]] = k.offs[fi] + s - sref
            if li in self.link_of_limb:
                seg_a[:, self.link_of_limb[li]] = a_end
                seg_b[:, self.link_of_limb[li]] = b_end
        cols = [_freedom_margins(vals, k.los, k.his, k.rot)] if k.fl else []
        cols += [c[:, None] for c in _cone_margins(seg_a, seg_b, R, k.cones)]
        return np.concatenate([*cols, closure[:, None]], axis=1), seg_a, seg_b

    def margins(self, R, p):
        pre, seg_a, seg_b = self.pre(R, p)
        out = np.empty((R.shape[0], len(self.k.names)))
        out[:, : self.n_pre] = pre[:, :-1]
        out[:, -1] = pre[:, -1]
        for i, col in enumerate(_pair_margins(seg_a, seg_b, self.k.pairs)):
            out[:, self.n_pre + i] = col
        return out

    def feasible(self, R, p):
        pre, seg_a, seg_b = self.pre(R, p)
        ok = np.all(pre >= 0.0, axis=1)
        live = np.flatnonzero(ok)  # interference (the costly part) only where the rest holds
        if live.size and self.k.pairs:
            for col in _pair_margins(seg_a[live], seg_b[live], self.k.pairs):
                ok[live[col < 0.0]] = False
        return ok


def _pinned(plan: list, L: float) -> dict[str, float]:
    """Position coordinates a C-U limb through the platform point fixes (its column's axis is a
    coordinate axis): ``{"x": ..., "y": ...}``."""
    pinned = {}
    for item in plan:
        if item[0] == "cu" and np.linalg.norm(item[3]) < 1e-12 * L:
            axis_k = np.flatnonzero(np.abs(np.abs(item[2]) - 1.0) < 1e-12)
            if axis_k.size == 1:
                pinned.update({POSITION_COORDINATES[i]: float(item[1][i]) for i in range(3) if i != axis_k[0]})
    return pinned


class _GeneralKernel:
    """Margins of stacks of poses by inverse position (see :func:`pose_checker`)."""

    def __init__(self, k: _Kernel, general_seeds: int):
        mech = k.mech
        refs = mech.freedom_refs
        self.k, self.general_seeds = k, general_seeds
        self.batchable = all(ends == (None, 0) for ends in mech.limb_ends)
        self.s_limits = any(mech.limbs[refs[f].limb].joints[refs[f].joint].type == "S" for f in k.fl)
        self.simple = not k.cones and not k.pairs
        self.model_limits = any(r.freedom.limits is not None for r in refs)
        self.legs = self.closed_form_legs(mech, refs)
        # the link ends, as joint points (limb, k): every link's start, then every link's end
        self.link_points = [(lk.limb, lk.ends[0]) for lk in k.links] + [(lk.limb, lk.ends[1]) for lk in k.links]

    def closed_form_legs(self, mech: Mechanism, refs):
        """The legs of a platform on six S-P-S legs (:func:`..kinematics.leg_platform.leg_platform`)
        when no margin depends on the legs' idle spins (no freedom limit on a ball, the checker's
        or the model's): :meth:`batch` then places the legs in closed form instead of a
        Gauss-Newton per leg; else ``None``."""
        from ...kinematics.leg_platform import leg_platform

        balls = [r for r in refs if mech.limbs[r.limb].joints[r.joint].type == "S"]
        if self.s_limits or any(r.freedom.limits is not None for r in balls):
            return None
        return leg_platform(mech)

    def row(self, config, R1):
        """The margins at a closed configuration (platform orientation ``R1``, (1, 3, 3))."""
        from ...kinematics.closure import joint_points

        k = self.k
        n_links = len(k.links)
        vals = k.offs + config.q
        pts = joint_points(k.mech, config)
        seg_a = np.array([[pts[lk.limb][lk.ends[0]] for lk in k.links]]).reshape(1, n_links, 3)
        seg_b = np.array([[pts[lk.limb][lk.ends[1]] for lk in k.links]]).reshape(1, n_links, 3)
        cols = [_freedom_margins(vals[k.fl][None], k.los, k.his, k.rot)] if k.fl else []
        cols += [c[:, None] for c in _cone_margins(seg_a, seg_b, R1, k.cones)]
        cols += [c[:, None] for c in _pair_margins(seg_a, seg_b, k.pairs)]
        cols.append(np.array([[1e-9 * k.L]]))  # reachable: the same closure margin as the closed form
        return np.concatenate(cols, axis=1)[0]

    def rows(self, q, R) -> np.ndarray:
        """The margins (one row per pose) at closed configurations of joint variables ``q`` (N, n)
        whose every limb starts on the ground (platform orientations ``R`` (N, 3, 3)): the rows
        :meth:`row` gives one by one, the joint points by the compiled kernel."""
        from ...kinematics import compiled

        k = self.k
        cols = [_freedom_margins(k.offs[k.fl] + q[:, k.fl], k.los, k.his, k.rot)] if k.fl else []
        if k.cones or k.pairs:
            cols.append(compiled.link_margins_many(k.mech, q, R, self.link_points, _cone_specs(k.cones), k.pairs))
        cols.append(np.full((q.shape[0], 1), 1e-9 * k.L))
        return np.concatenate(cols, axis=1)

    def batch(self, R, p) -> tuple[np.ndarray, np.ndarray]:
        """Rows of the poses whose every limb closes from the reference (compiled, batched) and
        which the per-pose path would give the same row: those within every limit (its first
        attempt is this one), and those that break only limits its search of other assemblies
        cannot change (:meth:`final`); ``done`` marks them, the rest go through the per-pose
        path."""
        from ...kinematics import compiled
        from ...kinematics.closure import recentre_balls

        k, mech = self.k, self.k.mech
        n = R.shape[0]
        out = np.empty((n, len(k.names)))
        D = np.zeros((n, 4, 4))
        D[:, :3, :3] = R
        D[:, :3, 3] = p - np.einsum("nij,j->ni", R, mech.platform_point)
        D[:, 3, 3] = 1.0
        if self.legs is not None:  # the same joint points and slides to the Gauss-Newton's tolerance
            q, _res, ok = compiled.inverse_legs_many(self.legs, D)
        else:
            q, _res, ok = compiled.limb_inverse_many(mech, D)
        done = np.all(ok, axis=1)
        idx = np.flatnonzero(done)
        qq = q[idx]
        if self.s_limits:
            qq = np.array([recentre_balls(mech, row) for row in qq]).reshape(qq.shape)
        out[idx] = self.rows(qq, R[idx])
        inside = np.all(out[idx] >= 0.0, axis=1)
        if self.model_limits and not k.fl:  # limits the checker ignores, but the per-pose solve
            inside &= self.within_model_limits(q[idx])  # retries a solution outside (other seeds)
        done[idx] = inside
        if not self.simple and not np.all(inside):
            out_idx = idx[~inside]
            done[out_idx] = self.final(q[out_idx])
        return out, done

    def final(self, q) -> np.ndarray:
        """Whether the per-pose path keeps the reference assembly's row at each closed
        configuration ``q`` (N, n) that breaks a cone or interference limit: its search
        (:meth:`other_assemblies`) solves every limb by the multi-start, whose first start is the
        reference and, when that solution breaks none of the model's freedom limits, chooses it
        again (fewest violations, the first on a tie): the same row.  Not decided here (``False``):
        a limb the homotopy would answer, freedom limits of S joints (the search compares rows of
        joint values not re-centred), a solution outside a freedom limit of the model."""
        if self.s_limits or not self.multistart_only():
            return np.zeros(q.shape[0], dtype=bool)
        return self.within_model_limits(q)

    def within_model_limits(self, q) -> np.ndarray:
        """Whether each row of joint variables ``q`` (N, n), rotations wrapped as the per-pose
        solve wraps them, is within every freedom limit of the model (whatever the checker's
        ``freedom_limits``)."""
        from ...kinematics.distinct import wrap_rotations
        from ...kinematics.position import within_limits

        if not self.model_limits:
            return np.ones(q.shape[0], dtype=bool)
        return np.array([not within_limits(self.k.mech, wrap_rotations(self.k.mech, row)) for row in q], dtype=bool)

    def multistart_only(self) -> bool:
        """Every limb of the mechanism is solved by the multi-start in :meth:`other_assemblies`
        (``method="auto"`` of :func:`..kinematics.position.inverse_position` takes the homotopy
        for none; asked at each call: a cached homotopy solve changes the answer)."""
        from ...kinematics.homotopy.inverse import auto_reason

        for li in range(len(self.k.mech.limbs)):
            try:
                if auto_reason(self.k.mech, li, 0) is None:
                    return False
            except InputError:  # the homotopy does not cover the limb
                continue
        return True

    def margins(self, R, p):
        from ...kinematics import backend
        from ...kinematics.position import inverse_position

        k = self.k
        n = R.shape[0]
        if self.batchable and n > 1 and backend.enabled():
            out, done = self.batch(R, p)
        else:
            out, done = np.empty((n, len(k.names))), np.zeros(n, dtype=bool)
        for i in np.flatnonzero(~done):
            pose = Pose(R[i], p[i])
            res = inverse_position(k.mech, pose)
            best = None
            if res.reachable and res.config is not None:
                best = self.row(res.config, R[i : i + 1])
                if np.all(best >= 0.0):
                    out[i] = best
                    continue
            best = self.other_assemblies(pose, R[i : i + 1], best)
            if best is None:
                best = np.ones(len(k.names))  # only the closure margin decides
                best[-1] = -k.L
            out[i] = best
        return out

    def other_assemblies(self, pose: Pose, R1, best):
        """``best`` (the margins of the reference assembly, ``None`` where it does not close) or,
        when larger in its smallest scaled margin, the margins of another assembly of some limb
        (e.g. a leg flipped through its base joint, with a negative slide): per group of limbs
        that share a body, the solution that violates the fewest freedom limits."""
        from ...kinematics.closure import Configuration, hub_displacements, limb_slices
        from ...kinematics.position import inverse_position, limb_clusters

        k, mech = self.k, self.k.mech
        alt = inverse_position(mech, pose, all_solutions=True, n_seeds=self.general_seeds)
        if not alt.reachable:
            return best
        q = np.zeros(len(mech.freedom_refs))
        sls = limb_slices(mech)
        # limbs that share a body have corresponding solutions: one choice per group
        for group in limb_clusters(mech):
            viol = [sum(len(alt.limbs[g].violations[j]) for g in group)
                    for j in range(len(alt.limbs[group[0]].solutions))]
            j = int(np.argmin(viol))
            for g in group:
                q[sls[g]] = alt.limbs[g].solutions[j]
        D = pose.displacement(mech.platform_point)
        row = self.row(Configuration(q, D, hub_displacements(mech, q, D)), R1)
        if best is None or np.min(row / k.scale) > np.min(best / k.scale):
            return row
        return best


# ------------------------------------------------------------------------------ configuration checker
@dataclass(frozen=True, eq=False)
class ConfigurationChecker:
    """Named margins (>= 0 inside every limit) of one *closed configuration*: freedom limits on
    ``offset + q``, cone limits, link interference; the same names, scales and margins as
    :func:`pose_checker` without its ``closure`` margin (a configuration is closed by
    construction: the caller solved it).  Used where the pose is not known beforehand, e.g. the
    workspace over the task coordinates of a lower-mobility mechanism, whose parasitic
    coordinates are solved first.
    """

    mechanism: Mechanism
    limits: WorkspaceLimits
    names: tuple[str, ...]
    scales: np.ndarray
    _fn: Callable = field(repr=False)
    _many: Callable | None = field(default=None, repr=False)

    def margins(self, config) -> np.ndarray:
        """The (m,) margins at ``config`` (a closed :class:`~spatialmech.kinematics.closure.Configuration`)."""
        if self._many is not None:
            from ...kinematics import backend

            if backend.enabled():
                return self._many(np.asarray(config.q, dtype=float)[None], np.asarray(config.D, dtype=float)[None])[0]
        return self._fn(config)

    def margins_many(self, configs) -> np.ndarray:
        """The (N, m) margins at the closed configurations ``configs``: in one batch (the joint
        points by the compiled kernel) when every limb starts on the ground and the compiled
        engine is in use, else one by one (:meth:`margins`)."""
        configs = list(configs)
        if self._many is not None and configs:
            from ...kinematics import backend

            if backend.enabled():
                return self._many(np.array([c.q for c in configs], dtype=float).reshape(len(configs), -1),
                                  np.array([c.D for c in configs], dtype=float).reshape(-1, 4, 4))
        return np.array([self._fn(c) for c in configs]).reshape(len(configs), len(self.names))

    def violated(self, config) -> str:
        """The most violated limit (scaled margins) at ``config``, ``""`` when within every limit."""
        if not self.names:
            return ""
        m = self.margins(config) / self.scales
        k = int(np.argmin(m))
        return self.names[k] if m[k] < 0 else ""


def configuration_checker(mech: Mechanism, limits: WorkspaceLimits | None = None) -> ConfigurationChecker:
    """The limit margins of closed configurations of ``mech`` (``limits`` default to
    :func:`default_limits`); see :class:`ConfigurationChecker`."""
    limits = default_limits(mech) if limits is None else limits
    if not isinstance(limits, WorkspaceLimits):
        raise InputError(f"limits: expected a WorkspaceLimits, got {type(limits).__name__}")
    from ...kinematics.closure import Configuration, joint_points

    ref_points = joint_points(mech, Configuration.reference(mech))
    links, cones, pairs, fl, names, scale = _common(mech, limits, ref_points)
    refs = mech.freedom_refs
    los = np.array([refs[k].freedom.limits[0] for k in fl])
    his = np.array([refs[k].freedom.limits[1] for k in fl])
    rot = np.array([refs[k].freedom.kind != "P" for k in fl], dtype=bool)
    offs = np.array([r.freedom.offset for r in refs])
    n_links = len(links)

    def fn(config) -> np.ndarray:
        cols = [_freedom_margins((offs + config.q)[fl][None], los, his, rot)] if fl else []
        if cones or pairs:
            pts = joint_points(mech, config)
            seg_a = np.array([pts[lk.limb][lk.ends[0]] for lk in links]).reshape(1, n_links, 3)
            seg_b = np.array([pts[lk.limb][lk.ends[1]] for lk in links]).reshape(1, n_links, 3)
            R1 = np.asarray(config.D, dtype=float)[None, :3, :3]
            cols += [c[:, None] for c in _cone_margins(seg_a, seg_b, R1, cones)]
            cols += [c[:, None] for c in _pair_margins(seg_a, seg_b, pairs)]
        return np.concatenate(cols, axis=1)[0] if cols else np.zeros(0)

    link_points = [(lk.limb, lk.ends[0]) for lk in links] + [(lk.limb, lk.ends[1]) for lk in links]

    def many(q: np.ndarray, D: np.ndarray) -> np.ndarray:
        """``fn`` for a stack of configurations (joint variables ``q`` (N, n), platforms ``D``)."""
        from ...kinematics import compiled

        cols = [_freedom_margins(offs[fl] + q[:, fl], los, his, rot)] if fl else []
        if cones or pairs:
            cols.append(compiled.link_margins_many(mech, q, D[:, :3, :3], link_points, _cone_specs(cones), pairs))
        return np.concatenate(cols, axis=1) if cols else np.zeros((q.shape[0], 0))

    ground = all(a is None for a, _ in mech.limb_ends)
    return ConfigurationChecker(mech, limits, tuple(names), np.asarray(scale, dtype=float), fn, many if ground else None)
