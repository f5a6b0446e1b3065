"""What kind of solution each forward-position root is (issue 27), whatever the engine.

Every forward solution carries three flags next to its conditioning:

- ``forward_singular``: the platform moves with the actuators locked: the conditioning of
  :func:`.forward.forward_conditioning` (``sigma_min`` below ``singular_below``).
- ``inverse_singular``: with the platform locked, an actuator can still move: its actuation
  wrench does not exist (:attr:`.jacobian.CompleteJacobian.inverse_singular`, the same test
  as ``spatialmech jacobian``: the actuated twist depends on the limb's other twists at the
  ``rank`` tolerance).  The actuators concerned are named.
- ``input_independent``: the solution persists for every actuator value (a branch of the
  closure on which the actuators move and the platform does not): the same platform pose still
  closes after random changes of every actuator value (:func:`input_independent`; sizes, count,
  seed and steps from :mod:`spatialmech.geometry.tolerances`, ``INPUT_PERTURBATION*``).  Such a
  solution lets every actuator move with the platform locked (it is inverse singular in every
  actuator), so the test runs only where every actuator's transmission index is below the
  forward-singular threshold (:func:`.assembly.singular_threshold`); it is no assembly mode of
  the requested actuator values.

Homotopy engines also say which end point a solution came from (``endpoint``: ``"real"``, or
``"singular"`` for a near-real singular end point polished by Newton; ``None`` when only the
multi-start search that the engine added found it); complex end points and those at infinity
are counted by the engine, never listed as solutions.  Homotopy in Study parameters also says
whether the solution is ``certified`` (a Krawczyk test in ball arithmetic proved a unique real
root of the exact system near it, distinct from the others: :mod:`.homotopy.certify`; ``None``
when not attempted).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.tolerances import (
    INPUT_PERTURBATION,
    INPUT_PERTURBATION_SEED,
    INPUT_PERTURBATION_STEPS,
    INPUT_PERTURBATIONS,
    current,
)
from ..model.mechanism import Mechanism, Pose
from .assembly import singular_threshold
from .backend import correct
from .closure import Configuration, active_mask
from .jacobian import complete_jacobian

__all__ = ["SolutionFlags", "actuator_targets", "configuration_at_pose", "input_independent", "solution_flags"]


@dataclass(frozen=True)
class SolutionFlags:
    """The kind of one forward solution (module docstring)."""

    forward_singular: bool
    inverse_singular: bool
    input_independent: bool
    inverse_singular_actuators: tuple[str, ...] = ()
    endpoint: str | None = None  # homotopy: the status of the end point it came from
    certified: bool | None = None  # homotopy: certified (homotopy/certify.py); None: not attempted

    def to_dict(self) -> dict:
        return {"forward_singular": bool(self.forward_singular), "inverse_singular": bool(self.inverse_singular),
                "inverse_singular_actuators": list(self.inverse_singular_actuators),
                "input_independent": bool(self.input_independent), "endpoint": self.endpoint,
                "certified": self.certified}

    def words(self) -> list[str]:
        """The flags that are set, in a few words each (the text of ``fk``)."""
        out = []
        if self.input_independent:
            out.append("INPUT-INDEPENDENT: this pose closes for every actuator value (the actuators move without "
                       "moving the platform); not an assembly mode of these values")
        if self.inverse_singular:
            out.append("INVERSE SINGULAR: with the platform locked, " + ", ".join(self.inverse_singular_actuators)
                       + " can still move")
        return out


def actuator_targets(mech: Mechanism, values) -> dict[int, float]:
    """The joint variables (``value - offset``) of the actuators, by freedom index (``values``
    in ``mech.actuators`` order, or a mapping by name), as forward position holds them."""
    from .forward import actuator_q

    return actuator_q(mech, values)


def input_independent(mech: Mechanism, config: Configuration, targets: dict[int, float]) -> bool:
    """Whether the platform pose of ``config`` still closes after every one of
    ``INPUT_PERTURBATIONS`` random changes of all the actuator values at once (random signs,
    sizes between half and one ``INPUT_PERTURBATION``, in rad or length / L; a seeded generator,
    so the answer is reproducible): the joints other than the actuators are solved by Newton from
    ``config`` with the platform held (at most ``INPUT_PERTURBATION_STEPS`` steps) and must close
    to the ``closure`` tolerance."""
    if not targets:
        return False
    rng = np.random.default_rng(INPUT_PERTURBATION_SEED)
    L = mech.characteristic_length
    refs = mech.freedom_refs
    idx = sorted(targets)
    scale = np.array([L if refs[i].freedom.kind == "P" else 1.0 for i in idx])
    mask = active_mask(mech)
    mask[idx] = False
    tol = current().closure
    for _ in range(INPUT_PERTURBATIONS):
        step = rng.choice([-1.0, 1.0], size=len(idx)) * rng.uniform(0.5, 1.0, size=len(idx)) * INPUT_PERTURBATION
        q = config.q.copy()
        q[idx] = [targets[i] for i in idx] + step * scale
        res = correct(mech, config.with_q(q), active=mask, fix_platform=True, tol=tol,
                      max_iter=INPUT_PERTURBATION_STEPS, method="joints")
        if not (res.converged and res.residual <= tol):
            return False
    return True


def solution_flags(mech: Mechanism, config: Configuration, targets: dict[int, float], *, forward_singular: bool,
                   endpoint: str | None = None, certified: bool | None = None) -> SolutionFlags:
    """The flags of the forward solution ``config`` (module docstring); ``forward_singular`` is
    the engine's conditioning verdict, ``targets`` the actuators' joint variables held."""
    J = complete_jacobian(mech, config)
    inv = tuple(J.inverse_singular)
    # a pose that holds for every actuator value lets each actuator move with the platform
    # locked: only where every actuator's transmission is (nearly) zero is the test run; below
    # the forward-singular threshold rather than the rank tolerance, for roots found to a few
    # digits only
    thr = singular_threshold()
    nearly = len(J.transmission) == len(targets) and all(t < thr for t in J.transmission)
    ii = nearly and input_independent(mech, config, targets)
    if ii and len(inv) < len(J.actuators):  # the perturbations moved every actuator: all of them are free
        inv = tuple(J.actuators)
    return SolutionFlags(bool(forward_singular), bool(inv), ii, inv, endpoint, certified)


def configuration_at_pose(mech: Mechanism, pose: Pose, targets: dict[int, float]) -> Configuration:
    """Every limb solved for the platform ``pose`` with the actuators held at ``targets`` (for a
    closed form, which gives the pose only)."""
    from .forward import limbs_at

    q0 = np.zeros(len(mech.freedom_refs))
    for i, v in targets.items():
        q0[i] = v
    return limbs_at(mech, pose.displacement(mech.platform_point), q0, targets, 0)
