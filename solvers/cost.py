"""Cost guard: the steps and memory a valve-train run will need, estimated before it starts.

A run covers ``t_end = degrees / (6 rpm)`` seconds (cam speed ω = 2π rpm / 60).
The work is

* a back end flagged ``fixed_step`` (``newmark``): ``t_end / Δt`` steps
  (plus the short refined stretches after events, not counted);
* any other (``exact``, ``scipy``): about 16 samples per period of the highest
  natural frequency, ``16 t_end ω_max / 2π`` (the exact back end scans at
  1/16 of the shortest period; solve_ivp's steps are of the same order);

and the memory is that of the output rows, ``degrees / output_interval + 1``
(or one per step with ``every_step``), each ``3 (n + n_s) + n_c + 2 + n_q``
values (coordinates with velocities and accelerations, contact forces, time
and configuration, the preset's extra quantities), counted as
:data:`BYTES_PER_VALUE` bytes each (the kernel's buffers, the joined trace,
the CSV table and its text: measured 3.7 GB peak for 900,000 rows of 47
values, which this counts as 2.9 GB), plus the configuration tables of
``6 n²`` floats each, for the configurations a run visits (allocated when first
visited): counted as ``min(2^n_c, TABLES_PER_CLEARANCE (n_c + 1))``.

A CSV file written as the run goes (``vtool solve --csv``) holds the output
rows, or with ``--every-step`` one row per step: ``steps + 1`` rows of
``columns`` values, :data:`CSV_BYTES_PER_VALUE` characters each (measured:
2.72 GB for the 6.04e6 steps of 3600 degrees of 1A at 100 rev/min, 42
values a row, 10.7 characters a value). A streamed every-step run keeps
only the interval rows in memory, so its memory estimate stays small while
its file grows by the step: the file has its own estimate (``file_bytes``) and
its own limit (:data:`MAX_FILE_BYTES`).

:func:`check` refuses a run above its back end's step limit
(:func:`max_steps_for`) or :data:`MAX_BYTES` bytes with one line giving the
estimate and how to proceed (``--max-steps``, fewer degrees, a coarser step
or output interval). At about 1 million Newmark steps per second on the
development machine, :data:`MAX_STEPS` bounds a run at roughly a minute. A
scipy sample costs far more (solve_ivp calls Python for every stage of
every step, and restarts at every event): 0.16 ms per estimated sample on
gnilka-1a with every contact linear at k = 1e10 lbf/in (14.6 s for 9.2e4),
so scipy's limit is :data:`MAX_SCIPY_STEPS`, about the same minute; its
estimate grows with the stiffest linear contact through omega_max (k = 1e13
gives 2.3e7 samples for 720 deg of 1A: refused, where it used to run for
more than 300 s).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from vtool.errors import InputError
from vtool.solvers import backends
from vtool.units import cam_speed

#: Default largest number of steps (or samples) of one run.
MAX_STEPS = 5e7
#: Largest --max-steps a user may ask for.
LARGEST_MAX_STEPS = 1e12
#: ... of a scipy run (module doc: a sample costs about 160 Newmark steps).
MAX_SCIPY_STEPS = 5e5
#: Default largest memory of one run's output (bytes).
MAX_BYTES = 2e9
#: Configuration tables counted per clearance (a run builds those it visits; 1A: 5 of 8).
TABLES_PER_CLEARANCE = 4.0
#: Samples per period of the highest natural frequency (exact, scipy).
SAMPLES_PER_PERIOD = 16.0
BYTES_PER_FLOAT = 8
#: Bytes per output value over the whole run: float copies (8 x 6) and about 20 characters of CSV.
BYTES_PER_VALUE = 8 * 6 + 20
#: Characters per value of a CSV row (``'%.10g'`` and its comma; measured 10.7, see the module doc).
CSV_BYTES_PER_VALUE = 11
#: Default largest CSV file a run writes (bytes).
MAX_FILE_BYTES = 2e9


@dataclass(frozen=True)
class Estimate:
    """What a run will cost: steps (or samples), output rows and bytes."""

    backend: str
    steps: float
    rows: float
    bytes: float
    t_end: float  # s
    file_rows: float = 0.0  # rows of the CSV file written as the run goes (0: none)
    file_bytes: float = 0.0

    def describe(self) -> str:
        text = f"{self.steps:.3g} steps, {self.rows:.3g} output rows, about {self.bytes / 1e6:,.0f} MB"
        if self.file_rows:
            text += f" in memory and {self.file_bytes / 1e6:,.0f} MB of CSV ({self.file_rows:.3g} rows)"
        return text


def estimate(*, backend: str, rpm: float, degrees: float, time_step: float, output_interval: float,
             every_step: bool, omega_max: float, n_coordinates: int, n_sources: int,
             n_clearances: int, n_quantities: int = 0, csv: bool = False, csv_every_step: bool = False) -> Estimate:
    """The cost of one run (see module doc); all inputs in the preset's units. ``every_step``: rows at every
    step in memory; ``csv``: a CSV file is written as the run goes, with a row at every step if
    ``csv_every_step``."""
    omega = cam_speed(rpm)
    t_end = math.radians(degrees) / omega if omega > 0 else math.inf
    if backends.get(backend).fixed_step:
        steps = t_end / time_step if time_step > 0 else math.inf
    else:
        steps = t_end * omega_max / (2.0 * math.pi) * SAMPLES_PER_PERIOD
    rows = steps + 1 if every_step else degrees / output_interval + 1
    columns = 3 * (n_coordinates + n_sources) + n_clearances + 2 + n_quantities
    tables = min(2.0**n_clearances, TABLES_PER_CLEARANCE * (n_clearances + 1)) * 6 * n_coordinates**2
    size = rows * columns * BYTES_PER_VALUE + tables * BYTES_PER_FLOAT
    file_rows = (steps + 1 if csv_every_step else degrees / output_interval + 1) if csv else 0.0
    file_bytes = file_rows * (columns + 2) * CSV_BYTES_PER_VALUE  # (+ the configuration's two text cells)
    return Estimate(backend, steps, rows, size, t_end, file_rows, file_bytes)


class CostError(InputError):
    """A run that would take more steps or memory than allowed; says how to proceed."""

    def __init__(self, cost: Estimate, max_steps: float, max_bytes: float, what: str) -> None:
        self.cost = cost
        self.max_steps = max_steps
        self.max_bytes = max_bytes
        self.what = what
        # the field a form marks: the step for a run shorter than one step, else the length of run
        super().__init__("run.time_step" if what == "short" else "run.degrees", cost.describe(), what)

    def one_line(self) -> str:
        c = self.cost
        if self.what == "short":
            return (f"run too short: {c.t_end:.3g} s of motion is less than one time step ({c.backend}); "
                    "to proceed: more --degrees or a smaller --dt")
        if self.what == "steps":
            allow = (f", or --max-steps {math.ceil(c.steps):d}" if c.steps <= LARGEST_MAX_STEPS
                     else f" (more than the largest --max-steps, {LARGEST_MAX_STEPS:.0e})")
            limit = (f"more than the limit of {self.max_steps:.3g} steps; to proceed: fewer --degrees, "
                     f"a higher --rpm, a larger --dt (fixed-step back ends){allow}")
        elif self.what == "file":
            limit = (f"more than the limit of {MAX_FILE_BYTES / 1e9:g} GB of CSV; to proceed: fewer --degrees, "
                     "a larger --dt, or no --every-step (a row every output interval)")
        else:
            limit = (f"more than the limit of {self.max_bytes / 1e9:g} GB of output; to proceed: fewer "
                     "--degrees, a larger run.output_interval, or no --every-step")
        return f"run too large: {c.describe()} ({c.backend}, {c.t_end:.3g} s of motion), {limit}"


def max_steps_for(backend: str) -> float:
    """The default step limit of a back end (module doc)."""
    limit = backends.get(backend).max_steps  # a back end may set its own (the scipy back end's steps cost more)
    return MAX_STEPS if limit is None else limit


def check(cost: Estimate, max_steps: float | None = None, max_bytes: float | None = None) -> Estimate:
    """Refuse (:class:`CostError`, exit 2) a run above the limits; returns ``cost``."""
    max_steps = max_steps_for(cost.backend) if max_steps is None else max_steps
    max_bytes = MAX_BYTES if max_bytes is None else max_bytes
    if not cost.steps >= 1.0:
        raise CostError(cost, max_steps, max_bytes, "short")
    if not cost.steps <= max_steps:
        raise CostError(cost, max_steps, max_bytes, "steps")
    if not cost.bytes <= max_bytes:
        raise CostError(cost, max_steps, max_bytes, "memory")
    if not cost.file_bytes <= MAX_FILE_BYTES:
        raise CostError(cost, max_steps, max_bytes, "file")
    return cost
