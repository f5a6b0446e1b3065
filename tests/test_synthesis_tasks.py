"""Task positions: McCarthy convention, named Euler sequences, matrices, files, bad tasks."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech.geometry.rotations import euler_matrix
from spatialmech.synthesis.burmester import burmester_curves
from spatialmech.synthesis.rccc import synthesize_rccc
from spatialmech.synthesis.tasks import (
    MCCARTHY, TaskPositions, get_task, loads_task, mccarthy_matrix, resolve_task, task_names,
)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


angle = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=30, deadline=None)
@given(angle, angle, angle)
def test_mccarthy_matrix_is_rz_lon_ry_minus_lat_rx_az(lon, lat, az):
    """Paper D's orientation: R = Rz(longitude) Ry(-latitude) Rx(azimuth), written out by hand."""
    expected = _rz(lon) @ _ry(-lat) @ _rx(az)
    assert np.allclose(mccarthy_matrix(lon, lat, az), expected, atol=1e-14)


def test_paper_d_table1_task():
    """Table 1 of paper D as the ready-made task (degrees in, radians/matrices inside)."""
    t = get_task("rccc-four-positions")
    assert "rccc-four-positions" in task_names()
    assert t.n == 4 and t.convention.startswith(MCCARTHY)
    assert np.allclose(t.p[3], [-55, -3, 1])
    assert np.allclose(t.R[1], mccarthy_matrix(np.radians(40), np.radians(45), np.radians(20)), atol=1e-15)
    # relative displacement maps the body of position 1 onto position j
    D = t.displacements()
    assert np.allclose(D[2][:3, :3] @ t.R[0], t.R[2], atol=1e-14)
    assert np.allclose(D[2][:3, :3] @ t.p[0] + D[2][:3, 3], t.p[2], atol=1e-12)


TOML = """
name = "mixed"
length_unit = "mm"
[[positions]]
point = [0, 0, 0]
mccarthy_deg = { longitude = 90, latitude = 0, azimuth = 15 }
[[positions]]
point = [-23, 8, 13]
euler = { seq = "ZYX", angles_deg = [40, -45, 20] }
[[positions]]
point = [-42, 9, 13]
matrix = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]
[[positions]]
point = [-55, -3, 1]
euler = { seq = "zyx", angles_deg = [5, -30, 40] }
"""


def test_task_file_with_three_conventions():
    t = loads_task(TOML)
    assert t.n == 4 and t.length_unit == "mm"
    assert np.allclose(t.R[0], mccarthy_matrix(90, 0, 15, degrees=True))
    # intrinsic ZYX (40, -45, 20) is the McCarthy orientation of table 1 position 2
    assert np.allclose(t.R[1], get_task("rccc-four-positions").R[1], atol=1e-14)
    assert np.allclose(t.R[2], _rx(np.pi / 2), atol=1e-14)
    assert np.allclose(t.R[3], euler_matrix("zyx", [5, -30, 40], degrees=True))
    assert "mixed" in t.convention


def test_resolve_task_from_file(tmp_path):
    f = tmp_path / "t.toml"
    f.write_text(TOML)
    assert resolve_task(str(f)).name == "mixed"
    with pytest.raises(KeyError, match="not a file and not a ready-made task"):
        resolve_task("no-such-task")


@pytest.mark.parametrize(
    "text, message",
    [
        (TOML.replace('matrix = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]', 'matrix = [[1, 0, 0], [0, 0, -1], [0, 1, 0.1]]'),
         r"positions\[2\].matrix: not orthonormal"),
        (TOML.replace('matrix = [[1, 0, 0], [0, 0, -1], [0, 1, 0]]', 'matrix = [[1, 0, 0], [0, 0, 1], [0, 1, 0]]'),
         r"positions\[2\].matrix: a reflection"),
        (TOML.replace('seq = "ZYX"', 'seq = "ZYZY"'), r"positions\[1\].euler.seq"),
        (TOML.replace("longitude = 90,", "longitude = 90, colour = 1,"), "unknown field"),
        (TOML.replace("point = [-23, 8, 13]", "point = [-23, 8]"), r"positions\[1\]\.point"),
        (TOML.replace("point = [-23, 8, 13]", "point = [-23, 8, nan]"), r"positions\[1\]\.point"),
        (TOML.replace('euler = { seq = "ZYX", angles_deg = [40, -45, 20] }', ""), r"positions\[1\]: give exactly one"),
    ],
)
def test_bad_task_files_give_one_line_errors_naming_the_field(text, message):
    with pytest.raises(ValueError, match=message):
        loads_task(text)


def test_identical_positions_are_rejected():
    t = get_task("rccc-four-positions")
    R = t.R.copy()
    p = t.p.copy()
    R[2], p[2] = R[0], p[0]
    with pytest.raises(ValueError, match=r"positions\[2\]: identical to positions\[0\]"):
        TaskPositions(R, p)


def test_fewer_than_four_positions_are_rejected_by_four_position_synthesis():
    t = get_task("rccc-four-positions").subset([0, 1, 2])
    with pytest.raises(ValueError, match=r"positions: .*needs exactly 4 positions, got 3"):
        burmester_curves(t)
    with pytest.raises(ValueError, match="needs exactly 4 positions, got 3"):
        synthesize_rccc(t)
    with pytest.raises(ValueError, match="need at least 2 positions"):
        TaskPositions(t.R[:1], t.p[:1])


def test_nan_and_non_orthonormal_matrices_are_rejected():
    t = get_task("rccc-four-positions")
    p = t.p.copy()
    p[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"positions\.p: contains NaN"):
        TaskPositions(t.R, p)
    R = t.R.copy()
    R[3] *= 1.01
    with pytest.raises(ValueError, match=r"positions\[3\].matrix: not orthonormal"):
        TaskPositions(R, t.p)
    with pytest.raises(ValueError, match="latitude: contains NaN"):
        mccarthy_matrix(0, np.nan, 0)


def test_same_orientation_twice_makes_burmester_degenerate():
    """A pure translation between two positions: every direction solves the direction equations."""
    t = get_task("rccc-four-positions")
    R = t.R.copy()
    R[3] = R[1]
    with pytest.raises(ValueError, match="same orientation"):
        burmester_curves(TaskPositions(R, t.p))
