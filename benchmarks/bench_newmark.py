"""Newmark back end benchmark on example 1A (850 degrees, dt = 1e-6 s): ratios measured in one run.

Run: ``python3 benchmarks/bench_newmark.py`` (``--ratio``: item 2 alone, every round printed;
``--no-compile``: without item 3). Prints figures, asserts nothing.

1. Warm wall time of a whole run (``simulate``: assemble + contact problem + kernel) of three
   presets, best of several.
2. The kernel per step against a floor: a compiled loop doing the least work a quiet step of
   the kernel does, on 1A's most visited configuration with the kernel's own tables (the fused
   step operator, one product for the free accelerations and the contact forces; the cam's
   angle by rotation and its harmonics; predictor and corrector; three gap checks). The kernel
   (the time inside its calls over the steps) and the floor alternate in ROUNDS rounds, each the
   best of REPEAT runs; the ratio is taken round by round, and its median and range printed
   (target: at most 1.5).
3. First compile with an empty cache: ``vtool solve gnilka-1a --json`` in a fresh process with a
   temporary ``NUMBA_CACHE_DIR``, COMPILES times: the kernel's compile as the run reports it (median
   and range; target: at most 15 s on the 2-core machine), the process' wall and CPU time.
4. A second process: ``vtool solve gnilka-1a`` in a fresh interpreter against
   ``python3 -c "import numpy, numba"``, alternating, ROUNDS each, both with their bytecode as a
   user's install has it (``PYTHONDONTWRITEBYTECODE`` dropped); the ratio of each pair, its median and
   range (target: at most 2.5).
"""

from __future__ import annotations

import json
import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from numba import njit

from vtool.presets import load_preset
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.backend import NewmarkBackend
from vtool.solvers.run import simulate

ROUNDS = 7  # kernel and floor timings, alternated
REPEAT = 11  # runs per timing, the best taken
COMPILES = 3  # first compiles, each in an empty cache
TARGET_STEP_RATIO = 1.5
TARGET_COMPILE_S = 15.0
TARGET_SECOND_PROCESS_RATIO = 2.5


@njit(cache=True, nogil=True, error_model="numpy")
def floor_loop(G, nf, nrows, m, source_of, sc, sa, sb, omega, h, beta, gamma, gaps, steps, z, zd, zdd):  # noqa: N803
    """``steps`` quiet steps of a layer with stored step operator G (transposed, parts C, K, P: see
    ``layout.CP_RAW``): the cam's harmonics by rotation, predictor, one product, corrector, and the
    gaps ``gaps[i] = (ahead, behind)`` checked. Returns the number of gap checks that failed (0)."""
    ns, nh = sc.shape[0], sa.shape[1]
    src = np.zeros(3 * ns)
    out = np.zeros(G.shape[2])
    rows = min((nrows + 3) // 4 * 4, G.shape[2])
    c0, s0 = 1.0, 0.0
    c_dt, s_dt = math.cos(omega * h), math.sin(omega * h)
    failed = 0
    for _ in range(steps):
        c1 = c0 * c_dt - s0 * s_dt
        s1 = s0 * c_dt + c0 * s_dt
        for s in range(ns):
            src[3 * s] = sc[s]
            src[3 * s + 1] = 0.0
            src[3 * s + 2] = 0.0
        ck, sk = 1.0, 0.0
        for k in range(nh):
            ck, sk = ck * c1 - sk * s1, sk * c1 + ck * s1
            wk = (k + 1) * omega
            for s in range(ns):
                src[3 * s] += sa[s, k] * ck + sb[s, k] * sk
                src[3 * s + 1] += wk * (sb[s, k] * ck - sa[s, k] * sk)
                src[3 * s + 2] -= wk * wk * (sa[s, k] * ck + sb[s, k] * sk)
        hx, hv = h * h * (0.5 - beta), h * (1.0 - gamma)
        for j in range(m):
            z[j] = z[j] + h * zd[j] + hx * zdd[j]
            zd[j] = zd[j] + hv * zdd[j]
        for j in range(nf, m):
            s = source_of[j]
            z[j], zd[j], zdd[j] = src[3 * s], src[3 * s + 1], src[3 * s + 2]
        for f in range(rows):
            out[f] = 0.0
        for g in range(nf):
            a, b = zd[g], z[g]
            for f in range(rows):
                out[f] -= G[0, g, f] * a + G[1, g, f] * b
        for p in range(m - nf):
            a, b, d = zdd[nf + p], zd[nf + p], z[nf + p]
            for f in range(rows):
                out[f] -= G[2, 3 * p, f] * a + G[2, 3 * p + 1, f] * b + G[2, 3 * p + 2, f] * d
        for f in range(nf):
            zdd[f] = out[f]
            z[f] += beta * h * h * out[f]
            zd[f] += gamma * h * out[f]
        for i in range(gaps.shape[0]):
            if z[gaps[i, 0]] - z[gaps[i, 1]] < -1e300:
                failed += 1
        c0, s0 = c1, s1
    return failed


def kernel_seconds(backend, mechanism, options) -> float:  # noqa: ANN001
    """Seconds spent inside the kernel's calls (run_chunk) during one run, Python around it left out."""
    from vtool.solvers.newmark import kernel

    inner = kernel.run_chunk
    spent = [0.0]

    def timed(*args):  # noqa: ANN002, ANN202
        started = time.perf_counter()
        try:
            return inner(*args)
        finally:
            spent[0] += time.perf_counter() - started

    kernel.run_chunk = timed
    try:
        backend.simulate(mechanism, options)
    finally:
        kernel.run_chunk = inner
    return spent[0]


def best_of(function, repeat: int = REPEAT) -> float:  # noqa: ANN001
    function()
    best = float("inf")
    for _ in range(repeat):
        started = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - started)
    return best


def floor_setup(mechanism, trace):  # noqa: ANN001, ANN201
    """The floor's arguments: 1A's configuration with the most output rows, its kernel tables."""
    from vtool.solvers.model.contact import ContactProblem

    problem = ContactProblem.for_run(mechanism)
    masks, counts = np.unique(trace.configuration, return_counts=True)
    mask = int(masks[np.argmax(counts)])
    problem.build(mask)
    ci, _, cp, _, _ = problem.tables.of(mask)
    nf, m, nrows = int(ci[layout.CI_NF]), int(ci[layout.CI_M]), int(ci[layout.CI_ROWS])
    source_of = ci[layout.CI_HEAD + 2 * problem.n:].copy()
    gaps = np.array([[0, min(1, nf - 1)], [min(2, nf - 1), min(3, nf - 1)], [min(4, nf - 1), 0]], dtype=np.int64)
    s = problem.series
    G = np.ascontiguousarray(cp[layout.CP_STD])
    h = mechanism.spec.run.time_step
    return G, nf, nrows, m, source_of, s.const, s.cos, s.sin, s.omega, h, 1.0 / 6.0, 0.5, gaps


def floor_seconds(arguments, steps: int) -> float:  # noqa: ANN001
    n = arguments[3]

    def run() -> None:
        floor_loop(*arguments, steps, np.full(n, 1e-3), np.zeros(n), np.zeros(n))

    return best_of(run) / steps


def step_rounds() -> list[tuple[float, float]]:
    """(kernel, floor) seconds per step in ROUNDS interleaved rounds."""
    spec = load_preset("gnilka-1a")
    mechanism = assemble(spec)
    backend = NewmarkBackend()
    options = backend.options_from_run(spec.run)
    trace = backend.simulate(mechanism, options)
    steps = trace.statistics.steps
    arguments = floor_setup(mechanism, trace)
    rounds = []
    for _ in range(ROUNDS):
        kernel = min(kernel_seconds(backend, mechanism, options) for _ in range(REPEAT)) / steps
        rounds.append((kernel, floor_seconds(arguments, steps)))
    return rounds


def ratio_line(rounds: list[tuple[float, float]]) -> str:
    ratios = [k / f for k, f in rounds]
    return (f"kernel per step / floor, round by round over {len(rounds)} interleaved rounds: median "
            f"{statistics.median(ratios):.2f} (range {min(ratios):.2f}-{max(ratios):.2f}; target <= "
            f"{TARGET_STEP_RATIO}); kernel median {statistics.median(k for k, _ in rounds) * 1e9:.0f} ns/step, "
            f"floor median {statistics.median(f for _, f in rounds) * 1e9:.0f} ns/step")


SOLVE = [sys.executable, "-m", "vtool", "solve", "gnilka-1a"]


def first_compile() -> tuple[float, float, float, int, int, int]:
    """(kernel compile s, process CPU s, process wall s, events, compiled functions, their compiled
    specialisations) of ``vtool solve gnilka-1a --json`` with an empty cache: the command the target
    names, with the CLI's own settings (its collector thresholds among them). The compile is the JSON's
    ``compile_time_s``; the functions and specialisations are counted in numba's cache (an index file per
    function, a data file per specialisation; inline helpers are compiled inside their callers)."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        out = subprocess.run([*SOLVE, "--json"], capture_output=True, text=True, check=True, env=env)
        wall = time.perf_counter() - started
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        functions = len(list(Path(cache).rglob("*.nbi")))
        specialisations = len(list(Path(cache).rglob("*.nbc")))
    summary = json.loads(out.stdout)
    cpu = after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    return summary["compile_time_s"], cpu, wall, summary["events"], functions, specialisations


def bytecode_environment() -> dict[str, str]:
    """This process' environment with Python writing and reading bytecode, as a user's has: pip compiles an
    installed package's bytecode, and an editable install's is written at its first import, as numpy's
    and numba's here are. Where ``PYTHONDONTWRITEBYTECODE`` is set (this machine sets it), a solve would
    otherwise compile every vtool module from its source in every process while the imports it is
    measured against load theirs."""
    return {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}


def process_seconds(command: list[str]) -> float:
    started = time.perf_counter()
    subprocess.run(command, capture_output=True, check=True, env=bytecode_environment())
    return time.perf_counter() - started


IMPORTS = [sys.executable, "-c", "import numpy, numba"]


def second_process() -> list[tuple[float, float]]:
    """(``vtool solve gnilka-1a``, ``import numpy, numba``) seconds of fresh processes, ROUNDS pairs
    alternating (after one solve that compiles or loads the kernel and writes the bytecode), each with its
    bytecode (:func:`bytecode_environment`)."""
    subprocess.run(SOLVE, capture_output=True, check=True, env=bytecode_environment())
    return [(process_seconds(SOLVE), process_seconds(IMPORTS)) for _ in range(ROUNDS)]


def second_process_line(pairs: list[tuple[float, float]]) -> str:
    ratios = [a / b for a, b in pairs]
    return (f"second process: `vtool solve gnilka-1a` median {statistics.median(a for a, _ in pairs):.2f} s, "
            f"`python3 -c \"import numpy, numba\"` median {statistics.median(b for _, b in pairs):.2f} s; "
            f"ratio pair by pair over {len(pairs)} alternating pairs: median {statistics.median(ratios):.2f} "
            f"(range {min(ratios):.2f}-{max(ratios):.2f}; target <= {TARGET_SECOND_PROCESS_RATIO})")


def main(argv: list[str]) -> None:
    if "--ratio" in argv:
        rounds = step_rounds()
        for number, (kernel, floor) in enumerate(rounds, 1):
            print(f"  round {number}: kernel {kernel * 1e9:5.1f} ns/step, floor {floor * 1e9:5.1f} ns/step, "
                  f"ratio {kernel / floor:.2f}")
        print("  " + ratio_line(rounds))
        return
    print("Newmark back end, ratios measured in this run")
    for name in ("gnilka-1a", "gnilka-1d", "gnilka-2"):
        spec = load_preset(name)
        whole = best_of(lambda spec=spec: simulate(spec))
        trace = simulate(spec)
        print(f"  {name}: warm simulate {whole * 1e3:7.2f} ms; {trace.statistics.steps} steps, "
              f"{len(trace.events)} events")
    print("  " + ratio_line(step_rounds()))
    if "--no-compile" not in argv:
        runs = sorted(first_compile() for _ in range(COMPILES))
        compile_s = [run[0] for run in runs]
        _, cpu, wall, events, functions, specialisations = runs[len(runs) // 2]  # the median run (COMPILES odd)
        print(f"  first run with an empty cache, `vtool solve gnilka-1a` {COMPILES} times: kernel compile median "
              f"{statistics.median(compile_s):.1f} s wall (range {min(compile_s):.1f}-{max(compile_s):.1f}; target <= "
              f"{TARGET_COMPILE_S:.0f} s); that process {wall:.1f} s wall, {cpu:.1f} s CPU; {events} events; "
              f"{functions} kernel functions compiled, {specialisations} specialisations")
    print("  " + second_process_line(second_process()))


if __name__ == "__main__":
    main(sys.argv[1:])
