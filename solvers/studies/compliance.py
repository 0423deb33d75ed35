"""A compliant contact against the rigid one: what a stiffness study measures (docs/contact.md).

Every clearance of a mechanism is given a linear contact of stiffness k and
damping ratio ζ (:class:`~vtool.solvers.model.spec.ClearanceSpec`), and the run's
first figures are compared with the rigid runs':

* the throw-off angle: the first opening of the cam contact (deg);
* the first seating: angle and approach velocity of the first closing of the
  seat clearance;
* the impulse of that impact, J = (M Δq̇) at the valve coordinate across the
  window [θ_c - 0.05°, θ_c + 0.5°] around it: for a rigid run the impact's
  impulse plus the window's other forces, for a compliant run the contact
  force's integral plus the same (read on output rows 0.05° apart);
* the peak seat force, the peak overlap and the event count;
* for the Newmark back end, the largest step 1 µs / 2^j that reproduces the
  exact back end's throw-off and seating angles within 0.01°, seating
  velocity within 0.5 % and peak seat force within 1 % (the step each k
  needs).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError
from vtool.solvers import backends
from vtool.solvers.model.mechanism import assemble
from vtool.solvers.model.spec import LINEAR, MechanismSpec
from vtool.solvers.trace import CLOSED, OPENED, Trace

OUTPUT_INTERVAL_DEG = 0.05
WINDOW_DEG = (0.05, 0.5)  # before, after the first seating
STEPS = tuple(1e-6 / 2**j for j in range(9))  # s: 1 µs down to 3.9 ns
ANGLE_TOLERANCE_DEG = 0.01
VELOCITY_TOLERANCE = 0.005
FORCE_TOLERANCE = 0.01


@dataclass(frozen=True)
class Figures:
    """A run's first figures (see the module doc); angles in deg, in the preset's units otherwise."""

    throw_off: float
    seating_angle: float
    seating_velocity: float
    impulse: float
    peak_seat_force: float
    peak_overlap: float | None
    events: int
    steps: int
    wall: float


def with_contacts(spec: MechanismSpec, stiffness: float | None, ratio: float = 1.0,
                  impact: str | None = None) -> MechanismSpec:
    """The spec with every enabled clearance linear (stiffness k, ratio ζ), or rigid (``None``) with this
    impact law; output rows every :data:`OUTPUT_INTERVAL_DEG`."""
    clearances = tuple(
        dataclasses.replace(c, contact=LINEAR, contact_stiffness=stiffness, contact_damping=None,
                            contact_damping_ratio=ratio) if stiffness is not None and c.state == "enabled"
        else c for c in spec.clearances)
    contact = spec.contact if impact is None else dataclasses.replace(spec.contact, impact=impact)
    run = dataclasses.replace(spec.run, output_interval=OUTPUT_INTERVAL_DEG)
    return dataclasses.replace(spec, clearances=clearances, contact=contact, run=run)


def figures(spec: MechanismSpec, backend: str | None = None, time_step: float | None = None) -> Figures:
    """Run the spec with a back end (default: the registry's reference back end) and read its first figures."""
    backend = backend or backends.with_flag("reference")[0]
    if time_step is not None:
        spec = dataclasses.replace(spec, run=dataclasses.replace(spec.run, time_step=time_step))
    mechanism = assemble(spec)
    runner = backends.get(backend)()
    started = time.perf_counter()
    trace = runner.simulate(mechanism, runner.options_from_run(spec.run))
    wall = time.perf_counter() - started - trace.statistics.compile_time
    seat_index = next(i for i, c in enumerate(spec.clearances)
                      if spec.seat is not None and c.behind == spec.seat.coordinate)
    seat = spec.clearances[seat_index]
    throw_off = next(e.cam_angle for e in trace.events if e.clearance == spec.clearances[0].name and e.kind == OPENED)
    seating = next(e for e in trace.events if e.clearance == seat.name and e.kind == CLOSED)
    summary = trace.summary()["clearances"][seat_index]
    return Figures(throw_off, seating.cam_angle, -seating.relative_velocity,
                   impulse(trace, mechanism.M, seat.ahead, seating.cam_angle), summary["peak_force"],
                   summary.get("peak_overlap"), len(trace.events), trace.statistics.steps, wall)


def impulse(trace: Trace, M: np.ndarray, coordinate: int, angle: float) -> float:
    """(M Δq̇) at ``coordinate`` between the output rows bracketing the window around ``angle``."""
    before = int(np.searchsorted(trace.cam_angle, angle - WINDOW_DEG[0], side="right")) - 1
    after = int(np.searchsorted(trace.cam_angle, angle + WINDOW_DEG[1], side="left"))
    if before < 0 or after >= len(trace.time):
        return float("nan")
    n = M.shape[0]
    change = trace.qd[after, :n] - trace.qd[before, :n]
    return float((M @ change)[coordinate - 1])


def step_needed(spec: MechanismSpec, reference: Figures) -> tuple[float | None, Figures | None]:
    """The largest step of :data:`STEPS` at which Newmark meets the tolerances against ``reference``."""
    for dt in STEPS:
        try:
            found = figures(spec, backends.with_flag("fixed_step")[0], dt)
        except InputError:  # beyond the stability limit
            continue
        if (abs(found.throw_off - reference.throw_off) <= ANGLE_TOLERANCE_DEG
                and abs(found.seating_angle - reference.seating_angle) <= ANGLE_TOLERANCE_DEG
                and abs(found.seating_velocity - reference.seating_velocity)
                <= VELOCITY_TOLERANCE * abs(reference.seating_velocity)
                and abs(found.peak_seat_force - reference.peak_seat_force)
                <= FORCE_TOLERANCE * abs(reference.peak_seat_force)):
            return dt, found
    return None, None


@dataclass(frozen=True)
class StudyRow:
    label: str
    exact: Figures
    step: float | None = None  # the step Newmark needs (s)
    newmark: Figures | None = None  # Newmark's figures at that step


def study(spec: MechanismSpec, stiffnesses: tuple[float, ...], ratio: float = 1.0,
          laws: tuple[str, ...] = ("local", "momentum")) -> list[StudyRow]:
    """The rigid runs (one per impact law) and one compliant run per stiffness, with the step each needs."""
    rows = [StudyRow(f"rigid, {law} law", figures(with_contacts(spec, None, impact=law))) for law in laws]
    for k in stiffnesses:
        compliant = with_contacts(spec, k, ratio)
        reference = figures(compliant)
        rows.append(StudyRow(f"linear, k = {k:.0e}", reference, *step_needed(compliant, reference)))
    return rows
