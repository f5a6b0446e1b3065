"""The public API: inverse dynamics (``sm.inverse_dynamics``) and statics along a motion
(``sm.statics_along``), with gravity on the links (docs/dynamics.md, docs/statics.md)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analysis import dynamics as dyn
from ..analysis.statics import JointReaction, joint_reactions
from ..analysis.statics import statics as _statics
from ..errors import InputError
from ..kinematics.closure import Configuration
from ..kinematics.position import platform_pose
from ..model.inertia import LinkInertia
from ..model.mechanism import Mechanism
from ..serialize import freedom_values_dict, pose_dict
from .threads import one_blas_thread
from .checks import (
    ModelLike,
    as_configuration,
    as_mechanism,
    as_positions,
    check_int,
    check_number,
    check_numbers,
)

__all__ = ["DynamicsResult", "StaticsPath", "inverse_dynamics", "masses_for", "statics_along"]

#: Standard gravity, m/s^2, along -z: the default of ``inverse_dynamics``.
STANDARD_GRAVITY = (0.0, 0.0, -9.81)


def _wrench_dict(w: np.ndarray) -> dict:
    return {"force_N": [float(v) + 0.0 for v in w[:3]], "moment_N_len": [float(v) + 0.0 for v in w[3:]]}


def _efforts_dict(mech: Mechanism, efforts: dict[str, float]) -> dict:
    return {"forces_N": {a: float(v) for a, v in efforts.items() if mech.freedom(a).freedom.kind == "P"},
            "torques_N_len": {a: float(v) for a, v in efforts.items() if mech.freedom(a).freedom.kind != "P"}}


def _reaction_dict(mech: Mechanism, r: JointReaction) -> dict:
    return {"limb": r.limb, "joint": r.joint, "point_len": [float(v) for v in r.point], **_wrench_dict(r.wrench),
            "moment_at_point_N_len": [float(v) + 0.0 for v in r.moment_at_point], "efforts": _efforts_dict(mech, r.efforts)}


def masses_for(mech: Mechanism, density: float | None) -> tuple[dict[str, LinkInertia], dict[str, str]]:
    """The links' mass properties and their source (``file``, ``density``, ``none``) for the
    verbs with gravity; an ``InputError`` when no link has a mass."""
    if density is not None:
        density = check_number(density, "density", positive=True)
    inertias, source = dyn.mass_properties(mech, density)
    if not any(li.mass_kg > 0 for li in inertias.values()):
        raise InputError(f"density: {mech.name} has no masses; give density= (kg/m^3, links as solid cylinders) or "
                         "masses in the model file")
    return inertias, source


def _masses_json(inertias: dict[str, LinkInertia], source: dict[str, str]) -> list[dict]:
    return [{"link": n, "source": source[n], "mass_kg": float(li.mass_kg), "com_len": [float(v) for v in li.com_m],
             "inertia_kg_len2": [[float(v) for v in row] for row in li.inertia_kg_m2]} for n, li in inertias.items()]


@dataclass(frozen=True, eq=False)
class DynamicsResult:
    """Inverse dynamics along a trajectory (:func:`inverse_dynamics`).  Efforts in N (prismatic
    actuators) and N m (revolute ones); ``efforts[i, j]``: sample ``i``, actuator ``j``."""

    mechanism: Mechanism
    actuators: tuple[str, ...]
    times: np.ndarray  # (n,) s
    values: np.ndarray  # (n, n_a) physical actuator values (m or rad)
    rates: np.ndarray  # (n, n_a) m/s or rad/s
    accelerations: np.ndarray  # (n, n_a)
    efforts: np.ndarray  # (n, n_a)
    samples: tuple[dyn.InverseDynamics, ...]
    reactions: tuple[tuple[JointReaction, ...], ...]  # per sample (empty where not computed)
    gravity: np.ndarray
    wrench: np.ndarray
    masses: dict[str, LinkInertia]
    mass_source: dict[str, str]
    notes: tuple[str, ...] = ()

    @property
    def by_actuator(self) -> dict[str, np.ndarray]:
        """Each actuator's effort along the trajectory."""
        return {a: self.efforts[:, j].copy() for j, a in enumerate(self.actuators)}

    @property
    def max_residual(self) -> float:
        """The largest relative residual of the virtual-power balance over the samples."""
        return max(s.residual for s in self.samples)

    def to_dict(self) -> dict:
        """JSON (``spatialmech dynamics --json``): per sample the time, the actuators' values,
        rates and accelerations (degrees for revolute ones), the efforts (``forces_N``,
        ``torques_N_len``), the joint reactions and the platform pose."""
        mech = self.mechanism
        samples = []
        for i, s in enumerate(self.samples):
            P = platform_pose(mech, s.state.config)
            by = dict(zip(self.actuators, self.efforts[i], strict=True))
            vals = freedom_values_dict(mech, dict(zip(self.actuators, self.values[i], strict=True)), "actuators")
            rates = freedom_values_dict(mech, dict(zip(self.actuators, self.rates[i], strict=True)), "rates")
            accs = freedom_values_dict(mech, dict(zip(self.actuators, self.accelerations[i], strict=True)), "accelerations")
            samples.append({"t_s": float(self.times[i]), "pose": pose_dict(P.R, P.p), **vals,
                            "rates_deg_per_s": rates["rates_deg"], "rates_len_per_s": rates["rates_len"],
                            "accelerations_deg_per_s2": accs["accelerations_deg"],
                            "accelerations_len_per_s2": accs["accelerations_len"],
                            **_efforts_dict(mech, by), "residual": float(s.residual),
                            "reactions": [_reaction_dict(mech, r) for r in self.reactions[i]]})
        return {"result": "dynamics", "actuators": list(self.actuators),
                "gravity_len_per_s2": [float(v) for v in self.gravity], "wrench": _wrench_dict(self.wrench),
                "masses": _masses_json(self.masses, self.mass_source),
                "idle_motions": int(self.samples[0].idle) if self.samples else 0,
                "max_residual": float(self.max_residual), "samples": samples, "notes": list(self.notes)}


def _trajectory(mech: Mechanism, start: Configuration, to, duration, samples, values, rates, accelerations, times):
    """Times, actuator values, rates and accelerations of the samples (see :func:`inverse_dynamics`)."""
    n_a = len(mech.actuators)
    a0 = dyn.actuator_values(mech, start)
    if to is not None:
        if values is not None or rates is not None or accelerations is not None:
            raise InputError("to/values: give a target (to=) or the samples (values=, rates=, accelerations=), not both")
        target = check_numbers(to, "to", shape=(n_a,))
        duration = check_number(duration, "duration", positive=True)
        samples = check_int(samples, "samples", minimum=2)
        return dyn.quintic(a0, target, duration, samples)
    if values is None:  # one sample at the start
        r = np.zeros(n_a) if rates is None else check_numbers(rates, "rates", shape=(n_a,))
        acc = np.zeros(n_a) if accelerations is None else check_numbers(accelerations, "accelerations", shape=(n_a,))
        return np.zeros(1), a0[None, :], r[None, :], acc[None, :]
    V = check_numbers(values, "values")
    if V.ndim != 2 or V.shape[1] != n_a:
        raise InputError(f"values: expected one row of {n_a} actuator values per sample, got shape {V.shape}")
    n = V.shape[0]
    R = np.zeros_like(V) if rates is None else check_numbers(rates, "rates", shape=(n, n_a))
    A = np.zeros_like(V) if accelerations is None else check_numbers(accelerations, "accelerations", shape=(n, n_a))
    T = np.arange(n, dtype=float) if times is None else check_numbers(times, "times", shape=(n,))
    return T, V, R, A


@one_blas_thread
def inverse_dynamics(model: ModelLike, pose=None, *, to=None, duration: float = 1.0, samples: int = 11, values=None,
                     rates=None, accelerations=None, times=None, config: Configuration | None = None,
                     gravity=STANDARD_GRAVITY, wrench=None, density: float | None = None,
                     degrees: bool = False) -> DynamicsResult:
    """Inverse dynamics of a closed chain along a trajectory: every actuator's force or torque
    and every joint's reaction, from Newton-Euler per link and the principle of virtual power
    (docs/dynamics.md).

    Parameters
    ----------
    model : Mechanism, str or path
        A mechanism, a ready-made model name or a TOML file (in metres).
    pose : Pose, tuple or int, optional
        Where the trajectory starts (default the reference configuration).
    to : sequence of floats, optional
        Target actuator values (m, rad): a rest-to-rest quintic law from the start's values in
        ``duration`` seconds, ``samples`` samples.
    duration : float
        Seconds (with ``to``).
    samples : int
        Number of samples, both ends included (with ``to``).
    values, rates, accelerations : array (n, n_a), optional
        Instead of ``to``: the actuators' values, rates and accelerations at each sample (rates
        and accelerations default to zero: statics with gravity at each sample); with
        ``values`` omitted too, one sample at the start with these rates and accelerations.
    times : array (n,), optional
        The samples' times with ``values`` (default 0, 1, 2 ...).
    config : Configuration, optional
        The start as a configuration instead of a pose.
    gravity : sequence of 3 floats
        m/s^2 (default ``(0, 0, -9.81)``).
    wrench : sequence of 6 floats, optional
        An external wrench ``(f ; m about the origin)`` on the output link, N and N m.
    density : float, optional
        kg/m^3 for the links without ``masses`` in the file (solid cylinders along the links);
        default the file's ``density_kg_m3``.
    degrees : bool
        Read a pose tuple's Euler angles in degrees.

    Returns
    -------
    DynamicsResult
        ``efforts`` (samples x actuators), ``by_actuator``, the joint ``reactions`` per sample,
        the ``masses`` used and their ``mass_source`` (``file``, ``density`` or ``none``).

    Raises
    ------
    InputError
        No masses; a model not in metres; a trajectory of the wrong shape; a sample at a
        singularity.
    ConvergenceError
        The forward position does not follow the actuators along the trajectory.

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.inverse_dynamics("delta-ruu", to=[0.2, 0.1, 0.0], duration=0.5, samples=5, density=2700)
    >>> r.efforts.shape, r.max_residual < 1e-10
    ((5, 3), True)
    """
    mech = as_mechanism(model)
    g = check_numbers(gravity, "gravity", shape=(3,))
    F = np.zeros(6) if wrench is None else check_numbers(wrench, "wrench", shape=(6,))
    inertias, source = masses_for(mech, density)
    start, _ = as_configuration(mech, pose, config, degrees)
    T, V, R, A = _trajectory(mech, start, to, duration, samples, values, rates, accelerations, times)
    configs = dyn.follow_actuators(mech, start, V)
    out, reactions = [], []
    for i, (c, r, a, t) in enumerate(zip(configs, R, A, T, strict=True)):
        try:
            st = dyn.state_from_actuators(mech, c, r, a, t=float(t))
        except InputError as e:
            raise InputError(f"sample {i} (t = {t:g} s): {str(e).split(': ', 1)[-1]}") from None
        res = dyn.inverse_dynamics(mech, st, inertias, g, F)
        out.append(res)
        reactions.append(joint_reactions(mech, c, res.limb_wrenches, res.by_actuator, dyn.distal_wrenches(mech, res)))
    notes = []
    if out and out[0].idle:
        notes.append(f"{out[0].idle} idle motion(s) (e.g. an SPS leg's spin): their accelerations follow from the "
                     "dynamics, their rates are the minimum-norm ones")
    massless = sorted(n for n, s in source.items() if s == "none")
    if massless:
        notes.append(f"massless links: {', '.join(massless)}")
    E = np.array([s.efforts for s in out])
    return DynamicsResult(mech, out[0].actuators, T, V, R, A, E, tuple(out), tuple(reactions), g, F, inertias, source,
                          tuple(notes))


@dataclass(frozen=True, eq=False)
class StaticsPath:
    """Statics at every sample of a motion (:func:`statics_along`)."""

    mechanism: Mechanism
    actuators: tuple[str, ...]
    values: np.ndarray  # (n, n_a) actuator values of the samples
    efforts: np.ndarray  # (n, n_a)
    balanced: np.ndarray  # (n,) bool
    singular: np.ndarray  # (n,) bool
    configs: tuple[Configuration, ...]
    wrench: np.ndarray
    gravity: np.ndarray | None
    masses: dict[str, LinkInertia]
    mass_source: dict[str, str]

    def to_dict(self) -> dict:
        mech = self.mechanism
        samples = []
        for i, c in enumerate(self.configs):
            P = platform_pose(mech, c)
            samples.append({"pose": pose_dict(P.R, P.p),
                            **freedom_values_dict(mech, dict(zip(self.actuators, self.values[i], strict=True)), "actuators"),
                            **_efforts_dict(mech, dict(zip(self.actuators, self.efforts[i], strict=True))),
                            "balanced": bool(self.balanced[i]), "singular": bool(self.singular[i])})
        return {"gravity_len_per_s2": None if self.gravity is None else [float(v) for v in self.gravity],
                "masses": _masses_json(self.masses, self.mass_source), "samples": samples}


@one_blas_thread
def statics_along(model: ModelLike, pose=None, *, to=None, samples: int = 11, values=None, poses=None,
                  config: Configuration | None = None, wrench=None, gravity=None, density: float | None = None,
                  degrees: bool = False) -> StaticsPath:
    """Statics at every sample of a motion: the actuator efforts that hold the mechanism against
    an external ``wrench`` on its output link and (with ``gravity``) the links' weights.

    Parameters
    ----------
    model : Mechanism, str or path
        A mechanism, a ready-made model name or a TOML file.
    pose : Pose, tuple or int, optional
        Where the motion starts (default the reference configuration).
    to : sequence of floats, optional
        Target actuator values: ``samples`` samples on the straight line of actuator values from
        the start's to these.
    samples : int
        Number of samples with ``to`` (both ends included).
    values : array (n, n_a), optional
        Instead of ``to``: the actuator values of each sample.
    poses : sequence of Pose, or a TOML file of ``[[positions]]``, optional
        Instead of ``to`` and ``values``: the output link's poses, each fitted onto the closure
        (inverse position), in order.
    config : Configuration, optional
        The start as a configuration.
    wrench : sequence of 6 floats, optional
        ``(f ; m about the origin)`` on the output link, N and N times the length unit.
    gravity : sequence of 3 floats, optional
        m/s^2; the links need masses (``density`` or the file's).
    density : float, optional
        kg/m^3 for the links without masses in the file.
    degrees : bool
        Read a pose tuple's Euler angles in degrees.

    Returns
    -------
    StaticsPath
        ``efforts`` (samples x actuators) and per sample ``balanced`` and ``singular``.

    Raises
    ------
    InputError
        Not exactly one of ``to``, ``values``, ``poses``; gravity without masses; a pose with no
        closed configuration near it.
    ConvergenceError
        The forward position does not follow the actuators.

    Examples
    --------
    >>> import spatialmech as sm
    >>> p = sm.statics_along("three-rps", to=[0.36, 0.34, 0.35], samples=3, gravity=[0, 0, -9.81], density=2700)
    >>> p.efforts.shape, bool(p.balanced.all())
    ((3, 3), True)
    """
    mech = as_mechanism(model)
    F = np.zeros(6) if wrench is None else check_numbers(wrench, "wrench", shape=(6,))
    g = None if gravity is None else check_numbers(gravity, "gravity", shape=(3,))
    inertias, source = masses_for(mech, density) if g is not None else ({}, {})
    if sum(x is not None for x in (to, values, poses)) != 1:
        raise InputError("to/values/poses: give exactly one: target actuator values, actuator values per sample, or "
                         "poses")
    if poses is not None:
        given = as_positions(poses) or ()
        configs = [as_configuration(mech, P, None, degrees, pose_name=f"poses[{k}]")[0] for k, P in enumerate(given)]
        if not configs:
            raise InputError("poses: no pose given")
        return _statics_at(mech, configs, np.array([dyn.actuator_values(mech, c) for c in configs]), F, g, inertias,
                           source)
    start, _ = as_configuration(mech, pose, config, degrees)
    if to is not None:
        a0 = dyn.actuator_values(mech, start)
        n = check_int(samples, "samples", minimum=2)
        V = a0 + np.linspace(0.0, 1.0, n)[:, None] * (check_numbers(to, "to", shape=(len(a0),)) - a0)
    else:
        V = check_numbers(values, "values")
        if V.ndim != 2 or V.shape[1] != len(mech.actuators):
            raise InputError(f"values: expected rows of {len(mech.actuators)} actuator values, got shape {V.shape}")
    return _statics_at(mech, dyn.follow_actuators(mech, start, V), V, F, g, inertias, source)


def _statics_at(mech: Mechanism, configs, V: np.ndarray, F: np.ndarray, g, inertias, source) -> StaticsPath:
    rows = []
    for c in configs:
        loads = dyn.gravity_loads(mech, c, inertias, g) if g is not None else None
        rows.append(_statics(mech, c, F, None, loads))
    return StaticsPath(mech, rows[0].actuators, V, np.array([s.efforts for s in rows]),
                       np.array([s.balanced for s in rows]), np.array([s.singular for s in rows]), tuple(configs), F, g,
                       inertias, source)
