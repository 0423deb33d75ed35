"""Between events the constrained valve train is linear: the machinery the ``exact`` and ``scipy`` back ends share.

In configuration c, with the ordered layer of the contact problem
(:class:`~vtool.solvers.contact.OrderedLayer`: free coordinates F first,
prescribed P after) and y = (z_F, ż_F),

    y' = A y + b(t),   A = ⎡ 0            I          ⎤,
                           ⎣ -M_FF⁻¹K_FF  -M_FF⁻¹C_FF ⎦

    b(t) = ⎡ 0                                             ⎤
           ⎣ -M_FF⁻¹ (M_FP z̈_P + C_FP ż_P + K_FP z_P)(t)   ⎦

The prescribed motions are Fourier series (:mod:`vtool.solvers.sources`), so
with the basis φ(t) = (1, cos ωt, sin ωt, …, cos Kωt, sin Kωt), b(t) = B φ(t)
and the particular solution y_p(t) = Y φ(t): the constant part from
K_FF x₀ = -K_FP z_P,0 (a direct solve: v₀ = 0), and per harmonic k

    ⎡ A     -kω I ⎤ ⎧Y_c⎫   ⎧-b_c⎫
    ⎣ kω I   A    ⎦ ⎩Y_s⎭ = ⎩-b_s⎭ .

Every output (coordinates, contact forces, gaps) is affine in y and φ(t).
The configurations, contact forces, impact laws and event rules are the
contact problem's (:mod:`vtool.solvers.contact`, the kernel's ``impact`` and
``settle``): only the integration differs. A back end subclasses
:class:`PiecewiseRun` and implements :meth:`PiecewiseRun.advance`.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

import numpy as np

from vtool.errors import RunError
from vtool.solvers import newmark_kernel as kernel
from vtool.solvers.backends import Backend, Cancel, Progress
from vtool.solvers.contact import EVENT_KINDS, ContactProblem, OrderedLayer
from vtool.solvers.sources import SourceSeries
from vtool.solvers.trace import TraceBuilder


def basis(omega: float, n_harmonics: int, t: float | np.ndarray) -> np.ndarray:
    """φ(t) = (1, cos ωt, sin ωt, …, cos Kωt, sin Kωt): a vector, or columns for an array of t."""
    t = np.asarray(t, dtype=float)
    rows = [np.ones_like(t)]
    for k in range(1, n_harmonics + 1):
        rows += [np.cos(k * omega * t), np.sin(k * omega * t)]
    return np.stack(rows)


def source_coefficients(series: SourceSeries, s: int) -> np.ndarray:
    """(3, 1 + 2K): x, v, a of source s as coefficients on the basis φ."""
    K = series.n_harmonics
    out = np.zeros((3, 1 + 2 * K))
    out[0, 0] = series.const[s]
    for k in range(1, K + 1):
        a, b, wk = series.cos[s, k - 1], series.sin[s, k - 1], k * series.omega
        out[0, 2 * k - 1], out[0, 2 * k] = a, b
        out[1, 2 * k - 1], out[1, 2 * k] = wk * b, -wk * a
        out[2, 2 * k - 1], out[2, 2 * k] = -wk * wk * a, -wk * wk * b
    return out


@dataclass
class StateSpace:
    """y' = A y + B φ(t) of one configuration, its particular solution Y φ(t), and its affine outputs."""

    mask: int
    A: np.ndarray
    B: np.ndarray  # (2nf, 1 + 2K)
    Y: np.ndarray  # (2nf, 1 + 2K)
    omega: float
    n_harmonics: int
    omega_max: float  # largest |eigenvalue| of A
    P: np.ndarray  # (3n, 2nf): full (x, v, a) from y
    Q: np.ndarray  # (3n, 1 + 2K): full (x, v, a) from φ
    G: np.ndarray  # (ncl, 2nf): monitors from y
    H: np.ndarray  # (ncl, 1 + 2K): monitors from φ

    @property
    def size(self) -> int:
        return self.A.shape[0]

    def basis(self, t: float | np.ndarray) -> np.ndarray:
        return basis(self.omega, self.n_harmonics, t)

    def forcing(self, t: float) -> np.ndarray:
        return self.B @ self.basis(t)

    def particular(self, t: float | np.ndarray) -> np.ndarray:
        """y_p at t (a vector), or at every t of an array (columns)."""
        return self.Y @ self.basis(t)

    def harmonic(self, coefficients: np.ndarray, t: float | np.ndarray) -> np.ndarray:
        return coefficients @ self.basis(t)


def static_deflection(K: np.ndarray, f: np.ndarray, label: str) -> np.ndarray:
    """x with K x = f. A free rigid-body motion (singular K) is allowed while f does not load it:
    then the minimum-norm solution (least squares), checked to round-off."""
    try:
        x = np.linalg.solve(K, f)
        if np.all(np.isfinite(x)) and np.allclose(K @ x, f, rtol=0, atol=1e-9 * np.abs(f).max()):
            return x
    except np.linalg.LinAlgError:
        pass
    x = np.linalg.lstsq(K, f, rcond=None)[0]
    if not np.allclose(K @ x, f, rtol=0, atol=1e-9 * np.abs(f).max()):
        raise RunError(f"configuration {label} has no steady solution under a constant load "
                       "(a free rigid-body motion is loaded)")
    return x


def state_space(problem: ContactProblem, layer: OrderedLayer) -> StateSpace:
    """The state-space form of a configuration, its particular solution and affine output maps."""
    series, tables = problem.series, problem.tables
    n, ncl, ns, K = problem.n, problem.ncl, problem.ns, series.n_harmonics
    nb = 1 + 2 * K
    m, nf, mask = layer.m, layer.nf, layer.mask
    M, C, Kmat = layer.M, layer.C, layer.K
    # prescribed z_P, ż_P, z̈_P as coefficients on φ: (3, m - nf, nb)
    zP = np.zeros((3, m - nf, nb))
    for p, s in enumerate(layer.source):
        zP[:, p, :] = source_coefficients(series, int(s))
    Minv = np.linalg.inv(M[:nf, :nf]) if nf else np.zeros((0, 0))
    A = np.zeros((2 * nf, 2 * nf))
    A[:nf, nf:] = np.eye(nf)
    A[nf:, :nf] = -Minv @ Kmat[:nf, :nf]
    A[nf:, nf:] = -Minv @ C[:nf, :nf]
    load = M[:nf, nf:] @ zP[2] + C[:nf, nf:] @ zP[1] + Kmat[:nf, nf:] @ zP[0]  # (nf, nb)
    B = np.zeros((2 * nf, nb))
    B[nf:] = -Minv @ load
    Y = np.zeros((2 * nf, nb))
    label = problem.label(mask)
    if nf and np.any(load[:, 0]):
        Y[:nf, 0] = static_deflection(Kmat[:nf, :nf], -(Kmat[:nf, nf:] @ zP[0, :, 0]), label)
    n2 = 2 * nf
    for k in range(1, K + 1):
        bc, bs = B[:, 2 * k - 1], B[:, 2 * k]
        if not (bc.any() or bs.any()):
            continue
        wk = k * series.omega
        big = np.block([[A, -wk * np.eye(n2)], [wk * np.eye(n2), A]])
        try:
            sol = np.linalg.solve(big, -np.concatenate([bc, bs]))
        except np.linalg.LinAlgError:
            raise RunError(f"harmonic {k} of the cam speed is exactly a natural frequency of configuration "
                           f"{label} (undamped resonance)") from None
        Y[:, 2 * k - 1], Y[:, 2 * k] = sol[:n2], sol[n2:]
    # the layer vector (z, ż, z̈) as affine maps of y and φ
    Zy = np.zeros((3, m, n2))
    Zb = np.zeros((3, m, nb))
    Zy[0, :nf, :nf] = np.eye(nf)
    Zy[1, :nf, nf:] = np.eye(nf)
    Zy[2, :nf] = A[nf:]
    Zb[2, :nf] = B[nf:]
    Zb[:, nf:] = zP
    group = layer.group
    P = np.concatenate([Zy[i][group] for i in range(3)])
    Q = np.concatenate([Zb[i][group] for i in range(3)])
    src = np.zeros((3 * ns, nb))  # the sources (x, v, a), s-major as the kernel's src vector
    for s in range(ns):
        src[3 * s:3 * s + 3] = source_coefficients(series, s)
    G = np.zeros((ncl, n2))
    H = np.zeros((ncl, nb))
    for k in range(ncl):
        kind, ahead, behind = (int(v) for v in tables.mk[mask, k])
        if kind == kernel.MK_GAP:
            G[k] += Zy[0, ahead]
            H[k] += Zb[0, ahead]
            H[k, 0] += problem.gap_noise
            if behind >= 0:
                G[k] -= Zy[0, behind]
                H[k] -= Zb[0, behind]
            else:
                H[k] -= src[3 * (-1 - behind)]
        elif kind == kernel.MK_FORCE:
            row = tables.mon[mask, k]
            for i in range(3):
                coefficients = row[i * n:i * n + m]
                G[k] += coefficients @ Zy[i]
                H[k] += coefficients @ Zb[i]
            H[k] += row[3 * n:3 * n + 3 * ns] @ src
            H[k, 0] += row[3 * n + 3 * ns]
    eig = np.linalg.eigvals(A) if n2 else np.zeros(0)
    return StateSpace(mask, A, B, Y, series.omega, K, float(np.abs(eig).max()) if n2 else 0.0, P, Q, G, H)


class PiecewiseRun(ABC):
    """Event-to-event driver shared by the exact and scipy back ends.

    Subclasses implement :meth:`advance`: integrate configuration ``ss`` from
    (t0, y0) towards t_stop, stop at the first monitor sign change, and call
    :meth:`emit` for the output rows on the way.
    """

    backend = "piecewise"

    def __init__(self, problem: ContactProblem, output_interval: float, every_step: bool,
                 builder: TraceBuilder) -> None:
        self.problem = problem
        self.mechanism = problem.mechanism
        self.builder = builder
        spec = problem.spec
        self.n, self.ncl = problem.n, problem.ncl
        self.t_end = spec.run.degrees * math.pi / 180.0 / problem.omega
        self.out_dt = output_interval * math.pi / 180.0 / problem.omega
        self.every_step = every_step
        self.ip, self.fp = problem.parameters(t_end=self.t_end)
        self.spaces: dict[int, StateSpace] = {}
        self.rows: list[tuple[float, np.ndarray, np.ndarray, int]] = []
        self.peak = np.zeros(self.ncl)
        self.peak_late = np.zeros(self.ncl)
        self.t_rev = 2 * math.pi / problem.omega
        self.steps = 0
        self.next_out = 0
        self.rapid = 0
        self.last_event = -1.0
        self.monitored = problem.cl[:, kernel.CL_MON].astype(bool)
        self.closed_bit = problem.cl[:, kernel.CL_BIT]
        self.ev_f = np.zeros((4 * self.ncl + 4, 2))
        self.ev_i = np.zeros((4 * self.ncl + 4, 4), dtype=np.int64)
        self.ist = np.zeros(kernel.I_SIZE, dtype=np.int64)

    # ----- configuration data -----
    def space(self, mask: int) -> StateSpace:
        if mask not in self.spaces:
            self.spaces[mask] = state_space(self.problem, self.problem.build(mask))
        return self.spaces[mask]

    def full_state(self, ss: StateSpace, t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        z = ss.P @ y + ss.harmonic(ss.Q, t)
        return z[:self.n], z[self.n:2 * self.n], z[2 * self.n:]

    def monitors(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        """Monitor values (contact force if closed, gap if open) at t; columns for arrays of t."""
        return ss.G @ y + ss.harmonic(ss.H, t)

    def state_of(self, ss: StateSpace, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        layer = self.problem.tables.layers[ss.mask]
        cols = layer.kept[:layer.nf]
        return np.concatenate([x[cols], v[cols]])

    def sources(self, t: float) -> np.ndarray:
        src = np.zeros(3 * self.problem.ns)
        series = self.problem.series
        kernel.fill_sources(self.problem.ns, self.problem.nh, series.omega, series.const, series.cos, series.sin,
                            t, src)
        return src

    # ----- output -----
    def track_peaks(self, ss: StateSpace, values: np.ndarray, t: float) -> None:
        """Update the peak contact forces from monitor values (forces of the closed clearances) at t."""
        closed = (ss.mask & self.closed_bit) != 0
        self.peak = np.where(closed, np.maximum(self.peak, values), self.peak)
        if t >= self.t_rev:
            self.peak_late = np.where(closed, np.maximum(self.peak_late, values), self.peak_late)

    def emit(self, ss: StateSpace, t: float, y: np.ndarray) -> None:
        x, v, a = self.full_state(ss, t, y)
        values = self.monitors(ss, t, y)
        F = np.where((ss.mask & self.closed_bit) != 0, values, 0.0)
        self.track_peaks(ss, F, t)
        src = self.sources(t).reshape(-1, 3)
        q3 = np.stack([np.concatenate([x, src[:, 0]]), np.concatenate([v, src[:, 1]]),
                       np.concatenate([a, src[:, 2]])])
        self.rows.append((t, q3, F, ss.mask))

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
        start = self.mechanism.start
        x, v, a = start.q.copy(), start.qd.copy(), start.qdd.copy()
        mask = self.settle(self.problem.start_mask, 0.0, x, v, a)
        ss = self.space(mask)
        t, y = 0.0, self.state_of(ss, x, v)
        for t_out in self.output_times(-1.0, 0.0):
            self.emit(ss, t_out, y)
        chunk = max(self.t_end / 200.0, 1e-12)
        while t < self.t_end * (1 - 1e-14):
            t, y, fired = self.advance(ss, t, y, min(t + chunk, self.t_end))
            if fired:
                mask, x, v, a = self.apply_events(ss, t, y, fired)
                ss = self.space(mask)
                y = self.state_of(ss, x, v)
            if progress is not None:
                progress(min(t / self.t_end, 1.0))
            if cancel is not None and cancel():
                raise RunError(f"cancelled at t = {t:.6g} s")

    def settle(self, mask: int, t: float, x: np.ndarray, v: np.ndarray, a: np.ndarray) -> int:
        """The kernel's settle (release of pulling contacts), building configurations as it asks."""
        problem, tables = self.problem, self.problem.tables
        m = problem.n
        while True:
            self.ist[kernel.I_NEV] = 0
            result = int(kernel.settle(self.ip, self.fp, problem.cl, tables.ci, tables.cm, tables.cp, tables.mk,
                                       tables.mon, mask, t, x, v, a, self.sources(t), self.ev_f, self.ev_i,
                                       self.ist, np.zeros(m), np.zeros(m), np.zeros(m), np.zeros(m)))
            self._take_events()
            if result >= 0:
                return result
            mask = -1 - result
            problem.build(mask)
            self.space(mask)

    def _take_events(self) -> None:
        for row in range(int(self.ist[kernel.I_NEV])):
            k, kind, before, after = (int(value) for value in self.ev_i[row])
            self.builder.add_event(self.ev_f[row, 0], k, EVENT_KINDS[kind], self.ev_f[row, 1], before, after)
        self.ist[kernel.I_NEV] = 0

    def apply_events(self, ss: StateSpace, t: float, y: np.ndarray,
                     fired: list[int]) -> tuple[int, np.ndarray, np.ndarray, np.ndarray]:
        """Open, or impact, the clearances whose monitor crossed zero at t, then settle."""
        x, v, a = (part.copy() for part in self.full_state(ss, t, y))
        c = ss.mask
        new_c = c
        closing = np.zeros(self.ncl, dtype=np.int64)
        for k in fired:
            if c & self.closed_bit[k]:
                new_c &= ~int(self.closed_bit[k])
            else:
                closing[k] = 1
        self.rapid = self.rapid + 1 if t - self.last_event <= self.problem.zeno_window else 0
        self.last_event = t
        if self.rapid >= self.problem.rules.zeno_stop:
            raise RunError(f"chattering contact at t = {t:.6g} s in configuration {self.problem.label(c)}")
        for k in range(self.ncl):
            if (c & self.closed_bit[k]) and not (new_c & self.closed_bit[k]):
                self.builder.add_event(t, k, EVENT_KINDS[kernel.EV_OPENED], 0.0, c, new_c)
        if closing.any():
            stick = self.rapid >= self.problem.rules.zeno_stick
            problem = self.problem
            self.ist[kernel.I_NEV] = 0
            new_c = int(kernel.impact(self.ip, self.fp, problem.cl, problem.clf, problem.mass, new_c, closing,
                                      self.sources(t), x, v, stick, self.ev_f, self.ev_i, self.ist, t))
            self._take_events()
        new_c = self.settle(new_c, t, x, v, a)
        return new_c, x, v, a

    def statistics(self, settings: dict[str, Any]) -> dict[str, Any]:
        self.rows.sort(key=lambda row: row[0])
        if self.rows:
            self.builder.add_rows(np.array([r[0] for r in self.rows]), np.array([r[1] for r in self.rows]),
                                  np.array([r[2] for r in self.rows]),
                                  np.array([r[3] for r in self.rows], dtype=np.int64))
        return {"steps": self.steps, "peak": self.peak, "peak_late": self.peak_late,
                "configurations": tuple(sorted(self.spaces)), "settings": settings}


class PiecewiseBackend(Backend):
    """A back end whose run is a :class:`PiecewiseRun` subclass (``run_class``)."""

    run_class: type[PiecewiseRun]

    def integrate(self, problem: ContactProblem, options: Any, builder: TraceBuilder,
                  progress: Progress | None, cancel: Cancel | None) -> dict[str, Any]:
        run = self.run_class(problem, options, builder)  # type: ignore[call-arg]
        run.execute(progress, cancel)
        return run.statistics(self.settings(options))

    def settings(self, options: Any) -> dict[str, Any]:
        return {}
