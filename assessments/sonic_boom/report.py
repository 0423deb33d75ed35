"""Plain-text tables, CSV text and JSON-ready dicts for sonic-boom results.

Presentation only (no physics, no UI library): ``vtool boom``, ``vtool
solve`` and the TUI print the same strings and write the same CSV, so a
number reads the same wherever it is shown. Every JSON document carries its
units in ``*_unit`` keys.
"""

from __future__ import annotations

import csv
import io
import math
from typing import Any

import numpy as np

from vtool.assessments.sonic_boom.assess import Assessment, Structure
from vtool.assessments.sonic_boom.response import QUANTITIES, PeakResponse
from vtool.assessments.sonic_boom.spec import UnitSystem
from vtool.assessments.sonic_boom.spectra import Envelope

ROW_HEADER = ("structure", "frequency source", "f [Hz]", "tau [s]", "tau/T [-]", "criterion",
              "response", "DAF [-]")


def fmt(value: float, digits: int = 4) -> str:
    return f"{value:.{digits}g}" if math.isfinite(value) else "inf"


def csv_text(header: list[str] | tuple[str, ...], rows: list[list[str]]) -> str:
    """A CSV document (header row, then ``rows``), ``\\n`` line ends."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(rows)
    return buffer.getvalue()


def _columns(table: list[tuple[str, ...]]) -> list[str]:
    widths = [max(len(str(row[i])) for row in table) for i in range(len(table[0]))]
    return ["  " + "  ".join(str(c).ljust(w) for c, w in zip(row, widths, strict=True)).rstrip()
            for row in table]


def structure_line(s: Structure, u: UnitSystem) -> str:
    d = s.details
    parts = []
    if "pseudo_height" in d:
        parts.append(f"pseudo-height {d['pseudo_height']:.2f} {u.length}")
    if "flexural_rigidity" in d:
        parts.append(f"D {d['flexural_rigidity']:.4g} {u.force} {u.length}")
    if "mass_per_area" in d:
        parts.append(f"mass {d['mass_per_area']:.4g} {u.mass} per {u.length}^2")
    if "stiffness" in d:
        parts.append(f"k {d['stiffness']:.4g} {u.force}/{u.length}, mass {d['mass']:.4g} {u.mass}, "
                     f"loaded area {d['loaded_area']:.4g} {u.length}^2")
    freqs = ", ".join(f"{k} {v:.3f} Hz" for k, v in s.frequencies.items())
    return f"  {s.name}: {'; '.join(parts)}; f: {freqs}"


def limits_text(a: Assessment, answer_first: bool = False) -> str:
    """The assessment as a table: DAF source, criteria, structures, allowable pressures.

    ``answer_first`` (the TUI, whose panel is often 80 columns wide) puts the
    allowable-pressure table right under the title, with its columns ordered
    structure, criterion, p+ in both units, then how it was found; the CLI
    keeps the order of the CSV.
    """
    u = a.units
    head = [a.title]
    details = [f"DAF source: {a.source}",
               f"units: {u.name} (pressure {u.pressure}, also {u.alt_pressure}; g = {u.gravity:g} "
               f"{u.length}/s^2)", "criteria:"]
    details += [f"  {c.describe()}" for c in a.criteria]
    details.append("structures:")
    details += [structure_line(s, u) for s in a.structures]
    header = (*ROW_HEADER, f"limit/DAF [{u.length}/s | {u.length}]", f"p+ [{u.pressure}]",
              f"p+ [{u.alt_pressure}]", "note")
    table: list[tuple[str, ...]] = [header]
    for r in a.rows:
        note = ", ".join(n for n, on in (("tentative", r.tentative),
                                         ("f outside criterion range", not r.in_range)) if on)
        table.append((r.structure, r.frequency_source, f"{r.frequency:.3f}", f"{r.tau:g}",
                      f"{r.ratio:.4f}", r.criterion, r.response, f"{r.daf:.4f}", fmt(r.normalized),
                      fmt(r.pressure), fmt(r.pressure_alt), note))
    if not answer_first:
        return "\n".join(head + details + ["allowable peak overpressure:"] + _columns(table))
    order = (0, 5, 9, 10, 1, 2, 3, 4, 6, 7, 8, 11)  # structure, criterion, p+ (both units), the rest
    table = [tuple(row[i] for i in order) for row in table]
    return "\n".join(head + ["allowable peak overpressure:"] + _columns(table) + details)


def limits_csv(a: Assessment) -> str:
    """The allowable-pressure CSV (``vtool boom wall|floor --csv``, ``vtool solve``, the TUI)."""
    u = a.units
    header = [*ROW_HEADER, f"limit/DAF [{u.length}/s | {u.length}]", f"p+ [{u.pressure}]",
              f"p+ [{u.alt_pressure}]"]
    rows = [[r.structure, r.frequency_source, f"{r.frequency:.10g}", f"{r.tau:.10g}",
             f"{r.ratio:.10g}", r.criterion, r.response, f"{r.daf:.10g}", f"{r.normalized:.10g}",
             f"{r.pressure:.10g}", f"{r.pressure_alt:.10g}"] for r in a.rows]
    return csv_text(header, rows)


def limits_dict(a: Assessment) -> dict[str, Any]:
    """JSON-ready assessment; units in ``*_unit`` keys."""
    u = a.units
    return {
        "kind": a.kind,
        "title": a.title,
        "units": u.name,
        "pressure_unit": u.pressure,
        "alt_pressure_unit": u.alt_pressure,
        "length_unit": u.length,
        "daf_source": a.source,
        "criteria": [{"name": c.name, "rule": c.rule(), "limited_quantity": c.quantity,
                      "value": c.value, "value_unit": c.unit, "response": c.response,
                      "tentative": c.tentative, "description": c.describe()} for c in a.criteria],
        "structures": [
            {"name": s.name, "frequencies_hz": s.frequencies, **s.details} for s in a.structures
        ],
        "limits": [
            {"structure": r.structure, "frequency_source": r.frequency_source,
             "frequency_hz": r.frequency, "tau_s": r.tau, "tau_over_T": r.ratio,
             "criterion": r.criterion, "response": r.response, "daf": r.daf,
             "limit_over_daf": r.normalized,
             "limit_over_daf_unit": f"{u.length}/s" if r.response == "velocity" else u.length,
             f"pressure_{u.pressure}": r.pressure, f"pressure_{u.alt_pressure}": r.pressure_alt,
             "criterion_frequency_range_ok": r.in_range, "tentative": r.tentative}
            for r in a.rows
        ],
    }


def design_series(a: Assessment) -> list[tuple[str, np.ndarray, dict[str, np.ndarray]]]:
    """(structure, frequencies, {label: p+ in the alternative unit}) per distinct set of design curves.

    Structures with the same mass have identical curves; each distinct set is listed once.
    """
    u = a.units
    by_structure: dict[str, dict[str, Any]] = {}
    for curve in a.curves:
        by_structure.setdefault(curve.structure, {})[f"{curve.criterion}, tau={curve.tau:g}s"] = curve
    shown: set[tuple[float, ...]] = set()
    out = []
    for name, curves in by_structure.items():
        key = tuple(round(float(v), 12) for c in curves.values() for v in c.pressure[::20])
        if key in shown:
            continue
        shown.add(key)
        first = next(iter(curves.values()))
        out.append((name, first.frequency,
                    {label: c.pressure * u.alt_per_pressure for label, c in curves.items()}))
    return out


# ----------------------------------------------------------------------------
# DAF curves (`vtool boom daf`)


def pulse_daf_table(res: PeakResponse, fourier_free: np.ndarray | None
                    ) -> tuple[list[str], list[list[str]]]:
    """CSV header and rows of one pulse's forced, free and overall DAFs against tau/T."""
    header = ["tau/T [-]"]
    columns = []
    for quantity in QUANTITIES:
        pk = res.peaks[quantity]
        for phase, values in (("forced", pk.forced), ("free", pk.free), ("overall", pk.overall)):
            header.append(f"{quantity} DAF {phase} [-]")
            columns.append(values)
        header.append(f"{quantity} peak instant [t/tau]")
        columns.append(pk.overall_at)
    if fourier_free is not None:
        header.append("free amplitude Fourier [-]")
        columns.append(fourier_free)
    rows = [[f"{r:.6g}"] + [f"{c[i]:.10g}" for c in columns] for i, r in enumerate(res.ratio)]
    return header, rows


def envelope_daf_table(envs: list[Envelope]) -> tuple[list[str], list[list[str]]]:
    header = ["tau/T [-]"]
    for env in envs:
        header += [f"{env.quantity} DAF envelope [-]", f"{env.quantity} governing pulse"]
    rows = [[f"{r:.6g}"] + [cell for env in envs for cell in (f"{env.daf[i]:.10g}", env.governing[i])]
            for i, r in enumerate(envs[0].ratio)]
    return header, rows


def _peak(values: np.ndarray, ratio: np.ndarray, at: np.ndarray | None = None) -> dict[str, Any]:
    i = int(np.argmax(values))
    out: dict[str, Any] = {"max": float(values[i]), "tau_over_T": float(ratio[i])}
    if at is not None:
        out["t_over_tau"] = float(at[i])
    return out


def pulse_daf_dict(res: PeakResponse, tau_seconds: float | None, peak_pressure: float | None,
                   fourier_gap: float | None) -> dict[str, Any]:
    """JSON-ready DAF curves of one pulse (non-dimensional; units named)."""
    quantities: dict[str, Any] = {}
    for q in QUANTITIES:
        pk = res.peaks[q]
        quantities[q] = {
            "daf_unit": "1 (peak / static response to p+)" if q == "displacement"
            else "1 (peak velocity / (p+/(m omega)))",
            "peaks": {"overall": _peak(pk.overall, res.ratio, pk.overall_at),
                      "forced": _peak(pk.forced, res.ratio, pk.forced_at),
                      "free": _peak(pk.free, res.ratio, pk.free_at)},
            "forced": pk.forced.tolist(), "free": pk.free.tolist(), "overall": pk.overall.tolist(),
            "peak_instant_t_over_tau": pk.overall_at.tolist(),
        }
    return {
        "source": res.pulse, "damping_ratio": res.damping,
        "tau_seconds": tau_seconds, "tau_seconds_unit": "s",
        "peak_pressure": peak_pressure, "peak_pressure_unit": "file units",
        "ratio_unit": "tau/T (positive duration / natural period)", "tau_over_T": res.ratio.tolist(),
        "time_unit": "t/tau", "fourier_free_max_difference": fourier_gap,
        "quantities": quantities,
    }


def envelope_daf_dict(envs: list[Envelope]) -> dict[str, Any]:
    return {
        "source": envs[0].spec.statement(), "family": envs[0].spec.family,
        "damping_ratio": envs[0].damping,
        "ratio_unit": "tau/T (positive duration / natural period)",
        "tau_over_T": envs[0].ratio.tolist(),
        "quantities": {
            env.quantity: {"daf_unit": "1", "statement": env.statement,
                           "peak": {**_peak(env.daf, env.ratio),
                                    "governing": env.governing[int(np.argmax(env.daf))]},
                           "envelope": env.daf.tolist(), "governing": list(env.governing)}
            for env in envs
        },
    }
