"""``vtool cam show PRESET [--plot] [--json] [--csv FILE]``: the cam's lift, its fit, spectrum and derivatives,
and with a follower the cam's shape."""

from __future__ import annotations

import json
from pathlib import Path

import click

from vtool.app.cli.options import OUTPUT, figure_option, json_alone, write_figure
from vtool.errors import InputError


@click.group()
def cam() -> None:
    """Cam profiles: lift tables, their Fourier fit and spectrum."""


@cam.command("show")
@click.argument("preset")
@click.option("--plot", is_flag=True, help="Draw lift, velocity, acceleration and jerk against cam angle.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@click.option("--csv", "csv_path", type=OUTPUT,
              help="With a [follower]: write the ground profile (polar and Cartesian, curvature) for grinding.")
@figure_option
def show(preset: str, plot: bool, as_json: bool, csv_path: Path | None, figure_path: Path | None) -> None:
    """Fit error, velocity/acceleration/jerk extremes at the preset's speed, the
    acceleration spectrum, and warnings where a lift table's acceleration jumps.
    With a follower ([follower] or a train type): the cam's shape, radius of
    curvature, undercut, pressure angle and a finger's ratio."""
    from vtool.presets import load_preset
    from vtool.solvers.model.cam import cam_report, report_text

    json_alone(as_json, plot=plot)
    spec = load_preset(preset)
    from vtool.presets.kinds import require_kind

    require_kind(spec, "valvetrain", "`vtool cam`")
    if csv_path is not None:  # the path was checked when the command line was read (options.OUTPUT)
        if spec.follower is None:
            raise InputError("--csv", csv_path, "a preset with a [follower] (the profile needs its geometry)")
    report = cam_report(spec)
    if spec.follower is not None:
        from vtool.solvers.model.camshape import shape_report

        report["shape"] = shape_report(spec)
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
        if "shape" in report:
            from vtool.solvers.model.camshape import shape_text

            click.echo(shape_text(report["shape"]))
    if csv_path is not None:
        from vtool.files import write_atomic
        from vtool.solvers.model.camshape import profile_csv_text

        write_atomic(csv_path, profile_csv_text(spec), "--csv")
        if not as_json:
            click.echo(f"wrote the cam profile to {csv_path}")
    if plot or figure_path is not None:
        from vtool.app.plots import chart_text
        from vtool.presets.charts import cam_charts, cam_shape_charts

        charts = cam_charts(spec) + (cam_shape_charts(spec) if spec.follower is not None else [])
        from vtool.presets.cam_scan import preset_scan

        scan = preset_scan(preset, spec.unit_system)
        if scan is not None:  # a measured scan: raw against smoothed derivatives
            from vtool.presets.charts import scan_charts

            charts = scan_charts(scan, spec.unit_system.length, spec.title) + charts
        if plot:
            click.echo("\n".join(chart_text(chart, height=14) for chart in charts))
        write_figure(charts, figure_path)
