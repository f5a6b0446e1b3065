"""Mechanism model: joints, limbs, mechanisms, poses, modes, and the TOML file format."""

from .joints import JOINT_TYPES, C, Freedom, H, Joint, P, R, S, Sm, U, make_joint
from .mechanism import Limb, Mechanism, Mode, Pose
from .dh import serial_from_dh
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .schema import ModelFileError, dump, dumps, load, loads

#: The TOML file format (:mod:`.schema`, built on pydantic: a third of a second to import) loads on
#: first use (PEP 562): the model types above do not need it.
_SCHEMA = ("ModelFileError", "dump", "dumps", "load", "loads")

__all__ = [
    "JOINT_TYPES",
    "C",
    "Freedom",
    "H",
    "Joint",
    "Limb",
    "Mechanism",
    "Mode",
    "ModelFileError",
    "P",
    "Pose",
    "R",
    "S",
    "Sm",
    "U",
    "dump",
    "dumps",
    "load",
    "loads",
    "make_joint",
    "serial_from_dh",
]


def __getattr__(name: str):
    if name in _SCHEMA:
        from . import schema

        return getattr(schema, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *_SCHEMA})
