"""Plain-text tables, CSV rows and JSON-ready dicts for plate results.

Presentation only (no physics, no UI library): the CLI prints these
strings, writes the rows through :func:`vtool.files.write_atomic`, and the
TUI can show the same text.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from vtool.assessments.plate.exact import NavierMode
from vtool.assessments.plate.model import Case
from vtool.assessments.plate.study import CaseRun, StudyResult, TransientRow
from vtool.assessments.plate.transient import SIGNED_PEAK_FLOOR, SIGNS, ExactHistories, Response
from vtool.assessments.plate.vibration import FreeVibration
from vtool.csvrows import csv_text

SIGNED_KEYS = tuple(q + s for q in ("displacement", "velocity", "acceleration") for s in SIGNS)
ELEMENT_TITLES = {"bfs16": "16-DOF element (bfs16)", "mason24": "24-DOF element (mason24)"}


def _pct(value: float, width: int = 8, digits: int = 3) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return f"{'n/a':>{width}}"
    return f"{value:>{width}.{digits}f}"


def case_description(case: Case) -> str:
    text = case.note or case.masters.describe()
    method = "" if case.masters.named == "all" or case.method == "guyan" else f" [{case.method}]"
    return f"{case.nx}x{case.ny} {text}{method}"


def frequency_table(free: list[FreeVibration], cases: dict[str, Case], title: str, *,
                    masters_last: bool = False) -> str:
    """Thesis Table 2/3 layout: one row per case, errors of the lowest modes in %.

    ``masters_last``: the master-set description after the numbers (the TUI beside its
    form: the errors stay in view, the description is what a narrow panel cuts).
    """
    if not free:
        return ""
    modes: list[NavierMode] = max((f.exact for f in free), key=len)
    numbers = "".join(f"{f'({m.m},{m.n})':>8}" for m in modes) + f"{'wmax/w11':>10}"
    table = [(f"{'case':<5} {'KS':>4}  ", "masters", numbers),
             (f"{'':<5} {'':>4}  ", "exact omega, rad/s", "".join(f"{m.omega:>8.1f}" for m in modes))]
    for f in free:
        errs = "".join(_pct(e) for e in f.errors_pct) + " " * 8 * (len(modes) - len(f.errors_pct))
        table.append((f"{f.case:<5} {f.size:>4}  ", case_description(cases[f.case])[:52],
                      f"{errs}{f.omega_max_ratio:>10.1f}"))
    if masters_last:
        lines = [start + f"{numbers:<{len(table[0][2])}}  " + text for start, text, numbers in table]
        rule = "-" * len(table[0][0] + table[0][2])
    else:
        lines = [start + f"{text:<52}" + numbers for start, text, numbers in table]
        rule = "-" * len(lines[0])
    lines = [title, lines[0], lines[1], rule, *lines[2:],
             "errors: (approximate - exact)/exact x 100 % (eq. 40), k-th lowest against k-th lowest"]
    return "\n".join(lines)


def convergence_table(result: StudyResult) -> str:
    lines = ["Mesh convergence of the unreduced models (fundamental frequency)",
             f"{'element':<10} {'mesh':>6} {'KS':>6} {'error %':>12}"]
    for r in result.convergence:
        lines.append(f"{r.element:<10} {f'{r.n}x{r.n}':>6} {r.size:>6} {r.fundamental_error_pct:>12.6f}")
    for element, order in result.orders.items():
        lines.append(f"observed order ({element}): {order:.2f}  (log-log fit of error against element size)")
    return "\n".join(lines)


def cost_table(result: StudyResult) -> str:
    """Thesis Table 4: computing time against KS (ratios against the largest case)."""
    free = result.free
    if not free:
        return ""
    ref = max(free, key=lambda f: f.size)
    lines = ["Table 4  computing time against KS (this machine; ratios against the largest case)",
             f"{'case':<5} {'KS':>4} {'eigen ms':>10} {'ratio':>8}   {'RK4 at wmax*h':<14} {'steps':>7} {'loop ms':>9} {'(2KS)^2 x steps':>16}"]
    rk: dict[str, list[Any]] = {}
    for r in result.transient:
        if r.load == result.study.transient.loads[0] and not math.isnan(r.omega_max_h):
            rk.setdefault(r.case, []).append(r)
    for f in free:
        base = f"{f.case:<5} {f.size:>4} {f.solve_seconds * 1e3:>10.3f} {f.solve_seconds / ref.solve_seconds:>8.3f}"
        runs = rk.get(f.case, [])
        if not runs:
            lines.append(base)
        for k, r in enumerate(runs):
            prefix = base if k == 0 else " " * len(base)
            lines.append(f"{prefix}   {r.omega_max_h:<14.2f} {r.steps:>7} {r.seconds * 1e3:>9.2f} {r.operations:>16.3g}")
    lines.append(f"eigenproblem time ~ KS^{result.eigen_exponent:.2f} over these cases "
                 "(thesis, IBM 360-65: KS^2.5; small KS is overhead-bound here)")
    return "\n".join(lines)


def truncation_pct(exact: ExactHistories, fine: ExactHistories) -> dict[str, float]:
    """Change of each exact peak magnitude from N to 4N modes, % of the 4N peak (peaks refined between
    the samples: :meth:`ExactHistories.extreme`)."""
    out = {}
    for q in ("displacement", "velocity", "acceleration"):
        a = max(exact.extreme(q, "+"), -exact.extreme(q, "-"))
        b = max(fine.extreme(q, "+"), -fine.extreme(q, "-"))
        out[q] = (a - b) / b * 100.0 if b else 0.0
    return out


def exact_note(exact: ExactHistories, fine: ExactHistories | None = None) -> str:
    c = exact.change_pct
    text = (f"exact {exact.load} load: {exact.n_modes} modes; peak change when halved: "
            f"displacement {c['displacement']:.3f} %, velocity {c['velocity']:.2f} %, "
            f"acceleration {c['acceleration']:.1f} %")
    if fine is not None:
        t = truncation_pct(exact, fine)
        text += (f"\n  truncation: {exact.n_modes}-mode peak against {fine.n_modes} modes: "
                 f"displacement {t['displacement']:+.3f} %, velocity {t['velocity']:+.2f} %, "
                 f"acceleration {t['acceleration']:+.1f} %")
    if not exact.acceleration_defined:
        text += ("\n  point-load acceleration does not converge with the number of modes "
                 "(its series terms do not decay): no exact value, its errors are not reported")
    elif not exact.acceleration_converged:
        text += (f"\n  uniform-load acceleration not converged at {exact.n_modes} modes (its peak moves "
                 f"{c['acceleration']:.1f} % when they are halved): its errors are against the "
                 f"{exact.n_modes}-mode series, as the thesis', not an exact value")
    return text


def transient_table(result: StudyResult) -> str:
    """Thesis Table 5 data: peak errors against exact, per case, load and step."""
    if not result.transient:
        return ""
    lines = ["Table 5  transient centre response: peak errors against exact (%), and the halving-h check",
             f"{'load':<8} {'case':<5} {'KS':>4} {'wmax*h':>7} {'steps':>6} {'disp':>8} {'vel':>8} {'acc':>8}"
             f"   {'halving h: disp':>15} {'vel':>7} {'acc':>7}"]
    for r in result.transient:
        wh = "modal" if math.isnan(r.omega_max_h) else f"{r.omega_max_h:.2f}"
        e = r.errors_pct
        row = (f"{r.load:<8} {r.case:<5} {r.size:>4} {wh:>7} {r.steps:>6} {_pct(e['displacement'])}"
               f" {_pct(e['velocity'])} {_pct(e['acceleration'])}")
        if r.halving_pct:
            h = r.halving_pct
            row += f"   {h['displacement']:>15.3f} {h['velocity']:>7.3f} {h['acceleration']:>7.3f}"
        lines.append(row)
    lines.append("'modal': exact integration of the reduced model (no step limit); halving: largest "
                 "change when h is halved, % of peak")
    for load, ex in result.exact.items():
        lines.append(exact_note(ex, result.exact_4n.get(load)))
    lines += list(result.warnings)
    return "\n".join(lines)


def signed_table(result: StudyResult) -> str:
    """Positive and negative peak errors, and the errors against the 4N-mode reference."""
    if not result.transient:
        return ""
    n = result.study.transient.exact_modes
    fine = bool(result.exact_4n)
    head = (f"{'load':<8} {'case':<5} {'wmax*h':>7} " + "".join(
        f"{q[:4] + s:>8}" for q in ("displacement", "velocity", "acceleration") for s in ("+", "-")))
    if fine:
        head += f"   {f'vs {4 * n} modes: disp':>20} {'vel':>8} {'acc':>8}"
    lines = [f"Positive (+) and negative (-) peak errors against the {n}-mode exact reference (%)"
             + (f", and the peak errors against {4 * n} modes" if fine else ""), head]
    for r in result.transient:
        wh = "modal" if math.isnan(r.omega_max_h) else f"{r.omega_max_h:.2f}"
        row = f"{r.load:<8} {r.case:<5} {wh:>7} " + "".join(_pct(r.signed_pct.get(k, math.nan))
                                                         for k in SIGNED_KEYS)
        if fine:
            e = r.errors_4n_pct
            row += (f"   {_pct(e.get('displacement', math.nan), 20)} {_pct(e.get('velocity', math.nan))}"
                    f" {_pct(e.get('acceleration', math.nan))}")
        lines.append(row)
    lines.append(f"n/a: no converged exact value, or the exact history's extreme of that sign is "
                 f"below {SIGNED_PEAK_FLOOR:.0%} of its largest magnitude")
    return "\n".join(lines)


def optimum_table(result: StudyResult) -> str:
    if not result.optima:
        return ""
    tol = result.study.transient.tolerance_pct
    lines = [f"Optimum combinations: cheapest RK4 run (operations) with |error| <= full model's own error + {tol:g} %",
             f"and a halving-h change <= {tol:g} %",
             f"{'load':<8} {'quantity':<13} {'case':<5} {'KS':>4} {'wmax*h':>7} {'error %':>9} {'limit %':>8}"]
    for o in result.optima:
        if o.row is None:
            lines.append(f"{o.load:<8} {o.quantity:<13} {'-':<5} {'':>4} {'':>7} {'':>9} {_pct(o.limit_pct, 8, 2)}  {o.note}")
        else:
            r = o.row
            lines.append(f"{o.load:<8} {o.quantity:<13} {r.case:<5} {r.size:>4} {r.omega_max_h:>7.2f}"
                         f" {r.errors_pct[o.quantity]:>9.3f} {o.limit_pct:>8.2f}")
    return "\n".join(lines)


def study_text(result: StudyResult) -> str:
    study = result.study
    cases = {c.name: c for c in study.cases}
    p = study.plate
    parts = [f"plate {p.a:g} x {p.b:g}, thickness {p.thickness:g}, E {p.youngs_modulus:g}, "
             f"nu {p.poisson:g}, density {p.density:g}; simply supported (kinematic constraints)"]
    by_element: dict[str, list[FreeVibration]] = {}
    for f in result.free:
        by_element.setdefault(cases[f.case].element, []).append(f)
    for number, (element, free) in enumerate(by_element.items(), start=2):
        label = "Table 2" if element == "bfs16" else "Table 3" if element == "mason24" else f"Table {number}"
        parts.append(frequency_table(free, cases, f"{label}  {ELEMENT_TITLES.get(element, element)}: "
                                                  "percentage errors of the lowest natural frequencies"))
    parts.append(convergence_table(result))
    parts.append(cost_table(result))
    for text in (transient_table(result), signed_table(result), optimum_table(result)):
        if text:
            parts.append(text)
    parts.append(f"study time {result.seconds:.1f} s")
    return "\n\n".join(parts)


def _row_dict(r: TransientRow) -> dict[str, Any]:
    return {
        "case": r.case, "KS": r.size, "load": r.load,
        "omega_max_h": None if math.isnan(r.omega_max_h) else r.omega_max_h,
        "steps": r.steps, "seconds": r.seconds, "operations": r.operations,
        "errors_pct": _nan_none(r.errors_pct),
        "signed_errors_pct": _nan_none(r.signed_pct),
        "errors_4n_modes_pct": _nan_none(r.errors_4n_pct),
        "halving_pct": r.halving_pct,
    }


def _nan_none(values: dict[str, float]) -> dict[str, float | None]:
    return {k: (None if math.isnan(v) else v) for k, v in values.items()}


def study_dict(result: StudyResult) -> dict[str, Any]:
    """JSON-ready summary of a study."""
    return {
        "frequencies": [
            {"case": f.case, "KS": f.size, "modes": [f"{m.m},{m.n}" for m in f.exact],
             "errors_pct": f.errors_pct.tolist(), "omega_max_over_omega11": f.omega_max_ratio,
             "eigen_seconds": f.solve_seconds}
            for f in result.free
        ],
        "convergence": [
            {"element": r.element, "mesh": r.n, "KS": r.size, "fundamental_error_pct": r.fundamental_error_pct}
            for r in result.convergence
        ],
        "convergence_order": result.orders,
        "eigen_time_exponent": result.eigen_exponent,
        "transient": [_row_dict(r) for r in result.transient],
        "exact": {k: {"modes": e.n_modes, "peak_change_pct": e.change_pct,
                      "acceleration_converged": e.acceleration_converged,
                      "check_modes": result.exact_4n[k].n_modes if k in result.exact_4n else None,
                      "truncation_pct": truncation_pct(e, result.exact_4n[k]) if k in result.exact_4n
                      else None}
                  for k, e in result.exact.items()},
        "window_periods": result.study.transient.periods,
        "warnings": list(result.warnings),
        "optima": [
            {"load": o.load, "quantity": o.quantity, "limit_pct": None if math.isnan(o.limit_pct) else o.limit_pct,
             "case": o.row.case if o.row else None, "KS": o.row.size if o.row else None,
             "omega_max_h": o.row.omega_max_h if o.row else None, "note": o.note}
            for o in result.optima
        ],
    }


def study_csv(result: StudyResult) -> str:
    """One row per case and quantity (long format), header with units; text cells quoted as needed."""
    rows: list[list[object]] = [["table", "case", "KS", "load", "omega_max_h", "quantity", "mode", "value", "unit"]]
    for f in result.free:
        for m, e in zip(f.exact, f.errors_pct, strict=True):
            rows.append(["frequency", f.case, f.size, "", "", "frequency_error", f"{m.m}-{m.n}", f"{e:.6g}", "%"])
        rows.append(["frequency", f.case, f.size, "", "", "omega_max_over_omega11", "", f"{f.omega_max_ratio:.6g}", "1"])
        rows.append(["cost", f.case, f.size, "", "", "eigen_time", "", f"{f.solve_seconds:.6g}", "s"])
    for r in result.convergence:
        rows.append(["convergence", f"{r.element}-{r.n}x{r.n}", r.size, "", "", "fundamental_error", "1-1",
                     f"{r.fundamental_error_pct:.6g}", "%"])
    for t in result.transient:
        wh = "modal" if math.isnan(t.omega_max_h) else f"{t.omega_max_h:g}"
        for suffix, errors in (("_peak_error", t.errors_pct), ("_peak_error_4n_modes", t.errors_4n_pct),
                               ("_peak_error", t.signed_pct)):
            for q, v in errors.items():
                value = "" if math.isnan(v) else f"{v:.6g}"
                name = q.replace("+", "_positive").replace("-", "_negative")
                rows.append(["transient", t.case, t.size, t.load, wh, f"{name}{suffix}", "", value, "%"])
        rows.append(["cost", t.case, t.size, t.load, wh, "time_loop", "", f"{t.seconds:.6g}", "s"])
        rows.append(["cost", t.case, t.size, t.load, wh, "steps", "", t.steps, "1"])
    return csv_text(rows)


def modes_text(free: FreeVibration, case: Case) -> str:
    lines = [f"case {free.case}: {case.element} {case_description(case)}; KS = {free.size}",
             f"{'mode':>4} {'(m,n)':>7} {'exact rad/s':>13} {'model rad/s':>13} {'error %':>9}"]
    for k, (m, e) in enumerate(zip(free.exact, free.errors_pct, strict=True), start=1):
        lines.append(f"{k:>4} {f'({m.m},{m.n})':>7} {m.omega:>13.3f} {free.omega[k - 1]:>13.3f} {e:>9.4f}")
    lines.append(f"omega_max = {free.omega[-1]:.1f} rad/s = {free.omega_max_ratio:.1f} x exact omega_11 "
                 f"(RK4 step h = (omega_max h) / omega_max); eigenproblem {free.solve_seconds * 1e3:.2f} ms")
    return "\n".join(lines)


MODES_HEADER = ["mode", "m", "n", "exact_omega_rad_per_s", "model_omega_rad_per_s", "error_pct"]


def modes_rows(free: FreeVibration) -> list[list[object]]:
    """The rows of :func:`modes_csv` (no header)."""
    return [[k, m.m, m.n, f"{m.omega:.9g}", f"{free.omega[k - 1]:.9g}", f"{e:.6g}"]
            for k, (m, e) in enumerate(zip(free.exact, free.errors_pct, strict=True), start=1)]


def modes_csv(free: FreeVibration) -> str:
    return csv_text([MODES_HEADER, *modes_rows(free)])


def cases_modes_csv(results: list[tuple[str, FreeVibration]]) -> str:
    """Several cases' modes in one CSV: ``case`` (quoted as needed) and ``KS`` columns first."""
    return csv_text([["case", "KS", *MODES_HEADER]]
                    + [[name, f.size, *row] for name, f in results for row in modes_rows(f)])


def response_csv(resp: Response, exact: ExactHistories | None) -> str:
    """Non-dimensional histories; the exact reference interpolated at the same times."""

    head = "t_over_T,displacement_w_over_p0_mw2,velocity_v_over_p0_mw,acceleration_a_over_p0_m"
    cols = [resp.tau, resp.displacement, resp.velocity, resp.acceleration]
    if exact is not None:
        head += ",exact_displacement,exact_velocity,exact_acceleration"
        cols += [np.interp(resp.tau, exact.tau, getattr(exact, q))
                 for q in ("displacement", "velocity", "acceleration")]
    rows = np.column_stack(cols)
    body = "\n".join(",".join(f"{v:.8g}" for v in row) for row in rows)
    return head + "\n" + body + "\n"


def case_run_text(run: CaseRun) -> str:
    """``vtool plate transient``'s table: peaks, exact peaks, errors (both signs), halving check."""
    resp = run.response
    step = (f"omega_max*h = {run.omega_max_h:g}, h = {resp.step:.4g} s, {resp.steps} steps"
            if resp.scheme == "rk4" else f"exact modal integration of the reduced model at {resp.steps} times")
    c = run.case
    lines = [f"case {c.name} ({c.element} {c.nx}x{c.ny}, KS = {run.size}), {resp.load} step load, "
             f"{resp.scheme}: {step}, {resp.seconds * 1e3:.2f} ms",
             f"{'quantity':<13} {'peak':>10} {'exact peak':>11} {'error %':>9} {'+ peak %':>9} "
             f"{'- peak %':>9}" + (f" {'halving h %':>12}" if run.halving_pct else "")]
    for q in ("displacement", "velocity", "acceleration"):
        a, e = getattr(resp, q), getattr(run.exact, q)
        k = int(np.argmax(np.abs(e)))
        peak = float(np.max(a)) if e[k] > 0 else float(np.min(a))
        err = run.errors_pct[q]
        exact_shown = "n/a" if math.isnan(err) else f"{e[k]:.4f}"
        line = (f"{q:<13} {peak:>10.4f} {exact_shown:>11} {_pct(err, 9)} {_pct(run.signed_pct[q + '+'], 9)}"
                f" {_pct(run.signed_pct[q + '-'], 9)}")
        if run.halving_pct:
            line += f" {run.halving_pct[q]:>12.3f}"
        lines.append(line)
    lines.append(exact_note(run.exact))
    lines += list(run.warnings)
    return "\n".join(lines)


def case_run_dict(run: CaseRun) -> dict[str, Any]:
    resp = run.response
    rk4 = resp.scheme == "rk4"
    return {
        "case": run.case.name, "KS": run.size, "load": resp.load, "scheme": resp.scheme,
        "omega_max_h": run.omega_max_h if rk4 else None, "steps": resp.steps,
        "step_s": resp.step if rk4 else None, "seconds": resp.seconds,
        "time_unit": "t/T (exact fundamental period)", "window_periods": float(resp.tau[-1]),
        "peak_errors_pct": _nan_none(run.errors_pct),
        "signed_peak_errors_pct": _nan_none(run.signed_pct),
        "halving_change_pct": run.halving_pct, "exact_modes": run.exact.n_modes,
        "exact_peak_change_pct": run.exact.change_pct,
        "exact_acceleration_converged": run.exact.acceleration_converged,
        "warnings": list(run.warnings),
    }
