"""What an engineer types: fields that replace their value, the Open dialog's path, the sweep tab's
labels, the 120 x 40 layout, a table-cam preset saved from the TUI (issue 37)."""

from __future__ import annotations

from pathlib import Path

import pytest

from vtool.app.tui.app import create_app

pytestmark = pytest.mark.asyncio


def make_app(preset: str = "gnilka-1a", config_dir: Path | None = None):  # type: ignore[no-untyped-def]
    if config_dir is None:
        return create_app(preset, remember=False, chart_color=False)
    return create_app(preset, config_dir=config_dir, chart_color=False)


async def test_typing_into_a_field_reached_by_focus_replaces_its_value() -> None:
    """The first field has the focus at start: typing 10500 made the cam speed 1100010500. A field
    reached by the keyboard (start, tab, a refused run) has its value selected, so typing replaces it."""
    app = make_app()
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        screen = app.screen
        rpm = screen.form.row("run.rpm").editor
        assert app.focused is rpm
        await pilot.press(*"10500")
        await pilot.pause()
        assert rpm.value == "10500"
        await pilot.press("tab", *"900")  # the next field: cam degrees, 850 -> 900
        await pilot.pause()
        assert screen.form.row("run.degrees").editor.value == "900"
        await pilot.press("shift+tab", "end", "backspace", "1")  # moving the cursor edits in place
        await pilot.pause()
        assert rpm.value == "10501"


@pytest.mark.slow
async def test_a_path_typed_in_the_open_dialog_is_what_opens(tmp_path: Path) -> None:
    """The list has the focus when the dialog opens: the typed characters went to it and enter
    chose its highlighted preset (boom-brick-wall). Typing now goes to the path field."""
    from vtool.app.tui.dialogs import OpenDialog

    preset = tmp_path / "mine.toml"
    preset.write_text(Path(__file__).parent.parent.joinpath("presets", "gnilka-1d.toml").read_text())
    app = make_app(config_dir=tmp_path)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+o")
        await pilot.pause()
        assert isinstance(app.screen, OpenDialog)
        await pilot.press(*str(preset), "enter")
        await pilot.pause()
        await pilot.pause()
        assert not app.errors_shown, app.errors_shown
        assert app.screen.source == str(preset.resolve()), app.screen
        # the list still opens a shipped preset by its arrows and enter
        await pilot.press("ctrl+o")
        await pilot.pause()
        await pilot.press("down", "enter")
        await pilot.pause()
        await pilot.pause()
        assert not isinstance(app.screen, OpenDialog) and app.screen.source != str(preset.resolve())


async def _shot_after_run(preset: str, tabs: int) -> tuple[object, str]:
    from vtool.app.tui.screenshots import svg_text

    app = make_app(preset)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        if preset.startswith("gnilka"):
            app.screen.form.row("run.degrees").editor.value = "200"
        await pilot.press("ctrl+r")
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.pause()
        await pilot.press(*["ctrl+t"] * tabs)
        await pilot.pause(0.2)
        return app.screen.results, svg_text(app.export_screenshot(), 120)


@pytest.mark.slow
async def test_at_120x40_with_the_form_the_peak_forces_and_plate_errors_are_in_view() -> None:
    """Beside the 50-column form the valve-train summary's peak-force column and every error of
    the plate's frequency table were cut at the right edge."""
    trace, text = await _shot_after_run("gnilka-1a", 4)  # Summary
    assert "cam speed" in text  # the form is shown
    for clearance, force in zip(trace.spec.clearances, trace.peak_force, strict=True):
        assert any(line.rstrip().endswith(f" {force:.6g}") and f"▕{clearance.name} " in line
                   for line in text.splitlines()), (clearance.name, force)
    run, text = await _shot_after_run("plate-table2", 0)  # Frequencies
    assert "side a (x)" in text  # the form is shown
    for free in run.study.free:
        line = next(line for line in text.splitlines() if f"▕{free.case} " in line)
        for error in free.errors_pct:
            assert f"{error:.3f}" in line, (free.case, error, line)


async def test_the_sweep_tabs_inputs_are_labelled_and_readable_beside_the_form() -> None:
    """The sweep tab's four inputs and its metric had no labels (a placeholder vanishes with a
    value), and at 120 x 40 beside the form the values input showed "9000:12"."""
    from textual.widgets import Input, Label, Select

    from vtool.app.tui.screenshots import svg_text
    from vtool.app.tui.sweep import SweepPane

    app = make_app()
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        app.screen.tabs.active = "tab-sweep"
        await pilot.pause()
        await pilot.pause(0.2)
        pane = app.screen.query_one(SweepPane)
        for editor in [*pane.query(Input), *pane.query(Select)]:
            siblings = list(editor.parent.children)
            before = siblings[siblings.index(editor) - 1]
            assert isinstance(before, Label), editor.id
        text = svg_text(app.export_screenshot(), 120)
        for shown in ("field run.rpm", "values 9000:12000:250", "metric spring_margin", "CSV file sweep.csv"):
            assert shown in text, shown
        assert "fixed " in text


async def test_a_table_cam_preset_saved_from_the_tui_has_its_table_inline(tmp_path: Path, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Saved from the presets folder, the copy kept ``lift_table = "ramped-cam.csv"``, a path the
    copy's own folder does not have (docs/cams.md: a saved preset writes the table inline)."""
    import tomllib

    from vtool.app.tui.dialogs import PathDialog
    from vtool.presets import find_preset, load_preset, valvetrain

    shipped = Path(find_preset("ramped-cam"))
    monkeypatch.chdir(shipped.parent)  # where the relative reference still loads
    app = make_app("ramped-cam", config_dir=tmp_path)
    target = tmp_path / "elsewhere" / "mine.toml"
    target.parent.mkdir()
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        app.screen.form.row("run.rpm").editor.value = "5000"
        await pilot.pause()
        await pilot.press("ctrl+s")
        await pilot.pause()
        assert isinstance(app.screen, PathDialog)
        app.screen.query_one("#path-input").value = str(target)
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen.status_log[-1].startswith(f"saved {target} (comments kept"), app.screen.status_log[-1]
    text = target.read_text()
    cam = tomllib.loads(text)["cam"]
    assert "lift_table" not in cam and len(cam["angles"]) == len(cam["lifts"]) > 10
    assert 'inline copy of lift_table = "ramped-cam.csv"' in text
    assert "# Prescribed coordinates." in text  # the file's own comments stay
    monkeypatch.chdir(tmp_path)
    saved = load_preset(str(target))
    expected = valvetrain.dump(load_preset("ramped-cam"))
    expected["run"]["rpm"] = 5000
    assert valvetrain.dump(saved) == expected


async def test_focusing_the_first_field_while_the_rows_are_refilled_is_harmless() -> None:
    """TUI monkey, seed 274: a preset opened while another screen mounted set the form's fields before
    their rows existed, and focusing the first field raised KeyError from on_mount."""
    from vtool.app.tui.form import Field

    app = make_app("boom-brick-wall")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        screen.form.fields = [Field(("not", "mounted"), "no row yet"), *screen.form.fields]
        screen.focus_first_field()
        await pilot.pause()
        assert app.focused is screen.form.row(screen.form.fields[1].path).editor
    assert app._exception is None
