"""The ``newmark`` back end: Newmark integration with located events and impacts.

The run loop is the numba kernel :func:`vtool.solvers.newmark.kernel.run_chunk`
on the shared contact problem (:mod:`vtool.solvers.model.contact`); this module
validates the settings, builds configurations lazily (the first time the
kernel reaches one), calls the kernel in chunks (progress, cancel), and hands
rows and events to the :class:`~vtool.solvers.trace.TraceBuilder`.

The method (configurations, event location by re-stepping, the impact laws,
resting contacts and chattering, the refinement after events, the stability
limit omega_max dt <= 1 / sqrt(gamma/2 - beta)) is in docs/valvetrain.md, "The
method"; its equations in :mod:`vtool.solvers.newmark.kernel`; the first run's
compile (:func:`compile_notice`, :class:`KernelRun`) in docs/developer.md,
"Compile".
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from vtool.errors import InputError, RunError
from vtool.solvers.backends import (
    AccuracyKnobs,
    AccuracySetting,
    Backend,
    Cancel,
    Progress,
    RunStats,
)
from vtool.solvers.model.contact import LAW_CODES, SOFT_CODES, ContactProblem, EventRules
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import (
    BETA_RANGE,
    GAMMA_RANGE,
    RIGID,
    MechanismSpec,
    RunSpec,
)
from vtool.solvers.newmark import layout
from vtool.solvers.newmark.records import Output, State, scratch
from vtool.solvers.trace import TraceBuilder

ROW_BUFFER = 4096  # output rows between flushes at most: memory stays bounded for any run length
EVENT_BUFFER = 1024  # events between flushes


def row_buffer(t_end: float, out_dt: float, every_step: bool) -> int:
    """Rows of a run's output buffer: :data:`ROW_BUFFER`, or fewer when the run's rows at the output
    interval (the start's included) fit in fewer (1A: 853 for its 851 rows, not 4096, to allocate per run)."""
    if every_step or not out_dt > 0.0:
        return ROW_BUFFER
    return int(min(ROW_BUFFER, t_end / out_dt + 3.0))


#: The accuracy study's row of the thesis' own scheme (see NewmarkBackend.accuracy_settings).
PLAIN_SETTING = "dt=1e-06 beta=1/6, no refinement (the thesis' scheme)"


@dataclass(frozen=True)
class NewmarkOptions:
    """Settings of the newmark back end."""

    time_step: float  # s
    beta: float = 1.0 / 6.0
    gamma: float = 0.5
    output_interval: float = 1.0  # degrees of cam rotation
    every_step: bool = False
    time_tolerance: float | None = None  # s; default 1e-6 * time_step
    rest_velocity: float | None = None  # length/s; default 1e-5 of the velocity scale (see ContactProblem)
    zeno_stick: int = 20
    zeno_stop: int = 400
    chunk_steps: int = 5000
    enforce_stability_limit: bool = True  # False only to study divergence (tests)
    refine: int = 10  # after each event, steps of time_step / refine ...
    refine_periods: float = 4.0  # ... for this many periods of the highest natural frequency


def kernel_laws(spec: Any, impacts: tuple[str, ...] = ()) -> tuple[bool | None, bool | None]:
    """The kernel's (hertz, momentum) switches for a valve-train spec, and for its runs under the impact
    laws ``impacts`` besides (``vtool compare``): :func:`~vtool.solvers.newmark.layout.laws` of the
    codes :class:`~vtool.solvers.model.contact.ContactProblem` puts in its clearance table (one
    derivation), with a rigid clearance per law of ``impacts``."""
    codes = [(SOFT_CODES[c.contact], LAW_CODES[spec.impact_law(c)]) for c in spec.clearances]
    codes += [(SOFT_CODES[RIGID], LAW_CODES[law]) for law in impacts]
    cl = np.zeros((len(codes), layout.CL_SIZE), dtype=np.int64)
    if codes:
        cl[:, [layout.CL_SOFT, layout.CL_LAW]] = codes
    return layout.laws(cl)


def compile_notice(backend: str = "newmark", laws: tuple[bool | None, bool | None] = (None, None)) -> str | None:
    """The line to show before a run that must first compile the solver, or None when it is compiled.

    The newmark back end runs ``run_chunk``; the piecewise back ends call the
    event rules (:data:`RULES`) from Python. ``laws``: see :func:`kernel_laws`
    (a kernel is compiled and cached per switch pair). Imports numba.
    """
    from vtool import jit
    from vtool.solvers.newmark import kernel

    name = "run_chunk" if backend == "newmark" else "rules"
    if jit.is_compiled(kernel.run_chunk if backend == "newmark" else kernel.release_pulling, name,
                       jit.law_key(*laws)):
        return None
    return jit.compile_notice("the solver" if backend == "newmark" else "the event rules", name)


def stability_limit(beta: float, gamma: float, omega_max: float) -> float:
    """Largest stable step (s) of Newmark(beta, gamma) for omega_max; inf if unconditional."""
    if 2.0 * beta >= gamma >= 0.5:
        return math.inf
    return 1.0 / math.sqrt(gamma / 2.0 - beta) / omega_max


def round_down(value: float, digits: int) -> float:
    """``value`` rounded down to ``digits`` significant digits (a printed limit never exceeds the limit)."""
    unit = 10.0 ** (math.floor(math.log10(value)) - digits + 1)
    return math.floor(value / unit) * unit


class NewmarkBackend(Backend[NewmarkOptions]):
    """Newmark back end (see module doc). Registered as ``newmark``."""

    name = "newmark"
    fixed_step = True
    remedy = "a smaller time step, or the exact back end"

    @staticmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> NewmarkOptions:
        return NewmarkOptions(run.time_step, run.beta, run.gamma, run.output_interval, every_step)

    @classmethod
    def stable_step(cls, mechanism: Mechanism) -> float:
        run = mechanism.spec.run
        return stability_limit(run.beta, run.gamma, mechanism.highest_frequency)

    @classmethod
    def compile_notice(cls, spec: MechanismSpec, impacts: tuple[str, ...] = ()) -> str | None:
        return compile_notice(cls.name, kernel_laws(spec, impacts))

    @classmethod
    def warm_up(cls, spec: MechanismSpec) -> None:
        """Compile the kernel for valve-train ``spec``'s contact laws, or load it from numba's cache: a run
        of ten time steps (the TUI starts it when a preset opens). Nothing when its settings are refused
        (the real run says why)."""
        from vtool.solvers.model.mechanism import assemble

        run = spec.run
        short = dataclasses.replace(spec, run=dataclasses.replace(run, degrees=10.0 * run.time_step * 6.0 * run.rpm))
        try:
            cls().simulate(assemble(short), cls.options_from_run(short.run))
        except (InputError, RunError):
            return

    @classmethod
    def accuracy_settings(cls, run: RunSpec, knobs: AccuracyKnobs) -> list[AccuracySetting]:
        """Every step at every beta (with the default refinement after events), then the thesis' plain
        scheme at 1 µs."""
        settings = [AccuracySetting(f"dt={dt:.0e} beta={'1/6' if abs(beta - 1 / 6) < 1e-12 else '1/4'}",
                                    dataclasses.replace(run, time_step=dt, beta=beta))
                    for beta in knobs.betas for dt in knobs.time_steps]
        return [*settings, AccuracySetting(PLAIN_SETTING, run, NewmarkOptions(1e-6, refine=1))]

    def check(self, mechanism: Mechanism, options: NewmarkOptions) -> None:
        """Refuse a step that is not positive or beyond the stability limit."""
        dt = options.time_step
        if not dt > 0.0:
            raise InputError("run.time_step", dt, "> 0", "s")
        (beta_low, beta_high), (gamma_low, gamma_high) = BETA_RANGE, GAMMA_RANGE  # the loader's bounds
        if not beta_low < options.beta <= beta_high:
            raise InputError("run.beta", options.beta, f"> {beta_low:g} and <= {beta_high:g}")
        if not gamma_low <= options.gamma <= gamma_high:
            raise InputError("run.gamma", options.gamma, f">= {gamma_low:g} and <= {gamma_high:g}")
        if not options.refine >= 1:
            raise InputError("refine", options.refine, ">= 1")
        limit = stability_limit(options.beta, options.gamma, mechanism.highest_frequency)
        if dt > limit and options.enforce_stability_limit:
            raise InputError(
                "run.time_step", dt,
                f"<= {round_down(limit, 6):.6g} (stability limit of Newmark beta={options.beta:.4g}, "
                f"gamma={options.gamma:.4g} for the stiffest configuration; use beta=1/4 for no limit)", "s",
            )

    def event_rules(self, options: NewmarkOptions) -> EventRules:
        return EventRules(options.rest_velocity, options.zeno_stick, options.zeno_stop)

    def integrate(self, problem: ContactProblem, options: NewmarkOptions, builder: TraceBuilder,
                  progress: Progress | None, cancel: Cancel | None) -> RunStats:
        run = KernelRun(problem, options, builder)
        run.execute(progress, cancel)
        o = options
        return RunStats(int(run.ist[layout.I_STEPS]), run.peak[layout.PEAK_ALL].copy(),
                        run.peak[layout.PEAK_LATE].copy(), run.peak[layout.PEAK_OVERLAP].copy(),
                        compile_time=run.compile_time,
                        settings={"time_step_s": o.time_step, "beta": o.beta, "gamma": o.gamma,
                                  "refine_after_events": o.refine})


class KernelRun:
    """The kernel's records for one run, and its chunked calls."""

    def __init__(self, problem: ContactProblem, options: NewmarkOptions, builder: TraceBuilder) -> None:
        self.problem = problem
        self.options = options
        self.builder = builder
        mechanism = problem.mechanism
        spec = mechanism.spec
        dt = options.time_step
        self.t_end = spec.run.degrees * math.pi / 180.0 / problem.omega
        fine = dt / options.refine
        problem.tables.use_step(dt, options.beta, options.gamma, fine)
        out_dt = options.output_interval * math.pi / 180.0 / problem.omega
        ip, fp = problem.parameters(
            dt=dt, beta=options.beta, gamma=options.gamma, t_end=self.t_end,
            out_dt=out_dt, every_step=options.every_step,
            time_tol=options.time_tolerance or 1e-6 * dt, refine=float(options.refine),
            refine_window=options.refine_periods * 2 * math.pi / problem.omega_max)
        self.record = problem.record(ip, fp)
        n, ncl, ns = problem.n, problem.ncl, problem.ns
        rows = row_buffer(self.t_end, out_dt, options.every_step)
        # uninitialised: the kernel fills a row (an event) whole before flush reads it, and reads no other.
        # (x, v, a) planes, each rows x (n + ns): a plane's filled rows are the trace's q, q̇ or q̈ as they
        # are (contiguous), with no copy at the end of a run (see flush)
        self.out = Output(np.empty(rows), np.empty((3, rows, n + ns)), np.empty((rows, ncl)),
                          np.empty(rows, dtype=np.int64), np.empty((EVENT_BUFFER, 2)),
                          np.empty((EVENT_BUFFER, 4), dtype=np.int64), np.zeros((3, ncl)))
        start = mechanism.start
        self.state = State(start.q.copy(), start.qd.copy(), start.qdd.copy(), np.zeros(layout.I_SIZE, dtype=np.int64),
                           np.zeros(layout.F_SIZE))
        self.ist, self.fst, self.peak = self.state.ist, self.state.fst, self.out.peak
        self.ist[layout.I_CFG] = problem.start_mask
        self.ist[layout.I_NEED_SETTLE] = 1
        self.fst[layout.F_LAST_EVENT] = -1.0
        self.scratch, self.scratch_buffer = scratch(n, ns, ncl)  # (zeroed before each call: chunk)
        self.compile_time = 0.0

    def flush(self, final: bool = False) -> None:
        """Move the filled rows and events out of the kernel's buffers. ``final``: the run is over and
        the kernel writes no more rows, so the trace may keep the buffers themselves rather than copies."""
        out = self.out
        nout = int(self.ist[layout.I_NOUT])
        nev = int(min(self.ist[layout.I_NEV], out.ev_f.shape[0]))
        self.builder.add_rows(out.t[:nout], out.q[:, :nout].transpose(1, 0, 2), out.F[:nout], out.c[:nout],
                              copy=not final)
        self.builder.add_events(out.ev_f[:nev], out.ev_i[:nev])
        self.ist[layout.I_NOUT] = 0
        self.ist[layout.I_NEV] = 0

    def chunk(self, fresh: bool = True) -> int:
        """One call of the kernel (the first one timed as the compile when the kernel was not compiled);
        ``fresh``: with a zeroed scratch, as every call but one that goes on after a chunk's end (which the
        kernel does by itself when nobody is to be told of the progress: ``layout.FP_CHUNK``)."""
        from vtool import jit
        from vtool.solvers.newmark import kernel

        problem = self.problem
        args = (self.record, problem.tables.record(), self.scratch, self.state, self.out, problem.hertz,
                problem.momentum)
        if fresh:
            self.scratch_buffer.fill(0.0)
            self.scratch.closing.fill(0)
        key = jit.law_key(problem.hertz, problem.momentum)
        status, seconds = jit.timed_call(kernel.run_chunk, "run_chunk", key, *args)
        self.compile_time = self.compile_time or seconds
        return int(status)

    def execute(self, progress: Progress | None, cancel: Cancel | None) -> None:
        problem = self.problem
        chunk = self.options.chunk_steps * self.options.time_step
        self.fst[layout.F_CHUNK_END] = self.fst[layout.F_T] + chunk
        # with no progress to report and no cancel to ask, the kernel goes on past a chunk's end itself
        self.record.fp[layout.FP_CHUNK] = chunk if progress is None and cancel is None else 0.0
        fresh = True
        while True:
            status = self.chunk(fresh)
            fresh = status != layout.CHUNK_END
            t = float(self.fst[layout.F_T])
            if status == layout.NEED_CONFIG:
                problem.build(int(self.ist[layout.I_WANT_CFG]))
                continue
            if status == layout.OUTPUT_FULL:  # the chunk goes on (its end stays: progress and cancel keep coming)
                self.flush()
                continue
            self.fst[layout.F_CHUNK_END] = t + chunk
            if status == layout.DIVERGED:
                raise RunError(self._where("diverged", t))
            if status == layout.CHATTER:
                raise RunError(self._where(
                    f"chattering contact: {self.options.zeno_stop} events within "
                    f"{problem.zeno_window:.3g} s of each other, even with sticking contacts", t))
            if progress is not None:
                progress(min(t / self.t_end, 1.0))
            if status == layout.FINISHED:
                self.flush(final=True)
                return
            if cancel is not None and cancel():
                raise RunError(f"cancelled at t = {t:.6g} s")

    def _where(self, what: str, t: float) -> str:
        angle = self.problem.time_to_angle(t)
        label = self.problem.label(int(self.ist[layout.I_CFG]))
        return f"{what} at t = {t:.6g} s (cam angle {angle:.3f} deg) in configuration {label}"
