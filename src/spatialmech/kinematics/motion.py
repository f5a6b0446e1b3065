"""The tangent space of the closure manifold, and a demonstration motion along it: a short loop
of closed configurations (what the 3-D viewer animates for a model of any mobility).

This is **not** the continuation tracker (:mod:`.tracking`): it does no driver-controlled
tracking, no branch or singularity handling and no step-size control beyond halving a failed
step.  It exists so that the viewer (:mod:`spatialmech.present.viewer`, which only draws) has
something honest to animate for any model: every configuration it returns satisfies the closure
equations of :mod:`.closure` (checked by :func:`.backend.correct`), and the viewer accepts any
list of :class:`~.closure.Configuration` so that tracked paths can be shown the same way (the
circuit of a one-degree-of-freedom linkage: :func:`spatialmech.analysis.traced_motion.traced_motion`).

The walk
--------
At a configuration ``x`` on the manifold, the tangent space is the null space of the
*nondimensional* closure Jacobian (rows: rotations in rad, translations divided by the
characteristic length ``L``; columns: joint rotations in rad, slides / ``L``, platform twist
``(w ; v / L)``).  One direction ``t0`` is chosen at the start, inside the part of the tangent
space that moves the platform (the largest platform motion for a one-parameter manifold, a
seeded random vector projected onto the platform-moving directions otherwise), in the sense of
a traced motion (the first actuator increasing, ...: docs/conventions.md), so that neither the
loop nor its first half depends on the basis or signs an SVD returns.  Along the walk the
direction is the projection of the previous one onto the current tangent space (so it never
flips), scaled so that its platform part ``(w ; v / L)`` has unit norm: the walk parameter
``s`` is therefore a pseudo arc length of the platform, nondimensional (rad, or length / L).

Frame ``i`` of ``n`` sits at ``s_i = amplitude * sin(2 pi i / n)``: from the start out to
``+amplitude``, back through the start to ``-amplitude`` and back.  Configurations are computed
once per distinct ``s`` by predictor (``x + ds t``) and Newton corrector
(:func:`~.backend.correct`), walking outwards from the start on each side, so the
loop closes exactly (frame ``i`` and frame ``n/2 - i`` are the same configuration).
"""

from __future__ import annotations

import numpy as np

from ..errors import ConvergenceError, InputError
from ..geometry.tolerances import current as current_tolerances
from ..geometry.validate import as_finite_array
from .closure import Configuration, active_mask, closure_scales
from .backend import closure_jacobian, correct, retract
from ..model.mechanism import Mechanism
from .tracking import conventional_sense, sense_order

__all__ = ["generic_configuration", "sample_motion", "tangent_space"]

#: Relative singular-value threshold for the rank of the nondimensional closure Jacobian
#: (the same as :func:`generic_configuration`).
RANK_RTOL = 1e-9
#: Largest predictor step (nondimensional platform motion) before a Newton correction.
MAX_STEP = 0.05
#: Smallest step tried after halving a step whose correction failed.
MIN_STEP = 1e-4


def tangent_space(mech: Mechanism, config: Configuration, *, active: np.ndarray | None = None):
    """Orthonormal basis of the tangent space of the closure manifold at ``config``.

    Returns ``N`` (k, n_active + 6): rows span the null space of the nondimensional closure
    Jacobian, in nondimensional coordinates (joint rotations in rad, slides / L, platform twist
    ``(w ; v / L)``, the last six columns).  Multiply by the column scaling of
    :func:`.backend.correct` to get SI steps.
    """
    if active is None:
        active = active_mask(mech)
    row, col = closure_scales(mech, active)
    A, _ = closure_jacobian(mech, config, active=active)
    As = row[:, None] * A * col[None, :]
    _, sv, vt = np.linalg.svd(As)
    r = int(np.sum(sv > RANK_RTOL * max(1.0, sv[0] if sv.size else 0.0)))
    return vt[r:]


def _initial_direction(N: np.ndarray, rng: np.random.Generator, order=()) -> np.ndarray:
    """A tangent direction (nondimensional) that moves the platform, platform part of norm 1,
    in the conventional sense (:func:`.tracking.conventional_sense` over ``order``).  It depends
    on the span of ``N`` only: ``Q`` below spans the same subspace for every orthonormal basis
    ``N``, and a seeded vector is projected onto it rather than combined with its columns."""
    Np = N[:, -6:]  # platform part of each null vector (k, 6)
    U, sv, _ = np.linalg.svd(Np, full_matrices=False)
    moving = int(np.sum(sv > 1e-8))
    if moving == 0:
        raise InputError(
            "mech: no motion of the closure manifold moves the platform (a structure, or only idle "
            "spins at this configuration); nothing to animate"
        )
    Q = N.T @ U[:, :moving]  # orthonormal columns: the platform-moving part of the tangent space
    t = Q[:, 0] if moving == 1 else Q @ (Q.T @ rng.standard_normal(N.shape[1]))
    t = t * conventional_sense(t, order)
    return t / np.linalg.norm(t[-6:])


def _walk(mech, start, t0, targets, active, col):
    """Configurations at the walk parameters ``targets`` (monotone away from 0), from ``start``."""
    out = []
    x, s, t = start, 0.0, t0
    for target in targets:
        while abs(target - s) > 1e-15:
            ds = float(np.clip(target - s, -MAX_STEP, MAX_STEP))
            while True:
                N = tangent_space(mech, x, active=active)
                tt = N.T @ (N @ t)  # keep the direction: project the previous one
                pn = float(np.linalg.norm(tt[-6:]))
                if pn < 1e-6:
                    raise ConvergenceError(
                        f"sample_motion: the walk direction stopped moving the platform at s = {s:.4g} "
                        "(a singularity); use a smaller amplitude"
                    )
                tt = tt / pn
                res = correct(mech, retract(mech, x, active, col * (ds * tt)), active=active)
                if res.converged:
                    break
                ds /= 2.0
                if abs(ds) < MIN_STEP:
                    raise ConvergenceError(
                        f"sample_motion: Newton correction did not converge at s = {s:.4g} "
                        f"(residual {res.residual:.2e}); use a smaller amplitude"
                    )
            x, s, t = res.config, s + ds, tt
        out.append(x)
    return out


def sample_motion(
    mech: Mechanism,
    *,
    n: int = 60,
    amplitude: float = 0.35,
    seed: int = 0,
    start: Configuration | None = None,
) -> list[Configuration]:
    """A closed demonstration loop of ``n`` configurations on the closure manifold.

    ``amplitude`` is the largest platform excursion along the walk, nondimensional: radians
    for rotations, lengths divided by :attr:`Mechanism.characteristic_length` for
    translations, measured as the pseudo arc length of the platform twist ``(w ; v / L)``
    (default 0.35, about 20 degrees of rotation).  ``seed`` picks the direction when the
    mechanism has several platform-moving freedoms.  ``start`` defaults to the reference
    configuration (every joint variable zero).  See the module docstring for the method; this
    is a demonstration motion for the viewer, not the continuation tracker.

    Raises ``ValueError`` for bad arguments or when nothing moves the platform, and
    ``RuntimeError`` when a Newton correction fails even after step halving (e.g. the loop
    would cross a singularity); it never returns a configuration that does not close.

    Example: ``sample_motion(catalog.build("bennett"), n=8)`` returns 8 configurations, the
    first the reference and ``configs[1] is configs[3]`` (the loop runs out and back).
    """
    if not isinstance(mech, Mechanism):
        raise InputError(f"mech: expected a Mechanism, got {type(mech).__name__}")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise InputError(f"n: expected an integer number of frames >= 2, got {n!r}")
    amplitude = float(amplitude)
    if not np.isfinite(amplitude) or amplitude <= 0:
        raise InputError(f"amplitude: expected a positive finite number, got {amplitude!r}")
    active = active_mask(mech)
    _, col = closure_scales(mech, active)
    if start is None:
        x0 = Configuration.reference(mech)
    elif not isinstance(start, Configuration):
        raise InputError(f"start: expected a Configuration, got {type(start).__name__}")
    else:
        x0 = Configuration(
            as_finite_array(start.q, "start.q", shape=(len(mech.freedom_refs),)),
            as_finite_array(start.D, "start.D", shape=(4, 4)),
        )
    res0 = correct(mech, x0, active=active)
    if not res0.converged:
        raise InputError(f"start: not on (or near) the closure manifold (residual {res0.residual:.2e})")
    x0 = res0.config
    t0 = _initial_direction(tangent_space(mech, x0, active=active), np.random.default_rng(seed),
                            sense_order(mech, active))

    s = amplitude * np.sin(2.0 * np.pi * np.arange(n) / n)
    s = np.where(np.abs(s) < 1e-12 * amplitude, 0.0, s)
    keys = np.round(s / amplitude, 12)
    pos = np.unique(keys[keys > 0])  # increasing
    neg = np.unique(keys[keys < 0])[::-1]  # decreasing
    at = {0.0: x0}
    at.update(zip(pos.tolist(), _walk(mech, x0, t0, amplitude * pos, active, col), strict=True))
    at.update(zip(neg.tolist(), _walk(mech, x0, t0, amplitude * neg, active, col), strict=True))
    return [at[float(k)] for k in keys]


def generic_configuration(
    mech: Mechanism,
    *,
    active: np.ndarray | None = None,
    seed: int = 0,
    step: float = 0.1,
    steps: int = 3,
    start: Configuration | None = None,
) -> Configuration:
    """A configuration on the closure manifold near ``start`` (default: the reference),
    reached by random steps along the manifold's tangent space, each corrected by Newton.

    Random directions avoid the special (often singular) symmetric reference poses of
    ready-made models.  ``step`` is nondimensional (radians, or lengths / L).  Raises
    ``RuntimeError`` if a correction does not converge.

    Each direction is a seeded standard-normal vector of the local coordinates projected onto
    the tangent space (``N^T N g``, the same for every orthonormal basis ``N``): the result
    depends on the model, ``start``, ``seed``, ``step`` and ``steps`` only, not on the basis or
    signs the SVD of the BLAS kernel in use returns (docs/conventions.md).
    """
    rng = np.random.default_rng(seed)
    if active is None:
        active = active_mask(mech)
    config = start if start is not None else Configuration.reference(mech)
    row, col = closure_scales(mech, active)
    for _ in range(steps):
        A, _ = closure_jacobian(mech, config, active=active)
        As = row[:, None] * A * col[None, :]
        _, sv, vt = np.linalg.svd(As)
        r = int(np.sum(sv > current_tolerances().rank * max(1.0, sv[0])))
        N = vt[r:]
        if N.shape[0] == 0:
            break
        g = rng.standard_normal(N.shape[1])
        t = N.T @ (N @ g)  # the projection onto the tangent space: independent of the basis
        t *= step / max(float(np.linalg.norm(t)), 1e-300)
        trial = retract(mech, config, active, col * t)
        res = correct(mech, trial, active=active)
        if not res.converged:
            raise ConvergenceError(
                f"generic configuration: Newton correction did not converge (residual {res.residual:.2e})"
            )
        config = res.config
    return config
