"""The figures docs/figures.md (and docs/torque.md) embed, drawn by the commands' own chart data (small PNGs
at 60 dpi).

``python benchmarks/docs_figures.py --write`` (re)draws every figure into
docs/figures/; ``--check`` draws them into a temporary folder and fails if a
figure its page embeds is missing, not a PNG, or larger than :data:`MAX_BYTES`
(pixels differ across machines' font rasterisers, so the check is not byte
for byte). Each figure belongs to one page (:data:`PAGES`; default
docs/figures.md). tests/test_figures.py runs ``--check`` on one figure.
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from collections.abc import Callable
from functools import cache
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FOLDER = ROOT / "docs" / "figures"
PAGE = ROOT / "docs" / "figures.md"
DPI = 60
MAX_BYTES = 120_000


def _solve() -> list:
    from vtool.presets import load_preset
    from vtool.presets.charts import trace_charts
    from vtool.solvers.run import simulate

    return trace_charts(simulate(load_preset("gnilka-1a")))


def _sweep() -> list:
    from vtool.presets.charts import sweep_chart, sweep_map
    from vtool.presets.paths import plan_sweep
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import SerialRunner, run_points

    plan = plan_sweep("gnilka-1a", ["run.rpm=8000:12000:500", "members.valve_spring.stiffness=200,254,300"])
    results = run_points(plan.points, SerialRunner()).results
    unit = dict(metric_columns(plan.spec))["peak_F1"]
    return [sweep_map(results, plan.fields, "peak_F1", unit, plan.spec.title),
            sweep_chart(results, plan.fields, "peak_F1", unit)]


def _cam() -> list:
    from vtool.presets import load_preset
    from vtool.presets.charts import cam_charts

    return cam_charts(load_preset("ramped-cam"))[:3]


def _daf() -> list:
    from vtool.assessments.sonic_boom import pulses, response, spectra
    from vtool.presets.charts import daf_chart

    ratio = spectra.ratio_grid(0.0, 2.5, 0.01)
    pulse = pulses.make_pulse(pulses.PulseParams("N", 2.0, 0.0, None, None, None))
    res = response.peak_response(pulse, ratio, 0.0)
    return [daf_chart(ratio, {"velocity overall": res.velocity.overall, "velocity forced": res.velocity.forced,
                              "displacement overall": res.displacement.overall}, f"DAF of {pulse.label}")]


def _torque_train() -> list:
    from vtool.presets import load_preset
    from vtool.presets.camshaft import train_torque_chart
    from vtool.solvers.run import simulate

    return [train_torque_chart(simulate(load_preset("ohc-finger-follower")))]


def _torque_camshaft() -> list:
    from vtool.presets.camshaft import camshaft_chart, load_camshaft, solve

    spec = load_camshaft("four-cylinder-intake")
    return [camshaft_chart(spec.title, solve(spec))]


@cache
def _hla_charts() -> list:
    """The chamber pressure and pump-up charts of the shipped HLA finger train over four cycles (one run for
    both figures; above the cost guard's default scipy limit, hence max_steps)."""
    import dataclasses

    from vtool.presets import load_preset
    from vtool.presets.hla_charts import hla_charts
    from vtool.solvers.run import simulate
    from vtool.solvers.studies.hla import hla_series

    spec = load_preset("ohc-finger-follower-hla")
    spec = dataclasses.replace(spec, run=dataclasses.replace(spec.run, cycles=4, degrees=1440.0))
    return hla_charts(hla_series(simulate(spec, max_steps=1e7)), spec.title)


FIGURES: dict[str, Callable[[], list]] = {"solve-gnilka-1a": _solve, "sweep-map": _sweep, "cam-ramped": _cam,
                                          "boom-daf": _daf, "torque-train": _torque_train,
                                          "torque-camshaft": _torque_camshaft,
                                          "hla-pressure": lambda: _hla_charts()[:1],
                                          "hla-pump-up": lambda: _hla_charts()[1:]}
#: the page that embeds a figure, where it is not docs/figures.md
PAGES: dict[str, Path] = {name: ROOT / "docs" / "torque.md"
                          for name in ("torque-train", "torque-camshaft", "hla-pressure", "hla-pump-up")}


def draw(names: list[str], folder: Path) -> list[Path]:
    from vtool.app.figures import save_figure

    return [save_figure(FIGURES[name](), folder / f"{name}.png", "docs", dpi=DPI) for name in names]


def check(paths: list[Path]) -> list[str]:
    problems = []
    embedded: dict[Path, set[str]] = {}
    for page in {PAGE, *PAGES.values()}:
        embedded[page] = set(re.findall(r"\]\(figures/([\w.-]+\.png)\)", page.read_text()))
        for name in embedded[page]:
            if not (FOLDER / name).is_file():
                problems.append(f"{page.relative_to(ROOT)} embeds figures/{name}, which is missing (run --write)")
    for path in paths:
        data = path.read_bytes()
        if not data.startswith(b"\x89PNG") or len(data) > MAX_BYTES:
            problems.append(f"{path.name}: not a PNG of at most {MAX_BYTES} bytes ({len(data)})")
        page = PAGES.get(path.stem, PAGE)
        if path.name not in embedded[page]:
            problems.append(f"{path.name} is drawn but {page.relative_to(ROOT)} does not embed it")
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true")
    parser.add_argument("--check", action="store_true")
    parser.add_argument("--only", help="comma-separated figure names (default: all)")
    args = parser.parse_args(argv)
    names = args.only.split(",") if args.only else list(FIGURES)
    if args.write:
        for path in draw(names, FOLDER):
            print(f"wrote {path.relative_to(ROOT)} ({path.stat().st_size:,} bytes)")
    with tempfile.TemporaryDirectory() as folder:
        problems = check(draw(names, Path(folder)))
    for problem in problems:
        print(problem)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
