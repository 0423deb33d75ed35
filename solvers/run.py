"""One call from a valve-train spec to its trace: assemble, pick the back end, simulate.

The CLI, the TUI, the benchmarks and a user's own script all go through
:func:`simulate`, so they share one code path.
"""

from __future__ import annotations

from collections.abc import Callable

from vtool.solvers import backends
from vtool.solvers.model import assemble
from vtool.solvers.spec import MechanismSpec
from vtool.solvers.trace import Trace


def simulate(
    spec: MechanismSpec,
    *,
    every_step: bool = False,
    progress: Callable[[float], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    options: object | None = None,
) -> Trace:
    """Run the preset's back end (``spec.run.backend``) on the assembled mechanism."""
    backend = backends.get(spec.run.backend)()
    mechanism = assemble(spec)
    if options is None:
        options = backend.options_from_run(spec.run, every_step)
    return backend.simulate(
        mechanism,
        options,
        progress=progress if backend.supports_progress else None,
        cancel=cancel if backend.supports_cancel else None,
    )
