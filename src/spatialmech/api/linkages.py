"""The public API: one-degree-of-freedom linkages and synthesis -- tracking, DJ tables,
defects, RCCC and CS-dyad synthesis (``sm.track``, ``sm.dj_table``, ``sm.defects``,
``sm.synth_rccc``, ``sm.synth_cs``)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import catalog
from ..errors import InputError, describe, require
from ..kinematics.closure import Configuration
from ..kinematics.position import freedom_values, platform_pose
from ..model.mechanism import Mechanism, Pose
from ..results import Progress, TrackStatus
if TYPE_CHECKING:
    from pathlib import Path

    from ..analysis.defects import DefectResult, DJTable
    from ..services.screening import ScreenSummary
    from ..synthesis.rccc import RCCCResult
    from ..kinematics.tracking import TrackResult
    from ..synthesis.cs_dyads import CSFamily
    from ..synthesis.five_cs import FiveCSCheck

from .checks import (
    ModelLike,
    as_configuration,
    as_mechanism,
    as_positions,
    check_bool,
    check_choice,
    check_int,
    check_names,
    check_number,
    check_path,
    optional_progress,
)
from .threads import one_blas_thread


# ============================================================================ tracking
@dataclass(frozen=True, eq=False)
class TraceResult:
    """The one-degree-of-freedom motion traced by continuation (:attr:`result`, a
    :class:`~spatialmech.kinematics.tracking.TrackResult` whose points are configurations), with
    the sign changes of DJ of the actuators as events (zeros: branch points)."""

    mechanism: Mechanism
    result: TrackResult

    @property
    def status(self) -> TrackStatus:
        return self.result.status

    @property
    def closed(self) -> bool:
        return self.result.closed

    @property
    def configurations(self) -> list[Configuration]:
        return self.result.points

    @property
    def poses(self) -> list[Pose]:
        return [platform_pose(self.mechanism, c) for c in self.result.points]

    def to_dict(self) -> dict:
        from ..serialize import freedom_values_dict

        tr, mech = self.result, self.mechanism
        ids = [r.id for r in mech.freedom_refs]
        q = np.array([freedom_values(mech, c.q) for c in tr.points]).reshape(len(tr.points), len(ids))
        values = freedom_values_dict(mech, dict.fromkeys(ids, 0.0), "joint_values")
        deg = {fid: [float(x) for x in np.degrees(q[:, ids.index(fid)])] for fid in values["joint_values_deg"]}
        lin = {fid: [float(x) for x in q[:, ids.index(fid)]] for fid in values["joint_values_len"]}
        return {
            "status": tr.status,
            "reason": tr.reason,
            "ok": tr.ok,
            "closed": tr.closed,
            "points": len(tr.points),
            "arc_length": float(tr.s[-1]),
            "arc": [float(s) for s in tr.s],
            "events": [{"name": e.name, "arc": float(e.s), "kind": e.kind} for e in tr.events],
            "rejected_steps": tr.rejected,
            "platform_points_len": [[float(x) for x in p.p] for p in self.poses],
            "joint_values_deg": deg,
            "joint_values_len": lin,
            "units": {"arc": "nondimensional arc length (joint rad, lengths / characteristic length)"},
        }


@one_blas_thread
def track(model: ModelLike, start=None, *, increasing: str | None = None, sense: int = 1, max_arc: float = 50.0,
          max_steps: int = 20000, h0: float = 0.02, degrees: bool = False,
          progress: Progress | None = None) -> TraceResult:
    """Follow the one-degree-of-freedom motion by pseudo-arclength continuation.

    From ``start`` until the motion closes (``status`` closed) or the arc length reaches
    ``max_arc``; the sign changes of DJ of the actuators are located as events.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    start : Pose, tuple, int or Configuration, optional
        The first pose (as ``pose`` in :func:`ik`, fitted onto the closure) or configuration;
        default: the reference configuration.
    increasing : str, optional
        A freedom whose variable grows at the start (default: the first actuator's: the
        convention of docs/conventions.md, the same sense on every machine).
    sense : {1, -1}
        ``-1``: that variable decreases at the start.
    max_arc : float
        The largest arc length (nondimensional).
    max_steps : int
        The largest number of continuation steps.
    h0 : float
        The first step (nondimensional arc length).
    degrees : bool
        Read the angles of a pose tuple (and angular values) in degrees instead of radians.
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.

    Returns
    -------
    TraceResult
        ``status`` (:class:`~spatialmech.results.TrackStatus`), ``closed``, ``configurations``,
        ``poses`` and the DJ events; ``to_dict()`` is its JSON.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> m = sm.track("bennett")
    >>> m.status, m.closed
    (<TrackStatus.CLOSED: 'closed'>, True)
    """
    from ..analysis.defects import dj_function
    from ..kinematics.tracking import trace_motion

    mech = as_mechanism(model)
    degrees = check_bool(degrees, "degrees")
    if increasing is not None and not isinstance(increasing, str):
        raise TypeError(f"increasing: expected a freedom name (str) or None, got {describe(increasing)}")
    sense = check_int(sense, "sense")
    if sense not in (-1, 1):
        raise InputError(f"sense: expected +1 or -1, got {sense}")
    max_arc = check_number(max_arc, "max_arc", positive=True)
    h0 = check_number(h0, "h0", positive=True)
    max_steps = check_int(max_steps, "max_steps", minimum=1)
    if isinstance(start, Configuration):
        c, _ = as_configuration(mech, None, start, degrees)
    else:
        c, _ = as_configuration(mech, start, None, degrees, pose_name="start")
    acts = list(mech.actuators)
    mon = None
    if acts:
        try:
            f, _ = dj_function(mech, acts, c)
            mon = (["DJ " + a for a in acts], f)
        except InputError:
            mon = None  # DJ undefined here (e.g. an actuator is locked): trace without events
    tr = trace_motion(mech, c, increasing=increasing, sense=sense, vector_monitor=mon, max_arc=max_arc,
                      max_steps=max_steps, h0=h0, progress=optional_progress(progress))
    return TraceResult(mech, tr)


# ============================================================================ defects
def dj_table(model: ModelLike, drivers=None, positions=None) -> DJTable:
    """DJ (det of the complete Jacobian) at the model's task positions, per driver.

    Only the signs along one driver are comparable.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    drivers : str or sequence of str, optional
        The drivers (default: every base-joint freedom).
    positions : sequence of Pose, str or path, optional
        The task positions (default: the model's own): a sequence of
        :class:`~spatialmech.Pose` (``R`` shape (3, 3), ``p`` shape (3,) in the model's length
        unit) or a TOML file of ``[[positions]]``.

    Returns
    -------
    DJTable
        :class:`~spatialmech.analysis.defects.DJTable`: the signs per driver and position,
        ``keeps_sign(driver)``, the fits of the printed poses (``fits``); ``to_dict()`` its JSON.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> t = sm.dj_table("five-cs-3", ["rot1", "rot3"])
    >>> t.keeps_sign("rot1"), t.keeps_sign("rot3")
    (True, False)
    """
    from ..analysis.defects import dj_table as _dj_table

    mech = as_mechanism(model)
    return _dj_table(mech, check_names(drivers, "drivers"), as_positions(positions))


@dataclass(frozen=True, eq=False)
class DefectAnalysis:
    """The defect analysis of a linkage (:attr:`result`, a
    :class:`~spatialmech.analysis.defects.DefectResult`: ``circuits``, ``circuit_defect``,
    ``order_defect``, ``drivers``, ``usable_drivers``, ``plan`` ...; its attributes are readable
    here directly), the task :attr:`positions` it was judged at, and the :attr:`figures` written
    (``plot=``).  ``to_dict()`` is the result's."""

    mechanism: Mechanism
    positions: tuple[Pose, ...]
    result: DefectResult
    figures: tuple[Path, ...] = ()

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_") or name == "result":
            raise AttributeError(name)
        return getattr(self.result, name)

    def to_dict(self) -> dict:
        return self.result.to_dict()


@one_blas_thread
def defects(model: ModelLike, positions=None, *, drivers=None, pose_tol: float | None = None,
            angle_tol_deg: float = 1.0, monte_carlo: int = 0, seed: int = 0, precision: float = 5e-4,
            plot: str | os.PathLike | None = None, progress: Progress | None = None) -> DefectAnalysis:
    """Circuit, branch and order defects of a one-degree-of-freedom linkage (paper A).

    For its task positions: the drivers that can be used, and a dual-drive plan when no single
    one can.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    positions : sequence of Pose, str or path, optional
        The task positions (default: the model's own): a sequence of
        :class:`~spatialmech.Pose` (``R`` shape (3, 3), ``p`` shape (3,) in the model's length
        unit) or a TOML file of ``[[positions]]``.
    drivers : str or sequence of str, optional
        The candidate drivers (default: every base-joint freedom).
    pose_tol : float, optional
        A position belongs to a circuit that passes within ``pose_tol`` of it (length unit;
        default 2 % of the characteristic length) and ``angle_tol_deg``.
    angle_tol_deg : float
        The angle tolerance of matching a position (degrees).
    monte_carlo : int
        Random perturbations of the positions within their printed precision (0: none).
    seed : int
        The random seed of those perturbations.
    precision : float
        The printed precision of the positions (length unit; axes by ``precision`` per unit).
    plot : str or path, optional
        A directory to write the figures into.
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.

    Returns
    -------
    DefectAnalysis
        The attributes of :class:`~spatialmech.analysis.defects.DefectResult` (``circuits``,
        ``circuit_defect``, ``order_defect``, ``usable_drivers``, ``plan``, ``circuit_status``:
        :class:`~spatialmech.results.TrackStatus` ...), the ``positions`` and the ``figures``
        written.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> motion = sm.track("planar-4r")                  # three positions on its circuit, in order
    >>> P = [motion.poses[k] for k in (0, 9, 18)]
    >>> r = sm.defects("planar-4r", P)
    >>> r.circuit_defect, r.order_defect, r.usable_drivers, r.circuit_status
    (False, False, ('A0.rot', 'B0.rot'), (<TrackStatus.CLOSED: 'closed'>,))
    """
    from ..analysis.defects import defect_analysis

    mech = as_mechanism(model)
    positions = as_positions(positions)
    pose_tol = check_number(pose_tol, "pose_tol", positive=True, optional=True)
    angle_tol_deg = check_number(angle_tol_deg, "angle_tol_deg", positive=True)
    precision = check_number(precision, "precision")
    plot = None if plot is None else check_path(plot, "plot")
    if plot is not None:  # before any work: the extra to install
        require("plot", "matplotlib", what="plot")
    res = defect_analysis(mech, positions, drivers=check_names(drivers, "drivers"), pose_tol=pose_tol,
                          angle_tol_deg=angle_tol_deg, monte_carlo=check_int(monte_carlo, "monte_carlo", minimum=0),
                          seed=check_int(seed, "seed"), precision=precision, progress=optional_progress(progress))
    figures: tuple[Path, ...] = ()
    if plot is not None:
        from ..present.defect_figures import write_defect_figures

        figures = tuple(write_defect_figures(mech, res, plot))
    return DefectAnalysis(mech, tuple(positions if positions is not None else mech.positions), res, figures)


# ============================================================================ synthesis
@one_blas_thread
def synth_rccc(task="rccc-four-positions", *, pick: str = "best-rc", samples: int = 360,
               save: str | os.PathLike | None = None, plot: str | os.PathLike | None = None) -> RCCCResult:
    """Four-position RCCC synthesis by solution regions (paper D).

    Parameters
    ----------
    task : str, path or TaskPositions
        A ready-made task name, a TOML task file, or a ``TaskPositions``.
    pick : {"best-rc", "interior"}
        ``"best-rc"``: the smallest largest input slide; ``"interior"``: the most interior
        defect-free crank-rocker.
    samples : int
        Points per Burmester-curve branch (at least 8).
    save : str or path, optional
        Write the RCCC as a model file (TOML).
    plot : str or path, optional
        Write the figures (curves, regions, solution lines, linkage) into that directory.

    Returns
    -------
    RCCCResult
        :class:`~spatialmech.synthesis.RCCCResult`: ``linkage`` (a Mechanism), ``task`` (the task
        positions), ``linkage_type``, ``defects`` ...

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.synth_rccc(samples=60)
    >>> r.linkage_type, r.defects
    ('crank-rocker', 0)
    """
    from ..synthesis.rccc import synthesize_rccc
    from ..synthesis.tasks import TaskPositions, resolve_task

    if not isinstance(task, (str, os.PathLike, TaskPositions)):
        raise TypeError(f"task: expected a task name, a TOML file path or a TaskPositions, got {describe(task)}")
    pick = check_choice(pick, "pick", ("best-rc", "interior"))
    samples = check_int(samples, "samples", minimum=8)
    save = None if save is None else check_path(save, "save")
    plot = None if plot is None else check_path(plot, "plot")
    if plot is not None:  # before any work: the extra to install
        require("plot", "matplotlib", what="plot")
    res = synthesize_rccc(resolve_task(task), pick=pick, samples=samples)
    if save is not None:
        from ..model.schema import dump

        dump(res.linkage, save)
    if plot is not None:
        from ..present.synthesis_figures import write_all

        write_all(res, plot)
    return res


@dataclass(frozen=True, eq=False)
class CSSynthesisResult:
    """Seven-position CS dyad synthesis (paper A): the one-parameter ``family`` of dyads, the
    picked dyads (``family.picks``), and with five picks the assembled 5-CS ``linkage`` and its
    ``check`` at the seven positions."""

    family: CSFamily
    positions_source: str
    samples: int
    linkage: Mechanism | None = None
    check: FiveCSCheck | None = None

    @property
    def success(self) -> bool | None:
        """The 5-CS closes at the seven positions with one degree of freedom and (when its defects
        were checked) is defect-free for some driver; ``None`` without a 5-CS."""
        return None if self.check is None else self.check.success

    def to_dict(self) -> dict:
        d = {**self.family.to_dict(samples=self.samples), "positions_source": self.positions_source,
             "five_cs": None, "success": None, "verdict": None}
        if self.check is not None:
            d["five_cs"] = self.check.to_dict()
            d["success"] = self.check.success
            d["verdict"] = self.check.verdict()
        return d


#: The name of paper A's seven task positions (table 9) where a positions argument is expected.
FIVE_CS_POSITIONS = "five-cs-positions"


def seven_positions(positions) -> tuple[tuple[Pose, ...], str]:
    """The task poses of a CS synthesis or screen, and where they came from: ``None`` or
    ``"five-cs-positions"`` (paper A's table 9), a model name or Mechanism (its task positions),
    a TOML file of ``[[positions]]``, or a sequence of Pose."""
    if positions is None or (isinstance(positions, str) and positions == FIVE_CS_POSITIONS):
        from ..catalog.papers import five_cs_positions

        return five_cs_positions(), "paper A table 9"
    if isinstance(positions, Mechanism) or (isinstance(positions, str) and positions in catalog.REGISTRY):
        mech = as_mechanism(positions, "positions")
        return mech.positions, f"the task positions of {mech.name}"
    poses = as_positions(positions) or ()
    return poses, os.fspath(positions) if isinstance(positions, (str, os.PathLike)) else "given poses"


@one_blas_thread
def synth_cs(positions=None, *, pick: int = 5, starts: int = 60, seed: int = 0, samples: int = 40,
             check_defects: bool = True, save: str | os.PathLike | None = None,
             progress: Progress | None = None) -> CSSynthesisResult:
    """Seven-position synthesis of CS dyads and a 5-CS linkage (paper A, section 3).

    Parameters
    ----------
    positions : str, Mechanism, path or sequence of Pose, optional
        Seven task poses: default paper A's table 9; a model name or Mechanism (its task
        positions), a TOML file of ``[[positions]]``, or seven :class:`~spatialmech.Pose`
        (``R`` shape (3, 3), ``p`` shape (3,), length unit).
    pick : int
        Small-slide dyads picked (5: also assemble and check the 5-CS).
    starts : int
        Random starts of the family's synthesis.
    seed : int
        Their random seed.
    samples : int
        Family points listed in ``to_dict()``.
    check_defects : bool
        With ``pick=5``: also the circuit, order and branch defects (about 10 s).
    save : str or path, optional
        Write the 5-CS as a model file (TOML; needs ``pick=5``).
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.

    Returns
    -------
    CSSynthesisResult
        The ``family`` of dyads and its picks; with five picks the assembled ``linkage`` and its
        ``check`` at the seven positions.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.synth_cs(pick=0, starts=4)
    >>> len(r.family.branches) >= 1, r.linkage is None
    (True, True)
    """
    from ..synthesis.cs_dyads import synthesize_cs
    from ..synthesis.five_cs import assemble_5cs, check_5cs

    pick = check_int(pick, "pick", minimum=0)
    check_defects = check_bool(check_defects, "check_defects")
    progress = optional_progress(progress)
    starts = check_int(starts, "starts", minimum=1)
    seed = check_int(seed, "seed")
    samples = check_int(samples, "samples", minimum=2)
    save = None if save is None else check_path(save, "save")
    if save is not None and pick != 5:
        raise InputError(f"save: a 5-CS linkage needs pick=5 (got pick={pick})")
    poses, source = seven_positions(positions)
    fam = synthesize_cs(poses, n_starts=starts, seed=seed, pick=pick)
    if pick != 5:
        return CSSynthesisResult(fam, source, samples)
    if len(fam.picks) < 5:
        raise InputError(f"pick: only {len(fam.picks)} well separated dyads found; try more starts")
    linkage = assemble_5cs(fam.task, fam.picks)
    check = check_5cs(linkage, fam.picks, defects=check_defects, progress=progress)
    if save is not None:
        from ..model.schema import dump

        dump(linkage, save)
    return CSSynthesisResult(fam, source, samples, linkage, check)


# ============================================================================ screening
#: Largest ``seed`` of :func:`screen` (a random generator's seed, stored as a 64-bit integer).
_SEED_MAX = 2**63 - 1


@one_blas_thread
def screen(task=None, out: str | os.PathLike = "screen.parquet", *, candidates: int = 1000, density: float = 0.5,
           workers: int | None = None, scheduler: str | None = None, top: int = 5, rank_by: str = "singularity",
           seed: int = 0, starts: int = 60, separation: float = 0.5, chunk_size: int = 20,
           progress: Progress | None = None) -> ScreenSummary:
    """Defect screening of 5-CS linkages for seven task positions (docs/screening.md).

    The CS dyad family is sampled, up to ``candidates`` sets of five dyads are formed, each is
    judged in stages (assembly at the positions, DJ signs, the full defect analysis) on Dask and
    the verdicts go to a Parquet dataset (resumable: a rerun with the same arguments skips
    finished chunks); the best usable linkages are written as model files (``out/_top/``).

    Parameters
    ----------
    task : str, Mechanism, path or sequence of Pose, optional
        ``None`` / ``"five-cs-positions"`` (paper A table 9), a model with seven task positions, a
        positions TOML file or seven :class:`~spatialmech.Pose`.
    out : str or path
        The Parquet dataset written.
    candidates : int
        The largest number of candidate sets.
    density : float
        Dyads per unit nondimensional arc length of the family.
    workers : int, optional
        Local worker processes (``None``: one per core, ``0``: serial without Dask).
    scheduler : str, optional
        The address of an existing Dask scheduler (then ``workers`` is ignored).
    top : int
        How many of the best usable linkages to write as model files.
    rank_by : {"singularity", "slide"}
        ``"singularity"``: the largest distance to a singularity along the path first;
        ``"slide"``: the smallest C-slide stroke first.
    seed : int
        The random seed (sampling and the family's synthesis).
    starts : int
        Random starts of the family's synthesis.
    separation : float
        The smallest distance between limbs (nondimensional).
    chunk_size : int
        Candidates per Parquet file and per Dask task.
    progress : callable, optional
        ``progress(done, total_or_None, message)``, called as the work goes on.

    Returns
    -------
    ScreenSummary
        :class:`~spatialmech.services.screening.ScreenSummary`: counts by stage, the usable ones,
        the files written; ``to_dict()`` for JSON, with ``positions_source``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import tempfile
    >>> import spatialmech as sm
    >>> s = sm.screen(out=tempfile.mkdtemp() + "/s.parquet", candidates=2, starts=4, workers=0, top=0)
    >>> s.judged, sum(s.rejected_by_stage.values()) + s.usable
    (2, 2)
    """
    require("screen", "distributed", "pyarrow", what="screening")  # before any work: the extra to install
    from ..services.screening import run_screen

    poses, source = seven_positions(task)
    for nm, v, lo in (("candidates", candidates, 1), ("top", top, 0), ("starts", starts, 1),
                      ("chunk_size", chunk_size, 1)):
        check_int(v, nm, minimum=lo)
    if workers is not None:
        check_int(workers, "workers", minimum=0)
    summary = run_screen(poses, out, candidates=candidates, density=check_number(density, "density"),
                         seed=check_int(seed, "seed", minimum=0, maximum=_SEED_MAX), starts=starts,
                         separation=check_number(separation, "separation"),
                         chunk_size=chunk_size, workers=workers, scheduler=scheduler, top=top, rank_by=rank_by,
                         progress=optional_progress(progress))
    summary.positions_source = source
    return summary
