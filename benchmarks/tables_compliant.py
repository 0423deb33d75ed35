"""Writes docs/contact.md's stiffness study: linear contacts on gnilka-1a against the rigid runs.

Run: ``python3 benchmarks/tables_compliant.py`` (``--check`` compares instead of writing and
exits 1 when the committed table differs). Every number comes from
:func:`vtool.solvers.studies.compliance.study` (exact back end; the Newmark step search against it).

The check allows ``CHECK_REL`` relative on each number: at k = 1e8 and 1e9 the
seat chatters for thousands of events, and the event count follows the last
bits of LAPACK's results, which differ between CPUs (1757 events on one
machine, 1755 on another, the same code).
"""

from __future__ import annotations

import sys
from pathlib import Path

from vtool.markdown import read_block, replace_block, table, table_differences
from vtool.presets import load_preset
from vtool.solvers.studies.compliance import study

DOC = Path(__file__).resolve().parent.parent / "docs" / "contact.md"
PRESET = "gnilka-1a"
STIFFNESSES = (1e5, 1e6, 1e7, 1e8, 1e9)  # lbf/in
RATIO = 1.0
BLOCK = "stiffness-study"
CHECK_REL = 5e-3  # see the module doc


def block() -> str:
    spec = load_preset(PRESET)
    units = spec.unit_system
    header = ["contact (every clearance)", "throw-off (deg)", "first seating (deg)",
              f"seating velocity ({units.velocity})", f"impulse J ({units.force}*s)",
              f"peak seat force ({units.force})", f"peak seat overlap ({units.length})", "events",
              "Newmark step it needs (us)", "Newmark steps"]
    rows = []
    for row in study(spec, STIFFNESSES, RATIO):
        f = row.exact
        rigid = f.peak_overlap is None
        step = "-" if rigid else (f"{row.step * 1e6:g}" if row.step is not None else "< 0.004")
        rows.append([row.label, f"{f.throw_off:.3f}", f"{f.seating_angle:.3f}", f"{f.seating_velocity:.1f}",
                     f"{f.impulse:.5f}", f"{f.peak_seat_force:.0f}",
                     "-" if f.peak_overlap is None else f"{f.peak_overlap:.3g}", str(f.events), step,
                     "-" if row.newmark is None else str(row.newmark.steps)])
    return table(header, rows)


def main(check: bool = False) -> int:
    text = block()
    if check:
        differences = table_differences(read_block(DOC, BLOCK), text, CHECK_REL)
        for line in differences:
            print(f"{DOC.name}: block {BLOCK}: {line} (`python3 benchmarks/tables_compliant.py` rewrites it)")
        return 1 if differences else 0
    replace_block(DOC, BLOCK, text)
    return 0


if __name__ == "__main__":
    sys.exit(main("--check" in sys.argv[1:]))
