"""Charts of a sweep: a metric against the first swept field, and a character map for two fields.

``fields`` are the chart's axes, (path, unit) of the swept fields that take
more than one value (fields set to a single value are fixed settings).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from vtool.app.plots import line_chart
from vtool.solvers.studies.sweep import PointResult, format_value

SHADES = " .:-=+*#%@"


def _key(result: PointResult, fields: Sequence[tuple[str, str]]) -> tuple:
    values = dict(result.values)
    return tuple(values[path] for path, _ in fields[:2])


def _axes(results: Sequence[PointResult], fields: Sequence[tuple[str, str]]) -> tuple[list, list]:
    """Distinct values of the first and second chart fields, in grid order."""
    first: list = []
    second: list = []
    for r in results:
        values = _key(r, fields)
        if values[0] not in first:
            first.append(values[0])
        if len(values) > 1 and values[1] not in second:
            second.append(values[1])
    return first, second


def _lookup(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], metric: str) -> dict[tuple, float]:
    return {_key(r, fields): float(r.metrics[metric]) for r in results}


def metric_chart(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], metric: str, unit: str,
                 *, width: int = 100, height: int = 22, color: bool = True) -> str:
    """``metric`` against the first swept field, one line per value of the second (NaN: gaps)."""
    first, second = _axes(results, fields)
    table = _lookup(results, fields, metric)
    x_path, x_unit = fields[0]
    series = {}
    for value in second or [None]:
        label = metric if value is None else f"{fields[1][0]} = {format_value(value)}"
        series[label] = [table.get((x,) if value is None else (x, value), math.nan) for x in first]
    xs = [float(x) for x in first]
    return line_chart(xs, series, title=f"{metric} ({unit})" if unit else metric,
                      xlabel=f"{x_path} ({x_unit})" if x_unit else x_path, ylabel=unit,
                      width=width, height=height, color=color)


def metric_map(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], metric: str, unit: str) -> str:
    """A character heat map of ``metric`` over two swept fields (rows: second field, columns: first).

    Shades run from the smallest value (' ') to the largest ('@'); a failed or
    undefined point is '?'. The scale is printed below the map.
    """
    if len(fields) < 2:
        raise ValueError("a map needs two swept fields")
    first, second = _axes(results, fields)
    table = _lookup(results, fields, metric)
    finite = [v for v in table.values() if math.isfinite(v)]
    low, high = (min(finite), max(finite)) if finite else (0.0, 0.0)
    label_width = max(len(format_value(v)) for v in second)
    def named(path: str, field_unit: str) -> str:
        return f"{path} ({field_unit})" if field_unit else path

    lines = [named(metric, unit), f"{named(*fields[1])} down, {named(*fields[0])} across"]
    for y in reversed(second):
        cells = []
        for x in first:
            v = table.get((x, y), math.nan)
            if not math.isfinite(v):
                cells.append("?")
            elif high == low:
                cells.append(SHADES[-1] if v else SHADES[0])
            else:
                cells.append(SHADES[min(int((v - low) / (high - low) * len(SHADES)), len(SHADES) - 1)])
        lines.append(f"{format_value(y):>{label_width}} |{''.join(c * 2 for c in cells)}|")
    lines.append(f"{'':>{label_width}}  {format_value(first[0])} ... {format_value(first[-1])}")
    lines.append(f"scale: '{SHADES[0]}' = {low:.4g} ... '{SHADES[-1]}' = {high:.4g} {unit}; '?' = none / failed")
    return "\n".join(lines)
