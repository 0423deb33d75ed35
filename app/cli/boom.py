"""``vtool boom daf | wall PRESET | floor PRESET``: sonic-boom DAFs and pressure limits.

Thin commands: parse options, call :mod:`vtool.assessments.sonic_boom`,
print a table, optionally write a CSV and draw plotext charts. Heavy imports
stay inside the command bodies.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import click

from vtool.app.cli.options import OUTPUT, figure_option, json_alone, write_figure
from vtool.errors import InputError

PULSE_CHOICES = ("N", "P", "Q", "R", "T")
FAMILIES = ("thesis", "equal-rise")  # assessments.sonic_boom.spectra.FAMILIES, kept import-free


def _parse_range(ctx: click.Context, param: click.Parameter, value: str) -> tuple[float, float, float]:
    parts = value.split(":")
    try:
        start, stop, step = (float(p) for p in parts)
    except ValueError:
        raise click.BadParameter(f"got {value!r}, expected start:stop:step (tau/T, e.g. 0:2.5:0.01)") from None
    if not (math.isfinite(start) and math.isfinite(stop) and math.isfinite(step)):
        raise click.BadParameter(f"got {value!r}, expected finite start:stop:step")
    if start < 0.0 or stop < start or step <= 0.0:
        raise click.BadParameter(f"got {value!r}, expected 0 <= start <= stop and step > 0 (tau/T)")
    return start, stop, step


@click.group()
def boom() -> None:
    """Sonic-boom response of walls and floors (thesis 001, Part I)."""


def _summary_lines(res: Any, quantity: str) -> list[str]:
    import numpy as np

    pk = res.peaks[quantity]
    lines = []
    for phase, daf, at in (("overall", pk.overall, pk.overall_at), ("forced", pk.forced, pk.forced_at),
                           ("free", pk.free, pk.free_at)):
        i = int(np.argmax(daf))
        lines.append(f"  {phase:<8}max {daf[i]:.6f} at tau/T = {res.ratio[i]:.4g} "
                     f"(peak at t/tau = {at[i]:.4f})")
    return lines


@boom.command("daf")
@click.option("--type", "kind", type=click.Choice(PULSE_CHOICES), default="N", show_default=True,
              help="Idealized boom type (thesis Figure 1(b)).")
@click.option("--s", "s", type=float, default=2.0, show_default=True,
              help="Total / positive duration (>= 1).")
@click.option("--r1", type=float, default=0.0, show_default=True, help="Rise-time ratio t_r/tau, [0, 1).")
@click.option("--r2", type=float, default=None, help="Second rise-time ratio (P, T); type default if omitted.")
@click.option("--alpha", type=float, default=None, help="Negative-phase ratio (Q, R) or slope ratio (T).")
@click.option("--beta", type=float, default=None, help="Pressure ratio after T's rear shock.")
@click.option("--pulse-csv", type=click.Path(path_type=Path), default=None,
              help="Tabulated pressure history (time [s], pressure) instead of --type.")
@click.option("--envelope", is_flag=True, help="Envelope over the thesis' family (s 1.6-2.2, r1 0-0.5).")
@click.option("--family", type=click.Choice(FAMILIES), default="thesis", show_default=True,
              help="Envelope family: thesis (P r2=(s-1)r1) or equal-rise (P r2=r1).")
@click.option("--damping", type=float, default=0.0, show_default=True, help="Damping ratio zeta, [0, 1).")
@click.option("--range", "grid", default="0:2.5:0.01", show_default=True, callback=_parse_range,
              help="tau/T values start:stop:step (inclusive).")
@click.option("--csv", "csv_path", type=OUTPUT, default=None,
              help="Write the DAF curves to this CSV file.")
@click.option("--json", "as_json", is_flag=True, help="Print the DAF curves as JSON (units named).")
@click.option("--plot", is_flag=True, help="Draw the DAF curves in the terminal.")
@figure_option
def daf_command(kind: str, s: float, r1: float, r2: float | None, alpha: float | None,
                beta: float | None, pulse_csv: Path | None, envelope: bool, family: str,
                damping: float, grid: tuple[float, float, float], csv_path: Path | None,
                as_json: bool, plot: bool, figure_path: Path | None) -> None:
    """DAF against tau/T (forced, free and overall) for one pulse, or an envelope."""
    import numpy as np

    from vtool.assessments.sonic_boom import fourier, pulses, report, response, spectra

    json_alone(as_json, plot=plot)
    response.check_damping(damping)
    ratio = spectra.ratio_grid(*grid)
    lines: list[str] = []
    if envelope:
        spec = spectra.EnvelopeSpec(family=family)
        envs = [spectra.envelope(spec, ratio, q, damping) for q in ("velocity", "displacement")]
        lines.append(f"source: {envs[0].statement}")
        for env in envs:
            i = int(np.argmax(env.daf))
            lines.append(f"{env.quantity} DAF envelope: max {env.daf[i]:.6f} at tau/T = {ratio[i]:.4g} "
                         f"({env.governing[i]})")
        header, rows = report.envelope_daf_table(envs)
        document = report.envelope_daf_dict(envs)
        series = {f"{env.quantity} envelope": env.daf for env in envs}
        title = f"DAF envelope ({family} family)"
    else:
        if pulse_csv is not None:
            pulse = pulses.read_pulse_csv(pulse_csv)
        else:
            pulse = pulses.make_pulse(pulses.PulseParams(kind, s, r1, r2, alpha, beta))
        res = response.peak_response(pulse, ratio, damping)
        damped = "undamped" if damping == 0.0 else f"damping ratio {damping:g}"
        lines.append(f"pulse: {pulse.label}, {damped}")
        if pulse.tau_seconds is not None:
            lines.append(f"  tabulated: tau = {pulse.tau_seconds:.6g} s (positive phase), "
                         f"p+ = {pulse.peak_pressure:.6g} (file units)")
        for quantity in response.QUANTITIES:
            lines.append(f"{quantity} DAF:")
            lines += _summary_lines(res, quantity)
        fourier_free = fourier.free_amplitude(pulse, ratio) if damping == 0.0 else None
        gap = None
        if fourier_free is not None:
            gap = float(np.max(np.abs(fourier_free - res.velocity.free)))
            lines.append(f"free-motion amplitude by Fourier transform (appendix A): "
                         f"max |difference| = {gap:.2e}")
        header, rows = report.pulse_daf_table(res, fourier_free)
        document = report.pulse_daf_dict(res, pulse.tau_seconds, pulse.peak_pressure, gap)
        series = {"velocity overall": res.velocity.overall, "velocity forced": res.velocity.forced,
                  "displacement overall": res.displacement.overall}
        title = f"DAF of {pulse.label}"
    if csv_path is not None:
        _write(csv_path, report.csv_text(header, rows))
        lines.append(f"wrote {csv_path}")
    if as_json:
        click.echo(json.dumps(document, indent=2))
    else:
        click.echo("\n".join(lines))
    if plot or figure_path is not None:
        from vtool.app.plots import chart_text
        from vtool.presets.charts import daf_chart

        chart = daf_chart(ratio, series, title)
        if plot:
            click.echo(chart_text(chart))
        write_figure([chart], figure_path)


def _write(path: Path, text: str) -> None:
    """Write ``text`` atomically; a folder that cannot be written is an input error, not a traceback."""
    from vtool.assessments.sonic_boom.pulses import shorten
    from vtool.files import write_atomic

    try:
        write_atomic(path, text, "--csv")
    except OSError as exc:
        raise InputError("--csv", shorten(str(path), 80),
                         f"a file in an existing, writable folder ({exc.strerror})") from None


def _preset_command(expected: str, name: str, preset: str, csv_path: Path | None, plot: bool,
                    as_json: bool, figure_path: Path | None) -> None:
    json_alone(as_json, plot=plot)
    from vtool.presets import load_preset
    from vtool.presets.kinds import require_kind

    spec = load_preset(preset)  # a pulse CSV is found beside the preset
    require_kind(spec, expected, f"`vtool boom {name}`")
    solve_preset(spec, csv_path, plot, as_json, figure=figure_path)


_preset_options = [
    click.argument("preset"),
    click.option("--csv", "csv_path", type=OUTPUT, default=None,
                 help="Write the allowable-pressure table to this CSV file."),
    click.option("--plot", is_flag=True, help="Draw the DAF and design curves in the terminal."),
    click.option("--json", "as_json", is_flag=True, help="Print the results as JSON."),
    figure_option,
]


def _with_preset_options(func: Any) -> Any:
    for option in reversed(_preset_options):
        func = option(func)
    return func


@boom.command("wall")
@_with_preset_options
def wall_command(preset: str, csv_path: Path | None, plot: bool, as_json: bool,
                 figure_path: Path | None) -> None:
    """Damage / safe-limit boom pressures for the walls of a boom_wall PRESET."""
    _preset_command("boom_wall", "wall", preset, csv_path, plot, as_json, figure_path)


@boom.command("floor")
@_with_preset_options
def floor_command(preset: str, csv_path: Path | None, plot: bool, as_json: bool,
                 figure_path: Path | None) -> None:
    """Annoyance boom pressures (tentative) for the floors of a boom_floor PRESET."""
    _preset_command("boom_floor", "floor", preset, csv_path, plot, as_json, figure_path)


def solve_preset(spec: Any, csv_path: Path | None, plot: bool, as_json: bool, *,
                 figure: Path | None = None) -> None:
    """Run a boom_wall / boom_floor preset: table (or JSON), optional CSV and charts.

    Shared by ``vtool boom wall|floor`` and ``vtool solve``.
    """
    from vtool.assessments.sonic_boom import report
    from vtool.assessments.sonic_boom.assess import assess

    a = assess(spec)
    if csv_path is not None:
        _write(csv_path, report.limits_csv(a))
    if as_json:
        click.echo(json.dumps(report.limits_dict(a), indent=2))
    else:
        click.echo(report.limits_text(a))
        if csv_path is not None:
            click.echo(f"wrote {csv_path}")
    if plot or figure is not None:
        from vtool.app.plots import chart_text
        from vtool.presets.charts import boom_design_charts

        charts = boom_design_charts(a, getattr(spec, "title", ""))
        if plot:
            for chart in charts:
                click.echo(chart_text(chart))
        write_figure(charts, figure)
