"""The camshaft screen (app/tui/camshaft.py): the kinds table opens it, a run shows the library's summed torque,
a stale run's result is dropped, the export is the CLI's CSV."""

from __future__ import annotations

import dataclasses

import pytest

from tests.test_camshaft import SMALL
from tests.tui_helpers import put, run_and_wait
from vtool.app.tui.app import create_app
from vtool.app.tui.camshaft import CamshaftScreen, CamshaftSolved

pytestmark = pytest.mark.asyncio


async def test_camshaft_screen_runs_shows_units_and_exports(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from vtool.presets.camshaft import load_camshaft, solve
    from vtool.solvers.studies.camshaft import camshaft_csv_text, camshaft_text

    preset = tmp_path / "two.toml"
    preset.write_text(SMALL)
    app = create_app(str(preset), remember=False, chart_color=False)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, CamshaftScreen)
        await put(pilot, screen, "camshaft.valves[1].phase", "45")
        await run_and_wait(pilot, app)
        spec = load_camshaft(preset)
        moved = dataclasses.replace(spec.valves[1], phase_deg=45.0, offset_deg=45.0)  # cylinder 2 fires first: 0
        spec = dataclasses.replace(spec, valves=(spec.valves[0], moved))
        assert screen.spec == spec
        expected = solve(spec)
        assert screen.results is not None
        assert (screen.results.torque == expected.torque).all()
        summary = screen.query_one("#camshaft-summary").text
        assert summary == camshaft_text(expected) and "N*mm" in summary and "peak-to-peak" in summary
        assert "camshaft torque (N*mm)" in screen.chart.chart_text
        assert "done: 2 valves" in screen.status_log[-1] and "N*mm" in screen.status_log[-1]
        # a result posted under an older run id is ignored (the run-id guard)
        screen.post_message(CamshaftSolved(screen.run_id - 1, spec, None))
        await pilot.pause()
        assert screen.results is not None and (screen.results.torque == expected.torque).all()
        screen.write_csv(str(tmp_path / "tui.csv"))
        assert (tmp_path / "tui.csv").read_text() == camshaft_csv_text(expected)
        # a bad field blocks the run and says why, in the loader's words
        await put(pilot, screen, "camshaft.valves[0].cylinder", "3")
        assert screen.problem is not None and "camshaft.valves[0].cylinder" in screen.problem.one_line()


async def test_f5_opens_the_shipped_camshaft() -> None:
    app = create_app("gnilka-1a", remember=False, chart_color=False)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        await pilot.press("f5")
        await pilot.pause()
        screen = app.screen
        assert isinstance(screen, CamshaftScreen) and screen.source == "four-cylinder-intake"
        assert screen.form.has_field("camshaft.valves[7].label") and screen.problem is None
