"""Camshaft presets on the command line: ``vtool solve PRESET`` for the ``camshaft`` kind
(:func:`solve_preset`, named by presets/kinds.py), and ``vtool camshaft PRESET``, the same run under the
command's older name, kept as an alias (it takes only camshaft presets).

Both print the summed drive torque's mean, extremes, each valve's share and the largest cam orders
(``--json``: the summary), write each valve's torque and the sum against camshaft angle (``--csv``),
draw the torque in the terminal (``--plot``) or as a figure (``--figure out.png|svg|pdf``; axes with
units). ``--rpm`` sets ``camshaft.rpm`` (every train at this cam speed); ``--max-steps`` is each train's
cost limit, as for a valve train.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import click

from vtool.app.cli.options import OUTPUT, figure_option, json_alone, write_figure


def solve_preset(spec: Any, csv_path: Path | None, plot: bool, as_json: bool, *, figure: Path | None = None,
                 max_steps: float | None = None) -> None:
    """Run a camshaft preset's trains, sum the valves' torques, print, write and draw (module doc)."""
    from vtool.app.cli.progress import DelayedProgress
    from vtool.files import write_atomic
    from vtool.presets.camshaft import camshaft_chart, solve
    from vtool.solvers.studies.camshaft import camshaft_csv_text, camshaft_text

    progress = DelayedProgress(f"camshaft, {len({v.path for v in spec.valves})} train run(s)")
    try:
        result = solve(spec, progress=progress, max_steps=max_steps)
    finally:
        progress.close()
    if csv_path is not None:
        write_atomic(csv_path, camshaft_csv_text(result), field="--csv")
    if as_json:
        click.echo(json.dumps({"title": spec.title} | result.summary(), indent=2))
    else:
        click.echo(spec.title)
        click.echo(camshaft_text(result))
    if plot:
        import shutil

        from vtool.app.plots import chart_text

        width = min(max(shutil.get_terminal_size((100, 24)).columns, 60), 160)
        click.echo(chart_text(camshaft_chart(spec.title, result), width=width, height=24))
    if figure is not None:
        write_figure([camshaft_chart(spec.title, result)], figure)


@click.command()
@click.argument("preset")
@click.option("--rpm", type=float, help="Cam speed of every train (rev/min); default: the preset's camshaft.rpm.")
@click.option("--json", "as_json", is_flag=True, help="Print the summary as JSON.")
@click.option("--csv", "csv_path", type=OUTPUT,
              help="Also write the torque against cam angle, each valve's and the sum (header names units).")
@click.option("--plot", is_flag=True, help="Draw the summed torque and each valve's in the terminal (not with --json).")
@figure_option
def camshaft(preset: str, rpm: float | None, as_json: bool, csv_path: Path | None, plot: bool,
             figure_path: Path | None) -> None:
    """Run each valve's train once (a camshaft preset: a shipped name or a file), shift each valve's cam
    drive torque by its phase and sum them: the same as `vtool solve PRESET` for a camshaft preset."""
    from vtool.presets import Override, load_preset
    from vtool.presets.kinds import require_kind

    json_alone(as_json, plot=plot)
    overrides = () if rpm is None else (Override("camshaft.rpm", rpm, "--rpm"),)
    spec = load_preset(preset, overrides)
    require_kind(spec, "camshaft", "vtool camshaft")
    solve_preset(spec, csv_path, plot, as_json, figure=figure_path)
