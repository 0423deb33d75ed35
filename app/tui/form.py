"""A parameter form bound to a preset document (the dict that ``dump(spec)`` gives).

Every field names a path in the document, its label and its unit. Editing
never validates here: the screen applies the form to the document and calls
the preset loader, so the messages are exactly the CLI's
(:meth:`vtool.errors.InputError.one_line`), shown beside the field they name.
"""

from __future__ import annotations

import copy
import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from rich.text import Text
from textual.app import ComposeResult
from textual.containers import VerticalScroll
from textual.widget import Widget
from textual.widgets import Input, Select, Static

from vtool.app.tui.messages import FieldEdited
from vtool.app.tui.widgets import ChoiceSelect, closing

Path = tuple[str | int, ...]

NUMBER = "number"
INTEGER = "integer"
NUMBERS = "numbers"  # a list of numbers, typed "0.05, 0.1"
CHOICE = "choice"
TEXT = "text"


@dataclass(frozen=True)
class Field:
    """One form field: where it lives in the preset document and how it is shown."""

    path: Path
    label: str
    unit: str = ""
    kind: str = NUMBER
    choices: tuple[str, ...] = ()
    optional: bool = False  # empty text removes the key from the document
    group: str = ""
    #: what the loader takes when the key is absent: the row shows it, and while the
    #: row still shows it an absent key stays absent (the saved file does not grow)
    default: Any = None

    @property
    def name(self) -> str:
        return dotted(self.path)

    @property
    def widget_id(self) -> str:
        return "f-" + re.sub(r"[^A-Za-z0-9_-]", "_", self.name)


def dotted(path: Path) -> str:
    """The field name the preset loaders use: ``clearances[1].restitution``."""
    text = ""
    for key in path:
        if isinstance(key, int):
            text += f"[{key}]"
        else:
            text += f".{key}" if text else key
    return text


def get_path(doc: Any, path: Path, default: Any = None) -> Any:
    node = doc
    for key in path:
        try:
            node = node[key]
        except (KeyError, IndexError, TypeError):
            return default
    return node


def set_path(doc: Any, path: Path, value: Any, remove: bool = False) -> None:
    node = doc
    for key in path[:-1]:
        if isinstance(key, str) and isinstance(node, dict) and key not in node:
            node[key] = {}
        node = node[key]
    if remove:
        if isinstance(node, dict):
            node.pop(path[-1], None)
    else:
        node[path[-1]] = value


def format_value(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if value.is_integer() and abs(value) < 1e15:
            return str(int(value))  # reads back as the same number (the loaders take ints)
        return repr(value)  # shortest text that reads back to the same float: the form loses nothing
    if isinstance(value, list):
        return ", ".join(format_value(v) for v in value)
    return str(value)


def _number(text: str) -> Any:
    """An int or float when the text is one; otherwise the text (the loader reports it).

    A number no float holds (a pasted run of 400 digits, ``1e999``, ``inf``)
    is kept as its text, so nothing downstream converts it: the loader says
    "expected a number".
    """
    try:
        value = int(text)
    except ValueError:
        pass
    else:
        try:
            float(value)
        except OverflowError:
            return text
        return value
    try:
        number = float(text)
    except ValueError:
        return text  # the loader reports "got 'abc', expected a number ..."
    return number if math.isfinite(number) else text


def parse_value(field: Field, text: str) -> Any:
    """Text typed into a field -> the TOML value the loader will judge."""
    text = text.strip()
    if field.kind in (NUMBER, INTEGER):
        return _number(text)
    if field.kind == NUMBERS:
        parts = [p for p in re.split(r"[,\s]+", text) if p]
        return [_number(p) for p in parts]
    return text


def first_line(text: str, width: int) -> str:
    """The first line of ``text`` wrapped at ``width`` cells by words (a longer first word is cut), as a
    label of that width shows it on one line."""
    line = ""
    for word in text.split():
        if not line:
            line = word[:width]
            if len(word) > width:
                break
        elif len(line) + 1 + len(word) <= width:
            line += " " + word
        else:
            break
    return line


class FieldRow(Widget):
    """Label, editor and unit on one line; the error message below it (a line mounted at the row's first
    error: most rows never show one).

    The row draws its label and unit itself (:meth:`render`, under the editor, which is its one child
    at the label's width): each widget of a screen costs its start about 4 ms, and two labels a row were
    92 of the valve-train screen's 305 widgets. The label is starred and highlighted when changed.
    """

    LABEL_WIDTH = 16  # cells, the label's own and a space
    EDITOR_WIDTH = 13
    COMPONENT_CLASSES = {"field-row--label", "field-row--unit"}
    DEFAULT_CSS = f"""
    FieldRow {{ height: auto; text-wrap: nowrap; text-overflow: clip; }}
    FieldRow > Input, FieldRow > Select {{ margin-left: {LABEL_WIDTH}; width: {EDITOR_WIDTH}; height: 1; }}
    FieldRow > .field-row--unit {{ color: $text-muted; }}
    FieldRow.-changed > .field-row--label {{ color: $warning; text-style: bold; }}
    FieldRow .field-error {{ color: $error; height: auto; display: none; }}
    FieldRow.-invalid .field-error {{ display: block; }}
    FieldRow.-invalid Input {{ color: $error; }}
    """

    def __init__(self, field: Field, value: Any) -> None:
        super().__init__(id=field.widget_id)
        self.field = field
        self.initial = field.default if value is None else value
        self.error: str | None = None
        self.error_line: Static | None = None  # below the row, from its first error on (see show_error)

    def compose(self) -> ComposeResult:
        f = self.field
        if f.kind == CHOICE:
            options = [(c, c) for c in f.choices]
            value = self.initial if self.initial in f.choices else f.choices[0]
            yield ChoiceSelect(options, value=value, allow_blank=False, compact=True, id=f"{f.widget_id}-editor")
        else:
            # select_on_focus: a field reached by the keyboard has its value selected, so typing replaces
            # it (as in a spreadsheet); a click or an arrow key places the cursor to edit in place
            yield Input(format_value(self.initial), compact=True, id=f"{f.widget_id}-editor")

    @property
    def label_text(self) -> str:
        """The label as shown: starred when the value changed from the loaded preset's."""
        return ("*" if self.has_class("-changed") else "") + self.field.label

    def render(self) -> Text:
        """The label (its first line, wrapped at the label's width less a space) and the unit, on the
        first line; the editor is drawn over the cells between them."""
        line = Text(no_wrap=True, overflow="crop")
        line.append(first_line(self.label_text, self.LABEL_WIDTH - 1), style=self.get_component_rich_style(
            "field-row--label"))
        line.pad_right(self.LABEL_WIDTH + self.EDITOR_WIDTH + 1 - len(line))
        line.append(self.field.unit, style=self.get_component_rich_style("field-row--unit"))
        return line

    def reload(self, value: Any) -> None:
        """The row as a new row of its field with ``value`` would be: that value, unchanged, no error."""
        self.initial = self.field.default if value is None else value
        f = self.field
        if f.kind == CHOICE:
            self.set_text(self.initial if self.initial in f.choices else f.choices[0])
        else:
            self.set_text(format_value(self.initial))
        self.mark_changed(False)
        self.show_error(None)

    @property
    def editor(self) -> Input | Select:
        return self.query_one(f"#{self.field.widget_id}-editor")  # type: ignore[return-value]  # the editor widget by its id: query_one is typed Widget

    @property
    def text(self) -> str:
        editor = self.editor
        if isinstance(editor, Select):
            return "" if editor.value is Select.NULL else str(editor.value)
        return editor.value

    def set_text(self, text: str) -> None:
        editor = self.editor
        if isinstance(editor, Select):
            if text in self.field.choices:
                editor.value = text
        else:
            editor.value = text

    def mark_changed(self, changed: bool) -> None:
        """Changed from the loaded preset: the label is highlighted and starred."""
        if changed != self.has_class("-changed"):
            self.set_class(changed, "-changed")
            self.refresh()

    def show_error(self, message: str | None) -> None:
        if message == self.error:
            return  # every edit re-shows every row's state: touch only what changed
        self.error = message
        self.set_class(bool(message), "-invalid")
        if self.error_line is None:  # the row's first error: its line is mounted now, not with every row
            self.error_line = Static(message or "", classes="field-error", markup=False)
            self.mount(self.error_line)
        else:
            self.error_line.update(message or "")


class ParamForm(VerticalScroll, can_focus=False):
    """Grouped fields of one preset document; posts :class:`FieldEdited` on every edit.

    The form itself takes no focus (its fields do; page keys and the wheel still
    scroll it): a click on a label would otherwise focus the container, and a focus
    change of the container restyles every row (about 0.3 s per click at 60 rows).
    """

    DEFAULT_CSS = """
    ParamForm { height: 1fr; }
    ParamForm .group-title { text-style: bold; color: $accent; margin-top: 1; }
    ParamForm #form-error { color: $error; display: none; }
    ParamForm.-invalid #form-error { display: block; }
    """

    def __init__(self, *, id: str | None = None) -> None:
        super().__init__(id=id)
        self.fields: list[Field] = []
        self.general_error: str | None = None
        self._filling = False

    def compose(self) -> ComposeResult:
        yield Static("", id="form-error", markup=False)

    async def set_fields(self, fields: Iterable[Field], doc: dict[str, Any]) -> None:
        """Replace the rows with ``fields``, filled from ``doc``. When the fields are the rows' own (a
        preset of the same form loaded again, or another one of the same shape), the rows stay and
        only their values change: mounting sixty rows anew restyled the whole form."""
        fields = list(fields)
        self._filling = True
        rows = list(self.query(FieldRow))
        if [row.field for row in rows] == fields:
            self.fields = fields
            for row in rows:
                row.reload(get_path(doc, row.field.path))
            self.show_error(None)
            self.call_after_refresh(self._done_filling)
            return
        self.fields = fields
        await self.query("FieldRow, .group-title").remove()
        if closing(self):  # the app closes: no rows to mount, no error line left to clear
            return
        widgets: list[Widget] = []
        group = None
        for f in self.fields:
            if f.group != group:
                group = f.group
                widgets.append(Static(group, classes="group-title", markup=False))
            widgets.append(FieldRow(f, get_path(doc, f.path)))
        await self.mount_all(widgets)
        if closing(self):
            return
        self.show_error(None)
        self.call_after_refresh(self._done_filling)

    def _done_filling(self) -> None:
        self._filling = False

    def row(self, path: Path | str) -> FieldRow:
        name = path if isinstance(path, str) else dotted(path)
        for row in self.query(FieldRow):
            if row.field.name == name:
                return row
        raise KeyError(name)

    def has_field(self, name: str) -> bool:
        return any(f.name == name for f in self.fields)

    def value(self, path: Path | str) -> str:
        return self.row(path).text

    def apply(self, doc: dict[str, Any]) -> dict[str, Any]:
        """A copy of ``doc`` with every field's current text written into it."""
        out = copy.deepcopy(doc)
        for row in self.query(FieldRow):
            f = row.field
            text = row.text
            kept_default = (f.default is not None and get_path(doc, f.path) is None
                            and text.strip() == format_value(f.default))
            if not text.strip() or kept_default:
                set_path(out, f.path, None, remove=True)
            else:
                set_path(out, f.path, parse_value(f, text))
        return out

    def mark_changed(self, loaded: dict[str, Any]) -> None:
        """Mark the rows whose text differs from the loaded document's value."""
        for row in self.query(FieldRow):
            value = get_path(loaded, row.field.path)
            if value is None:
                value = row.field.default  # absent: the default the row shows
            before = format_value(value)
            row.mark_changed(row.text.strip() != before and
                             parse_value(row.field, row.text) != parse_value(row.field, before))

    def show_error(self, error: Any | None) -> str | None:
        """Show an :class:`InputError` beside its field (or above the form); None clears.

        Returns the name of the field it was shown beside, if any.
        """
        shown_at = None
        message = None if error is None else error.one_line()
        field_name = getattr(error, "field", None)
        for row in self.query(FieldRow):
            here = message is not None and row.field.name == field_name
            row.show_error(message if here else None)
            if here:
                shown_at = row.field.name
        general = message if (message is not None and shown_at is None) else None
        if general != self.general_error:
            self.general_error = general
            self.set_class(general is not None, "-invalid")
            self.query_one("#form-error", Static).update(general or "")
        return shown_at

    def on_input_changed(self, event: Input.Changed) -> None:
        event.stop()
        self._edited(event.input)

    def on_select_changed(self, event: Select.Changed) -> None:
        event.stop()
        self._edited(event.select)

    def _edited(self, editor: Widget) -> None:
        if self._filling:
            return
        for ancestor in editor.ancestors:
            if isinstance(ancestor, FieldRow):
                self.post_message(FieldEdited(ancestor.field.path))
                return
