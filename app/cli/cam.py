"""``vtool cam show PRESET [--plot] [--json]``: the cam's lift, its fit, spectrum and derivatives."""

from __future__ import annotations

import json

import click


@click.group()
def cam() -> None:
    """Cam profiles: lift tables, their Fourier fit and spectrum."""


@cam.command("show")
@click.argument("preset")
@click.option("--plot", is_flag=True, help="Draw lift, velocity, acceleration and jerk against cam angle.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
def show(preset: str, plot: bool, as_json: bool) -> None:
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
    if plot:
        click.echo(_charts(spec))


def _charts(spec) -> str:  # type: ignore[no-untyped-def]

    import numpy as np

    from vtool.app.plots import line_chart
    from vtool.solvers.model.cam import cam_fit, derivatives

    fit = cam_fit(spec.cam)
    u = spec.unit_system.length
    omega = spec.run.omega
    angles = np.linspace(0.0, 360.0, 721)
    rows = derivatives(fit.c0, fit.a, fit.b, np.radians(angles))
    names = [f"lift ({u})", f"velocity ({u}/s)", f"acceleration ({u}/s^2)", f"jerk ({u}/s^3)"]
    charts = []
    for power, (name, values) in enumerate(zip(names, rows, strict=True)):
        series = {"Fourier series": values * omega**power}
        x = angles
        if power == 0 and spec.cam.angles:
            charts.append(line_chart(np.array(spec.cam.angles), {"table": np.array(spec.cam.lifts)},
                                     title=f"lift table ({u})", xlabel="cam angle (deg)", height=14))
        charts.append(line_chart(x, series, title=f"{name} at {spec.run.rpm:g} rpm",
                                 xlabel="cam angle (deg)", height=14))
    return "\n".join(charts)
