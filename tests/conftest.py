"""Test-session settings.

The suite runs on pytest-xdist workers (``-n auto``, at most four: see
``pyproject.toml``), each a process of its own that imports this file: the
workers share numba's cache, so a kernel one of them compiled is loaded by
the others. On the 2-core development machine two workers took the suite
from 8 min 21 s to 5 min 34 s (2026-11-26, empty numba cache both times).

Scheduling: ``--dist loadgroup`` (pyproject's addopts) sends the modules marked
``xdist_group`` whole to one worker, and first, the larger groups before the
smaller and before the single tests: the longest tests (the valve-train
tables' studies, mypy) start at once and the
short ones fill in at the end, so that neither worker idles at the end of a run
(mypy last took 16 s of tail, 2026-11-26). tests/test_tables_valvetrain.py
checks that pytest-xdist still sees the groups. The single tests go out in
collection order, and :func:`pytest_collection_modifyitems` puts those
marked ``slow`` (a few seconds or more) first: a long test sent last kept one
worker busy 4-8 s after the other had finished (three empty-cache runs,
2026-11-28).

Compiles shared out: in a whole run on pytest-xdist workers (at least
:data:`SHARED_OUT_FROM` tests), each worker first compiles its share of the
kernels the suite needs (the newmark kernel per contact-law pair, the event
rules of the piecewise back ends) into numba's shared cache, a different share
on each worker, and loads the rest from the cache when a test needs it. Without
it both workers' first tests wanted the same kernel and one waited for the
other's compile (10-16 s idle in each empty-cache run, 2026-11-26).

Python's garbage collector: each test process sets it as ``vtool tui`` does
(``vtool.app.cli.tui.tune_collector``: what is imported is frozen, never
scanned again, and it collects less often). A TUI test
makes hundreds of thousands of short-lived objects (Textual's styles,
messages, strips), and the collector's passes over them and over the
imported modules were a sixth to a fifth of the TUI tests' time (the two
valve-train TUI files: 73 s, then 60 s with these settings, one run each). What the
tests check does not depend on when cycles are collected.

At the session's end pytest collects five times over (its check for
exceptions raised in finalizers, at unconfigure), and each pass scanned the
worker's whole heap, numba's compile state included: 2-4 s after the last
test, while the run waited for the worker to exit. :func:`pytest_sessionfinish`
collects first, until a pass finds nothing (pytest's hook for those exceptions
is in place then, so any is reported as before), and freezes what lives:
pytest's own passes then scan only what is made after.
"""

import gc
import os
import signal
import threading
from collections.abc import Iterator

import pytest


def pytest_configure(config) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """The collector as ``vtool tui`` sets it; pytest's own objects frozen."""
    from vtool.app.cli.tui import tune_collector

    tune_collector()


def pytest_collection_modifyitems(items) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """The tests marked ``slow`` first, the others after them, each in collection order (see the module
    doc, "Scheduling")."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


def pytest_collection_finish(session) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """The test modules and what they import (numpy, numba, Textual, vtool) frozen too."""
    gc.freeze()


#: full collections at the session's end at most, until one finds nothing (see pytest_sessionfinish)
FINAL_COLLECTIONS = 5


def pytest_sessionfinish(session) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """Every unreachable cycle collected now, and what lives frozen (see the module doc, "Python's
    garbage collector")."""
    for _ in range(FINAL_COLLECTIONS):
        if not gc.collect():
            break
    gc.freeze()


#: the fewest collected tests for which the workers share out the compiles (a whole run, not a file)
SHARED_OUT_FROM = 300


def _compile_run(backend: str = "newmark", impact: str | None = None, hertz: bool = False) -> None:
    """A run of one degree (its kernel compiled, or loaded from numba's cache)."""
    from vtool.presets import load_preset
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.compare import with_model

    if hertz:
        from tests.test_compliant import hertz_doc
        from tests.valvetrain_cases import spec_from

        spec = spec_from(hertz_doc())
    else:
        spec = with_run_overrides(with_model(load_preset("gnilka-1a"), impact), degrees=1.0, backend=backend)
    simulate(spec)


#: in turn over the workers: worker k compiles entries k, k + n, ... (n workers)
#: (on two workers 12 and 17 s: the newmark kernel 11 s, the Hertz one 10, the momentum one 8, the rules 1)
SHARED_COMPILES = (
    lambda: _compile_run(),  # the thesis presets' newmark kernel
    lambda: _compile_run(hertz=True),
    lambda: _compile_run("exact"),  # the piecewise back ends' event rules
    lambda: _compile_run(impact="momentum"),
)


@pytest.fixture(scope="session", autouse=True)
def compiles_shared_out(request: pytest.FixtureRequest) -> None:
    """This worker's share of the suite's compiles, before its first test (see the module doc)."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")
    if not worker.startswith("gw") or len(request.session.items) < SHARED_OUT_FROM:
        return
    count = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    for compile_kernel in SHARED_COMPILES[int(worker[2:])::count]:
        compile_kernel()


#: SIGINTs this process received (see stop_after_an_interrupt)
_received: list[int] = []


def _in_gc_callback(frame) -> bool:  # type: ignore[no-untyped-def]  # noqa: ANN001  (a frame)
    """Whether the frame or one that called it is a function in ``gc.callbacks`` (hypothesis times the
    collector with one while a test runs)."""
    codes = {getattr(callback, "__code__", None) for callback in gc.callbacks}
    while frame is not None:
        if frame.f_code in codes:
            return True
        frame = frame.f_back
    return False


def _interrupt(signum: int, frame) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001  (a frame)
    if frame is not None and _in_gc_callback(frame):
        from vtool.app.cli.main import deliver_again

        deliver_again(signum)
        return
    _received.append(signum)
    raise KeyboardInterrupt


def pytest_sessionstart(session) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """Ctrl+C (or a deadline's SIGINT to the process group) stops the run wherever it lands.

    An interrupt raised inside a garbage-collector callback is unraisable: Python prints it and drops it.
    The suite then went on to the end, passed, and closed with "PytestUnraisableExceptionWarning:
    Exception ignored in: <function gc_cumulative_time.<locals>.gc_callback> ... KeyboardInterrupt"
    (hypothesis' callback; reproduced with SIGINT 9 s into a run of its test files). :func:`_interrupt`
    raises KeyboardInterrupt as Python's handler does, or sends the signal again 20 ms later while a
    callback runs (tests/test_interrupts.py). Installed before collection, in every process (the
    workers and the controller) and their main thread."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _interrupt)


@pytest.fixture(autouse=True)
def stop_after_an_interrupt(request: pytest.FixtureRequest) -> Iterator[None]:
    """The run stops after a test during which SIGINT arrived, also when the code under test took the
    interrupt as a program does (``vtool`` through CliRunner: exit 130, "interrupted: nothing was
    written"): the test failed on the 130 and the run went on to the end."""
    yield
    if _received:
        request.session.shouldstop = "interrupted (SIGINT)"
