"""The link graph of a mechanism (model/topology.py): links, joints as edges, a spanning tree
rooted at the ground, its cut joints and the independent loops."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech import catalog
from spatialmech.errors import InputError
from spatialmech.model import C, Limb, Mechanism, P, R, S, U
from spatialmech.model.topology import (
    GROUND,
    OUTPUT,
    GraphJoint,
    LinkGraph,
    cut_joints,
    default_cut_preference,
    link_graph,
    loops,
    spanning_tree,
)

MODELS = catalog.names()


def check_tree(g: LinkGraph, t) -> None:
    """A spanning tree: every link but the ground has one parent, reached from the ground; the
    tree has links - 1 joints; the cut joints are the others; the parents come first in order."""
    assert t.order[0] == GROUND and set(t.order) == {k.name for k in g.links} and len(t.order) == len(g.links)
    assert set(t.parent) == {k.name for k in g.links} - {GROUND}
    assert len(t.tree_joints) == len(g.links) - 1 == len(set(t.tree_joints))
    assert set(t.tree_joints) | set(t.cut) == {j.name for j in g.joints} and not set(t.tree_joints) & set(t.cut)
    seen = {GROUND}
    for link in t.order[1:]:
        parent, jn = t.parent[link]
        assert parent in seen  # parents before children: no cycle
        j = g.joint(jn)
        assert {j.a, j.b} == {parent, link}
        assert t.reversed(jn) == (j.a == link)
        seen.add(link)


def check_loops(g: LinkGraph, t) -> None:
    """One loop per cut joint; each is a closed walk through its cut joint and tree joints only."""
    ls = loops(t)
    assert len(ls) == len(t.cut) == g.n_loops
    for lp in ls:
        assert lp.names[0] == lp.cut and lp.names.count(lp.cut) == 1
        assert set(lp.names[1:]) <= set(t.tree_joints)
        at = g.joint(lp.cut).a
        for name, sense in lp.joints:
            j = g.joint(name)
            assert at == (j.a if sense > 0 else j.b)
            at = j.b if sense > 0 else j.a
        assert at == g.joint(lp.cut).a  # back where it started
    # independent: each cut joint is in its own loop only
    assert all(sum(c in lp.names for lp in ls) == 1 for c in t.cut)


@pytest.mark.parametrize("name", MODELS)
def test_ready_made_models_have_limbs_minus_one_loops(name):
    mech = catalog.build(name)
    g = link_graph(mech)
    n_joints = sum(len(limb.joints) for limb in mech.limbs)
    assert len(g.joints) == n_joints
    assert len(g.links) == 2 + len(mech.bodies) + sum(len(limb.joints) - 1 for limb in mech.limbs)
    # limbs between hubs: loops = limbs - moving hubs (output link and bodies)
    assert g.connected and g.n_loops == len(mech.limbs) - 1 - len(mech.bodies)
    t = spanning_tree(g)
    check_tree(g, t)
    check_loops(g, t)


@pytest.mark.parametrize("name, cuts", [
    ("four-sps-cu", ["A1", "A2", "A3", "A4"]),  # the platform-side S of every SPS leg, the CU limb whole
    ("stewart-6sps", ["A2", "A3", "A4", "A5", "A6"]),
    ("five-cs-3", ["S2", "S3", "S4", "S5"]),
    ("rssr", ["B1"]),
    ("three-rps", ["S2", "S3"]),
    ("three-rrr-sm", ["R6", "R9"]),  # no S: the joint nearest the output, the first limb whole
    ("bennett", ["J3"]),
])
def test_default_cuts_prefer_spherical_joints_near_the_output(name, cuts):
    t = spanning_tree(link_graph(catalog.build(name)))
    assert list(t.cut) == cuts
    assert not any(t.reversed(j) for j in t.tree_joints)  # every limb's chain runs from the ground


def test_a_cut_in_the_middle_of_a_limb_hangs_the_rest_from_the_output():
    """Cutting R2 of the 3-RRR's first limb leaves R3 in the tree, run from the platform."""
    g = link_graph(catalog.build("three-rrr-sm"))
    t = spanning_tree(g, cut_preference=lambda j: (0 if j.name in ("R2", "R5") else 1, default_cut_preference(j)))
    assert list(t.cut) == ["R2", "R5"]
    assert t.reversed("R3") and t.reversed("R6") and not t.reversed("R1")
    assert t.parent["limb1.link2"] == (OUTPUT, "R3")
    check_tree(g, t)
    check_loops(g, t)


def test_loop_of_the_four_sps_cu():
    t = spanning_tree(link_graph(catalog.build("four-sps-cu")))
    first = loops(t)[0]
    # A1 (leg 1 -> platform), back down the CU limb, up leg 1
    assert first.joints == (("A1", 1), ("U5", -1), ("C5", -1), ("B1", 1), ("L1", 1))


def test_graph_errors_name_the_problem():
    mech = catalog.build("rssr")
    g = link_graph(mech)
    j = g.joints[0]
    with pytest.raises(InputError, match="to itself"):
        LinkGraph("x", g.links, (GraphJoint("bad", j.joint, "ground", "ground", 0, 0),))
    with pytest.raises(InputError, match="unknown link 'nowhere'"):
        LinkGraph("x", g.links, (GraphJoint("bad", j.joint, "ground", "nowhere", 0, 0),))
    with pytest.raises(InputError, match="not connected"):
        spanning_tree(LinkGraph("x", g.links, g.joints[:1]))
    with pytest.raises(InputError, match="cut joint"):
        spanning_tree(g).reversed("B1")


# ------------------------------------------------------------------ random limbs to a platform
JOINT_TYPES = ["R", "P", "C", "U", "S"]


def make_joint(kind: str, name: str, rng: np.random.Generator):
    p = rng.uniform(-1, 1, 3)
    a = rng.normal(size=3)
    a /= np.linalg.norm(a)
    if kind == "U":
        b = np.cross(a, rng.normal(size=3))
        return U(name, p, [a, b / np.linalg.norm(b)])
    return {"R": R, "P": P, "C": C}[kind](name, p, a) if kind != "S" else S(name, p)


@settings(max_examples=40)
@given(st.lists(st.lists(st.sampled_from(JOINT_TYPES), min_size=1, max_size=4), min_size=1, max_size=5),
       st.integers(0, 2**31 - 1), st.randoms(use_true_random=False))
def test_random_limbs_give_a_spanning_tree_and_a_cycle_basis(limb_types, seed, rnd):
    rng = np.random.default_rng(seed)
    k = 0
    limbs = []
    for i, types in enumerate(limb_types):
        joints = []
        for kind in types:
            k += 1
            joints.append(make_joint(kind, f"J{k}", rng))
        limbs.append(Limb(f"limb{i}", tuple(joints)))
    mech = Mechanism("random", tuple(limbs))
    g = link_graph(mech)
    assert g.n_loops == len(limbs) - 1
    for pref in (None, lambda j: rnd.random()):  # the default choice and any other
        t = spanning_tree(g, cut_preference=pref)
        check_tree(g, t)
        check_loops(g, t)
    t = spanning_tree(g)
    # the default cuts as many S joints as a spanning tree can: a loop with an S never loses it
    # to a non-S cut when that S is free to be cut
    n_s_cut = sum(j.type == "S" for j in cut_joints(t))
    for other in range(5):
        order = np.random.default_rng(other).permutation(len(g.joints))
        rank = {j.name: int(k) for j, k in zip(g.joints, order, strict=True)}
        alt = spanning_tree(g, cut_preference=lambda j, rank=rank: rank[j.name])
        assert sum(j.type == "S" for j in cut_joints(alt)) <= n_s_cut
