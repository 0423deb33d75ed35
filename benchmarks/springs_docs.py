"""Regenerate docs/springs.md's generated blocks: the presets' data-sheet springs, surge, stress and coil bind.

Run: ``python benchmarks/springs_docs.py --write`` (a few seconds; the coil-bind
speed search about half a minute); ``--check`` exits 1 when a block is not
what the code gives now. ``tests/test_springs_docs.py`` regenerates the
closed-form blocks (data sheets, surge) and compares them with the committed
page. Every number of the page's tables comes from here:
:mod:`vtool.solvers.model.spring` (rate, mass, surge, stress), a run of each
preset at its own speed (its [checks]) and
:func:`vtool.solvers.studies.sweep.find_speed` (``coil-bind-speed``).
"""

from __future__ import annotations

import sys
from pathlib import Path

from vtool.markdown import table, write_or_check
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "springs.md"
PRESETS = ("direct-acting-bucket", "ohc-finger-follower", "nested-spring-clash")
SCAN = list(range(2000, 6001, 500))  # cam rev/min


def sheet_table() -> str:
    rows = []
    for name in PRESETS:
        spec = load_preset(name)
        u = spec.unit_system
        for s in spec.springs:
            kind = "pitch diagram" if s.segment_coils else "force-length table" if s.table_lengths else "wire and coils"
            rows.append([f"`{name}`", s.name, kind, f"{s.wire_diameter:g} / {s.coil_diameter:g} {u.length}",
                         f"{s.active_coils:g} / {s.total_coils:g}", f"{s.rate:.4g} {u.stiffness}",
                         f"{1e6 * s.active_mass:.1f} g", f"{s.preload:.1f} {u.force}",
                         f"{s.solid_length:.2f} {u.length}", f"{s.stress(s.preload):.0f} {u.pressure}"])
            assert u.mass == "N*s^2/mm"  # the mass column is written in grams from tonnes
    return table(["preset", "spring", "given by", "d / D", "active / total coils", "rate", "active mass",
                  "installed preload", "solid length", "installed stress (Bergstraesser)"], rows)


def surge_table() -> str:
    from vtool.solvers.model.spring import surge_table as surge

    rows = []
    for name in PRESETS:
        spec = load_preset(name)
        for row in surge(spec.springs, spec.run.rpm):
            rows.append([f"`{name}`", row["spring"], f"{spec.run.rpm:g}"]
                        + [f"{f:.1f} Hz (order {o:.2f})" for f, o in zip(row["surge_hz"], row["surge_order"],
                                                                          strict=True)])
    return table(["preset", "spring", "cam rev/min", "1st surge", "2nd surge", "3rd surge"], rows)


def pitch_table() -> str:
    from vtool.solvers.model.spring import closing_forces

    spec = load_preset("nested-spring-clash")
    s = spec.springs[0]
    u = spec.unit_system
    rows = [[str(i + 1), f"{n:g}", f"{p:g} {u.length}", f"{n * (p - s.axial_wire):.3f} {u.length}",
             f"{f:.1f} {u.force}"]
            for i, (n, p, f) in enumerate(zip(s.segment_coils, s.segment_pitches, closing_forces(s), strict=True))]
    return table(["segment", "active coils", "free pitch", "coil gap n (p - d)", "closes at G d^4 (p - d)/(8 D^3)"],
                 rows)


def run_table() -> str:
    from vtool.solvers.run import simulate

    rows = []
    for name in PRESETS:
        spec = load_preset(name)
        summary = simulate(spec).summary()
        u = spec.unit_system
        for r in summary["springs"]:
            fatigue = "-" if r["fatigue_factor"] is None else f"{r['fatigue_factor']:.3f}"
            clash = "-" if r.get("first_coil_bind_deg") is None else f"{r['first_coil_bind_deg']:.1f} deg"
            peak = f"{r['coil_contact_peak_force']:.1f} {u.force}" if "coil_contact_peak_force" in r else "-"
            rows.append([f"`{name}`", r["name"], f"{r['max_stress']:.0f} {u.pressure}",
                         f"{r['last_cycle_force'][0]:.1f} .. {r['last_cycle_force'][1]:.1f} {u.force}", fatigue,
                         f"{r['coil_bind_margin']:.3f} {u.length}", clash, peak])
    return table(["preset", "spring", "largest stress", "last cycle force", "Goodman factor", "coil-bind margin",
                  "first coil clash", "peak coil contact force"], rows)


def contact_table() -> str:
    """The nested preset's coil contacts: opening, block stiffness and damping, and a run's peak force on every
    back end (the opening is each back end's own code)."""
    from vtool.solvers.run import simulate

    spec = load_preset("nested-spring-clash")
    u = spec.unit_system
    runs = {b: simulate(with_run_overrides(spec, backend=b)) for b in ("newmark", "exact", "scipy")}
    rows = []
    for i, c in enumerate(spec.clearances):
        if "coils" not in c.name:
            continue
        rows.append([c.name, f"{c.opening:.3f} {u.length}", f"{c.contact_stiffness:,.0f} {u.stiffness}",
                     f"{c.contact_damping_ratio:g}"] + [f"{runs[b].peak_force[i]:.2f} {u.force}" for b in runs])
    return table(["clearance", "opening (coil gap)", "block stiffness", "damping ratio", "peak force newmark",
                  "exact", "scipy"], rows)


def strength_table() -> str:
    from vtool.solvers.model.spring import STRENGTH_MATERIALS, fitted_strength_law

    rows = []
    for material, points in STRENGTH_MATERIALS.items():
        A, m = fitted_strength_law(points)
        for d, rm in points:
            rows.append([material, f"{d:g} mm", f"{rm:g} MPa", f"{A / d ** m:.0f} MPa",
                         f"{100.0 * (A / d ** m / rm - 1.0):+.2f} %", f"A = {A:.1f} MPa mm^m, m = {m:.4f}"])
    return table(["material", "wire diameter (band's upper end)", "minimum R_m (sheet)", "A / d^m", "difference",
                  "fit"], rows)


def bind_table() -> str:
    from vtool.solvers.studies.sweep import SerialRunner, find_speed

    rows = []
    for name in PRESETS:
        spec = load_preset(name)
        result = find_speed("coil-bind-speed", lambda rpm, spec=spec: with_run_overrides(spec, rpm=rpm), SCAN,
                            SerialRunner())
        rows.append([f"`{name}`", f"{result.speed:,.0f}" if result.speed else result.message,
                     str(len(result.history))])
    return table(["preset", "coil bind from (cam rev/min)", "runs"], rows)


def closed_form_blocks() -> dict[str, str]:
    return {"springs-sheets": sheet_table(), "springs-surge": surge_table(), "springs-pitch": pitch_table(),
            "springs-strength": strength_table()}


def blocks() -> dict[str, str]:
    return closed_form_blocks() | {"springs-run": run_table(), "springs-contacts": contact_table(),
                                   "springs-bind": bind_table()}


def main() -> int:
    return write_or_check(DOC, blocks, "benchmarks/springs_docs.py", __doc__.splitlines()[0])


if __name__ == "__main__":
    sys.exit(main())
