"""The extremes table of docs/limits.md, measured by running the cases tests/test_extremes.py runs.

Used by benchmarks/limits_docs.py (blocks ``limits-extremes``, checked by
tests/test_limits_docs.py, and ``limits-extremes-long``, written by ``--write``
only: the four cases the suite marks slow). The cases are built with the
test module's own helpers (``variant``, ``static_max_lift``, ...), so the page
and the tests describe the same runs; the figures are deterministic (no wall
times). The tolerances a row quotes ("within 1e-6") are the test's asserted
bounds, not measurements.
"""

from __future__ import annotations

import math
import sys
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from tests.test_extremes import (  # noqa: E402
    CAM_BIT,
    SEAT_BIT,
    VALVE,
    VALVE_OPEN,
    bounce_trains,
    first_throw,
    free_vibration_doc,
    impacts,
    lowest_frequency,
    seatings_per_revolution,
    separations,
    static_max_lift,
    static_seating_angle,
    thesis_limit,
    valve_lift_bound,
    valve_ratio,
    variant,
)
from tests.valvetrain_cases import spec_from  # noqa: E402
from vtool.errors import InputError, PresetWarning, RunError  # noqa: E402
from vtool.markdown import table  # noqa: E402
from vtool.presets.valvetrain import with_run_overrides  # noqa: E402
from vtool.solvers.model.mechanism import Mechanism, assemble  # noqa: E402
from vtool.solvers.newmark.backend import NewmarkBackend, NewmarkOptions, stability_limit  # noqa: E402
from vtool.solvers.run import simulate  # noqa: E402
from vtool.solvers.trace import Trace  # noqa: E402

HEADER = ("extreme", "outcome", "measured", "test")


def run(doc: dict, every_step: bool = False) -> tuple[Trace, Mechanism]:
    """One case as the test runs it (without the test's wall-time watchdog); the preset warnings an
    extreme is expected to raise (a seat never reached, a nearly undamped run) are not printed."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PresetWarning)
        spec = spec_from(doc)
        return simulate(spec, every_step=every_step), assemble(spec)


def refusal(doc: dict) -> str:
    try:
        simulate(spec_from(doc))
    except InputError as error:
        return str(error)
    raise RuntimeError("expected a refusal")


def speed(event) -> str:  # impact speed, in/s
    return f"{-event.relative_velocity:,.0f}"


def peaks(trace: Trace) -> str:
    return " / ".join(f"{p:,.0f}" for p in trace.peak_force)


def percent(fraction: float, digits: int = 1) -> str:
    return f"{100.0 * fraction:.{digits}f} %"


def rows(nominal: Trace) -> list[tuple[str, str, str, str]]:
    out = []
    seat0 = impacts(nominal, "seat")[0]

    trace, mech = run(variant(rpm=30000.0))
    out.append(("30,000 rpm", "sane, separation",
                f"thrown off at {first_throw(trace):.1f}° ({first_throw(nominal):.1f}° at 11,000 rpm), cam contact "
                f"open {percent(np.mean(trace.configuration & CAM_BIT == 0))} of the time, valve floats to "
                f"{trace.coordinate(VALVE).max():.3g} in (static {static_max_lift(mech):.3g}, bound "
                f"{valve_lift_bound(mech):.3g}), seats at up to {max(-e.relative_velocity for e in impacts(trace, 'seat')):,.0f} in/s "
                f"({max(-e.relative_velocity for e in impacts(nominal, 'seat')):,.0f}); peaks {peaks(trace)} lbf",
                "`test_at_30000_rpm_the_follower_is_thrown_off_and_the_valve_floats`"))

    at_zero, _ = run(variant(seat=0.0))
    without, _ = run(variant(seat="removed"))
    identical = (np.array_equal(at_zero.q[:, :9], without.q[:, :9])
                 and np.array_equal(at_zero.contact_force, without.contact_force))
    seat_events = len([e for e in at_zero.events if e.clearance == "seat"])
    out.append(("seat at 0 in", "sane, never reached",
                f"{seat_events} seat events, valve ≥ {(at_zero.coordinate(VALVE) - at_zero.coordinate(10)).min():.3g} in "
                f"above the seat; trace {'identical (bit for bit)' if identical else 'not identical'} to the seat removed",
                "`test_a_seat_at_zero_is_never_reached_and_changes_nothing`"))

    trace, mech = run(variant(seat=1.0))
    first = impacts(trace, "seat")[0]
    out.append(("seat at 1 in", "sane",
                f"seats at {first.cam_angle:.1f}° (static {static_seating_angle(mech):.1f}°) at {speed(first)} in/s "
                f"({speed(seat0)} with the 0.7 in seat), seated {percent(np.mean(trace.configuration & SEAT_BIT != 0))} "
                f"of the time ({percent(np.mean(nominal.configuration & SEAT_BIT != 0))}), peak seat force "
                f"{trace.peak_force[2]:,.0f} lbf",
                "`test_a_seat_at_one_inch_closes_the_valve_earlier_harder_and_longer`"))

    start = assemble(spec_from(variant())).start.q[VALVE - 1]
    out.append((f"seat at 2 in (above the valve's start, {start:.3g} in)", "refused", f"`{refusal(variant(seat=2.0))}`",
                "`test_a_seat_above_the_valve_at_the_start_is_refused_or_run_off_the_seat`"))
    out.append(("pushrod–rocker lash", "not expressible: the clearance closes at q2 = q8; a `lash` key is refused; "
                "zero lash that never opens is `state = \"pinned\"` (1C, 1D); starting it open is refused", "`InputError`",
                "`test_the_pushrod_rocker_lash_is_zero_and_an_open_start_is_refused`"))

    undamped, _ = run(variant(damping=0.0), every_step=True)
    damped, _ = run(variant(damping=1.0))
    out.append(("damping ratio 0 (every mode, every layer)", "sane, restless",
                f"the contacts keep separating and re-closing: {len(undamped.events):,} events against "
                f"{len(damped.events):,} critically damped; free vibration keeps energy within 1e-6 over 45 ms and the "
                "fundamental follows cos/sin within 1e-5 (the test's bounds)",
                "`test_damping_extremes_make_a_restless_or_a_quiet_valve_train`, "
                "`test_free_vibration_of_the_fundamental_at_the_damping_extremes[0.0]`"))
    seatings = ", ".join(f"{e.cam_angle:.1f}° at {speed(e)} in/s" for e in impacts(damped, "seat"))
    out.append(("damping ratio 1", "sane, oscillations die out",
                (f"{len(impacts(damped, 'seat'))} seat impacts in 850° ({seatings}), " if seatings else
                 "the valve floats clear of the seat (no seat impact in 850°), ") +
                f"{len(damped.events)} events; "
                "free vibration: energy never rises, below 1e-3 of its start after 10 ms, the fundamental follows "
                "(η₀ + (η̇₀ + ωη₀)t)e^(−ωt) within 1e-5 (the test's bounds), the valve creeps back without overshoot",
                "`test_damping_extremes_make_a_restless_or_a_quiet_valve_train`, "
                "`test_free_vibration_of_the_fundamental_at_the_damping_extremes[1.0]`"))
    out.append(("damping ratio 1.01", "refused", f"`{refusal(variant(damping=1.01))}`",
                "`test_damping_ratio_above_one_is_refused`"))

    doc = variant(spring=0.1)
    rate = doc["members"]["valve_spring"]["stiffness"]
    trace, mech = run(doc)
    q7 = trace.coordinate(VALVE)
    out.append((f"spring × 0.1 ({rate:g} lbf/in)", "sane",
                f"fundamental {lowest_frequency(mech):,.0f} rad/s (cam {mech.omega:,.0f}): thrown off at "
                f"{first_throw(trace):.1f}°, cam contact open {percent(np.mean(trace.configuration & CAM_BIT == 0))} of "
                f"the time, valve {q7.min():.3g}–{q7.max():.3g} in (the same preload on a soft spring puts the start at "
                f"{mech.start.q[VALVE - 1]:.3g} in), {len(impacts(trace, 'seat'))} seat impacts",
                "`test_a_soft_spring_lets_the_follower_fly_most_of_the_revolution`"))

    trace, mech = run(variant(spring=100.0, seat="removed"))
    out.append(("spring × 100, seat removed", "sane",
                f"fundamental {lowest_frequency(mech):,.0f} rad/s: {len(trace.events)} events in 850°, "
                f"F1 ≥ {trace.force('cam').min():,.0f} lbf", "`test_a_stiff_spring_keeps_the_follower_on_the_cam`"))
    start = assemble(spec_from(variant(spring=100.0, seat="removed"))).start.q[VALVE - 1]
    out.append(("spring × 100 with the 0.7 in seat", f"refused: the valve would start at {start:.3g} in, inside its seat",
                f"`{refusal(variant(spring=100.0))}`",
                "`test_a_stiff_spring_with_the_thesis_seat_is_refused_or_run_off_the_seat`"))

    scaled, forces = [], []
    for amplitude in (1e-4, 1e-3):
        trace, mech = run(variant(amplitude=amplitude, seat="removed"))
        base = mech.spec.initial.spring_preload * mech.spec.initial.lever_ratio
        scaled.append((trace.force("cam") - base) / amplitude)
        forces.append(trace)
    small = forces[0]
    linear = float(np.abs(scaled[0] - scaled[1]).max() / np.abs(scaled[1]).max())
    always_open = bool((small.configuration == VALVE_OPEN).all())
    out.append(("cam amplitude 1e-4 in, seat removed", "sane, linear",
                f"{len(small.events)} events, configuration {'VII throughout' if always_open else 'changes'}, "
                f"F1 = {small.force('cam').min():.2f}–{small.force('cam').max():.2f} lbf; (F1 − {base:.1f} lbf)/A for "
                f"A = 1e-4 and 1e-3 in differ by {linear:.1e} of its largest value",
                "`test_a_tiny_cam_amplitude_gives_a_linear_response_without_events`"))
    start = assemble(spec_from(variant(amplitude=1e-4, seat="removed"))).start.q[VALVE - 1]
    out.append(("cam amplitude 1e-4 in with the 0.7 in seat", f"refused: the valve would start at {start:.3g} in, "
                "inside its seat", f"`{refusal(variant(amplitude=1e-4))}`",
                "`test_a_tiny_cam_amplitude_with_the_thesis_seat_is_refused_or_run_off_the_seat`"))

    trace, mech = run(variant(amplitude=2.0))
    out.append(("cam amplitude 2 in", "sane",
                f"thrown off at {first_throw(trace):.1f}°, valve to {trace.coordinate(VALVE).max():.3g} in (static "
                f"{static_max_lift(mech):.3g}, bound {valve_lift_bound(mech):.3g}), seats at up to "
                f"{max(-e.relative_velocity for e in impacts(trace, 'seat')):,.0f} in/s; peaks {peaks(trace)} lbf",
                "`test_a_large_cam_amplitude_throws_the_follower_earlier`"))

    limit = thesis_limit()
    trace, _ = run(variant(time_step=0.999 * limit))
    near, ref = impacts(trace, "seat"), impacts(nominal, "seat")

    def versus(a: float, b: float) -> str:
        return f"{a:,.0f} lbf (1 µs: {b:,.0f}, {100.0 * (a / b - 1.0):+.2f} %)"

    second = (f", second {near[1].cam_angle:.2f}° ({ref[1].cam_angle:.2f}°)" if len(near) > 1 and len(ref) > 1 else "")
    out.append((f"Δt = 0.999 × limit ({0.999 * limit * 1e6:.4g} µs)", "sane",
                f"{trace.statistics.steps:,} steps (1 µs: {nominal.statistics.steps:,}); first seating "
                f"{near[0].cam_angle:.3f}° ({ref[0].cam_angle:.3f}° at 1 µs){second}; seat peak "
                f"{versus(trace.peak_force[2], nominal.peak_force[2])}, rocker peak "
                f"{versus(trace.peak_force[1], nominal.peak_force[1])}",
                "`test_a_step_just_below_the_limit_runs_and_agrees_with_one_microsecond`"))
    for factor, test in ((1.001, "`test_a_step_just_above_the_limit_is_refused_with_the_limit[1.001]`"),
                         (1.00001, "`…[1.00001]`")):
        try:
            simulate(with_run_overrides(spec_from(variant()), time_step=factor * limit))
            message = "not refused"
        except InputError as error:
            message = f"`{error}`" + (": the printed limit is rounded down, never above the real one"
                                      if factor < 1.001 else "")
        out.append((f"Δt = {factor:g} × limit", "refused", message, test))

    spec = spec_from(free_vibration_doc(0.0, degrees=400.0))
    mech = assemble(spec)
    own = stability_limit(1.0 / 6.0, 0.5, float(mech.layer({"rocker"}).modes.omega.max()))
    below = NewmarkBackend().simulate(mech, NewmarkOptions(0.999 * own, enforce_stability_limit=False, every_step=True))
    from tests.test_extremes import energy
    E = energy(below, mech.M, mech.K)
    try:
        NewmarkBackend().simulate(mech, NewmarkOptions(1.001 * own, enforce_stability_limit=False, every_step=True))
        above = "runs"
    except RunError as error:
        above = f"`RunError: {error}`"
    out.extend(restitution_rows())
    out.append((f"the limit is sharp (free vibration, enforcement off, the pinned layer's own limit {own * 1e6:.4g} µs)",
                "—", f"0.999×: energy kept within {np.abs(E / E[0] - 1.0).max():.1e} over {below.statistics.steps:,} "
                f"steps; 1.001×: {above}", "`test_the_limit_is_sharp`"))
    return out


def restitution_rows() -> list[tuple[str, str, str, str]]:
    """Restitution 0.9 with the momentum law (as the test runs them): bounce trains per clearance."""
    out = []
    for bouncy, label, test in ((("seat",), "the seat", "`test_bouncing_contacts_make_finite_trains_decaying_at_the_restitution[seat]`"),
                                (("cam",), "the cam", "`…[cam]`"), (("seat", "cam"), "seat and cam", "`…[seat+cam]`")):
        trace, _ = run(variant(restitution={name: 0.9 for name in bouncy}, law="momentum"))
        parts = []
        for name in bouncy:
            trains = [t for t in bounce_trains(trace, name) if len(t) >= 5]
            lengths = [len(t) for t in trains]
            ratios = [float(np.median(t[1:] / t[:-1])) for t in trains]
            parts.append(f"{name}: {len(trains)} trains of {min(lengths)}–{max(lengths)} impacts, median speed ratio "
                         f"{min(ratios):.2f}–{max(ratios):.2f} per impact" if trains else f"{name}: no train of 5 impacts")
        out.append((f"restitution 0.9 on {label} (momentum law)", "sane",
                    f"{len(trace.events):,} events; " + "; ".join(parts), test))
    return out


def long_rows(nominal: Trace) -> list[tuple[str, str, str, str]]:
    """The cases the suite marks slow (a few seconds together)."""
    out = []
    trace, mech = run(variant(rpm=100.0, degrees=400.0, time_step=2.5e-6))
    spec, start = mech.spec, mech.start
    x = (spec.seat.position / valve_ratio(mech) - start.cam_offset) / spec.cam.amplitude
    seating_deg, lifting_deg = 180.0 - math.degrees(math.asin(x)), 360.0 + math.degrees(math.asin(x))
    seating = impacts(trace, "seat")[0]
    predicted = valve_ratio(mech) * spec.cam.amplitude * mech.omega * abs(math.cos(math.radians(seating_deg)))
    lifting = [e for e in separations(trace, "seat") if e.cam_angle > 270.0][0]
    riding = trace.configuration == VALVE_OPEN
    F1, F2 = trace.force("cam")[riding], trace.force("rocker")[riding]
    rate = next(m.stiffness for m in spec.members if m.name == "valve_spring")
    spring = rate * np.abs(trace.coordinate(4)[riding])
    lever = float(np.abs(F1 / (spec.initial.lever_ratio * spring) - 1.0).max())
    same = float(np.abs(F2 / F1 - 1.0).max())
    seated_only = all(e.after & SEAT_BIT for e in separations(trace, "cam"))
    out.append(("100 rpm (400°, Δt = 2.5 µs)", "sane, quasi-static",
                f"seats at {seating.cam_angle:.3f}° (static shape predicts {seating_deg:.3f}°) at "
                f"{-seating.relative_velocity:.4g} in/s (predicted {predicted:.4g}), lifts at {lifting.cam_angle:.2f}° "
                f"({lifting_deg:.2f}°); with the valve open F1 = {spec.initial.lever_ratio:g} × spring force within "
                f"{percent(lever)}, F2 = F1 within {percent(same)}; F1 {F1.min():,.0f}–{F1.max():,.0f} lbf; the follower "
                f"leaves the cam {'only with the valve seated (the lash opens)' if seated_only else 'with the valve open'}; "
                f"{trace.statistics.steps:,} steps", "`test_at_100_rpm_the_valve_train_is_quasi_static`"))
    for name, rpm_text, test in (("gnilka-1a", "1A", "`test_twenty_revolutions_keep_closed_contacts_shut_and_do_not_drift[gnilka-1a]`"),
                                 ("gnilka-2", "example 2", "`…[gnilka-2]`")):
        trace, mech = run(variant(name, degrees=7200.0), every_step=True)
        seatings, seat_peaks = seatings_per_revolution(trace, 20)
        out.append((f"20 revolutions, {rpm_text} ({mech.spec.run.rpm:,.0f} rpm), every step", "sane, no drift",
                    f"{len(trace.time):,} rows; first seating {seatings[0]:.4f}° every revolution (spread "
                    f"{np.ptp(seatings):.1e}°), seat peak {seat_peaks[0]:,.0f} lbf (spread "
                    f"{percent(np.ptp(seat_peaks) / seat_peaks[0], 3)}); {len(trace.events):,} events", test))
    trace, _ = run(variant(restitution={"cam": 0.9, "rocker": 0.9, "seat": 0.9}))
    hits = ", ".join(f"{name} {len(impacts(trace, name)):,}" for name in ("cam", "rocker", "seat"))
    parted = sum(len(separations(trace, name)) for name in ("cam", "rocker", "seat"))
    out.append(("restitution 0.9 on every clearance", "sane",
                f"{len(trace.events):,} events in 850°: impacts {hits}; {parted} separations (the bounce trains end "
                "in resting contact)",
                "`test_restitution_on_every_clearance_runs_sane_or_stops_clearly`"))
    trace, _ = run(variant(restitution={"cam": 0.9}, degrees=3600.0, law="momentum"))
    out.append((f"{len(trace.events):,} events in one run (restitution 0.9 on the cam, 3,600°, momentum law)",
                "sane, all recorded", f"{len(trace.events):,} events; the kernel hands its event buffer back before it "
                "can overflow", "`test_many_events_are_all_recorded`"))
    return out


def nominal_run() -> Trace:
    """The reference of the comparisons: 1A from the quasi-static start (the tests' ``nominal``)."""
    return run(variant())[0]


def extremes_block() -> str:
    return table(HEADER, rows(nominal_run()))


def long_block() -> str:
    return table(HEADER, long_rows(nominal_run()))
