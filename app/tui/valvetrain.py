"""The valve-train screen: mechanism and run form, simulation worker, charts, animation.

The result tabs are one list (:meth:`ValveTrainScreen.result_panes`): a new
tab (e.g. a sweep) is one more ``TabPane`` appended there.
"""

from __future__ import annotations

from typing import Any, ClassVar

from textual import work
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal
from textual.widgets import SelectionList, TabbedContent, TabPane
from textual.widgets.selection_list import Selection
from textual.worker import Worker, get_current_worker

from vtool.app.tui.animation import MechanismAnimation
from vtool.app.tui.base import DomainScreen
from vtool.app.tui.form import CHOICE, Field
from vtool.app.tui.messages import CompileAnnounced, SimulationFinished
from vtool.app.tui.reports import REPORT_BINDING
from vtool.app.tui.sweep import SweepPane
from vtool.app.tui.widgets import ChartView, TextPanel
from vtool.solvers.model.spec import IMPACT_LAWS, START_VELOCITIES

DEFAULT_PLOTTED = 4  # displacement quantities ticked after a load (all are in the list)

MEMBER_KEYS = (
    ("length", "length", "length"),
    ("diameter", "diameter", "length"),
    ("area", "area", "area"),
    ("inertia", "inertia", "inertia"),
    ("modulus", "modulus E", "pressure"),
    ("specific_weight", "spec. weight", "specific_weight"),
    ("density", "density", "density"),
    ("stiffness", "spring rate", "stiffness"),
    ("mass", "mass", "mass"),
)


def valvetrain_fields(spec: Any, doc: dict[str, Any]) -> list[Field]:
    """The form of a valve-train preset: run, cam, spring, clearances, members, damping."""
    from vtool.solvers import backends

    u = spec.unit_system
    unit = {"length": u.length, "area": f"{u.length}^2", "inertia": f"{u.length}^4",
            "pressure": u.pressure, "specific_weight": u.specific_weight, "density": u.density,
            "stiffness": u.stiffness, "mass": u.mass, "force": u.force}
    installed = tuple(backends.available())
    backend_choices = installed if doc["run"]["backend"] in installed else (doc["run"]["backend"], *installed)
    fields = [
        Field(("run", "rpm"), "cam speed", "rev/min", group="Run"),
        Field(("run", "degrees"), "cam degrees", "deg", group="Run"),
        Field(("run", "backend"), "back end", kind=CHOICE, choices=backend_choices, group="Run"),
        Field(("run", "time_step"), "time step", "s", group="Run"),
        Field(("run", "beta"), "Newmark beta", group="Run"),
        Field(("run", "gamma"), "Newmark gamma", group="Run"),
        Field(("run", "output_interval"), "output every", "deg", group="Run"),
    ]
    if "train" in doc:  # entered by train type: its parameters (presets/trains.py), not the expanded members
        return fields + train_fields(doc, unit) + damping_fields(doc)
    fields += [
        *([Field(("cam", "amplitude"), "cam amplitude", u.length, group="Cam and spring")]
          if "amplitude" in doc["cam"] else
          [Field(("cam", key), f"cam {key}", u.length if key == "tolerance" else "", group="Cam and spring")
           for key in ("harmonics", "tolerance") if key in doc["cam"]]),
        Field(("initial", "spring_preload"), "spring preload", u.force, group="Cam and spring"),
        Field(("initial", "lever_ratio"), "lever ratio", group="Cam and spring"),
        Field(("initial", "velocities"), "start velocities", kind=CHOICE, choices=START_VELOCITIES,
              group="Cam and spring"),
    ]
    for name, member in doc["members"].items():
        if "stiffness" in member:
            fields.append(Field(("members", name, "stiffness"), f"{name} rate", u.stiffness,
                                group="Cam and spring"))
    if "seat" in doc:
        key = "lash" if "lash" in doc["seat"] else "position"
        fields.append(Field(("seat", key), f"seat {key}", u.length, group="Clearances"))
    fields.append(Field(("contact", "impact"), "impact law", kind=CHOICE, choices=IMPACT_LAWS, group="Clearances"))
    fields.append(Field(("contact", "rocker_scale"), "rocker SCALE", group="Clearances"))
    for i, c in enumerate(doc["clearances"]):
        states = ("enabled", "removed") if c["kind"] == "external" else ("enabled", "pinned", "removed")
        fields.append(Field(("clearances", i, "state"), f"{c['name']} state", kind=CHOICE, choices=states,
                            group="Clearances"))
        fields.append(Field(("clearances", i, "restitution"), f"{c['name']} restit.", group="Clearances"))
    for name, member in doc["members"].items():
        group = f"Member {name} ({member['element']})"
        for key, label, kind in MEMBER_KEYS:
            if key in member and key != "stiffness":
                fields.append(Field(("members", name, key), label, unit[kind], group=group))
    fields += damping_fields(doc)
    fields.append(Field(("gravity",), "gravity", u.acceleration, group="Mechanism"))
    return fields


def damping_fields(doc: dict[str, Any]) -> list[Field]:
    fields = [Field(("damping", "factor"), "global factor", group="Damping (modal ratios)"),
              Field(("damping", "default_ratio"), "default ratio", group="Damping (modal ratios)")]
    for i, layer in enumerate(doc["damping"].get("layers", [])):
        closed = "+".join(layer["closed"]) or "none closed"
        fields.append(Field(("damping", "layers", i, "default_ratio"), f"{closed}: ratio",
                            group="Damping (modal ratios)"))
        for mode in layer.get("mode_ratios", {}):
            fields.append(Field(("damping", "layers", i, "mode_ratios", mode), f"{closed}: mode {mode}",
                                group="Damping (modal ratios)"))
    return fields


def train_fields(doc: dict[str, Any], unit: dict[str, str]) -> list[Field]:
    """A train type's numbers, one group per part ("Train: spring"), and its limits ([checks])."""
    from vtool.presets.trains import train_parameters

    kinds = unit | {"deg": "deg", "": ""}
    fields = []
    for path, kind in train_parameters(doc):
        part, key = path[1], path[2]
        fields.append(Field(path, key.replace("_", " ")[:15], kinds.get(kind, kind),
                            group=f"Train ({doc['train'].get('type', '')}): {part}"))
    return fields


def displacement_quantities(spec: Any) -> list[str]:
    """Every quantity the preset names (Gnilka's 11 printed ones), else the elastic coordinates."""
    return list(spec.run.quantities) or [f"q{i}" for i in range(1, spec.n_coordinates + 1)]


def quantity_unit(spec: Any, quantity: str) -> str:
    """The unit of ``q7``, ``q1-q9`` (a coordinate's) or ``F2`` (a force), for the pick list."""
    import re

    units = spec.unit_system
    if quantity.startswith("F"):
        return units.force
    number = int(re.findall(r"\d+", quantity)[0])
    if number <= spec.n_coordinates and spec.coordinates[number - 1].motion == "rotation":
        return "rad"
    return units.length


class ValveTrainScreen(DomainScreen):
    MODE = "valvetrain"
    DEFAULT_PRESET = "gnilka-1a"
    TITLE_TEXT = "VALVE TRAIN"
    # hidden from the footer (its keys are full at 80 columns); listed in the help and docs/tui.md
    BINDINGS: ClassVar[list[BindingType]] = [REPORT_BINDING]
    # a table cam's file is written inline (docs/cams.md): a saved copy must not depend on its folder
    FILE_REFERENCES = ((("cam",), "lift_table", ("angles", "lifts")),)

    def result_panes(self) -> list[TabPane]:
        """The result tabs, in order: a new tab is one more pane in this list."""
        color = self.app.chart_color  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        return [
            TabPane("Forces", ChartView("contact forces appear here after a run (ctrl+r)",
                                        id="force-chart", color=color), id="tab-forces"),
            TabPane("Quant.", Horizontal(
                SelectionList[str](id="quantities"),
                ChartView("the quantities ticked on the left appear here after a run",
                          id="displacement-chart", color=color)), id="tab-displacements"),
            TabPane("Config", ChartView("closed clearances against cam angle appear here after a run",
                                        id="configuration-chart", color=color), id="tab-configuration"),
            TabPane("Events", TextPanel("no run yet", id="events"), id="tab-events"),
            TabPane("Summary", TextPanel("no run yet", id="summary"), id="tab-summary"),
            TabPane("Anim.", MechanismAnimation(id="animation", color=color), id="tab-animation"),
            TabPane("Orders", ChartView("the cam-order spectrum of the seat force appears here after a run",
                                        id="order-chart", color=color), id="tab-orders"),
            TabPane("Sweep", SweepPane(self.DEFAULT_PRESET, workers=None, id="sweep", lazy=True), id="tab-sweep"),
        ]

    def on_source_changed(self, source: str) -> None:
        """The sweep tab sweeps the preset the form shows (as loaded; save the form to sweep edits)."""
        for pane in self.query(SweepPane):
            pane.preset = source

    def compose_results(self) -> ComposeResult:
        with Horizontal(id="results-row"):
            with TabbedContent(id="results-tabs"):
                yield from self.result_panes()
            yield TextPanel("", id="side-panel")

    # ----- typed access to the children -----
    @property
    def force_chart(self) -> ChartView:
        return self.query_one("#force-chart", ChartView)

    @property
    def displacement_chart(self) -> ChartView:
        return self.query_one("#displacement-chart", ChartView)

    @property
    def configuration_chart(self) -> ChartView:
        return self.query_one("#configuration-chart", ChartView)

    @property
    def order_chart(self) -> ChartView:
        return self.query_one("#order-chart", ChartView)

    @property
    def quantity_list(self) -> SelectionList[str]:
        return self.query_one("#quantities", SelectionList)

    @property
    def animation(self) -> MechanismAnimation:
        return self.query_one("#animation", MechanismAnimation)

    @property
    def trace(self) -> Any:
        return self.results

    # ----- spec -----
    def fields_for(self, spec: Any, doc: dict[str, Any]) -> list[Field]:
        return valvetrain_fields(spec, doc)

    def after_load(self) -> None:
        self.compile_solver(self.spec)
        quantities = displacement_quantities(self.spec)
        selection = self.quantity_list
        selection.clear_options()
        ticked = [q for q in quantities if not q.startswith("F")][:DEFAULT_PLOTTED] or quantities[:1]
        selection.add_options([Selection(f"{q} ({quantity_unit(self.spec, q)})", q, q in ticked)
                               for q in quantities])

    def selected_quantities(self) -> tuple[str, ...]:
        return tuple(self.quantity_list.selected)

    def clear_results(self) -> None:
        self.results = None
        for chart in (self.force_chart, self.displacement_chart, self.configuration_chart, self.order_chart):
            chart.plot(None)
        self.query_one("#events", TextPanel).set_text("no run yet")
        self.query_one("#summary", TextPanel).set_text("no run yet")
        self.query_one("#side-panel", TextPanel).set_text("")
        self.animation.clear()

    @work(thread=True, exclusive=True, exit_on_error=False, group="compile")
    def compile_solver(self, spec: Any) -> None:
        """Compile the solver for this preset's contact laws (or load it from numba's cache) while the
        screen is read, so that the first Run need not wait for it (a Run meanwhile waits for the same
        compile, its status line saying so)."""
        from vtool.solvers.backends import get

        get(spec.run.backend).warm_up(spec)

    # ----- run -----
    def start_run(self, spec: Any, run_id: int) -> Worker[Any]:
        return self.simulate(spec, run_id)

    @work(thread=True, exclusive=True, exit_on_error=False, group="run")
    def simulate(self, spec: Any, run_id: int) -> None:
        """Run the library's :func:`simulate` in a thread; post progress and the trace."""
        from vtool.solvers.run import simulate

        worker = get_current_worker()

        def announce() -> None:  # the input is checked: say so when a compile is to come, as the CLI does
            from vtool.solvers.backends import get

            notice = get(spec.run.backend).compile_notice(spec)
            if notice is not None:
                self.post_message(CompileAnnounced(run_id, notice))

        with self.run_slot() as go:  # the cancelled run's thread has left before this one allocates
            if not go:
                return
            trace = simulate(spec, progress=self.progress_reporter(run_id),
                             cancel=lambda: worker.is_cancelled, before_run=announce)
        if not worker.is_cancelled:
            self.post_message(SimulationFinished(run_id, spec, trace))

    def on_compile_announced(self, message: CompileAnnounced) -> None:
        message.stop()
        if message.run_id == self.run_id and self.running:
            self.set_status(f"running... (escape cancels); {message.text}")

    def on_simulation_finished(self, message: SimulationFinished) -> None:
        message.stop()
        if not self.accept(message):
            return
        trace = message.trace
        self.results = trace
        self.show_trace(trace)
        stats = trace.statistics
        self.set_status(f"done: {stats.steps} steps, {stats.events} events, {stats.wall_time:.2f} s ({stats.backend})")

    def show_trace(self, trace: Any) -> None:
        from vtool.app import valvetrain_charts as charts

        self.force_chart.plot(lambda w, h, c: charts.force_chart(trace, w, h, color=c))
        self.plot_displacements()
        self.configuration_chart.plot(lambda w, h, c: charts.configuration_chart(trace, w, h, color=c))
        from vtool.solvers.studies.metrics import evaluation_summary

        summary = trace.summary_text() + "\n\n" + "\n".join(evaluation_summary(trace)["lines"])
        events = trace.event_table() if trace.events else "no events"
        self.plot_orders(trace)
        self.query_one("#summary", TextPanel).set_text(summary)
        self.query_one("#events", TextPanel).set_text(events)
        self.query_one("#side-panel", TextPanel).set_text(f"{summary}\n\nevents\n{events}")
        self.animation.show_trace(trace)

    def plot_orders(self, trace: Any) -> None:
        """The spectrum of the default quantity (run.orders' first, else the seat force) over the evaluated
        cycles: its table and chart with the natural frequencies marked; a run without a whole evaluated
        cycle says so."""
        from vtool.errors import InputError
        from vtool.solvers.studies.orders import (
            default_quantity,
            dominant_text,
            natural_frequencies,
            spectrum,
        )

        try:
            orders = spectrum(trace, default_quantity(trace.spec))
        except InputError as exc:
            self.order_chart.placeholder = f"no spectrum: {exc}"
            self.order_chart.plot(None)
            return
        frequencies = natural_frequencies(trace)
        from vtool.app.order_charts import order_chart

        text = orders.table(6) + "\n" + dominant_text(orders, frequencies)
        self.order_chart.plot(lambda w, h, c: text + "\n" + order_chart(
            orders, frequencies, width=w, height=max(h - 11 - len(frequencies), 8), color=c))

    def plot_displacements(self) -> None:
        trace = self.results
        if trace is None:
            return
        from vtool.app import valvetrain_charts as charts

        quantities = self.selected_quantities() or ("q1",)
        self.displacement_chart.plot(
            lambda w, h, c: charts.displacement_chart(trace, quantities, w, h, color=c))

    def on_selection_list_selected_changed(self, event: SelectionList.SelectedChanged[str]) -> None:
        event.stop()
        self.plot_displacements()

    # ----- export -----
    def write_csv(self, path: str) -> None:
        self.results.write_csv(path)

    def action_save_report(self) -> None:
        """ctrl+g: the last run's report (what `vtool report` writes), as .pdf or .html."""
        from vtool.app.tui.reports import save_report
        from vtool.presets.report import report_of_trace

        results = self.results
        save_report(self, None if results is None else lambda: report_of_trace(results))


#: this module's screen, named by the kinds table (vtool.presets.kinds.KINDS)
SCREEN = ValveTrainScreen
