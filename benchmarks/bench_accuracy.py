"""The speed/accuracy trade of one preset, measured in one run (ratios, not absolute times).

Run: ``python3 benchmarks/bench_accuracy.py [PRESET]`` (default gnilka-1a).
Prints figures, asserts nothing. The tables in README.md and
docs/valvetrain.md are written by ``python3 benchmarks/tables_valvetrain.py``.

1. The accuracy table of ``vtool accuracy PRESET`` (every back end over its
   knob against the exact back end).
2. Newmark at dt = 1e-6 s against scipy at equal event-angle accuracy: the
   cheapest scipy setting at least as accurate, and the time ratio.
3. The exact back end's wall time, and the Newmark step at which Newmark
   costs as much.
"""

from __future__ import annotations

import sys

from vtool.presets import load_preset
from vtool.solvers.run import simulate
from vtool.solvers.studies.accuracy import accuracy_study, compare, table_text, with_run


def main(name: str = "gnilka-1a") -> None:
    spec = load_preset(name)
    simulate(spec)  # JIT warm-up
    reference, rows = accuracy_study(spec)
    print(table_text(rows))
    newmark = next(r for r in rows if r.setting == "dt=1e-06 beta=1/6")
    scipy_rows = [r for r in rows if r.backend == "scipy" and r.event_angle_error is not None]
    as_good = [r for r in scipy_rows if r.event_angle_error <= newmark.event_angle_error]
    cheapest = min(as_good, key=lambda r: r.wall_time) if as_good else None
    print()
    print(f"Newmark dt=1e-6 s, beta=1/6: {newmark.wall_time * 1e3:.1f} ms, max event-angle error "
          f"{newmark.event_angle_error:.3g} deg, peak-force error {newmark.peak_force_error * 100:.2g} %")
    if cheapest is not None:
        print(f"  cheapest scipy setting at least as accurate in event angles: {cheapest.setting}, "
              f"{cheapest.wall_time:.3f} s -> Newmark is {cheapest.wall_time / newmark.wall_time:.0f}x faster")
    for target in (0.1, 0.01):
        n = [r for r in rows if r.backend == "newmark" and r.event_angle_error is not None
             and r.event_angle_error <= target and r.unmatched_events == 0]
        s = [r for r in scipy_rows if r.event_angle_error <= target and r.unmatched_events == 0]
        if n and s:
            best_n, best_s = min(n, key=lambda r: r.wall_time), min(s, key=lambda r: r.wall_time)
            print(f"  event angles within {target} deg: Newmark {best_n.setting} {best_n.wall_time:.3f} s, "
                  f"scipy {best_s.setting} {best_s.wall_time:.3f} s -> ratio {best_s.wall_time / best_n.wall_time:.1f}")
    exact_time = reference.statistics.wall_time
    print(f"exact back end: {exact_time:.3f} s ({reference.statistics.steps} scan samples, "
          f"{reference.statistics.events} events)")
    for dt in (5e-8, 2e-8, 1e-8):
        trace = simulate(with_run(spec, time_step=dt))
        row = compare(trace, reference, "newmark", f"dt={dt:.0e}")
        print(f"  Newmark dt={dt:.0e} s: {row.wall_time:.3f} s = {row.wall_time / exact_time:.2f} x exact, "
              f"max event-angle error {row.event_angle_error:.2g} deg")


if __name__ == "__main__":
    main(*sys.argv[1:2])
