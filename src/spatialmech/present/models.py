"""Report sections about models rather than papers.

- :func:`section`: the mobility of every ready-made model (the demo's last section);
- :func:`model_section`: every analysis that applies to one model (``spatialmech report
  MODEL``): mobility of every mode, the complete Jacobian at the reference configuration,
  the DJ table at the model's task positions (one-degree-of-freedom models) or the Jacobian
  there, the motion traced by continuation (one degree of freedom) with DJ along it, and a
  3-D viewer (the traced motion, or a demonstration loop otherwise).

Units: the model's length unit; angles in degrees in tables and plots (labelled).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from .. import catalog
from ..analysis.mobility import mobility_modes
from ..analysis.defects import dj_function
from ..analysis.four_bar import four_bar_class
from ..kinematics.closure import Configuration
from ..kinematics.jacobian import CompleteJacobian, complete_jacobian
from ..kinematics.position import PoseFit, configuration_at_pose, freedom_values
from ..kinematics.tracking import trace_motion
from ..model.mechanism import Mechanism
from ..results import Progress, Steps
from . import figures as F
from .numbers import unit_label
from .report import Section, Table, Viewer

__all__ = ["MODEL_STEPS", "STEPS", "model_section", "section"]

#: Progress steps of :func:`section` and :func:`model_section`.
STEPS = 1
MODEL_STEPS = 5
#: Largest number of viewer frames (a traced motion is evenly subsampled).
VIEWER_FRAMES = 120
#: Step limit of the continuation trace of a one-degree-of-freedom model.
TRACE_MAX_STEPS = 4000

_MOB_COLS = ("model", "mode", "M", "instantaneous", "classic G-K", "motion", "lambda", "d", "n", "g", "sum f", "v", "xi")


def _mob_row(name, r):
    return (name, r.mode, r.dof, r.dof_instantaneous, r.gk_classic, r.motion, r.lam, r.d, r.n, r.g, r.sum_f, r.v, r.xi)


def section(progress: Progress | None = None) -> Section:
    """The mobility of every ready-made model (modified Kutzbach-Grübler, checked numerically)."""
    say = Steps(progress, STEPS)
    say("mobility of every ready-made model")
    rows, data = [], {}
    for name in catalog.names():
        res = mobility_modes(catalog.build(name))
        data[name] = [r.to_dict() for r in res]
        rows += [_mob_row(name, r) for r in res]
    return Section(
        "models", "Mobility of every ready-made model",
        "Modified Kutzbach-Grübler formula M = d(n - g - 1) + sum f + v - xi from the limbs' screw systems at the "
        "reference configuration; 'instantaneous' is the independent numerical check (rank of the loop-closure "
        "Jacobian at a generic configuration); 'classic G-K' the uncorrected count with d = 6.",
        tables=(Table("Mobility of every mode of every ready-made model", _MOB_COLS, tuple(rows)),),
        data={"mobility": data})


def _jacobian_row(label, J):
    return (label, ", ".join(J.actuators), J.det if J.det is not None else "not square", J.sigma_min, J.condition,
            ", ".join(J.inverse_singular) or "-")


def _dj_vector_monitor(mech: Mechanism, ref: Configuration, square: bool):
    """DJ of the first actuator as the tracker's vector monitor when J is not square (``None``
    when it is, or without actuators)."""
    if square or not mech.actuators:
        return None
    acts = list(mech.actuators[:1])
    return acts, dj_function(mech, acts, ref)[0]


def _four_bar_table(mech: Mechanism, data: dict) -> list[Table]:
    """The linkage class of a planar four-bar (no table for anything else); its JSON in ``data``."""
    fb = four_bar_class(mech)
    if fb is None:
        return []
    unit = unit_label(mech.length_unit)
    data["four_bar"] = fb.to_dict()
    lo, hi = fb.input_range_deg
    return [Table(
        "Linkage class (planar four-bar)",
        (f"ground [{unit}]", f"input [{unit}]", f"coupler [{unit}]", f"output [{unit}]", "type",
         "input range [deg]", "transmission angle range [deg]"),
        ((fb.ground, fb.input, fb.coupler, fb.output, fb.kind,
          "full turn" if (lo, hi) == (0.0, 360.0) else f"{lo:.2f} to {hi:.2f} (and its mirror)",
          f"{fb.transmission_range_deg[0]:.2f} to {fb.transmission_range_deg[1]:.2f}"),),
        "Input angle from the ground line (the input's base pivot towards the output's); the transmission "
        "angle is between coupler and output, 0 or 180 at a dead point (closed form, analysis/four_bar.py).")]


def model_section(mech: Mechanism, progress: Progress | None = None, *, trace: bool = True) -> Section:
    """Every analysis that applies to ``mech`` (see the module docstring)."""
    say = Steps(progress, MODEL_STEPS)
    from ..analysis.defects import dj_table
    from ..kinematics.motion import sample_motion

    tables, figs, viewers, notes = [], [], [], []
    data: dict[str, object] = {}  # JSON of each analysis, by name
    unit = unit_label(mech.length_unit)
    say(f"{mech.name}: mobility")
    mob = mobility_modes(mech)
    data["mobility"] = [r.to_dict() for r in mob]
    tables.append(Table("Mobility (modified Kutzbach-Grübler, checked numerically)", _MOB_COLS,
                        tuple(_mob_row(mech.name, r) for r in mob), "; ".join(dict.fromkeys(r.explanation for r in mob))))
    dof = mob[0].dof if len(mob) == 1 else None
    tables += _four_bar_table(mech, data)  # the linkage class of a planar four-bar

    say(f"{mech.name}: complete Jacobian at the reference configuration")
    ref = Configuration.reference(mech)
    jrows = []
    if mech.actuators:
        try:
            J0 = complete_jacobian(mech, ref)
            jrows.append(_jacobian_row("reference", J0))
            data["jacobian_reference"] = J0.to_dict()
        except ValueError as e:
            notes.append(f"complete Jacobian at the reference: {e}")
    else:
        notes.append("no actuated freedom: no complete Jacobian (mark freedoms 'actuated' in the model file)")

    say(f"{mech.name}: task positions")
    if mech.positions:
        if dof == 1:
            try:
                t = dj_table(mech)
                data["dj_table"] = t.to_dict()
                tables.append(Table("DJ at the task positions per base-joint driver (only signs along a row are comparable)",
                                    ("driver", *t.positions, "keeps sign"),
                                    tuple((d, *[float(x) for x in t.dj[i]], t.keeps_sign(d)) for i, d in enumerate(t.drivers))))
                fits: Sequence[PoseFit] = t.fits
            except ValueError as e:
                notes.append(str(e))
                fits = ()
        else:
            fitted: list[PoseFit] = []
            prev = None
            for P in mech.positions:
                fit = configuration_at_pose(mech, P, start=prev)
                fitted.append(fit)
                prev = fit.config if fit.converged else prev
                if fit.converged and mech.actuators:
                    try:
                        jrows.append(_jacobian_row(P.name, complete_jacobian(mech, fit.config)))
                    except ValueError as e:
                        notes.append(f"{P.name}: {e}")
            fits = fitted
        tables.append(Table("Task positions fitted onto the closure", ("position", "converged", "exact",
                            f"platform-point error [{unit}]", "orientation error [deg]"),
                            tuple((P.name, f.converged, f.exact, f.position_error, float(np.degrees(f.angle_error)))
                                  for P, f in zip(mech.positions, fits, strict=True))))
    if jrows:
        tables.insert(1, Table("Complete Jacobian (constraint + actuation wrenches; det only when square)",
                               ("configuration", "actuators", "det J", "sigma_min (scale-free)", "1/condition",
                                "inverse-singular actuators"), tuple(jrows)))

    say(f"{mech.name}: motion")
    configs: tuple[Configuration, ...] | None = None
    sing: tuple[object, ...] = ()  # the tracker's states at the zeros of DJ
    title = vnote = ""
    if dof == 1 and trace:
        square = False
        if mech.actuators:
            try:
                square = complete_jacobian(mech, ref).is_square
            except ValueError:
                square = False
        last: dict[str, CompleteJacobian | None] = {"J": None}

        def dj(c: Configuration) -> float:
            """DJ with the constraint bases kept continuous along the path (``reference``: the
            previous Jacobian); where a limb loses rank the matrix is not square: DJ = 0 there."""
            J = complete_jacobian(mech, c, reference=last["J"])
            if J.is_square:
                last["J"] = J
            return 0.0 if J.det is None else J.det

        mons: dict[str, Callable[[Configuration], float]] | None = {"DJ": dj} if square else None
        # a linkage with common constraints (a planar 4-bar) has no square J: DJ of the first
        # actuator from the closure Jacobian's cofactor (as `view` and the studio), so that its
        # dead points are counted, not reported as "0 zeros"
        vmon = _dj_vector_monitor(mech, ref, square)
        tr = trace_motion(mech, ref, increasing=mech.actuators[0] if mech.actuators else None, monitors=mons,
                          vector_monitor=vmon, max_arc=200, max_steps=TRACE_MAX_STEPS)
        q = np.array([freedom_values(mech, c.q) for c in tr.points])
        ids = [r.id for r in mech.freedom_refs]
        show = [i for i, r in enumerate(mech.freedom_refs) if r.id in mech.actuators] or list(range(min(3, len(ids))))
        fig = F.new_figure((10.0, 3.8))
        ax = fig.add_subplot(1, 2, 1)
        ys = {ids[i] + (" [deg]" if mech.freedom_refs[i].freedom.kind != "P" else f" [{unit}]"):
              (np.degrees(q[:, i]) if mech.freedom_refs[i].freedom.kind != "P" else q[:, i]) for i in show}
        F.curves(ax, tr.s, ys, xlabel="arc length (nondimensional)", ylabel=next(iter(ys)) if len(ys) == 1 else "joint value",
                 title=f"traced motion ({tr.message})")
        ax2 = fig.add_subplot(1, 2, 2)
        if mech.actuators:
            sig = np.array([complete_jacobian(mech, c).sigma_min for c in tr.points])
            F.curves(ax2, tr.s, {"sigma_min": sig}, xlabel="arc length (nondimensional)",
                     ylabel="scale-free sigma_min of J", title="distance to singularity", logy=bool(np.all(sig > 0)))
            data["trace_sigma_min"] = {"min": float(sig.min()), "max": float(sig.max())}
        kinds = [{"driver": e.name, "arc": float(e.s), "kind": e.kind} for e in tr.events]
        for ev in tr.events:
            ax.axvline(float(ev.s), color="#b3261e" if ev.kind == "zero" else "#555555", linestyle="--", linewidth=0.8)
        nz = sum(k["kind"] == "zero" for k in kinds)
        figs.append(F.to_png(fig, "motion.png", f"{mech.name}: the one-degree-of-freedom motion traced by continuation",
                             f"Pseudo-arclength continuation from the reference configuration until the motion closes "
                             f"({tr.message}); dashed lines: sign changes of DJ of {', '.join(mech.actuators) or '-'}, "
                             f"red: {nz} zeros (singular configurations), grey: {len(kinds) - nz} poles (DJ through "
                             "infinity: the platform at rest while the driver moves)."))
        data["trace"] = {"status": tr.status, "closed": tr.closed, "n_points": len(tr.points), "arc_length": float(tr.s[-1]),
                         "events": kinds, "ok": tr.ok}
        idx = np.unique(np.linspace(0, len(tr.points) - 1, min(VIEWER_FRAMES, len(tr.points))).round().astype(int))
        configs = tuple(tr.points[i] for i in idx)
        sing = tuple(e.x for e, k in zip(tr.events, kinds, strict=True) if k["kind"] == "zero")
        title = f"{mech.name}: the traced motion ({len(idx)} of {len(tr.points)} configurations)"
        vnote = f"Continuation trace, status {tr.message}; red x: the zeros of DJ (singular configurations)."
    if configs is None:
        try:
            configs = tuple(sample_motion(mech, n=48))
            title = f"{mech.name}: a demonstration loop from the reference configuration"
            vnote = "A short loop along the closure manifold (not a tracked motion)."
        except (ValueError, RuntimeError) as e:
            notes.append(f"viewer: {e}")
            configs = (ref,)
            title = f"{mech.name}: the reference configuration"
    viewers.append(Viewer(title, mech, configs, task_positions=mech.positions, singular_points=sing, note=vnote))
    intro = (f"{mech.description or mech.name}. Lengths in {unit}; angles in degrees in tables and plots."
             + ("\n\n" + "\n\n".join(notes) if notes else ""))
    return Section(f"model-{mech.name}", f"Model {mech.name}", intro, (), tuple(tables), tuple(figs), tuple(viewers),
                   data=data, length_unit=mech.length_unit)
