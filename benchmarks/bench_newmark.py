"""Newmark back end benchmark: example 1A (850 degrees, dt = 1e-6 s), ratios measured in one run.

Run: ``python3 benchmarks/bench_newmark.py`` (``--no-compile`` skips the empty-cache compile,
and the first-run measure, about 30 s together; ``--ratio`` measures item 2 alone and prints
every round). Prints figures, asserts nothing.

1. Warm wall time of a whole run (``simulate``: assemble + contact problem + kernel), best of
   several, and its ratio to the 5 ms target; the kernel alone per step. For 1A also over the
   rounds of item 2, each round's best of several: the best round, the median one, and the one
   whose dense loop ran slowest (this machine's speed drifts by up to half within a minute).
2. A dense 8-coordinate Newmark step loop in numba (no clearances, no events: the machine's
   floor for this problem size), measured in the same run, alternating with the kernel; the
   kernel's per-step cost (the time inside its calls over the steps) as a ratio to it (target: at
   most 2; the best of each, and the median of the rounds' ratios), and the whole run's.
3. First compile with an empty numba cache (a fresh process, a temporary cache folder,
   ``VTOOL_KERNEL=compiled``): wall and CPU time, the helper process's included (the compile runs on
   two processes, see ``kernel_build.compile_kernel``; target: under 10 s). Then the first run as a
   new user meets it (the default mode, no ``VTOOL_KERNEL``): ``vtool solve gnilka-1a`` with an
   empty cache, its wall time and steps run as plain Python, and when the background compile it
   started reached the cache (see newmark's "First run").
4. A second process: ``vtool solve gnilka-1a`` in a fresh interpreter, the default mode, after
   the first run's background build has put the kernel's native module beside numba's cache
   (target: at most 0.5 s; best of five, Python's bytecode cache on as by default, and again
   with ``PYTHONDONTWRITEBYTECODE=1``), whether it imported numba, the same with ``--csv``, and
   both on numba's cache instead (``VTOOL_NATIVE=0``) for comparison, measured in the same run.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from numba import njit

from vtool.presets import load_preset
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.newmark.backend import NewmarkBackend
from vtool.solvers.run import simulate

os.environ.setdefault("VTOOL_KERNEL", "compiled")  # timed runs compile first (newmark: "First run")

TARGET_WARM_S = 0.005
TARGET_COMPILE_S = 10.0
TARGET_SECOND_PROCESS_S = 0.5
ROUNDS = 7  # kernel and dense-loop timings, alternated
REPEAT = 11  # runs per timing, the best taken


@njit(cache=True, nogil=True)
def dense_newmark(M, C, K, Sinv, h, beta, gamma, steps, x, v, a):  # noqa: N803 (the math's names)
    """The floor: Newmark steps of a dense n-coordinate system with a stored effective inverse."""
    n = x.shape[0]
    xp = np.zeros(n)
    vp = np.zeros(n)
    rhs = np.zeros(n)
    for _ in range(steps):
        for i in range(n):
            xp[i] = x[i] + h * v[i] + h * h * (0.5 - beta) * a[i]
            vp[i] = v[i] + h * (1.0 - gamma) * a[i]
        for i in range(n):
            s = 0.0
            for j in range(n):
                s -= C[i, j] * vp[j] + K[i, j] * xp[j]
            rhs[i] = s
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += Sinv[i, j] * rhs[j]
            a[i] = s
            x[i] = xp[i] + beta * h * h * s
            v[i] = vp[i] + gamma * h * s
    return x[0]


def kernel_seconds(backend, mechanism, options) -> float:  # noqa: ANN001
    """Seconds spent inside the kernel's calls (run_chunk) during one run, Python around it left out."""
    from vtool.solvers.newmark import kernel as newmark_kernel

    inner = newmark_kernel.run_chunk
    spent = [0.0]

    def timed(*args):  # noqa: ANN002, ANN202
        started = time.perf_counter()
        try:
            return inner(*args)
        finally:
            spent[0] += time.perf_counter() - started

    newmark_kernel.run_chunk = timed
    try:
        backend.simulate(mechanism, options)
    finally:
        newmark_kernel.run_chunk = inner
    return spent[0]


def best_of(function, repeat: int = REPEAT) -> float:  # noqa: ANN001
    function()
    best = float("inf")
    for _ in range(repeat):
        started = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - started)
    return best


def dense_floor(steps: int) -> float:
    """Seconds per step of the dense loop on the rocker-open layer of 1A (8 coordinates)."""
    mechanism = assemble(load_preset("gnilka-1a"))
    layer = mechanism.layer(frozenset())
    M, C, K = layer.M, layer.C, layer.K
    h, beta, gamma = 1e-6, 1 / 6, 0.5
    Sinv = np.linalg.inv(M + gamma * h * C + beta * h * h * K)
    n = M.shape[0]

    def run() -> None:
        dense_newmark(M, C, K, Sinv, h, beta, gamma, steps, np.full(n, 1e-3), np.zeros(n), np.zeros(n))

    return best_of(run) / steps


COMPILE = """
import resource, time
started = time.perf_counter()
from vtool.presets import load_preset
from vtool.solvers.run import simulate
trace = simulate(load_preset("gnilka-1a"))
cpu = sum(u.ru_utime + u.ru_stime for u in (resource.getrusage(resource.RUSAGE_SELF),
                                              resource.getrusage(resource.RUSAGE_CHILDREN)))
print(trace.statistics.compile_time, cpu, time.perf_counter() - started)
"""

SECOND_PROCESS = """
import contextlib, io, sys, time
started = time.perf_counter()
from vtool.app.cli import main as entry
sys.argv = ["vtool", "solve", "gnilka-1a", *sys.argv[1:]]
output = io.StringIO()
try:
    with contextlib.redirect_stdout(output):
        entry.main()  # the installed entry point: the collector settings included
except SystemExit as exc:
    assert exc.code in (0, None), output.getvalue()
elapsed = time.perf_counter() - started
native = "numba" not in sys.modules
misses = hits = 0
if not native:  # (importing the kernel only to ask would import numba into a native run's process time)
    from vtool.solvers.newmark import kernel as newmark_kernel
    stats = newmark_kernel.run_chunk.stats
    misses, hits = sum(stats.cache_misses.values()), sum(stats.cache_hits.values())
print(elapsed, misses, hits, int(native))
"""

#: Import-time groups of the second process, by top-level package (``python -X importtime``).
GROUPS = {"numba": ("numba", "llvmlite"), "scipy": ("scipy",), "numpy": ("numpy",),
          "cffi (numba loads it)": ("cffi", "pycparser"), "vtool": ("vtool", "__editable___vtool_0_1_0_finder"),
          "click": ("click",)}


def import_breakdown() -> tuple[float, dict[str, float]]:
    """(process wall s, import seconds per group) of ``vtool solve gnilka-1a`` under ``-X importtime``.

    Imports made while numba loads the cached kernel (its typing registries, scipy.linalg for its
    BLAS check, cffi) are counted too: they happen at the first call, not at ``import numba``.
    """
    started = time.perf_counter()
    out = subprocess.run([sys.executable, "-X", "importtime", "-m", "vtool.app.cli.main", "solve", "gnilka-1a"],
                         capture_output=True, text=True, check=True, env=user_env())
    wall = time.perf_counter() - started
    seconds: dict[str, float] = dict.fromkeys([*GROUPS, "other"], 0.0)
    for line in out.stderr.splitlines():
        if not line.startswith("import time:") or line.count("|") != 2:
            continue
        self_us, _, name = _fields(line)
        top = name.split(".")[0]
        group = next((g for g, tops in GROUPS.items() if top in tops), "other")
        seconds[group] += self_us / 1e6
    return wall, seconds


def _fields(line: str) -> tuple[float, str, str]:
    """(self µs, cumulative µs, module) of one ``-X importtime`` line."""
    self_us, cumulative, name = line.removeprefix("import time:").split("|")
    if not self_us.strip().isdigit():
        return 0.0, "0", ""
    return float(self_us), cumulative.strip(), name.strip()


def first_compile() -> tuple[float, float, float]:
    """(kernel compile wall s, process CPU s, process wall s) with an empty numba cache."""
    with tempfile.TemporaryDirectory() as cache:
        out = subprocess.run([sys.executable, "-c", COMPILE], capture_output=True, text=True, check=True,
                             env=dict(os.environ, NUMBA_CACHE_DIR=cache))
    compile_s, cpu, wall = (float(v) for v in out.stdout.split())
    return compile_s, cpu, wall


CACHED = ("import sys; from vtool.solvers.newmark import kernel as k; "
          "sys.exit(0 if k.is_cached(('run_chunk',), None, None) else 1)")


NATIVE = ("import sys; from vtool.solvers.newmark import native as k; "
          "sys.exit(0 if k.exists((None, None)) else 1)")


def wait_for(probe: str, env: dict[str, str], started: float) -> float:
    """Seconds from ``started`` until ``python -c probe`` exits 0 (nan after 600 s)."""
    while subprocess.run([sys.executable, "-c", probe], env=env).returncode != 0:
        if time.perf_counter() - started > 600.0:
            return float("nan")
        time.sleep(0.5)
    return time.perf_counter() - started


def first_run_default() -> tuple[float, int, int, float, float]:
    """(process wall s, plain-Python steps, steps, s from the start until the background compile is in
    numba's cache, s until its native module is there) of ``vtool solve gnilka-1a --json`` with an empty
    numba cache, in the default mode."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        env.pop("VTOOL_KERNEL", None)
        started = time.perf_counter()
        out = subprocess.run([sys.executable, "-m", "vtool", "solve", "gnilka-1a", "--json"], capture_output=True,
                             text=True, check=True, env=env)
        wall = time.perf_counter() - started
        summary = json.loads(out.stdout)
        ready = wait_for(CACHED, env, started)
        native = wait_for(NATIVE, env, started)
    return wall, summary["plain_steps"], summary["steps"], ready, native


def user_env(native: bool = True) -> dict[str, str]:
    """The environment of a user's ``vtool solve``: the default mode (no ``VTOOL_KERNEL``); ``native``
    False sets ``VTOOL_NATIVE=0`` (numba's cache)."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONDONTWRITEBYTECODE", "VTOOL_KERNEL", "VTOOL_NATIVE")}
    if not native:
        env["VTOOL_NATIVE"] = "0"
    return env


def ensure_native() -> float:
    """Run ``vtool solve gnilka-1a`` as a user would until its native module is built (the first run
    that finds only numba's cache starts the build); seconds waited."""
    started = time.perf_counter()
    subprocess.run([sys.executable, "-m", "vtool", "solve", "gnilka-1a"], env=user_env(), capture_output=True,
                   check=True)
    return wait_for(NATIVE, user_env(), started)


def second_process(bytecode: bool = True, native: bool = True, csv: str | None = None,
                   ) -> tuple[float, float, int, int, bool]:
    """(process wall time, in-process solve time, numba cache misses, cache hits, whether numba stayed
    out) of ``vtool solve gnilka-1a`` as a user runs it (:func:`user_env`).

    ``bytecode``: Python's default, modules load from their ``__pycache__`` bytecode (written by
    the warm-up call before the measured one). False sets ``PYTHONDONTWRITEBYTECODE=1``, as some
    sandboxes and CI images do, so every process compiles vtool's sources again (about 50 ms).
    """
    env = user_env(native)
    if not bytecode:
        env["PYTHONDONTWRITEBYTECODE"] = "1"
    started = time.perf_counter()
    extra = ["--csv", csv] if csv else []
    out = subprocess.run([sys.executable, "-c", SECOND_PROCESS, *extra], capture_output=True, text=True, check=True,
                         env=env)
    total = time.perf_counter() - started
    solve_time, misses, hits, native_used = out.stdout.split()
    return total, float(solve_time), int(misses), int(hits), native_used == "1"


def kernel_rounds(backend, mechanism, options, steps: int,  # noqa: ANN001
                  spec=None) -> list[tuple[float, float, float]]:  # noqa: ANN001
    """(kernel, dense loop) seconds per step in each of ROUNDS interleaved rounds, and with ``spec``
    the whole warm run's seconds (``simulate(spec)``) in the same round (else NaN): a machine whose
    speed drifts slows them alike. Each is the best of REPEAT runs (:func:`best_of`'s count), so
    that the figures are the same estimator."""
    rounds = []
    for _ in range(ROUNDS):
        whole = best_of(lambda: simulate(spec)) if spec is not None else float("nan")
        kernel = min(kernel_seconds(backend, mechanism, options) for _ in range(REPEAT)) / steps
        rounds.append((kernel, dense_floor(steps), whole))
    return rounds


def whole_line(rounds: list[tuple[float, float, float]]) -> str:
    """The whole warm run over the rounds: the best, the median, and in the round whose dense loop was
    slowest (the machine at its slowest in this run)."""
    wholes = sorted(w for _, _, w in rounds)
    _, slow_floor, slow_whole = max(rounds, key=lambda r: r[1])
    return (f"simulate over the {ROUNDS} rounds: best {wholes[0] * 1e3:.2f} ms (ratio to the 5 ms target "
            f"{wholes[0] / TARGET_WARM_S:.2f}), median {wholes[ROUNDS // 2] * 1e3:.2f} ms "
            f"({wholes[ROUNDS // 2] / TARGET_WARM_S:.2f}); in the round with the slowest dense loop "
            f"({slow_floor * 1e9:.0f} ns/step) {slow_whole * 1e3:.2f} ms ({slow_whole / TARGET_WARM_S:.2f})")


def ratio_line(rounds: list[tuple[float, float, float]]) -> str:
    per_step = min(k for k, _, _ in rounds)
    floor = min(f for _, f, _ in rounds)
    ratios = sorted(k / f for k, f, _ in rounds)
    return (f"dense 8-coordinate Newmark loop: {floor * 1e9:5.0f} ns/step; the kernel (its calls alone) "
            f"{per_step * 1e9:5.0f} ns/step, {per_step / floor:.2f} x the floor (target <= 2; the best of each "
            f"over {ROUNDS} interleaved rounds; the rounds' median ratio {ratios[ROUNDS // 2]:.2f})")


def ratio_only() -> None:
    """Item 2 alone, every round printed."""
    spec = load_preset("gnilka-1a")
    mechanism = assemble(spec)
    backend = NewmarkBackend()
    options = backend.options_from_run(spec.run)
    steps = backend.simulate(mechanism, options).statistics.steps
    rounds = kernel_rounds(backend, mechanism, options, steps)
    for number, (kernel, floor, _) in enumerate(rounds, 1):
        print(f"  round {number}: kernel {kernel * 1e9:5.1f} ns/step, dense loop {floor * 1e9:5.1f} ns/step, "
              f"ratio {kernel / floor:.2f}")
    print("  " + ratio_line(rounds))


def main() -> None:
    if "--ratio" in sys.argv[1:]:
        ratio_only()
        return
    print("Newmark back end, ratios measured in this run")
    for name in ("gnilka-1a", "gnilka-1d", "gnilka-2"):
        spec = load_preset(name)
        whole = best_of(lambda spec=spec: simulate(spec))
        mechanism = assemble(spec)
        backend = NewmarkBackend()
        options = backend.options_from_run(spec.run)
        trace = backend.simulate(mechanism, options)
        reused = best_of(lambda b=backend, m=mechanism, o=options: b.simulate(m, o))
        steps = trace.statistics.steps
        print(f"  {name}: simulate {whole * 1e3:7.2f} ms (ratio to the 5 ms target {whole / TARGET_WARM_S:.2f}); "
              f"on an assembled mechanism {reused * 1e3:6.2f} ms; {steps} steps, {len(trace.events)} events, "
              f"{reused / steps * 1e9:5.0f} ns/step")
        if name == "gnilka-1a":
            rounds = kernel_rounds(backend, mechanism, options, steps, spec)
            floor = min(f for _, f, _ in rounds)
            print(f"  {ratio_line(rounds)}; the whole 1A run per step {reused / steps / floor:.2f} x")
            print(f"  {name}: {whole_line(rounds)}")
    if "--no-compile" not in sys.argv[1:]:
        compile_s, cpu, wall = first_compile()
        print(f"  first run with an empty numba cache: kernel compile {compile_s:.1f} s wall "
              f"(ratio to the 10 s target {compile_s / TARGET_COMPILE_S:.2f}); whole process {wall:.1f} s wall, "
              f"{cpu:.1f} s CPU")
        wall, plain, steps, ready, native = first_run_default()
        print(f"  first `vtool solve gnilka-1a` as a new user meets it (empty cache, default mode): {wall:.1f} s wall "
              f"(ratio to the 10 s target {wall / TARGET_COMPILE_S:.2f}), {plain} of {steps} steps as plain Python; "
              f"the compile it started in the background was in numba's cache {ready:.1f} s after its start, "
              f"the native module {native:.1f} s after it")
    waited = ensure_native()
    second_process()  # make sure the bytecode exists
    samples = sorted(second_process() for _ in range(5))
    total, solve_time, misses, hits, native_used = samples[0]
    median = samples[2][0]
    print(f"  second process: `vtool solve gnilka-1a` {total:.2f} s with interpreter start-up "
          f"(ratio to the 0.5 s target {total / TARGET_SECOND_PROCESS_S:.2f}; best of 5, median {median:.2f} s), "
          f"{solve_time:.3f} s in-process; "
          + ("on the native module, numba not imported" if native_used else
             f"numba imported (no native module {waited:.0f} s after a run); numba cache: {hits} hit(s), "
             f"{misses} miss(es) (a miss means it recompiled)"))
    plain_bytes = sorted(second_process(bytecode=False)[0] for _ in range(5))
    print(f"  the same with PYTHONDONTWRITEBYTECODE=1 (sources compiled in every process): best {plain_bytes[0]:.2f} s "
          f"(ratio {plain_bytes[0] / TARGET_SECOND_PROCESS_S:.2f}), median {plain_bytes[2]:.2f} s")
    jit = sorted(second_process(native=False) for _ in range(5))
    print(f"  the same on numba's cache (VTOOL_NATIVE=0): best {jit[0][0]:.2f} s (ratio {jit[0][0] / total:.2f} "
          f"x the native module's), median {jit[2][0]:.2f} s; numba cache: {jit[0][3]} hit(s), {jit[0][2]} miss(es)")
    with tempfile.TemporaryDirectory() as folder:
        csv = os.path.join(folder, "gnilka-1a.csv")
        with_csv = sorted(second_process(csv=csv) for _ in range(5))
        jit_csv = sorted(second_process(native=False, csv=csv) for _ in range(5))
    print(f"  with --csv (per-degree rows, the preset's quantities): best {with_csv[0][0]:.2f} s "
          f"({'numba not imported' if with_csv[0][4] else 'numba imported'}; ratio to the 0.5 s target "
          f"{with_csv[0][0] / TARGET_SECOND_PROCESS_S:.2f}); on numba's cache (VTOOL_NATIVE=0) {jit_csv[0][0]:.2f} s")
    wall, seconds = import_breakdown()
    parts = ", ".join(f"{group} {value:.2f} s" for group, value in seconds.items())
    print(f"  its imports (python -X importtime, {wall:.2f} s wall with the tracing): {sum(seconds.values()):.2f} s: "
          f"{parts}")


if __name__ == "__main__":
    main()
