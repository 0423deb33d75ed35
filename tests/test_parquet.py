"""``--format parquet`` (solvers/parquet.py): the same numbers as the CSV, in row groups; one line without pyarrow."""

from __future__ import annotations

import csv
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from vtool.app.cli.main import cli

pq = pytest.importorskip("pyarrow.parquet")


def run(*args: str):
    return CliRunner().invoke(cli, list(args))


def read_csv(path: Path) -> tuple[list[str], list[list[str]]]:
    rows = list(csv.reader(path.open()))
    return rows[0], rows[1:]


def test_every_step_parquet_has_the_csv_numbers_in_row_groups(tmp_path: Path) -> None:
    from vtool.solvers.parquet import ROW_GROUP

    result = run("solve", "gnilka-1a", "--every-step", "--out", str(tmp_path / "run.parquet"))
    assert result.exit_code == 0, result.output
    assert run("solve", "gnilka-1a", "--every-step", "--csv", str(tmp_path / "run.csv")).exit_code == 0
    header, rows = read_csv(tmp_path / "run.csv")
    parquet = pq.ParquetFile(tmp_path / "run.parquet")
    table = parquet.read()
    assert table.num_rows == len(rows) > ROW_GROUP  # a run of more steps than one group
    assert parquet.metadata.num_row_groups == math.ceil(len(rows) / ROW_GROUP)
    assert f"wrote {len(rows)} rows to" in result.output
    # every numeric column (named as the CSV names it, once) equal to the CSV's 10 significant digits
    names = list(dict.fromkeys(header[:-2]))
    assert table.schema.names == ["time (s)", "cam_angle (deg)", *names[2:], "configuration", "closed"]
    for name in names:
        column = header.index(name)
        expected = np.array([float(r[column]) if r[column] else math.nan for r in rows])
        assert np.allclose(table.column(name).to_numpy(), expected, rtol=6e-10, atol=0.0, equal_nan=True), name
    configuration = [int(r[-2]) if r[-2] else None for r in rows]
    assert table.column("configuration").to_pylist() == configuration
    assert table.column("closed").to_pylist() == [r[-1] for r in rows]
    assert parquet.schema_arrow.metadata[b"title"].decode().startswith("Gnilka 1971 example 1A")


def test_sweep_parquet_has_the_csv_points(tmp_path: Path) -> None:
    sweep = ["sweep", "gnilka-1d", "--set", "run.rpm=9000,10000,11000", "--set", "run.degrees=400", "--workers", "1"]
    result = run(*sweep, "--format", "parquet", "--out", str(tmp_path / "points.pq"))
    assert result.exit_code == 0, result.output
    assert "wrote 3 rows to" in result.output and "peak_F1" not in result.output  # the file has the table
    assert run(*sweep, "--csv", str(tmp_path / "points.csv")).exit_code == 0
    header, rows = read_csv(tmp_path / "points.csv")
    table = pq.read_table(tmp_path / "points.pq")
    assert table.schema.names == ["point", *header]
    by_point = sorted(zip(table.column("point").to_pylist(), range(table.num_rows), strict=True))
    for (point, row), expected in zip(by_point, rows, strict=True):
        assert point == rows.index(expected)
        for name, cell in zip(header, expected, strict=True):
            value = table.column(name)[row].as_py()
            if name == "status":
                assert value == cell
            else:
                assert (math.isnan(value) and cell == "") or value == pytest.approx(float(cell), rel=1e-9)


def test_sweep_writer_holds_at_most_one_row_group(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Memory bounded: the sink never buffers more than ROW_GROUP points (here 100, for a small test)."""
    import vtool.solvers.parquet as parquet
    from vtool.files import open_atomic_binary
    from vtool.presets import load_preset
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import PointResult

    monkeypatch.setattr(parquet, "ROW_GROUP", 100)
    spec = load_preset("gnilka-1d")
    names = [name for name, _ in metric_columns(spec)]
    most = 0
    with open_atomic_binary(tmp_path / "s.parquet") as handle:
        sink = parquet.SweepParquet(handle, (("run.rpm", "rev/min"),), spec)
        for i in range(1050):
            sink.append(PointResult(i, (("run.rpm", 1000.0 + i),), dict.fromkeys(names, float(i))))
            most = max(most, sink.groups.buffered + sink.held)
        sink.finish()
    assert most < 100
    file = pq.ParquetFile(tmp_path / "s.parquet")
    assert file.metadata.num_row_groups == 11 and file.metadata.num_rows == 1050
    assert file.read().column("run.rpm (rev/min)").to_pylist() == [1000.0 + i for i in range(1050)]


def test_a_sweeps_row_groups_hold_about_group_bytes_of_numbers(tmp_path: Path) -> None:
    """The writer's memory grows with a group's rows: a sweep's groups hold GROUP_BYTES of numbers (8 bytes a
    value), fewer rows for more columns, between 1,024 and ROW_GROUP rows."""
    from vtool.files import open_atomic_binary
    from vtool.presets import load_preset
    from vtool.solvers.parquet import GROUP_BYTES, ROW_GROUP, SweepParquet, group_rows
    from vtool.solvers.studies.metrics import metric_columns
    from vtool.solvers.studies.sweep import PointResult, column_title, report_columns

    assert group_rows(1) == ROW_GROUP and group_rows(10**6) == 1024 and group_rows(64) == GROUP_BYTES // 512
    spec = load_preset("gnilka-1d")
    names = [name for name, _ in metric_columns(spec)]
    with open_atomic_binary(tmp_path / "s.parquet") as handle:
        sink = SweepParquet(handle, (("run.rpm", "rev/min"), ("run.degrees", "deg")), spec)
        columns = 1 + 2 + 1 + len(report_columns(spec, timing=False))  # point, the fields, status, the metrics
        assert sink.size == GROUP_BYTES // (8 * columns) < ROW_GROUP
        count = 2 * sink.size + 7
        for i in range(count):
            sink.append(PointResult(i, (("run.rpm", 1000 + i), ("run.degrees", 0.5)), dict.fromkeys(names, i / 3)))
            assert sink.held < sink.size
        sink.finish()
    file = pq.ParquetFile(tmp_path / "s.parquet")
    assert [file.metadata.row_group(g).num_rows for g in range(file.metadata.num_row_groups)] == \
        [sink.size, sink.size, 7]
    table = file.read()
    assert table.column("run.rpm (rev/min)").to_pylist() == [1000.0 + i for i in range(count)]
    assert table.column("point").to_pylist() == list(range(count))
    assert table.column(column_title(names[0], dict(metric_columns(spec))[names[0]])).to_pylist() == \
        [i / 3 for i in range(count)]


def _points(path: Path) -> dict[int, dict]:
    """Each point's row, NaN as None (to compare files)."""
    table = pq.read_table(path).to_pylist()
    return {row.pop("point"): {k: None if isinstance(v, float) and math.isnan(v) else v for k, v in row.items()}
            for row in table}


def test_a_parquet_sweep_resumes_from_its_row_groups(tmp_path: Path) -> None:
    """--resume with Parquet: the old file's points that belong to this sweep (index and values) are copied,
    the rest run, the new file replaces the old one: the same points as an uninterrupted sweep."""
    sweep = ["sweep", "gnilka-1d", "--set", "run.degrees=100", "--workers", "1", "--format", "parquet"]
    full, part, other = tmp_path / "full.pq", tmp_path / "part.pq", tmp_path / "other.pq"
    assert run(*sweep, "--set", "run.rpm=9000,10000,11000", "--out", str(full)).exit_code == 0
    assert run(*sweep, "--set", "run.rpm=9000,10000", "--out", str(part)).exit_code == 0  # points 0 and 1
    result = run(*sweep, "--set", "run.rpm=9000,10000,11000", "--out", str(part), "--resume")
    assert result.exit_code == 0, result.output
    assert "resumed: 2 of 3 points were already in" in result.output
    assert _points(part) == _points(full)
    assert run(*sweep, "--set", "run.rpm=10000,11000", "--out", str(other)).exit_code == 0  # 0, 1: other speeds
    result = run(*sweep, "--set", "run.rpm=9000,10000,11000", "--out", str(other), "--resume")
    assert result.exit_code == 0 and "resumed:" not in result.output  # indices whose values differ: run again
    assert _points(other) == _points(full)
    result = run(*sweep, "--set", "run.rpm=9000,10000", "--set", "damping.factor=1", "--out", str(full), "--resume")
    assert result.exit_code == 2 and "a partial file of this same sweep (its columns differ)" in result.output
    (tmp_path / "text.pq").write_text("run.rpm\n")
    result = run(*sweep, "--set", "run.rpm=9000", "--out", str(tmp_path / "text.pq"), "--resume")
    assert result.exit_code == 2 and "this one is not Parquet" in result.output


def test_an_interrupted_parquet_sweep_keeps_its_finished_points(tmp_path: Path) -> None:
    """Ctrl+C (or SIGTERM) after a point finished: the file holds it (footer written, renamed into place) and
    --resume runs the rest; before any point finished, an existing file is left as it was."""
    from vtool.app.cli.sweep import _run_to_parquet
    from vtool.presets.paths import plan_sweep
    from vtool.solvers.studies.sweep import SerialRunner

    class StopAfterOne(SerialRunner):
        def run(self, batches, every_step, on_results, cancel):  # type: ignore[no-untyped-def]
            def one(results):  # type: ignore[no-untyped-def]
                on_results(results)
                raise KeyboardInterrupt

            return super().run(batches, every_step, one, cancel)

    plan = plan_sweep("gnilka-1d", ["run.rpm=9000,10000,11000", "run.degrees=100"])
    path = tmp_path / "s.parquet"
    written = [0]
    with pytest.raises(KeyboardInterrupt):
        _run_to_parquet(plan, StopAfterOne(), path, False, False, False, None, False, written)
    assert written == [1] and list(_points(path)) == [0]
    outcome = _run_to_parquet(plan, SerialRunner(), path, False, False, True, None, True, [0])
    assert outcome.skipped == 1 and [r.index for r in outcome.results] == [0, 1, 2]
    assert sorted(_points(path)) == [0, 1, 2]


def test_parquet_refusals_are_one_line(tmp_path: Path) -> None:
    result = run("sweep", "gnilka-1d", "--set", "run.rpm=9000,10000", "--format", "parquet", "--find", "jump-speed",
                 "--out", str(tmp_path / "p.parquet"))
    assert result.exit_code == 2 and "csv for --find" in result.output
    result = run("sweep", "gnilka-1d", "--set", "run.rpm=9000,10000", "--format", "parquet", "--resume",
                 "--out", str(tmp_path / "p.parquet"))
    assert result.exit_code == 2 and "an existing partial sweep file (none found)" in result.output
    result = run("solve", "gnilka-1d", "--format", "parquet")
    assert result.exit_code == 2 and "an output file" in result.output
    result = run("solve", "boom-brick-wall", "--format", "parquet", "--out", str(tmp_path / "b.parquet"))
    assert result.exit_code == 2 and "--format applies to valvetrain presets" in result.output
    assert not list(tmp_path.iterdir())


def test_without_pyarrow_parquet_is_one_line_and_nothing_runs(tmp_path: Path) -> None:
    """pyarrow is an optional extra: without it, asking for Parquet is one line, exit 2, before the run."""
    code = ("import sys\n"
            "sys.modules['pyarrow'] = None; sys.modules['pyarrow.parquet'] = None  # import now fails\n"
            "from vtool.app.cli.main import main\n"
            f"sys.argv = ['vtool', 'solve', 'gnilka-1a', '--every-step', '--out', {str(tmp_path / 'r.parquet')!r}]\n"
            "main()\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "error: --format: got 'parquet', expected pyarrow installed for Parquet output "
        "(pip install 'vtool[parquet]'); or --format csv"]
    assert done.stdout == "" and not list(tmp_path.iterdir())
