"""``vtool tui [--preset NAME|PATH]``: the terminal application."""

from __future__ import annotations

import gc

import click

#: Python's collector thresholds in the TUI process (``gc.set_threshold``; Python's own: 700, 10, 10).
COLLECTOR_THRESHOLDS = (10_000, 20, 20)


def tune_collector() -> None:
    """For a long-lived interactive process: what is imported so far is frozen (never scanned again) and
    the collector passes less often. Textual's short-lived objects made its passes a sixth to a fifth of
    the start-up (``benchmarks/bench_tui_start.py`` measures it; the tests' processes use it too)."""
    gc.freeze()
    gc.set_threshold(*COLLECTOR_THRESHOLDS)


@click.command()
@click.option("--preset", default=None, help="Preset to open (shipped name or path); default: gnilka-1a.")
def tui(preset: str | None) -> None:
    """Interactive screens for the valve train, sonic boom, plate and camshaft (keys: f1 for help)."""
    from vtool.app.tui.app import create_app

    tune_collector()  # after the app's imports
    create_app(preset).run()
