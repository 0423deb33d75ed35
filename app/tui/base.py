"""What every domain screen shares: the form, the run worker's life cycle, presets and export.

A domain screen (valve train, sonic boom, plate) says which loader turns
its document into a spec, which fields the form shows, how a run is done
in a worker and how its results are drawn and exported. This base class
does the rest the same way on every screen:

* every edit re-validates the whole document through the preset loader
  (the CLI's messages, shown beside the field); an invalid form blocks
  the run, the save and shows why;
* a run is a thread worker (``exclusive``: a new run cancels the old);
  the worker enters :meth:`run_slot` before it allocates, which waits for
  the cancelled run's thread to leave (a thread cannot be killed: it polls
  ``is_cancelled`` and returns), so two runs never hold memory at once;
  :meth:`progress_reporter` gives it a throttled progress callback;
  its failure reaches :meth:`on_worker_state_changed`, the one place that
  turns worker errors into the error dialog;
* results carry the run id, so a late message from a cancelled run is ignored;
* the status line wraps (never cut) and every message is kept in
  ``status_log``; the progress bar shows only while a run goes and starts
  at 0 % on every run;
* below 120 columns a finished run hides the form so the result tables are
  not cut (ctrl+f shows it again);
* saving edits the preset file itself (:mod:`vtool.app.tui.presetfile`):
  comments and layout stay, changed values get a ``# was ...`` note.
"""

from __future__ import annotations

import copy
import threading
import time
from abc import ABCMeta, abstractmethod
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.screen import Screen
from textual.widgets import ProgressBar, Static, TabbedContent
from textual.worker import Worker, WorkerState, get_current_worker

from vtool.app.tui.dialogs import PathDialog
from vtool.app.tui.form import Field, ParamForm
from vtool.app.tui.messages import FieldEdited, RunProgressed
from vtool.app.tui.widgets import KeyFooter, closing
from vtool.errors import InputError
from vtool.presets import kind_of, loader_for

if TYPE_CHECKING:
    from vtool.app.tui.presetfile import FileReference

PROGRESS_INTERVAL = 0.05  # s between progress messages: the bar needs no more
NARROW = 120  # columns below which a finished run hides the form


def path_problem(error: Exception, path: str) -> Exception:
    """A file error as the house reports it: OSError and InputError as they are, else the path's field."""
    if isinstance(error, OSError | InputError):
        return error
    return InputError("path", path, "a file path that can be written (no NUL or other control characters)")


class FormProblem:
    """A validation failure that is not an InputError (shown above the form)."""

    def __init__(self, message: str) -> None:
        self.field = ""
        self.message = message

    def one_line(self) -> str:
        return self.message


def width_class(width: int, breakpoints: list[tuple[int, str]]) -> str:
    """The class Textual gives a screen ``width`` cells wide: the name of the widest breakpoint not wider.

    A screen takes it in ``__init__``, before its widgets mount: Textual sets it on
    the screen's first resize, after they mount, and restyled the whole screen for
    it (about 0.4 s of a 2.2 s start, ``benchmarks/bench_tui_actions.py``).
    """
    return max((b for b in breakpoints if width >= b[0]), key=lambda b: b[0], default=(0, ""))[1]


class _AbstractScreenMeta(ABCMeta, type(Screen)):  # type: ignore[misc]  # a base computed at run time: Screen's metaclass
    """Screen's metaclass with abstract-method checks, so a domain screen must provide its hooks."""


class DomainScreen(Screen[None], metaclass=_AbstractScreenMeta):  # type: ignore[metaclass]  # (the metaclass above)
    """Form on the left, results on the right, progress and keys at the bottom."""

    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("ctrl+r", "run", "Run", priority=True),
        Binding("escape", "cancel", "Stop"),
        Binding("ctrl+s", "save", "Save", priority=True),
        Binding("ctrl+e", "export", "CSV", priority=True),
        Binding("ctrl+f", "toggle_form", "Form", priority=True),
        Binding("ctrl+t", "next_tab", "Tab", priority=True),
    ]

    #: mode name in the app and its default preset (the kinds it shows: vtool.presets.kinds.KINDS)
    MODE: ClassVar[str] = ""
    DEFAULT_PRESET: ClassVar[str] = ""
    TITLE_TEXT: ClassVar[str] = ""
    #: keys of a preset file that name another file, written inline on save (:mod:`.presetfile`)
    FILE_REFERENCES: ClassVar[tuple[FileReference, ...]] = ()

    def __init__(self) -> None:
        super().__init__()
        self.source: str = ""
        self.base_doc: dict[str, Any] = {}
        self.spec: Any = None
        self.problem: InputError | FormProblem | None = None
        self.run_id = 0
        self.worker: Worker[Any] | None = None
        self.results: Any = None  # what the last finished run returned
        self.results_spec: Any = None
        self.messages_seen: list[Any] = []  # typed run messages, in order (tests read them)
        self.loaded_doc: dict[str, Any] = {}  # the preset document as loaded (what a save compares)
        self.start_doc: dict[str, Any] = {}  # the form's document as loaded (what a star compares)
        self.status_log: list[str] = []  # every status message, in order
        self._run_lock = threading.Lock()  # held by the thread of the run that computes
        width = width_class(self.app.size.width, self.app.HORIZONTAL_BREAKPOINTS or [])
        if width:
            self.add_class(width, update=False)

    # ----- layout -----
    def compose(self) -> ComposeResult:
        with Horizontal(id="body"):
            with Vertical(id="form-panel"):
                yield Static(self.TITLE_TEXT, id="screen-title", markup=False)
                yield Static("", id="spec-title", markup=False)
                yield ParamForm(id="form")
            with Vertical(id="results"):
                yield from self.compose_results()
        with Horizontal(id="status-bar"):
            yield ProgressBar(total=1.0, show_eta=False, id="progress")
            yield Static("ready", id="status", markup=False)
        yield KeyFooter(show_command_palette=False, compact=True)

    @abstractmethod
    def compose_results(self) -> ComposeResult:
        """The result panes of the domain screen."""

    @property
    def form(self) -> ParamForm:
        return self.query_one("#form", ParamForm)

    @property
    def progress(self) -> ProgressBar:
        return self.query_one("#progress", ProgressBar)

    @property
    def status(self) -> Static:
        return self.query_one("#status", Static)

    @property
    def tabs(self) -> TabbedContent:
        return self.query_one("#results-tabs", TabbedContent)

    @property
    def running(self) -> bool:
        return self.worker is not None and self.worker.state in (WorkerState.PENDING, WorkerState.RUNNING)

    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """While a run goes: stop is offered; open, save and export wait for it."""
        if action == "cancel":
            return self.running
        if action in ("save", "export"):
            return not self.running
        return True

    def set_status(self, text: str) -> None:
        self.status_log.append(text)
        self.status.update(text)

    def show_progress(self, running: bool) -> None:
        """The bar shows only while a run goes (never a stale 100 %).

        A run starts with a pulsing bar (no total) that turns into a
        percentage at its worker's first :class:`RunProgressed`; a worker
        that reports no progress still shows that it is working.
        """
        self.progress.update(total=None if running else 1.0, progress=0)
        # on the bar itself: on the screen, each change restyled every widget of the form and the charts
        self.progress.set_class(running, "-running")

    # ----- what a domain screen provides -----
    def loader(self) -> Any:
        """The preset module (``load(doc)``, ``dump(spec)``) of the shown preset's kind (the kinds table's)."""
        return loader_for(kind_of(self.base_doc))

    @abstractmethod
    def fields_for(self, spec: Any, doc: dict[str, Any]) -> list[Field]:
        """The form fields of a spec."""

    def extra_checks(self, spec: Any) -> None:
        """Validation of run options that are not part of the preset (raise InputError)."""

    @abstractmethod
    def start_run(self, spec: Any, run_id: int) -> Worker[Any]:
        """Start the screen's worker for a validated spec."""

    @abstractmethod
    def clear_results(self) -> None:
        """Empty the result panes."""

    @abstractmethod
    def write_csv(self, path: str) -> None:
        """Export the current results as CSV (the CLI's writer)."""

    # ----- presets -----
    async def on_mount(self) -> None:
        self.app.mounted_modes.add(self.MODE)  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        pending = self.app.take_pending(self.MODE)  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        if pending is not None:
            spec, source = pending
        else:
            from vtool.presets import load_preset

            spec, source = load_preset(self.DEFAULT_PRESET), self.DEFAULT_PRESET
        await self.load_spec(spec, source)
        if not closing(self):
            self.focus_first_field()

    def focus_first_field(self) -> None:
        """Focus the first row the form shows, if any (a preset opened meanwhile may be refilling it:
        its fields are set before its rows are mounted)."""
        from vtool.app.tui.form import FieldRow

        rows = self.form.query(FieldRow)
        if rows:
            rows.first().editor.focus()

    def on_source_changed(self, source: str) -> None:
        """Hook: a screen that keeps the preset's name elsewhere (the valve train's sweep tab) updates it."""

    async def load_spec(self, spec: Any, source: str) -> None:
        """Show ``spec`` in the form (the document its loader dumps) and clear old results."""
        if self.running and self.worker is not None:
            self.worker.cancel()
        self.source = source
        self.on_source_changed(source)
        self.base_doc = loader_for(spec.kind).dump(spec)
        self.loaded_doc = self.loader().dump(spec)
        self.spec = spec
        self.problem = None
        await self.form.set_fields(self.fields_for(spec, self.base_doc), self.base_doc)
        if closing(self):  # the app closed during the refill: its panes are being removed
            return
        self.start_doc = copy.deepcopy(self.base_doc)  # with a screen's run options, if any
        self.query_one("#spec-title", Static).update(f"{Path(source).stem}: {getattr(spec, 'title', '')}")
        self.clear_results()
        self.show_progress(False)
        self.set_status(f"loaded {source}; ctrl+r runs")
        self.after_load()

    def after_load(self) -> None:
        """Hook: set up run options that depend on the spec."""

    def current_document(self) -> dict[str, Any]:
        return self.form.apply(self.base_doc)

    def validate(self) -> Any:
        """The spec of the form as it stands, or None (the problem shown beside its field)."""
        try:
            spec = self.loader().load(self.current_document())
            self.extra_checks(spec)
        except InputError as exc:
            self.spec, self.problem = None, exc
        except (TypeError, ValueError, KeyError, IndexError, ArithmeticError) as exc:
            self.spec, self.problem = None, FormProblem(f"invalid form: {exc}")
        else:
            self.spec, self.problem = spec, None
        self.form.show_error(self.problem)
        self.form.mark_changed(self.start_doc)
        return self.spec

    def on_field_edited(self, message: FieldEdited) -> None:
        message.stop()
        self.validate()
        self.field_edited(message.path)

    def field_edited(self, path: tuple[str | int, ...]) -> None:
        """Hook: react to an edit (e.g. show the fields of a chosen pulse type)."""

    def _refuse(self, action: str) -> None:
        problem = self.problem
        text = problem.one_line() if problem is not None else "the form is not valid"
        self.notify(text, title=f"cannot {action}", severity="error")
        self.set_status(f"cannot {action}: {text}")
        name = getattr(problem, "field", "")
        if name and self.form.has_field(name):
            self.form.row(name).editor.focus()

    # ----- run -----
    def action_run(self) -> None:
        spec = self.validate()
        if spec is None:
            self._refuse("run")
            return
        self.run_id += 1
        self.messages_seen.clear()
        self.show_progress(True)
        self.set_status("running... (escape cancels)")
        self.worker = self.start_run(spec, self.run_id)
        self.refresh_bindings()

    def action_cancel(self) -> None:
        if self.running and self.worker is not None:
            self.worker.cancel()
            self.set_status("cancelled")
            self.show_progress(False)
            self.refresh_bindings()

    @contextmanager
    def run_slot(self) -> Iterator[bool]:
        """In a worker thread: wait until the previous (cancelled) run's thread has left.

        Yields False when this run was itself cancelled while waiting (then
        it must return at once); the slot is held until the block ends.
        """
        worker = get_current_worker()
        while not self._run_lock.acquire(timeout=0.02):
            if worker.is_cancelled:
                yield False
                return
        try:
            yield not worker.is_cancelled
        finally:
            self._run_lock.release()

    def progress_reporter(self, run_id: int) -> Callable[[float], None]:
        """A progress callback for a worker: posts :class:`RunProgressed`, at most every 50 ms."""
        last = [0.0]

        def report(fraction: float) -> None:
            now = time.monotonic()
            if now - last[0] >= PROGRESS_INTERVAL or fraction >= 1.0:
                last[0] = now
                self.post_message(RunProgressed(run_id, fraction))

        return report

    def on_run_progressed(self, message: RunProgressed) -> None:
        message.stop()
        if message.run_id == self.run_id and self.running:
            self.messages_seen.append(message)
            self.progress.update(total=1.0, progress=min(max(message.fraction, 0.0), 1.0))

    def accept(self, message: Any) -> bool:
        """True when a finished-run message belongs to the current run."""
        if message.run_id != self.run_id:
            return False
        self.messages_seen.append(message)
        self.results, self.results_spec = None, message.spec
        self.show_progress(False)
        if self.size.width < NARROW and not self.form_hidden:
            self.set_form_hidden(True)
            self.notify("form hidden to show the results: ctrl+f shows it", timeout=3)
        return True

    def on_worker_state_changed(self, event: Worker.StateChanged) -> None:
        """The one handler for worker errors: an error dialog (never a crash)."""
        if event.worker is not self.worker:
            return
        self.refresh_bindings()
        self.app.refresh_bindings()
        if event.state in (WorkerState.SUCCESS, WorkerState.ERROR, WorkerState.CANCELLED):
            self.progress.set_class(False, "-running")
        if event.state == WorkerState.ERROR:
            error = event.worker.error
            if isinstance(error, InputError):
                self.problem = error
                self.form.show_error(error)
            self.set_status(f"failed: {self.app.error_text(error)}")  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
            self.app.report_error("Run failed", error)  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        elif event.state == WorkerState.CANCELLED:
            self.set_status("cancelled")

    # ----- save / export -----
    def action_save(self) -> None:
        spec = self.validate()
        if spec is None:
            self._refuse("save")
            return
        default = Path(self.source).name if self.source.endswith(".toml") else f"{Path(self.source).stem}.toml"
        document = self.current_document()

        def save(path: str | None) -> None:
            if not path:
                return
            try:
                kept = self.save_document(document, path)
            except (OSError, ValueError) as exc:  # ValueError: InputError, a NUL in the path
                self.app.report_error("Save failed", path_problem(exc, path))  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
                return
            full = str(Path(path).resolve())
            self.app.remember(full)  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
            self.source = full
            self.loaded_doc = self.loader().dump(spec)
            self.start_doc = self.form.apply(self.base_doc)
            self.form.mark_changed(self.start_doc)
            note = "comments kept, changes marked '# was'" if kept else "written afresh (no source file)"
            self.set_status(f"saved {path} ({note})")
            self.notify(f"saved {path}")

        self.app.push_screen(PathDialog("Save preset as", default), save)

    def save_document(self, document: dict[str, Any], path: str) -> bool:
        """Write the form's document as a preset; True when the source file's comments were kept."""
        import tomli_w

        from vtool.app.tui.presetfile import save_text
        from vtool.files import write_atomic
        from vtool.presets import find_preset

        loader = self.loader()
        try:
            source: Path | None = Path(find_preset(self.source))
        except InputError:
            source = None
        text, kept = save_text(source, self.loaded_doc, document,
                               lambda doc: loader.dump(loader.load(doc)),
                               lambda: tomli_w.dumps(loader.dump(loader.load(document))), self.FILE_REFERENCES)
        write_atomic(path, text)
        return kept

    def action_export(self) -> None:
        if self.results is None:
            self.notify("run first (ctrl+r): there are no results to export", severity="warning")
            return
        default = f"{Path(self.source).stem}.csv"

        def export(path: str | None) -> None:
            if not path:
                return
            try:
                self.write_csv(path)
            except (OSError, ValueError) as exc:  # ValueError: InputError, a NUL in the path
                self.app.report_error("Export failed", path_problem(exc, path))  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
                return
            self.set_status(f"wrote {path}")
            self.notify(f"wrote {path}")

        self.app.push_screen(PathDialog("Export CSV to", default), export)

    # ----- view -----
    def action_toggle_form(self) -> None:
        self.set_form_hidden(not self.form_hidden)

    @property
    def form_hidden(self) -> bool:
        return not self.query_one("#form-panel").display

    def set_form_hidden(self, hidden: bool) -> None:
        """Hide or show the form; with the form hidden the side panel (shown on huge terminals) widens.

        Set on the two panels themselves, not as a class of the screen: a class change restyles the
        whole subtree it is set on (the form's hundreds of widgets and the charts: about a tenth of a
        second on the 2-core machine)."""
        self.query_one("#form-panel").display = not hidden
        for side in self.query("#side-panel"):  # (the valve-train screen's)
            side.styles.width = 80 if hidden else None

    def action_next_tab(self) -> None:
        tabs = self.tabs
        panes = [pane.id for pane in tabs.query("TabPane") if pane.id and pane.parent is not None
                 and pane.parent.parent is tabs]
        if not panes:
            return
        current = tabs.active
        index = panes.index(current) if current in panes else -1
        tabs.active = panes[(index + 1) % len(panes)]
