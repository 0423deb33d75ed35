"""``vtool cam show PRESET [--plot] [--json]``: the cam's lift, its fit, spectrum and derivatives."""

from __future__ import annotations

import json

import click

from vtool.errors import InputError


@click.group()
def cam() -> None:
    """Cam profiles: lift tables, their Fourier fit and spectrum."""


@cam.command("show")
@click.argument("preset")
@click.option("--plot", is_flag=True, help="Draw lift, velocity, acceleration and jerk against cam angle.")
@click.option("--json", "as_json", is_flag=True, help="Print the report as JSON.")
@click.option("--csv", "csv_path", type=click.Path(),
              help="With a [follower]: write the ground profile (polar and Cartesian, curvature) for grinding.")
def show(preset: str, plot: bool, as_json: bool, csv_path: str | None) -> None:
    """Fit error, velocity/acceleration/jerk extremes at the preset's speed, the
    acceleration spectrum, and warnings where a lift table's acceleration jumps.
    With a follower ([follower] or a train type): the cam's shape, radius of
    curvature, undercut, pressure angle and a finger's ratio."""
    from vtool.presets import load_preset
    from vtool.solvers.model.cam import cam_report, report_text

    spec = load_preset(preset)
    from vtool.presets.kinds import require_kind

    require_kind(spec, "valvetrain", "`vtool cam`")
    if csv_path is not None:
        from vtool.files import check_output_path

        check_output_path(csv_path, "--csv")
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
    if plot:
        click.echo(_charts(spec))
        if spec.follower is not None:
            click.echo(_shape_charts(spec))


def _charts(spec) -> str:  # type: ignore[no-untyped-def]
    import math

    import numpy as np

    from vtool.app.plots import line_chart
    from vtool.solvers.model.cam import cam_fit, derivatives

    fit = cam_fit(spec.cam)
    u = spec.unit_system.length
    omega = spec.run.rpm * math.pi / 30.0
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


def _shape_charts(spec) -> str:  # type: ignore[no-untyped-def]
    """The ground profile (x-y) and its radius of curvature and pressure angle against cam angle."""
    import numpy as np

    from vtool.app.plots import line_chart
    from vtool.solvers.model.camshape import cam_profile, contact

    u = spec.unit_system.length
    profile = cam_profile(spec.follower, spec.lift_law, 720)
    c = contact(spec.follower, spec.lift_law, np.radians(profile.law_angle_deg))
    rho = np.clip(profile.curvature_radius, -5 * spec.follower.base_radius, 5 * spec.follower.base_radius)
    return "\n".join([
        line_chart(np.append(profile.x, profile.x[0]), {"profile": np.append(profile.y, profile.y[0])},
                   title=f"cam profile ({u}, cam frame)", xlabel=f"x ({u})", height=20),
        line_chart(profile.law_angle_deg, {"radius of curvature": rho}, title=f"radius of curvature ({u}, clipped)",
                   xlabel="law angle (deg)", height=14),
        line_chart(c.cam_angle_deg, {"pressure angle": c.pressure_angle_deg}, title="pressure angle (deg)",
                   xlabel="cam angle (deg)", height=14)])
