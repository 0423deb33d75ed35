"""Atomic file output: a failed run never leaves a half-written file.

:func:`write_atomic` writes a temporary file beside the target and renames it
over the target, so an existing file is either replaced whole or left intact
(also under SIGINT and SIGTERM, which the CLI turns into the same interrupt:
:func:`vtool.app.cli.main.main`; SIGKILL can leave the hidden temporary, which
the next write to the same path removes). :func:`check_output_path` is the one
check of an output path, run by every command before any work: it refuses, in
one line (:class:`vtool.errors.InputError`), an empty path, a missing or
read-only folder, and a folder, device, FIFO, socket or symbolic link at the
path. A symbolic link is never followed: vtool opens files with ``O_NOFOLLOW``
and renames over the path itself, so a link another user plants in a shared
folder cannot redirect a write onto someone else's file (give the link's
target instead). A rewritten file keeps its permission bits (a 0600 file
stays 0600); a new one gets 0644 masked by the umask. A failure while
writing (a full disk) is a :class:`vtool.errors.RunError`; nothing partial is
left.

:func:`is_file`, :func:`is_dir`, :func:`exists` and :func:`is_symlink` probe a path a user
typed: a path the system cannot even look up (a name over 255 bytes, a NUL,
a component that is a file) is simply not there, never an ``OSError``.
"""

from __future__ import annotations

import contextlib
import errno
import glob
import os
import stat
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO, TextIO

from vtool.errors import InputError, RunError


def _probe(path: str | os.PathLike[str], test: str) -> bool:
    try:
        return bool(getattr(Path(path), test)())
    except (OSError, ValueError):  # ENAMETOOLONG, EACCES, an embedded NUL ...: not a usable path
        return False


def is_file(path: str | os.PathLike[str]) -> bool:
    """``Path.is_file`` that answers False where the system cannot look the path up."""
    return _probe(path, "is_file")


def is_dir(path: str | os.PathLike[str]) -> bool:
    """``Path.is_dir`` that answers False where the system cannot look the path up."""
    return _probe(path, "is_dir")


def exists(path: str | os.PathLike[str]) -> bool:
    """``Path.exists`` that answers False where the system cannot look the path up."""
    return _probe(path, "exists")


def is_symlink(path: str | os.PathLike[str]) -> bool:
    """``Path.is_symlink`` that answers False where the system cannot look the path up."""
    return _probe(path, "is_symlink")


#: Temporaries of a dead process (or older than this, in s, when it cannot be told) are removed.
STALE_AFTER = 3600.0


def _tmp_prefix(path: Path) -> str:
    return f".{path.name}."


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return True
    return True


def clean_stale_temporaries(path: str | os.PathLike[str]) -> list[Path]:
    """Remove hidden ``.NAME.PID.*.tmp`` files a killed write to ``path`` left; returns them."""
    path = Path(path)
    removed: list[Path] = []
    try:
        siblings = list(path.parent.glob(f"{glob.escape(_tmp_prefix(path))}*.tmp"))
    except OSError:
        return removed
    for tmp in siblings:
        middle = tmp.name[len(_tmp_prefix(path)):].split(".")[0]
        try:
            stale = (not _pid_alive(int(middle))) if middle.isdigit() else (
                time.time() - tmp.stat().st_mtime > STALE_AFTER)
            if stale:
                tmp.unlink()
                removed.append(tmp)
        except OSError:
            continue
    return removed


def check_output_path(path: str | os.PathLike[str], field: str = "output") -> Path:
    """``path`` if vtool may write a file there (see the module doc), else a one-line InputError."""
    if str(path) == "":
        raise InputError(field, "", "a file path")
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not is_dir(directory):
        raise InputError(field, str(path), f"a file in an existing folder ({directory} does not exist)")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise InputError(field, str(path), f"a file in a writable folder ({directory} is read-only)")
    try:
        mode = path.lstat().st_mode
    except FileNotFoundError:
        return path
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or "not a usable path"
        raise InputError(field, str(path), f"a writable file path ({reason})") from None
    if stat.S_ISLNK(mode):
        raise InputError(field, str(path), "a file path that is not a symbolic link (vtool does not write "
                         "through links; give the link's target)")
    if stat.S_ISDIR(mode):
        raise InputError(field, str(path), "a file path, not a folder")
    if not stat.S_ISREG(mode):
        raise InputError(field, str(path), "a regular file path (not a device, pipe or socket)")
    if not os.access(path, os.W_OK):
        raise InputError(field, str(path), "a writable file (this one is read-only)")
    return path


def open_no_follow(path: str | os.PathLike[str], flags: int, field: str = "output") -> int:
    """``os.open`` that refuses a symbolic link as the last component (``O_NOFOLLOW``), in one line."""
    try:
        return os.open(path, flags | os.O_NOFOLLOW | getattr(os, "O_CLOEXEC", 0), 0o644)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise InputError(field, str(path), "a file path that is not a symbolic link") from None
        raise InputError(field, str(path), f"a writable file path ({exc.strerror})") from None


def output_mode(path: str | os.PathLike[str]) -> int:
    """Permission bits for a file written at ``path``: the existing regular file's, else 0644 & ~umask."""
    try:
        st = os.lstat(path)
        if stat.S_ISREG(st.st_mode):
            return stat.S_IMODE(st.st_mode)
    except OSError:
        pass
    umask = os.umask(0)
    os.umask(umask)
    return 0o644 & ~umask


def write_atomic(path: str | os.PathLike[str], text: str, field: str = "output") -> None:
    """Write text to ``path`` through a temporary file and a rename (see module doc).

    A failure part-way leaves any existing file untouched and no partial file.
    """
    with open_atomic(path, field) as handle:
        handle.write(text)


@contextlib.contextmanager
def open_atomic(path: str | os.PathLike[str], field: str = "output") -> Iterator[TextIO]:
    """A text file handle whose content replaces ``path`` only when the block ends without error.

    For output written in pieces (a long CSV written block by block); the same
    checks and guarantees as :func:`write_atomic` (see the module doc).
    """
    target = check_output_path(path, field)
    directory = target.parent if str(target.parent) else Path(".")
    clean_stale_temporaries(target)
    prefix = f"{_tmp_prefix(target)}{os.getpid()}."
    tmp: str | None = None  # known once mkstemp returns; an interrupt can come between its making and then
    try:
        try:  # mkstemp opens with O_CREAT | O_EXCL: never through a link
            fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=directory)
        except OSError as exc:
            raise InputError(field, str(path), f"a file in a writable folder ({exc.strerror})") from None
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as handle:
            yield handle
            handle.flush()
            os.fchmod(handle.fileno(), output_mode(target))
        if is_symlink(target):  # planted after the check: rename would replace the link, refuse instead
            raise InputError(field, str(path), "a file path that is not a symbolic link")
        os.replace(tmp, target)  # rename never follows a link at the target
    except OSError as exc:
        _remove_temporary(directory, prefix, tmp)
        reason = "the disk is full" if exc.errno in (errno.ENOSPC, errno.EDQUOT) else exc.strerror
        raise RunError(f"could not write {path}: {reason}; nothing was written") from None
    except BaseException:
        _remove_temporary(directory, prefix, tmp)
        raise


def _remove_temporary(directory: Path, prefix: str, tmp: str | None) -> None:
    """Remove :func:`open_atomic`'s temporary file ``tmp``; when the write failed before its name was known
    (an interrupt just after mkstemp made it), every ``PREFIX*.tmp`` there: the prefix holds this process's
    id and the target's name, so they are this write's (tests/test_outputs.py's SIGTERM test left one
    behind about 1 run in 13)."""
    if tmp is not None:
        Path(tmp).unlink(missing_ok=True)
        return
    with contextlib.suppress(OSError):
        for made in directory.glob(f"{glob.escape(prefix)}*.tmp"):
            made.unlink(missing_ok=True)


def finite_json(data: object) -> tuple[object, list[str]]:
    """``data`` with every NaN or infinite float replaced by ``None``, and where each was.

    JSON has no NaN or Infinity; :func:`json_text` writes the places as
    ``"non_finite": ["clearances[2].peak_force: nan", ...]`` beside them.
    """
    import math

    places: list[str] = []

    def clean(value: object, where: str) -> object:
        if isinstance(value, float) and not math.isfinite(value):
            places.append(f"{where}: {value}")
            return None
        if isinstance(value, dict):
            return {k: clean(v, f"{where}.{k}" if where else str(k)) for k, v in value.items()}
        if isinstance(value, list | tuple):
            return [clean(v, f"{where}[{i}]") for i, v in enumerate(value)]
        if hasattr(value, "tolist") and hasattr(value, "dtype"):  # numpy scalars and arrays
            return clean(value.tolist(), where)
        return value

    return clean(data, ""), places


def json_text(data: object, indent: int | None = 2) -> str:
    """Strict JSON (no NaN/Infinity): non-finite numbers become null, listed under ``non_finite``."""
    import json

    cleaned, places = finite_json(data)
    if places and isinstance(cleaned, dict):
        cleaned["non_finite"] = places
    return json.dumps(cleaned, indent=indent, allow_nan=False)


@contextlib.contextmanager
def open_atomic_binary(path: str | os.PathLike[str], field: str = "output") -> Iterator[BinaryIO]:
    """A binary file handle with :func:`open_atomic`'s checks and guarantees (figures, PDF, Parquet).

    The bytes go to the same temporary file, renamed over ``path`` only when the
    block ends without error.
    """
    with open_atomic(path, field) as handle:
        handle.flush()
        yield handle.buffer  # the text handle's own binary layer: nothing was written through the text one


def write_atomic_bytes(path: str | os.PathLike[str], data: bytes, field: str = "output") -> None:
    """Write bytes to ``path`` atomically (see the module doc)."""
    with open_atomic_binary(path, field) as handle:
        handle.write(data)
