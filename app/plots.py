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
    import plotext as plt

    xs = np.asarray(x, dtype=float)
    with _LOCK:
        plt.clf()
        plt.plotsize(max(int(width), 20), max(int(height), 8))
        plt.theme("pro" if color else "clear")
        for label, values in series.items():
            ys = np.asarray(values, dtype=float)
            if step:
                xs_s = np.repeat(xs, 2)[1:]
                ys_s = np.repeat(ys, 2)[:-1]
                plt.plot(xs_s.tolist(), ys_s.tolist(), label=label, marker="braille")
            else:
                plt.plot(xs.tolist(), ys.tolist(), label=label, marker="braille")
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
    import plotext as plt

    with _LOCK:
        plt.clf()
        plt.plotsize(max(int(width), 20), max(int(height), 8))
        plt.theme("pro" if color else "clear")
        for label, (xs, ys) in shapes.items():
            plt.plot(np.asarray(xs, dtype=float).tolist(), np.asarray(ys, dtype=float).tolist(),
                     label=label, marker="braille")
        if xlim is not None:
            plt.xlim(*xlim)
        if ylim is not None:
            plt.ylim(*ylim)
        plt.title(title)
        plt.xlabel(xlabel)
        plt.ylabel(ylabel)
        text = plt.build()
        plt.clf()
    if not color:
        text = plt.uncolorize(text)
    return text
