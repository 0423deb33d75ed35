"""The SweepPane widget in a minimal App, driven by Pilot: run, chart, table, export, cancel, bad input."""

from __future__ import annotations

from pathlib import Path

import pytest
from textual.app import App, ComposeResult
from textual.widgets import Input

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
        assert pane.plan is None and pane.outcome is None  # checked in the worker: nothing ran


@pytest.mark.slow
async def test_cancel_stops_and_keeps_finished_points() -> None:
    app = PaneApp(values="9000:12000:5", fixed="run.degrees=4000")  # ~20 s of work: still running at the cancel
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        pane.run_sweep()
        for _ in range(3000):  # the points are checked first
            await pilot.pause(0.02)
            if pane.status_text.startswith("running"):
                break
        await pilot.pause(0.3)
        await pilot.click("#sweep-cancel")
        await app.workers.wait_for_complete()
        await pilot.pause()
        await pilot.pause()
        assert pane.status_text.startswith("stopped:"), pane.status_text
        assert len(pane.outcome.results) < 601


async def test_several_workers_run_under_textual_and_its_stderr_is_kept() -> None:
    """Textual's stderr has no file descriptor (fileno() -1); the pool's first start handed it to
    multiprocessing's helper process: every run with workers failed "bad value(s) in fds_to_keep"."""
    import sys

    class TwoWorkers(App):
        def compose(self) -> ComposeResult:
            yield SweepPane("gnilka-1a", workers=2, values="10000,11000", fixed="run.degrees=460",
                            metric="peak_F1")

    app = TwoWorkers()
    async with app.run_test(size=(140, 50)) as pilot:
        textual_stderr = sys.stderr
        assert textual_stderr.fileno() == -1  # the condition of the bug
        pane = app.query_one(SweepPane)
        await _run(pilot, pane)
        assert pane.status_text.startswith("finished: 2 of 2 points"), pane.status_text
        assert [r.status for r in pane.outcome.results] == ["ok", "ok"]
        assert all(r.metrics["peak_F1"] > 0 for r in pane.outcome.results)
        assert sys.stderr is textual_stderr  # put back after the pool started
        await _run(pilot, pane)  # and a second run (the pool's helpers are running now)
        assert pane.status_text.startswith("finished: 2 of 2 points"), pane.status_text


async def test_descriptor_stderr_changes_nothing_when_stderr_has_a_descriptor() -> None:
    import os
    import sys

    from vtool.solvers.studies.sweep import descriptor_stderr

    class NoDescriptor:
        def fileno(self) -> int:
            return -1

    before = sys.stderr
    with descriptor_stderr():
        assert sys.stderr is before
    replaced = sys.stderr = NoDescriptor()  # type: ignore[assignment]
    try:
        with descriptor_stderr():
            assert sys.stderr.fileno() >= 0 and sys.stderr.name == os.devnull
        assert sys.stderr is replaced
    finally:
        sys.stderr = before


@pytest.mark.slow
async def test_points_are_checked_off_the_ui_thread_and_cancel_stops_a_large_sweep(monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Checking a point costs about 10 ms: 100,000 points froze the screen for minutes on the UI
    thread, and Cancel was not seen. The check runs in the worker (a range's ends and the grid's corners:
    the other points are made as they run), the run shows its count, and Cancel stops it."""
    import threading

    import vtool.presets as presets

    loads_on_ui_thread: list[int] = []
    load = presets.load_document

    def watched(*args, **kwargs):  # type: ignore[no-untyped-def]
        if threading.current_thread() is threading.main_thread():
            loads_on_ui_thread.append(1)
        return load(*args, **kwargs)

    monkeypatch.setattr(presets, "load_document", watched)
    app = PaneApp(values="9000:9100:10", fixed="run.degrees=100", metric="peak_F1")
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        await pilot.pause()
        loads_on_ui_thread.clear()  # (the pane reads its preset's metric names when it is made)
        await _run(pilot, pane)
        assert pane.status_text.startswith("finished: 11 of 11 points"), pane.status_text
        assert not loads_on_ui_thread
        pane.query_one("#sweep-values", Input).value = "1000:100999:1"  # 100,000 points
        pane.run_sweep()
        for _ in range(1500):  # the screen stays live while the worker checks and runs
            await pilot.pause(0.02)
            if "running 100000 points" in pane.status_text:
                break
        assert "running 100000 points" in pane.status_text, pane.status_text
        assert pane.running
        await pilot.click("#sweep-cancel")
        await app.workers.wait_for_complete()
        await pilot.pause()
        assert pane.status_text.startswith("stopped: "), pane.status_text
        done = int(pane.status_text.split()[1])
        assert done < 100_000 and pane.status_text.split()[3] == "100000"
        assert pane.outcome is not None and len(pane.outcome.results) == done
        assert not loads_on_ui_thread


async def test_a_metric_with_no_value_at_any_point_is_said_not_drawn() -> None:
    """seating_velocity_max is empty at 100 degrees (the valve has not come back to its seat): plotext's
    chart of all-NaN series raised IndexError and ended the app."""
    app = PaneApp(values="10000,11000", fixed="run.degrees=100", metric="seating_velocity_max")
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        await _run(pilot, pane)
        assert pane.status_text.startswith("finished: 2 of 2 points"), pane.status_text
        assert pane.chart.function is None
        assert "no point has a value of seating_velocity_max" in str(pane.chart.content)
    assert app._exception is None


async def test_a_speed_sweep_shows_the_intervals_and_a_two_field_sweep_the_map() -> None:
    """1A at 5,000, 6,000 and 7,000 rev/min (850 deg): the intervals where the follower leaves the cam and the
    valve bounces are those of the library's metrics at those speeds; a second swept field puts the map
    (sweep_charts.metric_map) above the table."""
    from vtool.app.sweep_charts import metric_map
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import scan_intervals

    app = PaneApp(values="5000,6000,7000", metric="cam_separations")
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        await _run(pilot, pane)
        results = pane.outcome.results
        jumps = scan_intervals(results, "run.rpm", "jump-speed")
        assert jumps and jumps[0][1] == 7000  # (in contact during lift at 5,000: 1A leaves the cam from 5,391)
        text = str(pane.intervals.content)
        assert text.startswith(f"the follower leaves the cam during lift: {jumps[0][0]:g}-7000 rev/min; the valve "
                               "bounces on its seat: ") and "vtool sweep --find bisects the edges" in text
        pane.query_one("#sweep-fixed", Input).value = "damping.factor=0.5,1"
        await _run(pilot, pane)
        plan, results = pane.plan, pane.outcome.results
        axes = [f for f in plan.fields if f[0] in ("run.rpm", "damping.factor")]
        units = dict(metric_columns(plan.spec))
        assert pane.table.text.startswith(metric_map(results, axes, "cam_separations", units["cam_separations"]))
        assert str(pane.intervals.content) == ""  # two fields: no speed intervals

async def test_export_while_the_next_sweep_is_checked_writes_the_last_finished_sweep(tmp_path: Path) -> None:
    """TUI monkey, seeds 108 and 160: Export CSV pressed while a new sweep was being checked met the new
    (empty) plan beside the last sweep's results (AttributeError)."""
    app = PaneApp(values="10000,11000", fixed="run.degrees=100", metric="peak_F1")
    async with app.run_test(size=(140, 50)) as pilot:
        pane = app.query_one(SweepPane)
        await _run(pilot, pane)
        pane.query_one("#sweep-values", Input).value = "1000:100999:1"
        pane.run_sweep()
        await pilot.pause()
        pane.export_csv(tmp_path / "last.csv")
        await pilot.pause()
        pane.cancel()
        while pane.running:
            await pilot.pause(0.05)
        await pilot.pause()
    assert app._exception is None
    rows = (tmp_path / "last.csv").read_text().splitlines()
    assert len(rows) == 3 and rows[1].startswith("10000,") and rows[2].startswith("11000,")
