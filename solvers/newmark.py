"""The ``newmark`` back end: Newmark integration with located events and impacts.

The run loop is the numba kernel :func:`vtool.solvers.newmark_kernel.run_chunk`;
this module validates the settings, builds configurations lazily (the first
time the kernel reaches one), calls the kernel in chunks (progress, cancel),
and assembles the :class:`~vtool.solvers.trace.Trace`.

Method (see the kernel's docstring for the equations):

* Newmark with general beta, gamma; the thesis' linear acceleration
  (beta = 1/6, gamma = 1/2) is the default. The effective matrix inverse
  (thesis BMIV) of a configuration is computed when the configuration is first
  visited and reused for every standard step.
* Events: after each step the contact force of every closed clearance and
  the gap of every open one are checked. A sign change is located by
  re-stepping from the start of the step (Illinois root finding on the
  Newmark solution itself, not on an interpolant) to within
  ``time_tolerance`` (default 1e-6 of the time step: 1e-12 s at 1 µs); when
  several monitors change sign in one step the earliest event is taken first
  and the rest of the step is integrated in the new configuration. A gap that
  starts at zero (a contact just released) has a round-off sign, so a gap
  closes when it falls below -1e-13 of the mechanism's size.
* Impacts: Newton's law with a restitution coefficient per clearance, with
  the impulses of all contacts involved solved together as a linear
  complementarity problem on the full consistent mass matrix (see
  :func:`vtool.solvers.newmark_kernel.impact`). Because an impulse through the
  consistent mass matrix also changes the neighbours' velocities, a contact
  that is already closed is part of the same impulse problem: it may be
  released (it separates with the velocity the impulse gives it) but is never
  pulled through, and a contact counts as closed afterwards only when it has no
  separating velocity. Separations and bounces slower than ``rest_velocity``
  (default 1e-5 of the cam amplitude times the larger of the cam speed and
  the lowest natural frequency) are resting contacts that stay
  closed until their contact force says otherwise: together these keep the
  examples from chattering.
* Chattering: ``zeno_stick`` (20) events each within 1e-3 of the shortest
  natural period of the previous one (events piling up) make
  every contact involved stick (restitution zero, held shut; their forces
  then decide separation); ``zeno_stop`` (400) such events stop the run with
  a message naming the time and configuration. A run never loops forever.
* Refinement after events: an impact excites the highest modes, which the
  step resolves poorly (omega_max dt = 1.37 at 1 µs in the thesis examples),
  and their error moves the events that follow. For two periods of the
  highest natural frequency after every event the step is divided by
  ``refine`` (10); the rest of the run keeps the user's step. On example 1A
  at 1 µs this takes the largest event-angle error against the exact back end
  from 0.33° to 0.005° and the peak-force error from 3.6 % to 0.08 %, for
  16 ms → 27 ms. ``refine = 1`` is the plain thesis scheme.
* Stability: for gamma = 1/2 and beta < 1/4 the step must satisfy
  omega_max dt <= 1 / sqrt(gamma/2 - beta) (2 sqrt 3 for linear acceleration:
  dt <= sqrt(3)/pi T_min), with omega_max the highest natural frequency of
  the unconstrained system, which bounds every configuration's.
"""

from __future__ import annotations

import math
import time as wallclock
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vtool.errors import InputError, RunError
from vtool.solvers import newmark_kernel as kernel
from vtool.solvers.configurations import (
    ConfigurationTables,
    clearance_bit,
    configuration_label,
    mask_of,
    source_parameters,
)
from vtool.solvers.damping import undamped_modes
from vtool.solvers.model import Mechanism
from vtool.solvers.spec import ENABLED, PINNED, RunSpec
from vtool.solvers.trace import CLOSED, OPENED, RELEASED, Event, RunStatistics, Trace

FINISHED, CHUNK_END, NEED_CONFIG, OUTPUT_FULL, DIVERGED, CHATTER = range(1, 7)
STATUS_CODES = (FINISHED, CHUNK_END, NEED_CONFIG, OUTPUT_FULL, DIVERGED, CHATTER)
EVENT_KINDS = {0: OPENED, 1: CLOSED, 2: RELEASED}

Progress = Callable[[float], None]
Cancel = Callable[[], bool]


@dataclass(frozen=True)
class NewmarkOptions:
    """Settings of the newmark back end."""

    time_step: float  # s
    beta: float = 1.0 / 6.0
    gamma: float = 0.5
    output_interval: float = 1.0  # degrees of cam rotation
    every_step: bool = False
    time_tolerance: float | None = None  # s; default 1e-6 * time_step
    rest_velocity: float | None = None  # length/s; default 1e-5 of the velocity scale (see KernelRun)
    zeno_stick: int = 20
    zeno_stop: int = 400
    chunk_steps: int = 5000
    enforce_stability_limit: bool = True  # False only to study divergence (tests)
    refine: int = 10  # after each event, steps of time_step / refine ...
    refine_periods: float = 2.0  # ... for this many periods of the highest natural frequency

    @classmethod
    def from_run(cls, run: RunSpec, every_step: bool = False) -> NewmarkOptions:
        return cls(run.time_step, run.beta, run.gamma, run.output_interval, every_step)


def stability_limit(beta: float, gamma: float, omega_max: float) -> float:
    """Largest stable step (s) of Newmark(beta, gamma) for omega_max; inf if unconditional."""
    if 2.0 * beta >= gamma >= 0.5:
        return math.inf
    return 1.0 / math.sqrt(gamma / 2.0 - beta) / omega_max


def round_down(value: float, digits: int) -> float:
    """``value`` rounded down to ``digits`` significant digits (a printed limit never exceeds the limit)."""
    unit = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.floor(value / unit) * unit


def highest_frequency(mechanism: Mechanism) -> float:
    """omega_max of the unconstrained system: no configuration is stiffer."""
    return float(undamped_modes(mechanism.M, mechanism.K).omega.max())


def check_settings(mechanism: Mechanism, options: NewmarkOptions) -> None:
    """Refuse a step that is not positive or beyond the stability limit."""
    dt = options.time_step
    if not dt > 0.0:
        raise InputError("run.time_step", dt, "> 0", "s")
    if not 0.0 < options.beta <= 0.5:
        raise InputError("run.beta", options.beta, "> 0 and <= 0.5")
    if not 0.5 <= options.gamma <= 1.0:
        raise InputError("run.gamma", options.gamma, ">= 0.5 and <= 1")
    limit = stability_limit(options.beta, options.gamma, highest_frequency(mechanism))
    if dt > limit and options.enforce_stability_limit:
        raise InputError(
            "run.time_step", dt,
            f"<= {round_down(limit, 6):.6g} (stability limit of Newmark beta={options.beta:.4g}, gamma={options.gamma:.4g} "
            f"for the stiffest configuration; use beta=1/4 for no limit)", "s",
        )


class NewmarkBackend:
    """Newmark back end (see module doc). Registered as ``newmark``."""

    name = "newmark"
    supports_cancel = True
    supports_progress = True

    @staticmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> NewmarkOptions:
        return NewmarkOptions.from_run(run, every_step)

    def simulate(
        self,
        mechanism: Mechanism,
        options: NewmarkOptions | None = None,
        progress: Progress | None = None,
        cancel: Cancel | None = None,
    ) -> Trace:
        spec = mechanism.spec
        options = options or NewmarkOptions.from_run(spec.run)
        check_settings(mechanism, options)
        started = wallclock.perf_counter()
        run = KernelRun(mechanism, options)
        run.execute(progress, cancel)
        return run.trace(wallclock.perf_counter() - started)


class KernelRun:
    """The contact problem as kernel arrays, and the chunked calls of one run.

    Also used by the exact and scipy back ends (:mod:`vtool.solvers.piecewise`)
    for the clearances, sources, configuration tables and the impact law.
    """

    def __init__(self, mechanism: Mechanism, options: NewmarkOptions) -> None:
        spec = mechanism.spec
        self.mechanism = mechanism
        self.options = options
        n = spec.n_coordinates
        ncl = len(spec.clearances)
        omega = mechanism.omega
        t_end = spec.run.degrees * math.pi / 180.0 / omega
        out_dt = options.output_interval * math.pi / 180.0 / omega
        kinds, par, self.source_numbers = source_parameters(mechanism)
        source_index = {number: s for s, number in enumerate(self.source_numbers)}
        x_scale = max(spec.cam.amplitude + abs(mechanism.start.cam_offset), 1e-9)
        dt = options.time_step
        self.problem = kernel.Problem(
            n=n, beta=options.beta, gamma=options.gamma, dt=dt, t_end=t_end, out_dt=out_dt,
            every_step=int(options.every_step),
            cl_ahead=np.array([c.ahead - 1 for c in spec.clearances], dtype=np.int64),
            cl_behind=np.array([c.behind - 1 if c.behind <= n else -1 for c in spec.clearances], dtype=np.int64),
            cl_src=np.array([source_index.get(c.behind, -1) for c in spec.clearances], dtype=np.int64),
            cl_monitored=np.array([int(c.state == ENABLED) for c in spec.clearances], dtype=np.int64),
            cl_pinned=np.array([int(c.state == PINNED) for c in spec.clearances], dtype=np.int64),
            cl_e=np.array([c.restitution for c in spec.clearances]),
            cl_bit=np.array([clearance_bit(spec, i) for i in range(ncl)], dtype=np.int64),
            src_kind=kinds, src_par=par,
            Minv=np.linalg.inv(mechanism.M),
            time_tol=options.time_tolerance or 1e-6 * dt,
            zeno_window=1e-3 * 2 * math.pi / highest_frequency(mechanism), zeno_stick=options.zeno_stick,
            zeno_stop=options.zeno_stop,
            x_limit=1e3 * x_scale,
            rest_velocity=options.rest_velocity or 1e-5 * self.velocity_scale(),
            gap_noise=1e-13 * x_scale,
            refine=float(options.refine),
            refine_window=options.refine_periods * 2 * math.pi / highest_frequency(mechanism),
        )
        self.tables = ConfigurationTables.empty(2**ncl, n, ncl, len(self.source_numbers))
        # the kernel sees the same arrays, so configurations built later are visible to it
        self.kernel_tables = kernel.Configs(*(getattr(self.tables, f) for f in kernel.Configs._fields))
        self.n_steps = int(math.ceil(t_end / dt - 1e-9))
        n_rows = self.n_steps + 1 if options.every_step else int(math.floor(t_end / out_dt + 1e-9)) + 1
        self.capacity = min(n_rows + 64, 200_000) if options.every_step else n_rows + 1
        self.out = self._new_output(self.capacity, 4096)
        ns = len(self.source_numbers)
        self.work = kernel.Work(
            xl=np.zeros(n), vl=np.zeros(n), al=np.zeros(n), rhs=np.zeros(n), S=np.zeros((n, n)),
            Sinv=np.zeros((n, n)), x0=np.zeros(n), v0=np.zeros(n), a0=np.zeros(n), x1=np.zeros(n),
            v1=np.zeros(n), a1=np.zeros(n), phi=np.zeros(ncl), tau=np.zeros(ncl), xo=np.zeros(n),
            vo=np.zeros(n), ao=np.zeros(n), src=np.zeros(3 * len(self.source_numbers)),
        )
        start = mechanism.start
        self.x, self.v, self.a = start.q.copy(), start.qd.copy(), start.qdd.copy()
        self.istate = np.zeros(10, dtype=np.int64)
        self.istate[kernel.I_CFG] = mask_of(spec, spec.initial.closed)
        self.istate[kernel.I_NEED_ACCEL] = 1
        self.fstate = np.zeros(4)
        self.fstate[kernel.F_LAST_EVENT] = -1.0
        self.rows: list[tuple[np.ndarray, ...]] = []
        self.event_rows: list[tuple[np.ndarray, ...]] = []
        self.ns = ns

    def velocity_scale(self) -> float:
        """Cam amplitude times the larger of the cam speed and the lowest elastic frequency."""
        omega = self.mechanism.start_layer.modes.omega
        lowest = float(omega[omega > 0].min()) if np.any(omega > 0) else 0.0
        return self.mechanism.spec.cam.amplitude * max(self.mechanism.omega, lowest)

    def _new_output(self, rows: int, events: int) -> kernel.Output:
        n = self.mechanism.spec.n_coordinates + len(self.source_numbers)
        ncl = len(self.mechanism.spec.clearances)
        return kernel.Output(
            t=np.zeros(rows), x=np.zeros((rows, n)), v=np.zeros((rows, n)), a=np.zeros((rows, n)),
            F=np.zeros((rows, ncl)), cfg=np.zeros(rows, dtype=np.int64),
            ev_t=np.zeros(events), ev_k=np.zeros(events, dtype=np.int64), ev_kind=np.zeros(events, dtype=np.int64),
            ev_u=np.zeros(events), ev_from=np.zeros(events, dtype=np.int64), ev_to=np.zeros(events, dtype=np.int64),
            F_peak=np.zeros(ncl),
        )

    def _flush(self) -> None:
        """Move the filled rows out of the kernel's buffers and reset them."""
        nout = int(self.istate[kernel.I_NOUT])
        nev = int(min(self.istate[kernel.I_NEV], self.out.ev_t.shape[0]))
        o = self.out
        self.rows.append((o.t[:nout].copy(), o.x[:nout].copy(), o.v[:nout].copy(), o.a[:nout].copy(),
                          o.F[:nout].copy(), o.cfg[:nout].copy()))
        self.event_rows.append((o.ev_t[:nev].copy(), o.ev_k[:nev].copy(), o.ev_kind[:nev].copy(),
                                o.ev_u[:nev].copy(), o.ev_from[:nev].copy(), o.ev_to[:nev].copy()))
        self.istate[kernel.I_NOUT] = 0
        self.istate[kernel.I_NEV] = 0

    def execute(self, progress: Progress | None, cancel: Cancel | None) -> None:
        prob = self.problem
        chunk = self.options.chunk_steps * prob.dt
        while True:
            self.fstate[kernel.F_CHUNK_END] = self.fstate[kernel.F_T] + chunk
            status = kernel.run_chunk(prob, self.kernel_tables, self.out, self.work, self.x, self.v, self.a,
                                      self.istate, self.fstate, STATUS_CODES)
            t = float(self.fstate[kernel.F_T])
            if status == NEED_CONFIG:
                self._build(int(self.istate[kernel.I_WANT_CFG]))
                continue
            if status == OUTPUT_FULL:
                self._flush()
                continue
            if status == DIVERGED:
                raise RunError(self._where("diverged", t))
            if status == CHATTER:
                raise RunError(self._where(
                    f"chattering contact: {self.options.zeno_stop} events within "
                    f"{prob.zeno_window:.3g} s of each other, even with sticking contacts", t))
            if progress is not None:
                progress(min(t / prob.t_end, 1.0))
            if status == FINISHED:
                self._flush()
                return
            if cancel is not None and cancel():
                raise RunError(f"cancelled at t = {t:.6g} s")

    def _build(self, mask: int) -> None:
        o = self.options
        self.tables.build(self.mechanism, mask, o.time_step, o.beta, o.gamma, o.time_step / o.refine)

    def _where(self, what: str, t: float) -> str:
        spec = self.mechanism.spec
        angle = t * self.mechanism.omega * 180.0 / math.pi
        label = configuration_label(spec, int(self.istate[kernel.I_CFG]))
        return f"{what} at t = {t:.6g} s (cam angle {angle:.3f} deg) in configuration {label}"

    def trace(self, wall_time: float) -> Trace:
        spec = self.mechanism.spec
        t, x, v, a, F, cfg = (np.concatenate(parts) for parts in zip(*self.rows, strict=True))
        ev = [np.concatenate(parts) for parts in zip(*self.event_rows, strict=True)]
        omega = self.mechanism.omega
        events = tuple(
            Event(float(et), float(et * omega * 180 / math.pi), spec.clearances[int(k)].name,
                  EVENT_KINDS[int(kind)], float(u), int(before), int(after))
            for et, k, kind, u, before, after in zip(*ev, strict=True)
        )
        numbers = tuple(range(1, spec.n_coordinates + 1)) + tuple(self.source_numbers)
        o = self.options
        settings = {"time_step_s": o.time_step, "beta": o.beta, "gamma": o.gamma,
                    "refine_after_events": o.refine, "rpm": spec.run.rpm, "degrees": spec.run.degrees}
        stats = RunStatistics("newmark", int(self.istate[kernel.I_STEPS]), len(events), wall_time,
                              tuple(self.tables.configurations_built()), settings)
        return Trace(spec, t, t * omega * 180 / math.pi, numbers, x, v, a, F, cfg, events, self.out.F_peak.copy(), stats)
