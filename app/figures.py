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
from collections.abc import Iterable, Sequence
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


def output_format(path: str | Path, field: str, formats: Sequence[str] = FORMATS) -> str:
    """The format an output path asks for by its suffix (one of ``formats``), or a one-line InputError."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in formats:
        names = [f".{f}" for f in formats]
        raise InputError(field, str(path), f"a file ending in {', '.join(names[:-1])} or {names[-1]}")
    return suffix


def check_output(path: str | Path, field: str, formats: Sequence[str] = FORMATS) -> Path:
    """``path`` if a file of one of ``formats`` may be written there (suffix and folder checked before
    any work is done)."""
    from vtool.files import check_output_path

    output_format(path, field, formats)
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
    if heat.lines and numeric:  # black lines in a white halo, each its own dash and marker: legible on any grey
        from matplotlib import patheffects

        halo = [patheffects.withStroke(linewidth=3.2, foreground="white")]
        for k, line in enumerate(heat.lines):
            style = _style(k, len(line.x)) | {"color": "black"}
            ax.plot(line.x, line.y, label=line.label, path_effects=halo, **style)
        step = [float(np.min(np.diff(v))) / 2 if len(v) > 1 else 0.5 for v in (xs, ys)]
        ax.set_xlim(xs.min() - step[0], xs.max() + step[0])  # the map's extent: a line leaves it at its edge
        ax.set_ylim(ys.min() - step[1], ys.max() + step[1])
        ax.legend(fontsize="x-small", loc="upper right", framealpha=0.8, title="natural frequencies",
                  title_fontsize="x-small")
    ax.set_xlabel(heat.xlabel)
    ax.set_ylabel(heat.ylabel)
    blank = " (blank: no value / failed)" if np.ma.count_masked(values) else ""
    ax.set_title(f"{heat.title}{blank}", fontsize="medium")


def build_figure(items: Sequence[Drawable], caption: str = "") -> Any:
    """One :class:`matplotlib.figure.Figure` with every chart and map stacked (see the module doc),
    and a caption under them when given."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    if not items:
        raise ValueError("a figure needs at least one chart")
    heights = [PANEL_IN * (len(i.panels) if isinstance(i, Chart) else 1.6) + CHART_EXTRA_IN for i in items]
    figure = Figure(figsize=(WIDTH_IN, sum(heights) + 0.4), layout="constrained")
    FigureCanvasAgg(figure)
    subfigures = figure.subfigures(len(items), 1, height_ratios=heights, squeeze=False)[:, 0]
    for subfigure, item in zip(subfigures, items, strict=True):
        if isinstance(item, HeatMap):
            _draw_map(subfigure, item)
        else:
            _draw_chart(subfigure, item)
    subject = next((i.subject for i in items if i.subject), "")
    if subject:
        figure.suptitle(subject, fontsize="large")
    if caption:
        figure.supxlabel(caption, fontsize="small", style="italic")
    return figure


def _save_options(fmt: str, dpi: float) -> dict[str, Any]:
    metadata = {"png": {"Software": None}, "svg": {"Date": None}, "pdf": {"CreationDate": None}}[fmt]
    return {"format": fmt, "dpi": dpi, "metadata": metadata}


def figure_bytes(figure: Any, fmt: str, dpi: float = DPI) -> bytes:
    """The figure rendered as PNG (at ``dpi``), SVG (text kept as text) or PDF."""
    import matplotlib

    buffer = io.BytesIO()
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "vtool"}):
        figure.savefig(buffer, **_save_options(fmt, dpi))
    return buffer.getvalue()


def save_figure(items: Sequence[Drawable], path: str | Path, field: str = "--figure", dpi: float = DPI) -> Path:
    """Draw ``items`` and write them to ``path`` (format by suffix), atomically."""
    from vtool.files import write_atomic_bytes

    fmt = output_format(path, field)
    write_atomic_bytes(path, figure_bytes(build_figure(items), fmt, dpi), field)
    return Path(path)


A4_IN = (8.27, 11.69)


def text_pages(lines: Sequence[str], heading: str) -> list[Any]:
    """A4 pages of fixed-width text (a report's tables): the font scaled down to fit the widest line
    (4.5 to 9 pt), as many lines on a page as that font allows."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    widest = max((len(line) for line in lines), default=1)
    size = max(4.5, min(9.0, 0.88 * A4_IN[0] * 72.0 / (0.6 * widest)))  # points: a mono glyph is 0.6 em wide
    per_page = int(0.9 * A4_IN[1] * 72.0 / (1.25 * size))
    pages = []
    for start in range(0, max(len(lines), 1), per_page):
        page = Figure(figsize=A4_IN)
        FigureCanvasAgg(page)
        page.text(0.06, 0.97, heading, fontsize=9, va="top", family="sans-serif")
        page.text(0.06, 0.945, "\n".join(lines[start:start + per_page]), fontsize=size, va="top",
                  family="monospace", linespacing=1.25)
        pages.append(page)
    return pages


def pdf_document(pages: Iterable[Any], title: str) -> bytes:
    """Figures as the pages of one PDF (matplotlib's PdfPages), no creation date (reproducible)."""
    from matplotlib.backends.backend_pdf import PdfPages

    buffer = io.BytesIO()
    with PdfPages(buffer, metadata={"Title": title, "Creator": "vtool", "CreationDate": None}) as pdf:
        for page in pages:
            pdf.savefig(page)
    return buffer.getvalue()


def svg_text(items: Sequence[Drawable]) -> str:
    """The figure as SVG markup (for inline use in an HTML report)."""
    return figure_bytes(build_figure(items), "svg").decode("utf-8")
