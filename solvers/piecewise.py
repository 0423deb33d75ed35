"""Between events the constrained valve train is linear: the machinery the ``exact`` and ``scipy`` back ends share.

In configuration c, with F the free layer coordinates and y = (x_F, v_F),

    y' = A y + b(t),   A = ⎡ 0            I          ⎤,
                           ⎣ -M_FF⁻¹K_FF  -M_FF⁻¹C_FF ⎦

    b(t) = ⎡ 0                                             ⎤
           ⎣ -M_FF⁻¹ (M_FP ä_P + C_FP v̇_P + K_FP x_P)(t)   ⎦

The prescribed motions are the harmonic cam and the fixed seat, so
b(t) = b₀ + b_s sin ωt + b_c cos ωt, with the particular solution
y_p(t) = Y₀ + Y_s sin ωt + Y_c cos ωt from

    A Y₀ = -b₀,   A Y_c - ω Y_s = -b_c,   ω Y_c + A Y_s = -b_s.

The configurations, contact forces, impact law (the same LCP as the
``newmark`` back end, :func:`vtool.solvers.newmark_kernel.impact`) and the
event rules are shared with ``newmark``: only the integration differs. A back
end subclasses :class:`PiecewiseRun` and implements :meth:`PiecewiseRun.advance`.
"""

from __future__ import annotations

import math
import time as wallclock
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vtool.errors import RunError
from vtool.solvers import newmark_kernel as kernel
from vtool.solvers.configurations import HARMONIC_SOURCE, configuration_label, mask_of
from vtool.solvers.model import Mechanism
from vtool.solvers.newmark import EVENT_KINDS, KernelRun, NewmarkOptions
from vtool.solvers.trace import Event, RunStatistics, Trace

Progress = Callable[[float], None]
Cancel = Callable[[], bool]


@dataclass
class StateSpace:
    """y' = A y + b(t) of one configuration, its particular solution, and the map back to full coordinates."""

    mask: int
    free: np.ndarray  # layer columns that are free
    A: np.ndarray
    b0: np.ndarray
    bs: np.ndarray
    bc: np.ndarray
    Y0: np.ndarray
    Ys: np.ndarray
    Yc: np.ndarray
    omega: float
    omega_max: float  # largest |eigenvalue| of A
    # affine maps, filled by PiecewiseRun.space: z = P y + harmonic(t), monitors = G y + harmonic(t)
    P: np.ndarray | None = None  # (3n, 2nf): full (x, v, a) from y
    Q: np.ndarray | None = None  # (3n, 3): full (x, v, a) constant, sin, cos parts
    G: np.ndarray | None = None  # (ncl, 2nf): monitors from y
    H: np.ndarray | None = None  # (ncl, 3): monitors constant, sin, cos parts

    @property
    def size(self) -> int:
        return self.A.shape[0]

    def forcing(self, t: float) -> np.ndarray:
        return self.b0 + self.bs * math.sin(self.omega * t) + self.bc * math.cos(self.omega * t)

    def particular(self, t: float | np.ndarray) -> np.ndarray:
        """y_p at t (a vector), or at every t of an array (columns)."""
        t = np.asarray(t, dtype=float)
        basis = np.stack([np.ones_like(t), np.sin(self.omega * t), np.cos(self.omega * t)])
        return np.stack([self.Y0, self.Ys, self.Yc], axis=1) @ basis

    def harmonic(self, coefficients: np.ndarray, t: float | np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        basis = np.stack([np.ones_like(t), np.sin(self.omega * t), np.cos(self.omega * t)])
        return coefficients @ basis


def state_space(run: KernelRun, mask: int) -> StateSpace:
    """Build the state-space form of configuration ``mask`` from the kernel tables."""
    tables, prob = run.tables, run.problem
    if not tables.built[mask]:
        run._build(mask)
    m, nf, npres = int(tables.m[mask]), int(tables.nf[mask]), int(tables.npres[mask])
    free = tables.free[mask, :nf].copy()
    pres = tables.pres[mask, :npres]
    ML, CL, KL = tables.ML[mask, :m, :m], tables.CL[mask, :m, :m], tables.KL[mask, :m, :m]
    Minv = tables.MinvFF[mask, :nf, :nf]
    A = np.zeros((2 * nf, 2 * nf))
    A[:nf, nf:] = np.eye(nf)
    A[nf:, :nf] = -Minv @ KL[np.ix_(free, free)]
    A[nf:, nf:] = -Minv @ CL[np.ix_(free, free)]
    omega = float(prob.src_par[0, 1])
    b0, bs, bc = np.zeros(2 * nf), np.zeros(2 * nf), np.zeros(2 * nf)
    for p, j in enumerate(pres):
        s = int(tables.pres_src[mask, p])
        amp, _, offset = prob.src_par[s]
        mj, cj, kj = ML[free, j], CL[free, j], KL[free, j]
        if prob.src_kind[s] == HARMONIC_SOURCE:  # x = amp sin + offset, v = amp w cos, a = -amp w² sin
            bs[nf:] -= Minv @ (kj * amp - mj * amp * omega**2)
            bc[nf:] -= Minv @ (cj * amp * omega)
            b0[nf:] -= Minv @ (kj * offset)
        else:
            b0[nf:] -= Minv @ (kj * amp)
    Y0 = np.linalg.lstsq(A, -b0, rcond=None)[0] if b0.any() else np.zeros(2 * nf)
    if b0.any() and not np.allclose(A @ Y0, -b0, rtol=0, atol=1e-9 * np.abs(b0).max()):
        raise RunError(f"configuration {configuration_label(run.mechanism.spec, mask)} has no steady "
                       "solution under a constant load (a free rigid-body motion is loaded)")
    n2 = 2 * nf
    big = np.block([[A, -omega * np.eye(n2)], [omega * np.eye(n2), A]])
    try:
        harmonic = np.linalg.solve(big, -np.concatenate([bc, bs]))
    except np.linalg.LinAlgError:
        raise RunError(f"the cam speed is exactly a natural frequency of configuration "
                       f"{configuration_label(run.mechanism.spec, mask)} (undamped resonance)") from None
    eig = np.linalg.eigvals(A) if n2 else np.zeros(0)
    return StateSpace(mask, free, A, b0, bs, bc, Y0, harmonic[n2:], harmonic[:n2], omega,
                      float(np.abs(eig).max()) if n2 else 0.0)


class PiecewiseRun(ABC):
    """Event-to-event driver shared by the exact and scipy back ends.

    Subclasses implement :meth:`advance`: integrate configuration ``ss`` from
    (t0, y0) towards t_stop, stop at the first monitor sign change, and call
    :meth:`emit_outputs` for the output rows on the way.
    """

    backend = "piecewise"

    def __init__(self, mechanism: Mechanism, output_interval: float, every_step: bool,
                 rest_velocity: float | None = None) -> None:
        self.mechanism = mechanism
        spec = mechanism.spec
        # the contact problem (clearances, sources, impact law, configuration tables) of the kernel
        nominal = NewmarkOptions(1e-6, output_interval=output_interval, rest_velocity=rest_velocity)
        self.setup = KernelRun(mechanism, nominal)
        self.prob = self.setup.problem
        self.n = spec.n_coordinates
        self.ncl = len(spec.clearances)
        self.t_end = self.prob.t_end
        self.out_dt = output_interval * math.pi / 180.0 / mechanism.omega
        self.every_step = every_step
        self.spaces: dict[int, StateSpace] = {}
        self.rows: list[tuple] = []
        self.events: list[Event] = []
        self.peak = np.zeros(self.ncl)
        self.steps = 0
        self.next_out = 0
        self.rapid = 0
        self.last_event = -1.0
        self.monitored = self.prob.cl_monitored.astype(bool)

    # ----- configuration data -----
    def space(self, mask: int) -> StateSpace:
        """State-space form of a configuration, with its affine output and monitor maps."""
        if mask not in self.spaces:
            ss = state_space(self.setup, mask)
            ss.P, ss.Q = self._affine(ss, lambda t, y: np.concatenate(self._full_state(ss, t, y)))
            ss.G, ss.H = self._affine(ss, lambda t, y: self._monitor_values(ss, t, y))
            self.spaces[mask] = ss
        return self.spaces[mask]

    @staticmethod
    def _affine(ss: StateSpace, f: Callable[[float, np.ndarray], np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """f(t, y) = P y + Q [1, sin wt, cos wt]: P by unit vectors, Q from three instants."""
        zero = np.zeros(ss.size)
        base = f(0.0, zero)
        P = np.column_stack([f(0.0, np.eye(ss.size)[j]) - base for j in range(ss.size)]) if ss.size else \
            np.zeros((base.size, 0))
        w = ss.omega
        instants = [0.0, math.pi / (2 * w), math.pi / (4 * w)] if w > 0 else [0.0, 0.0, 0.0]
        values = np.column_stack([f(t, zero) for t in instants])
        basis = np.array([[1.0, math.sin(w * t), math.cos(w * t)] for t in instants])
        Q = np.linalg.lstsq(basis, values.T, rcond=None)[0].T
        return P, Q

    def _full_state(self, ss: StateSpace, t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Full (x, v, a) at t from y (prescribed coordinates from their sources). Slow path."""
        tables, prob, mask = self.setup.tables, self.prob, ss.mask
        m, nf = int(tables.m[mask]), ss.free.size
        xl, vl, al = np.zeros(m), np.zeros(m), np.zeros(m)
        ydot = ss.A @ y + ss.forcing(t)
        xl[ss.free], vl[ss.free], al[ss.free] = y[:nf], y[nf:], ydot[nf:]
        for p in range(int(tables.npres[mask])):
            j, s = int(tables.pres[mask, p]), int(tables.pres_src[mask, p])
            xl[j], vl[j], al[j] = kernel.source_state(prob.src_kind, prob.src_par, s, t)
        group = tables.group[mask]
        return xl[group], vl[group], al[group]

    def _sources(self, t: float) -> np.ndarray:
        return np.array([kernel.source_state(self.prob.src_kind, self.prob.src_par, s, t)
                         for s in range(self.prob.src_kind.shape[0])])

    def _monitor_values(self, ss: StateSpace, t: float, y: np.ndarray) -> np.ndarray:
        x, v, a = self._full_state(ss, t, y)
        sources = self._sources(t)
        values = np.zeros(self.ncl)
        frow = self.setup.tables.Frow[ss.mask]
        state = np.concatenate([x, v, a, sources.ravel()])
        for k in range(self.ncl):
            if ss.mask & self.prob.cl_bit[k]:
                values[k] = frow[k] @ state
            else:
                behind = x[self.prob.cl_behind[k]] if self.prob.cl_behind[k] >= 0 else sources[self.prob.cl_src[k], 0]
                values[k] = x[self.prob.cl_ahead[k]] - behind + self.prob.gap_noise  # as the kernel's monitor
        return values

    def full_state(self, ss: StateSpace, t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        z = ss.P @ y + ss.harmonic(ss.Q, t)
        return z[:self.n], z[self.n:2 * self.n], z[2 * self.n:]

    def monitors(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        """Monitor values (contact force if closed, gap if open) at t; columns for arrays of t."""
        return ss.G @ y + ss.harmonic(ss.H, t)

    def state_of(self, ss: StateSpace, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        cols = self.setup.tables.kept[ss.mask][ss.free]
        return np.concatenate([x[cols], v[cols]])

    # ----- output -----
    def track_peaks(self, ss: StateSpace, values: np.ndarray) -> None:
        """Update the peak contact forces from monitor values (forces of the closed clearances)."""
        for k in range(self.ncl):
            if ss.mask & self.prob.cl_bit[k] and values[k] > self.peak[k]:
                self.peak[k] = values[k]

    def emit(self, ss: StateSpace, t: float, y: np.ndarray) -> None:
        x, v, a = self.full_state(ss, t, y)
        values = self.monitors(ss, t, y)
        F = np.array([values[k] if ss.mask & self.prob.cl_bit[k] else 0.0 for k in range(self.ncl)])
        self.peak = np.maximum(self.peak, F)
        src = self._sources(t)
        self.rows.append((t, np.concatenate([x, src[:, 0]]), np.concatenate([v, src[:, 1]]),
                          np.concatenate([a, src[:, 2]]), F, ss.mask))

    def output_times(self, t0: float, t1: float) -> list[float]:
        """Requested output instants in (t0, t1] not yet written (and t = 0 at the start)."""
        times = []
        while True:
            t = self.next_out * self.out_dt
            if t > t1 * (1 + 1e-12) or t > self.t_end * (1 + 1e-12):
                return times
            times.append(min(t, self.t_end))
            self.next_out += 1

    # ----- the loop -----
    @abstractmethod
    def advance(self, ss: StateSpace, t0: float, y0: np.ndarray, t_stop: float) -> tuple[float, np.ndarray, list[int]]:
        """Integrate to the first event or t_stop; return (t, y, the clearances whose monitor crossed zero)."""

    def execute(self, progress: Progress | None, cancel: Cancel | None) -> None:
        spec = self.mechanism.spec
        start = self.mechanism.start
        ss = self.space(mask_of(spec, spec.initial.closed))
        t, y = 0.0, self.state_of(ss, start.q, start.qd)
        for t_out in self.output_times(-1.0, 0.0):
            self.emit(ss, t_out, y)
        chunk = max(self.t_end / 200.0, 1e-12)
        while t < self.t_end * (1 - 1e-14):
            t, y, fired = self.advance(ss, t, y, min(t + chunk, self.t_end))
            if fired:
                mask, x, v = self.apply_events(ss, t, y, fired)
                ss = self.space(mask)
                y = self.state_of(ss, x, v)
            if progress is not None:
                progress(min(t / self.t_end, 1.0))
            if cancel is not None and cancel():
                raise RunError(f"cancelled at t = {t:.6g} s")

    def apply_events(self, ss: StateSpace, t: float, y: np.ndarray, fired: list[int]) -> tuple[int, np.ndarray, np.ndarray]:
        """Open, or impact, the clearances whose monitor crossed zero at t."""
        x, v, _ = self.full_state(ss, t, y)
        x, v = x.copy(), v.copy()
        c = ss.mask
        new_c = c
        closing = np.zeros(self.ncl, dtype=np.int64)
        for k in fired:
            if c & self.prob.cl_bit[k]:
                new_c &= ~int(self.prob.cl_bit[k])
            else:
                closing[k] = 1
        self.rapid = self.rapid + 1 if t - self.last_event <= self.prob.zeno_window else 0
        self.last_event = t
        if self.rapid >= self.prob.zeno_stop:
            raise RunError(f"chattering contact at t = {t:.6g} s in configuration "
                           f"{configuration_label(self.mechanism.spec, c)}")
        for k in range(self.ncl):
            if (c & self.prob.cl_bit[k]) and not (new_c & self.prob.cl_bit[k]):
                self._record(t, k, 0, 0.0, c, new_c)
        if closing.any():
            out, istate = self.setup.out, self.setup.istate
            istate[kernel.I_NEV] = 0
            stick = self.rapid >= self.prob.zeno_stick
            new_c = int(kernel.impact(self.prob, new_c, closing, t, x, v, stick, out, istate))
            for row in range(int(istate[kernel.I_NEV])):
                self._record(float(out.ev_t[row]), int(out.ev_k[row]), int(out.ev_kind[row]),
                             float(out.ev_u[row]), int(out.ev_from[row]), int(out.ev_to[row]))
        return new_c, x, v

    def _record(self, t: float, k: int, kind: int, u: float, before: int, after: int) -> None:
        angle = t * self.mechanism.omega * 180.0 / math.pi
        self.events.append(Event(t, angle, self.mechanism.spec.clearances[k].name, EVENT_KINDS[kind],
                                 u, before, after))

    def trace(self, wall_time: float, settings: dict) -> Trace:
        spec = self.mechanism.spec
        self.rows.sort(key=lambda row: row[0])
        t = np.array([r[0] for r in self.rows])
        x, v, a = (np.array([r[i] for r in self.rows]) for i in (1, 2, 3))
        F = np.array([r[4] for r in self.rows])
        cfg = np.array([r[5] for r in self.rows], dtype=np.int64)
        numbers = tuple(range(1, self.n + 1)) + tuple(self.setup.source_numbers)
        stats = RunStatistics(self.backend, self.steps, len(self.events), wall_time,
                              tuple(sorted(self.spaces)), settings)
        return Trace(spec, t, t * self.mechanism.omega * 180 / math.pi, numbers, x, v, a, F, cfg,
                     tuple(self.events), self.peak, stats)


def timed(run: PiecewiseRun, progress: Progress | None, cancel: Cancel | None, settings: dict) -> Trace:
    started = wallclock.perf_counter()
    run.execute(progress, cancel)
    return run.trace(wallclock.perf_counter() - started, settings)


