"""Shared Pilot helpers for the TUI tests."""

from __future__ import annotations


async def put(pilot, screen, name: str, text: str) -> None:  # type: ignore[no-untyped-def]
    """Replace a field's text in one edit (what a paste does); validation runs as for typing."""
    screen.form.row(name).editor.value = text
    await pilot.pause()


async def run_and_wait(pilot, app) -> None:  # type: ignore[no-untyped-def]
    await pilot.press("ctrl+r")
    await pilot.pause()
    await app.workers.wait_for_complete()
    await pilot.pause()


async def run_degrees(pilot, app, degrees: str):  # type: ignore[no-untyped-def]
    """On a newly opened app: set the run's degrees, run, wait; returns the screen."""
    await pilot.pause()
    screen = app.screen
    await put(pilot, screen, "run.degrees", degrees)
    await run_and_wait(pilot, app)
    return screen


async def answer_path_dialog(pilot, app, key: str, path: str) -> None:  # type: ignore[no-untyped-def]
    """Press ``key`` (save, export, report), check a path dialog opened, give it ``path``, and return to the
    screen."""
    from vtool.app.tui.dialogs import PathDialog

    screen = app.screen
    await pilot.press(key)
    await pilot.pause()
    assert isinstance(app.screen, PathDialog)
    app.screen.query_one("#path-input").value = path
    await pilot.press("enter")
    await pilot.pause()
    assert app.screen is screen
