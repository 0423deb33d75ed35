"""`vtool sweep`: values and paths, validation before work, a point equals `vtool solve`, execution paths
that give identical files, resume, the jump-speed search (thesis: 1A thrown off at 11,000, not 10,000 RPM)."""

from __future__ import annotations

import json
import math
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli
from vtool.errors import InputError
from vtool.presets import find_preset, load_preset, read_document
from vtool.presets.paths import get_field, parse_values, plan_sweep, set_field
from vtool.presets.valvetrain import with_run_overrides
from vtool.solvers.run import simulate
from vtool.solvers.studies import sweep
from vtool.solvers.studies.metrics import run_metrics
from vtool.solvers.studies.sweep import (
    DaskRunner,
    ProcessRunner,
    SerialRunner,
    SweepFile,
    evaluate,
    find_speed,
    grid,
    run_points,
)

# a short 1A run (460 deg: the second revolution's nose and the seating) keeps the tests quick
SHORT = "run.degrees=460"


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


# ----- values and paths -----

def test_ranges_include_stop_and_lists_keep_types() -> None:
    assert list(parse_values("run.rpm", "2000:3000:250")) == [2000, 2250, 2500, 2750, 3000]
    assert list(parse_values("f", "0.1:0.3:0.1")) == [0.1, 0.2, 0.3]
    assert list(parse_values("f", "3:1:-1")) == [3, 2, 1]
    assert parse_values("f", "1,2.5,newmark") == [1, 2.5, "newmark"]


@pytest.mark.parametrize("text, words", [("5000:4000:250", "sign of stop - start"), ("1:2:0", "other than 0"),
                                         (",", "non-empty"), ("1:2", "start:stop:step"), ("a:b:c", "three numbers")])
def test_bad_values_are_one_line_errors(text: str, words: str) -> None:
    with pytest.raises(InputError, match=words):
        parse_values("run.rpm", text)


def test_paths_read_and_set_tables_and_arrays() -> None:
    doc = read_document(find_preset("gnilka-1a"))
    assert get_field(doc, "members.valve_spring.stiffness") == 254.0
    assert get_field(doc, "clearances[2].name") == "seat"
    changed = set_field(doc, "clearances[2].restitution", 0.5)
    assert changed["clearances"][2]["restitution"] == 0.5 and doc["clearances"][2]["restitution"] == 0.0
    with pytest.raises(InputError, match=r"clearances\[5\]"):
        set_field(doc, "clearances[5].restitution", 0.5)


def test_grid_varies_the_first_field_fastest() -> None:
    points = grid([("a", [1, 2]), ("b", ["x", "y"])])
    assert points == [(("a", 1), ("b", "x")), (("a", 2), ("b", "x")), (("a", 1), ("b", "y")), (("a", 2), ("b", "y"))]


@pytest.mark.parametrize("args, message", [
    (["--set", "run.rpn=1000,2000"], "run.rpn: got 1000, expected"),
    (["--set", "members.spring.stiffness=100"], "members.spring: got missing"),
    (["--set", "run.rpm=5000:4000:250"], "sign of stop - start"),
    (["--set", "run.rpm=,"], "non-empty"),
    (["--set", "run.rpm=-100:100:100"], "run.rpm: got -100, expected"),
    (["--set", "clearances[2].restitution=0.5,1.5"], "clearances[2].restitution: got 1.5, expected"),
    (["--set", "run.rpm=9000", "--scheduler", "tcp://127.0.0.1:9"], "--scheduler: got 'tcp://127.0.0.1:9'"),
    (["--set", "run.rpm=9000", "--metric", "nonsense"], "--metric: got 'nonsense'"),
])
def test_bad_sweep_input_is_one_line_exit_2_nothing_written(tmp_path: Path, args: list[str], message: str) -> None:
    out = tmp_path / "sweep.csv"
    result = run("sweep", "gnilka-1a", *args, "--csv", str(out))
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and message in lines[0], result.output
    assert not out.exists() and list(tmp_path.iterdir()) == []


# ----- a sweep point is `vtool solve` at the same settings -----

def _without_timing(metrics: dict) -> dict:
    return {k: v for k, v in metrics.items() if k != "wall_time"}


def _same(a: dict, b: dict) -> bool:
    return all((math.isnan(a[k]) and math.isnan(b[k])) or a[k] == b[k] for k in a)


def test_a_sweep_point_equals_a_single_solve() -> None:
    plan = plan_sweep("gnilka-1a", ["run.rpm=10500,11000"])
    outcome = run_points(plan.points, SerialRunner())
    for point, result in zip(plan.points, outcome.results, strict=True):
        rpm = dict(point.values)["run.rpm"]
        alone = run_metrics(simulate(with_run_overrides(load_preset("gnilka-1a"), rpm=rpm)))
        assert _same(_without_timing(result.metrics), _without_timing(alone))
    # and `vtool solve --json` reports the same events and seat impacts
    solved = json.loads(run("solve", "gnilka-1a", "--rpm", "11000", "--json").output)
    metrics = outcome.results[1].metrics
    assert metrics["events"] == solved["events"]
    seat = [-e["relative_velocity"] for e in solved["events_list"]
            if e["clearance"] == "seat" and e["kind"] == "closed" and e["cam_angle_deg"] >= 360]
    assert metrics["seating_velocity_max"] == max(seat)
    assert metrics["seating_velocity_mean"] == pytest.approx(sum(seat) / len(seat), rel=1e-15)


def test_model_reuse_across_rpm_changes_nothing() -> None:
    """A chunk reuses the assembled model from one speed to the next: same numbers as fresh runs."""
    plan = plan_sweep("gnilka-1a", ["run.rpm=10000,10600", SHORT])
    chained = run_points(plan.points, SerialRunner()).results
    fresh = [evaluate(p)[0] for p in plan.points]  # no model to reuse: each assembled afresh
    for a, b in zip(chained, fresh, strict=True):
        assert _same(_without_timing(a.metrics), _without_timing(b.metrics))


def test_a_speed_search_assembles_its_model_once_and_each_point_keeps_its_own_title(monkeypatch) -> None:  # type: ignore[no-untyped-def]  # noqa: ANN001
    """The speed override rewrites the title, which is no part of the model: a serial search's scan and
    its bisection steps (one runner call each) share one assembled model, and so its configurations."""
    assembled = []
    real = sweep.assemble

    def counting(spec):  # type: ignore[no-untyped-def]  # noqa: ANN001, ANN202
        assembled.append(spec.title)
        return real(spec)

    monkeypatch.setattr(sweep, "assemble", counting)
    spec = load_preset("gnilka-1a")
    monkeypatch.setattr(sweep._LAST, "mechanism", None, raising=False)  # nothing kept from an earlier test
    result = find_speed("jump-speed", lambda rpm: with_run_overrides(with_run_overrides(spec, degrees=460), rpm=rpm),
                        [9000, 12000], SerialRunner())
    assert len(result.history) > 3 and len(assembled) == 1, assembled
    first, second = (with_run_overrides(spec, rpm=rpm) for rpm in (9000, 12000))
    assert first.title != second.title
    _, mechanism = evaluate(sweep.Point(0, (("run.rpm", 12000),), second), previous=real(first))
    assert mechanism is not None and mechanism.spec.title == second.title


# ----- execution paths, files, resume -----

def _sweep_file(tmp_path: Path, name: str, runner, plan) -> bytes:  # type: ignore[no-untyped-def]
    path = tmp_path / name
    try:
        run_points(plan.points, runner, sink=SweepFile(path, plan.fields, plan.spec))
    finally:
        runner.close()
    return path.read_bytes()


@pytest.mark.slow
def test_serial_processes_and_dask_give_identical_files(tmp_path: Path) -> None:
    plan = plan_sweep("gnilka-1a", ["run.rpm=10000:11000:250", "damping.factor=0.5,1", SHORT])
    serial = _sweep_file(tmp_path, "serial.csv", SerialRunner(), plan)
    processes = _sweep_file(tmp_path, "processes.csv", ProcessRunner(2), plan)
    dask = _sweep_file(tmp_path, "dask.csv", DaskRunner("local-threads:2"), plan)
    assert serial == processes == dask
    lines = serial.decode().splitlines()
    assert len(lines) == 11 and lines[0].startswith("run.rpm (rev/min),damping.factor,run.degrees (deg),status,cam_separations,")
    assert "peak_F1 (lbf)" in lines[0] and "wall_time" not in lines[0]


def test_resume_of_a_cut_file_gives_the_uninterrupted_file(tmp_path: Path) -> None:
    plan = plan_sweep("gnilka-1a", ["run.rpm=10000:11000:250", SHORT])
    full = _sweep_file(tmp_path, "full.csv", SerialRunner(), plan)
    lines = full.decode().splitlines(keepends=True)
    cut = tmp_path / "cut.csv"
    cut.write_text(lines[0] + lines[3] + lines[1] + lines[4][:20])  # out of order, last line cut by a kill
    sink = SweepFile(cut, plan.fields, plan.spec, resume=True)
    outcome = run_points(plan.points, SerialRunner(), sink=sink)
    assert outcome.skipped == 2 and len(outcome.results) == 5
    assert [r.index for r in outcome.results] == [0, 1, 2, 3, 4]
    assert cut.read_bytes() == full


def test_cancel_leaves_a_valid_partial_file(tmp_path: Path) -> None:
    plan = plan_sweep("gnilka-1a", ["run.rpm=10000:11000:250", SHORT])
    path = tmp_path / "partial.csv"
    calls = []

    def cancel() -> bool:
        calls.append(1)
        return len(calls) > 2

    outcome = run_points(plan.points, SerialRunner(), sink=SweepFile(path, plan.fields, plan.spec), cancel=cancel)
    assert not outcome.complete and 0 < len(outcome.results) < 5
    rows = path.read_text().splitlines()
    assert len(rows) == 1 + len(outcome.results)


@pytest.mark.slow
def test_resume_after_kill_gives_the_same_file(tmp_path: Path) -> None:
    # points of 40000 degrees (tens of ms each even on a fast machine), so that the kill lands mid-sweep
    sweep = [sys.executable, "-m", "vtool", "sweep", "gnilka-1a", "--set", "run.rpm=9000:11000:100",
             "--set", "run.degrees=40000", "--set", "run.output_interval=50", "--workers", "1"]
    full, partial = tmp_path / "full.csv", tmp_path / "partial.csv"
    assert subprocess.run(sweep + ["--csv", str(full)], capture_output=True).returncode == 0
    process = subprocess.Popen(sweep + ["--csv", str(partial)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while time.time() < deadline and (not partial.exists() or partial.read_text().count("\n") < 4):
        time.sleep(0.005)
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    kept = partial.read_text().count("\n") - 1
    assert 3 <= kept < 21
    resumed = subprocess.run(sweep + ["--csv", str(partial), "--resume"], capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert f"resumed: {kept} of 21 points" in resumed.stderr
    assert partial.read_bytes() == full.read_bytes()


# ----- derived speeds -----

def test_thesis_1a_is_thrown_off_over_the_nose_at_11000_not_10000_rpm() -> None:
    """At 10,000 rev/min the follower leaves the cam only on the opening flank (after the lash is taken up,
    320 deg), at 11,000 also over the nose (90 deg), as the thesis has it."""
    plan = plan_sweep("gnilka-1a", ["run.rpm=10000,11000"])
    low, high = run_points(plan.points, SerialRunner()).results
    assert low.metrics["cam_separations"] == 1 and 300 < low.metrics["cam_separation_angle"] < 340
    assert high.metrics["cam_separations"] >= 1
    assert 60 < high.metrics["cam_separation_angle"] < 120  # near the nose (90 deg)


@pytest.mark.slow
def test_jump_speed_agrees_with_a_one_rpm_grid() -> None:
    spec = load_preset("gnilka-1a")
    result = find_speed("jump-speed", lambda rpm: with_run_overrides(spec, rpm=rpm), [5000, 6000], SerialRunner())
    speed = result.speed
    assert speed is not None and 5000 < speed < 6000
    assert [b.stage for b in result.history][:2] == ["scan", "scan"] and len(result.history) <= 14
    plan = plan_sweep("gnilka-1a", [f"run.rpm={speed - 2}:{speed + 2}:1"])
    separations = [r.metrics["cam_separations"] for r in run_points(plan.points, SerialRunner()).results]
    assert [s >= 1 for s in separations] == [False, False, True, True, True]


def test_find_prints_the_bracket_history() -> None:
    """Scan two speeds (in contact during lift at 5,000, off the cam at 6,000) and bisect to 1 rev/min."""
    result = run("sweep", "gnilka-1a", "--find", "jump-speed", "--set", "run.rpm=5000,6000", "--workers", "1")
    assert result.exit_code == 0, result.output
    lines = result.stdout.splitlines()
    assert lines[0].startswith("criteria: the follower leaves the cam when its contact is open > 1 deg with a gap > "
                               "0.001 in during the lift event")  # the stated thresholds: 1 deg, 0.1 % of 1 in
    assert lines[1].startswith("each run: cycle by cycle to steady state (tolerance 0.001")
    lines = lines[2:]
    assert lines[0].split()[:4] == ["scan", "5000", "rev/min", "no"]
    assert lines[1].split()[:4] == ["scan", "6000", "rev/min", "holds"]
    assert all(line.split()[0] == "bisect" for line in lines[2:-2]) and 9 <= len(lines) - 4 <= 10
    assert lines[-2].startswith("  interval: ") and "(the highest scanned speed, or above)" in lines[-2]
    match = re.fullmatch(r"jump-speed: the follower leaves the cam during lift from (\d+) rev/min "
                         r"\(not at (\d+)\)", lines[-1])
    assert match is not None and int(match[1]) - int(match[2]) == 1


def test_cli_table_csv_json_plot_and_map(tmp_path: Path) -> None:
    out = tmp_path / "s.csv"
    args = ["sweep", "gnilka-1a", "--set", "run.rpm=10000,11000", "--set", "damping.factor=0.5,1", "--set", SHORT,
            "--workers", "1"]
    result = run(*args, "--csv", str(out), "--plot", "--map", "--metric", "peak_F1")
    assert result.exit_code == 0, result.output
    assert "wrote 4 rows" in result.output and "peak_F1 (lbf)" in result.output and "scale:" in result.output
    assert out.read_text().count("\n") == 5
    data = json.loads(run(*args, "--json").stdout)
    assert data["units"]["peak_F1_unit"] == "lbf" and data["units"]["run.rpm_unit"] == "rev/min"
    assert len(data["points"]) == 4 and data["points"][0]["status"] == "ok"


# ----- a large sweep keeps nothing per point -----

def test_the_grid_makes_its_points_on_demand_in_grid_order() -> None:
    """PointGrid (the plan's points) holds the fields' values only: point i's values are grid()'s i-th, its
    spec the loader's for them; run_order visits each index once with run.* varying fastest; locate inverts
    the values as a sweep file writes them."""
    from vtool.solvers.studies.sweep import format_value

    plan = plan_sweep("gnilka-1a", ["damping.factor=0.5,1,2", "run.rpm=10000,10500", SHORT])
    points = plan.points
    assert [p.values for p in points] == grid([("damping.factor", [0.5, 1, 2]), ("run.rpm", [10000, 10500]),
                                               ("run.degrees", [460])])
    doc = set_field(set_field(read_document(find_preset("gnilka-1a")), "damping.factor", 1), "run.rpm", 10500)
    from vtool.presets import load_document

    assert points[4].spec == load_document(set_field(doc, "run.degrees", 460), find_preset("gnilka-1a").parent)
    assert points.lazy(4).spec is None and points.lazy(4).make(points.values(4)) == points[4].spec
    order = list(points.run_order())
    assert sorted(order) == list(range(6)) and order[:2] == [0, 3]  # run.rpm first: 0.5 at 10000, 10500
    for i in range(6):
        assert points.locate([format_value(v) for _, v in points.values(i)]) == i
    assert points.locate(["0.7", "10000", "460"]) is None
    assert points.axes() == ["damping.factor", "run.rpm"]


def test_only_ranges_ends_and_corners_are_checked_before_the_run() -> None:
    """100,000 points are planned after a handful of loader checks, not 100,000 (each about 10 ms)."""
    import vtool.presets as presets

    calls = []
    load = presets.load_document

    def counted(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls.append(1)
        return load(*args, **kwargs)

    presets.load_document = counted
    try:
        plan = plan_sweep("gnilka-1a", ["run.rpm=1000:50999:1", "damping.factor=0.5,1"])
    finally:
        presets.load_document = load
    assert len(plan.points) == 100_000 and len(calls) < 20
    with pytest.raises(InputError, match="run.rpm"):  # a range's end is still refused up front
        plan_sweep("gnilka-1a", ["run.rpm=-1000:100999:1"])


def test_a_point_the_loader_refuses_when_it_runs_is_a_failed_row(tmp_path: Path) -> None:
    """A value no up-front check met (here a grid made without them) is the loader's one-line message as the
    point's status, NaN metrics, and the sweep goes on."""
    from vtool.presets.paths import PointGrid, SpecMaker

    doc = read_document(find_preset("gnilka-1a"))
    points = PointGrid([("run.rpm", [10000, -5]), ("run.degrees", [100])],
                       SpecMaker(doc, find_preset("gnilka-1a").parent, load_preset("gnilka-1a")))
    path = tmp_path / "s.csv"
    outcome = run_points(points, SerialRunner(), sink=SweepFile(path, [("run.rpm", "rev/min"),
                                                                     ("run.degrees", "deg")],
                                                                load_preset("gnilka-1a")))
    good, bad = outcome.results
    assert good.ok and not bad.ok and bad.status.startswith("run.rpm: got -5, expected")
    assert all(math.isnan(v) for v in bad.metrics.values())
    rows = path.read_text().splitlines()
    assert rows[2].startswith('-5,100,"run.rpm: got -5') and len(rows) == 3


def test_cancel_stops_the_check_of_the_points() -> None:
    """``plan_sweep``'s ``cancel`` is asked before each checked point (the TUI's Cancel while checking)."""
    from vtool.presets.paths import SweepCancelled, plan_sweep

    asked = []
    with pytest.raises(SweepCancelled):
        plan_sweep("gnilka-1a", ["run.rpm=1000:30999:1", "damping.factor=0.5,1,2"],
                   cancel=lambda: asked.append(1) or len(asked) > 2)
    assert len(asked) == 3


def test_a_pool_starts_every_worker_while_other_threads_hold_the_interpreter() -> None:
    """The pool's start tasks meet at a barrier, so no worker is idle before the last is submitted: each
    submission starts its own process. With plain os.getpid tasks a worker that finished while the starting
    thread waited for the GIL took the next task, fewer processes started than workers, and start() waited
    for the missing ones until its deadline (the TUI monkey's seed 148, sweeps started from several threads)."""
    import threading

    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            sum(range(1000))

    spinners = [threading.Thread(target=spin, daemon=True) for _ in range(4)]
    for thread in spinners:
        thread.start()
    runner = ProcessRunner(3)
    try:
        runner.start(timeout=60.0)
        assert len(runner.pids) == 3
    finally:
        stop.set()
        runner.close()
