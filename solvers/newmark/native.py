"""The kernel's run loop as a native extension module: a run that imports no numba at all.

Why: with numba's cache warm, a second ``vtool solve gnilka-1a`` spends most
of its second in numba itself (``import numba`` 0.4-0.9 s on the 2-core
machine, then its target refresh and the load of the cached kernel, about
0.3 s) and 5 ms in the run. numba can also compile ahead of time
(``numba.pycc``): the result is a CPython extension module that needs only
NumPy, and it imports in under a millisecond.

What: after the kernel's first compile, the same background child
(:mod:`vtool.solvers.newmark.build`) builds ``run_chunk`` for the run's
argument types as such a module (:func:`build`), from the same source, with
the same compiler, for the host CPU, and puts it beside numba's cache. From
then on a run in the default mode (``VTOOL_KERNEL=auto``) whose argument
types have a module calls it (:func:`load`) and imports no numba; any other
run goes on as before. ``VTOOL_NATIVE=0`` turns the modules off (neither
built nor used); the ``compiled`` and ``plain`` modes never use them.

Which module: one serves one kernel source, one set of argument types (which
include the law switches, see :func:`~vtool.solvers.newmark.layout.laws`),
one numba, llvmlite, NumPy and Python, and one CPU. Its name carries a
digest of all of them (:func:`module_name`), computed without numba: the
SHA-256 of ``newmark_kernel.py``, ``kernel_layout.py``, ``csvrows_kernel.py``
and this file, numba's and llvmlite's package files (path, modification
time, size), NumPy's version, Python's cache tag, the machine and the CPU's
model name and flags (``/proc/cpuinfo``; elsewhere
:func:`platform.processor`), and each argument's type (:func:`type_key`: an
array's dtype, dimensions, layout, writeability and alignment, the type of
anything else). A change to any of them gives another name: a stale module
is never loaded, only left unused.

The GIL: the module's functions release it around the call, as the JIT
kernel (``nogil=True``) does, so threads (a ``local-threads:N`` sweep) run
in parallel on it (:func:`_releasing_the_gil`).

Same results: the module is the JIT kernel's source compiled by the same
numba and LLVM with the same options; its results equal the JIT kernel's to
the last bit (``tests/test_native.py`` compares a whole 1A run).

Build: :func:`build` writes into a temporary folder beside the final file and
renames it into place, so a reader never sees half a module. ``numba.pycc``
needs a C compiler (for numba's small runtime helpers); without one the
build fails, the child leaves its ``.failed`` note (see
:mod:`vtool.solvers.newmark.build`) and runs stay on numba's cache.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.machinery
import importlib.util
import os
import platform
import shutil
import sys
import tempfile
import time
import warnings
from collections.abc import Iterator
from functools import cache
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from vtool import numba_cache

HERE = Path(__file__).resolve().parent
PREFIX = "vtool_native_"
_loaded: dict[str, ModuleType] = {}


def enabled() -> bool:
    """False under ``VTOOL_NATIVE=0`` or ``NUMBA_DISABLE_JIT`` (the plain reference runs), or with no cache folder."""
    if os.environ.get("VTOOL_NATIVE", "").strip() == "0":
        return False
    if os.environ.get("NUMBA_DISABLE_JIT", "0").strip() not in ("", "0"):
        return False
    numba_cache.configure(HERE)
    return numba_cache.CACHE_ENABLED  # (what folder() is None says, without making its path)


def folder() -> Path | None:
    """Where the modules live: numba's cache folder for the kernel (see :mod:`vtool.numba_cache`)."""
    numba_cache.configure(HERE)  # numba-free: only chooses the folder
    if not numba_cache.CACHE_ENABLED:
        return None
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    return Path(chosen) if chosen else HERE / "__pycache__"


def type_key(values: tuple[Any, ...]) -> str:
    """The argument types of ``values`` as text (what numba would compile ``run_chunk`` for)."""
    parts = []
    for value in values:
        if type(value) is np.ndarray:
            flags = value.flags
            layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
            parts.append(f"{value.dtype.str}/{value.ndim}{layout}{'w' if flags.writeable else 'r'}"
                         f"{'a' if flags.aligned else 'u'}")
        else:
            parts.append(type(value).__name__)
    return ",".join(parts)


def _package_stamp(name: str) -> str:
    spec = importlib.util.find_spec(name)
    if spec is None or spec.origin is None:
        return f"{name}:missing"
    stat = os.stat(spec.origin)
    return f"{spec.origin}:{stat.st_mtime_ns}:{stat.st_size}"


def _cpu() -> str:
    """The first CPU's model and flags from /proc/cpuinfo (Linux), else :func:`platform.processor`."""
    lines: list[str] = []
    with contextlib.suppress(OSError), open("/proc/cpuinfo", encoding="utf-8", errors="replace") as info:
        lines = [line for line in info.read().split("\n\n")[0].splitlines()
                 if line.startswith(("model name", "flags", "Features", "CPU part"))]
    return "\n".join(lines) if lines else platform.processor()


def sources() -> list[Path]:
    """What a module is compiled from (the run loop, its layout, the CSV formatter it carries too) and how
    (this file). Found, not imported: the CSV formatter's module imports numba."""
    csv = importlib.util.find_spec("vtool.csvrows_kernel")
    assert csv is not None and csv.origin is not None
    return [HERE / "kernel.py", HERE / "layout.py", Path(csv.origin), Path(__file__)]


@cache
def _environment() -> str:
    digest = hashlib.sha256()
    for source in sources():
        digest.update(source.read_bytes())
    parts = [digest.hexdigest(), _package_stamp("numba"), _package_stamp("llvmlite"), np.__version__,
             sys.implementation.cache_tag or "", platform.machine(), _cpu()]
    return "\n".join(parts)


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _switches(hertz: bool | None, momentum: bool | None) -> str:
    return f"h{int(hertz is not None)}m{int(momentum is not None)}"


#: The bits of ``ndarray.flags.num`` that :func:`type_key` reads: C and F contiguous, aligned, writeable.
FLAG_BITS = 0x1 | 0x2 | 0x100 | 0x400
_names: dict[tuple[Any, ...], str] = {}


def module_name(values: tuple[Any, ...]) -> str:
    """The module name (and file stem) for ``run_chunk`` on arguments ``values`` (see the module doc):
    the law switches (``values``' last two), the environment's digest, the argument types' digest.

    Kept per process by what :func:`type_key` reads of each argument, in a cheaper form (each array's
    dtype, dimensions and flag bits; each other value's type): 9 µs a run instead of 28 (timeit)."""
    key = tuple([(value.dtype, value.ndim, value.flags.num & FLAG_BITS) if type(value) is np.ndarray else type(value)
                 for value in values])
    name = _names.get(key)
    if name is None:
        name = _names[key] = f"{PREFIX}{_switches(*values[-2:])}_{_digest(_environment())}_{_digest(type_key(values))}"
    return name


def _pattern(switches: str) -> str:
    """The file names of this kernel's, numba's and CPU's modules for law switches ``switches`` (``*``: any)."""
    return f"{PREFIX}{switches}_{_digest(_environment())}_*{importlib.machinery.EXTENSION_SUFFIXES[0]}"


def exists(laws: tuple[bool | None, bool | None]) -> bool:
    """True when a native module for these law switches is there, for this kernel, numba and CPU (asked
    before a run is set up: a valve-train run's argument types are given by its law switches)."""
    where = folder() if enabled() else None
    if where is None:
        return False
    return any(where.glob(_pattern(_switches(*laws))))


def path(name: str) -> Path:
    where = folder()
    assert where is not None
    return where / (name + importlib.machinery.EXTENSION_SUFFIXES[0])


def load(values: tuple[Any, ...]) -> ModuleType | None:
    """The native module for arguments ``values``, or None when there is none (or it will not load)."""
    if not enabled():
        return None
    name = module_name(values)
    if name in _loaded:
        return _loaded[name]
    return _load_file(name, path(name))


def csv_writer() -> Any | None:
    """The CSV number formatter (:func:`vtool.csvrows_kernel.put_rows`) of a native module for this
    kernel, numba and CPU (any law switches: each module carries it), or None (default mode only)."""
    from vtool.solvers.newmark.build import kernel_mode

    if kernel_mode() != "auto" or not enabled():
        return None
    for loaded in _loaded.values():
        return loaded.put_rows
    where = folder()
    assert where is not None
    for file in sorted(where.glob(_pattern("*"))):
        found = _load_file(file.name.removesuffix(importlib.machinery.EXTENSION_SUFFIXES[0]), file)
        if found is not None:
            return found.put_rows
    return None


def _load_file(name: str, file: Path) -> ModuleType | None:
    if not file.exists():
        return None
    try:
        loader = importlib.machinery.ExtensionFileLoader(name, str(file))
        spec = importlib.util.spec_from_file_location(name, file, loader=loader)
        assert spec is not None
        module = importlib.util.module_from_spec(spec)
        loader.exec_module(module)
    except (ImportError, OSError):  # damaged or foreign: the JIT path still works
        return None
    _loaded[name] = module
    return module


@contextlib.contextmanager
def _releasing_the_gil() -> Iterator[None]:
    """numba.pycc's exported functions keep the GIL (its compile flags have no ``nogil``); the JIT kernel
    releases it (``nogil=True``), and a threaded sweep (``local-threads:N``) relies on that. For the
    compile, pycc's flags are made to release it too: the functions' CPython wrappers then drop the GIL
    around the call, as the JIT's do."""
    from numba.pycc import compiler

    original = compiler.Flags

    class Releasing(original):  # type: ignore[misc, valid-type]
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            self.release_gil = True

    compiler.Flags = Releasing  # type: ignore[misc]
    try:
        yield
    finally:
        compiler.Flags = original  # type: ignore[misc]


@contextlib.contextmanager
def _mixins_beside(cc: Any, where: Path) -> Iterator[None]:
    """pycc's C runtime helpers (its "mixins", about 3 s of gcc on the 2-core machine) compiled on a
    thread of their own from the start, while numba compiles the exports: ``CC.compile`` compiles the
    exports, then the mixins, one after the other, though neither needs the other. Each gcc is a
    process of its own, so the two run on two cores; the module is linked from the same objects."""
    import concurrent.futures

    where.mkdir()
    cc._toolchain.verbose = cc.verbose  # (what compile() sets first)
    compile_mixins = cc._compile_mixins
    with concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="pycc-mixins") as pool:
        objects = pool.submit(compile_mixins, str(where))
        cc._compile_mixins = lambda build_dir: objects.result()
        try:
            yield
        finally:
            del cc._compile_mixins
            objects.cancel()


def build(name: str, signature: tuple[Any, ...]) -> Path:
    """Compile ``run_chunk`` for numba's argument types ``signature`` into module ``name`` (the child's job),
    and beside it the CSV writer ``put_rows`` (for the types :func:`vtool.csvrows.arguments` gives).

    Returns the module's file. Atomic: written in a temporary folder beside it, then renamed.
    """
    import numba
    from numba import types
    from numba.pycc import CC

    from vtool import csvrows, csvrows_kernel
    from vtool.solvers.newmark import kernel

    target = path(name)
    target.parent.mkdir(parents=True, exist_ok=True)
    for left in target.parent.glob(".native-*"):  # of a build that was killed (an hour is long past any build)
        with contextlib.suppress(OSError):
            if time.time() - left.stat().st_mtime > 3600.0:
                shutil.rmtree(left, ignore_errors=True)
    scratch = Path(tempfile.mkdtemp(prefix=".native-", dir=target.parent))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # numba.pycc's pending-deprecation notice
            cc = CC(name)
            cc.output_dir = str(scratch)
            cc.target_cpu = "host"  # as the JIT compiles: this machine's CPU (part of the name's digest)
            cc.verbose = False
            cc.export("run_chunk", types.int64(*signature))(kernel.run_chunk.py_func)
            example = csvrows.arguments(np.zeros((1, 1)), ["label"], np.zeros(1, dtype=np.int64))
            rows = types.int64(*(numba.typeof(value) for value in example))
            cc.export("put_rows", rows)(csvrows_kernel.put_rows.py_func)
            with _releasing_the_gil(), _mixins_beside(cc, scratch / "mixins"):
                cc.compile()
        os.replace(scratch / cc.output_file, target)  # (pycc's own suffix; the loader takes any)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return target
