"""The ``exact`` back end: piecewise-exact integration, no time-step error.

Between events a configuration is linear with Fourier forcing
(:mod:`vtool.solvers.exact.statespace`), so its response is exact:

    y(t0 + τ) = e^{Aτ} (y(t0) - y_p(t0)) + y_p(t0 + τ),

with the particular solution y_p(t) = Y u(t) from one direct solve per
harmonic, and e^{Aτ} = V e^{Λτ} V⁻¹ from the eigendecomposition of A, done
once per configuration (or scipy's expm of A times the scan interval, once
per configuration, when V is ill-conditioned). The homogeneous state is
carried in modal coordinates h = V⁻¹ y_h, so advancing it is a product of
exponentials and a monitor (contact force if closed, gap if open) is

    g(t0 + τ) = Re Σ_j (g V)_j e^{λ_j τ} h_j + (G Y + H) u(t0 + τ),

a sum of exponentials and harmonics, cheap to evaluate anywhere.

The solution is sampled on a scan grid of π/(8 ω_max) (a sixteenth of the
shortest period of the configuration; samples carry no error, the
exponentials advance by products); a monitor that changes sign between two
samples is bracketed and its root found on the exact solution, by Newton's
method on g and its exact rate g' kept inside the bracket (:func:`safe_newton`),
to well within ``time_tolerance`` (default 1e-12 s). A contact force's local
maximum between samples is refined as the root of its exact rate g'(t)
(Brent's method), so peak forces are exact, not sampled. Outputs at the requested
angles are computed from the exact solution, not interpolated. Impacts,
contact forces and event rules are the ``newmark`` back end's.

The scan grid is the only approximation: two sign changes of one monitor
closer than a grid interval would be missed (the contact would have to open
and close within 1/16 of the shortest natural period).

Dense linear algebra runs single-threaded during a run
(:func:`vtool.threads.limited`; ``VTOOL_THREADS`` overrides).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from vtool.errors import InputError, RunError
from vtool.solvers.exact.piecewise import PiecewiseBackend, PiecewiseRun, refuse_hertz
from vtool.solvers.exact.statespace import Propagator, StateSpace, shift_coefficients
from vtool.solvers.model.contact import ContactProblem
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import RunSpec
from vtool.solvers.trace import TraceBuilder

SCAN_FRACTION = 1.0 / 16.0  # scan grid as a fraction of the shortest period
BLOCK = 1024  # samples evaluated together
PEAK_MARGIN = 1e-2  # local maxima of sampled forces within this fraction of the peak are refined


@dataclass(frozen=True)
class ExactOptions:
    output_interval: float = 1.0  # degrees
    every_step: bool = False  # output at every scan sample too
    time_tolerance: float = 1e-12  # s, event location
    scan_fraction: float = SCAN_FRACTION

    @classmethod
    def from_run(cls, run: RunSpec, every_step: bool = False) -> ExactOptions:
        return cls(run.output_interval, every_step)


class ExactBackend(PiecewiseBackend[ExactOptions]):
    """Piecewise-exact back end (see module doc). Registered as ``exact``."""

    name = "exact"
    reference = True

    @staticmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> ExactOptions:
        return ExactOptions.from_run(run, every_step)

    def check(self, mechanism: Mechanism, options: ExactOptions) -> None:
        if not 0.0 < options.time_tolerance < 1e-3:
            raise InputError("time_tolerance", options.time_tolerance, "> 0 and < 1e-3", "s")
        refuse_hertz(mechanism, self.name)

    def settings(self, options: ExactOptions) -> dict:
        return {"time_tolerance_s": options.time_tolerance}


def peak_brackets(values: np.ndarray, closed: np.ndarray, peak: np.ndarray,
                  margin: float = PEAK_MARGIN, tail: np.ndarray | None = None) -> list[tuple[int, int, int]]:
    """Sample intervals that may hold a contact force's maximum: (clearance, first, last sample).

    ``values`` (ncl, ns) are monitor samples in time order. A sample of a
    closed clearance at least as large as its neighbours (a missing neighbour
    counts as smaller) and within ``margin`` of the ``peak`` so far brackets a
    maximum between its neighbours (a sample alone at an end: between it and
    its one neighbour). ``tail`` (bool per clearance): the last interval ends
    at an event, which may leave a maximum with no sample near it (a contact
    closing and opening again within one scan interval); it is a bracket of
    these clearances too.
    """
    count = values.shape[1]
    if count < 2:
        return []
    tails = [(int(k), count - 2, count - 1) for k in np.flatnonzero(closed & tail)] if tail is not None else []
    threshold = peak - margin * np.abs(peak)
    rows = np.flatnonzero(closed & (values.max(axis=1) >= threshold))
    if not rows.size:
        return tails
    values, threshold = values[rows], threshold[rows]
    pad = np.full((values.shape[0], 1), -np.inf)
    padded = np.concatenate([pad, values, pad], axis=1)
    centre = padded[:, 1:-1]
    local = (centre >= padded[:, :-2]) & (centre > padded[:, 2:])
    local &= centre >= threshold[:, None]
    found = [(int(rows[k]), max(int(j) - 1, 0), min(int(j) + 1, count - 1))
             for k, j in zip(*np.nonzero(local), strict=True)]
    return found + [bracket for bracket in tails if bracket not in found]


def safe_newton(both: Callable[[float], tuple[float, float]], low: float, high: float, f_low: float,
                f_high: float, tol: float) -> float:
    """A zero of f in [low, high], given f(low) >= 0 > f(high), to well within ``tol``; ``both(x)`` gives
    f(x) and f'(x).

    Newton's method from the secant point, kept inside a bracket that every
    evaluation narrows: a step that would leave it, or is not half the one
    before (or a zero derivative), bisects instead. It stops at a step
    shorter than tol/4 (Newton's error then lies far inside it) or a bracket
    narrower than tol. On a monitor of the exact solution (smooth over a
    scan interval) it takes two or three evaluations of f and f' together
    where Brent's method took about five of f (1A: 124 against 288 for 54
    roots, the roots within 2.3e-13 s of each other)."""
    x = low + (high - low) * (f_low / (f_low - f_high))
    if not low < x < high:
        x = 0.5 * (low + high)
    previous = high - low
    for _ in range(200):
        f, slope = both(x)
        if f >= 0.0:
            low = x
        else:
            high = x
        if high - low <= tol:
            return low
        step = f / slope if slope != 0.0 else math.inf
        if not low < x - step < high or abs(step) > 0.5 * previous:  # out, or not converging: bisect
            step = x - 0.5 * (low + high)
        elif abs(step) <= 0.25 * tol:
            return x - step
        previous = abs(step)
        x -= step
    return low


@dataclass
class _Config:
    """What the exact back end derives once per configuration (see module doc)."""

    delta: float  # scan interval
    prop: Propagator
    GV: np.ndarray  # monitors from h
    GAV: np.ndarray  # monitor rates from h
    Hm: np.ndarray  # monitors' forced part, on u(t)
    PV: np.ndarray  # output rows (x, sources' x, v, sources' v, a, sources' a) from h
    Qm: np.ndarray  # output rows' forced part, on u(t)
    closed: np.ndarray  # bool per clearance
    grid_basis: np.ndarray  # u(τ) at τ = delta * (1..BLOCK)
    GFV: np.ndarray  # contact forces from h (the monitors themselves unless a compliant contact is closed)
    GFAV: np.ndarray
    HFm: np.ndarray
    soft: bool  # a compliant contact is closed: forces differ from monitors
    rows_h: np.ndarray  # PV over GFV: an output row's values and the contact forces, from h ...
    rows_u: np.ndarray  # ... and on u(t): Qm over HFm
    open_rows: np.ndarray  # the rows of rows_h of the open clearances' forces (set to 0)
    grid_taus: np.ndarray  # delta * (1..BLOCK)


class _ExactRun(PiecewiseRun):
    backend = "exact"
    progress_steps = 40  # a call scans about one block of samples (850 degrees of 1A: 37,000 samples)

    def __init__(self, problem: ContactProblem, options: ExactOptions, builder: TraceBuilder) -> None:
        super().__init__(problem, options.output_interval, options.every_step, builder)
        self.options = options
        self.series = problem.series
        self.monitored_index = np.flatnonzero(self.monitored)
        self.some_unmonitored = not self.monitored.all()  # else every monitor row is watched, as it is
        self._carry: tuple | None = None  # (mask, t, h, y) where the last advance stopped without an event
        self.configs: dict[int, _Config] = {}

    def config(self, ss: StateSpace) -> _Config:
        """What this back end derives from a configuration, once per scan interval (kept with ``ss``)."""
        cfg = self.configs.get(ss.mask)
        if cfg is not None:
            return cfg
        period = 2 * math.pi / ss.omega_max if ss.omega_max > 0 else self.t_end
        delta = min(self.options.scan_fraction * period, self.out_dt)
        key = ("exact", delta)
        if key not in ss.cache:
            prop = Propagator(ss.A, delta, ss.T, ss.Tinv)
            GV = ss.G @ prop.V
            closed = (ss.mask & self.closed_bit) != 0
            PV, Qm = self.output_maps(ss, prop)
            GAV, Hm = ss.G @ ss.A @ prop.V, ss.G @ ss.Y + ss.H
            soft = bool(ss.compliant is not None and ss.compliant.any())
            GFV, GFAV, HFm = ((ss.GF @ prop.V, ss.GF @ ss.A @ prop.V, ss.GF @ ss.Y + ss.HF) if soft
                              else (GV, GAV, Hm))
            taus = delta * np.arange(1, BLOCK + 1)
            ss.cache[key] = _Config(delta, prop, GV, GAV, Hm, PV, Qm, closed, ss.basis(taus), GFV, GFAV, HFm, soft,
                                    np.vstack([PV, GFV]), np.vstack([Qm, HFm]), PV.shape[0] + np.flatnonzero(~closed),
                                    taus)
        self.configs[ss.mask] = cfg = ss.cache[key]
        return cfg

    def output_maps(self, ss: StateSpace, prop: Propagator) -> tuple[np.ndarray, np.ndarray]:
        """Output rows z = Re(PV h) + Qm u(t): the coordinates' (x, v, a) and the sources' after them."""
        n, series = self.n, self.series
        harmonics = series.n_harmonics
        if ss.n_harmonics != harmonics:
            raise RunError("the sources and the configuration have different numbers of harmonics")
        kw = series.omega * np.arange(1, harmonics + 1)
        src_x = np.column_stack([series.const, series.cos, series.sin])
        src_v = np.column_stack([np.zeros(series.n_sources), kw * series.sin, -kw * series.cos])
        src_a = np.column_stack([np.zeros(series.n_sources), -kw**2 * series.cos, -kw**2 * series.sin])
        forced = ss.P @ ss.Y + ss.Q
        Qm = np.vstack([forced[:n], src_x, forced[n:2 * n], src_v, forced[2 * n:], src_a])
        homogeneous = ss.P @ prop.V
        none = np.zeros((series.n_sources, homogeneous.shape[1]), dtype=homogeneous.dtype)
        PV = np.vstack([homogeneous[:n], none, homogeneous[n:2 * n], none, homogeneous[2 * n:], none])
        return PV, Qm

    def advance(self, ss: StateSpace, t0: float, y0: np.ndarray, t_stop: float) -> tuple[float, np.ndarray, list[int]]:
        """Scan the exact solution in blocks of samples; stop at the first monitor sign change."""
        cfg = self.config(ss)
        prop, delta = cfg.prop, cfg.delta
        carried = self._carry
        if carried is not None and carried[0] == ss.mask and carried[1] == t0 and carried[3] is y0:
            t, h = t0, carried[2]  # where the last call stopped (no event): keep the modal state
        else:
            t, h = t0, prop.to_h(y0 - ss.particular(t0))
        self._carry = None
        tol = self.options.time_tolerance
        monitored = self.monitored_index
        base_v = (cfg.GV @ h).real + cfg.Hm @ ss.basis(t0)  # monitors at the block's start
        self.raise_peaks(cfg.closed, base_v, t0)
        while t < t_stop * (1 - 1e-15):
            count = int(min(BLOCK, math.floor((t_stop - t) / delta)))
            if count >= 1:  # whole scan intervals: one product with the stored powers
                taus = cfg.grid_taus[:count]
                values, states = prop.grid(h, count, cfg.GV)
                values += shift_coefficients(cfg.Hm, ss.omega, ss.n_harmonics, t) @ cfg.grid_basis[:, :count]
            elif t > t0 and t_stop < self.t_end:  # stop on the grid; the next call continues it
                break
            else:  # the remainder up to t_stop
                count, taus = 1, np.array([t_stop - t])
                hs = prop(h, taus)
                values = (cfg.GV @ hs).real + cfg.Hm @ ss.basis(t + taus)

                def states(index: int | slice, hs: np.ndarray = hs) -> np.ndarray:
                    return hs[:, index]
            times = t + taus
            crossed = ((values[monitored] if self.some_unmonitored else values) < 0.0).any(axis=0)
            last = int(np.argmax(crossed)) if crossed.any() else count
            start_tau, start_h = (float(taus[last - 1]), states(last - 1)) if last else (0.0, h)
            self.outputs(ss, cfg, t, h, self.output_times(t, t + start_tau))
            if self.every_step and last:
                self.emit_rows(ss, cfg, times[:last], states(slice(0, last)))
            self.steps += last
            if last < count:  # a sign change between t + start_tau and times[last]
                start_t = t + start_tau
                width = float(taus[last] - start_tau)
                fired = [int(k) for k in monitored if values[k, last] < 0.0]
                roots = {k: self.root(ss, cfg, start_t, start_h, k, width, tol, float(values[k, last])) for k in fired}
                tau = min(roots.values())
                self.outputs(ss, cfg, start_t, start_h, self.output_times(start_t, start_t + tau))
                self.steps += 1
                h_event = prop.at(start_h, tau)
                y_event = prop.real(h_event) + ss.particular(start_t + tau)
                # the peaks over [t, event]: the samples before the event and the event itself (an
                # event inside the first scan interval leaves no sample: a stiff contact's force is
                # largest where it closes, and this interval may hold the run's peak)
                at_event = (cfg.GV @ h_event).real + cfg.Hm @ ss.basis(start_t + tau)
                self.scan_peaks(ss, cfg, t, h, base_v, np.append(taus[:last], start_tau + tau),
                                np.column_stack([values[:, :last], at_event]),
                                states, (start_h, h_event))
                return start_t + tau, y_event, [k for k, r in roots.items() if r <= tau + tol]
            self.scan_peaks(ss, cfg, t, h, base_v, taus, values, states)
            t, h, base_v = float(times[-1]), states(count - 1), values[:, -1]
        y = prop.real(h) + ss.particular(t)
        self._carry = (ss.mask, t, h, y)
        return t, y, []

    def scan_peaks(self, ss: StateSpace, cfg: _Config, t: float, h: np.ndarray, base_v: np.ndarray,
                   taus: np.ndarray, values: np.ndarray, states: Callable,
                   tail: tuple[np.ndarray, np.ndarray] | None = None) -> None:
        """Peak forces (and a compliant contact's overlaps) over [t, t + taus[-1]], from the monitors
        ``base_v`` at t and ``values`` at t + taus (columns); ``states(index)`` gives the modal states at
        the scan samples (asked only when a compliant contact is closed: its force is not its monitor).
        ``tail``: the last τ is an event's, not a sample's: the modal states at the start of its interval
        and at the event (see :meth:`tail_rows`)."""
        tail_at = None
        if tail is not None:
            width = float(taus[-1]) - (float(taus[-2]) if taus.size > 1 else 0.0)
            tail_at = (np.column_stack(tail), ss.basis_rate(t + float(taus[-1]) - np.array([width, 0.0])), width)
        if cfg.soft:
            noise = self.problem.gap_noise
            self.overlap_peaks(ss, cfg, t, h, base_v, taus, values,
                               self.tail_rows(cfg, tail_at, cfg.GAV, cfg.Hm, base_v, values, self.peak_overlap + noise))
            hs = states(slice(0, taus.size - (tail is not None)))
            if tail is not None:
                hs = np.column_stack([hs, tail[1]])
            forces = (cfg.GFV @ hs).real + (
                shift_coefficients(cfg.HFm, ss.omega, ss.n_harmonics, t) @ ss.basis(taus))
            base_f = (cfg.GFV @ h).real + cfg.HFm @ ss.basis(t)
            self.peaks(ss, cfg, t, h, base_f, taus, forces,
                       self.tail_rows(cfg, tail_at, cfg.GFAV, cfg.HFm, base_f, forces, self.peak))
        else:
            self.peaks(ss, cfg, t, h, base_v, taus, values,
                       self.tail_rows(cfg, tail_at, cfg.GAV, cfg.Hm, base_v, values, self.peak))

    @staticmethod
    def tail_rows(cfg: _Config, tail_at: tuple[np.ndarray, np.ndarray, float] | None, rate_h: np.ndarray,
                  forced: np.ndarray, base: np.ndarray, values: np.ndarray, peak: np.ndarray) -> np.ndarray | None:
        """The closed clearances that may peak inside the interval ending at an event, where no sample
        may show it: the value (rate: ``rate_h`` from h, ``forced`` on u'(t)) rises at the interval's start
        and falls at the event, and the two end tangents meet within :data:`PEAK_MARGIN` of ``peak`` (the
        samples' rule, :func:`peak_brackets`). ``tail_at``: the modal states at the two ends (columns), u'
        there (columns) and the interval's width; None: no event. ``base``, ``values``: the values at the
        block's start and at its samples (the last at the event)."""
        if tail_at is None:
            return None
        hs, basis_rates, width = tail_at
        rates = (rate_h @ hs).real + forced @ basis_rates
        v0 = values[:, -2] if values.shape[1] > 1 else base
        v1, r0, r1 = values[:, -1], rates[:, 0], rates[:, 1]
        candidates = cfg.closed & (r0 > 0.0) & (r1 < 0.0)
        if not candidates.any():
            return candidates
        with np.errstate(divide="ignore", invalid="ignore"):
            meet = np.clip((v1 - v0 - r1 * width) / (r0 - r1), 0.0, width)  # where the tangents cross
        return candidates & (v0 + r0 * meet >= peak - PEAK_MARGIN * np.abs(peak))

    def monitor(self, ss: StateSpace, cfg: _Config, t: float, h: np.ndarray, k: int,  # noqa: ANN202
                force: bool = False):
        """Monitor k (or its contact force) at t + τ as a function of τ, its rate, and both at once
        (one exponential for the two), on the exact solution."""
        GV, GAV, Hm = (cfg.GFV, cfg.GFAV, cfg.HFm) if force else (cfg.GV, cfg.GAV, cfg.Hm)
        forced, prop = Hm[k], cfg.prop
        if prop.modal:  # Re Σ c_j e^{λ_j τ} (+ the rigid-body drift, linear in τ) + forced part
            lam = prop.lam
            coefficients = np.stack([GV[k] * h, GAV[k] * h])  # the value's c_j, the rate's
            drift = prop.drift * h[prop.drift_v]
            slope = float((GV[k, prop.drift_x] @ drift).real) if drift.size else 0.0
            slope_rate = float((GAV[k, prop.drift_x] @ drift).real) if drift.size else 0.0
            forcing = self.forced_part(ss, forced, t)

            def drifting_both(tau: float) -> tuple[float, float]:
                value, rate = (coefficients @ np.exp(lam * tau)).real
                at, rate_at = forcing(tau)
                return float(value) + slope * tau + at, float(rate) + slope_rate * tau + rate_at

            def drifting_value(tau: float) -> float:
                return drifting_both(tau)[0]

            def drifting_rate(tau: float) -> float:
                return drifting_both(tau)[1]

            return drifting_value, drifting_rate, drifting_both

        def value(tau: float) -> float:
            return float((GV[k] @ prop.at(h, tau)).real + forced @ ss.basis(t + tau))

        def rate(tau: float) -> float:
            return float((GAV[k] @ prop.at(h, tau)).real + forced @ ss.basis_rate(t + tau))

        def both(tau: float) -> tuple[float, float]:
            state = prop.at(h, tau)
            return (float((GV[k] @ state).real + forced @ ss.basis(t + tau)),
                    float((GAV[k] @ state).real + forced @ ss.basis_rate(t + tau)))

        return value, rate, both

    @staticmethod
    def forced_part(ss: StateSpace, forced: np.ndarray, t: float) -> Callable[[float], tuple[float, float]]:
        """τ -> (forced · u(t + τ), forced · u'(t + τ)); with one harmonic (the thesis' cams) in scalars."""
        if ss.n_harmonics == 1:
            constant, on_cos, on_sin = (float(value) for value in forced)
            omega = ss.omega

            def scalar(tau: float) -> tuple[float, float]:
                cos, sin = math.cos(omega * (t + tau)), math.sin(omega * (t + tau))
                return constant + on_cos * cos + on_sin * sin, omega * (on_sin * cos - on_cos * sin)

            return scalar

        def general(tau: float) -> tuple[float, float]:
            return float(forced @ ss.basis(t + tau)), float(forced @ ss.basis_rate(t + tau))

        return general

    def root(self, ss: StateSpace, cfg: _Config, t: float, h: np.ndarray, k: int, width: float,
             tol: float, last: float) -> float:
        """First zero of monitor k in (0, width], whose value at ``width`` is ``last`` (< 0): Newton's
        method on the exact solution, from the secant, kept inside the bracket (see :func:`safe_newton`)."""
        value, _, both = self.monitor(ss, cfg, t, h, k)
        low = min(0.5 * tol, 0.5 * width)
        start = value(low)
        if start < 0.0:  # already crossing at the start (a contact just released): now
            return low
        return safe_newton(both, low, width, start, last, tol)

    def peaks(self, ss: StateSpace, cfg: _Config, t: float, h: np.ndarray, base_v: np.ndarray,
              taus: np.ndarray, values: np.ndarray, tail: np.ndarray | None = None) -> None:
        """Peak forces from the samples at t (``base_v``) and t + taus, local maxima refined where g' = 0
        (``tail``: the last τ is an event's, see :func:`peak_brackets`)."""
        highest = values.max(axis=1)
        top = np.maximum(highest, base_v)
        self.raise_peaks(cfg.closed, top, t)
        if t + taus[-1] >= self.t_rev:  # samples after the first revolution: the last ones
            first = 0 if t + taus[0] >= self.t_rev else int(np.searchsorted(t + taus, self.t_rev))
            self.raise_peaks(cfg.closed, highest if first == 0 else values[:, first:].max(axis=1), self.t_rev)
        if (tail is None or not tail.any()) and not (cfg.closed & (top >= self.peak - PEAK_MARGIN * np.abs(self.peak))).any():
            return
        taus = np.concatenate([[0.0], taus])
        values = np.concatenate([base_v[:, None], values], axis=1)
        for k, first, last in peak_brackets(values, cfg.closed, self.peak, tail=tail):
            value, rate, _ = self.monitor(ss, cfg, t, h, k, force=True)
            low, high = float(taus[first]), float(taus[last])
            if rate(low) > 0.0 > rate(high):
                tau = brentq(rate, low, high, xtol=self.options.time_tolerance, rtol=4 * np.finfo(float).eps)
                self.peak[k] = max(self.peak[k], value(tau))
                if t + tau >= self.t_rev:
                    self.peak_late[k] = max(self.peak_late[k], value(tau))

    def overlap_peaks(self, ss: StateSpace, cfg: _Config, t: float, h: np.ndarray, base_v: np.ndarray,
                      taus: np.ndarray, values: np.ndarray, tail: np.ndarray | None = None) -> None:
        """Peak overlaps of the closed compliant contacts: samples, local maxima refined where δ' = 0."""
        self.track_overlap(ss, np.concatenate([base_v[:, None], values], axis=1))
        taus = np.concatenate([[0.0], taus])
        values = np.concatenate([base_v[:, None], values], axis=1) - self.problem.gap_noise
        assert ss.compliant is not None  # (a configuration with compliant contacts: set by state_space)
        for k, first, last in peak_brackets(values, ss.compliant, self.peak_overlap, tail=tail):
            value, rate, _ = self.monitor(ss, cfg, t, h, k)
            low, high = float(taus[first]), float(taus[last])
            if rate(low) > 0.0 > rate(high):
                tau = brentq(rate, low, high, xtol=self.options.time_tolerance, rtol=4 * np.finfo(float).eps)
                self.peak_overlap[k] = max(self.peak_overlap[k], value(tau) - self.problem.gap_noise)

    def outputs(self, ss: StateSpace, cfg: _Config, t: float, h: np.ndarray, times: list[float]) -> None:
        if times:
            at = np.array(times)
            self.emit_rows(ss, cfg, at, cfg.prop(h, at - t))

    def emit_rows(self, ss: StateSpace, cfg: _Config, times: np.ndarray, hs: np.ndarray) -> None:
        """Output rows at ``times`` (ascending) from the homogeneous states ``hs`` (columns): the rows'
        (x, v, a) and the contact forces after them, from one product of the stacked maps (``rows_h``,
        ``rows_u``)."""
        values = (cfg.rows_h @ hs).real + cfg.rows_u @ ss.basis(times)
        values[cfg.open_rows] = 0.0  # an open clearance's force
        nz = cfg.PV.shape[0]
        forces = values[nz:]
        self.peak = np.maximum(self.peak, forces.max(axis=1))
        if times[-1] >= self.t_rev:  # rows after the first revolution: the times' last ones
            first = int(np.searchsorted(times, self.t_rev))
            self.peak_late = np.maximum(self.peak_late, forces[:, first:].max(axis=1))
        self.rows.append((np.asarray(times, dtype=float), values[:nz].T.reshape(len(times), 3, -1), forces.T,
                          np.full(len(times), ss.mask, dtype=np.int64)))


ExactBackend.run_class = _ExactRun
