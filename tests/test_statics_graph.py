"""Statics on graph mechanisms (internal bodies: the Delta, the spatial six-bar) and redundant
actuation in the dynamics (issue 28): virtual work with loads on the links, joint reactions that
do no work, agreement with the inverse dynamics at rest, one minimum-norm rule."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis import dynamics as dy
from spatialmech.analysis.statics import statics
from spatialmech.api.checks import as_configuration
from spatialmech.geometry import screws as sc
from spatialmech.kinematics.closure import joint_twists

G = np.array([0.0, 0.0, -9.81])
GRAPHS = [("delta", ([0.02, 0.01, -0.33], None)), ("spatial-six-bar", None)]
finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


def _setup(name, pose):
    mech = catalog.resolve(name)
    c, _ = as_configuration(mech, pose, None, False)
    masses, _ = dy.mass_properties(mech, 2700.0)
    return mech, c, masses


@pytest.mark.slow
@pytest.mark.parametrize("name, pose", GRAPHS)
def test_graph_statics_virtual_work_with_gravity(name, pose):
    """For every motion the actuators' power cancels the external wrench's and the weights':
    sum(tau qdot) = -(F . $p) - sum_l (G_l . V_l), to 1e-9 of the terms (property test over
    wrenches and actuator rates; the link twists come from the velocity closure)."""
    mech, c, masses = _setup(name, pose)
    loads = dy.gravity_loads(mech, c, masses, G)
    assert set(loads) >= set(mech.bodies)  # the internal bodies weigh something

    @settings(max_examples=5, deadline=None)
    @given(st.lists(finite, min_size=6, max_size=6), st.lists(st.floats(-10, 10), min_size=len(mech.actuators),
                                                              max_size=len(mech.actuators)))
    def prop(wrench, rates):
        F = np.asarray(wrench)
        s = statics(mech, c, F, loads=loads)
        assert s.balanced and not s.singular
        zero = np.zeros(len(mech.actuators))
        d = dy.inverse_dynamics(mech, dy.state_from_actuators(mech, c, rates, zero), {}, np.zeros(3))
        V = d.link_twists
        power = float(s.efforts @ np.asarray(rates) + sc.reciprocal_product(F, V[mech.output])
                      + sum(sc.reciprocal_product(w, V[n]) for n, w in loads.items()))
        scale = float(np.abs(s.efforts) @ np.abs(rates) + np.linalg.norm(F) * np.linalg.norm(V[mech.output])
                      + sum(np.linalg.norm(w) * np.linalg.norm(V[n]) for n, w in loads.items()))
        assert abs(power) <= 1e-9 * scale, (power, scale)

    prop()


@pytest.mark.parametrize("name, pose", GRAPHS)
def test_graph_statics_reactions_do_no_work_and_match_the_dynamics_at_rest(name, pose):
    """Every joint's reaction is reciprocal to all its freedoms (a ball joint: a pure force through
    its centre); the efforts and reactions equal sm.inverse_dynamics at zero velocity and
    acceleration with the same masses and gravity (1e-10 relative)."""
    mech, _, _ = _setup(name, pose)
    F = np.array([1.0, 2.0, -30.0, 0.1, 0.2, 0.3])
    r = sm.statics(mech, pose, wrench=F, gravity=G, density=2700.0)
    assert r.balanced and len(r.reactions) == sum(len(limb.joints) for limb in mech.limbs)
    assert not any("not computed" in n for n in r.notes)
    tw = joint_twists(mech, r.config)
    worst = max(float(np.max(np.abs(j.wrench))) for j in r.reactions)
    by = {(j.limb, j.joint): j for j in r.reactions}
    for k, limb in enumerate(mech.limbs):
        col = 0
        for joint in limb.joints:
            rj = by[(limb.name, joint.name)]
            for g in range(len(joint.freedoms)):
                work = float(sc.reciprocal_product(rj.wrench, tw[k][:, col + g]))
                assert abs(work) <= 1e-9 * worst * mech.characteristic_length
            if joint.type == "S":
                assert np.allclose(rj.moment_at_point, 0.0, atol=1e-9 * worst * mech.characteristic_length)
            col += len(joint.freedoms)
    d = sm.inverse_dynamics(mech, pose, wrench=F, density=2700.0)
    scale = float(np.max(np.abs(r.analysis.efforts)))
    np.testing.assert_allclose(d.efforts[0], r.analysis.efforts, rtol=0, atol=1e-10 * scale)


@pytest.mark.parametrize("name, pose", GRAPHS)
def test_graph_statics_without_loads_match_the_jacobian_route(name, pose):
    """Without loads the closure balance and the complete Jacobian's wrenches give the same
    efforts: the Jacobian's rows times the efforts and constraint intensities cancel the wrench."""
    mech, c, _ = _setup(name, pose)
    F = np.array([3.0, -2.0, -50.0, 0.4, 0.7, -0.2])
    s = statics(mech, c, F)
    J = s.jacobian
    n_c = J.constraint_rows
    # the efforts fixed, the constraint wrenches must take up the rest exactly
    rest = -(F + J.wrenches[n_c:].T @ s.efforts)
    lam, *_ = np.linalg.lstsq(J.wrenches[:n_c].T, rest, rcond=None)
    L = mech.characteristic_length
    miss = sc.nondimensional(J.wrenches[:n_c].T @ lam - rest, L)
    assert np.linalg.norm(miss) <= 1e-9 * np.linalg.norm(sc.nondimensional(F, L))


def test_redundant_actuation_dynamics_at_rest_is_the_statics_minimum_norm():
    """The 4-SPS/CU with its CU slide driven too (five actuators, four needed): the inverse
    dynamics at rest gives the statics' minimum-norm efforts (forces as they are, torques / L),
    to 1e-9 relative, with and without the links' weights."""
    pose = ([0.0, 0.0, 0.12], ("ZYX", 0.6, -0.1, 0.2))
    mech = catalog.resolve("four-sps-cu")
    c, _ = as_configuration(mech, pose, None, False)
    drivers = ["L1.slide", "L2.slide", "L3.slide", "L4.slide", "C5.slide"]
    F = np.array([5.0, -3.0, -100.0, 1.0, -2.0, 0.5])
    s = statics(mech, c, F, drivers=drivers)
    assert s.redundant
    d = dy.inverse_dynamics(mech, dy.rest_state(mech, c), {}, np.zeros(3), F, drivers)
    np.testing.assert_allclose(d.efforts, s.efforts, rtol=0, atol=1e-9 * np.max(np.abs(s.efforts)))
    # with weights too, through the API
    r = sm.statics(mech, pose, wrench=F, drivers=drivers, gravity=G, density=2700.0)
    masses, _ = dy.mass_properties(mech, 2700.0)
    d2 = dy.inverse_dynamics(mech, dy.rest_state(mech, c), masses, G, F, drivers)
    np.testing.assert_allclose(d2.efforts, r.analysis.efforts, rtol=0, atol=1e-9 * np.max(np.abs(r.analysis.efforts)))
