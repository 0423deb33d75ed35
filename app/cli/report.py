"""``vtool report PRESET [--sweep FIELD=VALUES ...] -o report.pdf|html``: one document of a run.

The content (model, settings and version, summary and checks, figures, the
speed map of a sweep, the accuracy note) is :mod:`vtool.presets.report`'s;
:mod:`vtool.app.report` renders it. The output path is checked before any run.
"""

from __future__ import annotations

from pathlib import Path

import click


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
@click.option("--backend", help="Back end; default: the preset's run.backend.")
@click.option("--rpm", type=float, help="Cam speed (rev/min); default: the preset's run.rpm.")
@click.option("--degrees", type=float, help="Degrees of cam rotation; default: the preset's run.degrees.")
def report(preset: str, output: Path, sweep: tuple[str, ...], metric: str, workers: int, backend: str | None,
           rpm: float | None, degrees: float | None) -> None:
    """Write a report of PRESET (a valve train, a boom wall or floor, a plate study): model, settings,
    results and checks, figures, accuracy note. --sweep, --backend, --rpm and --degrees are a valve
    train's."""
    from vtool.app.cli.solve import announce_compile
    from vtool.app.report import write_report
    from vtool.presets import Override, load_preset
    from vtool.presets.kinds import kind_named, resolve

    # the flags are the preset's run fields: the loader checks them as the file's own values
    given = (("run.backend", backend, "--backend"), ("run.rpm", rpm, "--rpm"), ("run.degrees", degrees, "--degrees"))
    spec = load_preset(preset, tuple(Override(path, value, flag) for path, value, flag in given if value is not None))
    kind = kind_named(getattr(spec, "kind", None))
    if not kind.report:
        from vtool.errors import InputError
        from vtool.presets.kinds import KINDS

        raise InputError("preset", kind.name, "a preset of a kind with a report: "
                         + ", ".join(name for name, k in KINDS.items() if k.report))
    make = resolve(kind.report)
    content = make(spec, preset=preset, sweep=sweep, metric=metric, workers=workers,
                   before_run=lambda: announce_compile(spec))
    write_report(content, output)
    figures = len(content.figures)
    click.echo(f"wrote {output}: {len(content.sections)} sections, {figures} figures")
