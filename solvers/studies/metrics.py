"""Per-run metrics of a valve-train trace: the numbers a speed sweep reports.

One function, :func:`run_metrics`, turns a :class:`~vtool.solvers.trace.Trace`
into a flat, ordered dict of numbers; :func:`metric_columns` gives their names
and units for a spec. ``vtool sweep`` reports them per point, and a single
``vtool solve`` run gives the same numbers from the same trace. Definitions
(also in docs/sweep.md); "after the first revolution" means cam angle
>= 360 deg to the end of the run, revolution k covering [360 k, 360 (k+1)):

``cam_separations``
    Largest number, over the revolutions after the first, of cam-clearance
    separation episodes (``Trace.episodes``: a burst of events that leaves
    the clearance open) that start above mid-stroke (a lift table's cam: where
    its lift is above half its stroke): cam angle mod 360 in
    (0, 180) deg, where the harmonic cam q_cam = A sin(theta) + offset is
    above its offset and decelerating the follower. One or more means the
    follower leaves the cam (jump).
``cam_separation_angle`` (deg)
    The earliest such separation, as an angle within its revolution (NaN if
    none).
``cam_separation_duration`` (deg)
    The longest such separation: cam angle from the separation to the next
    cam impact (or to the end of the run); 0 when there is none.
``lift_loss`` (length)
    max over output rows after the first revolution of L_kin - L, where
    L = max(q_v - s, 0) is the valve's lift off its seat (q_v the seat
    clearance's ``ahead`` coordinate, s the seat position) and
    L_kin = max(r q_cam - s, 0) the kinematic lift of a train that keeps its
    static-start shape, with motion ratio r = q_v(0) / q_cam(0) from the first
    row (the static start). NaN without a seat.
``seating_velocity_max``, ``seating_velocity_mean`` (velocity)
    Approach speed (-d gap/dt before the impact) of the valve's impacts on the
    seat after the first revolution: largest and mean (NaN without impacts).
``seat_bounces``
    Largest number, over the revolutions after the first, of seat bounces
    (``Trace.seat_bounces``: a re-opening after an impact that closes again
    within ``BOUNCE_WINDOW_DEG``), counted in the revolution of the landing.
``bounce_height`` (length)
    Largest bounce height of those (the largest seat gap on the output rows
    between lift-off and landing; 0 without bounces, NaN without a seat).
``peak_F<i>`` (force)
    Largest contact force at each clearance after the first revolution, over
    every step (``Trace.peak_force_after_first_revolution``; on the output
    rows for a back end that does not record it; NaN for a removed
    clearance).
``spring_margin`` (force)
    Smallest cam contact force on the output rows after the first revolution
    over the nose (above mid-stroke, as for ``cam_separations``) while the cam clearance
    is closed: how much spring force is left before the follower leaves the
    cam (NaN when it is never in contact there).
``events``
    Events (configuration changes) in the whole run.
``wall_time`` (s)
    Wall time of the back end's run (not deterministic: kept out of files
    that are compared).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from vtool.solvers.model.cam import derivatives, lift_series
from vtool.solvers.model.configurations import clearance_bit
from vtool.solvers.model.spec import EXTERNAL, REMOVED, CamSpec, MechanismSpec
from vtool.solvers.trace import CLOSED, SEPARATION, Trace

REVOLUTION = 360.0
NAN = float("nan")

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
    return f"F{spec.clearances[index].ahead}"


def metric_columns(spec: MechanismSpec) -> list[tuple[str, str]]:
    """(name, unit) of every metric, in report order; ``""`` for counts."""
    u = spec.unit_system
    columns = [
        ("cam_separations", ""),
        ("cam_separation_angle", "deg"),
        ("cam_separation_duration", "deg"),
        ("lift_loss", u.length),
        ("seating_velocity_max", u.velocity),
        ("seating_velocity_mean", u.velocity),
        ("seat_bounces", ""),
        ("bounce_height", u.length),
    ]
    columns += [(f"peak_{force_label(spec, i)}", u.force) for i in range(len(spec.clearances))]
    columns += [("spring_margin", u.force), ("events", ""), ("wall_time", "s")]
    return columns


def _above_mid_stroke(cam: CamSpec, angle: float) -> bool:
    """The cam's lift above the middle of its stroke at ``angle`` (deg): for the harmonic cam
    q_cam = A sin(theta) + offset exactly 0 < angle mod 360 < 180; for a lift table the same rule on
    its fitted lift (the nose half of the event, wherever the table puts the nose)."""
    if cam.profile == "harmonic":
        return 0.0 < angle % REVOLUTION < 180.0
    low, high = _stroke(cam)
    lift = derivatives(*lift_series(cam), np.radians([angle]))[0, 0]
    return bool(lift > 0.5 * (low + high))


def _above_mid_stroke_rows(cam: CamSpec, angles: np.ndarray) -> np.ndarray:
    """:func:`_above_mid_stroke` at every row."""
    if cam.profile == "harmonic":
        return (np.mod(angles, REVOLUTION) > 0.0) & (np.mod(angles, REVOLUTION) < 180.0)
    low, high = _stroke(cam)
    return derivatives(*lift_series(cam), np.radians(angles))[0] > 0.5 * (low + high)


@lru_cache(maxsize=16)
def _stroke(cam: CamSpec) -> tuple[float, float]:
    lift = derivatives(*lift_series(cam), np.linspace(0.0, 2.0 * math.pi, 3600, endpoint=False))[0]
    return float(lift.min()), float(lift.max())


def _cam_separation(trace: Trace, name: str) -> tuple[int, float, float]:
    end = float(trace.cam_angle[-1]) if len(trace.cam_angle) else 0.0
    impacts = [e.cam_angle for e in trace.events if e.clearance == name and e.kind == CLOSED]
    per_revolution: dict[int, int] = {}
    first = NAN
    longest = 0.0
    for episode in trace.episodes(name):
        start = episode.first_angle
        if episode.kind != SEPARATION or start < REVOLUTION or not _above_mid_stroke(trace.spec.cam, start):
            continue
        revolution = int(start // REVOLUTION)
        per_revolution[revolution] = per_revolution.get(revolution, 0) + 1
        closing = next((a for a in impacts if a > episode.last_angle), end)
        first = start % REVOLUTION if math.isnan(first) else min(first, start % REVOLUTION)
        longest = max(longest, closing - start)
    return max(per_revolution.values(), default=0), first, longest


def _seat_metrics(trace: Trace, index: int | None, after: np.ndarray) -> dict[str, float]:
    spec = trace.spec
    result = {"lift_loss": NAN, "seating_velocity_max": NAN, "seating_velocity_mean": NAN,
              "seat_bounces": 0, "bounce_height": NAN}
    if index is None or spec.seat is None:
        return result
    clearance = spec.clearances[index]
    s = spec.seat.position
    valve = trace.coordinate(clearance.ahead)
    cam = trace.coordinate(spec.cam.coordinate)
    if len(valve) and after.any():
        ratio = valve[0] / cam[0] if cam[0] != 0.0 else spec.initial.lever_ratio
        lift = np.maximum(valve - s, 0.0)
        kinematic = np.maximum(ratio * cam - s, 0.0)
        result["lift_loss"] = float(np.max((kinematic - lift)[after]))
    impacts = [e for e in trace.events if e.clearance == clearance.name and e.kind == CLOSED
               and e.cam_angle >= REVOLUTION]
    if impacts:
        speeds = np.array([-e.relative_velocity for e in impacts])
        result["seating_velocity_max"] = float(speeds.max())
        result["seating_velocity_mean"] = float(speeds.mean())
    bounces = [b for b in trace.seat_bounces(clearance.name) if b[1] >= REVOLUTION]
    per_revolution: dict[int, int] = {}
    for _, landing, _ in bounces:
        per_revolution[int(landing // REVOLUTION)] = per_revolution.get(int(landing // REVOLUTION), 0) + 1
    result["seat_bounces"] = max(per_revolution.values(), default=0)
    result["bounce_height"] = max((height for _, _, height in bounces), default=0.0)
    return result


def _peak(trace: Trace, index: int, after: np.ndarray) -> float:
    if trace.spec.clearances[index].state == REMOVED:
        return NAN
    if trace.peak_force_after_first_revolution is not None:
        return float(trace.peak_force_after_first_revolution[index])
    values = trace.contact_force[after, index]
    return float(values.max()) if values.size else NAN


def run_metrics(trace: Trace) -> dict[str, float]:
    """The metrics of one run (see the module doc), keyed as :func:`metric_columns`."""
    spec = trace.spec
    after = trace.cam_angle >= REVOLUTION
    cam = cam_index(spec)
    metrics: dict[str, float] = {}
    count, angle, duration = _cam_separation(trace, spec.clearances[cam].name)
    metrics["cam_separations"] = count
    metrics["cam_separation_angle"] = angle
    metrics["cam_separation_duration"] = duration
    metrics.update(_seat_metrics(trace, seat_index(spec), after))
    for i in range(len(spec.clearances)):
        metrics[f"peak_{force_label(spec, i)}"] = _peak(trace, i, after)
    nose = after & _above_mid_stroke_rows(trace.spec.cam, trace.cam_angle)
    in_contact = nose & ((trace.configuration & clearance_bit(spec, cam)) != 0)
    metrics["spring_margin"] = float(trace.contact_force[in_contact, cam].min()) if in_contact.any() else NAN
    metrics["events"] = trace.statistics.events
    metrics["wall_time"] = trace.statistics.wall_time
    return metrics


def failed_metrics(spec: MechanismSpec) -> dict[str, float]:
    """All metrics NaN (a run that failed), with the same keys."""
    return {name: NAN for name, _ in metric_columns(spec)}
