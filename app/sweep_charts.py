"""Charts of a sweep as text: a metric against the first swept field, and a character map for two fields.

``fields`` are the chart's axes, (path, unit) of the swept fields that take
more than one value (fields set to a single value are fixed settings). The
series are :mod:`vtool.presets.charts`' (the same that ``--figure`` draws).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from vtool.app.plots import chart_text
from vtool.presets.charts import sweep_chart, sweep_map
from vtool.solvers.studies.orders import Campbell
from vtool.solvers.studies.sweep import PointResult, format_value

SHADES = " .:-=+*#%@"
DECADES = 3  # the Campbell map's shades span this many decades of amplitude


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


def campbell_map(data: Campbell, *, highest: int | None = None) -> str:
    """A Campbell (waterfall) map as characters: cam order up (1 at the bottom), cam speed across, each cell
    shaded by the order's amplitude on a log scale (decades below the largest), and 'o' where a natural
    frequency meets that order at that speed (order = f_n 60 / rpm)."""
    amplitude = data.amplitude[: highest or len(data.amplitude)]
    finite = amplitude[np.isfinite(amplitude) & (amplitude > 0)]
    top = float(finite.max()) if finite.size else 1.0
    levels = len(SHADES) - 1  # the shades span DECADES decades below the largest
    lines = [f"{data.quantity}: amplitude per cam order and speed (log shades over {DECADES} decades: "
             f"'{SHADES[-1]}' = {top:.4g} {data.unit}, '{SHADES[1]}' = {top / 10**DECADES:.3g} and below; "
             "'o' a natural frequency)", "cam order up, run.rpm across"]
    marks = np.zeros(amplitude.shape, dtype=bool)
    for _, hz in data.frequencies:
        order = np.rint(data.line(hz)).astype(int)
        for j, k in enumerate(order):
            if 1 <= k <= len(amplitude):
                marks[k - 1, j] = True
    for k in reversed(range(len(amplitude))):
        cells = []
        for j, v in enumerate(amplitude[k]):
            if marks[k, j]:
                cells.append("o")
            elif not math.isfinite(v):
                cells.append("?")
            else:
                level = levels * (1 + math.log10(v / top) / DECADES) if v > 0 else 1.0
                cells.append(SHADES[max(1, min(levels, int(math.floor(level))))])
        lines.append(f"{k + 1:>5} |{''.join(c * 2 for c in cells)}|")
    lines.append(f"{'':>5}  {data.rpm[0]:g} ... {data.rpm[-1]:g} rev/min")
    lines.append("natural frequencies: " + ", ".join(f"{hz:.0f} Hz ({label})" for label, hz in data.frequencies))
    return "\n".join(lines)

