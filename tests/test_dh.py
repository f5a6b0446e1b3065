"""Serial chains from Denavit-Hartenberg parameters (model/dh.py) and the ready-made PUMA 560."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

import spatialmech as sm
from spatialmech import catalog
from spatialmech.catalog import classic
from spatialmech.errors import InputError
from spatialmech.model.dh import dh_frames, serial_from_dh


def _rot(axis, t):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(t * np.eye(3)["xyz".index(axis)]).as_matrix()
    return T


def _move(axis, s):
    T = np.eye(4)
    T["xyz".index(axis), 3] = s
    return T


def _standard_by_hand(d, a, alpha, theta):
    T = np.eye(4)
    for di, ai, al, th in zip(d, a, alpha, theta, strict=True):
        T = T @ _rot("z", th) @ _move("z", di) @ _move("x", ai) @ _rot("x", al)
    return T


# values on a 1e-3 grid: a chain whose joints are 1e-124 apart is refused (its length scale)
value = st.integers(-1000, 1000).map(lambda k: k / 1000)
rows = st.lists(st.tuples(*[value] * 4), min_size=1, max_size=7)


@settings(max_examples=30, deadline=None)
@given(rows)
def test_standard_frames_are_the_product_of_elementary_transforms(r):
    d, a, alpha, theta = (np.array(c) for c in zip(*r, strict=True))
    F = dh_frames(d, a, alpha, theta)
    assert F.shape == (len(d) + 1, 4, 4)
    assert np.allclose(F[-1], _standard_by_hand(d, a, alpha, theta), atol=1e-13)


@settings(max_examples=30, deadline=None)
@given(rows)
def test_modified_rows_shifted_by_one_give_the_same_chain(r):
    """A standard chain ``Rz Tz Tx Rx`` per row is Craig's ``Rx Tx Rz Tz`` with ``a`` and
    ``alpha`` moved one row down; with the last ``a``, ``alpha`` zero both end frames agree, and
    the mechanisms have the same joint axes and platform point."""
    d, a, alpha, theta = (np.array(c) for c in zip(*r, strict=True))
    a[-1] = alpha[-1] = 0.0
    a_m, alpha_m = np.r_[0.0, a[:-1]], np.r_[0.0, alpha[:-1]]
    F_s = dh_frames(d, a, alpha, theta)
    F_m = dh_frames(d, a_m, alpha_m, theta, convention="modified")
    assert np.allclose(F_s[-1], F_m[-1], atol=1e-12)
    ms = serial_from_dh("s", d=d, a=a, alpha=alpha, theta=theta)
    mm = serial_from_dh("m", d=d, a=a_m, alpha=alpha_m, theta=theta, convention="modified")
    assert np.allclose(ms.platform_point, mm.platform_point, atol=1e-12)
    for js, jm in zip(ms.limbs[0].joints, mm.limbs[0].joints, strict=True):
        u = js.freedoms[0].direction
        assert np.allclose(u, jm.freedoms[0].direction, atol=1e-12)
        off = jm.point - js.point  # the same line: the offset is along the axis
        assert np.linalg.norm(off - (off @ u) * u) < 1e-12


def test_a_prismatic_row_slides_along_its_axis():
    m = serial_from_dh("rp", d=[0.0, 0.2], a=[0.3, 0.0], alpha=[90.0, 0.0], joints="RP", degrees=True)
    assert [j.type for j in m.limbs[0].joints] == ["R", "P"]
    assert np.allclose(m.platform_point, [0.3, -0.2, 0.0], atol=1e-15)
    res = sm.fk(m, [0.0, 0.05])
    assert np.allclose(res.poses[0].p, [0.3, -0.25, 0.0], atol=1e-12)


def test_the_reference_is_added_to_the_dh_values():
    """Joints placed at ``reference``: the mechanism's zero is the DH chain at that value."""
    ref = np.radians(classic.PUMA560_REFERENCE_DEG)
    F = dh_frames(classic.PUMA560_DH["d"], classic.PUMA560_DH["a"], np.radians(classic.PUMA560_DH["alpha"]), ref)
    m = catalog.resolve("puma560")
    assert np.allclose(m.platform_point, F[-1][:3, 3], atol=1e-15)
    for i, j in enumerate(m.limbs[0].joints):
        assert np.allclose(j.freedoms[0].direction, F[i][:3, 2], atol=1e-15)


def test_puma560_every_inverse_solution_reproduces_the_pose_to_round_off():
    """``ik puma560 --all``: 8 solutions proven, each a DH configuration whose end frame is the
    target (forward by the DH product, independent of the engine), residuals at round-off."""
    dh = classic.PUMA560_DH
    alpha, ref = np.radians(dh["alpha"]), np.radians(classic.PUMA560_REFERENCE_DEG)
    q_true = np.array([0.3, -0.4, 0.5, 0.6, -0.7, 0.8])
    F0 = dh_frames(dh["d"], dh["a"], alpha, ref)[-1]
    F1 = dh_frames(dh["d"], dh["a"], alpha, ref + q_true)[-1]
    pose = sm.Pose.from_displacement(F1 @ np.linalg.inv(F0), F0[:3, 3])
    res = sm.ik("puma560", pose, all_solutions=True).to_dict()
    sols = res["limbs"][0]["solutions"]
    assert len(sols) == 8 and res["n_certified"] == 8
    for s in sols:
        q = np.radians(list(s["joints_deg"].values()))
        assert np.allclose(dh_frames(dh["d"], dh["a"], alpha, ref + q)[-1], F1, atol=1e-12)
        assert s["residual"] < 1e-14
    assert any(np.allclose(np.angle(np.exp(1j * (np.radians(list(s["joints_deg"].values())) - q_true))), 0, atol=1e-10)
               for s in sols)


@pytest.mark.parametrize("kw, field", [
    ({"convention": "craig"}, "convention"),
    ({"joints": "RRX"}, "joints"),
    ({"joints": "RR"}, "joints"),
    ({"a": [0.1, 0.2]}, "a"),
    ({"alpha": [0.0, float("nan"), 0.0]}, "alpha"),
    ({"reference": [0.0]}, "reference"),
    ({"d": []}, "d"),
])
def test_bad_dh_input_names_the_field(kw, field):
    args = {"d": [0.0, 0.0, 0.0], "a": [0.1, 0.2, 0.3], "alpha": [0.0, 0.0, 0.0], **kw}
    with pytest.raises(InputError, match=f"^{field}:"):
        serial_from_dh("bad", **args)


PUMA_FILE = """
name = "my-puma"

[dh]
convention = "standard"
d = [0.0, 0.0, 0.15005, 0.4318, 0.0, 0.0]
a = [0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0]
alpha_deg = [90, 0, -90, 90, -90, 0]
reference_deg = [0, 45, 180, 0, 45, 0]
"""


def test_a_dh_file_is_the_ready_made_puma_and_round_trips():
    mine, ref = sm.loads(PUMA_FILE), catalog.resolve("puma560")
    assert mine.name == "my-puma" and mine.actuators == ref.actuators
    assert np.allclose(mine.platform_point, ref.platform_point, atol=1e-15)
    for x, y in zip(mine.limbs[0].joints, ref.limbs[0].joints, strict=True):
        assert np.allclose(x.point, y.point, atol=1e-15)
        assert np.allclose(x.freedoms[0].direction, y.freedoms[0].direction, atol=1e-15)
    back = sm.loads(sm.dumps(mine))  # written in the limbs form
    assert back.actuators == mine.actuators and np.allclose(back.platform_point, mine.platform_point)


@pytest.mark.parametrize("change, field", [
    (("convention = \"standard\"", ""), "dh.convention"),
    (("convention = \"standard\"", "convention = \"craig\""), "dh.convention"),
    (("a = [0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0]", "a = [0.0, 0.4318]"), "dh.a"),
    (("[dh]", "platform_point = [0, 0, 0]\n[dh]"), "platform_point"),
    (("reference_deg = [0, 45, 180, 0, 45, 0]", "joints = \"RRPRRR\"\nreference_deg = [0, 45, 180, 0, 45, 0]"),
     r"dh.reference_deg\[2\]"),
    (("reference_deg = [0, 45, 180, 0, 45, 0]", "joints = \"RRXRRR\""), "dh.joints"),
])
def test_a_bad_dh_file_names_the_field(change, field):
    with pytest.raises(sm.ModelFileError, match=field):
        sm.loads(PUMA_FILE.replace(*change))


def test_a_singular_reference_is_named():
    """Every standard-DH arm is singular at the DH zero (its joint axes are all perpendicular to
    x0): building one there warns, naming ``reference``; the PUMA at Corke's qn does not."""
    args = {"d": classic.PUMA560_DH["d"], "a": classic.PUMA560_DH["a"], "alpha": classic.PUMA560_DH["alpha"],
            "degrees": True}
    with pytest.warns(UserWarning, match="^reference: .* singular"):
        serial_from_dh("zero", **args)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        serial_from_dh("qn", **args, reference=classic.PUMA560_REFERENCE_DEG)
