"""Figures of the defect analysis (paper A figs 6-19), Matplotlib with the Agg canvas.

Each function takes a :class:`~spatialmech.analysis.defects.DefectResult` and returns a
``matplotlib.figure.Figure``; :func:`write_defect_figures` writes them all as PNG files.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from ..analysis.defects import DefectResult
from ..kinematics.position import freedom_values
from ..model.mechanism import Mechanism


def _fig(w=7.0, h=4.5):
    f = Figure(figsize=(w, h), dpi=110)
    FigureCanvasAgg(f)
    return f


def dj_at_positions(res: DefectResult) -> Figure:
    """DJ at the task positions for every driver (figs 6-9, 15-16), each driver's values
    divided by its largest |DJ| (magnitudes are not comparable between drivers)."""
    f = _fig(8, 4.8)
    ax = f.add_subplot(111)
    x = np.arange(1, len(res.fits) + 1)
    for v in res.drivers:
        dj = np.array(v.dj)
        m = np.max(np.abs(dj)) or 1.0
        ax.plot(x, dj / m, marker="o", ms=3, lw=1.2, ls="-" if v.keeps_sign else "--",
                label=v.driver + (" (keeps sign)" if v.keeps_sign else ""))
    ax.axhline(0, color="k", lw=0.8)
    ax.set_xticks(x, [f"P{i}" for i in x])
    ax.set_ylabel("DJ / max |DJ| (per driver)")
    ax.set_title(f"{res.mechanism}: DJ at the task positions")
    ax.legend(fontsize=8, ncol=2, loc="best")
    return f


def _path_arrays(res: DefectResult):
    tr = res.traces[0]
    s = np.asarray(tr.s)
    a = s if res.direction == 1 else (s[-1] - s if tr.closed else -s)
    if tr.closed and res.direction == 1:
        a = np.mod(a, s[-1])
    return tr, a


def dj_along_path(res: DefectResult, drivers=None) -> Figure:
    """DJ along the traced circuit of position 1 (figs 12-14, 18), positions marked."""
    f = _fig(8, 4.8)
    ax = f.add_subplot(111)
    tr, a = _path_arrays(res)
    order = np.argsort(a)
    drivers = drivers or (list(res.usable_drivers) + [s.driver for s in (res.plan or ())]) or [d.driver for d in res.drivers[:3]]
    on_path = (a >= 0) & (a <= (res.path_length or np.inf))
    for d in dict.fromkeys(drivers):
        y = np.asarray(tr.monitors[d])
        m = np.max(np.abs(y[on_path])) if np.any(on_path) else np.max(np.abs(y))
        m = m or 1.0
        ax.plot(a[order], (y / m)[order], lw=1.3, label=d)
    for j, arc in enumerate(res.position_arcs):
        if arc is not None:
            ax.axvline(arc, color="0.6", lw=0.8, ls=":")
            ax.text(arc, 1.02, f"P{j + 1}", ha="center", fontsize=8, transform=ax.get_xaxis_transform())
    if res.plan:
        for st in res.plan:
            if st.switch_window:
                ax.axvspan(*st.switch_window, color="tab:green", alpha=0.12)
    ax.axhline(0, color="k", lw=0.8)
    if res.path_length:
        ax.set_xlim(-0.05 * res.path_length, 1.05 * res.path_length)
    ax.set_xlabel("arc length along the path (nondimensional)")
    ax.set_ylabel("DJ / max |DJ|")
    ax.set_ylim(-1.1, 1.1)
    ax.set_title(f"{res.mechanism}: DJ along the path" + (" (green: switching window)" if res.plan else ""), pad=20)
    ax.legend(fontsize=8)
    return f


def driver_along_path(mech: Mechanism, res: DefectResult, driver: str) -> Figure:
    """The driver's value along the path (fig 17); turning points are its branch points."""
    f = _fig()
    ax = f.add_subplot(111)
    tr, a = _path_arrays(res)
    r = mech.freedom(driver)
    idx = mech.freedom_refs.index(r)
    vals = np.array([freedom_values(mech, c.q)[idx] for c in tr.points])
    rot = r.freedom.kind != "P"
    if rot:
        vals = np.degrees(np.unwrap(vals))
    order = np.argsort(a)
    ax.plot(a[order], vals[order], lw=1.4)
    for j, arc in enumerate(res.position_arcs):
        if arc is not None:
            ax.axvline(arc, color="0.6", lw=0.8, ls=":")
            ax.text(arc, 1.02, f"P{j + 1}", ha="center", fontsize=8, transform=ax.get_xaxis_transform())
    if res.path_length:
        ax.set_xlim(-0.05 * res.path_length, 1.05 * res.path_length)
    ax.set_xlabel("arc length along the path (nondimensional)")
    ax.set_ylabel(f"{driver} ({'deg' if rot else mech.length_unit})")
    ax.set_title(f"{res.mechanism}: driver {driver} along the path", pad=20)
    return f


def trajectories(mech: Mechanism, res: DefectResult) -> Figure:
    """The platform point along every traced circuit, task positions marked (figs 10, 11, 19)."""
    f = _fig(6.5, 6)
    ax = f.add_subplot(111, projection="3d")
    for k, tr in enumerate(res.traces):
        pts = np.array([c.D[:3, :3] @ mech.platform_point + c.D[:3, 3] for c in tr.points])
        ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], lw=1.2, label=f"circuit {k + 1}: P{', P'.join(map(str, res.circuits[k]))}")
    P = np.array([f.config.D[:3, :3] @ mech.platform_point + f.config.D[:3, 3] for f in res.fits])
    ax.scatter(P[:, 0], P[:, 1], P[:, 2], color="k", s=18)
    for j, p in enumerate(P):
        ax.text(p[0], p[1], p[2], f" P{j + 1}", fontsize=8)
    ax.set_xlabel(f"x ({mech.length_unit})")
    ax.set_ylabel(f"y ({mech.length_unit})")
    ax.set_zlabel(f"z ({mech.length_unit})")
    ax.set_title(f"{res.mechanism}: platform point on the circuits")
    ax.legend(fontsize=8, loc="upper left")
    return f


def write_defect_figures(mech: Mechanism, res: DefectResult, out: str | Path) -> list[Path]:
    """Write every defect figure of ``res`` into directory ``out``; returns the paths."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    figs = {"dj_at_positions": dj_at_positions(res), "trajectories": trajectories(mech, res)}
    if not res.circuit_defect:
        figs["dj_along_path"] = dj_along_path(res)
        drv = (list(res.usable_drivers) or [s.driver for s in (res.plan or ())] or [res.drivers[0].driver])[0]
        figs[f"driver_{drv}_along_path"] = driver_along_path(mech, res, drv)
    paths = []
    for name, fig in figs.items():
        p = out / f"{res.mechanism}_{name}.png"
        fig.savefig(p)
        paths.append(p)
    return paths
