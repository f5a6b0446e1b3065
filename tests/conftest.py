import os

import numpy as np
import pytest
from hypothesis import settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from spatialmech.geometry.rotations import transform

# No per-example deadline (machines differ in load); in CI the examples are derandomised so a
# run is reproducible (locally they stay random, to keep finding new cases).
settings.register_profile("spatialmech", deadline=None)
settings.register_profile("spatialmech-ci", deadline=None, derandomize=True)
settings.load_profile("spatialmech-ci" if os.environ.get("CI") else "spatialmech")


@pytest.fixture(scope="session")
def schema_validator():
    """``schema_validator(command)``: a JSON Schema validator of ``command``'s shipped schema
    (``spatialmech/interfaces/schemas/``), its references to ``common.schema.json`` resolved."""
    from jsonschema import Draft202012Validator
    from referencing import Registry, Resource

    from spatialmech.interfaces.common import load_schema

    common = load_schema("common")
    registry = Registry().with_resource(common["$id"], Resource.from_contents(common))
    return lambda command: Draft202012Validator(load_schema(command), registry=registry)


@pytest.fixture(scope="session")
def studio_ok(schema_validator):
    """``studio_ok(r)``: a studio answer (an HTTP response, or a ``studio --json`` document)
    checked: status 200, the envelope, the studio schema and the unit rule; returns the document."""
    from spatialmech.serialize import unit_rule_violations

    validator = schema_validator("studio")

    def check(r) -> dict:
        if hasattr(r, "status_code"):
            assert r.status_code == 200, r.text
            r = r.json()
        assert r["command"] == "studio" and r["schema_version"] == "2"
        errors = [(list(e.absolute_path), e.message[:200]) for e in validator.iter_errors(r)]
        assert not errors, errors[:3]
        assert unit_rule_violations(r) == []
        return r

    return check


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


finite = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
vec3 = st.lists(finite, min_size=3, max_size=3).map(np.array)
screw6 = st.lists(finite, min_size=6, max_size=6).map(np.array)
seeds = st.integers(0, 2**32 - 1)


def random_transform(seed: int) -> np.ndarray:
    r = np.random.default_rng(seed)
    return transform(Rotation.random(random_state=seed).as_matrix(), r.uniform(-5, 5, 3))


@pytest.fixture(scope="session")
def demo_report(tmp_path_factory):
    """``spatialmech demo`` built once for the whole session (about 45 s): ``(out_dir, results)``.
    The report tests, the regression test of its rows and the JSON-schema test of the ``demo``
    command all read this one run; nothing may modify ``results``."""
    from spatialmech.present.report import build_demo

    out = tmp_path_factory.mktemp("demo")
    return out, build_demo(out, progress=False)
