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
    "rotations",
    "screws",
    "DELTA",
    "axis_screw",
    "translation_screw",
    "reciprocal_product",
    "reciprocal_basis",
    "euler_matrix",
    "matrix_euler",
    "exp_twist",
    "log_transform",
    "transform",
]
