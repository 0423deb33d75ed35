"""Speed sweeps and design maps: many valve-train runs, one metrics row each.

A sweep is a list of :class:`Point` (an index, the swept values, a validated
spec; :mod:`vtool.presets.paths` builds them from a preset and ``--set``
assignments). This module evaluates them and keeps the results:

* :func:`evaluate_point` is the one point evaluation: spec -> run -> metrics
  (:func:`vtool.solvers.studies.metrics.run_metrics`), the same calls as
  :func:`vtool.solvers.run.simulate`, so a point equals ``vtool solve`` at the
  same settings. A faster path (warm kernel, reuse across RPM) replaces this
  one function.
* Points are grouped by model (the spec without its ``[run]`` settings) and cut
  into chunks; a worker evaluates a chunk in order and reuses the assembled
  model (matrices and contact layers, which do not depend on the run
  settings) from one point to the next.
* Chunks run serially, on local processes (``workers > 1``, a forkserver pool
  so that a thread-holding caller such as the TUI can use it safely), or on a
  Dask cluster (``scheduler = "tcp://HOST:PORT"``, ``"local:N"``: a
  ``distributed.LocalCluster`` with N worker processes, ``"local-threads:N"``:
  N threads in this process).
* Results go to a :class:`SweepFile` as they arrive (one CSV line each,
  flushed), so a killed sweep keeps what it finished and a resumed one skips
  it; when the sweep ends (or is stopped) the file is rewritten in point
  order, atomically, so every execution path gives the same bytes.
* :func:`find_speed` brackets and bisects every cam-speed interval in which a
  criterion (follower leaves the cam during lift; valve bounces on its seat,
  :mod:`vtool.solvers.studies.metrics`) holds.
"""

from __future__ import annotations

import array
import contextlib
import csv
import functools
import io
import itertools
import logging
import math
import os
import signal
import stat
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

from vtool.csvrows import csv_text
from vtool.errors import InputError, RunError
from vtool.files import check_output_path, exists, open_atomic, open_no_follow
from vtool.solvers import backends
from vtool.solvers.model.mechanism import Mechanism, assemble
from vtool.solvers.model.spec import MechanismSpec
from vtool.solvers.studies.metrics import (
    TIMING_METRICS,
    failed_metrics,
    metric_columns,
    run_metrics,
)
from vtool.solvers.studies.steady import is_cyclic, simulate_cycles

OK = "ok"


@dataclass(frozen=True)
class Point:
    """One sweep point: its index in the grid, the swept values (path -> value), its spec.

    A planned sweep's points carry no spec but ``make`` (a picklable callable: values -> spec, raising
    the loader's InputError for values it refuses), so that the spec is made where the point runs and
    not kept: :func:`point_spec`.
    """

    index: int
    values: tuple[tuple[str, Any], ...]
    spec: MechanismSpec | None
    make: Callable[[tuple[tuple[str, Any], ...]], MechanismSpec] | None = None


def point_spec(point: Point) -> tuple[MechanismSpec, str]:
    """(the point's spec, ``"ok"``), or (``make.base``, the loader's one-line message) for values it refuses."""
    if point.spec is not None:
        return point.spec, OK
    assert point.make is not None
    try:
        return point.make(point.values), OK
    except InputError as exc:
        return point.make.base, exc.one_line()  # type: ignore[attr-defined]  # SpecMaker.base: its columns


def evaluate(point: Point, *, every_step: bool = False, previous: Mechanism | None = None,
             cancel: Callable[[], bool] | None = None) -> tuple[PointResult, Mechanism | None]:
    """One point's result (a point whose values the loader refuses: NaN metrics, the message as status)
    and the mechanism for the next point to reuse."""
    spec, status = point_spec(point)
    if status != OK:
        return PointResult(point.index, point.values, failed_metrics(spec), status), previous
    metrics, status, mechanism = evaluate_point(spec, every_step=every_step, previous=previous, cancel=cancel)
    return PointResult(point.index, point.values, metrics, status), mechanism


@dataclass(frozen=True)
class PointResult:
    """Metrics of one point; ``status`` is ``"ok"`` or the failed run's one-line message."""

    index: int
    values: tuple[tuple[str, Any], ...]
    metrics: dict[str, float]
    status: str = OK

    @property
    def ok(self) -> bool:
        return self.status == OK


def grid(fields: Sequence[tuple[str, Sequence[Any]]]) -> list[tuple[tuple[str, Any], ...]]:
    """The cartesian product of the swept fields, the first field varying fastest.

    ``[("run.rpm", [1, 2]), ("damping.factor", [a, b])]`` gives
    (1, a), (2, a), (1, b), (2, b): each value of the second field is one line
    of the chart against the first.
    """
    points: list[tuple[tuple[str, Any], ...]] = [()]
    for path, values in fields:
        points = [p + ((path, v),) for v in values for p in points]
    order = [path for path, _ in fields]
    return [tuple(sorted(p, key=lambda pv: order.index(pv[0]))) for p in points]


# ----- point evaluation -----

def _model_key(spec: MechanismSpec) -> MechanismSpec:
    """The spec without its run settings and title (a speed override names the speed in the title): points with
    equal keys share one assembled model."""
    return replace(spec, run=None, title="")  # type: ignore[arg-type]  # a cache key, never run


def _mechanism(spec: MechanismSpec, previous: Mechanism | None) -> Mechanism:
    """An assembled mechanism for ``spec``, reusing ``previous``'s matrices and layers when only [run] (and the
    title) differs."""
    if previous is None or _model_key(previous.spec) != _model_key(spec):
        return assemble(spec)
    return previous.for_spec(spec)  # shares M, K, the contact layers and configuration tables


@functools.cache
def _backend_class(name: str) -> Any:
    """The back-end class, looked up once per process (an entry-point scan costs tens of ms)."""
    return backends.get(name)


def evaluate_point(spec: MechanismSpec, *, every_step: bool = False, previous: Mechanism | None = None,
                   cancel: Callable[[], bool] | None = None) -> tuple[dict[str, float], str, Mechanism | None]:
    """Run one point and return (metrics, status, mechanism for reuse by the next point).

    A run that fails (RunError: divergence, chattering) or that the back end
    rejects (InputError: e.g. a time step beyond the stability limit at this
    point) is a point result with NaN metrics and the message as status, not
    the end of the sweep.
    """
    mechanism = None
    try:
        mechanism = _mechanism(spec, previous)
        backend = _backend_class(spec.run.backend)()
        if is_cyclic(spec):  # run.cycles or run.steady: cycle by cycle, the metrics of the last
            trace = simulate_cycles(backend, mechanism, every_step=every_step, cancel=cancel)
        else:
            options = backend.options_from_run(spec.run, every_step)
            trace = backend.simulate(mechanism, options, progress=None,
                                     cancel=cancel if backend.supports_cancel else None)
    except (RunError, InputError) as exc:
        return failed_metrics(spec), str(exc).replace("\n", " "), mechanism
    return run_metrics(trace), OK, mechanism


#: The last mechanism each thread evaluated (:func:`evaluate_chunk`): a worker's next chunk of the same model
#: reuses it rather than assembling it again.
_LAST = threading.local()


def evaluate_chunk(chunk: Sequence[Point], every_step: bool = False) -> list[PointResult]:
    """Evaluate points in order, reusing the model across points that differ only in [run] (also from the
    worker's previous chunk: :func:`_mechanism` reuses it only for an equal model).

    Memory: a sweep over run settings assembled its model again at every chunk, and a process that assembles
    a model every few points grew by a few hundred bytes a point (measured on ``vtool sweep --workers 1``,
    benchmarks/bench_parquet.py: 11.9 MB after 4*10^4 points of a null sink, 0.4 MB with the model kept)."""
    results = []
    previous: Mechanism | None = getattr(_LAST, "mechanism", None)
    for point in chunk:
        result, previous = evaluate(point, every_step=every_step, previous=previous)
        results.append(result)
    _LAST.mechanism = previous
    return results


class IndexSet:
    """A set of point indices (``add``, ``update``, ``in``, ``len``, iteration) in one bit a possible index.

    A resumed sweep's finished points: a set of Python ints costs about 60 bytes a point, this an eighth of a
    byte an index up to the largest added (a 10^5-point grid: 12.5 kB).
    """

    def __init__(self, indices: Iterable[int] = ()) -> None:
        self.bits = bytearray()
        self.count = 0
        self.update(indices)

    def add(self, index: int) -> None:
        byte, bit = divmod(index, 8)
        if byte >= len(self.bits):
            self.bits.extend(bytes(max(byte + 1 - len(self.bits), len(self.bits))))  # doubled: amortised
        if not self.bits[byte] >> bit & 1:
            self.bits[byte] |= 1 << bit
            self.count += 1

    def update(self, indices: Iterable[int]) -> None:
        for index in indices:
            self.add(index)

    def __contains__(self, index: object) -> bool:
        if not isinstance(index, int) or index < 0:
            return False
        byte, bit = divmod(index, 8)
        return byte < len(self.bits) and bool(self.bits[byte] >> bit & 1)

    def __len__(self) -> int:
        return self.count

    def __iter__(self) -> Iterator[int]:
        for byte, value in enumerate(self.bits):
            if value:
                yield from (8 * byte + bit for bit in range(8) if value >> bit & 1)

    def copy(self) -> IndexSet:
        copied = IndexSet()
        copied.bits, copied.count = bytearray(self.bits), self.count
        return copied


def batched(points: Iterable[Point], size: int) -> Iterator[list[Point]]:
    """``points`` in lists of ``size`` (the last shorter), taken as they are needed."""
    batch: list[Point] = []
    for point in points:
        batch.append(point)
        if len(batch) >= size:
            yield batch
            batch = []
    if batch:
        yield batch


class Batches:
    """The chunks of a sweep's unfinished points, made as a runner takes them; ``count`` points in all.

    A planned grid (with ``run_order`` and ``lazy``: :class:`vtool.presets.paths.PointGrid`) is cut in its
    run order (the ``run.*`` fields varying fastest, so that neighbouring points share a model) into points
    without specs; nothing per point is held. A plain sequence of points is grouped by model (:func:`chunks`).
    """

    def __init__(self, points: Sequence[Point], skip: IndexSet | set[int], workers: int, per_worker: int = 4,
                 largest: int = 25) -> None:
        self.points = points
        self.skip = skip
        self.count = len(points) - len(skip)
        self.shape = (max(1, workers), per_worker, largest)
        self.size = max(1, min(largest, math.ceil(self.count / max(1, workers * per_worker))))

    def stream(self) -> Iterator[Point]:
        """The unfinished points, one by one, in run order."""
        if hasattr(self.points, "run_order"):
            make = self.points.lazy  # type: ignore[attr-defined]  # a PointGrid (checked above): presets/ type
            return (make(i) for i in self.points.run_order() if i not in self.skip)
        return (p for chunk in self for p in chunk)

    def __iter__(self) -> Iterator[list[Point]]:
        if hasattr(self.points, "run_order"):
            return batched(self.stream(), self.size)
        return iter(chunks([p for p in self.points if p.index not in self.skip], *self.shape))


def chunks(points: Sequence[Point], workers: int, per_worker: int = 4, largest: int = 25) -> list[list[Point]]:
    """Points (with specs) grouped by model, in index order, cut into about ``per_worker`` chunks per worker."""
    groups: dict[Any, list[Point]] = {}
    for point in sorted(points, key=lambda p: p.index):
        groups.setdefault(_model_key(point_spec(point)[0]), []).append(point)
    size = max(1, min(largest, math.ceil(len(points) / max(1, workers * per_worker))))
    result = []
    for group in groups.values():
        result += [group[i:i + size] for i in range(0, len(group), size)]
    return result


#: Chunks a pool or a Dask cluster holds at once per worker (submitted, running or waiting to be read):
#: the rest are made as these finish, so that a large sweep's memory does not grow with its length.
IN_FLIGHT_PER_WORKER = 4


# ----- execution -----

#: The pool's start barrier in a worker process (set by :func:`_ignore_interrupt`, see :meth:`ProcessRunner.start`).
_START_BARRIER: Any = None


def _ignore_interrupt(ready: Any = None, stderr: str | None = None, barrier: Any = None) -> None:
    """Worker initializer: Ctrl+C is handled by the parent, which stops the pool cleanly; with
    ``stderr`` (a file path), the worker's standard error (descriptor 2) is that file; ``ready`` (a
    semaphore) is released once the worker runs; ``barrier`` is kept for :func:`_started` (see
    :meth:`ProcessRunner.start`)."""
    global _START_BARRIER
    _START_BARRIER = barrier
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if stderr is not None:
        target = os.open(stderr, os.O_WRONLY | os.O_APPEND)
        os.dup2(target, 2)
        os.close(target)
    if ready is not None:
        ready.release()


def _started(timeout: float) -> int:
    """A start task: it returns (its worker's pid) only when as many start tasks run at once as the pool
    has workers, so that no worker is idle while the others are submitted (see :meth:`ProcessRunner.start`)."""
    if _START_BARRIER is not None:
        _START_BARRIER.wait(timeout)
    return os.getpid()


#: Most local Dask workers (processes or threads) per core: ``local:N`` above this is refused.
LOCAL_WORKERS_PER_CORE = 4


def max_local_workers() -> int:
    """The largest N of ``local:N`` / ``local-threads:N``: :data:`LOCAL_WORKERS_PER_CORE` per core."""
    return LOCAL_WORKERS_PER_CORE * (os.cpu_count() or 1)


SCHEDULER_FORMS = "tcp://HOST:PORT of a running Dask scheduler, local:N or local-threads:N"


def parse_scheduler(text: str) -> tuple[str, int]:
    """The one parser of ``--scheduler``: ``tcp://HOST:PORT`` -> ("address", 0); ``local:N`` /
    ``local-threads:N`` -> (kind, N) with 1 <= N <= :func:`max_local_workers`.

    Anything else (another protocol: ``tls://`` needs certificates vtool does not configure,
    ``inproc://`` and ``ucx://`` are not for a command line; a missing host or port; a ``;``, a space
    or a control character) is an InputError naming the accepted forms, before Dask is imported.
    """
    kind, sep, rest = text.partition(":")
    if kind in ("local", "local-threads") and sep:
        top = max_local_workers()
        if not rest.isascii() or not rest.isdigit() or not 1 <= int(rest) <= top:
            raise InputError("--scheduler", text, f"{kind}:N with N an integer from 1 to {top} "
                             f"({LOCAL_WORKERS_PER_CORE} per core, {os.cpu_count() or 1} cores)")
        return kind, int(rest)
    if text.isascii() and text.isprintable() and not any(c in text for c in " ;"):
        scheme, sep, address = text.partition("://")
        host, colon, port = address.rpartition(":")
        host_ok = bool(host) and all(c.isalnum() or c in ".-_" for c in host)
        if scheme == "tcp" and sep and colon and host_ok and port.isdigit() and 1 <= int(port) <= 65535:
            return "address", 0
    raise InputError("--scheduler", text, SCHEDULER_FORMS)


class DaskRunner:
    """A Dask client (to an existing scheduler or a LocalCluster it starts); connect before any output."""

    def __init__(self, scheduler: str, timeout: float = 3.0) -> None:
        kind, count = parse_scheduler(scheduler)
        from distributed import Client, LocalCluster

        self.cluster = None
        try:
            if kind == "address":
                self.client = Client(scheduler, timeout=timeout)
            else:
                with _pool_start():
                    self.cluster = LocalCluster(n_workers=count, threads_per_worker=1, processes=kind == "local",
                                                dashboard_address=None, silence_logs=logging.ERROR)
                self.client = Client(self.cluster)
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError("--scheduler", scheduler,
                             f"a reachable Dask scheduler ({type(exc).__name__}: {str(exc).splitlines()[0][:80]})"
                             ) from None
        self.workers = max(1, len(self.client.scheduler_info().get("workers", {})) or count or 1)

    def run(self, batches: Iterable[list[Point]], every_step: bool,
            on_results: Callable[[list[PointResult]], None], cancel: Callable[[], bool]) -> bool:
        from distributed import as_completed

        source = iter(batches)
        limit = IN_FLIGHT_PER_WORKER * self.workers

        def submit() -> Any:
            batch = next(source, None)
            return None if batch is None else self.client.submit(evaluate_chunk, batch, every_step, pure=False)

        futures = [f for f in (submit() for _ in range(limit)) if f is not None]
        pending = set(futures)
        try:
            queue = as_completed(futures)
            for future in queue:
                pending.discard(future)
                on_results(future.result())
                if cancel():
                    self.client.cancel(list(pending))
                    return False
                more = submit()
                if more is not None:
                    pending.add(more)
                    queue.add(more)
        except BaseException:
            self.client.cancel(list(pending))
            raise
        return True

    def close(self) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


@contextlib.contextmanager
def _pool_start() -> Iterator[None]:
    """Helper processes started inside this block import the installed ``vtool`` and never see Ctrl+C.

    Ctrl+C: SIGINT is blocked in this thread while the block runs; the mask is inherited through
    fork and exec, so a forkserver (or a Dask nanny) that is still importing numpy when the user
    presses Ctrl+C no longer prints a second traceback after the clean message. In the main thread,
    SIGINT and SIGTERM that reach this process meanwhile (through another thread, whose mask is its
    own) are held and raised when the block ends, so the block is never left half-way (a worker
    caught half-started when the pool is stopped prints a traceback of its own).

    Import path: ``PYTHONSAFEPATH=1`` in the environment while the pool starts its helper processes.

    multiprocessing starts the forkserver as ``python -c ...``, which puts the current folder first
    on the helper's import path; it then imports the preloaded ``vtool`` modules, so a folder named
    ``vtool`` in the current folder (an empty one will do) was imported instead of the installed
    package and every worker died (BrokenProcessPool). With ``PYTHONSAFEPATH`` (Python 3.11's ``-P``)
    the helper's path leaves the current folder out; the workers forked from it then take this
    process's own path (multiprocessing's preparation data), so they import what this process did.
    """
    import threading

    old = os.environ.get("PYTHONSAFEPATH")
    os.environ["PYTHONSAFEPATH"] = "1"
    held: list[int] = []
    handlers = {}
    if threading.current_thread() is threading.main_thread():
        handlers = {sig: signal.signal(sig, lambda signum, frame: held.append(signum))
                    for sig in (signal.SIGINT, signal.SIGTERM)}
    blocked = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        if old is None:
            os.environ.pop("PYTHONSAFEPATH", None)
        else:
            os.environ["PYTHONSAFEPATH"] = old
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
    for signum in held[:1]:  # what arrived meanwhile, as it would have arrived
        handler = handlers[signal.Signals(signum)]
        if callable(handler):
            handler(signum, None)
        elif handler == signal.SIG_DFL and signum == signal.SIGINT:
            raise KeyboardInterrupt
        elif handler == signal.SIG_DFL:
            signal.raise_signal(signum)


_STDERR_LOCK = threading.Lock()


@contextlib.contextmanager
def descriptor_stderr() -> Iterator[None]:
    """``sys.stderr`` a stream with a file descriptor (os.devnull) inside the block, when it has none.

    multiprocessing hands ``sys.stderr.fileno()`` to the resource-tracker process it
    starts with a process's first pool; a host that replaced ``sys.stderr`` with a stream
    without a descriptor (Textual's TUI: ``fileno()`` is -1) got "bad value(s) in
    fds_to_keep" from every pool. :class:`ProcessRunner` makes and starts its pool inside
    this block. With a real ``sys.stderr`` nothing changes; afterwards the replaced stream
    is put back unless something else replaced ``sys.stderr`` meanwhile.
    """
    import sys

    try:
        usable = sys.stderr is not None and sys.stderr.fileno() >= 0
    except (AttributeError, OSError, ValueError):
        usable = False
    if usable:
        yield
        return
    with _STDERR_LOCK, open(os.devnull, "w") as devnull:
        replaced, sys.stderr = sys.stderr, devnull
        try:
            yield
        finally:
            if sys.stderr is devnull:
                sys.stderr = replaced


class ProcessRunner:
    """A forkserver process pool of ``workers`` processes that ignore Ctrl+C (the parent stops them);
    its helper processes import the installed ``vtool`` whatever the current folder holds
    (:func:`_pool_start`).

    ``stderr``: a file the workers write their standard error to instead of the parent's (the TUI
    passes os.devnull: its terminal is Textual's screen).
    """

    def __init__(self, workers: int, stderr: str | None = None) -> None:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload(["vtool.solvers.studies.sweep", backends.module_of(backends.DEFAULT)])
        self.workers = workers
        self.started = False
        self.pids: set[int] = set()  # the worker processes, once started
        with descriptor_stderr():  # the pool's first semaphore starts multiprocessing's resource tracker
            self.ready = context.Semaphore(0)
            self.barrier = context.Barrier(workers)
            self.pool = ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_ignore_interrupt,
                                            initargs=(self.ready, stderr, self.barrier))

    def start(self, timeout: float = 300.0) -> None:
        """Start every worker and wait until each runs (inside :func:`_pool_start`).

        A worker still unpickling its start-up data when the parent stops the pool finds the pool's
        semaphores gone and prints a traceback; started all at once, before any point and with Ctrl+C
        held back until they run, no worker is ever caught half-started.
        """
        if self.started:
            return
        with _pool_start(), descriptor_stderr():
            # each submission to a pool without an idle worker starts one; a start task returns only when
            # all run at once (a barrier), so none has made its worker idle before the last is submitted (with
            # os.getpid, a worker that finished while this thread waited for the GIL took the next one: fewer
            # processes than workers, and this loop waited for the rest until its deadline: the TUI monkey's
            # seed 148 after 147 sequences, sweeps started by several threads at once)
            futures = [self.pool.submit(_started, timeout) for _ in range(self.workers)]
            deadline = time.perf_counter() + timeout
            running = 0
            while running < self.workers:
                if self.ready.acquire(timeout=0.1):
                    running += 1
                    continue
                failed = next((f.exception() for f in futures if f.done() and f.exception() is not None), None)
                if failed is not None:
                    raise RunError(f"the sweep's worker processes did not start ({type(failed).__name__}: "
                                   f"{str(failed)[:120]})")
                if time.perf_counter() > deadline:
                    raise RunError(f"the sweep's {self.workers} worker processes did not start within {timeout:g} s")
            self.pids = {future.result(timeout) for future in futures}  # one start task a worker process
        self.started = True

    def run(self, batches: Iterable[list[Point]], every_step: bool,
            on_results: Callable[[list[PointResult]], None], cancel: Callable[[], bool]) -> bool:
        from concurrent.futures import FIRST_COMPLETED, wait

        self.start()
        source = iter(batches)
        pending: set[Any] = set()

        def fill() -> None:  # at most IN_FLIGHT_PER_WORKER chunks a worker: the rest are made later
            while len(pending) < IN_FLIGHT_PER_WORKER * self.workers:
                batch = next(source, None)
                if batch is None:
                    return
                pending.add(self.pool.submit(evaluate_chunk, batch, every_step))

        try:
            fill()
            while pending:
                done, pending = wait(pending, timeout=0.2, return_when=FIRST_COMPLETED)
                for future in done:
                    on_results(future.result())
                if cancel():
                    for future in pending:
                        future.cancel()
                    return False
                fill()
        except BaseException:
            for future in pending:
                future.cancel()
            raise
        return True

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)


class SerialRunner:
    """Chunks in this process, one after the other (cancel is checked between points too)."""

    workers = 1

    def run(self, batches: Iterable[Iterable[Point]], every_step: bool,
            on_results: Callable[[list[PointResult]], None], cancel: Callable[[], bool]) -> bool:
        # the last mechanism, kept from chunk to chunk and from call to call as a worker keeps it (see
        # evaluate_chunk): a speed search calls once per bisection step, and each call assembled the model and
        # built its configurations again (548 assemblies for docs/sweep.md's 570 points, 8 models)
        previous: Mechanism | None = getattr(_LAST, "mechanism", None)
        try:
            for batch in batches:
                for point in batch:
                    if cancel():
                        return False
                    result, previous = evaluate(point, every_step=every_step, previous=previous, cancel=cancel)
                    if cancel() and not result.ok:
                        return False
                    on_results([result])
            return True
        finally:
            _LAST.mechanism = previous

    def close(self) -> None:
        pass


#: Seconds a local pool needs before its workers return their first points: the forkserver's imports,
#: the workers' start and each worker's first kernel load (benchmarks/bench_sweep_choice.py measures it:
#: 1.1 s for the pool and about 1 s for the first point on the 2-core development machine).
POOL_START_SECONDS = 2.0
#: Work per chunk sent to a worker (s): fewer, larger chunks cost less in hand-offs.
CHUNK_SECONDS = 0.25
#: Points measured in this process before the choice (the first also loads the kernel: the last one counts).
MEASURED_POINTS = 2


@dataclass(frozen=True)
class WorkerChoice:
    """How the rest of a sweep runs: ``workers`` processes (1: in this process), ``chunk`` points a task."""

    workers: int
    chunk: int
    reason: str


def choose_workers(point_seconds: float, points: int, cores: int, load: float | None = None,
                   start_seconds: float = POOL_START_SECONDS) -> WorkerChoice:
    """Workers and chunk size for ``points`` more points of ``point_seconds`` each (measured).

    The cores free for the sweep are ``cores + 1 - load`` (``load``: the one-minute load average, which
    counts this process), from 1 to ``cores``; with ``w`` workers on ``f`` free cores the pool takes
    ``start_seconds + points * point_seconds / min(w, f)`` against ``points * point_seconds`` serially,
    and is chosen only when that saves more than a tenth of the serial time. A chunk holds about
    :data:`CHUNK_SECONDS` of work, and there are at least two chunks per worker.
    """
    serial = points * point_seconds
    free = float(cores) if load is None else min(float(cores), max(1.0, cores + 1.0 - load))
    workers = min(cores, points, max(1, int(free + 0.5)))
    where = f"{points} more point{'s' if points != 1 else ''} of {1000 * point_seconds:.3g} ms"
    if workers < 2:
        return WorkerChoice(1, points or 1, f"{where} run in this process ({free:.1f} of {cores} cores free)")
    pooled = start_seconds + serial / min(workers, free)
    if pooled > 0.9 * serial:
        return WorkerChoice(1, points, f"{where} run in this process: {serial:.2g} s, where a pool of {workers} "
                            f"would take about {pooled:.2g} s with its {start_seconds:g} s start-up")
    chunk = max(1, min(math.ceil(CHUNK_SECONDS / max(point_seconds, 1e-6)), math.ceil(points / (2 * workers))))
    return WorkerChoice(workers, chunk, f"{where} run on {workers} worker processes in chunks of {chunk}: about "
                        f"{pooled:.2g} s against {serial:.2g} s in this process")


class AutoRunner:
    """The default local runner: measures a point in this process, then runs the rest there or on a pool
    (:func:`choose_workers`); ``announce`` is told the choice (the CLI prints it on stderr)."""

    def __init__(self, cores: int, stderr: str | None = None,
                 announce: Callable[[str], None] | None = None) -> None:
        self.cores = cores
        self.workers = cores  # (for the caller's first grouping; the choice regroups)
        self.stderr = stderr
        self.announce = announce
        self.choice: WorkerChoice | None = None
        self.pool: ProcessRunner | None = None
        self.serial = SerialRunner()

    def run(self, batches: Iterable[list[Point]], every_step: bool,
            on_results: Callable[[list[PointResult]], None], cancel: Callable[[], bool]) -> bool:
        """``batches``: a :class:`Batches` (its ``count`` tells the choice how many points there are) or
        lists of points; the points are taken from it one by one."""
        stream: Iterator[Point] = batches.stream() if isinstance(batches, Batches) else (
            p for batch in batches for p in batch)
        count = batches.count if isinstance(batches, Batches) else None
        if self.choice is None:
            first = list(itertools.islice(stream, MEASURED_POINTS))
            seconds = 0.0
            for point in first:
                started = time.perf_counter()
                if not self.serial.run([[point]], every_step, on_results, cancel):
                    return False
                seconds = time.perf_counter() - started
            if count is None:  # plain lists: counted (they are held anyway)
                rest = list(stream)
                stream, left = iter(rest), len(rest)
            else:
                left = count - len(first)
            load = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
            self.choice = choose_workers(seconds, left, self.cores, load)
            self.workers = self.choice.workers
            if self.announce is not None:
                self.announce(f"sweep: {self.choice.reason}")
            points = left
        else:
            points = count if count is not None else 1
        if self.choice.workers < 2:
            return self.serial.run([stream], every_step, on_results, cancel)
        if self.pool is None:
            self.pool = ProcessRunner(self.choice.workers, self.stderr)
        size = max(1, min(self.choice.chunk, math.ceil(points / (2 * self.choice.workers))))
        return self.pool.run(batched(stream, size), every_step, on_results, cancel)

    def close(self) -> None:
        if self.pool is not None:
            self.pool.close()


def check_workers(workers: int) -> int:
    """``workers`` if it is from 1 to :func:`max_local_workers`, else an InputError."""
    top = max_local_workers()
    if not 1 <= workers <= top:
        raise InputError("--workers", workers, f"an integer from 1 to {top} ({LOCAL_WORKERS_PER_CORE} per core, "
                         f"{os.cpu_count() or 1} cores)")
    return workers


def make_runner(workers: int | None = None, scheduler: str | None = None, *, stderr: str | None = None,
                announce: Callable[[str], None] | None = None) -> Any:
    """The runner for these settings; a Dask scheduler is connected here (InputError if unreachable).

    ``workers=None`` (the default) chooses from the measured cost of a point (:class:`AutoRunner`, which
    tells ``announce`` what it chose). ``stderr``: where local worker processes write their standard error
    (see :class:`ProcessRunner`).
    """
    if scheduler is not None:
        return DaskRunner(scheduler)
    if workers is None:
        cores = os.cpu_count() or 1
        return SerialRunner() if cores == 1 else AutoRunner(cores, stderr, announce)
    count = check_workers(workers)
    return SerialRunner() if count == 1 else ProcessRunner(count, stderr)


@dataclass
class SweepOutcome:
    """What a sweep produced: results in point order, whether it ran to the end, its wall time."""

    results: list[PointResult]
    complete: bool
    wall_time: float
    skipped: int = 0
    total: int = 0
    extra: dict = field(default_factory=dict)


def run_points(points: Sequence[Point], runner: Any, *, every_step: bool = False,
               sink: Any = None, progress: Callable[[int, int], object] | None = None,
               cancel: Callable[[], bool] | None = None, keep: bool = True) -> SweepOutcome:
    """Evaluate ``points`` with ``runner``; results go to ``sink`` (a :class:`SweepFile`, or
    :class:`vtool.solvers.parquet.SweepParquet`) as they arrive.

    Points already in ``sink`` (a resumed sweep) are skipped. KeyboardInterrupt
    stops the workers, leaves the sink in point order and propagates.
    ``keep=False`` (with a sink) keeps no result in memory: the outcome's
    ``results`` is empty and the file has them. With a planned grid
    (:class:`vtool.presets.paths.PointGrid`) the points' specs are made as they
    run (:class:`Batches`) and only the finished points' indices are held, so a
    large sweep's memory stays bounded (benchmarks/bench_parquet.py).
    """
    cancel = cancel or (lambda: False)
    started = time.perf_counter()
    if sink is not None:
        sink.open(points)
    finished = sink.finished if sink is not None else IndexSet()
    total = len(points)
    results: dict[int, PointResult] = {}
    skipped = len(finished)
    done = skipped

    def collect(batch: list[PointResult]) -> None:
        nonlocal done
        for result in batch:
            if keep or sink is None:
                results[result.index] = result
            if sink is not None:
                sink.append(result)
        done += len(batch)
        if progress is not None:
            progress(done, total)

    if progress is not None:
        progress(done, total)
    complete = False
    batches = Batches(points, finished.copy(), runner.workers)
    try:
        complete = runner.run(batches, every_step, collect, cancel)
    finally:
        if sink is not None:
            sink.finish()
    if sink is not None and keep:
        results = sink.finished_results(points) | results
    ordered = [results[i] for i in sorted(results)]
    return SweepOutcome(ordered, complete, time.perf_counter() - started, skipped, total)


# ----- output -----

def format_value(value: Any) -> str:
    """CSV text of one value: integers as integers, floats to 10 significant digits, NaN empty."""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return ""
        return f"{value:.10g}"
    return str(value)


def _parse_cell(text: str) -> float:
    """Inverse of :func:`format_value` for metrics: empty is NaN, integers stay integers."""
    if not text:
        return math.nan
    return int(text) if text.lstrip("-").isdigit() else float(text)


def column_title(name: str, unit: str) -> str:
    return f"{name} ({unit})" if unit else name


def csv_header(fields: Sequence[tuple[str, str]], spec: MechanismSpec, timing: bool = False) -> list[str]:
    """Swept fields (with units), ``status``, then every metric (with units)."""
    return ([column_title(f, u) for f, u in fields] + ["status"]
            + [column_title(n, u) for n, u in report_columns(spec, timing)])


def csv_row(result: PointResult, metrics: Sequence[tuple[str, str]]) -> list[str]:
    return ([format_value(v) for _, v in result.values] + [result.status]
            + [format_value(result.metrics[n]) for n, _ in metrics])


def csv_lines(rows: Iterable[list[str]]) -> str:
    return csv_text(rows)


def results_csv(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], spec: MechanismSpec,
                timing: bool = False) -> str:
    """The whole sweep as CSV text (the same bytes as a finished :class:`SweepFile`)."""
    metrics = report_columns(spec, timing)
    return csv_lines([csv_header(fields, spec, timing)] + [csv_row(r, metrics) for r in results])


#: Largest --resume file read (bytes): a sweep's CSV is a few hundred bytes a point.
MAX_RESUME_BYTES = 256 * 1024 * 1024


def point_values(points: Sequence[Point]) -> Callable[[int], tuple[tuple[str, Any], ...]]:
    """A function from a point's index to its swept values."""
    if hasattr(points, "run_order"):
        return points.values  # type: ignore[attr-defined]  # a PointGrid: made from the index
    return {p.index: p.values for p in points}.__getitem__


def point_locator(points: Sequence[Point]) -> Callable[[Sequence[str]], int | None]:
    """A function from a point's values as a sweep file writes them to its index (None: not a point)."""
    if hasattr(points, "locate"):
        return points.locate  # a planned grid (PointGrid): nothing per point
    index_of = {tuple(format_value(v) for _, v in p.values): p.index for p in points}
    return lambda texts: index_of.get(tuple(texts))


class SweepFile:
    """A CSV written as points finish, kept valid and resumable; see the module doc.

    Header: the swept fields (with units), ``status``, then the metrics (with
    units); ``timing=False`` leaves out machine-dependent columns (wall time)
    so that files from different execution paths compare byte for byte.

    The file is touched only when the first point finishes (:attr:`written`): a
    sweep stopped before that leaves an existing file as it was. A resumed file
    is checked before it is read (a regular file, not a link, a FIFO or a
    device, at most :data:`MAX_RESUME_BYTES`); the appends go through a
    descriptor opened without following a link (``O_NOFOLLOW``).

    Memory: no row is held. Each line's point index, offset and length in the
    file are (three numbers a point); :meth:`finish` copies the lines in point
    order into the rewritten file, and a resumed file is read line by line.
    """

    def __init__(self, path: str | os.PathLike[str], fields: Sequence[tuple[str, str]], spec: MechanismSpec,
                 *, resume: bool = False, timing: bool = False) -> None:
        self.path = check_output_path(path, "--csv")
        self.fields = [f for f, _ in fields]
        self.metrics = report_columns(spec, timing)
        self.spec = spec
        self.header = csv_header(fields, spec, timing)
        self.resumed = resume
        self.previous: bytes | None = None  # the resumed file's content is read again when the file starts
        if resume and exists(self.path):
            self._check_partial()
        elif resume:
            raise InputError("--resume", str(self.path), "an existing partial sweep file (none found)")
        self.finished = IndexSet()
        self.locate: Callable[[Sequence[str]], int | None] = lambda texts: None
        self.handle: io.TextIOWrapper | None = None
        self.written = False
        self.size = 0
        self.lines = array.array("q")  # (index, offset, length) of each data line written, flat

    @contextlib.contextmanager
    def _resumed(self) -> Iterator[io.BufferedReader]:
        """The resumed file, checked, read from its start."""
        fd = open_no_follow(self.path, os.O_RDONLY | os.O_NONBLOCK, "--resume")  # a FIFO must not block
        with os.fdopen(fd, "rb") as raw:
            st = os.fstat(raw.fileno())
            if not stat.S_ISREG(st.st_mode):
                raise InputError("--resume", str(self.path), "a regular file (not a device, pipe or socket)")
            if st.st_size > MAX_RESUME_BYTES:
                raise InputError("--resume", str(self.path), f"a partial sweep file of at most "
                                 f"{MAX_RESUME_BYTES // 2**20} MB (this one has {st.st_size:,} bytes)")
            yield raw

    def _resumed_rows(self) -> Iterator[tuple[list[str], bytes]]:
        """(cells, line with its newline) of each complete data line of the resumed file, read line by line."""
        with self._resumed() as raw:
            raw.readline()  # the header (checked when the file was opened)
            for line in raw:
                if not line.endswith(b"\n"):  # the last piece without a newline: a line cut by a kill
                    return
                try:
                    cells = next(csv.reader([line.decode("utf-8")]), [])
                except (csv.Error, UnicodeDecodeError):
                    continue
                if len(cells) == len(self.header):
                    yield cells, line

    def _check_partial(self) -> None:
        with self._resumed() as raw:
            first = raw.readline(1 << 20)
        try:
            header = next(csv.reader([first.decode("utf-8")]), []) if first.endswith(b"\n") else []
        except (UnicodeDecodeError, csv.Error):
            raise InputError("--resume", str(self.path), "a partial sweep file (UTF-8 CSV text)") from None
        if header != self.header:
            raise InputError("--resume", str(self.path), "a partial file of this same sweep (its header differs)")

    def open(self, points: Sequence[Point]) -> None:
        """Marks the points already in the file as finished; the file is written at the first new point."""
        self.locate = point_locator(points)
        if self.resumed:
            for cells, _ in self._resumed_rows():
                index = self.locate(cells[: len(self.fields)])
                if index is not None:
                    self.finished.add(index)

    def _start(self) -> None:
        """The file with its header and the kept rows, then a no-follow append descriptor on it."""
        kept = IndexSet()
        with open_atomic(self.path, "--csv") as out:
            self._write(out, self.header_text(), -1)
            if self.resumed:
                for cells, line in self._resumed_rows():
                    index = self.locate(cells[: len(self.fields)])
                    if index is not None and index in self.finished and index not in kept:
                        kept.add(index)
                        self._write(out, line.decode("utf-8"), index)
        fd = open_no_follow(self.path, os.O_WRONLY | os.O_APPEND, "--csv")
        self.handle = os.fdopen(fd, "a", encoding="utf-8", newline="")
        self.written = True

    def header_text(self) -> str:
        return self._text([self.header])

    def _write(self, handle: Any, text: str, index: int) -> None:
        """Write one line, noting where it is (``index`` -1: the header)."""
        handle.write(text)
        length = len(text.encode("utf-8"))
        if index >= 0:
            self.lines.extend((index, self.size, length))
        self.size += length

    def finished_results(self, points: Sequence[Point]) -> dict[int, PointResult]:
        """The points read back from a resumed file (numbers parsed; empty cells NaN)."""
        if not self.resumed or not exists(self.path):
            return {}
        locate = point_locator(points)
        values_of = point_values(points)
        results = {}
        with open(self.path, encoding="utf-8", newline="") as handle:
            for row in itertools.islice(csv.reader(handle), 1, None):
                index = locate(row[: len(self.fields)]) if len(row) == len(self.header) else None
                if index is None or index not in self.finished:
                    continue
                cells = row[len(self.fields) + 1:]
                metrics = failed_metrics(self.spec)  # NaN for the columns the file leaves out (wall time)
                metrics.update({name: _parse_cell(cell) for (name, _), cell in zip(self.metrics, cells,
                                                                                    strict=True)})
                results[index] = PointResult(index, values_of(index), metrics, row[len(self.fields)])
        return results

    def row(self, result: PointResult) -> list[str]:
        return csv_row(result, self.metrics)

    @staticmethod
    def _text(rows: Iterable[list[str]]) -> str:
        return csv_lines(rows)

    def append(self, result: PointResult) -> None:
        if self.handle is None:
            self._start()
        assert self.handle is not None
        self._write(self.handle, self._text([self.row(result)]), result.index)
        self.handle.flush()

    def finish(self) -> None:
        """Close, and rewrite the file atomically in point order (untouched if no point was added)."""
        if self.handle is not None:
            self.handle.close()
            self.handle = None
        if not (self.written or self.resumed):
            return
        if not self.written:  # resumed, nothing new: the kept rows, in order, without the cut line
            self._start()
            assert self.handle is not None
            self.handle.close()
            self.handle = None
        import numpy as np

        lines = np.frombuffer(self.lines, dtype=np.int64).reshape(-1, 3)
        order = np.argsort(lines[:, 0], kind="stable")
        fd = open_no_follow(self.path, os.O_RDONLY, "--csv")
        try:
            with open_atomic(self.path, "--csv") as out:
                out.write(self.header_text())
                for _, offset, length in lines[order]:
                    out.write(os.pread(fd, int(length), int(offset)).decode("utf-8"))
        finally:
            os.close(fd)


# ----- derived speeds -----

#: criterion name -> (metric, test, words); the criteria themselves: vtool.solvers.studies.metrics
CRITERIA: dict[str, tuple[str, Callable[[float], bool], str]] = {
    "jump-speed": ("cam_separations", lambda v: v >= 1, "the follower leaves the cam during lift"),
    "bounce-speed": ("seat_bounces", lambda v: v >= 1, "the valve bounces on its seat"),
    "coil-bind-speed": ("coil_bind_margin", lambda v: v <= 0.0, "a valve spring's coils touch (data-sheet spring)"),
}


@dataclass(frozen=True)
class Bracket:
    """One step of a speed search: the speed tried and whether the criterion held."""

    rpm: float
    holds: bool
    value: float
    stage: str  # "scan" or "bisect"
    status: str = OK


@dataclass(frozen=True)
class Interval:
    """A speed interval where the criterion holds: its bisected edges (rev/min) and the speeds just outside.

    ``low`` is the lowest speed found where it holds and ``below`` the highest where it does not (None:
    it holds at the lowest scanned speed); ``high`` and ``above`` likewise at the top (None: it holds at
    the highest scanned speed)."""

    low: float
    high: float
    below: float | None
    above: float | None

    def text(self) -> str:
        low = f"{self.low:g}" if self.below is not None else f"{self.low:g} (the lowest scanned speed, or below)"
        high = f"{self.high:g}" if self.above is not None else f"{self.high:g} (the highest scanned speed, or above)"
        outside = [f"not at {v:g}" for v in (self.below, self.above) if v is not None]
        return f"{low} to {high} rev/min" + (f" ({', '.join(outside)})" if outside else "")


@dataclass(frozen=True)
class SpeedResult:
    criterion: str
    speed: float | None  # rev/min: lowest speed found where the criterion holds; None if not bracketed
    history: tuple[Bracket, ...]
    message: str
    intervals: tuple[Interval, ...] = ()  # every speed interval where it holds, bisected at both ends


def find_speed(criterion: str, make_spec: Callable[[float], MechanismSpec], scan: Sequence[float],
               runner: Any, *, tolerance: float = 1.0, every_step: bool = False,
               report: Callable[[Bracket], None] | None = None,
               cancel: Callable[[], bool] | None = None, bisector: Any = None) -> SpeedResult:
    """Every cam-speed interval where ``criterion`` holds, each edge bisected to ``tolerance`` rev/min.

    The speeds ``scan`` (ascending) are run together on ``runner``; every change between neighbouring
    scanned speeds (holds / does not) brackets an edge, which is then bisected (integer speeds for
    tolerance 1). A window of contact loss below a window of contact is its own interval; an interval
    narrower than the scan's step can fall between two scanned speeds unseen (scan finer). ``speed``
    is the lowest edge (the jump speed), None when the criterion holds at no scanned speed or already
    at the lowest. The bisections run one point at a time on ``bisector`` (default: in this process).
    """
    if criterion not in CRITERIA:
        raise InputError("--find", criterion, f"one of: {', '.join(CRITERIA)}")
    metric, test, words = CRITERIA[criterion]
    history: list[Bracket] = []

    def note(rpm: float, result: PointResult, stage: str) -> bool:
        if not result.ok:
            raise RunError(f"{criterion}: the run at {rpm:g} rev/min failed: {result.status}")
        value = result.metrics[metric]
        entry = Bracket(rpm, bool(test(value)), value, stage)
        history.append(entry)
        if report is not None:
            report(entry)
        return entry.holds

    scan = sorted(scan)
    points = [Point(i, (("run.rpm", rpm),), make_spec(rpm)) for i, rpm in enumerate(scan)]
    outcome = run_points(points, runner, every_step=every_step, cancel=cancel)
    if not outcome.complete:
        raise RunError(f"{criterion}: stopped during the scan")
    holds = [note(rpm, r, "scan") for rpm, r in zip(scan, outcome.results, strict=True)]
    if not any(holds):
        return SpeedResult(criterion, None, tuple(history), f"{words} at none of the scanned speeds "
                                                            f"(up to {scan[-1]:g} rev/min)")
    serial = bisector if bisector is not None else SerialRunner()

    def bisect(low: float, high: float, rising: bool) -> tuple[float, float]:
        """(the last speed on the low side, the first on the high side) of one edge."""
        while high - low > tolerance:
            if cancel is not None and cancel():
                raise RunError(f"{criterion}: stopped while bisecting between {low:g} and {high:g} rev/min")
            mid = math.floor((low + high) / 2) if tolerance >= 1 else (low + high) / 2
            if mid <= low:
                mid = (low + high) / 2
            result = run_points([Point(0, (("run.rpm", mid),), make_spec(mid))], serial, every_step=every_step)
            if note(mid, result.results[0], "bisect") == rising:
                high = mid
            else:
                low = mid
        return low, high

    intervals = []
    start: tuple[float, float | None] | None = (scan[0], None) if holds[0] else None
    for i in range(1, len(scan)):
        if holds[i] and not holds[i - 1]:
            below, low = bisect(scan[i - 1], scan[i], rising=True)
            start = (low, below)
        elif holds[i - 1] and not holds[i]:
            assert start is not None
            high, above = bisect(scan[i - 1], scan[i], rising=False)
            intervals.append(Interval(start[0], high, start[1], above))
            start = None
    if start is not None:
        intervals.append(Interval(start[0], scan[-1], start[1], None))
    first = intervals[0]
    if first.below is None:
        message = f"{words} already at the lowest scanned speed ({scan[0]:g} rev/min): scan lower"
        speed = None
    else:
        message = f"{words} from {first.low:g} rev/min (not at {first.below:g})"
        speed = first.low
    return SpeedResult(criterion, speed, tuple(history), message, tuple(intervals))


def scan_intervals(results: Sequence[PointResult], field: str, criterion: str) -> list[tuple[float, float]]:
    """(first, last) swept value of every run of neighbouring points (in ``field``'s order) where ``criterion``
    (a :data:`CRITERIA` name) holds: the intervals a scan shows, edges not bisected (``find_speed`` does)."""
    metric, test, _ = CRITERIA[criterion]
    points = sorted(((dict(r.values)[field], r) for r in results if r.ok), key=lambda vr: vr[0])
    intervals: list[tuple[float, float]] = []
    start = None
    for k, (value, result) in enumerate(points):
        if test(result.metrics[metric]):
            start = value if start is None else start
        elif start is not None:
            intervals.append((start, points[k - 1][0]))
            start = None
    if start is not None:
        intervals.append((start, points[-1][0]))
    return intervals


# ----- reports -----

def report_columns(spec: MechanismSpec, timing: bool = True) -> list[tuple[str, str]]:
    return [(n, u) for n, u in metric_columns(spec) if timing or n not in TIMING_METRICS]


def results_table(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], spec: MechanismSpec) -> str:
    """A plain text table: one row per point, units on a second header line."""
    columns = [(f, u) for f, u in fields] + report_columns(spec)
    header = [name for name, _ in columns] + ["status"]
    units = [f"({u})" if u else "" for _, u in columns] + [""]
    rows = []
    for r in results:
        cells = [format_value(v) for _, v in r.values]
        for name, _ in report_columns(spec):
            value = r.metrics[name]
            cells.append("-" if isinstance(value, float) and math.isnan(value)
                         else f"{value:.4g}" if isinstance(value, float) else str(value))
        rows.append(cells + [r.status])
    widths = [max(len(h), len(u), *(len(row[i]) for row in rows)) for i, (h, u) in enumerate(zip(header, units,
                                                                                                 strict=True))]
    lines = ["  ".join(h.rjust(w) for h, w in zip(header, widths, strict=True)).rstrip(),
             "  ".join(u.rjust(w) for u, w in zip(units, widths, strict=True)).rstrip()]
    lines += ["  ".join(c.rjust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in rows]
    return "\n".join(lines)


def _json_value(value: Any) -> Any:
    return None if isinstance(value, float) and math.isnan(value) else value


def results_json(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], spec: MechanismSpec,
                 preset: str) -> dict:
    """The sweep as a JSON-ready dict: units as ``*_unit`` keys, NaN as null."""
    columns = report_columns(spec)
    units = {f"{f}_unit": u for f, u in fields} | {f"{n}_unit": u for n, u in columns}
    return {
        "preset": preset,
        "title": spec.title,
        "fields": [f for f, _ in fields],
        "metrics": [n for n, _ in columns],
        "units": units,
        "points": [dict(r.values) | {"status": r.status} | {n: _json_value(r.metrics[n]) for n, _ in columns}
                   for r in results],
    }
