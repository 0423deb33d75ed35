"""Generated Markdown blocks in README and docs: tables a script writes, never a person.

A generated block sits between two HTML comments that name it::

    <!-- generated:accuracy-1a (python3 benchmarks/tables_valvetrain.py) -->
    | ... the table ... |
    <!-- /generated:accuracy-1a -->

The text after the name in the opening comment says which command writes the
block. :func:`replace_block` rewrites the lines between the markers,
:func:`read_block` returns them, so a test can regenerate a table's
deterministic columns and compare them with the committed file.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
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
