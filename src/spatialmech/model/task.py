"""Task coordinates of a lower-mobility mechanism: which pose coordinates a user gives.

The output link's pose has six coordinates: ``x, y, z``, the position of its reference point
(``Mechanism.platform_point`` at the reference; the model's length unit), and ``a1, a2, a3``, its
orientation as Euler angles in an explicitly named sequence (default ``"ZYX"``, upper case =
intrinsic; radians inside, degrees in files, CLI and JSON).  A mechanism whose output link has
``M < 6`` freedoms is posed by ``M`` of them, the **given** coordinates; the other ``6 - M`` are
**solved** (its parasitic motion).  Which are given is chosen from the mobility analysis by
default (:func:`spatialmech.kinematics.task.default_task`) or named in the file::

    task = ["z", "a2", "a3"]
    task_euler = "ZYX"

    >>> t = TaskCoordinates(given=("z", "a2", "a3"))
    >>> t.solved
    ('x', 'y', 'a1')
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..geometry.rotations import check_sequence
from ..serialize import fields_dict

__all__ = ["TASK_NAMES", "TaskCoordinates"]

#: The six task coordinates, in this order everywhere.
TASK_NAMES = ("x", "y", "z", "a1", "a2", "a3")


@dataclass(frozen=True)
class TaskCoordinates:
    """The given task coordinates (a subset of :data:`TASK_NAMES`) and the Euler sequence."""

    given: tuple[str, ...]
    euler: str = "ZYX"

    def __post_init__(self):
        if isinstance(self.given, str) or not hasattr(self.given, "__iter__"):
            raise InputError(f"task: expected a list of coordinate names ({', '.join(TASK_NAMES)}), got {self.given!r}")
        given = tuple(self.given)
        for k, n in enumerate(given):
            if n not in TASK_NAMES:
                raise InputError(f"task[{k}]: unknown task coordinate {n!r}; expected one of {', '.join(TASK_NAMES)}")
        if len(set(given)) != len(given):
            raise InputError(f"task: {list(given)} repeats a coordinate")
        if not given:
            raise InputError("task: give at least one coordinate")
        if not isinstance(self.euler, str):
            raise InputError(f"task_euler: expected a sequence name such as 'ZYX', got {self.euler!r}")
        try:
            check_sequence(self.euler)
        except InputError as e:
            raise InputError(f"task_euler: {e}") from None
        object.__setattr__(self, "given", tuple(n for n in TASK_NAMES if n in given))

    @property
    def solved(self) -> tuple[str, ...]:
        """The coordinates that are solved (parasitic), in :data:`TASK_NAMES` order."""
        return tuple(n for n in TASK_NAMES if n not in self.given)

    def to_dict(self) -> dict:
        return fields_dict(self, names=("given", "solved", "euler"))
