"""The compile notices' estimates against the compiles they announce, each with empty caches.

Run: ``python3 benchmarks/bench_compile_estimate.py [--rounds N]``. Prints figures,
asserts nothing. For each compile a user can meet (the command a user types, in a
fresh process, with a new numba cache folder):

1. ``vtool solve gnilka-1a`` in the default mode: the Newmark kernel compiled in a
   child while the run goes on in plain Python (time until it is in numba's cache);
2. the same with ``VTOOL_KERNEL=compiled``: the compile in the run's own process
   (the process' time less that of the same command once cached);
3. ``vtool solve gnilka-1a --backend exact``: the event rules of the piecewise back ends;
4. ``vtool solve gnilka-1a --every-step --csv`` on numba's cache: the CSV number formatter.

Each line gives the N of the notice's "about N s", the time taken and their ratio, and the
reference time (:mod:`vtool.compile_estimate`) that this run implies: the time taken divided
by this machine's probe ratio and load factor at the start of the command. The reference
constants in ``solvers/newmark/backend.py`` and ``vtool/csvrows.py`` are such figures.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from vtool import compile_estimate

CACHED = ("import sys; from vtool.solvers.newmark import kernel as k; "
          "sys.exit(0 if k.is_cached(('run_chunk',), None, None) else 1)")


def env_for(cache: str, mode: str | None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in ("VTOOL_KERNEL", "VTOOL_NATIVE")}
    env.update(NUMBA_CACHE_DIR=cache, VTOOL_NATIVE="0")
    if mode is not None:
        env["VTOOL_KERNEL"] = mode
    return env


def timed(args: list[str], env: dict[str, str]) -> tuple[float, str]:
    """(wall s, stderr) of ``python -m vtool ARGS``."""
    started = time.perf_counter()
    out = subprocess.run([sys.executable, "-m", "vtool", *args], env=env, capture_output=True, text=True,
                         check=True)
    return time.perf_counter() - started, out.stderr


def announced(stderr: str) -> float:
    found = re.search(r"compiling the [^(]*\(about (\d+) s", stderr)
    return float(found.group(1)) if found else float("nan")


def factor(processes: int) -> float:
    return compile_estimate.probe() / compile_estimate.PROBE_REFERENCE_S * compile_estimate.load_factor(processes)


def line(name: str, estimate: float, taken: float, processes: int, scale: float) -> None:
    print(f"  {name}: announced about {estimate:.0f} s, took {taken:.2f} s (estimate / actual "
          f"{estimate / taken:.2f}); reference implied {taken / scale:.2f} s (n = {processes}, "
          f"probe and load factor {scale:.2f})", flush=True)


def background(folder: Path) -> None:
    cache = str(folder / "bg")
    env = env_for(cache, None)
    scale = factor(3)
    started = time.perf_counter()
    _, stderr = timed(["solve", "gnilka-1a"], env)
    while True:
        if (any(Path(cache).rglob("newmark_kernel.run_chunk-*.nbi"))
                and subprocess.run([sys.executable, "-c", CACHED], env=env).returncode == 0):
            break
        if time.perf_counter() - started > 600.0:
            print("  background compile: not in the cache after 600 s")
            return
        time.sleep(0.1)
    line("Newmark kernel in the background (a first run)", announced(stderr), time.perf_counter() - started,
         3, scale)


def first_and_again(name: str, folder: Path, args: list[str], processes: int, key: str,
                    prepare: list[str] | None = None) -> None:
    cache = str(folder / key)
    env = env_for(cache, "compiled")
    if prepare is not None:
        timed(prepare, env)
    scale = factor(processes)
    first, stderr = timed(args, env)
    again, _ = timed(args, env)
    line(name, announced(stderr), first - again, processes, scale)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=2)
    rounds = parser.parse_args().rounds
    print(f"compile notices against compiles, this machine: probe {compile_estimate.probe() * 1e3:.2f} ms "
          f"(reference {compile_estimate.PROBE_REFERENCE_S * 1e3:.2f} ms), {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.2f}")
    for number in range(rounds):
        print(f"round {number + 1}")
        with tempfile.TemporaryDirectory() as name:
            folder = Path(name)
            background(folder)
            first_and_again("Newmark kernel in the run's process (VTOOL_KERNEL=compiled)", folder,
                            ["solve", "gnilka-1a"], 2, "kernel")
            first_and_again("event rules (--backend exact)", folder, ["solve", "gnilka-1a", "--backend", "exact"],
                            1, "rules")
            csv = str(folder / "out.csv")
            first_and_again("CSV formatter (--every-step --csv)", folder,
                            ["solve", "gnilka-1a", "--every-step", "--csv", csv], 1, "kernel",
                            prepare=["solve", "gnilka-1a"])


if __name__ == "__main__":
    main()
