"""The error types for user mistakes, failed runs and warnings.

Every bad input (a preset field, a CLI option, a TUI form field) is reported as
an :class:`InputError` naming the field, the value given, what is allowed and
the unit. The CLI turns it into a one-line message and exit code 2; the TUI
shows the same text beside the field. A value echoed back is cut to
:data:`MAX_SHOWN` characters, so a 5 MB bad array still gives one readable line.

A preset that loads but probably does not mean what it says (a missing
[damping] section, a seat the valve never reaches) is reported with
:class:`PresetWarning` through :func:`warnings.warn`; the CLI prints each as
``warning: ...`` on stderr.
"""

from __future__ import annotations

from typing import Any

#: Longest echo of a bad value in a message (characters of its repr).
MAX_SHOWN = 80


def shown(value: Any, limit: int = MAX_SHOWN) -> str:
    """``repr(value)`` cut to ``limit`` characters, saying how long it was.

    The middle is cut, not the end: a long file path keeps its file name.
    """
    try:
        text = repr(value)
    except (ValueError, RecursionError):  # e.g. an int with more digits than repr allows
        text = f"<{type(value).__name__}>"
    if len(text) <= limit:
        return text
    head = (limit - 3) // 2
    return f"{text[:head]}...{text[len(text) - (limit - 3 - head):]} ({len(text):,} characters)"


def one_line(text: str, limit: int = 300) -> str:
    """A message on one line, at most ``limit`` characters."""
    flat = " ".join(str(text).split())
    return flat if len(flat) <= limit else flat[: limit - 3] + "..."


class InputError(ValueError):
    """A user-supplied value is missing, of the wrong type, or out of range.

    Attributes
    ----------
    field:
        Dotted path of the field, e.g. ``members.pushrod.length``.
    value:
        The offending value (``None`` when missing).
    expected:
        What is allowed, in words, e.g. ``"> 0"`` or ``"one of: newmark, exact"``.
    unit:
        Unit of the field, or ``""`` when dimensionless.
    """

    def __init__(self, field: str, value: Any, expected: str, unit: str = "") -> None:
        self.field = field
        self.value = value
        self.expected = expected
        self.unit = unit
        super().__init__(self.one_line())

    def one_line(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        value = "missing" if self.value is None else shown(self.value)
        field = self.field if len(self.field) <= MAX_SHOWN else f"{self.field[: MAX_SHOWN - 3]}..."
        return one_line(f"{field}: got {value}, expected {self.expected}{unit}", 400)


class RunError(RuntimeError):
    """A simulation could not be completed (divergence, stalled chattering, a failed file write).

    Raised by back ends; carries a one-line message naming the time and the
    configuration where it happened. Nothing is written when it is raised.
    """


class PresetWarning(UserWarning):
    """A preset loads, but a setting probably does not do what its author meant."""


class PresetNote(UserWarning):
    """What the loader assumed or converted (a scan's units, its smoothing): said once, not an error.

    Issued through :func:`warnings.warn`; the CLI prints each as ``note: ...`` on stderr.
    """
