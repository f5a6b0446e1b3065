"""What forward position reports about each root: conditioning, distinctness, self-motions.

Shared by the general engine (:func:`spatialmech.kinematics.forward.forward_position`) and the
closed forms (:func:`spatialmech.kinematics.closed_forms.four_sps_cu_forward.forward_all`), so that both
say the same things in the same words.

- :class:`Conditioning`: the smallest singular value and the inverse condition number
  (``sigma_min / sigma_max``) of the nondimensional Jacobian that decides whether the actuators
  hold the platform; a root is *singular* when ``sigma_min`` is below
  :func:`singular_threshold` (from :mod:`spatialmech.geometry.tolerances`).
- Distances between roots are measured in pose space, scale-free: the platform point divided by
  a length scale and the rotation matrix divided by ``sqrt(2)`` (:func:`pose_keys`), so that the
  distance is ``sqrt(|dp / L|^2 + (2 sin(theta / 2))^2)``, ``theta`` the relative rotation angle.
- :func:`group_roots` turns the converged runs of a multi-start search into results:
  regular roots closer than the ``dedup`` tolerance are one assembly mode; singular roots are followed
  along their self-motion (:func:`trace_set`, with the actuators held) and every root on one
  traced continuum is one :attr:`AssemblyKind.SELF_MOTION` result; singular roots without a
  finite self-motion (several assembly modes meeting) are one
  :attr:`AssemblyKind.SINGULAR` result within a looser distance (such a root is only found
  to about the square root of the solver tolerance; :func:`dedup_tolerances`).

    >>> import numpy as np
    >>> c = Conditioning.from_singular_values([2.0, 1.0, 1e-9], "example", threshold=1e-5)
    >>> c.singular, c.condition
    (True, 5e-10)
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np

from ..geometry.tolerances import Tolerances, current
from ..results import TrackStatus
from ..serialize import fields_dict
from .tracking import conventional_sense, correct_on_hyperplane, track

__all__ = [
    "AssemblyKind",
    "Conditioning",
    "RootGroup",
    "SelfMotion",
    "Trace",
    "dedup_tolerances",
    "distance_to_polylines",
    "group_roots",
    "polylines_touch",
    "pose_keys",
    "singular_threshold",
    "trace_set",
]

#: A root lies on a traced self-motion when its distance to the trace is below
#: ``TOUCH_TOL + TOUCH_REL * (length of the nearest traced segment)`` (chords cut corners).
TOUCH_TOL = 1e-3
TOUCH_REL = 0.25
#: A trace whose poses stay within this distance of its start is not a finite self-motion.
MOVED_TOL = 1e-2
#: Largest number of self-motion traces in one multi-start search (each costs many solves).
MAX_TRACES = 12


def singular_threshold(solver_tol: float | None = None, tol: Tolerances | None = None) -> float:
    """``sigma_min`` below which a root is singular: the ``singular`` tolerance, raised to ten
    times the square root of the solver's (nondimensional) residual tolerance (default: the
    ``newton`` tolerance).  A root on a singular set solved to a residual ``r`` lies up to about
    ``sqrt(r)`` from it (the residual grows quadratically there), where ``sigma_min`` is of that
    order: 1e-12 gives 1e-5."""
    t = current() if tol is None else tol
    r = t.newton if solver_tol is None else float(solver_tol)
    return max(t.singular, 10.0 * float(np.sqrt(r)))


def dedup_tolerances(solver_tol: float | None = None, tol: Tolerances | None = None) -> tuple[float, float]:
    """Pose distances below which two regular roots (the ``dedup`` tolerance), or two isolated
    singular roots (a hundred times the square root of the solver tolerance: such roots are only
    found to about that), are the same result."""
    t = current() if tol is None else tol
    r = t.newton if solver_tol is None else float(solver_tol)
    return t.dedup, max(t.dedup, 100.0 * float(np.sqrt(r)))


class AssemblyKind(StrEnum):
    """What one forward-position result is."""

    REGULAR = "regular"  #: an isolated assembly mode where the actuators hold the platform
    SINGULAR = "singular"  #: an isolated root where the Jacobian is singular (modes meet there)
    SELF_MOTION = "self-motion"  #: one point standing for a continuum of poses (actuators held)


@dataclass(frozen=True)
class Conditioning:
    """Conditioning of a forward-position root (nondimensional).

    ``sigma_min``: smallest singular value of the scale-free Jacobian named by ``measure`` (0 at
    a singularity); ``condition``: ``sigma_min / sigma_max`` in [0, 1] (the inverse condition
    number, as ``CompleteJacobian.condition``); ``singular``: ``sigma_min < threshold``
    (:func:`singular_threshold`)."""

    sigma_min: float
    condition: float
    measure: str
    threshold: float
    free_dim: int = 0  # independent platform twists left with the actuators held (singular values below threshold)

    @property
    def singular(self) -> bool:
        return bool(self.sigma_min < self.threshold)

    @classmethod
    def from_singular_values(cls, sv, measure: str, *, n_required: int | None = None,
                             threshold: float | None = None) -> Conditioning:
        """From the singular values of the Jacobian; fewer than ``n_required`` means
        rank-deficient by construction (``sigma_min = 0``).  ``threshold`` defaults to
        :func:`singular_threshold` ``()``."""
        thr = singular_threshold() if threshold is None else float(threshold)
        sv = np.sort(np.abs(np.asarray(sv, dtype=float).ravel()))[::-1]
        need = sv.size if n_required is None else int(n_required)
        free = int(max(need - sv.size, 0) + np.sum(sv < thr))
        if sv.size == 0 or sv.size < need or sv[0] <= 0:
            return cls(0.0, 0.0, measure, thr, max(free, 1))
        return cls(float(sv[-1]), float(sv[-1] / sv[0]), measure, thr, free)

    def to_dict(self) -> dict:
        return fields_dict(self, {"threshold": "singular_below"},
                           names=("sigma_min", "condition", "singular", "threshold", "measure", "free_dim"))


def pose_keys(R, p, length_scale: float) -> np.ndarray:
    """Scale-free pose coordinates (..., 12): ``(p / length_scale, R.ravel() / sqrt(2))``.

    Their Euclidean distance is ``sqrt(|dp / L|^2 + (2 sin(theta / 2))^2)`` (``theta`` the
    relative rotation angle): continuous, free of Euler-angle wrap-around and gimbal lock."""
    R = np.asarray(R, dtype=float)
    p = np.asarray(p, dtype=float)
    return np.concatenate([p / float(length_scale), R.reshape(*R.shape[:-2], 9) / np.sqrt(2.0)], axis=-1)


def _rotation_angle_of_key_gap(d) -> np.ndarray:
    """Relative rotation angle (rad) from the distance of the rotation parts of two keys."""
    return 2.0 * np.arcsin(np.clip(np.asarray(d, dtype=float) / 2.0, 0.0, 1.0))


def distance_to_polylines(points, polylines: Sequence[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """For each point (n, k): the smallest distance to the polylines (each (m, k)) and the length
    of the nearest segment (0 for a one-point polyline)."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    best = np.full(pts.shape[0], np.inf)
    seg_len = np.zeros(pts.shape[0])
    for poly in polylines:
        poly = np.atleast_2d(np.asarray(poly, dtype=float))
        if poly.shape[0] == 1:
            d = np.linalg.norm(pts - poly[0], axis=1)
            upd = d < best
            best[upd], seg_len[upd] = d[upd], 0.0
            continue
        a, b = poly[:-1], poly[1:]
        ab = b - a
        L2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
        for c in range(0, pts.shape[0], 64):  # chunks keep the (n, m, k) temporaries small
            P = pts[c : c + 64]
            t = np.clip(np.einsum("nij,ij->ni", P[:, None, :] - a[None], ab) / L2, 0.0, 1.0)
            d = np.linalg.norm(P[:, None, :] - (a[None] + t[..., None] * ab[None]), axis=-1)
            j = np.argmin(d, axis=1)
            dj = d[np.arange(P.shape[0]), j]
            m = dj < best[c : c + 64]
            idx = np.arange(c, c + P.shape[0])[m]
            best[idx] = dj[m]
            seg_len[idx] = np.sqrt(L2[j[m]])
    return best, seg_len


def _segment_distances(a0, a1, b0, b1) -> np.ndarray:
    """Smallest distances between the segments a0-a1 (n, k) and b0-b1 (m, k): (n, m)."""
    u, v = a1 - a0, b1 - b0
    w0 = a0[:, None, :] - b0[None, :, :]
    A = np.einsum("ik,ik->i", u, u)[:, None]
    B = np.einsum("ik,jk->ij", u, v)
    C = np.einsum("jk,jk->j", v, v)[None, :]
    D = np.einsum("ik,ijk->ij", u, w0)
    E = np.einsum("jk,ijk->ij", v, w0)
    den = A * C - B * B
    s = np.where(den > 1e-14 * np.maximum(A * C, 1e-300), (B * E - C * D) / np.where(den > 0, den, 1.0), 0.0)
    s = np.clip(s, 0.0, 1.0)
    t = np.clip((B * s + E) / np.maximum(C, 1e-300), 0.0, 1.0)
    s = np.clip((B * t - D) / np.maximum(A, 1e-300), 0.0, 1.0)
    diff = w0 + s[..., None] * u[:, None, :] - t[..., None] * v[None, :, :]
    return np.linalg.norm(diff, axis=-1)


def polylines_touch(first: Sequence[np.ndarray], second: Sequence[np.ndarray], tol: float = TOUCH_TOL,
                    rel: float = TOUCH_REL) -> bool:
    """Whether a segment (or point) of one set of polylines comes within ``tol + rel * (the longer
    segment's length)`` of one of the other's (chords of a traced curve cut its corners)."""
    for p in first:
        p = np.atleast_2d(p)
        pa, pb = (p[:-1], p[1:]) if p.shape[0] > 1 else (p, p)
        for q in second:
            q = np.atleast_2d(q)
            qa, qb = (q[:-1], q[1:]) if q.shape[0] > 1 else (q, q)
            la, lb = np.linalg.norm(pb - pa, axis=1), np.linalg.norm(qb - qa, axis=1)
            for c in range(0, pa.shape[0], 64):  # chunks keep the (n, m, k) temporaries small
                sl = slice(c, c + 64)
                limit = tol + rel * np.maximum(la[sl, None], lb[None, :])
                if bool(np.any(_segment_distances(pa[sl], pb[sl], qa, qb) <= limit)):
                    return True
    return False


@dataclass(frozen=True, eq=False)
class Trace:
    """A solution set followed from a root: polylines of pose keys (one per sense of travel)."""

    polylines: tuple[np.ndarray, ...]
    arc: float  # arc length in the problem's local coordinates (nondimensional)
    closed: bool
    hops: int  # singular points (e.g. where two continua cross) stepped over
    status: str

    @property
    def samples(self) -> int:
        return int(sum(p.shape[0] for p in self.polylines))

    def spread(self, key0) -> float:
        """Largest pose distance of a traced point from ``key0``."""
        return float(max(np.max(np.linalg.norm(p - key0, axis=1)) for p in self.polylines))


def trace_set(
    problem,
    x0,
    key_of: Callable[[Any], np.ndarray],
    *,
    h0: float = 0.02,
    h_max: float = 0.05,
    max_steps: int = 800,
    max_hops: int = 8,
) -> Trace:
    """Follow the solution set through the root ``x0`` of a tracking ``problem`` (see
    :mod:`spatialmech.kinematics.tracking`; its Jacobian is rank-deficient along the set) in both
    senses, stepping over singular points of the set (where it crosses another continuum) along
    the last tangent, until it closes or ``max_steps`` are used.  At an isolated root the trace
    does not get away from ``x0`` (see :attr:`Trace.spread`)."""
    k0 = key_of(x0)
    polylines: list[np.ndarray] = []
    arc, hops, closed = 0.0, 0, False
    status = ""
    try:
        t0 = np.asarray(problem.tangent(x0), dtype=float)
        t0 = t0 * conventional_sense(t0, getattr(problem, "sense_order", ()))  # not the SVD's sign
    except (RuntimeError, ValueError, np.linalg.LinAlgError) as e:
        return Trace((k0[None, :],), 0.0, False, 0, f"no tangent: {e}")
    budget = int(max_steps)
    for sense in (1.0, -1.0):
        line = [k0]
        nt = float(np.linalg.norm(t0))
        x, direction = x0, sense * t0 / (nt if nt > 0 else 1.0)
        state = {"far": 0.0, "steps": 0, "closed": False, "creep": False, "prev": k0, "kstep": 0.0}

        def stop(y, s, _state=state):
            k = key_of(y)
            d = float(np.linalg.norm(k - k0))
            _state["kstep"] = max(_state["kstep"], float(np.linalg.norm(k - _state["prev"])))
            _state["prev"] = k
            _state["far"] = max(_state["far"], d)
            _state["steps"] += 1
            if _state["far"] > max(3 * _state["kstep"], MOVED_TOL) and d < _state["kstep"]:
                _state["closed"] = True  # back at the start (a closed continuum)
                return True
            if _state["steps"] >= 20 and _state["far"] < 1e-2 * MOVED_TOL:
                _state["creep"] = True  # tiny accepted steps at an isolated root
                return True
            return False

        while budget > 0:
            try:
                tr = track(problem, x, direction=direction, h0=h0, h_max=h_max, max_steps=budget, max_arc=1e9,
                           detect_closure=False, stop=stop)
            except (RuntimeError, ValueError, np.linalg.LinAlgError) as e:
                status = f"stopped: {e}"
                break
            line.extend(key_of(p) for p in tr.points[1:])
            arc += float(tr.s[-1])
            budget -= max(len(tr.points) - 1, 1)
            status = tr.message
            if state["closed"] or state["creep"] or tr.status != TrackStatus.H_MIN or hops >= max_hops:
                break
            x_end, t_end = tr.points[-1], tr.tangents[-1]
            if t_end is None:
                break
            landed = None
            for H in (0.5 * h_max, h_max, 2 * h_max, 4 * h_max):
                xp = problem.retract(x_end, H * t_end)
                xn, ok, _, _ = correct_on_hyperplane(problem, xp, t_end, 1e-11, 20)
                if ok and float(problem.difference(x_end, xn) @ t_end) > 0.5 * H:
                    landed = xn
                    break
            if landed is None:
                break
            hops += 1
            line.append(key_of(landed))
            x, direction = landed, t_end
        polylines.append(np.array(line))
        if state["closed"]:
            status = "closed"
        elif state["creep"]:
            status = "no finite motion (tiny steps only)"
        if state["closed"]:
            closed = True
            polylines[-1] = np.vstack([polylines[-1], k0[None, :]])
            break
        if state["creep"] or budget <= 0:
            break
    return Trace(tuple(polylines), arc, closed, hops, status)


@dataclass(frozen=True)
class SelfMotion:
    """A continuum of poses with the actuators held, found through one or more roots."""

    members: int  # converged runs that landed on it
    samples: int  # traced points
    arc: float  # traced arc length (nondimensional local coordinates)
    closed: bool  # the trace came back to its start
    hops: int  # singular points of the set stepped over (crossings with other continua)
    position_spread: float  # largest distance of a traced platform point from the reported one (length unit)
    rotation_spread: float  # largest rotation (rad) of a traced pose from the reported one
    status: str

    def to_dict(self) -> dict:
        return {
            "members": self.members,
            "traced_samples": self.samples,
            "traced_arc": self.arc,
            "closed": self.closed,
            "crossings_stepped_over": self.hops,
            "platform_point_spread_len": self.position_spread,
            "rotation_spread_deg": float(np.degrees(self.rotation_spread)),
            "trace_status": self.status,
            "note": "a continuum of poses with the actuators held (a self-motion); the pose given is one point of it",
        }


@dataclass(eq=False)
class RootGroup:
    """Converged runs that are one result: ``rep`` is the best (smallest residual) member."""

    rep: int
    members: list[int]
    kind: AssemblyKind
    traces: list[Trace] = field(default_factory=list)
    untraced: str = ""  # why a singular root was not followed (several free directions, trace limit)

    def self_motion(self, keys: np.ndarray, length_scale: float) -> SelfMotion | None:
        if self.kind is not AssemblyKind.SELF_MOTION:
            return None
        k0 = keys[self.rep]
        pos = rot = 0.0
        for tr in self.traces:
            for p in tr.polylines:
                pos = max(pos, float(np.max(np.linalg.norm(p[:, :3] - k0[:3], axis=1))))
                rot = max(rot, float(np.max(_rotation_angle_of_key_gap(np.linalg.norm(p[:, 3:] - k0[3:], axis=1)))))
        return SelfMotion(
            members=len(self.members),
            samples=sum(t.samples for t in self.traces),
            arc=float(sum(t.arc for t in self.traces)),
            closed=any(t.closed for t in self.traces),
            hops=sum(t.hops for t in self.traces),
            position_spread=pos * float(length_scale),
            rotation_spread=rot,
            status="; ".join(t.status for t in self.traces),
        )


def group_roots(
    keys,
    singular,
    residual,
    trace: Callable[[int], Trace | None] | None,
    *,
    dedup_tol: float,
    singular_dedup_tol: float,
    prefer=None,
    free_dims=None,
    max_traces: int = MAX_TRACES,
) -> list[RootGroup]:
    """Group converged roots (pose ``keys`` (n, 12), ``singular`` flags (n,), ``residual`` (n,))
    into results (see the module docstring and :func:`dedup_tolerances`).  ``trace(i)`` follows
    the solution set through singular root ``i`` (``None``: do not trace; every singular root is
    then an isolated one).  A group's representative is its member with the smallest residual
    among those flagged in ``prefer`` (n,) (e.g. within limits), if any.  A singular root with
    ``free_dims[i] >= 2`` free platform directions (e.g. an under-actuated mechanism) is not
    followed (a curve tracer cannot cover a surface); neither is any after ``max_traces`` traces:
    such roots are kind ``singular`` with ``untraced`` saying why, merged within
    ``singular_dedup_tol``.  Groups come back in the order of their representatives' residuals."""
    keys = np.atleast_2d(np.asarray(keys, dtype=float))
    flags = np.asarray(singular, dtype=bool)
    res = np.asarray(residual, dtype=float)
    n = keys.shape[0]
    order = [int(i) for i in np.argsort(res, kind="stable")]
    group_of = [-1] * n
    groups: list[RootGroup] = []

    def join(g: int, i: int) -> None:
        groups[g].members.append(i)
        group_of[i] = g

    def on_trace(idx: list[int], g: RootGroup) -> list[int]:
        polys = [p for t in g.traces for p in t.polylines]
        d, seg = distance_to_polylines(keys[idx], polys)
        return [i for i, di, si in zip(idx, d, seg, strict=True) if di <= TOUCH_TOL + TOUCH_REL * si]

    dims = np.ones(n, dtype=int) if free_dims is None else np.asarray(free_dims, dtype=int)
    traces_used = 0
    sing = [i for i in order if flags[i]]
    for i in sing:
        if group_of[i] >= 0:
            continue
        # the same as a singular root already found, or on a continuum already traced?
        near = [g for g, grp in enumerate(groups)
                if grp.kind is AssemblyKind.SINGULAR and np.linalg.norm(keys[i] - keys[grp.rep]) <= singular_dedup_tol]
        if near:
            join(near[0], i)
            continue
        on = [g for g, grp in enumerate(groups) if grp.kind is AssemblyKind.SELF_MOTION and grp.members
              and on_trace([i], grp)]
        if on:
            join(on[0], i)
            continue
        why = ""
        if dims[i] >= 2:
            why = f"{dims[i]} free platform directions with the actuators held: a set of higher dimension, not traced"
        elif trace is not None and traces_used >= max_traces:
            why = f"not traced: the limit of {max_traces} traces per search was reached"
        tr = None
        if trace is not None and not why:
            tr = trace(i)
            traces_used += 1
        if tr is not None and tr.spread(keys[i]) > MOVED_TOL:
            new = RootGroup(i, [], AssemblyKind.SELF_MOTION, [tr])
            groups.append(new)
            gi = len(groups) - 1
            join(gi, i)
            for j in on_trace([j for j in sing if group_of[j] < 0], new):
                join(gi, j)
            # a trace that meets an earlier self-motion continues it (one connected set)
            for g_old in range(gi - 1, -1, -1):
                old = groups[g_old]
                if old.kind is AssemblyKind.SELF_MOTION and old.members and polylines_touch(
                    [p for t in old.traces for p in t.polylines], [p for t in new.traces for p in t.polylines]
                ):
                    for j in new.members:
                        join(g_old, j)
                    old.traces.extend(new.traces)
                    new.members, new.traces = [], []
                    new, gi = old, g_old
            continue
        groups.append(RootGroup(i, [], AssemblyKind.SINGULAR, untraced=why))  # isolated, or not traced
        join(len(groups) - 1, i)
    for i in order:
        if group_of[i] >= 0:
            continue
        for g, grp in enumerate(groups):
            if grp.kind is AssemblyKind.REGULAR and np.linalg.norm(keys[i] - keys[grp.rep]) <= dedup_tol:
                join(g, i)
                break
        else:
            groups.append(RootGroup(i, [], AssemblyKind.REGULAR))
            join(len(groups) - 1, i)
    pref = np.ones(n, dtype=bool) if prefer is None else np.asarray(prefer, dtype=bool)
    out = [grp for grp in groups if grp.members]
    for grp in out:
        grp.rep = min(grp.members, key=lambda j: (not pref[j], res[j]))
    out.sort(key=lambda grp: res[grp.rep])
    return out
