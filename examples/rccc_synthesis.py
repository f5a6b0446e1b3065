"""Paper D: a spatial RCCC linkage for the four positions of table 1, by solution regions.

The spherical Burmester curves give the axis directions, solution lines their positions;
the input C joint becomes an R joint where its slide between the positions is smallest.
The orientations are then met exactly and the positions approximately (an RC dyad is exact
for three positions, approximate for four).
"""

import numpy as np

import spatialmech as sm

res = sm.synth_rccc("rccc-four-positions")
task = res.task
u = task.length_unit
print(f"spherical 4R: {res.linkage_type}, defects: {res.defects}; pick {res.pick}, input dyad {res.input_dyad.kind}")
print(f"input slides replaced by the R joint: {np.round(res.slides, 3)} {u}")
print(f"position errors at positions 2-4: {np.round(res.check.position_errors, 3)} {u}")
print(f"orientation errors: {np.degrees(res.check.orientation_errors).max():.1e} deg")

assert res.pick == "best-rc" and res.input_dyad.kind == "RC"     # the C joint replaced by an R joint
assert res.linkage_type == "crank-rocker" and res.defects == 0
assert np.all(res.check.converged)
assert np.degrees(res.check.orientation_errors).max() < 1e-9       # orientations exact
assert res.max_abs_slide < 5.0 and res.check.position_errors.max() < 5.0   # positions within a few mm
