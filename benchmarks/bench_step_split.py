"""Where a warm run's kernel time goes on example 1A: the steps, the output rows, the rest (events).

Run: ``python3 benchmarks/bench_step_split.py [REF]``. Prints figures, asserts nothing. With REF (a
commit, e.g. 5077ed9, the kernel before issue 35's rewrite), that commit's kernel is split the same way
first, in a child process on its own sources and numba cache (laid out as ``bench_compile_ab.py`` does;
no floor: its tables differ), then this checkout's.

The kernel's time (``bench_newmark.kernel_seconds``: inside its calls, the best of REPEAT runs) is
taken for 1A as shipped and for three variants of it, in ROUNDS interleaved rounds (medians printed):

* the time step halved and quartered (the same events): the cost of one more step is the
  difference of the two, divided by the difference of their step counts (the quiet step's
  marginal cost, its share of the refined and event steps included);
* one output row instead of one a degree: the output rows' cost is the difference to 1A's.

What is left of 1A's time after its steps at the marginal cost and its rows is the fixed part: event
location, impacts, the returns to the step grid, the quiet loop's entries. The floor of
``bench_newmark.py`` (the least work a quiet step does) is timed in the same rounds, and the last
line says what 1A's ratio to it would be if every step cost no more than the floor: the bound that
the output rows and the events alone put on the step ratio.
"""

from __future__ import annotations

import dataclasses
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from bench_compile_ab import environment, layout
from bench_newmark import REPEAT, TARGET_STEP_RATIO, floor_seconds, floor_setup, kernel_seconds

from vtool.presets import load_preset
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.newmark.backend import NewmarkBackend

ROUNDS = 7


def variant(time_step_factor: float = 1.0, one_row: bool = False):  # noqa: ANN201
    """(backend, mechanism, options, trace) of 1A with its time step scaled, or with one output row."""
    spec = load_preset("gnilka-1a")
    run = spec.run
    run = dataclasses.replace(run, time_step=run.time_step * time_step_factor,
                              output_interval=run.degrees if one_row else run.output_interval)
    spec = dataclasses.replace(spec, run=run)
    mechanism = assemble(spec)
    backend = NewmarkBackend()
    options = backend.options_from_run(spec.run)
    return backend, mechanism, options, backend.simulate(mechanism, options)


def main(with_floor: bool = True) -> None:
    cases = {"1A": variant(), "dt/2": variant(0.5), "dt/4": variant(0.25), "one row": variant(one_row=True)}
    for name, (_, _, _, trace) in cases.items():
        print(f"  {name}: {trace.statistics.steps} steps, {len(trace.events)} events, {len(trace.time)} rows")
    base = cases["1A"]
    steps = {name: case[3].statistics.steps for name, case in cases.items()}
    rows = len(base[3].time)
    arguments = floor_setup(base[1], base[3]) if with_floor else None
    seconds: dict[str, list[float]] = {name: [] for name in [*cases, "floor"]}
    for _ in range(ROUNDS):
        for name, (backend, mechanism, options, _) in cases.items():
            seconds[name].append(min(kernel_seconds(backend, mechanism, options) for _ in range(REPEAT)))
        if arguments is not None:
            seconds["floor"].append(floor_seconds(arguments, steps["1A"]))
    kernel = statistics.median(seconds["1A"])
    step = statistics.median((q - h) / (steps["dt/4"] - steps["dt/2"]) for q, h in zip(seconds["dt/4"], seconds["dt/2"],
                                                                                       strict=True))
    output = statistics.median(k - o for k, o in zip(seconds["1A"], seconds["one row"], strict=True))
    fixed = kernel - step * steps["1A"] - output
    n = steps["1A"]
    print(f"gnilka-1a's kernel, medians of {ROUNDS} interleaved rounds (each the best of {REPEAT} runs):")
    print(f"  whole kernel {kernel * 1e6:.0f} us = {kernel / n * 1e9:.1f} ns per step over {n} steps")
    print(f"  steps at the marginal cost {step * 1e9:.1f} ns each: {step * n * 1e6:.0f} us ({100 * step * n / kernel:.0f} %)")
    print(f"  output rows: {output * 1e6:.0f} us ({100 * output / kernel:.0f} %), {output / (rows - 1) * 1e9:.0f} ns "
          f"per row, {output / n * 1e9:.1f} ns per step")
    print(f"  the rest (events, returns to the grid, quiet-loop entries): {fixed * 1e6:.0f} us "
          f"({100 * fixed / kernel:.0f} %), {fixed / n * 1e9:.1f} ns per step")
    if arguments is None:
        return
    floor = statistics.median(seconds["floor"])
    print(f"  floor {floor * 1e9:.1f} ns per step: whole kernel {kernel / n / floor:.2f} x the floor (target <= "
          f"{TARGET_STEP_RATIO}), steps {step / floor:.2f} x")
    bound = (floor * n + output + fixed) / (floor * n)
    print(f"  with every step at the floor's cost, rows and the rest as measured: ratio {bound:.2f}; "
          f"the {TARGET_STEP_RATIO} target then needs steps at most "
          f"{(TARGET_STEP_RATIO * floor * n - output - fixed) / n / floor:.2f} x the floor")


def earlier(ref: str) -> None:
    """The split of commit ``ref``'s kernel, in a child process on its own sources and numba cache."""
    with tempfile.TemporaryDirectory() as folder, tempfile.TemporaryDirectory() as cache:
        entry = layout(ref, Path(folder))
        env = environment(entry, cache)
        child = [sys.executable, str(Path(__file__).resolve()), "--no-floor"]
        out = subprocess.run(child, capture_output=True, text=True, env=env, cwd=tempfile.gettempdir())
        if out.returncode != 0:
            raise SystemExit(f"{ref}'s split failed:\n{out.stderr[-2000:]}")
        print(f"{ref}:\n{out.stdout}this checkout:")


if __name__ == "__main__":
    refs = [a for a in sys.argv[1:] if not a.startswith("--")]
    if refs:
        earlier(refs[0])
    sys.exit(main(with_floor="--no-floor" not in sys.argv))
