"""Grassmann line geometry: the linear variety spanned by a set of lines, and its structure.

A line is a normalised Plücker 6-vector ``(s ; s0)`` (``|s| = 1``, ``s . s0 = 0``; moment
``s0 = r x s`` of a point ``r`` on it, metres), the screw convention of the library.  A set of
lines (e.g. the force lines acting on a platform with its actuators locked) spans a linear
screw system of dimension ``rank``; the lines it contains form one of Grassmann's varieties
(Merlet, *Singular configurations of parallel manipulators and Grassmann geometry*, 1989;
Hunt, *Kinematic geometry of mechanisms*).  The variety is found from the rank and from the
Klein quadric ``K(x) = s . s0`` (``x^T DELTA x / 2``) restricted to the span or to its
reciprocal system:

============ ======================================================================= =========
rank         case (``LineSetGeometry.case``)                                          variety
============ ======================================================================= =========
1            ``single-line``                                                          line
2            ``planar-pencil`` (point + plane), ``parallel-planar-pencil``            pencil
             (direction + plane), ``two-skew-lines``
3            ``concurrent`` (a point), ``parallel`` (a direction: point at infinity), bundle
             ``coplanar`` (a plane), ``two-pencils-sharing-a-line`` (two planar
             pencils whose common line joins their centres and is the intersection
             of their planes; restricted quadric of rank 2), ``regulus`` (one
             ruling of a hyperboloid; rank 3)
4            ``degenerate-congruence`` (every line passes through a point or lies in a congruence
             plane through it), ``parabolic-congruence`` (one directrix),
             ``hyperbolic-congruence`` (every line meets two skew directrices),
             ``elliptic-congruence`` (no real directrix)
5            ``special-complex`` (every line meets one axis line),                    complex
             ``special-complex-at-infinity`` (every line is perpendicular to one
             direction), ``general-complex`` (reciprocal to a screw of pitch h != 0)
6            ``general``                                                              general
============ ======================================================================= =========

``degenerate-3-system`` is returned only if the rank-3 tests disagree numerically (an
ill-conditioned set near the tolerance); treat it as "inspect the set".

Rank decisions are scale-aware (:func:`..screws.rank` with ``length_scale``: moments divided
by a characteristic length).  Besides the whole set, :func:`classify_lines` reports the
structure of its subsets: how every pair of lines meets (point, plane) or is parallel or skew,
maximal groups of concurrent, coplanar and parallel lines, and every minimal dependent subset
(a *circuit*) classified in its own right.  A singular set (rank below ``min(6, n)``) is
explained by its circuits: e.g. paper B's singular case (c) is a rank-5 set whose circuit is
the four leg lines, a ``two-pencils-sharing-a-line``.

Worked example: three concurrent lines and a fourth one through the same point::

    >>> import numpy as np
    >>> from spatialmech.geometry.screws import plucker_line
    >>> p = np.array([0.0, 0.0, 0.4])
    >>> d = np.array([[1, 0, -1], [0, 1, -1], [-1, 0, -1], [0, -1, -1]]) / np.sqrt(2)
    >>> g = classify_lines([plucker_line(u, p) for u in d], length_scale=0.2)
    >>> g.rank, g.case, np.round(g.witnesses["point"], 12).tolist()
    (3, 'concurrent', [0.0, 0.0, 0.4])
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import combinations
from typing import Any

import numpy as np

from ..errors import InputError
from . import screws as sc

__all__ = ["LineSetGeometry", "classify_lines", "json_dict", "pair_relation"]

#: Default nondimensional tolerance (distances / length_scale, sines of angles, singular values).
DEFAULT_TOL = 1e-9

#: Subsets (circuits, groups) are analysed for at most this many lines (2^n subsets).
MAX_SUBSET_LINES = 10

_VARIETY = {1: "line", 2: "pencil", 3: "bundle", 4: "congruence", 5: "complex", 6: "general"}


# ---------------------------------------------------------------- result
def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    if isinstance(x, dict):
        return {k: _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, LineSetGeometry):
        return x.as_dict()
    return x


#: Keys of :meth:`LineSetGeometry.as_dict` that hold lengths (``*_len`` in JSON).
_LENGTH_KEYS = frozenset({"point", "offset", "distance", "pitch", "length_scale"})


def json_dict(d):
    """:meth:`LineSetGeometry.as_dict` (SI, radians) in the JSON rule of docs/json.md: lengths
    ``point_len``, ``offset_len``, ``distance_len``, ``pitch_len``, ``length_scale_len`` (the
    model's length unit), ``angle_deg`` in degrees; lines stay Plücker 6-vectors."""
    if isinstance(d, dict):
        out = {}
        for k, v in d.items():
            if k == "units":
                continue
            if k == "angle":
                out["angle_deg"] = None if v is None else float(np.degrees(v))
            elif k in _LENGTH_KEYS:
                out[f"{k}_len"] = json_dict(v)
            else:
                out[k] = json_dict(v)
        return out
    if isinstance(d, (list, tuple)):
        return [json_dict(v) for v in d]
    return d


@dataclass(frozen=True, eq=False)
class LineSetGeometry:
    """Grassmann classification of a set of lines (see the module docstring).

    ``rank`` dimension of the span; ``case`` a stable identifier (table above); ``variety``
    ``line | pencil | bundle | congruence | complex | general``; ``description`` one human
    sentence with the witnesses; ``witnesses`` the geometric evidence (SI units): ``point``,
    ``direction``, ``plane`` (``{"normal": n, "offset": c}`` for ``n . x = c``),
    ``common_line`` / ``axis`` / ``directrices`` / ``transversals`` (Plücker lines), ``pitch``,
    ``pencils`` (per pencil: line indices, centre, plane), ``lines`` (indices concerned).
    ``pairs`` how every pair meets; ``groups`` maximal concurrent / coplanar / parallel groups;
    ``circuits`` the minimal dependent subsets, each a :class:`LineSetGeometry` of that subset
    (``indices`` refer to the input order).
    """

    rank: int
    case: str
    variety: str
    description: str
    witnesses: dict = field(default_factory=dict)
    indices: tuple[int, ...] = ()
    pairs: tuple[dict, ...] = ()
    groups: dict = field(default_factory=dict)
    circuits: tuple[LineSetGeometry, ...] = ()
    length_scale: float = 1.0
    tol: float = DEFAULT_TOL

    @property
    def n_lines(self) -> int:
        return len(self.indices)

    @property
    def singular(self) -> bool:
        """Whether the lines are linearly dependent (rank below ``min(6, n)``)."""
        return self.rank < min(6, self.n_lines)

    def find_circuit(self, case: str) -> LineSetGeometry | None:
        """The first circuit of the given case, if any."""
        return next((c for c in self.circuits if c.case == case), None)

    def as_dict(self) -> dict:
        """Plain Python values, SI and radians (``point``, ``offset``, ``angle`` ...), as the
        witnesses are stored; :meth:`to_dict` is the JSON form."""
        return {
            "rank": self.rank,
            "case": self.case,
            "variety": self.variety,
            "description": self.description,
            "indices": list(self.indices),
            "witnesses": _jsonable(self.witnesses),
            "pairs": _jsonable(list(self.pairs)),
            "groups": _jsonable(self.groups),
            "circuits": [c.as_dict() for c in self.circuits],
            "length_scale": self.length_scale,
            "tol": self.tol,
            "units": "m (points, offsets, moments), unit vectors for directions",
        }

    def to_dict(self) -> dict:
        """JSON (docs/json.md): :meth:`as_dict` with units in the key names (:func:`json_dict`)."""
        return json_dict(self.as_dict())

    def summary(self) -> str:
        """Several lines of text: the classification, its witnesses and the circuits."""
        out = [f"{self.n_lines} lines, rank {self.rank}: {self.case}. {self.description}"]
        for c in self.circuits:
            out.append(f"  circuit {list(c.indices)} (rank {c.rank}): {c.case}. {c.description}")
        for kind, gs in self.groups.items():
            for g in gs:
                out.append(f"  {kind} group {g['lines']}")
        return "\n".join(out)


# ---------------------------------------------------------------- small geometry helpers
def _fmt(v) -> str:
    v = np.atleast_1d(np.asarray(v, float))
    return "(" + ", ".join(f"{x:.6g}" for x in np.where(np.abs(v) < 1e-12 * max(1.0, np.abs(v).max()), 0.0, v)) + ")"


def _canon_dir(d: np.ndarray) -> np.ndarray:
    """Unit direction with a deterministic sign (first clearly nonzero component positive)."""
    d = d / np.linalg.norm(d)
    k = int(np.argmax(np.abs(d) > 1e-9))
    return -d if d[k] < 0 else d


def _plane(normal, point) -> dict:
    n = _canon_dir(np.asarray(normal, float))
    return {"normal": n, "offset": float(n @ point)}


def _common_point(L: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares point nearest to all lines and its largest distance to them."""
    s, p = L[:, :3], sc.line_point(L)
    A = np.zeros((3, 3))
    rhs = np.zeros(3)
    for si, pi in zip(s, p, strict=True):
        P = np.eye(3) - np.outer(si, si)
        A += P
        rhs += P @ pi
    x = np.linalg.lstsq(A, rhs, rcond=None)[0]
    d = np.linalg.norm(np.cross(x - p, s), axis=1)
    return x, float(d.max())


def _common_plane(L: np.ndarray, scale: float) -> tuple[dict | None, float]:
    """Best plane containing every line: smallest singular vector of rows ``(s, 0)`` and
    ``(p/L, -1)`` acting on ``(n, c/L)``; returns the plane and the residual."""
    s, p = L[:, :3], sc.line_point(L) / scale
    M = np.vstack([np.c_[s, np.zeros(len(s))], np.c_[p, -np.ones(len(p))]])
    _, _sv, vt = np.linalg.svd(M)
    v = vt[-1]
    nn = np.linalg.norm(v[:3])
    if nn < 1e-12:
        return None, np.inf
    n, c = v[:3] / nn, v[3] / nn * scale
    # residual in nondimensional distances / sines
    res = max(np.abs(s @ n).max(), np.abs(sc.line_point(L) @ n - c).max() / scale)
    return _plane(n, n * c), float(res)


def _is_parallel_set(L: np.ndarray, tol: float) -> bool:
    s = L[:, :3]
    return bool(np.all(np.linalg.norm(np.cross(s[0], s), axis=1) < tol))


def _as_line(x: np.ndarray, scale: float, tol: float) -> dict:
    """A screw known to be a line (Klein quadric zero), in SI units: finite line (unit
    direction, point nearest the origin) or line at infinity (``(0 ; v)``: the lines meeting
    it are those perpendicular to ``v``)."""
    d = x[:3]
    nd = np.linalg.norm(d)
    if nd < tol * np.linalg.norm(x[3:]) / scale or nd < 1e-300:
        v = _canon_dir(x[3:])
        return {"at_infinity": True, "normal": v}
    s = x[:3] / nd
    m = x[3:] / nd
    m = m - s * (s @ m)  # project out round-off pitch
    sgn = 1.0 if s @ _canon_dir(s) > 0 else -1.0
    s, m = sgn * s, sgn * m
    return {"at_infinity": False, "line": np.r_[s, m], "direction": s, "point": np.cross(s, m)}


def _line_text(w: dict) -> str:
    if w["at_infinity"]:
        return f"the line at infinity of planes normal to {_fmt(w['normal'])}"
    return f"the line through {_fmt(w['point'])} along {_fmt(w['direction'])}"


def _meet(a: dict, b: dict, scale: float, tol: float) -> dict:
    """Centre (point or direction at infinity) and plane of two distinct intersecting lines
    given as :func:`_as_line` dicts."""
    if a["at_infinity"] and b["at_infinity"]:
        # two lines at infinity meet at the point at infinity along n_a x n_b
        return {"direction": _canon_dir(np.cross(a["normal"], b["normal"])), "plane": None}
    if a["at_infinity"] or b["at_infinity"]:
        f, i = (b, a) if a["at_infinity"] else (a, b)
        return {"direction": f["direction"], "plane": _plane(i["normal"], f["point"])}
    rel = pair_relation(a["line"], b["line"], length_scale=scale, tol=tol)
    out = {"plane": rel.get("plane")}
    if "point" in rel:
        out["point"] = rel["point"]
    else:
        out["direction"] = rel.get("direction", a["direction"])
    return out


def pair_relation(l1, l2, *, length_scale: float = 1.0, tol: float = DEFAULT_TOL) -> dict:
    """How two lines lie: ``{"relation": "coincide" | "intersect" | "parallel" | "skew", ...}``
    with the meeting ``point`` and common ``plane`` (intersect), the common ``direction``,
    ``plane`` and ``distance`` (parallel), or the ``distance`` and ``angle`` (rad) (skew).
    Tolerances are nondimensional (distances divided by ``length_scale``)."""
    l1 = np.asarray(l1, float)
    l2 = np.asarray(l2, float)
    s1, s2 = l1[:3], l2[:3]
    p1, p2 = sc.line_point(l1), sc.line_point(l2)
    c = np.cross(s1, s2)
    sn = float(np.linalg.norm(c))
    if sn < tol:
        dist = float(np.linalg.norm(np.cross(p2 - p1, s1)))
        if dist < tol * length_scale:
            return {"relation": "coincide"}
        return {
            "relation": "parallel",
            "direction": _canon_dir(s1),
            "distance": dist,
            "plane": _plane(np.cross(s1, p2 - p1), p1),
        }
    dist = abs(float(sc.reciprocal_product(l1, l2))) / sn
    if dist < tol * length_scale:
        # closest points
        M = np.array([[1.0, -(s1 @ s2)], [s1 @ s2, -1.0]])
        t, u = np.linalg.solve(M, [(p2 - p1) @ s1, (p2 - p1) @ s2])
        x = 0.5 * (p1 + t * s1 + p2 + u * s2)
        return {"relation": "intersect", "point": x, "plane": _plane(c, x), "angle": float(np.arcsin(min(sn, 1.0)))}
    return {"relation": "skew", "distance": dist, "angle": float(np.arctan2(sn, abs(s1 @ s2)))}


# ---------------------------------------------------------------- spans
def _span(L: np.ndarray, scale: float, tol: float) -> np.ndarray:
    """Orthonormal nondimensional basis (r, 6) of the span."""
    B = sc.basis(L, length_scale=scale, rtol=tol)
    return sc.nondimensional(B, scale)


def _reciprocal(L: np.ndarray, scale: float, tol: float) -> np.ndarray:
    """Orthonormal nondimensional basis of the reciprocal system (as screws)."""
    W = sc.reciprocal_basis(L, length_scale=scale, rtol=tol)
    return sc.nondimensional(W, scale)


def _klein(B: np.ndarray) -> np.ndarray:
    """Klein quadric restricted to the rows of ``B``: ``B DELTA B^T`` (= 2 s.s0 on the span)."""
    return B @ sc.DELTA @ B.T


def _eig(M):
    lam, V = np.linalg.eigh(M)
    return lam, V


# ---------------------------------------------------------------- classification by rank
def _rank2(L, idx, scale, tol):
    lines = [L[0]] + [l for l in L[1:] if pair_relation(L[0], l, length_scale=scale, tol=tol)["relation"] != "coincide"]
    rel = pair_relation(lines[0], lines[1], length_scale=scale, tol=tol)
    if rel["relation"] == "intersect":
        pt, pl = _common_point(L)[0], rel["plane"]
        return "planar-pencil", {"point": pt, "plane": pl}, (
            f"all lines pass through {_fmt(pt)} and lie in the plane n.x = c with n = "
            f"{_fmt(pl['normal'])}, c = {pl['offset']:.6g} (a planar pencil)"
        )
    if rel["relation"] == "parallel":
        return "parallel-planar-pencil", {"direction": rel["direction"], "plane": rel["plane"]}, (
            f"all lines are parallel to {_fmt(rel['direction'])} in the plane n = "
            f"{_fmt(rel['plane']['normal'])}, c = {rel['plane']['offset']:.6g}"
        )
    return "two-skew-lines", {"distance": rel["distance"]}, (
        f"only two distinct lines, skew (distance {rel['distance']:.6g}): their span holds no other line"
    )


def _rank3(L, idx, scale, tol):
    pt, dmax = _common_point(L)
    if _is_parallel_set(L, tol):
        d = _canon_dir(L[0, :3])
        return "parallel", {"direction": d}, (
            f"all lines are parallel to {_fmt(d)} (concurrent at a point at infinity)"
        )
    if dmax < tol * scale:
        return "concurrent", {"point": pt}, f"all lines pass through the point {_fmt(pt)}"
    plane, pres = _common_plane(L, scale)
    if plane is not None and pres < tol:
        return "coplanar", {"plane": plane}, (
            f"all lines lie in the plane n.x = c with n = {_fmt(plane['normal'])}, c = {plane['offset']:.6g}"
        )
    B = _span(L, scale, tol)
    lam, V = _eig(_klein(B))
    small = np.abs(lam) < tol * max(1.0, np.abs(lam).max()) * 10
    if small.sum() == 1:
        # line pair: the singular point of the conic is the common line of the two pencils
        x = V[:, small][:, 0] @ B
        x = np.r_[x[:3], x[3:] * scale]
        common = _as_line(x, scale, tol)
        wit: dict[str, Any] = {"common_line": common.get("line"), "pencils": []}
        if common["at_infinity"]:
            # two pencils of parallel lines in parallel planes (normal n): they share the line
            # at infinity of those planes; the pencils are the classes of parallel lines
            n = common["normal"]
            pens: list[list[int]] = []
            for k in range(len(L)):
                for ks in pens:
                    if np.linalg.norm(np.cross(L[ks[0], :3], L[k, :3])) < tol:
                        ks.append(k)
                        break
                else:
                    pens.append([k])
            wit = {"common_line_at_infinity_normal": n, "pencils": [
                {"lines": [int(idx[k]) for k in ks], "direction": _canon_dir(L[ks[0], :3]),
                 "plane": _plane(n, sc.line_point(L[ks[0]]))} for ks in pens]}
            wit["pencils"].sort(key=lambda p: p["lines"])
            return "two-pencils-sharing-a-line", wit, (
                f"two pencils of parallel lines in parallel planes normal to {_fmt(n)}: they share "
                "the line at infinity of those planes"
            )
        groups: list[tuple[dict, list[int]]] = []  # (relation to the common line, members)
        for k, l in enumerate(L):
            rel = pair_relation(common["line"], l, length_scale=scale, tol=tol)
            if rel["relation"] == "coincide":
                continue
            for rel0, ks in groups:
                same_point = "point" in rel and "point" in rel0 and (
                    np.linalg.norm(rel["point"] - rel0["point"]) < np.sqrt(tol) * scale
                )
                if same_point or ("point" not in rel and "point" not in rel0):
                    ks.append(k)
                    break
            else:
                groups.append((rel, [k]))
        for rel, ks in groups:
            centre = {"point": rel["point"]} if "point" in rel else {"direction": rel["direction"]}
            wit["pencils"].append({"lines": [int(idx[k]) for k in ks], **centre, "plane": rel["plane"]})
        wit["pencils"].sort(key=lambda p: p["lines"])
        text = "; ".join(
            f"lines {p['lines']} through "
            + (_fmt(p["point"]) if "point" in p else f"the point at infinity along {_fmt(p['direction'])}")
            + " in the plane n = "
            f"{_fmt(p['plane']['normal'])}, c = {p['plane']['offset']:.6g}"
            for p in wit["pencils"]
        )
        return "two-pencils-sharing-a-line", wit, (
            f"two planar pencils ({text}) that share {_line_text(common)}, the intersection "
            "line of their planes through both centres"
        )
    if small.sum() == 0:
        R = _reciprocal(L, scale, tol)
        mu, U = _eig(_klein(R))
        # conic x^T diag(mu) x = 0 with mixed signs: three of its points
        if mu[0] * mu[-1] >= 0:
            return "degenerate-3-system", {}, "a 3-system without a real regulus (numerically ambiguous)"
        sgn = -1.0 if np.sum(mu > 0) == 1 else 1.0  # make two eigenvalues positive
        mu = sgn * mu
        order = np.argsort(mu)[::-1]
        a, b, c = mu[order]
        trans = []
        for t in (0.0, 2 * np.pi / 3, 4 * np.pi / 3):
            y = np.zeros(3)
            y[order] = [np.cos(t) / np.sqrt(a), np.sin(t) / np.sqrt(b), 1.0 / np.sqrt(-c)]
            x = (U @ y) @ R
            x = np.r_[x[:3], x[3:] * scale]
            w = _as_line(x, scale, tol)
            trans.append(w.get("line", np.r_[np.zeros(3), w.get("normal", np.zeros(3))]))
        return "regulus", {"transversals": np.array(trans)}, (
            "the lines belong to one ruling of a hyperboloid (a regulus): each meets the three "
            "transversal lines given as witnesses, which belong to the other ruling"
        )
    return "degenerate-3-system", {}, "a 3-system with an unexpected structure (numerically ambiguous)"


def _rank4(L, idx, scale, tol):
    R = _reciprocal(L, scale, tol)
    mu, U = _eig(_klein(R))
    zero = np.abs(mu) < tol * 10
    if zero.all():
        w1 = _as_line(np.r_[R[0, :3], R[0, 3:] * scale], scale, tol)
        w2 = _as_line(np.r_[R[1, :3], R[1, 3:] * scale], scale, tol)
        m = _meet(w1, w2, scale, tol)
        centre = m.get("point", m.get("direction"))
        where = "the point" if "point" in m else "the point at infinity along"
        plane = m["plane"]
        wit = {k: v for k, v in m.items() if v is not None}
        ptxt = f" and the plane n = {_fmt(plane['normal'])}, c = {plane['offset']:.6g}" if plane else ""
        return "degenerate-congruence", wit, (
            f"every line passes through {where} {_fmt(centre)} or lies in the plane through it"
            f"{ptxt} (the reciprocal system is a planar pencil)"
        )
    if zero.sum() == 1:
        x = U[:, zero][:, 0] @ R
        d = _as_line(np.r_[x[:3], x[3:] * scale], scale, tol)
        return "parabolic-congruence", {"directrices": [d]}, (
            f"a parabolic congruence: every line meets {_line_text(d)}"
        )
    if mu[0] * mu[1] < 0:
        a, b = abs(mu[0]), abs(mu[1])
        dirs = []
        for sgn in (1.0, -1.0):
            y = np.array([1.0 / np.sqrt(a), sgn / np.sqrt(b)])
            x = (U @ y) @ R
            dirs.append(_as_line(np.r_[x[:3], x[3:] * scale], scale, tol))
        return "hyperbolic-congruence", {"directrices": dirs}, (
            f"every line meets two skew lines: {_line_text(dirs[0])} and {_line_text(dirs[1])}"
        )
    return "elliptic-congruence", {"reciprocal": np.c_[R[:, :3], R[:, 3:] * scale]}, (
        "an elliptic linear congruence (its reciprocal 2-system contains no real line)"
    )


def _rank5(L, idx, scale, tol):
    W = _reciprocal(L, scale, tol)[0]
    w, w0 = W[:3], W[3:]  # nondimensional
    if np.linalg.norm(w) < tol:
        n = _canon_dir(w0)
        return "special-complex-at-infinity", {"normal": n}, (
            f"every line is perpendicular to {_fmt(n)} (they meet a common line at infinity)"
        )
    h = float(w @ w0 / (w @ w)) * scale
    s = w / np.linalg.norm(w)
    m = (w0 * scale) / np.linalg.norm(w) - h * s
    axis = _as_line(np.r_[s, m], scale, tol)
    if abs(h) < tol * scale:
        return "special-complex", {"axis": axis["line"]}, f"every line meets {_line_text(axis)}"
    return "general-complex", {"axis": axis["line"], "pitch": h}, (
        f"a general linear complex: every line is reciprocal to the screw on "
        f"{_line_text(axis)} with pitch {h:.6g}"
    )


def _classify(L, idx, scale, tol) -> tuple[int, str, dict, str]:
    r = sc.rank(L, length_scale=scale, rtol=tol)
    if r == 1:
        return r, "single-line", {"line": L[0]}, "all lines coincide"
    if r == 6:
        return r, "general", {}, "the lines span all six dimensions: no Grassmann degeneracy"
    case, wit, text = {2: _rank2, 3: _rank3, 4: _rank4, 5: _rank5}[r](L, idx, scale, tol)
    return r, case, wit, text


# ---------------------------------------------------------------- subsets
def _pairs(L, idx, scale, tol):
    out = []
    for i, j in combinations(range(len(L)), 2):
        rel = pair_relation(L[i], L[j], length_scale=scale, tol=tol)
        out.append({"lines": [int(idx[i]), int(idx[j])], **rel})
    return tuple(out)


def _maximal(sets):
    sets = sorted({frozenset(s) for s in sets}, key=lambda s: (-len(s), sorted(s)))
    keep: list[frozenset[int]] = []
    for s in sets:
        if not any(s < k for k in keep):
            keep.append(s)
    return sorted(keep, key=lambda s: sorted(s))


def _groups(L, idx, pairs, scale, tol):
    n = len(L)
    conc, copl = [], []
    s = L[:, :3]
    p = sc.line_point(L)
    for pr in pairs:
        if pr["relation"] == "intersect":
            x = pr["point"]
            through = [k for k in range(n) if np.linalg.norm(np.cross(x - p[k], s[k])) < tol * scale]
            if len(through) >= 3:
                conc.append(through)
        if pr["relation"] in ("intersect", "parallel"):
            pl = pr["plane"]
            inside = [
                k for k in range(n)
                if abs(s[k] @ pl["normal"]) < tol and abs(p[k] @ pl["normal"] - pl["offset"]) < tol * scale
            ]
            if len(inside) >= 3:
                copl.append(inside)
    par = []
    for i in range(n):
        g = [k for k in range(n) if np.linalg.norm(np.cross(s[i], s[k])) < tol]
        if len(g) >= 2:
            par.append(g)
    out = {}
    for name, sets in (("concurrent", conc), ("coplanar", copl), ("parallel", par)):
        gs = []
        for g in _maximal(sets):
            ks = sorted(g)
            sub = L[ks]
            entry: dict[str, Any] = {"lines": [int(idx[k]) for k in ks]}
            if name == "concurrent":
                entry["point"] = _common_point(sub)[0]
            elif name == "coplanar":
                entry["plane"] = _common_plane(sub, scale)[0]
            else:
                entry["direction"] = _canon_dir(sub[0, :3])
            gs.append(entry)
        out[name] = gs
    return out


def _circuits(L, idx, scale, tol):
    """Minimal dependent subsets (size <= 7), each classified."""
    n = len(L)
    found: list[frozenset] = []
    out = []
    for k in range(2, min(n, 7) + 1):
        for sub in combinations(range(n), k):
            fs = frozenset(sub)
            if any(f <= fs for f in found):
                continue
            Ls = L[list(sub)]
            if sc.rank(Ls, length_scale=scale, rtol=tol) < k:
                found.append(fs)
                r, case, wit, text = _classify(Ls, [idx[s] for s in sub], scale, tol)
                out.append(
                    LineSetGeometry(
                        r, case, _VARIETY[r], text, wit, tuple(int(idx[s]) for s in sub),
                        length_scale=scale, tol=tol,
                    )
                )
    return tuple(out)


# ---------------------------------------------------------------- public entry point
def classify_lines(
    lines,
    *,
    length_scale: float = 1.0,
    tol: float = DEFAULT_TOL,
    subsets: bool = True,
) -> LineSetGeometry:
    """Classify a set of lines by Grassmann's varieties and report the structure of subsets.

    ``lines``: (n, 6) normalised Plücker lines ``(s ; s0)`` (validated with
    :func:`..screws.validate_line`: unit ``s``, ``s . s0 = 0``), SI units.
    ``length_scale``: characteristic length (m) dividing moments and distances so that the
    decisions do not depend on the unit (use the mechanism's size).  ``tol``: nondimensional
    tolerance for every "is zero" decision (rank: relative singular values; distances /
    ``length_scale``; sines of angles).  ``subsets``: also compute ``pairs``, ``groups`` and
    ``circuits`` (for at most :data:`MAX_SUBSET_LINES` lines).

    Raises ``ValueError`` naming the offending argument (``lines[k]`` for a bad line).
    """
    arr = np.asarray(lines, dtype=float) if not isinstance(lines, np.ndarray) else lines.astype(float)
    if arr.ndim != 2 or arr.shape[1] != 6:
        raise InputError(f"lines: expected shape (n, 6), got {arr.shape}")
    if arr.shape[0] == 0:
        raise InputError("lines: at least one line is needed")
    for k, l in enumerate(arr):
        sc.validate_line(l, name=f"lines[{k}]")
    if not (np.isfinite(length_scale) and length_scale > 0):
        raise InputError(f"length_scale: must be a positive finite length, got {length_scale!r}")
    if not (np.isfinite(tol) and 0 < tol < 1e-2):
        raise InputError(f"tol: must be in (0, 0.01), got {tol!r}")
    idx = list(range(len(arr)))
    r, case, wit, text = _classify(arr, idx, float(length_scale), float(tol))
    pairs, groups, circuits = (), {}, ()
    if subsets and len(arr) <= MAX_SUBSET_LINES:
        pairs = _pairs(arr, idx, length_scale, tol)
        groups = _groups(arr, idx, pairs, length_scale, tol)
        circuits = _circuits(arr, idx, length_scale, tol)
    return LineSetGeometry(
        r, case, _VARIETY[r], text, wit, tuple(idx), pairs, groups, circuits, float(length_scale), float(tol)
    )
