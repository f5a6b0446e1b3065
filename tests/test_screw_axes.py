"""Motion names that show screws (issue 30 item 6): helical systems are named H with pitch and
axis, and a 1-DOF output's instantaneous screw is in the mobility text and JSON."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech.analysis.mobility import motion_type
from spatialmech.catalog import build
from spatialmech.geometry.screw_axes import principal_screws
from spatialmech.interfaces.cli import cli

Z = np.array([0.0, 0.0, 1.0])


def _rot(v, k, t):
    k = k / np.linalg.norm(k)
    return v * np.cos(t) + np.cross(k, v) * np.sin(t) + k * np.dot(k, v) * (1 - np.cos(t))


def misassembled_3upu(axis: str = "z", twist_deg: float = 30.0) -> sm.Mechanism:
    """Tsai's 3-UPU (rb 0.3, rp 0.1, h 0.3) with each platform U turned by ``twist_deg`` about
    the vertical (``"z"``) or about the leg's first base axis (``"a"``)."""
    rb, rp, h = 0.3, 0.1, 0.3
    limbs = []
    for i, ang in enumerate(np.deg2rad([90.0, 210.0, 330.0])):
        r = np.array([np.cos(ang), np.sin(ang), 0.0])
        B, A = rb * r, rp * r + h * Z
        a = np.array([-np.sin(ang), np.cos(ang), 0.0])
        d = A - B
        L = float(np.linalg.norm(d))
        b = np.cross(d, a) / np.linalg.norm(np.cross(d, a))
        k = Z if axis == "z" else a
        a2, b2 = _rot(a, k, np.deg2rad(twist_deg)), _rot(b, k, np.deg2rad(twist_deg))
        limbs.append(sm.Limb(f"leg{i + 1}", [sm.U(f"UB{i + 1}", B, [a, b]),
                                             sm.P(f"L{i + 1}", B, d / L, actuated=True, offset=L),
                                             sm.U(f"UA{i + 1}", A, [b2, a2])]))
    return sm.Mechanism("misassembled-3upu", limbs, platform_point=h * Z)


def test_misassembled_3upu_is_helical_not_3r():
    r = sm.mobility(misassembled_3upu("z"))
    assert r.dof == 3 and r.motion_class == "3H" and r.motion == "3H"
    kinds = [(a.kind, a.multiplicity) for a in r.screw_axes]
    assert kinds == [("H", 1), ("H", 2)]
    pitches = sorted(a.pitch_m_per_rad for a in r.screw_axes)
    # principal pitches of the free system (reference values of this model, to 1e-3 m/rad)
    assert pitches == pytest.approx([-1.990, 0.8253], abs=1e-3)
    # the pitch form's eigenvalues sum to the trace of the system's w . v form
    assert r.screw_axes[0].direction == (0.0, 0.0, 1.0)


def test_turn_about_the_base_axis_keeps_rotations():
    r = sm.mobility(misassembled_3upu("a"))
    assert r.motion_class == "2R1T"
    assert [a.kind for a in r.screw_axes] == ["R", "T"] and r.screw_axes[0].multiplicity == 2


def test_tsai_3upu_and_3rps_unchanged():
    assert sm.mobility(build("three-upu")).motion == "TxTyTz"
    r = sm.mobility(build("three-rps"))
    assert r.motion == "RxRyTz" and [a.kind for a in r.screw_axes] == ["R", "T"]


def test_planar_4r_instantaneous_screw_is_a_vertical_rotation_axis():
    r = sm.mobility(build("planar-4r"))
    (ax,) = r.screw_axes
    assert ax.kind == "R" and ax.pitch_m_per_rad == 0.0 and ax.direction == (0.0, 0.0, 1.0)
    assert ax.point_m is not None and ax.point_m[2] == 0.0


def test_single_helical_screw_reference():
    # a screw of pitch 0.02 m/rad about the axis along y through (1, 0, 0)
    w, p, h = np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]), 0.02
    s = np.r_[w, np.cross(p, w) + h * w]
    (ax,) = principal_screws([-3.0 * s])
    assert ax.kind == "H" and ax.pitch_m_per_rad == pytest.approx(h, abs=1e-12)
    assert ax.direction == (0.0, 1.0, 0.0) and np.allclose(ax.point_m, p, atol=1e-12)
    assert motion_type([s], [0, 0, 0]) == ("1H", "1H")


def test_cylindrical_pair_is_a_rotation_and_a_translation():
    s = np.r_[Z, 0.5 * Z]  # a screw plus the translation along its axis: a C pair
    axes = principal_screws([s, np.r_[0, 0, 0, Z]])
    assert [a.kind for a in axes] == ["R", "T"] and axes[0].pitch_m_per_rad == 0.0


def test_basis_and_sign_do_not_change_the_answer():
    T = np.array(sm.mobility(misassembled_3upu("z")).constraint_wrenches)
    from spatialmech.geometry import screws as sc
    V = sc.reciprocal_basis(T)
    rng = np.random.default_rng(3)
    a0 = principal_screws(V)
    for _ in range(3):
        a1 = principal_screws(rng.normal(size=(3, 3)) @ V)
        assert [x.kind for x in a1] == [x.kind for x in a0]
        for x, y in zip(a0, a1, strict=True):
            assert np.allclose(x.direction, y.direction, atol=1e-9)
            assert np.allclose(x.point_m, y.point_m, atol=1e-9)
            assert x.pitch_m_per_rad == pytest.approx(y.pitch_m_per_rad, abs=1e-9)


def test_mobility_text_and_json_give_the_screw(tmp_path):
    run = CliRunner().invoke(cli, ["mobility", "bennett"], catch_exceptions=False)
    assert "instantaneous screw:" in run.output and "H(p = " in run.output and "m/rad) about the axis through" in run.output
    doc = json.loads(CliRunner().invoke(cli, ["mobility", "planar-4r", "--json"], catch_exceptions=False).output)
    (ax,) = doc["modes"][0]["screw_axes"]
    assert ax["kind"] == "R" and ax["pitch_len_per_deg"] == 0.0 and ax["direction"] == [0.0, 0.0, 1.0]
