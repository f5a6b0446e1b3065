"""Certificates of the loop formulation's solutions (issue 27): the forward position of a model
whose limbs do not reduce to the Study quadrics (:mod:`.loop_system`, solved by monodromy in
:mod:`.general`) certified by the Krawczyk test of :mod:`.certify`.

The exact system is the loop formulation's *square* system ``G(x; p) = 0`` at the requested
actuator values: the circles ``c^2 + s^2 = 1`` (and Study quadrics and patches of the hubs in
Study parameters), then the closure equations times the random complex matrix that makes the
system square (:meth:`.loop_system.LoopSystem.square`); its floats (the twist matrices, the
actuators' ``cos``/``sin`` or slides over ``L``, the random combination) taken as exact data.
Every configuration of the mechanism is a root of ``G``; a certificate proves that the box about
a solution holds exactly one root of ``G`` and that the boxes of the solutions are disjoint:
distinct configurations, each an approximate zero with its own root.  (Whether a root of ``G``
closes every equation of the full closure is the engine's floating-point check: ``G`` also has
spurious roots, none near a certified solution's box unless it is that box's one root.)

Ball evaluation.  :class:`LoopBallSystem` runs the *same* formulas as the floating-point system
(:meth:`.loop_system.LoopSystem.square` with ``reference=True``) on NumPy object arrays of
python-flint ``acb`` balls: every operation is then carried out in ball arithmetic, the values at
the point and the Jacobian over the box (its forward-mode derivative formulas, an enclosure of
``G'`` over the box) enclosing the exact ones.  The coefficients are complex: no root is proven
real by this test (``real`` stays undecided).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from flint import acb, acb_mat

from .certify import Certificate, certify
from .loop_system import LoopSystem, variables

__all__ = ["LoopBallSystem", "certify_loop"]


class LoopBallSystem:
    """The square system of the loop formulation at the parameters ``p`` (the actuators), in
    ball arithmetic (module docstring); ``n`` unknowns, complex coefficients."""

    real = False

    def __init__(self, sysm: LoopSystem, p: np.ndarray) -> None:
        self._sysm = sysm
        self.n = int(sysm.nx)
        self._p = [acb(complex(v)) for v in np.asarray(p, dtype=complex)]
        self._W = np.array([[acb(complex(v)) for v in sysm.identity_offsets(1)[0]]], dtype=object)

    def _z(self, x) -> np.ndarray:
        Z = np.empty((1, self.n + len(self._p)), dtype=object)
        for i in range(self.n):
            Z[0, i] = acb(x[i, 0])
        Z[0, self.n:] = self._p
        return Z

    def _eval(self, x, want_J: bool):
        F, J = self._sysm.square(self._z(x), self._W, reference=True, want_J=want_J)
        return F, J

    def values(self, x):
        F, _ = self._eval(x, False)
        return acb_mat([[acb(v)] for v in F[0]])

    def jacobian(self, x):
        _, J = self._eval(x, True)
        return acb_mat([[acb(v) for v in row[: self.n]] for row in J[0]])

    def jacobian_float_many(self, Y: np.ndarray) -> np.ndarray:
        """``G'`` in floating point at the points ``Y`` (k, n) (the preconditioners only)."""
        Y = np.asarray(Y, dtype=complex)
        P = np.broadcast_to(np.asarray([complex(v.mid()) for v in self._p]), (len(Y), len(self._p)))
        W = self._sysm.identity_offsets(len(Y))
        _, J = self._sysm.square(np.hstack([Y, P]), W, reference=True)
        return J[:, :, : self.n]


def certify_loop(sysm: LoopSystem, p: np.ndarray, configs: Sequence) -> list[Certificate]:
    """Certificates of the configurations ``configs`` (:class:`..closure.Configuration`) as roots
    of the square system of ``sysm`` at the actuator parameters ``p``
    (:meth:`.loop_system.LoopSystem.parameters`)."""
    if not configs:
        return []
    X = np.array([variables(sysm, c)[: sysm.nx] for c in configs], dtype=complex)
    return list(certify(LoopBallSystem(sysm, p), X))
