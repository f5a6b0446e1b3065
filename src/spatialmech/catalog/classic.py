"""Classic mechanisms beyond the papers, as ready-made models."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..geometry.rotations import euler_matrix, transform
from ..model.joints import P, R, S, U
from ..model.dh import serial_from_dh
from ..model.mechanism import Limb, Mechanism


def _ring(radius: float, angles_deg, z: float = 0.0) -> np.ndarray:
    a = np.deg2rad(np.asarray(angles_deg, dtype=float))
    return np.stack([radius * np.cos(a), radius * np.sin(a), np.full_like(a, z)], axis=1)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def stewart_6sps(rb: float = 1.0, rp: float = 0.6, h: float = 1.0) -> Mechanism:
    """Gough-Stewart platform, 6-SPS with actuated legs: 6 DOF."""
    B = _ring(rb, [15, 105, 135, 225, 255, 345])
    A = _ring(rp, [40, 80, 160, 200, 280, 320], h)
    limbs = []
    for i in range(6):
        d = A[i] - B[i]
        L = float(np.linalg.norm(d))
        limbs.append(
            Limb(
                f"leg{i + 1}",
                (S(f"B{i + 1}", B[i]), P(f"L{i + 1}", B[i], d / L, actuated=True, offset=L), S(f"A{i + 1}", A[i])),
            )
        )
    return Mechanism(
        "stewart-6sps", tuple(limbs), platform_point=np.array([0.0, 0.0, h]),
        description="Gough-Stewart platform (6-SPS), 6 DOF",
    )


def three_rps(rb: float = 0.3, rp: float = 0.15, h: float = 0.3) -> Mechanism:
    """3-RPS: base revolute axes tangent to the base circle, actuated legs: 2 rotations + Tz."""
    angs = [90, 210, 330]
    B = _ring(rb, angs)
    A = _ring(rp, angs, h)
    limbs = []
    for i, ang in enumerate(np.deg2rad(angs)):
        t = np.array([-np.sin(ang), np.cos(ang), 0.0])
        d = A[i] - B[i]
        L = float(np.linalg.norm(d))
        limbs.append(
            Limb(
                f"leg{i + 1}",
                (R(f"R{i + 1}", B[i], t), P(f"L{i + 1}", B[i], d / L, actuated=True, offset=L), S(f"S{i + 1}", A[i])),
            )
        )
    return Mechanism(
        "three-rps", tuple(limbs), platform_point=np.array([0.0, 0.0, h]),
        description="3-RPS parallel mechanism, 3 DOF (2 rotations + 1 translation, with parasitic motion)",
    )


def three_prs(rb: float = 0.3, rp: float = 0.15, h: float = 0.3) -> Mechanism:
    """3-PRS: actuated sliders on vertical rails at 120 deg (radius ``rb``, slider height 0 at the
    reference), an R joint on each slider with its axis tangent to the base circle, a leg of fixed
    length to an S joint on the platform (radius ``rp``, height ``h``): 2 rotations + Tz with the
    same parasitic motion as the 3-RPS (each S centre stays in its leg's radial plane)."""
    angs = [90, 210, 330]
    B = _ring(rb, angs)
    A = _ring(rp, angs, h)
    Z = np.array([0.0, 0.0, 1.0])
    limbs = []
    for i, ang in enumerate(np.deg2rad(angs)):
        t = np.array([-np.sin(ang), np.cos(ang), 0.0])
        limbs.append(
            Limb(
                f"leg{i + 1}",
                (P(f"P{i + 1}", B[i], Z, actuated=True), R(f"R{i + 1}", B[i], t), S(f"S{i + 1}", A[i])),
            )
        )
    return Mechanism(
        "three-prs", tuple(limbs), platform_point=np.array([0.0, 0.0, h]),
        description="3-PRS parallel mechanism (vertical rails), 3 DOF (2 rotations + 1 translation, with parasitic motion)",
    )


def three_upu(rb: float = 0.3, rp: float = 0.1, h: float = 0.3) -> Mechanism:
    """Translational 3-UPU (Tsai): in each leg the first base-U axis is parallel to the last
    platform-U axis and the two middle axes are parallel: pure translation, 3 DOF."""
    angs = [90, 210, 330]
    B = _ring(rb, angs)
    A = _ring(rp, angs, h)
    limbs = []
    for i, ang in enumerate(np.deg2rad(angs)):
        a = np.array([-np.sin(ang), np.cos(ang), 0.0])
        d = A[i] - B[i]
        L = float(np.linalg.norm(d))
        b = _unit(np.cross(d, a))
        limbs.append(
            Limb(
                f"leg{i + 1}",
                (
                    U(f"UB{i + 1}", B[i], [a, b]),
                    P(f"L{i + 1}", B[i], d / L, actuated=True, offset=L),
                    U(f"UA{i + 1}", A[i], [b, a]),
                ),
            )
        )
    return Mechanism(
        "three-upu", tuple(limbs), platform_point=np.array([0.0, 0.0, h]),
        description="Translational 3-UPU parallel mechanism (Tsai), 3 translations",
    )


def delta(rb: float = 0.2, arm: float = 0.2, rp: float = 0.05, h: float = -0.35, width: float = 0.06) -> Mechanism:
    """The Clavel Delta: per limb an actuated R joint on the base, an arm, and a parallelogram of
    two rods with spherical joints at both ends (``width`` apart) to the platform.  11 links, 3 R
    + 12 S joints, 5 independent loops; 3 DOF (3 translations) and the 6 rods' spins passive."""
    angs = [90, 210, 330]
    B = _ring(rb, angs)
    W = _ring(rp, angs, h)
    links = ["ground", "platform"]
    joints = []
    for i, ang in enumerate(np.deg2rad(angs)):
        r = np.array([np.cos(ang), np.sin(ang), 0.0])
        a = np.array([-np.sin(ang), np.cos(ang), 0.0])
        E = B[i] + arm * r
        k = i + 1
        links += [f"arm{k}", f"rod{k}a", f"rod{k}b"]
        joints.append((R(f"R{k}", B[i], a, actuated=True), "ground", f"arm{k}"))
        for side, sgn in (("a", 1.0), ("b", -1.0)):
            off = sgn * 0.5 * width * a
            joints.append((S(f"E{k}{side}", E + off), f"arm{k}", f"rod{k}{side}"))
            joints.append((S(f"W{k}{side}", W[i] + off), f"rod{k}{side}", "platform"))
    return Mechanism.from_graph(
        "delta", links, joints, platform_point=np.array([0.0, 0.0, h]),
        description="Clavel Delta robot (3 R + 12 S, parallelograms of two SS rods), 3 translations",
    )


def delta_ruu(rb: float = 0.2, arm: float = 0.2, rp: float = 0.05, h: float = -0.35) -> Mechanism:
    """Delta robot with the forearm parallelogram replaced by its kinematic equivalent, two
    universal joints with parallel inner axes (3-RUU): 3 translations."""
    angs = [90, 210, 330]
    B = _ring(rb, angs)
    W = _ring(rp, angs, h)
    limbs = []
    for i, ang in enumerate(np.deg2rad(angs)):
        r = np.array([np.cos(ang), np.sin(ang), 0.0])
        a = np.array([-np.sin(ang), np.cos(ang), 0.0])
        E = B[i] + arm * r
        f = W[i] - E
        c = _unit(np.cross(f, a))
        limbs.append(
            Limb(
                f"arm{i + 1}",
                (R(f"R{i + 1}", B[i], a, actuated=True), U(f"E{i + 1}", E, [a, c]), U(f"W{i + 1}", W[i], [c, a])),
            )
        )
    return Mechanism(
        "delta-ruu", tuple(limbs), platform_point=np.array([0.0, 0.0, h]),
        description="Delta robot (parallelograms as equivalent U-U pairs, 3-RUU), 3 translations",
    )


def planar_4r(
    ground: float = 4.0, crank: float = 1.0, coupler: float = 3.5, rocker: float = 3.0, angle_deg: float = 60.0
) -> Mechanism:
    """Planar four-bar (Grashof crank-rocker by default); the coupler is the platform."""
    z = np.array([0.0, 0.0, 1.0])
    A0 = np.zeros(3)
    B0 = np.array([ground, 0.0, 0.0])
    t = np.deg2rad(angle_deg)
    A1 = np.array([crank * np.cos(t), crank * np.sin(t), 0.0])
    # B1: intersection of circles |B1 - A1| = coupler, |B1 - B0| = rocker (upper solution)
    d = np.linalg.norm(B0 - A1)
    if not abs(coupler - rocker) <= d <= coupler + rocker:
        raise InputError("planar_4r: the loop cannot be assembled at this crank angle")
    x = (coupler**2 - rocker**2 + d**2) / (2 * d)
    y = np.sqrt(coupler**2 - x**2)
    e = (B0 - A1) / d
    n = np.cross(z, e)
    B1 = A1 + x * e + y * n
    limbs = (
        Limb("crank", (R("A0", A0, z, actuated=True), R("A1", A1, z))),
        Limb("rocker", (R("B0", B0, z), R("B1", B1, z))),
    )
    return Mechanism(
        "planar-4r", limbs, platform_point=A1,
        description="Planar four-bar linkage (crank-rocker), 1 DOF; the coupler is the platform",
    )


def _rz(t):
    return euler_matrix("zyx", [t, 0.0, 0.0])


def _rx(t):
    return euler_matrix("xyz", [t, 0.0, 0.0])


def _T(R, p):
    return transform(R, np.asarray(p, float))


def bennett(a: float = 1.0, alpha_deg: float = 30.0, b: float = 1.5, theta1_deg: float = 60.0) -> Mechanism:
    """Bennett linkage: link lengths a, b, a, b and twists alpha, beta, alpha, beta with
    sin(alpha)/a = sin(beta)/b.  Assembled numerically at input angle ``theta1``; the coupler
    (link 2) is the platform.  Classic Grübler-Kutzbach gives -2; its mobility is 1."""
    al = np.deg2rad(alpha_deg)
    s = b * np.sin(al) / a
    if not 0 < s < 1:
        raise InputError("bennett: sin(beta) = b sin(alpha)/a must lie in (0, 1)")
    be = np.arcsin(s)
    params = [(a, al), (b, be), (a, al), (b, be)]
    th1 = np.deg2rad(theta1_deg)

    def chain(th):
        T = np.eye(4)
        frames = [T]
        for t, (ai, ali) in zip(th, params, strict=True):
            T = T @ _T(_rz(t), [0, 0, 0]) @ _T(np.eye(3), [ai, 0, 0]) @ _T(_rx(ali), [0, 0, 0])
            frames.append(T)
        return frames

    def resid(x):
        T = chain([th1, *x])[-1]
        return np.r_[T[:3, :3].ravel() - np.eye(3).ravel(), T[:3, 3]]

    from scipy.optimize import least_squares  # on first use: scipy.optimize loads scipy.spatial (issue 29)

    best = None
    for guess in ([2.0, 2 * np.pi - th1, -2.0], [1.0, -th1, 1.0], [3.0, np.pi, 3.0], [-1.0, th1, -1.0]):
        sol = least_squares(resid, guess, xtol=1e-15, ftol=1e-15, gtol=1e-15)
        if np.linalg.norm(resid(sol.x)) < 1e-10:
            frames = chain([th1, *sol.x])
            axes = [f[:3, 2] for f in frames[:4]]
            # reject the folded (degenerate) assemblies: all four axes must be distinct lines
            if min(np.linalg.norm(np.cross(axes[i], axes[(i + 1) % 4])) for i in range(4)) > 1e-3:
                best = frames
                break
    if best is None:  # pragma: no cover - the default parameters assemble
        raise InputError("bennett: could not assemble the loop at this input angle")
    o = [f[:3, 3] for f in best[:4]]
    zax = [_unit(f[:3, 2]) for f in best[:4]]
    limbs = (
        Limb("input", (R("J1", o[0], zax[0], actuated=True), R("J2", o[1], zax[1]))),
        Limb("output", (R("J4", o[3], zax[3]), R("J3", o[2], zax[2]))),
    )
    return Mechanism(
        "bennett", limbs, platform_point=o[2],
        description="Bennett linkage (overconstrained spatial 4R): classic G-K -2, mobility 1",
    )


def spatial_six_bar() -> Mechanism:
    """A spatial six-bar of two RSSR loops that share a link: the crank (R about z) drives the
    rocker (R about x) through the rod ``rod1`` (S-S); the rocker drives the follower (R about
    y) through ``rod2`` (S-S).  6 links, 3 R + 4 S joints, 2 independent loops; mobility 1 with
    the two rods' spins passive.  The rocker has three joints: an internal body of the graph;
    the follower is the output link."""
    X, Y, Z = np.eye(3)
    links = ["ground", "crank", "rod1", "rocker", "rod2", "follower"]
    joints = [
        (R("A0", [0.0, 0.0, 0.0], Z, actuated=True), "ground", "crank"),
        (S("A1", [0.3, 0.0, 0.0]), "crank", "rod1"),
        (S("B1", [0.0, 1.0, -0.1]), "rod1", "rocker"),
        (R("B0", [0.0, 1.0, 0.5], X), "ground", "rocker"),
        (S("C1", [0.0, 1.3, 0.8]), "rocker", "rod2"),
        (S("D1", [0.9, 2.0, 0.5]), "rod2", "follower"),
        (R("D0", [0.6, 2.0, 0.5], Y), "ground", "follower"),
    ]
    return Mechanism.from_graph(
        "spatial-six-bar", links, joints, output="follower", platform_point=np.array([0.6, 2.0, 0.5]),
        description="Spatial six-bar: two RSSR loops sharing the rocker; 1 DOF (+2 passive rod spins)",
    )


def rssr() -> Mechanism:
    """Spatial RSSR four-bar: input crank about z, output rocker about x; the rocker is the
    platform.  One passive freedom (coupler spin about the S-S line): mobility 1."""
    X, Z = np.eye(3)[0], np.eye(3)[2]
    A0 = np.zeros(3)
    A1 = np.array([0.3, 0.0, 0.0])
    B0 = np.array([0.0, 1.0, 0.5])
    B1 = np.array([0.0, 1.0, -0.1])
    limbs = (
        Limb("input", (R("A0", A0, Z, actuated=True), S("A1", A1), S("B1", B1))),
        Limb("output", (R("B0", B0, X),)),
    )
    return Mechanism(
        "rssr", limbs, platform_point=B1,
        description="Spatial RSSR four-bar linkage, 1 DOF (+1 passive coupler spin)",
    )


#: Unimation PUMA 560, standard DH parameters (d, a in metres; alpha in degrees) as in P. Corke's
#: Robotics Toolbox (mdl_puma560, after Corke and Armstrong-Helouvry, ICRA 1994).
PUMA560_DH = {"d": [0.0, 0.0, 0.15005, 0.4318, 0.0, 0.0], "a": [0.0, 0.4318, 0.0203, 0.0, 0.0, 0.0],
              "alpha": [90.0, 0.0, -90.0, 90.0, -90.0, 0.0]}
#: its reference: Corke's nominal configuration ``qn`` in degrees (the DH zero is a wrist singularity)
PUMA560_REFERENCE_DEG = [0.0, 45.0, 180.0, 0.0, 45.0, 0.0]


def puma560() -> Mechanism:
    """The PUMA 560 arm (standard DH, Corke's parameters), placed at Corke's nominal
    configuration: its joint variables are the DH angles minus (0, 45, 180, 0, 45, 0) deg."""
    return serial_from_dh(
        "puma560", d=PUMA560_DH["d"], a=PUMA560_DH["a"], alpha=PUMA560_DH["alpha"],
        reference=PUMA560_REFERENCE_DEG, degrees=True,
        description="PUMA 560 6R arm (standard DH, Corke), at the nominal configuration qn",
    )


def agile_eye() -> Mechanism:
    """A spherical 3-RRR wrist of the Agile-Eye type (Gosselin and Hamel 1994): every joint axis
    through the origin, every link angle 90 degrees; at the reference leg ``i`` has its base,
    middle and platform axes along ``e_i``, ``e_(i+1)``, ``e_(i+2)`` (a regular configuration:
    the three platform axes orthonormal).  Dimensionless: a unit sphere (only directions)."""
    E = np.eye(3)
    o = np.zeros(3)
    limbs = tuple(
        Limb(f"leg{i + 1}", (R(f"A{i + 1}", o, E[i], actuated=True), R(f"B{i + 1}", o, E[(i + 1) % 3]),
                             R(f"C{i + 1}", o, E[(i + 2) % 3])))
        for i in range(3)
    )
    return Mechanism("agile-eye", limbs, platform_point=o,
                     description="Agile-Eye spherical 3-RRR wrist: 3 rotations about the origin")
