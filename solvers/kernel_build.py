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
argument types) is
created exclusively, so the workers of a sweep or several terminals started
together launch one child between them. A lock older than :data:`STALE_S` is
from a child that died and is replaced. The child's output goes nowhere; if it
fails, the run simply finishes without it and the next run tries again.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import subprocess
import sys
import tempfile
import time
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


def _take(lock: Path) -> bool | None:
    """Create the lock: True if taken, False if a live compile holds it, None if no lock can be made."""
    for _ in range(2):
        try:
            os.close(os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
            return True
        except FileExistsError:
            try:
                if time.time() - lock.stat().st_mtime < STALE_S:
                    return False
                lock.unlink()
            except FileNotFoundError:
                continue  # the child just finished: take it
            except OSError:
                return False
        except OSError:
            return None
    return False


def running() -> bool:
    """True while a child this process started is still compiling."""
    alive = [child for child in _children if child.poll() is None]
    _children[:] = alive
    return bool(alive)


def start(signature: tuple[Any, ...]) -> bool:
    """Start the child compile of ``run_chunk`` for ``signature`` unless one is running already.

    Returns True when a compile is under way (this call's or another
    process's), False when none could be started (the caller compiles itself).
    """
    lock = lock_path(signature)
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
    return True


def main(argv: list[str]) -> int:
    """The child: compile ``run_chunk`` for the pickled types on stdin; remove the lock ``argv[0]``."""
    lock = Path(argv[0]) if argv else None
    try:
        signature = pickle.loads(sys.stdin.buffer.read())
        from vtool.solvers import newmark_kernel as kernel

        kernel.run_chunk.compile(signature)
        return 0
    finally:
        if lock is not None:
            lock.unlink(missing_ok=True)


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
