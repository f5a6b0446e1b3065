"""JSON output of results: NumPy scalars and arrays become plain numbers and lists."""

from __future__ import annotations

import numpy as np

__all__ = ["json_default"]


def json_default(o):
    """``json.dumps(..., default=json_default)``: NumPy arrays and scalars to Python values."""
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")
