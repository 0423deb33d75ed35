"""The series every chart of vtool draws, as :class:`vtool.chart.Chart` data.

The terminal charts (:func:`vtool.app.plots.chart_text`), the figures
(:mod:`vtool.app.figures`, ``--figure out.png|svg|pdf``) and ``vtool report``
all draw these, so a figure shows what the terminal chart showed. Each chart
names its axes with units and carries the preset's title (``subject``);
valve-train charts mark the events (separations, impacts) of the run.

This module computes only (it lives below ``app/`` and imports no plotting
library); where a chart needs a run the terminal did not make (the plate
study's full model against exact) that run is made here.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from vtool.chart import Chart, Curve, HeatMap, Mark, Panel, curve, with_unit

CAM_ANGLE = "cam angle (deg)"


# ----------------------------------------------------------------------------
# valve-train runs


def _event_marks(trace: Any, panel: int = 0) -> tuple[Mark, ...]:
    """Separations (opened, released) and impacts (closed) of the run, one mark set per kind."""
    from vtool.solvers.trace import OPENED, RELEASED

    kinds: dict[str, list[float]] = {}
    for event in trace.events:
        kind = "separation" if event.kind in (OPENED, RELEASED) else "impact"
        kinds.setdefault(kind, []).append(event.cam_angle)
    return tuple(Mark(kind, np.asarray(angles, dtype=float), panel) for kind, angles in sorted(kinds.items()))


def force_chart(trace: Any) -> Chart:
    """Contact force at every clearance not removed, against cam angle; events marked."""
    units = trace.spec.unit_system
    curves = tuple(curve(f"{trace.force_label(i)} {c.name}", trace.cam_angle, trace.contact_force[:, i])
                   for i, c in enumerate(trace.spec.clearances) if c.state != "removed")
    return Chart(f"contact forces ({units.force})", CAM_ANGLE,
                 (Panel(curves, with_unit("contact force", units.force)),), trace.spec.title,
                 _event_marks(trace))


def plotted_quantities(trace: Any) -> tuple[str, ...]:
    """Every quantity the preset names (Gnilka's printed list), else the elastic coordinates."""
    return trace.spec.run.quantities or tuple(f"q{i}" for i in range(1, trace.spec.n_coordinates + 1))


def displacement_chart(trace: Any, quantities: tuple[str, ...] | None = None) -> Chart:
    """The chosen quantities (default: the first four displacements of the preset's list).

    Quantities of different units (in, rad, lbf) go on panels stacked over the
    cam angle, one unit per panel, so no curve is flattened by another's scale.
    """
    if quantities is None:
        quantities = tuple(q for q in plotted_quantities(trace) if not q.startswith("F"))[:4] or ("q1",)
    groups: dict[str, list[Curve]] = {}
    for q in quantities:
        groups.setdefault(trace.quantity_unit(q), []).append(curve(q, trace.cam_angle, trace.quantity(q)))
    title = "displacements" if all(not q.startswith("F") for q in quantities) else "quantities"
    units = trace.spec.unit_system
    names = {units.length: "displacement", units.force: "force", "rad": "rotation"}
    panels = tuple(Panel(tuple(curves), with_unit(names.get(unit, "value"), unit)) for unit, curves in groups.items())
    return Chart(title, CAM_ANGLE, panels, trace.spec.title, _event_marks(trace))


def configuration_chart(trace: Any) -> Chart:
    """One named lane per clearance: the lane's line is raised while the clearance is closed."""
    lanes = [(i, c) for i, c in enumerate(trace.spec.clearances) if c.state != "removed"]
    curves = []
    for lane, (i, c) in enumerate(lanes):
        bit = 1 << (len(trace.spec.clearances) - 1 - i)
        closed = (trace.configuration & bit) != 0
        curves.append(curve(c.name, trace.cam_angle, 2.0 * lane + 1.0 * closed, step=True))
    ticks = ([2.0 * lane + 0.5 for lane in range(len(lanes))], [c.name for _, c in lanes])
    panel = Panel(tuple(curves), "clearance (raised = closed)", (-0.5, 2.0 * len(lanes)), ticks)
    return Chart("configuration: a raised line = clearance closed", CAM_ANGLE, (panel,), trace.spec.title)


def trace_charts(trace: Any) -> list[Chart]:
    """What ``vtool solve --figure`` draws: forces, displacements, configuration; with a [follower], the cam's
    drive torque (:func:`vtool.presets.camshaft.train_torque_chart`); with a hydraulic lash adjuster, its
    chamber pressure and pump-up (:func:`vtool.presets.hla_charts.hla_charts`)."""
    charts = [force_chart(trace), displacement_chart(trace), configuration_chart(trace)]
    if trace.spec.follower is not None:
        from vtool.presets.camshaft import train_torque_chart

        charts.append(train_torque_chart(trace))
    if trace.states is not None:
        from vtool.presets.hla_charts import hla_charts
        from vtool.solvers.studies.hla import hla_series

        try:
            series = hla_series(trace)
        except KeyError:  # nonlinear elements, none of them an adjuster
            series = None
        if series is not None:
            charts += hla_charts(series, trace.spec.title)
    return charts


def compare_chart(variants: Sequence[Any]) -> Chart:
    """``vtool compare``: each enabled clearance's contact force, one panel each, one curve per variant."""
    spec = variants[0].trace.spec
    force = spec.unit_system.force
    panels = []
    for i, c in enumerate(spec.clearances):
        if c.state == "removed":
            continue
        curves = tuple(curve(v.label, v.trace.cam_angle, v.trace.contact_force[:, i]) for v in variants)
        panels.append(Panel(curves, with_unit(f"{variants[0].trace.force_label(i)} {c.name}", force)))
    return Chart(f"contact forces by impact law / start velocities ({force})", CAM_ANGLE, tuple(panels),
                 spec.title)


# ----------------------------------------------------------------------------
# sweeps


def _key(result: Any, fields: Sequence[tuple[str, str]]) -> tuple:
    values = dict(result.values)
    return tuple(values[path] for path, _ in fields[:2])


def sweep_axes(results: Sequence[Any], fields: Sequence[tuple[str, str]]) -> tuple[list, list]:
    """Distinct values of the first and second chart fields, in grid order."""
    first: list = []
    second: list = []
    for r in results:
        values = _key(r, fields)
        if values[0] not in first:
            first.append(values[0])
        if len(values) > 1 and values[1] not in second:
            second.append(values[1])
    return first, second


def _lookup(results: Sequence[Any], fields: Sequence[tuple[str, str]], metric: str) -> dict[tuple, float]:
    return {_key(r, fields): float(r.metrics[metric]) for r in results}


def sweep_chart(results: Sequence[Any], fields: Sequence[tuple[str, str]], metric: str, unit: str,
                subject: str = "") -> Chart:
    """``metric`` against the first swept field, one curve per value of the second (NaN: gaps).

    ``fields`` are the chart's axes: (path, unit) of the swept fields that take
    more than one value.
    """
    from vtool.solvers.studies.sweep import format_value

    first, second = sweep_axes(results, fields)
    table = _lookup(results, fields, metric)
    curves = []
    for value in second or [None]:
        label = metric if value is None else f"{fields[1][0]} = {format_value(value)}"
        ys = [table.get((x,) if value is None else (x, value), math.nan) for x in first]
        curves.append(curve(label, [float(x) for x in first], ys))
    none = "" if any(np.isfinite(c.y).any() for c in curves) else ": no point has a value"
    return Chart(with_unit(metric, unit) + none, with_unit(*fields[0]), (Panel(tuple(curves), with_unit(metric, unit)),),
                 subject)


def sweep_map(results: Sequence[Any], fields: Sequence[tuple[str, str]], metric: str, unit: str,
              subject: str = "") -> HeatMap:
    """``metric`` over two swept fields (a speed map when one is run.rpm); NaN where a point failed."""
    if len(fields) < 2:
        raise ValueError("a map needs two swept fields")
    first, second = sweep_axes(results, fields)
    table = _lookup(results, fields, metric)
    values = np.array([[table.get((x, y), math.nan) for x in first] for y in second], dtype=float)
    return HeatMap(with_unit(metric, unit), with_unit(*fields[0]), with_unit(*fields[1]),
                   with_unit(metric, unit), np.asarray(first), np.asarray(second),
                   values, subject)


# ----------------------------------------------------------------------------
# cams


def cam_charts(spec: Any, points: int = 721) -> list[Chart]:
    """``vtool cam show --plot``: the lift table and the fitted lift, velocity, acceleration and jerk.

    Derivatives are those of the Fourier series the solver uses, scaled to the
    preset's speed (ω, ω², ω³).
    """
    from vtool.solvers.model.cam import cam_fit, derivatives

    fit = cam_fit(spec.cam)
    u = spec.unit_system.length
    omega = spec.run.omega
    angles = np.linspace(0.0, 360.0, points)
    rows = derivatives(fit.c0, fit.a, fit.b, np.radians(angles))
    names = [("lift", u), ("velocity", f"{u}/s"), ("acceleration", f"{u}/s^2"), ("jerk", f"{u}/s^3")]
    charts = []
    for power, ((name, unit), values) in enumerate(zip(names, rows, strict=True)):
        if power == 0 and spec.cam.angles:
            charts.append(Chart(f"lift table ({u})", CAM_ANGLE,
                                (Panel((curve("table", spec.cam.angles, spec.cam.lifts),), with_unit("lift", u)),),
                                spec.title))
        charts.append(Chart(f"{with_unit(name, unit)} at {spec.run.rpm:g} rpm", CAM_ANGLE,
                            (Panel((curve("Fourier series", angles, values * omega**power),),
                                   with_unit(name, unit)),), spec.title))
    return charts


def scan_charts(scan: Any, unit: str, subject: str = "") -> list[Chart]:
    """A measured scan raw against smoothed: lift, velocity and acceleration per cam degree.

    Raw derivatives are central differences of the samples (the noise they
    carry is the point of the chart); smoothed ones are the series' own.
    """
    from vtool.presets.cam_scan import per_degree_derivatives, series_derivatives

    raw_angles = scan.angles if scan.raw_angles is None else scan.raw_angles
    raw_v, raw_a = per_degree_derivatives(raw_angles, scan.raw)
    curves = {"raw scan": (raw_angles, (scan.raw, raw_v, raw_a))}
    if scan.smoothed is not None:
        how = "spline, " if scan.smoothed.method == "spline" else ""
        curves[f"smoothed ({how}{scan.smoothed.harmonics} harmonics)"] = (
            scan.angles, (scan.lifts, *series_derivatives(scan.angles, scan.lifts)))
    names = (("lift", unit), ("velocity", f"{unit}/deg"), ("acceleration", f"{unit}/deg^2"))
    panels = tuple(Panel(tuple(curve(label, angles, values[i]) for label, (angles, values) in curves.items()),
                         with_unit(name, u)) for i, (name, u) in enumerate(names))
    return [Chart("measured scan: raw against smoothed (per cam degree)", CAM_ANGLE, panels, subject)]


def cam_shape_charts(spec: Any, points: int = 720) -> list[Chart]:
    """``vtool cam show --plot`` with a follower: the ground profile (cam frame), its radius of curvature
    against the law angle, and the pressure angle (and a finger's ratio) against cam angle."""
    from vtool.solvers.model.camshape import cam_profile, contact

    u = spec.unit_system.length
    follower = spec.follower
    profile = cam_profile(follower, spec.lift_law, points)
    c = contact(follower, spec.lift_law, np.radians(profile.law_angle_deg))
    limit = 5.0 * follower.base_radius  # an inflection's infinite radius clipped
    rho = np.clip(profile.curvature_radius, -limit, limit)
    charts = [
        Chart(f"cam profile ({u}, cam frame)", with_unit("x", u),
              (Panel((curve("profile", np.append(profile.x, profile.x[0]), np.append(profile.y, profile.y[0])),
                      curve("base circle", follower.base_radius * np.cos(np.linspace(0, 2 * math.pi, 361)),
                            follower.base_radius * np.sin(np.linspace(0, 2 * math.pi, 361)))),
                     with_unit("y", u)),), spec.title),
        Chart(f"radius of curvature ({u}; clipped at +-{limit:g})", "law angle (deg)",
              (Panel((curve("radius of curvature", profile.law_angle_deg, rho),), with_unit("radius", u)),),
              spec.title),
        Chart("pressure angle (deg)", CAM_ANGLE,
              (Panel((curve("pressure angle", c.cam_angle_deg, c.pressure_angle_deg),), "pressure angle (deg)"),),
              spec.title)]
    if follower.arrangement in ("finger", "rocker"):
        charts.append(Chart("finger ratio dV/du (-)", CAM_ANGLE,
                            (Panel((curve("ratio", c.cam_angle_deg, c.ratio),), "ratio (-)"),), spec.title))
    return charts


# ----------------------------------------------------------------------------
# cam orders


def order_chart(spectrum: Any, frequencies: list[tuple[str, float]], highest: float | None = None,
                subject: str = "") -> Chart:
    """``vtool solve --orders Q --plot``: amplitude per cam order as a staircase up to ``highest`` (default:
    past the highest natural frequency in orders, at most the Nyquist order); the natural frequencies of
    the visited configurations marked at their orders (omega_n / omega)."""
    cam_hz = spectrum.rpm / 60.0
    orders = [hz / cam_hz for _, hz in frequencies if hz / cam_hz <= spectrum.nyquist]
    top = highest or min(spectrum.nyquist, max([20.0] + [1.2 * m for m in orders]))
    keep = (spectrum.orders > 0) & (spectrum.orders <= top)
    marks = (Mark("natural frequency", np.array([o for o in orders if o <= top])),)
    panel = Panel((curve(with_unit(spectrum.quantity, spectrum.unit), spectrum.orders[keep],
                         spectrum.amplitude[keep], step=True),), with_unit("amplitude", spectrum.unit))
    return Chart(f"{spectrum.quantity}: amplitude per cam order at {spectrum.rpm:g} rev/min", "cam order (-)",
                 (panel,), subject, marks, xlim=(0.0, float(top)))


def campbell_chart(data: Any, subject: str = "") -> HeatMap:
    """``vtool sweep --campbell Q``: log10 of the order amplitudes over cam speed and cam order, with each
    natural frequency the terminal map marks drawn as its line order = f_n 60 / rpm (the orders it meets)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        values = np.where(data.amplitude > 0, np.log10(data.amplitude), np.nan)
    orders = np.arange(1, len(data.amplitude) + 1, dtype=float)
    rpm = np.asarray(data.rpm, dtype=float)
    lines = tuple(curve(f"{hz:.0f} Hz ({label})", rpm, data.line(hz)) for label, hz in data.frequencies)
    return HeatMap(f"{data.quantity}: amplitude per cam order and speed (log10)", "cam speed (rev/min)",
                   "cam order (-)", f"log10 amplitude ({data.unit})", rpm, orders, values, subject, lines)


# ----------------------------------------------------------------------------
# sonic boom


def daf_chart(ratio: np.ndarray, series: Mapping[str, np.ndarray], title: str) -> Chart:
    """``vtool boom daf``: dynamic amplification factors against tau/T (both dimensionless)."""
    curves = tuple(curve(label, ratio, values) for label, values in series.items())
    return Chart(title, "tau/T (-)", (Panel(curves, "DAF (-)"),), title)


def boom_design_charts(assessment: Any, subject: str = "") -> list[Chart]:
    """``vtool boom wall|floor --plot``: allowable p+ against frequency, per distinct set of curves."""
    from vtool.assessments.sonic_boom.report import design_series

    unit = assessment.units.alt_pressure
    return [Chart(f"{name}: allowable p+ against frequency", "f (Hz)",
                  (Panel(tuple(curve(label, frequency, values) for label, values in series.items()),
                         with_unit("p+", unit)),), subject)
            for name, frequency, series in design_series(assessment)]


# ----------------------------------------------------------------------------
# plates

PLATE_LABELS = {"displacement": "w / (p0/(m w11^2)) (-)", "velocity": "v / (p0/(m w11)) (-)",
                "acceleration": "a / (p0/m) (-)"}
PLATE_QUANTITIES = ("displacement", "velocity", "acceleration")


def plate_response_chart(resp: Any, exact: Any, quantity: str, subject: str = "") -> Chart:
    """One centre history of a transient run against the exact modal solution (dimensionless)."""
    curves = [curve(f"{resp.case} {resp.scheme}", resp.tau, getattr(resp, quantity))]
    if exact is not None and not (quantity == "acceleration" and not exact.acceleration_defined):
        curves.append(curve("exact", resp.tau, np.interp(resp.tau, exact.tau, getattr(exact, quantity))))
    return Chart(f"centre {quantity}, {resp.load} step load", "t / T (exact fundamental period) (-)",
                 (Panel(tuple(curves), PLATE_LABELS[quantity]),), subject)


def plate_study_charts(spec: Any, result: Any) -> list[Chart]:
    """``vtool plate study --plot``: the full model's histories (RK4 at omega_max*h = 1) against exact."""
    from vtool.assessments.plate.model import build_model
    from vtool.assessments.plate.transient import run_rk4

    if not result.exact:
        return []
    settings = spec.study.transient
    sizes = {r.case: r.size for r in result.transient}
    full = max(settings.cases, key=lambda name: sizes.get(name, 0))
    model = build_model(spec.study.plate, spec.study.case(full))
    charts = []
    for load, exact in result.exact.items():
        resp = run_rk4(spec.study.plate, model, load, 1.0, settings.periods)
        charts += [plate_response_chart(resp, exact, q, spec.title) for q in PLATE_QUANTITIES]
    return charts
