"""CSV output: the compiled number formatter writes Python's text; streamed rows equal the trace's CSV.

The reference for every number is Python's own ``'%.10g' % x`` (C's ``%g``
with 10 significant digits); for a streamed run, the CSV of the same run
held in memory.
"""

from __future__ import annotations

import io
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from vtool.app.cli.main import cli
from vtool.csvrows import format_rows, python_row
from vtool.errors import RunError
from vtool.files import open_atomic
from vtool.presets import load_preset
from vtool.solvers.backends import available
from vtool.solvers.run import simulate
from vtool.solvers.trace import CsvStream

EDGES = [0.0, -0.0, 1.0, -1.0, 0.5, 1e-4, 9.9999999995e-5, 9.99999999949e-5, 1e-5, 123456789.0, 1234567890.0,
         9999999999.0, 12345678901.0, 9999999999.5, 9999999998.5, 0.1, 0.2, 0.3, 1 / 3, 2 / 3, 1e22, 1e23, 1e-22,
         5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, math.nan, math.inf, -math.inf, 1e100,
         -1e-100, 0.00012345678905, 2.5, 1.00000000005, 1.00000000015, 1e16, 123.456, 1e-35, 1e35, 1e-36,
         1e36, 1e44, 1e-44, 4.35, 0.000123456789012345]


def reference(values: np.ndarray, labels: list[str], which: np.ndarray) -> str:
    return "".join(python_row(values[r], labels[int(which[r])]) for r in range(values.shape[0]))


def test_the_formatter_writes_pythons_text_on_edges_ties_and_every_magnitude() -> None:
    rng = np.random.default_rng(7)
    random = rng.uniform(-10, 10, 30_000) * 10.0 ** rng.integers(-40, 40, 30_000)
    ties = (rng.integers(0, 10**10, 5_000) + 0.5) * 10.0 ** rng.integers(-14, 4, 5_000)  # half-way at digit 11
    integers = rng.integers(-10**12, 10**12, 5_000).astype(float)
    values = np.concatenate([EDGES, -np.array(EDGES), random, ties, integers])
    values = np.concatenate([values, np.zeros(-values.size % 5)]).reshape(-1, 5)
    labels = ["7,cam+rocker", ",none", "II,siège"]  # a label may be empty in parts or not ASCII
    which = rng.integers(0, len(labels), values.shape[0])
    assert format_rows(values, labels, which, compiled=True) == reference(values, labels, which)


def test_repeated_columns_are_written_as_the_same_text() -> None:
    rng = np.random.default_rng(3)
    base = rng.normal(size=(500, 3)) * 10.0 ** rng.integers(-8, 8, (500, 3))
    base[7, 1] = math.nan  # a row Python writes: its copies too
    values = np.column_stack([base, base[:, 1], -base[:, 0], base[:, 0], np.where(base[:, 2] > 0, 0.0, -0.0)])
    which = np.zeros(len(values), dtype=np.int64)
    assert format_rows(values, ["x"], which, compiled=True) == reference(values, ["x"], which)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=1, max_size=12))
def test_the_formatter_agrees_with_python_for_any_float(numbers: list[float]) -> None:
    values = np.array(numbers)[None, :]
    assert format_rows(values, ["x"], np.zeros(1, dtype=np.int64), compiled=True) == python_row(values[0], "x")


def test_no_rows_is_no_text_and_python_writes_the_same_text() -> None:
    assert format_rows(np.zeros((0, 3)), ["x"], np.zeros(0, dtype=np.int64)) == ""
    values = np.array([[1.5, -0.0, 1e-300], [math.pi, 1e21, -7.25e-5]])
    which = np.array([0, 1])
    assert (format_rows(values, ["a", "b"], which, compiled=False)
            == format_rows(values, ["a", "b"], which, compiled=True) == "1.5,-0,1e-300,a\n3.141592654,1e+21,-7.25e-05,b\n")


@pytest.fixture(scope="module")
def spec_1a():  # noqa: ANN201
    spec = load_preset("gnilka-1a")
    return replace(spec, run=replace(spec.run, degrees=800.0))  # a seat bounce in the second revolution


def streamed(spec, handle, thin: bool = True):  # noqa: ANN001, ANN201
    stream = CsvStream(handle, spec.run.quantities, thin=thin)
    return simulate(spec, every_step=True, stream=stream), stream


@pytest.mark.parametrize("backend", available())
def test_a_streamed_every_step_csv_equals_the_trace_held_in_memory(spec_1a, backend: str) -> None:  # noqa: ANN001
    spec_1a = replace(spec_1a, run=replace(spec_1a.run, backend=backend))
    whole = simulate(spec_1a, every_step=True)
    buffer = io.StringIO()
    thinned, stream = streamed(spec_1a, buffer)
    assert buffer.getvalue() == whole.csv_text(spec_1a.run.quantities)
    assert stream.rows == len(whole.time) > 2 * len(thinned.time)
    # the summary (seat bounce heights included) is the whole trace's: only the wall times differ
    ours, theirs = thinned.summary(), whole.summary()
    for summary in (ours, theirs):
        summary.pop("wall_time_s")
        summary.pop("compile_time_s")
    assert ours == theirs
    assert any(c.get("bounce_heights_per_revolution", [[]])[0] for c in theirs["clearances"])
    assert thinned.time[-1] == whole.time[-1] and set(thinned.time) <= set(whole.time)


def test_a_streamed_csv_at_the_output_interval_equals_the_trace(spec_1a) -> None:  # noqa: ANN001
    trace = simulate(spec_1a)
    buffer = io.StringIO()
    stream = CsvStream(buffer, spec_1a.run.quantities)
    kept = simulate(spec_1a, stream=stream)
    assert buffer.getvalue() == trace.csv_text(spec_1a.run.quantities)
    assert len(kept.time) == len(trace.time) == stream.rows


def test_a_cancelled_streamed_run_leaves_no_file(tmp_path: Path, spec_1a) -> None:  # noqa: ANN001
    out = tmp_path / "out.csv"
    spec = replace(spec_1a, run=replace(spec_1a.run, backend="exact"))  # polls cancel after every segment
    stream = CsvStream(None, thin=True)

    def cancel() -> bool:
        return stream.rows > 100  # after rows were written to the temporary file

    with pytest.raises(RunError, match="cancelled"), open_atomic(out, "--csv") as handle:
        stream.handle = handle
        simulate(spec, every_step=True, stream=stream, cancel=cancel)
    assert stream.rows > 100 and list(tmp_path.iterdir()) == []


def test_rows_out_of_time_order_are_refused() -> None:
    from vtool.solvers.trace import TraceBuilder

    spec = load_preset("gnilka-1a")
    builder = TraceBuilder(spec, (10, 11), 100.0, CsvStream(io.StringIO()))
    q3 = np.zeros((2, 3, spec.n_coordinates + 2))
    builder.add_rows(np.array([0.0, 1.0]), q3, np.zeros((2, 3)), np.zeros(2, dtype=np.int64))
    with pytest.raises(RunError, match="out of time order"):
        builder.add_rows(np.array([0.5, 2.0]), q3, np.zeros((2, 3)), np.zeros(2, dtype=np.int64))


def test_cli_every_step_csv_counts_the_streamed_rows(tmp_path: Path) -> None:
    out = tmp_path / "steps.csv"
    result = CliRunner().invoke(cli, ["solve", "gnilka-1a", "--degrees", "100", "--every-step", "--csv", str(out)])
    assert result.exit_code == 0, result.output
    lines = out.read_text().splitlines()
    assert f"wrote {len(lines) - 1} rows to" in result.output
    assert lines[0].startswith("time (s),cam_angle (deg),q1 (in),") and lines[0].endswith(",configuration,closed")
