"""Typed, validated reads from a parsed TOML table.

A :class:`Table` wraps one TOML table together with its dotted path, so every
error names the full field (``members.pushrod.length``). Reading a key marks it
as used; :meth:`Table.finish` then rejects any key nobody asked for, so a typo
in a preset is an error rather than a silently ignored setting.

Example::

    t = Table(doc, "")
    length = t.number("length", unit="in", min_exclusive=0.0)
    t.finish()

Every read is also a field definition: inside :func:`recording`, each key a
loader asks for is noted as a :class:`FieldRead` (its path with ``*`` for a
named table and ``[]`` for an array entry, type, unit, allowed values and
default), which :mod:`vtool.presets.reference` turns into docs/presets.md.
"""

from __future__ import annotations

import difflib
import math
import re
import unicodedata
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any, Literal, overload

from vtool.errors import InputError

#: Longest list a preset may give for one field (coordinates, members, quantities, ...).
MAX_LIST = 1000
#: Longest string field (titles, notes, names).
MAX_STRING = 10_000
#: Unicode categories refused in a text field: controls, format characters (bidi overrides, zero-width),
#: line and paragraph separators, surrogates.
CONTROL_CATEGORIES = frozenset({"Cc", "Cf", "Zl", "Zp", "Cs"})


#: The default of a read that has none (the key is required).
REQUIRED = "(required)"


@dataclass
class FieldRead:
    """One key a loader reads, as :func:`recording` notes it; values seen in several reads are merged."""

    path: str  # e.g. "run.rpm", "members.*.length", "clearances[].gap"
    type: str  # number, integer, string, boolean, numbers, table, tables, array of tables, value
    units: set[str] = field(default_factory=set)
    allowed: set[str] = field(default_factory=set)
    defaults: set[str] = field(default_factory=set)


_recording: ContextVar[dict[str, FieldRead] | None] = ContextVar("vtool_field_reads", default=None)


@contextmanager
def recording() -> Iterator[dict[str, FieldRead]]:
    """Note every key read by a :class:`Table` in this context (path -> :class:`FieldRead`)."""
    reads: dict[str, FieldRead] = {}
    token = _recording.set(reads)
    try:
        yield reads
    finally:
        _recording.reset(token)


def _shown_default(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_shown_default(v) for v in value) + "]"
    return str(value)


def as_float(value: Any) -> float:
    """``float(value)`` for an int or float; an int too large for a float gives inf (refused later)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def closest(key: str, known: list[str]) -> str:
    """`` (did you mean `rpm`?)`` for the known key nearest to ``key``, or ``""``."""
    match = difflib.get_close_matches(key, known, n=1, cutoff=0.6)
    return f" (did you mean `{match[0]}`?)" if match else ""


def _kind_of(value: Any) -> str:
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, int | float):
        return "a number"
    if isinstance(value, str):
        return "a string"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a table"
    return type(value).__name__


class Table:
    """One TOML table with its dotted path; reads keys with validation."""

    def __init__(self, data: Any, path: str, pattern: str | None = None) -> None:
        if not isinstance(data, dict):
            raise InputError(path or "<preset>", _kind_of(data), "a table")
        self.data = data
        self.path = path
        #: the path with ``[]`` for an array entry and ``*`` for a named table (what the reference lists)
        self.pattern = re.sub(r"\[\d+\]", "[]", path) if pattern is None else pattern
        self._used: set[str] = set()

    def field(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def _pattern(self, key: str) -> str:
        key = "<number>" if str(key).isdigit() else key  # keys that are numbers (mode ratios): one entry
        return f"{self.pattern}.{key}" if self.pattern else key

    def _note(self, key: str, kind: str, unit: str = "", allowed: str = "", default: Any = None,
              required: bool = False, path: str | None = None) -> None:
        """Record this read as a field definition when :func:`recording` is on (``path``: the key's
        pattern when it is not this table's pattern and the key)."""
        reads = _recording.get()
        if reads is None:
            return
        path = self._pattern(key) if path is None else path
        read = reads.setdefault(path, FieldRead(path, kind))
        if unit:
            read.units.add(unit)
        if allowed:
            read.allowed.add(allowed)
        read.defaults.add(REQUIRED if required else "" if default is None else _shown_default(default))

    def has(self, key: str) -> bool:
        return key in self.data

    def _get(self, key: str, default: Any, required: bool) -> Any:
        self._used.add(key)
        if key in self.data:
            return self.data[key]
        if required:
            typo = difflib.get_close_matches(key, [str(k) for k in self.data], n=1, cutoff=0.6)
            if typo and typo[0] not in self._used:
                raise InputError(self.field(typo[0]), self.data[typo[0]],
                                 f"no such field (unknown key) (did you mean `{key}`?)")
            raise InputError(self.field(key), None, "a value (required field)")
        return default

    def number(
        self,
        key: str,
        *,
        unit: str = "",
        default: float | None = None,
        required: bool | None = None,
        min_value: float | None = None,
        min_exclusive: float | None = None,
        max_value: float | None = None,
        max_exclusive: float | None = None,
    ) -> float:
        """A finite float within the given bounds (ints are accepted)."""
        required = default is None if required is None else required
        expected = _range_text(min_value, min_exclusive, max_value, max_exclusive)
        self._note(key, "number", unit, expected, default, required)
        value = self._get(key, default, required)
        if value is None:
            return None  # type: ignore[return-value]  # required=False: None for a missing key, callers check
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise InputError(self.field(key), value, f"a number {expected}".strip(), unit)
        given, value = value, as_float(value)
        bad = (
            not math.isfinite(value)
            or (min_value is not None and value < min_value)
            or (min_exclusive is not None and value <= min_exclusive)
            or (max_value is not None and value > max_value)
            or (max_exclusive is not None and value >= max_exclusive)
        )
        if bad:
            raise InputError(self.field(key), given, expected or "a finite number", unit)
        return value

    def integer(
        self,
        key: str,
        *,
        default: int | None = None,
        min_value: int | None = None,
        max_value: int | None = None,
    ) -> int:
        expected = _range_text(min_value, None, max_value, None)
        self._note(key, "integer", "", expected, default, default is None)
        value = self._get(key, default, default is None)
        if isinstance(value, bool) or not isinstance(value, int):
            raise InputError(self.field(key), value, f"an integer {expected}".strip())
        if (min_value is not None and value < min_value) or (
            max_value is not None and value > max_value
        ):
            raise InputError(self.field(key), value, f"an integer {expected}")
        return value

    def string(self, key: str, *, default: str | None = None, choices: tuple[str, ...] = (),
               multiline: bool = False) -> str:
        """A text field: one line of printable text (``multiline``: line breaks and tabs allowed too,
        for notes); a control character (a newline in a name, an escape, a bidi override) is refused,
        so that no text field can break a CSV row, a table or a terminal line."""
        self._note(key, "string", "", f"one of: {', '.join(choices)}" if choices else "", default, default is None)
        value = self._get(key, default, default is None)
        if not isinstance(value, str):
            expected = f"one of: {', '.join(choices)}" if choices else "a string"
            raise InputError(self.field(key), value, expected)
        if choices and value not in choices:
            raise InputError(self.field(key), value, f"one of: {', '.join(choices)}")
        if len(value) > MAX_STRING:
            raise InputError(self.field(key), value, f"a string of at most {MAX_STRING:,} characters")
        allowed = "\n\t\r" if multiline else ""
        for position, char in enumerate(value):
            if char not in allowed and unicodedata.category(char) in CONTROL_CATEGORIES:
                words = "printable text" if multiline else "one line of printable text"
                raise InputError(self.field(key), value, f"{words} (U+{ord(char):04X}, a control character, "
                                 f"at position {position + 1})")
        return value

    def boolean(self, key: str, *, default: bool | None = None) -> bool:
        self._note(key, "boolean", "", "true or false", default, default is None)
        value = self._get(key, default, default is None)
        if not isinstance(value, bool):
            raise InputError(self.field(key), value, "true or false")
        return value

    @overload
    def table(self, key: str, *, required: Literal[True] = True, pattern: str | None = None,
              kind: str = "table") -> Table: ...

    @overload
    def table(self, key: str, *, required: bool, pattern: str | None = None, kind: str = "table") -> Table | None: ...

    def table(self, key: str, *, required: bool = True, pattern: str | None = None,
              kind: str = "table") -> Table | None:
        pattern = self._pattern(key) if pattern is None else pattern
        self._note(key, kind, required=required, path=pattern)
        value = self._get(key, None, required)
        if value is None:
            return None
        return Table(value, self.field(key), pattern)

    def tables(self, key: str, *, required: bool = True) -> Iterator[tuple[str, Table]]:
        """Sub-tables of a table of tables, e.g. ``[members.pushrod]`` (``members.*`` in the reference)."""
        outer = self.table(key, required=required, kind="tables")
        if outer is None:
            return iter(())
        inner = f"{outer.pattern}.*"
        return ((name, outer.table(name, pattern=inner)) for name in list(outer.data))

    def array_of_tables(self, key: str, *, required: bool = True) -> list[Table]:
        """Entries of an array of tables, e.g. ``[[clearances]]``."""
        self._note(key, "array of tables", required=required)
        value = self._get(key, [], required)
        if not isinstance(value, list):
            raise InputError(self.field(key), _kind_of(value), "an array of tables")
        if len(value) > MAX_LIST:
            raise InputError(self.field(key), f"{len(value)} entries", f"at most {MAX_LIST} entries")
        return [Table(item, f"{self.field(key)}[{i}]", f"{self._pattern(key)}[]") for i, item in enumerate(value)]

    def numbers(self, key: str, *, unit: str = "", default: list[float] | None = None) -> list[float]:
        self._note(key, "numbers", unit, "", default, default is None)
        value = self._get(key, default, default is None)
        if not isinstance(value, list) or any(
            isinstance(v, bool) or not isinstance(v, int | float) for v in value
        ):
            raise InputError(self.field(key), value, "a list of numbers", unit)
        if len(value) > MAX_LIST:
            raise InputError(self.field(key), f"{len(value)} numbers", f"at most {MAX_LIST} numbers", unit)
        numbers = [as_float(v) for v in value]
        if not all(math.isfinite(v) for v in numbers):
            raise InputError(self.field(key), value, "a list of finite numbers", unit)
        return numbers

    def raw(self, key: str, default: Any = None) -> Any:
        self._note(key, "value", default=default)
        return self._get(key, default, False)

    def finish(self) -> None:
        """Reject keys that were never read (typos, unsupported settings), naming the closest known key.

        Known keys are those the loader asked for, read or missing; a required
        key asked for after an unknown one would report itself as missing, so
        loaders that want the typo named call :meth:`check_unknown` first.
        """
        self.check_unknown(())

    def check_unknown(self, known: tuple[str, ...] | list[str]) -> None:
        """Reject keys neither read so far nor in ``known``, with the closest known key."""
        allowed = sorted(self._used | set(known))
        for key in self.data:
            if key not in allowed:
                raise InputError(self.field(key), self.data[key],
                                 f"no such field (unknown key){closest(str(key), allowed)}")


def _range_text(
    min_value: float | None,
    min_exclusive: float | None,
    max_value: float | None,
    max_exclusive: float | None,
) -> str:
    parts = []
    if min_value is not None:
        parts.append(f">= {min_value:g}")
    if min_exclusive is not None:
        parts.append(f"> {min_exclusive:g}")
    if max_value is not None:
        parts.append(f"<= {max_value:g}")
    if max_exclusive is not None:
        parts.append(f"< {max_exclusive:g}")
    return " and ".join(parts)
