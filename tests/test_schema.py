"""The TOML file format: round trips for every model, one clear error per kind of mistake."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import spatialmech as sm
from spatialmech import catalog
from spatialmech.kinematics.closure import reference_screws

GOOD = textwrap.dedent(
    """
    name = "my-4r"
    description = "a planar four-bar"
    platform_point = [0.5, 0.866, 0]

    [[limbs]]
    name = "crank"
    joints = [
      { name = "A0", type = "R", point = [0, 0, 0], axis = [0, 0, 1], actuated = true, limits_deg = [-180, 180] },
      { name = "A1", type = "R", point = [0.5, 0.866, 0], axis = [0, 0, 1] },
    ]

    [[limbs]]
    name = "rocker"
    joints = [
      { name = "B0", type = "R", point = [4, 0, 0], axis = [0, 0, 1] },
      { name = "B1", type = "R", point = [3.2, 2.5, 0], axis = [0, 0, 1] },
    ]
    """
)


def test_good_file_loads():
    mech = sm.loads(GOOD)
    assert mech.name == "my-4r"
    f = mech.freedom("A0").freedom
    assert f.limits == pytest.approx((-np.pi, np.pi))
    assert sm.mobility(mech).dof == 1


@pytest.mark.parametrize("name", catalog.names())
def test_every_ready_made_model_round_trips_through_toml(name):
    m = catalog.build(name)
    m2 = sm.loads(sm.dumps(m))
    assert np.allclose(reference_screws(m), reference_screws(m2), atol=1e-12)
    assert [f.id for f in m.freedom_refs] == [f.id for f in m2.freedom_refs]
    assert [(f.freedom.actuated, f.freedom.lockable, f.freedom.limits, f.freedom.offset) for f in m.freedom_refs] == [
        (f.freedom.actuated, f.freedom.lockable, f.freedom.limits, f.freedom.offset) for f in m2.freedom_refs
    ]
    assert [m.name for m in m.all_modes()] == [m.name for m in m2.all_modes()]
    for p, q in zip(m.positions, m2.positions, strict=True):
        assert np.allclose(p.R, q.R, atol=1e-12) and np.allclose(p.p, q.p)


BAD = {
    "unknown joint type": (GOOD.replace('type = "R", point = [0, 0, 0]', 'type = "Q", point = [0, 0, 0]'),
                           "limbs[0].joints[0].type: unknown joint type 'Q'"),
    "zero axis": (GOOD.replace("axis = [0, 0, 1], actuated", "axis = [0, 0, 0], actuated"),
                  "limbs[0].joints[0].axis: zero vector"),
    "non-unit axis": (GOOD.replace("axis = [0, 0, 1], actuated", "axis = [0, 0, 2], actuated"),
                      "limbs[0].joints[0].axis: not a unit vector"),
    "wrong vector length": (GOOD.replace("point = [4, 0, 0]", "point = [4, 0]"),
                            "limbs[1].joints[0].point: List should have at least 3 items"),
    "missing limb end (no joints)": ('name = "x"\n[[limbs]]\nname = "a"\njoints = []\n',
                                     "limbs[0].joints: List should have at least 1 item"),
    "missing joints": ('name = "x"\n[[limbs]]\nname = "a"\n', "limbs[0].joints: required field is missing"),
    "NaN": (GOOD.replace("point = [4, 0, 0]", "point = [4, nan, 0]"),
            "limbs[1].joints[0].point[1]: Input should be a finite number"),
    "unknown field": (GOOD.replace('description = "a planar four-bar"', 'descripton = "typo"'),
                      "descripton: unknown field"),
    "degrees on a slide": (GOOD.replace('type = "R", point = [4, 0, 0]', 'type = "P", point = [4, 0, 0], limits_deg = [0, 1]'),
                           "limits_deg.slide: a slide is a length"),
    "malformed TOML": ("name = \n", "not valid TOML"),
    "no limbs": ('name = "x"\nlimbs = []\n', "limbs: List should have at least 1 item"),
    "bad euler sequence": (GOOD + '\n[[positions]]\npoint = [0, 0, 0]\neuler = { seq = "ZZX", angles_deg = [0, 0, 0] }\n',
                           "positions[0]: seq"),
}


@pytest.mark.parametrize("kind", list(BAD))
def test_bad_files_give_one_line_errors_naming_the_field(kind):
    text, msg = BAD[kind]
    with pytest.raises(sm.ModelFileError) as e:
        sm.loads(text)
    assert msg in str(e.value)
    assert "\n" not in str(e.value)


@pytest.mark.slow  # a subprocess (interpreter start) each
@pytest.mark.parametrize("kind", ["unknown joint type", "NaN", "malformed TOML"])
def test_cli_reports_bad_files_in_one_line_with_exit_code_2(kind, tmp_path):
    text, msg = BAD[kind]
    f = tmp_path / "bad.toml"
    f.write_text(text)
    p = subprocess.run([sys.executable, "-m", "spatialmech", "mobility", str(f)], capture_output=True, text=True)
    assert p.returncode == 2
    assert "Traceback" not in p.stderr
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and msg in lines[0] and str(f) in lines[0]


def test_missing_file_or_unknown_model(tmp_path):
    with pytest.raises(sm.ModelFileError, match="not a file and not a ready-made model"):
        sm.load_model(tmp_path / "nope.toml")
