"""The speed/accuracy trade, measured: every back end over its accuracy knob against ``exact``.

For each setting the study records wall time, steps and events, and the
error against the exact back end in

* event angles: the event sequences are aligned (same clearance, same kind,
  in order); the largest |Δθ| over the aligned events, and how many events
  are missing or extra;
* peak contact forces: the largest relative error over the clearances;
* valve seating velocity: relative error of the first seat impact;
* valve lift: the largest absolute difference of the valve coordinate over
  the output angles.

Newmark runs use its default refinement after events (steps of dt/10 for two
periods of the highest mode); one extra row shows the plain thesis scheme at
1 µs. Settings a back end refuses (a Newmark step beyond its stability
limit) are listed with the reason instead of figures.
"""

from __future__ import annotations

import difflib
import io
import math
from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError, RunError
from vtool.files import write_atomic
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.model import assemble
from vtool.solvers.newmark import NewmarkBackend, NewmarkOptions
from vtool.solvers.run import simulate
from vtool.solvers.scipy_backend import ScipyBackend, ScipyOptions
from vtool.solvers.spec import EXTERNAL, MechanismSpec
from vtool.solvers.trace import CLOSED, Trace

NEWMARK_STEPS = (1e-4, 1e-5, 2e-6, 1e-6, 5e-7, 2e-7, 1e-7)
NEWMARK_BETAS = (1 / 6, 1 / 4)
SCIPY_RTOLS = (1e-4, 1e-6, 1e-8, 1e-9, 1e-10, 1e-11)


@dataclass(frozen=True)
class AccuracyRow:
    backend: str
    setting: str
    wall_time: float | None = None  # s
    steps: int | None = None
    events: int | None = None
    same_sequence: bool | None = None
    unmatched_events: int | None = None
    event_angle_error: float | None = None  # deg
    peak_force_error: float | None = None  # relative
    seating_velocity_error: float | None = None  # relative
    lift_error: float | None = None  # length
    note: str = ""


def seat_clearance(spec: MechanismSpec) -> str | None:
    for c in spec.clearances:
        if c.kind == EXTERNAL and c.behind != spec.cam.coordinate and c.state == "enabled":
            return c.name
    return None


def compare(trace: Trace, reference: Trace, backend: str, setting: str) -> AccuracyRow:
    """Errors of ``trace`` against the exact ``reference`` (see module doc)."""
    ours = [(e.clearance, e.kind) for e in trace.events]
    truth = [(e.clearance, e.kind) for e in reference.events]
    matcher = difflib.SequenceMatcher(a=truth, b=ours, autojunk=False)
    deltas, unmatched = [], 0
    for tag, i1, i2, j1, j2 in matcher.get_opcodes():
        if tag == "equal":
            deltas += [abs(reference.events[i].cam_angle - trace.events[j].cam_angle)
                       for i, j in zip(range(i1, i2), range(j1, j2), strict=True)]
        else:
            unmatched += (i2 - i1) + (j2 - j1)
    with np.errstate(divide="ignore", invalid="ignore"):
        peak = np.where(reference.peak_force > 0, np.abs(trace.peak_force / reference.peak_force - 1), 0.0)
    seat = seat_clearance(trace.spec)
    seating = None
    if seat is not None:
        ours_v = [e.relative_velocity for e in trace.events if e.clearance == seat and e.kind == CLOSED]
        true_v = [e.relative_velocity for e in reference.events if e.clearance == seat and e.kind == CLOSED]
        if ours_v and true_v:
            seating = abs(ours_v[0] / true_v[0] - 1)
    valve = next(c.ahead for c in trace.spec.clearances if c.name == seat) if seat else None
    lift = None
    if valve is not None and trace.time.shape == reference.time.shape:
        lift = float(np.abs(trace.coordinate(valve) - reference.coordinate(valve)).max())
    stats = trace.statistics
    return AccuracyRow(backend, setting, stats.wall_time, stats.steps, stats.events, ours == truth, unmatched,
                       max(deltas) if deltas else None, float(peak.max()), seating, lift)


def accuracy_study(
    spec: MechanismSpec,
    newmark_steps: tuple[float, ...] = NEWMARK_STEPS,
    newmark_betas: tuple[float, ...] = NEWMARK_BETAS,
    scipy_rtols: tuple[float, ...] = SCIPY_RTOLS,
) -> tuple[Trace, list[AccuracyRow]]:
    """Run the exact reference, then every setting; return (reference, rows)."""
    reference = simulate(with_run_overrides(spec, backend="exact"))
    rows = [AccuracyRow("exact", "reference", reference.statistics.wall_time, reference.statistics.steps,
                        reference.statistics.events, True, 0, 0.0, 0.0, 0.0, 0.0)]
    for beta in newmark_betas:
        for dt in newmark_steps:
            setting = f"dt={dt:.0e} beta={'1/6' if abs(beta - 1 / 6) < 1e-12 else '1/4'}"
            try:
                trace = simulate(with_run_overrides(spec, backend="newmark", time_step=dt, beta=beta))
            except InputError as error:
                rows.append(AccuracyRow("newmark", setting, note=f"refused: {error.expected}"))
                continue
            except RunError as error:
                rows.append(AccuracyRow("newmark", setting, note=f"failed: {error}"))
                continue
            rows.append(compare(trace, reference, "newmark", setting))
    mechanism = assemble(spec)
    plain = NewmarkBackend().simulate(mechanism, NewmarkOptions(1e-6, refine=1))
    rows.append(compare(plain, reference, "newmark", "dt=1e-06 beta=1/6, no refinement (the thesis' scheme)"))
    for rtol in scipy_rtols:
        trace = ScipyBackend().simulate(mechanism, ScipyOptions(rtol=rtol))
        rows.append(compare(trace, reference, "scipy", f"DOP853 rtol={rtol:.0e}"))
    return reference, rows


COLUMNS = ("backend", "setting", "wall time (s)", "steps", "events", "same sequence", "unmatched",
           "max |dtheta| (deg)", "peak force err (%)", "seating vel err (%)", "lift err (in)", "note")


def _cells(row: AccuracyRow, length_unit: str) -> list[str]:
    def fmt(value: float | None, spec: str, scale: float = 1.0) -> str:
        if value is None or (isinstance(value, float) and math.isnan(value)):
            return ""
        return format(value * scale if scale != 1.0 else value, spec)

    return [row.backend, row.setting, fmt(row.wall_time, ".3f"), fmt(row.steps, "d"), fmt(row.events, "d"),
            "" if row.same_sequence is None else ("yes" if row.same_sequence else "no"),
            fmt(row.unmatched_events, "d"), fmt(row.event_angle_error, ".2g"), fmt(row.peak_force_error, ".2g", 100),
            fmt(row.seating_velocity_error, ".2g", 100), fmt(row.lift_error, ".2g"), row.note]


def table_text(rows: list[AccuracyRow], length_unit: str = "in") -> str:
    header = [c.replace("(in)", f"({length_unit})") for c in COLUMNS]
    body = [_cells(row, length_unit) for row in rows]
    widths = [max(len(r[i]) for r in [header, *body]) for i in range(len(header) - 1)]
    lines = []
    for r in [header, *body]:
        lines.append("  ".join(cell.ljust(w) for cell, w in zip(r[:-1], widths, strict=True)) + "  " + r[-1])
    return "\n".join(line.rstrip() for line in lines)


def table_markdown(rows: list[AccuracyRow], length_unit: str = "in") -> str:
    header = [c.replace("(in)", f"({length_unit})") for c in COLUMNS]
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_cells(row, length_unit)) + " |" for row in rows]
    return "\n".join(lines)


def write_table_csv(path: str, rows: list[AccuracyRow], length_unit: str = "in") -> None:
    buffer = io.StringIO()
    header = [c.replace("(in)", f"({length_unit})") for c in COLUMNS]
    buffer.write(",".join(header) + "\n")
    for row in rows:
        buffer.write(",".join(cell.replace(",", ";") for cell in _cells(row, length_unit)) + "\n")
    write_atomic(path, buffer.getvalue())
