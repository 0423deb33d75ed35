"""The cost of steady state: cam cycles a run needs to settle, per preset and speed, from the static start and
from a periodic start (the state at the end of the previous, slower, sweep point's last cycle, velocities
scaled to the new speed: solvers/studies/steady.py State), and the cycles the periodic start saves.

    python benchmarks/bench_steady.py [--tolerance 1e-3] [--max-cycles 30]

Counts, not times: they do not depend on the machine. A point that does not settle counts its max_cycles.
"""

from __future__ import annotations

import argparse
import dataclasses
import warnings

from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers import backends
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.studies.steady import simulate_cycles

PRESETS = ("gnilka-1a", "gnilka-2", "ramped-cam")
SPEEDS = (3000, 4500, 6000, 7500, 9000, 10500, 12000, 13500, 15000)


def cycles(spec, start=None, keep=None):  # noqa: ANN001, ANN201
    backend = backends.get(spec.run.backend)()
    trace = simulate_cycles(backend, assemble(spec), start=start, on_state=keep)
    return trace.cycles.count, trace.cycles.settled


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tolerance", type=float, default=1e-3)
    parser.add_argument("--max-cycles", type=int, default=30)
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    print(f"cam cycles to settle to {args.tolerance:g} (at most {args.max_cycles}); static start / periodic start")
    print(f"{'preset':<12}" + "".join(f"{s:>9}" for s in SPEEDS) + f"{'total':>9}")
    for name in PRESETS:
        spec = load_preset(name)
        cells, static_total, periodic_total = [], 0, 0
        carried = []
        for rpm in SPEEDS:
            point = with_run_overrides(spec, rpm=rpm)
            point = dataclasses.replace(point, run=dataclasses.replace(point.run, steady_tolerance=args.tolerance,
                                                                       steady_max_cycles=args.max_cycles))
            n_static, ok_static = cycles(point)
            n_periodic, ok_periodic = cycles(point, carried[-1] if carried else None, carried.append)
            static_total += n_static
            periodic_total += n_periodic
            mark = lambda ok: "" if ok else "!"  # noqa: E731
            cells.append(f"{n_static}{mark(ok_static)}/{n_periodic}{mark(ok_periodic)}")
        print(f"{name:<12}" + "".join(f"{c:>9}" for c in cells) + f"{static_total:>5}/{periodic_total}")
        print(f"{'':<12}periodic start: {periodic_total / static_total:.2f} of the static start's cycles")
    print("! = did not settle within max-cycles")


if __name__ == "__main__":
    main()
