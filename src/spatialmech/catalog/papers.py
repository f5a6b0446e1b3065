"""The mechanisms of the four papers (see docs/conventions.md for the conventions used)."""

from __future__ import annotations

import json
from functools import lru_cache
from importlib import resources

import numpy as np

from ..kinematics.closed_forms.four_sps_cu import PAPER_B_DIMENSIONS, attachment_points
from ..model.joints import C, P, R, S, Sm, U
from ..model.mechanism import Limb, Mechanism, Mode, Pose

# ---------------------------------------------------------------- paper B: 4-SPS/CU
#: Section 6 dimensions of paper B (m), defined with the closed form (the catalogue builds its
#: model from the closed form's data, never the reverse).
FOUR_SPS_CU = PAPER_B_DIMENSIONS


def four_sps_cu_points(a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """Platform points ``A_i`` (platform frame) and base points ``B_i`` (conventions.md)."""
    return attachment_points(a, b)


def four_sps_cu(a: float | None = None, b: float | None = None, z0: float | None = None) -> Mechanism:
    """Paper B: four actuated SPS legs and a passive CU limb; 3 rotations + Tz."""
    a = FOUR_SPS_CU["a"] if a is None else a
    b = FOUR_SPS_CU["b"] if b is None else b
    z0 = FOUR_SPS_CU["z0"] if z0 is None else z0
    A, B = four_sps_cu_points(a, b)
    top = np.array([0.0, 0.0, z0])
    limbs = []
    for i in range(4):
        Ai = A[i] + top
        d = Ai - B[i]
        L = float(np.linalg.norm(d))
        limbs.append(
            Limb(
                f"leg{i + 1}",
                (
                    S(f"B{i + 1}", B[i]),
                    P(f"L{i + 1}", B[i], d / L, actuated=True, offset=L, limits=FOUR_SPS_CU["leg_limits"]),
                    S(f"A{i + 1}", Ai),
                ),
            )
        )
    ez, ey, ex = np.eye(3)[2], np.eye(3)[1], np.eye(3)[0]
    limbs.append(
        Limb(
            "cu",
            (
                C("C5", np.zeros(3), ez, offset={"slide": z0}, limits={"slide": FOUR_SPS_CU["cu_limits"]}),
                U("U5", top, [ey, ex]),
            ),
        )
    )
    return Mechanism(
        name="four-sps-cu",
        limbs=tuple(limbs),
        platform_point=top,
        description="Paper B: 4-SPS/CU parallel mechanism, 3 rotations + translation along Z",
        source="paper B (seed 002)",
        notes="Pose (z, alpha, beta, gamma) with T = Rz(gamma) Ry(beta) Rx(alpha) ('ZYX'). "
        "Every pose with alpha = beta = 0 (the reference included) is an actuation singularity.",
    )


# ---------------------------------------------------------------- paper C: 3-RRR metamorphic joint
#: Link radii of the simulation of section 4.2 (m), for drawing.
THREE_RRR_RADII = {"r2": 0.05, "r3": 0.05, "r5": 0.075, "r6": 0.075, "r7": 0.1, "r8": 0.1}

#: Table 2 of paper C (with the "R7 -> Rx" typo corrected to Rz): driven actuators -> motion.
THREE_RRR_TABLE2 = {
    ("R1",): "Ry",
    ("R4",): "Rx",
    ("R7",): "Rz",
    ("R1", "R4"): "RxRy",
    ("R1", "R7"): "RyRz",
    ("R4", "R7"): "RxRz",
    ("R1", "R4", "R7"): "RxRyRz",
}


def three_rrr_sm() -> Mechanism:
    """Paper C: the three-configuration actuated metamorphic parallel spherical joint."""
    o = np.zeros(3)
    X, Y, Z = np.eye(3)
    axes = {  # limb: (actuated base joint, middle, platform joint) at the home pose
        1: (Y, X, Z),
        2: (X, Z, Y),
        3: (Z, Y, X),
    }
    limbs = []
    for k, (a1, a2, a3) in axes.items():
        j0 = 3 * (k - 1) + 1
        limbs.append(
            Limb(
                f"limb{k}",
                (
                    R(f"R{j0}", o, a1, actuated=True, lockable=True),
                    R(f"R{j0 + 1}", o, a2),
                    R(f"R{j0 + 2}", o, a3),
                ),
            )
        )
    modes = tuple(
        Mode("+".join(d), tuple(d), f"drive {', '.join(d)}; paper C table 2: {m}")
        for d, m in THREE_RRR_TABLE2.items()
    )
    return Mechanism(
        name="three-rrr-sm",
        limbs=tuple(limbs),
        platform_point=o,
        description="Paper C: 3-RRR actuated metamorphic spherical joint (1, 2 or 3 rotations by locking actuators)",
        modes=modes,
        source="paper C (seed 003)",
        notes="R = Ry(beta) Rx(alpha) Rz(gamma) ('YXZ'); home: R1=Y R2=X R3=Z, R4=X R5=Z R6=Y, "
        "R7=Z R8=Y R9=X, all axes through the centre.",
    )


#: Section 5 of paper C: driven Sm rotations -> motion of the 3-SPS/SmPU (R1=Y, R4=X, R7=Z).
THREE_SPS_SMPU_MODES = {
    (): "RxRyTz",
    ("R1",): "RxRyTxTz",
    ("R4",): "RxRyTyTz",
    ("R7",): "RxRyRzTz",
    ("R1", "R4"): "RxRyTxTyTz",
    ("R1", "R7"): "RxRyRzTxTz",
    ("R4", "R7"): "RxRyRzTyTz",
    ("R1", "R4", "R7"): "RxRyRzTxTyTz",
}


def three_sps_smpu(rb: float = 0.25, rp: float = 0.12, h: float = 0.35) -> Mechanism:
    """Paper C section 5: three SPS legs and the SmPU limb (Sm at the base centre, P along Z,
    U at the platform centre with axes parallel to y then x).  The paper gives no dimensions;
    these are generic ones."""
    X, Y, Z = np.eye(3)
    top = np.array([0.0, 0.0, h])
    limbs = []
    for i, ang in enumerate(np.deg2rad([90.0, 210.0, 330.0])):
        bi = rb * np.array([np.cos(ang), np.sin(ang), 0.0])
        ai = top + rp * np.array([np.cos(ang + 0.5), np.sin(ang + 0.5), 0.0])
        d = ai - bi
        L = float(np.linalg.norm(d))
        limbs.append(
            Limb(
                f"leg{i + 1}",
                (S(f"B{i + 1}", bi), P(f"L{i + 1}", bi, d / L, actuated=True, offset=L), S(f"A{i + 1}", ai)),
            )
        )
    limbs.append(
        Limb(
            "smpu",
            (
                Sm("Sm", np.zeros(3), [Y, X, Z], freedom_names=("R1", "R4", "R7")),
                P("P4", np.zeros(3), Z, offset=h),
                U("U4", top, [Y, X]),
            ),
        )
    )
    modes = tuple(
        Mode(
            "+".join(d) if d else "Sm-locked",
            tuple(f"Sm.{x}" for x in d),
            f"Sm rotations driven: {', '.join(d) or 'none'}; paper C section 5: {m}",
        )
        for d, m in THREE_SPS_SMPU_MODES.items()
    )
    return Mechanism(
        name="three-sps-smpu",
        limbs=tuple(limbs),
        platform_point=top,
        description="Paper C: 3-SPS/SmPU metamorphic parallel mechanism with eight motion modes (3 to 6 DOF)",
        modes=modes,
        aliases={"R1": "Sm.R1", "R4": "Sm.R4", "R7": "Sm.R7"},
        source="paper C (seed 003), section 5",
        notes="Sm is the metamorphic spherical joint in its serial-equivalent form (rotations "
        "about y (R1), x (R4), z (R7) through the base centre), exact at the home pose with the "
        "locked joints at zero, as paper C's motion claims are.",
    )


# ---------------------------------------------------------------- paper A: 5-CS
@lru_cache(maxsize=1)
def five_cs_data() -> dict:
    """The tables of paper A (``data/five_cs.json``, transcribed from both OCR copies)."""
    with resources.files(__package__).joinpath("data/five_cs.json").open("r", encoding="utf-8") as fh:
        return json.load(fh)


def five_cs_positions() -> tuple[Pose, ...]:
    """The seven task positions of table 9: ``A = Rz(gamma) Rx(alpha) Ry(beta)`` ("ZXY")."""
    P = np.array(five_cs_data()["poses_table9"]["P"], dtype=float)
    return tuple(
        Pose.from_euler("ZXY", [row[5], row[3], row[4]], row[:3], degrees=True, name=f"P{i + 1}")
        for i, row in enumerate(P)
    )


def five_cs(which: int) -> Mechanism:
    """Paper A: 5-CS rigid-body guidance linkage number ``which`` (1, 2 or 3)."""
    data = five_cs_data()["linkages"][str(which)]
    positions = five_cs_positions()
    limbs = []
    aliases = {}
    for i in range(5):
        u = np.asarray(data["u"][i], dtype=float)
        B = np.asarray(data["B1"][i], dtype=float)
        M = np.asarray(data["M_by_position"][0][i], dtype=float)
        limbs.append(
            Limb(
                f"limb{i + 1}",
                (C(f"C{i + 1}", B, u, normalize=True, actuated=["rot"] if i == 0 else False), S(f"S{i + 1}", M)),
            )
        )
        aliases[f"rot{i + 1}"] = f"C{i + 1}.rot"
        aliases[f"slide{i + 1}"] = f"C{i + 1}.slide"
    return Mechanism(
        name=f"five-cs-{which}",
        limbs=tuple(limbs),
        platform_point=positions[0].p,
        description=f"Paper A: 5-CS rigid-body guidance linkage {which} (tables {data['tables']}) with its 7 task positions",
        positions=positions,
        aliases=aliases,
        length_unit="unit",
        source="paper A (seeds 000/001)",
        notes="Reference configuration = task position P1 (slides zero, identity orientation). "
        "Axes u normalised (printed to 3 decimals). Drivers rot1..rot5 / slide1..slide5.",
    )
