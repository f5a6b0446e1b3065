"""The studio's assembly modes and traced circuit: forward position at the current actuator
values through the one dispatcher, an explicit change of mode, and the whole circuit through the
current configuration of a one-degree-of-freedom linkage (a mixin of
:class:`~spatialmech.services.studio.session.Session`)."""

from __future__ import annotations

import numpy as np

from ...errors import InputError
from ...kinematics.closure import Configuration
from ...kinematics.dispatch import AssemblyMode, ForwardAnswer, forward_engine, solve_forward
from ...kinematics.forward import ForwardResult
from ...kinematics.position import configuration_at_pose, platform_pose
from ...model.mechanism import Mechanism
from ...serialize import pose_dict

__all__ = ["FK_ALL_SEEDS", "AssemblyModes"]

#: Default number of starts of fk_all where the multi-start search answers (interactive: the
#: ready-made models' modes are found with this many; the other engines take their own defaults).
FK_ALL_SEEDS = 40


class AssemblyModes:
    """``fk_all``, ``pick_mode`` and ``circuit`` of a studio session (needs the session's
    ``mech``, ``config``, ``history``, ``driven`` and the helpers named below)."""

    mech: Mechanism
    config: Configuration
    fk_modes: list[tuple[AssemblyMode, Configuration | None]]
    fk_branch: object
    _circuit: dict
    history: list[np.ndarray]
    driven: list[np.ndarray]

    def _platform_point(self, c: Configuration) -> np.ndarray:
        return c.D[:3, :3] @ self.mech.platform_point + c.D[:3, 3]

    def actuator_values(self, config: Configuration | None = None) -> np.ndarray:
        """The actuator values at ``config`` (the session's, which overrides this)."""
        raise NotImplementedError

    def circuit(self, frames: int = 240) -> dict:
        """The whole circuit through the current configuration of a one-degree-of-freedom model
        (the tracker, as ``view --motion trace``): the platform point along it and where DJ of
        the chosen driver vanishes (its branch points).  Cached per driver and branch start."""
        if len(self.mech.actuators) != 1:
            raise InputError(f"circuit: {self.mech.name} is driven by {len(self.mech.actuators)} actuators; the traced "
                             "circuit is drawn for one-degree-of-freedom linkages")
        from ...analysis.traced_motion import traced_motion

        key = (self.mech.actuators, id(self.fk_branch))
        if self._circuit.get("key") != key:
            configs, zeros = traced_motion(self.mech, frames=frames, start=self.config)
            pts = [self._platform_point(c) for c in configs]
            self._circuit = {"key": key, "circuit_len": [p.tolist() for p in pts],
                             "dj_zeros_len": [self._platform_point(z).tolist() for z in zeros]}
        return {k: v for k, v in self._circuit.items() if k != "key"}

    def fk_all(self, seeds: int | None = None) -> list[dict]:
        """Every assembly mode at the current actuator values, by the engine the one dispatcher
        picks (:func:`~spatialmech.kinematics.dispatch.solve_forward` with ``method="auto"``: the
        modes of ``sm.fk(..., all_solutions=True)`` and ``fk --all``); the mode nearest the
        current configuration first.  ``seeds``: the starts of a multi-start search (default: the
        engine's, :data:`FK_ALL_SEEDS` where the multi-start search answers); refused where
        homotopy continuation answers (it takes no starts)."""
        if seeds is not None and (isinstance(seeds, bool) or not isinstance(seeds, int) or not 1 <= seeds <= 2000):
            raise InputError(f"seeds: expected a whole number of starts from 1 to 2000, got {seeds!r}")
        if seeds is None and forward_engine(self.mech) == "multistart":
            seeds = FK_ALL_SEEDS
        ans = solve_forward(self.mech, self.actuator_values(), all_solutions=True, seeds=seeds)
        modes = list(zip(ans.modes, _mode_configurations(ans), strict=True))
        here = platform_pose(self.mech, self.config)
        L = self.mech.characteristic_length
        if modes:  # the current configuration's mode first, the others in the dispatcher's order
            near = min(range(len(modes)), key=lambda k: float(np.linalg.norm(modes[k][0].pose.p - here.p)) / L
                       + float(np.linalg.norm(modes[k][0].pose.R - here.R)))
            modes.insert(0, modes.pop(near))
        self.fk_modes = modes
        return [{"mode_number": k + 1, "kind": str(m.kind), "pose": pose_dict(m.pose.R, m.pose.p),
                 "sigma_min": float(m.sigma_min), "singular": bool(m.sigma_min < m.singular_below),
                 "within_limits": m.within_limits} for k, (m, _) in enumerate(modes)]

    def pick_mode(self, number) -> None:
        """Move to assembly mode ``number`` (from 1) of the last :meth:`fk_all` (an explicit
        branch change)."""
        if isinstance(number, bool) or not isinstance(number, int):
            raise InputError(f"mode_number: expected a whole number, got {number!r}")
        if not self.fk_modes:
            raise InputError("mode_number: run fk_all first (POST /api/fk_all)")
        if not 1 <= number <= len(self.fk_modes):
            raise InputError(f"mode_number: expected 1 to {len(self.fk_modes)}, got {number}")
        mode, config = self.fk_modes[number - 1]
        if config is None:  # an engine that gives the pose only (a closed form): the configuration at it
            fit = configuration_at_pose(self.mech, mode.pose, start=self.config)
            if not fit.converged:
                raise InputError(f"mode_number: no closed configuration at mode {number}'s pose "
                                 f"(residual {fit.ik_residual:.2e})")
            config = fit.config
        self.config = config
        self.fk_branch = object()
        self.history, self.driven = [self._platform_point(self.config)], [self.actuator_values()]


def _mode_configurations(ans: ForwardAnswer) -> list[Configuration | None]:
    """The configuration of every mode of ``ans`` where its engine gives one (the general
    engine's converged solutions, in the order of the modes), else ``None``."""
    if isinstance(ans.detail, ForwardResult):
        return [s.config for s in ans.detail.solutions if s.converged]
    return [None] * len(ans.modes)
