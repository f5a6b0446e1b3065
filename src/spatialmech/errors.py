"""The exceptions spatialmech raises on purpose, in one place.

Every error that a user can cause (a bad argument, a malformed file, an unknown name, an
unreachable pose, a search that would be too large) is an :class:`InputError`; a numerical
routine that did not reach its goal raises :class:`ConvergenceError`.  Both derive from
:class:`SpatialmechError` *and* from the built-in type a caller would expect (``ValueError``,
``KeyError``, ``RuntimeError``), so ``except ValueError`` keeps working.

The command line prints these as one line ``error: ...`` (exit code 2 for input errors, 1 for a
failed computation); any other exception is a programming error: exit code 3, and its traceback
under ``spatialmech --debug`` or ``SPATIALMECH_DEBUG=1`` (docs/index.md, "Errors and exit codes").

    >>> import spatialmech as sm
    >>> try:
    ...     sm.load_model("no-such-model")
    ... except sm.InputError as e:
    ...     print(type(e).__name__, isinstance(e, KeyError))
    UnknownNameError True
"""

from __future__ import annotations

__all__ = ["EXTRAS", "ConvergenceError", "InputError", "MissingExtraError", "SearchTooLargeError", "SpatialmechError",
           "UnknownNameError", "describe", "require"]


class SpatialmechError(Exception):
    """Base of every exception that spatialmech raises on purpose."""


class InputError(SpatialmechError, ValueError):
    """Bad input: the message is one line that names the argument or field and the problem."""


class UnknownNameError(InputError, KeyError):
    """A name (model, joint, freedom, mode, driver, link) that does not exist; lists the known ones."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


class SearchTooLargeError(InputError):
    """A requested search (modes, grid, candidates) exceeds its size limit; the message says the
    size and how to reduce it."""


#: The optional extras (``pip install 'spatialmech[EXTRA]'``, pyproject.toml) and the top-level
#: modules each one brings.  The core install (numpy, scipy, numba, pydantic, click, tomli-w,
#: threadpoolctl, python-flint) runs the model, mobility, kinematics, singularity, workspace,
#: defects and synthesis with text and JSON output; docs/install.md lists what needs which extra.
EXTRAS: dict[str, tuple[str, ...]] = {
    "plot": ("matplotlib", "plotly"),
    "studio": ("fastapi", "uvicorn", "starlette"),
    "sim": ("mujoco", "pinocchio"),
    "screen": ("dask", "distributed", "pyarrow"),
    "cad": ("build123d", "trimesh", "manifold3d"),
    "notebook": ("anywidget",),
}


class MissingExtraError(InputError, ImportError):
    """An optional dependency is not installed: the message names the extra that brings it
    (``pip install 'spatialmech[plot]'``); the command line exits with code 2."""

    def __init__(self, extra: str, module: str, what: str = ""):
        self.extra, self.module = extra, module
        need = f"{what} needs" if what else "this needs"
        super().__init__(f"{need} the optional extra '{extra}' ({module} is not installed): "
                         f"pip install 'spatialmech[{extra}]'")
        self.name = module  # ImportError's field: the module that did not import

    @classmethod
    def from_import_error(cls, error: BaseException) -> MissingExtraError | None:
        """The :class:`MissingExtraError` of an ``ImportError`` of a module that an extra brings,
        or ``None`` (another module, or not an import error)."""
        if isinstance(error, MissingExtraError):
            return error
        if not isinstance(error, ImportError) or not error.name:
            return None
        root = error.name.split(".")[0]
        extra = next((k for k, mods in EXTRAS.items() if root in mods), None)
        return None if extra is None else cls(extra, root)


def require(extra: str, *modules: str, what: str = "") -> None:
    """Check that the optional ``extra`` is installed by importing ``modules`` (default: the
    extra's first module, e.g. ``matplotlib`` for ``plot``); ``what`` names the feature in the
    message (``"--plot"``, ``"the studio"``).

    Raises
    ------
    MissingExtraError
        One of the modules does not import; the message names the extra to install.

        >>> require("plot", "matplotlib")
        >>> require("nope")
        Traceback (most recent call last):
        ...
        KeyError: "unknown extra 'nope'"
    """
    import importlib

    if extra not in EXTRAS:
        raise KeyError(f"unknown extra {extra!r}")
    for module in modules or EXTRAS[extra][:1]:
        try:
            importlib.import_module(module)
        except ImportError:
            raise MissingExtraError(extra, module, what) from None


class ConvergenceError(SpatialmechError, RuntimeError):
    """A numerical routine did not converge (the message says which and how far it got)."""


def describe(value) -> str:
    """What a value is, for an error message: its type and a short repr, or its shape.

        >>> describe("S"), describe([1, 2]), describe(None)
        ("str 'S'", 'list of length 2', 'None')
        >>> import numpy as np
        >>> describe(np.zeros((3, 4)))
        'ndarray of shape (3, 4)'
    """
    import reprlib

    if value is None:
        return "None"
    kind = type(value).__name__
    shape = getattr(value, "shape", None)
    if isinstance(shape, tuple) and not isinstance(value, (str, bytes)):
        return f"{kind} of shape {shape}"
    if isinstance(value, (list, tuple, dict, set, frozenset)):
        return f"{kind} of length {len(value)}"
    return f"{kind} {reprlib.repr(value)}"
