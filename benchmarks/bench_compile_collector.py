"""Python's garbage collector during the kernel's first compile: on, and paused as the solver pauses it.

Run: ``python3 benchmarks/bench_compile_collector.py [--pairs N]`` (N = 2 pairs by default,
about 25 s a process on two cores). Prints figures, asserts nothing.

Each process compiles ``gnilka-1a``'s kernel with an empty numba cache in one process, one
function after another (``run_chunk`` and all its callees, no helper process), either with
the collector as Python sets it or inside ``kernel_build.collector_paused()``, as
``compile_kernel`` and its helper compile. It prints the compile's wall time, the time of
the collector's passes (``gc.callbacks``) and the process's peak resident memory. The two
modes alternate, so that a machine whose speed drifts slows both alike.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

ONE = """
import contextlib, gc, os, resource, sys, tempfile, time
os.environ["NUMBA_CACHE_DIR"] = tempfile.mkdtemp()
sys.path.insert(0, {benchmarks!r})
import bench_compile_phases
types = bench_compile_phases.signature("gnilka-1a")
from vtool.solvers.newmark import build as kernel_build
kernel = kernel_build.kernel()
spent = [0.0, 0]
started = []
def timer(phase, info):
    if phase == "start":
        started.append(time.perf_counter())
    else:
        spent[0] += time.perf_counter() - started.pop()
        spent[1] += 1
gc.callbacks.append(timer)
paused = kernel_build.collector_paused() if {paused!r} else contextlib.nullcontext()
begin = time.perf_counter()
with paused:
    kernel.run_chunk.compile(types)
wall = time.perf_counter() - begin
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(wall, spent[0], spent[1], peak)
"""


def one(paused: bool) -> tuple[float, float, int, float]:
    code = ONE.format(benchmarks=str(ROOT / "benchmarks"), paused=paused)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    wall, collector, passes, peak = out.stdout.split()[-4:]
    return float(wall), float(collector), int(passes), float(peak)


def main(argv: list[str]) -> None:
    pairs = int(argv[argv.index("--pairs") + 1]) if "--pairs" in argv else 2
    runs: dict[bool, list[tuple[float, float, int, float]]] = {False: [], True: []}
    print("first compile of gnilka-1a's kernel in one process, empty cache")
    for _ in range(pairs):
        for paused in (False, True):
            result = one(paused)
            runs[paused].append(result)
            wall, collector, passes, peak = result
            print(f"  collector {'paused' if paused else 'on    '}: {wall:5.1f} s wall, collector {collector:4.2f} s "
                  f"in {passes} passes, peak {peak:.0f} MB", flush=True)
    on, off = (statistics.median(r[0] for r in runs[p]) for p in (False, True))
    print(f"median wall: collector on {on:.1f} s, paused {off:.1f} s; ratio {off / on:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
