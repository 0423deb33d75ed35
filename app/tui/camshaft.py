"""The camshaft screen: several valve trains on one camshaft, their summed drive torque.

A run does what ``vtool solve CAMSHAFT_PRESET`` does (:func:`vtool.presets.camshaft.solve`: each
distinct train once, each valve's torque shifted by its phase and summed), in a worker that reports
the trains' progress and stops on escape. The results: the summed torque and each lobe's share
against camshaft angle (the chart of ``--plot`` and ``--figure``), and the summary: mean,
extremes, peak-to-peak, each valve's phase, mean and peak, and the largest cam orders, each with
its unit. The export is the CLI's ``--csv`` (each valve's torque and the sum). A late result of a
cancelled run is dropped by its run id (:meth:`DomainScreen.accept`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from textual import work
from textual.app import ComposeResult
from textual.message import Message
from textual.widgets import TabbedContent, TabPane
from textual.worker import Worker, get_current_worker

from vtool.app.tui.base import DomainScreen
from vtool.app.tui.form import INTEGER, NUMBERS, TEXT, Field
from vtool.app.tui.widgets import ChartView, TextPanel
from vtool.errors import InputError

NO_RUN = "the summed torque, each valve's share and the cam orders appear here after a run (ctrl+r)"


class CamshaftSolved(Message):
    """A camshaft run returned its summed torque (:class:`vtool.solvers.studies.camshaft.CamshaftTorque`)."""

    def __init__(self, run_id: int, spec: Any, result: Any) -> None:
        super().__init__()
        self.run_id = run_id
        self.spec = spec
        self.result = result


def camshaft_fields(spec: Any, doc: dict[str, Any]) -> list[Field]:
    """The camshaft's speed, cylinders and firing order, then each valve's train, cylinder, phase and label."""
    shaft = "Camshaft"
    fields = [
        Field(("camshaft", "rpm"), "cam speed", "rev/min", optional=True, group=shaft),
        Field(("camshaft", "cylinders"), "cylinders", kind=INTEGER, group=shaft),
        Field(("camshaft", "firing_order"), "firing order", kind=NUMBERS, group=shaft),
    ]
    for i, valve in enumerate(doc["camshaft"]["valves"]):
        group = f"Valve {i + 1}: {valve.get('label', '')}"
        fields += [
            Field(("camshaft", "valves", i, "train"), "train preset", kind=TEXT, group=group),
            Field(("camshaft", "valves", i, "cylinder"), "cylinder", kind=INTEGER, optional=True, group=group),
            Field(("camshaft", "valves", i, "phase"), "phase offset", "cam deg", group=group),
            Field(("camshaft", "valves", i, "label"), "label", kind=TEXT, group=group),
        ]
    return fields


@dataclass(frozen=True)
class FolderLoader:
    """The camshaft loader with the shown preset's folder, where a train file it names is found (the form's
    document is checked as the file it came from would be)."""

    folder: Path | None

    def load(self, doc: dict[str, Any], folder: Path | None = None) -> Any:
        from vtool.presets.camshaft import load

        return load(doc, folder or self.folder)

    def dump(self, spec: Any) -> dict[str, Any]:
        from vtool.presets.camshaft import dump

        return dump(spec)


class CamshaftScreen(DomainScreen):
    MODE = "camshaft"
    DEFAULT_PRESET = "four-cylinder-intake"
    TITLE_TEXT = "CAMSHAFT (summed cam drive torque)"

    def compose_results(self) -> ComposeResult:
        color = self.app.chart_color  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        with TabbedContent(id="results-tabs"):
            with TabPane("Torque", id="tab-torque"):
                yield ChartView("the summed drive torque appears here after a run (ctrl+r)", id="torque-chart",
                                color=color)
            with TabPane("Summary", id="tab-summary"):
                yield TextPanel(NO_RUN, id="camshaft-summary")

    @property
    def chart(self) -> ChartView:
        return self.query_one("#torque-chart", ChartView)

    def fields_for(self, spec: Any, doc: dict[str, Any]) -> list[Field]:
        return camshaft_fields(spec, doc)

    def loader(self) -> Any:
        from vtool.presets import find_preset

        try:
            return FolderLoader(find_preset(self.source).parent if self.source else None)
        except InputError:
            return FolderLoader(None)

    def clear_results(self) -> None:
        self.results = None
        self.chart.plot(None)
        self.query_one("#camshaft-summary", TextPanel).set_text(NO_RUN)

    def start_run(self, spec: Any, run_id: int) -> Worker[Any]:
        return self.solve(spec, run_id)

    @work(thread=True, exclusive=True, exit_on_error=False, group="run")
    def solve(self, spec: Any, run_id: int) -> None:
        """Each train's run and the sum (:func:`vtool.presets.camshaft.solve`) in a thread."""
        from vtool.presets.camshaft import solve

        worker = get_current_worker()
        with self.run_slot() as go:  # the cancelled run's thread has left before this one allocates
            if not go:
                return
            result = solve(spec, progress=self.progress_reporter(run_id), cancel=lambda: worker.is_cancelled)
        if result is not None and not worker.is_cancelled:
            self.post_message(CamshaftSolved(run_id, spec, result))

    def on_camshaft_solved(self, message: CamshaftSolved) -> None:
        message.stop()
        if not self.accept(message):
            return
        from vtool.app.plots import chart_text
        from vtool.presets.camshaft import camshaft_chart
        from vtool.solvers.studies.camshaft import camshaft_text

        result, title = message.result, message.spec.title
        self.results = result
        self.chart.plot(lambda w, h, c: chart_text(camshaft_chart(title, result), width=w, height=h, color=c))
        self.query_one("#camshaft-summary", TextPanel).set_text(camshaft_text(result))
        s = result.summary()
        u = s["torque_unit"]
        self.set_status(f"done: {s['valves']} valves, mean {s['mean_torque']:.4g} {u}, "
                        f"peak-to-peak {s['peak_to_peak_torque']:.4g} {u}")

    def write_csv(self, path: str) -> None:
        from vtool.files import write_atomic
        from vtool.solvers.studies.camshaft import camshaft_csv_text

        write_atomic(path, camshaft_csv_text(self.results))


#: this module's screen, named by the kinds table (vtool.presets.kinds.KINDS)
SCREEN = CamshaftScreen
