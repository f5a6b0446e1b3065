"""Inverse dynamics (issue 28): at rest it is the statics with gravity (two independent routes:
the closure multipliers against the complete Jacobian with the loads carried through the limbs),
the actuators' power is the rate of change of the energy (finite differences along a motion), the
mass properties of the model file, and the command line's JSON."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from click.testing import CliRunner
from jsonschema import Draft202012Validator
from referencing import Registry, Resource

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis import dynamics as dy
from spatialmech.analysis.statics import joint_reactions, statics
from spatialmech.api.checks import as_configuration
from spatialmech.errors import InputError
from spatialmech.interfaces.cli import cli
from spatialmech.interfaces.common import load_schema
from spatialmech.model import schema
from spatialmech.model.inertia import spatial_inertia_matrix
from spatialmech.serialize import unit_rule_violations

G = np.array([0.0, 0.0, -9.81])
AT_REST = [("three-rps", None), ("delta-ruu", None), ("stewart-6sps", None),
           ("four-sps-cu", ([0, 0, 0.12], ("ZYX", 0.3, -0.4, 0.5)))]


@pytest.mark.parametrize("name, pose", AT_REST)
def test_dynamics_at_rest_equals_the_statics_with_gravity(name, pose):
    mech = catalog.resolve(name)
    masses, _ = dy.mass_properties(mech, 2700.0)
    c, _ = as_configuration(mech, pose, None, False)
    F = np.array([1.0, 2.0, -30.0, 0.1, 0.2, 0.3])
    zero = np.zeros(len(mech.actuators))
    d = dy.inverse_dynamics(mech, dy.state_from_actuators(mech, c, zero, zero), masses, G, F)
    s = statics(mech, c, F, loads=dy.gravity_loads(mech, c, masses, G))
    assert s.balanced and d.residual < 1e-12
    scale = np.max(np.abs(s.efforts))
    np.testing.assert_allclose(d.efforts, s.efforts, rtol=0, atol=1e-10 * scale)
    reactions = joint_reactions(mech, c, d.limb_wrenches, d.by_actuator, dy.distal_wrenches(mech, d))
    worst = max(float(np.max(np.abs(r.wrench))) for r in s.reactions)
    for a, b in zip(reactions, s.reactions, strict=True):
        np.testing.assert_allclose(a.wrench, b.wrench, rtol=0, atol=1e-10 * worst)
    # the API says the same
    r = sm.inverse_dynamics(mech, pose, wrench=F, density=2700.0)
    np.testing.assert_allclose(r.efforts[0], sm.statics(mech, pose, wrench=F, gravity=G, density=2700.0).analysis.efforts,
                               rtol=0, atol=1e-10 * scale)


def _energy(mech, masses, res) -> float:
    """Kinetic plus potential energy (J) at a result's state."""
    e = 0.0
    place = dy.link_placements(mech, res.state.config)
    for name, V in res.link_twists.items():
        li = masses[name]
        if li.mass_kg == 0:
            continue
        moved = li.moved(place[name])
        h = spatial_inertia_matrix(moved) @ V
        e += 0.5 * float(h[:3] @ V[3:] + h[3:] @ V[:3]) - li.mass_kg * float(G @ moved.com_m)
    return e


@pytest.mark.parametrize("name", ["three-rps", "delta-ruu"])
def test_dynamics_power_is_the_rate_of_change_of_the_energy(name):
    """Sum of effort x actuator rate = d(kinetic + potential energy)/dt, by a central difference
    of step 1e-4 s (error O(h^2)) along the quintic law."""
    mech = catalog.resolve(name)
    masses, _ = dy.mass_properties(mech, 2700.0)
    c0 = sm.Configuration.reference(mech)
    a0 = dy.actuator_values(mech, c0)
    a1 = a0 + np.array([0.03, -0.02, 0.01]) * (1.0 if name == "three-rps" else 5.0)
    h, T = 1e-4, 0.5
    for t in (0.15, 0.3):
        times = np.array([t - h, t, t + h])
        u = times / T
        s = 10 * u**3 - 15 * u**4 + 6 * u**5
        sd = (30 * u**2 - 60 * u**3 + 30 * u**4) / T
        sdd = (60 * u - 180 * u**2 + 120 * u**3) / T**2
        vals = a0 + s[:, None] * (a1 - a0)
        configs = dy.follow_actuators(mech, c0, vals)
        res = [dy.inverse_dynamics(mech, dy.state_from_actuators(mech, c, sd[i] * (a1 - a0), sdd[i] * (a1 - a0)),
                                   masses, G) for i, c in enumerate(configs)]
        dE = (_energy(mech, masses, res[2]) - _energy(mech, masses, res[0])) / (2 * h)
        power = float(res[1].efforts @ (sd[1] * (a1 - a0)))
        assert abs(dE - power) <= 1e-6 * max(abs(power), 1e-3), (t, dE, power)


def test_masses_in_the_model_file_and_their_checks():
    mech = catalog.resolve("three-rps")
    d = schema.to_dict(mech)
    d["masses"] = [{"link": "platform", "mass_kg": 2.0, "com_m": [0, 0, 0.3],
                    "inertia_kg_m2": [[0.02, 0, 0], [0, 0.02, 0], [0, 0, 0.03]]}]
    d["density_kg_m3"] = 1000.0
    m2 = schema.loads(schema.dumps(schema.from_dict(d)))
    masses, source = dy.mass_properties(m2)
    assert source["platform"] == "file" and masses["platform"].mass_kg == 2.0
    assert source["leg1.link1"] == "density" and masses["leg1.link1"].mass_kg > 0
    bad = dict(d, masses=[dict(d["masses"][0], inertia_kg_m2=[[1, 0, 0], [0, 1, 0], [0, 0, 3]])])
    with pytest.raises(sm.ModelFileError, match="triangle"):
        schema.from_dict(bad)
    with pytest.raises(sm.ModelFileError, match="not a moving link"):
        schema.from_dict(dict(d, masses=[dict(d["masses"][0], link="nowhere")]))
    with pytest.raises(InputError, match="no masses"):
        sm.statics("three-rps", wrench=[0] * 6, gravity=G)


@pytest.fixture(scope="module")
def registry():
    common = load_schema("common")
    return Registry().with_resource(common["$id"], Resource.from_contents(common))


@pytest.mark.parametrize("args, command", [
    (["dynamics", "delta-ruu", "--to", "10,5,0", "--samples", "3", "--density", "2700"], "dynamics"),
    (["dynamics", "three-rps", "--density", "2700", "--wrench", "0,0,-10,0,0,0"], "dynamics"),
    (["statics", "three-rps", "--gravity", "0,0,-9.81", "--density", "2700"], "statics"),
    (["statics", "three-rps", "--wrench", "0,0,-100,0,0,0", "--along", "0.36,0.34,0.35", "--samples", "3"],
     "statics along"),
])
def test_dynamics_json_follows_its_schema(args, command, registry, tmp_path):
    out = CliRunner().invoke(cli, [*args, "--json"], catch_exceptions=False)
    assert out.exit_code == 0, out.output
    doc = json.loads(out.output)
    assert doc["command"] == command
    errors = list(Draft202012Validator(load_schema(command), registry=registry).iter_errors(doc))
    assert not errors, [(list(e.absolute_path), e.message[:200]) for e in errors[:3]]
    assert unit_rule_violations(doc) == []


def test_dynamics_plot(tmp_path):
    path = tmp_path / "d.png"
    out = CliRunner().invoke(cli, ["dynamics", "three-rps", "--to", "0.36,0.34,0.35", "--samples", "3", "--density",
                                   "2700", "--plot", str(path)], catch_exceptions=False)
    assert out.exit_code == 0, out.output
    assert path.stat().st_size > 1000 and "L1.slide [N]" in out.output


def test_dynamics_masses_go_into_the_mujoco_export(tmp_path):
    import mujoco

    d = schema.to_dict(catalog.resolve("three-rps"))
    d["density_kg_m3"] = 2700.0
    path = tmp_path / "rps.toml"
    path.write_text(schema.dumps(schema.from_dict(d)))
    sm.export(path, tmp_path / "rps.xml")
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "rps.xml"))
    masses, _ = dy.mass_properties(sm.load_model(path))
    for name, li in masses.items():
        bid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
        assert m.body_mass[bid] == pytest.approx(li.mass_kg, rel=1e-12)
    sm.export("three-rps", tmp_path / "plain.xml")  # no masses in the model: the default inertias
    assert "fullinertia" not in (tmp_path / "plain.xml").read_text()


def _moved(mech, R: np.ndarray, p: np.ndarray, masses: dict):
    """The same mechanism, with its masses, displaced rigidly by ``(R, p)`` in the world."""
    from dataclasses import replace

    from spatialmech.model.mechanism import Limb

    def pt(x):
        return R @ x + p

    limbs = []
    for limb in mech.limbs:
        joints = [replace(j, point=pt(j.point), freedoms=tuple(replace(f, point=pt(f.point), direction=R @ f.direction)
                                                               for f in j.freedoms)) for j in limb.joints]
        limbs.append(Limb(limb.name, tuple(joints)))
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return replace(mech, limbs=tuple(limbs), platform_point=pt(mech.platform_point), positions=(),
                   inertias={n: li.moved(T) for n, li in masses.items()})


@given(q=st.lists(st.floats(-1, 1), min_size=4, max_size=4), p=st.lists(st.floats(-2, 2), min_size=3, max_size=3),
       rates=st.lists(st.floats(-0.5, 0.5), min_size=3, max_size=3),
       accs=st.lists(st.floats(-3, 3), min_size=3, max_size=3))
@settings(max_examples=15, deadline=None)
def test_dynamics_do_not_depend_on_where_the_world_frame_is(q, p, rates, accs):
    """The efforts of a mechanism moved rigidly with its gravity, masses and external wrench are
    the same: the moments about the origin, the momenta and the bias terms are bookkept right."""
    from scipy.spatial.transform import Rotation

    quat = np.asarray(q)
    assume(np.linalg.norm(quat) > 0.1)
    R = Rotation.from_quat(quat / np.linalg.norm(quat)).as_matrix()
    mech = catalog.resolve("three-rps")
    masses, _ = dy.mass_properties(mech, 2700.0)
    F = np.array([1.0, -2.0, 3.0, 0.2, -0.1, 0.3])
    moved = _moved(mech, R, np.asarray(p), masses)
    out = []
    for m, g, w in ((mech, G, F), (moved, R @ G, np.r_[R @ F[:3], R @ F[3:] + np.cross(p, R @ F[:3])])):
        c = sm.Configuration.reference(m)
        state = dy.state_from_actuators(m, c, rates, accs)
        out.append(dy.inverse_dynamics(m, state, m.inertias or masses, g, w).efforts)
    np.testing.assert_allclose(out[1], out[0], rtol=0, atol=1e-9 * np.max(np.abs(out[0])))


def test_dynamics_bad_input_is_named():
    with pytest.raises(InputError, match=r"sample 0 \(t = 0 s\): a direct singularity"):
        sm.inverse_dynamics("four-sps-cu", density=2700)  # the reference pose is singular
    with pytest.raises(InputError, match="length_unit: dynamics needs a model in metres"):
        sm.inverse_dynamics("five-cs-3", density=1)
    with pytest.raises(InputError, match="values: expected one row of 3"):
        sm.inverse_dynamics("three-rps", density=2700, values=[[1, 2]])
    with pytest.raises(InputError, match="density"):
        sm.inverse_dynamics("three-rps", density=-1)
    with pytest.raises(InputError, match="to/values"):
        sm.inverse_dynamics("three-rps", density=2700, to=[0.3] * 3, values=[[0.3] * 3])


def test_statics_along_poses_is_the_statics_at_each_pose():
    poses = [sm.Pose.from_euler("ZYX", [0, 5, 5], [0, 0, 0.33], degrees=True),
             sm.Pose.from_euler("ZYX", [0, -5, 3], [0, 0, 0.31], degrees=True)]
    F = [0, 0, -100, 0, 0, 0]
    p = sm.statics_along("three-rps", poses=poses, wrench=F, gravity=G, density=2700)
    for k, pose in enumerate(poses):
        s = sm.statics("three-rps", pose, wrench=F, gravity=G, density=2700)
        np.testing.assert_allclose(p.efforts[k], list(s.efforts.values()), rtol=1e-12)
    with pytest.raises(InputError, match="exactly one"):
        sm.statics_along("three-rps", poses=poses, to=[0.3] * 3)
