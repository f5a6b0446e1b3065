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

from .burmester import BurmesterCurves, burmester_curves, center_point, circle_point, poles
from .cs_dyads import CSDyad, CSFamily, synthesize_cs
from .dyads import Dyad, SolutionLine, direction_residuals, rc_dyad_three_positions, solution_line
from .five_cs import assemble_5cs, check_5cs, paper_a_check
from .rccc import RCCCResult, assemble, check_linkage, interior_pick, synthesize_rccc
from .regions import Region1, Region2, classify_spherical_4r, solution_region_1, solution_region_2
from .tasks import TaskPositions, get_task, load_task, loads_task, mccarthy_matrix, resolve_task, task_names

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
