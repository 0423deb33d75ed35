"""The one decorator of vtool's compiled kernels, and what a first run says about their compile.

``jit`` is numba's ``njit`` with ``cache=True`` (when :mod:`vtool.numba_cache`
found a safe folder), ``nogil=True`` (a sweep's threads run in parallel) and
numpy's error model (a division by zero gives inf, as the plain-NumPy
reference does); ``jit_inline`` is the same, copied into its callers
(``inline="always"``). ``NUMBA_DISABLE_JIT=1`` runs the same source as plain
Python, the reference of the tests. The cache, the borrowed views and the
first run's notice (a ``.done`` mark per entry point and law pair, written by
:func:`compiled`): docs/developer.md, "Compile".
"""

from __future__ import annotations

import gc
import os
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from vtool import numba_cache

numba_cache.configure()
#: numba's documented switch, set unless the user set it: typing the kernels tries thousands of overloads
#: that do not apply, and numba made each failure's message with colorama's streams set up and torn down
os.environ.setdefault("NUMBA_DISABLE_ERROR_MESSAGE_HIGHLIGHTING", "1")

from cffi import FFI  # noqa: E402
from numba import carray, config, njit  # noqa: E402 (after the cache folder is chosen)

_OPTIONS: dict[str, Any] = {"cache": numba_cache.CACHE_ENABLED, "nogil": True, "error_model": "numpy"}
jit = njit(**_OPTIONS)
jit_inline = njit(**_OPTIONS, inline="always")

#: cffi's FFI, whose ``from_buffer`` numba supports in nopython mode (numba imports cffi itself).
_FFI = FFI()

if config.DISABLE_JIT:  # plain Python: the arrays themselves (carray takes a ctypes pointer there)

    def borrowed(a):  # noqa: ANN001, ANN201
        return a

else:

    @jit_inline
    def borrowed(a):  # noqa: ANN001, ANN201
        """A view of C-contiguous array ``a`` that numba does not reference-count: numba's ``carray`` over
        its data pointer. Valid while ``a`` lives (the Python caller holds it for the whole call)."""
        return carray(_FFI.from_buffer(a), a.shape)


#: A first compile's length (s) when none was measured yet on this machine.
FIRST_GUESS = "5-20"
#: Python's collector thresholds while a kernel compiles (``gc.set_threshold``; Python's own: 700, 10, 10),
#: those ``vtool``'s CLI sets for its whole process (``vtool.app.cli.main.GC_THRESHOLDS``).
COMPILE_GC_THRESHOLDS = (100_000, 50, 100)


#: [blocks inside fewer_collections, the thresholds they found], for blocks in several threads at once
_RAISED: list = [0, None]
_RAISED_LOCK = threading.Lock()


@contextmanager
def fewer_collections() -> Iterator[None]:
    """Python's collector passes less often inside the block (never more often than the process had it),
    its thresholds restored when the last such block (of any thread) ends: numba's compile makes
    millions of short-lived objects (docs/developer.md, "Compile")."""
    with _RAISED_LOCK:
        if _RAISED[0] == 0:
            _RAISED[1] = before = gc.get_threshold()
            if before[0] != 0:  # (0: collection turned off by the process, left so)
                gc.set_threshold(*(max(now, wanted) for now, wanted in zip(before, COMPILE_GC_THRESHOLDS, strict=True)))
        _RAISED[0] += 1
    try:
        yield
    finally:
        with _RAISED_LOCK:
            _RAISED[0] -= 1
            if _RAISED[0] == 0:
                gc.set_threshold(*_RAISED[1])


def law_key(hertz: bool | None, momentum: bool | None) -> str:
    return f"{'hertz' if hertz else 'rigid'}-{'momentum' if momentum else 'local'}"


def _mark(name: str, key: str) -> Path | None:
    folder = numba_cache.FOLDER
    return None if folder is None else folder / f"{name}-{key}.done"


#: (name, key) pairs compiled or found compiled in this process: a run's later chunks ask again.
_READY: set[tuple[str, str]] = set()


def is_compiled(dispatcher: Any, name: str, key: str) -> bool:
    """True when ``dispatcher`` needs no compile for ``key``: plain Python, compiled in this process, or
    marked done in the cache folder."""
    if (name, key) in _READY or not hasattr(dispatcher, "signatures"):
        return True
    mark = _mark(name, key)
    if mark is not None and mark.exists():
        _READY.add((name, key))
        return True
    return False


def compiled(name: str, key: str, seconds: float) -> None:
    """Mark ``name`` compiled into the cache for ``key``, and keep how long it took."""
    _READY.add((name, key))
    numba_cache.record_compile(name, seconds)
    mark = _mark(name, key)
    if mark is not None:
        try:
            mark.touch()
        except OSError:
            pass


def compile_notice(what: str, name: str) -> str:
    """The line before a compile: "compiling WHAT once, about N s on this machine"."""
    last = numba_cache.last_compile(name)
    about = f"{last:.0f}" if last is not None else FIRST_GUESS
    later = "later runs load it from the cache" if numba_cache.CACHE_ENABLED else "no cache: every process compiles it"
    return f"compiling {what} once, about {about} s on this machine; {later}"


def timed_call(function: Any, name: str, key: str, *args: Any) -> tuple[Any, float]:
    """``function(*args)`` and the seconds of its compile: timed and marked :func:`compiled` when it had
    to be compiled (or loaded from numba's cache) first, else 0."""
    if is_compiled(function, name, key):
        return function(*args), 0.0
    started = time.perf_counter()
    with fewer_collections():
        result = function(*args)
    seconds = time.perf_counter() - started
    compiled(name, key, seconds)
    return result, seconds
