"""The cost of steady state: cam cycles a run needs to settle, per preset and speed, from the static start and
from a periodic start (the state at the end of the previous, slower, sweep point's last cycle, velocities
scaled to the new speed: solvers/studies/steady.py State), and the cycles the periodic start saves.

    python benchmarks/bench_steady.py [--tolerance 1e-3] [--max-cycles 30] [--write]

Counts, not times: they do not depend on the machine. A point that does not settle counts its max_cycles
(marked !); one that settles to a p-cycle orbit is marked /p. ``--write`` puts the table into the
steady-cycles block of docs/valvetrain.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import warnings
from pathlib import Path

from vtool.markdown import replace_block, table
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers import backends
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.studies.steady import simulate_cycles

PRESETS = ("gnilka-1a", "gnilka-1c", "ramped-cam", "ohv-pushrod-1a", "direct-acting-bucket", "ohc-finger-follower")
DOCS = Path(__file__).resolve().parent.parent / "docs" / "valvetrain.md"
SPEEDS = (3000, 4500, 6000, 7500, 9000, 10500, 12000, 13500, 15000)


def cycles(spec, start=None, keep=None):  # noqa: ANN001, ANN201
    """(cycles run, settled, period) of one run to steady state."""
    backend = backends.get(spec.run.backend)()
    trace = simulate_cycles(backend, assemble(spec), start=start, on_state=keep)
    return trace.cycles.count, bool(trace.cycles.settled), trace.cycles.period


def rows(tolerance: float, max_cycles: int) -> tuple[list[str], list[list[str]]]:
    """The table: per preset, the cycles at each speed (static start / periodic start) and the totals."""
    header = ["preset"] + [f"{s:,} rev/min" for s in SPEEDS] + ["total", "periodic / static"]
    table = []
    for name in PRESETS:
        spec = load_preset(name)
        cells, static_total, periodic_total = [], 0, 0
        carried: list = []
        for rpm in SPEEDS:
            point = with_run_overrides(spec, rpm=rpm)
            point = dataclasses.replace(point, run=dataclasses.replace(point.run, steady_tolerance=tolerance,
                                                                       steady_max_cycles=max_cycles))
            static = cycles(point)
            periodic = cycles(point, carried[-1] if carried else None, carried.append)
            static_total += static[0]
            periodic_total += periodic[0]
            cells.append(f"{mark(*static)}/{mark(*periodic)}")
        table.append([f"`{name}`"] + cells + [f"{static_total}/{periodic_total}",
                                              f"{periodic_total / static_total:.2f}"])
    return header, table


def mark(count: int, settled: bool, period: int) -> str:
    return f"{count}{'' if settled else '!'}{'' if period == 1 else f'p{period}'}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tolerance", type=float, default=1e-3)
    parser.add_argument("--max-cycles", type=int, default=30)
    parser.add_argument("--write", action="store_true", help="write the table into docs/valvetrain.md")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    text = table(*rows(args.tolerance, args.max_cycles))
    print(f"cam cycles to settle to {args.tolerance:g} (at most {args.max_cycles}); static start / periodic start; "
          "! = did not settle, pN = settled to an N-cycle orbit")
    print(text)
    if args.write:
        replace_block(DOCS, "steady-cycles", text)


if __name__ == "__main__":
    main()
