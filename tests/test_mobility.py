"""Mobility: every number of the papers as a named test, plus the classic mechanisms."""

import numpy as np
import pytest

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis.mobility import motion_type
from spatialmech.catalog.papers import THREE_RRR_TABLE2, THREE_SPS_SMPU_MODES


def motion_set(name):
    return {name[i : i + 2] for i in range(0, len(name), 2)}


def test_paper_B_four_sps_cu_mobility_breakdown():
    r = sm.mobility(catalog.build("four-sps-cu"))
    assert (r.n, r.g, r.sum_f, r.lam, r.d) == (11, 14, 32, 0, 6)
    assert (r.t, r.k, r.v, r.xi) == (2, 2, 0, 4)
    assert r.dof == 4 and r.dof_instantaneous == 4
    assert r.motion == "RxRyRzTz" and r.motion_class == "3R1T"
    # the CU limb's two constraint forces along x and y through the U centre (z0 = 0.2)
    W = np.array(r.constraint_wrenches)
    assert np.allclose(W, [[1, 0, 0, 0, 0.2, 0], [0, 1, 0, -0.2, 0, 0]])


@pytest.mark.parametrize("driven, motion", list(THREE_RRR_TABLE2.items()), ids=["+".join(d) for d in THREE_RRR_TABLE2])
def test_paper_C_table2_three_rrr_modes(driven, motion):
    r = sm.mobility(catalog.build("three-rrr-sm"), "+".join(driven))
    assert r.lam == 3 and r.d == 3
    assert r.dof == len(driven) == r.dof_instantaneous
    assert motion_set(r.motion) == motion_set(motion)
    assert set(r.actuators) == {f"{d}.rot" for d in driven}


def test_paper_C_eq10_13_16_counts():
    mech = catalog.build("three-rrr-sm")
    r1 = sm.mobility(mech, "R1")
    assert (r1.d, r1.n, r1.g, r1.sum_f, r1.v, r1.xi, r1.dof) == (3, 6, 7, 7, 0, 0, 1)  # eq 10
    assert (r1.t, r1.k) == (2, 2)  # "t = 2, k = 2" in section 3.1
    r2 = sm.mobility(mech, "R1+R4")
    assert (r2.d, r2.n, r2.g, r2.sum_f, r2.v, r2.xi, r2.dof) == (3, 7, 8, 8, 0, 0, 2)  # eq 13
    r3 = sm.mobility(mech, "R1+R4+R7")
    assert (r3.d, r3.n, r3.g, r3.sum_f, r3.v, r3.xi, r3.dof) == (3, 8, 9, 9, 0, 0, 3)  # eq 16


def test_paper_C_table2_R7_typo_is_Rz():
    r = sm.mobility(catalog.build("three-rrr-sm"), "R7")
    assert r.motion == "Rz"  # table 2 prints Rx


def test_paper_C_section5_eight_modes():
    rs = sm.mobility_modes(catalog.build("three-sps-smpu"))
    assert sorted(r.dof for r in rs) == [3, 4, 4, 4, 5, 5, 5, 6]
    for r in rs:
        driven = tuple(a.split(".")[1] for a in r.actuators if a.startswith("Sm."))
        assert motion_set(r.motion) == motion_set(THREE_SPS_SMPU_MODES[driven])
        assert r.dof == r.dof_instantaneous


@pytest.mark.parametrize("driven, motion", list(THREE_SPS_SMPU_MODES.items()),
                         ids=["+".join(d) or "Sm-locked" for d in THREE_SPS_SMPU_MODES])
def test_paper_C_section5_smpu_mode(driven, motion):
    """One motion mode of the 3-SPS/SmPU (section 5): 3 DOF plus one per driven Sm rotation."""
    r = sm.mobility(catalog.build("three-sps-smpu"), "+".join(driven) or "Sm-locked")
    assert r.dof == 3 + len(driven) == r.dof_instantaneous
    assert motion_set(r.motion) == motion_set(motion)


@pytest.mark.parametrize("k", [1, 2, 3])
def test_paper_A_five_cs_is_one_dof(k):
    r = sm.mobility(catalog.build(f"five-cs-{k}"))
    assert (r.n, r.g, r.sum_f, r.lam, r.t, r.k, r.v, r.xi) == (7, 10, 25, 0, 5, 5, 0, 0)
    assert r.dof == 1 == r.dof_instantaneous


EXPECTED = {
    "stewart-6sps": (6, "RxRyRzTxTyTz", 6),
    "three-rps": (3, "RxRyTz", 0),
    "three-upu": (3, "TxTyTz", 0),
    "delta": (3, "TxTyTz", 6),
    "delta-ruu": (3, "TxTyTz", 0),
    "spatial-six-bar": (1, "Ry", 2),
    "planar-4r": (1, "1R", 0),
    "bennett": (1, "1H", 0),  # the coupler screws about the ground (non-zero pitch)
    "rssr": (1, "1R", 1),
}


@pytest.mark.parametrize("name", list(EXPECTED))
def test_classic_models(name):
    dof, motion, xi = EXPECTED[name]
    r = sm.mobility(catalog.build(name))
    assert (r.dof, r.dof_instantaneous, r.motion, r.xi) == (dof, dof, motion, xi)


def test_bennett_classic_gk_is_minus_two_and_explained():
    r = sm.mobility(catalog.build("bennett"))
    assert r.gk_classic == -2
    assert r.dof == 1 and r.dof_instantaneous == 1 and r.lam == 3
    assert "classic Grübler-Kutzbach" in r.explanation and "-2" in r.explanation


def test_disagreement_at_a_special_reference_configuration_is_reported():
    # a planar four-bar assembled folded flat (all pivots on a line): the screw systems at the
    # reference have a rank drop; the generic configuration reveals the true mobility
    z = [0, 0, 1]
    mech = sm.Mechanism(
        "flat-4r",
        [sm.Limb("a", [sm.R("A0", [0, 0, 0], z), sm.R("A1", [1, 0, 0], z)]),
         sm.Limb("b", [sm.R("B0", [3, 0, 0], z), sm.R("B1", [2, 0, 0], z)])],
    )
    # links 1, 1, 1 on a ground of 3: the loop closes only stretched flat, an isolated
    # configuration (issue 27: the "generic" configuration Newton reached 1e-6 from it had full
    # rank, and the count was 1); the second-order tangent cone there is empty: rigid
    r = sm.mobility(mech)
    assert r.dof == 2 and r.dof_at_reference == 2
    assert r.dof_instantaneous == 0 == r.local_dof and r.branches == ()
    assert r.reference_singular and "isolated" in r.singular_note
    assert not r.agrees and "special" in r.explanation


def test_motion_type_names_and_classes():
    _X, _Y, Z = np.eye(3)
    assert motion_type([np.r_[Z, 0, 0, 0], np.r_[0, 0, 0, Z]], [0, 0, 0]) == ("RzTz", "1R1T")
    # a rotation about z through (1, 0, 0) seen from the origin is not a pure Rz there
    assert motion_type([np.r_[Z, np.cross([1, 0, 0], Z)]], [0, 0, 0]) == ("1R", "1R")
    assert motion_type([np.r_[Z, np.cross([1, 0, 0], Z)]], [1, 0, 0]) == ("Rz", "1R")
    assert motion_type(np.zeros((0, 6)), [0, 0, 0]) == ("rigid", "0")


def test_metamorphic_without_mode_is_an_error():
    with pytest.raises(ValueError, match="mode: three-rrr-sm is metamorphic"):
        sm.mobility(catalog.build("three-rrr-sm"))
    with pytest.raises(KeyError, match="unknown mode 'R2'"):
        sm.mobility(catalog.build("three-rrr-sm"), "R2")
