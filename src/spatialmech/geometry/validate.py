"""Input checks shared by the geometry core, the model and the file reader.

Every check raises ``ValueError`` whose message starts with the name of the offending field,
so the caller (a file reader, a CLI) can show it as one line.
"""

from __future__ import annotations

import numpy as np

#: Tolerance on ``| |v| - 1 |`` for a vector declared to be a unit vector.
UNIT_ATOL = 1e-6


def as_finite_array(value, name: str, *, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """``value`` as a float array of the given shape with no NaN or infinity."""
    try:
        a = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: expected numbers, got {value!r}") from None
    if shape is not None and a.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name}: contains NaN or infinity")
    return a


def as_unit_vector(value, name: str, *, normalize: bool = False) -> np.ndarray:
    """A 3-vector that must be of unit length (or is normalised when ``normalize``)."""
    v = as_finite_array(value, name, shape=(3,))
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        raise ValueError(f"{name}: zero vector cannot be an axis")
    if normalize:
        return v / n
    if abs(n - 1.0) > UNIT_ATOL:
        raise ValueError(
            f"{name}: not a unit vector (|v| = {n:.6g}); normalise it"
            " (or set normalize_axes = true in a file)"
        )
    return v / n
