"""Terminal charts. The only module in vtool that imports plotext.

plotext is pinned below 6: version 6 is an incompatible rewrite of the
5.x API used here (and textual-plotext also pins it below 6). plotext keeps
one global figure, so every chart is built under a lock and returned as a
string; the CLI prints it and the TUI puts it in a widget.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from vtool.chart import Chart

_LOCK = threading.Lock()


Curve = tuple[str, np.ndarray, np.ndarray]
Ticks = tuple[Sequence[float], Sequence[str]]


@dataclass(frozen=True)
class Panel:
    """One plot of a (possibly stacked) figure: labelled curves over a common x."""

    curves: list[Curve]
    title: str = ""
    ylabel: str = ""
    ylim: tuple[float, float] | None = None
    yticks: Ticks | None = None  # positions and names (e.g. one lane per clearance)


def _reset(plt) -> None:
    """Empty plotext's one global figure, subplots included (``clf`` clears only the active one)."""
    plt.main().clear_figure()  # the master figure: its __init__ forgets every subplot


def _render(panels: list[Panel], *, xlabel: str, width: int, height: int, color: bool,
            xlim: tuple[float, float] | None = None, xlog: bool = False) -> str:
    """Draw panels stacked top to bottom with plotext; return the text (the one place plotext is used)."""
    import plotext as plt

    with _LOCK:
        _reset(plt)
        plt.plotsize(max(int(width), 20), max(int(height), 8))
        if len(panels) > 1:
            plt.subplots(len(panels), 1)
        for number, panel in enumerate(panels, start=1):
            if len(panels) > 1:
                plt.subplot(number, 1)
            plt.theme("pro" if color else "clear")
            drawn = 0
            for label, xs, ys in panel.curves:
                xs, ys = np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)
                if not np.isfinite(xs[np.isfinite(ys)]).any():  # nothing to draw (plotext fails on it)
                    continue
                plt.plot(xs.tolist(), ys.tolist(), label=label, marker="braille")
                drawn += 1
            if xlim is not None:
                plt.xlim(*xlim)
            if panel.ylim is not None:
                plt.ylim(*panel.ylim)
            if panel.yticks is not None:
                plt.yticks(list(panel.yticks[0]), list(panel.yticks[1]))
            if xlog:
                plt.xscale("log")
            plt.title(panel.title if drawn else f"{panel.title}: no finite value to draw".lstrip(": "))
            plt.ylabel(panel.ylabel)
            if number == len(panels):
                plt.xlabel(xlabel)
        text = plt.build()
        _reset(plt)
    if not color:
        text = plt.uncolorize(text)
    return text


def _curves(xs: np.ndarray, series: Mapping[str, Sequence[float] | np.ndarray], step: bool) -> list[Curve]:
    curves = []
    for label, values in series.items():
        ys = np.asarray(values, dtype=float)
        if step:
            curves.append((label, np.repeat(xs, 2)[1:], np.repeat(ys, 2)[:-1]))
        else:
            curves.append((label, xs, ys))
    return curves


def line_chart(
    x: Sequence[float] | np.ndarray,
    series: Mapping[str, Sequence[float] | np.ndarray],
    *,
    title: str = "",
    xlabel: str = "",
    ylabel: str = "",
    width: int = 100,
    height: int = 22,
    color: bool = True,
    step: bool = False,
    ylim: tuple[float, float] | None = None,
    xlog: bool = False,
    yticks: Ticks | None = None,
) -> str:
    """A line chart of one or more series against a common x, as text.

    ``step=True`` draws the series as a staircase (for configuration traces);
    ``yticks`` names positions on the y axis; ``color=False`` gives plain
    text for files and tests.
    """
    panel = Panel(_curves(np.asarray(x, dtype=float), series, step), title, ylabel, ylim, yticks)
    return _render([panel], xlabel=xlabel, width=width, height=height, color=color, xlog=xlog)


def chart_text(chart: Chart, *, width: int = 100, height: int = 22, color: bool = True) -> str:
    """A :class:`vtool.chart.Chart` as text: its panels stacked, the title on the top one.

    Event marks are left to the figures (a braille chart has no room for them);
    the terminal lists events with ``--events``.
    """
    panels = [Panel([(c.label, *(_curves(c.x, {"": c.y}, c.step)[0][1:])) for c in panel.curves],
                    chart.title if i == 0 else "", panel.ylabel, panel.ylim, panel.yticks)
              for i, panel in enumerate(chart.panels)]
    return _render(panels, xlabel=chart.xlabel, width=width, height=height, color=color, xlim=chart.xlim,
                   xlog=chart.xlog)


def shape_chart(
    shapes: Mapping[str, tuple[Sequence[float] | np.ndarray, Sequence[float] | np.ndarray]],
    *,
    title: str = "",
    xlabel: str = "",
    ylabel: str = "",
    width: int = 100,
    height: int = 22,
    color: bool = True,
    xlim: tuple[float, float] | None = None,
    ylim: tuple[float, float] | None = None,
) -> str:
    """Polylines in the plane (one series per named shape), as text.

    For drawings such as a deformed mechanism: each shape is ``(x, y)``;
    fixed ``xlim`` / ``ylim`` keep the frame still between animation frames.
    """
    curves = [(label, np.asarray(xs, dtype=float), np.asarray(ys, dtype=float)) for label, (xs, ys) in shapes.items()]
    return _render([Panel(curves, title, ylabel, ylim)], xlabel=xlabel, width=width, height=height,
                   color=color, xlim=xlim)
