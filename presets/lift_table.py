"""Read a cam lift table from CSV: two columns, cam angle (deg) and lift (length units).

A header row (any non-numeric first line) and ``#`` comment lines are
skipped; commas, semicolons, tabs or spaces separate the columns. The file is
resolved against the preset's folder, must be a regular file and at most
:data:`MAX_BYTES` long, so a wrong path (a device, a FIFO, a huge log) fails
with one line instead of a hang.

An error names the file, the line number and what is wrong with the line
(how many cells, which are not numbers), never the line itself: the field
may name any file the user can read (``lift_table = "/etc/shadow"``), and an
error message must not show its content.
"""

from __future__ import annotations

import re
from pathlib import Path

from vtool.errors import InputError
from vtool.files import is_file

MAX_BYTES = 4_000_000
_SPLIT = re.compile(r"[,;\t ]+")


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def read_table_text(field: str, name: str, folder: Path | None) -> str:
    """The text of the file ``name`` (relative to ``folder``), with the checks of the module doc."""
    path = Path(name) if Path(name).is_absolute() or folder is None else Path(folder) / name
    if not is_file(path):
        raise InputError(field, str(path), "an existing regular file (relative to the preset's folder)")
    try:
        with path.open("rb") as handle:
            data = handle.read(MAX_BYTES + 1)
    except OSError as exc:
        raise InputError(field, str(path), f"a readable file ({exc.strerror})") from None
    if len(data) > MAX_BYTES:
        raise InputError(field, str(path), f"a file of at most {MAX_BYTES} bytes")
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        bad = data[: exc.start].count(b"\n") + 1
        raise InputError(field, str(path), f"UTF-8 text (line {bad} is not)") from None
    return text


def read_lift_table(field: str, name: str, folder: Path | None, unit: str) -> tuple[list[float], list[float]]:
    """(angles_deg, lifts) from the CSV ``name`` (relative to ``folder``)."""
    text = read_table_text(field, name, folder)
    path = Path(name) if Path(name).is_absolute() or folder is None else Path(folder) / name
    angles: list[float] = []
    lifts: list[float] = []
    first = True
    for number, line in enumerate(text.splitlines(), start=1):
        cells = [c for c in _SPLIT.split(line.split("#", 1)[0].strip()) if c]
        if not cells:
            continue
        header, first = first, False
        try:
            values = [float(c) for c in cells]
        except ValueError:
            if header:
                continue
            values = []
        if len(values) != 2:
            bad = sum(1 for c in cells if not _is_number(c))
            what = (f"{len(cells)} cell{'s' if len(cells) != 1 else ''}"
                    + (f", {bad} not a number" if bad else ""))
            raise InputError(f"{field} ({path.name}) line {number}", str(path),
                             f"two numbers per line, angle (deg) and lift ({unit}); this line has {what} "
                             "(its text is not shown)")
        angles.append(values[0])
        lifts.append(values[1])
    return angles, lifts
