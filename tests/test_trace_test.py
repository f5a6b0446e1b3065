"""The trace test (kinematics/homotopy/trace_test.py): a complete set of solutions passes, a set with one
solution left out fails; on toy families with known counts, and on the loop formulation's RSSR."""

from __future__ import annotations

import numpy as np
import pytest

import spatialmech as sm
from spatialmech.geometry.tolerances import TRACE_TOL
from spatialmech.kinematics.homotopy.trace_test import trace_test


def _conics(P0, V):
    """Two conics in the plane whose six coefficients each move along ``P0 + lam V``: four
    solutions at a generic member (Bezout)."""

    def F(x, P):
        x0, x1 = x[:, 0], x[:, 1]
        mono = np.stack([x0 * x0, x0 * x1, x1 * x1, x0, x1, np.ones_like(x0)], axis=1)
        dm0 = np.stack([2 * x0, x1, 0 * x0, 1 + 0 * x0, 0 * x0, 0 * x0], axis=1)
        dm1 = np.stack([0 * x0, x0, 2 * x1, 0 * x0, 1 + 0 * x0, 0 * x0], axis=1)
        f = np.stack([(P[:, :6] * mono).sum(1), (P[:, 6:] * mono).sum(1)], axis=1)
        J = np.stack([np.stack([(P[:, :6] * dm0).sum(1), (P[:, :6] * dm1).sum(1)], 1),
                      np.stack([(P[:, 6:] * dm0).sum(1), (P[:, 6:] * dm1).sum(1)], 1)], axis=1)
        dl = np.stack([(V[:6] * mono).sum(1), (V[6:] * mono).sum(1)], axis=1)
        return f, J, dl

    def curve(Y):
        P = P0[None] + Y[:, 2:3] * V[None]
        return F(Y[:, :2], P)

    return curve


def _roots(P):
    """The four intersection points of the two conics (resultant in x1, by numpy)."""
    from itertools import product
    sols = []
    grid = [np.array([a, b]) for a, b in product(np.linspace(-2, 2, 7), repeat=2)]
    for g0 in grid:  # Newton from a grid of complex starts
        x = g0 + 0.3j * g0[::-1]
        for _ in range(60):
            x0, x1 = x
            m = np.array([x0 * x0, x0 * x1, x1 * x1, x0, x1, 1])
            f = np.array([P[:6] @ m, P[6:] @ m])
            d0 = np.array([2 * x0, x1, 0, 1, 0, 0])
            d1 = np.array([0, x0, 2 * x1, 0, 1, 0])
            J = np.array([[P[:6] @ d0, P[:6] @ d1], [P[6:] @ d0, P[6:] @ d1]])
            try:
                x = x - np.linalg.solve(J, f)
            except np.linalg.LinAlgError:
                break
        if np.all(np.isfinite(x)) and np.linalg.norm(f) < 1e-12 and all(np.linalg.norm(x - s) > 1e-8 for s in sols):
            sols.append(x)
    return np.array(sols)


@pytest.fixture(scope="module")
def conics():
    rng = np.random.default_rng(5)
    P0 = rng.normal(size=12) + 1j * rng.normal(size=12)
    P1 = rng.normal(size=12) + 1j * rng.normal(size=12)
    X0, X1 = _roots(P0), _roots(P1)
    assert len(X0) == 4 and len(X1) == 4  # Bezout: the generic count
    return _conics(P0, P1 - P0), X0, X1


def test_all_four_solutions_pass_the_trace_test(conics):
    curve, X0, X1 = conics
    tr = trace_test(curve, X0, np.concatenate([X1[0], [1.0]]), np.random.default_rng(1))
    assert tr.verdict == "passed" and tr.deviation < TRACE_TOL and tr.n_witness >= 1


@pytest.mark.parametrize("drop", [0, 3])
def test_a_missing_solution_fails_the_trace_test(conics, drop):
    curve, X0, X1 = conics
    tr = trace_test(curve, np.delete(X0, drop, axis=0), np.concatenate([X1[0], [1.0]]), np.random.default_rng(1))
    assert tr.verdict == "failed" and tr.deviation > 1e3 * TRACE_TOL


def test_the_work_cap_stops_the_test(conics):
    curve, X0, X1 = conics
    tr = trace_test(curve, X0, np.concatenate([X1[0], [1.0]]), np.random.default_rng(1), max_work=1)
    assert tr.verdict == "capped" and not tr.passed


def test_rssr_all_assembly_modes_proven_complete_by_the_trace_test():
    r = sm.fk("rssr", [30.0], degrees=True, all_solutions=True)
    d = r.to_dict()
    assert d["complete"] is True and d["completeness"].startswith("complete (trace test)")
    assert d["search"]["trace_test"] == "passed" and d["search"]["trace_deviation"] < TRACE_TOL
    assert d["n_real"] == 2 and d["search"]["n_witness"] >= 1
