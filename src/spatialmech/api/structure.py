"""The public API: the ready-made models, loading a model, and mobility (``sm.models``,
``sm.load_model``, ``sm.mobility``, ``sm.mobility_modes``)."""

from __future__ import annotations

from dataclasses import dataclass

from typing import TYPE_CHECKING

from .. import catalog
from ..errors import describe
from ..model.mechanism import Mechanism
from .checks import ModelLike, as_mechanism, check_int

if TYPE_CHECKING:
    from ..analysis.mobility import MobilityResult


# ============================================================================ models
def models() -> dict[str, str]:
    """The ready-made models (the catalogue).

    Returns
    -------
    dict[str, str]
        Model name -> one-line description.

    Examples
    --------
    >>> import spatialmech as sm
    >>> "bennett" in sm.models() and "four-sps-cu" in sm.models()
    True
    """
    return {n: catalog.describe(n) for n in catalog.names()}


def load_model(model: ModelLike, *, name: str | None = "model") -> Mechanism:
    """A mechanism from a ready-made name, a TOML file path, or a Mechanism (returned as is).

    An MJCF file (``.xml`` / ``.mjcf``, as ``spatialmech export`` writes) is read through the
    importer (:func:`spatialmech.exchange.from_mjcf`); a URDF is refused (no importer), the
    message pointing to the TOML and MJCF forms.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``), a TOML model file or an MJCF file.
    name : str or None
        The argument named in error messages; ``None`` names the value itself, as the command line
        does for its MODEL argument (``NAME: not a file and not a ready-made model``).

    Returns
    -------
    Mechanism
        The model (SI lengths in the model's length unit, radians).

    Raises
    ------
    TypeError
        ``model`` is not a Mechanism, str or path; ``name`` not a str or None.
    UnknownNameError
        Neither a file nor a ready-made model (the message lists the known ones).
    ModelFileError
        A malformed model file (naming the file and the field).

    Examples
    --------
    >>> import spatialmech as sm
    >>> mech = sm.load_model("rssr")
    >>> mech.name, mech.actuators
    ('rssr', ('A0.rot',))
    """
    if name is not None and not isinstance(name, str):
        raise TypeError(f"name: expected a str or None, got {describe(name)}")
    return as_mechanism(model, name)


# ============================================================================ mobility
def mobility(model: ModelLike, mode: str | None = None, *, seed: int = 0, tol=None) -> MobilityResult:
    """Mobility by the modified Kutzbach-Grübler formula, checked numerically.

    One motion mode of a metamorphic mechanism (``mode``); every mode: :func:`mobility_modes`.

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    mode : str, optional
        A motion mode of a metamorphic mechanism (default: its first / only one).
    seed : int
        The random seed of the generic configuration the rank is checked at.
    tol : Tolerances or float, optional
        A :class:`~spatialmech.geometry.tolerances.Tolerances` or the rank tolerance
        (nondimensional; default: the tolerances in force).

    Returns
    -------
    MobilityResult
        ``dof``, ``motion`` (e.g. ``"RxRyRzTz"``), the formula's terms, the numerical rank ...;
        ``to_dict()`` is its JSON.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> r = sm.mobility("four-sps-cu")
    >>> (r.dof, r.motion)
    (4, 'RxRyRzTz')
    """
    mech = as_mechanism(model)
    if mode is not None and not isinstance(mode, str):
        raise TypeError(f"mode: expected a mode name (str) or None, got {describe(mode)}")
    from ..analysis.mobility import mobility as _mobility

    return _mobility(mech, mode, seed=check_int(seed, "seed"), tol=tol)


@dataclass(frozen=True, eq=False)
class MobilityModes:
    """The mobility of every motion mode (a sequence of
    :class:`~spatialmech.analysis.mobility.MobilityResult`; one for an ordinary mechanism)."""

    mechanism: Mechanism
    modes: tuple[MobilityResult, ...]

    def __iter__(self):
        return iter(self.modes)

    def __len__(self) -> int:
        return len(self.modes)

    def __getitem__(self, k):
        return self.modes[k]

    def to_dict(self) -> dict:
        return {"metamorphic": self.mechanism.is_metamorphic, "modes": [r.to_dict() for r in self.modes]}


def mobility_modes(model: ModelLike, *, mode: str | None = None, seed: int = 0, tol=None) -> MobilityModes:
    """Mobility of every motion mode (one result for a mechanism that is not metamorphic).

    Parameters
    ----------
    model : Mechanism, str or path
        The mechanism, a ready-made model name (``sm.models()``) or a TOML model file.
    mode : str, optional
        Only this motion mode.
    seed : int
        The random seed of the generic configurations.
    tol : Tolerances or float, optional
        As in :func:`mobility`.

    Returns
    -------
    MobilityModes
        A sequence of :class:`~spatialmech.analysis.mobility.MobilityResult`; ``to_dict()`` is the
        payload of ``spatialmech mobility --json``.

    Raises
    ------
    TypeError
        An argument of the wrong type (named in the message).
    InputError
        A bad value (a ``ValueError``, the argument named); an unknown model name raises
        :class:`~spatialmech.UnknownNameError`, a malformed model file
        :class:`~spatialmech.ModelFileError` (both ``InputError``).

    Examples
    --------
    >>> import spatialmech as sm
    >>> [r.dof for r in sm.mobility_modes("three-rrr-sm")]
    [1, 1, 1, 2, 2, 2, 3]
    """
    mech = as_mechanism(model)
    seed = check_int(seed, "seed")
    if mode is not None:
        return MobilityModes(mech, (mobility(mech, mode, seed=seed, tol=tol),))
    from ..analysis.mobility import mobility_modes as _mobility_modes

    return MobilityModes(mech, tuple(_mobility_modes(mech, seed=seed, tol=tol)))
