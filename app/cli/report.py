"""``vtool report PRESET [--sweep FIELD=VALUES ...] -o report.pdf|html``: one document of a run.

The content (model, settings and version, summary and checks, figures, the
speed map of a sweep, the accuracy note) is :mod:`vtool.presets.report`'s;
:mod:`vtool.app.report` renders it. The output path is checked before any run.
"""

from __future__ import annotations

from pathlib import Path

import click

from vtool.app.cli.solve import _run_flag


def _output(ctx: click.Context, param: click.Parameter, value: str) -> Path:
    from vtool.app.report import check_report_path

    return check_report_path(value, "-o")


@click.command()
@click.argument("preset")
@click.option("-o", "--output", "output", required=True, callback=_output, type=click.Path(dir_okay=False),
              help="The report file: OUT.html (self-contained, inline SVG) or OUT.pdf.")
@click.option("--sweep", "sweep", multiple=True, metavar="FIELD=VALUES",
              help="Also sweep FIELD over VALUES (as `vtool sweep --set`; two give a speed map).")
@click.option("--metric", default="spring_margin", show_default=True, help="Metric of the sweep's map.")
@click.option("--workers", type=int, default=1, show_default=True, help="Local processes for the sweep.")
@click.option("--backend", help="Back end; default: the preset's.")
@click.option("--rpm", type=float, callback=_run_flag("rpm"), help="Cam speed (rev/min); default: the preset's.")
@click.option("--degrees", type=float, callback=_run_flag("degrees"),
              help="Degrees of cam rotation; default: the preset's.")
def report(preset: str, output: Path, sweep: tuple[str, ...], metric: str, workers: int, backend: str | None,
           rpm: float | None, degrees: float | None) -> None:
    """Write a report of a valve-train PRESET: model, settings, summary and checks, figures, accuracy."""
    from vtool.app.cli.solve import announce_compile
    from vtool.app.report import write_report
    from vtool.presets import load_preset
    from vtool.presets.kinds import require_kind
    from vtool.presets.report import valvetrain_report
    from vtool.presets.valvetrain import with_run_overrides

    spec = load_preset(preset)
    require_kind(spec, "valvetrain", "`vtool report`")
    if backend is not None:
        from vtool.solvers.backends import available

        if backend not in available():
            from vtool.errors import InputError

            raise InputError("--backend", backend, f"one of: {', '.join(available())}")
    spec = with_run_overrides(spec, backend=backend, rpm=rpm, degrees=degrees)
    content = valvetrain_report(spec, preset=preset, sweep=sweep, metric=metric, workers=workers,
                                before_run=lambda: announce_compile(spec))
    write_report(content, output)
    figures = len(content.figures)
    click.echo(f"wrote {output}: {len(content.sections)} sections, {figures} figures")
