"""The app closing while a screen is still working (the monkey's seeds 219 and 555, issue 37).

On a starved machine (load average 40-110 on 2 cores) the monkey's Pilot gave up waiting
(30 s) while the app was still busy, and the app was shut down under it:

* seed 219: a preset was being opened (a valve-train screen mounting, about a minute of
  form refill at that load) when Pilot timed out on the next key, ``up``; the app shut
  down and then handled that key with its screens already gone: Textual's
  ``ScreenStackError: No screens on stack``, which replaced the real finding (a slow event);
* seed 555: ``f3`` mounted the sonic-boom screen, whose ``on_mount`` fills the form
  (``await``) and then clears the result panes; the app shut down during the refill, the
  panes were removed, and ``query_one("#limits")`` raised ``NoMatches``.

The same happens outside tests: ``ctrl+q`` while a screen is mounting or a preset loading.
The reproducers below make the app slow in the same places (a key waiting behind a busy
app; a form refill that takes 0.3 s) and close it in the middle: both raised before the
fix; the app now drops input that arrives while it closes, and a screen's handlers stop
after an ``await`` when the app is no longer running.
"""

from __future__ import annotations

import asyncio

import pytest
from textual import events

from vtool.app.tui.app import create_app
from vtool.app.tui.form import ParamForm

pytestmark = pytest.mark.asyncio

DELAY = 0.3  # s: what a form refill or a mount took at the monkey's load, scaled down


class PilotGaveUp(Exception):
    """What the monkey's Pilot raised: the app did not settle in time."""


async def test_a_key_left_waiting_when_the_app_closes_is_dropped() -> None:
    """Seed 219: the original failure is reported, not Textual's ScreenStackError from the key
    the closing app still handled."""
    app = create_app("boom-brick-wall", remember=False, chart_color=False)
    with pytest.raises(PilotGaveUp):
        async with app.run_test(size=(100, 30)) as pilot:
            await pilot.pause()

            async def busy() -> None:  # the app's loop busy (opening a preset on a starved machine)
                await asyncio.sleep(DELAY)

            app.call_next(busy)
            app.post_message(events.Key("up", None))  # the key Pilot sent and stopped waiting on
            app.post_message(events.Click(None, 5, 5, 0, 0, 1, False, False, False))  # and a click
            raise PilotGaveUp
    assert app._exception is None


@pytest.mark.parametrize(("start", "mode", "preset"), [
    ("plate-table2", "boom", None),  # seed 555: f3 mounts the sonic-boom screen
    ("boom-brick-wall", "plate", "plate-table2"),  # open a preset of a screen not yet shown
    ("boom-brick-wall", "boom", "boom-tall-building"),  # open a preset into the screen shown
    ("gnilka-1d", "valvetrain", "gnilka-1a"),  # the valve-train screen's form and sweep tab
])
async def test_a_screen_filling_its_form_when_the_app_closes_stops_quietly(
        monkeypatch, start: str, mode: str, preset: str | None) -> None:  # type: ignore[no-untyped-def]
    """Seed 555: the app closes while a screen awaits its form refill; the screen's handler then
    finds its panes removed. It must return without an error (the app's exception stays None)."""
    refill = ParamForm.set_fields

    async def slow_refill(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        await asyncio.sleep(DELAY)
        await refill(self, *args, **kwargs)

    app = create_app(start, remember=False, chart_color=False)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        monkeypatch.setattr(ParamForm, "set_fields", slow_refill)
        if preset is None:
            app.call_later(app.switch_mode, mode)
        else:
            app.call_later(app.open_preset, preset)
        await asyncio.sleep(DELAY / 3)  # the screen is now inside its refill
    assert app._exception is None

