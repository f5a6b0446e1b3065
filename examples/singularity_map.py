"""A singularity map of the 3-RPS: sigma_min over a tilt slice, with the singular loci.

The 3-RPS is posed by z, pitch (a2) and roll (a3); the parasitic x, y and yaw are solved at
every cell (``sm.singularity_slice`` with ``at={"z": ...}``).  The map shows the scale-free
smallest singular value of the Jacobian (0 at a singularity) and the zero set of ``det J``.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import spatialmech as sm

angles = np.radians(np.linspace(-40, 40, 33))
s = sm.singularity_slice("three-rps", {"a2": angles, "a3": angles}, at={"z": 0.33})
ok = np.isfinite(s.sigma_min)
print(f"{int(ok.sum())} of {ok.size} cells closed ({', '.join(s.solved)} solved); "
      f"smallest sigma_min {np.nanmin(s.sigma_min):.3g}")

fig, ax = plt.subplots(figsize=(5.5, 4.5))
U, V = np.degrees(s.u), np.degrees(s.v)
im = ax.pcolormesh(U, V, s.sigma_min, shading="auto", cmap="viridis")
if np.nanmin(s.det) < 0 < np.nanmax(s.det):
    ax.contour(U, V, s.det, levels=[0.0], colors="red")
fig.colorbar(im, ax=ax, label="sigma_min (scale-free)")
ax.set_xlabel("pitch a2 (deg)")
ax.set_ylabel("roll a3 (deg)")
ax.set_title("3-RPS at z = 0.33 m: distance to singularity")

assert ok.sum() > 0.5 * ok.size and np.all(s.sigma_min[ok] >= 0)
