"""Fuzz test of the file loader and the command line (issue 10), hypothesis-driven and bounded.

(a) The loader (:func:`spatialmech.loads`, :func:`~spatialmech.model.schema.from_dict`,
:func:`spatialmech.load`) on mutated valid files: wrong types, missing and unknown fields,
NaN / inf, huge and tiny numbers, deep nesting, junk text and bytes, unknown joint types, zero and
non-unit axes, every length scaled by 1e+-300.  Property: a mechanism or a
:class:`~spatialmech.model.schema.ModelFileError` with a one-line message; an accepted file
writes back and reads again.

(b) The command line through click's ``CliRunner``: random option values for ``mobility``,
``ik``, ``fk``, ``jacobian``, ``singularity`` and ``workspace`` on small models (junk numbers,
empty items, NaN, huge values, wrong counts).  Properties: exit code 0, 1 or 2 (3 is an internal
error, i.e. a bug), never an unexpected exception; a failure is one line ``error: ...`` on
stderr with no traceback; every call returns within :data:`CALL_SECONDS` (no hang); a JSON
output has no NaN / infinity and no null inside a list of numbers.

About 650 inputs in all; the whole file runs in well under a minute (small models, grids refused
or kept coarse).  A failing example is printed by hypothesis; rerun the command with
``spatialmech --debug ...`` for the traceback.
"""

from __future__ import annotations

import contextlib
import copy
import json
import math
import os
import signal
import tempfile
import tomllib
from pathlib import Path

import pytest
import tomli_w
from click.testing import CliRunner
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

import spatialmech as sm
from spatialmech import catalog
from spatialmech.interfaces.cli import cli
from spatialmech.model.schema import ModelFileError, from_dict

pytestmark = pytest.mark.slow  # about 40 s in all: out of the quick loop (pytest -m "not slow")

#: Longest a single call may take (seconds) before the fuzz reports a hang.
CALL_SECONDS = 20.0
#: Multiplies every ``max_examples``: a longer hunt, e.g. ``SPATIALMECH_FUZZ_SCALE=20 pytest tests/test_fuzz.py``.
SCALE = float(os.environ.get("SPATIALMECH_FUZZ_SCALE", "1"))


def examples(n: int) -> int:
    return max(1, round(n * SCALE))


SETTINGS = dict(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large,
                                                      HealthCheck.filter_too_much])


class Hang(BaseException):
    """Raised by the alarm: a BaseException, so no ``except Exception`` in the code swallows it."""


@contextlib.contextmanager
def time_limit(seconds: float = CALL_SECONDS):
    def on_alarm(signum, frame):
        raise Hang(f"no result after {seconds} s")

    old = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


# ============================================================== (a) the file loader
#: Valid files to mutate: every joint type, modes, aliases, positions, limits and offsets.
SEED_MODELS = ("rssr", "bennett", "planar-4r", "three-rrr-sm", "four-sps-cu", "three-sps-smpu", "five-cs-1")
SEED_TEXTS = {name: sm.dumps(catalog.build(name)) for name in SEED_MODELS}
SEED_DICTS = {name: tomllib.loads(text) for name, text in SEED_TEXTS.items()}

special_floats = st.sampled_from([0.0, -0.0, 1e308, -1e308, 5e-324, 1e-300, 1e300, math.nan, math.inf, -math.inf])
junk_value = st.one_of(
    st.booleans(),
    st.integers(-(10**30), 10**30),
    st.sampled_from([10**400, -(10**5000)]),  # beyond a float; beyond Python's int-to-str limit
    st.floats(allow_nan=True, allow_infinity=True),
    special_floats,
    st.text(max_size=8),
    st.sampled_from(["R", "P", "H", "C", "U", "S", "Sm", "Q", "", "r", "ZYX", "zyx", "ZZZ"]),
    st.lists(st.one_of(st.floats(allow_nan=True, allow_infinity=True), special_floats), max_size=4),
    st.lists(st.integers(-3, 3), max_size=4),
    st.lists(st.booleans(), min_size=3, max_size=3),
    st.sampled_from([[0, 0, 0], [0, 0, 2], [1, 1, 0], [1e-300, 0, 0], [1e200, 0, 0], [0.6, 0.8, 1e-4], [0, 0, -1]])
    .map(copy.deepcopy),  # a fresh list each time: a shared one could be mutated into a cycle
    st.lists(st.lists(st.floats(-2, 2), min_size=3, max_size=3), max_size=4),
    st.dictionaries(st.text(max_size=5), st.one_of(st.integers(), st.floats(), st.text(max_size=3)), max_size=2),
)


def _paths(node):
    """Every (container, key) below ``node`` (dicts and lists)."""
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for k, v in items:
        yield node, k
        yield from _paths(v)


def _scale(node, f):
    if isinstance(node, dict):
        return {k: _scale(v, f) for k, v in node.items()}
    if isinstance(node, list):
        return [_scale(v, f) for v in node]
    if isinstance(node, (int, float)) and not isinstance(node, bool):
        return float(node) * f if abs(node) < 1e300 else node
    return node


def _copy(node):
    return json.loads(json.dumps(node))


@st.composite
def mutated_dicts(draw):
    name = draw(st.sampled_from(SEED_MODELS))
    d = _copy(SEED_DICTS[name])
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["set", "set", "delete", "extra", "type", "axis", "scale", "perturb", "perturb",
                                   "flag", "rename"]))
        paths = list(_paths(d))
        if not paths:
            break
        node, key = draw(st.sampled_from(paths))
        numbers = [(n, k) for n, k in paths
                   if isinstance(n[k], float | int) and not isinstance(n[k], bool) and abs(n[k]) < 1e300]
        joints = _joints(d)
        if op == "perturb" and numbers:  # a plausible typo: the file stays valid more often
            n, k = draw(st.sampled_from(numbers))
            n[k] = float(n[k]) * draw(st.sampled_from([1.0001, 0.5, 2.0, -1.0, 10.0, 1e6, 1e-6])) + draw(
                st.sampled_from([0.0, 0.0, 1e-9, 0.1, -3.0]))
        elif op == "flag" and joints:
            j = draw(st.sampled_from(joints))
            j[draw(st.sampled_from(["actuated", "lockable", "locked"]))] = draw(st.one_of(
                st.booleans(), st.sampled_from(["rot", "slide", "rot1", "R1", ""]),
                st.lists(st.sampled_from(["rot", "rot1", "rot2", "rot3", "slide", "screw"]), max_size=3)))
        elif op == "rename" and len(joints) > 1:
            a, b = draw(st.permutations(joints))[:2]
            a["name"] = draw(st.sampled_from([b.get("name", "x"), "", "a.b", "rot1", "R1+R4", " "]))
        elif op == "set":
            node[key] = draw(junk_value)
        elif op == "delete":
            if isinstance(node, dict):
                del node[key]
            else:
                node.pop(key)
        elif op == "extra":
            tables = [n for n, _k in paths if isinstance(n, dict)] or [d]
            draw(st.sampled_from(tables))[draw(st.sampled_from(["pointt", "axes", "axis", "pitch", "x", "modes", "limb"]))] = \
                draw(junk_value)
        elif op in ("type", "axis"):
            if joints:
                j = draw(st.sampled_from(joints))
                j["type" if op == "type" else "axis"] = draw(
                    st.sampled_from(["R", "P", "H", "C", "U", "S", "Sm", "Q", "rr", ""]) if op == "type"
                    else st.sampled_from([[0, 0, 0], [0, 0, 2], [1, 1, 0], [1e-300, 0, 0], [1e300, 1e300, 0], [1, 0]])
                    .map(copy.deepcopy))
        elif op == "scale":
            d = _scale(d, draw(st.sampled_from([1e-300, 1e-150, 1e150, 1e300, -1.0, 0.0])))
    return d


def _joints(d) -> list[dict]:
    limbs = d.get("limbs") if isinstance(d.get("limbs"), list) else []
    return [j for limb in limbs if isinstance(limb, dict) and isinstance(limb.get("joints"), list)
            for j in limb["joints"] if isinstance(j, dict)]


def _check_load(load, *args):
    """``load(*args)`` gives a mechanism or a one-line ModelFileError; an accepted model
    writes back and reads again."""
    with time_limit():
        try:
            mech = load(*args)
        except ModelFileError as e:
            assert str(e) and "\n" not in str(e), repr(str(e))
            event("refused")
            return None
    event("accepted")
    assert isinstance(mech, sm.Mechanism)
    with time_limit():
        again = sm.loads(sm.dumps(mech))
    assert [f.id for f in again.freedom_refs] == [f.id for f in mech.freedom_refs]
    return mech


@settings(max_examples=examples(260), **SETTINGS)
@given(mutated_dicts())
def test_fuzz_loader_on_mutated_tables(d):
    """... and an accepted file goes through ``spatialmech mobility`` (odd scales, flags, names)."""
    mech = _check_load(from_dict, d)
    try:
        text = tomli_w.dumps(d)
    except (TypeError, ValueError):  # e.g. an empty key tomli-w cannot write: the dict case is enough
        text = None
        event("not writable as TOML")
    if text is not None:
        _check_load(sm.loads, text)
    if text is not None and mech is not None:
        with tempfile.TemporaryDirectory() as tmp:
            f = Path(tmp) / "model.toml"
            f.write_text(text, encoding="utf-8")
            _invoke(["mobility", str(f), "--json"])


@st.composite
def mutated_texts(draw):
    text = SEED_TEXTS[draw(st.sampled_from(SEED_MODELS))]
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(text)))
        op = draw(st.sampled_from(["insert", "delete", "replace", "nest", "truncate", "duplicate", "digits"]))
        if op == "insert":
            text = text[:i] + draw(st.text(max_size=12)) + text[i:]
        elif op == "delete":
            text = text[:i] + text[i + draw(st.integers(1, 40)):]
        elif op == "replace":
            text = text[:i] + draw(st.sampled_from(list("[]{}=\",.'#\n\x00\x7f é∞"))) + text[i + 1:]
        elif op == "nest":
            depth = draw(st.sampled_from([10, 200, 400, 1000, 5000]))
            key = draw(st.sampled_from(["notes", "platform_point", "aliases", "x"]))
            text = f"{key} = " + "[" * depth + "1" + "]" * depth + "\n" + text
        elif op == "truncate":
            text = text[:i]
        elif op == "digits":  # a number with thousands of digits where a digit was
            j = next((k for k in range(i, len(text)) if text[k].isdigit()), None)
            if j is not None:
                text = text[:j] + "1" * draw(st.sampled_from([400, 5000])) + text[j:]
        else:
            lines = text.splitlines(keepends=True)
            k = draw(st.integers(0, max(len(lines) - 1, 0)))
            text = "".join(lines[: k + 1] + lines[k:])
    return text


@settings(max_examples=examples(140), **SETTINGS)
@given(mutated_texts())
def test_fuzz_loader_on_mutated_text(text):
    _check_load(sm.loads, text)


@settings(max_examples=examples(40), **SETTINGS)
@given(st.sampled_from(SEED_MODELS), st.binary(min_size=1, max_size=64), st.integers(0, 400))
def test_fuzz_loader_and_cli_on_junk_bytes(name, junk, at):
    raw = SEED_TEXTS[name].encode("utf-8")
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "model.toml"
        f.write_bytes(raw[:at] + junk + raw[at:])
        mech = None
        with contextlib.suppress(ModelFileError):
            mech = _check_load(sm.load, f)
        r = _invoke(["mobility", str(f), "--json"])
        if mech is None:
            assert r.exit_code == 2 and str(f) in r.stderr, r.output


# ============================================================== (b) the command line
def _invoke(args):
    try:
        with time_limit():
            r = CliRunner().invoke(cli, args)
    except Hang as e:  # an AssertionError, so that hypothesis reports (and shrinks) the example
        raise AssertionError(f"{args}: {e}") from None
    err = r.stderr
    event(f"exit code {r.exit_code}")  # pytest --hypothesis-show-statistics: the mix of outcomes
    assert r.exception is None or isinstance(r.exception, SystemExit), (args, repr(r.exception), r.output)
    assert r.exit_code in (0, 1, 2), (args, r.exit_code, r.output)  # 3: an internal error
    assert "Traceback" not in r.output, (args, r.output)
    if r.exit_code:
        last = err.rstrip("\n").splitlines()[-1] if err.strip() else ""
        assert last.startswith("error: ") and err.count("error: ") == 1, (args, err)
    elif "--json" in args:
        doc = json.loads(r.stdout, parse_constant=lambda c: pytest.fail(f"{args}: {c} in the JSON output"))
        _no_null_among_numbers(doc, args)
    return r


def _no_null_among_numbers(node, args, where="$"):
    if isinstance(node, dict):
        for k, v in node.items():
            _no_null_among_numbers(v, args, f"{where}.{k}")
    elif isinstance(node, list):
        kinds = {type(x) for x in node}
        assert not (type(None) in kinds and kinds & {int, float}), f"{args}: null among numbers at {where}: {node}"
        for i, v in enumerate(node):
            _no_null_among_numbers(v, args, f"{where}[{i}]")


#: Number-like junk for an option that takes one number.
junk_number = st.one_of(
    st.sampled_from(["", " ", "nan", "NaN", "inf", "-inf", "1e400", "-1e400", "1e308", "-1e308", "1e-308", "5e-324",
                     "0", "-0", "abc", "1,2", "0x10", "1_0", "\u0663", "--json", "1e", ".", "-"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**6), 10**6).map(str),
    st.floats(-1, 1).map(lambda x: f"{x:.6g}"),
)
euler_seq = st.sampled_from(["ZYX", "zyx", "ZXZ", "XYZ", "ZZZ", "abc", "", "ZYXZ", "nan", "Zyx"])
small_models = st.sampled_from(["rssr", "bennett", "planar-4r", "four-sps-cu", "three-rrr-sm"])
json_flag = st.lists(st.just("--json"), max_size=1)
#: Pose values that cannot be used: not numbers, not finite, far out of any model's range.  (Valid
#: numbers are the model's reference pose, which every model reaches at once: an unreachable pose
#: costs seconds in the nearest-configuration fit of ``ik``, too slow for a fuzz budget.)
bad_pose_number = st.one_of(
    st.sampled_from(["", " ", "nan", "NaN", "inf", "-inf", "1e400", "-1e400", "1e308", "-1e308", "abc", "1,2", "0x10",
                     "1e", ".", "-", "1e30", "-7e12", "--json"]),
    st.floats(allow_nan=True, allow_infinity=True).filter(lambda x: not abs(x) < 1e7).map(repr),
)


@st.composite
def pose_args(draw, model: str):
    """Pose options for ``model``: its reference pose, spelled in every accepted way, with some
    values replaced by unusable ones, or clashing options."""
    p0 = [repr(float(x)) for x in catalog.build(model).platform_point]

    def values(ref):
        out = list(ref)
        for k in draw(st.lists(st.integers(0, 2), max_size=3, unique=True)) if draw(st.booleans()) else []:
            out[k] = draw(bad_pose_number)
        return out

    args = []
    kind = draw(st.sampled_from(["xyz", "xyz+euler", "euler", "pose", "position", "none", "clash"]))
    if kind in ("xyz", "xyz+euler", "clash"):
        args += ["--xyz", *values(p0)]
    if kind in ("xyz+euler", "euler", "clash"):
        args += ["--euler", draw(euler_seq), *values(["0", "0", "0"])]
    if kind in ("pose", "clash"):
        parts = [*p0, draw(euler_seq), "0", "0", "0"]
        if draw(st.booleans()):
            parts[draw(st.sampled_from([0, 1, 2, 4, 5, 6]))] = draw(bad_pose_number)
        if draw(st.booleans()):
            parts = parts[: draw(st.integers(0, 7))] + draw(st.lists(st.sampled_from(["", "0"]), max_size=2))
        args += ["--pose", ",".join(parts)]
    if kind in ("position", "clash"):
        args += ["--position", draw(st.sampled_from(["0", "1", "3", "8", "-1", "1e3", "x", "99999999999999999999"]))]
    return args


@settings(max_examples=examples(30), **SETTINGS)
@given(small_models, st.lists(st.one_of(st.sampled_from(["default", "R1", "R1+R4", "all-locked", ""]), st.text(max_size=6)),
                              max_size=1), json_flag)
def test_fuzz_cli_mobility(model, mode, as_json):
    _invoke(["mobility", model, *(["--mode", mode[0]] if mode else []), *as_json])


@settings(max_examples=examples(45), **SETTINGS)
@given(st.data(), st.sampled_from(["rssr", "planar-4r", "four-sps-cu", "bennett"]), json_flag,
       st.lists(st.just("--all"), max_size=1))
def test_fuzz_cli_ik(data, model, as_json, all_):
    if model in ("bennett", "four-sps-cu"):
        all_ = []  # their multi-start takes seconds: kept out of the fuzz budget
    _invoke(["ik", model, *data.draw(pose_args(model)), *all_, *as_json])


#: Plausible actuator values (degrees or metres) of the fk models, about their reference.
PLAUSIBLE_ACTUATORS = {"rssr": (-40.0, 40.0), "planar-4r": (-40.0, 40.0), "four-sps-cu": (0.19, 0.26)}


@st.composite
def actuator_lists(draw, model: str):
    """Comma-separated values: the model's number of them (mostly), plausible or junk, and odd
    separators."""
    n_act = len(catalog.build(model).actuators)
    n = draw(st.one_of(st.just(n_act), st.just(n_act), st.integers(0, 6)))
    lo, hi = PLAUSIBLE_ACTUATORS[model]
    plausible = st.floats(lo, hi).map(lambda x: f"{x:.4g}")
    items = draw(st.lists(st.one_of(plausible, plausible, junk_number), min_size=n, max_size=n))
    sep = draw(st.sampled_from([",", ",", ", ", ",,", ";", " "]))
    return sep.join(items)


@settings(max_examples=examples(50), **SETTINGS)
@given(st.data(), st.sampled_from(sorted(PLAUSIBLE_ACTUATORS)), json_flag,
       st.lists(st.sampled_from(["--all", "--seeds"]), max_size=2, unique=True),
       st.sampled_from(["1", "4", "0", "-3", "x", "1e9"]))
def test_fuzz_cli_fk(data, model, as_json, flags, seeds):
    args = ["fk", model, "--actuators", data.draw(actuator_lists(model)), *as_json]
    if "--all" in flags:  # always with few starts: the default 200 take seconds
        args += ["--all", "--seeds", seeds]
    elif "--seeds" in flags:
        args += ["--seeds", seeds]
    _invoke(args)


@settings(max_examples=examples(35), **SETTINGS)
@given(st.data(), st.sampled_from(["rssr", "bennett", "four-sps-cu"]), json_flag,
       st.lists(st.sampled_from(["A0", "B0", "L1.slide", "rot", "nosuch", ""]), max_size=2))
def test_fuzz_cli_jacobian(data, model, as_json, drivers):
    pose = data.draw(pose_args(model))
    _invoke(["jacobian", model, *pose, *[a for d in drivers for a in ("--driver", d)], *as_json])


@st.composite
def slice_specs(draw):
    def axis():
        name = draw(st.sampled_from(["x", "y", "z", "a1", "a2", "a3", "q", ""]))
        lo, hi = draw(junk_number), draw(junk_number)
        n = draw(st.sampled_from(["2", "3", "1", "0", "401", "-2", "x", "3.5"]))
        return ":".join([name, lo, hi, n][: draw(st.sampled_from([4, 4, 4, 3, 1]))])

    return ",".join(axis() for _ in range(draw(st.integers(0, 3))))


@settings(max_examples=examples(40), **SETTINGS)
@given(st.data(), st.sampled_from(["rssr", "bennett", "four-sps-cu"]), st.booleans(),
       st.one_of(st.none(), slice_specs()), json_flag)
def test_fuzz_cli_singularity(data, model, reference, slice_spec, as_json):
    if slice_spec is not None:
        model = "four-sps-cu"  # closed form; each slice pose of another model is a fit of about a second
    args = ["singularity", model, *(["--reference"] if reference else data.draw(pose_args(model))), *as_json]
    if slice_spec is not None:
        args += ["--slice", slice_spec]
    _invoke(args)


#: Step values that keep a workspace grid coarse (or are refused): never the slow default.
coarse_or_junk_step = st.one_of(st.sampled_from(["30", "45", "90", "1e300", "1e-6", "1e-300", "0", "-5", "nan", "inf",
                                                 "x", ""]), st.floats(25, 360).map(lambda x: f"{x:.3g}"))
at_specs = st.lists(st.tuples(st.sampled_from(["x", "y", "z", "alpha", "beta", "gamma", "q", ""]), junk_number),
                    max_size=3).map(lambda kv: ",".join(f"{k}={v}" for k, v in kv))


@settings(max_examples=examples(30), **SETTINGS)
@given(st.lists(st.sampled_from(["--orientation", "--position"]), max_size=2, unique=True), at_specs,
       coarse_or_junk_step, st.sampled_from(["0.05", "0.1", "1e300", "0", "-1", "nan", "1e-9"]),
       st.one_of(st.none(), junk_number), st.one_of(st.none(), junk_number),
       st.one_of(st.none(), st.sampled_from(["1", "100", "0", "-1", "x", "1e3"])), json_flag)
def test_fuzz_cli_workspace(kinds, at, step_deg, step_m, tol, link, max_poses, as_json):
    """On the 4-SPS/CU (the vectorised closed form): the general kernel needs minutes even for a
    coarse grid, so its models are not fuzzed here."""
    args = ["workspace", "four-sps-cu", *kinds, "--step-deg", step_deg, "--step", step_m, "--no-interference", *as_json]
    if at:
        args += ["--at", at]
    if tol is not None:
        args += ["--tol-deg" if "--position" not in kinds else "--tol", tol]
    if link is not None:
        args += ["--link-diameter", link]
    if max_poses is not None:
        args += ["--max-poses", max_poses]
    _invoke(args)


# ============================================================== (c) graph files (issue 30, item 11)
#: Graph-form files to mutate: the spatial six-bar, the Delta (11 links, 15 joints) and a serial
#: R-R chain (no loop); each with actuator values that fit the unmutated model.
GRAPH_SEEDS = {
    "spatial-six-bar": (tomllib.loads(sm.dumps(catalog.build("spatial-six-bar"))), "10"),
    "delta": (tomllib.loads(sm.dumps(catalog.build("delta"))), "10,10,10"),
    "serial-rr": ({"format": 1, "name": "serial-rr", "links": ["ground", "arm", "platform"], "joints": [
        {"name": "A", "type": "R", "links": ["ground", "arm"], "point": [0, 0, 0], "axis": [0, 0, 1], "actuated": True},
        {"name": "B", "type": "R", "links": ["arm", "platform"], "point": [1, 0, 0], "axis": [0, 0, 1],
         "actuated": True}]}, "10,20"),
}


@st.composite
def mutated_graphs(draw):
    """``(name, file dict, actuator values)``: a graph file with one to three mutations: a joint
    dropped, a link name emptied, a joint duplicated (between the same links, under a new
    name), a joint's link replaced by another (or an unknown one), a joint's ends swapped, a
    link dropped from ``links``."""
    name = draw(st.sampled_from(sorted(GRAPH_SEEDS)))
    d, acts = GRAPH_SEEDS[name]
    d = _copy(d)
    for _ in range(draw(st.integers(1, 3))):
        joints, links = d["joints"], d["links"]
        op = draw(st.sampled_from(["drop-joint", "empty-name", "duplicate", "wrong-link", "wrong-link", "swap",
                                   "drop-link"]))
        if not joints or not links:
            break
        j = draw(st.sampled_from(joints))
        if op == "drop-joint":
            joints.remove(j)
        elif op == "empty-name":
            k = draw(st.integers(0, len(links) - 1))
            new = draw(st.sampled_from(["", " ", links[k] + " "]))
            if draw(st.booleans()):
                j["links"] = [new if x == links[k] else x for x in j["links"]]
            else:
                links[k] = new
        elif op == "duplicate":
            joints.append({**_copy(j), "name": j["name"] + "2", "actuated": False})
        elif op == "wrong-link":
            j["links"][draw(st.integers(0, 1))] = draw(st.sampled_from([*links, "nosuch"]))
        elif op == "swap":
            j["links"] = j["links"][::-1]
        else:
            links.remove(draw(st.sampled_from(links)))
    return name, d, acts


@settings(max_examples=examples(60), **SETTINGS)
@given(mutated_graphs(), st.sampled_from(["mobility", "fk", "fk --all", "singularity --reference", "export"]))
def test_fuzz_cli_on_mutated_graph_files(graph, command):
    """Every command on a mutated graph file: a valid run or a clear error (exit 0, 1 or 2,
    never 3), each within :data:`CALL_SECONDS`.  The Delta's ``fk --all`` by the loop
    formulation can take a minute on a valid mutant: it runs a two-start multi-start search."""
    name, d, acts = graph
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "graph.toml"
        f.write_text(tomli_w.dumps(d), encoding="utf-8")
        verb, *rest = command.split()
        args = [verb, str(f), *rest]
        if verb == "fk":
            args += ["--actuators", acts]
            if "--all" in rest and name != "serial-rr":
                args += ["--method", "multistart", "--seeds", "2"]
        elif verb == "export":
            args.append(str(Path(tmp) / "out.toml"))
        event(f"{name} {command}")
        _invoke(args)
