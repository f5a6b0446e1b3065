"""Solution regions (Han's method, paper D section 2).

**Solution region 1** (paper D fig 3): the spherical 4R linkages of four orientations.  Its axes
are the Burmester-curve parameters of the input dyad and of the output dyad (a point of the
curve is a circle point ``u`` and its center point ``v``); each cell is a spherical 4R
``v_in - u_in - u_out - v_out`` classified by

- *type* for the input as driver: ``crank-rocker``, ``rocker-crank``, ``double-crank``,
  ``double-rocker`` (or ``degenerate`` when the two dyads share an axis);
- *defects* along the four positions: ``circuit`` (positions on different assembly circuits),
  ``branch`` (on one circuit but separated by a dead centre of the input), ``order`` (reached in
  the wrong order by a monotonic input motion).

The classification is exact on the sphere (no Grashof sign conventions, valid for link
angles beyond 90 deg): with ``A0 = v_in, A = u_in, B = u_out, B0 = v_out`` and link angles
``a = <A0 A>, b = <A B>, c = <B B0>, d = <A0 B0>``, the diagonal ``delta = <A B0>`` of any
configuration lies in both ``I1 = [|a-d|, min(a+d, 2 pi-a-d)]`` (triangle A0 A B0) and
``I2 = [|b-c|, min(b+c, 2 pi-b-c)]`` (triangle A B B0); a configuration is ``delta`` plus the
orientations ``s3 = sign det(A0, A, B0)`` and ``s1 = sign det(A, B, B0)``, which flip only where
their triangle degenerates, at an end of ``I1`` or ``I2``.  Hence: the input is a crank iff
``I1`` is inside ``I2``; then ``s1`` labels the two circuits.  If ``I2`` is inside ``I1``,
``s3`` labels them; otherwise there is one circuit.  Dead centres of the input are the
degeneracies of triangle A B B0, so ``s1`` labels the branches (rocker input).  The output is
a crank iff ``[|c-d|, min(c+d, 2 pi-c-d)]`` is inside ``[|a-b|, min(a+b, 2 pi-a-b)]``.

**Solution region 2** (paper D fig 5): for fixed directions, the input dyad's solution line and
the output dyad's solution line (parameters ``h_in``, ``h_out``: signed common-normal lengths,
see :mod:`.dyads`); each cell is an exact 4C linkage, coloured by the sign pattern of the
increments of the input fixed C joint's slide between consecutive positions (``+`` = along
``+v_in``).  The slide depends on ``h_in`` only: the region shows vertical stripes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .burmester import BurmesterCurves
from .dyads import SolutionLine
from .tasks import TaskPositions

__all__ = [
    "BRANCH",
    "CIRCUIT",
    "DEFECTS",
    "ORDER",
    "TYPES",
    "Region1",
    "Region2",
    "classify_spherical_4r",
    "sign_pattern",
    "solution_region_1",
    "solution_region_2",
]

#: Type codes of region 1.
TYPES = ("crank-rocker", "rocker-crank", "double-crank", "double-rocker", "degenerate")
#: Defect bits.
CIRCUIT, BRANCH, ORDER = 1, 2, 4
DEFECTS = {"circuit": CIRCUIT, "branch": BRANCH, "order": ORDER}

_TWO_PI = 2 * np.pi


def _angle(x, y):
    return np.arccos(np.clip(np.sum(x * y, axis=-1), -1.0, 1.0))


def _interval(p, q):
    return np.abs(p - q), np.minimum(p + q, _TWO_PI - p - q)


def classify_spherical_4r(C, u_in, v_in, u_out, v_out, *, tol: float = 1e-9):
    """Type and defects of spherical 4R linkages through four orientations (vectorised).

    ``C`` (3, 3, 3) relative rotations of the task; ``u_in, v_in, u_out, v_out`` (..., 3) unit
    vectors (moving axes at position 1, fixed axes), broadcast together.  Returns
    ``(type_code, defect_bits)`` int arrays of the broadcast shape (see :data:`TYPES`,
    :data:`DEFECTS`); ``defect_bits == 0`` is a defect-free linkage.
    """
    C = np.asarray(C, float)
    u_in, v_in, u_out, v_out = (np.asarray(x, float) for x in (u_in, v_in, u_out, v_out))
    shape = np.broadcast_shapes(u_in.shape, v_in.shape, u_out.shape, v_out.shape)[:-1]
    a = _angle(v_in, u_in)
    b = _angle(u_in, u_out)
    c = _angle(u_out, v_out)
    d = _angle(v_in, v_out)
    lo1, hi1 = _interval(a, d)
    lo2, hi2 = _interval(b, c)
    lo3, hi3 = _interval(c, d)
    lo4, hi4 = _interval(a, b)
    in_crank = (lo1 >= lo2 - tol) & (hi1 <= hi2 + tol)
    out_crank = (lo3 >= lo4 - tol) & (hi3 <= hi4 + tol)
    two_circ_s3 = ~in_crank & (lo2 >= lo1 - tol) & (hi2 <= hi1 + tol)
    type_code = np.where(in_crank, np.where(out_crank, 2, 0), np.where(out_crank, 1, 3))
    eps = 1e-7
    degenerate = (np.sin(a) < eps) | (np.sin(b) < eps) | (np.sin(c) < eps) | (np.sin(d) < eps)
    degenerate |= (lo1 > hi2 + tol) | (lo2 > hi1 + tol)  # cannot be assembled at all
    type_code = np.where(degenerate, 4, type_code)

    Cs = np.concatenate([np.eye(3)[None], C])  # (4, 3, 3)
    A = np.einsum("jab,...b->...ja", Cs, u_in)  # (..., 4, 3)
    B = np.einsum("jab,...b->...ja", Cs, u_out)
    vo = v_out[..., None, :]
    vi = v_in[..., None, :]
    s1 = np.sign(np.sum(A * np.cross(B, vo), axis=-1))  # det(A, B, B0)
    s3 = np.sign(np.sum(np.cross(vi, A) * vo, axis=-1))  # det(A0, A, B0)
    circuit = np.where(in_crank[..., None], s1, np.where(two_circ_s3[..., None], s3, 1.0))
    circuit_defect = np.any(circuit != circuit[..., :1], axis=-1)
    branch_defect = ~in_crank & ~circuit_defect & np.any(s1 != s1[..., :1], axis=-1)

    # input angles about v_in, measured from position 1
    a0 = A[..., 0, :] - np.sum(A[..., 0, :] * v_in, -1)[..., None] * v_in
    vin4 = np.broadcast_to(vi, A.shape)
    Ap = A - np.sum(A * vin4, -1)[..., None] * vin4
    theta = np.arctan2(np.sum(vin4 * np.cross(a0[..., None, :], Ap), -1), np.sum(a0[..., None, :] * Ap, -1))
    b0 = v_out - np.sum(v_out * v_in, -1)[..., None] * v_in
    theta0 = np.arctan2(np.sum(v_in * np.cross(a0, b0), -1), np.sum(a0 * b0, -1))
    # crank: cyclic order from position 1; rocker: order relative to an unreachable angle
    phi_crank = np.mod(theta[..., 1:] - theta[..., :1], _TWO_PI)
    ref = np.where(lo1 < lo2 - tol, theta0, theta0 + np.pi)
    phi_rock = np.mod(theta - ref[..., None], _TWO_PI)
    phi = np.where(in_crank[..., None], np.concatenate([np.zeros((*phi_crank.shape[:-1], 1)), phi_crank], -1), phi_rock)
    dphi = np.diff(phi, axis=-1)
    inc = np.all(dphi > 0, axis=-1)
    dec = np.all(dphi < 0, axis=-1)
    dec_crank = np.all(np.diff(phi_crank, axis=-1) < 0, axis=-1)
    ordered = np.where(in_crank, inc | dec_crank, inc | dec)
    order_defect = ~circuit_defect & ~branch_defect & ~ordered

    defects = circuit_defect * CIRCUIT + branch_defect * BRANCH + order_defect * ORDER
    defects = np.where(degenerate, 0, defects)
    return np.broadcast_to(type_code, shape).astype(np.int8), np.broadcast_to(defects, shape).astype(np.uint8)


@dataclass(frozen=True, eq=False)
class Region1:
    """Solution region 1: rows = input dyad (curve parameter ``t_in``), columns = output dyad."""

    t_in: np.ndarray
    t_out: np.ndarray
    index_in: np.ndarray  # sample indices into the curves
    index_out: np.ndarray
    type: np.ndarray  # (N, M) int8, codes of TYPES
    defects: np.ndarray  # (N, M) uint8, bits of DEFECTS

    @property
    def n_cells(self) -> int:
        return int(self.type.size)

    def mask(self, type_name: str | None = None, defect_free: bool = True) -> np.ndarray:
        m = self.type != TYPES.index("degenerate")
        if type_name is not None:
            if type_name not in TYPES:
                raise InputError(f"type: expected one of {TYPES}, got {type_name!r}")
            m &= self.type == TYPES.index(type_name)
        if defect_free:
            m &= self.defects == 0
        return m

    def counts(self) -> dict:
        out = {name: int(np.sum(self.type == k)) for k, name in enumerate(TYPES)}
        ok = self.type != TYPES.index("degenerate")
        out["defect_free"] = int(np.sum(ok & (self.defects == 0)))
        for name, bit in DEFECTS.items():
            out[f"{name}_defect"] = int(np.sum(ok & ((self.defects & bit) != 0)))
        return out

    def to_dict(self, grids: bool = False) -> dict:
        d = {"shape": list(self.type.shape), "types": list(TYPES), "defect_bits": dict(DEFECTS), "counts": self.counts()}
        if grids:
            d |= {"t_in": self.t_in.tolist(), "t_out": self.t_out.tolist(),
                  "type": self.type.tolist(), "defects": self.defects.tolist()}
        return d


def solution_region_1(task: TaskPositions, curves: BurmesterCurves, *, stride: int = 1) -> Region1:
    """Classify every pair (input sample, output sample) of the Burmester curves (paper D fig 3).

    ``stride`` takes every ``stride``-th sample on both axes (coarser, faster regions).
    """
    task.require(4, "solution region 1")
    if stride < 1:
        raise InputError(f"stride: must be >= 1, got {stride}")
    idx = np.arange(0, len(curves.t), stride)
    u, v = curves.u[idx], curves.v[idx]
    T, D = classify_spherical_4r(task.C, u[:, None], v[:, None], u[None, :], v[None, :])
    return Region1(curves.t[idx], curves.t[idx], idx, idx, T, D)


def sign_pattern(increments, *, zero: float = 0.0) -> np.ndarray:
    """``"+-+"``-style strings of the signs of slide increments (..., k) (``0`` within ``zero``)."""
    x = np.asarray(increments, float)
    ch = np.where(x > zero, "+", np.where(x < -zero, "-", "0"))
    return np.array(["".join(r) for r in ch.reshape(-1, x.shape[-1])]).reshape(x.shape[:-1])


@dataclass(frozen=True, eq=False)
class Region2:
    """Solution region 2 over ``h_in`` (rows) and ``h_out`` (columns): every cell an exact 4C.

    ``slides_in`` (N, 3): cumulative slides of the input fixed C joint from position 1;
    ``increments`` (N, 3): slides between consecutive positions; ``patterns`` (N,): their
    sign strings (the colour of fig 5; the same for every ``h_out``); ``slides_out`` (M, 3)."""

    h_in: np.ndarray
    h_out: np.ndarray
    slides_in: np.ndarray
    increments: np.ndarray
    patterns: np.ndarray
    slides_out: np.ndarray
    best_h_in: float
    best_max_abs_slide: float

    @property
    def pattern_grid(self) -> np.ndarray:
        """(N, M) pattern strings (vertical stripes: constant along ``h_out``)."""
        return np.broadcast_to(self.patterns[:, None], (len(self.h_in), len(self.h_out)))

    def to_dict(self) -> dict:
        uniq, counts = np.unique(self.patterns, return_counts=True)
        return {
            "h_in_len": self.h_in.tolist(), "h_out_len": self.h_out.tolist(),
            "patterns": self.patterns.tolist(),
            "pattern_counts": {str(k): int(n) for k, n in zip(uniq, counts, strict=True)},
            "best_h_in_len": self.best_h_in, "best_max_abs_slide_len": self.best_max_abs_slide,
        }


def solution_region_2(
    line_in: SolutionLine, line_out: SolutionLine, h_in, h_out
) -> Region2:
    """Region 2 over sampled parameters ``h_in`` (N,) and ``h_out`` (M,) (task length unit)."""
    h_in = np.asarray(h_in, float)
    h_out = np.asarray(h_out, float)
    if h_in.ndim != 1 or h_out.ndim != 1 or h_in.size < 2 or h_out.size < 2:
        raise InputError("h_in, h_out: expected 1-D arrays of at least two values")
    s = line_in.slides(h_in)
    inc = np.diff(np.concatenate([np.zeros((len(h_in), 1)), s], axis=1), axis=1)
    scale = max(1.0, float(np.max(np.abs(s))))
    pat = sign_pattern(inc, zero=1e-12 * scale)
    hb, vb = line_in.minimax_slide((float(h_in.min()), float(h_in.max())))
    return Region2(h_in, h_out, s, inc, pat, line_out.slides(h_out), hb, vb)
