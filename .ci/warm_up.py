"""Compile spatialmech's numba kernels into their on-disk cache before the tests, in two parts
that `.ci/run` runs at once on the two cores (the tests would otherwise compile them one by one,
on one core, as they first meet them: about two minutes of a cold run).

    python .ci/warm_up.py 0    # the closure engine (compiled.warm_up), the tracker (defect analyses), task grids
    python .ci/warm_up.py 1    # homotopy trackers, the loop formulation, 4-SPS/CU legs, CS dyads, certificates

Only a cache warm-up: the tests do not depend on it (a kernel it misses compiles when first used).
"""

from __future__ import annotations

import sys
import time

import numpy as np


def part0() -> None:
    import spatialmech as sm
    from spatialmech.kinematics import compiled

    compiled.warm_up()
    sm.defects("five-cs-3")
    sm.defects("five-cs-2")  # four circuits: the compiled search of a pose's distance from a circuit
    # the task grid's sweep and solve, the joint points and the cone margins (bench_limits.py)
    sm.workspace("three-rps", kind="task", over={"a2": (-0.1, 0.1, 3), "a3": (-0.1, 0.1, 3)}, at={"z": 0.33},
                 cones={"S1": 0.8})


def part1() -> None:
    import spatialmech as sm
    from spatialmech import catalog
    from spatialmech.kinematics.homotopy import study as hc
    from spatialmech.kinematics.closed_forms import four_sps_cu as k4
    from spatialmech.synthesis import cs_dyads

    hc.homotopy_forward(hc.pose_system(catalog.resolve("three-rps")), [0.34, 0.36, 0.32])
    _certify_warm_up()  # the certificates' compiled float pass
    sm.fk("rssr", [30.0], degrees=True, all_solutions=True)
    for n in (10, k4.PARALLEL_FROM):
        k4.leg_lengths(np.tile([0.2, 0.0, 0.0, 0.0], (n, 1)))
    x, D = np.linspace(0.1, 1.5, 15), np.tile(np.eye(4), (7, 1, 1))
    cs_dyads.dyad_residual(x, D)
    cs_dyads.dyad_jacobian(x, D)


def _certify_warm_up() -> None:
    """One certified inverse position of a PUMA 560 (standard DH) through the compiled float pass
    of the certificates (compiled/kernels_certify.py: one signature serves every limb and the
    quadrics' test)."""
    import spatialmech as sm
    from spatialmech.model.joints import R
    from spatialmech.model.mechanism import Limb, Mechanism, Pose

    dh = [(0.0, 0.0, np.pi / 2), (0.0, 0.4318, 0.0), (0.15005, 0.0203, -np.pi / 2), (0.4318, 0.0, np.pi / 2),
          (0.0, 0.0, -np.pi / 2), (0.0, 0.0, 0.0)]
    T, frames = np.eye(4), [np.eye(4)]
    for d, a, al in dh:
        T = T @ np.array([[1, 0, 0, a], [0, np.cos(al), -np.sin(al), 0], [0, np.sin(al), np.cos(al), d], [0, 0, 0, 1.0]])
        frames.append(T)
    arm = Mechanism("arm", (Limb("arm", tuple(R(f"J{i + 1}", frames[i][:3, 3], frames[i][:3, 2]) for i in range(6))),),
                    platform_point=frames[-1][:3, 3])
    sm.ik(arm, Pose.from_displacement(np.eye(4), frames[-1][:3, 3]), all_solutions=True)


if __name__ == "__main__":
    t = time.perf_counter()
    (part0 if sys.argv[1:] == ["0"] else part1)()
    print(f"warm-up part {sys.argv[1:]}: {time.perf_counter() - t:.1f} s")
