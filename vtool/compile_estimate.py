"""How long a first compile will take on this machine: the seconds in the line that announces it.

A numba compile is single-threaded work in each of its processes (numba's
typing and lowering in Python, LLVM's passes in C++), so its time follows
the machine's speed at such work and the cores it can have. Each estimate
is a time measured on a reference machine, scaled to this one:

    seconds = reference_s * (p / p_ref) * max(1, (L + n) / c)

* p: a small interpreted probe here (:func:`probe`: objects, dict lookups,
  attribute access and calls, as a compiler makes; the best of five, about
  7 ms in all), p_ref = :data:`PROBE_REFERENCE_S` the same on the reference
  machine. That the compile follows the probe from one machine to another
  is assumed, not measured: the one machine before the reference took
  8-9.4 s for the kernel's compile against 2.8-3.0 s here, and the probe
  was not run there. Its spread between processes on one machine is ~7 %.
* n: the compile's processes (2 for the Newmark kernel: a helper compiles
  part of its callees, :mod:`vtool.solvers.newmark.build`; 1 otherwise),
  c: the cores (``os.cpu_count()``), L: the processes already wanting a
  core (:func:`others_running`). The reference machine
  had two idle cores, where the factor is 1. With one of its two cores
  kept busy, the kernel's compile took 1.5x as long, as (1 + 2) / 2 says.

The probe runs once per process and only when a notice is shown (a cache
miss): a first run pays about 7 ms for it. ``python3
benchmarks/bench_compile_estimate.py`` measures each compile with empty
caches and prints the estimate beside it; the reference times
(``COMPILE_REFERENCE_S`` and alike in :mod:`vtool.solvers.newmark.backend` and
:mod:`vtool.csvrows`) are its figures on the reference machine (a 2-core
AMD EPYC, 2026-11-26).
"""

from __future__ import annotations

import math
import os
import time

#: the probe's best time on the reference machine (s)
PROBE_REFERENCE_S = 1.2e-3

_probed: list[float] = []


def _probe_once() -> None:
    class Node:
        __slots__ = ("name", "args", "kind")

        def __init__(self, name: str, args: tuple[int, int], kind: str) -> None:
            self.name, self.args, self.kind = name, args, kind

    table: dict[str, list[str]] = {}
    nodes = []
    for i in range(3000):
        node = Node(f"v{i % 97}", (i, i >> 1), "add" if i & 1 else "mul")
        nodes.append(node)
        table.setdefault(node.kind, []).append(node.name)
    total = 0
    for node in nodes:
        total += len(table[node.kind]) + node.args[1]


def probe() -> float:
    """Seconds of the probe here, the best of five (measured once per process)."""
    if not _probed:
        best = math.inf
        for _ in range(5):
            started = time.perf_counter()
            _probe_once()
            best = min(best, time.perf_counter() - started)
        _probed.append(best)
    return _probed[0]


def _runnable() -> float | None:
    """Threads running or ready to run now that are not this process' (Linux: ``/proc/loadavg`` counts all
    of them; this process' own are those of ``/proc/self/task`` in state R, such as BLAS threads still
    spinning after a product), or None."""
    try:
        with open("/proc/loadavg", encoding="ascii") as handle:
            everyone = float(handle.read().split()[3].split("/")[0])
        own = 0
        for task in os.scandir("/proc/self/task"):
            try:
                with open(f"{task.path}/stat", encoding="ascii") as handle:
                    own += handle.read().rpartition(")")[2].split()[0] == "R"
            except OSError:  # (the thread ended meanwhile)
                continue
        return max(0.0, everyone - own)
    except (OSError, IndexError, ValueError):
        return None


def others_running() -> float:
    """L: the other processes that want a core now. On Linux the threads ready to run, counted at five
    moments 1 ms apart, less this process' own; elsewhere the load average over the last minute (which
    still counts work that ended up to a minute ago)."""
    counts = []
    for _ in range(5):
        count = _runnable()
        if count is None:
            break
        counts.append(count)
        time.sleep(1e-3)
    if counts:
        return max(0.0, sum(counts) / len(counts))
    try:
        return os.getloadavg()[0]
    except OSError:  # (not on every platform)
        return 0.0


def load_factor(processes: int) -> float:
    """max(1, (L + n) / c): how much longer ``processes`` compiling processes take for want of cores."""
    return max(1.0, (others_running() + processes) / (os.cpu_count() or 1))


def seconds(reference_s: float, processes: int = 1) -> float:
    """The compile that took ``reference_s`` on the reference machine, here and now (s)."""
    return reference_s * probe() / PROBE_REFERENCE_S * load_factor(processes)


def about(reference_s: float, processes: int = 1) -> str:
    """``seconds`` as the notice shows it: whole seconds, rounded up (a compile that ends before the time
    announced surprises nobody)."""
    return f"{max(1, math.ceil(seconds(reference_s, processes))):d}"
