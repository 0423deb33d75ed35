"""Where numba caches vtool's compiled kernels: a private per-user folder, named by the kernels' source.

:func:`configure` runs before numba is imported and sets ``NUMBA_CACHE_DIR``
to ``BASE/kernels-DIGEST``. BASE is the user's ``NUMBA_CACHE_DIR`` when set (a
``kernels-DIGEST`` folder there was exported by a parent process: its parent is
the base, so that sweep workers and subprocesses share the parent's cache), else
the first of ``$XDG_CACHE_HOME/vtool/numba``, ``~/.cache/vtool/numba``,
``<tempdir>/vtool-numba-<uid>`` that can be created; DIGEST is :func:`digest` of
:func:`kernel_sources`. A folder is used only when it is the user's own and not
writable by group or others (:func:`unsafe`; new ones are made 0700), else
nothing is cached, with one warning. Why (numba's index files are pickles; a
cached function holds its callees' code): docs/developer.md, "Compile".
``BASE/compile-seconds.json`` keeps each kernel's last compile time (:func:`last_compile`).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import stat
import sys
import tempfile
from collections.abc import Iterable
from pathlib import Path

#: False when no safe cache folder was found: kernels are compiled in every process.
CACHE_ENABLED = True
#: The folder numba caches in (``NUMBA_CACHE_DIR``), or None before :func:`configure` or without a cache.
FOLDER: Path | None = None
BASE: Path | None = None
TIMES = "compile-seconds.json"
#: The name of a cache folder in its base (see :func:`configure`).
KERNELS = re.compile(r"kernels-[0-9a-f]{16}")
_configured: list[str] = []


def candidates() -> list[Path]:
    """Base folders tried in order (the user's ``NUMBA_CACHE_DIR`` alone when set)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        given = Path(os.environ["NUMBA_CACHE_DIR"])
        return [given.parent if KERNELS.fullmatch(given.name) else given]
    xdg = os.environ.get("XDG_CACHE_HOME")
    folders = [Path(xdg) / "vtool" / "numba"] if xdg else []
    folders.append(Path.home() / ".cache" / "vtool" / "numba")
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    folders.append(Path(tempfile.gettempdir()) / f"vtool-numba-{uid}")
    return folders


def unsafe(folder: Path) -> str | None:
    """Why ``folder`` may not hold a cache (None when it may): not a directory of the user's own, or
    writable by group or others."""
    try:
        info = os.lstat(folder)
    except OSError as exc:
        return f"{folder}: {exc.strerror}"
    if not stat.S_ISDIR(info.st_mode):
        return f"{folder} is not a directory"
    if hasattr(os, "getuid") and info.st_uid != os.getuid():
        return f"{folder} is owned by another user (uid {info.st_uid})"
    if info.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
        return f"{folder} is writable by others (mode {stat.S_IMODE(info.st_mode):o})"
    return None


def _made(folder: Path) -> bool:
    """Create ``folder`` (0700, parents as the umask says) unless it exists; False when it cannot be."""
    try:
        folder.parent.mkdir(parents=True, exist_ok=True)
        folder.mkdir(mode=0o700)
    except FileExistsError:
        pass
    except OSError:
        return False
    return True


def digest(sources: Iterable[Path]) -> str:
    """The first 16 hex digits of the SHA-256 of the kernels' files, numba's version and Python's."""
    from importlib.metadata import version

    hashed = hashlib.sha256(f"{version('numba')}|{sys.version}".encode())
    for path in sorted(sources):
        info = path.stat()
        hashed.update(f"{path.name}|{info.st_size}|{info.st_mtime_ns}|".encode())
        hashed.update(path.read_bytes())
    return hashed.hexdigest()[:16]


def kernel_sources() -> list[Path]:
    """The files of vtool's compiled kernels: the decorator (``jit.py``), the CSV formatter
    (``csvrows_kernel.py``) and the Newmark kernel (``solvers/newmark/kernel/*.py`` with the layout
    and records it reads; beside vtool/ in the source tree, under it once installed)."""
    here = Path(__file__).resolve().parent
    newmark = here / "solvers" / "newmark"
    if not newmark.is_dir():
        newmark = here.parent / "solvers" / "newmark"
    return [here / "jit.py", here / "csvrows_kernel.py", newmark / "layout.py", newmark / "records.py",
            *sorted((newmark / "kernel").glob("*.py"))]


def configure(sources: Iterable[Path] | None = None) -> str:
    """Choose and set numba's cache folder for kernels compiled from ``sources`` (default
    :func:`kernel_sources`; see the module doc); returns the choice in words. Idempotent: later calls
    return the first answer."""
    global CACHE_ENABLED, FOLDER, BASE
    if _configured:
        return _configured[0]
    sources = kernel_sources() if sources is None else list(sources)
    problem = "no folder could be created"
    for base in candidates():
        if not _made(base):
            continue
        problem = unsafe(base) or ""
        folder = base / f"kernels-{digest(sources)}"
        if not problem and _made(folder):
            problem = unsafe(folder) or ""
        if problem:
            break
        FOLDER, BASE = folder, base
        os.environ["NUMBA_CACHE_DIR"] = str(folder)
        if "numba" in sys.modules:  # imported before: numba.config holds the setting it read then
            import numba

            numba.config.CACHE_DIR = str(folder)
        _configured.append(f"NUMBA_CACHE_DIR={folder}")
        return _configured[0]
    CACHE_ENABLED = False
    _configured.append(f"no cache ({problem})")
    print(f"warning: numba's cache is off ({problem}); the solver is compiled in every process "
          "(set NUMBA_CACHE_DIR to a folder of your own, not writable by others)", file=sys.stderr)
    return _configured[0]


def _times() -> dict:
    """The kept compile times by kernel ({} without a cache, or when the file is missing or damaged)."""
    try:
        times = json.loads((BASE / TIMES).read_text()) if BASE is not None else {}
    except (OSError, ValueError):
        return {}
    return times if isinstance(times, dict) else {}


def last_compile(name: str) -> float | None:
    """Seconds the last compile of kernel ``name`` took on this machine (any kernel source), or None."""
    value = _times().get(name)
    return float(value) if isinstance(value, int | float) and value > 0 else None


def record_compile(name: str, seconds: float) -> None:
    """Keep ``seconds`` as the last compile time of kernel ``name`` (written whole, then renamed)."""
    if BASE is None:
        return
    times = {**_times(), name: round(seconds, 2)}
    try:
        partial = BASE / f"{TIMES}.{os.getpid()}"
        partial.write_text(json.dumps(times))
        partial.replace(BASE / TIMES)
    except OSError:
        pass
