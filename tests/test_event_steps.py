"""The Newmark kernel's event steps when a step is shorter than the event-location tolerance.

`vtool solve gnilka-1a --degrees 240000 --start quasi-static` stopped at 238,558.6 deg with
"chattering contact": the cam contact opened 3.5 ns before a point of the step grid, the round-off
of the cam's position at 4,164 rad (a few 1e-13 in, more than the gap allowance) closed it again
2.5e-13 s before the grid point, and the step that remained was shorter than the location tolerance
(1e-12 s). Two rules of loop.py failed there: the monitors that did not cross kept tau = 2h, which
take_events (tau <= h + tol) took as events once h < tol/2, so a seat pushing with 564 lbf was
opened and a rocker 0.0027 in apart was struck at +339 in/s; and locate_event returned the step's
start for a bracket narrower than the tolerance, an event that makes no progress, so the grazing
contact closed and opened again at the same instant until the chattering stop.

Here the situation is built directly: example 1A's static start with the cam contact open, its gap
exactly zero and closing at 10 in/s, 2.5e-13 s before the first grid point.
"""

from __future__ import annotations

import os

import pytest

from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.newmark import kernel, layout
from vtool.solvers.newmark.backend import KernelRun, NewmarkBackend
from vtool.solvers.trace import TraceBuilder

APPROACH = 10.0  # in/s: the cam gap's closing velocity at the start


def events_after_a_short_step():  # noqa: ANN201  (the events, the start time, the grid point, the problem)
    spec = with_run_overrides(load_preset("gnilka-1a"), degrees=0.2)  # 2.9 steps of 1 µs at 11,000 RPM
    mechanism = assemble(spec)
    backend = NewmarkBackend()
    options = backend.default_options(mechanism)
    problem = ContactProblem.for_run(mechanism, backend.event_rules(options))
    builder = TraceBuilder(spec, problem.source_numbers, problem.omega, None)
    run = KernelRun(problem, options, builder)
    dt = options.time_step
    t0 = dt - 0.25 * 1e-6 * dt  # a quarter of the location tolerance before the first grid point
    cam = [c.name for c in spec.clearances].index("cam")
    bits = problem.cl[:, layout.CL_BIT]
    state = run.state
    state.fst[layout.F_T] = t0
    state.ist[layout.I_CFG] = problem.start_mask & ~int(bits[cam])  # the cam contact open
    src = problem.sources_at(t0)
    kernel.shut_gap(problem.cl, problem.clf, cam, state.x, src)  # its gap exactly zero
    sense = problem.clf[cam, layout.CLF_SIGN]
    state.v[problem.cl[cam, layout.CL_AHEAD]] = src[3 * problem.cl[cam, layout.CL_SRC] + 1] - sense * APPROACH
    assert kernel.gap_velocity(problem.cl, problem.clf, cam, state.v, src) == pytest.approx(-APPROACH)
    run.execute(None, None)
    return builder.events, t0, dt, problem


def test_a_step_shorter_than_the_tolerance_takes_only_the_crossing_monitors_event() -> None:
    """The rocker (closed, pushing) and the seat (0.6 in open) do not cross in the 2.5e-13 s step: the
    cam's closing is the only event (the old rule opened the rocker and struck the seat)."""
    events, t0, dt, _ = events_after_a_short_step()
    first = [e for e in events if e.time <= dt]
    assert [(e.clearance, e.kind) for e in first] == [("cam", "closed")]
    assert first[0].relative_velocity == pytest.approx(-APPROACH, rel=1e-6)


def test_an_event_in_a_step_shorter_than_the_tolerance_is_at_the_steps_end() -> None:
    """The crossing lies within the tolerance of both ends of the step; the event is taken at its end
    (the grid point), so the run moves on (the old rule took it at the start, t0: no progress)."""
    events, t0, dt, _ = events_after_a_short_step()
    assert events[0].time > t0
    assert events[0].time == pytest.approx(dt, abs=1e-18)


@pytest.mark.skipif(not os.environ.get("VTOOL_SLOW_TESTS"), reason="620 MB of rows: VTOOL_SLOW_TESTS=1")
def test_the_reported_long_quasi_static_run_finishes() -> None:
    """The reported run (issue 37), 667 revolutions. Its grazing instant hangs on the last bits of the
    kernel's arithmetic, so the two tests above are the ones that fail reliably without the fix."""
    import vtool

    result = vtool.load("gnilka-1a").set({"initial.velocities": "quasi-static"}, degrees=240000.0).solve()
    assert len(result.events) > 15_000  # 15,994 with the fix; before it, "chattering contact" at 238,558.6 deg
