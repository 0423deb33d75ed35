"""A seeded monkey: random keys, clicks and pasted garbage across the three screens, no crash.

Each sequence starts a fresh app (the valve-train screen, its default preset
cut to a short run so runs finish inside a sequence) and sends ``EVENTS``
random events: screen keys (run, cancel, save, export, open, help, tabs,
f2-f4), field navigation and typing, clicks anywhere (dialogs included) and
pasted text (long digit runs, ``1e999``, ``nan``, control characters,
paths that cannot be written). The app must never hit an uncaught
exception; an error dialog is the expected answer to bad input.

CI runs one sequence of 30 events (about 11 s; docs/tui.md, "Monkey test",
says where a sequence's time goes); ``VTOOL_MONKEY=1000`` runs 1,000
sequences of 50 events and prints what it found::

    VTOOL_MONKEY=1000 .venv/bin/python -m pytest -q -n 0 -s tests/test_tui_monkey.py

A failure names the seed; ``VTOOL_MONKEY_SEED=<seed> VTOOL_MONKEY=1`` replays it.
"""

from __future__ import annotations

import os
import random
import time
import traceback
from dataclasses import dataclass, field

import pytest
from textual import _wait as textual_wait
from textual import events
from textual.pilot import OutOfBounds

from vtool.app.tui.app import create_app

pytestmark = pytest.mark.asyncio

SEQUENCES = int(os.environ.get("VTOOL_MONKEY", "1"))
EVENTS = int(os.environ.get("VTOOL_MONKEY_EVENTS", "50" if "VTOOL_MONKEY" in os.environ else "30"))
FIRST_SEED = int(os.environ.get("VTOOL_MONKEY_SEED", "0"))
SIZES = ((80, 24), (120, 40), (100, 30))

SCREEN_KEYS = ("ctrl+r", "ctrl+r", "escape", "escape", "ctrl+s", "ctrl+e", "ctrl+o", "ctrl+f", "ctrl+t",
               "f1", "f2", "f3", "f4", "enter", "enter")
MOVE_KEYS = ("tab", "tab", "shift+tab", "up", "down", "left", "right", "home", "end", "pageup",
             "pagedown", "space", "backspace", "delete", "ctrl+u")
TYPED_KEYS = tuple("0123456789.-eE+x,[] ") + ("plus", "minus", "left_square_bracket",
                                             "right_square_bracket")
GARBAGE = ("1" * 400, "9" * 40, "-" + "9" * 320, "1e999", "-1e999", "1e-400", "nan", "inf", "-0", "0",
           "", "   ", "abc", "ünï©ødé ☃", "1,2,,3", "[[x]]", "0.5, 1e308, 1e309", "\x00", "a\nb",
           "\t", "/nonexistent/dir/x.toml", "/proc/version", "gnilka-1b", "boom-tall-building",
           "plate-table3", ".", "..", "x" * 300, "1_000", "0x1F", "1e5", "-5", "3.14159")


@dataclass
class Found:
    crashes: list[str] = field(default_factory=list)
    internal: list[str] = field(default_factory=list)  # error dialogs for non-user errors


def garbage(rng: random.Random) -> str:
    if rng.random() < 0.3:
        return "".join(rng.choice("0123456789.,-+e ") for _ in range(rng.randint(1, 60)))
    return rng.choice(GARBAGE)


async def send(pilot, app, rng: random.Random) -> str:  # type: ignore[no-untyped-def]
    """One random event; returns its description."""
    roll = rng.random()
    if roll < 0.35:
        key = rng.choice(SCREEN_KEYS)
    elif roll < 0.6:
        key = rng.choice(MOVE_KEYS)
    elif roll < 0.75:
        key = rng.choice(TYPED_KEYS)
    elif roll < 0.88:
        text = garbage(rng)
        target = app.focused
        if target is not None:
            target.post_message(events.Paste(text))
        await pilot.pause()
        return f"paste {text[:20]!r} into {type(target).__name__}"
    else:
        width, height = app.size
        x, y = rng.randrange(width), rng.randrange(height - 1)  # the footer's Quit would end the app
        try:
            await pilot.click(offset=(x, y))
        except OutOfBounds:
            pass
        return f"click {x},{y}"
    await pilot.press(key)
    return key


def internal_errors(app, start: int) -> list[str]:  # type: ignore[no-untyped-def]
    return [t for t in app.errors_shown[start:] if t.startswith("the run could not be completed")]


async def one_sequence(seed: int, found: Found, tmp_path) -> None:  # type: ignore[no-untyped-def]
    rng = random.Random(seed)
    app = create_app("gnilka-1d", remember=False, chart_color=False)
    done: list[str] = []
    try:
        async with app.run_test(size=rng.choice(SIZES)) as pilot:
            await pilot.pause()
            app.screen.form.row("run.degrees").editor.value = "40"  # runs finish within a sequence
            await pilot.pause()
            for _ in range(EVENTS):
                done.append(await send(pilot, app, rng))
                if app._exception is not None or not app.is_running:
                    break
            app.workers.cancel_all()
            await pilot.pause()
    except Exception as exc:  # the monkey's one job: record what escaped the app
        where = " | ".join(line.strip().replace("\n", " ") for line in traceback.format_tb(exc.__traceback__)[-4:])
        found.crashes.append(f"seed {seed}: {type(exc).__name__}: {exc} after {done[-5:]} at {where}")
        return
    found.internal += [f"seed {seed}: {t}" for t in internal_errors(app, 0)]


async def test_monkey_finds_no_crash(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    # Textual's pilot waits after every key until the *process* is idle (process CPU time
    # standing still, at most 1 s per wait). A run computing in a worker thread keeps the
    # process busy, so every event sent during a run waited the full second: that was most
    # of a sequence's time. The pilot's idle now means the event loop's thread is idle; the
    # runs still go on in their threads while the monkey keeps pressing (events race runs,
    # as a user's do).
    monkeypatch.setattr(textual_wait, "process_time", time.thread_time)
    # and it looks for idle in 20 ms slices (at least two per key): 5 ms slices, same 1/10
    # busy threshold... cuts a sequence's idle waiting by about half
    monkeypatch.setattr(textual_wait, "SLEEP_GRANULARITY", 0.005)
    monkeypatch.setattr(textual_wait, "SLEEP_IDLE", 0.0005)
    monkeypatch.chdir(tmp_path)  # saves and exports land here
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path))
    found = Found()
    started = time.perf_counter()
    for seed in range(FIRST_SEED, FIRST_SEED + SEQUENCES):
        crashes = len(found.crashes)
        await one_sequence(seed, found, tmp_path)
        if SEQUENCES > 10:  # a long run reports as it goes (pytest -s), a crash at once
            for line in found.crashes[crashes:]:
                print("  ", line[:2000], flush=True)
            print(f"seed {seed}: {len(found.crashes)} crashes so far, "
                  f"{time.perf_counter() - started:.0f} s", flush=True)
    elapsed = time.perf_counter() - started
    print(f"\nTUI monkey: {SEQUENCES} sequences of {EVENTS} events in {elapsed:.0f} s: "
          f"{len(found.crashes)} crashes, {len(found.internal)} internal-error dialogs")
    for line in found.crashes + found.internal:
        print("  ", line[:300])
    assert not found.crashes, "\n".join(found.crashes)


async def test_paging_a_choice_list_before_it_is_laid_out_is_harmless() -> None:
    """Seed 812: ``down`` opened a choice field's list and ``pageup`` reached it before its
    first layout; Textual's OptionList indexed its empty line table (KeyError: 0). The
    reproducer pages the list directly while it has no size; every choice field and the sweep
    metric use ``ChoiceSelect``."""
    from textual.app import App, ComposeResult
    from textual.widgets import Select
    from textual.widgets._select import SelectOverlay

    from vtool.app.tui.form import FieldRow
    from vtool.app.tui.widgets import ChoiceSelect

    class OneChoice(App[None]):
        def compose(self) -> ComposeResult:
            yield ChoiceSelect([("a", "a"), ("b", "b")], value="a", allow_blank=False)

    app = OneChoice()
    async with app.run_test(size=(80, 24)) as pilot:
        overlay = app.query_one(SelectOverlay)
        assert not overlay.scrollable_content_region  # not laid out: Textual's own list raises here
        overlay.highlighted = 0
        overlay.action_page_up()
        overlay.action_page_down()
        await pilot.pause()
    assert app._exception is None
    # the app's choice fields are this widget, not a bare Select
    tui = create_app("gnilka-1a", remember=False, chart_color=False)
    async with tui.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        selects = list(tui.screen.query(Select))
        assert selects and all(isinstance(s, ChoiceSelect) for s in selects)
        assert any(isinstance(s.parent, FieldRow) for s in selects)


async def test_opening_a_name_too_long_for_the_system_shows_the_error_dialog() -> None:
    """Seed 366: a pasted 400-digit name in the open dialog reached Path.is_file, which raises
    ENAMETOOLONG; now it is "no such preset" in the error dialog and the app lives on."""
    from vtool.app.tui.dialogs import ErrorDialog

    app = create_app("gnilka-1d", remember=False, chart_color=False)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        assert await app.open_preset("1" * 400) is False
        await pilot.pause()
        assert isinstance(app.screen, ErrorDialog)
    assert app._exception is None
