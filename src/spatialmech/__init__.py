"""spatialmech: kinematic analysis and synthesis of spatial linkages and parallel mechanisms.

Conventions (written once, see docs/conventions.md): screws are ``(direction ; moment)``
6-vectors; SI units and radians inside the library, degrees only at the edges (files, CLI,
plots), always labelled; Euler sequences always named explicitly (``"ZXY"`` intrinsic,
``"zxy"`` extrinsic, as in ``scipy.spatial.transform``).

Every analysis by a short name (one page: docs/api.md; the functions are in
:mod:`spatialmech.api`): ``sm.load_model``, ``sm.mobility``, ``sm.ik``, ``sm.fk``,
``sm.jacobian``, ``sm.velocity``, ``sm.statics``, ``sm.stiffness``, ``sm.singularity``, ``sm.workspace``, ``sm.parasitic``,
``sm.track``,
``sm.defects``, ``sm.synth_rccc``, ``sm.synth_cs``, ``sm.screen``, ``sm.report``, ``sm.demo``, ``sm.view``,
``sm.export``, ``sm.validate``, ``sm.singularity_slice``, ``sm.studio_session``, ``sm.studio_app``.  Each takes a
:class:`Mechanism`, a ready-made model name or a TOML file path, checks its arguments
(``TypeError``, :class:`InputError`) and returns a result whose ``to_dict()`` is its JSON.

Quick example::

    >>> import spatialmech as sm
    >>> r = sm.mobility("four-sps-cu")
    >>> (r.dof, r.motion)
    (4, 'RxRyRzTz')
    >>> sm.ik("four-sps-cu", ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46)), degrees=True).reachable
    True
"""

from importlib.metadata import PackageNotFoundError, version

from . import results
from .api import (
    announce_compilation,
    default_tolerance,
    defects,
    demo,
    dj_table,
    export,
    fk,
    ik,
    jacobian,
    load_model,
    maps,
    mobility,
    mobility_modes,
    models,
    parasitic,
    report,
    singularity,
    singularity_slice,
    statics,
    stiffness,
    stiffness_map,
    studio_session,
    suggest_task_grid,
    screen,
    synth_cs,
    synth_rccc,
    tolerances,
    track,
    validate,
    velocity,
    view,
    workspace,
)
from .errors import ConvergenceError, InputError, SearchTooLargeError, SpatialmechError, UnknownNameError
from .kinematics.closure import Configuration
from .model import (
    C,
    H,
    Joint,
    Limb,
    Mechanism,
    Mode,
    ModelFileError,
    P,
    Pose,
    R,
    S,
    Sm,
    U,
    dump,
    dumps,
    load,
    loads,
)
from .results import Progress, TrackStatus

try:
    __version__ = version("spatialmech")
except PackageNotFoundError:  # pragma: no cover
    __version__ = "0+unknown"

__all__ = [
    "C",
    "Configuration",
    "ConvergenceError",
    "H",
    "InputError",
    "Joint",
    "Limb",
    "Mechanism",
    "Mode",
    "ModelFileError",
    "P",
    "Pose",
    "Progress",
    "R",
    "S",
    "SearchTooLargeError",
    "Sm",
    "SpatialmechError",
    "TrackStatus",
    "U",
    "UnknownNameError",
    "__version__",
    "announce_compilation",
    "closed_forms",
    "default_tolerance",
    "defects",
    "demo",
    "dj_table",
    "dump",
    "dumps",
    "export",
    "fk",
    "ik",
    "jacobian",
    "load",
    "load_model",
    "loads",
    "maps",
    "mobility",
    "mobility_modes",
    "models",
    "parasitic",
    "report",
    "results",
    "screen",
    "singularity",
    "singularity_slice",
    "statics",
    "stiffness",
    "stiffness_map",
    "studio_app",
    "studio_session",
    "suggest_task_grid",
    "synth_cs",
    "synth_rccc",
    "tolerances",
    "track",
    "validate",
    "velocity",
    "view",
    "workspace",
]


#: Names resolved on first use (:func:`__getattr__`), listed by ``dir(spatialmech)``.
_LAZY = ("closed_forms", "studio_app")


def __getattr__(name: str):
    """``sm.closed_forms``: the closed-form kernels (imported on first use: they load scipy.stats);
    ``sm.studio_app``: the design studio's web app, a driver (FastAPI) that lives in
    :mod:`spatialmech.interfaces.studio.app` above the API, imported on first use."""
    import importlib

    if name == "closed_forms":
        return importlib.import_module(".kinematics.closed_forms", __name__)
    if name == "studio_app":
        return importlib.import_module(".interfaces.studio.app", __name__).studio_app
    raise AttributeError(f"module 'spatialmech' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})
