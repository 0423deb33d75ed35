"""Model choices side by side: the same mechanism under several impact laws and start velocities.

``compare(spec, impacts, starts)`` runs every combination with the same back
end and step and reports, per variant, what an engineer reads off a run: the
event count and the physical episodes per clearance
(:meth:`vtool.solvers.trace.Trace.episodes`), the first throw-off angle in
each revolution after the first (a separation episode at the cam while the
cam is above mid-stroke, 0-180 degrees into the revolution), the peak contact forces
and the seating velocities after the first revolution (the window of
:mod:`vtool.solvers.studies.metrics`, which ``vtool solve`` and ``vtool
sweep`` report too), and the largest valve lift.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from vtool.solvers.model.spec import IMPACT_LAWS, START_VELOCITIES, MechanismSpec
from vtool.solvers.run import simulate
from vtool.solvers.studies.metrics import run_metrics
from vtool.solvers.trace import SEPARATION, Trace


def with_model(spec: MechanismSpec, impact: str | None = None, start: str | None = None,
               rocker_scale: float | None = None) -> MechanismSpec:
    """The spec with every clearance on one impact law and/or another start; None keeps the preset's."""
    if impact is not None:
        if impact not in IMPACT_LAWS:
            from vtool.errors import InputError

            raise InputError("contact.impact", impact, f"one of: {', '.join(IMPACT_LAWS)}")
        spec = dataclasses.replace(
            spec, contact=dataclasses.replace(spec.contact, impact=impact),
            clearances=tuple(dataclasses.replace(c, impact=None) for c in spec.clearances))
    if rocker_scale is not None:
        spec = dataclasses.replace(spec, contact=dataclasses.replace(spec.contact, rocker_scale=rocker_scale))
    if start is not None:
        if start not in START_VELOCITIES:
            from vtool.errors import InputError

            raise InputError("initial.velocities", start, f"one of: {', '.join(START_VELOCITIES)}")
        spec = dataclasses.replace(spec, initial=dataclasses.replace(spec.initial, velocities=start))
    return spec


def throw_off_angles(trace: Trace) -> list[float | None]:
    """First cam separation above mid-stroke in each revolution after the first (deg into the revolution)."""
    cam = next(c.name for c in trace.spec.clearances if c.behind == trace.spec.cam.coordinate)
    separations = [e.first_angle for e in trace.episodes(cam) if e.kind == SEPARATION]
    revolutions = int(trace.cam_angle[-1] // 360.0) if len(trace.cam_angle) else 0
    result: list[float | None] = []
    for r in range(1, revolutions):
        angles = [a - 360.0 * r for a in separations if 0.0 <= a - 360.0 * r <= 180.0]
        result.append(min(angles) if angles else None)
    return result


@dataclass(frozen=True)
class Variant:
    impact: str
    start: str
    trace: Trace

    @property
    def label(self) -> str:
        return f"{self.impact} / {self.start}"

    def row(self) -> dict[str, Any]:
        t, spec = self.trace, self.trace.spec
        summary = t.summary()
        late = t.peak_force_after_first_revolution
        seat = next((c for c in summary["clearances"] if "seating_velocities" in c), None)
        valve = seat and next(c for c in spec.clearances if c.name == seat["clearance"]).ahead
        row: dict[str, Any] = {"impact": self.impact, "start": self.start, "events": len(t.events)}
        for c in summary["clearances"]:
            if c["state"] != "enabled":
                continue
            ep = c["episodes"]
            row[f"{c['clearance']} episodes"] = (f"{ep[SEPARATION]}s/{ep['impact']}i/{ep['bounce']}b/"
                                                 f"{ep['flicker']}f")
        row["throw-off (deg)"] = [None if a is None else round(a, 2) for a in throw_off_angles(t)]
        # the evaluated window (not the start-up shock), as solve and sweep report it
        metrics = run_metrics(t)
        window = "after rev 1" if t.cycles is None else (
            "last cycle" if t.cycles.period == 1 else f"last {t.cycles.period} cycles")
        for i in range(len(spec.clearances)):
            value = metrics[f"peak_{t.force_label(i)}"] if late is not None or t.cycles is not None else math.nan
            row[f"peak {t.force_label(i)} {window} ({spec.unit_system.force})"] = None if math.isnan(value) else value
        if seat is not None:
            for name, key in (("max", "seating_velocity_max"), ("mean", "seating_velocity_mean")):
                value = metrics[key]
                row[f"seating velocity {name} {window} ({spec.unit_system.velocity})"] = (
                    None if math.isnan(value) else value)
        if valve is not None:
            row[f"max valve lift ({spec.unit_system.length})"] = float(
                (t.coordinate(valve) - spec.seat.position).max()) if spec.seat is not None else None
        return row


def compare(spec: MechanismSpec, impacts: tuple[str, ...] = IMPACT_LAWS, starts: tuple[str, ...] | None = None,
            every_step: bool = False, before_run: Callable[[], object] | None = None) -> list[Variant]:
    """Run every (impact law, start) combination with the preset's back end and step; ``before_run()``
    once the first variant's input checks have passed (see :func:`vtool.solvers.run.simulate`)."""
    starts = starts or (spec.initial.velocities,)
    variants = []
    for impact in impacts:
        for start in starts:
            trace = simulate(with_model(spec, impact, start), every_step=every_step, before_run=before_run)
            before_run = None
            variants.append(Variant(impact, start, trace))
    return variants


def table(variants: list[Variant]) -> tuple[list[str], list[list[Any]]]:
    """Header and rows (one per variant) of the comparison."""
    rows = [v.row() for v in variants]
    header: list[str] = []
    for row in rows:
        header += [key for key in row if key not in header]
    return header, [[row.get(key) for key in header] for row in rows]


def cell(value: Any) -> str:
    """A table cell: numbers to 4 significant digits, lists joined, missing as '-'."""
    if value is None:
        return "-"
    if isinstance(value, list):
        return " ".join(cell(v) for v in value) or "-"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)
