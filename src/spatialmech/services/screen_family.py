"""The CS dyad family of a screen, synthesised once per task and reused (issue 29).

A screen's family (:func:`~..synthesis.cs_dyads.synthesize_cs` of the seven positions, ``starts``
random starts, ``seed``) depends only on those, so it is stored

- with the dataset, ``OUT/_family.npz``: a resumed or repeated screen into ``OUT`` reads it;
- in the user's cache, ``$SPATIALMECH_CACHE_DIR`` (default ``$XDG_CACHE_HOME/spatialmech``, else
  ``~/.cache/spatialmech``), ``cs-families/<key>.npz``: a screen of the same task into another
  directory reads it.  ``SPATIALMECH_CACHE_DIR=off`` turns this cache off.

The key is a SHA-256 of the positions (to 1e-12), ``starts``, ``seed``, the file format and the
package version (a new version synthesises afresh).  The arrays round-trip exactly (float64 in
``.npz``, no pickle), so a screen from a stored family gives the same rows as one from a fresh
synthesis.  A file that cannot be read, or whose key differs, is ignored and replaced.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..results import BranchEnd
from ..synthesis.cs_dyads import CSBranch, CSFamily, CSTask, synthesize_cs

__all__ = ["CACHE_ENV", "FAMILY_FILE", "family_key", "load_family", "obtain_family", "save_family"]

#: Environment variable naming the cache directory (``off``: no cache outside the dataset).
CACHE_ENV = "SPATIALMECH_CACHE_DIR"
#: The family's file inside a screening dataset.
FAMILY_FILE = "_family.npz"
_FORMAT = "spatialmech-cs-family/1"


def family_key(task: CSTask, starts: int, seed: int) -> str:
    """The key of the family of ``task`` from ``starts`` random starts seeded with ``seed``."""
    from .. import __version__

    h = hashlib.sha256(f"{_FORMAT}|{__version__}|{int(starts)}|{int(seed)}".encode())
    for p in task.poses:
        h.update(np.round(np.asarray(p.R, dtype=float), 12).tobytes())
        h.update(np.round(np.asarray(p.p, dtype=float), 12).tobytes())
    return h.hexdigest()


def _cache_dir() -> Path | None:
    env = os.environ.get(CACHE_ENV)
    if env is not None:
        return None if env.strip().lower() in ("", "off", "0", "none") else Path(env)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "spatialmech"


def save_family(family: CSFamily, path: Path, key: str) -> None:
    """Write ``family`` (without its picks) to ``path`` atomically (a temporary file renamed)."""
    meta = {"format": _FORMAT, "key": key, "starts": family.starts, "extent": family.extent,
            "branches": [{"closed": bool(b.closed), "ends": [str(e) for e in b.ends], "residual": float(b.residual)}
                         for b in family.branches]}
    arrays: dict[str, Any] = {"meta": np.array(json.dumps(meta))}
    for k, b in enumerate(family.branches):
        arrays[f"points_{k}"] = np.asarray(b.points, dtype=np.float64)
        arrays[f"arc_{k}"] = np.asarray(b.arc, dtype=np.float64)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f"_tmp-{os.getpid()}-{path.name}")
    with open(tmp, "wb") as f:
        np.savez(f, **arrays)
    os.replace(tmp, path)


def load_family(path: Path, task: CSTask, key: str) -> CSFamily | None:
    """The family stored at ``path`` when it is there, readable and of ``key``; else ``None``."""
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"]))
            if meta.get("format") != _FORMAT or meta.get("key") != key:
                return None
            branches = tuple(
                CSBranch(np.array(z[f"points_{k}"]), np.array(z[f"arc_{k}"]), bool(b["closed"]),
                         (BranchEnd(b["ends"][0]), BranchEnd(b["ends"][1])), float(b["residual"]))
                for k, b in enumerate(meta["branches"]))
    except (OSError, ValueError, KeyError, TypeError) as e:  # a damaged file: synthesise afresh
        import warnings

        warnings.warn(f"ignoring the stored CS family {path} ({type(e).__name__}: {e})", RuntimeWarning, stacklevel=2)
        return None
    return CSFamily(task, branches, (), dict(meta["starts"]), float(meta["extent"]))


def obtain_family(task: CSTask, starts: int, seed: int, out: Path) -> tuple[CSFamily, str, str]:
    """The family of the screen into ``out``: ``(family, source, key)``, source ``"dataset"``
    (read from ``out``), ``"cache"`` (the user's cache) or ``"synthesised"`` (then written to the
    cache; the caller stores it with the dataset once ``out`` is prepared)."""
    key = family_key(task, starts, seed)
    cache = _cache_dir()
    cached = None if cache is None else cache / "cs-families" / f"{key}.npz"
    for where, path in (("dataset", out / FAMILY_FILE), ("cache", cached)):
        fam = None if path is None else load_family(path, task, key)
        if fam is not None:
            return fam, where, key
    fam = synthesize_cs(task, n_starts=int(starts), seed=seed, pick=0)
    if cached is not None:
        try:
            save_family(fam, cached, key)
        except OSError as e:  # a read-only home: the screen goes on, the next one synthesises again
            import warnings

            warnings.warn(f"cannot write the CS family cache {cached} ({e}); set {CACHE_ENV}", RuntimeWarning,
                          stacklevel=2)
    return fam, "synthesised", key
