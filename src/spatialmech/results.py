"""Vocabulary shared by every result: status enums and the one progress-callback signature.

Statuses are :class:`enum.StrEnum` members, not free strings: they compare equal to their
value (``TrackStatus.CLOSED == "closed"``) and serialise to it, so the JSON is unchanged, while a
typo in the code is an ``AttributeError`` instead of a silent mismatch.

    >>> from spatialmech.results import TrackStatus
    >>> TrackStatus.CLOSED == "closed", str(TrackStatus.MAX_ARC)
    (True, 'max_arc')
    >>> TrackStatus("h_min").ok
    False

Every analysis that reports progress takes ``progress: Progress | None`` and calls it as
``progress(done, total, message)``: ``done`` the amount of work done so far (poses checked,
starts tried, steps, arc length: the unit of the analysis), ``total`` the amount expected or
``None`` when unknown, ``message`` a short text (may be empty).  One signature everywhere, so one
callback (a progress bar, a logger) fits every analysis:

    >>> from spatialmech.results import Steps
    >>> seen = []
    >>> say = Steps(lambda done, total, msg: seen.append((done, total, msg)), total=2)
    >>> say("first"); say("second")
    >>> seen
    [(1, 2, 'first'), (2, 2, 'second')]

This module depends on nothing else in the package: the numerical core may import it.
"""

from __future__ import annotations

from collections.abc import Callable
from enum import StrEnum

__all__ = [
    "BranchEnd",
    "DriveStatus",
    "EndPointStatus",
    "EventKind",
    "Progress",
    "ScreenStage",
    "SingularityKind",
    "SolveStatus",
    "Steps",
    "TraceVerdict",
    "TrackStatus",
    "Verdict",
    "check_progress",
    "no_progress",
]

#: ``progress(done, total_or_None, message)``: the one progress-callback signature.
Progress = Callable[[float, float | None, str], None]


def no_progress(done: float, total: float | None, message: str) -> None:
    """A :data:`Progress` callback that does nothing."""


def check_progress(progress, name: str = "progress") -> Progress:
    """``progress`` itself when callable, :func:`no_progress` for ``None``; ``TypeError`` naming
    the argument otherwise."""
    if progress is None:
        return no_progress
    if not callable(progress):
        raise TypeError(f"{name}: expected a callable progress(done, total, message) or None, "
                        f"got {type(progress).__name__} {progress!r}")
    return progress


class Steps:
    """Announce numbered steps to a :data:`Progress` callback: ``say = Steps(progress, total)``,
    then ``say("message")`` calls ``progress(k, total, "message")`` with ``k = 1, 2, ...``."""

    def __init__(self, progress: Progress | None, total: int | None = None):
        self.progress = check_progress(progress)
        self.total = total
        self.done = 0

    def __call__(self, message: str) -> None:
        self.done += 1
        self.progress(self.done, self.total, message)


class TrackStatus(StrEnum):
    """How a continuation run (:func:`spatialmech.kinematics.tracking.track`) ended."""

    CLOSED = "closed"  #: the curve came back to its start (a closed circuit)
    MAX_ARC = "max_arc"  #: the arc-length budget (or step budget) was used up
    STOPPED = "stopped"  #: the caller's ``stop(x, s)`` asked to stop
    H_MIN = "h_min"  #: failure: no acceptable step above ``h_min`` (the reason is given alongside)

    @property
    def ok(self) -> bool:
        """True unless the tracker failed."""
        return self is not TrackStatus.H_MIN


class SolveStatus(StrEnum):
    """How an iterative solve (e.g. the closed-form forward position of the 4-SPS/CU) ended."""

    CONVERGED = "converged"
    MAX_ITER = "max_iter"  #: stopped at the iteration limit before converging
    STALLED = "stalled"  #: the step could not reduce the residual any more


class EventKind(StrEnum):
    """A located sign change of a monitor along a traced curve."""

    ZERO = "zero"  #: the monitor went through zero (e.g. a branch point: DJ = 0)
    POLE = "pole"  #: the monitor changed sign through infinity


class SingularityKind(StrEnum):
    """The kind of a singular configuration (:func:`spatialmech.analysis.singularity.singularity`)."""

    NONE = "none"
    INVERSE = "inverse"  #: serial: an actuator can move with the platform at rest
    CONSTRAINT = "constraint"  #: the limbs' constraint wrenches lose rank
    DIRECT = "direct"  #: parallel: an uncontrolled platform twist with the actuators locked
    INVERSE_CONSTRAINT = "inverse+constraint"

    @property
    def singular(self) -> bool:
        return self is not SingularityKind.NONE


class BranchEnd(StrEnum):
    """How one end of a traced branch of a synthesis family ends (CS dyads, paper A)."""

    CLOSED = "closed"  #: the branch is a closed curve
    LEFT_BOX = "left the box"  #: it left the search box (``extent``)
    MAX_ARC = "max_arc"  #: the arc-length budget was used up
    H_MIN = "h_min"  #: the tracker could not continue (a singular point of the family)


class Verdict(StrEnum):
    """The verdict of a claim row of the reproduction report."""

    REPRODUCED = "reproduced"
    CORRECTED = "reproduced after correction"
    NOT_REPRODUCED = "not reproduced"


class EndPointStatus(StrEnum):
    """The kind of one end point of a homotopy path (:mod:`spatialmech.kinematics.homotopy`,
    :mod:`~spatialmech.kinematics.homotopy_general`)."""

    REAL = "real"  #: a finite, nonsingular, real solution
    COMPLEX = "complex"  #: a finite, nonsingular solution that is not real
    SINGULAR = "singular"  #: the Jacobian is singular there (a multiple root or a continuum)
    AT_INFINITY = "at_infinity"  #: the path diverged (the platform escapes: e.e = 0)


class TraceVerdict(StrEnum):
    """The verdict of a trace test (:func:`spatialmech.kinematics.trace_test.trace_test`)."""

    PASSED = "passed"  #: the known solutions are complete
    FAILED = "failed"  #: some are missing (the traces are not on a line)
    INCONCLUSIVE = "inconclusive"  #: a path of the test's homotopies failed
    CAPPED = "capped"  #: the work cap ran out first


class DriveStatus(StrEnum):
    """How one studio drive or pose request ended (the ``status`` of ``POST /api/drive`` and
    ``POST /api/pose``)."""

    REACHED = "reached"  #: the requested values, on the same branch
    STOPPED_SINGULAR = "stopped_at_singularity"  #: the drivers lost control: DJ zero / dead point ahead
    STOPPED_TRACKER = "stopped"  #: the tracker could not step on (bifurcation, branch crossing, no closure)
    UNCHANGED = "unchanged"  #: nothing to do (the values are the current ones)
    STOPPED_LIMIT = "stopped_at_limit"  #: pose: an actuator would leave its joint limits
    LIMB_SINGULAR = "limb_singular"  #: pose: a limb reaches an inverse singularity (workspace edge)
    UNREACHABLE = "unreachable"  #: pose: no closed configuration further along the path


class ScreenStage(StrEnum):
    """The stage of the 5-CS screen that rejected a candidate (``rejected_by`` of
    :class:`spatialmech.synthesis.screening.CandidateVerdict`)."""

    ASSEMBLY = "assembly"  #: the candidate does not close (or is singular) at the task positions
    DJ_SIGNS = "dj_signs"  #: no single driver keeps the sign of DJ over the positions
    CIRCUITS = "circuits"  #: the full defect analysis found no usable driver
    ERROR = "error"  #: a numerical routine failed (``error`` says how)
