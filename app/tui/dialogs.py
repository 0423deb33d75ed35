"""Modal dialogs: error, open preset, file path (save / export), help."""

from __future__ import annotations

from collections.abc import Sequence

from rich.text import Text
from textual import events
from textual.app import ComposeResult
from textual.binding import Binding
from textual.containers import Vertical, VerticalScroll
from textual.screen import ModalScreen
from textual.widgets import Button, Input, Label, Markdown, OptionList, Static
from textual.widgets.option_list import Option


class ErrorDialog(ModalScreen[None]):
    """One dialog for every failure: a title and the one-line reason."""

    BINDINGS = [Binding("escape,enter", "dismiss", "Close")]

    def __init__(self, title: str, message: str) -> None:
        super().__init__(classes="dialog-screen")
        self.title_text = title
        self.message = message

    def compose(self) -> ComposeResult:
        with Vertical(id="error-dialog", classes="dialog"):
            yield Label(self.title_text, classes="dialog-title")
            yield Static(Text(self.message), id="error-message")
            yield Button("OK", variant="error", id="error-ok")

    def on_mount(self) -> None:
        self.query_one(Button).focus()

    def on_button_pressed(self, event: Button.Pressed) -> None:
        event.stop()
        self.dismiss(None)

    async def action_dismiss(self, result: None = None) -> None:
        self.dismiss(None)


class OpenDialog(ModalScreen[str | None]):
    """Pick a shipped or recently used preset, or type a path.

    The list has the focus (arrows and enter pick a preset); typing or pasting goes to the path
    field whatever has the focus, so enter then opens the typed path, not the highlighted preset.
    """

    BINDINGS = [Binding("escape", "cancel", "Cancel")]

    def __init__(self, shipped: Sequence[tuple[str, str, str]], recent: Sequence[str]) -> None:
        super().__init__(classes="dialog-screen")
        self.shipped = shipped
        self.recent = recent

    def compose(self) -> ComposeResult:
        with Vertical(id="open-dialog", classes="dialog"):
            yield Label("Open preset: pick one (arrows) or type a path; enter: load, esc: cancel",
                        classes="dialog-title")
            options: list[Option | None] = []
            if self.recent:
                options.append(Option(Text("recent", style="bold"), disabled=True))
                options += [Option(r, id=f"recent:{r}") for r in self.recent]
                options.append(Option(Text("shipped", style="bold"), disabled=True))
            for name, kind, title in self.shipped:
                line = f"{name:<19}{kind:<11}{title}"
                options.append(Option(line if len(line) <= 68 else line[:67] + "…", id=f"name:{name}"))
            yield OptionList(*options, id="open-list")
            # not select_on_focus: the key that moves the focus here is its first character
            yield Input(placeholder="or a path to a .toml preset", id="open-path", select_on_focus=False)

    def on_mount(self) -> None:
        option_list = self.query_one(OptionList)
        option_list.focus()
        for index in range(option_list.option_count):
            if not option_list.get_option_at_index(index).disabled:
                option_list.highlighted = index
                break

    @property
    def path_input(self) -> Input:
        return self.query_one("#open-path", Input)

    def on_key(self, event: events.Key) -> None:
        """A printable key outside the path field starts typing a path there."""
        if event.is_printable and event.character and self.focused is not self.path_input:
            event.stop()
            event.prevent_default()
            self.path_input.focus()
            self.path_input.insert_text_at_cursor(event.character)

    def on_paste(self, event: events.Paste) -> None:
        if self.focused is not self.path_input:
            event.stop()
            self.path_input.focus()
            self.path_input.insert_text_at_cursor(event.text)

    def on_option_list_option_selected(self, event: OptionList.OptionSelected) -> None:
        event.stop()
        option_id = event.option.id or ""
        self.dismiss(option_id.split(":", 1)[1] if ":" in option_id else None)

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        self.dismiss(event.value.strip() or None)

    def action_cancel(self) -> None:
        self.dismiss(None)


class PathDialog(ModalScreen[str | None]):
    """Ask for a file path (save a preset, export CSV)."""

    BINDINGS = [Binding("escape", "cancel", "Cancel")]

    def __init__(self, title: str, default: str) -> None:
        super().__init__(classes="dialog-screen")
        self.title_text = title
        self.default = default

    def compose(self) -> ComposeResult:
        with Vertical(id="path-dialog", classes="dialog"):
            yield Label(f"{self.title_text} (enter: write, esc: cancel)", classes="dialog-title")
            yield Input(self.default, id="path-input")

    def on_mount(self) -> None:
        self.query_one(Input).focus()

    def on_input_submitted(self, event: Input.Submitted) -> None:
        event.stop()
        self.dismiss(event.value.strip() or None)

    def action_cancel(self) -> None:
        self.dismiss(None)


HELP = """\
# vtool

Valve-train dynamics, sonic-boom and plate checks.

## Screens

- `f2` valve train, `f3` sonic boom, `f4` plate, `f5` camshaft

## Everywhere

- `ctrl+r` run (validated form; a bad field blocks the run)
- `escape` cancel the running job
- `ctrl+o` open a shipped or recent preset, or a path
- `ctrl+s` save the form as a preset (the file's comments kept, changes noted `# was ...`)
- `ctrl+e` export the current results as CSV (same as `vtool solve --csv`)
- `ctrl+g` valve train: save the last run's report, .pdf or .html (same as `vtool report`)
- `ctrl+f` hide / show the form (a run hides it below 120 columns)
- `ctrl+t` next result tab
- `tab` / `shift+tab` next / previous field
- `f1` this help, `ctrl+q` quit

## Valve-train animation tab

- `space` play / pause, `home` first row
- `left` / `right` step one output row
- `+` / `-` deformation scale x2 / /2
- `]` / `[` play faster / slower (x1 plays a run in 10 s)

Fields show their unit on the right; a starred label is a value changed
from the loaded preset. A field reached by `tab` has its value selected:
typing replaces it (a click or an arrow key edits in place). A bad value shows the same message as the CLI
below the field. The status line keeps every message (it wraps, never cuts).
"""


class HelpScreen(ModalScreen[None]):
    BINDINGS = [Binding("escape,f1,q", "close", "Close")]

    def __init__(self) -> None:
        super().__init__(classes="dialog-screen")

    def compose(self) -> ComposeResult:
        with VerticalScroll(id="help-dialog", classes="dialog"):
            yield Markdown(HELP, id="help-text")

    def action_close(self) -> None:
        self.dismiss(None)
