"""The one decorator of vtool's compiled kernels, their cache folder, and what a first run says.

Every compiled function (the Newmark kernel's files under ``solvers/newmark/``,
the CSV formatter :mod:`vtool.csvrows_kernel`) is ``@jit``: numba's ``njit`` with
``cache=True`` (when :mod:`vtool.numba_cache` found a safe folder),
``nogil=True`` (threads of a sweep run in parallel) and numpy's error model
(a division by zero gives inf, as the plain-NumPy reference does). The few
small helpers of the quiet step are ``@jit_inline``: the same, copied into
their callers as numba IR (``inline="always"``) so that LLVM vectorizes them
in place. ``NUMBA_DISABLE_JIT=1`` runs the same source as plain Python, the
reference the tests compare the compiled kernel with.

The cache folder's name carries a digest of all of the kernels' files
(:func:`vtool.numba_cache.kernel_sources`): an edit of any of them starts an empty cache.

First run: :func:`compile_notice` says whether an entry point still has to be
compiled for a law pair (a ``.done`` mark in the cache folder, written by
:func:`compiled`, or a compile in this process already) and how long it took
last time on this machine.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from vtool import numba_cache

numba_cache.configure()

from cffi import FFI  # noqa: E402
from numba import carray, config, njit  # noqa: E402 (after the cache folder is chosen)

_OPTIONS: dict[str, Any] = {"cache": numba_cache.CACHE_ENABLED, "nogil": True, "error_model": "numpy"}
jit = njit(**_OPTIONS)
jit_inline = njit(**_OPTIONS, inline="always")

#: cffi's FFI, whose ``from_buffer`` numba supports in nopython mode. With cffi installed, numba
#: imports it (and pycparser) itself during a solve's first compiled call (its cffi typing support;
#: seen with ``python -X importtime``), so this costs a solve no import of its own.
_FFI = FFI()

if config.DISABLE_JIT:  # plain Python: the arrays themselves (carray takes a ctypes pointer there)

    def borrowed(a):  # noqa: ANN001, ANN201
        return a

else:

    @jit_inline
    def borrowed(a):  # noqa: ANN001, ANN201
        """A view of C-contiguous array ``a`` that numba does not reference-count, for the length of a call.

        numba counts references to every array it passes: a compiled function
        takes (an atomic increment) and drops (an atomic decrement) a count of
        each array in its arguments, records included, and its optimiser removes
        few of these pairs in a function with branches. The kernel's entry point
        hands its callees views made by numba's documented ``carray`` over the
        arrays' data pointers (cffi's ``ffi.from_buffer``, supported in nopython
        mode): such a view has no owner to count, so each count is a null check.
        It is valid while ``a`` lives: the Python caller holds every array for
        the whole call, and no view outlives it.
        """
        return carray(_FFI.from_buffer(a), a.shape)


#: A first compile's length when none was measured yet on this machine (s; the 2-core development
#: machine took 9-14 s for 1A's kernel with other work running).
FIRST_GUESS = "5-20"


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
