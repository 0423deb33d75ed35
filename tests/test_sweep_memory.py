"""A large sweep keeps nothing per point (issue 42): a range is (start, step, count) with the values the list had,
a resumed sweep's finished points are one bit each, and planning a 10^5-point range allocates next to nothing."""

from __future__ import annotations

import tracemalloc
from decimal import Decimal
from typing import Any

from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.presets.paths import (
    CHECK_ALL_VALUES,
    PointGrid,
    SpecMaker,
    ValueRange,
    parse_values,
    plan_sweep,
)
from vtool.solvers.studies.sweep import IndexSet, format_value


def listed(start: int | float, step: int | float, count: int) -> list[Any]:
    """The swept values as parse_values listed them before ranges were kept as three numbers."""
    if isinstance(start, int) and isinstance(step, int):
        return [start + i * step for i in range(count)]
    return [float(f"{start + i * step:.12g}") for i in range(count)]


def same(a: list[Any], b: list[Any]) -> bool:
    """Equal value by value, bit for bit and in type (1000 and 1000.0 are written differently)."""
    return [(type(v), v.hex() if isinstance(v, float) else v) for v in a] == \
        [(type(v), v.hex() if isinstance(v, float) else v) for v in b]


decimals = st.decimals(min_value=-100_000, max_value=100_000, places=3, allow_nan=False, allow_infinity=False)
steps = st.decimals(min_value=Decimal("0.001"), max_value=1000, places=3).map(lambda d: d.normalize())


@settings(max_examples=200, deadline=None)
@given(start=decimals, step=steps, count=st.integers(1, 2000), falling=st.booleans(), integer=st.booleans())
def test_a_range_gives_the_exact_decimal_values_the_list_gave(start: Decimal, step: Decimal, count: int,
                                                               falling: bool, integer: bool) -> None:
    """Typed as a user types it: each value is the exact decimal start + i*step (at most 10 significant digits
    here, so the 12-digit rounding makes it exact, except near 0), bit-identical to the old list, and found
    from its text."""
    if integer:
        start, step = start.to_integral_value(), max(step.to_integral_value(), Decimal(1))
    step = -step if falling else step
    stop = start + (count - 1) * step
    text = f"{start}:{stop}:{step}"
    values = parse_values("f", text)
    assert isinstance(values, ValueRange) and len(values) == count
    got = list(values)
    numbers = [float(start + i * step) for i in range(count)]
    # the exact decimal, but near 0 (12 significant digits of the sum's round-off: -0.071 + 71 * 0.001 is
    # 1.39e-17, as the list had it) only within 1e-12 of the range's size
    scale = float(max(abs(start), abs(stop)))
    assert all(g == n if abs(n) > 1e-3 * scale else abs(g - n) <= 1e-12 * scale for g, n in zip(got, numbers,
                                                                                              strict=True))
    assert same(got, listed(values.start, values.step, count))
    assert same([values[i] for i in range(-count, count)], got + got)
    assert values.extremes() == (got[0], got[-1])
    first: dict[str, int] = {}
    for i, value in enumerate(got):
        first.setdefault(format_value(value), i)
    for shown, i in first.items():
        assert values.index_of(shown, format_value) == i


def test_1000_to_6000_by_0_05_is_the_list_bit_for_bit() -> None:
    assert list(parse_values("f", "10935.322:10935.326:0.001"))[-1] == 10935.326  # counted in floats: 4 values
    values = parse_values("run.rpm", "1000:6000:0.05", max_points=200_000)
    assert len(values) == 100_001 and values[-1] == 6000.0 and values[20] == 1001.0
    assert same(list(values), listed(1000, 0.05, 100_001))
    assert all(v == float(Decimal(1000) + i * Decimal("0.05")) for i, v in enumerate(values))


@settings(max_examples=60, deadline=None)
@given(start=st.integers(-1000, 1000), digits=st.integers(7, 13), count=st.integers(2, 400), falling=st.booleans())
def test_fine_ranges_locate_and_axes_as_the_list_did(start: int, digits: int, count: int, falling: bool) -> None:
    """Steps below the 10 digits a sweep file writes (and the 12 a value keeps): several values share one text;
    locate gives the first index with that text and axes() counts distinct values, as the lists' tables did."""
    step = Decimal(1).scaleb(-digits) * (-1 if falling else 1)
    values = parse_values("f", f"{start}:{start + (count - 1) * step}:{step}")
    got = list(values)
    grid = PointGrid([("f", values), ("g", [1, 2])], SpecMaker({}))
    reference = {format_value(v): i for i, v in reversed(list(enumerate(got)))}
    for v in got:
        assert grid.locate([format_value(v), "2"]) == reference[format_value(v)] + count
    assert grid.locate([format_value(got[-1] + 10.0 * abs(float(step)) + 1), "1"]) is None
    assert grid.locate(["x", "1"]) is None and grid.locate([format_value(got[0]), "3"]) is None
    assert ("f" in grid.axes()) == (len(set(map(repr, got))) > 1) and "g" in grid.axes()


@settings(max_examples=100, deadline=None)
@given(st.lists(st.integers(0, 5000), max_size=300))
def test_index_set_is_a_set(indices: list[int]) -> None:
    found = IndexSet(indices)
    assert len(found) == len(set(indices)) and sorted(found) == sorted(set(indices)) == list(found)
    assert all(i in found for i in indices) and all(i not in found for i in range(6000) if i not in set(indices))
    assert -1 not in found and "1" not in found
    copied = found.copy()
    copied.add(7000)
    assert 7000 in copied and 7000 not in found and len(copied) == len(found) + 1
    assert len(found.bits) <= 2 * (max(indices, default=0) // 8 + 1)  # one bit an index, doubled when grown


def peak_bytes(rpm: str) -> int:
    """Bytes allocated at the peak while ``run.rpm=rpm`` is planned and its axes, checked points, last point's
    index and first 1,000 points in run order are asked for."""
    tracemalloc.start()
    try:
        plan = plan_sweep("gnilka-1a", [f"run.rpm={rpm}"])
        points = plan.points
        assert points.axes() == ["run.rpm"] and isinstance(points.fields[0][1], ValueRange)
        last = len(points) - 1
        assert points.locate([format_value(points.values(last)[0][1])]) == last
        assert len(list(points.checked_values())) == (len(points) if len(points) <= CHECK_ALL_VALUES else 2)
        assert sum(1 for _ in zip(range(1000), points.run_order(), strict=False)) == min(1000, len(points))
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_planning_a_100000_point_range_allocates_what_a_10_point_one_does() -> None:
    """The plan of 10^5 points: within 50 kB of the peak of a 10-point range's (the loader's own work, about
    1 MB, is the same for both). A list of the values alone is 3.2 MB; the old axes() made a set of their
    texts, about 10 MB."""
    plan_sweep("gnilka-1a", ["run.rpm=1000:1001:1"])  # the loader's imports and caches
    small, large = peak_bytes("1000:1000.45:0.05"), peak_bytes("1000:5999.95:0.05")
    assert large - small < 50_000, (small, large)
