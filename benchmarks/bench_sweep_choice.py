"""Does a parallel sweep pay? Serial against every parallel mode at 100 and 1,000 points, in one run.

Run: ``python3 benchmarks/bench_sweep_choice.py [--points 100,1000] [--degrees 360]``. Prints the
figures, asserts nothing; every ratio is taken between runs of this one process (these machines are
shared and loaded: the one-minute load average is printed beside them).

For each point count N (an RPM sweep of example 1A from 9,000 rev/min in 1 rev/min steps, each point
``--degrees`` of cam rotation), wall time from the runner's creation to the last result, start-up
included:

* ``serial``: every point in this process (``--workers 1``);
* ``pool``: a forkserver pool of one worker per core (``--workers N``), its start included;
* ``dask``: ``--scheduler local:N``, the LocalCluster's start included;
* ``auto``: the default (:class:`vtool.solvers.studies.sweep.AutoRunner`): two points measured here,
  then the rest here or on a pool as :func:`~vtool.solvers.studies.sweep.choose_workers` decides; its
  choice is printed.

The ratio column is serial time / mode time (above 1: the mode is faster). The pool's start-up alone
(forkserver, workers, each worker's first kernel load) is measured too: it is the figure
``POOL_START_SECONDS`` stands for.
"""

from __future__ import annotations

import argparse
import os
import time

from vtool.presets.paths import plan_sweep
from vtool.solvers.studies.sweep import (
    POOL_START_SECONDS,
    DaskRunner,
    ProcessRunner,
    SerialRunner,
    make_runner,
    run_points,
)


def timed(make, points) -> tuple[float, str]:  # type: ignore[no-untyped-def]
    """Seconds from creating the runner to the last result, and the runner's announced choice."""
    said: list[str] = []
    started = time.perf_counter()
    runner = make(said.append)
    try:
        outcome = run_points(points, runner)
    finally:
        runner.close()
    elapsed = time.perf_counter() - started
    assert outcome.complete and len(outcome.results) == len(points)
    return elapsed, "; ".join(said)


def pool_start(cores: int, points) -> float:  # type: ignore[no-untyped-def]
    """A pool's start and one point on each worker (each loads the kernel once)."""
    started = time.perf_counter()
    pool = ProcessRunner(cores)
    try:
        run_points(points[:cores], pool)
    finally:
        pool.close()
    return time.perf_counter() - started


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", default="100,1000", help="comma-separated point counts")
    parser.add_argument("--degrees", type=float, default=360.0, help="cam degrees per point")
    args = parser.parse_args()
    cores = os.cpu_count() or 1
    counts = [int(c) for c in args.points.split(",")]
    plan = plan_sweep("gnilka-1a", [f"run.rpm=9000:{9000 + max(counts) - 1}:1", f"run.degrees={args.degrees:g}"])
    run_points(plan.points[:2], SerialRunner())  # the kernel loaded in this process first
    start = pool_start(cores, plan.points)
    print(f"{cores} cores, load average {os.getloadavg()[0]:.1f}; pool start-up with one point per worker "
          f"{start:.2f} s (POOL_START_SECONDS = {POOL_START_SECONDS:g})")
    modes = {
        "serial": lambda say: SerialRunner(),
        "pool": lambda say: ProcessRunner(cores),
        "dask": lambda say: DaskRunner(f"local:{cores}"),
        "auto": lambda say: make_runner(announce=say),
    }
    print(f"{'points':>6}  {'mode':<7} {'wall s':>8} {'serial/mode':>11}  load  choice")
    for count in counts:
        points = plan.points[:count]
        serial = None
        for name, make in modes.items():
            seconds, said = timed(make, points)
            serial = seconds if name == "serial" else serial
            assert serial is not None
            print(f"{count:>6}  {name:<7} {seconds:>8.2f} {serial / seconds:>11.2f}  {os.getloadavg()[0]:4.1f}  "
                  f"{said}")


if __name__ == "__main__":
    main()
