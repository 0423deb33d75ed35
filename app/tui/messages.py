"""Typed messages of the TUI, named in the past tense (what happened).

Workers post these to the screen that started them; ``RunProgressed``
collapses so a flood of progress updates shows only the latest.
"""

from __future__ import annotations

from typing import Any

from textual.message import Message


class RunProgressed(Message):
    """A run reached ``fraction`` (0..1) of its work."""

    def __init__(self, run_id: int, fraction: float) -> None:
        super().__init__()
        self.run_id = run_id
        self.fraction = fraction

    def can_replace(self, message: Message) -> bool:
        return isinstance(message, RunProgressed) and message.run_id == self.run_id


class CompileAnnounced(Message):
    """A run must compile the solver first (a new install's first run): the line the CLI prints."""

    def __init__(self, run_id: int, text: str) -> None:
        super().__init__()
        self.run_id = run_id
        self.text = text


class SimulationFinished(Message):
    """A valve-train run returned its trace."""

    def __init__(self, run_id: int, spec: Any, trace: Any) -> None:
        super().__init__()
        self.run_id = run_id
        self.spec = spec
        self.trace = trace


class AssessmentFinished(Message):
    """A sonic-boom assessment returned (assessment and the DAF curves drawn)."""

    def __init__(self, run_id: int, spec: Any, assessment: Any, daf: dict[str, Any]) -> None:
        super().__init__()
        self.run_id = run_id
        self.spec = spec
        self.assessment = assessment
        self.daf = daf


class PlateStudyFinished(Message):
    """A plate study (and the chosen case's transient run) returned."""

    def __init__(self, run_id: int, spec: Any, result: Any) -> None:
        super().__init__()
        self.run_id = run_id
        self.spec = spec
        self.result = result


class FieldEdited(Message):
    """A form field changed (validation runs on every edit)."""

    def __init__(self, path: tuple[str | int, ...]) -> None:
        super().__init__()
        self.path = path
