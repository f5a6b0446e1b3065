"""Task coordinates (issue 11): the model's description, the default choice, and the solve that
holds the given coordinates and finds the parasitic ones."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech import catalog
from spatialmech.errors import InputError
from spatialmech.kinematics.backend import closure_residual
from spatialmech.kinematics.task import coordinate_map, default_task, pose_from_task, solve_task, task_values
from spatialmech.model import schema
from spatialmech.model.task import TaskCoordinates
from spatialmech.results import SolveStatus


@pytest.mark.parametrize("name, given", [
    ("three-rps", ("z", "a2", "a3")),
    ("three-upu", ("x", "y", "z")),
    ("delta", ("x", "y", "z")),
    ("delta-ruu", ("x", "y", "z")),
    ("four-sps-cu", ("z", "a1", "a2", "a3")),
    ("stewart-6sps", ("x", "y", "z", "a1", "a2", "a3")),
    ("spatial-six-bar", ("a2",)),
    ("rssr", ("a3",)),
])
def test_default_task_follows_the_output_twist_space(name, given):
    assert default_task(catalog.build(name)).given == given


def test_task_coordinates_are_checked():
    assert TaskCoordinates(("a3", "z", "a2")).given == ("z", "a2", "a3")
    for bad, msg in [(("q",), "unknown task coordinate 'q'"), (("z", "z"), "repeats"), ((), "at least one")]:
        with pytest.raises(InputError, match=msg):
            TaskCoordinates(bad)
    with pytest.raises(InputError, match="task_euler"):
        TaskCoordinates(("z",), "ZZY")


def test_task_in_the_file_round_trips_and_is_used():
    m = catalog.build("three-rps")
    text = schema.dumps(m).replace("platform_point", 'task = ["z", "a2", "a3"]\ntask_euler = "XYZ"\nplatform_point', 1)
    m2 = schema.loads(text)
    assert m2.task == TaskCoordinates(("z", "a2", "a3"), "XYZ")
    assert default_task(m2) is m2.task
    assert schema.loads(schema.dumps(m2)).task == m2.task


@settings(max_examples=15, deadline=None)
@given(st.lists(st.floats(-3.0, 3.0), min_size=6, max_size=6), st.sampled_from(["ZYX", "XYZ", "ZXZ", "zyx"]))
def test_coordinate_map_is_the_derivative_of_the_pose(v, seq):
    """V = C d(values)/dt: compare with the finite-difference twist of pose_from_task."""
    m = catalog.build("three-rps")
    v = np.array(v) * np.r_[0.1, 0.1, 0.1, 0.4, 0.4, 0.4]
    if seq in ("ZXZ",) and abs(np.sin(v[4])) < 0.05:
        v[4] += 0.3  # away from the sequence's own singularity
    from spatialmech.geometry.rotations import inverse_transform, log_transform

    C = coordinate_map(v, seq)
    h = 1e-6
    for k in range(6):
        e = np.zeros(6)
        e[k] = h
        dD = pose_from_task(m, v + e, seq) @ inverse_transform(pose_from_task(m, v - e, seq))
        assert np.allclose(log_transform(dD) / (2 * h), C[:, k], atol=1e-6)
    assert np.allclose(task_values(m, pose_from_task(m, v, seq), seq)[:3], v[:3], atol=1e-12)


@pytest.mark.parametrize("name, given", [
    ("three-rps", {"z": 0.33, "a2": np.radians(8.0), "a3": np.radians(-5.0)}),
    ("three-upu", {"x": 0.02, "y": -0.01, "z": 0.31}),
    ("delta", {"x": 0.02, "y": -0.01, "z": -0.33}),
    ("four-sps-cu", {"z": 0.11, "a1": np.radians(10.0), "a2": np.radians(5.0), "a3": np.radians(-4.0)}),
])
def test_solve_task_holds_the_given_and_closes(name, given):
    m = catalog.build(name)
    r = solve_task(m, given)
    assert r.converged and r.status == SolveStatus.CONVERGED
    assert np.max(np.abs(closure_residual(m, r.config))) < 1e-9
    v = task_values(m, r.config.D, r.task.euler)
    for k, x in given.items():
        assert abs(v[list(r.values).index(k)] - x) < 1e-12
    assert set(r.given) == set(given) and set(r.solved).isdisjoint(given)
    if name in ("three-upu", "delta"):  # translational: no parasitic rotation
        assert max(abs(r.values[a]) for a in ("a1", "a2", "a3")) < 1e-9


def test_solving_a_coordinate_that_is_not_given_is_refused():
    m = catalog.build("three-rps")
    with pytest.raises(InputError, match=r"given\.x: x is solved"):
        solve_task(m, {"x": 0.1})


def test_an_unreachable_task_pose_reports_its_status():
    m = catalog.build("delta")  # arms and rods of fixed length cannot reach 2 m below the base
    r = solve_task(m, {"x": 0.0, "y": 0.0, "z": -2.0}, max_iter=30)
    assert not r.converged and r.status in (SolveStatus.MAX_ITER, SolveStatus.STALLED)
    assert r.residual > 1e-3
