"""Dietmaier's 6-6 Gough-Stewart platform: all 40 forward solutions real, proven complete.

P. Dietmaier, "The Stewart-Gough platform of general geometry can have 40 real postures",
Advances in Robot Kinematics: Analysis and Control, Kluwer, 1998, pp. 7-16, built the first
platform whose 40 (complex) forward solutions are all real.  His base points, platform points
(platform frame) and leg lengths, to the six digits published, are below; the mechanism is
described by them alone, in a few lines of Python: for the reference configuration the platform
frame is put 1 m above the world frame, unrotated (any placement that keeps the legs apart would
do; their reference lengths are whatever it gives, and the actuators' values are leg lengths).

`sm.fk(..., all_solutions=True)` solves it by homotopy continuation: 40 solutions, every one
real and each closing its six legs to 1e-9 m, the set complete (every path of a total-degree
homotopy accounted for), about a second.  Several postures lie close to forward singularities
(the smallest scale-free conditioning about 2e-5), as a construction that pushed complex pairs
onto the real axis leaves them.  The same mechanism ships as a file,
`examples/models/stewart-dietmaier.toml`, for the command line:

    spatialmech fk examples/models/stewart-dietmaier.toml \
        --actuators 1,0.645275,1.086284,1.503439,1.281933,0.771071 --all
"""

from pathlib import Path

import numpy as np

import spatialmech as sm

base = np.array([[0, 0, 0], [1.107915, 0, 0], [0.549094, 0.756063, 0],              # b_i, world frame [m]
                 [0.735077, -0.223935, 0.525991], [0.514188, -0.526063, -0.368418],
                 [0.590473, 0.094733, -0.205018]])
platform = np.array([[0, 0, 0], [0.542805, 0, 0], [0.956919, -0.528915, 0],          # a_i, platform frame [m]
                     [0.665885, -0.353482, 1.402538], [0.478359, 1.158742, 0.107672],
                     [-0.137087, -0.235121, 0.353913]])
legs = np.array([1.0, 0.645275, 1.086284, 1.503439, 1.281933, 0.771071])             # |R a_i + p - b_i| [m]

origin = np.array([0.0, 0.0, 1.0])                               # the platform frame at the reference [m]
limbs = []
for i, (b, a) in enumerate(zip(base, platform + origin, strict=True)):
    d = a - b                                                     # the leg at the reference
    limbs.append(sm.Limb(f"leg{i + 1}", [sm.S(f"B{i + 1}", b),
                                          sm.P(f"L{i + 1}", b, d / np.linalg.norm(d), actuated=True,
                                               offset=np.linalg.norm(d)),   # the actuator's value is the leg length
                                          sm.S(f"A{i + 1}", a)]))
mech = sm.Mechanism("stewart-dietmaier", limbs, platform_point=origin)   # poses: of the platform frame

res = sm.fk(mech, legs, all_solutions=True)
d = res.to_dict()
print(f"{d['n_real']} real of {d['search']['n_generic']} solutions; complete: {d['complete']} "
      f"({d['completeness']})")
print("method:", d["method"])

closes = [np.abs(np.linalg.norm(s.pose.p + platform @ s.pose.R.T - base, axis=1) - legs).max()
          for s in res.result.solutions]
print(f"largest leg-length error over the {len(closes)} poses: {max(closes):.1e} m")

# the shipped file: the same legs (examples/models/; a gallery build runs the script without __file__)
here = Path(__file__).parent if "__file__" in globals() else Path(sm.__file__).parents[2] / "examples"
file_mech = sm.load(here / "models" / "stewart-dietmaier.toml")
for mine, theirs in zip(mech.limbs, file_mech.limbs, strict=True):
    for j, k in zip(mine.joints, theirs.joints, strict=True):
        assert j.type == k.type and np.allclose(j.point, k.point, atol=1e-12)
        assert all(np.allclose(f.screw, g.screw, atol=1e-12) and f.offset == g.offset
                   for f, g in zip(j.freedoms, k.freedoms, strict=True))

assert d["method"].startswith("homotopy continuation") and not res.closed_form   # no silent multi-start fallback
assert d["complete"] and d["search"]["n_generic"] == 40
assert d["n_real"] == 40 and len(res.result.solutions) == 40
assert max(closes) < 1e-9
