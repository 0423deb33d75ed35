"""The Newmark kernel's cost per step on example 1A: this checkout against an earlier commit, alternating.

Run: ``python3 benchmarks/bench_step_ab.py REF [--pairs N] [--whole]`` (N = 5 pairs by default; the first
pair also compiles both kernels into their own temporary numba caches; an old REF runs with
``VTOOL_KERNEL=compiled VTOOL_NATIVE=0``, numba's kernel in the process, as this checkout's). Each
process times the kernel's calls (``bench_newmark.kernel_seconds``: the time inside ``run_chunk``
over the steps, the best of 4 rounds of 5 runs) in a warm run of ``gnilka-1a``; the two versions
alternate, so that a machine whose speed drifts slows both alike, and the ratio of the best of
each is the figure to quote. The earlier commit is laid out as ``bench_compile_ab.py`` does.
``--whole`` times the whole warm run instead, ``simulate(spec)`` as ``bench_newmark.py``'s first
figure does (assembly, contact problem, kernel, trace; the best of 4 rounds of 5 runs).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

from bench_compile_ab import ROOT, arguments, environment, layout

TIMING = """
import sys
sys.path.insert(0, {benchmarks!r})
from bench_newmark import kernel_seconds
import vtool.solvers.newmark.kernel as kernel
assert kernel.__file__.startswith({prefix!r}), kernel.__file__
from vtool.presets import load_preset
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.newmark.backend import NewmarkBackend
spec = load_preset("gnilka-1a")
mechanism = assemble(spec)
backend = NewmarkBackend()
options = backend.options_from_run(spec.run)
steps = backend.simulate(mechanism, options).statistics.steps
print(min(min(kernel_seconds(backend, mechanism, options) for _ in range(5)) for _ in range(4)) / steps)
"""

WHOLE = """
import sys, time
sys.path.insert(0, {benchmarks!r})
import vtool.solvers.newmark.kernel as kernel
assert kernel.__file__.startswith({prefix!r}), kernel.__file__
from vtool.presets import load_preset
from vtool.solvers.run import simulate
spec = load_preset("gnilka-1a")
simulate(spec)
best = float("inf")
for _ in range(20):
    started = time.perf_counter()
    simulate(spec)
    best = min(best, time.perf_counter() - started)
print(best)
"""


def per_step(path_entry: Path | None, prefix: str, cache: str, whole: bool = False) -> float:
    env = environment(path_entry, cache)
    out = subprocess.run([sys.executable, "-c", (WHOLE if whole else TIMING).format(benchmarks=str(ROOT / "benchmarks"), prefix=prefix)],
                         capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
    if out.returncode != 0:
        raise SystemExit(f"timing run failed:\n{out.stderr[-2000:]}")
    return float(out.stdout.split()[-1])


def main(argv: list[str]) -> None:
    whole = "--whole" in argv
    ref, pairs = arguments([a for a in argv if a != "--whole"], 5)
    scale, unit = (1e3, "ms/run") if whole else (1e9, "ns/step")
    old, new = [], []
    with tempfile.TemporaryDirectory() as folder, tempfile.TemporaryDirectory() as cache_old, \
            tempfile.TemporaryDirectory() as cache_new:
        entry = layout(ref, Path(folder))
        for _ in range(pairs):
            old.append(per_step(entry, str(entry), cache_old, whole))
            new.append(per_step(None, str(ROOT), cache_new, whole))
            print(f"  {ref}: {old[-1] * scale:.2f} {unit}   this checkout: {new[-1] * scale:.2f} {unit}", flush=True)
    a, b = min(old), min(new)
    what = "the whole warm run (simulate)" if whole else "the kernel per step"
    print(f"{what} on gnilka-1a, best of {pairs} alternating processes: {ref} {a * scale:.2f} {unit}, "
          f"this checkout {b * scale:.2f} {unit}; ratio {b / a:.3f}")


if __name__ == "__main__":
    main(sys.argv[1:])
