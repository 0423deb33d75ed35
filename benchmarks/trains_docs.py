"""Regenerate docs/trains.md's generated blocks and its cam-shape figure.

Run: ``python benchmarks/trains_docs.py --write`` (about half a minute);
``--check`` exits 1 when a block is not what the code gives now.
``tests/test_trains_docs.py`` regenerates the blocks and compares them with
the committed page. Every number of the page's tables comes from here: the
cam's shape (:mod:`vtool.solvers.model.camshape`), a run of each preset at its
own speed and its [checks] (:mod:`vtool.solvers.model.camstress`,
:mod:`vtool.solvers.studies.checks`), and the jump speed
(:func:`vtool.solvers.studies.sweep.find_speed`).
"""

from __future__ import annotations

import sys
from pathlib import Path

from vtool.markdown import table, write_or_check
from vtool.presets import load_preset
from vtool.presets.valvetrain import with_run_overrides

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "trains.md"
FIGURE = ROOT / "docs" / "figures" / "trains-cam-shape.svg"
PRESETS = ("direct-acting-bucket", "ohc-finger-follower")
SCAN = list(range(1000, 8001, 1000))  # cam rev/min


def shape_table() -> str:
    from vtool.solvers.model.camshape import shape_report

    rows = []
    for name in PRESETS:
        spec = load_preset(name)
        r = shape_report(spec)
        u = r["length_unit"]
        ratio = (f"{r['ratio_base_circle']:.4f} (base circle), {r['ratio_min']:.4f} .. {r['ratio_max']:.4f}"
                 if "ratio_min" in r else "1 (direct)")
        travel = f"{r['max_contact_travel']:.3f} {u}" if "max_contact_travel" in r else "-"
        undercut = ", ".join(f"{a:.1f}..{b:.1f} deg" for a, b in r["undercut_deg"]) or "none"
        rows.append([f"`{name}`", f"{r['follower']}, {r['arrangement']}", f"{r['base_radius']:g} {u}",
                     f"{r['min_convex_curvature_radius']:.3f} {u}", undercut,
                     f"{r['max_pressure_angle_deg']:.2f}", travel, f"{r['max_valve_lift']:.3f} {u}", ratio])
    return table(["preset", "follower", "base radius", "smallest radius of curvature", "undercut",
                  "largest pressure angle (deg)", "contact travel", "valve lift", "finger ratio dV/du"], rows)


def stress_table() -> str:
    from vtool.solvers.run import simulate

    rows = []
    for name in PRESETS:
        spec = load_preset(name)
        summary = simulate(spec).summary()
        s = summary["contact_stress"]
        p, u = s["pressure_unit"], s["length_unit"]
        film = "-" if s.get("min_film_thickness") is None else \
            f"{1000.0 * s['min_film_thickness']:.3f} um at {s['min_film_thickness_angle_deg']:.0f} deg"
        checks = "; ".join(f"{c['name']} {'PASS' if c['passed'] else 'FAIL' if c['passed'] is not None else 'n/a'}"
                           + ("" if c["margin"] is None else f" ({c['margin']:.3g} {c['unit']})")
                           for c in summary.get("checks", []))
        rows.append([f"`{name}`", f"{spec.run.rpm:g}", f"{s['max_contact_pressure']:.1f} {p} at "
                     f"{s['max_contact_pressure_angle_deg']:.0f} deg", f"{1000.0 * s['max_half_width']:.1f} um",
                     f"{s['max_normal_force']:.1f} {s['force_unit']}", film, checks])
        assert u == "mm"  # the film and half-width columns are written in um from mm
    return table(["preset", "cam rev/min", "max Hertz pressure", "max half-width", "max normal force",
                  "min film (Dowson-Higginson)", "checks (margin)"], rows)


def jump_table() -> str:
    from vtool.solvers.studies.sweep import SerialRunner, find_speed

    rows = []
    for name in PRESETS:
        spec = load_preset(name)
        result = find_speed("jump-speed", lambda rpm, spec=spec: with_run_overrides(spec, rpm=rpm), SCAN,
                            SerialRunner())
        rows.append([f"`{name}`", f"{result.speed:,.0f}" if result.speed else result.message,
                     f"{2 * result.speed:,.0f}" if result.speed else "-", str(len(result.history))])
    return table(["preset", "jump speed (cam rev/min)", "engine rev/min", "runs"], rows)


def blocks() -> dict[str, str]:
    return {"trains-shape": shape_table(), "trains-stress": stress_table(), "trains-jump": jump_table()}


def figure_bytes() -> bytes:
    from vtool.app.figures import build_figure, figure_bytes
    from vtool.presets.charts import cam_shape_charts

    charts = [chart for name in PRESETS for chart in cam_shape_charts(load_preset(name))]
    return figure_bytes(build_figure(charts), "svg")


def write_figure() -> None:
    from vtool.files import write_atomic_bytes

    FIGURE.parent.mkdir(exist_ok=True)
    write_atomic_bytes(FIGURE, figure_bytes(), "figure")
    print(f"wrote {FIGURE.relative_to(ROOT)}", file=sys.stderr)


def main() -> int:
    return write_or_check(DOC, blocks, "benchmarks/trains_docs.py", __doc__.splitlines()[0], write_figure)


if __name__ == "__main__":
    sys.exit(main())
