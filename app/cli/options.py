"""Reusable click options whose callbacks turn strings into domain values (and refuse bad ones in one line)."""

from __future__ import annotations

from pathlib import Path

import click

from vtool.solvers.model.spec import IMPACT_LAWS, START_VELOCITIES


def _choices(field: str, allowed: tuple[str, ...]):
    def convert(ctx: click.Context, param: click.Parameter, value: str | None) -> tuple[str, ...] | None:
        if value is None:
            return None
        items = tuple(v.strip() for v in value.split(",") if v.strip())
        bad = [v for v in items if v not in allowed]
        if bad or not items:
            from vtool.errors import InputError

            raise InputError(field, value, f"a comma-separated list from: {', '.join(allowed)}")
        return items

    return convert


impact_laws_option = click.option(
    "--impact", "impacts", default=",".join(IMPACT_LAWS), show_default=True,
    callback=_choices("--impact", IMPACT_LAWS), help="Impact laws to compare (comma-separated).")
start_option = click.option(
    "--start", "starts", default=None, callback=_choices("--start", START_VELOCITIES),
    help=f"Start velocities to compare (comma-separated from {', '.join(START_VELOCITIES)}); default: the preset's.")


def _figure_path(ctx: click.Context, param: click.Parameter, value: str | None):
    if value is None:
        return None
    from vtool.app.figures import check_output

    return check_output(value, "--figure")


figure_option = click.option(
    "--figure", "figure_path", type=click.Path(dir_okay=False), callback=_figure_path,
    help="Also write the charts as a report figure: OUT.png, OUT.svg or OUT.pdf (axes with units, "
         "events marked, black-and-white readable).")


def write_figure(items, path) -> None:
    """Draw chart data to ``path`` (checked by the option) and say so on stderr."""
    if path is None:
        return
    from vtool.app.figures import save_figure

    save_figure(items, path)
    click.echo(f"wrote {path}", err=True)


class OutputPath(click.ParamType):
    """An output file path, checked when the command line is read, before any work
    (:func:`vtool.files.check_output_path`: an empty path, a missing or read-only folder, a folder,
    device, FIFO, socket or symbolic link at the path are refused in one line, exit 2)."""

    name = "path"

    def convert(self, value: object, param: click.Parameter | None, ctx: click.Context | None) -> Path:
        from vtool.files import check_output_path

        field = (param.opts[0] if param is not None and param.opts else "output")
        if param is not None and param.param_type_name == "argument":
            field = (param.name or "output").upper()
        return check_output_path(str(value), field)


#: The one type of every output-file option (``--csv`` of every command).
OUTPUT = OutputPath()


def json_alone(as_json: bool, **others: bool) -> None:
    """With ``--json`` the JSON document is alone on stdout: a chart flag beside it (``plot=True``,
    ``map=True`` for ``--plot``, ``--map``) is refused in one line before any work."""
    for name, given in others.items():
        if as_json and given:
            from vtool.errors import InputError

            flag = f"--{name}"
            raise InputError(flag, "with --json", f"one of --json (machine-readable stdout) or {flag}")
