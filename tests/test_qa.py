"""QA sweep of the command line, the docs and the error handling.

Each test pins one defect found by running the documented commands and bad input as a user
would: every user error is ONE line ``error: ...`` with exit code 2 (no usage block, no
traceback), numbers are labelled with units, singular results say so, and the docs' numbers are
what the code gives (checked independently where possible).
"""

import json

import numpy as np
import pytest
from click.testing import CliRunner

import spatialmech as sm
from spatialmech.analysis.defects import defect_analysis
from spatialmech.interfaces.cli import cli
from spatialmech.kinematics.position import configuration_at_pose, inverse_position
from spatialmech.kinematics.forward import forward_position


def run(*args):
    return CliRunner().invoke(cli, [str(a) for a in args])


def assert_one_line_error(r, code=2, contains=""):
    """One line ``error: ...`` and nothing else (no usage block, no progress, no traceback)."""
    assert r.exit_code == code, r.output
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert r.output.startswith("error: ") and r.output.count("\n") == 1, r.output
    assert "Traceback" not in r.output
    assert contains in r.output, r.output


# ------------------------------------------------------------------ click's own usage errors
@pytest.mark.parametrize(
    "args, contains",
    [
        (["jacobian", "four-sps-cu", "--reference"], "No such option '--reference'"),
        (["--bogus"], "No such option '--bogus'"),
        (["no-such-command"], "No such command"),
        (["ik", "four-sps-cu", "--xyz", "0", "0"], "--xyz"),
        (["view", "four-sps-cu"], "Missing option '--out'"),
        (["view", "four-sps-cu", "--frames", "0", "--out", "x.html"], "--frames"),
        (["workspace", "four-sps-cu", "--method", "nosuch"], "--method"),
        (["fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2", "--all", "--seeds", "0"], "--seeds"),
        (["synth", "rccc", "--bogus"], "No such option '--bogus'"),
    ],
)
def test_usage_errors_are_one_line_with_exit_code_2(args, contains):
    """Before: click printed a four-line 'Usage: ... Try ... Error: ...' block (and --seeds 0 or
    -3 was accepted, reporting '-2 start(s)')."""
    r = run(*args)
    assert_one_line_error(r, 2, contains)
    assert "--help" in r.output  # points to the help of the command


@pytest.mark.parametrize("args", [["--help"], ["--version"], ["demo", "--help"], ["ik", "-h"], ["synth", "rccc", "--help"]])
def test_help_and_version_still_exit_0(args):
    """click's --help / --version exit through ``click.exceptions.Exit``, a RuntimeError: the
    one-line handler of failed computations must let it through."""
    r = run(*args)
    assert r.exit_code == 0 and not r.output.startswith("error"), r.output


def test_no_arguments_still_prints_the_help():
    r = run()
    assert r.output.startswith("Usage: ") and "mobility" in r.output
    assert not any(line.startswith("error") for line in r.output.splitlines()), r.output  # no error message


# ------------------------------------------------------------------ files that cannot be written
def test_export_to_a_missing_directory_is_one_line(tmp_path):
    """Before: a FileNotFoundError traceback (exit code 1)."""
    r = run("export", "rssr", tmp_path / "no" / "such" / "dir" / "x.toml")
    assert_one_line_error(r, 2, "No such file or directory")


@pytest.mark.parametrize("cmd", [["report", "bennett"], ["demo"]])
def test_report_to_an_unwritable_directory_fails_at_once(tmp_path, cmd):
    """Before: the whole computation ran (about 45 s for the demo) and then a traceback.  Now the
    output directory is created first: one line, no progress output, exit code 2."""
    blocker = tmp_path / "a-file"
    blocker.write_text("not a directory")
    r = run(*cmd, "--out", blocker / "sub")
    assert_one_line_error(r, 2, str(blocker / "sub"))


# ------------------------------------------------------------------ mobility
def test_unknown_mode_of_a_non_metamorphic_mechanism_is_refused():
    """Before: ``mobility four-sps-cu --mode R1`` printed a result labelled 'mode R1'."""
    assert_one_line_error(run("mobility", "four-sps-cu", "--mode", "R1"), 2, "unknown mode 'R1'; modes: default")
    with pytest.raises(KeyError, match="unknown mode"):
        sm.mobility(sm.load_model("stewart-6sps"), "nosuch")
    assert sm.mobility(sm.load_model("four-sps-cu"), "default").dof == 4  # the one real mode still works


# ------------------------------------------------------------------ forward position
def test_fk_text_output_labels_units_and_prints_no_numpy_repr():
    """Before: ``position [ 2.188963e-16 -3.466236e-17  1.080541e+00]  ZYX (deg) [2.2259e-14 ...]``."""
    r = run("fk", "stewart-6sps", "--actuators", "1.2,1.2,1.2,1.2,1.2,1.2")
    assert r.exit_code == 0, r.output
    line = r.output.splitlines()[1]
    assert "[" not in line.split("]", 1)[1] and "e-1" not in line, line
    assert "platform point (0, 0, 1.08054) m" in line and "ZYX angles (0.0000, 0.0000, 0.0000) deg" in line
    # the platform height from the leg length alone: all six legs equal, the platform stays level
    fk = forward_position(sm.load_model("stewart-6sps"), [1.2] * 6)
    assert abs(fk.solutions[0].pose.p[2] - 1.08054) < 5e-6


@pytest.mark.slow
def test_fk_closed_form_honours_seeds_and_flags_singular_self_motion_samples():
    """Equal legs put the 4-SPS/CU on its singular set alpha = beta = 0, where the locked
    mechanism has a self-motion (docs/singularity.md): every start converges to a different
    point of that curve.  Before: the CLI listed them all as distinct 'assembly modes' (512 for
    0.2,0.2,0.2,0.2) with nothing saying they are singular, and ignored --seeds (always 512)."""
    r = run("fk", "four-sps-cu", "--actuators", "0.2,0.2,0.2,0.2", "--all", "--seeds", "8")
    assert r.exit_code == 0, r.output
    # (issue 10: the samples of the continuum are now one result, flagged as a self-motion set)
    assert "8 start(s), 8 converged" in r.output and "0 assembly modes, 1 self-motion set" in r.output
    assert "SINGULAR, SELF-MOTION" in r.output and "not an assembly mode; 8 start(s) landed on it" in r.output
    d = json.loads(run("fk", "four-sps-cu", "--actuators", "0.216745,0.23896,0.227321,0.206933",
                       "--all", "--seeds", "64", "--json").output)
    assert d["search"]["n_seeds"] == 64
    # a regular example: no solution is flagged (smallest sigma_min ~1.5e-3 >> 1e-9)
    regular = run("fk", "four-sps-cu", "--actuators", "0.216745,0.23896,0.227321,0.206933", "--all")
    # (the flags line names each kind and says no: "forward singular no, inverse singular no, ...")
    said = regular.output.replace("forward singular no", "").replace("inverse singular no", "")
    said = said.replace("nonsingular", "")  # the completeness proof's "finite nonsingular" end points
    assert "singular" not in said.lower() and "-0.0000" not in regular.output


def test_forward_position_refuses_a_non_positive_number_of_starts():
    """Before: ``n_seeds=-5`` ran and reported ``'seeds': -4``."""
    st = sm.load_model("stewart-6sps")
    for n in (0, -5):
        with pytest.raises(ValueError, match="n_seeds"):
            forward_position(st, [1.2] * 6, all_solutions=True, n_seeds=n)


# ------------------------------------------------------------------ inverse position, Jacobian
def test_ik_of_a_printed_task_position_reports_the_fit():
    """``spatialmech ik five-cs-1 --position 3`` (a docs example) says 'NOT reachable': paper
    A's positions are rounded and a 5-freedom C-S limb cannot reach an arbitrary pose.  The
    command now says how far the nearest closed configuration is (text and JSON)."""
    mech = sm.load_model("five-cs-1")
    fit = configuration_at_pose(mech, mech.positions[2])
    r = run("ik", "five-cs-1", "--position", "3")
    assert r.exit_code == 0 and "NOT reachable" in r.output
    assert f"{fit.position_error:.3g} unit and {np.degrees(fit.angle_error):.3g} deg" in r.output
    d = json.loads(run("ik", "five-cs-1", "--position", "3", "--json").output)
    assert not d["reachable"] and d["pose_fit"]["position_error_len"] == pytest.approx(fit.position_error, rel=1e-9)
    # rounded data: off by less than the 2 % membership tolerance of the defect analysis
    assert 0 < d["pose_fit"]["position_error_len"] < 0.02 * mech.characteristic_length
    assert json.loads(run("ik", "five-cs-1", "--position", "1", "--json").output)["pose_fit"] is None


def test_jacobian_says_singular_at_the_singular_home_pose():
    """At alpha = beta = 0 the 4-SPS/CU is singular (the four legs meet on the Z axis): before,
    ``jacobian four-sps-cu --xyz 0 0 0.12`` printed 'det J = +2.27e-18' as if it were a value."""
    sing = run("jacobian", "four-sps-cu", "--xyz", "0", "0", "0.12")
    assert sing.exit_code == 0 and "SINGULAR configuration" in sing.output
    reg = run("jacobian", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "34.38", "-5.73", "11.46")
    assert reg.exit_code == 0 and "SINGULAR" not in reg.output


# ------------------------------------------------------------------ defects
@pytest.mark.parametrize("kw, name", [({"pose_tol": -1.0}, "pose_tol"), ({"angle_tol_deg": float("nan")}, "angle_tol_deg"),
                                      ({"monte_carlo": -1}, "monte_carlo"), ({"precision": -1e-3}, "precision")])
def test_defect_analysis_validates_its_tolerances(kw, name):
    """Before: negative or NaN tolerances and a negative Monte-Carlo count ran silently."""
    with pytest.raises(ValueError, match=name):
        defect_analysis(sm.load_model("five-cs-1"), **kw)


def test_defects_cli_rejects_a_negative_monte_carlo_count():
    assert_one_line_error(run("defects", "five-cs-1", "--monte-carlo", "-1"), 2, "monte_carlo")


@pytest.mark.slow
def test_defects_notes_a_position_far_from_the_linkage(tmp_path):
    """A task position 7.8 m from an RSSR of size ~1 m was silently given a circuit of its own
    ('circuit defect: YES').  The text output now says how far its printed pose is from the
    nearest closed configuration, which the analysis uses."""
    f = tmp_path / "pos.toml"
    f.write_text('[[positions]]\nname = "P1"\npoint = [0, 1, -0.1]\neuler = { seq = "ZXY", angles_deg = [0, 0, 0] }\n'
                 '[[positions]]\nname = "P2"\npoint = [5, 5, 5]\neuler = { seq = "ZXY", angles_deg = [40, 10, 0] }\n')
    r = run("defects", "rssr", "--positions", f)
    assert r.exit_code == 0, r.output
    note = [ln for ln in r.output.splitlines() if ln.startswith("  note: the pose of P2")]
    assert len(note) == 1 and " m and " in note[0]
    assert not any(ln.startswith("  note: the pose of P1") for ln in r.output.splitlines())


@pytest.mark.slow
def test_defects_lists_repeated_branch_intervals_once_with_a_count():
    """Before: 'slide5 ... branch defect (P3-P4, P6-P7, P6-P7)'; two DJ zeros between P6 and P7
    are now 'P6-P7 x2'."""
    r = run("defects", "five-cs-1", "--driver", "slide5")
    assert r.exit_code == 0, r.output
    line = next(ln for ln in r.output.splitlines() if ln.strip().startswith("slide5"))
    assert "P6-P7 x2" in line and "P6-P7, P6-P7" not in line


# ------------------------------------------------------------------ singularity, workspace
def test_singularity_slice_rejects_non_finite_bounds_naming_the_option():
    """Before: 'error: angles: contains NaN or infinity' (no mention of --slice)."""
    r = run("singularity", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "20", "0", "0",
            "--slice", "a2:nan:30:5,a3:-30:30:5")
    assert_one_line_error(r, 2, "--slice")


@pytest.mark.slow
def test_singularity_slice_where_nothing_closes_is_an_error_not_nan():
    """The CU limb keeps x = y = 0: a slice over x, y at +-1, +-3 m has no closed pose.  Before:
    exit 0 with 'smallest sigma_min nan' and two RuntimeWarnings."""
    r = run("singularity", "four-sps-cu", "--xyz", "0", "0", "0.12", "--euler", "ZYX", "20", "0", "0",
            "--slice", "x:-3:3:4,y:-3:3:4")
    assert "nan" not in r.output
    assert r.exit_code == 2 and r.output.splitlines()[-1].startswith("error: --slice: no pose")


@pytest.mark.parametrize(
    "args, contains",
    [(["--position", "--step", "-1"], "--step"), (["--position", "--tol", "0"], "--tol"),
     (["--at", "z=0.1", "--max-poses", "10"], "--max-poses = 10")],
)
def test_workspace_errors_name_the_option_and_print_no_progress(args, contains):
    """Before: 'checking poses' was printed before the error, and the message named the library
    argument (``step``, ``max_poses``) instead of the option to change."""
    assert_one_line_error(run("workspace", "four-sps-cu", *args), 2, contains)


# ------------------------------------------------------------------ the docs' numbers
def test_kinematics_doc_leg_length_of_the_stewart_example():
    """docs/kinematics.md said ``{"L1.slide": 1.07..., ...}``; the pose gives 1.2655 m.  Checked
    independently of the solver: the leg length is |D a1 - b1| with D the platform displacement."""
    st = sm.load_model("stewart-6sps")
    pose = sm.Pose.from_euler("ZYX", [10, -5, 4], [0.02, -0.01, 1.05], degrees=True)
    legs = inverse_position(st, pose).actuator_values(st)
    D = pose.displacement(st.platform_point)
    limb = st.limbs[0]
    b, a = limb.joints[0].point, limb.joints[-1].point
    direct = float(np.linalg.norm(D[:3, :3] @ a + D[:3, 3] - b))
    assert legs["L1.slide"] == pytest.approx(direct, abs=1e-9)
    assert abs(direct - 1.2655) < 1e-4
