"""The polynomial systems of the homotopy forward position (:mod:`.study`): each limb of a
platform, with the actuator values given, as quadrics in the Study parameters ``x = (e ; g)``
of the platform displacement.

:class:`StewartSystem`: S-P-S / U-P-S / S-P-U / R-P-S legs and passive C-U / C-S limbs with
fixed centres (the squared leg lengths the parameters).  :class:`PoseSystem`: the general
reduction, whose coefficients depend on the actuators (P-R-S and U-P-U legs, S-S rods from
bodies driven by actuated joints alone, as the Delta's arms); its parameter space is the
affine span of the coefficient tensors.  See docs/homotopy.md.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ...model.mechanism import Mechanism

__all__ = [
    "PoseSystem",
    "StewartSystem",
    "geometry_family",
    "pose_system",
    "qmul",
    "stewart_system",
    "system_from_points",
    "unsupported_reason",
]

_N = 8  # unknowns: e0..e3, g0..g3


def _qmat_left(q) -> np.ndarray:
    """``L(q)`` with ``q r = L(q) r`` (quaternions scalar first)."""
    w, x, y, z = q
    return np.array([[w, -x, -y, -z], [x, w, -z, y], [y, z, w, -x], [z, -y, x, w]], dtype=float)


def _qmat_right(r) -> np.ndarray:
    """``R(r)`` with ``q r = R(r) q``."""
    w, x, y, z = r
    return np.array([[w, -x, -y, -z], [x, w, z, -y], [y, -z, w, x], [z, y, -x, w]], dtype=float)


def qmul(q, r):
    """Quaternion product ``q r`` (scalar first)."""
    w1, x1, y1, z1 = q
    w2, x2, y2, z2 = r
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


@dataclass(frozen=True, eq=False)
class StewartSystem:
    """The polynomial system of a platform on actuated S-P-S legs and passive point-on-line
    limbs (see the module docstring).

    ``base``, ``platform``: the legs' base and platform centres at the reference (model units);
    the squared leg length of leg ``k`` is ``(d_ref[k] + sign[k] * (v_k - offset[k]))^2`` for
    the actuator value ``v_k``.  ``lines``: per point-on-line limb, the platform point at the
    reference, a point of the base line and its direction (a C-U or C-S limb: the U or S centre
    stays on the C axis; two quadrics each)."""

    base: np.ndarray  # (n_legs, 3)
    platform: np.ndarray  # (n_legs, 3)
    d_ref: np.ndarray
    sign: np.ndarray
    offset: np.ndarray
    L: float
    Q: np.ndarray = field(repr=False)  # (7, 8, 8): Study quadric, the legs without the length term, the lines
    lines: tuple = ()

    @property
    def n_legs(self) -> int:
        return len(self.base)

    def lengths(self, values) -> np.ndarray:
        """Leg lengths (model units) for actuator values."""
        v = np.asarray(values, dtype=float)
        return self.d_ref + self.sign * (v - self.offset)

    @property
    def n_act(self) -> int:
        return len(self.base)

    def coefficients(self, values) -> np.ndarray:
        """The seven quadrics (7, 8, 8) at actuator values (model units)."""
        Qv = self.Q.copy()
        l2 = (self.lengths(values) / self.L) ** 2
        for k in range(self.n_legs):
            Qv[1 + k, :4, :4] -= l2[k] * np.eye(4)
        return Qv

    def affine_span(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(Q0, B, scale)``: every coefficient tensor of the family is ``Q0 + sum z_j B_j``
        (here ``z`` are the squared leg lengths over ``L^2``), ``scale`` the size of ``z``."""
        B = np.zeros((self.n_legs, 7, _N, _N))
        for k in range(self.n_legs):
            B[k, 1 + k, :4, :4] = -np.eye(4)
        return self.Q, B, np.ones(self.n_legs)

    def key(self) -> bytes:
        return np.round(self.Q, 12).tobytes()


def _point_on_line(limb, L: float) -> tuple | None:
    """(platform point, line point, line direction) of a C-U / C-S limb whose centre is on the C
    axis, else ``None``."""
    types = [j.type for j in limb.joints]
    if types not in (["C", "U"], ["C", "S"]) or any(f.actuated for j in limb.joints for f in j.freedoms):
        return None
    c, t = limb.joints
    rot = next(f for f in c.freedoms if f.kind == "R")
    sl = next(f for f in c.freedoms if f.kind == "P")
    d = rot.direction / np.linalg.norm(rot.direction)
    if np.linalg.norm(np.cross(d, sl.direction)) > 1e-9:
        return None
    u = t.point
    if np.linalg.norm(np.cross(u - rot.point, d)) > 1e-9 * L:
        return None
    if t.type == "U" and np.linalg.norm(t.freedoms[0].point - t.freedoms[1].point) > 1e-9 * L:
        return None
    n1 = np.cross(d, [1.0, 0, 0] if abs(d[0]) < 0.9 else [0, 1.0, 0])
    n1 /= np.linalg.norm(n1)
    return u, rot.point, (n1, np.cross(d, n1))


def _rps_plane(limb, L: float) -> tuple | None:
    """(platform centre, base point, (axis,)) of an R-P-S leg whose slide is perpendicular to the
    R axis and runs from the axis to the S centre (the centre stays in the plane normal to the
    axis through the base point), else ``None``."""
    if [j.type for j in limb.joints] != ["R", "P", "S"]:
        return None
    r, pj, sj = limb.joints
    n = r.freedoms[0].direction / np.linalg.norm(r.freedoms[0].direction)
    d = sj.point - r.freedoms[0].point
    nd = float(np.linalg.norm(d))
    sl = pj.freedoms[0]
    if (nd < 1e-9 * L or abs(float(d @ n)) > 1e-9 * nd or abs(abs(float(d @ sl.direction)) - nd) > 1e-9 * nd
            or not sl.actuated):
        return None
    return sj.point, r.freedoms[0].point, (n,)


def unsupported_reason(mech: Mechanism) -> str | None:
    """``None`` when the homotopy formulation covers ``mech``, else why not (one sentence)."""
    if _stewart_reason(mech) is None:
        return None
    return _general(mech)[0]


def _stewart_reason(mech: Mechanism) -> str | None:
    """``None`` when :func:`stewart_system` covers ``mech``."""
    if mech.bodies:
        return "a link-and-joint graph (internal bodies)"
    L = mech.characteristic_length
    n_eq = 0
    for limb in mech.limbs:
        types = [j.type for j in limb.joints]
        if limb.base != "ground" or limb.tip is not None:
            return f"limb {limb.name} does not run from the ground to the platform"
        if _point_on_line(limb, L) is not None:
            n_eq += 2
            continue
        if _rps_plane(limb, L) is not None:
            n_eq += 2
            continue
        if len(types) != 3 or types[1] != "P" or not set(types[::2]) <= {"S", "U"} or types[::2] == ["U", "U"]:
            return (f"limb {limb.name} is {'-'.join(types)} (the formulation covers S-P-S, U-P-S, S-P-U and R-P-S legs "
                    "and C-U / C-S limbs with the centre on the C axis)")
        slide = limb.joints[1].freedoms[0]
        if not slide.actuated:
            return f"limb {limb.name}: its slide is not the actuator"
        for j in limb.joints[::2]:
            if j.type == "U" and np.linalg.norm(j.freedoms[0].point - j.freedoms[1].point) > 1e-9 * L:
                return f"limb {limb.name}: the axes of {j.name} do not meet"
        d = limb.joints[2].point - limb.joints[0].point
        nd = float(np.linalg.norm(d))
        if nd < 1e-9 * L or abs(abs(float(d @ slide.direction)) - nd) > 1e-9 * nd:
            return f"limb {limb.name}: the slide does not run along the line of its two centres"
        n_eq += 1
    others = [r.id for r in mech.freedom_refs if r.freedom.actuated and r.freedom.kind != "P"]
    if others:
        return "actuators other than the leg slides"
    if n_eq != 6:
        return f"its limbs give {n_eq} equations on the platform pose, not 6"
    return None


def stewart_system(mech: Mechanism) -> StewartSystem:
    """The system of ``mech`` (``InputError`` naming the reason when it is not covered)."""
    why = _stewart_reason(mech)
    if why is not None:
        raise InputError(f"model: homotopy forward position does not cover {mech.name}: {why}; use method='multistart'")
    L = float(mech.characteristic_length)
    legs = [limb for limb in mech.limbs if _point_on_line(limb, L) is None]
    lines = tuple(x for x in (_point_on_line(limb, L) or _rps_plane(limb, L) for limb in mech.limbs) if x is not None)
    order = []
    for act in mech.actuators:
        ref = mech.freedom(act)
        order.append(next(i for i, limb in enumerate(legs) if limb.joints[1].freedoms[0] is ref.freedom))
    legs = [legs[k] for k in order]
    a = np.array([limb.joints[0].point for limb in legs], dtype=float).reshape(-1, 3)
    b = np.array([limb.joints[2].point for limb in legs], dtype=float).reshape(-1, 3)
    d = b - a
    d_ref = np.linalg.norm(d, axis=1)
    sign = np.array([np.sign(float(d[i] @ limb.joints[1].freedoms[0].direction)) for i, limb in enumerate(legs)])
    offset = np.array([limb.joints[1].freedoms[0].offset for limb in legs])
    return system_from_points(a, b, L=L, d_ref=d_ref, sign=sign, offset=offset, lines=lines)


def _line_quadrics(u, o, normals, L: float) -> list[np.ndarray]:
    """Quadrics ``n . vec((e u - o e + 2 g) e*) = 0``: the platform point ``u`` in the planes
    through ``o`` normal to each ``n`` (two normals: on a line)."""
    K = np.hstack([_qmat_right(np.r_[0.0, u / L]) - _qmat_left(np.r_[0.0, o / L]), 2 * np.eye(4)])
    conj = np.diag([1.0, -1, -1, -1])
    out = []
    for n in normals:
        M = np.zeros((_N, _N))
        for i in range(_N):
            for j in range(4):  # e components of the second argument
                M[i, j] = n @ qmul(K[:, i], conj[:, j])[1:]
        out.append(0.5 * (M + M.T))
    return out


def system_from_points(base, platform, *, L: float | None = None, d_ref=None, sign=None, offset=None,
                       lines: tuple = ()) -> StewartSystem:
    """The system of legs from ``base[k]`` to ``platform[k]`` (reference placement; by default
    the actuator values are the leg lengths) and point-on-line constraints ``lines``
    (``(platform point, base point, normals)``: one normal, a plane; two, a line); six
    equations in all."""
    a = np.asarray(base, dtype=float).reshape(-1, 3)
    b = np.asarray(platform, dtype=float).reshape(-1, 3)
    n_eq = len(a) + sum(len(x[2]) for x in lines)
    if n_eq != 6 or b.shape != a.shape:
        raise InputError(f"base, platform: {len(a)} legs and {len(lines)} point constraints give {n_eq} equations, not 6")
    if L is None:
        pts = np.vstack([a, b])
        L = float(np.sqrt(np.mean(np.sum((pts - pts.mean(axis=0)) ** 2, axis=1))))
    if d_ref is None:
        d_ref = np.linalg.norm(b - a, axis=1)
        sign, offset = np.ones(len(a)), d_ref.copy()
    Q = np.zeros((7, _N, _N))
    Q[0, :4, 4:] = Q[0, 4:, :4] = 0.5 * np.eye(4)
    for i in range(len(a)):
        K = np.hstack([_qmat_right(np.r_[0.0, b[i] / L]) - _qmat_left(np.r_[0.0, a[i] / L]), 2 * np.eye(4)])
        Q[i + 1] = K.T @ K
    row = 1 + len(a)
    for u, o, normals in lines:
        for M in _line_quadrics(np.asarray(u, float), np.asarray(o, float), normals, L):
            Q[row] = M
            row += 1
    return StewartSystem(a, b, np.asarray(d_ref, float), np.asarray(sign, float), np.asarray(offset, float), L, Q,
                         tuple(lines))


# ------------------------------------------------------------------------------ general limbs
def _k_matrix(b, c, L: float) -> np.ndarray:
    """``K`` with ``K x = e b - c e + 2 g`` (a quaternion; ``b``, ``c`` model units over ``L``)."""
    return np.hstack([_qmat_right(np.r_[0.0, b / L]) - _qmat_left(np.r_[0.0, c / L]), 2 * np.eye(4)])


def _sphere_quadric(b, c, r: float, L: float) -> np.ndarray:
    """The platform point ``b`` (reference) at distance ``r`` from the point ``c``:
    ``|e b - c e + 2 g|^2 - (r / L)^2 e.e``."""
    K = _k_matrix(b, c, L)
    M = K.T @ K
    M[:4, :4] -= (r / L) ** 2 * np.eye(4)
    return M


def _bilinear_e(K: np.ndarray, f) -> np.ndarray:
    """The symmetric quadric of ``x -> f(K x, e*)`` for ``f`` bilinear in two quaternions (real
    result)."""
    conj = np.diag([1.0, -1, -1, -1])
    M = np.zeros((_N, _N))
    for i in range(_N):
        for j in range(4):
            M[i, j] = f(K[:, i], conj[:, j])
    return 0.5 * (M + M.T)


def _upu_quadric(b, a, n1, n_p, L: float) -> np.ndarray:
    """The U-P-U condition ``n1 . ((u - a) x R n_p) = 0`` (the base U's first axis ``n1``, the
    platform U's platform axis ``n_p``, the two middle axes parallel and normal to the leg) as
    the quadric ``n1 . vec(v n_p e*) = 0``, ``v = e b - a e + 2 g`` (valid on the Study quadric,
    where ``v e*`` is a pure quaternion)."""
    K = _k_matrix(b, a, L)
    npq = np.r_[0.0, n_p]
    return _bilinear_e(K, lambda v, ec: float(n1 @ qmul(qmul(v, npq), ec)[1:]))


def _plane_quadric(b, o, n, L: float) -> np.ndarray:
    """The platform point ``b`` in the plane through ``o`` normal to ``n``."""
    return _line_quadrics(np.asarray(b, float), np.asarray(o, float), (np.asarray(n, float),), L)[0]


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


@dataclass(frozen=True, eq=False)
class PoseSystem:
    """The forward position of a platform as six quadrics in the Study parameters whose
    coefficients depend on the actuator values (see :func:`pose_system`): ``rows(values)``
    gives the six constraint quadrics (model units), ``reductions`` one line per limb (group)
    saying what it became, ``scales`` the actuator sample sizes for the affine span."""

    name: str
    L: float
    n_act: int
    rows: Callable[[np.ndarray], list] = field(repr=False)  # values -> the six (8, 8) quadrics
    reference: np.ndarray = field(repr=False)  # actuator values at the reference
    scales: np.ndarray = field(repr=False)
    reductions: tuple = ()
    _span: list = field(default_factory=list, repr=False)

    def coefficients(self, values) -> np.ndarray:
        Qv = np.zeros((7, _N, _N))
        Qv[0, :4, 4:] = Qv[0, 4:, :4] = 0.5 * np.eye(4)
        Qv[1:] = np.array(self.rows(np.asarray(values, dtype=float)))
        return Qv

    def affine_span(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(Q0, B, scale)``: the affine hull of the coefficient tensors over the actuator
        values, ``Q0 + sum z_j B_j`` (orthonormal ``B``), from seeded random samples around the
        reference (the coefficients are polynomials in the actuator values or in their cosines
        and sines, so samples span the hull with probability one)."""
        if not self._span:
            rng = np.random.default_rng(12345)
            Q0 = self.coefficients(self.reference)
            n_s = 4 * self.n_act + 8
            D = np.array([(self.coefficients(self.reference + self.scales * rng.normal(size=self.n_act)) - Q0).ravel()
                          for _ in range(n_s)])
            _, sv, Vt = np.linalg.svd(D, full_matrices=False)
            rank = int(np.sum(sv > 1e-9 * max(float(sv[0]), 1e-300)))
            B = Vt[:rank].reshape(rank, 7, _N, _N)
            z = D @ Vt[:rank].T
            self._span.append((Q0, B, np.maximum(z.std(axis=0), 1e-6)))
        return self._span[0]

    def key(self) -> bytes:
        Q0, B, _ = self.affine_span()
        return np.round(Q0, 12).tobytes() + np.round(np.abs(B).sum(axis=0), 10).tobytes()


def _slide(limb, k: int):
    return limb.joints[k].freedoms[0]


def _is_rod(joints, L: float) -> bool:
    """Two joints S-S, S-U or U-S (the U's axes meeting): a rod that keeps only its length."""
    types = [j.type for j in joints]
    if len(types) != 2 or types not in (["S", "S"], ["S", "U"], ["U", "S"]):
        return False
    return all(j.type != "U" or np.linalg.norm(j.freedoms[0].point - j.freedoms[1].point) <= 1e-9 * L for j in joints)


def _uu_rod(joints, L: float) -> tuple[np.ndarray, np.ndarray] | None:
    """A U-U rod of the U-P-U's layout (each U's axes meeting, the two inner axes parallel and
    normal to the rod and to the outer axes, as the ``delta-ruu``'s parallelogram equivalents):
    ``(n1, n_p)``, the first U's outer axis (carried by the body before the rod) and the second
    U's outer axis (carried by the platform), reference directions; else ``None``."""
    if [j.type for j in joints] != ["U", "U"]:
        return None
    tol = 1e-9
    if any(np.linalg.norm(j.freedoms[0].point - j.freedoms[1].point) > tol * L for j in joints):
        return None
    w = joints[1].point - joints[0].point
    if np.linalg.norm(w) < tol * L:
        return None
    w = _unit(w)
    n1, m = _unit(joints[0].freedoms[0].direction), _unit(joints[0].freedoms[1].direction)
    m2, n_p = _unit(joints[1].freedoms[0].direction), _unit(joints[1].freedoms[1].direction)
    if abs(m @ n1) > tol or abs(m @ w) > tol or np.linalg.norm(np.cross(m, m2)) > tol or abs(n_p @ m2) > tol:
        return None
    return n1, n_p


def _rod_rows(D: np.ndarray, a, b, r: float, uu, L: float) -> list[np.ndarray]:
    """A rod from the point ``a`` of a body displaced by ``D`` (the actuators fix it) to the
    platform point ``b``: the sphere about the moving centre and, for a U-U rod (``uu`` =
    ``(n1, n_p)``), the U-P-U condition with the first outer axis carried by the body."""
    c = D[:3, :3] @ a + D[:3, 3]
    rows = [_sphere_quadric(b, c, r, L)]
    if uu is not None:
        rows.append(_upu_quadric(b, c, D[:3, :3] @ uu[0], uu[1], L))
    return rows


def _driven_rod(limb, L: float, act_index: dict, hubs: dict) -> tuple[str | None, list, str] | None:
    """(why not, builders, description) of a rod limb after a body the actuators fix: a limb from
    a driven body that is a rod, or actuated joints from the ground then a rod (S-S, S-U, U-S:
    a sphere about a moving centre; U-U of the U-P-U's layout: the sphere and the U-joint
    condition); ``None`` when the limb is neither."""
    types = [j.type for j in limb.joints]
    if limb.base != "ground":
        if limb.base not in hubs:
            return f"limb {limb.name} starts on body {limb.base}, whose pose the actuators do not fix", [], ""
        uu = _uu_rod(limb.joints, L)
        if not _is_rod(limb.joints, L) and uu is None:
            return (f"limb {limb.name} from body {limb.base} is {'-'.join(types)} (from a driven body the "
                    "formulation covers S-S, S-U, U-S rods and U-U rods of the U-P-U's layout)"), [], ""
        hub = hubs[limb.base]
        a, b = limb.joints[0].point, limb.joints[1].point
        r = float(np.linalg.norm(b - a))

        def rod(v, hub=hub, a=a, b=b, r=r, uu=uu):
            return _rod_rows(hub(v), a, b, r, uu, L)

        return None, [rod], f"{limb.name} ({'-'.join(types)} rod from driven {limb.base}): sphere about a moving centre"
    prefix = [f for j in limb.joints[:-2] for f in j.freedoms]
    if len(types) <= 2 or not all(f.actuated and id(f) in act_index for f in prefix):
        return None
    uu = _uu_rod(limb.joints[-2:], L)
    if not _is_rod(limb.joints[-2:], L) and uu is None:
        return None
    from ..closure import limb_forward

    S = np.array([f.screw for f in prefix])
    ks = [act_index[id(f)] for f in prefix]
    offs = np.array([f.offset for f in prefix])
    a, b = limb.joints[-2].point, limb.joints[-1].point
    r = float(np.linalg.norm(b - a))

    def crank(v, S=S, ks=ks, offs=offs, a=a, b=b, r=r, uu=uu):
        return _rod_rows(limb_forward(S, np.asarray(v)[ks] - offs)[0], a, b, r, uu, L)

    what = "sphere about a moving centre" + ("" if uu is None else " and the U-joint condition n1 . ((u - c) x R n_p) = 0")
    return None, [crank], f"{limb.name} ({'-'.join(types)}): driven crank and rod, {what}"


def _reduce_limb(limb, L: float, act_index: dict, hubs: dict) -> tuple[str | None, list, str]:
    """(why not, constraint builders ``values -> [quadrics]``, description) of one limb to the
    platform."""
    types = [j.type for j in limb.joints]
    tol = 1e-9
    driven = _driven_rod(limb, L, act_index, hubs)
    if driven is not None:
        return driven
    if types == ["P", "R", "S"]:
        sl, rj, sj = _slide(limb, 0), limb.joints[1].freedoms[0], limb.joints[2]
        if not sl.actuated or id(sl) not in act_index:
            return f"limb {limb.name}: its slide is not the actuator", [], ""
        k = act_index[id(sl)]
        n = _unit(rj.direction)
        s_dir = _unit(sl.direction)
        f = rj.point + float((sj.point - rj.point) @ n) * n
        rho = float(np.linalg.norm(sj.point - f))
        if rho < tol * L:
            return f"limb {limb.name}: the S centre is on the R axis", [], ""
        u = sj.point

        def prs(v, k=k, f=f, s_dir=s_dir, off=sl.offset, rho=rho, u=u, n=n):
            cen = f + (v[k] - off) * s_dir
            return [_sphere_quadric(u, cen, rho, L), _plane_quadric(u, cen, n, L)]

        return None, [prs], f"{limb.name} (P-R-S): circle about the slider = sphere and plane, moving with the slide"
    if types == ["U", "P", "U"]:
        ub, pj, ua = limb.joints
        sl = pj.freedoms[0]
        if not sl.actuated or id(sl) not in act_index:
            return f"limb {limb.name}: its slide is not the actuator", [], ""
        for j in (ub, ua):
            if np.linalg.norm(j.freedoms[0].point - j.freedoms[1].point) > tol * L:
                return f"limb {limb.name}: the axes of {j.name} do not meet", [], ""
        a, b = ub.point, ua.point
        w = b - a
        d_ref = float(np.linalg.norm(w))
        if d_ref < tol * L or abs(abs(float(_unit(w) @ _unit(sl.direction))) - 1) > tol:
            return f"limb {limb.name}: the slide does not run along the line of its two centres", [], ""
        w = w / d_ref
        n1, m = _unit(ub.freedoms[0].direction), _unit(ub.freedoms[1].direction)
        m2, n_p = _unit(ua.freedoms[0].direction), _unit(ua.freedoms[1].direction)
        if (abs(m @ n1) > tol or abs(m @ w) > tol or np.linalg.norm(np.cross(m, m2)) > tol or abs(n_p @ m2) > tol):
            return (f"limb {limb.name}: U-P-U with the two middle axes parallel, normal to the leg and to the outer "
                    "axes is covered; this one is not"), [], ""
        k = act_index[id(sl)]
        sign = float(np.sign(w @ sl.direction))
        upu = _upu_quadric(b, a, n1, n_p, L)

        def upu_rows(v, k=k, a=a, b=b, d_ref=d_ref, sign=sign, off=sl.offset, upu=upu):
            return [_sphere_quadric(b, a, d_ref + sign * (v[k] - off), L), upu]

        return None, [upu_rows], f"{limb.name} (U-P-U): leg sphere and the U-joint condition n1 . ((u - a) x R n_p) = 0"
    if len(types) == 3 and types[1] == "P" and set(types[::2]) <= {"S", "U"} and types != ["U", "P", "U"]:
        sl = _slide(limb, 1)
        if not sl.actuated or id(sl) not in act_index:
            return f"limb {limb.name}: its slide is not the actuator", [], ""
        a, b = limb.joints[0].point, limb.joints[2].point
        w = b - a
        d_ref = float(np.linalg.norm(w))
        if d_ref < tol * L or abs(abs(float(_unit(w) @ _unit(sl.direction))) - 1) > tol:
            return f"limb {limb.name}: the slide does not run along the line of its two centres", [], ""
        k = act_index[id(sl)]
        sign = float(np.sign(w @ sl.direction))

        def sps(v, k=k, a=a, b=b, d_ref=d_ref, sign=sign, off=sl.offset):
            return [_sphere_quadric(b, a, d_ref + sign * (v[k] - off), L)]

        return None, [sps], f"{limb.name} ({'-'.join(types)}): leg sphere"
    pol = _point_on_line(limb, L)
    if pol is not None:
        u, o, normals = pol
        qs = [_plane_quadric(u, o, n, L) for n in normals]
        return None, [lambda v, qs=qs: qs], f"{limb.name} ({'-'.join(types)}): centre on the C axis (two planes)"
    rps = _rps_plane(limb, L)
    if rps is not None:
        u, o, (n,) = rps
        sl = _slide(limb, 1)
        k = act_index[id(sl)]
        d = u - o
        d_ref = float(np.linalg.norm(d))
        sign = float(np.sign(d @ sl.direction))
        pq = _plane_quadric(u, o, n, L)

        def rps_rows(v, k=k, u=u, o=o, d_ref=d_ref, sign=sign, off=sl.offset, pq=pq):
            return [_sphere_quadric(u, o, d_ref + sign * (v[k] - off), L), pq]

        return None, [rps_rows], f"{limb.name} (R-P-S): leg sphere and the plane normal to the R axis"
    return (f"limb {limb.name} is {'-'.join(types)} (covered: S-P-S, U-P-S, S-P-U, U-P-U, R-P-S and P-R-S legs, "
            "C-U / C-S limbs with the centre on the C axis, S-S / S-U / U-S rods and U-U rods of the U-P-U's layout "
            "after actuated joints or from a body driven by actuated joints only)"), [], ""


def _general(mech: Mechanism) -> tuple[str | None, PoseSystem | None]:
    """(why not, system) of the general reduction (see :func:`pose_system`)."""
    from ..closure import limb_forward, limb_slices, reference_screws

    L = float(mech.characteristic_length)
    acts = [mech.freedom(a) for a in mech.actuators]
    act_index = {id(r.freedom): k for k, r in enumerate(acts)}
    refs = mech.freedom_refs
    screws = reference_screws(mech)
    hubs: dict = {}
    used: set = set()
    limbs = list(zip(mech.limbs, limb_slices(mech), strict=True))
    for limb, sl in limbs:
        if limb.tip is None:
            continue
        frs = refs[sl]
        if limb.base != "ground" or not all(r.freedom.actuated for r in frs) or limb.tip in hubs:
            return (f"limb {limb.name} ends on body {limb.tip}: only bodies driven from the ground by actuated joints "
                    "alone are covered"), None
        ks = [act_index[id(r.freedom)] for r in frs]
        offs = np.array([r.freedom.offset for r in frs])
        S = screws[sl]
        hubs[limb.tip] = lambda v, ks=ks, offs=offs, S=S: limb_forward(S, np.asarray(v)[ks] - offs)[0]
        used.update(ks)
    builders, notes = [], []
    for limb, _ in limbs:
        if limb.tip is not None:
            continue
        why, bs, note = _reduce_limb(limb, L, act_index, hubs)
        if why is not None:
            return why, None
        builders += bs
        notes.append(note)
        for j in limb.joints:
            for f in j.freedoms:
                if f.actuated and id(f) in act_index:
                    used.add(act_index[id(f)])
    if used != set(range(len(acts))):
        return "actuators other than the covered leg slides and driving joints", None
    ref = np.array([r.freedom.offset for r in acts], dtype=float)
    n_eq = sum(len(b(ref)) for b in builders)
    if n_eq != 6:
        return f"its limbs give {n_eq} equations on the platform pose, not 6", None
    scales = np.array([0.3 * L if r.freedom.kind == "P" else 0.5 for r in acts])

    def rows(v, builders=tuple(builders)):
        return [q for b in builders for q in b(v)]

    return None, PoseSystem(mech.name, L, len(acts), rows, ref, scales, tuple(notes))


def pose_system(mech: Mechanism) -> StewartSystem | PoseSystem:
    """The polynomial system of ``mech``: :func:`stewart_system` for S-P-S / R-P-S legs and C-U /
    C-S limbs, else the general reduction (each limb, with the actuators given, to conditions on
    the platform point it carries: a sphere about a point fixed by the actuators, a plane, a
    line, the U-P-U condition) when it covers the model; ``InputError`` naming why not."""
    if _stewart_reason(mech) is None:
        return stewart_system(mech)
    if mech in _SYSTEMS:  # its affine span computed once per model object
        return _SYSTEMS[mech]
    why, sysm = _general(mech)
    if sysm is None:
        raise InputError(f"model: homotopy forward position does not cover {mech.name}: {why}; use method='multistart'")
    _SYSTEMS[mech] = sysm
    return sysm


_SYSTEMS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def geometry_family(base, platform, lengths=None) -> PoseSystem:
    """A 6-6 Stewart platform whose *geometry* is the parameter vector: 42 values (the base
    centres, the platform centres (reference placement), the leg lengths, model units; the
    given ones the reference).  Its affine span holds every 6-6 platform, so one generic solve
    serves every geometry and a new geometry is a parameter-homotopy re-solve (the search for
    many real solutions in benchmarks/bench_all_real.py)."""
    a0 = np.asarray(base, dtype=float).reshape(6, 3)
    b0 = np.asarray(platform, dtype=float).reshape(6, 3)
    l0 = np.linalg.norm(b0 - a0, axis=1) if lengths is None else np.asarray(lengths, dtype=float).reshape(6)
    pts = np.vstack([a0, b0])
    L = float(np.sqrt(np.mean(np.sum((pts - pts.mean(axis=0)) ** 2, axis=1))))

    def rows(v):
        a, b, r = v[:18].reshape(6, 3), v[18:36].reshape(6, 3), v[36:]
        return [_sphere_quadric(b[i], a[i], r[i], L) for i in range(6)]

    ref = np.r_[a0.ravel(), b0.ravel(), l0]
    return PoseSystem("6-6 geometry family", L, 42, rows, ref, np.full(42, 0.3 * L), ("six legs, geometry free",))
