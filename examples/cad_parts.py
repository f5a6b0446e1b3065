"""CAD parts of an RSSR linkage: one solid per link, placed at a crank angle, with units.

``sm.export`` writes an STL assembly in millimetres (the unit in the file name and in a JSON
sidecar) and one file per link in its own frame; ``read_joint_frames`` reads the joint centres
back, in metres, and they are the model's.  Needs the ``cad`` extra (trimesh, manifold3d).
"""

import importlib.util
import json
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import spatialmech as sm

if importlib.util.find_spec("trimesh") is None or importlib.util.find_spec("manifold3d") is None:
    print("this example needs the cad extra: pip install 'spatialmech[cad]'")
else:
    import trimesh

    from spatialmech.exchange.cad import read_joint_frames

    with tempfile.TemporaryDirectory() as d:
        r = sm.export("rssr", Path(d) / "rssr.stl", actuators=[40.0], degrees=True, unit="mm")
        print("wrote", ", ".join(f.name for f in r.files))
        frames = read_joint_frames(r.out)
        meshes = {link: trimesh.load_mesh(Path(d) / info["file"]) for link, info in r.joints.items()}
        placements = {link: np.asarray(v["placement"]) for link, v in
                      json.loads((Path(d) / "rssr.mm.json").read_text())["links"].items()}

    print(f"unit read back: {frames['unit']}")
    for link, feats in frames["links"].items():
        print(f"  {link:12s}", ", ".join(f"{f['joint']} at ({', '.join(f'{v:.4f}' for v in f['centre'])}) m" for f in feats))
    # each joint sits where both of its links say
    by_joint: dict[str, list] = {}
    for feats in frames["links"].values():
        for f in feats:
            by_joint.setdefault(f["joint"], []).append(np.asarray(f["centre"]))
    for name, cs in by_joint.items():
        assert len(cs) == 2 and np.linalg.norm(cs[0] - cs[1]) < 1e-9, name

    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d")
    for (link, mesh), colour in zip(meshes.items(), ["0.6", "tab:blue", "tab:orange", "tab:green"], strict=False):
        m = mesh.copy().apply_transform(placements[link])
        ax.plot_trisurf(*m.vertices.T, triangles=m.faces, color=colour, linewidth=0, alpha=0.9)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_title("RSSR at a crank angle of 40 deg: the STL assembly")
    ax.set_box_aspect(np.ptp(np.vstack([m.bounds for m in meshes.values()]), axis=0) + 1e-9)
