"""Forward position of a 5-CS guidance linkage (paper A): the coupler carried by five C-S dyads,
one C joint's rotation driven; every assembly configuration, proven complete.

Recognised from the mechanism itself (:func:`recognise`): five limbs from the ground to the
coupler, each a C joint (none locked, no pitch) then an S joint, exactly one actuator: the
rotation of one C joint.

Elimination of the passive joints.  Dyad ``i`` (C axis through ``c_i`` along the unit ``u_i``, S
centre at ``s_i`` at the reference) holds the S centre ``R s_i + t`` on the cylinder of radius
``r_i = |u_i x (s_i - c_i)|`` about its axis.  With the driven dyad's rotation ``theta`` given, its
S centre is on a line, ``g + sigma u_a`` (``g = c_a + Rot(u_a, theta) (s_a - c_a)``, ``sigma`` its
slide), so ``t = g + sigma u_a - R s_a``: the unknowns are the coupler's rotation ``R`` and
``sigma``, and each other dyad gives one equation, with ``w_i = R (s_i - s_a) + g - c_i + sigma u_a``,

    |w_i|^2 - (u_i . w_i)^2 - r_i^2 = 0,

of degree 2 in the entries of ``R`` and ``sigma`` together: four quadrics on ``SO(3) x C``
(lengths over the characteristic length).  ``SO(3)`` is a variety of degree 8 in the 9 entries,
so there are at most ``8 x 2^4 = 128`` isolated solutions (Bezout on a variety).

Homotopy on the variety.  The unknowns are the 9 entries and ``sigma``; ``R^T R = I`` (6
quadrics, constant along the homotopy: every path stays on ``SO(3) x C``) and
``(1 - t) gamma G + t F`` for the four equations, ``G_i`` a product of two random complex affine
forms (a linear-product start system).  Its start points: for each of the 16 choices of one
form per equation, four affine equations on ``SO(3) x C``; the first gives ``sigma``, the other
three are linear in ``R``, three quadrics in its quaternion (8 rotations,
:func:`.projective_quadrics.solve_projective_quadrics`): 128 start points, computed once per
process (they do not depend on the mechanism).  With the gamma trick every isolated solution of
the request is the end of a path.  Completeness: every one of the 128 paths ends at a finite
nonsingular point or diverges (a solution at infinity: no configuration); a path ending at a
singular point (a multiple root, or a continuum: a singular input) leaves the set unproven, and
the answer says so.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from itertools import product

import numpy as np

from ...errors import InputError
from ...geometry.tolerances import HOMOTOPY_NEAR_REAL, HOMOTOPY_REAL, HOMOTOPY_SINGULAR, MONODROMY_DIVERGED
from ...model.mechanism import Mechanism
from ..homotopy.study import track
from .projective_quadrics import solve_projective_quadrics
from .spherical_rrr_forward import matrix_quadric, quaternion_rotation

__all__ = ["CsLinkage", "clear_cache", "homogeneous_quadrics", "linkage_of", "recognise", "solve", "solve_rotations"]

_N = 10  # unknowns: the 9 entries of R (row-major), sigma
_IU = np.triu_indices(3)


@dataclass(frozen=True)
class CsLinkage:
    """The geometry read from a 5-CS linkage, nondimensional (lengths over ``L``): per dyad the
    C axis point ``c`` and unit direction ``u`` (rows), the S centre ``s`` at the reference and the
    radius ``r``; ``driven`` the dyad whose rotation is actuated, its ``offset``."""

    c: np.ndarray
    u: np.ndarray
    s: np.ndarray
    r: np.ndarray
    driven: int
    offset: float
    L: float

    def others(self) -> list[int]:
        return [i for i in range(len(self.c)) if i != self.driven]

    def line(self, theta: float) -> np.ndarray:
        """``g``: the driven S centre at slide 0 for the C rotation ``theta`` (rad)."""
        a = self.driven
        u = self.u[a]
        K = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
        Rot = np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * (K @ K)
        return self.c[a] + Rot @ (self.s[a] - self.c[a])


def linkage_of(mech: Mechanism) -> CsLinkage | None:
    """The :class:`CsLinkage` of ``mech`` when it is a 5-CS linkage with one C rotation driven
    (module docstring), else ``None``."""
    if mech.is_graph or len(mech.limbs) != 5 or len(mech.actuators) != 1:
        return None
    L = mech.characteristic_length
    c, u, s, driven, offset = [], [], [], None, 0.0
    for k, limb in enumerate(mech.limbs):
        if [j.type for j in limb.joints] != ["C", "S"]:
            return None
        C, S = limb.joints
        if any(f.locked for j in limb.joints for f in j.freedoms) or any(f.actuated for f in S.freedoms):
            return None
        rot, slide = C.freedoms
        if slide.actuated:
            return None
        if rot.actuated:
            driven, offset = k, rot.offset
        c.append(np.asarray(rot.point, float) / L)
        u.append(np.asarray(rot.direction, float) / np.linalg.norm(rot.direction))
        s.append(np.asarray(S.point, float) / L)
    if driven is None:
        return None
    cc, uu, ss = np.array(c), np.array(u), np.array(s)
    r = np.linalg.norm(np.cross(uu, ss - cc), axis=1)
    return CsLinkage(cc, uu, ss, r, driven, offset, L)


def driven_slide_note(mech: Mechanism) -> str | None:
    """Why the 5-CS closed form does not answer ``mech`` when it is a 5-CS linkage (five C-S
    dyads, nothing locked) with a C joint's slide driven instead of its rotation, else ``None``.

    The closed form eliminates the driven rotation (four quadrics on ``SO(3) x C``); with the
    slide driven the unknowns are ``SO(3) x S^1`` (the driven C's rotation free), a
    formulation this module does not have."""
    if mech.is_graph or len(mech.limbs) != 5 or len(mech.actuators) != 1:
        return None
    if any([j.type for j in limb.joints] != ["C", "S"] for limb in mech.limbs):
        return None
    if any(f.locked for limb in mech.limbs for j in limb.joints for f in j.freedoms):
        return None
    slides = [limb.joints[0].name for limb in mech.limbs if limb.joints[0].freedoms[1].actuated]
    if not slides:
        return None
    return (f"the 5-CS closed form (4 quadrics on SO(3) x C) covers a driven C rotation only, not the driven "
            f"slide of {slides[0]} (that would be a system on SO(3) x S^1, not formulated)")


# ------------------------------------------------------------------ the system on SO(3) x C
def _orth(X):
    """``R^T R - I`` (upper triangle, 6) and its Jacobian (n, 6, 10)."""
    R = X[:, :9].reshape(-1, 3, 3)
    P = np.einsum("nki,nkj->nij", R, R) - np.eye(3)
    J = np.zeros((len(X), 6, _N), dtype=complex)
    for m, (i, j) in enumerate(zip(*_IU, strict=True)):
        for k in range(3):  # d(R_ki R_kj) / dR_kl
            J[:, m, 3 * k + i] += R[:, k, j]
            J[:, m, 3 * k + j] += R[:, k, i]
    return P[:, _IU[0], _IU[1]], J


def _target(X, D, E, U, ua, r):
    """The four dyad equations at points ``X`` (n, 10) and their Jacobian (n, 4, 10): ``D`` (4, 3)
    the S centres relative to the driven one, ``E`` (4, 3) ``g - c_i``, ``U`` (4, 3) the axes."""
    R = X[:, :9].reshape(-1, 3, 3)
    sig = X[:, 9]
    W = np.einsum("nab,ib->nia", R, D) + E[None] + sig[:, None, None] * ua  # (n, 4, 3)
    uw = np.einsum("nia,ia->ni", W, U)
    F = np.einsum("nia,nia->ni", W, W) - uw ** 2 - r ** 2
    V = 2 * (W - uw[..., None] * U[None])  # dF/dW
    J = np.empty((len(X), 4, _N), dtype=complex)
    J[:, :, :9] = np.einsum("nia,ib->niab", V, D).reshape(len(X), 4, 9)
    J[:, :, 9] = V @ ua
    return F, J


@dataclass(frozen=True, eq=False)
class _Start:
    alpha: np.ndarray  # (4, 2, 10) the affine forms' coefficients
    beta: np.ndarray  # (4, 2)
    X: np.ndarray  # (128, 10) the start points
    complete: bool


_START: dict[int, _Start] = {}


def clear_cache() -> None:
    """Forget the start system's points (the next solve computes them again: benchmarks time
    that first solve)."""
    _START.clear()


def _start_system(seed: int = 0) -> _Start:
    """The linear-product start system and its 128 points on ``SO(3) x C`` (module docstring),
    computed once per seed."""
    if seed in _START:
        return _START[seed]
    rng = np.random.default_rng(1000 + seed)
    alpha = rng.normal(size=(4, 2, _N)) + 1j * rng.normal(size=(4, 2, _N))
    beta = rng.normal(size=(4, 2)) + 1j * rng.normal(size=(4, 2))
    pts, ok = [], True
    for choice in product((0, 1), repeat=4):
        a = np.array([alpha[i, choice[i]] for i in range(4)])
        b = np.array([beta[i, choice[i]] for i in range(4)])
        # sigma from the first form; the other three linear in R: C_k . R = k_k
        Cs = a[1:, :9] - np.outer(a[1:, 9] / a[0, 9], a[0, :9])
        ks = -(b[1:] - a[1:, 9] / a[0, 9] * b[0])
        Q = np.array([matrix_quadric(Cs[k].reshape(3, 3), ks[k]) for k in range(3)])
        sol = solve_projective_quadrics(Q, seed=seed)
        ok &= sol.complete and sol.n_paths == 8
        for y in sol.Y:
            R = quaternion_rotation(y)
            sig = -(a[0, :9] @ R.ravel() + b[0]) / a[0, 9]
            pts.append(np.concatenate([R.ravel(), [sig]]))
    st = _Start(alpha, beta, np.array(pts), bool(ok))
    _START[seed] = st
    return st


def solve_rotations(link: CsLinkage, theta: float, *, seed: int = 0):
    """Every solution ``(R, sigma)`` of the driven rotation ``theta`` (joint angle, rad): the
    homotopy on ``SO(3) x C`` (module docstring).  Returns ``(real, counts, complete, why)``:
    the real solutions (rotation, slide / L), the counts ``(real, complex, singular, at_infinity,
    paths)`` and whether every path is accounted for (``why``: what is not)."""
    out, counts, complete, why, _ = _solve(link, theta, seed)
    return out, counts, complete, why


def homogeneous_quadrics(D, E, U, ua, r) -> np.ndarray:
    """The system of :func:`solve_rotations` as 10 homogeneous quadrics ``z^T Q z`` (10, 11, 11,
    real) in ``z = (R entries, sigma, h)`` (``h = 1``): ``R^T R - h^2 I`` (upper triangle), then
    each dyad's ``|M z|^2 - (u_i . M z)^2 - r_i^2 h^2`` with ``W_i = M z = R D_i + sigma u_a + E_i h``
    (the exact data of its certificates, :mod:`.certificates`)."""
    Q = np.zeros((_N, _N + 1, _N + 1))
    for m, (i, j) in enumerate(zip(*_IU, strict=True)):
        for k in range(3):
            Q[m, 3 * k + i, 3 * k + j] += 0.5
            Q[m, 3 * k + j, 3 * k + i] += 0.5
        Q[m, _N, _N] = -1.0 if i == j else 0.0
    for d in range(len(D)):
        M = np.zeros((3, _N + 1))
        for a in range(3):
            M[a, 3 * a:3 * a + 3] = D[d]
        M[:, 9], M[:, _N] = np.real(ua), E[d]
        P = np.eye(3) - np.outer(U[d], U[d])
        Q[6 + d] = M.T @ P @ M
        Q[6 + d, _N, _N] -= r[d] ** 2
    return Q


def _solve(link: CsLinkage, theta: float, seed: int):
    """:func:`solve_rotations` and, last, ``(Q, Z)``: :func:`homogeneous_quadrics` and the
    listed solutions' points ``z`` (real parts, ``h = 1``), for their certificates."""
    st = _start_system(seed)
    a, o = link.driven, link.others()
    g = link.line(theta)
    D = link.s[o] - link.s[a]
    E = g[None] - link.c[o]
    U = link.u[o]
    ua = link.u[a].astype(complex)
    r = link.r[o]
    gamma = np.exp(1j * np.random.default_rng(7 + seed).uniform(0, 2 * np.pi))

    def G(X):
        lin = np.einsum("ijk,nk->nij", st.alpha, X) + st.beta[None]  # (n, 4, 2)
        Gv = lin[:, :, 0] * lin[:, :, 1]
        JG = lin[:, :, 1, None] * st.alpha[None, :, 0] + lin[:, :, 0, None] * st.alpha[None, :, 1]
        return Gv, JG

    def fun(X, t):
        P, JP = _orth(X)
        F, JF = _target(X, D, E, U, ua, r)
        Gv, JG = G(X)
        s = t[:, None]
        H = np.concatenate([P, (1 - s) * gamma * Gv + s * F], axis=1)
        Hx = np.concatenate([JP, (1 - s[..., None]) * gamma * JG + s[..., None] * JF], axis=1)
        Ht = np.concatenate([np.zeros_like(P), F - gamma * Gv], axis=1)
        return H, Hx, Ht

    X, _, reached, _ = track(fun, st.X)
    X = _refine(X, D, E, U, ua, r)
    with np.errstate(all="ignore"):
        P, JP = _orth(X)
        F, JF = _target(X, D, E, U, ua, r)
        J = np.concatenate([JP, JF], axis=1)
        res = np.linalg.norm(np.concatenate([P, F], axis=1), axis=1)
        nrm = np.linalg.norm(X, axis=1)
        fin = np.all(np.isfinite(J), axis=(1, 2)) & np.isfinite(nrm)
        rows = J / np.maximum(np.linalg.norm(J, axis=2, keepdims=True), 1e-300)
        sv = np.linalg.svd(np.where(fin[:, None, None], rows, np.eye(_N)), compute_uv=False)
    rcond = np.where(fin, sv[:, -1] / sv[:, 0], 0.0)
    inf = ~fin | (nrm > MONODROMY_DIVERGED) | (~reached & (nrm > 1e2))
    good = ~inf & reached & (res < 1e-8 * np.maximum(1.0, nrm ** 2))
    sing = ~inf & ~(good & (rcond >= HOMOTOPY_SINGULAR))
    nonsing = good & ~sing
    real = nonsing & (np.linalg.norm(X.imag, axis=1) < HOMOTOPY_REAL * np.maximum(1.0, nrm))
    cplx = nonsing & ~real
    # distinct: two paths at one nonsingular point would mean a path jump
    pts = X[nonsing] / np.maximum(nrm[nonsing, None], 1.0)
    dup = 0
    if len(pts) > 1:
        G2 = np.linalg.norm(pts[:, None] - pts[None], axis=2)
        np.fill_diagonal(G2, np.inf)
        dup = int(np.sum(np.min(G2, axis=1) < 1e-8))
    # near-real singular end points (a double root at a singular input) are listed too: the
    # lifting polishes them, and the answer is then not proven
    near = sing & ~inf & (np.linalg.norm(X.imag, axis=1) < HOMOTOPY_NEAR_REAL * np.maximum(1.0, nrm))
    out = []
    for x in X[real | near]:
        Uu, _, Vt = np.linalg.svd(x[:9].real.reshape(3, 3))
        out.append((Uu @ Vt, float(x[9].real)))
    counts = (int(real.sum()), int(cplx.sum()), int(sing.sum()), int(inf.sum()), len(st.X))
    complete = st.complete and not sing.any() and dup == 0
    why = ("" if complete else
           f"{int(sing.sum())} path(s) end at singular points (a multiple root or a continuum)" if sing.any() else
           f"{dup} paths end at one point (a path jump)" if dup else "the start system was not solved completely")
    Z = np.hstack([np.real(X[real | near]), np.ones((int(np.sum(real | near)), 1))])
    return out, counts, complete, why, (homogeneous_quadrics(D, E, U, ua, r), Z)


def _refine(X, D, E, U, ua, r, iters: int = 3) -> np.ndarray:
    """Newton on the full system at ``t = 1`` where it lowers the residual."""
    X = X.copy()
    with np.errstate(all="ignore"):
        for _ in range(iters):
            P, JP = _orth(X)
            F, JF = _target(X, D, E, U, ua, r)
            H = np.concatenate([P, F], axis=1)
            J = np.concatenate([JP, JF], axis=1)
            ok = np.all(np.isfinite(J), axis=(1, 2)) & (np.abs(np.linalg.det(J)) > 0)
            idx = np.flatnonzero(ok)
            if not idx.size:
                break
            Xn = X[idx] - np.linalg.solve(J[idx], H[idx][..., None])[..., 0]
            Pn, _ = _orth(Xn)
            Fn, _ = _target(Xn, D, E, U, ua, r)
            better = np.linalg.norm(np.concatenate([Pn, Fn], axis=1), axis=1) <= np.linalg.norm(H[idx], axis=1)
            X[idx[better]] = Xn[better]
    return X


# ------------------------------------------------------------------ the registered solver
def solve(mech: Mechanism, values, *, seeds: int | None = None, seed: int | None = None):
    """The registered forward solver (:data:`..dispatch.FORWARD_CLOSED_FORMS`): every assembly
    configuration of the 5-CS linkage at the driven rotation ``values`` (rad), a
    :class:`..dispatch.ForwardAnswer`.  ``seeds`` is refused (no search); ``seed`` draws the
    start system and ``gamma``."""
    from . import certificates
    from .forward_answer import Counts, answer_from_poses

    if seeds is not None:
        raise InputError(f"seeds: the 5-CS closed form of {mech.name} tracks the 128 paths of a homotopy on "
                         "SO(3) x C and takes no starts; method='multistart' runs a multi-start search")
    t0 = time.perf_counter()
    link = linkage_of(mech)
    assert link is not None
    theta = float(np.asarray(values, float).ravel()[0]) - link.offset
    sols, (nr, nc, ns, ni, npaths), complete, why, (Q, Z) = _solve(link, theta, 0 if seed is None else seed)
    certs = certificates.run(lambda: certificates.affine(Q, list(Z)))
    a = link.driven
    g = link.line(theta)
    p0 = np.asarray(mech.platform_point, float) / link.L
    poses = []
    for R, sig in sols:
        t = g + sig * link.u[a] - R @ link.s[a]
        poses.append((R, (R @ p0 + t) * link.L))
    if complete:
        how = (f"every path accounted for: the four other dyads are 4 quadrics on SO(3) x C (the coupler's rotation "
               f"and the driven slide), at most 8 x 2^4 = {npaths} solutions; the {npaths} paths of a linear-product "
               f"homotopy on that variety (gamma trick) end at {nr + nc} distinct nonsingular points ({nr} real, "
               f"{nc} complex) and {ni} diverge (no configuration)")
    else:
        how = f"NOT proven: of the {npaths} paths of the homotopy on SO(3) x C, {why}"
    return answer_from_poses(mech, values, poses, label=f"5-CS closed form (4 quadrics on SO(3) x C, {npaths} paths)",
                             complete=complete, completeness=how, counts=Counts(nr, nc, ns, ni, npaths),
                             seconds=time.perf_counter() - t0, certified=certs)


def recognise(mech: Mechanism):
    """The forward solver :func:`solve` when ``mech`` is a 5-CS linkage with a C rotation
    driven, else ``None``."""
    return solve if linkage_of(mech) is not None else None
