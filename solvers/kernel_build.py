"""Compile the Newmark kernel into numba's cache in a child process, while the run goes on without it.

A new install's first run would otherwise wait for the compile (about
:data:`vtool.solvers.newmark.COMPILE_ESTIMATE_S` s on two cores) before its
first step. Instead :func:`start` launches ``python -m
vtool.solvers.kernel_build LOCK`` with the pickled argument types of
``run_chunk`` on its standard input and returns at once; the child compiles
``run_chunk`` for those types (numba writes its cache as it compiles), removes
the lock and exits. The parent never waits for it: between chunks it asks
numba's cache whether the kernel is there
(:func:`vtool.solvers.newmark_kernel.is_cached`) and then loads it.

One compile at a time: the lock file (in the temporary folder, named by the
kernel file's path, modification time and size, ``NUMBA_CACHE_DIR`` and the
argument types) is created exclusively and holds the child's process id, so
the workers of a sweep or several terminals started together launch one
child between them, and each can tell whether it still runs
(:func:`compiling`). A lock whose process is gone, or older than
:data:`STALE_S`, is replaced. A child that fails leaves a ``.failed`` file
beside the lock with its error; later runs then compile in their own process
(where the error shows) instead of starting it again.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import subprocess
import sys
import tempfile
import time
import traceback
from pathlib import Path
from typing import Any

#: A lock older than this (s) is from a child that did not finish; a new compile replaces it.
STALE_S = 600.0
_children: list[subprocess.Popen] = []  # type: ignore[type-arg]  # polled so that finished children are reaped


def lock_path(signature: tuple[Any, ...]) -> Path:
    """The lock file of a compile of ``run_chunk`` for these argument types (numba types)."""
    from vtool.solvers import newmark_kernel as kernel

    source = Path(kernel.__file__).resolve()
    stamp = source.stat()
    cache = os.environ.get("NUMBA_CACHE_DIR", "")
    key = f"{source}|{stamp.st_mtime_ns}|{stamp.st_size}|{cache}|{signature!r}".encode()
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    return Path(tempfile.gettempdir()) / f"vtool-kernel-{uid}-{hashlib.sha1(key).hexdigest()[:16]}.lock"


def failed_path(lock: Path) -> Path:
    return lock.with_suffix(".failed")


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # it exists, owned by someone else
        return True
    return True


def holder_alive(lock: Path) -> bool:
    """True when ``lock`` exists, is younger than :data:`STALE_S` and its process (if written yet) runs."""
    for child in _children[:]:
        if child.poll() is not None:
            _children.remove(child)  # reaped
    try:
        if time.time() - lock.stat().st_mtime >= STALE_S:
            return False
        text = lock.read_text().strip()
    except OSError:
        return False
    if not text:
        return True  # just created: the process id follows
    return text.isdigit() and _alive(int(text))


def _take(lock: Path) -> bool | None:
    """Create the lock: True if taken, False if a live compile holds it, None if no lock can be made."""
    for _ in range(2):
        try:
            os.close(os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
            return True
        except FileExistsError:
            if holder_alive(lock):
                return False
            try:
                lock.unlink()
            except FileNotFoundError:
                continue  # the child just finished: take it
            except OSError:
                return False
        except OSError:
            return None
    return False


def start(signature: tuple[Any, ...]) -> bool:
    """Start the child compile of ``run_chunk`` for ``signature`` unless one is running already.

    Returns True when a compile is under way (this call's or another
    process's), False when none could be started or an earlier one failed
    (the caller compiles itself).
    """
    lock = lock_path(signature)
    if failed_path(lock).exists():
        return False
    taken = _take(lock)
    if taken is False:
        return True
    try:
        child = subprocess.Popen([sys.executable, "-m", "vtool.solvers.kernel_build", str(lock)],
                                 stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 close_fds=True)
        assert child.stdin is not None
        child.stdin.write(pickle.dumps(signature))
        child.stdin.close()
    except OSError:  # no process to be had (or it died at once): the caller compiles in-process
        if taken:
            lock.unlink(missing_ok=True)
        return False
    _children.append(child)
    if taken:
        try:  # not O_CREAT: a child that has finished already has removed the lock
            descriptor = os.open(lock, os.O_WRONLY)
            os.write(descriptor, str(child.pid).encode())
            os.close(descriptor)
        except OSError:
            pass
    return True


def compiling(signature: tuple[Any, ...]) -> bool:
    """True while a child compile for ``signature`` (this process's or another's) is still running; a
    lock left by one that was killed is removed."""
    lock = lock_path(signature)
    if holder_alive(lock):
        return True
    lock.unlink(missing_ok=True)
    return False


def main(argv: list[str]) -> int:
    """The child: compile ``run_chunk`` for the pickled types on stdin; remove the lock ``argv[0]``."""
    lock = Path(argv[0]) if argv else None
    try:
        signature = pickle.loads(sys.stdin.buffer.read())
        from vtool.solvers import newmark_kernel as kernel

        kernel.run_chunk.compile(signature)
        return 0
    except BaseException:
        if lock is not None:
            try:
                failed_path(lock).write_text(traceback.format_exc())
            except OSError:
                pass
        raise
    finally:
        if lock is not None:
            lock.unlink(missing_ok=True)


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
