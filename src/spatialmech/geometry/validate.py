"""Input checks shared by the geometry core, the model and the file reader.

Every check raises ``ValueError`` whose message starts with the name of the offending field,
so the caller (a file reader, a CLI) can show it as one line.
"""

from __future__ import annotations

from typing import overload

import numpy as np

from ..errors import InputError
from .tolerances import DEFAULT, current

#: Tolerance on ``| |v| - 1 |`` for a vector declared to be a unit vector (the default of
#: :attr:`~spatialmech.geometry.tolerances.Tolerances.unit`; the one in force is used).
UNIT_ATOL = DEFAULT.unit


def _has_non_number(value, depth: int = 0) -> bool:
    """A boolean or a string anywhere in a (nested) list or tuple: not a number."""
    if isinstance(value, (bool, np.bool_, str, bytes)):
        return True
    if isinstance(value, (list, tuple)) and depth < 4:
        return any(_has_non_number(v, depth + 1) for v in value)
    return False


def _short(value, width: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


def as_finite_array(value, name: str, *, shape: tuple[int, ...] | None = None, max_abs: float | None = None) -> np.ndarray:
    """``value`` as a float array of the given shape with no NaN or infinity (and, with
    ``max_abs``, no entry larger than that in magnitude).  Booleans and strings are not numbers
    (``[True, 0, 0]`` and ``"1.5"`` are refused)."""
    if not isinstance(value, np.ndarray) and _has_non_number(value):
        raise InputError(f"{name}: expected numbers, got {_short(value)}")
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected numbers, got {_short(value)}") from None
    if raw.dtype.kind in "bUSVO" and not (raw.dtype.kind == "O" and not _has_non_number(raw.tolist())):
        raise InputError(f"{name}: expected numbers, got {_short(value)}")
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            a = np.asarray(raw, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name}: expected numbers, got {_short(value)}") from None
    if shape is not None and a.shape != shape:
        raise InputError(f"{name}: expected shape {shape}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise InputError(f"{name}: contains NaN or infinity (or a number too large for a float)")
    if max_abs is not None and a.size and float(np.max(np.abs(a))) > max_abs:
        raise InputError(f"{name}: {float(np.max(np.abs(a))):.3g} is beyond the supported magnitude {max_abs:g}")
    return a


@overload
def as_model_number(value, name: str, *, shape: tuple[()] = ()) -> float: ...
@overload
def as_model_number(value, name: str, *, shape: tuple[int, *tuple[int, ...]]) -> np.ndarray: ...
@overload
def as_model_number(value, name: str, *, shape: None) -> np.ndarray | float: ...
def as_model_number(value, name: str, *, shape: tuple[int, ...] | None = ()) -> np.ndarray | float:
    """A number (or array) typed into a model: finite and at most
    :attr:`~spatialmech.geometry.tolerances.Tolerances.max_input` in magnitude."""
    a = as_finite_array(value, name, shape=shape, max_abs=current().max_input)
    return float(a) if a.shape == () else a


def as_unit_vector(value, name: str, *, normalize: bool = False) -> np.ndarray:
    """A 3-vector that must be of unit length (or is normalised when ``normalize``)."""
    v = as_finite_array(value, name, shape=(3,))
    n = float(np.linalg.norm(v / max(float(np.max(np.abs(v))), 1e-300)) * np.max(np.abs(v)))  # no overflow
    if not n > 0:  # any nonzero direction can be normalised (its length is not a length)
        raise InputError(f"{name}: zero vector cannot be an axis")
    if normalize:
        return v / n
    if abs(n - 1.0) > current().unit:
        raise InputError(
            f"{name}: not a unit vector (|v| = {n:.6g}); normalise it"
            " (or set normalize_axes = true in a file)"
        )
    return v / n
