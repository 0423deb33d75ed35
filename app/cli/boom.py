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

from vtool.errors import InputError

PULSE_CHOICES = ("N", "P", "Q", "R", "T")


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


def _fmt(value: float, digits: int = 4) -> str:
    return f"{value:.{digits}g}" if math.isfinite(value) else "inf"


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
@click.option("--damping", type=float, default=0.0, show_default=True, help="Damping ratio zeta, [0, 1).")
@click.option("--range", "grid", default="0:2.5:0.01", show_default=True, callback=_parse_range,
              help="tau/T values start:stop:step (inclusive).")
@click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
              help="Write the DAF curves to this CSV file.")
@click.option("--plot", is_flag=True, help="Draw the DAF curves in the terminal.")
def daf_command(kind: str, s: float, r1: float, r2: float | None, alpha: float | None,
                beta: float | None, pulse_csv: Path | None, envelope: bool, damping: float,
                grid: tuple[float, float, float], csv_path: Path | None, plot: bool) -> None:
    """DAF against tau/T (forced, free and overall) for one pulse, or an envelope."""
    import numpy as np

    from vtool.assessments.sonic_boom import fourier, pulses, response, spectra

    response.check_damping(damping)
    ratio = spectra.ratio_grid(*grid)
    if envelope:
        env_v = spectra.envelope(spectra.THESIS_ENVELOPE, ratio, "velocity", damping)
        env_x = spectra.envelope(spectra.THESIS_ENVELOPE, ratio, "displacement", damping)
        click.echo(f"source: {env_v.statement}")
        for env in (env_v, env_x):
            i = int(np.argmax(env.daf))
            click.echo(f"{env.quantity} DAF envelope: max {env.daf[i]:.6f} at tau/T = {ratio[i]:.4g} "
                       f"({env.governing[i]})")
        header = ["tau/T [-]", "velocity DAF envelope [-]", "velocity governing pulse",
                  "displacement DAF envelope [-]", "displacement governing pulse"]
        rows = [[f"{r:.6g}", f"{v:.10g}", gv, f"{x:.10g}", gx] for r, v, gv, x, gx in
                zip(ratio, env_v.daf, env_v.governing, env_x.daf, env_x.governing, strict=True)]
        series = {"velocity envelope": env_v.daf, "displacement envelope": env_x.daf}
        title = "DAF envelope (thesis family)"
    else:
        if pulse_csv is not None:
            pulse = pulses.read_pulse_csv(pulse_csv)
        else:
            pulse = pulses.make_pulse(pulses.PulseParams(kind, s, r1, r2, alpha, beta))
        res = response.peak_response(pulse, ratio, damping)
        damped = "undamped" if damping == 0.0 else f"damping ratio {damping:g}"
        click.echo(f"pulse: {pulse.label}, {damped}")
        if pulse.tau_seconds is not None:
            click.echo(f"  tabulated: tau = {pulse.tau_seconds:.6g} s (positive phase), "
                       f"p+ = {pulse.peak_pressure:.6g} (file units)")
        for quantity in response.QUANTITIES:
            click.echo(f"{quantity} DAF:")
            for line in _summary_lines(res, quantity):
                click.echo(line)
        fourier_free = fourier.free_amplitude(pulse, ratio) if damping == 0.0 else None
        if fourier_free is not None:
            gap = float(np.max(np.abs(fourier_free - res.velocity.free)))
            click.echo(f"free-motion amplitude by Fourier transform (appendix A): "
                       f"max |difference| = {gap:.2e}")
        header = ["tau/T [-]"]
        columns = []
        for quantity in response.QUANTITIES:
            pk = res.peaks[quantity]
            for phase, values in (("forced", pk.forced), ("free", pk.free), ("overall", pk.overall)):
                header.append(f"{quantity} DAF {phase} [-]")
                columns.append(values)
            header.append(f"{quantity} peak instant [t/tau]")
            columns.append(pk.overall_at)
        if fourier_free is not None:
            header.append("free amplitude Fourier [-]")
            columns.append(fourier_free)
        rows = [[f"{r:.6g}"] + [f"{c[i]:.10g}" for c in columns] for i, r in enumerate(ratio)]
        series = {"velocity overall": res.velocity.overall, "velocity forced": res.velocity.forced,
                  "displacement overall": res.displacement.overall}
        title = f"DAF of {pulse.label}"
    if csv_path is not None:
        _write_csv(csv_path, header, rows)
        click.echo(f"wrote {csv_path}")
    if plot:
        from vtool.app.plots import line_chart

        click.echo(line_chart(ratio, series, title=title, xlabel="tau/T", ylabel="DAF"))


def _write_csv(path: Path, header: list[str], rows: list[list[str]]) -> None:
    import csv
    import io

    from vtool.files import write_atomic

    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    write_atomic(path, buffer.getvalue())


def _preset_command(expected: str, name: str, preset: str, csv_path: Path | None, plot: bool,
                    as_json: bool) -> None:
    from vtool.presets import load_preset

    spec = load_preset(preset)
    if spec.kind != expected:
        raise InputError("preset", preset, f"a {expected} preset for `vtool boom {name}` (got {spec.kind})")
    solve_preset(spec, csv_path, plot, as_json)


_preset_options = [
    click.argument("preset"),
    click.option("--csv", "csv_path", type=click.Path(dir_okay=False, path_type=Path), default=None,
                 help="Write the allowable-pressure table to this CSV file."),
    click.option("--plot", is_flag=True, help="Draw the DAF and design curves in the terminal."),
    click.option("--json", "as_json", is_flag=True, help="Print the results as JSON."),
]


def _with_preset_options(func: Any) -> Any:
    for option in reversed(_preset_options):
        func = option(func)
    return func


@boom.command("wall")
@_with_preset_options
def wall_command(preset: str, csv_path: Path | None, plot: bool, as_json: bool) -> None:
    """Damage / safe-limit boom pressures for the walls of a boom_wall PRESET."""
    _preset_command("boom_wall", "wall", preset, csv_path, plot, as_json)


@boom.command("floor")
@_with_preset_options
def floor_command(preset: str, csv_path: Path | None, plot: bool, as_json: bool) -> None:
    """Annoyance boom pressures (tentative) for the floors of a boom_floor PRESET."""
    _preset_command("boom_floor", "floor", preset, csv_path, plot, as_json)


# ----------------------------------------------------------------------------
# shared by `vtool boom wall|floor` and `vtool solve`

_ROW_HEADER = ("structure", "frequency source", "f [Hz]", "tau [s]", "tau/T [-]", "criterion",
               "response", "DAF [-]")


def _report(assessment: Any) -> dict[str, Any]:
    u = assessment.units
    return {
        "kind": assessment.kind,
        "title": assessment.title,
        "units": u.name,
        "daf_source": assessment.source,
        "criteria": [c.describe() for c in assessment.criteria],
        "structures": [
            {"name": s.name, "frequencies_hz": s.frequencies, **s.details} for s in assessment.structures
        ],
        "limits": [
            {"structure": r.structure, "frequency_source": r.frequency_source, "frequency_hz": r.frequency,
             "tau_s": r.tau, "tau_over_T": r.ratio, "criterion": r.criterion, "response": r.response,
             "daf": r.daf, "limit_over_daf": r.normalized, f"pressure_{u.pressure}": r.pressure,
             f"pressure_{u.alt_pressure}": r.pressure_alt, "criterion_frequency_range_ok": r.in_range,
             "tentative": r.tentative}
            for r in assessment.rows
        ],
    }


def _structure_line(s: Any, u: Any) -> str:
    d = s.details
    parts = []
    if "pseudo_height" in d:
        parts.append(f"pseudo-height {d['pseudo_height']:.1f} {u.length}")
    if "flexural_rigidity" in d:
        parts.append(f"D {d['flexural_rigidity']:.4g} {u.force} {u.length}")
    if "mass_per_area" in d:
        parts.append(f"mass {d['mass_per_area']:.4g} {u.mass} per {u.length}^2")
    if "stiffness" in d:
        parts.append(f"k {d['stiffness']:.4g} {u.force}/{u.length}, mass {d['mass']:.4g} {u.mass}, "
                     f"loaded area {d['loaded_area']:.4g} {u.length}^2")
    freqs = ", ".join(f"{k} {v:.3f} Hz" for k, v in s.frequencies.items())
    return f"  {s.name}: {'; '.join(parts)}; f: {freqs}"


def solve_preset(spec: Any, csv_path: Path | None, plot: bool, as_json: bool) -> None:
    """Run a boom_wall / boom_floor preset: table (or JSON), optional CSV and charts."""
    from vtool.assessments.sonic_boom.assess import assess

    a = assess(spec)
    u = a.units
    p_cols = (f"limit/DAF [{u.length}/s | {u.length}]", f"p+ [{u.pressure}]", f"p+ [{u.alt_pressure}]")
    if as_json:
        click.echo(json.dumps(_report(a), indent=2))
    else:
        click.echo(a.title)
        click.echo(f"DAF source: {a.source}")
        click.echo(f"units: {u.name} (pressure {u.pressure}, also {u.alt_pressure}; g = {u.gravity:g} "
                   f"{u.length}/s^2)")
        click.echo("criteria:")
        for c in a.criteria:
            click.echo(f"  {c.describe()}")
        click.echo("structures:")
        for s in a.structures:
            click.echo(_structure_line(s, u))
        click.echo("allowable peak overpressure:")
        header = (*_ROW_HEADER, *p_cols, "note")
        table = [header]
        for r in a.rows:
            note = []
            if r.tentative:
                note.append("tentative")
            if not r.in_range:
                note.append("f outside criterion range")
            table.append((r.structure, r.frequency_source, f"{r.frequency:.3f}", f"{r.tau:g}",
                          f"{r.ratio:.4f}", r.criterion, r.response, f"{r.daf:.4f}",
                          _fmt(r.normalized), _fmt(r.pressure), _fmt(r.pressure_alt), ", ".join(note)))
        widths = [max(len(str(row[i])) for row in table) for i in range(len(header))]
        for row in table:
            click.echo("  " + "  ".join(str(c).ljust(w) for c, w in zip(row, widths, strict=True)).rstrip())
    if csv_path is not None:
        _write_csv(csv_path, *limits_csv_rows(a))
        if not as_json:
            click.echo(f"wrote {csv_path}")
    if plot:
        _plot(a)


def limits_csv_rows(a: Any) -> tuple[list[str], list[list[str]]]:
    """Header and rows of the allowable-pressure CSV (``vtool solve BOOM_PRESET --csv``, the TUI export)."""
    u = a.units
    p_cols = [f"limit/DAF [{u.length}/s | {u.length}]", f"p+ [{u.pressure}]", f"p+ [{u.alt_pressure}]"]
    rows = [[r.structure, r.frequency_source, f"{r.frequency:.10g}", f"{r.tau:.10g}", f"{r.ratio:.10g}",
             r.criterion, r.response, f"{r.daf:.10g}", f"{r.normalized:.10g}", f"{r.pressure:.10g}",
             f"{r.pressure_alt:.10g}"] for r in a.rows]
    return [*_ROW_HEADER, *p_cols], rows


def design_series(a: Any) -> list[tuple[str, Any, dict[str, Any]]]:
    """(structure, frequencies, {label: p+ in the alternative unit}) per distinct set of design curves.

    Structures with the same mass have identical curves; each distinct set is listed once.
    """
    u = a.units
    by_structure: dict[str, dict[str, Any]] = {}
    for curve in a.curves:
        by_structure.setdefault(curve.structure, {})[f"{curve.criterion}, tau={curve.tau:g}s"] = curve
    shown: set[tuple[float, ...]] = set()
    out = []
    for name, curves in by_structure.items():
        key = tuple(round(float(v), 12) for c in curves.values() for v in c.pressure[::20])
        if key in shown:
            continue
        shown.add(key)
        first = next(iter(curves.values()))
        out.append((name, first.frequency, {label: c.pressure * u.alt_per_pressure for label, c in curves.items()}))
    return out


def _plot(a: Any) -> None:
    """Design curves (thesis Figures 4 and 7): allowable p+ against frequency, per structure."""
    from vtool.app.plots import line_chart

    for name, frequency, series in design_series(a):
        click.echo(line_chart(frequency, series, title=f"{name}: allowable p+ against frequency",
                              xlabel="f [Hz]", ylabel=f"p+ [{a.units.alt_pressure}]"))
