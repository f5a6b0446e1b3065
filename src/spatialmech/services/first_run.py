"""The first command after installation (issue 31): answer in seconds, compile in the background.

numba compiles a kernel on its first use and keeps it in an on-disk cache; on a fresh install the
first command waits for its kernels (15-17 s on a quiet machine, minutes on a busy one) although
the pure-Python reference engine (:mod:`..kinematics.backend`, same results) answers a single command in a
few seconds.  So, when the kernels have never been compiled here, the command line:

1. says so in one line (once: the line is printed by the process that starts the compilation);
2. starts one detached background process (``python -m spatialmech.services.first_run``) that
   compiles the common kernels into numba's cache and then writes a marker file;
3. runs its own command on the Python reference engine.

Later commands find the marker and run compiled.  The marker lives beside numba's cache: in
``NUMBA_CACHE_DIR`` when it is set (an empty one is a fresh install), else in the user's cache
directory, keyed by the package's location and the spatialmech and numba versions (an upgrade
compiles again, as numba does).  ``SPATIALMECH_BACKGROUND_COMPILE=0`` turns all of this off (the
command then compiles in the foreground, as before; the test suite does this).
"""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import time
from pathlib import Path

__all__ = ["BACKGROUND_ENV", "marker_path", "start", "warm"]

#: Set to ``0`` to compile in the foreground (no background process, no pure-Python first run).
BACKGROUND_ENV = "SPATIALMECH_BACKGROUND_COMPILE"
#: A lock older than this (s) is a warm-up that died: another process may start one.
_STALE_LOCK = 1800.0


def _key() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        ours = version("spatialmech")
    except PackageNotFoundError:  # pragma: no cover - a source tree that is not installed
        ours = "source"
    try:
        numba_version = version("numba")
    except PackageNotFoundError:  # pragma: no cover - no numba: nothing compiles
        numba_version = "none"
    where = str(Path(__file__).resolve().parent)
    return hashlib.sha256(f"{where}|{ours}|{numba_version}".encode()).hexdigest()[:16]


def marker_path() -> Path:
    """The file whose presence says that the kernels were compiled here."""
    base = os.environ.get("NUMBA_CACHE_DIR")
    root = Path(base) if base else Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "spatialmech"
    return root / f"spatialmech-kernels-{_key()}.done"


def _enabled() -> bool:
    value = os.environ.get(BACKGROUND_ENV, "1").strip().lower()
    return value not in ("0", "false", "no", "off")


def _take_lock(lock: Path) -> bool:
    try:
        lock.parent.mkdir(parents=True, exist_ok=True)
        fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
    except FileExistsError:
        try:
            if time.time() - lock.stat().st_mtime < _STALE_LOCK:
                return False  # another process is compiling
            lock.unlink()
        except OSError:
            return False
        return _take_lock(lock)
    except OSError:  # an unwritable cache directory: compile in the foreground
        return False
    os.close(fd)
    return True


def start(stream) -> bool:
    """On a machine where the kernels were never compiled: start the background compilation
    (one process at a time), write one line to ``stream`` (``None``: silent) and return True:
    the caller then runs on the Python reference engine.  False (the caller runs compiled): the
    kernels are compiled, numba is missing, the reference engine is already selected, or
    ``SPATIALMECH_BACKGROUND_COMPILE=0``."""
    import importlib.util

    from ..kinematics.backend import PURE_ENV

    pure = os.environ.get(PURE_ENV, "").strip() not in ("", "0")
    if not _enabled() or pure or importlib.util.find_spec("numba") is None:
        return False
    marker = marker_path()
    if marker.exists():
        return False
    lock = marker.with_suffix(".lock")
    started = _take_lock(lock)
    if started:
        env = {**os.environ, BACKGROUND_ENV: "0"}
        child = subprocess.Popen([sys.executable, "-m", "spatialmech.services.first_run", str(marker)], env=env,
                                 stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 start_new_session=True)
        lock.write_text(f"{child.pid}\n")  # who is compiling
    if stream is not None and started:
        print("spatialmech: first run here: numerical kernels are compiling in the background (once, about a "
              "minute); until then commands use the pure-Python engine (same results, slower on large jobs)",
              file=stream, flush=True)
    return True


def warm(marker: Path) -> None:
    """Compile the kernels the common commands use (the background process), then write the
    marker and remove the lock."""
    import spatialmech as sm

    from ..kinematics import compiled

    try:
        compiled.warm_up()
        sm.ik("four-sps-cu", ([0, 0, 0.12], ("ZYX", 34.38, -5.73, 11.46)), degrees=True)
        sm.fk("four-sps-cu", [0.2167, 0.2390, 0.2273, 0.2069], all_solutions=True)
        sm.fk("rssr", [30.0], degrees=True, all_solutions=True)
        sm.defects("five-cs-1")
        marker.parent.mkdir(parents=True, exist_ok=True)
        marker.write_text(f"compiled {time.strftime('%Y-%m-%dT%H:%M:%SZ', time.gmtime())}\n")
    finally:
        marker.with_suffix(".lock").unlink(missing_ok=True)


if __name__ == "__main__":
    warm(Path(sys.argv[1]))
