"""Every numerical tolerance of spatialmech, in one place, and the scale they are measured in.

A decision that depends on a tolerance (is this screw system of rank 4? is this configuration
closed? is this pose reachable? are these two solutions the same?) reads it from a
:class:`Tolerances`.  Every tolerance is *nondimensional*: lengths are divided by the
mechanism's characteristic length ``L`` (:func:`characteristic_length`, the RMS distance of the
joint points from their centroid), so a model in millimetres and the same model in metres make
the same decisions.  Angles are in radians (already nondimensional).

The tolerances in force are :data:`DEFAULT` unless a caller passes its own, either explicitly
(``mobility(mech, tol=1e-4)``) or for a whole block of work with :func:`use` (the command
line's ``--tol`` does that)::

    >>> from spatialmech.geometry.tolerances import DEFAULT, Tolerances, current, use
    >>> DEFAULT.rank
    1e-09
    >>> with use(rank=1e-4):
    ...     current().rank
    0.0001
    >>> current().rank
    1e-09
    >>> Tolerances.parse("1e-4", primary="reachability").reachability
    0.0001
    >>> Tolerances.parse("rank=1e-6,closure=1e-8").closure
    1e-08

Scale.  The characteristic length must lie in ``[min_length, max_length]`` model units and the
model must not lie more than ``max_ratio`` characteristic lengths from its origin (a helical
pitch, likewise, at most ``max_ratio`` characteristic lengths per radian): outside these the
moments of the screws lose the digits that the rank decisions need, so such models are refused
with an :class:`~spatialmech.errors.InputError` naming the field rather than analysed wrongly.
Every number typed into a model must be finite and at most ``max_input`` in magnitude.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, fields, replace

import numpy as np

from ..errors import InputError
from ..serialize import fields_dict

__all__ = [
    "BLOCK_MAX_COND",
    "BLOCK_RANK_ZERO",
    "BRANCH_REACH",
    "BRANCH_STEP",
    "CONE_DIFFERENCE_STEP",
    "CONE_EMPTY",
    "CONE_ZERO",
    "DEFAULT",
    "ENDGAME_AGREE",
    "ENDGAME_CLOSED",
    "ENDGAME_LOOPS",
    "ENDGAME_POINTS",
    "ENDGAME_RADIUS",
    "HOMOTOPY_FLOOR",
    "HOMOTOPY_INFINITY",
    "HOMOTOPY_JUMP",
    "HOMOTOPY_NEAR_REAL",
    "HOMOTOPY_NEWTON",
    "HOMOTOPY_REAL",
    "HOMOTOPY_SINGULAR",
    "IK_DETOURS",
    "IK_DETOUR_SIZE",
    "INPUT_PERTURBATION",
    "INPUT_PERTURBATIONS",
    "INPUT_PERTURBATION_SEED",
    "INPUT_PERTURBATION_STEPS",
    "INVERSE_SINGULAR",
    "LOCAL_DIMENSION_STEP",
    "MONODROMY_DIVERGED",
    "MONODROMY_MAX_LOOPS",
    "MONODROMY_MAX_SOLUTIONS",
    "MONODROMY_MAX_WORK",
    "MONODROMY_PARALLEL",
    "MONODROMY_RESIDUAL",
    "MONODROMY_STALE_LOOPS",
    "NEAR_INVERSE_SINGULAR",
    "NEAR_SINGULAR",
    "ROTATION_EXACT",
    "ROTATION_INPUT",
    "SINGULAR_LEFT",
    "TRACE_MAX_LOOPS",
    "TRACE_MAX_WORK",
    "TRACE_MAX_WORK_FULL",
    "TRACE_STALE_LOOPS",
    "TRACE_STEP",
    "TRACE_TOL",
    "Tolerances",
    "characteristic_length",
    "current",
    "use",
]


@dataclass(frozen=True)
class Tolerances:
    """The numerical tolerances (all nondimensional; see the module docstring)."""

    #: Relative singular-value threshold for the rank of a screw system or of a Jacobian made
    #: nondimensional (moments / L, slides / L) and row- or column-normalised: a singular value
    #: ``s`` counts when ``s > rank * max(1, s_max)``.  Decides lambda, t, k, xi, the motion type,
    #: the instantaneous mobility, the tangent space of the closure manifold.
    rank: float = 1e-9
    #: Scale-free smallest singular value of a complete Jacobian (or of a wrench system at a pose)
    #: below which the configuration is reported singular (``singularity``, ``jacobian``, ``fk``).
    singular: float = 1e-7
    #: Nondimensional closure residual (rad, and length / L) at which Newton corrections stop and
    #: count as converged (forward position, generic configurations, path tracking).
    newton: float = 1e-12
    #: Nondimensional residual below which a limb solved for a given platform pose counts as
    #: closed (inverse position, pose fits).
    closure: float = 1e-10
    #: Largest nondimensional pose error (rad, and length / L) between a requested platform pose
    #: and the nearest closed configuration for which ``ik`` fits the pose (and says by how
    #: much) instead of calling it unreachable: covers poses printed with 6 significant digits.
    reachability: float = 1e-5
    #: Nondimensional distance between two solutions below which they are the same solution
    #: (inverse position: in configuration space, every angle as 2 sin(d / 2), slides / L, an S
    #: joint's rotation as 2 sin(d / 2) of the angle between the two; forward position: the pose
    #: distance of kinematics/assembly.py).
    dedup: float = 1e-6
    #: Pivot threshold of the readable (row-echelon) basis of a screw system, relative to the
    #: largest remaining entry: smaller pivots are rounding noise of typed data, not structure.
    pivot: float = 1e-3
    #: Relative singular-value threshold for "this screw lies in that system" (motion names).
    contains: float = 1e-6
    #: Tolerance on ``| |axis| - 1 |`` and on the perpendicularity of the declared axes of a joint.
    unit: float = 1e-6
    #: Smallest and largest accepted characteristic length, in model units.
    min_length: float = 1e-12
    max_length: float = 1e12
    #: Largest accepted distance of the model from its origin, and helical pitch, in
    #: characteristic lengths.
    max_ratio: float = 1e6
    #: Largest magnitude of any number typed into a model (coordinates, pitches, offsets, limits).
    max_input: float = 1e12

    def __post_init__(self):
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0:
                raise InputError(f"tolerances.{f.name}: expected a positive finite number, got {v!r}")
            object.__setattr__(self, f.name, float(v))
        for name in ("rank", "singular", "newton", "closure", "reachability", "dedup", "pivot", "contains", "unit"):
            if getattr(self, name) >= 1:
                raise InputError(f"tolerances.{name}: a relative tolerance must be below 1, got {getattr(self, name):g}")
        if self.min_length >= self.max_length:
            raise InputError(f"tolerances.min_length: must be below max_length ({self.min_length:g} >= {self.max_length:g})")
        if self.max_ratio < 1:
            raise InputError(f"tolerances.max_ratio: must be at least 1, got {self.max_ratio:g}")

    def replace(self, **changes) -> Tolerances:
        """A copy with some tolerances changed (names checked)."""
        known = {f.name for f in fields(self)}
        bad = sorted(set(changes) - known)
        if bad:
            raise InputError(f"tolerances: unknown name(s) {', '.join(bad)}; known: {', '.join(sorted(known))}")
        return replace(self, **changes)

    def to_dict(self) -> dict:
        return fields_dict(self)

    @classmethod
    def parse(cls, text: str, *, primary: str = "rank", base: Tolerances | None = None) -> Tolerances:
        """``"1e-4"`` (sets ``primary``) or ``"rank=1e-4,closure=1e-8"`` (named ones), on top of
        ``base`` (default: the tolerances in force).  The error names ``--tol``."""
        base = current() if base is None else base
        text = str(text).strip()
        if not text:
            raise InputError("--tol: expected a number or NAME=VALUE[,NAME=VALUE...], got an empty value")
        changes: dict[str, float] = {}
        for part in text.split(","):
            part = part.strip()
            name, sep, value = part.partition("=")
            if not sep:
                name, value = primary, name
            name = name.strip()
            try:
                x = float(value)
            except ValueError:
                raise InputError(f"--tol: expected a number or NAME=VALUE, got {part!r}") from None
            if name in changes:
                raise InputError(f"--tol: {name} given twice")
            changes[name] = x
        try:
            return base.replace(**changes)
        except InputError as e:
            raise InputError(f"--tol: {e}") from None


#: The tolerances used when none are given.
DEFAULT = Tolerances()

#: Scale-free smallest singular value of the complete Jacobian below which the design studio
#: (``spatialmech studio``) warns that the configuration is near a singularity (colour warning);
#: a reading aid, not a verdict (``singular`` above decides that).
NEAR_SINGULAR = 0.02
#: Actuation transmission index ``|W.$a| / (|W| |$a|)`` below which a limb is called inversely
#: singular where a studio pose drag cannot go on (``limb_singular``), and the studio's inverse
#: light turns red; below :data:`NEAR_INVERSE_SINGULAR` it is amber (a reading aid, as above).
INVERSE_SINGULAR = 0.05
NEAR_INVERSE_SINGULAR = 0.1

#: A pose's rotation matrix may be this far from orthonormal (``max |R R^T - I|``): a matrix
#: typed with six decimals is.  Beyond :data:`ROTATION_EXACT` (round-off of the library's own
#: products) it is replaced by its nearest rotation, with a warning naming the error.
ROTATION_INPUT = 1e-6
ROTATION_EXACT = 1e-12

#: Points whose spread is below this, relative to their coordinates, are the same point (round-off).
_SAME_POINT = 1e-13

_CURRENT: ContextVar[Tolerances] = ContextVar("spatialmech_tolerances", default=DEFAULT)


def current() -> Tolerances:
    """The tolerances in force (:data:`DEFAULT` outside a :func:`use` block)."""
    return _CURRENT.get()


def resolve(tol: Tolerances | float | None, field: str = "rank") -> Tolerances:
    """``tol`` as a :class:`Tolerances`: ``None`` -> the tolerances in force, a number -> them with
    ``field`` set to it."""
    if tol is None:
        return current()
    if isinstance(tol, Tolerances):
        return tol
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.floating)):
        raise InputError(f"tol: expected a number or a Tolerances, got {type(tol).__name__}")
    return current().replace(**{field: float(tol)})


@contextmanager
def use(tol: Tolerances | None = None, **changes) -> Iterator[Tolerances]:
    """Run a block with other tolerances: ``use(Tolerances(...))`` or ``use(rank=1e-4)``."""
    t = current() if tol is None else tol
    if not isinstance(t, Tolerances):
        raise InputError(f"tol: expected a Tolerances, got {type(t).__name__}")
    t = t.replace(**changes) if changes else t
    token = _CURRENT.set(t)
    try:
        yield t
    finally:
        _CURRENT.reset(token)


def characteristic_length(points, *, tol: Tolerances | None = None, field: str = "points") -> float:
    """RMS distance of ``points`` (n x 3) from their centroid, computed without overflow or
    underflow.  When the points coincide (up to round-off relative to their size) the length
    is their distance from the origin, or 1 when that is zero too (a spherical mechanism
    centred at the origin).

    Raises :class:`InputError` naming ``field`` when the length is outside
    ``[min_length, max_length]`` or the points lie more than ``max_ratio`` such lengths from the
    origin (see the module docstring).
    """
    t = current() if tol is None else tol
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    if not np.all(np.isfinite(P)):
        raise InputError(f"{field}: contain NaN or infinity")
    size = float(np.max(np.abs(P))) if P.size else 0.0
    if size == 0.0:
        return 1.0
    Q = P / size  # O(1): no overflow or underflow in the squares
    c = Q.mean(axis=0)
    spread = float(np.sqrt(np.mean(np.sum((Q - c) ** 2, axis=1))))
    if spread <= _SAME_POINT:  # every point at the same place (up to round-off): a spherical mechanism
        L = size * float(np.linalg.norm(c))
        what = "distance of the joint points (which coincide) from the origin"
    else:
        L = size * spread
        what = "characteristic length (RMS distance of the joint points from their centroid)"
    if not t.min_length <= L <= t.max_length:
        hint = (" (a spherical mechanism centred at the origin: put its joint points exactly there)"
                if t.min_length > L else "")
        raise InputError(
            f"{field}: the model's {what} is {L:.3g} model units, outside the supported range "
            f"[{t.min_length:g}, {t.max_length:g}]; express its lengths in another unit{hint}"
        )
    far = size / L
    if far > t.max_ratio:
        raise InputError(
            f"{field}: the model lies {far:.3g} characteristic lengths ({L:.3g}) from its origin, more than "
            f"{t.max_ratio:g}: the screws' moments would lose the digits that rank decisions need; "
            "move the origin near the mechanism"
        )
    return L


#: Homotopy continuation (:mod:`spatialmech.kinematics.homotopy`), all nondimensional: Newton
#: corrector stopping size (relative to the point's norm), the largest first Newton update that
#: a step may take (path-jumping guard), the inverse condition number below which an end point
#: is singular, the ``|e.e| / |x|^2`` below which an end point is at infinity (the exceptional
#: generator of the Study quadric), the imaginary part (relative) below which it is real, and
#: below which a singular end point (located to a few digits only) seeds a real Newton polish.
HOMOTOPY_NEWTON = 1e-11
HOMOTOPY_JUMP = 1e-3
#: The limb inverse position's tracker (kinematics/compiled/kernels_ik.py) also accepts a step
#: whose two Newton corrections are both below this (relative): the corrector's rounding floor at
#: an ill-conditioned point (a complex angle far from real: cos and sin of about e^|Im theta|),
#: where neither correction can contract further.
HOMOTOPY_FLOOR = 1e-5
HOMOTOPY_SINGULAR = 1e-7
HOMOTOPY_INFINITY = 1e-7
HOMOTOPY_REAL = 1e-7
HOMOTOPY_NEAR_REAL = 1e-3
#: Smallest singular value of a near-real end point's square system, relative to its largest,
#: below which an end point that is not real to :data:`HOMOTOPY_REAL` is taken for a multiple
#: root (whose end points keep about the square root of the rounding in their imaginary parts:
#: a real solution at a singular configuration) rather than a complex solution.
HOMOTOPY_ILL = 1e-4

#: Certified solutions (kinematics/homotopy/certify.py), nondimensional (relative to ``1 + max |y|``,
#: ``y`` the point in the system's coordinates): the half-width of the first Krawczyk box (or four
#: times the point's Newton correction, if larger), the factor between the boxes tried, and the
#: largest box: a point whose root lies farther away is not certified.  The ball arithmetic's
#: working precision in bits, and the precision of a second try for a point whose boxes all fail
#: (an ill-conditioned root: at 53 bits the enclosure of ``A F(y)`` is as wide as the condition
#: number times the rounding, and no box about the point contracts).
CERTIFY_MIN_RADIUS = 1e-13
CERTIFY_GROWTH = 100.0
CERTIFY_MAX_RADIUS = 1e-8
CERTIFY_PRECISION = 53
CERTIFY_PRECISION_HIGH = 106

#: Forward-position solution flags (kinematics/solution_flags.py).  A solution is
#: *input-independent* (it persists for every actuator value: the actuators move without moving
#: the platform) when the same platform pose still closes after each of ``INPUT_PERTURBATIONS``
#: random changes of every actuator value at once (seed ``INPUT_PERTURBATION_SEED``), each change
#: of a random sign and a size between half and one ``INPUT_PERTURBATION`` (rad, or length / L):
#: the joints solved by Newton (at most ``INPUT_PERTURBATION_STEPS`` steps) from the solution's,
#: with the platform and the actuators held, must reach the ``closure`` tolerance.  The change is
#: not tiny on purpose: at an inverse singularity (a leg stretched) the closure error of a held
#: pose grows with the square of the change, about 1e-4 here, far above the closure tolerance.
INPUT_PERTURBATION = 1e-2
INPUT_PERTURBATIONS = 3
INPUT_PERTURBATION_SEED = 27
INPUT_PERTURBATION_STEPS = 30

#: Cauchy end game (:mod:`spatialmech.kinematics.homotopy.endgame`), nondimensional: the first radius of
#: the loops about ``t = 1`` (in the homotopy parameter), the points per loop, the most loops
#: before a path must close (its winding number), the relative distance at which a loop has
#: closed, the relative agreement of the estimates at two radii that accepts the end point, and
#: the relative size of the perturbations of the local dimension test.
ENDGAME_RADIUS = 0.05
ENDGAME_POINTS = 24
ENDGAME_LOOPS = 6
ENDGAME_CLOSED = 1e-6
ENDGAME_AGREE = 1e-8
LOCAL_DIMENSION_STEP = 1e-4

#: Monodromy (kinematics/homotopy/general.py): loops in a row without a new solution before the
#: solve stops (saturation, not a proof), the most loops, and the relative residual of the full
#: closure below which an end point of the square system is a solution (else spurious).
MONODROMY_STALE_LOOPS = 8
MONODROMY_MAX_LOOPS = 80
MONODROMY_MAX_SOLUTIONS = 128  # method="auto" gives up beyond this (the multi-start runs instead)
#: and beyond this work: the tracker's steps times unknowns, the next round predicted from the
#: last (a count, not a time, so that every machine makes the same choice; about 10-20 s here
#: for five-cs-3, three-rrr-sm or delta-ruu; the Bennett's 40 generic solutions take 150,000;
#: method="homotopy" has neither cap)
MONODROMY_MAX_WORK = 250_000
MONODROMY_DIVERGED = 1e4  # a path stopped short with |x| beyond this is at infinity (affine variables)
MONODROMY_PARALLEL = 4  # loops tracked together in one batch
MONODROMY_RESIDUAL = 1e-8
#: A limb's inverse position (kinematics/homotopy/inverse.py): when a path of the re-solve stops
#: midway (a near miss of a branch point), all paths are tracked again through a random complex
#: waypoint near the pose (at this fraction of the parameters' distance from the generic instance),
#: at most this many times.
IK_DETOURS = 3
IK_DETOUR_SIZE = 0.3

#: Trace test (kinematics/homotopy/trace_test.py), nondimensional: the largest relative deviation of the
#: traces from a line that passes (a complete set gives 1e-11 or less, a missing solution of the
#: order of 1e-2 to 1), the size of the two moves of the fibre, the loops in a row without a new
#: witness point before a test, and the most loops over the hyperplanes; and the work (paths
#: tracked times unknowns) after which ``method="auto"`` stops it (verdict "capped", not proven),
#: and the work after which ``method="homotopy"`` stops it.
TRACE_TOL = 1e-8
TRACE_STEP = 0.3
TRACE_STALE_LOOPS = 8
TRACE_MAX_LOOPS = 200
TRACE_MAX_WORK = 40_000
TRACE_MAX_WORK_FULL = 2_000_000

#: Block elimination of the closure's Newton step (kinematics/compiled/kernels_blocks.py), relative to a
#: block's largest column: remaining columns at or below ``BLOCK_RANK_ZERO`` are rank-deficient
#: directions (an S-P-S leg's idle spin: about 1e-16), and a block whose rank lies between the
#: two, or whose triangular factor is conditioned worse than ``BLOCK_MAX_COND``, goes to the
#: general least-squares solver (the SVD decides there).
BLOCK_RANK_ZERO = 1e-13
BLOCK_MAX_COND = 1e8

#: Mobility at a singular reference (analysis/mobility.py, docs/mobility.md), all nondimensional
#: (rad, and length / L, in the local coordinates of the closure manifold): the distance a generic
#: configuration must have moved from the reference to count as having left it; the step of the
#: central second differences of the closure residual along the kernel (their error is about
#: 1e-8 of the quadrics' size); the size of the second-order obstruction ``|Q(v)|`` (relative to
#: the largest quadric, ``|v| = 1``) below which a kernel direction ``v`` lies in the tangent cone
#: (100 times that error; the rank tolerance when looser), and above which at every start the cone
#: has no real direction (1000 times the error; between the two: undecided);
#: the predictor step along a branch and the distance out to which it is followed before its
#: dimension is read (the rank there is ~BRANCH_REACH times the rank jump away from the tolerance).
SINGULAR_LEFT = 1e-3
CONE_DIFFERENCE_STEP = 1e-4
CONE_ZERO = 1e-6
CONE_EMPTY = 1e-5
BRANCH_STEP = 0.01
BRANCH_REACH = 0.1
