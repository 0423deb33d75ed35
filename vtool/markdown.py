"""Generated Markdown blocks in README and docs: tables a script writes, never a person.

A generated block sits between two HTML comments that name it::

    <!-- generated:accuracy-1a (python3 benchmarks/tables_valvetrain.py) -->
    | ... the table ... |
    <!-- /generated:accuracy-1a -->

The text after the name in the opening comment says which command writes the
block. :func:`replace_block` rewrites the lines between the markers,
:func:`read_block` returns them, so a test can regenerate a table's
deterministic columns and compare them with the committed file.
:func:`table_differences` compares two tables cell by cell with a relative
tolerance on numbers, for tables whose last digits depend on the machine
(a chattering contact's event count follows LAPACK's last bits, which differ
between CPUs).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Sequence
from pathlib import Path

from vtool.files import write_atomic


def _pattern(name: str) -> re.Pattern[str]:
    return re.compile(
        rf"(<!-- generated:{re.escape(name)}(?: [^>]*)? -->\n)(.*?)(<!-- /generated:{re.escape(name)} -->)",
        re.DOTALL,
    )


def table(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    """A GitHub Markdown table; cells are written with ``str``."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(cell) for cell in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def read_block(path: str | Path, name: str) -> str:
    """The text between the markers of block ``name`` in ``path``."""
    text = Path(path).read_text(encoding="utf-8")
    match = _pattern(name).search(text)
    if match is None:
        raise KeyError(f"{path}: no generated block {name!r}")
    return match.group(2)


def replace_block(path: str | Path, name: str, content: str) -> bool:
    """Replace block ``name`` in ``path`` with ``content`` (atomically); True when the file changed."""
    text = Path(path).read_text(encoding="utf-8")
    pattern = _pattern(name)
    if pattern.search(text) is None:
        raise KeyError(f"{path}: no generated block {name!r}")
    body = content if content.endswith("\n") else content + "\n"
    new = pattern.sub(lambda m: m.group(1) + body + m.group(3), text, count=1)
    if new != text:
        write_atomic(str(path), new)
    return new != text


def _number(cell: str) -> float | None:
    try:
        return float(cell)
    except ValueError:
        return None


def _within_decades(a: str, b: str, decades: int) -> bool:
    """Both cells bounds ``< x`` (x > 0) whose x differ by at most ``decades`` powers of ten."""
    if not (a.startswith("< ") and b.startswith("< ")):
        return False
    x, y = _number(a[2:]), _number(b[2:])
    return x is not None and y is not None and x > 0 and y > 0 and abs(math.log10(x / y)) <= decades + 1e-9


def table_differences(committed: str, fresh: str, rel: float, decades: int = 0) -> list[str]:
    """The cells where two Markdown tables differ: text exactly, numbers beyond ``rel`` relative,
    bounds ``< 1e-7`` by more than ``decades`` powers of ten.

    Returns one line per differing cell (line, column, both values), or a line
    naming a difference in shape; an empty list when the tables agree.
    """
    rows_a = [line.strip().strip("|").split("|") for line in committed.strip().splitlines()]
    rows_b = [line.strip().strip("|").split("|") for line in fresh.strip().splitlines()]
    if len(rows_a) != len(rows_b):
        return [f"{len(rows_a)} lines committed, {len(rows_b)} generated"]
    out = []
    for r, (row_a, row_b) in enumerate(zip(rows_a, rows_b, strict=True)):
        if len(row_a) != len(row_b):
            out.append(f"line {r + 1}: {len(row_a)} cells committed, {len(row_b)} generated")
            continue
        for col, (a, b) in enumerate(zip(row_a, row_b, strict=True)):
            a, b = a.strip(), b.strip()
            x, y = _number(a), _number(b)
            if x is not None and y is not None:
                if abs(x - y) <= rel * max(abs(x), abs(y)):
                    continue
            elif a == b or _within_decades(a, b, decades):
                continue
            out.append(f"line {r + 1}, column {col + 1}: committed {a}, generated {b}")
    return out


def write_or_check(path: Path, blocks: Callable[[], dict[str, str]], script: str, description: str,
                   after_write: Callable[[], None] | None = None) -> int:
    """A docs script's command line: ``--write`` replaces each generated block of ``path`` with what
    ``blocks()`` gives (then calls ``after_write``: figures), ``--check`` returns 1 (naming ``script``)
    when one is not current."""
    import argparse
    import sys

    parser = argparse.ArgumentParser(description=description)
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true", help="rewrite the blocks")
    mode.add_argument("--check", action="store_true", help="exit 1 if a block is not current")
    args = parser.parse_args()
    fresh = blocks()
    if args.write:
        for name, text in fresh.items():
            changed = replace_block(path, name, text)
            print(f"{name}: {'updated' if changed else 'unchanged'}", file=sys.stderr)
        if after_write is not None:
            after_write()
        return 0
    stale = [name for name, text in fresh.items() if read_block(path, name) != text]
    for name in stale:
        print(f"{name} is not current: run python {script} --write", file=sys.stderr)
    return 1 if stale else 0
