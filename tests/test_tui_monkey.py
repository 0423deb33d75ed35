"""A seeded monkey: random keys, clicks and pasted garbage across the three screens and the sweep tab.

Each sequence starts a fresh app on one of four places, by seed: the sweep
tab with a pool of ``SWEEP_WORKERS`` processes, the valve-train screen (its
preset cut to a short run so runs finish inside a sequence), the sonic-boom
screen and the plate screen. It sends ``EVENTS`` random events: screen keys
(run, cancel, save, export, open, help, tabs, f2-f4), field navigation and
typing, clicks anywhere (dialogs included), pasted text (long digit runs,
``1e999``, ``nan``, control characters, paths that cannot be written) and
sweep actions (show the tab, run, cancel, export). The monkey fails when

* the app hits an uncaught exception, or
* a status line (a screen's or the sweep tab's) or an error dialog shows an
  error the sequence did not ask for. Bad input is answered by its one-line
  message (a field, the value, the allowed range) and a failed run by its
  reason: those are asked for. An error that is neither, the app words as
  "... could not be completed: ..." (a run or a sweep failing for a reason of
  the program's, like the pool error "bad value(s) in fds_to_keep"), and a
  form the loader failed on with something other than its one-line message
  shows "invalid form: ...": those fail the monkey (:func:`unexpected`).

CI runs one sequence of 30 events (seed 0: the sweep tab; about 15 s);
``VTOOL_MONKEY=300`` runs 300 sequences of 50 events, the four starts in
turn, and prints what it found::

    VTOOL_MONKEY=300 .venv/bin/python -m pytest -q -n 0 -s tests/test_tui_monkey.py

A failure names the seed; ``VTOOL_MONKEY_SEED=<seed> VTOOL_MONKEY=1`` replays it
(``VTOOL_MONKEY_SEED=N VTOOL_MONKEY=K`` runs seeds N to N+K-1, so a long run can
be split over processes).
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
from textual.pilot import OutOfBounds, WaitForScreenTimeout

from vtool.app.tui.app import create_app

pytestmark = pytest.mark.asyncio

SEQUENCES = int(os.environ.get("VTOOL_MONKEY", "1"))
EVENTS = int(os.environ.get("VTOOL_MONKEY_EVENTS", "50" if "VTOOL_MONKEY" in os.environ else "30"))
FIRST_SEED = int(os.environ.get("VTOOL_MONKEY_SEED", "0"))
SIZES = ((80, 24), (120, 40), (100, 30))
STARTS = ("sweep", "valvetrain", "boom", "plate")  # by seed, in turn
PRESETS = {"sweep": "gnilka-1d", "valvetrain": "gnilka-1d", "boom": "boom-brick-wall", "plate": "plate-table2"}
SWEEP_WORKERS = 3  # a process pool, whatever the machine's core count

SCREEN_KEYS = ("ctrl+r", "ctrl+r", "escape", "escape", "ctrl+s", "ctrl+e", "ctrl+o", "ctrl+f", "ctrl+t",
               "f1", "f2", "f3", "f4", "enter", "enter")
MOVE_KEYS = ("tab", "tab", "shift+tab", "up", "down", "left", "right", "home", "end", "pageup",
             "pagedown", "space", "backspace", "delete", "ctrl+u")
TYPED_KEYS = tuple("0123456789.-eE+x,[] ") + ("plus", "minus", "left_square_bracket",
                                             "right_square_bracket")
GARBAGE = ("1" * 400, "9" * 40, "-" + "9" * 320, "1e999", "-1e999", "1e-400", "nan", "inf", "-0", "0",
           "", "   ", "abc", "ünï©ødé ☃", "1,2,,3", "[[x]]", "0.5, 1e308, 1e309", "\x00", "a\nb",
           "\t", "/nonexistent/dir/x.toml", "/proc/version", "gnilka-1b", "boom-tall-building",
           "plate-table3", ".", "..", "x" * 300, "1_000", "0x1F", "1e5", "-5", "3.14159",
           "9000:9500:250", "1:1e9:1", "run.degrees=30", "damping.factor=0.5,2", "run.rpm=", "x.y.z=1")
SWEEP_ACTIONS = ("#sweep-run", "#sweep-run", "#sweep-cancel", "#sweep-export", "tab")

#: what the app shows for an error that no input asked for (see the module doc)
UNEXPECTED = ("could not be completed", "invalid form:")


def unexpected(text: str) -> bool:
    """True for a status or dialog message of an error that is not the answer to bad input or a failed run."""
    return any(marker in text for marker in UNEXPECTED)


SETTLE = 600.0  # s a starved app may take to work off its messages before it counts as hung


@dataclass
class Found:
    crashes: list[str] = field(default_factory=list)
    unexpected: list[str] = field(default_factory=list)  # status lines and dialogs no input asked for
    sweeps: int = 0  # sweeps that ran to their end or were stopped (the pool did start)
    slow: list[str] = field(default_factory=list)  # events the app took over Pilot's 30 s to work off


async def settles(app, timeout: float = SETTLE) -> bool:  # type: ignore[no-untyped-def]
    """True when the app and every widget of its screen work off the messages queued now within ``timeout``.

    Pilot gives up after 30 s (WaitForScreenTimeout). On a machine shared by many
    processes (load average 100 on 2 cores: a process gets a few per cent of a core)
    a form refill takes that long; a hung app never gets there. This is Pilot's
    own wait with a longer timeout."""
    import asyncio

    pending = [0]
    drained = asyncio.Event()

    def one_done() -> None:
        pending[0] -= 1
        if pending[0] == 0:
            drained.set()

    for node in [app, *app.screen.walk_children(with_self=True)]:
        if node.call_later(one_done):
            pending[0] += 1
    if not pending[0]:
        return True
    try:
        await asyncio.wait_for(drained.wait(), timeout)
    except TimeoutError:
        return False
    return True


def garbage(rng: random.Random) -> str:
    if rng.random() < 0.3:
        return "".join(rng.choice("0123456789.,-+e ") for _ in range(rng.randint(1, 60)))
    return rng.choice(GARBAGE)


def sweep_pane(app):  # type: ignore[no-untyped-def]
    """The valve-train screen's sweep pane when that screen is on top (no dialog), else None."""
    from vtool.app.tui.sweep import SweepPane
    from vtool.app.tui.valvetrain import ValveTrainScreen

    if not isinstance(app.screen, ValveTrainScreen):
        return None
    return app.screen.query_one(SweepPane)


async def show_sweep_tab(pilot, app):  # type: ignore[no-untyped-def]
    """Show the sweep tab; at its first showing, a pool of SWEEP_WORKERS and short runs."""
    from textual.widgets import Input

    pane = sweep_pane(app)
    if pane is None:
        return None
    app.screen.tabs.active = "tab-sweep"
    await pilot.pause()
    if pane.sweep_workers != SWEEP_WORKERS:
        await pilot.pause()
        pane.sweep_workers = SWEEP_WORKERS
        pane.query_one("#sweep-fixed", Input).value = "run.degrees=40"
    return pane


async def send(pilot, app, rng: random.Random) -> str:  # type: ignore[no-untyped-def]
    """One random event; returns its description."""
    roll = rng.random()
    if roll < 0.33:
        key = rng.choice(SCREEN_KEYS)
    elif roll < 0.56:
        key = rng.choice(MOVE_KEYS)
    elif roll < 0.7:
        key = rng.choice(TYPED_KEYS)
    elif roll < 0.82:
        text = garbage(rng)
        target = app.focused
        if target is not None:
            target.post_message(events.Paste(text))
        await pilot.pause()
        return f"paste {text[:20]!r} into {type(target).__name__}"
    elif roll < 0.9:
        action = rng.choice(SWEEP_ACTIONS)
        pane = await show_sweep_tab(pilot, app)
        if pane is None:
            return f"sweep {action} (no sweep tab on top)"
        if action == "tab":
            pane.query_one("#sweep-field").focus()
            await pilot.pause()
        else:
            try:
                await pilot.click(action)
            except OutOfBounds:
                pass
        return f"sweep {action}"
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


class Messages:
    """Every status and dialog message of a sequence, read as it grows (screens and panes as they appear)."""

    def __init__(self, app) -> None:  # type: ignore[no-untyped-def]
        self.app = app
        self.logs: dict[int, tuple[str, list[str]]] = {}
        self.read: dict[int, int] = {}

    def new(self) -> list[str]:
        from vtool.app.tui.base import DomainScreen
        from vtool.app.tui.sweep import SweepPane

        for screen in self.app.screen_stack:
            if isinstance(screen, DomainScreen):
                self.logs.setdefault(id(screen), (screen.MODE, screen.status_log))
                for pane in screen.query(SweepPane):
                    self.logs.setdefault(id(pane), ("sweep tab", pane.status_log))
        self.logs.setdefault(id(self.app), ("dialog", self.app.errors_shown))
        fresh = []
        for key, (where, log) in self.logs.items():
            fresh += [f"{where}: {text}" for text in log[self.read.get(key, 0):]]
            self.read[key] = len(log)
        return fresh


async def one_sequence(seed: int, found: Found, tmp_path) -> None:  # type: ignore[no-untyped-def]
    rng = random.Random(seed)
    start = STARTS[seed % len(STARTS)]
    app = create_app(PRESETS[start], remember=False, chart_color=False)
    done: list[str] = []
    inside: list[BaseException] = []  # what the sequence itself raised
    try:
        async with app.run_test(size=rng.choice(SIZES)) as pilot:
            try:
                await drive(pilot, app, rng, start, seed, found, done)
            except Exception as exc:
                inside.append(exc)
                raise
    except Exception as exc:  # the monkey's one job: record what escaped the app
        # the sequence's own failure (a Pilot timeout) first: Textual's run_test re-raises, on
        # leaving, the first error of the closing app instead (seed 219's ScreenStackError)
        first = inside[0] if inside else exc
        where = " | ".join(line.strip().replace("\n", " ") for line in traceback.format_tb(first.__traceback__)[-4:])
        then = f" (then, closing: {type(exc).__name__}: {exc})" if exc is not first else ""
        found.crashes.append(f"seed {seed}: {type(first).__name__}: {first}{then} after {done[-5:]} at {where}")


async def drive(pilot, app, rng: random.Random, start: str, seed: int, found: Found,  # type: ignore[no-untyped-def]
                done: list[str]) -> None:
    """One sequence's events on a running app (``done`` names them as they are sent)."""
    await pilot.pause()
    if start in ("valvetrain", "sweep"):
        app.screen.form.row("run.degrees").editor.value = "40"  # runs finish within a sequence
        await pilot.pause()
    if start == "sweep":
        await show_sweep_tab(pilot, app)
        await pilot.click("#sweep-run")
        done.append("sweep #sweep-run")
    messages = Messages(app)
    for _ in range(EVENTS):
        try:
            done.append(await send(pilot, app, rng))
        except WaitForScreenTimeout:
            if not await settles(app):
                raise
            found.slow.append(f"seed {seed}: after {done[-5:]}")
            done.append("(slow: the app worked off the event after Pilot's 30 s)")
        found.unexpected += [f"seed {seed}: {text} after {done[-5:]}" for text in messages.new()
                             if unexpected(text)]
        if app._exception is not None or not app.is_running:
            break
    for _ in range(200):  # a sweep still going is let finish (a few seconds), then stopped
        pane = sweep_pane(app)
        if pane is None or not pane.running:
            break
        await pilot.pause(0.05)
    app.workers.cancel_all()
    await pilot.pause()
    found.unexpected += [f"seed {seed}: {text} at the end" for text in messages.new() if unexpected(text)]
    found.sweeps += sum(text.startswith(("finished: ", "stopped: ")) for where, log in messages.logs.values()
                        if where == "sweep tab" for text in log)


def quick_pilot(monkeypatch, tmp_path) -> None:  # type: ignore[no-untyped-def]
    """The monkey's pilot settings, its folder and config (see the comments)."""
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


@pytest.mark.slow
async def test_monkey_finds_no_crash_and_no_unexpected_error(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    quick_pilot(monkeypatch, tmp_path)
    found = Found()
    started = time.perf_counter()
    for seed in range(FIRST_SEED, FIRST_SEED + SEQUENCES):
        before = len(found.crashes) + len(found.unexpected)
        await one_sequence(seed, found, tmp_path)
        if SEQUENCES > 10:  # a long run reports as it goes (pytest -s), a finding at once
            for line in (found.crashes + found.unexpected)[before:]:
                print("  ", line[:2000], flush=True)
            print(f"seed {seed}: {len(found.crashes)} crashes, {len(found.unexpected)} unexpected errors, "
                  f"{found.sweeps} sweeps, {len(found.slow)} slow events so far, "
                  f"{time.perf_counter() - started:.0f} s", flush=True)
    elapsed = time.perf_counter() - started
    print(f"\nTUI monkey: {SEQUENCES} sequences of {EVENTS} events in {elapsed:.0f} s: "
          f"{len(found.crashes)} crashes, {len(found.unexpected)} unexpected errors, {found.sweeps} sweeps "
          f"ran (pool of {SWEEP_WORKERS} workers), {len(found.slow)} events slower than Pilot's 30 s "
          "(the app worked them off later: a starved machine, not a hang)")
    for line in found.crashes + found.unexpected:
        print("  ", line[:300])
    assert not found.crashes, "\n".join(found.crashes)
    assert not found.unexpected, "\n".join(found.unexpected)


@pytest.mark.slow
async def test_the_monkey_fails_on_an_error_no_input_asked_for(tmp_path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """The sweep tab's pool failing to start (issue 37: "bad value(s) in fds_to_keep" on every Run, shown
    in the status line, no exception: the old monkey saw nothing) fails the monkey's sweep sequence."""
    import vtool.solvers.studies.sweep as sweep

    def pool_fails(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise ValueError("bad value(s) in fds_to_keep")  # what _posixsubprocess raised

    quick_pilot(monkeypatch, tmp_path)
    monkeypatch.setattr(sweep, "make_runner", pool_fails)
    found = Found()
    await one_sequence(0, found, tmp_path)  # seed 0 starts on the sweep tab and runs it
    assert not found.crashes, found.crashes
    assert found.unexpected and all("fds_to_keep" in line or "could not be completed" in line
                                    for line in found.unexpected), found.unexpected
    assert unexpected("failed: the run could not be completed: singular matrix")
    assert not unexpected("cannot run: members.pushrod.length: got -5, expected > 0 in")
    assert not unexpected("error: --set run.rpm: got '5000:4000:250', expected a step with the sign of stop - start (-)")


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
