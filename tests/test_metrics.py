"""Per-run metrics (solvers/studies/metrics.py) on a hand-built trace whose answers follow from its construction,
and on real runs where only the definitions' structure is checked."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.run import simulate
from vtool.solvers.studies.metrics import (
    GAP_FRACTION,
    LIFT_EVENT_FRACTION,
    Criteria,
    failed_metrics,
    lift_event,
    metric_columns,
    run_metrics,
)
from vtool.solvers.trace import CLOSED, OPENED, RELEASED, Event, RunStatistics, Trace

CAM_BIT = 0b100  # 1A: cam, rocker, seat; the cam clearance is the leading bit
OFFSET = 0.6  # in: cam offset of the hand-built trace
RATIO = 1.5  # valve motion per cam motion at the start
SEAT = 0.7  # in: 1A's seat position


def _event(angle: float, clearance: str, kind: str, before: int, after: int, velocity: float = 0.0) -> Event:
    return Event(angle / 66000.0, angle, clearance, kind, velocity, before, after)


def hand_built_trace() -> Trace:
    """Two and a bit revolutions, 1 deg rows, with one jump, one seat bounce and known dips and spikes."""
    spec = load_preset("gnilka-1a")
    angle = np.arange(0.0, 801.0)
    theta = np.radians(angle)
    cam = 0.5 * np.sin(theta) + OFFSET
    valve = np.maximum(RATIO * cam, SEAT)  # follows the cam kinematically, seated below the seat position
    rows = {int(a): i for i, a in enumerate(angle)}
    valve[rows[450]] -= 0.01  # lift loss 0.01 in at the second revolution's nose
    valve[rows[566]], valve[rows[567]] = SEAT + 0.02, SEAT + 0.03  # a bounce 0.03 in high
    q = np.zeros((len(angle), 10))
    q[:, 8], q[:, 6], q[:, 9] = cam, valve, SEAT
    q[:, 0] = cam  # the follower on the cam ...
    force = np.zeros((len(angle), 3))
    force[:, 0] = 100.0 + 50.0 * np.sin(theta)
    force[:, 1] = 80.0
    force[rows[400], 0] = 900.0
    force[rows[50], 0] = 5000.0  # first revolution: not counted
    force[rows[561], 2] = 300.0
    configuration = np.full(len(angle), CAM_BIT | 0b010)
    open_rows = (angle > 450.5) & (angle < 470.5)
    configuration[open_rows] &= ~CAM_BIT
    force[open_rows, 0] = 0.0
    q[open_rows, 0] += 0.01  # ... but 0.01 in off it during the jump
    micro = (angle > 420.5) & (angle < 421.0)  # a 0.5 deg micro-separation: below the 1 deg threshold
    q[(angle > 100.0) & (angle < 110.0), 0] += 0.02  # the first revolution's separation
    # masks: cam 0b100, rocker 0b010, seat 0b001
    events = (
        _event(100.0, "cam", OPENED, 0b110, 0b010),  # first revolution: not counted
        _event(110.0, "cam", CLOSED, 0b010, 0b110, -3.0),
        _event(420.5, "cam", OPENED, 0b110, 0b010),  # a micro-separation (0.5 deg): not a jump
        _event(421.0, "cam", CLOSED, 0b010, 0b110, -0.1),
        _event(450.5, "cam", OPENED, 0b110, 0b010),  # the jump: 90.5 deg, 20 deg long
        _event(470.5, "cam", CLOSED, 0b010, 0b110, -5.0),
        _event(560.0, "seat", CLOSED, 0b110, 0b111, -400.0),  # the seating ...
        _event(565.0, "seat", OPENED, 0b111, 0b110),  # ... a bounce ...
        _event(568.0, "seat", CLOSED, 0b110, 0b111, -100.0),  # ... and its landing
        _event(600.0, "cam", RELEASED, 0b111, 0b011, 1.0),  # below mid-stroke: not a jump
    )
    assert not micro.any()  # (no output row inside it: its gap is unseen, its length decides)
    statistics = RunStatistics("hand", len(angle), len(events), 0.25, ())
    after = angle >= 360.0
    return Trace(spec, angle / 66000.0, angle, tuple(range(1, 11)), q, q * 0, q * 0, force, configuration, events,
                 force.max(axis=0), statistics, peak_force_after_first_revolution=force[after].max(axis=0))


def test_hand_built_trace_gives_the_constructed_answers() -> None:
    m = run_metrics(hand_built_trace())
    assert list(m) == [name for name, _ in metric_columns(load_preset("gnilka-1a"))]
    assert m["cam_separations"] == 1
    assert m["cam_separation_angle"] == pytest.approx(90.5)
    assert m["cam_separation_duration"] == pytest.approx(20.0)
    assert m["cam_separation_gap"] == pytest.approx(0.01)
    assert m["lift_loss"] == pytest.approx(0.01, abs=1e-12)
    assert m["seating_velocity_max"] == 400.0 and m["seating_velocity_mean"] == 250.0
    assert m["seat_bounces"] == 1 and m["bounce_height"] == pytest.approx(0.03)
    assert (m["peak_F1"], m["peak_F2"], m["peak_F7"]) == (900.0, 80.0, 300.0)
    start, _ = lift_event(load_preset("gnilka-1a"))  # the smallest cam force in the lift event: at its start
    assert m["spring_margin"] == pytest.approx(100.0 + 50.0 * math.sin(math.radians(math.ceil(start))))
    assert m["events"] == 10 and m["wall_time"] == 0.25
    assert m["startup_peak_force"] == 5000.0 and math.isnan(m["startup_seating_velocity"])
    assert m["cycles"] == 0 and math.isnan(m["cycle_change"])


def test_thresholds_decide_what_counts() -> None:
    """A gap threshold above the jump's 0.01 in, or an angle threshold above its 20 deg, drops it; a bounce
    lift above 0.03 in drops the bounce."""
    trace = hand_built_trace()
    for change in ({"jump_gap": 0.011}, {"jump_angle": 20.5}):
        spec = dataclasses.replace(trace.spec, run=dataclasses.replace(trace.spec.run, **change))
        assert run_metrics(dataclasses.replace(trace, spec=spec))["cam_separations"] == 0
    spec = dataclasses.replace(trace.spec, run=dataclasses.replace(trace.spec.run, jump_gap=0.009, bounce_lift=0.031))
    m = run_metrics(dataclasses.replace(trace, spec=spec))
    assert m["cam_separations"] == 1 and m["seat_bounces"] == 0 and m["bounce_height"] == 0.0


def test_lift_event_of_the_harmonic_cam_follows_from_its_lift_and_lash() -> None:
    """1A: L = A (1 + sin θ), lift event where L - lash > 0.5 % of 2A, lash = r s - base (seat.lash's rule)."""
    from vtool.solvers.model.lash import base_and_ratio

    spec = load_preset("gnilka-1a")
    base, ratio = base_and_ratio(spec)
    A = spec.cam.amplitude
    lash = ratio * spec.seat.position - base
    # A (1 + sin θ) = lash + 0.01 A  ->  sin θ = lash / A - 0.99 = sin θ0: the event is θ0 < θ < 180 - θ0
    theta0 = math.degrees(math.asin(lash / A + LIFT_EVENT_FRACTION * 2 - 1.0))
    assert theta0 < 0.0
    start, end = lift_event(spec)
    assert start == pytest.approx(360.0 + theta0, abs=0.1) and end == pytest.approx(540.0 - theta0, abs=0.1)
    assert Criteria.of(spec).jump_gap == pytest.approx(GAP_FRACTION * 2 * A, rel=1e-6)


def test_units_follow_the_preset() -> None:
    units = dict(metric_columns(load_preset("gnilka-1a")))
    assert units["lift_loss"] == "in" and units["seating_velocity_max"] == "in/s" and units["peak_F7"] == "lbf"
    assert units["cam_separation_angle"] == "deg" and units["cam_separations"] == "" and units["wall_time"] == "s"


def test_failed_point_has_every_metric_as_nan() -> None:
    spec = load_preset("gnilka-1a")
    assert all(math.isnan(v) for v in failed_metrics(spec).values())
    assert list(failed_metrics(spec)) == [n for n, _ in metric_columns(spec)]


def test_without_a_seat_the_seat_metrics_are_undefined() -> None:
    spec = with_run_overrides(load_preset("gnilka-1b"), degrees=400.0)
    m = run_metrics(simulate(spec))
    assert math.isnan(m["lift_loss"]) and math.isnan(m["seating_velocity_max"]) and m["seat_bounces"] == 0
    assert set(m) == {n for n, _ in metric_columns(spec)}
