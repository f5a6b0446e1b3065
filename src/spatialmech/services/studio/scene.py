"""What the studio page draws: the mechanism at one configuration as JSON (model length unit)."""

from __future__ import annotations

from ...kinematics.closure import Configuration
from ...model.mechanism import Mechanism
from ...present.shapes import joint_list, joint_meshes, mesh_json, platform_solid
from ...present.viewer import LIMB_COLOURS, drawing

__all__ = ["scene"]


def scene(mech: Mechanism, config: Configuration, history) -> dict:
    """Limb polylines, base and platform outlines, every joint with its type, limb and axis
    directions, the platform point and frame, the platform point's trail (``history``, the
    last 400 points) and the task positions."""
    m, c = mech, config
    d = drawing(m, c)
    jl = joint_list(m, c)
    joints = [{"name": j["name"], "type": j["type"], "limb_index": j["limb_index"],
               "joint_axes": [v.tolist() for v in j["axes"]], "centre_len": j["centre"].tolist()} for j in jl]
    solid = platform_solid(m, d.platform, d.limbs, d.platform_point)
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
        "joint_meshes": [mesh_json(x) for x in joint_meshes(jl, len(m.limbs), float(d.scale))],
        "bodies_len": d.bodies.tolist(),
        "joints": joints,
        "platform_point_len": d.platform_point.tolist(),
        "platform_frame": d.platform_frame.tolist(),
        "scale_len": float(d.scale),
        "trail_len": [p.tolist() for p in history[-400:]],
        "task_positions_len": [pz.p.tolist() for pz in m.positions],
    }
