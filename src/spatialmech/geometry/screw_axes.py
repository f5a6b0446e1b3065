"""Principal screws of a twist system: the axes, directions and pitches that name it.

A twist system is named by the rank of its rotational part ("3R", "2R1T") only when its
members of non-zero pitch can be told apart: a 3-system whose screws all have pitch 1.74 m/rad
is *not* three rotations.  This module splits a system into

- its translations (twists ``(0; t)``), and
- ``r`` principal screws of the rotational part once the translations are removed from the
  moments: the eigenvectors of the pitch form ``Q(s) = w . v`` on twists with orthonormal
  rotation parts.  The eigenvalues are the principal pitches (m/rad) and do not depend on the
  basis; a screw's axis passes through ``w x v / |w|^2``.

Everything is deterministic: a repeated pitch (a whole plane of axes with the same pitch) is
given by the reduced row-echelon basis of its directions, never by an eigenvector that the
LAPACK kernel could turn around, and every direction is signed so that its first significant
component is positive.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .screws import basis, rref
from .tolerances import current

__all__ = ["ScrewAxis", "principal_screws"]


@dataclass(frozen=True)
class ScrewAxis:
    """One principal screw of a twist system (world frame, SI units).

    ``kind`` is ``"R"`` (pitch zero), ``"H"`` (helical, pitch non-zero) or ``"T"``
    (translation: no axis point, pitch infinite and given as ``None``).
    """

    kind: str
    direction: tuple[float, float, float]
    point_m: tuple[float, float, float] | None
    pitch_m_per_rad: float | None
    #: How many principal screws share this pitch (a repeated pitch: the axes are not unique).
    multiplicity: int = 1
    #: The model's length unit: ``point_m`` and ``pitch_m_per_rad`` are in it (metres for SI models).
    length_unit: str = "m"

    def to_dict(self) -> dict:
        """JSON fields (docs/json.md: lengths in the document's unit, the pitch per degree)."""
        return {"kind": self.kind, "direction": list(self.direction),
                "point_len": None if self.point_m is None else list(self.point_m),
                "pitch_len_per_deg": None if self.pitch_m_per_rad is None else float(np.deg2rad(self.pitch_m_per_rad)),
                "multiplicity": self.multiplicity, "length_unit": self.length_unit}

    def describe(self, fmt=lambda x: f"{x:.4g}") -> str:
        """``"H(p = 1.74 m/rad) about the axis through (x, y, z) m along (dx, dy, dz)"``."""
        d = "(" + ", ".join(fmt(x) for x in self.direction) + ")"
        if self.kind == "T" or self.point_m is None:
            return f"T along {d}"
        u = self.length_unit
        p = "(" + ", ".join(fmt(x) for x in self.point_m) + f") {u}"
        head = "R" if self.kind == "R" else f"H(p = {fmt(self.pitch_m_per_rad)} {u}/rad)"
        rep = (f" [x{self.multiplicity}: every direction in a plane has this pitch; one axis shown]"
               if self.multiplicity > 1 else "")
        return f"{head} about the axis through {p} along {d}{rep}"


def _signed(v: np.ndarray) -> np.ndarray:
    """``v`` with its first component of significant size positive (a sign fixed by the data)."""
    k = int(np.argmax(np.abs(v) > 1e-9 * max(float(np.max(np.abs(v))), 1e-300)))
    return -v if v[k] < 0 else v


def _clean(v, scale: float) -> tuple[float, float, float]:
    """A 3-vector with round-off (relative to ``scale``) set to 0."""
    a, b, c = (0.0 if abs(x) <= 1e-12 * scale else float(x) for x in v)
    return (a, b, c)


def _axis(w, v, pitch_h: float, mult: int, length_scale: float) -> ScrewAxis:
    n = float(np.linalg.norm(w))
    w, v = w / n, v / n
    if _signed(w) is not w:
        w, v = -w, -v
    point = np.cross(w, v)  # |w| = 1: the foot of the axis nearest the origin
    kind = "R" if pitch_h == 0.0 else "H"
    return ScrewAxis(kind, _clean(w, 1.0), _clean(point, length_scale), pitch_h, mult)


def _pitch_groups(W, V, ptol: float, length_scale: float) -> list[ScrewAxis]:
    """Principal screws of twists ``(W; V)`` with orthonormal ``W`` rows (equal pitches grouped)."""
    r = W.shape[0]
    out: list[ScrewAxis] = []
    if r == 0:
        return out
    h, E = np.linalg.eigh(0.5 * (W @ V.T + V @ W.T))
    i = 0
    while i < r:
        j = i + 1
        while j < r and abs(h[j] - h[i]) <= ptol:
            j += 1
        pitch_h = float(np.mean(h[i:j]))
        pitch_h = 0.0 if abs(pitch_h) <= ptol else pitch_h
        C = E[:, i:j].T
        if j - i > 1:  # a repeated pitch: one axis, the first of the rref basis of its directions
            Wg = C @ W
            C = (np.linalg.lstsq(Wg.T, rref(Wg).T, rcond=None)[0].T @ C)[:1]
        out.extend(_axis(c @ W, c @ V, pitch_h, j - i, length_scale) for c in C)
        i = j
    return out


def principal_screws(twists, *, length_scale: float = 1.0, rtol: float | None = None,
                     pitch_tol: float | None = None) -> list[ScrewAxis]:
    """The principal screws of the twist system spanned by the rows of ``twists``.

    Parameters
    ----------
    twists : array_like, shape (k, 6)
        Twists ``(w; v)`` in the world frame (moments about the origin).
    length_scale : float
        Characteristic length (m) making the rank and the pitch test scale-free.
    rtol : float, optional
        Rank tolerance (default: the ``rank`` tolerance in force).
    pitch_tol : float, optional
        Relative pitch below which a screw counts as a rotation, times ``length_scale``
        (default: the ``contains`` tolerance in force).

    Returns
    -------
    list of ScrewAxis
        Rotations and helical screws, smallest pitch first, then the translations.
    """
    T = np.atleast_2d(np.asarray(twists, dtype=float))
    t = current()
    rtol = t.rank if rtol is None else rtol
    ptol = (t.contains if pitch_tol is None else pitch_tol) * length_scale
    if T.size == 0:
        return []
    B = basis(T, length_scale=length_scale, rtol=rtol)
    if B.shape[0] == 0:
        return []
    U, S, _ = np.linalg.svd(B[:, :3])
    floor = rtol * max(1.0, float(S[0]) if S.size else 1.0)
    r = int(np.sum(floor < S))
    trans = U[:, r:].T @ B  # rows (0; t)
    tv = rref(trans[:, 3:]) if trans.shape[0] else np.zeros((0, 3))
    Q = np.linalg.qr(tv.T)[0].T if tv.shape[0] else np.zeros((0, 3))
    out: list[ScrewAxis] = []
    if r:
        reps = (U[:, :r].T @ B) / S[:r, None]  # rotation parts orthonormal
        W, V = reps[:, :3], reps[:, 3:]
        # rotation directions with a component along a translation of the system can take any
        # pitch (add that translation): they are rotations.  The pitch form is intrinsic only on
        # the directions normal to every translation of the system.
        if Q.shape[0]:
            Uc, Sc, _ = np.linalg.svd(W @ Q.T)
            k_free = int(np.sum(Sc > rtol))
            N, Rest = Uc[:, k_free:].T, Uc[:, :k_free].T
        else:
            N, Rest = np.eye(r), np.zeros((0, r))
        Vp = V - (V @ Q.T) @ Q
        out += _pitch_groups(N @ W, N @ Vp, ptol, length_scale)
        if Rest.shape[0]:
            Wr = Rest @ W
            C = np.linalg.lstsq(Wr.T, rref(Wr).T, rcond=None)[0].T @ Rest
            for c in C:
                w, v = c @ W, c @ V
                tw = (w @ Q.T) @ Q  # a translation of the system with w . tw > 0
                v = v - (w @ v) / float(tw @ tw) * tw
                out.append(_axis(w, v, 0.0, 1, length_scale))
    for q in tv:
        d = _signed(q / np.linalg.norm(q))
        out.append(ScrewAxis("T", _clean(d, 1.0), None, None))
    return out
