"""The content of ``vtool report PRESET``: sections of tables, checks, text and charts, as data.

:func:`valvetrain_report` runs the preset (and a sweep when given) and returns a
:class:`Report`; :mod:`vtool.app.report` renders it as a self-contained HTML
file (inline SVG) or a PDF (matplotlib's PdfPages). The TUI saves the same
report from its last run (:func:`report_of_trace`). Content only: this module
imports no drawing library.

Sections, in order (:data:`SECTIONS`):

1. **Model**: the train's data (units, cam, seat, start) and tables of its
   members and clearances.
2. **Settings and version**: vtool's version, Python and NumPy, the back
   end and its settings.
3. **Run summary and checks**: per clearance counts and peak forces, the run
   statistics and the checks below, each pass or fail with its margin.
4. **Figures**: contact forces, displacements, configuration (the charts of
   ``vtool solve --plot``, events marked).
5. **Speed map** (with a sweep): the metric over the swept fields, as a map
   for two fields or a chart for one, and the table of points.
6. **Accuracy note**: back end, step and event tolerance, and what they mean.

Boom (wall, floor) and plate presets have their own reports
(:func:`boom_report`, :func:`plate_report`: model, settings and version,
results and checks, figures, accuracy note), from the same computation as
``vtool solve`` on them; the kinds table names each kind's report function.

The checks are the run's own criteria (the metrics of
:mod:`vtool.solvers.studies.metrics`, evaluated after the first revolution):
the run completes; the follower stays on the cam (``cam_separations = 0``);
the valve does not bounce on its seat (``seat_bounces = 0``); spring force
is left over the nose (``spring_margin > 0``). A run of one revolution or
less cannot be judged: its checks say ``n/a``. The limits of the preset's
``[checks]`` table (:mod:`vtool.solvers.studies.checks`) follow, each with
its limit, value and margin.
"""

from __future__ import annotations

import math
import platform
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from vtool.chart import Chart, HeatMap

SECTIONS = ("Model", "Settings and version", "Run summary and checks", "Figures", "Speed map", "Accuracy note")
PASS, FAIL, NOT_APPLICABLE = "pass", "fail", "n/a"


@dataclass(frozen=True)
class Table:
    title: str
    header: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


@dataclass(frozen=True)
class Check:
    """One pass/fail criterion: ``value`` against ``criterion``; ``margin`` how far inside (+) or out (-)."""

    name: str
    criterion: str
    value: str
    outcome: str  # PASS, FAIL or NOT_APPLICABLE
    margin: str = ""


@dataclass(frozen=True)
class Figure:
    """A figure of the report: charts stacked, with a caption."""

    caption: str
    charts: tuple[Chart | HeatMap, ...]


@dataclass(frozen=True)
class Section:
    """``text``: fixed-width blocks shown as they are (an assessment's own printed tables)."""

    title: str
    paragraphs: tuple[str, ...] = ()
    tables: tuple[Table, ...] = ()
    checks: tuple[Check, ...] = ()
    figures: tuple[Figure, ...] = ()
    text: tuple[str, ...] = ()


@dataclass(frozen=True)
class Report:
    title: str
    subtitle: str
    sections: tuple[Section, ...] = field(default_factory=tuple)

    @property
    def figures(self) -> list[Figure]:
        return [f for s in self.sections for f in s.figures]

    def section(self, title: str) -> Section:
        return next(s for s in self.sections if s.title == title)


def _g(value: Any, digits: int = 6) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.{digits}g}" if math.isfinite(value) else "nan"
    return str(value)


# ----------------------------------------------------------------------------
# sections


def model_section(spec: Any) -> Section:
    u = spec.unit_system
    cam = spec.cam
    data = [("title", spec.title), ("units", f"{spec.units} (length {u.length}, force {u.force}, time {u.time})"),
            ("coordinates", f"{spec.n_coordinates} elastic"),
            ("cam", f"{cam.profile}, amplitude {_g(cam.amplitude)} {u.length}"
                    + (f", {len(cam.angles)} table points" if cam.angles else "")
                    + (f", from {cam.lift_table}" if cam.lift_table else "")),
            ("seat", "none" if spec.seat is None else f"position {_g(spec.seat.position)} {u.length}"),
            ("start", f"closed: {', '.join(spec.initial.closed) or 'none'}; spring preload "
                      f"{_g(spec.initial.spring_preload)} {u.force}; lever ratio {_g(spec.initial.lever_ratio)}; "
                      f"velocities {spec.initial.velocities}"),
            ("damping", f"factor {_g(spec.damping.factor)}, default ratio {_g(spec.damping.default_ratio)}")]
    members: list[tuple[str, ...]] = []
    for m in spec.members:
        members.append((m.name, m.element, _g(m.length), _g(m.modulus), _g(m.diameter), _g(m.area),
                        _g(m.inertia), _g(m.density), _g(m.specific_weight), _g(m.stiffness), _g(m.mass),
                        " ".join(str(c) for c in m.coordinates), str(m.elements)))
    member_header: tuple[str, ...] = ("member", "element", f"length ({u.length})", f"modulus ({u.pressure})",
                     f"diameter ({u.length})", f"area ({u.length}^2)", f"inertia ({u.length}^4)",
                     f"density ({u.density})",
                     f"specific weight ({u.force}/{u.length}^3)",
                     f"stiffness ({u.stiffness})", f"mass ({u.mass})", "coordinates", "elements")
    keep = [i for i, _ in enumerate(member_header) if any(row[i] != "-" for row in members)]
    shown_header = tuple(member_header[i] for i in keep)
    shown_members = tuple(tuple(row[i] for i in keep) for row in members)
    clearances = [(c.name, c.kind, c.state, f"q{c.ahead} - q{c.behind}", c.contact,
                   spec.impact_law(c) if c.rigid else "-", _g(c.restitution)) for c in spec.clearances]
    return Section("Model", (spec.notes.strip(),) if spec.notes.strip() else (), (
        Table("train data", ("item", "value"), tuple(data)),
        Table("members (columns no member gives are left out; -: computed from the section and material)", shown_header,
              shown_members),
        Table("clearances (gap = q_ahead - q_behind)",
              ("clearance", "kind", "state", "gap", "contact", "impact law", "restitution"), tuple(clearances))))


def settings_section(spec: Any, trace: Any) -> Section:
    import numpy

    from vtool import __version__

    stats = trace.statistics
    rows = [("vtool", __version__), ("Python", platform.python_version()), ("NumPy", numpy.__version__),
            ("back end", stats.backend), ("cam speed", f"{_g(spec.run.rpm)} rev/min"),
            ("run", f"{_g(spec.run.degrees)} deg of cam rotation"),
            ("output interval", f"{_g(spec.run.output_interval)} deg")]
    rows += [(str(k), _g(v) if not isinstance(v, list | tuple) else ", ".join(map(str, v)))
             for k, v in stats.settings.items()]
    return Section("Settings and version", (), (Table("settings", ("setting", "value"), tuple(rows)),))


def run_checks(trace: Any) -> tuple[Check, ...]:
    """The checks of the module doc, from the run's metrics."""
    from vtool.solvers.studies.metrics import run_metrics, seat_index

    metrics = run_metrics(trace)
    judged = float(trace.cam_angle[-1]) > 360.0 if len(trace.cam_angle) else False
    force = trace.spec.unit_system.force
    checks = [Check("run completes", "the back end reached the end of the run", trace.message or "completed",
                    PASS if trace.success else FAIL)]

    def count_check(name: str, metric: str, what: str) -> Check:
        value = metrics[metric]
        if not judged or not math.isfinite(value):
            return Check(name, f"{metric} = 0 after the first revolution", "-", NOT_APPLICABLE,
                         "a run past 360 deg is needed")
        return Check(name, f"{metric} = 0 after the first revolution", f"{int(value)} {what}",
                     PASS if value == 0 else FAIL)

    checks.append(count_check("follower stays on the cam", "cam_separations", "separation episodes"))
    if seat_index(trace.spec) is not None:
        checks.append(count_check("valve does not bounce", "seat_bounces", "bounces"))
    margin = metrics["spring_margin"]
    if judged and math.isfinite(margin):
        checks.append(Check("spring force left over the nose", f"spring_margin > 0 {force}",
                            f"{_g(margin)} {force}", PASS if margin > 0 else FAIL, f"{_g(margin)} {force}"))
    else:
        checks.append(Check("spring force left over the nose", f"spring_margin > 0 {force}", "-", NOT_APPLICABLE,
                            "no cam contact over the nose after the first revolution"))
    if getattr(trace.spec, "checks", None):  # the limits of the preset's [checks] table
        from vtool.solvers.studies.checks import MAX
        from vtool.solvers.studies.checks import evaluate as evaluate_limits

        for c in evaluate_limits(trace.spec, trace):
            sign = "<=" if c.sense == MAX else ">="
            outcome = NOT_APPLICABLE if c.passed is None else PASS if c.passed else FAIL
            checks.append(Check(c.description, f"{sign} {_g(c.limit)} {c.unit} ([checks] {c.name})",
                                "-" if c.value is None else f"{_g(c.value)} {c.unit}", outcome,
                                "" if c.margin is None else f"{_g(c.margin)} {c.unit}"))
    return tuple(checks)


def summary_section(trace: Any) -> Section:
    s = trace.summary()
    rows = tuple((c["clearance"], c["force"], c["state"], str(c["separations"]), str(c["impacts"]),
                  _g(c["peak_force"]), _g(c["peak_force_after_first_revolution"])) for c in s["clearances"])
    force = trace.spec.unit_system.force
    stats = trace.statistics
    text = (f"{stats.steps} steps, {stats.events} events, {stats.wall_time:.3g} s of back-end wall time"
            + (f"; {trace.message}" if trace.message else ""),)
    return Section("Run summary and checks", text, (
        Table("per clearance", ("clearance", "force", "state", "separations", "impacts", f"peak force ({force})",
                                f"peak after rev 1 ({force})"), rows),), run_checks(trace))


def figures_section(trace: Any) -> Section:
    from vtool.presets.charts import configuration_chart, displacement_chart, force_chart

    return Section("Figures", ("Events: a downward triangle marks a separation, an x an impact.",), figures=(
        Figure("Contact forces against cam angle.", (force_chart(trace),)),
        Figure("Displacements against cam angle, one unit per panel.", (displacement_chart(trace),)),
        Figure("Configuration: each clearance's lane is raised while it is closed.", (configuration_chart(trace),))))


def accuracy_section(trace: Any) -> Section:
    stats = trace.statistics
    settings = stats.settings
    step = settings.get("time_step_s")
    tolerance = next((settings[k] for k in ("time_tolerance_s", "time_tolerance") if k in settings), None)
    from vtool.solvers.backends import get

    backend = get(stats.backend)  # what it is, by its flags (the registry's contract), not by its name
    if backend.fixed_step:
        tolerance = tolerance if tolerance is not None else (None if step is None else 1e-6 * float(step))
        note = ("A fixed-step scheme (Newmark's beta, gamma above: second-order accurate in the step); events "
                "are located inside a step by root finding on the step's interpolant to the time tolerance, "
                "and steps after an event are refined. Halve the step (vtool accuracy) to see how the answers "
                "move.")
    elif backend.reference:
        note = ("Each configuration's linear equations are integrated exactly (the matrix exponential): no step "
                "error; events are located by root finding on the exact solution to the time tolerance.")
    else:
        note = "An adaptive integrator with the stated tolerances; events are located by its event functions."
    rows = [("back end", stats.backend), ("time step", "-" if step is None else f"{_g(step)} s"),
            ("event time tolerance", "-" if tolerance is None else f"{_g(tolerance)} s"),
            ("error estimate", "-" if stats.error_estimate is None else _g(stats.error_estimate))]
    rows += [(k, _g(v)) for k, v in settings.items() if k in ("rtol", "atol")]
    return Section("Accuracy note", (note,), (Table("accuracy", ("item", "value"), tuple(rows)),))


def speed_map_section(spec: Any, results: Sequence[Any], fields: Sequence[tuple[str, str]], metric: str,
                      unit: str) -> Section:
    from vtool.presets.charts import sweep_axes, sweep_chart, sweep_map
    from vtool.solvers.studies.sweep import format_value

    first, second = sweep_axes(results, fields)
    charts: tuple[Chart | HeatMap, ...]
    if len(fields) >= 2:
        charts = (sweep_map(results, fields, metric, unit, spec.title), sweep_chart(results, fields, metric, unit))
        caption = f"{metric} over {fields[0][0]} and {fields[1][0]} (darker: larger)."
    else:
        charts = (sweep_chart(results, fields, metric, unit, spec.title),)
        caption = f"{metric} against {fields[0][0]}."
    header = tuple(f"{p} ({u})" if u else p for p, u in fields[:2]) + (f"{metric} ({unit})" if unit else metric,
                                                                       "status")
    rows = tuple(tuple(format_value(dict(r.values)[p]) for p, _ in fields[:2]) + (_g(r.metrics[metric]), r.status)
                 for r in results)
    return Section("Speed map", (f"{len(results)} points; {len(first)} x {max(len(second), 1)} grid.",),
                   (Table("points", header, rows),), figures=(Figure(caption, charts),))


# ----------------------------------------------------------------------------
# whole reports


def report_of_trace(trace: Any, sweep: Section | None = None) -> Report:
    """The report of a finished run (the TUI's save-report, and :func:`valvetrain_report`)."""
    spec = trace.spec
    sections = [model_section(spec), settings_section(spec, trace), summary_section(trace), figures_section(trace)]
    if sweep is not None:
        sections.append(sweep)
    sections.append(accuracy_section(trace))
    return Report(spec.title, f"vtool report: {spec.run.degrees:g} deg at {spec.run.rpm:g} rev/min, "
                              f"back end {trace.statistics.backend}", tuple(sections))


def sweep_section(preset: str, sets: Sequence[str], metric: str, workers: int | None = 1) -> Section:
    """Run the sweep ``sets`` (``FIELD=VALUES`` as ``vtool sweep --set``) and make its section."""
    from vtool.errors import InputError
    from vtool.presets.paths import plan_sweep
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import make_runner, run_points

    plan = plan_sweep(preset, list(sets))
    names = dict(metric_columns(plan.spec))
    if metric not in names:
        raise InputError("--metric", metric, f"one of: {', '.join(names)}")
    axes = [f for f in plan.fields if f[0] in plan.points.axes()]
    if not axes:
        raise InputError("--sweep", ", ".join(sets), "a swept field with two or more values")
    runner = make_runner(workers)
    try:
        outcome = run_points(plan.points, runner)
    finally:
        runner.close()
    return speed_map_section(plan.spec, outcome.results, axes, metric, names[metric])


def valvetrain_report(spec: Any, *, preset: str | None = None, sweep: Sequence[str] = (),
                      metric: str = "spring_margin", workers: int | None = 1, **run: Any) -> Report:
    """Run ``spec`` (``run``: keyword arguments of :func:`vtool.solvers.run.simulate`), and the sweep of
    ``preset`` over ``sweep`` when given, and return the report's content."""
    from vtool.solvers.run import simulate

    section = sweep_section(preset or spec.title, sweep, metric, workers) if sweep else None
    return report_of_trace(simulate(spec, **run), section)


# ----------------------------------------------------------------------------
# boom and plate presets


def _versions(rows: Sequence[tuple[str, str]]) -> Section:
    import numpy

    from vtool import __version__

    head = [("vtool", __version__), ("Python", platform.python_version()), ("NumPy", numpy.__version__)]
    return Section("Settings and version", (), (Table("settings", ("setting", "value"), tuple(head) + tuple(rows)),))


def _no_sweep(sweep: Sequence[str], kind: str) -> None:
    from vtool.errors import InputError

    if sweep:
        raise InputError("--sweep", ", ".join(sweep), f"no sweep for a {kind} preset (sweeps are of valve trains)")


def boom_report(spec: Any, *, assessment: Any = None, sweep: Sequence[str] = (), **_: Any) -> Report:
    """The report of a boom wall or floor preset: ``vtool solve``'s assessment (``assessment``: one already
    made, the TUI's) as model, settings, the allowable overpressures with their checks, the design figures and
    the note on the DAF source. A check is each row's frequency within its criterion's frequency range.
    (``vtool solve``'s printed table is the allowables table here: not repeated as text.)"""
    from vtool.assessments.sonic_boom.assess import assess
    from vtool.assessments.sonic_boom.report import limits_dict
    from vtool.presets.charts import boom_design_charts

    _no_sweep(sweep, "boom")
    a = assessment if assessment is not None else assess(spec)
    d = limits_dict(a)
    length, pressure = d["length_unit"], d["pressure_unit"]
    structures = tuple((s["name"], ", ".join(f"{k} {_g(v, 5)}" for k, v in s["frequencies_hz"].items()),
                        _g(s.get("mass_per_area")), _g(s.get("flexural_rigidity")), _g(s.get("pseudo_height")))
                       for s in d["structures"])
    criteria = tuple((c["name"], c["rule"], c["response"], "yes" if c["tentative"] else "no") for c in d["criteria"])
    model = Section("Model", (spec.title, *(f"Criterion {c['description']}" for c in d["criteria"])), (
        Table("structures", ("structure", "natural frequencies (Hz)", "mass per area", "flexural rigidity D",
                             f"pseudo-height ({length})"), structures),
        Table("criteria", ("criterion", "rule", "response", "tentative"), criteria)))
    rows = tuple((r["structure"], r["frequency_source"], _g(r["frequency_hz"], 5), r["criterion"], _g(r["daf"], 5),
                  _g(r.get(f"pressure_{pressure}"), 4), "tentative" if r["tentative"] else "") for r in d["limits"])
    checks = tuple(Check(f"{r['structure']}, {r['frequency_source']}, {r['criterion']}",
                         "frequency within the criterion's frequency range", f"{_g(r['frequency_hz'], 5)} Hz",
                         PASS if r["criterion_frequency_range_ok"] else FAIL,
                         "tentative criterion" if r["tentative"] else "") for r in d["limits"])
    results = Section("Results and checks", ("Allowable peak overpressure p+ for each structure, frequency and "
                                             "criterion (the limit over the dynamic amplification factor).",),
                      (Table("allowable peak overpressure", ("structure", "frequency source", "f (Hz)", "criterion",
                                                             "DAF (-)", f"p+ ({pressure})", "note"), rows),),
                      checks)
    charts = boom_design_charts(a, spec.title)
    figures = Section("Figures", (), figures=tuple(Figure(c.title + ".", (c,)) for c in charts))
    accuracy = Section("Accuracy note", (f"DAF source: {d['daf_source']}.", "Each allowable is the criterion's "
                                         "limit divided by the DAF at the structure's tau/T; the DAF curves are "
                                         "computed, not read off the thesis' figures (docs/sonic-boom.md)."))
    return Report(spec.title, f"vtool report: {d['kind'].replace('_', ' ')} assessment",
                  (model, _versions((("kind", d["kind"]), ("units", d["units"]))), results, figures, accuracy))


def plate_report(spec: Any, *, study: Any = None, sweep: Sequence[str] = (), **_: Any) -> Report:
    """The report of a plate preset: ``vtool solve``'s study (``study``: one already run, the TUI's) as
    model, settings, the study's tables with its checks (each exact reference's acceleration converged:
    its peak moves at most 1 % when its modes are halved), the transient figures and the accuracy note."""
    from vtool.assessments.plate.report import study_dict, study_text
    from vtool.assessments.plate.study import run_study
    from vtool.presets.charts import plate_study_charts

    _no_sweep(sweep, "plate")
    result = study if study is not None else run_study(spec.study, transient=True)
    d = study_dict(result)
    text = study_text(result)
    model = Section("Model", (spec.title, text.splitlines()[0]) + ((spec.notes.strip(),) if getattr(
        spec, "notes", "").strip() else ()))
    checks = tuple(Check(f"{load} exact reference", "acceleration peak moves <= 1 % when the modes are halved",
                         f"{_g(e['peak_change_pct']['acceleration'], 3)} %",
                         PASS if e["acceleration_converged"] else FAIL, f"{e['modes']} modes")
                   for load, e in (d.get("exact") or {}).items())
    results = Section("Study results and checks", tuple(d.get("warnings") or ()), checks=checks,
                      text=("\n".join(text.splitlines()[1:]).strip("\n"),))
    charts = plate_study_charts(spec, result) if result.exact else []
    figures = Section("Figures", () if charts else ("No transient runs in this study: no figures.",),
                      figures=tuple(Figure(c.title + ".", (c,)) for c in charts))
    notes = [f"{load}: exact modal (Navier) solution with {e['modes']} modes, checked against {e['check_modes']} "
             f"(truncation: {', '.join(f'{q} {_g(v, 3)} %' for q, v in e['truncation_pct'].items())})"
             for load, e in (d.get("exact") or {}).items()]
    accuracy = Section("Accuracy note", tuple(notes) + (
        f"Errors are percentages of the exact peaks over a window of {_g(d.get('window_periods'))} fundamental "
        "periods (docs/plate.md).",))
    return Report(spec.title, "vtool report: condensed-plate study",
                  (model, _versions((("kind", spec.kind), ("units", str(spec.units)), ("element", str(spec.element)))),
                   results, figures, accuracy))
