"""The vtool Textual application and the one factory that builds it.

``create_app`` is used by ``vtool tui``, by the tests and by the screenshot
script, so all three see the same app. One screen per domain, each a
Textual mode (f2 / f3 / f4): switching keeps each screen's form and results.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, ClassVar

from textual import events
from textual.app import App
from textual.binding import Binding, BindingType
from textual.screen import ModalScreen, Screen

from vtool.app.tui.base import DomainScreen
from vtool.app.tui.dialogs import ErrorDialog, HelpScreen, OpenDialog
from vtool.app.tui.recent import RecentFiles, default_path
from vtool.errors import InputError, RunError
from vtool.files import is_file
from vtool.presets.kinds import KINDS, kind_named, resolve


def screen_for_kind(kind: str) -> type[DomainScreen]:
    """The screen that shows presets of ``kind`` (the kinds table's screen module)."""
    return resolve(kind_named(kind).screen).SCREEN


#: the app's modes (one per screen, several kinds may share one), in the kinds table's order
SCREENS_BY_MODE: dict[str, type[DomainScreen]] = {screen_for_kind(kind).MODE: screen_for_kind(kind) for kind in KINDS}


def mode_for_kind(kind: str) -> str:
    return screen_for_kind(kind).MODE


class VtoolApp(App[None]):
    """Valve train, sonic boom, plate and camshaft screens over the vtool library."""

    CSS_PATH = "vtool.tcss"
    TITLE = "vtool"
    ENABLE_COMMAND_PALETTE = False
    HORIZONTAL_BREAKPOINTS: list[tuple[int, str]] | None = [(0, "-narrow"), (120, "-wide"), (170, "-huge")]
    MODES: ClassVar[dict[str, str | Callable[[], Screen[Any]]]] = dict(SCREENS_BY_MODE)
    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("ctrl+o", "open", "Open", priority=True),
        Binding("f1", "help", "Help"),
        Binding("f2", "switch_mode('valvetrain')", "Screen", key_display="f2-5",
                tooltip="f2 valve train, f3 sonic boom, f4 plate, f5 camshaft"),
        Binding("f3", "switch_mode('boom')", "Sonic boom", show=False),
        Binding("f4", "switch_mode('plate')", "Plate", show=False),
        Binding("f5", "switch_mode('camshaft')", "Camshaft", show=False),
        Binding("ctrl+q", "quit", "Quit", priority=True),
    ]

    def __init__(self, preset: str | None = None, *, recent: RecentFiles | None = None,
                 chart_color: bool = True) -> None:
        super().__init__()
        self.initial_preset = preset
        self.recent = recent if recent is not None else RecentFiles(None)
        self.chart_color = chart_color
        self._pending: dict[str, tuple[Any, str]] = {}
        self.mounted_modes: set[str] = set()
        self.errors_shown: list[str] = []  # every error dialog's text, in order

    # ----- start-up -----
    async def on_mount(self) -> None:
        mode = "valvetrain"
        problem: Exception | None = None
        if self.initial_preset:
            try:
                spec = self._load(self.initial_preset)
                mode = mode_for_kind(spec.kind)
                self._pending[mode] = (spec, self.initial_preset)
            except InputError as exc:
                problem = exc
        await self.switch_mode(mode)
        if problem is not None and self.is_running:
            self.report_error("Cannot open preset", problem)

    async def on_event(self, event: events.Event) -> None:
        """Input that reaches the app while it closes is dropped: its screens are gone.

        A key or click queued behind a busy app (a preset opening on a starved machine) was
        handled after the close had emptied the screen stacks: Textual's ``ScreenStackError:
        No screens on stack`` (the monkey's seed 219, its own Pilot having given up waiting).
        """
        if isinstance(event, events.InputEvent) and not self.is_running:
            return
        await super().on_event(event)

    def take_pending(self, mode: str) -> tuple[Any, str] | None:
        return self._pending.pop(mode, None)

    # ----- errors -----
    @staticmethod
    def error_text(error: BaseException | None) -> str:
        """The house's one-line message: never an exception class name or a traceback."""
        if isinstance(error, InputError):
            return error.one_line()
        if isinstance(error, OSError) and error.strerror:
            where = f"{error.filename}: " if error.filename else ""
            return f"{where}{error.strerror.lower()}"
        lines = str(error).strip().splitlines() if error is not None else []
        text = lines[0].strip() if lines else ""
        if isinstance(error, RunError):
            return text or "the run could not be completed"
        if not text:
            return "the run could not be completed (an internal error; please report the preset)"
        return f"the run could not be completed: {text[0].lower()}{text[1:]}"

    def report_error(self, title: str, error: BaseException | None) -> None:
        """Show an error dialog (the app's one way of reporting a failure)."""
        text = self.error_text(error)
        self.errors_shown.append(text)
        self.push_screen(ErrorDialog(title, text))

    # ----- presets -----
    def _load(self, name: str) -> Any:
        from vtool.presets import load_preset

        return load_preset(name)

    def remember(self, item: str) -> None:
        self.recent.add(item)

    def action_open(self) -> None:
        from vtool.presets import list_presets

        if isinstance(self.screen, ModalScreen):
            return  # a dialog is on top: it has the keys
        shipped = [(i.name, i.kind, i.title) for i in list_presets()]
        self.push_screen(OpenDialog(shipped, self.recent.items), self._open_chosen)

    async def _open_chosen(self, choice: str | None) -> None:
        if choice:
            await self.open_preset(choice)

    async def open_preset(self, name: str) -> bool:
        """Load a preset (shipped name or path) into the screen of its kind."""
        try:
            spec = self._load(name)
            mode = mode_for_kind(spec.kind)
        except InputError as exc:
            self.report_error("Cannot open preset", exc)
            return False
        item = name if not is_file(name) else str(Path(name).resolve())
        if mode in self.mounted_modes:
            await self.switch_mode(mode)
            screen = self.domain_screen() if self.is_running else None
            if screen is None:
                return False
            await screen.load_spec(spec, item)
        else:
            self._pending[mode] = (spec, item)
            await self.switch_mode(mode)
        if not self.is_running:
            return False  # the app closed while the preset was loading
        self.remember(item)
        return True

    def domain_screen(self) -> DomainScreen | None:
        """The current mode's domain screen, after closing any dialog left on top of it."""
        while isinstance(self.screen, ModalScreen) and len(self.screen_stack) > 1:
            self.pop_screen()
        return self.screen if isinstance(self.screen, DomainScreen) else None

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """Screen-level actions are ignored while a dialog is on top (it has the keys)."""
        if action in ("open", "switch_mode", "help") and isinstance(self.screen, ModalScreen):
            return False
        if action == "open" and getattr(self.screen, "running", False):
            return False  # finish or cancel the run first (escape)
        return True

    def action_help(self) -> None:
        if not isinstance(self.screen, ModalScreen):
            self.push_screen(HelpScreen())


def create_app(preset: str | None = None, *, config_dir: Path | None = None, remember: bool = True,
               chart_color: bool = True) -> VtoolApp:
    """The app for the CLI, the tests and the screenshots.

    ``config_dir`` holds ``recent.json`` (default: ``$XDG_CONFIG_HOME/vtool``);
    ``remember=False`` keeps the recent-files list in memory only.
    """
    if not remember:
        recent = RecentFiles(None)
    elif config_dir is not None:
        recent = RecentFiles(Path(config_dir) / "recent.json")
    else:
        recent = RecentFiles(default_path())
    return VtoolApp(preset, recent=recent, chart_color=chart_color)
