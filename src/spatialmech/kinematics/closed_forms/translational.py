"""The translational assembly modes of a platform in closed form: the forward-position solutions
whose platform keeps its reference orientation (issue 27).

On the Delta (``delta``, its parallelograms as two S-S rods, and ``delta-ruu``, as U-U pairs)
and on Tsai's 3-UPU, every limb's conditions on the platform (the quadrics of
:func:`..homotopy.systems.pose_system`, read from the model, not from its name) become, with the
platform held at its reference orientation, a sphere for its translation ``t`` (a leg, a rod
from a driven arm; a parallelogram's two rods give the same sphere) or hold identically (the
U-P-U condition).  Three distinct spheres: their pairwise differences are two linear equations,
a line, and the first sphere a quadratic on it, so there are **at most 2** solutions (Bezout:
``1 * 1 * 2``), in closed form, both real or a complex pair (a double root on the boundary of the
workspace).

These are *not* the complete forward position of those models: their configuration spaces also
hold assembly modes with the platform turned (the parallelograms broken, the U-P-U legs off
Tsai's translational branch), which ``sm.fk(..., all_solutions=True)`` finds by homotopy
continuation and proves complete (docs/homotopy.md).  The translational modes are exactly those
of its solutions whose rotation is the identity (tested), and :func:`translational_modes` is the
closed-form check of that subset.

Example::

    >>> import numpy as np
    >>> from spatialmech import catalog
    >>> t = translational_modes(catalog.resolve("delta"), np.radians([5.73, 11.46, -5.73]))
    >>> t.n_real, t.n_complex, sorted(np.round(t.points[:, 2], 6).tolist())
    (2, 0, [-0.36245, 0.336205])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError
from ...model.mechanism import Mechanism, Pose

__all__ = ["TranslationalModes", "translational_modes", "translational_note", "translational_reason"]

#: Relative size below which a coefficient counts as zero (the quadrics are nondimensional, of order 1).
_ZERO = 1e-10


@dataclass(frozen=True, eq=False)
class TranslationalModes:
    """The translational solutions of one request: ``points`` (k, 3) the real platform points
    (model units), ``poses`` the same as :class:`Pose` (reference orientation), ``n_real`` and
    ``n_complex`` (``n_real + n_complex`` is 2, the Bezout bound, unless the linear equations are
    inconsistent: then 0), ``residual`` the largest nondimensional residual of the limb conditions
    at the real points, ``statement`` how the count is proven."""

    points: np.ndarray
    n_real: int
    n_complex: int
    residual: float
    statement: str

    @property
    def poses(self) -> tuple[Pose, ...]:
        return tuple(Pose(np.eye(3), p, f"translational {k + 1}") for k, p in enumerate(self.points))


def _rows(mech: Mechanism, values) -> list[tuple[np.ndarray, np.ndarray, float]]:
    """Each limb quadric of ``mech`` (Study parameters) restricted to the reference orientation,
    as ``(A, b, c)`` of ``tau^T A tau + b . tau + c`` in ``tau = t / L``; rows that vanish
    identically there are left out."""
    from ..homotopy.systems import pose_system

    Qv = pose_system(mech).coefficients(np.asarray(values, dtype=float))
    x0 = np.zeros(8)
    x0[0] = 1.0  # e = 1: R = I
    M = np.zeros((8, 3))
    M[5:, :] = 0.5 * np.eye(3)  # g = (0, tau / 2): p = 2 g e* = tau
    out = []
    for Q in Qv[1:]:
        A, b, c = M.T @ Q @ M, 2.0 * M.T @ Q @ x0, float(x0 @ Q @ x0)
        if max(np.abs(A).max(), np.abs(b).max(), abs(c)) > _ZERO:
            out.append((A, b, c))
    return out


def _spheres_and_planes(rows) -> tuple[str | None, list, list]:
    """(why not, spheres ``(b, c)`` of ``|tau|^2 + b . tau + c``, linear rows ``(b, c)``)."""
    spheres, linear = [], []
    for A, b, c in rows:
        alpha = float(np.trace(A)) / 3.0
        if np.abs(A - alpha * np.eye(3)).max() > _ZERO * max(1.0, abs(alpha)):
            return "a limb condition at the reference orientation is a quadric other than a sphere", [], []
        if abs(alpha) > _ZERO:
            spheres.append((b / alpha, c / alpha))
        else:
            linear.append((b, c))
    return None, spheres, linear


def translational_reason(mech: Mechanism, values=None) -> str | None:
    """``None`` when :func:`translational_modes` applies to ``mech`` (its limbs reduce to spheres
    for the translation, at least one, with the reference orientation held), else why not."""
    v = np.array([mech.freedom(a).freedom.offset for a in mech.actuators]) if values is None else values
    return _spheres(mech, v)[0]


def _spheres(mech: Mechanism, values) -> tuple[str | None, list]:
    """(why not, the sphere conditions ``(b, c)``) of ``mech`` at ``values``, the rows computed once."""
    from ..homotopy.systems import pose_system, unsupported_reason

    try:
        pose_system(mech)  # cached per model object
    except InputError:
        return f"its limbs do not reduce to quadrics in the platform pose: {unsupported_reason(mech)}", []
    why, spheres, linear = _spheres_and_planes(_rows(mech, values))
    if why is None and (not spheres or linear):
        why = "its limbs give planes, not only spheres, at the reference orientation (no translational family)"
    if why is None and (n := _n_distinct(spheres)) != 3:
        why = (f"its limbs give {n} distinct spheres at the reference orientation, not 3 (a translational family "
               "has three: a Delta, a 3-UPU)")
    return why, spheres


def _n_distinct(spheres) -> int:
    """How many of the spheres ``(b, c)`` differ (a parallelogram's two rods give one)."""
    kept: list = []
    for b, c in spheres:
        if not any(np.abs(b - b2).max() + abs(c - c2) < 1e-9 * (1.0 + np.abs(b).max() + abs(c)) for b2, c2 in kept):
            kept.append((b, c))
    return len(kept)


def translational_modes(mech: Mechanism, values) -> TranslationalModes:
    """The forward-position solutions of ``mech`` at the actuator values ``values`` (physical, SI,
    in ``mech.actuators`` order) whose platform keeps its reference orientation, in closed form
    (module docstring): three spheres for the translation, at most two solutions.  Raises
    :class:`InputError` naming the reason when the limbs do not reduce to spheres there, or when
    the spheres do not cut out finitely many points (concentric or coaxial centres)."""
    values = np.asarray(values, dtype=float).ravel()
    if values.size != len(mech.actuators):
        raise InputError(f"values: expected {len(mech.actuators)} actuator values ({', '.join(mech.actuators)}), "
                         f"got {values.size}")
    why, spheres = _spheres(mech, values)
    if why is not None:
        raise InputError(f"model: no translational closed form for {mech.name}: {why}")
    b0, c0 = spheres[0]
    G = np.array([b - b0 for b, _ in spheres[1:]]).reshape(-1, 3)  # differences: G tau = h
    h = np.array([c0 - c for _, c in spheres[1:]])
    sv = np.linalg.svd(G, compute_uv=False) if G.size else np.zeros(0)
    rank = int(np.sum(sv > 1e-9 * max(1.0, float(sv[0]) if sv.size else 0.0)))
    if rank != 2:
        raise InputError(f"model: the {len(spheres)} spheres of {mech.name} at these actuator values have "
                         f"centres spanning {rank} dimension(s): not a finite intersection of three spheres")
    tau0 = np.linalg.lstsq(G, h, rcond=None)[0]
    n = np.linalg.svd(G)[2][-1]
    n = n * (1.0 if n[np.argmax(np.abs(n))] > 0 else -1.0)  # a fixed sense, whatever the SVD's sign
    L = mech.characteristic_length
    p0 = mech.platform_point
    if np.abs(G @ tau0 - h).max() > 1e-9 * max(1.0, np.abs(h).max()):
        return TranslationalModes(np.zeros((0, 3)), 0, 0, 0.0,
                                  "no translational solution: the spheres' radical planes do not meet")
    # |tau0 + s n|^2 + b0 . (tau0 + s n) + c0 = 0, a quadratic in s (n a unit vector)
    bq = 2.0 * tau0 @ n + b0 @ n
    cq = tau0 @ tau0 + b0 @ tau0 + c0
    disc = bq * bq - 4.0 * cq
    if disc < -1e-12 * max(1.0, bq * bq):
        pts = np.zeros((0, 3))
        n_real, n_complex = 0, 2
    else:
        r = np.sqrt(max(disc, 0.0))
        s = np.array([(-bq + r) / 2.0, (-bq - r) / 2.0])
        pts = p0 + L * (tau0[None, :] + s[:, None] * n[None, :])
        n_real, n_complex = 2, 0
    res = 0.0
    for p in pts:
        tau = (p - p0) / L
        res = max(res, max(abs(tau @ tau + b @ tau + c) for b, c in spheres))
    statement = (f"translational modes in closed form: {len(spheres)} sphere conditions with the reference "
                 "orientation held (three distinct spheres), two radical planes and a quadratic: at most 2 "
                 f"(Bezout 1 x 1 x 2); {n_real} real, {n_complex} complex")
    return TranslationalModes(pts, n_real, n_complex, float(res), statement)


def translational_note(mech: Mechanism, values, poses) -> str | None:
    """The sentence the complete forward position adds for a model with a translational family
    (``None`` for the others, and where the spheres meet in no point at all): how many of its
    real solutions ``poses`` keep the platform's reference orientation, and whether the closed
    form (:func:`translational_modes`) gives the same ones."""
    from ...geometry.tolerances import current

    try:
        t = translational_modes(mech, values)
    except InputError:
        return None
    if t.n_real + t.n_complex == 0:
        return None
    L = mech.characteristic_length
    tol = current().dedup
    ident = [p for p in poses if np.linalg.norm(p.R - np.eye(3)) < tol]
    same = len(ident) == t.n_real and all(any(np.linalg.norm(p.p - q.p) / L < tol for q in ident) for p in t.poses)
    return (f"{len(ident)} of the real solutions keep the platform's reference orientation (the translational "
            f"modes; the others have it turned); the translational closed form (three spheres: at most 2, Bezout) "
            f"gives {t.n_real} real and {t.n_complex} complex, {'the same' if same else 'NOT the same (a defect)'}")
