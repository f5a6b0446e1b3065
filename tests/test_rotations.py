"""Named Euler sequences and rigid displacements."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from spatialmech.geometry.rotations import euler_matrix, matrix_euler, rotation_angle


def Rx(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def Ry(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def Rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


angles = st.lists(st.floats(-3, 3), min_size=3, max_size=3)


@given(angles)
def test_papers_sequences_are_products_of_elementary_rotations(a):
    a1, a2, a3 = a
    # paper A: A = Rz(gamma) Rx(alpha) Ry(beta), intrinsic Z-X-Y
    assert np.allclose(euler_matrix("ZXY", [a1, a2, a3]), Rz(a1) @ Rx(a2) @ Ry(a3))
    # paper B: T = Rz(gamma) Ry(beta) Rx(alpha), intrinsic Z-Y-X
    assert np.allclose(euler_matrix("ZYX", [a1, a2, a3]), Rz(a1) @ Ry(a2) @ Rx(a3))
    # paper C: R = Ry(beta) Rx(alpha) Rz(gamma), intrinsic Y-X-Z
    assert np.allclose(euler_matrix("YXZ", [a1, a2, a3]), Ry(a1) @ Rx(a2) @ Rz(a3))
    # extrinsic is the reversed product
    assert np.allclose(euler_matrix("zxy", [a1, a2, a3]), Ry(a3) @ Rx(a2) @ Rz(a1))


def test_degrees_are_explicit_and_round_trip():
    R = euler_matrix("ZXY", [-50, 6, 60], degrees=True)
    assert np.allclose(matrix_euler("ZXY", R, degrees=True), [-50, 6, 60])
    assert rotation_angle(euler_matrix("ZXY", [0, 0, 30], degrees=True)) == pytest.approx(np.pi / 6)


@pytest.mark.parametrize("seq", ["ZX", "ZZX", "ZxY", "abc", 3])
def test_bad_sequences(seq):
    with pytest.raises(ValueError, match="seq"):
        euler_matrix(seq, [0, 0, 0])


def test_bad_angles():
    with pytest.raises(ValueError, match="angles: contains NaN"):
        euler_matrix("ZXY", [0, np.nan, 0])
    with pytest.raises(ValueError, match=r"angles: expected shape"):
        euler_matrix("ZXY", [0, 0])


@pytest.mark.parametrize("seq, angles", [("ZYX", (90.0, -90.0, 0.0)), ("ZYX", (-30.0, 90.0, 40.0)),
                                         ("ZXZ", (20.0, 0.0, 35.0)), ("xyz", (10.0, 90.0, -70.0))])
def test_gimbal_lock_gives_angles_that_rebuild_the_matrix_without_a_warning(seq, angles):
    """At gimbal lock the outer angles are not separately defined: the third is set to zero and
    the angles still give back the matrix; scipy's warning does not reach the user's output."""
    import warnings

    R = euler_matrix(seq, angles, degrees=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        a = matrix_euler(seq, R, degrees=True)
    assert abs(a[2]) < 1e-9
    assert np.max(np.abs(euler_matrix(seq, a, degrees=True) - R)) < 1e-12
