"""The ``scipy`` back end: ``scipy.integrate.solve_ivp`` between events.

Each configuration's constrained equations, y' = A y + b(t)
(:mod:`vtool.solvers.exact.piecewise`), are integrated by DOP853 (default) or
Radau with the user's tolerances; every monitored clearance is a terminal
event function (contact force if closed, gap if open, direction negative).
At an event the integration stops, the event rules and impact law of the
other back ends are applied, and a new integration starts in the new
configuration. Outputs at the requested angles come from the dense output.
Peak contact forces are not only taken at the steps: every local maximum of
a contact force among the steps (within 1 % of the peak so far) is refined on
the dense output by a bounded Brent search between its neighbouring steps
(steps alone read peaks 0.04-6.6 % low).

This is what a Python user would reach for, and its known weakness shows:
solve_ivp only looks for sign changes between its own steps, so a monitor
that crosses zero twice within one step is missed, and every impact needs a
restart.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from vtool.errors import InputError, RunError
from vtool.solvers.backends import AccuracyKnobs, AccuracySetting
from vtool.solvers.cost import MAX_SCIPY_STEPS
from vtool.solvers.exact.backend import peak_brackets
from vtool.solvers.exact.piecewise import PiecewiseBackend, PiecewiseRun
from vtool.solvers.exact.statespace import StateSpace
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import RunSpec
from vtool.solvers.trace import TraceBuilder

METHODS = ("DOP853", "Radau", "RK45", "LSODA")
GUARD = 1e-12  # s after a restart during which no event is taken


@dataclass(frozen=True)
class ScipyOptions:
    rtol: float = 1e-9
    atol: float | None = None  # default: rtol times each state's scale
    method: str = "DOP853"
    output_interval: float = 1.0  # degrees
    every_step: bool = False

    @classmethod
    def from_run(cls, run: RunSpec, every_step: bool = False) -> ScipyOptions:
        return cls(output_interval=run.output_interval, every_step=every_step)


class ScipyBackend(PiecewiseBackend[ScipyOptions]):
    """solve_ivp back end (see module doc). Registered as ``scipy``."""

    name = "scipy"
    library_dependent = True
    max_steps = MAX_SCIPY_STEPS
    remedy = "a tighter rtol, or the exact back end"

    @staticmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> ScipyOptions:
        return ScipyOptions.from_run(run, every_step)

    @classmethod
    def accuracy_settings(cls, run: RunSpec, knobs: AccuracyKnobs) -> list[AccuracySetting]:
        """DOP853 at every relative tolerance."""
        return [AccuracySetting(f"DOP853 rtol={rtol:.0e}", run, ScipyOptions(rtol=rtol)) for rtol in knobs.rtols]

    def check(self, mechanism: Mechanism, options: ScipyOptions) -> None:
        if not 1e-14 <= options.rtol <= 1e-2:
            raise InputError("rtol", options.rtol, ">= 1e-14 and <= 1e-2")
        if options.method not in METHODS:
            raise InputError("method", options.method, f"one of: {', '.join(METHODS)}")

    def settings(self, options: ScipyOptions) -> dict:
        return {"method": options.method, "rtol": options.rtol}


class _ScipyRun(PiecewiseRun):
    backend = "scipy"

    def __init__(self, problem: ContactProblem, options: ScipyOptions, builder: TraceBuilder) -> None:
        super().__init__(problem, options.output_interval, options.every_step, builder)
        self.options = options
        start = problem.mechanism.start
        self.x_scale = max(float(np.abs(start.q).max()), 1e-12)
        self.v_scale = max(float(np.abs(start.qd).max()), self.x_scale * problem.omega, 1e-12)

    def advance(self, ss: StateSpace, t0: float, y0: np.ndarray, t_stop: float) -> tuple[float, np.ndarray, list[int]]:
        nf = ss.size // 2
        atol: float | np.ndarray | None = self.options.atol
        if atol is None:
            atol = np.concatenate([np.full(nf, self.x_scale), np.full(nf, self.v_scale)]) * self.options.rtol

        if ss.hertz is not None and ss.hertz.size:

            def rhs(t: float, y: np.ndarray) -> np.ndarray:
                return ss.A @ y + ss.forcing(t) + ss.hertz_rate @ self.hertz_forces(ss, t, y)
        else:

            def rhs(t: float, y: np.ndarray) -> np.ndarray:
                return ss.A @ y + ss.forcing(t)

        events = []
        monitored = [int(k) for k in np.flatnonzero(self.monitored)]
        for k in monitored:

            def event(t: float, y: np.ndarray, k: int = k, t0: float = t0) -> float:
                # a clearance that just changed starts at zero, where round-off decides the sign:
                # the first picosecond counts as positive (a crossing there is taken at its end)
                if t - t0 <= GUARD:
                    return 1.0
                return float(self.monitors(ss, t, y)[k])

            event.terminal = True  # type: ignore[attr-defined]  # solve_ivp reads an event's function attributes
            event.direction = -1  # type: ignore[attr-defined]  # (as above)
            events.append(event)
        times = self.output_times(t0, t_stop)
        solution = solve_ivp(rhs, (t0, t_stop), y0, method=self.options.method, rtol=self.options.rtol,
                             atol=atol, events=events, dense_output=True)
        if solution.status == -1:
            raise RunError(f"solve_ivp failed at t = {solution.t[-1]:.6g} s: {solution.message}")
        self.steps += len(solution.t) - 1
        t_end = float(solution.t[-1])
        fired = [k for k, times_k in zip(monitored, solution.t_events, strict=True)
                 if solution.status == 1 and len(times_k) and times_k[-1] == t_end]
        for t_out in times:
            if t_out <= t_end * (1 + 1e-15):
                self.emit(ss, t_out, solution.sol(t_out))
            else:
                self.next_out -= 1  # not reached before the event: output it in the next configuration
        samples = solution.t[1:] if self.every_step else ()
        for t_sample in samples:
            self.emit(ss, float(t_sample), solution.sol(t_sample))
        self.refine_peaks(ss, solution)
        return t_end, solution.y[:, -1], fired

    def refine_peaks(self, ss: StateSpace, solution) -> None:  # noqa: ANN001 (an OdeResult)
        """Peak contact forces: at the steps, and each local maximum between steps refined on the
        dense output (bounded Brent), so a peak between two steps is not missed."""
        values = self.forces(ss, solution.t, solution.y)
        self.track_overlap(ss, self.monitors(ss, solution.t, solution.y))
        closed = (ss.mask & self.closed_bit) != 0
        for i, t_sample in enumerate(solution.t):
            self.raise_peaks(closed, values[:, i], float(t_sample))
        for k, first, last in peak_brackets(values, closed, self.peak):
            low, high = float(solution.t[first]), float(solution.t[last])
            if high <= low:
                continue

            def force(t: float, k: int = k) -> float:
                return -float(self.forces(ss, t, solution.sol(t))[k])

            best = minimize_scalar(force, bounds=(low, high), method="bounded",
                                   options={"xatol": 1e-9 * (high - low)})
            self.peak[k] = max(self.peak[k], -float(best.fun))
            if best.x >= self.t_rev:
                self.peak_late[k] = max(self.peak_late[k], -float(best.fun))
        if ss.compliant is not None and ss.compliant.any():  # the peak overlaps, refined the same way
            overlaps = self.monitors(ss, solution.t, solution.y) - self.problem.gap_noise
            for k, first, last in peak_brackets(overlaps, ss.compliant, self.peak_overlap):
                low, high = float(solution.t[first]), float(solution.t[last])
                if high <= low:
                    continue

                def overlap(t: float, k: int = k) -> float:
                    return -float(self.monitors(ss, t, solution.sol(t))[k]) + self.problem.gap_noise

                best = minimize_scalar(overlap, bounds=(low, high), method="bounded",
                                       options={"xatol": 1e-9 * (high - low)})
                self.peak_overlap[k] = max(self.peak_overlap[k], -float(best.fun))


ScipyBackend.run_class = _ScipyRun
