"""Every assembly mode of a platform by homotopy continuation: Stewart platforms (S-P-S, U-P-S,
S-P-U legs), R-P-S, P-R-S and U-P-U legs, passive C-U / C-S limbs, and S-S rods from bodies
driven by actuated joints alone (the Delta).

Formulation.  The platform displacement is written in Study parameters ``x = (e ; g)`` (two
quaternions, projective): rotation ``R v = e v e* / (e.e)``, translation ``p = 2 g e* / (e.e)``.
With the actuator values given, each limb is a set of conditions on the platform point ``b``
it carries (reference placement, model units over the characteristic length ``L``), each one
homogeneous quadric in ``x``; with ``v = e b - c e + 2 g``:

    sphere about c, radius r:   |v|^2 - (r / L)^2 (e.e) = 0     (legs, S-S rods, P-R-S)
    plane through c, normal n:  n . vec(v e*) = 0                (R-P-S, P-R-S; two: a line, C-U)
    U-P-U:                      n1 . vec(v n_p e*) = 0           (with c the base U centre)

(:class:`StewartSystem` for legs and point-on-line limbs with fixed centres, :class:`PoseSystem`
for the general reduction, whose centres and radii depend on the actuators).  With the Study
quadric ``e.g = 0`` and a random complex affine patch ``c.x = 1`` this is a square system of 7
quadrics and 1 linear equation in 8 unknowns (Bezout number 128).  Points with ``e.e = 0`` are
the exceptional generator of the Study quadric: translation at infinity, never a pose.

Method.  (1) A total-degree homotopy ``(1 - t) gamma G + t F`` (``G_j = x_j^2 - x_7^2``, 128
start points, random complex ``gamma``) to a generic complex instance: a random complex point
of the affine span of the coefficient tensors over all actuator values (computed once per
geometry; cached in memory with the solve): every path must end either at a finite
nonsingular point or at the exceptional set, or the run is repeated with other random numbers;
by the gamma trick every isolated solution of the generic instance is the end of a path, so the
finite nonsingular end points are all of them (40 for a general 6-6 geometry).  (2) A parameter
homotopy along the straight segment in that (linear) coefficient space from the generic
instance to the requested one tracks exactly those paths: every isolated solution of the
request is the end of one of them (the segment from a generic complex point avoids the
discriminant before its end).

The tracker is vectorised over paths in NumPy: 4th-order Runge-Kutta predictor on the
Davidenko equation, Newton corrector with a path-jumping guard (the first update must be small
and the second must contract), step halved on rejection and grown on acceptance.  End game:
a path that cannot reach ``t = 1`` (its step falls below ``1e-14``) is classified at its last
point: at infinity when ``|e.e| / |x|^2`` is small (the platform escapes), else singular. End
points are classified by the inverse condition number of the row-normalised Jacobian
(singular), ``|e.e| / |x|^2`` (at infinity) and the size of the imaginary part after removing
the projective phase (real).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from ..geometry.tolerances import (
    HOMOTOPY_INFINITY,
    HOMOTOPY_JUMP,
    HOMOTOPY_NEAR_REAL,
    HOMOTOPY_NEWTON,
    HOMOTOPY_REAL,
    HOMOTOPY_SINGULAR,
)
from ..model.mechanism import Mechanism
from . import compiled
from .jit import njit

__all__ = [
    "HomotopyResult",
    "HomotopySolution",
    "PoseSystem",
    "StewartSystem",
    "clear_cache",
    "homotopy_forward",
    "phc_input",
    "pose_system",
    "stewart_system",
    "study_to_pose",
    "system_from_points",
    "track",
    "track_parameter",
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


def _qmul(q, r):
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
                M[i, j] = n @ _qmul(K[:, i], conj[:, j])[1:]
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
    return _bilinear_e(K, lambda v, ec: float(n1 @ _qmul(_qmul(v, npq), ec)[1:]))


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
    rows: object = field(repr=False)  # callable values -> list of six (8, 8)
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


def _reduce_limb(limb, L: float, act_index: dict, hubs: dict) -> tuple[str | None, list, str]:
    """(why not, constraint builders ``values -> [quadrics]``, description) of one limb to the
    platform."""
    types = [j.type for j in limb.joints]
    tol = 1e-9
    if limb.base != "ground":
        if limb.base not in hubs:
            return f"limb {limb.name} starts on body {limb.base}, whose pose the actuators do not fix", [], ""
        if types != ["S", "S"]:
            return (f"limb {limb.name} from body {limb.base} is {'-'.join(types)} (from a driven body the "
                    "formulation covers S-S rods)"), [], ""
        hub = hubs[limb.base]
        a, b = limb.joints[0].point, limb.joints[1].point
        r = float(np.linalg.norm(b - a))

        def rod(v, hub=hub, a=a, b=b, r=r):
            D = hub(v)
            return [_sphere_quadric(b, D[:3, :3] @ a + D[:3, 3], r, L)]

        return None, [rod], f"{limb.name} (S-S from driven {limb.base}): sphere about a moving centre"
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
            "C-U / C-S limbs with the centre on the C axis, and S-S rods from a body driven by actuated joints only)"), [], ""


def _general(mech: Mechanism) -> tuple[str | None, PoseSystem | None]:
    """(why not, system) of the general reduction (see :func:`pose_system`)."""
    from .closure import limb_forward, limb_slices, reference_screws

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
    why, sysm = _general(mech)
    if sysm is None:
        raise InputError(f"model: homotopy forward position does not cover {mech.name}: {why}; use method='multistart'")
    return sysm


# ------------------------------------------------------------------------------ evaluation
def _eval_quad(Qc: np.ndarray, c: np.ndarray, X: np.ndarray):
    """F and its Jacobian for points ``X`` (n, 8): the seven quadrics ``Qc`` ((7, 8, 8), or
    (n, 7, 8, 8) one set per point) and the patch ``c . x = 1``; and ``e.e``."""
    QX = np.einsum("kij,nj->nki", Qc, X) if Qc.ndim == 3 else np.einsum("nkij,nj->nki", Qc, X)  # (n, 7, 8)
    F = np.empty((len(X), _N), dtype=complex)
    J = np.empty((len(X), _N, _N), dtype=complex)
    F[:, :7] = np.einsum("nki,ni->nk", QX, X)
    E = np.einsum("ni,ni->n", X[:, :4], X[:, :4])
    J[:, :7] = 2 * QX
    F[:, 7] = X @ c - 1
    J[:, 7] = c
    return F, J, E


def track(fun, X0: np.ndarray, *, h0: float = 0.02, hmin: float = 1e-14, max_steps: int = 4000):
    """Track the paths ``H(x, t) = 0`` from ``t = 0`` (points ``X0``, (n, m)) to ``t = 1``.

    ``fun(X, t)`` (``t``: (n,)) returns ``H`` (n, m), ``H_x`` (n, m, m) and ``H_t`` (n, m).
    Returns ``(X, t, ok, steps)``: the end points, the ``t`` reached, whether ``t = 1`` was
    reached with a converged corrector, and the accepted steps per path."""
    X = np.array(X0, dtype=complex)
    n = len(X)
    t = np.zeros(n)
    h = np.full(n, h0)
    done = np.zeros(n, bool)
    failed = np.zeros(n, bool)
    steps = np.zeros(n, int)
    good = np.zeros(n, int)

    def vel(x, tt):
        _, Hx, Ht = fun(x, tt)
        return -np.linalg.solve(Hx, Ht[..., None])[..., 0]

    for _ in range(max_steps):
        idx = np.flatnonzero(~done & ~failed)
        if idx.size == 0:
            break
        x, tt = X[idx], t[idx]
        hh = np.minimum(h[idx], 1.0 - tt)
        with np.errstate(all="ignore"):
            try:
                k1 = vel(x, tt)
                k2 = vel(x + 0.5 * hh[:, None] * k1, tt + 0.5 * hh)
                k3 = vel(x + 0.5 * hh[:, None] * k2, tt + 0.5 * hh)
                k4 = vel(x + hh[:, None] * k3, tt + hh)
                xc = x + hh[:, None] / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
                tn = tt + hh
                nx = 1 + np.linalg.norm(xc, axis=1)
                H, Hx, _ = fun(xc, tn)
                dx = np.linalg.solve(Hx, H[..., None])[..., 0]
                d0 = np.linalg.norm(dx, axis=1) / nx
                xc = xc - dx
                H, Hx, _ = fun(xc, tn)
                dx = np.linalg.solve(Hx, H[..., None])[..., 0]
                d1 = np.linalg.norm(dx, axis=1) / nx
                xc = xc - dx
            except np.linalg.LinAlgError:  # a singular Jacobian in the batch: go path by path
                ok = np.zeros(idx.size, bool)
                h[idx] *= 0.5
                failed[idx[h[idx] < hmin]] = True
                continue
            ok = np.isfinite(d0) & np.isfinite(d1) & (d0 < HOMOTOPY_JUMP) & ((d1 < 0.1 * d0) | (d1 < HOMOTOPY_NEWTON))
        acc = idx[ok]
        X[acc] = xc[ok]
        t[acc] = tn[ok]
        steps[acc] += 1
        good[acc] += 1
        h[acc] = np.where(good[acc] >= 2, 2.0 * h[acc], h[acc])
        good[acc] = np.where(good[acc] >= 2, 0, good[acc])
        rej = idx[~ok]
        h[rej] *= 0.5
        good[rej] = 0
        done[acc[t[acc] >= 1.0]] = True
        failed[rej[h[rej] < hmin]] = True
    return X, t, done, steps


# ------------------------------------------------------------------------------ compiled parameter homotopy
@njit(cache=True)
def _lu_solve(A, b, out):
    """``A x = b`` (complex, small) by LU with partial pivoting into ``out``; False when a pivot
    is zero or not finite (the batched NumPy tracker's LinAlgError)."""
    n = A.shape[0]
    M = A.copy()
    y = b.copy()
    for k in range(n):
        p = k
        big = abs(M[k, k])
        for i in range(k + 1, n):
            if abs(M[i, k]) > big:
                big = abs(M[i, k])
                p = i
        if not big > 0.0 or not np.isfinite(big):
            return False
        if p != k:
            for j in range(n):
                M[k, j], M[p, j] = M[p, j], M[k, j]
            y[k], y[p] = y[p], y[k]
        for i in range(k + 1, n):
            f = M[i, k] / M[k, k]
            for j in range(k, n):
                M[i, j] -= f * M[k, j]
            y[i] -= f * y[k]
    for i in range(n - 1, -1, -1):
        acc = y[i]
        for j in range(i + 1, n):
            acc -= M[i, j] * out[j]
        out[i] = acc / M[i, i]
    return True


@njit(cache=True)
def _param_system(Q0, dQ, c, x, t, F, J, Ht):
    """:func:`_eval_quad` of one point on the straight coefficient path ``Q0 + t dQ`` and ``H_t``."""
    n = x.shape[0]
    for k in range(7):
        acc = 0.0j
        acct = 0.0j
        for i in range(n):
            qx = 0.0j
            dx = 0.0j
            for j in range(n):
                qx += (Q0[k, i, j] + t * dQ[k, i, j]) * x[j]
                dx += dQ[k, i, j] * x[j]
            J[k, i] = 2.0 * qx
            acc += qx * x[i]
            acct += dx * x[i]
        F[k] = acc
        Ht[k] = acct
    acc = -1.0 + 0.0j
    for i in range(n):
        acc += x[i] * c[i]
        J[7, i] = c[i]
    F[7] = acc
    Ht[7] = 0.0


@njit(cache=True)
def _param_vel(Q0, dQ, c, x, t, F, J, Ht, out):
    ok = True
    _param_system(Q0, dQ, c, x, t, F, J, Ht)
    for i in range(Ht.shape[0]):
        Ht[i] = -Ht[i]
    ok = _lu_solve(J, Ht, out)
    return ok


@njit(cache=True)
def _track_param(Q0, dQ, c, X0, h0, hmin, max_steps, jump, newton, X, T, done):
    """:func:`track` of the parameter homotopy, path by path (compiled): the same RK4 predictor,
    two Newton corrections, acceptance test and step control."""
    n = X0.shape[1]
    F = np.empty(n, dtype=np.complex128)
    J = np.empty((n, n), dtype=np.complex128)
    Ht = np.empty(n, dtype=np.complex128)
    k1 = np.empty(n, dtype=np.complex128)
    k2 = np.empty(n, dtype=np.complex128)
    k3 = np.empty(n, dtype=np.complex128)
    k4 = np.empty(n, dtype=np.complex128)
    xs = np.empty(n, dtype=np.complex128)
    xc = np.empty(n, dtype=np.complex128)
    dx = np.empty(n, dtype=np.complex128)
    for p in range(X0.shape[0]):
        x = X[p]
        for i in range(n):
            x[i] = X0[p, i]
        t = 0.0
        h = h0
        good = 0
        fin = False
        for _ in range(max_steps):
            hh = min(h, 1.0 - t)
            ok = _param_vel(Q0, dQ, c, x, t, F, J, Ht, k1)
            if ok:
                for i in range(n):
                    xs[i] = x[i] + 0.5 * hh * k1[i]
                ok = _param_vel(Q0, dQ, c, xs, t + 0.5 * hh, F, J, Ht, k2)
            if ok:
                for i in range(n):
                    xs[i] = x[i] + 0.5 * hh * k2[i]
                ok = _param_vel(Q0, dQ, c, xs, t + 0.5 * hh, F, J, Ht, k3)
            if ok:
                for i in range(n):
                    xs[i] = x[i] + hh * k3[i]
                ok = _param_vel(Q0, dQ, c, xs, t + hh, F, J, Ht, k4)
            d0 = np.inf
            d1 = np.inf
            tn = t + hh
            if ok:
                nx = 0.0
                for i in range(n):
                    xc[i] = x[i] + hh / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
                    nx += abs(xc[i]) ** 2
                nx = 1.0 + np.sqrt(nx)
                _param_system(Q0, dQ, c, xc, tn, F, J, Ht)
                ok = _lu_solve(J, F, dx)
                if ok:
                    s0 = 0.0
                    for i in range(n):
                        s0 += abs(dx[i]) ** 2
                        xc[i] -= dx[i]
                    d0 = np.sqrt(s0) / nx
                    _param_system(Q0, dQ, c, xc, tn, F, J, Ht)
                    ok = _lu_solve(J, F, dx)
                if ok:
                    s1 = 0.0
                    for i in range(n):
                        s1 += abs(dx[i]) ** 2
                        xc[i] -= dx[i]
                    d1 = np.sqrt(s1) / nx
            acc = ok and np.isfinite(d0) and np.isfinite(d1) and d0 < jump and (d1 < 0.1 * d0 or d1 < newton)
            if acc:
                for i in range(n):
                    x[i] = xc[i]
                t = tn
                good += 1
                if good >= 2:
                    h *= 2.0
                    good = 0
                if t >= 1.0:
                    fin = True
                    break
            else:
                h *= 0.5
                good = 0
                if h < hmin:
                    break
        T[p] = t
        done[p] = fin


def track_parameter(Q0: np.ndarray, Q1: np.ndarray, c: np.ndarray, X0: np.ndarray, *,
                    h0: float = 0.02, hmin: float = 1e-14, max_steps: int = 4000):
    """The parameter homotopy from the quadrics ``Q0`` (7, 8, 8; points ``X0``) to ``Q1`` along
    the straight segment in the coefficient space: :func:`track`, compiled and path by path when
    the compiled core is in use (the batched NumPy :func:`track` otherwise).  Returns
    ``(X, t, done)``."""
    X0 = np.ascontiguousarray(X0, dtype=complex)
    Q0 = np.ascontiguousarray(Q0, dtype=complex)
    dQ = np.ascontiguousarray(np.asarray(Q1, dtype=complex) - Q0)
    if compiled.enabled():
        X = np.empty_like(X0)
        T = np.zeros(len(X0))
        done = np.zeros(len(X0), dtype=np.bool_)
        if len(X0):
            _track_param(Q0, dQ, np.ascontiguousarray(c, dtype=complex), X0,
                         float(h0), float(hmin), int(max_steps), float(HOMOTOPY_JUMP), float(HOMOTOPY_NEWTON),
                         X, T, done)
        return X, T, done

    def fun(X, t):
        F, J, _ = _eval_quad(Q0[None] + t[:, None, None, None] * dQ[None], c, X)
        Ht = np.zeros_like(F)
        Ht[:, :7] = np.einsum("ni,kij,nj->nk", X, dQ, X)
        return F, J, Ht

    X, T, done, _ = track(fun, X0, h0=h0, hmin=hmin, max_steps=max_steps)
    return X, T, done


def _refine(Qc, c, X, iters: int = 4):
    """Newton at ``t = 1`` (batched; a point whose step fails keeps its last value)."""
    X = X.copy()
    with np.errstate(all="ignore"):
        for _ in range(iters):
            F, J, _ = _eval_quad(Qc, c, X)
            ok = np.all(np.isfinite(J), axis=(1, 2)) & np.all(np.isfinite(F), axis=1)
            ok &= np.abs(np.linalg.det(np.where(ok[:, None, None], J, np.eye(_N)))) > 0
            if not ok.any():
                break
            dx = np.linalg.solve(J[ok], F[ok][..., None])[..., 0]
            Xn = X[ok] - dx
            fin = np.all(np.isfinite(Xn), axis=1)
            X[np.flatnonzero(ok)[fin]] = Xn[fin]
        F, J, E = _eval_quad(Qc, c, X)
    return X, F, J, E


def _classify(Qc, c, X):
    """Status of each end point: (status, rcond, rel_inf, imag_rel, residual, y, x refined),
    ``y`` the point with its projective phase removed, ``x`` in the affine patch."""
    if len(X) == 0:
        return []
    xr, F, J, E = _refine(Qc, c, X)
    out = []
    with np.errstate(all="ignore"):
        nx = np.linalg.norm(xr, axis=1)
        rows = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
        finite = np.all(np.isfinite(rows), axis=(1, 2))
        sv = np.linalg.svd(np.where(finite[:, None, None], rows, np.eye(_N)), compute_uv=False)
    for n in range(len(X)):
        x = xr[n]
        rel_inf = float(abs(E[n])) / nx[n] ** 2 if nx[n] > 0 and np.isfinite(nx[n]) else 0.0
        rcond = float(sv[n, -1] / sv[n, 0]) if finite[n] else 0.0
        k = int(np.argmax(np.abs(x)))
        y = x * (abs(x[k]) / x[k]) if x[k] != 0 else x
        imag = float(np.linalg.norm(y.imag) / max(float(np.linalg.norm(y)), 1e-300))
        res = float(np.linalg.norm(F[n, :7]) / max(nx[n] ** 2, 1e-300))
        if not np.isfinite(nx[n]) or rel_inf < HOMOTOPY_INFINITY:
            st = "at_infinity"
        elif rcond < HOMOTOPY_SINGULAR:
            st = "singular"
        elif imag < HOMOTOPY_REAL:
            st = "real"
        else:
            st = "complex"
        out.append((st, rcond, rel_inf, imag, res, y, x))
    return out


def study_to_pose(x, L: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Rotation and translation (model units, ``L`` the length scale) of real Study parameters."""
    x = np.real(np.asarray(x))
    e, g = x[:4], x[4:]
    E = float(e @ e)
    q = e / np.sqrt(E)
    w, i, j, k = q
    R = np.array([[1 - 2 * (j * j + k * k), 2 * (i * j - w * k), 2 * (i * k + w * j)],
                  [2 * (i * j + w * k), 1 - 2 * (i * i + k * k), 2 * (j * k - w * i)],
                  [2 * (i * k - w * j), 2 * (j * k + w * i), 1 - 2 * (i * i + j * j)]])
    p = 2 * _qmul(g, e * np.array([1, -1, -1, -1]))[1:] / E * L
    return R, p


# ------------------------------------------------------------------------------ generic instance
@dataclass(frozen=True, eq=False)
class _Generic:
    c: np.ndarray
    Q: np.ndarray  # (7, 8, 8) complex: the generic instance's quadrics
    X: np.ndarray  # (N, 8) the isolated solutions
    n_paths: int
    n_at_infinity: int
    attempts: int
    seconds: float


_CACHE: dict[bytes, _Generic] = {}


def clear_cache() -> None:
    """Forget every cached generic solve (the next solve of each geometry starts from the
    total-degree homotopy again; benchmarks time that first solve)."""
    _CACHE.clear()


def phc_input(sysm: StewartSystem | PoseSystem, values, c) -> str:
    """The system of ``sysm`` at actuator ``values`` (model units, radians), with the affine
    normalisation ``c . x = 1`` (8 coefficients), in PHCpack's input format: for an independent
    solve by ``phc -b`` (tests, benchmarks/bench_homotopy.py)."""
    names = ["e0", "e1", "e2", "e3", "g0", "g1", "g2", "g3"]
    Qv = sysm.coefficients(np.asarray(values, dtype=float))

    def quad(M):
        return " ".join(f"{(M[i, j] if i == j else M[i, j] + M[j, i]):+.17e}*{names[i]}*{names[j]}"
                        for i in range(8) for j in range(i, 8)) + ";"

    eqs = [quad(Qv[k]) for k in range(7)]
    eqs.append(" ".join(f"{c[i]:+.17e}*{names[i]}" for i in range(8)) + " - 1;")
    return "8\n" + "\n".join(eqs) + "\n"


def _generic_solve(sysm: StewartSystem | PoseSystem, seed: int = 0, max_attempts: int = 3) -> tuple[_Generic, bool]:
    """Total-degree homotopy to a generic complex instance of the family (a random complex point
    of the affine span of its coefficient tensors); (result, every path accounted for)."""
    key = sysm.key()
    if key in _CACHE:
        return _CACHE[key], True
    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    Qb, B, scale = sysm.affine_span()
    best = None
    for attempt in range(1, max_attempts + 1):
        c = rng.normal(size=_N) + 1j * rng.normal(size=_N)
        z = scale * (1 + rng.random(len(B))) * np.exp(1j * rng.uniform(-np.pi, np.pi, len(B)))
        Qg = Qb + np.einsum("j,jkab->kab", z, B)
        gamma = np.exp(1j * rng.uniform(0, 2 * np.pi))
        signs = np.array(np.meshgrid(*[[1.0, -1.0]] * 7, indexing="ij")).reshape(7, -1).T  # (128, 7)
        S = np.hstack([signs, np.ones((len(signs), 1))]).astype(complex)
        X0 = S / (S @ c)[:, None]

        def fun(X, t, c=c, gamma=gamma, Qg=Qg):
            F, J, _ = _eval_quad(Qg, c, X)
            G = np.empty_like(F)
            JG = np.zeros_like(J)
            G[:, :7] = X[:, :7] ** 2 - X[:, 7:8] ** 2
            idx = np.arange(7)
            JG[:, idx, idx] = 2 * X[:, :7]
            JG[:, :7, 7] = -2 * X[:, 7:8]
            s = t[:, None]
            H = (1 - s) * gamma * G + s * F
            H[:, 7] = F[:, 7]
            Hx = (1 - s[..., None]) * gamma * JG + s[..., None] * J
            Hx[:, 7] = J[:, 7]
            Ht = F - gamma * G
            Ht[:, 7] = 0
            return H, Hx, Ht

        X, _, _, _ = track(fun, X0)
        cls = _classify(Qg, c, X)
        fin = [i for i, r in enumerate(cls) if r[0] in ("real", "complex")]
        inf = [i for i, r in enumerate(cls) if r[0] == "at_infinity"]
        pts = np.array([cls[i][6] for i in fin]).reshape(-1, _N)
        distinct = _distinct(pts)
        accounted = len(fin) + len(inf) == len(X) and distinct
        g = _Generic(c, Qg, pts, len(X), len(inf), attempt, time.perf_counter() - t0)
        if accounted:
            _CACHE[key] = g
            return g, True
        if best is None or len(fin) > len(best.X):
            best = g
    assert best is not None
    return best, False


def _distinct(P: np.ndarray) -> bool:
    if len(P) < 2:
        return True
    Pn = P / np.linalg.norm(P, axis=1, keepdims=True)
    G = np.abs(Pn.conj() @ Pn.T)
    np.fill_diagonal(G, 0)
    return bool(np.all(G < 1 - 1e-8))


# ------------------------------------------------------------------------------ results
@dataclass(frozen=True, eq=False)
class HomotopySolution:
    """One end point: ``status`` real / complex / singular / at_infinity, the Study parameters
    (projective, phase removed), the inverse condition number of the row-normalised Jacobian,
    ``|e.e| / |x|^2``, the relative residual and, for a real end point, the displacement."""

    status: str
    study: np.ndarray
    rcond: float
    infinity_ratio: float
    imag_ratio: float
    residual: float
    R: np.ndarray | None = None
    p: np.ndarray | None = None

    def to_dict(self) -> dict:
        return {"status": self.status, "study_parameters_real": [float(v) for v in self.study.real],
                "study_parameters_imag": [float(v) for v in self.study.imag], "inverse_condition": self.rcond,
                "infinity_ratio": self.infinity_ratio, "imaginary_ratio": self.imag_ratio, "residual": self.residual}


@dataclass(frozen=True, eq=False)
class HomotopyResult:
    solutions: tuple[HomotopySolution, ...]
    complete: bool
    completeness: str
    n_generic: int
    n_paths_total_degree: int
    seconds_generic: float
    seconds: float
    cached: bool

    def count(self, status: str) -> int:
        return sum(s.status == status for s in self.solutions)


def homotopy_forward(mech: Mechanism | StewartSystem | PoseSystem, actuator_values, *, seed: int = 0) -> HomotopyResult:
    """Every complex solution of the forward position of a platform for actuator values (model
    units and radians, in ``mech.actuators`` order): see the module docstring."""
    t0 = time.perf_counter()
    sysm = mech if isinstance(mech, (StewartSystem, PoseSystem)) else pose_system(mech)
    vals = np.asarray(actuator_values, dtype=float).ravel()
    if vals.shape != (sysm.n_act,) or not np.all(np.isfinite(vals)):
        raise InputError(f"actuators: expected {sysm.n_act} finite values, got {vals.tolist()}")
    cached = sysm.key() in _CACHE
    gen, accounted = _generic_solve(sysm, seed=seed)
    Qt = sysm.coefficients(vals)
    c = gen.c
    X = track_parameter(gen.Q, Qt, c, gen.X)[0] if len(gen.X) else gen.X
    sols = []
    for st, rc, ri, im, res, y, _ in _classify(Qt, c, X):
        R = p = None
        if (st == "real" or (st == "singular" and im < HOMOTOPY_NEAR_REAL)) and ri >= HOMOTOPY_INFINITY:
            R, p = study_to_pose(y / np.linalg.norm(y), sysm.L)
        sols.append(HomotopySolution(st, y, rc, ri, im, res, R, p))
    n_par = len(sysm.affine_span()[1])
    how = (f"total-degree homotopy ({gen.n_paths} paths, gamma trick) to a generic complex instance: every path "
           f"accounted for ({len(gen.X)} finite nonsingular, {gen.n_at_infinity} at the exceptional generator e.e = 0); "
           f"parameter homotopy of those {len(gen.X)} paths to the requested actuator values (straight segment in the "
           f"{n_par}-dimensional affine span of the coefficients)")
    n_sing = sum(s.status == "singular" for s in sols)
    if accounted and n_sing:
        how += (f"; but {n_sing} end point(s) are singular (a continuum of solutions or a multiple root at these values, "
                "located to a few digits only): not proven complete there; real points near them polished, the multi-start "
                "roots added, and a continuum reported as one self-motion set")
    if not accounted:
        how = (f"NOT complete: {gen.n_paths - len(gen.X) - gen.n_at_infinity} of the {gen.n_paths} total-degree paths "
               f"ended neither at a finite nonsingular point nor at infinity after {gen.attempts} attempts")
    return HomotopyResult(tuple(sols), accounted and not n_sing, how, len(gen.X), gen.n_paths, gen.seconds,
                          time.perf_counter() - t0, cached)
