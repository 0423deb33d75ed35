"""Every table of measured valve-train numbers in README.md and docs/valvetrain.md, regenerated.

Run: ``python3 benchmarks/tables_valvetrain.py`` (about a minute on an idle
2-core machine; ``--no-write`` only prints). It rewrites the generated blocks

* ``accuracy-<preset>`` in docs/valvetrain.md: the speed/accuracy trade of
  each valve-train preset (``vtool accuracy PRESET``);
* ``accuracy-worst`` in README.md: per setting, the worst case over the
  presets; ``accuracy-default``: the default setting, preset by preset;
* ``speed`` in README.md and docs/valvetrain.md: warm wall time, steps and
  events of the default run of every preset, the exact back end's warm time
  (both the best of five after a first run), and a second process' start-up
  from the numba cache;
* ``table-6-1`` in docs/valvetrain.md: example 1A's events beside the
  thesis' Table 6.1.

Wall times are one run on the machine at hand; everything else (steps,
events, unmatched events, errors to two significant digits) is deterministic
for given numpy/scipy versions, which the scipy rows name, and
tests/test_tables_valvetrain.py checks it against the committed blocks.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

from vtool.markdown import replace_block, table
from vtool.presets import load_preset
from vtool.solvers.model.spec import MechanismSpec
from vtool.solvers.run import simulate
from vtool.solvers.studies.accuracy import (
    RTOLS,
    AccuracyRow,
    accuracy_study,
    cells,
    fmt,
    markdown_header,
    with_run,
)
from vtool.solvers.trace import CLOSED, OPENED, Trace

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOC = ROOT / "docs" / "valvetrain.md"
PRESETS = ("gnilka-1a", "gnilka-1b", "gnilka-1c", "gnilka-1d", "gnilka-2", "gnilka-3")
DEFAULT_SETTING = "dt=1e-06 beta=1/6"
FLOAT_DEG = 1.0  # a cam-clearance opening longer than this is the pushrod floating, not a ping
TIMING_HEADERS = ("wall time", "(ms)")  # columns that are not reproducible


@dataclass(frozen=True)
class PresetStudy:
    name: str
    spec: MechanismSpec
    reference: Trace
    rows: list[AccuracyRow]


def study(name: str, scipy: bool = True) -> PresetStudy:
    """The accuracy study of one preset (without the scipy rows if ``scipy`` is False)."""
    spec = load_preset(name)
    reference, rows = accuracy_study(spec, rtols=RTOLS if scipy else ())
    return PresetStudy(name, spec, reference, rows)


def accuracy_block(result: PresetStudy) -> str:
    return table(markdown_header(result.spec.unit_system.length), [cells(row) for row in result.rows])


def worst_block(results: list[PresetStudy]) -> str:
    """Per setting, the worst figure over the presets, and which preset it is."""
    studied = [{(row.backend, row.setting) for row in r.rows} for r in results]
    settings = [(row.backend, row.setting) for row in results[0].rows
                if all((row.backend, row.setting) in keys for keys in studied)]
    body = []
    for backend, setting in settings:
        rows = [(r.name, next(x for x in r.rows if (x.backend, x.setting) == (backend, setting)))
                for r in results]
        measured = [(name, row) for name, row in rows if row.events is not None]
        refused = len(rows) - len(measured)
        if not measured:
            body.append([backend, setting, "", "", "", "", "", "", rows[0][1].note])
            continue

        def worst(key: str, spec: str, scale: float = 1.0, measured: list = measured) -> str:
            values = [(getattr(row, key), name) for name, row in measured if getattr(row, key) is not None]
            if not values:
                return ""
            value, name = max(values, key=lambda item: item[0])  # the first preset of a tie
            text = fmt(value, spec, scale)
            return f"{text} ({name.removeprefix('gnilka-')})" if value > 0 else text

        slowest = max(row.wall_time for _, row in measured)
        parts = [(name, part) for name, row in measured for part in row.note.split("; ") if part]
        pulled = sorted({name.removeprefix("gnilka-") for name, part in parts if part.startswith("closed contacts pulled")})
        notes = sorted({part for _, part in parts if not part.startswith("closed contacts pulled")})
        note = "; ".join(([f"closed contacts pulled ({', '.join(pulled)})"] if pulled else []) + notes)
        if refused:
            note = f"refused for {refused} preset(s); " + note
        body.append([backend, setting, fmt(slowest, ".3f"), worst("unmatched_events", "d"),
                     worst("event_angle_error", ".2g"), worst("peak_force_error", ".2g", 100),
                     worst("seating_velocity_error", ".2g", 100), worst("lift_error", ".2g"), note])
    head = ["backend", "setting", "wall time (s), slowest", "unmatched, most (preset)",
            "max \\|dtheta\\| (deg), worst", "peak force err (%), worst", "seating vel err (%), worst",
            "lift err (in), worst", "note"]
    return table(head, body)


def default_block(results: list[PresetStudy]) -> str:
    """The default setting (Newmark, beta = 1/6, dt = 1 µs, refined) against exact, per preset, worst first."""
    body = []
    for r in results:
        row = next(x for x in r.rows if x.setting == DEFAULT_SETTING)
        exact = r.rows[0]
        body.append((row.event_angle_error or 0.0, [
            r.name, fmt(row.event_angle_error, ".2g"), fmt(row.unmatched_events, "d"),
            fmt(row.peak_force_error, ".2g", 100), fmt(row.seating_velocity_error, ".2g", 100),
            fmt(row.lift_error, ".2g"), f"{row.events} / {exact.events}",
            fmt(row.wall_time, ".3f"), fmt(exact.wall_time, ".3f")]))
    body.sort(key=lambda item: -item[0])
    head = ["preset", "max \\|dtheta\\| (deg)", "unmatched", "peak force err (%)", "seating vel err (%)",
            "lift err (in)", "events (Newmark / exact)", "wall time (s)", "exact wall time (s)"]
    return table(head, [cells for _, cells in body])


def warm_time(spec: MechanismSpec, repeat: int = 5) -> tuple[float, Trace]:
    simulate(spec)  # JIT warm-up (or cache load)
    best, trace = float("inf"), None
    for _ in range(repeat):
        started = time.perf_counter()
        trace = simulate(spec)
        best = min(best, time.perf_counter() - started)
    return best, trace


def speed_block(results: list[PresetStudy], second_process: tuple[float, float] | None) -> str:
    """Default run (Newmark, the preset's step) of every preset, slowest first, and the exact back end."""
    body = []
    for r in results:
        best, trace = warm_time(r.spec)
        exact_best, exact = warm_time(with_run(r.spec, backend="exact"))  # warm, as the 50 ms target is set
        body.append((best, [r.name, f"{best * 1e3:.1f}", str(trace.statistics.steps), str(trace.statistics.events),
                            f"{exact_best * 1e3:.0f}", str(exact.statistics.events)]))
    body.sort(key=lambda item: -item[0])
    rows = [cells for _, cells in body]
    if second_process is not None:
        total, ratio = second_process
        rows.append(["`vtool solve gnilka-1a` in a second process (numba's cache and Python's bytecode), median of seven",
                     f"{total * 1e3:.0f} with interpreter start-up, {ratio:.2f} x `python3 -c \"import numpy, numba\"`",
                     "", "", "", ""])
    head = ["preset (Newmark, the preset's dt, with refinement after events)", "warm wall time (ms)", "steps",
            "events", "exact back end, warm (ms)", "exact events"]
    return table(head, rows)


def _at(events: Iterable, clearance: str, kind: str, after: float) -> object | None:
    return next((e for e in events if e.clearance == clearance and e.kind == kind and e.cam_angle > after), None)


def table_6_1_block(trace: Trace) -> str:
    """Example 1A's second cycle beside the thesis' Table 6.1 (points read off its graphs).

    The points are found by rules over the event list of the default run:
    N the first seat impact past 540°, P the first opening at the cam after N
    that lasts more than FLOAT_DEG (the pushrod floats), A the cam impact that ends it, D the next seat impact, E the first rocker
    impact after D, G the first cam impact after E, I the first cam opening
    after G.
    """
    events = trace.events
    rows = []

    def angle(event: object | None) -> str:
        return "" if event is None else f"{event.cam_angle:.1f}"

    def speed(event: object | None) -> str:
        return "" if event is None else f"{abs(event.relative_velocity):.0f}"

    n = _at(events, "seat", CLOSED, 540.0)
    p = a = None
    after = n.cam_angle if n else math.inf
    while p is None and (opening := _at(events, "cam", OPENED, after)) is not None:
        landing = _at(events, "cam", CLOSED, opening.cam_angle)
        if landing is None or landing.cam_angle - opening.cam_angle > FLOAT_DEG:
            p, a = opening, landing
        after = opening.cam_angle
    d = _at(events, "seat", CLOSED, n.cam_angle) if n else None
    e = _at(events, "rocker", CLOSED, d.cam_angle) if d else None
    g = _at(events, "cam", CLOSED, e.cam_angle) if e else None
    i = _at(events, "cam", OPENED, g.cam_angle) if g else None
    unit = trace.spec.unit_system
    velocity = f"{unit.length}/{unit.time}"
    for point, thesis, what, event, rule in (
        ("N", "579", "valve impacts the seat", n, "first seat impact past 540°"),
        ("P", "583", "valve bounce, pushrod floats clear", p, f"cam clearance opens for > {FLOAT_DEG:g}° after N"),
        ("A", "270 (630)", "cam at its lowest, pushrod floating", a, "pushrod lands on the cam, ending P"),
        ("D", "300 (660)", "valve bounces on the seat", d, "next seat impact"),
        ("E", "336 (696)", "pushrod impacts the rocker", e, "first rocker impact after D"),
        ("G", "357 (717)", "cam contacts the pushrod", g, "first cam impact after E"),
        ("I", "380 (740)", "the pushrod is thrown clear", i, "cam clearance opens after G"),
    ):
        impact = event is not None and event.kind == CLOSED
        rows.append([point, thesis, what, angle(event), speed(event) if impact else "", rule])
    return table(["thesis point", "thesis (deg)", "what the thesis describes", "vtool 1A (deg)",
                  f"impact velocity ({velocity})", "which event (rule)"], rows)


def deterministic(block: str) -> list[list[str]]:
    """The cells of a generated table with the wall-time columns blanked."""
    lines = [line for line in block.strip().splitlines() if line.startswith("|")]
    rows = [[cell.strip() for cell in line.strip().strip("|").split(" | ")] for line in lines]
    timing = [k for k, name in enumerate(rows[0]) if any(t in name for t in TIMING_HEADERS)]
    return [[("" if k in timing else cell) for k, cell in enumerate(row)] for row in rows if not row[0].startswith("---")
            and "second process" not in row[0]]


def blocks(results: list[PresetStudy], second_process: tuple[float, float] | None) -> dict:
    """{(path, block name): Markdown}."""
    out = {(DOC, f"accuracy-{r.name.removeprefix('gnilka-')}"): accuracy_block(r) for r in results}
    out[(README, "accuracy-worst")] = worst_block(results)
    out[(README, "accuracy-default")] = default_block(results)
    speed = speed_block(results, second_process)
    out[(README, "speed")] = speed
    out[(DOC, "speed")] = speed
    one_a = next((r for r in results if r.name == "gnilka-1a"), None)
    if one_a is not None:
        out[(DOC, "table-6-1")] = table_6_1_block(simulate(one_a.spec))
    return out


def warm_up() -> None:
    """Compile (or load) every back end's kernels first, so no wall time in the tables includes it."""
    spec = load_preset(PRESETS[0])
    for backend in ("newmark", "exact", "scipy"):
        simulate(with_run(spec, backend=backend, degrees=20.0))


def main(argv: list[str]) -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import statistics

    from bench_newmark import second_process

    warm_up()
    results = []
    for name in PRESETS:
        started = time.perf_counter()
        results.append(study(name))
        print(f"{name}: {time.perf_counter() - started:.1f} s", file=sys.stderr)
    pairs = second_process()  # (solve, import numpy and numba) seconds, alternating
    generated = blocks(results, (statistics.median(a for a, _ in pairs), statistics.median(a / b for a, b in pairs)))
    for (path, name), text in generated.items():
        if "--no-write" in argv:
            print(f"{path.name} {name}:\n{text}")
        elif replace_block(path, name, text):
            print(f"rewrote {path.relative_to(ROOT)} block {name}")
        else:
            print(f"{path.relative_to(ROOT)} block {name}: unchanged")


if __name__ == "__main__":
    main(sys.argv[1:])
