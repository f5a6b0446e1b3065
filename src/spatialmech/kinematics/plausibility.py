"""Plausibility of a position result: sizes far from the model's and negative leg lengths.

A forward or inverse position result may be exact and still implausible: a platform point a
thousand model sizes away (the actuator values typed in millimetres for a model in metres), an
actuator slide far longer than the model, or a leg of negative length on a model without joint
limits (an S-P-S leg "through" its own base joint).  :func:`plausibility_warnings` says so in
sentences for the result's ``warnings`` (JSON) and the ``warning: ...`` lines of the text;
nothing is refused.  A model with limits flags negative slides as outside them instead.

    >>> from spatialmech.catalog import build
    >>> m = build("stewart-6sps")
    >>> plausibility_warnings(m, points=[[0, 0, 1200.0]])[0][:40]
    'platform point 1.2e+03 m from the refere'
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from ..model.mechanism import Mechanism

__all__ = ["FAR_FACTOR", "has_limits", "plausibility_warnings"]

#: A platform point farther than this many characteristic lengths from the reference one, or an
#: actuator slide longer than this many, is implausible (a unit mistake?).
FAR_FACTOR = 100.0


def has_limits(mech: Mechanism) -> bool:
    """Whether any joint freedom of ``mech`` has limits (else "within limits" says nothing)."""
    return any(r.freedom.limits is not None for r in mech.freedom_refs)


def plausibility_warnings(mech: Mechanism, points: Iterable = (), slides: Mapping[str, float] | None = None
                          ) -> list[str]:
    """Sentences on an implausible result: a platform point (``points``, length unit) more than
    :data:`FAR_FACTOR` characteristic lengths from the reference platform point; a slide
    (``slides``: freedom id -> value, length unit) longer than that; a negative slide of a freedom
    without limits ("negative leg length")."""
    L, unit = mech.characteristic_length, mech.length_unit
    out: list[str] = []
    for p in points:
        d = float(np.linalg.norm(np.asarray(p, float) - mech.platform_point))
        if d > FAR_FACTOR * L:
            out.append(f"platform point {d:.3g} {unit} from the reference one, {d / L:.3g} times the size of "
                       f"{mech.name} ({L:.3g} {unit}): is the unit of the values wrong (the model is in {unit})?")
    slides = {fid: float(v) for fid, v in (slides or {}).items() if mech.freedom(fid).freedom.kind == "P"}
    big = {fid: v for fid, v in slides.items() if abs(v) > FAR_FACTOR * L}
    if big:
        top = max(abs(v) for v in big.values())
        out.append(f"{_listed(big, unit)}: up to {top / L:.3g} times the size of {mech.name} ({L:.3g} {unit}): "
                   f"is the unit of the values wrong (the model is in {unit})?")
    neg = {fid: v for fid, v in slides.items() if v < 0 and mech.freedom(fid).freedom.limits is None}
    if neg:
        out.append(f"negative leg length: {_listed(neg, unit)} (no joint limits in the model to refuse it; a real "
                   "leg's length is positive: give the model limits to flag it as outside them)")
    return out


def _listed(values: Mapping[str, float], unit: str) -> str:
    return ", ".join(f"{fid} = {v:.6g} {unit}" for fid, v in values.items())
