"""Page faults per warm run of example 1A: what a run costs the operating system in fresh memory.

Run: ``python3 benchmarks/bench_page_faults.py [--runs N]`` (N = 200). Prints figures, asserts nothing.

A warm run that allocates large arrays and frees them again takes fresh pages at every run, once
the C library has returned the freed memory to the system, and each page is faulted in on first
touch (on the 2-core machine a few microseconds each). Whether it returns them depends on what
else lies on the heap: a process with numba imported rarely does, a process on the kernel's
native module (the default once it is built: numba not imported) did at every run. So the
process's minor page faults (``resource.getrusage``'s ``ru_minflt``) are counted over N warm
``simulate(spec)`` runs after a warm-up, in a process of each kind, with the best time of those
runs. The native module is the one the default mode builds after a first run (``vtool solve
gnilka-1a``, then wait for the background build); without it that line says so.
"""

from __future__ import annotations

import os
import subprocess
import sys

ONE = """
import resource, time
from vtool.presets import load_preset
from vtool.solvers.run import simulate
spec = load_preset("gnilka-1a")
for _ in range(20):
    trace = simulate(spec)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
best = float("inf")
for _ in range({runs}):
    started = time.perf_counter()
    simulate(spec)
    best = min(best, time.perf_counter() - started)
print(trace.statistics.kernel, resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before, best)
"""


def main(argv: list[str]) -> None:
    runs = int(argv[argv.index("--runs") + 1]) if "--runs" in argv else 200
    for mode, what in (("compiled", "numba's kernel (numba imported)"), ("auto", "the native module")):
        env = dict(os.environ, VTOOL_KERNEL=mode, VTOOL_NATIVE="1")
        out = subprocess.run([sys.executable, "-c", ONE.format(runs=runs)], env=env, capture_output=True,
                             text=True, check=True)
        kernel, faults, best = out.stdout.split()[-3:]
        if mode == "auto" and kernel != "native":
            print(f"gnilka-1a on {what}: none built for this checkout yet (the runs took the {kernel} kernel); "
                  "run `vtool solve gnilka-1a` and wait for the background build")
            continue
        print(f"gnilka-1a on {what}: {int(faults) / runs:.1f} minor page faults a warm run ({faults} over {runs}); "
              f"best run {float(best) * 1e3:.2f} ms")


if __name__ == "__main__":
    main(sys.argv[1:])
