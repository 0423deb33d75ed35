"""Snapshots at fixed terminal sizes: the screen as text (from Textual's SVG screenshot).

Not pixel comparisons (a theme tweak would break those); the assertions say
what an engineer must see at 80 x 24 and what a wide terminal adds.
"""

from __future__ import annotations

import pytest

from vtool.app.tui.app import create_app
from vtool.app.tui.screenshots import svg_text

pytestmark = pytest.mark.asyncio


async def shot(app, pilot, width: int) -> str:  # type: ignore[no-untyped-def]
    await pilot.pause(0.1)
    return svg_text(app.export_screenshot(), width)


async def test_valvetrain_at_80x24_shows_form_units_chart_status_and_keys() -> None:
    app = create_app("gnilka-1d", remember=False, chart_color=False)
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        assert app.focused is screen.form.row("run.rpm").editor  # typing starts at the first field
        screen.form.row("run.degrees").editor.value = "90"
        text = await shot(app, pilot, 80)
        lines = text.splitlines()
        assert len(lines) == 24
        assert lines[0].startswith(" VALVE TRAIN") and "Forces" in lines[0] and "Config" in lines[0]
        assert any("cam speed" in line and "11000" in line and "rev/min" in line for line in lines)
        assert any("*cam degrees" in line and "90" in line and "deg" in line for line in lines)
        await pilot.press("ctrl+r")
        await pilot.pause()
        await app.workers.wait_for_complete()
        text = await shot(app, pilot, 80)
        lines = text.splitlines()
        # below 120 columns a run hides the form: the chart gets the width, the bar is gone
        assert "VALVE TRAIN" not in text and "contact forces (lbf)" in text and "cam angle (deg)" in text
        assert max(len(line) for line in lines) > 75
        assert lines[-2].startswith("done:") and "%" not in lines[-2]
        for key in ("^r Run", "^s Save", "^e CSV", "^f Form", "^t Tab", "^q Quit", "^o Open", "f1 Help",
                    "f2-5 Screen"):
            assert key in lines[-1], key
        await pilot.press("ctrl+f")  # the form comes back
        text = await shot(app, pilot, 80)
        assert "VALVE TRAIN" in text and "cam speed" in text
        # a long status message wraps: nothing is cut
        message = "cannot run: " + "members.pushrod.length: got -1, expected a number > 0 in; " * 2
        screen.set_status(message.strip())
        text = await shot(app, pilot, 80)
        assert " ".join(text.split()).count("expected a number > 0 in") == 2
        # the help screen lists every key, rendered once (Markdown)
        await pilot.press("f1")
        text = await shot(app, pilot, 80)
        assert "ctrl+r run" in text and "escape cancel" in text and "f2 valve train" in text
        assert text.count("Valve-train dynamics") == 1
        await pilot.press("escape")


async def test_valvetrain_at_120x40_keeps_the_form_beside_named_configuration_lanes() -> None:
    app = create_app("gnilka-1d", remember=False, chart_color=False)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        screen = app.screen
        screen.form.row("run.degrees").editor.value = "90"
        await pilot.press("ctrl+r")
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.press("ctrl+t", "ctrl+t")
        text = await shot(app, pilot, 120)
        lines = text.splitlines()
        assert len(lines) == 40
        assert "VALVE TRAIN" in text and "cam speed" in text  # wide enough: the form stays
        assert "configuration" in text
        for c in screen.trace.spec.clearances:  # the y axis names the lanes
            if c.state != "removed":
                assert any(f"{c.name}┤" in line or f"{c.name}└" in line for line in lines), c.name


async def test_wide_terminal_adds_the_summary_beside_the_charts() -> None:
    app = create_app("gnilka-1d", remember=False, chart_color=False)
    async with app.run_test(size=(180, 40)) as pilot:
        await pilot.pause()
        app.screen.form.row("run.degrees").editor.value = "90"
        await pilot.press("ctrl+r")
        await pilot.pause()
        await app.workers.wait_for_complete()
        text = await shot(app, pilot, 180)
        lines = text.splitlines()
        assert len(lines) == 40
        header = next(line for line in lines if "clearance" in line and "separations" in line)
        assert header.index("clearance") > header.index("▕") + 40  # right of the form and the charts
        assert "contact forces (lbf)" in text and "events" in text


async def boom_limits_shot(size: tuple[int, int]) -> tuple[str, object]:
    app = create_app("boom-brick-wall", remember=False, chart_color=False)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+r")
        await pilot.pause()
        await app.workers.wait_for_complete()
        text = await shot(app, pilot, size[0])
        return text, app.screen.results


@pytest.mark.parametrize("size", [(80, 24), (120, 40)])
async def test_boom_limits_show_the_answer_column_without_scrolling(size: tuple[int, int]) -> None:
    """The allowable p+ (the answer) is on screen right after the criterion, in both units."""
    text, results = await boom_limits_shot(size)
    lines = text.splitlines()
    assert len(lines) == size[1]
    header = next(line for line in lines if "criterion" in line and "structure" in line)
    assert "p+ [psi]" in header and "p+ [lb/ft^2]" in header
    assert header.index("p+ [psi]") > header.index("criterion")
    if size[0] >= 120:
        assert "SONIC BOOM" in text  # wide enough: the form stays beside the table
    for r in results.rows:  # every row's answer, in both units, on screen
        row = next(line for line in lines if r.criterion in line and f"{r.pressure:.4g}" in line)
        assert f"{r.pressure_alt:.4g}" in row


async def test_width_class_is_the_widest_breakpoint_not_wider() -> None:
    from vtool.app.tui.app import VtoolApp
    from vtool.app.tui.base import width_class

    breakpoints = VtoolApp.HORIZONTAL_BREAKPOINTS or []
    expected = {0: "-narrow", 80: "-narrow", 119: "-narrow", 120: "-wide", 169: "-wide", 170: "-huge", 400: "-huge"}
    assert {width: width_class(width, breakpoints) for width in expected} == expected
    assert width_class(10, [(20, "-big")]) == ""


@pytest.mark.parametrize("width", [80, 150])
async def test_the_screen_is_composed_with_its_width_class(width: int) -> None:
    """The screen has Textual's width class before its widgets mount (one restyle of the whole screen fewer
    at the start), and the one class Textual gives it, whatever the width; a resize still moves it."""
    from vtool.app.tui.base import DomainScreen

    seen: list[set[str]] = []
    compose = DomainScreen.compose

    def recording(self):  # type: ignore[no-untyped-def]  # noqa: ANN001, ANN202
        seen.append(set(self.classes))
        return compose(self)

    app = create_app("gnilka-1a", remember=False, chart_color=False)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(DomainScreen, "compose", recording)
        async with app.run_test(size=(width, 30)) as pilot:
            await pilot.pause()
            named = {"-narrow", "-wide", "-huge"}
            assert seen and seen[0] & named == app.screen.classes & named == {"-narrow" if width < 120 else "-wide"}
            await pilot.resize_terminal(200, 30)
            await pilot.pause()
            assert app.screen.classes & named == {"-huge"}
