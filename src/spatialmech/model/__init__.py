"""Mechanism model: joints, limbs, mechanisms, poses, modes, and the TOML file format."""

from .joints import JOINT_TYPES, C, Freedom, H, Joint, P, R, S, Sm, U, make_joint
from .mechanism import Limb, Mechanism, Mode, Pose
from .schema import ModelFileError, dump, dumps, load, loads

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
]
