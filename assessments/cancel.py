"""Co-operative cancellation for long assessments (a TUI escape, or a new run).

A caller passes ``cancel``, a function returning True once the work should
stop; the assessment calls :func:`check` between pieces of work (envelope
members, transient runs, blocks of time steps) and :class:`Cancelled`
unwinds it with nothing half-built.
"""

from __future__ import annotations

from collections.abc import Callable

Cancel = Callable[[], bool]


class Cancelled(Exception):
    """The caller asked the assessment to stop."""


def check(cancel: Cancel | None) -> None:
    """Raise :class:`Cancelled` when ``cancel()`` says so."""
    if cancel is not None and cancel():
        raise Cancelled
