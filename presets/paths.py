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
import functools
import math
import re
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
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


@dataclass(frozen=True)
class ValueRange(Sequence[Any]):
    """The values of ``start:stop:step``, made on demand: three numbers whatever the count.

    Value ``i`` is ``start + i * step`` when start and step are both integers, else that sum rounded to 12
    significant digits (``float(f"{start + i * step:.12g}")``, so that ``0.1:0.3:0.1`` gives 0.3 and not
    0.30000000000000004). The values are monotonic in ``i`` (the sum, the rounding and the decimal text of
    each are), which :meth:`index_of` uses to find a value from its text by bisection.
    """

    start: int | float
    step: int | float
    size: int  # how many values

    def __len__(self) -> int:
        return self.size

    def _value(self, i: int) -> Any:
        if isinstance(self.start, int) and isinstance(self.step, int):
            return self.start + i * self.step
        return float(f"{self.start + i * self.step:.12g}")

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return [self._value(i) for i in range(*index.indices(self.size))]
        if not -self.size <= index < self.size:
            raise IndexError(index)
        return self._value(index % self.size)

    def __iter__(self) -> Iterator[Any]:
        return (self._value(i) for i in range(self.size))

    def extremes(self) -> tuple[Any, Any]:
        """(first, last): also the smallest and largest, in some order (the values are monotonic)."""
        return self._value(0), self._value(self.size - 1)

    def index_of(self, text: str, shown: Callable[[Any], str]) -> int | None:
        """The first ``i`` whose value ``shown`` writes as ``text`` (None: no such value).

        ``shown`` (a sweep file's number format) must be monotonic as the values are: the number it writes
        is found by bisection, then its text compared."""
        try:
            wanted = float(text)
        except ValueError:
            return None
        sign = 1 if self.step > 0 else -1
        low, high = 0, self.size  # the first i whose shown number is >= wanted (<= for a falling range)
        while low < high:
            mid = (low + high) // 2
            if sign * float(shown(self._value(mid))) < sign * wanted:
                low = mid + 1
            else:
                high = mid
        return low if low < self.size and shown(self._value(low)) == text else None


def parse_values(field: str, text: str, max_points: int = 100_000) -> Sequence[Any]:
    """Values of ``start:stop:step`` (stop included when reached: a :class:`ValueRange`) or ``a,b,c`` (a list)."""
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
        # counted on the typed decimals: in floats, 10935.322:10935.326:0.001 lost its stop to round-off
        try:
            exact = [Decimal(p.strip()) for p in parts]
        except InvalidOperation:
            raise InputError(where, text, "start:stop:step with three numbers") from None
        count = int(math.floor((exact[1] - exact[0]) / exact[2] * (1 + Decimal("1e-12")) + Decimal("1e-9"))) + 1
        if count > max_points:
            raise InputError(where, text, f"at most {max_points} values (this range has {count})")
        return ValueRange(start, step, count)
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


def parse_assignments(sets: list[str] | tuple[str, ...],
                      max_points: int = 100_000) -> list[tuple[str, Sequence[Any]]]:
    """``FIELD=VALUES`` texts (``--set`` of ``vtool sweep`` and ``vtool solve``) -> (path, values), in order;
    each field once."""
    fields: list[tuple[str, Sequence[Any]]] = []
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


#: A swept field's values are all checked up front when it has at most this many (a typed list); a longer
#: one (a range) has its first and last value checked, and its smallest and largest when they differ.
CHECK_ALL_VALUES = 100
#: Most corner points (each field at its first or last value) checked up front.
MAX_CORNERS = 64


@dataclass(frozen=True)
class SpecMaker:
    """A point's spec from its swept values: the loader on the base document with them set, then the plan's
    study settings (``orders``: order amplitudes as metrics, ``steady``: run to steady state).

    Picklable (a plain document and settings), so that a sweep's worker process makes its points' specs
    itself; a value the loader refuses raises its own one-line InputError (the point's status, its
    metrics the columns of ``base``, the plan's spec)."""

    doc: dict[str, Any]
    folder: Path | None = None
    base: Any = None
    orders: tuple[str, ...] = ()
    steady: bool = False

    def __call__(self, values: tuple[tuple[str, Any], ...]) -> Any:
        from vtool.presets import load_document

        return self.settle(load_document(set_fields(self.doc, dict(values)), self.folder))

    def settle(self, spec: Any) -> Any:
        """``spec`` with the plan's study settings."""
        from vtool.solvers.studies.orders import with_orders
        from vtool.solvers.studies.steady import with_steady

        spec = with_orders(spec, self.orders) if self.orders else spec
        return with_steady(spec) if self.steady else spec


class PointGrid(Sequence[Any]):
    """The grid of a sweep's points, made on demand: nothing per point is kept.

    ``grid[i]`` is :class:`vtool.solvers.studies.sweep.Point` ``i`` (in
    :func:`vtool.solvers.studies.sweep.grid`'s order, the first field varying
    fastest) with its spec made and checked now; :meth:`lazy` gives it without
    the spec, which the evaluation makes (a worker process makes its own).
    :meth:`run_order` lists the indices with the ``run.*`` fields varying
    fastest, so that neighbouring points share an assembled model; :meth:`locate`
    finds a point's index from its values as a sweep file writes them.
    """

    def __init__(self, fields: Sequence[tuple[str, Sequence[Any]]], maker: SpecMaker) -> None:
        self.fields: list[tuple[str, Sequence[Any]]] = [
            (path, values if isinstance(values, ValueRange) else list(values)) for path, values in fields]
        self.maker = maker
        self.sizes = [len(values) for _, values in self.fields]
        self.strides = [math.prod(self.sizes[:k]) for k in range(len(self.sizes))]
        self.total = math.prod(self.sizes)
        self._positions: list[Callable[[str], int | None]] | None = None

    def __len__(self) -> int:
        return self.total

    def values(self, index: int) -> tuple[tuple[str, Any], ...]:
        """The swept values of point ``index``, in the fields' order."""
        return tuple((path, values[(index // stride) % size]) for (path, values), stride, size
                     in zip(self.fields, self.strides, self.sizes, strict=True))

    def lazy(self, index: int) -> Any:
        """Point ``index`` without its spec (``make`` makes it when the point is evaluated)."""
        from vtool.solvers.studies.sweep import Point

        return Point(index, self.values(index), None, self.maker)

    def __getitem__(self, index: Any) -> Any:
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(self.total))]
        if not -self.total <= index < self.total:
            raise IndexError(index)
        from vtool.solvers.studies.sweep import Point

        index %= self.total
        values = self.values(index)
        return Point(index, values, self.maker(values))

    def __iter__(self) -> Iterator[Any]:
        return (self[i] for i in range(self.total))

    def run_order(self) -> Iterator[int]:
        """Every index once, the ``run.*`` fields varying fastest (then the grid's own order)."""
        axes = sorted(range(len(self.fields)), key=lambda k: not self.fields[k][0].startswith("run."))
        for flat in range(self.total):
            index = 0
            for k in axes:
                index += (flat % self.sizes[k]) * self.strides[k]
                flat //= self.sizes[k]
            yield index

    def locate(self, texts: Sequence[str]) -> int | None:
        """The index of the point whose values a sweep file writes as ``texts`` (None: not in this grid)."""
        from vtool.solvers.studies.sweep import format_value

        if self._positions is None:  # a range finds its value by bisection; a typed list has a table
            self._positions = [functools.partial(values.index_of, shown=format_value)
                               if isinstance(values, ValueRange)
                               else {format_value(v): i for i, v in reversed(list(enumerate(values)))}.get
                               for _, values in self.fields]
        if len(texts) != len(self.fields):
            return None
        index = 0
        for text, position, stride in zip(texts, self._positions, self.strides, strict=True):
            found = position(text)
            if found is None:
                return None
            index += found * stride
        return index

    def axes(self) -> list[str]:
        """The swept fields with more than one distinct value."""
        return [path for path, values in self.fields
                if (len(set(map(repr, values))) if not isinstance(values, ValueRange)
                    else 1 + (repr(values[0]) != repr(values[-1]))) > 1]  # a range is monotonic

    def checked_values(self) -> Iterator[tuple[tuple[str, Any], ...]]:
        """The points checked before a sweep runs: each field's values (a long range: its ends and extremes)
        with the other fields at their first value, then the corners (each field at its first or last value)."""
        firsts = {path: values[0] for path, values in self.fields}
        seen: set[str] = set()

        def point(assignment: dict[str, Any]) -> tuple[tuple[str, Any], ...] | None:
            values = tuple((path, assignment[path]) for path, _ in self.fields)
            key = repr(values)
            if key in seen:
                return None
            seen.add(key)
            return values

        for path, values in self.fields:
            for value in _checked(values):
                found = point(firsts | {path: value})
                if found is not None:
                    yield found
        ends = [(values[0], values[-1]) for _, values in self.fields]
        for corner in range(min(2 ** len(ends), MAX_CORNERS)):
            found = point({path: pair[(corner >> k) & 1] for k, ((path, _), pair)
                           in enumerate(zip(self.fields, ends, strict=True))})
            if found is not None:
                yield found


def _checked(values: Sequence[Any]) -> list[Any]:
    """A field's values checked up front (see :data:`CHECK_ALL_VALUES`)."""
    if len(values) <= CHECK_ALL_VALUES:
        return list(values)
    if isinstance(values, ValueRange):  # monotonic: its ends are its extremes
        return list(values.extremes())
    chosen = [values[0], values[-1]]
    if all(isinstance(v, int | float) and not isinstance(v, bool) for v in (values[0], values[-1])):
        numbers = [v for v in values if isinstance(v, int | float) and not isinstance(v, bool)]
        chosen += [min(numbers), max(numbers)]
    return chosen


@dataclass(frozen=True)
class SweepPlan:
    """A checked sweep: the base document and spec, the swept fields with units, the points (made on demand).

    ``points`` is a :class:`PointGrid`: a sequence of
    :class:`vtool.solvers.studies.sweep.Point` that keeps nothing per point.
    """

    doc: dict[str, Any]
    spec: Any
    fields: tuple[tuple[str, str], ...]  # (path, unit)
    points: PointGrid

    def with_settings(self, orders: tuple[str, ...] = (), steady: bool = False) -> SweepPlan:
        """The plan with every point (and its base spec) reporting ``orders``' amplitudes and run to steady
        state when ``steady``."""
        from dataclasses import replace

        maker = replace(self.points.maker, orders=self.points.maker.orders + tuple(orders),
                        steady=self.points.maker.steady or steady)
        spec = maker.settle(self.spec)
        return replace(self, spec=spec, points=PointGrid(self.points.fields, replace(maker, base=spec)))


def plan_sweep(preset: str, sets: list[str], max_points: int = 100_000, *,
               progress: Callable[[int, int], None] | None = None,
               cancel: Callable[[], bool] | None = None) -> SweepPlan:
    """Parse ``FIELD=VALUES`` assignments and check them with the preset loader; nothing runs.

    A bad field, range or value raises the loader's own one-line InputError
    before any work starts: every value of a typed list, a range's ends (and
    extremes) and the grid's corners are checked (:meth:`PointGrid.checked_values`),
    about 10 ms each; ``progress(done, total)`` is called as they are and ``cancel()``
    between them (True raises :class:`SweepCancelled`). Every other point is made
    and checked when it runs: one the loader refuses there (a combination of
    values no single field shows) is a failed point whose status is the loader's message.
    """
    from vtool.presets import find_preset, load_document, read_document
    from vtool.presets.kinds import require_kind

    folder = find_preset(preset).parent
    doc = read_document(find_preset(preset))
    require_kind(load_document(doc, folder), "valvetrain", "a sweep")
    fields = parse_assignments(sets, max_points)
    return plan_document(doc, fields, max_points, folder, progress=progress, cancel=cancel)


def plan_document(doc: dict[str, Any], fields: Sequence[tuple[str, Sequence[Any]]], max_points: int = 100_000,
                  folder: Path | None = None, *, progress: Callable[[int, int], None] | None = None,
                  cancel: Callable[[], bool] | None = None) -> SweepPlan:
    """:func:`plan_sweep` for a parsed valvetrain document and (path, values) pairs (the Python API's sweep).

    ``folder`` resolves a file the document names (a cam lift table) as :func:`vtool.presets.load_document`.
    """
    from vtool.presets import load_document
    from vtool.presets.kinds import require_kind

    spec = load_document(doc, folder)
    require_kind(spec, "valvetrain", "a sweep")
    count = math.prod(len(v) for _, v in fields)
    if count > max_points:
        raise InputError("--set", count, f"a grid of at most {max_points} points")
    points = PointGrid(fields, SpecMaker(doc, folder, spec))
    checks = list(points.checked_values())
    for done, values in enumerate(checks, start=1):
        if cancel is not None and cancel():
            raise SweepCancelled
        points.maker(values)
        if progress is not None:
            progress(done, len(checks))
    units = tuple((path, field_unit(doc, path, folder)) for path, _ in fields)
    return SweepPlan(doc, spec, units, points)
