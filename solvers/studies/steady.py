"""Runs to steady state: cam cycle after cam cycle, until the cycle's start state and metrics settle.

With ``run.cycles = N`` a run is N cam cycles (360 deg each); with
``run.steady = { tolerance, max_cycles }`` it goes on cycle by cycle until
the change from one cycle to the next (:func:`cycle_change`) is at most the
tolerance, or stops after ``max_cycles`` and says it did not settle and by
how much the last cycle still moved. The metrics cover the last cycle
(:mod:`vtool.solvers.studies.metrics`).

How a run continues: each cycle is one back-end run of 360 deg started from
the state at the previous cycle's end (:meth:`Mechanism.with_start
<vtool.solvers.model.mechanism.Mechanism.with_start>`: the cam is periodic in
360 deg, so the state at its end is a start at cam angle zero). Every back
end starts from the mechanism's ``start`` and the contact problem's start
mask, so every back end continues a run unchanged (the Python layer only;
the compiled kernel is untouched); a cycle continued so equals the same
cycle of one long run to 1e-11 of the motion (newmark, exact; 1A at 5,000
rev/min) and 1e-8 (scipy, its own tolerance), and to about 1e-6 where
events follow (the step grid restarts at each cycle: 1A at 9,000). What a continuation does not carry: a chattering
contact's stick counters and a Hertz contact's approach velocity (both
re-derived at the next event).

The change from cycle k-1 to cycle k is the largest of

* the state at the cycle's start: max |Δq| over the elastic coordinates
  relative to the cycle's largest |q|, and likewise for q̇;
* the cycle's metrics: every clearance's peak force relative to the
  cycle's largest peak force; the lift loss relative to the cam's total
  lift; the largest seating velocity relative to the cam's velocity scale
  (total lift times the cam speed in rad/s). A metric that appears or
  disappears (NaN on one side) counts as a change of 1.

and the events per clearance must be the same in both cycles. A run whose
cycle-to-cycle change does not settle is also compared with the cycle 2 to
``MAX_PERIOD`` (4) cycles before: a train that repeats every p cycles (a
subharmonic orbit: 1A at 15,000 rev/min alternates 24 and 22 events a
cycle) has settled with period p, and its last p cycles are evaluated (its
spectrum then has orders in steps of 1/p). A run that neither settles nor
repeats stops after ``max_cycles`` and says by how much its last cycle
still moved and how its events per clearance changed.

A periodic start (:class:`State`): a sweep carries the state at the end of
a point's last cycle to the next point, velocities scaled by the ratio of
the cam speeds and accelerations by its square (the state of a train
moving with its cam); benchmarks/bench_steady.py measures the cycles saved.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.studies.metrics import settling_metrics, total_lift
from vtool.solvers.trace import MAX_PERIOD, Cycles, Event, RunStatistics, Trace

#: run.steady's defaults
DEFAULT_TOLERANCE = 1e-3
DEFAULT_MAX_CYCLES = 30
REVOLUTION = 360.0


@dataclass(frozen=True)
class State:
    """A run's state at a cam cycle's start (cam angle zero): the elastic coordinates, their velocities and
    accelerations, the configuration, and the cam speed (rad/s) it was reached at."""

    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    mask: int
    omega: float
    states: np.ndarray | None = None  # the nonlinear elements' states (an HLA's chamber pressure)

    @classmethod
    def at_end(cls, trace: Trace, omega: float) -> State:
        n = trace.spec.n_coordinates
        states = None if trace.states is None else trace.states[-1].copy()
        return cls(trace.q[-1, :n].copy(), trace.qd[-1, :n].copy(), trace.qdd[-1, :n].copy(),
                   int(trace.configuration[-1]), omega, states)

    def start(self, mechanism: Mechanism) -> Mechanism:
        """``mechanism`` started from this state, scaled to its cam speed."""
        ratio = mechanism.omega / self.omega if self.omega > 0 else 1.0
        return mechanism.with_start(self.q, self.qd * ratio, self.qdd * ratio**2, self.mask, self.states)


def is_cyclic(spec: Any) -> bool:
    """Whether the spec's run goes cycle by cycle (run.cycles or run.steady)."""
    return spec.run.cycles > 0 or spec.run.steady_tolerance > 0


def with_steady(spec: Any) -> Any:
    """The spec run to steady state (run.steady's defaults) unless it already runs cycle by cycle."""
    if is_cyclic(spec):
        return spec
    return dataclasses.replace(spec, run=dataclasses.replace(spec.run, steady_tolerance=DEFAULT_TOLERANCE,
                                                             steady_max_cycles=DEFAULT_MAX_CYCLES))


def steady_text(spec: Any) -> str:
    """How the spec's runs are evaluated: one line."""
    r = spec.run
    if r.cycles:
        return f"each run: {r.cycles} cam cycles, the last evaluated"
    if r.steady_tolerance:
        return (f"each run: cycle by cycle to steady state (tolerance {r.steady_tolerance:g}, at most "
                f"{r.steady_max_cycles} cycles), the last cycle evaluated")
    return f"each run: {r.degrees:g} deg, evaluated after the first revolution (not checked for a steady state)"


def max_cycles(spec: Any) -> int:
    r = spec.run
    return r.cycles if r.cycles > 0 else (r.steady_max_cycles or DEFAULT_MAX_CYCLES)


def run_degrees(spec: Any) -> float:
    """Degrees the run may cover (the cost estimate's): its cycles, or ``degrees`` for a plain run."""
    return REVOLUTION * max_cycles(spec) if is_cyclic(spec) else spec.run.degrees


def _relative(a: float, b: float, scale: float) -> float:
    if math.isnan(a) and math.isnan(b):
        return 0.0
    if math.isnan(a) or math.isnan(b):
        return 1.0
    return abs(a - b) / max(scale, 1e-300)


def _event_counts(trace: Trace) -> dict[str, int]:
    counts = {c.name: 0 for c in trace.spec.clearances}
    for e in trace.events:
        counts[e.clearance] += 1
    return counts


@dataclass(frozen=True)
class _Measures:
    """What :func:`cycle_change` compares of one cycle's run: its :func:`settling_metrics` over the cycle,
    its elastic coordinates' and velocities' largest magnitudes and start values, its events per clearance."""

    metrics: dict[str, float]
    largest: dict[str, float]  # "q", "qd": the largest magnitude over the run
    start: dict[str, np.ndarray]  # "q", "qd": the first row
    events: dict[str, int]

    @classmethod
    def of(cls, trace: Trace) -> _Measures:
        n = trace.spec.n_coordinates
        largest, start = {}, {}
        for data in ("q", "qd"):
            values = getattr(trace, data)[:, :n]
            largest[data] = float(np.abs(values).max())
            start[data] = values[0]
        return cls(settling_metrics(trace, (0.0, REVOLUTION)), largest, start, _event_counts(trace))


class Measured:
    """Each cycle's :class:`_Measures`, made once (by the trace's id: the caller keeps the traces alive): a
    run of cycles compares each cycle with the one before and up to MAX_PERIOD more."""

    def __init__(self) -> None:
        self.kept: dict[int, _Measures] = {}

    def __call__(self, trace: Trace) -> _Measures:
        if id(trace) not in self.kept:
            self.kept[id(trace)] = _Measures.of(trace)
        return self.kept[id(trace)]


def cycle_change(before: Trace, after: Trace, measured: Measured | None = None) -> tuple[float, str, str]:
    """The largest relative change of the continuous measures from one cycle's run to another (see the
    module doc), what it is, and how the events per clearance differ ("" when they are the same).
    ``measured`` keeps each run's measures (see :class:`Measured`)."""
    spec = after.spec
    a, b = (_Measures.of(before), _Measures.of(after)) if measured is None else (measured(before), measured(after))
    changes: dict[str, float] = {}
    for name, data in (("start displacements", "q"), ("start velocities", "qd")):
        scale = max(a.largest[data], b.largest[data], 1e-300)
        changes[name] = float(np.abs(b.start[data] - a.start[data]).max()) / scale
    m0, m1 = a.metrics, b.metrics
    peaks = [k for k in m1 if k.startswith("peak_")]
    force_scale = max([abs(m1[k]) for k in peaks if not math.isnan(m1[k])] + [1e-300])
    for k in peaks:
        changes[k] = _relative(m0[k], m1[k], force_scale)
    lift = total_lift(spec.cam)
    omega = spec.run.omega
    changes["lift_loss"] = _relative(m0["lift_loss"], m1["lift_loss"], lift)
    changes["seating_velocity_max"] = _relative(m0["seating_velocity_max"], m1["seating_velocity_max"], lift * omega)
    what = max(changes, key=lambda k: changes[k])
    c0, c1 = a.events, b.events
    events = ", ".join(f"{k} {c0[k]} -> {c1[k]}" for k in c1 if c0[k] != c1[k])
    return changes[what], what, events


def _periodic(traces: list[Trace], tolerance: float,
              measured: Measured | None = None) -> tuple[int, float, str, str] | None:
    """(period, change, what, events) of the shortest period p = 2 .. MAX_PERIOD over which the last cycle
    repeats the one p cycles before it (the first cycle, the start-up, left out), or None."""
    for period in range(2, MAX_PERIOD + 1):
        if len(traces) - 1 - period < 1:
            break
        change, what, events = cycle_change(traces[-1 - period], traces[-1], measured)
        if not events and change <= tolerance:
            return period, change, what, events
    return None


def _shifted(trace: Trace, k: int, period: float, skip_first: bool) -> tuple[slice, list[Event]]:
    rows = slice(1 if skip_first else 0, None)
    seconds, degrees = k * period, k * REVOLUTION
    events = [e.shifted(seconds, degrees) for e in trace.events]
    return rows, events


def concatenate(traces: list[Trace], spec: Any, omega: float, cycles: Cycles) -> Trace:
    """One trace of consecutive cycle runs: times and angles shifted by whole cycles, the first row of every
    cycle after the first left out (it is the previous cycle's last), events, peaks and statistics joined."""
    period = 2 * math.pi / omega
    parts = [_shifted(t, k, period, k > 0) for k, t in enumerate(traces)]

    def join(name: str) -> np.ndarray:
        return np.concatenate([getattr(t, name)[rows] for t, (rows, _) in zip(traces, parts, strict=True)])

    time = np.concatenate([t.time[rows] + k * period for k, (t, (rows, _)) in enumerate(zip(traces, parts,
                                                                                             strict=True))])
    angle = np.concatenate([t.cam_angle[rows] + k * REVOLUTION for k, (t, (rows, _)) in enumerate(zip(traces, parts,
                                                                                                      strict=True))])
    events = tuple(e for _, evs in parts for e in evs)
    first = traces[0].statistics
    stats = RunStatistics(first.backend, sum(t.statistics.steps for t in traces), len(events),
                          sum(t.statistics.wall_time for t in traces),
                          tuple(sorted({c for t in traces for c in t.statistics.configurations_built})),
                          dict(first.settings, degrees=REVOLUTION * len(traces), cycles=len(traces)),
                          compile_time=sum(t.statistics.compile_time for t in traces))
    peak = np.max([t.peak_force for t in traces], axis=0)
    late = np.max([t.peak_force for t in traces[1:]], axis=0) if len(traces) > 1 else None
    overlaps = [t.peak_overlap for t in traces if t.peak_overlap is not None]
    states = join("states") if traces[0].states is not None else None
    return Trace(spec, time, angle, traces[0].coordinate_numbers, join("q"), join("qd"), join("qdd"),
                 join("contact_force"), join("configuration"), events, peak, stats,
                 peak_force_after_first_revolution=late,
                 peak_overlap=np.max(overlaps, axis=0) if overlaps else None, cycles=cycles, states=states)


def simulate_cycles(backend: Any, mechanism: Mechanism, *, every_step: bool = False,
                    progress: Callable[[float], None] | None = None, cancel: Callable[[], bool] | None = None,
                    start: State | None = None, on_state: Callable[[State], None] | None = None) -> Trace:
    """Run ``mechanism`` cycle by cycle (its spec's run.cycles or run.steady) on ``backend``; see the module
    doc. ``start`` is a periodic start (default: the static start); ``on_state`` receives the state at the
    last cycle's end (for the next sweep point's start)."""
    spec = mechanism.spec
    run = spec.run
    fixed = run.cycles > 0
    limit = max_cycles(spec)
    tolerance = 0.0 if fixed else run.steady_tolerance
    one = dataclasses.replace(run, degrees=REVOLUTION)
    base = mechanism.with_run(one)
    options = backend.options_from_run(one, every_step)
    current = base if start is None else start.start(base)
    traces: list[Trace] = []
    measured = Measured()  # each cycle's measures, by id (traces holds them)
    changes = [math.nan]
    change, changed, events = math.nan, "", ""
    settled: bool | None = None if fixed else False
    period = 1
    for k in range(limit):
        part = None if progress is None else (lambda f, k=k: progress((k + f) / limit))
        trace = backend.simulate(current, options, progress=part if backend.supports_progress else None,
                                 cancel=cancel if backend.supports_cancel else None)
        traces.append(trace)
        if k > 0:
            change, changed, events = cycle_change(traces[-2], trace, measured)
            changes.append(math.inf if events else change)
            if not fixed and not events and change <= tolerance:
                settled = True
                break
            repeating = None if fixed else _periodic(traces, tolerance, measured)
            if repeating is not None:
                period, change, changed, events = repeating
                settled = True
                break
        state = State.at_end(trace, base.omega)
        current = state.start(base)
    if on_state is not None:
        on_state(State.at_end(traces[-1], base.omega))
    peaks = np.max([t.peak_force for t in traces[-period:]], axis=0)
    startup = traces[0].peak_force.copy() if start is None else np.full_like(traces[0].peak_force, math.nan)
    cycles = Cycles(len(traces), settled, tolerance, change, changed, tuple(changes), peaks, startup,
                    max_cycles=limit, period=period, events_changed=events)
    return concatenate(traces, spec, base.omega, cycles)
