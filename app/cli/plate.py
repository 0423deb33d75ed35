"""``vtool plate modes | transient | study PRESET``: condensed-plate checks.

Thin commands over :mod:`vtool.assessments.plate`: load the preset, build
or run, print the report, write CSV through :func:`vtool.files.write_atomic`
and draw charts through :func:`vtool.app.plots.line_chart`.
:func:`solve_preset` is what ``vtool solve PRESET`` calls for a plate preset.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import click

from vtool.app.cli.options import OUTPUT, figure_option, json_alone, write_figure
from vtool.errors import InputError

RK4_LIMIT = 2.8  # thesis eq. 44; kept here so --help needs no numerics


def _load_plate_spec(preset: str) -> Any:
    from vtool.presets import load_preset
    from vtool.presets.kinds import require_kind

    spec = load_preset(preset)
    require_kind(spec, "plate", "`vtool plate`")
    return spec


def _cases(spec: Any, case_name: str | None) -> list[Any]:
    cases = list(spec.study.cases)
    if case_name is None:
        return cases
    for case in cases:
        if case.name == case_name:
            return [case]
    raise InputError("--case", case_name, f"one of: {', '.join(c.name for c in cases)}")


def _wh(ctx: click.Context, param: click.Parameter, value: float) -> float:
    if not 0.01 <= value <= RK4_LIMIT:
        raise InputError("--wh", value, f">= 0.01 and <= {RK4_LIMIT} (omega_max*h, RK4 stability limit, "
                         "thesis eq. 44)")
    return value


def _width() -> int:
    return max(60, min(shutil.get_terminal_size((100, 24)).columns, 140))


csv_option = click.option("--csv", "csv_path", type=OUTPUT,
                          help="Also write the results to this CSV file (header names units).")
json_option = click.option("--json", "as_json", is_flag=True, help="Print JSON instead of tables.")


@click.group()
def plate() -> None:
    """Condensed-plate checks: 16/24-DOF elements, Irons/Guyan and IRS reduction,
    exact Navier references, transient accuracy against cost (thesis 001, Part II)."""


@plate.command("modes")
@click.argument("preset")
@click.option("--case", "case_name", help="Only this case (default: every case of the preset).")
@click.option("--count", type=click.IntRange(1, 500), help="Number of lowest modes (default: the preset's).")
@csv_option
@json_option
def modes(preset: str, case_name: str | None, count: int | None, csv_path: Path | None, as_json: bool) -> None:
    """Lowest natural frequencies of each case against the exact ones (eq. 40), and omega_max."""
    from vtool.assessments.plate.model import build_model
    from vtool.assessments.plate.report import cases_modes_csv, modes_text
    from vtool.assessments.plate.vibration import free_vibration

    spec = _load_plate_spec(preset)
    plate_ = spec.study.plate
    n = count or spec.study.frequencies
    results = [(c, free_vibration(plate_, build_model(plate_, c), n)) for c in _cases(spec, case_name)]
    if as_json:
        click.echo(json.dumps([
            {"case": c.name, "KS": f.size, "modes": [[m.m, m.n] for m in f.exact],
             "exact_omega_rad_s": [m.omega for m in f.exact],
             "omega_rad_s": f.omega[: len(f.exact)].tolist(), "errors_pct": f.errors_pct.tolist(),
             "omega_max_over_omega11": f.omega_max_ratio} for c, f in results], indent=2))
    else:
        click.echo("\n\n".join(modes_text(f, c) for c, f in results))
    if csv_path is not None:
        _write(csv_path, cases_modes_csv([(c.name, f) for c, f in results]))
        click.echo(f"wrote {csv_path}", err=True)


def _chart(resp: Any, exact: Any, quantity: str) -> str:
    from vtool.app.plots import chart_text
    from vtool.presets.charts import plate_response_chart

    return chart_text(plate_response_chart(resp, exact, quantity), width=_width(), height=18)


@plate.command("transient")
@click.argument("preset")
@click.option("--case", "case_name", help="Case to run (default: the preset's first case).")
@click.option("--load", type=click.Choice(["uniform", "point"]), default="uniform", show_default=True,
              help="Step pressure over the plate, or step force P = p0*a*b at the centre.")
@click.option("--scheme", type=click.Choice(["rk4", "modal"]), default="rk4", show_default=True,
              help="RK4 at --wh, or exact modal integration of the reduced model.")
@click.option("--wh", type=float, default=1.0, show_default=True, callback=_wh,
              help="omega_max*h, the RK4 step parameter (stable up to 2.8; adequate at 1).")
@click.option("--periods", type=click.FloatRange(0.5, 20.0), default=None,
              help="Duration in exact fundamental periods (default: the preset's).")
@click.option("--modes", "exact_modes", type=click.IntRange(2, 1000), default=None,
              help="Modes of the exact reference (default: the preset's).")
@click.option("--plot/--no-plot", default=True, show_default=True, help="Draw the histories.")
@csv_option
@json_option
def transient(preset: str, case_name: str | None, load: str, scheme: str, wh: float,
              periods: float | None, exact_modes: int | None, plot: bool, csv_path: Path | None,
              as_json: bool) -> None:
    """Centre displacement, velocity and acceleration under a step load, against exact."""
    from vtool.assessments.plate.report import case_run_dict, case_run_text, response_csv
    from vtool.assessments.plate.study import run_case

    spec = _load_plate_spec(preset)  # with --json, the histories are not drawn (--plot is on by default)
    settings = spec.study.transient
    case = _cases(spec, case_name)[0]
    run = run_case(spec.study.plate, case, load, scheme, wh, periods or settings.periods,
                   exact_modes or settings.exact_modes)
    if csv_path is not None:
        _write(csv_path, response_csv(run.response, run.exact))
    if as_json:
        click.echo(json.dumps(case_run_dict(run), indent=2))
    else:
        click.echo(case_run_text(run))
        if plot:
            for q in ("displacement", "velocity", "acceleration"):
                click.echo(_chart(run.response, run.exact, q))
    if csv_path is not None:
        click.echo(f"wrote {csv_path}", err=True)


def _write(path: Path, text: str) -> None:
    """Write atomically; an unwritable path is an input error (one line), not a traceback."""
    from vtool.files import write_atomic

    try:
        write_atomic(path, text, "--csv")
    except OSError as exc:
        shown = str(path) if len(str(path)) <= 80 else str(path)[:77] + "..."
        raise InputError("--csv", shown, f"a file in an existing, writable folder ({exc.strerror})") from None


@plate.command("study")
@click.argument("preset")
@click.option("--transient/--no-transient", default=True, show_default=True,
              help="Include the transient runs (Tables 4 and 5).")
@click.option("--plot", is_flag=True, help="Draw the full model's histories against exact.")
@figure_option
@csv_option
@json_option
def study(preset: str, transient: bool, plot: bool, figure_path: Path | None, csv_path: Path | None,
          as_json: bool) -> None:
    """The thesis' Tables 2-5 regenerated: every case, its KS, errors and cost."""
    json_alone(as_json, plot=plot)
    spec = _load_plate_spec(preset)
    solve_preset(spec, csv_path, plot, as_json, transient=transient, figure=figure_path)


def solve_preset(spec: Any, csv_path: Path | None, plot: bool, as_json: bool, *,
                 transient: bool = True, figure: Path | None = None) -> None:
    """Run a plate preset's study: print its tables (or JSON), write CSV, draw charts.

    The batch entry point ``vtool solve PRESET`` calls this for plate presets.
    """
    from vtool.assessments.plate.report import study_csv, study_dict, study_text
    from vtool.assessments.plate.study import run_study

    if figure is not None and not transient:
        raise InputError("--figure", str(figure), "a study with its transient runs (not with --no-transient)")
    result = run_study(spec.study, transient=transient)
    if as_json:
        doc = {"title": spec.title, "units": spec.units, **study_dict(result)}
        click.echo(json.dumps(doc, indent=2))
    else:
        click.echo(spec.title)
        click.echo(study_text(result))
    if csv_path is not None:
        _write(csv_path, study_csv(result))
        click.echo(f"wrote {csv_path}", err=True)
    if (plot or figure is not None) and result.exact:
        from vtool.app.plots import chart_text
        from vtool.presets.charts import plate_study_charts

        charts = plate_study_charts(spec, result)
        if plot:
            for chart in charts:
                click.echo(chart_text(chart, width=_width(), height=18))
        write_figure(charts, figure)
    elif figure is not None:
        click.echo(f"warning: no transient runs in this study: {figure} not written", err=True)
