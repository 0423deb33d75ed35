"""The SweepPane widget in a minimal App, driven by Pilot: run, chart, table, export, cancel, bad input."""

from __future__ import annotations

from pathlib import Path

import pytest
from textual.app import App, ComposeResult

from vtool.app.sweep_charts import metric_chart
from vtool.app.tui.sweep import SweepPane

pytestmark = pytest.mark.asyncio


class PaneApp(App):
    def __init__(self, **options) -> None:  # type: ignore[no-untyped-def]
        super().__init__()
        self.options = options

    def compose(self) -> ComposeResult:
        yield SweepPane("gnilka-1a", workers=1, **self.options)


async def _run(pilot, pane: SweepPane) -> None:  # type: ignore[no-untyped-def]
    pane.run_sweep()
    await pilot.pause()
    await pilot.app.workers.wait_for_complete()
    await pilot.pause()
    await pilot.pause()


async def test_pane_runs_charts_tabulates_and_exports(tmp_path: Path) -> None:
    app = PaneApp(values="10000,11000", fixed="run.degrees=460", metric="peak_F1")
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        await pilot.click("#sweep-run")
        await pilot.pause()
        await app.workers.wait_for_complete()
        await pilot.pause()
        await pilot.pause()
        assert pane.status_text.startswith("finished: 2 of 2 points"), pane.status_text
        assert "peak_F1" in pane.table.text and "11000" in pane.table.text
        width, height = pane.chart.chart_size
        results, plan = pane.outcome.results, pane.plan
        assert pane.chart.chart_text == metric_chart(results, plan.fields[:1], "peak_F1", "lbf", width=width,
                                                     height=height, color=True)
        out = tmp_path / "pane.csv"
        pane.export_csv(out)
        rows = out.read_text().splitlines()
        assert len(rows) == 3 and rows[0].startswith("run.rpm (rev/min),run.degrees (deg),status,")
        assert pane.status_text == f"wrote 2 rows to {out}"


async def test_bad_range_shows_one_line_and_runs_nothing() -> None:
    app = PaneApp(values="5000:4000:250")
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        await _run(pilot, pane)
        assert pane.status_text.startswith("error: --set run.rpm: got '5000:4000:250'")
        assert pane.worker is None and pane.outcome is None


async def test_cancel_stops_and_keeps_finished_points() -> None:
    app = PaneApp(values="9000:12000:2", fixed="run.degrees=2000")
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        pane.run_sweep()
        await pilot.pause(0.3)
        await pilot.click("#sweep-cancel")
        await app.workers.wait_for_complete()
        await pilot.pause()
        await pilot.pause()
        assert pane.status_text.startswith("stopped:"), pane.status_text
        assert len(pane.outcome.results) < 1501
