"""Ready-made models, usable by name wherever a model file path is accepted."""

from __future__ import annotations

import importlib
from collections.abc import Callable

from ..errors import UnknownNameError
from ..model.mechanism import Mechanism

__all__ = ["REGISTRY", "build", "describe", "names", "resolve"]


def _lazy(module: str, builder: str, *args) -> Callable[[], Mechanism]:
    """``catalog.<module>.<builder>(*args)``, its module imported on the first build (listing
    the models, ``spatialmech models``, imports no model code)."""

    def build() -> Mechanism:
        return getattr(importlib.import_module(f"{__name__}.{module}"), builder)(*args)

    build.__name__ = builder
    build.__qualname__ = f"{module}.{builder}"
    return build


#: name -> (builder, one-line description)
REGISTRY: dict[str, tuple[Callable[[], Mechanism], str]] = {
    "four-sps-cu": (_lazy("papers", "four_sps_cu"), "Paper B: 4-SPS/CU parallel mechanism (3 rotations + Tz)"),
    "three-rrr-sm": (_lazy("papers", "three_rrr_sm"), "Paper C: 3-RRR actuated metamorphic spherical joint (7 modes)"),
    "three-sps-smpu": (_lazy("papers", "three_sps_smpu"), "Paper C: 3-SPS/SmPU metamorphic mechanism (8 modes, 3-6 DOF)"),
    "five-cs-1": (_lazy("papers", "five_cs", 1), "Paper A: 5-CS guidance linkage 1 (tables 1-3, 7) + 7 task positions"),
    "five-cs-2": (_lazy("papers", "five_cs", 2), "Paper A: 5-CS guidance linkage 2 (tables 4-6, 8) + 7 task positions"),
    "five-cs-3": (_lazy("papers", "five_cs", 3), "Paper A: 5-CS guidance linkage 3 (tables 10-13) + 7 task positions"),
    "stewart-6sps": (_lazy("classic", "stewart_6sps"), "Gough-Stewart platform 6-SPS, 6 DOF"),
    "three-rps": (_lazy("classic", "three_rps"), "3-RPS parallel mechanism, 2 rotations + 1 translation"),
    "three-prs": (_lazy("classic", "three_prs"), "3-PRS parallel mechanism (vertical rails), 2 rotations + 1 translation"),
    "three-upu": (_lazy("classic", "three_upu"), "Translational 3-UPU (Tsai), 3 translations"),
    "delta": (_lazy("classic", "delta"), "Clavel Delta robot (3 R + 12 S, 5 loops), 3 translations"),
    "delta-ruu": (_lazy("classic", "delta_ruu"), "Delta robot (parallelograms as U-U pairs), 3 translations"),
    "planar-4r": (_lazy("classic", "planar_4r"), "Planar four-bar crank-rocker, 1 DOF"),
    "bennett": (_lazy("classic", "bennett"), "Bennett overconstrained spatial 4R, 1 DOF (classic G-K -2)"),
    "rssr": (_lazy("classic", "rssr"), "Spatial RSSR four-bar, 1 DOF + 1 passive spin"),
    "spatial-six-bar": (_lazy("classic", "spatial_six_bar"),
                        "Spatial six-bar (two RSSR loops sharing a link), 1 DOF + 2 passive spins"),
    "puma560": (_lazy("classic", "puma560"), "PUMA 560 6R serial arm (standard DH, Corke), 6 DOF"),
    "agile-eye": (_lazy("classic", "agile_eye"), "Agile-Eye spherical 3-RRR wrist (all link angles 90 deg), 3 rotations"),
}


def names() -> list[str]:
    return list(REGISTRY)


def describe(name: str) -> str:
    return REGISTRY[name][1]


def build(name: str) -> Mechanism:
    """Build a ready-made model by name (``KeyError`` listing the known names otherwise)."""
    try:
        builder = REGISTRY[name][0]
    except KeyError:
        raise UnknownNameError(f"unknown ready-made model {name!r}; known: {', '.join(REGISTRY)}") from None
    return builder()


def _load_file(p) -> Mechanism:
    """A model file: TOML (the model format), or MJCF (``.xml`` / ``.mjcf``, e.g. written by
    ``spatialmech export``) through the importer :func:`spatialmech.exchange.from_mjcf`; a URDF
    is refused (no importer: its loop closures are not standard URDF), pointing to the others."""
    from ..model.schema import ModelFileError, load

    suffix = p.suffix.lower()
    if suffix in (".xml", ".mjcf"):
        from ..errors import InputError
        from ..exchange import from_mjcf

        try:
            return from_mjcf(p)
        except InputError as e:
            raise ModelFileError(f"{p}: read as MJCF (.xml): {e}") from None
    if suffix == ".urdf":
        raise ModelFileError(f"{p}: a URDF cannot be read back (no URDF importer: loop closures are not standard "
                             "URDF); give the model's TOML file, or its MJCF (spatialmech export MODEL FILE.xml), "
                             "which is imported")
    return load(p)


def resolve(spec) -> Mechanism:
    """A mechanism from a ready-made name, a file path, or a Mechanism (returned as is).

    Raises :class:`~spatialmech.model.schema.ModelFileError` with a one-line message.
    """
    from pathlib import Path

    from ..model.schema import ModelFileError

    if isinstance(spec, Mechanism):
        return spec
    s = str(spec)
    if s in REGISTRY:
        return build(s)
    p = Path(s)
    if p.exists():
        return _load_file(p)
    raise ModelFileError(
        f"{s}: not a file and not a ready-made model (ready-made: {', '.join(REGISTRY)})"
    )
