"""Paper B: leg lengths of the 4-SPS/CU along a trajectory, and its Jacobian checked by
finite differences.

Pose phi = (z, alpha, beta, gamma) in m and rad, R = Rz(gamma) Ry(beta) Rx(alpha).  The leg
lengths are eq 8 corrected (l_i = |T A_i - B_i|); Jx = dl/dphi is eq 9's L^-1 J.
"""

import numpy as np

import spatialmech as sm

k = sm.closed_forms.four_sps_cu                  # the paper-B closed forms, vectorised

t = np.linspace(0.0, 2.0, 9)
phi = np.stack([0.2 + 0.02 * np.sin(2 * np.pi * t), 0.25 * np.cos(np.pi * t), 0.25 * np.sin(np.pi * t),
                0.3 * np.sin(np.pi * t)], axis=-1)
legs = k.leg_lengths(phi)                        # (9, 4), vectorised over the poses
for ti, l in zip(t, legs, strict=True):
    print(f"t = {ti:4.2f} s  legs [m] = {np.round(l, 5)}")

Jx = k.jacobian_x(phi)                           # (9, 4, 4)
h = 1e-7
fd = np.stack([(k.leg_lengths(phi + h * e) - k.leg_lengths(phi - h * e)) / (2 * h) for e in np.eye(4)], axis=-1)
err = np.abs(Jx - fd).max()
print(f"Jx against central differences: largest difference {err:.1e}")

assert np.all((legs > 0.1) & (legs < 0.4))                        # within the leg limits of section 6
assert err < 1e-7
# the home pose alpha = beta = 0 is singular (the legs meet on the Z axis), contrary to the paper
assert abs(np.linalg.det(k.jacobian_x([0.2, 0.0, 0.0, 0.3]))) < 1e-15
