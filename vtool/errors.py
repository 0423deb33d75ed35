"""The one error type for user mistakes.

Every bad input (a preset field, a CLI option, a TUI form field) is reported as
an :class:`InputError` naming the field, the value given, what is allowed and
the unit. The CLI turns it into a one-line message and exit code 2; the TUI
shows the same text beside the field.
"""

from __future__ import annotations

from typing import Any


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
        shown = "missing" if self.value is None else f"{self.value!r}"
        return f"{self.field}: got {shown}, expected {self.expected}{unit}"


class RunError(RuntimeError):
    """A simulation could not be completed (divergence, stalled chattering).

    Raised by back ends; carries a one-line message naming the time and the
    configuration where it happened. Nothing is written when it is raised.
    """
