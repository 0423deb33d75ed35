"""The ``vtool`` command: a root click group whose subcommands load lazily.

Each subcommand lives in its own module under :mod:`vtool.app.cli`; the
table :data:`COMMANDS` maps its name to ``module:attribute`` so that
``vtool --help`` imports none of the heavy numerical code.

User mistakes (:class:`vtool.errors.InputError`, click usage errors) end with a
one-line message on stderr and exit code 2; a failed run
(:class:`vtool.errors.RunError`) ends with its message and exit code 1. No
traceback is shown for either. Notes (:class:`vtool.errors.PresetNote`: what a loader assumed or
converted) are one ``note: ...`` line each, once. Warnings (:class:`vtool.errors.PresetWarning`)
are one ``warning: ...`` line each on stderr.

Start-up: a ``vtool solve`` process creates about 120,000 long-lived objects
while importing numpy and numba and loading the cached kernel; with Python's
default collector thresholds they are rescanned by several full collections
during the run and once more at interpreter exit, about 0.3 s of a 1.3 s
process (benchmarks/bench_newmark.py, the second-process line). :func:`main`
raises the first threshold (:data:`GC_THRESHOLDS`: cyclic garbage is still
collected, only less often) and freezes the survivors before the interpreter
exits (:func:`gc.freeze`), so that the exit does not scan them again.

Signals: SIGTERM (what ``timeout``, ``kill`` and a cancelled CI job send) is
handled like Ctrl+C (:class:`Terminated`, a KeyboardInterrupt): every file
being written is cleaned up the same way (no hidden temporary is left, an
existing output is kept), the message is ``terminated: ...`` and the exit
code 143 (128 + 15). Both signals raise their interrupt where Python is, except inside code
that cannot unwind it (:func:`_held_back`) or while a file of numba's cache is being written
(:func:`_writing_cache`), where it is delivered again 20 ms later: Ctrl+C always ends with the one
line and 130 (143), never with a traceback, a lost interrupt or a half-written file.
"""

from __future__ import annotations

import gc
import importlib
import importlib.util
import os
import signal
import sys
import threading
import warnings
from typing import Any

import click

from vtool import __version__
from vtool.errors import InputError, PresetNote, PresetWarning, RunError, one_line

#: Collector thresholds for a command-line process (see the module doc); Python's default is (700, 10, 10).
GC_THRESHOLDS = (100_000, 50, 100)

COMMANDS: dict[str, tuple[str, str]] = {
    "solve": ("vtool.app.cli.solve", "solve"),
    "modes": ("vtool.app.cli.modes", "modes"),
    "presets": ("vtool.app.cli.presets", "presets"),
    "boom": ("vtool.app.cli.boom", "boom"),
    "plate": ("vtool.app.cli.plate", "plate"),
    "accuracy": ("vtool.app.cli.accuracy", "accuracy"),
    "sweep": ("vtool.app.cli.sweep", "sweep"),
    "compare": ("vtool.app.cli.compare", "compare"),
    "cam": ("vtool.app.cli.cam", "cam"),
    "camshaft": ("vtool.app.cli.camshaft", "camshaft"),
    "size": ("vtool.app.cli.size", "size"),
    "report": ("vtool.app.cli.report", "report"),
    "tui": ("vtool.app.cli.tui", "tui"),
}


#: Seconds after which an interrupt that arrived inside code that cannot take it is delivered again.
RETRY_SECONDS = 0.02
#: The file name of code run by exec or eval from a string; llvmlite's bindings, whose Python callbacks
#: LLVM calls from C through ctypes (numba's compile hands it its object-code cache).
_STRING_SOURCE = "<string>"
_CALLBACKS = f"{os.sep}llvmlite{os.sep}binding{os.sep}"


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is, so that it unwinds exactly as Ctrl+C does."""


def _held_back(frame: Any) -> bool:
    """Whether the frame, or one that called it up to :func:`main`, cannot take an interrupt.

    * Source run by ``exec`` or ``eval`` from a string (dataclasses, namedtuple, scipy's imports do it):
      an interrupt leaving such code makes CPython remember it as unhandled even when it is handled
      later, and ``python -m vtool`` then ends by SIGINT itself (returncode -2) after the clean
      message and exit 130.
    * llvmlite's bindings: ctypes prints an exception raised in a callback from C ("Exception ignored
      on calling ctypes callback function") and drops it, so Ctrl+C during the compile was lost (the
      run went on and exited 0) or left numba without its object code (RuntimeError, exit 1).
    """
    while frame is not None and frame.f_code is not main.__code__:
        name = frame.f_code.co_filename
        if name == _STRING_SOURCE or _CALLBACKS in name:
            return True
        frame = frame.f_back
    return False


def _writing_cache() -> bool:
    """Whether this process holds a temporary file of numba's cache folder open: numba writes each cache
    file under a temporary name (``NAME.tmp.ID``) and renames it when whole, and removes it on an error but
    not on an interrupt, which left it in the folder. (Linux's ``/proc/self/fd``; elsewhere False.)"""
    cache = sys.modules.get("vtool.numba_cache")  # not imported: nothing compiles
    folder = getattr(cache, "FOLDER", None)
    if folder is None:
        return False
    try:
        descriptors = os.listdir("/proc/self/fd")
    except OSError:
        return False
    for descriptor in descriptors:
        try:
            target = os.readlink(f"/proc/self/fd/{descriptor}")
        except OSError:
            continue
        if target.startswith(os.path.join(folder, "")) and ".tmp." in os.path.basename(target):
            return True
    return False


def _interrupt(signum: int, frame: Any) -> None:
    """SIGINT and SIGTERM: KeyboardInterrupt (:class:`Terminated`) where the program is, or the same signal
    again :data:`RETRY_SECONDS` later when it is where the interrupt cannot unwind (:func:`_held_back`) or
    while a cache file is being written (:func:`_writing_cache`)."""
    if frame is not None and (_held_back(frame) or _writing_cache()):
        deliver_again(signum)
        return
    raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def deliver_again(signum: int, seconds: float = RETRY_SECONDS) -> None:
    """Send this process ``signum`` again after ``seconds`` (from a daemon thread): a handler that cannot
    raise its interrupt where the program is leaves it to the next delivery."""
    again = threading.Timer(seconds, os.kill, (os.getpid(), signum))
    again.daemon = True
    again.start()


def _interrupted(exc: BaseException | None) -> tuple[str, int]:
    """The word and exit code of an interrupt: Ctrl+C 130, SIGTERM 143."""
    while exc is not None and not isinstance(exc, KeyboardInterrupt):
        exc = exc.__cause__ or exc.__context__
    return ("terminated", 128 + signal.SIGTERM) if isinstance(exc, Terminated) else ("interrupted", 130)


def _installed_commands() -> list[str]:
    return [name for name, (module, _) in COMMANDS.items() if importlib.util.find_spec(module)]


class LazyGroup(click.Group):
    """A group whose subcommands are imported only when invoked."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return _installed_commands()

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in COMMANDS or cmd_name not in _installed_commands():
            return None
        module, attribute = COMMANDS[cmd_name]
        return getattr(importlib.import_module(module), attribute)

    def invoke(self, ctx: click.Context):
        with warnings.catch_warnings():
            # a library's deprecation notice is not the user's business: only our warnings are shown
            warnings.simplefilter("ignore", DeprecationWarning)
            warnings.simplefilter("ignore", PendingDeprecationWarning)
            warnings.simplefilter("always", PresetWarning)
            warnings.simplefilter("default", PresetNote)  # once per text: a sweep loads the preset per point
            warnings.showwarning = _show_warning
            try:
                return super().invoke(ctx)
            except InputError as exc:
                click.echo(f"error: {exc.one_line()}", err=True)
                ctx.exit(2)
            except RunError as exc:
                word, code = _interrupted(exc)
                if code != 130:  # an interrupted study said where its finished part is: same words, SIGTERM's code
                    click.echo(f"{word}: {one_line(str(exc), 400).removeprefix('interrupted: ')}", err=True)
                    ctx.exit(code)
                click.echo(f"run failed: {one_line(str(exc), 400)}", err=True)
                ctx.exit(1)

    def main(self, *args: Any, **kwargs: Any) -> Any:
        """click's main, with usage errors on one line (``error: ...``, exit 2) instead of four."""
        standalone = kwargs.pop("standalone_mode", True)
        try:
            result = super().main(*args, standalone_mode=False, **kwargs)  # type: ignore[call-overload]  # click's overloads take no *args
            code = result if isinstance(result, int) else 0
        except click.exceptions.UsageError as exc:
            where = f" (see `{exc.ctx.command_path} --help`)" if exc.ctx is not None else ""
            click.echo(f"error: {one_line(exc.format_message(), 300)}{where}", err=True)
            code = 2
        except click.ClickException as exc:
            click.echo(f"error: {one_line(exc.format_message(), 300)}", err=True)
            code = exc.exit_code
        except (click.exceptions.Abort, KeyboardInterrupt) as exc:  # click turns an interrupt into Abort
            word, code = _interrupted(exc)
            click.echo(f"{word}: nothing was written", err=True)
        if standalone:
            sys.exit(code)
        return code


def _show_warning(message: Warning | str, category: type[Warning], *args: Any, **kwargs: Any) -> None:
    """Every warning as one line on stderr: ``warning: ...`` (a :class:`PresetNote`: ``note: ...``)."""
    word = "note" if issubclass(category, PresetNote) else "warning"
    click.echo(f"{word}: {one_line(str(message), 400)}", err=True)


@click.group(cls=LazyGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="vtool")
def cli() -> None:
    """vtool: valve-train dynamics with clearances, sonic-boom and plate checks.

    Presets are found by path or by shipped name (see `vtool presets list`).
    """


def install_signal_handlers() -> None:
    """SIGINT and SIGTERM raise their interrupt through :func:`_interrupt` (SIGTERM cleaned up like Ctrl+C:
    see the module doc). Main thread only (Python's rule for signal handlers)."""
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _interrupt)


def main() -> None:
    gc.set_threshold(*GC_THRESHOLDS)
    install_signal_handlers()
    try:
        cli(prog_name="vtool")
    finally:
        gc.freeze()  # what is left lives until exit: no final scan of it (see the module doc)


if __name__ == "__main__":
    main()
