"""A back end written only against the back-end contract: fixed-step RK4 between located events.

It uses nothing but :mod:`vtool.solvers.backends` (the base class, RunStats)
and the contact problem's Python-level methods
(:meth:`~vtool.solvers.model.contact.ContactProblem.accelerations`,
``project``, ``monitors``, ``contact_forces``, ``sources_at`` and the
:class:`~vtool.solvers.model.contact.Transitions` from ``transitions``):
between events, the classical fourth-order Runge-Kutta step on (x, v) of
every coordinate in the current configuration; an event is located by
bisection of the step to ``time_tolerance``; the shared rules then give the
next configuration. tests/test_contract_backend.py runs gnilka-1a with it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError, RunError
from vtool.solvers.backends import Backend, Cancel, Progress, RunStats
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import RunSpec
from vtool.solvers.trace import TraceBuilder


@dataclass(frozen=True)
class RK4Options:
    time_step: float  # s
    output_interval: float = 1.0  # deg
    time_tolerance: float = 1e-12  # s, event location


class RK4Backend(Backend[RK4Options]):
    """Fixed-step RK4 between events (rigid and linear contacts)."""

    name = "rk4-test"
    fixed_step = True
    supports_progress = True

    @staticmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> RK4Options:
        return RK4Options(run.time_step, run.output_interval)

    def check(self, mechanism: Mechanism, options: RK4Options) -> None:
        if not options.time_step > 0.0:
            raise InputError("run.time_step", options.time_step, "> 0", "s")
        if any(c.contact == "hertz" for c in mechanism.spec.clearances):
            raise InputError("run.backend", self.name, "a preset with rigid or linear contacts only")

    def integrate(self, problem: ContactProblem, options: RK4Options, builder: TraceBuilder,
                  progress: Progress | None, cancel: Cancel | None) -> RunStats:
        run = _Run(problem, options, builder)
        run.execute(progress, cancel)
        return RunStats(run.steps, run.peak, run.peak_late, settings={"time_step_s": options.time_step})


class _Run:
    def __init__(self, problem: ContactProblem, options: RK4Options, builder: TraceBuilder) -> None:
        self.problem, self.options, self.builder = problem, options, builder
        self.t_end = problem.angle_to_time(problem.spec.run.degrees)
        self.out_dt = problem.angle_to_time(options.output_interval)
        self.t_rev = problem.angle_to_time(360.0)
        self.watched = np.flatnonzero(problem.monitored)
        self.peak, self.peak_late = np.zeros(problem.ncl), np.zeros(problem.ncl)
        self.steps, self.next_out = 0, 0
        self.rows: list[tuple[float, np.ndarray, np.ndarray, int]] = []

    def step(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, h: float) -> tuple[np.ndarray, ...]:
        """(x, v, a) at t + h from (x, v) at t: one classical RK4 step, then the configuration's ties."""
        acc = self.problem.accelerations
        k1x, k1v = v, acc(mask, t, x, v)
        k2x, k2v = v + 0.5 * h * k1v, acc(mask, t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v)
        k3x, k3v = v + 0.5 * h * k2v, acc(mask, t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v)
        k4x, k4v = v + h * k3v, acc(mask, t + h, x + h * k3x, v + h * k3v)
        x1 = x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v1 = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        x1, v1 = self.problem.project(mask, t + h, x1, v1)
        return x1, v1, acc(mask, t + h, x1, v1)

    def crossed(self, values: np.ndarray, before: np.ndarray) -> list[int]:
        """Watched monitors below zero that were not, or are falling further (a just-released contact's
        force may start a round-off below zero)."""
        return [int(k) for k in self.watched if values[k] < 0.0 and (before[k] >= 0.0 or values[k] < before[k])]

    def record(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, a: np.ndarray) -> None:
        src = self.problem.sources_at(t)
        q3 = np.stack([np.concatenate([x, src[0::3]]), np.concatenate([v, src[1::3]]),
                       np.concatenate([a, src[2::3]])])
        self.rows.append((t, q3, self.problem.contact_forces(mask, t, x, v, a), mask))

    def outputs(self, mask: int, t0: float, x: np.ndarray, v: np.ndarray, t1: float) -> None:
        """Rows at the output angles in [t0, t1), from the state at t0."""
        while self.next_out * self.out_dt < t1 and self.next_out * self.out_dt <= self.t_end:
            t = self.next_out * self.out_dt
            self.record(mask, t, *((x, v, self.problem.accelerations(mask, t0, x, v)) if t == t0
                                   else self.step(mask, t0, x, v, t - t0)))
            self.next_out += 1

    def execute(self, progress: Progress | None, cancel: Cancel | None) -> None:
        problem, dt, tol = self.problem, self.options.time_step, self.options.time_tolerance
        rules = problem.transitions(self.builder)
        mask, x, v, a = rules.start()
        t = 0.0
        before = problem.monitors(mask, t, x, v, a)
        while t < self.t_end:
            h = min(dt, self.t_end - t)
            state = self.step(mask, t, x, v, h)
            values = problem.monitors(mask, t + h, *state)
            fired = self.crossed(values, before)
            if fired:  # bisect the step down to the first crossing
                low, high = 0.0, h
                while high - low > tol:
                    middle = 0.5 * (low + high)
                    trial = self.step(mask, t, x, v, middle)
                    trial_values = problem.monitors(mask, t + middle, *trial)
                    if self.crossed(trial_values, before):
                        high, state, values = middle, trial, trial_values
                    else:
                        low = middle
                h = high
                fired = self.crossed(values, before)
            self.outputs(mask, t, x, v, t + h)
            forces = problem.contact_forces(mask, t + h, *state)
            np.maximum(self.peak, forces, out=self.peak)
            if t + h >= self.t_rev:
                np.maximum(self.peak_late, forces, out=self.peak_late)
            t, (x, v, a), before = t + h, state, values
            self.steps += 1
            if fired:
                mask, x, v, a = rules.apply(mask, t, x, v, fired)
                before = problem.monitors(mask, t, x, v, a)
            if progress is not None and self.steps % 1000 == 0:
                progress(t / self.t_end)
            if cancel is not None and cancel():
                raise RunError(f"cancelled at t = {t:.6g} s")
        self.outputs(mask, t, x, v, self.t_end * (1 + 1e-12))
        times, q3, forces, masks = zip(*self.rows, strict=True)
        self.builder.add_rows(np.array(times), np.array(q3), np.array(forces), np.array(masks, dtype=np.int64))
