"""Mobility: the modified Kutzbach-Grübler formula from screw systems, and a numerical check.

Modified formula (Huang; papers B and C, eq 4 / eq 9)::

    M = d (n - g - 1) + sum(f_i) + v - xi,     d = 6 - lambda,   v = t - k

All of ``lambda, t, k, xi`` are derived from the screw systems of the limbs at the reference
configuration (not typed in):

- ``lambda`` common constraints: the wrenches reciprocal to every joint twist of the
  mechanism, ``6 - rank(all twists)``;
- ``t`` the number of limb constraint wrenches once the common ones are removed,
  ``sum_k (dim W_k - lambda)`` with ``W_k`` the constraint system of limb ``k``;
- ``k`` the number of independent ones among them, ``dim(sum_k W_k) - lambda``;
- ``v = t - k`` redundant constraints (paper C prints ``k - t``: a typo that is harmless there
  because ``t = k``);
- ``xi`` passive (local) freedoms: motions of a limb's joints with the platform at rest,
  ``sum_k (f_k - rank T_k)``, e.g. the spin of an SPS leg about its own axis.

``n`` counts links including base and platform, ``g`` joints; a locked joint is removed and its
two links merged.  The numerical check is independent: the nullity of the loop-closure
Jacobian at a *generic* configuration reached by moving along the closure manifold, minus the
passive freedoms, is the instantaneous mobility ``dof_instantaneous``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from ..geometry import screws as sc
from ..kinematics.closure import (
    Configuration,
    active_mask,
    closure_jacobian,
    generic_configuration,
    joint_twists,
    limb_slices,
)
from ..model.mechanism import Mechanism, Mode

__all__ = ["MobilityResult", "mobility", "mobility_modes", "motion_type", "ELEMENTARY_MOTIONS"]

#: The elementary platform motions used to name a motion type, at the platform point.
ELEMENTARY_MOTIONS = {
    "Rx": np.array([1.0, 0, 0, 0, 0, 0]),
    "Ry": np.array([0, 1.0, 0, 0, 0, 0]),
    "Rz": np.array([0, 0, 1.0, 0, 0, 0]),
    "Tx": np.array([0, 0, 0, 1.0, 0, 0]),
    "Ty": np.array([0, 0, 0, 0, 1.0, 0]),
    "Tz": np.array([0, 0, 0, 0, 0, 1.0]),
}


def motion_type(twists, point, *, length_scale: float = 1.0) -> tuple[str, str]:
    """Name a platform twist system at ``point``: ``("RxRyRzTz", "3R1T")``.

    The first name lists the elementary motions (rotations about axes through ``point``
    parallel to x, y, z; translations along x, y, z) when they span the system; otherwise it is
    the class name alone (e.g. a coupled screw motion, or rotation axes not through the point).
    """
    T = np.atleast_2d(np.asarray(twists, dtype=float))
    p = np.asarray(point, dtype=float)
    if T.size == 0:
        return "rigid", "0"
    at_p = T.copy()
    at_p[:, 3:] = T[:, 3:] + np.cross(T[:, :3], p)
    dim = sc.rank(at_p, length_scale=length_scale)
    if dim == 0:
        return "rigid", "0"
    B = sc.basis(at_p, length_scale=length_scale)  # orthonormal basis of the system
    w = B[:, :3]
    sv = np.linalg.svd(w, compute_uv=False)
    r = int(np.sum(sv > 1e-9))
    tdim = dim - r
    cls = (f"{r}R" if r else "") + (f"{tdim}T" if tdim else "")
    members = [k for k, e in ELEMENTARY_MOTIONS.items() if sc.contains(at_p, e, length_scale=length_scale)]
    if len(members) == dim:
        return "".join(members), cls
    return cls, cls


@dataclass(frozen=True)
class MobilityResult:
    """Mobility of one mode of a mechanism, with the whole breakdown."""

    mechanism: str
    mode: str
    actuators: tuple[str, ...]
    dof: int
    dof_instantaneous: int
    gk_classic: int
    motion: str
    motion_class: str
    lam: int
    d: int
    n: int
    g: int
    sum_f: int
    t: int
    k: int
    v: int
    xi: int
    limb_constraints: tuple[int, ...]
    constraint_wrenches: tuple[tuple[float, ...], ...]
    agrees: bool
    explanation: str
    passive: tuple[int, ...] = field(default=())

    def to_dict(self) -> dict:
        d = asdict(self)
        d["lambda"] = d.pop("lam")
        d["actuators"] = list(self.actuators)
        d["limb_constraints"] = list(self.limb_constraints)
        d["passive"] = list(self.passive)
        d["constraint_wrenches"] = [list(w) for w in self.constraint_wrenches]
        return d

    def formula(self) -> str:
        return (
            f"M = d(n - g - 1) + sum f + v - xi = {self.d}({self.n} - {self.g} - 1) + {self.sum_f}"
            f" + {self.v} - {self.xi} = {self.dof}"
        )


def _canonical(W: np.ndarray, L: float) -> np.ndarray:
    """A readable basis of a screw system: reduced row echelon form, then each screw scaled to
    a unit direction (or a unit moment for a pure couple/translation)."""
    if W.shape[0] == 0:
        return W
    A = sc.rref(sc.nondimensional(W, L))
    A[:, 3:] *= L
    out = []
    for w in A:
        n = np.linalg.norm(w[:3])
        w = w / (n if n > 1e-12 else np.linalg.norm(w[3:]))
        w = np.where(np.abs(w) < 1e-12, 0.0, w)
        out.append(np.round(w, 12) + 0.0)
    return np.array(out)


def _count_structure(mech: Mechanism) -> tuple[int, int, int, list[int]]:
    """Links n (incl. base and platform), joints g, sum of freedoms, per-limb freedoms."""
    g = 0
    n = 2
    f_limbs = []
    for limb in mech.limbs:
        gk = sum(1 for j in limb.joints if j.dof > 0)
        g += gk
        n += gk - 1
        f_limbs.append(limb.dof)
    return n, g, sum(f_limbs), f_limbs


def _nullity(A: np.ndarray, rtol: float = 1e-9) -> int:
    if A.shape[1] == 0:
        return 0
    sv = np.linalg.svd(A, compute_uv=False)
    r = int(np.sum(sv > rtol * max(1.0, sv[0]))) if sv.size else 0
    return A.shape[1] - r


def _instantaneous(mech: Mechanism, config: Configuration) -> tuple[int, int, np.ndarray]:
    """(platform dof, passive freedoms, platform twist basis) at ``config``, nondimensionally."""
    active = active_mask(mech)
    L = mech.characteristic_length
    A, _ = closure_jacobian(mech, config, active=active)
    K = len(mech.limbs)
    row = np.tile(np.r_[np.ones(3), np.full(3, 1.0 / L)], K)
    lin = np.array([r.freedom.is_linear for r in mech.freedom_refs])[active]
    col = np.r_[np.where(lin, L, 1.0), np.ones(3), np.full(3, L)]
    As = row[:, None] * A * col[None, :]
    N = _nullity(As)
    # passive freedoms: limb Jacobians' null spaces (platform at rest)
    xi = 0
    na = 0
    idx = np.flatnonzero(active)
    for sl in limb_slices(mech):
        cols = [i for i, gi in enumerate(idx) if sl.start <= gi < sl.stop]
        xi += _nullity(As[:, cols]) if cols else 0
        na += len(cols)
    # platform twists = projection of the null space onto V
    _, sv, vt = np.linalg.svd(As)
    r = int(np.sum(sv > 1e-9 * max(1.0, sv[0])))
    null = vt[r:]
    V = null[:, -6:] / col[-6:]  # back to SI twists
    Vb = sc.basis(V, length_scale=L) if V.shape[0] else np.zeros((0, 6))
    return N - xi, xi, Vb


def mobility(mech: Mechanism, mode: Mode | str | None = None, *, seed: int = 0) -> MobilityResult:
    """Mobility of ``mech`` (in ``mode`` for a metamorphic mechanism).

    Raises ``ValueError`` when a metamorphic mechanism is given without a mode while its
    declared modes are several (use :func:`mobility_modes`).
    """
    if mode is None:
        modes = mech.all_modes()
        if len(modes) != 1:
            raise ValueError(
                f"mode: {mech.name} is metamorphic with modes {', '.join(m.name for m in modes)}; name one"
            )
        mode = modes[0]
    if isinstance(mode, str) and not mech.is_metamorphic:
        mode = mech.mode(mode)  # KeyError naming the modes for an unknown name
    m = mech.in_mode(mode) if mech.is_metamorphic else mech
    mode_obj = m.modes[0] if m.modes else (mode if isinstance(mode, Mode) else Mode(str(mode), ()))
    L = m.characteristic_length
    ref = Configuration.reference(m)
    active = active_mask(m)
    tw = joint_twists(m, ref)
    limbs_T = []
    for sl, J in zip(limb_slices(m), tw):
        a = active[sl]
        limbs_T.append(J[:, a].T)
    all_T = np.vstack([T for T in limbs_T if T.size] or [np.zeros((0, 6))])
    lam = 6 - sc.rank(all_T, length_scale=L) if all_T.size else 6
    d = 6 - lam
    W = [sc.reciprocal_basis(T, length_scale=L) if T.size else np.eye(6) for T in limbs_T]
    ranks = [sc.rank(T, length_scale=L) if T.size else 0 for T in limbs_T]
    t = sum(w.shape[0] - lam for w in W)
    Wall = np.vstack(W)
    k = sc.rank(Wall, length_scale=L) - lam
    v = t - k
    n, g, sum_f, f_limbs = _count_structure(m)
    passive = tuple(f - r for f, r in zip(f_limbs, ranks))
    xi = sum(passive)
    M = d * (n - g - 1) + sum_f + v - xi
    gk = 6 * (n - g - 1) + sum_f

    # the free platform twist system at the reference: reciprocal to all limb constraints
    Vref = sc.reciprocal_basis(Wall, length_scale=L)
    try:
        gen = generic_configuration(m, seed=seed)
        dof_inst, xi_num, Vgen = _instantaneous(m, gen)
        generic_note = ""
    except RuntimeError as e:  # pragma: no cover - reported, not hidden
        gen = ref
        dof_inst, xi_num, Vgen = _instantaneous(m, ref)
        generic_note = f" (no generic configuration could be reached: {e}; the reference was used)"

    if Vref.shape[0] == dof_inst:
        motion, mclass = motion_type(Vref, m.platform_point, length_scale=L)
        where = "at the reference configuration"
    else:
        p_now = gen.D[:3, :3] @ m.platform_point + gen.D[:3, 3]
        motion, mclass = motion_type(Vgen, p_now, length_scale=L)
        where = "at a generic configuration"

    notes = []
    if gk != M:
        parts = [f"{lam} common constraint(s) (d = {d})" if lam else "",
                 f"{v} redundant constraint(s)" if v else "",
                 f"{xi} passive freedom(s)" if xi else ""]
        notes.append(
            f"The classic Grübler-Kutzbach count (d = 6, no corrections) gives {gk}; it ignores the "
            + ", ".join(p for p in parts if p) + " found from the screw systems."
        )
    if M != dof_inst:
        notes.append(
            f"The screw systems at the reference configuration give M = {M}, but the loop-closure "
            f"Jacobian at a generic configuration has instantaneous mobility {dof_inst}: the "
            "reference configuration is special (singular or a bifurcation), so the formula's "
            "counts there do not describe the finite motion."
        )
    if not notes:
        notes.append(f"The modified formula and the numerical rank agree: {M}.")
    wr = _canonical(sc.basis(Wall, length_scale=L), L) if Wall.size else np.zeros((0, 6))
    return MobilityResult(
        mechanism=mech.name,
        mode=mode_obj.name,
        actuators=m.actuators,
        dof=int(M),
        dof_instantaneous=int(dof_inst),
        gk_classic=int(gk),
        motion=motion,
        motion_class=mclass,
        lam=int(lam),
        d=int(d),
        n=int(n),
        g=int(g),
        sum_f=int(sum_f),
        t=int(t),
        k=int(k),
        v=int(v),
        xi=int(xi),
        limb_constraints=tuple(int(w.shape[0]) for w in W),
        constraint_wrenches=tuple(tuple(float(x) for x in w) for w in wr),
        agrees=bool(M == dof_inst),
        explanation=" ".join(notes) + f" Motion named {where}." + generic_note,
        passive=passive,
    )


def mobility_modes(mech: Mechanism, *, seed: int = 0) -> list[MobilityResult]:
    """Mobility of every mode (one element for a mechanism that is not metamorphic)."""
    return [mobility(mech, m, seed=seed) for m in mech.all_modes()]
