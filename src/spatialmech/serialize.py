"""JSON output of results: one envelope, one unit rule (docs/json.md), NumPy to plain values.

Every JSON document spatialmech writes for a command (``--json``) is an object

    {"schema_version": "2", "command": "fk", "model": "four-sps-cu", "length_unit": "m", ...}

built by :func:`envelope` around a result's ``to_dict()``.  The unit rule: a number's unit is
named by the nearest enclosing key that ends with a unit suffix (:data:`UNIT_SUFFIXES`: ``_deg``
degrees, ``_len`` the document's top-level ``length_unit``, ...), or that key is one of the
documented unit-free quantities (:data:`UNIT_FREE_KEYS`: counts, indices, nondimensional
numbers) or screws (:data:`SCREW_KEYS`: ``(direction ; moment)`` 6-vectors, the moment in
``length_unit``).  Angles are degrees in JSON, radians only inside the Python API.
:func:`unit_rule_violations` checks a document mechanically.

    >>> import numpy as np
    >>> d = envelope("fk", "demo", {"pose": pose_dict(np.eye(3), [0, 0, 0.1])}, length_unit="m")
    >>> d["schema_version"], d["pose"]["euler_sequence"], d["pose"]["position_len"]
    ('2', 'ZYX', [0.0, 0.0, 0.1])
    >>> unit_rule_violations(d)
    []
    >>> for problem in unit_rule_violations({"solutions": [{"angle": 0.5, "point": [1, 2, 3]}]}):
    ...     print(problem)
    solutions[].angle: an angle without the '_deg' suffix
    solutions[].angle: a number under a key with no unit suffix (or a documented unit-free key)
    solutions[].point: a number under a key with no unit suffix (or a documented unit-free key)
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable, Mapping
from typing import Any

import numpy as np

__all__ = [
    "EMBEDDED_KEYS",
    "HTML_MAX_ROWS",
    "JSON_EULER_SEQUENCE",
    "SCHEMA_VERSION",
    "SCREW_KEYS",
    "UNIT_FREE_KEYS",
    "UNIT_FREE_MAPS",
    "UNIT_SUFFIXES",
    "envelope",
    "fields_dict",
    "freedom_values_dict",
    "html_cell",
    "html_summary",
    "json_default",
    "json_value",
    "pose_dict",
    "unit_rule_violations",
]

#: Version of the JSON layout (the envelope, the unit rule and every command's fields).
SCHEMA_VERSION = "2"

#: The Euler sequence of every pose in JSON (intrinsic Z, then Y, then X: R = Rz(a1) Ry(a2) Rx(a3)).
JSON_EULER_SEQUENCE = "ZYX"

#: Unit suffixes of JSON keys: the key's numbers (and every number nested under it) are in this unit.
UNIT_SUFFIXES: dict[str, str] = {
    "_deg": "degrees",
    "_deg2": "square degrees (area in two Euler-angle coordinates)",
    "_deg3": "cubic degrees (volume in Euler-angle coordinates)",
    "_len": "the document's length_unit",
    "_len2": "square of the document's length_unit",
    "_len3": "cube of the document's length_unit",
    "_len_per_s": "length_unit per second",
    "_len_per_s2": "length_unit per second squared",
    "_len_per_deg": "length_unit per degree (a screw pitch)",
    "_s": "seconds",
    "_per_s": "per second (a rate)",
    "seconds": "seconds (the key is the unit)",
    "_N": "newtons (the force unit of a given wrench: statics is linear in it)",
    "_N_len": "newtons times the document's length_unit (a torque, or a moment)",
    "_N_per_len": "newtons per length_unit (a linear stiffness)",
    "_len_per_N": "length_unit per newton (a linear compliance)",
    "_per_N": "per newton (a coupling compliance: length_unit per N length_unit, or rad per N)",
    "_per_N_len": "per newton length_unit (a rotational compliance: rad per N length_unit)",
    "_deg_per_s": "degrees per second (an angular rate)",
    "_deg_per_s2": "degrees per second squared (an angular acceleration)",
    "_kg": "kilograms",
    "_kg_len2": "kilograms times the square of the document's length_unit (an inertia; the metre for dynamics)",
    "_kg_per_len3": "kilograms per cube of the document's length_unit (a density)",
}

#: Keys whose numbers have no unit, with their meaning: counts, indices, signs, nondimensional
#: quantities.  (docs/json.md lists them; tests/test_json_schema.py checks the two agree.)
UNIT_FREE_KEYS: dict[str, str] = {
    # counts and sizes
    "active_limits": "refined boundary points bounded by each limit",
    "bytes": "size of the written file, in bytes",
    "claims": "number of claims (report summary)",
    "constraint_rank": "rank of the limbs' constraint wrenches",
    "constraint_rank_generic": "that rank at a generic configuration",
    "constraint_rows": "number of constraint rows of the complete Jacobian",
    "crossings_stepped_over": "singular points stepped over while tracing a self-motion",
    "d": "order of the screw system (mobility formula)",
    "defects": "defect count or bit mask of a spherical four-bar (synth rccc)",
    "dof": "degrees of freedom",
    "idle_motions": "number of idle motions (every actuator still: an SPS leg's spin) of inverse dynamics",
    "max_residual": "largest relative residual of the virtual-power balance over the samples (dynamics)",
    "dof_instantaneous": "instantaneous degrees of freedom (rank of the closure Jacobian)",
    "dof_at_reference": "instantaneous degrees of freedom at the reference configuration itself (mobility)",
    "loss_rate": "accuracy: the singular value that removes a freedom, per unit tolerance scale (scale-free)",
    "local_dof": "largest dimension of the branches through the reference (mobility; null: undecided)",
    "dimension": "dimension of a branch of closed configurations (its degrees of freedom)",
    "expected_rank": "rank of a non-singular wrench system",
    "failed": "Monte-Carlo samples whose analysis failed",
    "frames": "number of configurations (animation frames)",
    "g": "number of joints (mobility formula)",
    "gk_classic": "classic Grübler-Kutzbach count",
    "hits": "starts that reached each solution",
    "inconsistent": "number of claims whose own consistency check failed (report summary)",
    "inverse_singular_points": "poles of DJ on a traced circuit",
    "iterations": "solver iterations",
    "k": "k of the mobility formula (docs/mobility.md)",
    "lambda": "common constraints (mobility formula)",
    "limb_constraints": "constraint wrenches per limb",
    "max_iter": "iteration limit",
    "members": "converged starts that one result stands for",
    "n": "number of links (mobility formula)",
    "links": "number of links (mobility; = n)",
    "grid_points": "points per grid axis (parasitic)",
    "cells": "number of grid cells (parasitic)",
    "loops": "number of independent loops of the link graph (mobility)",
    "n_branches": "number of branches",
    "n_converged": "number of converged starts",
    "n_distinct": "number of distinct solutions",
    "n_grid": "grid points sampled",
    "n_grid_converged": "grid points where the task coordinates close (the parasitic ones solved)",
    "n_grid_feasible": "feasible grid points",
    "n_new_branches": "starts that found a new branch",
    "n_points": "number of points",
    "n_poses_checked": "poses checked",
    "n_seeds": "number of starts",
    "n_input_independent": "forward solutions that hold for every actuator value (input-independent: not assembly modes)",
    "n_solutions": "number of solutions found",
    "n_tried": "number of starts tried",
    "n_within_limits": "solutions within the limits",
    "not reproduced": "claims not reproduced (report summary)",
    "passive": "passive freedoms per limb",
    "passive_dim": "dimension of a limb's solution set",
    "rank": "rank of a screw system",
    "n_regular": "regular assembly modes found",
    "reproduced": "claims reproduced (report summary)",
    "reproduced after correction": "claims reproduced after a correction (report summary)",
    "same_verdict": "Monte-Carlo samples with the same verdict",
    "samples": "number of samples",
    "seed": "seed of a random or quasi-random sequence",
    "n_self_motion_sets": "self-motion sets found",
    "n_singular": "isolated singular roots found; homotopy: singular end points",
    "n_complex": "homotopy end points with a non-real solution",
    "n_real": "homotopy end points that are real (before grouping into assembly modes)",
    "n_at_infinity": "homotopy end points at infinity (the platform escapes: e.e = 0 in Study parameters)",
    "n_singular_roots": "isolated singular real roots found (homotopy search)",
    "n_generic": "isolated solutions of the generic instance (homotopy paths tracked)",
    "n_paths": "paths of the total-degree homotopy (loop formulation: of the final parameter homotopy)",
    "n_spurious": "end points of the squared-up loop system that do not satisfy the full closure (discarded)",
    "n_lost": "paths of a limb's homotopy that failed before the pose (after the re-tracks through a waypoint)",
    "monodromy_loops": "monodromy loops run before the solution set stopped growing",
    "trace_deviation": "relative deviation of the trace test's traces from a line (a ratio)",
    "n_witness": "witness points of the trace test's curve (a count)",
    "variables_real": "real part of a loop-formulation end point: (cos, sin) of each passive rotation, slides / L, "
                      "Study parameters when the platform is not fixed by a limb",
    "variables_imag": "imaginary part of the same variables",
    "study_parameters_real": "real part of the Study parameters (e0..e3, g0..g3; g scaled by 1/L), projective",
    "study_parameters_imag": "imaginary part of the Study parameters, same scaling",
    "inverse_condition": "inverse condition number of the row-normalised Jacobian at a homotopy end point",
    "infinity_ratio": "|e.e| / |x|^2 at a homotopy end point (0 at infinity)",
    "imaginary_ratio": "|Im x| / |x| at a homotopy end point after removing the projective phase",
    "multiplicity": "how many homotopy paths end at this point, or principal screws share a pitch (a count)",
    "winding_number": "loops of the Cauchy end game about t = 1 before the path closed (a count)",
    "n_certified": "solutions certified by a Krawczyk test in ball arithmetic (null: not attempted)",
    "n_certified_complex": "complex homotopy end points certified (distinct non-real roots)",
    "box_radius": "half-width of a certified box in the system's nondimensional unknowns",
    "duplicate_of": "index of the point whose certified box holds the same root",
    "singular_points": "singular points marked in a viewer",
    "starts_per_limb": "starts of the inverse-position search per limb",
    "sum_f": "sum of the joint freedoms (mobility formula)",
    "t": "t of the mobility formula; a curve parameter in synthesis data",
    "task_positions": "task positions shown in a viewer",
    "traced_samples": "points of a traced curve",
    "v": "v = t - k of the mobility formula; a unit direction in synthesis data (paper D)",
    "xi": "passive freedoms (mobility formula)",
    # indices and signs
    "also_within_tolerance_of": "other circuits passing within tolerance of a position (numbers)",
    "between": "the two task positions (numbered from 1) a point lies between",
    "branch_point_arcs": "arcs (nondimensional) of the DJ zeros, by name",
    "sign_changes_after": "positions (from 0) after which DJ changes sign, by driver",
    "circuit": "circuit number (from 1)",
    "circuits": "task positions (numbered from 1) on each circuit",
    "constraint_limbs": "limb index of each constraint row",
    "indices": "line indices (input order)",
    "lines": "line indices (input order)",
    "min_closure_sigma_between": "the two task positions bracketing the closest approach to a singularity",
    "order": "task positions in the order they are met",
    "path_direction": "+1: the path runs along the traced direction, -1: against it",
    "position_number": "task position number (from 1)",
    "sign": "sign of det J (+1, -1, 0)",
    "sign_changes_along_u": "sign changes of det J along the first slice axis",
    "signs": "signs of DJ (+1, -1, 0)",
    "switch_between": "the two task positions bracketing a driver switch",
    # nondimensional quantities
    "arc": "arc length along a traced curve, nondimensional (joint rad, lengths / characteristic length)",
    "arc_length": "arc length of a traced curve, nondimensional",
    "center_cubic": "coefficients of the center-point cubic (unit vectors)",
    "center_direction": "unit direction of a center-point pole (paper D)",
    "center_points": "center-point unit vectors (Burmester curves)",
    "circle_cubic": "coefficients of the circle-point cubic (unit vectors)",
    "circle_direction": "unit direction of a circle-point pole (paper D)",
    "circle_points": "circle-point unit vectors (Burmester curves)",
    "condition": "inverse condition number sigma_min / sigma_max, in [0, 1]",
    "corrected_rank": "rank of the wrench system as corrected (paper B case (c))",
    "engine_sigma_min_home": "scale-free sigma_min of the general engine at the home pose",
    "eq22_max_fd_error": "largest error of eq 22's Jacobian against finite differences (rad per rad)",
    "forward_acceleration_error": "largest error of the recovered phi'' (a round-off check; z in length/s^2, angles in rad/s^2)",
    "forward_velocity_error": "largest error of the recovered phi' (a round-off check; z in length/s, angles in rad/s)",
    "fraction_det_negative": "fraction of sampled poses with det J < 0",
    "max_det_poles": "largest |det| of the Burmester equations at the poles (unit vectors)",
    "max_det_samples": "largest |det| of the Burmester equations at the traced samples (unit vectors)",
    "max_direction_residual": "largest residual of the direction equations (unit vectors)",
    "max_fd_error": "largest error against finite differences (rad per rad)",
    "max_sigma_min_on_singular_set": "largest scale-free sigma_min on the singular set alpha = beta = 0",
    "min_sigma_min_sample": "smallest scale-free sigma_min over the sampled poses",
    "residuals": "residuals of the direction equations (unit vectors), by name",
    "worded_rank": "rank of the wrench system as the paper words it (paper B case (c))",
    "curve_parameter": "parameter along a Burmester curve",
    "dP1_dh": "rate of a solution-line point per unit of h",
    "dP2_dh": "rate of a solution-line point per unit of h",
    "dedup_tol": "distance (nondimensional) below which two solutions are one",
    "det": "determinant of the complete Jacobian as printed (only its sign is comparable)",
    "direction": "unit direction vector",
    "dj": "DJ = det of the complete Jacobian (only signs along one driver are comparable)",
    "extent": "size of the search box, in task scales",
    "fraction_same": "fraction of Monte-Carlo samples with the same verdict",
    "reachable_fraction": "fraction of the grid cells that are reachable (close within every limit)",
    "from": "arc (nondimensional) where a plan step starts; lower end of a tolerance range",
    "ik_residual": "nondimensional closure residual of a pose fit",
    "ik_residuals": "nondimensional closure residuals of pose fits",
    "io_matrix": ("input-output Jacobian over the given task coordinates (rows: actuators, columns: given "
                  "coordinates), nondimensional: lengths / characteristic length, angles in rad"),
    "min_closure_sigma_on_path": "scale-free closeness of the path to a singularity of the linkage",
    "min_sigma_on_path": "scale-free closeness of the path to a singularity of a driver",
    "normal": "unit normal of a plane",
    "on_curve": "nondimensional on-curve tolerance",
    "path_length": "arc length of the path from the first to the last position, nondimensional",
    "plane_normal": "unit normal of a planar linkage's plane (the studio's top view)",
    "platform_frame": "columns: the platform's x, y, z unit vectors",
    "pose_error": "nondimensional pose error (rad, and length / characteristic length)",
    "position_arcs": "arc of each task position along the first circuit, nondimensional",
    "residual": "nondimensional residual (lengths divided by the characteristic length, angles in rad)",
    "rotation_matrix": "a 3x3 rotation matrix (rows)",
    "sigma_min": "scale-free smallest singular value (0 at a singularity)",
    "singular_below": "sigma_min below which a configuration is reported singular",
    "slide_beta": "rate of the slides per unit of h",
    "switch_window": "arc interval (nondimensional) in which to switch drivers",
    "to": "arc (nondimensional) where a plan step ends; upper end of a tolerance range",
    "tol": "nondimensional tolerance",
    "tolerance": "nondimensional tolerance",
    "trace_sigma_min": "smallest and largest sigma_min along a traced motion",
    "transmission": "transmission index per actuator, in [0, 1]",
    "u": "unit direction of a C joint axis (paper A) or moving axis (paper D)",
    "traced_arc": "arc length of a traced self-motion, nondimensional",
    # table cells (their units are in the column titles)
    "rows": "table cells; the table's columns name their units",
    "dj_by_driver": "DJ of each candidate single driver at the studio's configuration, by name",
    "hull_faces": "triangles of a convex hull, as index triples into its vertices (studio scene)",
    "triangles": "triangles of a mesh, as index triples into its vertices_len (studio scene: joint solids, platform)",
    "joint_axes": "unit directions of a joint's axes (studio scene)",
    "limb_index": "index of a limb (from 0)",
    "mode_number": "assembly mode number (from 1)",
    "near_singular_below": "sigma_min below which the studio warns of a nearby singularity",
    "dj_rate": "a single driver's share of its linkage's motion: absolute rate along the unit tangent (0: no control)",
    "transmission_min": "the smallest transmission index of the actuators, in [0, 1] (studio inverse light)",
    "inverse_singular_below": "transmission index below which the studio calls a limb inversely singular",
    "near_inverse_singular_below": "transmission index below which the studio warns of a nearby inverse singularity",
    "branch": "per slice grid point: 0 on the given pose's branch, 1 on another branch, -1 not solved",
    "n_branch_switched": "slice grid points on another branch than the given pose's (masked)",
    "n_unreached": "slice grid points where no closed configuration was found on the branch",
    "port": "TCP port number",
    "tracker_steps": "accepted continuation steps",
    # defect screening (screen)
    "candidates": "candidate linkages formed (screen)",
    "judged": "candidates with a verdict in the dataset (screen)",
    "judged_this_run": "candidates judged by this run (screen)",
    "chunks": "chunks (Parquet files) of the screen",
    "chunks_resumed": "chunks already written by an earlier run (screen)",
    "rejected_by_stage": "candidates rejected by each stage of the screen, by stage",
    "usable": "usable candidates found (screen)",
    "workers": "Dask workers used (0: serial)",
    "candidate": "candidate number (from 0) in a screen",
    "dyads": "indices (from 0) of a candidate's dyads in the screen's pool; in pool: how many were sampled",
    "place": "place in the ranking (from 1)",
    "density": "dyads sampled per unit nondimensional arc length of the family",
    "separation": "smallest nondimensional distance between two limbs of a candidate",
    "min_closure_sigma_at_positions": "smallest scale-free closure sigma over the task positions",
    # performance maps (docs/maps.md)
    "manipulability": "sqrt det(G^T G) of the nondimensional forward velocity Jacobian (maps)",
    "iti": "input transmission index, in [0, 1] (maps)",
    "oti": "output transmission index, in [0, 1] (maps)",
    "lti": "local transmission index min(ITI, OTI), in [0, 1] (maps)",
    "lci": "local constraint index, in [0, 1] (maps)",
    "velocity_axes": "semi-axes of the nondimensional velocity ellipsoid (maps)",
    "force_axes": "semi-axes of the nondimensional force ellipsoid (maps)",
    "status_counts": "grid cells of each status (maps)",
    # stiffness (docs/stiffness.md)
    "rigid_rank": "independent rigid constraint wrenches (stiffness)",
    "repeated": "how many principal stiffnesses equal this one (stiffness)",
}

#: Unit-free keys that hold a map by name (actuator, limit, monomial) of unit-free numbers; any
#: other object under a unit-free key names the units of its own fields.
UNIT_FREE_MAPS: frozenset[str] = frozenset({"active_limits", "branch_point_arcs", "center_cubic", "circle_cubic",
                                            "residuals", "rejected_by_stage", "sign_changes_after", "dj_by_driver",
                                            "signs", "trace_sigma_min", "transmission",
                                            "status_counts"})

#: Keys holding screws: ``(direction ; moment)`` 6-vectors (or matrices of them) whose direction
#: part is unit-free and whose moment part is in ``length_unit`` (the Jacobian ``matrix`` rows
#: are the wrenches swapped, ``(moment ; direction)``, acting on twists ``(omega ; v)``).
SCREW_KEYS: dict[str, str] = {
    "axis": "a joint or cone axis as a unit direction (3), or a Plücker line (6)",
    "common_line": "a Plücker line",
    "constraint_wrenches": "constraint wrenches of the platform",
    "directrices": "Plücker lines",
    "line": "a Plücker line",
    "matrix": "rows of the complete Jacobian, (moment ; direction)",
    "transversals": "Plücker lines",
    "twist": "uncontrolled platform twists (omega ; v); stiffness: a principal displacement (dtheta ; dp)",
    "softest_twist": "the softest displacement (dtheta ; dp) of each grid cell (stiffness --over)",
    "unbalanced_wrench": "the wrench direction (f ; m) a singular configuration cannot balance (statics)",
    "wrenches": "wrenches of the complete Jacobian, (direction ; moment)",
}

#: Keys holding a whole document of another format, whose units that format defines (a model in
#: the TOML file format of docs/file-format.md); the unit rule does not look inside them.
EMBEDDED_KEYS: frozenset[str] = frozenset({"linkage"})


def json_default(o):
    """``json.dumps(..., default=json_default)``: NumPy arrays and scalars to Python values."""
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    if hasattr(o, "value") and isinstance(getattr(o, "value", None), str):  # a str enum member
        return o.value
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def envelope(command: str, model: str | None, payload: Mapping, *, length_unit: str | None = None) -> dict:
    """The JSON document of one command: ``schema_version``, ``command``, ``model`` (``None``
    where no model applies), ``length_unit`` (the unit of every ``*_len`` field; ``None`` when
    the document has none), then the payload's fields (a payload may not redefine these four)."""
    if not isinstance(command, str) or not command:
        raise TypeError(f"command: expected a command name, got {command!r}")
    if model is not None and not isinstance(model, str):
        raise TypeError(f"model: expected a model name or None, got {type(model).__name__}")
    if length_unit is not None and not isinstance(length_unit, str):
        raise TypeError(f"length_unit: expected a unit name or None, got {type(length_unit).__name__}")
    head = {"schema_version": SCHEMA_VERSION, "command": command, "model": model, "length_unit": length_unit}
    clash = sorted(set(head) & set(payload))
    if clash:
        raise ValueError(f"payload: must not define the envelope's keys {clash}")
    return {**head, **payload}


def _clean(v: float) -> float:
    """A float without round-off noise below 1e-12 of 1 and without negative zero."""
    v = float(v)
    return 0.0 if abs(v) < 1e-15 else v + 0.0


def pose_dict(R, p, *, sequence: str = JSON_EULER_SEQUENCE) -> dict:
    """A pose in JSON: ``position_len`` (the platform point), ``euler_sequence``, ``euler_deg``
    (angles of that named sequence, degrees) and the ``rotation_matrix`` itself."""
    from .geometry.rotations import matrix_euler

    R = np.asarray(R, dtype=float)
    return {
        "position_len": [_clean(x) for x in np.asarray(p, dtype=float)],
        "euler_sequence": sequence,
        "euler_deg": [_clean(x) for x in matrix_euler(sequence, R, degrees=True)],
        "rotation_matrix": [[_clean(x) for x in row] for row in R],
    }


def freedom_values_dict(mech, values: Mapping[str, float], prefix: str) -> dict:
    """Values of freedoms (SI inside: rad or length) as two JSON maps by freedom id:
    ``{prefix}_deg`` (rotations, degrees) and ``{prefix}_len`` (slides, length unit)."""
    deg: dict[str, float] = {}
    ln: dict[str, float] = {}
    for fid, v in values.items():
        if mech.freedom(fid).freedom.kind == "P":
            ln[fid] = float(v)
        else:
            deg[fid] = float(np.degrees(v))
    return {f"{prefix}_deg": deg, f"{prefix}_len": ln}


#: Keys naming an angle: they must carry a degree suffix wherever they hold numbers.
_ANGLE_WORD = re.compile(r"(^|_)(angle|angles|alpha|beta|gamma|theta|phi|psi|euler|rotation|rotated|twist_angle)(_|$)")


def json_value(v: Any, *, degrees: bool = False) -> Any:
    """``v`` as plain JSON values: NumPy arrays and tuples to lists, NumPy scalars to Python ones,
    mappings' values and lists' items converted in turn, results to their ``to_dict()``;
    ``degrees``: numbers (radians) to degrees.  Strings (str enums too), bools, ``None`` as they are."""
    if v is None or isinstance(v, (str, bool, np.bool_)):
        return v.item() if isinstance(v, np.bool_) else v
    if isinstance(v, np.ndarray):
        return (np.degrees(v) if degrees else v).tolist()
    if isinstance(v, (np.floating, np.integer)):
        return float(np.degrees(v)) if degrees else v.item()
    if isinstance(v, (int, float)):
        return float(np.degrees(v)) if degrees else v
    if isinstance(v, Mapping):
        return {k: json_value(w, degrees=degrees) for k, w in v.items()}
    if isinstance(v, (list, tuple)):
        return [json_value(w, degrees=degrees) for w in v]
    if callable(getattr(v, "to_dict", None)):
        return v.to_dict()
    raise TypeError(f"not JSON serialisable: {type(v).__name__}")


def _converts_to_degrees(name: str, key: str) -> bool:
    return key.endswith("_deg") and not name.endswith("_deg")


def fields_dict(obj, keys: Mapping[str, str] | None = None, *, names: Iterable[str] | None = None) -> dict:
    """The JSON payload of a dataclass result, derived from its fields (docs/json.md).

    ``names``: the attributes to write, in order (default: every dataclass field, in declaration
    order; a property may be named too).  ``keys``: the one table of renames and units, attribute
    -> JSON key, for the attributes whose key is not their own name.  The key's unit suffix is the
    unit rule: a key that ends with ``_deg`` for an attribute that does not holds radians
    converted to degrees; the other suffixes (``_len``, ``_s`` ...) only name the unit the value
    is already in (the model's length unit, seconds).  Values go through :func:`json_value`.

        >>> from dataclasses import dataclass
        >>> @dataclass
        ... class Fit:
        ...     converged: bool
        ...     position_error: float
        ...     angle_error: float
        >>> fields_dict(Fit(True, 0.25, np.pi / 2), {"position_error": "position_error_len",
        ...                                          "angle_error": "angle_error_deg"})
        {'converged': True, 'position_error_len': 0.25, 'angle_error_deg': 90.0}
    """
    keys = keys or {}
    if names is None:
        names = [f.name for f in dataclasses.fields(obj)]
    out = {}
    for name in names:
        key = keys.get(name, name)
        out[key] = json_value(getattr(obj, name), degrees=_converts_to_degrees(name, key))
    return out


def _unit_of(key: str) -> str | None:
    if key in UNIT_FREE_KEYS or key in SCREW_KEYS:
        return "unit-free"
    for suffix in sorted(UNIT_SUFFIXES, key=len, reverse=True):
        if key.endswith(suffix):
            return "suffix"
    return None


def _field(path: str) -> str:
    """``"a[3].b[0][1]"`` -> ``"a[].b"``: a field's path, without list positions."""
    return re.sub(r"(\[\])+$", "", re.sub(r"\[\d+\]", "[]", path))


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def _has_number(x) -> bool:
    if _is_number(x):
        return True
    if isinstance(x, Mapping):
        return any(_has_number(v) for v in x.values())
    if isinstance(x, (list, tuple)):
        return any(_has_number(v) for v in x)
    return False


def _numbers_only(x) -> bool:
    """Numbers, ``None``, strings and (nested) lists of them: no objects with named fields."""
    if isinstance(x, Mapping):
        return False
    if isinstance(x, (list, tuple)):
        return all(_numbers_only(v) for v in x)
    return True


def unit_rule_violations(doc) -> list[str]:
    """Where a JSON document breaks the unit rule of docs/json.md (empty when it follows it).

    - Every number (not a bool) sits under a key that names its unit: the key holding it (through
      lists) ends with a unit suffix (:data:`UNIT_SUFFIXES`) or is a documented unit-free or screw
      key (:data:`UNIT_FREE_KEYS`, :data:`SCREW_KEYS`).  A key with a unit suffix names the unit of
      everything beneath it (e.g. ``"actuators_len": {"L1.slide": 0.2}``); so does a unit-free
      key of :data:`UNIT_FREE_MAPS` holding a map by name of numbers (``"transmission":
      {"L1.slide": 0.8}``); any other object under a unit-free key names its fields' units.
    - A key that names an angle (``angle``, ``alpha``, ``euler`` ...) ends with ``_deg`` (or
      lies under a ``_deg`` key: ``"gap_deg": {"alpha": 0.1}``).
    - No key ends with ``_rad`` (angles are degrees in JSON).
    - A ``*_len`` field has a ``length_unit`` declared: at the top level or on an enclosing
      object (a report's sections, which span models in different units, declare their own).
    - Keys in :data:`EMBEDDED_KEYS` (a model file) are not looked into.
    """
    problems: list[str] = []
    undeclared_len: list[str] = []
    degree_suffixes = ("_deg", "_deg2", "_deg3")

    def walk(x, path: str, decided: str | None, in_degrees: bool, declared: bool) -> None:
        # decided: "all" (a unit suffix above, or a flat map under a unit-free key), "direct" (the
        # numbers directly under a unit-free key), or None; in_degrees: the suffix above is a degree
        # one; declared: an enclosing object declares length_unit
        if isinstance(x, Mapping):
            unit = x.get("length_unit")
            declared = declared or (isinstance(unit, str) and bool(unit))
            for k, v in x.items():
                k = str(k)
                here = f"{path}.{k}" if path else k
                if k in EMBEDDED_KEYS:
                    continue
                if k.endswith(("_rad", "_radians", "_rad_per_s")):
                    problems.append(f"{_field(here)}: radians in JSON (angles are degrees, '_deg')")
                kind = _unit_of(k)
                if "_len" in k and kind == "suffix" and not declared:
                    undeclared_len.append(_field(here))
                if (_ANGLE_WORD.search(k) and kind is None and not in_degrees and not k.endswith(degree_suffixes)
                        and _has_number(v)):
                    problems.append(f"{_field(here)}: an angle without the '_deg' suffix")
                if kind == "suffix":
                    walk(v, here, "all", k.endswith(degree_suffixes), declared)
                elif kind == "unit-free":
                    flat_map = k in UNIT_FREE_MAPS and isinstance(v, Mapping) and all(_numbers_only(w) for w in v.values())
                    walk(v, here, "all" if flat_map else "direct", False, declared)
                else:
                    walk(v, here, decided if decided == "all" else None, in_degrees and decided == "all", declared)
        elif isinstance(x, (list, tuple)):
            for i, v in enumerate(x):
                walk(v, f"{path}[{i}]", decided, in_degrees, declared)
        elif _is_number(x) and decided is None:
            problems.append(f"{_field(path)}: a number under a key with no unit suffix (or a documented unit-free key)")

    walk(doc, "", None, False, False)
    problems = list(dict.fromkeys(problems))  # one line per field, not per list item
    if undeclared_len:
        fields = list(dict.fromkeys(undeclared_len))
        problems.append(f"length_unit: *_len fields ({', '.join(fields[:3])}{' ...' if len(fields) > 3 else ''}) "
                        "without a length_unit declared at the top level or on an enclosing object")
    return problems


# ---------------------------------------------------------------------------- notebook display
#: Most rows of a list of records (solutions, limbs) that :func:`html_summary` shows.
HTML_MAX_ROWS = 12


def html_cell(v: Any) -> str:
    """One value of a JSON document as short HTML text: numbers to 5 significant digits, short
    vectors inline, a matrix by its shape, long text cut; escaped."""
    from html import escape

    if isinstance(v, bool) or v is None:
        return escape(str(v))
    if isinstance(v, float):
        return f"{v:.5g}"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return escape(v if len(v) <= 120 else v[:117] + "...")
    if isinstance(v, dict):
        inner = [f"{escape(str(k))}: {html_cell(x)}" for k, x in v.items() if not isinstance(x, (dict, list))]
        return ", ".join(inner) if inner else f"{{{len(v)} fields}}"
    if isinstance(v, (list, tuple)):
        if v and all(isinstance(x, (list, tuple)) for x in v):
            return f"{len(v)} x {len(v[0])} matrix"
        if len(v) <= 8 and not any(isinstance(x, (dict, list, tuple)) for x in v):
            return "[" + ", ".join(html_cell(x) for x in v) + "]"
        return f"{len(v)} items"
    return escape(str(v))


def html_summary(title: str, doc: Mapping, records: str | None = None, columns: Iterable[str] = ()) -> str:
    """A compact HTML table of a result's JSON document ``doc`` (``to_dict()``: units in the
    field names) for a notebook's ``_repr_html_``: one row per top-level field, and the list of
    records under ``records`` (e.g. the solutions) as a table of ``columns`` (a pose field shows
    its position and Euler angles)."""
    from html import escape

    cols = list(columns)
    rows = "".join(f"<tr><th style='text-align:left'>{escape(str(k))}</th><td style='text-align:left'>{html_cell(v)}</td></tr>"
                   for k, v in doc.items() if k != records)
    out = [f"<div class='spatialmech-result'><b>{escape(title)}</b><table>{rows}</table>"]
    recs = doc.get(records) if records else None
    if isinstance(recs, list) and recs and cols:
        def cell(r, c):
            v = r.get(c) if isinstance(r, dict) else None
            if c == "pose" and isinstance(v, dict):
                seq = escape(str(v.get("euler_sequence")))
                return f"{html_cell(v.get('position_len'))}; {seq} {html_cell(v.get('euler_deg'))} deg"
            return html_cell(v)
        head = "".join(f"<th>{escape(c)}</th>" for c in ["#", *cols])
        body = "".join("<tr>" + f"<td>{k + 1}</td>" + "".join(f"<td>{cell(r, c)}</td>" for c in cols) + "</tr>"
                       for k, r in enumerate(recs[:HTML_MAX_ROWS]))
        more = f"<div>... {len(recs) - HTML_MAX_ROWS} more</div>" if len(recs) > HTML_MAX_ROWS else ""
        out.append(f"<b>{escape(records or '')}</b><table><tr>{head}</tr>{body}</table>{more}")
    return "".join(out) + "</div>"
