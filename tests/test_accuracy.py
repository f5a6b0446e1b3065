"""Accuracy (issue 28): first-order sensitivities against finite differences of the exact forward
position, the three estimates agreeing for small tolerances and parting for large ones, the
mobility loss of overconstrained designs, the command line."""

import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech import catalog
from spatialmech.analysis import accuracy as acc
from spatialmech.interfaces.cli import cli

STEWART_POSE = ([0.05, -0.03, 1.02], ("ZYX", 5, -3, 4))


@pytest.mark.parametrize("name, pose", [("stewart-6sps", STEWART_POSE), ("three-rps", ([0, 0, 0.33], None))])
def test_first_order_matches_finite_differences_of_the_exact_forward_position(name, pose):
    mech = catalog.build(name)
    config = sm.ik(mech, pose, degrees=True).config
    params = acc.error_parameters(mech, acc.ErrorBudget(actuator=1e-5, point=1e-5))
    G, inconsistency, rows = acc.sensitivity(mech, config, params)
    assert rows == 6 and inconsistency == 0.0
    h = 1e-6
    checked = 0
    for i in range(0, len(params), 3):  # every third parameter: actuators, points and axes
        e = np.zeros(len(params))
        e[i] = h
        fd = (acc._exact(mech, config, params, e) - acc._exact(mech, config, params, -e)) / (2 * h)
        scale = max(1.0, float(np.max(np.abs(G[:, i]))))
        assert np.max(np.abs(fd - G[:, i])) / scale < 1e-6, (params[i].name, fd, G[:, i])
        checked += 1
    assert checked >= 10 and {p.kind for p in params} == {"actuator", "point", "axis"}


def test_geometric_errors_vanish_at_the_reference_configuration():
    """The product-of-exponentials model: perturbed joints at the reference, actuators zeroed there."""
    r = sm.accuracy("stewart-6sps", tolerances={"geometry": 1e-4}, samples=0, mobility_check=False)
    assert np.max(np.abs(r.analysis.G)) < 1e-12


def test_the_three_estimates_agree_for_small_tolerances():
    t = 1e-6
    r = sm.accuracy("stewart-6sps", STEWART_POSE, degrees=True, samples=200, seed=3,
                    tolerances={"actuator": t, "geometry": t, "clearance": t})
    a = r.analysis
    assert a.mc_failures == 0 and a.mc_errors.shape == (200, 6)
    # each exact sample is the first-order prediction of the same draw, to second order
    rng = np.random.default_rng(3)
    tol = np.array([p.tolerance for p in a.params])
    E = np.array([rng.uniform(-1.0, 1.0, len(a.params)) * tol for _ in range(200)])
    pred = E @ a.G.T
    assert np.max(np.abs(a.mc_errors - pred)) < 1e-4 * np.max(a.worst_case)
    # the spread lies within the worst-case box, its std matches the first-order covariance
    assert np.all(np.abs(a.mc_errors) <= a.worst_case)
    assert np.all(np.abs(r.std_monte_carlo / r.std_first_order - 1) < 0.25)  # 200 samples: ~5 % sampling error
    assert np.allclose(a.exact_at_worst, a.worst_case, rtol=1e-4)
    d = r.to_dict()
    assert d["monte_carlo"]["within_worst_case"] and d["mobility_under_tolerances"]["loses_mobility"] is False
    json.dumps(d, allow_nan=False)


def test_first_order_and_exact_part_for_large_tolerances():
    r = sm.accuracy("stewart-6sps", STEWART_POSE, degrees=True, samples=0, mobility_check=False,
                    tolerances={"actuator": 0.03, "geometry": 0.03})
    ratio = r.analysis.exact_at_worst / r.analysis.worst_case
    assert np.max(np.abs(ratio - 1)) > 0.05  # the linearisation is off by more than 5 % somewhere


@pytest.mark.parametrize("name, mode", [("bennett", None), ("three-rrr-sm", "R1")])
def test_overconstrained_designs_lose_their_mobility(name, mode):
    mech = catalog.build(name)
    if mode:
        mech = mech.in_mode(mode)
    params = acc.error_parameters(mech, acc.ErrorBudget(point=1e-5))
    b = acc.mobility_breakdown(mech, params)
    assert b.loses_mobility and b.nominal_dof == 1 and b.perturbed_dof == 0
    # the break is where the lost singular value passes the rank tolerance: rate x scale = tol
    assert b.breaks_at_scale is not None and b.rate is not None
    assert b.rate * b.breaks_at_scale == pytest.approx(b.rank_tolerance, rel=0.05)


@pytest.mark.parametrize("name", ["stewart-6sps", "four-sps-cu", "three-rps"])
def test_designs_that_are_not_overconstrained_keep_their_mobility(name):
    mech = catalog.build(name)
    b = acc.mobility_breakdown(mech, acc.error_parameters(mech, acc.ErrorBudget(point=1e-5)))
    assert not b.loses_mobility and b.perturbed_dof == b.nominal_dof


def test_bad_tolerances_are_refused():
    with pytest.raises(sm.InputError, match=r"tolerances\.geometry"):
        sm.accuracy("stewart-6sps", tolerances={"geometry": -1.0})
    with pytest.raises(sm.InputError, match="unknown key"):
        sm.accuracy("stewart-6sps", tolerances={"points": 1e-5})
    with pytest.raises(sm.InputError, match="every tolerance is zero"):
        sm.accuracy("stewart-6sps", tolerances={})
    with pytest.raises(sm.InputError, match="mode"):
        sm.accuracy("three-rrr-sm", tolerances={"geometry": 1e-5})


@pytest.mark.slow
def test_command_line_text_json_and_plot(tmp_path):
    r = CliRunner().invoke(cli, ["accuracy", "bennett", "--geometry-tolerance", "1e-5", "--samples", "0"],
                           catch_exceptions=False)
    assert r.exit_code == 0 and "OVERCONSTRAINED" in r.output
    png = tmp_path / "acc.png"
    r = CliRunner().invoke(cli, ["accuracy", "three-rps", "--xyz", "0", "0", "0.33", "--actuator-error", "1e-5",
                                 "--clearance", "1e-5", "--samples", "10", "--plot", str(png), "--json"],
                           catch_exceptions=False)
    assert r.exit_code == 0 and png.stat().st_size > 1000
    d = json.loads(r.output)
    assert d["command"] == "accuracy" and d["monte_carlo"]["n_converged"] == 10
    assert {p["kind"] for p in d["parameters"]} == {"actuator", "clearance"}


def test_worst_case_equals_the_linear_programme_over_the_box():
    """sum |G_ci| t_i is the maximum of the linearised error over the box: scipy's LP agrees."""
    from scipy.optimize import linprog

    r = sm.accuracy("three-rps", ([0, 0, 0.33], None), samples=0, mobility_check=False,
                    tolerances={"actuator": 1e-5, "geometry": 2e-5, "clearance": 1e-5})
    a = r.analysis
    t = np.array([p.tolerance for p in a.params])
    for c in range(6):
        lp = linprog(-a.G[c], bounds=list(zip(-t, t, strict=True)), method="highs")
        assert lp.status == 0
        assert -lp.fun == pytest.approx(a.worst_case[c], rel=1e-9, abs=1e-18)
        assert a.G[c] @ a.worst_vertex[c] == pytest.approx(a.worst_case[c], rel=1e-12, abs=1e-18)


@pytest.mark.slow
def test_to_dict_is_the_payload_of_the_command():
    r = CliRunner().invoke(cli, ["accuracy", "three-rps", "--xyz", "0", "0", "0.33", "--actuator-error", "1e-5",
                                 "--geometry-tolerance", "1e-5", "--samples", "6", "--seed", "2", "--json"],
                           catch_exceptions=False)
    doc = json.loads(r.output)
    payload = {k: v for k, v in doc.items() if k not in ("schema_version", "command", "model", "length_unit", "plot")}
    facade = sm.accuracy("three-rps", ([0, 0, 0.33], None), samples=6, seed=2,
                         tolerances={"actuator": 1e-5, "geometry": 1e-5, "clearance": 0.0})
    assert json.loads(json.dumps(facade.to_dict(), allow_nan=False)) == payload


@pytest.mark.parametrize("name, pose", [("delta", ([0.02, 0.01, -0.33], None)), ("spatial-six-bar", None)])
def test_graph_mechanism_first_order_matches_finite_differences(name, pose):
    """Graph mechanisms (internal bodies): the loop-closure sensitivity against central finite
    differences of the exact re-assembly of perturbed models (1e-6 relative), every parameter kind;
    the three estimates agree for small tolerances and the design keeps its mobility."""
    mech = catalog.build(name)
    config = sm.ik(mech, pose).config if pose is not None else sm.statics(mech, wrench=[1, 0, 0, 0, 0, 0]).config
    params = acc.error_parameters(mech, acc.ErrorBudget(actuator=1e-5, point=1e-5, clearance=1e-5))
    G, inconsistency, _ = acc.sensitivity(mech, config, params)
    assert inconsistency < 1e-9
    h = 1e-6
    kinds = set()
    for i in range(0, len(params), max(1, len(params) // 12)):
        if params[i].kind == "clearance":
            continue  # play enters every estimate through its first-order effect
        e = np.zeros(len(params))
        e[i] = h
        fd = (acc._exact(mech, config, params, e) - acc._exact(mech, config, params, -e)) / (2 * h)
        scale = max(1.0, float(np.max(np.abs(G[:, i]))))
        assert np.max(np.abs(fd - G[:, i])) / scale < 1e-6, (params[i].name, fd, G[:, i])
        kinds.add(params[i].kind)
    assert {"actuator", "point"} <= kinds
    t = 1e-6
    r = sm.accuracy(mech, config=config, samples=30, seed=1, tolerances={"actuator": t, "geometry": t, "clearance": t})
    a = r.analysis
    floor = 1e-4 * float(np.max(a.worst_case))  # second order, in the components the design cannot move to first
    assert a.mc_failures == 0 and np.all(np.abs(a.mc_errors) <= a.worst_case * (1 + 1e-6) + floor)
    assert np.allclose(a.exact_at_worst, a.worst_case, rtol=1e-4, atol=floor)
    assert r.to_dict()["mobility_under_tolerances"]["loses_mobility"] is False
