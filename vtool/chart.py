"""Chart data: what a chart shows, as plain data, for every way of drawing it.

The series, axis labels (with units), titles and event marks of a chart are
computed below ``app/`` (:mod:`vtool.presets.charts` builds them from a trace,
a sweep, a cam, a boom or a plate study) and drawn by ``app/``: as text with
plotext (:func:`vtool.app.plots.chart_text`, the terminal and the TUI) or as a
report-grade figure with matplotlib (:mod:`vtool.app.figures`, PNG/SVG/PDF and
``vtool report``). Both draw the same :class:`Chart`, so a figure in a report
shows exactly what the terminal chart showed.

A :class:`Chart` is one or more :class:`Panel` stacked over a common x axis
(one y unit per panel); :class:`Mark` are events at an x (a valve-train
impact, a separation) drawn as symbols on the panel named by ``panel``.
A :class:`HeatMap` is a metric over two swept fields (``vtool sweep --map``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Curve:
    """One labelled series; ``step=True`` draws it as a staircase (a configuration trace)."""

    label: str
    x: np.ndarray
    y: np.ndarray
    step: bool = False


@dataclass(frozen=True)
class Mark:
    """Events of one kind (``label``) at x positions, drawn as symbols on a panel."""

    label: str
    x: np.ndarray
    panel: int = 0


@dataclass(frozen=True)
class Panel:
    """Curves sharing one y axis; ``ylabel`` names the quantity and its unit."""

    curves: tuple[Curve, ...]
    ylabel: str = ""
    ylim: tuple[float, float] | None = None
    yticks: tuple[Sequence[float], Sequence[str]] | None = None  # positions and names (lanes)


@dataclass(frozen=True)
class Chart:
    """Panels stacked over one x axis. ``subject`` is what it is of (the preset's title)."""

    title: str
    xlabel: str
    panels: tuple[Panel, ...]
    subject: str = ""
    marks: tuple[Mark, ...] = ()
    xlog: bool = False
    xlim: tuple[float, float] | None = None

    def labels(self) -> list[str]:
        """The axis labels (x first), for checks that each names its unit."""
        return [self.xlabel] + [p.ylabel for p in self.panels]


@dataclass(frozen=True)
class HeatMap:
    """``values[j, i]`` of a metric at ``x[i]`` (first swept field) and ``y[j]`` (second); NaN: none.

    ``x`` and ``y`` hold the swept values as given (numbers, or names such as impact laws);
    ``lines``: curves in the map's own coordinates drawn over it (a Campbell map's natural frequencies).
    """

    title: str
    xlabel: str
    ylabel: str
    zlabel: str
    x: np.ndarray
    y: np.ndarray
    values: np.ndarray
    subject: str = ""
    lines: tuple[Curve, ...] = ()

    def labels(self) -> list[str]:
        return [self.xlabel, self.ylabel, self.zlabel]


def curve(label: str, x: Sequence[float] | np.ndarray, y: Sequence[float] | np.ndarray,
          step: bool = False) -> Curve:
    """A :class:`Curve` with float arrays."""
    return Curve(label, np.asarray(x, dtype=float), np.asarray(y, dtype=float), step)


def with_unit(name: str, unit: str) -> str:
    """``name (unit)``, or the name alone for a dimensionless quantity."""
    return f"{name} ({unit})" if unit else name
