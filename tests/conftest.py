"""Test-session settings.

``VTOOL_KERNEL=compiled``: every run in the tests (and in the processes they
start) compiles the Newmark kernel in-process, or loads it from numba's cache,
before its first step, so that each test runs the compiled kernel it means to
test and no background compile competes with the suite for the CPU. The first
run's other paths (``auto``, ``plain``) have their own tests, which set the
variable themselves (tests/test_first_run.py).

``VTOOL_NATIVE=0``: no run builds or uses the kernel's native module
(:mod:`vtool.solvers.kernel_native`), so that a test in ``auto`` mode starts no
native build in the background; the native module's own tests set it to 1.

The suite runs on pytest-xdist workers (``-n auto``, at most four: see
``pyproject.toml``), each a process of its own that imports this file: the
workers share numba's cache, so a kernel one of them compiled is loaded by
the others. On the 2-core development machine two workers took the suite
from 8 min 21 s to 5 min 34 s (2026-11-26, empty numba cache both times).

Python's garbage collector: each test process sets it as ``vtool tui`` does
(``vtool.app.cli.tui.tune_collector``: what is imported is frozen, never
scanned again, and it collects less often). A TUI test
makes hundreds of thousands of short-lived objects (Textual's styles,
messages, strips), and the collector's passes over them and over the
imported modules were a sixth to a fifth of the TUI tests' time (the two
valve-train TUI files: 73 s, then 60 s with these settings, one run each). What the
tests check does not depend on when cycles are collected.
"""

import gc
import os

os.environ["VTOOL_KERNEL"] = "compiled"
os.environ["VTOOL_NATIVE"] = "0"


def pytest_configure(config) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """The collector as ``vtool tui`` sets it; pytest's own objects frozen."""
    from vtool.app.cli.tui import tune_collector

    tune_collector()


def pytest_collection_finish(session) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """The test modules and what they import (numpy, numba, Textual, vtool) frozen too."""
    gc.freeze()
