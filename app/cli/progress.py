"""A progress bar for runs longer than a second (stderr, nothing for short runs or a non-terminal)."""

from __future__ import annotations

import sys
import time

import click


class DelayedProgress:
    """Callable taking the fraction done; draws a bar only once a second has passed."""

    def __init__(self, label: str, delay: float = 1.0) -> None:
        self.label = label
        self.delay = delay
        self.started = time.perf_counter()
        self.bar = None
        self.shown = 0
        # a bar on a file or pipe is one label with no newline, which would run into an error line
        self.interactive = sys.stderr.isatty()

    def __call__(self, fraction: float) -> None:
        if self.bar is None:
            if time.perf_counter() - self.started < self.delay or not self.interactive:
                return
            self.bar = click.progressbar(length=1000, label=self.label, file=sys.stderr)
            self.bar.__enter__()
        done = int(1000 * min(max(fraction, 0.0), 1.0))
        self.bar.update(done - self.shown)
        self.shown = done

    def close(self) -> None:
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
