"""BLAS threads: the plate study on one thread (vtool's default) against the libraries' own threads.

Run: ``python3 benchmarks/bench_threads.py [--rounds N] [--write]`` (N = 3; 5-15 s a round on a
2-core machine). Prints figures, asserts nothing; ``--write`` also writes them into the ``threads``
block of docs/plate.md.

Each round runs ``vtool plate study plate-table3`` alone, then with ``plate-table2`` beside it (two
processes at once, as on a loaded machine or two test workers), once with vtool's default
(``vtool.threads.limited``: one BLAS thread) and once with ``VTOOL_THREADS=0`` (the libraries' own
setting), in alternating order, and prints each's wall time and its processes' CPU time. The figures
to quote are the best of each over the rounds and their ratios.
"""

from __future__ import annotations

import os
import platform
import resource
import subprocess
import sys
import time
from pathlib import Path

from vtool.markdown import replace_block, table

DOC = Path(__file__).resolve().parent.parent / "docs" / "plate.md"

STUDIES = ("plate-table3", "plate-table2")


def children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def studies(names: tuple[str, ...], threads: str | None) -> tuple[float, float]:
    """(wall, CPU) seconds of ``vtool plate study NAME`` for every name at once."""
    env = dict(os.environ)
    env.pop("VTOOL_THREADS", None)
    if threads is not None:
        env["VTOOL_THREADS"] = threads
    cpu, started = children_cpu(), time.perf_counter()
    processes = [subprocess.Popen([sys.executable, "-m", "vtool", "plate", "study", name], env=env,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE) for name in names]
    for process in processes:
        _, err = process.communicate()
        if process.returncode != 0:
            raise SystemExit(f"vtool plate study failed: {err.decode()[-500:]}")
    return time.perf_counter() - started, children_cpu() - cpu


def main(argv: list[str]) -> None:
    rounds = int(argv[argv.index("--rounds") + 1]) if "--rounds" in argv else 3
    settings = {"one BLAS thread (default)": None, "the libraries' threads (VTOOL_THREADS=0)": "0"}
    best: dict[tuple[str, int], tuple[float, float]] = {}
    print("vtool plate study, wall and CPU seconds (all its processes)")
    for r in range(rounds):
        order = list(settings.items()) if r % 2 == 0 else list(settings.items())[::-1]
        for label, threads in order:
            for count in (1, 2):
                wall, cpu = studies(STUDIES[:count], threads)
                key = (label, count)
                best[key] = min(best.get(key, (wall, cpu)), (wall, cpu))
                print(f"  {label}, {' and '.join(STUDIES[:count])}: {wall:.2f} s wall, {cpu:.2f} s CPU", flush=True)
    one, lib = settings
    rows = []
    for count in (1, 2):
        (w1, c1), (w0, c0) = best[(one, count)], best[(lib, count)]
        case = f"{' and '.join(STUDIES[:count])} {'at once' if count == 2 else 'alone'}"
        print(f"{case}, best of {rounds}: one thread "
              f"{w1:.2f} s wall ({c1:.2f} s CPU), the libraries' threads {w0:.2f} s ({c0:.2f} s CPU); "
              f"ratio {w1 / w0:.2f} wall, {c1 / c0:.2f} CPU")
        rows.append([f"`vtool plate study`: {case}", f"{w1:.2f}", f"{c1:.2f}", f"{w0:.2f}", f"{c0:.2f}",
                     f"{w1 / w0:.2f}", f"{c1 / c0:.2f}"])
    if "--write" in argv:
        header = [f"case (best of {rounds}, {os.cpu_count() or 1} cores, {platform.machine()})",
                  "one thread: wall (s)", "CPU (s)", "the libraries' threads: wall (s)", "CPU (s)",
                  "ratio, wall", "ratio, CPU"]
        replace_block(DOC, "threads", table(header, rows))
        print(f"wrote the threads block of {DOC.name}")


if __name__ == "__main__":
    main(sys.argv[1:])
