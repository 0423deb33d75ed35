"""Back-end registry: lowercase names to back-end classes, fed by entry points.

Back ends register in the entry-point group ``vtool.backends`` (see
pyproject.toml). Listing them imports none; :func:`get` loads one.

The contract every back end follows (subclass :class:`Backend`)
---------------------------------------------------------------
1. A lowercase ``name`` and the ability flags (class attributes):
   ``supports_cancel``, ``supports_progress``; ``fixed_step`` (it steps by
   the run's ``time_step``: ``--dt`` applies, a run costs ``t_end / dt``
   steps, its step may be bounded by :meth:`Backend.stable_step`);
   ``reference`` (its events are located on the exact solution: the
   reference of accuracy studies); ``library_dependent`` (its last bits
   follow the numerical libraries' versions and BLAS kernels);
   ``nonlinear_elements`` (it runs the nonlinear elements of
   :mod:`vtool.solvers.model.nonlinear`: an HLA, friction and gas forces on the
   motion; :meth:`Backend.simulate` refuses a preset with one on a back end
   without the flag, in one line naming the field and the back ends that run it).
   Other modules ask the registry (:func:`available`, :func:`get`,
   :func:`with_flag`) and these flags, and never name a back end.
2. ``options_from_run(run: RunSpec, every_step: bool) -> Options``: the back
   end's own frozen options dataclass, built from the preset's run settings.
3. ``check(mechanism, options)``: raise :class:`vtool.errors.InputError` for
   settings a user can fix (time step beyond the stability limit, tolerances
   out of range), before any work.
4. ``integrate(problem, options, builder, progress, cancel) -> RunStats``:
   run the :class:`~vtool.solvers.model.contact.ContactProblem` from its
   static start (:meth:`~vtool.solvers.model.contact.ContactProblem.start_state`)
   to the end, adding rows and events to the
   :class:`~vtool.solvers.trace.TraceBuilder`. Between events a back end
   integrates the configuration's equations
   (:meth:`~vtool.solvers.model.contact.ContactProblem.accelerations`) and
   watches the monitors (``monitors``: a gap while open, a contact force
   while closed; an event is a monitor reaching zero); at an event it calls
   :meth:`~vtool.solvers.model.contact.ContactProblem.transition`, the
   shared event and impact rules (opening, the impact laws, the release of
   pulling contacts), which records the events. Those methods are plain
   Python over NumPy arrays; the Newmark back end runs the same rules in
   its compiled kernel. Return the figures as a :class:`RunStats`.
   ``progress(f)`` is called with the fraction done (0..1) between chunks,
   ``cancel()`` polled between chunks (a true answer stops the run).
5. Errors: a run that cannot be completed (divergence, endless chattering,
   cancellation) raises :class:`vtool.errors.RunError` with a one-line
   message naming the time and configuration. A back end never returns a
   partial trace.

:meth:`Backend.simulate` is the template every back end shares: options,
checks, the contact problem, timing, single-threaded small linear algebra,
and the :class:`~vtool.solvers.trace.Trace` (with a
:class:`~vtool.solvers.trace.CsvStream`, the rows also go to a CSV file as
they are added, so a back end hands them to the builder in time order).
"""

from __future__ import annotations

import math
import time as wallclock
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cache, lru_cache
from importlib.metadata import EntryPoint, entry_points
from typing import TYPE_CHECKING, Any, ClassVar, Generic, TypeVar

from vtool.errors import InputError
from vtool.solvers.model.spec import DEFAULT_BACKEND

if TYPE_CHECKING:  # (numpy too: `vtool --help` imports this module and no numerics)
    import numpy as np

    from vtool.solvers.model.contact import ContactProblem, EventRules
    from vtool.solvers.model.mechanism import Mechanism
    from vtool.solvers.model.spec import MechanismSpec, RunSpec
    from vtool.solvers.trace import CsvStream, Trace, TraceBuilder

ENTRY_POINT_GROUP = "vtool.backends"

Progress = Callable[[float], None]
Cancel = Callable[[], bool]
#: A back end's own frozen options dataclass (NewmarkOptions, ExactOptions, ...).
OptionsT = TypeVar("OptionsT")


@dataclass(frozen=True)
class RunStats:
    """What :meth:`Backend.integrate` returns: the run's own figures, which :meth:`Backend.simulate`
    turns into the trace's :class:`~vtool.solvers.trace.RunStatistics` and peaks."""

    steps: int  # integration steps taken (a piecewise back end: its samples)
    peak: np.ndarray  # largest contact force of each clearance over the run (force unit)
    peak_late: np.ndarray | None = None  # the same after the first revolution
    peak_overlap: np.ndarray | None = None  # largest overlap of each compliant contact (length)
    configurations: tuple[int, ...] | None = None  # masks built (None: the contact problem's built layers)
    settings: dict[str, Any] = field(default_factory=dict)  # the back end's own settings, for the record
    compile_time: float = 0.0  # s spent compiling or loading compiled code, not in the wall time
    sort: bool = False  # the rows were added out of time order: the builder sorts them


@dataclass(frozen=True)
class AccuracyKnobs:
    """What an accuracy study sweeps: steps and Newmark-type beta values for fixed-step back ends,
    relative tolerances for adaptive ones (each back end takes the knobs that apply to it)."""

    time_steps: tuple[float, ...] = ()  # s
    betas: tuple[float, ...] = ()
    rtols: tuple[float, ...] = ()


@dataclass(frozen=True)
class AccuracySetting:
    """One setting of a back end in an accuracy study: its label, the run settings (the back end's
    options from them, unless ``options`` are given), and a note for its row."""

    label: str
    run: RunSpec
    options: Any = None
    note: str = ""


@lru_cache(maxsize=1)
def _entry_points() -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def available() -> list[str]:
    """Names of the installed back ends (nothing is imported)."""
    return sorted(_entry_points())


#: The back end a preset runs when its [run] table names none.
DEFAULT = DEFAULT_BACKEND


def with_flag(flag: str) -> list[str]:
    """Names of the installed back ends whose class sets ``flag`` (e.g. ``"reference"``), sorted; this
    imports them all."""
    return [name for name in available() if getattr(get(name), flag)]


def module_of(name: str) -> str:
    """The module that holds back end ``name`` (nothing is imported)."""
    ep = _entry_points().get(name)
    if ep is None:
        raise InputError("run.backend", name, f"one of the installed back ends: {', '.join(available())}")
    return ep.module


@cache
def get(name: str) -> type[Backend[Any]]:
    """The back-end class registered under ``name``."""
    ep = _entry_points().get(name)
    if ep is None:
        raise InputError("run.backend", name, f"one of the installed back ends: {', '.join(available())}")
    return ep.load()


class Backend(ABC, Generic[OptionsT]):
    """Base class of every back end: see the contract in the module doc."""

    name: ClassVar[str]
    supports_cancel: ClassVar[bool] = True
    supports_progress: ClassVar[bool] = True
    fixed_step: ClassVar[bool] = False
    reference: ClassVar[bool] = False
    library_dependent: ClassVar[bool] = False
    nonlinear_elements: ClassVar[bool] = False
    #: the cost guard's default step limit for this back end (None: vtool.solvers.cost.MAX_STEPS)
    max_steps: ClassVar[float | None] = None
    #: what to try when a run's result is not to be trusted (the trace's warnings say it)
    remedy: ClassVar[str] = "another back end to compare"

    @classmethod
    def stable_step(cls, mechanism: Mechanism) -> float:
        """The largest stable step of this back end for the mechanism's run settings (s; inf: no bound)."""
        return math.inf

    @classmethod
    def compile_notice(cls, spec: MechanismSpec, impacts: tuple[str, ...] = ()) -> str | None:
        """The line to show before a run of ``spec`` (and of it under the impact laws ``impacts``) that
        must first compile code, or None (default: nothing to compile)."""
        return None

    @classmethod
    def warm_up(cls, spec: MechanismSpec) -> None:  # noqa: B027 (optional hook)
        """Compile (or load) what a run of ``spec`` will need, ahead of it (default: nothing)."""

    @classmethod
    def accuracy_settings(cls, run: RunSpec, knobs: AccuracyKnobs) -> list[AccuracySetting]:
        """The settings an accuracy study runs this back end at (default: none; see
        :mod:`vtool.solvers.studies.accuracy`)."""
        return []

    @staticmethod
    @abstractmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> OptionsT:
        """The back end's options from a preset's run settings."""

    def default_options(self, mechanism: Mechanism) -> OptionsT:
        return self.options_from_run(mechanism.spec.run)

    def check(self, mechanism: Mechanism, options: OptionsT) -> None:  # noqa: B027 (optional hook)
        """Raise InputError for settings the user can fix (default: none to check)."""

    @classmethod
    def refuse_elements(cls, spec: MechanismSpec) -> None:
        """One line (InputError) if ``spec`` has nonlinear elements and this back end does not take them."""
        if cls.nonlinear_elements:
            return
        from vtool.solvers.model.nonlinear import element_fields

        fields = element_fields(spec)
        if fields:
            raise InputError("run.backend", cls.name, f"a back end that runs nonlinear elements "
                             f"({', '.join(with_flag('nonlinear_elements'))}) for a preset with [{fields[0]}]")

    def event_rules(self, options: OptionsT) -> EventRules | None:
        """The settings of the shared event rules from the options (None: the defaults)."""
        return None

    @abstractmethod
    def integrate(self, problem: ContactProblem, options: OptionsT, builder: TraceBuilder,
                  progress: Progress | None, cancel: Cancel | None) -> RunStats:
        """Run the contact problem into the builder; return the statistics (see the contract)."""

    def simulate(self, mechanism: Mechanism, options: OptionsT | None = None, progress: Progress | None = None,
                 cancel: Cancel | None = None, stream: CsvStream | None = None) -> Trace:
        from vtool.solvers.model.contact import ContactProblem, EventRules
        from vtool.solvers.trace import RunStatistics, TraceBuilder
        from vtool.threads import limited

        self.refuse_elements(mechanism.spec)
        options = options if options is not None else self.default_options(mechanism)
        self.check(mechanism, options)
        rules = self.event_rules(options) or EventRules()
        with limited():
            started = wallclock.perf_counter()
            problem = ContactProblem.for_run(mechanism, rules)
            builder = TraceBuilder(mechanism.spec, problem.source_numbers, problem.omega, stream)
            stats = self.integrate(problem, options, builder, progress, cancel)
            compile_time = stats.compile_time
            writing = stream.seconds if stream is not None else 0.0  # the CSV's share, not the solver's
            wall = wallclock.perf_counter() - started - compile_time - writing
        spec = mechanism.spec
        settings = dict(stats.settings)
        settings.update(rpm=spec.run.rpm, degrees=spec.run.degrees,
                        impact=sorted({spec.impact_law(c) for c in spec.clearances if c.rigid}),
                        rocker_scale=spec.contact.rocker_scale, start_velocities=spec.initial.velocities)
        if any(not c.rigid for c in spec.clearances):
            settings["contact"] = {c.name: c.contact for c in spec.clearances if not c.rigid}
        if stats.configurations is None:  # the configurations this run held: its start and every event's two
            # (the tables are shared by every run of the mechanism, so what they have built says nothing of this run)
            built = {problem.start_mask} | {e.before for e in builder.events} | {e.after for e in builder.events}
        else:
            built = set(stats.configurations)
        statistics = RunStatistics(self.name, stats.steps, len(builder.events), wall, tuple(sorted(built)), settings,
                                   compile_time=compile_time,
                                   remedy=self.remedy)
        return builder.build(stats.peak, statistics, stats.peak_late, sort=stats.sort,
                             peak_overlap=stats.peak_overlap)
