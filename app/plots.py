"""Terminal charts. The only module in vtool that imports plotext.

plotext is pinned below 6: version 6 is an incompatible rewrite of the
5.x API used here (and textual-plotext also pins it below 6). plotext keeps
one global figure, so every chart is built under a lock and returned as a
string; the CLI prints it and the TUI puts it in a widget.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping, Sequence

import numpy as np

_LOCK = threading.Lock()


Curve = tuple[str, np.ndarray, np.ndarray]


def _render(curves: list[Curve], *, title: str, xlabel: str, ylabel: str, width: int, height: int,
            color: bool, xlim: tuple[float, float] | None = None, ylim: tuple[float, float] | None = None,
            xlog: bool = False) -> str:
    """Draw labelled (x, y) curves with plotext and return the text (the one place plotext is used)."""
    import plotext as plt

    with _LOCK:
        plt.clf()
        plt.plotsize(max(int(width), 20), max(int(height), 8))
        plt.theme("pro" if color else "clear")
        for label, xs, ys in curves:
            plt.plot(np.asarray(xs, dtype=float).tolist(), np.asarray(ys, dtype=float).tolist(),
                     label=label, marker="braille")
        if xlim is not None:
            plt.xlim(*xlim)
        if ylim is not None:
            plt.ylim(*ylim)
        if xlog:
            plt.xscale("log")
        plt.title(title)
        plt.xlabel(xlabel)
        plt.ylabel(ylabel)
        text = plt.build()
        plt.clf()
    if not color:
        text = plt.uncolorize(text)
    return text


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
) -> str:
    """A line chart of one or more series against a common x, as text.

    ``step=True`` draws the series as a staircase (for configuration traces);
    ``color=False`` gives plain text for files and tests.
    """
    xs = np.asarray(x, dtype=float)
    curves = []
    for label, values in series.items():
        ys = np.asarray(values, dtype=float)
        if step:
            curves.append((label, np.repeat(xs, 2)[1:], np.repeat(ys, 2)[:-1]))
        else:
            curves.append((label, xs, ys))
    return _render(curves, title=title, xlabel=xlabel, ylabel=ylabel, width=width, height=height, color=color,
                   ylim=ylim, xlog=xlog)


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
    return _render(curves, title=title, xlabel=xlabel, ylabel=ylabel, width=width, height=height, color=color,
                   xlim=xlim, ylim=ylim)
