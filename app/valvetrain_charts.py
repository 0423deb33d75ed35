"""Charts of a valve-train trace (contact forces, displacements, configuration), for the CLI and the TUI.

The series are :mod:`vtool.presets.charts`' (the same that ``--figure`` draws); this module draws them as text.
"""

from __future__ import annotations

from vtool.app.plots import chart_text
from vtool.presets import charts
from vtool.solvers.trace import Trace


def force_chart(trace: Trace, width: int = 100, height: int = 20, color: bool = True) -> str:
    return chart_text(charts.force_chart(trace), width=width, height=height, color=color)


def displacement_chart(trace: Trace, quantities: tuple[str, ...] | None = None, width: int = 100,
                       height: int = 20, color: bool = True) -> str:
    """The chosen quantities (default: the first four displacements of the preset's list), one unit per panel."""
    return chart_text(charts.displacement_chart(trace, quantities), width=width, height=height, color=color)


def configuration_chart(trace: Trace, width: int = 100, height: int = 14, color: bool = True) -> str:
    """One named lane per clearance: the lane's line is raised while the clearance is closed."""
    return chart_text(charts.configuration_chart(trace), width=width, height=height, color=color)


def all_charts(trace: Trace, width: int = 100, color: bool = True) -> str:
    return "\n".join([force_chart(trace, width, color=color), displacement_chart(trace, width=width, color=color),
                      configuration_chart(trace, width, color=color)])
