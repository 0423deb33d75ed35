"""Stability at the extremes (issue 4, item 5): the ``newmark`` back end at the edges of its inputs.

Each case either gives a physically sane answer, checked against what an
engineer expects and not merely "it ran", or is refused with one line: an
:class:`~vtool.errors.InputError` naming field, value, limit and unit before
any work, or a :class:`~vtool.errors.RunError` naming time and configuration.

Sane, for every run (:func:`assert_sane`): contacts push and never pull; an
open clearance is not penetrated; a closed one is shut exactly (gap and gap
rate zero to round-off); every impact approaches (or is a resting contact);
the event list chains from the start configuration to the final one; the
valve rises no higher than a throw at twice the cam's top speed would carry
it. Each case adds the physics it is about: the quasi-static answer at
100 rpm, separation at 30,000 rpm, no seat bounce at critical damping, ...

The variants start from the thesis' example 1A (``gnilka-1a``: 11,000 rpm,
seat at 0.7 in, spring 254 lbf/in, cam amplitude 0.5 in, Δt = 1 µs, the
local impact law), from the quasi-static start: the thesis' start shock
would otherwise throw the follower off at about 15 degrees whatever the
extreme, and the first revolution should show the extreme's own physics. The
figures measured at each extreme and the list of enforced limits are in
docs/limits.md.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import replace

import numpy as np
import pytest

from tests.valvetrain_cases import spec_from, thesis_doc
from vtool.errors import InputError, RunError
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.model.configurations import clearance_bit, mask_of
from vtool.solvers.model.mechanism import Mechanism, assemble
from vtool.solvers.newmark.backend import (
    NewmarkBackend,
    NewmarkOptions,
    stability_limit,
)
from vtool.solvers.run import simulate
from vtool.solvers.trace import CLOSED, OPENED, RELEASED, Event, Trace

CAM_BIT, ROCKER_BIT, SEAT_BIT = 4, 2, 1  # configuration bits of the thesis' three clearances
VALVE_OPEN = CAM_BIT | ROCKER_BIT  # configuration VII: the valve train in one piece, off its seat
FOLLOWER, VALVE, SPRING_END, CAM, SEAT = 1, 7, 4, 9, 10  # coordinate numbers (q4: spring end)

#: how far below zero an open gap may be seen (in): events are located on the side where the
#: gap is still open, so only round-off and the output interpolant can dip below zero
PENETRATION = 1e-8
#: a closed gap is the same number on both sides (tied or prescribed), so zero to round-off
SHUT = 1e-12
#: ... and its rate (length/s) zero to round-off too
SHUT_RATE = 1e-6
#: a contact force may be this fraction of the run's peak force below zero (round-off): it never pulls
PULL = 1e-6
#: the peak force (over every step) is at least this fraction of the largest sampled force (samples
#: are interpolated inside the steps and may exceed the step values a little at the stability limit)
PEAK_FRACTION = 0.9
#: wall time after which a run counts as hung (each run here takes 0.01-2 s on two cores)
WALL_TIME_BUDGET = 60.0


# ----- building and running variants of example 1A -----

def variant(name: str = "gnilka-1a", *, seat: float | str | None = None, spring: float = 1.0,
            amplitude: float | None = None, damping: float | None = None,
            restitution: dict[str, float] | None = None, law: str | None = None, **run_settings: float) -> dict:
    """A thesis preset with one input pushed to an extreme.

    ``law``: the impact law of every clearance (default: the preset's, local).
    ``seat``: seat position (in) or ``"removed"``; ``spring``: factor on the
    valve-spring rate; ``damping``: one modal damping ratio for every mode of
    every layer; ``restitution``: per clearance name; ``run_settings``: [run] keys.
    """
    doc = thesis_doc(name)
    doc["initial"]["velocities"] = "quasi-static"
    clearances = {c["name"]: c for c in doc["clearances"]}
    if seat == "removed":
        clearances["seat"]["state"] = "removed"
    elif seat is not None:
        doc["seat"]["position"] = seat
    doc["members"]["valve_spring"]["stiffness"] *= spring
    if amplitude is not None:
        doc["cam"]["amplitude"] = amplitude
    if damping is not None:
        doc["damping"] = {"factor": 1.0, "default_ratio": damping}
    for name_, e in (restitution or {}).items():
        clearances[name_]["restitution"] = e
    if law is not None:
        doc["contact"]["impact"] = law
    doc["run"].update(run_settings)
    return doc


def run(doc: dict, every_step: bool = False, budget: float = WALL_TIME_BUDGET,
        chunk_steps: int = 100) -> tuple[Trace, Mechanism]:
    """Run a preset document; a run still going after ``budget`` s of wall time fails the test.

    The back end polls ``cancel`` between chunks of ``chunk_steps`` steps (the
    answer does not depend on the chunk size), so a run that crawls fails here
    instead of holding up the suite.
    """
    spec = spec_from(doc)
    options = replace(NewmarkBackend.options_from_run(spec.run, every_step), chunk_steps=chunk_steps)
    started = time.perf_counter()
    reached = [0.0]

    def progress(fraction: float) -> None:
        reached[0] = fraction * spec.run.degrees

    def too_long() -> bool:
        return time.perf_counter() - started > budget

    try:
        trace = simulate(spec, every_step=every_step, options=options, progress=progress, cancel=too_long)
    except RunError as error:
        if str(error).startswith("cancelled"):
            pytest.fail(f"no answer after {budget:g} s of wall time, stuck near {reached[0]:.4f} deg: {error}")
        raise
    return trace, assemble(spec)


def impacts(trace: Trace, clearance: str) -> list[Event]:
    return [e for e in trace.events if e.clearance == clearance and e.kind == CLOSED]


def separations(trace: Trace, clearance: str) -> list[Event]:
    return [e for e in trace.events if e.clearance == clearance and e.kind in (OPENED, RELEASED)]


def first_throw(trace: Trace) -> float:
    """Cam angle (deg) at which the follower first leaves the cam over the nose (0-180 deg)."""
    return next(e.cam_angle for e in separations(trace, "cam") if e.cam_angle % 360.0 < 180.0)


def bounce_trains(trace: Trace, clearance: str, gap_deg: float = 2.0) -> list[np.ndarray]:
    """Impact speeds at one clearance, grouped into trains (impacts less than gap_deg apart)."""
    trains: list[list[float]] = []
    last = -math.inf
    for e in impacts(trace, clearance):
        if e.cam_angle - last > gap_deg:
            trains.append([])
        trains[-1].append(-e.relative_velocity)
        last = e.cam_angle
    return [np.array(t) for t in trains]


# ----- physical yardsticks -----

def valve_ratio(mechanism: Mechanism) -> float:
    """Valve travel per unit follower travel in the static deflection shape (about the rocker ratio)."""
    q = mechanism.start.q
    return float(q[VALVE - 1] / q[FOLLOWER - 1])


def static_max_lift(mechanism: Mechanism) -> float:
    """Valve position (q7) with the follower on the cam's nose, statically."""
    return valve_ratio(mechanism) * (mechanism.start.cam_offset + mechanism.spec.cam.amplitude)


def lowest_frequency(mechanism: Mechanism) -> float:
    return min(float(layer.modes.omega[layer.modes.omega > 0].min()) for layer in mechanism.all_layers())


def valve_lift_bound(mechanism: Mechanism) -> float:
    """How high the valve can go: its highest static lift plus a throw at twice the cam's top
    speed (a rebound with e <= 1 off the cam) through the rocker, against a spring-mass at the
    lowest natural frequency of any contact layer."""
    cam_speed = mechanism.spec.cam.amplitude * mechanism.omega
    return static_max_lift(mechanism) + 2.0 * valve_ratio(mechanism) * cam_speed / lowest_frequency(mechanism)


def rest_velocity(mechanism: Mechanism) -> float:
    """The back end's resting-contact speed (docs/valvetrain.md): 1e-5 x cam amplitude x the larger
    of the cam speed and the lowest natural frequency of the starting layer."""
    omega = mechanism.start_layer.modes.omega
    return 1e-5 * mechanism.spec.cam.amplitude * max(mechanism.omega, float(omega[omega > 0].min()))


def energy(trace: Trace, M: np.ndarray, K: np.ndarray) -> np.ndarray:
    n = M.shape[0]
    q, qd = trace.q[:, :n], trace.qd[:, :n]
    return 0.5 * np.einsum("ti,ij,tj->t", qd, M, qd) + 0.5 * np.einsum("ti,ij,tj->t", q, K, q)


# ----- what every run must satisfy -----

def assert_sane(trace: Trace, mechanism: Mechanism) -> None:
    spec = trace.spec
    assert trace.success
    assert np.isfinite(trace.q).all() and np.isfinite(trace.contact_force).all()
    force_scale = max(float(trace.peak_force.max()), 1.0)
    for i, c in enumerate(spec.clearances):
        if c.state == "removed":
            continue
        closed = (trace.configuration & clearance_bit(spec, i)) != 0
        gap = trace.coordinate(c.ahead) - trace.coordinate(c.behind)
        gap_rate = trace.qd[:, trace.coordinate_numbers.index(c.ahead)] - \
            trace.qd[:, trace.coordinate_numbers.index(c.behind)]
        assert np.abs(gap[closed]).max(initial=0.0) <= SHUT, f"{c.name}: closed but not shut"
        assert np.abs(gap_rate[closed]).max(initial=0.0) <= SHUT_RATE, f"{c.name}: closed but moving apart"
        worst = gap[~closed].min(initial=math.inf)
        assert worst >= -PENETRATION, f"{c.name}: open gap penetrated by {-worst:.3g} at {trace.cam_angle[np.argmin(np.where(closed, np.inf, gap))]:.2f} deg"
        force = trace.contact_force[:, i]
        if c.state == "enabled":
            assert force.min() >= -PULL * force_scale, f"{c.name}: pulls with {force.min():.4g}"
        # peaks are taken at step ends; an interpolated sample may exceed them a little, never grossly
        assert trace.peak_force[i] >= PEAK_FRACTION * force.max(), f"{c.name}: peak force below a sampled force"
    rest = rest_velocity(mechanism)
    for e in trace.events:
        if e.kind == CLOSED:
            assert e.relative_velocity < rest, f"impact with separating velocity {e.relative_velocity:.3g} at {e.cam_angle:.3f} deg"
    current, previous = int(mask_of(spec, spec.initial.closed)), None
    for e in trace.events:
        if (e.time, e.before, e.after) == previous:
            continue  # more events of the same impact
        assert e.before == current, f"event at {e.cam_angle:.3f} deg starts from {e.before}, not {current}"
        current, previous = e.after, (e.time, e.before, e.after)
    assert trace.configuration[-1] == current, "the events do not lead to the final configuration"
    if spec.seat is not None:
        assert trace.coordinate(VALVE).max() <= valve_lift_bound(mechanism)


def refused_or_sane(doc: dict) -> InputError | Trace:
    """Either a one-line InputError before any work, or a sane run (never a silent absurd answer)."""
    try:
        trace, mechanism = run(doc)
    except InputError as error:
        assert "\n" not in str(error) and error.field and error.expected
        return error
    assert_sane(trace, mechanism)
    return trace


@pytest.fixture(scope="module")
def nominal() -> Trace:
    trace, mechanism = run(variant())
    assert_sane(trace, mechanism)
    return trace


# ----- cam speed -----

@pytest.mark.slow
def test_at_100_rpm_the_valve_train_is_quasi_static() -> None:
    """Seating angle and speed from the static deflection shape; forces are the static ones."""
    trace, mechanism = run(variant(rpm=100.0, degrees=400.0, time_step=2.5e-6))
    assert_sane(trace, mechanism)
    spec, start = mechanism.spec, mechanism.start
    r, amplitude, omega = valve_ratio(mechanism), spec.cam.amplitude, mechanism.omega
    # statically the valve reaches its seat where r * q9 = seat position, on the closing flank
    x = (spec.seat.position / r - start.cam_offset) / amplitude
    seating_deg, lifting_deg = 180.0 - math.degrees(math.asin(x)), 360.0 + math.degrees(math.asin(x))
    seating = impacts(trace, "seat")[0]
    assert seating.cam_angle == pytest.approx(seating_deg, abs=0.05)
    assert -seating.relative_velocity == pytest.approx(
        r * amplitude * omega * abs(math.cos(math.radians(seating_deg))), rel=0.02)
    lifting = [e for e in separations(trace, "seat") if e.cam_angle > 270.0][0]
    assert lifting.cam_angle == pytest.approx(lifting_deg, abs=0.1)
    # valve open: follower force = k_eff q9 = lever ratio x spring force = rocker force
    riding = trace.configuration == VALVE_OPEN
    F1, F2 = trace.force("cam")[riding], trace.force("rocker")[riding]
    rate = next(m.stiffness for m in spec.members if m.name == "valve_spring")
    spring = rate * np.abs(trace.coordinate(SPRING_END)[riding])
    np.testing.assert_allclose(F1, start.follower_stiffness * trace.coordinate(CAM)[riding], rtol=5e-3)
    np.testing.assert_allclose(F1, spec.initial.lever_ratio * spring, rtol=5e-3)
    np.testing.assert_allclose(F2, F1, rtol=5e-3)
    # the follower leaves the cam only with the valve on its seat (the lash opens), never during the lift
    assert separations(trace, "cam") and all(e.after & SEAT_BIT for e in separations(trace, "cam"))


def test_at_30000_rpm_the_follower_is_thrown_off_and_the_valve_floats(nominal: Trace) -> None:
    trace, mechanism = run(variant(rpm=30000.0))
    assert_sane(trace, mechanism)
    assert first_throw(trace) < first_throw(nominal)  # 86.5 deg at 11,000 rpm
    assert trace.coordinate(VALVE).max() > static_max_lift(mechanism)  # the valve overshoots its lift
    fastest = max(-e.relative_velocity for e in impacts(trace, "seat"))
    assert fastest > max(-e.relative_velocity for e in impacts(nominal, "seat"))


# ----- seat position and lash -----

def test_a_seat_at_zero_is_never_reached_and_changes_nothing() -> None:
    at_zero, mechanism = run(variant(seat=0.0))
    without, _ = run(variant(seat="removed"))
    assert_sane(at_zero, mechanism)
    assert not [e for e in at_zero.events if e.clearance == "seat"]
    assert (at_zero.coordinate(VALVE) - at_zero.coordinate(SEAT)).min() > 0.5
    np.testing.assert_array_equal(at_zero.q[:, :9], without.q[:, :9])
    np.testing.assert_array_equal(at_zero.contact_force, without.contact_force)
    assert [(e.time, e.clearance, e.kind) for e in at_zero.events] == \
        [(e.time, e.clearance, e.kind) for e in without.events]


def static_seating_angle(mechanism: Mechanism) -> float:
    x = (mechanism.spec.seat.position / valve_ratio(mechanism) - mechanism.start.cam_offset) / mechanism.spec.cam.amplitude
    return 180.0 - math.degrees(math.asin(x))


def test_a_seat_at_one_inch_closes_the_valve_earlier_harder_and_longer(nominal: Trace) -> None:
    trace, mechanism = run(variant(seat=1.0))
    assert_sane(trace, mechanism)
    first, nominal_first = impacts(trace, "seat")[0], impacts(nominal, "seat")[0]
    assert first.cam_angle == pytest.approx(static_seating_angle(mechanism), abs=1.0)  # 205.0 (static 205.2)
    assert first.cam_angle < nominal_first.cam_angle - 20.0  # 235.1 with the seat at 0.7 in
    assert -first.relative_velocity > 1.3 * -nominal_first.relative_velocity  # 788 against 498 in/s
    seated = np.mean(trace.configuration & SEAT_BIT != 0)
    assert seated > 1.5 * np.mean(nominal.configuration & SEAT_BIT != 0)
    assert trace.coordinate(VALVE).min() >= 1.0 - PENETRATION


def test_the_pushrod_rocker_lash_is_zero_and_an_open_start_is_refused() -> None:
    """The rocker clearance has no lash field: it closes at q2 = q8. Starting with it open leaves
    the pushrod floating, with no static start; that is refused in one line."""
    doc = variant()
    doc["clearances"][1]["lash"] = 0.01
    with pytest.raises(InputError, match=r"^clearances\[1\]\.lash: got 0\.01, expected no such field"):
        spec_from(doc)
    doc = variant()
    doc["initial"]["closed"] = ["cam"]
    with pytest.raises(InputError) as info:
        run(doc)
    assert "\n" not in str(info.value) and "statically stable" in str(info.value)


def test_a_seat_above_the_valve_at_the_start_is_refused_or_run_off_the_seat() -> None:
    """Seat at 2 in, the valve starts at 1.32 in: inside its seat."""
    refused_or_sane(variant(seat=2.0))


def test_the_seat_cannot_be_closed_at_the_static_start() -> None:
    doc = variant()
    doc["initial"]["closed"] = ["cam", "rocker", "seat"]
    with pytest.raises(InputError) as info:
        spec_from(doc)
    assert info.value.field == "initial.closed" and info.value.value == "seat"


# ----- damping -----

def test_damping_extremes_make_a_restless_or_a_quiet_valve_train() -> None:
    """Undamped, the contacts keep separating and re-closing; critically damped, the valve seats at
    most once per revolution (with the local law and the quasi-static start it floats clear of the seat:
    the follower leaves the cam at 90 degrees and lands at 305) and little else happens. (A plain 1 µs Newmark run showed six seat bounces per revolution undamped: its
    high-mode error after impacts, which the refinement after events removes.)"""
    # Undamped, the run is chaotic: a round-off change (every-step output against 1-degree output
    # already differs by 1e-12 s at event 43) gives another, equally valid sequence. The invariants
    # are checked at every step, where the method defines the contact forces; 1-degree rows inside a
    # step are its cubic interpolant, which in one such sequence dipped to -10 lbf (0.1 % of the
    # peak) between two positive step ends (docs/limits.md, "what every run must satisfy").
    undamped, mechanism = run(variant(damping=0.0), every_step=True)
    assert_sane(undamped, mechanism)
    damped, mechanism = run(variant(damping=1.0))
    assert_sane(damped, mechanism)
    assert all(count <= 1 for count in damped.bounces_per_revolution("seat"))  # the revolution 360-720 deg
    assert undamped.bounces_per_revolution("seat")[0] >= 1
    assert len(undamped.events) > 5 * len(damped.events)


def free_vibration_doc(ratio: float, **run_settings: float) -> dict:
    """Example 1A with the rocker pinned and cam and seat removed: free vibration from the static start."""
    doc = variant(damping=ratio)
    for c in doc["clearances"]:
        c["state"] = {"cam": "removed", "rocker": "pinned", "seat": "removed"}[c["name"]]
    doc["initial"]["closed"] = ["rocker"]
    doc["run"].update({"degrees": 3000.0, **run_settings})
    return doc


@pytest.mark.parametrize("ratio", [0.0, 1.0])
def test_free_vibration_of_the_fundamental_at_the_damping_extremes(ratio: float) -> None:
    """The modal damping decouples the modes: the fundamental's modal coordinate is an
    oscillator, undamped (ζ = 0) or critically damped (ζ = 1), with a closed form."""
    spec = spec_from(free_vibration_doc(ratio))
    mechanism = assemble(spec)
    trace = simulate(spec, every_step=True)
    layer = mechanism.layer({"rocker"})
    phi, w = layer.modes.shapes[:, 0], float(layer.modes.omega[0])
    kept = [k - 1 for k in layer.kept]
    eta = trace.q[:, kept] @ layer.M @ phi
    eta_rate = trace.qd[:, kept] @ layer.M @ phi
    t, e0, v0 = trace.time, eta[0], eta_rate[0]
    if ratio == 0.0:
        exact = e0 * np.cos(w * t) + v0 / w * np.sin(w * t)
    else:
        exact = (e0 + (v0 + w * e0) * t) * np.exp(-w * t)
    assert np.abs(eta - exact).max() < 1e-5 * abs(e0)
    E = energy(trace, mechanism.M, mechanism.K)
    if ratio == 0.0:
        assert np.abs(E / E[0] - 1.0).max() < 1e-6  # 5 periods of the fundamental, 45 ms
    else:
        assert np.diff(E).max() <= 1e-12 * E[0]  # never rises
        assert E[np.searchsorted(t, 0.01)] < 1e-3 * E[0]  # died out within 10 ms (7 w1 t)
        assert (trace.coordinate(VALVE) > 0).all()  # no overshoot: the valve creeps back to rest


def test_damping_ratio_above_one_is_refused() -> None:
    with pytest.raises(InputError, match=r"^damping.default_ratio: got 1.01, expected >= 0 and <= 1$"):
        spec_from(variant(damping=1.01))


# ----- valve-spring rate -----

def test_a_soft_spring_lets_the_follower_fly_most_of_the_revolution(nominal: Trace) -> None:
    """Spring x0.1: fundamental 219 rad/s, five times below the cam's 1152 rad/s."""
    trace, mechanism = run(variant(spring=0.1))
    assert_sane(trace, mechanism)
    assert first_throw(trace) < 0.5 * first_throw(nominal)
    airborne = np.mean(trace.configuration & CAM_BIT == 0)
    assert airborne > 0.5 > 2 * np.mean(nominal.configuration & CAM_BIT == 0)


def test_a_stiff_spring_keeps_the_follower_on_the_cam() -> None:
    """Spring x100: fundamental 6.7e3 rad/s; with the seat out of the way nothing ever separates."""
    trace, mechanism = run(variant(spring=100.0, seat="removed"))
    assert_sane(trace, mechanism)
    assert not trace.events and (trace.configuration == VALVE_OPEN).all()
    preload = mechanism.spec.initial.spring_preload * mechanism.spec.initial.lever_ratio
    assert trace.force("cam").min() > 0.5 * preload


def test_a_stiff_spring_with_the_thesis_seat_is_refused_or_run_off_the_seat() -> None:
    """Spring x100 moves the static start: the valve starts at 0.51 in, below its seat at 0.7 in."""
    refused_or_sane(variant(spring=100.0))


# ----- cam amplitude -----

def test_a_tiny_cam_amplitude_gives_a_linear_response_without_events() -> None:
    """A = 1e-4 in and 1e-3 in: the follower force minus the base-circle force scales with A."""
    scaled = []
    for amplitude in (1e-4, 1e-3):
        trace, mechanism = run(variant(amplitude=amplitude, seat="removed"))
        assert_sane(trace, mechanism)
        assert not trace.events and (trace.configuration == VALVE_OPEN).all()
        base = mechanism.spec.initial.spring_preload * mechanism.spec.initial.lever_ratio
        scaled.append((trace.force("cam") - base) / amplitude)
    np.testing.assert_allclose(scaled[0], scaled[1], rtol=0, atol=1e-6 * np.abs(scaled[1]).max())


def test_a_tiny_cam_amplitude_with_the_thesis_seat_is_refused_or_run_off_the_seat() -> None:
    """A = 1e-4 in puts the static start at q7 = 0.571 in, below the seat at 0.7 in."""
    refused_or_sane(variant(amplitude=1e-4))


def test_a_large_cam_amplitude_throws_the_follower_earlier(nominal: Trace) -> None:
    trace, mechanism = run(variant(amplitude=2.0))
    assert_sane(trace, mechanism)
    assert first_throw(trace) < first_throw(nominal) - 20.0  # 51.8 against 86.5 deg
    assert trace.coordinate(VALVE).max() > static_max_lift(mechanism)


# ----- Newmark time step at the stability limit -----

def thesis_limit() -> float:
    return stability_limit(1.0 / 6.0, 0.5, assemble(spec_from(variant())).highest_frequency)


def test_the_enforced_limit_is_root_three_over_pi_of_the_shortest_period() -> None:
    t_min = 2.0 * math.pi / assemble(spec_from(variant())).highest_frequency
    assert thesis_limit() == pytest.approx(math.sqrt(3.0) / math.pi * t_min, rel=1e-14)
    assert thesis_limit() == pytest.approx(2.527e-6, rel=1e-3)


def test_a_step_just_below_the_limit_runs_and_agrees_with_one_microsecond(nominal: Trace) -> None:
    trace, mechanism = run(variant(time_step=0.999 * thesis_limit()))
    assert_sane(trace, mechanism)
    assert impacts(trace, "seat")[0].cam_angle == pytest.approx(impacts(nominal, "seat")[0].cam_angle, abs=0.01)
    assert trace.peak_force[2] == pytest.approx(nominal.peak_force[2], rel=0.02)


@pytest.mark.parametrize("factor", [1.00001, 1.001])
def test_a_step_just_above_the_limit_is_refused_with_the_limit(factor: float) -> None:
    step = factor * thesis_limit()
    with pytest.raises(InputError) as info:
        simulate(with_run_overrides(spec_from(variant()), time_step=step))
    error = info.value
    assert (error.field, error.value, error.unit) == ("run.time_step", step, "s")
    assert "stability limit" in str(error) and "\n" not in str(error)
    stated = float(re.search(r"<= ([0-9.eE+-]+)", str(error))[1])
    assert stated == pytest.approx(thesis_limit(), rel=1e-3)
    assert stated < step, "the message must show the step beyond the limit it states"


@pytest.mark.parametrize("factor", [0.999, 1.001])
def test_the_limit_is_sharp(factor: float) -> None:
    """Undamped free vibration at the limit of its own stiffest mode (enforcement off): just below,
    energy is kept; just above, the highest mode grows from round-off and the run stops."""
    spec = spec_from(free_vibration_doc(0.0, degrees=400.0))
    mechanism = assemble(spec)
    step = factor * stability_limit(1.0 / 6.0, 0.5, float(mechanism.layer({"rocker"}).modes.omega.max()))
    options = NewmarkOptions(step, enforce_stability_limit=False, every_step=True)
    if factor < 1.0:
        E = energy(NewmarkBackend().simulate(mechanism, options), mechanism.M, mechanism.K)
        assert np.abs(E / E[0] - 1.0).max() < 1e-5  # 2e-6: linear acceleration keeps energy only nearly
    else:
        with pytest.raises(RunError, match=r"^diverged at t = \S+ s \(cam angle \S+ deg\) in configuration III \(rocker\)$"):
            NewmarkBackend().simulate(mechanism, options)


# ----- long runs -----

def seatings_per_revolution(trace: Trace, revolutions: int) -> tuple[list[float], list[float]]:
    """Per revolution: the first seating's angle within it (deg) and the largest seat force."""
    seatings, peaks = [], []
    for revolution in range(revolutions):
        inside = (trace.cam_angle >= 360.0 * revolution) & (trace.cam_angle < 360.0 * (revolution + 1))
        seatings.append(next(e.cam_angle for e in impacts(trace, "seat") if e.cam_angle >= 360.0 * revolution)
                        - 360.0 * revolution)
        peaks.append(float(trace.force("seat")[inside].max()))
    return seatings, peaks


@pytest.mark.slow
@pytest.mark.parametrize("name", ["gnilka-1a", "gnilka-2"])
def test_twenty_revolutions_keep_closed_contacts_shut_and_do_not_drift(name: str) -> None:
    """At every step for 20 revolutions: closed gaps zero to round-off (assert_sane), and
    each revolution seats the valve at the same angle with the same force."""
    trace, mechanism = run(variant(name, degrees=7200.0), every_step=True)
    assert_sane(trace, mechanism)
    seatings, peaks = seatings_per_revolution(trace, 20)
    np.testing.assert_allclose(seatings, seatings[0], rtol=0, atol=0.01)
    np.testing.assert_allclose(peaks, peaks[0], rtol=0.005)


# ----- chattering contacts -----

@pytest.mark.parametrize("bouncy", [("seat",), ("cam",), ("seat", "cam")], ids="+".join)
def test_bouncing_contacts_make_finite_trains_decaying_at_the_restitution(bouncy: tuple[str, ...]) -> None:
    """Restitution 0.9 with the momentum law (the impulse acts on the whole train): each bounce train
    slows geometrically, about 0.8-0.9 per impact, and ends. (With the local law the rebounding valve
    or follower is driven back at once by the train behind it: four impacts a train, not decaying.)"""
    trace, mechanism = run(variant(restitution={name: 0.9 for name in bouncy}, law="momentum"))
    assert_sane(trace, mechanism)
    assert len(trace.events) < 5000
    for name in bouncy:
        trains = [t for t in bounce_trains(trace, name) if len(t) >= 5]
        assert trains
        for speeds in trains:
            assert len(speeds) < 200
            assert 0.7 < np.median(speeds[1:] / speeds[:-1]) < 0.95
            assert speeds[-1] < 0.5 * speeds.max()


@pytest.mark.slow
def test_restitution_on_every_clearance_runs_sane_or_stops_clearly() -> None:
    """Restitution 0.9 on cam, rocker and seat: the pushrod rattles between cam and rocker
    (about 17,000 events in 850 deg). A clear stop is acceptable; a trace must be whole,
    and it must come in reasonable time."""
    doc = variant(restitution={"cam": 0.9, "rocker": 0.9, "seat": 0.9})
    try:
        trace, mechanism = run(doc, budget=30.0, chunk_steps=1)
    except RunError as error:
        assert re.fullmatch(r".* at t = \S+ s \(cam angle \S+ deg\) in configuration \S+ \(\S+\)", str(error))
        return
    assert_sane(trace, mechanism)


@pytest.mark.slow
def test_many_events_are_all_recorded() -> None:
    """Restitution 0.9 on the cam for ten revolutions (momentum law): thousands of events. The event list is
    the same whether the back end hands back control every 100 steps or once at the end."""
    spec = spec_from(variant(restitution={"cam": 0.9}, degrees=3600.0, law="momentum"))
    counts = {}
    for chunk_steps in (100, 10**6):
        trace = NewmarkBackend().simulate(assemble(spec), NewmarkOptions(1e-6, chunk_steps=chunk_steps))
        counts[chunk_steps] = len(trace.events)
        assert trace.events[-1].after == trace.configuration[-1]
    assert counts[10**6] == counts[100] > 4096


# ----- limits the loader enforces -----

LIMITS = [
    # (path in the preset, bad value, field, expected, unit)
    (("run", "rpm"), 0.0, "run.rpm", ">= 0.001 and <= 1e+06", "rev/min"),
    (("run", "degrees"), 0.0, "run.degrees", ">= 1e-06 and <= 3.6e+06", "deg"),
    (("run", "time_step"), 0.0, "run.time_step", ">= 1e-12 and <= 0.1", "s"),
    (("run", "output_interval"), 0.0, "run.output_interval", ">= 1e-06 and <= 3.6e+06", "deg"),
    (("run", "beta"), 0.0, "run.beta", "> 0 and <= 0.5", ""),
    (("run", "beta"), 0.6, "run.beta", "> 0 and <= 0.5", ""),
    (("run", "gamma"), 0.4, "run.gamma", ">= 0.5 and <= 1", ""),
    (("cam", "amplitude"), 0.0, "cam.amplitude", ">= 1e-06 and <= 10000", "in"),
    (("cam", "offset"), -1.0, "cam.offset", ">= 0", "in"),
    (("clearances", 2, "restitution"), 1.1, "clearances[2].restitution", ">= 0 and <= 1", ""),
    (("clearances", 0, "restitution"), -0.1, "clearances[0].restitution", ">= 0 and <= 1", ""),
    (("damping", "default_ratio"), -0.1, "damping.default_ratio", ">= 0 and <= 1", ""),
    (("damping", "layers", 1, "mode_ratios", "2"), 1.5, "damping.layers[1].mode_ratios.2", ">= 0 and <= 1", ""),
    (("damping", "factor"), -1.0, "damping.factor", ">= 0", ""),
    (("initial", "spring_preload"), -1.0, "initial.spring_preload", ">= 0", "lbf"),
    (("initial", "lever_ratio"), 0.0, "initial.lever_ratio", ">= 0.001 and <= 1000", ""),
    (("members", "valve_spring", "stiffness"), 0.0, "members.valve_spring.stiffness", ">= 1e-06 and <= 1e+13", "lbf/in"),
    (("members", "pushrod", "length"), -9.0, "members.pushrod.length", ">= 1e-06 and <= 10000", "in"),
    (("members", "pushrod", "modulus"), 0.0, "members.pushrod.modulus", ">= 0.001 and <= 1e+13", "lbf/in^2"),
    (("gravity",), 0.0, "gravity", ">= 0.001 and <= 100000", "in/s^2"),
]


@pytest.mark.parametrize("path, value, field, expected, unit", LIMITS, ids=[f"{l[2]}={l[1]}" for l in LIMITS])
def test_every_range_limit_is_refused_in_one_line(path: tuple, value: float, field: str, expected: str,
                                                   unit: str) -> None:
    doc = variant()
    target = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    with pytest.raises(InputError) as info:
        spec_from(doc)
    error = info.value
    assert (error.field, error.value, error.unit) == (field, value, unit)
    assert expected in error.expected
    assert str(error) == f"{field}: got {value!r}, expected {error.expected}" + (f" {unit}" if unit else "")
