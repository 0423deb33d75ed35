"""Sweep benchmark: a 1,000-point RPM sweep of example 1A (850 deg, dt = 1 us) on all local cores.

Run: ``python3 benchmarks/bench_sweep.py [--points N] [--write-docs]``. Prints
figures, asserts nothing; every figure is measured in this one run.

1. Warm single run: ``simulate(spec)`` at 11,000 rev/min, best of 5 (the
   reference for the per-point cost).
2. Serial sweep of 20 points around 11,000 rev/min in this process: per-point
   cost inside a sweep, and its ratio to the warm single run.
3. The N-point sweep 2,000 ... 11,990 rev/min in 10 rev/min steps (N = 1,000)
   on a local process pool with every core: wall time (target: under 10 s),
   points per second, and the same 20-point sweep on the pool for the
   per-point cost with worker start-up included.
4. Dask: the 20-point sweep on a ``LocalCluster`` with as many worker
   processes as cores: start-up (cluster and client) and per-point overhead
   against the process pool.

``--write-docs`` puts the table into docs/sweep.md (block ``sweep-bench``).
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from vtool.markdown import replace_block, table
from vtool.presets import load_preset
from vtool.presets.paths import plan_sweep
from vtool.solvers.run import simulate
from vtool.solvers.studies.sweep import DaskRunner, ProcessRunner, SerialRunner, run_points

TARGET_S = 10.0
DOCS = Path(__file__).resolve().parent.parent / "docs" / "sweep.md"


def warm_single(repeat: int = 5) -> float:
    spec = load_preset("gnilka-1a")
    simulate(spec)
    best = float("inf")
    for _ in range(repeat):
        started = time.perf_counter()
        simulate(spec)
        best = min(best, time.perf_counter() - started)
    return best


def timed(points, runner) -> float:  # type: ignore[no-untyped-def]
    started = time.perf_counter()
    outcome = run_points(points, runner)
    elapsed = time.perf_counter() - started
    assert outcome.complete and all(r.ok for r in outcome.results)
    return elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1000)
    parser.add_argument("--write-docs", action="store_true")
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    near = plan_sweep("gnilka-1a", ["run.rpm=10900:11090:10"]).points
    big = plan_sweep("gnilka-1a", [f"run.rpm=2000:{2000 + 10 * (args.points - 1)}:10"]).points

    single = warm_single()
    serial = timed(near, SerialRunner()) / len(near)

    started = time.perf_counter()
    pool = ProcessRunner(cores)
    try:
        pool_near = timed(near, pool) / len(near)  # includes the workers' start-up
        pool_big = timed(big, pool)
    finally:
        pool.close()
    pool_total = time.perf_counter() - started

    started = time.perf_counter()
    dask = DaskRunner(f"local:{cores}")
    dask_start = time.perf_counter() - started
    try:
        dask_first = timed(near, dask) / len(near)
        dask_near = timed(near, dask) / len(near)
    finally:
        dask.close()
    warm_pool = ProcessRunner(cores)
    try:
        timed(near, warm_pool)
        pool_warm = timed(near, warm_pool) / len(near)
    finally:
        warm_pool.close()

    rows = [
        ["warm single simulate (1A, 11,000 rev/min)", f"{1000 * single:.1f} ms", "1.00"],
        ["sweep point, serial, same speeds", f"{1000 * serial:.1f} ms", f"{serial / single:.2f}"],
        [f"{len(big)}-point sweep 2,000-{2000 + 10 * (len(big) - 1):,} rev/min, {cores} processes",
         f"{pool_big:.1f} s", f"{pool_big / TARGET_S:.2f} of the 10 s target"],
        [f"  per point ({len(big) / pool_big:.1f} points/s)", f"{1000 * pool_big / len(big):.1f} ms", ""],
        ["process pool, 20 points, first use (worker start-up)", f"{1000 * pool_near:.1f} ms/point", ""],
        ["process pool, 20 points, warm workers", f"{1000 * pool_warm:.1f} ms/point",
         f"{pool_warm / single:.2f}"],
        [f"Dask LocalCluster start-up ({cores} processes)", f"{dask_start:.2f} s", ""],
        ["Dask, 20 points, first use", f"{1000 * dask_first:.1f} ms/point", ""],
        ["Dask, 20 points, warm workers", f"{1000 * dask_near:.1f} ms/point", f"{dask_near / single:.2f}"],
        ["Dask overhead per point vs warm process pool", f"{1000 * (dask_near - pool_warm):+.1f} ms", ""],
    ]
    text = table(["measure", "value", "ratio"], rows)
    print(text)
    print(f"(process pool total including start-up: {pool_total:.1f} s; {cores} cores)")
    if args.write_docs:
        replace_block(DOCS, "sweep-bench", text)
        print(f"updated {DOCS}")


if __name__ == "__main__":
    main()
