"""Issue 26, one front door for position analysis: the engine of forward position is chosen in
one place (kinematics/dispatch.py), ``sm.fk`` / ``sm.ik`` / ``sm.jacobian`` go through it and the
``fk`` / ``ik`` / ``jacobian`` commands call only them, so the command line and the API cannot
drift apart again.

Before: ``fk four-sps-cu ... --all --method multistart`` ran the general multi-start (3 modes)
while ``sm.fk(..., method="multistart")`` ran the closed form (4 modes); ``sm.fk`` ignored
``seeds`` on the homotopy path; examples/stewart_forward_all.py printed "0 starts; a multi-start
search cannot prove completeness" after a proven homotopy run."""

from __future__ import annotations

import ast
import json
import runpy
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics import dispatch

ROOT = Path(__file__).parent.parent
LEGS = [0.2167, 0.2390, 0.2273, 0.2069]
LEGS_TEXT = ",".join(map(str, LEGS))
#: Keys of the CLI's envelope, and of timings / caches that differ between two runs.
ENVELOPE = {"schema_version", "command", "model", "length_unit"}
VOLATILE = {"elapsed_s", "generic_elapsed_s", "generic_cached", "trace_elapsed_s", "certify_elapsed_s"}


def _strip(x):
    if isinstance(x, dict):
        return {k: _strip(v) for k, v in x.items() if k not in VOLATILE}
    if isinstance(x, list):
        return [_strip(v) for v in x]
    return x


def cli_payload(*args: str) -> dict:
    r = CliRunner().invoke(cli, [*args, "--json"], catch_exceptions=False)
    assert r.exit_code == 0, r.output
    doc = json.loads(r.stdout)
    return _strip({k: v for k, v in doc.items() if k not in ENVELOPE})


def api_payload(result) -> dict:
    return _strip(json.loads(json.dumps(result.to_dict(), allow_nan=False)))


def _modes(payload: dict) -> list:
    return sorted(tuple(np.round(s["pose"]["position_len"] + s["pose"]["euler_deg"], 6)) for s in payload["solutions"])


# ------------------------------------------------------------------ (a) --method multistart means one thing
@pytest.mark.slow
def test_multistart_is_the_general_search_on_the_cli_and_the_api():
    cli_doc = cli_payload("fk", "four-sps-cu", "--actuators", LEGS_TEXT, "--all", "--method", "multistart", "--seeds", "60")
    r = sm.fk("four-sps-cu", LEGS, all_solutions=True, method="multistart", seeds=60)
    assert r.engine == cli_doc["engine"] == "multistart" and not r.closed_form and not r.complete
    assert _modes(api_payload(r)) == _modes(cli_doc) and api_payload(r) == cli_doc
    # "auto" keeps the closed form on this layout, on both sides, and asks for it by name too
    closed = sm.fk("four-sps-cu", LEGS, all_solutions=True, method="closed-form", seeds=64)
    assert closed.engine == "closed-form" and len(closed.poses) == 4
    assert api_payload(closed) == cli_payload("fk", "four-sps-cu", "--actuators", LEGS_TEXT, "--all", "--seeds", "64")


def test_the_engine_of_each_method_is_decided_in_one_place():
    k4, stewart, rssr, smpu = (sm.load_model(n) for n in ("four-sps-cu", "stewart-6sps", "rssr", "three-sps-smpu"))
    assert dispatch.forward_engine(k4) == dispatch.forward_engine(k4, "closed-form") == "closed-form"
    assert dispatch.forward_engine(k4, "multistart") == "multistart"
    assert dispatch.forward_engine(k4, "homotopy") == "homotopy"
    assert dispatch.forward_engine(stewart) == "homotopy" and dispatch.forward_engine(rssr) == "monodromy"
    assert dispatch.forward_engine(smpu) == "multistart" and dispatch.forward_engine(k4, all_solutions=False) == "newton"
    with pytest.raises(sm.InputError, match="method: homotopy forward position does not cover three-sps-smpu"):
        dispatch.forward_engine(smpu, "homotopy")
    with pytest.raises(sm.InputError, match="method: no closed form of forward position recognises stewart-6sps"):
        sm.fk(stewart, [1.2] * 6, all_solutions=True, method="closed-form")
    # the registry: each closed form recognises its own layout from the mechanism, nothing else
    [cf] = [c for c in dispatch.FORWARD_CLOSED_FORMS if "4-SPS/CU" in c.name]
    assert cf.recognise(k4) is not None and cf.recognise(stewart) is None and cf.recognise(rssr) is None


# ------------------------------------------------------------------ (b) options an engine ignores are refused
@pytest.mark.parametrize("kwargs, named", [
    ({"all_solutions": True, "seeds": 40}, "seeds"),  # method="auto": homotopy here
    ({"all_solutions": True, "seeds": 40, "method": "homotopy"}, "seeds"),
    ({"seeds": 40}, "seeds"),  # one Newton solve: no starts
    ({"seed": 3}, "seed"),
    ({"method": "multistart"}, "method"),
])
def test_an_option_the_engine_would_ignore_is_refused_by_name(kwargs, named):
    with pytest.raises(sm.InputError, match=rf"^{named}: "):
        sm.fk("stewart-6sps", [1.2] * 6, **kwargs)


def test_the_cli_refuses_them_too():
    r = CliRunner().invoke(cli, ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all", "--seeds", "40"])
    assert r.exit_code == 2 and "seeds: homotopy continuation answers stewart-6sps" in r.output
    assert "method='multistart'" in r.output and "Traceback" not in r.output
    r = CliRunner().invoke(cli, ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--method", "homotopy"])
    assert r.exit_code == 2 and "method: only with all_solutions" in r.output


# ------------------------------------------------------------------ (c) the example says what ran
@pytest.mark.slow
def test_the_stewart_example_reports_the_engine_that_ran(capsys):
    runpy.run_path(str(ROOT / "examples" / "stewart_forward_all.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "assembly modes found by homotopy (proven complete: " in out
    assert "multi-start" not in out and "0 starts" not in out


# ------------------------------------------------------------------ (d) the same payload on both sides
POSE_B = ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46))
PARITY = [
    ("ik-four-sps-cu", lambda: sm.ik("four-sps-cu", POSE_B, degrees=True),
     ["ik", "four-sps-cu", "--pose", "0,0,0.12,ZYX,34.38,-5.73,11.46"]),
    ("ik-stewart", lambda: sm.ik("stewart-6sps", ([0.02, -0.01, 1.05], ("ZYX", 10, -5, 4)), degrees=True),
     ["ik", "stewart-6sps", "--xyz", "0.02", "-0.01", "1.05", "--euler", "ZYX", "10", "-5", "4"]),
    ("ik-three-rps-free", lambda: sm.ik("three-rps", ([0, 0, 0.33], ("ZYX", 0, 5, 5)), degrees=True, free=["x", "y", "a1"]),
     ["ik", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,y,a1"]),
    ("fk-four-sps-cu", lambda: sm.fk("four-sps-cu", LEGS), ["fk", "four-sps-cu", "--actuators", LEGS_TEXT]),
    ("fk-stewart", lambda: sm.fk("stewart-6sps", [1.2] * 6), ["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2"]),
    ("fk-three-rps", lambda: sm.fk("three-rps", [0.374613, 0.366706, 0.347013]),
     ["fk", "three-rps", "--actuators", "0.374613,0.366706,0.347013"]),
    ("jacobian-four-sps-cu", lambda: sm.jacobian("four-sps-cu", POSE_B, degrees=True),
     ["jacobian", "four-sps-cu", "--pose", "0,0,0.12,ZYX,34.38,-5.73,11.46"]),
    ("jacobian-stewart", lambda: sm.jacobian("stewart-6sps", ([0, 0, 1.05], None)),
     ["jacobian", "stewart-6sps", "--xyz", "0", "0", "1.05"]),
    ("jacobian-three-rps-free", lambda: sm.jacobian("three-rps", ([0, 0, 0.33], ("ZYX", 0, 5, 5)), degrees=True,
                                                    free=["x", "y", "a1"]),
     ["jacobian", "three-rps", "--pose", "0,0,0.33,ZYX,0,5,5", "--free", "x,y,a1"]),
]


@pytest.mark.parametrize("call, args", [p[1:] for p in PARITY], ids=[p[0] for p in PARITY])
def test_cli_and_api_give_the_same_payload(call, args):
    assert api_payload(call()) == cli_payload(*args)


@pytest.mark.slow
def test_cli_and_api_agree_on_the_homotopy_of_the_stewart_platform():
    r = sm.fk("stewart-6sps", [1.2] * 6, all_solutions=True)
    doc = cli_payload("fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all")
    assert r.engine == doc["engine"] == "homotopy" and r.complete and doc["complete"] is True
    assert api_payload(r) == doc


def test_every_engine_returns_the_one_result_type():
    one = sm.fk("stewart-6sps", [1.2] * 6)
    assert isinstance(one.answer, dispatch.ForwardAnswer) and one.engine == "newton" and not one.complete
    assert all(isinstance(m, dispatch.AssemblyMode) for m in one.modes) and one.poses[0] is one.modes[0].pose
    d = one.to_dict()
    assert d["engine"] == "newton" and d["complete"] is False and "one Newton solve" in d["completeness"]


# ------------------------------------------------------------------ the commands call the API only
def test_the_kinematics_commands_import_nothing_but_the_api():
    path = ROOT / "src" / "spatialmech" / "interfaces" / "cmd_kinematics.py"
    tree = ast.parse(path.read_text(encoding="utf-8"))
    modules = [("." * n.level) + (n.module or "") for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    modules += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    names = [a.name for n in ast.walk(tree) if isinstance(n, ast.ImportFrom) and n.module is None for a in n.names]
    for banned in ("kinematics", "analysis", "synthesis", "catalog"):
        assert not any(banned in m.split(".") for m in modules), (banned, modules)
        assert banned not in names, (banned, names)
