"""Newmark back end benchmark: example 1A (850 degrees, dt = 1e-6 s, about 12,900 steps).

Run: ``python3 benchmarks/bench_newmark.py``. Prints figures, asserts nothing.

1. Warm wall time of a whole run (assemble + simulate), best of several,
   after the JIT warm-up, and as a ratio to the 20 ms target.
2. Start-up of a second process with the numba cache on: wall time of
   ``vtool solve gnilka-1a`` in a fresh interpreter, and whether numba
   compiled anything in it (it must not: the cache is reused).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

from vtool.presets import load_preset
from vtool.solvers.run import simulate

TARGET_S = 0.020


def warm_run_time(name: str, repeat: int = 9) -> tuple[float, int, int]:
    spec = load_preset(name)
    simulate(spec)  # JIT warm-up (or cache load)
    best = float("inf")
    for _ in range(repeat):
        started = time.perf_counter()
        trace = simulate(spec)
        best = min(best, time.perf_counter() - started)
    return best, trace.statistics.steps, trace.statistics.events


SECOND_PROCESS = """
import time
started = time.perf_counter()
from click.testing import CliRunner
from vtool.app.cli.main import cli
result = CliRunner().invoke(cli, ["solve", "gnilka-1a"])
assert result.exit_code == 0, result.output
elapsed = time.perf_counter() - started
from vtool.solvers import newmark_kernel
stats = newmark_kernel.run_chunk.stats
print(elapsed, sum(stats.cache_misses.values()), sum(stats.cache_hits.values()))
"""


def second_process() -> tuple[float, float, int, int]:
    """(process wall time, in-process solve time, numba cache misses, cache hits) of the run loop."""
    started = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", SECOND_PROCESS], capture_output=True, text=True, check=True,
                         env=dict(os.environ))
    total = time.perf_counter() - started
    solve_time, misses, hits = out.stdout.split()
    return total, float(solve_time), int(misses), int(hits)


def main() -> None:
    print("Newmark back end, example 1A (850 deg, dt = 1e-6 s)")
    for name in ("gnilka-1a", "gnilka-1d", "gnilka-2"):
        best, steps, events = warm_run_time(name)
        print(f"  {name}: warm run {best * 1e3:7.2f} ms  ({steps} steps, {events} events, "
              f"{best / steps * 1e9:6.0f} ns/step)  ratio to the 20 ms target: {best / TARGET_S:.2f}")
    second_process()  # make sure the cache exists
    total, solve_time, misses, hits = second_process()
    print(f"  second process: `vtool solve gnilka-1a` {solve_time:.3f} s in-process "
          f"({total:.2f} s with interpreter start-up); run loop from the numba cache: "
          f"{hits} hit(s), {misses} miss(es) (a miss means it recompiled)")


if __name__ == "__main__":
    main()
