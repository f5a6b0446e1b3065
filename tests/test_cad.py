"""CAD export with units (exchange/cad.py, docs/cad.md): STEP, STL and GLB files whose joint
centres and axes, read back from the files, are the model's at the exported configuration to
1e-9 of its characteristic length, and whose unit is checked on re-import."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

import spatialmech as sm
from spatialmech.analysis.dynamics import actuator_values
from spatialmech.errors import InputError
from spatialmech.kinematics.closure import chain_forward, limb_chains, limb_slices
from spatialmech.model.topology import link_graph

pytest.importorskip("trimesh", reason="the cad extra (trimesh, manifold3d) is not installed")
pytest.importorskip("manifold3d", reason="the cad extra (trimesh, manifold3d) is not installed")
from spatialmech.exchange.cad import cad_links, housing_mesh, housing_solid, read_joint_frames, read_placements

#: Cone half-angles and the fraction of the sphere a housing keeps: outside a cone of half-angle
#: a the solid angle left is 1 - (1 - cos a) / 2 of the sphere's.
HOUSINGS = [(np.pi / 3, 0.75), (np.pi / 2, 0.5), (2 * np.pi / 3, 0.25)]


def _model_joints(mech, config):
    """Per joint name, its centre and (first) axis in the world at ``config``, from the limb
    chains' prefix displacements (independent of the exporter's link placement)."""
    out = {}
    for li, (ch, sl) in enumerate(zip(limb_chains(mech), limb_slices(mech), strict=True)):
        _, _, pre = chain_forward(ch, np.asarray(config.q, float)[sl], prefixes=True)
        base = config.hub(mech.limb_ends[li][0])
        seen = set()
        for k, r in enumerate(r for r in mech.freedom_refs if r.limb == li):
            if r.joint in seen:
                continue
            seen.add(r.joint)
            j = mech.limbs[li].joints[r.joint]
            T = base @ pre[k]
            out[j.name] = (T[:3, :3] @ j.point + T[:3, 3], T[:3, :3] @ j.freedoms[0].direction)
    return out


def _config(mech, pose):
    from spatialmech.api.checks import as_configuration

    return as_configuration(mech, pose, None, True)[0]


def _check_round_trip(mech, config, frames, L):
    want = _model_joints(mech, config)
    graph = link_graph(mech)
    ends = {gj.name: {gj.a, gj.b} for gj in graph.joints}
    seen = {}
    for link, feats in frames["links"].items():
        for f in feats:
            name = f["joint"].split("#")[0]
            assert link in ends[name]
            c, u = want[name]
            u = u / np.linalg.norm(u)
            d = np.asarray(f["centre"]) - c
            if f["role"] == "rod":  # a slide's rod carries its reference point along the axis: on the axis line
                d = d - (d @ u) * u
            assert np.linalg.norm(d) <= 1e-9 * L, (link, name)
            if f["type"] not in ("S", "Sm") and "#" not in f["joint"]:
                # R, P, C: the axis the joint's first freedom turns or slides along; U: its first axis
                assert np.linalg.norm(np.asarray(f["axis"]) - u) <= 1e-9, (link, name)
            seen.setdefault(name, set()).add(link)
    assert seen == ends  # every joint on both of its links


@pytest.mark.parametrize("fmt,unit", [("stl", "mm"), ("stl", "m"), ("glb", "m")])
def test_mesh_round_trip(tmp_path, fmt, unit):
    """STL and GLB: the assembly's joint frames read back at the exported pose, the link files'
    in their own frames; every joint on both of its links."""
    mech = sm.load_model("stewart-6sps")
    pose = ((0.02, -0.01, 1.1), ("ZYX", 5.0, 3.0, -2.0))
    r = sm.export(mech, tmp_path / f"part.{fmt}", pose=pose, degrees=True, unit=unit)
    assert r.unit == unit and r.out.exists()
    if fmt == "stl":
        assert r.out.name == f"part.{unit}.stl"
        assert json.loads((tmp_path / f"part.{unit}.json").read_text())["unit"] == unit
    frames = read_joint_frames(r.out)
    assert frames["unit"] == unit
    _check_round_trip(mech, _config(mech, pose), frames, mech.characteristic_length)
    one = read_joint_frames(r.files[1])  # the ground's file: its frame is the world
    (link, feats), = one["links"].items()
    assert link == "ground" and feats == frames["links"]["ground"]


def _placed(f, T):
    return {**f, "centre": (T[:3, :3] @ np.asarray(f["centre"]) + T[:3, 3]).tolist(),
            "axis": (T[:3, :3] @ np.asarray(f["axis"])).tolist()}


def test_motion_round_trip(tmp_path):
    """Along a motion: the placements file, re-read, puts every link's joints (from its own
    file, in its frame) where the model's forward position at that sample's actuator value puts
    them (the limb chains, independent of the exporter), to 1e-9 of the characteristic length;
    each sample's assembly reads back the same; the link files are written once."""
    mech = sm.load_model("rssr")
    L = mech.characteristic_length
    r = sm.export(mech, tmp_path / "part.stl", actuators=[10.0], along=[70.0], samples=4, degrees=True, unit="mm")
    assert r.samples == 4 and r.out.name == "part.000.mm.stl" and r.to_dict()["samples"] == 4
    motion = read_placements(r.placements)
    assert motion["unit"] == "mm" and [s["assembly"] for s in motion["samples"]] == [
        f"part.{i:03d}.mm.stl" for i in range(4)]
    own = {}
    for name in motion["link_files"].values():
        own.update(read_joint_frames(tmp_path / name)["links"])  # metres, in the link's own frame
    assert set(own) == set(motion["link_files"]) == {"ground", "input.link1", "input.link2", "platform"}
    origin = next(k.origin for k in cad_links(mech) if k.link == mech.output)  # the output link's frame
    for deg, sample in zip(np.linspace(10.0, 70.0, 4), motion["samples"], strict=True):
        assert sample["actuators_deg"]["A0.rot"] == pytest.approx(deg, abs=1e-9)
        placed = {k: [_placed(f, sample["links"][k]) for f in feats] for k, feats in own.items()}
        # the model's closed configuration nearest the output link's placement: at the sample's
        # actuator value (the forward position), and the limb chains put every joint there
        T = sample["links"][mech.output]
        config = _config(mech, sm.Pose(T[:3, :3], T[:3, :3] @ (mech.platform_point - origin) + T[:3, 3]))
        assert np.degrees(actuator_values(mech, config)[0]) == pytest.approx(deg, abs=1e-7)
        _check_round_trip(mech, config, {"links": placed}, L)
        _check_round_trip(mech, config, read_joint_frames(tmp_path / sample["assembly"]), L)


@pytest.mark.slow
def test_step_round_trip_and_header_unit(tmp_path):
    """STEP: joint edges re-read from the assembly at a forward-position configuration, in mm
    and in m (the header's SI unit), the same metres both ways."""
    pytest.importorskip("build123d", reason="the cad extra (build123d) is not installed")
    mech = sm.load_model("rssr")
    r = sm.export(mech, tmp_path / "rssr.step", actuators=[25.0], degrees=True, unit="mm")
    assert "SI_UNIT(.MILLI.,.METRE.)" in r.out.read_text()
    frames = read_joint_frames(r.out)
    fk = sm.fk(mech, [25.0], degrees=True)
    _check_round_trip(mech, _config(mech, fk.poses[0]), frames, mech.characteristic_length)
    (tmp_path / "m").mkdir()
    rm = sm.export(mech, tmp_path / "m" / "rssr.step", actuators=[25.0], degrees=True, unit="m")
    text = rm.out.read_text()
    assert "SI_UNIT($,.METRE.)" in text and ".MILLI." not in text
    back = read_joint_frames(rm.out)
    for link, feats in back["links"].items():
        for a, b in zip(feats, frames["links"][link], strict=True):
            assert np.allclose(a["centre"], b["centre"], rtol=0, atol=1e-9 * mech.characteristic_length)


def test_stl_unit_is_checked(tmp_path):
    """An STL whose name lost its unit, or whose mesh was rescaled, is refused on re-import."""
    import trimesh

    r = sm.export("rssr", tmp_path / "p.stl")
    bare = tmp_path / "p.stl"
    bare.write_bytes(r.out.read_bytes())
    with pytest.raises(InputError, match="unit is not in the file name"):
        read_joint_frames(bare)
    m = trimesh.load_mesh(r.out)
    m.apply_scale(1e-3)  # a millimetre part taken for metres
    m.export(r.out)
    with pytest.raises(InputError, match="bounds"):
        read_joint_frames(r.out)


def test_glb_is_metres_and_cli(tmp_path):
    from click.testing import CliRunner

    from spatialmech.interfaces.cli import cli

    with pytest.raises(InputError, match="GLB is in metres"):
        sm.export("rssr", tmp_path / "p.glb", unit="mm")
    with pytest.raises(InputError, match="only for a CAD export"):
        sm.export("rssr", tmp_path / "p.xml", unit="mm")
    res = CliRunner().invoke(cli, ["export", "three-rps", str(tmp_path / "t.glb"), "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    assert d["file_length_unit"] == "m" and len(d["files"]) == 1 + len(d["links"])
    import jsonschema

    from spatialmech.serialize import unit_rule_violations

    schema = json.loads((Path(sm.__file__).parent / "interfaces" / "schemas" / "export.schema.json").read_text())
    jsonschema.validate(d, schema)
    assert unit_rule_violations(d) == []
    res = CliRunner().invoke(cli, ["export", "rssr", str(tmp_path / "a.glb"), "--along", "40", "--samples", "2", "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.output)
    jsonschema.validate(d, schema)
    assert unit_rule_violations(d) == [] and d["samples"] == 2 and d["out"].endswith("a.000.glb")
    assert [s["assembly"] for s in read_placements(d["placements"])["samples"]] == ["a.000.glb", "a.001.glb"]


@pytest.mark.parametrize("alpha,kept", HOUSINGS)
def test_housing_opening_is_the_cone_limit(alpha, kept):
    """A ball housing keeps the sphere outside the cone the leg may sweep (mesh: within the
    tessellation's 2 %)."""
    import trimesh

    w = np.array([0.0, 0.6, 0.8])
    m = housing_mesh(trimesh, np.array([0.1, 0.2, 0.3]), 0.5, w, alpha)
    full = 4 / 3 * np.pi * 0.5**3
    assert m.is_watertight and m.volume / full == pytest.approx(kept, abs=0.02)
    v = m.vertices - [0.1, 0.2, 0.3]
    far = np.linalg.norm(v, axis=1) > 0.45  # on the sphere: none inside the open cone
    assert np.all(v[far] @ w / np.linalg.norm(v[far], axis=1) <= np.cos(alpha) + 0.03)


@pytest.mark.slow
def test_housing_solid_and_paper_b_cones():
    """The STEP housing's volume is the solid-angle fraction exactly; paper B's 90 deg cones
    open the ground's housings upwards and the platform's downwards (its four S joints' and the
    CU column's universal joint U5's, whose cone is in the platform's frame too)."""
    b3d = pytest.importorskip("build123d", reason="the cad extra (build123d) is not installed")
    for alpha, kept in HOUSINGS:
        h = housing_solid(b3d, np.zeros(3), 2.0, np.array([0.0, 0.0, 1.0]), alpha)
        assert h.volume / (4 / 3 * np.pi * 8.0) == pytest.approx(kept, rel=1e-6)
    links = {k.link: k for k in cad_links(sm.load_model("four-sps-cu"))}
    for link, w, n in (("ground", [0, 0, 1], 4), ("platform", [0, 0, -1], 5)):
        hs = [p for p in links[link].primitives if p[0] == "housing"]
        assert len(hs) == n and all(np.allclose(p[3], w) and p[4] == pytest.approx(np.pi / 2) for p in hs)
    u5 = next(f for f in links["platform"].joints if f.name == "U5")
    assert any(p[0] == "housing" and np.allclose(p[1], u5.centre) for p in links["platform"].primitives)
    assert not any(p[0] == "housing" for p in links["cu.link1"].primitives)  # the column's side: its hubs only


def test_missing_cad_extra_names_it(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "trimesh", None)
    with pytest.raises(InputError, match=r"spatialmech\[cad\]"):
        sm.export("rssr", tmp_path / "p.stl")
