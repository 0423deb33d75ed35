"""Writes the model-choice tables of docs/valvetrain.md (impact laws x start velocities).

Run: ``python3 benchmarks/tables_compare.py`` (``--check`` compares instead of writing
and exits 1 when a committed table differs). Every number in the blocks comes from
:func:`vtool.solvers.studies.compare.compare`, the same code as ``vtool compare``.
"""

from __future__ import annotations

import sys
from pathlib import Path

from vtool.markdown import read_block, replace_block, table
from vtool.presets import load_preset
from vtool.solvers.studies.compare import cell, compare
from vtool.solvers.studies.compare import table as comparison

DOC = Path(__file__).resolve().parent.parent / "docs" / "valvetrain.md"
PRESETS = ("gnilka-1a", "gnilka-2")
STARTS = ("thesis", "quasi-static")


def block(name: str) -> str:
    header, rows = comparison(compare(load_preset(name), starts=STARTS))
    return table(header, [[cell(v) for v in row] for row in rows])


def main(check: bool = False) -> int:
    stale = []
    for name in PRESETS:
        text = block(name)
        key = f"compare-{name}"
        if check:
            if read_block(DOC, key) != text:
                stale.append(key)
        else:
            replace_block(DOC, key, text)
    for key in stale:
        print(f"{DOC.name}: block {key} differs from `python3 benchmarks/tables_compare.py`")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main("--check" in sys.argv[1:]))
