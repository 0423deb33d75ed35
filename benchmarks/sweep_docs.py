"""Regenerate the figures of docs/sweep.md: jump and bounce speeds, sweep charts, the spring-rate map.

Run: ``python3 benchmarks/sweep_docs.py`` (all local cores; about a minute on
two). Every number in docs/sweep.md's generated blocks comes from here; the
solver's numbers change when its impact law or kernel changes, and this one
command brings the page up to date. ``tests/test_sweep_docs.py`` regenerates
the deterministic tables and compares them with the committed page.
"""

from __future__ import annotations

import dataclasses
import os
import sys
from pathlib import Path

from vtool.markdown import replace_block, table
from vtool.presets import load_preset
from vtool.presets.paths import plan_sweep
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.studies.metrics import metric_columns, seat_index
from vtool.solvers.studies.steady import with_steady
from vtool.solvers.studies.sweep import SerialRunner, chunks, find_speed, make_runner, run_points

DOCS = Path(__file__).resolve().parent.parent / "docs" / "sweep.md"
PRESETS = (("gnilka-1a", "1A: three clearances, valve seat"),
           ("gnilka-1b", "1B: three clearances, no valve seat"),
           ("gnilka-1c", "1C: two clearances (rocker pinned), valve seat"),
           ("gnilka-2", "example 2 (and 3): three clearances, valve seat"),
           ("ramped-cam", "1A's mechanism on a dwell-and-ramps cam with lash"),
           ("ohv-pushrod-1a", "the train-type preset (ohv-pushrod) of 1A's data"),
           ("direct-acting-bucket", "train type direct-acting (bucket tappet)"),
           ("ohc-finger-follower", "train type finger-follower (overhead cam)"))
CAMPBELL = (("gnilka-1a", "F7"), ("ramped-cam", "F7"))  # the seat force's orders against speed
CAMPBELL_RPM = list(range(2000, 16001, 500))
SCAN = list(range(1000, 16001, 1000))  # rev/min
CHART_RPM = "run.rpm=6000:14000:250"
SPRING = "members.valve_spring.stiffness=150:350:50"
MAP_RPM = "run.rpm=8000:14000:250"


class Remembered:
    """A runner that runs each distinct point (its spec) once and hands out the kept result again.

    The speeds table's jump-speed and bounce-speed searches of a preset scan the same speeds of the same
    spec, and where both criteria change between the same scanned speeds their bisections try the same
    speeds too: the second search took the first one's runs again (a quarter of the page's regeneration).
    A point's result depends on its spec alone (:func:`vtool.solvers.studies.sweep.evaluate_point`), so the
    kept one is the result the run would give; only the index and the swept values are the asking point's.
    """

    def __init__(self, runner, kept: dict | None = None) -> None:  # type: ignore[no-untyped-def]
        self.runner = runner
        self.workers = runner.workers
        self.kept = {} if kept is None else kept  # (spec, every_step) -> its PointResult
        self.runs = 0  # points actually run

    def run(self, batches, every_step, on_results, cancel) -> bool:  # type: ignore[no-untyped-def]
        fresh = []
        for point in (p for batch in batches for p in batch):
            kept = self.kept.get((point.spec, every_step))
            if kept is None:
                fresh.append(point)
            else:
                on_results([dataclasses.replace(kept, index=point.index, values=point.values)])
        specs = {point.index: point.spec for point in fresh}
        self.runs += len(fresh)

        def keep(results) -> None:  # type: ignore[no-untyped-def]
            for result in results:
                self.kept[(specs[result.index], every_step)] = result
            on_results(results)

        return self.runner.run(chunks(fresh, self.workers), every_step, keep, cancel)

    def close(self) -> None:
        self.runner.close()


def speeds_table(runner) -> str:  # type: ignore[no-untyped-def]
    runner = Remembered(runner)
    bisector = Remembered(SerialRunner(), runner.kept)  # find_speed's default: one point at a time, here
    rows = []
    for name, words in PRESETS:
        spec = load_preset(name)
        cells = [f"`{name}`", words]
        for criterion in ("jump-speed", "bounce-speed"):  # (coil-bind-speed: docs/springs.md)
            if criterion == "bounce-speed" and seat_index(spec) is None:
                cells.append("no seat")
                continue
            result = find_speed(criterion, lambda rpm, spec=spec: with_steady(with_run_overrides(spec, rpm=rpm)),
                                SCAN, runner, bisector=bisector)
            steps = len(result.history)
            intervals = "; ".join(f"{i.low:,.0f}-{i.high:,.0f}" + ("" if i.above is not None else "+")
                                  for i in result.intervals)
            cells.append(f"{result.speed:,.0f} ({steps} runs; intervals {intervals})" if result.speed
                         else result.message)
        rows.append(cells)
    return table(["preset", "mechanism", "jump speed (rev/min)", "bounce speed (rev/min)"], rows)


def spring_table(runner) -> str:  # type: ignore[no-untyped-def]
    base = load_preset("gnilka-1a")
    unit = base.unit_system.stiffness
    rows = []
    for point in plan_sweep("gnilka-1a", [SPRING]).points:
        stiffness = dict(point.values)["members.valve_spring.stiffness"]
        result = find_speed("jump-speed", lambda rpm, spec=point.spec: with_run_overrides(spec, rpm=rpm), SCAN,
                            runner)
        rows.append([f"{stiffness:g}", f"{result.speed:,.0f}" if result.speed else result.message])
    return table([f"valve-spring rate ({unit})", "1A jump speed (rev/min)"], rows)


def chart_blocks(runner) -> dict[str, str]:  # type: ignore[no-untyped-def]
    from vtool.app.sweep_charts import metric_chart, metric_map

    blocks = {}
    for name, _ in PRESETS[:4]:  # the thesis presets (plan_sweep cannot yet find the ramped cam's lift table)
        plan = plan_sweep(name, [CHART_RPM])
        results = run_points(plan.points, runner).results
        units = dict(metric_columns(plan.spec))
        charts = [metric_chart(results, plan.fields, metric, units[metric], width=90, height=18, color=False)
                  for metric in ("spring_margin", "cam_separation_duration")]
        blocks[f"sweep-chart-{name}"] = "```text\n" + "\n".join(charts) + "\n```\n"
    plan = plan_sweep("gnilka-1a", [MAP_RPM, SPRING])
    results = run_points(plan.points, runner).results
    units = dict(metric_columns(plan.spec))
    blocks["sweep-spring-map"] = ("```text\n" + metric_map(results, plan.fields, "cam_separation_duration",
                                                           units["cam_separation_duration"]) + "\n```\n")
    return blocks


def campbell_block(runner, name: str, quantity: str) -> str:  # type: ignore[no-untyped-def]
    """``vtool sweep NAME --set run.rpm=2000:16000:500 --steady --campbell QUANTITY``'s map."""
    from vtool.app.sweep_charts import campbell_map
    from vtool.solvers.studies.orders import campbell, with_orders
    from vtool.solvers.studies.sweep import Point

    spec = with_steady(with_orders(load_preset(name), (quantity,)))
    points = [Point(i, (("run.rpm", rpm),), with_run_overrides(spec, rpm=rpm)) for i, rpm in enumerate(CAMPBELL_RPM)]
    results = run_points(points, runner).results
    data = campbell([(float(dict(r.values)["run.rpm"]), r.metrics) for r in results if r.ok], spec, quantity)
    return "```text\n" + campbell_map(data) + "\n```\n"


def deterministic_blocks(runner=None) -> dict[str, str]:  # type: ignore[no-untyped-def]
    """The tables and maps a test regenerates (no wall times in them)."""
    runner = runner or SerialRunner()
    blocks = {"sweep-speeds": speeds_table(runner), "sweep-spring": spring_table(runner)}
    for name, quantity in CAMPBELL:
        blocks[f"sweep-campbell-{name}"] = campbell_block(runner, name, quantity)
    return blocks


def main() -> None:
    runner = make_runner(os.cpu_count() or 1)
    try:
        blocks = deterministic_blocks(runner) | chart_blocks(runner)
    finally:
        runner.close()
    for name, text in blocks.items():
        changed = replace_block(DOCS, name, text)
        print(f"{name}: {'updated' if changed else 'unchanged'}", file=sys.stderr)


if __name__ == "__main__":
    main()
