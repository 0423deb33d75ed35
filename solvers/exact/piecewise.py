"""Between events the constrained valve train is linear: the machinery the ``exact`` and ``scipy`` back ends share.

In configuration c, with the ordered layer of the contact problem
(:class:`~vtool.solvers.model.contact.OrderedLayer`: free coordinates F first,
prescribed P after) and y = (z_F, ż_F),

    y' = A y + b(t),   A = ⎡ 0            I          ⎤,
                           ⎣ -M_FF⁻¹K_FF  -M_FF⁻¹C_FF ⎦

    b(t) = ⎡ 0                                             ⎤
           ⎣ -M_FF⁻¹ (M_FP z̈_P + C_FP ż_P + K_FP z_P)(t)   ⎦

The prescribed motions are Fourier series (:mod:`vtool.solvers.model.sources`), so
with the basis u(t) = (1, cos kωt…, sin kωt…), b(t) = B u(t) and the
particular solution y_p(t) = Y u(t), one direct solve per harmonic
(:mod:`vtool.solvers.exact.statespace`). Every output (coordinates, contact
forces, gaps) is affine in y and u(t): the maps P, Q, G, H built here.
The configurations, contact forces, impact laws and event rules are the
contact problem's (:mod:`vtool.solvers.model.contact`: its
:class:`~vtool.solvers.model.contact.Transitions` start the run and apply
every event): only the integration differs. A back end subclasses
:class:`PiecewiseRun` and implements :meth:`PiecewiseRun.advance`.
"""

from __future__ import annotations

import contextlib
import math
import time
import weakref
from abc import ABC, abstractmethod
from typing import Any

import numpy as np

from vtool.errors import InputError, RunError
from vtool.solvers.backends import Backend, Cancel, OptionsT, Progress, RunStats
from vtool.solvers.exact.statespace import StateSpace, from_layer
from vtool.solvers.model.contact import ContactProblem, OrderedLayer
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.sources import SourceSeries
from vtool.solvers.model.spec import HERTZ, MechanismSpec
from vtool.solvers.newmark import layout
from vtool.solvers.trace import TraceBuilder

#: The state spaces of a mechanism's configurations, kept as long as its configuration tables: a
#: second run of the same mechanism (a sweep, a benchmark, the TUI) reuses them and what the back
#: ends derived from them (``StateSpace.cache``: eigendecompositions, scan powers).
_SPACES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def source_coefficients(series: SourceSeries, s: int) -> np.ndarray:
    """(3, 1 + 2K): x, v, a of source s as coefficients on the basis u = (1, cos kωt.., sin kωt..)."""
    K = series.n_harmonics
    kw = series.omega * np.arange(1, K + 1)
    a, b = series.cos[s], series.sin[s]
    out = np.zeros((3, 1 + 2 * K))
    out[0, 0] = series.const[s]
    out[0, 1:K + 1], out[0, K + 1:] = a, b
    out[1, 1:K + 1], out[1, K + 1:] = kw * b, -kw * a
    out[2, 1:K + 1], out[2, K + 1:] = -kw * kw * a, -kw * kw * b
    return out


def state_space(problem: ContactProblem, layer: OrderedLayer) -> StateSpace:
    """The state-space form of a configuration (:func:`vtool.solvers.exact.statespace.from_layer`: A, B, the
    particular solution) and its affine output maps P, Q (coordinates) and G, H (monitors)."""
    series, tables = problem.series, problem.tables
    n, ncl, ns, K = problem.n, problem.ncl, problem.ns, series.n_harmonics
    nb = 1 + 2 * K
    m, nf, mask = layer.m, layer.nf, layer.mask
    _, _, _, mk, mon = tables.of(mask)
    ss = from_layer(problem, layer)
    A, B = ss.A, ss.B
    n2 = 2 * nf
    zP = np.zeros((3, m - nf, nb))
    for p, s in enumerate(layer.source):
        zP[:, p, :] = source_coefficients(series, int(s))
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
    G, H = np.zeros((ncl, n2)), np.zeros((ncl, nb))  # monitors (kernel.monitors)
    GF, HF = np.zeros((ncl, n2)), np.zeros((ncl, nb))  # contact forces (kernel.forces.linear_force)
    for k in range(ncl):
        kind, ahead, behind = (int(v) for v in mk[k, :layout.MK_M])
        if kind in (layout.MK_GAP, layout.MK_OVERLAP):
            sign = (1.0 if kind == layout.MK_GAP else -1.0) * problem.clf[k, layout.CLF_SIGN]  # and the gap's sense
            G[k] += sign * Zy[0, ahead]
            H[k] += sign * Zb[0, ahead]
            if behind >= 0:
                G[k] -= sign * Zy[0, behind]
                H[k] -= sign * Zb[0, behind]
            else:
                H[k] -= sign * src[3 * (-1 - behind)]
            H[k, 0] += problem.gap_noise + (1.0 if kind == layout.MK_GAP else -1.0) * problem.clf[k, layout.CLF_OPEN]
        if kind in (layout.MK_FORCE, layout.MK_OVERLAP):
            row = mon[k]
            for i in range(3):
                coefficients = row[i * n:i * n + m]
                GF[k] += coefficients @ Zy[i]
                HF[k] += coefficients @ Zb[i]
            HF[k] += row[3 * n:3 * n + 3 * ns] @ src
            HF[k, 0] += row[3 * n + 3 * ns]
        if kind == layout.MK_FORCE:
            G[k], H[k] = GF[k], HF[k]
    ss.compliant = mk[:, layout.MK_KIND] == layout.MK_OVERLAP
    hertz = np.flatnonzero(ss.compliant & (problem.cl[:, layout.CL_SOFT] == layout.SOFT_HERTZ))
    ss.hertz = hertz
    if hertz.size:  # F_j acts as F_j w_j: on ÿ through M_FF⁻¹ w_F, on the rigid forces through their rows
        GF[hertz], HF[hertz] = 0.0, 0.0
        w = -mon[hertz][:, :nf].T  # (nf, nh): the Hertz rows hold -w
        ss.hertz_rate = np.vstack([np.zeros((nf, hertz.size)), np.linalg.solve(layer.M[:nf, :nf], w)])
        head = 3 * n + 3 * ns + 1
        ss.hertz_force = mon[:, head + hertz].copy()
        ss.hertz_force[hertz, np.arange(hertz.size)] = 1.0
    ss.P, ss.Q, ss.G, ss.H, ss.GF, ss.HF = P, Q, G, H, GF, HF
    return ss


class PiecewiseRun(ABC):
    """Event-to-event driver shared by the exact and scipy back ends.

    Subclasses implement :meth:`advance`: integrate configuration ``ss`` from
    (t0, y0) towards t_stop, stop at the first monitor sign change, and call
    :meth:`emit` for the output rows on the way.
    """

    backend = "piecewise"
    #: advance() returns at least this many times over a run (progress, cancel, rows to the builder)
    progress_steps = 200

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
        self.record = problem.record(*problem.parameters(t_end=self.t_end))
        self.spaces: dict[int, StateSpace] = {}
        # output rows not yet handed to the builder: blocks (t, q3, F, cfg), flushed in time order
        self.rows: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = []
        self.peak = np.zeros(self.ncl)
        self.peak_late = np.zeros(self.ncl)
        self.peak_overlap = np.zeros(self.ncl)
        self.t_rev = 2 * math.pi / problem.omega
        self.steps = 0
        self.next_out = 0
        self.monitored = problem.cl[:, layout.CL_MON].astype(bool)
        self.closed_bit = problem.cl[:, layout.CL_BIT]
        self.transitions = problem.transitions(builder)  # the shared event and impact rules
        self.rules = self.transitions.rules  # the compiled kernel's Hertz law and event rules

    # ----- configuration data -----
    def space(self, mask: int) -> StateSpace:
        """Configuration ``mask``'s state space: built once per mechanism and cam motion (see _SPACES)."""
        if mask not in self.spaces:
            problem = self.problem
            layer = problem.build(mask)
            series = problem.series
            key = (mask, float(series.omega), problem.gap_noise, series.const.tobytes(), series.cos.tobytes(),
                   series.sin.tobytes())
            shared = _SPACES.setdefault(problem.tables, {})
            if key not in shared:
                shared[key] = state_space(problem, layer)
            self.spaces[mask] = shared[key]
        return self.spaces[mask]

    def full_state(self, ss: StateSpace, t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        assert ss.P is not None and ss.Q is not None  # (set by state_space)
        z = ss.P @ y + ss.harmonic(ss.Q, t)
        return z[:self.n], z[self.n:2 * self.n], z[2 * self.n:]

    def monitors(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        """Monitor values (rigid contact force or compliant overlap if closed, gap if open) at t;
        columns for arrays of t."""
        assert ss.G is not None and ss.H is not None  # (set by state_space)
        linear = ss.G @ y + ss.harmonic(ss.H, t)
        if ss.hertz is None or not ss.hertz.size or ss.hertz_force is None:
            return linear
        coupling = ss.hertz_force.copy()  # the rigid contacts' forces include the Hertz forces' pull
        coupling[~(ss.mask & self.closed_bit != 0) | ss.compliant] = 0.0
        return linear + coupling @ self.hertz_forces(ss, t, y)

    def forces(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        """Contact forces (0 for an open clearance) at t; columns for arrays of t."""
        assert ss.GF is not None and ss.HF is not None  # (set by state_space)
        linear = ss.GF @ y + ss.harmonic(ss.HF, t)
        if ss.hertz is None or not ss.hertz.size or ss.hertz_force is None:
            return linear
        return linear + ss.hertz_force @ self.hertz_forces(ss, t, y)

    def hertz_forces(self, ss: StateSpace, t: float | np.ndarray, y: np.ndarray) -> np.ndarray:
        """Forces of the closed Hertz contacts (the kernel's ``hertz_law``) at t; columns for arrays of t."""
        rows = ss.hertz
        assert ss.G is not None and ss.H is not None and rows is not None
        nf = ss.size // 2
        delta = ss.G[rows] @ y + ss.harmonic(ss.H[rows], t) - self.problem.gap_noise
        rate = ss.G[rows, :nf] @ y[nf:] + ss.H[rows] @ ss.basis_rate(t)
        out = np.zeros(np.shape(delta))
        for i, k in enumerate(rows):
            for index in np.ndindex(np.shape(delta)[1:]):
                at = (i, *index)
                out[at] = self.rules.hertz_force(self.problem.clf, int(k), float(delta[at]), float(rate[at]))[0]
        return out

    def track_overlap(self, ss: StateSpace, values: np.ndarray) -> None:
        """Raise the peak overlaps of the closed compliant contacts with monitor values (columns or one)."""
        if ss.compliant is not None and ss.compliant.any():
            top = values.max(axis=1) if values.ndim == 2 else values
            self.peak_overlap = np.where(ss.compliant, np.maximum(self.peak_overlap, top - self.problem.gap_noise),
                                         self.peak_overlap)

    def state_of(self, ss: StateSpace, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        layer = self.problem.tables.layers[ss.mask]
        cols = layer.kept[:layer.nf]
        return np.concatenate([x[cols], v[cols]])

    def sources(self, t: float) -> np.ndarray:
        return self.problem.sources_at(t)

    # ----- output -----
    def track_peaks(self, ss: StateSpace, values: np.ndarray, t: float) -> None:
        """Update the peak contact forces from monitor values (forces of the closed clearances) at t."""
        closed = (ss.mask & self.closed_bit) != 0
        np.maximum(self.peak, values, out=self.peak, where=closed)
        if t >= self.t_rev:
            np.maximum(self.peak_late, values, out=self.peak_late, where=closed)

    def raise_peaks(self, closed: np.ndarray, values: np.ndarray, t: float) -> None:
        """Raise the peaks of the closed clearances to ``values`` seen at (or, for a block, up to) t."""
        np.copyto(self.peak, values, where=closed & (values > self.peak))  # (in place: fewer calls)
        if t >= self.t_rev:
            np.copyto(self.peak_late, values, where=closed & (values > self.peak_late))

    def emit(self, ss: StateSpace, t: float, y: np.ndarray) -> None:
        x, v, a = self.full_state(ss, t, y)
        F = self.forces(ss, t, y)
        self.track_peaks(ss, F, t)
        self.track_overlap(ss, self.monitors(ss, t, y))
        src = self.sources(t).reshape(-1, 3)
        q3 = np.stack([np.concatenate([x, src[:, 0]]), np.concatenate([v, src[:, 1]]),
                       np.concatenate([a, src[:, 2]])])
        self.rows.append((np.array([t]), q3[None], F[None], np.array([ss.mask], dtype=np.int64)))

    def flush_rows(self) -> None:
        """Hand the rows emitted so far to the builder, in time order (stable: ties keep their order).

        Called after every :meth:`advance`: a call's rows may interleave (outputs at the requested
        angles and every-step samples) but all come before the next call's."""
        if not self.rows:
            return
        blocks, self.rows = self.rows, []
        if len(blocks) == 1:  # one block: in time order as emitted; fresh arrays nobody writes again, kept as they are
            self.builder.add_rows(*blocks[0], copy=False)
            return
        t, q3, F, cfg = (np.concatenate(parts) for parts in zip(*blocks, strict=True))
        if np.any(np.diff(t) < 0.0):
            order = np.argsort(t, kind="stable")
            t, q3, F, cfg = t[order], q3[order], F[order], cfg[order]
        self.builder.add_rows(t, q3, F, cfg)

    def output_times(self, t0: float, t1: float) -> list[float]:
        """Requested output instants in (t0, t1] not yet written (and t = 0 at the start)."""
        times: list[float] = []
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
        """The run; the first one that compiles the event rules marks them compiled, with its time
        (compile-bound: :func:`vtool.solvers.newmark.backend.compile_notice` quotes it)."""
        from vtool import jit

        key = jit.law_key(self.problem.hertz, self.problem.momentum)
        compiled = jit.is_compiled(self.rules.release_pulling, "rules", key)
        started = time.perf_counter()
        with contextlib.nullcontext() if compiled else jit.fewer_collections():
            self.integrate(progress, cancel)
        if not compiled:
            jit.compiled("rules", key, time.perf_counter() - started)

    def integrate(self, progress: Progress | None, cancel: Cancel | None) -> None:
        """Event to event: :meth:`advance` in the current configuration, then the shared rules
        (:class:`~vtool.solvers.model.contact.Transitions`) give the next one and its state."""
        transitions = self.transitions
        mask, x, v, _ = transitions.start()
        ss = self.space(mask)
        t, y = 0.0, self.state_of(ss, x, v)
        for t_out in self.output_times(-1.0, 0.0):
            self.emit(ss, t_out, y)
        chunk = max(self.t_end / self.progress_steps, 1e-12)
        while t < self.t_end * (1 - 1e-14):
            t, y, fired = self.advance(ss, t, y, min(t + chunk, self.t_end))
            self.flush_rows()
            if fired:
                x, v, _ = self.full_state(ss, t, y)
                mask, x, v, _ = transitions.apply(ss.mask, t, x, v, fired, accelerations=False)
                ss = self.space(mask)
                y = self.state_of(ss, x, v)
            if progress is not None:
                progress(min(t / self.t_end, 1.0))
            if cancel is not None and cancel():
                raise RunError(f"cancelled at t = {t:.6g} s")

    def statistics(self, settings: dict[str, Any]) -> RunStats:
        self.flush_rows()
        # configurations=None: the ones this run held, from its start and events (as every back end)
        return RunStats(self.steps, self.peak, self.peak_late, self.peak_overlap, None, settings)


def refuse_hertz(mechanism: Mechanism, backend: str) -> None:
    """One line for a back end that integrates linear configurations only, given a Hertz contact."""
    for c in mechanism.spec.clearances:
        if c.contact == HERTZ:
            raise InputError("run.backend", backend, f"newmark or scipy for a preset with a hertz contact "
                             f"({c.name}: nonlinear between events, so the exact solution does not apply)")


class PiecewiseBackend(Backend[OptionsT]):
    """A back end whose run is a :class:`PiecewiseRun` subclass (``run_class``)."""

    run_class: type[PiecewiseRun]

    @classmethod
    def compile_notice(cls, spec: MechanismSpec, impacts: tuple[str, ...] = ()) -> str | None:
        """The event rules' compile (``apply_impacts``, ``release_pulling``, ``sources``, ...), called from Python."""
        from vtool.solvers.newmark.backend import compile_notice, kernel_laws

        return compile_notice(cls.name, kernel_laws(spec, impacts))

    def integrate(self, problem: ContactProblem, options: OptionsT, builder: TraceBuilder,
                  progress: Progress | None, cancel: Cancel | None) -> RunStats:
        run = self.run_class(problem, options, builder)  # type: ignore[call-arg, arg-type]  # a subclass: (problem, options, builder)
        run.execute(progress, cancel)
        return run.statistics(self.settings(options))

    def settings(self, options: OptionsT) -> dict[str, Any]:
        return {}
