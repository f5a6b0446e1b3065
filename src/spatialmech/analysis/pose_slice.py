"""A pose slice that follows the given pose's working mode.

A slice of ``det J`` over two pose coordinates (:func:`~spatialmech.analysis.singularity.singularity_slice`)
is only a map of singularities when every grid point is on the same branch: the same
assembly and the same *working mode* (inverse-position branch) of every limb.  A limb with a
6-freedom chain (a 6-RUS crank, U and S) closes a pose in two ways (elbow up / down); Newton from
a far start, or a restart, may take the other, and ``det J`` then changes sign between grid
points with no singularity between them.

:func:`follow_grid` therefore starts at the given pose's configuration (the one ``sm.jacobian``
analyses), solves the grid point nearest to it by continuation, and grows the solved set
neighbour to neighbour (breadth first): each point is solved from a solved neighbour's
configuration, directly and, if that fails or lands on another branch, by continuation along
the straight pose path in :data:`SUBSTEPS` steps.  A point is on the branch when its working-mode
signature (:func:`mode_signature`) is the start's and no joint moved by more than
:data:`MAX_JOINT_JUMP` from the neighbour.  Points on another branch are ``SWITCHED``, points
where no closed configuration was found ``UNREACHED``; both are masked (``det`` is ``nan``
there), so no zero contour is drawn across a branch switch.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

import numpy as np

from ..geometry.tolerances import current
from ..kinematics.backend import joint_twists
from ..kinematics.closure import Configuration
from ..kinematics.position import configuration_at_pose
from ..kinematics.task import joint_change
from ..model.mechanism import Mechanism, Pose

__all__ = ["FOLLOWED", "MAX_JOINT_JUMP", "SUBSTEPS", "SWITCHED", "UNREACHED", "follow_grid", "mode_signature"]

#: Branch codes of the grid points: on the given pose's branch, on another one, not solved.
FOLLOWED, SWITCHED, UNREACHED = 0, 1, -1
#: Continuation steps between two neighbouring grid points when the direct solve fails.
SUBSTEPS = 4
#: Largest change of any joint (rad; slides in characteristic lengths) between neighbouring grid
#: points on one branch (a larger one is a jump to another branch).
MAX_JOINT_JUMP = 1.0


def mode_signature(mech: Mechanism, config: Configuration) -> tuple[int, ...]:
    """The working mode of each limb whose chain has six active freedoms: the sign of the
    determinant of its nondimensional joint twists (moments / L, each twist normalised), 0 where
    it is within the ``singular`` tolerance (the limb at an inverse singularity: undecided);
    limbs of another size give 0.  The sign changes exactly where the limb passes an inverse
    singularity, so two configurations with different signatures are on different branches."""
    L = mech.characteristic_length
    out = []
    refs = mech.freedom_refs
    start = 0
    for T in joint_twists(mech, config):
        n = T.shape[1]
        active = [i for i in range(n) if not refs[start + i].freedom.locked]
        start += n
        if len(active) != 6:
            out.append(0)
            continue
        M = np.array(T[:, active], dtype=float)
        M[3:] /= L
        M /= np.maximum(np.linalg.norm(M, axis=0), 1e-300)
        d = float(np.linalg.det(M))
        out.append(0 if abs(d) < current().singular else (1 if d > 0 else -1))
    return tuple(out)


def _same_mode(a: tuple[int, ...], b: tuple[int, ...]) -> bool:
    return all(x == y or x == 0 or y == 0 for x, y in zip(a, b, strict=True))


def _blend(p: Pose, q: Pose, s: float) -> Pose:
    """The pose a fraction ``s`` of the way from ``p`` to ``q`` (position linear, rotation along
    the geodesic)."""
    from scipy.spatial.transform import Rotation

    rel = Rotation.from_matrix(p.R.T @ q.R).as_rotvec()
    return Pose(p.R @ Rotation.from_rotvec(s * rel).as_matrix(), (1 - s) * np.asarray(p.p) + s * np.asarray(q.p))


def _solve(mech: Mechanism, pose: Pose, seed: Configuration) -> Configuration | None:
    fit = configuration_at_pose(mech, pose, start=seed, n_restarts=0)
    return fit.config if fit.converged and fit.exact else None


def _follow(mech: Mechanism, p_from: Pose, c_from: Configuration, p_to: Pose, mode) -> tuple[int, Configuration | None]:
    """Solve ``p_to`` from the neighbour ``(p_from, c_from)`` on the branch ``mode``: directly,
    else by :data:`SUBSTEPS` continuation steps.  ``(code, configuration)``."""
    other = None
    c = _solve(mech, p_to, c_from)
    if c is not None:
        if _same_mode(mode, mode_signature(mech, c)) and joint_change(mech, c_from, c) <= MAX_JOINT_JUMP:
            return FOLLOWED, c
        other = c
    cur = c_from
    for k in range(1, SUBSTEPS + 1):
        nxt = _solve(mech, _blend(p_from, p_to, k / SUBSTEPS), cur)
        if nxt is None or joint_change(mech, cur, nxt) > MAX_JOINT_JUMP or not _same_mode(mode, mode_signature(mech, nxt)):
            return (SWITCHED, other) if other is not None else (UNREACHED, None)
        cur = nxt
    return FOLLOWED, cur


def follow_grid(mech: Mechanism, pose_of: Callable[[float, float], Pose], u: np.ndarray, v: np.ndarray,
                start_pose: Pose, start: Configuration, progress: Callable | None = None) -> tuple[np.ndarray, np.ndarray, tuple]:
    """Configurations over the grid ``pose_of(u_i, v_j)`` on the branch of ``start`` (the closed
    configuration at ``start_pose``), and the branch code of each point (``FOLLOWED``,
    ``SWITCHED``, ``UNREACHED``); both arrays of shape (len(v), len(u)); and the (row, column)
    the grid was entered at, the point nearest ``start_pose``.  See the module
    docstring.  ``progress(done, total, "slice")`` every grid row's worth of points."""
    nv, nu = len(v), len(u)
    configs = np.empty((nv, nu), dtype=object)
    code = np.full((nv, nu), UNREACHED, dtype=int)
    tried = np.zeros((nv, nu), dtype=int)
    mode = mode_signature(mech, start)
    poses = {(j, i): pose_of(u[i], v[j]) for j in range(nv) for i in range(nu)}
    L = mech.characteristic_length

    def dist(j: int, i: int) -> float:
        p = poses[(j, i)]
        rel = np.clip((np.trace(start_pose.R.T @ p.R) - 1) / 2, -1.0, 1.0)
        return float(np.linalg.norm(p.p - start_pose.p)) / L + float(np.arccos(rel))

    j0, i0 = min(poses, key=lambda k: dist(*k))
    c0, x0 = _follow(mech, start_pose, start, poses[(j0, i0)], mode)
    code[j0, i0] = c0
    configs[j0, i0] = x0
    queue = deque([(j0, i0)] if c0 == FOLLOWED else [])
    done = 0
    while queue:
        j, i = queue.popleft()
        for jj, ii in ((j, i - 1), (j, i + 1), (j - 1, i), (j + 1, i)):
            if not (0 <= jj < nv and 0 <= ii < nu) or code[jj, ii] == FOLLOWED or tried[jj, ii] >= 4:
                continue
            tried[jj, ii] += 1
            c, x = _follow(mech, poses[(j, i)], configs[j, i], poses[(jj, ii)], mode)
            if c == FOLLOWED or code[jj, ii] == UNREACHED:
                code[jj, ii], configs[jj, ii] = c, x
            if c == FOLLOWED:
                queue.append((jj, ii))
            done += 1
            if progress is not None and done % max(nu, 1) == 0:
                progress(min(done // max(nu, 1), nv), nv, "slice")
    return configs, code, (j0, i0)
