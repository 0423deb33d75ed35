"""Exact back end benchmark: example 1A (850 degrees), with the newmark back end in the same run.

Run: ``python3 benchmarks/bench_exact.py [--write]``. Prints figures, asserts nothing;
``--write`` also writes them into the ``exact-1a`` block of docs/valvetrain.md.

1. Warm wall time and CPU time of a whole run (simulate on an assembled mechanism),
   best of several, with the BLAS threads limited to one (vtool.threads), and the
   ratio to the 50 ms target. The configurations' state spaces and decompositions are
   kept with the mechanism, so this is the cost of a second run of one mechanism.
2. The newmark back end (1 us, with its refinement after events) in the same run.
3. The exact back end on a fresh mechanism each time (assemble, build the configurations'
   state spaces and decompositions, run): what a first run in a process costs.
The scan samples, events and peak forces are the columns a test regenerates.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from vtool.markdown import replace_block, table
from vtool.presets import load_preset
from vtool.solvers.exact.backend import ExactBackend
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.newmark.backend import NewmarkBackend
from vtool.threads import limited

TARGET_S = 0.050
ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "valvetrain.md"
BLOCK = "exact-1a"


class _Fresh:
    """Stands for a mechanism that is assembled anew for every run (see best_times)."""

    def __init__(self, spec: object) -> None:
        self.spec = spec


def best_times(backend: object, mechanism: object, repeat: int) -> tuple[float, float, object]:
    def run() -> object:
        return backend.simulate(assemble(mechanism.spec) if isinstance(mechanism, _Fresh) else mechanism)

    run()  # warm-up (numba kernels, imports)
    wall = cpu = float("inf")
    trace = None
    for _ in range(repeat):
        started, started_cpu = time.perf_counter(), time.process_time()
        trace = run()
        wall = min(wall, time.perf_counter() - started)
        cpu = min(cpu, time.process_time() - started_cpu)
    return wall, cpu, trace


HEADER = ("run", "wall time (ms)", "CPU time (ms)", "wall / 50 ms target", "scan samples", "events",
          "peak F1, F2, F7 (lbf)")


def deterministic(trace: object) -> tuple[str, str, str]:
    """The columns a test can regenerate: scan samples, events, peak forces."""
    peaks = ", ".join(f"{p:.4f}" for p in trace.peak_force)
    return str(trace.statistics.steps), str(trace.statistics.events), peaks


def row(label: str, wall: float, cpu: float, trace: object) -> list[str]:
    return [label, f"{wall * 1e3:.1f}", f"{cpu * 1e3:.1f}", f"{wall / TARGET_S:.2f}", *deterministic(trace)]


def main() -> None:
    mechanism = assemble(load_preset("gnilka-1a"))
    with limited():
        wall, cpu, trace = best_times(ExactBackend(), mechanism, 9)
    rows = [row("1A, this version (1 BLAS thread), best of 9", wall, cpu, trace)]
    print(f"exact 1A, this version: {wall * 1e3:.1f} ms wall, {cpu * 1e3:.1f} ms CPU (best of 9); "
          f"{trace.statistics.steps} scan samples, {trace.statistics.events} events; "
          f"wall / target {TARGET_S * 1e3:.0f} ms = {wall / TARGET_S:.2f}")
    newmark = NewmarkBackend()
    newmark_wall, newmark_cpu, newmark_trace = best_times(newmark, mechanism, 9)
    rows.append(row("1A, newmark at 1 us in the same run, best of 9", newmark_wall, newmark_cpu, newmark_trace))
    print(f"newmark 1A in the same run: {newmark_wall * 1e3:.1f} ms wall; exact / newmark = "
          f"{wall / newmark_wall:.1f}")
    spec = load_preset("gnilka-1a")
    with limited():
        fresh_wall, fresh_cpu, fresh_trace = best_times(ExactBackend(), _Fresh(spec), 9)
    rows.append(row("1A, a fresh mechanism each run (assemble + build + run), best of 9", fresh_wall, fresh_cpu,
                    fresh_trace))
    print(f"exact 1A on a fresh mechanism each run: {fresh_wall * 1e3:.1f} ms wall "
          f"(ratio to the target {fresh_wall / TARGET_S:.2f})")
    if "--write" in sys.argv:
        replace_block(DOC, BLOCK, table(HEADER, rows))
        print(f"wrote the {BLOCK} block of {DOC.relative_to(ROOT)}")


if __name__ == "__main__":
    sys.exit(main())
