"""Dotted preset paths: read and set one field of a parsed preset document.

A path is the name the loaders use in their error messages: table keys joined
by dots, array-of-tables entries by a 0-based index in brackets::

    run.rpm
    members.valve_spring.stiffness
    seat.position
    damping.factor
    clearances[2].restitution
    damping.layers[1].mode_ratios.2

:func:`set_field` returns a copy of the document with one value replaced (or
added: a key the table does not hold yet is added and left to the preset
loader, whose ``Table.finish()`` rejects it if no such field exists), so that
a swept value is validated by the loader itself and its error is the loader's
own. Only the tables and array entries on the way must already exist.

:func:`parse_values` turns a sweep's ``VALUES`` text (``start:stop:step`` or
``a,b,c``) into the list of values, with one-line errors for an empty range
or a step of the wrong sign.
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from vtool.errors import InputError

_SEGMENT = re.compile(r"([A-Za-z0-9_\-]+)((?:\[\d+\])*)")


def parse_path(path: str) -> list[str | int]:
    """``clearances[2].restitution`` -> ``["clearances", 2, "restitution"]``."""
    keys: list[str | int] = []
    parts = path.split(".") if path else []
    for part in parts:
        match = _SEGMENT.fullmatch(part)
        if match is None:
            raise InputError("--set", path, "a dotted preset path such as run.rpm or clearances[2].restitution")
        keys.append(match[1])
        keys += [int(i) for i in re.findall(r"\[(\d+)\]", match[2])]
    if not keys:
        raise InputError("--set", path, "a dotted preset path such as run.rpm or clearances[2].restitution")
    return keys


def _shown(keys: list[str | int]) -> str:
    text = ""
    for key in keys:
        text += f"[{key}]" if isinstance(key, int) else (f".{key}" if text else key)
    return text


def get_field(doc: dict[str, Any], path: str) -> Any:
    """The value at ``path`` (``None`` when the last key is absent)."""
    keys = parse_path(path)
    parent = _parent(doc, keys)
    last = keys[-1]
    if isinstance(last, int):
        return parent[last]
    return parent.get(last)


def _parent(doc: dict[str, Any], keys: list[str | int]) -> Any:
    node: Any = doc
    for depth, key in enumerate(keys[:-1]):
        where = _shown(keys[: depth + 1])
        if isinstance(key, int):
            if not isinstance(node, list) or not 0 <= key < len(node):
                size = len(node) if isinstance(node, list) else 0
                raise InputError(where, key, f"an index 0..{size - 1} of the preset's entries" if size
                                 else "an existing array of tables")
            node = node[key]
        else:
            if not isinstance(node, dict) or key not in node:
                raise InputError(where, None, "a table or array present in the preset")
            node = node[key]
    last = keys[-1]
    if isinstance(last, int):
        if not isinstance(node, list) or not 0 <= last < len(node):
            raise InputError(_shown(keys), last, "an existing entry of the preset's array")
    elif not isinstance(node, dict):
        raise InputError(_shown(keys[:-1]), None, "a table (a field can only be set inside a table)")
    return node


def set_field(doc: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    """A deep copy of ``doc`` with ``path`` set to ``value`` (see the module doc)."""
    result = copy.deepcopy(doc)
    keys = parse_path(path)
    _parent(result, keys)[keys[-1]] = value
    return result


def set_fields(doc: dict[str, Any], assignments: dict[str, Any]) -> dict[str, Any]:
    """``doc`` with several paths set (one deep copy)."""
    result = copy.deepcopy(doc)
    for path, value in assignments.items():
        keys = parse_path(path)
        _parent(result, keys)[keys[-1]] = value
    return result


def _scalar(text: str) -> Any:
    """A number when the text is one (int if written as an integer), else the stripped text."""
    text = text.strip()
    if re.fullmatch(r"[+-]?\d+", text):
        return int(text)
    try:
        return float(text)
    except ValueError:
        pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text


def parse_values(field: str, text: str, max_points: int = 100_000) -> list[Any]:
    """Values of ``start:stop:step`` (stop included when reached) or ``a,b,c``."""
    where = f"--set {field}"
    if ":" in text:
        parts = text.split(":")
        numbers = [_scalar(p) for p in parts]
        if len(parts) != 3 or any(isinstance(n, bool) or not isinstance(n, int | float) for n in numbers):
            raise InputError(where, text, "start:stop:step with three numbers")
        start, stop, step = numbers
        if not all(math.isfinite(n) for n in numbers):
            raise InputError(where, text, "finite start, stop and step")
        if step == 0:
            raise InputError(where, text, "a step other than 0")
        if (stop - start) * step < 0:
            raise InputError(where, text, f"a step with the sign of stop - start ({'+' if stop > start else '-'})")
        count = int(math.floor((stop - start) / step * (1 + 1e-12) + 1e-9)) + 1
        if count > max_points:
            raise InputError(where, text, f"at most {max_points} values (this range has {count})")
        if all(isinstance(n, int) for n in numbers):
            return [start + i * step for i in range(count)]
        return [float(f"{start + i * step:.12g}") for i in range(count)]
    values = [_scalar(p) for p in text.split(",") if p.strip()]
    if not values:
        raise InputError(where, text, "a non-empty list a,b,c or a range start:stop:step")
    return values


def field_unit(doc: dict[str, Any], path: str, folder: Path | None = None) -> str:
    """The unit the loader states for ``path`` (asked by offering it a non-number), or ``""``."""
    from vtool.presets import load_document

    try:
        load_document(set_field(doc, path, "?"), folder)
    except InputError as exc:
        if exc.field == path:
            return exc.unit
    return ""


class SweepCancelled(Exception):
    """:func:`plan_sweep` stopped because its ``cancel`` said so (nothing was planned)."""


def parse_assignments(sets: list[str] | tuple[str, ...], max_points: int = 100_000) -> list[tuple[str, list[Any]]]:
    """``FIELD=VALUES`` texts (``--set`` of ``vtool sweep`` and ``vtool solve``) -> (path, values), in order;
    each field once."""
    fields: list[tuple[str, list[Any]]] = []
    for text in sets:
        path, sep, values = text.partition("=")
        path = path.strip()
        if not sep or not path:
            raise InputError("--set", text, "FIELD=VALUES, e.g. run.rpm=9000:12000:250 or damping.factor=0.5,1,2")
        if any(path == p for p, _ in fields):
            raise InputError("--set", path, "each field set once")
        parse_path(path)
        fields.append((path, parse_values(path, values, max_points)))
    return fields


def apply_sets(doc: dict[str, Any], sets: list[str] | tuple[str, ...]) -> dict[str, Any]:
    """``doc`` with ``FIELD=VALUE`` assignments (one value each: ``vtool solve --set``, the same paths and
    values as a sweep's, a single point); the preset's loader then checks them."""
    assignments = {}
    for path, values in parse_assignments(sets, max_points=1_000):
        if len(values) != 1:
            raise InputError(f"--set {path}", ",".join(str(v) for v in values),
                             "one value (a range or list is a sweep: vtool sweep)")
        assignments[path] = values[0]
    return set_fields(doc, assignments)


@dataclass(frozen=True)
class SweepPlan:
    """A validated sweep: the base document and spec, the swept fields with units, every point."""

    doc: dict[str, Any]
    spec: Any
    fields: tuple[tuple[str, str], ...]  # (path, unit)
    points: tuple[Any, ...]  # vtool.solvers.studies.sweep.Point


def plan_sweep(preset: str, sets: list[str], max_points: int = 100_000, *,
               progress: Callable[[int, int], None] | None = None,
               cancel: Callable[[], bool] | None = None) -> SweepPlan:
    """Parse ``FIELD=VALUES`` assignments and validate every grid point with the preset loader.

    Nothing runs: a bad field, range or value raises the loader's own one-line
    InputError before any work starts. Validating a point costs about 10 ms, so a
    large grid takes minutes: ``progress(done, total)`` is called as points are
    checked and ``cancel()`` between them (True raises :class:`SweepCancelled`).
    """
    from vtool.presets import find_preset, load_document, read_document
    from vtool.presets.kinds import require_kind

    folder = find_preset(preset).parent
    doc = read_document(find_preset(preset))
    require_kind(load_document(doc, folder), "valvetrain", "a sweep")
    fields = parse_assignments(sets, max_points)
    return plan_document(doc, fields, max_points, folder, progress=progress, cancel=cancel)


def plan_document(doc: dict[str, Any], fields: list[tuple[str, list[Any]]], max_points: int = 100_000,
                  folder: Path | None = None, *, progress: Callable[[int, int], None] | None = None,
                  cancel: Callable[[], bool] | None = None) -> SweepPlan:
    """:func:`plan_sweep` for a parsed valvetrain document and (path, values) pairs (the Python API's sweep).

    ``folder`` resolves a file the document names (a cam lift table) as :func:`vtool.presets.load_document`.
    """
    from vtool.presets import load_document
    from vtool.presets.kinds import require_kind
    from vtool.solvers.studies.sweep import Point, grid

    spec = load_document(doc, folder)
    require_kind(spec, "valvetrain", "a sweep")
    count = math.prod(len(v) for _, v in fields)
    if count > max_points:
        raise InputError("--set", count, f"a grid of at most {max_points} points")
    points = []
    for index, assignment in enumerate(grid(fields)):
        if cancel is not None and cancel():
            raise SweepCancelled
        points.append(Point(index, assignment, load_document(set_fields(doc, dict(assignment)), folder)))
        if progress is not None:
            progress(index + 1, count)
    units = tuple((path, field_unit(doc, path, folder)) for path, _ in fields)
    return SweepPlan(doc, spec, units, tuple(points))
