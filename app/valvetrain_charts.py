"""Charts of a valve-train trace (contact forces, displacements, configuration), for the CLI and the TUI."""

from __future__ import annotations

from vtool.app.plots import line_chart, stacked_chart
from vtool.solvers.trace import Trace


def force_chart(trace: Trace, width: int = 100, height: int = 20, color: bool = True) -> str:
    units = trace.spec.unit_system
    series = {f"{trace.force_label(i)} {c.name}": trace.contact_force[:, i]
              for i, c in enumerate(trace.spec.clearances) if c.state != "removed"}
    return line_chart(trace.cam_angle, series, title=f"contact forces ({units.force})",
                      xlabel="cam angle (deg)", ylabel=units.force, width=width, height=height, color=color)


def plotted_quantities(trace: Trace) -> tuple[str, ...]:
    """Every quantity the preset names (Gnilka's printed list), else the elastic coordinates."""
    return trace.spec.run.quantities or tuple(f"q{i}" for i in range(1, trace.spec.n_coordinates + 1))


def displacement_chart(trace: Trace, quantities: tuple[str, ...] | None = None, width: int = 100,
                       height: int = 20, color: bool = True) -> str:
    """The chosen quantities (default: the first four displacements of the preset's list).

    Quantities of different units (in, rad, lbf) go on panels stacked over the
    cam angle, one unit per panel, so no curve is flattened by another's scale.
    """
    if quantities is None:
        quantities = tuple(q for q in plotted_quantities(trace) if not q.startswith("F"))[:4] or ("q1",)
    groups: dict[str, dict[str, object]] = {}
    for q in quantities:
        groups.setdefault(trace.quantity_unit(q), {})[q] = trace.quantity(q)
    title = "displacements" if all(not q.startswith("F") for q in quantities) else "quantities"
    return stacked_chart(trace.cam_angle, list(groups.items()), title=title, xlabel="cam angle (deg)",
                         width=width, height=height, color=color)  # type: ignore[arg-type]


def configuration_chart(trace: Trace, width: int = 100, height: int = 14, color: bool = True) -> str:
    """One named lane per clearance: the lane's line is raised while the clearance is closed."""
    series = {}
    lanes = [(i, c) for i, c in enumerate(trace.spec.clearances) if c.state != "removed"]
    for lane, (i, c) in enumerate(lanes):
        bit = 1 << (len(trace.spec.clearances) - 1 - i)
        closed = (trace.configuration & bit) != 0
        series[c.name] = 2.0 * lane + 1.0 * closed
    ticks = ([2.0 * lane + 0.5 for lane in range(len(lanes))], [c.name for _, c in lanes])
    return line_chart(trace.cam_angle, series, title="configuration: a raised line = clearance closed",
                      xlabel="cam angle (deg)", width=width, height=height, color=color, step=True,
                      ylim=(-0.5, 2.0 * len(lanes)), yticks=ticks)


def all_charts(trace: Trace, width: int = 100, color: bool = True) -> str:
    return "\n".join([force_chart(trace, width, color=color), displacement_chart(trace, width=width, color=color),
                      configuration_chart(trace, width, color=color)])


