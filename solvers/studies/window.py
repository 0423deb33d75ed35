"""The window of cam angle a run's metrics and spectra cover (see :mod:`vtool.solvers.studies.metrics`)."""

from __future__ import annotations

from vtool.solvers.trace import Trace

REVOLUTION = 360.0


def evaluation_window(trace: Trace) -> tuple[float, float]:
    """The cam angles (deg) the metrics and spectra cover: a run cycle by cycle, its last cycle; a plain run,
    after the first revolution (the whole run if it is no longer than one)."""
    if trace.cycles is not None:
        return trace.cycles.window
    end = float(trace.cam_angle[-1]) if len(trace.cam_angle) else 0.0
    return (REVOLUTION, end) if end > REVOLUTION * (1 + 1e-9) else (0.0, end)


def window_text(trace: Trace) -> str:
    """One line: which cycles the metrics cover, and whether they settled."""
    if trace.cycles is not None:
        return trace.cycles.text()
    start, end = evaluation_window(trace)
    if start == 0.0:
        return (f"evaluated: the whole run (cam angle 0-{end:g} deg), start-up shock included: not a steady "
                "state (set run.cycles or run.steady)")
    return (f"evaluated: after the first revolution (cam angle {start:g}-{end:g} deg), not checked for a "
            "steady state (set run.cycles or run.steady)")
