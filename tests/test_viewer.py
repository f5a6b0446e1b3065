"""The demonstration motion, the viewer's geometry and figure, and ``spatialmech view``
(everything that does not need a browser; see test_viewer_browser.py for that)."""

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings

from spatialmech import catalog
from spatialmech.kinematics.closure import Configuration, CorrectionResult, joint_points
from spatialmech.kinematics.backend import closure_residual
from spatialmech.kinematics.motion import generic_configuration
from spatialmech.model.joints import R
from spatialmech.model.mechanism import Limb, Mechanism
from spatialmech.kinematics.motion import sample_motion
from spatialmech.present.viewer import (
    ARC_RADIUS0,
    ARC_RADIUS_STEP,
    AXIS_HALF,
    DIV_ID,
    drawing,
    viewer_figure,
    viewer_html,
    write_viewer,
)
from spatialmech.interfaces.cmd_view import view

from .conftest import seeds

#: Closure tolerance of a returned configuration: nondimensional residual of closure.correct
#: is < 1e-12; in SI with L <= 16 (5-CS) the residual norm stays well below this.
CLOSE_TOL = 1e-9


def _rotation_angle(D):
    return math.acos(np.clip((np.trace(D[:3, :3]) - 1) / 2, -1, 1))


@pytest.fixture(scope="module")
def motions():
    """Short demonstration loops of the models the tests look at (computed once)."""
    out = {}
    for name in ("four-sps-cu", "three-rrr-sm", "five-cs-1", "bennett"):
        mech = catalog.build(name)
        out[name] = (mech, sample_motion(mech, n=12))
    return out


# ------------------------------------------------------------------ sample_motion
@pytest.mark.parametrize("name", ["four-sps-cu", "three-rrr-sm", "five-cs-1", "bennett"])
def test_demo_motion_closes_everywhere_and_moves_the_platform(motions, name):
    mech, cs = motions[name]
    assert len(cs) == 12
    assert np.allclose(cs[0].q, 0) and np.allclose(cs[0].D, np.eye(4))  # starts at the reference
    for c in cs:
        assert np.linalg.norm(closure_residual(mech, c)) < CLOSE_TOL
    moved = [np.linalg.norm(c.D - np.eye(4)) for c in cs]
    assert max(moved) > 1e-2


def test_demo_motion_is_an_exact_out_and_back_loop(motions):
    """Frame i sits at s_i = A sin(2 pi i / n); frames with equal s are the same configuration,
    so the loop closes exactly (n = 12: frames 1 and 5, 7 and 11; 3 and 9 are the extremes)."""
    _, cs = motions["bennett"]
    assert cs[1] is cs[5] and cs[2] is cs[4] and cs[7] is cs[11] and cs[0] is cs[6]
    assert cs[3] is not cs[9]
    assert len({id(c) for c in cs}) == 7  # 0, +-1/2, +-sqrt(3)/2, +-1 of the amplitude


def test_demo_motion_amplitude_is_the_platform_arc_length():
    """For the spherical 3-RRR the platform only rotates, so the walk parameter is the arc
    length of the rotation: the extreme frame is turned by ~amplitude rad (a path on SO(3) is
    never shorter than the rotation angle it reaches: angle <= amplitude, 5 % tolerance below
    for the projected, non-geodesic path and 1 % above for predictor overshoot)."""
    mech = catalog.build("three-rrr-sm")
    for amp in (0.1, 0.35):
        cs = sample_motion(mech, n=8, amplitude=amp)
        ang = _rotation_angle(cs[2].D)  # s = +amplitude
        assert 0.95 * amp <= ang <= 1.01 * amp
        assert np.allclose(cs[2].D[:3, 3], 0, atol=1e-12)  # the centre stays put


def test_demo_motion_seed_picks_a_direction_for_multi_dof():
    mech = catalog.build("four-sps-cu")  # 4 DOF
    a = sample_motion(mech, n=4, seed=0)[1].D
    b = sample_motion(mech, n=4, seed=1)[1].D
    assert np.linalg.norm(a - b) > 1e-3
    assert np.allclose(sample_motion(mech, n=4, seed=0)[1].D, a, atol=1e-14)  # reproducible


@pytest.mark.parametrize(
    "kwargs, field",
    [({"n": 1}, "n:"), ({"n": 2.5}, "n:"), ({"amplitude": float("nan")}, "amplitude:"),
     ({"amplitude": -0.1}, "amplitude:"), ({"start": Configuration(np.zeros(3), np.eye(4))}, "start.q:")],
)
def test_demo_motion_rejects_bad_arguments(kwargs, field):
    with pytest.raises(ValueError, match=f"^{field}"):
        sample_motion(catalog.build("bennett"), **kwargs)


def test_demo_motion_start_off_the_manifold_is_refused():
    mech = catalog.build("bennett")
    q = np.zeros(len(mech.freedom_refs))
    q[0] = 0.05  # slightly off: corrected onto the manifold first, the loop starts there
    cs = sample_motion(mech, start=Configuration(q, np.eye(4)), n=4)
    assert np.linalg.norm(closure_residual(mech, cs[0])) < CLOSE_TOL
    q[1] = np.nan
    with pytest.raises(ValueError, match=r"^start\.q: contains NaN"):
        sample_motion(mech, start=Configuration(q, np.eye(4)), n=4)


def test_demo_motion_reports_failed_corrections(monkeypatch):
    """Non-convergence is never silent: at the start it is a ValueError (the start is not on
    the manifold), during the walk a RuntimeError after step halving down to MIN_STEP."""
    import spatialmech.kinematics.motion as motion

    real = motion.correct
    mech = catalog.build("bennett")
    def failing(m, c, **kw):
        return CorrectionResult(c, False, 50, 1.0)
    monkeypatch.setattr(motion, "correct", failing)
    with pytest.raises(ValueError, match=r"^start: not on"):
        sample_motion(mech, n=4)
    calls = []

    def first_only(m, c, **kw):
        calls.append(1)
        return real(m, c, **kw) if len(calls) == 1 else failing(m, c)

    monkeypatch.setattr(motion, "correct", first_only)
    with pytest.raises(RuntimeError, match="did not converge"):
        sample_motion(mech, n=4)
    # steps MAX_STEP / 2^k tried while >= MIN_STEP: floor(log2(MAX_STEP / MIN_STEP)) + 1 attempts
    assert len(calls) - 1 == math.floor(math.log2(motion.MAX_STEP / motion.MIN_STEP)) + 1 == 9


def test_demo_motion_of_a_structure_is_refused():
    """Two R joints with different axes hold the platform: nothing can move."""
    ez, ex = np.eye(3)[2], np.eye(3)[0]
    mech = Mechanism("locked", (Limb("a", (R("A", np.zeros(3), ez),)), Limb("b", (R("B", np.ones(3), ex),))))
    with pytest.raises(ValueError, match=r"^mech: no motion"):
        sample_motion(mech, n=4)


# ------------------------------------------------------------------ drawing
def test_drawing_four_sps_cu_reference():
    """Paper B geometry (a = 0.1, b = 0.2, z0 = 0.2 m): base square of side 0.4 m, platform
    square of side 0.2 m at z = 0.2, 7 axis segments (4 leg slides, the C axis and the two U
    axes), all centred on their joints, of length 2 * AXIS_HALF * L."""
    mech = catalog.build("four-sps-cu")
    d = drawing(mech, Configuration.reference(mech))
    assert len(d.limbs) == 5
    def side(poly):
        return np.linalg.norm(np.diff(poly, axis=0), axis=1)
    assert d.base.shape == (5, 3) and np.allclose(side(d.base), 0.4, atol=1e-12)
    assert d.platform.shape == (5, 3) and np.allclose(side(d.platform), 0.2, atol=1e-12)
    assert np.allclose(d.platform[:, 2], 0.2) and np.allclose(d.base[:, 2], 0.0)
    assert d.axes.shape == (7, 2, 3)
    lengths = np.linalg.norm(d.axes[:, 1] - d.axes[:, 0], axis=1)
    assert np.allclose(lengths, 2 * AXIS_HALF * mech.characteristic_length)
    mids = d.axes.mean(axis=1)
    assert all(np.min(np.linalg.norm(d.joints - m, axis=1)) < 1e-12 for m in mids)
    dirs = (d.axes[:, 1] - d.axes[:, 0]) / lengths[:, None]
    assert sum(abs(v @ [0, 0, 1]) > 1 - 1e-12 for v in dirs) == 1  # the C axis along z
    assert np.allclose(d.platform_point, [0, 0, 0.2]) and np.allclose(d.platform_frame, np.eye(3))
    json.dumps(d.to_dict())


def test_drawing_spherical_linkage_links_are_arcs_on_spheres(motions):
    """3-RRR (paper C): every joint is at the centre, so each limb is drawn as spokes along the
    joint axes and great-circle arcs of radius (ARC_RADIUS0 + k ARC_RADIUS_STEP) L; the arcs'
    ends lie on the joint axes of the current configuration (checked at every frame)."""
    mech, cs = motions["three-rrr-sm"]
    L = mech.characteristic_length
    for c in cs:
        d = drawing(mech, c)
        for k, poly in enumerate(d.limbs):
            r = np.linalg.norm(poly, axis=1)
            on_sphere = r[r > 1e-12]
            assert np.allclose(on_sphere, (ARC_RADIUS0 + ARC_RADIUS_STEP * k) * L)
            # the spoke ends (points right after / before the centre) are along drawn axes
            axis_dirs = (d.axes[:, 1] - d.axes[:, 0]) / np.linalg.norm(d.axes[:, 1] - d.axes[:, 0], axis=1)[:, None]
            for i in np.flatnonzero(r < 1e-12):
                for nb in (i - 1, i + 1):
                    if 0 <= nb < len(poly) and r[nb] > 1e-12:
                        u = poly[nb] / r[nb]
                        assert np.max(np.abs(axis_dirs @ u)) > 1 - 1e-9


def test_drawing_platform_joints_follow_the_platform(motions):
    """On the closure manifold each limb's last joint point is the platform displacement of its
    reference position, so the platform outline is rigid: its edge lengths never change."""
    for name in ("four-sps-cu", "five-cs-1", "bennett"):
        mech, cs = motions[name]
        ref = np.array([p[-1] for p in joint_points(mech, Configuration.reference(mech))])
        edges0 = np.linalg.norm(np.diff(drawing(mech, cs[0]).platform, axis=0), axis=1)
        for c in cs:
            last = np.array([p[-1] for p in joint_points(mech, c)])
            assert np.allclose(last, ref @ c.D[:3, :3].T + c.D[:3, 3], atol=1e-9)
            edges = np.linalg.norm(np.diff(drawing(mech, c).platform, axis=0), axis=1)
            assert np.allclose(edges, edges0, atol=1e-9)


@settings(max_examples=10, deadline=None)
@given(seeds)
def test_drawing_invariants_at_generic_configurations(seed):
    """Stewart platform at random closed configurations: finite geometry, fixed base, leg
    polylines from base joint to platform joint, platform frame orthonormal."""
    mech = catalog.build("stewart-6sps")
    c = generic_configuration(mech, seed=seed % 1000, step=0.15, steps=2)
    d = drawing(mech, c)
    ref = drawing(mech, Configuration.reference(mech))
    assert np.all(np.isfinite(d.points()))
    assert np.allclose(d.base, ref.base)
    assert np.allclose(d.platform_frame.T @ d.platform_frame, np.eye(3), atol=1e-12)
    pts = joint_points(mech, c)
    for poly, p in zip(d.limbs, pts, strict=True):
        assert np.allclose(poly[0], p[0]) and np.allclose(poly[-1], p[-1])


def test_drawing_rejects_mismatched_configurations():
    mech = catalog.build("bennett")
    with pytest.raises(ValueError, match=r"^config.q: expected shape"):
        drawing(mech, Configuration(np.zeros(2), np.eye(4)))
    D = np.eye(4)
    D[0, 3] = np.nan
    with pytest.raises(ValueError, match=r"^config.D: contains NaN"):
        drawing(mech, Configuration(np.zeros(4), D))
    with pytest.raises(ValueError, match=r"^config: expected a Configuration"):
        drawing(mech, np.zeros(4))


# ------------------------------------------------------------------ figure
def _numbers(trace):
    vals = []
    for ax in "xyz":
        v = trace[ax]
        vals += [x for x in (v if v is not None else ()) if x is not None]
    return np.array(vals, float)


def test_figure_has_one_frame_per_configuration_and_a_slider(motions):
    mech, cs = motions["four-sps-cu"]
    fig = viewer_figure(mech, cs)
    assert len(fig.frames) == len(cs) == len(fig.layout.sliders[0].steps)
    assert [f.name for f in fig.frames] == [str(k) for k in range(len(cs))]
    assert [list(s.args[0]) for s in fig.layout.sliders[0].steps] == [[str(k)] for k in range(len(cs))]
    assert [b.label for b in fig.layout.updatemenus[0].buttons] == ["Play", "Pause"]
    assert all(s.args[1]["frame"]["redraw"] for s in fig.layout.sliders[0].steps)  # 3-D needs redraw
    # frame 0 is what is drawn before any interaction
    for k, idx in enumerate(fig.frames[0].traces):
        assert np.array_equal(_numbers(fig.frames[0].data[k]), _numbers(fig.data[idx]))


def test_figure_geometry_changes_between_frames_and_has_no_nan(motions):
    mech, cs = motions["bennett"]
    fig = viewer_figure(mech, cs)
    for f in fig.frames:
        for t in f.data:
            assert np.all(np.isfinite(_numbers(t)))
    for t in fig.data:
        assert np.all(np.isfinite(_numbers(t)))
    a = np.concatenate([_numbers(t) for t in fig.frames[0].data])
    b = np.concatenate([_numbers(t) for t in fig.frames[3].data])  # s = +amplitude
    assert a.shape == b.shape and np.max(np.abs(a - b)) > 0.05  # metres; the 1.5 m coupler turns ~20 deg
    c = np.concatenate([_numbers(t) for t in fig.frames[6].data])  # back at the start
    assert np.allclose(a, c)


def test_figure_marks_task_positions_and_singular_points(motions):
    """Paper A's seven task positions (table 9) and two singular points, both given as a
    point and as a Configuration; the scene box is a cube containing everything."""
    mech, cs = motions["five-cs-1"]
    sing = [np.array([1.0, 2.0, 3.0]), cs[3]]
    fig = viewer_figure(mech, cs, title="t", task_positions=mech.positions, singular_points=sing)
    by_name = {t.name: t for t in fig.data}
    tp = by_name["task positions"]
    assert list(tp.text) == [f"P{k}" for k in range(1, 8)]
    assert np.allclose(np.c_[tp.x, tp.y, tp.z], [p.p for p in mech.positions])
    sp = by_name["singular points"]
    expected = cs[3].D[:3, :3] @ mech.platform_point + cs[3].D[:3, 3]
    assert np.allclose(np.c_[sp.x, sp.y, sp.z], [[1, 2, 3], expected])
    sc = fig.layout.scene
    spans = [sc[f"{a}axis"].range[1] - sc[f"{a}axis"].range[0] for a in "xyz"]
    assert sc.aspectmode == "cube" and np.allclose(spans, spans[0])
    for t in list(fig.data) + [t for f in fig.frames for t in f.data]:
        if t.x is None:
            continue
        for a in "xyz":
            v = np.array([x for x in t[a] if x is not None], float)
            lo, hi = sc[f"{a}axis"].range
            assert np.all((v >= lo) & (v <= hi))
    assert fig.layout.scene.xaxis.title.text == "x [length unit not stated]"  # paper A's lengths have no unit


@pytest.mark.parametrize(
    "kwargs, match",
    [({"configs": []}, "^configs: at least one"),
     ({"task_positions": [np.zeros(3)]}, r"^task_positions\[0\]: expected a Pose"),
     ({"singular_points": [[0.0, np.nan, 0.0]]}, r"^singular_points\[0\]: contains NaN"),
     ({"singular_points": [[0.0, 1.0]]}, r"^singular_points\[0\]: expected shape")],
)
def test_figure_rejects_bad_input(kwargs, match):
    mech = catalog.build("bennett")
    args = {"configs": [Configuration.reference(mech)], **kwargs}
    with pytest.raises(ValueError, match=match):
        viewer_figure(mech, args.pop("configs"), **args)


# ------------------------------------------------------------------ page
def test_page_is_self_contained(tmp_path, motions):
    """plotly.js is inlined (several MB), no script is loaded from the network."""
    mech, cs = motions["bennett"]
    info = write_viewer(tmp_path / "b.html", mech, cs, title="Bennett <demo>")
    page = (tmp_path / "b.html").read_text(encoding="utf-8")
    assert info.frames == len(cs) and info.bytes == (tmp_path / "b.html").stat().st_size > 3_000_000
    assert f'id="{DIV_ID}"' in page and "<title>Bennett &lt;demo&gt;</title>" in page
    tags = re.findall(r"<script[^>]*>", page)
    assert len(tags) >= 2 and not any("src=" in t for t in tags)  # every script is inline
    assert "plotly.js v" in page  # the library itself is in the page
    assert json.loads(json.dumps(info.to_dict())) == {"out": str(tmp_path / "b.html"), "frames": len(cs),
                                                      "bytes": info.bytes, "plotly": "inline"}
    div = viewer_html(mech, cs, full_html=False, include_plotlyjs=False)
    assert len(div) < 200_000 and "<html" not in div


def test_smaller_pages_load_plotly_once_from_a_directory_or_the_cdn(tmp_path, motions):
    """--plotly directory: two small pages share one plotly.min.js written next to them (it is
    written once: its modification time does not change); cdn: a small page with one script
    from cdn.plot.ly."""
    mech, cs = motions["bennett"]
    a = write_viewer(tmp_path / "a.html", mech, cs, plotly="directory")
    js = tmp_path / "plotly.min.js"
    stamp = js.stat().st_mtime_ns
    b = write_viewer(tmp_path / "b.html", mech, cs, plotly="directory")
    assert js.stat().st_mtime_ns == stamp and js.stat().st_size > 3_000_000 and "plotly.js v" in js.read_text()
    for info in (a, b):
        page = Path(info.out).read_text(encoding="utf-8")
        assert info.plotly == "directory" and info.bytes < 1_000_000
        srcs = [t for t in re.findall(r"<script[^>]*>", page) if "src=" in t]
        assert len(srcs) == 1 and 'src="plotly.min.js"' in srcs[0]
    c = write_viewer(tmp_path / "c.html", mech, cs, plotly="cdn")
    srcs = [t for t in re.findall(r"<script[^>]*>", Path(c.out).read_text(encoding="utf-8")) if "src=" in t]
    assert c.bytes < 1_000_000 and len(srcs) == 1 and "cdn.plot.ly" in srcs[0]
    with pytest.raises(ValueError, match="plotly: expected one of inline, cdn, directory"):
        write_viewer(tmp_path / "d.html", mech, cs, plotly="web")


# ------------------------------------------------------------------ CLI
def test_cli_view_json(tmp_path):
    out = tmp_path / "v.html"
    r = CliRunner().invoke(view, ["three-rrr-sm", "--frames", "6", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.output)
    assert d == {"schema_version": "2", "command": "view", "model": "three-rrr-sm", "length_unit": "m",
                 "out": str(out), "frames": 6, "bytes": out.stat().st_size, "plotly": "inline", "motion": "demo", "note": ""}


@pytest.mark.slow
def test_cli_view_text_and_task_positions(tmp_path):
    out = tmp_path / "a.html"
    r = CliRunner().invoke(view, ["five-cs-2", "--frames", "4", "--out", str(out)])
    assert r.exit_code == 0 and r.output.startswith(f"wrote {out} (4 frames")
    assert '"task positions"' in out.read_text(encoding="utf-8")


@pytest.mark.parametrize(
    "args, msg",
    [(["no-such-model", "--out", "x.html"], "error: no-such-model: not a file and not a ready-made model"),
     (["bennett", "--out", "/nonexistent-dir/x.html"], "error: --out: cannot write")],
)
def test_cli_view_errors_are_one_line(args, msg):
    r = CliRunner().invoke(view, args)
    assert r.exit_code == 2 and r.output.startswith(msg) and r.output.count("\n") == 1


def test_cli_view_rejects_too_few_frames(tmp_path):
    r = CliRunner().invoke(view, ["bennett", "--frames", "1", "--out", str(tmp_path / "x.html")])
    assert r.exit_code == 2 and "--frames" in r.output
