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
``sm.export``, ``sm.validate``, ``sm.singularity_slice``, ``sm.studio_session``, ``sm.studio_app``,
``sm.studio`` (the studio as a Jupyter widget).  Each takes a
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

from typing import TYPE_CHECKING

from . import results
from .errors import ConvergenceError, InputError, SearchTooLargeError, SpatialmechError, UnknownNameError
from .results import Progress, TrackStatus

if TYPE_CHECKING:  # what mypy sees; at run time :func:`__getattr__` imports these on first use
    from .api import (
        accuracy,
        announce_compilation,
        default_tolerance,
        defects,
        demo,
        dj_table,
        first_run,
        export,
        fk,
        ik,
        inverse_dynamics,
        jacobian,
        load_model,
        maps,
        mobility,
        mobility_modes,
        models,
        parasitic,
        report,
        screen,
        singularity,
        singularity_slice,
        statics,
        statics_along,
        stiffness,
        stiffness_map,
        studio_session,
        suggest_task_grid,
        synth_cs,
        synth_rccc,
        tolerances,
        track,
        validate,
        velocity,
        view,
        workspace,
    )
    from .interfaces.studio.app import studio_app
    from .interfaces.studio.widget import studio
    from .kinematics import closed_forms
    from .kinematics.closure import Configuration
    from .model import (C, H, Joint, Limb, Mechanism, Mode, ModelFileError, P, Pose, R, S, Sm, U, dump, dumps, load, loads,
                        serial_from_dh)

    __version__: str

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
    "accuracy",
    "announce_compilation",
    "closed_forms",
    "default_tolerance",
    "defects",
    "demo",
    "dj_table",
    "dump",
    "dumps",
    "export",
    "first_run",
    "fk",
    "ik",
    "inverse_dynamics",
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
    "serial_from_dh",
    "singularity",
    "singularity_slice",
    "statics",
    "statics_along",
    "stiffness",
    "stiffness_map",
    "studio",
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


#: Names resolved on first use (PEP 562, :func:`__getattr__`) -> the module that defines them;
#: ``dir(spatialmech)`` lists them.  ``import spatialmech`` thus loads the errors and the result
#: enums only: no analysis, no scipy.spatial, no numba until a verb runs (issue 29).
_LAZY: dict[str, str] = {
    **dict.fromkeys(("C", "H", "Joint", "Limb", "Mechanism", "Mode", "ModelFileError", "P", "Pose", "R", "S", "Sm",
                     "U", "dump", "dumps", "load", "loads", "serial_from_dh"), ".model"),
    "Configuration": ".kinematics.closure",
    "closed_forms": ".kinematics.closed_forms",  # the closed-form kernels (a module; they load scipy.stats)
    # the studio's web app (FastAPI) and Jupyter widget (anywidget), drivers above the API: their entry
    # points check the extra first (a MissingExtraError naming it) and import nothing optional themselves
    "studio_app": ".interfaces.studio.entry",
    "studio": ".interfaces.studio.entry",
    **{name: ".api" for name in __all__ if name[0].islower() and name not in {"__version__", "closed_forms",
                                                                               "dump", "dumps", "load", "loads",
                                                                               "results", "serial_from_dh", "studio",
                                                                               "studio_app"}},
}


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("spatialmech")
    except PackageNotFoundError:  # pragma: no cover
        return "0+unknown"


def __getattr__(name: str):
    """A name of :data:`_LAZY` (or ``__version__``, read from the installed metadata): import its
    module, bind the name here (later lookups are plain attribute reads) and return it."""
    import importlib

    value: object
    if name == "__version__":
        value = _version()
    elif (where := _LAZY.get(name)) is not None:
        module = importlib.import_module(where, __name__)
        value = module if where.endswith("." + name) else getattr(module, name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY, "__version__"})
