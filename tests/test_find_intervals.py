"""Every speed interval where the follower leaves the cam or the valve bounces (solvers/studies/sweep.py
find_speed), each run to steady state, against brute-force scans of the same runs."""

from __future__ import annotations

import warnings

import pytest

from tests.test_backends import base_excited_doc
from vtool.presets import load_preset
from vtool.presets.valvetrain import load, with_run_overrides
from vtool.solvers.studies.steady import with_steady
from vtool.solvers.studies.sweep import CRITERIA, Point, SerialRunner, find_speed, run_points


def holds(criterion: str, make_spec, speeds: list[float]) -> list[bool]:  # noqa: ANN001
    """The brute-force scan: the criterion at every speed, each run to steady state."""
    metric, test, _ = CRITERIA[criterion]
    points = [Point(i, (("run.rpm", r),), make_spec(r)) for i, r in enumerate(speeds)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return [bool(test(r.metrics[metric])) for r in run_points(points, SerialRunner()).results]


def preset_at(name: str):  # noqa: ANN201
    spec = load_preset(name)
    return lambda rpm: with_steady(with_run_overrides(spec, rpm=rpm))


def two_windows_at(rpm: float):  # noqa: ANN201
    """A follower (0.3 g) pressed on a 0.1 in harmonic cam by a 50 lbf preload through a drive spring to a
    sprung mass: the mass' resonance (about 11,000 rev/min) throws the follower off, above it the mass is
    isolated and the follower stays on, and above about 35,000 its own inertia throws it off again."""
    doc = base_excited_doc(360.0)
    doc["cam"]["amplitude"] = 0.1
    doc["damping"] = {"default_ratio": 0.05}
    doc["members"]["drive"]["mass"] = 3e-4
    doc["run"].update(rpm=rpm, steady={"tolerance": 1e-3, "max_cycles": 40}, time_step=2e-6)
    return load(doc)


def check_edges(criterion: str, make_spec, result, step: float, reach: float,  # noqa: ANN001
                upper: bool = True) -> None:
    """Around every bisected edge a fine scan (``step`` rev/min, ``reach`` either side) has its own edge (the
    lowest speed that holds for a lower edge, the highest for an upper one) within two steps of it: an edge
    can be ragged on a scale below the step (where 1A's bounces end, near 12,000 rev/min, they stop and
    start again within tens of rev/min)."""
    for interval in result.intervals:
        for edge, lower in ((interval.low, True), (interval.high, False)):
            if (interval.below if lower else interval.above) is None or not (lower or upper):
                continue
            speeds = [edge + k * step for k in range(-int(reach / step), int(reach / step) + 1)]
            fine = holds(criterion, make_spec, speeds)
            held = [s for s, h in zip(speeds, fine, strict=True) if h]
            assert held and not all(fine), (edge, list(zip(speeds, fine, strict=True)))
            fine_edge = min(held) if lower else max(held)
            assert abs(fine_edge - edge) <= 2 * step, (edge, list(zip(speeds, fine, strict=True)))


@pytest.mark.slow
def test_two_windows_of_contact_loss_are_two_intervals_each_where_a_fine_scan_puts_it() -> None:
    result = find_speed("jump-speed", two_windows_at, list(range(2000, 60001, 2000)), SerialRunner())
    assert len(result.intervals) == 2
    first, second = result.intervals
    assert 9000 < first.low < first.high < 14000 < 30000 < second.low < 40000 and second.above is None
    assert first.high - first.low < 3000  # a window, not a threshold
    assert result.speed == first.low
    check_edges("jump-speed", two_windows_at, result, step=50.0, reach=150.0)
    # and the brute-force scan between the windows: in contact all the way
    assert not any(holds("jump-speed", two_windows_at, list(range(int(first.high) + 500, int(second.low), 2000))))


@pytest.mark.slow
@pytest.mark.parametrize("name", ["gnilka-1a", "ramped-cam", "ohv-pushrod-1a", "direct-acting-bucket",
                                  "ohc-finger-follower"])
@pytest.mark.slow
def test_jump_speed_is_the_lowest_speed_a_brute_force_scan_shows_the_follower_off_the_cam(name: str) -> None:
    """The thesis mechanism, the ramped cam and the train-type presets."""
    make = preset_at(name)
    result = find_speed("jump-speed", make, list(range(1000, 20001, 1000)), SerialRunner())
    assert result.speed is not None
    below = holds("jump-speed", make, list(range(1000, int(result.speed), 200)))
    assert not any(below)  # nothing below the answer on a 200 rev/min scan ...
    check_edges("jump-speed", make, result, step=20.0, reach=60.0)  # ... and the edge where a 20 one puts it


def test_gnilka_1a_leaves_the_cam_at_15000_to_16000_rpm() -> None:
    assert all(holds("jump-speed", preset_at("gnilka-1a"), [15000.0, 15500.0, 16000.0]))


@pytest.mark.slow
def test_the_bounce_speed_of_gnilka_1a_is_found_and_where_a_fine_scan_puts_it() -> None:
    make = preset_at("gnilka-1a")
    result = find_speed("bounce-speed", make, list(range(1000, 20001, 1000)), SerialRunner())
    assert result.speed is not None and 1000 < result.speed < 5000
    # the bounce speed (the lower edge); the upper end, near 12,000 rev/min, is ragged over hundreds of rev/min
    check_edges("bounce-speed", make, result, step=20.0, reach=60.0, upper=False)


def test_cli_find_writes_every_interval_to_csv_and_json(tmp_path) -> None:  # noqa: ANN001
    """1A's bounce over 2,000-13,000 rev/min in 5,500 steps: one interval bisected at both ends, in the
    CSV's intervals column and the JSON's intervals list, equal to find_speed's."""
    import csv
    import json

    from click.testing import CliRunner

    from vtool.app.cli.main import cli

    out = tmp_path / "find.csv"
    args = ["sweep", "gnilka-1a", "--find", "bounce-speed", "--set", "run.rpm=2000,7500,13000", "--workers", "1"]
    written = CliRunner().invoke(cli, args + ["--csv", str(out)])
    assert written.exit_code == 0, written.output
    header, row = list(csv.reader(out.read_text().splitlines()))
    assert header == ["bounce_speed (rev/min)", "intervals (rev/min)", "message"]
    result = find_speed("bounce-speed", preset_at("gnilka-1a"), [2000, 7500, 13000], SerialRunner())
    (interval,) = result.intervals
    assert row[1] == f"{interval.low:g}-{interval.high:g}" and row[0] == f"{result.speed:g}"
    assert interval.below is not None and interval.above is not None  # both ends bracketed and bisected
    shown = CliRunner().invoke(cli, args + ["--json"])
    searches = json.loads(shown.stdout)["searches"]
    assert searches[0]["intervals"] == [{"low_rpm": interval.low, "high_rpm": interval.high,
                                         "below_rpm": interval.below, "above_rpm": interval.above}]


class PatternRunner:
    """A runner (the sweep's runner interface) that runs nothing: a point "holds" when its speed lies in one
    of the given integer intervals, so that find_speed's bracketing and bisection can be checked on any
    pattern of contact loss."""

    workers = 1

    def __init__(self, intervals: list[tuple[int, int]]) -> None:
        self.intervals = intervals
        self.runs = 0

    def holds(self, rpm: float) -> bool:
        return any(a <= rpm <= b for a, b in self.intervals)

    def run(self, batches, every_step, on_results, cancel) -> bool:  # noqa: ANN001
        from vtool.solvers.studies.sweep import PointResult

        for batch in batches:
            self.runs += len(batch)
            on_results([PointResult(p.index, p.values, {"cam_separations": int(self.holds(dict(p.values)["run.rpm"]))})
                        for p in batch])
        return True


def test_every_interval_a_scan_touches_is_found_with_exact_edges() -> None:
    """Property (hypothesis): for any set of disjoint integer speed intervals whose edges fall between
    different pairs of neighbouring scanned speeds (one change of state per bracket), every interval is
    reported with its exact edges (tolerance 1 rev/min), and no other."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    spec = load_preset("gnilka-1a")
    scan = list(range(1000, 20001, 1000))
    brackets = st.lists(st.integers(0, len(scan) - 2), max_size=8, unique=True).map(sorted)

    @st.composite
    def patterns(draw) -> list[tuple[int, int]]:  # noqa: ANN001
        """Changes of state at t = first speed of the new state, one in each chosen (scan[i], scan[i + 1]]."""
        chosen = draw(brackets)
        changes = [scan[i] + draw(st.integers(1, scan[i + 1] - scan[i])) for i in chosen]
        changes = changes[: len(changes) // 2 * 2]
        return [(changes[i], changes[i + 1] - 1) for i in range(0, len(changes), 2)]

    @settings(max_examples=60, deadline=None)
    @given(patterns())
    def check(intervals: list[tuple[int, int]]) -> None:
        runner = PatternRunner(intervals)
        result = find_speed("jump-speed", lambda rpm: spec, scan, runner, bisector=runner)
        assert [(i.low, i.high) for i in result.intervals] == intervals
        for i in result.intervals:
            assert i.below == i.low - 1 and i.above == i.high + 1  # bracketed to 1 rev/min either side
        assert result.speed == (intervals[0][0] if intervals else None)
        assert runner.runs <= len(scan) + 2 * len(intervals) * 10  # 10 bisections an edge: log2(1000)

    check()
