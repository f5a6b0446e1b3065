"""Serial chains from Denavit-Hartenberg parameters.

A row of DH parameters places one joint after the other.  Two conventions are in use and both
are named explicitly (never implied):

``"standard"`` (Denavit and Hartenberg; Spong; Corke's ``DHLink``)
    ``T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``: joint ``i`` turns about (or slides
    along) the ``z`` axis of frame ``i - 1`` through that frame's origin.
``"modified"`` (Craig)
    ``T_i = Rx(alpha_(i-1)) Tx(a_(i-1)) Rz(theta_i) Tz(d_i)``: joint ``i`` turns about (or
    slides along) the ``z`` axis of frame ``i`` itself; row ``i`` holds ``alpha_(i-1)`` and
    ``a_(i-1)``.

The chain becomes a :class:`~.mechanism.Mechanism` of one limb from the ground to the output
link (frame ``n``), every joint actuated, the joints placed at the *reference* joint values
``theta`` (revolute) or ``d`` (prismatic) given by ``reference``: the mechanism's joint
variables are then measured from that reference (a DH value is ``reference + q``), and the
output frame's origin is the platform point.  Lengths in metres, angles in radians (the
``degrees=True`` flag reads ``theta``, ``alpha`` and ``reference`` of revolutes in degrees).

>>> import numpy as np
>>> from spatialmech.model.dh import serial_from_dh
>>> m = serial_from_dh("2r", d=[0, 0], a=[1.0, 0.5], alpha=[0, 0])
>>> [j.type for j in m.limbs[0].joints], m.platform_point.round(12).tolist()
(['R', 'R'], [1.5, 0.0, 0.0])
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..errors import InputError
from ..geometry.screws import nondimensional
from ..geometry.tolerances import current
from .joints import P, R
from .mechanism import Limb, Mechanism

__all__ = ["CONVENTIONS", "dh_frames", "serial_from_dh"]

#: the DH conventions understood here (module docstring)
CONVENTIONS = ("standard", "modified")


def _rows(name: str, v, n: int | None) -> np.ndarray:
    try:
        x = np.asarray(v, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a sequence of numbers, got {v!r}") from None
    if x.ndim != 1 or (n is not None and len(x) != n):
        raise InputError(f"{name}: expected {n if n is not None else 'a list of'} numbers, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise InputError(f"{name}: every value must be finite, got {x.tolist()}")
    return x


def _check(d, a, alpha, theta, joints: str, convention: str):
    if convention not in CONVENTIONS:
        raise InputError(f"convention: expected one of {', '.join(CONVENTIONS)}, got {convention!r}")
    d_ = _rows("d", d, None)
    n = len(d_)
    if n == 0:
        raise InputError("d: a serial chain needs at least one joint (got an empty list)")
    a_, alpha_, theta_ = _rows("a", a, n), _rows("alpha", alpha, n), _rows("theta", theta, n)
    if len(joints) != n or set(joints) - {"R", "P"}:
        raise InputError(f"joints: expected {n} letters R or P (one per DH row), got {joints!r}")
    return d_, a_, alpha_, theta_


def dh_frames(d, a, alpha, theta, *, joints: str | None = None, convention: str = "standard") -> np.ndarray:
    """The frames ``0 .. n`` of a DH chain, shape ``(n + 1, 4, 4)``; frame 0 is the base.

    ``d``, ``a``, ``alpha``, ``theta``: one value per row (metres, radians), the joint values
    included (``theta`` of a revolute, ``d`` of a prismatic joint); ``joints`` is only checked
    here (the frames do not depend on which value is the variable).
    """
    n = len(np.atleast_1d(d))
    d_, a_, al_, th_ = _check(d, a, alpha, theta, joints or "R" * n, convention)
    F = np.empty((n + 1, 4, 4))
    F[0] = np.eye(4)
    for i in range(n):
        ct, st, ca, sa = np.cos(th_[i]), np.sin(th_[i]), np.cos(al_[i]), np.sin(al_[i])
        if convention == "standard":
            T = np.array([[ct, -st * ca, st * sa, a_[i] * ct], [st, ct * ca, -ct * sa, a_[i] * st],
                          [0.0, sa, ca, d_[i]], [0.0, 0.0, 0.0, 1.0]])
        else:
            T = np.array([[ct, -st, 0.0, a_[i]], [st * ca, ct * ca, -sa, -sa * d_[i]],
                          [st * sa, ct * sa, ca, ca * d_[i]], [0.0, 0.0, 0.0, 1.0]])
        F[i + 1] = F[i] @ T
    return F


def serial_from_dh(
    name: str,
    *,
    d: Sequence[float],
    a: Sequence[float],
    alpha: Sequence[float],
    theta: Sequence[float] | None = None,
    joints: str | None = None,
    reference: Sequence[float] | None = None,
    convention: str = "standard",
    degrees: bool = False,
    description: str = "",
) -> Mechanism:
    """A serial chain from DH parameters: one limb from the ground to the output link.

    Parameters
    ----------
    name : str
        The mechanism's name.
    d, a, alpha : sequence of float
        One value per row (metres; ``alpha`` in radians unless ``degrees``), in the order of
        ``convention`` (module docstring: ``"modified"`` rows hold ``a_(i-1)``, ``alpha_(i-1)``).
    theta : sequence of float, optional
        The constant joint angle of each row (the offset of a revolute's angle, the angle of a
        prismatic row); default 0.
    joints : str, optional
        One letter per row, ``"R"`` (revolute: ``theta`` varies) or ``"P"`` (prismatic: ``d``
        varies); default all ``"R"``.
    reference : sequence of float, optional
        The joint values added to ``theta`` (revolute) or ``d`` (prismatic) at which the joints
        are placed; the mechanism's joint variables are measured from there.  Choose a regular
        configuration: the analyses start from it.  Default 0.
    convention : {"standard", "modified"}
        The DH convention, named explicitly.
    degrees : bool
        ``alpha``, ``theta`` and the revolutes' ``reference`` in degrees.
    description : str
        A one-line description.

    Returns
    -------
    Mechanism
        Joints ``J1 .. Jn``, all actuated; the platform point is the origin of frame ``n``.

    Raises
    ------
    InputError
        A convention or joint letter not known, lists of different lengths, a value not finite.

    Examples
    --------
    >>> from spatialmech.model.dh import serial_from_dh
    >>> m = serial_from_dh("rp", d=[0.0, 0.2], a=[0.3, 0.0], alpha=[90.0, 0.0], joints="RP", degrees=True)
    >>> [j.name for j in m.limbs[0].joints], m.platform_point.round(12).tolist()
    (['J1', 'J2'], [0.3, -0.2, 0.0])
    """
    n = len(np.atleast_1d(np.asarray(d, dtype=object)))
    joints = joints if joints is not None else "R" * n
    d_, a_, al_, th_ = _check(d, a, alpha, np.zeros(n) if theta is None else theta, joints, convention)
    ref = _rows("reference", np.zeros(n) if reference is None else reference, n)
    rev = np.array([c == "R" for c in joints])
    if degrees:
        al_, th_ = np.radians(al_), np.radians(th_)
        ref = np.where(rev, np.radians(ref), ref)
    F = dh_frames(np.where(rev, d_, d_ + ref), a_, al_, np.where(rev, th_ + ref, th_), joints=joints,
                  convention=convention)
    # the frame whose z axis is joint i's axis: i - 1 (standard) or i (modified)
    axis_frames = F[:-1] if convention == "standard" else F[1:]
    made = []
    for i, (c, Fi) in enumerate(zip(joints, axis_frames, strict=True)):
        make = R if c == "R" else P
        made.append(make(f"J{i + 1}", Fi[:3, 3], Fi[:3, 2], actuated=True))
    mech = Mechanism(name, (Limb("arm", tuple(made)),), platform_point=F[-1][:3, 3].copy(),
                     description=description or f"serial {joints} chain ({convention} DH)")
    _warn_if_singular(mech, min(6, len(joints)))
    return mech


def _warn_if_singular(mech: Mechanism, need: int) -> None:
    """A warning naming ``reference`` when the arm is singular there: its joint screws (moments
    over the length scale) span fewer than ``need = min(6, n)`` dimensions.  At the DH zero every
    standard-DH arm is (every joint axis is perpendicular to ``x0``), so the default reference
    needs one given by the user for the analyses that start from it."""
    import warnings

    S = nondimensional([j.freedoms[0].screw for j in mech.limbs[0].joints], mech.characteristic_length)
    sv = np.linalg.svd(S, compute_uv=False)
    if len(sv) < need or sv[need - 1] < current().rank * sv[0]:
        warnings.warn(f"reference: the arm {mech.name!r} is singular at its reference configuration (its joint "
                      f"screws span fewer than {need} dimensions; at the DH zero every standard-DH arm is); "
                      "give a regular reference (e.g. reference_deg in a file): fk, ik and the maps start there",
                      UserWarning, stacklevel=3)
