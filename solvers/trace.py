"""The result of a valve-train run, the same for every back end.

A :class:`Trace` holds the sampled response (time, cam angle, coordinates,
velocities, accelerations, contact forces, configuration), the event list,
the peak contact forces seen at every step, and run statistics. It exports
CSV text with units in the header and a summary (separations and impacts per
clearance, peak forces, valve seating velocities, bounces per cam revolution).
"""

from __future__ import annotations

import io
import math
import re
from dataclasses import dataclass, field

import numpy as np

from vtool.files import write_atomic
from vtool.solvers.configurations import closed_names, configuration_label, thesis_number
from vtool.solvers.spec import EXTERNAL, MechanismSpec

OPENED = "opened"
CLOSED = "closed"
RELEASED = "released"  # a persistent contact pulled apart by another contact's impact


@dataclass(frozen=True)
class Event:
    """One configuration change at one clearance.

    ``relative_velocity`` is d(gap)/dt: before the impact for ``closed``
    (negative: approaching), after it for ``released``, zero for ``opened``.
    """

    time: float
    cam_angle: float  # degrees
    clearance: str
    kind: str
    relative_velocity: float
    before: int  # configuration masks
    after: int


@dataclass(frozen=True)
class RunStatistics:
    backend: str
    steps: int
    events: int
    wall_time: float  # s
    configurations_built: tuple[int, ...]
    settings: dict = field(default_factory=dict)
    error_estimate: float | None = None


@dataclass(frozen=True)
class Trace:
    """Response of one run (see module doc). Rows are output instants."""

    spec: MechanismSpec
    time: np.ndarray
    cam_angle: np.ndarray  # degrees
    coordinate_numbers: tuple[int, ...]  # column numbers of q: elastic, then cam, seat
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    contact_force: np.ndarray  # rows x clearances, compression positive, 0 when open
    configuration: np.ndarray  # masks
    events: tuple[Event, ...]
    peak_force: np.ndarray  # per clearance, over every step
    statistics: RunStatistics
    success: bool = True
    message: str = ""

    # ----- columns by the engineer's names -----
    def coordinate(self, number: int) -> np.ndarray:
        return self.q[:, self.coordinate_numbers.index(number)]

    def force_label(self, index: int) -> str:
        return f"F{self.spec.clearances[index].ahead}"

    def force(self, label_or_name: str) -> np.ndarray:
        for i, c in enumerate(self.spec.clearances):
            if label_or_name in (c.name, self.force_label(i)):
                return self.contact_force[:, i]
        raise KeyError(label_or_name)

    def quantity(self, expression: str) -> np.ndarray:
        """``q7``, ``q1-q9`` or ``F2`` (the force at the clearance ahead of q2)."""
        text = expression.replace(" ", "")
        if match := re.fullmatch(r"q(\d+)-q(\d+)", text):
            return self.coordinate(int(match[1])) - self.coordinate(int(match[2]))
        if match := re.fullmatch(r"q(\d+)", text):
            return self.coordinate(int(match[1]))
        if re.fullmatch(r"F\d+", text):
            return self.force(text)
        raise KeyError(expression)

    def coordinate_unit(self, number: int) -> str:
        units = self.spec.unit_system
        if number <= self.spec.n_coordinates and self.spec.coordinates[number - 1].motion == "rotation":
            return "rad"
        return units.length

    def quantity_unit(self, expression: str) -> str:
        text = expression.replace(" ", "")
        if text.startswith("F"):
            return self.spec.unit_system.force
        return self.coordinate_unit(int(re.findall(r"\d+", text)[0]))

    # ----- export -----
    def csv_text(self, quantities: tuple[str, ...] = ()) -> str:
        """CSV with one header row naming each quantity and its unit."""
        units = self.spec.unit_system
        header = ["time (s)", "cam_angle (deg)"]
        columns: list[np.ndarray] = [self.time, self.cam_angle]
        for prefix, data, suffix in (("q", self.q, ""), ("qd", self.qd, f"/{units.time}"),
                                     ("qdd", self.qdd, f"/{units.time}^2")):
            for j, number in enumerate(self.coordinate_numbers):
                header.append(f"{prefix}{number} ({self.coordinate_unit(number)}{suffix})")
                columns.append(data[:, j])
        for i in range(len(self.spec.clearances)):
            header.append(f"{self.force_label(i)} ({units.force})")
            columns.append(self.contact_force[:, i])
        for expression in quantities:
            header.append(f"{expression} ({self.quantity_unit(expression)})")
            columns.append(self.quantity(expression))
        header += ["configuration", "closed"]
        numbers = [thesis_number(self.spec, int(m)) for m in self.configuration]
        closed = ["+".join(closed_names(self.spec, int(m))) or "none" for m in self.configuration]
        buffer = io.StringIO()
        buffer.write(",".join(header) + "\n")
        table = np.column_stack(columns)
        for row, number, names in zip(table, numbers, closed, strict=True):
            buffer.write(",".join(f"{value:.10g}" for value in row))
            buffer.write(f",{'' if number is None else number},{names}\n")
        return buffer.getvalue()

    def write_csv(self, path: str, quantities: tuple[str, ...] | None = None) -> None:
        """Write :meth:`csv_text` atomically (the preset's quantities by default)."""
        write_atomic(path, self.csv_text(self.spec.run.quantities if quantities is None else quantities))

    # ----- summary -----
    def events_at(self, clearance: str, kinds: tuple[str, ...]) -> list[Event]:
        return [e for e in self.events if e.clearance == clearance and e.kind in kinds]

    def bounces_per_revolution(self, clearance: str) -> list[int]:
        """Impacts at a clearance in each whole cam revolution after the first."""
        revolutions = int(self.cam_angle[-1] // 360.0) if len(self.cam_angle) else 0
        counts = [0] * max(revolutions - 1, 0)
        for e in self.events_at(clearance, (CLOSED,)):
            index = int(e.cam_angle // 360.0) - 1
            if 0 <= index < len(counts):
                counts[index] += 1
        return counts

    def summary(self) -> dict:
        """Counts, peaks and seating velocities per clearance, and the run statistics."""
        units = self.spec.unit_system
        clearances = []
        for i, c in enumerate(self.spec.clearances):
            impacts = self.events_at(c.name, (CLOSED,))
            entry = {
                "clearance": c.name,
                "force": self.force_label(i),
                "state": c.state,
                "separations": len(self.events_at(c.name, (OPENED, RELEASED))),
                "impacts": len(impacts),
                "peak_force": float(self.peak_force[i]),
                "peak_force_unit": units.force,
            }
            if c.kind == EXTERNAL and c.behind != self.spec.cam.coordinate:
                entry["seating_velocities"] = [-e.relative_velocity for e in impacts]
                entry["seating_velocity_unit"] = units.velocity
                entry["bounces_per_revolution"] = self.bounces_per_revolution(c.name)
            clearances.append(entry)
        stats = self.statistics
        return {
            "title": self.spec.title,
            "success": self.success,
            "message": self.message,
            "backend": stats.backend,
            "settings": stats.settings,
            "steps": stats.steps,
            "events": stats.events,
            "wall_time_s": stats.wall_time,
            "configurations_built": [configuration_label(self.spec, m) for m in stats.configurations_built],
            "events_list": [
                {"time_s": e.time, "cam_angle_deg": e.cam_angle, "clearance": e.clearance, "kind": e.kind,
                 "relative_velocity": e.relative_velocity,
                 "before": configuration_label(self.spec, e.before), "after": configuration_label(self.spec, e.after)}
                for e in self.events
            ],
            "clearances": clearances,
        }

    def summary_text(self) -> str:
        s = self.summary()
        units = self.spec.unit_system
        lines = [s["title"], f"back end {s['backend']}: " + ", ".join(f"{k} = {v}" for k, v in s["settings"].items())]
        lines.append(
            f"steps {s['steps']}, events {s['events']}, wall time {s['wall_time_s']:.3f} s, "
            f"configurations built: {', '.join(s['configurations_built'])}"
        )
        lines.append("")
        lines.append(f"{'clearance':<10} {'force':<6} {'state':<8} {'separations':>11} {'impacts':>8} "
                     f"{'peak force (' + units.force + ')':>18}")
        for c in s["clearances"]:
            lines.append(f"{c['clearance']:<10} {c['force']:<6} {c['state']:<8} {c['separations']:>11} "
                         f"{c['impacts']:>8} {c['peak_force']:>18.6g}")
        for c in s["clearances"]:
            if "seating_velocities" in c and c["seating_velocities"]:
                v = np.array(c["seating_velocities"])
                lines.append(
                    f"{c['clearance']} seating velocity ({units.velocity}): first {v[0]:.4g}, "
                    f"max {v.max():.4g}, mean {v.mean():.4g} over {len(v)} impacts"
                )
                lines.append(f"{c['clearance']} bounces per revolution (after the first): "
                             f"{c['bounces_per_revolution']}")
        if not s["success"]:
            lines.append(f"run stopped: {s['message']}")
        return "\n".join(lines)

    def event_table(self) -> str:
        units = self.spec.unit_system
        lines = [f"{'cam angle (deg)':>15} {'time (s)':>12} {'clearance':<10} {'event':<9} "
                 f"{'rel. velocity (' + units.velocity + ')':>24}  configuration"]
        for e in self.events:
            lines.append(
                f"{e.cam_angle:>15.4f} {e.time:>12.6e} {e.clearance:<10} {e.kind:<9} "
                f"{e.relative_velocity:>24.5g}  {configuration_label(self.spec, e.before)} -> "
                f"{configuration_label(self.spec, e.after)}"
            )
        return "\n".join(lines)


def cam_angle_deg(time: np.ndarray, omega: float) -> np.ndarray:
    return np.asarray(time) * omega * 180.0 / math.pi
