"""Reusable widgets: a chart that redraws to its size, a plain-text panel, a Select safe to page."""

from __future__ import annotations

from collections.abc import Callable
from typing import Literal

from rich.text import Text
from textual.app import ComposeResult
from textual.containers import ScrollableContainer
from textual.dom import DOMNode
from textual.screen import Screen
from textual.widgets import Footer, Select, Static
from textual.widgets._select import SelectCurrent, SelectOverlay

ChartFunction = Callable[[int, int, bool], str]  # (width, height, color) -> chart text


def closing(node: DOMNode) -> bool:
    """True once the app is shutting down or ``node`` has left the DOM.

    A handler that awaited (a form refill, a mount, a mode switch) checks this before it
    goes on: while the app closes (``ctrl+q``, or a test's teardown) Textual removes the
    screens' widgets under it, and a query for a result pane then raised ``NoMatches``
    (the monkey's seed 555: ``#limits`` on the sonic-boom screen, mounting at the close).
    """
    return not node.app.is_running or not node.is_attached


class ChartView(Static):
    """A plotext chart (text) drawn by a function of the widget's size.

    ``chart_text`` keeps the last string drawn, so tests compare it with the
    library's chart for the same data and size.
    """

    DEFAULT_CSS = """
    ChartView { width: 1fr; height: 1fr; min-height: 8; }
    """

    def __init__(self, placeholder: str = "", *, id: str | None = None, classes: str | None = None,
                 color: bool = True) -> None:
        super().__init__(placeholder, id=id, classes=classes, markup=False)
        self.placeholder = placeholder
        self.function: ChartFunction | None = None
        self.chart_text = ""
        self.chart_size = (0, 0)
        self.color = color

    def plot(self, function: ChartFunction | None) -> None:
        """Draw ``function`` now (and again on every resize); None shows the placeholder."""
        self.function = function
        self.chart_size = (0, 0)
        self.redraw()

    def redraw(self) -> None:
        if self.function is None:
            self.chart_text = ""
            self.update(self.placeholder)
            return
        width, height = self.size.width, self.size.height
        if width <= 0 or height <= 0:
            return  # hidden (an inactive tab): drawn on the resize that shows it
        if (width, height) == self.chart_size:
            return
        self.chart_size = (width, height)
        self.chart_text = self.function(width, height, self.color)
        self.update(Text.from_ansi(self.chart_text, no_wrap=True) if self.color else
                    Text(self.chart_text, no_wrap=True))

    def on_resize(self) -> None:
        if self.function is not None:
            self.redraw()


class TextPanel(ScrollableContainer):
    """Plain, unwrapped text (tables, summaries) that scrolls both ways."""

    DEFAULT_CSS = """
    TextPanel { height: 1fr; }
    TextPanel > Static { width: auto; height: auto; }
    """

    def __init__(self, text: str = "", *, id: str | None = None, classes: str | None = None) -> None:
        super().__init__(id=id, classes=classes, can_focus=True)
        self._initial = text
        self.text = text

    def compose(self):
        yield Static(Text(self._initial, no_wrap=True), markup=False)

    def set_text(self, text: str) -> None:
        self.text = text
        self.query_one(Static).update(Text(text, no_wrap=True))


class KeyFooter(Footer):
    """Textual's footer, rebuilt only when the keys it shows change.

    Textual rebuilds the footer (a widget per key) on every focus change, and a
    rebuild lays out the whole screen: about half of what a ``tab`` costs on the
    valve-train form. The keys shown rarely change with focus, so an unchanged
    set is not rebuilt.
    """

    _shown: tuple[object, ...] | None = None

    def bindings_changed(self, screen: Screen[object]) -> None:
        shown = tuple((b.key, b.description, b.action, b.group, enabled, tooltip)
                      for (_, b, enabled, tooltip) in screen.active_bindings.values() if b.show)
        if self._bindings_ready and shown == self._shown:
            return
        if screen.app.app_focus and self.is_attached and screen is self.screen:
            self._shown = shown  # what the rebuild below will show
        super().bindings_changed(screen)


class _PagingOverlay(SelectOverlay):
    """Select's drop-down list, safe to page before it has been laid out.

    Textual 8.2's ``OptionList._move_page`` indexes its line table, which is
    empty until the list has a size: page-up pressed in the same frame as the
    key that opens the list raised ``KeyError: 0`` (TUI monkey, seed 812:
    ``down`` then ``pageup`` on a choice field). Paging an unlaid list does
    nothing here.
    """

    def _move_page(self, direction: Literal[-1, 1]) -> None:
        if (self.highlighted or 0) not in self._index_to_line:
            return
        super()._move_page(direction)


class ChoiceSelect(Select[str]):
    """A ``Select`` whose drop-down is the paging-safe overlay above."""

    def compose(self) -> ComposeResult:
        yield SelectCurrent(self.prompt)
        yield _PagingOverlay(type_to_search=self._type_to_search).data_bind(compact=Select.compact)
