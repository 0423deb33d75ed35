"""Per-run metrics of a valve-train trace: the numbers a speed sweep reports.

One function, :func:`run_metrics`, turns a :class:`~vtool.solvers.trace.Trace`
into a flat, ordered dict of numbers over one window of cam angle;
:func:`metric_columns` gives their names and units for a spec. ``vtool solve``,
``vtool sweep``, ``vtool compare``, ``vtool size`` and the TUI all evaluate the
same window (:func:`evaluation_window`):

* a run cycle by cycle (``run.cycles`` or ``run.steady``,
  :mod:`vtool.solvers.studies.steady`): its last cycle, the settled one;
* a plain run of ``degrees``: after the first revolution, cam angle 360 deg
  to the end (the whole run if it is shorter than that), which is not a
  steady state: :func:`window_text` says so.

The first revolution's start-up shock (the static start catching up with the
cam) is its own metrics, ``startup_*``.

Speed criteria from the lift event, for any cam (:class:`Criteria`):

* the **lift event** is where the cam's lift L(θ) (its Fourier series,
  :mod:`vtool.solvers.model.cam`) above its base circle exceeds the lash
  (the follower clearance on the base circle with the valve seated,
  :mod:`vtool.solvers.model.lash`; 0 without a seat) by more than
  ``LIFT_EVENT_FRACTION`` of the total lift: where the cam, not the seat,
  holds the train (a train with lash is off the cam on the base circle and
  on the ramps' foot by design). For the thesis' harmonic cam (1A) it is
  278 to 622 deg, every angle but 82 deg about the base point (270 deg);
  for the ramped cam, about +-60 deg about the nose at 0.
* the follower **leaves the cam** when the cam clearance is open during
  the lift event for more than ``run.jump_angle`` (deg, default 1) with a
  gap (follower minus cam, on the output rows) above ``run.jump_gap``
  (default ``GAP_FRACTION`` of the cam's total lift) inside the lift
  event: a numerical micro-separation (a fraction of a degree, or a gap at round-off) does not
  count.
* the valve **bounces** when it re-opens after seating (within
  ``BOUNCE_WINDOW_DEG``) by more than ``run.bounce_lift`` (default
  ``GAP_FRACTION`` of the cam's total lift), on the output rows.

Metrics (also in docs/sweep.md):

``cam_separations``
    Largest number, over the revolutions of the window, of intervals where
    the follower leaves the cam (counted in the revolution where they open,
    or where the window starts for one already open).
``cam_separation_angle`` (deg)
    The earliest such interval's opening, as an angle within its revolution
    (NaN if none).
``cam_separation_duration`` (deg)
    The longest such interval, cam angle from opening to closing (or to the
    window's end); 0 when there is none.
``cam_separation_gap`` (length)
    The largest gap of those intervals; 0 when there is none.
``lift_loss`` (length)
    max over output rows of the window of L_kin - L, where
    L = max(q_v - s, 0) is the valve's lift off its seat (q_v the seat
    clearance's ``ahead`` coordinate, s the seat position) and
    L_kin = max(r q_cam - s, 0) the kinematic lift of a train that keeps its
    static-start shape, with motion ratio r = q_v(0) / q_cam(0) from the first
    row (the static start). NaN without a seat.
``seating_velocity_max``, ``seating_velocity_mean`` (velocity)
    Approach speed (-d gap/dt before the impact) of the valve's impacts on the
    seat in the window: largest and mean (NaN without impacts).
``seat_bounces``
    Largest number, over the revolutions of the window, of seat bounces
    higher than ``bounce_lift`` (``Trace.seat_bounces``), counted in the
    revolution of the landing.
``bounce_height`` (length)
    Largest bounce height of those (0 without bounces, NaN without a seat).
``peak_F<i>`` (force)
    Largest contact force at each clearance in the window, over every step
    where the back end records it (a run cycle by cycle: its last cycle; a
    plain run: ``Trace.peak_force_after_first_revolution``), else on the
    output rows; NaN for a removed clearance.
``spring_margin`` (force)
    Smallest cam contact force on the output rows of the window during the
    lift event while the cam clearance is closed: how much spring force is
    left before the follower leaves the cam (NaN when never in contact there).
``startup_peak_force`` (force), ``startup_seating_velocity`` (velocity)
    The start-up shock: the largest contact force at any clearance and the
    largest seating velocity in the first revolution (every step where the
    back end records it).
``cycles``, ``cycle_change``
    Cycles run (0 for a plain run) and the relative change of the last cycle
    (NaN for a plain run); see :class:`~vtool.solvers.trace.Cycles`.
``events``
    Events (configuration changes) in the whole run.
``wall_time`` (s)
    Wall time of the back end's run (not deterministic: kept out of files
    that are compared).
``<quantity>_order_<k>`` (the quantity's unit)
    For each quantity in ``run.orders`` (``F7``, ``q7``, ``q1-q9``): its
    amplitude at cam order k = 1 .. ``run.highest_order`` (default 24) over
    the whole cycles of the window (:mod:`vtool.solvers.studies.orders`;
    NaN above the Nyquist order of the output interval).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from vtool.errors import InputError
from vtool.solvers.model.configurations import clearance_bit
from vtool.solvers.model.spec import EXTERNAL, REMOVED, CamSpec, MechanismSpec, RunSpec
from vtool.solvers.studies.orders import order_column, quantity_unit, spectrum
from vtool.solvers.studies.window import REVOLUTION, evaluation_window, window_text
from vtool.solvers.trace import CLOSED, Trace

__all__ = ["evaluation_window", "window_text"]  # (the window is shared with vtool.solvers.studies.orders)
NAN = float("nan")
#: the lift event: lift above the base circle by more than this share of the total lift
LIFT_EVENT_FRACTION = 5e-3
#: default gap (leaves the cam) and bounce lift: this share of the cam's total lift
GAP_FRACTION = 1e-3
#: the lift event's resolution (bins per revolution)
EVENT_BINS = 3600
_NO_RUN = RunSpec(rpm=1.0, degrees=1.0, time_step=1.0)  # the run settings of a model's key

#: metrics whose values depend on the machine, not the model
TIMING_METRICS = ("wall_time",)


def cam_index(spec: MechanismSpec) -> int:
    return next(i for i, c in enumerate(spec.clearances) if c.behind == spec.cam.coordinate)


def seat_index(spec: MechanismSpec) -> int | None:
    if spec.seat is None:
        return None
    for i, c in enumerate(spec.clearances):
        if c.kind == EXTERNAL and c.behind == spec.seat.coordinate and c.state != REMOVED:
            return i
    return None


def force_label(spec: MechanismSpec, index: int) -> str:
    return spec.force_label(index)


# ----- the lift event and the criteria -----

@lru_cache(maxsize=32)
def _lift(cam: CamSpec) -> np.ndarray:
    from vtool.solvers.model.cam import derivatives, lift_series

    c0, a, b = lift_series(cam)
    theta = np.radians((np.arange(EVENT_BINS) + 0.5) * REVOLUTION / EVENT_BINS)
    return derivatives(c0, a, b, theta)[0]


def total_lift(cam: CamSpec) -> float:
    """The cam's total lift (length): max - min of its lift law."""
    lift = _lift(cam)
    return float(lift.max() - lift.min())


def _lash(spec: MechanismSpec) -> float:
    """The follower clearance on the base circle with the valve seated (:mod:`vtool.solvers.model.lash`;
    0 without a seat, or when the seat holds the valve off the cam nowhere)."""
    if seat_index(spec) is None:
        return 0.0
    model = dataclasses.replace(spec, run=_NO_RUN, title="", notes="")  # the model alone: one lash per model
    try:
        return _lash_of(model)
    except TypeError:  # an unhashable spec (built by hand with lists)
        return _lash_of.__wrapped__(model)


@lru_cache(maxsize=32)
def _lash_of(spec: MechanismSpec) -> float:
    from vtool.solvers.model.lash import base_and_ratio

    base, ratio = base_and_ratio(spec)
    return max(ratio * spec.seat.position - base, 0.0) if spec.seat is not None else 0.0


def lift_event_bins(spec: MechanismSpec) -> np.ndarray:
    """Per bin of ``360 / EVENT_BINS`` deg: whether it lies in the lift event (see the module doc)."""
    return _event_bins(spec.cam, _lash(spec))


@lru_cache(maxsize=32)
def _event_bins(cam: CamSpec, lash: float) -> np.ndarray:
    lift = _lift(cam) - _lift(cam).min()
    return lift - lash > LIFT_EVENT_FRACTION * max(float(lift.max()), 1e-300)


def lift_event(spec: MechanismSpec, inside: np.ndarray | None = None) -> tuple[float, float]:
    """(start, end) of the lift event in deg, start in [0, 360), end > start (it may pass 360)."""
    inside = lift_event_bins(spec) if inside is None else inside
    if inside.all():
        return 0.0, REVOLUTION
    step = REVOLUTION / EVENT_BINS
    starts = np.flatnonzero(inside & ~np.roll(inside, 1))
    ends = np.flatnonzero(~inside & np.roll(inside, 1))
    best = (0.0, 0.0)
    for s in starts:  # the longest run of bins in the event (a cam has one lift event)
        e = ends[ends > s][0] if np.any(ends > s) else ends[0] + EVENT_BINS
        if (e - s) * step > best[1] - best[0]:
            best = (s * step, e * step)
    return best


def in_lift_event(inside: np.ndarray, start_deg: float, end_deg: float) -> float:
    """Degrees of [start_deg, end_deg] (absolute cam angles) inside the lift event (``inside``:
    :func:`lift_event_bins`)."""
    if end_deg <= start_deg:
        return 0.0
    step = REVOLUTION / EVENT_BINS
    first, last = math.floor(start_deg / step), math.ceil(end_deg / step)
    bins = np.arange(first, last)
    widths = np.minimum((bins + 1) * step, end_deg) - np.maximum(bins * step, start_deg)
    return float(np.sum(widths[inside[bins % EVENT_BINS]]))


@dataclass(frozen=True)
class Criteria:
    """The thresholds of the speed criteria (see the module doc), lengths in the spec's unit."""

    jump_angle: float  # deg
    jump_gap: float
    bounce_lift: float
    lift_event: tuple[float, float]  # deg
    bins: np.ndarray = field(repr=False, compare=False)  # lift_event_bins

    @classmethod
    def of(cls, spec: MechanismSpec) -> Criteria:
        r = spec.run
        default = GAP_FRACTION * total_lift(spec.cam)
        bins = lift_event_bins(spec)
        return cls(r.jump_angle, default if r.jump_gap is None else r.jump_gap,
                   default if r.bounce_lift is None else r.bounce_lift, lift_event(spec, bins), bins)

    def text(self, length: str) -> str:
        start, end = self.lift_event
        return (f"criteria: the follower leaves the cam when its contact is open > {self.jump_angle:g} deg with a "
                f"gap > {self.jump_gap:.3g} {length} during the lift event ({start:g} to {end:g} deg); the "
                f"valve bounces when it re-opens > {self.bounce_lift:.3g} {length} after seating")

    def as_dict(self, length: str) -> dict[str, float | str]:
        return {"jump_angle_deg": self.jump_angle, "jump_gap": self.jump_gap, "jump_gap_unit": length,
                "bounce_lift": self.bounce_lift, "bounce_lift_unit": length,
                "lift_event_start_deg": self.lift_event[0], "lift_event_end_deg": self.lift_event[1]}


def metric_columns(spec: MechanismSpec) -> list[tuple[str, str]]:
    """(name, unit) of every metric, in report order; ``""`` for counts."""
    u = spec.unit_system
    columns = [
        ("cam_separations", ""),
        ("cam_separation_angle", "deg"),
        ("cam_separation_duration", "deg"),
        ("cam_separation_gap", u.length),
        ("lift_loss", u.length),
        ("seating_velocity_max", u.velocity),
        ("seating_velocity_mean", u.velocity),
        ("seat_bounces", ""),
        ("bounce_height", u.length),
    ]
    columns += [(f"peak_{force_label(spec, i)}", u.force) for i in range(len(spec.clearances))]
    columns += [("spring_margin", u.force), ("startup_peak_force", u.force), ("startup_seating_velocity", u.velocity),
                ("cycles", ""), ("cycle_change", ""), ("events", ""), ("wall_time", "s")]
    if spec.springs:  # data-sheet springs (vtool.solvers.model.spring): <= 0 when coils touch
        columns.append(("coil_bind_margin", u.length))
    if any(s.contacts for s in spec.springs):  # coil contacts: the first clash in the window and its peak force
        columns += [("coil_bind_angle", "deg"), ("coil_contact_peak_force", u.force)]
    return columns + order_columns(spec)


def order_columns(spec: MechanismSpec) -> list[tuple[str, str]]:
    """The amplitude of every ``run.orders`` quantity at cam orders 1..``run.highest_order`` (its unit)."""
    return [(order_column(q, k), quantity_unit(spec, q)) for q in spec.run.orders
            for k in range(1, spec.run.highest_order + 1)]


# ----- intervals -----

def open_intervals(trace: Trace, index: int, window: tuple[float, float]) -> list[tuple[float, float]]:
    """(opening, closing) cam angles (deg) where clearance ``index`` is open within the window, from its
    events (exact angles) and its state at the window's first row; clipped to the window."""
    start, end = window
    bit = clearance_bit(trace.spec, index)
    name = trace.spec.clearances[index].name
    rows = np.flatnonzero(trace.cam_angle >= start)
    if not len(rows):
        return []
    first = rows[0]
    # the state at the window's start: the row's configuration, unless an event at the same angle follows
    opened_at: float | None = start if not trace.configuration[first] & bit else None
    intervals = []
    for e in trace.events:
        if e.clearance != name or e.cam_angle < start or e.cam_angle > end:
            continue
        if e.cam_angle == start:  # the row may show either side of an event at the window's edge
            opened_at = None if e.after & bit else start
            continue
        if e.after & bit and opened_at is not None:
            intervals.append((opened_at, e.cam_angle))
            opened_at = None
        elif not e.after & bit and opened_at is None:
            opened_at = e.cam_angle
    if opened_at is not None and opened_at < end:
        intervals.append((opened_at, end))
    return intervals


def _during_lift(trace: Trace, inside: np.ndarray) -> np.ndarray:
    """Per output row: whether its cam angle lies in the lift event (``inside``: :func:`lift_event_bins`)."""
    bins = np.floor(np.mod(trace.cam_angle, REVOLUTION) / (REVOLUTION / EVENT_BINS)).astype(int) % EVENT_BINS
    return inside[bins]


def _largest(values: np.ndarray, angles: np.ndarray, a: float, b: float) -> float:
    inside = (angles >= a) & (angles <= b)
    return float(values[inside].max()) if inside.any() else 0.0


def leaves_the_cam(trace: Trace, window: tuple[float, float], criteria: Criteria) -> list[tuple[float, float, float]]:
    """(opening, closing, largest gap) of every interval in the window where the follower leaves the cam."""
    spec = trace.spec
    cam = cam_index(spec)
    c = spec.clearances[cam]
    if c.state == REMOVED:
        return []
    gap = trace.coordinate(c.ahead) - trace.coordinate(c.behind)
    during = _during_lift(trace, criteria.bins)
    result = []
    for a, b in open_intervals(trace, cam, window):
        if in_lift_event(criteria.bins, a, b) <= criteria.jump_angle:
            continue
        height = _largest(np.where(during, gap, 0.0), trace.cam_angle, a, b)
        if height > criteria.jump_gap:
            result.append((a, b, height))
    return result


def _per_revolution(angles: list[float]) -> int:
    counts: dict[int, int] = {}
    for angle in angles:
        counts[int(angle // REVOLUTION)] = counts.get(int(angle // REVOLUTION), 0) + 1
    return max(counts.values(), default=0)


def _cam_separation(trace: Trace, window: tuple[float, float], criteria: Criteria) -> dict[str, float]:
    intervals = leaves_the_cam(trace, window, criteria)
    return {"cam_separations": _per_revolution([a for a, _, _ in intervals]),
            "cam_separation_angle": min((a % REVOLUTION for a, _, _ in intervals), default=NAN),
            "cam_separation_duration": max((b - a for a, b, _ in intervals), default=0.0),
            "cam_separation_gap": max((h for _, _, h in intervals), default=0.0)}


def _seatings(trace: Trace, index: int, window: tuple[float, float]) -> list[float]:
    name = trace.spec.clearances[index].name
    return [-e.relative_velocity for e in trace.events
            if e.clearance == name and e.kind == CLOSED and window[0] <= e.cam_angle < window[1]]


def _seat_metrics(trace: Trace, index: int | None, window: tuple[float, float], criteria: Criteria) -> dict[str, float]:
    spec = trace.spec
    result = _seat_motion(trace, index, window) | {"seat_bounces": 0, "bounce_height": NAN}
    if index is None or spec.seat is None:
        return result
    clearance = spec.clearances[index]
    bounces = [b for b in trace.seat_bounces(clearance.name)
               if window[0] <= b[1] <= window[1] and b[2] > criteria.bounce_lift]
    result["seat_bounces"] = _per_revolution([landing for _, landing, _ in bounces])
    result["bounce_height"] = max((height for _, _, height in bounces), default=0.0)
    return result


def _seat_motion(trace: Trace, index: int | None, window: tuple[float, float]) -> dict[str, float]:
    """The lift loss and the seating velocities in the window (NaN without a seat or a seating)."""
    spec = trace.spec
    result = {"lift_loss": NAN, "seating_velocity_max": NAN, "seating_velocity_mean": NAN}
    if index is None or spec.seat is None:
        return result
    clearance = spec.clearances[index]
    s = spec.seat.position
    valve = trace.coordinate(clearance.ahead)
    cam = trace.coordinate(spec.cam.coordinate)
    rows = (trace.cam_angle >= window[0]) & (trace.cam_angle <= window[1])
    if len(valve) and rows.any():
        ratio = valve[0] / cam[0] if cam[0] != 0.0 else spec.initial.lever_ratio
        lift = np.maximum(valve - s, 0.0)
        kinematic = np.maximum(ratio * cam - s, 0.0)
        result["lift_loss"] = float(np.max((kinematic - lift)[rows]))
    speeds = _seatings(trace, index, window)
    if speeds:
        result["seating_velocity_max"] = float(max(speeds))
        result["seating_velocity_mean"] = float(np.mean(speeds))
    return result


def _peaks(trace: Trace, window: tuple[float, float]) -> np.ndarray:
    """Every-step peak forces in the window where the trace has them, else the output rows' largest."""
    if trace.cycles is not None:
        return trace.cycles.peaks
    if window[0] == REVOLUTION and trace.peak_force_after_first_revolution is not None:
        return trace.peak_force_after_first_revolution
    if window[0] == 0.0:
        return trace.peak_force
    rows = (trace.cam_angle >= window[0]) & (trace.cam_angle <= window[1])
    return trace.contact_force[rows].max(axis=0) if rows.any() else np.full(len(trace.spec.clearances), NAN)


def _startup(trace: Trace, seat: int | None) -> dict[str, float]:
    """The start-up shock (first revolution): largest force at any clearance and seating velocity."""
    spec = trace.spec
    used = [i for i, c in enumerate(spec.clearances) if c.state != REMOVED]
    if trace.cycles is not None:
        peaks = trace.cycles.startup_peaks
    else:
        rows = trace.cam_angle < REVOLUTION
        peaks = trace.contact_force[rows].max(axis=0) if rows.any() else np.zeros(len(spec.clearances))
        late = trace.peak_force_after_first_revolution
        if late is not None:  # a whole-run peak above the later one happened in the first revolution
            peaks = np.where(trace.peak_force > late, trace.peak_force, peaks)
        elif not np.any(trace.cam_angle > REVOLUTION):  # the run is its first revolution
            peaks = trace.peak_force
    speeds = _seatings(trace, seat, (0.0, REVOLUTION)) if seat is not None else []
    return {"startup_peak_force": float(np.max(peaks[used])) if used else NAN,
            "startup_seating_velocity": float(max(speeds)) if speeds else NAN}


def _peak_metrics(trace: Trace, peaks: np.ndarray) -> dict[str, float]:
    spec = trace.spec
    return {f"peak_{force_label(spec, i)}": NAN if c.state == REMOVED else float(peaks[i])
            for i, c in enumerate(spec.clearances)}


def settling_metrics(trace: Trace, window: tuple[float, float]) -> dict[str, float]:
    """The metrics by which a run's cycle is compared with another (:func:`vtool.solvers.studies.steady.cycle_change`):
    the peak forces, the lift loss and the largest seating velocity, each as :func:`run_metrics` gives it (the
    same functions), without the rest of its work (the cam separations, the coil-bind margin, a spectrum)."""
    seat = _seat_motion(trace, seat_index(trace.spec), window)
    return _peak_metrics(trace, _peaks(trace, window)) | {"lift_loss": seat["lift_loss"],
                                                          "seating_velocity_max": seat["seating_velocity_max"]}


def run_metrics(trace: Trace, window: tuple[float, float] | None = None) -> dict[str, float]:
    """The metrics of one run over ``window`` (default :func:`evaluation_window`), keyed as
    :func:`metric_columns`."""
    spec = trace.spec
    window = evaluation_window(trace) if window is None else window
    criteria = Criteria.of(spec)
    cam = cam_index(spec)
    seat = seat_index(spec)
    metrics: dict[str, float] = {}
    metrics.update(_cam_separation(trace, window, criteria))
    metrics.update(_seat_metrics(trace, seat, window, criteria))
    peaks = _peaks(trace, window)
    metrics.update(_peak_metrics(trace, peaks))
    rows = (trace.cam_angle >= window[0]) & (trace.cam_angle <= window[1])
    during = rows & _during_lift(trace, criteria.bins)
    in_contact = during & ((trace.configuration & clearance_bit(spec, cam)) != 0)
    metrics["spring_margin"] = float(trace.contact_force[in_contact, cam].min()) if in_contact.any() else NAN
    metrics.update(_startup(trace, seat))
    metrics["cycles"] = trace.cycles.count if trace.cycles is not None else 0
    metrics["cycle_change"] = trace.cycles.change if trace.cycles is not None else NAN
    metrics["events"] = trace.statistics.events
    metrics["wall_time"] = trace.statistics.wall_time
    if spec.springs:
        from vtool.solvers.model.spring import coil_bind_margin

        metrics["coil_bind_margin"] = coil_bind_margin(spec.springs, trace, rows)
    contacts = [spec.clearances.index(spec.clearance(name)) for s in spec.springs for name in s.contacts]
    if contacts:  # the first coil contact closing in the window (NaN: none) and the largest coil contact force
        closings = [e.cam_angle for e in trace.events if e.kind == "closed" and e.clearance in
                    {spec.clearances[k].name for k in contacts} and window[0] <= e.cam_angle <= window[1]]
        metrics["coil_bind_angle"] = min(closings) if closings else NAN
        metrics["coil_contact_peak_force"] = float(max(peaks[k] for k in contacts))
    for quantity in spec.run.orders:  # over the whole cycles of the evaluated window (NaN: none to analyse)
        try:
            orders = spectrum(trace, quantity)
        except InputError:
            orders = None
        for k in range(1, spec.run.highest_order + 1):
            metrics[order_column(quantity, k)] = (orders.amplitude_of(k) if orders is not None
                                                  and k <= orders.nyquist else NAN)
    return metrics


def failed_metrics(spec: MechanismSpec) -> dict[str, float]:
    """All metrics NaN (a run that failed), with the same keys."""
    return {name: NAN for name, _ in metric_columns(spec)}


def evaluation_summary(trace: Trace) -> dict:
    """What a run's summary adds: the window, the criteria, and the window's and the start-up's metrics,
    as lines of text and as JSON-ready values (units as ``*_unit`` keys, NaN as None)."""
    spec = trace.spec
    units = dict(metric_columns(spec))
    metrics = run_metrics(trace)
    criteria = Criteria.of(spec)
    start, end = evaluation_window(trace)

    def shown(name: str) -> str:
        value = metrics[name]
        text = "-" if isinstance(value, float) and math.isnan(value) else f"{value:.6g}"
        return f"{name} {text}{' ' + units[name] if units[name] else ''}"

    window = ["cam_separations", "cam_separation_angle", "cam_separation_duration", "seat_bounces",
              "seating_velocity_max", "lift_loss"] + [n for n in units if n.startswith("peak_")]
    lines = [window_text(trace), criteria.text(spec.unit_system.length),
             "in the window: " + ", ".join(shown(n) for n in window),
             "start-up shock (first revolution): " + ", ".join(shown(n) for n in ("startup_peak_force",
                                                                               "startup_seating_velocity"))]
    values = {n: (None if isinstance(v, float) and math.isnan(v) else v) for n, v in metrics.items()
              if n != "wall_time"}
    return {"lines": lines, "window_deg": [start, end], "text": lines[0],
            "settled": None if trace.cycles is None else trace.cycles.settled,
            "criteria": criteria.as_dict(spec.unit_system.length),
            "metrics": values | {f"{n}_unit": units[n] for n in values if units.get(n)}}

