"""The forces section of the per-model report (``spatialmech report MODEL``; issue 28): statics,
stiffness, accuracy and a performance map at the model's reference configuration, each with its
assumptions stated, where the model supports them.

Every analysis is the library's own (:mod:`spatialmech.analysis.statics`, ``.stiffness``,
``.accuracy``, ``.maps``); an analysis the model does not support (a singular reference
configuration, a complete Jacobian that is not 6 x 6 for the map) is listed as *not in this
report* with the reason, never silently left out.
"""

from __future__ import annotations

import numpy as np

from ..analysis import accuracy as acc
from ..analysis.dynamics import gravity_loads, mass_properties
from ..analysis.maps import closed_form_plan, performance_map
from ..analysis.statics import statics
from ..analysis.stiffness import stiffness
from ..errors import ConvergenceError, InputError
from ..kinematics.closure import Configuration
from ..model.mechanism import Mechanism
from . import figures as F
from .report import Section, Table

#: Density of the links when the model gives no masses (kg/m^3; aluminium), links as solid
#: cylinders (docs/dynamics.md).
REPORT_DENSITY_KG_M3 = 2700.0
#: Default tolerances of the accuracy section: actuator error (m or rad) and joint point (m) /
#: axis (rad, point / L) tolerances; no clearance.
REPORT_ACTUATOR_TOL = 1e-5
REPORT_POINT_TOL_M = 1e-5
#: Grid of the performance map: points per axis over x, y at the reference height.
MAP_POINTS = 21

__all__ = ["forces_section"]


def _statics_table(mech: Mechanism, c: Configuration, notes: list[str]) -> Table | None:
    unit = mech.length_unit
    F_unit = np.array([0.0, 0.0, -1.0, 0.0, 0.0, 0.0])
    s1 = statics(mech, c, F_unit)
    cols = ["actuator", "kind", "unit wrench: effort"]
    grav = None
    if unit == "m":
        masses, source = mass_properties(mech, None if mech.inertias or mech.density_kg_m3 else REPORT_DENSITY_KG_M3)
        loads = gravity_loads(mech, c, masses, (0.0, 0.0, -9.81))
        if loads:
            grav = statics(mech, c, np.zeros(6), loads=loads)
            cols.append("gravity: effort")
            given = sorted({v for v in source.values() if v != "none"})
            notes.append(f"Statics under gravity (0, 0, -9.81) m/s^2: link masses from {', '.join(given)}"
                         + (f" ({REPORT_DENSITY_KG_M3:g} kg/m^3, links as solid cylinders)" if "density" in given else "")
                         + f"; {'balanced' if grav.balanced else 'NOT balanced'}.")
    notes.append("Statics: a unit force of 1 N along -z on the output link (moment about the origin); efforts in N "
                 f"(slides) or N {unit} (rotations); massless, frictionless joints"
                 + ("; singular here: least squares" if s1.singular else "") + ".")
    rows = []
    for i, (a, k) in enumerate(zip(s1.actuators, s1.kinds, strict=True)):
        row = [a, k, float(s1.efforts[i])]
        if grav is not None:
            row.append(float(grav.efforts[i]))
        rows.append(tuple(row))
    return Table("Actuator efforts at the reference configuration", tuple(cols), tuple(rows),
                 note=f"N for a force, N {unit} for a torque")


def _stiffness_table(mech: Mechanism, c: Configuration, notes: list[str]) -> Table:
    k = stiffness(mech, c)
    unit = mech.length_unit
    notes.append("Stiffness: actuators as springs along their freedoms"
                 + (f" (unit stiffness for {', '.join(k.defaulted)}: the model gives none, so the values are per unit "
                    "actuator stiffness)" if k.defaulted else "")
                 + "; rigid links and constraints unless the model gives constraint stiffness; unloaded (no geometric "
                 f"term); principal stiffnesses about the platform point, nondimensional with L = {k.characteristic_length:g} "
                 f"{unit} (a rotation's torsional stiffness is k L^2 per rad).")
    rows = tuple((i + 1, "inf" if not np.isfinite(v) else float(v), int(m))
                 for i, (v, m) in enumerate(zip(k.principal_stiffness, k.multiplicity, strict=True)))
    return Table("Principal stiffnesses (softest first)", ("rank", f"k (N/{unit})", "multiplicity"), rows,
                 note="inf: a rigid direction" + ("; singular: softest 0" if k.singular else ""))


def _accuracy_table(mech: Mechanism, c: Configuration, notes: list[str]) -> Table:
    budget = acc.ErrorBudget(actuator=REPORT_ACTUATOR_TOL, point=REPORT_POINT_TOL_M)
    a = acc.accuracy_analysis(mech, c, budget, samples=0, breakdown=False)
    notes.append(f"Accuracy: actuator errors up to {REPORT_ACTUATOR_TOL:g} (m or rad), joint points up to "
                 f"{REPORT_POINT_TOL_M:g} m per component and single-axis joint axes up to {REPORT_POINT_TOL_M:g} m / L "
                 "rad; no clearance; first order (standard deviation of uniform errors) and worst case over the box, "
                 "with the exact model at the worst vertex; no Monte-Carlo and no mobility check here "
                 "(`spatialmech accuracy` does both).")
    rows = tuple((comp, float(a.std_first_order[i]), float(a.worst_case[i]),
                  None if not np.isfinite(a.exact_at_worst[i]) else float(a.exact_at_worst[i]))
                 for i, comp in enumerate(acc.COMPONENTS))
    return Table("Output error at the reference configuration", ("component", "first-order std", "worst case",
                                                                   "exact at worst vertex"), rows,
                 note="m for dx, dy, dz; rad for rx, ry, rz (rotation vector)")


def _map_figure(mech: Mechanism, c: Configuration, notes: list[str]):
    from .maps import maps_figure

    plan = closed_form_plan(mech)
    if isinstance(plan, str):
        raise InputError(f"no closed-form inverse position for the batched kernel ({plan}); the per-pose map is too "
                         "slow for the report: run `spatialmech maps`")
    p = c.D[:3, :3] @ mech.platform_point + c.D[:3, 3]
    L = mech.characteristic_length
    over = {"x": (p[0] - L, p[0] + L, MAP_POINTS), "y": (p[1] - L, p[1] + L, MAP_POINTS)}
    m = performance_map(mech, kind="position", over=over, at={"z": float(p[2])}, indices=["sigma_min", "condition"])
    notes.append(f"Performance map: {MAP_POINTS} x {MAP_POINTS} positions over +-L around the reference platform point, "
                 "at its height and orientation; the complete Jacobian's smallest singular value and condition number, "
                 f"nondimensional with L = {L:g} {mech.length_unit}; grey: outside the workspace or unassembled.")
    fig = maps_figure(m, ["sigma_min", "condition"])
    return F.to_png(fig, "forces-map.png", "Performance map", "sigma_min and condition number over a horizontal slice")


def forces_section(mech: Mechanism) -> Section:
    """The forces section of ``mech``'s report (module docstring)."""
    c = Configuration.reference(mech)
    notes: list[str] = []
    tables, figures, pending = [], [], []
    for what, build in (("statics", _statics_table), ("stiffness", _stiffness_table), ("accuracy", _accuracy_table)):
        try:
            t = build(mech, c, notes)
        except (InputError, ConvergenceError) as e:
            pending.append(f"{what}: {e}")
            continue
        if t is not None:
            tables.append(t)
    try:
        figures.append(_map_figure(mech, c, notes))
    except (InputError, ConvergenceError, ValueError) as e:
        pending.append(f"performance map: {e}")
    intro = ("Forces, stiffness, accuracy and a performance map at the reference configuration.\n\n" + "\n\n".join(notes))
    return Section(f"forces-{mech.name}", f"Forces and accuracy: {mech.name}", intro, (), tuple(tables), tuple(figures),
                   (), tuple(pending), length_unit=mech.length_unit)
