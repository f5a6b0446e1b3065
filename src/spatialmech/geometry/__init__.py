"""Geometry core: screws (``(direction ; moment)``), rotations with named Euler sequences."""

from . import rotations, screws
from .rotations import euler_matrix, exp_twist, log_transform, matrix_euler, transform
from .screws import (
    DELTA,
    axis_screw,
    reciprocal_basis,
    reciprocal_product,
    translation_screw,
)

__all__ = [
    "DELTA",
    "axis_screw",
    "euler_matrix",
    "exp_twist",
    "log_transform",
    "matrix_euler",
    "reciprocal_basis",
    "reciprocal_product",
    "rotations",
    "screws",
    "transform",
    "translation_screw",
]
