"""``vtool camshaft PRESET [--json] [--csv FILE]``: several valve trains on one camshaft, their summed drive
torque, its mean, peak-to-peak and orders (presets/camshaft.py, solvers/studies/camshaft.py)."""

from __future__ import annotations

import json
from pathlib import Path

import click

from vtool.app.cli.options import OUTPUT


@click.command()
@click.argument("preset")
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON.")
@click.option("--csv", "csv_path", type=OUTPUT,
              help="Also write the torque against cam angle, each valve's and the sum (header names units).")
def camshaft(preset: str, as_json: bool, csv_path: Path | None) -> None:
    """Run each valve's train once (a camshaft preset: a shipped name from presets/camshafts/ or a file),
    shift each valve's cam drive torque by its phase and sum them."""
    from vtool.files import write_atomic
    from vtool.presets.camshaft import load_camshaft, solve
    from vtool.solvers.studies.camshaft import camshaft_csv_text, camshaft_text

    spec = load_camshaft(preset)
    result = solve(spec)
    if csv_path is not None:
        write_atomic(csv_path, camshaft_csv_text(result), field="--csv")
    if as_json:
        click.echo(json.dumps({"title": spec.title} | result.summary(), indent=2))
    else:
        click.echo(spec.title)
        click.echo(camshaft_text(result))
