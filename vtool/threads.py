"""Small dense linear algebra runs single-threaded: threads cost more than they give on 8x8 matrices.

The valve train's matrices are 8x8 to 64x64; a multi-threaded BLAS spends more
time waking its threads than computing, and on a loaded machine much more
(the plate study 5.6x slower, the exact back end 4.3x). Runs therefore limit
BLAS/OpenMP to ``VTOOL_THREADS`` threads (default 1) while they compute;
set ``VTOOL_THREADS=0`` to leave the libraries' own defaults.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager


def thread_limit() -> int | None:
    """Threads a run may use for linear algebra: VTOOL_THREADS (default 1); None = no limit."""
    text = os.environ.get("VTOOL_THREADS", "1").strip()
    try:
        value = int(text)
    except ValueError:
        return 1
    return None if value <= 0 else value


@contextmanager
def limited() -> Iterator[None]:
    """Limit BLAS/OpenMP threads to :func:`thread_limit` inside the block."""
    limit = thread_limit()
    if limit is None:
        yield
        return
    with _controller().limit(limits=limit):
        yield


_CONTROLLERS: list = []


def _controller():  # type: ignore[no-untyped-def]
    """One ThreadpoolController per process (inspecting the loaded libraries costs about 30 ms)."""
    if not _CONTROLLERS:
        from threadpoolctl import ThreadpoolController

        _CONTROLLERS.append(ThreadpoolController())
    return _CONTROLLERS[0]
