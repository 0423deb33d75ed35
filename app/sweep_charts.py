"""Charts of a sweep as text: a metric against the first swept field, and a character map for two fields.

``fields`` are the chart's axes, (path, unit) of the swept fields that take
more than one value (fields set to a single value are fixed settings). The
series are :mod:`vtool.presets.charts`' (the same that ``--figure`` draws).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from vtool.app.plots import chart_text
from vtool.presets.charts import sweep_chart, sweep_map
from vtool.solvers.studies.sweep import PointResult, format_value

SHADES = " .:-=+*#%@"


def metric_chart(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], metric: str, unit: str,
                 *, width: int = 100, height: int = 22, color: bool = True) -> str:
    """``metric`` against the first swept field, one line per value of the second (NaN: gaps)."""
    return chart_text(sweep_chart(results, fields, metric, unit), width=width, height=height, color=color)


def metric_map(results: Sequence[PointResult], fields: Sequence[tuple[str, str]], metric: str, unit: str) -> str:
    """A character heat map of ``metric`` over two swept fields (rows: second field, columns: first).

    Shades run from the smallest value (' ') to the largest ('@'); a failed or
    undefined point is '?'. The scale is printed below the map.
    """
    heat = sweep_map(results, fields, metric, unit)
    finite = [float(v) for v in heat.values.ravel() if math.isfinite(v)]
    low, high = (min(finite), max(finite)) if finite else (0.0, 0.0)
    label_width = max(len(format_value(v)) for v in heat.y)
    lines = [heat.zlabel, f"{heat.ylabel} down, {heat.xlabel} across"]
    for j in reversed(range(len(heat.y))):
        cells = []
        for v in heat.values[j]:
            if not math.isfinite(v):
                cells.append("?")
            elif high == low:
                cells.append(SHADES[-1] if v else SHADES[0])
            else:
                cells.append(SHADES[min(int((v - low) / (high - low) * len(SHADES)), len(SHADES) - 1)])
        lines.append(f"{format_value(heat.y[j]):>{label_width}} |{''.join(c * 2 for c in cells)}|")
    lines.append(f"{'':>{label_width}}  {format_value(heat.x[0])} ... {format_value(heat.x[-1])}")
    lines.append(f"scale: '{SHADES[0]}' = {low:.4g} ... '{SHADES[-1]}' = {high:.4g} {unit}; '?' = none / failed")
    return "\n".join(lines)
