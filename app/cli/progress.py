"""A progress bar for runs longer than a second (stderr, nothing for short runs or a non-terminal), and
the elapsed seconds of a compile before it."""

from __future__ import annotations

import sys
import threading
import time
from typing import Any

import click


class DelayedProgress:
    """Callable taking the fraction done; draws a bar only once a second has passed."""

    def __init__(self, label: str, delay: float = 1.0) -> None:
        self.label = label
        self.delay = delay
        self.started = time.perf_counter()
        self.bar: Any = None  # click's progress bar, once shown
        self.shown = 0
        # a bar on a file or pipe is one label with no newline, which would run into an error line
        self.interactive = sys.stderr.isatty()
        self.ticker: tuple[threading.Event, threading.Thread] | None = None

    def tick(self) -> None:
        """Show the seconds elapsed on stderr, once a second, until the first progress (a compile before
        the run's first chunk); on a terminal only, nothing on a pipe or file."""
        if not self.interactive or self.ticker is not None:
            return
        stop = threading.Event()
        started = time.perf_counter()

        def show() -> None:
            while not stop.wait(1.0):
                sys.stderr.write(f"\r  compiling... {time.perf_counter() - started:.0f} s")
                sys.stderr.flush()

        self.ticker = (stop, threading.Thread(target=show, daemon=True))
        self.ticker[1].start()

    def _stop_ticking(self) -> None:
        if self.ticker is not None:
            stop, thread = self.ticker
            stop.set()
            thread.join()
            sys.stderr.write("\r\033[K")  # the line cleared
            sys.stderr.flush()
            self.ticker = None

    def __call__(self, fraction: float) -> None:
        self._stop_ticking()
        if self.bar is None:
            if time.perf_counter() - self.started < self.delay or not self.interactive:
                return
            self.bar = click.progressbar(length=1000, label=self.label, file=sys.stderr)
            self.bar.__enter__()
        done = int(1000 * min(max(fraction, 0.0), 1.0))
        self.bar.update(done - self.shown)
        self.shown = done

    def close(self) -> None:
        self._stop_ticking()
        if self.bar is not None:
            self.bar.__exit__(None, None, None)
