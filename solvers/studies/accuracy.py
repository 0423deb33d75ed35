"""The speed/accuracy trade, measured: every back end over its accuracy knob against the reference.

The reference is the installed back end flagged ``reference`` (``exact``);
every other back end is run at the settings it takes from the knobs
(:meth:`vtool.solvers.backends.Backend.accuracy_settings`): steps and beta
values for a fixed-step one, tolerances for an adaptive one. No back end is
named here.

For each setting the study records wall time, steps and events, and the
error against the exact back end in

* event angles: the events are paired with the reference's by clearance,
  kind and nearest time (:func:`vtool.solvers.studies.pairing.pair_events`: a window
  of half the spacing of that clearance's events of that kind in the
  reference); the largest |Δθ| over the pairs, and how many events have no
  partner (missing from the run or extra in it: *unmatched*);
* peak contact forces: the largest relative error over the clearances, of
  the peak over the whole run and of the peak after the first revolution
  (a run's largest force is often the start shock of its first 3 degrees,
  which every setting gets right: a wrong peak later, such as scipy's +277 %
  on gnilka-1d at rtol 1e-6, would hide behind it);
* valve seating velocity: relative error of the impact velocity at the first
  seat impact of the reference that has a partner;
* valve lift: the largest absolute difference of the valve coordinate over
  the output angles.

A run whose closed contacts pulled (:meth:`vtool.solvers.trace.Trace.tensile_forces`:
a release the back end missed) says so in the note column.

Newmark runs use its default refinement after events (steps of
dt / ``NewmarkOptions.refine`` for ``refine_periods`` periods of the highest
mode); one extra row shows the plain thesis scheme at 1 µs. Settings a back end refuses (a Newmark step beyond its stability
limit) are listed with the reason instead of figures. scipy rows depend on
the scipy and numpy versions and the CPU's BLAS kernels, which
:func:`library_versions` names.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from vtool.csvrows import csv_text
from vtool.errors import InputError, RunError
from vtool.files import write_atomic
from vtool.markdown import table as markdown_table
from vtool.solvers import backends
from vtool.solvers.model.spec import EXTERNAL, MechanismSpec
from vtool.solvers.run import simulate
from vtool.solvers.studies.pairing import pair_events
from vtool.solvers.trace import CLOSED, Trace

#: The knobs swept by default: steps and beta values of fixed-step back ends, tolerances of adaptive ones.
TIME_STEPS = (1e-4, 1e-5, 2e-6, 1e-6, 5e-7, 2e-7, 1e-7)  # s
BETAS = (1 / 6, 1 / 4)
RTOLS = (1e-4, 1e-6, 1e-8, 1e-9, 1e-10, 1e-11)
RESOLUTION_DEG = 0.1  # smallest pairing window: bursts of contacts microseconds apart move as a whole


@dataclass(frozen=True)
class AccuracyRow:
    backend: str
    setting: str
    wall_time: float | None = None  # s
    steps: int | None = None
    events: int | None = None
    unmatched_events: int | None = None
    event_angle_error: float | None = None  # deg, over paired events
    peak_force_error: float | None = None  # relative
    seating_velocity_error: float | None = None  # relative
    lift_error: float | None = None  # length
    note: str = ""


def library_versions() -> str:
    """What the scipy rows' last bits depend on: the numpy and scipy versions and the BLAS kernels
    chosen for this CPU, e.g. ``scipy 1.17.1, numpy 2.4.6, openblas Haswell``.

    A chattering run at a loose tolerance follows the last bits of its matrix
    products, which the BLAS kernels (AVX2 or AVX-512, picked at load time)
    set: the same versions on another CPU give another event sequence.
    """
    import scipy
    import scipy.linalg  # noqa: F401 (loads scipy's BLAS, so that threadpoolctl sees it)
    from threadpoolctl import threadpool_info

    kernels = sorted({f"{lib.get('internal_api')} {lib.get('architecture')}" for lib in threadpool_info()
                      if lib.get("user_api") == "blas"})
    return ", ".join([f"scipy {scipy.__version__}", f"numpy {np.__version__}", *kernels])


def with_run(spec: MechanismSpec, **changes: Any) -> MechanismSpec:
    """``spec`` with some of its RunSpec fields replaced (``None`` values are ignored)."""
    changes = {key: value for key, value in changes.items() if value is not None}
    return dataclasses.replace(spec, run=dataclasses.replace(spec.run, **changes))


def seat_clearance(spec: MechanismSpec) -> str | None:
    for c in spec.clearances:
        if c.kind == EXTERNAL and c.behind not in (spec.cam.coordinate, 0) and c.state == "enabled":
            return c.name
    return None


def relative_errors(values: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """|values / reference - 1| where the reference is positive, else 0."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(reference > 0, np.abs(values / reference - 1), 0.0)


def compare(trace: Trace, reference: Trace, backend: str, setting: str, note: str = "") -> AccuracyRow:
    """Errors of ``trace`` against the exact ``reference`` (see module doc)."""
    duration = float(reference.time[-1] - reference.time[0]) if reference.time.size else None
    resolution = RESOLUTION_DEG / (6.0 * reference.spec.run.rpm)  # s; 6 rpm = deg/s
    pairing = pair_events(reference.events, trace.events, duration, resolution)
    deltas = [abs(reference.events[i].cam_angle - trace.events[j].cam_angle) for i, j in pairing.pairs]
    peak = relative_errors(trace.peak_force, reference.peak_force)
    late, late_reference = trace.peak_force_after_first_revolution, reference.peak_force_after_first_revolution
    if late is not None and late_reference is not None:
        peak = np.maximum(peak, relative_errors(late, late_reference))
    tensile = trace.tensile_forces()
    if tensile.any():
        unit = trace.spec.unit_system.force
        pulled = ", ".join(f"{trace.force_label(int(k))} {tensile[k]:.3g} {unit}" for k in np.flatnonzero(tensile))
        note = "; ".join(n for n in (f"closed contacts pulled: {pulled}", note) if n)
    seat = seat_clearance(trace.spec)
    seating = None
    seat_pairs = [(i, j) for i, j in pairing.pairs
                  if reference.events[i].clearance == seat and reference.events[i].kind == CLOSED]
    if seat_pairs:
        i, j = seat_pairs[0]
        seating = abs(trace.events[j].relative_velocity / reference.events[i].relative_velocity - 1)
    valve = next(c.ahead for c in trace.spec.clearances if c.name == seat) if seat else None
    lift = None
    if valve is not None and trace.time.shape == reference.time.shape:
        lift = float(np.abs(trace.coordinate(valve) - reference.coordinate(valve)).max())
    stats = trace.statistics
    return AccuracyRow(backend, setting, stats.wall_time, stats.steps, stats.events, pairing.unmatched,
                       max(deltas) if deltas else None, float(peak.max()), seating, lift, note)


def accuracy_study(
    spec: MechanismSpec,
    time_steps: tuple[float, ...] = TIME_STEPS,
    betas: tuple[float, ...] = BETAS,
    rtols: tuple[float, ...] = RTOLS,
) -> tuple[Trace, list[AccuracyRow]]:
    """Run the reference back end, then every other installed back end at each of its settings
    (:meth:`~vtool.solvers.backends.Backend.accuracy_settings` from these knobs); return (reference, rows)."""
    reference_name = backends.with_flag("reference")[0]
    reference = simulate(with_run(spec, backend=reference_name))
    rows = [AccuracyRow(reference_name, "reference", reference.statistics.wall_time, reference.statistics.steps,
                        reference.statistics.events, 0, 0.0, 0.0, 0.0, 0.0)]
    knobs = backends.AccuracyKnobs(time_steps, betas, rtols)
    for name in backends.available():
        backend = backends.get(name)
        if backend.reference:
            continue
        for setting in backend.accuracy_settings(spec.run, knobs):
            note = library_versions() if backend.library_dependent else setting.note
            run = dataclasses.replace(setting.run, backend=name)
            try:
                trace = simulate(dataclasses.replace(spec, run=run), options=setting.options)
            except InputError as error:
                rows.append(AccuracyRow(name, setting.label, note=f"refused: {error.expected}"))
                continue
            except RunError as error:
                rows.append(AccuracyRow(name, setting.label, note=f"failed: {error}"))
                continue
            rows.append(compare(trace, reference, name, setting.label, note))
    return reference, rows


COLUMNS = ("backend", "setting", "wall time (s)", "steps", "events", "unmatched",
           "max |dtheta| (deg)", "peak force err (%)", "seating vel err (%)", "lift err (in)", "note")


def header(length_unit: str = "in") -> list[str]:
    return [c.replace("(in)", f"({length_unit})") for c in COLUMNS]


def fmt(value: float | None, spec: str, scale: float = 1.0) -> str:
    """``value * scale`` formatted; blank for None or NaN."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    return format(value * scale if scale != 1.0 else value, spec)


def cells(row: AccuracyRow) -> list[str]:
    """One table row: errors to two significant digits, wall time to 1 ms."""
    return [row.backend, row.setting, fmt(row.wall_time, ".3f"), fmt(row.steps, "d"), fmt(row.events, "d"),
            fmt(row.unmatched_events, "d"), fmt(row.event_angle_error, ".2g"), fmt(row.peak_force_error, ".2g", 100),
            fmt(row.seating_velocity_error, ".2g", 100), fmt(row.lift_error, ".2g"), row.note]


def table_text(rows: list[AccuracyRow], length_unit: str = "in") -> str:
    body = [cells(row) for row in rows]
    widths = [max(len(r[i]) for r in [header(length_unit), *body]) for i in range(len(COLUMNS) - 1)]
    lines = []
    for r in [header(length_unit), *body]:
        lines.append("  ".join(cell.ljust(w) for cell, w in zip(r[:-1], widths, strict=True)) + "  " + r[-1])
    return "\n".join(line.rstrip() for line in lines)


def markdown_header(length_unit: str = "in") -> list[str]:
    """The header with its pipes escaped for a Markdown table."""
    return [c.replace("|", "\\|") for c in header(length_unit)]


def table_markdown(rows: list[AccuracyRow], length_unit: str = "in") -> str:
    return markdown_table(markdown_header(length_unit), [cells(row) for row in rows]).rstrip("\n")


def write_table_csv(path: str, rows: list[AccuracyRow], length_unit: str = "in") -> None:
    write_atomic(path, csv_text([header(length_unit), *(cells(row) for row in rows)]), "--csv")
