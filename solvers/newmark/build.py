"""Compile the Newmark kernel into numba's cache in a child process, while the run goes on without it.

A new install's first run would otherwise wait for the compile (seconds:
:data:`vtool.solvers.newmark.backend.COMPILE_REFERENCE_S` on the reference machine of
:mod:`vtool.compile_estimate`) before its first step. Instead :func:`start` launches ``python -m
vtool.solvers.newmark.build LOCK`` with the pickled jobs (here ``run_chunk`` and
numba's types of its arguments) on its standard input and returns at once;
the child compiles them (numba writes its cache as it compiles), removes the
lock and exits; a ``native`` job after ``run_chunk`` builds its native module
(:mod:`vtool.solvers.newmark.native`). The parent never waits for it: between
chunks it asks numba's cache whether the kernel is there
(:func:`vtool.solvers.newmark.kernel.is_cached`) and then loads it. The
child compiles ``run_chunk`` on two processes (:func:`compile_kernel`: a
helper, ``python -m vtool.solvers.newmark.build --part``, compiles part of its
callees meanwhile, then the machine code of all of them); so does a
``compiled``-mode run in its own process.

One compile at a time: the lock file (in the temporary folder, named by the
kernel file's path, modification time and size, ``NUMBA_CACHE_DIR`` and the
jobs) is created exclusively and holds the child's process id, so
the workers of a sweep or several terminals started together launch one
child between them, and each can tell whether it still runs
(:func:`compiling`). A lock whose process is gone, or older than
:data:`STALE_S`, is replaced. A child that fails leaves a ``.failed`` file
beside the lock with its error; later runs then compile in their own process
(where the error shows) instead of starting it again.

Which kernel a run uses (``VTOOL_KERNEL``, :func:`kernel_mode`): ``auto``
(the default) as above; ``compiled`` compiles in the run's own process
before its first step, as numba does by default (or, while another process
compiles the same kernel, waits for it and loads it: :func:`compile_once`);
``plain`` never compiles.
The piecewise back ends call only the event rules (``settle``, ``impact``,
``fill_sources`` and, with compliant contacts, ``snap_shut``,
``relative_velocity``, ``hertz_law``), a few hundred times a run: in
``auto`` mode, until those are cached, a run calls them as plain Python
(:class:`RecordingRules`, which notes the types they were called with) and
then starts their compile the same way.
"""

from __future__ import annotations

import contextlib
import gc
import hashlib
import importlib.util
import os
import pickle
import secrets
import shutil
import subprocess
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Iterator
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np

from vtool.errors import InputError

#: A lock older than this (s) is from a child that did not finish; a new compile replaces it.
STALE_S = 600.0
KERNEL_MODES = ("auto", "compiled", "plain")  # VTOOL_KERNEL
_children: list[subprocess.Popen] = []  # type: ignore[type-arg]  # polled so that finished children are reaped
_plain_module: list[ModuleType] = []

KERNEL_FILE = Path(__file__).with_name("kernel.py")  # the kernel's source (no import needed)

#: A compile job: an entry point's name and numba's types of its arguments.
Job = tuple[str, tuple[Any, ...]]


_array_types: dict[tuple[Any, ...], Any] = {}


def numba_types(values: tuple[Any, ...]) -> tuple[Any, ...]:
    """``numba.typeof`` of each value, arrays' memoized by what numba's array type holds (dtype,
    dimensions, layout, writeable, aligned): numba's own takes about 20 µs an array, a tenth of
    a short run for a kernel call's two dozen."""
    import numba

    found: list[Any] = []
    for value in values:
        if type(value) is not np.ndarray:
            found.append(numba.typeof(value))
            continue
        flags = value.flags
        layout = "C" if flags.c_contiguous else "F" if flags.f_contiguous else "A"
        key = (value.dtype, value.ndim, layout, flags.writeable, flags.aligned)
        if key not in _array_types:
            _array_types[key] = numba.typeof(value)
        found.append(_array_types[key])
    return tuple(found)


def kernel() -> ModuleType:
    """The kernel module, imported when first needed: it imports numba, which a run on the native module
    (:mod:`vtool.solvers.newmark.native`) never does."""
    from vtool.solvers.newmark import kernel as newmark_kernel

    return newmark_kernel


def kernel_mode() -> str:
    """``VTOOL_KERNEL`` (default ``auto``): how a run gets its compiled kernel (see the module doc)."""
    mode = os.environ.get("VTOOL_KERNEL", "").strip() or "auto"
    if mode not in KERNEL_MODES:
        raise InputError("VTOOL_KERNEL", mode, "one of " + ", ".join(KERNEL_MODES))
    return mode


def jit_enabled() -> bool:
    """False under ``NUMBA_DISABLE_JIT`` (the kernel module is plain Python already)."""
    return hasattr(kernel().run_chunk, "py_func")  # a dispatcher (its ``signatures`` would list them: slower)


def plain_kernel() -> ModuleType:
    """The kernel's source loaded a second time as plain Python (``newmark_kernel_plain``; no numba)."""
    if not jit_enabled():
        return kernel()
    if not _plain_module:
        compiled = kernel()
        spec = importlib.util.spec_from_file_location(compiled.__name__ + compiled.PLAIN_SUFFIX, compiled.__file__)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        _plain_module.append(module)
    return _plain_module[0]


class RecordingRules:
    """The plain kernel's functions, noting numba's types of the first call of each (:attr:`jobs`)."""

    def __init__(self) -> None:
        self.plain = plain_kernel()
        self.jobs: dict[str, tuple[Any, ...]] = {}

    def __getattr__(self, name: str) -> Any:
        function = getattr(self.plain, name)

        def call(*args: Any) -> Any:
            if name not in self.jobs:
                import numba

                self.jobs[name] = tuple(numba.typeof(value) for value in args)
            return function(*args)

        setattr(self, name, call)  # found as an attribute from now on: __getattr__ runs once per name
        return call


def rules(hertz: bool | None, momentum: bool | None) -> Any:
    """The module whose event rules a piecewise run calls: the compiled kernel, or (``auto`` mode, not
    cached yet; ``plain`` mode) a :class:`RecordingRules` on the plain one."""
    mode = kernel_mode()
    if not jit_enabled() or mode == "compiled":
        return kernel()
    compiled = kernel()
    if mode == "auto" and compiled.is_cached(("impact", "settle", "fill_sources"), hertz, momentum):
        return compiled
    return RecordingRules()


def compile_recorded(used: Any) -> None:
    """After a piecewise run on :func:`rules`: start the compile of what it called as plain Python."""
    from vtool import numba_cache

    if isinstance(used, RecordingRules) and used.jobs and kernel_mode() == "auto" and numba_cache.CACHE_ENABLED:
        start(sorted(used.jobs.items()))  # (with no cache to write, a compile would be lost: plain it stays)


def lock_path(jobs: list[Job]) -> Path:
    """The lock file of a compile of these jobs."""
    source = KERNEL_FILE.resolve()
    stamp = source.stat()
    cache = os.environ.get("NUMBA_CACHE_DIR", "")
    key = f"{source}|{stamp.st_mtime_ns}|{stamp.st_size}|{cache}|{jobs!r}".encode()
    uid = os.getuid() if hasattr(os, "getuid") else "user"
    return Path(tempfile.gettempdir()) / f"vtool-kernel-{uid}-{hashlib.sha1(key).hexdigest()[:16]}.lock"


def failed_path(lock: Path) -> Path:
    return lock.with_suffix(".failed")


def _alive(pid: int) -> bool:
    for child in _children:  # this process's own children: one that has ended is reaped, not taken for alive
        child.poll()
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # it exists, owned by someone else
        pass
    return True


def holder_alive(lock: Path) -> bool:
    """True when ``lock`` exists, is younger than :data:`STALE_S` and its process (if written yet) runs."""
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


def start(jobs: list[Job]) -> bool:
    """Start the child compile of ``jobs`` unless one is running already.

    Returns True when a compile is under way (this call's or another
    process's), False when none could be started or an earlier one failed
    (the caller compiles itself).
    """
    lock = lock_path(jobs)
    if failed_path(lock).exists():
        return False
    taken = _take(lock)
    if taken is False:
        return True
    try:
        child = subprocess.Popen([sys.executable, "-m", "vtool.solvers.newmark.build", str(lock)],
                                 stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                 close_fds=True)
        assert child.stdin is not None
        child.stdin.write(pickle.dumps(jobs))
        child.stdin.close()
    except OSError:  # no process to be had (or it died at once): the caller compiles in-process
        if taken:
            lock.unlink(missing_ok=True)
        return False
    _children[:] = [*(c for c in _children if c.poll() is None), child]  # finished ones are reaped
    if taken:
        with contextlib.suppress(OSError):  # not O_CREAT: a child that has finished has removed the lock
            descriptor = os.open(lock, os.O_WRONLY)
            os.write(descriptor, str(child.pid).encode())
            os.close(descriptor)
    return True


def compiling(jobs: list[Job]) -> bool:
    """True while a child compile of ``jobs`` (this process's or another's) is still running; a lock
    left by one that was killed is removed."""
    lock = lock_path(jobs)
    if holder_alive(lock):
        return True
    lock.unlink(missing_ok=True)
    return False


def kernel_split(signature: tuple[Any, ...]) -> tuple[list[Job], list[Job]]:
    """The callees of ``run_chunk`` compiled before it, for numba's types ``signature`` of its arguments:
    (a helper process's share, the compiling process's share).

    Each entry's types are those numba infers for the call inside
    ``run_chunk`` (its arguments' types and its locals': ``np.zeros`` vectors,
    ``int64`` indices, ``float64`` times), so that when ``run_chunk`` is
    typed it finds each one in the cache (compiled by the helper) or in this
    process; a mismatch would only cost a second compile of that callee.
    ``tests/test_first_run.py`` checks them against the compiled kernel's. The
    shares are balanced by their compile times (measured with numba's compile
    events on the development machine).
    """
    from numba import types

    (ip, fp, cl, clf, sc, sa, sb, mass, ci, cm, cp, mk, mon, out_t, out_q, out_F, out_c, ev_f, ev_i, peak,
     x, v, a, ist, fst, work, L, closing, hertz, momentum) = signature
    i8, f8, b1 = types.int64, types.float64, types.boolean
    vec, mat, ivec = types.Array(f8, 1, "C"), types.Array(f8, 2, "C"), types.Array(i8, 1, "C")
    helper: list[Job] = [
        ("release_pulling", (ip, fp, cl, clf, ci, cm, cp, mk, mon, i8, f8, x, v, a, vec, ev_f, ev_i, ist, vec, vec, vec,
                             vec, hertz)),
        ("locate_event", (ci, cm, cp, cl, clf, mk, mon, i8, i8, i8, i8, i8, fp, sc, sa, sb, f8, f8, f8, f8,
                          *(vec,) * 9, mat, hertz)),
        ("step_rows", (ci, cl, clf, mk, mon, i8, i8, i8, i8, i8, fp, sc, sa, sb, f8, f8, *(vec,) * 10, out_t, out_q,
                       out_F, out_c, ist, hertz)),
        # (compiled by locate_event already; a job so that the bundle holds run_chunk's own calls of it too)
        ("layer_step", (ci, cm, cp, i8, f8, f8, f8, i8, mat, i8, *(vec,) * 9, cl, clf, mk, mon, hertz)),
    ]
    own: list[Job] = [
        ("advance", (ip, fp, cl, sc, sa, sb, ci, cm, cp, mk, mon, out_t, out_q, out_F, out_c, peak, ist, fst,
                     i8, *(vec,) * 13)),
        ("take_events", (ip, fp, cl, clf, mass, i8, f8, f8, vec, ivec, x, v, vec, ev_f, ev_i, ist, fst, momentum)),
        ("record_row", (ci, cl, clf, mk, mon, i8, i8, i8, i8, f8, f8, vec, vec, vec, vec, out_t, out_q, out_F, out_c,
                        i8, hertz)),
        ("track_peaks", (cl, clf, mk, mon, i8, i8, i8, i8, f8, b1, vec, vec, vec, vec, vec, peak, hertz)),
        ("monitors", (cl, clf, mk, mon, i8, i8, i8, i8, f8, vec, vec, vec, vec, vec, hertz)),
    ]
    return helper, own


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Python's cyclic garbage collector off while numba compiles (restored after).

    A compile makes millions of small objects (numba's IR and types,
    llvmlite's IR), most of which live until it ends, and the collector's
    repeated passes over them free little: ``benchmarks/bench_compile_collector.py``
    prints the collector's time and the peak memory of a one-process compile
    with it and paused; ``benchmarks/bench_compile_ab.py`` the two-process
    compile's wall time against an earlier commit.

    What the compile made is then frozen (``gc.freeze``: never looked at
    again by the collector) before the collector comes back. Else its next
    pass went over all of it at once, inside the compile's wall time: 0.65 s
    of 1A's 10 s, for 342,000 objects collected. numba keeps most of what
    it made (types, code libraries) for the process's life; the garbage
    among it, left in memory, is about 4 MB on 1A (the resident set 272 MB
    frozen, 268 MB once unfrozen and collected). What the process held
    before is frozen with it: a compile comes once per process, in the
    compiling mode or the background child (a run in the default mode only
    loads what the child compiled, outside this block).
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if enabled:
            gc.enable()


#: How long (s) a compile waits for its helper process before going on without it.
HELPER_WAIT_S = 300.0
#: The callees of ``run_chunk`` that run once per event or output row, not per step: their machine code in
#: the bundle is made for size (:mod:`vtool.numba_link`, "Made for size"), as is ``run_chunk``'s own (it
#: takes the steps that are not quiet; :func:`~vtool.solvers.newmark.kernel.advance` takes the others).
#: On 1A the bundle was ready about 0.6 s sooner and ``run_chunk``'s own machine code took half the
#: time; the first compile 0.93 of before (``bench_compile_ab.py``, 8 pairs), the kernel per step 1.00
#: (``bench_step_ab.py``, 8 pairs), its results the same to the last bit.
RARE = ("release_pulling", "take_events", "record_row", "track_peaks", "monitors")
#: How often (s) the two processes of a compile look for each other's marks (:func:`compile_kernel`).
MARK_POLL_S = 0.01


def _wait_for(path: Path, alive: Any, timeout: float) -> bool:
    """True once ``path`` exists; False if ``alive()`` turns false first (after one more look) or at ``timeout`` s."""
    deadline = time.monotonic() + timeout
    while not path.exists():
        if not alive():
            return path.exists()
        if time.monotonic() > deadline:
            return False
        time.sleep(MARK_POLL_S)
    return True


def _bundle_fetcher(folder: Path, helper: Any) -> Callable[[], dict[str, Any] | None]:
    """The callable that gives ``run_chunk``'s library the helper's bundle (or None: the helper failed)."""
    def fetch() -> dict[str, Any] | None:
        if not _wait_for(folder / "bundle", lambda: helper.poll() is None, HELPER_WAIT_S):
            return None
        with contextlib.suppress(OSError, pickle.UnpicklingError, EOFError):
            bundle = pickle.loads((folder / "bundle").read_bytes())
            if isinstance(bundle, dict):
                return bundle
        return None
    return fetch


def compile_kernel(signature: tuple[Any, ...]) -> None:
    """Compile ``run_chunk`` for ``signature`` on two processes (numba compiles on one core).

    A helper process compiles its share of the callees (:func:`kernel_split`)
    into numba's cache while this one compiles the rest; then ``run_chunk``
    is compiled here, loading the helper's from the cache. Meanwhile the
    helper loads this process's share from the cache and makes the machine
    code of both shares (a bundle, :func:`vtool.numba_link.build_bundle`),
    which ``run_chunk``'s library takes instead of linking them in
    (:func:`vtool.numba_link.expecting_bundle`). The two processes mark their
    progress with empty files in a temporary folder (``own``, ``share``; the
    bundle arrives as ``bundle``). On two cores the compile's wall time is
    that of the larger share, then the larger of ``run_chunk``'s typing and
    lowering and the bundle, then ``run_chunk``'s own machine code
    (``python3 benchmarks/bench_compile_ab.py REF`` measures it against an
    earlier commit). Without a cache to share through, or without a helper
    (it could not start, or failed: this process then compiles what it left,
    and links it in as numba does), the compile is the plain one.
    """
    from vtool import numba_cache, numba_link

    helper_jobs, own = kernel_split(signature)
    helper = None
    folder = Path(tempfile.mkdtemp(prefix="vtool-compile-"))
    kernel()  # imported (it installs numba_link) before asking for a bundle: the background child has not yet
    bundle = numba_link.installed() and numba_link.enabled()
    if numba_cache.CACHE_ENABLED:
        with contextlib.suppress(OSError):
            helper = subprocess.Popen([sys.executable, "-m", "vtool.solvers.newmark.build", "--part"],
                                      stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      close_fds=True)
            assert helper.stdin is not None
            helper.stdin.write(pickle.dumps({"jobs": helper_jobs, "bundle": (own, str(folder)) if bundle else None}))
            helper.stdin.close()
    try:
        with collector_paused():
            if helper is None:
                kernel().run_chunk.compile(signature)
                return
            for name, arg_types in own:
                getattr(kernel(), name).compile(arg_types)
            (folder / "own").touch()  # the helper may now bundle these with its own
            _wait_for(folder / "share", lambda: helper.poll() is None, HELPER_WAIT_S)
            with numba_link.expecting_bundle("run_chunk", _bundle_fetcher(folder, helper), entry_for_size=True):
                kernel().run_chunk.compile(signature)
    finally:
        if helper is not None and helper.poll() is None:
            helper.kill()
            helper.wait()
        shutil.rmtree(folder, ignore_errors=True)


def _part(payload: Any) -> None:
    """The helper's work (``--part``): its share of the callees, then (with a bundle folder) their bundle.

    The share goes into numba's cache and a ``share`` mark into the folder.
    Then, once the compiling process has marked its own share done (``own``),
    the helper loads that share from the cache and makes the bundle of both
    (:func:`vtool.numba_link.build_bundle`) into the folder's ``bundle``
    file (written whole, then renamed), while the compiling process types and
    lowers ``run_chunk``, which takes it (:func:`compile_kernel`).
    """
    if isinstance(payload, list):
        payload = {"jobs": payload, "bundle": None}
    jobs = payload["jobs"]
    for name, signature in jobs:
        getattr(kernel(), name).compile(signature)
    if payload["bundle"] is None:
        return
    own, folder_name = payload["bundle"]
    folder = Path(folder_name)
    (folder / "share").touch()
    parent = os.getppid()
    if not _wait_for(folder / "own", lambda: os.getppid() == parent, HELPER_WAIT_S):
        return
    from vtool import numba_link

    compiled = []
    for name, signature in [*jobs, *own]:
        dispatcher = getattr(kernel(), name)
        dispatcher.compile(signature)  # the compiling process's share: from the cache
        compiled.append((name, dispatcher.overloads[tuple(signature)]))
    bundle = numba_link.build_bundle(compiled, secrets.token_hex(6), for_size=RARE)
    partial = folder / "bundle.part"
    partial.write_bytes(pickle.dumps(bundle))
    partial.replace(folder / "bundle")


#: How often (s) a run polls the lock of a compile another process is doing (:func:`compile_once`).
POLL_S = 0.2


def compile_once(signature: tuple[Any, ...], cached: Any) -> None:
    """:func:`compile_kernel` for ``signature``, or, while another process compiles the same kernel,
    wait for it and load its result from numba's cache.

    ``cached()`` says whether the kernel is in the cache. The compile holds
    the lock of the job ``("run_chunk", signature)`` (:func:`lock_path`; a
    child started with that job list holds the same one): so the workers
    of a sweep, the processes of a parallel test run or terminals started
    together in the ``compiled`` mode compile a kernel once between them,
    where each compiled it on two processes of its own, all at once. A lock
    whose process dies, or that outlives :data:`STALE_S`, stops the wait;
    then this process compiles. Without a cache to share through (or
    without a lock), it compiles at once.
    """
    from vtool import numba_cache

    lock = lock_path([("run_chunk", signature)])
    while numba_cache.CACHE_ENABLED:
        taken = _take(lock)
        if taken is None:
            break  # no lock can be made here: compile without one
        if taken is False:  # another process compiles it
            while holder_alive(lock):
                time.sleep(POLL_S)
            if cached():
                kernel().run_chunk.compile(signature)  # a load from the cache
                return
            continue  # it ended without the kernel: take the lock and compile here
        try:
            with contextlib.suppress(OSError):
                lock.write_text(str(os.getpid()))
            compile_kernel(signature)
        finally:
            lock.unlink(missing_ok=True)
        return
    compile_kernel(signature)


def _compile(jobs: list[Job]) -> None:
    for name, signature in jobs:
        if name == "run_chunk":
            compile_kernel(signature)
        elif name == "native":  # (module name, run_chunk's types): after run_chunk, whose callees it reuses
            from vtool.solvers.newmark import native as kernel_native

            kernel_native.build(*signature)
        else:
            getattr(kernel(), name).compile(signature)


def main(argv: list[str]) -> int:
    """The child: compile the pickled jobs on stdin (into numba's cache); remove the lock ``argv[0]``.

    With ``--part`` (a helper of :func:`compile_kernel`): compile them, no lock, no ``run_chunk`` split, and
    end without Python's shutdown (``os._exit``) once numba has written them.
    """
    if argv[:1] == ["--part"]:
        with collector_paused():
            _part(pickle.loads(sys.stdin.buffer.read()))
        # done: numba wrote each function's cache files as it compiled them. The compiling process
        # waits for this one to end, and Python's own shutdown (modules, objects, numba's exit
        # handlers) took about 0.7 s more on the 2-core machine: end here, as a forked child does
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(0)
    lock = Path(argv[0]) if argv else None
    try:
        with collector_paused():  # (the native module's build too)
            _compile(pickle.loads(sys.stdin.buffer.read()))
        return 0
    except BaseException:
        if lock is not None:
            with contextlib.suppress(OSError):
                failed_path(lock).write_text(traceback.format_exc())
        raise
    finally:
        if lock is not None:
            lock.unlink(missing_ok=True)


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
