"""The viewer's animation frames built as plain dicts (issue 29: plotly's validated setters
took 3-4 s of the demo for 564 frames): the page content is the same as the validated
figure's, array for array."""

import json

import numpy as np

from spatialmech import catalog
from spatialmech.kinematics.motion import sample_motion
from spatialmech.present.viewer import DIV_ID, viewer_figure, viewer_figure_dict, viewer_html


def _canon(d):
    return json.dumps(d, sort_keys=True, default=str)


def test_plain_frames_are_the_validated_figures_dict():
    mech = catalog.build("five-cs-1")  # limbs, joint solids, a platform body, task positions
    configs = sample_motion(mech, n=6)
    kw = dict(title="t", task_positions=mech.positions, singular_points=[np.array([0.0, 0.0, 0.1])])
    ref = viewer_figure(mech, configs, **kw).to_dict()
    got = viewer_figure_dict(mech, configs, **kw)
    assert len(got["frames"]) == 6
    assert _canon(got) == _canon(ref)
    assert any(isinstance(v, dict) and "bdata" in v for tr in got["frames"][0]["data"] for v in tr.values())


def test_viewer_html_writes_the_frames_unvalidated_with_its_div():
    mech = catalog.build("stewart-6sps")
    configs = sample_motion(mech, n=4)
    page = viewer_html(mech, configs, full_html=False, include_plotlyjs=False)
    assert f'id="{DIV_ID}"' in page and page.count('"name":"') >= 4
    other = viewer_html(mech, configs, full_html=False, include_plotlyjs=False, div_id="v2", default_height="640px")
    assert 'id="v2"' in other and "640px" in other
