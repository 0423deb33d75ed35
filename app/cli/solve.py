"""``vtool solve PRESET``: the one batch entry point for every preset kind.

The preset's kind picks what runs, from the one kinds table
(:data:`vtool.presets.kinds.KINDS`). A flag that is a preset field
(``--rpm`` is ``run.rpm``, the table's ``overrides``) is not checked here: it
is set into the preset document and the loader checks it once, with the
file's own values, naming the flag in its error (docs/architecture.md walks
``--rpm`` and ``--dt`` through). ``--backend`` lists the installed back ends.
The output path is checked before the run starts, and a run's cost is
estimated and refused above ``--max-steps`` before the back end starts
(:mod:`vtool.solvers.cost`).
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from vtool.app.cli.options import OUTPUT, figure_option, json_alone, write_figure
from vtool.errors import InputError
from vtool.solvers.backends import available
from vtool.solvers.cost import MAX_SCIPY_STEPS, MAX_STEPS
from vtool.solvers.model.spec import IMPACT_LAWS, START_VELOCITIES

if TYPE_CHECKING:
    from vtool.solvers.trace import CsvStream


def _max_steps(ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
    if value is not None and not 1.0 <= value <= 1e12:
        raise InputError("--max-steps", value, ">= 1 and <= 1e12 steps")
    return value


@click.command()
@click.argument("preset")
@click.option("--backend", type=click.Choice(available()), help="Back end; default: the preset's.")
@click.option("--dt", type=float, help="Time step (s, 1e-12 to 0.1); default: the preset's run.time_step.")
@click.option("--rpm", type=float, help="Cam speed (rev/min, 0.001 to 1e6); default: the preset's run.rpm.")
@click.option("--degrees", type=float,
              help="Degrees of cam rotation to run (1e-6 to 3.6e6); default: the preset's run.degrees.")
@click.option("--max-steps", type=float, callback=_max_steps,
              help=f"Refuse runs estimated above this many steps (default {MAX_STEPS:.0e}; scipy {MAX_SCIPY_STEPS:.0e}).")
@click.option("--csv", "--out", "csv_path", type=OUTPUT,
              help="Write the response as CSV (per output interval, or per step with --every-step).")
@click.option("--format", "file_format", type=click.Choice(["csv", "parquet"]),
              help="Format of the --csv/--out file (default: parquet for a .parquet file, else csv); Parquet "
                   "needs pyarrow (pip install 'vtool[parquet]'), written in row groups as the run goes.")
@click.option("--every-step", is_flag=True, help="CSV rows at every time step (and event) instead of per degree.")
@click.option("--plot", is_flag=True, help="Draw force, displacement and configuration charts (not with --json).")
@figure_option
@click.option("--json", "as_json", is_flag=True, help="Print the summary (with the event list) as JSON.")
@click.option("--events", "show_events", is_flag=True, help="Also print the event list.")
@click.option("--impact", help=f"Impact law for every clearance ({', '.join(IMPACT_LAWS)}); default: the preset's.")
@click.option("--start", help=f"Start velocities ({', '.join(START_VELOCITIES)}); default: the preset's.")
@click.option("--orders", "orders", metavar="QUANTITY",
              help="Also print the cam-order spectrum of QUANTITY (q7, q1-q9, F7) over the evaluated cycles: "
                   "a table, and with --plot a chart with the natural frequencies marked.")
@click.option("--set", "sets", multiple=True, metavar="FIELD=VALUE",
              help="Set a preset field for this run (dotted path as in `vtool sweep`, e.g. "
                   "members.valve_spring.stiffness=300 or clearances[2].restitution=0.5); checked by the preset's loader.")
def solve(preset: str, backend: str | None, dt: float | None, rpm: float | None, degrees: float | None,
          max_steps: float | None, csv_path: Path | None, every_step: bool, plot: bool, as_json: bool,
          show_events: bool, orders: str | None, impact: str | None, start: str | None,
          figure_path: Path | None, file_format: str | None, sets: tuple[str, ...] = ()) -> None:
    """Run a preset: a valve-train simulation, a sonic-boom assessment or a plate study.

    Valve train: prints the summary (separations and impacts per clearance,
    peak forces, valve seating velocities, bounces per revolution, run
    statistics). Files are written only when the run succeeds.
    """
    from vtool.presets import Override, find_preset, kind_of, load_document, read_document
    from vtool.presets.kinds import KINDS, resolve

    json_alone(as_json, plot=plot)
    csv_file = csv_path  # checked when the command line was read (options.OUTPUT)
    if file_format is not None and csv_file is None:
        raise InputError("--format", file_format, "an output file to write (--out PATH)")
    if csv_file is not None and file_format is None and str(csv_file).lower().endswith((".parquet", ".pq")):
        file_format = "parquet"
    path = find_preset(preset)
    doc = read_document(path)
    if sets:
        from vtool.presets.paths import apply_sets

        doc = apply_sets(doc, sets)
    kind = KINDS[kind_of(doc)]
    given = {"--backend": backend, "--dt": dt, "--rpm": rpm, "--degrees": degrees,
             "--max-steps": max_steps, "--every-step": every_step or None,
             "--events": show_events or None, "--impact": impact, "--start": start, "--orders": orders,
             "--format": None if file_format == "csv" else file_format}
    for flag, value in given.items():
        if value is not None and flag not in kind.run_options:
            raise InputError(flag, value, f"no {flag} for {preset}: it is a {kind.name} preset "
                             f"({flag} applies to {', '.join(applies_to(flag)) or 'no'} presets)")
    fields = dict(kind.overrides)
    overrides = tuple(Override(fields[flag], value, flag) for flag, value in given.items()
                      if flag in fields and value is not None)
    spec = load_document(doc, path.parent, overrides)
    flags = {FLAG_ARGUMENTS[flag]: value for flag, value in given.items()
             if flag in kind.run_options and flag not in fields and value is not None}
    resolve(kind.solve)(spec, csv_file, plot, as_json, figure=figure_path, **flags)


#: ``vtool solve``'s run flags and the keyword that carries each to a kind's solve function
FLAG_ARGUMENTS = {"--backend": "backend", "--dt": "dt", "--rpm": "rpm", "--degrees": "degrees",
                  "--max-steps": "max_steps", "--every-step": "every_step", "--events": "show_events",
                  "--impact": "impact", "--start": "start", "--orders": "orders", "--format": "file_format"}


def applies_to(flag: str) -> list[str]:
    """The preset kinds whose ``vtool solve`` takes ``flag`` (the kinds table's run options)."""
    from vtool.presets.kinds import KINDS

    return [name for name, kind in KINDS.items() if flag in kind.run_options]


def run_valvetrain(spec: Any, csv_path: Path | None, plot: bool, as_json: bool, *, every_step: bool = False,
                   show_events: bool = False, max_steps: float | None = None, figure: Path | None = None,
                   orders: str | None = None, file_format: str | None = None) -> None:
    """``vtool solve`` for a valvetrain preset (its flags that are preset fields already in ``spec``): the
    run and its summary."""
    from vtool.app.cli.progress import DelayedProgress
    from vtool.files import json_text
    from vtool.solvers.run import simulate

    parquet = False
    if csv_path is not None:
        from vtool.solvers.parquet import output_format

        parquet = output_format(csv_path, file_format) == "parquet"  # pyarrow checked before the run
    progress = DelayedProgress(f"{spec.run.backend} {spec.run.degrees:g} deg")

    def before_run() -> None:  # the input is checked: announce a compile, if one is to come
        if announce_compile(spec, csv=csv_path is not None and every_step):
            progress.tick()  # elapsed seconds on a terminal until the run's first progress

    try:
        if csv_path is None:
            trace = simulate(spec, every_step=every_step, progress=progress, max_steps=max_steps,
                             before_run=before_run)
        elif parquet:  # row groups to the temporary file as the run makes them; renamed at the end
            from vtool.files import open_atomic_binary
            from vtool.solvers.parquet import ParquetStream

            with open_atomic_binary(csv_path, "--out") as binary:
                parquet_stream = ParquetStream(binary, spec.run.quantities, thin=every_step, title=spec.title)
                stream: CsvStream = parquet_stream
                try:
                    trace = simulate(spec, every_step=every_step, progress=progress, max_steps=max_steps,
                                     stream=stream, before_run=before_run)
                finally:  # the writer's footer goes to the temporary file before it is renamed (or removed)
                    parquet_stream.close()
        else:  # rows go to the temporary file as the run makes them; renamed over the target at the end
            from vtool.files import open_atomic
            from vtool.solvers.trace import CsvStream

            with open_atomic(csv_path, "--csv") as handle:
                stream = CsvStream(handle, spec.run.quantities, thin=every_step)
                trace = simulate(spec, every_step=every_step, progress=progress, max_steps=max_steps,
                                 stream=stream, before_run=before_run)
    finally:
        progress.close()
    from vtool.solvers.studies.metrics import evaluation_summary

    evaluation = evaluation_summary(trace)
    spectrum = None
    if orders is not None:
        from vtool.solvers.studies.orders import spectrum as order_spectrum

        spectrum = order_spectrum(trace, orders)
    if as_json:
        summary = trace.summary() | {"evaluation": evaluation}
        if spectrum is not None:
            summary["orders"] = spectrum.as_dict()
        click.echo(json_text(summary))
    else:
        click.echo(trace.summary_text())
        click.echo("")
        click.echo("\n".join(evaluation["lines"]))
        if spectrum is not None:
            from vtool.solvers.studies.orders import dominant_text, natural_frequencies

            click.echo("")
            click.echo(spectrum.table())
            click.echo(dominant_text(spectrum, natural_frequencies(trace)))
        if show_events:
            click.echo("")
            click.echo(trace.event_table())
        if csv_path is not None:
            click.echo(f"wrote {stream.rows} rows to {csv_path} ({stream.seconds:.1f} s formatting and writing)")
    if plot:
        from vtool.app.valvetrain_charts import all_charts

        click.echo(all_charts(trace))
        if spectrum is not None:
            from vtool.app.order_charts import order_chart
            from vtool.solvers.studies.orders import natural_frequencies

            click.echo(order_chart(spectrum, natural_frequencies(trace)))
    if figure is not None:
        from vtool.presets.charts import order_chart as order_chart_data
        from vtool.presets.charts import trace_charts

        charts = trace_charts(trace)
        if spectrum is not None:  # the --orders spectrum, natural frequencies marked
            from vtool.solvers.studies.orders import natural_frequencies

            charts.append(order_chart_data(spectrum, natural_frequencies(trace), subject=trace.spec.title))
        write_figure(charts, figure)


def announce_compile(spec: Any, csv: bool = False, impacts: tuple[str, ...] = ()) -> bool:
    """One line on stderr before a run that must first compile the solver (a new install's first run, or
    the first with Hertz contacts or momentum-law impacts), and one before the first every-step CSV
    compiles its number formatter (a few seconds, once). ``impacts``: further impact laws to be run.
    True when a line was shown."""
    from vtool.solvers.backends import get

    notices = [get(spec.run.backend).compile_notice(spec, impacts)]
    if csv:
        from vtool.csvrows import compile_notice as csv_notice

        notices.append(csv_notice())
    for notice in notices:
        if notice:
            click.echo(notice, err=True)
    return any(notices)
