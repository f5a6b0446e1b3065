"""Inverse dynamics of a closed chain recomputed by two independent engines on the same inertias,
for the cross-checks (tests/test_dynamics_mujoco.py, tests/test_dynamics_pinocchio.py).

Both engines get the mechanism as a tree (the MJCF export's spanning tree, :mod:`spatialmech.exchange.bodies`)
with the links' mass properties, and the state as the library computed it: ``qvel`` and ``qacc``
are the engine's own joint rates and accelerations that reproduce every body's twist and spatial
acceleration (least squares on the engine's body Jacobians and their time derivatives; the
residual is returned, it is round-off when the state is consistent).  Then, in each engine:

- the tree's inverse dynamics ``qfrc`` (gravity, Coriolis and inertia forces; MuJoCo ``mj_inverse``
  with the constraint solver disabled, joint damping and armature zeroed; Pinocchio ``rnea``);
- the loop closures' Jacobian ``Jc`` (MuJoCo: the ``efc_J`` rows of its ``connect`` / ``weld``
  equality constraints; Pinocchio: the difference of the two bodies' point velocity (``connect``)
  or twist (``weld``) from ``getJointJacobian``);
- the efforts from ``qfrc = B^T tau + Jc^T lambda`` (least squares; its relative residual is
  returned): the closed chain's inverse dynamics, with the constraint forces exact (MuJoCo's own
  forward dynamics would make them soft).
"""

from __future__ import annotations

import numpy as np

from spatialmech.analysis.dynamics import InverseDynamics, link_placements
from spatialmech.analysis.validation import MujocoSimulator
from spatialmech.exchange.bodies import body_tree
from spatialmech.exchange.mjcf import to_mjcf
from spatialmech.model.mechanism import Mechanism


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.linalg.norm(a - b) / max(float(np.linalg.norm(b)), 1e-300))


def _split_efforts(K: np.ndarray, qfrc: np.ndarray, n_act: int) -> tuple[np.ndarray, float]:
    z, *_ = np.linalg.lstsq(K, qfrc, rcond=None)
    return z[:n_act], _rel(K @ z, qfrc)


def mujoco_efforts(mech: Mechanism, inertias: dict, res: InverseDynamics, gravity, wrench=None
                   ) -> tuple[np.ndarray, dict]:
    """The actuator efforts MuJoCo gives at the library's state ``res.state`` (module docstring),
    and the residuals: ``qvel``, ``qacc`` (the body motions reproduced) and the split.  ``wrench``:
    ``(f ; m about the origin)`` on the output body, its generalized force ``J^T (m ; f)`` taken
    off the tree's."""
    import mujoco as mj

    tree = body_tree(mech)
    m = mj.MjModel.from_xml_string(to_mjcf(tree, inertias))
    m.opt.jacobian = mj.mjtJacobian.mjJAC_DENSE
    m.opt.gravity[:] = gravity
    m.dof_damping[:] = 0.0
    m.dof_armature[:] = 0.0
    d = mj.MjData(m)
    d.qpos[:] = MujocoSimulator(mech).qpos_of(res.state.config)
    mj.mj_forward(m, d)
    bodies = [(mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, b.name), b.link) for b in tree.bodies]
    rows, want = [], []
    for bid, link in bodies:
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mj.mj_jac(m, d, jp, jr, np.zeros(3), bid)  # the body point at the origin: the spatial twist
        rows += [jr, jp]
        want.append(res.link_twists[link])
    J, V = np.vstack(rows), np.concatenate(want)
    qvel, *_ = np.linalg.lstsq(J, V, rcond=None)
    resid = {"qvel": _rel(J @ qvel, V) if np.any(V) else 0.0}
    d.qvel[:] = qvel
    mj.mj_forward(m, d)
    rows, want = [], []
    for bid, link in bodies:
        jp, jr, jpd, jrd = (np.zeros((3, m.nv)) for _ in range(4))
        r = d.xpos[bid].copy()
        mj.mj_jac(m, d, jp, jr, r, bid)
        mj.mj_jacDot(m, d, jpd, jrd, r, bid)
        V, A = res.link_twists[link], res.link_accelerations[link]
        a_r = A[3:] + np.cross(A[:3], r) + np.cross(V[:3], V[3:] + np.cross(V[:3], r))  # the point's acceleration
        rows += [jr, jp]
        want += [A[:3] - jrd @ qvel, a_r - jpd @ qvel]
    J, Acc = np.vstack(rows), np.concatenate(want)
    qacc, *_ = np.linalg.lstsq(J, Acc, rcond=None)
    resid["qacc"] = _rel(J @ qacc, Acc)
    eq = np.asarray(d.efc_type) == mj.mjtConstraint.mjCNSTR_EQUALITY
    Jc = np.asarray(d.efc_J)[: d.nefc * m.nv].reshape(d.nefc, m.nv)[eq]
    m.opt.disableflags = int(m.opt.disableflags) | int(mj.mjtDisableBit.mjDSBL_CONSTRAINT)
    d.qacc[:] = qacc
    mj.mj_inverse(m, d)
    act = [int(m.jnt_dofadr[mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, a)]) for a in res.actuators]
    B = np.zeros((len(act), m.nv))
    B[np.arange(len(act)), act] = 1.0
    qfrc = d.qfrc_inverse.copy()
    if wrench is not None:
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mj.mj_jac(m, d, jp, jr, np.zeros(3), mj.mj_name2id(m, mj.mjtObj.mjOBJ_BODY, tree.output))
        qfrc -= jp.T @ np.asarray(wrench[:3]) + jr.T @ np.asarray(wrench[3:])
    tau, resid["split"] = _split_efforts(np.hstack([B.T, Jc.T]), qfrc, len(act))
    return tau, resid


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


class PinocchioTree:
    """The body tree as a Pinocchio model: one joint per simulator joint (``hinge``:
    ``JointModelRevoluteUnaligned``, ``slide``: ``JointModelPrismaticUnaligned``, ``ball``:
    ``JointModelSpherical``), placed at its anchor with world-aligned axes (the reference
    configuration is Pinocchio's neutral one), the link's inertia on the last joint of its body
    (shared by a link's ghost copies)."""

    def __init__(self, mech: Mechanism, inertias: dict, gravity):
        import pinocchio as pin

        self.pin, self.mech = pin, mech
        self.tree = tree = body_tree(mech)
        self.sim = MujocoSimulator(mech)
        model = pin.Model()
        model.gravity = pin.Motion(np.asarray(gravity, float), np.zeros(3))
        last: dict[str | None, tuple[int, np.ndarray]] = {None: (0, np.zeros(3))}
        copies: dict[str, int] = {}
        for b in tree.bodies:
            copies[b.link] = copies.get(b.link, 0) + 1
        self.axes = []  # (pin joint id, axis)
        for b in tree.bodies:
            jid, at = last[b.parent]
            if b.joint is None:
                raise ValueError(f"body {b.name}: rigidly attached bodies are not built here")
            for ax in b.joint.axes:
                place = pin.SE3(np.eye(3), ax.anchor - at)
                if ax.kind == "hinge":
                    jm = pin.JointModelRevoluteUnaligned(*ax.axis)
                elif ax.kind == "slide":
                    jm = pin.JointModelPrismaticUnaligned(*ax.axis)
                else:
                    jm = pin.JointModelSpherical()
                jid = model.addJoint(jid, jm, place, ax.name)
                at = ax.anchor
                self.axes.append((jid, ax))
            li = inertias[b.link]
            n = copies[b.link]
            model.appendBodyToJoint(jid, pin.Inertia(li.mass_kg / n, li.com_m - at, li.inertia_kg_m2 / n), pin.SE3.Identity())
            last[b.name] = (jid, at)
        self.last = last
        self.model, self.data = model, model.createData()

    def q_of(self, config) -> np.ndarray:
        """Pinocchio's ``q`` from MuJoCo's ``qpos`` of the same configuration (hinge and slide:
        the value minus its reference; ball: the quaternion reordered to x, y, z, w)."""
        import mujoco as mj

        qpos = self.sim.qpos_of(config)
        m = self.sim.model
        q = np.zeros(self.model.nq)
        for jid, ax in self.axes:
            adr = int(m.jnt_qposadr[mj.mj_name2id(m, mj.mjtObj.mjOBJ_JOINT, ax.name)])
            iq = self.model.idx_qs[jid]
            if ax.kind == "ball":
                w, x, y, z = qpos[adr : adr + 4]
                q[iq : iq + 4] = [x, y, z, w]
            else:
                q[iq] = qpos[adr] - ax.ref
        return q

    def body_jacobians(self, q: np.ndarray, v: np.ndarray | None = None) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """Per body, ``(J, Jdot)`` of its twist ``(omega ; v at the origin)`` (Pinocchio's WORLD
        frame, halves swapped to the screw convention)."""
        pin = self.pin
        v = np.zeros(self.model.nv) if v is None else v
        pin.computeJointJacobians(self.model, self.data, q)
        pin.computeJointJacobiansTimeVariation(self.model, self.data, q, v)
        out = {}
        for b in self.tree.bodies:
            jid = self.last[b.name][0]
            J = pin.getJointJacobian(self.model, self.data, jid, pin.ReferenceFrame.WORLD)
            Jd = pin.getJointJacobianTimeVariation(self.model, self.data, jid, pin.ReferenceFrame.WORLD)
            out[b.name] = (np.vstack([J[3:], J[:3]]), np.vstack([Jd[3:], Jd[:3]]))
        return out

    def closure_jacobian(self, q: np.ndarray) -> np.ndarray:
        """Rows of the loop closures: a connect's common point velocity, a weld's twist."""
        pin = self.pin
        pin.forwardKinematics(self.model, self.data, q)
        jac = self.body_jacobians(q)
        rows = []
        for c in self.tree.closures:
            blocks = []
            for body, sign in ((c.body1, 1.0), (c.body2, -1.0)):
                if body is None:
                    continue
                J = jac[body][0]
                if c.kind == "connect":
                    jid, at = self.last[body]
                    p = self.data.oMi[jid].act(c.anchor - at)  # the anchor carried by the body
                    blocks.append(sign * (J[3:] - _skew(p) @ J[:3]))
                else:
                    blocks.append(sign * J)
            rows.append(sum(blocks))
        return np.vstack(rows)

    def efforts(self, res: InverseDynamics, wrench=None) -> tuple[np.ndarray, dict]:
        """The actuator efforts Pinocchio gives at the library's state, and the residuals;
        ``wrench`` on the output body as in :func:`mujoco_efforts`."""
        pin = self.pin
        q = self.q_of(res.state.config)
        jac = self.body_jacobians(q)
        J = np.vstack([jac[b.name][0] for b in self.tree.bodies])
        V = np.concatenate([res.link_twists[b.link] for b in self.tree.bodies])
        v, *_ = np.linalg.lstsq(J, V, rcond=None)
        resid = {"v": _rel(J @ v, V) if np.any(V) else 0.0}
        jac = self.body_jacobians(q, v)
        Jd = np.vstack([jac[b.name][1] for b in self.tree.bodies])
        Acc = np.concatenate([res.link_accelerations[b.link] for b in self.tree.bodies]) - Jd @ v
        a, *_ = np.linalg.lstsq(J, Acc, rcond=None)
        resid["a"] = _rel(J @ a, Acc)
        qfrc = pin.rnea(self.model, self.data, q, v, a).copy()
        if wrench is not None:
            Jo = jac[self.tree.output][0]
            qfrc -= Jo.T @ np.r_[np.asarray(wrench[3:]), np.asarray(wrench[:3])]
        Jc = self.closure_jacobian(q)
        act = [self.model.idx_vs[self.model.getJointId(name)] for name in res.actuators]
        B = np.zeros((len(act), self.model.nv))
        B[np.arange(len(act)), act] = 1.0
        tau, resid["split"] = _split_efforts(np.hstack([B.T, Jc.T]), qfrc, len(act))
        # the placements agree with the library's: every body's origin and axes
        pin.forwardKinematics(self.model, self.data, q)
        place = link_placements(self.mech, res.state.config)
        err = 0.0
        for b in self.tree.bodies:
            jid, at = self.last[b.name]
            M, T = self.data.oMi[jid], place[b.link]
            err = max(err, float(np.linalg.norm(M.act(b.origin - at) - (T[:3, :3] @ b.origin + T[:3, 3]))),
                      float(np.linalg.norm(M.rotation - T[:3, :3])))
        resid["placement"] = err
        return tau, resid
