"""``vtool accuracy PRESET``: every back end over its accuracy knob, against the exact back end."""

from __future__ import annotations

from pathlib import Path

import click

from vtool.app.cli.options import OUTPUT


@click.command()
@click.argument("preset")
@click.option("--degrees", type=float, help="Degrees of cam rotation; default: the preset's.")
@click.option("--csv", "csv_path", type=OUTPUT, help="Also write the table as CSV.")
@click.option("--markdown", is_flag=True, help="Print the table as Markdown (for reports).")
def accuracy(preset: str, degrees: float | None, csv_path: Path | None, markdown: bool) -> None:
    """The speed/accuracy trade of a valve-train preset: Newmark (dt 1e-4 to 1e-7 s, beta 1/6 and 1/4)
    and scipy (rtol 1e-4 to 1e-11) against the exact back end: wall time, steps, events, and errors in
    event angles, peak contact forces, valve seating velocity and valve lift."""
    from vtool.presets import Override, load_preset
    from vtool.presets.kinds import require_kind
    from vtool.solvers.studies.accuracy import (
        accuracy_study,
        table_markdown,
        table_text,
        write_table_csv,
    )

    # --degrees is the preset's run.degrees: the loader checks it, as the file's own value
    spec = load_preset(preset, () if degrees is None else (Override("run.degrees", degrees, "--degrees"),))
    require_kind(spec, "valvetrain", "`vtool accuracy`")
    _, rows = accuracy_study(spec)
    unit = spec.unit_system.length
    click.echo(f"{spec.title}: {spec.run.degrees:g} degrees at {spec.run.rpm:g} rev/min, errors against the exact back end")
    click.echo(table_markdown(rows, unit) if markdown else table_text(rows, unit))
    if csv_path is not None:
        write_table_csv(str(csv_path), rows, unit)
        click.echo(f"wrote {csv_path}")
