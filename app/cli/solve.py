"""``vtool solve PRESET``: the one batch entry point for every preset kind."""

from __future__ import annotations

import json
from pathlib import Path

import click

from vtool.app.cli.options import impact_option, start_velocities_option


@click.command()
@click.argument("preset")
@click.option("--backend", help="Back end (newmark, ...); default: the preset's.")
@click.option("--dt", type=float, help="Time step (s); default: the preset's.")
@click.option("--rpm", type=float, help="Cam speed (rev/min); default: the preset's.")
@click.option("--degrees", type=float, help="Degrees of cam rotation to run; default: the preset's.")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path),
              help="Write the response as CSV (per output interval, or per step with --every-step).")
@click.option("--every-step", is_flag=True, help="CSV rows at every time step (and event) instead of per degree.")
@click.option("--plot", is_flag=True, help="Draw force, displacement and configuration charts.")
@click.option("--json", "as_json", is_flag=True, help="Print the summary (with the event list) as JSON.")
@click.option("--events", "show_events", is_flag=True, help="Also print the event list.")
@impact_option
@start_velocities_option
def solve(preset: str, backend: str | None, dt: float | None, rpm: float | None, degrees: float | None,
          csv_path: Path | None, every_step: bool, plot: bool, as_json: bool, show_events: bool,
          impact: str | None, start: str | None) -> None:
    """Run a preset: a valve-train simulation, a sonic-boom assessment or a plate study.

    Valve train: prints the summary (separations and impacts per clearance,
    peak forces, valve seating velocities, bounces per revolution, run
    statistics). Files are written only when the run succeeds.
    """
    from vtool.presets import load_preset

    spec = load_preset(preset)
    if spec.kind != "valvetrain":
        given = [name for name, value in (("--backend", backend), ("--dt", dt), ("--rpm", rpm),
                                          ("--degrees", degrees), ("--impact", impact), ("--start", start))
                 if value is not None]
        if given or every_step or show_events:
            raise click.BadParameter(f"{', '.join(given) or '--every-step/--events'} applies to valvetrain "
                                     f"presets only; {preset} is a {spec.kind} preset", param_hint="options")
        module = "boom" if spec.kind.startswith("boom") else "plate"
        solve_preset = __import__(f"vtool.app.cli.{module}", fromlist=["solve_preset"]).solve_preset
        solve_preset(spec, csv_path, plot, as_json)
        return
    if impact is not None or start is not None:
        from vtool.solvers.compare import with_model

        spec = with_model(spec, impact, start)
    run_valvetrain(spec, backend, dt, rpm, degrees, csv_path, every_step, plot, as_json, show_events)


def run_valvetrain(spec, backend, dt, rpm, degrees, csv_path, every_step, plot, as_json,  # type: ignore[no-untyped-def]
                   show_events) -> None:
    from vtool.app.cli.progress import DelayedProgress
    from vtool.presets.valvetrain import with_run_overrides
    from vtool.solvers.run import simulate

    spec = with_run_overrides(spec, backend=backend, time_step=dt, rpm=rpm, degrees=degrees)
    announce_compile(spec.run.backend)
    progress = DelayedProgress(f"{spec.run.backend} {spec.run.degrees:g} deg")
    try:
        trace = simulate(spec, every_step=every_step, progress=progress)
    finally:
        progress.close()
    if csv_path is not None:
        trace.write_csv(str(csv_path))
    if as_json:
        click.echo(json.dumps(trace.summary(), indent=2))
    else:
        click.echo(trace.summary_text())
        if show_events:
            click.echo("")
            click.echo(trace.event_table())
        if csv_path is not None:
            click.echo(f"wrote {len(trace.time)} rows to {csv_path}")
    if plot:
        from vtool.app.valvetrain_charts import all_charts

        click.echo(all_charts(trace))


def announce_compile(backend: str) -> None:
    """One line on stderr before a run that must first compile the solver (a new install's first run)."""
    from vtool.solvers.newmark import compile_notice

    notice = compile_notice(backend)
    if notice:
        click.echo(notice, err=True)
