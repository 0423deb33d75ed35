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

Nonlinear elements (:mod:`vtool.solvers.model.nonlinear`: an HLA's chamber,
the valve's guide friction and gas force) run here: their states are
integrated beside y, their forces enter the accelerations and the closed
rigid contacts' forces (:mod:`vtool.solvers.scipy.elements`), their states
go to the trace's rows. At an event the states carry over unchanged.

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
from vtool.solvers.model.attached import elements_of
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import RunSpec
from vtool.solvers.newmark import layout
from vtool.solvers.scipy.elements import terms
from vtool.solvers.trace import OPENED, TraceBuilder

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
    nonlinear_elements = True
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
        mechanism = problem.mechanism
        self.elements = mechanism.kept(("nonlinear elements",), lambda: elements_of(mechanism.spec))
        carried = mechanism.start_states
        self.s = (np.array(carried, dtype=float) if carried is not None
                  else self.elements.initial(start.q, start.qd))  # the elements' states now
        self.s_scale = np.maximum(np.abs(self.s), 1e-6)
        self.state_rows: list[np.ndarray] = []
        if self.elements.elements:
            self.transitions.release = self.release_pulling

    # ----- the nonlinear elements' states beside y (module doc) -----
    def split(self, ss: StateSpace, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(y, s) of an extended state (or of a configuration state y, with the states now)."""
        if y.shape[0] > ss.size:
            return y[:ss.size], y[ss.size:]
        return y, (self.s if y.ndim == 1 else np.repeat(self.s[:, None], y.shape[1], axis=1))

    def element_force(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray,
                      s: np.ndarray) -> np.ndarray:
        e = terms(self.problem, ss)
        u = ss.basis(t)
        x, v = e.Px @ y + e.Qx @ u, e.Pv @ y + e.Qv @ u
        return self.elements.evaluate(t, x, v, s)[0]

    def full_state(self, ss: StateSpace, t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        y, s = self.split(ss, y)
        x, v, a = super().full_state(ss, t, y)
        if self.elements.size or self.elements.elements:
            e = terms(self.problem, ss)
            a = a + e.Sel @ (e.R @ self.element_force(ss, t, y, s))
        return x, v, a

    def forces(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        y, s = self.split(ss, y)
        out = super().forces(ss, t, y)
        if self.elements.elements:
            out = out + terms(self.problem, ss).Phi @ self.element_force(ss, t, y, s)
        return out

    def monitors(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        y, s = self.split(ss, y)
        out = super().monitors(ss, t, y)
        if self.elements.elements:  # Φ is zero but on the closed rigid contacts, whose monitor is their force
            out = out + terms(self.problem, ss).Phi @ self.element_force(ss, t, y, s)
        return out

    def emit(self, ss: StateSpace, t: float, y: np.ndarray) -> None:
        y, s = self.split(ss, y)
        saved, self.s = self.s, s
        super().emit(ss, t, y)
        self.s = saved
        if self.elements.elements:
            self.state_rows.append(np.array(s, dtype=float))

    def release_pulling(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, a: np.ndarray) -> int:
        """With elements, the release of pulling contacts is judged here, on the contact forces with the
        elements' share (the compiled rules see the linear equations only): the most pulling closed rigid
        contact is released first, until every one pushes (at most one release per clearance)."""
        tolerance = self.problem.force_tolerance()
        for _ in range(self.ncl + 1):
            self.problem.build(mask)
            ss = self.space(mask)
            forces = self.forces(ss, t, self.state_of(ss, x, v))
            kinds = self.problem.tables.of(mask)[3][:, layout.MK_KIND]
            pulling = (kinds == layout.MK_FORCE) & self.monitored & (forces < -tolerance)
            if not pulling.any():
                return mask
            worst = int(np.argmin(np.where(pulling, forces, np.inf)))
            released = mask & ~int(self.closed_bit[worst])
            self.builder.add_event(t, worst, OPENED, 0.0, mask, released)
            mask = released
        return mask

    def flush_rows(self) -> None:
        if not self.elements.elements:
            super().flush_rows()
            return
        if not self.rows:
            return
        blocks, self.rows = self.rows, []
        states, self.state_rows = np.array(self.state_rows), []
        t, q3, F, cfg = (np.concatenate(parts) for parts in zip(*blocks, strict=True))
        if np.any(np.diff(t) < 0.0):
            order = np.argsort(t, kind="stable")
            t, q3, F, cfg, states = t[order], q3[order], F[order], cfg[order], states[order]
        self.builder.add_rows(t, q3, F, cfg, states=states)

    def advance(self, ss: StateSpace, t0: float, y0: np.ndarray, t_stop: float) -> tuple[float, np.ndarray, list[int]]:
        nf = ss.size // 2
        atol: float | np.ndarray | None = self.options.atol
        if atol is None:
            atol = np.concatenate([np.full(nf, self.x_scale), np.full(nf, self.v_scale)]) * self.options.rtol

        if ss.hertz is not None and ss.hertz.size:

            def linear(t: float, y: np.ndarray) -> np.ndarray:
                return ss.A @ y + ss.forcing(t) + ss.hertz_rate @ self.hertz_forces(ss, t, y)
        else:

            def linear(t: float, y: np.ndarray) -> np.ndarray:
                return ss.A @ y + ss.forcing(t)

        rhs = linear
        if self.elements.elements:  # y extended by the elements' states (module doc)
            e = terms(self.problem, ss)
            size = ss.size
            evaluate = self.elements.evaluate

            hertz = ss.hertz is not None and ss.hertz.size

            def rhs(t: float, y: np.ndarray) -> np.ndarray:
                z, s = y[:size], y[size:]
                u = ss.basis(t)
                force, rates = evaluate(t, e.Px @ z + e.Qx @ u, e.Pv @ z + e.Qv @ u, s)
                dz = linear(t, z) if hertz else ss.A @ z + ss.B @ u
                dz[nf:] += e.R @ force
                return np.concatenate([dz, rates])

            y0 = np.concatenate([y0, self.s])
            if np.ndim(atol):
                atol = np.concatenate([atol, self.s_scale * self.options.rtol])

        events = []
        monitored = [int(k) for k in np.flatnonzero(self.monitored)]
        last: list = [None, None, None]  # (t, y, monitors): solve_ivp asks every event at the same (t, y) in turn

        def monitors_at(t: float, y: np.ndarray) -> np.ndarray:
            if last[0] != t or last[1] is not y:
                last[:] = t, y, self.monitors(ss, t, y)
            return last[2]

        for k in monitored:

            def event(t: float, y: np.ndarray, k: int = k, t0: float = t0) -> float:
                # a clearance that just changed starts at zero, where round-off decides the sign:
                # the first picosecond counts as positive (a crossing there is taken at its end)
                if t - t0 <= GUARD:
                    return 1.0
                return float(monitors_at(t, y)[k])

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
        end = solution.y[:, -1]
        if self.elements.elements:
            end, self.s = end[:ss.size], end[ss.size:].copy()
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
        return t_end, end, fired

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
