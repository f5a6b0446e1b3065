"""Inverse dynamics of closed chains against Pinocchio on the same inertias (issue 28).

Pinocchio (the ``pin`` wheel) gets the same spanning tree with the same inertias; at the library's
states along a trajectory, ``rnea`` gives the tree's generalized forces and the loop closures'
Jacobian comes from its body Jacobians (a ``connect``: the common point's velocity; a ``weld``:
the twist); the efforts from ``qfrc = B^T tau + Jc^T lambda`` (tests/dynamics_engines.py).
Agreement: 1e-6 relative asked; about 1e-14 reached."""

from __future__ import annotations

import numpy as np
import pytest

from .test_dynamics_mujoco import TRAJECTORIES, trajectory

pytest.importorskip("pinocchio")

from .dynamics_engines import PinocchioTree


@pytest.mark.parametrize("name", list(TRAJECTORIES))
def test_dynamics_against_pinocchio(name):
    r = trajectory(name)
    tree = PinocchioTree(r.mechanism, r.masses, r.gravity)
    for i in (1, 2, 3):
        s = r.samples[i]
        tau, resid = tree.efforts(s, r.wrench)
        assert max(resid.values()) < 1e-9, resid  # same placements; the bodies' motion reproduced
        rel = np.max(np.abs(tau - s.efforts)) / np.max(np.abs(s.efforts))
        assert rel < 1e-6, (name, i, rel)
