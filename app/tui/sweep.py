"""The sweep pane: a self-contained widget to sweep one preset field and chart a metric.

``SweepPane(preset)`` is mounted as a tab on the valve-train screen (or in any
App). The user picks a field (dotted preset path), its values
(``start:stop:step`` or ``a,b,c``) and a metric, and presses *Run*. Everything
after that happens in a thread worker, so the screen stays live however large
the grid: the points are first validated like a preset (about 10 ms a point;
the bar counts them, and an error is shown on the status line and nothing
runs), then evaluated; the worker posts :class:`SweepProgressed` (collapsing)
and :class:`SweepFinished`. *Cancel* stops between points, while checking or
running, and keeps what finished; *Export CSV* writes the results atomically
(same bytes as ``vtool sweep --csv``).

With several workers the points run on a process pool. Textual replaces
``sys.stderr`` with a stream that has no file descriptor, and multiprocessing
hands ``sys.stderr``'s descriptor to the helper process it starts with a
process's first pool ("bad value(s) in fds_to_keep"): the pool is made with
an explicit stream (:func:`descriptor_stderr`), and its workers write their
standard error to os.devnull, not over Textual's screen.
"""

from __future__ import annotations

import math
import os
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from textual import on, work
from textual.app import ComposeResult
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.widget import Widget
from textual.widgets import Button, Input, Label, ProgressBar, Select, Static
from textual.worker import Worker, WorkerState, get_current_worker

from vtool.app.tui.widgets import ChartView, ChoiceSelect, TextPanel

DEFAULT_METRICS = ("spring_margin", "cam_separation_duration", "cam_separations", "lift_loss",
                   "seating_velocity_max", "seat_bounces", "bounce_height", "peak_F1", "peak_F2", "peak_F7",
                   "events", "wall_time")


_STDERR_LOCK = threading.Lock()


@contextmanager
def descriptor_stderr() -> Iterator[None]:
    """``sys.stderr`` a stream with a file descriptor (os.devnull) inside the block, when it has none.

    For making a process pool under Textual (see the module doc). Outside an app
    (a real ``sys.stderr``) nothing changes. Afterwards the replaced stream is put
    back unless something else replaced ``sys.stderr`` meanwhile (the app ending).
    """
    try:
        usable = sys.stderr is not None and sys.stderr.fileno() >= 0
    except (AttributeError, OSError, ValueError):
        usable = False
    if usable:
        yield
        return
    with _STDERR_LOCK, open(os.devnull, "w") as devnull:
        replaced, sys.stderr = sys.stderr, devnull
        try:
            yield
        finally:
            if sys.stderr is devnull:
                sys.stderr = replaced


def failure_text(error: BaseException | None) -> str:
    """A failed sweep in one line: a bad input or a failed run as it says itself; anything else
    (a failure of the program, not of the input) says the sweep could not be completed."""
    from vtool.errors import InputError, RunError

    if isinstance(error, InputError):
        return error.one_line()
    lines = str(error).strip().splitlines() if error is not None else []
    text = lines[0].strip() if lines else ""
    if isinstance(error, RunError):
        return text or "a run failed"
    return f"the sweep could not be completed: {text or type(error).__name__}"


class SweepProgressed(Message):
    """``done`` of ``total`` points are finished (``checking``: validated, before any runs)."""

    def __init__(self, done: int, total: int, checking: bool = False) -> None:
        super().__init__()
        self.done = done
        self.total = total
        self.checking = checking

    def can_replace(self, message: Message) -> bool:
        return isinstance(message, SweepProgressed)


class SweepFinished(Message):
    """The worker ended: ``outcome.complete`` is False when it was cancelled; ``plan`` and ``outcome``
    are None when it was cancelled while checking the points, and ``error`` is then the input error
    that refused them, if any."""

    def __init__(self, plan: Any, outcome: Any, error: str | None = None, checked: int = 0) -> None:
        super().__init__()
        self.plan = plan
        self.outcome = outcome
        self.error = error
        self.checked = checked


class SweepPane(Widget):
    """Field, range and metric inputs; run/cancel/export; progress, chart and table (see module doc)."""

    DEFAULT_CSS = """
    SweepPane { height: 1fr; }
    SweepPane .sweep-row { height: 1; }
    SweepPane .sweep-label { width: auto; padding: 0 1; color: $text-muted; }
    SweepPane Input { width: 1fr; }
    SweepPane #sweep-metric { width: 28; }
    SweepPane Button { width: auto; min-width: 0; margin-right: 1; }
    SweepPane #sweep-status { height: auto; }
    SweepPane ChartView { height: 2fr; }
    SweepPane TextPanel { height: 1fr; }
    """

    def __init__(self, preset: str | Path = "gnilka-1a", *, workers: int | None = 1, field: str = "run.rpm",
                 values: str = "9000:12000:250", fixed: str = "", metric: str = "spring_margin",
                 id: str | None = None, lazy: bool = False) -> None:
        super().__init__(id=id)
        self.preset = str(preset)
        self.sweep_workers = workers
        self._initial = (field, values, fixed, metric)
        self.plan: Any = None
        self.outcome: Any = None
        self.worker: Worker[Any] | None = None
        self.status_log: list[str] = []  # every status message, in order (tests read them)
        # lazy: the widgets are made when the pane is first shown (a tab not yet opened costs the screen's
        # start nothing: the valve-train screen's Sweep tab was 25 of its widgets)
        self.composed = not lazy

    def compose(self) -> ComposeResult:
        if not self.composed:
            return
        field, values, fixed, metric = self._initial
        csv = "sweep.csv"
        with Vertical():
            # each input has its label on its left; compact widgets, one line each (the chart gets the height)
            with Horizontal(classes="sweep-row"):
                yield Label("field", classes="sweep-label")
                yield Input(field, placeholder="e.g. run.rpm", id="sweep-field", compact=True)
                yield Label("values", classes="sweep-label")
                yield Input(values, placeholder="start:stop:step or a,b,c", id="sweep-values", compact=True)
            with Horizontal(classes="sweep-row"):
                yield Label("fixed", classes="sweep-label")
                yield Input(fixed, placeholder="e.g. run.degrees=460; damping.factor=2", id="sweep-fixed",
                            compact=True)
                yield Label("metric", classes="sweep-label")
                names = self._metric_names()
                yield ChoiceSelect([(m, m) for m in names], value=metric if metric in names else names[0],
                                   allow_blank=False, compact=True, id="sweep-metric")
            with Horizontal(classes="sweep-row"):
                yield Button("Run", id="sweep-run", variant="primary", compact=True)
                yield Button("Cancel", id="sweep-cancel", compact=True)
                yield Label("CSV file", classes="sweep-label")
                yield Input(csv, placeholder="e.g. sweep.csv", id="sweep-csv", compact=True)
                yield Button("Export CSV", id="sweep-export", compact=True)
            yield ProgressBar(total=1, show_eta=True, id="sweep-progress")
            yield Static("", id="sweep-status", markup=False)
            yield Static("", id="sweep-intervals", markup=False)
            yield ChartView("run a sweep to see the chart", id="sweep-chart")
            yield TextPanel("", id="sweep-table")

    async def on_show(self) -> None:
        if not self.composed:  # a lazy pane's first showing
            self.composed = True
            await self.recompose()

    def _metric_names(self) -> tuple[str, ...]:
        """The preset's metrics (its own force labels), or a default list if it does not load."""
        from vtool.errors import InputError
        from vtool.presets import load_preset
        from vtool.solvers.studies.metrics import metric_columns

        try:
            return tuple(name for name, _ in metric_columns(load_preset(self.preset)))
        except (InputError, AttributeError, StopIteration):
            return DEFAULT_METRICS

    # ----- small typed accessors -----
    def _input(self, name: str) -> Input:
        return self.query_one(f"#sweep-{name}", Input)

    @property
    def status(self) -> Static:
        return self.query_one("#sweep-status", Static)

    @property
    def status_text(self) -> str:
        return str(self.status.content)

    def set_status(self, text: str, log: bool = True) -> None:
        """Show ``text`` on the pane's status line; every message but progress is kept in ``status_log``."""
        if log:
            self.status_log.append(text)
        self.status.update(text)

    @property
    def chart(self) -> ChartView:
        return self.query_one("#sweep-chart", ChartView)

    @property
    def table(self) -> TextPanel:
        return self.query_one("#sweep-table", TextPanel)

    @property
    def metric(self) -> str:
        return str(self.query_one("#sweep-metric", Select).value)

    @property
    def running(self) -> bool:
        return self.worker is not None and self.worker.state in (WorkerState.PENDING, WorkerState.RUNNING)

    # ----- actions -----
    def assignments(self) -> list[str]:
        """The inputs as ``vtool sweep --set`` assignments: the swept field, then the fixed settings."""
        sets = [f"{self._input('field').value.strip()}={self._input('values').value.strip()}"]
        return sets + [s.strip() for s in self._input("fixed").value.split(";") if s.strip()]

    def run_sweep(self) -> None:
        """Start the worker: it checks every point (errors on the status line), then runs them.

        ``plan`` and ``outcome`` stay the last finished sweep's (a pair: what the chart, the table and
        *Export CSV* show) until this one finishes."""
        self.query_one("#sweep-progress", ProgressBar).update(total=None, progress=0)
        self.set_status("checking the points ... (Cancel stops)")
        self.worker = self._work(self.preset, self.assignments())

    @work(thread=True, exclusive=True, exit_on_error=False, group="sweep")
    def _work(self, preset: str, sets: list[str]) -> None:
        from vtool.errors import InputError
        from vtool.presets.paths import SweepCancelled, plan_sweep
        from vtool.solvers.studies.sweep import make_runner, run_points

        worker = get_current_worker()
        checked = [0]

        def check_progress(done: int, total: int) -> None:
            checked[0] = done
            self.post_message(SweepProgressed(done, total, checking=True))

        try:
            plan = plan_sweep(preset, sets, progress=check_progress, cancel=lambda: worker.is_cancelled)
        except InputError as exc:
            self.post_message(SweepFinished(None, None, error=exc.one_line()))
            return
        except SweepCancelled:
            self.post_message(SweepFinished(None, None, checked=checked[0]))
            return
        self.post_message(SweepProgressed(0, len(plan.points)))
        with descriptor_stderr():  # the pool's helper processes start here
            runner = make_runner(self.sweep_workers, stderr=os.devnull)
        try:
            outcome = run_points(plan.points, runner, progress=lambda d, t: self.post_message(SweepProgressed(d, t)),
                                 cancel=lambda: worker.is_cancelled)
        finally:
            runner.close()
        self.post_message(SweepFinished(plan, outcome))

    def cancel(self) -> None:
        if self.running and self.worker is not None:
            self.worker.cancel()
            self.set_status("stopping ...")

    def export_csv(self, path: str | Path | None = None) -> None:
        from vtool.errors import InputError
        from vtool.files import write_atomic
        from vtool.solvers.studies.sweep import results_csv

        if self.outcome is None or not self.outcome.results:
            self.set_status("error: nothing to export (run a sweep first)")
            return
        target = Path(path or self._input("csv").value.strip() or "sweep.csv")
        try:
            write_atomic(target, results_csv(self.outcome.results, self.plan.fields, self.plan.spec))
        except InputError as exc:
            self.set_status(f"error: {exc.one_line()}")
            return
        except OSError as exc:
            self.set_status(f"error: {target}: {exc.strerror}")
            return
        except ValueError:  # a NUL in the path
            self.set_status(f"error: {InputError('CSV file', str(target), 'a file path without NUL').one_line()}")
            return
        self.set_status(f"wrote {len(self.outcome.results)} rows to {target}")

    # ----- handlers -----
    @on(Button.Pressed, "#sweep-run")
    def _run_pressed(self) -> None:
        if not self.running:
            self.run_sweep()

    @on(Button.Pressed, "#sweep-cancel")
    def _cancel_pressed(self) -> None:
        self.cancel()

    @on(Button.Pressed, "#sweep-export")
    def _export_pressed(self) -> None:
        self.export_csv()

    @on(Select.Changed, "#sweep-metric")
    def _metric_changed(self) -> None:
        self._draw()

    def on_sweep_progressed(self, message: SweepProgressed) -> None:
        self.query_one("#sweep-progress", ProgressBar).update(total=message.total, progress=message.done)
        if not self.running:
            return  # a late message of a stopped worker
        # (every message says it: progress messages collapse, so a particular one may never arrive)
        if message.checking:
            self.set_status(f"checking {message.total} points: {message.done} valid ... (Cancel stops)", log=False)
        else:
            self.set_status(f"running {message.total} points ... (Cancel stops)", log=message.done == 0)

    def on_sweep_finished(self, message: SweepFinished) -> None:
        if message.outcome is None:  # refused or stopped before any point ran
            self.set_status(f"error: {message.error}" if message.error else
                               f"stopped while checking the points ({message.checked} checked): nothing ran")
            return
        self.plan = message.plan
        self.outcome = message.outcome
        done = len(message.outcome.results)
        state = "finished" if message.outcome.complete else "stopped"
        self.set_status(f"{state}: {done} of {message.outcome.total} points in {message.outcome.wall_time:.2f} s")
        self._draw()

    def on_worker_state_changed(self, event: Worker.StateChanged) -> None:
        if event.worker is self.worker and event.state == WorkerState.ERROR:
            self.set_status(f"error: {failure_text(event.worker.error)}")

    @property
    def intervals(self) -> Static:
        return self.query_one("#sweep-intervals", Static)

    @staticmethod
    def _intervals_text(results: Any, axes: list) -> str:
        """The speed intervals of a one-field sweep over run.rpm where the follower leaves the cam or the valve
        bounces, on the scanned speeds (``vtool sweep --find`` bisects their edges)."""
        from vtool.solvers.studies.sweep import CRITERIA, scan_intervals

        if len(axes) != 1 or axes[0][0] != "run.rpm":
            return ""
        parts = []
        for criterion in CRITERIA:
            words = CRITERIA[criterion][2]
            found = scan_intervals(results, "run.rpm", criterion)
            spans = ", ".join(f"{a:g}-{b:g}" if a != b else f"{a:g}" for a, b in found) or "at no scanned speed"
            parts.append(f"{words}: {spans}" + (" rev/min" if found else ""))
        return "; ".join(parts) + " (scanned speeds; vtool sweep --find bisects the edges)"

    def _draw(self) -> None:
        from vtool.solvers.studies.metrics import metric_columns
        from vtool.solvers.studies.sweep import results_table

        if self.outcome is None or not self.outcome.results or self.plan is None:
            return
        results, plan, metric = self.outcome.results, self.plan, self.metric
        units = dict(metric_columns(plan.spec))
        axes = [f for f in plan.fields if len({dict(r.values)[f[0]] for r in results}) > 1]
        self.intervals.update(self._intervals_text(results, axes))
        table = results_table(results, plan.fields, plan.spec)
        if len(axes) == 2 and metric in units:  # a grid of two fields: the map above the table
            from vtool.app.sweep_charts import metric_map

            table = metric_map(results, axes, metric, units[metric]) + "\n\n" + table
        self.table.set_text(table)
        if metric not in units:
            self.chart.plot(None)
            return
        values = [r.metrics.get(metric) for r in results]
        if not axes or not any(isinstance(v, int | float) and math.isfinite(v) for v in values):
            self.chart.placeholder = (f"no point has a value of {metric}" if axes else
                                      "a chart needs a swept field with two or more values")
            self.chart.plot(None)
            return
        from vtool.app.sweep_charts import metric_chart

        self.chart.plot(lambda width, height, color: metric_chart(results, axes, metric, units[metric], width=width,
                                                                  height=height, color=color))
