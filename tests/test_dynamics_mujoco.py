"""Inverse dynamics of closed chains against MuJoCo on the same inertias (issue 28).

MuJoCo recomputes the efforts at the library's states along a trajectory: the exported MJCF with
the links' mass properties as inertials, ``mj_inverse`` for the tree (constraint solver off, no
damping or armature) and the Jacobian of its own ``connect`` / ``weld`` equality constraints for
the loops (tests/dynamics_engines.py).  MuJoCo's forward dynamics would make the loop constraints
soft; their Jacobian is exact, so the split ``qfrc = B^T tau + Jc^T lambda`` is too.  Agreement:
1e-6 relative asked; about 1e-14 reached."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import spatialmech as sm
from spatialmech import catalog

from .dynamics_engines import mujoco_efforts

#: (model, start pose or None, target actuator values relative to the start)
TRAJECTORIES = {
    "four-sps-cu": (([0, 0, 0.12], ("ZYX", 0.3, -0.4, 0.5)), [0.004, -0.003, 0.002, 0.005]),
    "delta-ruu": (None, [0.2, 0.1, -0.05]),
    "delta": (None, [0.17, 0.09, 0.0]),  # the Clavel Delta: a graph with parallelograms, 6 idle spins
    "five-cs-3": (None, [0.15]),
}


def model(name: str):
    mech = catalog.resolve(name)
    if mech.length_unit != "m":  # paper A's linkages are dimensionless: read them in metres
        mech = dataclasses.replace(mech, length_unit="m")
    return mech


def trajectory(name: str) -> sm.DynamicsResult:
    from spatialmech.analysis.dynamics import actuator_values
    from spatialmech.api.checks import as_configuration

    mech = model(name)
    pose, step = TRAJECTORIES[name]
    start, _ = as_configuration(mech, pose, None, False)
    to = actuator_values(mech, start) + np.asarray(step)
    return sm.inverse_dynamics(mech, pose, to=to, duration=0.4, samples=5, density=2700.0, wrench=[1, -2, 3, 0.1, 0.2, -0.3])


@pytest.mark.parametrize("name", list(TRAJECTORIES))
def test_dynamics_against_mujoco(name):
    r = trajectory(name)
    assert r.max_residual < 1e-10
    for i in (1, 2, 3):  # moving samples: velocities and accelerations not zero
        s = r.samples[i]
        assert np.linalg.norm(s.state.x) > 0 and np.linalg.norm(s.xdot) > 0
        tau, resid = mujoco_efforts(r.mechanism, r.masses, s, r.gravity, r.wrench)
        assert max(resid.values()) < 1e-9, resid  # MuJoCo reproduces the bodies' motion; the split is exact
        rel = np.max(np.abs(tau - s.efforts)) / np.max(np.abs(s.efforts))
        assert rel < 1e-6, (name, i, rel)
