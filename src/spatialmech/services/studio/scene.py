"""What the studio page draws: the mechanism at one configuration as JSON (model length unit)."""

from __future__ import annotations

import numpy as np

from ...geometry.tolerances import current
from ...kinematics.closure import Configuration
from ...model.mechanism import Mechanism
from ...present.shapes import joint_list, joint_meshes, mesh_json, platform_solid
from ...present.viewer import LIMB_COLOURS, drawing

__all__ = ["plane_normal", "scene"]


def scene(mech: Mechanism, config: Configuration, history, solids: bool = True) -> dict:
    """Limb polylines, base and platform outlines, every joint with its type, limb and axis
    directions, the platform point and frame, the platform point's trail (``history``, the
    last 400 points), the task positions and, for a planar linkage, its plane's normal (the
    page's top view).  ``solids=False`` leaves the joint solids out (``joint_meshes`` empty:
    the light 3-D view draws the joints as markers)."""
    m, c = mech, config
    d = drawing(m, c)
    jl = joint_list(m, c)
    joints = [{"name": j["name"], "type": j["type"], "limb_index": j["limb_index"],
               "joint_axes": [v.tolist() for v in j["axes"]], "centre_len": j["centre"].tolist()} for j in jl]
    solid = platform_solid(m, d.platform, d.limbs, d.platform_point)
    normal = plane_normal(jl)
    hull = solid if solid is not None and solid["hull"] else None  # the platform mesh, when it is a hull
    return {
        "limbs_len": [l.tolist() for l in d.limbs],
        "limb_names": [l.name for l in m.limbs],
        "limb_colours": [LIMB_COLOURS[i % len(LIMB_COLOURS)] for i in range(len(m.limbs))],
        "base_len": d.base.tolist(),
        "platform_len": d.platform.tolist(),
        "platform_hull_len": hull["vertices"].tolist() if hull is not None else [],
        "hull_faces": hull["triangles"].tolist() if hull is not None else [],
        "platform_mesh": mesh_json(solid),
        "joint_meshes": [mesh_json(x) for x in joint_meshes(jl, len(m.limbs), float(d.scale))] if solids else [],
        "bodies_len": d.bodies.tolist(),
        "joints": joints,
        "platform_point_len": d.platform_point.tolist(),
        "platform_frame": d.platform_frame.tolist(),
        "scale_len": float(d.scale),
        "trail_len": [p.tolist() for p in history[-400:]],
        "task_positions_len": [pz.p.tolist() for pz in m.positions],
        "plane_normal": normal.tolist() if normal is not None else None,
    }


def plane_normal(joints: list[dict]) -> np.ndarray | None:
    """The unit normal of the plane a planar linkage moves in (the page's top view), ``None``
    when the linkage is not planar: every joint an R joint whose axis is parallel to the
    others' (within :attr:`~spatialmech.geometry.tolerances.Tolerances.unit`) or a P joint whose
    slide lies in the plane, with at least two R joints.  Oriented by its largest component
    (positive), never by a factorisation."""
    tol = current().unit
    r_axes = [np.asarray(j["axes"][0], dtype=float) for j in joints if j["type"] == "R" and len(j["axes"]) == 1]
    if len(r_axes) < 2 or any(j["type"] not in ("R", "P") for j in joints):
        return None
    n = r_axes[0] / np.linalg.norm(r_axes[0])
    if any(float(np.linalg.norm(np.cross(n, a / np.linalg.norm(a)))) > tol for a in r_axes[1:]):
        return None
    slides = [np.asarray(j["axes"][0], dtype=float) for j in joints if j["type"] == "P" and j["axes"]]
    if any(abs(float(n @ a)) > tol * float(np.linalg.norm(a)) for a in slides):
        return None
    return n if n[int(np.argmax(np.abs(n)))] > 0 else -n
