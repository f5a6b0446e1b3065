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
from dataclasses import dataclass, replace

import numpy as np

from ...errors import InputError
from ...geometry.tolerances import (
    HOMOTOPY_INFINITY,
    HOMOTOPY_JUMP,
    HOMOTOPY_NEAR_REAL,
    HOMOTOPY_NEWTON,
    HOMOTOPY_REAL,
    HOMOTOPY_SINGULAR,
)
from ...model.mechanism import Mechanism
from ...results import EndPointStatus
from .. import backend
from .endgame import cauchy_endgame, local_dimension, multiple_root_end
from .systems import (
    PoseSystem,
    StewartSystem,
    geometry_family,
    pose_system,
    qmul,
    stewart_system,
    system_from_points,
    unsupported_reason,
)

__all__ = [
    "HomotopyResult",
    "HomotopySolution",
    "PoseSystem",
    "StewartSystem",
    "clear_cache",
    "geometry_family",
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


def track(fun, X0: np.ndarray, *, h0: float = 0.02, hmin: float = 1e-14, max_steps: int = 4000,
          indexed: bool = False):
    """Track the paths ``H(x, t) = 0`` from ``t = 0`` (points ``X0``, (n, m)) to ``t = 1``.

    ``fun(X, t)`` (``t``: (n,)) returns ``H`` (n, m), ``H_x`` (n, m, m) and ``H_t`` (n, m); with
    ``indexed``, ``fun(X, t, idx)`` is also told which paths (rows of ``X0``) it is given.
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

    for _ in range(max_steps):
        idx = np.flatnonzero(~done & ~failed)
        if idx.size == 0:
            break

        def fun_i(x, tt, idx=idx):
            return fun(x, tt, idx) if indexed else fun(x, tt)

        def vel(x, tt):
            _, Hx, Ht = fun_i(x, tt)
            return -np.linalg.solve(Hx, Ht[..., None])[..., 0]

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
                H, Hx, _ = fun_i(xc, tn)
                dx = np.linalg.solve(Hx, H[..., None])[..., 0]
                d0 = np.linalg.norm(dx, axis=1) / nx
                xc = xc - dx
                H, Hx, _ = fun_i(xc, tn)
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


def track_parameter(Q0: np.ndarray, Q1: np.ndarray, c: np.ndarray, X0: np.ndarray, *,
                    h0: float = 0.02, hmin: float = 1e-14, max_steps: int = 4000):
    """The parameter homotopy from the quadrics ``Q0`` (7, 8, 8; points ``X0``) to ``Q1`` along
    the straight segment in the coefficient space: :func:`track`, compiled and path by path when
    the compiled core is in use (the batched NumPy :func:`track` otherwise).  Returns
    ``(X, t, done)``."""
    X0 = np.ascontiguousarray(X0, dtype=complex)
    Q0 = np.ascontiguousarray(Q0, dtype=complex)
    dQ = np.ascontiguousarray(np.asarray(Q1, dtype=complex) - Q0)
    if (fast := backend.engine()) is not None:
        return fast.track_parameter(Q0, dQ, c, X0, h0=h0, hmin=hmin, max_steps=max_steps)

    def fun(X, t):
        F, J, _ = _eval_quad(Q0[None] + t[:, None, None, None] * dQ[None], c, X)
        Ht = np.zeros_like(F)
        Ht[:, :7] = np.einsum("ni,kij,nj->nk", X, dQ, X)
        return F, J, Ht

    X, T, done, _ = track(fun, X0, h0=h0, hmin=hmin, max_steps=max_steps)
    return X, T, done


def _refine(Qc, c, X, iters: int = 4):
    """Newton at ``t = 1`` (batched).  A point keeps its last value when its step fails or does not
    lower the residual: at a singular root (located by the end game) the Jacobian is singular to
    rounding, and a Newton step there would throw the point onto another root."""
    X = X.copy()
    with np.errstate(all="ignore"):
        F, J, _ = _eval_quad(Qc, c, X)
        for _ in range(iters):
            ok = np.all(np.isfinite(J), axis=(1, 2)) & np.all(np.isfinite(F), axis=1)
            ok &= np.abs(np.linalg.det(np.where(ok[:, None, None], J, np.eye(_N)))) > 0
            if not ok.any():
                break
            idx = np.flatnonzero(ok)
            dx = np.linalg.solve(J[idx], F[idx][..., None])[..., 0]
            Xn = X[idx] - dx
            Fn, Jn, _ = _eval_quad(Qc, c, Xn)
            better = np.all(np.isfinite(Xn), axis=1) & (np.linalg.norm(Fn, axis=1) < np.linalg.norm(F[idx], axis=1))
            X[idx[better]], F[idx[better]], J[idx[better]] = Xn[better], Fn[better], Jn[better]
            if not better.any():
                break
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
        y = _phase_free(x)
        imag = float(np.linalg.norm(y.imag) / max(float(np.linalg.norm(y)), 1e-300))
        res = float(np.linalg.norm(F[n, :7]) / max(nx[n] ** 2, 1e-300))
        if not np.isfinite(nx[n]) or rel_inf < HOMOTOPY_INFINITY:
            st = EndPointStatus.AT_INFINITY
        elif rcond < HOMOTOPY_SINGULAR or multiple_root_end(imag, rcond):
            st = EndPointStatus.SINGULAR
        elif imag < HOMOTOPY_REAL:
            st = EndPointStatus.REAL
        else:
            st = EndPointStatus.COMPLEX
        out.append((st, rcond, rel_inf, imag, res, y, x))
    return out


def _certified_simple(Qt, sols: list) -> tuple[list, int]:
    """The singular end points proven simple non-real roots: each refined by Newton steps in
    106-bit balls (:func:`.certify.refine_projective`), then all finite end points certified
    together (:func:`.certify.certify_projective`, so that every box is also disjoint from the
    others'); when *every* singular one is certified and proven non-real, they become complex
    solutions at their refined points.  Returns the end points and how many changed (0: none,
    or not all of them; also when certification is off)."""
    from . import certify as hcert

    sing = [i for i, s in enumerate(sols) if s.status == EndPointStatus.SINGULAR]
    if not sing or not hcert.enabled():
        return sols, 0
    finite = [i for i, s in enumerate(sols) if s.status != EndPointStatus.AT_INFINITY]
    refined = {i: _phase_free(y)
               for i, y in zip(sing, hcert.refine_projective(Qt, np.array([sols[i].study for i in sing])), strict=True)}
    Y = np.array([refined[i] if i in refined else sols[i].study for i in finite])
    _, certs = hcert.certify_projective(Qt, [], Y)
    by_point = dict(zip(finite, certs, strict=True))
    if not all(by_point[i].certified and by_point[i].real is False for i in sing):
        return sols, 0
    out = list(sols)
    for i in sing:
        out[i] = replace(sols[i], status=EndPointStatus.COMPLEX, study=refined[i], R=None, p=None)
    return out, len(sing)


def _phase_free(x: np.ndarray) -> np.ndarray:
    """A projective point with its phase removed as :func:`_classify` does (largest entry real)."""
    k = int(np.argmax(np.abs(x)))
    return x * (abs(x[k]) / x[k]) if x[k] != 0 else x


#: A singular end point is *near the exceptional generator* when ``|e| / |x|`` is below this
#: (its ``e.e / |x|^2`` is then below its square, a few times ``HOMOTOPY_INFINITY`` at most).
NEAR_GENERATOR = 1e-2


def _near_infinity_note(sols) -> str:
    """What the singular end points near the exceptional generator ``e = 0`` are, said precisely:
    how near it and how far from real they are, and that the end game did not resolve them.
    (Measured on the 3-UPU, docs/homotopy.md: such points are finite, ``e.e / |x|^2`` settles at
    1e-5 .. 4e-4 as the path nears its end; at slides near 0.4 m they are simple roots with
    sigma_min / sigma_max about 1e-8; they are not at infinity.)"""
    near = []
    for s in sols:
        if s.status != EndPointStatus.SINGULAR:
            continue
        y = np.asarray(s.study, dtype=complex)
        ratio = float(np.linalg.norm(y[:4]) / max(float(np.linalg.norm(y)), 1e-300))
        g = y[4:]
        iso = float(abs(g @ g) / max(float(np.linalg.norm(g)) ** 2, 1e-300))
        if ratio < NEAR_GENERATOR:
            near.append((ratio, iso, s.imag_ratio))
    if not near:
        return ""
    return (f"; {len(near)} of the singular end point(s) lie near the exceptional generator e = 0 (|e| / |x| <= "
            f"{max(r for r, _, _ in near):.0e}, e.e / |x|^2 above the {HOMOTOPY_INFINITY:g} that counts a point at "
            f"infinity) with g isotropic (|g.g| / |g|^2 <= {max(i for _, i, _ in near):.0e}): finite complex points "
            "close to the solutions at infinity, too ill-conditioned to count as regular, where the end game did not "
            "converge, so whether each is a simple root, a multiple root or on a continuum is not decided; none is "
            "near a real pose (imaginary part >= "
            f"{min(m for _, _, m in near):.0%} of the point); not proven only because these end points are not resolved")


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
    p = 2 * qmul(g, e * np.array([1, -1, -1, -1]))[1:] / E * L
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
        fin = [i for i, r in enumerate(cls) if r[0] in (EndPointStatus.REAL, EndPointStatus.COMPLEX)]
        inf = [i for i, r in enumerate(cls) if r[0] == EndPointStatus.AT_INFINITY]
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


def _groups(P: np.ndarray, tol: float = 1e-6) -> list[np.ndarray]:
    """Indices of the points ``P`` (n, m) grouped by relative distance below ``tol``."""
    groups: list[list[int]] = []
    for i, x in enumerate(P):
        for g in groups:
            y = P[g[0]]
            if np.linalg.norm(x - y) <= tol * max(float(np.linalg.norm(y)), 1e-300):
                g.append(i)
                break
        else:
            groups.append([i])
    return [np.array(g, dtype=np.int64) for g in groups]


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

    status: EndPointStatus
    study: np.ndarray
    rcond: float
    infinity_ratio: float
    imag_ratio: float
    residual: float
    R: np.ndarray | None = None
    p: np.ndarray | None = None
    multiplicity: int = 1  # paths ending at this point (singular end points)
    winding: int = 0  # the Cauchy end game's winding number (singular end points; 0: not run or failed)

    def to_dict(self) -> dict:
        return {"status": self.status, "study_parameters_real": [float(v) for v in self.study.real],
                "study_parameters_imag": [float(v) for v in self.study.imag], "inverse_condition": self.rcond,
                "infinity_ratio": self.infinity_ratio, "imaginary_ratio": self.imag_ratio, "residual": self.residual,
                "multiplicity": self.multiplicity, "winding_number": self.winding}


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

    def count(self, status: EndPointStatus | str) -> int:
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
    X, _, done = track_parameter(gen.Q, Qt, c, gen.X) if len(gen.X) else (gen.X, None, np.ones(0, dtype=bool))
    cls = _classify(Qt, c, X)
    # singular end points, and paths that stopped short of t = 1 without escaping to infinity
    sing = np.array([i for i, r in enumerate(cls)
                     if r[0] == EndPointStatus.SINGULAR or (not done[i] and r[0] != EndPointStatus.AT_INFINITY)],
                    dtype=np.int64)
    mult = np.ones(len(cls), dtype=np.int64)
    wind = np.zeros(len(cls), dtype=np.int64)
    isolated = True
    groups: list[np.ndarray] = []
    if len(sing):  # the Cauchy end game locates them; then multiple roots or a continuum
        eg = cauchy_endgame(track_parameter, gen.Q, Qt, c, gen.X[sing])
        X = X.copy()
        X[sing[eg.converged]] = eg.X[eg.converged]
        wind[sing] = eg.winding
        cls = _classify(Qt, c, X)
        isolated = bool(eg.converged.all())
        groups = _groups(X[sing])
        for grp in groups:
            mult[sing[grp]] = len(grp)
            dim = local_dimension(lambda Y: _eval_quad(Qt, c, Y)[:2], X[sing[grp[0]]])
            isolated &= dim == 0 and len(grp) > 1
    sols = []
    for i, (st, rc, ri, im, res, y, _) in enumerate(cls):
        R = p = None
        if (st == EndPointStatus.REAL or (st == EndPointStatus.SINGULAR and im < HOMOTOPY_NEAR_REAL)) and ri >= HOMOTOPY_INFINITY:
            R, p = study_to_pose(y / np.linalg.norm(y), sysm.L)
        sols.append(HomotopySolution(st, y, rc, ri, im, res, R, p, int(mult[i]), int(wind[i])))
    certified_simple = 0
    if accounted and not isolated and len(sing) and done[sing].all():  # every such path reached t = 1
        sols, certified_simple = _certified_simple(Qt, sols)
    n_par = len(sysm.affine_span()[1])
    how = (f"total-degree homotopy ({gen.n_paths} paths, gamma trick) to a generic complex instance: every path "
           f"accounted for ({len(gen.X)} finite nonsingular, {gen.n_at_infinity} at the exceptional generator e.e = 0); "
           f"parameter homotopy of those {len(gen.X)} paths to the requested actuator values (straight segment in the "
           f"{n_par}-dimensional affine span of the coefficients)")
    n_sing = sum(s.status == EndPointStatus.SINGULAR for s in sols)
    if certified_simple:
        how += (f"; {certified_simple} end point(s) too ill-conditioned to count as regular (sigma_min / sigma_max below "
                f"{HOMOTOPY_SINGULAR:g}) are certified simple non-real roots by the Krawczyk test in ball arithmetic, each "
                "box disjoint from every other end point's: complex solutions")
    if accounted and n_sing and isolated:
        how += (f"; {n_sing} path(s) end at {len(groups)} isolated multiple root(s) (multiplicities "
                f"{sorted(int(m) for m in set(mult[sing].tolist()))}), located by a Cauchy end game (winding numbers "
                f"{sorted(set(wind[sing].tolist()))}) and found isolated by a local dimension test")
    elif accounted and n_sing:
        how += (f"; but {n_sing} end point(s) are singular and not all isolated multiple roots (a continuum of "
                "solutions, or an end game that did not converge): not proven complete there; real points near them "
                "polished, the multi-start roots added, and a continuum reported as one self-motion set")
        how += _near_infinity_note(sols)
    if not accounted:
        how = (f"NOT complete: {gen.n_paths - len(gen.X) - gen.n_at_infinity} of the {gen.n_paths} total-degree paths "
               f"ended neither at a finite nonsingular point nor at infinity after {gen.attempts} attempts")
    return HomotopyResult(tuple(sols), accounted and (not n_sing or isolated), how, len(gen.X), gen.n_paths, gen.seconds,
                          time.perf_counter() - t0, cached)
