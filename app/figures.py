"""Report-grade figures with matplotlib: the only module in vtool that imports matplotlib.

Every figure draws :class:`vtool.chart.Chart` / :class:`vtool.chart.HeatMap`
data, the same series the terminal charts draw (:mod:`vtool.presets.charts`).
Choices, written down here because the issue left them open:

- No pyplot: each figure is a :class:`matplotlib.figure.Figure` rendered by
  the Agg canvas (PNG), or matplotlib's SVG and PDF back ends, chosen by the
  output file's suffix (``.png``, ``.svg``, ``.pdf``). Nothing global is set,
  so a user's notebook backend is left alone and threads may draw at once.
- One file per command: its charts are stacked top to bottom (a chart's
  panels share the x axis); the preset's title heads the figure, each
  chart's title its first panel.
- Readable in black and white: curves differ by line style and marker
  (black and greys), events are symbols on the bottom edge of a panel (a
  downward triangle for separations, an x for impacts), heat maps are grey.
- PNG at 150 dpi (the resolution of the EXCITE study's deliverable); SVG
  keeps text as text (searchable, selectable) and carries no date, so a
  docs figure regenerates byte for byte.
- Files are written through :mod:`vtool.files` (a temporary file renamed
  over the target): a failed or interrupted write leaves nothing half-written.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from vtool.chart import Chart, HeatMap
from vtool.errors import InputError

FORMATS = ("png", "svg", "pdf")
DPI = 150
WIDTH_IN = 7.5
PANEL_IN = 2.1
CHART_EXTRA_IN = 0.7

COLORS = ("black", "0.45", "0.25", "0.6")
STYLES = ("-", "--", "-.", ":")
MARKERS = ("", "o", "s", "^", "D", "+", "*")  # 7 against 4 line styles: 28 curves look different
EVENT_MARKERS = {"separation": "v", "impact": "x"}

Drawable = Chart | HeatMap


def figure_format(path: str | Path, field: str = "--figure") -> str:
    """The format a figure path asks for by its suffix, or a one-line InputError."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise InputError(field, str(path), "a file ending in .png, .svg or .pdf")
    return suffix


def check_figure_path(path: str | Path, field: str = "--figure") -> Path:
    """``path`` if a figure may be written there (suffix and folder checked before any work)."""
    from vtool.files import check_output_path

    figure_format(path, field)
    check_output_path(path, field)
    return Path(path)


def _style(k: int, n_points: int) -> dict[str, Any]:
    marker = MARKERS[k % len(MARKERS)]
    return {"color": COLORS[k % len(COLORS)], "linestyle": STYLES[k % len(STYLES)], "marker": marker or None,
            "markevery": max(1, n_points // 12), "markersize": 4, "linewidth": 1.1}


def _draw_chart(subfigure: Any, chart: Chart) -> None:
    axes = subfigure.subplots(len(chart.panels), 1, sharex=True, squeeze=False)[:, 0]
    for number, (ax, panel) in enumerate(zip(axes, chart.panels, strict=True)):
        for k, c in enumerate(panel.curves):
            style = _style(k, len(c.x))
            if c.step:
                ax.step(c.x, c.y, where="post", label=c.label, **style)
            else:
                ax.plot(c.x, c.y, label=c.label, **style)
        for mark in chart.marks:
            if mark.panel == number and len(mark.x):
                ax.plot(mark.x, np.full(len(mark.x), 0.03), linestyle="none", color="black", markersize=5,
                        marker=EVENT_MARKERS.get(mark.label, "|"), label=f"{mark.label} ({len(mark.x)})",
                        transform=ax.get_xaxis_transform(), clip_on=False)
        ax.set_ylabel(panel.ylabel)
        if panel.ylim is not None:
            ax.set_ylim(*panel.ylim)
        if panel.yticks is not None:
            ax.set_yticks(list(panel.yticks[0]), list(panel.yticks[1]))
        if chart.xlog:
            ax.set_xscale("log")
        if chart.xlim is not None:
            ax.set_xlim(*chart.xlim)
        ax.grid(True, color="0.85", linewidth=0.5)
        if len(panel.curves) > 1 or any(m.panel == number for m in chart.marks) or (
                panel.curves and panel.yticks is None and panel.curves[0].label not in ("", panel.ylabel)):
            ax.legend(fontsize="x-small", loc="best", framealpha=0.8)
    axes[0].set_title(chart.title, fontsize="medium")
    axes[-1].set_xlabel(chart.xlabel)


def _draw_map(subfigure: Any, heat: HeatMap) -> None:
    ax = subfigure.subplots(1, 1)
    numeric = all(np.issubdtype(np.asarray(v).dtype, np.number) for v in (heat.x, heat.y))
    xs = np.asarray(heat.x, dtype=float) if numeric else np.arange(len(heat.x), dtype=float)
    ys = np.asarray(heat.y, dtype=float) if numeric else np.arange(len(heat.y), dtype=float)
    values = np.ma.masked_invalid(np.asarray(heat.values, dtype=float))
    mesh = ax.pcolormesh(xs, ys, values, cmap="Greys", shading="nearest")
    subfigure.colorbar(mesh, ax=ax, label=heat.zlabel)
    if not numeric:
        ax.set_xticks(xs, [str(v) for v in heat.x])
        ax.set_yticks(ys, [str(v) for v in heat.y])
    ax.set_facecolor("white")
    ax.set_xlabel(heat.xlabel)
    ax.set_ylabel(heat.ylabel)
    blank = " (blank: no value / failed)" if np.ma.count_masked(values) else ""
    ax.set_title(f"{heat.title}{blank}", fontsize="medium")


def build_figure(items: Sequence[Drawable]) -> Any:
    """One :class:`matplotlib.figure.Figure` with every chart and map stacked (see the module doc)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if not items:
        raise ValueError("a figure needs at least one chart")
    heights = [PANEL_IN * (len(i.panels) if isinstance(i, Chart) else 1.6) + CHART_EXTRA_IN for i in items]
    figure = Figure(figsize=(WIDTH_IN, sum(heights) + 0.4), layout="constrained")
    FigureCanvasAgg(figure)
    subfigures = figure.subfigures(len(items), 1, height_ratios=heights, squeeze=False)[:, 0]
    for subfigure, item in zip(subfigures, items, strict=True):
        (_draw_map if isinstance(item, HeatMap) else _draw_chart)(subfigure, item)
    subject = next((i.subject for i in items if i.subject), "")
    if subject:
        figure.suptitle(subject, fontsize="large")
    return figure


def _save_options(fmt: str) -> dict[str, Any]:
    metadata = {"png": {"Software": None}, "svg": {"Date": None}, "pdf": {"CreationDate": None}}[fmt]
    return {"format": fmt, "dpi": DPI, "metadata": metadata}


def figure_bytes(figure: Any, fmt: str) -> bytes:
    """The figure rendered as PNG, SVG (text kept as text) or PDF."""
    import matplotlib

    buffer = io.BytesIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "vtool"}):
        figure.savefig(buffer, **_save_options(fmt))
    return buffer.getvalue()


def save_figure(items: Sequence[Drawable], path: str | Path, field: str = "--figure") -> Path:
    """Draw ``items`` and write them to ``path`` (format by suffix), atomically."""
    from vtool.files import write_atomic_bytes

    fmt = figure_format(path, field)
    write_atomic_bytes(path, figure_bytes(build_figure(items), fmt), field)
    return Path(path)


def svg_text(items: Sequence[Drawable]) -> str:
    """The figure as SVG markup (for inline use in an HTML report)."""
    return figure_bytes(build_figure(items), "svg").decode("utf-8")
