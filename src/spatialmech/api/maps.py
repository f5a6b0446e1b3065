"""The public API: performance maps over a workspace grid (``sm.maps``)."""

from __future__ import annotations

from collections.abc import Mapping

from ..analysis.maps import INDICES, MapResult, performance_map
from ..analysis.workspace import WorkspaceLimits
from ..errors import InputError
from .checks import ModelLike, as_mechanism, check_choice, check_grid, check_names
from .threads import one_blas_thread

__all__ = ["MapResult", "maps"]


@one_blas_thread
def maps(model: ModelLike, *, kind: str = "position", over: Mapping, at: Mapping[str, float] | None = None,
         indices=None, limits: WorkspaceLimits | None = None, method: str = "auto") -> MapResult:
    """Performance maps: kinetostatic indices at every pose of a grid (docs/maps.md).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism (its complete Jacobian must be 6 x 6: constraint rows + actuators = 6).
    kind : {"position", "orientation"}
        ``"position"``: ``over`` grids ``x, y, z`` (length) at a fixed orientation;
        ``"orientation"``: ``over`` grids ``alpha, beta, gamma`` (rad, ``R = Rz(gamma) Ry(beta)
        Rx(alpha)``) at a fixed position.
    over : mapping
        1 to 3 coordinates, each to ``(lo, hi, n)`` or to its values (SI, rad).
    at : mapping, optional
        The other coordinates (default: the reference platform point, no rotation).
    indices : list of str, optional
        The indices kept (default: all that apply): ``sigma_min``, ``condition``,
        ``manipulability``, ``iti``, ``oti``, ``lti``, ``lci`` (with constraint wrenches only),
        ``velocity_axes``, ``force_axes``.
    limits : WorkspaceLimits, optional
        Default: the model's (:func:`~spatialmech.analysis.workspace.default_limits`).
    method : {"auto", "loop", "batched"}
        ``"auto"``: compiled and batched when the engine is on; ``"loop"``: the per-pose Python
        reference.

    Returns
    -------
    MapResult
        Grid axes, index arrays (nondimensional, characteristic length
        :attr:`~MapResult.characteristic_length`), a status per cell; ``to_dict()`` is the JSON
        of ``spatialmech maps --json``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (the argument named): an unknown model, coordinate or index, a grid too
        large, a Jacobian that is not 6 x 6.

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.maps("stewart-6sps", over={"x": (-0.1, 0.1, 3), "y": (-0.1, 0.1, 3)})
    >>> r.shape, r.status_counts()["ok"], float(r.values["iti"].min())
    ((3, 3), 9, 1.0)
    >>> round(float(r.values["sigma_min"][1, 1]), 6) == round(sm.jacobian("stewart-6sps").sigma_min, 6)
    True
    """
    mech = as_mechanism(model)
    kind = check_choice(kind, "kind", ("position", "orientation"))
    method = check_choice(method, "method", ("auto", "loop", "batched"))
    check_grid(over, at, limits)
    names = check_names(indices, "indices")
    if names is not None:
        for n in names:
            if n not in INDICES:
                raise InputError(f"indices: unknown index {n!r}; expected some of {', '.join(INDICES)}")
    return performance_map(mech, kind=kind, over=over, at=at, limits=limits, indices=names, method=method)
