"""Forward position of the spherical 3-RRR wrist proven complete (issue 27): the passive joints
eliminated, three quadrics in the platform's quaternion, Bezout's bound 8 attained
(kinematics/closed_forms/spherical_rrr_forward.py)."""

from __future__ import annotations

import json
import re
import shutil
import subprocess

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import spatialmech as sm
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.closed_forms import spherical_rrr_forward as srf
from spatialmech.kinematics.closed_forms.projective_quadrics import solve_projective_quadrics
from spatialmech.kinematics.dispatch import forward_engine

WRIST_INPUTS = [0.3, -0.2, 0.5]  # rad: R1, R4, R7 (as tests/test_fk_flags.py)


@pytest.fixture(scope="module")
def wrist():
    return sm.load_model("three-rrr-sm").in_mode("R1+R4+R7")


@pytest.fixture(scope="module")
def wrist_all(wrist):
    return sm.fk(wrist, WRIST_INPUTS, all_solutions=True)


def _signed_permutation(R) -> bool:
    A = np.abs(np.asarray(R))
    return bool(np.allclose(np.sort(A, axis=1), [[0, 0, 1]] * 3, atol=1e-9) and np.allclose(A.sum(axis=0), 1, atol=1e-9))


# ------------------------------------------------------------------ the Agile-Eye type wrist (paper C)
def test_the_wrist_is_recognised_geometrically_and_answered_by_the_closed_form(wrist):
    assert forward_engine(wrist) == "closed-form"
    renamed = sm.Mechanism("my-wrist", wrist.limbs, platform_point=wrist.platform_point)  # not by its name
    assert srf.wrist_of(renamed) is not None
    assert srf.wrist_of(sm.load_model("rssr")) is None and srf.wrist_of(sm.load_model("three-rps")) is None


def test_wrist_four_modes_and_four_input_independent_flagged_proven(wrist_all):
    r = wrist_all
    assert r.engine == "closed-form" and r.complete
    assert r.completeness.startswith("Bezout's bound attained") and "8 distinct nonsingular points" in r.completeness
    e = r.answer.endpoints
    assert (e.n_real, e.n_complex, e.n_singular, e.n_at_infinity, e.n_generic) == (8, 0, 0, 0, 8)
    modes = r.modes
    assert len(modes) == 8 and r.answer.n_input_independent == 4
    ii = [m for m in modes if m.input_independent]
    assert all(_signed_permutation(m.pose.R) for m in ii)  # each leg's platform axis on its base axis
    assert all(m.flags.inverse_singular_actuators == ("R1.rot", "R4.rot", "R7.rot") for m in ii)
    real = [m for m in modes if m.assembly_mode]
    assert len(real) == 4 and not any(_signed_permutation(m.pose.R) for m in real)
    assert all(m.residual < 1e-10 and not m.forward_singular for m in modes)
    # paper C's closed form (eq 21, both limb assemblies) gives the inputs back at the 4 modes
    from spatialmech.kinematics.closed_forms.spherical_rrr import actuator_angles_from_matrix

    for m in real:
        th = actuator_angles_from_matrix(m.pose.R)
        d = np.angle(np.exp(1j * (th - np.array(WRIST_INPUTS))))
        assert np.all(np.minimum(np.abs(d), np.pi - np.abs(d)) < 1e-9)  # theta or theta + pi per limb


@pytest.mark.slow
def test_the_multistart_finds_the_same_eight_orientations(wrist, wrist_all):
    ms = sm.fk(wrist, WRIST_INPUTS, all_solutions=True, method="multistart", seeds=200, seed=0)
    ours = [m.pose.R for m in wrist_all.modes]
    assert len(ms.modes) == len(ours) == 8
    for m in ms.modes:
        assert min(np.linalg.norm(m.pose.R - R) for R in ours) < 1e-8


def test_text_and_json_say_complete_proven():
    r = CliRunner().invoke(cli, ["fk", "three-rrr-sm", "--actuators", "10,20,30", "--all"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    assert "complete (proven): Bezout's bound attained" in r.stdout
    assert "4 real assembly modes, 4 input-independent" in r.stdout.splitlines()[0]
    r = CliRunner().invoke(cli, ["fk", "three-rrr-sm", "--actuators", "10,20,30", "--all", "--json"],
                           catch_exceptions=False)
    doc = json.loads(r.stdout)
    assert doc["engine"] == "closed-form" and doc["complete"] is True
    assert doc["n_real"] == 8 and doc["n_complex"] == 0 and doc["n_input_independent"] == 4
    r = CliRunner().invoke(cli, ["fk", "three-rrr-sm", "--actuators", "10,20,30", "--all", "--seeds", "5"])
    assert r.exit_code != 0 and "takes no starts" in r.output


# ------------------------------------------------------------------ random wrists: fk(ik) round trips
def _rot(axis, t):
    return Rotation.from_rotvec(np.asarray(axis) * t).as_matrix()


def _random_wrist(seed: int):
    """A random wrist that closes at a random rotation ``R0``: per limb random unit base and
    middle axes and joint angles, the platform axis and angle those of the rotation left,
    ``Rot(p, t3) = (Rot(a, t1) Rot(m, t2))^-1 R0``; a random actuated joint per limb, random
    centre.  Returns the mechanism, ``R0`` and the actuated joints' angles there."""
    rng = np.random.default_rng(seed)
    o = rng.normal(size=3)
    R0 = Rotation.random(random_state=int(rng.integers(2**31))).as_matrix()
    limbs, angles = [], []
    for i in range(3):
        a, m = (v / np.linalg.norm(v) for v in rng.normal(size=(2, 3)))
        t1, t2 = rng.uniform(-np.pi, np.pi, 2)
        rv = Rotation.from_matrix((_rot(a, t1) @ _rot(m, t2)).T @ R0).as_rotvec()
        p, t3 = rv / np.linalg.norm(rv), float(np.linalg.norm(rv))
        j = int(rng.integers(3))
        ax = [a, m, p]
        limbs.append(sm.Limb(f"l{i}", [sm.R(f"J{i}{k}", o + 0.3 * (k + 1) * ax[k], ax[k], actuated=k == j)
                                        for k in range(3)]))
        angles.append([t1, t2, t3][j])
    return sm.Mechanism("random-wrist", limbs, platform_point=o + rng.normal(size=3)), R0, np.array(angles)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.integers(0, 10**6))
def test_fk_of_ik_returns_the_pose_on_random_wrists(seed):
    """A random wrist built to close at a random rotation with known joint angles (base, middle
    or platform joint actuated), then the forward solve from those actuator angles: proven
    complete, and the rotation is among its solutions; every solution satisfies the limbs."""
    mech, R0, angles = _random_wrist(seed)
    w = srf.wrist_of(mech)
    assert w is not None
    rots, counts, proven, _ = srf.forward_rotations(w, angles)
    assert proven and counts[4] == 8 and sum(counts[:4]) == 8 and counts[0] % 2 == 0
    assert min(np.linalg.norm(R - R0) for R in rots) < 1e-9
    U, V, K = w.conditions(angles)
    for R in rots:
        assert np.allclose(np.einsum("ij,jk,ik->i", U, R, V), K, atol=1e-10)
        assert np.allclose(R.T @ R, np.eye(3), atol=1e-12) and np.linalg.det(R) > 0


def test_a_random_wrist_through_sm_fk_lifts_every_rotation():
    mech, R0, angles = _random_wrist(5)
    r = sm.fk(mech, angles, all_solutions=True)
    assert r.engine == "closed-form" and r.complete
    assert any(np.allclose(m.pose.R, R0, atol=1e-9) for m in r.modes)
    assert all(m.residual < 1e-10 for m in r.modes)


def test_bezout_count_of_two_plane_conics():
    """The solver on its own: two conics in P^2 meet in 4 points (x^2 + y^2 = 5 z^2 and
    x y = 2 z^2: x = +-1, +-2 at z = 1, all real); x^2 + y^2 = 3 z^2 and x y = 2 z^2: 4 complex."""
    A = np.zeros((2, 3, 3))
    A[0] = np.diag([1.0, 1.0, -5.0])
    A[1, 0, 1] = A[1, 1, 0] = 0.5
    A[1, 2, 2] = -2.0
    s = solve_projective_quadrics(A)
    assert s.complete and s.n_paths == 4 and s.real.all()
    assert sorted(round(float((y[0] / y[2]).real), 9) for y in s.Y) == [-2.0, -1.0, 1.0, 2.0]
    A[0, 2, 2] = -3.0
    s = solve_projective_quadrics(A)
    assert s.complete and not s.real.any()


# ------------------------------------------------------------------ PHCpack cross-check
@pytest.mark.skipif(shutil.which("phc") is None, reason="PHCpack (Debian phcpack) not installed")
def test_phcpack_finds_the_same_eight_rotations(wrist, tmp_path):
    """PHCpack's blackbox on the same three quaternion quadrics with the patch w = 1: 8 regular
    solutions, the same real rotations."""
    w = srf.wrist_of(wrist)
    U, V, K = w.conditions(np.array(WRIST_INPUTS))
    names = ["qw", "qx", "qy", "qz"]  # not i, j: PHCpack reads those as the imaginary unit
    eqs = []
    for n in range(3):
        A = srf.quaternion_quadric(U[n], V[n], K[n])
        eqs.append(" ".join(f"{(A[a, b] if a == b else 2 * A[a, b]):+.17e}*{names[a]}*{names[b]}"
                            for a in range(4) for b in range(a, 4)) + ";")
    rng = np.random.default_rng(2)
    c = rng.normal(size=4)
    eqs.append(" ".join(f"{c[a]:+.17e}*{names[a]}" for a in range(4)) + " - 1;")
    (tmp_path / "w.in").write_text("4\n" + "\n".join(eqs) + "\n")
    subprocess.run(["phc", "-b", str(tmp_path / "w.in"), str(tmp_path / "w.out")], stdin=subprocess.DEVNULL,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=120, check=True)
    out = (tmp_path / "w.out").read_text()
    assert int(re.findall(r"Number of regular solutions\s*:\s*(\d+)", out)[-1]) == 8
    phc = []
    for block in out[out.rfind("THE SOLUTIONS"):].split("solution ")[1:]:
        vals = {k: complex(float(x), float(y)) for k, x, y in re.findall(r"\b(q[wxyz]) :\s+(\S+)\s+(\S+)", block)}
        if len(vals) == 4 and "real regular" in block:
            w_, i_, j_, k_ = np.array([vals[k] for k in names]).real
            phc.append(Rotation.from_quat([i_, j_, k_, w_]).as_matrix())
    rots, counts, proven, _ = srf.forward_rotations(w, np.array(WRIST_INPUTS))
    assert proven and len(phc) == len(rots) == counts[0] == 8
    for R in phc:
        assert min(np.linalg.norm(R - Q) for Q in rots) < 1e-8


def test_a_continuum_is_not_proven():
    """Two equal conics meet in a curve: the end points are singular or lost, never 'complete'."""
    A = np.zeros((2, 3, 3))
    A[0] = A[1] = np.diag([1.0, 1.0, -5.0])
    s = solve_projective_quadrics(A)
    assert not s.complete


@pytest.mark.parametrize("args", [["three-rrr-sm", "--actuators", "10,20,30"], ["bennett", "--actuators", "40"],
                                  ["five-cs-3", "--actuators", "10"]])
def test_closed_form_json_validates_against_the_schema(args):
    from jsonschema import Draft202012Validator
    from referencing import Registry, Resource

    from spatialmech.interfaces.common import load_schema

    common = load_schema("common")
    registry = Registry().with_resource(common["$id"], Resource.from_contents(common))
    r = CliRunner().invoke(cli, ["fk", *args, "--all", "--json"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    errors = list(Draft202012Validator(load_schema("fk"), registry=registry).iter_errors(doc))
    assert not errors, [(list(e.absolute_path), e.message[:300]) for e in errors[:5]]
    assert doc["engine"] == "closed-form" and doc["complete"] is True
    assert all(s["endpoint"] == "real" for s in doc["solutions"])
