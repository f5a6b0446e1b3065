"""The block-elimination Newton step (kinematics/compiled/kernels_blocks.py) is lstsq's minimum-norm step,
or declines; and the compiled forward solve that uses it still equals the Python reference."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spatialmech import catalog
from spatialmech.kinematics import backend, compiled
from spatialmech.kinematics.closure import Configuration, active_mask
from spatialmech.kinematics.backend import correct
from spatialmech.kinematics.motion import generic_configuration

pytestmark = pytest.mark.skipif(not compiled.AVAILABLE, reason="numba is not available")


def _system(rng, ms, s, deficient, identity_hubs):
    """A closure-shaped system: limb k's own columns only in its six rows, ``s`` shared columns."""
    K = len(ms)
    A = np.zeros((6 * K, sum(ms) + s))
    lo, hi, c = [], [], 0
    for k, m in enumerate(ms):
        J = rng.normal(size=(6, m))
        if deficient[k] and m > 1:  # a dependent column: an idle freedom such as an S-P-S leg's spin
            J[:, -1] = J[:, :-1] @ rng.normal(size=m - 1)
        A[6 * k:6 * k + 6, c:c + m] = J
        lo.append(c)
        c += m
        hi.append(c)
        if s:
            A[6 * k:6 * k + 6, sum(ms):] = -np.eye(6)[:, :s] if identity_hubs else rng.normal(size=(6, s))
    return A, np.array(lo), np.array(hi), sum(ms)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), K=st.integers(1, 6), shared=st.booleans(), identity=st.booleans())
def test_block_step_is_lstsq_minimum_norm_step_or_declines(seed, K, shared, identity):
    rng = np.random.default_rng(seed)
    ms = [int(m) for m in rng.integers(1, 9, size=K)]
    deficient = rng.random(K) < 0.5
    A, lo, hi, ns0 = _system(rng, ms, 6 if shared else 0, deficient, identity)
    b = rng.normal(size=A.shape[0])
    x = compiled.minnorm_blocks(A, b, lo, hi, ns0)
    ok = x is not None
    ref = np.linalg.lstsq(A, b, rcond=None)[0]
    ranks = [np.linalg.matrix_rank(A[6 * k:6 * k + 6, lo[k]:hi[k]]) for k in range(K)]
    if not shared:  # limbs decouple: always taken, any rank, consistent or not
        assert ok
    elif sum(6 - r for r in ranks) != 6:  # the reduced system is not square: the general solver decides
        assert not ok
    if ok:
        scale = max(1.0, float(np.abs(ref).max()))
        assert np.abs(x - ref).max() <= 1e-10 * scale * np.linalg.cond(A[:, np.abs(A).sum(0) > 0])


def test_stewart_legs_are_taken_and_the_idle_spins_get_no_step():
    """Six S-P-S legs with their slides held (rank 5 each: the spin about the leg) and the platform
    twist shared: the reduced system is the six leg lines, square; the step is lstsq's to 1e-13."""
    mech = catalog.build("stewart-6sps")
    mask = active_mask(mech)
    act = [i for i, r in enumerate(mech.freedom_refs) if r.freedom.actuated]
    mask[act] = False
    cfg = generic_configuration(mech, seed=2, step=0.2)
    A, r = compiled.closure_jacobian(mech, cfg, active=mask)
    lo = np.arange(6) * 6
    x = compiled.minnorm_blocks(A, -r + 1e-3, lo, lo + 6, 36)
    assert x is not None
    ref = np.linalg.lstsq(A, -r + 1e-3, rcond=None)[0]
    assert np.abs(x - ref).max() < 1e-13 * max(1.0, np.abs(ref).max())


def test_overconstrained_and_singular_systems_decline():
    rng = np.random.default_rng(5)
    # two full-rank 6x6 limbs sharing a 6-twist: 0 reduced rows for 6 unknowns -> not square
    A, lo, hi, ns0 = _system(rng, [6, 6], 6, [False, False], True)
    assert compiled.minnorm_blocks(A, rng.normal(size=12), lo, hi, ns0) is None
    # a limb block whose rank is unclear (a column nearly, not exactly, dependent)
    A, lo, hi, ns0 = _system(rng, [6], 0, [True], True)
    A[:, 5] += 1e-10 * rng.normal(size=6)
    assert compiled.minnorm_blocks(A, rng.normal(size=6), lo, hi, ns0) is None


@pytest.mark.parametrize("seed", range(6))
def test_bordered_block_step_solves_the_square_system_or_declines(seed):
    """The hyperplane corrector's step (five 5-column limbs sharing a twist, the tangent as the
    border row): the solution of the square ``[A; t] x = [b; 0]``; declined when a limb's own
    columns are dependent (its step is then not a function of the shared twist)."""
    rng = np.random.default_rng(seed)
    A, lo, hi, ns0 = _system(rng, [5] * 5, 6, [False] * 5, seed % 2 == 0)
    t, b = rng.normal(size=A.shape[1]), rng.normal(size=A.shape[0])
    x = compiled.minnorm_blocks(A, b, lo, hi, ns0, border=(t, 0.0))
    M = np.vstack([A, t])
    ref = np.linalg.solve(M, np.append(b, 0.0))
    assert x is not None
    assert np.abs(x - ref).max() <= 1e-12 * np.linalg.cond(M) * max(1.0, np.abs(ref).max())
    A, lo, hi, ns0 = _system(rng, [5] * 5, 6, [True] + [False] * 4, False)
    assert compiled.minnorm_blocks(A, b, lo, hi, ns0, border=(t, 0.0)) is None


@pytest.mark.parametrize("name", ["stewart-6sps", "three-rps", "four-sps-cu"])
def test_compiled_forward_solve_equals_the_python_reference(name):
    """Forward position from the reference with the actuators moved: the compiled correct (block
    steps) and the Python one (np.linalg.lstsq) give the same configuration to 1e-10."""
    mech = catalog.build(name)
    goal = generic_configuration(mech, seed=3, step=0.2)
    act = [i for i, r in enumerate(mech.freedom_refs) if r.freedom.actuated]
    mask = active_mask(mech)
    mask[act] = False
    start = Configuration.reference(mech)
    q0 = start.q.copy()
    q0[act] = goal.q[act]
    seed = start.with_q(q0)
    fast = correct(mech, seed, active=mask)
    with backend.python_reference():
        ref = correct(mech, seed, active=mask)
    assert fast.converged == ref.converged and fast.iterations == ref.iterations
    assert np.abs(fast.config.q - ref.config.q).max() < 1e-10
    assert np.abs(fast.config.D - ref.config.D).max() < 1e-10
