"""Paper A at scale: screen 5-CS linkages drawn from the CS dyad family of the seven task
positions of table 9, keep the usable ones (no circuit, order or branch defect for some driver),
rank them, and check the best one with the single-linkage defect analysis.

A serial screen of 30 candidates (``workers=0``: no Dask; the default uses a local Dask cluster,
docs/screening.md) takes about 10 s here.  Usable candidates are rare (1 or 2 in 100 of the
weighted sample): seed 7 draws two among its first 30, seed 0 none among its first 200.
"""

import tempfile
from pathlib import Path

import spatialmech as sm

out = Path(tempfile.mkdtemp()) / "screen.parquet"
s = sm.screen("five-cs-positions", out, candidates=30, workers=0, top=3, seed=7)
print(f"{s.judged} candidates judged in {s.seconds:.1f} s ({s.scheduler}): rejected {s.rejected_by_stage}, "
      f"usable {s.usable}")
assert s.workers == 0 and s.scheduler.startswith("serial")  # workers=0: in this process, no Dask
assert s.judged == 30 and sum(s.rejected_by_stage.values()) + s.usable == 30
assert s.rejected_by_stage["dj_signs"] > s.rejected_by_stage["circuits"]  # the cheap stage rejects the most

best = s.top[0]
print(f"best: candidate {best['candidate']}, dyads {best['dyads']}, drivers {best['usable_drivers']}, "
      f"min sigma on the path {best['min_sigma_on_path']:.3g}, slide stroke {best['stroke_len']:.4g}")
linkage = sm.load_model(best["model_file"])       # a model file like any other, with its 7 task positions
assert len(linkage.positions) == 7 and sm.mobility(linkage).dof == 1
d = sm.defects(linkage)                           # the whole defect analysis of that one linkage
assert not d.circuit_defect and not d.order_defect
assert set(best["usable_drivers"]) <= set(d.usable_drivers)
print("confirmed by sm.defects: usable with", ", ".join(d.usable_drivers))
