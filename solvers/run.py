"""One call from a valve-train spec to its trace: assemble, pick the back end, simulate.

The CLI, the TUI, the benchmarks and a user's own script all go through
:func:`simulate`, so they share one code path. Before the back end starts,
the run's cost is estimated and refused above the limits
(:mod:`vtool.solvers.cost`), and a seat the valve never reaches is a
:class:`vtool.errors.PresetWarning` (:mod:`vtool.solvers.model.preflight`). A
numerical failure inside the run (a singular matrix, an overflow, a
non-finite result) is a :class:`vtool.errors.RunError` naming what failed.
"""

from __future__ import annotations

import dataclasses
import threading
import warnings
from collections import OrderedDict
from collections.abc import Callable

import numpy as np

from vtool.errors import PresetWarning, RunError
from vtool.solvers import backends, cost
from vtool.solvers.model.mechanism import Mechanism, assemble
from vtool.solvers.model.preflight import run_warnings
from vtool.solvers.model.spec import MechanismSpec, RunSpec
from vtool.solvers.studies.steady import is_cyclic, run_degrees, simulate_cycles
from vtool.solvers.trace import CsvStream, Trace
from vtool.threads import limited

CANONICAL_RUN = RunSpec(rpm=1.0, degrees=1.0, time_step=1.0)  # the run settings of a kept mechanism's key

#: Numerical failures turned into a RunError (the input is valid but the numbers are not).
NUMERICAL_FAILURES = (np.linalg.LinAlgError, FloatingPointError, ZeroDivisionError, OverflowError)


def run_cost(mechanism: Mechanism, every_step: bool = False, csv: bool = False,
             csv_every_step: bool = False) -> cost.Estimate:
    """The estimated steps, memory and CSV size of the spec's run on this mechanism (:func:`cost.estimate`)."""
    spec = mechanism.spec
    r = spec.run
    omega_max = mechanism.highest_frequency
    n_sources = 1 + (spec.seat is not None)
    return cost.estimate(backend=r.backend, rpm=r.rpm, degrees=run_degrees(spec), time_step=r.time_step,
                         output_interval=r.output_interval, every_step=every_step, omega_max=omega_max,
                         n_coordinates=spec.n_coordinates, n_sources=n_sources,
                         n_clearances=len(spec.clearances), n_quantities=len(r.quantities), csv=csv,
                         csv_every_step=csv_every_step)


#: Assembled mechanisms kept per thread (the last few specs, run settings aside): a second run of
#: the same mechanism (another speed, step or back end; the TUI's reruns) reuses its layers and
#: built configurations. Per thread, because a mechanism's tables hold the step's effective
#: inverses (ConfigurationTables.use_step), which two threads must not share.
ASSEMBLED_KEPT = 4
_kept = threading.local()
#: What a kept mechanism is found by: the spec's compared fields but its run settings and title (a speed
#: override names the speed in the title).
_KEY_FIELDS = tuple(f.name for f in dataclasses.fields(MechanismSpec) if f.compare and f.name not in ("run", "title"))


class _Key:
    """A spec's fields but its run settings, hashed once (the kept mechanisms' ordered dict hashes its
    key at each lookup and move, and a spec's hash goes through every member and clearance: the lookup
    of a kept mechanism took 45 µs, now 17, by timeit)."""

    __slots__ = ("fields", "hash")

    def __init__(self, spec: MechanismSpec) -> None:
        self.fields = tuple([getattr(spec, name) for name in _KEY_FIELDS])
        self.hash = hash(self.fields)

    def __hash__(self) -> int:
        return self.hash

    def __eq__(self, other: object) -> bool:
        return isinstance(other, _Key) and self.hash == other.hash and self.fields == other.fields


def _assemble(spec: MechanismSpec) -> Mechanism:
    kept: OrderedDict = _kept.__dict__.setdefault("mechanisms", OrderedDict())
    try:
        key: _Key | None = _Key(spec)
        base = kept.get(key)
    except TypeError:  # an unhashable spec (built by hand with lists): assemble it afresh
        key, base = None, None
    if base is None:
        try:
            with limited():  # (the runs' BLAS setting for the assembly and its modes too)
                base = assemble(dataclasses.replace(spec, run=CANONICAL_RUN))
                base.highest_frequency  # noqa: B018 (computed once: every run of the mechanism shares it)
        except NUMERICAL_FAILURES as exc:
            raise RunError(f"assembling the mechanism failed ({type(exc).__name__}: {str(exc)[:80]}); "
                           "check the members' sections, moduli and masses") from None
        if key is not None:
            kept[key] = base
            while len(kept) > ASSEMBLED_KEPT:
                kept.popitem(last=False)
    else:
        kept.move_to_end(key)
    return base.for_spec(spec)


def _check_finite(trace: Trace) -> Trace:
    for name in ("q", "qd", "qdd", "contact_force"):
        values = getattr(trace, name)
        if np.isfinite(values).all():
            continue
        bad = ~np.isfinite(values)
        if bad.any():
            row = int(np.argwhere(bad)[0][0])
            raise RunError(f"the run diverged: non-finite {name} at t = {trace.time[row]:.6g} s "
                           f"(cam angle {trace.cam_angle[row]:.4g} deg); likely too large a time step "
                           "or stiffnesses and masses of very different size")
    return trace


def simulate(
    spec: MechanismSpec,
    *,
    every_step: bool = False,
    progress: Callable[[float], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    options: object | None = None,
    max_steps: float | None = None,
    max_bytes: float | None = None,
    stream: CsvStream | None = None,
    before_run: Callable[[], object] | None = None,
) -> Trace:
    """Run the preset's back end (``spec.run.backend``) on the assembled mechanism.

    ``max_steps`` and ``max_bytes`` override the cost limits
    (:data:`vtool.solvers.cost.MAX_STEPS`, :data:`vtool.solvers.cost.MAX_BYTES`).
    A spec with ``run.cycles`` or ``run.steady`` runs cycle by cycle
    (:mod:`vtool.solvers.studies.steady`; ``options`` are then the run's own).
    With a ``stream`` the rows are written to its CSV as the run goes; a
    thinning stream keeps the memory of an every-step run to that of a run at
    the output interval (the memory limit counts it so). ``before_run()`` is
    called once every input check has passed (the cost limits, the back end's
    settings), just before the run: the CLI prints its compile notice there,
    so that bad input stays one line.
    """
    backend = backends.get(spec.run.backend)()
    mechanism = _assemble(spec)
    in_memory_every_step = every_step and not (stream is not None and stream.thin)
    cost.check(run_cost(mechanism, in_memory_every_step, csv=stream is not None, csv_every_step=every_step),
               max_steps, max_bytes)
    for message in run_warnings(mechanism):
        warnings.warn(PresetWarning(message), stacklevel=2)
    if options is None:
        options = backend.options_from_run(spec.run, every_step)
    if before_run is not None:
        backend.check(mechanism, options)  # (checked again in backend.simulate, for its direct callers)
        before_run()
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            if is_cyclic(spec):  # cycle by cycle: the rows go to the CSV when the run has ended
                trace = simulate_cycles(backend, mechanism, every_step=every_step, progress=progress,
                                        cancel=cancel)
                if stream is not None:
                    stream.write(trace)
            else:
                trace = backend.simulate(
                    mechanism,
                    options,
                    progress=progress if backend.supports_progress else None,
                    cancel=cancel if backend.supports_cancel else None,
                    stream=stream,
                )
    except NUMERICAL_FAILURES as exc:
        raise RunError(f"{spec.run.backend} run failed ({type(exc).__name__}: {str(exc)[:80]}); likely "
                       "input: the time step, or stiffnesses and masses of very different size") from None
    trace = _check_finite(trace)
    sign = trace.force_sign_warning()
    if sign is not None:
        warnings.warn(PresetWarning(sign), stacklevel=2)
    return trace
