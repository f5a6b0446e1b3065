"""The screen's batched judgement (issue 29) against its reference path.

- :func:`~spatialmech.synthesis.five_cs.cs_configurations` (vectorised, no SciPy) gives the
  joint values of :func:`~spatialmech.synthesis.five_cs.cs_configuration` (SciPy's rotations,
  pose by pose) to 1e-12, on the candidates of paper A's pool and on random poses (hypothesis);
- ``judge_candidate(batched=True)`` (the positions' stages in one compiled call, the defect
  analysis without its mobility check, its circuit stage in the compiled loops) gives the
  verdict rows of ``batched=False`` (the position-by-position reference, the tracker's Python
  loop) to 1e-10, on the first 30 candidates of paper A's screen (DJ-sign rejections and
  circuit judgements) and on a usable and a two-circuit candidate;
- the compiled circuit stage gives the whole defect analysis of the Python loops on those two.
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from spatialmech.geometry.rotations import rotvec_matrix
from spatialmech.model.mechanism import Pose
from spatialmech.synthesis.five_cs import cs_configuration, cs_configurations
from spatialmech.synthesis.screening import (candidate_linkage, candidate_sets, dyad_pool, judge_candidate,
                                             row_differences)

pytestmark = pytest.mark.slow

#: A usable candidate and one rejected by its circuits (two of them): tests/test_screening.py.
USABLE = [20, 36, 64, 67, 115]
TWO_CIRCUITS = [27, 67, 70, 122, 128]


@pytest.fixture(scope="module")
def pool(paper_a_cs_family):
    return dyad_pool(dataclasses.replace(paper_a_cs_family, picks=()), 0.5)


def ball_rotations(mech, q):
    """Each S joint's rotation ``exp(A q_ball)`` (its rotation vector is ambiguous at pi)."""
    out = []
    for k, lb in enumerate(mech.limbs):
        A = np.array([f.direction for f in lb.joints[1].freedoms]).T
        out.append(rotvec_matrix(A @ q[5 * k + 2:5 * k + 5]))
    return np.array(out)


def test_closed_forms_agree_at_the_positions_of_paper_a_candidates(pool):
    sets, _ = candidate_sets(pool, 20, seed=0)
    worst = 0.0
    for c in [*sets, USABLE, TWO_CIRCUITS]:
        mech = candidate_linkage(pool, c)
        fast = cs_configurations(mech)
        assert fast is not None and len(fast) == len(mech.positions)
        for P, b in zip(mech.positions, fast, strict=True):
            a = cs_configuration(mech, P)
            worst = max(worst, float(np.max(np.abs(a.q - b.q))), float(np.max(np.abs(a.D - b.D))))
    assert worst < 1e-12, worst  # measured 1.1e-14


@given(rv=st.lists(st.floats(-3.0, 3.0), min_size=3, max_size=3), p=st.lists(st.floats(-1.0, 1.0), min_size=3,
                                                                          max_size=3))
def test_closed_forms_agree_at_random_poses(pool, rv, p):
    mech = candidate_linkage(pool, USABLE)
    P0 = mech.positions[0]
    pose = Pose(rotvec_matrix(np.array(rv)) @ P0.R, P0.p + np.array(p), "random")
    a = cs_configuration(mech, pose)
    (b,) = cs_configurations(mech, [pose])
    for k in range(5):  # C rotation and slide: the same numbers
        assert abs(a.q[5 * k] - b.q[5 * k]) < 1e-12 and abs(a.q[5 * k + 1] - b.q[5 * k + 1]) < 1e-12
    # the S rotations: the same rotation (a rotation vector of angle pi has two spellings)
    assert np.max(np.abs(ball_rotations(mech, a.q) - ball_rotations(mech, b.q))) < 1e-12


def test_the_batched_judgement_gives_the_reference_verdicts(pool):
    sets, _ = candidate_sets(pool, 30, seed=0)
    cands = [*(list(map(int, c)) for c in sets), USABLE, TWO_CIRCUITS]
    stages = set()
    for n, c in enumerate(cands):
        ref = judge_candidate(pool, c, candidate=n, batched=False).row()
        got = judge_candidate(pool, c, candidate=n, batched=True).row()
        assert row_differences(ref, got, 1e-10) == [], (c, ref, got)
        stages.add((ref["rejected_by"], ref["circuit_defect"], ref["usable"]))
    # the set holds DJ-sign rejections, circuit judgements with a circuit defect and a usable one
    assert ("dj_signs", None, False) in stages and ("circuits", True, False) in stages and (None, False, True) in stages


def test_the_compiled_circuit_stage_gives_the_reference_analysis(pool, monkeypatch):
    """The circuit stage's compiled loops (the tracker's loop, the positions placed on the traced
    circuits: ``arc_on_curve``'s corrections and ``pose_distance``'s Brent search, the path's
    sigmas) against the Python loops (``python_loop()``): the whole defect analysis of a usable
    and a two-circuit candidate, every number to 1e-10 (measured: equal bit for bit)."""
    from spatialmech.analysis.defects import defect_analysis
    from spatialmech.kinematics import compiled
    from spatialmech.kinematics.tracking import python_loop
    from tests.test_tracking_compiled import assert_same_document

    searches = []
    search = compiled.pose_search
    monkeypatch.setattr(compiled, "pose_search", lambda *a: searches.append(a) or search(*a))
    for c in (USABLE, TWO_CIRCUITS):
        mech = candidate_linkage(pool, c)
        n0 = len(searches)
        got = defect_analysis(mech, check_dof=False).to_dict()
        with python_loop():
            ref = defect_analysis(mech, check_dof=False).to_dict()
        assert_same_document(got, ref)
        # the two-circuit candidate's positions 5-7 measured from the first circuit by the search
        assert (len(searches) > n0) == (c is TWO_CIRCUITS)
