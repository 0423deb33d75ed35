"""Thread limits for the small dense linear algebra of a run.

vtool's matrices are small (8x8 to 64x64). A multi-threaded BLAS (OpenBLAS,
MKL) starts its thread pool for every product and solve, and on a loaded
2-core machine the hand-offs cost more than the arithmetic: the plate study
ran 5.6x slower and the exact back end 4.3x slower with the default threads.
So a run limits the BLAS and OpenMP pools to one thread while it runs:

    with vtool.threads.limited():
        ...

or as a decorator, ``@vtool.threads.limited()``. The pools are restored on
exit (threadpoolctl).

The environment variable ``VTOOL_THREADS`` overrides the default of 1: a
positive integer is the thread count, ``0`` or ``default`` leaves the
libraries' own settings untouched (e.g. for a large plate mesh on an idle
many-core machine). Any other value is an input error naming the variable.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

from vtool.errors import InputError

ENVIRONMENT = "VTOOL_THREADS"
DEFAULT = 1


def thread_limit(value: str | None = None) -> int | None:
    """Threads allowed to BLAS/OpenMP: from ``value`` (default: $VTOOL_THREADS); None = no limit."""
    if value is None:
        value = os.environ.get(ENVIRONMENT)
    if value is None or value.strip() == "":
        return DEFAULT
    text = value.strip().lower()
    if text in ("0", "default"):
        return None
    try:
        count = int(text)
    except ValueError:
        count = -1
    if count < 1 or count > 1024:
        raise InputError(ENVIRONMENT, value, "1 to 1024 threads, or 0 / default for the libraries' "
                         "own setting")
    return count


@contextmanager
def limited(threads: int | None = None) -> Iterator[None]:
    """Limit BLAS/OpenMP pools to ``threads`` (default: :func:`thread_limit`) inside the block.

    Usable as a context manager or a decorator (``@limited()``).
    """
    count = thread_limit() if threads is None else threads
    if count is None:
        yield
        return
    # each pool set and restored by hand, and only where it differs: threadpoolctl's own limit() (the
    # same settings) took about 0.05 ms a block, a tenth of the Python around a warm 1A run
    changed = []
    for library in _controller().lib_controllers:
        before = library.num_threads
        if before != count:
            library.set_num_threads(count)
            changed.append((library, before))
    try:
        yield
    finally:
        for library, before in reversed(changed):
            library.set_num_threads(before)


_CONTROLLERS: list = []


def _controller():
    """One ThreadpoolController per process: inspecting the loaded libraries costs about 30 ms,
    limiting with it afterwards about 0.1 ms."""
    if not _CONTROLLERS:
        from threadpoolctl import (
            ThreadpoolController,  # imported lazily: a small import, but not free
        )

        _CONTROLLERS.append(ThreadpoolController())
    return _CONTROLLERS[0]
