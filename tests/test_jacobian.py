"""The complete Jacobian: definition checks on motions, and paper A's DJ sign patterns."""

import numpy as np
import pytest

from spatialmech import catalog
from spatialmech.geometry.rotations import inverse_transform, log_transform
from spatialmech.geometry.tolerances import DEFAULT
from spatialmech.kinematics.closure import Configuration, active_mask
from spatialmech.kinematics.backend import closure_jacobian, correct
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.jacobian import complete_jacobian
from spatialmech.kinematics.position import configuration_at_pose

DRIVERS = [f"rot{i}" for i in range(1, 6)] + [f"slide{i}" for i in range(1, 6)]


def _tangent(mech, config):
    A, _ = closure_jacobian(mech, config)
    _, _, vt = np.linalg.svd(A)
    return vt[-1]  # 1-DOF mechanism without passive freedoms: the null space is a line


def test_complete_jacobian_maps_the_platform_twist_to_the_driver_rate():
    mech = catalog.build("five-cs-3")
    c = generic_configuration(mech, seed=4)
    t = _tangent(mech, c)
    qdot, V = t[:-6], t[-6:]
    for d in DRIVERS:
        J = complete_jacobian(mech, c, [d])
        i = [r.id for r in mech.freedom_refs].index(mech.freedom(d).id)
        assert np.allclose(J.constraints @ V, 0, atol=1e-9)
        assert J.actuation @ V == pytest.approx([qdot[i]], abs=1e-9)


def test_complete_jacobian_against_finite_motion():
    mech = catalog.build("five-cs-1")
    c0 = generic_configuration(mech, seed=1)
    t = _tangent(mech, c0)
    h = 1e-6
    from spatialmech.kinematics.backend import retract
    c1 = correct(mech, retract(mech, c0, active_mask(mech), h * t)).config
    V = log_transform(c1.D @ inverse_transform(c0.D)) / h
    dq = (c1.q - c0.q) / h
    J = complete_jacobian(mech, c0, ["slide2"])
    i = [r.id for r in mech.freedom_refs].index("C2.slide")
    assert J.actuation @ V == pytest.approx([dq[i]], rel=1e-4, abs=1e-6)


def test_stewart_jacobian_is_the_inverse_velocity_map():
    mech = catalog.build("stewart-6sps")
    c = generic_configuration(mech, seed=2)
    J = complete_jacobian(mech, c)
    assert J.constraint_rows == 0 and J.matrix.shape == (6, 6)
    # actuation rows are unit forces along the legs (for a unit leg-rate twist they give the rate)
    rng = np.random.default_rng(0)
    V = rng.normal(size=6)
    A, _ = closure_jacobian(mech, c)
    n = len(c.q)
    qdot = np.linalg.lstsq(A[:, :n], -(A[:, n:] @ V), rcond=None)[0]  # J_k qdot_k = V (A = [J | -1])
    idx = [[r.id for r in mech.freedom_refs].index(a) for a in mech.actuators]
    assert np.allclose(J.matrix @ V, qdot[idx], atol=1e-9)
    assert 0 < J.condition <= 1 and J.sigma_min > 0


def test_four_sps_cu_home_is_singular_and_generic_is_not():
    mech = catalog.build("four-sps-cu")
    J0 = complete_jacobian(mech, Configuration.reference(mech))
    assert J0.constraint_rows == 2 and J0.matrix.shape == (6, 6)
    assert abs(J0.det) < 1e-12 and J0.sigma_min < 1e-9
    # the generic configuration depends on the model and the seed only (not on the BLAS kernel:
    # docs/conventions.md); seed 0 gives sigma_min 4.7e-4 on every kernel, regular by three orders
    # of magnitude above the singular tolerance (sigma_min of generic ones spreads over 1e-4..1e-2)
    J1 = complete_jacobian(mech, generic_configuration(mech, seed=0, step=0.5))
    assert J1.sigma_min > 1e3 * DEFAULT.singular


def test_inverse_singularity_is_flagged():
    # RSSR: the input limb R-S-S has a passive spin, so its six remaining twists still span
    # every twist when one S freedom is taken out: that freedom cannot act as an actuator.
    mech = catalog.build("rssr")
    c = generic_configuration(mech, seed=0)
    J = complete_jacobian(mech, c, ["A1.rot1"])
    assert J.inverse_singular == ("A1.rot1",) and J.sigma_min == 0.0
    assert complete_jacobian(mech, c, ["A0.rot"]).inverse_singular == ()
    stewart = catalog.build("stewart-6sps")
    with pytest.raises(ValueError, match="repeated"):
        complete_jacobian(stewart, Configuration.reference(stewart), ["L1.slide", "L1.slide"])


def _dj_signs(name):
    mech = catalog.build(name)
    prev, cfgs = None, []
    for P in mech.positions:
        fit = configuration_at_pose(mech, P, start=prev)
        assert fit.converged
        prev = fit.config
        cfgs.append(fit.config)
    return {d: np.sign([complete_jacobian(mech, c, [d]).det for c in cfgs]) for d in DRIVERS}


def test_paper_A_linkage1_every_driver_changes_sign_figs_6_7():
    signs = _dj_signs("five-cs-1")
    for d, s in signs.items():
        assert abs(s.sum()) < 7, d


def test_paper_A_linkage1_rot1_changes_sign_between_P6_P7_rot5_between_P3_P4_fig_14():
    signs = _dj_signs("five-cs-1")
    # rot1 changes only between P6 and P7 (K2), rot5 between P3 and P4 (K1)
    assert list(np.flatnonzero(np.diff(signs["rot1"]))) == [5]
    assert list(np.flatnonzero(np.diff(signs["rot5"]))) == [2]


def test_paper_A_linkage2_slides_3_4_5_keep_sign_figs_8_9():
    signs = _dj_signs("five-cs-2")
    keep = {d for d, s in signs.items() if abs(s.sum()) == 7}
    assert keep == {"slide3", "slide4", "slide5"}


def test_paper_A_linkage3_rot1_rot2_keep_sign_others_change_figs_15_16():
    signs = _dj_signs("five-cs-3")
    keep = {d for d, s in signs.items() if abs(s.sum()) == 7}
    assert keep == {"rot1", "rot2"}


def test_printed_positions_are_inconsistent_by_a_reported_amount():
    mech = catalog.build("five-cs-3")
    fit = configuration_at_pose(mech, mech.positions[3])
    # the rounded tables do not close exactly: the nearest closed pose is off, and says so
    assert not fit.exact
    assert 0.05 < fit.position_error < 0.5


def test_pose_fit_does_not_stop_in_a_wrong_local_minimum():
    # from the reference, linkage 2's P5 once converged to a configuration 2.3 units / 42 deg away
    mech = catalog.build("five-cs-2")
    fit = configuration_at_pose(mech, mech.positions[4])
    assert fit.converged and fit.position_error < 0.05 and np.degrees(fit.angle_error) < 0.5


@pytest.mark.parametrize("name", ["five-cs-3", "three-rps"])
def test_complete_jacobians_share_the_constraints_exactly(name):
    """complete_jacobians (one evaluation of the constraint wrenches for several actuator sets,
    as the DJ table uses it) equals complete_jacobian called per set, bit for bit."""
    from spatialmech.analysis.defects import candidate_drivers
    from spatialmech.kinematics.jacobian import complete_jacobians

    mech = catalog.build(name)
    config = generic_configuration(mech)
    sets = [[d] for d in candidate_drivers(mech)] + [None]
    for got, a in zip(complete_jacobians(mech, config, sets), sets, strict=True):
        ref = complete_jacobian(mech, config, a)
        assert np.array_equal(got.matrix, ref.matrix)
        assert got.actuators == ref.actuators and got.constraint_limbs == ref.constraint_limbs
        assert got.inverse_singular == ref.inverse_singular and got.transmission == ref.transmission
        assert got.sigma_min == ref.sigma_min
