"""Paper A: the sign of DJ at the seven task positions of 5-CS linkage 3, for the ten drivers.

Only the rotations of C1 and C2 keep the sign of DJ over the seven positions (paper A
figs 15-16): with any other driver the linkage would pass a singularity (a branch defect)
between two positions.
"""

import spatialmech as sm

mech = sm.load_model("five-cs-3")
table = sm.dj_table(mech)
print(f"{mech.name}: sign of DJ at {', '.join(table.positions)}")
for i, d in enumerate(table.drivers):
    signs = " ".join("+" if s > 0 else "-" for s in table.signs[i])
    print(f"  {d:>7s}  {signs}   {'keeps its sign' if table.keeps_sign(d) else 'changes sign'}")
worst = max(f.position_error for f in table.fits)
print(f"(printed, rounded poses fitted onto the closure: largest platform-point error {worst:.3f} {mech.length_unit})")

assert {d for d in table.drivers if table.keeps_sign(d)} == {"rot1", "rot2"}
assert all(f.converged for f in table.fits)
