"""Independent validation in MuJoCo: drive the exported model through a motion computed by
spatialmech and compare the simulated output-link pose with the library's forward position.

The mechanism is exported as MJCF (:mod:`spatialmech.exchange.mjcf`: a body tree, loop
closures as equality constraints, a position actuator per actuated freedom) and compiled by
MuJoCo; nothing of the library's kinematics is used on the simulator's side.  The library
computes a motion (:func:`library_motion`): configurations, each with its actuator values.  The
simulator starts in the library's first configuration (an assembly mode has to be chosen, as in
any simulator) and is then driven to each pose through the intermediate actuator values, by
one of two methods:

``project`` (default)
    the actuated joints are held at their targets and MuJoCo's own equality-constraint
    residuals and Jacobians (``efc_pos``, ``efc_J`` after ``mj_fwdPosition``) are driven to
    zero by Gauss-Newton steps in the free joints, integrated on MuJoCo's configuration space
    (``mj_integratePos``).  A purely kinematic check: it converges to round-off (measured:
    residuals about 1e-16 L, pose errors 1e-15 to 1e-13 L on the ready-made models) in a few
    iterations per pose.
``settle``
    quasi-static simulation: the position actuators' targets are set and ``mj_step`` runs (joint
    damping, critically damped servos, gravity and contacts off) until every joint velocity is
    below ``1e-10`` (rad/s, length / L per s) and the constraint residual below ``1e-10 L``.
    Measured on the 4-SPS/CU: pose errors about 2e-14 L after 9000-11000 steps per pose (MuJoCo's
    constraints are soft, so the residual decays with the constraint time constant).  Slower,
    and as tight as the velocity threshold allows.

At each pose the report states the position error (model length unit), the orientation error
(the angle of ``R_sim R_lib^T``), whether the simulator settled, and whether it switched branch:
its pose, one of its hinge or slide values, or the pose of an internal body (a hub link of a
link-and-joint graph, such as a Delta arm) is more than ``branch_tol`` (nondimensional: rad,
length / L) from the library's -- near a singularity, where a simulator driven by its
actuators may leave the library's assembly mode, as ADAMS would.

Mechanisms described as limbs and as link-and-joint graphs with internal loops (the Clavel
Delta, a spatial six-bar) are exported, driven and compared alike.

MuJoCo is imported here, lazily: a missing package is an :class:`~spatialmech.errors.InputError`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ConvergenceError, InputError, MissingExtraError
from ..geometry.rotations import rotation_angle, rotvec_matrix
from ..kinematics.closure import Configuration
from ..kinematics.position import configuration_at_pose, freedom_values, platform_pose
from ..kinematics.forward import forward_conditioning, forward_position
from ..model.mechanism import Mechanism, Pose
from ..serialize import freedom_values_dict, pose_dict

__all__ = [
    "BRANCH_TOL",
    "DEFAULT_TOL",
    "METHODS",
    "MOTIONS",
    "SETTLE_TIMESTEP",
    "LibraryPose",
    "MujocoSimulator",
    "PoseCheck",
    "ValidationResult",
    "library_motion",
    "validate",
]

#: Largest pose error at a settled pose, as a fraction of the characteristic length (and in rad).
DEFAULT_TOL = 1e-8
#: Nondimensional distance (pose: rad and length / L; hinge and slide values) beyond which the
#: simulator is said to have switched branch.
BRANCH_TOL = 1e-4
#: Ways of driving the simulator (module docstring).
METHODS = ("project", "settle")
#: Library motions: a traced one-degree-of-freedom motion, a loop of the actuators, a path of
#: actuator values.
MOTIONS = ("trace", "loop", "actuators")

#: Time step of the ``settle`` method (s; the MJCF file says 0.002 s): with the implicitfast
#: integrator, joint damping and critically damped servos, a pose settles in 1500-2500 steps.
SETTLE_TIMESTEP = 0.01
#: Largest change of any actuator between two targets given to the simulator (rad, length / L).
_SIM_STEP = 0.01
#: Largest change of any actuator between two library forward-position solves (rad, length / L).
_LIB_STEP = 0.01


def _mujoco():
    try:
        import mujoco  # type: ignore[import-untyped]
    except ImportError:
        raise MissingExtraError("sim", "mujoco", "validation") from None
    return mujoco


# ================================================================== the library's motion
@dataclass(frozen=True, eq=False)
class LibraryPose:
    """A pose of the library's motion: its configuration, the actuator values (SI, in
    ``mech.actuators`` order) and the actuator values to pass through on the way from the
    previous pose (``via``, each an array like ``actuators``)."""

    label: str
    config: Configuration
    actuators: np.ndarray
    via: tuple[np.ndarray, ...] = ()


def _actuator_indices(mech: Mechanism) -> list[int]:
    return [mech.freedom_refs.index(mech.freedom(a)) for a in mech.actuators]


def _actuator_values(mech: Mechanism, config: Configuration) -> np.ndarray:
    return freedom_values(mech, config.q)[_actuator_indices(mech)]


def _scales(mech: Mechanism) -> np.ndarray:
    """Per actuator, the unit of a nondimensional step: 1 rad, or the characteristic length."""
    L = mech.characteristic_length
    return np.array([L if mech.freedom(a).freedom.kind == "P" else 1.0 for a in mech.actuators])


def _follow(mech: Mechanism, config: Configuration, a_to: np.ndarray, *, what: str) -> list[Configuration]:
    """Forward position by continuation from ``config`` to actuator values ``a_to``: steps of at
    most ``_LIB_STEP`` (halved where Newton fails), each from the previous solution.  Returns
    the configurations of every step (the last one at ``a_to``).  Raises
    :class:`~spatialmech.errors.ConvergenceError` where it cannot follow (a singularity)."""
    from ..kinematics.assembly import singular_threshold

    scale = _scales(mech)
    a_from = _actuator_values(mech, config)
    n = max(1, math.ceil(float(np.max(np.abs(a_to - a_from) / scale)) / _LIB_STEP))
    out: list[Configuration] = []
    cur, t, dt = config, 0.0, 1.0 / n
    thr = singular_threshold()
    while t < 1.0 - 1e-15:
        t1 = min(1.0, t + dt)
        res = forward_position(mech, a_from + t1 * (a_to - a_from), start=cur)
        s = res.solutions[0]
        if not s.converged:
            if dt < 1e-4 / n:
                raise ConvergenceError(f"{what}: the library's forward position does not follow the actuators beyond "
                                       f"{t:.4f} of the way (a singularity or the edge of the workspace)")
            dt /= 2
            continue
        cond = s.conditioning if s.conditioning is not None else forward_conditioning(mech, s.config)
        if cond.sigma_min < thr:
            raise ConvergenceError(f"{what}: the motion reaches a singular configuration (sigma_min below {thr:g}); "
                                   "choose another start or a smaller amplitude")
        cur, t = s.config, t1
        out.append(cur)
    return out


def _platform_points(mech: Mechanism, configs) -> tuple[np.ndarray, np.ndarray]:
    """Platform positions (n, 3) and orientations (n, 3, 3) of configurations."""
    D = np.array([c.D for c in configs])
    return D[:, :3, :3] @ mech.platform_point + D[:, :3, 3], D[:, :3, :3]


def _pose_distance(mech: Mechanism, configs, P: Pose) -> np.ndarray:
    """Nondimensional distance (position / L + angle in rad) of each configuration's platform
    pose from ``P``."""
    p, R = _platform_points(mech, configs)
    c = (np.einsum("nij,ij->n", R, P.R) - 1.0) / 2.0
    return np.linalg.norm(p - P.p, axis=1) / mech.characteristic_length + np.arccos(np.clip(c, -1.0, 1.0))


class _Passing:
    """A ``stop(x, s)`` for the tracker: stop once the platform has passed one of the ``targets``
    (its distance had a minimum below ``near`` and has grown again); ``passed`` says which."""

    def __init__(self, mech: Mechanism, targets: dict[int, Pose], near: float = 0.2):
        self.mech, self.targets, self.near = mech, targets, near
        self.best = dict.fromkeys(targets, np.inf)
        self.passed: int | None = None

    def __call__(self, x, s) -> bool:
        for n, P in self.targets.items():
            d = float(_pose_distance(self.mech, [x], P)[0])
            if d < self.best[n]:
                self.best[n] = d
            elif self.best[n] < self.near and d > self.best[n] + 0.05:
                self.passed = n
                return True
        return False


def _trace_poses(mech: Mechanism, start: Configuration, frames: int, to_position: int | None,
                 arc: float) -> list[LibraryPose]:
    from ..kinematics.tracking import trace_motion

    acts = list(mech.actuators)
    if len(acts) != 1:
        raise InputError(f"motion: 'trace' follows a one-degree-of-freedom motion driven by one actuator; {mech.name} "
                         f"has {len(acts)} actuators ({', '.join(acts) or 'none'}): use the 'loop' motion or an "
                         "actuator path")
    end_label = "end"
    named: dict[int, str] = {}  # trace index -> task position label
    if to_position is None:
        tr = trace_motion(mech, start, increasing=acts[0], max_arc=arc)
        if not tr.ok:
            raise ConvergenceError(f"motion: the tracker stopped ({tr.message}); trace a shorter arc")
        pts = list(tr.points)
    else:
        if not mech.positions:
            raise InputError(f"to_position: {mech.name} has no task positions")
        if not 1 <= to_position <= len(mech.positions):
            raise InputError(f"to_position: expected a task position 1..{len(mech.positions)}, got {to_position}")
        goal = mech.positions[to_position - 1]
        at = {n for n, P in enumerate(mech.positions, start=1) if _pose_distance(mech, [start], P)[0] < 0.2}
        others = {n: P for n, P in enumerate(mech.positions, start=1) if n not in at and n != to_position}
        sense = 1
        if others:  # probe both senses: go the way on which the first task position met lies before the goal
            first = (min(at) if at else 0)
            toward = {n for n in others if (first < n < to_position) or (to_position < n < first)}
            for sense in (1, -1):
                probe = _Passing(mech, {**others, to_position: goal})
                trace_motion(mech, start, increasing=acts[0], sense=sense, max_arc=10.0, stop=probe)
                if probe.passed in toward or (probe.passed is not None and not toward and probe.passed != to_position):
                    break
            else:
                sense = 1
        tr = trace_motion(mech, start, increasing=acts[0], sense=sense, max_arc=400, stop=_Passing(mech, {0: goal}))
        if not tr.ok:
            raise ConvergenceError(f"motion: the tracker stopped before task position {to_position} ({tr.message})")
        pts = list(tr.points)
        dist = _pose_distance(mech, pts, goal)
        k_end = int(np.argmin(dist))
        if dist[k_end] > 0.2:
            raise InputError(f"to_position: task position {to_position} is not on the circuit traced from the start "
                             f"(nearest point {dist[k_end]:.3g} away, nondimensional)")
        pts = pts[: k_end + 1]
        fit = configuration_at_pose(mech, goal, start=pts[-1])
        if fit.converged:
            pts[-1] = fit.config
        end_label = f"P{to_position}"
        for n, P in others.items():  # the task positions met on the way are poses too, fitted onto the closure
            d = _pose_distance(mech, pts, P)
            k = int(np.argmin(d))
            if d[k] < 0.2 and 0 < k < len(pts) - 1:
                fit = configuration_at_pose(mech, P, start=pts[k])
                if fit.converged:
                    pts[k] = fit.config
                    named[k] = f"P{n}"
    even = np.linspace(0, len(pts) - 1, max(2, min(frames, len(pts)))).round().astype(int)
    idx = np.unique(np.r_[even, list(named)]).astype(int)
    here = [n for n, P in enumerate(mech.positions, start=1) if _pose_distance(mech, [start], P)[0] < 1e-6]
    start_label = f"P{here[0]}" if here else "start"
    out: list[LibraryPose] = []
    prev = 0
    for n, k in enumerate(idx):
        via = tuple(_actuator_values(mech, pts[j]) for j in range(prev + 1, k))
        label = start_label if k == 0 else end_label if k == len(pts) - 1 else named.get(int(k), f"trace {n}")
        out.append(LibraryPose(label, pts[k], _actuator_values(mech, pts[k]), via))
        prev = k
    return out


def _path_poses(mech: Mechanism, start: Configuration, targets: list[np.ndarray], labels: list[str],
                what: str) -> list[LibraryPose]:
    out: list[LibraryPose] = []
    cur = start
    for a, label in zip(targets, labels, strict=True):
        steps = _follow(mech, cur, np.asarray(a, dtype=float), what=f"{what} ({label})")
        cur = steps[-1]
        out.append(LibraryPose(label, cur, _actuator_values(mech, cur), tuple(_actuator_values(mech, c)
                                                                               for c in steps[:-1])))
    return out


def _loop_directions(mech: Mechanism, config: Configuration) -> tuple[np.ndarray, np.ndarray]:
    """Two unit directions in nondimensional actuator space for the ``loop`` motion: the ones
    that move the output link least (the right singular vectors of the smallest singular values
    of the map from actuator rates to the nondimensional output twist), which keeps the loop
    away from singularities; one actuator: a stroke back and forth."""
    from ..kinematics.velocity import forward_velocity

    n = len(mech.actuators)
    if n == 1:
        return np.ones(1), np.zeros(1)
    scale = _scales(mech)
    L = mech.characteristic_length
    cols = []
    for k in range(n):
        rate = np.zeros(n)
        rate[k] = scale[k]
        try:
            V, _ = forward_velocity(mech, config, rate)
        except InputError as e:
            raise InputError(f"start: the actuators do not determine the output link here ({e}); start the loop at "
                             "a non-singular configuration") from None
        cols.append(np.r_[V[:3], V[3:] / L])
    _, _, wt = np.linalg.svd(np.array(cols).T)
    from ..kinematics.tracking import conventional_sense

    # signs by the documented convention (first non-negligible component positive), not the SVD's
    return wt[-1] * conventional_sense(wt[-1]), wt[-2] * conventional_sense(wt[-2])


def library_motion(mech: Mechanism, motion: str = "trace", *, start: Configuration | None = None, frames: int = 12,
                   to_position: int | None = None, amplitude: float = 0.02, arc: float = 2.0,
                   actuator_path: np.ndarray | None = None) -> list[LibraryPose]:
    """The library's motion to validate, as poses (configurations and actuator values):

    - ``"trace"``: the one-degree-of-freedom motion traced by continuation from ``start``
      (default: the reference) over an arc length ``arc`` (nondimensional: joint rotations in
      rad, slides and platform translation / L), ``frames`` poses evenly spread along it; or up
      to task position ``to_position``, in the sense in which the other task positions come
      first (the last pose is that position fitted onto the closure);
    - ``"loop"``: the actuators round a closed loop ``a(t) = a0 + A (sin(2 pi t) u + (1 - cos(2 pi
      t)) v)``, ``u`` and ``v`` the two actuator directions that move the output link least
      (:func:`_loop_directions`), ``A = amplitude`` (rad, or times the characteristic length for
      slides), ``frames`` poses, each solved by forward-position continuation from the previous one;
    - ``"actuators"``: the rows of ``actuator_path`` (SI values in ``mech.actuators`` order), by
      continuation from ``start``.
    """
    if motion not in MOTIONS:
        raise InputError(f"motion: expected one of {', '.join(MOTIONS)}, got {motion!r}")
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 2:
        raise InputError(f"frames: expected an integer >= 2, got {frames!r}")
    if not mech.actuators:
        raise InputError(f"model: {mech.name} has no actuators to drive")
    cfg = start if start is not None else Configuration.reference(mech)
    if motion == "trace":
        if isinstance(arc, bool) or not (isinstance(arc, (int, float)) and math.isfinite(arc) and arc > 0):
            raise InputError(f"arc: expected a positive number, got {arc!r}")
        return _trace_poses(mech, cfg, int(frames), to_position, float(arc))
    first = LibraryPose("start", cfg, _actuator_values(mech, cfg))
    if motion == "loop":
        if isinstance(amplitude, bool) or not (isinstance(amplitude, (int, float)) and math.isfinite(amplitude)
                                               and amplitude > 0):
            raise InputError(f"amplitude: expected a positive number, got {amplitude!r}")
        u, v = _loop_directions(mech, cfg)
        a0 = first.actuators
        amp = amplitude * _scales(mech)
        ts = np.arange(1, int(frames)) / (int(frames) - 1)
        targets = [a0 + amp * (np.sin(2 * np.pi * t) * u + (1.0 - np.cos(2 * np.pi * t)) * v) for t in ts]
        return [first, *_path_poses(mech, cfg, targets, [f"loop {k}" for k in range(1, len(ts) + 1)], "loop")]
    if actuator_path is None:
        raise InputError("actuator_path: required for the 'actuators' motion")
    path = np.asarray(actuator_path, dtype=float)
    if path.ndim != 2 or path.shape[1] != len(mech.actuators) or path.shape[0] < 1:
        raise InputError(f"actuator_path: expected rows of {len(mech.actuators)} values ({', '.join(mech.actuators)}), "
                         f"got shape {path.shape}")
    if not np.all(np.isfinite(path)):
        raise InputError("actuator_path: contains NaN or infinity")
    return _path_poses(mech, cfg, list(path), [f"row {k}" for k in range(1, len(path) + 1)], "actuator path")


# ================================================================== the simulator
class MujocoSimulator:
    """The exported MJCF of a mechanism compiled by MuJoCo, with the maps between the library's
    freedoms and MuJoCo's joints."""

    def __init__(self, mech: Mechanism):
        from ..exchange.bodies import body_tree
        from ..exchange.mjcf import to_mjcf

        mj = _mujoco()
        self.mj = mj
        self.mech = mech
        self.tree = body_tree(mech)
        self.xml = to_mjcf(self.tree)
        self.model = mj.MjModel.from_xml_string(self.xml)
        self.data = mj.MjData(self.model)
        self.model.opt.jacobian = mj.mjtJacobian.mjJAC_DENSE
        m = self.model
        self.L = mech.characteristic_length
        self.output = mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, self.tree.output)
        refs = mech.freedom_refs
        self._index = {r.id: k for k, r in enumerate(refs)}
        self._joints = []  # (axis, joint id, reversed)
        for b in self.tree.bodies:
            if b.joint is not None:
                for ax in b.joint.axes:
                    self._joints.append((ax, mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, ax.name), b.joint.reversed))
        self._coupled = {c.joint1: (c.joint2, c.polycoef[1]) for c in self.tree.couplings if c.joint2 is not None}
        jid = {ax.name: j for ax, j, _ in self._joints}
        self.act_qpos = np.array([m.jnt_qposadr[jid[a]] for a in mech.actuators], dtype=int)
        self.act_dof = np.array([m.jnt_dofadr[jid[a]] for a in mech.actuators], dtype=int)
        self.free_dof = np.array([i for i in range(m.nv) if i not in set(self.act_dof.tolist())], dtype=int)
        lin = np.zeros(m.nv)
        for _, j, _ in self._joints:
            if m.jnt_type[j] == mj.mjtJoint.mjJNT_SLIDE:
                lin[m.jnt_dofadr[j]] = 1.0
        self._dof_scale = np.where(lin > 0, 1.0 / self.L, 1.0)  # rad, length / L
        self._scalar = [(ax, j) for ax, j, _ in self._joints if ax.kind != "ball" and ax.freedoms]

    # ---------------------------------------------------------------- state
    def qpos_of(self, config: Configuration) -> np.ndarray:
        """MuJoCo's ``qpos`` of a library configuration (hinge and slide values are the freedoms'
        physical values; a ball's quaternion is the S joint's rotation, inverted when the tree
        runs against the limb: the tree joint against the joint's described direction, or the
        limb against it, but not both)."""
        mj, m = self.mj, self.model
        vals = freedom_values(self.mech, config.q)
        q = np.array(m.qpos0, dtype=float)
        by_name: dict[str, float] = {}
        for ax, j, rev in self._joints:
            adr = int(m.jnt_qposadr[j])
            if ax.kind == "ball":
                idx = [self._index[f] for f in ax.freedoms]
                refs = [self.mech.freedom_refs[i] for i in idx]
                A = np.array([r.freedom.direction for r in refs]).T
                R = rotvec_matrix(A @ config.q[idx])  # the motion in the limb's direction
                flipped = self.mech.limbs[refs[0].limb].joints[refs[0].joint].reversed
                quat = np.zeros(4)
                mj.mju_mat2Quat(quat, (R.T if rev != flipped else R).ravel())
                q[adr:adr + 4] = quat
            elif ax.freedoms:
                q[adr] = by_name[ax.name] = float(vals[self._index[ax.freedoms[0]]])
        for slide, (hinge, pitch) in self._coupled.items():  # helical joints' slides
            j = next(jj for ax, jj, _ in self._joints if ax.name == slide)
            jh = next(jj for ax, jj, _ in self._joints if ax.name == hinge)
            q[m.jnt_qposadr[j]] = m.qpos0[m.jnt_qposadr[j]] + pitch * (by_name[hinge] - m.qpos0[m.jnt_qposadr[jh]])
        return q

    def set_configuration(self, config: Configuration) -> None:
        self.data.qpos[:] = self.qpos_of(config)
        self.data.qvel[:] = 0.0
        self.data.ctrl[:] = _actuator_values(self.mech, config)
        self.mj.mj_forward(self.model, self.data)

    def output_pose(self) -> Pose:
        d = self.data
        return Pose(d.xmat[self.output].reshape(3, 3).copy(), d.xpos[self.output].copy(), "simulated")

    def equality_residual(self) -> tuple[np.ndarray, np.ndarray]:
        """MuJoCo's equality-constraint residuals and their Jacobian (rows) at the current qpos."""
        mj, m, d = self.mj, self.model, self.data
        mj.mj_fwdPosition(m, d)
        rows = np.asarray(d.efc_type) == mj.mjtConstraint.mjCNSTR_EQUALITY
        J = np.asarray(d.efc_J)[: d.nefc * m.nv].reshape(d.nefc, m.nv)
        return np.asarray(d.efc_pos)[rows].copy(), J[rows].copy()

    def joint_deviation(self, config: Configuration) -> float:
        """Largest difference (rad, length / L) between the simulator's hinge and slide values and
        the library's, angles compared modulo a turn."""
        want = self.qpos_of(config)
        worst = 0.0
        for ax, j in self._scalar:
            adr = int(self.model.jnt_qposadr[j])
            diff = float(self.data.qpos[adr] - want[adr])
            if ax.kind == "hinge":
                diff = (diff + np.pi) % (2 * np.pi) - np.pi
            else:
                diff /= self.L
            worst = max(worst, abs(diff))
        return worst

    def body_deviation(self, config: Configuration) -> float:
        """Largest distance (position / L + angle in rad) between the simulator's pose of an
        internal body of a link-and-joint graph (a Delta arm, the shared rocker of a six-bar)
        and the library's (``config.B``); 0 for a mechanism without internal bodies."""
        worst = 0.0
        for k, name in enumerate(self.mech.bodies):
            bid = self.mj.mj_name2id(self.model, self.mj.mjtObj.mjOBJ_BODY, name)
            B = np.asarray(config.B[k])
            p = B[:3, :3] @ self.tree.body(name).origin + B[:3, 3]
            R = self.data.xmat[bid].reshape(3, 3)
            worst = max(worst, float(np.linalg.norm(self.data.xpos[bid] - p)) / self.L
                        + float(rotation_angle(R @ B[:3, :3].T)))
        return worst

    # ---------------------------------------------------------------- driving
    def project(self, targets: np.ndarray, *, tol: float = 1e-14, max_iter: int = 40) -> tuple[bool, float, int]:
        """Hold the actuated joints at ``targets`` and solve MuJoCo's equality constraints for
        the other joints (Gauss-Newton, minimum-norm steps in nondimensional joint coordinates).
        Returns (converged, residual / L, iterations)."""
        mj, m, d = self.mj, self.model, self.data
        d.qpos[self.act_qpos] = targets
        d.ctrl[:] = targets
        rn = np.inf
        best = np.inf
        for it in range(max_iter + 1):
            r, J = self.equality_residual()
            rn = float(np.linalg.norm(r)) / self.L if r.size else 0.0
            if rn < tol:
                return True, rn, it
            if it > 5 and rn > 0.5 * best and rn < 1e-12:  # stagnating at round-off
                return True, rn, it
            best = min(best, rn)
            if it == max_iter or not np.isfinite(rn):
                break
            s = self._dof_scale[self.free_dof]
            x, *_ = np.linalg.lstsq(J[:, self.free_dof] / s[None, :], -r, rcond=None)
            step = np.zeros(m.nv)
            step[self.free_dof] = x / s
            mj.mj_integratePos(m, d.qpos, step, 1.0)
        return False, rn, max_iter

    def settle(self, targets: np.ndarray, *, vel_tol: float = 1e-10, res_tol: float = 1e-10, max_steps: int = 200_000,
               chunk: int = 100) -> tuple[bool, float, int]:
        """Set the position actuators' targets and step the dynamics until every joint velocity
        is below ``vel_tol`` (rad/s, length / L per s) and the constraint residual below
        ``res_tol`` L.  Returns (settled, residual / L, steps)."""
        mj, m, d = self.mj, self.model, self.data
        m.opt.timestep, m.opt.tolerance, m.opt.iterations = SETTLE_TIMESTEP, 1e-15, 200
        d.ctrl[:] = targets
        steps = 0
        rn = np.inf
        while steps < max_steps:
            mj.mj_step(m, d, nstep=chunk)
            steps += chunk
            v = float(np.max(np.abs(d.qvel * self._dof_scale))) if m.nv else 0.0
            if not np.isfinite(v):
                break
            if v < vel_tol:
                r, _ = self.equality_residual()
                rn = float(np.linalg.norm(r)) / self.L if r.size else 0.0
                if rn < res_tol:
                    return True, rn, steps
        r, _ = self.equality_residual()
        rn = float(np.linalg.norm(r)) / self.L if r.size else 0.0
        return False, rn, steps

    def ramp(self, targets: np.ndarray) -> None:
        """Move the position actuators' targets to ``targets`` and settle loosely (velocities
        below 1e-4, residual below 1e-6 L): the way through intermediate targets in ``settle``."""
        self.settle(targets, vel_tol=1e-4, res_tol=1e-6, max_steps=20_000, chunk=20)


# ================================================================== the check
@dataclass(frozen=True, eq=False)
class PoseCheck:
    """One pose of a validation: the library's pose and the simulator's, and how far apart."""

    label: str
    actuators: dict[str, float]  # SI
    library: Pose
    simulated: Pose
    position_error: float  # model length unit
    orientation_error: float  # rad
    settled: bool
    residual: float  # the simulator's constraint residual / L
    iterations: int  # Newton iterations (project) or time steps (settle)
    branch_switched: bool
    joint_deviation: float  # rad, length / L: hinge and slide values, and internal bodies' poses


@dataclass(frozen=True, eq=False)
class ValidationResult:
    """A validation run: every pose checked, the largest errors, and whether it passed (every
    pose settled on the library's branch, errors within ``tolerance`` L and ``tolerance`` rad)."""

    mechanism: Mechanism
    motion: str
    method: str
    simulator: str
    poses: tuple[PoseCheck, ...]
    tolerance: float
    elapsed: float  # s
    mode: str | None = None
    notes: tuple[str, ...] = field(default=())

    @property
    def max_position_error(self) -> float:
        return max((p.position_error for p in self.poses), default=0.0)

    @property
    def max_orientation_error(self) -> float:
        return max((p.orientation_error for p in self.poses), default=0.0)

    @property
    def branch_switches(self) -> tuple[str, ...]:
        return tuple(p.label for p in self.poses if p.branch_switched)

    @property
    def passed(self) -> bool:
        L = self.mechanism.characteristic_length
        return (bool(self.poses) and all(p.settled for p in self.poses) and not self.branch_switches
                and self.max_position_error <= self.tolerance * L and self.max_orientation_error <= self.tolerance)

    def to_dict(self) -> dict:
        """JSON (docs/json.md): lengths in the model's unit (``_len``), angles in degrees."""
        mech = self.mechanism
        return {
            "simulator": self.simulator,
            "mode": self.mode,
            "motion": self.motion,
            "method": self.method,
            "passed": self.passed,
            "tolerance": self.tolerance,
            "characteristic_length_len": mech.characteristic_length,
            "max_position_error_len": self.max_position_error,
            "max_orientation_error_deg": float(np.degrees(self.max_orientation_error)),
            "n_poses_checked": len(self.poses),
            "branch_switches": list(self.branch_switches),
            "time_s": self.elapsed,
            "notes": list(self.notes),
            "poses": [
                {
                    "label": p.label,
                    **freedom_values_dict(mech, p.actuators, "actuators"),
                    "pose": pose_dict(p.library.R, p.library.p),
                    "simulated_pose": pose_dict(p.simulated.R, p.simulated.p),
                    "position_error_len": p.position_error,
                    "orientation_error_deg": float(np.degrees(p.orientation_error)),
                    "settled": p.settled,
                    "residual": p.residual,
                    "iterations": p.iterations,
                    "branch_switched": p.branch_switched,
                }
                for p in self.poses
            ],
        }


def _through(a: np.ndarray, b: np.ndarray, scale: np.ndarray) -> list[np.ndarray]:
    """Targets from ``a`` (excluded) to ``b`` (included) in steps of at most ``_SIM_STEP``."""
    n = max(1, math.ceil(float(np.max(np.abs(b - a) / scale)) / _SIM_STEP))
    return [a + (b - a) * (k / n) for k in range(1, n + 1)]


def _turning_points(mech: Mechanism, poses: list[LibraryPose]) -> list[str]:
    """Notes on the actuators that turn back along the library's path (branch points of a
    driver, where it cannot drive the motion on: a simulator driven by it may leave the path)."""
    out = []
    for k, name in enumerate(mech.actuators):
        prev_label, prev_dir, last = poses[0].label, 0.0, float(poses[0].actuators[k])
        for lp in poses[1:]:
            for a in (*lp.via, lp.actuators):
                step = float(a[k]) - last
                last = float(a[k])
                if abs(step) < 1e-12:
                    continue
                if prev_dir and np.sign(step) != prev_dir:
                    out.append(f"{name} turns back between {prev_label} and {lp.label} (a branch point of this driver): "
                               "driven by it, a simulator may leave the library's path there")
                prev_dir = float(np.sign(step))
            prev_label = lp.label
    return out


def validate(mech: Mechanism, motion: str | None = None, *, method: str = "project",
             start: Configuration | Pose | None = None, frames: int = 12, to_position: int | None = None,
             amplitude: float = 0.02, arc: float = 2.0,
             actuator_path: np.ndarray | None = None, tol: float = DEFAULT_TOL, branch_tol: float = BRANCH_TOL,
             mode: str | None = None) -> ValidationResult:
    """Drive the exported MJCF of ``mech`` through a motion of the library and compare the
    output-link poses (module docstring).

    ``motion``: ``"trace"`` (default for one actuator), ``"loop"`` (default otherwise) or
    ``"actuators"`` (give ``actuator_path``); see :func:`library_motion`.  ``method``:
    ``"project"`` or ``"settle"``.  ``mode``: a motion mode of a metamorphic mechanism (its
    undriven lockable freedoms are locked).  ``tol``: the largest error that passes, a fraction
    of the characteristic length (and radians).
    """
    if not isinstance(mech, Mechanism):
        raise TypeError(f"mech: expected a Mechanism, got {type(mech).__name__}")
    if method not in METHODS:
        raise InputError(f"method: expected one of {', '.join(METHODS)}, got {method!r}")
    for name, v in (("tol", tol), ("branch_tol", branch_tol)):
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0):
            raise InputError(f"{name}: expected a positive number, got {v!r}")
    if mode is not None:
        mech = mech.in_mode(mode)
    if motion is None:
        motion = "actuators" if actuator_path is not None else ("trace" if len(mech.actuators) == 1 else "loop")
    t0 = time.perf_counter()
    sim = MujocoSimulator(mech)  # fails early when mujoco is missing
    if isinstance(start, Pose):
        fit = configuration_at_pose(mech, start)
        if not fit.converged or fit.error > 1e-5:
            raise InputError(f"start: the pose is not reached by {mech.name} (pose error {fit.error:.2e})")
        start = fit.config
    poses = library_motion(mech, motion, start=start, frames=frames, to_position=to_position, amplitude=amplitude,
                           arc=arc, actuator_path=actuator_path)
    L = mech.characteristic_length
    scale = _scales(mech)
    sim.set_configuration(poses[0].config)
    current = poses[0].actuators
    checks = []
    for lp in poses:
        for target in (*lp.via, lp.actuators):
            for a in _through(current, target, scale)[:-1] if target is lp.actuators else _through(current, target, scale):
                if method == "project":
                    sim.project(a)
                else:
                    sim.ramp(a)
            current = target
        settled, residual, iters = sim.project(lp.actuators) if method == "project" else sim.settle(lp.actuators)
        fk = forward_position(mech, lp.actuators, start=lp.config).solutions[0]  # the library's forward position
        config = fk.config if fk.converged else lp.config
        lib = platform_pose(mech, config)
        got = sim.output_pose()
        perr = float(np.linalg.norm(got.p - lib.p))
        oerr = float(rotation_angle(got.R @ lib.R.T))
        dev = max(sim.joint_deviation(config), sim.body_deviation(config))
        switched = max(perr / L, oerr) > branch_tol or dev > branch_tol
        acts = dict(zip(mech.actuators, (float(x) for x in lp.actuators), strict=True))
        checks.append(PoseCheck(lp.label, acts, lib, got, perr, oerr, settled, residual, iters, switched, dev))
    mj = _mujoco()
    notes = ["the simulator starts in the library's first configuration (its assembly mode)"]
    if motion == "trace":  # round a loop or along a path of their own the actuators turn back by design
        notes += _turning_points(mech, poses)
    return ValidationResult(mech, motion, method, f"MuJoCo {mj.__version__}", tuple(checks), float(tol),
                            time.perf_counter() - t0, mode, tuple(notes))
