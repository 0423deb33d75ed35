"""The plate screen: plate, mesh, element, master set; frequencies, transient response, cost.

A run does what ``vtool solve PLATE_PRESET`` does (:func:`run_study`, so the
CSV export is the CLI's) and, for the chosen case, what ``vtool plate
transient`` does: the centre response to the chosen load by the chosen
scheme, against the exact (Navier) reference.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

from textual import work
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import VerticalScroll
from textual.widgets import TabbedContent, TabPane
from textual.worker import Worker, get_current_worker

from vtool.app.tui.base import DomainScreen
from vtool.app.tui.form import CHOICE, INTEGER, NUMBERS, TEXT, Field, dotted
from vtool.app.tui.messages import PlateStudyFinished
from vtool.app.tui.reports import REPORT_BINDING
from vtool.app.tui.widgets import ChartView, TextPanel, closing
from vtool.errors import InputError

RUN = "_run"  # run options live under this key of the form's document, never in the preset
AUTO = "auto (Henshell-Ong)"
LABELS = "labels"
QUANTITY_LABELS = {"displacement": "w / (p0/(m w11^2))", "velocity": "v / (p0/(m w11))",
                   "acceleration": "a / (p0/m)"}


@dataclass(frozen=True)
class PlateRun:
    """A study and the chosen case's modes and transient run."""

    study: Any  # StudyResult
    case: Any  # Case
    free: Any  # FreeVibration of the chosen case
    run: Any  # CaseRun: the chosen case's transient against exact
    options: dict[str, Any]

    @property
    def response(self) -> Any:
        return self.run.response

    @property
    def exact(self) -> Any:
        return self.run.exact

    @property
    def errors(self) -> dict[str, float]:
        return self.run.errors_pct


def run_defaults(spec: Any) -> dict[str, Any]:
    t = spec.study.transient
    first = t.cases[0] if t.cases else spec.study.cases[0].name
    return {"case": first, "load": t.loads[0], "scheme": "rk4", "omega_max_h": 1.0,
            "periods": t.periods, "exact_modes": t.exact_modes}


def plate_fields(spec: Any, doc: dict[str, Any]) -> list[Field]:
    from vtool.assessments.plate.elements import ELEMENTS
    from vtool.assessments.plate.masters import NAMED_SETS
    from vtool.assessments.plate.transient import LOADS, SCHEMES

    u = spec.unit_system
    elements = tuple(ELEMENTS)
    names = tuple(c["name"] for c in doc["cases"])
    index = names.index(doc[RUN]["case"])
    case = doc["cases"][index]
    masters = (*NAMED_SETS, AUTO) + ((LABELS,) if isinstance(case.get("masters"), list) else ())
    fields = [
        Field((RUN, "case"), "case", kind=CHOICE, choices=names, group="Run (chosen case)"),
        Field((RUN, "load"), "step load", kind=CHOICE, choices=tuple(LOADS), group="Run (chosen case)"),
        Field((RUN, "scheme"), "scheme", kind=CHOICE, choices=tuple(SCHEMES), group="Run (chosen case)"),
        Field((RUN, "omega_max_h"), "omega_max*h", "<= 2.8", group="Run (chosen case)"),
        Field((RUN, "periods"), "duration", "periods T", group="Run (chosen case)"),
        Field((RUN, "exact_modes"), "exact modes", kind=INTEGER, group="Run (chosen case)"),
        Field(("cases", index, "element"), "element", kind=CHOICE, choices=elements, group=f"Case {case['name']}"),
        Field(("cases", index, "mesh"), "mesh NX, NY", kind=NUMBERS, group=f"Case {case['name']}"),
        Field(("cases", index, "masters"), "master set", kind=CHOICE, choices=masters, group=f"Case {case['name']}"),
    ]
    if case.get("masters") == AUTO or "auto" in case:
        fields.append(Field(("cases", index, "auto"), "auto masters", kind=INTEGER, group=f"Case {case['name']}"))
    if isinstance(case.get("labels"), list):
        fields.append(Field(("cases", index, "labels"), "master labels", kind=TEXT, group=f"Case {case['name']}"))
    fields += [
        Field(("cases", index, "method"), "reduction", kind=CHOICE, choices=("guyan", "irs"),
              group=f"Case {case['name']}"),
        Field(("plate", "a"), "side a (x)", u.length, group="Plate (simply supported)"),
        Field(("plate", "b"), "side b (y)", u.length, group="Plate (simply supported)"),
        Field(("plate", "thickness"), "thickness", u.length, group="Plate (simply supported)"),
        Field(("plate", "youngs_modulus"), "modulus E", u.pressure, group="Plate (simply supported)"),
        Field(("plate", "poisson"), "Poisson nu", group="Plate (simply supported)"),
        Field(("plate", "density"), "density", u.density, group="Plate (simply supported)"),
        Field(("study", "element"), "default elem.", kind=CHOICE, choices=elements, group="Study (all cases)"),
        Field(("study", "mesh"), "default mesh", kind=NUMBERS, group="Study (all cases)"),
        Field(("study", "frequencies"), "modes compared", kind=INTEGER, group="Study (all cases)"),
    ]
    return fields


def editable_document(doc: dict[str, Any], options: dict[str, Any]) -> dict[str, Any]:
    """The preset document with the run options and the chosen case written out in full."""
    doc[RUN] = dict(options)
    names = [c["name"] for c in doc["cases"]]
    if doc[RUN]["case"] not in names:
        doc[RUN]["case"] = names[0]
    case = doc["cases"][names.index(doc[RUN]["case"])]
    case.setdefault("element", doc["study"]["element"])
    case.setdefault("mesh", list(doc["study"]["mesh"]))
    case.setdefault("method", "guyan")
    if "auto" in case:
        case["masters"] = AUTO
    elif isinstance(case.get("masters"), list):
        case["labels"] = case["masters"]
        case["masters"] = LABELS
    return doc


def preset_document(doc: dict[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Split the form's document into the preset document and the run options."""
    options = doc.pop(RUN, {})
    for case in doc.get("cases", []):
        masters = case.get("masters")
        if masters == AUTO:
            case.pop("masters")
            case.pop("labels", None)
            case.setdefault("auto", 1)
        elif masters == LABELS:
            labels = case.pop("labels", "")
            case["masters"] = [p.strip() for p in labels.split(",") if p.strip()] if isinstance(labels, str) \
                else labels
            case.pop("auto", None)
        elif masters is not None:
            case.pop("auto", None)
            case.pop("labels", None)
    return doc, options


def check_options(spec: Any, options: dict[str, Any]) -> dict[str, Any]:
    """Validate the run options (the same ranges as ``vtool plate transient``)."""
    from vtool.assessments.plate.study import check_run_options

    names = [c.name for c in spec.study.cases]
    if options.get("case") not in names:
        raise InputError(f"{RUN}.case", options.get("case"), f"one of: {', '.join(names)}")
    check_run_options(options.get("load"), options.get("scheme"), options.get("omega_max_h"),  # type: ignore[arg-type]  # the form's raw options: check_run_options refuses bad ones
                      options.get("periods"), options.get("exact_modes"), prefix=f"{RUN}.")  # type: ignore[arg-type]  # the form's raw options: check_run_options refuses bad ones
    return {**options, "omega_max_h": float(options["omega_max_h"]), "periods": float(options["periods"])}


def run_plate(spec: Any, options: dict[str, Any], cancel: Any = None) -> PlateRun:
    """The study (as ``vtool solve``) and the chosen case's modes and transient (as ``vtool plate``)."""
    from vtool.assessments.plate.model import build_model
    from vtool.assessments.plate.study import run_case, run_study
    from vtool.assessments.plate.vibration import free_vibration

    study = run_study(spec.study, transient=True, cancel=cancel)
    plate = spec.study.plate
    case = spec.study.case(options["case"])
    free = free_vibration(plate, build_model(plate, case), spec.study.frequencies)
    run = run_case(plate, case, options["load"], options["scheme"], options["omega_max_h"],
                   options["periods"], options["exact_modes"], halving=False, cancel=cancel)
    return PlateRun(study, case, free, run, dict(options))


def transient_chart(run: PlateRun, quantity: str, width: int, height: int, color: bool) -> str:
    """Centre history of the chosen case against exact (the chart of ``vtool plate transient``)."""
    import numpy as np

    from vtool.app.plots import line_chart

    resp, exact = run.response, run.exact
    series = {f"{resp.case} {resp.scheme}": getattr(resp, quantity)}
    if not (quantity == "acceleration" and not exact.acceleration_defined):
        series["exact"] = np.interp(resp.tau, exact.tau, getattr(exact, quantity))
    return line_chart(resp.tau, series, title=f"centre {quantity}, {resp.load} step load",
                      xlabel="t / T (exact fundamental period)", ylabel=QUANTITY_LABELS[quantity],
                      width=width, height=height, color=color)


def case_text(run: PlateRun) -> str:
    """Modes of the chosen case, its transient peak errors and what it cost."""
    from vtool.assessments.plate.report import case_run_text, modes_text

    resp = run.response
    return "\n".join([modes_text(run.free, run.case), "", case_run_text(run.run), "",
                      f"cost: KS = {run.free.size}, eigenproblem {run.free.solve_seconds * 1e3:.3f} ms, "
                      f"time loop {resp.loop_seconds * 1e3:.2f} ms, {resp.operations:.3g} multiply-adds"])


class PlateScreen(DomainScreen):
    MODE = "plate"
    BINDINGS: ClassVar[list[BindingType]] = [REPORT_BINDING]  # ctrl+g: save the report
    DEFAULT_PRESET = "plate-table2"
    TITLE_TEXT = "PLATE (condensation)"

    def __init__(self) -> None:
        super().__init__()
        self.options: dict[str, Any] = {}

    def compose_results(self) -> ComposeResult:
        color = self.app.chart_color  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        with TabbedContent(id="results-tabs"):
            with TabPane("Frequencies", id="tab-frequencies"):
                yield TextPanel("the frequency table appears here after a run (ctrl+r)", id="frequencies")
            with TabPane("Transient", id="tab-transient"):
                with VerticalScroll(classes="chart-stack"):
                    for q in ("displacement", "velocity", "acceleration"):
                        yield ChartView(f"the centre {q} appears here after a run", id=f"{q}-chart",
                                        color=color)
            with TabPane("Case & cost", id="tab-case"):
                yield TextPanel("no run yet", id="case-text")
            with TabPane("Study", id="tab-study"):
                yield TextPanel("no run yet", id="study-text")

    def chart(self, quantity: str) -> ChartView:
        return self.query_one(f"#{quantity}-chart", ChartView)

    async def load_spec(self, spec: Any, source: str) -> None:
        self.options = run_defaults(spec)
        await super().load_spec(spec, source)

    def fields_for(self, spec: Any, doc: dict[str, Any]) -> list[Field]:
        editable_document(doc, self.options)
        return plate_fields(spec, doc)

    def current_document(self) -> dict[str, Any]:
        doc, options = preset_document(self.form.apply(self.base_doc))
        self.options = options
        return doc

    def extra_checks(self, spec: Any) -> None:
        self.options = check_options(spec, self.options)

    def field_edited(self, path: tuple[str | int, ...]) -> None:
        name = dotted(path)
        if name == f"{RUN}.case" or name.endswith(".masters"):
            doc, options = preset_document(self.form.apply(self.base_doc))
            if name.endswith(".masters") and options.get("case"):
                case = next(c for c in doc["cases"] if c["name"] == options["case"])
                chosen = self.form.value(path)
                if chosen == AUTO:
                    case.pop("masters", None)
                    case.setdefault("auto", 1)
            self.options = options
            self.call_later(self.rebuild_form, doc, name)

    async def rebuild_form(self, doc: dict[str, Any], focus: str) -> None:
        self.base_doc = editable_document(doc, self.options)
        spec = self.spec if self.spec is not None else self.results_spec
        if spec is None:
            from vtool.presets import load_preset

            spec = load_preset(self.DEFAULT_PRESET)
        await self.form.set_fields(plate_fields(spec, self.base_doc), self.base_doc)
        if closing(self):
            return
        self.validate()
        if self.form.has_field(focus):
            self.form.row(focus).editor.focus()

    def clear_results(self) -> None:
        self.results = None
        for q in ("displacement", "velocity", "acceleration"):
            self.chart(q).plot(None)
        self.query_one("#frequencies", TextPanel).set_text("the frequency table appears here after a run (ctrl+r)")
        self.query_one("#case-text", TextPanel).set_text("no run yet")
        self.query_one("#study-text", TextPanel).set_text("no run yet")

    def start_run(self, spec: Any, run_id: int) -> Worker[Any]:
        return self.study(spec, dict(self.options), run_id)

    @work(thread=True, exclusive=True, exit_on_error=False, group="run")
    def study(self, spec: Any, options: dict[str, Any], run_id: int) -> None:
        from vtool.assessments.cancel import Cancelled

        worker = get_current_worker()

        def cancel() -> bool:
            return worker.is_cancelled

        # the previous run (cancelled by this one: exclusive) leaves the slot when it has
        # stopped: only one run's arrays exist at a time (the base's cancellable wait)
        with self.run_slot() as go:
            if not go:
                return
            try:
                result = run_plate(spec, options, cancel)
            except Cancelled:
                return
        if not worker.is_cancelled:
            self.post_message(PlateStudyFinished(run_id, spec, result))

    def on_plate_study_finished(self, message: PlateStudyFinished) -> None:
        message.stop()
        if not self.accept(message):
            return
        from vtool.assessments.plate.report import ELEMENT_TITLES, frequency_table, study_text

        run: PlateRun = message.result
        self.results = run
        study = run.study
        cases = {c.name: c for c in study.study.cases}
        tables = []
        for element in dict.fromkeys(cases[f.case].element for f in study.free):
            free = [f for f in study.free if cases[f.case].element == element]
            tables.append(frequency_table(free, cases, f"{ELEMENT_TITLES.get(element, element)}: "
                                                       "percentage errors of the lowest natural frequencies",
                                          masters_last=True))
        self.query_one("#frequencies", TextPanel).set_text("\n\n".join(tables))
        self.query_one("#case-text", TextPanel).set_text(case_text(run))
        self.query_one("#study-text", TextPanel).set_text(study_text(study))
        for q in ("displacement", "velocity", "acceleration"):
            def draw(w: int, h: int, c: bool, q: str = q) -> str:
                return transient_chart(run, q, w, h, c)

            self.chart(q).plot(draw)
        self.set_status(f"done: {len(study.free)} cases, study {study.seconds:.1f} s; case {run.case.name} "
                        f"KS = {run.free.size}")

    def write_csv(self, path: str) -> None:
        from vtool.assessments.plate.report import study_csv
        from vtool.files import write_atomic

        write_atomic(path, study_csv(self.results.study))

    def action_save_report(self) -> None:
        """ctrl+g: the last run's report (what `vtool report` writes), as .pdf or .html."""
        from vtool.app.tui.reports import save_report
        from vtool.presets.report import plate_report

        results, spec = self.results, self.results_spec
        save_report(self, None if results is None else lambda: plate_report(spec, study=results.study))


#: this module's screen, named by the kinds table (vtool.presets.kinds.KINDS)
SCREEN = PlateScreen
