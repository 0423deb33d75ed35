"""Charts of a valve-train trace (contact forces, displacements, configuration), for the CLI and the TUI."""

from __future__ import annotations

from vtool.app.plots import line_chart
from vtool.solvers.trace import Trace


def force_chart(trace: Trace, width: int = 100, height: int = 20, color: bool = True) -> str:
    units = trace.spec.unit_system
    series = {f"{trace.force_label(i)} {c.name}": trace.contact_force[:, i]
              for i, c in enumerate(trace.spec.clearances) if c.state != "removed"}
    return line_chart(trace.cam_angle, series, title=f"contact forces ({units.force})",
                      xlabel="cam angle (deg)", ylabel=units.force, width=width, height=height, color=color)


def displacement_chart(trace: Trace, quantities: tuple[str, ...] | None = None, width: int = 100,
                       height: int = 20, color: bool = True) -> str:
    """The chosen displacement quantities (default: the first four of the preset's quantities)."""
    if quantities is None:
        quantities = tuple(q for q in trace.spec.run.quantities if not q.startswith("F"))[:4] or ("q1",)
    series = {f"{q} ({trace.quantity_unit(q)})": trace.quantity(q) for q in quantities}
    return line_chart(trace.cam_angle, series, title="displacements", xlabel="cam angle (deg)",
                      width=width, height=height, color=color)


def configuration_chart(trace: Trace, width: int = 100, height: int = 14, color: bool = True) -> str:
    """One lane per clearance: the lane is raised while the clearance is closed."""
    series = {}
    lanes = [(i, c) for i, c in enumerate(trace.spec.clearances) if c.state != "removed"]
    for lane, (i, c) in enumerate(lanes):
        bit = 1 << (len(trace.spec.clearances) - 1 - i)
        closed = (trace.configuration & bit) != 0
        series[f"{c.name} (lane {lane})"] = 2.0 * lane + 1.0 * closed
    return line_chart(trace.cam_angle, series, title="configuration: raised lane = clearance closed",
                      xlabel="cam angle (deg)", width=width, height=height, color=color, step=True,
                      ylim=(-0.5, 2.0 * len(lanes)))


def all_charts(trace: Trace, width: int = 100, color: bool = True) -> str:
    return "\n".join([force_chart(trace, width, color=color), displacement_chart(trace, width=width, color=color),
                      configuration_chart(trace, width, color=color)])


