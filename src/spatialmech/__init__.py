"""spatialmech: kinematic analysis and synthesis of spatial linkages and parallel mechanisms.

Conventions (written once, see docs/conventions.md): screws are ``(direction ; moment)``
6-vectors; SI units and radians inside the library, degrees only at the edges (files, CLI,
plots), always labelled; Euler sequences always named explicitly (``"ZXY"`` intrinsic,
``"zxy"`` extrinsic, as in ``scipy.spatial.transform``).

Quick example::

    >>> import spatialmech as sm
    >>> mech = sm.load_model("four-sps-cu")
    >>> r = sm.mobility(mech)
    >>> (r.dof, r.motion)
    (4, 'RxRyRzTz')
"""

from importlib.metadata import PackageNotFoundError, version

from .analysis.mobility import mobility, mobility_modes
from .catalog import resolve as load_model
from .model import (
    C, H, Limb, Mechanism, Mode, ModelFileError, P, Pose, R, S, Sm, U, dump, dumps, load, loads,
)

try:
    __version__ = version("spatialmech")
except PackageNotFoundError:  # pragma: no cover
    __version__ = "0+unknown"

__all__ = [
    "__version__", "load_model", "mobility", "mobility_modes", "Mechanism", "Limb", "Mode", "Pose",
    "R", "P", "H", "C", "U", "S", "Sm", "load", "loads", "dump", "dumps", "ModelFileError",
]
