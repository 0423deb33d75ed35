"""Per-run metrics of a valve-train trace: the numbers a speed sweep reports.

One function, :func:`run_metrics`, turns a :class:`~vtool.solvers.trace.Trace`
into a flat, ordered dict of numbers; :func:`metric_columns` gives their names
and units for a spec. ``vtool sweep`` reports them per point, and a single
``vtool solve`` run gives the same numbers from the same trace. Definitions
(also in docs/sweep.md); "after the first revolution" means cam angle
>= 360 deg to the end of the run, revolution k covering [360 k, 360 (k+1)):

``cam_separations``
    Largest number, over the revolutions after the first, of cam-clearance
    separations (``opened`` or ``released`` events) that start above
    mid-stroke: cam angle mod 360 in (0, 180) deg, where the harmonic cam
    q_cam = A sin(theta) + offset is above its offset and decelerating the
    follower. One or more means the follower leaves the cam (jump).
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
    Largest number, over the revolutions after the first, of seat impacts
    beyond the first one (the seating) in that revolution.
``bounce_height`` (length)
    Largest seat gap q_v - s on the output rows between a bounce's lift-off
    and its impact (0 when a bounce falls between two rows; NaN without a
    seat).
``peak_F<i>`` (force)
    Largest contact force at each clearance on the output rows after the
    first revolution (NaN for a removed clearance). ``Trace.peak_force`` is
    over every step of the whole run; these are over the output rows (set
    ``run.output_interval`` or ``every_step`` for finer sampling).
``spring_margin`` (force)
    Smallest cam contact force on the output rows after the first revolution
    over the nose (cam angle mod 360 in (0, 180) deg) while the cam clearance
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

import numpy as np

from vtool.solvers.configurations import clearance_bit
from vtool.solvers.spec import EXTERNAL, REMOVED, MechanismSpec
from vtool.solvers.trace import CLOSED, OPENED, RELEASED, Trace

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


def _above_mid_stroke(angle: float) -> bool:
    return 0.0 < angle % REVOLUTION < 180.0


def _cam_separation(trace: Trace, name: str) -> tuple[int, float, float]:
    end = float(trace.cam_angle[-1]) if len(trace.cam_angle) else 0.0
    per_revolution: dict[int, int] = {}
    first = NAN
    longest = 0.0
    events = [e for e in trace.events if e.clearance == name]
    for k, e in enumerate(events):
        if e.kind not in (OPENED, RELEASED) or e.cam_angle < REVOLUTION or not _above_mid_stroke(e.cam_angle):
            continue
        revolution = int(e.cam_angle // REVOLUTION)
        per_revolution[revolution] = per_revolution.get(revolution, 0) + 1
        closing = next((f.cam_angle for f in events[k + 1:] if f.kind == CLOSED), end)
        first = min(first, e.cam_angle % REVOLUTION) if not math.isnan(first) else e.cam_angle % REVOLUTION
        duration = closing - e.cam_angle
        longest = max(longest, duration)
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
    events = [e for e in trace.events if e.clearance == clearance.name]
    impacts = [e for e in events if e.kind == CLOSED and e.cam_angle >= REVOLUTION]
    if impacts:
        speeds = np.array([-e.relative_velocity for e in impacts])
        result["seating_velocity_max"] = float(speeds.max())
        result["seating_velocity_mean"] = float(speeds.mean())
    by_revolution: dict[int, list[float]] = {}
    for e in impacts:
        by_revolution.setdefault(int(e.cam_angle // REVOLUTION), []).append(e.cam_angle)
    result["seat_bounces"] = max((len(v) - 1 for v in by_revolution.values()), default=0)
    height = 0.0
    for angles in by_revolution.values():
        for landing in angles[1:]:
            lift_off = max((e.cam_angle for e in events if e.kind in (OPENED, RELEASED) and e.cam_angle < landing),
                           default=landing)
            inside = (trace.cam_angle > lift_off) & (trace.cam_angle < landing)
            if inside.any():
                height = max(height, float(np.max(valve[inside] - s)))
    result["bounce_height"] = height
    return result


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
    for i, c in enumerate(spec.clearances):
        values = trace.contact_force[after, i]
        peak = float(values.max()) if values.size and c.state != REMOVED else NAN
        metrics[f"peak_{force_label(spec, i)}"] = peak
    nose = after & (np.mod(trace.cam_angle, REVOLUTION) > 0.0) & (np.mod(trace.cam_angle, REVOLUTION) < 180.0)
    in_contact = nose & ((trace.configuration & clearance_bit(spec, cam)) != 0)
    metrics["spring_margin"] = float(trace.contact_force[in_contact, cam].min()) if in_contact.any() else NAN
    metrics["events"] = trace.statistics.events
    metrics["wall_time"] = trace.statistics.wall_time
    return metrics


def failed_metrics(spec: MechanismSpec) -> dict[str, float]:
    """All metrics NaN (a run that failed), with the same keys."""
    return {name: NAN for name, _ in metric_columns(spec)}
