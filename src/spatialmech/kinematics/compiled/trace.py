"""The Python entry of the compiled tracker loop (:mod:`.kernels_trace`): :class:`TraceLoop`
holds one track's arrays and runs the kernel from the Python loop's state
(``tracking._Walk``), appending what it traced to that state's lists."""

from __future__ import annotations

import numpy as np

from ...model.mechanism import Mechanism
from ..closure import Configuration
from .engine import compile_mechanism, driver_columns
from .kernels_trace import CLOSED, DONE, FULL, H_MIN, PYTHON_STEP, nb_arc_near, nb_pose_search, nb_trace

__all__ = ["CLOSED", "DONE", "H_MIN", "PYTHON_STEP", "TraceLoop", "arc_near", "motion_arrays", "pose_search"]


def _f64(x) -> np.ndarray:
    return np.require(x, np.float64, ["C", "W"])


class TraceLoop:
    """The compiled loop of one track of ``mech``'s motion (active freedoms ``active``, row and
    column scales ``row``, ``col``, wrapped coordinates ``wrap``) with the DJ of ``drivers`` as
    its monitors, from ``x0`` with start tangent ``t0``.  ``settings``: h0, h_min, h_max,
    max_arc, tol, cos_max, event_tol, detect_closure, max_steps; ``rank``: the rank tolerance."""

    DONE, H_MIN, CLOSED, PYTHON_STEP = DONE, H_MIN, CLOSED, PYTHON_STEP
    #: Points and events the output arrays hold; a longer track refills them (``FULL``).
    CAPACITY = (1024, 256)

    def __init__(self, mech: Mechanism, active, row, col, wrap, drivers, x0: Configuration, t0, settings: tuple,
                 rank: float):
        cm = compile_mechanism(mech)
        self.nb = cm.n_bodies
        self.G = motion_arrays(mech, active, row, col, wrap, drivers)
        idx = self.G[9]
        self.par = np.array([cm.length, rank, *settings, 1.0 if cm.n_bodies else 0.0], dtype=np.float64)
        self.X0 = (_f64(x0.q).copy(), _f64(x0.D).copy(), _f64(x0.B).reshape(self.nb, 4, 4).copy())
        self.t0 = _f64(t0).copy()
        self.n, self.nl, self.nd = cm.n, len(self.t0), len(idx)
        self._alloc(*self.CAPACITY)

    @staticmethod
    def applies(mech: Mechanism, active, n_local: int) -> bool:
        """Whether the kernel can run this motion: the engine's active freedoms, and a Jacobian
        with one column more than rows (the bordered step test)."""
        cm = compile_mechanism(mech)
        a = np.asarray(active, dtype=bool)
        return bool(np.array_equal(a, cm.active)) and n_local == 6 * cm.n_limbs + 1

    def _alloc(self, cap: int, ecap: int) -> None:
        n, nb, nl, nd = self.n, self.nb, self.nl, self.nd
        # room for one step at least (a point, an event per driver and the closure): the kernel
        # returns FULL before a step without it, and would never make one
        cap, ecap = max(cap, 2), max(ecap, nd + 1)
        self.Bf = (np.empty((cap, n)), np.empty((cap, 4, 4)), np.empty((cap, nb, 4, 4)), np.empty(cap),
                   np.empty((cap, nl)), np.empty((cap, nd)), np.empty((ecap, n)), np.empty((ecap, 4, 4)),
                   np.empty((ecap, nb, 4, 4)), np.empty((ecap, 8)), np.empty(cap))

    def run(self, w, names: list[str], event_type) -> int:
        """The kernel from the state ``w`` (``tracking._Walk``) until it finishes or hands a step
        back: ``w`` updated, its lists extended; returns the kernel's code (never ``FULL``)."""
        x = w.x
        X = (_f64(x.q).copy(), _f64(x.D).copy(), _f64(x.B).reshape(self.nb, 4, 4).copy())
        t = _f64(w.t).copy()
        fs = np.array([w.s, w.h, w.orient, 0.0])
        ist = np.array([w.flips, w.rejected, w.total_iters, w.steps, 0, 0, len(w.xs)], dtype=np.int64)
        mlast = np.array([w.mon[k][-1] for k in names], dtype=np.float64)
        while True:
            code = int(nb_trace(self.G, self.par, self.X0, self.t0, X, t, fs, ist, mlast, self.Bf))
            self._collect(w, int(ist[4]), int(ist[5]), names, event_type)
            ist[4] = ist[5] = 0
            ist[6] = len(w.xs)
            if code != FULL:
                break
        w.flips, w.rejected, w.total_iters, w.steps = int(ist[0]), int(ist[1]), int(ist[2]), int(ist[3])
        w.s, w.h, w.orient = float(fs[0]), float(fs[1]), float(fs[2])
        if code == CLOSED:
            w.s = float(fs[3])
        else:
            w.x, w.t = Configuration.of(X[0], X[1], X[2] if self.nb else x.B), t
        return code

    def _collect(self, w, npts: int, nev: int, names, event_type) -> None:
        """Points and events written by the kernel, appended to ``w``'s lists (copies: the
        arrays are written again by the next call)."""
        Pq, PD, PB, Ps, Pt, Pm, Eq, ED, EB, Ef, Pf = (a.copy() for a in self._used(npts, nev))
        B0 = w.xs[0].B
        w.floors.update(zip(range(len(w.xs), len(w.xs) + npts), Pf.tolist(), strict=True))
        w.xs.extend(Configuration.of(Pq[i], PD[i], PB[i] if self.nb else B0) for i in range(npts))
        w.ss.extend(Ps.tolist())
        w.ts.extend(Pt)
        for j, nm in enumerate(names):
            w.mon[nm].extend(Pm[:, j].tolist())
        for e in range(nev):
            f = Ef[e].tolist()
            x = Configuration.of(Eq[e], ED[e], EB[e] if self.nb else B0)
            w.events.append(event_type(names[int(f[0])], f[1], x, int(f[2]), f[3], f[4], f[5], (f[6], f[7])))

    def _used(self, npts: int, nev: int) -> tuple:
        Bf = self.Bf
        return (*(a[:npts] for a in Bf[:6]), *(a[:nev] for a in Bf[6:10]), Bf[10][:npts])


def motion_arrays(mech: Mechanism, active, row, col, wrap, drivers=()) -> tuple:
    """The arrays ``G`` of :mod:`.kernels_trace` for a motion of ``mech``."""
    cm = compile_mechanism(mech)
    idx, pos = driver_columns(mech, cm, drivers) if drivers else (np.zeros(0, np.int64), np.zeros(0, np.int64))
    return (cm.screws, cm.ball_of, cm.ball_first, cm.ball_axes, cm.ball_centre, cm.limb_start, cm.ends, cm.linear,
            np.require(active, np.bool_, ["C"]), idx, pos, _f64(row), _f64(col), np.require(wrap, np.bool_, ["C"]))


def pose_search(G: tuple, x: Configuration, t, h: float, pose: np.ndarray, xatol: float) -> tuple[float, float, float,
                                                                                                   float]:
    """:func:`.kernels_trace.nb_pose_search`: ``(step length, normalised distance, |dp|, angle)``
    of the point of the step nearest the printed pose (``pose``: R row by row, p, platform point,
    pose_tol, angle_tol)."""
    res = np.empty(4)
    nb = np.asarray(x.B).shape[0]
    nb_pose_search(G, _f64(x.q), _f64(x.D), _f64(x.B).reshape(nb, 4, 4), _f64(t), float(h), _f64(pose), float(xatol),
                   res)
    return float(res[0]), float(res[1]), float(res[2]), float(res[3])


def arc_near(G: tuple, stacked: tuple, tangents: np.ndarray, s: np.ndarray, ks: list[int],
             config: Configuration) -> tuple[float, float]:
    """:func:`.kernels_trace.nb_arc_near`: ``(distance, arc)`` of the traced points ``ks``
    (``stacked``: all points' ``q, D, B``), each moved along its tangent and corrected onto the
    curve, nearest ``config``."""
    res = np.empty(2)
    Q, DS, BS = stacked
    nb = np.asarray(config.B).shape[0]
    nb_arc_near(G, _f64(Q), _f64(DS), _f64(BS).reshape(len(Q), nb, 4, 4), _f64(tangents), _f64(s),
                np.array(ks, dtype=np.int64), _f64(config.q), _f64(config.D), _f64(config.B).reshape(nb, 4, 4), res)
    return float(res[0]), float(res[1])
