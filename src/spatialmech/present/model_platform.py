"""The one-model report of a parallel platform (``spatialmech report stewart-6sps``, a 6-RUS, a
3-RPS): its assembly modes, a singularity map and its workspace, each with a figure.

:func:`platform_section` adds to :func:`.models.model_section` for a model whose actuators drive
an output of two or more freedoms (``None`` for anything else):

- **assembly modes** at the reference actuator values: every mode of ``fk --all``
  (:func:`~spatialmech.kinematics.dispatch.solve_forward`, the same engine and flags), its pose
  (Euler angles in the named "ZYX" sequence), the scale-free ``sigma_min`` and the certificate,
  whether the set is proven complete; a figure of ``sigma_min`` per mode and a 3-D viewer of
  the modes;
- **singularity map**: a slice through the reference pose on the reference's working mode
  (:func:`~spatialmech.analysis.pose_slice.follow_grid` through
  :func:`~spatialmech.analysis.singularity.singularity_slice`; over the task coordinates for a
  lower-mobility mechanism), drawn by :func:`.singularity.slice_figure`;
- **workspace** under the model's own limits: the position workspace at the reference
  orientation of a six-freedom platform, the task workspace over the slice's coordinates of a
  lower-mobility one, with the volume and its error estimate.

The grids are small so that the report stays fast; their resolution is stated in the text
(:data:`SLICE_POINTS`, :data:`WORKSPACE_POINTS`).  Units: the model's length unit, degrees.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import cast

import numpy as np

from ..analysis.mobility import mobility_modes
from ..analysis.singularity import singularity_slice
from ..analysis.task_slice import task_singularity_slice
from ..analysis.workspace import position_workspace, task_workspace
from ..geometry.rotations import euler_matrix, matrix_euler
from ..kinematics.closure import Configuration
from ..kinematics.jacobian import complete_jacobian
from ..kinematics.dispatch import solve_forward, solve_inverse
from ..kinematics.position import configuration_at_pose, freedom_values
from ..kinematics.task import default_task, task_values
from ..kinematics.task_grid import TASK_NAMES
from ..model.mechanism import Mechanism, Pose
from ..results import Progress, Steps
from ..serialize import freedom_values_dict
from . import figures as F
from .numbers import ROUNDOFF, unit_label
from .report import Section, Table, Viewer

__all__ = ["PLATFORM_STEPS", "SLICE_POINTS", "WORKSPACE_POINTS", "applies", "platform_section"]

#: Progress steps of :func:`platform_section`.
PLATFORM_STEPS = 3
#: Grid of the singularity map: points along (u, v).
SLICE_POINTS = (13, 11)
#: Grid points per coordinate of the report's workspace.
WORKSPACE_POINTS = 9
#: Half-width of the singularity map's angle axis (rad).
SLICE_HALF_ANGLE = np.radians(60.0)
#: Half-width of the task workspace's angle axes (rad).
TASK_HALF_ANGLE = np.radians(40.0)


def applies(mech: Mechanism) -> bool:
    """True for a model whose actuators drive an output of two or more freedoms, one actuator
    per freedom (a parallel platform)."""
    if len(mech.actuators) < 2 or not getattr(mech, "limbs", None):
        return False
    mob = mobility_modes(mech)
    return len(mob) == 1 and mob[0].dof == len(mech.actuators)


def _euler_deg(R: np.ndarray) -> np.ndarray:
    return np.degrees(matrix_euler("ZYX", R))


def _modes(mech: Mechanism, ref: Configuration, data: dict) -> tuple[Table, F.ReportFigure, Viewer | None, str]:
    """The assembly modes at the reference actuator values (as ``fk --all``)."""
    ids = [r.id for r in mech.freedom_refs]
    fv = freedom_values(mech, ref.q)
    values = np.array([fv[ids.index(a)] for a in mech.actuators])
    ans = solve_forward(mech, values, all_solutions=True)
    modes = [m for m in ans.modes if m.assembly_mode]
    ref_p = np.asarray(mech.platform_point, dtype=float)
    near = (int(np.argmin([np.linalg.norm(m.pose.p - ref_p) + np.linalg.norm(m.pose.R - np.eye(3)) for m in modes]))
            if modes else -1)
    unit = unit_label(mech.length_unit)
    rows, js = [], []
    for k, m in enumerate(modes):
        cert = None if m.flags is None else m.flags.certified
        e = _euler_deg(m.pose.R)
        L = mech.characteristic_length
        rows.append((k + 1, *[_shown(x, L) for x in m.pose.p], *[_shown(x, 180.0) for x in e], float(m.sigma_min),
                     "yes" if cert else ("no" if cert is False else "-"), "yes" if m.within_limits else "no",
                     "reference" if k == near else ""))
        js.append({"mode": k + 1, "position_len": [float(x) for x in m.pose.p], "euler_sequence": "ZYX",
                   "euler_deg": [float(x) for x in e], "sigma_min": float(m.sigma_min), "certified": cert,
                   "within_limits": m.within_limits, "reference": k == near})
    others = len(ans.modes) - len(modes)
    data["assembly_modes"] = {"engine": str(ans.engine), "method": ans.label, "complete": ans.complete,
                              "completeness": ans.completeness, "n_modes": len(modes), "n_other_roots": others,
                              "actuators": {a: float(v) for a, v in zip(mech.actuators, values, strict=True)},
                              "modes": js}
    n_cert = sum(r[-3] == "yes" for r in rows)
    text = (f"{len(modes)} assembly modes at the reference actuator values by {ans.label} "
            f"({'proven complete' if ans.complete else 'not proven complete'}: {ans.completeness}); "
            f"{n_cert} of {len(modes)} certified" + (f"; {others} singular or self-motion roots not listed" if others else ""))
    table = Table("Assembly modes at the reference actuator values (fk --all)",
                  ("mode", f"x [{unit}]", f"y [{unit}]", f"z [{unit}]", "a1 [deg]", "a2 [deg]", "a3 [deg]",
                   "sigma_min (scale-free)", "certified", "within limits", ""), tuple(rows),
                  text + ". Orientation R = Rz(a1) Ry(a2) Rx(a3) (intrinsic ZYX); sigma_min of the complete "
                  "Jacobian's wrench bases, 0 at a singularity.")
    fig = F.new_figure((7.0, 3.4))
    ax = fig.add_subplot(1, 1, 1)
    sig = np.array([float(m.sigma_min) for m in modes])
    colours = ["#d62728" if k == near else "#4c72b0" for k in range(len(modes))]
    ax.bar(np.arange(1, len(modes) + 1), sig, color=colours)
    ax.set_xticks(np.arange(1, len(modes) + 1))
    ax.set_xlabel("assembly mode")
    ax.set_ylabel("scale-free sigma_min of J")
    ax.set_title("distance to a singularity of each assembly mode (red: the reference's)", fontsize=10)
    ax.grid(alpha=0.3, axis="y")
    fig_out = F.to_png(fig, "assembly_modes.png", f"{mech.name}: the assembly modes and their distance to a singularity",
                       text + ".")
    configs = []
    start = None
    for m in modes:
        fit = configuration_at_pose(mech, m.pose, start=start)
        if fit.converged:
            configs.append(fit.config)
    viewer = (Viewer(f"{mech.name}: the {len(configs)} assembly modes (one per frame)", mech, tuple(configs),
                     note="Frame k: assembly mode k of the table (not a motion between them).")
              if configs else None)
    return table, fig_out, viewer, text


def _serial(mech: Mechanism) -> bool:
    """One limb from the ground to the output link and no internal bodies: a serial arm, whose
    forward position is one pose and whose inverse solutions are the table to show."""
    return len(mech.limbs) == 1 and not mech.bodies and mech.limbs[0].tip is None


def _inverse_solutions(mech: Mechanism, data: dict) -> tuple[Table, str]:
    """Every inverse solution of a serial arm at its reference pose (as ``ik --all``), each
    with the scale-free sigma_min of its Jacobian and its certificate."""
    pose = _reference_pose(mech)
    res = solve_inverse(mech, pose, all_solutions=True).result
    limb, rep = res.limbs[0], res.search["limbs"][0]
    D = pose.displacement(mech.platform_point)
    refs = mech.freedom_refs
    lin = np.array([r.freedom.kind == "P" for r in refs])
    rows, js = [], []
    for k, q in enumerate(limb.solutions):
        q = np.asarray(q, dtype=float)
        sig = float(complete_jacobian(mech, Configuration(q, D)).sigma_min)
        cert = limb.certificates[k]["certified"] if limb.certificates else None
        values = freedom_values_dict(mech, {r.id: v for r, v in zip(refs, q, strict=True)}, "joints")
        shown = [values["joints_len" if r.freedom.kind == "P" else "joints_deg"][r.id] for r in refs]
        home = np.all(np.abs(np.where(lin, q, np.angle(np.exp(1j * q)))) < 1e-9)  # the reference configuration
        rows.append((k + 1, *[_shown(v, 180.0) for v in shown], sig, "yes" if cert else ("no" if cert is False else "-"),
                     "reference" if home else ""))
        js.append({**values, "sigma_min": sig, "certified": cert})
    data["inverse_solutions"] = {"method": rep["method"], "complete": rep["complete"],
                                 "completeness": rep["completeness"], "n_solutions": len(rows), "solutions": js}
    unit = unit_label(mech.length_unit)
    text = f"{len(rows)} inverse solutions of the arm at its reference pose by {rep['method']}: {rep['completeness']}"
    cols = tuple(f"{r.id} [{'deg' if r.freedom.kind != 'P' else unit}]" for r in refs)
    return Table("Inverse solutions at the reference pose (ik --all)", ("solution", *cols, "sigma_min (scale-free)",
                 "certified", ""), tuple(rows), text + "; sigma_min of the complete Jacobian, 0 at a singularity."), text


def _shown(x: float, scale: float) -> float:
    """``x`` for a table cell: round-off against ``scale`` shown as 0 (JSON keeps every digit)."""
    return 0.0 if abs(float(x)) <= ROUNDOFF * scale else float(x)


def _reference_pose(mech: Mechanism) -> Pose:
    return Pose(np.eye(3), np.asarray(mech.platform_point, dtype=float), "reference")


def _slice(mech: Mechanism, ref: Configuration, data: dict) -> tuple[F.ReportFigure, str, dict]:
    """The singularity map through the reference pose (over yaw and z for a six-freedom platform,
    over the first two given task coordinates otherwise)."""
    nu, nv = SLICE_POINTS
    L = mech.characteristic_length
    p0 = np.asarray(mech.platform_point, dtype=float)
    if len(mech.actuators) == 6:
        u = np.linspace(-SLICE_HALF_ANGLE, SLICE_HALF_ANGLE, nu)
        v = np.linspace(p0[2] - L / 4, p0[2] + L / 4, nv)

        def pose_of(a1: float, z: float) -> Pose:
            return Pose(euler_matrix("ZYX", [a1, 0.0, 0.0]), np.array([p0[0], p0[1], z]))

        res = singularity_slice(mech, pose_of, u, v, names=("a1", "z"), units=("rad", mech.length_unit),
                                start=(_reference_pose(mech), ref))
        what = (f"yaw a1 in +-{np.degrees(SLICE_HALF_ANGLE):.0f} deg ({nu} points) and z = {p0[2]:.4g} +- {L / 4:.3g} "
                f"{mech.length_unit} ({nv} points), x, y and the tilts held at the reference")
        shown = replace(res, u=np.degrees(res.u), units=("deg", unit_label(mech.length_unit)))
    else:
        task = default_task(mech)
        ref_vals = dict(zip(TASK_NAMES, task_values(mech, np.eye(4), task.euler), strict=True))
        order = sorted(task.given, key=lambda c: not c.startswith("a"))
        axes = {}
        for c, n in zip(order[:2], (nu, nv), strict=True):
            half = SLICE_HALF_ANGLE / 2 if c.startswith("a") else L / 4
            axes[c] = np.linspace(ref_vals[c] - half, ref_vals[c] + half, n)
        at = {c: ref_vals[c] for c in order[2:]}
        res = task_singularity_slice(mech, cast(Mapping[str, Sequence[float]], axes), at=at, task=task, seed=ref)
        shown = res.for_display()
        what = (", ".join(f"{c} in [{_show(c, a[0])}, {_show(c, a[-1])}] ({a.size} points)" for c, a in axes.items())
                + "; " + ", ".join(f"{c} = {_show(c, x)} held" for c, x in at.items())
                + f"; {', '.join(task.solved)} solved at every point")
    det = np.asarray(res.det, dtype=float)
    sig = np.asarray(res.sigma_min, dtype=float)
    ok = np.isfinite(det)
    changes = bool(np.nanmin(det) < 0 < np.nanmax(det)) if ok.any() else False
    numbers = {"grid": [nu, nv], "points_on_branch": int(ok.sum()), "points": int(det.size),
               "sigma_min_min": float(np.nanmin(sig[ok])) if ok.any() else None,
               "sigma_min_max": float(np.nanmax(sig[ok])) if ok.any() else None, "det_changes_sign": changes,
               "slice": what}
    data["singularity_map"] = numbers
    text = (f"Singularity map through the reference pose on its working mode: {what}. {int(ok.sum())} of {det.size} "
            f"points on the reference's branch; sigma_min from {numbers['sigma_min_min']:.3g} to "
            f"{numbers['sigma_min_max']:.3g}; det J " + ("changes sign: the black curve is a singularity locus."
                                                            if changes else "keeps its sign: no singularity on the slice."))
    from .singularity import slice_figure

    fig = slice_figure(shown, f"{mech.name}: singularity map through the reference pose")
    return F.to_png(fig, "singularity_map.png", f"{mech.name}: singularity map through the reference pose", text), text, numbers


def _show(c: str, x: float) -> str:
    return f"{np.degrees(x):.4g} deg" if c.startswith("a") else f"{x:.4g}"


#: Seconds between two progress lines of a long step (the workspace's poses checked).
PROGRESS_EVERY_S = 5.0


def _within_step(say: Steps, label: str) -> Progress:
    """A progress callback for the work inside the current step of ``say``: the same step
    number, the count in the message, at most one line every :data:`PROGRESS_EVERY_S`."""
    from time import perf_counter

    last = [perf_counter()]

    def cb(done, total, message) -> None:
        now = perf_counter()
        if now - last[0] >= PROGRESS_EVERY_S:
            last[0] = now
            count = f"{int(done)}/{int(total)}" if total else f"{int(done)}"
            say.progress(say.done, say.total, f"{label}: {message or 'working'} {count}")

    return cb


def _workspace(mech: Mechanism, data: dict, progress: Progress | None = None) -> tuple[F.ReportFigure, str]:
    """The workspace under the model's own limits (position at the reference orientation, or over
    the task coordinates), small grid, with its volume and error estimate."""
    n = WORKSPACE_POINTS
    L = mech.characteristic_length
    unit = unit_label(mech.length_unit)
    if len(mech.actuators) == 6:
        step = 4 * L / (n - 1)
        res = position_workspace(mech, at={"alpha": 0.0, "beta": 0.0, "gamma": 0.0}, step=step, polish=False,
                                 progress=progress)
        err = float(res.volume_error)
        limits = ", ".join(f"{k} {v}" for k, v in res.active_limits.items()) or "none"
        text = (f"Position workspace of the platform point at the reference orientation (alpha = beta = gamma = 0), "
                f"grid step {step:.3g} {unit} ({' x '.join(str(len(g)) for g in res.grid)} points) over the reference "
                f"point +- 2 characteristic lengths, boundary bisected to {max(res.tol.values()):.2g} {unit}: volume "
                f"{res.volume:.4g} +- {err:.2g} {unit}^3 (grid estimate |V_h - V_2h| + bisection tolerance); "
                f"boundary points by active limit: {limits}"
                + (" ('box': the model has no limit there, only the searched box bounds the set)."
                   if "box" in res.active_limits else "."))
        data["workspace"] = {"kind": "position", "volume_len3": float(res.volume), "volume_error_len3": err,
                             "grid": [len(g) for g in res.grid], "step_len": step,
                             "active_limits": res.active_limits, "n_poses_checked": res.n_poses}
        from .workspace import workspace_figure

        fig = workspace_figure(res)
    else:
        task = default_task(mech)
        ref_vals = dict(zip(TASK_NAMES, task_values(mech, np.eye(4), task.euler), strict=True))
        order = sorted(task.given, key=lambda c: not c.startswith("a"))
        over = {c: ((ref_vals[c] - TASK_HALF_ANGLE, ref_vals[c] + TASK_HALF_ANGLE, n) if c.startswith("a")
                    else (ref_vals[c] - L / 2, ref_vals[c] + L / 2, n)) for c in order[:2]}
        at = {c: ref_vals[c] for c in order[2:]}
        tres = task_workspace(mech, over, at=at, task=task, progress=progress)
        d = tres.to_dict()
        vkey = next((k for k in d if k.startswith("volume_") and k not in ("volume_note",)
                     and not k.startswith("volume_error")), None)
        vtext = ("no measure (the grid mixes lengths and angles)" if vkey is None else
                 f"measure {d[vkey]:.4g} +- {d[vkey.replace('volume_', 'volume_error_', 1)]:.2g} "
                 f"{'deg' if '_deg' in vkey else unit}^{len(tres.over)} (grid estimate |V_h - V_2h| + boundary tolerance)")
        limits = ", ".join(f"{k} {v}" for k, v in tres.active_limits.items()) or "none"
        text = ("Workspace over the task coordinates "
                + ", ".join(f"{c} in [{_show(c, lo)}, {_show(c, hi)}] ({k} points)" for c, (lo, hi, k) in over.items())
                + (", " + ", ".join(f"{c} = {_show(c, x)} held" for c, x in at.items()) if at else "")
                + f", {', '.join(tres.solved)} solved at every cell: {tres.n_feasible} of {tres.feasible.size} cells "
                f"reachable, {vtext}; boundary points by active limit: {limits}"
                + ("" if tres.limit_names else " (the model has no limits: only closure and the grid bound the set)")
                + ".")
        data["workspace"] = {"kind": "task", "over": list(tres.over), "grid": [n, n],
                             "volume": None if vkey is None else d[vkey], "volume_key": vkey,
                             "volume_error": None if vkey is None else d[vkey.replace("volume_", "volume_error_", 1)],
                             "n_feasible": tres.n_feasible, "active_limits": tres.active_limits}
        from .task_workspace import task_workspace_figure

        fig = task_workspace_figure(tres)
    return F.to_png(fig, "workspace.png", f"{mech.name}: workspace under the model's limits", text), text


def platform_section(mech: Mechanism, progress: Progress | None = None) -> Section | None:
    """Assembly modes, a singularity map and the workspace of a parallel platform (module
    docstring); ``None`` when :func:`applies` is False.  Each analysis that fails says why in
    the section's text instead of stopping the report."""
    if not applies(mech):
        return None
    say = Steps(progress, PLATFORM_STEPS)
    ref = Configuration.reference(mech)
    tables: list[Table] = []
    figs: list[F.ReportFigure] = []
    viewers: list[Viewer] = []
    notes: list[str] = []
    data: dict = {}
    if _serial(mech):
        say(f"{mech.name}: inverse solutions at the reference pose (ik --all)")
        try:
            tables.append(_inverse_solutions(mech, data)[0])
        except (ValueError, RuntimeError) as e:
            notes.append(f"inverse solutions: {e}")
    else:
        say(f"{mech.name}: assembly modes (fk --all)")
        try:
            table, fig, viewer, _ = _modes(mech, ref, data)
            tables.append(table)
            figs.append(fig)
            if viewer is not None:
                viewers.append(viewer)
        except (ValueError, RuntimeError) as e:
            notes.append(f"assembly modes: {e}")
    say(f"{mech.name}: singularity map through the reference pose")
    try:
        fig, _, _ = _slice(mech, ref, data)
        figs.append(fig)
    except (ValueError, RuntimeError) as e:
        notes.append(f"singularity map: {e}")
    say(f"{mech.name}: workspace")
    try:
        fig, _ = _workspace(mech, data, _within_step(say, f"{mech.name}: workspace"))
        figs.append(fig)
    except (ValueError, RuntimeError) as e:
        notes.append(f"workspace: {e}")
    intro = ("The platform's assembly modes, a singularity map through its reference pose and its workspace under "
             "the model's own limits. The grids are small to keep the report fast (their resolution is in each "
             "caption); run `spatialmech singularity` and `spatialmech workspace` for finer ones."
             + ("\n\n" + "\n\n".join(notes) if notes else ""))
    return Section(f"platform-{mech.name}", f"Platform {mech.name}: assembly modes, singularities, workspace", intro,
                   (), tuple(tables), tuple(figs), tuple(viewers), data=data, length_unit=mech.length_unit)
