"""``vtool tui [--preset NAME|PATH]``: the terminal application."""

from __future__ import annotations

import click


@click.command()
@click.option("--preset", default=None, help="Preset to open (shipped name or path); default: gnilka-1a.")
def tui(preset: str | None) -> None:
    """Interactive screens for the valve train, sonic boom and plate (keys: f1 for help)."""
    import gc

    from vtool.app.tui.app import create_app

    # a long-lived interactive process: what is imported is frozen (never scanned again) and the
    # collector passes less often; Textual's short-lived objects made its passes a sixth to a fifth
    # of the start-up (benchmarks/bench_tui_start.py measures it)
    gc.freeze()
    gc.set_threshold(10_000, 20, 20)
    create_app(preset).run()
