"""The screens' *save report* action (ctrl+g): the file ``vtool report`` writes, from the last run.

Each screen that has one binds ctrl+g to an action that calls :func:`save_report`
with a function making the report's content from its last results
(:mod:`vtool.presets.report`); this asks for the path (.pdf or .html) and
writes it atomically with :func:`vtool.app.report.write_report`.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from textual.binding import Binding

#: the binding each screen with a report adds (hidden from the footer; listed in the help and docs/tui.md)
REPORT_BINDING = Binding("ctrl+g", "save_report", "Report", show=False)


def save_report(screen: Any, make: Callable[[], Any] | None) -> None:
    """Ask where, then write ``make()``'s report; ``make`` None (no finished run): say so instead."""
    if make is None or screen.running:
        screen.notify("run first (ctrl+r): a report needs a finished run", severity="warning")
        return
    from vtool.app.tui.base import path_problem
    from vtool.app.tui.dialogs import PathDialog

    def save(path: str | None) -> None:
        if not path:
            return
        from vtool.app.report import write_report

        try:
            write_report(make(), path, "report")
        except (OSError, ValueError) as exc:  # ValueError: InputError (suffix, folder), a NUL in the path
            screen.app.report_error("Report failed", path_problem(exc, path))
            return
        screen.set_status(f"wrote {path}")
        screen.notify(f"wrote {path}")

    screen.app.push_screen(PathDialog("Save report (.pdf or .html) to", f"{Path(screen.source).stem}-report.pdf"),
                           save)
