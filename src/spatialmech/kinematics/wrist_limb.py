"""Every inverse solution of a six-joint limb with a spherical wrist, by decoupling.

A limb of six joints from the ground to the output link whose last three are revolutes with
axes through one point ``c`` (a spherical wrist: the Stanford arm, most industrial arms) splits
in two (Pieper 1968):

1. **position**: the output displacement ``D`` places the wrist centre at ``D c``; the first
   three joints must bring ``c`` there.  That is the limb's first three joints followed by an S
   joint at ``c``: solved by the limb homotopy (``kind = "point"``, a square system of three
   freedoms) and proven complete by its root count (three revolutes: Pieper's quartic, 4) or by
   the trace test (any other three joints: a few seconds the first time, cached per geometry);
2. **orientation**: for each wrist-centre solution the wrist must turn by
   ``(E1 E2 E3)^-1 D``, a rotation about ``c``: the spherical 3R closed form
   (:mod:`.closed_forms.spherical_3r_limb`), at most two configurations, both found.

So the limb's solutions are the products, and the set is complete when step 1 is proven and no
wrist pose is a continuum.  A 6R with such a wrist (the PUMA 560) is already proven by the 6R
root count (8); this serves the limbs with a slide among the first three joints, whose six-joint
homotopy has no known root count (its trace test runs for minutes and may be inconclusive).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.joints import S
from ..model.mechanism import GROUND, Limb, Mechanism, Pose
from .closed_forms import spherical_3r_limb as s3r
from .closure import chain_forward, limb_chains

__all__ = ["WristSplit", "solve", "wrist_split"]


@dataclass(frozen=True, eq=False)
class WristSplit:
    """The positioning limb (the first three joints and an S joint at the wrist centre, as its
    own mechanism) and the wrist (:class:`~.closed_forms.spherical_3r_limb.Spherical3R`)."""

    position: Mechanism
    wrist: s3r.Spherical3R


def wrist_split(mech: Mechanism, li: int) -> WristSplit | None:
    """Limb ``li`` split at a spherical wrist, or ``None``: not six unlocked one-freedom joints
    (R of pitch 0 or P) from the ground to the output link, the first three all revolute (a 6R:
    its own root count proves it), or the last three axes not a spherical 3R."""
    limb = mech.limbs[li]
    if limb.base != GROUND or limb.tip not in (None, mech.output) or len(limb.joints) != 6:
        return None
    if any(j.type not in ("R", "P") or j.freedoms[0].locked or j.freedoms[0].pitch != 0.0 for j in limb.joints):
        return None
    if all(j.type == "R" for j in limb.joints[:3]) or any(j.type != "R" for j in limb.joints[3:]):
        return None
    wrist = s3r.spherical_axes(limb_chains(mech)[li].screws[3:])
    if wrist is None:
        return None
    arm = Limb("arm", (*limb.joints[:3], S("wrist_centre", wrist.centre)))
    position = Mechanism(f"{mech.name} (wrist centre)", (arm,), platform_point=wrist.centre,
                         length_unit=mech.length_unit)
    return WristSplit(position, wrist)


def solve(mech: Mechanism, li: int, split: WristSplit, D: np.ndarray, seed: int = 0
          ) -> tuple[list[np.ndarray], str, bool]:
    """The real configurations of limb ``li`` at the output displacement ``D`` (4x4), the
    statement, and whether the set is proven complete."""
    from .position import inverse_position  # the positioning limb is solved by the same front

    c = split.wrist.centre
    target = D[:3, :3] @ c + D[:3, 3]
    pos = inverse_position(split.position, Pose(np.eye(3), target), all_solutions=True, method="homotopy",
                           seed=seed)
    rep = pos.search["limbs"][0]
    ch = limb_chains(mech)[li]
    L = mech.characteristic_length
    out: list[np.ndarray] = []
    continuum = False
    for q3 in pos.limbs[0].solutions if pos.reachable else ():
        q = np.r_[np.asarray(q3, dtype=float)[:3], 0.0, 0.0, 0.0]
        T, _ = chain_forward(ch, q)
        Dw = np.linalg.solve(T, D)
        wrists, _, proven = s3r.solve(split.wrist, Dw, L)
        continuum |= not proven
        out += [np.r_[q[:3], w] for w in wrists]
    head = ("decoupled at the spherical wrist (the last three axes meet at one point): the wrist centre's "
            f"positions by the limb homotopy ({rep['completeness']}), times the wrist's orientations in closed form "
            "(Paden-Kahan: at most 2 for each)")
    if continuum:
        return out, f"NOT proven: {head}; but at one wrist-centre solution the wrist turns in a continuum", False
    if not rep["complete"]:
        return out, f"NOT proven: {head}", False
    return out, f"complete (proven, with probability one): {head}: {len(out)} real", True
