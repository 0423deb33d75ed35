"""The compile notices' estimates (vtool.compile_estimate): the scaling law of its docstring, and the
notices that show it."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import time

import pytest

from vtool import compile_estimate
from vtool.solvers.newmark import backend as newmark
from vtool.solvers.newmark import build as kernel_build


def test_the_probe_is_measured_once_per_process() -> None:
    first = compile_estimate.probe()
    assert 0.0 < first < 1.0 and compile_estimate.probe() == first


@pytest.mark.parametrize(("cores", "running", "processes", "factor"), [
    (2, [0, 0, 0, 0, 0], 2, 1.0),   # nothing else: two idle cores for two compiling processes
    (2, [1, 1, 1, 1, 1], 2, 1.5),   # one other busy process: (1 + 2) / 2
    (2, [0, 0, 0, 0, 0], 3, 1.5),   # a first run beside a compile of two processes
    (1, [0, 0, 0, 0, 0], 2, 2.0),   # one core for two processes
    (8, [3, 3, 3, 3, 3], 2, 1.0),   # cores to spare
    (2, [2, 1, 2, 1, 4], 2, 2.0),   # the mean of the five counts: L = 2, (2 + 2) / 2
])
def test_the_load_factor_is_cores_wanted_over_cores(monkeypatch, cores, running, processes, factor) -> None:  # noqa: ANN001
    counts = iter(running)
    monkeypatch.setattr(compile_estimate, "_runnable", lambda: float(next(counts)))
    monkeypatch.setattr(compile_estimate.os, "cpu_count", lambda: cores)
    assert compile_estimate.load_factor(processes) == pytest.approx(factor)


@pytest.mark.skipif(not os.path.exists("/proc/loadavg"), reason="Linux only")
def test_a_busy_process_is_counted() -> None:
    spinner = subprocess.Popen([sys.executable, "-c", "while True: pass"])
    try:
        time.sleep(0.3)  # (its interpreter started)
        assert compile_estimate.others_running() >= 1.0
    finally:
        spinner.kill()
        spinner.wait()


def test_without_proc_the_load_average_counts(monkeypatch) -> None:  # noqa: ANN001
    monkeypatch.setattr(compile_estimate, "_runnable", lambda: None)
    monkeypatch.setattr(compile_estimate.os, "getloadavg", lambda: (3.0, 0.0, 0.0))
    monkeypatch.setattr(compile_estimate.os, "cpu_count", lambda: 2)
    assert compile_estimate.load_factor(1) == pytest.approx(2.0)


@pytest.mark.parametrize(("speed", "load", "expected"), [(1.0, 1.0, 3), (3.0, 1.0, 9), (0.5, 1.0, 2),
                                                         (3.0, 1.5, 13), (0.01, 1.0, 1)])
def test_the_estimate_scales_the_reference_and_rounds_up(monkeypatch, speed, load, expected) -> None:  # noqa: ANN001
    """seconds = reference * (p / p_ref) * load factor, announced in whole seconds rounded up, at least 1."""
    monkeypatch.setattr(compile_estimate, "probe", lambda: compile_estimate.PROBE_REFERENCE_S * speed)
    monkeypatch.setattr(compile_estimate, "load_factor", lambda processes: load)
    assert compile_estimate.seconds(2.8, 2) == pytest.approx(2.8 * speed * load)
    assert compile_estimate.about(2.8, 2) == str(expected) == str(max(1, math.ceil(2.8 * speed * load)))


class _Uncached:
    def is_cached(self, *args: object) -> bool:
        return False


@pytest.mark.parametrize(("backend", "mode", "reference", "processes"), [
    ("newmark", "compiled", newmark.COMPILE_REFERENCE_S, 2),
    ("exact", "compiled", newmark.RULES_REFERENCE_S, 1),
    ("newmark", "auto", newmark.BACKGROUND_REFERENCE_S, 3),
])
def test_the_notices_announce_the_estimate_for_this_machine(monkeypatch, backend, mode, reference,  # noqa: ANN001
                                                             processes) -> None:
    monkeypatch.setattr(compile_estimate, "probe", lambda: compile_estimate.PROBE_REFERENCE_S * 3.0)
    monkeypatch.setattr(compile_estimate, "load_factor", lambda n: {1: 1.0, 2: 1.25, 3: 1.5}[n])
    monkeypatch.setattr(kernel_build, "kernel_mode", lambda: mode)
    monkeypatch.setattr(kernel_build, "jit_enabled", lambda: True)
    monkeypatch.setattr(kernel_build, "kernel", lambda: _Uncached())
    monkeypatch.setattr(newmark.kernel_native, "exists", lambda laws: False)
    monkeypatch.setattr(newmark.numba_cache, "CACHE_ENABLED", True)
    notice = newmark.compile_notice(backend)
    factor = {1: 1.0, 2: 1.25, 3: 1.5}[processes]
    assert notice is not None and f"(about {math.ceil(reference * 3.0 * factor)} s)" in notice
