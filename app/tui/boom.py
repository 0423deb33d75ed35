"""The sonic-boom screen: pulse and structures, DAF and design curves, allowable pressures.

The assessment is :func:`vtool.assessments.sonic_boom.assess.assess`, the
call behind ``vtool boom wall|floor`` and ``vtool solve``; the DAF curve is
:func:`vtool.assessments.sonic_boom.spectra.daf_at` over the source the
assessment used (pulse or envelope).
"""

from __future__ import annotations

from typing import Any, ClassVar

from textual import work
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import VerticalScroll
from textual.widgets import TabbedContent, TabPane
from textual.worker import Worker, get_current_worker

from vtool.app.tui.base import DomainScreen
from vtool.app.tui.form import CHOICE, INTEGER, NUMBERS, TEXT, Field, dotted
from vtool.app.tui.messages import AssessmentFinished
from vtool.app.tui.reports import REPORT_BINDING
from vtool.app.tui.widgets import ChartView, TextPanel, closing
from vtool.assessments.sonic_boom.spec import PSEUDO_HEIGHT_RULES
from vtool.assessments.sonic_boom.spectra import FAMILIES

PULSES = ("envelope", "N", "P", "Q", "R", "T", "csv")
IDEALIZED_KEYS = ("s", "r1", "r2", "alpha", "beta")
ENVELOPE_DEFAULT = {"types": ["N", "P", "Q", "R", "T"], "s": [1.6, 2.2, 0.1], "r1": [0.0, 0.5, 0.1]}


def boom_fields(spec: Any, doc: dict[str, Any]) -> list[Field]:
    u = spec.units
    boom = doc["boom"]
    g = "Boom"
    fields = [
        Field(("boom", "pulse"), "pulse", kind=CHOICE, choices=PULSES, group=g),
        Field(("boom", "positive_durations"), "durations tau", "s", kind=NUMBERS, group=g),
        Field(("boom", "damping"), "damping ratio", group=g),
    ]
    pulse = boom.get("pulse", "envelope")
    if pulse == "envelope":
        fields += [
            Field(("boom", "envelope", "types"), "env. types", kind=TEXT, group=g),
            Field(("boom", "envelope", "s"), "env. s", "first,last,step", kind=NUMBERS, group=g),
            Field(("boom", "envelope", "r1"), "env. r1", "first,last,step", kind=NUMBERS, group=g),
            Field(("boom", "envelope", "alpha"), "env. alpha", optional=True, group=g),
            Field(("boom", "envelope", "beta"), "env. beta", optional=True, group=g),
            Field(("boom", "envelope", "family"), "env. family", kind=CHOICE, choices=tuple(FAMILIES),
                  default="thesis", group=g),
        ]
    elif pulse == "csv":
        fields.append(Field(("boom", "csv"), "pulse CSV file", kind=TEXT, group=g))
    else:
        fields += [
            Field(("boom", "s"), "s (total/pos.)", group=g),
            Field(("boom", "r1"), "r1 rise ratio", group=g),
            Field(("boom", "r2"), "r2", optional=True, group=g),
            Field(("boom", "alpha"), "alpha", optional=True, group=g),
            Field(("boom", "beta"), "beta", optional=True, group=g),
        ]
    fields.append(Field(("criteria",), "criteria", kind=TEXT, group="Criteria"))
    fields += [
        Field(("design", "f_min"), "f min", "Hz", group="Design curves"),
        Field(("design", "f_max"), "f max", "Hz", group="Design curves"),
        Field(("design", "points"), "points", kind=INTEGER, group="Design curves"),
    ]
    for i, wall in enumerate(doc.get("walls", [])):
        grp = f"Wall {wall.get('name', i)}"
        fields += [
            Field(("walls", i, "base_width"), "base width a", u.length, group=grp),
            Field(("walls", i, "thickness"), "thickness h", u.length, group=grp),
            Field(("walls", i, "youngs_modulus"), "modulus E", u.pressure, group=grp),
            Field(("walls", i, "poisson_ratio"), "Poisson nu", group=grp),
            Field(("walls", i, "surface_weight"), "surface wt.", u.surface_weight, group=grp),
            Field(("walls", i, "net_area"), "net area", f"{u.length}^2", optional=True, group=grp),
            Field(("walls", i, "height"), "height b", u.length, optional=True, group=grp),
            Field(("walls", i, "measured_frequency"), "measured f", "Hz", optional=True, group=grp),
            Field(("walls", i, "pseudo_height_rule"), "pseudo-height", kind=CHOICE,
                  choices=PSEUDO_HEIGHT_RULES, default="exact", group=grp),
        ]
    for i, floor in enumerate(doc.get("floors", [])):
        grp = f"Floor {floor.get('name', i)}"
        fields += [
            Field(("floors", i, "columns"), "columns n", kind=INTEGER, group=grp),
            Field(("floors", i, "youngs_modulus"), "column E", u.pressure, group=grp),
            Field(("floors", i, "moment_of_inertia"), "column I", f"{u.length}^4", group=grp),
            Field(("floors", i, "storey_height"), "storey l", u.length, group=grp),
            Field(("floors", i, "face_width"), "face width d", u.length, group=grp),
            Field(("floors", i, "floor_weight"), "floor weight", u.force, group=grp),
            Field(("floors", i, "measured_frequency"), "measured f", "Hz", optional=True, group=grp),
        ]
    return fields


def _names(value: Any) -> Any:
    if isinstance(value, str):
        return [part.strip() for part in value.split(",") if part.strip()]
    return value


def switch_pulse(doc: dict[str, Any]) -> dict[str, Any]:
    """Keep only the keys the chosen pulse kind reads (defaults for a newly chosen kind)."""
    boom = doc["boom"]
    pulse = boom.get("pulse", "envelope")
    if pulse != "envelope":
        boom.pop("envelope", None)
    if pulse != "csv":
        boom.pop("csv", None)
    if pulse in ("envelope", "csv"):
        for key in IDEALIZED_KEYS:
            boom.pop(key, None)
    if pulse == "envelope":
        boom.setdefault("envelope", dict(ENVELOPE_DEFAULT))
    elif pulse == "csv":
        boom.setdefault("csv", "")
    else:
        boom.setdefault("s", 2.0)
        boom.setdefault("r1", 0.0)
    return doc


#: Points of the TUI's DAF chart: a chart is ~100 columns wide, so more is waste.
CHART_POINTS = 501


def daf_curves(spec: Any, assessment: Any, cancel: Any = None) -> dict[str, Any]:
    """The overall DAF of the assessment's source against tau/T, for each response its criteria use.

    At most :data:`CHART_POINTS` values of tau/T (step 0.01 up to 5, coarser beyond).
    """
    import numpy as np

    from vtool.assessments.sonic_boom.assess import boom_source
    from vtool.assessments.sonic_boom.spectra import daf_at

    top = max([2.5, *(1.1 * r.ratio for r in assessment.rows)])
    stop = float(np.ceil(top * 10) / 10)
    ratio = np.linspace(0.0, stop, min(CHART_POINTS, int(round(stop / 0.01)) + 1))
    source = boom_source(spec.boom)
    series = {}
    statements = []
    for quantity in dict.fromkeys(c.response for c in spec.criteria):
        daf, statement = daf_at(source, ratio, quantity, spec.boom.damping, cancel)
        series[f"{quantity} DAF"] = daf
        statements.append(statement)
    return {"ratio": ratio, "series": series, "statement": " | ".join(statements)}


class BoomScreen(DomainScreen):
    MODE = "boom"
    BINDINGS: ClassVar[list[BindingType]] = [REPORT_BINDING]  # ctrl+g: save the report
    DEFAULT_PRESET = "boom-brick-wall"
    TITLE_TEXT = "SONIC BOOM"

    def compose_results(self) -> ComposeResult:
        color = self.app.chart_color  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        with TabbedContent(id="results-tabs"):
            with TabPane("Limits", id="tab-limits"):
                yield TextPanel("allowable pressures appear here after a run (ctrl+r)", id="limits")
            with TabPane("DAF", id="tab-daf"):
                yield ChartView("the DAF curve appears here after a run", id="daf-chart", color=color)
            with TabPane("Design curves", id="tab-design"):
                yield VerticalScroll(id="design-charts", classes="chart-stack")

    @property
    def limits_panel(self) -> TextPanel:
        return self.query_one("#limits", TextPanel)

    @property
    def daf_chart(self) -> ChartView:
        return self.query_one("#daf-chart", ChartView)

    @property
    def design_charts(self) -> list[ChartView]:
        return list(self.query_one("#design-charts").query(ChartView))

    def fields_for(self, spec: Any, doc: dict[str, Any]) -> list[Field]:
        return boom_fields(spec, doc)

    def current_document(self) -> dict[str, Any]:
        doc = self.form.apply(self.base_doc)
        doc["criteria"] = _names(doc.get("criteria", ""))
        envelope = doc["boom"].get("envelope")
        if isinstance(envelope, dict) and "types" in envelope:
            envelope["types"] = _names(envelope["types"])
        return doc

    def field_edited(self, path: tuple[str | int, ...]) -> None:
        if dotted(path) == "boom.pulse":
            doc = switch_pulse(self.current_document())
            self.call_later(self.rebuild_form, doc)

    async def rebuild_form(self, doc: dict[str, Any]) -> None:
        self.base_doc = doc
        spec = self.spec if self.spec is not None else self.results_spec
        if spec is None:
            from vtool.presets import load_preset

            spec = load_preset(self.DEFAULT_PRESET)
        await self.form.set_fields(self.fields_for(spec, doc), doc)
        if closing(self):
            return
        self.validate()
        self.form.row("boom.pulse").editor.focus()

    def clear_results(self) -> None:
        self.results = None
        self.limits_panel.set_text("allowable pressures appear here after a run (ctrl+r)")
        self.daf_chart.plot(None)
        self.query_one("#design-charts").remove_children()

    def start_run(self, spec: Any, run_id: int) -> Worker[Any]:
        return self.assess(spec, run_id)

    @work(thread=True, exclusive=True, exit_on_error=False, group="run")
    def assess(self, spec: Any, run_id: int) -> None:
        from vtool.assessments.cancel import Cancelled
        from vtool.assessments.sonic_boom.assess import assess

        worker = get_current_worker()

        def cancel() -> bool:
            return worker.is_cancelled

        # the previous run (cancelled by this one: exclusive) leaves the slot when it has
        # stopped: only one run's arrays exist at a time (the base's cancellable wait)
        with self.run_slot() as go:
            if not go:
                return
            try:
                assessment = assess(spec, cancel)
                daf = daf_curves(spec, assessment, cancel)
            except Cancelled:
                return
        if not worker.is_cancelled:
            self.post_message(AssessmentFinished(run_id, spec, assessment, daf))

    async def on_assessment_finished(self, message: AssessmentFinished) -> None:
        message.stop()
        if not self.accept(message):
            return
        from vtool.app.plots import line_chart
        from vtool.assessments.sonic_boom import report

        a, daf = message.assessment, message.daf
        self.results = a
        self.limits_panel.set_text(report.limits_text(a, answer_first=True))
        self.daf_chart.plot(lambda w, h, c: line_chart(daf["ratio"], daf["series"], title="overall DAF",
                                                       xlabel="tau/T", ylabel="DAF", width=w, height=h,
                                                       color=c))
        stack = self.query_one("#design-charts")
        await stack.remove_children()
        if closing(self):
            return
        color = self.app.chart_color  # type: ignore[attr-defined]  # VtoolApp's own attribute (Screen.app is typed as App)
        charts = []
        u = a.units
        for name, freq, series in report.design_series(a):
            chart = ChartView(id=None, color=color)
            chart.structure = name  # type: ignore[attr-defined]  # a label this screen puts on its chart widget
            charts.append((chart, name, freq, series))
        await stack.mount_all([c for c, *_ in charts])
        if closing(self):
            return
        for chart, name, freq, series in charts:
            def draw(w: int, h: int, c: bool, name: str = name, freq: Any = freq, series: Any = series) -> str:
                return line_chart(freq, series, title=f"{name}: allowable p+ against frequency", xlabel="f [Hz]",
                                  ylabel=f"p+ [{u.alt_pressure}]", width=w, height=h, color=c)

            chart.plot(draw)
        self.set_status(f"done: {len(a.rows)} limits, {len(a.structures)} structure(s)")

    def write_csv(self, path: str) -> None:
        from vtool.assessments.sonic_boom.report import limits_csv
        from vtool.files import write_atomic

        write_atomic(path, limits_csv(self.results))

    def action_save_report(self) -> None:
        """ctrl+g: the last run's report (what `vtool report` writes), as .pdf or .html."""
        from vtool.app.tui.reports import save_report
        from vtool.presets.report import boom_report

        results, spec = self.results, self.results_spec
        save_report(self, None if results is None else lambda: boom_report(spec, assessment=results))


#: this module's screen, named by the kinds table (vtool.presets.kinds.KINDS)
SCREEN = BoomScreen
