"""The mechanism model built from Python: validation with field names."""

import numpy as np
import pytest

import spatialmech as sm
from spatialmech.model import make_joint


def test_build_a_mechanism_in_a_few_lines():
    z, x = [0, 0, 1], [1, 0, 0]
    mech = sm.Mechanism(
        "my-rssr",
        limbs=[
            sm.Limb("in", [sm.R("A0", [0, 0, 0], z, actuated=True), sm.S("A1", [0.3, 0, 0]), sm.S("B1", [0, 1, -0.1])]),
            sm.Limb("out", [sm.R("B0", [0, 1, 0.5], x)]),
        ],
        platform_point=[0, 1, -0.1],
    )
    r = sm.mobility(mech)
    assert (r.dof, r.dof_instantaneous, r.xi) == (1, 1, 1)
    assert mech.actuators == ("A0.rot",)
    assert mech.freedom("A0").id == "A0.rot"


@pytest.mark.parametrize(
    "kwargs, msg",
    [
        (dict(type="Q", axis=[0, 0, 1]), "type: unknown joint type 'Q'"),
        (dict(type="R", axis=[0, 0, 0]), "axis: zero vector"),
        (dict(type="R", axis=[0, 0, 2]), "axis: not a unit vector"),
        (dict(type="R", axis=[0, 1]), r"axis: expected shape \(3,\)"),
        (dict(type="R", axis=[0, np.nan, 1]), "axis: contains NaN"),
        (dict(type="R"), "axis: required"),
        (dict(type="U", axes=[[1, 0, 0], [0.6, 0.8, 0]]), "must be perpendicular"),
        (dict(type="S", axes=[[1, 0, 0], [0, 1, 0], [0, 1, 0]]), "mutually perpendicular"),
        (dict(type="C", axis=[0, 0, 1], actuated=["spin"]), "actuated: unknown freedom 'spin'"),
        (dict(type="P", axis=[0, 0, 1], limits=[0.4, 0.1]), "lower limit"),
        (dict(type="R", axis=[0, 0, 1], point=[0, 0, np.inf]), "point: contains NaN or infinity"),
    ],
)
def test_joint_errors_name_the_field(kwargs, msg):
    t = kwargs.pop("type")
    with pytest.raises(ValueError, match=msg) as e:
        make_joint(t, "J", field="limbs[0].joints[2]", **kwargs)
    assert str(e.value).startswith("limbs[0].joints[2].")


def test_normalize_flag_accepts_printed_axes():
    j = make_joint("C", "C1", axis=[0.745, 0.485, 0.458], normalize=True)
    assert np.linalg.norm(j.freedoms[0].direction) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="not a unit vector"):
        make_joint("C", "C1", axis=[0.745, 0.485, 0.458])


def test_a_freedom_screw_is_computed_once_and_handed_out_as_a_copy():
    """``Freedom.screw`` is kept after the first call (issue 29: building many linkages from
    shared joints); a caller that writes into the array it got changes nothing."""
    from spatialmech.geometry.screws import axis_screw

    f = make_joint("C", "C1", point=[0.1, 0.2, 0.3], axis=[0.0, 0.6, 0.8]).freedoms[0]
    s = f.screw
    np.testing.assert_array_equal(s, axis_screw(f.direction, f.point))
    s[:] = 0.0
    np.testing.assert_array_equal(f.screw, axis_screw(f.direction, f.point))
    assert f.screw is not f.screw


def test_mechanism_errors():
    def j(n):
        return sm.R(n, [0, 0, 0], [0, 0, 1])
    with pytest.raises(ValueError, match="duplicate joint name 'A'"):
        sm.Mechanism("m", [sm.Limb("a", [j("A")]), sm.Limb("b", [j("A")])])
    with pytest.raises(ValueError, match="duplicate limb name"):
        sm.Mechanism("m", [sm.Limb("a", [j("A")]), sm.Limb("a", [j("B")])])
    with pytest.raises(ValueError, match="has no joints"):
        sm.Limb("a", [])
    with pytest.raises(KeyError, match=r"unknown freedom 'Z\.rot'"):
        sm.Mechanism("m", [sm.Limb("a", [j("A")])], aliases={"x": "Z.rot"})
    with pytest.raises(ValueError, match="is not a lockable freedom"):
        sm.Mechanism("m", [sm.Limb("a", [j("A")])], modes=[sm.Mode("m1", ("A",))])


def test_pose_validation():
    with pytest.raises(ValueError, match="not a rotation matrix"):
        sm.Pose(np.diag([1.0, 1.0, -1.0]), [0, 0, 0], "bad")
    p = sm.Pose.from_euler("ZXY", [10, 20, 30], [1, 2, 3], degrees=True)
    D = p.displacement([1, 0, 0])
    assert np.allclose(D[:3, :3] @ [1, 0, 0] + D[:3, 3], [1, 2, 3])


def test_a_rotation_typed_with_six_decimals_becomes_its_nearest_rotation():
    import warnings

    R = sm.Pose.from_euler("ZXY", [10, 20, 30], [0, 0, 0], degrees=True).R
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.array_equal(sm.Pose(R, [0, 0, 0]).R, R)  # a rotation to round-off: untouched, no warning
    typed = np.round(R, 6)
    with pytest.warns(UserWarning, match=r"orthonormal only to .*nearest rotation is used"):
        p = sm.Pose(typed, [0, 0, 0], "typed")
    assert np.max(np.abs(p.R @ p.R.T - np.eye(3))) < 1e-15 and np.linalg.det(p.R) > 0
    assert np.max(np.abs(p.R - R)) < 1e-6 and np.max(np.abs(p.R - typed)) < 1e-6
    # the nearest rotation: no other rotation is closer to the typed matrix (Frobenius norm)
    from scipy.spatial.transform import Rotation

    best = np.linalg.norm(p.R - typed)
    for v in np.random.default_rng(1).normal(size=(200, 3)):  # rotations within 1e-6 rad of it
        other = p.R @ Rotation.from_rotvec(1e-6 * v / np.linalg.norm(v)).as_matrix()
        assert best <= np.linalg.norm(other - typed) + 1e-15
    with pytest.raises(ValueError, match="not a rotation matrix"):
        sm.Pose(np.round(R, 4) + 1e-4, [0, 0, 0])  # beyond rounding: refused, as before


def test_modes_enumerated_when_not_declared():
    Y = [0, 1, 0]
    mech = sm.Mechanism(
        "lockable",
        [sm.Limb("a", [sm.R("A", [0, 0, 0], Y, lockable=True), sm.R("B", [1, 0, 0], Y, lockable=True)])],
    )
    assert [m.name for m in mech.all_modes()] == ["all-locked", "A.rot", "B.rot", "A.rot+B.rot"]
    assert sm.mobility(mech, "A.rot+B.rot").dof == 2
    assert sm.mobility(mech, "all-locked").dof == 0
