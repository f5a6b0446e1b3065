"""Solid shapes of a configuration, shared by the static viewer (``view``) and the design studio:
joints as solids along their axes and the platform as a translucent body.

* :func:`joint_list` -- every joint with its type, limb, centre and current axis directions
  (the direction part of each freedom's twist; the moment part for a prismatic freedom).
* :func:`joint_meshes` -- one triangle mesh per limb (for one plotly ``mesh3d`` trace each):
  cylinders along the axes of R, H and U joints, longer ones for C, long thin ones for P,
  balls for S; sizes are fractions of the drawing scale (the characteristic length).
* :func:`platform_solid` -- the platform: its outline as a flat polygon when the attachment
  points and the platform point lie in a plane, else their convex hull (a 5-CS coupler).

A mesh is a dict ``{"vertices": (n, 3), "triangles": (m, 3) vertex indices}`` in the model's
length unit; :func:`plotly_mesh` gives a plotly ``mesh3d``'s fields, :func:`mesh_json` its
JSON.  The joint meshes' topology depends only on the joint types (an animation may update
their coordinates alone); a hull's may change between configurations.
"""

from __future__ import annotations

import numpy as np

from ..kinematics.closure import Configuration, joint_points
from ..kinematics.backend import joint_twists
from ..model.mechanism import Mechanism

__all__ = ["JOINT_SIZES", "joint_list", "joint_meshes", "mesh_json", "platform_solid", "plotly_mesh"]

#: (radius, length) of a joint's solid as fractions of the scale, by joint type; S: (radius, -).
JOINT_SIZES = {"R": (0.05, 0.25), "H": (0.05, 0.25), "U": (0.05, 0.25), "C": (0.04, 0.45), "P": (0.025, 0.5),
               "S": (0.06, 0.0)}
#: Sides of a cylinder and rings of a ball.
CYLINDER_SIDES, SPHERE_RINGS = 8, 4


def joint_list(mech: Mechanism, config: Configuration) -> list[dict]:
    """Every joint in limb order: ``name``, ``type``, ``limb_index``, ``centre`` (3,) and
    ``axes`` (unit directions, one per distinct axis; none for S)."""
    tw = joint_twists(mech, config)
    pts = joint_points(mech, config)
    out = []
    for li, limb in enumerate(mech.limbs):
        refs = [r for r in mech.freedom_refs if r.limb == li]
        for j, joint in enumerate(limb.joints):
            dirs: list[np.ndarray] = []
            for k, r in enumerate(refs):
                if r.joint != j or joint.type == "S":
                    continue
                t = tw[li][:, k]
                v = t[3:] if r.freedom.kind == "P" else t[:3]
                v = v / max(float(np.linalg.norm(v)), 1e-300)
                if not any(abs(float(v @ e)) > 1 - 1e-9 for e in dirs):  # C: rotation and slide share the axis
                    dirs.append(v)
            out.append({"name": joint.name, "type": joint.type, "limb_index": li, "centre": np.asarray(pts[li][j]),
                        "axes": dirs})
    return out


def _perp(d: np.ndarray) -> np.ndarray:
    t = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(d, t)
    return u / np.linalg.norm(u)


def _cylinder(verts: list, tris: list, c, d, r: float, h: float, n: int = CYLINDER_SIDES) -> None:
    d = np.asarray(d, float)
    u = _perp(d)
    v = np.cross(d, u)
    t = 2 * np.pi * np.arange(n) / n
    ring = np.cos(t)[:, None] * u + np.sin(t)[:, None] * v
    a, b = c - 0.5 * h * d, c + 0.5 * h * d
    o = len(verts)
    verts.extend(a + r * ring)
    verts.extend(b + r * ring)
    verts.extend([a, b])
    ia, ib, ca, cb = o, o + n, o + 2 * n, o + 2 * n + 1
    for s in range(n):
        s2 = (s + 1) % n
        tris += [(ia + s, ia + s2, ib + s), (ib + s, ia + s2, ib + s2), (ca, ia + s2, ia + s), (cb, ib + s, ib + s2)]


def _sphere(verts: list, tris: list, c, r: float, n: int = SPHERE_RINGS) -> None:
    th = np.pi * np.arange(n + 1) / n
    ph = np.pi * np.arange(2 * n) / n
    o = len(verts)
    for a in th:
        verts.extend(c + r * np.c_[np.sin(a) * np.cos(ph), np.sin(a) * np.sin(ph), np.full(2 * n, np.cos(a))])
    for a in range(n):
        for b in range(2 * n):
            b2 = (b + 1) % (2 * n)
            p, q = o + a * 2 * n, o + (a + 1) * 2 * n
            tris += [(p + b, q + b, p + b2), (p + b2, q + b, q + b2)]


def _mesh(verts: list, tris: list) -> dict:
    return {"vertices": np.asarray(verts, float).reshape(-1, 3), "triangles": np.asarray(tris, int).reshape(-1, 3)}


def plotly_mesh(mesh: dict) -> dict:
    """The fields ``x, y, z, i, j, k`` of a plotly ``mesh3d`` for ``mesh``."""
    V, T = mesh["vertices"], mesh["triangles"]
    return {"x": V[:, 0].tolist(), "y": V[:, 1].tolist(), "z": V[:, 2].tolist(),
            "i": T[:, 0].tolist(), "j": T[:, 1].tolist(), "k": T[:, 2].tolist()}


def mesh_json(mesh: dict | None, digits: int = 6) -> dict | None:
    """JSON of ``mesh`` (docs/json.md): ``vertices_len`` (rounded to ``digits`` decimals of
    the length unit) and ``triangles`` (vertex index triples)."""
    if mesh is None:
        return None
    return {"vertices_len": np.round(mesh["vertices"], digits).tolist(), "triangles": mesh["triangles"].tolist()}


def joint_meshes(joints: list[dict], n_limbs: int, scale: float) -> list[dict]:
    """One mesh per limb with the solids of its joints (see the module docstring)."""
    parts: list[tuple[list, list]] = [([], []) for _ in range(n_limbs)]
    for jd in joints:
        verts, tris = parts[jd["limb_index"]]
        c = np.asarray(jd["centre"], float)
        r, h = JOINT_SIZES.get(jd["type"], JOINT_SIZES["R"])
        if jd["type"] == "S":
            _sphere(verts, tris, c, r * scale)
            continue
        for d in jd["axes"]:
            _cylinder(verts, tris, c, d, r * scale, h * scale, 6 if jd["type"] == "P" else CYLINDER_SIDES)
    return [_mesh(v, t) for v, t in parts]


def platform_solid(mech: Mechanism, outline: np.ndarray, limbs, point: np.ndarray) -> dict | None:
    """The platform as a mesh: its closed ``outline`` (k, 3; last = first:
    :attr:`.viewer.Drawing.platform`) as a flat polygon when the platform's joint points (the
    last points of the polylines ``limbs`` of the limbs ending on the output link) and the
    platform ``point`` lie in a plane (to a thousandth of their size), else the convex hull of
    them (``"hull": True`` in the mesh); ``None`` for fewer than three points."""
    from scipy.spatial import ConvexHull, QhullError

    ends = np.array([l[-1] for limb, l in zip(mech.limbs, limbs, strict=True) if mech.limb_tip(limb) == mech.output],
                    float).reshape(-1, 3)
    pts = np.vstack([ends, np.asarray(point, float)[None, :]])
    if len(pts) >= 4:
        sv = np.linalg.svd(pts - pts.mean(axis=0), compute_uv=False)
        if sv[2] > 1e-3 * max(sv[0], 1e-300):
            try:
                hull = ConvexHull(pts)
            except QhullError:
                hull = None
            if hull is not None:
                return {**_mesh(list(pts), [tuple(f) for f in hull.simplices]), "hull": True}
    P = np.asarray(outline, float)[:-1]
    if len(P) < 3:
        return None
    return {**_mesh(list(P), [(0, q, q + 1) for q in range(1, len(P) - 1)]), "hull": False}
