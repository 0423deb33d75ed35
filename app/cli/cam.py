"""``vtool cam show PRESET [--plot] [--json]``: the cam's lift, its fit, spectrum and derivatives."""

from __future__ import annotations

import json
from pathlib import Path

import click

from vtool.app.cli.options import figure_option, write_figure


@click.group()
def cam() -> None:
    """Cam profiles: lift tables, their Fourier fit and spectrum."""


@cam.command("show")
@click.argument("preset")
@click.option("--plot", is_flag=True, help="Draw lift, velocity, acceleration and jerk against cam angle.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@figure_option
def show(preset: str, plot: bool, as_json: bool, figure_path: Path | None) -> None:
    """Fit error, velocity/acceleration/jerk extremes at the preset's speed, the
    acceleration spectrum, and warnings where a lift table's acceleration jumps."""
    from vtool.presets import load_preset
    from vtool.solvers.model.cam import cam_report, report_text

    spec = load_preset(preset)
    from vtool.presets.kinds import require_kind

    require_kind(spec, "valvetrain", "`vtool cam`")
    report = cam_report(spec)
    if spec.seat is not None:
        from vtool.solvers.model.lash import lash_of

        report["seat_position"], report["lash"] = spec.seat.position, lash_of(spec)
    if as_json:
        click.echo(json.dumps(report, indent=2))
    else:
        click.echo(report_text(report))
        if spec.seat is not None:
            u = spec.unit_system.length
            click.echo(f"seat position {report['seat_position']:.6g} {u}, lash {report['lash']:.6g} {u}")
    if plot or figure_path is not None:
        from vtool.app.plots import chart_text
        from vtool.presets.charts import cam_charts

        charts = cam_charts(spec)
        from vtool.presets.cam_scan import preset_scan

        scan = preset_scan(preset, spec.unit_system)
        if scan is not None:  # a measured scan: raw against smoothed derivatives
            from vtool.presets.charts import scan_charts

            charts = scan_charts(scan, spec.unit_system.length, spec.title) + charts
        if plot:
            click.echo("\n".join(chart_text(chart, height=14) for chart in charts))
        write_figure(charts, figure_path)
