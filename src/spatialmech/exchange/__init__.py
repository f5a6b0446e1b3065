"""Models that travel to other tools: MuJoCo (MJCF) and URDF exports, and MJCF import.

One intermediate structure, :class:`~.bodies.BodyTree` (a spanning tree of the link graph as
bodies, plus the loop closures), serves both writers; see docs/validation.md.

    >>> import spatialmech as sm
    >>> from spatialmech.exchange import body_tree, to_mjcf, to_urdf
    >>> tree = body_tree(sm.load_model("rssr"))
    >>> [c.kind for c in tree.closures], [a.name for a in tree.actuated]
    (['connect'], ['A0.rot'])
    >>> to_mjcf(tree).startswith('<mujoco model="rssr">'), "<robot" in to_urdf(tree)
    (True, True)
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from ..model.mechanism import Mechanism
from .bodies import Axis, Body, BodyTree, Closure, Coupling, TreeJoint, body_tree, mechanism_from_tree
from .mjcf import from_mjcf, to_mjcf
from .urdf import to_urdf

__all__ = [
    "FORMATS",
    "Axis",
    "Body",
    "BodyTree",
    "Closure",
    "Coupling",
    "TreeJoint",
    "body_tree",
    "export_model",
    "format_of",
    "from_mjcf",
    "mechanism_from_tree",
    "to_mjcf",
    "to_urdf",
]

#: Export formats and the file extensions that imply them.
FORMATS = {"toml": (".toml",), "mjcf": (".xml", ".mjcf"), "urdf": (".urdf",),
           "step": (".step", ".stp"), "stl": (".stl",), "glb": (".glb",)}


def format_of(path, fmt: str | None = None) -> str:
    """The export format: ``fmt`` if given (one of :data:`FORMATS`; refused when the file's
    extension names another format), else from the file's extension (``.toml``; ``.xml`` /
    ``.mjcf``; ``.urdf``; ``.step``; ``.stl``; ``.glb``)."""
    suffix = Path(os.fspath(path)).suffix.lower()
    if fmt is not None:
        if fmt not in FORMATS:
            raise InputError(f"--format: expected one of {', '.join(FORMATS)}, got {fmt!r}")
        named = [name for name, suffixes in FORMATS.items() if suffix in suffixes]
        if named and fmt not in named:
            raise InputError(f"--format: {fmt!r} contradicts the extension {suffix!r} of {os.fspath(path)} "
                             f"(a {named[0]} file); drop --format or name the file for {fmt}")
        return fmt
    for name, suffixes in FORMATS.items():
        if suffix in suffixes:
            return name
    raise InputError(f"FILE: cannot tell the format from the extension {suffix or '(none)'!r} of {os.fspath(path)}; "
                     f"use .toml, .xml (MJCF), .urdf, .step, .stl or .glb, or give --format {'|'.join(FORMATS)}")


def _model_masses(mech: Mechanism) -> dict | None:
    """The links' mass properties when the model gives them (``masses``, ``density_kg_m3``) for
    every moving link, else ``None`` (the MJCF keeps its default inertias)."""
    if not (mech.inertias or mech.density_kg_m3 is not None) or mech.length_unit != "m":
        return None
    from ..analysis.dynamics import mass_properties

    masses, _ = mass_properties(mech)
    return masses if all(li.mass_kg > 0 for li in masses.values()) else None


def export_model(mech: Mechanism, path, fmt: str | None = None) -> str:
    """Write ``mech`` to ``path`` as TOML (the model file format), MJCF, URDF or CAD; returns the
    format used (``fmt`` or the one the extension implies).  An MJCF of a model whose file gives
    every link a mass (``masses``, ``density_kg_m3``) carries those mass properties."""
    fmt = format_of(path, fmt)
    if fmt in ("step", "stl", "glb"):  # CAD parts at the reference configuration (.cad.export_cad)
        from .cad import export_cad

        export_cad(mech, path, fmt, unit="m" if fmt == "glb" else "mm")
    elif fmt == "toml":
        from ..model.schema import dump

        dump(mech, path)
    else:
        text = to_mjcf(mech, _model_masses(mech)) if fmt == "mjcf" else to_urdf(mech)
        Path(os.fspath(path)).write_text(text, encoding="utf-8")
    return fmt
