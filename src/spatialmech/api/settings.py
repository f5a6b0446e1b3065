"""The public API: the settings a run is made with -- the tolerances in force and the notice of
numba compilations (``sm.tolerances``, ``sm.default_tolerance``, ``sm.announce_compilation``)."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager

from ..errors import InputError, describe
from ..geometry import tolerances as _tol


@contextmanager
def tolerances(spec=None, *, primary: str = "rank") -> Iterator[_tol.Tolerances]:
    """Run a block with other tolerances (docs/conventions.md, Tolerances); a context manager.

    Parameters
    ----------
    spec : Tolerances, float, str or None
        ``None``: the tolerances in force; a :class:`~spatialmech.geometry.tolerances.Tolerances`;
        a number (nondimensional, sets ``primary``); or the text ``NAME=VALUE[,NAME=VALUE]`` (what
        ``--tol`` takes; a bare number sets ``primary``).
    primary : str
        The tolerance a bare number sets (``"rank"``, ``"singular"``, ``"newton"``, ...).

    Returns
    -------
    Iterator[Tolerances]
        Used as ``with sm.tolerances(...) as t``: ``t`` is the tolerances in force inside the block
        (the previous ones are restored on exit).

    Raises
    ------
    TypeError
        ``primary`` is not a str.
    InputError
        ``spec`` of another type, an unknown tolerance name or a value out of its range.

    Examples
    --------
    >>> import spatialmech as sm
    >>> with sm.tolerances("1e-4", primary="rank") as t:
    ...     t.rank, sm.mobility("four-sps-cu").dof
    (0.0001, 4)
    >>> sm.default_tolerance("rank") == 1e-4
    False
    """
    if not isinstance(primary, str):
        raise TypeError(f"primary: expected a tolerance name (str), got {describe(primary)}")
    t: _tol.Tolerances | None
    if isinstance(spec, str):
        t = _tol.Tolerances.parse(spec, primary=primary)
    elif spec is None or isinstance(spec, _tol.Tolerances):
        t = spec
    else:
        t = _tol.resolve(spec, primary)
    with _tol.use(t) as inside:
        yield inside


def default_tolerance(name: str) -> float:
    """The library's default value of one tolerance, as printed by ``--help``.

    Parameters
    ----------
    name : str
        ``"rank"``, ``"singular"``, ``"newton"``, ``"reachability"`` ... (the fields of
        :class:`~spatialmech.geometry.tolerances.Tolerances`).

    Returns
    -------
    float
        The default value (nondimensional).

    Raises
    ------
    TypeError
        ``name`` is not a str.
    InputError
        An unknown tolerance name.

    Examples
    --------
    >>> import spatialmech as sm
    >>> sm.default_tolerance("singular") > 0
    True
    """
    if not isinstance(name, str):
        raise TypeError(f"name: expected a tolerance name (str), got {describe(name)}")
    value = getattr(_tol.DEFAULT, name, None)
    if not isinstance(value, float):
        raise InputError(f"name: unknown tolerance {name!r}")
    return value


def _check_stream(stream) -> None:
    """``TypeError`` unless ``stream`` is None or has a ``write`` method."""
    if stream is not None and not callable(getattr(stream, "write", None)):
        raise TypeError(f"stream: expected a text stream (with a write method) or None, got {describe(stream)}")


def announce_compilation(stream) -> bool:
    """Announce numba compilations: one line per kernel that compiles (a miss of the on-disk
    cache: the first use after installation), with its seconds.

    Parameters
    ----------
    stream : text stream or None
        Where the lines go (e.g. ``sys.stderr`` when it is a terminal); ``None`` removes the
        listener.

    Returns
    -------
    bool
        Whether a listener is installed.

    Raises
    ------
    TypeError
        ``stream`` has no ``write`` method.

    Examples
    --------
    >>> import spatialmech as sm
    >>> sm.announce_compilation(None)
    False
    """
    from ..kinematics.compiled.jit import announce_compilation as _announce

    _check_stream(stream)
    return _announce(stream)


def first_run(stream) -> bool:
    """On a machine where the numba kernels were never compiled (a fresh install): start their
    compilation in a background process, say so in one line on ``stream``, and run the rest of
    this process on the pure-Python reference engine (same results), so that a first command
    answers in seconds instead of waiting for the compiler.  Later processes find the kernels
    compiled and run them.  ``SPATIALMECH_BACKGROUND_COMPILE=0`` turns this off.

    Parameters
    ----------
    stream : text stream or None
        Where the one line goes (the command line passes ``sys.stderr``); ``None``: silent.

    Returns
    -------
    bool
        True when this process now runs on the Python reference engine.

    Raises
    ------
    TypeError
        ``stream`` has no ``write`` method.

    Examples
    --------
    >>> import os, spatialmech as sm
    >>> os.environ["SPATIALMECH_BACKGROUND_COMPILE"] = "0"
    >>> sm.first_run(None)
    False
    """
    from ..kinematics import backend
    from ..services import first_run as fr

    _check_stream(stream)
    if not fr.start(stream):
        return False
    backend.use_python_reference()
    return True
