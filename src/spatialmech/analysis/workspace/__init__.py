"""Workspace under joint limits: orientation workspace at a fixed position, position workspace at
a fixed orientation, for any model (paper B, section 6, eqs 16-22, generalised).

Pose coordinates
----------------
``x, y, z`` (m): the platform point ``p`` (:attr:`Mechanism.platform_point` at the reference)
in the base frame; ``alpha, beta, gamma`` (rad): the platform orientation

    R = Rz(gamma) Ry(beta) Rx(alpha)      # ORIENTATION_SEQUENCE = "ZYX", angles (gamma, beta, alpha)

which is paper B's eq 7 (and the matrix printed with eq 18).  ``alpha`` is about x, ``beta``
about y, ``gamma`` about z.  Everything inside is SI and radians; :meth:`WorkspaceResult.to_dict`
is the edge and gives angles in degrees with ``_deg`` keys.

Limits (all optional, from the model and a :class:`WorkspaceLimits`)
--------------------------------------------------------------------
- every freedom's ``limits`` on its physical value ``offset + q`` (actuator strokes, the passive
  CU length: paper B eqs 16, 17);
- cone limits of spherical / universal joints (:class:`ConeLimit`, paper B eqs 18-20): the angle
  between the limb's link at the joint (oriented from the base towards the platform) and a
  reference axis fixed in the base or in the platform must not exceed ``max_angle``;
- link interference (eq 22): every limb's links (segments between consecutive distinct joint
  points) are capsules of the given diameter; two links of different limbs that do not share a
  joint interfere when their distance is below the mean of their diameters;
- closure: the pose must be reachable by every limb (e.g. the CU limb keeps the platform point
  on the Z axis).

Algorithm
---------
1. A pose-check kernel returns named *margins* (>= 0 inside) for stacks of poses.  The
   closed-form kernel (limbs S-P-S, U-P-S or C-U, as in the 4-SPS/CU and Gough-Stewart
   platforms) is vectorised (the SPS leg vectors of :mod:`..kinematics.closed_forms.sps`) and
   processed in chunks of ``chunk`` poses to bound memory; any other model uses the general
   kernel: one :func:`..kinematics.position.inverse_position` per pose (from the reference
   configuration, so the assembly branch is the one reached from it), then the same limits on
   the solved joint values and :func:`..kinematics.closure.joint_points`.  The result says
   which ``path`` was used.
2. The free coordinates are sampled on a regular grid (step ``<= step``; the fixed point lies on
   the grid when the bounds are symmetric about it).
3. Every change of feasibility between two neighbouring grid samples, along each grid
   direction, is refined by vectorised bisection to ``tol``; the limit violated just outside
   is the *active limit* of that boundary point.
4. Extents: of each coordinate alone (the others at their fixed value, on a 1-D line sampled at
   ``step`` and refined the same way) and over the whole set (min/max of the refined boundary
   points, then polished by SLSQP on the closed-form kernel's margins and accepted only when
   the kernel confirms the polished pose is feasible).  Accuracy: ``tol`` along the lines;
   a feasible island narrower than the grid step can be missed (stated in the result).
5. Volume: the refined feasible length of every grid line along the first free coordinate,
   integrated over the other coordinates by the trapezoid rule (units: product of the free
   coordinates' units, e.g. rad^3 of Euler-angle coordinates; not the Haar measure of SO(3)).

Paper B (:func:`paper_b_limits`): at ``z = 0.1 m`` with ``a = 0.1, b = 0.2 m`` the model gives
``alpha, beta in +-atan(z / b) = +-26.565 deg`` (platform-side spherical cone, eq 18) and
``gamma in +-128.682 deg`` (leg length 0.4 m: ``l^2 = 2a^2 + 2b^2 + z^2 - 4ab cos(gamma)``),
and the whole set has the same extents; the paper's 48 / 48 / 65 deg do not follow from its
stated model (docs/workspace.md).

Example::

    >>> import numpy as np
    >>> from spatialmech import catalog
    >>> ws = orientation_workspace(catalog.build("four-sps-cu"), at={"z": 0.1},
    ...                            limits=paper_b_limits(), step=np.radians(6))
    >>> round(float(np.degrees(ws.alone["alpha"].hi)), 3), ws.alone["alpha"].hi_limit
    (26.565, 'A1 cone')
"""

from __future__ import annotations

from .checker import ConfigurationChecker, PoseChecker, configuration_checker, pose_checker, segment_distance
from .limits import (
    COORDINATES,
    ORIENTATION_SEQUENCE,
    PAPER_B_LINK_DIAMETERS,
    ConeLimit,
    WorkspaceLimits,
    default_limits,
    paper_b_limits,
    with_freedom_limits,
)
from .search import MAX_POSES, MAX_POSES_GENERAL, Extent, WorkspaceResult, orientation_workspace, position_workspace
from .task import TASK_PATH, TaskWorkspaceResult, task_workspace

__all__ = [
    "COORDINATES",
    "MAX_POSES",
    "MAX_POSES_GENERAL",
    "ORIENTATION_SEQUENCE",
    "PAPER_B_LINK_DIAMETERS",
    "TASK_PATH",
    "ConeLimit",
    "ConfigurationChecker",
    "Extent",
    "PoseChecker",
    "TaskWorkspaceResult",
    "WorkspaceLimits",
    "WorkspaceResult",
    "configuration_checker",
    "default_limits",
    "orientation_workspace",
    "paper_b_limits",
    "pose_checker",
    "position_workspace",
    "segment_distance",
    "task_workspace",
    "with_freedom_limits",
]
