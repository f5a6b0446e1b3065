"""Numbers as a reader sees them: round-off printed as 0.

One helper for the text outputs: a value whose size is round-off against the scale it is read
at (``ROUNDOFF`` times the largest entry of its matrix, or 1) prints as ``0`` rather than
``-5.00000e-16``; negative zero prints as ``0`` too.  Nothing here changes a computed value, only
how it is printed (JSON keeps every digit).
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

__all__ = ["ROUNDOFF", "UNSTATED_UNIT", "fmt_number", "fmt_numbers", "unit_label"]

#: The length unit of a model whose source states none (paper A's linkages).
UNSTATED_UNIT = "unit"


def unit_label(unit: str) -> str:
    """The length unit as an axis or column label shows it: ``"m"`` stays ``"m"``; a unit the
    model's source does not state (:data:`UNSTATED_UNIT`) reads ``"length unit not stated"``
    rather than the placeholder ``"unit"``."""
    return "length unit not stated" if unit == UNSTATED_UNIT else unit


#: Relative size below which a printed number is round-off (a few hundred ulps of double).
ROUNDOFF = 1e-13


def fmt_number(x: float, spec: str = ".4g", *, scale: float = 1.0) -> str:
    """``x`` formatted with ``spec``, or ``"0"`` (padded as ``spec`` would pad a 0) when
    ``|x| <= ROUNDOFF * scale``.

    Parameters
    ----------
    x : float
        The value.
    spec : str
        A format spec (``"+.5e"``, ``".4g"``, ``"10.3f"``).
    scale : float
        The size the value is read against (the largest entry of its matrix).

    Returns
    -------
    str
        The formatted value.
    """
    v = float(x)
    if np.isfinite(v) and abs(v) <= ROUNDOFF * max(abs(float(scale)), np.finfo(float).tiny):
        zero = format(0.0, spec)
        return zero.replace("+0", " 0", 1) if "+" in spec else zero
    return format(v, spec)


def fmt_numbers(xs: Iterable[float], spec: str = ".4g", *, scale: float | None = None, sep: str = " ") -> str:
    """The values of ``xs`` joined by ``sep``, round-off against ``scale`` (default: their
    largest size) printed as 0 (:func:`fmt_number`)."""
    vals = [float(x) for x in xs]
    finite = [abs(v) for v in vals if np.isfinite(v)]
    s = max(finite, default=1.0) if scale is None else scale
    return sep.join(fmt_number(v, spec, scale=s) for v in vals)
