"""Pilot tests of the valve-train screen: form -> worker -> charts, against the library.

Every expected value comes from calling the library with the same inputs
(the TUI holds no physics); runs are shortened (degrees) where the point is
the wiring, not the response.
"""

from __future__ import annotations

import asyncio
import re
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from click.testing import CliRunner
from textual import events

from tests.tui_helpers import answer_path_dialog, put, run_and_wait, run_degrees
from vtool.app import valvetrain_charts as charts
from vtool.app.cli.main import cli
from vtool.app.plots import shape_chart
from vtool.app.tui.app import create_app
from vtool.app.tui.dialogs import ErrorDialog, PathDialog
from vtool.app.tui.messages import RunProgressed, SimulationFinished
from vtool.app.tui.valvetrain import ValveTrainScreen
from vtool.errors import InputError, RunError
from vtool.presets import load_preset, valvetrain
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.model.shapes import deformed_members
from vtool.solvers.run import simulate

pytestmark = pytest.mark.asyncio


def make_app(preset: str | None = "gnilka-1c", tmp_path=None):  # type: ignore[no-untyped-def]
    if tmp_path is None:
        return create_app(preset, remember=False, chart_color=False)
    return create_app(preset, config_dir=tmp_path, chart_color=False)


async def set_field(pilot, screen, name: str, text: str) -> None:  # type: ignore[no-untyped-def]
    """Type into a field as a user does: focus, clear, type, let validation run."""
    editor = screen.form.row(name).editor
    editor.focus()
    await pilot.pause()
    await pilot.press("end", "ctrl+u")
    await pilot.press(*text)
    await pilot.pause()




def summary_values(trace) -> dict:  # type: ignore[no-untyped-def]
    s = trace.summary()
    return {k: v for k, v in s.items() if k not in ("wall_time_s", "compile_time_s")}


def untimed(summary: str) -> str:
    """A summary text without its timings: the wall time, and the kernel's compile or load (shown from 0.5 s,
    so it is in whichever run came first in this process when loading it was slow)."""
    summary = re.sub(r"wall time [0-9.]+ s", "wall time", summary)
    return re.sub(r" \(\+ [0-9.]+ s compiling or loading the solver\)", "", summary)


@pytest.mark.slow
async def test_opens_on_valvetrain_and_1a_run_draws_the_library_charts() -> None:
    app = make_app(None)
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, ValveTrainScreen)
        # load 1A through the open dialog, as a user does
        await pilot.press("ctrl+o")
        await pilot.pause()
        option_list = app.screen.query_one("#open-list")
        index = next(i for i in range(option_list.option_count)
                     if option_list.get_option_at_index(i).id == "name:gnilka-1a")
        option_list.highlighted = index
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is screen and screen.source == "gnilka-1a"
        expected = simulate(load_preset("gnilka-1a"))
        started = time.perf_counter()
        await run_and_wait(pilot, app)
        assert time.perf_counter() - started < 20.0
        assert app.errors_shown == []
        trace = screen.trace
        assert trace.spec == expected.spec  # the form loses nothing of the preset
        np.testing.assert_array_equal(trace.contact_force, expected.contact_force)
        np.testing.assert_array_equal(trace.configuration, expected.configuration)
        assert summary_values(trace) == summary_values(expected)
        for tab, view, draw in (("tab-forces", screen.force_chart, charts.force_chart),
                                ("tab-configuration", screen.configuration_chart, charts.configuration_chart)):
            screen.tabs.active = tab
            await pilot.pause()
            w, h = view.chart_size
            assert view.chart_text == draw(expected, w, h, color=False)
            assert view.chart_text.strip()
        screen.tabs.active = "tab-displacements"
        await pilot.pause()
        w, h = screen.displacement_chart.chart_size
        quantities = tuple(q for q in expected.spec.run.quantities if not q.startswith("F"))[:4]
        assert screen.selected_quantities() == quantities
        assert screen.displacement_chart.chart_text == charts.displacement_chart(expected, quantities, w, h,
                                                                                 color=False)
        # choosing other quantities redraws the chart from the same trace
        screen.quantity_list.deselect_all()
        screen.quantity_list.select("q7")
        await pilot.pause()
        assert screen.selected_quantities() == ("q7",)
        assert screen.displacement_chart.chart_text == charts.displacement_chart(expected, ("q7",), w, h,
                                                                                 color=False)
        from vtool.solvers.studies.metrics import evaluation_summary

        assert untimed(screen.query_one("#summary").text) == untimed(
            expected.summary_text() + "\n\n" + "\n".join(evaluation_summary(expected)["lines"]))
        # the order spectrum of the seat force (F7) over the evaluated cycle, as the library computes it
        from vtool.app.order_charts import order_chart
        from vtool.solvers.studies.orders import dominant_text, natural_frequencies, spectrum

        screen.tabs.active = "tab-orders"
        await pilot.pause()
        w, h = screen.order_chart.chart_size
        orders = spectrum(expected, "F7")
        frequencies = natural_frequencies(expected)
        assert screen.order_chart.chart_text == orders.table(6) + "\n" + dominant_text(orders, frequencies) + "\n" + \
            order_chart(orders, frequencies, width=w, height=max(h - 11 - len(frequencies), 8), color=False)
        assert "F7 in cam orders over 1 cycle (cam angle 360-720 deg" in screen.order_chart.chart_text
        kinds = [type(m) for m in screen.messages_seen]
        assert kinds[-1] is SimulationFinished
        assert all(k is RunProgressed for k in kinds[:-1])


async def test_edited_fields_run_what_the_library_runs() -> None:
    app = make_app("gnilka-1c")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        await set_field(pilot, screen, "run.rpm", "9000")
        await put(pilot, screen, "run.degrees", "200")
        await put(pilot, screen, "members.valve_spring.stiffness", "300")
        assert screen.problem is None
        await run_and_wait(pilot, app)
        doc = valvetrain.dump(load_preset("gnilka-1c"))
        doc["run"].update(rpm=9000, degrees=200)
        doc["members"]["valve_spring"]["stiffness"] = 300
        spec = valvetrain.load(doc)
        assert screen.trace.spec == spec
        expected = simulate(spec)
        np.testing.assert_array_equal(screen.trace.q, expected.q)
        assert summary_values(screen.trace) == summary_values(expected)
        w, h = screen.force_chart.chart_size
        assert screen.force_chart.chart_text == charts.force_chart(expected, w, h, color=False)


INVALID = [("members.pushrod.length", "-5", "9"), ("run.rpm", "fast", "11000"),
           ("clearances[1].restitution", "1.5", "0")]


@pytest.mark.slow
async def test_invalid_fields_show_the_cli_message_and_block_the_run(tmp_path) -> None:  # type: ignore[no-untyped-def]
    app = make_app("gnilka-1c")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        for k, (name, text, good) in enumerate(INVALID):
            if k == 0:
                await set_field(pilot, screen, name, text)  # typed key by key
            else:
                await put(pilot, screen, name, text)
            doc = screen.current_document()
            with pytest.raises(InputError) as info:
                valvetrain.load(doc)
            message = info.value.one_line()
            assert message.startswith(name)
            row = screen.form.row(name)
            assert row.has_class("-invalid")
            assert str(row.query_one(".field-error").render()) == message
            await pilot.press("ctrl+r")
            await pilot.pause()
            assert screen.worker is None and screen.results is None
            assert screen.form.row(name).editor.has_focus
            # the CLI says the same about the same document
            preset = tmp_path / "bad.toml"
            preset.write_text(tomli_w.dumps(doc))
            result = CliRunner().invoke(cli, ["solve", str(preset)])
            assert result.exit_code == 2
            assert result.output.strip() == f"error: {message}"
            # fixing the value clears the message
            await put(pilot, screen, name, good)
            assert screen.problem is None and not row.has_class("-invalid")


async def test_failed_runs_show_an_error_dialog_and_the_app_lives_on(monkeypatch: pytest.MonkeyPatch) -> None:
    import vtool.solvers.run as run_module

    app = make_app("gnilka-1c")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "run.time_step", "0.001")
        await put(pilot, screen, "run.degrees", "30")
        await run_and_wait(pilot, app)
        assert isinstance(app.screen, ErrorDialog)
        with pytest.raises(InputError) as info:
            simulate(with_run_overrides(load_preset("gnilka-1c"), time_step=0.001, degrees=30))
        assert app.errors_shown == [info.value.one_line()]
        assert app.screen.message == info.value.one_line()
        await pilot.press("escape")
        await pilot.pause()
        assert app.screen is screen and screen.results is None
        assert screen.form.row("run.time_step").has_class("-invalid")
        # the app still works: fix the step and run
        await put(pilot, screen, "run.time_step", "1e-6")
        await run_and_wait(pilot, app)
        assert screen.results is not None and app.errors_shown == [info.value.one_line()]
        # a run that cannot be completed (RunError) takes the same way
        diverged = "diverged at t = 0.001 s (cam angle 66 deg) in configuration VII (cam+rocker)"

        def diverging(spec, **kwargs):  # type: ignore[no-untyped-def]
            raise RunError(diverged)

        monkeypatch.setattr(run_module, "simulate", diverging)
        await run_and_wait(pilot, app)
        assert isinstance(app.screen, ErrorDialog) and app.errors_shown[-1] == diverged
        await pilot.press("enter")
        await pilot.pause()
        assert app.screen is screen and diverged in str(screen.status.render())


def slowed(report):  # type: ignore[no-untyped-def]
    """A progress callback that sleeps 10 ms a report: a long run really runs, but a fast machine runs
    400000 degrees in under a second, before a test has typed its keys; this keeps it going until cancelled."""

    def report_and_wait(fraction: float) -> None:
        report(fraction)
        time.sleep(0.01)

    return report_and_wait


async def test_keys_work_during_a_long_run_and_cancel_stops_it(monkeypatch: pytest.MonkeyPatch) -> None:
    import vtool.solvers.run as run_module

    real = run_module.simulate
    ended = threading.Event()
    outcome: list[BaseException | None] = []

    def watched(spec, **kwargs):  # type: ignore[no-untyped-def]
        kwargs["progress"] = slowed(kwargs["progress"])
        try:
            trace = real(spec, **kwargs)
        except BaseException as exc:
            outcome.append(exc)
            raise
        else:
            outcome.append(None)
            return trace
        finally:
            ended.set()

    monkeypatch.setattr(run_module, "simulate", watched)
    app = make_app("gnilka-1d")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "run.degrees", "400000")  # 1-20 s of work by machine, 12 s more slowed
        await put(pilot, screen, "run.output_interval", "50")
        # keys go in as the terminal driver sends them (app.simulate_key, Key events); the Pilot's own
        # press waits for an idle CPU, which a busy solver thread never gives it
        app.simulate_key("ctrl+r")
        assert await until(lambda: bool(screen.messages_seen), 30.0), "no progress from the run"
        assert screen.running
        # the UI responds while the worker runs: switch tabs, type into a field
        before = screen.tabs.active
        started = time.perf_counter()
        app.simulate_key("ctrl+t")
        assert await until(lambda: screen.tabs.active != before, 2.0)
        assert time.perf_counter() - started < 1.0
        editor = screen.form.row("run.rpm").editor
        editor.focus()
        assert await until(lambda: editor.has_focus, 2.0)
        expected_values = ["11000", "", "1", "10", "100", "1000", "10000"]
        for key, value in zip(("end", "ctrl+u", "1", "0", "0", "0", "0"), expected_values, strict=True):
            app.post_message(events.Key(key, key if len(key) == 1 else None))
            assert await until(lambda value=value: editor.value == value, 1.0), (key, editor.value)
        assert screen.running and not ended.is_set() and app.errors_shown == []
        app.simulate_key("escape")
        assert await until(lambda: not screen.running, 2.0)
        assert ended.wait(10.0), "the simulation thread did not stop after cancel"
        assert isinstance(outcome[0], RunError) and "cancelled" in str(outcome[0])
        await pilot.pause()
        assert screen.results is None and app.errors_shown == []
        assert "cancelled" in str(screen.status.render())


async def until(condition, timeout: float) -> bool:  # type: ignore[no-untyped-def]
    deadline = time.perf_counter() + timeout
    while not condition():
        if time.perf_counter() > deadline:
            return False
        await asyncio.sleep(0.02)
    return True


async def test_csv_export_equals_vtool_solve_csv(tmp_path) -> None:  # type: ignore[no-untyped-def]
    app = make_app("gnilka-1c")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        await pilot.press("ctrl+e")  # nothing to export yet: a warning, no dialog
        await pilot.pause()
        assert not isinstance(app.screen, PathDialog)
        await run_and_wait(pilot, app)
        await answer_path_dialog(pilot, app, "ctrl+e", str(tmp_path / "tui.csv"))
    result = CliRunner().invoke(cli, ["solve", "gnilka-1c", "--csv", str(tmp_path / "cli.csv")])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "tui.csv").read_text() == (tmp_path / "cli.csv").read_text()


async def test_save_then_load_round_trips_and_is_remembered(tmp_path) -> None:  # type: ignore[no-untyped-def]
    app = make_app("gnilka-1c", tmp_path)
    path = tmp_path / "my-valve.toml"
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "run.rpm", "9500")
        await put(pilot, screen, "clearances[2].restitution", "0.25")
        edited = screen.spec
        await pilot.press("ctrl+s")
        await pilot.pause()
        app.screen.query_one("#path-input").value = str(path)
        await pilot.press("enter")
        await pilot.pause()
        assert load_preset(path) == edited
        assert edited.run.rpm == 9500 and edited.clearances[2].restitution == 0.25
        await app.open_preset("gnilka-1a")
        await pilot.pause()
        assert screen.form.value("run.rpm") == "11000"
        await app.open_preset(str(path))
        await pilot.pause()
        assert screen.form.value("run.rpm") == "9500"
        assert screen.form.value("clearances[2].restitution") == "0.25"
        assert screen.validate() == edited
    # the file keeps the shipped preset's comments and provenance; changed values are noted
    text = path.read_text(encoding="utf-8")
    shipped = (Path(valvetrain.__file__).parent / "gnilka-1c.toml").read_text(encoding="utf-8")
    comments = [line for line in shipped.splitlines() if line.startswith("#")]
    assert comments and all(line in text.splitlines() for line in comments)
    assert "rpm = 9500 # was 11000.0" in text
    assert sum("# was" in line or "; was" in line for line in text.splitlines()) == 2
    again = make_app(None, tmp_path)
    assert again.recent.items[0] == str(path.resolve())
    assert "gnilka-1a" in again.recent.items


async def test_animation_steps_through_the_deformed_mechanism() -> None:
    app = make_app("gnilka-1c")
    async with app.run_test(size=(100, 30)) as pilot:
        screen = await run_degrees(pilot, app, "40")
        screen.tabs.active = "tab-animation"
        await pilot.pause()
        animation = screen.animation
        animation.focus()
        await pilot.pause()
        await pilot.press("right", "right", "plus")
        await pilot.pause()
        assert animation.row == 2 and animation.scale == 2.0
        trace = screen.trace
        n = trace.spec.n_coordinates
        shapes = deformed_members(trace.spec, trace.q[2, :n], 2.0)
        xlim, ylim = animation.limits()
        w, h = animation.size
        title = f"cam {trace.cam_angle[2]:.1f} deg, row 3/{len(trace.time)}, scale x2, speed x1, paused"
        assert animation.frame_text == shape_chart(shapes, title=title, xlabel="in", width=w, height=h,
                                                   color=False, xlim=xlim, ylim=ylim)
        # the frame is fitted to the moving members: the 36-in spring bar (given by its rate) is not
        spring = next(m for m in trace.spec.members if m.stiffness is not None)
        assert spring.name not in animation.fitted_members() and spring.length == 36.0
        assert ylim[1] - ylim[0] < 0.5 * spring.length
        # a run plays in PLAY_SECONDS at x1 whatever its rows; ] doubles the speed
        from vtool.app.tui.animation import FPS, PLAY_SECONDS

        await pilot.press("right_square_bracket")
        assert animation.speed == 2.0
        assert animation.rows_per_tick == pytest.approx(max(len(trace.time) / (PLAY_SECONDS * FPS),
                                                            1.0 / FPS) * 2.0)
        await pilot.press("space")
        await pilot.pause(0.5)
        assert animation.playing and animation.row > 2
        await pilot.press("space")
        assert not animation.playing


async def test_unknown_preset_on_the_command_line_shows_an_error_and_opens_the_default() -> None:
    app = make_app("no-such-preset")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        assert isinstance(app.screen, ErrorDialog)
        assert app.errors_shown[0].startswith("preset: got 'no-such-preset'")
        await pilot.press("escape")
        await pilot.pause()
        assert isinstance(app.screen, ValveTrainScreen) and app.screen.source == "gnilka-1a"


async def test_changed_fields_are_starred_and_the_thesis_quantities_can_all_be_plotted() -> None:
    app = make_app("gnilka-1c")
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        screen = app.screen
        assert app.focused is screen.form.row("run.rpm").editor  # typing starts at the first field
        await put(pilot, screen, "run.degrees", "40")
        row = screen.form.row("run.degrees")
        drawn = row.render()  # the row draws its label and unit (the editor is its one child)
        assert row.has_class("-changed") and drawn.plain.startswith("*cam degrees") and drawn.plain.endswith("deg")
        label_style = drawn.get_style_at_offset(app.console, 0)
        assert label_style.bold and label_style == row.get_component_rich_style("field-row--label")
        assert drawn.get_style_at_offset(app.console, len(drawn) - 1) == row.get_component_rich_style("field-row--unit")
        await put(pilot, screen, "run.degrees", "850")  # back to the preset's value: no star
        assert not row.has_class("-changed") and row.render().plain.startswith("cam degrees ")
        assert not row.get_component_rich_style("field-row--label").bold
        await put(pilot, screen, "run.degrees", "40")
        await run_and_wait(pilot, app)
        trace = screen.trace
        pick = screen.quantity_list
        quantities = [pick.get_option_at_index(i).value for i in range(pick.option_count)]
        assert quantities == list(trace.spec.run.quantities) and len(quantities) == 11  # Gnilka's list
        chosen = ("q1-q9", "q7-q6", "F7")
        screen.quantity_list.deselect_all()
        for q in chosen:
            screen.quantity_list.select(q)
        await pilot.pause()
        screen.tabs.active = "tab-displacements"
        await pilot.pause(0.2)
        w, h = screen.displacement_chart.size
        picked = screen.selected_quantities()
        assert sorted(picked) == sorted(chosen)
        assert screen.displacement_chart.chart_text == charts.displacement_chart(trace, picked, w, h,
                                                                                 color=False)
        assert "lbf" in screen.displacement_chart.chart_text  # the force has its own panel
        # the configuration chart names its lanes
        text = charts.configuration_chart(trace, 80, 14, color=False)
        for c in trace.spec.clearances:
            if c.state != "removed":
                assert any(line.strip().startswith(c.name) for line in text.splitlines()), c.name


async def test_dialog_on_top_ignores_screen_keys_and_open_preset_still_works() -> None:
    app = make_app("gnilka-1c")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        app.report_error("Run failed", RunError("diverged"))
        await pilot.pause()
        await pilot.press("ctrl+o", "f3", "f1")  # ignored: the dialog has the keys
        await pilot.pause()
        assert isinstance(app.screen, ErrorDialog)
        assert await app.open_preset("gnilka-1a")  # e.g. a recent file chosen from a menu
        await pilot.pause()
        assert app.screen is screen and screen.source == "gnilka-1a"


async def test_error_dialogs_show_one_line_never_an_exception_name(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import vtool.solvers.run as run_module

    def singular(spec, **kwargs):  # type: ignore[no-untyped-def]
        raise np.linalg.LinAlgError("Singular matrix\nmore detail")

    monkeypatch.setattr(run_module, "simulate", singular)
    app = make_app("gnilka-1c")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        await run_and_wait(pilot, app)
        assert isinstance(app.screen, ErrorDialog)
        assert app.errors_shown == ["the run could not be completed: singular matrix"]


async def test_a_new_run_cancels_and_joins_the_old_one_before_it_starts(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    import vtool.solvers.run as run_module

    real = run_module.simulate
    log: list[str] = []

    def watched(spec, **kwargs):  # type: ignore[no-untyped-def]
        degrees = spec.run.degrees
        log.append(f"start {degrees:g}")
        if degrees == 400000:
            kwargs["progress"] = slowed(kwargs["progress"])
        try:
            trace = real(spec, **kwargs)
        except Exception:  # the Newmark back end stops on a cancel with a RunError, assessments with Cancelled
            log.append(f"{'cancelled' if kwargs['cancel']() else 'failed'} {degrees:g}")
            raise
        log.append(f"end {degrees:g}")
        return trace

    monkeypatch.setattr(run_module, "simulate", watched)
    app = make_app("gnilka-1d")
    async with app.run_test(size=(80, 24)) as pilot:
        await pilot.pause()
        screen = app.screen
        await put(pilot, screen, "run.degrees", "400000")
        app.simulate_key("ctrl+r")
        assert await until(lambda: bool(screen.messages_seen), 30.0)
        await put(pilot, screen, "run.degrees", "30")
        app.simulate_key("ctrl+r")
        assert await until(lambda: screen.results is not None, 60.0)
        assert log == ["start 400000", "cancelled 400000", "start 30", "end 30"]
        assert screen.results.spec.run.degrees == 30 and app.errors_shown == []


async def test_opening_a_preset_of_the_same_form_shows_what_a_fresh_form_shows() -> None:
    """Another preset with the same fields keeps the rows and refills them (no remount): the texts equal
    a form opened on that preset, the edited field's star goes, and so does its error."""
    from vtool.app.tui.form import FieldRow

    async def texts(app) -> dict[str, str]:  # type: ignore[no-untyped-def]
        return {row.field.name: row.text for row in app.screen.form.query(FieldRow)}

    fresh_app = make_app("gnilka-3")
    async with fresh_app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        fresh = await texts(fresh_app)
    app = make_app("gnilka-1d")
    async with app.run_test(size=(100, 30)) as pilot:
        await pilot.pause()
        screen = app.screen
        rows = list(screen.form.query(FieldRow))
        assert await texts(app) != fresh  # the two presets differ in some field
        await set_field(pilot, screen, "run.rpm", "-5")
        assert screen.form.row("run.rpm").has_class("-changed")
        assert screen.form.row("run.rpm").has_class("-invalid")
        assert await app.open_preset("gnilka-3")
        await pilot.pause()
        assert list(screen.form.query(FieldRow)) == rows  # the same rows, refilled
        assert await texts(app) == fresh
        assert not any(row.has_class("-changed") or row.has_class("-invalid") for row in rows)


async def test_the_sweep_tab_makes_its_widgets_when_first_opened_for_the_preset_shown() -> None:
    """The Sweep tab's pane is lazy: no widgets at the start; opened, it has its inputs, buttons and
    chart, for the preset the form shows then, with that preset's metrics."""
    from textual.widgets import Button, Input, Select

    from vtool.app.tui.sweep import SweepPane
    from vtool.solvers.studies.metrics import metric_columns

    app = make_app("gnilka-1a")
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        pane = app.screen.query_one(SweepPane)
        assert not pane.children and not pane.composed
        assert await app.open_preset("gnilka-2")
        await pilot.pause()
        app.screen.tabs.active = "tab-sweep"
        await pilot.pause()
        await pilot.pause()
        assert pane.composed and len(pane.query(Input)) == 4 and len(pane.query(Button)) == 3
        assert pane.preset.endswith("gnilka-2.toml") or pane.preset == "gnilka-2"
        options = [value for _, value in pane.query_one("#sweep-metric", Select)._options]
        assert options == [name for name, _ in metric_columns(load_preset("gnilka-2"))]
        assert pane.status_text == ""


async def test_a_first_run_says_it_compiles(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """A run asks the back end for the CLI's compile notice once its input is checked (the status line
    shows it while a run that must compile goes on; a run this short may end first)."""
    import vtool.solvers.newmark.backend as newmark

    asked = []
    monkeypatch.setattr(newmark, "compile_notice", lambda backend, laws: asked.append(backend) or "compiling (test)")
    app = make_app("gnilka-1d")
    async with app.run_test(size=(80, 24)) as pilot:
        screen = await run_degrees(pilot, app, "30")
        assert asked == ["newmark"]
        assert screen.status_log[-1].startswith("done: ")
