"""Back-end registry: lowercase names to back-end classes, fed by entry points.

Back ends register in the entry-point group ``vtool.backends`` (see
pyproject.toml). Listing them imports none; :func:`get` loads one.

The contract every back end follows
-----------------------------------
1. A class with a lowercase ``name`` and the ability flags
   ``supports_cancel`` and ``supports_progress``.
2. ``options_from_run(run: RunSpec, every_step: bool) -> Options``: the back
   end's own frozen options dataclass, built from the preset's run settings.
3. ``simulate(mechanism, options=None, progress=None, cancel=None) -> Trace``:
   ``mechanism`` is a :class:`vtool.solvers.model.Mechanism`; ``progress(f)``
   is called with the fraction done (0..1) between chunks when the back end
   supports it; ``cancel()`` is polled between chunks and a true answer stops
   the run.
4. Errors: settings a user can fix (time step beyond the stability limit,
   tolerances out of range) raise :class:`vtool.errors.InputError` before any
   work; a run that cannot be completed (divergence, endless chattering,
   cancellation) raises :class:`vtool.errors.RunError` with a one-line
   message naming the time and configuration. A back end never returns a
   partial trace.
"""

from __future__ import annotations

from importlib.metadata import entry_points
from typing import Any

from vtool.errors import InputError

ENTRY_POINT_GROUP = "vtool.backends"


def available() -> list[str]:
    """Names of the installed back ends (nothing is imported)."""
    return sorted({ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)})


def get(name: str) -> Any:
    """The back-end class registered under ``name``."""
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name == name:
            return ep.load()
    raise InputError("run.backend", name, f"one of the installed back ends: {', '.join(available())}")
