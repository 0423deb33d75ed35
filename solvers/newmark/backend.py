"""The ``newmark`` back end: Newmark integration with located events and impacts.

The run loop is the numba kernel :func:`vtool.solvers.newmark.kernel.run_chunk`
on the shared contact problem (:mod:`vtool.solvers.model.contact`); this module
validates the settings, builds configurations lazily (the first time the
kernel reaches one), calls the kernel in chunks (progress, cancel), and hands
rows and events to the :class:`~vtool.solvers.trace.TraceBuilder`.

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
* Impacts: the clearance's impact law (``local``, ``thesis``, ``momentum``;
  see :func:`vtool.solvers.newmark.kernel.impact`) with Newton's restitution
  coefficient. After every transition the contact forces of the new
  configuration are evaluated and any contact that would pull is released
  at once (:func:`vtool.solvers.newmark.kernel.settle`). Separations and
  bounces slower than ``rest_velocity`` (default 1e-5 of the cam amplitude
  times the larger of the cam speed and the lowest natural frequency) are
  resting contacts that stay closed until their contact force says
  otherwise.
* Chattering: ``zeno_stick`` (20) events each within 1e-3 of the shortest
  natural period of the previous one (events piling up) make
  every contact involved stick (restitution zero, held shut; their forces
  then decide separation); ``zeno_stop`` (400) such events stop the run with
  a message naming the time and configuration. A run never loops forever.
* Refinement after events: an impact excites the highest modes, which the
  step resolves poorly (omega_max dt = 1.37 at 1 µs in the thesis examples),
  and their error moves the events that follow. For four periods of the
  highest natural frequency after every event the step is divided by
  ``refine`` (10); the rest of the run keeps the user's step. Four periods,
  not two: with two, a grazing rocker re-contact of example 3 (7 lbf just
  after the impact) came out as an extra separation; with four, all six
  thesis presets give the exact back end's event sequence (the accuracy
  tables give the figures). ``refine = 1`` is the plain thesis scheme.
* First run: when numba's cache has no compiled kernel for this mechanism's
  contact laws (a new install, or the first Hertz or momentum-law run), the
  run does not wait for the compile. A child process compiles the kernel
  into the cache (:mod:`vtool.solvers.newmark.build`) while the run starts at
  once in the kernel's own source run as plain Python
  (:func:`~vtool.solvers.newmark.build.plain_kernel`); between chunks the
  run looks in the cache and, once the kernel is there,
  loads it and goes on compiled (should the child end without it, the run
  compiles the kernel itself). Both execute the same source, and their
  results agree to the last bit on every thesis preset (a test compares
  them to the reference tolerances). ``VTOOL_KERNEL`` chooses otherwise:
  ``compiled`` compiles first, in this process (benchmarks, and the tests,
  which need the compiled kernel), ``plain`` never compiles.
* Native module: after that compile the child also builds ``run_chunk`` as
  a native extension module (:mod:`vtool.solvers.newmark.native`); a later
  ``auto`` run that finds the module for its argument types calls it and
  imports no numba (one that finds only numba's cache starts the build).
* Stability: for gamma = 1/2 and beta < 1/4 the step must satisfy
  omega_max dt <= 1 / sqrt(gamma/2 - beta) (2 sqrt 3 for linear acceleration:
  dt <= sqrt(3)/pi T_min), with omega_max the highest natural frequency of
  the unconstrained system, which bounds every configuration's.
"""

from __future__ import annotations

import dataclasses
import math
import time as wallclock
from dataclasses import dataclass
from functools import cached_property
from types import ModuleType
from typing import Any

import numpy as np

from vtool import compile_estimate, numba_cache
from vtool.errors import InputError, RunError
from vtool.solvers.backends import (
    AccuracyKnobs,
    AccuracySetting,
    Backend,
    Cancel,
    Progress,
    RunStats,
)
from vtool.solvers.model.contact import ContactProblem, EventRules
from vtool.solvers.model.mechanism import Mechanism
from vtool.solvers.model.spec import (
    BETA_RANGE,
    GAMMA_RANGE,
    HERTZ,
    MOMENTUM,
    RIGID,
    MechanismSpec,
    RunSpec,
)
from vtool.solvers.newmark import build as kernel_build
from vtool.solvers.newmark import layout
from vtool.solvers.newmark import native as kernel_native
from vtool.solvers.trace import TraceBuilder

#: first compiles on the reference machine of :mod:`vtool.compile_estimate` (s), which scales them to the
#: machine at hand for the notice (``python3 benchmarks/bench_compile_estimate.py`` measures them): the kernel
#: in the run's own process (two processes compile: n = 2) ...
COMPILE_REFERENCE_S = 2.8
#: ... in a child beside a first run in plain Python, until it is in numba's cache (the run is a third
#: process while it lasts: n = 3; the child's own start-up is in it) ...
BACKGROUND_REFERENCE_S = 2.7
#: ... and the event rules alone (impact, settle, fill_sources: the piecewise back ends; n = 1)
RULES_REFERENCE_S = 1.6
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

    @classmethod
    def from_run(cls, run: RunSpec, every_step: bool = False) -> NewmarkOptions:
        return cls(run.time_step, run.beta, run.gamma, run.output_interval, every_step)


def kernel_laws(spec: Any, impacts: tuple[str, ...] = ()) -> tuple[bool | None, bool | None]:
    """The kernel's (hertz, momentum) switches (:func:`vtool.solvers.newmark.kernel.laws`) for a
    valve-train spec, and for its runs under the impact laws ``impacts`` besides (``vtool compare``)."""
    hertz = any(c.contact == HERTZ for c in spec.clearances)
    momentum = MOMENTUM in impacts or any(c.contact == RIGID and spec.impact_law(c) == MOMENTUM
                                          for c in spec.clearances)
    return (True if hertz else None), (True if momentum else None)


def compile_notice(backend: str = "newmark", laws: tuple[bool | None, bool | None] = (None, None)) -> str | None:
    """The line to show before a run that must first compile the kernel, or None when it is cached.

    The newmark back end runs ``run_chunk``; the piecewise back ends call the
    event rules (``impact``, ``settle``, ``fill_sources``) from Python. ``laws``:
    see :func:`kernel_laws` (a kernel is compiled and cached per switch pair).
    In the default ``auto`` mode no run waits for the compile: a newmark run
    says so; a piecewise run calls the event rules as plain Python, a few
    milliseconds more, and says nothing (:mod:`vtool.solvers.newmark.build`).
    """
    names = ("run_chunk",) if backend == "newmark" else ("impact", "settle", "fill_sources")
    mode = kernel_build.kernel_mode()
    if mode == "auto" and backend == "newmark" and kernel_native.exists(laws):
        return None  # (asked before numba is imported: a run on the native module imports none)
    if not kernel_build.jit_enabled() or kernel_build.kernel().is_cached(names, *laws):
        return None
    if mode == "plain":
        return None
    if mode == "auto" and numba_cache.CACHE_ENABLED:
        if backend != "newmark":
            return None
        return (f"compiling the solver for these contact laws in the background, once (about "
                f"{compile_estimate.about(BACKGROUND_REFERENCE_S, 3)} s); this run starts now in plain Python "
                "and moves to the compiled solver when it is ready")
    estimate = (compile_estimate.about(COMPILE_REFERENCE_S, 2) if backend == "newmark"
                else compile_estimate.about(RULES_REFERENCE_S, 1))
    return (f"compiling the solver for these contact laws, once (about {estimate} s); "
            "later runs load it from the cache")


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
    return mechanism.highest_frequency


def check_settings(mechanism: Mechanism, options: NewmarkOptions) -> None:
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
    limit = stability_limit(options.beta, options.gamma, highest_frequency(mechanism))
    if dt > limit and options.enforce_stability_limit:
        raise InputError(
            "run.time_step", dt,
            f"<= {round_down(limit, 6):.6g} (stability limit of Newmark beta={options.beta:.4g}, gamma={options.gamma:.4g} "
            f"for the stiffest configuration; use beta=1/4 for no limit)", "s",
        )


class NewmarkBackend(Backend[NewmarkOptions]):
    """Newmark back end (see module doc). Registered as ``newmark``."""

    name = "newmark"
    fixed_step = True
    remedy = "a smaller time step, or the exact back end"

    @staticmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> NewmarkOptions:
        return NewmarkOptions.from_run(run, every_step)

    @classmethod
    def stable_step(cls, mechanism: Mechanism) -> float:
        run = mechanism.spec.run
        return stability_limit(run.beta, run.gamma, highest_frequency(mechanism))

    @classmethod
    def compile_notice(cls, spec: MechanismSpec, impacts: tuple[str, ...] = ()) -> str | None:
        return compile_notice(cls.name, kernel_laws(spec, impacts))

    @classmethod
    def accuracy_settings(cls, run: RunSpec, knobs: AccuracyKnobs) -> list[AccuracySetting]:
        """Every step at every beta (with the default refinement after events), then the thesis' plain
        scheme at 1 µs."""
        settings = [AccuracySetting(f"dt={dt:.0e} beta={'1/6' if abs(beta - 1 / 6) < 1e-12 else '1/4'}",
                                    dataclasses.replace(run, time_step=dt, beta=beta))
                    for beta in knobs.betas for dt in knobs.time_steps]
        return [*settings, AccuracySetting(PLAIN_SETTING, run, NewmarkOptions(1e-6, refine=1))]

    def check(self, mechanism: Mechanism, options: NewmarkOptions) -> None:
        check_settings(mechanism, options)

    def event_rules(self, options: NewmarkOptions) -> EventRules:
        return EventRules(options.rest_velocity, options.zeno_stick, options.zeno_stop)

    def integrate(self, problem: ContactProblem, options: NewmarkOptions, builder: TraceBuilder,
                  progress: Progress | None, cancel: Cancel | None) -> RunStats:
        run = KernelRun(problem, options, builder)
        run.execute(progress, cancel)
        o = options
        return RunStats(int(run.ist[layout.I_STEPS]), run.peak[layout.PEAK_ALL].copy(),
                        run.peak[layout.PEAK_LATE].copy(), run.peak[layout.PEAK_OVERLAP].copy(),
                        compile_time=run.compile_time, plain_steps=run.plain_steps, kernel=run.kernel,
                        settings={"time_step_s": o.time_step, "beta": o.beta, "gamma": o.gamma,
                                  "refine_after_events": o.refine})


def kernel_kind(module: ModuleType) -> str:
    """What a kernel module is: "native" (:mod:`vtool.solvers.newmark.native`'s extension module), "numba"
    (numba's compiled kernel) or "plain" (the source as plain Python: a first run before the compile, or
    ``VTOOL_KERNEL=plain``, or ``NUMBA_DISABLE_JIT``)."""
    if module.__name__.startswith(kernel_native.PREFIX):
        return "native"
    return "numba" if hasattr(module.run_chunk, "py_func") else "plain"


#: Native modules whose build this process found failed, or could not start: each warm run on numba's
#: kernel asked again (the build's lock file named and its failure note looked for: 0.25 ms a run).
_no_native_build: set[str] = set()
#: The argument types ``run_chunk`` is compiled or loaded for in this process, by their objects' ids: a
#: warm run's check without hashing them (numba hashes its 32 types in about 25 µs, a hundredth of a run).
_compiled_for: dict[tuple[int, ...], tuple[Any, ...]] = {}


class KernelRun:
    """The kernel's buffers and state for one run, and its chunked calls."""

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
        self.ip, self.fp = problem.parameters(
            dt=dt, beta=options.beta, gamma=options.gamma, t_end=self.t_end,
            out_dt=out_dt, every_step=options.every_step,
            time_tol=options.time_tolerance or 1e-6 * dt, refine=float(options.refine),
            refine_window=options.refine_periods * 2 * math.pi / problem.omega_max)
        n, ncl, ns = problem.n, problem.ncl, problem.ns
        rows = row_buffer(self.t_end, out_dt, options.every_step)
        # uninitialised: the kernel fills a row (an event) whole before flush reads it, and reads no other
        self.out_t = np.empty(rows)
        # (x, v, a) planes, each rows x (n + ns): a plane's filled rows are the trace's q, q̇ or q̈ as they
        # are (contiguous), with no copy at the end of a run (see flush)
        self.out_q = np.empty((3, rows, n + ns))
        self.out_F = np.empty((rows, ncl))
        self.out_c = np.empty(rows, dtype=np.int64)
        self.ev_f = np.empty((EVENT_BUFFER, 2))
        self.ev_i = np.empty((EVENT_BUFFER, 4), dtype=np.int64)
        self.peak = np.zeros((3, ncl))
        start = mechanism.start
        self.x, self.v, self.a = start.q.copy(), start.qd.copy(), start.qdd.copy()
        self.ist = np.zeros(layout.I_SIZE, dtype=np.int64)
        self.ist[layout.I_CFG] = problem.start_mask
        self.ist[layout.I_NEED_SETTLE] = 1
        self.fst = np.zeros(layout.F_SIZE)
        self.fst[layout.F_LAST_EVENT] = -1.0
        # run_chunk's scratch (it zeroes them at each call)
        self.work = np.zeros(layout.WORK_PER_N * n + layout.WORK_PER_SOURCE * ns + layout.WORK_PER_CLEARANCE * ncl)
        self.L = np.zeros((n, n))
        self.closing = np.zeros(ncl, dtype=np.int64)
        self.compile_time = 0.0
        self.plain_steps = 0  # steps taken by the plain-Python kernel (before the compiled one was ready)
        self.kernel = ""  # what took the last chunk: "native" (module), "numba" or "plain" (see kernel_kind)

    def flush(self, final: bool = False) -> None:
        """Move the filled rows and events out of the kernel's buffers. ``final``: the run is over and
        the kernel writes no more rows, so the trace may keep the buffers themselves rather than copies
        (in a process on the native module each copy took fresh memory, which the machine faulted in
        page by page: 68 page faults a warm 1A run, none now; ``benchmarks/bench_page_faults.py``)."""
        nout = int(self.ist[layout.I_NOUT])
        nev = int(min(self.ist[layout.I_NEV], self.ev_f.shape[0]))
        self.builder.add_rows(self.out_t[:nout], self.out_q[:, :nout].transpose(1, 0, 2), self.out_F[:nout],
                              self.out_c[:nout], copy=not final)
        self.builder.add_events(self.ev_f[:nev], self.ev_i[:nev])
        self.ist[layout.I_NOUT] = 0
        self.ist[layout.I_NEV] = 0

    @cached_property
    def _arguments(self) -> tuple:
        problem, tables = self.problem, self.problem.tables
        return (self.ip, self.fp, problem.cl, problem.clf, problem.series.const, problem.series.cos,
                problem.series.sin, problem.mass, tables.ci, tables.cm, tables.cp, tables.mk, tables.mon,
                self.out_t, self.out_q, self.out_F, self.out_c, self.ev_f, self.ev_i, self.peak,
                self.x, self.v, self.a, self.ist, self.fst, self.work, self.L, self.closing, problem.hertz,
                problem.momentum)

    def arguments(self) -> tuple:
        """``run_chunk``'s arguments: arrays made once for the run (the kernel writes into them), so the
        tuple is made once too."""
        return self._arguments

    @cached_property
    def signature(self) -> tuple[Any, ...]:
        """numba's types of :meth:`arguments` (what ``run_chunk`` is compiled for; fixed for the run)."""
        return kernel_build.numba_types(self.arguments())

    @cached_property
    def signature_key(self) -> tuple[int, ...]:
        """:attr:`signature` by its types' ids (numba interns its types: equal types are one object), the key
        of ``_compiled_for``."""
        return tuple(map(id, self.signature))

    def compile(self) -> None:
        """Compile (or load from the cache) the kernel for these argument types; timed apart from the run."""
        if not kernel_build.jit_enabled():
            return  # NUMBA_DISABLE_JIT (the plain reference)
        signature = self.signature
        if self.signature_key in _compiled_for:
            return
        kernel = kernel_build.kernel()
        if signature not in kernel.run_chunk.signatures:  # (compiled or loaded in this process already)
            started = wallclock.perf_counter()
            if self.ready():
                kernel.run_chunk.compile(signature)  # a load from the cache
            else:  # on two processes; once, should another process be compiling the same kernel
                kernel_build.compile_once(signature, self.ready)
            self.compile_time += wallclock.perf_counter() - started
        _compiled_for[self.signature_key] = signature  # (the types kept alive: their ids stay theirs)

    def ready(self) -> bool:
        """True when ``run_chunk`` for these argument types is loaded in this process, or in numba's cache."""
        if self.signature_key in _compiled_for:
            return True
        kernel = kernel_build.kernel()
        return (self.signature in kernel.run_chunk.signatures
                or kernel.is_cached(("run_chunk",), self.problem.hertz, self.problem.momentum))

    def first_kernel(self) -> tuple[ModuleType, bool]:
        """The kernel module that takes the first chunk, and whether a compile is under way meanwhile
        (see "First run" in the module doc)."""
        mode = kernel_build.kernel_mode()
        if mode == "auto":
            native = kernel_native.load(self.arguments())
            if native is not None:
                return native, False  # numba is not imported
        if not kernel_build.jit_enabled():
            return kernel_build.kernel(), False
        if mode == "plain":
            return kernel_build.plain_kernel(), False
        if (mode == "compiled" or not numba_cache.CACHE_ENABLED or self.ready()
                or not kernel_build.start(self.jobs)):
            self.compile()
            if mode == "auto" and kernel_native.enabled():  # the kernel was cached but has no native module yet
                name = kernel_native.module_name(self.arguments())
                if name not in _no_native_build and not kernel_build.start(self.jobs[1:]):
                    _no_native_build.add(name)  # its build failed (no C compiler?): not asked again in this process
            return kernel_build.kernel(), False
        return kernel_build.plain_kernel(), True

    @cached_property
    def jobs(self) -> list[kernel_build.Job]:
        """What the background child builds for this run: ``run_chunk`` into numba's cache, then (unless
        ``VTOOL_NATIVE=0``) its native module (:mod:`vtool.solvers.newmark.native`). Fixed for the run."""
        jobs: list[kernel_build.Job] = [("run_chunk", self.signature)]
        if kernel_native.enabled():
            jobs.append(("native", (kernel_native.module_name(self.arguments()), self.signature)))
        return jobs

    def execute(self, progress: Progress | None, cancel: Cancel | None) -> None:
        problem = self.problem
        chunk = self.options.chunk_steps * self.options.time_step
        module, building = self.first_kernel()
        args = self.arguments()
        self.fst[layout.F_CHUNK_END] = self.fst[layout.F_T] + chunk
        while True:
            # the child's compile is in the cache (or the child is gone without it: compile here): go on compiled
            if building and (self.ready() or not kernel_build.compiling(self.jobs)):
                self.plain_steps = int(self.ist[layout.I_STEPS])
                self.compile()
                module, building = kernel_build.kernel(), False
            status = module.run_chunk(*args)
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
                self.kernel = kernel_kind(module)
                if getattr(module, "PLAIN", False):  # the whole run in plain Python
                    self.plain_steps = int(self.ist[layout.I_STEPS])
                return
            if cancel is not None and cancel():
                raise RunError(f"cancelled at t = {t:.6g} s")

    def _where(self, what: str, t: float) -> str:
        angle = self.problem.time_to_angle(t)
        label = self.problem.label(int(self.ist[layout.I_CFG]))
        return f"{what} at t = {t:.6g} s (cam angle {angle:.3f} deg) in configuration {label}"
