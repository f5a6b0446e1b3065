"""Synthesis: task positions -> dyads -> linkages (paper D: four-position RCCC by solution regions;
paper A: seven-position CS dyads and 5-CS linkages).

Modules: :mod:`.cs_dyads` (paper A section 3: the CS dyad family), :mod:`.five_cs` (5-CS linkages from
five dyads, paper A's claims), :mod:`.tasks` (task positions, the ready-made ``rccc-four-positions``),
:mod:`.burmester` (spherical Burmester curves), :mod:`.dyads` (CC/RC dyads, solution lines),
:mod:`.regions` (solution regions 1 and 2), :mod:`.rccc` (the pipeline and the closure check).
The figures are drawn by :mod:`spatialmech.present.synthesis_figures`.  See ``docs/synthesis.md``.

Quick example::

    >>> from spatialmech.synthesis import get_task, synthesize_rccc
    >>> res = synthesize_rccc(get_task("rccc-four-positions"), samples=120)
    >>> res.linkage_type, res.defects
    ('crank-rocker', 0)
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .burmester import BurmesterCurves, burmester_curves, center_point, circle_point, poles
    from .cs_dyads import CSDyad, CSFamily, synthesize_cs
    from .dyads import Dyad, SolutionLine, direction_residuals, rc_dyad_three_positions, solution_line
    from .five_cs import assemble_5cs, check_5cs, paper_a_check
    from .rccc import RCCCResult, assemble, check_linkage, interior_pick, synthesize_rccc
    from .regions import Region1, Region2, classify_spherical_4r, solution_region_1, solution_region_2
    from .tasks import TaskPositions, get_task, load_task, loads_task, mccarthy_matrix, resolve_task, task_names

#: Where each public name lives: the modules are imported on first use (PEP 562), so that a
#: process that needs one of them (a screen's worker: cs_dyads and five_cs) does not import the
#: others and SciPy's optimisers with them.
_WHERE = {
    **dict.fromkeys(("BurmesterCurves", "burmester_curves", "center_point", "circle_point", "poles"), "burmester"),
    **dict.fromkeys(("CSDyad", "CSFamily", "synthesize_cs"), "cs_dyads"),
    **dict.fromkeys(("Dyad", "SolutionLine", "direction_residuals", "rc_dyad_three_positions", "solution_line"),
                    "dyads"),
    **dict.fromkeys(("assemble_5cs", "check_5cs", "paper_a_check"), "five_cs"),
    **dict.fromkeys(("RCCCResult", "assemble", "check_linkage", "interior_pick", "synthesize_rccc"), "rccc"),
    **dict.fromkeys(("Region1", "Region2", "classify_spherical_4r", "solution_region_1", "solution_region_2"),
                    "regions"),
    **dict.fromkeys(("TaskPositions", "get_task", "load_task", "loads_task", "mccarthy_matrix", "resolve_task",
                     "task_names"), "tasks"),
}


def __getattr__(name: str):
    try:
        where = _WHERE[name]
    except KeyError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f".{where}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "BurmesterCurves",
    "CSDyad",
    "CSFamily",
    "Dyad",
    "RCCCResult",
    "Region1",
    "Region2",
    "SolutionLine",
    "TaskPositions",
    "assemble",
    "assemble_5cs",
    "burmester_curves",
    "center_point",
    "check_5cs",
    "check_linkage",
    "circle_point",
    "classify_spherical_4r",
    "direction_residuals",
    "get_task",
    "interior_pick",
    "load_task",
    "loads_task",
    "mccarthy_matrix",
    "paper_a_check",
    "poles",
    "rc_dyad_three_positions",
    "resolve_task",
    "solution_line",
    "solution_region_1",
    "solution_region_2",
    "synthesize_cs",
    "synthesize_rccc",
    "task_names",
]
