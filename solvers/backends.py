"""Back-end registry: lowercase names to back-end classes, fed by entry points.

Back ends register in the entry-point group ``vtool.backends`` (see
pyproject.toml). Listing them imports none; :func:`get` loads one.

The contract every back end follows (subclass :class:`Backend`)
---------------------------------------------------------------
1. A lowercase ``name`` and the ability flags ``supports_cancel`` and
   ``supports_progress`` (class attributes).
2. ``options_from_run(run: RunSpec, every_step: bool) -> Options``: the back
   end's own frozen options dataclass, built from the preset's run settings.
3. ``check(mechanism, options)``: raise :class:`vtool.errors.InputError` for
   settings a user can fix (time step beyond the stability limit, tolerances
   out of range), before any work.
4. ``integrate(problem, options, builder, progress, cancel) -> dict``: run
   the :class:`~vtool.solvers.model.contact.ContactProblem` from its static start to
   the end, adding rows and events to the
   :class:`~vtool.solvers.trace.TraceBuilder`; apply the shared event rules
   (kernel functions ``apply_impacts`` and ``release_pulling``); return the statistics
   (``steps``, ``peak``, ``peak_late``, ``peak_overlap``, ``configurations``, ``settings``; optionally
   ``compile_time``, see :class:`~vtool.solvers.trace.RunStatistics`).
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

import time as wallclock
from abc import ABC, abstractmethod
from collections.abc import Callable
from functools import cache, lru_cache
from importlib.metadata import EntryPoint, entry_points
from typing import TYPE_CHECKING, Any, ClassVar

from vtool.errors import InputError

if TYPE_CHECKING:
    from vtool.solvers.model.contact import ContactProblem
    from vtool.solvers.model.mechanism import Mechanism
    from vtool.solvers.model.spec import RunSpec
    from vtool.solvers.trace import CsvStream, Trace, TraceBuilder

ENTRY_POINT_GROUP = "vtool.backends"

Progress = Callable[[float], None]
Cancel = Callable[[], bool]


@lru_cache(maxsize=1)
def _entry_points() -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def available() -> list[str]:
    """Names of the installed back ends (nothing is imported)."""
    return sorted(_entry_points())


@cache
def get(name: str) -> type[Backend]:
    """The back-end class registered under ``name``."""
    ep = _entry_points().get(name)
    if ep is None:
        raise InputError("run.backend", name, f"one of the installed back ends: {', '.join(available())}")
    return ep.load()  # type: ignore[no-any-return]


class Backend(ABC):
    """Base class of every back end: see the contract in the module doc."""

    name: ClassVar[str]
    supports_cancel: ClassVar[bool] = True
    supports_progress: ClassVar[bool] = True

    @staticmethod
    @abstractmethod
    def options_from_run(run: RunSpec, every_step: bool = False) -> Any:
        """The back end's options from a preset's run settings."""

    def default_options(self, mechanism: Mechanism) -> Any:
        return self.options_from_run(mechanism.spec.run)

    def check(self, mechanism: Mechanism, options: Any) -> None:  # noqa: B027 (optional hook)
        """Raise InputError for settings the user can fix (default: none to check)."""

    @abstractmethod
    def integrate(self, problem: ContactProblem, options: Any, builder: TraceBuilder,
                  progress: Progress | None, cancel: Cancel | None) -> dict[str, Any]:
        """Run the contact problem into the builder; return the statistics (see the contract)."""

    def simulate(self, mechanism: Mechanism, options: Any = None, progress: Progress | None = None,
                 cancel: Cancel | None = None, stream: CsvStream | None = None) -> Trace:
        from vtool.solvers.model.contact import ContactProblem, EventRules
        from vtool.solvers.trace import RunStatistics, TraceBuilder
        from vtool.threads import limited

        options = options if options is not None else self.default_options(mechanism)
        self.check(mechanism, options)
        rules = EventRules(rest_velocity=getattr(options, "rest_velocity", None),
                           zeno_stick=getattr(options, "zeno_stick", 20),
                           zeno_stop=getattr(options, "zeno_stop", 400))
        with limited():
            started = wallclock.perf_counter()
            problem = ContactProblem.for_run(mechanism, rules)
            builder = TraceBuilder(mechanism.spec, problem.source_numbers, problem.omega, stream)
            stats = self.integrate(problem, options, builder, progress, cancel)
            compile_time = float(stats.get("compile_time", 0.0))
            writing = stream.seconds if stream is not None else 0.0  # the CSV's share, not the solver's
            wall = wallclock.perf_counter() - started - compile_time - writing
        spec = mechanism.spec
        settings = dict(stats.get("settings", {}))
        settings.update(rpm=spec.run.rpm, degrees=spec.run.degrees,
                        impact=sorted({spec.impact_law(c) for c in spec.clearances if c.rigid}),
                        rocker_scale=spec.contact.rocker_scale, start_velocities=spec.initial.velocities)
        if any(not c.rigid for c in spec.clearances):
            settings["contact"] = {c.name: c.contact for c in spec.clearances if not c.rigid}
        statistics = RunStatistics(self.name, int(stats["steps"]), len(builder.events), wall,
                                   tuple(sorted(stats.get("configurations", problem.tables.layers))), settings,
                                   compile_time=compile_time)
        return builder.build(stats["peak"], statistics, stats.get("peak_late"), sort=stats.get("sort", False),
                             peak_overlap=stats.get("peak_overlap"))
