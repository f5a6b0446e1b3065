"""Exports to MuJoCo (MJCF) and URDF, and the MJCF import (spatialmech/exchange/).

The exported geometry is checked with MuJoCo itself: at the reference (qpos0) and at generic
configurations of the library, mapped to MuJoCo's joints, every loop closure holds to
round-off and the output body is where the library puts the platform.  Limbs to a platform and
link-and-joint graphs with internal loops (the Clavel Delta, the spatial six-bar, a graph whose
joints are described against the way its limbs run) go through the same path."""

import json
import re
import xml.etree.ElementTree as ET

import mujoco
import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis.validation import MujocoSimulator
from spatialmech.errors import InputError
from spatialmech.exchange import body_tree, export_model, format_of, from_mjcf, to_mjcf, to_urdf
from spatialmech.exchange.urdf import DRAKE_NS, SPATIALMECH_NS
from spatialmech.geometry.rotations import rotation_angle
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.backend import closure_residual
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.kinematics.position import platform_pose
from spatialmech.model import C, H, Limb, Mechanism, P, R, S, U
from spatialmech.model.topology import link_graph, spanning_tree

MODELS = catalog.names()


def run(*args):
    return CliRunner().invoke(cli, list(args), catch_exceptions=False)


def custom() -> Mechanism:
    """A mechanism with every awkward case: the only S joint is mid-limb (the joints after it
    hang reversed from the platform, a slide with an offset and limits among them), a helical
    joint, a U joint with a locked freedom, and a non-S cut nowhere (one loop, cut at A1)."""
    x, y, z = np.eye(3)
    a = Limb("a", (R("A0", [0, 0, 0], z, actuated=True), S("A1", [1, 0, 0]),
                   P("A2", [1, 0.5, 0.5], [0, 1, 1], normalize=True, offset=0.3, limits=(0.1, 0.9)),
                   R("A3", [1, 1, 1], x, limits=(-1.0, 2.0))))
    b = Limb("b", (H("B0", [2, 0, 0], z, pitch=0.1), U("B1", [2, 0, 1], [x, y], locked=["rot2"]),
                   R("B2", [1.5, 1, 1], [0, 0.6, 0.8])))
    return Mechanism("custom", (a, b), platform_point=[1.2, 1, 1])


def flipped_graph() -> Mechanism:
    """A spatial six-bar as a link-and-joint graph whose joints are described against the way
    its limbs and its spanning tree run (flipped S, R and U joints), with an output link named
    "follower", its point off the follower's C joint, and a second loop without an S joint
    (R-U-U-C: cut at a U joint, closed by a weld of a ghost body)."""
    x, y, z = np.eye(3)
    links = ["ground", "crank", "rod1", "rocker", "rod2", "follower"]
    joints = [
        (R("A0", [0.0, 0.0, 0.0], z, actuated=True), "crank", "ground"),
        (S("A1", [0.3, 0.0, 0.0]), "rod1", "crank"),
        (S("B1", [0.0, 1.0, -0.1]), "rod1", "rocker"),
        (R("B0", [0.0, 1.0, 0.5], x), "rocker", "ground"),
        (U("C1", [0.0, 1.3, 0.8], [x, [0, 0.6, 0.8]]), "rod2", "rocker"),
        (U("D1", [0.9, 2.0, 0.5], [[0.6, 0, 0.8], y]), "follower", "rod2"),
        (C("D0", [0.6, 2.0, 0.5], y), "follower", "ground"),
    ]
    return Mechanism.from_graph("flipped", links, joints, output="follower", platform_point=[0.7, 2.1, 0.4])


def without_metadata(mech: Mechanism, keep: dict | None = None) -> str:
    """The MJCF of ``mech`` with its spatialmech metadata replaced by ``keep`` (as a hand-written
    file would have it: nothing, or only the output body's name)."""
    data = json.dumps(keep or {}).replace('"', "&quot;")
    text, n = re.subn(r'<text name="spatialmech" data="[^"]*"', f'<text name="spatialmech" data="{data}"', to_mjcf(mech))
    assert n == 1
    return text


def closure_at(sim: MujocoSimulator, config) -> tuple[float, float]:
    """MuJoCo's constraint residual / L and the output body's distance from the library's
    platform pose (position / L + angle) with the library's configuration loaded."""
    sim.data.qpos[:] = sim.qpos_of(config)
    r, _ = sim.equality_residual()
    got, want = sim.output_pose(), platform_pose(sim.mech, config)
    ang = rotation_angle(got.R @ want.R.T)
    return float(np.linalg.norm(r)) / sim.L, float(np.linalg.norm(got.p - want.p)) / sim.L + float(ang)


# ------------------------------------------------------------------ MJCF
@pytest.mark.parametrize("name", MODELS)
def test_every_ready_made_model_exports_to_mjcf_that_mujoco_loads(name, tmp_path):
    f = tmp_path / f"{name}.xml"
    r = run("export", name, str(f), "--json")
    assert r.exit_code == 0, r.output
    doc = json.loads(r.output)
    assert doc["format"] == "mjcf" and doc["bytes"] == f.stat().st_size
    m = mujoco.MjModel.from_xml_path(str(f))
    mech = catalog.build(name)
    tree = spanning_tree(link_graph(mech))
    assert m.nu == len(mech.actuators)
    assert m.neq == len(tree.cut) + sum(r.freedom.locked for r in mech.freedom_refs)
    assert m.opt.gravity.tolist() == [0, 0, 0] and m.opt.disableflags & mujoco.mjtDisableBit.mjDSBL_CONTACT
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)  # at qpos0 the mechanism is assembled: every closure holds
    assert np.max(np.abs(d.efc_pos[d.efc_type == mujoco.mjtConstraint.mjCNSTR_EQUALITY]), initial=0.0) < 1e-12 * (
        mech.characteristic_length)


@pytest.mark.parametrize("name", MODELS)
def test_generic_configurations_close_in_mujoco_too(name):
    """The library's configurations, mapped to MuJoCo's joints (balls as quaternions, hinges and
    slides as physical values), satisfy MuJoCo's closures and place the output body at the
    platform pose: the exported geometry is the library's."""
    mech = catalog.build(name)
    sim = MujocoSimulator(mech)
    for seed in (1, 2):
        c = generic_configuration(mech, seed=seed, step=0.3)
        assert np.linalg.norm(closure_residual(mech, c)) < 1e-10
        res, pose_err = closure_at(sim, c)
        assert res < 1e-11 and pose_err < 1e-11, (res, pose_err)


def test_metamorphic_modes_lock_freedoms_with_joint_equalities(tmp_path):
    f = tmp_path / "m.xml"
    assert run("export", "three-rrr-sm", str(f), "--mode", "R1").exit_code == 0
    m = mujoco.MjModel.from_xml_path(str(f))
    locks = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_EQUALITY, k) for k in range(m.neq)
             if m.eq_type[k] == mujoco.mjtEq.mjEQ_JOINT]
    assert sorted(locks) == ["lock:R4.rot", "lock:R7.rot"] and m.nu == 1
    back = from_mjcf(f)
    assert back.actuators == ("R1.rot",) and {r.id for r in back.freedom_refs if r.freedom.locked} == {"R4.rot", "R7.rot"}


def test_a_graph_with_joints_described_backwards_exports_exactly():
    """Flipped joints (a limb or the tree traversing a joint against its description): a ball's
    rotation is inverted once for each, so MuJoCo's closures hold at the library's
    configurations; the loop without an S joint is closed by a weld."""
    mech = flipped_graph()
    assert sm.mobility(mech).dof == 1
    assert [j.name for limb in mech.limbs for j in limb.joints if j.reversed] == ["B1"]
    tree = body_tree(mech)
    assert tree.output == "follower" and tree.hubs == ("rocker",)
    assert tree.joint_links["A0"] == ("crank", "ground") and tree.joint_links["C1"] == ("rod2", "rocker")
    assert {b.joint.name for b in tree.bodies if b.joint is not None and b.joint.reversed} == {"A0", "B0", "B1", "D0"}
    assert [(c.name, c.kind) for c in tree.closures] == [("A1", "connect"), ("C1", "weld")]
    sim = MujocoSimulator(mech)
    for seed in (1, 2, 3):
        c = generic_configuration(mech, seed=seed, step=0.4)
        res, pose_err = closure_at(sim, c)
        assert res < 1e-11 and pose_err < 1e-11, (seed, res, pose_err)


def test_graph_models_become_body_trees_with_internal_bodies():
    """The Delta: 10 bodies (3 arms, 6 rods, the platform), a connect per cut S joint (5 loops),
    the arms drawn as stars from their R joint; the metadata names limbs, ends and bodies."""
    mech = catalog.build("delta")
    tree = body_tree(mech)
    assert len(tree.bodies) == 10 and [c.kind for c in tree.closures] == ["connect"] * 5
    assert tree.hubs == ("arm1", "arm2", "arm3") and tree.output == "platform"
    arm = tree.body("arm1")
    assert arm.parent is None and arm.joint.name == "R1" and len(arm.segments) == 2
    assert all(np.allclose(a, arm.origin) for a, _ in arm.segments)
    meta = tree.metadata()
    assert meta["bodies"] == ["arm1", "arm2", "arm3"] and ["arm1", "platform"] in meta["limb_ends"]
    assert meta["joint_links"]["E1a"] == ["arm1", "rod1a"]
    six = body_tree(catalog.build("spatial-six-bar"))
    follower = six.body("follower")  # the output link: its frame at the platform point
    assert six.output == "follower" and np.allclose(follower.origin, [0.6, 2.0, 0.5])


def test_reversed_helical_and_locked_joints_export_exactly():
    mech = custom()
    tree = body_tree(mech)
    rev = {b.joint.name for b in tree.bodies if b.joint is not None and b.joint.reversed}
    assert rev == {"A2", "A3"}  # cut at the S joint A1: the rest of limb a hangs from the platform
    assert [c.kind for c in tree.closures] == ["connect"]
    assert {c.purpose for c in tree.couplings} == {"helical", "lock"}
    sim = MujocoSimulator(mech)
    for seed in (1, 2, 3):
        c = generic_configuration(mech, seed=seed, step=0.4)
        res, pose_err = closure_at(sim, c)
        assert res < 1e-11 and pose_err < 1e-11


def same_mechanism(a: Mechanism, b: Mechanism) -> None:
    assert a.name == b.name and a.length_unit == b.length_unit
    assert [limb.name for limb in a.limbs] == [limb.name for limb in b.limbs]
    assert (a.output, a.bodies, a.is_graph) == (b.output, b.bodies, b.is_graph)
    assert [(la.base, a.limb_tip(la), la.link_names) for la in a.limbs] == [
        (lb.base, b.limb_tip(lb), lb.link_names) for lb in b.limbs]
    assert [[j.reversed for j in limb.joints] for limb in a.limbs] == [[j.reversed for j in limb.joints] for limb in b.limbs]
    assert np.allclose(a.platform_point, b.platform_point, atol=1e-15)
    assert a.actuators == b.actuators and a.lockable == b.lockable and a.aliases == b.aliases
    assert [m.name for m in a.modes] == [m.name for m in b.modes]
    for la, lb in zip(a.limbs, b.limbs, strict=True):
        assert [(j.name, j.type) for j in la.joints] == [(j.name, j.type) for j in lb.joints]
        for ja, jb in zip(la.joints, lb.joints, strict=True):
            assert np.allclose(ja.point, jb.point, atol=1e-12)
            for fa, fb in zip(ja.freedoms, jb.freedoms, strict=True):
                assert fa.name == fb.name and fa.kind == fb.kind and fa.locked == fb.locked
                assert fa.offset == pytest.approx(fb.offset, abs=1e-15) and fa.limits == fb.limits
                assert fa.pitch == pytest.approx(fb.pitch, abs=1e-15)
                if ja.type != "S":  # a ball has no axes in MuJoCo: any orthonormal triple is the same joint
                    assert np.allclose(fa.direction, fb.direction, atol=1e-12)
    # the same screws at the reference: the same kinematics
    sa = np.array([r.freedom.screw for r in a.freedom_refs if a.limbs[r.limb].joints[r.joint].type != "S"])
    sb = np.array([r.freedom.screw for r in b.freedom_refs if b.limbs[r.limb].joints[r.joint].type != "S"])
    assert np.allclose(sa, sb, atol=1e-12)


@pytest.mark.parametrize("name", MODELS)
def test_mjcf_round_trip(name, tmp_path):
    mech = catalog.build(name)
    f = tmp_path / "m.xml"
    export_model(mech, f)
    back = from_mjcf(f)
    same_mechanism(mech, back)
    if mech.is_graph:  # the graph form comes back, with its loops and mobility
        m0, m1 = sm.mobility(mech), sm.mobility(back)
        assert (m1.dof, m1.loops, m1.motion) == (m0.dof, m0.loops, m0.motion)


def test_round_trip_of_reversed_helical_and_locked_joints(tmp_path):
    f = tmp_path / "c.xml"
    f.write_text(to_mjcf(custom()))
    same_mechanism(custom(), from_mjcf(f))


def test_round_trip_of_a_graph_with_joints_described_backwards(tmp_path):
    f = tmp_path / "g.xml"
    f.write_text(to_mjcf(flipped_graph()))
    back = from_mjcf(f)
    same_mechanism(flipped_graph(), back)
    g0, g1 = link_graph(flipped_graph()), link_graph(back)
    assert {(j.name, j.a, j.b) for j in g0.joints} == {(j.name, j.a, j.b) for j in g1.joints}


@pytest.mark.parametrize("name, dof, loops", [("delta", 3, 5), ("spatial-six-bar", 1, 2)])
def test_an_mjcf_with_internal_loops_and_no_metadata_imports_as_a_graph(name, dof, loops, tmp_path):
    """A hand-written MJCF (here an export without its metadata, but for the output body's
    name): the link graph is cut into limbs between hub links, giving the graph form with the
    same links, joints, loops and mobility."""
    mech = catalog.build(name)
    f = tmp_path / "g.xml"
    f.write_text(without_metadata(mech, {"output": mech.output}))
    back = from_mjcf(f)
    assert back.is_graph and back.output == mech.output and set(back.bodies) == set(mech.bodies)
    g0, g1 = link_graph(mech), link_graph(back)
    assert {k.name for k in g0.links} == {k.name for k in g1.links}
    assert {(j.name, j.type, frozenset((j.a, j.b))) for j in g0.joints} == {
        (j.name, j.type, frozenset((j.a, j.b))) for j in g1.joints}
    assert g1.n_loops == loops
    m0, m1 = sm.mobility(mech), sm.mobility(back)
    assert m1.dof == m0.dof == dof and m1.loops == loops and m1.motion == m0.motion
    if name == "spatial-six-bar":  # without its name in the metadata, the output body is not known
        f.write_text(without_metadata(mech))
        with pytest.raises(InputError, match="no output link"):
            from_mjcf(f)


def test_damaged_metadata_is_an_input_error(tmp_path):
    f = tmp_path / "g.xml"
    f.write_text(without_metadata(catalog.build("delta"), {"limbs": 3}))
    with pytest.raises(InputError, match="is not spatialmech metadata"):
        from_mjcf(f)


GENERIC = """<mujoco model="hand-written">
  <compiler angle="degree"/>
  <worldbody>
    <body name="crank">
      <joint name="A0" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 1 0 0" size="0.05"/>
      <body name="platform" pos="1 0 0" euler="90 0 0">
        <joint name="A1" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 2 0 0" size="0.05"/>
      </body>
    </body>
    <body name="rocker" pos="3 0 0">
      <joint name="B0" type="hinge" axis="0 0 1" range="-45 45"/>
      <geom type="capsule" fromto="0 0 0 0 1 0" size="0.05"/>
    </body>
  </worldbody>
  <equality>
    <connect body1="platform" body2="rocker" anchor="2 0 0"/>
  </equality>
  <actuator>
    <motor joint="A0"/>
  </actuator>
</mujoco>
"""


def test_import_of_a_hand_written_mjcf(tmp_path):
    """Any orientation form MuJoCo reads (here euler angles in degrees) is read through MuJoCo;
    a connect equality is an S joint; limbs run from the ground to the body named platform."""
    f = tmp_path / "g.xml"
    f.write_text(GENERIC)
    mech = from_mjcf(f)
    assert mech.name == "hand-written" and mech.actuators == ("A0.rot",)
    assert [[(j.name, j.type) for j in limb.joints] for limb in mech.limbs] == [
        [("A0", "R"), ("A1", "R")], [("B0", "R"), ("connect0", "S")]]
    a1 = mech.limbs[0].joints[1]
    assert np.allclose(a1.point, [1, 0, 0]) and np.allclose(a1.axes[0], [0, 0, 1], atol=1e-12)  # y turned onto z
    assert np.allclose(mech.limbs[1].joints[1].point, [3, 0, 0], atol=1e-12)
    assert mech.limbs[1].joints[0].freedoms[0].limits == pytest.approx((-np.pi / 4, np.pi / 4))


@pytest.mark.parametrize("xml, message", [
    (GENERIC.replace('<joint name="B0" type="hinge" axis="0 0 1" range="-45 45"/>', '<freejoint/>'), "free joint"),
    (GENERIC.replace('name="platform"', 'name="coupler"').replace('body1="platform"', 'body1="coupler"'),
     "no output link"),
    ("<mujoco><worldbody><body><geom size='0.1'/></worldbody></mujoco>", "MuJoCo cannot load it"),
])
def test_import_errors_name_the_problem(tmp_path, xml, message):
    f = tmp_path / "bad.xml"
    f.write_text(xml)
    with pytest.raises(InputError, match=message):
        from_mjcf(f)


# ------------------------------------------------------------------ URDF
@pytest.mark.parametrize("name", MODELS)
def test_urdf_is_a_tree_and_lists_the_closures(name, tmp_path):
    mech = catalog.build(name)
    f = tmp_path / f"{name}.urdf"
    r = run("export", name, str(f))
    assert r.exit_code == 0 and "(urdf)" in r.output
    root = ET.parse(f).getroot()
    assert root.tag == "robot" and root.get("name") == name
    links = {k.get("name") for k in root.findall("link")}
    children = [j.find("child").get("link") for j in root.findall("joint")]
    assert sorted(children) == sorted(links - {"ground"})  # every link but the root has one parent: a tree
    assert all(j.find("parent").get("link") in links for j in root.findall("joint"))
    assert mech.output in links
    assert root.find(f"{{{SPATIALMECH_NS}}}loop_closures").get("output") == mech.output
    closures = root.findall(f"{{{SPATIALMECH_NS}}}loop_closures/{{{SPATIALMECH_NS}}}closure")
    cut = spanning_tree(link_graph(mech)).cut
    assert [c.get("name") for c in closures] == list(cut)
    for c in closures:
        assert {c.get("link1"), c.get("link2")} <= links
    balls = [c for c in closures if c.get("kind") == "ball"]
    assert len(root.findall(f"{{{DRAKE_NS}}}ball_constraint")) == len(balls)
    assert len(root.findall("gazebo/joint")) == len(closures)
    offsets = {o.get("joint"): float(o.get("value")) for o in root.iter(f"{{{SPATIALMECH_NS}}}offset")}
    assert offsets == {r.id: r.freedom.offset for r in mech.freedom_refs if r.freedom.offset != 0.0}


def test_urdf_joints_split_multi_freedom_joints():
    root = ET.fromstring(to_urdf(custom()))
    kinds = {j.get("name"): j.get("type") for j in root.findall("joint")}
    assert kinds["A0.rot"] == "continuous" and kinds["A3.rot"] == "revolute" and kinds["A2.slide"] == "prismatic"
    assert kinds["B1.rot1"] == "continuous" and kinds["B1.rot2"] == "fixed"  # the locked freedom
    mimic = root.find("joint[@name='B0.screw:slide']/mimic")
    assert mimic.get("joint") == "B0.screw" and float(mimic.get("multiplier")) == 0.1
    lim = root.find("joint[@name='A2.slide']/limit")  # URDF values are q: the limits less the offset
    assert (float(lim.get("lower")), float(lim.get("upper"))) == pytest.approx((0.1 - 0.3, 0.9 - 0.3))


# ------------------------------------------------------------------ formats
def test_the_format_follows_the_extension_or_the_option(tmp_path):
    assert [format_of(n) for n in ("a.toml", "a.xml", "a.MJCF", "a.urdf")] == ["toml", "mjcf", "mjcf", "urdf"]
    assert format_of("a.txt", "urdf") == "urdf"
    with pytest.raises(InputError, match="cannot tell the format"):
        format_of("a.txt")
    f = tmp_path / "model.txt"
    r = run("export", "rssr", str(f))
    assert r.exit_code == 2 and "cannot tell the format" in r.output and not f.exists()
    assert run("export", "rssr", str(f), "--format", "mjcf").exit_code == 0
    assert mujoco.MjModel.from_xml_path(str(f)).nu == 1
    assert run("export", "rssr", str(tmp_path / "r.toml")).exit_code == 0
    assert (tmp_path / "r.toml").read_text().lstrip().startswith(("name", "#"))
