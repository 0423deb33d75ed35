"""``vtool tui [--preset NAME|PATH]``: the terminal application."""

from __future__ import annotations

import click


@click.command()
@click.option("--preset", default=None, help="Preset to open (shipped name or path); default: gnilka-1a.")
def tui(preset: str | None) -> None:
    """Interactive screens for the valve train, sonic boom and plate (keys: f1 for help)."""
    from vtool.app.tui.app import create_app

    create_app(preset).run()
