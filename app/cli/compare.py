"""``vtool compare PRESET``: model choices (impact law, start velocities) side by side."""

from __future__ import annotations

import json
from pathlib import Path

import click

from vtool.app.cli.options import (
    OUTPUT,
    figure_option,
    impact_laws_option,
    start_option,
    write_figure,
)


@click.command()
@click.argument("preset")
@impact_laws_option
@start_option
@click.option("--degrees", type=float, help="Degrees of cam rotation; default: the preset's.")
@click.option("--csv", "csv_path", type=OUTPUT, help="Also write the table as CSV.")
@click.option("--json", "as_json", is_flag=True, help="Print the table as JSON.")
@click.option("--markdown", is_flag=True, help="Print the table as Markdown (for reports).")
@click.option("--plot", is_flag=True, help="Draw each clearance's contact force, one curve per variant.")
@figure_option
def compare(preset: str, impacts: tuple[str, ...], starts: tuple[str, ...] | None, degrees: float | None,
            csv_path: Path | None, as_json: bool, markdown: bool, plot: bool, figure_path: Path | None) -> None:
    """Run a valve-train preset under several impact laws (and start velocities) with the same back end and
    step, and print side by side: events, episodes per clearance (separations/impacts/bounces/flickers),
    the first throw-off angle in each revolution after the first, peak contact forces after the first
    revolution, valve seating velocities and the largest valve lift."""
    from vtool.files import write_atomic
    from vtool.markdown import table as markdown_table
    from vtool.presets import Override, load_preset
    from vtool.presets.kinds import require_kind
    from vtool.solvers.studies.compare import cell, table
    from vtool.solvers.studies.compare import compare as run_compare

    # --degrees is the preset's run.degrees: the loader checks it, as the file's own value
    spec = load_preset(preset, () if degrees is None else (Override("run.degrees", degrees, "--degrees"),))
    require_kind(spec, "valvetrain", "`vtool compare`")
    from vtool.app.cli.solve import announce_compile

    variants = run_compare(spec, impacts, starts, before_run=lambda: announce_compile(spec, impacts=impacts))
    header, rows = table(variants)
    if as_json:
        click.echo(json.dumps({"title": spec.title, "backend": spec.run.backend, "rpm": spec.run.rpm,
                               "degrees": spec.run.degrees, "episode_window_deg": 0.1,
                               "rows": [dict(zip(header, row, strict=True)) for row in rows]}, indent=2))
    else:
        click.echo(f"{spec.title}: {spec.run.degrees:g} degrees at {spec.run.rpm:g} rev/min, back end "
                   f"{spec.run.backend}; episodes: separations/impacts/bounces/flickers (events at one "
                   f"clearance within 0.1 deg are one)")
        text_rows = [[cell(value) for value in row] for row in rows]
        if markdown:
            click.echo(markdown_table(header, text_rows), nl=False)
        else:
            widths = [max(len(h), *(len(r[i]) for r in text_rows)) for i, h in enumerate(header)]
            click.echo("  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True)))
            for r in text_rows:
                click.echo("  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)))
    if csv_path is not None:
        import csv
        import io

        buffer = io.StringIO()
        writer = csv.writer(buffer)
        writer.writerow(header)
        writer.writerows([[cell(v) for v in row] for row in rows])
        write_atomic(csv_path, buffer.getvalue())
        if not as_json:
            click.echo(f"wrote {csv_path}")
    if plot or figure_path is not None:
        from vtool.app.plots import chart_text
        from vtool.presets.charts import compare_chart

        chart = compare_chart(variants)
        if plot and not as_json:
            click.echo(chart_text(chart))
        write_figure([chart], figure_path)
