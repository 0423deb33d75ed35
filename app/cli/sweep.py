"""``vtool sweep PRESET --set FIELD=VALUES ...``: grids of valve-train runs and derived speeds."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import click

from vtool.app.cli.options import OUTPUT, figure_option, json_alone, write_figure

DEFAULT_SCAN = "1000:20000:1000"


class CountProgress:
    """A click progress bar with ETA on stderr, fed (done, total)."""

    def __init__(self, label: str) -> None:
        self.label = label
        self.bar: Any = None  # click's progress bar, once shown
        self.shown = 0

    def __call__(self, done: int, total: int) -> None:
        if self.bar is None:
            self.bar = click.progressbar(length=total, label=self.label, show_eta=True, show_pos=True,
                                         file=sys.stderr)
            self.bar.__enter__()
        self.bar.update(done - self.shown)
        self.shown = done

    def close(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
            self.bar = None


def _workers(ctx: click.Context, param: click.Parameter, value: int | None) -> int | None:
    from vtool.solvers.studies.sweep import check_workers

    return None if value is None else check_workers(value)


def _scheduler(ctx: click.Context, param: click.Parameter, value: str | None) -> str | None:
    from vtool.solvers.studies.sweep import parse_scheduler

    if value is not None:
        parse_scheduler(value)  # the one parser: refused here, before the preset is loaded
    return value


@click.command()
@click.argument("preset")
@click.option("--set", "sets", multiple=True, metavar="FIELD=VALUES",
              help="Swept field (dotted preset path, e.g. run.rpm, members.valve_spring.stiffness, "
                   "clearances[2].restitution) and its values: start:stop:step (stop included) or a,b,c. "
                   "Several --set make a grid.")
@click.option("--find", "find", type=click.Choice(["jump-speed", "bounce-speed", "coil-bind-speed"]),
              help="Bracket and bisect (to 1 rev/min) every cam-speed interval where the follower leaves the "
                   "cam during lift (jump-speed), the valve bounces on its seat (bounce-speed) or a data-sheet "
                   "valve spring's coils touch (coil-bind-speed), each run to "
                   f"steady state; --set run.rpm gives the scan (default {DEFAULT_SCAN}), other --set fields a "
                   "grid of searches.")
@click.option("--workers", type=int, callback=_workers,
              help="Local worker processes (default: chosen from the measured cost of a point; 1 = in this process).")
@click.option("--scheduler", callback=_scheduler, help="Dask: tcp://HOST:PORT of a running scheduler, local:N (a LocalCluster of N "
                                  "processes) or local-threads:N.")
@click.option("--csv", "--out", "csv_path", type=OUTPUT,
              help="Write one row per point (swept fields, status, metrics; units in the header), appended as "
                   "points finish.")
@click.option("--format", "file_format", type=click.Choice(["csv", "parquet"]),
              help="Format of the --csv/--out file (default: parquet for a .parquet file, else csv). Parquet "
                   "(needs pyarrow: pip install 'vtool[parquet]') is written in row groups, memory bounded; "
                   "the table is then not printed unless --json, --plot, --map or --figure needs it; an "
                   "interrupted sweep keeps its finished points (--resume continues it), a killed one nothing.")
@click.option("--resume", is_flag=True, help="Continue the sweep in the --csv/--out file (CSV or Parquet), skipping "
                                            "finished points.")
@click.option("--timing", is_flag=True, help="Also write each point's wall time to the CSV (not reproducible).")
@click.option("--json", "as_json", is_flag=True, help="Print the results as JSON instead of a table.")
@click.option("--plot", is_flag=True, help="Chart --metric against the first swept field (--figure: also as a figure file).")
@click.option("--map", "as_map", is_flag=True, help="Character heat map of --metric over two swept fields.")
@click.option("--metric", default="spring_margin", show_default=True, help="Metric for --plot and --map.")
@click.option("--every-step", is_flag=True, help="Metrics from every time step instead of the output rows.")
@click.option("--steady", is_flag=True, help="Run every point to steady state (run.steady's defaults) unless the "
                                            "preset sets run.cycles or run.steady; the metrics cover the last cycle.")
@click.option("--orders", "orders", multiple=True, metavar="QUANTITY",
              help="Also report QUANTITY's (q7, q1-q9, F7) cam-order amplitudes, orders 1 to run.highest_order "
                   "(24), as metrics QUANTITY_order_K (for --metric, --plot, --map).")
@click.option("--campbell", metavar="QUANTITY",
              help="Campbell (waterfall) map of QUANTITY's order amplitudes against run.rpm, the natural "
                   "frequencies drawn as the orders they meet.")
@figure_option
def sweep(preset: str, sets: tuple[str, ...], find: str | None, workers: int | None, scheduler: str | None,
          csv_path: Path | None, resume: bool, timing: bool, as_json: bool, plot: bool, as_map: bool,
          metric: str, every_step: bool, figure_path: Path | None, steady: bool, orders: tuple[str, ...],
          campbell: str | None, file_format: str | None) -> None:
    """Run a valve-train preset over a grid of field values and report per-point metrics.

    \b
    Examples:
      vtool sweep gnilka-1a --set run.rpm=8000:12000:250 --plot --metric peak_F1
      vtool sweep gnilka-1a --set run.rpm=9000:12000:500 --set members.valve_spring.stiffness=200,254,300 --map
      vtool sweep gnilka-1a --find jump-speed

    The values are checked like a preset before any run starts (every listed
    value, a range's ends, the grid's corners); each point is made when it
    runs, and one the preset loader refuses is a failed row with its message.
    Metrics and their definitions: docs/sweep.md.
    """
    from vtool.errors import InputError, RunError
    from vtool.presets.paths import plan_sweep
    from vtool.solvers.studies.metrics import metric_columns, seat_index
    from vtool.solvers.studies.sweep import (
        SweepFile,
        make_runner,
        results_json,
        results_table,
        run_points,
    )

    json_alone(as_json, plot=plot, map=as_map)
    if resume and csv_path is None:
        raise InputError("--resume", True, "a --csv file to resume")
    if file_format is not None and csv_path is None:
        raise InputError("--format", file_format, "an output file to write (--out PATH)")
    parquet = False
    if csv_path is not None:
        from vtool.solvers.parquet import output_format

        parquet = output_format(csv_path, file_format) == "parquet"
        if parquet and find is not None:
            raise InputError("--format", "parquet", "csv for --find (a search writes one row per search)")
    if find is not None:
        if not any(s.partition("=")[0].strip() == "run.rpm" for s in sets):
            sets = (f"run.rpm={DEFAULT_SCAN}",) + sets
        if resume or plot or as_map or figure_path:
            raise InputError("--find", find, "no --resume, --plot, --map or --figure (a search prints its bracket "
                             "history)")
    elif not sets:
        raise InputError("--set", None, "at least one FIELD=VALUES (or --find jump-speed)")
    plan = plan_sweep(preset, list(sets))
    if steady or orders or campbell:
        plan = plan.with_settings(orders + ((campbell,) if campbell else ()), steady)
    if campbell and not any(f == "run.rpm" for f, _ in plan.fields):
        raise InputError("--campbell", campbell, "a sweep over run.rpm")
    if find == "bounce-speed" and seat_index(plan.spec) is None:
        raise InputError("--find", find, "a preset with a valve seat (this one has none)")
    if find == "coil-bind-speed" and not getattr(plan.spec, "springs", ()):
        raise InputError("--find", find, "a preset with a data-sheet valve spring ([train.spring] wire_diameter ...)")
    names = {name: unit for name, unit in metric_columns(plan.spec)}
    if metric not in names:
        raise InputError("--metric", metric, f"one of: {', '.join(names)}")
    varied = plan.points.axes()
    axes = [f for f in plan.fields if f[0] in varied]
    if as_map and len(axes) != 2:
        raise InputError("--map", len(axes), "exactly two swept fields with more than one value")
    if (plot or figure_path) and not axes:
        raise InputError("--plot", plan.fields[0][0] if plan.fields else None, "a swept field with two or more values")
    import time

    started = time.perf_counter()  # the wall time counts a Dask cluster's or a pool's start-up
    runner = make_runner(workers, scheduler,  # a Dask scheduler is reached here, before any file is written
                         announce=lambda text: click.echo(text, err=True))
    startup = time.perf_counter() - started
    try:
        if find is not None:
            _find(find, plan, runner, csv_path, as_json, every_step)
            return
        sink = SweepFile(csv_path, plan.fields, plan.spec, resume=resume, timing=timing) if (
            csv_path and not parquet) else None
        progress = CountProgress(f"{len(plan.points)} points")
        keep = not parquet or as_json or plot or as_map or bool(campbell) or figure_path is not None
        outcome_rows = [0]  # rows of an interrupted Parquet sweep's file
        try:
            if parquet:
                outcome = _run_to_parquet(plan, runner, csv_path, every_step, timing, keep, progress, resume,
                                          outcome_rows)
            else:
                outcome = run_points(plan.points, runner, every_step=every_step, sink=sink, progress=progress)
        except KeyboardInterrupt:
            progress.close()
            if parquet and outcome_rows[0]:
                where = f"the finished points are in {csv_path}; run again with --resume to finish"
            elif parquet:
                where = f"no point had finished: nothing was written ({csv_path} is as it was)"
            elif sink is not None and (sink.written or resume):
                where = f"the finished points are in {csv_path}; run again with --resume to finish"
            elif sink is not None:
                where = f"no point had finished: nothing was written ({csv_path} is as it was)"
            else:
                where = "nothing was kept (use --csv to keep finished points)"
            raise RunError(f"interrupted: {where}") from None
        finally:
            progress.close()
    finally:
        runner.close()
    results = outcome.results
    if (sink is not None or parquet) and outcome.skipped:
        click.echo(f"resumed: {outcome.skipped} of {outcome.total} points were already in {csv_path}", err=True)
    from vtool.solvers.studies.metrics import Criteria
    from vtool.solvers.studies.steady import steady_text

    length = plan.spec.unit_system.length
    if as_json:
        click.echo(json.dumps(results_json(results, plan.fields, plan.spec, preset)
                              | {"evaluation": steady_text(plan.spec),
                                 "criteria": Criteria.of(plan.spec).as_dict(length)}, indent=2))
    else:
        if results and not parquet:
            click.echo(results_table(results, plan.fields, plan.spec))
        click.echo(steady_text(plan.spec))  # which cycles the metrics cover, and by which criteria
        click.echo(Criteria.of(plan.spec).text(length))
        n = outcome.total - outcome.skipped
        wall = startup + outcome.wall_time
        begun = f", {startup:.2f} s of it starting the cluster" if startup >= 0.005 else ""
        click.echo(f"{n} points in {wall:.2f} s ({1000 * wall / max(n, 1):.1f} ms per "
                   f"point, {runner.workers} worker{'s' if runner.workers > 1 else ''}{begun})")
        if csv_path is not None:
            click.echo(f"wrote {outcome.total} rows to {csv_path}")
    if results and (plot or as_map):
        from vtool.app.sweep_charts import metric_chart, metric_map

        if plot:
            click.echo(metric_chart(results, axes, metric, names[metric]))
        if as_map:
            click.echo(metric_map(results, axes, metric, names[metric]))
    if results and campbell:
        from vtool.app.sweep_charts import campbell_map
        from vtool.solvers.studies.orders import campbell as campbell_data

        rows = [(float(dict(r.values)["run.rpm"]), r.metrics) for r in results if r.ok]
        waterfall = campbell_data(rows, plan.spec, campbell)
        click.echo(campbell_map(waterfall))
    if results and figure_path is not None:  # the --plot chart, the --map and the --campbell as grey maps
        from vtool.presets.charts import campbell_chart, sweep_chart, sweep_map

        items: list = [sweep_chart(results, axes, metric, names[metric], plan.spec.title)]
        if as_map:
            items.append(sweep_map(results, axes, metric, names[metric], plan.spec.title))
        if campbell:
            items.append(campbell_chart(waterfall, plan.spec.title))
        write_figure(items, figure_path)


def _run_to_parquet(plan, runner, path, every_step, timing, keep, progress, resume, written):
    """The sweep with its points written to a Parquet file as they finish, renamed into place at the end; an
    interrupted sweep's file (its footer written by run_points) is renamed into place too when it holds a
    point (``written[0]``: its rows), so that --resume continues it; a failed one leaves the old file."""
    from vtool.errors import InputError
    from vtool.files import exists, open_atomic_binary
    from vtool.solvers.parquet import SweepParquet
    from vtool.solvers.studies.sweep import run_points

    if resume and not exists(path):
        raise InputError("--resume", str(path), "an existing partial sweep file (none found)")
    interrupted = None
    with open_atomic_binary(path, "--out") as handle:
        sink = SweepParquet(handle, plan.fields, plan.spec, timing=timing, resume=path if resume else None)
        try:
            outcome = run_points(plan.points, runner, every_step=every_step, sink=sink, progress=progress,
                                 keep=keep)
        except KeyboardInterrupt as exc:
            written[0] = sink.rows
            if not sink.rows:
                raise
            interrupted = exc  # the block ends normally: the file with the finished points replaces the old one
    if interrupted is not None:
        raise interrupted
    return outcome


def _find(criterion, plan, runner, csv_path, as_json, every_step) -> None:
    """One speed search per grid point of the fields other than run.rpm."""
    from vtool.files import write_atomic
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.studies.metrics import Criteria
    from vtool.solvers.studies.steady import steady_text, with_steady
    from vtool.solvers.studies.sweep import find_speed, format_value

    grid = plan.points
    speeds = dict(grid.fields)["run.rpm"]
    scan = sorted(set(speeds))
    others = [f for f in plan.fields if f[0] != "run.rpm"]
    searches: dict[tuple, object] = {}
    for index in range(len(grid)):  # one search per value of the other fields, its spec at the first speed
        values = grid.values(index)
        if dict(values)["run.rpm"] == speeds[0]:
            searches.setdefault(tuple((k, v) for k, v in values if k != "run.rpm"), grid.maker(values))
    rows = []
    found = []
    first = with_steady(plan.spec)
    if not as_json:  # the answers come from steady state, by criteria with stated thresholds
        click.echo(Criteria.of(first).text(first.unit_system.length))
        click.echo(steady_text(first))
    for key, spec in searches.items():
        if key and not as_json:
            click.echo(", ".join(f"{k} = {format_value(v)}" for k, v in key))

        def report(b):
            if not as_json:
                click.echo(f"  {b.stage:<6} {b.rpm:>9g} rev/min  {'holds' if b.holds else 'no':<5}  "
                           f"({format_value(b.value)})")

        def at_speed(rpm: float, spec: Any = spec) -> Any:
            return with_steady(with_run_overrides(spec, rpm=rpm))

        result = find_speed(criterion, at_speed, scan, runner, every_step=every_step, report=report)
        if not as_json:
            for interval in result.intervals:
                click.echo(f"  interval: {interval.text()}")
            click.echo(f"{criterion}: {result.message}")
        intervals = ";".join(f"{format_value(i.low)}-{format_value(i.high)}" for i in result.intervals)
        rows.append([format_value(v) for _, v in key] + [format_value(result.speed) if result.speed else "",
                                                         intervals, result.message])
        found.append(dict(key) | {criterion.replace("-", "_"): result.speed,
                                  f"{criterion.replace('-', '_')}_unit": "rev/min", "message": result.message,
                                  "history": [{"rpm": b.rpm, "holds": b.holds, "value": b.value, "stage": b.stage}
                                              for b in result.history],
                                  "intervals": [{"low_rpm": i.low, "high_rpm": i.high, "below_rpm": i.below,
                                                 "above_rpm": i.above} for i in result.intervals]})
    if as_json:
        click.echo(json.dumps({"preset": plan.spec.title, "criterion": criterion,
                               "criteria": Criteria.of(first).as_dict(first.unit_system.length),
                               "evaluation": steady_text(first), "searches": found}, indent=2))
    if csv_path is not None:
        header = [f"{f} ({u})" if u else f for f, u in others] + [f"{criterion.replace('-', '_')} (rev/min)",
                                                                  "intervals (rev/min)", "message"]
        import csv
        import io

        buffer = io.StringIO()
        csv.writer(buffer, lineterminator="\n").writerows([header] + rows)
        write_atomic(csv_path, buffer.getvalue())
