"""Issue 27: the 4-SPS/CU's default ``fk --all`` (paper B's closed-form search) is proven
complete by the Study homotopy, with the closed form's own solutions in its own order."""

from __future__ import annotations

import numpy as np
import pytest

import spatialmech as sm

LEGS = [0.216745, 0.23896, 0.227321, 0.206933]


@pytest.mark.slow
def test_four_sps_cu_default_is_proven_and_keeps_the_closed_forms_answer():
    mech = sm.load_model("four-sps-cu")
    proven = sm.fk(mech, LEGS, all_solutions=True)
    search = sm.fk(mech, LEGS, all_solutions=True, seeds=512)  # the same search, not proven
    assert proven.engine == search.engine == "closed-form"
    assert proven.complete and not search.complete
    assert proven.completeness.startswith("proven: the closed form's 4 mode(s) are exactly the real solutions")
    assert len(proven.modes) == len(search.modes) == 4
    for a, b in zip(proven.modes, search.modes, strict=True):  # same poses, same order
        assert np.allclose(a.pose.R, b.pose.R, atol=1e-12) and np.allclose(a.pose.p, b.pose.p, atol=1e-12)
    hom = sm.fk(mech, LEGS, all_solutions=True, method="homotopy")
    assert hom.complete and len(hom.modes) == 4
    d = proven.to_dict()
    assert d["complete"] is True and d["n_certified"] == 4


def test_four_sps_cu_proven_empty_set_is_an_answer_not_an_error():
    """Leg lengths with no real assembly: the homotopy proves the empty set, so the text output
    says so (exit 0) instead of 'no assembly found ... not a proof'; the JSON agrees."""
    import json

    from click.testing import CliRunner

    from spatialmech.interfaces.cli import cli

    args = ["fk", "four-sps-cu", "--actuators", "0.21,0.25,0.22,0.19", "--all"]
    r = CliRunner().invoke(cli, args, catch_exceptions=False)
    assert r.exit_code == 0, r.output
    assert "four-sps-cu: 0 real assembly modes" in r.output and "complete (proven)" in r.output
    assert "not a proof" not in r.output
    d = json.loads(CliRunner().invoke(cli, [*args, "--json"], catch_exceptions=False).output)
    assert d["n_solutions"] == 0 and d["complete"] is True
